//! Film-to-film contact between two meshed layers of one model (issue 43, "layers that
//! touch"): node to surface, each slave node against the master layer's flat triangles, and
//! optionally both ways (each layer's nodes against the other's triangles, the classical
//! two-pass node-to-surface scheme).
//!
//! **Kinematics** (Wriggers, *Computational Contact Mechanics*, 2006, §4.1 and §9.1; Laursen,
//! *Computational Contact and Impact Mechanics*, 2002, ch. 5). Master triangle `x1 x2 x3`,
//! `a1 = x2 − x1`, `a2 = x3 − x1`, unit normal `n = s (a1 × a2)/|a1 × a2|` with the side
//! `s = ±1` the slave lies on. The closest point of the slave node `x` on the triangle's plane
//! has the convected coordinates `ξ = G⁻¹ Aᵀ (x − x1)` (`A = [a1 a2]`, `G = AᵀA`), the gap is
//! `g = (x − x1)·n`. The pair is in contact when `g < 0` and the projection lies in the
//! triangle (each shape function `≥ −`[`EXTEND`], so a node over a ridge between two triangles
//! is not lost in the gap between their normals).
//!
//! **Law** (penalty, as the gaps and the curved supports): `λN = −k_n g`; the tangential gap
//! is the vector from the master's material point at the anchor `ξ̄` to the contact point,
//! `g_T = A (ξ − ξ̄)`; trial `f* = −k_s g_T`; isotropic Coulomb: stick `f = f*` where
//! `|f*| ≤ μ λN`, else slip `f = μ λN f*/|f*|` (the return mapping onto the cone). The anchor
//! committed with a converged state is `ξ̄ ← ξ + G⁻¹ Aᵀ f / k_s` (the point `f` implies), the
//! slip of the increment `|f − f*|/k_s`. Force on the slave `F = λN n + f`; on the master's
//! nodes `−N_i(ξ) F` (`N = (1 − ξ1 − ξ2, ξ1, ξ2)`): the pair's forces sum to zero.
//!
//! **Tangent.** The pair's residual `−F` is written once in forward dual numbers ([`dual`])
//! over its twelve coordinates, so its Jacobian (the consistent tangent, including the moving
//! projection `∂ξ/∂x`, the rotating normal and the return mapping) is exact; the tests check it
//! against central differences in every status.
//!
//! **Search.** Each slave node's candidate triangles are those of the master within
//! `search_distance` of it in the reference configuration (brute force once at setup,
//! `O(slave nodes × master triangles)`; they also fix the sparsity pattern). At every
//! evaluation the node keeps its history's triangle while it projects in it, else takes the
//! candidate whose closest point (clamped to the triangle) is nearest: `O(candidates)` per node
//! and iterate. A node that leaves its candidates' reach loses
//! contact: choose `search_distance` above the largest sliding expected.
//!
//! | file | what |
//! |---|---|
//! | `mod.rs` | the model item, the setup (passes, candidates), the pair's law |
//! | [`dual`] | forward dual numbers for the pair's tangent |
//! | `tests` | tangent against central differences in every status, force balance |

pub mod dual;

use nalgebra::{Matrix2, SMatrix, SVector, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::mech::elements::gap::{FrictionLaw, GapStatus};
use crate::mech::model::Model;
use dual::{Dual, V3};

/// How far outside a master triangle (in shape-function value) a projection still counts.
pub const EXTEND: f64 = 0.05;

/// The pair's 12×12 tangent (slave node, then the triangle's three nodes).
pub type PairMatrix = SMatrix<f64, 12, 12>;
/// The pair's 12 residual components.
pub type PairVector = SVector<f64, 12>;

/// One layer of a layer contact: a named `layers` item or a list of triangles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum LayerSurface {
    /// The triangles of the model's layer of this name.
    Layer(String),
    /// The listed triangles (0-based).
    Triangles(Vec<usize>),
}

/// On which side of the master triangles the slave layer lies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// Along the triangles' normal `(x2 − x1) × (x3 − x1)` (node order, right-hand rule).
    #[default]
    Front,
    /// Against it.
    Back,
}

