//! Tests of the plastic film: closed forms and finite-difference tangents in every state.

use super::*;

const E: f64 = 1.0e9;
const NU: f64 = 0.43;

/// The issue's example table.
fn table() -> Hardening {
    Hardening::new(vec![[0.0, 16e6], [0.02, 19e6], [0.15, 24e6], [1.0, 40e6]]).unwrap()
}

fn film(tension_field: bool) -> PlasticFilm {
    PlasticFilm {
        youngs_modulus: E,
        poisson_ratio: NU,
        hardening: table(),
        tension_field,
    }
}

fn virgin() -> PlasticHistory {
    film(false).initial_history([0.0; 3])
}

/// Green strain (Voigt) of the in-plane stretch `U = R diag(l1, l2) Rᵀ`, `R` by `angle`.
fn green(l1: f64, l2: f64, angle: f64) -> Vector3<f64> {
    let (s, c) = angle.sin_cos();
    let (a, b) = (0.5 * (l1 * l1 - 1.0), 0.5 * (l2 * l2 - 1.0));
    Vector3::new(
        a * c * c + b * s * s,
        a * s * s + b * c * c,
        2.0 * (a - b) * s * c,
    )
}

/// The plastic strain `x` on the table at which `x·k + σy(x)·f = target` (a monotone
/// relation between log strain and plastic strain), segment by segment from the rows.
fn plastic_strain_where(k: f64, f: f64, target: f64) -> f64 {
    let rows = table().rows().to_vec();
    for i in 0..rows.len() {
        let slope = if i + 1 < rows.len() {
            (rows[i + 1][1] - rows[i][1]) / (rows[i + 1][0] - rows[i][0])
        } else {
            (rows[i][1] - rows[i - 1][1]) / (rows[i][0] - rows[i - 1][0])
        };
        // x k + f (σ_i + slope (x − x_i)) = target
        let x = (target - f * (rows[i][1] - slope * rows[i][0])) / (k + f * slope);
        let end = rows.get(i + 1).map_or(f64::INFINITY, |r| r[0]);
        if x >= rows[i][0] && x <= end {
            return x;
        }
    }
    unreachable!()
}

fn table_stress(x: f64) -> f64 {
    let rows = table().rows().to_vec();
    let i = rows
        .iter()
        .rposition(|r| r[0] <= x)
        .unwrap()
        .min(rows.len() - 2);
    rows[i][1] + (rows[i + 1][1] - rows[i][1]) / (rows[i + 1][0] - rows[i][0]) * (x - rows[i][0])
}

/// Central-difference `∂S/∂E`, or `None` if a perturbation changes the state or crosses a
/// row of the table.
fn fd_tangent(f: &PlasticFilm, h: &PlasticHistory, strain: &Vector3<f64>) -> Option<Matrix3<f64>> {
    let base = f.response(h, strain);
    let segment = |r: &PlasticResponse| table().segment(r.history.equivalent_plastic_strain).0[0];
    let step = 1e-7;
    let mut t = Matrix3::zeros();
    for j in 0..3 {
        let (mut p, mut m) = (*strain, *strain);
        p[j] += step;
        m[j] -= step;
        let (rp, rm) = (f.response(h, &p), f.response(h, &m));
        for r in [&rp, &rm] {
            if r.state != base.state || r.yielding != base.yielding || segment(r) != segment(&base)
            {
                return None;
            }
        }
        t.set_column(j, &((rp.stress - rm.stress) / (2.0 * step)));
    }
    Some(t)
}

/// The history left by straining a virgin film to `strain` in one increment.
fn yielded(f: &PlasticFilm, strain: Vector3<f64>) -> PlasticHistory {
    let r = f.response(&virgin(), &strain);
    assert!(r.yielding);
    r.history
}

fn assert_tangent(
    f: &PlasticFilm,
    h: &PlasticHistory,
    strain: Vector3<f64>,
    state: WrinklingState,
    yielding: bool,
) {
    let (r, tangent) = f.response_and_tangent(h, &strain);
    assert_eq!((r.state, r.yielding), (state, yielding), "at {strain:?}");
    assert_eq!(
        r,
        f.response(h, &strain),
        "plain and dual evaluations agree"
    );
    let fd = fd_tangent(f, h, &strain).expect("state stable under the perturbation");
    let err = (fd - tangent).amax();
    assert!(
        err < 1e-6 * E,
        "{state:?} yielding {yielding} at {strain:?}: error {err:e}\n{tangent}\n{fd}"
    );
}

