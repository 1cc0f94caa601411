//! The inflation unit as the shared glue (`fmu/glue`) sees it: a [`ScalarModel`] whose
//! instance core ([`Scalar`]) and FMI 2.0 and 3.0 C layers ([`fmi_glue::export_fmi2!`],
//! [`fmi_glue::export_fmi3!`]) are the glue's, as for the jack (`fmu/jack`). The phases, the
//! checks of value references, the refused step that keeps the last state, the FMU states (and
//! their bytes, [`ScalarModel::to_numbers`]) and the log are the glue's.

use fmi_glue::scalar::{Scalar, ScalarModel};

use crate::{DESCRIPTION, Unit, check_value};

impl ScalarModel for Unit {
    fmi_glue::scalar_values!(DESCRIPTION, check_value);

    fn initialize(&mut self) -> Result<(), String> {
        Unit::initialize(self)
    }

    fn step(&mut self, h: f64) -> Result<(), String> {
        Unit::step(self, h)
    }

    /// None: the unit provides no directional derivatives (its switch is discontinuous; the
    /// description says `providesDirectionalDerivative="false"`).
    fn derivative(&self, _unknown: u32, _known: u32) -> Option<f64> {
        None
    }

    fn to_numbers(&self) -> Option<Vec<f64>> {
        Some(Unit::to_numbers(self))
    }

    fn from_numbers(numbers: &[f64]) -> Result<Self, String> {
        Unit::from_numbers(numbers)
    }
}

/// The inflation unit's FMU instance: the glue's core over [`Unit`].
pub type Instance = Scalar<Unit>;

fmi_glue::export_fmi2!(Instance);
fmi_glue::export_fmi3!(Instance);
