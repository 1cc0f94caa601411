//! External loads: follower pressure on element sets, self-weight, nodal forces.
//!
//! Each load kind implements [`ExternalLoad`]: it subtracts its force from the residual
//! `R = f_int − f_ext` (over all DOFs, so that reactions of supports and groups include it) and
//! adds its load stiffness `−∂f_ext/∂u` into the slots of the Newton matrix. The solver only
//! calls [`Loads::add_to`]; a new load kind is a new type implementing the trait.
//!
//! The magnitudes of the loads at an instant are a [`LoadLevels`]; a step ramps them from the
//! converged state's levels to the target levels over its increments, like the group targets.
//!
//! * Follower pressure `p` on a triangle with current nodes `x1, x2, x3`:
//!   `f_a = p/6 · (x2 − x1) × (x3 − x1)` on each node (a third of `p` times the area vector of
//!   the deformed triangle). With `n = (x2−x1)×(x3−x1)`, `∂n/∂x_k = [x_{k+2} − x_{k+1}]×`
//!   (indices cyclic, `[v]× w = v × w`), so the load stiffness block is
//!   `K_ak = −p/6 [x_{k+2} − x_{k+1}]×`: skew blocks, unsymmetric in general.
//! * Self-weight: `ρ t A0 g / 3` on each node of each triangle (reference area: the film's mass
//!   does not change); no stiffness.
//! * Nodal forces: the set's force on each of its nodes (dead load); no stiffness.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::assembly::{System, node_dofs, node_vector};
use super::element::{ElementMatrix, ElementVector};
use super::model::{ElementSelection, Model};

/// The magnitudes of the model's loads at one instant (what a step ramps).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadLevels {
    /// Pressure of each pressure set (Pa), model order.
    pub pressure: Vec<f64>,
    /// Force on each node of each force set (N), model order.
    pub force: Vec<[f64; 3]>,
    /// Gravity acceleration (m/s²) acting on the film's mass.
    pub gravity: [f64; 3],
}

impl LoadLevels {
    /// All loads of `model` at zero (the unloaded start of an analysis).
    pub fn zero(model: &Model) -> Self {
        Self {
            pressure: vec![0.0; model.loads.pressures.len()],
            force: vec![[0.0; 3]; model.loads.forces.len()],
            gravity: [0.0; 3],
        }
    }

    /// The load values written in the model file (the targets of a standard run).
    pub fn of_model(model: &Model) -> Self {
        Self {
            pressure: model.loads.pressures.iter().map(|p| p.pressure).collect(),
            force: model.loads.forces.iter().map(|f| f.force).collect(),
            gravity: model.loads.gravity,
        }
    }

    /// `self + (target − self) · fraction`, component by component (same sizes assumed).
    pub fn interpolate(&self, target: &Self, fraction: f64) -> Self {
        let lerp = |a: f64, b: f64| a + (b - a) * fraction;
        Self {
            pressure: self
                .pressure
                .iter()
                .zip(&target.pressure)
                .map(|(&a, &b)| lerp(a, b))
                .collect(),
            force: self
                .force
                .iter()
                .zip(&target.force)
                .map(|(a, b)| std::array::from_fn(|c| lerp(a[c], b[c])))
                .collect(),
            gravity: std::array::from_fn(|c| lerp(self.gravity[c], target.gravity[c])),
        }
    }

    /// `self · factor` (a proportional load level).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            pressure: self.pressure.iter().map(|p| p * factor).collect(),
            force: self.force.iter().map(|f| f.map(|v| v * factor)).collect(),
            gravity: self.gravity.map(|g| g * factor),
        }
    }

    /// Every number, in a fixed order (for finiteness checks).
    pub fn values(&self) -> impl Iterator<Item = f64> + '_ {
        self.pressure
            .iter()
            .chain(self.force.iter().flatten())
            .chain(&self.gravity)
            .copied()
    }

    /// Whether every level is finite.
    pub fn is_finite(&self) -> bool {
        self.values().all(f64::is_finite)
    }

    /// Whether the sizes match `model`'s pressure and force sets.
    pub fn fits(&self, model: &Model) -> bool {
        self.pressure.len() == model.loads.pressures.len()
            && self.force.len() == model.loads.forces.len()
    }
}

/// A load acting on the film: its force on the nodes and its stiffness.
pub trait ExternalLoad {
    /// Subtracts the load's nodal forces at displacement `u` and levels `levels` from
    /// `residual` (all DOFs) and, when `values` is given, adds `−∂f_ext/∂u` into the Newton
    /// matrix (the system's value array). A lower-only (symmetric) matrix gets the symmetric
    /// part of an unsymmetric load stiffness.
    fn add_to(
        &self,
        system: &System,
        levels: &LoadLevels,
        u: &[f64],
        residual: &mut [f64],
        values: Option<&mut [f64]>,
    );
}

/// Follower pressure on sets of triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct FollowerPressure {
    /// For each pressure set, the triangles (indices into `System::triangles`) it acts on.
    sets: Vec<Vec<usize>>,
    /// Reference node coordinates (m).
    reference: Vec<Vector3<f64>>,
}

/// Self-weight of the film.
#[derive(Clone, Debug, PartialEq)]
pub struct SelfWeight {
    /// Lumped mass `Σ ρ t A0 / 3` of each node (kg).
    nodal_mass: Vec<f64>,
    /// Whether every mass is zero (density 0).
    weightless: bool,
}

