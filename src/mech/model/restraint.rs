//! Rigid-body modes that no restraint holds: a structural check of a model before any analysis.
//!
//! A model whose free DOFs allow a rigid-body motion has a singular Newton matrix: the
//! factorization divides by a zero pivot and the answer is NaN. [`check`] finds such models when
//! they are validated, in time linear in the model's size.
//!
//! **The rule** (the paper leaves it open; it is written here once):
//! * A node that belongs to no triangle must have all three DOFs held by a support, symmetry
//!   plane or boundary group. Only its gaps act on it, and their forces must balance, so they
//!   cannot fix its position (a single gap must be open; an open gap has no stiffness).
//! * The film nodes form *components*: nodes joined by triangles, and by node-to-node gaps
//!   between two film nodes (the gap is counted as a joint). Each component moves rigidly by
//!   `u(x) = t + ω × (x − c)` (3 translations, 3 rotations; `c` its centroid).
//! * Restraints of a component, each a direction `d` at a node `x` that the motion must not move
//!   along (`d·(t + ω × (x − c)) = 0`): a support's fixed axes, a symmetry plane's normal, the
//!   three axes of a node in a boundary group, and for a gap from a film node to a fixed point
//!   or to a held node: its frame's `z` and, since every gap has `k_s > 0`, its `x` and `y`.
//! * The modes no restraint holds are the null space of the 6 × 6 Gram matrix `Σ a aᵀ` of the
//!   restraint rows `a = (d, (x − c)/L × d)` (`L` the component's radius, so that both halves
//!   are lengths): eigenvalues below `1e-9` of the largest (or of 1) count as zero.
//!
//! **Initial stress** (issue 17): a mode the restraints leave free may still be held by the
//! stress the film carries before any load, the prestress of the film and of the cables (loads
//! start at zero and every gap is open, so nothing else is stressed at validation). A taut
//! string, or a flat prestressed triangle whose third node is held in x and y only, resists
//! moving across: the geometric stiffness. The criterion, for the free modes `V` of a component
//! (its columns are the nodal displacements of the rigid-body motions above):
//! * `K0` is the Newton matrix at the initial state (zero displacement): material plus geometric
//!   stiffness of the triangles and the cables, assembled by the elements' own code. Its material
//!   part vanishes on rigid motions, so `M = Vᵀ K0 V` is the geometric energy of the modes,
//!   `Σ_e V0 σ0 : (∇u)ᵀ∇u` (a translation has `∇u = 0`: prestress never holds one).
//! * The modes are held if `M` is positive definite, its smallest eigenvalue above `1e-8` of
//!   `E·t·A/L²` (`A` the component's area): a prestress above about `1e-8·E` across the mode.
//! * And the initial state is an equilibrium on the component's free DOFs: the initial nodal
//!   forces along every axis that no support, symmetry plane or group holds are below `1e-6` of
//!   the component's largest initial nodal force. Then `M` is the second variation of the energy
//!   along the modes at a state of equilibrium: positive definite, no combination of them is a
//!   motion without energy there (the Newton matrix has no null vector in their span).
//!   Otherwise the solver moves the unbalanced nodes until the prestress that gave `M` is
//!   relieved: a square held at one corner and in z only gets
//!   `uᵀ K0 u = t·A·(σx + σy) ω² > 0` for its in-plane rotation, but its free edges contract to a
//!   stress-free state in which the rotation is free again. Such modes are refused, the message
//!   naming the unbalanced node.
//!
//! A refused mode is described by the combination of free modes with the least energy (the
//! first free mode, as the restraints alone find it, when the prestress holds none).
//!
//! **Limits.** The check is structural. Gaps count as restraints although every gap is open at
//! the start (`g = g0 + d_z ≥ 0` at zero displacement) and carries nothing until it closes, and
//! a slipping gap does not hold the tangential direction; two components joined by a single
//! node-to-node gap still rotate about it. A prestress that holds a mode at the start may be
//! lost under load (a wrinkled or slack film). Those models pass validation and are caught at
//! the first factorization, which reports the DOFs without stiffness by node (see `solve/linear`).

