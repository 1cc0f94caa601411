//! Properties of the mechanics core, each test named after what it proves.
//!
//! Sources: the reference paper (eqs. 2.2–2.13, §3, §4.4 Figs. 7–8 statements) and closed forms
//! worked by hand in the comments. Small models are built inline:
//!
//! ```text
//!   film patch (nx × ny cells, two triangles each), z = 0
//!   3 --- 4 --- 5        group "edge": chosen boundary nodes, moved by (dx, dy, dz)
//!   |  /  |  /  |        gaps: film node → fixed point below it, frame x = X, z = Z
//!   0 --- 1 --- 2
//! ```

mod common;
use common::{dense, worst_fd_mismatch};
use membrane_contact::mech::elements::gap::{
    FrictionLaw, GapFrame, GapLaw, GapResponse, GapStatus, IterationMatrix,
};
use membrane_contact::mech::elements::material::{
    DEFAULT_WRINKLING_REGULARISATION, Wrinkling, WrinklingState,
};
use membrane_contact::mech::elements::triangle::{ElementVector, Material, MembraneTriangle};
use membrane_contact::mech::model::{
    Axis, BoundaryGroup, GapSpec, GapSupport, Model, Support, Symmetry,
};
use membrane_contact::mech::solve::assembly::{Dof, System};
use membrane_contact::mech::{Analysis, SolverSettings};
use membrane_contact::specimens::ParallelArch;
use nalgebra::{DMatrix, Matrix3, Rotation3, Vector2, Vector3};

fn etfe() -> Material {
    Material {
        youngs_modulus: 1.0e9,
        poisson_ratio: 0.43,
        thickness: 250e-6,
        prestress: [0.5e6, 0.5e6, 0.0],
        density: 0.0,
        wrinkling: Wrinkling::None,
        wrinkling_regularisation: DEFAULT_WRINKLING_REGULARISATION,
        yield_stress: None,
        plasticity: None,
        temperature: 23.0,
    }
}

