//! Geodesic seams (issue 46): straightest geodesics on the triangulated film (Polthier &
//! Schmies 1998), spaced by a strip width measured along the surface, and the strips between
//! them.
//!
//! *Tracing* (Polthier & Schmies, §3–4): inside a triangle a geodesic is a straight segment;
//! across an edge the next triangle is unfolded about the edge into the current one's plane
//! and the segment goes on straight (the direction keeps its components along the edge and
//! across it); through a vertex of total angle `Θ` it leaves so that the angles on its two
//! sides are equal, `Θ/2` each (their Def. 4, the *straightest* geodesic, unique for any start
//! direction). A geodesic ends on the film's boundary.
//!
//! *Seams*: from the middle of the user's start line (mesh nodes along the film's boundary) a
//! transverse geodesic goes into the film perpendicular to the line; seam `k` starts at arc
//! length `k w` along it and runs perpendicular to it both ways (on a developable surface the
//! seams are then the parallels at distance `k w` of the start line: on a cylinder, its
//! generators). A start line inside the film (from boundary to boundary) is itself a seam, and
//! the transverse geodesic goes from its middle to both sides: the seams lie at `k w` on each
//! side, numbered from the side on the line's left (walking from its first node to its last,
//! the triangles' normals up) to its right. *Strips*: a triangle lies beyond a seam when its
//! centroid lies on the far side (along the transverse geodesic) of the seam's nearest segment;
//! its strip is the number of seams it lies beyond. The strips' edges follow the triangles on either side of each seam (as
//! with seam planes): the mesh is not split along the geodesic ([`super::split`] does).

use std::collections::HashMap;

use nalgebra::Vector3;

use crate::mech::model::Model;

type V3 = Vector3<f64>;

/// A point of a traced geodesic and the straight segment that leaves it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeodesicPoint {
    /// Position (m).
    pub point: [f64; 3],
    /// The triangle the segment leaving the point crosses.
    pub triangle: usize,
    /// The segment's unit direction (in that triangle's plane).
    pub direction: [f64; 3],
    /// Arc length from the geodesic's start (m).
    pub length: f64,
}

/// Where the tracer entered its current triangle (excluded as an exit).
#[derive(Clone, Copy, PartialEq)]
enum Entry {
    Start,
    Edge([usize; 2]),
    Vertex(usize),
}

/// Geodesics seams of a strip width from a start line.
#[derive(Clone, Debug, PartialEq)]
pub struct GeodesicSeams {
    /// The transverse geodesic through the start line's middle, across the film (from the
    /// boundary, through the start, to the boundary for a start line inside the film).
    pub transverse: Vec<GeodesicPoint>,
    /// The arc length of the start line's middle along `transverse` (0 on the boundary).
    pub origin: f64,
    /// Each seam, from one boundary to the other, in their order along `transverse` (inside the
    /// film: from the start line's left to its right).
    pub seams: Vec<Vec<GeodesicPoint>>,
    /// The index in `seams` of the start line itself, when it lies inside the film.
    pub start_seam: Option<usize>,
    /// The triangles of each strip, from the start line on.
    pub strips: Vec<Vec<usize>>,
}

/// The film's triangles, their edges and vertices, for tracing.
pub struct Surface<'a> {
    model: &'a Model,
    by_edge: HashMap<[usize; 2], Vec<usize>>,
    by_vertex: Vec<Vec<usize>>,
}

fn key(a: usize, b: usize) -> [usize; 2] {
    [a.min(b), a.max(b)]
}

/// The unit component of `w` perpendicular to the unit `u`.
fn across(w: V3, u: V3) -> V3 {
    (w - u * u.dot(&w)).normalize()
}

impl<'a> Surface<'a> {
    /// The surface of `model`'s triangles.
    pub fn new(model: &'a Model) -> Self {
        let mut by_vertex = vec![Vec::new(); model.nodes.len()];
        for (t, tri) in model.triangles.iter().enumerate() {
            tri.iter().for_each(|&v| by_vertex[v].push(t));
        }
        Self {
            model,
            by_edge: super::seams::triangles_by_edge(model),
            by_vertex,
        }
    }

    fn x(&self, v: usize) -> V3 {
        V3::from(self.model.nodes[v])
    }

