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
//!   above. Every tensor of the update is `x I + y dev Y` with `x`, `y` functions of the two
//!   invariants `s = ½ tr Y`, `r² = −det dev Y` alone, so `S = p Cp⁻¹ + q M`
//!   (`M = Q dev Y Qᵀ`, `(p, q)` from `τ̂ Y⁻¹`). `p`, `q` are computed on dual numbers in
//!   `(s, r²)`, through the return and one Newton step of it from its converged root (the
//!   implicit-function derivative); the chain rule to `E` is written out
//!   (`ds = ½ Cp⁻¹ : dC`, `d(r²) = M : dC`, `dM = Cp⁻¹ dC Cp⁻¹ − ds Cp⁻¹`). Matrix logarithm and
//!   exponential are written as `a I + b D` with `a`, `b` smooth in `|D|²`, so equal principal
//!   stretches (the undeformed film, equibiaxial stretch) need no special case. The tests check
//!   this against the same update run on dual numbers in the three strains, tensors included
//!   (`reference.rs`).
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
//! | `reference` | (tests) the update on dual numbers in the three strains, the oracle of the tangent |
//! | `tests` | closed forms (uniaxial, equibiaxial, pure shear) and finite-difference tangents |

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::material::WrinklingState;

pub mod hardening;
mod numbers;
#[cfg(test)]
mod reference;
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

/// Relative rounding of the return's scalar equations, in the size of their terms.
const ROUNDING: f64 = 1e-14;

/// Units in the last place of the return's root below which a Newton step or the bracket
/// counts as converged (the residual is then rounding noise).
const ROOT_ULPS: f64 = 4.0;

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
        let trial = Trial::new(history, strain);
        let ret = self.return_map(history.equivalent_plastic_strain, trial.s, trial.r2);
        trial.response(history, &ret)
    }

    /// [`PlasticFilm::response`] and the consistent algorithmic tangent `∂S/∂E` (3×3, Voigt,
    /// engineering shear in `E`): the return runs on dual numbers in the invariants `(s, r²)`
    /// of `Y`, and the chain rule through `S = p Cp⁻¹ + q M` is written out (module doc).
    pub fn response_and_tangent(
        &self,
        history: &PlasticHistory,
        strain: &Vector3<f64>,
    ) -> (PlasticResponse, Matrix3<f64>) {
        let trial = Trial::new(history, strain);
        let s = Dual2 {
            v: trial.s,
            d: [1.0, 0.0],
        };
        let r2 = Dual2 {
            v: trial.r2,
            d: [0.0, 1.0],
        };
        let ret = self.return_map(history.equivalent_plastic_strain, s, r2);
        let (p, q) = coefficients(s, r2, ret.a, ret.b);
        let value = Return {
            a: ret.a.v,
            b: ret.b.v,
            state: ret.state,
            flow: ret.flow,
            eps_e33: ret.eps_e33,
        };
        (trial.response(history, &value), trial.tangent(p, q))
    }

    /// The return of the module doc in the invariants `s = ½ tr Y`, `r² = −det dev Y` of the
    /// trial `Y`, from the equivalent plastic strain `ep_n`: generic over plain numbers and
    /// dual numbers in `(s, r²)`. Every tensor of the update is `x I + y dev Y`.
    fn return_map<T: Real>(&self, ep_n: f64, s: T, r2: T) -> Return<T> {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        let (g2, ebar) = (2.0 * self.shear_modulus(), self.areal_modulus());
        // εtr = ½ ln Y = ¼ ln(s² − r²) I + β dev Y, β = g(r²/s²)/(2s).
        let mean_tr = (s * s - r2).ln() * T::c(0.25);
        let beta = atanh_over(r2 / (s * s)) / (s * T::c(2.0));
        let r = r2.v().sqrt();
        let hardening = &self.hardening;
        // Largest trial principal log strain: slack test.
        let (major, scale) = (mean_tr.v() + beta.v() * r, mean_tr.v().abs() + beta.v() * r);
        if self.tension_field && major <= 1e-12 * scale {
            return Return {
                a: T::c(0.0),
                b: T::c(0.0),
                state: WrinklingState::Slack,
                flow: None,
                eps_e33: 0.0,
            };
        }
        // Biaxial (taut) trial and return: τtr = m_tr I + b_tr dev Y, |dev τtr|² = 2 b_tr² r².
        let m_trial = mean_tr * T::c(ebar);
        let b_trial = beta * T::c(g2);
        let d2_trial = b_trial * b_trial * r2 * T::c(2.0);
        let (a, b, dgamma) = match taut_return(hardening, ebar, g2, ep_n, m_trial, d2_trial) {
            Some(dg) => {
                let a = m_trial / (T::c(1.0) + dg * T::c(ebar / 3.0));
                let b = b_trial / (T::c(1.0) + dg * T::c(g2));
                (a, b, Some(dg.v()))
            }
            None => (m_trial, b_trial, None),
        };
        let rho_tau = b.v().abs() * r;
        let minor = a.v() - rho_tau;
        if self.tension_field && minor < -1e-12 * (a.v().abs() + rho_tau) {
            return self.wrinkled_return(ep_n, r2, mean_tr, beta);
        }
        // Taut: εe = Dps⁻¹ τ̂, Δεp = εtr − εe.
        let flow = dgamma.map(|dg| {
            let xi = a.v() * a.v() * (2.0 / 3.0) + 2.0 * b.v() * b.v() * r2.v();
            Flow {
                mean: mean_tr.v() - a.v() / ebar,
                dev: beta.v() - b.v() / g2,
                equivalent: dg * (xi * 2.0 / 3.0).sqrt(),
            }
        });
        Return {
            a,
            b,
            state: WrinklingState::Taut,
            flow,
            eps_e33: -2.0 * nu * a.v() / e,
        }
    }

    /// Uniaxial return along the trial tension direction `n1n1 = ½ I + dev Y/(2r)` (wrinkled
    /// point), from the trial strain `εtr = mean_tr I + β dev Y`.
    fn wrinkled_return<T: Real>(&self, ep_n: f64, r2: T, mean_tr: T, beta: T) -> Return<T> {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        let hardening = &self.hardening;
        let r = r2.sqrt();
        let tau_trial = (mean_tr + beta * r) * T::c(e);
        let (tau1, dl) = bar_return(hardening, e, ep_n, tau_trial);
        // Δεp = Δ (n1n1 − ½ n2n2) = Δ (3/2 n1n1 − ½ I) = Δ/4 I + 3Δ/(4r) dev Y.
        Return {
            a: tau1 * T::c(0.5),
            b: tau1 / (r * T::c(2.0)),
            state: WrinklingState::Wrinkled,
            flow: (dl > 0.0).then(|| Flow {
                mean: 0.25 * dl,
                dev: 0.75 * dl / r.v(),
                equivalent: dl,
            }),
            eps_e33: -nu * tau1.v() / e,
        }
    }
}

