//! The stress update as first written (issue 20), kept as the oracle of the fast one: the whole
//! update, tensors included, runs on dual numbers in the three Green strains, so its tangent is
//! the derivative of the update by construction. `tests.rs` checks that the closed-form
//! assembly of `mod.rs` gives the same stress, history and tangent to rounding in every state.

use std::ops::Add;

use nalgebra::{Matrix3, Vector3};

use super::numbers::*;
use super::*;

impl PlasticFilm {
    /// Stress and updated history at the Green strain `strain` (Voigt `[Exx, Eyy, 2Exy]`),
    /// starting from `history`.
    pub(super) fn dual_response(
        &self,
        history: &PlasticHistory,
        strain: &Vector3<f64>,
    ) -> PlasticResponse {
        let c = Sym2 {
            xx: 1.0 + 2.0 * strain.x,
            yy: 1.0 + 2.0 * strain.y,
            xy: strain.z,
        };
        let update = self.dual_update(history, c);
        update.response(|s| s)
    }

    /// [`PlasticFilm::dual_response`] and the consistent algorithmic tangent `∂S/∂E` (3×3, Voigt,
    /// engineering shear in `E`).
    pub(super) fn dual_response_and_tangent(
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
        let update = self.dual_update(history, c);
        let s = update.stress;
        let tangent = Matrix3::from_fn(|i, j| [s.xx, s.yy, s.xy][i].d[j]);
        (update.response(|x: Dual| x.v), tangent)
    }

    /// The stress update of the module doc, generic over plain and dual numbers.
    fn dual_update<T: Real>(&self, history: &PlasticHistory, c: Sym2<T>) -> Update<T> {
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
        let (m_tau, dev_tau, dgamma) =
            if let Some(dg) = taut_return(hardening, ebar, g2, ep_n, m_trial, d2_trial) {
                let m = m_trial / (T::c(1.0) + dg * T::c(ebar / 3.0));
                let dev = dev_trial.scale_t(T::c(1.0) / (T::c(1.0) + dg * T::c(g2)));
                (m, dev, Some(dg))
            } else {
                (m_trial, dev_trial, None)
            };
        let rho_tau = dev_tau.frob2().v().sqrt() / 2f64.sqrt();
        let minor = m_tau.v() - rho_tau;
        if self.tension_field && minor < -1e-12 * (m_tau.v().abs() + rho_tau) {
            return self.dual_wrinkled(history, q, &y, mean_tr, dev_tr);
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
    fn dual_wrinkled<T: Real>(
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
        let (tau1, dl) = bar_return(hardening, e, ep_n, tau_trial);
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

/// Result of [`PlasticFilm::dual_update`] in the number type `T`.
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
