//! Linear response of the converged state (issue 21 item 1): how the results of the last step
//! move when the end values of its inputs (group translations and angles, load levels, μ)
//! move, the start of its last increment held: the derivatives a coupling master needs.
//!
//! The last increment's Newton equation `g_f(u, p, λ, μ) = 0` (free DOFs `u`, prescribed values
//! `p`, load levels `λ`, friction `μ`; gap laws and curved-support contacts from the
//! increment's start, as Newton used them) is linearized at its solution:
//! `K_ff du = −∂g_f/∂(p, λ, μ) · seed`, with `K_ff` the consistent tangent at the converged
//! point.
//!
//! Cost: one solve per seed. The first seed at a converged state assembles `K_ff` there and
//! factorizes it; the factor stays in the analysis's linear solver, and later seeds at the same
//! state solve with it (`LinearSolver::solve_held`: the same path, a slipping gap's Woodbury
//! block reused, every solution checked). It is held for the converged state, the increment's
//! start and the factor's identity (`LinearSolver::factor_id`) together, so that a step (whose
//! Newton iterations factorize), a restored state ([`Analysis::set_state`]) or a new μ
//! ([`Analysis::set_friction`]) each make the next seed factorize again: the derivatives are
//! then bit for bit those of an analysis that never held a factor. Newton's own last factor is
//! not the one: it is the tangent at the iterate before the converged one (Newton stops once
//! the correction it solved for is small), shifted by Levenberg–Marquardt or pseudo-time where
//! those acted. The held tangent's values are kept beside the factor (one array of the
//! pattern's size) for the solutions' checks.
//!
//! The right-hand side, by kind of input, free DOFs held:
//! * loads (pressures, nodal forces): exact. The residual is linear in the load levels
//!   (a follower pressure's force is `p/6 (x2 − x1) × (x3 − x1)` at the current positions), so
//!   the loads' residual at the seed's levels is `∂g/∂λ · seed` itself;
//! * μ (every gap's and curved-support contact's own coefficient, each moved by the seed): the
//!   central difference of the residual of the gaps and curved-support contacts alone
//!   (nothing else depends on μ), step ε below. A slipping gap's force `μ N t` is linear in μ
//!   on its side of the cone, so the difference is exact but for rounding; at the cone it is
//!   the law's average of the two sides (see below);
//! * group translations and angles: the central difference of the assembled residual along
//!   the prescribed displacements `dp` (step ε: a relative change of 1e-6 of the largest
//!   seeded quantity). The exact form, `K_fp dp`, needs the tangent's prescribed columns, which
//!   the pattern does not hold (prescribed DOFs are eliminated when it is built): a second
//!   pattern and slot table for every contribution, against two residual assemblies per seed
//!   (the same answers as FMU steps to 1e-6, unchanged). The difference's rounding is
//!   that of the residual over ε: for a pressure seed on the cushion it was 5e-8 of the
//!   derivatives, which the exact load form removed.
//!
//! The results then move along `(du, dp, dλ, dμ)`: [`Response`] holds them at `±h, ±2h` along
//! it (`h ≥ ε`, large enough that the rounding of the displacements does not swamp a small
//! response), so that the derivative of any result is its fourth-order central difference.
//! Each of those results is that of the histories a step ending there would commit, as a
//! step's results are (an open curved contact's anchor follows its node, so its slip does not
//! move).
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
use crate::mech::elements::load::{ExternalLoad, LoadLevels};
use crate::mech::results::Results;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::Dof;
use crate::mech::solve::contributions::{Contribution, Evaluation};
use crate::mech::solve::linear::FactorizationError;
use crate::mech::solve::state::{AnalysisState, GroupMotion};

/// The largest displacement change of the outputs' central difference, as a fraction of the
/// model's size (see `Analysis::linear_response`; 1e-7 and 1e-6 each missed the differences of
/// steps by 2e-6 on the hinged panel's reaction, 3e-7 meets every check).
const OUTPUT_STEP: f64 = 3e-7;

