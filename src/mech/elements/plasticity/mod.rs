//! Elasto-plastic film (issue 20): plane-stress von Mises (J2) plasticity at finite strain with
//! piecewise-linear isotropic hardening, for the constant-strain membrane triangle.
//!
//! `docs/mechanics.md` § "Plastic film" has the formulation, the sources and the assumptions;
//! in short (symbols as there):
//!
//! * **Kinematics.** Multiplicative split `F = Fe Fp`, stored as the in-plane inverse plastic
//!   metric `Cp⁻¹` (2×2, element frame) per element. With `Cp⁻¹ = Q Qᵀ` (Cholesky), the elastic
//!   trial left Cauchy–Green tensor `be = F Cp⁻¹ Fᵀ` has the eigenvalues of `Y = Qᵀ C Q`,
//!   `C = FᵀF = I + 2E`; the trial elastic logarithmic (Hencky) strain is `εtr = ½ ln Y`.
//! * **Elasticity.** Hencky, isotropic, plane stress in log space: Kirchhoff `τ = Ē ε` on the
//!   spherical part (`Ē = E/(1−ν)`) and `2G ε` on the deviator; `τ33 = 0` gives
//!   `εe33 = −ν (τ1 + τ2)/E`.
//! * **Return.** Exponential map (Simo 1992; de Souza Neto, Perić & Owen 2008, ch. 14): because
//!   the law is isotropic, the return happens in log space exactly like small-strain plane-stress
//!   J2 with the plane-stress-projected algorithm (ibid. ch. 9, Box 9.4): `m = m_tr/(1 + Δγ Ē/3)`,
//!   `dev τ = dev τ_tr/(1 + 2G Δγ)`, `Φ(Δγ) = ½ξ − ⅓σy(ε̄p)² = 0`, `ξ = ⅔m² + |dev τ|²`,
//!   `Δε̄p = Δγ √(⅔ξ)`. Plastic flow is isochoric: `Δεp33 = −tr Δεp`. The yield function is on
//!   the Kirchhoff stress.
//! * **Stress.** `S = Q (τ̂ Y⁻¹) Qᵀ` (2nd Piola–Kirchhoff, per unit initial volume, element frame);
//!   `Cp⁻¹ ← Q exp(−2Δεp) Qᵀ`.
//! * **Tangent.** The algorithmic tangent `∂S/∂E` is the exact derivative of the stress update
//!   above, computed by forward-mode differentiation (dual numbers) through the update and one
//!   Newton step of the return from its converged root (which is the implicit-function
//!   derivative). Matrix logarithm and exponential are written as `a I + b D` with `a`, `b`
//!   smooth in `|D|²`, so equal principal stretches (the undeformed film, equibiaxial stretch)
//!   need no special case.
//! * **Tension field.** With wrinkling, the film carries no compression: the wrinkling strain is a
//!   contraction across the tension direction that costs no energy. Slack if the larger trial
//!   elastic log strain is `≤ 0` (no stress, no flow); otherwise the biaxial return is taut if its
//!   smaller principal stress is `≥ 0`, else the point is wrinkled and returns as a uniaxial
//!   bar along the trial tension direction `n1` (its flow across `n1` is absorbed by the
//!   wrinkles). By convexity of the incremental energy in the wrinkling strain this is the
//!   unique admissible state.
//! * **Prestress** is an initial elastic strain: `Cp⁻¹(0) = exp(2 D⁻¹σ0)`, so that `S(u = 0) = σ0`.

//!
//! | file | what |
//! |---|---|
//! | `mod.rs` | the material point: history, the return mapping, stress and algorithmic tangent |
//! | [`hardening`] | the hardening table, its validation, the default ETFE curve and its sources |
//! | `numbers` | dual numbers and 2×2 symmetric tensors the update is differentiated through |
//! | `tests` | closed forms (uniaxial, equibiaxial, pure shear) and finite-difference tangents |

use std::ops::Add;

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::material::WrinklingState;

pub mod hardening;
mod numbers;
#[cfg(test)]
mod tests;

pub use hardening::*;
use numbers::*;

/// `material.plasticity` of a model: J2 plasticity with this hardening table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plasticity {
    /// Rows (equivalent plastic strain, flow stress in Pa); the first is initial yield.
    pub hardening: Hardening,
}

