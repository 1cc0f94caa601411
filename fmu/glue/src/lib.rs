//! The FMI glue shared by the project's FMUs (the film, `src/fmi2`, and the hydraulic jack,
//! `fmu/jack`): what every FMU's C layer needs, written once.
//!
//! | module | what |
//! |---|---|
//! | [`status`] | the status a call returns (FMI 2.0 and 3.0 share its values) |
//! | [`phase`] | the phases, which call is allowed in which phase (masks), how a call fails |
//! | [`ffi`] | C arrays and strings turned into Rust references after NULL and length checks |
//! | [`logger`] | the importer's logger of either version, filtered by declared categories |
//! | [`core`] | [`Core`](core::Core): the instance contract every C layer calls |
//! | [`fmi2`] | the FMI 2.0 C layer over any `Core`, and [`export_fmi2!`] |
//! | [`fmi3`] | the FMI 3.0 Co-Simulation C layer over any `Core`, and [`export_fmi3!`] |
//! | [`description`] | a variable table and the `modelDescription.xml` it generates |
//! | [`scalar`] | the instance core of a model of Real scalars, a `Core` |
//!
//! `unsafe` code is only in [`ffi`], [`logger`]'s callback calls and [`fmi2`] (the C layer);
//! each block says why it is sound. No panic crosses the C boundary: every entry point runs
//! its body under `catch_unwind`, and a panic makes the instance fatal.

pub mod core;
pub mod description;
pub mod ffi;
pub mod fmi2;
pub mod fmi3;
pub mod logger;
pub mod phase;
pub mod scalar;
pub mod status;

pub use status::Status;
