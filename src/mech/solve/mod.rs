//! Solving: the DOF map and assembly, the linear solvers, and the Newton–Raphson analysis with
//! increments and cut-backs (eqs. 2.11–2.12, procedure §3).
//!
//! | file | what |
//! |---|---|
//! | [`assembly`] | DOF numbering, sparsity pattern, scatter (eq. 2.11) |
//! | [`contributions`] | the [`Contribution`](contributions::Contribution) trait: residual, tangent and history of each kind (triangles, gaps, loads, cables, curved contacts, chambers) |
//! | [`linear`] | sparse LDLᵀ / Woodbury / GMRES / LU with a reused symbolic analysis |
//! | `low_rank` | the chambers' pneumatic stiffness by Sherman–Morrison–Woodbury; sealing the chambers |
//! | [`analysis`] | [`Analysis`]: setup, state, steps and their input checks |
//! | `inputs` | checks of a step's targets, angles and load levels; prescribed values |
//! | `increments` | the increment controller (Ramm's rule, cut-back), the strategy table, the predictor |
//! | `newton` | one increment: semismooth Newton on the laws' equations |
//! | `continuation` | its globalization: pseudo-transient continuation (SER) |
//! | [`progress`] | [`IncrementNote`]: each increment as it ends, for a front end's log |
//! | [`settings`] | [`SolverSettings`] |
//! | [`state`] | [`AnalysisState`], the converged state an FMU state serializes |
//! | [`report`] | [`StepReport`], [`IncrementFailure`] and its advice, [`StepError`], [`SetupError`] |
//! | `sensitivity` | [`Analysis::linear_response`]: the converged state's linear response to a [`Seed`] (the FMU's directional derivatives) |

pub mod analysis;
mod arc_length;
pub mod assembly;
mod continuation;
pub mod contributions;
mod increments;
mod inputs;
pub mod linear;
mod low_rank;
mod newton;
pub mod progress;
pub mod report;
mod sensitivity;
pub mod settings;
pub mod state;

pub use analysis::Analysis;
pub use increments::{Control, STRATEGIES, Strategy};
pub use newton::max_abs;
pub use progress::{IncrementNote, IncrementObserver};
pub use report::{
    Attempt, DISSIPATION_BOUND, IncrementFailure, IterationRecord, STABILIZATION_BOUND,
    SettingNames, SetupError, StepError, StepReport,
};
pub use sensitivity::{OutputWeights, Response, Seed};
pub use settings::{DEFAULT_INCREMENTS_PER_STEP, MAX_THREADS, SolverSettings};
pub use state::AnalysisState;
