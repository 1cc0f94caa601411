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
//! * a chamber's inputs (its supply's pressure, its air's temperature rise, the air supplied;
//!   issue 43): the central difference of the chambers' residual alone (nothing else depends
//!   on them), the gas of the increment's start with the orifices' exchange over the
//!   increment, as Newton evaluates it. A sealed chamber's pressure is affine in the air added
//!   and in the temperature, a supplied one's is its supply's level: exact but for rounding;
//!   through an orifice (the backward-Euler transfer) to the difference's ε²;
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
//! With gas chambers (issue 43) `K_ff` is the sparse tangent `S` (the pressure's load
//! stiffness `−p ∂²V/∂u²` in it) plus the sealed chambers' pneumatic stiffness `G A Gᵀ`, solved
//! as Newton's correction solves it (`solve/low_rank.rs`: the Sherman–Morrison–Woodbury update
//! of `S`'s factor, `S⁻¹ G` solved at the first seed and held with the factor; the transpose
//! solve of an adjoint takes `Aᵀ`, which an orifice makes differ from `A`). A supplied chamber
//! adds no such term: its pressure is its supply's level, fixed in `u`. The chambers' outputs
//! (pressure, volume, mass, temperature) at the points below are those of the gas a step
//! ending there would commit.
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
//!
//! **One-solve adjoint** ([`Analysis::adjoint_response`], issue 45): `vᵀ J` over any number of
//! inputs for outputs whose gradient with respect to the displacements is known without
//! differences: a reaction (a group's, a support set's, the total: a sum of the residual's
//! restrained rows r, `∂R/∂u_f = K_rf`) and an output point's displacement (a unit row). With `y` those outputs and `g` the residual,
//! `vᵀ dy/dq = vᵀ ∂y/∂q − λᵀ ∂g_f/∂q`, `K_ffᵀ λ = (∂y/∂u_f)ᵀ v`: one solve for λ, then per
//! input the residual's derivative above (two residual assemblies for a group's motion, the
//! loads' residual for a load, the contacts' for μ) contracted with λ and with the reactions'
//! weights. The solve is the held factor's transpose solve (`LinearSolver::solve_held_transpose`:
//! the LU's transpose, or `Kᵀ = S − K_skew` on the symmetric part's LDLᵀ by Woodbury or GMRES,
//! checked against `Kᵀ`), so a sliding contact or a follower pressure (an unsymmetric tangent)
//! costs one solve too (issue 45: `vᵀ(J s) = (Jᵀ v)ᵀ s` to 9e-13 of the largest under a slipping
//! gap, 4e-12 under a follower pressure, with output points' weights). A reaction's part of
//! the right-hand side, `K_rfᵀ v`, is made of the tangent's rows at the restrained DOFs,
//! which the system's pattern drops (it eliminates prescribed DOFs): they are assembled from
//! the same element, gap, contact and load tangents into a copy of the system whose value
//! array goes on with a slot for each entry at a restrained row and a free column
//! (`System::with_constrained_rows`), then contracted with the reactions' weights, so that a
//! sliding contact or a follower pressure costs one solve for reactions too. The values agree
//! with J's columns to the columns' own accuracy (a fourth-order difference of the results along
//! each response, the adjoint a contraction of exact rows and residual differences).

use crate::mech::elements::chamber::GasLaw;
use crate::mech::elements::gap::IterationMatrix;
use crate::mech::elements::load::{ExternalLoad, LoadLevels};
use crate::mech::results::Results;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::Dof;
use crate::mech::solve::contributions::{Contribution, Evaluation, LowRank};
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
    /// The sealed chambers' pneumatic stiffness `G A Gᵀ` at that state, beside the sparse
    /// values (`solve/low_rank.rs`).
    low_rank: LowRank,
    /// `S⁻¹ G` and `S⁻ᵀ G` of [`Self::low_rank`], each solved at its first use.
    solved: [Option<Vec<Vec<f64>>>; 2],
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
    /// Per chamber: the pressure its supply holds (Pa; [`LoadLevels::chambers`]).
    pub supply: Vec<f64>,
    /// Per chamber: the air's temperature rise (K; [`LoadLevels::heating`]).
    pub heating: Vec<f64>,
    /// Per chamber: the air supplied since the start (kg; [`LoadLevels::air`]).
    pub air: Vec<f64>,
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
            supply: vec![0.0; analysis.model().chambers.len()],
            heating: vec![0.0; analysis.model().chambers.len()],
            air: vec![0.0; analysis.model().chambers.len()],
        }
    }

    /// Whether it moves a chamber's input (supply, heating, air).
    fn moves_chambers(&self) -> bool {
        let moves = |v: &[f64]| v.iter().any(|&x| x != 0.0);
        moves(&self.supply) || moves(&self.heating) || moves(&self.air)
    }
}

/// The weights `v` of the outputs a one-solve adjoint ([`Analysis::adjoint_response`])
/// contracts: the outputs whose gradient with respect to the displacements the analysis has
/// without differences (a reaction: a sum of the residual's restrained rows; a point's
/// displacement: a unit row).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputWeights {
    /// Per group: the weight of its reaction along x, y, z (prescribed components; others
    /// ignored).
    pub reactions: Vec<[f64; 3]>,
    /// Per named support set: the weight of its reaction along x, y, z (fixed components).
    pub supports: Vec<[f64; 3]>,
    /// The weight of the total reaction (every restraint) along x, y, z.
    pub total: [f64; 3],
    /// Per output point: the weight of its displacement along x, y, z.
    pub points: Vec<[f64; 3]>,
}

