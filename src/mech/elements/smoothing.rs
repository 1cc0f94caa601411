//! The laws' switches with their corners rounded, for the smoothing homotopy that a refused
//! increment tries last (`solve/smoothing.rs`, docs/mechanics.md "Smoothing homotopy"): the C¹
//! [`ramp`] in place of `max(x, 0)`, and the tension-field film rounded with it
//! ([`Material::tension_field_rounded`]); the contact law's rounding is in
//! `curved_contact/smoothing.rs`. A rounded law is only ever a step on the way: no increment is
//! accepted under it.

use nalgebra::{Matrix3, Vector3};

use super::material::{Material, principal_strains};

/// `max(y, 0)` with its corner rounded over `|y| < w/2` (`w > 0`), C¹: the value, the first and
/// the second derivative. `ρ(y) ≥ max(y, 0)` everywhere; `ρ(y) − max(y, 0) ≤ w/8` (at `y = 0`);
/// `ρ_w(λ y) = λ ρ_{w/λ}(y)` for `λ > 0`.
pub fn ramp(y: f64, w: f64) -> (f64, f64, f64) {
    if y <= -0.5 * w {
        (0.0, 0.0, 0.0)
    } else if y >= 0.5 * w {
        (y, 1.0, 0.0)
    } else {
        let s = y + 0.5 * w;
        (s * s / (2.0 * w), s / w, 1.0 / w)
    }
}

impl Material {
    /// The tension-field film (module doc of `material`) with its two switches rounded over the
    /// strain width `w > 0`: its principal stresses are `σ2 = Ē ρ_{(1+ν)w}(ê2 + ν ê1)` and
    /// `σ1 = Y ρ_w(ê1) + ν σ2` (exactly the law's with `max` for `ρ`: taut `D ε̂`, wrinkled
    /// `Y ê1` along `n1`, slack nothing; the widths make `σ1 = σ2` wherever `ê1 = ê2`, so the
    /// stress does not depend on the undefined direction there). Stress `S = σ1 m + σ2 m⊥` and
    /// Newton matrix `Σ ∂σi/∂êj mi mjᵀ + (σ1 − σ2)/ρ P Pᵀ` (`m⊥ = [s², c², −cs]`; the last term
    /// is the turning of the principal directions, `∂θ/∂ε̂ = P/(2ρ)`), plus `η D` where the
    /// film is not taut, as the law's own (`Material::iteration_tangent`).
    pub fn tension_field_rounded(
        &self,
        strain: &Vector3<f64>,
        w: f64,
    ) -> (Vector3<f64>, Matrix3<f64>) {
        let (y, nu) = (self.youngs_modulus, self.poisson_ratio);
        let yb = y / (1.0 - nu * nu);
        let e = self.effective_strain(strain);
        let (e1, e2, rho) = principal_strains(&e);
        let (r1, d1, _) = ramp(e1, w);
        let (r2, d2, _) = ramp(e2 + nu * e1, (1.0 + nu) * w);
        let (sigma1, sigma2) = (y * r1 + nu * yb * r2, yb * r2);
        // ∂σi/∂êj
        let (a11, a12, a22) = (y * d1 + nu * nu * yb * d2, nu * yb * d2, yb * d2);
        let theta = 0.5 * e.z.atan2(e.x - e.y);
        let (s, c) = theta.sin_cos();
        let m1 = Vector3::new(c * c, s * s, c * s);
        let m2 = Vector3::new(s * s, c * c, -c * s);
        let p = Vector3::new(-c * s, c * s, 0.5 * (c * c - s * s));
        // (σ1 − σ2)/ρ, and its limit ∂(σ1 − σ2)/∂ê1 − ∂(σ1 − σ2)/∂ê2 where ρ vanishes.
        let kappa = if rho > 1e-9 * (e1.abs() + e2.abs() + w) {
            (sigma1 - sigma2) / rho
        } else {
            a11 - 2.0 * a12 + a22
        };
        let stress = m1 * sigma1 + m2 * sigma2;
        let mut tangent = m1 * m1.transpose() * a11
            + (m1 * m2.transpose() + m2 * m1.transpose()) * a12
            + m2 * m2.transpose() * a22
            + p * p.transpose() * kappa;
        if d2 < 1.0 {
            tangent += self.elasticity() * self.wrinkling_regularisation;
        }
        (stress, tangent)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::elements::material::{Wrinkling, WrinklingState};

    fn film() -> Material {
        let mut m: Material = serde_json::from_str(
            r#"{"youngs_modulus": 8e8, "poisson_ratio": 0.45, "thickness": 2.5e-4,
                "prestress": [2e6, 1e6, 0.3e6], "wrinkling": "tension-field"}"#,
        )
        .unwrap();
        m.wrinkling_regularisation = 0.0;
        m
    }

