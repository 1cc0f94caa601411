//! The contract of everything that adds force and stiffness to the system, and the list of
//! them in assembly order. The Newton loop, the line search and the results see only
//! [`Contribution`]s: they never match on kinds.
//!
//! A contribution adds its residual `f_int − f_ext` and, when asked, its part of the Newton
//! matrix through the system's precomputed slots ([`System::add_element_matrix`]). Its history
//! (a gap's slip, a curved contact's anchor; a plastic material's internal variables) follows
//! the trial/commit/restore cycle of an increment:
//!
//! * [`Contribution::restore`]: the trial history is reset to the converged state `start` at
//!   the start of every increment, so a cut-back or an enlarged retry starts from the same
//!   history, and a restored FMU state continues from its own;
//! * [`Contribution::add`]: evaluated (and trial history updated) at each iterate;
//! * [`Contribution::commit`]: written into the next converged [`AnalysisState`] only when
//!   the increment converges (a failed increment commits nothing).
//!
//! A material with history variables plugs in here: its per-element history goes into
//! [`AnalysisState`] (serialized with FMU states), [`Triangles`] reads it in `restore`, updates
//! a trial copy in `add` and writes it in `commit`; the loop stays as it is.
//!
//! The order of [`Contributions::all_mut`] is the order of the floating-point sums into the
//! residual and the matrix: triangles, gaps, loads, cables, curved contacts, and last the
//! viscous stabilization (off unless a step needs it; it sizes itself from the others' matrix).
//!
//! | file | what |
//! |---|---|
//! | `triangles` | the membrane triangles (and the film's stresses in the results) |
//! | `gaps` | the friction gaps: trial laws and slip history, Ju–Rowlands latching |
//! | `loads` | external loads and edge cables |
//! | `curved` | node-to-surface contacts on curved supports |
//! | `stabilization` | the viscous stabilization of a step whose equilibrium is not unique |

mod chambers;
mod curved;
mod gaps;
mod loads;
mod stabilization;
mod triangles;

pub use chambers::{ChamberResult, ChamberState, Chambers};
pub use curved::CurvedContacts;
pub use gaps::Gaps;
pub use stabilization::ViscousStabilization;
pub use triangles::Triangles;

use crate::mech::elements::cable::Cables;
use crate::mech::elements::gap::{GapStatus, IterationMatrix};
use crate::mech::elements::load::{LoadLevels, Loads};
use crate::mech::model::Model;
use crate::mech::results::Results;
use crate::mech::solve::assembly::System;
use crate::mech::solve::state::AnalysisState;

/// Where a contribution is evaluated.
#[derive(Clone, Copy, Debug)]
pub struct Evaluation<'a> {
    /// The discretized system (DOF map, slots, triangles).
    pub system: &'a System,
    /// Displacements, three per node (m).
    pub u: &'a [f64],
    /// Load levels.
    pub levels: &'a LoadLevels,
    /// The Newton iteration this evaluation serves (`None`: the residual alone, for results).
    pub iteration: Option<usize>,
    /// Which matrix drives the iterations.
    pub matrix: IterationMatrix,
}

/// Something that adds force and stiffness: see the module doc for its history cycle.
pub trait Contribution {
    /// Resets the trial history to the converged `start` (start of an increment or a retry).
    fn restore(&mut self, _start: &AnalysisState) {}

    /// Adds the residual at `at` into `residual` (all DOFs) and, when `values` is given, the
    /// Newton matrix entries into it (the system's value array).
    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>);

    /// Writes the trial history of a converged iterate into `state` (`start`: the increment's).
    fn commit(&self, _start: &AnalysisState, _state: &mut AnalysisState) {}

    /// Prepares an evaluation at the converged `state` for [`Contribution::results`].
    fn at_converged(&mut self, _state: &AnalysisState) {}

    /// Appends the contact statuses at the last evaluation (the line search's watchdog keeps a
    /// full step only while they stay).
    fn statuses(&self, _out: &mut Vec<GapStatus>) {}

    /// Notes the statuses at Newton iteration `iteration` (to name items that keep switching).
    fn note_iteration(&mut self, _iteration: usize) {}

    /// Appends the names of items whose status changed at an iteration `≥ since` (and > 0).
    fn chattering(&self, _since: usize, _out: &mut Vec<String>) {}

    /// Appends the elements whose state differs between displacements `a` and `b` (called
    /// once when an increment fails).
    fn flipping(&self, _system: &System, _a: &[f64], _b: &[f64], _out: &mut Vec<usize>) {}

    /// Appends the film elements in compression (`σ2 < 0`) at `u` where the film law carries
    /// compression (`wrinkling: "none"`; called once when an increment fails).
    fn compressed(&self, _system: &System, _u: &[f64], _out: &mut Vec<usize>) {}

    /// Appends the names of the contacts that lift off with a force the law gives no bound
    /// ([`LiftOff`]; called once when an increment fails).
    fn lifting_off(&self, _out: &mut Vec<String>) {}

    /// Marks, in an increment's converged start `start`, the contacts in `names` that lift off
    /// ([`LiftOff`]) as lifting off there and landing again within the increment, holding
    /// nothing across until it converges; appends the largest cross force each was seen holding
    /// in the increment's last attempt (N). Contacts already marked are left.
    fn release_lift_off(
        &mut self,
        _names: &[String],
        _start: &mut AnalysisState,
        _out: &mut Vec<f64>,
    ) {
    }

    /// Corrects the first iterate `u` of an increment predicted from the converged `start`
    /// (`increments.rs`) where the prediction leaves the item's constraint (a closed contact
    /// pushed into its support).
    fn correct_prediction(&self, _system: &System, _start: &AnalysisState, _u: &mut [f64]) {}

    /// Fills its part of `out` at the converged `state` (after an evaluation at it).
    fn results(
        &self,
        _at: &Evaluation<'_>,
        _state: &AnalysisState,
        _model: &Model,
        _out: &mut Results,
    ) {
    }
}

