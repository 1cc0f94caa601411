//! The cylinder strip: a film strip over a cylinder, pulled down and out.

use crate::mech::elements::material::Material;
use crate::mech::model::{BoundaryGroup, Model};
use crate::specimens::parallel_arch::ParallelArch;
use crate::specimens::scenarios::CircularSupport;
use crate::specimens::scenarios::Family;
use crate::specimens::scenarios::GapConstants;
use crate::specimens::scenarios::LoadPath;
use crate::specimens::scenarios::Scenario;
use crate::specimens::scenarios::Stage;
use crate::specimens::scenarios::arc::check_positive;
use crate::specimens::scenarios::arc::validated;
use crate::specimens::scenarios::gaps_on_arc;

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
            chambers: vec![],
            layers: vec![],
            orifices: vec![],
            layer_contacts: vec![],
            frame_axis: None,
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
                    air: Default::default(),
                    targets: model.groups.iter().map(|g| g.target).collect(),
                    steps,
                    friction: None,
                    pressure: None,
                }],
                increments_per_step,
            },
            model,
        })
    }
}
