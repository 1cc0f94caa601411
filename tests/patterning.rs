//! Form finding and patterning (issue 46): `mech::formfinding`, `mech::patterning`.
//!
//! SOURCES: Bletzinger & Ramm, Int. J. Space Struct. 14 (1999) (updated reference strategy);
//! Schek, CMAME 3 (1974) (force density); the catenoid `r(z) = a cosh(z/a)` with
//! `R = a cosh(h/(2a))` and Scherk's surface `z = ln(cos y / cos x)` (minimal surfaces: an
//! isotropic prestress in equilibrium).
//!
//! TEST GOAL: the found catenoid's waist radius is `a` within 0.5 %, and every node lies on
//! `a cosh(z/a)`; Scherk's surface is found from a flat start within its discretization error,
//! which falls as the mesh is refined (0.5 % of the rim's height); the step matrix is the derivative of the membrane
//! element's own force with the prestress alone (central differences, an orthotropic prestress
//! with shear); a found shape keeps its prestress within 1e-3 in the project's own analysis.
//! Patterning: a strip of a cylinder (developable) flattens to its exact size with no strain; a
//! strip of a sphere reports its strain, and the relaxation lowers it below the conformal map's;
//! the relaxation's Jacobian is the derivative of its residual; seam planes and seam node lines
//! along the same meridians cut the same strips; the prestress compensation of an isotropic
//! prestress is `σ(1 − ν)/E` both ways; the SVG names every strip with its length.
//! Element-wise compensation: a strip refitted to a uniform target metric `diag(a², b²)` takes
//! the lengths `2a × b` exactly; the fixed point on the reference metrics brings an uncompensated
//! cut over a frictionless drum within 0.5 % in one correction; with μ = 0.3 it stalls and names
//! the crown's elements as held by friction. A winding rail path (up 0.10 m and in 0.03 m, down,
//! then out) erects the drum film to the straight path's stresses without friction (the end
//! state of an elastic film on a frictionless support does not depend on the path) and to other
//! stresses with μ = 0.3; the element-wise compensation along it reaches 5 % away from the rails
//! or names every triangle it leaves above and those friction holds, through the CLI as well,
//! which writes each erection's model as it erects it.
//!
//! MESHES (erection): a flat 2 m × 1 m film, 8 × 4 cells, rim held; a film over a drum
//! (cylinder `r = 0.5 m` along y, a curved support), ±60° of arc (12 cells) and 0.5 m tangents
//! (4 cells) to a rail each side, 1 m wide (4 cells), side edges on symmetry planes.
//!
//! MESHES (patterning): a quarter cylinder `R = 1 m`, 2 m long, 12 × 8 cells; a strip of the
//! unit sphere, polar angle 30°–150°, 40° wide, 12 × 4 cells.
//!
//! MESHES: catenoid: `NT` nodes around × `NZ` cells along, rings at `z = ±h/2` (one boundary
//! group each, all components held), started as the cylinder `r = R`. Scherk: a square
//! `|x|, |y| ≤ c` of `n × n` cells, each cell cut along the diagonal that points at the centre;
//! the boundary nodes on the exact surface (one group), the inside flat (z = 0).
//!
//! PARAMETERS: ETFE film of the specimen (t = 0.2 mm), prestress 2 MPa isotropic.

mod common;

use common::{analysis_stress_error, film_model, surface_grid};
use membrane_contact::mech::elements::gap::GapStatus;
use membrane_contact::mech::elements::material::{Material, Wrinkling};
use membrane_contact::mech::elements::triangle::MembraneTriangle;
use membrane_contact::mech::formfinding::contact::{ContactSettings, find_shape_with_contact};
use membrane_contact::mech::formfinding::force_density::force_density_shape;
use membrane_contact::mech::formfinding::update_reference::{
    UpdateSettings, find_shape, reference_stiffness,
};
use membrane_contact::mech::formfinding::{form_found_model, held_dofs};
use membrane_contact::mech::model::{BoundaryGroup, Model};
use membrane_contact::mech::patterning::Strip;
use membrane_contact::mech::patterning::contact_stiffness::{
    ContactStiffness, support_stiffnesses, tributary_length,
};
use membrane_contact::mech::patterning::cut::{Compensation, cut_pattern};
use membrane_contact::mech::patterning::element_compensation::{
    ElementCompensation, ElementSettings, Erected, away_from_rails, compensate_elements,
    cut_metrics, erect_along, erect_through, erect_with_contacts, passed_through_supports,
    rail_start_offsets, rail_waypoints, refit_strips, settling_amplitude, settling_waypoints,
};
use membrane_contact::mech::patterning::erection::{compensate_by_erection, erect_by_analysis};
use membrane_contact::mech::patterning::flatten::conformal_map;
use membrane_contact::mech::patterning::outline::{OutlineLabel, boundary_edges, bounds, dxf, svg};
use membrane_contact::mech::patterning::reference::{erection_model, reference_geometry};
use membrane_contact::mech::patterning::relax::{
    StrainTerm, relax_strains, strain_measure, strain_residual,
};
use membrane_contact::mech::patterning::seams::{
    SeamPlane, strips_by_node_lines, strips_by_planes,
};
use membrane_contact::mech::{Analysis, SolverSettings};
use nalgebra::{Matrix2, SVector, Vector3};

const ISOTROPIC: [f64; 3] = [2.0e6, 2.0e6, 0.0];

fn group(name: &str, nodes: Vec<usize>) -> BoundaryGroup {
    BoundaryGroup {
        name: name.into(),
        nodes,
        target: [0.0; 3],
        components: None,
        hinge: None,
    }
}

