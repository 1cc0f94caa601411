//! Node-to-surface contact on curved supports (issue 10): `mech::surface` through the solver.
//!
//! TEST GOAL: (1) a film node pressed onto a rigid cylinder and dragged a full quarter-turn
//! around it (its film patch turned about the cylinder's axis by a hinged group) stays at one
//! radius, `r − λN/k_n`, and reports as slip the arc length `r Δφ` of its own position; without
//! friction it follows the turn exactly, with friction it lags and slides at `|T| = μN`; the
//! (2) a strip wrapped half-way round a cylinder and pulled at one end until it slides
//! over every station reaches the capstan ratio of its polygon of stations (within 1 %; the
//! continuous `e^{μθ}` differs from it by the polygon's coarseness), closer than the paper's
//! fixed-frame gaps at the same stations.
//!
//! MODELS: (1) a 3 × 3-node patch (8 triangles, 20 mm) tangent to a cylinder of radius 0.1 m
//! (axis y), its 8 rim nodes one hinged group lowered 2 mm so the film presses the centre node
//! onto the cylinder; (2) a 20 mm wide strip (ν = 0) over a cylinder of radius 0.1 m, `n`
//! stations on the half circle, vertical legs of 0.1 m, the left end held, the right end
//! pulled down.

use membrane_contact::mech::elements::curved_contact::{
    Centreline, CurvedSupport, SurfaceContactResult,
};
use membrane_contact::mech::elements::gap::GapFrame;
use membrane_contact::mech::elements::gap::{FrictionLaw, GapStatus};
use membrane_contact::mech::model::{BoundaryGroup, GapSpec, GapSupport, Hinge, Model};
use membrane_contact::mech::{Analysis, LoadLevels, SolverSettings};
use membrane_contact::specimens::ParallelArch;
use nalgebra::Vector3;

mod common;
use common::film_model;

const R: f64 = 0.1;

fn cylinder(name: &str, nodes: Vec<usize>, mu: f64, kn: f64) -> CurvedSupport {
    CurvedSupport {
        name: name.into(),
        centreline: Centreline::Line {
            point: [0.0, 0.0, 0.0],
            axis: [0.0, 1.0, 0.0],
        },
        tube_radius: R,
        nodes,
        normal_stiffness: kn,
        tangential_stiffness: 0.2 * kn,
        friction: mu,
        friction_law: FrictionLaw::Isotropic,
    }
}

/// The patch: centre node 0 on top of the cylinder, rim nodes 1..=8 around it lowered by `dip`,
/// all rim nodes one group turning about the cylinder's axis.
fn patch(mu: f64) -> Model {
    let mut m = patch_at([0.0, 0.0, R], Some([0.0; 3]));
    m.curved_supports.push(cylinder("drum", vec![0], mu, 1.0e6));
    m
}

/// A 3 × 3-node patch (20 mm) centred on node 0 at `centre`, its rim nodes 1..=8 2 mm lower,
/// all one group (hinged about the y axis through `hinge` when given).
fn patch_at(centre: [f64; 3], hinge: Option<[f64; 3]>) -> Model {
    let (h, dip) = (0.01, 0.002);
    let mut nodes = vec![centre];
    let ring = [
        (1, 0),
        (1, 1),
        (0, 1),
        (-1, 1),
        (-1, 0),
        (-1, -1),
        (0, -1),
        (1, -1),
    ];
    for (i, j) in ring {
        nodes.push([
            centre[0] + i as f64 * h,
            centre[1] + j as f64 * h,
            centre[2] - dip,
        ]);
    }
    let triangles = (0..8).map(|k| [0, 1 + k, 1 + (k + 1) % 8]).collect();
    let mut m = film_model("Patch", nodes, triangles);
    m.groups.push(BoundaryGroup {
        name: "rim".into(),
        nodes: (1..=8).collect(),
        target: [0.0; 3],
        components: None,
        hinge: hinge.map(|point| Hinge {
            point,
            axis: [0.0, 1.0, 0.0],
            target_angle: 0.0,
        }),
    });
    m
}