/// Plastic history of one material point: what an increment starts from.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlasticHistory {
    /// Inverse plastic metric `Cp⁻¹` (Voigt `[xx, yy, xy]`, element frame); the identity for a
    /// virgin film without prestress.
    pub inverse_plastic_metric: [f64; 3],
    /// Equivalent plastic strain `ε̄p`.
    pub equivalent_plastic_strain: f64,
    /// `ln(t_u/t0)`: log of the thickness the point would have if elastically unloaded, over the
    /// model's thickness `t0` (plastic thickness strain, plus `ν(σ0x + σ0y)/E` with prestress so
    /// that the film has thickness `t0` at zero displacement).
    pub unloaded_thickness_strain: f64,
}

/// Committed and trial history of one material point: the trial follows the Newton iterates,
/// [`PlasticPoint::commit`] accepts it when an increment converges, [`PlasticPoint::restore`]
/// discards it (cut-back, Discard, restored FMU state).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlasticPoint {
    /// History at the end of the last converged increment.
    pub committed: PlasticHistory,
    /// History of the current iterate.
    pub trial: PlasticHistory,
}

impl PlasticPoint {
    /// A point whose committed and trial history are `history`.
    pub fn new(history: PlasticHistory) -> Self {
        Self {
            committed: history,
            trial: history,
        }
    }

    /// Accepts the trial history (the increment converged).
    pub fn commit(&mut self) {
        self.committed = self.trial;
    }

    /// Discards the trial history.
    pub fn restore(&mut self) {
        self.trial = self.committed;
    }
}

/// The elasto-plastic film law: Hencky elasticity, J2 plasticity, optional tension field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlasticFilm {
    /// Young's modulus `E` (Pa).
    pub youngs_modulus: f64,
    /// Poisson's ratio `ν`.
    pub poisson_ratio: f64,
    /// Isotropic hardening curve.
    pub hardening: Hardening,
    /// Whether the film wrinkles instead of carrying compression.
    pub tension_field: bool,
}

/// Stress, state and updated (trial) history at one strain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlasticResponse {
    /// 2nd Piola–Kirchhoff stress `S` (Pa, per unit initial volume), Voigt, element frame.
    pub stress: Vector3<f64>,
    /// The history after this increment (the trial history).
    pub history: PlasticHistory,
    /// Taut, wrinkled or slack (always taut without the tension field).
    pub state: WrinklingState,
    /// Whether the increment flows plastically.
    pub yielding: bool,
    /// Current over initial thickness `t/t0`.
    pub thickness_ratio: f64,
    /// Von Mises equivalent of the Kirchhoff stress (Pa), the stress the yield condition is on.
    pub equivalent_stress: f64,
    /// Principal Kirchhoff stresses `τ1 ≥ τ2` (Pa).
    pub principal_kirchhoff: [f64; 2],
}

/// Relative tolerance of the yield check and of the return's root.
const YIELD_TOLERANCE: f64 = 1e-12;

impl PlasticFilm {
    /// Shear modulus `G`.
    fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// Plane-stress bulk-like modulus `Ē = E/(1 − ν)` of the spherical part.
    fn areal_modulus(&self) -> f64 {
        self.youngs_modulus / (1.0 - self.poisson_ratio)
    }

    /// History of a virgin film with the initial stress `prestress` (Voigt, Pa): the prestress
    /// is an initial elastic strain (module doc).
    pub fn initial_history(&self, prestress: [f64; 3]) -> PlasticHistory {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        let [sx, sy, sxy] = prestress;
        // D⁻¹ σ0 as a strain tensor (shear: γ/2 = (1 + ν) τ / E).
        let strain = Sym2 {
            xx: (sx - nu * sy) / e,
            yy: (sy - nu * sx) / e,
            xy: (1.0 + nu) * sxy / e,
        };
        let metric = exp_sym(strain.scale(2.0));
        PlasticHistory {
            inverse_plastic_metric: [metric.xx, metric.yy, metric.xy],
            equivalent_plastic_strain: 0.0,
            unloaded_thickness_strain: nu * (sx + sy) / e,
        }
    }

    /// Stress and updated history at the Green strain `strain` (Voigt `[Exx, Eyy, 2Exy]`),
    /// starting from `history`.
    pub fn response(&self, history: &PlasticHistory, strain: &Vector3<f64>) -> PlasticResponse {
        let c = Sym2 {
            xx: 1.0 + 2.0 * strain.x,
            yy: 1.0 + 2.0 * strain.y,
            xy: strain.z,
        };
        let update = self.update(history, c);
        update.response(|s| s)
    }

