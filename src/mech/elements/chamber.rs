//! Enclosed gas chambers (issue 43; docs/mechanics.md, "Chambers"): the volume a set of film
//! triangles encloses, its gradient and Hessian, and the gas law that makes the pressure a
//! function of it.
//!
//! The volume is the divergence theorem on the current configuration, summed as signed
//! tetrahedra from an origin `o`: `V = Σ (x1 − o)·((x2 − o) × (x3 − o))/6` over the chamber's
//! triangles, each oriented so that its node-order normal points out of the chamber. For a
//! closed surface `o` is arbitrary; a surface closed by a rigid plane (the frame's plane) puts
//! `o` on that plane, whose own face then adds nothing (`(x − o)·n = 0` on it). The pressure's
//! nodal forces are `p ∂V/∂x` — the follower pressure on each triangle, and on the nodes of the
//! plane's rim their share of the closing face — and the tangent gains the pneumatic stiffness
//! `−(dp/dV) g gᵀ` (`g = ∂V/∂u`) beside the load stiffness `−p ∂²V/∂u²`.

use std::collections::HashMap;

use nalgebra::{Matrix3, Vector3};

use crate::mech::elements::triangle::{ElementMatrix, ElementVector};
use crate::mech::model::{ChamberSpec, Model};

/// `(x1 − o)·((x2 − o) × (x3 − o))/6`: the signed volume of the tetrahedron from `o` on one
/// triangle with current nodes `x`.
pub fn tet_volume(o: &Vector3<f64>, x: &[Vector3<f64>; 3]) -> f64 {
    (x[0] - o).dot(&(x[1] - o).cross(&(x[2] - o))) / 6.0
}

/// `∂V/∂x` of [`tet_volume`]: node `a`'s block is `(x_b − o) × (x_c − o)/6`, `(a, b, c)` cyclic.
pub fn tet_gradient(o: &Vector3<f64>, x: &[Vector3<f64>; 3]) -> ElementVector {
    let mut g = ElementVector::zeros();
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let block = (x[b] - o).cross(&(x[c] - o)) / 6.0;
        g.fixed_rows_mut::<3>(3 * a).copy_from(&block);
    }
    g
}

/// `∂²V/∂x²` of [`tet_volume`] (9×9, symmetric): block `(a, b)` is `−[x_c − o]×/6` and block
/// `(a, c)` is `[x_b − o]×/6` for `(a, b, c)` cyclic; the diagonal blocks are zero.
pub fn tet_hessian(o: &Vector3<f64>, x: &[Vector3<f64>; 3]) -> ElementMatrix {
    let mut h = ElementMatrix::zeros();
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        h.fixed_view_mut::<3, 3>(3 * a, 3 * b)
            .copy_from(&(-skew(&(x[c] - o)) / 6.0));
        h.fixed_view_mut::<3, 3>(3 * a, 3 * c)
            .copy_from(&(skew(&(x[b] - o)) / 6.0));
    }
    h
}

/// `[v]×`, the matrix of `w ↦ v × w`.
fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The enclosed gas's law `(p + p_a) V^κ = C T/T₀` (Boyle–Mariotte and Gay-Lussac for `κ = 1`,
/// isothermal; the adiabatic law for `κ = 1.4`), `p` the gauge pressure (Pa), `p_a` the
/// atmosphere's, `T` the air's temperature and `C` the gas's constant at its reference
/// temperature `T₀`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GasLaw {
    /// Polytropic exponent `κ` (1: isothermal, 1.4: adiabatic air).
    pub kappa: f64,
    /// Atmospheric pressure `p_a` (Pa).
    pub atmosphere: f64,
    /// Reference temperature `T₀` of the constant (K).
    pub temperature: f64,
}

/// The specific gas constant of dry air (J/(kg K)).
pub const AIR_GAS_CONSTANT: f64 = 287.05;

impl GasLaw {
    /// `C` of gas at gauge pressure `p` in volume `v` at temperature `t`.
    pub fn constant(&self, p: f64, v: f64, t: f64) -> f64 {
        (p + self.atmosphere) * v.powf(self.kappa) * self.temperature / t
    }

    /// The gauge pressure `C (T/T₀) / V^κ − p_a` of the gas of constant `c` in volume `v` at
    /// temperature `t`.
    pub fn pressure(&self, c: f64, v: f64, t: f64) -> f64 {
        c * (t / self.temperature) / v.powf(self.kappa) - self.atmosphere
    }