/// Two layers that may touch (`"layer_contacts"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerContactSpec {
    /// Name (an identifier).
    pub name: String,
    /// The layer whose nodes are checked against the master's triangles.
    pub slave: LayerSurface,
    /// The layer whose triangles the slave's nodes may not cross.
    pub master: LayerSurface,
    /// The side of the master's triangles the slave lies on.
    #[serde(default)]
    pub side: Side,
    /// Also the master's nodes against the slave's triangles (two-pass).
    #[serde(default)]
    pub both_ways: bool,
    /// Penalty `k_n` per node (N/m).
    pub normal_stiffness: f64,
    /// Penalty `k_s` per node (N/m).
    pub tangential_stiffness: f64,
    /// Coulomb coefficient `μ` (0: frictionless).
    #[serde(default)]
    pub friction: f64,
    /// Friction law: only `isotropic` (film on film has no preferred sliding direction).
    #[serde(default)]
    pub friction_law: FrictionLaw,
    /// Reach of the contact search in the reference configuration (m).
    pub search_distance: f64,
}

impl LayerContactSpec {
    /// The triangles of `surface` in `model` (Err: an unknown layer).
    pub fn triangles(model: &Model, surface: &LayerSurface) -> Result<Vec<usize>, String> {
        match surface {
            LayerSurface::Triangles(list) => Ok(list.clone()),
            LayerSurface::Layer(name) => model
                .layers
                .iter()
                .find(|l| &l.name == name)
                .map(|l| model.selected_triangles(&l.elements))
                .ok_or_else(|| format!("names layer '{name}', which the model does not have")),
        }
    }
}

/// A candidate master triangle of a slave node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// The triangle (model index).
    pub triangle: usize,
    /// The side `s` of its normal the slave lies on.
    pub sign: f64,
    /// The pair's block in the system's pattern.
    pub block: usize,
}

/// A slave node of one pass of a layer contact.
#[derive(Clone, Debug, PartialEq)]
pub struct SlaveNode {
    /// The node.
    pub node: usize,
    /// The layer contact (model order).
    pub contact: usize,
    /// Whether it belongs to the reverse pass (a master-layer node).
    pub reverse: bool,
    /// Its tributary area in its layer, reference configuration (m²).
    pub area: f64,
    /// The triangles it may touch.
    pub candidates: Vec<Candidate>,
}

/// Every slave node of the model's layer contacts and the pairs of the pattern.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LayerContactSetup {
    /// Slave nodes: contacts in model order, the forward pass before the reverse.
    pub slaves: Vec<SlaveNode>,
    /// `(slave node, triangle nodes)` of each pattern block, in block order.
    pub blocks: Vec<(usize, [usize; 3])>,
}

fn position(model: &Model, v: usize) -> Vector3<f64> {
    Vector3::from(model.nodes[v])
}

fn corners(model: &Model, t: usize) -> [Vector3<f64>; 3] {
    model.triangles[t].map(|v| position(model, v))
}

fn unit_normal(x: &[Vector3<f64>; 3]) -> Vector3<f64> {
    (x[1] - x[0]).cross(&(x[2] - x[0])).normalize()
}

impl LayerContactSetup {
    /// The slave nodes and candidates of a validated `model` (empty without layer contacts).
    pub fn new(model: &Model) -> Self {
        let mut setup = Self::default();
        for (c, spec) in model.layer_contacts.iter().enumerate() {
            let (Ok(slave), Ok(master)) = (
                LayerContactSpec::triangles(model, &spec.slave),
                LayerContactSpec::triangles(model, &spec.master),
            ) else {
                continue;
            };
            let s = if spec.side == Side::Front { 1.0 } else { -1.0 };
            let forward: Vec<(usize, f64)> = master.iter().map(|&t| (t, s)).collect();
            setup.add_pass(model, c, false, &slave, &forward, spec.search_distance);
            if spec.both_ways {
                // The master layer lies on the side −s n_M of its nearest master triangle M.
                let back: Vec<(usize, f64)> = slave
                    .iter()
                    .map(|&t| {
                        let x = corners(model, t);
                        let centre = (x[0] + x[1] + x[2]) / 3.0;
                        let nearest = master.iter().copied().min_by(|&a, &b| {
                            let d = |m| closest_point(&centre, &corners(model, m)).0;
                            d(a).total_cmp(&d(b))
                        });
                        let toward = nearest.map_or(0.0, |m| {
                            -s * unit_normal(&x).dot(&unit_normal(&corners(model, m)))
                        });
                        (t, if toward < 0.0 { -1.0 } else { 1.0 })
                    })
                    .collect();
                setup.add_pass(model, c, true, &master, &back, spec.search_distance);
            }
        }
        setup
    }

