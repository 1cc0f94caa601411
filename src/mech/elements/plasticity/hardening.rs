//! The hardening table of the plastic film (`material.plasticity.hardening`): piecewise-linear
//! isotropic hardening, validated row by row, and the default ETFE curve with its sources.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::numbers::Real;

/// Most rows a hardening table may have (stored inline, so that a material stays `Copy`).
pub const MAX_HARDENING_ROWS: usize = 32;

/// A piecewise-linear isotropic hardening curve: rows of (equivalent plastic strain, flow stress in
/// Pa). The first row is initial yield at zero plastic strain; past the last row the last slope
/// continues (a single row is perfect plasticity).
///
/// In a model file it is the table of rows or the name of a known curve
/// ([`NAMED_HARDENING`], e.g. `"etfe-23C"`); a curve read by name is written back by name.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(into = "serde_json::Value")]
pub struct Hardening {
    table: [[f64; 2]; MAX_HARDENING_ROWS],
    len: usize,
    /// The name it was given by ([`NAMED_HARDENING`]); none for a table.
    name: Option<&'static str>,
}

/// The hardening curves a model file may name instead of giving the table: name, what it is,
/// the curve.
pub const NAMED_HARDENING: [(&str, &str, fn() -> Hardening); 1] = [(
    "etfe-23C",
    "ETFE's data-sheet curve at 23 °C, etfe_datasheet_hardening: [[0, 21e6], [1.4547, 275e6]]",
    etfe_datasheet_hardening,
)];

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

impl TryFrom<serde_json::Value> for Hardening {
    type Error = String;
    /// A table of rows, or the name of a known curve (the error names the known ones).
    fn try_from(value: serde_json::Value) -> Result<Self, String> {
        if let serde_json::Value::String(name) = &value {
            return Self::named(name);
        }
        let rows: Vec<[f64; 2]> = serde_json::from_value(value).map_err(|e| {
            format!(
                "hardening: {e}; give a table [[ε̄p, σ in Pa], …] or a name ({})",
                known_names()
            )
        })?;
        Self::new(rows).map_err(|e| e.to_string())
    }
}

impl<'de> Deserialize<'de> for Hardening {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let value = serde_json::Value::deserialize(d)?;
        Self::try_from(value).map_err(serde::de::Error::custom)
    }
}

impl From<Hardening> for serde_json::Value {
    fn from(h: Hardening) -> Self {
        match h.name {
            Some(name) => serde_json::Value::from(name),
            None => serde_json::json!(h.rows()),
        }
    }
}

/// The names of [`NAMED_HARDENING`] with what each is, for messages.
fn known_names() -> String {
    NAMED_HARDENING
        .iter()
        .map(|(name, what, _)| format!("\"{name}\": {what}"))
        .collect::<Vec<_>>()
        .join("; ")
}

impl Hardening {
    /// The known curve called `name` ([`NAMED_HARDENING`]); the error names the known ones.
    pub fn named(name: &str) -> Result<Self, String> {
        let (known, _, curve) = NAMED_HARDENING
            .iter()
            .find(|(known, _, _)| *known == name)
            .ok_or_else(|| {
                format!(
                    "hardening: unknown curve \"{name}\"; the known names are {}",
                    known_names()
                )
            })?;
        Ok(Self {
            name: Some(known),
            ..curve()
        })
    }

    /// The name the curve was given by, if it was read by name.
    pub fn name(&self) -> Option<&'static str> {
        self.name
    }

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
            name: None,
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
    pub(super) fn segment(&self, plastic_strain: f64) -> ([f64; 2], f64) {
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

    /// The same curve with every flow stress multiplied by `factor` (> 0); no longer the named
    /// curve.
    pub fn scaled(&self, factor: f64) -> Self {
        let mut scaled = *self;
        scaled.name = None;
        scaled.table.iter_mut().for_each(|r| r[1] *= factor);
        scaled
    }

    /// `σy` at a (possibly dual) plastic strain, the segment chosen from its value.
    pub(super) fn flow_stress_of<T: Real>(&self, plastic_strain: T) -> T {
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
