//! The parallel-arch specimen (`specimen.rs`) pinned to numbers that do not come from it
//! (issue 23 item 1).
//!
//! TEST GOAL: the geometry `ParallelArch::model` builds is the one its assumption table
//! documents, worked here by hand for each arch rise (crown at `z = H`, feet at `z = 0` at the
//! half span, radius `R = (s²/4 + H²) / 2H`, the nine gaps on the arch line with their frames,
//! the curved support, the wrapped frame path); and the 300 mm slips at `dz = −H/2`, μ = 0.2,
//! equal those of a model file written here from the documented dimensions alone, run through
//! the public model API, for the lowered and the wrapped frame path.
//!
//! MODEL (the assumption table of `src/mech/specimen.rs`, the 1/4 model):
//!
//! ```text
//!   y ↑  frame edge y = 1 (held)                film flat at z = H, 10 × 10 cells of 0.1 m,
//!   1.0 +---------------------+                 each cell split along its (i,j)–(i+1,j+1)
//!       |        :            |                 diagonal; x = 0 and y = 0 symmetry planes;
//!   0.8 |  ..... G9 (foot)    | frame edge      arch in the plane x = 0.4, crown at y = 0,
//!       |        :            | x = 1 (held)    foot at y = 0.8 (half span 0.8 m);
//!       |        G2           |                 gaps G1…G9 at the film nodes x = 0.4,
//!   0.0 +--------G1-----------+ → x             y = 0, 0.1, …, 0.8.
//!       0       0.4          1.0
//! ```
//!
//! The only detail of the mesh the table leaves open is the diagonal of each cell; the one
//! used here is the program's (another diagonal is another discretisation, not an error).
//! The model file numbers its nodes column by column and lists its triangles in another order
//! than the program does, so the two runs agree to the solver's tolerance, not bit for bit.

use membrane_contact::mech::elements::curved_contact::Centreline;
use membrane_contact::mech::model::GapSupport;
use membrane_contact::mech::{Analysis, Model, Results, SolverSettings};
use membrane_contact::specimens::ParallelArch;
use membrane_contact::specimens::parallel_arch::{FramePath, SpecimenContact};

// The documented dimensions (assumption table), written as numbers, not read from the program.
const HALF_SPAN: f64 = 0.8;
const ARCH_X: f64 = 0.4;
const FRAME: f64 = 1.0;
const CELLS: usize = 10;
const CELL: f64 = FRAME / CELLS as f64;
const E: f64 = 1.0e9;
const NU: f64 = 0.43;
const T: f64 = 250e-6;
const PRESTRESS: f64 = 0.5e6;
const KN: f64 = 1000.0 * E * T;
const KS: f64 = 0.1 * KN;
const PIPE: f64 = 0.0243;
const HEIGHTS: [f64; 3] = [0.2, 0.3, 0.4];

/// The arch radius from the rise `h` and the span `s = 2 · HALF_SPAN`: the circle through the
/// crown `(0, h)` and the feet `(±s/2, 0)` has `R² = (s/2)² + (R − h)²`.
fn radius(h: f64) -> f64 {
    let span = 2.0 * HALF_SPAN;
    (span * span / 4.0 + h * h) / (2.0 * h)
}

/// Angle of the foot seen from the arch centre, measured from the crown.
fn foot_angle(h: f64) -> f64 {
    (HALF_SPAN / radius(h)).asin()
}

/// A point of the arch line (in the plane `x = ARCH_X`) at angle `phi` from the crown: `(y, z)`.
fn arch_point(h: f64, phi: f64) -> [f64; 2] {
    let r = radius(h);
    [r * phi.sin(), h - r + r * phi.cos()]
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(p, q)| (p - q).abs() <= tol)
}

/// Index of the node of `model` at `(x, y)` (every node starts at z = H).
fn node_at(model: &Model, x: f64, y: f64) -> usize {
    let found: Vec<usize> = (0..model.nodes.len())
        .filter(|&k| close(&model.nodes[k][..2], &[x, y], 1e-12))
        .collect();
    assert_eq!(found.len(), 1, "one node at ({x}, {y}): {found:?}");
    found[0]
}

fn sorted(mut v: Vec<usize>) -> Vec<usize> {
    v.sort_unstable();
    v
}

