//! Orifices between two chambers (issue 43 item 2; docs/mechanics.md, "Orifices"): the air's
//! mass flow by the incompressible orifice equation, and the mass it moves over a time step by
//! backward Euler.
//!
//! The flow law is the orifice (Bernoulli) equation with a discharge coefficient,
//! `ṁ = C_d A √(2 ρ |Δp|) sign(Δp)`, `Δp = p_from − p_to` and `ρ = (p + p_a)/(R T)` the
//! upstream air's density (ideal gas); ISO 5167-2:2003 writes it for orifice plates (with the
//! expansibility factor ε, here 1, and the approach factor `1/√(1 − β⁴)`, here 1: an opening
//! small against the chambers). Over a step `Δt` the moved mass `m` solves
//! `m = Δt · ṁ(Δp(m))` at the end of the step. `Δp(m) = Δp(0) − m R (T_f/V_f + T_t/V_t)` is
//! linear and decreasing in `m`, so `m − Δt ṁ(m)` increases strictly and has one root between
//! 0 and the mass `m_eq` that equalises the pressures: bisection finds it, and the pressures
//! never cross however long the step (no overshoot).

use super::chamber::{AIR_GAS_CONSTANT, GasLaw};

/// One chamber at an orifice's end in an evaluation: its gas and current volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrificeEnd {
    /// The chamber's gas law.
    pub law: GasLaw,
    /// The gas's constant `C` before the orifice's transfer.
    pub constant: f64,
    /// The chamber's volume (m³).
    pub volume: f64,
    /// The air's temperature (K).
    pub temperature: f64,
    /// `Some(p)`: a supply holds the gauge pressure `p` (Pa) whatever air passes (the chamber
    /// is not sealed; its `constant` is unused).
    pub held: Option<f64>,
}

impl OrificeEnd {
    /// The gauge pressure (Pa) with `mass` kg of air added (negative: let out).
    pub fn pressure_with(&self, mass: f64) -> f64 {
        if let Some(p) = self.held {
            return p;
        }
        let c = self.law.with_air(self.constant, mass, self.volume);
        self.law.pressure(c, self.volume, self.temperature)
    }

    /// `∂p/∂m = R T/V` (Pa/kg): how the pressure rises with air added (0 where a supply holds
    /// it).
    pub fn mass_stiffness(&self) -> f64 {
        match self.held {
            Some(_) => 0.0,
            None => AIR_GAS_CONSTANT * self.temperature / self.volume,
        }
    }

    /// The air's density (kg/m³) at gauge pressure `p` (ideal gas).
    fn density(&self, p: f64) -> f64 {
        (p + self.law.atmosphere) / (AIR_GAS_CONSTANT * self.temperature)
    }
}

/// The orifice equation `ṁ = C_d A √(2 ρ |Δp|) sign(Δp)` (kg/s): `cda = C_d A` (m²), `dp` the
/// pressure difference (Pa) and `density` the upstream air's (kg/m³).
pub fn orifice_flow(cda: f64, dp: f64, density: f64) -> f64 {
    cda * (2.0 * density.max(0.0) * dp.abs()).sqrt() * dp.signum()
}

/// The mass flow (kg/s) from `from` to `to` once `mass` kg has moved.
fn flow_after(cda: f64, from: &OrificeEnd, to: &OrificeEnd, mass: f64) -> f64 {
    let (pf, pt) = (from.pressure_with(-mass), to.pressure_with(mass));
    let density = if pf >= pt {
        from.density(pf)
    } else {
        to.density(pt)
    };
    orifice_flow(cda, pf - pt, density)
}

