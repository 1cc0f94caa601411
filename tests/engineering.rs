//! Engineering output (issue 17 item 9): reactions per unit length along boundary groups and
//! support sets, and the run report.
//!
//! SOURCE: closed form of a uniformly stretched strip (total Lagrangian plane stress, uniaxial:
//! Green strain `E = (λ² − 1)/2`, second Piola–Kirchhoff stress `S = Y·E` with the lateral
//! contraction free, nominal stress `P = λ S`): the force per unit reference length along either
//! end edge is `q = P t`, at every node, the end nodes of the edge (tributary half an edge)
//! included, because the consistent nodal forces of a uniform stress are the tributary ones.
//!
//! TEST GOAL: the line reactions of the clamped edge and of the pulled edge equal `∓P t` to the
//! solver's tolerance at every node, on an uneven mesh (tributary lengths 0.05 … 0.2 m); Σ q·l
//! over a line equals the set's reaction to rounding; the CLI's CSV gives the same numbers, the
//! film VTK carries them as point data, and the report has every section with numbers that match
//! the CSV.
//!
//! MODEL: strip 2 m × 1 m in z = 0, x = 0, 0.5, 1, 2; y = 0, 0.1, 0.3, 0.4, 0.7, 1 (two triangles
//! per cell); edge x = 0: support set `clamp` (x, z; y too at (0, 0)); every other node held in z;
//! edge x = 2: group `pull` prescribed in x only, target dx = 0.02 m (λ = 1.01).
//!
//! PARAMETERS: Y = 1 GPa, ν = 0.3, t = 0.25 mm, no prestress, tolerances 1e-11.

use std::process::Command;

use membrane_contact::mech::results::lines::{LineKind, reaction_lines};
use membrane_contact::mech::{Analysis, Model, SolverSettings};

const XS: [f64; 4] = [0.0, 0.5, 1.0, 2.0];
const YS: [f64; 6] = [0.0, 0.1, 0.3, 0.4, 0.7, 1.0];
const YOUNG: f64 = 1e9;
const THICKNESS: f64 = 2.5e-4;
const STRETCH: f64 = 0.02;

