//! The FMI 2.0 Co-Simulation glue: the only module with `unsafe`.
//!
//! Call chain of every entry point:
//!
//! ```text
//! importer ── fmi2DoStep(c, t, h, …)              exports.rs   #[unsafe(export_name)] extern "C", one line
//!          └─ guard::with_instance(c, mask, …)    guard.rs     NULL/phase checks, catch_unwind, log, status
//!             └─ Instance::do_step(t, h)          instance.rs  safe: state machine, values, FMU states
//!                └─ mech::Analysis::step_to(…)    the mechanics core (knows nothing of FMI)
//! ```
//!
//! | module | what |
//! |---|---|
//! | [`types`] | the FMI 2.0 C types, written from the standard headers |
//! | [`guard`] | every raw pointer, `Box::into_raw`/`from_raw`, the panic barrier |
//! | [`logger`] | the variadic C logger, called with `"%s"`; log categories |
//! | [`variables`] | the variable table, derived from the model: the one source of the interface |
//! | [`description`] | `modelDescription.xml` (from `modelDescription.xml.in`), GUID, documentation |
//! | [`resources`] | what an FMU is built from, its `resources/` file, the resource URI parser |
//! | [`instance`] | the instance: state machine, get/set, DoStep, FMU states |
//! | [`state`] | the FMU state snapshot and its serialized byte format |
//! | [`exports`] | the 44 exported `fmi2*` functions (25 common, 9 CS, 10 ME error stubs) |
//!
//! No global mutable state: everything lives in the [`Instance`](instance::Instance) behind
//! `fmi2Component`; instances are independent and may run on different threads. The library
//! keeps no thread: the assembly's threads (`solver.threads`) are scoped and joined before the
//! FMI call that started them returns, on Linux until their tasks have left `/proc/self/task`
//! (`tests/threads.rs`). It is linked with `-z nodelete` (see `fmu/build.rs`), so an
//! importer's `dlclose` cannot unload code that is still referenced.

pub mod description;
pub mod exports;
pub mod guard;
pub mod instance;
pub mod logger;
pub mod resources;
pub mod state;
pub mod types;
pub mod variables;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod wiring_tests;
