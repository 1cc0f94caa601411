//! Film material: plane-stress St. Venant–Kirchhoff with an initial stress (paper eq. 2.3), and
//! an optional tension-field (wrinkling) modification for a film that cannot carry compression.
//!
//! Symbols (Voigt, engineering shear): strain `ε = [Exx, Eyy, 2Exy]`, stress `S = [Sxx, Syy, Sxy]`,
//! `Y` Young's modulus, `ν` Poisson's ratio, `Ē = Y/(1−ν²)`, `G = Y/(2(1+ν))`.
//!
//! **`wrinkling: none`** (the paper, written by its specimens): `S = D ε + S0`, `C = D`.
//!
//! **`wrinkling: tension-field`** (the default; summary and sources in `docs/mechanics.md` § "Wrinkling";
//! derivations in the implementation note it cites):
//! * the prestress is a strain shift, `ε̂ = ε + D⁻¹ S0`, so that `D ε̂ = D ε + S0` (a prestressed
//!   film can still go slack);
//! * principal strains `ê1 ≥ ê2` of `ε̂`, direction `n1 = (c, s)`, `θ = ½ atan2(2Exy, Exx − Eyy)`,
//!   `m = [c², s², cs]`, `P = [−cs, cs, (c² − s²)/2]`, `ρ = (ê1 − ê2)/2`;
//! * mixed criterion (Roddeman et al. 1987; Kang & Im 1997): **slack** if `ê1 ≤ 0`, else **taut**
//!   if `σ2 ∝ ê2 + ν ê1 > 0`, else **wrinkled**;
//! * stress and consistent tangent: taut `D ε̂`, `D`; wrinkled `Y ê1 m`,
//!   `Y m mᵀ + κ P Pᵀ` with `κ = Y ê1/ρ ∈ (0, 4G]` (the `κ` term is the turning of the tension
//!   direction); slack `0`, `0`.
//!
//! The wrinkled tangent is rank 2 and the slack one zero. The Newton matrix adds `η D` in those
//! two states ([`Material::iteration_tangent`]); the stress never does, so a converged solution is
//! exactly the tension-field one whatever `η` (shown by `tests/mechanics.rs`).

use nalgebra::{Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use super::plasticity::{PlasticFilm, Plasticity};
use super::temperature::{REFERENCE_TEMPERATURE, flow_stress_factor, modulus_factor};

/// Default `η` of [`Material::wrinkling_regularisation`].
pub const DEFAULT_WRINKLING_REGULARISATION: f64 = 1e-5;

/// Whether the film may wrinkle (carry no compression).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Wrinkling {
    /// Linear elastic in tension and compression (the paper's film).
    None,
    /// Tension-field membrane: taut, wrinkled (uniaxial tension) or slack (no stress). The
    /// default of a model file without the entry (issue 19: measured in `docs/mechanics.md`).
    #[default]
    TensionField,
}

impl Wrinkling {
    /// Whether this is [`Wrinkling::None`].
    pub fn is_none(&self) -> bool {
        *self == Self::None
    }

    /// Whether this is the default (left out of written model files).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// State of a tension-field material point (always `Taut` without wrinkling).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WrinklingState {
    /// Biaxial tension (or any state of a film that may not wrinkle).
    #[default]
    Taut = 0,
    /// Uniaxial tension along the tension direction, wrinkles across it.
    Wrinkled = 1,
    /// No stress.
    Slack = 2,
}