fn strip_json() -> String {
    let (nx, ny) = (XS.len(), YS.len());
    let id = |i: usize, j: usize| j * nx + i;
    let nodes: Vec<[f64; 3]> = (0..ny)
        .flat_map(|j| (0..nx).map(move |i| [XS[i], YS[j], 0.0]))
        .collect();
    let mut triangles = vec![];
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    let mut supports = vec![];
    for j in 0..ny {
        for i in 0..nx - 1 {
            let v = id(i, j);
            supports.push(match (i, j) {
                (0, 0) => format!(r#"{{"node": {v}, "fixed": ["x", "y", "z"], "name": "clamp"}}"#),
                (0, _) => format!(r#"{{"node": {v}, "fixed": ["x", "z"], "name": "clamp"}}"#),
                _ => format!(r#"{{"node": {v}, "fixed": ["z"]}}"#),
            });
        }
    }
    let pulled: Vec<usize> = (0..ny).map(|j| id(nx - 1, j)).collect();
    format!(
        r#"{{"name": "Strip", "nodes": {nodes:?}, "triangles": {triangles:?},
        "material": {{"youngs_modulus": {YOUNG}, "poisson_ratio": 0.3, "thickness": {THICKNESS}}},
        "supports": [{}],
        "groups": [{{"name": "pull", "nodes": {pulled:?}, "target": [{STRETCH}, 0, 0], "components": ["x"]}}]}}"#,
        supports.join(", ")
    )
}

/// `P t` of the closed form (N/m).
fn closed_form() -> f64 {
    let lambda = 1.0 + STRETCH / XS[XS.len() - 1];
    let green = 0.5 * (lambda * lambda - 1.0);
    lambda * YOUNG * green * THICKNESS
}

fn tight() -> SolverSettings {
    SolverSettings {
        displacement_tolerance: 1e-11,
        residual_tolerance: 1e-11,
        ..SolverSettings::default()
    }
}

#[test]
fn line_reactions_of_a_stretched_strip_are_the_stress_resultant_at_every_node() {
    let model = Model::from_json(&strip_json()).unwrap();
    let mut analysis = Analysis::new(model.clone(), tight()).unwrap();
    analysis.step_to(&[[STRETCH, 0.0, 0.0]], 4).unwrap();
    let results = analysis.results();
    let (lines, notes) = reaction_lines(&model);
    assert!(notes.is_empty(), "{notes:?}");
    assert_eq!(lines.len(), 2);
    let q = closed_form();
    for line in &lines {
        let rows = line.reactions(&results);
        let (sign, total) = match line.kind {
            LineKind::Group(g) => (1.0, results.reactions[g]),
            LineKind::SupportSet(s) => (-1.0, results.support_reactions[s]),
        };
        assert_eq!(rows.len(), YS.len());
        // along y from y = 0: the chain's order, positions and tributary lengths
        let ys: Vec<f64> = rows.iter().map(|r| model.nodes[r.node][1]).collect();
        assert_eq!(ys, YS);
        assert_eq!(
            rows.iter().map(|r| r.position.unwrap()).collect::<Vec<_>>(),
            YS
        );
        let expected_tributary = [0.05, 0.15, 0.15, 0.2, 0.3, 0.15];
        for (r, l) in rows.iter().zip(expected_tributary) {
            assert!((r.tributary - l).abs() < 1e-15, "{} {l}", r.tributary);
            let [qx, qy, qz] = r.per_length;
            assert!(
                (qx - sign * q).abs() < 1e-8 * q,
                "{} node {}: qx = {qx}, closed form {}",
                line.name,
                r.node,
                sign * q
            );
            assert!(qy.abs() < 1e-8 * q && qz.abs() < 1e-8 * q, "{qy} {qz}");
        }
        // Σ q·l is the set's reaction, to rounding
        for (c, &reaction) in total.iter().enumerate() {
            let sum: f64 = rows.iter().map(|r| r.per_length[c] * r.tributary).sum();
            assert!(
                (sum - reaction).abs() <= 1e-12 * q,
                "{} component {c}: Σ q·l = {sum}, reaction {reaction}",
                line.name
            );
        }
        assert!((total[0] - sign * q * 1.0).abs() < 1e-8 * q);
    }
}

fn csv_rows(text: &str) -> Vec<Vec<String>> {
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn cli_writes_line_reactions_vtk_point_data_and_a_report_that_agree() {
    let dir = std::env::temp_dir().join(format!("engineering-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model_file = dir.join("strip.json");
    std::fs::write(&model_file, strip_json()).unwrap();
    let (csv, report, vtk) = (
        dir.join("lines.csv"),
        dir.join("report.md"),
        dir.join("vtk"),
    );
    let run = Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
        .arg("model")
        .arg(&model_file)
        .args(["--steps", "2", "--quiet", "--vtk-format", "ascii"])
        .args([
            "--displacement-tolerance",
            "1e-11",
            "--residual-tolerance",
            "1e-11",
        ])
        .arg("--line-reactions")
        .arg(&csv)
        .arg("--report")
        .arg(&report)
        .arg("--vtk")
        .arg(&vtk)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let rows = csv_rows(&std::fs::read_to_string(&csv).unwrap());
    assert_eq!(rows.len(), 2 * 2 * YS.len(), "2 steps × 2 lines × 6 nodes");
    let q = closed_form();
    let last: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == "2").collect();
    for r in &last {
        let qx: f64 = r[13].parse().unwrap();
        let sign = if r[2] == "pull" { 1.0 } else { -1.0 };
        assert!((qx - sign * q).abs() < 1e-8 * q, "{r:?}");
        assert_eq!(
            r[3],
            if r[2] == "pull" {
                "group"
            } else {
                "support_set"
            }
        );
    }
    // the film VTK of the last step: point data line_reaction at the pulled edge's nodes
    let film = std::fs::read_to_string(vtk.join("Strip_film_0002.vtu")).unwrap();
    let start = film
        .find("Name=\"line_reaction\"")
        .expect("line_reaction point data");
    let values: Vec<f64> = film[start..]
        .split_once('>')
        .unwrap()
        .1
        .split('<')
        .next()
        .unwrap()
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    for r in &last {
        let v: usize = r[4].parse().unwrap();
        let qx: f64 = r[13].parse().unwrap();
        assert!((values[3 * v] - qx).abs() <= 1e-9 * q, "node {v}");
    }
    assert_eq!(
        values[3], 0.0,
        "node 1 (0.5, 0) is on no line: no line reaction"
    );
    // the report: every section, and the CSV's numbers
    let md = std::fs::read_to_string(&report).unwrap();
    for section in [
        "# Run report: Strip",
        "## Model",
        "## Load steps",
        "## Reactions",
        "### Reaction of group `pull` (N)",
        "### Reaction of support set `clamp` (N)",
        "## Reactions per unit length (last step)",
        "### group `pull`: 6 nodes, length 1.00000 m",
        "## Stresses (last step)",
        "### Wrinkled and slack film (last step)",
        "## Slips along the supports (last step)",
        "## Warnings",
        "## Solver",
    ] {
        assert!(md.contains(section), "no '{section}' in\n{md}");
    }
    for r in &last {
        let qx: f64 = r[13].parse().unwrap();
        let row = format!("| {} | {} |", r[4], fmt_like_report(r[5].parse().unwrap()));
        let line = md
            .lines()
            .skip_while(|l| !l.contains(&format!("`{}`: 6 nodes", r[2])))
            .find(|l| l.starts_with(&row))
            .unwrap_or_else(|| panic!("no row '{row}' under {} in\n{md}", r[2]));
        let reported: f64 = line.split('|').nth(7).unwrap().trim().parse().unwrap();
        assert!((reported - qx).abs() <= 1e-5 * q, "{line} vs {qx}");
    }
    // the group's reaction in the report's last step row = Σ Rx of the CSV
    let total: f64 = last
        .iter()
        .filter(|r| r[2] == "pull")
        .map(|r| r[10].parse::<f64>().unwrap())
        .sum();
    let table = md.split("### Reaction of group `pull` (N)").nth(1).unwrap();
    let step2 = table.lines().find(|l| l.starts_with("| 2 |")).unwrap();
    let rx: f64 = step2.split('|').nth(2).unwrap().trim().parse().unwrap();
    assert!(
        (rx - total).abs() <= 1e-5 * total.abs(),
        "{step2} vs {total}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The report's number format for a coordinate (0 → "0", else six significant digits).
fn fmt_like_report(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        let decimals = (5 - x.abs().log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    }
}
