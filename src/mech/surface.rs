//! Node-to-surface friction contact on rigid curved supports (issue 10): a film node against a
//! tube of radius `r` around a centreline — a straight line (a cylinder) or a plane curve
//! (circle/arc, parabola, polyline) — whose closest point, normal and sliding directions
//! follow the node (the paper's fixed gap frames, §4.3–4.4, do not).
//!
//! **Cylinder** (axis `a` through `c0`, `q = (I − a⊗a)(x − c0)`, `ρ = |q|`, `e_ρ = q/ρ`,
//! `T = a × e_ρ`, angle `φ` of `e_ρ` about `a` unwrapped from the last converged value):
//! `d = ρ`, `n = e_ρ`, `∂n/∂x = T⊗T/d`; `ξ1 = r φ` round the axis (`∇ξ1 = (r/ρ) T`,
//! `∇²ξ1 = −(r/ρ²)(e_ρ⊗T + T⊗e_ρ)`), `ξ2 = a·(x − c0)` along it.
//!
//! **Plane curve** `C(u)` in the plane of unit normal `p` (a circle's axis; `up × along` for a
//! parabola; a polyline's `normal`), closed by hemispherical caps at the ends of an open curve.
//! The closest point of the curve (ends included) to `x`, `w = x − C`, `d = |w|`, `n = w/d`:
//!
//! * on a smooth part, `w·C′(u) = 0` gives `∇u = C′/D`, `D = |C′|² − w·C″`,
//!   `∇²u = (C′⊗C″ + C″⊗C′)/D² − (3 C′·C″ − w·C‴) C′⊗C′/D³` (`w·C‴ = 0` on these curves:
//!   `C‴ ∥ C′` on a circle, `C‴ = 0` on a parabola or a segment),
//!   `∂n/∂x = (I − n⊗n − C′⊗C′/D)/d`; with `ξ1 = g(u)`: `∇ξ1 = g′ ∇u`,
//!   `∇²ξ1 = g″ ∇u⊗∇u + g′ ∇²u` (for a ring `D = Rc ρ`: the ring formulas);
//! * at a polyline's inner vertex `V` (the node in the wedge between the two segments'
//!   normals, on the convex side of the turn): `C = V`, `∂n/∂x = (I − n⊗n)/d`,
//!   `ξ1 = ξ1(V⁻) + r ψ`, `ψ` the angle of `w`'s in-plane part about `p` from the incoming
//!   segment's normal: the cylinder's formulas about the line through `V` along `p`;
//! * beyond an end `E` (tangent `t_E`): `C = E`, `∂n/∂x = (I − n⊗n)/d`,
//!   `ξ1 = ξ1(E) + t_E·w` (the distance past the end's normal plane), `∇ξ1 = t_E`.
//!
//! `ξ1` is the length along the tube's surface on the side `t × p` (the outer side of a circle
//! turning counter-clockwise about `p`, the top of an arch): `g(u) = s(u) + r θ(u)`, `s` the
//! centreline's arc length, `θ` its tangent's turning angle about `p` — `(Rc + r) φ` on a ring,
//! `s + r atan(2ku)` (plus constants) on a parabola `apex + u along − k u² up`, segment lengths
//! plus `r ×` each corner's turn on a polyline; continuous over corners and caps. `ξ2 = p·(x − C0)`
//! across (exact for a straight tube, to first order in the normal's tilt out of the plane on a
//! curved one). On the concave side of a polyline's vertex the two segments' tubes meet in a
//! crease where the closest point jumps from one segment to the next: the normal turns by the
//! vertex's angle `Δ` at once and `ξ1` jumps by `2d tan(|Δ|/2) ∓ r|Δ|` (`−` on the `t × p`
//! side, `+` on the other); use finer polylines or a parabola where a film slides there.
//!
//! Normal: gap `g = d − r`, contact force `λN = k_n ⟨−g⟩` along `n` (the paper's penalty).
//! Friction (penalty `k_s`, history `ξ̄` of the last converged state): trial
//! `f = −k_s (ξ − ξ̄)`; `isotropic`: Coulomb cone `|f| ≤ μλN`, returned to it along `f`;
//! `sliding-direction` (the paper's law): `ξ1` slides at `|f1| = μλN`, `ξ2` stays elastic.
//! Force on the film `F = λN n + Σ fα ∇ξα`; consistent tangent of `−F`:
//! `k_n n⊗n − λN ∂n/∂x − Σ (∂fα/∂ξβ) ∇ξα⊗∇ξβ − Σ (∂fα/∂λN) ∇ξα⊗∇λN − Σ fα ∇²ξα`
//! (`∇λN = −k_n n`), checked against central differences in every status and region
//! (`tangent_matches_finite_differences_in_every_status`). The slip reported is `ξ1 − ξ1(0)`:
//! the length the node has travelled along the support, as the experiment measured it.
//! Source of the formulas: the project's note on node-to-curve contact (derived and
//! FD-checked there), following Wriggers, *Computational Contact Mechanics* (2006), ch. 4
//! (closest-point projection on a curve: `∇u`, the curvature terms).

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use super::assembly::{System, node_vector};
use super::contact::{FrictionLaw, GapStatus};
use super::element::ElementMatrix;
use super::model::Model;

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
    fn new(centre: [f64; 3], axis: [f64; 3], start: Option<[f64; 3]>) -> Self {
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
struct Polyline {
    points: Vec<Vector3<f64>>,
    tangents: Vec<Vector3<f64>>,
    length: Vec<f64>,
    turn: Vec<f64>,
    normal: Vector3<f64>,
}

impl Polyline {
    /// The polyline through `points`, or what is wrong with them.
    fn new(points: &[[f64; 3]], normal: Option<[f64; 3]>) -> Result<Self, String> {
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
enum Path {
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
enum Shape {
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
enum Foot {
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
fn bracketed_newton(h: impl Fn(f64) -> (f64, f64), mut lo: f64, mut hi: f64, guess: f64) -> f64 {
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
    fn foot(&self, x: &Vector3<f64>, near: f64, r: f64) -> Foot {
        match self {
            Path::Circle { frame, radius, arc } => {
                let rc = *radius;
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
                        if !(*lo..=*hi).contains(&phi) {
                            let (p_lo, _, t_lo) = at(*lo);
                            let (p_hi, _, t_hi) = at(*hi);
                            return if (x - p_lo).norm() <= (x - p_hi).norm() {
                                Foot::End {
                                    u: *lo,
                                    point: p_lo,
                                    tangent: t_lo,
                                    g: reference * lo,
                                }
                            } else {
                                Foot::End {
                                    u: *hi,
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
            Path::Parabola {
                apex,
                along,
                up,
                k,
                half_span,
            } => {
                let (k, l) = (*k, *half_span);
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
                    let g2 =
                        2.0 * k * w / root - 8.0 * k * k * r * w / ((1.0 + w * w) * (1.0 + w * w));
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
            Path::Polyline(p) => {
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
        }
    }
}

/// One contact: a support and a node.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceContact {
    shape: Shape,
    tube_radius: f64,
    pub node: usize,
    kn: f64,
    ks: f64,
    law: FrictionLaw,
}

/// The history a contact carries from one converged state to the next.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactHistory {
    /// Anchor `ξ̄` of the tangential penalty (m).
    pub anchor: [f64; 2],
    /// [`Projection::parameter`] at the converged state: the unwrapped angle is the branch for
    /// the next projection, the parabola's parameter the start of its Newton iteration.
    pub angle: f64,
    /// `ξ1` from which the slip is measured: that of the reference configuration, moved with
    /// the node over every step that starts open.
    pub origin: f64,
    /// Status at convergence.
    pub status: GapStatus,
    /// Friction coefficient.
    pub friction: f64,
}

/// Force on the film, tangent and status of a contact at one iterate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactResponse {
    /// Residual contribution `−F` (the support's force on the film is `F`).
    pub residual: Vector3<f64>,
    /// `∂(−F)/∂x`.
    pub tangent: Matrix3<f64>,
    pub status: GapStatus,
    /// `λN ≥ 0` (N).
    pub normal_force: f64,
    /// Friction force components `[f1, f2]` along `ξ1`, `ξ2` (N).
    pub friction: Vector2<f64>,
    /// `ξ` at this iterate, and the anchor to commit if it converges.
    pub xi: Vector2<f64>,
    pub next_anchor: Vector2<f64>,
    /// [`Projection::parameter`] at this iterate.
    pub angle: f64,
}

/// Angle of `v` (normal to `a`) about `a` in the frame, unwrapped toward `near`.
fn unwrapped_angle(frame: &Frame, v: &Vector3<f64>, near: f64) -> f64 {
    let raw = v.dot(&frame.e2).atan2(v.dot(&frame.e1));
    let tau = std::f64::consts::TAU;
    raw + tau * ((near - raw) / tau).round()
}

/// `e⊗T + T⊗e`.
fn sym(e: &Vector3<f64>, t: &Vector3<f64>) -> Matrix3<f64> {
    e * t.transpose() + t * e.transpose()
}

impl SurfaceContact {
    /// Contact of `node` with `support` (validated: see [`Centreline::check`]).
    pub fn new(support: &CurvedSupport, node: usize) -> Self {
        let shape = match &support.centreline {
            Centreline::Line { point, axis } => Shape::Cylinder(Frame::new(*point, *axis, None)),
            Centreline::Circle {
                centre,
                axis,
                radius,
                angles,
                start_direction,
            } => {
                let frame = Frame::new(*centre, *axis, *start_direction);
                Shape::Curve {
                    normal: frame.a,
                    origin: frame.centre,
                    path: Path::Circle {
                        frame,
                        radius: *radius,
                        arc: *angles,
                    },
                }
            }
            Centreline::Parabola {
                apex,
                up,
                along,
                half_span,
                rise,
            } => {
                let up = Vector3::from(*up).normalize();
                let along = Vector3::from(*along);
                let along = (along - up * up.dot(&along)).normalize();
                Shape::Curve {
                    normal: up.cross(&along),
                    origin: Vector3::from(*apex),
                    path: Path::Parabola {
                        apex: Vector3::from(*apex),
                        along,
                        up,
                        k: rise / (half_span * half_span),
                        half_span: *half_span,
                    },
                }
            }
            Centreline::Polyline { points, normal } => {
                let p = Polyline::new(points, *normal)
                    .unwrap_or_else(|e| panic!("support '{}' not validated: {e}", support.name));
                Shape::Curve {
                    normal: p.normal,
                    origin: p.points[0],
                    path: Path::Polyline(p),
                }
            }
        };
        Self {
            shape,
            tube_radius: support.tube_radius,
            node,
            kn: support.normal_stiffness,
            ks: support.tangential_stiffness,
            law: support.friction_law,
        }
    }

    /// The projection of the point `x`, an angle unwrapped toward `near` (the last converged
    /// [`Projection::parameter`]).
    pub fn project(&self, x: &Vector3<f64>, near: f64) -> Projection {
        let r = self.tube_radius;
        let (path, p, origin) = match &self.shape {
            Shape::Cylinder(f) => return self.project_on_cylinder(f, x, near),
            Shape::Curve {
                path,
                normal,
                origin,
            } => (path, normal, origin),
        };
        let eye = Matrix3::identity();
        let foot = path.foot(x, near, r);
        let point = match &foot {
            Foot::Smooth { c, .. } => c[0],
            Foot::Corner { point, .. } | Foot::End { point, .. } => *point,
        };
        let w = x - point;
        let d = w.norm();
        let n = w / d;
        let nn = n * n.transpose();
        let (parameter, region, dn, xi1, grad1, hessian1) = match foot {
            Foot::Smooth { u, c, g } => {
                // w·C'(u) = 0: ∇u = C'/D, D = |C'|² − w·C''.
                let dd = c[1].norm_squared() - w.dot(&c[2]);
                let grad_u = c[1] / dd;
                let hess_u = sym(&c[1], &c[2]) / (dd * dd)
                    - c[1] * c[1].transpose() * (3.0 * c[1].dot(&c[2]) / dd.powi(3));
                (
                    u,
                    Region::Tube,
                    (eye - nn - c[1] * c[1].transpose() / dd) / d,
                    g[0],
                    grad_u * g[1],
                    grad_u * grad_u.transpose() * g[2] + hess_u * g[1],
                )
            }
            Foot::Corner { u, base, start, .. } => {
                // ξ1 = base + r ψ, ψ the angle of w's in-plane part about p from `start`.
                let q = w - p * p.dot(&w);
                let rho = q.norm();
                let e = q / rho;
                let t = p.cross(&e);
                let psi = start.cross(&q).dot(p).atan2(start.dot(&q));
                (
                    u,
                    Region::Corner,
                    (eye - nn) / d,
                    base + r * psi,
                    t * (r / rho),
                    sym(&e, &t) * (-r / (rho * rho)),
                )
            }
            Foot::End { u, tangent, g, .. } => (
                u,
                Region::EndCap,
                (eye - nn) / d,
                g + tangent.dot(&w),
                tangent,
                Matrix3::zeros(),
            ),
        };
        Projection {
            gap: d - r,
            normal: n,
            parameter,
            normal_derivative: dn,
            xi: Vector2::new(xi1, p.dot(&(x - origin))),
            grad: [grad1, *p],
            hessian: [hessian1, Matrix3::zeros()],
            region,
        }
    }

    /// A cylinder: `ξ1 = r φ` round the axis, `ξ2` along it.
    fn project_on_cylinder(&self, f: &Frame, x: &Vector3<f64>, near: f64) -> Projection {
        let a = f.a;
        let rel = x - f.centre;
        let q = rel - a * a.dot(&rel);
        let rho = q.norm();
        let e_rho = q / rho;
        let t = a.cross(&e_rho);
        let angle = unwrapped_angle(f, &q, near);
        let r = self.tube_radius;
        Projection {
            gap: rho - r,
            normal: e_rho,
            parameter: angle,
            normal_derivative: t * t.transpose() / rho,
            xi: Vector2::new(r * angle, a.dot(&rel)),
            grad: [t * (r / rho), a],
            hessian: [sym(&e_rho, &t) * (-r / (rho * rho)), Matrix3::zeros()],
            region: Region::Tube,
        }
    }

    /// The contact's response at node position `x` from the converged `history`.
    pub fn respond(&self, x: &Vector3<f64>, history: &ContactHistory) -> ContactResponse {
        let p = self.project(x, history.angle);
        let anchor = Vector2::from(history.anchor);
        let open = ContactResponse {
            residual: Vector3::zeros(),
            tangent: Matrix3::zeros(),
            status: GapStatus::Open,
            normal_force: 0.0,
            friction: Vector2::zeros(),
            xi: p.xi,
            // An open contact forgets its anchor: it sticks where it touches down next.
            next_anchor: p.xi,
            angle: p.parameter,
        };
        if p.gap >= 0.0 {
            return open;
        }
        let lambda = -self.kn * p.gap;
        let n = p.normal;
        let limit = history.friction * lambda;
        let trial = -(p.xi - anchor) * self.ks;
        // f, ∂f/∂ξ and ∂f/∂λN per law and status.
        let (status, f, df_dxi, df_dlambda) = match self.law {
            FrictionLaw::Isotropic => {
                let m = trial.norm();
                if m <= limit {
                    (
                        GapStatus::Stick,
                        trial,
                        -Matrix2::identity() * self.ks,
                        Vector2::zeros(),
                    )
                } else {
                    let dir = trial / m;
                    let f = dir * limit;
                    let dfd =
                        -(Matrix2::identity() - dir * dir.transpose()) * (self.ks * limit / m);
                    (GapStatus::Slip, f, dfd, dir * history.friction)
                }
            }
            FrictionLaw::SlidingDirection => {
                let mut dfd = -Matrix2::identity() * self.ks;
                if trial.x.abs() <= limit {
                    (GapStatus::Stick, trial, dfd, Vector2::zeros())
                } else {
                    let s = trial.x.signum();
                    dfd[(0, 0)] = 0.0;
                    (
                        GapStatus::Slip,
                        Vector2::new(s * limit, trial.y),
                        dfd,
                        Vector2::new(s * history.friction, 0.0),
                    )
                }
            }
        };
        let force = n * lambda + p.grad[0] * f.x + p.grad[1] * f.y;
        let grad_lambda = -n * self.kn;
        let mut k = n * n.transpose() * self.kn - p.normal_derivative * lambda;
        for al in 0..2 {
            for be in 0..2 {
                k -= p.grad[al] * p.grad[be].transpose() * df_dxi[(al, be)];
            }
            k -= p.grad[al] * grad_lambda.transpose() * df_dlambda[al];
            k -= p.hessian[al] * f[al];
        }
        ContactResponse {
            residual: -force,
            tangent: k,
            status,
            normal_force: lambda,
            friction: f,
            xi: p.xi,
            // f = −k_s (ξ − ξ̄_new): the anchor the committed friction force implies.
            next_anchor: p.xi + f / self.ks,
            angle: p.parameter,
        }
    }

    /// Checks a converged `history` read back, at node position `x`, against this contact's own
    /// law ([`SurfaceContact::respond`], either friction law): open where the gap is not
    /// negative; in contact (stick or slip) where it is not positive, with an anchor that the
    /// law's return map leaves where it is (stick inside the limit, slip on it), and for slip
    /// the trial force on or beyond the limit (`|f|` isotropic, `|f1|` sliding-direction). The
    /// gap to `length_tolerance` (m), forces to `force_tolerance` (N). Err: what differs.
    pub fn check_committed(
        &self,
        x: &Vector3<f64>,
        history: &ContactHistory,
        length_tolerance: f64,
        force_tolerance: f64,
    ) -> Result<(), String> {
        let gap = self.project(x, history.angle).gap;
        let r = self.respond(x, history);
        let anchor = Vector2::from(history.anchor);
        let moved = (r.next_anchor - anchor).norm() * self.ks;
        let trial = -(r.xi - anchor) * self.ks;
        let measure = match self.law {
            FrictionLaw::Isotropic => trial.norm(),
            FrictionLaw::SlidingDirection => trial.x.abs(),
        };
        let limit = history.friction * r.normal_force;
        let in_contact = gap <= length_tolerance && moved <= force_tolerance;
        let consistent = match history.status {
            GapStatus::Open => gap >= -length_tolerance,
            GapStatus::Stick => in_contact,
            GapStatus::Slip => in_contact && measure >= limit - force_tolerance,
        };
        if consistent {
            return Ok(());
        }
        Err(format!(
            "the {} law gives {:?} there (gap {gap:e} m, trial friction ({:e}, {:e}) N, \
             limit μN = {limit:e} N, a further slip of {:e} m)",
            self.law,
            r.status,
            trial.x,
            trial.y,
            moved / self.ks
        ))
    }

    /// The history of the undeformed state at `x0` with friction `mu`.
    pub fn initial_history(&self, x0: &Vector3<f64>, mu: f64) -> ContactHistory {
        let p = self.project(x0, 0.0);
        ContactHistory {
            anchor: p.xi.into(),
            angle: p.parameter,
            origin: p.xi.x,
            // A node that starts on the support is in contact from the start (its first step
            // slides); the others approach first.
            status: if p.gap <= 0.0 {
                GapStatus::Stick
            } else {
                GapStatus::Open
            },
            friction: mu,
        }
    }
}

/// Results of one contact node.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SurfaceContactResult {
    /// Arc length slid along the support while in contact (m): the change of `ξ1` summed over
    /// the converged steps that start in contact (a step that starts open is approach, not
    /// sliding); for a node in contact from the start, `ξ1 − ξ1(0)`.
    pub slip: f64,
    /// Arc length the node has travelled along the support since the start, `ξ1 − ξ1(0)`, in
    /// contact or not (what a fixed-frame gap's local-x displacement approximates) (m).
    pub travel: f64,
    /// Travel along the axis (across a ring), `ξ2 − ξ2(0)` (m).
    pub slip_across: f64,
    /// Gap `d − r` (m; negative: penetration).
    pub gap: f64,
    /// Closest point on the support's surface (m, current).
    pub contact_point: [f64; 3],
    /// Normal force (N).
    pub normal_force: f64,
    /// Friction force magnitude (N).
    pub friction_force: f64,
    /// Friction force components along `ξ1` (the support's length) and `ξ2` (across) (N).
    #[serde(default)]
    pub friction: [f64; 2],
    /// Force of the support on the film, global axes: normal and friction (N).
    #[serde(default)]
    pub force: [f64; 3],
    pub status: GapStatus,
}

/// Every contact of the model's curved supports.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceContacts {
    pub contacts: Vec<SurfaceContact>,
    /// A triangle with each contact's node and the node's position in it (for the slots).
    slots: Vec<(usize, usize)>,
    reference: Vec<Vector3<f64>>,
}

impl SurfaceContacts {
    /// The contacts of a validated model.
    pub fn new(model: &Model) -> Self {
        let mut contacts = vec![];
        for s in &model.curved_supports {
            for &v in &s.nodes {
                contacts.push(SurfaceContact::new(s, v));
            }
        }
        let mut first = vec![None; model.nodes.len()];
        for (t, tri) in model.triangles.iter().enumerate() {
            for (k, &v) in tri.iter().enumerate() {
                first[v].get_or_insert((t, k));
            }
        }
        let slots = contacts
            .iter()
            .map(|c| first[c.node].unwrap_or((0, 0)))
            .collect();
        Self {
            contacts,
            slots,
            reference: model.nodes.iter().map(|&p| Vector3::from(p)).collect(),
        }
    }

    /// Histories of the undeformed state, with each support's friction coefficient.
    pub fn initial_histories(&self, model: &Model) -> Vec<ContactHistory> {
        let mus = model
            .curved_supports
            .iter()
            .flat_map(|s| s.nodes.iter().map(move |_| s.friction));
        self.contacts
            .iter()
            .zip(mus)
            .map(|(c, mu)| c.initial_history(&self.reference[c.node], mu))
            .collect()
    }

    fn position(&self, c: &SurfaceContact, u: &[f64]) -> Vector3<f64> {
        self.reference[c.node] + node_vector(u, c.node)
    }

    /// Each contact's response at `u` from the converged `histories`.
    pub fn respond(&self, u: &[f64], histories: &[ContactHistory]) -> Vec<ContactResponse> {
        self.contacts
            .iter()
            .zip(histories)
            .map(|(c, h)| c.respond(&self.position(c, u), h))
            .collect()
    }

    /// Adds the contacts' residuals and tangents at `u` (from `histories`) to `residual` and
    /// the Newton matrix `values`; leaves the responses in `responses` (reused: no allocation
    /// once it has grown).
    pub fn add_to(
        &self,
        system: &System,
        u: &[f64],
        histories: &[ContactHistory],
        residual: &mut [f64],
        mut values: Option<&mut [f64]>,
        responses: &mut Vec<ContactResponse>,
    ) {
        responses.clear();
        responses.extend(
            self.contacts
                .iter()
                .zip(histories)
                .map(|(c, h)| c.respond(&self.position(c, u), h)),
        );
        for ((c, r), &(triangle, local)) in
            self.contacts.iter().zip(responses.iter()).zip(&self.slots)
        {
            for k in 0..3 {
                residual[3 * c.node + k] += r.residual[k];
            }
            if let Some(values) = values.as_deref_mut()
                && r.status != GapStatus::Open
            {
                let mut ke = ElementMatrix::zeros();
                ke.fixed_view_mut::<3, 3>(3 * local, 3 * local)
                    .copy_from(&r.tangent);
                system.add_element_matrix(triangle, &ke, values);
            }
        }
    }

    /// The histories to carry on from a converged iterate's `responses`.
    pub fn commit(
        responses: &[ContactResponse],
        histories: &[ContactHistory],
    ) -> Vec<ContactHistory> {
        responses
            .iter()
            .zip(histories)
            .map(|(r, h)| ContactHistory {
                anchor: r.next_anchor.into(),
                angle: r.angle,
                status: r.status,
                // Slip is sliding in contact: a step that starts open (where the anchor is the
                // node's `ξ1`) moves the origin with the node, so its travel is not counted.
                origin: if h.status == GapStatus::Open {
                    h.origin + r.xi.x - h.anchor[0]
                } else {
                    h.origin
                },
                ..*h
            })
            .collect()
    }

    /// [`SurfaceContact::check_committed`] for every contact at `u`, with tolerances scaled by
    /// `size` (m): Err names the first contact that fails by its position in the model.
    pub fn check_committed(
        &self,
        u: &[f64],
        histories: &[ContactHistory],
        size: f64,
    ) -> Result<(), (usize, String)> {
        for (k, (c, h)) in self.contacts.iter().zip(histories).enumerate() {
            let x = self.position(c, u);
            let lambda = c.kn * (-c.project(&x, h.angle).gap).max(0.0);
            let force = 1e-6 * (h.friction * lambda).max(c.ks * 1e-9 * size);
            c.check_committed(&x, h, 1e-9 * size, force)
                .map_err(|e| (k, e))?;
        }
        Ok(())
    }

    /// Results at `u` with the converged `histories`.
    pub fn results(&self, u: &[f64], histories: &[ContactHistory]) -> Vec<SurfaceContactResult> {
        self.contacts
            .iter()
            .zip(histories)
            .map(|(c, h)| {
                let x = self.position(c, u);
                let p = c.project(&x, h.angle);
                let x0 = c.project(&self.reference[c.node], 0.0);
                let r = c.respond(&x, h);
                SurfaceContactResult {
                    contact_point: (x - p.normal * p.gap).into(),
                    slip: p.xi.x - h.origin,
                    travel: p.xi.x - x0.xi.x,
                    slip_across: p.xi.y - x0.xi.y,
                    gap: p.gap,
                    normal_force: r.normal_force,
                    friction_force: r.friction.norm(),
                    friction: r.friction.into(),
                    force: (-r.residual).into(),
                    status: h.status,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
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

    /// Central differences of the residual against the tangent, for random positions near the
    /// support (in every region of its surface: tube, polyline corners, end caps) and anchors
    /// chosen to give each status.
    #[test]
    fn tangent_matches_finite_differences_in_every_status() {
        let mut seen = std::collections::HashSet::new();
        let mut seed = 7u64;
        let mut rand = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
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
                    let depth = 1e-4 * (rand() + 0.3);
                    let x = y - py.normal * (py.gap + depth);
                    let p0 = c.project(&x, py.parameter);
                    // Anchors near ξ (stick) or far (slip), either side.
                    let offset = if case % 3 == 0 { 1e-6 } else { 5e-3 } * rand().signum();
                    let history = ContactHistory {
                        anchor: [p0.xi.x + offset, p0.xi.y - 0.5 * offset],
                        angle: p0.parameter,
                        origin: 0.0,
                        status: GapStatus::Stick,
                        friction: 0.3,
                    };
                    let r = c.respond(&x, &history);
                    // Skip points within reach of a change of status or region.
                    let h = 1e-7;
                    let unchanged = (0..3).all(|k| {
                        [-1.0, 1.0].iter().all(|sgn| {
                            let y = x + Vector3::ith(k, 20.0 * h * sgn);
                            c.respond(&y, &history).status == r.status
                                && c.project(&y, history.angle).region == p0.region
                        })
                    });
                    if !unchanged {
                        continue;
                    }
                    seen.insert((law, kind, p0.region, r.status as u8));
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
                for region in regions {
                    for status in [GapStatus::Stick, GapStatus::Slip] {
                        assert!(
                            seen.contains(&(law, kind, region, status as u8)),
                            "{law:?} {kind} {region:?} {status:?} never tested"
                        );
                    }
                }
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
}