/// Flat position `(X, Y)` of a frame node → its displacement at stage `t` of the wrapped path
/// (assumption table, `frame_path: wrapped`): during the first half the film's line over the
/// arch winds onto the arch circle up to `2t · θ_foot` and leaves it along the tangent; during
/// the second half the boundary is extended by `(2t − 1) ε`: the point at flat distance `Y`
/// from the crown sits at arc length `(1 + e) Y` along that line, and `x` grows by
/// `e (X − x_arch)` beyond the arch line only.
fn wrapped_by_hand(h: f64, eps: f64, x: f64, y: f64, t: f64) -> [f64; 3] {
    let r = radius(h);
    let wound = (2.0 * t).min(1.0) * foot_angle(h);
    let e = (2.0 * t - 1.0).clamp(0.0, 1.0) * eps;
    let s = (1.0 + e) * y;
    let [py, pz] = if s <= r * wound {
        arch_point(h, s / r)
    } else {
        // Along the tangent at the last wound point, (cos θ, −sin θ) in (y, z).
        let [ty, tz] = arch_point(h, wound);
        let free = s - r * wound;
        [ty + free * wound.cos(), tz - free * wound.sin()]
    };
    let across = if x > ARCH_X { e * (x - ARCH_X) } else { 0.0 };
    [across, py - y, pz - h]
}

#[test]
fn arch_circle_passes_through_the_crown_at_h_and_the_feet_at_z_zero() {
    // The hand radius against the numbers the issue quotes (1.22 m for 300 mm, not 4.4 m).
    assert!((radius(0.3) - 73.0 / 60.0).abs() < 1e-15);
    for h in HEIGHTS {
        let [cy, cz] = arch_point(h, 0.0);
        assert!(
            cy.abs() < 1e-15 && (cz - h).abs() < 1e-15,
            "crown {cy} {cz}"
        );
        let [fy, fz] = arch_point(h, foot_angle(h));
        assert!(
            (fy - HALF_SPAN).abs() < 1e-14 && fz.abs() < 1e-14,
            "H = {h}: foot ({fy}, {fz})"
        );
    }
}

