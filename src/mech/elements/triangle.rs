//! Constant-strain membrane triangle, total Lagrangian (paper §2.1, eqs. 2.2–2.7).
//!
//! Three nodes, nine DOF `u = [u1 v1 w1 u2 v2 w2 u3 v3 w3]` in global axes. The element's
//! local in-plane frame `(e1, e2)` is fixed at the initial configuration (e1 = the model's
//! `frame_axis` projected on the element plane, [`MembraneTriangle::new_along`]; without one,
//! global X projected, or global Y when X is normal to it), so a uniform anisotropic prestress
//! stays uniform across a mesh.
//!
//! | paper (Zienkiewicz / Tabarrok–Qin notation) | here |
//! |---|---|
//! | `θ = G u` (six in-plane gradients) | columns of `∇u = F − F0` (3×2) |
//! | `ε = B0 u + ½ A θ` (2.2) | Green–Lagrange `E = ½(FᵀF − I)`, Voigt `[Exx, Eyy, 2Exy]` |
//! | `σ = D ε + σ0` (2.3) | [`Material::stress`]; `σ` is the 2nd Piola–Kirchhoff stress |
//! | `(B0 + A G)` | [`MembraneTriangle::strain_operator`] (3×3 per node, rows from `F`) |
//! | `r = ∫ (B0 + AG)ᵀ σ dV` (2.6) | `r_k = V0 · F S ∇N_k` |
//! | `k = ∫ (B0+AG)ᵀ D (B0+AG) + Gᵀ M G dV` (2.7) | `K_kl = V0 [B_kᵀ D B_l + (∇N_kᵀ S ∇N_l) I3]` |
//!
//! Writing `F` in global axes makes the rotation `T = diag(R, R, R)` of the paper unnecessary:
//! `(B0 + AG)` expressed on global DOF is exactly `B_k` below, and `GᵀMG` is the isotropic
//! `(∇N_kᵀ S ∇N_l) I3` block. `docs/mechanics.md` has the derivation.
//!
//! A wrinkling film ([`Material::response`]) replaces `σ` by the tension-field stress `S_mod` in
//! the force and in the geometric term, and `D` by its consistent tangent (+ `η D`) in `B_kᵀ D B_l`.

use nalgebra::{Matrix2, Matrix3, Matrix3x2, SMatrix, SVector, Vector2, Vector3};
use serde::{Deserialize, Serialize};

pub use crate::mech::elements::material::{Material, Wrinkling, WrinklingState};
use crate::mech::elements::plasticity::{PlasticFilm, PlasticHistory, PlasticResponse};

/// Element vector on the nine nodal DOF.
pub type ElementVector = SVector<f64, 9>;
/// Element matrix on the nine nodal DOF.
pub type ElementMatrix = SMatrix<f64, 9, 9>;

/// Strain and stress state of one element.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ElementStress {
    /// Green–Lagrange strain `[εx, εy, γxy]` in the element's local frame.
    pub strain: [f64; 3],
    /// Stress `σ = Dε + σ0` `[σx, σy, τxy]` (Pa) in the element's local frame (the
    /// tension-field stress when the material wrinkles).
    pub stress: [f64; 3],
    /// Principal stresses `σ1 ≥ σ2` (Pa).
    pub principal: [f64; 2],
    /// Plane-stress von Mises equivalent stress `√(σ1² − σ1σ2 + σ2²)` (Pa).
    pub von_mises: f64,
    /// Taut, wrinkled or slack (always taut without wrinkling).
    #[serde(default)]
    pub state: WrinklingState,
    /// Unit tension direction `F n1/|F n1|` in global axes on the deformed film when wrinkled
    /// (the wrinkles run along it); zero otherwise.
    #[serde(default)]
    pub tension_direction: [f64; 3],
    /// Plastic state of an elasto-plastic film; none for the elastic film.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plastic: Option<PlasticOutput>,
}

/// Plastic state of one element of an elasto-plastic film.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlasticOutput {
    /// Equivalent plastic strain `ε̄p`.
    pub equivalent_plastic_strain: f64,
    /// Current film thickness (m).
    pub thickness: f64,
}

/// How many elements are taut, wrinkled and slack (indexed by [`WrinklingState`] as `usize`).
pub fn state_counts(elements: &[ElementStress]) -> [usize; 3] {
    let mut counts = [0; 3];
    elements.iter().for_each(|e| counts[e.state as usize] += 1);
    counts
}

