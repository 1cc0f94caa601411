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
//!   the slip history; **stick** while `|t*| − μN ≤ 0`, the paper's check (2.13)
//!   `√(r_x² + r_y²) − μ|r_z|` on the *total* tangential force "in stick condition" (§3(f));
//!   else **slip**, by the gap's [`FrictionLaw`] (below).
//!
//! # The two friction laws (the one place they are decided)
//!
//! * [`FrictionLaw::Isotropic`] (default): the Coulomb cone of the tangent plane. Return mapping
//!   `t = μN t*/|t*|`; the gap slides along its trial force, in any tangential direction.
//! * [`FrictionLaw::SlidingDirection`], the paper's law. §2.2: "the sliding direction, when Gap
//!   element is in sliding status, is assumed in x direction"; in sliding status the x force
//!   obeys Mohr–Coulomb, "`f_s = r_x = μ f_n`", and the slip matrix `k` of (2.9) keeps `k_s` on
//!   y; §4.4 / Fig. 6: "the sliding … can be only seen in arch direction". Hence:
//!   - **status**: slip once (2.13) on the *total* trial force is reached, `|t*| > μN`, exactly
//!     the §3(f) check; the same test as the isotropic law;
//!   - **y stays elastic** while the gap presses: `t_y = t*_y = k_s (d_y − s_py)`, `s_py`
//!     unchanged (row y of the slip `k` in (2.9) is `(0, k_s, 0)`), up to the cross hold
//!     `|t_y| ≤ κN`, `κ = max(`[`FrictionLaw::CROSS_HOLD`]`, μ)`, beyond which `s_py` follows
//!     the node (`t_y = ±κN`); the y history follows the node while the gap is open;
//!     **The cross hold at lift-off**: the paper's law holds `|t_y|` without a bound, so a
//!     contact lifting off (`N → 0`) dropped a cross force of `k_s` times its drift since it
//!     closed at once (44 N at `λN = 1e-5 N` on held-out `reversal#0`), a jump of the residual
//!     that no Newton method settles. Bounded by `κN`, the hold goes to zero with `N`: the law is
//!     continuous everywhere and piecewise smooth (semismooth). `κ = 100` is above every ratio
//!     the paper's specimens reach (27 at most, measured on 200/300/400 mm at μ = 0.1, 0.2,
//!     0.5), so Table 1 and Fig. 7 are the paper's law's;
//!   - **x slides** by Coulomb along x: `t_x = clamp(t*_x, −μN, μN)`, so `f_s = μ f_n` wherever x
//!     slides (`|t*_x| > μN`), in the direction `s = sign(t*_x)` taken at every evaluation (slip
//!     reverses with the trial force); where (2.13) is reached through `t_y` while
//!     `|t*_x| ≤ μN`, x holds elastically, `t_x = t*_x`.
//!
//!   Why not the other readings (measured on the 300 mm specimen with `μ` = 0.1…0.5): setting
//!   `t_x = sμN` in every slip state, as the words alone say, makes the force jump where (2.13)
//!   switches with `t_y ≠ 0` (the trial there has `|t*_x| < μN`), pushes x with a slip increment
//!   against the friction force, and jumps by `2μN` when `t*_x` changes sign; capping the total
//!   force on the cone, `t_x = s√(μ²N² − t_y²)`, takes the x friction away as soon as the elastic
//!   `t_y` reaches `μN`, which it does at every closed gap of the 300 mm specimen (`|t_y|` ≈ 7–14
//!   μN at `μ = 0.2`), so the slips no longer depend on `μ`, against the paper's Fig. 7. Both
//!   agree with the law above when `t_y = 0`, the paper's own case of sliding along the arch.
//!
//! The forces always come from this law, never from summing stiffness × increment; the paper's
//! remark on the `μ k_n Δu` term (§2.2) is exactly why. Internal force on A is `r_A = Rᵀ(t, −N)`,
//! `r_B = −r_A` (eq. 2.8 with the paper's sign: `r = k_g Δu`).
//!
//! Two iteration matrices (the `k` block of eq. 2.9, in the local frame):
//! * [`IterationMatrix::JuRowlands`]: stick `diag(k_s, k_s, k_n)`; slip `k_n a aᵀ + k_s p pᵀ` with
//!   `a = (−μ n, 1)`, `n` the unit slip direction and `p ⊥ n` in the tangent plane (isotropic
//!   law), or `a = (−μ s, 0, 1)`, `p = y` (sliding-direction law, `n = (s, 0)`): for `n = ±x`
//!   both are the paper's matrix with the sign of the sliding direction. Symmetric.
//! * [`IterationMatrix::Consistent`]: the exact derivative of the law, unsymmetric in slip.

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// Status of a gap element.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum GapStatus {
    /// Gap not closed, or the normal force would pull: no force, no stiffness.
    Open = 0,
    /// Closed, friction force inside the Coulomb cone.
    Stick = 1,
    /// Closed, (2.13) reached: the friction force is the [`FrictionLaw`]'s return mapping.
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