#[test]
fn specimen_geometry_is_the_documented_one_worked_by_hand_at_every_height() {
    for h in HEIGHTS {
        let spec = ParallelArch::with_height(h);
        let m = spec.model().unwrap();
        let r = radius(h);
        // Film: the 11 × 11 grid of 0.1 m at z = H, two triangles per cell along one diagonal.
        assert_eq!(m.nodes.len(), (CELLS + 1) * (CELLS + 1));
        assert!(m.nodes.iter().all(|p| (p[2] - h).abs() < 1e-15));
        let grid = |i: usize, j: usize| node_at(&m, i as f64 * CELL, j as f64 * CELL);
        let mut cells = vec![];
        for j in 0..CELLS {
            for i in 0..CELLS {
                let (a, b, c, d) = (
                    grid(i, j),
                    grid(i + 1, j),
                    grid(i + 1, j + 1),
                    grid(i, j + 1),
                );
                cells.push(sorted(vec![a, b, c]));
                cells.push(sorted(vec![a, c, d]));
            }
        }
        let built: Vec<Vec<usize>> = m.triangles.iter().map(|t| sorted(t.to_vec())).collect();
        assert_eq!(sorted_rows(built), sorted_rows(cells), "H = {h}: triangles");
        // Symmetry planes and the held frame edges.
        let edge = |pred: &dyn Fn(usize, usize) -> bool| -> Vec<usize> {
            let mut v = vec![];
            for j in 0..=CELLS {
                for i in 0..=CELLS {
                    if pred(i, j) {
                        v.push(grid(i, j));
                    }
                }
            }
            sorted(v)
        };
        let planes: Vec<Vec<usize>> = m.symmetry.iter().map(|s| sorted(s.nodes.clone())).collect();
        assert_eq!(
            planes,
            [
                edge(&|i, j| i == 0 && j < CELLS),
                edge(&|i, j| j == 0 && i < CELLS)
            ]
        );
        assert_eq!(m.groups.len(), 1);
        assert_eq!(
            sorted(m.groups[0].nodes.clone()),
            edge(&|i, j| i == CELLS || j == CELLS)
        );
        assert_eq!(m.groups[0].target, [0.0, 0.0, -h / 2.0]);
        // Film material.
        let mat = &m.material;
        assert_eq!(
            (
                mat.youngs_modulus,
                mat.poisson_ratio,
                mat.thickness,
                mat.prestress
            ),
            (E, NU, T, [PRESTRESS, PRESTRESS, 0.0])
        );
        // The nine gaps: film node (0.4, 0.1 k, H); the arch centre is (0.4, 0, H − R), so the
        // node is at (Y, R) from it in (y, z): normal (0, Y, R)/√(Y² + R²), support point on
        // the arch R along it, g0 = √(Y² + R²) − R, x the arch tangent toward the foot.
        assert_eq!(m.gaps.len(), 9);
        for (k, g) in m.gaps.iter().enumerate() {
            let y = k as f64 * CELL;
            let d = (y * y + r * r).sqrt();
            let (ny, nz) = (y / d, r / d);
            assert_eq!(g.name, format!("G{}", k + 1));
            assert_eq!(g.film_node, node_at(&m, ARCH_X, y), "H = {h}, {}", g.name);
            let GapSupport::Point(p) = g.support else {
                panic!("{}: fixed support point", g.name)
            };
            let expected = [ARCH_X, r * ny, h - r + r * nz];
            assert!(
                close(&p, &expected, 1e-12),
                "H = {h}, {}: {p:?} vs {expected:?}",
                g.name
            );
            assert!(
                close(&g.frame.z, &[0.0, ny, nz], 1e-12)
                    && close(&g.frame.x, &[0.0, nz, -ny], 1e-12)
                    && close(&g.frame.y, &[-1.0, 0.0, 0.0], 1e-12),
                "H = {h}, {}: frame {:?}",
                g.name,
                g.frame
            );
            assert!(
                (g.initial_gap - (d - r)).abs() < 1e-12,
                "H = {h}, {}",
                g.name
            );
            assert_eq!(
                (g.normal_stiffness, g.tangential_stiffness, g.friction),
                (KN, KS, 0.2)
            );
        }
        // The curved-support contact model: a ring of radius R − r_p about the arch's axis.
        let curved = ParallelArch {
            contact: SpecimenContact::CurvedSupport,
            ..spec
        }
        .model()
        .unwrap();
        assert!(curved.gaps.is_empty());
        let [support] = &curved.curved_supports[..] else {
            panic!("one curved support")
        };
        let Centreline::Circle {
            centre,
            radius: ring,
            angles,
            ..
        } = support.centreline
        else {
            panic!("the arch is a circle")
        };
        assert!(close(&centre, &[ARCH_X, 0.0, h - r], 1e-12), "{centre:?}");
        assert!((ring + PIPE - r).abs() < 1e-12 && support.tube_radius == PIPE);
        let [from, to] = angles.unwrap();
        assert!(
            from < 0.0 && (to - 0.1 - foot_angle(h)).abs() < 1e-12,
            "{angles:?}"
        );
        let arch_nodes: Vec<usize> = m.gaps.iter().map(|g| g.film_node).collect();
        assert_eq!(support.nodes, arch_nodes);
    }
}

fn sorted_rows(mut v: Vec<Vec<usize>>) -> Vec<Vec<usize>> {
    v.sort();
    v
}

#[test]
fn wrapped_frame_path_is_the_film_wound_to_the_foot_worked_by_hand() {
    let eps = 0.02;
    for h in HEIGHTS {
        let spec = ParallelArch {
            frame_path: FramePath::Wrapped { extension: eps },
            ..ParallelArch::with_height(h)
        };
        let m = spec.model().unwrap();
        assert_eq!(m.groups.len(), 2 * CELLS + 1);
        for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let targets = spec.boundary_targets(&m, t);
            for (g, target) in m.groups.iter().zip(&targets) {
                let [x, y, _] = m.nodes[g.nodes[0]];
                let expected = wrapped_by_hand(h, eps, x, y, t);
                assert!(
                    close(target, &expected, 1e-12),
                    "H = {h}, t = {t}, node ({x}, {y}): {target:?} vs {expected:?}"
                );
                if t == 1.0 {
                    assert_eq!(&g.target, target);
                }
            }
        }
        // At the end the frame edge y = 1 hangs below the foot: its film is wound down to z = 0
        // at the half span and runs on down the tangent.
        let foot = node_at(&m, 0.0, FRAME);
        let g = m.groups.iter().find(|g| g.nodes == [foot]).unwrap();
        assert!(h + g.target[2] < 0.0, "H = {h}: {:?}", g.target);
    }
}

// ------------------------------------------------------------- the same problem, written by hand