/// Why a triangle cannot be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DegenerateTriangle {
    /// Twice the area that was found (m²).
    pub doubled_area: f64,
}

/// A constant-strain membrane triangle in its initial configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MembraneTriangle {
    /// `F0 = [e1 e2]`: the deformation gradient at zero displacement (global ← local 2D).
    initial_frame: Matrix3x2<f64>,
    /// Shape-function gradients `∇N_k = (b_k, c_k)` in the local frame.
    gradients: [Vector2<f64>; 3],
    /// Initial area `A0` (m²).
    area: f64,
    /// Its layer's thickness (m; `"layers"` of the model file), None: the material's.
    layer_thickness: Option<f64>,
}

/// Largest `|e3 · axis|` at which a model's `frame_axis` still sets a triangle's e1 (5.7° from
/// the normal): validation refuses a triangle closer to it.
pub const AXIS_NORMAL_COSINE: f64 = 0.995;

impl MembraneTriangle {
    /// Builds the element from its three initial node positions (e1 = global X projected).
    pub fn new(x: [Vector3<f64>; 3]) -> Result<Self, DegenerateTriangle> {
        Self::new_along(x, None)
    }

    /// Builds the element with e1 = `axis` projected on its plane (`None`, or an axis within
    /// 5.7° of the normal: global X projected, or Y when X is within 26° of the normal).
    pub fn new_along(
        x: [Vector3<f64>; 3],
        axis: Option<[f64; 3]>,
    ) -> Result<Self, DegenerateTriangle> {
        let (a, b) = (x[1] - x[0], x[2] - x[0]);
        let normal = a.cross(&b);
        let doubled_area = normal.norm();
        let scale = a.norm_squared().max(b.norm_squared());
        if !(doubled_area > 1e-10 * scale) || !doubled_area.is_finite() {
            return Err(DegenerateTriangle { doubled_area });
        }
        let e3 = normal / doubled_area;
        let reference = match axis.map(|a| Vector3::from(a).normalize()) {
            Some(a) if e3.dot(&a).abs() < AXIS_NORMAL_COSINE => a,
            _ if e3.x.abs() < 0.9 => Vector3::x(),
            _ => Vector3::y(),
        };
        let e1 = (reference - e3 * e3.dot(&reference)).normalize();
        let e2 = e3.cross(&e1);
        let local = |p: Vector3<f64>| Vector2::new(p.dot(&e1), p.dot(&e2));
        let (p1, p2) = (local(a), local(b));
        // ∇N for linear shape functions on the triangle (0, p1, p2); det = 2A > 0 by construction.
        let det = p1.x * p2.y - p2.x * p1.y;
        let g1 = Vector2::new(p2.y, -p2.x) / det;
        let g2 = Vector2::new(-p1.y, p1.x) / det;
        let g0 = -(g1 + g2);
        Ok(Self {
            initial_frame: Matrix3x2::from_columns(&[e1, e2]),
            gradients: [g0, g1, g2],
            area: 0.5 * doubled_area,
            layer_thickness: None,
        })
    }

    /// The element with the thickness `t` (m) of its layer instead of the material's.
    pub fn with_thickness(self, t: f64) -> Self {
        Self {
            layer_thickness: Some(t),
            ..self
        }
    }

    /// Initial area `A0` (m²).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Shape-function gradients `∇N_k` in the local frame (eq. 2.2's `G`, per node).
    pub fn shape_gradients(&self) -> [Vector2<f64>; 3] {
        self.gradients
    }

    /// Initial thickness `t0` (m): its layer's, else the material's.
    pub fn thickness(&self, material: &Material) -> f64 {
        self.layer_thickness.unwrap_or(material.thickness)
    }

    /// Initial volume `A0 t0` (m³).
    pub fn volume(&self, material: &Material) -> f64 {
        self.area * self.thickness(material)
    }

    /// Unit vectors `(e1, e2)` of the local frame the strains and stresses are given in.
    pub fn local_axes(&self) -> (Vector3<f64>, Vector3<f64>) {
        (
            self.initial_frame.column(0).into(),
            self.initial_frame.column(1).into(),
        )
    }

    /// Deformation gradient `F = F0 + Σ u_k ∇N_kᵀ` (3×2, global ← local).
    pub fn deformation_gradient(&self, u: &ElementVector) -> Matrix3x2<f64> {
        let mut f = self.initial_frame;
        for (k, g) in self.gradients.iter().enumerate() {
            let uk = u.fixed_rows::<3>(3 * k);
            f += uk * g.transpose();
        }
        f
    }

