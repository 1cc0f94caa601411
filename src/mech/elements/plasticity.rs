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

use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Sub};

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::material::WrinklingState;

/// Most rows a hardening table may have (stored inline, so that a material stays `Copy`).
pub const MAX_HARDENING_ROWS: usize = 32;

/// A piecewise-linear isotropic hardening curve: rows of (equivalent plastic strain, flow stress in
/// Pa). The first row is initial yield at zero plastic strain; past the last row the last slope
/// continues (a single row is perfect plasticity).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Vec<[f64; 2]>", into = "Vec<[f64; 2]>")]
pub struct Hardening {
    table: [[f64; 2]; MAX_HARDENING_ROWS],
    len: usize,
}

/// Why a hardening table is refused; `row` is the 0-based index in the table.
#[derive(Clone, Debug, PartialEq)]
pub enum HardeningError {
    /// The table has no rows.
    Empty,
    /// The table has more than [`MAX_HARDENING_ROWS`] rows.
    TooLong {
        /// Rows given.
        rows: usize,
    },
    /// A value is NaN or infinite.
    NotFinite {
        /// Offending row.
        row: usize,
    },
    /// The first row's plastic strain is not 0.
    FirstStrainNotZero {
        /// The strain found.
        strain: f64,
    },
    /// Initial yield is not positive.
    YieldNotPositive {
        /// The stress found (Pa).
        stress: f64,
    },
    /// A row's plastic strain is not above the previous row's.
    StrainNotIncreasing {
        /// Offending row.
        row: usize,
        /// Its strain.
        strain: f64,
        /// The previous row's strain.
        previous: f64,
    },
    /// A row's flow stress is below the previous row's (softening is not supported).
    StressDecreasing {
        /// Offending row.
        row: usize,
        /// Its stress (Pa).
        stress: f64,
        /// The previous row's stress (Pa).
        previous: f64,
    },
}

impl fmt::Display for HardeningError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Empty => write!(
                f,
                "hardening: the table is empty; give at least the initial yield row [0.0, σy]"
            ),
            Self::TooLong { rows } => write!(
                f,
                "hardening: {rows} rows; at most {MAX_HARDENING_ROWS} are supported"
            ),
            Self::NotFinite { row } => write!(f, "hardening[{row}]: values must be finite"),
            Self::FirstStrainNotZero { strain } => write!(
                f,
                "hardening[0]: the first row is initial yield and must have plastic strain 0, not {strain}"
            ),
            Self::YieldNotPositive { stress } => write!(
                f,
                "hardening[0]: initial yield stress {stress} must be > 0 (Pa)"
            ),
            Self::StrainNotIncreasing {
                row,
                strain,
                previous,
            } => write!(
                f,
                "hardening[{row}]: plastic strain {strain} is not above the previous row's {previous} \
                 (rows must be in increasing plastic strain)"
            ),
            Self::StressDecreasing {
                row,
                stress,
                previous,
            } => write!(
                f,
                "hardening[{row}]: flow stress {stress} Pa is below the previous row's {previous} Pa \
                 (softening is not supported)"
            ),
        }
    }
}

impl std::error::Error for HardeningError {}

impl TryFrom<Vec<[f64; 2]>> for Hardening {
    type Error = HardeningError;
    fn try_from(rows: Vec<[f64; 2]>) -> Result<Self, Self::Error> {
        Self::new(rows)
    }
}

impl From<Hardening> for Vec<[f64; 2]> {
    fn from(h: Hardening) -> Self {
        h.rows().to_vec()
    }
}

impl Hardening {
    /// Validates and builds the table (errors name the bad row).
    pub fn new(rows: Vec<[f64; 2]>) -> Result<Self, HardeningError> {
        let first = rows.first().ok_or(HardeningError::Empty)?;
        if rows.len() > MAX_HARDENING_ROWS {
            return Err(HardeningError::TooLong { rows: rows.len() });
        }
        if let Some(row) = rows.iter().position(|r| !r.iter().all(|v| v.is_finite())) {
            return Err(HardeningError::NotFinite { row });
        }
        if first[0] != 0.0 {
            return Err(HardeningError::FirstStrainNotZero { strain: first[0] });
        }
        if first[1] <= 0.0 {
            return Err(HardeningError::YieldNotPositive { stress: first[1] });
        }
        for (row, pair) in rows.windows(2).enumerate() {
            let (previous, this) = (pair[0], pair[1]);
            if this[0] <= previous[0] {
                return Err(HardeningError::StrainNotIncreasing {
                    row: row + 1,
                    strain: this[0],
                    previous: previous[0],
                });
            }
            if this[1] < previous[1] {
                return Err(HardeningError::StressDecreasing {
                    row: row + 1,
                    stress: this[1],
                    previous: previous[1],
                });
            }
        }
        let mut table = [[0.0; 2]; MAX_HARDENING_ROWS];
        table[..rows.len()].copy_from_slice(&rows);
        Ok(Self {
            table,
            len: rows.len(),
        })
    }