/// The catenoid's `a` on the stable branch: `R = a cosh(h/(2a))`, by bisection on `a > h/(2·1.1997)`.
fn catenoid_a(r: f64, h: f64) -> f64 {
    // a cosh(h/2a) has its minimum at h/(2a) = 1.19968; the stable branch is the larger a.
    let (mut lo, mut hi) = (h / (2.0 * 1.199_678_640_257_734), r);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid * (h / (2.0 * mid)).cosh() > r {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// A cylinder `r = R`, `|z| ≤ h/2`, `nt` around × `nz` cells along, rings held.
fn cylinder(r: f64, h: f64, nt: usize, nz: usize) -> Model {
    let id = |i: usize, j: usize| j * nt + i % nt;
    let mut nodes = vec![];
    for j in 0..=nz {
        for i in 0..nt {
            let phi = 2.0 * std::f64::consts::PI * i as f64 / nt as f64;
            nodes.push([
                r * phi.cos(),
                r * phi.sin(),
                -0.5 * h + h * j as f64 / nz as f64,
            ]);
        }
    }
    let mut triangles = vec![];
    for j in 0..nz {
        for i in 0..nt {
            // Diagonals mirrored about z = 0, so the mesh is symmetric about the waist.
            if (2 * j < nz) == (i % 2 == 0) {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                triangles.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                triangles.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    let mut model = film_model("Catenoid", nodes, triangles);
    model.groups = vec![
        group("bottom", (0..nt).map(|i| id(i, 0)).collect()),
        group("top", (0..nt).map(|i| id(i, nz)).collect()),
    ];
    model
}

/// Scherk's surface `z = ln(cos y / cos x)`.
fn scherk(x: f64, y: f64) -> f64 {
    (y.cos() / x.cos()).ln()
}

/// The square `|x|, |y| ≤ c` of `n × n` cells, boundary on Scherk's surface, inside flat.
fn scherk_square(c: f64, n: usize) -> Model {
    let id = |i: usize, j: usize| j * (n + 1) + i;
    let mut nodes = vec![];
    let mut rim = vec![];
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (
                -c + 2.0 * c * i as f64 / n as f64,
                -c + 2.0 * c * j as f64 / n as f64,
            );
            let on_rim = i == 0 || j == 0 || i == n || j == n;
            nodes.push([x, y, if on_rim { scherk(x, y) } else { 0.0 }]);
            if on_rim {
                rim.push(id(i, j));
            }
        }
    }
    let mut triangles = vec![];
    for j in 0..n {
        for i in 0..n {
            let (a, b, cc, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (2 * i < n) == (2 * j < n) {
                triangles.extend([[a, b, cc], [a, cc, d]]);
            } else {
                triangles.extend([[a, b, d], [b, cc, d]]);
            }
        }
    }
    let mut model = film_model("Scherk", nodes, triangles);
    model.groups = vec![group("rim", rim)];
    model
}

/// The isotropic shape found from the model's own geometry, default settings.
fn found_from_model(
    model: &Model,
) -> membrane_contact::mech::formfinding::update_reference::FoundShape {
    find_shape(
        model,
        model.nodes.clone(),
        ISOTROPIC,
        UpdateSettings::default(),
    )
    .unwrap()
}

#[test]
fn catenoid_waist_is_a_within_half_a_percent_and_nodes_lie_on_a_cosh() {
    let (r, h) = (1.0, 1.0);
    let a = catenoid_a(r, h);
    let model = cylinder(r, h, 64, 32);
    let start = std::time::Instant::now();
    let found = found_from_model(&model);
    let radius = |p: &[f64; 3]| p[0].hypot(p[1]);
    let waist: Vec<f64> = found.nodes[16 * 64..17 * 64].iter().map(radius).collect();
    let waist = waist.iter().sum::<f64>() / waist.len() as f64;
    let waist_error = (waist - a) / a;
    let surface_error = found
        .nodes
        .iter()
        .map(|p| (radius(p) - a * (p[2] / a).cosh()).abs() / a)
        .fold(0.0, f64::max);
    eprintln!(
        "catenoid a = {a:.6}: waist {waist:.6} ({:+.4} %), max |r − a cosh(z/a)|/a {:.4} %, {} steps, {:.2?}",
        100.0 * waist_error,
        100.0 * surface_error,
        found.steps,
        start.elapsed()
    );
    assert!(waist_error.abs() < 0.005, "waist error {waist_error}");
    assert!(surface_error < 0.005, "surface error {surface_error}");
}

/// Largest `|z − z_Scherk(x, y)|` of the found shape over the largest `|z|` of the rim.
fn scherk_error(n: usize) -> (f64, usize) {
    let model = scherk_square(1.0, n);
    let found = found_from_model(&model);
    let z_max = model.nodes.iter().map(|p| p[2].abs()).fold(0.0, f64::max);
    let error = found
        .nodes
        .iter()
        .map(|p| (p[2] - scherk(p[0], p[1])).abs())
        .fold(0.0, f64::max);
    (error / z_max, found.steps)
}

#[test]
fn scherk_surface_is_found_from_flat_within_its_discretization_error() {
    let start = std::time::Instant::now();
    let (coarse, coarse_steps) = scherk_error(8);
    let (fine, fine_steps) = scherk_error(16);
    eprintln!(
        "Scherk: max |z − z_exact|/max|z_rim| {:.4} % (8×8, {coarse_steps} steps), {:.4} % (16×16, {fine_steps} steps), {:.2?}",
        100.0 * coarse,
        100.0 * fine,
        start.elapsed()
    );
    assert!(fine < 0.005, "{fine}");
    // Refining the mesh brings the shape closer (the out-of-balance tolerance, not the mesh,
    // bounds the error at 16 × 16).
    assert!(fine < coarse, "{coarse} → {fine}");
}

#[test]
fn step_matrix_is_the_derivative_of_the_element_force_under_the_prestress_alone() {
    let model = scherk_square(1.2, 4);
    let prestress = [3.0e6, 1.5e6, 0.4e6];
    // The element's force (eq. 2.6) with D = 0 is t A F S ∇N: the step's residual.
    let material = Material {
        youngs_modulus: 0.0,
        prestress,
        wrinkling: Wrinkling::None,
        ..model.material
    };
    let x0 = model.nodes.clone();
    let k = reference_stiffness(&model, &x0, prestress).unwrap();
    let mut dense = vec![vec![0.0; x0.len()]; x0.len()];
    k.iter().for_each(|&(i, j, v)| dense[i][j] += v);
    let force = |x: &[[f64; 3]]| {
        let mut r = vec![[0.0; 3]; x.len()];
        for tri in &model.triangles {
            let element = MembraneTriangle::new(tri.map(|v| Vector3::from(x0[v]))).unwrap();
            let u = SVector::<f64, 9>::from_fn(|i, _| x[tri[i / 3]][i % 3] - x0[tri[i / 3]][i % 3]);
            let re = element.internal_force(&material, &u);
            (0..9).for_each(|i| r[tri[i / 3]][i % 3] += re[i]);
        }
        r
    };
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    let scale = dense.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for j in 0..x0.len() {
        for c in 0..3 {
            let shifted = |s: f64| {
                let mut x = x0.clone();
                x[j][c] += s;
                force(&x)
            };
            let (plus, minus) = (shifted(h), shifted(-h));
            for i in 0..x0.len() {
                for d in 0..3 {
                    let fd = (plus[i][d] - minus[i][d]) / (2.0 * h);
                    let exact = if c == d { dense[i][j] } else { 0.0 };
                    worst = worst.max((fd - exact).abs());
                }
            }
        }
    }
    assert!(worst < 1e-7 * scale, "{worst} vs {scale}");
}

#[test]
fn found_minimal_surface_keeps_its_prestress_in_the_analysis() {
    {
        let prestress = ISOTROPIC;
        let model = scherk_square(1.0, 10);
        let first = force_density_shape(&model).unwrap();
        let found = find_shape(&model, first, prestress, UpdateSettings::default()).unwrap();
        let error = analysis_stress_error(form_found_model(&model, found.nodes.clone(), prestress));
        // The start (the force density net) is not in equilibrium under the prestress.
        let start = form_found_model(&model, force_density_shape(&model).unwrap(), prestress);
        let start_error = analysis_stress_error(start);
        eprintln!(
            "{prestress:?}: stress error after analysis {error:.3e} (force density start {start_error:.3e})"
        );
        assert!(error < 1e-3, "{error}");
        assert!(start_error > 100.0 * error);
    }
    assert!(
        held_dofs(&scherk_square(1.0, 2))
            .iter()
            .filter(|h| h[0])
            .count()
            == 8
    );
}

/// `examples/catenoid.json`: the cylinder between the rings, 32 × 16 cells, 2 MPa isotropic.
fn catenoid_example() -> Model {
    let mut model = cylinder(1.0, 1.0, 32, 16);
    model.description = "A film between two coaxial rings of radius 1 m, 1 m apart, cut as a \
        cylinder: `membrane-contact form-find` finds the catenoid r(z) = a cosh(z/a), \
        a = 0.848338 m (issue 46)."
        .into();
    model.material.prestress = ISOTROPIC;
    model
}

#[test]
fn catenoid_example_form_finds_and_patterns_through_the_cli_to_its_golden_waist() {
    common::assert_example_file("catenoid.json", &catenoid_example());
    let out = std::env::temp_dir().join(format!("catenoid-found-{}.json", std::process::id()));
    let path = format!("{}/examples/catenoid.json", env!("CARGO_MANIFEST_DIR"));
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
        .args(["form-find", &path, "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let found = Model::from_json(&std::fs::read_to_string(&out).unwrap()).unwrap();
    // The found film cut into quarters: one line per strip, the SVG and the erection model.
    let (svg_file, erection) = (
        out.with_extension("svg"),
        out.with_extension("erection.json"),
    );
    let pattern = std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
        .arg("pattern")
        .arg(&out)
        .args([
            "--seam-plane",
            "0,0,0,1,0,0",
            "--seam-plane",
            "0,0,0,0,1,0",
            "--svg",
        ])
        .arg(&svg_file)
        .arg("--erection-model")
        .arg(&erection)
        .output()
        .unwrap();
    let stdout = String::from_utf8(pattern.stdout).unwrap();
    assert!(
        pattern.status.success() && stdout.lines().count() == 4,
        "{stdout}"
    );
    assert_eq!(
        std::fs::read_to_string(&svg_file)
            .unwrap()
            .matches("<g id=")
            .count(),
        4
    );
    let erection = Model::from_json(&std::fs::read_to_string(&erection).unwrap()).unwrap();
    assert_eq!(erection.groups.len(), 64);
    for file in [&out, &svg_file, &out.with_extension("erection.json")] {
        std::fs::remove_file(file).ok();
    }
    // The waist ring is the ninth of seventeen; its mean radius is the README's golden number.
    let ring = &found.nodes[8 * 32..9 * 32];
    let waist = ring.iter().map(|p| p[0].hypot(p[1])).sum::<f64>() / 32.0;
    eprintln!("example waist {waist:.6} (a = {:.6})", catenoid_a(1.0, 1.0));
    assert!((waist - 0.84668).abs() < 2e-5, "{waist}");
    assert_eq!(found.material.prestress, ISOTROPIC);
}

fn quarter_cylinder() -> Model {
    surface_grid(12, 8, |u, v| {
        let phi = 0.5 * std::f64::consts::PI * u;
        [phi.cos(), phi.sin(), 2.0 * v]
    })
}

fn sphere_strip() -> Model {
    surface_grid(4, 12, |u, v| {
        let (theta, phi) = ((30.0 + 120.0 * v).to_radians(), (40.0 * u).to_radians());
        [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ]
    })
}

fn whole(model: &Model) -> Vec<Vec<usize>> {
    vec![(0..model.triangles.len()).collect()]
}

#[test]
fn developable_cylinder_strip_flattens_to_its_size_with_no_strain() {
    let model = quarter_cylinder();
    let cut = cut_pattern(&model, whole(&model), Compensation::Uniform([0.0; 2])).unwrap();
    let width = 12.0 * 2.0 * (std::f64::consts::PI / 48.0).sin();
    let d = cut[0].distortion;
    eprintln!(
        "cylinder strip: max strain {:.2e}, rms {:.2e}, size {:?} (exact [2, {width:.6}])",
        d.max_strain, d.rms_strain, cut[0].size
    );
    assert!(d.max_strain < 1e-9, "{d:?}");
    assert!(
        (cut[0].size[0] - 2.0).abs() < 1e-9 && (cut[0].size[1] - width).abs() < 1e-9,
        "{:?}",
        cut[0].size
    );
}

#[test]
fn doubly_curved_sphere_strip_reports_strain_and_relaxation_lowers_it() {
    let model = sphere_strip();
    let mut strip = Strip::new(&model, whole(&model).remove(0));
    let elements = strip.elements(&model, &model.nodes).unwrap();
    conformal_map(&mut strip, &elements, &model.nodes).unwrap();
    let terms: Vec<StrainTerm> = elements.iter().map(StrainTerm::from).collect();
    let conformal = strain_measure(&terms, &strip.flat, 0.0, &strip.flat);
    let relaxed = relax_strains(&mut strip, &elements, 100).unwrap();
    let cut = cut_pattern(&model, whole(&model), Compensation::Uniform([0.0; 2])).unwrap();
    let d = cut[0].distortion;
    eprintln!(
        "sphere strip: Φ conformal {conformal:.3e} → relaxed {relaxed:.3e}; max strain {:.3e}, rms {:.3e}",
        d.max_strain, d.rms_strain
    );
    assert!(
        d.max_strain > 1e-3 && d.rms_strain > 1e-4 && d.rms_strain < d.max_strain,
        "{d:?}"
    );
    assert!(relaxed < 0.5 * conformal, "{conformal} → {relaxed}");
}

#[test]
fn relaxation_jacobian_is_the_derivative_of_its_residual_flat_and_in_space() {
    let model = sphere_strip();
    let strip = Strip::new(&model, vec![5]);
    let term = StrainTerm::from(&strip.elements(&model, &model.nodes).unwrap()[0]);
    check_strain_jacobian(&term, [[0.1, 0.05], [0.3, 0.02], [0.12, 0.31]]);
    check_strain_jacobian(
        &term,
        [[0.1, 0.05, 0.2], [0.3, 0.02, -0.1], [0.12, 0.31, 0.05]],
    );
}

/// Central differences of [`strain_residual`] against its Jacobian at the positions `y`.
fn check_strain_jacobian<const D: usize>(term: &StrainTerm, y: [[f64; D]; 3]) {
    let (_, j) = strain_residual(term, &y);
    let h = 1e-7;
    for k in 0..3 {
        for c in 0..D {
            let shifted = |s: f64| {
                let mut y = y;
                y[k][c] += s;
                strain_residual(term, &y).0
            };
            let fd = (shifted(h) - shifted(-h)) / (2.0 * h);
            let exact = Vector3::new(j[0][k][c], j[1][k][c], j[2][k][c]);
            assert!(
                (fd - exact).norm() < 1e-7 * (1.0 + exact.norm()),
                "node {k} axis {c}: {fd} vs {exact}"
            );
        }
    }
}

#[test]
fn seam_planes_and_seam_node_lines_along_the_same_meridians_cut_the_same_strips() {
    let model = catenoid_example();
    let planes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].map(|normal| SeamPlane {
        point: [0.0; 3],
        normal,
    });
    let mut by_planes = strips_by_planes(&model, &planes);
    let lines: Vec<Vec<usize>> = [0, 8, 16, 24]
        .iter()
        .map(|&i| (0..=16).map(|j| j * 32 + i).collect())
        .collect();
    let mut by_lines = strips_by_node_lines(&model, &lines);
    by_planes.sort();
    by_lines.sort();
    assert_eq!(by_planes.len(), 4);
    assert!(
        by_planes
            .iter()
            .all(|s| s.len() == model.triangles.len() / 4)
    );
    assert_eq!(by_planes, by_lines);
}

#[test]
fn isotropic_prestress_compensation_is_sigma_one_minus_nu_over_e_and_the_svg_dimensions_each_strip()
{
    let mut model = sphere_strip();
    model.material.prestress = ISOTROPIC;
    let strips = vec![(0..48).collect(), (48..96).collect()];
    let cut = cut_pattern(&model, strips, Compensation::Prestress).unwrap();
    let m = &model.material;
    let expected = ISOTROPIC[0] * (1.0 - m.poisson_ratio) / m.youngs_modulus;
    for c in &cut {
        assert!(
            c.compensation
                .iter()
                .all(|c| (c - expected).abs() < 1e-12 * expected),
            "{:?} vs {expected}",
            c.compensation
        );
    }
    let labels: Vec<OutlineLabel> = (0..2)
        .map(|k| OutlineLabel {
            name: format!("strip {k}"),
            compensation: cut[k].compensation,
        })
        .collect();
    let strips: Vec<Strip> = cut.iter().map(|c| c.strip.clone()).collect();
    let text = svg(&model, &strips, &labels);
    assert_eq!(text.matches("<g id=").count(), 2);
    for c in &cut {
        assert!(
            text.contains(&format!("L = {:.1} mm", 1000.0 * c.size[0])),
            "{text}"
        );
    }
}

/// The DXF drawing holds each strip's boundary edges as LINEs on its own layer, in mm, placed
/// so that its outline spans the strip's length and width, and a TEXT with them.
#[test]
fn dxf_outline_draws_each_strips_boundary_on_its_layer_with_its_dimensions() {
    let model = sphere_strip();
    let strips = vec![(0..48).collect(), (48..96).collect()];
    let cut = cut_pattern(&model, strips, Compensation::Uniform([0.0, 0.0])).unwrap();
    let labels: Vec<OutlineLabel> = (0..2)
        .map(|k| OutlineLabel {
            name: format!("strip {k}"),
            compensation: cut[k].compensation,
        })
        .collect();
    let strips: Vec<Strip> = cut.iter().map(|c| c.strip.clone()).collect();
    let text = dxf(&model, &strips, &labels);
    assert!(text.starts_with("0\nSECTION\n2\nHEADER\n") && text.ends_with("0\nEOF\n"));
    let lines: Vec<&str> = text.lines().collect();
    for (k, c) in cut.iter().enumerate() {
        let layer = format!("STRIP_{k}");
        // Each LINE entity: 0 LINE 8 layer 10 x1 20 y1 30 z 11 x2 21 y2 31 z.
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        let at = |i: usize| lines[i].parse::<f64>().unwrap();
        for i in 0..lines.len() {
            if lines[i] == "LINE" && lines[i + 2] == layer {
                xs.extend([at(i + 4), at(i + 10)]);
                ys.extend([at(i + 6), at(i + 12)]);
            }
        }
        let edges = boundary_edges(&model, &c.strip).len();
        assert_eq!(xs.len(), 2 * edges, "{layer}");
        let span = |v: &[f64]| {
            v.iter().fold(f64::MIN, |m, x| m.max(*x)) - v.iter().fold(f64::MAX, |m, x| m.min(*x))
        };
        for (axis, v) in [&xs, &ys].into_iter().enumerate() {
            let size = 1000.0 * c.size[axis];
            assert!(
                (span(v) - size).abs() < 1e-2,
                "{layer} {axis}: {} vs {size}",
                span(v)
            );
        }
        // Its first line is its first boundary edge, the strip's corner at the origin (strip 0).
        if k == 0 {
            let [x0, y0, _, _] = bounds(&c.strip.flat);
            let [a, b] = boundary_edges(&model, &c.strip)[0];
            let at = |v: usize| {
                [
                    1000.0 * (c.strip.flat[v][0] - x0),
                    1000.0 * (c.strip.flat[v][1] - y0),
                ]
            };
            let drawn = [[xs[0], ys[0]], [xs[1], ys[1]]];
            for (d, e) in drawn.iter().zip([at(a), at(b)]) {
                assert!(
                    (d[0] - e[0]).abs() < 1e-3 && (d[1] - e[1]).abs() < 1e-3,
                    "{d:?} vs {e:?}"
                );
            }
        }
        assert!(text.contains(&format!(
            "strip {k}: L = {:.1} mm, W = {:.1} mm",
            1000.0 * c.size[0],
            1000.0 * c.size[1]
        )));
    }
}

/// A flat 2 m × 1 m film, 8 × 4 cells, rim held (one group), 2 MPa isotropic: its own found shape.
fn flat_film() -> Model {
    let (nodes, triangles) = common::flat_grid(8, 4, 2.0, 1.0);
    let rim = (0..nodes.len())
        .filter(|&v| {
            let p = nodes[v];
            p[0] == 0.0 || p[0] == 2.0 || p[1] == 0.0 || p[1] == 1.0
        })
        .collect();
    let mut model = film_model("FlatFilm", nodes, triangles);
    model.groups = vec![group("rim", rim)];
    model.material.prestress = ISOTROPIC;
    model.material.wrinkling = Wrinkling::None;
    model
}

/// The flat film's two halves, cut by the plane x = 1 m.
fn halves(model: &Model) -> Vec<Vec<usize>> {
    let seam = SeamPlane {
        point: [1.0, 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
    };
    strips_by_planes(model, &[seam])
}

/// Largest and mean `|σ − σ0|/|σ0|` (x and y) after erecting `cut` of the found `model`.
fn erected_stress_error(
    model: &Model,
    cut: &[membrane_contact::mech::patterning::cut::CutStrip],
) -> (f64, f64) {
    let reference = reference_geometry(model, cut).unwrap();
    let erection = erection_model(model, reference);
    let targets: Vec<[f64; 3]> = erection.groups.iter().map(|g| g.target).collect();
    let mut analysis = Analysis::new(erection, SolverSettings::default()).unwrap();
    analysis.step_to(&targets, 2).unwrap();
    let sigma = model.material.prestress[0];
    let errors: Vec<f64> = analysis
        .results()
        .elements
        .iter()
        .map(|e| ((e.stress[0] - sigma).abs()).max((e.stress[1] - sigma).abs()) / sigma)
        .collect();
    (
        errors.iter().fold(0.0, |m, &e| f64::max(m, e)),
        errors.iter().sum::<f64>() / errors.len() as f64,
    )
}

#[test]
fn erecting_the_prestress_compensated_cut_of_a_flat_film_gives_the_target_prestress() {
    let model = flat_film();
    let strips = halves(&model);
    let cut = cut_pattern(&model, strips.clone(), Compensation::Prestress).unwrap();
    let (max, mean) = erected_stress_error(&model, &cut);
    // Without compensation the erected film carries no stress at all.
    let uncompensated = cut_pattern(&model, strips, Compensation::Uniform([0.0; 2])).unwrap();
    let (max0, _) = erected_stress_error(&model, &uncompensated);
    eprintln!(
        "flat film erected: stress error max {:.3} %, mean {:.3} % (uncompensated: {:.1} %)",
        100.0 * max,
        100.0 * mean,
        100.0 * max0
    );
    assert!(max < 0.005, "{max}");
    assert!(max0 > 0.9);
}

#[test]
fn erection_fixed_point_corrects_a_cut_made_to_the_found_shape_to_the_target_prestress() {
    let model = flat_film();
    let strips = halves(&model);
    let mut erect = |m: Model| erect_by_analysis(m, 2);
    // The mistake: the film cut to the found shape (no compensation) carries no stress.
    let history = compensate_by_erection(
        &model,
        strips,
        Compensation::Uniform([0.0; 2]),
        (5, 1e-3),
        &mut erect,
    )
    .unwrap();
    for (k, h) in history.iter().enumerate() {
        eprintln!(
            "erection {k}: mean error {:.4} %, max {:.4} %, compensation {:?}",
            100.0 * h.mean_error,
            100.0 * h.max_error,
            h.compensation
        );
    }
    assert!(history[0].mean_error > 0.9);
    let last = history.last().unwrap();
    assert!(history.len() <= 3 && last.max_error < 0.005, "{history:?}");
}

/// A film over a drum (cylinder of radius 0.5 m along y, 1 m wide): wrapped ±60° from the crown,
/// then straight along the tangents for 0.5 m to a rail on each side; side edges on symmetry
/// planes; μ on the drum. With an isotropic prestress this is its own found shape (the hoop
/// tension is constant over a frictionless drum).
fn film_over_drum(mu: f64) -> Model {
    let (r, theta, lt, width) = (0.5f64, 60f64.to_radians(), 0.5, 1.0);
    let (n_arc, n_t, ny) = (12usize, 4usize, 4usize);
    let section: Vec<[f64; 2]> = {
        let (s, c) = theta.sin_cos();
        let tangent = |side: f64, k: usize| {
            let d = lt * k as f64 / n_t as f64;
            [side * (r * s + d * c), r * c - d * s]
        };
        let mut pts: Vec<[f64; 2]> = (1..=n_t).rev().map(|k| tangent(-1.0, k)).collect();
        pts.extend((0..=n_arc).map(|k| {
            let phi = -theta + 2.0 * theta * k as f64 / n_arc as f64;
            [r * phi.sin(), r * phi.cos()]
        }));
        pts.extend((1..=n_t).map(|k| tangent(1.0, k)));
        pts
    };
    let nx = section.len() - 1;
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut nodes = vec![];
    for j in 0..=ny {
        for p in &section {
            nodes.push([p[0], width * j as f64 / ny as f64, p[1]]);
        }
    }
    let mut triangles = vec![];
    for j in 0..ny {
        for i in 0..nx {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mut model = film_model("Drum", nodes, triangles);
    model.material.prestress = ISOTROPIC;
    let rails = [0, nx].map(|i| (0..=ny).map(|j| id(i, j)).collect::<Vec<_>>());
    model.groups = vec![
        group("railW", rails[0].clone()),
        group("railE", rails[1].clone()),
    ];
    let contact: Vec<usize> = (0..=ny)
        .flat_map(|j| (n_t..=n_t + n_arc).map(move |i| id(i, j)))
        .collect();
    let extra = serde_json::json!({
        "symmetry": [
            { "name": "south", "normal": "y", "nodes": (1..nx).map(|i| id(i, 0)).collect::<Vec<_>>() },
            { "name": "north", "normal": "y", "nodes": (1..nx).map(|i| id(i, ny)).collect::<Vec<_>>() }
        ],
        "curved_supports": [{ "name": "drum", "centreline": { "line": { "point": [0, 0, 0], "axis": [0, 1, 0] } },
            "tube_radius": r, "nodes": contact, "normal_stiffness": 1e7, "tangential_stiffness": 1e6, "friction": mu }]
    });
    let mut value = serde_json::to_value(&model).unwrap();
    for key in ["symmetry", "curved_supports"] {
        value[key] = extra[key].clone();
    }
    Model::from_json(&value.to_string()).unwrap()
}

/// The x of triangle `t`'s centroid.
fn centre_x(model: &Model, t: usize) -> f64 {
    model.triangles[t]
        .iter()
        .map(|&v| model.nodes[v][0])
        .sum::<f64>()
        / 3.0
}

/// The hoop stress `σx` after erecting the prestress-compensated cut of the drum film in one
/// strip: the mean over the crown (|x| < 0.1 m) and over the straight parts, and the erection's
/// largest error.
fn drum_erection(mu: f64) -> (f64, f64, f64) {
    let model = film_over_drum(mu);
    let erect = |m: Model| erect_by_analysis(m, 10);
    let strips = strips_by_planes(&model, &[]);
    let stresses = std::cell::RefCell::new(vec![]);
    let mut keep = |m: Model| {
        let s = erect(m)?;
        *stresses.borrow_mut() = s.clone();
        Ok(s)
    };
    let history =
        compensate_by_erection(&model, strips, Compensation::Prestress, (1, 0.0), &mut keep)
            .unwrap();
    let s = stresses.into_inner();
    let centre = |t: usize| centre_x(&model, t);
    let mean = |pick: &dyn Fn(f64) -> bool| {
        let chosen: Vec<f64> = (0..s.len())
            .filter(|&t| pick(centre(t)))
            .map(|t| s[t].stress[0])
            .collect();
        chosen.iter().sum::<f64>() / chosen.len() as f64
    };
    (
        mean(&|x| x.abs() < 0.1),
        mean(&|x| x.abs() > 0.45),
        history[0].max_error,
    )
}

#[test]
fn erected_over_a_frictionless_drum_the_cut_carries_its_target_and_friction_leaves_the_crown_short()
{
    let start = std::time::Instant::now();
    let (crown0, straight0, error0) = drum_erection(0.0);
    let (crown, straight, error) = drum_erection(0.3);
    eprintln!(
        "drum: μ = 0: crown {:.3} MPa, straight {:.3} MPa, largest error {:.2} %; μ = 0.3: crown {:.3} MPa, straight {:.3} MPa, largest error {:.2} % ({:.2?})",
        crown0 / 1e6,
        straight0 / 1e6,
        100.0 * error0,
        crown / 1e6,
        straight / 1e6,
        100.0 * error,
        start.elapsed()
    );
    assert!(error0 < 0.005, "{error0}");
    // The capstan: the film slides over the drum towards the rails; friction holds the crown back.
    assert!(
        crown < 0.97 * ISOTROPIC[0] && straight > 1.03 * ISOTROPIC[0],
        "{crown} {straight}"
    );
}

/// The element-wise fixed point on the drum film (one strip, the prestress compensation to start).
fn drum_element_iterations(
    mu: f64,
    (iterations, tolerance): (usize, f64),
    start: Compensation,
    planes: &[SeamPlane],
) -> ElementCompensation {
    let model = film_over_drum(mu);
    let strips = strips_by_planes(&model, planes);
    let settings = ElementSettings {
        iterations,
        tolerance,
        counted: away_from_rails(&model),
    };
    let mut erect = |m: Model| erect_with_contacts(m, 10);
    let outcome = compensate_elements(&model, strips, start, &settings, &mut erect).unwrap();
    for (k, h) in outcome.history.iter().enumerate() {
        eprintln!(
            "drum μ = {mu}: erection {k}: mean error {:.3} %, max {:.3} % (triangle {}), compensation {:?}",
            100.0 * h.mean_error,
            100.0 * h.max_error.0,
            h.max_error.1,
            h.compensation
        );
    }
    eprintln!(
        "stalled {:?}, held by friction {:?}",
        outcome.stalled, outcome.held_by_friction
    );
    outcome
}

#[test]
fn a_strip_refitted_to_a_uniform_target_metric_takes_exactly_its_lengths() {
    // A flat film in one strip (2 m × 1 m, each triangle's frame e1 = X): the target metric
    // diag(a², b²) everywhere is compatible, so the refitted strip is the film scaled by a and b.
    let model = flat_film();
    let mut cut = cut_pattern(&model, whole(&model), Compensation::Uniform([0.0; 2])).unwrap();
    let (a, b) = (0.98, 1.03);
    let metrics = vec![Matrix2::new(a * a, 0.0, 0.0, b * b); model.triangles.len()];
    refit_strips(&model, &mut cut, &metrics, &[[2.0, 1.0]]).unwrap();
    let size = cut[0].size;
    assert!(
        (size[0] - 2.0 * a).abs() < 1e-9 && (size[1] - b).abs() < 1e-9,
        "{size:?}"
    );
    let c = cut[0].compensation;
    assert!((c[0] - (1.0 / a - 1.0)).abs() < 1e-9 && (c[1] - (1.0 / b - 1.0)).abs() < 1e-9);
    // A metric that is not positive definite is refused, naming the triangle.
    let mut bad = metrics.clone();
    bad[5] = Matrix2::new(1.0, 0.0, 0.0, -0.1);
    let error = refit_strips(&model, &mut cut, &bad, &[[2.0, 1.0]]).unwrap_err();
    assert!(error.contains("triangle 5"), "{error}");
}

/// The drum cut in four strips by planes across the hoop (x = −0.3, 0, 0.3 m).
fn across_the_hoop() -> [SeamPlane; 3] {
    [-0.3, 0.0, 0.3].map(|x| SeamPlane {
        point: [x, 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
    })
}

#[test]
fn element_wise_fixed_point_brings_an_uncompensated_cut_over_a_frictionless_drum_to_its_target() {
    // The mistake (cut to the found shape) erected over the frictionless drum carries no
    // stress; the first correction is exact to first order (module doc): one correction brings
    // every element away from the rails within 0.5 % (0.375 %). (Below about 0.2 % it stalls: a
    // frictionless support carries one hoop tension, and where the film leaves the drum the
    // node's radial contact force is not along the bisector of the film's kink there, so the
    // discrete arc and straight parts differ by 0.38 %; docs/mechanics.md.)
    let outcome = drum_element_iterations(
        0.0,
        (3, 0.005),
        Compensation::Uniform([0.0; 2]),
        &across_the_hoop(),
    );
    let h = &outcome.history;
    assert!(h[0].mean_error > 0.99, "{:?}", h[0].mean_error);
    let last = h.last().unwrap();
    assert!(
        h.len() == 2 && last.max_error.0 < 0.005,
        "{:?}",
        last.max_error
    );
    assert!(outcome.stalled.is_empty() && outcome.held_by_friction.is_empty());
    // Each strip's overall compensation is σ(1 − ν)/E = 0.114 % both ways.
    let m = film_over_drum(0.0).material;
    let expected = ISOTROPIC[0] * (1.0 - m.poisson_ratio) / m.youngs_modulus;
    for c in last.compensation.iter().flatten() {
        assert!((c - expected).abs() < 0.01 * expected, "{c} vs {expected}");
    }
}

#[test]
fn element_wise_fixed_point_over_a_drum_with_friction_stalls_and_names_the_elements_friction_holds()
{
    // With μ = 0.3 the film laid on the drum sticks at the crown's middle nodes and slides
    // against friction over the rest of the drum towards the rails: the stress there is set by
    // friction (a sticking node keeps the place it first touched, a sliding one carries μN), not
    // by the element's cut, so the corrections do not bring it down; the iteration names the
    // elements friction holds. (Counting sticking nodes only names 6 of the 16 crown elements.)
    let outcome = drum_element_iterations(0.3, (4, 0.01), Compensation::Prestress, &[]);
    let (first, last) = (&outcome.history[0], outcome.history.last().unwrap());
    assert!(last.max_error.0 > 0.1, "{:?}", last.max_error);
    assert!(last.max_error.0 > 0.9 * first.max_error.0);
    // The worst element and every element at the crown (|x| < 0.1 m) are held by friction.
    let model = film_over_drum(0.3);
    let centre = |t: usize| centre_x(&model, t);
    let held = &outcome.held_by_friction;
    assert!(held.contains(&last.max_error.1), "{held:?}");
    let crown: Vec<usize> = (0..model.triangles.len())
        .filter(|&t| centre(t).abs() < 0.1)
        .collect();
    assert!(crown.iter().all(|t| held.contains(t)), "{crown:?} {held:?}");
    // The elements on the straight parts are off the drum: stalled, but not held.
    let straight: Vec<usize> = (0..model.triangles.len())
        .filter(|&t| centre(t).abs() > 0.5 && outcome.stalled.contains(&t))
        .collect();
    assert!(!straight.is_empty() && straight.iter().all(|t| !held.contains(t)));
}

/// `examples/drum.json`: the film over the drum with μ = 0.3 (its own found shape).
fn drum_example() -> Model {
    let mut model = film_over_drum(0.3);
    model.description = "A film over a drum (r = 0.5 m, a curved support, μ = 0.3), wrapped ±60° \
        with 0.5 m tangents to two rails, 1 m wide between symmetry planes, 2 MPa isotropic: its \
        own found shape. `membrane-contact pattern drum.json --erect 4 --by-element` shows where \
        friction keeps the erected film from its prestress (issue 46)."
        .into();
    model
}

#[test]
fn by_element_erections_through_the_cli_name_the_triangles_friction_holds() {
    common::assert_example_file("drum.json", &drum_example());
    let path = format!("{}/examples/drum.json", env!("CARGO_MANIFEST_DIR"));
    let report = std::env::temp_dir().join(format!("drum-report-{}.json", std::process::id()));
    let run = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
            .args(["pattern", &path, "--erect", "3"])
            .args(extra)
            .output()
            .unwrap()
    };
    let out = run(&["--by-element", "--report", report.to_str().unwrap()]);
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(out.status.success(), "{stdout}");
    assert!(stdout.contains("held by friction on a support"), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    std::fs::remove_file(&report).ok();
    // The same erections as the library's (drum_element_iterations with μ = 0.3).
    let library = drum_element_iterations(0.3, (3, 0.01), Compensation::Prestress, &[]);
    assert_eq!(json["erections"].as_array().unwrap().len(), 3);
    let first = json["erections"][0]["max_error"].as_f64().unwrap();
    assert!(
        (first - library.history[0].max_error.0).abs() < 1e-9,
        "{first}"
    );
    let held: Vec<usize> = serde_json::from_value(json["held_by_friction"].clone()).unwrap();
    assert_eq!(held, library.held_by_friction);
    // --by-element without erections is refused.
    let refused = std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
        .args(["pattern", &path, "--by-element"])
        .output()
        .unwrap();
    let stderr = String::from_utf8(refused.stderr).unwrap();
    assert!(
        !refused.status.success() && stderr.contains("--erect"),
        "{stderr}"
    );
}

/// Distance in the xz-plane from `p` to the drum film's exact profile: the arc `r = 0.5 m` for
/// `|x| ≤ r sin 60°`, the tangent lines beyond.
fn drum_profile_distance(p: [f64; 3]) -> f64 {
    let (r, theta) = (0.5f64, 60f64.to_radians());
    let (s, c) = theta.sin_cos();
    if p[0].abs() <= r * s {
        (p[0].hypot(p[2]) - r).abs()
    } else {
        // The tangent line through (r sin θ, r cos θ) with direction (cos θ, −sin θ).
        let (dx, dz) = (p[0].abs() - r * s, p[2] - r * c);
        (dx * s + dz * c).abs()
    }
}

#[test]
fn form_finding_against_a_frictionless_drum_puts_a_lifted_film_back_on_its_profile() {
    // The film lifted 3 % off the drum (rails held where they are): the updated reference with
    // λ = 0.01, each step by the analysis with the drum frictionless, lays it back on the drum
    // and on the straight tangents (the closed-form profile), every arc node touching, and the
    // found model keeps its prestress in the analysis within 0.5 % (where the film leaves the
    // drum a uniform stress has no exact discrete equilibrium: 0.38 % between arc and tangent,
    // see the element-wise compensation).
    let model = film_over_drum(0.0);
    let held = held_dofs(&model);
    let start: Vec<[f64; 3]> = model
        .nodes
        .iter()
        .zip(&held)
        .map(|(p, h)| if h[2] { *p } else { [p[0], p[1], 1.03 * p[2]] })
        .collect();
    let off = start
        .iter()
        .map(|p| drum_profile_distance(*p))
        .fold(0.0, f64::max);
    let settings = ContactSettings {
        tolerance: 0.005,
        ..Default::default()
    };
    let start_copy = start.clone();
    let found = find_shape_with_contact(&model, start, ISOTROPIC, settings).unwrap();
    let error = found
        .nodes
        .iter()
        .map(|p| drum_profile_distance(*p))
        .fold(0.0, f64::max);
    let stress_error =
        analysis_stress_error(form_found_model(&model, found.nodes.clone(), ISOTROPIC));
    eprintln!(
        "drum form finding: lifted {off:.4} m → {error:.2e} m from the profile, {} updates, {} nodes touching; analysis of the found model: largest stress error {stress_error:.3e}",
        found.moves.len(),
        found.touching.len(),
    );
    assert!(off > 0.01 && error < 1e-5, "{error}");
    assert_eq!(found.touching.len(), 13 * 5);
    assert!(stress_error < 0.005, "{stress_error}");
    // The CLI's `form-find --on-supports` finds the same shape.
    let mut lifted = model.clone();
    lifted.nodes = start_copy;
    let dir = std::env::temp_dir();
    let (input, out) = (
        dir.join(format!("drum-lifted-{}.json", std::process::id())),
        dir.join(format!("drum-found-{}.json", std::process::id())),
    );
    std::fs::write(&input, lifted.to_json()).unwrap();
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
        .arg("form-find")
        .arg(&input)
        .args(["--on-supports", "--stress-tolerance", "0.005", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let cli = Model::from_json(&std::fs::read_to_string(&out).unwrap()).unwrap();
    for file in [&input, &out] {
        std::fs::remove_file(file).ok();
    }
    let apart = cli
        .nodes
        .iter()
        .zip(&found.nodes)
        .map(|(p, q)| (Vector3::from(*p) - Vector3::from(*q)).norm())
        .fold(0.0, f64::max);
    assert!(apart < 1e-12, "{apart}");
}

#[test]
fn an_orthotropic_target_is_found_against_a_frictionless_drum_with_its_hoop_stress_on_the_drum() {
    // CLOSED FORM: over a frictionless drum a film's section is the arc and its straight
    // tangents whatever its stresses (a string over a pulley), the axial stress is carried
    // straight between the symmetry planes, and the drum presses on the film with the hoop force
    // turned through the wrap: `Σ N = σ_hoop t w θ` (`θ = 120°`, `w = 1 m`). The target is
    // orthotropic, warp 3 MPa and fill 1 MPa; the warp along x (projected on the film: the hoop)
    // or along y (the axis) puts 3 MPa or 1 MPa round the drum. From the film lifted 3 % off the
    // drum, each is found on the profile, its analysis keeps the target in each triangle's warp
    // frame, and the drum's force is the hoop's.
    const ORTHOTROPIC: [f64; 3] = [3.0e6, 1.0e6, 0.0];
    for (axis, hoop) in [
        ([1.0, 0.0, 0.0], ORTHOTROPIC[0]),
        ([0.0, 1.0, 0.0], ORTHOTROPIC[1]),
    ] {
        let mut model = film_over_drum(0.0);
        model.frame_axis = Some(axis);
        let held = held_dofs(&model);
        let start: Vec<[f64; 3]> = (model.nodes.iter().zip(&held))
            .map(|(p, h)| if h[2] { *p } else { [p[0], p[1], 1.03 * p[2]] })
            .collect();
        let settings = ContactSettings {
            tolerance: 0.005,
            ..Default::default()
        };
        let found = find_shape_with_contact(&model, start, ORTHOTROPIC, settings).unwrap();
        let off = (found.nodes.iter())
            .map(|p| drum_profile_distance(*p))
            .fold(0.0, f64::max);
        let found_model = form_found_model(&model, found.nodes.clone(), ORTHOTROPIC);
        let (t, theta) = (found_model.material.thickness, 120f64.to_radians());
        let stress_error = analysis_stress_error(found_model.clone());
        let mut analysis = Analysis::new(found_model, SolverSettings::default()).unwrap();
        analysis.step_to(&[[0.0; 3]; 2], 1).unwrap();
        let pressed: f64 = (analysis.results().surface_contacts.iter())
            .map(|c| c.normal_force)
            .sum();
        let closed = hoop * t * 1.0 * theta;
        eprintln!(
            "orthotropic drum, warp along {axis:?}: {} updates, {off:.2e} m off the profile, {} nodes touching, stress error {stress_error:.2e}, drum force {pressed:.2} N against {closed:.2} N",
            found.moves.len(),
            found.touching.len()
        );
        assert!(off < 1e-5, "{off}");
        assert_eq!(found.touching.len(), 13 * 5);
        assert!(stress_error < 0.005, "{stress_error}");
        assert!((pressed / closed - 1.0).abs() < 0.01, "{pressed} {closed}");
    }
}

#[test]
fn the_rail_path_starts_each_rail_up_and_in_across_it_and_refuses_a_node_without_a_group() {
    // The drum's rails run along y at x = ±0.683 m: each starts 0.10 m up and 0.03 m towards
    // x = 0, whatever its node's y.
    let model = film_over_drum(0.3);
    let offsets = rail_start_offsets(&model, 0.10, 0.03);
    assert_eq!(offsets.len(), 10);
    for (v, o) in &offsets {
        let inward = -model.nodes[*v][0].signum() * 0.03;
        assert!(
            (o[0] - inward).abs() < 1e-12 && o[1].abs() < 1e-12 && (o[2] - 0.10).abs() < 1e-12,
            "{v}: {o:?}"
        );
    }
    // Erected along the path, the drum film comes to the same rails (its groups' targets).
    let cut = cut_pattern(&model, whole(&model), Compensation::Prestress).unwrap();
    let erection = erection_model(&model, reference_geometry(&model, &cut).unwrap());
    let erected = erect_along(erection.clone(), 10, &offsets).unwrap();
    assert_eq!(erected.elements.len(), model.triangles.len());
    // Node 52 (mid-film) is held by nothing, so it has no group to start from.
    let Err(error) = erect_along(erection, 10, &[(52, [0.0, 0.0, 0.1])]) else {
        panic!("a path for a node without a group was accepted");
    };
    assert!(error.contains("node 52"), "{error}");
}

#[test]
fn element_wise_iteration_stops_when_the_largest_error_grows_and_keeps_the_best_cut() {
    // A stand-in erection whose stress falls further below the target at each erection (as the
    // friction-held vault did on one path): the iteration stops at the second erection, whose
    // largest error grew, and returns the first erection's cut.
    let model = flat_film();
    let calls = std::cell::Cell::new(0);
    let mut erect = |m: Model| {
        calls.set(calls.get() + 1);
        let mut elements = erect_with_contacts(m, 2)?.elements;
        let scale = 1.0 - 0.1 * calls.get() as f64;
        elements
            .iter_mut()
            .for_each(|e| e.stress = e.stress.map(|s| s * scale));
        Ok(Erected {
            frictional: vec![false; model.nodes.len()],
            elements,
            contacts: vec![],
        })
    };
    let settings = ElementSettings {
        iterations: 5,
        tolerance: 1e-6,
        counted: away_from_rails(&model),
    };
    let start = Compensation::Prestress;
    let outcome =
        compensate_elements(&model, halves(&model), start.clone(), &settings, &mut erect).unwrap();
    let h = &outcome.history;
    assert_eq!(
        h.len(),
        2,
        "{:?}",
        h.iter().map(|h| h.max_error).collect::<Vec<_>>()
    );
    assert!(h[1].max_error.0 > h[0].max_error.0);
    let first = cut_pattern(&model, halves(&model), start).unwrap();
    assert_eq!(outcome.cut, first);
}

/// The largest difference between two erections' stresses, relative to the target prestress.
fn stress_apart(a: &Erected, b: &Erected) -> f64 {
    (a.elements.iter().zip(&b.elements))
        .flat_map(|(p, q)| (0..3).map(move |i| (p.stress[i] - q.stress[i]).abs()))
        .fold(0.0, f64::max)
        / ISOTROPIC[0]
}

/// The bay path as waypoints: up 0.10 m and in 0.03 m, then down, then out.
const DOWN_THEN_OUT: [[f64; 2]; 2] = [[0.10, 0.03], [0.0, 0.03]];

#[test]
fn a_winding_rail_path_matters_only_with_friction_and_the_compensation_along_it_reaches_the_target_or_names_what_friction_holds()
 {
    let mut apart = [0.0; 2];
    for (k, mu) in [0.0, 0.3].into_iter().enumerate() {
        let model = film_over_drum(mu);
        let cut = cut_pattern(&model, whole(&model), Compensation::Prestress).unwrap();
        let erection = erection_model(&model, reference_geometry(&model, &cut).unwrap());
        let straight = erect_along(
            erection.clone(),
            10,
            &rail_start_offsets(&model, 0.10, 0.03),
        );
        let winding = erect_through(erection, 10, &rail_waypoints(&model, &DOWN_THEN_OUT));
        apart[k] = stress_apart(&straight.unwrap(), &winding.unwrap());
    }
    eprintln!(
        "drum, winding against straight path: stresses apart by {:.2e} of the target without friction, {:.3} with μ = 0.3",
        apart[0], apart[1]
    );
    assert!(apart[0] < 1e-6 && apart[1] > 0.01, "{apart:?}");
    // The element-wise compensation along the winding path, μ = 0.3, tolerance 5 %.
    let model = film_over_drum(0.3);
    let settings = ElementSettings {
        iterations: 3,
        tolerance: 0.05,
        counted: away_from_rails(&model),
    };
    let path = rail_waypoints(&model, &DOWN_THEN_OUT);
    let mut erect = |m: Model| erect_through(m, 10, &path);
    let start = Compensation::Prestress;
    let outcome = compensate_elements(&model, whole(&model), start, &settings, &mut erect).unwrap();
    let last = outcome.history.last().unwrap();
    let above: Vec<usize> = (0..model.triangles.len())
        .filter(|&t| settings.counted[t] && last.element_errors[t] > settings.tolerance)
        .collect();
    for (k, h) in outcome.history.iter().enumerate() {
        eprintln!(
            "winding path, μ = 0.3: erection {k}: mean {:.2} %, max {:.2} % (triangle {}), {} yielded",
            100.0 * h.mean_error,
            100.0 * h.max_error.0,
            h.max_error.1,
            h.yielded
        );
    }
    eprintln!(
        "above 5 %: {above:?}; stalled {:?}; held by friction {:?}",
        outcome.stalled, outcome.held_by_friction
    );
    // Reached, or every triangle left above the tolerance is named, and friction is why.
    if !above.is_empty() {
        assert_eq!(above, outcome.stalled);
        assert!(outcome.held_by_friction.contains(&last.max_error.1));
    }
    assert!(
        outcome
            .held_by_friction
            .iter()
            .all(|t| outcome.stalled.contains(t))
    );
    // The CLI's repeated --rail-path is the same path.
    let path = format!("{}/examples/drum.json", env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::temp_dir().join(format!("winding-{}", std::process::id()));
    let (report, best) = (dir.join("report.json"), dir.join("best.json"));
    let erect = ["--erect", "3", "--by-element", "--erect-tolerance", "5"];
    let rails = ["--rail-path", "0.10,0.03", "--rail-path", "0,0.03"];
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
        .args(["pattern", &path])
        .args(erect)
        .args(rails)
        .arg("--report")
        .arg(&report)
        .arg("--erection-models")
        .arg(dir.join("models"))
        .arg("--erection-model")
        .arg(&best)
        .output()
        .unwrap();
    let json = succeeded_report(&out, &report);
    let first = json["erections"][0]["max_error"].as_f64().unwrap();
    let library = outcome.history[0].max_error.0;
    assert!((first - library).abs() < 1e-9, "{first}");
    let stalled: Vec<usize> = serde_json::from_value(json["stalled"].clone()).unwrap();
    assert_eq!(stalled, outcome.stalled);
    // --erection-models wrote each erection's model as it was erected; the one of the smallest
    // largest error is the kept cut's, which --erection-model writes.
    let read = |f: &std::path::Path| Model::from_json(&std::fs::read_to_string(f).unwrap());
    let erections = json["erections"].as_array().unwrap();
    let models = std::fs::read_dir(dir.join("models")).unwrap().count();
    assert_eq!(models, erections.len());
    let error = |k: usize| erections[k]["max_error"].as_f64().unwrap();
    let kept = (0..models).min_by(|&i, &j| error(i).total_cmp(&error(j)));
    let kept_model = read(&dir.join(format!("models/erection-{}.json", kept.unwrap())));
    assert!(kept_model.unwrap() == read(&best).unwrap());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn settling_waypoints_alternate_past_and_short_of_the_places_shrinking_by_the_ratio() {
    // After [0.10, 0.03] (down 0.10 m and out 0.03 m to the places), the rails pass their places
    // by 1 mm along that leg, come back 0.5 mm short, pass by 0.25 mm: w_k = (−1)^{k+1} a rᵏ d.
    let path = [[0.3, 0.0], [0.10, 0.03]];
    let w = settling_waypoints(&path, 1e-3, 0.5, 3).unwrap();
    assert_eq!(w[..2], path);
    let d = [0.10, 0.03].map(|c: f64| c / 0.10f64.hypot(0.03));
    for (k, a) in [-1e-3, 5e-4, -2.5e-4].into_iter().enumerate() {
        let expected = d.map(|c| a * c);
        assert!(
            (0..2).all(|c| (w[2 + k][c] - expected[c]).abs() < 1e-15),
            "{k}: {:?} against {expected:?}",
            w[2 + k]
        );
    }
    assert_eq!(w.len(), 5);
    // Refused, naming what is wrong.
    let refused = [
        (settling_waypoints(&[], 1e-3, 0.5, 3), "--rail-path"),
        (
            settling_waypoints(&[[0.0, 0.0]], 1e-3, 0.5, 3),
            "no direction",
        ),
        (settling_waypoints(&path, -1e-3, 0.5, 3), "amplitude -0.001"),
        (settling_waypoints(&path, 1e-3, 1.0, 3), "ratio 1"),
        (settling_waypoints(&path, 1e-3, 0.5, 1001), "1001 cycles"),
    ];
    for (r, says) in refused {
        let Err(e) = r else { panic!("accepted: {r:?}") };
        assert!(e.contains(says), "{e}");
    }
}

#[test]
fn settling_the_rails_ends_the_drum_film_sticking_at_its_prestress_where_the_path_alone_leaves_a_capstan_fall()
 {
    // The drum film (μ = 0.3), prestress compensation, rails down 0.10 m and out 0.03 m: every
    // contact node off the sticking ones slides and the error away from the rails is 21 %. The
    // same path then settled (1 mm past the places and back, 12 waypoints shrinking by 0.7):
    // every contact node sticks and every triangle away from the rails is within 5 %.
    let model = film_over_drum(0.3);
    let cut = cut_pattern(&model, whole(&model), Compensation::Prestress).unwrap();
    let erection = erection_model(&model, reference_geometry(&model, &cut).unwrap());
    let counted = away_from_rails(&model);
    let target = model.material.prestress[0];
    let largest = |e: &Erected| {
        (e.elements.iter().zip(&counted))
            .filter(|(_, c)| **c)
            .map(|(s, _)| {
                (s.stress[0] - target)
                    .abs()
                    .max((s.stress[1] - target).abs())
            })
            .fold(0.0, f64::max)
            / target
    };
    let path = [[0.10, 0.03]];
    let settled = settling_waypoints(&path, 1e-3, 0.7, 12).unwrap();
    let plain = erect_through(erection.clone(), 10, &rail_waypoints(&model, &path)).unwrap();
    let settled = erect_through(erection, 10, &rail_waypoints(&model, &settled)).unwrap();
    let sliding = |e: &Erected| {
        (e.contacts.iter())
            .filter(|c| c.status == GapStatus::Slip)
            .count()
    };
    let (before, after) = (largest(&plain), largest(&settled));
    eprintln!(
        "drum, μ = 0.3: largest error away from the rails {:.2} % on the path, {:.2} % settled; sliding contact nodes {} and {} of {}",
        100.0 * before,
        100.0 * after,
        sliding(&plain),
        sliding(&settled),
        settled.contacts.len()
    );
    assert!(before > 0.15 && sliding(&plain) > 0, "{before}");
    assert!(after < 0.05 && sliding(&settled) == 0, "{after}");
    // The CLI settles the same way (`--settle`), and takes waypoints below or outside the
    // rails' places as they are written (`--rail-path -0.001,-0.0003`).
    let drum = format!("{}/examples/drum.json", env!("CARGO_MANIFEST_DIR"));
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
            .args(["pattern", &drum, "--erect", "1", "--by-element"])
            .args(args)
            .output()
            .unwrap()
    };
    let out = run(&["--rail-path", "0.10,0.03", "--settle", "0.001,0.7,12"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("0 triangles yielded"), "{stdout}");
    let out = run(&["--rail-path", "0.10,0.03", "--rail-path", "-0.001,-0.0003"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run(&["--rail-path", "0.10,0.03", "--settle", "0.001,0.7,2.5"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("2.5 cycles"));
}

#[test]
fn a_cut_heavier_at_the_crown_does_not_lift_the_drum_films_crown_on_the_rail_path_alone_and_settling_does()
 {
    // Why no cut reaches an even prestress on the path alone: where the film slides, μN and
    // equilibrium fix the hoop tension from the rail's, whatever the rest lengths. The drum film
    // cut with the prestress compensation plus a field heavier at the crown (each triangle's
    // metric shrunk by 2k(1/2 − |x|/x_t) more, x_t the tangent points: the crown k/2 more than the
    // mean, the tangents k/2 less): the hoop stress at the crown against the tangents' does not
    // come closer to 1 (it falls further: more of the film slides); settled, the uniform cut's
    // is within 5 % of 1.
    let model = film_over_drum(0.3);
    let x_t = 0.5 * 60f64.to_radians().sin();
    let hoop = |e: &Erected, near: f64| {
        // Triangles whose first edge runs along the hoop (every even one), centroid at |x| ≈ near.
        let (mut s, mut n) = (0.0, 0.0);
        for (t, tri) in model.triangles.iter().enumerate().step_by(2) {
            let x = tri.iter().map(|&v| model.nodes[v][0]).sum::<f64>() / 3.0;
            if (x.abs() - near).abs() < 0.05 {
                (s, n) = (s + e.elements[t].stress[0], n + 1.0);
            }
        }
        s / n
    };
    let erect = |k: f64, path: &[[f64; 2]]| {
        let strips = whole(&model);
        let mut cut = cut_pattern(&model, strips, Compensation::Prestress).unwrap();
        let uncut: Vec<[f64; 2]> = (cut.iter())
            .map(|c| [0, 1].map(|a| c.size[a] * (1.0 + c.compensation[a])))
            .collect();
        let mut metrics = cut_metrics(&model, &cut).unwrap();
        for (t, m) in metrics.iter_mut().enumerate() {
            let x = model.triangles[t]
                .iter()
                .map(|&v| model.nodes[v][0])
                .sum::<f64>()
                / 3.0;
            *m *= 1.0 - 2.0 * k * (0.5 - x.abs().min(x_t) / x_t);
        }
        refit_strips(&model, &mut cut, &metrics, &uncut).unwrap();
        let erection = erection_model(&model, reference_geometry(&model, &cut).unwrap());
        erect_through(erection, 10, &rail_waypoints(&model, path)).unwrap()
    };
    let sliding = |e: &Erected| -> Vec<usize> {
        (e.contacts.iter())
            .filter(|c| c.status == GapStatus::Slip)
            .map(|c| c.node)
            .collect()
    };
    let alone = [[0.10, 0.03]];
    let base = erect(0.0, &alone);
    let fall = |e: &Erected| hoop(e, 0.0) / hoop(e, x_t - 0.03);
    for k in [0.001, 0.002] {
        let heavy = erect(k, &alone);
        eprintln!(
            "drum, path alone: crown hoop over the tangents' {:.4} with the prestress compensation, {:.4} with {:.2} % more at the crown; {} and {} nodes sliding",
            fall(&base),
            fall(&heavy),
            50.0 * k,
            sliding(&base).len(),
            sliding(&heavy).len()
        );
        assert!(fall(&heavy) < fall(&base) + 0.005, "{k}");
    }
    let settled = erect(0.0, &settling_waypoints(&alone, 1e-3, 0.7, 12).unwrap());
    eprintln!("settled: {:.4}", fall(&settled));
    assert!((fall(&settled) - 1.0).abs() < 0.05 && fall(&base) < 0.9);
}

/// A film 1 m × 0.5 m across a tube (radius 30 mm along y through the origin): its middle line
/// 1 mm above the tube and a contact node of it, its edges held at `x = ±0.5 m` and pulled down
/// by `drop`; prestressed so that its first iterate is defined.
fn film_across_a_tube(drop: f64) -> Model {
    let nodes: Vec<[f64; 3]> = [0.0, 0.5]
        .iter()
        .flat_map(|&y| [-0.5, 0.0, 0.5].map(|x| [x, y, 0.031]))
        .collect();
    let triangles = vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
    let mut model = film_model("FilmAcrossATube", nodes, triangles);
    model.material.prestress = ISOTROPIC;
    let edge = |name: &str, nodes: Vec<usize>| {
        let mut g = group(name, nodes);
        g.target = [0.0, 0.0, -drop];
        g
    };
    model.groups = vec![edge("west", vec![0, 3]), edge("east", vec![2, 5])];
    let tube = serde_json::json!([{ "name": "tube",
        "centreline": { "line": { "point": [0, 0, 0], "axis": [0, 1, 0] } },
        "tube_radius": 0.03, "nodes": [1, 4], "normal_stiffness": 1e7,
        "tangential_stiffness": 1e6, "friction": 0.0 }]);
    let mut value = serde_json::to_value(&model).unwrap();
    value["curved_supports"] = tube;
    Model::from_json(&value.to_string()).unwrap()
}

#[test]
fn an_erection_never_ends_with_the_film_through_a_tube_it_retries_with_more_increments_or_refuses()
{
    // Pulled 0.2 m down in one increment, the first Newton iterate carries the middle line
    // 0.2 m down, past the tube's centreline, where the two-sided tube contact pushes it on down:
    // the film would hang flat under the tube at its prestress (without the check it does). The
    // erection sees it and erects again with 2 increments, whose 0.1 m steps keep it on top.
    let model = film_across_a_tube(0.2);
    let erected = erect_through(model.clone(), 1, &[]).unwrap();
    for c in &erected.contacts {
        assert!(
            c.status != GapStatus::Open && c.normal_force > 1e3,
            "the film lies on the tube: {c:?}"
        );
    }
    // The film over the tube is stretched: sqrt(0.5² + 0.2²)/0.5 − 1 ≈ 7.7 % more than flat.
    assert!(
        erected
            .elements
            .iter()
            .all(|e| e.stress[0] > 10.0 * ISOTROPIC[0])
    );
    let nodes = |x: f64| -> Vec<[f64; 3]> {
        model
            .nodes
            .iter()
            .map(|p| [p[0], p[1], p[2] - x * (0.5 - p[0].abs())])
            .collect()
    };
    assert!(passed_through_supports(&model, &nodes(0.0)).is_empty());
    let under = passed_through_supports(&model, &nodes(0.2));
    assert_eq!(
        under,
        vec![("tube".to_string(), 1), ("tube".to_string(), 4)]
    );
    // Pulled 0.8 m in 1, 2 and 4 increments every try passes through (the film's pull on the
    // tube is more than its penalty holds at the centreline): refused, naming the nodes.
    let e = erect_through(film_across_a_tube(0.8), 1, &[]).unwrap_err();
    assert!(
        e.contains("tube at node 1") && e.contains("1 to 4 increments"),
        "{e}"
    );
}

/// The JSON report a `pattern` run wrote to `report`, the run asserted to have succeeded.
fn succeeded_report(out: &std::process::Output, report: &std::path::Path) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap()
}

/// A film 1 m wide across a tube along y: three node columns at x = −0.5, 0, 0.5 m, `n` cells
/// along y, the middle column on the tube's top (gap 1 mm, within the line's tolerance);
/// `contact` of its nodes `j` listed on the tube, at `k` per metre.
fn film_along_a_tube(n: usize, contact: std::ops::Range<usize>, k: f64) -> Model {
    let (nodes, triangles) = common::flat_grid(2, n, 1.0, 1.0);
    let nodes = nodes.iter().map(|p| [p[0] - 0.5, p[1], 0.031]).collect();
    let mut model = film_model("FilmAlongATube", nodes, triangles);
    model.material.prestress = ISOTROPIC;
    let column = |i: usize| (0..=n).map(|j| 3 * j + i).collect();
    model.groups = vec![group("west", column(0)), group("east", column(2))];
    let tube = serde_json::json!([{ "name": "tube",
        "centreline": { "line": { "point": [0, 0, 0], "axis": [0, 1, 0] } },
        "tube_radius": 0.03, "nodes": contact.map(|j| 3 * j + 1).collect::<Vec<_>>(),
        "normal_stiffness": k, "tangential_stiffness": 0.1 * k, "friction": 0.3 }]);
    let mut value = serde_json::to_value(&model).unwrap();
    value["curved_supports"] = tube;
    Model::from_json(&value.to_string()).unwrap()
}

#[test]
fn contact_stiffness_per_length_gives_a_row_the_same_line_stiffness_on_every_mesh_and_refuses_an_area()
 {
    // Contact nodes along the whole 1 m row: each takes half the spacing to each neighbour, the
    // ends one half, so the row's penalties add up to k' times its 1 m on any mesh.
    for n in [2, 5, 16] {
        let model = film_along_a_tube(n, 0..n + 1, 3.0e7);
        let k = support_stiffnesses(&model, ContactStiffness::PerLength).unwrap();
        let total = k[0].normal_stiffness * (n + 1) as f64;
        assert!((total - 3.0e7).abs() < 1e-6 * 3.0e7, "{n} cells: {total}");
        assert!((k[0].tangential_stiffness - 0.1 * k[0].normal_stiffness).abs() < 1e-6);
        assert_eq!(
            k,
            support_stiffnesses(&model, ContactStiffness::Auto).unwrap()
        );
    }
    // Without the row's end nodes on the support (an arch between rails on its tube): the ends
    // lie on its line, so every contact node takes the whole spacing.
    let model = film_along_a_tube(8, 1..8, 3.0e7);
    let l = tributary_length(&model, 0, &model.nodes).unwrap();
    assert!((l - 0.125).abs() < 1e-12, "{l}");
    // Per node: the numbers as given.
    let k = support_stiffnesses(&model, ContactStiffness::PerNode).unwrap();
    assert_eq!(
        (k[0].tributary_length, k[0].normal_stiffness),
        (None, 3.0e7)
    );
    // The drum's film touches it over an area: auto keeps its penalties per node, per-length
    // refuses it naming the support.
    let drum = film_over_drum(0.3);
    let k = support_stiffnesses(&drum, ContactStiffness::Auto).unwrap();
    assert_eq!((k[0].tributary_length, k[0].normal_stiffness), (None, 1e7));
    let e = support_stiffnesses(&drum, ContactStiffness::PerLength).unwrap_err();
    assert!(e.contains("'drum'") && e.contains("side by side"), "{e}");
}

#[test]
fn the_chosen_settling_amplitude_is_half_the_prestress_length_change_of_the_longest_strip() {
    // The flat film's halves, prestress compensation: ε = σ(1 − ν)/E biaxial, each strip a 1 m
    // square less its compensation ε, so the longest distance across it is its diagonal √2 and
    // a = ½ ε √2 (to the compensation's relative ε).
    let model = flat_film();
    let cut = cut_pattern(&model, halves(&model), Compensation::Prestress).unwrap();
    let (e, nu, s) = (
        model.material.youngs_modulus,
        model.material.poisson_ratio,
        model.material.prestress[0],
    );
    let strain = s * (1.0 - nu) / e;
    let a = settling_amplitude(&model, &cut).unwrap();
    let expected = 0.5 * strain * 2f64.sqrt();
    assert!((a / expected - 1.0).abs() < 1.5 * strain, "{a} {expected}");
    // No target prestress: nothing to size it by, and the message says what to give.
    let mut slack = model.clone();
    slack.material.prestress = [0.0; 3];
    let e = settling_amplitude(&slack, &cut).unwrap_err();
    assert!(e.contains("--settle AMPLITUDE,RATIO,CYCLES"), "{e}");
}

#[test]
fn settle_auto_chooses_and_reports_its_amplitude_and_settles_the_drum_film_to_its_prestress() {
    // `--settle auto` on the drum (μ = 0.3, rails down 0.10 m and out 0.03 m): the amplitude is
    // half the prestress's length change of the strip (reported, with the ratio 0.7 and 12
    // waypoints), and the film ends sticking everywhere within 6 % away from the rails, where
    // the path alone leaves it sliding 21 % off (the test above). The friction's answer depends
    // on the path: 5.48 % with these 10 increments an erection, 5.64 % with 40 (the path
    // followed finely; 4.64 % at 10 before hopeless increments were refused early, issue 41).
    let drum = format!("{}/examples/drum.json", env!("CARGO_MANIFEST_DIR"));
    let report = std::env::temp_dir().join(format!("drum-auto-{}.json", std::process::id()));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
        .args(["pattern", &drum, "--erect", "1", "--by-element"])
        .args(["--rail-path", "0.10,0.03", "--settle", "auto", "--report"])
        .arg(&report)
        .output()
        .unwrap();
    let json = succeeded_report(&out, &report);
    std::fs::remove_file(&report).ok();
    let stderr = String::from_utf8_lossy(&out.stderr);
    // The strip is the whole film, 1 m wide, its profile 2 × 0.5 m of tangents and 120° of a
    // 0.5 m arc long: flat, a rectangle whose diagonal is the longest distance across it.
    let model = drum_example();
    let (length, width) = (1.0 + std::f64::consts::PI / 3.0, 1.0f64);
    let m = &model.material;
    let strain = m.prestress[0] * (1.0 - m.poisson_ratio) / m.youngs_modulus;
    let expected = 0.5 * strain * length.hypot(width);
    let settle = &json["settle"];
    let amplitude = settle["amplitude"].as_f64().unwrap();
    assert!(
        (amplitude / expected - 1.0).abs() < 1.5 * strain,
        "{settle} {expected}"
    );
    assert_eq!(settle["chosen"], true);
    assert_eq!(
        (settle["ratio"].as_f64(), settle["cycles"].as_u64()),
        (Some(0.7), Some(12))
    );
    assert!(stderr.contains("settling: amplitude"), "{stderr}");
    let end = &json["erections"][0];
    assert!(
        end["max_error"].as_f64().unwrap() < 0.06,
        "{}",
        end["max_error"]
    );
    let contacts = end["contacts"].as_array().unwrap();
    let sliding = contacts.iter().filter(|c| c["status"] != "Stick").count();
    assert_eq!(
        sliding,
        0,
        "{} of {} contact nodes not sticking",
        sliding,
        contacts.len()
    );
    // The drum's contact is over an area: its penalties stay per node.
    assert_eq!(
        json["contact_stiffness"][0]["tributary_length"],
        serde_json::Value::Null
    );
}
