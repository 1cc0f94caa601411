use super::*;

fn support(centreline: Centreline, law: FrictionLaw) -> CurvedSupport {
    CurvedSupport {
        name: "s".into(),
        centreline,
        tube_radius: 0.05,
        nodes: vec![0],
        normal_stiffness: 1.0e6,
        tangential_stiffness: 4.0e5,
        friction: 0.3,
        friction_law: law,
    }
}

/// A cylinder round the y axis (isotropic friction, μ = 0.3).
fn y_cylinder() -> CurvedSupport {
    let centreline = Centreline::Line {
        point: [0.0; 3],
        axis: [0.0, 1.0, 0.0],
    };
    support(centreline, FrictionLaw::Isotropic)
}

fn ring(angles: Option<[f64; 2]>) -> Centreline {
    Centreline::Circle {
        centre: [0.0, 0.0, -1.0],
        axis: [0.0, 1.0, 0.05],
        radius: 1.0,
        angles,
        start_direction: None,
    }
}

fn kinds() -> Vec<(&'static str, Centreline)> {
    vec![
        (
            "cylinder",
            Centreline::Line {
                point: [0.1, -0.2, 0.05],
                axis: [0.2, 1.0, 0.1],
            },
        ),
        ("ring", ring(None)),
        ("arc", ring(Some([0.3, 1.6]))),
        (
            "parabola",
            Centreline::Parabola {
                apex: [0.1, 0.2, 0.5],
                up: [0.1, 0.0, 1.0],
                along: [1.0, 0.2, 0.0],
                half_span: 1.0,
                rise: 0.6,
            },
        ),
        (
            // Turns both ways (−, −, +) in a tilted plane.
            "polyline",
            Centreline::Polyline {
                points: [
                    [-1.0, -0.5],
                    [-0.6, 0.0],
                    [0.0, 0.2],
                    [0.6, 0.0],
                    [1.0, 0.1],
                ]
                .map(|[a, b]| [a, 0.1 * a + 0.2 * b, b])
                .to_vec(),
                normal: None,
            },
        ),
    ]
}

/// A point of the centreline at parameter `u`, continued straight beyond a polyline's ends
/// and along the curve's formula beyond the others'.
fn centre_at(shape: &Shape, u: f64) -> Vector3<f64> {
    match shape {
        Shape::Cylinder(f) => f.centre + f.a * u,
        Shape::Curve { path, .. } => match path {
            Path::Circle { frame, radius, .. } => {
                frame.centre + (frame.e1 * u.cos() + frame.e2 * u.sin()) * *radius
            }
            Path::Parabola {
                apex, along, up, k, ..
            } => apex + along * u - up * (k * u * u),
            Path::Polyline(p) => {
                let j = p.length[1..p.tangents.len()].partition_point(|&l| l < u);
                p.points[j] + p.tangents[j] * (u - p.length[j])
            }
        },
    }
}

/// The range of parameters sampled: the whole centreline and some way beyond its ends.
fn sampled_range(shape: &Shape) -> [f64; 2] {
    match shape {
        Shape::Cylinder(_) => [-0.3, 0.3],
        Shape::Curve { path, .. } => match path {
            Path::Circle { arc: None, .. } => [-3.0, 3.0],
            Path::Circle {
                arc: Some([lo, hi]),
                ..
            } => [lo - 0.2, hi + 0.2],
            Path::Parabola { half_span, .. } => [-1.2 * half_span, 1.2 * half_span],
            Path::Polyline(p) => {
                let total = p.length[p.length.len() - 1];
                [-0.1 * total, 1.1 * total]
            }
        },
    }
}