    /// `dp/dV = −κ C (T/T₀) / V^{κ+1}` (negative: compressing the gas raises its pressure).
    pub fn slope(&self, c: f64, v: f64, t: f64) -> f64 {
        -self.kappa * c * (t / self.temperature) / v.powf(self.kappa + 1.0)
    }

    /// The mass of air (kg) at gauge pressure `p` in volume `v` at temperature `t` (ideal gas).
    pub fn mass(&self, p: f64, v: f64, t: f64) -> f64 {
        (p + self.atmosphere) * v / (AIR_GAS_CONSTANT * t)
    }
}

/// A chamber's boundary: each of its triangles with the sign that orients it out of the
/// chamber, and the origin of its tetrahedra (on the closing plane, if any).
#[derive(Clone, Debug, PartialEq)]
pub struct ChamberGeometry {
    /// `(triangle, ±1)`: the triangle's node-order volume times the sign is its share.
    pub triangles: Vec<(usize, f64)>,
    /// Each triangle's nodes, in [`Self::triangles`]' order.
    corners: Vec<[usize; 3]>,
    /// The tetrahedra's common apex `o` (m).
    pub origin: Vector3<f64>,
}

impl ChamberGeometry {
    /// The boundary of `spec` in `model`, oriented out of the chamber by its shared edges:
    /// Err names what is wrong (an edge of three triangles, a surface that cannot be oriented,
    /// an open rim off the closing plane or without one, no volume enclosed).
    pub fn new(model: &Model, spec: &ChamberSpec) -> Result<Self, String> {
        let triangles = model.selected_triangles(&spec.elements);
        if triangles.is_empty() {
            return Err("has no triangles".into());
        }
        let signs = orient(model, &triangles)?;
        let x = |v: usize| Vector3::from(model.nodes[v]);
        let size = crate::mech::model::bounding_diagonal(&model.nodes);
        let rim = rim_edges(model, &triangles);
        let origin = match &spec.closed_by_plane {
            Some(plane) => {
                let (p, n) = (Vector3::from(plane.point), Vector3::from(plane.normal));
                if n.norm() == 0.0 || !n.iter().chain(p.iter()).all(|v| v.is_finite()) {
                    return Err("closed_by_plane needs a finite point and a non-zero normal".into());
                }
                let n = n.normalize();
                for &(a, b) in &rim {
                    for v in [a, b] {
                        let off = (x(v) - p).dot(&n);
                        if off.abs() > 1e-6 * size {
                            return Err(format!(
                                "node {v} of its rim is {off:.3e} m off the closing plane"
                            ));
                        }
                    }
                }
                p
            }
            None => {
                if let Some(&(a, b)) = rim.first() {
                    return Err(format!(
                        "is not closed: edge ({a}, {b}) bounds one of its triangles only \
                         (close it by a plane with closed_by_plane, or add the other layer)"
                    ));
                }
                x(model.triangles[triangles[0]][0])
            }
        };
        let mut geometry = Self {
            corners: triangles.iter().map(|&e| model.triangles[e]).collect(),
            triangles: triangles.into_iter().zip(signs).collect(),
            origin,
        };
        let v = geometry.volume(
            &model
                .nodes
                .iter()
                .map(|&p| Vector3::from(p))
                .collect::<Vec<_>>(),
        );
        // Out of the chamber: a positive volume. Where the reference encloses none (a flat film
        // on its closing plane, flat layers welded at their rim) the plane's normal orients it
        // (the chamber on its side), else the node order of the chamber's first triangle.
        let side = match &spec.closed_by_plane {
            _ if v.abs() > 1e-12 * size.powi(3) => v,
            Some(plane) => geometry
                .area_vector(model)
                .dot(&Vector3::from(plane.normal)),
            None => geometry.triangles[0].1,
        };
        if spec.sealed && v.abs() <= 1e-12 * size.powi(3) {
            return Err(
                "is sealed but encloses no volume in the reference geometry \
                        (inflate it from a supply, then seal it)"
                    .into(),
            );
        }
        if side < 0.0 {
            for t in &mut geometry.triangles {
                t.1 = -t.1;
            }
        }
        Ok(geometry)
    }

