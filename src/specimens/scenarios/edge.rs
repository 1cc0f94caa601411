//! The arch edge: a film whose edge lies on an arch, lowered with its frame.

use crate::mech::elements::gap::FrictionLaw;
use crate::mech::elements::material::{Material, Wrinkling};
use crate::mech::model::{Axis, BoundaryGroup, Model, Symmetry};
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
use crate::specimens::scenarios::arc::grid_triangles;
use crate::specimens::scenarios::arc::validated;
use crate::specimens::scenarios::gaps_on_arc;

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
            chambers: vec![],
            layers: vec![],
            orifices: vec![],
            layer_contacts: vec![],
            frame_axis: None,
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
                    air: Default::default(),
                    targets: vec![[0.0, 0.0, -depth * self.arch_height]],
                    steps,
                    friction: None,
                    pressure: None,
                }],
                increments_per_step,
            },
        })
    }
}