/// How a closed gap slides (module doc: the precise laws and their source).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FrictionLaw {
    /// Coulomb cone of the tangent plane: slides along the trial friction force.
    #[default]
    Isotropic,
    /// The paper's law (§2.2): slides along local x only, y elastic with `k_s` up to the cross
    /// hold `κN` ([`FrictionLaw::CROSS_HOLD`]).
    SlidingDirection,
}

impl FrictionLaw {
    /// Both laws, in the order of their names in messages.
    pub const ALL: [Self; 2] = [Self::Isotropic, Self::SlidingDirection];

    /// The sliding-direction law's bound on its elastic cross hold, as a ratio to the normal
    /// force: `|t_y| ≤ CROSS_HOLD · N` (module doc, "The cross hold at lift-off"). The paper's
    /// specimens reach 27 at most (400 mm, μ = 0.1), so their slips are the paper's law's.
    pub const CROSS_HOLD: f64 = 100.0;

    /// The sliding-direction law's bound on `|t_y|` at the normal force `normal_force` with the
    /// friction coefficient `mu`: `max(CROSS_HOLD, μ) · N` (never below the friction limit).
    pub fn cross_limit(normal_force: f64, mu: f64) -> f64 {
        Self::CROSS_HOLD.max(mu) * normal_force
    }

    /// The name used in model files, on the command line and in the FMU.
    pub fn name(self) -> &'static str {
        match self {
            Self::Isotropic => "isotropic",
            Self::SlidingDirection => "sliding-direction",
        }
    }

    /// Friction force on the slip limit and slip direction for a trial force `t*` outside (2.13)
    /// (`|t*| > limit = μN`).
    fn return_map(
        self,
        trial: Vector2<f64>,
        trial_magnitude: f64,
        limit: f64,
        (normal_force, mu): (f64, f64),
    ) -> [Vector2<f64>; 2] {
        match self {
            Self::Isotropic => {
                let n = trial / trial_magnitude;
                [n * limit, n]
            }
            Self::SlidingDirection => {
                let s = if trial.x < 0.0 { -1.0 } else { 1.0 };
                let cross = Self::cross_limit(normal_force, mu);
                [
                    Vector2::new(trial.x.clamp(-limit, limit), trial.y.clamp(-cross, cross)),
                    Vector2::new(s, 0.0),
                ]
            }
        }
    }

    /// Consistent tangent `∂r_A/∂d` in slip.
    fn slip_tangent(self, law: &GapLaw, r: &GapResponse) -> Matrix3<f64> {
        let (kn, ks, mu) = (law.normal_stiffness, law.tangential_stiffness, law.friction);
        match self {
            Self::Isotropic => {
                let n = r.direction;
                let radial = mu * r.normal_force * ks / r.trial_magnitude;
                let tt = (Matrix2::identity() - n * n.transpose()) * radial;
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
            Self::SlidingDirection => {
                // x holding (|t*_x| < μN): elastic; x sliding: t_x = s μN, ∂t_x/∂d_z = −s μ k_n.
                let (xx, xz) = if r.force.x.abs() < mu * r.normal_force {
                    (ks, 0.0)
                } else {
                    (0.0, -mu * kn * r.direction.x)
                };
                // y holding (|t*_y| < κN): elastic; y let go: t_y = ±κN, ∂t_y/∂d_z = ∓κ k_n.
                let kappa = Self::CROSS_HOLD.max(mu);
                let (yy, yz) = if r.force.y.abs() < kappa * r.normal_force {
                    (ks, 0.0)
                } else {
                    (0.0, -kappa * kn * r.force.y.signum())
                };
                Matrix3::new(xx, 0.0, xz, 0.0, yy, yz, 0.0, 0.0, kn)
            }
        }
    }

    /// The Ju–Rowlands slip matrix for slip direction `n`.
    fn ju_rowlands_slip(self, law: &GapLaw, n: Vector2<f64>) -> Matrix3<f64> {
        let (kn, ks, mu) = (law.normal_stiffness, law.tangential_stiffness, law.friction);
        match self {
            Self::Isotropic => {
                let a = Vector3::new(-mu * n.x, -mu * n.y, 1.0);
                let p = Vector3::new(-n.y, n.x, 0.0);
                a * a.transpose() * kn + p * p.transpose() * ks
            }
            Self::SlidingDirection => {
                // Eq. (2.9) slip `k` with the sign of the sliding direction `s = n_x`.
                let c = -mu * n.x.signum();
                Matrix3::new(c * c * kn, 0.0, c * kn, 0.0, ks, 0.0, c * kn, 0.0, kn)
            }
        }
    }
}

