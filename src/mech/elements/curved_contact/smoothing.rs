//! The contact law with its corners rounded over a width `w` (m): the smoothed problems of the
//! smoothing homotopy that a refused increment tries last (`Analysis::step_to_motion`,
//! docs/mechanics.md "Smoothing homotopy"). Each switch of the law, a corner of `max(x, 0)`,
//! becomes the C¹ ramp `ρ_w` ([`ramp`]):
//!
//! * normal: `λN = k_n ρ_w(−g)` instead of `k_n ⟨−g⟩`: no force where `g ≥ w/2`, the penalty's
//!   where `g ≤ −w/2`, a quadratic between;
//! * slip (the return to the friction limit `L = μλN`): the trial force `t = −k_s (ξ − ξ̄)` times
//!   `q = L / (L + ρ_{k_s w}(|t| − L))` (isotropic: `t` whole; sliding-direction: `t1`). Since
//!   `ρ(y) ≥ max(y, 0)`, `|q t| ≤ L` everywhere (the cone is kept), `q = 1` (stick) where
//!   `|t| ≤ L − k_s w/2`, the exact return where `|t| ≥ L + k_s w/2`;
//! * the sliding-direction law's hold across (the jump at lift-off, eleventh round): `f2 = c t2`
//!   with `c = ρ′_w(−g)`, rising from 0 at `g = w/2` to 1 at `g = −w/2`.
//!
//! At `w → 0` every part is the law's own ([`super::SurfaceContact::respond_as`]); for `w > 0`
//! the residual is C¹ in the position, so Newton's iterates do not switch between the branches
//! of the law (Chen & Harker 1993, Kanzow 1996: smoothing/noninterior continuation for
//! complementarity problems; Wriggers, *Computational Contact Mechanics*, 2006, §5.2: the
//! regularized penalty). The smoothed problem is never an answer: the homotopy ends on the
//! law's own equilibrium, or the increment is refused.

use nalgebra::{Matrix2, Vector2, Vector3};

use super::{ContactHistory, ContactResponse, SurfaceContact};
use crate::mech::elements::gap::{FrictionLaw, GapStatus};
use crate::mech::elements::smoothing::ramp;

/// The return factor `q = L / (L + ρ_wf(m − L))` of a trial force of magnitude `m` to the limit
/// `L ≥ 0`, with `∂q/∂m` and `∂q/∂L` (`wf > 0`: the denominator is at least `wf/8` at `m = L = 0`).
fn return_factor(m: f64, limit: f64, wf: f64) -> (f64, f64, f64) {
    let (e, de, _) = ramp(m - limit, wf);
    let s = limit + e;
    let q = limit / s;
    (
        q,
        -limit * de / (s * s),
        1.0 / s - limit * (1.0 - de) / (s * s),
    )
}

impl SurfaceContact {
    /// The response at `x` from `history` under the law smoothed over the width `w > 0` (m)
    /// (module doc); `status` and `natural` are the law's branch the smoothed force is on
    /// (open: no force; stick: no return; slip: a return, partial within the rounding).
    pub fn respond_smoothed(
        &self,
        x: &Vector3<f64>,
        history: &ContactHistory,
        w: f64,
    ) -> ContactResponse {
        let p = self.project(x, history.angle);
        let anchor = Vector2::from(history.anchor);
        let (phi, dphi, ddphi) = ramp(-p.gap, w);
        let lambda = self.kn * phi;
        // ∂λN/∂g
        let dlambda_dg = -self.kn * dphi;
        let mu = history.friction;
        let limit = mu * lambda;
        let trial = -(p.xi - anchor) * self.ks;
        let wf = self.ks * w;
        // f, ∂f/∂ξ, ∂f/∂g (at fixed ξ), and whether a return acts.
        let (f, df_dxi, df_dg, returned) = match self.law {
            FrictionLaw::Isotropic => {
                let m = trial.norm();
                let (q, dq_dm, dq_dl) = return_factor(m, limit, wf);
                let mut df_dt = Matrix2::identity() * q;
                if m > 0.0 {
                    df_dt += trial * trial.transpose() * (dq_dm / m);
                }
                (
                    trial * q,
                    -df_dt * self.ks,
                    trial * (dq_dl * mu * dlambda_dg),
                    q < 1.0,
                )
            }
            FrictionLaw::SlidingDirection => {
                let m = trial.x.abs();
                let (q, dq_dm, dq_dl) = return_factor(m, limit, wf);
                // The hold across fades in with the contact (none while landing).
                let (c, dc_dg) = if history.lands {
                    (0.0, 0.0)
                } else {
                    (dphi, -ddphi)
                };
                (
                    Vector2::new(trial.x * q, trial.y * c),
                    Matrix2::new(-(q + dq_dm * m) * self.ks, 0.0, 0.0, -c * self.ks),
                    Vector2::new(trial.x * dq_dl * mu * dlambda_dg, trial.y * dc_dg),
                    q < 1.0,
                )
            }
        };
        let status = if phi == 0.0 {
            GapStatus::Open
        } else if returned {
            GapStatus::Slip
        } else {
            GapStatus::Stick
        };
        let n = p.normal;
        let force = n * lambda + p.grad[0] * f.x + p.grad[1] * f.y;
        let mut k = n * n.transpose() * (self.kn * dphi) - p.normal_derivative * lambda;
        for al in 0..2 {
            for be in 0..2 {
                k -= p.grad[al] * p.grad[be].transpose() * df_dxi[(al, be)];
            }
            k -= p.grad[al] * n.transpose() * df_dg[al];
            k -= p.hessian[al] * f[al];
        }
        ContactResponse {
            residual: -force,
            tangent: k,
            status,
            natural: status,
            normal_force: lambda,
            friction: f,
            xi: p.xi,
            next_anchor: p.xi + f / self.ks,
            angle: p.parameter,
        }
    }
}