/// Linear-elastic plane-stress film with an initial stress (eq. 2.3), optionally wrinkling.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Young's modulus `E` (Pa).
    pub youngs_modulus: f64,
    /// Poisson's ratio `ν`, in `[0, 0.5)`.
    pub poisson_ratio: f64,
    /// Film thickness `t` (m).
    pub thickness: f64,
    /// Initial stress `σ0 = [σx, σy, τxy]` (Pa) in each element's local frame (e1 ∥ the model's
    /// `frame_axis`, or global X, projected).
    #[serde(default)]
    pub prestress: [f64; 3],
    /// Density `ρ` (kg/m³) for self-weight (ETFE ≈ 1750); 0 (the default): weightless film.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub density: f64,
    /// Compression model: `"tension-field"` (the default: a film carries no compression) or
    /// `"none"` (the paper's linear film; its specimens write it).
    #[serde(default, skip_serializing_if = "Wrinkling::is_default")]
    pub wrinkling: Wrinkling,
    /// `η`: the Newton matrix of wrinkled and slack points gets `η D` added (never the stress).
    #[serde(
        default = "default_regularisation",
        skip_serializing_if = "is_default_regularisation"
    )]
    pub wrinkling_regularisation: f64,
    /// Equivalent (von Mises) stress above which the linear law (2.3) no longer describes the
    /// film (Pa): ETFE's first yield, about 14–16 MPa at 23 °C. A converged state beyond it is
    /// reported with a warning (`summary::assumption_warnings`); none: no check.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yield_stress: Option<f64>,
    /// Elasto-plastic film (issue 20): finite-strain J2 plasticity with this hardening table
    /// (`plasticity/`); none (the default): the elastic law (2.3), bit for bit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plasticity: Option<Plasticity>,
    /// Film temperature (°C), in `[0, 50]`: `youngs_modulus`, `yield_stress` and the hardening
    /// table are given at 23 °C (the default) and scaled by ETFE's published relation
    /// ([`temperature`](super::temperature), [`Material::at_temperature`]).
    #[serde(
        default = "default_temperature",
        skip_serializing_if = "is_default_temperature"
    )]
    pub temperature: f64,
}

fn default_temperature() -> f64 {
    REFERENCE_TEMPERATURE
}

fn is_default_temperature(t: &f64) -> bool {
    *t == REFERENCE_TEMPERATURE
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn default_regularisation() -> f64 {
    DEFAULT_WRINKLING_REGULARISATION
}

fn is_default_regularisation(eta: &f64) -> bool {
    *eta == DEFAULT_WRINKLING_REGULARISATION
}

/// Stress and state of one material point ([`Material::tangent`] gives its tangent). Small on
/// purpose: it is built for every element in every assembly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialResponse {
    /// Second Piola–Kirchhoff stress `S_mod` (Pa), Voigt.
    pub stress: Vector3<f64>,
    /// Taut, wrinkled or slack.
    pub state: WrinklingState,
    /// Tension direction `n1 = (c, s)` in the element frame when wrinkled, zero otherwise.
    pub direction: Vector2<f64>,
    /// `κ = Y ê1/ρ` of the wrinkled tangent (Pa); zero otherwise.
    pub kappa: f64,
}

impl Material {
    /// The material at 23 °C that behaves as this one at its `temperature`: `E` times
    /// [`modulus_factor`], `yield_stress` and every flow stress of the hardening table times
    /// [`flow_stress_factor`] (plastic strains kept). The solver uses this; at 23 °C it is the
    /// material itself, bit for bit.
    pub fn at_temperature(&self) -> Material {
        if self.temperature == REFERENCE_TEMPERATURE {
            return *self;
        }
        let stress = flow_stress_factor(self.temperature);
        Material {
            youngs_modulus: self.youngs_modulus * modulus_factor(self.temperature),
            yield_stress: self.yield_stress.map(|y| y * stress),
            plasticity: self.plasticity.map(|p| Plasticity {
                hardening: p.hardening.scaled(stress),
            }),
            temperature: REFERENCE_TEMPERATURE,
            ..*self
        }
    }

    /// The elasto-plastic film law of this material, if it has `plasticity`.
    pub fn plastic_film(&self) -> Option<PlasticFilm> {
        self.plasticity.map(|p| PlasticFilm {
            youngs_modulus: self.youngs_modulus,
            poisson_ratio: self.poisson_ratio,
            hardening: p.hardening,
            tension_field: self.wrinkling == Wrinkling::TensionField,
        })
    }