use nalgebra::{DMatrix, Matrix6, SymmetricEigen, Vector3, Vector6};

use crate::mech::elements::cable::segment_force_and_tangent;
use crate::mech::elements::triangle::ElementVector;
use crate::mech::model::{GapSupport, Model, ModelError};

/// How many node numbers a message lists before "…".
const LISTED_NODES: usize = 6;

/// Smallest energy of a free mode under the initial tangent that counts as held, as a fraction
/// of `E·t·A/L²` (module doc): a prestress of about `1e-8·E` across the mode.
const STIFFENING_RATIO: f64 = 1e-8;

/// Largest initial force on a free DOF, as a fraction of the component's largest initial nodal
/// force, of a state that counts as an equilibrium (module doc).
const EQUILIBRIUM_TOLERANCE: f64 = 1e-6;

/// Refuses models with a rigid-body mode that neither a restraint nor the initial stress holds;
/// see the module doc for the rule.
pub fn check(model: &Model) -> Result<(), ModelError> {
    let n = model.nodes.len();
    let held = held_axes(model);
    let mut in_film = vec![false; n];
    let mut sets = DisjointSets::new(n);
    for t in &model.triangles {
        t.iter().for_each(|&v| in_film[v] = true);
        sets.union(t[0], t[1]);
        sets.union(t[0], t[2]);
    }
    for (v, h) in held.iter().enumerate() {
        if !in_film[v] && !h.iter().all(|&x| x) {
            return Err(ModelError::Unconnected { node: v });
        }
    }
    for g in &model.gaps {
        if let GapSupport::Node(b) = g.support
            && in_film[g.film_node]
            && in_film[b]
        {
            sets.union(g.film_node, b);
        }
    }

    // Components: index of each film node's, size, centroid, radius, first nodes for messages.
    let mut index = vec![usize::MAX; n];
    let mut part_of = vec![usize::MAX; n];
    let mut parts: Vec<Component> = Vec::new();
    for v in (0..n).filter(|&v| in_film[v]) {
        let root = sets.find(v);
        if index[root] == usize::MAX {
            index[root] = parts.len();
            parts.push(Component::default());
        }
        part_of[v] = index[root];
        let part = &mut parts[index[root]];
        part.count += 1;
        part.centroid += Vector3::from(model.nodes[v]);
        if part.first.len() < LISTED_NODES {
            part.first.push(v);
        }
    }
    parts.iter_mut().for_each(|p| p.centroid /= p.count as f64);
    for v in (0..n).filter(|&v| in_film[v]) {
        let p = &mut parts[part_of[v]];
        p.radius = p
            .radius
            .max((Vector3::from(model.nodes[v]) - p.centroid).norm());
    }

    // Restraint rows.
    let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
    for (v, h) in held.iter().enumerate() {
        if in_film[v] {
            for (a, _) in h.iter().enumerate().filter(|(_, held)| **held) {
                parts[part_of[v]].restrain(model.nodes[v], axes[a]);
            }
        }
    }
    for g in &model.gaps {
        let film = match g.support {
            GapSupport::Point(_) => Some(g.film_node),
            GapSupport::Node(b) => match (in_film[g.film_node], in_film[b]) {
                (true, false) => Some(g.film_node),
                (false, true) => Some(b),
                _ => None, // joined above, or both held
            },
        };
        if let Some(v) = film.filter(|&v| in_film[v]) {
            for d in [g.frame.z, g.frame.x, g.frame.y] {
                parts[part_of[v]].restrain(model.nodes[v], Vector3::from(d));
            }
        }
    }

    for (i, p) in parts.iter().enumerate() {
        let modes = p.free_modes();
        if modes.is_empty() {
            continue;
        }
        let (motion, note) = match initial_stiffness(model, &part_of, i, p, &modes, &held) {
            InitialStiffness::Holds => continue,
            InitialStiffness::Free { mode, count } => (p.describe(&mode, count), None),
            InitialStiffness::Unbalanced { node, axis, force } => (
                p.describe(&modes[0], modes.len()),
                Some(format!(
                    "its prestress would stiffen this motion but is not in equilibrium: node \
                     {node} carries an initial force of {force:.3e} N along {} that nothing holds, \
                     so the film relaxes until that stress is gone",
                    ["X", "Y", "Z"][axis]
                )),
            ),
        };
        return Err(ModelError::Unrestrained {
            nodes: p.first.clone(),
            node_count: p.count,
            motion,
            note,
        });
    }
    Ok(())
}