/// The end values of a step's inputs moved along a seed: group motion, load levels, and the
/// change of every friction coefficient.
type Moved = (GroupMotion, LoadLevels, f64);

/// The consistent tangent at a converged state and the identity of its factor in the
/// analysis's linear solver: what every seed at that state solves with (module doc).
#[derive(Clone, Debug)]
pub(in crate::mech) struct HeldTangent {
    /// [`LinearSolver::factor_id`](crate::mech::solve::linear::LinearSolver::factor_id) of its
    /// factor (0: none).
    factor: u64,
    /// The converged state and the increment start it was assembled at.
    end: AnalysisState,
    start: Option<AnalysisState>,
    /// Its values on the system's pattern (the solves' accuracy check and GMRES read them).
    values: Vec<f64>,
}

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
        if !end.chambers.is_empty() {
            return Err(
                "derivatives are not available for a model with gas chambers: \
                        the pneumatic stiffness is not in the held tangent"
                    .into(),
            );
        }
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
            end.friction
                .first()
                .or(end.contacts.first().map(|c| &c.friction))
                .copied()
                .unwrap_or(0.0),
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
                chambers: end.loads.chambers.clone(),
                heating: end.loads.heating.clone(),
                air: end.loads.air.clone(),
                time: end.loads.time,
            };
            (motion, levels, s * seed.friction)
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
        // ∂g/∂(p, λ, μ) · seed over every DOF, free DOFs held: by kind of input.
        let mut dg = vec![0.0; end.displacement.len()];
        if du.iter().any(|&d| d != 0.0) {
            // Group motion: central difference of the whole residual (module doc: why).
            let held = |m: Moved| (m.0, end.loads.clone(), 0.0);
            let (_, g_plus) =
                self.results_from(&start, along(&end.displacement, &du, eps), &held(plus));
            let (_, g_minus) =
                self.results_from(&start, along(&end.displacement, &du, -eps), &held(minus));
            for ((d, p), m) in dg.iter_mut().zip(&g_plus).zip(&g_minus) {
                *d += (p - m) / (2.0 * eps);
            }
        }
        if seed.pressure.iter().any(|&p| p != 0.0) || seed.force.iter().flatten().any(|&f| f != 0.0)
        {
            // Loads are linear in their levels: the residual of the loads alone at the seed's
            // levels is their derivative, exactly.
            let levels = LoadLevels {
                pressure: seed.pressure.clone(),
                force: seed.force.clone(),
                gravity: [0.0; 3],
                chambers: vec![0.0; end.loads.chambers.len()],
                heating: vec![0.0; end.loads.heating.len()],
                air: vec![0.0; end.loads.air.len()],
                time: 0.0,
            };
            self.parts
                .loads
                .add_to(&self.system, &levels, &end.displacement, &mut dg, None);
        }
        if seed.friction != 0.0 {
            self.add_friction_derivative(&start, &end, eps * seed.friction, &mut dg, 1.0 / eps);
        }
        let mut rhs = vec![0.0; self.system.free_count];
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Free(f) = *d {
                rhs[f] = -dg[i];
            }
        }
        if !rhs.is_empty() {
            self.solve_with_tangent(&start, &end, &mut rhs)
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

    /// Adds `scale · (g(μ + δ) − g(μ − δ))/2` to `dg`: the central difference of the residual
    /// of the gaps and curved-support contacts alone (nothing else depends on μ) at the
    /// converged displacements, friction coefficients moved by `±delta`, histories of `start`.
    fn add_friction_derivative(
        &mut self,
        start: &AnalysisState,
        end: &AnalysisState,
        delta: f64,
        dg: &mut [f64],
        scale: f64,
    ) {
        let mut g = [vec![0.0; dg.len()], vec![0.0; dg.len()]];
        for (sign, g) in [1.0, -1.0].into_iter().zip(&mut g) {
            let from = with_friction(start, end, sign * delta);
            let at = Evaluation {
                system: &self.system,
                u: &end.displacement,
                levels: &end.loads,
                iteration: None,
                matrix: self.settings.iteration_matrix,
            };
            let parts: [&mut dyn Contribution; 2] = [&mut self.parts.gaps, &mut self.parts.curved];
            for c in parts {
                c.restore(&from);
                c.add(&at, g, None);
            }
        }
        for ((d, p), m) in dg.iter_mut().zip(&g[0]).zip(&g[1]) {
            *d += 0.5 * scale * (p - m);
        }
    }

    /// Solves `K_ff x = rhs` in place with the consistent tangent at the converged state `end`
    /// (histories of `start`): with the factor held when it is that state's (same state, same
    /// increment start, no factorization since), else assembled and factorized, then held.
    fn solve_with_tangent(
        &mut self,
        start: &AnalysisState,
        end: &AnalysisState,
        rhs: &mut [f64],
    ) -> Result<(), FactorizationError> {
        if let Some(held) = self.held_tangent.as_deref_mut()
            && held.factor != 0
            && held.factor == self.linear.factor_id()
            && held.end == *end
            && held.start == self.increment_start
        {
            let matrix = self.system.matrix(&held.values);
            let solved = self.linear.solve_held(matrix, rhs);
            // A solution that failed its check was redone by a new factorization (of the same
            // matrix): that one is held now.
            held.factor = self.linear.factor_id();
            return solved;
        }
        let from = with_friction(start, end, 0.0);
        for c in self.parts.all_mut() {
            c.restore(&from);
        }
        self.assemble_at(&end.displacement, &end.loads, Some(1));
        let matrix = self.system.matrix(&self.work.values);
        self.linear.factorize_and_solve(matrix, rhs)?;
        self.held_tangent = Some(Box::new(HeldTangent {
            factor: self.linear.factor_id(),
            end: end.clone(),
            start: self.increment_start.clone(),
            values: self.work.values.clone(),
        }));
        Ok(())
    }

    /// The results and the out-of-balance force of every DOF at displacements `u` and the
    /// group motion, load levels and friction `at`, the gap and contact histories of `start`;
    /// the state is left as it was. The force is that of `start`'s histories (what Newton's
    /// last increment solves); the results are those of the histories a step ending at `u`
    /// commits, as a step's results are (a curved contact's slip from its committed anchor,
    /// which an open contact moves along with its node).
    fn results_from(
        &mut self,
        start: &AnalysisState,
        u: Vec<f64>,
        at: &Moved,
    ) -> (Results, Vec<f64>) {
        let (motion, levels, friction) = at;
        let from = with_friction(start, &self.state, *friction);
        for c in self.parts.all_mut() {
            c.restore(&from);
        }
        let mut trial = AnalysisState {
            displacement: u,
            plastic_slip: from.plastic_slip.clone(),
            contacts: from.contacts.clone(),
            layer_contacts: from.layer_contacts.clone(),
            boundary: motion.translation.clone(),
            angles: motion.angles.clone(),
            loads: levels.clone(),
            friction: from.friction.clone(),
            ..self.state.clone()
        };
        // The committed histories differ in what the results report only for curved and layer
        // contacts (their anchors) and a plastic film: elsewhere one evaluation serves both.
        let commit = !trial.contacts.is_empty()
            || !trial.layer_contacts.is_empty()
            || !trial.plastic.is_empty();
        let mut internal = None;
        if commit {
            self.assemble_at(&trial.displacement, &trial.loads, None);
            internal = Some(self.work.internal.clone());
            for c in self.parts.all() {
                c.commit(&from, &mut trial);
            }
        }
        let saved = std::mem::replace(&mut self.state, trial);
        let results = self.results();
        self.state = saved;
        let internal = internal.unwrap_or_else(|| self.work.internal.clone());
        (results, internal)
    }
}

