//! The mechanics core: membrane finite elements with friction gap elements (the reference
//! paper's method). It knows nothing of FMI, holds no global state and does no I/O.
//!
//! | module | what |
//! |---|---|
//! | [`element`] | CST membrane triangle, eqs. (2.2)–(2.7) |
//! | [`material`] | film law, eq. (2.3), and its tension-field (wrinkling) option |
//! | [`cable`] | tension-only edge cables (2-node truss segments along triangle edges) |
//! | [`contact`] | friction gap element, eqs. (2.8), (2.9), (2.13) |
//! | [`finite`] | finiteness check of reported results |
//! | [`model`] | model file format and validation |
//! | [`load`] | follower pressure, self-weight, nodal forces and their load stiffness |
//! | [`restraint`] | rigid-body modes no restraint holds (singular models), found at validation |
//! | [`assembly`] | DOF numbering, sparsity pattern, scatter (eq. 2.11) |
//! | [`linear`] | sparse LDLᵀ / LU with a reused symbolic analysis |
//! | [`solver`] | Newton–Raphson with increments and cut-backs (eqs. 2.11–2.12, §3) |
//! | [`summary`] | output points and field summaries over element sets |
//! | [`lines`] | reactions per unit length along boundary groups and support sets |
//! | [`specimen`] | the parallel-arch specimens of §4 and every assumption about them |
//! | [`scenarios`] | load-path generators (specimen family, arch panel, cylinder strip, arch edge) |
//! | [`vtk`] | VTK text of the deformed film and its stresses (Fig. 6) |

pub mod assembly;
pub mod cable;
pub mod contact;
pub mod element;
pub mod finite;
pub mod linear;
pub mod lines;
pub mod load;
pub mod material;
pub mod model;
pub mod plasticity;
pub mod restraint;
pub mod scenarios;
pub mod solver;
pub mod specimen;
pub mod summary;
pub mod surface;
pub mod vtk;

pub use contact::{FrictionLaw, GapStatus, IterationMatrix};
pub use finite::check_results;
pub use load::LoadLevels;
pub use material::{Material, Wrinkling, WrinklingState};
pub use model::{Model, ModelError};
pub use solver::{
    Analysis, AnalysisState, Results, SettingNames, SolverSettings, StepError, StepReport,
};
pub use specimen::ParallelArch;
