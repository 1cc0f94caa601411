//! Reactions per unit length along a boundary group or a support set (N/m: the load a rail, a
//! clamp or an edge beam takes from the film), for design calculations.
//!
//! A *reaction line* is a boundary group, or the nodes of a named support set, whose nodes are
//! joined by film edges: the edges of triangles with both ends in the set, except those inside a
//! patch of the set (an edge both of whose triangles have all three nodes in the set). Each node's
//! **tributary length** is half the sum of the reference lengths of its line edges (so an end
//! node of a straight edge gets half an edge, an inner node half of each neighbour), and its
//! **line reaction** is its reaction (over the components the group prescribes or the support
//! fixes, the same as the set's total in [`Results`]) divided by that length. Summing
//! `q · tributary` over the line gives back the set's reaction; for a uniform stress resultant
//! `n` (N/m) normal to a straight clamped edge, `q = n` at every node, end nodes included.
//!
//! Lengths are those of the reference geometry: a group translates (and may turn) as a rigid
//! body, a support does not move. A set whose node is joined to no other of its nodes by a film
//! edge has no line (a single node, a node in no triangle): [`reaction_lines`] says so instead.

use std::collections::HashMap;

use crate::mech::model::Model;
use crate::mech::results::Results;

/// What a reaction line belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineKind {
    /// A boundary group (index into `model.groups`).
    Group(usize),
    /// A named support set (index into `model.support_sets()`).
    SupportSet(usize),
}

impl LineKind {
    /// `group` or `support set`, for tables and messages.
    pub fn label(self) -> &'static str {
        match self {
            Self::Group(_) => "group",
            Self::SupportSet(_) => "support set",
        }
    }
}

/// A boundary group or support set seen as a line of film edges.
#[derive(Clone, Debug, PartialEq)]
pub struct ReactionLine {
    /// The group's or support set's name.
    pub name: String,
    /// What it is.
    pub kind: LineKind,
    /// Its nodes: in order along the line when its edges form one chain (open or closed), else
    /// ascending.
    pub nodes: Vec<usize>,
    /// The components whose reactions count, per node (the group's prescribed ones, the
    /// support's fixed ones).
    pub components: Vec<[bool; 3]>,
    /// Tributary length of each node (m): half the reference length of its line edges.
    pub tributary: Vec<f64>,
    /// Arc length from the first node along the chain (m), when the edges form one chain.
    pub position: Option<Vec<f64>>,
}

/// The line reaction of one node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeLineReaction {
    /// The node.
    pub node: usize,
    /// Arc length along the line (m), when it is one chain.
    pub position: Option<f64>,
    /// Tributary length (m).
    pub tributary: f64,
    /// The node's reaction over the line's components (N), global axes.
    pub reaction: [f64; 3],
    /// Reaction per unit length `reaction / tributary` (N/m).
    pub per_length: [f64; 3],
}

impl ReactionLine {
    /// The line reaction of each node from the restraint forces of `results`.
    pub fn reactions(&self, results: &Results) -> Vec<NodeLineReaction> {
        self.nodes
            .iter()
            .enumerate()
            .map(|(k, &v)| {
                let r = results.node_reactions.get(v).copied().unwrap_or([0.0; 3]);
                let reaction: [f64; 3] =
                    std::array::from_fn(|c| if self.components[k][c] { r[c] } else { 0.0 });
                NodeLineReaction {
                    node: v,
                    position: self.position.as_ref().map(|p| p[k]),
                    tributary: self.tributary[k],
                    reaction,
                    per_length: reaction.map(|f| f / self.tributary[k]),
                }
            })
            .collect()
    }

    /// Total reference length of the line's edges (m): the sum of the tributary lengths.
    pub fn length(&self) -> f64 {
        self.tributary.iter().sum()
    }
}