/// One point in each state: (film, history, strain, expected state, yielding).
fn every_state() -> Vec<(
    PlasticFilm,
    PlasticHistory,
    Vector3<f64>,
    WrinklingState,
    bool,
)> {
    use WrinklingState::*;
    let (j2, tf) = (film(false), film(true));
    let v = virgin();
    let loaded = Vector3::new(0.1, -0.03, 0.02);
    let h = yielded(&j2, loaded);
    let w = Vector3::new(0.2, -0.1, 0.03);
    let hw = tf.response(&v, &w).history;
    assert!(hw.equivalent_plastic_strain > 0.05);
    vec![
        // Elastic from virgin (also at exactly zero strain: equal principal stretches).
        (j2, v, Vector3::new(0.005, 0.002, 0.001), Taut, false),
        (j2, v, Vector3::zeros(), Taut, false),
        // Plastic loading, from virgin and from a yielded history; equibiaxial (degenerate).
        (j2, v, loaded, Taut, true),
        (j2, h, Vector3::new(0.13, -0.02, 0.05), Taut, true),
        (j2, h, green(1.2, 1.2, 0.0), Taut, true),
        // Elastic unloading of a yielded point, and compression past zero.
        (j2, h, Vector3::new(0.09, -0.03, 0.02), Taut, false),
        (j2, h, Vector3::new(0.08, -0.035, 0.018), Taut, false),
        // Tension field: wrinkled (elastic, plastic, unloading a yielded point), taut plastic,
        // slack with a yielded history.
        (tf, v, Vector3::new(0.005, -0.01, 0.002), Wrinkled, false),
        (tf, v, w, Wrinkled, true),
        (tf, hw, Vector3::new(0.18, -0.1, 0.03), Wrinkled, false),
        (tf, hw, Vector3::new(0.25, -0.12, 0.05), Wrinkled, true),
        (tf, v, Vector3::new(0.1, 0.08, 0.01), Taut, true),
        (tf, hw, Vector3::new(0.05, -0.1, 0.0), Slack, false),
    ]
}

#[test]
fn algorithmic_tangent_matches_finite_differences_in_every_state() {
    for (f, h, strain, state, yielding) in every_state() {
        assert_tangent(&f, &h, strain, state, yielding);
    }
}

/// Largest difference between the closed-form evaluation and the dual-number reference
/// (`reference.rs`) at one point, relative to the stress (tangent) scale; the state and
/// whether the point flows must be the same.
fn difference_from_dual_update(f: &PlasticFilm, h: &PlasticHistory, strain: &Vector3<f64>) -> f64 {
    let (r, t) = f.response_and_tangent(h, strain);
    let (d, td) = f.dual_response_and_tangent(h, strain);
    assert_eq!(d, f.dual_response(h, strain));
    assert_eq!(
        (r.state, r.yielding),
        (d.state, d.yielding),
        "at {strain:?}"
    );
    let stress_scale = d.stress.amax().max(1e-6 * E);
    let relative = |x: f64, y: f64, scale: f64| (x - y).abs() / scale;
    let (a, b) = (r.history, d.history);
    [
        (r.stress - d.stress).amax() / stress_scale,
        (t - td).amax() / td.amax().max(1e-6 * E),
        relative(r.thickness_ratio, d.thickness_ratio, 1.0),
        relative(r.equivalent_stress, d.equivalent_stress, stress_scale),
        relative(
            a.equivalent_plastic_strain,
            b.equivalent_plastic_strain,
            1.0,
        ),
        relative(
            a.unloaded_thickness_strain,
            b.unloaded_thickness_strain,
            1.0,
        ),
    ]
    .into_iter()
    .chain((0..3).map(|k| {
        let (x, y) = (a.inverse_plastic_metric[k], b.inverse_plastic_metric[k]);
        relative(x, y, 1.0)
    }))
    .chain((0..2).map(|k| {
        let (x, y) = (r.principal_kirchhoff[k], d.principal_kirchhoff[k]);
        relative(x, y, stress_scale)
    }))
    .fold(0.0, f64::max)
}