    /// The enclosed volume (m³) with the nodes at `x`.
    pub fn volume(&self, x: &[Vector3<f64>]) -> f64 {
        self.triangles
            .iter()
            .zip(&self.corners)
            .map(|(&(_, sign), c)| sign * tet_volume(&self.origin, &c.map(|v| x[v])))
            .sum()
    }

    /// Sum of the oriented triangles' area vectors in the reference geometry.
    fn area_vector(&self, model: &Model) -> Vector3<f64> {
        self.triangles
            .iter()
            .map(|&(e, sign)| {
                let x = model.triangles[e].map(|v| Vector3::from(model.nodes[v]));
                (x[1] - x[0]).cross(&(x[2] - x[0])) * (0.5 * sign)
            })
            .sum()
    }

    /// Each triangle with its orientation sign and nodes.
    pub fn oriented(&self) -> impl Iterator<Item = (usize, f64, [usize; 3])> + '_ {
        self.triangles
            .iter()
            .zip(&self.corners)
            .map(|(&(e, sign), &c)| (e, sign, c))
    }
}

/// One line per chamber of `model` for `check`: its triangles, what closes it, the volume it
/// encloses in the reference geometry and its air.
pub fn chamber_report(model: &Model) -> Vec<String> {
    let x: Vec<Vector3<f64>> = model.nodes.iter().map(|&p| Vector3::from(p)).collect();
    model
        .chambers
        .iter()
        .map(|c| {
            let closed = match &c.closed_by_plane {
                None => "closed by its own triangles".to_string(),
                Some(p) => format!(
                    "closed by the plane through {:?} with normal {:?} into it",
                    p.point, p.normal
                ),
            };
            let volume = ChamberGeometry::new(model, c).map_or(f64::NAN, |g| g.volume(&x));
            let air = if c.sealed {
                format!("air enclosed at {} Pa (κ {})", c.pressure, c.kappa)
            } else {
                format!("air held by a supply at {} Pa", c.pressure)
            };
            format!(
                "chamber '{}': {} triangles, {closed}, {volume:.6} m³ in the reference geometry, {air}",
                c.name,
                model.selected_triangles(&c.elements).len()
            )
        })
        .collect()
}

/// Orientation signs of `triangles` (+1 keeps the node order) so that every edge two of them
/// share is traversed once each way: a flood over shared edges from the first triangle of each
/// connected part. Err names an edge of three triangles or one that cannot be made consistent.
fn orient(model: &Model, triangles: &[usize]) -> Result<Vec<f64>, String> {
    let mut by_edge: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (k, &e) in triangles.iter().enumerate() {
        let t = model.triangles[e];
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(k);
        }
    }
    if let Some(((a, b), _)) = by_edge.iter().find(|(_, ks)| ks.len() > 2) {
        return Err(format!(
            "edge ({a}, {b}) is shared by more than two of its triangles (layers welded at a rim \
             must not share an edge off it: mesh the corner cells so that no triangle has all \
             three nodes on the rim)"
        ));
    }
    // Whether triangle k traverses a → b in its node order.
    let forward = |k: usize, a: usize, b: usize| {
        let t = model.triangles[triangles[k]];
        (0..3).any(|i| t[i] == a && t[(i + 1) % 3] == b)
    };
    let mut sign = vec![0.0; triangles.len()];
    for seed in 0..triangles.len() {
        if sign[seed] != 0.0 {
            continue;
        }
        sign[seed] = 1.0;
        let mut stack = vec![seed];
        while let Some(k) = stack.pop() {
            let t = model.triangles[triangles[k]];
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                for &j in &by_edge[&(a.min(b), a.max(b))] {
                    if j == k {
                        continue;
                    }
                    // Consistent: j traverses the edge the other way once both are signed.
                    let want = if forward(j, a, b) { -sign[k] } else { sign[k] };
                    if sign[j] == 0.0 {
                        sign[j] = want;
                        stack.push(j);
                    } else if sign[j] != want {
                        return Err(format!(
                            "cannot be oriented consistently at edge ({a}, {b}) (triangles {} and {})",
                            triangles[k], triangles[j]
                        ));
                    }
                }
            }
        }
    }
    Ok(sign)
}