/// The status of each item (gap, contact) at the previous Newton iteration and the last
/// iteration it changed: to name the items that keep switching when an increment stalls.
#[derive(Clone, Debug, Default)]
pub struct StatusChanges {
    previous: Vec<GapStatus>,
    changed_at: Vec<Option<usize>>,
}

impl StatusChanges {
    /// Starts an increment from the converged statuses `start`.
    pub fn reset(&mut self, start: impl Iterator<Item = GapStatus>) {
        self.previous.clear();
        self.previous.extend(start);
        self.changed_at.clear();
        self.changed_at.resize(self.previous.len(), None);
    }

    /// Notes the statuses `now` at Newton iteration `iteration`.
    pub fn note(&mut self, iteration: usize, now: impl Iterator<Item = GapStatus>) {
        for ((p, c), s) in self.previous.iter_mut().zip(&mut self.changed_at).zip(now) {
            if s != *p {
                *p = s;
                *c = Some(iteration);
            }
        }
    }

    /// Appends the `names` of the items that changed at an iteration `≥ since` (and > 0).
    pub fn changed_since(&self, since: usize, names: &[String], out: &mut Vec<String>) {
        out.extend(
            self.changed_at
                .iter()
                .zip(names)
                .filter(|(c, _)| c.is_some_and(|c| c > 0 && c >= since))
                .map(|(_, n)| n.clone()),
        );
    }
}

/// The contacts of the paper's `sliding-direction` friction law that lift off while holding
/// the film across the support with more than `μN`, over one increment's evaluations (line
/// search trials included): to name them when the increment fails.
///
/// The law (§2.2, [`crate::mech::elements::gap`]) keeps the cross direction elastic with `k_s`
/// however little the contact presses, so the cross force does not go to zero with the normal
/// force: where the contact opens, a force of `k_s` times the cross drift since it closed
/// vanishes at once. Newton cannot resolve that jump (measured on the held-out set,
/// `benches/heldout.rs`: the same paths with the isotropic cone, whose friction vanishes with
/// the normal force, converge; docs/benchmarks.md).
#[derive(Clone, Debug, Default)]
pub struct LiftOff {
    /// Per contact: seen open, seen closed holding more than `μN` across.
    seen: Vec<(bool, bool)>,
    /// Per contact: the largest cross force seen while closed beyond `μN` (N).
    hold: Vec<f64>,
}

impl LiftOff {
    /// Starts an increment for `count` contacts.
    pub fn reset(&mut self, count: usize) {
        self.seen.clear();
        self.seen.resize(count, (false, false));
        self.hold.clear();
        self.hold.resize(count, 0.0);
    }

    /// Notes contact `k` at an evaluation: open, or closed with the cross force `cross` (N)
    /// against the Coulomb limit `limit = μN` (N).
    pub fn note(&mut self, k: usize, open: bool, cross: f64, limit: f64) {
        if let Some(s) = self.seen.get_mut(k) {
            if open {
                s.0 = true;
            } else if cross.abs() > limit {
                s.1 = true;
                self.hold[k] = self.hold[k].max(cross.abs());
            }
        }
    }

    /// The largest cross force contact `k` was seen holding beyond `μN` in this attempt (N).
    pub fn hold(&self, k: usize) -> f64 {
        self.hold.get(k).copied().unwrap_or(0.0)
    }