    fn normal(&self, t: usize) -> V3 {
        let [a, b, c] = self.model.triangles[t].map(|v| self.x(v));
        (b - a).cross(&(c - a)).normalize()
    }

    /// The vertex of `t` that is neither `a` nor `b`.
    fn third(&self, t: usize, a: usize, b: usize) -> usize {
        let tri = self.model.triangles[t];
        *tri.iter().find(|&&v| v != a && v != b).expect("a triangle")
    }

    /// The triangle across edge `[a, b]` from `t` (none on the boundary).
    fn across_edge(&self, t: usize, a: usize, b: usize) -> Option<usize> {
        self.by_edge[&key(a, b)].iter().copied().find(|&s| s != t)
    }

    /// Whether node `v` lies on the film's boundary (an edge of one triangle ends at it).
    fn on_boundary(&self, v: usize) -> bool {
        self.by_vertex[v].iter().any(|&t| {
            let tri = self.model.triangles[t];
            tri.iter()
                .any(|&u| u != v && self.by_edge[&key(u, v)].len() == 1)
        })
    }

    /// The first exit of the ray `p + s d` from `t`: `(s, [a, b], λ)` on edge `a → b`.
    fn exit(&self, t: usize, p: V3, d: V3, entry: Entry) -> Option<(f64, [usize; 2], f64)> {
        let tri = self.model.triangles[t];
        let scale = (self.x(tri[1]) - self.x(tri[0])).norm();
        let mut best: Option<(f64, [usize; 2], f64)> = None;
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let skip = match entry {
                Entry::Edge(e) => e == key(a, b),
                Entry::Vertex(v) => a == v || b == v,
                Entry::Start => false,
            };
            let e = self.x(b) - self.x(a);
            let de = d.cross(&e);
            if skip || de.norm() < 1e-12 * e.norm() {
                continue;
            }
            // p + s d = x_a + λ e: cross with e for s, with d for λ.
            let w = self.x(a) - p;
            let s = w.cross(&e).dot(&de) / de.norm_squared();
            let lambda = w.cross(&d).dot(&de) / de.norm_squared();
            let inside = (-1e-9..=1.0 + 1e-9).contains(&lambda);
            if inside && s > 1e-10 * scale && best.is_none_or(|(s0, _, _)| s < s0) {
                best = Some((s, [a, b], lambda.clamp(0.0, 1.0)));
            }
        }
        best
    }

    /// The straightest continuation through vertex `v`, entered from triangle `t` along `d`
    /// (Polthier & Schmies, Def. 4: `Θ/2` on each side): the next triangle and direction; none
    /// at a boundary vertex.
    fn through_vertex(&self, v: usize, t: usize, d: V3) -> Option<(usize, V3)> {
        let xv = self.x(v);
        let tri = self.model.triangles[t];
        let i = tri.iter().position(|&u| u == v)?;
        let (a, b) = (tri[(i + 1) % 3], tri[(i + 2) % 3]);
        // The fan of triangles around v, each a wedge from edge v→p to v→q.
        let mut fan = vec![(t, a, b)];
        while fan.len() <= self.by_vertex[v].len() {
            let &(s, _, q) = fan.last()?;
            let next = self.across_edge(s, v, q)?;
            if next == t {
                break;
            }
            fan.push((next, q, self.third(next, v, q)));
        }
        let angle = |p: V3, q: V3| p.cross(&q).norm().atan2(p.dot(&q));
        let wedges: Vec<f64> = fan
            .iter()
            .map(|&(_, p, q)| angle(self.x(p) - xv, self.x(q) - xv))
            .collect();
        let total: f64 = wedges.iter().sum();
        let mut gamma = angle(self.x(a) - xv, -d) + 0.5 * total;
        if gamma >= total {
            gamma -= total;
        }
        for (&(s, p, q), &w) in fan.iter().zip(&wedges) {
            if gamma <= w + 1e-12 || s == fan.last()?.0 {
                let u = (self.x(p) - xv).normalize();
                let across = across(self.x(q) - xv, u);
                return Some((s, u * gamma.min(w).cos() + across * gamma.min(w).sin()));
            }
            gamma -= w;
        }
        None
    }

    /// The triangle around `t` (sharing a vertex with it) that `p` moved a little along `d`
    /// lies in: where a geodesic starting at `p` along `d` begins.
    fn locate(&self, t: usize, p: V3, d: V3) -> usize {
        let tri = self.model.triangles[t];
        let h = (self.x(tri[1]) - self.x(tri[0])).norm();
        let q = p + d * (1e-6 * h);
        let candidates = tri.iter().flat_map(|&v| self.by_vertex[v].iter().copied());
        let score = |s: usize| {
            let [a, b, c] = self.model.triangles[s].map(|v| self.x(v));
            let n = (b - a).cross(&(c - a));
            let bary = [(b, c), (c, a), (a, b)].map(|(u, w)| (u - q).cross(&(w - q)).dot(&n));
            let off = n.normalize().dot(&(q - a)).abs() / h;
            bary.iter()
                .fold(0.0f64, |m, &l| m.min(l / n.norm_squared()))
                - off
        };
        candidates
            .max_by(|&r, &s| score(r).total_cmp(&score(s)))
            .unwrap_or(t)
    }

    /// The geodesic from `p` in (or on) triangle `t` along the unit `d` until the boundary or
    /// the arc length `limit` (Polthier & Schmies, §4).
    pub fn trace(&self, t: usize, p: [f64; 3], d: [f64; 3], limit: f64) -> Vec<GeodesicPoint> {
        let (mut p, mut d) = (V3::from(p), V3::from(d).normalize());
        let mut t = self.locate(t, p, d);
        let (n, mut entry, mut length) = (self.normal(t), Entry::Start, 0.0);
        d = across(d, n);
        let mut path = Vec::new();
        for _ in 0..100 * self.model.triangles.len().max(1) {
            path.push(GeodesicPoint {
                point: p.into(),
                triangle: t,
                direction: d.into(),
                length,
            });
            let Some((s, [a, b], lambda)) = self.exit(t, p, d, entry) else {
                break;
            };
            if length + s >= limit {
                path.push(GeodesicPoint {
                    point: (p + d * (limit - length)).into(),
                    length: limit,
                    ..path[path.len() - 1]
                });
                break;
            }
            length += s;
            let vertex = [(lambda < 1e-7, a), (lambda > 1.0 - 1e-7, b)];
            let next = match vertex.iter().find(|(at, _)| *at) {
                Some(&(_, v)) => {
                    p = self.x(v);
                    entry = Entry::Vertex(v);
                    self.through_vertex(v, t, d)
                }
                None => {
                    p += d * s;
                    entry = Entry::Edge(key(a, b));
                    self.across_edge(t, a, b).map(|next| {
                        let e = (self.x(b) - self.x(a)).normalize();
                        let into = across(self.x(self.third(next, a, b)) - self.x(a), e);
                        let along = d.dot(&e);
                        (
                            next,
                            e * along + into * (1.0 - along * along).max(0.0).sqrt(),
                        )
                    })
                }
            };
            let Some((next, direction)) = next else {
                path.push(GeodesicPoint {
                    point: p.into(),
                    length,
                    ..path[path.len() - 1]
                });
                break;
            };
            (t, d) = (next, direction);
        }
        path
    }
}

