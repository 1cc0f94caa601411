//! Load-path generators: the models and load paths users try (issue 7), each deterministic from a
//! few parameters, and the sampling grid of the robustness benchmark (`benches/robustness.rs`).
//!
//! A [`Scenario`] is a validated [`Model`] plus a [`LoadPath`]: stages, each a target for every
//! boundary group reached in a number of communication steps (targets interpolated linearly
//! within a stage, as the CLI and a ramping master do), optionally with `μ` for the stage.
//! [`Scenario::run`] drives [`Analysis::step_to`] once per communication step, as the FMU does,
//! and records per step: converged or the error text, Newton iterations, increments, cut-backs.
//!
//! # Families
//!
//! **Specimen** ([`SpecimenPath`]): the paper's 1/4 parallel-arch specimen ([`ParallelArch`])
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
//! **Circular membrane** ([`CircularMembrane`], issue 8): a flat disc meshed in rings (the
//! centre, then `6k` nodes on ring `k`), its rim a boundary group `rim` held at zero (so the FMU
//! reports the rim reaction), a pressure set `top` on every triangle (normals +Z). Hencky's
//! clamped membrane under pressure, and the FMU's pressure example.
//!
//! # Assumptions
//!
//! The issue's gmsh panel and strip files are not available: the panel and the strip above are
//! this module's reconstructions (same sizes, triangle and gap counts). Film, penalties and
//! friction are the specimen's ([`ParallelArch::default`], assumptions in `specimen.rs`).

use std::fmt;

use nalgebra::Vector3;

use crate::mech::elements::gap::{FrictionLaw, GapFrame};
use crate::mech::elements::material::{Material, Wrinkling};
use crate::mech::model::{
    AllElements, Axis, BoundaryGroup, ElementSelection, ElementSet, GapSpec, GapSupport, LoadSpec,
    Model, OutputPoint, OutputSpec, PressureSet, Support, Symmetry,
};
use crate::mech::solve::{Analysis, SolverSettings, StepError};
use crate::specimens::parallel_arch::{FramePath, ParallelArch, SpecimenContact};

// ------------------------------------------------------------------------------- load paths

/// One stage of a load path: every group moves linearly to `targets` in `steps` steps.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    /// Target displacement of every boundary group at the end of the stage (m).
    pub targets: Vec<[f64; 3]>,
    /// Communication steps (one `step_to` each) of the stage.
    pub steps: usize,
    /// Friction coefficient of every gap from this stage on (`None`: unchanged).
    pub friction: Option<f64>,
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
}

impl Family {
    /// Every family, in table order.
    pub const ALL: [Family; 5] = [
        Self::Specimen,
        Self::Panel,
        Self::Strip,
        Self::ArchEdge,
        Self::Wrapped,
    ];

    /// Short name (the benchmark's `--family` filter).
    pub fn name(self) -> &'static str {
        match self {
            Self::Specimen => "specimen",
            Self::Panel => "panel",
            Self::Strip => "strip",
            Self::ArchEdge => "arch-edge",
            Self::Wrapped => "wrapped",
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
    /// Increments made larger than asked because every smaller one failed.
    pub enlarged: usize,
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

    /// Enlarged increments over all steps.
    pub fn enlarged(&self) -> usize {
        self.steps.iter().map(|s| s.enlarged).sum()
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
    /// and the analysis at its converged state (to check what a path converges to).
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
        for (s, stage) in self.path.stages.iter().enumerate() {
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
                    enlarged: 0,
                    residual: 0.0,
                    error: None,
                };
                match analysis.step_to(&target, self.path.increments_per_step) {
                    Ok(report) => {
                        record.iterations = report.total_iterations();
                        record.max_increment_iterations =
                            report.iterations.iter().copied().max().unwrap_or(0);
                        record.increments = report.iterations.len();
                        record.cutbacks = report.cutbacks;
                        record.enlarged = report.enlarged;
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
        }
        outcome
    }
}

// ------------------------------------------------------------------- gaps on a circular arc

/// A circular support: an arch (a circle arc in the plane through `centre` normal to `axis`) or
/// a cylinder (the same circle swept along `axis`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CircularSupport {
    /// Centre of curvature (m).
    pub centre: [f64; 3],
    /// Unit normal of the circle's plane (the cylinder's axis).
    pub axis: [f64; 3],
    /// Radius (m).
    pub radius: f64,
}

/// Penalties and friction of generated gaps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GapConstants {
    /// `k_n` (N/m).
    pub normal_stiffness: f64,
    /// `k_s` (N/m).
    pub tangential_stiffness: f64,
    /// `μ`.
    pub friction: f64,
    /// Friction law of every generated gap.
    pub friction_law: FrictionLaw,
}

impl GapConstants {
    /// The specimen's rule (`k_n = 1000 E t`, `k_s = 0.1 k_n`, see `specimen.rs`) for a film.
    pub fn for_film(material: &Material, friction: f64) -> Self {
        let spec = ParallelArch::default();
        let kn = spec.normal_penalty_factor * material.membrane_stiffness();
        Self {
            normal_stiffness: kn,
            tangential_stiffness: spec.tangential_penalty_ratio * kn,
            friction,
            friction_law: FrictionLaw::default(),
        }
    }
}