    /// Adds the nodes of `slave`'s triangles against the (triangle, side) list `master`.
    fn add_pass(
        &mut self,
        model: &Model,
        contact: usize,
        reverse: bool,
        slave: &[usize],
        master: &[(usize, f64)],
        reach: f64,
    ) {
        let mut area = vec![0.0; model.nodes.len()];
        let mut nodes = Vec::new();
        for &t in slave {
            let x = corners(model, t);
            let a = (x[1] - x[0]).cross(&(x[2] - x[0])).norm() / 6.0;
            for &v in &model.triangles[t] {
                if area[v] == 0.0 {
                    nodes.push(v);
                }
                area[v] += a;
            }
        }
        nodes.sort_unstable();
        for node in nodes {
            let x = position(model, node);
            let mut candidates = Vec::new();
            for &(t, sign) in master {
                let tri = model.triangles[t];
                if tri.contains(&node) || closest_point(&x, &corners(model, t)).0 > reach {
                    continue;
                }
                candidates.push(Candidate {
                    triangle: t,
                    sign,
                    block: self.blocks.len(),
                });
                self.blocks.push((node, tri));
            }
            self.slaves.push(SlaveNode {
                node,
                contact,
                reverse,
                area: area[node],
                candidates,
            });
        }
    }
}

/// The convected coordinates `ξ` of the projection of `x` on the plane of triangle `t`.
pub fn plane_coordinates(x: &Vector3<f64>, t: &[Vector3<f64>; 3]) -> Vector2<f64> {
    let a1 = t[1] - t[0];
    let a2 = t[2] - t[0];
    let r = x - t[0];
    let g = Matrix2::new(a1.dot(&a1), a1.dot(&a2), a1.dot(&a2), a2.dot(&a2));
    g.try_inverse().unwrap_or_else(Matrix2::zeros) * Vector2::new(a1.dot(&r), a2.dot(&r))
}

/// The smallest shape function `min(1 − ξ1 − ξ2, ξ1, ξ2)` at `xi` (negative: outside).
pub fn inside(xi: &Vector2<f64>) -> f64 {
    (1.0 - xi.x - xi.y).min(xi.x).min(xi.y)
}

/// Distance from `x` to triangle `t` (clamped to the triangle) and the unclamped `ξ`.
pub fn closest_point(x: &Vector3<f64>, t: &[Vector3<f64>; 3]) -> (f64, Vector2<f64>) {
    let xi = plane_coordinates(x, t);
    if inside(&xi) >= 0.0 {
        let p = t[0] + (t[1] - t[0]) * xi.x + (t[2] - t[0]) * xi.y;
        return ((x - p).norm(), xi);
    }
    let segment = |a: &Vector3<f64>, b: &Vector3<f64>| {
        let e = b - a;
        let s = ((x - a).dot(&e) / e.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        (x - (a + e * s)).norm()
    };
    let d = segment(&t[0], &t[1])
        .min(segment(&t[1], &t[2]))
        .min(segment(&t[2], &t[0]));
    (d, xi)
}

/// The law of one pair: penalties, friction and side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairLaw {
    /// `k_n` (N/m).
    pub kn: f64,
    /// `k_s` (N/m).
    pub ks: f64,
    /// `μ`.
    pub mu: f64,
    /// The side `s` of the triangle's normal the slave lies on.
    pub sign: f64,
}

