//! Properties of the external loads (follower pressure, self-weight, nodal forces), each test
//! named after what it proves.
//!
//! The circular-membrane tests compare with the Föppl–Hencky membrane solution, computed here
//! by shooting on its ODE (see [`hencky`]), which reproduces Hencky's (1915) series coefficient
//! `b0 = 1.7244` and `w0/a = 0.6534 (qa/Et)^{1/3}` for ν = 0.3 (Fichter, NASA TP-3658, 1997).

use membrane_contact::mech::elements::load::{
    ExternalLoad, LoadLevels, Loads, orientation, pressure_force, pressure_signs,
    pressure_stiffness,
};
use membrane_contact::mech::elements::triangle::{ElementVector, Material};
use membrane_contact::mech::model::{
    AllElements, Axis, BoundaryGroup, ElementSelection, ElementSet, ForceSet, LoadSpec, Model,
    OutputPoint, OutputSpec, PressureKind, PressureSet, Side, Support, Towards,
};
use membrane_contact::mech::solve::assembly::{Dof, System};
use membrane_contact::mech::{Analysis, IterationMatrix, SolverSettings, StepError};
use membrane_contact::specimens::scenarios::CircularMembrane;
use nalgebra::{DMatrix, Vector3};

mod common;
use common::{assert_example_file, film, flat_grid, hencky};

/// A small deterministic generator (xorshift64*) for random configurations.
struct Random(u64);

impl Random {
    /// Uniform in [−1, 1).
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        2.0 * (bits as f64 / (1u64 << 53) as f64) - 1.0
    }
}

/// A flat `lx × ly` patch of `nx × ny` cells (two triangles each, normals +Z), all loads empty.
fn patch(nx: usize, ny: usize, lx: f64, ly: f64) -> Model {
    let (nodes, triangles) = flat_grid(nx, ny, lx, ly);
    Model {
        name: "Patch".into(),
        description: String::new(),
        nodes,
        triangles,
        material: film(1e6),
        supports: vec![],
        symmetry: vec![],
        gaps: vec![],
        groups: vec![],
        loads: LoadSpec::default(),
        outputs: Default::default(),
        cables: vec![],
        curved_supports: vec![],
        chambers: vec![],
        layers: vec![],
        orifices: vec![],
        layer_contacts: vec![],
        frame_axis: None,
    }
}

fn pressure_everywhere(name: &str, p: f64) -> PressureSet {
    PressureSet {
        kind: Default::default(),
        name: name.into(),
        elements: ElementSelection::All(AllElements::All),
        pressure: p,
        towards: None,
    }
}

fn clamp(model: &mut Model, nodes: impl IntoIterator<Item = usize>) {
    for node in nodes {
        model.supports.push(Support {
            node,
            fixed: vec![Axis::X, Axis::Y, Axis::Z],
            name: None,
        });
    }
}

fn random_triangle(rng: &mut Random) -> [Vector3<f64>; 3] {
    let base = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.0, 0.1, 0.0),
        Vector3::new(0.2, 0.9, 0.0),
    ];
    base.map(|x| x + 0.4 * Vector3::new(rng.next(), rng.next(), rng.next()))
}

#[test]
fn pressure_stiffness_matches_central_differences_on_random_deformed_triangles() {
    let mut rng = Random(0x9E37_79B9_7F4A_7C15);
    for _ in 0..50 {
        let x = random_triangle(&mut rng);
        let p = 1e3 * rng.next();
        let k = pressure_stiffness(p, &x);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for j in 0..9 {
            let moved = |s: f64| {
                let mut y = x;
                y[j / 3][j % 3] += s;
                pressure_force(p, &y)
            };
            // K = −∂f/∂x.
            let column = -(moved(h) - moved(-h)) / (2.0 * h);
            for i in 0..9 {
                worst = worst.max((k[(i, j)] - column[i]).abs());
            }
        }
        assert!(
            worst <= 1e-8 * p.abs().max(1.0),
            "K differs from FD by {worst:e} (p = {p})"
        );
        // Unsymmetric in general: the check has teeth.
        assert!((k - k.transpose()).norm() > 1e-3 * k.norm());
    }
}

/// Dense free–free Newton matrix from the system's value array.
fn dense(system: &System, values: &[f64]) -> DMatrix<f64> {
    let n = system.free_count;
    let pattern = system.pattern();
    let mut m = DMatrix::zeros(n, n);
    for j in 0..n {
        for at in pattern.col_ptr()[j]..pattern.col_ptr()[j + 1] {
            m[(pattern.row_idx()[at], j)] = values[at];
        }
    }
    m
}

/// The residual `f_int − f_ext` (all DOFs) and, when asked, the Newton matrix values.
fn residual(
    system: &System,
    loads: &Loads,
    levels: &LoadLevels,
    u: &[f64],
    values: Option<&mut Vec<f64>>,
) -> Vec<f64> {
    let mut r = vec![0.0; u.len()];
    let mut values = values.map(|v| v.as_mut_slice());
    system.assemble(u, &mut r, values.as_deref_mut(), |_, _| {
        unreachable!("no gaps")
    });
    loads.add_to(system, levels, u, &mut r, values);
    r
}