/// A flat `nx × ny` patch of size `lx × ly` at z = 0.
fn patch(nx: usize, ny: usize, lx: f64, ly: f64) -> Model {
    let mut nodes = vec![];
    for j in 0..=ny {
        for i in 0..=nx {
            nodes.push([lx * i as f64 / nx as f64, ly * j as f64 / ny as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut triangles = vec![];
    for j in 0..ny {
        for i in 0..nx {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Model {
        loads: Default::default(),
        outputs: Default::default(),
        cables: vec![],
        curved_supports: vec![],
        chambers: vec![],
        layers: vec![],
        orifices: vec![],
        layer_contacts: vec![],
        frame_axis: None,
        name: "Patch".into(),
        description: String::new(),
        nodes,
        triangles,
        material: etfe(),
        supports: vec![],
        symmetry: vec![],
        gaps: vec![],
        groups: vec![],
    }
}

fn gap_below(name: &str, node: usize, at: [f64; 3], g0: f64, mu: f64) -> GapSpec {
    let kn = 1000.0 * etfe().youngs_modulus * etfe().thickness;
    GapSpec {
        name: name.into(),
        film_node: node,
        support: GapSupport::Point([at[0], at[1], at[2] - g0]),
        frame: GapFrame::from_x_and_z(Vector3::x(), Vector3::z()),
        initial_gap: g0,
        normal_stiffness: kn,
        tangential_stiffness: 0.1 * kn,
        friction: mu,
        friction_law: FrictionLaw::Isotropic,
    }
}

/// One free film node (the centre of a 2 × 2 patch) on a gap; the rim is the group "rim".
fn pressed_node_model(g0: f64, mu: f64) -> Model {
    let mut m = patch(2, 2, 0.2, 0.2);
    m.gaps.push(gap_below("G", 4, m.nodes[4], g0, mu));
    m.groups.push(BoundaryGroup {
        name: "rim".into(),
        nodes: vec![0, 1, 2, 3, 5, 6, 7, 8],
        target: [0.0; 3],
        components: None,
        hinge: None,
    });
    m
}

fn free_residual(system: &System, internal: &[f64]) -> Vec<f64> {
    let mut r = vec![0.0; system.free_count];
    for (i, d) in system.dofs.iter().enumerate() {
        if let Dof::Free(eq) = d {
            r[*eq] = internal[i];
        }
    }
    r
}

/// Internal force over all DOFs and the free–free matrix at `u` with the consistent gap law
/// (or the JR matrix with `status` when given).
fn assemble(
    system: &System,
    laws: &[GapLaw],
    history: &[Vector2<f64>],
    u: &[f64],
    jr: Option<GapStatus>,
) -> (Vec<f64>, DMatrix<f64>) {
    let mut internal = vec![0.0; u.len()];
    let mut values = vec![0.0; system.nonzeros()];
    system.assemble(u, &mut internal, Some(&mut values), |g, d| {
        let r = laws[g].evaluate(d, history[g]);
        let k = match jr {
            None => laws[g].consistent_tangent(&r),
            Some(status) => laws[g].ju_rowlands_matrix(status, r.direction),
        };
        (r.force, k)
    });
    (internal, dense(system, &values))
}

#[test]
fn assembled_tangent_matches_finite_difference_in_every_gap_status_of_both_laws() {
    // Four gaps on a deformed 3 × 2 patch: open (g0 large), sticking, and two slipping, one
    // mostly across x (for the sliding-direction law: (2.13) reached through y, x holding).
    for law in FrictionLaw::ALL {
        let mut m = patch(3, 2, 0.3, 0.2);
        m.gaps.push(gap_below("Gopen", 5, m.nodes[5], 0.05, 0.3));
        m.gaps.push(gap_below("Gstick", 6, m.nodes[6], 0.0, 0.3));
        m.gaps.push(gap_below("Gslip", 9, m.nodes[9], 0.0, 0.3));
        m.gaps.push(gap_below("Gslipx", 10, m.nodes[10], 0.0, 0.3));
        m.set_friction_law(law);
        m.supports.push(Support {
            node: 0,
            fixed: vec![Axis::X, Axis::Y, Axis::Z],
            name: None,
        });
        m.validate().unwrap();
        let system = System::new(&m, false).unwrap();
        let laws: Vec<GapLaw> = m.gaps.iter().map(|g| g.law()).collect();
        let history = vec![Vector2::zeros(); 4];
        let mut u: Vec<f64> = (0..m.dof_count())
            .map(|i| 1e-3 * ((i as f64 * 0.77).sin()))
            .collect();
        u[0..3].fill(0.0);
        // node 6: pressed, tiny shear (stick); nodes 9, 10: pressed, large shear (slip)
        u[3 * 6..3 * 6 + 3].copy_from_slice(&[1e-7, 0.0, -1e-4]);
        u[3 * 9..3 * 9 + 3].copy_from_slice(&[1e-4, 3e-3, -1e-4]);
        u[3 * 10..3 * 10 + 3].copy_from_slice(&[-3e-3, 1e-4, -1e-4]);
        let responses: Vec<_> = (0..4)
            .map(|g| laws[g].evaluate(system.gap_relative(g, &u), history[g]))
            .collect();
        let statuses: Vec<GapStatus> = responses.iter().map(|r| r.status).collect();
        use GapStatus::*;
        assert_eq!(statuses, vec![Open, Stick, Slip, Slip], "{law}");
        if law == FrictionLaw::SlidingDirection {
            let limit = |r: &GapResponse| laws[0].friction * r.normal_force;
            assert!(
                responses[2].force.x.abs() < limit(&responses[2]),
                "x holding"
            );
            assert_eq!(responses[3].force.x, -limit(&responses[3]), "x sliding");
        }
        let (_, k) = assemble(&system, &laws, &history, &u, None);
        let worst = worst_fd_mismatch(&system, &u, 1e-9, &k, |v| {
            free_residual(&system, &assemble(&system, &laws, &history, v, None).0)
        });
        assert!(
            worst < 1e-5 * k.amax(),
            "{law}: worst FD mismatch {worst:e} (scale {:e})",
            k.amax()
        );
    }
}

#[test]
fn ju_rowlands_assembled_matrix_is_symmetric() {
    let mut m = pressed_node_model(0.0, 0.2);
    m.gaps[0].frame = GapFrame::from_x_and_z(Vector3::new(1.0, 1.0, 0.0), Vector3::z());
    let system = System::new(&m, false).unwrap();
    let laws: Vec<GapLaw> = m.gaps.iter().map(|g| g.law()).collect();
    let mut u = vec![0.0; m.dof_count()];
    u[3 * 4..3 * 4 + 3].copy_from_slice(&[2e-3, -1e-3, -1e-4]);
    for status in [GapStatus::Stick, GapStatus::Slip] {
        let (_, k) = assemble(&system, &laws, &[Vector2::zeros()], &u, Some(status));
        assert!(
            (&k - k.transpose()).amax() <= 1e-12 * k.amax(),
            "{status:?} matrix not symmetric"
        );
    }
    let (_, consistent) = assemble(&system, &laws, &[Vector2::zeros()], &u, None);
    assert!(
        (&consistent - consistent.transpose()).amax() > 1e-3 * consistent.amax(),
        "consistent slip tangent is unsymmetric"
    );
}

#[test]
fn rigid_translation_and_large_rotation_leave_strain_and_stress_unchanged() {
    let x = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(0.4, 0.1, 0.05),
        Vector3::new(0.1, 0.3, -0.02),
    ];
    let tri = MembraneTriangle::new(x).unwrap();
    let mat = etfe();
    let rotation = Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vector3::new(0.3, -1.0, 0.5)),
        1.2,
    );
    let shift = Vector3::new(0.7, -0.2, 3.0);
    let u = ElementVector::from_fn(|i, _| {
        let p = x[i / 3];
        (rotation * p + shift - p)[i % 3]
    });
    let s = tri.stress_state(&mat, &u);
    assert!(
        s.strain.iter().all(|e| e.abs() < 1e-14),
        "strain {:?}",
        s.strain
    );
    for (a, b) in s.stress.iter().zip(mat.prestress) {
        assert!(
            (a - b).abs() < 1e-6,
            "stress {:?} vs prestress {:?}",
            s.stress,
            mat.prestress
        );
    }
    // The internal force is the prestress force rotated with the element.
    let r0 = tri.internal_force(&mat, &ElementVector::zeros());
    let r = tri.internal_force(&mat, &u);
    for k in 0..3 {
        let expected = rotation * Vector3::new(r0[3 * k], r0[3 * k + 1], r0[3 * k + 2]);
        let got = Vector3::new(r[3 * k], r[3 * k + 1], r[3 * k + 2]);
        assert!((expected - got).amax() < 1e-9 * r0.amax());
    }
}

#[test]
fn uniform_biaxial_stretch_gives_exact_st_venant_kirchhoff_stress() {
    // Stretch λx = 1.02, λy = 0.995 of a tilted triangle: E = ½(λ² − 1), S = D E + σ0 exactly.
    let (lx, ly) = (1.02_f64, 0.995_f64);
    let x = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(0.5, 0.0, 0.0),
        Vector3::new(0.2, 0.4, 0.0),
    ];
    let tri = MembraneTriangle::new(x).unwrap();
    let u = ElementVector::from_fn(|i, _| {
        let p = x[i / 3];
        [p.x * (lx - 1.0), p.y * (ly - 1.0), 0.0][i % 3]
    });
    let mat = etfe();
    let s = tri.stress_state(&mat, &u);
    let (ex, ey) = (0.5 * (lx * lx - 1.0), 0.5 * (ly * ly - 1.0));
    let c = mat.youngs_modulus / (1.0 - mat.poisson_ratio.powi(2));
    let sx = c * (ex + mat.poisson_ratio * ey) + mat.prestress[0];
    let sy = c * (ey + mat.poisson_ratio * ex) + mat.prestress[1];
    assert!(
        (s.strain[0] - ex).abs() < 1e-15
            && (s.strain[1] - ey).abs() < 1e-15
            && s.strain[2].abs() < 1e-15
    );
    assert!(
        (s.stress[0] - sx).abs() < 1e-6 * sx.abs(),
        "{} vs {sx}",
        s.stress[0]
    );
    assert!(
        (s.stress[1] - sy).abs() < 1e-6 * sy.abs(),
        "{} vs {sy}",
        s.stress[1]
    );
    assert!((s.von_mises - (sx * sx - sx * sy + sy * sy).sqrt()).abs() < 1e-6 * sx.abs());
}

#[test]
fn gap_pressed_then_sheared_sticks_then_slips_at_mu_times_normal_force() {
    // Law level: press by 0.1 mm, then shear in 20 increments with history committed each time.
    let law = GapLaw {
        normal_stiffness: 2.5e8,
        tangential_stiffness: 2.5e7,
        friction: 0.3,
        initial_gap: 0.0,
        friction_law: FrictionLaw::Isotropic,
    };
    let mut history = Vector2::zeros();
    let mut seen = vec![];
    for k in 0..=20 {
        let d = Vector3::new(k as f64 * 0.5e-6, 0.0, -1e-7);
        let r = law.evaluate(d, history);
        let t = (r.force.x.powi(2) + r.force.y.powi(2)).sqrt();
        assert!(t <= law.friction * r.normal_force * (1.0 + 1e-12));
        if r.status == GapStatus::Slip {
            assert!((t - law.friction * r.normal_force).abs() < 1e-9 * r.normal_force);
        }
        history = r.plastic_slip;
        seen.push(r.status);
    }
    assert_eq!(seen[0], GapStatus::Stick);
    assert!(
        seen.iter()
            .skip_while(|s| **s == GapStatus::Stick)
            .all(|s| *s == GapStatus::Slip)
    );
    assert_eq!(seen.last(), Some(&GapStatus::Slip));

    // Model level: the rim presses the centre node onto the gap, then drags it along x.
    let mut a = Analysis::new(pressed_node_model(0.0, 0.3), SolverSettings::default()).unwrap();
    a.step_to(&[[0.0, 0.0, -0.01]], 5).unwrap();
    let pressed = a.results().gaps[0];
    assert_eq!(pressed.status, GapStatus::Stick);
    assert!(pressed.normal_force > 0.0);
    let mut statuses = vec![];
    for k in 1..=10 {
        a.step_to(&[[k as f64 * 4e-6, 0.0, -0.01]], 1).unwrap();
        let g = a.results().gaps[0];
        assert!(g.friction_force <= 0.3 * g.normal_force * (1.0 + 1e-9));
        if g.status == GapStatus::Slip {
            assert!((g.friction_force - 0.3 * g.normal_force).abs() < 1e-8 * g.normal_force);
        }
        statuses.push(g.status);
    }
    assert_eq!(statuses[0], GapStatus::Stick, "{statuses:?}");
    assert_eq!(*statuses.last().unwrap(), GapStatus::Slip, "{statuses:?}");
}

#[test]
fn open_gap_carries_nothing_until_it_closes() {
    let mut a = Analysis::new(pressed_node_model(0.004, 0.2), SolverSettings::default()).unwrap();
    let mut closed_at = None;
    for k in 1..=10 {
        let dz = -0.001 * k as f64;
        a.step_to(&[[0.0, 0.0, dz]], 1).unwrap();
        let g = a.results().gaps[0];
        let w = a.node_displacement(4).z;
        if w > -0.004 + 1e-9 {
            assert_eq!(
                g.status,
                GapStatus::Open,
                "gap open while the node is above the support"
            );
            assert_eq!((g.normal_force, g.friction_force), (0.0, 0.0));
        } else if w < -0.004 - 1e-9 {
            closed_at.get_or_insert(k);
            assert!(g.normal_force > 0.0);
        }
    }
    assert!(closed_at.is_some(), "the gap never closed");
}

#[test]
fn newton_converges_quadratically_where_no_status_changes() {
    // Membrane only: a 4 × 4 patch whose right edge is pulled and lifted (large rotation).
    let mut m = patch(4, 4, 0.4, 0.4);
    let left: Vec<usize> = (0..5).map(|j| j * 5).collect();
    let right: Vec<usize> = (0..5).map(|j| j * 5 + 4).collect();
    m.groups.push(BoundaryGroup {
        name: "left".into(),
        nodes: left,
        target: [0.0; 3],
        components: None,
        hinge: None,
    });
    m.groups.push(BoundaryGroup {
        name: "right".into(),
        nodes: right,
        target: [0.0; 3],
        components: None,
        hinge: None,
    });
    let mut a = Analysis::new(
        m,
        SolverSettings {
            residual_tolerance: 1e-12,
            ..Default::default()
        },
    )
    .unwrap();
    let report = a.step_to(&[[0.0; 3], [0.01, 0.0, 0.05]], 1).unwrap();
    let r = &report.residual_history;
    assert!(r.len() >= 4, "{r:?}");
    // In the last iterations above round-off, r_{k+1} ≤ C r_k² with a moderate C.
    let tail: Vec<f64> = r.iter().copied().filter(|v| *v > 1e-7).collect();
    let n = tail.len();
    assert!(n >= 3, "{r:?}");
    let ratio = |k: usize| tail[k + 1] / tail[k].powi(2);
    let ratios: Vec<f64> = (n - 3..n - 1).map(ratio).collect();
    assert!(
        ratios.iter().all(|c| *c < 1.0),
        "not quadratic: residuals {r:?}, ratios {ratios:?}"
    );
    assert!(r.last().unwrap() / r[1] < 1e-9, "{r:?}");
}

#[test]
fn both_iteration_matrices_converge_to_the_same_answer() {
    let run = |matrix| {
        // Tight tolerances: the test compares the answers to 1e-9 m, below the defaults' accuracy.
        let settings = SolverSettings {
            iteration_matrix: matrix,
            max_iterations: 200,
            displacement_tolerance: 1e-8,
            residual_tolerance: 1e-8,
            ..Default::default()
        };
        let mut a = Analysis::new(pressed_node_model(0.0, 0.3), settings).unwrap();
        let mut iterations = 0;
        iterations += a
            .step_to(&[[0.0, 0.0, -0.01]], 5)
            .unwrap()
            .total_iterations();
        iterations += a
            .step_to(&[[0.002, 0.0, -0.01]], 5)
            .unwrap()
            .total_iterations();
        (
            a.results().gaps[0],
            a.state().displacement.clone(),
            iterations,
        )
    };
    let (g1, u1, it1) = run(IterationMatrix::Consistent);
    let (g2, u2, it2) = run(IterationMatrix::JuRowlands);
    assert_eq!(g1.status, GapStatus::Slip);
    assert_eq!(g1.status, g2.status);
    let du = u1
        .iter()
        .zip(&u2)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(du < 1e-9, "displacements differ by {du:e} m");
    assert!((g1.slip_x - g2.slip_x).abs() < 1e-9);
    assert!((g1.friction_force - g2.friction_force).abs() < 1e-6 * g1.friction_force);
    assert!(
        it1 <= it2,
        "consistent {it1} vs Ju–Rowlands {it2} iterations"
    );
}

/// The pressed-node model with friction law `law`, its rim lowered by 10 mm onto the gap.
fn pressed_with(law: FrictionLaw, mu: f64, settings: SolverSettings) -> Analysis {
    let mut m = pressed_node_model(0.0, mu);
    m.set_friction_law(law);
    let mut a = Analysis::new(m, settings).unwrap();
    a.step_to(&[[0.0, 0.0, -0.01]], 5).unwrap();
    a
}

#[test]
fn sliding_direction_law_sticks_then_slips_at_mu_times_normal_force_along_x() {
    // The rim presses the centre node onto the gap, then drags it along x: stick until the
    // friction force reaches μN (2.13), then slip with t_x at exactly μN, a small elastic y
    // force (from the patch's skew mesh) and no slip across x.
    let mut a = pressed_with(
        FrictionLaw::SlidingDirection,
        0.3,
        SolverSettings::default(),
    );
    let closed = a.state().plastic_slip[0];
    let mut statuses = vec![];
    for k in 1..=10 {
        a.step_to(&[[k as f64 * 4e-6, 0.0, -0.01]], 1).unwrap();
        let g = a.results().gaps[0];
        let limit = 0.3 * g.normal_force;
        assert!(g.friction[0] <= limit * (1.0 + 1e-9), "{g:?}");
        assert!(g.friction[1].abs() < 0.5 * limit, "{g:?}");
        if g.status == GapStatus::Slip {
            assert!((g.friction[0] - limit).abs() < 1e-8 * limit, "{g:?}");
        }
        assert_eq!(a.state().plastic_slip[0][1], closed[1]);
        statuses.push(g.status);
    }
    assert_eq!(statuses[0], GapStatus::Stick, "{statuses:?}");
    assert_eq!(*statuses.last().unwrap(), GapStatus::Slip, "{statuses:?}");
}

#[test]
fn sliding_direction_law_keeps_cross_slip_elastic() {
    // Pressed, then dragged diagonally (2 mm along x, 1 mm along y): the isotropic cone slides
    // along the drag; the paper's law slides along x only with t_x = μN, and its y force stays
    // k_s·(d_y − s_y) with the y slip history of the closure, far above μN.
    let drag = |law| {
        let mut a = pressed_with(law, 0.3, SolverSettings::default());
        let closed = a.state().plastic_slip[0];
        a.step_to(&[[2e-3, 1e-3, -0.01]], 10).unwrap();
        (a.results().gaps[0], closed, a.state().plastic_slip[0])
    };
    let (g, closed, history) = drag(FrictionLaw::SlidingDirection);
    let ks = pressed_node_model(0.0, 0.3).gaps[0].tangential_stiffness;
    assert_eq!(g.status, GapStatus::Slip);
    assert_eq!(history[1], closed[1], "y slip history moved");
    assert!(
        history[0] > closed[0] + 1e-4,
        "no slip along x: {history:?}"
    );
    assert!((g.friction[1] - ks * (g.slip_y - history[1])).abs() < 1e-9 * g.normal_force);
    let limit = 0.3 * g.normal_force;
    assert!((g.friction[0] - limit).abs() < 1e-9 * limit, "{g:?}");
    assert!(g.friction[1].abs() > limit, "{g:?}");
    let (cone, closed, history) = drag(FrictionLaw::Isotropic);
    assert!(
        history[1] > closed[1] + 1e-4,
        "the cone slides across x too"
    );
    assert!((cone.friction_force - 0.3 * cone.normal_force).abs() < 1e-9 * cone.normal_force);
}

#[test]
fn sliding_direction_slip_reverses_with_the_drag() {
    let mut a = pressed_with(
        FrictionLaw::SlidingDirection,
        0.2,
        SolverSettings::default(),
    );
    a.step_to(&[[1e-3, 0.0, -0.01]], 5).unwrap();
    let forward = a.results().gaps[0];
    let slipped = a.state().plastic_slip[0][0];
    a.step_to(&[[-1e-3, 0.0, -0.01]], 10).unwrap();
    let back = a.results().gaps[0];
    assert_eq!(
        (forward.status, back.status),
        (GapStatus::Slip, GapStatus::Slip)
    );
    assert!(
        forward.friction[0] > 0.0 && back.friction[0] < 0.0,
        "{forward:?} {back:?}"
    );
    assert!((back.friction[0] + 0.2 * back.normal_force).abs() < 1e-8 * back.normal_force);
    assert!(
        a.state().plastic_slip[0][0] < slipped - 1e-4,
        "slip did not reverse"
    );
}

#[test]
fn both_iteration_matrices_converge_to_the_same_answer_with_the_sliding_direction_law() {
    // Dragged along x (slip along x with a small elastic y force: the paper's own case for the
    // (2.9) matrix), and with a y drag that makes the elastic y force exceed μN.
    let run = |matrix, target| {
        let settings = SolverSettings {
            iteration_matrix: matrix,
            max_iterations: 400,
            ..Default::default()
        };
        let mut a = pressed_with(FrictionLaw::SlidingDirection, 0.3, settings);
        a.step_to(&[target], 5).unwrap();
        (a.results().gaps[0], a.state().displacement.clone())
    };
    for target in [[2e-3, 0.0, -0.01], [2e-3, 2e-4, -0.01]] {
        let (g1, u1) = run(IterationMatrix::Consistent, target);
        let (g2, u2) = run(IterationMatrix::JuRowlands, target);
        assert_eq!((g1.status, g2.status), (GapStatus::Slip, GapStatus::Slip));
        assert!(
            g1.friction[1].abs() > 1e-3 * g1.friction_force,
            "y force {g1:?}"
        );
        assert!((g1.friction[0] - 0.3 * g1.normal_force).abs() < 1e-8 * g1.normal_force);
        let du = u1
            .iter()
            .zip(&u2)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(du < 1e-9, "{target:?}: displacements differ by {du:e} m");
        let df = (g1.friction[0] - g2.friction[0]).abs() + (g1.friction[1] - g2.friction[1]).abs();
        assert!(df < 1e-6 * g1.friction_force, "{g1:?} vs {g2:?}");
    }
}

/// A film edge lying on an arch (issue 7, case 5).
///
/// ```text
///   z ↑  film: a cylinder segment x ∈ [0, 0.6], y ∈ [0, 0.6] on the arch radius R = 1 m
///      |  (axis along X, crown at y = 0, z = 0); 6 × 6 cells
///   y=0.6  E E E E E E E    E: group "edge" (outer edges), lowered by dz
///          G · · · · · E    G0..G5: gaps on the edge x = 0, on the arch (g0 = 0), frame x =
///          G · · · · · E    arch tangent, z = radial, y = z × x = global ±X (across the arch)
///   y=0    G s s s s s E    s: symmetry plane y = 0
///         x=0         x=0.6
/// ```
/// Prestress 0.5 MPa around the arch, `prestress_across` across it (σx).
fn film_edge_on_arch(law: FrictionLaw, prestress_across: f64) -> Model {
    let (nx, ny, r) = (6, 6, 1.0);
    let mut m = patch(nx, ny, 0.6, 0.6);
    for p in &mut m.nodes {
        p[2] = -r + (r * r - p[1] * p[1]).sqrt();
    }
    m.material.prestress = [prestress_across, 0.5e6, 0.0];
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let centre = Vector3::new(0.0, 0.0, -r);
    for j in 0..ny {
        let node = id(0, j);
        let n = (Vector3::from(m.nodes[node]) - centre).normalize();
        let mut gap = gap_below(&format!("G{j}"), node, m.nodes[node], 0.0, 0.2);
        gap.support = GapSupport::Point((centre + n * r).into());
        gap.frame = GapFrame::from_x_and_z(Vector3::new(0.0, n.z, -n.y), n);
        gap.friction_law = law;
        m.gaps.push(gap);
    }
    m.symmetry.push(Symmetry {
        name: "y0".into(),
        normal: Axis::Y,
        nodes: (0..nx).map(|i| id(i, 0)).collect(),
    });
    let mut edge: Vec<usize> = (0..=ny).map(|j| id(nx, j)).collect();
    edge.extend((0..nx).map(|i| id(i, ny)));
    m.groups.push(BoundaryGroup {
        name: "edge".into(),
        nodes: edge,
        target: [0.0, 0.0, -0.1],
        components: None,
        hinge: None,
    });
    m
}

#[test]
fn papers_law_holds_a_film_edge_on_an_arch_that_the_cone_lets_slide_across() {
    // Issue 7, case 5: with no prestress across the arch, the cone lets the edge slide
    // sideways and Newton stalls; the paper's law converges with default settings and keeps
    // the edge on the arch line, sliding along it only.
    let run = |law, across| {
        let mut a =
            Analysis::new(film_edge_on_arch(law, across), SolverSettings::default()).unwrap();
        for k in 1..=20 {
            a.step_to(&[[0.0, 0.0, -0.1 * k as f64 / 20.0]], 1)
                .map_err(|e| format!("{law}, step {k}: {e}"))?;
        }
        Ok::<_, String>(a.results().gaps)
    };
    for across in [0.0, 0.5e6] {
        let gaps = run(FrictionLaw::SlidingDirection, across).unwrap();
        assert!(gaps.iter().all(|g| g.slip_y.abs() < 2e-4), "{gaps:?}");
        assert!(
            gaps[5].slip_x > 0.05,
            "the edge slides along the arch: {gaps:?}"
        );
    }
    // With prestress across the arch the cone converges, having slid the edge off the arch line.
    let cone = run(FrictionLaw::Isotropic, 0.5e6).unwrap();
    assert!(cone.iter().any(|g| g.slip_y.abs() > 0.01), "{cone:?}");
}

#[test]
fn model_files_name_the_friction_law_and_default_to_isotropic() {
    let mut m = pressed_node_model(0.0, 0.2);
    let text = m.to_json();
    assert!(text.contains("\"friction_law\": \"isotropic\""), "{text}");
    let old = text.replace(",\n      \"friction_law\": \"isotropic\"", "");
    assert!(!old.contains("friction_law"), "{old}");
    assert_eq!(Model::from_json(&old).unwrap(), m);
    m.set_friction_law(FrictionLaw::SlidingDirection);
    let paper = m.to_json();
    assert!(paper.contains("\"friction_law\": \"sliding-direction\""));
    assert_eq!(
        Model::from_json(&paper).unwrap().uniform_friction_law(),
        Some(FrictionLaw::SlidingDirection)
    );
    let err = Model::from_json(&paper.replace("sliding-direction", "x-only"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("x-only") && err.contains("sliding-direction"),
        "{err}"
    );
}

#[test]
fn failed_step_keeps_the_last_converged_state() {
    let settings = SolverSettings {
        max_iterations: 2,
        max_cutbacks: 1,
        stabilization: false,
        ..Default::default()
    };
    let mut a = Analysis::new(pressed_node_model(0.0, 0.2), settings).unwrap();
    a.step_to(&[[0.0, 0.0, -0.001]], 1).unwrap();
    let before = a.state().clone();
    let err = a.step_to(&[[0.05, 0.0, -0.2]], 1).unwrap_err();
    assert!(
        err.to_string().contains("last converged state is kept"),
        "{err}"
    );
    assert_eq!(a.state(), &before);
    assert!(a.step_to(&[[f64::NAN, 0.0, 0.0]], 1).is_err());
    assert_eq!(a.state(), &before);
}

#[test]
fn malformed_models_are_rejected_naming_the_bad_item() {
    let good = pressed_node_model(0.0, 0.2);
    good.validate().unwrap();
    let cases: Vec<(Box<dyn Fn(&mut Model)>, &str)> = vec![
        (Box::new(|m| m.triangles[0][1] = 99), "node 99"),
        (Box::new(|m| m.triangles[1] = [0, 1, 2]), "triangle 1"),
        (Box::new(|m| m.material.youngs_modulus = 0.0), "E = 0"),
        (Box::new(|m| m.material.poisson_ratio = 0.5), "ν = 0.5"),
        (Box::new(|m| m.gaps[0].friction = -0.1), "gap 'G'"),
        (
            Box::new(|m| m.gaps[0].frame.y = [0.0, 0.0, 1.0]),
            "not orthonormal",
        ),
        (Box::new(|m| m.groups[0].name = "G".into()), "used twice"),
        (Box::new(|m| m.gaps[0].name = "1bad".into()), "identifier"),
        (
            Box::new(|m| {
                m.symmetry.push(Symmetry {
                    name: "s".into(),
                    normal: Axis::X,
                    nodes: vec![0],
                })
            }),
            "node 0",
        ),
        (Box::new(|m| m.nodes[3][2] = f64::NAN), "node 3"),
    ];
    for (break_it, expected) in cases {
        let mut m = good.clone();
        break_it(&mut m);
        let message = m.validate().unwrap_err().to_string();
        assert!(
            message.contains(expected),
            "'{message}' should mention '{expected}'"
        );
        // The JSON route reports the same (NaN has no JSON form).
        if expected != "node 3" {
            assert!(
                Model::from_json(&m.to_json())
                    .unwrap_err()
                    .to_string()
                    .contains(expected)
            );
        }
    }
    let syntax = Model::from_json("{\"name\": \"x\", \"nodes\": [[0,0]]}")
        .unwrap_err()
        .to_string();
    assert!(syntax.contains("model file"), "{syntax}");
}

#[test]
fn model_json_round_trips() {
    let model = ParallelArch::with_height(0.3).model().unwrap();
    assert_eq!(Model::from_json(&model.to_json()).unwrap(), model);
}

fn specimen_slips(height: f64, mu: f64) -> Vec<f64> {
    let spec = ParallelArch {
        friction: mu,
        ..ParallelArch::with_height(height)
    };
    let mut a = Analysis::new(spec.model().unwrap(), SolverSettings::default()).unwrap();
    a.step_to(&[spec.target()], 10).unwrap();
    a.results().gaps.iter().map(|g| g.slip_x).collect()
}

#[test]
fn specimen_matches_the_paper_layout() {
    let m = ParallelArch::with_height(0.3).model().unwrap();
    assert_eq!(m.triangles.len(), 200);
    assert_eq!(m.gaps.len(), 9);
    assert_eq!(
        m.gaps.iter().map(|g| g.name.as_str()).collect::<Vec<_>>(),
        ["G1", "G2", "G3", "G4", "G5", "G6", "G7", "G8", "G9"]
    );
    // k_n three orders above the film's E·t, k_s = 0.1 k_n (§4.4); crown gap touches.
    let et = m.material.youngs_modulus * m.material.thickness;
    assert!(
        m.gaps
            .iter()
            .all(|g| (g.normal_stiffness / et - 1000.0).abs() < 1e-9
                && (g.tangential_stiffness / g.normal_stiffness - 0.1).abs() < 1e-12)
    );
    assert_eq!(m.gaps[0].initial_gap, 0.0);
    // Normals point from the arch centre to the contact point: z·(A − centre) > 0, frames orthonormal.
    for g in &m.gaps {
        assert!(g.frame.orthonormality_error() < 1e-12);
        let z = Vector3::from(g.frame.z);
        assert!(z.z > 0.0 && z.x.abs() < 1e-12);
    }
    let refined = ParallelArch {
        refinement: 3,
        ..ParallelArch::with_height(0.3)
    }
    .model()
    .unwrap();
    assert_eq!(refined.triangles.len(), 200 * 9);
    assert_eq!(refined.gaps.len(), 9);
}

#[test]
fn specimen_slip_is_zero_at_the_crown_and_grows_toward_the_foot() {
    let s = specimen_slips(0.3, 0.2);
    assert!(s[0].abs() < 1e-9, "crown slip {}", s[0]);
    assert!(
        s.windows(2).all(|w| w[1] > w[0]),
        "slip not increasing toward the foot: {s:?}"
    );
}

#[test]
fn higher_arches_slide_more() {
    let (s200, s300, s400) = (
        specimen_slips(0.2, 0.2),
        specimen_slips(0.3, 0.2),
        specimen_slips(0.4, 0.2),
    );
    for g in [1, 3, 5, 7] {
        assert!(
            s200[g] < s300[g] && s300[g] < s400[g],
            "G{}: {} {} {}",
            g + 1,
            s200[g],
            s300[g],
            s400[g]
        );
    }
}

#[test]
fn larger_friction_gives_less_slip() {
    let slips: Vec<Vec<f64>> = [0.1, 0.2, 0.3, 0.5]
        .iter()
        .map(|&mu| specimen_slips(0.3, mu))
        .collect();
    for g in [1, 2, 3] {
        let column: Vec<f64> = slips.iter().map(|s| s[g]).collect();
        assert!(
            column.windows(2).all(|w| w[1] < w[0]),
            "G{}: slip vs μ {column:?}",
            g + 1
        );
    }
}

#[test]
fn papers_law_on_the_specimen_slides_along_the_arch_and_less_for_larger_friction() {
    // The paper's Fig. 7 statements with its own friction law (§2.2): slip zero at the crown,
    // growing toward the foot, smaller for larger μ. 60 increments: with 10 the closing of G2
    // makes Newton chatter open ↔ closed (reported in docs/mechanics.md).
    let slips: Vec<(Vec<f64>, Vec<f64>)> = [0.1, 0.2, 0.5]
        .iter()
        .map(|&mu| {
            let spec = ParallelArch {
                friction: mu,
                friction_law: FrictionLaw::SlidingDirection,
                ..ParallelArch::with_height(0.3)
            };
            let mut a = Analysis::new(spec.model().unwrap(), SolverSettings::default()).unwrap();
            a.step_to(&[spec.target()], 60).unwrap();
            let r = a.results();
            let x = r.gaps.iter().map(|g| g.slip_x).collect();
            // Closed gaps that slide carry f_s = μN along the arch.
            let f = r
                .gaps
                .iter()
                .filter(|g| g.status == GapStatus::Slip)
                .map(|g| g.friction[0].abs() / (mu * g.normal_force))
                .collect();
            (x, f)
        })
        .collect();
    for (s, ratios) in &slips {
        assert!(s[0].abs() < 1e-9, "crown slip {}", s[0]);
        assert!(s.windows(2).all(|w| w[1] > w[0]), "{s:?}");
        assert!(ratios.iter().any(|r| (r - 1.0).abs() < 1e-9), "{ratios:?}");
        assert!(ratios.iter().all(|r| *r <= 1.0 + 1e-9), "{ratios:?}");
    }
    for g in [1, 2, 3] {
        let column: Vec<f64> = slips.iter().map(|(s, _)| s[g]).collect();
        assert!(
            column.windows(2).all(|w| w[1] < w[0]),
            "G{}: {column:?}",
            g + 1
        );
    }
}

#[test]
fn gap_frame_rotation_has_the_frame_as_rows() {
    let f = GapFrame::from_x_and_z(Vector3::new(0.0, 0.6, -0.8), Vector3::new(0.0, 0.8, 0.6));
    let r: Matrix3<f64> = f.rotation();
    assert!((r * Vector3::from(f.z) - Vector3::z()).amax() < 1e-15);
    assert!((Vector3::from(f.y) - Vector3::new(-1.0, 0.0, 0.0)).amax() < 1e-15);
}

/// A `.vtu` read back: piece sizes and every data array as numbers (`points` for the unnamed
/// coordinates), from ASCII or raw appended data.
struct Vtu {
    points: usize,
    cells: usize,
    arrays: std::collections::HashMap<String, Vec<f64>>,
}

/// Parses a `.vtu` as `vtk::Encoding` writes it and checks its framing: well-formed XML before
/// the appended data, one UInt64 byte count per block, offsets that tile the appended bytes.
fn read_vtu(bytes: &[u8]) -> Vtu {
    const APPENDED: &[u8] = b"<AppendedData encoding=\"raw\">\n_";
    let (xml, appended) = match bytes.windows(APPENDED.len()).position(|w| w == APPENDED) {
        Some(at) => {
            let tail = &bytes[at + APPENDED.len()..];
            let end = b"\n</AppendedData>\n</VTKFile>\n";
            assert!(tail.ends_with(end), "appended data closes the file");
            let mut xml = String::from_utf8(bytes[..at].to_vec()).unwrap();
            xml.push_str("</VTKFile>");
            (xml, &tail[..tail.len() - end.len()])
        }
        None => (String::from_utf8(bytes.to_vec()).unwrap(), &[][..]),
    };
    let mut reader = quick_xml::Reader::from_str(&xml);
    let (mut vtu, mut current) = (
        Vtu {
            points: 0,
            cells: 0,
            arrays: Default::default(),
        },
        None,
    );
    let mut next_offset = 0;
    loop {
        let (e, empty) = match reader.read_event().expect("well-formed XML") {
            quick_xml::events::Event::Start(e) => (e, false),
            quick_xml::events::Event::Empty(e) => (e, true),
            quick_xml::events::Event::Text(t) => {
                if let Some((name, _)) = current.take() {
                    let values: Vec<f64> = t
                        .into_inner()
                        .split_whitespace()
                        .map(|v| v.parse().unwrap())
                        .collect();
                    vtu.arrays.insert(name, values);
                }
                continue;
            }
            quick_xml::events::Event::Eof => break,
            _ => continue,
        };
        let attribute = |name: &str| {
            e.try_get_attribute(name)
                .unwrap()
                .map(|a| a.value.to_string())
        };
        match e.name().0 {
            "VTKFile" => assert_eq!(attribute("header_type").as_deref(), Some("UInt64")),
            "Piece" => {
                vtu.points = attribute("NumberOfPoints").unwrap().parse().unwrap();
                vtu.cells = attribute("NumberOfCells").unwrap().parse().unwrap();
            }
            "DataArray" => {
                let name = attribute("Name").unwrap_or_else(|| "points".into());
                let kind = attribute("type").unwrap();
                match attribute("format").unwrap().as_str() {
                    "ascii" => current = Some((name, kind)),
                    "appended" => {
                        assert!(empty, "{name}: an appended DataArray has no text");
                        let offset: usize = attribute("offset").unwrap().parse().unwrap();
                        assert_eq!(offset, next_offset, "{name}: blocks follow each other");
                        let block = &appended[offset..];
                        let count = u64::from_le_bytes(block[..8].try_into().unwrap()) as usize;
                        let data = &block[8..8 + count];
                        next_offset = offset + 8 + count;
                        let values: Vec<f64> = match kind.as_str() {
                            "Float64" => data
                                .chunks_exact(8)
                                .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
                                .collect(),
                            "Int64" => data
                                .chunks_exact(8)
                                .map(|b| i64::from_le_bytes(b.try_into().unwrap()) as f64)
                                .collect(),
                            "Int32" => data
                                .chunks_exact(4)
                                .map(|b| i32::from_le_bytes(b.try_into().unwrap()) as f64)
                                .collect(),
                            "UInt8" => data.iter().map(|&b| b as f64).collect(),
                            other => panic!("{name}: type {other}"),
                        };
                        vtu.arrays.insert(name, values);
                    }
                    other => panic!("{name}: format {other}"),
                }
            }
            _ => {}
        }
    }
    assert_eq!(
        next_offset,
        appended.len(),
        "the blocks fill the appended data"
    );
    vtu
}

/// The specimen (200 mm) after 4 increments to its target, and its results.
fn specimen_state() -> (Analysis, membrane_contact::mech::Results) {
    let spec = ParallelArch::with_height(0.2);
    let mut a = Analysis::new(spec.model().unwrap(), SolverSettings::default()).unwrap();
    a.step_to(&[spec.target()], 4).unwrap();
    let results = a.results();
    (a, results)
}

#[test]
fn vtk_film_and_gap_files_are_complete_without_placeholders() {
    use membrane_contact::mech::results::vtk::{self, Encoding};
    let (a, results) = specimen_state();
    let (model, u) = (a.model(), &a.state().displacement);
    for encoding in [Encoding::Ascii, Encoding::Binary] {
        let film = read_vtu(&vtk::film_grid(model, u, &results, encoding));
        assert_eq!((film.points, film.cells), (121, 200), "{encoding:?}");
        let arrays = &film.arrays;
        assert!(arrays.values().flatten().all(|v| v.is_finite()));
        assert_eq!(arrays["points"].len(), 3 * 121);
        assert_eq!(arrays["displacement"].len(), 3 * 121);
        assert_eq!(arrays["connectivity"].len(), 3 * 200);
        assert!(arrays["types"].iter().all(|&t| t == 5.0));
        for name in [
            "offsets",
            "von_mises",
            "principal_1",
            "principal_2",
            "principal_strain_1",
            "principal_strain_2",
            "wrinkling_state",
        ] {
            assert_eq!(arrays[name].len(), 200, "{name}");
        }
        for name in ["stress", "strain", "tension_direction"] {
            assert_eq!(arrays[name].len(), 3 * 200, "{name}");
        }
        assert!(arrays["wrinkling_state"].iter().all(|&s| s >= 0.0));
        assert!(
            arrays["von_mises"].iter().all(|&s| s > 0.0),
            "no zero filler"
        );

        let gaps = read_vtu(&vtk::gap_grid(model, u, &results, encoding));
        assert_eq!((gaps.points, gaps.cells), (18, 9), "{encoding:?}");
        let arrays = &gaps.arrays;
        assert!(arrays["types"].iter().all(|&t| t == 3.0));
        let lines: Vec<f64> = (0..9).flat_map(|k| [k as f64, 9.0 + k as f64]).collect();
        assert_eq!(arrays["connectivity"], lines);
        for (k, g) in model.gaps.iter().enumerate() {
            assert_eq!(arrays["film_node"][k], g.film_node as f64);
            let n = g.film_node;
            for i in 0..3 {
                assert_eq!(
                    arrays["points"][3 * k + i],
                    model.nodes[n][i] + u[3 * n + i]
                );
            }
            let r = &results.gaps[k];
            assert_eq!(arrays["gap_slip_x"][k], r.slip_x);
            assert_eq!(arrays["gap_normal_force"][k], r.normal_force);
            assert_eq!(arrays["gap_status"][k], r.status as i32 as f64);
        }
        for name in ["gap_slip_y", "gap_friction_force"] {
            assert_eq!(arrays[name].len(), 9, "{name}");
        }
        assert!(!arrays.contains_key("von_mises") && !arrays.contains_key("displacement"));
    }
    assert!(vtk::collection(&[(0.5, "a.vtu".into())]).contains("timestep=\"0.5\""));
    assert_eq!(
        vtk::state_file_name("M", vtk::Block::Gaps, 7),
        "M_gaps_0007.vtu"
    );
    assert_eq!(
        vtk::collection_file_name("M", vtk::Block::Film),
        "M_film.pvd"
    );
}

#[test]
fn binary_vtu_round_trips_points_and_fields() {
    use membrane_contact::mech::results::vtk::{self, Encoding};
    let (a, results) = specimen_state();
    let (model, u) = (a.model(), &a.state().displacement);
    let binary = vtk::film_grid(model, u, &results, Encoding::Binary);
    let ascii = vtk::film_grid(model, u, &results, Encoding::Ascii);
    let (b, t) = (read_vtu(&binary), read_vtu(&ascii));
    // ASCII writes shortest round-trip floats: both encodings hold the same bits.
    assert_eq!(b.arrays, t.arrays);
    let points: Vec<f64> = model
        .nodes
        .iter()
        .flatten()
        .zip(u)
        .map(|(x, u)| x + u)
        .collect();
    assert_eq!(b.arrays["points"], points);
    assert_eq!(b.arrays["displacement"], u[..3 * model.nodes.len()]);
    let field = |f: fn(&membrane_contact::mech::elements::triangle::ElementStress) -> Vec<f64>| -> Vec<f64> {
        results.elements.iter().flat_map(f).collect()
    };
    assert_eq!(b.arrays["von_mises"], field(|e| vec![e.von_mises]));
    assert_eq!(b.arrays["stress"], field(|e| e.stress.to_vec()));
    assert_eq!(b.arrays["strain"], field(|e| e.strain.to_vec()));
    // Principal strains: invariants of the Voigt strain (trace, and e1 ≥ e2).
    for (e, s) in results.elements.iter().enumerate() {
        let (e1, e2) = (
            b.arrays["principal_strain_1"][e],
            b.arrays["principal_strain_2"][e],
        );
        assert!(e1 >= e2 && (e1 + e2 - s.strain[0] - s.strain[1]).abs() < 1e-15);
        let det = s.strain[0] * s.strain[1] - 0.25 * s.strain[2] * s.strain[2];
        assert!((e1 * e2 - det).abs() < 1e-12 * (e1 * e1 + e2 * e2).max(1e-30));
    }
    assert!(
        binary.len() * 3 < ascii.len() * 2,
        "binary {} bytes, ascii {} bytes",
        binary.len(),
        ascii.len()
    );
    let gaps = vtk::gap_grid(model, u, &results, Encoding::Binary);
    let ascii_gaps = vtk::gap_grid(model, u, &results, Encoding::Ascii);
    assert_eq!(read_vtu(&gaps).arrays, read_vtu(&ascii_gaps).arrays);
}

/// A small deterministic generator (xorshift) so the randomized checks are reproducible.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

#[test]
fn tangent_matches_finite_difference_on_random_triangles_and_states() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut checked = 0;
    while checked < 60 {
        let x = [0, 1, 2].map(|_| Vector3::new(rng.next(), rng.next(), 0.3 * rng.next()));
        let Ok(tri) = MembraneTriangle::new(x) else {
            continue;
        };
        if tri.area() < 0.05 {
            continue; // keep the finite difference well conditioned
        }
        let mat = Material {
            prestress: [
                1e6 * rng.next().abs(),
                1e6 * rng.next().abs(),
                3e5 * rng.next(),
            ],
            ..etfe()
        };
        let u = ElementVector::from_fn(|_, _| 0.1 * rng.next());
        let k = tri.tangent_stiffness(&mat, &u);
        let h = 1e-7;
        for j in 0..9 {
            let (mut up, mut um) = (u, u);
            up[j] += h;
            um[j] -= h;
            let column =
                (tri.internal_force(&mat, &up) - tri.internal_force(&mat, &um)) / (2.0 * h);
            let err = (column - k.column(j)).amax();
            assert!(
                err < 1e-5 * k.amax(),
                "triangle {x:?}, dof {j}: {err:e} vs {:e}",
                k.amax()
            );
        }
        checked += 1;
    }
}

#[test]
fn gap_tangent_matches_finite_difference_on_random_states_of_both_laws() {
    let mut rng = Rng(0x2545_F491_4F6C_DD1D);
    for friction_law in FrictionLaw::ALL {
        let mut seen = std::collections::HashSet::new();
        let mut checked = 0;
        while checked < 300 {
            let kn = 1e8 * (1.0 + rng.next().abs());
            let law = GapLaw {
                normal_stiffness: kn,
                tangential_stiffness: kn * (0.05 + 0.2 * rng.next().abs()),
                friction: 0.5 * rng.next().abs(),
                initial_gap: 1e-4 * rng.next().abs(),
                friction_law,
            };
            // Tangential scale spread over two decades so that both stick and slip occur.
            let t = 10f64.powf(-6.0 + 2.0 * rng.next().abs());
            let d = Vector3::new(t * rng.next(), t * rng.next(), 3e-4 * rng.next());
            let history = Vector2::new(0.1 * t * rng.next(), 0.1 * t * rng.next());
            let r = law.evaluate(d, history);
            // Skip points next to the non-smooth surfaces: gap closing, the cone edge (2.13), and
            // for the sliding-direction law |t*_x| = μN, where x starts sliding.
            let gap = law.initial_gap + d.z;
            let limit = law.friction * r.normal_force;
            let trial_x = law.tangential_stiffness * (d.x - history.x);
            if gap.abs() < 1e-6
                || (r.trial_magnitude - limit).abs() < 1e-3 * limit
                || (friction_law == FrictionLaw::SlidingDirection
                    && (trial_x.abs() - limit).abs() < 1e-3 * limit)
            {
                continue;
            }
            let k = law.consistent_tangent(&r);
            let h = 1e-11;
            for j in 0..3 {
                let (mut dp, mut dm) = (d, d);
                dp[j] += h;
                dm[j] -= h;
                let column =
                    (law.evaluate(dp, history).force - law.evaluate(dm, history).force) / (2.0 * h);
                let err = (column - k.column(j)).amax();
                assert!(
                    err < 1e-5 * kn,
                    "{friction_law} {:?} d {d:?}: column {j} off by {err:e}",
                    r.status
                );
            }
            let state = match r.status {
                GapStatus::Slip if friction_law == FrictionLaw::Isotropic => "slip",
                GapStatus::Slip if r.force.x.abs() < limit => "slip by (2.13), x holding",
                GapStatus::Slip if r.force.x > 0.0 => "slip +x",
                GapStatus::Slip => "slip -x",
                other => {
                    if other == GapStatus::Open {
                        "open"
                    } else {
                        "stick"
                    }
                }
            };
            seen.insert(state);
            checked += 1;
        }
        let expected = match friction_law {
            FrictionLaw::Isotropic => 3,
            FrictionLaw::SlidingDirection => 5,
        };
        assert_eq!(
            seen.len(),
            expected,
            "{friction_law}: states checked {seen:?}"
        );
    }
}

// ------------------------------------------------------------------ wrinkling (tension field)
//
// Source: docs/mechanics.md § "Wrinkling: tension-field film" (the formulation, its criterion and tangent). Film
// Y = 1000, ν = 0.3, t = 1 on a unit square unless said.
//
//   n × n unit patch (here n = 4)       boundary nodes: one group each, target = map(X) − X
//   20 - 21 - 22 - 23 - 24              interior nodes: free in x, y; z held (a flat membrane has
//   |  / |  / |  / |  / |               no out-of-plane stiffness across the wrinkles)
//   ...
//   0 -- 1 -- 2 -- 3 -- 4

/// The benchmark film of the note with the tension-field option and regularisation `eta`.
fn tension_field_film(eta: f64, prestress: f64) -> Material {
    Material {
        youngs_modulus: 1000.0,
        poisson_ratio: 0.3,
        thickness: 1.0,
        prestress: [prestress, prestress, 0.0],
        density: 0.0,
        wrinkling: Wrinkling::TensionField,
        yield_stress: None,
        plasticity: None,
        temperature: 23.0,
        wrinkling_regularisation: eta,
    }
}

/// A unit `n × n` patch whose boundary nodes each follow `map` (every boundary node its own
/// group "b<node>"); interior nodes are free in-plane with z held. Returns the model and targets.
fn mapped_boundary_patch(
    n: usize,
    material: Material,
    map: impl Fn(f64, f64) -> [f64; 2],
) -> (Model, Vec<[f64; 3]>) {
    let mut m = patch(n, n, 1.0, 1.0);
    m.material = material;
    let mut targets = vec![];
    for (v, p) in m.nodes.clone().iter().enumerate() {
        let on_boundary = [p[0], p[1]]
            .iter()
            .any(|c| c.abs() < 1e-12 || (c - 1.0).abs() < 1e-12);
        if on_boundary {
            let x = map(p[0], p[1]);
            let target = [x[0] - p[0], x[1] - p[1], 0.0];
            m.groups.push(BoundaryGroup {
                name: format!("b{v}"),
                nodes: vec![v],
                target,
                components: None,
                hinge: None,
            });
            targets.push(target);
        } else {
            m.supports.push(Support {
                node: v,
                fixed: vec![Axis::Z],
                name: None,
            });
        }
    }
    (m, targets)
}

/// Total reaction (x, y) of the boundary groups whose node satisfies `on_edge`.
fn edge_reaction(
    model: &Model,
    reactions: &[[f64; 3]],
    on_edge: impl Fn([f64; 3]) -> bool,
) -> [f64; 2] {
    let mut f = [0.0; 2];
    for (g, group) in model.groups.iter().enumerate() {
        if on_edge(model.nodes[group.nodes[0]]) {
            f[0] += reactions[g][0];
            f[1] += reactions[g][1];
        }
    }
    f
}

#[test]
fn homogeneous_simple_shear_gives_the_tension_field_closed_form() {
    // x = X + γY, y = Y on the whole boundary; every element is wrinkled with (note §2.1)
    // ê1,2 = γ²/4 ± (γ/2)√(1 + γ²/4), θ = 45° + ½ atan(γ/2), S = Y ê1 [c², s², cs],
    // top-edge force Fx = tL(Sxy + γ Syy), Fy = tL Syy; small γ: Sxy → Yγ/4 (Wagner's tension
    // field), not the taut Gγ.
    let (y, nu, gamma) = (1000.0, 0.3, 0.01);
    let (model, targets) = mapped_boundary_patch(4, tension_field_film(1e-5, 0.0), |x, yy| {
        [x + gamma * yy, yy]
    });
    let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
    a.step_to(&targets, 5).unwrap();
    let results = a.results();
    let root = (1.0 + gamma * gamma / 4.0).sqrt();
    let e1 = gamma * gamma / 4.0 + 0.5 * gamma * root;
    let theta = std::f64::consts::FRAC_PI_4 + 0.5 * (gamma / 2.0).atan();
    let (s, c) = theta.sin_cos();
    let exact = [c * c, s * s, c * s].map(|m| y * e1 * m);
    for (i, e) in results.elements.iter().enumerate() {
        assert_eq!(e.state, WrinklingState::Wrinkled, "element {i}");
        for k in 0..3 {
            assert!(
                (e.stress[k] - exact[k]).abs() < 1e-9 * y * e1,
                "element {i}: {:?} vs {exact:?}",
                e.stress
            );
        }
        // The tension rays are F n1 on the deformed film.
        let ray = Vector3::new(c + gamma * s, s, 0.0).normalize();
        assert!(
            (Vector3::from(e.tension_direction) - ray).amax() < 1e-9,
            "{:?}",
            e.tension_direction
        );
        assert!(e.principal[1].abs() < 1e-9 * e.principal[0]);
    }
    let top = edge_reaction(a.model(), &results.reactions, |p| {
        (p[1] - 1.0).abs() < 1e-12
    });
    let (fx, fy) = (exact[2] + gamma * exact[1], exact[1]);
    assert!(
        (top[0] - fx).abs() < 1e-9 * fx && (top[1] - fy).abs() < 1e-9 * fy,
        "{top:?} vs {fx}, {fy}"
    );
    // The note's published figures for these numbers.
    assert!((exact[0] - 2.499969).abs() < 1e-6 && (exact[1] - 2.525094).abs() < 1e-6);
    assert!((exact[2] - 2.512500).abs() < 1e-6);
    assert!((fx - 2.537751).abs() < 1e-6 && (fy - 2.525094).abs() < 1e-6);
    // Wagner's linear tension field Yγ/4 within O(γ); far below the taut shear stress Gγ.
    let g = y / (2.0 * (1.0 + nu));
    assert!((exact[2] - y * gamma / 4.0).abs() < gamma * y * gamma / 4.0);
    assert!(exact[2] < 0.7 * g * gamma);
}

#[test]
fn over_contracted_stretch_is_uniaxial_tension() {
    // x = 1.02 X, y = 0.99 Y: Eyy = −0.00995 < −ν Exx ⇒ wrinkled, Sxx = Y Exx = 20.2,
    // Syy = Sxy = 0, right-edge force λ1 Sxx t L = 20.604 (note §2.2). Without wrinkling the
    // same stretch gives Sxx = 18.918, Syy = −4.275 (compression).
    let run = |wrinkling| {
        let film = Material {
            wrinkling,
            ..tension_field_film(1e-5, 0.0)
        };
        let (model, targets) = mapped_boundary_patch(3, film, |x, y| [1.02 * x, 0.99 * y]);
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        a.step_to(&targets, 2).unwrap();
        let results = a.results();
        let right = edge_reaction(a.model(), &results.reactions, |p| {
            (p[0] - 1.0).abs() < 1e-12
        });
        let text = membrane_contact::mech::results::vtk::film_grid(
            a.model(),
            &a.state().displacement,
            &results,
            membrane_contact::mech::results::vtk::Encoding::Ascii,
        );
        let text = String::from_utf8(text).unwrap();
        (results, right, text)
    };
    let (results, right, text) = run(Wrinkling::TensionField);
    // The VTK cell data carry the state (1 = wrinkled) and the tension direction (global X).
    let array = |name: &str| -> Vec<f64> {
        let start = text.find(&format!("Name=\"{name}\"")).unwrap();
        let body = &text[text[start..].find('>').unwrap() + start + 1..];
        body[..body.find("</DataArray>").unwrap()]
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect()
    };
    assert!(array("wrinkling_state").iter().all(|&s| s == 1.0));
    let directions = array("tension_direction");
    assert_eq!(directions.len(), 3 * results.elements.len());
    assert!(
        directions
            .chunks(3)
            .all(|d| (d[0] - 1.0).abs() < 1e-12 && d[1].abs() < 1e-12)
    );
    let exx = 0.5 * (1.02f64.powi(2) - 1.0);
    for e in &results.elements {
        assert_eq!(e.state, WrinklingState::Wrinkled);
        assert!(
            (e.stress[0] - 1000.0 * exx).abs() < 1e-9 * 20.0,
            "{:?}",
            e.stress
        );
        assert!(
            e.stress[1].abs() < 1e-9 && e.stress[2].abs() < 1e-9,
            "{:?}",
            e.stress
        );
        assert!((Vector3::from(e.tension_direction) - Vector3::x()).amax() < 1e-12);
    }
    assert!((exx * 1000.0 - 20.2).abs() < 1e-9);
    assert!(
        (right[0] - 20.604).abs() < 1e-9 && right[1].abs() < 1e-9,
        "{right:?}"
    );
    let (taut, _, _) = run(Wrinkling::None);
    assert!(
        taut.elements
            .iter()
            .all(|e| e.state == WrinklingState::Taut)
    );
    assert!((taut.elements[0].stress[0] - 18.918).abs() < 1e-3);
    assert!((taut.elements[0].stress[1] + 4.275).abs() < 1e-3);
}

#[test]
fn slack_film_gives_zero_reactions_without_a_singular_solve() {
    // λ1 = 0.99, λ2 = 0.98: both principal strains negative ⇒ slack everywhere, no stress; the
    // interior nodes keep only the η D tangent, which must keep the Newton matrix regular.
    let (model, targets) = mapped_boundary_patch(3, tension_field_film(1e-5, 0.0), |x, y| {
        [0.99 * x, 0.98 * y]
    });
    let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
    let report = a.step_to(&targets, 2).expect("a slack film solves");
    let results = a.results();
    // A slack film has no unique shape: any arrangement of the free nodes in which no element
    // is stretched is in equilibrium. Newton stops at one within its tolerances, so an element
    // may end a hair on the wrinkled side, with a stress of nano-pascals against the taut
    // film's 20 MPa at this strain: the film carries nothing.
    assert!(
        results
            .elements
            .iter()
            .filter(|e| e.state != WrinklingState::Slack)
            .all(|e| e.von_mises < 1e-6 && e.state == WrinklingState::Wrinkled),
        "{:?}",
        results.elements
    );
    assert!(
        results
            .elements
            .iter()
            .filter(|e| e.state == WrinklingState::Slack)
            .all(|e| e.von_mises == 0.0 && e.tension_direction == [0.0; 3])
    );
    assert!(
        results
            .elements
            .iter()
            .filter(|e| e.state == WrinklingState::Slack)
            .count()
            > results.elements.len() / 2
    );
    assert!(
        results.reactions.iter().flatten().all(|r| r.abs() < 1e-8),
        "{:?}",
        results.reactions
    );
    assert!(report.residual < 1e-8, "{}", report.residual);
    // A prestress s0 moves the threshold to Exx = −s0 (1 − ν)/Y: the same film with enough
    // prestress stays taut under this compression.
    let s0 = 20.0; // shift 0.014 > the 0.0199 / 2… strains: Exx = −0.00995, Eyy = −0.0198
    let (model, targets) =
        mapped_boundary_patch(3, tension_field_film(1e-5, s0), |x, y| [0.99 * x, 0.98 * y]);
    let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
    a.step_to(&targets, 2).unwrap();
    let results = a.results();
    assert!(
        results
            .elements
            .iter()
            .all(|e| e.state != WrinklingState::Slack)
    );
}

/// A unit square, bottom edge clamped, top edge moved by (γ, δ), free sides, z held: the
/// realistic shear panel (Wong & Pellegrino 2006), wrinkled in the middle, taut elsewhere.
fn shear_panel(n: usize, material: Material) -> Model {
    let mut m = patch(n, n, 1.0, 1.0);
    m.material = material;
    let top: Vec<usize> = (0..=n).map(|i| n * (n + 1) + i).collect();
    for v in 0..m.nodes.len() {
        let fixed = if v <= n {
            vec![Axis::X, Axis::Y, Axis::Z]
        } else {
            vec![Axis::Z]
        };
        if !top.contains(&v) {
            m.supports.push(Support {
                node: v,
                fixed,
                name: None,
            });
        }
    }
    m.groups.push(BoundaryGroup {
        name: "top".into(),
        nodes: top,
        target: [0.05, 0.005, 0.0],
        components: None,
        hinge: None,
    });
    m
}

fn state_counts(results: &membrane_contact::mech::Results) -> [usize; 3] {
    membrane_contact::mech::elements::triangle::state_counts(&results.elements)
}

#[test]
fn wrinkled_element_carries_no_compression() {
    let settings = SolverSettings {
        max_iterations: 40,
        ..Default::default()
    };
    let run = |wrinkling| {
        let film = Material {
            wrinkling,
            ..tension_field_film(1e-5, 0.5)
        };
        let mut a = Analysis::new(shear_panel(8, film), settings).unwrap();
        a.step_to(&[[0.05, 0.005, 0.0]], 10).unwrap();
        a.results()
    };
    let results = run(Wrinkling::TensionField);
    let [taut, wrinkled, _] = state_counts(&results);
    assert!(wrinkled > 20 && taut > 0, "{:?}", state_counts(&results));
    let largest = results
        .elements
        .iter()
        .fold(0.0_f64, |m, e| m.max(e.principal[0]));
    for e in &results.elements {
        assert!(e.principal[1] >= -1e-12 * largest, "{e:?}");
        if e.state == WrinklingState::Wrinkled {
            assert!(e.principal[1].abs() <= 1e-12 * largest, "{e:?}");
        }
    }
    // The same panel without wrinkling is in compression: the check above can fail.
    let linear = run(Wrinkling::None);
    let most_compressed = linear
        .elements
        .iter()
        .fold(0.0_f64, |m, e| m.min(e.principal[1]));
    assert!(
        most_compressed < -0.1 * largest,
        "{most_compressed} vs {largest}"
    );
}

#[test]
fn regularisation_does_not_change_the_converged_answer() {
    // η enters the Newton matrix only: η and η/10 must converge to the same displacements (to
    // the solver tolerance). A small prestress gives a taut start (without it the slack corners
    // of this panel have no unique displacement, see docs/mechanics.md).
    let settings = SolverSettings {
        max_iterations: 60,
        displacement_tolerance: 1e-10,
        residual_tolerance: 1e-10,
        ..Default::default()
    };
    let run = |eta| {
        let mut a = Analysis::new(shear_panel(8, tension_field_film(eta, 0.5)), settings).unwrap();
        a.step_to(&[[0.05, 0.005, 0.0]], 10).unwrap();
        (a.state().displacement.clone(), a.results())
    };
    let (u1, r1) = run(1e-4);
    let (u2, r2) = run(1e-5);
    let scale = u1.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let du = u1
        .iter()
        .zip(&u2)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        du < 1e-8 * scale,
        "displacements differ by {du:e} (scale {scale:e})"
    );
    assert_eq!(state_counts(&r1), state_counts(&r2));
    let reaction = |r: &membrane_contact::mech::Results| r.reactions[0];
    for k in 0..2 {
        let (a, b) = (reaction(&r1)[k], reaction(&r2)[k]);
        assert!((a - b).abs() < 1e-7 * a.abs().max(b.abs()), "{a} vs {b}");
    }
}

#[test]
fn newton_converges_quadratically_with_wrinkled_and_taut_elements() {
    // η = 0 and a prestress (taut start, note §1.5 option 3): the consistent tension-field tangent
    // makes the last iterations quadratic once the states settle.
    let settings = SolverSettings {
        max_iterations: 40,
        residual_tolerance: 1e-13,
        displacement_tolerance: 1e-13,
        ..Default::default()
    };
    let mut a = Analysis::new(shear_panel(6, tension_field_film(0.0, 0.5)), settings).unwrap();
    a.step_to(&[[0.025, 0.02, 0.0]], 8).unwrap();
    let report = a.step_to(&[[0.03, 0.02, 0.0]], 1).unwrap();
    let [taut, wrinkled, _] = state_counts(&a.results());
    assert!(taut > 0 && wrinkled > 0, "{taut} taut, {wrinkled} wrinkled");
    let r = &report.residual_history;
    let tail: Vec<f64> = r.iter().copied().filter(|v| *v > 1e-11).collect();
    let n = tail.len();
    assert!(n >= 3, "{r:?}");
    let ratios: Vec<f64> = (n - 3..n - 1)
        .map(|k| tail[k + 1] / tail[k].powi(2))
        .collect();
    assert!(
        ratios.iter().all(|c| *c < 10.0),
        "not quadratic: {r:?}, ratios {ratios:?}"
    );
    assert!(r.last().unwrap() / r[0] < 1e-10, "{r:?}");
}

#[test]
fn wrinkling_tangent_matches_finite_difference_in_every_state() {
    // Element level (note §1.7.3): random triangles and displacements, tension-field film with
    // and without prestress, η = 0; points whose state changes under ±h are skipped.
    let mut rng = Rng(0x51_7C_C1_B7_27_22_0A_95);
    let mut seen = [0usize; 3];
    while seen.iter().any(|&n| n < 15) {
        let x = [0, 1, 2].map(|_| Vector3::new(rng.next(), rng.next(), 0.3 * rng.next()));
        let Ok(tri) = MembraneTriangle::new(x) else {
            continue;
        };
        if tri.area() < 0.05 {
            continue;
        }
        let prestress = if rng.next() > 0.0 {
            0.0
        } else {
            5.0 * rng.next().abs()
        };
        let mat = tension_field_film(0.0, prestress);
        let u = ElementVector::from_fn(|_, _| 0.02 * rng.next());
        let state = tri.stress_state(&mat, &u).state;
        let k = tri.tangent_stiffness(&mat, &u);
        let scale = tri.area() * mat.elasticity().amax();
        let h = 1e-7;
        let mut columns = vec![];
        for j in 0..9 {
            let (mut up, mut um) = (u, u);
            up[j] += h;
            um[j] -= h;
            if tri.stress_state(&mat, &up).state != state
                || tri.stress_state(&mat, &um).state != state
            {
                break;
            }
            columns
                .push((tri.internal_force(&mat, &up) - tri.internal_force(&mat, &um)) / (2.0 * h));
        }
        if columns.len() < 9 {
            continue;
        }
        for (j, column) in columns.iter().enumerate() {
            let err = (column - k.column(j)).amax();
            assert!(
                err < 1e-6 * scale,
                "{state:?} dof {j}: {err:e} vs {scale:e}"
            );
        }
        // The regularisation reaches the tangent only, and only off the taut state.
        let regular = Material {
            wrinkling_regularisation: 1e-3,
            ..mat
        };
        assert_eq!(
            tri.internal_force(&regular, &u),
            tri.internal_force(&mat, &u)
        );
        let added = (tri.tangent_stiffness(&regular, &u) - k).amax();
        assert_eq!(added == 0.0, state == WrinklingState::Taut, "{state:?}");
        seen[state as usize] += 1;
    }
}

/// An annular film `a ≤ r ≤ b` (geometric radial spacing, `nr × nt` cells, alternating
/// diagonals): hub nodes one group each ("h<node>"), outer rim clamped, z held elsewhere.
fn annulus(a: f64, b: f64, nr: usize, nt: usize, material: Material) -> Model {
    let mut m = patch(1, 1, 1.0, 1.0);
    m.material = material;
    m.nodes.clear();
    m.triangles.clear();
    let id = |i: usize, j: usize| i * nt + j % nt;
    for i in 0..=nr {
        let r = a * (b / a).powf(i as f64 / nr as f64);
        for j in 0..nt {
            let phi = std::f64::consts::TAU * j as f64 / nt as f64;
            m.nodes.push([r * phi.cos(), r * phi.sin(), 0.0]);
        }
    }
    for i in 0..nr {
        for j in 0..nt {
            let (p, q, r, s) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                m.triangles.extend([[p, q, r], [p, r, s]]);
            } else {
                m.triangles.extend([[p, q, s], [q, r, s]]);
            }
        }
    }
    for j in 0..nt {
        m.groups.push(BoundaryGroup {
            name: format!("h{j}"),
            nodes: vec![id(0, j)],
            target: [0.0; 3],
            components: None,
            hinge: None,
        });
        m.supports.push(Support {
            node: id(nr, j),
            fixed: vec![Axis::X, Axis::Y, Axis::Z],
            name: None,
        });
        for i in 1..nr {
            m.supports.push(Support {
                node: id(i, j),
                fixed: vec![Axis::Z],
                name: None,
            });
        }
    }
    m
}

