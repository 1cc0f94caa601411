//! Orthotropic target prestress in form finding and geodesic seams (issue 46's gaps).
//!
//! SOURCES: Bletzinger & Ramm, Int. J. Space Struct. 14 (1999) (updated reference strategy, eq.
//! 12 at `λ = 0`); the membrane's normal equilibrium `σ1 κ1 + σ2 κ2 + 2τ κ12 = 0` (no load).
//!
//! CLOSED FORM (orthotropic saddle). A film under a uniform warp stress `σ1` along a direction
//! `w` in the xy-plane and fill `σ2` across it, over a square, with its rim on
//! `z = h (σ2 u² − σ1 v²)`, `u = w·p`, `v = (ẑ × w)·p`. For a shallow surface the curvatures
//! along `w` and across are `z_uu` and `z_vv`, so the normal equilibrium reads
//! `σ1 z_uu + σ2 z_vv = σ1 (2hσ2) + σ2 (−2hσ1) = 0`: the saddle is in equilibrium, and the
//! tangential equilibrium holds because the stress is uniform in a (nearly) constant frame. The
//! slopes neglected are `O(|∇z|²)`: with `h` such that `|∇z| ≤ 0.05` they move `z` by well
//! under 0.5 % of the rim's height. On a uniform mesh the linear triangles' stencil (centrally
//! symmetric, consistent) is exact on quadratics, so the mesh adds nothing. The isotropic
//! target on the same rim gives a different surface (the harmonic extension of the rim), which
//! the test shows is more than 10 % of the rim's height away: the closed form tells the two apart.
//!
//! WHY NOT AN ORTHOTROPIC CATENOID: on a surface of revolution with meridional `σ1` and hoop
//! `σ2`, both uniform, the meridional equilibrium `d(r σ1)/ds − σ2 dr/ds = (σ1 − σ2) dr/ds = 0`
//! fails wherever the radius changes, unless `σ1 = σ2`: no such surface exists between two rings
//! (docs/mechanics.md, "Orthotropic targets").
//!
//! TEST GOAL: the orthotropic saddle is found from a flat start within 0.5 % of the rim's
//! height of the closed form, with the warp at 30° to X (the model's `frame_axis`); the found
//! model keeps its prestress within 1e-3 in the project's own analysis (which reads the same
//! frame axis); a frame axis normal to a triangle is refused naming the triangle. Against
//! supports (`λ > 0`): the same closed form with the warp along x and the edges `y = ±1` on
//! frictionless tubes along the rim's parabolas is found from half its height.
//!
//! MESH: the square `|x|, |y| ≤ 1 m`, 16 × 16 cells, every diagonal the same way (uniform); the
//! rim (one group, all components held) on the closed form, the inside flat.
//!
//! PARAMETERS: ETFE film of the specimen (t = 0.2 mm); warp 3 MPa, fill 1 MPa, no shear.

mod common;

use common::{analysis_stress_error, film_model, flat_grid, surface_grid};
use membrane_contact::mech::formfinding::contact::{ContactSettings, find_shape_with_contact};
use membrane_contact::mech::formfinding::form_found_model;
use membrane_contact::mech::formfinding::update_reference::{UpdateSettings, find_shape};
use membrane_contact::mech::model::{BoundaryGroup, Model};

const WARP: [f64; 3] = [3.0e6, 1.0e6, 0.0];

/// The warp direction: 30° from X in the xy-plane.
fn warp_axis() -> [f64; 3] {
    let a = 30f64.to_radians();
    [a.cos(), a.sin(), 0.0]
}

/// The closed form `z = h (σ2 u² − σ1 v²)` (module doc) at `p`.
fn saddle(p: [f64; 3], h: f64, stress: [f64; 3]) -> f64 {
    let w = warp_axis();
    let u = w[0] * p[0] + w[1] * p[1];
    let v = -w[1] * p[0] + w[0] * p[1];
    h * (stress[1] * u * u - stress[0] * v * v)
}

/// The square `|x|, |y| ≤ 1`, `n × n` uniform cells, rim on the saddle, inside flat, the frame
/// along the warp.
fn saddle_square(n: usize, h: f64) -> Model {
    let (mut nodes, triangles) = flat_grid(n, n, 2.0, 2.0);
    let mut rim = vec![];
    for (k, p) in nodes.iter_mut().enumerate() {
        let (i, j) = (k % (n + 1), k / (n + 1));
        p[0] -= 1.0;
        p[1] -= 1.0;
        if i == 0 || j == 0 || i == n || j == n {
            p[2] = saddle(*p, h, WARP);
            rim.push(k);
        }
    }
    rim_held(film_model("Saddle", nodes, triangles), rim, warp_axis())
}