/// The reaction lines of `model` (groups first, then support sets) and, for each group or set
/// that is not a line of film edges, a sentence saying why it has none.
pub fn reaction_lines(model: &Model) -> (Vec<ReactionLine>, Vec<String>) {
    let mut sets: Vec<Candidate> = vec![];
    for (i, g) in model.groups.iter().enumerate() {
        let mut nodes = g.nodes.clone();
        nodes.sort_unstable();
        nodes.dedup();
        let comps = vec![g.prescribes(); nodes.len()];
        sets.push((g.name.clone(), LineKind::Group(i), nodes, comps));
    }
    for (i, name) in model.support_sets().into_iter().enumerate() {
        let mut fixed: HashMap<usize, [bool; 3]> = HashMap::new();
        for s in model
            .supports
            .iter()
            .filter(|s| s.name.as_ref() == Some(&name))
        {
            let mask = fixed.entry(s.node).or_default();
            for a in &s.fixed {
                mask[a.index()] = true;
            }
        }
        let mut nodes: Vec<usize> = fixed.keys().copied().collect();
        nodes.sort_unstable();
        let comps = nodes.iter().map(|v| fixed[v]).collect();
        sets.push((name, LineKind::SupportSet(i), nodes, comps));
    }
    let mut lines = vec![];
    let mut notes = vec![];
    for (name, kind, nodes, comps) in sets {
        match line_of(model, &nodes) {
            Ok((order, tributary, position)) => {
                let index: HashMap<usize, usize> =
                    nodes.iter().enumerate().map(|(k, &v)| (v, k)).collect();
                lines.push(ReactionLine {
                    name,
                    kind,
                    components: order.iter().map(|v| comps[index[v]]).collect(),
                    nodes: order,
                    tributary,
                    position,
                });
            }
            Err(why) => notes.push(format!(
                "{} '{name}' has no reactions per unit length: {why}",
                kind.label()
            )),
        }
    }
    (lines, notes)
}

/// A group or support set before its line is found: name, kind, nodes, components per node.
type Candidate = (String, LineKind, Vec<usize>, Vec<[bool; 3]>);

/// Nodes in line order, their tributary lengths, their positions along a chain.
type Layout = (Vec<usize>, Vec<f64>, Option<Vec<f64>>);

/// The nodes in line order, their tributary lengths and positions, or why `nodes` is no line.
fn line_of(model: &Model, nodes: &[usize]) -> Result<Layout, String> {
    let inside: std::collections::HashSet<usize> = nodes.iter().copied().collect();
    // edge (a < b) → number of its triangles with all three nodes in the set
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    for t in &model.triangles {
        let full = t.iter().all(|v| inside.contains(v));
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if inside.contains(&a) && inside.contains(&b) {
                *edges.entry((a.min(b), a.max(b))).or_default() += usize::from(full);
            }
        }
    }
    let length = |a: usize, b: usize| {
        let (p, q) = (model.nodes[a], model.nodes[b]);
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    let mut neighbours: HashMap<usize, Vec<usize>> = HashMap::new();
    let mut tributary: HashMap<usize, f64> = HashMap::new();
    let mut line_edges: Vec<(usize, usize)> = edges
        .into_iter()
        .filter(|&(_, full)| full <= 1)
        .map(|(e, _)| e)
        .collect();
    line_edges.sort_unstable();
    for &(a, b) in &line_edges {
        let half = 0.5 * length(a, b);
        *tributary.entry(a).or_default() += half;
        *tributary.entry(b).or_default() += half;
        neighbours.entry(a).or_default().push(b);
        neighbours.entry(b).or_default().push(a);
    }
    if let Some(&v) = nodes
        .iter()
        .find(|v| tributary.get(v).is_none_or(|&l| l <= 0.0))
    {
        return Err(format!(
            "node {v} is joined to no other of its nodes by a film edge"
        ));
    }
    let order = chain(nodes, &neighbours, line_edges.len());
    let position = order.is_some().then(|| {
        let order = order.as_ref().unwrap();
        let mut s = vec![0.0];
        for w in order.windows(2) {
            s.push(s.last().unwrap() + length(w[0], w[1]));
        }
        s
    });
    let order = order.unwrap_or_else(|| nodes.to_vec());
    let tributary = order.iter().map(|v| tributary[v]).collect();
    Ok((order, tributary, position))
}