#[test]
fn closed_form_update_equals_the_dual_number_update_in_every_state() {
    for (f, h, strain, ..) in every_state() {
        let err = difference_from_dual_update(&f, &h, &strain);
        assert!(err < 1e-12, "at {strain:?} from {h:?}: {err:e}");
    }
    // Spread histories (with prestress) and strains, both films.
    let spread = |k: usize| ((k as f64 * 78.233).sin() * 43758.5453).rem_euclid(1.0) * 2.0 - 1.0;
    let mut k = 0;
    let mut next = || {
        k += 1;
        spread(k)
    };
    let mut seen = std::collections::HashSet::new();
    for i in 0..2000 {
        let f = film(next() > 0.0);
        let start = f.initial_history([2e6 * next(), 2e6 * next(), 1e6 * next()]);
        let (l1, l2, angle) = (1.0 + 0.3 * next(), 1.0 + 0.3 * next(), 3.0 * next());
        let h = f.response(&start, &green(l1, l2, angle)).history;
        let scale = [0.001, 0.05, 0.3][i % 3];
        let mut near = |x: f64| x + scale * next();
        let strain = green(near(l1), near(l2), near(angle));
        let err = difference_from_dual_update(&f, &h, &strain);
        assert!(err < 1e-12, "at {strain:?} from {h:?}: {err:e}");
        let r = f.response(&h, &strain);
        seen.insert((f.tension_field, r.state as usize, r.yielding));
    }
    assert_eq!(seen.len(), 7, "state combinations covered: {seen:?}");
}

#[test]
fn algorithmic_tangent_matches_finite_differences_at_spread_points() {
    // Deterministic spread of histories and strains, both films, with prestress.
    let spread = |k: usize| ((k as f64 * 12.9898).sin() * 43758.5453).rem_euclid(1.0) * 2.0 - 1.0;
    let mut k = 0;
    let mut next = || {
        k += 1;
        spread(k)
    };
    let mut seen = std::collections::HashSet::new();
    for _ in 0..400 {
        let f = film(next() > 0.0);
        let prestress = [2e6 * next(), 2e6 * next(), 1e6 * next()];
        let start = f.initial_history(prestress);
        let pre = Vector3::new(0.15 * next(), 0.15 * next(), 0.15 * next());
        let h = if next() > -0.3 {
            f.response(&start, &pre).history
        } else {
            start
        };
        let strain = pre + Vector3::new(0.05 * next(), 0.05 * next(), 0.05 * next());
        let (r, tangent) = f.response_and_tangent(&h, &strain);
        let Some(fd) = fd_tangent(&f, &h, &strain) else {
            continue;
        };
        let err = (fd - tangent).amax();
        assert!(
            err < 1e-6 * E,
            "{:?} {} at {strain:?} from {h:?}: {err:e}",
            r.state,
            r.yielding
        );
        seen.insert((
            f.tension_field,
            r.state as usize,
            r.yielding,
            h.equivalent_plastic_strain > 0.0,
        ));
    }
    assert!(seen.len() >= 8, "state combinations covered: {seen:?}");
}

#[test]
fn algorithmic_tangent_is_symmetric() {
    let (j2, tf) = (film(false), film(true));
    let h = yielded(&j2, Vector3::new(0.1, -0.03, 0.02));
    for (f, strain) in [
        (&j2, Vector3::new(0.13, -0.02, 0.05)),
        (&tf, Vector3::new(0.2, -0.1, 0.03)),
    ] {
        let t = f.response_and_tangent(&h, &strain).1;
        assert!((t - t.transpose()).amax() < 1e-9 * t.amax(), "{t}");
    }
}

