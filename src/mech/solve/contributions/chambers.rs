//! The gas chambers as a contribution (issue 43; [`crate::mech::elements::chamber`]): the
//! pressure's nodal forces `p ∂V/∂x`, the load stiffness `−p ∂²V/∂u²` into the sparse matrix,
//! and the pneumatic stiffness `−(dp/dV) g gᵀ` of each sealed chamber kept aside as a rank-one
//! term, which the Newton correction adds by the Sherman–Morrison–Woodbury identity
//! (`solve/low_rank.rs`), never as a dense row.

use nalgebra::{DMatrix, Vector3};
use serde::{Deserialize, Serialize};

use super::{Contribution, Evaluation};
use crate::mech::elements::chamber::AIR_GAS_CONSTANT;
use crate::mech::elements::chamber::{ChamberGeometry, GasLaw, tet_gradient, tet_hessian};
use crate::mech::elements::orifice::{OrificeEnd, implicit_transfer, transfer_sensitivity};
use crate::mech::model::Model;
use crate::mech::results::Results;
use crate::mech::solve::assembly::{Dof, node_dofs};
use crate::mech::solve::state::AnalysisState;

/// The gas of one chamber in a converged state (serialized with FMU states).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChamberState {
    /// Whether the gas is enclosed (else a supply holds the load level's pressure).
    pub sealed: bool,
    /// `C = (p + p_a) V^κ` of the enclosed gas at the chamber's reference temperature
    /// (Pa m^{3κ}; 0 while supplied).
    pub constant: f64,
    /// Gauge pressure (Pa) at convergence.
    pub pressure: f64,
    /// Volume (m³) at convergence.
    pub volume: f64,
    /// The air's temperature (K) at convergence (0 in a state written before it was kept).
    #[serde(default)]
    pub temperature: f64,
    /// The supplied-air level ([`crate::mech::LoadLevels::air`], kg) that [`Self::constant`]
    /// already holds: air supplied beyond it is added to the gas at the next evaluation (0 in
    /// a state written before it was kept).
    #[serde(default)]
    pub supplied: f64,
}

/// One chamber's result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChamberResult {
    /// The chamber's name.
    pub name: String,
    /// Gauge pressure (Pa).
    pub pressure: f64,
    /// Enclosed volume (m³).
    pub volume: f64,
    /// Whether the gas is enclosed.
    pub sealed: bool,
    /// The air's temperature (K).
    pub temperature: f64,
    /// The air's mass (kg, ideal gas).
    pub mass: f64,
}

/// One orifice's result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OrificeResult {
    /// The orifice's name.
    pub name: String,
    /// Mass flow (kg/s) from its `from` chamber to its `to` over the last increment.
    pub mass_flow: f64,
    /// Air (kg) passed from `from` to `to` since the analysis started.
    #[serde(default)]
    pub moved: f64,
}

/// The chambers' pneumatic stiffness `G A Gᵀ`, added to the Newton matrix by the
/// Sherman–Morrison–Woodbury identity (`solve/low_rank.rs`), never as dense rows.
#[derive(Clone, Debug, Default)]
pub struct LowRank {
    /// `g = ∂V/∂u` of each sealed chamber over the free equations: the columns of `G`.
    pub columns: Vec<Vec<f64>>,
    /// `A_ij = −∂p_i/∂V_j` between those chambers: diagonal (`−dp/dV` at a fixed air mass)
    /// without orifices; an orifice couples its two chambers, not symmetrically.
    pub matrix: DMatrix<f64>,
}

/// An orifice between two chambers: their indices and `C_d A` (m²).
#[derive(Clone, Debug)]
struct Orifice {
    name: String,
    from: usize,
    to: usize,
    cda: f64,
}