    /// The rows (equivalent plastic strain, flow stress in Pa).
    pub fn rows(&self) -> &[[f64; 2]] {
        &self.table[..self.len]
    }

    /// Initial yield stress (Pa): the first row.
    pub fn initial_yield(&self) -> f64 {
        self.table[0][1]
    }

    /// Flow stress `σy(ε̄p)` (Pa) and slope `H = dσy/dε̄p` (right slope at a row).
    pub fn flow_stress(&self, plastic_strain: f64) -> (f64, f64) {
        let (start, slope) = self.segment(plastic_strain);
        (start[1] + slope * (plastic_strain - start[0]), slope)
    }

    /// The row a strain lies after and the slope of its segment.
    fn segment(&self, plastic_strain: f64) -> ([f64; 2], f64) {
        let rows = self.rows();
        let i = rows
            .iter()
            .rposition(|r| r[0] <= plastic_strain)
            .unwrap_or(0);
        let slope_of = |k: usize| (rows[k + 1][1] - rows[k][1]) / (rows[k + 1][0] - rows[k][0]);
        let slope = match rows.len() {
            1 => 0.0,
            n if i + 1 < n => slope_of(i),
            n => slope_of(n - 2),
        };
        (rows[i], slope)
    }

    /// The same curve with every flow stress multiplied by `factor` (> 0).
    pub fn scaled(&self, factor: f64) -> Self {
        let mut scaled = *self;
        scaled.table.iter_mut().for_each(|r| r[1] *= factor);
        scaled
    }

    /// `σy` at a (possibly dual) plastic strain, the segment chosen from its value.
    fn flow_stress_of<T: Real>(&self, plastic_strain: T) -> T {
        let (start, slope) = self.segment(plastic_strain.v());
        T::c(start[1]) + (plastic_strain - T::c(start[0])) * T::c(slope)
    }
}

/// Young's modulus of the ETFE data sheet the default curve is taken from (Pa).
pub const ETFE_DATASHEET_YOUNGS_MODULUS: f64 = 1100e6;

/// Nominal elongation at break of the same data sheet (450 %); its equivalent plastic strain
/// is [`etfe_datasheet_hardening`]'s last row, the documented rupture strain.
pub const ETFE_DATASHEET_ELONGATION_AT_BREAK: f64 = 4.5;

/// Equivalent plastic strain at which ETFE tears: the data sheet's elongation at break (450 %)
/// in uniaxial tension, `ln 5.5 − 275 MPa/1100 MPa` (the last row of
/// [`etfe_datasheet_hardening`]); a converged state past it is reported with a warning.
pub const ETFE_RUPTURE_PLASTIC_STRAIN: f64 = 1.454_748_092_238_425_3;

/// Default ETFE hardening at 23 °C from the only tensile numbers we could verify (the etferoof
/// data sheet: E = 1100 MPa, yield 21 MPa, tensile strength 50 MPa at 450 % elongation; sources
/// and what this leaves out in `docs/mechanics.md` § "Plastic film"): bilinear in true stress
/// against log plastic strain, from initial yield to the breaking point converted with
/// `τ = σ_nom (1 + ε_nom)`, `ε̄p = ln(1 + ε_nom) − τ/E`.
pub fn etfe_datasheet_hardening() -> Hardening {
    let (yield_stress, strength) = (21e6, 50e6);
    let stretch = 1.0 + ETFE_DATASHEET_ELONGATION_AT_BREAK;
    let tau = strength * stretch;
    let rupture = stretch.ln() - tau / ETFE_DATASHEET_YOUNGS_MODULUS;
    Hardening::new(vec![[0.0, yield_stress], [rupture, tau]]).expect("a valid table")
}

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

/// Anything the stress update runs on: `f64` and the dual numbers.
trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    fn c(x: f64) -> Self;
    fn v(self) -> f64;
    fn sqrt(self) -> Self;
    fn ln(self) -> Self;
    fn map(self, f: f64, df: f64) -> Self;
}

