//! Geometry of the rigid curved supports: the centreline shapes (line, circle/arc, parabola,
//! polyline), their frames, and the closest-point projection of a point on the tube around them
//! (distance, normal, surface coordinates `ξ` and their derivatives). The formulas are derived in
//! [the contact's](super) module doc; the contact law on top of them lives there.

use nalgebra::{Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::mech::elements::gap::FrictionLaw;

/// The centreline of a tube-shaped support.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Centreline {
    /// A straight line through `point` along `axis`: the support is a cylinder.
    Line { point: [f64; 3], axis: [f64; 3] },
    /// A circle (or, with `angles`, an arc) of `radius` about `axis` through `centre`: the
    /// support is a ring, e.g. a bent pipe arch. `angles`: `[from, to]` (rad) about `axis`,
    /// measured from `start_direction` (default: any direction normal to `axis`, see
    /// [`Frame`]); omitted, the whole circle.
    Circle {
        centre: [f64; 3],
        axis: [f64; 3],
        radius: f64,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        angles: Option<[f64; 2]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        start_direction: Option<[f64; 3]>,
    },
    /// A parabolic arch `apex + s along − (rise/half_span²) s² up`, `s ∈ [−half_span,
    /// half_span]` (span `2 half_span`, crown `apex`; the Python importer's parametrisation),
    /// traversed along `along`; its plane's normal is `up × along`.
    Parabola {
        apex: [f64; 3],
        up: [f64; 3],
        along: [f64; 3],
        half_span: f64,
        rise: f64,
    },
    /// A plane polyline through `points` (at least two), traversed from the first to the last;
    /// `normal` of its plane (default: the one about which it turns counter-clockwise, so that
    /// `t × normal` is its convex side; required when the points are collinear).
    Polyline {
        points: Vec<[f64; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        normal: Option<[f64; 3]>,
    },
}

/// A rigid curved support and the film nodes that may touch it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurvedSupport {
    /// Name (an identifier): FMU variables `<name>.<k>.slip`… per contact node.
    pub name: String,
    /// The centreline.
    pub centreline: Centreline,
    /// Radius of the tube around the centreline (m), `> 0`: the pipe's radius.
    pub tube_radius: f64,
    /// Film nodes that may touch the support.
    pub nodes: Vec<usize>,
    /// Penalty `k_n` (N/m).
    pub normal_stiffness: f64,
    /// Penalty `k_s` (N/m).
    pub tangential_stiffness: f64,
    /// Coulomb coefficient `μ`.
    pub friction: f64,
    /// Friction law (the gaps' names: `isotropic`, `sliding-direction`).
    #[serde(default)]
    pub friction_law: FrictionLaw,
}

/// The axis frame of a centreline: unit axis `a` and two unit vectors `e1`, `e2 = a × e1`
/// normal to it; `φ` is measured from `e1` toward `e2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub centre: Vector3<f64>,
    pub a: Vector3<f64>,
    pub e1: Vector3<f64>,
    pub e2: Vector3<f64>,
}

impl Frame {
    pub(super) fn new(centre: [f64; 3], axis: [f64; 3], start: Option<[f64; 3]>) -> Self {
        let a = Vector3::from(axis).normalize();
        let guess = start.map(Vector3::from).unwrap_or_else(|| {
            // Any direction normal to a: the global axis least aligned with it.
            let k = (0..3)
                .min_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
                .unwrap_or(0);
            Vector3::ith(k, 1.0)
        });
        let e1 = (guess - a * a.dot(&guess)).normalize();
        Self {
            centre: Vector3::from(centre),
            a,
            e1,
            e2: a.cross(&e1),
        }
    }
}