/// The chambers of a model with their state at the start of the increment and at the last
/// evaluation.
#[derive(Clone, Debug, Default)]
pub struct Chambers {
    geometry: Vec<ChamberGeometry>,
    laws: Vec<GasLaw>,
    names: Vec<String>,
    reference: Vec<Vector3<f64>>,
    /// The gas at the increment's start.
    start: Vec<ChamberState>,
    /// Pressure and volume at the last evaluation.
    last: Vec<ChamberState>,
    /// The pneumatic stiffness at the last evaluation with a matrix.
    low_rank: LowRank,
    orifices: Vec<Orifice>,
    /// The analysis time (s) at the increment's start.
    start_time: f64,
    /// Each orifice's mass flow (kg/s) over the increment at the last evaluation.
    flows: Vec<f64>,
    /// Each orifice's moved air (kg) over the increment at the last evaluation.
    moved: Vec<f64>,
    /// `∂p_i/∂V_j` of the chambers at the last evaluation (Pa/m³), the orifices' transfers
    /// included: zero rows for supplied chambers.
    slopes: DMatrix<f64>,
}

impl Chambers {
    /// The chambers of a validated `model`.
    pub fn new(model: &Model) -> Self {
        Self {
            geometry: model
                .chambers
                .iter()
                .map(|c| ChamberGeometry::new(model, c).expect("validated chamber"))
                .collect(),
            laws: model
                .chambers
                .iter()
                .map(|c| GasLaw {
                    kappa: c.kappa,
                    atmosphere: c.atmosphere,
                    temperature: c.temperature,
                })
                .collect(),
            names: model.chambers.iter().map(|c| c.name.clone()).collect(),
            orifices: model
                .orifices
                .iter()
                .map(|o| {
                    let index = |name: &str| {
                        let k = model.chambers.iter().position(|c| c.name == name);
                        k.expect("validated orifice")
                    };
                    Orifice {
                        name: o.name.clone(),
                        from: index(&o.from),
                        to: index(&o.to),
                        cda: o.discharge_coefficient * o.area,
                    }
                })
                .collect(),
            reference: model.nodes.iter().map(|&p| Vector3::from(p)).collect(),
            ..Self::default()
        }
    }

    /// The gas of each chamber in the reference geometry: sealed ones enclosed at their
    /// `pressure`, the others supplied.
    pub fn initial_states(&self, model: &Model) -> Vec<ChamberState> {
        model
            .chambers
            .iter()
            .zip(&self.geometry)
            .zip(&self.laws)
            .map(|((c, g), law)| {
                let volume = g.volume(&self.reference);
                ChamberState {
                    sealed: c.sealed,
                    constant: if c.sealed {
                        law.constant(c.pressure, volume, c.temperature)
                    } else {
                        0.0
                    },
                    pressure: if c.sealed { c.pressure } else { 0.0 },
                    volume,
                    temperature: c.temperature,
                    supplied: 0.0,
                }
            })
            .collect()
    }

    /// Chamber `k`'s air `c` enclosed at its converged pressure and volume (the inflation
    /// unit's valve closes; unchanged if enclosed already); Err where it encloses no volume.
    pub fn enclosed(&self, k: usize, c: &ChamberState) -> Result<ChamberState, String> {
        if c.sealed {
            return Ok(*c);
        }
        if !(c.volume > 0.0) {
            return Err(format!(
                "chamber '{}' encloses no volume ({:e} m³): it cannot be sealed",
                self.names[k], c.volume
            ));
        }
        Ok(ChamberState {
            sealed: true,
            constant: self.laws[k].constant(c.pressure, c.volume, c.temperature),
            ..*c
        })
    }

    /// Whether the model has a sealed chamber now (a pneumatic stiffness to add).
    pub fn any_sealed(&self) -> bool {
        self.start.iter().any(|c| c.sealed)
    }

    /// The pneumatic stiffness `G A Gᵀ` of the last evaluation with a matrix (to add to it).
    pub fn low_rank(&self) -> &LowRank {
        &self.low_rank
    }

    /// Each chamber's gas at the evaluation `at` with the current `volumes`, before the
    /// orifices: the start's gas with the air supplied since, at the heated temperature.
    fn gas_at(&self, at: &Evaluation<'_>, volumes: &[f64]) -> Vec<ChamberState> {
        (0..self.geometry.len())
            .map(|k| {
                // Before any restore (a first evaluation) the air is the reference's, supplied.
                let gas = self.start.get(k).copied().unwrap_or_default();
                let law = &self.laws[k];
                let t = law.temperature + at.levels.heating.get(k).copied().unwrap_or(0.0);
                let supplied = at.levels.air.get(k).copied().unwrap_or(0.0);
                let constant = if gas.sealed {
                    law.with_air(gas.constant, supplied - gas.supplied, gas.volume)
                } else {
                    gas.constant
                };
                let pressure = if gas.sealed {
                    law.pressure(constant, volumes[k], t)
                } else {
                    at.levels.chambers.get(k).copied().unwrap_or(0.0)
                };
                ChamberState {
                    constant,
                    pressure,
                    volume: volumes[k],
                    temperature: t,
                    supplied,
                    ..gas
                }
            })
            .collect()
    }

