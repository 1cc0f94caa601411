//! Node-to-node friction gap element (paper §2.2, §3(f), §4.3).
//!
//! Node A is on the film, B on the support (a node or a fixed point). The local frame
//! `(x, y, z)` is fixed for the whole analysis (§4.3): `z` is the outward normal of the support,
//! `x` the sliding direction, `y = z × x`. With `d = R (u_A − u_B)` the relative displacement
//! in that frame and `g = g0 + d_z` the gap:
//!
//! * **open** (`g > 0`, the normal force would pull): no force, no stiffness; the tangential
//!   reference follows node A, so sliding is counted from closure. A touching gap (`g = 0`
//!   exactly, e.g. `g0 = 0` at the start) is closed with `N = 0`: it carries nothing, but its
//!   tangent holds the node against penetration, where the open tangent would leave an
//!   unstressed film a mechanism pushing straight into the support (measured: the strip over a
//!   cylinder of issue 7, whose Newton direction then raised the residual at every step size);
//! * **closed**: normal force `N = −k_n g ≥ 0`; trial friction `t* = k_s (d_t − s_p)` with `s_p`
//!   the slip history; **stick** while `|t*| − μN ≤ 0` (eq. 2.13), else **slip** with the
//!   return mapping `t = μN t*/|t*|` onto the Coulomb limit, the direction (and so its sign) taken
//!   from the trial force at every evaluation, so slip can reverse.
//!
//! The forces always come from this law, never from summing stiffness × increment; the paper's
//! remark on the `μ k_n Δu` term (§2.2) is exactly why. Internal force on A is `r_A = Rᵀ(t, −N)`,
//! `r_B = −r_A` (eq. 2.8 with the paper's sign: `r = k_g Δu`).
//!
//! Two iteration matrices (the `k` block of eq. 2.9, in the local frame):
//! * [`IterationMatrix::JuRowlands`]: stick `diag(k_s, k_s, k_n)`; slip `k_n a aᵀ + k_s p pᵀ` with
//!   `a = (−μ n, 1)`, `n` the unit slip direction and `p ⊥ n` in the tangent plane. For `n = ±x`
//!   this is the paper's matrix with the sign of the sliding direction. Symmetric.
//! * [`IterationMatrix::Consistent`]: the exact derivative of the law, unsymmetric in slip.

use nalgebra::{Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// Status of a gap element.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum GapStatus {
    /// Gap not closed, or the normal force would pull: no force, no stiffness.
    Open = 0,
    /// Closed, friction force inside the Coulomb cone.
    Stick = 1,
    /// Closed, friction force on the Coulomb limit `μ·N`.
    Slip = 2,
}

/// Which matrix drives the Newton iterations (both converge to the same answer).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum IterationMatrix {
    /// The paper's symmetric Ju–Rowlands matrix (eq. 2.9) with the §3(f) rule that a gap that
    /// starts slipping keeps the slip matrix until the Newton loop ends. Factorized by LDLᵀ.
    JuRowlands,
    /// The consistent (unsymmetric) tangent of the same friction law. Factorized by LU.
    #[default]
    Consistent,
}

/// Orthonormal, right-handed local frame of a gap: `x` sliding, `z` normal, `y = z × x`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GapFrame {
    /// Sliding direction (the support's tangent).
    pub x: [f64; 3],
    /// `z × x`.
    pub y: [f64; 3],
    /// Outward normal of the support at the contact point.
    pub z: [f64; 3],
}

impl GapFrame {
    /// Builds the frame from the sliding direction and the normal; `y = z × x`.
    pub fn from_x_and_z(x: Vector3<f64>, z: Vector3<f64>) -> Self {
        let (x, z) = (x.normalize(), z.normalize());
        let y = z.cross(&x);
        Self {
            x: x.into(),
            y: y.into(),
            z: z.into(),
        }
    }

    /// Rotation `R` whose rows are `x, y, z` (local ← global).
    pub fn rotation(&self) -> Matrix3<f64> {
        Matrix3::from_rows(&[
            Vector3::from(self.x).transpose(),
            Vector3::from(self.y).transpose(),
            Vector3::from(self.z).transpose(),
        ])
    }

    /// Largest deviation from an orthonormal frame with `y = z × x`.
    pub fn orthonormality_error(&self) -> f64 {
        let r = self.rotation();
        let (x, y, z) = (
            Vector3::from(self.x),
            Vector3::from(self.y),
            Vector3::from(self.z),
        );
        let gram = (r * r.transpose() - Matrix3::identity()).amax();
        gram.max((z.cross(&x) - y).amax())
    }
}

/// Constitutive constants of a gap.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GapLaw {
    /// Normal penalty `k_n` (N/m).
    pub normal_stiffness: f64,
    /// Tangential penalty `k_s` (N/m).
    pub tangential_stiffness: f64,
    /// Friction coefficient `μ`.
    pub friction: f64,
    /// Initial gap `g0 ≥ 0` (m).
    pub initial_gap: f64,
}

/// Result of evaluating the friction law at one relative displacement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GapResponse {
    /// Status given by the law.
    pub status: GapStatus,
    /// Relative displacement `d = R(u_A − u_B)` in the local frame.
    pub relative: Vector3<f64>,
    /// Internal force on node A in the local frame `(t_x, t_y, −N)`.
    pub force: Vector3<f64>,
    /// Normal (contact) force `N ≥ 0`.
    pub normal_force: f64,
    /// Slip history after this evaluation (the value to commit on convergence).
    pub plastic_slip: Vector2<f64>,
    /// Unit direction of the trial friction force `t*/|t*|` (zero when open or `t* = 0`); in
    /// slip it is the slip direction, its sign included.
    pub direction: Vector2<f64>,
    /// `|t*|`, the trial friction force magnitude.
    pub trial_magnitude: f64,
}

