//! Node-to-surface friction contact on rigid curved supports (issue 10): a film node against a
//! tube of radius `r` around a straight or circular centreline, whose closest point, normal and
//! sliding directions follow the node (the paper's fixed gap frames, §4.3–4.4, do not).
//!
//! Geometry (axis unit vector `a`, centre `c0`, `Π = I − a⊗a`, `q = Π(x − c0)`, `ρ = |q|`,
//! `e_ρ = q/ρ`, `T = a × e_ρ`, angle `φ` of `e_ρ` about `a`, unwrapped from the last converged
//! value):
//!
//! * **cylinder** (straight centreline along `a` through `c0`, a capstan, a straight rail):
//!   `d = ρ`, `n = e_ρ`, `∂n/∂x = T⊗T/d`;
//! * **ring** (circular centreline of radius `Rc` about `a` through `c0`, the parallel arches'
//!   pipes): closest centreline point `C = c0 + Rc e_ρ`, `w = x − C`, `d = |w|`, `n = w/d`,
//!   `b = n × T`, `∂n/∂x = b⊗b/d + (n·e_ρ/ρ) T⊗T`; an `arc` limits `φ` to a range: outside it
//!   the node is not in contact with this support.
//!
//! Normal: gap `g = d − r`, contact force `λN = k_n ⟨−g⟩` along `n` (the paper's penalty).
//! Tangential coordinates (surface lengths): `ξ1 = R φ` around the axis (`R = r` for a cylinder,
//! the circumference; `R = Rc + r` for a ring, the outer surface along the arch), with
//! `∇ξ1 = (R/ρ) T`, `∇²ξ1 = −(R/ρ²)(e_ρ⊗T + T⊗e_ρ)`; `ξ2 = a·(x − c0)` along the axis
//! (`∇ξ2 = a`; for a ring this is across the pipe, equal to the surface length to first order in
//! the normal's tilt out of the ring plane). Friction (penalty `k_s`, history `ξ̄` of the last
//! converged state): trial `f = −k_s (ξ − ξ̄)`; `isotropic`: Coulomb cone `|f| ≤ μλN`, returned to
//! it along `f`; `sliding-direction` (the paper's law): `ξ1` slides at `|f1| = μλN`, `ξ2` stays
//! elastic. Force on the film `F = λN n + Σ fα ∇ξα`; consistent tangent of `−F`:
//! `k_n n⊗n − λN ∂n/∂x − Σ (∂fα/∂ξβ) ∇ξα⊗∇ξβ − Σ (∂fα/∂λN) ∇ξα⊗∇λN − Σ fα ∇²ξα`
//! (`∇λN = −k_n n`), checked against central differences in every status
//! (`tangent_matches_finite_differences_in_every_status`). The slip reported is `ξ1 − ξ1(0)`:
//! the arc length the node has travelled along the support, as the experiment measured it.
//! Source of the formulas: the project's note on node-to-curve contact (derived and
//! FD-checked there), following Wriggers, *Computational Contact Mechanics* (2006), ch. 4.

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

/// Where a node is relative to a support.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Gap `g = d − r` (negative: penetration).
    pub gap: f64,
    /// Outward unit normal of the support at the closest point.
    pub normal: Vector3<f64>,
    /// Unwrapped angle `φ` about the axis.
    pub angle: f64,
    /// `∂n/∂x`.
    pub normal_derivative: Matrix3<f64>,
    /// Surface coordinates `[ξ1, ξ2]` and their gradients and Hessians.
    pub xi: Vector2<f64>,
    pub grad: [Vector3<f64>; 2],
    pub hessian: [Matrix3<f64>; 2],
    /// Whether the angle lies within the arc (always for lines and full circles).
    pub on_support: bool,
}

/// One contact: a support and a node.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceContact {
    frame: Frame,
    /// `None` for a line; `Some((Rc, arc))` for a circle.
    ring: Option<(f64, Option<[f64; 2]>)>,
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
    /// Unwrapped angle `φ` at the converged state (the branch for the next projection).
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
    pub angle: f64,
}