#[test]
fn node_dragged_a_quarter_turn_round_a_cylinder_keeps_its_radius_and_reports_the_arc_length() {
    for mu in [0.0, 0.3] {
        let m = patch(mu);
        let mut analysis = Analysis::new(m.clone(), SolverSettings::default()).unwrap();
        let loads = LoadLevels::zero(&m);
        let steps = 18;
        let mut radius_seen: Option<f64> = None;
        for k in 1..=steps {
            // The rim turns about +y: a point on top (+z) moves toward +x.
            let theta = std::f64::consts::FRAC_PI_2 * k as f64 / steps as f64;
            analysis
                .step_to_motion(&[[0.0; 3]], &[theta], &loads, 2)
                .unwrap_or_else(|e| panic!("μ = {mu}, step {k}: {e}"));
            let x = Vector3::from(m.nodes[0]) + analysis.node_displacement(0);
            let radius = x.x.hypot(x.z);
            let contact = analysis.results().surface_contacts[0];
            assert!(contact.normal_force > 0.0, "μ = {mu}, step {k}: no contact");
            // The penalty's depth, the same at every step.
            let expected = R - contact.normal_force / 1.0e6;
            assert!(
                (radius - expected).abs() < 1e-12,
                "μ = {mu}, step {k}: {radius} vs {expected}"
            );
            if let Some(first) = radius_seen {
                assert!(
                    (radius - first).abs() < 1e-3 * (R - first),
                    "μ = {mu}: radius drifts"
                );
            }
            radius_seen.get_or_insert(radius);
            // Slip = r × the angle the node has travelled (from +z toward +x about +y).
            let travelled = x.x.atan2(x.z);
            assert!(
                (contact.slip - R * travelled).abs() < 1e-12,
                "μ = {mu}, step {k}: slip {} vs arc {}",
                contact.slip,
                R * travelled
            );
            if mu == 0.0 {
                assert!(
                    (travelled - theta).abs() < 1e-9,
                    "frictionless: follows the turn"
                );
                assert_eq!(contact.friction_force, 0.0);
            } else if k > 2 {
                assert_eq!(contact.status, GapStatus::Slip, "step {k}");
                assert!(
                    (contact.friction_force - mu * contact.normal_force).abs()
                        < 1e-9 * contact.normal_force,
                    "step {k}"
                );
                assert!(travelled < theta, "friction makes the node lag");
            }
        }
        let slip = analysis.results().surface_contacts[0].slip;
        println!(
            "μ = {mu}: slip after a quarter turn {slip:.6} m (r π/2 = {:.6} m)",
            R * std::f64::consts::FRAC_PI_2
        );
        assert!(slip > 0.9 * R * std::f64::consts::FRAC_PI_2);
    }
}

/// The strip: `n` segments on the half circle (stations at θ = 0…π in the x–z plane, 0 at
/// +x), legs of `LEG` down from both ends in `legs` segments; two nodes across (y = 0, W).
const W: f64 = 0.02;
const LEG: f64 = 0.1;

fn strip(n: usize, mu: f64) -> (Model, Vec<usize>) {
    let legs = 4;
    let mut line = vec![];
    // Right leg from the bottom up, the arc from θ = 0 to π, the left leg down.
    for k in 0..legs {
        line.push([R, -LEG * (legs - k) as f64 / legs as f64]);
    }
    for i in 0..=n {
        let th = std::f64::consts::PI * i as f64 / n as f64;
        line.push([R * th.cos(), R * th.sin()]);
    }
    for k in 1..=legs {
        line.push([-R, -LEG * k as f64 / legs as f64]);
    }
    let mut nodes = vec![];
    for p in &line {
        nodes.push([p[0], 0.0, p[1]]);
        nodes.push([p[0], W, p[1]]);
    }
    let mut triangles = vec![];
    for k in 0..line.len() - 1 {
        let (a, b, c, d) = (2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3);
        triangles.push([a, c, d]);
        triangles.push([a, d, b]);
    }
    let mut m = film_model("Capstan", nodes, triangles);
    m.material.poisson_ratio = 0.0;
    m.material.prestress = [1.0e6, 1.0e6, 0.0];
    let last = line.len() - 1;
    for (name, k) in [("pulled", 0), ("held", last)] {
        m.groups.push(BoundaryGroup {
            name: name.into(),
            nodes: vec![2 * k, 2 * k + 1],
            target: [0.0; 3],
            components: None,
            hinge: None,
        });
    }
    let stations: Vec<usize> = (legs..=legs + n).flat_map(|k| [2 * k, 2 * k + 1]).collect();
    m.curved_supports
        .push(cylinder("drum", stations.clone(), mu, 1.0e7));
    (m, stations)
}

/// Tension ratio of a polygon of stations: the end stations turn the strip by Δθ/2, the others
/// by Δθ; at each, `(T_out − T_in) cos(α/2) = μ (T_in + T_out) sin(α/2)`.
fn polygon_ratio(n: usize, mu: f64) -> f64 {
    let q = |alpha: f64| (1.0 + mu * (alpha / 2.0).tan()) / (1.0 - mu * (alpha / 2.0).tan());
    let dt = std::f64::consts::PI / n as f64;
    q(dt).powi(n as i32 - 1) * q(dt / 2.0).powi(2)
}

/// The same strip on the paper's fixed-frame gaps: at each station a gap to the cylinder's
/// surface point, `z` radial and `x` along the circle, fixed at the start (§4.3).
fn strip_on_gaps(n: usize, mu: f64) -> Model {
    let (mut m, stations) = strip(n, mu);
    let drum = m.curved_supports.remove(0);
    for v in stations {
        let p = m.nodes[v];
        let z = Vector3::new(p[0], 0.0, p[2]) / R;
        let x = Vector3::new(-z.z, 0.0, z.x);
        m.gaps.push(GapSpec {
            name: format!("G{v}"),
            film_node: v,
            support: GapSupport::Point(p),
            frame: GapFrame {
                x: x.into(),
                y: z.cross(&x).into(),
                z: z.into(),
            },
            initial_gap: 0.0,
            normal_stiffness: drum.normal_stiffness,
            tangential_stiffness: drum.tangential_stiffness,
            friction: mu,
            friction_law: FrictionLaw::Isotropic,
        });
    }
    m
}