impl Centreline {
    /// Checks the shape itself (with the tube's radius `r`): the message names the bad field.
    /// The line's and circle's own fields are checked by the model's validation.
    pub fn check(&self, r: f64) -> Result<(), String> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        match self {
            Centreline::Line { .. } => Ok(()),
            Centreline::Circle { radius, angles, .. } => {
                if r >= *radius {
                    return Err(format!(
                        "tube_radius = {r} must be smaller than the circle's radius {radius}"
                    ));
                }
                match angles {
                    Some([lo, hi]) if hi - lo > std::f64::consts::TAU => {
                        Err(format!("angles [{lo}, {hi}] span more than a full turn"))
                    }
                    _ => Ok(()),
                }
            }
            Centreline::Parabola {
                apex,
                up,
                along,
                half_span,
                rise,
            } => {
                if !finite(apex) || !finite(up) || !finite(along) {
                    return Err("parabola apex, up or along not finite".into());
                }
                let (u, a) = (Vector3::from(*up), Vector3::from(*along));
                if u.norm() == 0.0 {
                    return Err("parabola up is the zero vector".into());
                }
                let u = u.normalize();
                if (a - u * u.dot(&a)).norm() <= 1e-9 * a.norm() || a.norm() == 0.0 {
                    return Err("parabola along is zero or parallel to up".into());
                }
                for (what, v) in [("half_span", *half_span), ("rise", *rise)] {
                    if !(v > 0.0 && v.is_finite()) {
                        return Err(format!("parabola {what} = {v} must be > 0"));
                    }
                }
                let crown = half_span * half_span / (2.0 * rise);
                if r >= crown {
                    return Err(format!(
                        "tube_radius = {r} must be smaller than the parabola's radius of \
                         curvature at its crown, half_span²/(2 rise) = {crown}"
                    ));
                }
                Ok(())
            }
            Centreline::Polyline { points, normal } => Polyline::new(points, *normal).map(|_| ()),
        }
    }
}

/// Which part of a support's surface the closest point lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Region {
    /// The tube over a smooth part of the centreline (and every point of a cylinder).
    Tube,
    /// The rounded corner (a sphere's zone) over an inner vertex of a polyline.
    Corner,
    /// The hemispherical cap over an end of an arc, a parabola or a polyline.
    EndCap,
}

/// Where a node is relative to a support.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Gap `g = d − r` (negative: penetration).
    pub gap: f64,
    /// Outward unit normal of the support at the closest point.
    pub normal: Vector3<f64>,
    /// Unwrapped angle `φ` about the axis (cylinder, circle), the parameter `s` of the closest
    /// point (parabola) or its arc length from the first point (polyline).
    pub parameter: f64,
    /// `∂n/∂x`.
    pub normal_derivative: Matrix3<f64>,
    /// Surface coordinates `[ξ1, ξ2]` and their gradients and Hessians.
    pub xi: Vector2<f64>,
    pub grad: [Vector3<f64>; 2],
    pub hessian: [Matrix3<f64>; 2],
    /// The part of the surface the closest point lies on.
    pub region: Region,
}

/// A polyline's segments: start points, unit tangents, arc length at each point and the
/// tangent's turning angle `θ_j` (about the plane's normal) on each segment.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Polyline {
    pub(super) points: Vec<Vector3<f64>>,
    pub(super) tangents: Vec<Vector3<f64>>,
    pub(super) length: Vec<f64>,
    pub(super) turn: Vec<f64>,
    pub(super) normal: Vector3<f64>,
}

