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
//! `sliding-direction` (the paper's law): `ξ1` slides at `|f1| = μλN`, `ξ2` stays elastic up to
//! the cross hold `|f2| ≤ κλN` (`FrictionLaw::CROSS_HOLD`; the gap module's "cross hold at
//! lift-off": the hold goes to zero with the normal force).
//! Force on the film `F = λN n + Σ fα ∇ξα`; consistent tangent of `−F`:
//! `k_n n⊗n − λN ∂n/∂x − Σ (∂fα/∂ξβ) ∇ξα⊗∇ξβ − Σ (∂fα/∂λN) ∇ξα⊗∇λN − Σ fα ∇²ξα`
//! (`∇λN = −k_n n`), checked against central differences in every status and region
//! (`tangent_matches_finite_differences_in_every_status`). The slip reported is `ξ1 − ξ1(0)`:
//! the length the node has travelled along the support, as the experiment measured it.
//! Source of the formulas: the project's note on node-to-curve contact (derived and
//! FD-checked there), following Wriggers, *Computational Contact Mechanics* (2006), ch. 4
//! (closest-point projection on a curve: `∇u`, the curvature terms).
//!
//! | file | what |
//! |---|---|
//! | `mod.rs` | the contact law: [`SurfaceContact`], [`SurfaceContacts`], histories, responses |
//! | [`surface`] | the supports' geometry: centrelines, frames, closest-point projection |
//! | `tests` | tangent against central differences, caps, corners, slip |

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::mech::elements::gap::{FrictionLaw, GapStatus};
use crate::mech::elements::triangle::ElementMatrix;
use crate::mech::model::Model;
use crate::mech::solve::assembly::{System, node_vector};
pub mod surface;