/// Angle of `v` (normal to `a`) about `a` in the frame, unwrapped toward `near`.
fn unwrapped_angle(frame: &Frame, v: &Vector3<f64>, near: f64) -> f64 {
    let raw = v.dot(&frame.e2).atan2(v.dot(&frame.e1));
    let tau = std::f64::consts::TAU;
    raw + tau * ((near - raw) / tau).round()
}

impl SurfaceContact {
    /// Contact of `node` with `support`.
    pub fn new(support: &CurvedSupport, node: usize) -> Self {
        let (frame, ring) = match &support.centreline {
            Centreline::Line { point, axis } => (Frame::new(*point, *axis, None), None),
            Centreline::Circle {
                centre,
                axis,
                radius,
                angles,
                start_direction,
            } => (
                Frame::new(*centre, *axis, *start_direction),
                Some((*radius, *angles)),
            ),
        };
        Self {
            frame,
            ring,
            tube_radius: support.tube_radius,
            node,
            kn: support.normal_stiffness,
            ks: support.tangential_stiffness,
            law: support.friction_law,
        }
    }

    /// The projection of the point `x`, its angle unwrapped toward `near`.
    pub fn project(&self, x: &Vector3<f64>, near: f64) -> Projection {
        let f = &self.frame;
        let a = f.a;
        let rel = x - f.centre;
        let q = rel - a * a.dot(&rel);
        let rho = q.norm();
        let e_rho = q / rho;
        let t = a.cross(&e_rho);
        let angle = unwrapped_angle(f, &q, near);
        let r = self.tube_radius;
        let (d, normal, dn, reference, on_support) = match self.ring {
            None => (rho, e_rho, t * t.transpose() / rho, r, true),
            Some((rc, arc)) => {
                let w = q - e_rho * rc + a * a.dot(&rel);
                let d = w.norm();
                let n = w / d;
                let b = n.cross(&t);
                let dn = b * b.transpose() / d + t * t.transpose() * (n.dot(&e_rho) / rho);
                let inside = arc.is_none_or(|[lo, hi]| {
                    // The arc's range, shifted by whole turns toward the angle.
                    let tau = std::f64::consts::TAU;
                    let shift = tau * ((angle - 0.5 * (lo + hi)) / tau).round();
                    (lo + shift..=hi + shift).contains(&angle)
                });
                (d, n, dn, rc + r, inside)
            }
        };
        let xi = Vector2::new(reference * angle, a.dot(&rel));
        let grad = [t * (reference / rho), a];
        let sym = e_rho * t.transpose() + t * e_rho.transpose();
        let hessian = [sym * (-reference / (rho * rho)), Matrix3::zeros()];
        Projection {
            gap: d - r,
            normal,
            angle,
            normal_derivative: dn,
            xi,
            grad,
            hessian,
            on_support,
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
            angle: p.angle,
        };
        if p.gap >= 0.0 || !p.on_support {
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
            angle: p.angle,
        }
    }

