use super::*;

/// A tilted, scalene master triangle (so the projection, the normal and the metric all move
/// with every coordinate) and a slave node above its interior, pushed `depth` into it and
/// displaced `(s1, s2)` from the anchor at the triangle's centroid.
fn pair(depth: f64, s1: f64, s2: f64) -> [Vector3<f64>; 4] {
    let t = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.1, 0.1, 0.2),
        Vector3::new(0.2, 0.9, -0.1),
    ];
    let n = unit_normal(&t);
    let centre = (t[0] + t[1] + t[2]) / 3.0;
    let along = (t[1] - t[0]).normalize();
    let across = n.cross(&along);
    [
        centre + along * s1 + across * s2 - n * depth,
        t[0],
        t[1],
        t[2],
    ]
}

const LAW: PairLaw = PairLaw {
    kn: 1e5,
    ks: 4e4,
    mu: 0.3,
    sign: 1.0,
};

fn centroid() -> Vector2<f64> {
    Vector2::new(1.0 / 3.0, 1.0 / 3.0)
}

/// The largest difference between the tangent and central differences of the residual, over
/// the largest tangent entry.
fn tangent_error(x: &[Vector3<f64>; 4], law: &PairLaw, held: Option<GapStatus>) -> f64 {
    let r = respond(x, centroid(), law, held);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for j in 0..12 {
        let mut plus = *x;
        let mut minus = *x;
        plus[j / 3][j % 3] += h;
        minus[j / 3][j % 3] -= h;
        let rp = respond(&plus, centroid(), law, held);
        let rm = respond(&minus, centroid(), law, held);
        assert_eq!(
            rp.status, r.status,
            "the status changes within the difference step"
        );
        let fd = (rp.residual - rm.residual) / (2.0 * h);
        for i in 0..12 {
            worst = worst.max((fd[i] - r.tangent[(i, j)]).abs());
        }
    }
    worst / r.tangent.amax().max(f64::MIN_POSITIVE)
}

#[test]
fn open_pair_has_no_force_and_no_stiffness() {
    let r = respond(&pair(-1e-3, 0.0, 0.0), centroid(), &LAW, None);
    assert_eq!(r.status, GapStatus::Open);
    assert!((r.gap - 1e-3).abs() < 1e-12, "{}", r.gap);
    assert_eq!(r.residual, PairVector::zeros());
    assert_eq!(r.tangent, PairMatrix::zeros());
}

#[test]
fn tangent_matches_central_differences_in_frictionless_contact() {
    let law = PairLaw { mu: 0.0, ..LAW };
    let x = pair(2e-3, 0.05, -0.02);
    let r = respond(&x, centroid(), &law, None);
    assert_eq!(r.status, GapStatus::Slip, "μ = 0 slides freely");
    assert!((r.normal_force - 200.0).abs() < 1e-6, "{}", r.normal_force);
    let e = tangent_error(&x, &law, None);
    assert!(e < 1e-6, "relative error {e:e}");
}

#[test]
fn tangent_matches_central_differences_in_stick() {
    // |f*| = k_s · 0.004 = 160 N < μλN = 0.3 · 1e5 · 0.01 = 300 N.
    let x = pair(1e-2, 0.004, 0.0);
    let r = respond(&x, centroid(), &LAW, None);
    assert_eq!(r.status, GapStatus::Stick);
    assert!(
        (r.friction.norm() - 160.0).abs() < 1e-6,
        "{}",
        r.friction.norm()
    );
    let e = tangent_error(&x, &LAW, None);
    assert!(e < 1e-6, "relative error {e:e}");
}

#[test]
fn tangent_matches_central_differences_in_slip() {
    // |f*| = k_s · 0.02 = 800 N > μλN = 300 N: the force sits on the cone.
    let x = pair(1e-2, 0.012, -0.016);
    let r = respond(&x, centroid(), &LAW, None);
    assert_eq!(r.status, GapStatus::Slip);
    assert!(
        (r.friction.norm() - 300.0).abs() < 1e-9,
        "{}",
        r.friction.norm()
    );
    let e = tangent_error(&x, &LAW, None);
    assert!(e < 1e-6, "relative error {e:e}");
}

#[test]
fn tangent_matches_central_differences_under_held_statuses() {
    for (x, held) in [
        (pair(1e-2, 0.004, 0.0), GapStatus::Slip),
        (pair(1e-2, 0.012, -0.016), GapStatus::Stick),
    ] {
        let r = respond(&x, centroid(), &LAW, Some(held));
        assert_eq!(r.status, held);
        let e = tangent_error(&x, &LAW, Some(held));
        assert!(e < 1e-6, "{held:?}: relative error {e:e}");
    }
}

#[test]
fn pair_forces_balance_and_split_by_the_shape_functions() {
    let x = pair(1e-2, 0.012, -0.016);
    let r = respond(&x, centroid(), &LAW, None);
    let sum = (0..4).fold(Vector3::zeros(), |s, i| {
        s + r.residual.fixed_rows::<3>(3 * i).into_owned()
    });
    assert!(sum.norm() < 1e-9 * r.residual.amax(), "{sum:?}");
    let on_slave = -r.residual.fixed_rows::<3>(0).into_owned();
    let xi = r.xi;
    for (i, n) in [1.0 - xi.x - xi.y, xi.x, xi.y].into_iter().enumerate() {
        let on_master = r.residual.fixed_rows::<3>(3 * (i + 1)).into_owned();
        assert!((on_master - on_slave * n).norm() < 1e-9 * on_slave.norm());
    }
}

#[test]
fn committed_anchor_reproduces_the_friction_force_and_the_slip() {
    let x = pair(1e-2, 0.012, -0.016);
    let r = respond(&x, centroid(), &LAW, None);
    // From the committed anchor the same position holds the same friction force, on the cone
    // (stick or slip by round-off) and without sliding further.
    let again = respond(&x, r.next_anchor, &LAW, None);
    assert!(again.slip < 1e-12, "{}", again.slip);
    assert!((again.friction - r.friction).norm() < 1e-9 * r.friction.norm());
    // Trial 800 N, returned to 300 N: it slid (800 − 300)/k_s.
    assert!((r.slip - 500.0 / LAW.ks).abs() < 1e-12, "{}", r.slip);
}

#[test]
fn back_side_reverses_the_normal() {
    let x = pair(-1e-3, 0.0, 0.0);
    let law = PairLaw { sign: -1.0, ..LAW };
    let r = respond(&x, centroid(), &law, None);
    assert!((r.gap + 1e-3).abs() < 1e-12, "{}", r.gap);
    assert!(r.normal_force > 0.0);
}

#[test]
fn closest_point_clamps_outside_the_triangle() {
    let t = [Vector3::zeros(), Vector3::x(), Vector3::y()];
    let (d, xi) = closest_point(&Vector3::new(2.0, 0.0, 1.0), &t);
    assert!((d - 2f64.sqrt()).abs() < 1e-12, "{d}");
    assert!(inside(&xi) < 0.0);
    let (d, _) = closest_point(&Vector3::new(0.2, 0.2, -0.5), &t);
    assert!((d - 0.5).abs() < 1e-12, "{d}");
}