#[test]
fn assembled_tangent_with_pressure_matches_central_differences_of_the_assembled_residual() {
    let mut model = patch(3, 2, 1.5, 1.0);
    // Triangles 1 and 4 wound the other way (normal −Z): the set "oriented" pushes every one of
    // its triangles down, so its pressure is turned on 2 and 5 and not on 1 and 4.
    for e in [1, 4] {
        model.triangles[e].swap(1, 2);
    }
    model.loads.pressures = vec![
        pressure_everywhere("all", 700.0),
        PressureSet {
            kind: Default::default(),
            name: "part".into(),
            elements: ElementSelection::List(vec![0, 3, 4]),
            pressure: -300.0,
            towards: None,
        },
        PressureSet {
            kind: Default::default(),
            name: "oriented".into(),
            elements: ElementSelection::List(vec![1, 2, 4, 5]),
            pressure: 450.0,
            towards: Some(Towards::Side(Side::MinusZ)),
        },
    ];
    assert_eq!(
        pressure_signs(&model, &model.loads.pressures[2]),
        [(1, 1.0), (2, -1.0), (4, 1.0), (5, -1.0)]
    );
    model.material.density = 1750.0;
    model.loads.forces = vec![ForceSet {
        name: "tip".into(),
        nodes: vec![5, 6],
        force: [1.0, -2.0, 3.0],
    }];
    clamp(&mut model, [0, 1, 2, 3, 4]);
    model.validate().unwrap();
    let system = System::new(&model, false).unwrap();
    let loads = Loads::new(&model, &system);
    let levels = LoadLevels::of_model(&model);
    let mut rng = Random(42);
    let u: Vec<f64> = (0..model.dof_count())
        .map(|i| match system.dofs[i] {
            Dof::Free(_) => 0.05 * rng.next(),
            _ => 0.0,
        })
        .collect();
    let mut values = vec![0.0; system.nonzeros()];
    residual(&system, &loads, &levels, &u, Some(&mut values));
    let k = dense(&system, &values);
    let mut fd = DMatrix::zeros(system.free_count, system.free_count);
    let h = 1e-7;
    for (gj, dj) in system.dofs.iter().enumerate() {
        let Dof::Free(j) = *dj else { continue };
        let at = |s: f64| {
            let mut v = u.clone();
            v[gj] += s;
            residual(&system, &loads, &levels, &v, None)
        };
        let (plus, minus) = (at(h), at(-h));
        for (gi, di) in system.dofs.iter().enumerate() {
            if let Dof::Free(i) = *di {
                fd[(i, j)] = (plus[gi] - minus[gi]) / (2.0 * h);
            }
        }
    }
    let error = (&k - &fd).amax();
    assert!(
        error <= 1e-6 * k.amax(),
        "tangent differs from FD by {error:e} (max entry {:e})",
        k.amax()
    );
    assert!(
        (&k - k.transpose()).amax() > 1e-3,
        "pressure made it unsymmetric"
    );

    // The lower-only (Ju–Rowlands) pattern gets the symmetric part of the same matrix.
    let lower = System::new(&model, true).unwrap();
    let mut lower_values = vec![0.0; lower.nonzeros()];
    residual(&lower, &loads, &levels, &u, Some(&mut lower_values));
    let symmetric = 0.5 * (&k + k.transpose());
    let stored = dense(&lower, &lower_values);
    let difference = (stored - symmetric.lower_triangle()).amax();
    assert!(
        difference <= 1e-9 * k.amax(),
        "lower part differs by {difference:e}"
    );
}

#[test]
fn pressure_on_a_closed_deformed_surface_sums_to_zero() {
    // Octahedron, outward normals, every node moved at random: Σ f = p/6 Σ 2A n = 0.
    let nodes = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let faces = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let mut rng = Random(7);
    let x: Vec<Vector3<f64>> = nodes
        .iter()
        .map(|&p| Vector3::from(p) + 0.3 * Vector3::new(rng.next(), rng.next(), rng.next()))
        .collect();
    let mut total = Vector3::zeros();
    let mut outward = 0.0;
    for f in faces {
        let xf = f.map(|v| x[v]);
        let force = pressure_force(2.5e3, &xf);
        for a in 0..3 {
            total += Vector3::new(force[3 * a], force[3 * a + 1], force[3 * a + 2]);
            outward += Vector3::new(force[3 * a], force[3 * a + 1], force[3 * a + 2]).dot(&xf[a]);
        }
    }
    assert!(total.norm() < 1e-10 * 2.5e3, "net force {total}");
    assert!(outward > 0.0, "positive pressure pushes outward");
}

#[test]
fn pressure_on_a_flat_plate_totals_p_times_area_along_the_normal() {
    let mut model = patch(4, 3, 2.0, 1.5);
    model.loads.pressures = vec![pressure_everywhere("top", 120.0)];
    let system = System::new(&model, false).unwrap();
    let loads = Loads::new(&model, &system);
    let u = vec![0.0; model.dof_count()];
    let mut r = vec![0.0; u.len()];
    loads.add_to(&system, &LoadLevels::of_model(&model), &u, &mut r, None);
    let total: Vector3<f64> = (0..model.nodes.len())
        .map(|v| -Vector3::new(r[3 * v], r[3 * v + 1], r[3 * v + 2]))
        .sum();
    let expected = Vector3::new(0.0, 0.0, 120.0 * 2.0 * 1.5);
    assert!(
        (total - expected).norm() < 1e-10 * expected.norm(),
        "{total}"
    );
    // An element set covers only its triangles (the element vector of each is p A / 3 per node).
    let x = model.triangles[0].map(|v| Vector3::from(model.nodes[v]));
    let one = pressure_force(120.0, &x);
    let area = 0.5 * (x[1] - x[0]).cross(&(x[2] - x[0])).norm();
    assert!((one.sum() - 120.0 * area).abs() < 1e-12);
    assert_eq!(
        one,
        ElementVector::from_fn(|i, _| if i % 3 == 2 { 40.0 * area } else { 0.0 })
    );
}