/// What the initial stress does to the free modes of a component (module doc).
enum InitialStiffness {
    /// It holds them all.
    Holds,
    /// It leaves `count` of them free (without energy), `mode` the one with the least.
    Free { mode: Vector6<f64>, count: usize },
    /// It would hold them, but the initial state is not an equilibrium: the largest force on a
    /// free DOF (N) and where.
    Unbalanced {
        node: usize,
        axis: usize,
        force: f64,
    },
}

/// Energy of the free `modes` of component `part` (index `i`) under the Newton matrix at zero
/// displacement, and the initial forces on its free DOFs (module doc).
fn initial_stiffness(
    model: &Model,
    part_of: &[usize],
    i: usize,
    part: &Component,
    modes: &[Vector6<f64>],
    held: &[[bool; 3]],
) -> InitialStiffness {
    let k = modes.len();
    let length = part.radius.max(f64::MIN_POSITIVE);
    // Displacement of node `v` in mode `a = (t, ρ)`: `t + (ρ/L) × (x − c)`.
    let at = |a: &Vector6<f64>, v: usize| -> Vector3<f64> {
        let (t, rho) = (a.fixed_rows::<3>(0), a.fixed_rows::<3>(3));
        t + (rho / length).cross(&(Vector3::from(model.nodes[v]) - part.centroid))
    };
    let mut energy = DMatrix::<f64>::zeros(k, k);
    let mut force = vec![Vector3::<f64>::zeros(); model.nodes.len()];
    let mut area = 0.0;
    let mut add = |nodes: &[usize], f: &[f64], kt: &dyn Fn(usize, usize) -> f64| {
        for (j, &v) in nodes.iter().enumerate() {
            force[v] += Vector3::new(f[3 * j], f[3 * j + 1], f[3 * j + 2]);
        }
        let u: Vec<Vec<f64>> = modes
            .iter()
            .map(|a| {
                nodes
                    .iter()
                    .flat_map(|&v| {
                        let d = at(a, v);
                        [d.x, d.y, d.z]
                    })
                    .collect()
            })
            .collect();
        let m = 3 * nodes.len();
        // K·u of each mode, then the energies uᵀ K u (the matrix is symmetric).
        let ku: Vec<Vec<f64>> = u
            .iter()
            .map(|uq| {
                (0..m)
                    .map(|r| (0..m).map(|c| kt(r, c) * uq[c]).sum())
                    .collect()
            })
            .collect();
        for p in 0..k {
            for q in p..k {
                let e: f64 = (0..m).map(|r| u[p][r] * ku[q][r]).sum();
                energy[(p, q)] += e;
                if q != p {
                    energy[(q, p)] += e;
                }
            }
        }
    };
    let zero = ElementVector::zeros();
    for (e, t) in (model.triangles.iter().enumerate()).filter(|(_, t)| part_of[t[0]] == i) {
        let Ok(element) = model.element_on(e, &model.nodes) else {
            continue; // validation refused it before this check
        };
        area += element.area();
        let (f, kt) = element.force_and_tangent(&model.material, &zero, true);
        add(t, f.as_slice(), &|r, s| kt[(r, s)]);
    }
    for c in &model.cables {
        for pair in c.nodes.windows(2).filter(|p| part_of[p[0]] == i) {
            let [a, b] = [pair[0], pair[1]].map(|v| Vector3::from(model.nodes[v]));
            let ea = c.youngs_modulus * c.area;
            let (f, kt) = segment_force_and_tangent(&a, &b, (a - b).norm(), ea, c.prestress_force);
            add(pair, f.as_slice(), &|r, s| kt[(r, s)]);
        }
    }

    let eigen = SymmetricEigen::new(energy);
    let scale = model.material.membrane_stiffness() * area / (length * length);
    let free: Vec<usize> = (0..k)
        .filter(|&j| {
            let energy = eigen.eigenvalues[j];
            energy.is_nan() || energy <= STIFFENING_RATIO * scale
        })
        .collect();
    if free.len() == k {
        // Nothing holds them: the first, as the restraints alone describe it.
        return InitialStiffness::Free {
            mode: modes[0],
            count: k,
        };
    }
    if let Some(&least) = free
        .iter()
        .min_by(|&&a, &&b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]))
    {
        let x = eigen.eigenvectors.column(least);
        let mode = modes
            .iter()
            .zip(x.iter())
            .fold(Vector6::zeros(), |m, (a, w)| m + a * *w);
        return InitialStiffness::Free {
            mode,
            count: free.len(),
        };
    }
    let nodes = || (0..model.nodes.len()).filter(|&v| part_of[v] == i);
    let largest = nodes().map(|v| force[v].amax()).fold(0.0, f64::max);
    let worst = nodes()
        .flat_map(|v| (0..3).filter(move |&c| !held[v][c]).map(move |c| (v, c)))
        .max_by(|&(v, c), &(w, d)| force[v][c].abs().total_cmp(&force[w][d].abs()));
    match worst {
        Some((node, axis)) if force[node][axis].abs() > EQUILIBRIUM_TOLERANCE * largest => {
            InitialStiffness::Unbalanced {
                node,
                axis,
                force: force[node][axis],
            }
        }
        _ => InitialStiffness::Holds,
    }
}