/// The 300 mm specimen as a model file (JSON) from the documented dimensions: nodes numbered
/// column by column (`i (n + 1) + j`, the program numbers them row by row), triangles listed
/// column by column, frame groups `wrapped`: one group per frame node (target at the end of
/// the path), else one group `frame` lowered by `H/2`.
fn model_file(h: f64, mu: f64, wrapped: Option<f64>) -> String {
    let n = CELLS;
    let id = |i: usize, j: usize| i * (n + 1) + j;
    let r = radius(h);
    let mut nodes = vec![];
    for i in 0..=n {
        for j in 0..=n {
            nodes.push(format!(
                "[{:e}, {:e}, {h:e}]",
                i as f64 * CELL,
                j as f64 * CELL
            ));
        }
    }
    let mut triangles = vec![];
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push(format!("[{a}, {b}, {c}]"));
            triangles.push(format!("[{a}, {c}, {d}]"));
        }
    }
    let list = |v: Vec<usize>| {
        v.iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let x0 = list((0..n).map(|j| id(0, j)).collect());
    let y0 = list((0..n).map(|i| id(i, 0)).collect());
    let arch = (ARCH_X / CELL).round() as usize;
    let gaps: Vec<String> = (0..9)
        .map(|k| {
            let y = k as f64 * CELL;
            let d = (y * y + r * r).sqrt();
            let (ny, nz) = (y / d, r / d);
            format!(
                "{{\"name\": \"G{}\", \"film_node\": {}, \"support\": {{\"point\": [{ARCH_X:e}, {:e}, {:e}]}}, \
                 \"frame\": {{\"x\": [0, {nz:e}, {:e}], \"y\": [-1, 0, 0], \"z\": [0, {ny:e}, {nz:e}]}}, \
                 \"initial_gap\": {:e}, \"normal_stiffness\": {KN:e}, \"tangential_stiffness\": {KS:e}, \
                 \"friction\": {mu:e}}}",
                k + 1,
                id(arch, k),
                r * ny,
                h - r + r * nz,
                -ny,
                d - r
            )
        })
        .collect();
    let frame: Vec<(usize, usize)> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .filter(|&(i, j)| i == n || j == n)
        .collect();
    let groups: Vec<String> = match wrapped {
        None => vec![format!(
            "{{\"name\": \"frame\", \"nodes\": [{}], \"target\": [0, 0, {:e}]}}",
            list(frame.iter().map(|&(i, j)| id(i, j)).collect()),
            -h / 2.0
        )],
        Some(eps) => frame
            .iter()
            .map(|&(i, j)| {
                let [dx, dy, dz] = wrapped_by_hand(h, eps, i as f64 * CELL, j as f64 * CELL, 1.0);
                format!(
                    "{{\"name\": \"n{i}_{j}\", \"nodes\": [{}], \"target\": [{dx:e}, {dy:e}, {dz:e}]}}",
                    id(i, j)
                )
            })
            .collect(),
    };
    let wrinkling = if wrapped.is_some() {
        "tension-field"
    } else {
        "none"
    };
    format!(
        "{{\"name\": \"ByHand\", \"description\": \"the 300 mm specimen from its documented dimensions\",\n\
         \"nodes\": [{}],\n\"triangles\": [{}],\n\
         \"material\": {{\"youngs_modulus\": {E:e}, \"poisson_ratio\": {NU}, \"thickness\": {T:e}, \
         \"prestress\": [{PRESTRESS:e}, {PRESTRESS:e}, 0], \"wrinkling\": \"{wrinkling}\"}},\n\
         \"symmetry\": [{{\"name\": \"x0\", \"normal\": \"x\", \"nodes\": [{x0}]}}, \
         {{\"name\": \"y0\", \"normal\": \"y\", \"nodes\": [{y0}]}}],\n\
         \"gaps\": [{}],\n\"groups\": [{}]}}",
        nodes.join(", "),
        triangles.join(", "),
        gaps.join(",\n"),
        groups.join(",\n")
    )
}

/// Tolerances of both runs: tight enough that the comparison below measures the problem, not
/// the default stopping test.
const TOLERANCE: f64 = 1e-9;

fn settings() -> SolverSettings {
    SolverSettings {
        displacement_tolerance: TOLERANCE,
        residual_tolerance: TOLERANCE,
        ..SolverSettings::default()
    }
}