#[test]
fn self_weight_totals_density_thickness_area_gravity_and_balances_the_reactions() {
    let mut model = patch(4, 2, 2.0, 1.0);
    model.material.density = 1750.0;
    model.loads.gravity = [0.5, 0.0, -9.81];
    let edges: Vec<usize> = (0..model.nodes.len())
        .filter(|&v| v % 5 == 0 || v % 5 == 4)
        .collect();
    clamp(&mut model, edges);
    let mass = 1750.0 * 2.0e-4 * 2.0;
    let analysis_model = model.clone();
    let mut analysis = Analysis::new(analysis_model, SolverSettings::default()).unwrap();
    assert!((analysis.loads().mass() - mass).abs() < 1e-12 * mass);
    let target = LoadLevels::of_model(&model);
    analysis.step_to_with_loads(&[], &target, 4).unwrap();
    assert_eq!(analysis.state().loads, target);
    // The supports carry the weight: Σ residual over fixed DOFs = −(m g) … reaction = f_int − f_ext.
    let system = analysis.system().clone();
    let loads = analysis.loads().clone();
    let u = analysis.state().displacement.clone();
    let r = residual(&system, &loads, &target, &u, None);
    let mut reaction = Vector3::zeros();
    for (i, d) in system.dofs.iter().enumerate() {
        if *d == Dof::Fixed {
            reaction[i % 3] += r[i];
        }
    }
    let weight = Vector3::from(model.loads.gravity) * mass;
    assert!(
        (reaction + weight).norm() < 1e-6 * weight.norm(),
        "reaction {reaction} vs weight {weight}"
    );
    // The sag is downward.
    assert!(analysis.node_displacement(7).z < 0.0);
}

#[test]
fn nodal_forces_act_on_each_node_of_the_set_and_group_reactions_balance_them() {
    let mut model = patch(2, 2, 1.0, 1.0);
    model.groups = vec![BoundaryGroup {
        name: "edge".into(),
        nodes: vec![0, 1, 2, 3, 5, 6, 7, 8],
        target: [0.0; 3],
        components: None,
        hinge: None,
    }];
    model.loads.forces = vec![ForceSet {
        name: "hook".into(),
        nodes: vec![4],
        force: [0.0, 0.0, 3.0],
    }];
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let levels = LoadLevels::of_model(&model);
    analysis
        .step_to_with_loads(&[[0.0; 3]], &levels, 2)
        .unwrap();
    let results = analysis.results();
    let reaction = results.reactions[0];
    assert!((reaction[2] + 3.0).abs() < 1e-6, "{reaction:?}");
    assert!(analysis.node_displacement(4).z > 0.0);
    // The old entry point keeps the loads where they are.
    analysis.step_to(&[[0.0, 0.0, 0.001]], 2).unwrap();
    assert_eq!(analysis.state().loads, levels);
}

#[test]
fn hencky_ode_reproduces_the_published_coefficients() {
    let (s0, cw, _) = hencky(0.3, 0.0);
    assert!((4.0 * s0 - 1.7244).abs() < 2e-4, "b0 = {}", 4.0 * s0);
    assert!((cw - 0.6534).abs() < 2e-4, "w0 coefficient {cw}");
}

/// A disc of radius `a` in `rings` rings (scenarios.rs), rim held, no pressure yet.
fn disc(a: f64, rings: usize, material: Material) -> Model {
    CircularMembrane {
        radius: a,
        rings,
        material,
        pressure: 0.0,
    }
    .model()
    .unwrap()
}

/// Centre deflection and mean in-plane stress of the centre triangles after pressure `q`,
/// reached in steps to the fractions `path` of it (one increment each, cut back as needed).
fn inflate(model: &Model, q: f64, path: &[f64]) -> (f64, f64) {
    let mut model = model.clone();
    model.loads.pressures = vec![pressure_everywhere("top", q)];
    inflate_as_given(&model, path)
}

/// [`inflate`] with the model's own pressure sets.
fn inflate_as_given(model: &Model, path: &[f64]) -> (f64, f64) {
    let model = model.clone();
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let full = LoadLevels::of_model(&model);
    for &fraction in path {
        analysis
            .step_to_with_loads(&[[0.0; 3]], &full.scaled(fraction), 1)
            .unwrap();
    }
    let results = analysis.results();
    let centre: Vec<f64> = model
        .triangles
        .iter()
        .zip(&results.elements)
        .filter(|(t, _)| t.contains(&0))
        .map(|(_, e)| 0.5 * (e.stress[0] + e.stress[1]))
        .collect();
    (
        analysis.node_displacement(0).z,
        centre.iter().sum::<f64>() / centre.len() as f64,
    )
}

