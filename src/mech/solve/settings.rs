//! Newton and increment-control settings of an analysis, and their validation.

use serde::{Deserialize, Serialize};

use crate::mech::elements::gap::IterationMatrix;

/// Newton and increment-control settings.
///
/// Convergence (every criterion on the residual of the true friction law, never of a frozen or
/// modified one) needs both
/// * `‖ΔU‖∞ ≤ displacement_tolerance · U_ref`, `U_ref = max(‖U − U_start‖∞, ‖U‖∞, 1e-9·L)`: the
///   last correction is small against the displacements (paper §3(g)); `L` is the model's
///   bounding-box diagonal;
/// * `‖R_free‖∞ ≤ residual_tolerance · F_ref`, `F_ref = max(‖R_all‖∞, 1e-6·E·t·L)`: the largest
///   out-of-balance force is small against the largest nodal force of the model (the reactions
///   and gap forces; the floor is the membrane's own force scale, for unloaded states).
///
/// Both are scaled by the model, so the same defaults serve a 1 N strip and a 10 kN roof.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSettings {
    /// Which matrix drives the iterations.
    pub iteration_matrix: IterationMatrix,
    /// Relative tolerance of the last displacement correction (see the type's doc).
    pub displacement_tolerance: f64,
    /// Relative tolerance of the out-of-balance force (see the type's doc).
    pub residual_tolerance: f64,
    /// Newton iterations per increment before the increment is cut back. A stalled or
    /// diverging iteration is cut back earlier (see [`IncrementFailure`](super::IncrementFailure)).
    pub max_iterations: usize,
    /// How many times an increment may be halved before the step fails.
    pub max_cutbacks: usize,
    /// Factorize a consistent tangent that is symmetric (no slipping gap, no follower pressure)
    /// by LDLᵀ instead of LU (`solve/linear`); false: always LU.
    pub symmetric_factorization: bool,
    /// The viscous stabilization's rows of the strategy table (`increments.rs`) for the rest of
    /// a step whose smallest increment Newton refused; its work is reported and judged against
    /// the strain energy. false: the first two rows only, Newton and arc-length (the stabilization-free answer).
    pub stabilization: bool,
    /// Threads of the element assembly and of the LDLᵀ factorizations (each scoped: none
    /// outlives a call); 0 = automatic: the assembly one below
    /// [`PARALLEL_MIN_TRIANGLES`](crate::mech::solve::assembly::PARALLEL_MIN_TRIANGLES)
    /// triangles, else one per
    /// [`TRIANGLES_PER_THREAD`](crate::mech::solve::assembly::TRIANGLES_PER_THREAD) up to the
    /// idle cores ([`idle_cores`](crate::mech::solve::assembly::idle_cores): the available
    /// ones less the load average of other processes); the factorization one below
    /// [`PARALLEL_MIN_FACTOR`](crate::mech::solve::linear::PARALLEL_MIN_FACTOR) factor values,
    /// else the idle cores. Studies set 1 per worker. Results are bit-identical for every count.
    pub threads: usize,
}

/// Default of the smallest number of increments a step is cut into (the largest increment is
/// this fraction of a step; the controller cuts further where Newton needs it): the CLI's
/// `--increments` and the FMU's `solver.incrementsPerStep` both start from it, so that a CLI
/// check predicts an FMU run with default parameters.
pub const DEFAULT_INCREMENTS_PER_STEP: usize = 1;

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            iteration_matrix: IterationMatrix::default(),
            displacement_tolerance: 1e-5,
            residual_tolerance: 1e-5,
            max_iterations: 100,
            max_cutbacks: 12,
            symmetric_factorization: true,
            stabilization: true,
            threads: 0,
        }
    }
}

impl SolverSettings {
    /// Checks the settings (tolerances in (0, 1), at least one iteration).
    pub fn validate(&self) -> Result<(), String> {
        let ok = |v: f64| v > 0.0 && v < 1.0;
        if !ok(self.displacement_tolerance) || !ok(self.residual_tolerance) {
            return Err(format!(
                "tolerances ({:e}, {:e}) must lie in (0, 1): they are relative to the model's displacement and force scales",
                self.displacement_tolerance, self.residual_tolerance
            ));
        }
        if self.max_iterations == 0 {
            return Err("max_iterations must be at least 1".into());
        }
        if self.max_cutbacks > 60 {
            return Err("max_cutbacks must be at most 60".into());
        }
        if self.threads > MAX_THREADS {
            return Err(format!(
                "threads = {} must be at most {MAX_THREADS} (0: automatic)",
                self.threads
            ));
        }
        Ok(())
    }
}

/// Most assembly threads [`SolverSettings::threads`] accepts.
pub const MAX_THREADS: usize = 256;
