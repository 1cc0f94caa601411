//! Load-path generators: the models and load paths users try (issue 7), each deterministic from a
//! few parameters, and the sampling grid of the robustness benchmark (`benches/robustness.rs`).
//!
//! A [`Scenario`] is a validated [`Model`] plus a [`LoadPath`]: stages, each a target for every
//! boundary group reached in a number of communication steps (targets interpolated linearly
//! within a stage, as the CLI and a ramping master do), optionally with `μ` for the stage, and
//! what the stage does with the gas chambers ([`Air`]: supplies ramped, or the air sealed).
//! [`Scenario::run`] drives [`Analysis::step_to`] once per communication step, as the FMU does,
//! and records per step: converged or the error text, Newton iterations, increments, cut-backs.
//!
//! # Families
//!
//! **Specimen** ([`SpecimenPath`]): the paper's 1/4 parallel-arch specimen ([`ParallelArch`](crate::specimens::ParallelArch))
//! with the frame driven down to a depth (up to `−H`), down–up–down (reversal), down then pulled
//! in plane (`dx`, `dy` of the frame), or down and back to 0 (unloading).
//!
//! **Panel over two arches** ([`ArchPanel`]): a 3 m × 2 m film laid flat at crown height over two
//! parallel circular arches, one edge clamped, the opposite edge jacked down about a hinge at its
//! corner. Groups only translate, so every node of the jacked edge is its own group `J<j>` whose
//! target follows the rotation ([`ArchPanel::jack_targets`]).
//!
//! ```text
//!   y (m)                                         z
//!   2.0  +----+---------+---------+----+ J24       ^   jacked edge, seen along x:
//!        |    |         |         |    |           |   J0 ---- J12 ---- J24   (θ = 0, z = H)
//!   1.75 |    o AL19    o AR19    |    |           |   J0 ·.
//!        |    o         o         |    |           |         ·. J12
//!  clamp |    o  arch   o  arch   |    | jack      |               ·. J24    (rotated by θ about
//!  (xyz) |    o         o         |    | groups    |                        the x axis through J0)
//!   0.25 |    o AL1     o AR1     |    | J0..J24   +---------------------> y
//!        |    |         |         |    |
//!   0.0  +----+---------+---------+----+ J0 = hinge      arch (in the plane x = 1 or 2):
//!       x=0  x=1       x=2       x=3                     crown z = H at y = 1, feet z = 0 at
//!   structured mesh 15r × 12r cells (r = 2: 1 440 triangles), gaps on the  y = 1 ∓ span/2;
//!   film nodes above each arch (19 + 19 = 38 for the default span 1.5 m); edges y = 0, 2 free
//! ```
//!
//! **Strip over a half cylinder** ([`CylinderStrip`], reproduction 4): an unstressed strip lying
//! on the upper half of a cylinder (axis along `y`), with a one-cell straight leg hanging from
//! each foot; every node on the half circle has a gap to the cylinder (`g0 = 0`: touching, open),
//! and pulling both leg ends down (and out) closes all of them in the first step.
//!
//! ```text
//!            ___o___o___
//!         o/  2 rows of  \o        o: film node with a gap (both rows: 2 × 19 = 38)
//!        o  cylinder R    o
//!        o       +        o  z = 0 (axis, along y)
//!        |                |  one-cell legs
//!    left *              * right   groups pulled (∓out, 0, −down)
//! ```
//!
//! **Film edge on an arch** ([`ArchEdge`], reproduction 5): a film whose free edge lies on an
//! arch (the arch's profile extruded sideways, gaps with `g0 = 0` on every edge node from crown
//! to foot), prestressed along the arch only (none across the edge, which is free); the far
//! edge and the foot line are the frame, lowered.
//!
//! **Wrapped specimen** ([`WrappedSpecimen`], issue 10): the specimen wound onto the arch from
//! crown to foot and its boundary extended by `ε` (`FramePath::Wrapped`), one step per stage of
//! the non-linear frame path; gaps or curved supports; optionally released back to the wound
//! film (the extension retraced).
//!
//! **Plastic** ([`plastic_paths`], issue 20): ETFE's elasto-plastic film (the data-sheet curve)
//! on the specimens lowered at every height and wrapped then partly released, on circular
//! cushions inflated past yield and deflated, and on panels jacked and released.
//!
//! **Cushion** ([`cushion_paths`], issue 43): a three-layer circular cushion ([`LayeredCushion`]:
//! top, perforated middle, bottom) inflated by a supply, its air sealed, snow on the top raised
//! until the top inverts onto the middle layer (frictional layer contact), then removed.
//!
//! **Circular membrane** ([`CircularMembrane`], issue 8): a flat disc meshed in rings (the
//! centre, then `6k` nodes on ring `k`), its rim a boundary group `rim` held at zero (so the FMU
//! reports the rim reaction), a pressure set `top` on every triangle (normals +Z). Hencky's
//! clamped membrane under pressure, and the FMU's pressure example.
//!
//! # Assumptions
//!
//! The issue's gmsh panel and strip files are not available: the panel and the strip above are
//! this module's reconstructions (same sizes, triangle and gap counts). Film, penalties and
//! friction are the specimen's ([`ParallelArch::default`](crate::specimens::ParallelArch::default), assumptions in `parallel_arch.rs`).
//!
//! # Files
//!
//! | file | what |
//! |---|---|
//! | `mod.rs` | [`Scenario`], [`LoadPath`], [`Stage`], [`Family`], run outcomes |
//! | `arc` | gaps on a circular arc ([`gaps_on_arc`]), grid helpers shared by the meshes |
//! | `specimen` | [`SpecimenPath`], [`PathShape`], [`WrappedSpecimen`] |
//! | `panel` | [`ArchPanel`] |
//! | `strip` | [`CylinderStrip`] |
//! | `edge` | [`ArchEdge`] |
//! | `membrane` | [`CircularMembrane`] |
//! | `cushion` | [`LayeredCushion`], [`cushion_paths`] |
//! | `grid` | the robustness benchmark's grid ([`robustness_grid`], [`grid_slice`]) |