/// Hub targets for a rigid rotation by `phi` of the hub nodes (the first groups).
fn hub_rotation(model: &Model, phi: f64) -> Vec<[f64; 3]> {
    let (s, c) = phi.sin_cos();
    model
        .groups
        .iter()
        .map(|g| {
            let [x, y, _] = model.nodes[g.nodes[0]];
            [c * x - s * y - x, s * x + c * y - y, 0.0]
        })
        .collect()
}

#[test]
// M_cr = 2π a² t σ0 happens to be 2π N·m here: the literal 6.283 checks the comment's worked
// number, it is not an approximation of τ.
#[allow(clippy::approx_constant)]
fn rotated_hub_wrinkles_at_the_annulus_onset_torque() {
    // In-plane torsion of an annulus (note §2.3; Mikulas 1964, Miller & Hedgepeth 1982): hub
    // a = 0.1, rim b = 0.5, t = 1e-4, Y = 1 GPa, ν = 0.3, σ0 = 1 MPa isotropic. Taut (linear):
    // M = 4π t G φ / (1/a² − 1/b²); τ(r) = M/(2π t r²) in every state; first wrinkles at the hub
    // when τ(a) = σ0: M_cr = 2π a² t σ0 = 6.283 N·m at φ_cr = σ0 (1 − a²/b²)/(2G) = 1.248e-3.
    let (a, b, t, y, nu, s0) = (0.1, 0.5, 1e-4, 1e9, 0.3, 1e6);
    let film = Material {
        youngs_modulus: y,
        poisson_ratio: nu,
        thickness: t,
        prestress: [s0, s0, 0.0],
        density: 0.0,
        yield_stress: None,
        plasticity: None,
        temperature: 23.0,
        wrinkling: Wrinkling::TensionField,
        wrinkling_regularisation: DEFAULT_WRINKLING_REGULARISATION,
    };
    let g = y / (2.0 * (1.0 + nu));
    let (m_cr, phi_cr) = (
        std::f64::consts::TAU * a * a * t * s0,
        s0 * (1.0 - a * a / (b * b)) / (2.0 * g),
    );
    assert!((m_cr - 6.283).abs() < 1e-3 && (phi_cr - 1.248e-3).abs() < 1e-6);
    let model = annulus(a, b, 12, 48, film);
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    // Hub torque from the reactions (the force the hub applies to the film), deformed positions.
    let torque = |analysis: &mut Analysis| {
        let results = analysis.results();
        let m: f64 = (0..model.groups.len())
            .map(|k| {
                let v = model.groups[k].nodes[0];
                let p = Vector3::from(model.nodes[v]) + analysis.node_displacement(v);
                let r = results.reactions[k];
                p.x * r[1] - p.y * r[0]
            })
            .sum();
        (m, results)
    };
    let centroid_radius = |tri: &[usize; 3]| {
        tri.iter()
            .fold(Vector3::zeros(), |s, &v| s + Vector3::from(model.nodes[v]))
            .norm()
            / 3.0
    };
    let mut done = 0.0;
    for fraction in [0.5, 0.9, 1.1, 2.0] {
        let increments = (4.0 * (fraction - done) / 0.5_f64).ceil() as usize;
        done = fraction;
        analysis
            .step_to(&hub_rotation(&model, fraction * phi_cr), increments)
            .unwrap();
        let (m, results) = torque(&mut analysis);
        let [_, wrinkled, slack] = state_counts(&results);
        assert_eq!(slack, 0, "the prestress keeps the radial tension");
        // Tangential equilibrium, ring by ring (96 triangles each), in every state:
        // τ_rθ = −M/(2π t r²) (the hub turns the film counter-clockwise).
        for ring in 0..12 {
            let (mut tau, mut radius) = (0.0, 0.0);
            for e in 96 * ring..96 * (ring + 1) {
                let c = model.triangles[e]
                    .iter()
                    .fold(Vector3::zeros(), |s, &v| s + Vector3::from(model.nodes[v]));
                let th = c.y.atan2(c.x);
                let [sx, sy, sxy] = results.elements[e].stress;
                tau += ((sy - sx) * th.sin() * th.cos() + sxy * (2.0 * th).cos()) / 96.0;
                radius += centroid_radius(&model.triangles[e]) / 96.0;
            }
            let expected = -m / (std::f64::consts::TAU * t * radius * radius);
            assert!(
                (tau - expected).abs() < 0.015 * expected.abs(),
                "φ = {fraction} φ_cr, ring {ring}: τ {tau:e} vs {expected:e}"
            );
        }
        let zone = results
            .elements
            .iter()
            .zip(&model.triangles)
            .filter(|(e, _)| e.state == WrinklingState::Wrinkled)
            .fold(0.0_f64, |r, (_, tri)| r.max(centroid_radius(tri)));
        match fraction {
            // Taut: the linear torque (CST within 2 %), no wrinkles below the onset.
            f if f < 1.0 => {
                assert_eq!(wrinkled, 0, "φ = {f} φ_cr");
                assert!((m / (f * m_cr) - 1.0).abs() < 0.02, "M {m} vs {}", f * m_cr);
            }
            // Just past the onset: wrinkles only in the ring at the hub.
            f if f < 1.5 => assert!(wrinkled > 0 && zone < (b / a).powf(1.0 / 12.0) * a),
            // Well past it: the torque softens below the linear one, and the wrinkled zone
            // reaches about R = √(M/(2π t σ0)) (exact at onset, first estimate beyond).
            f => {
                assert!(m < 0.9 * f * m_cr, "M {m} vs linear {}", f * m_cr);
                let r_estimate = (m / (std::f64::consts::TAU * t * s0)).sqrt();
                assert!(
                    zone < r_estimate && zone > 0.8 * r_estimate,
                    "{zone} vs {r_estimate}"
                );
                assert!(
                    results.elements[..96]
                        .iter()
                        .all(|e| e.state == WrinklingState::Wrinkled)
                );
            }
        }
    }
}