/// The edges of `triangles` that bound one of them only (the rim), each once.
fn rim_edges(model: &Model, triangles: &[usize]) -> Vec<(usize, usize)> {
    let mut count: HashMap<(usize, usize), usize> = HashMap::new();
    for &e in triangles {
        let t = model.triangles[e];
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut rim: Vec<(usize, usize)> = count
        .into_iter()
        .filter(|(_, c)| *c == 1)
        .map(|(e, _)| e)
        .collect();
    rim.sort_unstable();
    rim
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_triangle(seed: &mut u64) -> ([Vector3<f64>; 3], Vector3<f64>) {
        let mut r = || {
            *seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let x = std::array::from_fn(|_| Vector3::new(r(), r(), r()));
        (x, Vector3::new(r(), r(), r()))
    }

    /// The gradient and the Hessian of the tetrahedron volume match central differences of the
    /// volume and of the gradient; the Hessian is symmetric.
    #[test]
    fn volume_gradient_and_hessian_match_finite_differences() {
        let mut seed = 3;
        for _ in 0..50 {
            let (x, o) = random_triangle(&mut seed);
            let g = tet_gradient(&o, &x);
            let h = tet_hessian(&o, &x);
            let eps = 1e-6;
            for i in 0..9 {
                let moved = |s: f64| {
                    let mut y = x;
                    y[i / 3][i % 3] += s * eps;
                    y
                };
                let fd = (tet_volume(&o, &moved(1.0)) - tet_volume(&o, &moved(-1.0))) / (2.0 * eps);
                assert!((fd - g[i]).abs() < 1e-8, "gradient {i}: {fd} vs {}", g[i]);
                let fdg =
                    (tet_gradient(&o, &moved(1.0)) - tet_gradient(&o, &moved(-1.0))) / (2.0 * eps);
                for j in 0..9 {
                    assert!((fdg[j] - h[(j, i)]).abs() < 1e-8, "hessian ({j}, {i})");
                }
            }
            assert!((h - h.transpose()).amax() < 1e-15);
        }
    }

    /// A unit cube's twelve outward triangles enclose 1 m³ from any origin; its gradient is the
    /// outward area vector over three at each node (summing to zero).
    #[test]
    fn a_closed_cube_encloses_its_volume_from_any_origin() {
        let c = |i: usize| Vector3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64);
        // Faces as quads, counter-clockwise seen from outside.
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        for o in [Vector3::zeros(), Vector3::new(3.0, -2.0, 0.5)] {
            let mut v = 0.0;
            for q in quads {
                for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                    v += tet_volume(&o, &t.map(c));
                }
            }
            assert!((v - 1.0).abs() < 1e-14, "{v}");
        }
    }

    /// Boyle–Mariotte at κ = 1: `p V` of the absolute pressure is constant, and proportional to
    /// the temperature (Gay-Lussac); the slope is the derivative of the pressure (central
    /// difference), negative; the mass is the ideal gas's.
    #[test]
    fn the_gas_law_keeps_p_v_kappa_over_t_and_its_slope_is_the_derivative() {
        for kappa in [1.0, 1.4] {
            let law = GasLaw {
                kappa,
                atmosphere: 101_325.0,
                temperature: 293.15,
            };
            let c = law.constant(300.0, 2.0, 293.15);
            assert!((law.pressure(c, 2.0, 293.15) - 300.0).abs() < 1e-9);
            let v = 1.9;
            let expected = (300.0 + 101_325.0) * (2.0_f64 / v).powf(kappa) - 101_325.0;
            assert!((law.pressure(c, v, 293.15) - expected).abs() < 1e-8);
            let hot = (expected + 101_325.0) * 323.15 / 293.15 - 101_325.0;
            assert!((law.pressure(c, v, 323.15) - hot).abs() < 1e-8);
            let warm = law.constant(300.0, 2.0, 303.15);
            assert!((law.pressure(warm, 2.0, 303.15) - 300.0).abs() < 1e-9);
            let h = 1e-6;
            let fd = (law.pressure(c, v + h, 300.0) - law.pressure(c, v - h, 300.0)) / (2.0 * h);
            assert!((fd - law.slope(c, v, 300.0)).abs() < 1e-5 * fd.abs() && fd < 0.0);
        }
        let law = GasLaw {
            kappa: 1.0,
            atmosphere: 101_325.0,
            temperature: 293.15,
        };
        // 1 m³ of air at 1 atm and 20 °C: 1.204 kg.
        assert!((law.mass(0.0, 1.0, 293.15) - 1.2041).abs() < 1e-4);
    }
}