/// `model` with its `rim` nodes held in place (group `rim`) and its frame along `axis`.
fn rim_held(mut model: Model, rim: Vec<usize>, axis: [f64; 3]) -> Model {
    model.groups = vec![BoundaryGroup {
        name: "rim".into(),
        nodes: rim,
        target: [0.0; 3],
        components: None,
        hinge: None,
    }];
    model.frame_axis = Some(axis);
    model
}

/// Largest `|z − z_closed|` of `nodes` over the rim's largest `|z|`.
fn saddle_error(model: &Model, nodes: &[[f64; 3]], h: f64) -> f64 {
    let z_max = model.nodes.iter().map(|p| p[2].abs()).fold(0.0, f64::max);
    let error = nodes
        .iter()
        .map(|p| (p[2] - saddle(*p, h, WARP)).abs())
        .fold(0.0, f64::max);
    error / z_max
}

#[test]
fn orthotropic_saddle_is_found_within_half_a_percent_of_its_closed_form_along_a_turned_warp() {
    // |∇z| ≤ 2h·σ1·|v| ≤ 2h·3e6·√2: h = 5e-9 keeps it below 0.05.
    let h = 5.0e-9;
    let model = saddle_square(16, h);
    // The default tolerance (1e-4 of t·|σ|·L̄): the out-of-balance stalls near 2e-5 here, at
    // O(|∇z|²) (halving h takes it to 5.6e-6), as no exact orthotropic equilibrium exists on a
    // curved surface with the warp's frame (docs/mechanics.md, "Orthotropic targets").
    let settings = UpdateSettings::default();
    let found = find_shape(&model, model.nodes.clone(), WARP, settings).unwrap();
    let error = saddle_error(&model, &found.nodes, h);
    let isotropic = [2.0e6, 2.0e6, 0.0];
    let iso = find_shape(&model, model.nodes.clone(), isotropic, settings).unwrap();
    let iso_error = saddle_error(&model, &iso.nodes, h);
    let stress_error = analysis_stress_error(form_found_model(&model, found.nodes, WARP));
    eprintln!(
        "orthotropic saddle: max |z − z_closed| {:.4} % of the rim (isotropic target: {:.2} %), {} updates; stress after analysis {stress_error:.2e}",
        100.0 * error,
        100.0 * iso_error,
        found.steps
    );
    assert!(error < 0.005, "{error}");
    assert!(iso_error > 0.1, "{iso_error}");
    assert!(stress_error < 1e-3, "{stress_error}");
}

#[test]
fn a_frame_axis_normal_to_a_triangle_is_refused_naming_it() {
    let mut model = saddle_square(2, 0.0);
    model.frame_axis = Some([0.0, 0.0, 1.0]);
    let err = model.validate().unwrap_err().to_string();
    assert!(
        err.contains("frame_axis") && err.contains("triangle 0"),
        "{err}"
    );
    let found = find_shape(&model, model.nodes.clone(), WARP, UpdateSettings::default());
    let err = found.unwrap_err().to_string();
    assert!(err.contains("triangle 0's normal"), "{err}");
    model.frame_axis = Some([0.0; 3]);
    let err = model.validate().unwrap_err().to_string();
    assert!(err.contains("not a direction"), "{err}");
}

