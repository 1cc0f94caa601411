//! The increments of a step as they end, for a front end's log while the step runs (the CLI's
//! `--log-increments`, the FMU's `logIncrements` category): a hopeless step shows its cut-backs
//! as they happen instead of minutes of silence.

use std::fmt;
use std::sync::Arc;

/// One increment of a step, converged or refused.
#[derive(Clone, Debug, PartialEq)]
pub struct IncrementNote {
    /// Share of the step reached before it.
    pub from: f64,
    /// Share of the step it aimed at.
    pub to: f64,
    /// How it was solved (`"Newton"`, `"continuation"`, `"stabilized"`, …) or, refused, tried.
    pub attempt: &'static str,
    /// Newton iterations of the increment, converged or refused.
    pub iterations: usize,
    /// `‖R_free‖∞` at its end (N; NaN where refused).
    pub residual: f64,
    /// Why it was refused, one phrase (None: converged).
    pub refused: Option<&'static str>,
    /// Cut-backs of the step so far.
    pub cutbacks: usize,
}

impl fmt::Display for IncrementNote {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "increment {:.4} → {:.4} of the step: ",
            self.from, self.to
        )?;
        match self.refused {
            None => write!(
                f,
                "{} in {} iterations, residual {:.3e} N",
                self.attempt, self.iterations, self.residual
            )?,
            Some(why) => write!(
                f,
                "refused ({why}) after {} iterations of {}",
                self.iterations, self.attempt
            )?,
        }
        write!(f, "; {} cut-backs so far", self.cutbacks)
    }
}

/// A front end's observer of increments (none by default), called as each one ends.
#[derive(Clone, Default)]
pub struct IncrementObserver(Option<Arc<dyn Fn(&IncrementNote) + Send + Sync>>);

impl IncrementObserver {
    /// An observer calling `f`.
    pub fn new(f: impl Fn(&IncrementNote) + Send + Sync + 'static) -> Self {
        Self(Some(Arc::new(f)))
    }

    /// Passes `note` to the observer, if any.
    pub(crate) fn note(&self, note: impl FnOnce() -> IncrementNote) {
        if let Some(f) = &self.0 {
            f(&note());
        }
    }
}

impl fmt::Debug for IncrementObserver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() {
            "IncrementObserver(set)"
        } else {
            "IncrementObserver(none)"
        })
    }
}