/// The nodes in order along their edges when these form one chain (a path from its lower end, or
/// a loop from its lowest node), else None.
fn chain(
    nodes: &[usize],
    neighbours: &HashMap<usize, Vec<usize>>,
    edge_count: usize,
) -> Option<Vec<usize>> {
    if neighbours.values().any(|n| n.len() > 2) {
        return None;
    }
    let start = nodes
        .iter()
        .copied()
        .find(|v| neighbours[v].len() == 1)
        .unwrap_or(nodes[0]);
    let (mut order, mut previous) = (vec![start], None);
    while let Some(&next) = neighbours[order.last().unwrap()]
        .iter()
        .find(|&&w| Some(w) != previous && w != start)
    {
        previous = order.last().copied();
        order.push(next);
    }
    let closed = order.len() == edge_count;
    (order.len() == nodes.len() && (closed || order.len() == edge_count + 1)).then_some(order)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 1 strip of four triangles, nodes 0 1 2 (y = 0), 3 4 5 (y = 1), x = 0, 1, 3 (uneven).
    fn strip() -> Model {
        let json = r#"{"name": "Strip", "nodes": [[0,0,0],[1,0,0],[3,0,0],[0,1,0],[1,1,0],[3,1,0]],
            "triangles": [[0,1,4],[0,4,3],[1,2,5],[1,5,4]],
            "material": {"youngs_modulus": 1e9, "poisson_ratio": 0.3, "thickness": 1e-4},
            "supports": [{"node": 0, "fixed": ["x","y","z"], "name": "bottom"},
                         {"node": 1, "fixed": ["y","z"], "name": "bottom"},
                         {"node": 2, "fixed": ["y","z"], "name": "bottom"},
                         {"node": 3, "fixed": ["z"], "name": "lone"}],
            "groups": [{"name": "top", "nodes": [5, 4, 3], "target": [0, 0.1, 0], "components": ["y"]}]}"#;
        Model::from_json(json).unwrap()
    }

    #[test]
    fn tributary_lengths_are_half_the_adjacent_edges_and_chains_run_end_to_end() {
        let (lines, notes) = reaction_lines(&strip());
        assert_eq!(lines.len(), 2, "{notes:?}");
        let top = &lines[0];
        assert_eq!(top.kind, LineKind::Group(0));
        assert_eq!(top.nodes, vec![3, 4, 5]);
        assert_eq!(top.tributary, vec![0.5, 1.5, 1.0]);
        assert_eq!(top.position.as_deref(), Some(&[0.0, 1.0, 3.0][..]));
        assert_eq!(top.components, vec![[false, true, false]; 3]);
        let bottom = &lines[1];
        assert_eq!(bottom.kind, LineKind::SupportSet(0));
        assert_eq!(bottom.nodes, vec![0, 1, 2]);
        assert_eq!(bottom.components[0], [true, true, true]);
        assert_eq!(bottom.components[1], [false, true, true]);
        assert_eq!(bottom.length(), 3.0);
        assert_eq!(notes.len(), 1);
        assert!(
            notes[0].contains("support set 'lone'") && notes[0].contains("node 3"),
            "{notes:?}"
        );
    }

    #[test]
    fn a_patch_counts_its_outline_only() {
        // every node in one group: the outline (6 edges, length 8) is the line, not the diagonals
        let mut model = strip();
        model.groups[0].nodes = (0..6).collect();
        model.supports.clear();
        let (lines, _) = reaction_lines(&model);
        assert_eq!(lines[0].length(), 8.0);
        assert_eq!(
            lines[0].nodes,
            vec![0, 1, 2, 5, 4, 3],
            "a loop from its lowest node"
        );
        assert_eq!(lines[0].tributary, vec![1.0, 1.5, 1.5, 1.5, 1.5, 1.0]);
    }
}