/// The saddle with the warp along x on tubes: the square `|x|, |y| ≤ 1` (`n × n` cells) on
/// `z = h (σ2 x² − σ1 y²)`, the edges `x = ±1` held, the edges `y = ±1` (corners excepted) on
/// frictionless tubes of radius `r` that touch them from inside the square: each centreline is
/// the edge's parabola moved by `r` against the film's outward direction there,
/// `(0, ±1, z_y)/√(1 + z_y²)` with `z_y = ∓2hσ1` (to `O(r z_x z_y)`).
fn saddle_on_tubes(n: usize, h: f64, r: f64) -> Model {
    let closed = |x: f64, y: f64| h * (WARP[1] * x * x - WARP[0] * y * y);
    let (mut nodes, triangles) = flat_grid(n, n, 2.0, 2.0);
    let (mut rim, mut sides) = (vec![], [vec![], vec![]]);
    for (k, p) in nodes.iter_mut().enumerate() {
        let (i, j) = (k % (n + 1), k / (n + 1));
        p[0] -= 1.0;
        p[1] -= 1.0;
        p[2] = closed(p[0], p[1]);
        if i == 0 || i == n {
            rim.push(k);
        } else if j == 0 || j == n {
            sides[usize::from(j == n)].push(k);
        }
    }
    let model = rim_held(
        film_model("SaddleOnTubes", nodes, triangles),
        rim,
        [1.0, 0.0, 0.0],
    );
    let slope = 2.0 * h * WARP[0];
    let c = 1.0 / slope.hypot(1.0);
    // `apex + s along − (H/L²) s² up` with `up = −z`: `z = z_apex + (H/L²) s²`, `H/L² = h σ2`.
    let tube = |name: &str, y: f64, nodes: &Vec<usize>| {
        let apex = [0.0, y * (1.0 - r * c), closed(0.0, 1.0) + slope * r * c];
        serde_json::json!({ "name": name, "nodes": nodes, "tube_radius": r,
            "centreline": { "parabola": { "apex": apex, "up": [0, 0, -1], "along": [1, 0, 0],
                "half_span": 1.5, "rise": h * WARP[1] * 2.25 } },
            "normal_stiffness": 1e7, "tangential_stiffness": 1e6, "friction": 0.0 })
    };
    let mut value = serde_json::to_value(&model).unwrap();
    value["curved_supports"] = serde_json::json!([
        tube("south", -1.0, &sides[0]),
        tube("north", 1.0, &sides[1])
    ]);
    Model::from_json(&value.to_string()).unwrap()
}

#[test]
fn orthotropic_saddle_is_found_against_frictionless_tubes_along_two_of_its_edges() {
    // The closed form with the warp along x (3 MPa) and the fill along y (1 MPa): the edges
    // y = ±1 lie on frictionless tubes along the rim's parabolas, which hold them across (the
    // fill's pull) but not along (no shear there). From the inside at half the saddle's height,
    // the updated reference with λ = 0.01 against the tubes (`find_shape_with_contact`) finds
    // the saddle within 0.5 % of the rim's height, both tubes touched along their edges, and the
    // analysis of the found model keeps the target. (From a flat inside the first steps move the
    // edges round the tubes and the steps diverge: a start near the shape is needed, as over the
    // drum.)
    let (n, h, r) = (16, 5.0e-9, 1.0e-2);
    let model = saddle_on_tubes(n, h, r);
    let closed = |p: &[f64; 3]| h * (WARP[1] * p[0] * p[0] - WARP[0] * p[1] * p[1]);
    let off = |nodes: &[[f64; 3]]| {
        let worst = nodes.iter().map(|p| (p[2] - closed(p)).abs());
        worst.fold(0.0, f64::max) / (h * WARP[0])
    };
    let start: Vec<[f64; 3]> = (model.nodes.iter().enumerate())
        .map(|(k, p)| {
            let (i, j) = (k % (n + 1), k / (n + 1));
            let inside = i > 0 && i < n && j > 0 && j < n;
            [p[0], p[1], if inside { 0.5 * p[2] } else { p[2] }]
        })
        .collect();
    let found =
        find_shape_with_contact(&model, start.clone(), WARP, ContactSettings::default()).unwrap();
    let stress_error = analysis_stress_error(form_found_model(&model, found.nodes.clone(), WARP));
    eprintln!(
        "orthotropic saddle on tubes: start {:.2} % of the rim off the closed form, found {:.4} % in {} updates, {} nodes touching; stress after analysis {stress_error:.2e}",
        100.0 * off(&start),
        100.0 * off(&found.nodes),
        found.moves.len(),
        found.touching.len()
    );
    assert!(off(&start) > 0.1);
    assert!(off(&found.nodes) < 0.005, "{}", off(&found.nodes));
    assert_eq!(found.touching.len(), 2 * (n - 1));
    assert!(stress_error < 1e-3, "{stress_error}");
}

/// `examples/orthotropic_saddle.json`: the saddle's rim over a flat square, 16 × 16 cells, the
/// warp target 3/1 MPa, no frame axis (the CLI's `--warp` gives it).
fn saddle_example() -> Model {
    let mut model = saddle_square(16, 5.0e-9);
    model.frame_axis = None;
    model.material.prestress = WARP;
    model.description = "A flat film whose rim lies on the saddle z = h(σ2 u² − σ1 v²), u along \
        the warp at 30° to X: `membrane-contact form-find --warp 0.8660254,0.5,0 --prestress 3,1` \
        finds the saddle (issue 46)."
        .into();
    model
}

