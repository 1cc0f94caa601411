//! Free edges of a prestressed film: boundary edges that the prestress pulls across and that
//! nothing holds, found before any step so that `check` and the FMU's instantiation can warn.
//!
//! A film edge that belongs to exactly one triangle carries the traction `σ0 · m` of the
//! prestress across it (`m` the edge's outward normal in the triangle's plane, `σ0` in the
//! triangle's frame, eq. 2.3): at the start the element pulls its two nodes inward with the
//! force `t · L · σ0 · m` (`t` the thickness, `L` the edge's length). Unless something holds
//! them, the initial state is not an equilibrium and the first step pulls the edge in until the
//! prestress across it is gone: a wrinkled band along the edge and a slow first step (issue 47
//! item 8: 302 of 728 elements wrinkled on a vault roof, a 100 s first stage).
//!
//! **The rule.** A boundary edge is *free* when the prestress pulls across it (the traction above
//! [`ACROSS_FRACTION`] of the prestress's largest principal value) and one of its nodes is not
//! held along that pull. A node is held along a unit direction `d` when
//! * a support, symmetry plane or boundary group fixes enough of its axes that the part of `d`
//!   along its free axes is at most [`FREE_PULL_FRACTION`] (a symmetry plane normal to the pull
//!   holds a symmetry edge; a support fixing `z` only does not hold a flat film's edge in-plane);
//! * or a gap or a curved support acts on it (counted as holding, as the restraint check counts
//!   gaps: the user put the film on that support on purpose);
//! * an edge is also held when an edge cable runs along it (a consecutive pair of a cable's
//!   nodes), whatever its nodes: the cable is the usual way to carry a film's edge.

use nalgebra::{Matrix2, Vector2, Vector3};

use super::format::Model;

/// Smallest traction across a boundary edge, as a fraction of the prestress's largest principal
/// value, that counts as a pull: a film prestressed in one direction only (`[σx, 0, 0]`) pulls
/// no edge parallel to it (its traction is exactly zero, or round-off at 1e-16); 0.1 % keeps
/// round-off and negligible shear out and every edge a prestress really pulls in.
pub const ACROSS_FRACTION: f64 = 1e-3;

/// Largest part of a pull's unit direction along a node's free axes for which the node counts
/// as held: 0.1, the pull within about 6° of the held axes. A support, plane or group at a
/// larger angle to the pull lets the node slide along the film's plane.
pub const FREE_PULL_FRACTION: f64 = 0.1;

/// How many chains a warning names before "…".
const LISTED_CHAINS: usize = 3;

/// One free edge: its two nodes.
type Edge = [usize; 2];

/// The free edges of `model` (module doc), each `[a, b]` with `a < b`, in the order of their
/// triangles. Empty when the film has no prestress. Triangles with unknown or repeated nodes,
/// or degenerate, are skipped (validation refuses them).
pub fn free_edges(model: &Model) -> Vec<Edge> {
    let [sx, sy, txy] = model.material.prestress;
    let sigma = Matrix2::new(sx, txy, txy, sy);
    let largest = sigma.symmetric_eigenvalues().amax();
    if largest.is_nan() || largest <= 0.0 {
        return vec![];
    }
    let n = model.nodes.len();
    let held = super::restraint::held_axes(model);
    let mut contact = vec![false; n];
    for g in &model.gaps {
        let support = match g.support {
            super::GapSupport::Node(b) => Some(b),
            super::GapSupport::Point(_) => None,
        };
        for v in [Some(g.film_node), support].into_iter().flatten() {
            if v < n {
                contact[v] = true;
            }
        }
    }
    for s in &model.curved_supports {
        s.nodes
            .iter()
            .filter(|&&v| v < n)
            .for_each(|&v| contact[v] = true);
    }
    let cabled: std::collections::HashSet<Edge> = model
        .cables
        .iter()
        .flat_map(|c| c.nodes.windows(2).map(|p| sorted([p[0], p[1]])))
        .collect();
    let held_along = |v: usize, d: Vector3<f64>| {
        let free: f64 = (0..3).filter(|&c| !held[v][c]).map(|c| d[c] * d[c]).sum();
        contact[v] || free.sqrt() <= FREE_PULL_FRACTION
    };
    let mut count = std::collections::HashMap::<Edge, usize>::new();
    for t in &model.triangles {
        for (i, j) in [(0, 1), (1, 2), (2, 0)] {
            *count.entry(sorted([t[i], t[j]])).or_default() += 1;
        }
    }
    let mut free = vec![];
    for (e, t) in (model.triangles.iter().enumerate()).filter(|(_, t)| t.iter().all(|&v| v < n)) {
        let Ok(element) = model.element_on(e, &model.nodes) else {
            continue;
        };
        let (e1, e2) = element.local_axes();
        for (i, j, k) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)] {
            let edge = sorted([t[i], t[j]]);
            if count[&edge] != 1 || cabled.contains(&edge) {
                continue;
            }
            let [a, b, c] = [t[i], t[j], t[k]].map(|v| Vector3::from(model.nodes[v]));
            let along = b - a;
            let away = (a - c) - along * along.dot(&(a - c)) / along.norm_squared();
            let m = Vector2::new(away.dot(&e1), away.dot(&e2)).normalize();
            let traction = sigma * m;
            if traction.norm() <= ACROSS_FRACTION * largest {
                continue;
            }
            let pull = (e1 * traction.x + e2 * traction.y).normalize();
            if !(held_along(edge[0], pull) && held_along(edge[1], pull)) {
                free.push(edge);
            }
        }
    }
    free
}