#[test]
fn hencky_clamped_circular_membrane_matches_the_closed_form_within_one_percent() {
    let (a, q) = (1.0, 20.0);
    // A prestress of 1e-4 of the centre stress only gives Newton a start (a flat film without
    // one has no transverse stiffness); the reference includes it exactly.
    let m = film(100.0);
    let (e, t, nu) = (m.youngs_modulus, m.thickness, m.poisson_ratio);
    let stress_scale = (e * q * q * a * a / (t * t)).cbrt();
    let (s0, cw, _) = hencky(nu, 100.0 / stress_scale);
    // A flat film is stiffened only by the deflection, `q ∝ w³`: a load growing tenfold per step
    // lets Newton start near each answer (w grows 2.15× per step).
    let path: Vec<f64> = (0..=6).map(|k| 10f64.powi(k - 6)).collect();
    let (w0, sigma0) = inflate(&disc(a, 24, m), q, &path);
    let w_ref = a * (q * a / (e * t)).cbrt() * cw;
    let sigma_ref = s0 * stress_scale;
    let (w_err, s_err) = (w0 / w_ref - 1.0, sigma0 / sigma_ref - 1.0);
    println!(
        "Hencky: w0 = {w0:.6e} m vs {w_ref:.6e} m ({:+.3}%), σ0 = {sigma0:.6e} Pa vs {sigma_ref:.6e} Pa ({:+.3}%); \
         published 0.6534·a(qa/Et)^⅓ = {:.6e} m",
        100.0 * w_err,
        100.0 * s_err,
        0.6534 * a * (q * a / (e * t)).cbrt()
    );
    assert!(w_err.abs() < 0.01, "w0 error {:.3}%", 100.0 * w_err);
    assert!(s_err.abs() < 0.01, "σ0 error {:.3}%", 100.0 * s_err);
}

#[test]
fn prestressed_circular_membrane_matches_the_foppl_hencky_solution_and_its_linear_limit() {
    let (a, sigma_pre) = (1.0, 1.0e6);
    let m = film(sigma_pre);
    let (e, t, nu) = (m.youngs_modulus, m.thickness, m.poisson_ratio);
    let model = disc(a, 24, m);
    for (q, limit_tolerance) in [(1.0, 0.002), (20.0, f64::INFINITY)] {
        let stress_scale = (e * q * q * a * a / (t * t)).cbrt();
        let (_, cw, _) = hencky(nu, sigma_pre / stress_scale);
        let w_ref = a * (q * a / (e * t)).cbrt() * cw;
        // Small load: the prestress carries it, w0 = q a²/(4 N0) (linear membrane, N0 = σ0 t).
        let w_linear = q * a * a / (4.0 * sigma_pre * t);
        let (w0, _) = inflate(&model, q, &[0.5, 1.0]);
        println!(
            "prestressed, q = {q} Pa: w0 = {w0:.6e} m, Föppl–Hencky {w_ref:.6e} m ({:+.3}%), linear {w_linear:.6e} m",
            100.0 * (w0 / w_ref - 1.0)
        );
        assert!((w0 / w_ref - 1.0).abs() < 0.01);
        assert!((w_ref / w_linear - 1.0).abs() < limit_tolerance);
    }
}

#[test]
fn a_failed_step_with_pressure_keeps_the_last_converged_state_and_load_level() {
    let mut model = disc(1.0, 4, film(1.0e6));
    model.loads.pressures = vec![pressure_everywhere("top", 0.0)];
    let settings = SolverSettings {
        max_iterations: 2,
        max_cutbacks: 0,
        ..SolverSettings::default()
    };
    let mut analysis = Analysis::new(model, settings).unwrap();
    let mut levels = LoadLevels {
        pressure: vec![10.0],
        force: vec![],
        gravity: [0.0; 3],
        chambers: vec![],
        heating: vec![],
        air: vec![],
        time: 0.0,
    };
    analysis
        .set_limits(SolverSettings {
            max_iterations: 50,
            ..settings
        })
        .unwrap();
    analysis
        .step_to_with_loads(&[[0.0; 3]], &levels, 1)
        .unwrap();
    analysis.set_limits(settings).unwrap();
    let before = analysis.state().clone();
    levels.pressure[0] = 1.0e5;
    let error = analysis
        .step_to_with_loads(&[[0.0; 3]], &levels, 1)
        .unwrap_err();
    assert!(matches!(error, StepError::NotConverged { .. }), "{error}");
    assert_eq!(analysis.state(), &before);
    assert_eq!(analysis.state().loads.pressure, vec![10.0]);
    // Non-finite and mis-sized load targets are refused before solving.
    levels.pressure[0] = f64::NAN;
    let error = analysis
        .step_to_with_loads(&[[0.0; 3]], &levels, 1)
        .unwrap_err();
    assert!(
        error.to_string().contains("pressure of set 'top'"),
        "{error}"
    );
    levels.pressure.clear();
    assert!(matches!(
        analysis.step_to_with_loads(&[[0.0; 3]], &levels, 1),
        Err(StepError::InvalidInput { .. })
    ));
    assert_eq!(analysis.state(), &before);
}

#[test]
fn ju_rowlands_matrix_with_the_symmetric_part_reaches_the_same_inflated_state() {
    let mut model = disc(1.0, 6, film(1.0e6));
    model.loads.pressures = vec![pressure_everywhere("top", 50.0)];
    let levels = LoadLevels::of_model(&model);
    let mut deflection = vec![];
    for matrix in [IterationMatrix::Consistent, IterationMatrix::JuRowlands] {
        let settings = SolverSettings {
            iteration_matrix: matrix,
            ..SolverSettings::default()
        };
        let mut analysis = Analysis::new(model.clone(), settings).unwrap();
        analysis
            .step_to_with_loads(&[[0.0; 3]], &levels, 4)
            .unwrap();
        deflection.push(analysis.node_displacement(0).z);
    }
    assert!(
        (deflection[0] - deflection[1]).abs() < 1e-4 * deflection[0].abs(),
        "{deflection:?}"
    );
}

/// A disc whose every other triangle is wound the other way (node order 0, 2, 1): half its
/// node-order normals point down.
fn half_flipped(model: &Model) -> Model {
    let mut model = model.clone();
    for t in model.triangles.iter_mut().step_by(2) {
        t.swap(1, 2);
    }
    model
}