    /// The history of the undeformed state at `x0` with friction `mu`.
    pub fn initial_history(&self, x0: &Vector3<f64>, mu: f64) -> ContactHistory {
        let p = self.project(x0, 0.0);
        ContactHistory {
            anchor: p.xi.into(),
            angle: p.angle,
            origin: p.xi.x,
            // A node that starts on the support is in contact from the start (its first step
            // slides); the others approach first.
            status: if p.gap <= 0.0 && p.on_support {
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

    fn kinds() -> Vec<(&'static str, Centreline)> {
        vec![
            (
                "cylinder",
                Centreline::Line {
                    point: [0.1, -0.2, 0.05],
                    axis: [0.2, 1.0, 0.1],
                },
            ),
            (
                "ring",
                Centreline::Circle {
                    centre: [0.0, 0.0, -1.0],
                    axis: [0.0, 1.0, 0.05],
                    radius: 1.0,
                    angles: None,
                    start_direction: None,
                },
            ),
        ]
    }

    /// Central differences of the residual against the tangent, for random positions near the
    /// support and anchors chosen to give each status.
    #[test]
    fn tangent_matches_finite_differences_in_every_status() {
        let mut seen = std::collections::HashSet::new();
        for law in FrictionLaw::ALL {
            for (kind, centreline) in kinds() {
                let s = support(centreline, law);
                let c = SurfaceContact::new(&s, 0);
                let mut seed = 7u64;
                let mut rand = || {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
                };
                for case in 0..40 {
                    // A point on the support's surface at a random angle, pushed in or out.
                    let f = c.frame;
                    let phi = 0.7 * rand();
                    let e = f.e1 * phi.cos() + f.e2 * phi.sin();
                    let along = 0.3 * rand();
                    let surface = match c.ring {
                        None => f.centre + f.a * along + e * s.tube_radius,
                        Some((rc, _)) => f.centre + e * (rc + s.tube_radius) + f.a * 0.01 * rand(),
                    };
                    let depth = 1e-4 * (rand() + 0.3);
                    let x = surface + e * (-depth) + f.a * (0.001 * rand());
                    let p0 = c.project(&x, phi);
                    // Anchors near ξ (stick) or far (slip), either side.
                    let offset = if case % 3 == 0 { 1e-6 } else { 5e-3 } * rand().signum();
                    let history = ContactHistory {
                        anchor: [p0.xi.x + offset, p0.xi.y - 0.5 * offset],
                        angle: phi,
                        origin: 0.0,
                        status: GapStatus::Stick,
                        friction: 0.3,
                    };
                    let r = c.respond(&x, &history);
                    // Skip points within reach of a status change.
                    let h = 1e-8;
                    let statuses: Vec<_> = (0..3)
                        .flat_map(|k| {
                            [-1.0, 1.0].map(|sgn| {
                                c.respond(&(x + Vector3::ith(k, 20.0 * h * sgn)), &history)
                                    .status
                            })
                        })
                        .collect();
                    if statuses.iter().any(|st| *st != r.status) {
                        continue;
                    }
                    seen.insert((law, kind, r.status as u8));
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
                        "{law:?} {kind} {:?}: relative error {error:e}\nanalytic {}\nfd {}",
                        r.status,
                        r.tangent,
                        fd
                    );
                }
            }
        }
        for law in FrictionLaw::ALL {
            for (kind, _) in kinds() {
                for status in [GapStatus::Stick, GapStatus::Slip] {
                    assert!(
                        seen.contains(&(law, kind, status as u8)),
                        "{law:?} {kind} {status:?} never tested"
                    );
                }
            }
        }
    }

    #[test]
    fn a_node_outside_the_tube_or_the_arc_is_open_and_carries_nothing() {
        let s = support(kinds().remove(1).1, FrictionLaw::Isotropic);
        let c = SurfaceContact::new(&s, 0);
        let f = c.frame;
        let history = c.initial_history(&(f.centre + f.e1 * 1.2), 0.3);
        let r = c.respond(&(f.centre + f.e1 * 1.2), &history);
        assert_eq!((r.status, r.residual), (GapStatus::Open, Vector3::zeros()));
        let arc = CurvedSupport {
            centreline: Centreline::Circle {
                centre: [0.0, 0.0, -1.0],
                axis: [0.0, 1.0, 0.05],
                radius: 1.0,
                angles: Some([0.5, 1.0]),
                start_direction: None,
            },
            ..s
        };
        let c = SurfaceContact::new(&arc, 0);
        let inside = f.centre + f.e1 * 1.04;
        assert!(!c.project(&inside, 0.0).on_support);
        let e = f.e1 * 0.7f64.cos() + f.e2 * 0.7f64.sin();
        assert!(c.project(&(f.centre + e * 1.04), 0.0).on_support);
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
        let at = |radius: f64, phi: f64| {
            c.frame.centre + (c.frame.e1 * phi.cos() + c.frame.e2 * phi.sin()) * radius
        };
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
        // Open, then landing (approach: not slip), then two steps dragged in contact.
        let expected = [0.0, 0.0, r * 0.3, r * 0.7];
        for (k, (s, e)) in slips.iter().zip(expected).enumerate() {
            assert!((s - e).abs() < 1e-12, "step {k}: slip {s} vs {e}");
        }
        let touching = c.initial_history(&at(0.99 * r, 0.0), 0.0);
        assert_eq!(
            touching.status,
            GapStatus::Stick,
            "a node on the support starts in contact"
        );
    }
}