#[test]
fn form_find_with_a_warp_through_the_cli_writes_the_frame_axis_and_finds_the_saddle() {
    common::assert_example_file("orthotropic_saddle.json", &saddle_example());
    let path = format!(
        "{}/examples/orthotropic_saddle.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let run = |warp: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
            .args(["form-find", &path, "--prestress", "3,1", "--warp", warp])
            .output()
            .unwrap()
    };
    let output = run("0.8660254,0.5,0");
    assert!(output.status.success(), "{output:?}");
    let found = Model::from_json(std::str::from_utf8(&output.stdout).unwrap()).unwrap();
    assert_eq!(found.frame_axis, Some([0.8660254, 0.5, 0.0]));
    assert_eq!(found.material.prestress, WARP);
    let error = saddle_error(&found, &found.nodes, 5.0e-9);
    assert!(error < 0.005, "{error}");
    let refused = run("0,0,1");
    let message = String::from_utf8(refused.stderr).unwrap();
    assert!(
        !refused.status.success()
            && message.contains("--warp: frame_axis")
            && message.contains("triangle 0"),
        "{message}"
    );
}

// ---------------------------------------------------------------------------------------------
// Geodesic seams.
//
// SOURCES: Polthier & Schmies, "Straightest geodesics on polyhedral surfaces" (1998): inside a
// triangle straight, across an edge unfolded, through a vertex of total angle Θ with Θ/2 on
// each side.
//
// CLOSED FORMS: on a cylinder (developable) the geodesics perpendicular to the hoop through a
// hoop geodesic are the generators, and the arc length along the (polygonal) hoop from the
// start generator is the seam spacing; a strip between generators is a developable strip that
// flattens with no strain to `L × w`. On a sphere the seams are the meridians (within mesh
// accuracy) and the strips are doubly curved: they report a strain, smaller for narrower strips.
//
// MESHES: half cylinder `r = 1 m`, axis along y, 2 m long: 24 cells around × 8 along; a
// sphere patch `r = 1 m`, polar angle 30°–150°, 60° of azimuth, 12 × 12 cells. Start line: the
// generator (meridian) at azimuth 0, a boundary line.

use membrane_contact::mech::patterning::cut::{Compensation, cut_pattern};
use membrane_contact::mech::patterning::geodesic::{
    GeodesicPoint, GeodesicSeams, Surface, geodesic_seams,
};

fn half_cylinder() -> Model {
    surface_grid(24, 8, |u, v| {
        let phi = std::f64::consts::PI * u;
        [phi.cos(), 2.0 * v, phi.sin()]
    })
}

/// The start line: the column `i = 0` of a `nu × nv` grid.
fn first_column(nu: usize, nv: usize) -> Vec<usize> {
    (0..=nv).map(|j| j * (nu + 1)).collect()
}

/// The hoop chord of the half cylinder's 24 cells.
fn chord() -> f64 {
    2.0 * (std::f64::consts::PI / 48.0).sin()
}

/// The point of the polygonal hoop (24 chords from azimuth 0) at arc length `s`, as an azimuth.
fn hoop_azimuth(s: f64) -> f64 {
    let step = std::f64::consts::PI / 24.0;
    let (k, f) = ((s / chord()).floor(), (s / chord()).fract());
    let (a, b) = (k * step, (k + 1.0) * step);
    let p = [
        a.cos() * (1.0 - f) + b.cos() * f,
        a.sin() * (1.0 - f) + b.sin() * f,
    ];
    p[1].atan2(p[0])
}

/// Largest azimuth deviation of each seam from `hoop_azimuth(first + k w)` (seam `k`), and each
/// seam's y range.
fn seam_errors(seams: &GeodesicSeams, first: f64, width: f64) -> (f64, Vec<[f64; 2]>) {
    let mut worst: f64 = 0.0;
    let mut spans = vec![];
    for (k, seam) in seams.seams.iter().enumerate() {
        let expected = hoop_azimuth(first + k as f64 * width);
        for g in seam {
            worst = worst.max((g.point[2].atan2(g.point[0]) - expected).abs());
        }
        let ys = seam.iter().map(|g| g.point[1]);
        spans.push([
            ys.clone().fold(f64::MAX, f64::min),
            ys.fold(f64::MIN, f64::max),
        ]);
    }
    (worst, spans)
}

#[test]
fn geodesic_seams_on_a_cylinder_are_generators_spaced_by_the_width_along_the_hoop() {
    let model = half_cylinder();
    for cells in [4.0, 2.5] {
        let width = cells * chord();
        let seams = geodesic_seams(&model, &first_column(24, 8), width).unwrap();
        let (worst, spans) = seam_errors(&seams, width, width);
        eprintln!(
            "cylinder, width {cells} chords: {} seams, largest azimuth error {worst:.2e} rad, y spans {spans:?}",
            seams.seams.len()
        );
        assert_eq!(seams.seams.len(), (24.0 / cells - 1e-9).floor() as usize);
        assert!(worst < 1e-9, "{worst}");
        for span in spans {
            assert!(
                span[0].abs() < 1e-9 && (span[1] - 2.0).abs() < 1e-9,
                "{span:?}"
            );
        }
    }
}

