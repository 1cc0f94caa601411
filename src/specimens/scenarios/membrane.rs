//! A flat circular membrane under pressure (the peers' benchmark sheet).

use crate::mech::elements::material::Material;
use crate::mech::model::{
    AllElements, BoundaryGroup, ElementSelection, ElementSet, LoadSpec, Model, OutputPoint,
    OutputSpec, PressureSet,
};
use crate::specimens::scenarios::arc::validated;
use crate::specimens::scenarios::{Family, LoadPath, Scenario, Stage};

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
                    kind: Default::default(),
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
            chambers: vec![],
            layers: vec![],
            orifices: vec![],
            layer_contacts: vec![],
            frame_axis: None,
        })
    }

    /// A cushion's pressure cycle: the set `top` raised from zero to `peak` (Pa) in `steps`
    /// communication steps, then lowered to `deflated` in as many, the rim held (family
    /// [`Family::Plastic`]: for a film that yields on the way up and unloads on the way down).
    pub fn inflated(
        &self,
        peak: f64,
        deflated: f64,
        steps: usize,
        increments_per_step: usize,
    ) -> Result<Scenario, String> {
        if steps == 0 || !(peak.is_finite() && deflated.is_finite()) {
            return Err("cushion path: steps must be ≥ 1 and the pressures finite".into());
        }
        let stage = |p: f64| Stage {
            air: Default::default(),
            targets: vec![[0.0; 3]],
            steps,
            friction: None,
            pressure: Some(vec![p]),
        };
        Ok(Scenario {
            family: Family::Plastic,
            name: format!(
                "cushion a={} peak={peak}Pa deflated={deflated}Pa steps={steps}",
                self.radius
            ),
            model: self.model()?,
            path: LoadPath {
                stages: vec![stage(peak), stage(deflated)],
                increments_per_step,
            },
        })
    }
}