/// Drives `stretch(λ) → (l1, l2)` (with `l2 = None`: the lateral stretch free, solved for
/// `S_yy = 0` with the tangent) through the log strains `path`, committing each increment.
/// Returns, per point, `(λ1, l2, nominal stress P1 = λ1 S_xx, t/t0, ε̄p)`.
fn drive(
    f: &PlasticFilm,
    path: &[f64],
    lateral: impl Fn(f64) -> Option<f64>,
    angle: f64,
) -> Vec<[f64; 5]> {
    let mut point = PlasticPoint::new(virgin());
    let mut l2 = 1.0;
    let mut out = vec![];
    for &eps in path {
        let l1 = eps.exp();
        let mut r;
        match lateral(l1) {
            Some(l) => {
                l2 = l;
                r = f.response(&point.committed, &green(l1, l2, angle));
            }
            None => loop {
                let (resp, t) = f.response_and_tangent(&point.committed, &green(l1, l2, 0.0));
                r = resp;
                if resp.stress.y.abs() < 1e-9 * f.hardening.initial_yield() {
                    break;
                }
                // dE_yy = l2 dl2
                l2 -= resp.stress.y / (t[(1, 1)] * l2);
            },
        }
        point.trial = r.history;
        point.commit();
        // Principal S along the stretch axes.
        let (s, c) = angle.sin_cos();
        let s1 = r.stress.x * c * c + r.stress.y * s * s + 2.0 * r.stress.z * s * c;
        out.push([
            l1,
            l2,
            l1 * s1,
            r.thickness_ratio,
            point.committed.equivalent_plastic_strain,
        ]);
    }
    out
}

fn up_and_down(peak: f64, end: f64, n: usize) -> Vec<f64> {
    let up = (1..=n).map(|i| peak * i as f64 / n as f64);
    let down = (1..=n).map(|i| peak + (end - peak) * i as f64 / n as f64);
    up.chain(down).collect()
}

/// Asserts that a proportional path up to `path[59]` and back (60 increments each way)
/// followed the closed form `ln λ = a ε̄p + b σy(ε̄p)`, `τ = c σy` (elastic: `σeq = ln λ/b`,
/// unloading: `σeq = (ln λ − a ε̄p,max)/b`), nominal stress `τ/λ`, thickness `t(τ, ε̄p)`, and
/// ended at zero stress. Returns `ε̄p,max`.
fn assert_follows_table(
    path: &[f64],
    points: &[[f64; 5]],
    [a, b, c]: [f64; 3],
    thickness: impl Fn(f64, f64) -> f64,
) -> f64 {
    let ep_max = plastic_strain_where(a, b, path[59]);
    for (i, (eps, p)) in path.iter().zip(points).enumerate() {
        let (seq, ep) = if i >= 60 {
            ((eps - a * ep_max) / b, ep_max)
        } else if *eps <= b * 16e6 {
            (eps / b, 0.0)
        } else {
            let ep = plastic_strain_where(a, b, *eps);
            (table_stress(ep), ep)
        };
        let tau = c * seq;
        let nominal = tau / p[0];
        assert!(
            (p[2] - nominal).abs() < 1e-6 * tau.abs().max(1e6),
            "ε {eps}: P {} vs {nominal}",
            p[2]
        );
        assert!((p[4] - ep).abs() < 1e-9, "ε {eps}: ε̄p {} vs {ep}", p[4]);
        let t = thickness(tau, ep);
        assert!((p[3] - t).abs() < 1e-6 * t, "ε {eps}: t/t0 {} vs {t}", p[3]);
    }
    let last = points.last().unwrap();
    assert!(last[2].abs() < 1e-6 * 16e6, "residual stress {}", last[2]);
    ep_max
}

#[test]
fn uniaxial_strip_to_30_percent_and_back_follows_the_hardening_table() {
    // ln λ = σy(ε̄p)/E + ε̄p, P = τ/λ, t/t0 = exp(−ν τ/E − ε̄p/2); unloading is elastic from
    // the peak's ε̄p, zero force at ln λ = ε̄p (the residual strain).
    let (peak, ep_max) = (0.3, plastic_strain_where(1.0, 1.0 / E, 0.3));
    let path = up_and_down(peak, ep_max, 60);
    let thickness = |tau: f64, ep: f64| (-NU * tau / E - ep / 2.0).exp();
    for tension_field in [false, true] {
        // With the tension field the strip is held at 0.8 across: it wrinkles and is a bar.
        let lateral = |_: f64| if tension_field { Some(0.8) } else { None };
        let points = drive(&film(tension_field), &path, lateral, 0.0);
        assert_follows_table(&path, &points, [1.0, 1.0 / E, 1.0], thickness);
        if !tension_field {
            // The width contracts like the thickness.
            for p in &points {
                assert!(
                    (p[1] - p[3]).abs() < 1e-6,
                    "width {} vs thickness {}",
                    p[1],
                    p[3]
                );
            }
        }
    }
}

