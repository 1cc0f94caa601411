//! The film split along seams that cross its triangles (issue 46): the strips' outlines follow
//! the seams exactly.
//!
//! Inside a triangle a seam is straight (a geodesic, [`super::geodesic`]), so it is a *chord*
//! from one point of the triangle's boundary to another. Every point where a seam crosses an
//! edge becomes a node on that edge (at `X_a + λ (X_b − X_a)`, the seam point's projection on
//! the edge, so that the triangles on both sides share it); where two seams cross inside a
//! triangle, a node at their intersection. Each triangle is then the convex polygon of its
//! corners and the nodes on its edges, cut by its chords into convex polygons, each
//! triangulated by ear clipping (an ear is a corner of positive area whose diagonal passes
//! through no other node). The pieces lie in the triangle's plane and tile it, so the split
//! film has the same area and the same reference geometry as the film it was cut from; every
//! triangle the seams do not cross keeps its index, and a split triangle's first piece takes
//! its index, the others are appended. The seam edges are the pieces' edges along a chord;
//! the strips are the triangles connected across every other edge
//! ([`super::seams::strips_by_edges`]).
//!
//! A node added on an edge joins each node set of the model (supports with the same fixed
//! components and name, symmetry planes, boundary groups, curved supports' contact nodes) that
//! holds both of the edge's ends, and each cable along the edge at its place; a node added
//! inside a triangle joins the sets that hold its three corners. A split triangle's new
//! pieces join every triangle list that held it (layers, chambers, pressure sets, output sets,
//! layer contacts). Force sets (a force on each node) are not extended.

use std::collections::{HashMap, HashSet};

use nalgebra::Vector3;

use super::geodesic::GeodesicPoint;
use super::seams::strips_by_edges;
use crate::mech::elements::layer_contact::LayerSurface;
use crate::mech::model::{ElementSelection, Model, Support};

type V3 = Vector3<f64>;

/// Relative distance (to the triangle's longest edge) below which two points are one node.
const SAME_POINT: f64 = 1e-9;

/// A seam that crosses an edge within this fraction of its length from an end goes through that
/// end instead: no sliver piece (a seam along a mesh line of a curved film crosses its edges
/// within 1e-5 to 1e-3 of their ends), the outline off the seam by at most this much of the edge.
pub const SNAP: f64 = 0.02;

/// The film split along its seams.
#[derive(Clone, Debug, PartialEq)]
pub struct SplitFilm {
    /// The split film: the original nodes (same indices) and the new ones after them.
    pub model: Model,
    /// The original triangle each triangle of `model` is a piece of.
    pub parent: Vec<usize>,
    /// The seam edges of `model` (`[low, high]`).
    pub seam_edges: HashSet<[usize; 2]>,
    /// The triangles of each strip between the seams, ordered by their first triangle.
    pub strips: Vec<Vec<usize>>,
}

/// A seam's straight run through one triangle: its two points on the triangle's boundary.
#[derive(Clone, Copy, Debug)]
struct Chord {
    triangle: usize,
    ends: [V3; 2],
}

/// Where a new node lies: on an original edge `[a, b]`, or inside a triangle.
#[derive(Clone, Copy, Debug)]
enum Origin {
    Edge([usize; 2]),
    Inside(usize),
}

fn key(a: usize, b: usize) -> [usize; 2] {
    [a.min(b), a.max(b)]
}

/// Each seam's chords: consecutive segments in one triangle merged (a seam's middle point lies
/// inside a triangle), segments of no length left out.
fn chords(seams: &[Vec<GeodesicPoint>]) -> Vec<Chord> {
    let mut out: Vec<Chord> = Vec::new();
    for seam in seams {
        let start = out.len();
        for w in seam.windows(2) {
            let (p, q) = (V3::from(w[0].point), V3::from(w[1].point));
            if (q - p).norm() == 0.0 {
                continue;
            }
            let same = out.len() > start && out.last().is_some_and(|c| c.triangle == w[0].triangle);
            match out.last_mut() {
                Some(c) if same => c.ends[1] = q,
                _ => out.push(Chord {
                    triangle: w[0].triangle,
                    ends: [p, q],
                }),
            }
        }
    }
    out
}