fn sorted([a, b]: Edge) -> Edge {
    [a.min(b), a.max(b)]
}

/// The free edges joined into chains (edges sharing a node), each described by its end nodes
/// and length: `nodes 4 to 9 (5 segments)`, or `a closed loop through node 4 (12 segments)`.
fn chains(edges: &[Edge]) -> Vec<String> {
    let mut neighbours = std::collections::BTreeMap::<usize, Vec<usize>>::new();
    for &[a, b] in edges {
        neighbours.entry(a).or_default().push(b);
        neighbours.entry(b).or_default().push(a);
    }
    // Open chains first, from their ends (nodes without two free edges), then loops.
    let ends = neighbours
        .iter()
        .filter(|(_, n)| n.len() != 2)
        .map(|(&v, _)| v);
    let starts: Vec<usize> = ends.chain(neighbours.keys().copied()).collect();
    let mut chain_of = std::collections::HashMap::<usize, usize>::new();
    let mut found: Vec<(usize, Vec<usize>)> = vec![]; // (start, ends) of each chain
    for start in starts {
        if chain_of.contains_key(&start) {
            continue;
        }
        let (id, mut stack, mut chain_ends) = (found.len(), vec![start], vec![]);
        while let Some(v) = stack.pop() {
            if chain_of.insert(v, id).is_some() {
                continue;
            }
            if neighbours[&v].len() != 2 {
                chain_ends.push(v);
            }
            stack.extend(neighbours[&v].iter().filter(|w| !chain_of.contains_key(w)));
        }
        found.push((start, chain_ends));
    }
    let mut segments = vec![0usize; found.len()];
    edges.iter().for_each(|[a, _]| segments[chain_of[a]] += 1);
    found
        .iter()
        .zip(segments)
        .map(|((start, chain_ends), k)| {
            let count = format!("{k} segment{}", if k == 1 { "" } else { "s" });
            match chain_ends.as_slice() {
                [] => format!("a closed loop through node {start} ({count})"),
                [a, b] => format!("nodes {} to {} ({count})", a.min(b), a.max(b)),
                many => {
                    let listed: Vec<String> = many.iter().map(|v| v.to_string()).collect();
                    format!("ends at nodes {} ({count})", listed.join(", "))
                }
            }
        })
        .collect()
}