    /// Green–Lagrange strain `ε = B0 u + ½ A θ` (eq. 2.2) in Voigt form `[εx, εy, γxy]`.
    pub fn green_strain(&self, u: &ElementVector) -> Vector3<f64> {
        strain_from(&self.deformation_gradient(u))
    }

    /// Strain operator `B_k = ∂ε/∂u_k` (the node-`k` block of `B0 + A G`, eq. 2.2).
    pub fn strain_operator(&self, f: &Matrix3x2<f64>, k: usize) -> Matrix3<f64> {
        let (b, c) = (self.gradients[k].x, self.gradients[k].y);
        let (f1, f2) = (f.column(0), f.column(1));
        Matrix3::from_rows(&[
            (f1 * b).transpose(),
            (f2 * c).transpose(),
            (f1 * c + f2 * b).transpose(),
        ])
    }

    /// Internal force vector `r` of eq. (2.6).
    pub fn internal_force(&self, material: &Material, u: &ElementVector) -> ElementVector {
        self.force_and_tangent(material, u, false).0
    }

    /// Tangent stiffness `∂r/∂u` of eq. (2.7): material part plus initial-stress part `GᵀMG`.
    pub fn tangent_stiffness(&self, material: &Material, u: &ElementVector) -> ElementMatrix {
        self.force_and_tangent(material, u, true).1
    }

    /// Internal force (2.6) and, when `with_tangent`, the tangent (2.7) in one pass.
    pub fn force_and_tangent(
        &self,
        material: &Material,
        u: &ElementVector,
        with_tangent: bool,
    ) -> (ElementVector, ElementMatrix) {
        let f = self.deformation_gradient(u);
        let strain = strain_from(&f);
        // One monomorphized pass per material kind: the paper's film runs exactly its own code.
        match material.wrinkling {
            Wrinkling::None => self.force_and_tangent_with(
                material,
                &f,
                material.stress(&strain),
                with_tangent,
                || material.elasticity(),
            ),
            Wrinkling::TensionField => {
                // S_mod enters the force and the geometric term; the material term gets C_mod + η D.
                let response = material.response(&strain);
                self.force_and_tangent_with(material, &f, response.stress, with_tangent, || {
                    material.iteration_tangent(&response)
                })
            }
        }
    }

    /// Internal force, tangent (when `with_tangent`) and material response of an elasto-plastic
    /// film (`plasticity/`) starting from the committed `history`: `S` and the algorithmic
    /// `∂S/∂E` enter (2.6)–(2.7) in place of `σ` and `D`; wrinkled and slack points get `η D`
    /// added to the Newton matrix, as the elastic tension field does.
    pub fn force_and_tangent_plastic(
        &self,
        material: &Material,
        film: &PlasticFilm,
        history: &PlasticHistory,
        u: &ElementVector,
        with_tangent: bool,
    ) -> (ElementVector, ElementMatrix, PlasticResponse) {
        let f = self.deformation_gradient(u);
        let strain = strain_from(&f);
        let (response, c) = if with_tangent {
            let (response, mut c) = film.response_and_tangent(history, &strain);
            if response.state != WrinklingState::Taut {
                c += material.elasticity() * material.wrinkling_regularisation;
            }
            (response, c)
        } else {
            (film.response(history, &strain), Matrix3::zeros())
        };
        let (r, k) = self.force_and_tangent_with(material, &f, response.stress, with_tangent, || c);
        (r, k, response)
    }

    /// Force and tangent from the stress `s` and the material tangent `tangent()`.
    #[allow(non_snake_case)]
    #[inline(always)]
    fn force_and_tangent_with(
        &self,
        material: &Material,
        f: &Matrix3x2<f64>,
        s: Vector3<f64>,
        with_tangent: bool,
        tangent: impl FnOnce() -> Matrix3<f64>,
    ) -> (ElementVector, ElementMatrix) {
        let volume = self.volume(material);
        let S = Matrix2::new(s.x, s.z, s.z, s.y);
        let FS = f * S;
        let mut r = ElementVector::zeros();
        for k in 0..3 {
            r.fixed_rows_mut::<3>(3 * k)
                .copy_from(&(FS * self.gradients[k] * volume));
        }
        let mut kt = ElementMatrix::zeros();
        if with_tangent {
            let C = tangent();
            let B = [0, 1, 2].map(|k| self.strain_operator(f, k));
            let CB = B.map(|b| C * b);
            // The tangent is symmetric: compute the blocks l ≥ k and mirror them.
            for k in 0..3 {
                for l in k..3 {
                    let geometric = (self.gradients[k].transpose() * S * self.gradients[l])[0];
                    let block =
                        (B[k].transpose() * CB[l] + Matrix3::identity() * geometric) * volume;
                    kt.fixed_view_mut::<3, 3>(3 * k, 3 * l).copy_from(&block);
                    if l != k {
                        kt.fixed_view_mut::<3, 3>(3 * l, 3 * k)
                            .copy_from(&block.transpose());
                    }
                }
            }
        }
        (r, kt)
    }