/// The split being built: every node's position, the new nodes' origins, the nodes on each
/// original edge.
struct Builder<'a> {
    model: &'a Model,
    x: Vec<V3>,
    origin: Vec<Origin>,
    on_edge: HashMap<[usize; 2], Vec<(f64, usize)>>,
    snap: f64,
}

impl<'a> Builder<'a> {
    fn new(model: &'a Model, snap: f64) -> Self {
        Self {
            snap,
            model,
            x: model.nodes.iter().map(|&p| V3::from(p)).collect(),
            origin: Vec::new(),
            on_edge: HashMap::new(),
        }
    }

    fn corners(&self, t: usize) -> [usize; 3] {
        self.model.triangles[t]
    }

    /// The longest edge of original triangle `t`.
    fn size(&self, t: usize) -> f64 {
        let [a, b, c] = self.corners(t).map(|v| self.x[v]);
        [(b - a).norm(), (c - b).norm(), (a - c).norm()]
            .into_iter()
            .fold(0.0, f64::max)
    }

    fn normal(&self, t: usize) -> V3 {
        let [a, b, c] = self.corners(t).map(|v| self.x[v]);
        (b - a).cross(&(c - a)).normalize()
    }

    fn add(&mut self, x: V3, origin: Origin) -> usize {
        self.x.push(x);
        self.origin.push(origin);
        self.x.len() - 1
    }

    /// The node at `p` on the boundary of triangle `t`: a corner, or a node on an edge (made
    /// once for both triangles of the edge).
    fn boundary_node(&mut self, t: usize, p: V3) -> Result<usize, String> {
        let tol = SAME_POINT * self.size(t);
        let tri = self.corners(t);
        if let Some(&v) = tri.iter().find(|&&v| (self.x[v] - p).norm() <= tol) {
            return Ok(v);
        }
        let edge = |k: usize| key(tri[k], tri[(k + 1) % 3]);
        let place = |[a, b]: [usize; 2]| {
            let e = self.x[b] - self.x[a];
            let lambda = ((p - self.x[a]).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
            (lambda, (self.x[a] + e * lambda - p).norm())
        };
        let (k, (lambda, off)) = (0..3)
            .map(|k| (k, place(edge(k))))
            .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
            .expect("three edges");
        if off > tol {
            return Err(format!(
                "seam point {:?} is {off:.3e} m off the edges of triangle {t}",
                <[f64; 3]>::from(p)
            ));
        }
        let [a, b] = edge(k);
        // Within SNAP of an end, the seam goes through that end (decided on the edge alone, so
        // both triangles of the edge decide alike).
        if lambda < self.snap || lambda > 1.0 - self.snap {
            return Ok(if lambda < 0.5 { a } else { b });
        }
        if let Some(&(_, v)) = self.on_edge.get(&[a, b]).and_then(|nodes| {
            let length = (self.x[b] - self.x[a]).norm();
            nodes
                .iter()
                .find(|(l, _)| (l - lambda).abs() * length <= tol)
        }) {
            return Ok(v);
        }
        let v = self.add(
            self.x[a] + (self.x[b] - self.x[a]) * lambda,
            Origin::Edge([a, b]),
        );
        self.on_edge.entry([a, b]).or_default().push((lambda, v));
        Ok(v)
    }

    /// Triangle `t` as the polygon of its corners and the nodes on its edges, in its order.
    fn polygon(&self, t: usize) -> Vec<usize> {
        let tri = self.corners(t);
        let mut polygon = Vec::new();
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            polygon.push(a);
            let mut between: Vec<(f64, usize)> = self
                .on_edge
                .get(&key(a, b))
                .map(|n| n.iter().map(|&(l, v)| (if a < b { l } else { 1.0 - l }, v)))
                .into_iter()
                .flatten()
                .collect();
            between.sort_by(|p, q| p.0.total_cmp(&q.0));
            polygon.extend(between.into_iter().map(|(_, v)| v));
        }
        polygon
    }