#[test]
fn equibiaxial_stretch_to_30_percent_and_back_follows_the_hardening_table() {
    // τ1 = τ2 = τ, von Mises τ; ln λ = (1 − ν) τ/E + ε̄p/2, t/t0 = exp(−2ντ/E − ε̄p);
    // zero stress again at ln λ = ε̄p/2. Axes at 0.3 rad to the element frame.
    let k = (1.0 - NU) / E;
    let ep_max = plastic_strain_where(0.5, k, 0.3);
    let path = up_and_down(0.3, ep_max / 2.0, 60);
    let points = drive(&film(false), &path, Some, 0.3);
    let thickness = |tau: f64, ep: f64| (-2.0 * NU * tau / E - ep).exp();
    assert_follows_table(&path, &points, [0.5, k, 1.0], thickness);
}

#[test]
fn pure_shear_to_30_percent_and_back_follows_the_hardening_table() {
    // Stretches (λ, 1/λ) on axes at 0.5 rad: τ1 = −τ2 = τ, von Mises √3 τ, no thickness
    // change; ln λ = τ/(2G) + (√3/2) ε̄p with √3 τ = σy(ε̄p); zero stress at ln λ = (√3/2) ε̄p.
    let (g2, r3) = (E / (1.0 + NU), 3f64.sqrt());
    let case = [r3 / 2.0, 1.0 / (r3 * g2), 1.0 / r3];
    let ep_max = plastic_strain_where(case[0], case[1], 0.3);
    let path = up_and_down(0.3, ep_max * r3 / 2.0, 60);
    let points = drive(&film(false), &path, |l| Some(1.0 / l), 0.5);
    assert_follows_table(&path, &points, case, |_, _| 1.0);
}