impl Real for f64 {
    fn c(x: f64) -> Self {
        x
    }
    fn v(self) -> f64 {
        self
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn ln(self) -> Self {
        f64::ln(self)
    }
    fn map(self, f: f64, _df: f64) -> Self {
        f
    }
}

/// A number with its gradient with respect to the three Green strains.
#[derive(Clone, Copy, Debug)]
struct Dual {
    v: f64,
    d: [f64; 3],
}

/// A number with one derivative (the return's scalar equations).
#[derive(Clone, Copy, Debug)]
struct Dual1 {
    v: f64,
    d: f64,
}

macro_rules! dual_ops {
    ($t:ty, $zip:expr, $scale:expr) => {
        #[allow(clippy::suspicious_arithmetic_impl)]
        impl Add for $t {
            type Output = Self;
            fn add(self, o: Self) -> Self {
                Self {
                    v: self.v + o.v,
                    d: $zip(self.d, o.d, 1.0, 1.0),
                }
            }
        }
        #[allow(clippy::suspicious_arithmetic_impl)]
        impl Sub for $t {
            type Output = Self;
            fn sub(self, o: Self) -> Self {
                Self {
                    v: self.v - o.v,
                    d: $zip(self.d, o.d, 1.0, -1.0),
                }
            }
        }
        #[allow(clippy::suspicious_arithmetic_impl)]
        impl Mul for $t {
            type Output = Self;
            fn mul(self, o: Self) -> Self {
                Self {
                    v: self.v * o.v,
                    d: $zip(self.d, o.d, o.v, self.v),
                }
            }
        }
        #[allow(clippy::suspicious_arithmetic_impl)]
        impl Div for $t {
            type Output = Self;
            fn div(self, o: Self) -> Self {
                let inv = 1.0 / o.v;
                Self {
                    v: self.v / o.v,
                    d: $zip(self.d, o.d, inv, -self.v * inv * inv),
                }
            }
        }
        impl Neg for $t {
            type Output = Self;
            fn neg(self) -> Self {
                Self {
                    v: -self.v,
                    d: $scale(self.d, -1.0),
                }
            }
        }
        impl Real for $t {
            fn c(x: f64) -> Self {
                Self {
                    v: x,
                    d: $scale(Default::default(), 0.0),
                }
            }
            fn v(self) -> f64 {
                self.v
            }
            fn sqrt(self) -> Self {
                let r = self.v.sqrt();
                self.map(r, 0.5 / r)
            }
            fn ln(self) -> Self {
                self.map(self.v.ln(), 1.0 / self.v)
            }
            fn map(self, f: f64, df: f64) -> Self {
                Self {
                    v: f,
                    d: $scale(self.d, df),
                }
            }
        }
    };
}

dual_ops!(
    Dual,
    |a: [f64; 3], b: [f64; 3], x: f64, y: f64| [
        a[0] * x + b[0] * y,
        a[1] * x + b[1] * y,
        a[2] * x + b[2] * y
    ],
    |a: [f64; 3], s: f64| [a[0] * s, a[1] * s, a[2] * s]
);
dual_ops!(
    Dual1,
    |a: f64, b: f64, x: f64, y: f64| a * x + b * y,
    |a: f64, s: f64| a * s
);

/// `x²`.
fn sq<T: Real>(x: T) -> T {
    x * x
}

/// `atanh(√w)/√w`, smooth in `w ∈ [0, 1)` (series near 0).
fn atanh_over<T: Real>(w: T) -> T {
    let wv = w.v();
    if wv < 1e-6 {
        T::c(1.0) + w * (T::c(1.0 / 3.0) + w * (T::c(0.2) + w * T::c(1.0 / 7.0)))
    } else {
        let z = wv.sqrt();
        let f = z.atanh() / z;
        // d/dw [atanh(z)/z] = (1/(1 − w) − atanh(z)/z) / (2w).
        w.map(f, (1.0 / (1.0 - wv) - f) / (2.0 * wv))
    }
}

/// A symmetric 2×2 tensor.
#[derive(Clone, Copy, Debug)]
struct Sym2<T> {
    xx: T,
    yy: T,
    xy: T,
}

impl<T: Real> Add for Sym2<T> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            xx: self.xx + o.xx,
            yy: self.yy + o.yy,
            xy: self.xy + o.xy,
        }
    }
}