/// Gaps from film nodes to a circular support with the paper's §4.3 frames: for each node, `z`
/// points from the axis (the centre of curvature) towards the node, the support point is on the
/// circle (cylinder) along that radius at the node's axial position, `x = z × axis` is the
/// tangent of the circle (the sliding direction), `y = z × x` (along the axis), and the initial
/// gap `g0` is the node's distance from the support along `z`. Gaps are named
/// `<prefix><k+1>` in the order of `film_nodes`.
///
/// Errors name the node: unknown index, on the axis, or inside the support (penetrating by more
/// than rounding). `ParallelArch` builds its gaps the same way (axis `+X`).
pub fn gaps_on_arc(
    nodes: &[[f64; 3]],
    film_nodes: &[usize],
    support: &CircularSupport,
    constants: GapConstants,
    prefix: &str,
) -> Result<Vec<GapSpec>, String> {
    let axis = Vector3::from(support.axis);
    let (length, radius) = (axis.norm(), support.radius);
    if length == 0.0 || !length.is_finite() || radius <= 0.0 || !radius.is_finite() {
        return Err("circular support: axis must be non-zero and radius > 0".into());
    }
    let axis = axis.normalize();
    let centre = Vector3::from(support.centre);
    film_nodes
        .iter()
        .enumerate()
        .map(|(k, &node)| {
            let name = format!("{prefix}{}", k + 1);
            let p = Vector3::from(
                *nodes
                    .get(node)
                    .ok_or_else(|| format!("gap {name}: node {node} does not exist"))?,
            );
            let along = (p - centre).dot(&axis);
            let radial = p - centre - axis * along;
            let distance = radial.norm();
            if distance < 1e-9 * support.radius {
                return Err(format!(
                    "gap {name}: node {node} lies on the support's axis"
                ));
            }
            let z = radial / distance;
            let g0 = distance - support.radius;
            if g0 < -1e-9 * support.radius {
                return Err(format!(
                    "gap {name}: node {node} lies {:.3e} m inside the support",
                    -g0
                ));
            }
            Ok(GapSpec {
                name,
                film_node: node,
                support: GapSupport::Point((centre + axis * along + z * support.radius).into()),
                frame: GapFrame::from_x_and_z(z.cross(&axis), z),
                initial_gap: g0.max(0.0),
                normal_stiffness: constants.normal_stiffness,
                tangential_stiffness: constants.tangential_stiffness,
                friction: constants.friction,
                friction_law: constants.friction_law,
            })
        })
        .collect()
}

/// Node index of grid point `(i, j)` in a row-major grid with `nx + 1` nodes per row.
fn grid_id(nx: usize, i: usize, j: usize) -> usize {
    j * (nx + 1) + i
}

/// Triangles of an `nx × ny` structured grid (two per cell, diagonal from `(i, j)` to `(i+1, j+1)`).
fn grid_triangles(nx: usize, ny: usize) -> Vec<[usize; 3]> {
    let id = |i, j| grid_id(nx, i, j);
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    triangles
}

/// Grid index of coordinate `x` on a grid of spacing `dx`, if `x` falls on a grid line.
fn grid_line(x: f64, dx: f64, n: usize) -> Option<usize> {
    let i = (x / dx).round();
    ((x / dx - i).abs() < 1e-9 && i >= 0.0 && i <= n as f64).then_some(i as usize)
}

/// Radius of a circular arch from its rise and span.
fn arch_radius(rise: f64, span: f64) -> f64 {
    (rise * rise + span * span / 4.0) / (2.0 * rise)
}

fn check_positive(items: &[(&str, f64)]) -> Result<(), String> {
    for (name, v) in items {
        if !(*v > 0.0 && v.is_finite()) {
            return Err(format!("{name} = {v} must be > 0"));
        }
    }
    Ok(())
}

fn validated(model: Model) -> Result<Model, String> {
    model.validate().map_err(|e| e.to_string())?;
    Ok(model)
}

// ------------------------------------------------------------------------------- specimen

/// The shape of a specimen load path (frame displacement over pseudo-time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PathShape {
    /// Down to the depth.
    Monotone,
    /// Down to the depth, up to half of it (half the steps), down again (half the steps).
    Reversal,
    /// Down to the depth, then the frame pulled in plane by `(dx, dy)` (m) in half the steps.
    Pull { dx: f64, dy: f64 },
    /// Down to the depth and pulled in plane by `(dx, dy)` at the same time.
    PullWhileLowering { dx: f64, dy: f64 },
    /// Down to the depth, then back to 0 in as many steps.
    Unload,
}

/// A load path on the paper's specimen ([`ParallelArch`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecimenPath {
    /// The specimen (its `friction` is `μ`, its `arch_height` the rise `H`).
    pub specimen: ParallelArch,
    /// Depth of the frame as a multiple of `H` (0.5: the paper's assumed target; up to 1).
    pub depth: f64,
    /// Steps of the first stage.
    pub steps: usize,
    /// Shape of the path.
    pub shape: PathShape,
    /// Increments per communication step.
    pub increments_per_step: usize,
}