/// The point of `path` at arc length `s` and the segment it lies on.
pub fn point_at(path: &[GeodesicPoint], s: f64) -> GeodesicPoint {
    let i = path.partition_point(|g| g.length <= s).saturating_sub(1);
    let g = path[i];
    let p = V3::from(g.point) + V3::from(g.direction) * (s - g.length);
    GeodesicPoint {
        point: p.into(),
        length: s,
        ..g
    }
}

/// Where the transverse geodesic starts: the middle (by length) of the start line.
struct Start {
    /// The middle point.
    point: [f64; 3],
    /// The triangle on each side of the line there (one on the boundary; inside the film two,
    /// the right one first) and the direction into it, perpendicular to the line.
    sides: Vec<(usize, [f64; 3])>,
}

/// The start of the transverse geodesic from the start `line`, checked: its nodes are nodes,
/// consecutive ones share a triangle edge, and a line inside the film ends on the boundary.
fn start_of(surface: &Surface<'_>, line: &[usize]) -> Result<Start, String> {
    let n = surface.model.nodes.len();
    if let Some(v) = line.iter().find(|&&v| v >= n) {
        return Err(format!(
            "geodesic seams: start line node {v} is not a node of the model"
        ));
    }
    if line.len() < 2 {
        return Err("geodesic seams: the start line needs two nodes or more".into());
    }
    let mut lengths = vec![0.0];
    for w in line.windows(2) {
        if !surface.by_edge.contains_key(&key(w[0], w[1])) {
            return Err(format!(
                "geodesic seams: start line nodes {} and {} are not joined by a triangle edge",
                w[0], w[1]
            ));
        }
        lengths.push(lengths.last().unwrap() + (surface.x(w[1]) - surface.x(w[0])).norm());
    }
    let half = 0.5 * lengths.last().unwrap();
    let i = lengths
        .partition_point(|&l| l <= half)
        .clamp(1, line.len() - 1)
        - 1;
    let (a, b) = (line[i], line[i + 1]);
    let triangles = &surface.by_edge[&key(a, b)];
    if triangles.len() > 2 {
        return Err(format!(
            "geodesic seams: the start line's segment {a}–{b} is an edge of more than two triangles"
        ));
    }
    if triangles.len() == 2 {
        let ends = [line[0], line[line.len() - 1]];
        if let Some(v) = ends.into_iter().find(|&v| !surface.on_boundary(v)) {
            return Err(format!(
                "geodesic seams: the start line lies inside the film but its end node {v} is not on the film's boundary"
            ));
        }
    }
    let e = surface.x(b) - surface.x(a);
    let p = surface.x(a) + e * ((half - lengths[i]) / e.norm());
    // At a node inside the line, the line's tangent there is the chord of its two neighbours.
    let tangent = match (half - lengths[i] < 1e-9 * e.norm(), i.checked_sub(1)) {
        (true, Some(before)) => surface.x(b) - surface.x(line[before]),
        _ => e,
    };
    let mut sides: Vec<(usize, V3)> = (triangles.iter())
        .map(|&t| {
            let into = across(
                surface.x(surface.third(t, a, b)) - surface.x(a),
                tangent.normalize(),
            );
            (t, into)
        })
        .collect();
    // Inside the film the right side (walking along the line, the normals up) goes first: the
    // transverse geodesic then runs from the left side's boundary to the right side's.
    sides.sort_by_key(|&(t, d)| tangent.cross(&d).dot(&surface.normal(t)) > 0.0);
    Ok(Start {
        point: p.into(),
        sides: sides.into_iter().map(|(t, d)| (t, d.into())).collect(),
    })
}