impl Polyline {
    /// The polyline through `points`, or what is wrong with them.
    pub(super) fn new(points: &[[f64; 3]], normal: Option<[f64; 3]>) -> Result<Self, String> {
        if points.len() < 2 {
            return Err(format!(
                "polyline has {} point(s): at least two needed",
                points.len()
            ));
        }
        if let Some(i) = points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(format!("polyline points[{i}] not finite"));
        }
        let points: Vec<Vector3<f64>> = points.iter().map(|&p| Vector3::from(p)).collect();
        let total: f64 = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        let mut tangents = vec![];
        let mut length = vec![0.0];
        for (i, w) in points.windows(2).enumerate() {
            let l = (w[1] - w[0]).norm();
            if l <= 1e-9 * total {
                return Err(format!(
                    "polyline points[{i}] and points[{}] coincide: a segment of zero length",
                    i + 1
                ));
            }
            tangents.push((w[1] - w[0]) / l);
            length.push(length[i] + l);
        }
        for (j, t) in tangents.windows(2).enumerate() {
            if t[0].dot(&t[1]) <= -1.0 + 1e-9 {
                return Err(format!(
                    "polyline turns back on itself at points[{}]",
                    j + 1
                ));
            }
        }
        let normal = match normal {
            Some(n) => {
                let n = Vector3::from(n);
                if !(n.norm() > 0.0 && n.norm().is_finite()) {
                    return Err("polyline normal is zero or not finite".into());
                }
                n.normalize()
            }
            None => {
                // The plane of the first turn, oriented so that the turns add up positive.
                let turns = tangents.windows(2).map(|t| t[0].cross(&t[1]));
                let Some(first) = turns.clone().find(|c| c.norm() > 1e-9) else {
                    return Err("polyline points are collinear: give its plane's normal".into());
                };
                let total: Vector3<f64> = turns.sum();
                first.normalize() * total.dot(&first).signum()
            }
        };
        if let Some(j) = tangents.iter().position(|t| t.dot(&normal).abs() > 1e-6) {
            return Err(format!(
                "polyline points[{}] leaves the plane normal to {:?} through points[{j}]",
                j + 1,
                normal.as_slice()
            ));
        }
        let mut turn = vec![0.0];
        for (j, t) in tangents.windows(2).enumerate() {
            let delta = t[0].cross(&t[1]).dot(&normal).atan2(t[0].dot(&t[1]));
            turn.push(turn[j] + delta);
        }
        Ok(Self {
            points,
            tangents,
            length,
            turn,
            normal,
        })
    }
}

/// The centreline of a curve support with the data its closest point needs.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Path {
    /// Ring: frame (axis = plane normal), radius `Rc`, optional arc `[from, to]`.
    Circle {
        frame: Frame,
        radius: f64,
        arc: Option<[f64; 2]>,
    },
    /// `C(s) = apex + s along − k s² up`, `|s| ≤ half_span`.
    Parabola {
        apex: Vector3<f64>,
        along: Vector3<f64>,
        up: Vector3<f64>,
        k: f64,
        half_span: f64,
    },
    Polyline(Polyline),
}

/// The geometry of a support: a cylinder, or a tube with end caps around a plane curve.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Shape {
    Cylinder(Frame),
    Curve {
        path: Path,
        /// Unit normal `p` of the curve's plane: `ξ2 = p·(x − origin)`; `t × p` is the side
        /// whose surface length `ξ1` measures.
        normal: Vector3<f64>,
        origin: Vector3<f64>,
    },
}

/// The closest point of a plane curve (with end caps) to a node.
pub(super) enum Foot {
    /// On a smooth part, at parameter `u`: `C, C', C''` and `g, g', g''` of `ξ1 = g(u)`.
    Smooth {
        u: f64,
        c: [Vector3<f64>; 3],
        g: [f64; 3],
    },
    /// At an inner vertex of a polyline (arc length `u`): `ξ1 = base + r ψ`, `ψ` the angle
    /// about the plane's normal from the in-plane direction `start`.
    Corner {
        u: f64,
        point: Vector3<f64>,
        base: f64,
        start: Vector3<f64>,
    },
    /// At an end (parameter `u`) with unit tangent `t`: `ξ1 = g + t·(x − C)`.
    End {
        u: f64,
        point: Vector3<f64>,
        tangent: Vector3<f64>,
        g: f64,
    },
}

/// Root of `h`, decreasing on `[lo, hi]` with `h(lo) ≥ 0 ≥ h(hi)`: Newton from `guess`,
/// bisecting whenever a step leaves the bracket.
pub(super) fn bracketed_newton(
    h: impl Fn(f64) -> (f64, f64),
    mut lo: f64,
    mut hi: f64,
    guess: f64,
) -> f64 {
    let mut u = guess.clamp(lo, hi);
    for _ in 0..100 {
        let (v, dv) = h(u);
        if v > 0.0 {
            lo = u;
        } else if v < 0.0 {
            hi = u;
        } else {
            return u;
        }
        let newton = u - v / dv;
        let next = if dv < 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - u).abs() <= 1e-15 * (1.0 + u.abs()) || hi - lo <= 1e-15 * (1.0 + u.abs()) {
            return next;
        }
        u = next;
    }
    u
}