/// A reproducible sequence, uniform on [−1, 1), from `seed`.
fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// `x`'s response from `history` with the relative mismatch of its tangent against central
/// differences of the residual (step `h` = 1e-7 m; scale: the tangent's norm, at least 1e-3
/// `k_n`) and its status code (the status, + 10 where the sliding-direction law's cross hold
/// let go); None within reach (20 h) of a change of the law's smooth piece (status, components
/// on their bounds), of the surface's region or of the side `s`.
fn checked_tangent(
    c: &SurfaceContact,
    x: &Vector3<f64>,
    history: &ContactHistory,
) -> Option<(ContactResponse, f64, u8)> {
    let mu = history.friction;
    let piece = |r: &ContactResponse| {
        let on = |f: f64, b: f64| f.abs() >= b * (1.0 - 1e-12) && b > 0.0;
        (
            r.status,
            on(r.friction.x, mu * r.normal_force),
            on(r.friction.y, FrictionLaw::cross_limit(r.normal_force, mu)),
        )
    };
    let (r, p) = (c.respond(x, history), c.project_from(x, history));
    let h = 1e-7;
    let unchanged = (0..3).all(|k| {
        [-1.0, 1.0].iter().all(|sgn| {
            let y = x + Vector3::ith(k, 20.0 * h * sgn);
            let q = c.project_from(&y, history);
            piece(&c.respond(&y, history)) == piece(&r) && q.region == p.region && q.side == p.side
        })
    });
    if !unchanged {
        return None;
    }
    let (_, _, across) = piece(&r);
    let let_go = c.law == FrictionLaw::SlidingDirection && across && r.status == GapStatus::Slip;
    let mut fd = Matrix3::zeros();
    for k in 0..3 {
        let e = Vector3::ith(k, h);
        let plus = c.respond(&(x + e), history).residual;
        let minus = c.respond(&(x - e), history).residual;
        fd.set_column(k, &((plus - minus) / (2.0 * h)));
    }
    let error = (fd - r.tangent).norm() / r.tangent.norm().max(c.kn * 1e-3);
    Some((r, error, r.status as u8 + 10 * u8::from(let_go)))
}

/// Central differences of the residual against the tangent, for random positions near the
/// support (in every region of its surface: tube, polyline corners, end caps) and anchors
/// chosen to give each status, for both friction laws.
#[test]
fn tangent_matches_finite_differences_in_every_status() {
    let mut seen = std::collections::HashSet::new();
    let mut rand = uniform(7);
    for law in FrictionLaw::ALL {
        for (kind, centreline) in kinds() {
            let s = support(centreline, law);
            let c = SurfaceContact::new(&s, 0);
            let [lo, hi] = sampled_range(&c.shape);
            for case in 0..400 {
                // A point near the centreline; its closest point on the surface, from which
                // the node is pushed in (or pulled out).
                let u = lo + (hi - lo) * 0.5 * (rand() + 1.0);
                let dir = Vector3::new(rand(), rand(), rand()).normalize();
                let y = centre_at(&c.shape, u) + dir * (s.tube_radius * (0.5 + rand().abs()));
                let py = c.project(&y, u);
                // Every fourth case pressed lightly and dragged far across: the
                // sliding-direction law's cross hold let go (|f2| = κλN).
                let across = case % 4 == 1;
                let depth = if across {
                    2e-5 * (1.0 + rand().abs())
                } else {
                    1e-4 * (rand() + 0.3)
                };
                let x = y - py.normal * (py.gap + depth);
                let p0 = c.project(&x, py.parameter);
                // Anchors near ξ (stick) or far (slip), either side.
                let offset = if case % 3 == 0 { 1e-6 } else { 5e-3 } * rand().signum();
                {
                    let history = ContactHistory {
                        anchor: [
                            p0.xi.x + offset,
                            p0.xi.y - if across { 4.0 } else { 0.5 } * offset,
                        ],
                        angle: p0.parameter,
                        origin: 0.0,
                        status: GapStatus::Stick,
                        friction: 0.3,
                        side: [0.0; 3],
                    };
                    let Some((r, error, code)) = checked_tangent(&c, &x, &history) else {
                        continue;
                    };
                    seen.insert((law, kind, p0.region, code));
                    assert!(
                        error < 1e-5,
                        "{law:?} {kind} {:?} {:?}: relative error {error:e}",
                        p0.region,
                        r.status,
                    );
                }
            }
        }
    }
    for law in FrictionLaw::ALL {
        for (kind, _) in kinds() {
            let mut regions = vec![Region::Tube];
            if matches!(kind, "arc" | "parabola" | "polyline") {
                regions.push(Region::EndCap);
            }
            if kind == "polyline" {
                regions.push(Region::Corner);
            }
            assert!(
                seen.contains(&(law, kind, Region::Tube, GapStatus::Open as u8)),
                "{law:?} {kind} open never tested"
            );
            if law == FrictionLaw::SlidingDirection {
                assert!(
                    seen.contains(&(law, kind, Region::Tube, 10 + GapStatus::Slip as u8)),
                    "{law:?} {kind}: the cross hold let go never tested"
                );
            }
            for region in regions {
                for status in [GapStatus::Stick, GapStatus::Slip] {
                    let hold = |c: u8| seen.contains(&(law, kind, region, c));
                    assert!(
                        hold(status as u8) || hold(10 + status as u8),
                        "{law:?} {kind} {region:?} {status:?} never tested"
                    );
                }
            }
        }
    }
}