    /// Strains, stresses, principal and von Mises stress at displacement `u`.
    pub fn stress_state(&self, material: &Material, u: &ElementVector) -> ElementStress {
        let f = self.deformation_gradient(u);
        let strain = strain_from(&f);
        let response = material.response(&strain);
        let s = response.stress;
        let tension = f * response.direction;
        let tension_direction = if response.state == WrinklingState::Wrinkled {
            (tension / tension.norm()).into()
        } else {
            [0.0; 3]
        };
        let centre = 0.5 * (s.x + s.y);
        let radius = (0.25 * (s.x - s.y).powi(2) + s.z * s.z).sqrt();
        let (s1, s2) = (centre + radius, centre - radius);
        ElementStress {
            strain: strain.into(),
            stress: s.into(),
            principal: [s1, s2],
            von_mises: (s1 * s1 - s1 * s2 + s2 * s2).sqrt(),
            state: response.state,
            tension_direction,
            plastic: None,
        }
    }

    /// [`MembraneTriangle::stress_state`] of an elasto-plastic film from `history` (the
    /// converged history at a converged `u`). `stress` is `S`; the principal and von Mises
    /// stresses are Cauchy's in the material, `τ/J` with the elastic volume ratio
    /// `J = exp((1 − 2ν)(τ1 + τ2)/E)` (plastic flow is isochoric, wrinkles are no material strain).
    pub fn stress_state_plastic(
        &self,
        material: &Material,
        film: &PlasticFilm,
        history: &PlasticHistory,
        u: &ElementVector,
    ) -> ElementStress {
        let f = self.deformation_gradient(u);
        let strain = strain_from(&f);
        let r = film.response(history, &strain);
        let [t1, t2] = r.principal_kirchhoff;
        let j = ((1.0 - 2.0 * film.poisson_ratio) * (t1 + t2) / film.youngs_modulus).exp();
        // Wrinkled: S = s v vᵀ, v along the tension direction (reference); F v on the film.
        let s = Matrix2::new(r.stress.x, r.stress.z, r.stress.z, r.stress.y);
        let v = if s.column(0).norm() >= s.column(1).norm() {
            s.column(0).into_owned()
        } else {
            s.column(1).into_owned()
        };
        let tension = f * v;
        let tension_direction = if r.state == WrinklingState::Wrinkled {
            (tension / tension.norm()).into()
        } else {
            [0.0; 3]
        };
        ElementStress {
            strain: strain.into(),
            stress: r.stress.into(),
            principal: [t1 / j, t2 / j],
            von_mises: r.equivalent_stress / j,
            state: r.state,
            tension_direction,
            plastic: Some(PlasticOutput {
                equivalent_plastic_strain: r.history.equivalent_plastic_strain,
                thickness: self.thickness(material) * r.thickness_ratio,
            }),
        }
    }
}