impl Path {
    /// The closest point to `x` (an angle unwrapped toward `near` for a circle; `near` starts
    /// the parabola's Newton iteration); `r` the tube's radius (in `ξ1`'s surface length).
    pub(super) fn foot(&self, x: &Vector3<f64>, near: f64, r: f64) -> Foot {
        match self {
            Path::Circle { frame, radius, arc } => circle_foot(frame, *radius, *arc, x, near, r),
            Path::Parabola {
                apex,
                along,
                up,
                k,
                half_span,
            } => parabola_foot([apex, along, up], [*k, *half_span], x, near, r),
            Path::Polyline(p) => polyline_foot(p, x, r),
        }
    }
}

/// [`Path::foot`] on a ring of radius `rc` (an arc `[from, to]` where given).
fn circle_foot(
    frame: &Frame,
    rc: f64,
    arc: Option<[f64; 2]>,
    x: &Vector3<f64>,
    near: f64,
    r: f64,
) -> Foot {
    let rel = x - frame.centre;
    let q = rel - frame.a * frame.a.dot(&rel);
    let angle = unwrapped_angle(frame, &q, near);
    let at = |phi: f64| {
        let e = frame.e1 * phi.cos() + frame.e2 * phi.sin();
        let t = frame.a.cross(&e);
        (frame.centre + e * rc, e, t)
    };
    let reference = rc + r;
    let angle = match arc {
        None => angle,
        Some([lo, hi]) => {
            // The angle, shifted by whole turns toward the middle of the arc.
            let tau = std::f64::consts::TAU;
            let phi = angle - tau * ((angle - 0.5 * (lo + hi)) / tau).round();
            if !(lo..=hi).contains(&phi) {
                let (p_lo, _, t_lo) = at(lo);
                let (p_hi, _, t_hi) = at(hi);
                return if (x - p_lo).norm() <= (x - p_hi).norm() {
                    Foot::End {
                        u: lo,
                        point: p_lo,
                        tangent: t_lo,
                        g: reference * lo,
                    }
                } else {
                    Foot::End {
                        u: hi,
                        point: p_hi,
                        tangent: t_hi,
                        g: reference * hi,
                    }
                };
            }
            phi
        }
    };
    let (c, e, t) = at(angle);
    Foot::Smooth {
        u: angle,
        c: [c, t * rc, -e * rc],
        g: [reference * angle, reference, 0.0],
    }
}

