//! Messages to the importer through the FMI logger callback.
//!
//! The C logger is variadic with printf semantics. Every message is formatted in Rust and passed
//! as `logger(env, instanceName, status, category, "%s", message)`, so a `%` in a message (a path,
//! a model name) can never act as a format directive.
//!
//! Categories are the ones declared in `modelDescription.xml` ([`CATEGORIES`], rendered from this
//! table). A message goes out only when its category is enabled:
//! * `fmi2Instantiate(loggingOn = true)` enables all of them;
//! * `loggingOn = false` keeps only `logStatusDiscard`, `logStatusError` and `logStatusFatal`, so
//!   that a failing call still explains itself (switch those off with `fmi2SetDebugLogging`);
//! * `fmi2SetDebugLogging(on, 0, NULL)` switches all, `(on, n, names)` the named ones
//!   (`logAll` stands for every category).

use fmi_glue::logger::Sink;

use super::types::{Fmi2CallbackLogger, Fmi2ComponentEnvironment, Status};
use crate::mech::solve::{IncrementNote, IncrementObserver};

/// The declared log categories: name and description (`<LogCategories>`).
pub const CATEGORIES: [(&str, &str); 7] = [
    (
        "logEvents",
        "initialization, steps and their Newton statistics, state save/restore",
    ),
    ("logStatusWarning", "calls that return fmi2Warning"),
    (
        "logStatusDiscard",
        "steps that did not converge (fmi2Discard): the last converged state is kept",
    ),
    (
        "logStatusError",
        "calls that return fmi2Error: bad arguments, wrong call order, invalid parameters",
    ),
    (
        "logStatusFatal",
        "internal errors (fmi2Fatal): the instance must be freed",
    ),
    (
        "logIncrements",
        "each increment of a step as it ends: share of the step, how it was solved or why it was \
         refused, iterations, residual, cut-backs (a line per increment: not enabled by \
         loggingOn = true, only by name or logAll)",
    ),
    ("logAll", "all of the above"),
];

const EVENTS: usize = 0;
const INCREMENTS: usize = 5;
const ALL: usize = 6;

/// The category a message of this status goes to.
fn category_of(status: Status) -> usize {
    match status {
        Status::Ok | Status::Pending => EVENTS,
        Status::Warning => 1,
        Status::Discard => 2,
        Status::Error => 3,
        Status::Fatal => 4,
    }
}

/// One instance's logger: the importer's callback of either FMI version (the shared glue's
/// [`Sink`]) and the enabled categories.
#[derive(Clone, Debug)]
pub struct Logger {
    sink: Sink,
    enabled: [bool; CATEGORIES.len()],
}

impl Logger {
    /// A logger for `instance_name`; `callback` may be `None` (messages are then dropped).
    pub fn new(
        callback: Fmi2CallbackLogger,
        environment: Fmi2ComponentEnvironment,
        instance_name: &str,
        logging_on: bool,
    ) -> Self {
        Self::with_sink(Sink::fmi2(callback, environment, instance_name), logging_on)
    }

    /// A logger over `sink` (FMI 2.0 or 3.0) with the categories `loggingOn` enables.
    pub fn with_sink(sink: Sink, logging_on: bool) -> Self {
        let mut enabled = [logging_on; CATEGORIES.len()];
        for status in [Status::Discard, Status::Error, Status::Fatal] {
            enabled[category_of(status)] = true;
        }
        enabled[INCREMENTS] = false;
        Self { sink, enabled }
    }

    /// A logger that drops every message.
    pub fn silent() -> Self {
        Self::new(None, std::ptr::null_mut(), "", false)
    }

    /// `fmi2SetDebugLogging`: switch all categories (`names` empty) or the named ones.
    /// An unknown name changes nothing and is reported.
    pub fn set_debug_logging(&mut self, on: bool, names: &[&str]) -> Result<(), String> {
        if names.is_empty() {
            self.enabled = [on; CATEGORIES.len()];
            return Ok(());
        }
        let mut indices = Vec::with_capacity(names.len());
        for name in names {
            match CATEGORIES.iter().position(|(c, _)| c == name) {
                Some(i) => indices.push(i),
                None => {
                    let known: Vec<&str> = CATEGORIES.iter().map(|(c, _)| *c).collect();
                    return Err(format!(
                        "unknown log category '{name}' (declared: {})",
                        known.join(", ")
                    ));
                }
            }
        }
        for i in indices {
            if i == ALL {
                self.enabled = [on; CATEGORIES.len()];
            } else {
                self.enabled[i] = on;
            }
        }
        Ok(())
    }