use std::fmt;

use crate::mech::elements::load::LoadLevels;
use crate::mech::model::Model;
use crate::mech::solve::{Analysis, SolverSettings, StepError};

mod arc;
mod cushion;
mod edge;
mod grid;
mod membrane;
mod panel;
mod specimen;
mod sphere;
mod strip;

pub use arc::{CircularSupport, GapConstants, gaps_on_arc};
pub use cushion::{LayeredCushion, cushion_paths};
pub use edge::ArchEdge;
pub use grid::{grid_slice, plastic_paths, robustness_grid};
pub use membrane::CircularMembrane;
pub use panel::ArchPanel;
pub use specimen::{PathShape, SpecimenPath, WrappedSpecimen};
pub use sphere::InflatedSphere;
pub use strip::CylinderStrip;

// ------------------------------------------------------------------------------- load paths

/// One stage of a load path: every group moves linearly to `targets` in `steps` steps (and the
/// pressures to `pressure`).
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    /// Target displacement of every boundary group at the end of the stage (m).
    pub targets: Vec<[f64; 3]>,
    /// Communication steps (one `step_to` each) of the stage.
    pub steps: usize,
    /// Friction coefficient of every gap from this stage on (`None`: unchanged).
    pub friction: Option<f64>,
    /// Pressure of every pressure set at the end of the stage (Pa, model order; `None`: kept).
    pub pressure: Option<Vec<f64>>,
    /// What the stage does with the model's gas chambers.
    pub air: Air,
}

/// What a [`Stage`] does with the model's gas chambers (issue 43).
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Air {
    /// Nothing: supplies keep their pressure, enclosed gas stays enclosed.
    #[default]
    Kept,
    /// Every chamber's supply ramped to these pressures (Pa, model order) over the stage.
    Supplied(Vec<f64>),
    /// Every chamber's gas enclosed at the start of the stage, at the converged state
    /// ([`Analysis::seal_chambers`]).
    Sealed,
}

/// A load path: stages from the unloaded state, and the increments of every step.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadPath {
    /// Stages in order; the first starts from zero displacement.
    pub stages: Vec<Stage>,
    /// Increments per communication step given to `step_to` (the FMU's
    /// `solver.incrementsPerStep` and the CLI's `--increments` default to
    /// [`crate::mech::solve::DEFAULT_INCREMENTS_PER_STEP`]).
    pub increments_per_step: usize,
}