    /// Appends the `names` of the contacts seen both open and closed beyond the limit.
    pub fn lifted(&self, names: &[String], out: &mut Vec<String>) {
        out.extend(
            self.seen
                .iter()
                .zip(names)
                .filter(|(s, _)| s.0 && s.1)
                .map(|(_, n)| n.clone()),
        );
    }
}

/// Every contribution of an analysis.
#[derive(Clone, Debug)]
pub struct Contributions {
    /// Membrane triangles.
    pub triangles: Triangles,
    /// Friction gaps.
    pub gaps: Gaps,
    /// External loads.
    pub loads: Loads,
    /// Tension-only edge cables.
    pub cables: Cables,
    /// Node-to-surface contacts on curved supports.
    pub curved: CurvedContacts,
    /// Gas chambers.
    pub chambers: Chambers,
    /// The viscous stabilization of the current step (off unless a step turns it on).
    pub stabilization: ViscousStabilization,
}

impl Contributions {
    /// The contributions of `model` on `system` (`diagonal`: each free equation's diagonal slot;
    /// `mass`: its pseudo-mass, `continuation::pseudo_mass`).
    pub fn new(model: &Model, system: &System, diagonal: Vec<usize>, mass: Vec<f64>) -> Self {
        Self {
            triangles: Triangles::default(),
            gaps: Gaps::new(model),
            loads: Loads::new(model, system),
            cables: Cables::new(model),
            curved: CurvedContacts::new(model),
            chambers: Chambers::new(model),
            stabilization: ViscousStabilization::new(diagonal, mass),
        }
    }

    /// All of them, in assembly order (the order of the floating-point sums).
    pub fn all_mut(&mut self) -> [&mut dyn Contribution; 7] {
        [
            &mut self.triangles,
            &mut self.gaps,
            &mut self.loads,
            &mut self.cables,
            &mut self.curved,
            &mut self.chambers,
            &mut self.stabilization,
        ]
    }

    /// All of them, in assembly order.
    pub fn all(&self) -> [&dyn Contribution; 7] {
        [
            &self.triangles,
            &self.gaps,
            &self.loads,
            &self.cables,
            &self.curved,
            &self.chambers,
            &self.stabilization,
        ]
    }

    /// Zeroes `residual` (and `values`) and adds every contribution at `at`.
    pub fn assemble(
        &mut self,
        at: &Evaluation<'_>,
        residual: &mut [f64],
        mut values: Option<&mut [f64]>,
    ) {
        residual.fill(0.0);
        if let Some(v) = values.as_deref_mut() {
            v.fill(0.0);
        }
        for c in self.all_mut() {
            c.add(at, residual, values.as_deref_mut());
        }
    }