    /// Plane-stress elasticity matrix `D` of eq. (2.3).
    pub fn elasticity(&self) -> Matrix3<f64> {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        let c = e / (1.0 - nu * nu);
        Matrix3::new(
            c,
            c * nu,
            0.0,
            c * nu,
            c,
            0.0,
            0.0,
            0.0,
            c * (1.0 - nu) / 2.0,
        )
    }

    /// Stress `σ = D ε + σ0` (eq. 2.3) of the film without wrinkling, Voigt `[εx, εy, γxy]`.
    pub fn stress(&self, strain: &Vector3<f64>) -> Vector3<f64> {
        self.elasticity() * strain + Vector3::from(self.prestress)
    }

    /// Membrane stiffness `E·t` (N/m), the scale the gap penalties are set against.
    pub fn membrane_stiffness(&self) -> f64 {
        self.youngs_modulus * self.thickness
    }

    /// Stress and state at the Green strain `strain` (module doc); [`Material::tangent`] and
    /// [`Material::iteration_tangent`] take the result.
    #[inline]
    pub fn response(&self, strain: &Vector3<f64>) -> MaterialResponse {
        let d = self.elasticity();
        match self.wrinkling {
            Wrinkling::None => MaterialResponse {
                stress: d * strain + Vector3::from(self.prestress),
                state: WrinklingState::Taut,
                direction: Vector2::zeros(),
                kappa: 0.0,
            },
            Wrinkling::TensionField => self.tension_field(d, strain),
        }
    }

    /// Consistent tangent `C_mod = ∂S_mod/∂ε` (Pa) at `response`, without regularisation: `D`,
    /// `Y m mᵀ + κ P Pᵀ` or `0` (module doc).
    #[inline]
    pub fn tangent(&self, response: &MaterialResponse) -> Matrix3<f64> {
        match response.state {
            WrinklingState::Taut => self.elasticity(),
            WrinklingState::Wrinkled => self.wrinkled_tangent(response),
            WrinklingState::Slack => Matrix3::zeros(),
        }
    }

    /// `Y m mᵀ + κ P Pᵀ`, out of line like [`Material::tension_field`].
    #[inline(never)]
    fn wrinkled_tangent(&self, response: &MaterialResponse) -> Matrix3<f64> {
        let (c, s) = (response.direction.x, response.direction.y);
        let m = Vector3::new(c * c, s * s, c * s);
        let p = Vector3::new(-c * s, c * s, 0.5 * (c * c - s * s));
        m * m.transpose() * self.youngs_modulus + p * p.transpose() * response.kappa
    }

    /// The Newton matrix's material part: the consistent tangent, plus `η D` when wrinkled or slack.
    #[inline]
    pub fn iteration_tangent(&self, response: &MaterialResponse) -> Matrix3<f64> {
        match response.state {
            WrinklingState::Taut => self.elasticity(),
            _ => self.tangent(response) + self.elasticity() * self.wrinkling_regularisation,
        }
    }

    /// `ε̂ = ε + D⁻¹ S0`, `D⁻¹ = (1/Y) [[1, −ν, 0], [−ν, 1, 0], [0, 0, 2(1 + ν)]]` (module doc).
    #[inline]
    pub fn effective_strain(&self, strain: &Vector3<f64>) -> Vector3<f64> {
        let (y, nu) = (self.youngs_modulus, self.poisson_ratio);
        let s0 = self.prestress;
        strain
            + Vector3::new(
                s0[0] - nu * s0[1],
                s0[1] - nu * s0[0],
                2.0 * (1.0 + nu) * s0[2],
            ) / y
    }