impl<T: Real> Sym2<T> {
    fn identity(s: T) -> Self {
        Self {
            xx: s,
            yy: s,
            xy: T::c(0.0),
        }
    }
    fn mean(&self) -> T {
        (self.xx + self.yy) * T::c(0.5)
    }
    fn dev(&self) -> Self {
        let m = self.mean();
        Self {
            xx: self.xx - m,
            yy: self.yy - m,
            xy: self.xy,
        }
    }
    fn scale(&self, s: f64) -> Self {
        self.scale_t(T::c(s))
    }
    fn scale_t(&self, s: T) -> Self {
        Self {
            xx: self.xx * s,
            yy: self.yy * s,
            xy: self.xy * s,
        }
    }
    fn sub(&self, o: Self) -> Self {
        Self {
            xx: self.xx - o.xx,
            yy: self.yy - o.yy,
            xy: self.xy - o.xy,
        }
    }
    fn frob2(&self) -> T {
        self.xx * self.xx + self.yy * self.yy + self.xy * self.xy * T::c(2.0)
    }
    fn value(&self) -> Sym2<f64> {
        Sym2 {
            xx: self.xx.v(),
            yy: self.yy.v(),
            xy: self.xy.v(),
        }
    }
    /// `M A Mᵀ` for a plain 2×2 `M`.
    fn congruence(&self, m: &[[f64; 2]; 2]) -> Self {
        let a = [[self.xx, self.xy], [self.xy, self.yy]];
        let entry = |i: usize, j: usize| {
            let mut s = T::c(0.0);
            for (k, ak) in a.iter().enumerate() {
                for (l, akl) in ak.iter().enumerate() {
                    s = s + *akl * T::c(m[i][k] * m[j][l]);
                }
            }
            s
        };
        Self {
            xx: entry(0, 0),
            yy: entry(1, 1),
            xy: entry(0, 1),
        }
    }
    /// `A B` of two commuting symmetric tensors (symmetric; off-diagonal averaged).
    fn commuting_product(&self, b: &Self) -> Self {
        Self {
            xx: self.xx * b.xx + self.xy * b.xy,
            yy: self.xy * b.xy + self.yy * b.yy,
            xy: (self.xx * b.xy + self.xy * b.yy + self.xy * b.xx + self.yy * b.xy) * T::c(0.5),
        }
    }
}

/// `exp A` of a symmetric 2×2: `e^m (cosh ρ I + sinh ρ/ρ dev A)`, `ρ² = −det(dev A)`.
fn exp_sym(a: Sym2<f64>) -> Sym2<f64> {
    let (m, dev) = (a.mean(), a.dev());
    let rho2 = dev.xx * dev.xx + dev.xy * dev.xy;
    let (cosh, sinhc) = if rho2 < 1e-8 {
        (
            1.0 + rho2 / 2.0 + rho2 * rho2 / 24.0,
            1.0 + rho2 / 6.0 + rho2 * rho2 / 120.0,
        )
    } else {
        let rho = rho2.sqrt();
        (rho.cosh(), rho.sinh() / rho)
    };
    Sym2::identity(m.exp() * cosh) + dev.scale(m.exp() * sinhc)
}

#[cfg(test)]
mod tests {
    use super::*;

    const E: f64 = 1.0e9;
    const NU: f64 = 0.43;

    /// The issue's example table.
    fn table() -> Hardening {
        Hardening::new(vec![[0.0, 16e6], [0.02, 19e6], [0.15, 24e6], [1.0, 40e6]]).unwrap()
    }

    fn film(tension_field: bool) -> PlasticFilm {
        PlasticFilm {
            youngs_modulus: E,
            poisson_ratio: NU,
            hardening: table(),
            tension_field,
        }
    }

    fn virgin() -> PlasticHistory {
        film(false).initial_history([0.0; 3])
    }

    /// Green strain (Voigt) of the in-plane stretch `U = R diag(l1, l2) Rᵀ`, `R` by `angle`.
    fn green(l1: f64, l2: f64, angle: f64) -> Vector3<f64> {
        let (s, c) = angle.sin_cos();
        let (a, b) = (0.5 * (l1 * l1 - 1.0), 0.5 * (l2 * l2 - 1.0));
        Vector3::new(
            a * c * c + b * s * s,
            a * s * s + b * c * c,
            2.0 * (a - b) * s * c,
        )
    }

    /// The plastic strain `x` on the table at which `x·k + σy(x)·f = target` (a monotone
    /// relation between log strain and plastic strain), segment by segment from the rows.
    fn plastic_strain_where(k: f64, f: f64, target: f64) -> f64 {
        let rows = table().rows().to_vec();
        for i in 0..rows.len() {
            let slope = if i + 1 < rows.len() {
                (rows[i + 1][1] - rows[i][1]) / (rows[i + 1][0] - rows[i][0])
            } else {
                (rows[i][1] - rows[i - 1][1]) / (rows[i][0] - rows[i - 1][0])
            };
            // x k + f (σ_i + slope (x − x_i)) = target
            let x = (target - f * (rows[i][1] - slope * rows[i][0])) / (k + f * slope);
            let end = rows.get(i + 1).map_or(f64::INFINITY, |r| r[0]);
            if x >= rows[i][0] && x <= end {
                return x;
            }
        }
        unreachable!()
    }

