//! Specimen load paths (monotone, cyclic, unloading, pulled) and the wrapped specimen.

use crate::specimens::parallel_arch::{FramePath, ParallelArch};
use crate::specimens::scenarios::Family;
use crate::specimens::scenarios::LoadPath;
use crate::specimens::scenarios::Scenario;
use crate::specimens::scenarios::Stage;

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
            air: Default::default(),
            targets: vec![t],
            steps,
            friction: None,
            pressure: None,
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
            air: Default::default(),
            targets: spec.boundary_targets(&model, t),
            steps: 1,
            friction: None,
            pressure: None,
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
