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
//! * A load per plan area (a pressure set of kind `"plan"`, snow): `p · A_d / 3` along the unit
//!   direction `d` (`towards`, default `−z`) on each node of each triangle, `A_d = ½ |n0 · d|`
//!   the triangle's initial area projected on the plane normal to `d` (`n0` its initial
//!   node-order normal vector): a dead load, no stiffness. A flat roof at slope `θ` carries
//!   `p A cos θ`, the plan area's share, whatever its node order.
//!
//! A pressure set's sense: without `towards`, `p > 0` pushes along each triangle's node-order
//! normal; with it, each triangle's pressure is signed once, from its initial normal, so that it
//! pushes to the side facing `towards` ([`pressure_signs`]); the force and stiffness above are
//! those of the signed pressure. [`orientation`] reports how a set faces and how many triangles
//! push against their edge neighbours (a mesh with flipped triangles).

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::mech::elements::triangle::{ElementMatrix, ElementVector};
use crate::mech::model::{Model, PressureKind, PressureSet};
use crate::mech::solve::assembly::{System, node_dofs, node_vector};

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
    /// Supply pressure of each chamber (Pa), model order (a sealed chamber's is its gas's).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub chambers: Vec<f64>,
    /// Temperature rise of each chamber's air above its reference temperature (K), model order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub heating: Vec<f64>,
    /// Air mass supplied into each chamber since the analysis started (kg), model order: a
    /// running total that a step ramps like the other levels (`<chamber>.massFlow` times the
    /// step). Only a sealed chamber's air takes it in; empty reads as zeros (states written
    /// before it was kept).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub air: Vec<f64>,
    /// The analysis time (s) the levels belong to: the step's length is what moves air through
    /// the orifices ([`crate::mech::model::OrificeSpec`]); 0 in a state written before it was kept.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub time: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// `a[k] + (b[k] − a[k]) · fraction` over the longer of `a` and `b`, a missing entry read as 0.
fn lerp_padded(a: &[f64], b: &[f64], fraction: f64) -> Vec<f64> {
    let at = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(0.0);
    (0..a.len().max(b.len()))
        .map(|k| at(a, k) + (at(b, k) - at(a, k)) * fraction)
        .collect()
}

impl LoadLevels {
    /// All loads of `model` at zero (the unloaded start of an analysis).
    pub fn zero(model: &Model) -> Self {
        Self {
            pressure: vec![0.0; model.loads.pressures.len()],
            force: vec![[0.0; 3]; model.loads.forces.len()],
            gravity: [0.0; 3],
            chambers: vec![0.0; model.chambers.len()],
            heating: vec![0.0; model.chambers.len()],
            air: vec![0.0; model.chambers.len()],
            time: 0.0,
        }
    }

    /// The load values written in the model file (the targets of a standard run).
    pub fn of_model(model: &Model) -> Self {
        Self {
            pressure: model.loads.pressures.iter().map(|p| p.pressure).collect(),
            force: model.loads.forces.iter().map(|f| f.force).collect(),
            gravity: model.loads.gravity,
            chambers: model.chambers.iter().map(|c| c.pressure).collect(),
            heating: model.chambers.iter().map(|c| c.heating).collect(),
            air: vec![0.0; model.chambers.len()],
            time: 0.0,
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
            chambers: self
                .chambers
                .iter()
                .zip(&target.chambers)
                .map(|(&a, &b)| lerp(a, b))
                .collect(),
            heating: self
                .heating
                .iter()
                .zip(&target.heating)
                .map(|(&a, &b)| lerp(a, b))
                .collect(),
            air: lerp_padded(&self.air, &target.air, fraction),
            time: lerp(self.time, target.time),
        }
    }