    fn table_stress(x: f64) -> f64 {
        let rows = table().rows().to_vec();
        let i = rows
            .iter()
            .rposition(|r| r[0] <= x)
            .unwrap()
            .min(rows.len() - 2);
        rows[i][1]
            + (rows[i + 1][1] - rows[i][1]) / (rows[i + 1][0] - rows[i][0]) * (x - rows[i][0])
    }

    /// Central-difference `∂S/∂E`, or `None` if a perturbation changes the state or crosses a
    /// row of the table.
    fn fd_tangent(
        f: &PlasticFilm,
        h: &PlasticHistory,
        strain: &Vector3<f64>,
    ) -> Option<Matrix3<f64>> {
        let base = f.response(h, strain);
        let segment =
            |r: &PlasticResponse| table().segment(r.history.equivalent_plastic_strain).0[0];
        let step = 1e-7;
        let mut t = Matrix3::zeros();
        for j in 0..3 {
            let (mut p, mut m) = (*strain, *strain);
            p[j] += step;
            m[j] -= step;
            let (rp, rm) = (f.response(h, &p), f.response(h, &m));
            for r in [&rp, &rm] {
                if r.state != base.state
                    || r.yielding != base.yielding
                    || segment(r) != segment(&base)
                {
                    return None;
                }
            }
            t.set_column(j, &((rp.stress - rm.stress) / (2.0 * step)));
        }
        Some(t)
    }

    /// The history left by straining a virgin film to `strain` in one increment.
    fn yielded(f: &PlasticFilm, strain: Vector3<f64>) -> PlasticHistory {
        let r = f.response(&virgin(), &strain);
        assert!(r.yielding);
        r.history
    }

    fn assert_tangent(
        f: &PlasticFilm,
        h: &PlasticHistory,
        strain: Vector3<f64>,
        state: WrinklingState,
        yielding: bool,
    ) {
        let (r, tangent) = f.response_and_tangent(h, &strain);
        assert_eq!((r.state, r.yielding), (state, yielding), "at {strain:?}");
        assert_eq!(
            r,
            f.response(h, &strain),
            "plain and dual evaluations agree"
        );
        let fd = fd_tangent(f, h, &strain).expect("state stable under the perturbation");
        let err = (fd - tangent).amax();
        assert!(
            err < 1e-6 * E,
            "{state:?} yielding {yielding} at {strain:?}: error {err:e}\n{tangent}\n{fd}"
        );
    }

    #[test]
    fn algorithmic_tangent_matches_finite_differences_in_every_state() {
        use WrinklingState::*;
        let (j2, tf) = (film(false), film(true));
        let v = virgin();
        let loaded = Vector3::new(0.1, -0.03, 0.02);
        let h = yielded(&j2, loaded);
        // Elastic from virgin (also at exactly zero strain: equal principal stretches).
        assert_tangent(&j2, &v, Vector3::new(0.005, 0.002, 0.001), Taut, false);
        assert_tangent(&j2, &v, Vector3::zeros(), Taut, false);
        // Plastic loading, from virgin and from a yielded history; equibiaxial (degenerate).
        assert_tangent(&j2, &v, loaded, Taut, true);
        assert_tangent(&j2, &h, Vector3::new(0.13, -0.02, 0.05), Taut, true);
        assert_tangent(&j2, &h, green(1.2, 1.2, 0.0), Taut, true);
        // Elastic unloading of a yielded point, and compression past zero.
        assert_tangent(&j2, &h, Vector3::new(0.09, -0.03, 0.02), Taut, false);
        assert_tangent(&j2, &h, Vector3::new(0.08, -0.035, 0.018), Taut, false);
        // Tension field: wrinkled (elastic, plastic, unloading a yielded point), taut plastic,
        // slack with a yielded history.
        let w = Vector3::new(0.2, -0.1, 0.03);
        let hw = tf.response(&v, &w).history;
        assert_tangent(&tf, &v, Vector3::new(0.005, -0.01, 0.002), Wrinkled, false);
        assert_tangent(&tf, &v, w, Wrinkled, true);
        assert_tangent(&tf, &hw, Vector3::new(0.18, -0.1, 0.03), Wrinkled, false);
        assert_tangent(&tf, &hw, Vector3::new(0.25, -0.12, 0.05), Wrinkled, true);
        assert_tangent(&tf, &v, Vector3::new(0.1, 0.08, 0.01), Taut, true);
        assert_tangent(&tf, &hw, Vector3::new(0.05, -0.1, 0.0), Slack, false);
        assert!(hw.equivalent_plastic_strain > 0.05);
    }