    /// [`PlasticFilm::response`] and the consistent algorithmic tangent `∂S/∂E` (3×3, Voigt,
    /// engineering shear in `E`).
    pub fn response_and_tangent(
        &self,
        history: &PlasticHistory,
        strain: &Vector3<f64>,
    ) -> (PlasticResponse, Matrix3<f64>) {
        // C = I + 2E: ∂Cxx/∂Exx = 2, ∂Cyy/∂Eyy = 2, ∂Cxy/∂γ = 1.
        let c = Sym2 {
            xx: Dual {
                v: 1.0 + 2.0 * strain.x,
                d: [2.0, 0.0, 0.0],
            },
            yy: Dual {
                v: 1.0 + 2.0 * strain.y,
                d: [0.0, 2.0, 0.0],
            },
            xy: Dual {
                v: strain.z,
                d: [0.0, 0.0, 1.0],
            },
        };
        let update = self.update(history, c);
        let s = update.stress;
        let tangent = Matrix3::from_fn(|i, j| [s.xx, s.yy, s.xy][i].d[j]);
        (update.response(|x: Dual| x.v), tangent)
    }

    /// The stress update of the module doc, generic over plain and dual numbers.
    fn update<T: Real>(&self, history: &PlasticHistory, c: Sym2<T>) -> Update<T> {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        let (g2, ebar) = (2.0 * self.shear_modulus(), self.areal_modulus());
        let [a, b, d] = history.inverse_plastic_metric;
        // Cp⁻¹ = Q Qᵀ, Q lower triangular.
        let q11 = a.sqrt();
        let q21 = d / q11;
        let q22 = (b - q21 * q21).sqrt();
        let q = [[q11, 0.0], [q21, q22]];
        let qt = [[q11, q21], [0.0, q22]];
        let y = c.congruence(&qt);
        let (s_y, dev_y) = (y.mean(), y.dev());
        let r2_y = dev_y.xx * dev_y.xx + dev_y.xy * dev_y.xy;
        // εtr = ½ ln Y = ¼ ln(s² − r²) I + (g(r²/s²)/(2s)) dev Y.
        let mean_tr = (s_y * s_y - r2_y).ln() * T::c(0.25);
        let dev_tr = dev_y.scale_t(atanh_over(r2_y / (s_y * s_y)) / (s_y * T::c(2.0)));
        let rho2_tr = dev_tr.xx * dev_tr.xx + dev_tr.xy * dev_tr.xy;
        let ep_n = history.equivalent_plastic_strain;
        let hardening = &self.hardening;
        // Largest trial principal log strain: slack test.
        let major = mean_tr.v() + rho2_tr.v().sqrt();
        let scale = mean_tr.v().abs() + rho2_tr.v().sqrt();
        if self.tension_field && major <= 1e-12 * scale {
            return Update::slack(history);
        }
        // Biaxial (taut) trial and return.
        let m_trial = mean_tr * T::c(ebar);
        let dev_trial = dev_tr.scale(g2);
        let d2_trial = dev_trial.frob2();
        let phi = |dg, m, d2| taut_yield(hardening, ebar, g2, ep_n, m, d2, dg);
        let sy_n = hardening.flow_stress(ep_n).0;
        let trial_excess = phi(0.0, m_trial.v(), d2_trial.v());
        let (m_tau, dev_tau, dgamma) = if trial_excess > YIELD_TOLERANCE * sy_n * sy_n {
            let (m, d2) = (Dual1::c(m_trial.v()), Dual1::c(d2_trial.v()));
            let dg: T = return_root(
                |x| taut_yield(hardening, ebar, g2, ep_n, m, d2, x),
                |x| taut_yield(hardening, ebar, g2, ep_n, m_trial, d2_trial, x),
                1.0 / g2,
            );
            let m = m_trial / (T::c(1.0) + dg * T::c(ebar / 3.0));
            let dev = dev_trial.scale_t(T::c(1.0) / (T::c(1.0) + dg * T::c(g2)));
            (m, dev, Some(dg))
        } else {
            (m_trial, dev_trial, None)
        };
        let rho_tau = dev_tau.frob2().v().sqrt() / 2f64.sqrt();
        let minor = m_tau.v() - rho_tau;
        if self.tension_field && minor < -1e-12 * (m_tau.v().abs() + rho_tau) {
            return self.wrinkled(history, q, &y, mean_tr, dev_tr);
        }
        // Taut: τ̂ = m I + dev τ, εe = Dps⁻¹ τ̂, Δεp = εtr − εe.
        let tau = Sym2::identity(m_tau) + dev_tau;
        let (yielding, dep_bar) = match dgamma {
            Some(dg) => {
                let xi = m_tau * m_tau * T::c(2.0 / 3.0) + dev_tau.frob2();
                (true, dg.v() * (xi.v() * 2.0 / 3.0).sqrt())
            }
            None => (false, 0.0),
        };
        let eps_e33 = -2.0 * nu * m_tau.v() / e;
        let dep_mean = mean_tr.v() - m_tau.v() / ebar;
        let dep_dev = dev_tr.value().sub(dev_tau.value().scale(1.0 / g2));
        let dep = Sym2::identity(dep_mean).add(dep_dev);
        Update::finish(
            q,
            &y,
            tau,
            WrinklingState::Taut,
            history,
            if yielding { Some(dep) } else { None },
            dep_bar,
            eps_e33,
        )
    }

