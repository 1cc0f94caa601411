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

/// Uniform numbers in [−1, 1) from a 64-bit linear congruential generator seeded with `seed`
/// (Knuth's MMIX constants): the same sequence on every platform.
fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
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
                    };
                    let r = c.respond(&x, &history);
                    // The smooth piece of the law: the status, and which components are on
                    // their bounds (μλN along, κλN across).
                    let piece = |r: &ContactResponse| {
                        let on = |f: f64, b: f64| f.abs() >= b * (1.0 - 1e-12) && b > 0.0;
                        let mu = history.friction;
                        (
                            r.status,
                            on(r.friction.x, mu * r.normal_force),
                            on(r.friction.y, FrictionLaw::cross_limit(r.normal_force, mu)),
                        )
                    };
                    // Skip points within reach of a change of piece or region.
                    let h = 1e-7;
                    let unchanged = (0..3).all(|k| {
                        [-1.0, 1.0].iter().all(|sgn| {
                            let y = x + Vector3::ith(k, 20.0 * h * sgn);
                            piece(&c.respond(&y, &history)) == piece(&r)
                                && c.project(&y, history.angle).region == p0.region
                        })
                    });
                    if !unchanged {
                        continue;
                    }
                    let cross = FrictionLaw::cross_limit(r.normal_force, history.friction);
                    let let_go = law == FrictionLaw::SlidingDirection
                        && r.friction.y.abs() >= cross * (1.0 - 1e-12)
                        && r.status == GapStatus::Slip;
                    seen.insert((law, kind, p0.region, r.status as u8 + 10 * u8::from(let_go)));
                    let mut fd = Matrix3::zeros();
                    for k in 0..3 {
                        let e = Vector3::ith(k, h);
                        let plus = c.respond(&(x + e), &history).residual;
                        let minus = c.respond(&(x - e), &history).residual;
                        fd.set_column(k, &((plus - minus) / (2.0 * h)));
                    }
                    let scale = r.tangent.norm().max(s.normal_stiffness * 1e-3);
                    let error = (fd - r.tangent).norm() / scale;
                    assert!(
                        error < 1e-5,
                        "{law:?} {kind} {:?} {:?}: relative error {error:e}\nanalytic {}\nfd {}",
                        p0.region,
                        r.status,
                        r.tangent,
                        fd
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
        centreline: Centreline::Line {
            point: [0.0; 3],
            axis: [0.0, 1.0, 0.0],
        },
        friction: 0.0,
        ..support(kinds().remove(0).1, FrictionLaw::Isotropic)
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
    let s = CurvedSupport {
        centreline: Centreline::Line {
            point: [0.0; 3],
            axis: [0.0, 1.0, 0.0],
        },
        ..support(kinds().remove(0).1, FrictionLaw::Isotropic)
    };
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