#[test]
fn strips_between_geodesic_seams_of_a_cylinder_flatten_to_length_by_width_with_no_strain() {
    let model = half_cylinder();
    let width = 4.0 * chord();
    let seams = geodesic_seams(&model, &first_column(24, 8), width).unwrap();
    assert_eq!(seams.strips.len(), 6);
    let cut = cut_pattern(&model, seams.strips, Compensation::Uniform([0.0; 2])).unwrap();
    for (k, strip) in cut.iter().enumerate() {
        eprintln!(
            "strip {k}: {} triangles, size {:?}, max strain {:.2e}",
            strip.strip.triangles.len(),
            strip.size,
            strip.distortion.max_strain
        );
        assert_eq!(strip.strip.triangles.len(), 64);
        assert!(strip.distortion.max_strain < 1e-9, "{:?}", strip.distortion);
        assert!((strip.size[0] - 2.0).abs() < 1e-9, "{:?}", strip.size);
        assert!((strip.size[1] - width).abs() < 1e-9, "{:?}", strip.size);
    }
}

/// The start line: the column `i` of a `nu × nv` grid.
fn column_of(i: usize, nu: usize, nv: usize) -> Vec<usize> {
    (0..=nv).map(|j| j * (nu + 1) + i).collect()
}

#[test]
fn geodesic_seams_from_a_generator_inside_a_cylinder_are_generators_on_both_sides_of_it() {
    // The start line is the generator at azimuth 90° (column 12 of 24), from one rim to the
    // other: the transverse geodesic is the polygonal hoop from it both ways, the seams the
    // generators at arc lengths 12 chords ± k W along it, the line itself one of them.
    let model = half_cylinder();
    for (cells, count, start) in [(4.0, 5, 2), (2.5, 9, 4)] {
        let width = cells * chord();
        let seams = geodesic_seams(&model, &column_of(12, 24, 8), width).unwrap();
        let first = 12.0 * chord() - start as f64 * width;
        let (worst, spans) = seam_errors(&seams, first, width);
        let total = seams.transverse.last().unwrap().length;
        eprintln!(
            "cylinder from the middle, width {cells} chords: {} seams (start line {:?}), origin {:.6} of {total:.6} m, largest azimuth error {worst:.2e} rad",
            seams.seams.len(),
            seams.start_seam,
            seams.origin
        );
        assert_eq!((seams.seams.len(), seams.start_seam), (count, Some(start)));
        assert!(
            (seams.origin - 12.0 * chord()).abs() < 1e-12,
            "{}",
            seams.origin
        );
        assert!((total - 24.0 * chord()).abs() < 1e-12, "{total}");
        assert!(worst < 1e-9, "{worst}");
        for span in spans {
            assert!(
                span[0].abs() < 1e-9 && (span[1] - 2.0).abs() < 1e-9,
                "{span:?}"
            );
        }
    }
    // Strips W wide on both sides of the line flatten to exactly 2 m × W.
    let width = 4.0 * chord();
    let seams = geodesic_seams(&model, &column_of(12, 24, 8), width).unwrap();
    let cut = cut_pattern(&model, seams.strips, Compensation::Uniform([0.0; 2])).unwrap();
    assert_eq!(cut.len(), 6);
    let strain = cut.iter().map(|c| c.distortion.max_strain);
    eprintln!(
        "cylinder from the middle: 6 strips, largest strain {:.2e}",
        strain.fold(0.0, f64::max)
    );
    for strip in &cut {
        assert_eq!(strip.strip.triangles.len(), 64);
        assert!(strip.distortion.max_strain < 1e-9, "{:?}", strip.distortion);
        assert!((strip.size[0] - 2.0).abs() < 1e-9, "{:?}", strip.size);
        assert!((strip.size[1] - width).abs() < 1e-9, "{:?}", strip.size);
    }
}