    /// The node where chord `[p, q]` of triangle `t` crosses a polygon side at `x`: an end of
    /// the chord, or a node inside `t` (one for every polygon that meets there).
    fn crossing(&mut self, t: usize, x: V3, [p, q]: [usize; 2]) -> usize {
        let tol = SAME_POINT * self.size(t);
        if let Some(v) = [p, q].into_iter().find(|&v| (self.x[v] - x).norm() <= tol) {
            return v;
        }
        let n0 = self.model.nodes.len();
        let inside = (0..self.origin.len()).find(|&i| {
            matches!(self.origin[i], Origin::Inside(s) if s == t)
                && (self.x[n0 + i] - x).norm() <= tol
        });
        inside.map_or_else(|| self.add(x, Origin::Inside(t)), |i| n0 + i)
    }

    /// `polygons` of triangle `t` cut along the line of chord `[p, q]`.
    fn cut(&mut self, t: usize, polygons: Vec<Vec<usize>>, [p, q]: [usize; 2]) -> Vec<Vec<usize>> {
        let tol = SAME_POINT * self.size(t);
        let across = self.normal(t).cross(&(self.x[q] - self.x[p])).normalize();
        let mut out = Vec::new();
        for polygon in polygons {
            let s: Vec<f64> = polygon
                .iter()
                .map(|&v| (self.x[v] - self.x[p]).dot(&across))
                .collect();
            if !(s.iter().any(|&s| s > tol) && s.iter().any(|&s| s < -tol)) {
                out.push(polygon);
                continue;
            }
            let (mut left, mut right) = (Vec::new(), Vec::new());
            for i in 0..polygon.len() {
                let j = (i + 1) % polygon.len();
                if s[i] >= -tol {
                    left.push(polygon[i]);
                }
                if s[i] <= tol {
                    right.push(polygon[i]);
                }
                if (s[i] > tol && s[j] < -tol) || (s[i] < -tol && s[j] > tol) {
                    let f = s[i] / (s[i] - s[j]);
                    let x = self.x[polygon[i]] + (self.x[polygon[j]] - self.x[polygon[i]]) * f;
                    let v = self.crossing(t, x, [p, q]);
                    left.push(v);
                    right.push(v);
                }
            }
            out.extend([left, right]);
        }
        out
    }

    /// The convex `polygon` of triangle `t` in triangles (ear clipping, the best-shaped ear
    /// first; an ear's diagonal must pass through no other node).
    fn triangulate(&self, t: usize, polygon: &[usize]) -> Result<Vec<[usize; 3]>, String> {
        let (normal, size) = (self.normal(t), self.size(t));
        let on_segment = |w: usize, a: usize, c: usize| {
            let (e, d) = (self.x[c] - self.x[a], self.x[w] - self.x[a]);
            let f = d.dot(&e) / e.norm_squared();
            (0.0..=1.0).contains(&f) && (d - e * f).norm() <= SAME_POINT * size
        };
        let quality = |[a, b, c]: [usize; 3]| {
            let area = (self.x[b] - self.x[a])
                .cross(&(self.x[c] - self.x[a]))
                .dot(&normal);
            let edges = (self.x[b] - self.x[a]).norm_squared()
                + (self.x[c] - self.x[b]).norm_squared()
                + (self.x[a] - self.x[c]).norm_squared();
            area / edges
        };
        let mut p = polygon.to_vec();
        let mut out = Vec::new();
        while p.len() > 3 {
            let n = p.len();
            let ear = |i: usize| [p[(i + n - 1) % n], p[i], p[(i + 1) % n]];
            let best = (0..n)
                .filter(|&i| {
                    let [a, b, c] = ear(i);
                    quality(ear(i)) > 1e-12
                        && !p
                            .iter()
                            .any(|&w| ![a, b, c].contains(&w) && on_segment(w, a, c))
                })
                .max_by(|&i, &j| quality(ear(i)).total_cmp(&quality(ear(j))))
                .ok_or_else(|| format!("triangle {t}: its pieces cannot be triangulated"))?;
            out.push(ear(best));
            p.remove(best);
        }
        if quality([p[0], p[1], p[2]]) <= 1e-12 {
            return Err(format!("triangle {t}: a piece has no area"));
        }
        out.push([p[0], p[1], p[2]]);
        Ok(out)
    }
}