    #[test]
    fn algorithmic_tangent_matches_finite_differences_at_spread_points() {
        // Deterministic spread of histories and strains, both films, with prestress.
        let spread =
            |k: usize| ((k as f64 * 12.9898).sin() * 43758.5453).rem_euclid(1.0) * 2.0 - 1.0;
        let mut k = 0;
        let mut next = || {
            k += 1;
            spread(k)
        };
        let mut seen = std::collections::HashSet::new();
        for _ in 0..400 {
            let f = film(next() > 0.0);
            let prestress = [2e6 * next(), 2e6 * next(), 1e6 * next()];
            let start = f.initial_history(prestress);
            let pre = Vector3::new(0.15 * next(), 0.15 * next(), 0.15 * next());
            let h = if next() > -0.3 {
                f.response(&start, &pre).history
            } else {
                start
            };
            let strain = pre + Vector3::new(0.05 * next(), 0.05 * next(), 0.05 * next());
            let (r, tangent) = f.response_and_tangent(&h, &strain);
            let Some(fd) = fd_tangent(&f, &h, &strain) else {
                continue;
            };
            let err = (fd - tangent).amax();
            assert!(
                err < 1e-6 * E,
                "{:?} {} at {strain:?} from {h:?}: {err:e}",
                r.state,
                r.yielding
            );
            seen.insert((
                f.tension_field,
                r.state as usize,
                r.yielding,
                h.equivalent_plastic_strain > 0.0,
            ));
        }
        assert!(seen.len() >= 8, "state combinations covered: {seen:?}");
    }

    #[test]
    fn algorithmic_tangent_is_symmetric() {
        let (j2, tf) = (film(false), film(true));
        let h = yielded(&j2, Vector3::new(0.1, -0.03, 0.02));
        for (f, strain) in [
            (&j2, Vector3::new(0.13, -0.02, 0.05)),
            (&tf, Vector3::new(0.2, -0.1, 0.03)),
        ] {
            let t = f.response_and_tangent(&h, &strain).1;
            assert!((t - t.transpose()).amax() < 1e-9 * t.amax(), "{t}");
        }
    }

    /// Drives `stretch(λ) → (l1, l2)` (with `l2 = None`: the lateral stretch free, solved for
    /// `S_yy = 0` with the tangent) through the log strains `path`, committing each increment.
    /// Returns, per point, `(λ1, l2, nominal stress P1 = λ1 S_xx, t/t0, ε̄p)`.
    fn drive(
        f: &PlasticFilm,
        path: &[f64],
        lateral: impl Fn(f64) -> Option<f64>,
        angle: f64,
    ) -> Vec<[f64; 5]> {
        let mut point = PlasticPoint::new(virgin());
        let mut l2 = 1.0;
        let mut out = vec![];
        for &eps in path {
            let l1 = eps.exp();
            let mut r;
            match lateral(l1) {
                Some(l) => {
                    l2 = l;
                    r = f.response(&point.committed, &green(l1, l2, angle));
                }
                None => loop {
                    let (resp, t) = f.response_and_tangent(&point.committed, &green(l1, l2, 0.0));
                    r = resp;
                    if resp.stress.y.abs() < 1e-9 * f.hardening.initial_yield() {
                        break;
                    }
                    // dE_yy = l2 dl2
                    l2 -= resp.stress.y / (t[(1, 1)] * l2);
                },
            }
            point.trial = r.history;
            point.commit();
            // Principal S along the stretch axes.
            let (s, c) = angle.sin_cos();
            let s1 = r.stress.x * c * c + r.stress.y * s * s + 2.0 * r.stress.z * s * c;
            out.push([
                l1,
                l2,
                l1 * s1,
                r.thickness_ratio,
                point.committed.equivalent_plastic_strain,
            ]);
        }
        out
    }

    fn up_and_down(peak: f64, end: f64, n: usize) -> Vec<f64> {
        let up = (1..=n).map(|i| peak * i as f64 / n as f64);
        let down = (1..=n).map(|i| peak + (end - peak) * i as f64 / n as f64);
        up.chain(down).collect()
    }