/// Which axes of each node a support, symmetry plane or group holds.
pub(crate) fn held_axes(model: &Model) -> Vec<[bool; 3]> {
    let mut held = vec![[false; 3]; model.nodes.len()];
    for s in &model.supports {
        s.fixed.iter().for_each(|a| held[s.node][a.index()] = true);
    }
    for s in &model.symmetry {
        s.nodes
            .iter()
            .for_each(|&v| held[v][s.normal.index()] = true);
    }
    for g in &model.groups {
        let prescribed = g.prescribes();
        for &v in &g.nodes {
            (0..3).for_each(|c| held[v][c] |= prescribed[c]);
        }
    }
    held
}

/// One film component and the Gram matrix of its restraint rows (added after the radius pass).
#[derive(Default)]
struct Component {
    count: usize,
    centroid: Vector3<f64>,
    radius: f64,
    first: Vec<usize>,
    gram: Matrix6<f64>,
}

impl Component {
    /// Adds the restraint "node at `x` does not move along `d`".
    fn restrain(&mut self, x: [f64; 3], d: Vector3<f64>) {
        let d = d.normalize();
        let arm = (Vector3::from(x) - self.centroid) / self.radius.max(f64::MIN_POSITIVE);
        let r = arm.cross(&d);
        let a = Vector6::new(d.x, d.y, d.z, r.x, r.y, r.z);
        self.gram += a * a.transpose();
    }

