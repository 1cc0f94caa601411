//! The status a call returns: FMI 2.0's `fmi2Status` and FMI 3.0's `fmi3Status` share the values
//! 0 to 4 (`Pending`, 5, is FMI 2.0's only and never returned by this project's FMUs).

use core::ffi::c_int;

/// The status of a call, ordered by severity so that "the worst status wins" is `max`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
    Pending = 5,
}

impl Status {
    /// The value returned to C.
    pub fn raw(self) -> c_int {
        self as c_int
    }

    /// The FMI 2.0 C name, for messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ok => "fmi2OK",
            Self::Warning => "fmi2Warning",
            Self::Discard => "fmi2Discard",
            Self::Error => "fmi2Error",
            Self::Fatal => "fmi2Fatal",
            Self::Pending => "fmi2Pending",
        }
    }
}