impl SpecimenPath {
    /// `depth · H` down in `steps` steps with `μ`, the FMU's 10 increments per step.
    pub fn monotone(arch_height: f64, mu: f64, depth: f64, steps: usize) -> Self {
        Self {
            specimen: ParallelArch {
                friction: mu,
                ..ParallelArch::with_height(arch_height)
            },
            depth,
            steps,
            shape: PathShape::Monotone,
            increments_per_step: 10,
        }
    }

    /// The scenario (validated model, path).
    pub fn scenario(&self) -> Result<Scenario, String> {
        let h = self.specimen.arch_height;
        if !(self.depth > 0.0 && self.depth <= 1.0) || self.steps == 0 {
            return Err(format!(
                "specimen path: depth {} must lie in (0, 1] and steps {} ≥ 1",
                self.depth, self.steps
            ));
        }
        let model = self.specimen.model()?;
        let down = [0.0, 0.0, -self.depth * h];
        let half = self.steps.div_ceil(2);
        let stage = |t: [f64; 3], steps| Stage {
            targets: vec![t],
            steps,
            friction: None,
        };
        let stages = match self.shape {
            PathShape::Monotone => vec![stage(down, self.steps)],
            PathShape::Reversal => vec![
                stage(down, self.steps),
                stage([0.0, 0.0, down[2] / 2.0], half),
                stage(down, half),
            ],
            PathShape::Pull { dx, dy } => {
                vec![stage(down, self.steps), stage([dx, dy, down[2]], half)]
            }
            PathShape::PullWhileLowering { dx, dy } => vec![stage([dx, dy, down[2]], self.steps)],
            PathShape::Unload => vec![stage(down, self.steps), stage([0.0; 3], self.steps)],
        };
        let shape = match self.shape {
            PathShape::Monotone => "down".to_string(),
            PathShape::Reversal => "down-up-down".to_string(),
            PathShape::Pull { dx, dy } => format!("down+pull({:.0},{:.0})mm", dx * 1e3, dy * 1e3),
            PathShape::PullWhileLowering { dx, dy } => {
                format!("down&pull({:.0},{:.0})mm", dx * 1e3, dy * 1e3)
            }
            PathShape::Unload => "down-unload".to_string(),
        };
        Ok(Scenario {
            family: Family::Specimen,
            name: format!(
                "specimen H={:.2} mu={} depth={}H steps={} {shape}",
                h, self.specimen.friction, self.depth, self.steps
            ),
            model,
            path: LoadPath {
                stages,
                increments_per_step: self.increments_per_step,
            },
        })
    }
}

// ------------------------------------------------------------------------- wrapped specimen

/// The specimen wound onto the arch from crown to foot and its boundary extended
/// ([`FramePath::Wrapped`](crate::specimens::parallel_arch::FramePath)), one communication step per stage of
/// the frame path (the path is not linear between its stages).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WrappedSpecimen {
    /// The specimen, its `frame_path` wrapped.
    pub specimen: ParallelArch,
    /// Communication steps to the end of the path.
    pub steps: usize,
    /// Then back to the wound film without extension in this many steps (0: no release).
    pub release_steps: usize,
    /// Increments per communication step.
    pub increments_per_step: usize,
}

impl WrappedSpecimen {
    /// The scenario (validated model, path).
    pub fn scenario(&self) -> Result<Scenario, String> {
        let spec = &self.specimen;
        let FramePath::Wrapped { extension } = spec.frame_path else {
            return Err("wrapped specimen: the frame path must be wrapped".into());
        };
        if self.steps == 0 {
            return Err("wrapped specimen: steps must be ≥ 1".into());
        }
        let model = spec.model()?;
        let stage = |t: f64| Stage {
            targets: spec.boundary_targets(&model, t),
            steps: 1,
            friction: None,
        };
        let mut stages: Vec<Stage> = (1..=self.steps)
            .map(|k| stage(k as f64 / self.steps as f64))
            .collect();
        // Releasing the extension retraces the second half of the path back to t = 1/2.
        stages.extend(
            (1..=self.release_steps)
                .map(|k| stage(1.0 - 0.5 * k as f64 / self.release_steps as f64)),
        );
        Ok(Scenario {
            family: Family::Wrapped,
            name: format!(
                "wrapped H={:.2} {:?} mu={} eps={} steps={}{}",
                spec.arch_height,
                spec.contact,
                spec.friction,
                extension,
                self.steps,
                if self.release_steps > 0 {
                    format!(" release={}", self.release_steps)
                } else {
                    String::new()
                }
            ),
            model,
            path: LoadPath {
                stages,
                increments_per_step: self.increments_per_step,
            },
        })
    }
}

// ---------------------------------------------------------------------------------- panel

/// A film panel over two parallel arches, one edge clamped and the opposite edge jacked down
/// about a hinge (layout in the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArchPanel {
    /// Film size along `x`, across the arches (m).
    pub length: f64,
    /// Film size along `y`, along the arches (m).
    pub width: f64,
    /// Mesh refinement: `15 r × 12 r` cells (2 gives 1 440 triangles).
    pub refinement: usize,
    /// Arch rise `H` (m); the film lies flat at `z = H`.
    pub arch_rise: f64,
    /// Arch span (m), centred on `y = width / 2`.
    pub arch_span: f64,
    /// `x` of the two arches (m); each must fall on a grid line.
    pub arch_x: [f64; 2],
    /// Film material.
    pub material: Material,
    /// `μ` of every gap.
    pub friction: f64,
    /// Drop of the far corner of the jacked edge at the end of the standard run (m): the model's
    /// group targets (what `membrane-contact model` ramps to) and [`ArchPanel::jacked`]'s.
    pub corner_drop: f64,
}

