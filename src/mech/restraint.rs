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
//! **Limits.** The check is structural. Gaps count as restraints although every gap is open at
//! the start (`g = g0 + d_z ≥ 0` at zero displacement) and carries nothing until it closes, and
//! a slipping gap does not hold the tangential direction; two components joined by a single
//! node-to-node gap still rotate about it. Those models pass validation and are caught at the
//! first factorization, which reports the DOFs without stiffness by node (see `linear.rs`).

use nalgebra::{Matrix6, SymmetricEigen, Vector3, Vector6};

use super::model::{GapSupport, Model, ModelError};

/// How many node numbers a message lists before "…".
const LISTED_NODES: usize = 6;

/// Refuses models with a rigid-body mode no restraint holds; see the module doc for the rule.
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

    // Components: index, size, centroid, radius, and the first nodes for messages.
    let mut index = vec![usize::MAX; n];
    let mut parts: Vec<Component> = Vec::new();
    for v in (0..n).filter(|&v| in_film[v]) {
        let root = sets.find(v);
        if index[root] == usize::MAX {
            index[root] = parts.len();
            parts.push(Component::default());
        }
        let part = &mut parts[index[root]];
        part.count += 1;
        part.centroid += Vector3::from(model.nodes[v]);
        if part.first.len() < LISTED_NODES {
            part.first.push(v);
        }
    }
    let component = |sets: &mut DisjointSets, v: usize| index[sets.find(v)];
    parts.iter_mut().for_each(|p| p.centroid /= p.count as f64);
    for v in (0..n).filter(|&v| in_film[v]) {
        let p = &mut parts[component(&mut sets, v)];
        p.radius = p
            .radius
            .max((Vector3::from(model.nodes[v]) - p.centroid).norm());
    }

    // Restraint rows.
    let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
    for (v, h) in held.iter().enumerate() {
        if in_film[v] {
            let c = component(&mut sets, v);
            for (a, _) in h.iter().enumerate().filter(|(_, held)| **held) {
                parts[c].restrain(model.nodes[v], axes[a]);
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
            let c = component(&mut sets, v);
            for d in [g.frame.z, g.frame.x, g.frame.y] {
                parts[c].restrain(model.nodes[v], Vector3::from(d));
            }
        }
    }

    for p in &parts {
        if let Some(motion) = p.free_motion() {
            return Err(ModelError::Unrestrained {
                nodes: p.first.clone(),
                node_count: p.count,
                motion,
            });
        }
    }
    Ok(())
}

/// Which axes of each node a support, symmetry plane or group holds.
fn held_axes(model: &Model) -> Vec<[bool; 3]> {
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

    /// The first rigid-body motion no restraint holds, in words, with the number of such modes.
    fn free_motion(&self) -> Option<String> {
        let eigen = SymmetricEigen::new(self.gram);
        let largest = eigen.eigenvalues.amax().max(1.0);
        let free: Vec<usize> = (0..6)
            .filter(|&i| eigen.eigenvalues[i] <= 1e-9 * largest)
            .collect();
        let &first = free.first()?;
        let mode = eigen.eigenvectors.column(first);
        let (t, rho) = (mode.fixed_rows::<3>(0), mode.fixed_rows::<3>(3));
        let modes = match free.len() {
            1 => String::new(),
            k => format!(" ({k} rigid-body modes are free)"),
        };
        // A pure translation if the rotation part is negligible; otherwise a rotation (with
        // ω = ρ/L, the axis passes through c + ω × t / |ω|²).
        let tolerance = 1e-9 * largest;
        let axis_translation = (0..3).find(|&i| self.gram[(i, i)] <= tolerance);
        let text = if let Some(i) = axis_translation {
            format!("can translate along {}", ["X", "Y", "Z"][i])
        } else if rho.norm() < 1e-6 {
            format!("can translate along {}", direction(t.into_owned()))
        } else {
            let omega = rho / self.radius.max(f64::MIN_POSITIVE);
            let point = self.centroid + omega.cross(&t) / omega.norm_squared();
            format!(
                "can rotate about an axis along {} through ({:.4}, {:.4}, {:.4})",
                direction(omega.into_owned()),
                point.x,
                point.y,
                point.z
            )
        };
        Some(text + &modes)
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
    use crate::mech::ParallelArch;

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