/// Runs `model` through `steps` equal steps, the targets of step `k` given by `targets(k)`.
fn run(model: Model, steps: usize, targets: impl Fn(&Model, f64) -> Vec<[f64; 3]>) -> Results {
    let mut a = Analysis::new(model.clone(), settings()).unwrap();
    for k in 1..=steps {
        a.step_to(&targets(&model, k as f64 / steps as f64), 1)
            .unwrap_or_else(|e| panic!("{}, step {k}: {e}", model.name));
    }
    a.results()
}

/// Bound on the difference of a slip between two runs of the same problem: each step stops
/// with its last correction `‖ΔU‖∞ ≤ TOLERANCE · U_ref` (`SolverSettings`), `U_ref` at most the
/// largest boundary displacement `u_max`; Newton converging quadratically, the error left after
/// the stop is below that correction, and an increment's start error passes to the next at
/// most unchanged (a stable friction path), so the errors of `steps` steps add up, once for
/// each run.
fn slip_bound(steps: usize, u_max: f64) -> f64 {
    2.0 * steps as f64 * TOLERANCE * u_max
}

fn assert_same_slips(by_hand: &Results, program: &Results, bound: f64, what: &str) {
    let largest = by_hand
        .gaps
        .iter()
        .zip(&program.gaps)
        .map(|(a, b)| (a.slip_x - b.slip_x).abs().max((a.slip_y - b.slip_y).abs()))
        .fold(0.0, f64::max);
    println!("{what}: largest slip difference {largest:e} m (bound {bound:e} m)");
    assert_eq!(by_hand.gaps.len(), 9);
    assert_eq!(program.gaps.len(), 9);
    for (k, (a, b)) in by_hand.gaps.iter().zip(&program.gaps).enumerate() {
        assert!(
            (a.slip_x - b.slip_x).abs() <= bound && (a.slip_y - b.slip_y).abs() <= bound,
            "{what}, G{}: by hand {} {}, specimen {} {} (bound {bound:e})",
            k + 1,
            a.slip_x,
            a.slip_y,
            b.slip_x,
            b.slip_y
        );
        assert_eq!(a.status, b.status, "{what}, G{}", k + 1);
    }
    // The slips are not all zero: the comparison has something to compare.
    assert!(
        program.gaps[7].slip_x > 1e-3,
        "{what}: {:?}",
        program.gaps[7]
    );
}

#[test]
fn specimen_300mm_slips_at_half_the_rise_equal_those_of_a_model_file_written_by_hand() {
    let (h, mu, steps) = (0.3, 0.2, 10);
    let by_hand = Model::from_json(&model_file(h, mu, None)).unwrap();
    let spec = ParallelArch {
        friction: mu,
        ..ParallelArch::with_height(h)
    };
    let lowered = |m: &Model, t: f64| vec![m.groups[0].target.map(|v| v * t); m.groups.len()];
    let a = run(by_hand, steps, lowered);
    let b = run(spec.model().unwrap(), steps, |m, t| {
        spec.boundary_targets(m, t)
    });
    assert_same_slips(&a, &b, slip_bound(steps, h / 2.0), "lowered");
    // The frame reaction too, to the residual tolerance of the largest nodal force.
    let scale = b.reactions[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(close(
        &a.reactions[0],
        &b.reactions[0],
        10.0 * TOLERANCE * scale
    ));
}

#[test]
fn specimen_300mm_wrapped_slips_equal_those_of_a_model_file_written_by_hand() {
    let (h, mu, eps, steps) = (0.3, 0.2, 0.02, 40);
    let by_hand = Model::from_json(&model_file(h, mu, Some(eps))).unwrap();
    // Each group is one frame node, named n<i>_<j> after its grid position.
    let wrapped = move |m: &Model, t: f64| -> Vec<[f64; 3]> {
        m.groups
            .iter()
            .map(|g| {
                let [x, y, _] = m.nodes[g.nodes[0]];
                wrapped_by_hand(h, eps, x, y, t)
            })
            .collect()
    };
    let spec = ParallelArch {
        friction: mu,
        frame_path: FramePath::Wrapped { extension: eps },
        ..ParallelArch::with_height(h)
    };
    let a = run(by_hand, steps, wrapped);
    let b = run(spec.model().unwrap(), steps, |m, t| {
        spec.boundary_targets(m, t)
    });
    // The largest boundary displacement: the foot corner, wound down by about H + 0.2.
    let u_max = h + (FRAME - HALF_SPAN) + eps * FRAME;
    assert_same_slips(&a, &b, slip_bound(steps, u_max), "wrapped");
}
