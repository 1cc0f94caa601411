//! The cushion family of the robustness benchmark (issue 43): a three-layer circular ETFE
//! cushion whose air is inflated by a supply, sealed, and loaded by snow until the top layer
//! inverts onto the middle layer, then unloaded.
//!
//! ```text
//!            top (snow set, faces +z)     ___----___
//!   rim  ___---                                     ---___  rim (group `rim`, held)
//!       o=================  middle (perforated) ===========o   z = 0 (flat, no pressure)
//!            ---___                                 ___---
//!                   bottom (faces −z)    ---___---
//!   chamber `air`: top + bottom; contact `landing`: top on the middle, both ways
//! ```
//!
//! The middle layer is perforated, as the middle layers of real cushions are: it is not part of
//! the chamber's boundary and carries no pressure, only what the top layer puts on it through
//! the contact. The air between top and bottom keeps its mass once sealed, so as the top comes
//! down the pressure rises (Boyle, or the adiabatic law) and the bottom sags further.

use crate::mech::elements::layer_contact::{LayerContactSpec, LayerSurface, Side};
use crate::mech::elements::triangle::Material;
use crate::mech::model::{
    ChamberSpec, ElementSelection, Model, OutputPoint, OutputSpec, PressureSet, Towards,
};
use crate::specimens::parallel_arch::ParallelArch;
use crate::specimens::scenarios::{Air, CircularMembrane, Family, LoadPath, Scenario, Stage};

/// A three-layer circular cushion (top, perforated middle, bottom) clamped at its rim, its air
/// between top and bottom.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayeredCushion {
    /// Radius of the clamped rim (m).
    pub radius: f64,
    /// Rings of triangles of each layer ([`CircularMembrane`]'s mesh, `6 rings²` triangles).
    pub rings: usize,
    /// Film of every layer.
    pub material: Material,
    /// Polytropic exponent of the sealed air (1 isothermal, 1.4 adiabatic).
    pub kappa: f64,
    /// Coulomb coefficient between the top and the middle layer.
    pub friction: f64,
    /// The supply's pressure before the air is sealed (Pa).
    pub inflation: f64,
}

impl Default for LayeredCushion {
    /// 1 m radius, 6 rings, the specimens' film, isothermal air, `μ` = 0.3, inflated to 300 Pa.
    fn default() -> Self {
        Self {
            radius: 1.0,
            rings: 6,
            material: ParallelArch::default().material,
            kappa: 1.0,
            friction: 0.3,
            inflation: 300.0,
        }
    }
}

impl LayeredCushion {
    /// Node of the crown of the top (`0`), middle (`1`) or bottom (`2`) layer.
    pub fn crown(&self, layer: usize) -> usize {
        // Each layer after the top adds the disc's interior nodes (all but the rim's 6 · rings).
        let interior = 1 + 3 * self.rings * (self.rings - 1);
        let disc = 1 + 3 * self.rings * (self.rings + 1);
        if layer == 0 {
            0
        } else {
            disc + (layer - 1) * interior
        }
    }

    /// The model: the three layers sharing the rim, pressure set `snow` on the top (towards
    /// −z, zero), chamber `air` (top and bottom, supplied at [`Self::inflation`]), layer contact
    /// `landing` (top on the middle's front, both ways, `k_n` = 10⁶ N/m, `k_s` = 10⁵ N/m).
    pub fn model(&self) -> Result<Model, String> {
        let disc = CircularMembrane {
            radius: self.radius,
            rings: self.rings,
            material: self.material,
            pressure: 0.0,
        };
        let mut m = disc.model()?;
        let per_layer = m.triangles.len();
        let n = m.nodes.len();
        let rim = disc.ring(self.rings).start;
        let top: Vec<[usize; 3]> = m.triangles.clone();
        // The middle (same order, faces +z) and the bottom (reversed, faces −z): interior nodes
        // copied, the rim shared.
        for reversed in [false, true] {
            let first = m.nodes.len();
            for v in 0..rim {
                m.nodes.push(m.nodes[v]);
            }
            let copy = |v: usize| if v >= rim { v } else { first + v };
            m.triangles.extend(top.iter().map(|t| {
                let t = t.map(copy);
                if reversed { [t[0], t[2], t[1]] } else { t }
            }));
        }
        debug_assert_eq!(m.nodes.len(), n + 2 * rim);
        let (top_set, middle_set): (Vec<usize>, Vec<usize>) = (
            (0..per_layer).collect(),
            (per_layer..2 * per_layer).collect(),
        );
        m.name = "LayeredCushion".into();
        m.description = format!(
            "three-layer cushion, radius {} m, {} rings a layer, air (kappa {}) between top and \
             bottom, perforated middle layer, snow on the top",
            self.radius, self.rings, self.kappa
        );
        m.loads.pressures = vec![PressureSet {
            name: "snow".into(),
            elements: ElementSelection::List(top_set.clone()),
            pressure: 0.0,
            towards: Some(Towards::Direction([0.0, 0.0, -1.0])),
            kind: Default::default(),
        }];
        m.chambers = vec![ChamberSpec {
            name: "air".into(),
            elements: ElementSelection::List(
                top_set
                    .iter()
                    .copied()
                    .chain(2 * per_layer..3 * per_layer)
                    .collect(),
            ),
            closed_by_plane: None,
            pressure: self.inflation,
            sealed: false,
            kappa: self.kappa,
            atmosphere: 101_325.0,
            temperature: 293.15,
            heating: 0.0,
        }];
        m.layer_contacts = vec![LayerContactSpec {
            name: "landing".into(),
            slave: LayerSurface::Triangles(top_set),
            master: LayerSurface::Triangles(middle_set),
            side: Side::Front,
            both_ways: true,
            normal_stiffness: 1e6,
            tangential_stiffness: 1e5,
            friction: self.friction,
            friction_law: Default::default(),
            search_distance: 0.3 * self.radius,
        }];
        m.outputs = OutputSpec {
            points: ["crownTop", "crownMiddle", "crownBottom"]
                .iter()
                .enumerate()
                .map(|(k, name)| OutputPoint {
                    name: (*name).into(),
                    node: self.crown(k),
                })
                .collect(),
            element_sets: vec![],
        };
        m.validate().map_err(|e| e.to_string())?;
        Ok(m)
    }