impl LoadPath {
    /// Total communication steps.
    pub fn steps(&self) -> usize {
        self.stages.iter().map(|s| s.steps).sum()
    }
}

/// The family a scenario belongs to (the benchmark's rows).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Family {
    /// [`SpecimenPath`].
    Specimen,
    /// [`ArchPanel`].
    Panel,
    /// [`CylinderStrip`].
    Strip,
    /// [`ArchEdge`].
    ArchEdge,
    /// [`WrappedSpecimen`].
    Wrapped,
    /// ETFE's elasto-plastic film ([`plastic_paths`]): specimens, cushions, panels.
    Plastic,
    /// Three-layer cushions with sealed air under snow ([`cushion_paths`]).
    Cushion,
}

impl Family {
    /// Every family, in table order.
    pub const ALL: [Family; 7] = [
        Self::Specimen,
        Self::Panel,
        Self::Strip,
        Self::ArchEdge,
        Self::Wrapped,
        Self::Plastic,
        Self::Cushion,
    ];

    /// Short name (the benchmark's `--family` filter).
    pub fn name(self) -> &'static str {
        match self {
            Self::Specimen => "specimen",
            Self::Panel => "panel",
            Self::Strip => "strip",
            Self::ArchEdge => "arch-edge",
            Self::Wrapped => "wrapped",
            Self::Plastic => "plastic",
            Self::Cushion => "cushion",
        }
    }
}

impl fmt::Display for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A model and the load path to run on it.
#[derive(Clone, Debug)]
pub struct Scenario {
    /// Family of the generator.
    pub family: Family,
    /// Name with the generating parameters.
    pub name: String,
    /// The validated model.
    pub model: Model,
    /// The load path.
    pub path: LoadPath,
}

/// What happened in one communication step.
#[derive(Clone, Debug, PartialEq)]
pub struct StepOutcome {
    /// Stage index (0-based).
    pub stage: usize,
    /// Step within the stage (1-based).
    pub step: usize,
    /// Newton iterations of the converged increments.
    pub iterations: usize,
    /// Most Newton iterations of one converged increment.
    pub max_increment_iterations: usize,
    /// Converged increments.
    pub increments: usize,
    /// Halved increments.
    pub cutbacks: usize,
    /// Increments solved with the viscous stabilization on.
    pub stabilized: usize,
    /// Whether the artificial energy left exceeds `STABILIZATION_BOUND` of the strain energy.
    pub over_bound: bool,
    /// `‖R_free‖∞` at the converged end of the step (N; 0 for a refused step).
    pub residual: f64,
    /// The error text when the step was refused.
    pub error: Option<String>,
}

/// The record of a run: one entry per attempted step; a run stops at its first refused step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunOutcome {
    /// Steps attempted, in order.
    pub steps: Vec<StepOutcome>,
    /// The analysis could not be set up (the model or settings were refused).
    pub setup_error: Option<String>,
}

impl RunOutcome {
    /// Whether every step of the path converged.
    pub fn converged(&self) -> bool {
        self.setup_error.is_none() && self.steps.iter().all(|s| s.error.is_none())
    }

    /// The refused step, if any.
    pub fn failure(&self) -> Option<&StepOutcome> {
        self.steps.iter().find(|s| s.error.is_some())
    }

    /// A one-line description of the failure (`None` when converged).
    pub fn failure_message(&self) -> Option<String> {
        if let Some(e) = &self.setup_error {
            return Some(format!("setup: {e}"));
        }
        let s = self.failure()?;
        let number = self.steps.iter().position(|t| std::ptr::eq(t, s))? + 1;
        Some(format!(
            "step {number} (stage {}, step {}): {}",
            s.stage + 1,
            s.step,
            s.error.as_deref().unwrap_or("")
        ))
    }

    /// Newton iterations of all converged increments.
    pub fn iterations(&self) -> usize {
        self.steps.iter().map(|s| s.iterations).sum()
    }

    /// Converged increments.
    pub fn increments(&self) -> usize {
        self.steps.iter().map(|s| s.increments).sum()
    }