/// The warning about the free edges of a prestressed film (module doc), naming the chains of
/// free edges by their end nodes and saying what holds them; none when there is none.
pub fn free_edge_warning(model: &Model) -> Option<String> {
    let edges = free_edges(model);
    if edges.is_empty() {
        return None;
    }
    let chains = chains(&edges);
    let listed = chains
        .iter()
        .take(LISTED_CHAINS)
        .cloned()
        .collect::<Vec<_>>()
        .join("; ");
    let more = if chains.len() > LISTED_CHAINS {
        "; …"
    } else {
        ""
    };
    let (s, c) = (
        if edges.len() == 1 { "" } else { "s" },
        if chains.len() == 1 { "" } else { "s" },
    );
    Some(format!(
        "the film's prestress pulls across {} free edge segment{s} in {} chain{c} ({listed}{more}) \
         that no support, symmetry plane, group, gap, curved support or edge cable holds: the \
         film starts out of equilibrium and the first step pulls these edges in until the \
         prestress across them is gone (wrinkles along them, a slow first step); hold each edge \
         with an edge cable (cables), a group or supports, or give the film no prestress across it",
        edges.len(),
        chains.len()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 0.1 m square of two triangles (nodes 0..3 counter-clockwise from the origin) with
    /// `prestress` and extra model items (a JSON fragment after the supports), held in x, y, z
    /// at node 0, in y and z at node 1 and in z at node 2 (every rigid-body mode held).
    fn square(prestress: [f64; 3], more: &str) -> Model {
        Model::from_json(&format!(
            r#"{{ "name": "Sq", "nodes": [[0,0,0], [0.1,0,0], [0.1,0.1,0], [0,0.1,0]],
                 "triangles": [[0,1,2], [0,2,3]],
                 "material": {{ "youngs_modulus": 1e9, "poisson_ratio": 0.43,
                                "thickness": 250e-6, "prestress": {prestress:?} }},
                 "supports": [{{ "node": 0, "fixed": ["x", "y", "z"] }},
                              {{ "node": 1, "fixed": ["y", "z"] }},
                              {{ "node": 2, "fixed": ["z"] }}] {more} }}"#
        ))
        .unwrap()
    }

    #[test]
    fn edges_the_prestress_pulls_that_nothing_holds_are_free() {
        // 0–1 lies along X on two nodes held in y: the pull across it (−Y) is held. The other
        // three have a node free along their pull.
        let model = square([5e5, 5e5, 0.0], "");
        assert_eq!(free_edges(&model), vec![[1, 2], [2, 3], [0, 3]]);
        let w = free_edge_warning(&model).unwrap();
        assert!(
            w.starts_with(
                "the film's prestress pulls across 3 free edge segments in 1 chain (nodes 0 to 1 \
                 (3 segments)) that no support"
            ),
            "{w}"
        );
        assert!(w.contains("hold each edge with an edge cable"), "{w}");
    }

    #[test]
    fn a_film_without_prestress_across_an_edge_has_no_free_edge_there() {
        assert_eq!(free_edges(&square([0.0; 3], "")), Vec::<Edge>::new());
        assert_eq!(free_edge_warning(&square([0.0; 3], "")), None);
        // σx only pulls across the edges along Y (1–2 and 3–0), in two chains.
        let model = square([5e5, 0.0, 0.0], "");
        assert_eq!(free_edges(&model), vec![[1, 2], [0, 3]]);
        let w = free_edge_warning(&model).unwrap();
        assert!(
            w.contains("2 free edge segments in 2 chains (nodes 0 to 3 (1 segment); nodes 1 to 2 (1 segment))"),
            "{w}"
        );
    }

    #[test]
    fn an_edge_cable_a_symmetry_plane_or_a_group_holds_an_edge() {
        let cable = r#", "cables": [{ "name": "Edge", "nodes": [1, 2, 3, 0], "area": 1e-6,
                                      "youngs_modulus": 1e11 }]"#;
        assert_eq!(
            free_edges(&square([5e5, 5e5, 0.0], cable)),
            Vec::<Edge>::new()
        );
        // A symmetry plane normal to X holds the edge x = 0 (pulled along +X) only.
        let plane = r#", "symmetry": [{ "name": "S", "normal": "x", "nodes": [0, 3] }]"#;
        assert_eq!(
            free_edges(&square([5e5, 5e5, 0.0], plane)),
            vec![[1, 2], [2, 3]]
        );
        // A group holds the edge 3–0 (pulled along +X) with node 3, unless it prescribes z only.
        let group = r#", "groups": [{ "name": "G", "nodes": [3] }]"#;
        assert_eq!(
            free_edges(&square([5e5, 5e5, 0.0], group)),
            vec![[1, 2], [2, 3]]
        );
        let group = r#", "groups": [{ "name": "G", "nodes": [3], "components": ["z"] }]"#;
        assert_eq!(
            free_edges(&square([5e5, 5e5, 0.0], group)),
            vec![[1, 2], [2, 3], [0, 3]]
        );
    }
}