    /// Whether a message of `status` would be passed on.
    pub fn is_enabled(&self, status: Status) -> bool {
        self.sink.is_some() && self.enabled[category_of(status)]
    }

    /// Whether `logIncrements` messages would be passed on.
    pub fn increments_enabled(&self) -> bool {
        self.sink.is_some() && self.enabled[INCREMENTS]
    }

    /// Sends an increment's line ([`Self::increments_enabled`]) to the importer, status OK.
    pub fn log_increment(&self, message: &str) {
        self.send(INCREMENTS, Status::Ok, message);
    }

    /// The solver's observer of increments for the next step: a `logIncrements` line per
    /// increment where the category is enabled, else none.
    pub fn increment_observer(&self) -> IncrementObserver {
        if !self.increments_enabled() {
            return IncrementObserver::default();
        }
        let logger = SteppingLogger(self.clone());
        IncrementObserver::new(move |note| logger.say(note))
    }

    /// Sends `message` with `status` to the importer if its category is enabled.
    pub fn log(&self, status: Status, message: &str) {
        self.send(category_of(status), status, message);
    }

    /// Sends `message` in `category` with `status` if the category is enabled.
    fn send(&self, category: usize, status: Status, message: &str) {
        if self.enabled[category] {
            self.sink
                .send(status, Some(CATEGORIES[category].0), message);
        }
    }
}

/// A copy of an instance's logger held by the solver's increment observer.
struct SteppingLogger(Logger);

impl SteppingLogger {
    /// Logs `note` in `logIncrements`.
    fn say(&self, note: &IncrementNote) {
        self.0.log_increment(&note.to_string());
    }
}

// SAFETY: the observer holding it is called only from `Analysis::step_to_motion`, which the
// instance runs inside its own fmi2DoStep, on the thread the importer called it from; it is
// replaced before each step. So the callback and environment pointers are used exactly as the
// instance's own logger uses them, inside an FMI call, never concurrently with it (FMI 2.0
// §2.1.5: an instance is called by one thread at a time).
unsafe impl Send for SteppingLogger {}
// SAFETY: as for `Send`: no two threads call the observer at once (it is only called inside
// the instance's fmi2DoStep), so shared references never race.
unsafe impl Sync for SteppingLogger {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_categories_follow_logging_on() {
        let on = Logger::new(None, std::ptr::null_mut(), "a", true);
        // Every category but the increments' (a line per increment: only by name).
        let named = |i: usize| i == INCREMENTS;
        assert!(on.enabled.iter().enumerate().all(|(i, &e)| e != named(i)));
        let off = Logger::new(None, std::ptr::null_mut(), "a", false);
        assert!(!off.enabled[category_of(Status::Ok)]);
        assert!(
            off.enabled[category_of(Status::Error)] && off.enabled[category_of(Status::Discard)]
        );
        // Without a callback nothing is ever "enabled".
        assert!(!on.is_enabled(Status::Error));
    }

    #[test]
    fn set_debug_logging_by_name_and_all() {
        let mut l = Logger::new(None, std::ptr::null_mut(), "a", false);
        l.set_debug_logging(true, &["logEvents"]).unwrap();
        assert!(l.enabled[EVENTS]);
        l.set_debug_logging(false, &["logAll"]).unwrap();
        assert!(l.enabled.iter().all(|&e| !e));
        l.set_debug_logging(true, &[]).unwrap();
        assert!(l.enabled.iter().all(|&e| e));
        let err = l
            .set_debug_logging(false, &["logStatusError", "nope"])
            .unwrap_err();
        assert!(err.contains("'nope'"), "{err}");
        assert!(
            l.enabled[category_of(Status::Error)],
            "a failed call changes nothing"
        );
    }
}