/// Splits `model`'s film along the `seams` (points on its triangles' edges, each point's
/// `triangle` the one the segment leaving it crosses, as [`super::geodesic`] traces them) and
/// returns the split film, its seam edges and the strips between them. A crossing within `snap`
/// of an edge's length from its end goes through that end ([`SNAP`]; 0: every crossing is a
/// node, the outlines exactly on the seams).
pub fn split_along(
    model: &Model,
    seams: &[Vec<GeodesicPoint>],
    snap: f64,
) -> Result<SplitFilm, String> {
    let chords = chords(seams);
    let mut b = Builder::new(model, snap);
    let mut by_triangle: Vec<Vec<[usize; 2]>> = vec![Vec::new(); model.triangles.len()];
    for c in &chords {
        let ends = [
            b.boundary_node(c.triangle, c.ends[0])?,
            b.boundary_node(c.triangle, c.ends[1])?,
        ];
        if ends[0] != ends[1] {
            by_triangle[c.triangle].push(ends);
        }
    }
    let mut pieces: Vec<Vec<[usize; 3]>> = Vec::with_capacity(model.triangles.len());
    let mut seam_edges = HashSet::new();
    for t in 0..model.triangles.len() {
        let polygon = b.polygon(t);
        if polygon.len() == 3 && by_triangle[t].is_empty() {
            pieces.push(vec![model.triangles[t]]);
            continue;
        }
        let mut polygons = vec![polygon];
        for &chord in &by_triangle[t] {
            polygons = b.cut(t, polygons, chord);
        }
        let mut split = Vec::new();
        for polygon in &polygons {
            split.extend(b.triangulate(t, polygon)?);
        }
        for &[p, q] in &by_triangle[t] {
            for tri in &split {
                for k in 0..3 {
                    let (u, w) = (tri[k], tri[(k + 1) % 3]);
                    if b.on_chord(t, u, [p, q]) && b.on_chord(t, w, [p, q]) {
                        seam_edges.insert(key(u, w));
                    }
                }
            }
        }
        pieces.push(split);
    }
    let mut split = assemble(model, &b, pieces);
    let strips = strips_by_edges(&split.model, &seam_edges);
    split.seam_edges = seam_edges;
    split.strips = strips;
    Ok(split)
}

impl Builder<'_> {
    /// Whether node `v` lies on chord `[p, q]` of triangle `t`.
    fn on_chord(&self, t: usize, v: usize, [p, q]: [usize; 2]) -> bool {
        let (e, d) = (self.x[q] - self.x[p], self.x[v] - self.x[p]);
        let f = d.dot(&e) / e.norm_squared();
        let tol = SAME_POINT * self.size(t);
        (-tol..=1.0 + tol).contains(&f) && (d - e * f).norm() <= tol
    }
}

