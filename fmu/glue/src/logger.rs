//! Messages to the importer: the callback of either FMI version ([`Sink`]), and a [`Logger`]
//! that filters by the log categories a model declares.
//!
//! FMI 2.0's logger is variadic with printf semantics: every message is formatted in Rust and
//! passed as `logger(env, instanceName, status, category, "%s", message)`, so a `%` in a message
//! can never act as a format directive. FMI 3.0's `fmi3LogMessageCallback` takes the message
//! itself (no format, no instance name).

use core::ffi::{c_char, c_int, c_void};
use std::ffi::CString;

use crate::status::Status;

/// `fmi2CallbackLogger`: variadic, printf semantics.
pub type Fmi2LoggerFn = unsafe extern "C" fn(
    environment: *mut c_void,
    instance_name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
    ...
);

/// `fmi3LogMessageCallback`.
pub type Fmi3LoggerFn = unsafe extern "C" fn(
    environment: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
);

/// Where an instance's messages go: the importer's callback (copied at instantiation), or
/// nowhere.
#[derive(Clone, Debug)]
pub enum Sink {
    /// No callback: messages are dropped.
    None,
    /// FMI 2.0: callback, `componentEnvironment`, instance name.
    Fmi2(Fmi2LoggerFn, *mut c_void, CString),
    /// FMI 3.0: callback and `instanceEnvironment`.
    Fmi3(Fmi3LoggerFn, *mut c_void),
}

impl Sink {
    /// An FMI 2.0 sink (`None` without a callback).
    pub fn fmi2(callback: Option<Fmi2LoggerFn>, environment: *mut c_void, name: &str) -> Self {
        callback.map_or(Self::None, |f| Self::Fmi2(f, environment, c_string(name)))
    }

    /// An FMI 3.0 sink (`None` without a callback).
    pub fn fmi3(callback: Option<Fmi3LoggerFn>, environment: *mut c_void) -> Self {
        callback.map_or(Self::None, |f| Self::Fmi3(f, environment))
    }

    /// Whether messages reach anyone.
    pub fn is_some(&self) -> bool {
        !matches!(self, Self::None)
    }

    /// Sends `message` in `category` (NULL where `None`) with `status`.
    pub fn send(&self, status: Status, category: Option<&str>, message: &str) {
        let category = category.map(c_string);
        let category = category.as_ref().map_or(std::ptr::null(), |c| c.as_ptr());
        let message = c_string(message);
        match self {
            Self::None => {}
            // SAFETY: `f` is the importer's fmi2CallbackLogger, copied from the callbacks struct
            // in fmi2Instantiate (FMI 2.0 §2.1.5 requires it to stay callable for the life of the
            // instance). Every pointer passed is NULL (category) or a NUL-terminated string that
            // outlives the call, and the format "%s" consumes exactly the one C string after it.
            Self::Fmi2(f, environment, name) => unsafe {
                f(
                    *environment,
                    name.as_ptr(),
                    status.raw(),
                    category,
                    c"%s".as_ptr(),
                    message.as_ptr(),
                )
            },
            // SAFETY: `f` is the importer's fmi3LogMessageCallback given to
            // fmi3InstantiateCoSimulation (FMI 3.0 §2.3.1: callable for the life of the
            // instance); the strings are NUL-terminated and outlive the call.
            Self::Fmi3(f, environment) => unsafe {
                f(*environment, status.raw(), category, message.as_ptr())
            },
        }
    }
}

/// The log categories the FMI standard names (FMI 2.0 §2.2.4, FMI 3.0 §2.4.5).
pub const STANDARD_CATEGORIES: [&str; 10] = [
    "logEvents",
    "logSingularLinearSystems",
    "logNonlinearSystems",
    "logDynamicStateSelection",
    "logStatusWarning",
    "logStatusDiscard",
    "logStatusError",
    "logStatusFatal",
    "logStatusPending",
    "logAll",
];

/// The standard category a message of `status` goes to.
pub fn standard_category(status: Status) -> &'static str {
    match status {
        Status::Ok | Status::Pending => "logEvents",
        Status::Warning => "logStatusWarning",
        Status::Discard => "logStatusDiscard",
        Status::Error => "logStatusError",
        Status::Fatal => "logStatusFatal",
    }
}