/// With `towards` the pressure pushes every triangle to the named side, so a disc inflates the
/// same whatever its triangles' winding: half of them flipped gives the deflection of the
/// consistently wound disc (to round-off), `"towards": [0, 0, 1]` and `"+z"` alike; without
/// `towards` the flipped half pushes down and the disc barely moves.
#[test]
fn oriented_pressure_deflects_a_disc_the_same_whatever_the_triangles_winding() {
    let base = disc(1.0, 4, film(1e6));
    let path = [0.25, 0.5, 0.75, 1.0];
    let with = |model: &Model, towards: Option<Towards>| {
        let mut model = model.clone();
        model.loads.pressures = vec![PressureSet {
            kind: Default::default(),
            towards,
            ..pressure_everywhere("top", 300.0)
        }];
        model.validate().unwrap();
        inflate_as_given(&model, &path).0
    };
    let reference = with(&base, None);
    assert!(reference > 1e-3, "the disc bulges up: {reference}");
    let flipped = half_flipped(&base);
    for towards in [
        Towards::Direction([0.0, 0.0, 1.0]),
        Towards::Side(Side::PlusZ),
    ] {
        for model in [&base, &flipped] {
            let w = with(model, Some(towards));
            assert!(
                (w - reference).abs() <= 1e-9 * reference,
                "{towards:?}: {w} vs {reference}"
            );
        }
    }
    // Pushing down: the mirror image.
    let down = with(&flipped, Some(Towards::Direction([0.0, 0.1, -2.0])));
    assert!((down + reference).abs() <= 1e-9 * reference, "{down}");
    let unoriented = with(&flipped, None);
    assert!(unoriented.abs() < 0.2 * reference, "{unoriented}");
}

/// A pressure set with flipped triangles and no `towards` is warned about, naming how many of
/// its triangles push against their neighbours; with `towards` (which turns them) and on the
/// consistently wound disc there is no such warning. `orientation` reports the turned count.
#[test]
fn flipped_triangles_in_a_pressure_set_without_towards_are_warned_naming_how_many() {
    use membrane_contact::mech::results::warnings::model_warnings;
    let base = disc(1.0, 4, film(1e6));
    let flipped = half_flipped(&base);
    let count = base.triangles.len();
    let set = |towards| PressureSet {
        kind: Default::default(),
        towards,
        ..pressure_everywhere("top", 300.0)
    };
    let warnings = |model: &Model, towards| {
        let mut model = model.clone();
        model.loads.pressures = vec![set(towards)];
        model.validate().unwrap();
        model_warnings(&model)
    };
    let expected = format!(
        "pressure set 'top': {} of its {count} triangles are pushed to the other side than their neighbours",
        count / 2
    );
    let found = warnings(&flipped, None);
    assert!(found.iter().any(|w| w.starts_with(&expected)), "{found:?}");
    // One flipped triangle is the minority of one.
    let mut one = base.clone();
    one.triangles[7].swap(0, 1);
    let found = warnings(&one, None);
    assert!(
        found
            .iter()
            .any(|w| w.contains(&format!("'top': 1 of its {count} triangles are pushed"))),
        "{found:?}"
    );
    for (model, towards) in [
        (&flipped, Some(Towards::Side(Side::PlusZ))),
        (&base, None),
        (&base, Some(Towards::Side(Side::MinusZ))),
    ] {
        let found = warnings(model, towards);
        assert!(
            !found.iter().any(|w| w.contains("pressure set")),
            "{found:?}"
        );
    }
    let mut model = flipped.clone();
    model.loads.pressures = vec![set(Some(Towards::Side(Side::PlusZ)))];
    let o = orientation(&model, &model.loads.pressures[0]);
    assert_eq!(
        (o.triangles, o.turned, o.against_neighbours),
        (count, count / 2, 0)
    );
    assert!((o.mean_direction[2] - 1.0).abs() < 1e-12, "{o:?}");
}

/// `towards` is read as a vector or a signed axis and written back; an unknown side, a zero
/// direction and a triangle edge-on to the direction are refused naming the set.
#[test]
fn pressure_towards_is_read_checked_and_written() {
    let text = |towards: &str| {
        format!(
            r#"{{"name": "P", "nodes": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]],
            "material": {{"youngs_modulus": 1e9, "poisson_ratio": 0.43, "thickness": 2e-4}},
            "supports": [{{"node": 0, "fixed": ["x","y","z"]}}, {{"node": 1, "fixed": ["x","y","z"]}},
                         {{"node": 2, "fixed": ["x","y","z"]}}],
            "loads": {{"pressures": [{{"name": "top", "elements": "all", "pressure": 1,
                                       "towards": {towards}}}]}}}}"#
        )
    };
    for (given, expect) in [
        ("\"-z\"", Towards::Side(Side::MinusZ)),
        ("[0, 0.5, 2]", Towards::Direction([0.0, 0.5, 2.0])),
    ] {
        let model = Model::from_json(&text(given)).unwrap();
        assert_eq!(model.loads.pressures[0].towards, Some(expect));
        assert_eq!(Model::from_json(&model.to_json()).unwrap(), model);
        // The FMU's input says which way it pushes.
        let description = membrane_contact::fmi2::description::describe(
            &membrane_contact::fmi2::resources::Source::Model(model),
        )
        .unwrap();
        let input = description
            .variables
            .iter()
            .find(|v| v.name == "top.pressure");
        let towards = format!("positive pushes towards {:?}", expect.vector());
        assert!(input.unwrap().description.contains(&towards), "{input:?}");
    }
    for bad in ["\"up\"", "[0, 1]", "3"] {
        let error = Model::from_json(&text(bad)).unwrap_err().to_string();
        assert!(
            error.contains(&format!(
                "towards {} is neither a direction [x, y, z] nor one of \"+x\"",
                bad.replace(' ', "")
            )),
            "{error}"
        );
    }
    let error = Model::from_json(&text("[0, 0, 0]"))
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("pressure set 'top': towards [0.0, 0.0, 0.0] must be a finite, non-zero"),
        "{error}"
    );
    let error = Model::from_json(&text("\"+x\"")).unwrap_err().to_string();
    assert!(
        error.contains("pressure set 'top': triangle 0 is edge-on to towards"),
        "{error}"
    );
}