    /// Chamber `k`'s end of an orifice in [`Self::last`]'s gas.
    fn end(&self, k: usize) -> OrificeEnd {
        let c = &self.last[k];
        OrificeEnd {
            law: self.laws[k],
            constant: c.constant,
            volume: c.volume,
            temperature: c.temperature,
            held: (!c.sealed).then_some(c.pressure),
        }
    }

    /// Moves the air each orifice passes over `dt` seconds between the gas of [`Self::last`]
    /// (backward Euler, [`implicit_transfer`]; one orifice after the other where several share
    /// a chamber), keeps their flows and `∂p_i/∂V_j` ([`Self::slopes`]). A supplied chamber
    /// keeps its pressure (its supply makes good what passes); two supplies pass nothing.
    ///
    /// The slopes follow each chamber's constant `C_i` through the transfers, `dC_i/dV_j`:
    /// with `m` kg added, `C' = C + m R T₀ V^{κ−1}` and `p = C' (T/T₀)/V^κ − p_a`, so at a fixed
    /// `m` `dp = p_C (dC + m R T₀ (κ−1) V^{κ−2} dV) + (∂p/∂V)_{C'} dV`, `p_C = (T/T₀)/V^κ`, and
    /// `dm` follows those by [`transfer_sensitivity`].
    fn exchange(&mut self, dt: f64) {
        let n = self.last.len();
        let mut dc = DMatrix::<f64>::zeros(n, n);
        self.flows.clear();
        self.moved.clear();
        for o in &self.orifices {
            let (from, to) = (self.end(o.from), self.end(o.to));
            if from.held.is_some() && to.held.is_some() {
                self.flows.push(0.0);
                self.moved.push(0.0);
                continue;
            }
            let m = implicit_transfer(o.cda, &from, &to, dt);
            let (sf, st) = transfer_sensitivity(&from, &to, m, dt);
            // `dC'` at a fixed moved mass (with `−m` at `from`, `m` at `to`) and `dp` from it.
            let fixed = |k: usize, end: &OrificeEnd, dc: &DMatrix<f64>, mass: f64| {
                let (law, v) = (&end.law, end.volume);
                let mut row = dc.row(k).clone_owned();
                row[k] += mass
                    * AIR_GAS_CONSTANT
                    * law.temperature
                    * (law.kappa - 1.0)
                    * v.powf(law.kappa - 2.0);
                let c = law.with_air(end.constant, mass, v);
                let p_c = (end.temperature / law.temperature) / v.powf(law.kappa);
                let mut dp = &row * p_c;
                dp[k] += law.slope(c, v, end.temperature);
                (row, dp)
            };
            let (row_f, dp_f) = fixed(o.from, &from, &dc, -m);
            let (row_t, dp_t) = fixed(o.to, &to, &dc, m);
            let dm = if from.held.is_some() {
                dp_t * st
            } else if to.held.is_some() {
                dp_f * sf
            } else {
                dp_f * sf + dp_t * st
            };
            for (k, end, row, sign) in [(o.from, from, row_f, -1.0), (o.to, to, row_t, 1.0)] {
                if end.held.is_some() {
                    continue;
                }
                let law = &end.law;
                let per_kg = AIR_GAS_CONSTANT * law.temperature * end.volume.powf(law.kappa - 1.0);
                dc.set_row(k, &(row + &dm * (sign * per_kg)));
                let c = &mut self.last[k];
                c.constant = law.with_air(end.constant, sign * m, end.volume);
                c.pressure = end.pressure_with(sign * m);
            }
            self.flows.push(if dt > 0.0 { m / dt } else { 0.0 });
            self.moved.push(m);
        }
        self.slopes = DMatrix::from_fn(n, n, |i, j| {
            let (c, law) = (&self.last[i], &self.laws[i]);
            if !c.sealed {
                return 0.0;
            }
            let p_c = (c.temperature / law.temperature) / c.volume.powf(law.kappa);
            let own = if i == j {
                law.slope(c.constant, c.volume, c.temperature)
            } else {
                0.0
            };
            p_c * dc[(i, j)] + own
        });
    }