    /// Which part of each rounded switch a strain is on: (ê1's, ê2 + νê1's), each 0 below, 1
    /// within, 2 above the rounding.
    fn parts(m: &Material, strain: &Vector3<f64>, w: f64) -> (u8, u8) {
        let nu = m.poisson_ratio;
        let (e1, e2, _) = principal_strains(&m.effective_strain(strain));
        let zone = |y: f64, w: f64| {
            if y <= -0.5 * w {
                0
            } else if y < 0.5 * w {
                1
            } else {
                2
            }
        };
        (zone(e1, w), zone(e2 + nu * e1, (1.0 + nu) * w))
    }

    /// The rounded film's tangent against central differences of its stress at random strains
    /// in every part of both rounded switches (slack, wrinkled and taut, and between them),
    /// including nearly equal principal strains.
    #[test]
    fn rounded_tension_field_tangent_matches_finite_differences_in_every_part() {
        let m = film();
        let w = 1e-4;
        let mut seen = std::collections::HashSet::new();
        let mut seed = 5u64;
        let mut rand = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let shift = m.effective_strain(&Vector3::zeros());
        for case in 0..20000 {
            // Effective strains of a few widths, sometimes nearly equibiaxial.
            let scale = if case % 2 == 0 { 2.0 * w } else { 20.0 * w };
            let mut e = Vector3::new(rand(), rand(), rand()) * scale;
            if case % 5 == 0 {
                e.y = e.x + 1e-3 * w * rand();
                e.z = 1e-3 * w * rand();
            }
            let strain = e - shift;
            let here = parts(&m, &strain, w);
            let h = 1e-9;
            let near = (0..3).any(|k| {
                [-1.0, 1.0]
                    .iter()
                    .any(|sg| parts(&m, &(strain + Vector3::ith(k, 20.0 * h * sg)), w) != here)
            });
            if near {
                continue;
            }
            let (_, tangent) = m.tension_field_rounded(&strain, w);
            let mut fd = Matrix3::zeros();
            for k in 0..3 {
                let d = Vector3::ith(k, h);
                let plus = m.tension_field_rounded(&(strain + d), w).0;
                let minus = m.tension_field_rounded(&(strain - d), w).0;
                fd.set_column(k, &((plus - minus) / (2.0 * h)));
            }
            let error = (fd - tangent).amax() / m.elasticity().amax();
            assert!(
                error < 1e-5,
                "parts {here:?} at ε̂ {e:?}: relative error {error:e}\nanalytic {tangent}\nfd {fd}"
            );
            seen.insert(here);
        }
        for part in [(0, 0), (1, 0), (1, 1), (2, 0), (2, 1), (2, 2)] {
            assert!(seen.contains(&part), "part {part:?} never tested");
        }
    }

    /// Away from its switches the rounded film is the tension-field law itself: slack, wrinkled
    /// and taut give the law's stress, and the law's tangent.
    #[test]
    fn rounded_tension_field_is_the_law_away_from_its_switches() {
        let m = film();
        let shift = m.effective_strain(&Vector3::zeros());
        let mut states = std::collections::HashSet::new();
        for e in [
            Vector3::new(-2e-3, -1e-3, 5e-4),
            Vector3::new(3e-3, -2e-3, 1e-3),
            Vector3::new(3e-3, 2e-3, -1e-3),
            Vector3::new(2e-3, 2e-3, 0.0),
        ] {
            let strain = e - shift;
            let law = m.response(&strain);
            let (stress, tangent) = m.tension_field_rounded(&strain, 1e-9);
            states.insert(law.state as u8);
            let scale = m.elasticity().amax();
            assert!(
                (stress - law.stress).amax() < 1e-9 * scale * 1e-3,
                "{:?}",
                law.state
            );
            assert!(
                (tangent - m.tangent(&law)).amax() < 1e-9 * scale,
                "{:?}",
                law.state
            );
        }
        assert_eq!(states.len(), 3, "slack, wrinkled and taut each compared");
        assert_eq!(m.wrinkling, Wrinkling::TensionField);
        let _ = WrinklingState::Taut;
    }
}