/// The start `line` as a seam: its nodes, each segment in a triangle of its edge.
fn line_seam(surface: &Surface<'_>, line: &[usize]) -> Vec<GeodesicPoint> {
    let mut length = 0.0;
    let mut seam = Vec::with_capacity(line.len());
    for (i, &v) in line.iter().enumerate() {
        let (a, b) = (line[i.min(line.len() - 2)], line[i.min(line.len() - 2) + 1]);
        let chord = surface.x(b) - surface.x(a);
        seam.push(GeodesicPoint {
            point: surface.x(v).into(),
            triangle: surface.by_edge[&key(a, b)][0],
            direction: chord.normalize().into(),
            length,
        });
        if i + 1 < line.len() {
            length += (surface.x(line[i + 1]) - surface.x(v)).norm();
        }
    }
    seam
}

/// The geodesic `back` (from a point) reversed and joined to `forward` (from the same point):
/// one path, each point's direction the chord to the next and its length from the path's start.
fn joined(back: &[GeodesicPoint], forward: Vec<GeodesicPoint>) -> Vec<GeodesicPoint> {
    // The segment from back[j+1] to back[j] lies in back[j]'s triangle.
    let mut path: Vec<GeodesicPoint> = (1..back.len())
        .rev()
        .map(|j| GeodesicPoint {
            point: back[j].point,
            triangle: back[j - 1].triangle,
            ..back[j]
        })
        .collect();
    path.extend(forward);
    let mut length = 0.0;
    for i in 0..path.len() {
        let next = path.get(i + 1).map_or(path[i].point, |g| g.point);
        let chord = V3::from(next) - V3::from(path[i].point);
        path[i].length = length;
        if chord.norm() > 0.0 {
            path[i].direction = chord.normalize().into();
        }
        length += chord.norm();
    }
    path
}