/// The air mass (kg) that flows from `from` to `to` over `dt` seconds by backward Euler: the
/// root of `m − dt ṁ(m)` between 0 and the equalising mass (0 where `dt ≤ 0` or a volume is
/// not positive). Between two supplies, whose pressures no air changes, it is `dt ṁ`.
pub fn implicit_transfer(cda: f64, from: &OrificeEnd, to: &OrificeEnd, dt: f64) -> f64 {
    let stiffness = from.mass_stiffness() + to.mass_stiffness();
    if !(dt > 0.0 && from.volume > 0.0 && to.volume > 0.0 && stiffness.is_finite()) {
        return 0.0;
    }
    if stiffness == 0.0 {
        return dt * flow_after(cda, from, to, 0.0);
    }
    let equal = (from.pressure_with(0.0) - to.pressure_with(0.0)) / stiffness;
    if !equal.is_finite() || equal == 0.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = if equal > 0.0 {
        (0.0, equal)
    } else {
        (equal, 0.0)
    };
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if mid - dt * flow_after(cda, from, to, mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// How the backward-Euler transfer `m` over `dt` follows its ends' pressures: `(∂m/∂P_f,
/// ∂m/∂P_t)` with `P_f`, `P_t` the pressures after the transfer at a fixed `m` (what the
/// volumes and the air already moved make). Differentiating `m = dt ṁ(Δp, ρ)` with
/// `dΔp = dP_f − dP_t − s dm`, `s = k_f + k_t` ([`OrificeEnd::mass_stiffness`]),
/// `dt ∂ṁ/∂Δp = m/(2Δp) = 1/r` and `dt ∂ṁ/∂ρ dρ = δ dP_up`, `δ = m/(2(P_up + p_a))` of the
/// upstream end (its density's change; the upstream pressure itself moves by `∓k dm`):
/// `dm (r + s + r (δ_f k_f − δ_t k_t)) = (1 + r δ_f) dP_f − (1 − r δ_t) dP_t`, `δ` nonzero
/// at the upstream end only. `r = 0` once the pressures are equal (the flow law is infinitely
/// steep there): `dm = (dP_f − dP_t)/s`. Nothing where `dt ≤ 0` or no air moved against a
/// pressure difference.
pub fn transfer_sensitivity(from: &OrificeEnd, to: &OrificeEnd, mass: f64, dt: f64) -> (f64, f64) {
    let (kf, kt) = (from.mass_stiffness(), to.mass_stiffness());
    let (pf, pt) = (from.pressure_with(-mass), to.pressure_with(mass));
    let dp = pf - pt;
    if !(dt > 0.0 && (kf + kt).is_finite()) || (mass == 0.0 && dp != 0.0) {
        return (0.0, 0.0);
    }
    let r = if mass == 0.0 {
        0.0
    } else {
        (2.0 * dp / mass).max(0.0)
    };
    let (df, dt_) = if pf >= pt {
        (mass / (2.0 * (pf + from.law.atmosphere)), 0.0)
    } else {
        (0.0, mass / (2.0 * (pt + to.law.atmosphere)))
    };
    let denominator = r + kf + kt + r * (df * kf - dt_ * kt);
    if !(denominator > 0.0) {
        return (0.0, 0.0);
    }
    ((1.0 + r * df) / denominator, -(1.0 - r * dt_) / denominator)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn end(pressure: f64, volume: f64) -> OrificeEnd {
        let law = GasLaw {
            kappa: 1.0,
            atmosphere: 101_325.0,
            temperature: 293.15,
        };
        OrificeEnd {
            law,
            constant: law.constant(pressure, volume, 293.15),
            volume,
            temperature: 293.15,
            held: None,
        }
    }

    /// Rigid chambers: a long step ends at Boyle's shared pressure
    /// `p + p_a = Σ (p_i + p_a) V_i / Σ V_i` without crossing it.
    #[test]
    fn a_long_step_equalises_two_rigid_chambers_at_boyles_pressure() {
        let (a, b) = (end(400.0, 0.2), end(100.0, 0.6));
        let m = implicit_transfer(1e-3, &a, &b, 1e6);
        let shared = ((400.0 + 101_325.0) * 0.2 + (100.0 + 101_325.0) * 0.6) / 0.8 - 101_325.0;
        let (pa, pb) = (a.pressure_with(-m), b.pressure_with(m));
        assert!(
            (pa - shared).abs() < 1e-6 && (pb - shared).abs() < 1e-6,
            "{pa} {pb} {shared}"
        );
        assert!(pa >= pb, "no overshoot");
    }

    /// A short step moves the law's `ṁ Δt` at the start's pressures (within the change of
    /// `ṁ` over the step).
    #[test]
    fn a_short_step_moves_the_laws_flow_times_the_step() {
        let (a, b) = (end(400.0, 0.2), end(100.0, 0.6));
        let (cda, dt) = (0.6 * 1e-4, 1e-4);
        let rate = orifice_flow(cda, 300.0, a.density(400.0));
        let m = implicit_transfer(cda, &a, &b, dt);
        assert!((m / (rate * dt) - 1.0).abs() < 1e-3, "{m} vs {}", rate * dt);
        // Reversed ends: the same mass the other way.
        let back = implicit_transfer(cda, &b, &a, dt);
        assert!((back + m).abs() < 1e-12 * m.abs());
    }
}