/// The trial kinematics of one evaluation: `Cp⁻¹ = Q Qᵀ`, `Y = Qᵀ C Q` by its invariants
/// `s = ½ tr Y`, `r² = −det dev Y` and its deviator, and `M = Q dev Y Qᵀ`.
struct Trial {
    q: [[f64; 2]; 2],
    metric: Sym2<f64>,
    s: f64,
    r2: f64,
    dev: Sym2<f64>,
    m: Sym2<f64>,
}

/// What [`PlasticFilm::return_map`] gives: `τ̂ = a I + b dev Y` in `T` and the flow.
struct Return<T> {
    a: T,
    b: T,
    state: WrinklingState,
    /// The plastic increment, when the point flows.
    flow: Option<Flow>,
    /// Elastic thickness strain `εe33`.
    eps_e33: f64,
}

/// A plastic increment `Δεp = mean I + dev · dev Y` with its `Δε̄p`.
#[derive(Clone, Copy)]
struct Flow {
    mean: f64,
    dev: f64,
    equivalent: f64,
}

/// `τ̂ Y⁻¹ = p I + q dev Y` from `τ̂ = a I + b dev Y` (with `(dev Y)² = r² I`).
fn coefficients<T: Real>(s: T, r2: T, a: T, b: T) -> (T, T) {
    let det = s * s - r2;
    ((a * s - b * r2) / det, (b * s - a) / det)
}