/// Pulls the strip's right end down in steps of 0.5 mm until every station slides (or 20
/// steps); the tension ratio `T2/T1` from the two ends' reactions.
fn pull_until_sliding(m: &Model) -> f64 {
    let mut analysis = Analysis::new(m.clone(), SolverSettings::default()).unwrap();
    let mut ratio = 0.0;
    for k in 1..=20 {
        let pull = -0.0005 * k as f64;
        analysis
            .step_to(&[[0.0, 0.0, pull], [0.0; 3]], 4)
            .unwrap_or_else(|e| panic!("{}, step {k}: {e}", m.name));
        let r = analysis.results();
        let (t2, t1) = (-r.reactions[0][2], -r.reactions[1][2]);
        ratio = t2 / t1;
        let sliding = |s: GapStatus| s == GapStatus::Slip;
        if r.surface_contacts.iter().all(|c| sliding(c.status))
            && r.gaps.iter().all(|g| sliding(g.status))
        {
            break;
        }
    }
    ratio
}

#[test]
fn strip_pulled_over_a_cylinder_reaches_the_capstan_ratio_of_its_stations() {
    let mu = 0.3;
    for n in [6, 12] {
        let (m, _) = strip(n, mu);
        let ratio = pull_until_sliding(&m);
        let gaps = pull_until_sliding(&strip_on_gaps(n, mu));
        let target = polygon_ratio(n, mu);
        let continuous = (mu * std::f64::consts::PI).exp();
        println!(
            "n = {n}: T2/T1 = {ratio:.5} curved support, {gaps:.5} fixed-frame gaps; polygon {target:.5}, e^(μπ) = {continuous:.5}"
        );
        assert!(
            (ratio / target - 1.0).abs() < 0.01,
            "n = {n}: {ratio} vs {target}"
        );
        // The gaps' normals stay where the stations started while the strip stretches and
        // slides along the circle: their ratio is further from the polygon's.
        assert!(
            (ratio - target).abs() < (gaps - target).abs(),
            "n = {n}: curved {ratio}, gaps {gaps}, polygon {target}"
        );
    }
}

#[test]
fn curved_supports_read_from_model_files_and_bad_ones_are_refused_by_name() {
    let m = patch(0.2);
    let text = m.to_json();
    assert!(
        text.contains("\"curved_supports\"") && text.contains("\"line\""),
        "{text}"
    );
    assert_eq!(Model::from_json(&text).unwrap(), m);
    let ring = r#"{"name": "pipe", "centreline": {"circle": {"centre": [0, 0, -2], "axis": [0, 1, 0],
        "radius": 2.1, "angles": [0.5, 2.6]}}, "tube_radius": 0.02, "nodes": [0],
        "normal_stiffness": 1e7, "tangential_stiffness": 1e6, "friction": 0.2,
        "friction_law": "sliding-direction"}"#;
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["curved_supports"]
        .as_array_mut()
        .unwrap()
        .insert(0, serde_json::from_str(ring).unwrap());
    let parsed = Model::from_json(&value.to_string()).unwrap();
    assert_eq!(parsed.curved_supports.len(), 2);
    assert_eq!(
        parsed.curved_supports[0].friction_law,
        FrictionLaw::SlidingDirection
    );
    type Change = Box<dyn Fn(&mut CurvedSupport)>;
    let cases: Vec<(Change, &str)> = vec![
        (
            Box::new(|s| s.tube_radius = 0.0),
            "tube_radius = 0 must be > 0",
        ),
        (Box::new(|s| s.nodes = vec![99]), "node 99"),
        (Box::new(|s| s.nodes.clear()), "lists no nodes"),
        (Box::new(|s| s.friction = -1.0), "friction μ = -1"),
        (
            Box::new(|s| {
                s.centreline = Centreline::Line {
                    point: [0.0; 3],
                    axis: [0.0; 3],
                }
            }),
            "axis is the zero vector",
        ),
        (
            Box::new(|s| {
                s.centreline = Centreline::Line {
                    point: [0.0, 0.0, R],
                    axis: [0.0, 1.0, 0.0],
                }
            }),
            "node 0 lies on the centreline's axis",
        ),
        (
            Box::new(|s| {
                s.centreline = Centreline::Circle {
                    centre: [0.0; 3],
                    axis: [0.0, 1.0, 0.0],
                    radius: 0.1,
                    angles: Some([1.0, 0.5]),
                    start_direction: None,
                }
            }),
            "angles [1, 0.5] must increase",
        ),
    ];
    for (change, expected) in cases {
        let mut bad = patch(0.2);
        change(&mut bad.curved_supports[0]);
        let e = bad.validate().unwrap_err().to_string();
        assert!(
            e.contains("curved support 'drum'") && e.contains(expected),
            "{e}"
        );
    }
    let typo = text.replace("\"tube_radius\"", "\"tube_radios\"");
    assert!(
        Model::from_json(&typo)
            .unwrap_err()
            .to_string()
            .contains("tube_radios")
    );
}