    /// The path: the supply raised to [`Self::inflation`] in 3 steps, the air sealed, snow on
    /// the top raised to `snow` (Pa) in `steps` communication steps and lowered to zero in as
    /// many.
    pub fn snowed(
        &self,
        snow: f64,
        steps: usize,
        increments_per_step: usize,
    ) -> Result<Scenario, String> {
        if steps == 0 || !snow.is_finite() {
            return Err("cushion path: steps must be ≥ 1 and the snow finite".into());
        }
        let stage = |steps, snow: f64, air| Stage {
            targets: vec![[0.0; 3]],
            steps,
            friction: None,
            pressure: Some(vec![snow]),
            air,
        };
        Ok(Scenario {
            family: Family::Cushion,
            name: format!(
                "cushion rings={} kappa={} mu={} snow={snow}Pa steps={steps}",
                self.rings, self.kappa, self.friction
            ),
            model: self.model()?,
            path: LoadPath {
                stages: vec![
                    stage(3, 0.0, Air::Supplied(vec![self.inflation])),
                    stage(steps, snow, Air::Sealed),
                    stage(steps, 0.0, Air::Kept),
                ],
                increments_per_step,
            },
        })
    }
}

/// The cushion family of the grid: [`LayeredCushion`] (radius 1 m, inflated to 300 Pa) with
/// snow ∈ {3, 4.5} kPa (the top lands on the middle layer near 2 kPa) × `μ` ∈ {0, 0.3} ×
/// `κ` ∈ {1, 1.4} × rings ∈ {6, 10}, snow raised in 10 steps and removed in 10 (16 paths; the
/// 6-ring cushions come first in each pair, so every 10th path is one of them).
pub fn cushion_paths(increments_per_step: usize) -> Result<Vec<Scenario>, String> {
    let mut out = Vec::new();
    for snow in [3000.0, 4500.0] {
        for friction in [0.0, 0.3] {
            for kappa in [1.0, 1.4] {
                for rings in [6, 10] {
                    let cushion = LayeredCushion {
                        rings,
                        kappa,
                        friction,
                        ..LayeredCushion::default()
                    };
                    out.push(cushion.snowed(snow, 10, increments_per_step)?);
                }
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::solve::{DEFAULT_INCREMENTS_PER_STEP, SolverSettings};

    /// The family's point: under the peak snow the top layer is inverted (its crown below the
    /// rim) and lies on the middle layer (within 1 mm of it), the sealed air above its
    /// inflation pressure; unloaded, the top rises back above the rim and leaves the middle.
    #[test]
    fn snow_inverts_the_top_layer_onto_the_middle_layer_and_unloading_lifts_it_off() {
        let cushion = LayeredCushion::default();
        let s = cushion
            .snowed(3000.0, 10, DEFAULT_INCREMENTS_PER_STEP)
            .unwrap();
        let (top, middle) = (cushion.crown(0), cushion.crown(1));
        let mut at_peak = None;
        let mut at_end = None;
        let outcome = s.run_observed(SolverSettings::default(), |step, analysis| {
            let z = |v| analysis.node_displacement(v).z;
            let state = (z(top), z(middle), analysis.results().chambers[0].pressure);
            if step.stage == 1 && step.step == 10 {
                at_peak = Some(state);
            }
            if step.stage == 2 && step.step == 10 {
                at_end = Some(state);
            }
        });
        assert!(outcome.converged(), "{:?}", outcome.failure_message());
        let (t, m, p) = at_peak.unwrap();
        println!("peak snow: top crown {t:.4} m, middle {m:.4} m, air {p:.1} Pa");
        assert!(t < 0.0 && (t - m).abs() < 1e-3 && p > cushion.inflation);
        let (t, m, p) = at_end.unwrap();
        println!("unloaded: top crown {t:.4} m, middle {m:.4} m, air {p:.1} Pa");
        assert!(t > 0.0 && t - m > 0.01);
    }
}