    /// The rigid-body motions no restraint holds (a basis, unit vectors `(t, ρ)`, `ω = ρ/L`).
    fn free_modes(&self) -> Vec<Vector6<f64>> {
        let eigen = SymmetricEigen::new(self.gram);
        let largest = eigen.eigenvalues.amax().max(1.0);
        (0..6)
            .filter(|&i| eigen.eigenvalues[i] <= 1e-9 * largest)
            .map(|i| eigen.eigenvectors.column(i).into_owned())
            .collect()
    }

    /// The free motion `mode` in words, with the number `count` of free modes when above one.
    fn describe(&self, mode: &Vector6<f64>, count: usize) -> String {
        let (t, rho) = (mode.fixed_rows::<3>(0), mode.fixed_rows::<3>(3));
        let modes = match count {
            1 => String::new(),
            k => format!(" ({k} rigid-body modes are free)"),
        };
        // A pure translation if the rotation part is negligible; otherwise a rotation (with
        // ω = ρ/L, the axis passes through c + ω × t / |ω|²).
        let tolerance = 1e-9 * SymmetricEigen::new(self.gram).eigenvalues.amax().max(1.0);
        let axis_translation = (0..3).find(|&i| self.gram[(i, i)] <= tolerance);
        let text = if let Some(i) = axis_translation {
            format!("can translate along {}", ["X", "Y", "Z"][i])
        } else if rho.norm() < 1e-6 * mode.norm() {
            format!("can translate along {}", direction(t.into_owned()))
        } else {
            let omega = rho / self.radius.max(f64::MIN_POSITIVE);
            // Exact zeros print without a sign ("-0.0000" for a round-off of −1e-18).
            let point = (self.centroid + omega.cross(&t) / omega.norm_squared())
                .map(|v| if v.abs() < 5e-5 { 0.0 } else { v });
            format!(
                "can rotate about an axis along {} through ({:.4}, {:.4}, {:.4})",
                direction(omega.into_owned()),
                point.x,
                point.y,
                point.z
            )
        };
        text + &modes
    }
}

/// `X`, `Y`, `Z` for a direction along an axis, else the unit vector (first non-zero
/// component positive).
fn direction(v: Vector3<f64>) -> String {
    let mut v = v.normalize();
    if let Some(first) = v.iter().find(|c| c.abs() > 1e-9)
        && *first < 0.0
    {
        v = -v;
    }
    let v = v.map(|c| if c.abs() < 5e-4 { 0.0 } else { c });
    for (name, axis) in ["X", "Y", "Z"].iter().zip(0..3) {
        if v[axis].abs() > 0.9999 {
            return (*name).to_string();
        }
    }
    format!("({:.3}, {:.3}, {:.3})", v.x, v.y, v.z)
}

/// Union–find with path halving and union by size.
struct DisjointSets {
    parent: Vec<usize>,
    size: Vec<u32>,
}

impl DisjointSets {
    fn new(n: usize) -> Self {
        Self {
            parent: (0..n).collect(),
            size: vec![1; n],
        }
    }

    fn find(&mut self, mut v: usize) -> usize {
        while self.parent[v] != v {
            self.parent[v] = self.parent[self.parent[v]];
            v = self.parent[v];
        }
        v
    }

    fn union(&mut self, a: usize, b: usize) {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        if self.size[a] < self.size[b] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b] = a;
        self.size[a] += self.size[b];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::specimens::ParallelArch;