#[test]
fn fmu_reports_each_contact_node_and_states_carry_the_contact_history() {
    use membrane_contact::fmi2::description::describe;
    use membrane_contact::fmi2::resources::Source;
    let m = patch(0.3);
    let d = describe(&Source::Model(m.clone())).unwrap();
    let names: Vec<&str> = d.variables.iter().map(|v| v.name.as_str()).collect();
    for suffix in ["slip", "normalForce", "frictionForce", "status"] {
        assert!(
            names.contains(&format!("drum.node0.{suffix}").as_str()),
            "{suffix}"
        );
    }
    let mut analysis = Analysis::new(m.clone(), SolverSettings::default()).unwrap();
    analysis
        .step_to_motion(&[[0.0; 3]], &[0.3], &LoadLevels::zero(&m), 4)
        .unwrap();
    let saved = analysis.state().clone();
    assert_eq!(saved.contacts[0].status, GapStatus::Slip);
    membrane_contact::fmi2::state::check_analysis_state(&m, &saved).unwrap();
    let mut broken = saved.clone();
    broken.contacts.clear();
    let e = membrane_contact::fmi2::state::check_analysis_state(&m, &broken).unwrap_err();
    assert!(e.contains("curved-support contacts"), "{e}");
    // Continuing from a restored state repeats the original exactly.
    analysis
        .step_to_motion(&[[0.0; 3]], &[0.6], &LoadLevels::zero(&m), 4)
        .unwrap();
    let reference = analysis.results().surface_contacts;
    analysis.set_state(saved).unwrap();
    analysis
        .step_to_motion(&[[0.0; 3]], &[0.6], &LoadLevels::zero(&m), 4)
        .unwrap();
    assert_eq!(analysis.results().surface_contacts, reference);
}

/// TEST GOAL (issue 10 item 3): the specimen with its nine arch nodes in curved-support contact
/// (`contact: curved-support`) runs to the standard target for the three heights and agrees
/// with the paper's fixed-frame gaps where the film touches the arch: the node's travel along the
/// arch (G2, G4 within 10 %: the largest, 7 % at G2 of the 400 mm specimen, whose film slides
/// furthest round the arch) against the gap's local x; the slip (sliding in contact only) is no
/// larger than the travel, and zero at the open G8 while the gap's local x is not.
#[test]
fn specimen_on_curved_supports_agrees_with_the_gaps_where_the_film_touches_the_arch() {
    use membrane_contact::specimens::parallel_arch::SpecimenContact;
    for h in [0.2, 0.3, 0.4] {
        let run = |contact| {
            let spec = ParallelArch {
                contact,
                ..ParallelArch::with_height(h)
            };
            let m = spec.model().unwrap();
            let mut analysis = Analysis::new(m, SolverSettings::default()).unwrap();
            analysis.step_to(&[spec.target()], 20).unwrap();
            let r = analysis.results();
            match contact {
                SpecimenContact::Gaps => r
                    .gaps
                    .iter()
                    .map(|g| (g.slip_x, g.status))
                    .collect::<Vec<_>>(),
                SpecimenContact::CurvedSupport => r
                    .surface_contacts
                    .iter()
                    .map(|c| {
                        assert!(c.slip.abs() <= c.travel.abs() + 1e-12, "H = {h}: {c:?}");
                        (c.travel, c.status)
                    })
                    .collect(),
            }
        };
        let (gaps, curved) = (
            run(SpecimenContact::Gaps),
            run(SpecimenContact::CurvedSupport),
        );
        for k in [1, 3] {
            assert_ne!(curved[k].1, GapStatus::Open, "H = {h}: G{} touches", k + 1);
            assert!(
                (curved[k].0 / gaps[k].0 - 1.0).abs() < 0.10,
                "H = {h}, G{}: {} vs {}",
                k + 1,
                curved[k].0,
                gaps[k].0
            );
        }
        assert!(
            curved[7].0 < gaps[7].0,
            "H = {h}: arc length below the tangent's"
        );
        assert_eq!(curved[7].1, GapStatus::Open, "H = {h}: G8 never touches");
    }
}