// Issue 12, item 2: models that validate but are singular. Source: statics (a body needs six
// independent restraints; a node without stiffness has none).
//
//   patch 2 × 2 cells, 0.2 m, z = 0 (nodes 0..8 as in `patch`)
//   (a) rim = group, plus node 9 off the film held only by a gap  → Unconnected (node 9)
//   (b) no group, z fixed everywhere, x at nodes 0 and 6          → free along Y
//   (c) held only by three gaps to points (all open at the start) → validates, but the first
//       factorization is singular: the step fails naming nodes, never NaN
#[test]
fn singular_models_are_refused_at_validation_naming_nodes_and_motion() {
    let mut lonely = pressed_node_model(0.0, 0.2);
    lonely.nodes.push([0.1, 0.1, 0.05]);
    lonely
        .gaps
        .push(gap_below("Lonely", 9, [0.1, 0.1, 0.05], 0.0, 0.2));
    let message = lonely.validate().unwrap_err().to_string();
    assert!(
        message.contains("node 9") && message.contains("no triangle"),
        "{message}"
    );

    let mut sliding = patch(2, 2, 0.2, 0.2);
    for v in 0..9 {
        sliding.supports.push(Support {
            node: v,
            fixed: vec![Axis::Z],
            name: None,
        });
    }
    sliding.supports.push(Support {
        node: 0,
        fixed: vec![Axis::X],
        name: None,
    });
    sliding.supports.push(Support {
        node: 6,
        fixed: vec![Axis::X],
        name: None,
    });
    let message = sliding.validate().unwrap_err().to_string();
    assert!(message.contains("can translate along Y"), "{message}");
    assert!(
        message.contains("nodes 0, 1, 2, 3, 4, 5, … (9 nodes)"),
        "{message}"
    );
}

