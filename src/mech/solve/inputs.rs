//! The checks of a step's inputs (group targets, hinge angles, load levels), each refusal
//! naming the bad item, and the prescribed value of a DOF under a group motion.

use crate::mech::elements::load::LoadLevels;
use crate::mech::model::Hinge;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::report::StepError;
use crate::mech::solve::state::GroupMotion;

impl Analysis {
    /// Refuses targets of the wrong length, non-finite or beyond
    /// [`Self::MAX_TARGET_PER_SIZE`] times the model's size.
    pub(super) fn check_targets(&self, target: &[[f64; 3]]) -> Result<(), StepError> {
        let invalid = |message| Err(StepError::InvalidInput { message });
        if target.len() != self.state.boundary.len() {
            return invalid(format!(
                "{} group targets given, the model has {}",
                target.len(),
                self.state.boundary.len()
            ));
        }
        let limit = Self::MAX_TARGET_PER_SIZE * self.length_scale;
        for (g, t) in target.iter().enumerate() {
            let name = &self.model.groups[g].name;
            if t.iter().any(|v| !v.is_finite()) {
                return invalid(format!(
                    "the target of group '{name}' {t:?} is NaN or infinite"
                ));
            }
            if let Some(v) = t.iter().find(|v| v.abs() > limit) {
                return invalid(format!(
                    "the target of group '{name}' ({v:e} m) is more than {} times the model's size ({:.4} m): \
                     refused before solving",
                    Self::MAX_TARGET_PER_SIZE,
                    self.length_scale
                ));
            }
        }
        Ok(())
    }

    /// Refuses angles of the wrong length, not finite, beyond [`Hinge::MAX_ANGLE`] or given to
    /// a group without a hinge.
    pub(super) fn check_angles(&self, angles: &[f64]) -> Result<(), StepError> {
        let invalid = |message| Err(StepError::InvalidInput { message });
        if angles.len() != self.model.groups.len() {
            return invalid(format!(
                "{} group angles given, the model has {} groups",
                angles.len(),
                self.model.groups.len()
            ));
        }
        for (g, &a) in self.model.groups.iter().zip(angles) {
            if !a.is_finite() || a.abs() > Hinge::MAX_ANGLE {
                return invalid(format!(
                    "the angle of group '{}' ({a} rad) is not finite or beyond two full turns",
                    g.name
                ));
            }
            if g.hinge.is_none() && a != 0.0 {
                return invalid(format!(
                    "group '{}' has no hinge and cannot turn ({a} rad asked)",
                    g.name
                ));
            }
        }
        Ok(())
    }

    /// The prescribed value of global DOF `i` (node `i / 3`, component `component`) of group
    /// `group` under `motion`: its translation plus the turn about its hinge.
    pub(super) fn prescribed_value(
        &self,
        i: usize,
        group: usize,
        component: usize,
        motion: &GroupMotion,
    ) -> f64 {
        let turn = self.model.groups[group].hinge.as_ref().map_or(0.0, |h| {
            h.displacement(self.model.nodes[i / 3], motion.angles[group])[component]
        });
        motion.translation[group][component] + turn
    }

    /// Refuses load targets of the wrong sizes or not finite.
    pub(super) fn check_loads(&self, loads: &LoadLevels) -> Result<(), StepError> {
        let invalid = |message| Err(StepError::InvalidInput { message });
        if !loads.fits(&self.model) {
            return invalid(format!(
                "{} pressures and {} nodal forces given, the model has {} pressure sets and {} force sets",
                loads.pressure.len(),
                loads.force.len(),
                self.model.loads.pressures.len(),
                self.model.loads.forces.len()
            ));
        }
        for (p, set) in loads.pressure.iter().zip(&self.model.loads.pressures) {
            if !p.is_finite() {
                return invalid(format!(
                    "the pressure of set '{}' ({p}) is NaN or infinite",
                    set.name
                ));
            }
        }
        for (f, set) in loads.force.iter().zip(&self.model.loads.forces) {
            if f.iter().any(|v| !v.is_finite()) {
                return invalid(format!(
                    "the force of set '{}' {f:?} is NaN or infinite",
                    set.name
                ));
            }
        }
        if loads.gravity.iter().any(|v| !v.is_finite()) {
            return invalid(format!("gravity {:?} is NaN or infinite", loads.gravity));
        }
        Ok(())
    }
}