impl Trial {
    fn new(history: &PlasticHistory, strain: &Vector3<f64>) -> Self {
        let c = Sym2 {
            xx: 1.0 + 2.0 * strain.x,
            yy: 1.0 + 2.0 * strain.y,
            xy: strain.z,
        };
        let [a, b, d] = history.inverse_plastic_metric;
        // Cp⁻¹ = Q Qᵀ, Q lower triangular.
        let q11 = a.sqrt();
        let q21 = d / q11;
        let q22 = (b - q21 * q21).sqrt();
        let q = [[q11, 0.0], [q21, q22]];
        let y = c.congruence(&[[q11, q21], [0.0, q22]]);
        let (s, dev) = (y.mean(), y.dev());
        Self {
            q,
            metric: Sym2 {
                xx: a,
                yy: b,
                xy: d,
            },
            s,
            r2: dev.xx * dev.xx + dev.xy * dev.xy,
            dev,
            m: dev.congruence(&q),
        }
    }

    /// `S = Q (τ̂ Y⁻¹) Qᵀ = p Cp⁻¹ + q M` and the history update `Cp⁻¹ ← Q exp(−2Δεp) Qᵀ`.
    fn response(&self, history: &PlasticHistory, ret: &Return<f64>) -> PlasticResponse {
        let (p, q) = coefficients(self.s, self.r2, ret.a, ret.b);
        let stress = self.metric.scale(p) + self.m.scale(q);
        let mut next = *history;
        if let Some(flow) = ret.flow {
            let dep = Sym2::identity(flow.mean) + self.dev.scale(flow.dev);
            let p = exp_sym(dep.scale(-2.0)).congruence(&self.q);
            next.inverse_plastic_metric = [p.xx, p.yy, p.xy];
            next.equivalent_plastic_strain += flow.equivalent;
            next.unloaded_thickness_strain -= 2.0 * dep.mean();
        }
        let radius = ret.b.abs() * self.r2.sqrt();
        let [t1, t2] = [ret.a + radius, ret.a - radius];
        PlasticResponse {
            stress: Vector3::new(stress.xx, stress.yy, stress.xy),
            history: next,
            state: ret.state,
            yielding: ret.flow.is_some(),
            thickness_ratio: (next.unloaded_thickness_strain + ret.eps_e33).exp(),
            equivalent_stress: (t1 * t1 - t1 * t2 + t2 * t2).sqrt(),
            principal_kirchhoff: [t1, t2],
        }
    }