#[test]
fn model_held_only_by_open_gaps_gives_a_finite_answer_or_an_error_naming_nodes() {
    let mut m = patch(2, 2, 0.2, 0.2);
    for (name, v) in [("A", 0), ("B", 2), ("C", 6)] {
        m.gaps.push(gap_below(name, v, m.nodes[v], 0.001, 0.2));
    }
    m.validate().unwrap(); // the documented limit of the structural check: gaps count
    let mut a = Analysis::new(m, SolverSettings::default()).unwrap();
    let before = a.state().clone();
    match a.step_to(&[], 1) {
        // LU may find a tiny pivot instead of a zero one: the rigid position is then arbitrary,
        // but every number is finite.
        Ok(_) => assert!(a.state().displacement.iter().all(|v| v.is_finite())),
        Err(e) => {
            let e = e.to_string();
            assert!(
                e.contains("singular Newton matrix") && e.contains("node "),
                "{e}"
            );
            assert_eq!(a.state(), &before);
        }
    }
}

// Issue 12, item 4: text that goes into modelDescription.xml.
#[test]
fn control_characters_in_the_description_are_refused_naming_the_field() {
    let mut m = pressed_node_model(0.0, 0.2);
    m.description = "line one\nline two\ttabbed, ünïcödé & <xml>".into();
    m.validate().unwrap();
    for bad in ["\u{1}", "\u{7f}", "\u{9b}", "\u{fffe}", "\0"] {
        m.description = format!("a{bad}b");
        let message = m.validate().unwrap_err().to_string();
        assert!(
            message.starts_with("model description: character U+"),
            "{message}"
        );
    }
}

