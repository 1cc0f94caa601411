//! The arch panel: a film over a circular arch, jacked at its far corner.

use crate::mech::elements::material::{Material, Wrinkling};
use crate::mech::model::{Axis, BoundaryGroup, Model, Support};
use crate::specimens::parallel_arch::ParallelArch;
use crate::specimens::scenarios::CircularSupport;
use crate::specimens::scenarios::Family;
use crate::specimens::scenarios::GapConstants;
use crate::specimens::scenarios::LoadPath;
use crate::specimens::scenarios::Scenario;
use crate::specimens::scenarios::Stage;
use crate::specimens::scenarios::arc::arch_radius;
use crate::specimens::scenarios::arc::check_positive;
use crate::specimens::scenarios::arc::grid_id;
use crate::specimens::scenarios::arc::grid_line;
use crate::specimens::scenarios::arc::grid_triangles;
use crate::specimens::scenarios::arc::validated;
use crate::specimens::scenarios::gaps_on_arc;

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
            chambers: vec![],
            layers: vec![],
            orifices: vec![],
            layer_contacts: vec![],
            frame_axis: None,
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
                air: Default::default(),
                targets: self.jack_targets(angle * k as f64 / stages as f64),
                steps,
                friction: if k == 1 { mu } else { None },
                pressure: None,
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
