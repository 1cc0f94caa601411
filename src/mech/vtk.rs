//! VTK output of the deformed film (the paper's Fig. 6): a ParaView-readable XML unstructured
//! grid (`.vtu`) per state and a `.pvd` collection over pseudo-time. Text only; the caller
//! writes the files.
//!
//! Points are the deformed node positions followed by one point per gap support. Cells are the
//! triangles (VTK type 5) followed by one line (type 3) per gap from its film node to its
//! support. Point data: `displacement`. Cell data (triangles | gaps): `von_mises`,
//! `principal_1`, `principal_2`, `stress` (σx, σy, τxy in the element frame) | zero, and
//! `gap_slip_x`, `gap_slip_y`, `gap_normal_force`, `gap_friction_force`, `gap_status`
//! (0 open, 1 stick, 2 slip) | zero / −1 on triangles; `wrinkling_state` (0 taut, 1 wrinkled,
//! 2 slack) | −1, and `tension_direction` (unit vector along the tension rays of a wrinkled
//! triangle, global axes, deformed film; zero when taut or slack) | zero.

use std::fmt::Write;

use super::model::{GapSupport, Model};
use super::solver::Results;

/// The `.vtu` text of one state (`displacement`: three per node).
pub fn unstructured_grid(model: &Model, displacement: &[f64], results: &Results) -> String {
    let nodes = model.nodes.len();
    let mut points = Vec::with_capacity(nodes + model.gaps.len());
    for (i, p) in model.nodes.iter().enumerate() {
        points.push([
            p[0] + displacement[3 * i],
            p[1] + displacement[3 * i + 1],
            p[2] + displacement[3 * i + 2],
        ]);
    }
    for g in &model.gaps {
        points.push(match &g.support {
            GapSupport::Point(p) => *p,
            GapSupport::Node(b) => points[*b],
        });
    }
    let (tris, gaps) = (model.triangles.len(), model.gaps.len());
    let mut s = String::with_capacity(200 * (points.len() + tris));
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n");
    let _ = writeln!(
        s,
        "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        points.len(),
        tris + gaps
    );
    s.push_str(
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for p in &points {
        let _ = writeln!(s, "{:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for t in &model.triangles {
        let _ = writeln!(s, "{} {} {}", t[0], t[1], t[2]);
    }
    for (k, g) in model.gaps.iter().enumerate() {
        let _ = writeln!(s, "{} {}", g.film_node, nodes + k);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    let offsets: Vec<String> = (1..=tris)
        .map(|i| (3 * i).to_string())
        .chain((1..=gaps).map(|k| (3 * tris + 2 * k).to_string()))
        .collect();
    s.push_str(&offsets.join(" "));
    s.push_str("\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    let types: Vec<&str> = std::iter::repeat_n("5", tris)
        .chain(std::iter::repeat_n("3", gaps))
        .collect();
    s.push_str(&types.join(" "));
    s.push_str("\n</DataArray>\n</Cells>\n<PointData Vectors=\"displacement\">\n");
    s.push_str("<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for i in 0..nodes {
        let _ = writeln!(
            s,
            "{:e} {:e} {:e}",
            displacement[3 * i],
            displacement[3 * i + 1],
            displacement[3 * i + 2]
        );
    }
    for _ in 0..gaps {
        s.push_str("0 0 0\n");
    }
    s.push_str("</DataArray>\n</PointData>\n<CellData Scalars=\"von_mises\">\n");
    let mut scalar = |name: &str, tri: &dyn Fn(usize) -> f64, gap: &dyn Fn(usize) -> f64| {
        let _ = writeln!(
            s,
            "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">"
        );
        let values: Vec<String> = (0..tris)
            .map(|e| format!("{:e}", tri(e)))
            .chain((0..gaps).map(|k| format!("{:e}", gap(k))))
            .collect();
        s.push_str(&values.join(" "));
        s.push_str("\n</DataArray>\n");
    };
    let el = &results.elements;
    let gp = &results.gaps;
    scalar("von_mises", &|e| el[e].von_mises, &|_| 0.0);
    scalar("principal_1", &|e| el[e].principal[0], &|_| 0.0);
    scalar("principal_2", &|e| el[e].principal[1], &|_| 0.0);
    scalar("gap_slip_x", &|_| 0.0, &|k| gp[k].slip_x);
    scalar("gap_slip_y", &|_| 0.0, &|k| gp[k].slip_y);
    scalar("gap_normal_force", &|_| 0.0, &|k| gp[k].normal_force);
    scalar("gap_friction_force", &|_| 0.0, &|k| gp[k].friction_force);
    scalar("gap_status", &|_| -1.0, &|k| gp[k].status as i32 as f64);
    scalar("wrinkling_state", &|e| el[e].state as i32 as f64, &|_| -1.0);
    let mut vector = |name: &str, tri: &dyn Fn(usize) -> [f64; 3]| {
        let _ = writeln!(
            s,
            "<DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"3\" format=\"ascii\">"
        );
        for e in 0..tris {
            let v = tri(e);
            let _ = writeln!(s, "{:e} {:e} {:e}", v[0], v[1], v[2]);
        }
        for _ in 0..gaps {
            s.push_str("0 0 0\n");
        }
        s.push_str("</DataArray>\n");
    };
    vector("stress", &|e| el[e].stress);
    vector("tension_direction", &|e| el[e].tension_direction);
    s.push_str("</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// The `.pvd` collection text listing `(time, file name)` pairs.
pub fn collection(entries: &[(f64, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n<Collection>\n",
    );
    for (t, file) in entries {
        let _ = writeln!(
            s,
            "<DataSet timestep=\"{t}\" part=\"0\" file=\"{}\"/>",
            xml_escape(file)
        );
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    s
}

fn xml_escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