/// Residual and Newton matrix of the refined specimen (1 800 triangles, wrinkling film) with
/// every other gap, curved supports taken from the curved-support variant on the other nodes, a
/// follower pressure and self-weight, at a displacement away from equilibrium: the
/// same bits for 1, 2, 3 and 64 assembly threads (each entry receives the same additions in the
/// same order; 64 parts of a few columns each), for the consistent tangent and the Ju–Rowlands
/// matrix.
#[test]
fn parallel_assembly_is_bit_identical_to_serial_for_every_thread_count() {
    use membrane_contact::mech::LoadLevels;
    use membrane_contact::mech::elements::material::Wrinkling;
    use membrane_contact::mech::model::{AllElements, ElementSelection, PressureSet};
    use membrane_contact::specimens::parallel_arch::SpecimenContact;
    let spec = ParallelArch {
        refinement: 3,
        ..ParallelArch::with_height(0.3)
    };
    let mut model = spec.model().unwrap();
    let curved = ParallelArch {
        contact: SpecimenContact::CurvedSupport,
        ..spec
    }
    .model()
    .unwrap();
    // Every other gap is kept; its neighbours' nodes touch the curved supports instead.
    let mut k = 0;
    model.gaps.retain(|_| {
        k += 1;
        k % 2 == 0
    });
    let with_gap: Vec<usize> = model.gaps.iter().map(|g| g.film_node).collect();
    model.curved_supports = curved.curved_supports.clone();
    for s in &mut model.curved_supports {
        s.nodes.retain(|v| !with_gap.contains(v));
    }
    model.curved_supports.retain(|s| !s.nodes.is_empty());
    assert!(!model.curved_supports.is_empty() && !model.gaps.is_empty());
    model.material.wrinkling = Wrinkling::TensionField;
    model.material.density = 1750.0;
    model.loads.gravity = [0.0, 0.0, -9.81];
    model.loads.pressures.push(PressureSet {
        kind: Default::default(),
        name: "wind".into(),
        elements: ElementSelection::All(AllElements::All),
        pressure: 300.0,
        towards: None,
    });
    let levels = LoadLevels::of_model(&model);
    let u: Vec<f64> = (0..model.dof_count())
        .map(|i| 2e-3 * (i as f64 * 0.37).sin() - 4e-3 * ((i % 3 == 2) as u8 as f64))
        .collect();
    for matrix in [IterationMatrix::Consistent, IterationMatrix::JuRowlands] {
        let run = |threads: usize| {
            let settings = SolverSettings {
                iteration_matrix: matrix,
                threads,
                ..SolverSettings::default()
            };
            let mut analysis = Analysis::new(model.clone(), settings).unwrap();
            assert_eq!(analysis.system().threads(), threads);
            // Some triangles lie across two threads' DOFs: both compute them, each adds its part.
            assert!(threads == 1 || analysis.system().computed_share() > 1.0);
            analysis.residual_and_matrix(&u, &levels)
        };
        let (serial_force, serial_matrix) = run(1);
        assert!(serial_matrix.iter().any(|v| *v != 0.0));
        for threads in [2, 3, 64] {
            let (force, values) = run(threads);
            let same = |a: &[f64], b: &[f64]| {
                a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
            };
            assert!(
                same(&force, &serial_force),
                "{matrix:?}, {threads} threads: forces differ"
            );
            assert!(
                same(&values, &serial_matrix),
                "{matrix:?}, {threads} threads: matrices differ"
            );
        }
    }
}