    /// Asserts that a proportional path up to `path[59]` and back (60 increments each way)
    /// followed the closed form `ln λ = a ε̄p + b σy(ε̄p)`, `τ = c σy` (elastic: `σeq = ln λ/b`,
    /// unloading: `σeq = (ln λ − a ε̄p,max)/b`), nominal stress `τ/λ`, thickness `t(τ, ε̄p)`, and
    /// ended at zero stress. Returns `ε̄p,max`.
    fn assert_follows_table(
        path: &[f64],
        points: &[[f64; 5]],
        [a, b, c]: [f64; 3],
        thickness: impl Fn(f64, f64) -> f64,
    ) -> f64 {
        let ep_max = plastic_strain_where(a, b, path[59]);
        for (i, (eps, p)) in path.iter().zip(points).enumerate() {
            let (seq, ep) = if i >= 60 {
                ((eps - a * ep_max) / b, ep_max)
            } else if *eps <= b * 16e6 {
                (eps / b, 0.0)
            } else {
                let ep = plastic_strain_where(a, b, *eps);
                (table_stress(ep), ep)
            };
            let tau = c * seq;
            let nominal = tau / p[0];
            assert!(
                (p[2] - nominal).abs() < 1e-6 * tau.abs().max(1e6),
                "ε {eps}: P {} vs {nominal}",
                p[2]
            );
            assert!((p[4] - ep).abs() < 1e-9, "ε {eps}: ε̄p {} vs {ep}", p[4]);
            let t = thickness(tau, ep);
            assert!((p[3] - t).abs() < 1e-6 * t, "ε {eps}: t/t0 {} vs {t}", p[3]);
        }
        let last = points.last().unwrap();
        assert!(last[2].abs() < 1e-6 * 16e6, "residual stress {}", last[2]);
        ep_max
    }

    #[test]
    fn uniaxial_strip_to_30_percent_and_back_follows_the_hardening_table() {
        // ln λ = σy(ε̄p)/E + ε̄p, P = τ/λ, t/t0 = exp(−ν τ/E − ε̄p/2); unloading is elastic from
        // the peak's ε̄p, zero force at ln λ = ε̄p (the residual strain).
        let (peak, ep_max) = (0.3, plastic_strain_where(1.0, 1.0 / E, 0.3));
        let path = up_and_down(peak, ep_max, 60);
        let thickness = |tau: f64, ep: f64| (-NU * tau / E - ep / 2.0).exp();
        for tension_field in [false, true] {
            // With the tension field the strip is held at 0.8 across: it wrinkles and is a bar.
            let lateral = |_: f64| if tension_field { Some(0.8) } else { None };
            let points = drive(&film(tension_field), &path, lateral, 0.0);
            assert_follows_table(&path, &points, [1.0, 1.0 / E, 1.0], thickness);
            if !tension_field {
                // The width contracts like the thickness.
                for p in &points {
                    assert!(
                        (p[1] - p[3]).abs() < 1e-6,
                        "width {} vs thickness {}",
                        p[1],
                        p[3]
                    );
                }
            }
        }
    }

    #[test]
    fn equibiaxial_stretch_to_30_percent_and_back_follows_the_hardening_table() {
        // τ1 = τ2 = τ, von Mises τ; ln λ = (1 − ν) τ/E + ε̄p/2, t/t0 = exp(−2ντ/E − ε̄p);
        // zero stress again at ln λ = ε̄p/2. Axes at 0.3 rad to the element frame.
        let k = (1.0 - NU) / E;
        let ep_max = plastic_strain_where(0.5, k, 0.3);
        let path = up_and_down(0.3, ep_max / 2.0, 60);
        let points = drive(&film(false), &path, Some, 0.3);
        let thickness = |tau: f64, ep: f64| (-2.0 * NU * tau / E - ep).exp();
        assert_follows_table(&path, &points, [0.5, k, 1.0], thickness);
    }

    #[test]
    fn pure_shear_to_30_percent_and_back_follows_the_hardening_table() {
        // Stretches (λ, 1/λ) on axes at 0.5 rad: τ1 = −τ2 = τ, von Mises √3 τ, no thickness
        // change; ln λ = τ/(2G) + (√3/2) ε̄p with √3 τ = σy(ε̄p); zero stress at ln λ = (√3/2) ε̄p.
        let (g2, r3) = (E / (1.0 + NU), 3f64.sqrt());
        let case = [r3 / 2.0, 1.0 / (r3 * g2), 1.0 / r3];
        let ep_max = plastic_strain_where(case[0], case[1], 0.3);
        let path = up_and_down(0.3, ep_max * r3 / 2.0, 60);
        let points = drive(&film(false), &path, |l| Some(1.0 / l), 0.5);
        assert_follows_table(&path, &points, case, |_, _| 1.0);
    }

