//! External loads and edge cables as contributions: both add through [`ExternalLoad`] and
//! carry no history.

use super::{Contribution, Evaluation};
use crate::mech::elements::cable::Cables;
use crate::mech::elements::load::{ExternalLoad, Loads};
use crate::mech::model::Model;
use crate::mech::results::Results;
use crate::mech::solve::state::AnalysisState;

impl Contribution for Loads {
    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>) {
        self.add_to(at.system, at.levels, at.u, residual, values);
    }
}

impl Contribution for Cables {
    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>) {
        self.add_to(at.system, at.levels, at.u, residual, values);
    }

    fn results(
        &self,
        at: &Evaluation<'_>,
        _state: &AnalysisState,
        _model: &Model,
        out: &mut Results,
    ) {
        out.cables = Cables::results(self, at.u);
    }
}
