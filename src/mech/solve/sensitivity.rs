//! Linear response of the converged state (issue 21 item 1): how the results of the last step
//! move when the end values of its inputs (group translations and angles, load levels, μ)
//! move, the start of its last increment held: the derivatives a coupling master needs.
//!
//! The last increment's Newton equation `g_f(u, p, λ, μ) = 0` (free DOFs `u`, prescribed values
//! `p`, load levels `λ`, friction `μ`; gap laws and curved-support contacts from the
//! increment's start, as Newton used them) is linearized at its solution:
//! `K_ff du = −∂g_f/∂(p, λ, μ) · seed`, with `K_ff` the consistent tangent assembled at the
//! converged point and factorized once for the seed, and the right-hand side the central
//! difference of the assembled residual along the seed (step ε: a relative change of 1e-6 of
//! the largest seeded quantity), free DOFs held. The results then move along
//! `(du, dp, dλ, dμ)`: [`Response`] holds them at `±h, ±2h` along it (`h ≥ ε`, large enough
//! that the rounding of the displacements does not swamp a small response), so that the
//! derivative of any result is its fourth-order central difference.
//!
//! What the derivatives mean:
//! * exact (to the central difference's ~1e-9) where the step was one increment, or the
//!   response is path-independent over the step (gaps open or sticking, an elastic film);
//!   otherwise they are those of the last increment (the earlier ones held);
//! * at a switch (a gap exactly at opening, at the friction cone), one-sided: the law's own
//!   evaluation on either side of the converged point decides, which for a point on the switch
//!   itself averages the two slopes; the gap's status is the one the law finds at the
//!   converged point, kept;
//! * after [`Analysis::set_state`] (an FMU state restored) and before the next step, the start
//!   is the restored state itself: the linear response of the next increment.

use crate::mech::elements::gap::IterationMatrix;
use crate::mech::elements::load::LoadLevels;
use crate::mech::results::Results;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::Dof;
use crate::mech::solve::state::{AnalysisState, GroupMotion};

/// The largest displacement change of the outputs' central difference, as a fraction of the
/// model's size (see `Analysis::linear_response`; 1e-7 and 1e-6 each missed the differences of
/// steps by 2e-6 on the hinged panel's reaction, 3e-7 meets every check).
const OUTPUT_STEP: f64 = 3e-7;

/// The end values of a step's inputs moved along a seed: group motion, load levels, friction.
type Moved = (GroupMotion, LoadLevels, Vec<f64>);

/// A direction in the end values of a step's inputs (each in the input's own unit).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Seed {
    /// Per group: translation (m).
    pub translation: Vec<[f64; 3]>,
    /// Per group: angle about its hinge (rad).
    pub angles: Vec<f64>,
    /// Per pressure set (Pa).
    pub pressure: Vec<f64>,
    /// Per force set: force on each node (N).
    pub force: Vec<[f64; 3]>,
    /// Friction coefficient of every gap and curved-support contact.
    pub friction: f64,
}

impl Seed {
    /// The zero direction of `analysis`'s model.
    pub fn zero(analysis: &Analysis) -> Self {
        let state = analysis.state();
        Seed {
            translation: vec![[0.0; 3]; state.boundary.len()],
            angles: vec![0.0; state.angles.len()],
            pressure: vec![0.0; state.loads.pressure.len()],
            force: vec![[0.0; 3]; state.loads.force.len()],
            friction: 0.0,
        }
    }
}

/// The results at the converged state moved by `−2ε, −ε, ε, 2ε` along its linear response
/// to a seed: the derivative of any result is their fourth-order central difference.
#[derive(Clone, Debug)]
pub struct Response {
    /// Results at `−2ε, −ε, ε, 2ε` along the response.
    pub points: [Results; 4],
    /// The step `ε` (per unit seed).
    pub epsilon: f64,
}

impl Response {
    /// The derivative of the result `of` along the seed.
    pub fn derivative(&self, of: impl Fn(&Results) -> f64) -> f64 {
        let [m2, m1, p1, p2] = self.points.each_ref().map(&of);
        (8.0 * (p1 - m1) - (p2 - m2)) / (12.0 * self.epsilon)
    }
}

