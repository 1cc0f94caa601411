//! The FMI 2.0 Co-Simulation glue: the instance behind the shared glue's C layers (`fmu/glue`,
//! where the `unsafe` code is; here only what its macros write and the tests' calls).
//!
//! Call chain of every entry point:
//!
//! ```text
//! importer ── fmi2DoStep(c, t, h, …)              exports.rs   fmi_glue::export_fmi2!(Instance): the glue's C layer
//!          └─ fmi_glue::fmi2::with(c, mask, …)    fmu/glue     NULL/phase checks, catch_unwind, log, status
//!             └─ Core::do_step → Instance::do_step core.rs, stepping.rs  safe: one file per duty
//!                └─ mech::Analysis::step_to(…)    the mechanics core (knows nothing of FMI)
//! ```
//!
//! | module | what |
//! |---|---|
//! | [`types`] | the FMI 2.0 C types, written from the standard headers |
//! | [`guard`] | the glue's barrier (`with_instance`), freeing and array helpers, re-exported |
//! | [`logger`] | the variadic C logger, called with `"%s"`; log categories |
//! | [`variables`] | the variable table, derived from the model: the one source of the interface |
//! | [`scalar_variable`] | one variable: type, causality, variability, value, binding, value check |
//! | [`description`] | `modelDescription.xml` (from `modelDescription.xml.in`), GUID, documentation |
//! | [`resources`] | what an FMU is built from, its `resources/` file, the resource URI parser |
//! | [`phase`] | the state machine's phases, which call is allowed in which phase (masks), [`Failure`](phase::Failure) |
//! | [`instance`] | the instance: its fields, instantiation, the model and analysis its parameters build |
//! | `lifecycle` | the transitions: setup, enter/exit initialization, terminate, reset, debug logging |
//! | `values` | `fmi2Get*`/`fmi2Set*` by value reference, and which variable may be set when |
//! | `outputs` | the outputs from the converged state's results, checked finite; assumption warnings |
//! | `stepping` | `fmi2DoStep` and what it drives (inputs, μ, the checked core step, retry); the status queries |
//! | `vtk_output` | the results files: VTK `.vtu`/`.pvd` of every converged state (`results.directory`) |
//! | `derivatives` | `fmi2GetDirectionalDerivative` from the core's linear response |
//! | `fmu_states` | the instance's saved FMU states: get, set, free, (de)serialize |
//! | [`state`] | one FMU state: the snapshot, its serialized byte format and its checks |
//! | [`exports`] | the 44 exported `fmi2*` functions (25 common, 9 CS, 10 ME error stubs): `fmi_glue::export_fmi2!` |
//! | `core` | the instance as the glue's `Core`: what both C layers call |
//! | `tests/` | tests through the exported functions, as an importer calls them, one file per duty |
//! | `wiring_tests` | every FMU parameter and input against the core, from the variable table |
//!
//! The instance's files have no import (or call) circle: `phase` uses only `types`; `instance`
//! uses `phase` and `state` (for the `Snapshot` type) and none of its duty files; `outputs` and
//! `vtk_output` use `instance`; `values` uses `outputs`; `stepping` uses `values`, `outputs`
//! and `vtk_output`; `lifecycle` uses `outputs` and `vtk_output`; `fmu_states` uses `instance`
//! and `state`; `state` takes `Phase` from `phase`.
//!
//! No global mutable state: everything lives in the [`Instance`](instance::Instance) behind
//! `fmi2Component`; instances are independent and may run on different threads. The library
//! keeps no thread: the assembly's threads (`solver.threads`) are scoped and joined before the
//! FMI call that started them returns, on Linux until their tasks have left `/proc/self/task`
//! (`tests/threads.rs`). It is linked with `-z nodelete` (see `fmu/build.rs`), so an
//! importer's `dlclose` cannot unload code that is still referenced.

mod core;
mod derivatives;
pub mod description;
pub mod exports;
mod fmu_states;
pub mod guard;
pub mod instance;
mod lifecycle;
pub mod logger;
mod outputs;
pub mod phase;
pub mod resources;
pub mod scalar_variable;
pub mod state;
mod stepping;
pub mod types;
mod values;
pub mod variables;
mod vtk_output;

#[cfg(test)]
pub(crate) mod tests;
#[cfg(test)]
mod wiring_tests;