/// Issue 46: a node past the centreline (`s = −1`: `w` against the committed side `n̄`), at
/// 0.1–1.6 tube radii from it, in every status it can have there (stick, slip, the cross hold
/// let go; never open: `g = −d − r`) under both friction laws on every kind of support: the
/// tangent `k_n n⊗n − λN s ∂n/∂x − …` matches central differences of the residual, the contact
/// pushes the node toward the committed side (`F·n̄ > 0`) and the gap is `−d − r`.
#[test]
fn tangent_matches_finite_differences_past_the_centreline_in_every_status() {
    let mut seen = std::collections::HashSet::new();
    let (mut worst, mut regions) = (0.0f64, std::collections::HashSet::new());
    let mut rand = uniform(46);
    for law in FrictionLaw::ALL {
        for (kind, centreline) in kinds() {
            let s = support(centreline, law);
            let r = s.tube_radius;
            let c = SurfaceContact::new(&s, 0);
            let [lo, hi] = sampled_range(&c.shape);
            for case in 0..300 {
                let u = lo + (hi - lo) * 0.5 * (rand() + 1.0);
                let dir = Vector3::new(rand(), rand(), rand()).normalize();
                let x = centre_at(&c.shape, u) + dir * (r * (0.1 + 1.5 * rand().abs()));
                let geometric = c.project(&x, u);
                // A committed side pointing away from the node (w·n̄ ≤ −0.3 d).
                let tilt = Vector3::new(rand(), rand(), rand()) * 0.5;
                let side = -(geometric.normal + tilt).normalize();
                if geometric.normal.dot(&side) > -0.3 {
                    continue;
                }
                // The cylinder's angle is that of s q: half a turn from the node's own.
                let near = match c.shape {
                    Shape::Cylinder(_) => geometric.parameter + std::f64::consts::PI,
                    Shape::Curve { .. } => geometric.parameter,
                };
                let p0 = c.project_on_side(&x, near, &side);
                assert_eq!(p0.side, -1.0, "{kind}");
                assert!((p0.gap + geometric.gap + 2.0 * r).abs() < 1e-12, "{kind}");
                // Anchors near ξ (stick) or far (slip: k_s |ξ − ξ̄| beyond μ k_n (d + r)), some
                // dragged 100 m across (the cross hold κ k_n (d + r) let go, κ = 100).
                let across = case % 4 == 1;
                let offset = if case % 3 == 0 { 1e-6 } else { 0.3 } * rand().signum();
                let history = ContactHistory {
                    anchor: [
                        p0.xi.x + if across { 1e-6 } else { offset },
                        p0.xi.y - if across { 100.0 } else { 0.5 * offset },
                    ],
                    angle: p0.parameter,
                    origin: 0.0,
                    status: GapStatus::Stick,
                    friction: 0.3,
                    side: side.into(),
                };
                let Some((resp, error, code)) = checked_tangent(&c, &x, &history) else {
                    continue;
                };
                assert_ne!(resp.status, GapStatus::Open, "{kind}");
                // The normal force λN s n pushes the node back toward the committed side.
                assert!(
                    resp.normal_force > 0.0 && p0.normal.dot(&side) >= 0.3,
                    "{kind}: pushed on through"
                );
                seen.insert((law, kind, code));
                regions.insert(p0.region);
                worst = worst.max(error);
                assert!(
                    error < 1e-5,
                    "{law:?} {kind} {:?} {:?} past the centreline: relative error {error:e}",
                    p0.region,
                    resp.status,
                );
            }
        }
    }
    eprintln!("past the centreline: worst relative tangent error {worst:e} in {regions:?}");
    for law in FrictionLaw::ALL {
        for (kind, _) in kinds() {
            let mut statuses = vec![GapStatus::Stick as u8, GapStatus::Slip as u8];
            if law == FrictionLaw::SlidingDirection {
                statuses.push(10 + GapStatus::Slip as u8);
            }
            for status in statuses {
                assert!(
                    seen.contains(&(law, kind, status)),
                    "{law:?} {kind} status {status} past the centreline never tested"
                );
            }
        }
    }
}