impl Default for ArchPanel {
    fn default() -> Self {
        Self {
            length: 3.0,
            width: 2.0,
            refinement: 2,
            arch_rise: 0.2,
            arch_span: 1.5,
            arch_x: [1.0, 2.0],
            // A jacked panel puts regions into compression; ETFE wrinkles there instead of
            // carrying it (issue 7: without wrinkling its Newton stalls, see docs/benchmarks.md).
            material: Material {
                wrinkling: Wrinkling::TensionField,
                ..ParallelArch::default().material
            },
            friction: 0.2,
            corner_drop: 0.2,
        }
    }
}

impl ArchPanel {
    fn cells(&self) -> (usize, usize) {
        (15 * self.refinement, 12 * self.refinement)
    }

    /// The validated model: clamped edge `x = 0` (supports), groups `J0…J<ny>` on the edge
    /// `x = length` (the `J0` node is the hinge), gaps `AL1…` and `AR1…` on the arches.
    pub fn model(&self) -> Result<Model, String> {
        check_positive(&[
            ("panel length", self.length),
            ("panel width", self.width),
            ("arch rise", self.arch_rise),
            ("arch span", self.arch_span),
        ])?;
        if !(1..=20).contains(&self.refinement) {
            return Err(format!("refinement {} must lie in 1..=20", self.refinement));
        }
        if self.arch_span > self.width || self.arch_rise > self.arch_span / 2.0 {
            return Err(
                "arch span must fit in the width and the rise must not exceed half the span".into(),
            );
        }
        let (nx, ny) = self.cells();
        let (dx, dy) = (self.length / nx as f64, self.width / ny as f64);
        let h = self.arch_rise;
        let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            for i in 0..=nx {
                nodes.push([i as f64 * dx, j as f64 * dy, h]);
            }
        }
        let id = |i, j| grid_id(nx, i, j);
        let radius = arch_radius(h, self.arch_span);
        let yc = self.width / 2.0;
        let constants = GapConstants::for_film(&self.material, self.friction);
        let mut gaps = Vec::new();
        for (x, prefix) in self.arch_x.iter().zip(["AL", "AR"]) {
            let i = grid_line(*x, dx, nx)
                .filter(|&i| i > 0 && i < nx)
                .ok_or_else(|| {
                    format!("arch at x = {x} must lie on an interior grid line (spacing {dx})")
                })?;
            let film: Vec<usize> = (0..=ny)
                .filter(|&j| (j as f64 * dy - yc).abs() <= self.arch_span / 2.0 + 1e-9)
                .map(|j| id(i, j))
                .collect();
            let support = CircularSupport {
                centre: [*x, yc, h - radius],
                axis: [1.0, 0.0, 0.0],
                radius,
            };
            gaps.extend(gaps_on_arc(&nodes, &film, &support, constants, prefix)?);
        }
        let supports = (0..=ny)
            .map(|j| Support {
                node: id(0, j),
                fixed: vec![Axis::X, Axis::Y, Axis::Z],
                name: None,
            })
            .collect();
        let groups = self
            .jack_targets(self.angle_for_drop(self.corner_drop))
            .into_iter()
            .enumerate()
            .map(|(j, target)| BoundaryGroup {
                name: format!("J{j}"),
                nodes: vec![id(nx, j)],
                target,
                components: None,
                hinge: None,
            })
            .collect();
        validated(Model {
            loads: Default::default(),
            outputs: Default::default(),
            cables: vec![],
            curved_supports: vec![],
            name: "ArchPanel".into(),
            description: format!(
                "{} m x {} m film over two arches (rise {} m, span {} m), edge x = {} jacked about a hinge",
                self.length, self.width, h, self.arch_span, self.length
            ),
            nodes,
            triangles: grid_triangles(nx, ny),
            material: self.material,
            supports,
            symmetry: vec![],
            gaps,
            groups,
        })
    }

    /// Targets of the groups `J0…` for the jacked edge rotated by `angle` (rad, positive down)
    /// about the `x` axis through its corner `y = 0` (rigid rotation of the edge beam).
    pub fn jack_targets(&self, angle: f64) -> Vec<[f64; 3]> {
        let (_, ny) = self.cells();
        let (s, c) = angle.sin_cos();
        (0..=ny)
            .map(|j| {
                let y = j as f64 * self.width / ny as f64;
                [0.0, y * (c - 1.0), -y * s]
            })
            .collect()
    }

    /// The angle (rad) that lowers the far corner of the jacked edge by `drop` (m).
    pub fn angle_for_drop(&self, drop: f64) -> f64 {
        (drop / self.width).clamp(-1.0, 1.0).asin()
    }

    /// Jacked down until the far corner has dropped by `corner_drop`, in `stages` equal stages
    /// (of the angle) of `steps` steps each, `μ` set at the first stage to `mu` (`None`: the
    /// model's); every stage ends on the exact rotation. `jacked(1, n, None, 1)` is what
    /// `membrane-contact model panel.json --steps n` does.
    pub fn jacked(
        &self,
        stages: usize,
        steps: usize,
        mu: Option<f64>,
        increments_per_step: usize,
    ) -> Result<Scenario, String> {
        if stages == 0 || steps == 0 {
            return Err("panel path: stages and steps must be ≥ 1".into());
        }
        let model = self.model()?;
        let angle = self.angle_for_drop(self.corner_drop);
        let stages_list = (1..=stages)
            .map(|k| Stage {
                targets: self.jack_targets(angle * k as f64 / stages as f64),
                steps,
                friction: if k == 1 { mu } else { None },
            })
            .collect();
        Ok(Scenario {
            family: Family::Panel,
            name: format!(
                "panel H={} mu={} drop={}m stages={stages}x{steps} incr={increments_per_step}",
                self.arch_rise,
                mu.unwrap_or(self.friction),
                self.corner_drop
            ),
            model,
            path: LoadPath {
                stages: stages_list,
                increments_per_step,
            },
        })
    }
}