/// One seam through `g` (a point of the transverse geodesic), perpendicular to it, from
/// boundary to boundary; each point's direction is the chord to the next.
fn seam_through(surface: &Surface<'_>, g: GeodesicPoint) -> Vec<GeodesicPoint> {
    let along = surface.normal(g.triangle).cross(&V3::from(g.direction));
    let forward = surface.trace(g.triangle, g.point, along.into(), f64::INFINITY);
    let back = surface.trace(g.triangle, g.point, (-along).into(), f64::INFINITY);
    joined(&back, forward)
}

/// Whether `c` lies on the side of `seam` that `towards` (a point and direction near it)
/// points to: by the seam's segment nearest to each.
fn beyond(surface: &Surface<'_>, seam: &[GeodesicPoint], c: V3, towards: (V3, V3)) -> bool {
    let side = |q: V3| {
        let segments = seam.windows(2).filter(|w| w[0].point != w[1].point);
        let nearest = segments.map(|w| {
            let (a, b) = (V3::from(w[0].point), V3::from(w[1].point));
            let foot =
                a + (b - a) * ((q - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
            let normal = surface.normal(w[0].triangle);
            ((q - foot).norm(), (q - foot).dot(&normal.cross(&(b - a))))
        });
        nearest
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(0.0, |n| n.1)
    };
    let reference = side(towards.0 + towards.1 * 1e-6).signum();
    side(c) * reference > 0.0
}

/// The geodesic seams at arc lengths `k · width` (`k = 1, 2, …`) along the transverse geodesic
/// from the start `line` (mesh nodes along the film's boundary, or across the film from
/// boundary to boundary: then the line is a seam and the others lie on both sides of it), and
/// the strips between them.
pub fn geodesic_seams(model: &Model, line: &[usize], width: f64) -> Result<GeodesicSeams, String> {
    if !(width > 0.0 && width.is_finite()) {
        return Err(format!(
            "geodesic seams: strip width {width} must be positive"
        ));
    }
    let surface = Surface::new(model);
    let start = start_of(&surface, line)?;
    let halves: Vec<Vec<GeodesicPoint>> = (start.sides.iter())
        .map(|&(t, d)| surface.trace(t, start.point, d, f64::INFINITY))
        .collect();
    let (transverse, origin) = match &halves[..] {
        // The start point is the back half's last point, reversed: at index back.len() − 1.
        [forward, back] => {
            let path = joined(back, forward.clone());
            let origin = path[back.len() - 1].length;
            (path, origin)
        }
        _ => (halves[0].clone(), 0.0),
    };
    let total = transverse.last().map_or(0.0, |g| g.length);
    let before = (1..)
        .map(|k| origin - k as f64 * width)
        .take_while(|&s| s > 1e-6 * width);
    let after = (1..)
        .map(|k| origin + k as f64 * width)
        .take_while(|&s| s < total - 1e-6 * width);
    let mut offsets: Vec<f64> = before.collect();
    offsets.reverse();
    let start_seam = (start.sides.len() == 2).then_some(offsets.len());
    offsets.extend(start_seam.map(|_| origin));
    offsets.extend(after);
    let at: Vec<GeodesicPoint> = offsets.iter().map(|&s| point_at(&transverse, s)).collect();
    let seams: Vec<Vec<GeodesicPoint>> = (at.iter().enumerate())
        .map(|(k, &g)| match start_seam == Some(k) {
            true => line_seam(&surface, line),
            false => seam_through(&surface, g),
        })
        .collect();
    Ok(GeodesicSeams {
        strips: strips_between(&surface, &seams, &at, width),
        transverse,
        origin,
        seams,
        start_seam,
    })
}

/// The triangles of each strip: those beyond the same number of `seams` (each crossing the
/// transverse geodesic at its point of `at`), in their order.
fn strips_between(
    surface: &Surface<'_>,
    seams: &[Vec<GeodesicPoint>],
    at: &[GeodesicPoint],
    width: f64,
) -> Vec<Vec<usize>> {
    let mut strips: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for (t, tri) in surface.model.triangles.iter().enumerate() {
        let c = tri.iter().map(|&v| surface.x(v)).sum::<V3>() / 3.0;
        let index = (seams.iter().zip(at))
            .filter(|(seam, g)| {
                beyond(
                    surface,
                    seam,
                    c,
                    (V3::from(g.point), V3::from(g.direction) * width),
                )
            })
            .count();
        strips.entry(index).or_default().push(t);
    }
    strips.into_values().collect()
}