/// Issue 46: on a straight path `C + t n̄` through a centreline point `C` along the committed
/// side's normal, from `t = 0.9 r` (in contact on the committed side) to `t = −0.9 r` (past the
/// centreline), the gap is `t − r`, the contact direction stays `n̄`, the force `k_n (r − t)`
/// along it and `ξ` stay put (continuous through `t = 0`, where the plain distance law
/// reverses its force); on every kind of support, at points all along it.
#[test]
fn gap_force_and_surface_coordinates_are_continuous_through_the_centreline() {
    for (kind, centreline) in kinds() {
        let s = support(centreline, FrictionLaw::Isotropic);
        let r = s.tube_radius;
        let c = SurfaceContact::new(&s, 0);
        let [lo, hi] = sampled_range(&c.shape);
        let mut tested = 0;
        for k in 1..12 {
            let u = lo + (hi - lo) * k as f64 / 12.0;
            // The foot C of a point 0.9 r off the centreline and the direction n̄ to it.
            let dir = Vector3::new((k as f64).sin(), 0.3, (k as f64).cos()).normalize();
            let y = centre_at(&c.shape, u) + dir * (0.9 * r);
            let q = c.project(&y, u);
            if q.region != Region::Tube {
                continue;
            }
            let foot = y - q.normal * (q.gap + r);
            let mut history = c.initial_history(&y, 0.3);
            assert!(
                (Vector3::from(history.side) - q.normal).norm() < 1e-12,
                "{kind}"
            );
            history.status = GapStatus::Stick;
            let mut before: Option<(f64, ContactResponse)> = None;
            for i in 0..=36 {
                let t = r * (0.9125 - 1.8 * i as f64 / 36.0);
                let x = foot + q.normal * t;
                let resp = c.respond(&x, &history);
                let p = c.project_from(&x, &history);
                assert!(
                    (resp.gap - (t - r)).abs() < 1e-12,
                    "{kind} t = {t}: gap {}",
                    resp.gap
                );
                assert!(
                    (p.normal - q.normal).norm() < 1e-9,
                    "{kind} t = {t}: {}",
                    p.normal
                );
                assert!(
                    (resp.normal_force - s.normal_stiffness * (r - t)).abs() < 1e-6,
                    "{kind} t = {t}"
                );
                // ξ1 stays (the foot does not move), ξ2 = p·x moves with t at most.
                if let Some((t0, r0)) = before {
                    assert!(
                        (resp.xi.x - r0.xi.x).abs() < 1e-9
                            && (resp.xi.y - r0.xi.y).abs() <= (t - t0).abs() + 1e-12,
                        "{kind} t = {t}: ξ {} after {}",
                        resp.xi,
                        r0.xi
                    );
                }
                before = Some((t, resp));
            }
            tested += 1;
        }
        assert!(tested >= 5, "{kind}: {tested} paths");
    }
}