/// The seams 20° of arc apart from the sphere patch's middle meridian (azimuth 30°, column
/// `n/2` of `n × n` cells): each seam's largest azimuth deviation from `10°`, `30°` and `50°`
/// (rad), and its strips' largest strains.
fn sphere_seams_from_the_middle(n: usize) -> (Vec<f64>, Vec<f64>) {
    let model = sphere_patch_of(n);
    let line = column_of(n / 2, n, n);
    let seams = geodesic_seams(&model, &line, 20f64.to_radians()).unwrap();
    assert_eq!((seams.seams.len(), seams.start_seam), (3, Some(1)));
    // The transverse geodesic runs near the polygonal equator (the triangulated cells are not
    // symmetric about it), from the middle both ways.
    let chord = 2.0 * (30f64 / n as f64).to_radians().sin();
    let total = seams.transverse.last().unwrap().length;
    eprintln!(
        "sphere from the middle meridian, {n} cells: transverse {total:.7} m (polygonal equator {:.7} m), start at {:.7} m",
        n as f64 * chord,
        seams.origin
    );
    assert!((seams.origin - 0.5 * total).abs() < 1e-3 * total);
    assert!((total - n as f64 * chord).abs() < 1e-4 * total, "{total}");
    let deviation = |(k, seam): (usize, &Vec<GeodesicPoint>)| {
        let meridian = (10.0 + 20.0 * k as f64).to_radians();
        let off = seam
            .iter()
            .map(|g| (g.point[1].atan2(g.point[0]) - meridian).abs());
        off.fold(0.0f64, f64::max)
    };
    let deviations = seams.seams.iter().enumerate().map(deviation).collect();
    let cut = cut_pattern(&model, seams.strips, Compensation::Uniform([0.0; 2])).unwrap();
    (
        deviations,
        cut.iter().map(|c| c.distortion.max_strain).collect(),
    )
}

#[test]
fn geodesic_seams_from_a_meridian_inside_a_sphere_patch_approach_the_meridians_on_both_sides() {
    // The transverse geodesic from the middle meridian's equator point is the (polygonal)
    // equator both ways; the seams perpendicular to it 20° of arc away are the sphere's
    // meridians at 10° and 50° as the mesh is refined, the middle one the start line itself.
    let runs = [12, 24, 48].map(sphere_seams_from_the_middle);
    for (n, (deviations, strains)) in [12, 24, 48].iter().zip(&runs) {
        eprintln!(
            "sphere from the middle meridian, {n} cells: seams off their meridians {deviations:?} rad, strips' largest strains {strains:.4?}"
        );
    }
    // Not monotone: a seam that starts within a small fraction of an edge of a vertex (the
    // seams lie 20° of arc from the middle, just past a mesh meridian) follows the vertex's
    // straightest continuation or not, as the geodesics near a cone point do.
    let geodesic = |r: &(Vec<f64>, Vec<f64>)| r.0[0].max(r.0[2]);
    assert!(geodesic(&runs[0]) < 0.2 * 5f64.to_radians());
    assert!(geodesic(&runs[1]) < 0.5 * geodesic(&runs[0]));
    assert!(geodesic(&runs[2]) < 0.1 * geodesic(&runs[0]));
    for (deviations, strains) in &runs {
        assert!(
            deviations[1] < 1e-12,
            "the start line is a meridian of the mesh"
        );
        assert_eq!(strains.len(), 4);
        // Doubly curved: every strip reports its distortion (4 strips 20° wide or less).
        assert!(strains.iter().all(|&s| s > 1e-4 && s < 0.02), "{strains:?}");
    }
}

fn sphere_patch() -> Model {
    sphere_patch_of(12)
}

/// The sphere patch in `n × n` cells.
fn sphere_patch_of(n: usize) -> Model {
    surface_grid(n, n, |u, v| {
        let (theta, phi) = ((30.0 + 120.0 * v).to_radians(), (60.0 * u).to_radians());
        [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ]
    })
}

/// The largest strain of the strips geodesic seams `cells` equator chords apart cut.
fn sphere_strip_strains(cells: f64) -> Vec<f64> {
    let model = sphere_patch();
    let width = cells * 2.0 * 2.5f64.to_radians().sin();
    let seams = geodesic_seams(&model, &first_column(12, 12), width).unwrap();
    let cut = cut_pattern(&model, seams.strips, Compensation::Uniform([0.0; 2])).unwrap();
    cut.iter().map(|c| c.distortion.max_strain).collect()
}

#[test]
fn strips_between_geodesic_seams_of_a_sphere_report_a_strain_that_narrower_strips_lower() {
    let (wide, narrow) = (sphere_strip_strains(4.0), sphere_strip_strains(2.0));
    eprintln!("sphere: strains of 4-cell strips {wide:.4?}, of 2-cell strips {narrow:.4?}");
    assert_eq!((wide.len(), narrow.len()), (3, 6));
    assert!(
        wide.iter()
            .chain(&narrow)
            .all(|&s| s > 1e-4 && s.is_finite())
    );
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, &s| m.max(s));
    assert!(largest(&narrow) < 0.5 * largest(&wide));
}