    /// Cut-backs (including those of a refused step).
    pub fn cutbacks(&self) -> usize {
        self.steps.iter().map(|s| s.cutbacks).sum()
    }

    /// Increments solved with the viscous stabilization on, over all steps.
    pub fn stabilized(&self) -> usize {
        self.steps.iter().map(|s| s.stabilized).sum()
    }

    /// Whether every step converged within the stabilization bound.
    pub fn within_bound(&self) -> bool {
        self.converged() && self.steps.iter().all(|s| !s.over_bound)
    }

    /// Most Newton iterations of one converged increment.
    pub fn max_increment_iterations(&self) -> usize {
        self.steps
            .iter()
            .map(|s| s.max_increment_iterations)
            .max()
            .unwrap_or(0)
    }
}

impl Scenario {
    /// Runs the load path with `settings`: one [`Analysis::step_to`] per communication step with
    /// the path's increments per step, `μ` set at the start of a stage that gives one. Stops at
    /// the first refused step (the FMU would return `fmi2Discard` there).
    pub fn run(&self, settings: SolverSettings) -> RunOutcome {
        self.run_observed(settings, |_, _| {})
    }

    /// [`Scenario::run`], calling `observe` after every converged step with the step's record
    /// and the analysis at its converged state (to check what a path converges to). Pressures
    /// move linearly within a stage as the targets do, from zero at the start.
    pub fn run_observed(
        &self,
        settings: SolverSettings,
        mut observe: impl FnMut(&StepOutcome, &mut Analysis),
    ) -> RunOutcome {
        let mut outcome = RunOutcome::default();
        let mut analysis = match Analysis::new(self.model.clone(), settings) {
            Ok(a) => a,
            Err(e) => {
                outcome.setup_error = Some(e.to_string());
                return outcome;
            }
        };
        let mut previous = vec![[0.0; 3]; self.model.groups.len()];
        let mut levels = LoadLevels::zero(&self.model);
        for (s, stage) in self.path.stages.iter().enumerate() {
            let mut end = levels.clone();
            if let Some(p) = &stage.pressure {
                end.pressure.clone_from(p);
            }
            let sealed = match &stage.air {
                Air::Kept => Ok(()),
                Air::Supplied(p) => {
                    end.chambers.clone_from(p);
                    Ok(())
                }
                Air::Sealed => analysis.seal_chambers(),
            };
            if let Err(e) = sealed {
                outcome.setup_error = Some(format!("stage {}: {e}", s + 1));
                return outcome;
            }
            if let Some(mu) = stage.friction
                && let Err(e) = analysis.set_friction(mu)
            {
                outcome.setup_error = Some(format!("stage {}: {e}", s + 1));
                return outcome;
            }
            for k in 1..=stage.steps {
                let f = k as f64 / stage.steps as f64;
                let target: Vec<[f64; 3]> = previous
                    .iter()
                    .zip(&stage.targets)
                    .map(|(a, b)| std::array::from_fn(|c| a[c] + (b[c] - a[c]) * f))
                    .collect();
                let mut record = StepOutcome {
                    stage: s,
                    step: k,
                    iterations: 0,
                    max_increment_iterations: 0,
                    increments: 0,
                    cutbacks: 0,
                    stabilized: 0,
                    over_bound: false,
                    residual: 0.0,
                    error: None,
                };
                let loads = levels.interpolate(&end, f);
                match analysis.step_to_with_loads(&target, &loads, self.path.increments_per_step) {
                    Ok(report) => {
                        record.iterations = report.total_iterations();
                        record.max_increment_iterations =
                            report.iterations.iter().copied().max().unwrap_or(0);
                        record.increments = report.iterations.len();
                        record.cutbacks = report.cutbacks;
                        record.stabilized = report.stabilized;
                        record.over_bound = report.stabilization_warning().is_some();
                        record.residual = report.residual;
                        observe(&record, &mut analysis);
                        outcome.steps.push(record);
                    }
                    Err(e) => {
                        if let StepError::NotConverged { cutbacks, .. } = &e {
                            record.cutbacks = *cutbacks;
                        }
                        record.error = Some(e.to_string());
                        outcome.steps.push(record);
                        return outcome;
                    }
                }
            }
            previous.clone_from(&stage.targets);
            levels = end;
        }
        outcome
    }
}