#[test]
fn load_sets_are_validated_naming_the_bad_item() {
    let base = patch(1, 1, 1.0, 1.0);
    type Change = Box<dyn Fn(&mut Model)>;
    let cases: Vec<(Change, &str)> = vec![
        (
            Box::new(|m| {
                m.loads.pressures = vec![PressureSet {
                    kind: Default::default(),
                    name: "top".into(),
                    elements: ElementSelection::List(vec![0, 5]),
                    pressure: 1.0,
                    towards: None,
                }]
            }),
            "pressure set 'top': triangle 5 does not exist",
        ),
        (
            Box::new(|m| {
                m.loads.pressures = vec![PressureSet {
                    kind: Default::default(),
                    name: "top".into(),
                    elements: ElementSelection::List(vec![]),
                    pressure: 1.0,
                    towards: None,
                }]
            }),
            "pressure set 'top': has no elements",
        ),
        (
            Box::new(|m| m.loads.pressures = vec![pressure_everywhere("top", f64::NAN)]),
            "pressure set 'top' pressure",
        ),
        (
            Box::new(|m| {
                m.loads.forces = vec![ForceSet {
                    name: "f".into(),
                    nodes: vec![9],
                    force: [0.0; 3],
                }]
            }),
            "force set 'f': node 9 does not exist",
        ),
        (
            Box::new(|m| {
                m.loads.pressures = vec![pressure_everywhere("same", 1.0)];
                m.loads.forces = vec![ForceSet {
                    name: "same".into(),
                    nodes: vec![0],
                    force: [0.0; 3],
                }]
            }),
            "force set 'same': name is used twice",
        ),
        (Box::new(|m| m.material.density = -1.0), "density = -1"),
        (
            Box::new(|m| m.loads.gravity = [0.0, f64::INFINITY, 0.0]),
            "loads gravity",
        ),
    ];
    for (change, message) in cases {
        let mut model = base.clone();
        change(&mut model);
        let error = model.validate().unwrap_err().to_string();
        assert!(error.contains(message), "'{error}' lacks '{message}'");
    }
}

#[test]
fn model_files_read_and_write_the_loads_section() {
    let text = r#"{
      "name": "Cushion",
      "nodes": [[0,0,0],[1,0,0],[0,1,0]],
      "triangles": [[0,1,2]],
      "material": {"youngs_modulus": 1e9, "poisson_ratio": 0.43, "thickness": 2e-4, "density": 1750},
      "supports": [{"node": 0, "fixed": ["x","y","z"]}, {"node": 1, "fixed": ["x","y","z"]},
                   {"node": 2, "fixed": ["x","y","z"]}],
      "loads": {
        "pressures": [{"name": "inside", "elements": "all", "pressure": 300},
                      {"name": "wind", "elements": [0], "pressure": -150}],
        "forces": [{"name": "lamp", "nodes": [2], "force": [0, 0, -5]}],
        "gravity": [0, 0, -9.81]
      }
    }"#;
    let model = Model::from_json(text).unwrap();
    assert_eq!(model.loads.pressures.len(), 2);
    assert_eq!(model.material.density, 1750.0);
    assert_eq!(Model::from_json(&model.to_json()).unwrap(), model);
    let levels = LoadLevels::of_model(&model);
    assert_eq!(levels.pressure, vec![300.0, -150.0]);
    assert_eq!(levels.force, vec![[0.0, 0.0, -5.0]]);
    // Unknown fields are refused; a model without loads writes no loads section.
    let typo = text.replace("\"pressure\": 300", "\"presure\": 300");
    assert!(Model::from_json(&typo).is_err());
    let plain = patch(1, 1, 1.0, 1.0);
    assert!(!plain.to_json().contains("loads"));
    assert!(!plain.to_json().contains("density"));
}

/// The example of docs/model-format.md and README: the circular membrane of scenarios.rs with
/// ETFE's density, a pressure and a nodal force. `UPDATE_EXAMPLES=1` rewrites the file.
fn example_membrane() -> Model {
    let mut model = CircularMembrane {
        radius: 1.0,
        rings: 4,
        material: Material {
            density: 1750.0,
            prestress: [0.5e6, 0.5e6, 0.0],
            poisson_ratio: 0.43,
            thickness: 250e-6,
            ..film(0.0)
        },
        pressure: 200.0,
    }
    .model()
    .unwrap();
    model.loads.forces.push(ForceSet {
        name: "lamp".into(),
        nodes: vec![0],
        force: [0.0, 0.0, -5.0],
    });
    model
}

