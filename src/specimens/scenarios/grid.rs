//! The robustness benchmark's fixed sampling grid over every family.

use crate::specimens::parallel_arch::{FramePath, ParallelArch, SpecimenContact, etfe_plastic};
use crate::specimens::scenarios::ArchEdge;
use crate::specimens::scenarios::ArchPanel;
use crate::specimens::scenarios::CircularMembrane;
use crate::specimens::scenarios::CylinderStrip;
use crate::specimens::scenarios::Family;
use crate::specimens::scenarios::PathShape;
use crate::specimens::scenarios::Scenario;
use crate::specimens::scenarios::SpecimenPath;
use crate::specimens::scenarios::Stage;
use crate::specimens::scenarios::WrappedSpecimen;
use crate::specimens::scenarios::cushion_paths;

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
///   × {`ε` = 0.02 in 10 steps, 0.04 in 40, 0.04 in 40 then released in 10} (54 paths);
/// * plastic: [`plastic_paths`];
/// * cushion: [`cushion_paths`].
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
    out.extend(plastic_paths(ips)?);
    out.extend(cushion_paths(ips)?);
    Ok(out)
}

/// The plastic family of the grid (issue 20): ETFE's elasto-plastic film ([`etfe_plastic`], the
/// data-sheet curve: first yield 21 MPa) where the linear film goes past yield, `μ` = 0.2:
///
/// * specimen lowered, `H` ∈ {0.15, 0.2, …, 0.45} m (every height of the specimen family) ×
///   {to `−H` in 5 steps and in 80, down–up–down (to `−H` in 40, up to `−H/2`, down again)}
///   (at `−H/2` the lower arches stay below yield);
/// * wrapped specimen, `H` ∈ {0.2, 0.3, 0.4} m × {gaps, curved support}: `ε` = 0.04 in 40
///   steps, then the extension released by a quarter (to `ε` = 0.03) in 10;
/// * cushion (a clamped disc of radius 1 m, 8 rings, [`CircularMembrane::inflated`]): inflated to
///   {4, 6, 8} kPa (first yield near 3 kPa) in {10, 40} steps, deflated to 300 Pa in as many;
/// * panel ([`ArchPanel`], tension-field film, refinement 1: 360 triangles), (rise, far-corner
///   drop) ∈ {(0.15, 0.45), (0.3, 0.45), (0.3, 0.6)} m: jacked in 5 steps, then released to half
///   the angle in 5, and the first also to the start (up to a drop of `H` the panel's film
///   wrinkles and stays below yield).
///
/// A film that has flowed is longer than the boundary that stretched it: released all the way
/// (the frame back at the start, a cushion at zero pressure) it is slack and has no stiffness,
/// so these paths stop short of that. Every 10th path (what the benchmark's `--quick` run and
/// the robustness test's sample draw) is a cushion, a panel, a wrapped and a lowered specimen
/// in turn; the others are interleaved.
pub fn plastic_paths(increments_per_step: usize) -> Result<Vec<Scenario>, String> {
    let ips = increments_per_step;
    let mu = 0.2;
    let mut kinds: [Vec<Scenario>; 4] = Default::default();
    for peak in [4e3, 6e3, 8e3] {
        for steps in [10, 40] {
            let cushion = CircularMembrane {
                radius: 1.0,
                rings: 8,
                material: etfe_plastic(ParallelArch::default().material),
                pressure: peak,
            };
            kinds[0].push(cushion.inflated(peak, 300.0, steps, ips)?);
        }
    }
    for (rise, corner_drop, back) in [
        (0.15, 0.45, 0.0),
        (0.15, 0.45, 0.5),
        (0.3, 0.45, 0.5),
        (0.3, 0.6, 0.5),
    ] {
        let defaults = ArchPanel::default();
        let panel = ArchPanel {
            arch_rise: rise,
            friction: mu,
            corner_drop,
            refinement: 1,
            material: etfe_plastic(defaults.material),
            ..defaults
        };
        let mut s = panel.jacked(1, 5, None, ips)?;
        s.path.stages.push(Stage {
            air: Default::default(),
            targets: panel.jack_targets(back * panel.angle_for_drop(corner_drop)),
            steps: 5,
            friction: None,
            pressure: None,
        });
        s.name = format!("{} released to {back} of the angle", s.name);
        kinds[1].push(s);
    }
    for h in [0.2, 0.3, 0.4] {
        for contact in [SpecimenContact::Gaps, SpecimenContact::CurvedSupport] {
            let extension = 0.04;
            let specimen = ParallelArch {
                contact,
                friction: mu,
                frame_path: FramePath::Wrapped { extension },
                ..ParallelArch::with_height(h)
            };
            let specimen = ParallelArch {
                material: etfe_plastic(specimen.material),
                ..specimen
            };
            let mut s = WrappedSpecimen {
                specimen,
                steps: 40,
                release_steps: 0,
                increments_per_step: ips,
            }
            .scenario()?;
            // A quarter of the extension released: path time from 1 back to 7/8.
            let release = 10;
            s.path.stages.extend((1..=release).map(|k| Stage {
                air: Default::default(),
                targets:
                    specimen.boundary_targets(&s.model, 1.0 - 0.125 * k as f64 / release as f64),
                steps: 1,
                friction: None,
                pressure: None,
            }));
            s.name = format!("{} released to eps=0.03", s.name);
            kinds[2].push(s);
        }
    }
    for h in [0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45] {
        let mut base = SpecimenPath {
            increments_per_step: ips,
            ..SpecimenPath::monotone(h, mu, 0.5, 20)
        };
        base.specimen.material = etfe_plastic(base.specimen.material);
        for (depth, steps, shape) in [
            (1.0, 5, PathShape::Monotone),
            (1.0, 80, PathShape::Monotone),
            (1.0, 40, PathShape::Reversal),
        ] {
            kinds[3].push(
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
    // Every 10th path is one kind in turn, the rest round robin.
    let total: usize = kinds.iter().map(Vec::len).sum();
    let mut kinds = kinds.map(std::collections::VecDeque::from);
    let (mut out, mut turn) = (Vec::with_capacity(total), 0);
    for j in 0..total {
        let want = if j % 10 == 0 {
            (j / 10) % kinds.len()
        } else {
            turn = (turn + 1) % kinds.len();
            turn
        };
        let Some(mut s) =
            (0..kinds.len()).find_map(|d| kinds[(want + d) % kinds.len()].pop_front())
        else {
            break;
        };
        s.family = Family::Plastic;
        if !s.name.starts_with("cushion") {
            s.name = format!("plastic {}", s.name);
        }
        out.push(s);
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