#[test]
fn a_start_line_inside_the_film_short_of_its_boundary_or_not_along_edges_is_refused_naming_it() {
    let model = half_cylinder();
    let column = |i: usize| (0..=8).map(|j| j * 25 + i).collect::<Vec<_>>();
    let err = geodesic_seams(&model, &column(3)[..7], 0.5).unwrap_err();
    assert!(
        err.contains("end node 153 is not on the film's boundary"),
        "{err}"
    );
    assert!(geodesic_seams(&model, &column(3), 0.5).is_ok());
    let err = geodesic_seams(&model, &[0, 2], 0.5).unwrap_err();
    assert!(err.contains("nodes 0 and 2"), "{err}");
    let err = geodesic_seams(&model, &[0, 9999], 0.5).unwrap_err();
    assert!(err.contains("node 9999"), "{err}");
    let err = geodesic_seams(&model, &column(0), -1.0).unwrap_err();
    assert!(err.contains("width -1"), "{err}");
}

#[test]
fn pattern_with_geodesic_seams_through_the_cli_cuts_the_cylinder_into_strips_of_the_width() {
    let file = std::env::temp_dir().join(format!("geodesic-cylinder-{}.json", std::process::id()));
    let mut model = half_cylinder();
    let rim = (0..model.nodes.len())
        .filter(|&k| [0, 24].contains(&(k % 25)) || [0, 8].contains(&(k / 25)));
    model.groups = vec![BoundaryGroup {
        name: "rim".into(),
        nodes: rim.collect(),
        target: [0.0; 3],
        components: None,
        hinge: None,
    }];
    std::fs::write(&file, model.to_json()).unwrap();
    let run = |line: &[usize], width: &str| {
        let line: Vec<String> = line.iter().map(|v| v.to_string()).collect();
        std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"))
            .arg("pattern")
            .arg(&file)
            .args(["--geodesic-from", &line.join(","), "--strip-width", width])
            .args(["--compensation", "0"])
            .output()
            .unwrap()
    };
    // Six strips of 64 triangles, 2 m × W each: the stderr.
    let six_strips = |output: std::process::Output| {
        let (stdout, stderr) = (
            String::from_utf8(output.stdout).unwrap(),
            String::from_utf8(output.stderr).unwrap(),
        );
        assert!(output.status.success(), "{stderr}");
        assert_eq!(stdout.lines().count(), 6, "{stdout}");
        assert!(
            stdout
                .lines()
                .all(|l| l.contains("64 triangles") && l.contains("2.0000 × 0.5232 m")),
            "{stdout}"
        );
        stderr
    };
    let width = format!("{}", 4.0 * chord());
    let stderr = six_strips(run(&first_column(24, 8), &width));
    assert!(stderr.contains("geodesic seams: 5 seams"), "{stderr}");
    // From the middle generator (inside the film): the same strips, on both sides of it.
    let stderr = six_strips(run(&column_of(12, 24, 8), &width));
    assert!(
        stderr.contains("5 seams")
            && stderr.contains("(the start line, inside the film, is seam 2)")
            && stderr.contains("split along the seams: 0 nodes"),
        "{stderr}"
    );
    let refused = run(&first_column(24, 8), "0");
    let message = String::from_utf8(refused.stderr).unwrap();
    assert!(
        !refused.status.success()
            && message.contains("--geodesic-from: geodesic seams: strip width 0"),
        "{message}"
    );
    std::fs::remove_file(&file).ok();
}

/// The largest azimuth deviation (rad) of the 20°-apart geodesic seams of the sphere patch in
/// `n × n` cells from the meridian through each seam's middle point.
fn sphere_seam_deviation(n: usize) -> f64 {
    let model = sphere_patch_of(n);
    let seams = geodesic_seams(&model, &first_column(n, n), 20f64.to_radians()).unwrap();
    assert_eq!(seams.seams.len(), 2);
    let azimuth = |p: [f64; 3]| p[1].atan2(p[0]);
    let deviation = |seam: &Vec<GeodesicPoint>| {
        let meridian = azimuth(seam[seam.len() / 2].point);
        let off = seam.iter().map(|g| (azimuth(g.point) - meridian).abs());
        off.fold(0.0f64, f64::max)
    };
    seams.seams.iter().map(deviation).fold(0.0, f64::max)
}