/// The split model from each original triangle's `pieces`: nodes and triangles, the new nodes
/// in the node sets, the new pieces in the triangle lists.
fn assemble(model: &Model, b: &Builder<'_>, pieces: Vec<Vec<[usize; 3]>>) -> SplitFilm {
    let mut split = model.clone();
    split.nodes = b.x.iter().map(|&p| p.into()).collect();
    let mut parent: Vec<usize> = (0..model.triangles.len()).collect();
    let mut children = vec![Vec::new(); model.triangles.len()];
    for (t, p) in pieces.into_iter().enumerate() {
        split.triangles[t] = p[0];
        for &piece in &p[1..] {
            children[t].push(split.triangles.len());
            split.triangles.push(piece);
            parent.push(t);
        }
    }
    let n0 = model.nodes.len();
    for (i, origin) in b.origin.iter().enumerate() {
        let of = match *origin {
            Origin::Edge(edge) => edge.to_vec(),
            Origin::Inside(t) => model.triangles[t].to_vec(),
        };
        join_node_sets(&mut split, n0 + i, &of);
    }
    extend_cables(&mut split, b);
    extend_triangle_lists(&mut split, &children);
    SplitFilm {
        model: split,
        parent,
        seam_edges: HashSet::new(),
        strips: Vec::new(),
    }
}

/// Node `v` joins every node set of `model` that holds all of `of`.
fn join_node_sets(model: &mut Model, v: usize, of: &[usize]) {
    let all = |nodes: &[usize]| of.iter().all(|u| nodes.contains(u));
    let like = |s: &Support, r: &Support| r.fixed == s.fixed && r.name == s.name;
    let supports: Vec<Support> = (model.supports.iter())
        .filter(|s| {
            s.node == of[0]
                && (of[1..].iter())
                    .all(|&u| model.supports.iter().any(|r| r.node == u && like(s, r)))
        })
        .map(|s| Support {
            node: v,
            ..s.clone()
        })
        .collect();
    model.supports.extend(supports);
    for s in &mut model.symmetry {
        if all(&s.nodes) {
            s.nodes.push(v);
        }
    }
    for g in &mut model.groups {
        if all(&g.nodes) {
            g.nodes.push(v);
        }
    }
    for c in &mut model.curved_supports {
        if all(&c.nodes) {
            c.nodes.push(v);
        }
    }
}

/// Each cable's nodes with the new nodes on its edges in their place.
fn extend_cables(model: &mut Model, b: &Builder<'_>) {
    for cable in &mut model.cables {
        let mut nodes = vec![cable.nodes[0]];
        for w in cable.nodes.windows(2) {
            let mut between: Vec<(f64, usize)> = b
                .on_edge
                .get(&key(w[0], w[1]))
                .map(|n| {
                    n.iter()
                        .map(|&(l, v)| (if w[0] < w[1] { l } else { 1.0 - l }, v))
                        .collect()
                })
                .unwrap_or_default();
            between.sort_by(|p, q| p.0.total_cmp(&q.0));
            nodes.extend(between.into_iter().map(|(_, v)| v));
            nodes.push(w[1]);
        }
        cable.nodes = nodes;
    }
}

/// Each triangle list with the new pieces of the triangles it holds.
fn extend_triangle_lists(model: &mut Model, children: &[Vec<usize>]) {
    let extend = |list: &mut Vec<usize>| {
        let added: Vec<usize> = list
            .iter()
            .flat_map(|&t| children.get(t).into_iter().flatten().copied())
            .collect();
        list.extend(added);
    };
    let mut selections: Vec<&mut ElementSelection> = Vec::new();
    selections.extend(model.layers.iter_mut().map(|l| &mut l.elements));
    selections.extend(model.chambers.iter_mut().map(|c| &mut c.elements));
    selections.extend(model.loads.pressures.iter_mut().map(|p| &mut p.elements));
    selections.extend(
        model
            .outputs
            .element_sets
            .iter_mut()
            .map(|s| &mut s.elements),
    );
    for s in selections {
        if let ElementSelection::List(list) = s {
            extend(list);
        }
    }
    for c in &mut model.layer_contacts {
        for surface in [&mut c.slave, &mut c.master] {
            if let LayerSurface::Triangles(list) = surface {
                extend(list);
            }
        }
    }
}