/// The laws held in a status by the Newton loop's hold of a contact cycling between stick and
/// slip (`respond_held`): the tangent matches central differences of the residual for both
/// friction laws, held in stick where the law slips and in slip where it sticks; the response
/// reports the held status; nothing held is the law itself, and an open contact stays open.
#[test]
fn held_laws_tangent_matches_finite_differences_in_both_held_statuses() {
    let mut rand = uniform(11);
    let mut checked = std::collections::HashSet::new();
    for law in FrictionLaw::ALL {
        let s = support(ring(None), law);
        let c = SurfaceContact::new(&s, 0);
        let [lo, hi] = sampled_range(&c.shape);
        for case in 0..200 {
            let u = lo + (hi - lo) * 0.5 * (rand() + 1.0);
            let dir = Vector3::new(rand(), rand(), rand()).normalize();
            let y = centre_at(&c.shape, u) + dir * (s.tube_radius * (0.5 + rand().abs()));
            let py = c.project(&y, u);
            let x = y - py.normal * (py.gap + 1e-4 * (1.0 + rand().abs()));
            let p0 = c.project(&x, py.parameter);
            if p0.region != Region::Tube {
                continue;
            }
            let offset = if case % 2 == 0 { 1e-6 } else { 5e-3 } * rand().signum();
            let history = ContactHistory {
                anchor: [p0.xi.x + offset, p0.xi.y - 0.5 * offset],
                angle: p0.parameter,
                origin: 0.0,
                status: GapStatus::Stick,
                friction: 0.3,
                side: [0.0; 3],
            };
            let natural = c.respond(&x, &history);
            let unheld = c.respond_held(&x, &history, None);
            assert_eq!(natural.residual, unheld.residual);
            assert_eq!(natural.tangent, unheld.tangent);
            if natural.status == GapStatus::Open {
                continue;
            }
            for held in [GapStatus::Stick, GapStatus::Slip] {
                let r = c.respond_held(&x, &history, Some(held));
                assert_eq!(r.status, held, "{law:?}");
                // Within reach of the slip direction's own kink (the trial force's zero) only
                // by a step well below the anchor's distance.
                let h = (1e-3 * (p0.xi - Vector2::from(history.anchor)).norm()).min(1e-7);
                let mut fd = Matrix3::zeros();
                for k in 0..3 {
                    let e = Vector3::ith(k, h);
                    let plus = c.respond_held(&(x + e), &history, Some(held)).residual;
                    let minus = c.respond_held(&(x - e), &history, Some(held)).residual;
                    fd.set_column(k, &((plus - minus) / (2.0 * h)));
                }
                let scale = r.tangent.norm().max(s.normal_stiffness * 1e-3);
                let error = (fd - r.tangent).norm() / scale;
                assert!(
                    error < 1e-5,
                    "{law:?} held {held:?} (law: {:?}): relative error {error:e}",
                    natural.status
                );
                checked.insert((law, held as u8, natural.status as u8));
            }
        }
    }
    for law in FrictionLaw::ALL {
        for (held, other) in [
            (GapStatus::Stick, GapStatus::Slip),
            (GapStatus::Slip, GapStatus::Stick),
        ] {
            assert!(
                checked.contains(&(law, held as u8, other as u8)),
                "{law:?} held {held:?} where the law gives {other:?} never tested"
            );
        }
    }
}

#[test]
fn a_node_outside_the_tube_is_open_and_carries_nothing() {
    let s = support(ring(None), FrictionLaw::Isotropic);
    let c = SurfaceContact::new(&s, 0);
    let x = Vector3::new(0.0, 0.0, -1.0) + Vector3::new(1.2, 0.0, 0.0);
    let history = c.initial_history(&x, 0.3);
    let r = c.respond(&x, &history);
    assert_eq!((r.status, r.residual), (GapStatus::Open, Vector3::zeros()));
}

/// Beyond an arc's end the closest point is the end point (a hemispherical cap): the node
/// is still held, by a normal from the end, and `ξ1` goes on past the end's normal plane.
#[test]
fn beyond_an_arc_end_the_cap_holds_the_node_along_the_normal_from_the_end_point() {
    let s = support(ring(Some([0.5, 1.0])), FrictionLaw::Isotropic);
    let c = SurfaceContact::new(&s, 0);
    let Shape::Curve {
        path: Path::Circle { frame: f, .. },
        ..
    } = c.shape
    else {
        unreachable!()
    };
    let end = f.centre + f.e1 * 0.5f64.cos() + f.e2 * 0.5f64.sin();
    let tangent = f.a.cross(&(end - f.centre));
    // 1 mm past the end, 0.04 m outward from it: inside the cap (r = 0.05).
    let out = (end - f.centre).normalize();
    let x = end - tangent * 0.001 + out * 0.04;
    let p = c.project(&x, 0.0);
    assert_eq!(p.region, Region::EndCap);
    assert!(((x - end).norm() - 0.05 - p.gap).abs() < 1e-15);
    assert!((p.normal - (x - end).normalize()).norm() < 1e-15);
    assert!((p.xi.x - (1.05 * 0.5 - 0.001)).abs() < 1e-12, "{}", p.xi.x);
    let history = c.initial_history(&x, 0.3);
    let r = c.respond(&x, &history);
    assert_eq!(r.status, GapStatus::Stick);
    assert!((r.normal_force - 1.0e6 * (0.05 - (x - end).norm())).abs() < 1e-6);
    // Just inside the arc: on the tube, the same gap and ξ1 to first order.
    let inside = end + tangent * 1e-9 + out * 0.04;
    let q = c.project(&inside, 0.0);
    assert_eq!(q.region, Region::Tube);
    assert!((q.gap - (0.04 - 0.05)).abs() < 1e-12);
    assert!((q.xi.x - 1.05 * 0.5).abs() < 1e-8);
}

