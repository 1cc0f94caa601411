//! Strips from seams. A seam is a plane (`point`, `normal`): a triangle belongs to the side of
//! each plane its centroid lies on, and the triangles with the same sides form a strip. Or a
//! seam is a line of mesh nodes: the strips are the triangles that stay connected across every
//! edge that is not a seam segment.

use std::collections::HashMap;

use crate::mech::model::Model;

/// A seam plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeamPlane {
    /// A point of the plane (m).
    pub point: [f64; 3],
    /// Its normal (any length but zero).
    pub normal: [f64; 3],
}

/// The triangles of each strip the `planes` cut, strips ordered by their sides.
pub fn strips_by_planes(model: &Model, planes: &[SeamPlane]) -> Vec<Vec<usize>> {
    let mut strips: std::collections::BTreeMap<Vec<bool>, Vec<usize>> = Default::default();
    for (t, tri) in model.triangles.iter().enumerate() {
        let c: [f64; 3] =
            std::array::from_fn(|i| tri.iter().map(|&v| model.nodes[v][i]).sum::<f64>() / 3.0);
        let sides = planes
            .iter()
            .map(|p| {
                (0..3)
                    .map(|i| (c[i] - p.point[i]) * p.normal[i])
                    .sum::<f64>()
                    > 0.0
            })
            .collect();
        strips.entry(sides).or_default().push(t);
    }
    strips.into_values().collect()
}

/// The triangles on each edge `[low, high]` of the film (one on the boundary, two inside).
pub fn triangles_by_edge(model: &Model) -> HashMap<[usize; 2], Vec<usize>> {
    let key = |a: usize, b: usize| [a.min(b), a.max(b)];
    let mut by_edge: HashMap<[usize; 2], Vec<usize>> = HashMap::new();
    for (t, tri) in model.triangles.iter().enumerate() {
        for k in 0..3 {
            by_edge
                .entry(key(tri[k], tri[(k + 1) % 3]))
                .or_default()
                .push(t);
        }
    }
    by_edge
}

/// The triangles of each strip bounded by the seam node `lines` (consecutive nodes of a line
/// are a seam segment) and the film's edges, strips ordered by their first triangle.
pub fn strips_by_node_lines(model: &Model, lines: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let key = |a: usize, b: usize| [a.min(b), a.max(b)];
    let seams: std::collections::HashSet<[usize; 2]> = lines
        .iter()
        .flat_map(|l| l.windows(2).map(|w| key(w[0], w[1])))
        .collect();
    strips_by_edges(model, &seams)
}

/// The triangles of each strip bounded by the seam `edges` (`[low, high]` node pairs) and the
/// film's edges: the triangles connected across every other edge, strips ordered by their
/// first triangle.
pub fn strips_by_edges(
    model: &Model,
    seams: &std::collections::HashSet<[usize; 2]>,
) -> Vec<Vec<usize>> {
    let key = |a: usize, b: usize| [a.min(b), a.max(b)];
    let by_edge = triangles_by_edge(model);
    let mut strip_of = vec![usize::MAX; model.triangles.len()];
    let mut strips = Vec::new();
    for first in 0..model.triangles.len() {
        if strip_of[first] != usize::MAX {
            continue;
        }
        let (id, mut stack, mut members) = (strips.len(), vec![first], vec![]);
        strip_of[first] = id;
        while let Some(t) = stack.pop() {
            members.push(t);
            let tri = model.triangles[t];
            for k in 0..3 {
                let edge = key(tri[k], tri[(k + 1) % 3]);
                if seams.contains(&edge) {
                    continue;
                }
                for &n in &by_edge[&edge] {
                    if strip_of[n] == usize::MAX {
                        strip_of[n] = id;
                        stack.push(n);
                    }
                }
            }
        }
        members.sort_unstable();
        strips.push(members);
    }
    strips
}