    /// Each chamber's volume (m³) at the displacements `u`.
    fn volumes(&self, u: &[f64]) -> Vec<f64> {
        let x: Vec<Vector3<f64>> = self
            .reference
            .iter()
            .enumerate()
            .map(|(v, p)| p + Vector3::new(u[3 * v], u[3 * v + 1], u[3 * v + 2]))
            .collect();
        self.geometry.iter().map(|g| g.volume(&x)).collect()
    }
}

impl Contribution for Chambers {
    fn restore(&mut self, start: &AnalysisState) {
        self.start.clone_from(&start.chambers);
        self.start_time = start.loads.time;
    }

    fn at_converged(&mut self, state: &AnalysisState) {
        self.start.clone_from(&state.chambers);
        self.start_time = state.loads.time;
    }

    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], mut values: Option<&mut [f64]>) {
        if self.geometry.is_empty() {
            return;
        }
        let volumes = self.volumes(at.u);
        self.last = self.gas_at(at, &volumes);
        self.exchange(at.levels.time - self.start_time);
        let mut columns = Vec::with_capacity(self.geometry.len());
        let system = at.system;
        for (k, g) in self.geometry.iter().enumerate() {
            let (gas, p) = (self.last[k], self.last[k].pressure);
            // `g` over the free equations, for the rank-one term: only where a matrix is asked.
            let mut gradient =
                (gas.sealed && values.is_some()).then(|| vec![0.0; system.free_count]);
            for (e, sign, nodes) in g.oriented() {
                let x = nodes.map(|n| {
                    self.reference[n] + Vector3::new(at.u[3 * n], at.u[3 * n + 1], at.u[3 * n + 2])
                });
                let ge = tet_gradient(&g.origin, &x) * sign;
                for (i, d) in node_dofs(&nodes).into_iter().enumerate() {
                    residual[d] -= p * ge[i];
                    if let (Some(grad), Dof::Free(eq)) = (gradient.as_mut(), &system.dofs[d]) {
                        grad[*eq] += ge[i];
                    }
                }
                if let Some(values) = values.as_deref_mut() {
                    let h = tet_hessian(&g.origin, &x) * (-p * sign);
                    system.add_element_matrix(e, &h, values);
                }
            }
            columns.push(gradient);
        }
        let sealed: Vec<usize> = (0..columns.len())
            .filter(|&k| columns[k].is_some())
            .collect();
        self.low_rank = LowRank {
            matrix: DMatrix::from_fn(sealed.len(), sealed.len(), |i, j| {
                -self.slopes[(sealed[i], sealed[j])]
            }),
            columns: columns.into_iter().flatten().collect(),
        };
    }

    fn commit(&self, start: &AnalysisState, state: &mut AnalysisState) {
        if !self.geometry.is_empty() {
            state.chambers.clone_from(&self.last);
            state.orifices.clone_from(&self.flows);
            state.orifice_moved = (0..self.moved.len())
                .map(|k| start.orifice_moved.get(k).copied().unwrap_or(0.0) + self.moved[k])
                .collect();
        }
    }

    fn results(
        &self,
        _at: &Evaluation<'_>,
        state: &AnalysisState,
        _model: &Model,
        out: &mut Results,
    ) {
        out.chambers = state
            .chambers
            .iter()
            .zip(&self.names)
            .zip(&self.laws)
            .map(|((c, name), law)| ChamberResult {
                name: name.clone(),
                pressure: c.pressure,
                volume: c.volume,
                sealed: c.sealed,
                temperature: c.temperature,
                mass: law.mass(c.pressure, c.volume, c.temperature),
            })
            .collect();
        out.orifices = self
            .orifices
            .iter()
            .enumerate()
            .map(|(k, o)| OrificeResult {
                name: o.name.clone(),
                mass_flow: state.orifices.get(k).copied().unwrap_or(0.0),
                moved: state.orifice_moved.get(k).copied().unwrap_or(0.0),
            })
            .collect();
    }
}