// ---------------------------------------------------------------------------------- strip

/// An unstressed film strip over a half cylinder, both ends pulled (layout in the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylinderStrip {
    /// Cylinder radius (m); axis along `y` through the origin.
    pub radius: f64,
    /// Strip width along the axis (m), one cell.
    pub width: f64,
    /// Film nodes per row on the half circle (each with a gap).
    pub arc_nodes: usize,
    /// Length of the straight leg below each foot (m).
    pub leg: f64,
    /// Film material (no prestress by default).
    pub material: Material,
    /// `μ` of every gap.
    pub friction: f64,
    /// Downward pull of both leg ends at the end of the standard run (m).
    pub down: f64,
    /// Outward pull of both leg ends (m).
    pub out: f64,
}

impl Default for CylinderStrip {
    fn default() -> Self {
        Self {
            radius: 0.3,
            width: 0.1,
            arc_nodes: 19,
            leg: 0.2,
            material: Material {
                prestress: [0.0; 3],
                ..ParallelArch::default().material
            },
            friction: 0.2,
            down: 0.005,
            out: 0.0,
        }
    }
}

impl CylinderStrip {
    /// The validated model: groups `left` and `right` (the leg ends), gaps `C1…` on the arc.
    pub fn model(&self) -> Result<Model, String> {
        check_positive(&[
            ("cylinder radius", self.radius),
            ("strip width", self.width),
            ("leg", self.leg),
        ])?;
        if self.arc_nodes < 3 {
            return Err("strip: at least 3 arc nodes".into());
        }
        let n = self.arc_nodes;
        let r = self.radius;
        // Stations along the strip: 0 left end, 1..=n the half circle, n + 1 right end.
        let mut nodes = Vec::with_capacity(2 * (n + 2));
        for s in 0..n + 2 {
            let p = match s {
                0 => [-r, 0.0, -self.leg],
                s if s == n + 1 => [r, 0.0, -self.leg],
                s => {
                    let phi = -std::f64::consts::FRAC_PI_2
                        + std::f64::consts::PI * (s - 1) as f64 / (n - 1) as f64;
                    [r * phi.sin(), 0.0, r * phi.cos()]
                }
            };
            nodes.push(p);
            nodes.push([p[0], self.width, p[2]]);
        }
        let id = |s: usize, j: usize| 2 * s + j;
        let triangles = (0..n + 1)
            .flat_map(|s| {
                [
                    [id(s, 0), id(s + 1, 0), id(s + 1, 1)],
                    [id(s, 0), id(s + 1, 1), id(s, 1)],
                ]
            })
            .collect();
        let film: Vec<usize> = (1..=n).flat_map(|s| [id(s, 0), id(s, 1)]).collect();
        let support = CircularSupport {
            centre: [0.0; 3],
            axis: [0.0, 1.0, 0.0],
            radius: r,
        };
        let constants = GapConstants::for_film(&self.material, self.friction);
        let gaps = gaps_on_arc(&nodes, &film, &support, constants, "C")?;
        let group = |name: &str, s, sign: f64| BoundaryGroup {
            name: name.into(),
            nodes: vec![id(s, 0), id(s, 1)],
            target: [sign * self.out, 0.0, -self.down],
            components: None,
            hinge: None,
        };
        validated(Model {
            loads: Default::default(),
            outputs: Default::default(),
            cables: vec![],
            curved_supports: vec![],
            name: "CylinderStrip".into(),
            description: format!("unstressed strip over a half cylinder of radius {r} m"),
            nodes,
            triangles,
            material: self.material,
            supports: vec![],
            symmetry: vec![],
            gaps,
            groups: vec![group("left", 0, -1.0), group("right", n + 1, 1.0)],
        })
    }

    /// Both ends pulled down by `down` and out by `out` in `steps` steps.
    pub fn pulled(&self, steps: usize, increments_per_step: usize) -> Result<Scenario, String> {
        if steps == 0 {
            return Err("strip path: steps must be ≥ 1".into());
        }
        let model = self.model()?;
        Ok(Scenario {
            family: Family::Strip,
            name: format!(
                "strip R={} mu={} down={:.0}mm out={:.0}mm steps={steps}",
                self.radius,
                self.friction,
                self.down * 1e3,
                self.out * 1e3
            ),
            path: LoadPath {
                stages: vec![Stage {
                    targets: model.groups.iter().map(|g| g.target).collect(),
                    steps,
                    friction: None,
                }],
                increments_per_step,
            },
            model,
        })
    }
}