/// A pair's response at one iterate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairResponse {
    /// Residual `−F` on the slave, `N_i F` on the master's nodes (N).
    pub residual: PairVector,
    /// Its Jacobian over the twelve coordinates.
    pub tangent: PairMatrix,
    /// Open, stick or slip.
    pub status: GapStatus,
    /// `λN` (N).
    pub normal_force: f64,
    /// The signed gap (m; negative: pressed in).
    pub gap: f64,
    /// The friction force on the slave (N).
    pub friction: Vector3<f64>,
    /// `ξ` at this iterate.
    pub xi: Vector2<f64>,
    /// The anchor to commit if it converges.
    pub next_anchor: Vector2<f64>,
    /// The slip of this increment `|f − f*|/k_s` (m).
    pub slip: f64,
}

impl PairResponse {
    /// An open pair at `gap` whose node projects at `xi`: no force, no stiffness.
    pub fn open(gap: f64, xi: Vector2<f64>) -> Self {
        Self {
            residual: PairVector::zeros(),
            tangent: PairMatrix::zeros(),
            status: GapStatus::Open,
            normal_force: 0.0,
            gap,
            friction: Vector3::zeros(),
            xi,
            // An open pair forgets its anchor: it sticks where it touches down next.
            next_anchor: xi,
            slip: 0.0,
        }
    }
}

/// The pair's response at positions `x` (slave, then the triangle's nodes) from the anchor
/// `anchor` (`ξ̄` in this triangle), with the friction status `held` imposed where closed
/// (None: the law's own).
pub fn respond(
    x: &[Vector3<f64>; 4],
    anchor: Vector2<f64>,
    law: &PairLaw,
    held: Option<GapStatus>,
) -> PairResponse {
    let p: [V3; 4] =
        std::array::from_fn(|i| std::array::from_fn(|k| Dual::variable(x[i][k], 3 * i + k)));
    let a1 = dual::sub(&p[2], &p[1]);
    let a2 = dual::sub(&p[3], &p[1]);
    let r = dual::sub(&p[0], &p[1]);
    let m = dual::cross(&a1, &a2);
    let n = dual::scale(&m, Dual::constant(law.sign) / dual::dot(&m, &m).sqrt());
    let (g11, g12, g22) = (
        dual::dot(&a1, &a1),
        dual::dot(&a1, &a2),
        dual::dot(&a2, &a2),
    );
    let det = g11 * g22 - g12 * g12;
    let (b1, b2) = (dual::dot(&a1, &r), dual::dot(&a2, &r));
    let xi1 = (g22 * b1 - g12 * b2) / det;
    let xi2 = (g11 * b2 - g12 * b1) / det;
    let gap = dual::dot(&r, &n);
    let xi = Vector2::new(xi1.v, xi2.v);
    let mut out = PairResponse::open(gap.v, xi);
    if gap.v >= 0.0 {
        return out;
    }
    let lambda = gap * (-law.kn);
    let slide = dual::add(
        &dual::scale(&a1, xi1 - Dual::constant(anchor.x)),
        &dual::scale(&a2, xi2 - Dual::constant(anchor.y)),
    );
    let trial = dual::scale(&slide, Dual::constant(-law.ks));
    let size = dual::dot(&trial, &trial).v.sqrt();
    let limit = law.mu * lambda.v;
    let stick = size == 0.0
        || match held {
            Some(GapStatus::Stick) => true,
            Some(GapStatus::Slip) => false,
            _ => size <= limit,
        };
    let f = if stick {
        trial
    } else {
        dual::scale(&trial, lambda * law.mu / dual::dot(&trial, &trial).sqrt())
    };
    let force = dual::add(&dual::scale(&n, lambda), &f);
    let shape = [Dual::constant(1.0) - xi1 - xi2, xi1, xi2];
    for (k, &component) in force.iter().enumerate() {
        let rows = [-component]
            .into_iter()
            .chain(shape.iter().map(|&s| s * component));
        for (i, value) in rows.enumerate() {
            out.residual[3 * i + k] = value.v;
            for j in 0..12 {
                out.tangent[(3 * i + k, j)] = value.d[j];
            }
        }
    }
    let fv = Vector3::new(f[0].v, f[1].v, f[2].v);
    let tv = Vector3::new(trial[0].v, trial[1].v, trial[2].v);
    let (a1v, a2v) = (x[2] - x[1], x[3] - x[1]);
    let metric = Matrix2::new(g11.v, g12.v, g12.v, g22.v);
    let back = metric.try_inverse().unwrap_or_else(Matrix2::zeros)
        * Vector2::new(a1v.dot(&fv), a2v.dot(&fv));
    out.status = if stick {
        GapStatus::Stick
    } else {
        GapStatus::Slip
    };
    out.normal_force = lambda.v;
    out.friction = fv;
    out.next_anchor = xi + back / law.ks;
    out.slip = (fv - tv).norm() / law.ks;
    out
}

