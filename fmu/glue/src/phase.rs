//! The co-simulation state machine's vocabulary: the phases an instance can be in, which call is
//! allowed in which phase (one [`Mask`] per function, in [`allowed`]), and how a call fails
//! ([`Failure`]). Shared by every FMU of the project: the transitions themselves are the
//! instance's (the film's `src/fmi2/lifecycle.rs`, [`crate::scalar`] for the jack); the C layer
//! ([`crate::fmi2`], the film's `guard.rs`) checks the mask on entry to every call.
//!
//! # State machine (FMI 2.0 §4.2.4)
//!
//! ```text
//! Instantiate → Instantiated ─SetupExperiment, EnterInitializationMode→ Initialization
//!   ─ExitInitializationMode (builds the Analysis)→ StepComplete ─DoStep ok→ StepComplete
//!                                                    │  └DoStep Discard→ StepFailed
//!   Terminate (StepComplete | StepFailed) → Terminated;  Reset (any) → Instantiated
//!   a panic inside any call → Fatal (only fmi2FreeInstance is left)
//! ```
//! [`allowed`] holds one mask per function. Deviations from the standard's table, both so that
//! a master can retry a step the FMU refused:
//! * in `StepFailed` (after `fmi2Discard`), inputs may be set and `fmi2DoStep` called again from
//!   the same time: the instance kept its last converged state and time;
//! * a call that fails with `fmi2Error` (bad argument, unknown value reference, wrong state,
//!   invalid parameters at `fmi2ExitInitializationMode`) has no effect and leaves the instance
//!   in its state, instead of making it unusable.

use serde::{Deserialize, Serialize};

use crate::status::Status;

/// Why a call failed: the status to return and the message to log.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub status: Status,
    pub message: String,
}

impl Failure {
    pub fn error(message: impl Into<String>) -> Self {
        Self {
            status: Status::Error,
            message: message.into(),
        }
    }

    pub fn discard(message: impl Into<String>) -> Self {
        Self {
            status: Status::Discard,
            message: message.into(),
        }
    }

    /// The call did its work, but something on the side failed (the VTK output): logged under
    /// `logStatusWarning`, `fmi2Warning` returned, the instance's new state stands.
    pub fn warning(message: impl Into<String>) -> Self {
        Self {
            status: Status::Warning,
            message: message.into(),
        }
    }
}

/// The result of an instance method.
pub type Outcome<T = ()> = Result<T, Failure>;

/// The states of the co-simulation state machine this FMU can be in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Phase {
    Instantiated,
    Initialization,
    StepComplete,
    StepFailed,
    Terminated,
    /// A call panicked: only `fmi2FreeInstance` is left.
    Fatal,
}

impl Phase {
    const fn bit(self) -> u8 {
        1 << self as u8
    }
}

/// A set of phases.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mask(u8);

impl Mask {
    const fn of(phases: &[Phase]) -> Self {
        let mut bits = 0;
        let mut i = 0;
        while i < phases.len() {
            bits |= phases[i].bit();
            i += 1;
        }
        Self(bits)
    }

    pub fn allows(self, phase: Phase) -> bool {
        self.0 & phase.bit() != 0
    }
}

/// In which phases each function may be called.
pub mod allowed {
    use super::Mask;
    use super::Phase::*;

    pub const SET_DEBUG_LOGGING: Mask = Mask::of(&[
        Instantiated,
        Initialization,
        StepComplete,
        StepFailed,
        Terminated,
    ]);
    pub const SETUP_EXPERIMENT: Mask = Mask::of(&[Instantiated]);
    pub const ENTER_INITIALIZATION: Mask = Mask::of(&[Instantiated]);
    pub const EXIT_INITIALIZATION: Mask = Mask::of(&[Initialization]);
    pub const TERMINATE: Mask = Mask::of(&[StepComplete, StepFailed]);
    pub const RESET: Mask = Mask::of(&[
        Instantiated,
        Initialization,
        StepComplete,
        StepFailed,
        Terminated,
    ]);
    pub const GET: Mask = Mask::of(&[Initialization, StepComplete, StepFailed, Terminated]);
    /// StepFailed: deviation, so that a refused step can be retried with other inputs.
    pub const SET: Mask = Mask::of(&[Instantiated, Initialization, StepComplete, StepFailed]);
    pub const FMU_STATE: Mask = Mask::of(&[
        Instantiated,
        Initialization,
        StepComplete,
        StepFailed,
        Terminated,
    ]);
    pub const DIRECTIONAL_DERIVATIVE: Mask =
        Mask::of(&[Initialization, StepComplete, StepFailed, Terminated]);
    pub const SET_INPUT_DERIVATIVES: Mask = Mask::of(&[Instantiated, Initialization, StepComplete]);
    pub const GET_OUTPUT_DERIVATIVES: Mask = Mask::of(&[StepComplete, StepFailed, Terminated]);
    /// StepFailed: deviation (retry after fmi2Discard).
    pub const DO_STEP: Mask = Mask::of(&[StepComplete, StepFailed]);
    /// Only in stepInProgress, which this synchronous FMU never enters.
    pub const CANCEL_STEP: Mask = Mask::of(&[]);
    pub const STATUS: Mask = Mask::of(&[StepComplete, StepFailed, Terminated]);
    /// Model Exchange stubs: any live instance gets the "not provided" error.
    pub const ANY: Mask = Mask::of(&[
        Instantiated,
        Initialization,
        StepComplete,
        StepFailed,
        Terminated,
    ]);
}