// ------------------------------------------------------------------------------- arch edge

/// A film whose free edge `x = 0` lies on an arch from crown (`y = 0`, symmetry plane) to foot:
/// the film is the arch's profile extruded along `x` up to the frame edge `x = length`, gaps
/// `E1…` on every edge node (`g0 = 0`), prestress along the arch only (`σ_y`; none across the
/// edge, which is free); the frame (edges `x = length` and the foot line) is lowered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArchEdge {
    /// Arch rise `H` (m).
    pub arch_height: f64,
    /// Arch half span (m).
    pub arch_half_span: f64,
    /// Film size in `x`, from the arch to the frame (m).
    pub length: f64,
    /// Cells along the arch (crown to foot); gaps: one more.
    pub cells_along: usize,
    /// Prestress along the arch, `σ_y` (Pa); `σ_x = τ = 0`.
    pub prestress_along: f64,
    /// `μ`.
    pub friction: f64,
    /// Friction law of the edge gaps: the paper's (§2.2, sliding along the arch only) by
    /// default, as in reproduction 5 of issue 7; the isotropic cone lets the unprestressed edge
    /// slide across the arch.
    pub friction_law: FrictionLaw,
    /// Compression model of the film: tension field by default (about 70 % of the elements
    /// would be compressed otherwise, and Newton stalls, see docs/benchmarks.md).
    pub wrinkling: Wrinkling,
}

impl Default for ArchEdge {
    fn default() -> Self {
        Self {
            arch_height: 0.3,
            arch_half_span: 0.8,
            length: 0.6,
            cells_along: 8,
            prestress_along: ParallelArch::default().material.prestress[1],
            friction: 0.2,
            friction_law: FrictionLaw::SlidingDirection,
            wrinkling: Wrinkling::TensionField,
        }
    }
}

impl ArchEdge {
    /// The validated model (8 × 6 cells of ≈ 0.1 m for the default size, 9 gaps).
    pub fn model(&self) -> Result<Model, String> {
        check_positive(&[
            ("arch height", self.arch_height),
            ("arch half span", self.arch_half_span),
            ("film length", self.length),
        ])?;
        if self.arch_height > self.arch_half_span || self.cells_along < 2 {
            return Err(
                "arch height larger than the half span, or fewer than 2 cells along it".into(),
            );
        }
        let ny = self.cells_along;
        let dy = self.arch_half_span / ny as f64;
        let nx = ((self.length / dy).round() as usize).max(1);
        let dx = self.length / nx as f64;
        let h = self.arch_height;
        let radius = arch_radius(h, 2.0 * self.arch_half_span);
        let mut nodes = Vec::new();
        for j in 0..=ny {
            let y = j as f64 * dy;
            let z = h - radius + (radius * radius - y * y).sqrt();
            for i in 0..=nx {
                nodes.push([i as f64 * dx, y, z]);
            }
        }
        let id = |i, j| grid_id(nx, i, j);
        let material = Material {
            prestress: [0.0, self.prestress_along, 0.0],
            wrinkling: self.wrinkling,
            ..ParallelArch::default().material
        };
        let film: Vec<usize> = (0..=ny).map(|j| id(0, j)).collect();
        let support = CircularSupport {
            centre: [0.0, 0.0, h - radius],
            axis: [1.0, 0.0, 0.0],
            radius,
        };
        let gaps = gaps_on_arc(
            &nodes,
            &film,
            &support,
            GapConstants {
                friction_law: self.friction_law,
                ..GapConstants::for_film(&material, self.friction)
            },
            "E",
        )?;
        let frame = (0..=ny)
            .flat_map(|j| (0..=nx).map(move |i| (i, j)))
            .filter(|&(i, j)| (i == nx || j == ny) && i > 0)
            .map(|(i, j)| id(i, j))
            .collect();
        validated(Model {
            loads: Default::default(),
            outputs: Default::default(),
            cables: vec![],
            curved_supports: vec![],
            name: "ArchEdge".into(),
            description: format!(
                "film edge lying on an arch of rise {h} m, prestress {} Pa along it and none across",
                self.prestress_along
            ),
            nodes,
            triangles: grid_triangles(nx, ny),
            material,
            supports: vec![],
            symmetry: vec![Symmetry {
                name: "y0".into(),
                normal: Axis::Y,
                nodes: (0..nx).map(|i| id(i, 0)).collect(),
            }],
            gaps,
            groups: vec![BoundaryGroup {
                name: "frame".into(),
                nodes: frame,
                target: [0.0, 0.0, -h / 2.0],
                components: None,
                hinge: None,
            }],
        })
    }