impl std::str::FromStr for FrictionLaw {
    type Err = String;

    fn from_str(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|l| l.name() == name)
            .ok_or_else(|| {
                format!("unknown friction law '{name}' (isotropic or sliding-direction)")
            })
    }
}

impl std::fmt::Display for FrictionLaw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
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
    /// How the gap slides.
    #[serde(default)]
    pub friction_law: FrictionLaw,
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
    /// slip it is the slip direction, its sign included: `(±1, 0)` for the sliding-direction
    /// law, the sign of `t*_x` (`+1` when `t*_x = 0`).
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
        let held_across = self.friction_law != FrictionLaw::SlidingDirection
            || trial.y.abs() <= FrictionLaw::cross_limit(normal_force, self.friction);
        if trial_magnitude - limit <= 0.0 && held_across {
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
            let [t, direction] = self.friction_law.return_map(
                trial,
                trial_magnitude,
                limit,
                (normal_force, self.friction),
            );
            GapResponse {
                status: GapStatus::Slip,
                relative: d,
                force: Vector3::new(t.x, t.y, -normal_force),
                normal_force,
                // Slip increment (t* − t)/k_s: zero across x for the sliding-direction law.
                plastic_slip: plastic_slip + (trial - t) / self.tangential_stiffness,
                direction,
                trial_magnitude,
            }
        }
    }

    /// Checks that `status` with the slip history `plastic_slip` is what [`GapLaw::evaluate`]
    /// commits at `d` from some history before it (a converged state read back): open or stick
    /// exactly as the law evaluates them; slip closed, with the trial force on or beyond (2.13)
    /// and the law's own return map leaving the history where it is (a committed slip is the
    /// fixed point of the return map: on the cone for the isotropic law, `|t_x| ≤ μN` for the
    /// sliding-direction law, whose `t_y` is elastic), both to `tolerance` (N). Err: what differs.
    pub fn check_committed(
        &self,
        status: GapStatus,
        d: Vector3<f64>,
        plastic_slip: Vector2<f64>,
        tolerance: f64,
    ) -> Result<(), String> {
        let r = self.evaluate(d, plastic_slip);
        let limit = self.friction * r.normal_force;
        let moved = (r.plastic_slip - plastic_slip).norm() * self.tangential_stiffness;
        let consistent = match status {
            GapStatus::Open | GapStatus::Stick => r.status == status,
            GapStatus::Slip => {
                r.status != GapStatus::Open
                    && r.trial_magnitude >= limit - tolerance
                    && moved <= tolerance
            }
        };
        if consistent {
            return Ok(());
        }
        let trial = (Vector2::new(d.x, d.y) - plastic_slip) * self.tangential_stiffness;
        Err(format!(
            "the {} law gives {:?} there (gap {:e} m, trial friction ({:e}, {:e}) N, \
             limit μN = {:e} N{})",
            self.friction_law,
            r.status,
            self.initial_gap + d.z,
            trial.x,
            trial.y,
            limit,
            if moved > tolerance {
                format!(
                    ", a further slip of {:e} m",
                    moved / self.tangential_stiffness
                )
            } else {
                String::new()
            }
        ))
    }

    /// Consistent tangent `∂r_A/∂d` of [`GapLaw::evaluate`] in the local frame.
    pub fn consistent_tangent(&self, response: &GapResponse) -> Matrix3<f64> {
        let (kn, ks) = (self.normal_stiffness, self.tangential_stiffness);
        match response.status {
            GapStatus::Open => Matrix3::zeros(),
            GapStatus::Stick => Matrix3::from_diagonal(&Vector3::new(ks, ks, kn)),
            GapStatus::Slip => self.friction_law.slip_tangent(self, response),
        }
    }

    /// The paper's symmetric matrix `k` of eq. (2.9) for a status and slip direction `n`.
    pub fn ju_rowlands_matrix(&self, status: GapStatus, direction: Vector2<f64>) -> Matrix3<f64> {
        let (kn, ks) = (self.normal_stiffness, self.tangential_stiffness);
        match status {
            GapStatus::Open => Matrix3::zeros(),
            GapStatus::Stick => Matrix3::from_diagonal(&Vector3::new(ks, ks, kn)),
            GapStatus::Slip => self.friction_law.ju_rowlands_slip(self, direction),
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
            friction_law: FrictionLaw::Isotropic,
        }
    }

    fn law_of(friction_law: FrictionLaw) -> GapLaw {
        GapLaw {
            friction_law,
            ..law()
        }
    }

    /// Central differences of the force of `law` at `d` against its consistent tangent.
    fn assert_tangent_matches_finite_difference(law: &GapLaw, d: Vector3<f64>, h: Vector2<f64>) {
        let response = law.evaluate(d, h);
        let k = law.consistent_tangent(&response);
        let step = 1e-10;
        for j in 0..3 {
            let (mut dp, mut dm) = (d, d);
            dp[j] += step;
            dm[j] -= step;
            let column = (law.evaluate(dp, h).force - law.evaluate(dm, h).force) / (2.0 * step);
            let err = (column - k.column(j)).amax();
            assert!(
                err < 1e-6 * law.normal_stiffness,
                "{} {:?} at {d:?}, column {j}: {err:e}",
                law.friction_law,
                response.status
            );
        }
    }

    // Pressed by 0.1 mm (N = 2.5e4 N, μN = 5e3 N), history (1e-5, −2e-5) m.
    const HISTORY: Vector2<f64> = Vector2::new(1e-5, -2e-5);
    const STATES: [(&str, [f64; 3], GapStatus); 6] = [
        ("open", [3e-6, 1e-6, 4e-6], GapStatus::Open),
        ("stick", [2e-5, -2e-5, -1e-4], GapStatus::Stick),
        ("slip +x", [4e-4, -1e-5, -1e-4], GapStatus::Slip), // t* = (9750, 250)
        ("slip -x", [-4e-4, -3e-5, -1e-4], GapStatus::Slip), // t* = (−10250, −250)
        (
            "(2.13) reached through y",
            [2e-5, 3e-4, -1e-4],
            GapStatus::Slip,
        ), // t* = (250, 8000)
        // Pressed by 1 nm (N = 0.25 N): the sliding-direction law's cross hold let go.
        ("cross hold let go", [1e-5, 1e-5, -1e-9], GapStatus::Slip), // t* = (0, 750)
    ];

    #[test]
    fn consistent_tangent_matches_finite_difference_in_each_status_of_both_laws() {
        for friction_law in FrictionLaw::ALL {
            let law = law_of(friction_law);
            for (name, d, status) in STATES {
                let d = Vector3::from(d);
                assert_eq!(
                    law.evaluate(d, HISTORY).status,
                    status,
                    "{friction_law} {name}"
                );
                assert_tangent_matches_finite_difference(&law, d, HISTORY);
            }
        }
    }

    #[test]
    fn committed_states_of_both_laws_pass_their_check_and_altered_ones_do_not() {
        let tolerance = 1e-6 * 5e3;
        for friction_law in FrictionLaw::ALL {
            let law = law_of(friction_law);
            for (name, d, status) in STATES {
                let d = Vector3::from(d);
                let r = law.evaluate(d, HISTORY);
                let check = |status, slip| law.check_committed(status, d, slip, tolerance);
                assert_eq!(
                    check(status, r.plastic_slip),
                    Ok(()),
                    "{friction_law} {name}"
                );
                for other in [GapStatus::Open, GapStatus::Stick, GapStatus::Slip] {
                    if other != status && !(status == GapStatus::Slip && other == GapStatus::Stick)
                    {
                        assert!(
                            check(other, r.plastic_slip).is_err(),
                            "{friction_law} {name} as {other:?}"
                        );
                    }
                }
                if status == GapStatus::Slip {
                    // The history before the slip is not a committed slip (it would slide on),
                    // except where (2.13) is reached through y under the paper's law (x holds).
                    let through_y = friction_law == FrictionLaw::SlidingDirection && d.y > 1e-4;
                    let err = check(GapStatus::Slip, HISTORY);
                    assert_eq!(err.is_ok(), through_y, "{friction_law} {name}: {err:?}");
                    if let Err(e) = err {
                        assert!(e.contains("further slip"), "{e}");
                    }
                }
            }
        }
    }

    #[test]
    fn sliding_direction_law_slides_along_x_at_mu_n_and_keeps_y_elastic() {
        let law = law_of(FrictionLaw::SlidingDirection);
        for (name, d, _) in &STATES[2..4] {
            let r = law.evaluate(Vector3::from(*d), HISTORY);
            let limit = law.friction * r.normal_force;
            let trial = (Vector2::new(d[0], d[1]) - HISTORY) * law.tangential_stiffness;
            // f_s = μ f_n along x with the trial force's sign; y elastic.
            assert_eq!(r.force.x, trial.x.signum() * limit, "{name}");
            assert_eq!(r.force.y, trial.y, "{name}");
            assert_eq!(r.direction, Vector2::new(trial.x.signum(), 0.0), "{name}");
            // The slip is along x only, and along the friction force (dissipative).
            assert_eq!(r.plastic_slip.y, HISTORY.y, "{name}");
            assert!((r.plastic_slip.x - HISTORY.x) * r.force.x > 0.0, "{name}");
        }
    }

    #[test]
    fn sliding_direction_law_is_continuous_where_its_status_and_x_slip_switch() {
        // t*_y = 3000 N, μN = 5000 N: (2.13) switches at t*_x = 4000 N, x starts sliding at 5000 N.
        let law = law_of(FrictionLaw::SlidingDirection);
        let dy = 3000.0 / law.tangential_stiffness;
        let at = |tx: f64| {
            let d = Vector3::new(tx / law.tangential_stiffness, dy, -1e-4);
            law.evaluate(d, Vector2::zeros())
        };
        for (switch, name) in [(4000.0, "(2.13)"), (5000.0, "x slip")] {
            let (inside, outside) = (at(switch * (1.0 - 1e-9)), at(switch * (1.0 + 1e-9)));
            assert!(
                (inside.force - outside.force).amax() < 1e-5,
                "{name}: {inside:?} vs {outside:?}"
            );
        }
        assert_eq!(
            (at(3999.0).status, at(4001.0).status),
            (GapStatus::Stick, GapStatus::Slip)
        );
    }

    /// The sliding-direction law's cross hold goes to zero with the normal force: a gap holding
    /// 44 N across (held-out `reversal#0`) lets go continuously as it lifts off, the force
    /// within `κ k_n |g|` of zero on either side of `g = 0` (it jumped by 44 N before the bound).
    #[test]
    fn sliding_direction_law_lets_go_across_continuously_at_lift_off() {
        let law = law_of(FrictionLaw::SlidingDirection);
        let dy = 44.0 / law.tangential_stiffness;
        let at = |gap: f64| law.evaluate(Vector3::new(0.0, dy, gap), Vector2::zeros());
        let pressed = at(-1e-4);
        assert_eq!((pressed.status, pressed.force.y), (GapStatus::Stick, 44.0));
        for g in [1e-9, 1e-12, 1e-15] {
            let bound = FrictionLaw::CROSS_HOLD * law.normal_stiffness * g * (1.0 + 1e-9);
            let (closed, open) = (at(-g), at(g));
            assert_eq!(open.force, Vector3::zeros());
            assert!(closed.force.amax() <= bound, "g = -{g}: {:?}", closed.force);
        }
        // In between, the hold is κN until the elastic trial force is below it.
        let light = at(-44.0 / (FrictionLaw::CROSS_HOLD * law.normal_stiffness) / 2.0);
        assert!((light.force.y - 22.0).abs() < 1e-9, "{:?}", light.force);
        assert_eq!(light.status, GapStatus::Slip);
    }

    #[test]
    fn reaching_2_13_through_y_leaves_x_elastic() {
        // t* = (250, 8000) N against μN = 5000 N: slip status by (2.13), but x is inside μN.
        let law = law_of(FrictionLaw::SlidingDirection);
        let (_, d, _) = STATES[4];
        let r = law.evaluate(Vector3::from(d), HISTORY);
        let trial = (Vector2::new(d[0], d[1]) - HISTORY) * law.tangential_stiffness;
        assert_eq!(r.status, GapStatus::Slip);
        assert_eq!(Vector2::new(r.force.x, r.force.y), trial);
        assert!(r.force.y > law.friction * r.normal_force, "y is not capped");
        assert_eq!(r.plastic_slip, HISTORY);
        let (ks, kn) = (law.tangential_stiffness, law.normal_stiffness);
        assert_eq!(
            law.consistent_tangent(&r),
            Matrix3::from_diagonal(&Vector3::new(ks, ks, kn))
        );
        // The isotropic cone slides along the trial force instead, across x too.
        let cone = law_of(FrictionLaw::Isotropic).evaluate(Vector3::from(d), HISTORY);
        assert!(cone.plastic_slip.y > HISTORY.y);
    }

    #[test]
    fn ju_rowlands_matrix_is_the_papers_for_sliding_along_x() {
        // Eq. (2.9), slip: [[μ²k_n, 0, μk_n], [0, k_s, 0], [μk_n, 0, k_n]], printed for one sliding
        // direction (−x with r_z = −N); sliding towards +x flips the sign of μ (notes §2).
        let (kn, ks, mu) = (2.5e8, 2.5e7, 0.2);
        let paper =
            |mu: f64| Matrix3::new(mu * mu * kn, 0.0, mu * kn, 0.0, ks, 0.0, mu * kn, 0.0, kn);
        for friction_law in FrictionLaw::ALL {
            let law = law_of(friction_law);
            for (s, expected) in [(-1.0, paper(mu)), (1.0, paper(-mu))] {
                let k = law.ju_rowlands_matrix(GapStatus::Slip, Vector2::new(s, 0.0));
                assert!((k - expected).amax() < 1e-6, "{friction_law} n = {s}x: {k}");
            }
            let stick = law.ju_rowlands_matrix(GapStatus::Stick, Vector2::new(1.0, 0.0));
            assert_eq!(stick, Matrix3::from_diagonal(&Vector3::new(ks, ks, kn)));
        }
        // The sliding-direction law always hands the solver n = ±x, the sign of t*_x.
        let law = law_of(FrictionLaw::SlidingDirection);
        let r = law.evaluate(Vector3::from(STATES[3].1), HISTORY);
        assert_eq!(law.ju_rowlands_matrix(r.status, r.direction), paper(mu));
    }

    #[test]
    fn friction_law_names_parse_and_unknown_ones_are_refused() {
        for l in FrictionLaw::ALL {
            assert_eq!(l.name().parse::<FrictionLaw>(), Ok(l));
            assert_eq!(
                serde_json::to_string(&l).unwrap(),
                format!("\"{}\"", l.name())
            );
        }
        let err = "x-only".parse::<FrictionLaw>().unwrap_err();
        assert!(
            err.contains("'x-only'") && err.contains("sliding-direction"),
            "{err}"
        );
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