    /// `self · factor` (a proportional load level).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            pressure: self.pressure.iter().map(|p| p * factor).collect(),
            force: self.force.iter().map(|f| f.map(|v| v * factor)).collect(),
            gravity: self.gravity.map(|g| g * factor),
            chambers: self.chambers.iter().map(|p| p * factor).collect(),
            heating: self.heating.iter().map(|t| t * factor).collect(),
            air: self.air.iter().map(|m| m * factor).collect(),
            time: self.time * factor,
        }
    }

    /// Every number, in a fixed order (for finiteness checks).
    pub fn values(&self) -> impl Iterator<Item = f64> + '_ {
        self.path()
            .chain(self.air.iter().copied())
            .chain(std::iter::once(self.time))
    }

    /// The levels a step's path moves proportionally, in a fixed order: pressures, forces,
    /// gravity, chambers' supply pressures and heating (not the air supplied, whose list may be
    /// empty, nor the time): the predictor compares successive increments' changes of them.
    pub fn path(&self) -> impl Iterator<Item = f64> + '_ {
        self.pressure
            .iter()
            .chain(self.force.iter().flatten())
            .chain(&self.gravity)
            .chain(&self.chambers)
            .chain(&self.heating)
            .copied()
    }

    /// Whether every level is finite.
    pub fn is_finite(&self) -> bool {
        self.values().all(f64::is_finite)
    }

    /// Whether the sizes match `model`'s pressure and force sets and chambers.
    pub fn fits(&self, model: &Model) -> bool {
        self.pressure.len() == model.loads.pressures.len()
            && self.force.len() == model.loads.forces.len()
            && self.chambers.len() == model.chambers.len()
            && self.heating.len() == model.chambers.len()
            && (self.air.is_empty() || self.air.len() == model.chambers.len())
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
    /// For each pressure set, the triangles (indices into `System::triangles`) it acts on and
    /// the sign of each one's pressure relative to its node-order normal ([`pressure_signs`]).
    sets: Vec<Vec<(usize, f64)>>,
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

/// Loads per plan area: for each pressure set, the nodal forces of a unit value (N/Pa; empty
/// for a follower set).
#[derive(Clone, Debug, PartialEq)]
pub struct PlanLoads {
    sets: Vec<Vec<(usize, Vector3<f64>)>>,
}

impl PlanLoads {
    /// The unit nodal forces of each pressure set of `model` of kind `"plan"`.
    fn new(model: &Model) -> Self {
        let sets = model
            .loads
            .pressures
            .iter()
            .map(|set| {
                if set.kind != PressureKind::Plan {
                    return Vec::new();
                }
                let d = plan_direction(set);
                let mut forces = Vec::new();
                for e in model.selected_triangles(&set.elements) {
                    let share = 0.5 * initial_normal(model, e).dot(&d).abs() / 3.0;
                    forces.extend(model.triangles[e].map(|v| (v, d * share)));
                }
                forces
            })
            .collect();
        Self { sets }
    }
}

/// The unit direction of a load per plan area: `towards`, else down (`−z`).
pub fn plan_direction(set: &PressureSet) -> Vector3<f64> {
    set.towards
        .map_or(-Vector3::z(), |t| Vector3::from(t.vector()).normalize())
}

impl ExternalLoad for PlanLoads {
    fn add_to(
        &self,
        _system: &System,
        levels: &LoadLevels,
        _u: &[f64],
        residual: &mut [f64],
        _values: Option<&mut [f64]>,
    ) {
        for (set, &p) in self.sets.iter().zip(&levels.pressure) {
            for &(v, f) in set {
                for c in 0..3 {
                    residual[3 * v + c] -= p * f[c];
                }
            }
        }
    }
}

/// Every external load of a model.
#[derive(Clone, Debug, PartialEq)]
pub struct Loads {
    /// Follower pressure.
    pub pressure: FollowerPressure,
    /// Loads per plan area.
    pub plan: PlanLoads,
    /// Self-weight.
    pub self_weight: SelfWeight,
    /// Nodal forces.
    pub nodal: NodalForces,
}

impl Loads {
    /// The loads of a validated `model` whose system is `system`.
    pub fn new(model: &Model, system: &System) -> Self {
        let sets = model
            .loads
            .pressures
            .iter()
            .map(|p| match p.kind {
                PressureKind::Follower => pressure_signs(model, p),
                PressureKind::Plan => Vec::new(),
            })
            .collect();
        let reference = model.nodes.iter().map(|&p| Vector3::from(p)).collect();
        let m = &model.material;
        let mut nodal_mass = vec![0.0; model.nodes.len()];
        if m.density > 0.0 {
            for (nodes, tri) in &system.triangles {
                for &v in nodes {
                    nodal_mass[v] += m.density * tri.thickness(m) * tri.area() / 3.0;
                }
            }
        }
        Self {
            pressure: FollowerPressure { sets, reference },
            plan: PlanLoads::new(model),
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
        self.plan
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

/// Triangles whose initial normal is closer than this (cosine) to perpendicular to a pressure
/// set's `towards` are refused: the side they face is not defined.
pub const EDGE_ON_COSINE: f64 = 1e-3;

/// Node-order normal `(x2 − x1) × (x3 − x1)` of triangle `e` in the initial configuration.
fn initial_normal(model: &Model, e: usize) -> Vector3<f64> {
    let x = model.triangles[e].map(|v| Vector3::from(model.nodes[v]));
    (x[1] - x[0]).cross(&(x[2] - x[0]))
}

/// The triangles of pressure set `set` with the sign of each one's pressure relative to its
/// node-order normal: `+1`, or, with `towards`, `−1` where the initial normal points away from
/// it (the pressure then pushes to the side facing `towards` on every triangle).
pub fn pressure_signs(model: &Model, set: &PressureSet) -> Vec<(usize, f64)> {
    let towards = set.towards.map(|t| Vector3::from(t.vector()));
    model
        .selected_triangles(&set.elements)
        .into_iter()
        .map(|e| {
            let sign = match &towards {
                Some(d) if initial_normal(model, e).dot(d) < 0.0 => -1.0,
                _ => 1.0,
            };
            (e, sign)
        })
        .collect()
}

/// Checks a pressure set's `towards`: finite, not zero, and no triangle of the set edge-on to it
/// (within [`EDGE_ON_COSINE`]), naming the triangle.
pub fn check_towards(model: &Model, set: &PressureSet) -> Result<(), String> {
    let Some(towards) = set.towards else {
        return Ok(());
    };
    let d = Vector3::from(towards.vector());
    if !d.iter().all(|v| v.is_finite()) || d.norm() == 0.0 {
        return Err(format!(
            "towards {:?} must be a finite, non-zero direction",
            towards.vector()
        ));
    }
    if set.kind == PressureKind::Plan {
        return Ok(()); // the load's direction: a triangle edge-on to it carries nothing
    }
    for e in model.selected_triangles(&set.elements) {
        let n = initial_normal(model, e);
        let cosine = n.dot(&d) / (n.norm() * d.norm());
        if cosine.abs() < EDGE_ON_COSINE {
            return Err(format!(
                "triangle {e} is edge-on to towards {:?} (its normal is perpendicular to it): the \
                 side it faces is not defined; split the set or give a direction the set faces",
                towards.vector()
            ));
        }
    }
    Ok(())
}

/// How a pressure set faces, as [`orientation`] finds it in the initial configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Orientation {
    /// Triangles of the set.
    pub triangles: usize,
    /// Triangles whose node-order normal points away from `towards` (their pressure is turned);
    /// 0 without `towards`.
    pub turned: usize,
    /// Triangles pushed to the other side than the majority of their patch (the triangles
    /// connected to them through shared edges): a mesh with flipped triangles, or, with
    /// `towards`, a set folding past edge-on to it.
    pub against_neighbours: usize,
    /// Area-weighted mean of the unit normals of the pushed sides (not normalised: its length
    /// is 1 for a flat set, less for a curved one).
    pub mean_direction: [f64; 3],
}

/// How pressure set `set` faces: the side a positive pressure pushes each triangle to (see
/// [`pressure_signs`]), the average of those sides, and how many triangles disagree with their
/// edge neighbours (two triangles sharing an edge push to the same side when their pushed
/// normals are wound the same way across it).
pub fn orientation(model: &Model, set: &PressureSet) -> Orientation {
    use std::collections::HashMap;
    let signed = pressure_signs(model, set);
    let (mut mean, mut area) = (Vector3::zeros(), 0.0);
    for &(e, sign) in &signed {
        let n = initial_normal(model, e);
        mean += sign * n * 0.5;
        area += 0.5 * n.norm();
    }
    // Each edge with the triangles (local index) using it and whether their pushed normal runs
    // it from the smaller node to the larger.
    let mut edges: HashMap<(usize, usize), Vec<(usize, bool)>> = HashMap::new();
    for (k, &(e, sign)) in signed.iter().enumerate() {
        let t = model.triangles[e];
        for c in 0..3 {
            let (a, b) = (t[c], t[(c + 1) % 3]);
            edges
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push((k, (a < b) == (sign > 0.0)));
        }
    }
    let mut neighbours: Vec<Vec<(usize, bool)>> = vec![vec![]; signed.len()];
    for users in edges.values() {
        for (i, &(k, forward)) in users.iter().enumerate() {
            for &(l, other) in &users[i + 1..] {
                // Same pushed side when the shared edge runs opposite ways in the two.
                let same = forward != other;
                neighbours[k].push((l, same));
                neighbours[l].push((k, same));
            }
        }
    }
    let mut side: Vec<Option<bool>> = vec![None; signed.len()];
    let mut against_neighbours = 0;
    for start in 0..signed.len() {
        if side[start].is_some() {
            continue;
        }
        side[start] = Some(true);
        let (mut stack, mut counts) = (vec![start], [0usize; 2]);
        while let Some(k) = stack.pop() {
            let s = side[k] == Some(true);
            counts[usize::from(s)] += 1;
            for &(l, same) in &neighbours[k] {
                if side[l].is_none() {
                    side[l] = Some(s == same);
                    stack.push(l);
                }
            }
        }
        against_neighbours += counts[0].min(counts[1]);
    }
    let mean = if area > 0.0 { mean / area } else { mean };
    Orientation {
        triangles: signed.len(),
        turned: signed.iter().filter(|(_, s)| *s < 0.0).count(),
        against_neighbours,
        mean_direction: mean.into(),
    }
}

/// Warnings about the pressure sets' orientation: a set with triangles pushed to the other side
/// than their neighbours, naming how many.
pub fn orientation_warnings(model: &Model) -> Vec<String> {
    let mut warnings = vec![];
    for set in model
        .loads
        .pressures
        .iter()
        .filter(|s| s.kind == PressureKind::Follower)
    {
        let o = orientation(model, set);
        if o.against_neighbours == 0 {
            continue;
        }
        let fix = if set.towards.is_some() {
            "towards turns them so: the set folds past edge-on to towards; check the direction or \
             split the set"
        } else {
            "their node order is flipped against the rest (a mesh with flipped triangles); give \
             the set \"towards\" (the side the pressure pushes to) or fix the mesh's orientation"
        };
        warnings.push(format!(
            "pressure set '{}': {} of its {} triangles are pushed to the other side than their \
             neighbours: {fix}",
            set.name, o.against_neighbours, o.triangles
        ));
    }
    warnings
}

/// One line per pressure set: the side it pushes to on average and what [`orientation`] found.
pub fn orientation_report(model: &Model) -> Vec<String> {
    model
        .loads
        .pressures
        .iter()
        .map(|set| {
            if set.kind == PressureKind::Plan {
                return plan_report(model, set);
            }
            let o = orientation(model, set);
            let m = o.mean_direction;
            let sense = match set.towards {
                Some(t) => format!(
                    "towards {:?}; {} triangles' node-order normals point away from it and are turned",
                    t.vector(),
                    o.turned
                ),
                None => "along each triangle's node-order normal".into(),
            };
            format!(
                "pressure set '{}': {} triangles, a positive pressure pushes {sense}; mean pushed \
                 normal [{:.3}, {:.3}, {:.3}]; {} triangles pushed against their neighbours",
                set.name, o.triangles, m[0], m[1], m[2], o.against_neighbours
            )
        })
        .collect()
}

/// The `check` line of a load per plan area: its direction, its plan area and the force a
/// value of 1 kPa puts on the film.
fn plan_report(model: &Model, set: &PressureSet) -> String {
    let d = plan_direction(set);
    let triangles = model.selected_triangles(&set.elements);
    let area: f64 = triangles
        .iter()
        .map(|&e| 0.5 * initial_normal(model, e).dot(&d).abs())
        .sum();
    format!(
        "pressure set '{}': {} triangles, a load per plan area along [{:.3}, {:.3}, {:.3}]; plan \
         area {area:.4} m² (1 kPa: {:.4e} N)",
        set.name,
        triangles.len(),
        d.x,
        d.y,
        d.z,
        1e3 * area
    )
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
            for &(e, sign) in set {
                let p = sign * p;
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