    /// `∂S/∂E` of `S = p(s, r²) Cp⁻¹ + q(s, r²) M`: with `P = Cp⁻¹` and `dC = 2 dE`,
    /// `ds = ½ P : dC`, `d(r²) = M : dC` and `dM = P dC P − ds P`.
    fn tangent(&self, p: Dual2, q: Dual2) -> Matrix3<f64> {
        let pm = &self.metric;
        let pv = [pm.xx, pm.yy, pm.xy];
        let mv = [self.m.xx, self.m.yy, self.m.xy];
        // (P dC_j P) in Voigt, column j = Exx, Eyy, γxy.
        let (xx, yy, xy) = (pm.xx, pm.yy, pm.xy);
        let pdcp = Matrix3::new(
            2.0 * xx * xx,
            2.0 * xy * xy,
            2.0 * xx * xy,
            2.0 * xy * xy,
            2.0 * yy * yy,
            2.0 * xy * yy,
            2.0 * xx * xy,
            2.0 * xy * yy,
            xx * yy + xy * xy,
        );
        Matrix3::from_fn(|i, j| {
            let (ds, dr2) = (pv[j], 2.0 * mv[j]);
            let dp = p.d[0] * ds + p.d[1] * dr2;
            let dq = q.d[0] * ds + q.d[1] * dr2;
            dp * pv[i] + dq * mv[i] + q.v * (pdcp[(i, j)] - ds * pv[i])
        })
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

/// `Δγ` of the taut return from the trial mean Kirchhoff stress `m_trial` and squared deviator
/// norm `d2_trial`, or `None` when the trial state is elastic.
fn taut_return<T: Real>(
    hardening: &Hardening,
    ebar: f64,
    g2: f64,
    ep_n: f64,
    m_trial: T,
    d2_trial: T,
) -> Option<T> {
    let sy_n = hardening.flow_stress(ep_n).0;
    let trial_excess = taut_yield(hardening, ebar, g2, ep_n, m_trial.v(), d2_trial.v(), 0.0);
    (trial_excess > YIELD_TOLERANCE * sy_n * sy_n).then(|| {
        let (m, d2) = (Dual1::c(m_trial.v()), Dual1::c(d2_trial.v()));
        return_root(
            |x| taut_yield(hardening, ebar, g2, ep_n, m, d2, x),
            |x| taut_yield(hardening, ebar, g2, ep_n, m_trial, d2_trial, x),
            1.0 / g2,
            sy_n * sy_n / 3.0,
        )
    })
}

/// The uniaxial return from the trial stress `τ_tr`: the stress `τ1` and the plastic strain
/// increment `Δ` (0 when elastic).
fn bar_return<T: Real>(hardening: &Hardening, e: f64, ep_n: f64, tau_trial: T) -> (T, f64) {
    let sy_n = hardening.flow_stress(ep_n).0;
    if bar_yield(hardening, e, ep_n, tau_trial.v(), 0.0) > YIELD_TOLERANCE * sy_n {
        let t = Dual1::c(tau_trial.v());
        let dl: T = return_root(
            |x| bar_yield(hardening, e, ep_n, t, x),
            |x| bar_yield(hardening, e, ep_n, tau_trial, x),
            1.0 / e,
            sy_n,
        );
        (tau_trial - dl * T::c(e), dl.v())
    } else {
        (tau_trial, 0.0)
    }
}

/// Uniaxial yield function after a plastic strain increment `Δ` from the trial stress `τ_tr`.
fn bar_yield<U: Real>(hardening: &Hardening, e: f64, ep_n: f64, tau_trial: U, dl: U) -> U {
    tau_trial - dl * U::c(e) - hardening.flow_stress_of(U::c(ep_n) + dl)
}

/// Root in `T` of a decreasing scalar equation with `f(0) > 0` whose terms are of the size
/// `terms`: solved on plain numbers (`f` with one derivative), then one Newton step in `T` (`ft`)
/// from the root, which carries the implicit-function derivative of the root with respect to
/// the strains.
fn return_root<T: Real>(
    f: impl Fn(Dual1) -> Dual1,
    ft: impl Fn(T) -> T,
    scale: f64,
    terms: f64,
) -> T {
    let (root, slope) = solve_decreasing(
        |x: f64| {
            let r = f(Dual1 { v: x, d: 1.0 });
            (r.v, r.d)
        },
        scale,
        terms,
    );
    T::c(root) - ft(T::c(root)) / T::c(slope)
}

/// Root of a decreasing function with `f(0) > 0`, and the slope there: Newton from 0 inside
/// the bracket found so far, bisection when Newton leaves it; while no point with `f < 0` is
/// known, a step Newton cannot take goes to `scale` (a first guess of the root's size) and then
/// quadruples. Converged when `|f| ≤ 1e-15 f(0)`, or `|f|` is at the rounding of terms of size
/// `terms` (a small `f(0)`: a point just past yield), or the step or the bracket is a few ulps.
fn solve_decreasing(f: impl Fn(f64) -> (f64, f64), scale: f64, terms: f64) -> (f64, f64) {
    #[cfg(test)]
    let f = |x| {
        tests::EVALUATIONS.with(|n| n.set(n.get() + 1));
        f(x)
    };
    let (mut lo, mut hi) = (0.0, f64::INFINITY);
    let mut x = 0.0;
    let (mut fx, mut dfx) = f(x);
    let tolerance = (1e-15 * fx.abs()).max(ROUNDING * terms);
    for _ in 0..400 {
        if fx.abs() <= tolerance {
            break;
        }
        if fx > 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - fx / dfx;
        if dfx < 0.0 && (newton - x).abs() <= ROOT_ULPS * f64::EPSILON * x {
            // Converged to rounding: `fx` is noise in the terms of `f`, below 1e-15 f(0).
            break;
        }
        x = if dfx < 0.0 && newton > lo && newton < hi {
            newton
        } else if hi.is_finite() {
            0.5 * (lo + hi)
        } else if lo == 0.0 {
            scale
        } else {
            4.0 * lo
        };
        (fx, dfx) = f(x);
        if hi.is_finite() && hi - lo <= ROOT_ULPS * f64::EPSILON * hi {
            break;
        }
    }
    (x, dfx)
}