    /// The frame lowered by `depth · H` in `steps` steps.
    pub fn lowered(
        &self,
        depth: f64,
        steps: usize,
        increments_per_step: usize,
    ) -> Result<Scenario, String> {
        if steps == 0 {
            return Err("arch-edge path: steps must be ≥ 1".into());
        }
        Ok(Scenario {
            family: Family::ArchEdge,
            name: format!(
                "arch-edge H={} mu={} depth={depth}H steps={steps}",
                self.arch_height, self.friction
            ),
            model: self.model()?,
            path: LoadPath {
                stages: vec![Stage {
                    targets: vec![[0.0, 0.0, -depth * self.arch_height]],
                    steps,
                    friction: None,
                }],
                increments_per_step,
            },
        })
    }
}

// ------------------------------------------------------------------------- benchmark grid

/// The robustness benchmark's fixed sampling grid (no randomness), in family order:
///
/// * specimen: `H` ∈ {0.15, 0.2, …, 0.45} m × `μ` ∈ {0, 0.1, 0.2, 0.4, 0.8} × 12 paths: down to
///   `−H/2` in 1, 20 and 200 steps, in steps of 1.5 mm until `−H/2` is passed (the issue's
///   reproduction 1), to `−H`
///   in 5 and 80 steps, down–up–down (to `−H/2` in 20 and to `−0.75 H` in 40), down and unload
///   (20 + 20), down then pulled 5 mm in `x` or `y`, lowered while pulled 5 mm in `x` and `y`
///   (420 paths);
/// * panel: rise ∈ {0.15, 0.3} m × `μ` ∈ {0, 0.2, 0.5} × far-corner drop ∈ {H/2, H} × paths
///   {20 steps × 1 increment (the CLI's `--steps 20`), 5 steps × 10, 3 stages × 5 steps × 10
///   (a staged master)} (36 paths);
/// * strip: `R` ∈ {0.2, 0.3, 0.5} m × `μ` ∈ {0, 0.2, 0.5} × pull (down, out) ∈ {(5, 0),
///   (10, 0), (10, 5)} mm × steps ∈ {1, 10} (54 paths);
/// * arch edge: `H` ∈ {0.2, 0.3, 0.4} m × `μ` ∈ {0.1, 0.2, 0.5} × steps ∈ {20, 80} to `−H/2`
///   (18 paths);
/// * wrapped: `H` ∈ {0.2, 0.3, 0.4} m × contact ∈ {gaps, curved support} × `μ` ∈ {0, 0.2, 0.8}
///   × {`ε` = 0.02 in 10 steps, 0.04 in 40, 0.04 in 40 then released in 10} (54 paths).
///
/// `increments_per_step` is the FMU's default for every path except the CLI-style panel ramp.
///
/// The benchmark's `--quick` run and the robustness test draw their samples from this grid with
/// [`grid_slice`].
pub fn robustness_grid(increments_per_step: usize) -> Result<Vec<Scenario>, String> {
    let ips = increments_per_step;
    let mut out = Vec::new();
    for h in [0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45] {
        for mu in [0.0, 0.1, 0.2, 0.4, 0.8] {
            let base = SpecimenPath {
                increments_per_step: ips,
                ..SpecimenPath::monotone(h, mu, 0.5, 20)
            };
            // 1.5 mm per step until −H/2 is reached (reproduction 1 of issue 7).
            let fine = ((0.5 * h) / 0.0015).ceil() as usize;
            let fine_depth = fine as f64 * 0.0015 / h;
            let paths = [
                (0.5, 1, PathShape::Monotone),
                (0.5, 20, PathShape::Monotone),
                (0.5, 200, PathShape::Monotone),
                (fine_depth, fine, PathShape::Monotone),
                (1.0, 5, PathShape::Monotone),
                (1.0, 80, PathShape::Monotone),
                (0.5, 20, PathShape::Reversal),
                (0.75, 40, PathShape::Reversal),
                (0.5, 20, PathShape::Unload),
                (0.5, 20, PathShape::Pull { dx: 0.005, dy: 0.0 }),
                (0.5, 20, PathShape::Pull { dx: 0.0, dy: 0.005 }),
                (
                    0.5,
                    20,
                    PathShape::PullWhileLowering {
                        dx: 0.005,
                        dy: 0.005,
                    },
                ),
            ];
            for (depth, steps, shape) in paths {
                out.push(
                    SpecimenPath {
                        depth,
                        steps,
                        shape,
                        ..base
                    }
                    .scenario()?,
                );
            }
        }
    }
    for rise in [0.15, 0.3] {
        for mu in [0.0, 0.2, 0.5] {
            for corner_drop in [0.5 * rise, rise] {
                let panel = ArchPanel {
                    arch_rise: rise,
                    friction: mu,
                    corner_drop,
                    ..ArchPanel::default()
                };
                out.push(panel.jacked(1, 20, None, 1)?);
                out.push(panel.jacked(1, 5, None, ips)?);
                out.push(panel.jacked(3, 5, None, ips)?);
            }
        }
    }
    for radius in [0.2, 0.3, 0.5] {
        for mu in [0.0, 0.2, 0.5] {
            for (down, pull_out) in [(0.005, 0.0), (0.01, 0.0), (0.01, 0.005)] {
                let strip = CylinderStrip {
                    radius,
                    friction: mu,
                    down,
                    out: pull_out,
                    ..CylinderStrip::default()
                };
                for steps in [1, 10] {
                    out.push(strip.pulled(steps, ips)?);
                }
            }
        }
    }
    for h in [0.2, 0.3, 0.4] {
        for mu in [0.1, 0.2, 0.5] {
            let edge = ArchEdge {
                arch_height: h,
                friction: mu,
                ..ArchEdge::default()
            };
            for steps in [20, 80] {
                out.push(edge.lowered(0.5, steps, ips)?);
            }
        }
    }
    for h in [0.2, 0.3, 0.4] {
        for contact in [SpecimenContact::Gaps, SpecimenContact::CurvedSupport] {
            for mu in [0.0, 0.2, 0.8] {
                for (extension, steps, release_steps) in
                    [(0.02, 10, 0), (0.04, 40, 0), (0.04, 40, 10)]
                {
                    let specimen = ParallelArch {
                        contact,
                        friction: mu,
                        frame_path: FramePath::Wrapped { extension },
                        ..ParallelArch::with_height(h)
                    };
                    out.push(
                        WrappedSpecimen {
                            specimen,
                            steps,
                            release_steps,
                            increments_per_step: ips,
                        }
                        .scenario()?,
                    );
                }
            }
        }
    }
    Ok(out)
}

