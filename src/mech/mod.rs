//! The mechanics core: membrane finite elements with friction gap elements (the reference
//! paper's method). It knows nothing of FMI, holds no global state and does no I/O.
//!
//! The folders read like the method, and depend on each other one way, top to bottom:
//!
//! | folder | what |
//! |---|---|
//! | [`model`] | the model file's format, its validation, the restraint check |
//! | [`elements`] | what adds force and stiffness: membrane triangle and its film law, cables, gaps, curved-support contact, external loads |
//! | [`formfinding`] | the prestressed shape: force density first shape, updated reference strategy |
//! | [`patterning`] | cutting patterns: strips, flattening, distortion, compensation, outlines |
//! | [`solve`] | DOF map and assembly, the linear solvers, Newton, line search, increment control |
//! | [`results`] | results of a converged state: summaries, reaction lines, finiteness, VTK |

pub mod elements;
pub mod formfinding;
pub mod model;
pub mod patterning;
pub mod results;
pub mod solve;

pub use elements::gap::{FrictionLaw, GapStatus, IterationMatrix};
pub use elements::load::LoadLevels;
pub use elements::material::{Material, Wrinkling, WrinklingState};
pub use model::{Model, ModelError};
pub use results::Results;
pub use results::finite::check_results;
pub use solve::{
    Analysis, AnalysisState, OutputWeights, Response, Seed, SettingNames, SolverSettings,
    StepError, StepReport,
};