/// A node walked along the outer surface (`t × p` side) of each curve, 5 mm deep in the
/// tube, from the start cap round the polyline's corners to the far cap: the gap stays the
/// depth and position, normal and `ξ1` change continuously, `ξ1` growing with the path by
/// the ratio of the surface's radius to the walk's (≤ 0.05/0.045 round a corner, `1 + O(rκ)`
/// along the tube, ≤ 1 over a cap, where `ξ1` is the distance past the end's plane).
#[test]
fn walking_over_corners_and_caps_keeps_gap_normal_and_surface_length_continuous() {
    for (kind, centreline) in kinds().into_iter().skip(2) {
        let s = support(centreline, FrictionLaw::Isotropic);
        let c = SurfaceContact::new(&s, 0);
        let Shape::Curve { normal: p, .. } = c.shape else {
            unreachable!()
        };
        let (depth, h) = (0.005, 1e-4);
        let [lo, _] = sampled_range(&c.shape);
        let t = (centre_at(&c.shape, lo + 1e-6) - centre_at(&c.shape, lo)).normalize();
        let y = centre_at(&c.shape, lo) + t.cross(&p) * s.tube_radius;
        let q = c.project(&y, lo);
        let mut x = y - q.normal * (q.gap + depth);
        let mut prev = c.project(&x, q.parameter);
        assert_eq!(prev.region, Region::EndCap, "{kind}");
        let (mut regions, mut in_far_cap, mut creases) = (vec![prev.region], 0.0, 0);
        while in_far_cap < 0.5 * s.tube_radius {
            let along = prev.grad[0] - prev.normal * prev.normal.dot(&prev.grad[0]);
            let y = x + along.normalize() * h;
            let q = c.project(&y, prev.parameter);
            let next = y - q.normal * (q.gap + depth);
            let now = c.project(&next, prev.parameter);
            let step = (next - x).norm();
            assert!(step < 1.5 * h, "{kind}: jump of {step} at {next}");
            assert!((now.gap + depth).abs() < 1e-12, "{kind}: gap {}", now.gap);
            let dxi = now.xi.x - prev.xi.x;
            if (now.normal - prev.normal).norm() > 5e-3 {
                // The crease on the concave side of a polyline's vertex: the closest
                // point jumps to the next segment; ξ1 by 2d tan(|Δ|/2) − r|Δ| (mm).
                creases += 1;
                assert!(dxi.abs() < 5e-3, "{kind}: ξ1 jumps by {dxi} at {next}");
            } else {
                let ratio = dxi / step;
                let (low, high) = match (prev.region, now.region) {
                    (Region::EndCap, Region::EndCap) => (0.0, 1.0 + 1e-9),
                    (Region::EndCap, _) | (_, Region::EndCap) => (0.0, 1.12),
                    _ => (0.95, 1.12),
                };
                assert!(
                    ratio > low && ratio < high,
                    "{kind} {:?}: dξ1/ds = {ratio} at {next}",
                    now.region
                );
            }
            if regions.last() != Some(&now.region) {
                regions.push(now.region);
            }
            if now.region == Region::EndCap && regions.len() > 1 {
                in_far_cap += step;
            }
            (x, prev) = (next, now);
        }
        // The polyline turns +, +, − about its normal: two corners on this side, one crease.
        let (expected, expected_creases) = match kind {
            "polyline" => (
                vec![
                    Region::EndCap,
                    Region::Tube,
                    Region::Corner,
                    Region::Tube,
                    Region::Corner,
                    Region::Tube,
                    Region::EndCap,
                ],
                1,
            ),
            _ => (vec![Region::EndCap, Region::Tube, Region::EndCap], 0),
        };
        assert_eq!((regions, creases), (expected, expected_creases), "{kind}");
    }
}

