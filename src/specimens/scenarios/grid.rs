//! The robustness benchmark's fixed sampling grid over every family.

use crate::specimens::parallel_arch::{FramePath, ParallelArch, SpecimenContact};
use crate::specimens::scenarios::ArchEdge;
use crate::specimens::scenarios::ArchPanel;
use crate::specimens::scenarios::CylinderStrip;
use crate::specimens::scenarios::Family;
use crate::specimens::scenarios::PathShape;
use crate::specimens::scenarios::Scenario;
use crate::specimens::scenarios::SpecimenPath;
use crate::specimens::scenarios::WrappedSpecimen;

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
