//! Results a user reads off a model: named output points (a node's displacement: the sag at
//! mid-span, the crown) and field summaries over named element sets (model file `"outputs"`,
//! FMU outputs `<point>.ux/.uy/.uz` and `<set>.maxPrincipalStress`, …).

use serde::{Deserialize, Serialize};

use crate::mech::elements::material::WrinklingState;
use crate::mech::elements::triangle::ElementStress;

/// Extremes of the film's fields over a set of triangles.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FieldSummary {
    /// Largest major principal stress `σ1` (Pa).
    pub max_principal_stress: f64,
    /// Smallest minor principal stress `σ2` (Pa): negative where the film is compressed
    /// (never below zero with the tension-field film).
    pub min_principal_stress: f64,
    /// Largest von Mises stress (Pa).
    pub max_equivalent_stress: f64,
    /// Largest major principal Green–Lagrange strain.
    pub max_strain: f64,
    /// Reference area of the triangles that would be compressed (m²): wrinkled or slack with the
    /// tension-field film, `σ2 < 0` without it.
    pub compressed_area: f64,
    /// Largest equivalent plastic strain `ε̄p` (0 for the elastic film).
    #[serde(default)]
    pub max_plastic_strain: f64,
}

/// A stress given in Pa, in MPa for a summary or a message: three decimals (`14.708`) where they
/// show its magnitude, else three significant digits in exponent form (`1.000e-306` for
/// 1e-300 Pa, which three decimals print as `0.000`; `1.000e302` instead of 303 digits).
pub fn mpa(pa: f64) -> String {
    let x = pa / 1e6;
    if x == 0.0 || !x.is_finite() || (1e-3..1e9).contains(&x.abs()) {
        format!("{x:.3}")
    } else {
        format!("{x:.3e}")
    }
}

/// Major principal value of a Voigt tensor `[xx, yy, 2·xy]` (engineering shear, as strains)
/// or `[xx, yy, xy]` (`shear_factor` 1, as stresses).
pub(super) fn major_principal(v: [f64; 3], shear_factor: f64) -> f64 {
    let shear = v[2] * shear_factor;
    0.5 * (v[0] + v[1]) + (0.25 * (v[0] - v[1]).powi(2) + shear * shear).sqrt()
}

/// Whether a triangle counts in [`FieldSummary::compressed_area`].
fn compressed(e: &ElementStress) -> bool {
    match e.state {
        WrinklingState::Taut => e.principal[1] < 0.0,
        WrinklingState::Wrinkled | WrinklingState::Slack => true,
    }
}

/// The summary of the triangles `set` (indices into `elements` and `areas`, the reference
/// areas). An empty set gives zeros.
pub fn summarize(elements: &[ElementStress], areas: &[f64], set: &[usize]) -> FieldSummary {
    if set.is_empty() {
        return FieldSummary {
            max_principal_stress: 0.0,
            min_principal_stress: 0.0,
            max_equivalent_stress: 0.0,
            max_strain: 0.0,
            compressed_area: 0.0,
            max_plastic_strain: 0.0,
        };
    }
    let mut s = FieldSummary {
        max_principal_stress: f64::NEG_INFINITY,
        min_principal_stress: f64::INFINITY,
        max_equivalent_stress: f64::NEG_INFINITY,
        max_strain: f64::NEG_INFINITY,
        compressed_area: 0.0,
        max_plastic_strain: 0.0,
    };
    // NaN-aware folds: a NaN field makes the summary NaN, which the finiteness check refuses.
    let max = |a: f64, b: f64| {
        if a.is_nan() || b.is_nan() {
            f64::NAN
        } else {
            a.max(b)
        }
    };
    let min = |a: f64, b: f64| {
        if a.is_nan() || b.is_nan() {
            f64::NAN
        } else {
            a.min(b)
        }
    };
    for &i in set {
        let e = &elements[i];
        s.max_principal_stress = max(s.max_principal_stress, e.principal[0]);
        s.min_principal_stress = min(s.min_principal_stress, e.principal[1]);
        s.max_equivalent_stress = max(s.max_equivalent_stress, e.von_mises);
        s.max_strain = max(s.max_strain, major_principal(e.strain, 0.5));
        if compressed(e) {
            s.compressed_area += areas[i];
        }
        if let Some(p) = e.plastic {
            s.max_plastic_strain = max(s.max_plastic_strain, p.equivalent_plastic_strain);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn element(principal: [f64; 2], strain: [f64; 3], state: WrinklingState) -> ElementStress {
        let (s1, s2) = (principal[0], principal[1]);
        ElementStress {
            strain,
            stress: [s1, s2, 0.0],
            principal,
            von_mises: (s1 * s1 - s1 * s2 + s2 * s2).sqrt(),
            state,
            tension_direction: [0.0; 3],
            plastic: None,
        }
    }

    #[test]
    fn principal_strain_is_the_mohr_circle_maximum() {
        // εx = 0.01, εy = −0.01, γxy = 0.02 → ε1 = √(0.01² + 0.01²).
        let e = major_principal([0.01, -0.01, 0.02], 0.5);
        assert!((e - 2e-4f64.sqrt()).abs() < 1e-15, "{e}");
    }

    #[test]
    fn compressed_area_counts_negative_minor_stress_or_a_wrinkling_state() {
        let elements = [
            element([2e6, 1e6], [0.001, 0.0, 0.0], WrinklingState::Taut),
            element([2e6, -1e5], [0.002, 0.0, 0.0], WrinklingState::Taut),
            element([3e6, 0.0], [0.003, 0.0, 0.0], WrinklingState::Wrinkled),
            element([0.0, 0.0], [-0.001, 0.0, 0.0], WrinklingState::Slack),
        ];
        let areas = [1.0, 2.0, 4.0, 8.0];
        let s = summarize(&elements, &areas, &[0, 1, 2, 3]);
        assert_eq!(s.compressed_area, 14.0);
        assert_eq!(s.max_principal_stress, 3e6);
        assert_eq!(s.min_principal_stress, -1e5);
        assert_eq!(s.max_strain, 0.003);
        let only_first = summarize(&elements, &areas, &[0]);
        assert_eq!(only_first.compressed_area, 0.0);
        assert_eq!(only_first.max_equivalent_stress, elements[0].von_mises);
    }

    #[test]
    fn a_nan_field_makes_the_summary_nan() {
        let elements = [
            element([2e6, 1e6], [0.001, 0.0, 0.0], WrinklingState::Taut),
            element([f64::NAN, 1e6], [0.001, 0.0, 0.0], WrinklingState::Taut),
        ];
        let s = summarize(&elements, &[1.0, 1.0], &[0, 1]);
        assert!(s.max_principal_stress.is_nan());
    }

    #[test]
    fn stresses_in_mpa_keep_their_magnitude_at_every_scale() {
        for (pa, text) in [
            (14.708e6, "14.708"),
            (0.0, "0.000"),
            (-2.5e5, "-0.250"),
            (1e-300, "1.000e-306"),
            (400.0, "4.000e-4"),
            (1e308, "1.000e302"),
        ] {
            assert_eq!(mpa(pa), text, "{pa} Pa");
        }
    }
}