impl Analysis {
    /// The linear response of the converged state to `seed` (module doc). Errors: a seed of
    /// the wrong size, the Ju–Rowlands matrix (not the tangent), a singular tangent.
    pub fn linear_response(&mut self, seed: &Seed) -> Result<Response, String> {
        if self.settings.iteration_matrix != IterationMatrix::Consistent {
            return Err(
                "derivatives need the consistent tangent (solver.useJuRowlands = false)".into(),
            );
        }
        let end = self.state.clone();
        if seed.translation.len() != end.boundary.len()
            || seed.angles.len() != end.angles.len()
            || seed.pressure.len() != end.loads.pressure.len()
            || seed.force.len() != end.loads.force.len()
        {
            return Err("the seed does not fit the model's groups and load sets".into());
        }
        let start = self.increment_start.clone().unwrap_or_else(|| end.clone());
        // ε: a relative change of 1e-6 of the largest seeded quantity.
        let relative = |d: f64, x: f64, floor: f64| d.abs() / x.abs().max(floor);
        let l = self.length_scale;
        let mut largest = relative(
            seed.friction,
            end.friction.first().copied().unwrap_or(0.0),
            1e-2,
        );
        for (t, b) in seed.translation.iter().zip(&end.boundary) {
            for c in 0..3 {
                largest = largest.max(relative(t[c], b[c], l));
            }
        }
        for a in &seed.angles {
            largest = largest.max(a.abs());
        }
        for (d, p) in seed.pressure.iter().zip(&end.loads.pressure) {
            largest = largest.max(relative(*d, *p, 1.0));
        }
        for (d, f) in seed.force.iter().zip(&end.loads.force) {
            for c in 0..3 {
                largest = largest.max(relative(d[c], f[c], 1.0));
            }
        }
        if !largest.is_finite() {
            return Err("the seed holds values that are not finite".into());
        }
        if largest == 0.0 {
            let r = self.results();
            return Ok(Response {
                points: [r.clone(), r.clone(), r.clone(), r],
                epsilon: 1.0,
            });
        }
        let eps = 1e-6 / largest;
        let moved = |sign: f64| -> Moved {
            let s = sign * eps;
            let motion = GroupMotion {
                translation: end
                    .boundary
                    .iter()
                    .zip(&seed.translation)
                    .map(|(b, t)| std::array::from_fn(|c| b[c] + s * t[c]))
                    .collect(),
                angles: end
                    .angles
                    .iter()
                    .zip(&seed.angles)
                    .map(|(a, d)| a + s * d)
                    .collect(),
            };
            let levels = LoadLevels {
                pressure: end
                    .loads
                    .pressure
                    .iter()
                    .zip(&seed.pressure)
                    .map(|(p, d)| p + s * d)
                    .collect(),
                force: end
                    .loads
                    .force
                    .iter()
                    .zip(&seed.force)
                    .map(|(f, d)| std::array::from_fn(|c| f[c] + s * d[c]))
                    .collect(),
                gravity: end.loads.gravity,
            };
            let friction: Vec<f64> = end.friction.iter().map(|m| m + s * seed.friction).collect();
            (motion, levels, friction)
        };
        // Prescribed values along the seed.
        let (plus, minus) = (moved(1.0), moved(-1.0));
        let mut du = vec![0.0; end.displacement.len()];
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Prescribed { group, component } = *d {
                du[i] = (self.prescribed_value(i, group, component, &plus.0)
                    - self.prescribed_value(i, group, component, &minus.0))
                    / (2.0 * eps);
            }
        }
        let along = |u: &[f64], d: &[f64], s: f64| -> Vec<f64> {
            u.iter().zip(d).map(|(a, b)| a + s * b).collect()
        };
        // ∂g_f/∂(p, λ, μ) · seed, free DOFs held.
        let (_, g_plus) = self.results_from(&start, along(&end.displacement, &du, eps), &plus);
        let (_, g_minus) = self.results_from(&start, along(&end.displacement, &du, -eps), &minus);
        // The consistent tangent at the converged point, from the increment's start.
        let from = with_friction(&start, &end.friction);
        for c in self.parts.all_mut() {
            c.restore(&from);
        }
        self.assemble_at(&end.displacement, &end.loads, Some(1));
        let mut rhs = vec![0.0; self.system.free_count];
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Free(f) = *d {
                rhs[f] = -(g_plus[i] - g_minus[i]) / (2.0 * eps);
            }
        }
        if !rhs.is_empty() {
            let matrix = self.system.matrix(&self.work.values);
            self.linear
                .factorize_and_solve(matrix, &mut rhs)
                .map_err(|e| format!("the tangent at the converged state: {}", e.0))?;
        }
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Free(f) = *d {
                du[i] = rhs[f];
            }
        }
        // The outputs move along (du, seed) by a step of their own, at least ε: with ε alone, a
        // response that is small against the displacements themselves (the normal
        // displacement of a gap under a μ seed: 1e-14 m against 0.1 m) is lost to the
        // rounding of `u + ε du`, and a stiff gap (k_n = 2.5e8 N/m) turned that rounding into
        // 2e-3 of its normal force's derivative (issue 21: why μ was refused). The largest
        // displacement moves by `OUTPUT_STEP` of the model's size (the input by at most 1e-3
        // of itself); the fourth-order difference keeps the truncation (the slip direction
        // turns over the slip) below 1e-6 at that step.
        let du_max = du.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        let eps_out = if du_max > 0.0 {
            (OUTPUT_STEP * l / du_max).min(1e-3 / largest).max(eps)
        } else {
            eps
        };
        let points = [-2.0, -1.0, 1.0, 2.0].map(|k: f64| {
            let at = moved(k * eps_out / eps);
            self.results_from(&start, along(&end.displacement, &du, k * eps_out), &at)
                .0
        });
        self.state = end;
        Ok(Response {
            points,
            epsilon: eps_out,
        })
    }

    /// The results and the out-of-balance force of every DOF at displacements `u` and the
    /// group motion, load levels and friction `at`, the gap and contact histories of `start`;
    /// the state is left as it was.
    fn results_from(
        &mut self,
        start: &AnalysisState,
        u: Vec<f64>,
        at: &Moved,
    ) -> (Results, Vec<f64>) {
        let (motion, levels, friction) = at;
        let from = with_friction(start, friction);
        let trial = AnalysisState {
            displacement: u,
            plastic_slip: from.plastic_slip,
            contacts: from.contacts,
            boundary: motion.translation.clone(),
            angles: motion.angles.clone(),
            loads: levels.clone(),
            friction: from.friction,
            ..self.state.clone()
        };
        let saved = std::mem::replace(&mut self.state, trial);
        let results = self.results();
        let internal = self.work.internal.clone();
        self.state = saved;
        (results, internal)
    }
}

/// `state` with the friction coefficients `friction` (gaps and curved-support contacts).
fn with_friction(state: &AnalysisState, friction: &[f64]) -> AnalysisState {
    let mut s = state.clone();
    s.friction = friction.to_vec();
    if let Some(&mu) = friction.first() {
        s.contacts.iter_mut().for_each(|c| c.friction = mu);
    }
    s
}