#[test]
fn example_model_file_is_the_generated_circular_membrane_and_runs() {
    let model = example_membrane();
    assert_example_file("circular_membrane.json", &model);
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let levels = LoadLevels::of_model(&model);
    for k in 1..=4 {
        analysis
            .step_to_with_loads(&[[0.0; 3]], &levels.scaled(k as f64 / 4.0), 1)
            .unwrap();
    }
    // The rim carries p A_polygon up, the weight and the lamp down.
    let area = 0.5 * 24.0 * (std::f64::consts::TAU / 24.0).sin();
    let weight = analysis.loads().mass() * 9.81;
    let rz = analysis.results().reactions[0][2];
    assert!(
        (rz + 200.0 * area - weight - 5.0).abs() < 1e-6 * 200.0 * area,
        "{rz}"
    );
    assert!(analysis.node_displacement(0).z > 0.0);
}

/// Two prestressed discs sealed at a common rim (the rim held), the lower one with reversed
/// triangles so that its normals point down: a cushion. A small inside pressure `p` bulges each
/// film into a spherical cap: Laplace `p = 2 N0/R` for a film under tension `N0 = σ_pre t`, so
/// the crown rises `h = a²/(2R) = p a²/(4 N0)` (the linear limit of the prestressed membrane
/// above); the pressures on the closed cushion cancel, so the rim carries no net force.
/// Two copies of the disc `top` sealed at its rim (group `rim`), the lower one with reversed
/// triangles (normals down), under the inside pressure `p` (set `inside`).
fn cushion(top: &Model, p: f64) -> Model {
    let rim: Vec<usize> = top.groups[0].nodes.clone();
    let interior = top.nodes.len() - rim.len();
    let mut model = top.clone();
    model.name = "Cushion".into();
    // The interior nodes are the first ones (ring by ring from the centre): copy them for the
    // lower film.
    assert!(rim.iter().all(|&v| v >= interior));
    model.nodes.extend_from_slice(&top.nodes[..interior]);
    let lower = |v: usize| if v < interior { top.nodes.len() + v } else { v };
    for t in &top.triangles {
        model
            .triangles
            .push([lower(t[0]), lower(t[2]), lower(t[1])]);
    }
    model.loads.pressures = vec![pressure_everywhere("inside", p)];
    model
}

/// `examples/cushion.json`: a round ETFE cushion of 2 m diameter (two 250 µm films, 1 MPa
/// prestress, ETFE density and first yield), its rim clamped in the frame (group `rim`),
/// inflated to 300 Pa (set `inside`), with the crowns and both films as outputs.
fn example_cushion() -> Model {
    let material = Material {
        density: 1750.0,
        prestress: [1.0e6, 1.0e6, 0.0],
        poisson_ratio: 0.43,
        thickness: 250e-6,
        yield_stress: Some(15.0e6),
        plasticity: None,
        temperature: 23.0,
        ..film(0.0)
    };
    let top = disc(1.0, 8, material);
    let mut model = cushion(&top, 300.0);
    model.description =
        "ETFE cushion, 2 m diameter, inflated to 300 Pa (examples/cushion.json)".into();
    let films = top.triangles.len();
    model.outputs = OutputSpec {
        points: vec![
            OutputPoint {
                name: "crownTop".into(),
                node: 0,
            },
            OutputPoint {
                name: "crownBottom".into(),
                node: top.nodes.len(),
            },
        ],
        element_sets: vec![
            ElementSet {
                name: "upper".into(),
                elements: ElementSelection::List((0..films).collect()),
            },
            ElementSet {
                name: "lower".into(),
                elements: ElementSelection::List((films..2 * films).collect()),
            },
        ],
    };
    model
}

#[test]
fn example_cushion_file_is_generated_and_inflates_symmetrically() {
    let model = example_cushion();
    assert_example_file("cushion.json", &model);
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let full = LoadLevels::of_model(&model);
    for k in 1..=5 {
        analysis
            .step_to_with_loads(&[[0.0; 3]], &full.scaled(k as f64 / 5.0), 1)
            .unwrap_or_else(|e| panic!("step {k}: {e}"));
    }
    let results = analysis.results();
    let (up, down) = (results.points[0][2], results.points[1][2]);
    println!("cushion at 300 Pa: crowns {up:.4} m, {down:.4} m");
    // Gravity pulls both films down a little; the pressure pushes them apart symmetrically.
    assert!(up > 0.05 && down < -0.05, "{up} {down}");
    assert!((up + down).abs() < 0.02 * up, "{up} {down}");
}

#[test]
fn inflated_cushion_reaches_the_spherical_cap_and_its_pressure_has_no_resultant() {
    let (a, sigma_pre, p) = (1.0, 1.0e6, 1.0);
    let top = disc(a, 12, film(sigma_pre));
    let model = cushion(&top, p);
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    analysis
        .step_to_with_loads(&[[0.0; 3]], &LoadLevels::of_model(&model), 2)
        .unwrap();
    let cap = p * a * a / (4.0 * sigma_pre * film(sigma_pre).thickness);
    let (up, down) = (
        analysis.node_displacement(0).z,
        analysis.node_displacement(top.nodes.len()).z,
    );
    println!("cushion: crown {up:.6e} m and {down:.6e} m, spherical cap {cap:.6e} m");
    assert!((up / cap - 1.0).abs() < 0.005, "{up} vs {cap}");
    assert!((down / cap + 1.0).abs() < 0.005, "{down} vs {cap}");
    let reaction = analysis.results().reactions[0];
    let pushed = p * std::f64::consts::PI * a * a;
    assert!(
        reaction.iter().all(|r| r.abs() < 1e-6 * pushed),
        "{reaction:?}"
    );
}