/// `start` with the friction coefficients of `end` (gaps and curved-support contacts, each its
/// own) changed by `change`.
fn with_friction(start: &AnalysisState, end: &AnalysisState, change: f64) -> AnalysisState {
    let mut s = start.clone();
    s.friction = end.friction.iter().map(|m| m + change).collect();
    for (c, e) in s.contacts.iter_mut().zip(&end.contacts) {
        c.friction = e.friction + change;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::Model;
    use crate::mech::solve::settings::SolverSettings;
    use crate::specimens::ParallelArch;

    /// Numeric factorizations so far (LDLᵀ and LU).
    fn factorizations(a: &Analysis) -> usize {
        let p = a.solve_profile();
        p.ldlt_count + p.lu_count
    }

    /// The default specimen after `steps` steps of a twentieth of its lowering (one increment
    /// each), the friction coefficient raised to 0.5 before the last.
    fn lowered(steps: usize) -> (Analysis, ParallelArch) {
        let spec = ParallelArch::default();
        let model = spec.model().unwrap();
        let targets: Vec<_> = (1..=steps)
            .map(|k| spec.boundary_targets(&model, 0.05 * k as f64))
            .collect();
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        for (k, t) in targets.iter().enumerate() {
            if k + 1 == steps {
                a.set_friction(0.5).unwrap();
            }
            a.step_to(t, 1).unwrap();
        }
        (a, spec)
    }

    /// Every group moved along z by 1 m per unit seed.
    fn dz(a: &Analysis) -> Seed {
        let mut s = Seed::zero(a);
        s.translation.iter_mut().for_each(|t| t[2] = 1.0);
        s
    }

    fn mu(a: &Analysis) -> Seed {
        Seed {
            friction: 1.0,
            ..Seed::zero(a)
        }
    }

    /// The derivatives of the reactions and of every gap's forces and slips.
    fn derivatives(r: &Response) -> Vec<f64> {
        let mut d: Vec<f64> = (0..r.points[0].reactions.len())
            .flat_map(|g| (0..3).map(move |c| (g, c)))
            .map(|(g, c)| r.derivative(|x| x.reactions[g][c]))
            .collect();
        for i in 0..r.points[0].gaps.len() {
            d.push(r.derivative(|x| x.gaps[i].normal_force));
            d.push(r.derivative(|x| x.gaps[i].friction_force));
            d.push(r.derivative(|x| x.gaps[i].slip_x));
        }
        d
    }

    /// Issue 21: "one solve per seed direction with the stored factor". The first seed at a
    /// converged state factorizes the tangent, later seeds solve with that factor, and their
    /// answers are those of a new factorization (an analysis's copy holds no factor).
    #[test]
    fn a_second_seed_solves_with_the_factor_of_the_first() {
        let (mut a, _) = lowered(3);
        let before = factorizations(&a);
        let first = a.linear_response(&dz(&a)).unwrap();
        assert_eq!(factorizations(&a), before + 1);
        let p = a.solve_profile();
        let second = a.linear_response(&mu(&a)).unwrap();
        let again = a.linear_response(&dz(&a)).unwrap();
        assert_eq!(factorizations(&a), before + 1, "a later seed factorized");
        // One solve each: the slipping gaps' Woodbury path with its block kept, one column.
        let q = a.solve_profile();
        assert_eq!(q.held_solves, p.held_solves + 2);
        assert_eq!(q.woodbury_count, p.woodbury_count + 2);
        assert_eq!(q.woodbury_columns, p.woodbury_columns + 2);
        assert_eq!(q.gmres_count, p.gmres_count);
        assert_eq!(again.points, first.points);
        let mut copy = a.clone();
        let fresh = copy.linear_response(&mu(&copy)).unwrap();
        assert_eq!(factorizations(&copy), 1);
        for (h, f) in derivatives(&second).iter().zip(derivatives(&fresh)) {
            assert!((h - f).abs() <= 1e-12 * f.abs().max(1.0), "{h} vs {f}");
        }
        assert!(derivatives(&second).iter().any(|&d| d != 0.0));
    }

    /// The factor held belongs to one converged state: a step, a restored state and a new
    /// friction coefficient each replace it, and the derivatives are then those of an analysis
    /// that never held one, bit for bit.
    #[test]
    fn a_step_a_restored_state_or_a_new_mu_replaces_the_held_factor() {
        let (mut a, spec) = lowered(2);
        let earlier = a.state().clone();
        a.linear_response(&dz(&a)).unwrap();
        let model = a.model().clone();
        a.step_to(&spec.boundary_targets(&model, 0.15), 1).unwrap();
        let after_step = a.linear_response(&dz(&a)).unwrap();
        let (mut b, _) = lowered(2);
        b.step_to(&spec.boundary_targets(&model, 0.15), 1).unwrap();
        assert_eq!(a.state(), b.state());
        assert_eq!(
            after_step.points,
            b.linear_response(&dz(&b)).unwrap().points
        );

        // Restored to the earlier state (no factorization in between: only the state tells).
        let before = factorizations(&a);
        a.set_state(earlier.clone()).unwrap();
        let restored = a.linear_response(&dz(&a)).unwrap();
        assert_eq!(factorizations(&a), before + 1);
        let mut c = Analysis::new(model, SolverSettings::default()).unwrap();
        c.set_state(earlier).unwrap();
        assert_eq!(restored.points, c.linear_response(&dz(&c)).unwrap().points);

        // μ changed after the step: the tangent's slipping gaps change with it.
        a.set_friction(0.3).unwrap();
        c.set_friction(0.3).unwrap();
        let raised = a.linear_response(&mu(&a)).unwrap();
        assert_eq!(raised.points, c.linear_response(&mu(&c)).unwrap().points);
        assert_ne!(derivatives(&raised), derivatives(&restored));
    }

    /// The exact right-hand side of a pressure seed (the loads' residual at the seed's levels)
    /// against a central difference of the whole residual on the cushion (whose follower
    /// pressure moves with the film), with a step of 1 Pa, which the residual's linearity in
    /// the level makes exact but for rounding: the output points move alike to 1e-9.
    #[test]
    fn exact_load_derivative_agrees_with_the_residual_difference() {
        let model = Model::from_json(include_str!("../../../examples/cushion.json")).unwrap();
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        let mut levels = a.state().loads.clone();
        levels.pressure[0] = 200.0;
        let target = a.state().boundary.clone();
        a.step_to_with_loads(&target, &levels, 4).unwrap();
        let mut seed = Seed::zero(&a);
        seed.pressure[0] = 1.0;
        let exact = a.linear_response(&seed).unwrap();
        let end = a.state().clone();
        let start = a.increment_start.clone().unwrap();
        let at = |s: f64| {
            let mut l = end.loads.clone();
            l.pressure[0] += s;
            let motion = GroupMotion {
                translation: end.boundary.clone(),
                angles: end.angles.clone(),
            };
            (motion, l, 0.0)
        };
        let (_, plus) = a.results_from(&start, end.displacement.clone(), &at(1.0));
        let (_, minus) = a.results_from(&start, end.displacement.clone(), &at(-1.0));
        let mut du = vec![0.0; a.system.free_count];
        for (i, d) in a.system.dofs.iter().enumerate() {
            if let Dof::Free(f) = *d {
                du[f] = -(plus[i] - minus[i]) / 2.0;
            }
        }
        a.solve_with_tangent(&start, &end, &mut du).unwrap();
        let points = a.model.outputs.points.clone();
        assert!(!points.is_empty());
        let mut pairs = vec![];
        for (p, point) in points.iter().enumerate() {
            for c in 0..3 {
                let expected = match a.system.dofs[3 * point.node + c] {
                    Dof::Free(f) => du[f],
                    _ => 0.0,
                };
                pairs.push((expected, exact.derivative(|r| r.points[p][c])));
            }
        }
        let largest = pairs.iter().fold(0.0_f64, |m, p| m.max(p.0.abs()));
        assert!(largest > 0.0);
        for (expected, got) in pairs {
            assert!(
                (expected - got).abs() <= 1e-9 * largest,
                "{got} vs {expected}"
            );
        }
    }
}