/// Every `stride`-th path of `family` in `grid`, from its first, in grid order (`stride` 0 is
/// taken as 1).
pub fn grid_slice(grid: &[Scenario], family: Family, stride: usize) -> Vec<Scenario> {
    grid.iter()
        .filter(|s| s.family == family)
        .step_by(stride.max(1))
        .cloned()
        .collect()
}

// ------------------------------------------------------------------------ circular membrane

/// A flat circular film in the XY plane, rim held by the group `rim`, pressure set `top`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CircularMembrane {
    /// Radius `a` (m).
    pub radius: f64,
    /// Rings of triangles (ring `k` has `6k` nodes; `1 + 3 rings (rings + 1)` nodes in all).
    pub rings: usize,
    /// Film.
    pub material: Material,
    /// Pressure of the set `top` in the model file (Pa; positive pushes towards +Z).
    pub pressure: f64,
}

impl CircularMembrane {
    /// Node indices of ring `k` (ring 0 is the centre, node 0).
    pub fn ring(&self, k: usize) -> std::ops::Range<usize> {
        if k == 0 {
            0..1
        } else {
            let first = 1 + 3 * k * (k - 1);
            first..first + 6 * k
        }
    }

    /// The validated model (name `CircularMembrane`).
    pub fn model(&self) -> Result<Model, String> {
        if self.rings == 0 || self.radius.is_nan() || self.radius <= 0.0 {
            return Err("a circular membrane needs rings ≥ 1 and a radius > 0".into());
        }
        let mut nodes = vec![[0.0, 0.0, 0.0]];
        for k in 1..=self.rings {
            let r = self.radius * k as f64 / self.rings as f64;
            for j in 0..6 * k {
                let phi = std::f64::consts::TAU * j as f64 / (6 * k) as f64;
                nodes.push([r * phi.cos(), r * phi.sin(), 0.0]);
            }
        }
        let mut triangles = vec![];
        for k in 1..=self.rings {
            let inner: Vec<usize> = self.ring(k - 1).collect();
            let outer: Vec<usize> = self.ring(k).collect();
            let (m, n) = (inner.len(), outer.len());
            if m == 1 {
                for j in 0..n {
                    triangles.push([0, outer[j], outer[(j + 1) % n]]);
                }
                continue;
            }
            // Zip the two rings by angle (both start at angle 0, equally spaced), counter-clockwise.
            let (mut i, mut j) = (0, 0);
            while i < m || j < n {
                let next_outer = (j + 1) as f64 / n as f64;
                let next_inner = (i + 1) as f64 / m as f64;
                if j < n && (i == m || next_outer <= next_inner + 1e-12) {
                    triangles.push([inner[i % m], outer[j], outer[(j + 1) % n]]);
                    j += 1;
                } else {
                    triangles.push([inner[i % m], outer[j % n], inner[(i + 1) % m]]);
                    i += 1;
                }
            }
        }
        validated(Model {
            name: "CircularMembrane".into(),
            description: format!(
                "flat circular film, radius {} m, {} rings, rim held by group 'rim', pressure set 'top'",
                self.radius, self.rings
            ),
            nodes,
            triangles,
            material: self.material,
            supports: vec![],
            symmetry: vec![],
            gaps: vec![],
            groups: vec![BoundaryGroup {
                name: "rim".into(),
                nodes: self.ring(self.rings).collect(),
                target: [0.0; 3],
                components: None,
                hinge: None,
            }],
            loads: LoadSpec {
                pressures: vec![PressureSet {
                    name: "top".into(),
                    elements: ElementSelection::All(AllElements::All),
                    pressure: self.pressure,
                    towards: None,
                }],
                ..LoadSpec::default()
            },
            // The centre's rise and the whole film's stress extremes.
            outputs: OutputSpec {
                points: vec![OutputPoint {
                    name: "centre".into(),
                    node: 0,
                }],
                element_sets: vec![ElementSet {
                    name: "disc".into(),
                    elements: ElementSelection::All(AllElements::All),
                }],
            },
            cables: vec![],
            curved_supports: vec![],
        })
    }
}