#[test]
fn hardening_table_errors_name_the_bad_row() {
    let err = |rows: Vec<[f64; 2]>| Hardening::new(rows).unwrap_err().to_string();
    assert!(err(vec![]).contains("empty"));
    assert!(err(vec![[0.0, 16e6]; 33]).contains("33 rows; at most 32"));
    assert!(err(vec![[0.01, 16e6]]).starts_with("hardening[0]:"));
    assert!(err(vec![[0.0, 0.0]]).starts_with("hardening[0]: initial yield"));
    assert!(err(vec![[0.0, 16e6], [0.02, f64::NAN]]).starts_with("hardening[1]:"));
    // Two rows swapped: the strain goes back.
    let swapped = vec![[0.0, 16e6], [0.15, 24e6], [0.02, 19e6], [1.0, 40e6]];
    assert!(err(swapped).starts_with("hardening[2]: plastic strain 0.02 is not above"));
    let softening = vec![[0.0, 16e6], [0.02, 19e6], [0.15, 18e6]];
    assert!(err(softening).starts_with("hardening[2]: flow stress"));
    let from_json = |text: &str| serde_json::from_str::<Plasticity>(text);
    let e = from_json(r#"{"hardening": [[0.0, 16e6], [0.0, 19e6]]}"#).unwrap_err();
    assert!(
        e.to_string()
            .contains("hardening[1]: plastic strain 0 is not above"),
        "{e}"
    );
    let e = from_json(r#"{"hardening": [[0.0, 16e6]], "kinematic": 1}"#).unwrap_err();
    assert!(e.to_string().contains("unknown field `kinematic`"), "{e}");
    let ok = from_json(r#"{"hardening": [[0.0, 16e6], [0.02, 19e6]]}"#).unwrap();
    assert_eq!(ok.hardening.rows(), &[[0.0, 16e6], [0.02, 19e6]]);
    assert_eq!(table().flow_stress(0.01), (17.5e6, 150e6));
    assert_eq!(table().flow_stress(2.0).0, 40e6 + 16e6 / 0.85 * 1.0);
}

#[test]
fn prestress_is_the_stress_of_the_undeformed_film() {
    for tension_field in [false, true] {
        let f = film(tension_field);
        let s0 = [3e6, 1e6, 0.5e6];
        let r = f.response(&f.initial_history(s0), &Vector3::zeros());
        assert!(
            (r.stress - Vector3::from(s0)).amax() < 1e-9 * 3e6,
            "{:?}",
            r.stress
        );
        assert!((r.thickness_ratio - 1.0).abs() < 1e-15);
        assert!(!r.yielding);
    }
}

#[test]
fn trial_history_is_kept_until_committed_and_restores_exactly() {
    let f = film(false);
    let mut point = PlasticPoint::new(virgin());
    // An iterate that yields changes only the trial history.
    point.trial = f
        .response(&point.committed, &Vector3::new(0.1, -0.03, 0.02))
        .history;
    assert_eq!(point.committed, virgin());
    assert!(point.trial.equivalent_plastic_strain > 0.0);
    point.restore();
    assert_eq!(point, PlasticPoint::new(virgin()));
    // Elastic and slack increments leave the history as it was, bit for bit.
    let h = yielded(&f, Vector3::new(0.1, -0.03, 0.02));
    assert_eq!(f.response(&h, &Vector3::new(0.09, -0.03, 0.02)).history, h);
    assert_eq!(
        film(true)
            .response(&h, &Vector3::new(0.0, -0.1, 0.0))
            .history,
        h
    );
    let mut point = PlasticPoint::new(h);
    point.trial = f.response(&h, &Vector3::new(0.2, -0.03, 0.02)).history;
    point.commit();
    assert_eq!(point.committed, point.trial);
    assert!(point.committed.equivalent_plastic_strain > h.equivalent_plastic_strain);
}

#[test]
fn datasheet_curve_gives_the_datasheet_strip_back() {
    // A uniaxial strip of the default film: nominal stress = yield at first yield, and the
    // data sheet's tensile strength at its elongation at break (closed form ln λ = τ/E + ε̄p).
    let h = etfe_datasheet_hardening();
    let e = ETFE_DATASHEET_YOUNGS_MODULUS;
    let [_, [ep_break, tau_break]] = [h.rows()[0], h.rows()[1]];
    let stretch = (tau_break / e + ep_break).exp();
    assert!((stretch - 5.5).abs() < 1e-12);
    assert!((tau_break / stretch - 50e6).abs() < 1e-6);
    assert_eq!(h.initial_yield(), 21e6);
    assert!((ep_break - ETFE_RUPTURE_PLASTIC_STRAIN).abs() < 1e-15);
}

thread_local! {
    /// Evaluations of the return's scalar equation on this thread (`solve_decreasing`).
    pub(super) static EVALUATIONS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

#[test]
fn returns_along_a_loading_path_in_small_increments_take_a_few_evaluations() {
    // Newton iterates of a structure load a yielded point in small steps: its trial excess
    // f(0) is then a tiny part of the terms of Φ, and 1e-15 f(0) is below their rounding (the
    // return took its 200-iteration limit there, ~190 evaluations per return on average in the
    // 300 mm crown-to-foot run). A wrinkled point solves the taut return (which decides that it
    // wrinkles) and then the bar's.
    for (tension_field, direction) in [(false, [1.0, -0.3, 0.2]), (true, [1.0, -0.5, 0.1])] {
        let f = film(tension_field);
        let mut h = virgin();
        let (mut returns, mut most, mut total) = (0, 0, 0);
        for k in 1..=400 {
            let t = 0.1 * k as f64 / 400.0;
            let strain = Vector3::from(direction) * t;
            for nudge in [1e-9, 1e-6, 1e-4] {
                EVALUATIONS.with(|n| n.set(0));
                let r = f.response_and_tangent(&h, &(strain * (1.0 + nudge))).0;
                let n = EVALUATIONS.with(|n| n.get());
                returns += usize::from(r.yielding);
                most = most.max(n);
                total += n;
            }
            h = f.response(&h, &strain).history;
        }
        assert!(returns > 500, "{returns} returns");
        let mean = total as f64 / returns as f64;
        assert!(
            most <= 10 && mean <= 8.0,
            "tension field {tension_field}: {most} evaluations at most, {mean} on average"
        );
    }
}