/// [`Path::foot`] on the parabola `C(s) = apex + s along − k s² up`, `|s| ≤ half_span`.
fn parabola_foot(
    [apex, along, up]: [&Vector3<f64>; 3],
    [k, l]: [f64; 2],
    x: &Vector3<f64>,
    near: f64,
    r: f64,
) -> Foot {
    let rel = x - apex;
    let (pa, pu) = (rel.dot(along), rel.dot(up));
    // (x − C(s))·C'(s) = pa − (1 + 2k pu) s − 2k² s³ =: h(s), h' = −D.
    let c1 = 1.0 + 2.0 * k * pu;
    let h = |s: f64| {
        (
            pa - c1 * s - 2.0 * k * k * s * s * s,
            -c1 - 6.0 * k * k * s * s,
        )
    };
    let point = |s: f64| apex + along * s - up * (k * s * s);
    // h decreases except on (−s_c, s_c) when c1 < 0: the minima of the distance are
    // its roots where it decreases, within [−L, L]; the ends are candidates too.
    let mut cuts = vec![-l];
    if c1 < 0.0 {
        let sc = (-c1 / (6.0 * k * k)).sqrt();
        cuts.extend([-sc, sc].into_iter().filter(|s| s.abs() < l));
    }
    cuts.push(l);
    let mut best: Option<(f64, f64, bool)> = None;
    let mut consider = |s: f64, interior: bool| {
        let d = (x - point(s)).norm_squared();
        if best.is_none_or(|(bd, _, _)| d < bd) {
            best = Some((d, s, interior));
        }
    };
    for w in cuts.windows(2) {
        let (lo, hi) = (w[0], w[1]);
        if h(0.5 * (lo + hi)).1 < 0.0 && h(lo).0 >= 0.0 && h(hi).0 <= 0.0 {
            consider(bracketed_newton(h, lo, hi, near), true);
        }
    }
    consider(-l, false);
    consider(l, false);
    let (_, s, interior) = best.unwrap_or((0.0, 0.0, true));
    let w = 2.0 * k * s;
    let root = (1.0 + w * w).sqrt();
    let arc = |s: f64| {
        let w = 2.0 * k * s;
        (w * (1.0 + w * w).sqrt() + w.asinh()) / (4.0 * k)
    };
    let g = arc(s) - arc(-l) + r * (w.atan() + (2.0 * k * l).atan());
    let c1v = along - up * w;
    if interior {
        let g1 = root + 2.0 * k * r / (1.0 + w * w);
        let g2 = 2.0 * k * w / root - 8.0 * k * k * r * w / ((1.0 + w * w) * (1.0 + w * w));
        Foot::Smooth {
            u: s,
            c: [point(s), c1v, -up * (2.0 * k)],
            g: [g, g1, g2],
        }
    } else {
        Foot::End {
            u: s,
            point: point(s),
            tangent: c1v / root,
            g,
        }
    }
}

/// [`Path::foot`] on a polyline: a segment, an end, or an inner vertex's corner zone.
fn polyline_foot(p: &Polyline, x: &Vector3<f64>, r: f64) -> Foot {
    // The nearest segment (first of equals), its parameter before clamping.
    let mut best = (f64::INFINITY, 0, 0.0);
    for (j, t) in p.tangents.iter().enumerate() {
        let len = p.length[j + 1] - p.length[j];
        let tau = (x - p.points[j]).dot(t);
        let d = (x - (p.points[j] + t * tau.clamp(0.0, len))).norm_squared();
        if d < best.0 {
            best = (d, j, tau);
        }
    }
    let (_, j, tau) = best;
    let len = p.length[j + 1] - p.length[j];
    let last = p.tangents.len() - 1;
    let vertex = if tau <= 0.0 {
        j
    } else if tau >= len {
        j + 1
    } else {
        let t = p.tangents[j];
        return Foot::Smooth {
            u: p.length[j] + tau,
            c: [p.points[j] + t * tau, t, Vector3::zeros()],
            g: [p.length[j] + tau + r * p.turn[j], 1.0, 0.0],
        };
    };
    if vertex == 0 || vertex == last + 1 {
        let s = vertex.min(last);
        return Foot::End {
            u: p.length[vertex],
            point: p.points[vertex],
            tangent: p.tangents[s],
            g: p.length[vertex] + r * p.turn[s],
        };
    }
    // An inner vertex: the corner's zone starts at the incoming segment's normal on
    // the convex side (the side the turn tells; for a straight vertex the node's).
    let outer = p.tangents[vertex - 1].cross(&p.normal);
    let delta = p.turn[vertex] - p.turn[vertex - 1];
    let side = if delta != 0.0 {
        delta
    } else {
        (x - p.points[vertex]).dot(&outer)
    };
    Foot::Corner {
        u: p.length[vertex],
        point: p.points[vertex],
        base: p.length[vertex] + r * p.turn[vertex - 1],
        start: if side >= 0.0 { outer } else { -outer },
    }
}

/// Angle of `v` (normal to `a`) about `a` in the frame, unwrapped toward `near`.
pub(super) fn unwrapped_angle(frame: &Frame, v: &Vector3<f64>, near: f64) -> f64 {
    let raw = v.dot(&frame.e2).atan2(v.dot(&frame.e1));
    let tau = std::f64::consts::TAU;
    raw + tau * ((near - raw) / tau).round()
}