/// A sink filtered by declared categories: a message goes out only in a declared, enabled
/// category ([`standard_category`] of its status). `loggingOn = false` still keeps
/// `logStatusDiscard`, `logStatusError` and `logStatusFatal`, so a failing call explains itself.
#[derive(Clone, Debug)]
pub struct Logger {
    sink: Sink,
    categories: &'static [(&'static str, &'static str)],
    enabled: Vec<bool>,
}

impl Logger {
    /// A logger over `sink` for the declared `categories` (`logAll` stands for all of them).
    pub fn new(
        sink: Sink,
        categories: &'static [(&'static str, &'static str)],
        logging_on: bool,
    ) -> Self {
        let always = ["logStatusDiscard", "logStatusError", "logStatusFatal"];
        let enabled = categories
            .iter()
            .map(|(c, _)| logging_on || always.contains(c))
            .collect();
        Self {
            sink,
            categories,
            enabled,
        }
    }

    /// `fmiXSetDebugLogging`: switch all categories (`names` empty) or the named ones. A
    /// standard category the FMU does not declare ([`STANDARD_CATEGORIES`]) has nothing to
    /// switch and is passed over (masters ask for `logStatusWarning` of every FMU); any other
    /// unknown name changes nothing and is reported.
    pub fn set_debug_logging(&mut self, on: bool, names: &[&str]) -> Result<(), String> {
        let position = |name: &&str| self.categories.iter().position(|(c, _)| c == name);
        let unknown = |n: &&&str| position(n).is_none() && !STANDARD_CATEGORIES.contains(n);
        if let Some(unknown) = names.iter().find(unknown) {
            let known: Vec<&str> = self.categories.iter().map(|(c, _)| *c).collect();
            return Err(format!(
                "unknown log category '{unknown}' (declared: {})",
                known.join(", ")
            ));
        }
        let all = names.is_empty() || names.contains(&"logAll");
        for (i, (c, _)) in self.categories.iter().enumerate() {
            if all || names.contains(c) {
                self.enabled[i] = on;
            }
        }
        Ok(())
    }

    /// Whether a message of `status` would be passed on.
    pub fn is_enabled(&self, status: Status) -> bool {
        let name = standard_category(status);
        self.sink.is_some()
            && (self.categories.iter())
                .zip(&self.enabled)
                .any(|((c, _), &on)| on && *c == name)
    }

    /// Sends `message` with `status` if its category is declared and enabled.
    pub fn log(&self, status: Status, message: &str) {
        if self.is_enabled(status) {
            self.sink
                .send(status, Some(standard_category(status)), message);
        }
    }
}

/// A C string of `text`; an interior NUL (which C would read as the end) becomes U+FFFD.
pub fn c_string(text: &str) -> CString {
    CString::new(text.replace('\0', "\u{FFFD}")).expect("no NUL left")
}

#[cfg(test)]
mod tests {
    use super::*;

    const CATEGORIES: &[(&str, &str)] =
        &[("logEvents", ""), ("logStatusError", ""), ("logAll", "")];

    unsafe extern "C" fn ignore(_: *mut c_void, _: c_int, _: *const c_char, _: *const c_char) {}

    #[test]
    fn logging_off_keeps_errors_and_set_debug_logging_switches_by_name_or_all() {
        let mut l = Logger::new(
            Sink::fmi3(Some(ignore), std::ptr::null_mut()),
            CATEGORIES,
            false,
        );
        assert!(l.is_enabled(Status::Error) && !l.is_enabled(Status::Ok));
        assert!(!l.is_enabled(Status::Discard), "not declared, never sent");
        l.set_debug_logging(true, &["logEvents"]).unwrap();
        assert!(l.is_enabled(Status::Ok));
        l.set_debug_logging(false, &["logAll"]).unwrap();
        assert!(!l.is_enabled(Status::Error) && !l.is_enabled(Status::Ok));
        let err = l
            .set_debug_logging(true, &["logEvents", "nope"])
            .unwrap_err();
        assert!(err.contains("'nope'"), "{err}");
        assert!(!l.is_enabled(Status::Ok), "a refused call changes nothing");
        let silent = Logger::new(Sink::None, CATEGORIES, true);
        assert!(!silent.is_enabled(Status::Error));
    }

    #[test]
    fn c_string_replaces_nul() {
        assert_eq!(c_string("a\0b").to_str().unwrap(), "a\u{FFFD}b");
    }
}