/// A node that travels round a cylinder while clear of it, then lands and is dragged on:
/// only the arc length after landing is slip; the travel counts both.
#[test]
fn slip_counts_sliding_in_contact_not_the_approach() {
    let s = CurvedSupport {
        friction: 0.0,
        ..y_cylinder()
    };
    let c = SurfaceContact::new(&s, 0);
    let r = s.tube_radius;
    // Round the y axis in the x–z plane.
    let at = |radius: f64, phi: f64| Vector3::new(phi.sin(), 0.0, phi.cos()) * radius;
    let mut history = c.initial_history(&at(1.5 * r, 0.0), 0.0);
    assert_eq!(history.status, GapStatus::Open);
    let path = [
        (1.5 * r, 0.4),
        (0.99 * r, 0.6),
        (0.99 * r, 0.9),
        (0.99 * r, 1.3),
    ];
    let mut slips = vec![];
    for (radius, phi) in path {
        let response = c.respond(&at(radius, phi), &history);
        history = SurfaceContacts::commit(&[response], &[history])[0];
        slips.push(response.xi.x - history.origin);
    }
    // Open, then landing (approach: not slip), then two steps dragged in contact: the
    // surface length r·Δφ from where it landed.
    let expected = [0.0, 0.0, r * 0.3, r * 0.7];
    for (k, (s, e)) in slips.iter().zip(expected).enumerate() {
        assert!((s.abs() - e).abs() < 1e-12, "step {k}: slip {s} vs ±{e}");
    }
    let touching = c.initial_history(&at(0.99 * r, 0.0), 0.0);
    assert_eq!(
        touching.status,
        GapStatus::Stick,
        "a node on the support starts in contact"
    );
}

/// The predictor's correction (`keep_gaps`): a closed contact predicted further into its
/// support goes back to the gap it had, along the normal only; an open contact, a node that
/// is not free and a prediction away from the support are left as predicted.
#[test]
fn a_prediction_into_the_support_is_moved_back_to_the_converged_gap() {
    let s = y_cylinder();
    let r = s.tube_radius;
    let c = SurfaceContact::new(&s, 0);
    let x0 = Vector3::new(0.0, 0.0, 0.99 * r);
    let contacts = SurfaceContacts {
        contacts: vec![c.clone()],
        slots: vec![],
        reference: vec![x0],
    };
    let closed = c.initial_history(&x0, 0.3);
    assert_ne!(closed.status, GapStatus::Open);
    let start = [0.0; 3];
    let gap = |u: &[f64]| c.project(&(x0 + Vector3::new(u[0], u[1], u[2])), 0.0).gap;
    let into = [0.004, 0.002, -0.01];
    let mut u = into;
    contacts.keep_gaps(&start, &[closed], |_| true, &mut u);
    assert!(
        (gap(&u) - gap(&start)).abs() < 1e-15,
        "{} vs {}",
        gap(&u),
        gap(&start)
    );
    // Along the normal at the predicted point only: the angle round the tube and the
    // position along it are the prediction's.
    assert_eq!(u[1], into[1]);
    assert!((u[0] / (u[2] + x0.z) - into[0] / (into[2] + x0.z)).abs() < 1e-12);
    let open = ContactHistory {
        status: GapStatus::Open,
        ..closed
    };
    for (history, free, predicted) in [
        (open, true, into),
        (closed, false, into),
        (closed, true, [0.004, 0.0, 0.01]),
    ] {
        let mut u = predicted;
        contacts.keep_gaps(&start, &[history], |_| free, &mut u);
        assert_eq!(u, predicted);
    }
}

/// Issue 46: a node remembers its side (the contact direction `s n`) while it is within one tube
/// radius of the surface, at the start and at every converged state, and none beyond (where it
/// may go round the support within an increment): a node 1.1 radii off a cylinder that swings
/// round to the opposite side in one step stays open, one 0.9 radii off is held on its side.
#[test]
fn a_node_remembers_its_side_within_one_tube_radius_of_the_surface_only() {
    let s = y_cylinder();
    let c = SurfaceContact::new(&s, 0);
    let r = s.tube_radius;
    for (off, remembered) in [(0.9, true), (1.1, false)] {
        let x0 = Vector3::new(0.0, 0.0, r * (1.0 + off));
        let start = c.initial_history(&x0, 0.3);
        let committed = SurfaceContacts::commit(&[c.respond(&x0, &start)], &[start])[0];
        for h in [start, committed] {
            let side = Vector3::from(h.side);
            assert_eq!(side != Vector3::zeros(), remembered, "{off} radii off");
            if remembered {
                assert!((side - Vector3::z()).norm() < 1e-15);
            }
        }
        // Swung round to the far side, as far from the axis.
        let far = c.respond(&-x0, &committed);
        if remembered {
            assert_eq!(far.status, GapStatus::Stick, "{off}");
            assert!((far.gap + r * (2.0 + off)).abs() < 1e-12);
            assert!(-far.residual.z > 0.0, "pushed back up");
        } else {
            assert_eq!(
                (far.status, far.residual),
                (GapStatus::Open, Vector3::zeros())
            );
        }
    }
}