    /// Uniaxial return along the trial tension direction `n1` (wrinkled point).
    fn wrinkled<T: Real>(
        &self,
        history: &PlasticHistory,
        q: [[f64; 2]; 2],
        y: &Sym2<T>,
        mean_tr: T,
        dev_tr: Sym2<T>,
    ) -> Update<T> {
        let e = self.youngs_modulus;
        let nu = self.poisson_ratio;
        let ep_n = history.equivalent_plastic_strain;
        let hardening = &self.hardening;
        let rho = dev_tr.frob2().sqrt() * T::c(0.5f64.sqrt());
        let n1n1 = Sym2::identity(T::c(0.5)) + dev_tr.scale_t(T::c(0.5) / rho);
        let tau_trial = (mean_tr + rho) * T::c(e);
        let sy_n = hardening.flow_stress(ep_n).0;
        let (tau1, dl) =
            if bar_yield(hardening, e, ep_n, tau_trial.v(), 0.0) > YIELD_TOLERANCE * sy_n {
                let t = Dual1::c(tau_trial.v());
                let dl: T = return_root(
                    |x| bar_yield(hardening, e, ep_n, t, x),
                    |x| bar_yield(hardening, e, ep_n, tau_trial, x),
                    1.0 / e,
                );
                (tau_trial - dl * T::c(e), dl.v())
            } else {
                (tau_trial, 0.0)
            };
        let tau = n1n1.scale_t(tau1);
        // Δεp = Δ (n1n1 − ½ n2n2) = Δ (3/2 n1n1 − ½ I).
        let dep = n1n1.value().scale(1.5 * dl).add(Sym2::identity(-0.5 * dl));
        let eps_e33 = -nu * tau1.v() / e;
        Update::finish(
            q,
            y,
            tau,
            WrinklingState::Wrinkled,
            history,
            if dl > 0.0 { Some(dep) } else { None },
            dl,
            eps_e33,
        )
    }
}

/// Result of [`PlasticFilm::update`] in the number type `T`.
struct Update<T> {
    stress: Sym2<T>,
    history: PlasticHistory,
    state: WrinklingState,
    yielding: bool,
    thickness_ratio: f64,
    principal: [f64; 2],
}

impl<T: Real> Update<T> {
    fn slack(history: &PlasticHistory) -> Self {
        Self {
            stress: Sym2::identity(T::c(0.0)),
            history: *history,
            state: WrinklingState::Slack,
            yielding: false,
            thickness_ratio: history.unloaded_thickness_strain.exp(),
            principal: [0.0; 2],
        }
    }

