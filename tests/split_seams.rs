//! The film split along geodesic seams that cross its triangles, and seams from several start
//! lines (issue 46's gaps).
//!
//! MESH (slanted half cylinder): radius 1 m, 12 columns of nodes on generators at azimuths
//! `φ_i = π i / 12`, 8 rows; node `(i, j)` at height `y = s u_i (1 − j/8) + 2 j/8` with
//! `u_i = i c` its developed abscissa (`c` the hoop chord) and `s = 0.5`. Every triangle has its
//! corners on two neighbouring generators, so it lies in their plane: the triangulated surface
//! is developable (each cell is planar), whatever the heights. The bottom row is a helix (a
//! straight line of slope `s` in the development), the top row a circle.
//!
//! CLOSED FORM: on a developable surface the geodesics are the straight lines of its
//! development. The seams from the bottom row at width `w` are the lines parallel to it at
//! distances `w, 2w, …`: helices at `atan 0.5 = 26.6°` to the hoop, which cut the triangles
//! across (they run along no edge). Each strip between them is a plane region of the
//! development, so it flattens with no strain. The seams from the first column (a generator) at
//! width `w2` are the generators at `u = w2, 2 w2, …` while the transverse geodesic from its
//! middle (`y = 1`, horizontal in the development) stays in the film, which it leaves through the
//! bottom helix at `u = 2`: with `w2 = 0.7` two of them, which cross the four helices 4 and 3
//! times (the helix `k` reaches the top `y = 2` at `u = 2 (2 − 0.3354 k)`). Segments that end on
//! the rim divide a disc into `1 + segments + crossings` regions: `1 + 6 + 7 = 14` strips.
//!
//! TEST GOAL: the film split along the seams has the original area to round-off (1e-12), every
//! piece of a triangle lies in its plane, every strip's outline edge inside the film lies on a
//! seam (1e-12 of the film's size; with the crossings near an edge's end moved to that end,
//! within `SNAP` of the longest edge), the strips flatten with no strain (1e-9); seams from two
//! start lines (the bottom row and the first column) cross inside the film and split it into the
//! 14 strips of both families, each flat with no strain, also through the CLI.
//!
//! PARAMETERS: strip widths 0.3 m and 0.7 m (not multiples of the mesh's spacings).

mod common;

use std::collections::HashMap;

use common::film_model;
use membrane_contact::mech::elements::triangle::MembraneTriangle;
use membrane_contact::mech::model::{BoundaryGroup, Model};
use membrane_contact::mech::patterning::Strip;
use membrane_contact::mech::patterning::cut::{Compensation, cut_pattern};
use membrane_contact::mech::patterning::geodesic::{GeodesicPoint, geodesic_seams};
use membrane_contact::mech::patterning::outline::boundary_edges;
use membrane_contact::mech::patterning::split::{SNAP, SplitFilm, split_along};
use nalgebra::Vector3;

const NU: usize = 12;
const NV: usize = 8;
const WIDTH: f64 = 0.3;

fn id(i: usize, j: usize) -> usize {
    j * (NU + 1) + i
}