/// History of one slave node, carried from one converged state to the next.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LayerContactHistory {
    /// The master triangle of the anchor (None: the node projected on none).
    pub triangle: Option<usize>,
    /// Anchor `ξ̄` in that triangle.
    pub anchor: [f64; 2],
    /// Status at convergence.
    pub status: GapStatus,
    /// Slip accumulated over the converged increments (m).
    pub slip: f64,
}

impl Default for LayerContactHistory {
    fn default() -> Self {
        Self {
            triangle: None,
            anchor: [0.0; 2],
            status: GapStatus::Open,
            slip: 0.0,
        }
    }
}

/// Results of one slave node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LayerContactResult {
    /// `<contact>.<node>` (forward pass) or `<contact>.back.<node>` (reverse pass).
    pub name: String,
    /// The layer contact (model order).
    pub contact: usize,
    /// The slave node.
    pub node: usize,
    /// The master triangle it is projected on (None: none within reach).
    pub triangle: Option<usize>,
    /// Signed gap (m; negative: penetration).
    pub gap: f64,
    /// Normal force (N).
    pub normal_force: f64,
    /// Contact pressure: the normal force over the node's tributary area (Pa).
    pub pressure: f64,
    /// Friction force on the slave, global axes (N).
    pub friction: [f64; 3],
    /// Slip accumulated between the layers (m).
    pub slip: f64,
    /// Status.
    pub status: GapStatus,
}

/// What a layer contact carries over all its slave nodes (both passes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Totals {
    /// Total normal force (N).
    pub normal_force: f64,
    /// Nodes in contact.
    pub closed: usize,
    /// Nodes sliding.
    pub sliding: usize,
    /// Largest contact pressure (Pa).
    pub max_pressure: f64,
    /// Largest slip (m).
    pub max_slip: f64,
}

impl Totals {
    /// The totals of layer contact `k` in `results`.
    pub fn of(results: &crate::mech::results::Results, k: usize) -> Self {
        let mut t = Self::default();
        for c in results.layer_contacts.iter().filter(|c| c.contact == k) {
            t.normal_force += c.normal_force;
            t.closed += usize::from(c.status != GapStatus::Open);
            t.sliding += usize::from(c.status == GapStatus::Slip);
            t.max_pressure = t.max_pressure.max(c.pressure);
            t.max_slip = t.max_slip.max(c.slip);
        }
        t
    }
}

/// One line per layer contact: its total normal force, nodes in contact (of which sliding),
/// largest contact pressure and slip (the CLI's report).
pub fn summary(model: &Model, results: &crate::mech::results::Results) -> Vec<String> {
    model
        .layer_contacts
        .iter()
        .enumerate()
        .map(|(k, spec)| {
            let t = Totals::of(results, k);
            format!(
                "layer contact {}: normal force {:.3} N, {} nodes in contact ({} sliding), \
                 largest contact pressure {:.3} Pa, largest slip {:.3} mm{}",
                spec.name,
                t.normal_force,
                t.closed,
                t.sliding,
                t.max_pressure,
                t.max_slip * 1e3,
                if spec.both_ways {
                    " (two-way: each pass carries about half the pressure between the layers)"
                } else {
                    ""
                }
            )
        })
        .collect()
}

#[cfg(test)]
mod tests;