#[test]
fn geodesic_seams_on_a_sphere_approach_its_meridians_as_the_mesh_is_refined() {
    let deviations = [12, 24, 48].map(sphere_seam_deviation);
    eprintln!("sphere seams off their meridians (12, 24, 48 cells): {deviations:?} rad");
    assert!(deviations[0] < 0.2 * 5f64.to_radians(), "{deviations:?}");
    assert!(deviations[1] < 0.5 * deviations[0] && deviations[2] < 0.5 * deviations[1]);
}

#[test]
fn a_straightest_geodesic_through_a_cone_apex_leaves_half_the_total_angle_on_each_side() {
    // A hexagonal cone, apex height 1 over a unit hexagon: each of the six wedges has the apex
    // angle α < 60°, so Θ = 6α < 2π. From the middle of wedge 0's base towards the apex, Θ/2 on
    // each side (Polthier & Schmies, Def. 4) puts the exit at the middle of wedge 3's base,
    // opposite; a straight continuation (π) would not.
    let mut nodes = vec![[0.0, 0.0, 1.0]];
    nodes.extend((0..6).map(|k| {
        let a = (60.0 * k as f64).to_radians();
        [a.cos(), a.sin(), 0.0]
    }));
    let triangles = (1..=6).map(|k| [0, k, k % 6 + 1]).collect();
    let model = film_model("Cone", nodes, triangles);
    let mid = |a: usize, b: usize| -> [f64; 3] {
        std::array::from_fn(|c| 0.5 * (model.nodes[a][c] + model.nodes[b][c]))
    };
    let (start, opposite) = (mid(1, 2), mid(4, 5));
    let d: [f64; 3] = std::array::from_fn(|c| model.nodes[0][c] - start[c]);
    let surface = Surface::new(&model);
    let path = surface.trace(0, start, d, f64::INFINITY);
    let end = path.last().unwrap().point;
    let miss = (0..3)
        .map(|c| (end[c] - opposite[c]).powi(2))
        .sum::<f64>()
        .sqrt();
    eprintln!(
        "cone: {} points, exit {end:?}, opposite {opposite:?}, miss {miss:.2e} m",
        path.len()
    );
    assert!(miss < 1e-12, "{miss}");
}

/// The figure after `label` (`"error mean "`, …) in each `erection K:` line of `text`.
fn figures_after(text: &str, label: &str) -> Vec<f64> {
    text.lines()
        .filter(|l| l.starts_with("erection "))
        .filter_map(|l| l.split(label).nth(1))
        .filter_map(|rest| rest.split_whitespace().next()?.parse().ok())
        .collect()
}

#[test]
fn a_warp_at_sixty_degrees_to_the_strips_misses_its_shear_strip_wise_and_is_reached_element_wise() {
    // The strips run along y, the warp (3 MPa) at 30° to x, fill 1 MPa: in the strips' axes the
    // target has the shear τ = (σ1 − σ2)/2 · sin 120° = 0.866 MPa, which a strip's two
    // compensations (along, across) cannot give. Its lack, seen in the warp frame 60° away, is
    // τ sin 120° = 0.75 MPa on the normal components: 25 % of the warp stress.
    let dir = std::env::temp_dir();
    let found = dir.join(format!("saddle-found-{}.json", std::process::id()));
    let example = format!(
        "{}/examples/orthotropic_saddle.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let cli = || std::process::Command::new(env!("CARGO_BIN_EXE_membrane-contact"));
    let status = cli()
        .args(["form-find", &example, "--warp", "0.8660254,0.5,0", "--out"])
        .arg(&found)
        .output()
        .unwrap();
    assert!(status.status.success(), "{status:?}");
    let line: Vec<String> = (0..17).map(|j| (17 * j).to_string()).collect();
    let pattern = |extra: &[&str]| {
        let out = cli()
            .arg("pattern")
            .arg(&found)
            .args(["--geodesic-from", &line.join(","), "--strip-width", "0.5"])
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{out:?}");
        String::from_utf8(out.stdout).unwrap()
    };
    let strip_wise = figures_after(&pattern(&["--erect", "2"]), "error mean ");
    let by_element = figures_after(&pattern(&["--erect", "3", "--by-element"]), "max ");
    std::fs::remove_file(&found).ok();
    eprintln!("strip-wise mean errors {strip_wise:?} %, element-wise largest {by_element:?} %");
    assert!(
        strip_wise.iter().all(|e| (e - 25.0).abs() < 1.0),
        "{strip_wise:?}"
    );
    assert!(*by_element.last().unwrap() < 0.5, "{by_element:?}");
}