fn slanted_half_cylinder() -> Model {
    let chord = 2.0 * (std::f64::consts::PI / (2.0 * NU as f64)).sin();
    let mut nodes = vec![];
    for j in 0..=NV {
        for i in 0..=NU {
            let phi = std::f64::consts::PI * i as f64 / NU as f64;
            let v = j as f64 / NV as f64;
            let y = 0.5 * chord * i as f64 * (1.0 - v) + 2.0 * v;
            nodes.push([phi.cos(), y, phi.sin()]);
        }
    }
    let mut triangles = vec![];
    for j in 0..NV {
        for i in 0..NU {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mut model = film_model("SlantedCylinder", nodes, triangles);
    let rim = (0..=NV).flat_map(|j| (0..=NU).map(move |i| (i, j)));
    model.groups = vec![BoundaryGroup {
        name: "rim".into(),
        nodes: (rim.filter(|&(i, j)| i % NU == 0 || j % NV == 0))
            .map(|(i, j)| id(i, j))
            .collect(),
        target: [0.0; 3],
        components: None,
        hinge: None,
    }];
    model
}

fn longest_edge(model: &Model) -> f64 {
    let x = |v: usize| Vector3::from(model.nodes[v]);
    (model.triangles.iter())
        .flat_map(|t| (0..3).map(move |k| (x(t[k]) - x(t[(k + 1) % 3])).norm()))
        .fold(0.0, f64::max)
}

fn area(model: &Model, t: usize) -> f64 {
    MembraneTriangle::new(model.triangles[t].map(|v| Vector3::from(model.nodes[v])))
        .unwrap()
        .area()
}

/// The distance from `p` to the nearest segment of any of the `seams`.
fn off_seams(seams: &[Vec<GeodesicPoint>], p: [f64; 3]) -> f64 {
    let p = Vector3::from(p);
    let segments = seams.iter().flat_map(|s| s.windows(2));
    segments
        .map(|w| {
            let (a, b) = (Vector3::from(w[0].point), Vector3::from(w[1].point));
            let e = b - a;
            let f = if e.norm() > 0.0 {
                ((p - a).dot(&e) / e.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (a + e * f - p).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The largest distance from a seam of the nodes of every strip's outline edges that lie inside
/// the film (an edge of two triangles of the film), and how many such edges there are.
fn outline_off_seams(
    model: &Model,
    strips: &[Vec<usize>],
    seams: &[Vec<GeodesicPoint>],
) -> (f64, usize) {
    let mut count: HashMap<[usize; 2], usize> = HashMap::new();
    for tri in &model.triangles {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *count.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    let (mut worst, mut edges) = (0.0f64, 0);
    for triangles in strips {
        let strip = Strip::new(model, triangles.clone());
        for [a, b] in boundary_edges(model, &strip) {
            let [a, b] = [strip.nodes[a], strip.nodes[b]];
            if count[&[a.min(b), a.max(b)]] == 2 {
                edges += 1;
                for v in [a, b] {
                    worst = worst.max(off_seams(seams, model.nodes[v]));
                }
            }
        }
    }
    (worst, edges)
}

/// The split's area and its largest piece's distance from its parent triangle's plane.
fn split_area_and_flatness(original: &Model, split: &SplitFilm) -> (f64, f64) {
    let total = (0..split.model.triangles.len())
        .map(|t| area(&split.model, t))
        .sum::<f64>();
    let mut off = 0.0f64;
    for (t, &p) in split.parent.iter().enumerate() {
        let [a, b, c] = original.triangles[p].map(|v| Vector3::from(original.nodes[v]));
        let n = (b - a).cross(&(c - a)).normalize();
        for v in split.model.triangles[t] {
            off = off.max((Vector3::from(split.model.nodes[v]) - a).dot(&n).abs());
        }
    }
    (total, off)
}

#[test]
fn a_film_split_along_slanted_geodesic_seams_keeps_its_area_and_its_strips_outlines_lie_on_the_seams()
 {
    let model = slanted_half_cylinder();
    let bottom: Vec<usize> = (0..=NU).map(|i| id(i, 0)).collect();
    let seams = geodesic_seams(&model, &bottom, WIDTH).unwrap();
    let split = split_along(&model, &seams.seams, 0.0).unwrap();
    split.model.validate().unwrap();
    // The seams' ends on the rim are new nodes of the rim group.
    let rim = &split.model.groups[0].nodes;
    assert_eq!(rim.len() - model.groups[0].nodes.len(), 2 * 4, "{rim:?}");
    let original: f64 = (0..model.triangles.len()).map(|t| area(&model, t)).sum();
    let (total, off_plane) = split_area_and_flatness(&model, &split);
    let (outline_off, outline_edges) = outline_off_seams(&split.model, &split.strips, &seams.seams);
    // The whole triangles along each seam (the strips without the split) stray from it.
    let (whole_off, _) = outline_off_seams(&model, &seams.strips, &seams.seams);
    eprintln!(
        "slanted cylinder: {} seams, {} nodes and {} triangles added, area {total:.15} m² vs {original:.15} m² (relative {:.1e}), pieces off their plane {off_plane:.1e} m; {outline_edges} outline edges inside the film, largest distance from a seam {outline_off:.1e} m (whole triangles: {whole_off:.3} m)",
        seams.seams.len(),
        split.model.nodes.len() - model.nodes.len(),
        split.model.triangles.len() - model.triangles.len(),
        (total - original).abs() / original,
    );
    assert_eq!(seams.seams.len(), 4);
    assert!(split.model.nodes.len() > model.nodes.len());
    assert!(
        (total - original).abs() < 1e-12 * original,
        "{total} {original}"
    );
    assert!(off_plane < 1e-12, "{off_plane}");
    assert!(outline_edges > 0);
    assert!(outline_off < 1e-12 * 2.0, "{outline_off}");
    assert!(whole_off > 0.01, "{whole_off}");
    assert_eq!(split.strips.len(), 5);
    let mut every: Vec<usize> = split.strips.concat();
    every.sort_unstable();
    assert_eq!(every, (0..split.model.triangles.len()).collect::<Vec<_>>());
    let cut = cut_pattern(
        &split.model,
        split.strips.clone(),
        Compensation::Uniform([0.0; 2]),
    )
    .unwrap();
    for (k, c) in cut.iter().enumerate() {
        eprintln!(
            "strip {k}: {} triangles, size {:?}, max strain {:.2e}",
            c.strip.triangles.len(),
            c.size,
            c.distortion.max_strain
        );
        assert!(c.distortion.max_strain < 1e-9, "{k}: {:?}", c.distortion);
    }
    // Crossings within SNAP of an edge's end go through that end: the outline stays within
    // SNAP of the longest edge, the area exact.
    let snapped = split_along(&model, &seams.seams, SNAP).unwrap();
    let (snapped_off, _) = outline_off_seams(&snapped.model, &snapped.strips, &seams.seams);
    let (snapped_area, _) = split_area_and_flatness(&model, &snapped);
    eprintln!(
        "snapped within {SNAP} of the edges' ends: {} nodes added, outline off the seams {snapped_off:.2e} m",
        snapped.model.nodes.len() - model.nodes.len()
    );
    assert!(snapped_off < SNAP * longest_edge(&model), "{snapped_off}");
    assert!((snapped_area - original).abs() < 1e-12 * original);
}

#[test]
fn seams_from_two_start_lines_cross_and_split_the_film_into_the_strips_of_both_families() {
    let model = slanted_half_cylinder();
    let bottom: Vec<usize> = (0..=NU).map(|i| id(i, 0)).collect();
    let column: Vec<usize> = (0..=NV).map(|j| id(0, j)).collect();
    let helices = geodesic_seams(&model, &bottom, WIDTH).unwrap().seams;
    let generators = geodesic_seams(&model, &column, 0.7).unwrap().seams;
    assert_eq!((helices.len(), generators.len()), (4, 2));
    let both = [helices, generators].concat();
    let split = split_along(&model, &both, SNAP).unwrap();
    split.model.validate().unwrap();
    let original: f64 = (0..model.triangles.len()).map(|t| area(&model, t)).sum();
    let (total, _) = split_area_and_flatness(&model, &split);
    let (outline_off, _) = outline_off_seams(&split.model, &split.strips, &both);
    let cut = cut_pattern(
        &split.model,
        split.strips.clone(),
        Compensation::Uniform([0.0; 2]),
    );
    let strains: Vec<f64> = (cut.unwrap().iter())
        .map(|c| c.distortion.max_strain)
        .collect();
    eprintln!(
        "two start lines: {} strips, {} nodes added, area relative error {:.1e}, outline off the seams {outline_off:.1e} m, largest strain {:.1e}",
        split.strips.len(),
        split.model.nodes.len() - model.nodes.len(),
        (total - original).abs() / original,
        strains.iter().fold(0.0f64, |m, &s| m.max(s))
    );
    assert_eq!(split.strips.len(), 14);
    assert!((total - original).abs() < 1e-12 * original);
    assert!(outline_off < SNAP * longest_edge(&model), "{outline_off}");
    assert!(strains.iter().all(|&s| s < 1e-9), "{strains:?}");
    // The CLI takes --geodesic-from twice and prints a line per strip.
    let file = std::env::temp_dir().join(format!("two-lines-{}.json", std::process::id()));
    std::fs::write(&file, model.to_json()).unwrap();
    let list = |l: &[usize]| {
        l.iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(",")
    };
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
        .arg("pattern")
        .arg(&file)
        .args(["--geodesic-from", &list(&bottom), "--strip-width", "0.3"])
        .args(["--geodesic-from", &list(&column), "--strip-width", "0.7"])
        .args(["--compensation", "0"])
        .output()
        .unwrap();
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert!(output.status.success(), "{stderr}");
    assert!(stderr.contains("geodesic seams: 4 seams"), "{stderr}");
    let stdout = String::from_utf8(output.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 14, "{stdout}");
    // Three widths for two lines are refused.
    let refused = std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
        .arg("pattern")
        .arg(&file)
        .args([
            "--geodesic-from",
            &list(&bottom),
            "--geodesic-from",
            &list(&column),
        ])
        .args([
            "--strip-width",
            "0.3",
            "--strip-width",
            "0.7",
            "--strip-width",
            "0.5",
        ])
        .output()
        .unwrap();
    let message = String::from_utf8(refused.stderr).unwrap();
    assert!(
        !refused.status.success() && message.contains("2 lines, 3 widths"),
        "{message}"
    );
    std::fs::remove_file(&file).ok();
}