    #[test]
    fn hardening_table_errors_name_the_bad_row() {
        let err = |rows: Vec<[f64; 2]>| Hardening::new(rows).unwrap_err().to_string();
        assert!(err(vec![]).contains("empty"));
        assert!(err(vec![[0.0, 16e6]; 33]).contains("33 rows; at most 32"));
        assert!(err(vec![[0.01, 16e6]]).starts_with("hardening[0]:"));
        assert!(err(vec![[0.0, 0.0]]).starts_with("hardening[0]: initial yield"));
        assert!(err(vec![[0.0, 16e6], [0.02, f64::NAN]]).starts_with("hardening[1]:"));
        // Two rows swapped: the strain goes back.
        let swapped = vec![[0.0, 16e6], [0.15, 24e6], [0.02, 19e6], [1.0, 40e6]];
        assert!(err(swapped).starts_with("hardening[2]: plastic strain 0.02 is not above"));
        let softening = vec![[0.0, 16e6], [0.02, 19e6], [0.15, 18e6]];
        assert!(err(softening).starts_with("hardening[2]: flow stress"));
        let from_json = |text: &str| serde_json::from_str::<Plasticity>(text);
        let e = from_json(r#"{"hardening": [[0.0, 16e6], [0.0, 19e6]]}"#).unwrap_err();
        assert!(
            e.to_string()
                .contains("hardening[1]: plastic strain 0 is not above"),
            "{e}"
        );
        let e = from_json(r#"{"hardening": [[0.0, 16e6]], "kinematic": 1}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `kinematic`"), "{e}");
        let ok = from_json(r#"{"hardening": [[0.0, 16e6], [0.02, 19e6]]}"#).unwrap();
        assert_eq!(ok.hardening.rows(), &[[0.0, 16e6], [0.02, 19e6]]);
        assert_eq!(table().flow_stress(0.01), (17.5e6, 150e6));
        assert_eq!(table().flow_stress(2.0).0, 40e6 + 16e6 / 0.85 * 1.0);
    }

    #[test]
    fn prestress_is_the_stress_of_the_undeformed_film() {
        for tension_field in [false, true] {
            let f = film(tension_field);
            let s0 = [3e6, 1e6, 0.5e6];
            let r = f.response(&f.initial_history(s0), &Vector3::zeros());
            assert!(
                (r.stress - Vector3::from(s0)).amax() < 1e-9 * 3e6,
                "{:?}",
                r.stress
            );
            assert!((r.thickness_ratio - 1.0).abs() < 1e-15);
            assert!(!r.yielding);
        }
    }

    #[test]
    fn trial_history_is_kept_until_committed_and_restores_exactly() {
        let f = film(false);
        let mut point = PlasticPoint::new(virgin());
        // An iterate that yields changes only the trial history.
        point.trial = f
            .response(&point.committed, &Vector3::new(0.1, -0.03, 0.02))
            .history;
        assert_eq!(point.committed, virgin());
        assert!(point.trial.equivalent_plastic_strain > 0.0);
        point.restore();
        assert_eq!(point, PlasticPoint::new(virgin()));
        // Elastic and slack increments leave the history as it was, bit for bit.
        let h = yielded(&f, Vector3::new(0.1, -0.03, 0.02));
        assert_eq!(f.response(&h, &Vector3::new(0.09, -0.03, 0.02)).history, h);
        assert_eq!(
            film(true)
                .response(&h, &Vector3::new(0.0, -0.1, 0.0))
                .history,
            h
        );
        let mut point = PlasticPoint::new(h);
        point.trial = f.response(&h, &Vector3::new(0.2, -0.03, 0.02)).history;
        point.commit();
        assert_eq!(point.committed, point.trial);
        assert!(point.committed.equivalent_plastic_strain > h.equivalent_plastic_strain);
    }

    #[test]
    fn datasheet_curve_gives_the_datasheet_strip_back() {
        // A uniaxial strip of the default film: nominal stress = yield at first yield, and the
        // data sheet's tensile strength at its elongation at break (closed form ln λ = τ/E + ε̄p).
        let h = etfe_datasheet_hardening();
        let e = ETFE_DATASHEET_YOUNGS_MODULUS;
        let [_, [ep_break, tau_break]] = [h.rows()[0], h.rows()[1]];
        let stretch = (tau_break / e + ep_break).exp();
        assert!((stretch - 5.5).abs() < 1e-12);
        assert!((tau_break / stretch - 50e6).abs() < 1e-6);
        assert_eq!(h.initial_yield(), 21e6);
        assert!((ep_break - ETFE_RUPTURE_PLASTIC_STRAIN).abs() < 1e-15);
    }
}