    /// Tension-field response (mixed criterion, closed form for isotropic SVK). Kept out of line
    /// so that the `none` path of [`Material::response`] inlines into the element loop.
    #[inline(never)]
    fn tension_field(&self, d: Matrix3<f64>, strain: &Vector3<f64>) -> MaterialResponse {
        let (y, nu) = (self.youngs_modulus, self.poisson_ratio);
        let e = self.effective_strain(strain);
        let (e1, e2, rho) = principal_strains(&e);
        // Relative tolerance: exactly zero strain is slack; never divide by ρ outside `wrinkled`.
        let tol = 1e-12 * (e1.abs() + e2.abs());
        if e1 <= tol {
            return MaterialResponse {
                stress: Vector3::zeros(),
                state: WrinklingState::Slack,
                direction: Vector2::zeros(),
                kappa: 0.0,
            };
        }
        if e2 + nu * e1 > tol {
            return MaterialResponse {
                stress: d * e,
                state: WrinklingState::Taut,
                direction: Vector2::zeros(),
                kappa: 0.0,
            };
        }
        // Wrinkled: ρ ≥ (1 + ν) ê1 / 2 > 0, so θ and κ are well defined.
        let theta = 0.5 * e.z.atan2(e.x - e.y);
        let (s, c) = theta.sin_cos();
        let m = Vector3::new(c * c, s * s, c * s);
        MaterialResponse {
            stress: m * (y * e1),
            state: WrinklingState::Wrinkled,
            direction: Vector2::new(c, s),
            kappa: y * e1 / rho,
        }
    }
}