/// The Newton matrix assembled with curved-support contacts in slip (specimen, isotropic cone,
/// the 24 mm pipe, the frame lowered 0.8 H) against central differences of the assembled
/// residual, column by column over the contact nodes and their neighbours.
#[test]
fn assembled_tangent_with_sliding_curved_contacts_matches_finite_differences() {
    use membrane_contact::mech::solve::assembly::Dof;
    use membrane_contact::specimens::parallel_arch::SpecimenContact;
    let spec = ParallelArch {
        contact: SpecimenContact::CurvedSupport,
        target_dz_per_height: -0.8,
        ..ParallelArch::with_height(0.3)
    };
    let m = spec.model().unwrap();
    let mut analysis = Analysis::new(m.clone(), SolverSettings::default()).unwrap();
    analysis.step_to(&[spec.target()], 30).unwrap();
    assert!(
        analysis
            .results()
            .surface_contacts
            .iter()
            .filter(|c| c.status == GapStatus::Slip)
            .count()
            >= 4
    );
    let levels = analysis.state().loads.clone();
    // A point a little along the last increment beyond the converged state.
    let mut u = analysis.state().displacement.clone();
    for (x, d) in u.iter_mut().zip(&analysis.state().last_increment) {
        *x += 0.3 * d;
    }
    let (_, values) = analysis.residual_and_matrix(&u, &levels);
    let system = analysis.system().clone();
    let pattern = system.pattern();
    let (ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
    let equation: Vec<Option<usize>> = system
        .dofs
        .iter()
        .map(|d| if let Dof::Free(e) = d { Some(*e) } else { None })
        .collect();
    let dof_of: Vec<usize> = {
        let mut v = vec![0; system.free_count];
        for (i, e) in equation.iter().enumerate() {
            if let Some(e) = e {
                v[*e] = i;
            }
        }
        v
    };
    let contact_nodes = &m.curved_supports[0].nodes;
    let mut worst = 0.0_f64;
    for &node in contact_nodes {
        for c in 0..3 {
            let i = 3 * node + c;
            let Some(col) = equation[i] else { continue };
            let h = 1e-7;
            let mut up = u.clone();
            up[i] += h;
            let (plus, _) = analysis.residual_and_matrix(&up, &levels);
            up[i] -= 2.0 * h;
            let (minus, _) = analysis.residual_and_matrix(&up, &levels);
            let fd: Vec<f64> = plus
                .iter()
                .zip(&minus)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            let mut analytic = vec![0.0; u.len()];
            for k in ptr[col]..ptr[col + 1] {
                analytic[dof_of[rows[k]]] = values[k];
            }
            let scale = analytic.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (r, e) in equation.iter().enumerate() {
                if e.is_some() {
                    worst = worst.max((analytic[r] - fd[r]).abs() / scale);
                }
            }
        }
    }
    println!("largest relative difference {worst:e}");
    assert!(worst < 1e-4, "largest relative difference {worst:e}");
}

#[test]
fn the_friction_law_setting_reaches_curved_supports_too() {
    let mut m = patch(0.3);
    assert_eq!(m.uniform_friction_law(), Some(FrictionLaw::Isotropic));
    m.set_friction_law(FrictionLaw::SlidingDirection);
    assert_eq!(
        m.curved_supports[0].friction_law,
        FrictionLaw::SlidingDirection
    );
    assert_eq!(
        m.uniform_friction_law(),
        Some(FrictionLaw::SlidingDirection)
    );
    use membrane_contact::fmi2::description::describe;
    use membrane_contact::fmi2::resources::Source;
    use membrane_contact::fmi2::variables::Value;
    let d = describe(&Source::Model(m)).unwrap();
    let law = d
        .variables
        .iter()
        .find(|v| v.name == "frictionLaw")
        .unwrap();
    assert_eq!(law.start, Some(Value::String("sliding-direction".into())));
    assert!(d.variables.iter().any(|v| v.name == "mu"));
}

/// A support for the patch's node 0 (`k_n` = 1e6 N/m, `k_s` = 2e5 N/m, isotropic).
fn support_along(name: &str, centreline: Centreline, mu: f64) -> CurvedSupport {
    CurvedSupport {
        centreline,
        ..cylinder(name, vec![0], mu, 1.0e6)
    }
}

/// The closest point of the plane curve `c(u)` (in the x–z plane, `u ∈ [lo, hi]`) to `x`: a
/// dense scan, then bisection (independent of `mech::surface`).
fn closest_on(c: &dyn Fn(f64) -> [f64; 2], lo: f64, hi: f64, x: Vector3<f64>) -> (f64, f64) {
    let dist = |u: f64| {
        let p = c(u);
        (x.x - p[0]).hypot(x.z - p[1])
    };
    let n = 2000;
    let k = (0..=n)
        .min_by(|&i, &j| {
            let u = |i: usize| lo + (hi - lo) * i as f64 / n as f64;
            dist(u(i)).total_cmp(&dist(u(j)))
        })
        .unwrap();
    let step = (hi - lo) / n as f64;
    let (mut a, mut b) = (
        (lo + step * (k as f64 - 1.0)).max(lo),
        (lo + step * (k as f64 + 1.0)).min(hi),
    );
    // Bisection on (x − c)·c′ (c′ by central differences), positive before the minimum.
    let slope = |u: f64| {
        let (p, q, h) = (c(u - 1e-6), c(u + 1e-6), c(u));
        (x.x - h[0]) * (q[0] - p[0]) + (x.z - h[1]) * (q[1] - p[1])
    };
    while b - a > 1e-14 {
        let m = 0.5 * (a + b);
        if slope(m) > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    let u = 0.5 * (a + b);
    (u, dist(u))
}

/// TEST GOAL (issue 10 item 1): a node pressed onto a parabolic arch or a polyline (x–z plane)
/// and dragged along it, with and without friction, stays at `d = r − λN/k_n` from the
/// centreline (its distance found independently) and reports as slip the length travelled on
/// the tube's upper surface: for the parabola `s(u) + r θ(u)` (closed-form arc length
/// `(w√(1+w²) + asinh w)/4k`, `w = 2ku`, turning `θ = atan 2ku`), for the polyline the segments'
/// lengths plus `r ×` the angle turned round each corner.
#[test]
fn node_dragged_along_a_parabola_or_a_polyline_keeps_the_tube_radius_and_reports_the_surface_length()
 {
    let k = 0.3;
    let parabola = Centreline::Parabola {
        apex: [0.0; 3],
        up: [0.0, 0.0, 1.0],
        along: [1.0, 0.0, 0.0],
        half_span: 1.0,
        rise: k,
    };
    let arc = |u: f64| {
        let w = 2.0 * k * u;
        (w * (1.0 + w * w).sqrt() + w.asinh()) / (4.0 * k) + R * w.atan()
    };
    let points = [[-1.0, -0.09], [0.1, 0.01], [0.2, -0.01], [1.0, -0.25]];
    let polyline = Centreline::Polyline {
        points: points.iter().map(|p| [p[0], 0.0, p[1]]).collect(),
        normal: None,
    };
    // The polyline's surface length at the closest point of x (on the side of +z).
    let poly_at = |u: f64| {
        let j = ((0..2).filter(|&j| u > points[j + 1][0]).count()).min(2);
        let (a, b) = (points[j], points[j + 1]);
        let f = (u - a[0]) / (b[0] - a[0]);
        [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
    };
    let slope = |j: usize| (points[j + 1][1] - points[j][1]).atan2(points[j + 1][0] - points[j][0]);
    let poly_length = |x: Vector3<f64>| {
        let (u, _) = closest_on(&poly_at, -1.0, 1.0, x);
        let mut s = 0.0;
        for j in 0..3 {
            let (a, b) = (points[j], points[j + 1]);
            let seg = (b[0] - a[0]).hypot(b[1] - a[1]);
            if j > 0 && (u - a[0]).abs() < 1e-5 {
                // At the vertex a: r × the angle of x − a from the incoming segment's normal.
                let incoming = slope(j - 1);
                let angle = (x.z - a[1]).atan2(x.x - a[0]);
                let psi = incoming + std::f64::consts::FRAC_PI_2 - angle;
                return (s, slope(0) - incoming + psi, true);
            }
            if u < b[0] - 1e-5 {
                let along = ((x.x - a[0]) * (b[0] - a[0]) + (x.z - a[1]) * (b[1] - a[1])) / seg;
                return (s + along, slope(0) - slope(j), false);
            }
            s += seg;
        }
        unreachable!()
    };
    let start_poly = {
        let a = slope(0);
        let p = poly_at(0.0);
        [p[0] - R * a.sin(), 0.0, p[1] + R * a.cos()]
    };
    type Curve<'a> = Box<dyn Fn(f64) -> [f64; 2] + 'a>;
    type Length<'a> = Box<dyn Fn(Vector3<f64>) -> (f64, bool) + 'a>;
    let cases: Vec<(&str, Centreline, [f64; 3], Curve, Length)> = vec![
        (
            "parabola",
            parabola,
            [0.0, 0.0, R],
            Box::new(move |u| [u, -k * u * u]),
            Box::new(move |x| {
                let (u, _) = closest_on(&|u| [u, -k * u * u], -1.0, 1.0, x);
                (arc(u), false)
            }),
        ),
        (
            "polyline",
            polyline,
            start_poly,
            Box::new(poly_at),
            Box::new(|x| {
                let (s, turn, corner) = poly_length(x);
                (s + R * turn, corner)
            }),
        ),
    ];
    for (kind, centreline, start, curve, length) in cases {
        for mu in [0.0, 0.3] {
            let mut m = patch_at(start, None);
            m.curved_supports
                .push(support_along("arch", centreline.clone(), mu));
            let mut analysis = Analysis::new(m.clone(), SolverSettings::default()).unwrap();
            let x0 = Vector3::from(start);
            let (origin, _) = length(x0);
            let mut corners = 0;
            for step in 1..=25 {
                // The rim follows the centreline's height, 10 mm a step.
                let u = 0.01 * step as f64;
                let target = [u, 0.0, curve(u)[1] - curve(0.0)[1]];
                analysis
                    .step_to(&[target], 2)
                    .unwrap_or_else(|e| panic!("{kind} μ = {mu}, step {step}: {e}"));
                let x = x0 + analysis.node_displacement(0);
                let contact = analysis.results().surface_contacts[0];
                assert!(contact.normal_force > 0.0, "{kind} μ = {mu}, step {step}");
                // The polyline's distance exactly: the nearest of its segments' clamped feet.
                let d = match kind {
                    "polyline" => points
                        .windows(2)
                        .map(|w| {
                            let (a, b) = (
                                Vector3::new(w[0][0], 0.0, w[0][1]),
                                Vector3::new(w[1][0], 0.0, w[1][1]),
                            );
                            let f =
                                ((x - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
                            (x - a - (b - a) * f).norm()
                        })
                        .fold(f64::INFINITY, f64::min),
                    _ => closest_on(&*curve, -1.0, 1.0, x).1,
                };
                let expected = R - contact.normal_force / 1.0e6;
                assert!(
                    (d - expected).abs() < 1e-10,
                    "{kind} μ = {mu}, step {step}: distance {d} vs {expected}"
                );
                let (surface, corner) = length(x);
                corners += corner as usize;
                assert!(
                    (contact.slip - (surface - origin)).abs() < 1e-9,
                    "{kind} μ = {mu}, step {step}: slip {} vs {}",
                    contact.slip,
                    surface - origin
                );
                if mu > 0.0 && step > 2 {
                    assert_eq!(contact.status, GapStatus::Slip, "{kind}, step {step}");
                }
            }
            if kind == "polyline" {
                assert!(corners >= 2, "μ = {mu}: {corners} steps ended at a corner");
            }
        }
    }
}

/// TEST GOAL (issue 10 item 1): a polyline inscribed in a circle approaches the circle support
/// as its segments shrink. The patch's node pressed on a ring (centreline radius 0.5 m, tube
/// 0.1 m, μ = 0.3; a soft film, E = 10 MPa, so that the normal force follows the surface's
/// height smoothly) is dragged 0.5 rad round it by the rim's hinge in 10 steps; the same on
/// polylines of `n` segments over the half circle. The largest difference over the steps in
/// normal force shrinks as `(π/n)²`, with the sagitta `Rc (π/n)²/8` by which the polygon's
/// surface dips between its vertices (the film's normal stiffness, ≈ 400 N/m here, turns the
/// dip into force); the slip (surface length) agrees to 3e-4 and better. Measured (printed):
/// n = 32: slip 3.1e-4, normal force 47 %; n = 128: 1.5e-5, 3.4 %; n = 512: 1.0e-5, 0.24 %.
#[test]
fn polyline_inscribed_in_a_circle_converges_to_the_circle_support() {
    let rc = 0.5;
    let run = |centreline: Centreline| {
        let mut m = patch_at([0.0, 0.0, R], Some([0.0, 0.0, -rc]));
        m.material.youngs_modulus = 1.0e7;
        m.curved_supports
            .push(support_along("arch", centreline, 0.3));
        let mut analysis = Analysis::new(m.clone(), SolverSettings::default()).unwrap();
        (1..=10)
            .map(|k| {
                analysis
                    .step_to_motion(&[[0.0; 3]], &[0.05 * k as f64], &LoadLevels::zero(&m), 2)
                    .unwrap_or_else(|e| panic!("step {k}: {e}"));
                analysis.results().surface_contacts[0]
            })
            .collect::<Vec<_>>()
    };
    let circle = run(Centreline::Circle {
        centre: [0.0, 0.0, -rc],
        axis: [0.0, 1.0, 0.0],
        radius: rc,
        angles: None,
        start_direction: None,
    });
    assert!(circle.iter().all(|c| c.status == GapStatus::Slip));
    let mut errors = vec![];
    for n in [32, 128, 512] {
        // Vertices on the circle from −x over the top (a vertex at the top) to +x.
        let points = (0..=n)
            .map(|i| {
                let b = std::f64::consts::PI * (i as f64 / n as f64 - 0.5);
                [rc * b.sin(), 0.0, rc * (b.cos() - 1.0)]
            })
            .collect();
        let poly = run(Centreline::Polyline {
            points,
            normal: None,
        });
        let worst = |f: &dyn Fn(&SurfaceContactResult) -> f64| {
            poly.iter()
                .zip(&circle)
                .map(|(p, c)| (f(p) / f(c) - 1.0).abs())
                .fold(0.0, f64::max)
        };
        let (slip, force) = (worst(&|c| c.slip), worst(&|c| c.normal_force));
        let last = (poly[9], circle[9]);
        println!(
            "n = {n}: largest difference in slip {slip:.2e}, in normal force {force:.2e}; \
             after 0.5 rad slip {:.6} m vs {:.6} m, normal force {:.4} N vs {:.4} N",
            last.0.slip, last.1.slip, last.0.normal_force, last.1.normal_force
        );
        errors.push((slip, force));
    }
    // The force to second order: four times finer, about sixteen times closer (at least
    // eight); the slip within 5e-4 and, from n = 128, 2e-5.
    for w in errors.windows(2) {
        assert!(w[1].1 < w[0].1 / 8.0, "{errors:?}");
    }
    assert!(errors[0].0 < 5e-4, "{errors:?}");
    assert!(errors[1].0 < 2e-5 && errors[2].0 < 2e-5, "{errors:?}");
    assert!(errors[2].1 < 5e-3, "{errors:?}");
}

/// Parabola and polyline centrelines read from a model file; bad ones (and bad tube radii for
/// circles) are refused with a message naming the support and the item.
#[test]
fn parabola_and_polyline_supports_read_from_model_files_and_bad_ones_are_refused_by_name() {
    let mut m = patch(0.2);
    let text = m.to_json();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    let extra = r#"[
      {"name": "arch", "centreline": {"parabola": {"apex": [0, 0, 0], "up": [0, 0, 1],
        "along": [1, 0, 0], "half_span": 1.0, "rise": 0.3}}, "tube_radius": 0.1, "nodes": [0],
        "normal_stiffness": 1e6, "tangential_stiffness": 2e5, "friction": 0.2},
      {"name": "rail", "centreline": {"polyline": {"points": [[-1, 0, 0], [0, 0, 0.01],
        [1, 0, 0]]}}, "tube_radius": 0.09, "nodes": [0],
        "normal_stiffness": 1e6, "tangential_stiffness": 2e5, "friction": 0.2}]"#;
    value["curved_supports"]
        .as_array_mut()
        .unwrap()
        .extend(serde_json::from_str::<Vec<serde_json::Value>>(extra).unwrap());
    let parsed = Model::from_json(&value.to_string()).unwrap();
    assert_eq!(parsed.curved_supports.len(), 3);
    assert_eq!(Model::from_json(&parsed.to_json()).unwrap(), parsed);
    let parabola = |rise: f64, along: [f64; 3]| Centreline::Parabola {
        apex: [0.0; 3],
        up: [0.0, 0.0, 1.0],
        along,
        half_span: 1.0,
        rise,
    };
    let polyline =
        |points: Vec<[f64; 3]>, normal: Option<[f64; 3]>| Centreline::Polyline { points, normal };
    let circle = |radius: f64, angles: Option<[f64; 2]>| Centreline::Circle {
        centre: [0.0, 0.0, -1.0],
        axis: [0.0, 1.0, 0.0],
        radius,
        angles,
        start_direction: None,
    };
    let cases: Vec<(Centreline, &str)> = vec![
        (
            parabola(0.0, [1.0, 0.0, 0.0]),
            "parabola rise = 0 must be > 0",
        ),
        (
            parabola(0.3, [0.0, 0.0, 2.0]),
            "parabola along is zero or parallel to up",
        ),
        (
            // Radius of curvature at the crown 1/(2·6) < r = 0.1.
            parabola(6.0, [1.0, 0.0, 0.0]),
            "smaller than the parabola's radius of curvature",
        ),
        (polyline(vec![[0.0; 3]], None), "polyline has 1 point(s)"),
        (
            polyline(vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], None),
            "points[1] and points[2] coincide",
        ),
        (
            polyline(vec![[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], None),
            "collinear: give its plane's normal",
        ),
        (
            polyline(
                vec![
                    [-1.0, 0.0, 0.0],
                    [0.0, 0.0, 0.1],
                    [1.0, 0.0, 0.0],
                    [2.0, 0.5, 0.0],
                ],
                None,
            ),
            "points[3] leaves the plane",
        ),
        (
            polyline(
                vec![[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
                None,
            ),
            "turns back on itself at points[1]",
        ),
        (
            polyline(vec![[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], Some([0.0; 3])),
            "polyline normal is zero",
        ),
        (
            // Through node 0 at (0, 0, R).
            polyline(vec![[-1.0, 0.0, R], [1.0, 0.0, R]], Some([0.0, 1.0, 0.0])),
            "node 0 lies on the centreline",
        ),
        (circle(0.05, None), "smaller than the circle's radius"),
        (circle(1.0, Some([0.0, 7.0])), "span more than a full turn"),
    ];
    for (centreline, expected) in cases {
        m.curved_supports[0].centreline = centreline;
        let e = m.validate().unwrap_err().to_string();
        assert!(
            e.contains("curved support 'drum'") && e.contains(expected),
            "{expected}: {e}"
        );
    }
}

/// TEST GOAL (issue 10 item 1, end caps): a node dragged past the end of an arc is held by the
/// end's hemispherical cap — its distance from the end point `E` is `r − λN/k_n`, its slip
/// the arc's surface length to `E` plus the distance past the end's normal plane, its normal
/// force falls steadily (measured: 0.97 N at 1.2 mm past the end to 0.01 N at 21.5 mm) —
/// until the film lets it go; every step converges (before, the contact vanished at the end).
#[test]
fn node_dragged_off_an_arc_end_is_held_by_the_cap_then_lets_go() {
    let rc = 0.5;
    let top = -std::f64::consts::FRAC_PI_2;
    let end = top + 0.2;
    let mut m = patch_at([0.0, 0.0, R], Some([0.0, 0.0, -rc]));
    // A soft film (normal stiffness ≈ 400 N/m) presses the node on over a few mm.
    m.material.youngs_modulus = 1.0e7;
    m.curved_supports.push(support_along(
        "arch",
        Centreline::Circle {
            centre: [0.0, 0.0, -rc],
            axis: [0.0, 1.0, 0.0],
            radius: rc,
            angles: Some([top - 0.3, end]),
            start_direction: Some([1.0, 0.0, 0.0]),
        },
        0.0,
    ));
    // φ from +x toward −z (= y × x) about +y; the top is φ = −π/2.
    let radial = Vector3::new(end.cos(), 0.0, -end.sin());
    let e = Vector3::new(0.0, 0.0, -rc) + radial * rc;
    let t_e = Vector3::y().cross(&radial);
    let mut analysis = Analysis::new(m.clone(), SolverSettings::default()).unwrap();
    let (mut on_cap, mut released, mut force) = (0, false, f64::INFINITY);
    // To 0.15 rad in 3 steps, then 1.2 mm of travel a step past the end (at 0.2 rad).
    let angles = (1..=3)
        .map(|k| 0.05 * k as f64)
        .chain((1..=60).map(|k| 0.15 + 0.002 * k as f64));
    for (k, angle) in angles.enumerate() {
        analysis
            .step_to_motion(&[[0.0; 3]], &[angle], &LoadLevels::zero(&m), 2)
            .unwrap_or_else(|e| panic!("step {k}: {e}"));
        let x = Vector3::from(m.nodes[0]) + analysis.node_displacement(0);
        let c = analysis.results().surface_contacts[0];
        if (x - e).dot(&t_e) <= 0.0 {
            continue;
        }
        if c.status == GapStatus::Open {
            assert!((x - e).norm() > R, "step {k}: open inside the cap");
            released = true;
            continue;
        }
        assert!(!released, "step {k}: touches again");
        on_cap += 1;
        println!(
            "step {k}: {:.2} mm past the end, normal force {:.3} N",
            1e3 * (x - e).dot(&t_e),
            c.normal_force
        );
        let expected = R - c.normal_force / 1.0e6;
        assert!(((x - e).norm() - expected).abs() < 1e-12, "step {k}");
        let slip = (rc + R) * 0.2 + (x - e).dot(&t_e);
        assert!(
            (c.slip - slip).abs() < 1e-12,
            "step {k}: {} vs {slip}",
            c.slip
        );
        assert!(
            c.normal_force < force,
            "step {k}: the force grows on the cap"
        );
        force = c.normal_force;
    }
    assert!(
        on_cap >= 10 && released,
        "{on_cap} steps on the cap, released {released}"
    );
}