use surface::*;
pub use surface::{Centreline, CurvedSupport};

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
    /// The status whose law gave this response (imposed in an active-set iteration).
    pub status: GapStatus,
    /// `λN ≥ 0` (N; negative only where a closed status was imposed on an open gap).
    pub normal_force: f64,
    /// The signed gap to the surface (m; negative: pressed in).
    pub gap: f64,
    /// Friction force components `[f1, f2]` along `ξ1`, `ξ2` (N).
    pub friction: Vector2<f64>,
    /// `ξ` at this iterate, and the anchor to commit if it converges.
    pub xi: Vector2<f64>,
    pub next_anchor: Vector2<f64>,
    /// [`Projection::parameter`] at this iterate.
    pub angle: f64,
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
        self.respond_held(x, history, None)
    }

    /// [`Self::respond`] with the friction status `held` imposed where the contact is closed
    /// (stick: the elastic law; slip: on the bound along the slip direction; None: the law's
    /// own): the Newton loop's hold of a contact cycling between stick and slip (`newton.rs`).
    pub fn respond_held(
        &self,
        x: &Vector3<f64>,
        history: &ContactHistory,
        held: Option<GapStatus>,
    ) -> ContactResponse {
        let p = self.project(x, history.angle);
        let anchor = Vector2::from(history.anchor);
        let lambda = -self.kn * p.gap;
        let limit = history.friction * lambda;
        let trial = -(p.xi - anchor) * self.ks;
        let cross = FrictionLaw::cross_limit(lambda, history.friction);
        let status = if p.gap >= 0.0 {
            GapStatus::Open
        } else if match self.law {
            FrictionLaw::Isotropic => trial.norm() <= limit,
            FrictionLaw::SlidingDirection => trial.x.abs() <= limit && trial.y.abs() <= cross,
        } {
            GapStatus::Stick
        } else {
            GapStatus::Slip
        };
        let open = ContactResponse {
            residual: Vector3::zeros(),
            tangent: Matrix3::zeros(),
            status: GapStatus::Open,
            normal_force: 0.0,
            gap: p.gap,
            friction: Vector2::zeros(),
            xi: p.xi,
            // An open contact forgets its anchor: it sticks where it touches down next.
            next_anchor: p.xi,
            angle: p.parameter,
        };
        if status == GapStatus::Open {
            return open;
        }
        let used = held.unwrap_or(status);
        let n = p.normal;
        // f, ∂f/∂ξ and ∂f/∂λN per law and status.
        let (status, f, df_dxi, df_dlambda) = match self.law {
            FrictionLaw::Isotropic => {
                let m = trial.norm();
                if used == GapStatus::Stick || m == 0.0 {
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
                // Each direction elastic inside its bound (μN along, κN across the support)
                // and on it beyond: `f = ±bound`, `∂f/∂λN = ±ratio`.
                let mut dfd = -Matrix2::identity() * self.ks;
                let mut dfl = Vector2::zeros();
                let mut f = trial;
                let kappa = FrictionLaw::CROSS_HOLD.max(history.friction);
                for (i, (bound, ratio)) in [(limit, history.friction), (cross, kappa)]
                    .into_iter()
                    .enumerate()
                {
                    let on_bound = match held {
                        Some(GapStatus::Stick) => false,
                        Some(GapStatus::Slip) if i == 0 => true,
                        _ => trial[i].abs() > bound,
                    };
                    if on_bound {
                        f[i] = trial[i].signum() * bound;
                        dfd[(i, i)] = 0.0;
                        dfl[i] = trial[i].signum() * ratio;
                    }
                }
                (used, f, dfd, dfl)
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
            gap: p.gap,
            friction: f,
            xi: p.xi,
            // f = −k_s (ξ − ξ̄_new): the anchor the committed friction force implies.
            next_anchor: p.xi + f / self.ks,
            angle: p.parameter,
        }
    }

    /// The tube's radius (m).
    pub fn tube_radius(&self) -> f64 {
        self.tube_radius
    }

    /// The friction law.
    pub fn law(&self) -> FrictionLaw {
        self.law
    }

    /// Checks a converged `history` read back, at node position `x`, against this contact's own
    /// law ([`SurfaceContact::respond`], either friction law): open where the gap is not
    /// negative; in contact (stick or slip) where it is not positive, with an anchor that the
    /// law's return map leaves where it is (stick inside the limit, slip on it), and for slip
    /// the trial force on or beyond the limit (`|f|` isotropic; `|f1|` or the cross hold `|f2|`,
    /// sliding-direction). The
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
        let limit = history.friction * r.normal_force;
        // How far the trial force is beyond its bound (≥ 0 on it).
        let measure = match self.law {
            FrictionLaw::Isotropic => trial.norm() - limit,
            FrictionLaw::SlidingDirection => (trial.x.abs() - limit)
                .max(trial.y.abs() - FrictionLaw::cross_limit(r.normal_force, history.friction)),
        };
        let in_contact = gap <= length_tolerance && moved <= force_tolerance;
        let consistent = match history.status {
            GapStatus::Open => gap >= -length_tolerance,
            GapStatus::Stick => in_contact,
            GapStatus::Slip => in_contact && measure >= -force_tolerance,
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

    /// Moves the closed contacts' nodes of a predicted iterate `u` back to the gap they had at
    /// the converged `start` (histories `histories`) where the prediction pushed them further
    /// into their support, along the support's normal there; `free(node)` tells whether all
    /// three DOFs of a node are free (others are left as predicted). A node that landed on its
    /// support in the last increment keeps moving into it under the predictor's linear
    /// extrapolation, by as much as it approached, which the penalty `k_n` turns into a force
    /// at the first iterate (8.9e4 N measured on a held-out path, `docs/benchmarks.md`).
    pub fn keep_gaps(
        &self,
        start: &[f64],
        histories: &[ContactHistory],
        free: impl Fn(usize) -> bool,
        u: &mut [f64],
    ) {
        for (c, h) in self.contacts.iter().zip(histories) {
            if h.status == GapStatus::Open || !free(c.node) {
                continue;
            }
            let before = c.project(&self.position(c, start), h.angle).gap;
            let now = c.project(&self.position(c, u), h.angle);
            if now.gap < before {
                for k in 0..3 {
                    u[3 * c.node + k] += now.normal[k] * (before - now.gap);
                }
            }
        }
    }

    /// Each contact's response at `u` from the converged `histories`.
    pub fn respond(&self, u: &[f64], histories: &[ContactHistory]) -> Vec<ContactResponse> {
        self.contacts
            .iter()
            .zip(histories)
            .map(|(c, h)| c.respond(&self.position(c, u), h))
            .collect()
    }

    /// Adds the contacts' residuals and tangents at `u` (from `histories`, with the statuses
    /// `held` imposed: [`SurfaceContact::respond_held`]; empty: none) to `residual` and the
    /// Newton matrix `values`; leaves the responses in `responses` (reused: no allocation
    /// once it has grown).
    pub fn add_to(
        &self,
        system: &System,
        u: &[f64],
        (histories, held): (&[ContactHistory], &[Option<GapStatus>]),
        residual: &mut [f64],
        mut values: Option<&mut [f64]>,
        responses: &mut Vec<ContactResponse>,
    ) {
        responses.clear();
        responses.extend(
            self.contacts
                .iter()
                .zip(histories)
                .enumerate()
                .map(|(k, (c, h))| {
                    c.respond_held(&self.position(c, u), h, held.get(k).copied().flatten())
                }),
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

    /// The largest penetration `−g` (m) at `u` of the contacts closed in `histories`, 0 if none.
    pub fn largest_penetration(&self, u: &[f64], histories: &[ContactHistory]) -> f64 {
        self.contacts
            .iter()
            .zip(histories)
            .filter(|(_, h)| h.status != GapStatus::Open)
            .map(|(c, h)| -c.project(&self.position(c, u), h.angle).gap)
            .fold(0.0, f64::max)
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
mod tests;