    /// The contact statuses at the last evaluation, of every contribution in order.
    pub fn statuses(&self) -> Vec<GapStatus> {
        let mut out = Vec::new();
        for c in self.all() {
            c.statuses(&mut out);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::elements::gap::{FrictionLaw, GapLaw};
    use crate::mech::solve::Analysis;
    use crate::mech::solve::settings::SolverSettings;
    use crate::specimens::ParallelArch;
    use crate::specimens::parallel_arch::SpecimenContact;

    /// The 300 mm specimen with `contact` and friction `law`, lowered a quarter of the way.
    fn lowered_specimen(contact: SpecimenContact, law: FrictionLaw) -> Analysis {
        let spec = ParallelArch {
            contact,
            friction_law: law,
            ..ParallelArch::default()
        };
        let model = spec.model().unwrap();
        let targets = spec.boundary_targets(&model, 0.6);
        let mut analysis = Analysis::new(model, SolverSettings::default()).unwrap();
        analysis.step_to(&targets, 5).unwrap();
        analysis
    }

    /// The contacts named as lifting off with more than `μN` across (`LiftOff`) after
    /// evaluating, from the 300 mm specimen lowered a quarter of the way, the film dragged
    /// 10 µm across the arch (closed, the cross force `k_s` × 10 µm above `μN`) and then
    /// `lift` m up.
    fn lifted_after_a_drag(contact: SpecimenContact, law: FrictionLaw, lift: f64) -> Vec<String> {
        let mut analysis = lowered_specimen(contact, law);
        let converged = analysis.state().clone();
        let Analysis { system, parts, .. } = &mut analysis;
        let mut residual = vec![0.0; converged.displacement.len()];
        let moved = |dx: f64, dz: f64| -> Vec<f64> {
            let u = &converged.displacement;
            (0..u.len())
                .map(|i| match i % 3 {
                    0 => u[i] + dx,
                    2 => u[i] + dz,
                    _ => u[i],
                })
                .collect()
        };
        for c in parts.all_mut() {
            c.restore(&converged);
        }
        for u in [moved(1e-5, 0.0), moved(1e-5, lift)] {
            let at = Evaluation {
                system,
                u: &u,
                levels: &converged.loads,
                iteration: Some(1),
                matrix: IterationMatrix::Consistent,
            };
            parts.assemble(&at, &mut residual, None);
        }
        let mut names = Vec::new();
        for c in parts.all() {
            c.lifting_off(&mut names);
        }
        names
    }

    /// Contacts released at lift-off (`Contribution::release_lift_off`, gaps and curved
    /// contacts alike) hold nothing across while the increment is solved, and the converged
    /// state they commit carries no mark and holds from where it ended: re-evaluated there,
    /// still nothing across. Unreleased, the same drag holds more than `μN` across.
    #[test]
    fn released_contacts_hold_nothing_across_and_commit_where_they_landed() {
        for contact in [SpecimenContact::Gaps, SpecimenContact::CurvedSupport] {
            let mut analysis = lowered_specimen(contact, FrictionLaw::SlidingDirection);
            let converged = analysis.state().clone();
            let Analysis { system, parts, .. } = &mut analysis;
            let mut residual = vec![0.0; converged.displacement.len()];
            let dragged: Vec<f64> = (converged.displacement.iter().enumerate())
                .map(|(i, u)| if i % 3 == 0 { u + 1e-5 } else { *u })
                .collect();
            let at = Evaluation {
                system,
                u: &dragged,
                levels: &converged.loads,
                iteration: Some(1),
                matrix: IterationMatrix::Consistent,
            };
            // The cross force of every closed sliding-direction contact at `dragged`.
            let across = |parts: &Contributions, state: &AnalysisState| -> Vec<f64> {
                match contact {
                    SpecimenContact::Gaps => (0..state.plastic_slip.len())
                        .map(|g| {
                            let d = system.gap_relative(g, &dragged);
                            let law = GapLaw {
                                friction: state.friction[g],
                                ..parts.gaps.laws()[g]
                            };
                            let r = if state.landing.contains(&g) {
                                law.evaluate_landing(d, state.plastic_slip[g].into())
                            } else {
                                law.evaluate(d, state.plastic_slip[g].into())
                            };
                            r.force.y
                        })
                        .collect(),
                    SpecimenContact::CurvedSupport => parts
                        .curved
                        .contacts
                        .respond(&dragged, &state.contacts)
                        .iter()
                        .map(|r| r.friction.y)
                        .collect(),
                }
            };
            let held = across(parts, &converged);
            assert!(
                held.iter().any(|f| f.abs() > 1.0),
                "{contact:?}: nothing held across"
            );
            let names: Vec<String> = match contact {
                SpecimenContact::Gaps => model_names(parts, false),
                SpecimenContact::CurvedSupport => model_names(parts, true),
            };
            let mut start = converged.clone();
            let mut released = Vec::new();
            for c in parts.all_mut() {
                c.release_lift_off(&names, &mut start, &mut released);
            }
            assert_eq!(released.len(), names.len(), "{contact:?}");
            assert!(
                across(parts, &start).iter().all(|f| *f == 0.0),
                "{contact:?}"
            );
            for c in parts.all_mut() {
                c.restore(&start);
            }
            parts.assemble(&at, &mut residual, None);
            let mut committed = start.clone();
            for c in parts.all() {
                c.commit(&start, &mut committed);
            }
            assert!(committed.landing.is_empty(), "{contact:?}");
            assert!(committed.contacts.iter().all(|h| !h.lands), "{contact:?}");
            let after = across(parts, &committed);
            assert!(
                after.iter().all(|f| f.abs() < 1e-9),
                "{contact:?}: {after:?}"
            );
        }
    }

    /// The names of every gap (`curved` false) or curved-support contact.
    fn model_names(parts: &Contributions, curved: bool) -> Vec<String> {
        if curved {
            parts.curved.names.clone()
        } else {
            parts.gaps.names.clone()
        }
    }

    /// The paper's sliding-direction law holds the film across the arch with more than `μN`;
    /// a contact that then opens is named, for gaps and curved-support contacts alike. The
    /// isotropic cone never holds more than `μN`, and a contact that stays closed is not named.
    #[test]
    fn a_contact_lifting_off_with_more_than_its_friction_limit_across_is_named() {
        use FrictionLaw::{Isotropic, SlidingDirection};
        for contact in [SpecimenContact::Gaps, SpecimenContact::CurvedSupport] {
            let named = lifted_after_a_drag(contact, SlidingDirection, 0.05);
            assert!(!named.is_empty(), "{contact:?}: none named");
            assert!(
                lifted_after_a_drag(contact, Isotropic, 0.05).is_empty(),
                "{contact:?}: the cone named {named:?}"
            );
            assert!(
                lifted_after_a_drag(contact, SlidingDirection, 0.0).is_empty(),
                "{contact:?}: named without lifting off"
            );
        }
    }
}