/// From a flat prestressed disc, the first full Newton step of a pressure load raises the
/// residual (the film stretches in-plane) before the next ones converge quadratically; the line
/// search keeps such steps where no contact changes status (only a tenfold rise is refused), so
/// each of the five load steps converges in one increment, without a crawl (19 iterations at
/// most measured; a backtracking crawl took hundreds).
#[test]
fn a_pressure_step_from_a_flat_film_converges_in_one_increment_without_a_crawl() {
    let mut model = disc(1.0, 12, film(1.0e6));
    model.loads.pressures = vec![pressure_everywhere("top", 1000.0)];
    let full = LoadLevels::of_model(&model);
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    for k in 1..=5 {
        let report = analysis
            .step_to_with_loads(&[[0.0; 3]], &full.scaled(k as f64 / 5.0), 1)
            .unwrap();
        assert_eq!(report.cutbacks, 0, "step {k}: {report:?}");
        assert!(
            report.total_iterations() <= 25,
            "step {k}: {} iterations",
            report.total_iterations()
        );
    }
}

/// A load per plan area (pressure set `"kind": "plan"`, snow) on a flat patch tilted by `θ`
/// about x totals `s · A cos θ` straight down (the plan area's share, EN 1991-1-3), whatever the
/// triangles' node order; along `towards` when given; carries no stiffness (the residual does
/// not depend on `u`); and balances the reactions of a clamped film at equilibrium. A follower
/// pressure of the same value on the same film totals `s · A` along the normal instead.
#[test]
fn a_load_per_plan_area_totals_its_value_times_the_projected_area_along_its_direction() {
    let (s, theta) = (800.0, 0.5_f64);
    let mut model = patch(4, 3, 2.0, 1.5);
    for p in &mut model.nodes {
        let (y, z) = (p[1], p[2]);
        (p[1], p[2]) = (
            y * theta.cos() - z * theta.sin(),
            y * theta.sin() + z * theta.cos(),
        );
    }
    for t in model.triangles.iter_mut().step_by(3) {
        t.swap(1, 2); // node order does not matter
    }
    let mut snow = pressure_everywhere("snow", s);
    snow.kind = PressureKind::Plan;
    model.loads.pressures = vec![snow.clone()];
    let total = |model: &Model, u: &[f64]| -> Vector3<f64> {
        let system = System::new(model, false).unwrap();
        let loads = Loads::new(model, &system);
        let mut r = vec![0.0; u.len()];
        loads.add_to(&system, &LoadLevels::of_model(model), u, &mut r, None);
        (0..model.nodes.len())
            .map(|v| -Vector3::new(r[3 * v], r[3 * v + 1], r[3 * v + 2]))
            .sum()
    };
    let area = 2.0 * 1.5;
    let still = vec![0.0; model.dof_count()];
    let down = Vector3::new(0.0, 0.0, -s * area * theta.cos());
    assert!((total(&model, &still) - down).norm() < 1e-10 * down.norm());
    let mut rng = Random(5);
    let moved: Vec<f64> = still.iter().map(|_| 0.05 * rng.next()).collect();
    assert_eq!(total(&model, &moved), total(&model, &still), "a dead load");
    // Its tangent is zero: every DOF's residual is the same at any displacement (the central
    // difference of the force is 0 in every component), and it adds nothing to the matrix.
    let system = System::new(&model, false).unwrap();
    let loads = Loads::new(&model, &system);
    let levels = LoadLevels::of_model(&model);
    let residual_at = |u: &[f64]| {
        let mut r = vec![0.0; u.len()];
        let mut values = vec![0.0; system.nonzeros()];
        loads.add_to(&system, &levels, u, &mut r, Some(&mut values));
        assert!(values.iter().all(|&v| v == 0.0), "plan load stiffness");
        r
    };
    assert_eq!(residual_at(&moved), residual_at(&still));
    // Along towards: the area projected on the plane normal to it.
    let mut along_y = model.clone();
    along_y.loads.pressures[0].towards = Some(Towards::Side(Side::PlusY));
    let sideways = Vector3::new(0.0, s * area * theta.sin(), 0.0);
    assert!((total(&along_y, &still) - sideways).norm() < 1e-10 * sideways.norm());
    // The follower pressure of the same value: s A along the normal.
    let mut follower = model.clone();
    follower.loads.pressures[0].kind = PressureKind::Follower;
    follower.loads.pressures[0].towards = Some(Towards::Side(Side::MinusZ));
    let normal = total(&follower, &still);
    assert!(
        (normal.norm() - s * area).abs() < 1e-9 * s * area,
        "{normal}"
    );
    // A clamped film at equilibrium: the rim's reactions carry it.
    let rim: Vec<usize> = (0..model.nodes.len())
        .filter(|&v| v % 5 == 0 || v % 5 == 4)
        .collect();
    clamp(&mut model, rim);
    let mut analysis = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
    let target = LoadLevels::of_model(&model);
    analysis.step_to_with_loads(&[], &target, 4).unwrap();
    let system = analysis.system().clone();
    let r = residual(
        &system,
        analysis.loads(),
        &target,
        &analysis.state().displacement,
        None,
    );
    let mut reaction = Vector3::zeros();
    for (i, d) in system.dofs.iter().enumerate() {
        if *d == Dof::Fixed {
            reaction[i % 3] += r[i];
        }
    }
    assert!(
        (reaction + down).norm() < 1e-6 * down.norm(),
        "{reaction} vs {down}"
    );
    // Read and written by its kind; a follower set writes none.
    let json = serde_json::to_value(&snow).unwrap();
    assert_eq!(json["kind"], "plan");
    assert!(
        serde_json::to_value(pressure_everywhere("p", 1.0))
            .unwrap()
            .get("kind")
            .is_none()
    );
    assert_eq!(serde_json::from_value::<PressureSet>(json).unwrap(), snow);
}