    /// `S = Q (τ̂ Y⁻¹) Qᵀ` and the history update `Cp⁻¹ ← Q exp(−2Δεp) Qᵀ`.
    #[allow(clippy::too_many_arguments)]
    fn finish(
        q: [[f64; 2]; 2],
        y: &Sym2<T>,
        tau: Sym2<T>,
        state: WrinklingState,
        history: &PlasticHistory,
        plastic_increment: Option<Sym2<f64>>,
        dep_bar: f64,
        eps_e33: f64,
    ) -> Self {
        let (s, dev) = (y.mean(), y.dev());
        let det = s * s - (dev.xx * dev.xx + dev.xy * dev.xy);
        let y_inv = Sym2 {
            xx: (s - dev.xx) / det,
            yy: (s + dev.xx) / det,
            xy: -dev.xy / det,
        };
        let stress = tau.commuting_product(&y_inv).congruence(&q);
        let mut next = *history;
        if let Some(dep) = plastic_increment {
            let p = exp_sym(dep.scale(-2.0)).congruence(&q);
            next.inverse_plastic_metric = [p.xx, p.yy, p.xy];
            next.equivalent_plastic_strain += dep_bar;
            next.unloaded_thickness_strain -= 2.0 * dep.mean();
        }
        let tv = tau.value();
        let (m, r) = (tv.mean(), (tv.dev().frob2() / 2.0).sqrt());
        Self {
            stress,
            history: next,
            state,
            yielding: plastic_increment.is_some(),
            thickness_ratio: (next.unloaded_thickness_strain + eps_e33).exp(),
            principal: [m + r, m - r],
        }
    }

    fn response(&self, value: impl Fn(T) -> f64) -> PlasticResponse {
        let [t1, t2] = self.principal;
        PlasticResponse {
            stress: Vector3::new(
                value(self.stress.xx),
                value(self.stress.yy),
                value(self.stress.xy),
            ),
            history: self.history,
            state: self.state,
            yielding: self.yielding,
            thickness_ratio: self.thickness_ratio,
            equivalent_stress: (t1 * t1 - t1 * t2 + t2 * t2).sqrt(),
            principal_kirchhoff: self.principal,
        }
    }
}

/// Plane-stress-projected J2 yield function after a return `Δγ` (de Souza Neto et al., Box 9.4)
/// from the trial mean Kirchhoff stress `m` and squared deviator norm `d2`.
fn taut_yield<U: Real>(
    hardening: &Hardening,
    ebar: f64,
    g2: f64,
    ep_n: f64,
    m: U,
    d2: U,
    dg: U,
) -> U {
    let m = m / (U::c(1.0) + dg * U::c(ebar / 3.0));
    let dev2 = d2 / sq(U::c(1.0) + dg * U::c(g2));
    let xi = m * m * U::c(2.0 / 3.0) + dev2;
    let ep = U::c(ep_n) + dg * (xi * U::c(2.0 / 3.0)).sqrt();
    let sy = hardening.flow_stress_of(ep);
    xi * U::c(0.5) - sy * sy * U::c(1.0 / 3.0)
}

/// Uniaxial yield function after a plastic strain increment `Δ` from the trial stress `τ_tr`.
fn bar_yield<U: Real>(hardening: &Hardening, e: f64, ep_n: f64, tau_trial: U, dl: U) -> U {
    tau_trial - dl * U::c(e) - hardening.flow_stress_of(U::c(ep_n) + dl)
}

/// Root in `T` of a decreasing scalar equation with `f(0) > 0`: solved on plain numbers (`f`
/// with one derivative), then one Newton step in `T` (`ft`) from the root, which carries the
/// implicit-function derivative of the root with respect to the strains.
fn return_root<T: Real>(f: impl Fn(Dual1) -> Dual1, ft: impl Fn(T) -> T, scale: f64) -> T {
    let eval = |x: f64| {
        let r = f(Dual1 { v: x, d: 1.0 });
        (r.v, r.d)
    };
    let root = solve_decreasing(eval, scale);
    let slope = eval(root).1;
    T::c(root) - ft(T::c(root)) / T::c(slope)
}

/// Root of a decreasing function with `f(0) > 0`: Newton inside a bracket, bisection when
/// Newton leaves it. `scale` is a first guess of the root's size.
fn solve_decreasing(f: impl Fn(f64) -> (f64, f64), scale: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, scale);
    for _ in 0..200 {
        if f(hi).0 < 0.0 {
            break;
        }
        lo = hi;
        hi *= 4.0;
    }
    let mut x = lo;
    let f0 = f(0.0).0.abs();
    for _ in 0..200 {
        let (fx, dfx) = f(x);
        if fx.abs() <= 1e-15 * f0 {
            return x;
        }
        if fx > 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - fx / dfx;
        x = if dfx < 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo <= 1e-16 * hi {
            return x;
        }
    }
    x
}