/// Voigt Green–Lagrange strain from the 3×2 deformation gradient.
fn strain_from(f: &Matrix3x2<f64>) -> Vector3<f64> {
    let c = f.transpose() * f;
    Vector3::new(0.5 * (c[(0, 0)] - 1.0), 0.5 * (c[(1, 1)] - 1.0), c[(0, 1)])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn etfe() -> Material {
        Material {
            youngs_modulus: 1.0e9,
            poisson_ratio: 0.43,
            thickness: 250e-6,
            prestress: [1.0e6, 0.5e6, 0.2e6],
            density: 0.0,
            wrinkling: Wrinkling::None,
            wrinkling_regularisation: 1e-5,
            yield_stress: None,
            plasticity: None,
            temperature: 23.0,
        }
    }

    fn skew_triangle() -> MembraneTriangle {
        MembraneTriangle::new([
            Vector3::new(0.1, 0.2, 0.3),
            Vector3::new(1.3, 0.1, 0.5),
            Vector3::new(0.4, 0.9, 0.1),
        ])
        .unwrap()
    }

    fn pseudo_random_displacement(scale: f64) -> ElementVector {
        ElementVector::from_fn(|i, _| scale * ((i as f64 * 1.7 + 0.3).sin()))
    }

    /// A layer's own thickness scales the element's force and tangent as the material's would,
    /// and its tangent matches central differences of its force.
    #[test]
    fn a_layer_thickness_acts_as_the_materials_and_its_tangent_matches_finite_differences() {
        let mat = etfe();
        let layered = skew_triangle().with_thickness(3.0 * mat.thickness);
        let thick = Material {
            thickness: 3.0 * mat.thickness,
            ..mat.clone()
        };
        let u = pseudo_random_displacement(0.05);
        assert_eq!(layered.thickness(&mat), thick.thickness);
        let (f, k) = (
            layered.internal_force(&mat, &u),
            layered.tangent_stiffness(&mat, &u),
        );
        let (f3, k3) = (
            skew_triangle().internal_force(&thick, &u),
            skew_triangle().tangent_stiffness(&thick, &u),
        );
        assert!((f - f3).amax() <= 1e-12 * f3.amax() && (k - k3).amax() <= 1e-12 * k3.amax());
        let h = 1e-7;
        for j in 0..9 {
            let (mut up, mut um) = (u, u);
            up[j] += h;
            um[j] -= h;
            let column =
                (layered.internal_force(&mat, &up) - layered.internal_force(&mat, &um)) / (2.0 * h);
            assert!(
                (column - k.column(j)).amax() < 1e-6 * k.amax(),
                "column {j}"
            );
        }
    }

    #[test]
    fn tangent_matches_finite_difference() {
        let (tri, mat) = (skew_triangle(), etfe());
        let u = pseudo_random_displacement(0.05);
        let k = tri.tangent_stiffness(&mat, &u);
        let h = 1e-7;
        let mut worst: f64 = 0.0;
        for j in 0..9 {
            let mut up = u;
            let mut um = u;
            up[j] += h;
            um[j] -= h;
            let column =
                (tri.internal_force(&mat, &up) - tri.internal_force(&mat, &um)) / (2.0 * h);
            worst = worst.max((column - k.column(j)).amax());
        }
        assert!(
            worst < 1e-6 * k.amax(),
            "worst {worst:e} vs scale {:e}",
            k.amax()
        );
    }

    #[test]
    fn internal_force_is_gradient_of_strain_energy() {
        let (tri, mat) = (skew_triangle(), etfe());
        let energy = |u: &ElementVector| {
            let e = tri.green_strain(u);
            let s0 = Vector3::from(mat.prestress);
            tri.area() * mat.thickness * (0.5 * e.dot(&(mat.elasticity() * e)) + s0.dot(&e))
        };
        let u = pseudo_random_displacement(0.03);
        let r = tri.internal_force(&mat, &u);
        let h = 1e-7;
        for j in 0..9 {
            let mut up = u;
            let mut um = u;
            up[j] += h;
            um[j] -= h;
            let d = (energy(&up) - energy(&um)) / (2.0 * h);
            assert!(
                (d - r[j]).abs() < 1e-6 * r.amax(),
                "dof {j}: {d} vs {}",
                r[j]
            );
        }
    }

    #[test]
    fn tangent_is_symmetric() {
        let k = skew_triangle().tangent_stiffness(&etfe(), &pseudo_random_displacement(0.1));
        assert!((k - k.transpose()).amax() < 1e-9 * k.amax());
    }

    #[test]
    fn plastic_tangent_matches_finite_difference_in_every_state() {
        use crate::mech::elements::plasticity::{Hardening, PlasticFilm};
        let tri = skew_triangle();
        let hardening =
            Hardening::new(vec![[0.0, 16e6], [0.02, 19e6], [0.15, 24e6], [1.0, 40e6]]).unwrap();
        let spread =
            |k: usize| ((k as f64 * 12.9898).sin() * 43758.5453).rem_euclid(1.0) * 2.0 - 1.0;
        let mut seen = std::collections::HashSet::new();
        for k in 0..300 {
            let tension_field = k % 2 == 0;
            let mat = Material {
                wrinkling: if tension_field {
                    Wrinkling::TensionField
                } else {
                    Wrinkling::None
                },
                wrinkling_regularisation: 0.0,
                ..etfe()
            };
            let film = PlasticFilm {
                youngs_modulus: mat.youngs_modulus,
                poisson_ratio: mat.poisson_ratio,
                hardening,
                tension_field,
            };
            let fresh = film.initial_history(mat.prestress);
            let pre = ElementVector::from_fn(|i, _| 0.1 * spread(40 * k + i));
            let history = if k % 3 == 0 {
                fresh
            } else {
                tri.force_and_tangent_plastic(&mat, &film, &fresh, &pre, false)
                    .2
                    .history
            };
            let u = pre + ElementVector::from_fn(|i, _| 0.04 * spread(40 * k + 20 + i));
            let (_, kt, at) = tri.force_and_tangent_plastic(&mat, &film, &history, &u, true);
            let h = 1e-7;
            let mut fd = ElementMatrix::zeros();
            let mut stable = true;
            for j in 0..9 {
                let (mut up, mut um) = (u, u);
                up[j] += h;
                um[j] -= h;
                let (rp, _, ap) = tri.force_and_tangent_plastic(&mat, &film, &history, &up, false);
                let (rm, _, am) = tri.force_and_tangent_plastic(&mat, &film, &history, &um, false);
                let same = |a: &PlasticResponse| (a.state, a.yielding) == (at.state, at.yielding);
                stable &= same(&ap) && same(&am);
                fd.set_column(j, &((rp - rm) / (2.0 * h)));
            }
            if !stable {
                continue;
            }
            let err = (fd - kt).amax();
            assert!(
                err < 1e-6 * kt.amax().max(1.0),
                "{:?} yielding {} : {err:e} vs {:e}",
                at.state,
                at.yielding,
                kt.amax()
            );
            seen.insert((
                at.state as usize,
                at.yielding,
                history.equivalent_plastic_strain > 0.0,
            ));
        }
        // Taut, wrinkled and slack; loading and unloading; virgin and yielded histories.
        assert!(seen.len() >= 7, "states covered: {seen:?}");
    }

    #[test]
    fn plastic_stress_state_reports_cauchy_stress_thickness_and_tension_direction() {
        use crate::mech::elements::plasticity::{Hardening, PlasticFilm};
        // A flat triangle stretched by 1.3 along X and held at 0.7 along Y: a wrinkled bar.
        let tri = MembraneTriangle::new([
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.3, 0.8, 0.0),
        ])
        .unwrap();
        let mat = Material {
            wrinkling: Wrinkling::TensionField,
            prestress: [0.0; 3],
            ..etfe()
        };
        let film = PlasticFilm {
            hardening: Hardening::new(vec![[0.0, 16e6], [1.0, 40e6]]).unwrap(),
            youngs_modulus: mat.youngs_modulus,
            poisson_ratio: mat.poisson_ratio,
            tension_field: true,
        };
        let nodes = [[0.0, 0.0], [1.0, 0.0], [0.3, 0.8]];
        let stretched = |lx: f64, ly: f64| {
            let u = ElementVector::from_fn(|i, _| match i % 3 {
                0 => (lx - 1.0) * nodes[i / 3][0],
                1 => (ly - 1.0) * nodes[i / 3][1],
                _ => 0.0,
            });
            tri.stress_state_plastic(&mat, &film, &film.initial_history([0.0; 3]), &u)
        };
        // Taut, equibiaxial: Cauchy σ = τ/J with τ = λ² S and J = λ² t/t0.
        let l = 1.2f64;
        let out = stretched(l, l);
        let plastic = out.plastic.unwrap();
        let sigma = out.stress[0] * l * l / (l * l * plastic.thickness / mat.thickness);
        assert_eq!(out.state, WrinklingState::Taut);
        for s in [out.principal[0], out.principal[1], out.von_mises] {
            assert!((s - sigma).abs() < 1e-9 * sigma, "{s} vs {sigma}");
        }
        // Wrinkled bar along X: tension direction X, no stress across.
        let out = stretched(1.3, 0.7);
        let plastic = out.plastic.unwrap();
        assert_eq!(out.state, WrinklingState::Wrinkled);
        let along = Vector3::from(out.tension_direction) - Vector3::x();
        assert!(along.norm() < 1e-12, "{:?}", out.tension_direction);
        assert!(out.principal[1].abs() < 1e-9 * out.principal[0]);
        assert!(plastic.equivalent_plastic_strain > 0.2 && plastic.thickness < mat.thickness);
    }
}