impl GapLaw {
    /// Evaluates the friction law (return mapping) for a relative displacement `d` and the slip
    /// history `s_p` committed at the start of the increment.
    pub fn evaluate(&self, d: Vector3<f64>, plastic_slip: Vector2<f64>) -> GapResponse {
        let tangential = Vector2::new(d.x, d.y);
        let gap = self.initial_gap + d.z;
        if gap > 0.0 {
            return GapResponse {
                status: GapStatus::Open,
                relative: d,
                force: Vector3::zeros(),
                normal_force: 0.0,
                plastic_slip: tangential,
                direction: Vector2::zeros(),
                trial_magnitude: 0.0,
            };
        }
        let normal_force = -self.normal_stiffness * gap;
        let trial = (tangential - plastic_slip) * self.tangential_stiffness;
        let trial_magnitude = trial.norm();
        let limit = self.friction * normal_force;
        // Eq. (2.13): sqrt(rx² + ry²) − μ|rz| with the stick (trial) forces.
        let direction = if trial_magnitude > 0.0 {
            trial / trial_magnitude
        } else {
            Vector2::zeros()
        };
        if trial_magnitude - limit <= 0.0 {
            GapResponse {
                status: GapStatus::Stick,
                relative: d,
                force: Vector3::new(trial.x, trial.y, -normal_force),
                normal_force,
                plastic_slip,
                direction,
                trial_magnitude,
            }
        } else {
            let t = direction * limit;
            GapResponse {
                status: GapStatus::Slip,
                relative: d,
                force: Vector3::new(t.x, t.y, -normal_force),
                normal_force,
                plastic_slip: tangential - t / self.tangential_stiffness,
                direction,
                trial_magnitude,
            }
        }
    }

    /// Consistent tangent `∂r_A/∂d` of [`GapLaw::evaluate`] in the local frame.
    pub fn consistent_tangent(&self, response: &GapResponse) -> Matrix3<f64> {
        let (kn, ks, mu) = (
            self.normal_stiffness,
            self.tangential_stiffness,
            self.friction,
        );
        match response.status {
            GapStatus::Open => Matrix3::zeros(),
            GapStatus::Stick => Matrix3::from_diagonal(&Vector3::new(ks, ks, kn)),
            GapStatus::Slip => {
                let n = response.direction;
                let radial = mu * response.normal_force * ks / response.trial_magnitude;
                let tt = (nalgebra::Matrix2::identity() - n * n.transpose()) * radial;
                Matrix3::new(
                    tt[(0, 0)],
                    tt[(0, 1)],
                    -mu * kn * n.x,
                    tt[(1, 0)],
                    tt[(1, 1)],
                    -mu * kn * n.y,
                    0.0,
                    0.0,
                    kn,
                )
            }
        }
    }

    /// The paper's symmetric matrix `k` of eq. (2.9) for a status and slip direction `n`.
    pub fn ju_rowlands_matrix(&self, status: GapStatus, direction: Vector2<f64>) -> Matrix3<f64> {
        let (kn, ks, mu) = (
            self.normal_stiffness,
            self.tangential_stiffness,
            self.friction,
        );
        match status {
            GapStatus::Open => Matrix3::zeros(),
            GapStatus::Stick => Matrix3::from_diagonal(&Vector3::new(ks, ks, kn)),
            GapStatus::Slip => {
                let a = Vector3::new(-mu * direction.x, -mu * direction.y, 1.0);
                let p = Vector3::new(-direction.y, direction.x, 0.0);
                a * a.transpose() * kn + p * p.transpose() * ks
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law() -> GapLaw {
        GapLaw {
            normal_stiffness: 2.5e8,
            tangential_stiffness: 2.5e7,
            friction: 0.2,
            initial_gap: 0.0,
        }
    }

    #[test]
    fn consistent_tangent_matches_finite_difference_in_each_status() {
        let law = law();
        let history = Vector2::new(1e-5, -2e-5);
        for d in [
            Vector3::new(3e-6, 1e-6, 4e-6),   // open
            Vector3::new(2e-5, -2e-5, -1e-4), // stick
            Vector3::new(3e-4, 1e-4, -1e-4),  // slip
        ] {
            let response = law.evaluate(d, history);
            let k = law.consistent_tangent(&response);
            let h = 1e-10;
            for j in 0..3 {
                let mut dp = d;
                let mut dm = d;
                dp[j] += h;
                dm[j] -= h;
                let column =
                    (law.evaluate(dp, history).force - law.evaluate(dm, history).force) / (2.0 * h);
                let err = (column - k.column(j)).amax();
                assert!(
                    err < 1e-6 * law.normal_stiffness,
                    "{:?} col {j}: {err:e}",
                    response.status
                );
            }
        }
    }

    #[test]
    fn ju_rowlands_keeps_force_increment_on_the_cone() {
        // x–z block is k_n a aᵀ: an increment moves the force along the cone edge t = μN n.
        let law = law();
        let n = Vector2::new(-1.0, 0.0);
        let k = law.ju_rowlands_matrix(GapStatus::Slip, n);
        assert!((k - k.transpose()).amax() == 0.0);
        let dr = k * Vector3::new(1e-6, 0.0, -2e-6);
        // Δt_x / ΔN = μ n_x with ΔN = −Δr_z.
        assert!((dr.x / (-dr.z) - law.friction * n.x).abs() < 1e-12);
    }
}
