//! Arc-length control where a pressure-controlled path passes a limit point (issue 41): an
//! ETFE sphere inflated past its largest pressure, against the closed form of a sphere in
//! equibiaxial tension, `p = 2 N/r` with `N = S t0` (the film's own stress update at the
//! stretch `λ = r/R`).
//!
//! ```text
//!   octant of a sphere of radius R, x, y, z ≥ 0; symmetry planes x = 0, y = 0, z = 0
//!   pressure from inside (follower), the film's outward normals
//! ```

use membrane_contact::mech::elements::material::{DEFAULT_WRINKLING_REGULARISATION, Wrinkling};
use membrane_contact::mech::elements::plasticity::{Hardening, Plasticity};
use membrane_contact::mech::elements::triangle::Material;
use membrane_contact::mech::{Analysis, LoadLevels, StepError};
use membrane_contact::specimens::scenarios::InflatedSphere;
use nalgebra::Vector3;

const R: f64 = 1.0;

/// An octant of 8 × 8 cells of a 200 µm film (E = 1 GPa, ν = 0.43) with the hardening table
/// `hardening`, its pressure set at `pressure`.
fn sphere(hardening: &[[f64; 2]], pressure: f64) -> InflatedSphere {
    InflatedSphere {
        radius: R,
        cells: 8,
        material: Material {
            youngs_modulus: 1.0e9,
            poisson_ratio: 0.43,
            thickness: 200e-6,
            prestress: [0.0; 3],
            density: 0.0,
            wrinkling: Wrinkling::None,
            wrinkling_regularisation: DEFAULT_WRINKLING_REGULARISATION,
            yield_stress: None,
            plasticity: Some(Plasticity {
                hardening: Hardening::new(hardening.to_vec()).unwrap(),
            }),
            temperature: 23.0,
        },
        pressure,
    }
}

/// The closed form's pressures at the stretches `1 + k/20 000` up to 2.
fn closed_form(hardening: &[[f64; 2]]) -> (Vec<f64>, Vec<f64>) {
    let stretches: Vec<f64> = (0..=20_000).map(|k| 1.0 + k as f64 / 20_000.0).collect();
    let p = sphere(hardening, 0.0).closed_form(&stretches).unwrap();
    (stretches, p)
}

/// The first largest pressure of a monotone inflation and its stretch, from the closed form
/// on a grid of stretches up to 2.
fn first_limit(table: &[[f64; 2]]) -> (f64, f64) {
    let (stretches, p) = closed_form(table);
    let k = (1..p.len())
        .find(|&k| p[k] < p[k - 1])
        .expect("a limit point")
        - 1;
    (p[k], stretches[k])
}

/// The mean radius of the inflated octant's nodes.
fn mean_radius(a: &Analysis) -> f64 {
    let nodes = &a.model().nodes;
    (0..nodes.len())
        .map(|v| (Vector3::from(nodes[v]) + a.node_displacement(v)).norm())
        .sum::<f64>()
        / nodes.len() as f64
}

/// The default ETFE curve: σ = 21 MPa + 175 MPa ε̄p.
const ETFE: [[f64; 2]; 2] = [[0.0, 21e6], [1.4547, 275e6]];

/// The sphere's pressure peaks where `dτ/dε = 3τ` (about 97 MPa on the ETFE curve) and falls
/// for ever after: a step to 1.2 times the peak has no equilibrium. Load control refuses the
/// smallest increment near the peak; arc-length control follows the path over it and down, and
/// the step is refused as a limit point at the closed form's largest pressure (the octant of
/// 8 × 8 cells carries 1.1 % more), the step's start kept.
#[test]
fn a_sphere_inflated_past_its_largest_pressure_is_refused_at_the_closed_form_limit() {
    let (peak, stretch) = first_limit(&ETFE);
    assert!((stretch - 1.314).abs() < 0.01, "{stretch}");
    let model = sphere(&ETFE, 1.2 * peak).model().unwrap();
    let levels = LoadLevels::of_model(&model);
    let mut a = Analysis::new(model, Default::default()).unwrap();
    let before = a.state().clone();
    match a.step_to_with_loads(&[], &levels, 10) {
        Err(StepError::LimitPoint { fraction, levels }) => {
            let found = levels.pressure[0];
            eprintln!("burst: limit {found:.1} Pa, closed form {peak:.1} Pa");
            assert!((fraction * 1.2 * peak - found).abs() < 1e-9 * peak);
            assert!(
                (found / peak - 1.0).abs() < 0.015,
                "limit {found} Pa against the closed form's {peak} Pa"
            );
        }
        other => panic!("expected a limit point, got {other:?}"),
    }
    assert_eq!(
        a.state(),
        &before,
        "a refused step keeps the last converged state"
    );
    assert!((mean_radius(&a) - R).abs() < 1e-12);
}

/// A film whose hardening stiffens after a soft stretch (σ = 21 → 30 MPa over ε̄p = 0.3, then
/// to 500 MPa at 0.6): the pressure peaks just after yield, falls, and rises again. A step to
/// 1.1 times the first peak passes the limit point by arc length, down and up the far branch,
/// with no artificial damping, and ends at the closed form's radius for that pressure.
#[test]
fn a_sphere_that_snaps_through_ends_on_the_far_branch_at_the_closed_form_radius() {
    let table = [[0.0, 21e6], [0.3, 30e6], [0.6, 500e6]];
    let (peak, _) = first_limit(&table);
    let target = 1.1 * peak;
    let model = sphere(&table, target).model().unwrap();
    let levels = LoadLevels::of_model(&model);
    let mut a = Analysis::new(model, Default::default()).unwrap();
    let report = a.step_to_with_loads(&[], &levels, 10).unwrap();
    let radius = mean_radius(&a);
    assert_eq!(report.stabilized, 0);
    assert_eq!(report.stabilization_dissipated, 0.0);
    let arc: Vec<_> = report
        .attempts
        .iter()
        .filter(|t| t.strategy == 1 && t.converged)
        .collect();
    assert!(
        arc.iter().any(|t| t.to < t.from),
        "the load factor falls past the limit point: {arc:?}"
    );
    // The far branch: the first stretch whose closed-form pressure reaches the target (above
    // the first peak, so beyond the valley).
    let (stretches, p) = closed_form(&table);
    let far = (0..p.len()).find(|&k| p[k] >= target).unwrap();
    eprintln!(
        "snap: radius {radius:.5} closed form {:.5}",
        stretches[far] * R
    );
    assert!(
        (radius / (stretches[far] * R) - 1.0).abs() < 0.01,
        "radius {radius} against the closed form's {}",
        stretches[far] * R
    );
}