    /// A 0.1 m square of two triangles (nodes 0..3 counter-clockwise from the origin) with the
    /// given supports and gaps (JSON fragments).
    fn square(supports: &str, gaps: &str) -> Result<Model, ModelError> {
        Model::from_json(&format!(
            r#"{{ "name": "Sq", "nodes": [[0,0,0], [0.1,0,0], [0.1,0.1,0], [0,0.1,0]],
                 "triangles": [[0,1,2], [0,2,3]],
                 "material": {{ "youngs_modulus": 1e9, "poisson_ratio": 0.43, "thickness": 250e-6,
                                "prestress": [5e5, 5e5, 0] }},
                 "supports": [{supports}], "gaps": [{gaps}] }}"#
        ))
    }

    fn gap_to_point(name: &str, node: usize, point: [f64; 3]) -> String {
        // The patch lies in z = 0: the gap is the support point's depth.
        let gap = -point[2];
        format!(
            r#"{{ "name": "{name}", "film_node": {node}, "support": {{ "point": {point:?} }},
                 "frame": {{ "x": [1,0,0], "y": [0,1,0], "z": [0,0,1] }}, "initial_gap": {gap},
                 "normal_stiffness": 2.5e8, "tangential_stiffness": 2.5e7, "friction": 0.2 }}"#
        )
    }

    #[test]
    fn patch_free_to_slide_along_y_is_refused_with_its_nodes() {
        let supports = (0..4)
            .map(|v| format!(r#"{{ "node": {v}, "fixed": ["z"] }}"#))
            .chain([r#"{ "node": 0, "fixed": ["x"] }"#.to_string()])
            .chain([r#"{ "node": 3, "fixed": ["x"] }"#.to_string()])
            .collect::<Vec<_>>()
            .join(",");
        let err = square(&supports, "").unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, ModelError::Unrestrained { .. }), "{text}");
        assert!(text.contains("can translate along Y"), "{text}");
        assert!(text.contains("nodes 0, 1, 2, 3 (4 nodes)"), "{text}");
    }

    #[test]
    fn patch_held_at_two_points_can_rotate_about_the_line_through_them() {
        let err = square(
            r#"{ "node": 0, "fixed": ["x", "y", "z"] }, { "node": 2, "fixed": ["x", "y", "z"] }"#,
            "",
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains(
                "can rotate about an axis along (0.707, 0.707, 0.000) through (0.0500, 0.0500, 0.0000)"
            ),
            "{err}"
        );
    }

    /// The issue's triangle: nodes 0 and 1 held in x, y, z on the X axis, node 2 above them
    /// held in x and y only, with `material` and `cables` (JSON fragments).
    fn triangle(material: &str, cables: &str) -> Result<Model, ModelError> {
        Model::from_json(&format!(
            r#"{{ "name": "Tri", "nodes": [[0,0,0], [0.1,0,0], [0.05,0.1,0]],
                 "triangles": [[0,1,2]], "material": {material},
                 "supports": [{{ "node": 0, "fixed": ["x", "y", "z"] }},
                              {{ "node": 1, "fixed": ["x", "y", "z"] }},
                              {{ "node": 2, "fixed": ["x", "y"] }}],
                 "cables": [{cables}] }}"#
        ))
    }

    fn film(prestress: [f64; 3]) -> String {
        format!(
            r#"{{ "youngs_modulus": 1e9, "poisson_ratio": 0.43, "thickness": 250e-6,
                 "prestress": {prestress:?} }}"#
        )
    }

    #[test]
    fn prestress_across_the_hinge_holds_the_node_held_in_plane_only() {
        triangle(&film([5e5, 5e5, 0.0]), "").unwrap();
        // Across is y: σy alone holds it.
        triangle(&film([0.0, 5e5, 0.0]), "").unwrap();
    }

    #[test]
    fn without_prestress_across_the_hinge_the_triangle_is_refused_as_today() {
        // Node 2 turns about the line through nodes 0 and 1; the axis point printed is the one
        // nearest the centroid (0.05, 0.0333, 0).
        let today = "the film part with nodes 0, 1, 2 (3 nodes) can rotate about an axis along X \
                     through (0.0500, 0.0000, 0.0000): no support, symmetry plane, boundary group \
                     or gap restrains it (singular system)";
        for prestress in [[0.0; 3], [5e5, 0.0, 0.0]] {
            let err = triangle(&film(prestress), "").unwrap_err();
            assert!(matches!(err, ModelError::Unrestrained { .. }), "{err}");
            assert_eq!(err.to_string(), today, "prestress {prestress:?}");
        }
    }

    #[test]
    fn a_prestressed_cable_across_the_hinge_holds_it_too() {
        let cable = |force: f64| {
            format!(
                r#"{{ "name": "Edge", "nodes": [0, 2], "area": 1e-6, "youngs_modulus": 1e11,
                     "prestress_force": {force} }}"#
            )
        };
        triangle(&film([0.0; 3]), &cable(10.0)).unwrap();
        let err = triangle(&film([0.0; 3]), &cable(0.0)).unwrap_err();
        assert!(
            err.to_string().contains("can rotate about an axis along X"),
            "{err}"
        );
    }

    #[test]
    fn prestress_that_is_not_in_equilibrium_does_not_hold_a_rotation() {
        // z held everywhere and x, y at node 0 only: the in-plane rotation about node 0 has
        // uᵀ K0 u = t·A·(σx + σy)·ω² > 0, but nothing holds the edges in-plane, so the film
        // contracts until the stress, and the stiffness, are gone.
        let supports = (1..4)
            .map(|v| format!(r#"{{ "node": {v}, "fixed": ["z"] }}"#))
            .chain([r#"{ "node": 0, "fixed": ["x", "y", "z"] }"#.to_string()])
            .collect::<Vec<_>>()
            .join(",");
        let err = square(&supports, "").unwrap_err().to_string();
        assert!(
            err.contains("can rotate about an axis along Z through (0.0000, 0.0000, 0.0000)"),
            "{err}"
        );
        assert!(
            err.contains("restrains it (singular system); its prestress would stiffen this motion but is not in equilibrium"),
            "{err}"
        );
    }

    #[test]
    fn three_supports_that_are_not_collinear_hold_the_patch() {
        let xyz = |v: usize| format!(r#"{{ "node": {v}, "fixed": ["x", "y", "z"] }}"#);
        square(&[xyz(0), xyz(1), xyz(2)].join(","), "").unwrap();
        // Fewer fixed axes also do, if they take all six modes: z at three corners, x at two
        // nodes on a line along y and y at one node.
        square(
            r#"{ "node": 0, "fixed": ["x", "y", "z"] }, { "node": 3, "fixed": ["x", "z"] },
               { "node": 1, "fixed": ["z"] }"#,
            "",
        )
        .unwrap();
    }

    #[test]
    fn gaps_to_fixed_points_count_as_restraints() {
        let gaps = [(0, "A"), (1, "B"), (3, "C")]
            .map(|(v, name)| gap_to_point(name, v, [0.0, 0.0, -0.01]))
            .join(",");
        square("", &gaps).unwrap();
        // One gap leaves the rotations free.
        let one = gap_to_point("A", 0, [0.0, 0.0, -0.01]);
        let err = square("", &one).unwrap_err().to_string();
        assert!(err.contains("can rotate"), "{err}");
    }

    #[test]
    fn node_held_only_by_a_gap_is_refused() {
        let mut model = ParallelArch::default().model().unwrap();
        let v = model.nodes.len();
        // Beside the first gap's film node along its sliding direction: the same initial gap.
        let (a, x) = (model.nodes[model.gaps[0].film_node], model.gaps[0].frame.x);
        model
            .nodes
            .push(std::array::from_fn(|c| a[c] + 0.01 * x[c]));
        let mut gap = model.gaps[0].clone();
        gap.name = "Lonely".into();
        gap.film_node = v;
        model.gaps.push(gap);
        let err = model.validate().unwrap_err();
        assert_eq!(err, ModelError::Unconnected { node: v });
        assert!(err.to_string().contains("belongs to no triangle"));
    }

    #[test]
    fn specimens_validate() {
        for arch_height in [0.2, 0.3, 0.4] {
            let spec = ParallelArch {
                arch_height,
                ..Default::default()
            };
            spec.model().unwrap().validate().unwrap();
        }
    }
}