impl OutputWeights {
    /// No weight, for `analysis`'s model.
    pub fn zero(analysis: &Analysis) -> Self {
        OutputWeights {
            reactions: vec![[0.0; 3]; analysis.state().boundary.len()],
            supports: vec![[0.0; 3]; analysis.model().support_sets().len()],
            total: [0.0; 3],
            points: vec![[0.0; 3]; analysis.model().outputs.points.len()],
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
        let (start, end) = self.derivative_states(seed)?;
        let Some(largest) = self.seed_scale(&end, seed)? else {
            let r = self.results();
            return Ok(Response {
                points: [r.clone(), r.clone(), r.clone(), r],
                epsilon: 1.0,
            });
        };
        // ε: a relative change of 1e-6 of the largest seeded quantity.
        let eps = 1e-6 / largest;
        let (mut du, dg) = self.seed_residual(&start, &end, seed, eps);
        let mut rhs = vec![0.0; self.system.free_count];
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Free(f) = *d {
                rhs[f] = -dg[i];
            }
        }
        if !rhs.is_empty() {
            self.solve_with_tangent(&start, &end, &mut rhs, false)
                .map_err(|e| format!("the tangent at the converged state: {}", e.0))?;
        }
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Free(f) = *d {
                du[i] = rhs[f];
            }
        }
        let (points, epsilon) = self.response_points(&start, &end, seed, (eps, largest), &du);
        self.state = end;
        Ok(Response { points, epsilon })
    }

    /// The increment's start and the converged state a seed's derivatives are taken at, once
    /// the analysis and the seed allow them (the consistent tangent, a seed of the model's
    /// sizes).
    fn derivative_states(&self, seed: &Seed) -> Result<(AnalysisState, AnalysisState), String> {
        if self.settings.iteration_matrix != IterationMatrix::Consistent {
            return Err(
                "derivatives need the consistent tangent (solver.useJuRowlands = false)".into(),
            );
        }
        let end = self.state.clone();
        let chambers = self.model.chambers.len();
        if seed.translation.len() != end.boundary.len()
            || seed.angles.len() != end.angles.len()
            || seed.pressure.len() != end.loads.pressure.len()
            || seed.force.len() != end.loads.force.len()
            || [&seed.supply, &seed.heating, &seed.air]
                .iter()
                .any(|v| v.len() != chambers)
        {
            return Err("the seed does not fit the model's groups, load sets and chambers".into());
        }
        let start = self.increment_start.clone().unwrap_or_else(|| end.clone());
        Ok((start, end))
    }

    /// The largest seeded quantity, each relative to its input's value (at least its floor);
    /// None for a zero seed.
    fn seed_scale(&self, end: &AnalysisState, seed: &Seed) -> Result<Option<f64>, String> {
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
        largest = largest.max(self.chamber_seed_scale(end, seed));
        if !largest.is_finite() {
            return Err("the seed holds values that are not finite".into());
        }
        Ok((largest != 0.0).then_some(largest))
    }

    /// The prescribed DOFs' motion along `seed` (0 at free DOFs) and `∂g/∂(p, λ, μ) · seed`
    /// over every DOF, free DOFs held, by kind of input (module doc), differences of step
    /// `eps`.
    fn seed_residual(
        &mut self,
        start: &AnalysisState,
        end: &AnalysisState,
        seed: &Seed,
        eps: f64,
    ) -> (Vec<f64>, Vec<f64>) {
        let (plus, minus) = (moved(end, seed, eps), moved(end, seed, -eps));
        let mut du = vec![0.0; end.displacement.len()];
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Prescribed { group, component } = *d {
                du[i] = (self.prescribed_value(i, group, component, &plus.0)
                    - self.prescribed_value(i, group, component, &minus.0))
                    / (2.0 * eps);
            }
        }
        let mut dg = vec![0.0; end.displacement.len()];
        if du.iter().any(|&d| d != 0.0) {
            // Group motion: central difference of the whole residual (module doc: why).
            let held = |m: Moved| (m.0, end.loads.clone(), 0.0);
            let (_, g_plus) =
                self.results_from(start, along(&end.displacement, &du, eps), &held(plus));
            let (_, g_minus) =
                self.results_from(start, along(&end.displacement, &du, -eps), &held(minus));
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
            self.add_friction_derivative(start, end, eps * seed.friction, &mut dg, 1.0 / eps);
        }
        if seed.moves_chambers() {
            self.add_chamber_derivative(start, end, seed, eps, &mut dg);
        }
        (du, dg)
    }

    /// The largest of a seed's chamber inputs, each relative to its value: the supply's
    /// pressure (at least 1 Pa), the air's absolute temperature, its mass (at least 1 mg).
    fn chamber_seed_scale(&self, end: &AnalysisState, seed: &Seed) -> f64 {
        let mut largest = 0.0_f64;
        for (k, spec) in self.model.chambers.iter().enumerate() {
            let level = |v: &[f64]| v.get(k).copied().unwrap_or(0.0);
            let gas = end.chambers.get(k).copied().unwrap_or_default();
            let law = GasLaw {
                kappa: spec.kappa,
                atmosphere: spec.atmosphere,
                temperature: spec.temperature,
            };
            let temperature = spec.temperature + level(&end.loads.heating);
            let mass = law.mass(gas.pressure, gas.volume, temperature);
            largest = largest
                .max(seed.supply[k].abs() / level(&end.loads.chambers).abs().max(1.0))
                .max(seed.heating[k].abs() / temperature.abs())
                .max(seed.air[k].abs() / mass.abs().max(1e-6));
        }
        largest
    }

    /// Adds the central difference of the chambers' residual (nothing else depends on their
    /// inputs) along `seed`'s chamber inputs, step `eps`, at the converged displacements, the
    /// gas of `start` (with the orifices' exchange over the increment, as Newton's): exact but
    /// for rounding without orifices (the pressure is affine in the supply's level, in the air
    /// added and in the temperature), to the difference's `eps²` with them.
    fn add_chamber_derivative(
        &mut self,
        start: &AnalysisState,
        end: &AnalysisState,
        seed: &Seed,
        eps: f64,
        dg: &mut [f64],
    ) {
        let mut g = [vec![0.0; dg.len()], vec![0.0; dg.len()]];
        for (sign, g) in [1.0, -1.0].into_iter().zip(&mut g) {
            let (_, levels, _) = moved(end, seed, sign * eps);
            let at = Evaluation {
                system: &self.system,
                u: &end.displacement,
                levels: &levels,
                iteration: None,
                matrix: self.settings.iteration_matrix,
            };
            self.parts.chambers.restore(start);
            self.parts.chambers.add(&at, g, None);
        }
        for ((d, p), m) in dg.iter_mut().zip(&g[0]).zip(&g[1]) {
            *d += (p - m) / (2.0 * eps);
        }
    }

    /// The results at `−2h, −h, h, 2h` along the response `du` (every DOF) to `seed`, and `h`.
    fn response_points(
        &mut self,
        start: &AnalysisState,
        end: &AnalysisState,
        seed: &Seed,
        (eps, largest): (f64, f64),
        du: &[f64],
    ) -> ([Results; 4], f64) {
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
            (OUTPUT_STEP * self.length_scale / du_max)
                .min(1e-3 / largest)
                .max(eps)
        } else {
            eps
        };
        let points = [-2.0, -1.0, 1.0, 2.0].map(|k: f64| {
            // The inputs' step as the seed's sign times ε, rounded as before the split.
            let at = moved(end, seed, (k * eps_out / eps) * eps);
            self.results_from(start, along(&end.displacement, du, k * eps_out), &at)
                .0
        });
        (points, eps_out)
    }

    /// `Jᵀ v` over `seeds` (one value per seed: `vᵀ J seed`), `v` the weights of the group
    /// reactions and output points' displacements, J the derivatives
    /// [`Analysis::linear_response`] gives, at the cost of **one** solve with the held
    /// tangent's transpose (module doc, "One-solve adjoint"), symmetric or not, reactions'
    /// rows `K_rf` assembled. Errors: those of [`Analysis::linear_response`] and weights of
    /// the wrong size.
    pub fn adjoint_response(
        &mut self,
        weights: &OutputWeights,
        seeds: &[Seed],
    ) -> Result<Vec<f64>, String> {
        let zero = Seed::zero(self);
        let (start, end) = self.derivative_states(&zero)?;
        if weights.reactions.len() != end.boundary.len()
            || weights.supports.len() != self.model.support_sets().len()
            || weights.points.len() != self.model.outputs.points.len()
        {
            return Err("the weights do not fit the model's groups and output points".into());
        }
        // w = Cᵀ v over the free DOFs: a reaction's row of C is K_rf (r: its restrained DOFs),
        // assembled from the element tangents (`K_rfᵀ v`, any tangent); a point's is its free
        // DOFs.
        let restrained = self.restrained_weights(weights);
        if restrained.iter().any(|&x| x != 0.0)
            && let Some(c) = self
                .model
                .chambers
                .iter()
                .zip(&end.chambers)
                .find(|(_, c)| c.sealed)
        {
            // Refused before the solve, so that the caller's columns are all it pays.
            return Err(format!(
                "chamber '{}' is sealed: the restrained rows of its pneumatic stiffness (a \
                 low-rank term outside the assembled tangent) are not in a reaction's K_rfᵀ v",
                c.0.name
            ));
        }
        let mut w = if restrained.iter().any(|&x| x != 0.0) {
            self.restrained_rows_transposed(&start, &end, &restrained)?
        } else {
            vec![0.0; self.system.free_count]
        };
        for (point, weight) in self.model.outputs.points.iter().zip(&weights.points) {
            for (c, x) in weight.iter().enumerate() {
                if let Dof::Free(f) = self.system.dofs[3 * point.node + c] {
                    w[f] += x;
                }
            }
        }
        // λ = K⁻ᵀ w: the one solve, the held factor's transpose solve.
        let mut lambda = w;
        if lambda.iter().any(|&x| x != 0.0) {
            self.solve_with_tangent(&start, &end, &mut lambda, true)
                .map_err(|e| format!("the tangent at the converged state: {}", e.0))?;
        }
        let values = seeds
            .iter()
            .map(|seed| self.adjoint_entry((&start, &end), (weights, &restrained), &lambda, seed))
            .collect();
        self.state = end;
        values
    }

    /// `vᵀ J seed = vᵀ (∂y/∂q seed) − λᵀ ∂g_f/∂q seed`: the outputs' direct dependence on the
    /// inputs (a reaction's residual rows, a prescribed point's motion) less the free
    /// residual's derivative contracted with the adjoint `λ`.
    fn adjoint_entry(
        &mut self,
        (start, end): (&AnalysisState, &AnalysisState),
        (weights, restrained): (&OutputWeights, &[f64]),
        lambda: &[f64],
        seed: &Seed,
    ) -> Result<f64, String> {
        self.derivative_states(seed)?;
        let Some(largest) = self.seed_scale(end, seed)? else {
            return Ok(0.0);
        };
        let (du, dg) = self.seed_residual(start, end, seed, 1e-6 / largest);
        let mut value = 0.0;
        for (i, d) in self.system.dofs.iter().enumerate() {
            match *d {
                Dof::Free(f) => value -= lambda[f] * dg[i],
                _ => value += restrained[i] * dg[i],
            }
        }
        for (point, weight) in self.model.outputs.points.iter().zip(&weights.points) {
            for (c, x) in weight.iter().enumerate() {
                value += x * du[3 * point.node + c];
            }
        }
        Ok(value)
    }

    /// The reactions' weights on every DOF (0 at free ones): a reaction is the sum of the
    /// residual's rows it gathers (`Analysis::results`), so its weight goes to each of them.
    fn restrained_weights(&self, weights: &OutputWeights) -> Vec<f64> {
        let mut on = vec![0.0; self.system.dofs.len()];
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Prescribed { group, component } = *d {
                on[i] += weights.reactions[group][component];
            }
            if !matches!(d, Dof::Free(_)) {
                on[i] += weights.total[i % 3];
            }
        }
        let sets = self.model.support_sets();
        for s in &self.model.supports {
            let Some(set) = s
                .name
                .as_ref()
                .and_then(|n| sets.iter().position(|m| m == n))
            else {
                continue;
            };
            for a in &s.fixed {
                on[3 * s.node + a.index()] += weights.supports[set][a.index()];
            }
        }
        on
    }

    /// `K_rfᵀ v` over the free DOFs, `v` the reactions' weights on every DOF (`restrained`, 0 at
    /// free ones): the rows of the constrained DOFs of the consistent tangent at `end`
    /// (histories of `start`, as the held tangent), which the system's pattern drops, assembled
    /// from the same contributions into a copy of the system that holds them
    /// ([`System::with_constrained_rows`](crate::mech::solve::assembly::System::with_constrained_rows)).
    fn restrained_rows_transposed(
        &mut self,
        start: &AnalysisState,
        end: &AnalysisState,
        restrained: &[f64],
    ) -> Result<Vec<f64>, String> {
        let (system, rows) = self.system.with_constrained_rows().map_err(|e| e.0)?;
        let from = with_friction(start, end, 0.0);
        for c in self.parts.all_mut() {
            c.restore(&from);
        }
        let at = Evaluation {
            system: &system,
            u: &end.displacement,
            levels: &end.loads,
            iteration: Some(1),
            matrix: self.settings.iteration_matrix,
        };
        let nnz = system.nonzeros();
        let mut values = vec![0.0; nnz + rows.len()];
        let mut residual = vec![0.0; end.displacement.len()];
        self.parts.assemble(&at, &mut residual, Some(&mut values));
        let mut w = vec![0.0; self.system.free_count];
        for (&(r, f), k) in rows.iter().zip(&values[nnz..]) {
            w[f] += restrained[r] * k;
        }
        Ok(w)
    }

    /// Ok when the held tangent is symmetric to rounding (`|K_ij − K_ji| ≤ 1e-10 max |K|`), else
    /// the error names the largest asymmetry: the tests' proof that a case's tangent is not.
    #[cfg(test)]
    fn held_tangent_symmetric(&self) -> Result<(), String> {
        let Some(held) = self.held_tangent.as_deref() else {
            return Err("no tangent held".into());
        };
        let m = self.system.matrix(&held.values);
        let largest = held.values.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let mut worst = 0.0_f64;
        for j in 0..m.ncols() {
            for (&i, &v) in m.row_idx_of_col_raw(j).iter().zip(m.val_of_col(j)) {
                let t = m.get(j, i).copied().unwrap_or(0.0);
                worst = worst.max((v - t).abs());
            }
        }
        if worst <= 1e-10 * largest {
            Ok(())
        } else {
            Err(format!(
                "the tangent is not symmetric (|K_ij − K_ji| up to {worst:e} of {largest:e})"
            ))
        }
    }

    /// Solves with the consistent tangent at the converged state since the analysis was built
    /// (the derivatives' solves: the one of an adjoint, one per seed of a linear response).
    pub fn tangent_solves(&self) -> usize {
        self.tangent_solves
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

    /// Solves `K_ff x = rhs` (`K_ffᵀ x = rhs` with `transpose`: an adjoint's solve) in place
    /// with the consistent tangent at the converged state `end` (histories of `start`): with
    /// the factor held when it is that state's (same state, same increment start, no
    /// factorization since), else assembled and factorized, then held.
    fn solve_with_tangent(
        &mut self,
        start: &AnalysisState,
        end: &AnalysisState,
        rhs: &mut [f64],
        transpose: bool,
    ) -> Result<(), FactorizationError> {
        self.tangent_solves += 1;
        if let Some(held) = self.held_tangent.as_deref_mut()
            && held.factor != 0
            && held.factor == self.linear.factor_id()
            && held.end == *end
            && held.start == self.increment_start
        {
            let matrix = self.system.matrix(&held.values);
            let solved = if transpose {
                self.linear.solve_held_transpose(matrix, rhs)
            } else {
                self.linear.solve_held(matrix, rhs)
            };
            // A solution that failed its check was redone by a new factorization (of the same
            // matrix): that one is held now.
            held.factor = self.linear.factor_id();
            solved?;
            return self.add_held_low_rank(rhs, transpose);
        }
        let from = with_friction(start, end, 0.0);
        for c in self.parts.all_mut() {
            c.restore(&from);
        }
        self.assemble_at(&end.displacement, &end.loads, Some(1));
        let matrix = self.system.matrix(&self.work.values);
        if transpose {
            // The factorization's own solve is not the one asked: its transpose follows.
            let mut forward = rhs.to_vec();
            self.linear.factorize_and_solve(matrix, &mut forward)?;
            self.linear.solve_held_transpose(matrix, rhs)?;
        } else {
            self.linear.factorize_and_solve(matrix, rhs)?;
        }
        self.held_tangent = Some(Box::new(HeldTangent {
            factor: self.linear.factor_id(),
            end: end.clone(),
            start: self.increment_start.clone(),
            values: self.work.values.clone(),
            low_rank: self.parts.chambers.low_rank().clone(),
            solved: [None, None],
        }));
        self.add_held_low_rank(rhs, transpose)
    }

    /// Turns `rhs = S⁻¹ b` (`S⁻ᵀ b` with `transpose`), solved with the held tangent's sparse
    /// part, into the solution with its chambers' pneumatic stiffness `G A Gᵀ` (the Newton
    /// correction's Woodbury update, `solve/low_rank.rs`), `S⁻¹ G` solved at the first seed
    /// and kept: nothing without a sealed chamber.
    fn add_held_low_rank(
        &mut self,
        rhs: &mut [f64],
        transpose: bool,
    ) -> Result<(), FactorizationError> {
        let Some(held) = self.held_tangent.as_deref_mut() else {
            return Ok(());
        };
        if held.low_rank.is_empty() {
            return Ok(());
        }
        let slot = &mut held.solved[usize::from(transpose)];
        if slot.is_none() {
            let matrix = self.system.matrix(&held.values);
            *slot = Some(
                held.low_rank
                    .solved_columns(&mut self.linear, matrix, transpose)?,
            );
        }
        let z = slot.as_deref().expect("solved above");
        held.low_rank.correct(z, rhs, transpose)
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
            || !trial.plastic.is_empty()
            || !trial.chambers.is_empty();
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

/// The end values of a step's inputs moved by `s` along `seed`.
fn moved(end: &AnalysisState, seed: &Seed, s: f64) -> Moved {
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
        chambers: shifted(&end.loads.chambers, &seed.supply, s),
        heating: shifted(&end.loads.heating, &seed.heating, s),
        air: shifted(&end.loads.air, &seed.air, s),
        time: end.loads.time,
    };
    (motion, levels, s * seed.friction)
}

/// The chambers' levels `v` moved by `s d` (an entry `v` lacks read as 0, as the levels read
/// it); `v` itself where `d` is zero.
fn shifted(v: &[f64], d: &[f64], s: f64) -> Vec<f64> {
    if d.iter().all(|&x| x == 0.0) {
        return v.to_vec();
    }
    (0..v.len().max(d.len()))
        .map(|k| v.get(k).copied().unwrap_or(0.0) + s * d.get(k).copied().unwrap_or(0.0))
        .collect()
}

/// `u + s d`.
fn along(u: &[f64], d: &[f64], s: f64) -> Vec<f64> {
    u.iter().zip(d).map(|(a, b)| a + s * b).collect()
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
#[path = "adjoint_tests.rs"]
mod adjoint_tests;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::Model;
    use crate::mech::elements::gap::FrictionLaw;
    use crate::mech::elements::gap::GapStatus;
    use crate::mech::solve::settings::SolverSettings;
    use crate::specimens::ParallelArch;

    /// The one-solve adjoint's largest difference from `vᵀ` times J's columns, relative to the
    /// largest (the columns' differences bound it).
    pub(super) const COLUMNS: f64 = 1e-8;

    /// The one-solve adjoint's largest difference from `vᵀ (J s)` of the same parts solved
    /// forward, relative to the largest (rounding of the two solves).
    pub(super) const TRANSPOSED: f64 = 2e-11;

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

    pub(super) fn mu(a: &Analysis) -> Seed {
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

    /// The one-solve adjoint (issue 45 item 1). TEST GOAL: `vᵀ J` over many inputs (every
    /// group's three translations and μ) costs one solve with the held tangent, and equals
    /// `vᵀ` times J's columns (one linear response per input) to their differences' accuracy.
    /// MODEL: the specimen's frame lowered by 5 mm per step with μ = 0.2, then two steps with
    /// μ = 9.9 (the closed gaps stick: a symmetric tangent; as in `src/fmi3/tests`), two output
    /// points: a free film node and a frame node (whose displacement is the input's own).
    /// Weights: pseudo-random on every group's reactions, the total reaction (the symmetry
    /// supports' too) and both points.
    #[test]
    fn an_adjoint_over_many_inputs_is_one_solve_and_the_columns_transpose() {
        let spec = ParallelArch::default();
        let mut model = spec.model().unwrap();
        let frame_node = (0..model.nodes.len())
            .find(|&n| model.groups.iter().any(|g| g.nodes.contains(&n)))
            .unwrap();
        let free_node = (0..model.nodes.len())
            .find(|&n| {
                model.groups.iter().all(|g| !g.nodes.contains(&n))
                    && model.supports.iter().all(|s| s.node != n)
            })
            .unwrap();
        for (name, node) in [("free", free_node), ("edge", frame_node)] {
            let name = name.to_string();
            model
                .outputs
                .points
                .push(crate::mech::model::OutputPoint { name, node });
        }
        let targets: Vec<_> = (1..=12)
            .map(|k| spec.boundary_targets(&model, k as f64 / 30.0))
            .collect();
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        a.set_friction(0.2).unwrap();
        for (k, t) in targets.iter().enumerate() {
            if k == 10 {
                a.set_friction(9.9).unwrap();
            }
            a.step_to(t, 1).unwrap();
        }
        assert!(a.results().gaps.iter().all(|g| g.status != GapStatus::Slip));
        let mut weights = OutputWeights::zero(&a);
        let mut x = 0.37_f64;
        let mut next = || {
            x = (x * 997.0 + 0.13).fract();
            2.0 * x - 1.0
        };
        for w in (weights.reactions.iter_mut())
            .chain(&mut weights.supports)
            .chain(&mut weights.points)
            .chain([&mut weights.total])
        {
            *w = [next(), next(), next()];
        }
        let mut seeds = vec![mu(&a)];
        for g in 0..weights.reactions.len() {
            for c in 0..3 {
                let mut s = Seed::zero(&a);
                s.translation[g][c] = 1.0;
                seeds.push(s);
            }
        }
        let before = a.tangent_solves();
        let adjoint = a.adjoint_response(&weights, &seeds).unwrap();
        assert_eq!(a.tangent_solves(), before + 1, "{} inputs", seeds.len());
        let prescribed = |a: &Analysis, g: usize, c: usize| {
            a.system
                .dofs
                .iter()
                .any(|d| matches!(*d, Dof::Prescribed { group, component } if (group, component) == (g, c)))
        };
        let mut largest = 0.0_f64;
        let mut columns = vec![];
        for s in &seeds {
            let r = a.linear_response(s).unwrap();
            let mut v = 0.0;
            for (g, w) in weights.reactions.iter().enumerate() {
                for c in (0..3).filter(|&c| prescribed(&a, g, c)) {
                    v += w[c] * r.derivative(|x| x.reactions[g][c]);
                }
            }
            for (p, w) in weights.points.iter().enumerate() {
                for c in 0..3 {
                    v += w[c] * r.derivative(|x| x.points[p][c]);
                }
            }
            for (set, w) in weights.supports.iter().enumerate() {
                for c in 0..3 {
                    v += w[c] * r.derivative(|x| x.support_reactions[set][c]);
                }
            }
            for c in 0..3 {
                v += weights.total[c] * r.derivative(|x| x.total_reaction[c]);
            }
            largest = largest.max(v.abs());
            columns.push(v);
        }
        let worst = worst_relative(&adjoint, &columns);
        eprintln!(
            "{} inputs: adjoint vs columns {worst:e} of the largest",
            seeds.len()
        );
        for (k, (adj, col)) in adjoint.iter().zip(&columns).enumerate() {
            assert!(
                (adj - col).abs() <= 1e-6 * largest,
                "input {k}: adjoint {adj} vs columns {col} (largest {largest})"
            );
        }
    }

    /// The one-solve adjoint of a support set's and a hinged group's reactions (issue 45).
    /// MODEL: `examples/hinged_panel.json` (the hinged group `rail`, the support set `frame`, no
    /// contacts: a symmetric tangent), `rail.dz` to −5 mm and `rail.angle` to 0.01 rad in one
    /// step. TEST GOAL: `vᵀ J` of the rail's, the frame's and the total reactions over the rail's
    /// translations and angle is one solve, and `vᵀ` times J's columns to 1e-6.
    #[test]
    fn an_adjoint_of_support_set_and_hinged_group_reactions_is_one_solve() {
        let model = Model::from_json(include_str!("../../../examples/hinged_panel.json")).unwrap();
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        let loads = a.state().loads.clone();
        a.step_to_motion(&[[0.0, 0.0, -0.005]], &[0.01], &loads, 2)
            .unwrap();
        let mut weights = OutputWeights::zero(&a);
        assert_eq!(weights.supports.len(), 1);
        weights.reactions[0] = [0.4, -0.9, 1.3];
        weights.supports[0] = [-0.6, 0.8, 0.5];
        weights.total = [0.2, 0.3, -0.7];
        let mut seeds = vec![];
        for c in 0..3 {
            let mut s = Seed::zero(&a);
            s.translation[0][c] = 1.0;
            seeds.push(s);
        }
        let mut s = Seed::zero(&a);
        s.angles[0] = 1.0;
        seeds.push(s);
        let before = a.tangent_solves();
        let adjoint = a.adjoint_response(&weights, &seeds).unwrap();
        assert_eq!(a.tangent_solves(), before + 1);
        let columns: Vec<f64> = seeds
            .iter()
            .map(|s| {
                let r = a.linear_response(s).unwrap();
                (0..3)
                    .map(|c| {
                        weights.supports[0][c] * r.derivative(|x| x.support_reactions[0][c])
                            + weights.total[c] * r.derivative(|x| x.total_reaction[c])
                            + weights.reactions[0][c] * r.derivative(|x| x.reactions[0][c])
                    })
                    .sum()
            })
            .collect();
        let largest = columns.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        assert!(largest > 0.0);
        for (adj, col) in adjoint.iter().zip(&columns) {
            assert!(
                (adj - col).abs() <= 1e-6 * largest,
                "{adjoint:?} vs {columns:?}"
            );
        }
    }

    /// The largest difference of `adjoint` from `columns`, relative to the largest column
    /// (which must not be 0).
    pub(super) fn worst_relative(adjoint: &[f64], columns: &[f64]) -> f64 {
        let largest = columns.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(largest > 0.0);
        adjoint
            .iter()
            .zip(columns)
            .fold(0.0_f64, |m, (a, c)| m.max((a - c).abs() / largest))
    }

    /// Pseudo-random weights in [−1, 1] on every output a one-solve adjoint takes: each group's
    /// reactions, each support set's, the total reaction and each output point's displacement.
    pub(super) fn every_weight(a: &Analysis) -> OutputWeights {
        let mut weights = OutputWeights::zero(a);
        let mut x = 0.37_f64;
        for w in (weights.reactions.iter_mut())
            .chain(&mut weights.supports)
            .chain(&mut weights.points)
            .chain([&mut weights.total])
            .flatten()
        {
            x = (x * 997.0 + 0.13).fract();
            *w = 2.0 * x - 1.0;
        }
        weights
    }

    /// `vᵀ y`: the outputs of `r` weighted by `weights`.
    pub(in crate::mech::solve::sensitivity) fn weighted(
        weights: &OutputWeights,
        r: &Results,
    ) -> f64 {
        let dot = |w: &[[f64; 3]], y: &[[f64; 3]]| -> f64 {
            w.iter()
                .zip(y)
                .map(|(w, y)| (0..3).map(|c| w[c] * y[c]).sum::<f64>())
                .sum()
        };
        dot(&weights.reactions, &r.reactions)
            + dot(&weights.supports, &r.support_reactions)
            + dot(&[weights.total], &[r.total_reaction])
            + dot(&weights.points, &r.points)
    }

    /// `(Jᵀ v)ᵀ s` of the one-solve adjoint for every seed `s`, `v` = `weights`: asserts that
    /// the adjoint is one solve with one factorization and its transpose solve on the factor's
    /// own path (no LU), and returns its largest difference from `vᵀ (J s)` of J's columns
    /// (each a linear response: a fourth-order difference of the results along it) and from
    /// `vᵀ (J s)` linearized of the same parts as the adjoint (a forward solve with the held
    /// factor instead of the transpose solve), each relative to the largest.
    pub(super) fn adjoint_against_columns(
        a: &mut Analysis,
        seeds: &[Seed],
        weights: &OutputWeights,
    ) -> (f64, f64) {
        let (solves, p) = (a.tangent_solves(), a.solve_profile());
        let adjoint = a.adjoint_response(weights, seeds).unwrap();
        let q = a.solve_profile();
        assert_eq!(a.tangent_solves(), solves + 1, "{} inputs", seeds.len());
        assert_eq!(q.ldlt_count + q.lu_count, p.ldlt_count + p.lu_count + 1);
        assert_eq!(
            q.held_solves,
            p.held_solves + 1,
            "the transpose on the held factor"
        );
        let forward: Vec<f64> = seeds
            .iter()
            .map(|s| a.forward_weighted(weights, s))
            .collect();
        let columns: Vec<f64> = seeds
            .iter()
            .map(|s| {
                a.linear_response(s)
                    .unwrap()
                    .derivative(|x| weighted(weights, x))
            })
            .collect();
        let worst = worst_relative(&adjoint, &columns);
        let transposed = worst_relative(&adjoint, &forward);
        eprintln!(
            "{} inputs, path {:?}: adjoint vs columns {worst:e}, vs forward {transposed:e} of \
             the largest",
            seeds.len(),
            (
                q.woodbury_count - p.woodbury_count,
                q.gmres_count - p.gmres_count
            ),
        );
        (worst, transposed)
    }

    impl Analysis {
        /// `vᵀ (J s)` of the same parts as [`Analysis::adjoint_response`] (the seed's residual
        /// difference, the reactions' assembled rows `K_rf`), with the forward solve
        /// `K_ff du = −∂g_f/∂q s` on the held factor in place of the adjoint's transpose solve.
        pub(super) fn forward_weighted(&mut self, weights: &OutputWeights, seed: &Seed) -> f64 {
            let (start, end) = self.derivative_states(seed).unwrap();
            let Some(largest) = self.seed_scale(&end, seed).unwrap() else {
                return 0.0;
            };
            let (du, dg) = self.seed_residual(&start, &end, seed, 1e-6 / largest);
            let mut x: Vec<f64> = (self.system.dofs.iter().zip(&dg))
                .filter(|(d, _)| matches!(d, Dof::Free(_)))
                .map(|(_, g)| -g)
                .collect();
            self.solve_with_tangent(&start, &end, &mut x, false)
                .unwrap();
            let restrained = self.restrained_weights(weights);
            let rows = self
                .restrained_rows_transposed(&start, &end, &restrained)
                .unwrap();
            let mut value = rows.iter().zip(&x).map(|(w, x)| w * x).sum::<f64>();
            for (i, d) in self.system.dofs.iter().enumerate() {
                if !matches!(d, Dof::Free(_)) {
                    value += restrained[i] * dg[i];
                }
            }
            for (point, weight) in self.model.outputs.points.iter().zip(&weights.points) {
                for (c, w) in weight.iter().enumerate() {
                    let i = 3 * point.node + c;
                    value += w * match self.system.dofs[i] {
                        Dof::Free(f) => x[f],
                        _ => du[i],
                    };
                }
            }
            self.state = end;
            value
        }
    }

    /// Output points `p0`, `p1`, … on every seventh film node (neither in a group nor supported).
    pub(super) fn add_film_points(model: &mut Model) {
        let film: Vec<usize> = (0..model.nodes.len())
            .filter(|&n| {
                model.groups.iter().all(|g| !g.nodes.contains(&n))
                    && model.supports.iter().all(|s| s.node != n)
            })
            .step_by(7)
            .collect();
        for (k, &node) in film.iter().enumerate() {
            let name = format!("p{k}");
            model
                .outputs
                .points
                .push(crate::mech::model::OutputPoint { name, node });
        }
    }

    /// `first`, then a unit seed along each of every group's translations.
    pub(super) fn with_translations(a: &Analysis, first: Seed) -> Vec<Seed> {
        let mut seeds = vec![first];
        for g in 0..a.state().boundary.len() {
            for c in 0..3 {
                let mut s = Seed::zero(a);
                s.translation[g][c] = 1.0;
                seeds.push(s);
            }
        }
        seeds
    }

    /// The adjoint of an unsymmetric tangent (issue 45): a slipping gap. MODEL: the specimen
    /// lowered three twentieths with μ = 0.5 before the last step, under each friction law,
    /// output points on every seventh film node, weights on them and on every reaction. TEST
    /// GOAL: `vᵀ(J s) = (Jᵀ v)ᵀ s` to [`COLUMNS`] of the largest over μ and every group's
    /// translations (and to [`TRANSPOSED`] solved forward), the adjoint one transpose solve.
    #[test]
    fn an_adjoint_under_a_slipping_gap_transposes_the_columns_in_one_solve() {
        for law in FrictionLaw::ALL {
            let spec = ParallelArch {
                friction_law: law,
                ..ParallelArch::default()
            };
            let mut model = spec.model().unwrap();
            add_film_points(&mut model);
            let targets: Vec<_> = (1..=3)
                .map(|k| spec.boundary_targets(&model, 0.05 * k as f64))
                .collect();
            let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
            for (k, t) in targets.iter().enumerate() {
                if k == 2 {
                    a.set_friction(0.5).unwrap();
                }
                a.step_to(t, 1).unwrap();
            }
            let slipping = a.results().gaps.iter().any(|g| g.status == GapStatus::Slip);
            assert!(slipping, "{law:?}: a gap slips");
            let seeds = with_translations(&a, mu(&a));
            let weights = every_weight(&a);
            let (worst, transposed) = adjoint_against_columns(&mut a, &seeds, &weights);
            assert!(
                a.held_tangent_symmetric().is_err(),
                "an unsymmetric tangent"
            );
            assert!(worst <= COLUMNS, "{law:?}: {worst:e}");
            assert!(transposed <= TRANSPOSED, "{law:?}: {transposed:e}");
        }
    }

    /// The adjoint of an unsymmetric tangent (issue 45): a follower pressure. MODEL:
    /// `examples/cushion.json` with its pressure on the upper film's first 192 triangles only
    /// (over the whole closed cushion the load stiffness is symmetric: the edge terms of the
    /// loaded region cancel), at 200 Pa in four increments, its two output points. TEST GOAL:
    /// `vᵀ(J s) = (Jᵀ v)ᵀ s` to [`COLUMNS`] of the largest over the pressure and the group's
    /// translations (and to [`TRANSPOSED`] solved forward), the adjoint one transpose solve.
    #[test]
    fn an_adjoint_under_a_follower_pressure_transposes_the_columns_in_one_solve() {
        let part = format!("\"elements\": {:?}", (0..192).collect::<Vec<usize>>());
        let json =
            include_str!("../../../examples/cushion.json").replace("\"elements\": \"all\"", &part);
        let model = Model::from_json(&json).unwrap();
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        let mut levels = a.state().loads.clone();
        levels.pressure[0] = 200.0;
        let target = a.state().boundary.clone();
        a.step_to_with_loads(&target, &levels, 4).unwrap();
        let mut pressure = Seed::zero(&a);
        pressure.pressure[0] = 1.0;
        let seeds = with_translations(&a, pressure);
        // The points alone: the rim is the only restraint, so its translations move the cushion
        // rigidly and the reactions' columns along them are the rounding of the reactions over
        // the difference's step (7e-3 of the largest), where the adjoint has 2e-6; reactions
        // under a follower pressure are checked on the specimen (`adjoint_tests.rs`).
        let mut weights = every_weight(&a);
        weights.reactions.iter_mut().for_each(|w| *w = [0.0; 3]);
        weights.total = [0.0; 3];
        let (worst, transposed) = adjoint_against_columns(&mut a, &seeds, &weights);
        assert!(
            a.held_tangent_symmetric().is_err(),
            "an unsymmetric tangent"
        );
        assert!(worst <= COLUMNS, "{worst:e}");
        assert!(transposed <= TRANSPOSED, "{transposed:e}");
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
        a.solve_with_tangent(&start, &end, &mut du, false).unwrap();
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