/// Dead forces on sets of nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct NodalForces {
    /// The nodes of each force set.
    sets: Vec<Vec<usize>>,
}

/// Every external load of a model.
#[derive(Clone, Debug, PartialEq)]
pub struct Loads {
    /// Follower pressure.
    pub pressure: FollowerPressure,
    /// Self-weight.
    pub self_weight: SelfWeight,
    /// Nodal forces.
    pub nodal: NodalForces,
}

impl Loads {
    /// The loads of a validated `model` whose system is `system`.
    pub fn new(model: &Model, system: &System) -> Self {
        let all: Vec<usize> = (0..model.triangles.len()).collect();
        let sets = model
            .loads
            .pressures
            .iter()
            .map(|p| match &p.elements {
                ElementSelection::All(_) => all.clone(),
                ElementSelection::List(list) => list.clone(),
            })
            .collect();
        let reference = model.nodes.iter().map(|&p| Vector3::from(p)).collect();
        let m = &model.material;
        let mut nodal_mass = vec![0.0; model.nodes.len()];
        if m.density > 0.0 {
            for (nodes, tri) in &system.triangles {
                for &v in nodes {
                    nodal_mass[v] += m.density * m.thickness * tri.area() / 3.0;
                }
            }
        }
        Self {
            pressure: FollowerPressure { sets, reference },
            self_weight: SelfWeight {
                weightless: nodal_mass.iter().all(|&m| m == 0.0),
                nodal_mass,
            },
            nodal: NodalForces {
                sets: model.loads.forces.iter().map(|f| f.nodes.clone()).collect(),
            },
        }
    }

    /// Total mass of the film (kg).
    pub fn mass(&self) -> f64 {
        self.self_weight.nodal_mass.iter().sum()
    }
}

impl ExternalLoad for Loads {
    fn add_to(
        &self,
        system: &System,
        levels: &LoadLevels,
        u: &[f64],
        residual: &mut [f64],
        mut values: Option<&mut [f64]>,
    ) {
        self.pressure
            .add_to(system, levels, u, residual, values.as_deref_mut());
        self.self_weight
            .add_to(system, levels, u, residual, values.as_deref_mut());
        self.nodal.add_to(system, levels, u, residual, values);
    }
}

/// Force `p/6 · (x2 − x1) × (x3 − x1)` on each node of a triangle with current nodes `x`.
pub fn pressure_force(p: f64, x: &[Vector3<f64>; 3]) -> ElementVector {
    let f = (x[1] - x[0]).cross(&(x[2] - x[0])) * (p / 6.0);
    ElementVector::from_fn(|i, _| f[i % 3])
}

/// Load stiffness `−∂f/∂x` of [`pressure_force`] (9×9, unsymmetric in general): block
/// `(a, k) = −p/6 [x_{k+2} − x_{k+1}]×`, the same for every row node `a`.
pub fn pressure_stiffness(p: f64, x: &[Vector3<f64>; 3]) -> ElementMatrix {
    let mut k = ElementMatrix::zeros();
    for c in 0..3 {
        let edge = x[(c + 2) % 3] - x[(c + 1) % 3];
        let block = -(p / 6.0) * skew(&edge);
        for a in 0..3 {
            k.fixed_view_mut::<3, 3>(3 * a, 3 * c).copy_from(&block);
        }
    }
    k
}

/// `[v]×`, the matrix of `w ↦ v × w`.
fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

impl ExternalLoad for FollowerPressure {
    fn add_to(
        &self,
        system: &System,
        levels: &LoadLevels,
        u: &[f64],
        residual: &mut [f64],
        mut values: Option<&mut [f64]>,
    ) {
        let symmetric = system.is_lower_only();
        for (set, &p) in self.sets.iter().zip(&levels.pressure) {
            if p == 0.0 {
                continue;
            }
            for &e in set {
                let nodes = &system.triangles[e].0;
                let x = nodes.map(|v| self.reference[v] + node_vector(u, v));
                let f = pressure_force(p, &x);
                for (i, g) in node_dofs(nodes).into_iter().enumerate() {
                    residual[g] -= f[i];
                }
                if let Some(v) = values.as_deref_mut() {
                    let k = pressure_stiffness(p, &x);
                    if symmetric {
                        system.add_element_matrix(e, &(0.5 * (k + k.transpose())), v);
                    } else {
                        system.add_element_matrix(e, &k, v);
                    }
                }
            }
        }
    }
}

impl ExternalLoad for SelfWeight {
    fn add_to(
        &self,
        _system: &System,
        levels: &LoadLevels,
        _u: &[f64],
        residual: &mut [f64],
        _values: Option<&mut [f64]>,
    ) {
        // A weightless film (density 0, the default) costs nothing.
        if levels.gravity == [0.0; 3] || self.weightless {
            return;
        }
        for (v, &m) in self.nodal_mass.iter().enumerate() {
            for c in 0..3 {
                residual[3 * v + c] -= m * levels.gravity[c];
            }
        }
    }
}

impl ExternalLoad for NodalForces {
    fn add_to(
        &self,
        _system: &System,
        levels: &LoadLevels,
        _u: &[f64],
        residual: &mut [f64],
        _values: Option<&mut [f64]>,
    ) {
        for (nodes, force) in self.sets.iter().zip(&levels.force) {
            for &v in nodes {
                for c in 0..3 {
                    residual[3 * v + c] -= force[c];
                }
            }
        }
    }
}