/// The principal strains `ê1 ≥ ê2` of the Voigt strain `e` and `ρ = (ê1 − ê2)/2`.
#[inline]
pub fn principal_strains(e: &Vector3<f64>) -> (f64, f64, f64) {
    let half_diff = 0.5 * (e.x - e.y);
    let rho = (half_diff * half_diff + 0.25 * e.z * e.z).sqrt();
    let mean = 0.5 * (e.x + e.y);
    (mean + rho, mean - rho, rho)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Y = 1000, ν = 0.3` with an anisotropic prestress, wrinkling, no regularisation.
    fn film(prestress: [f64; 3]) -> Material {
        Material {
            youngs_modulus: 1000.0,
            poisson_ratio: 0.3,
            thickness: 1.0,
            prestress,
            density: 0.0,
            wrinkling: Wrinkling::TensionField,
            wrinkling_regularisation: 0.0,
            yield_stress: None,
            plasticity: None,
            temperature: REFERENCE_TEMPERATURE,
        }
    }

    /// The `k`-th of a deterministic, well-spread sequence in `[-1, 1)` (fractional part of a
    /// scaled sine: enough for sampling, no generator state).
    fn spread(k: usize) -> f64 {
        ((k as f64 * 12.9898).sin() * 43758.5453).rem_euclid(1.0) * 2.0 - 1.0
    }

    /// Central-difference `∂S_mod/∂ε` at `strain`, or `None` if a perturbation changes the state.
    fn fd_tangent(mat: &Material, strain: &Vector3<f64>) -> Option<Matrix3<f64>> {
        let state = mat.response(strain).state;
        let h = 1e-8;
        let mut c = Matrix3::zeros();
        for j in 0..3 {
            let (mut p, mut m) = (*strain, *strain);
            p[j] += h;
            m[j] -= h;
            let (rp, rm) = (mat.response(&p), mat.response(&m));
            if rp.state != state || rm.state != state {
                return None;
            }
            c.set_column(j, &((rp.stress - rm.stress) / (2.0 * h)));
        }
        Some(c)
    }

    /// Random strains (scale 1e-2) with and without prestress, checked in every state.
    fn check_random_points(mut visit: impl FnMut(&Material, &Vector3<f64>, &MaterialResponse)) {
        let mut k = 0;
        let mut next = || {
            k += 1;
            spread(k)
        };
        let mut seen = [0usize; 3];
        // Bounded: a material that never reaches a state fails here instead of looping forever.
        for _ in 0..100_000 {
            if seen.iter().all(|&n| n >= 50) {
                break;
            }
            let prestress = if next() > 0.0 {
                [0.0; 3]
            } else {
                [5.0 * next(), 5.0 * next(), 2.0 * next()]
            };
            let mat = film(prestress);
            let strain = Vector3::new(next(), next(), next()) * 1e-2;
            let r = mat.response(&strain);
            visit(&mat, &strain, &r);
            seen[r.state as usize] += 1;
        }
        assert!(
            seen.iter().all(|&n| n >= 50),
            "taut, wrinkled, slack points seen: {seen:?} (50 of each wanted)"
        );
    }

    #[test]
    fn consistent_tangent_matches_finite_differences_in_every_state() {
        check_random_points(|mat, strain, r| {
            let Some(fd) = fd_tangent(mat, strain) else {
                return;
            };
            let scale = mat.elasticity().amax();
            let err = (fd - mat.tangent(r)).amax();
            assert!(err < 1e-6 * scale, "{:?} at {strain:?}: {err:e}", r.state);
        });
    }

    #[test]
    fn frozen_direction_tangent_misses_exactly_the_turning_term() {
        // The statically condensed matrix D − (Dw)(Dw)ᵀ/(wᵀDw), w = strain-like n2⊗n2, ignores
        // dθ/dε. The FD check must see that it is off by (κ − 4G) P Pᵀ, and by nothing else.
        let mut wrinkled = 0;
        check_random_points(|mat, strain, r| {
            if r.state != WrinklingState::Wrinkled {
                return;
            }
            let Some(fd) = fd_tangent(mat, strain) else {
                return;
            };
            let (c, s) = (r.direction.x, r.direction.y);
            let d = mat.elasticity();
            let w = Vector3::new(s * s, c * c, -2.0 * c * s);
            let dw = d * w;
            let frozen = d - dw * dw.transpose() / w.dot(&dw);
            let (y, nu) = (mat.youngs_modulus, mat.poisson_ratio);
            let g = y / (2.0 * (1.0 + nu));
            let e = strain + d.try_inverse().unwrap() * Vector3::from(mat.prestress);
            let rho = (0.25 * (e.x - e.y).powi(2) + 0.25 * e.z * e.z).sqrt();
            let e1 = 0.5 * (e.x + e.y) + rho;
            let kappa = y * e1 / rho;
            let p = Vector3::new(-c * s, c * s, 0.5 * (c * c - s * s));
            let expected = p * p.transpose() * (kappa - 4.0 * g);
            let scale = d.amax();
            assert!(((fd - frozen) - expected).amax() < 1e-6 * scale);
            if (kappa - 4.0 * g).abs() > 0.1 * g {
                wrinkled += 1; // a point where the missing term is large
            }
        });
        assert!(wrinkled > 20);
    }

    #[test]
    fn wrinkled_tangent_and_stress_vanish_across_the_wrinkles() {
        check_random_points(|mat, _, r| {
            if r.state != WrinklingState::Wrinkled {
                return;
            }
            let (c, s) = (r.direction.x, r.direction.y);
            // Strain-like Voigt of n2⊗n2 is a null vector of C_w; S_mod has no n2n2 component.
            let w = Vector3::new(s * s, c * c, -2.0 * c * s);
            let scale = mat.elasticity().amax();
            assert!((mat.tangent(r) * w).amax() < 1e-12 * scale);
            assert!(r.stress.dot(&w).abs() < 1e-12 * r.stress.amax());
            // κ ∈ (0, 4G]: the tangent is positive semi-definite.
            let eig = mat.tangent(r).symmetric_eigenvalues();
            assert!(eig.min() > -1e-12 * scale, "{eig:?}");
        });
    }

    #[test]
    fn without_wrinkling_the_response_is_the_papers_law() {
        let mat = Material {
            wrinkling: Wrinkling::None,
            ..film([3.0, -2.0, 1.0])
        };
        let strain = Vector3::new(-0.02, 0.01, 0.005);
        let r = mat.response(&strain);
        assert_eq!(r.stress, mat.stress(&strain));
        assert_eq!(mat.tangent(&r), mat.elasticity());
        assert_eq!(r.state, WrinklingState::Taut);
        assert_eq!(mat.iteration_tangent(&r), mat.elasticity());
    }

    #[test]
    fn regularisation_enters_the_iteration_tangent_only() {
        let eta = 1e-4;
        let mat = Material {
            wrinkling_regularisation: eta,
            ..film([0.0; 3])
        };
        for strain in [
            Vector3::new(0.01, -0.01, 0.0),  // wrinkled
            Vector3::new(-0.01, -0.02, 0.0), // slack
            Vector3::new(0.01, 0.01, 0.0),   // taut: nothing added
        ] {
            let (r, r0) = (mat.response(&strain), film([0.0; 3]).response(&strain));
            assert_eq!(
                r, r0,
                "the stress and consistent tangent do not depend on η"
            );
            let added = mat.iteration_tangent(&r) - mat.tangent(&r);
            let expected = match r.state {
                WrinklingState::Taut => Matrix3::zeros(),
                _ => mat.elasticity() * eta,
            };
            assert!((added - expected).amax() < 1e-15 * mat.elasticity().amax());
        }
    }

    #[test]
    fn at_temperature_scales_modulus_yield_stress_and_every_flow_stress() {
        use crate::mech::elements::plasticity::Hardening;
        use crate::mech::elements::temperature::{flow_stress_factor, modulus_factor};
        let rows = vec![[0.0, 16e6], [0.02, 19e6], [1.0, 40e6]];
        let at_23 = Material {
            yield_stress: Some(15e6),
            plasticity: Some(Plasticity {
                hardening: Hardening::new(rows.clone()).unwrap(),
            }),
            ..film([1.0, 2.0, 0.5])
        };
        assert_eq!(at_23.at_temperature(), at_23, "23 °C: the material itself");
        let cold = Material {
            temperature: 0.0,
            ..at_23
        };
        let m = cold.at_temperature();
        let (e, s) = (modulus_factor(0.0), flow_stress_factor(0.0));
        assert_eq!(m.youngs_modulus, 1000.0 * e);
        assert_eq!(m.yield_stress, Some(15e6 * s));
        let scaled: Vec<[f64; 2]> = rows.iter().map(|r| [r[0], r[1] * s]).collect();
        assert_eq!(m.plasticity.unwrap().hardening.rows(), &scaled[..]);
        // Everything else is kept; the result is a material at 23 °C (not scaled twice).
        assert_eq!(
            (m.poisson_ratio, m.prestress, m.temperature),
            (0.3, [1.0, 2.0, 0.5], 23.0)
        );
        assert_eq!(m.at_temperature(), m);
    }

    /// Issue 19: a material without a `wrinkling` entry is the tension-field film; `"none"` is
    /// the paper's, and it survives a write and a read (the default is the entry left out).
    #[test]
    fn a_material_without_a_wrinkling_entry_is_the_tension_field_film() {
        let base = r#"{"youngs_modulus": 8e8, "poisson_ratio": 0.45, "thickness": 2.5e-4"#;
        let read = |extra: &str| -> Material {
            serde_json::from_str(&format!("{base}{extra}}}")).unwrap()
        };
        assert_eq!(read("").wrinkling, Wrinkling::TensionField);
        assert_eq!(read(r#", "wrinkling": "none""#).wrinkling, Wrinkling::None);
        for m in [read(""), read(r#", "wrinkling": "none""#)] {
            let text = serde_json::to_string(&m).unwrap();
            assert_eq!(
                text.contains(r#""wrinkling":"none""#),
                m.wrinkling.is_none(),
                "{text}"
            );
            assert_eq!(
                serde_json::from_str::<Material>(&text).unwrap(),
                m,
                "{text}"
            );
        }
    }

    #[test]
    fn prestress_moves_the_slack_threshold_to_zero_effective_strain() {
        // S0 = s0 I shifts ε̂ by s0 (1 − ν)/Y on both axes: slack once Exx = Eyy < −s0 (1 − ν)/Y.
        let mat = film([5.0, 5.0, 0.0]);
        let shift = 5.0 * (1.0 - 0.3) / 1000.0;
        let at = |e: f64| mat.response(&Vector3::new(e, e, 0.0)).state;
        assert_eq!(at(-shift * 0.999), WrinklingState::Taut);
        assert_eq!(at(-shift * 1.001), WrinklingState::Slack);
    }
}
