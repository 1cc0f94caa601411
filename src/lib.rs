//! membrane-contact: geometrically nonlinear ETFE membrane finite elements with friction gap
//! elements (Bui & Kawabata), and an FMI 2.0 Co-Simulation FMU around them.
//!
//! * [`mech`]: the mechanics core (no FMI, no `unsafe`);
//! * [`specimens`]: the paper's specimens and load-path scenarios, built on the core;
//! * [`fmi2`]: the FMI 2.0 glue, the only place with `unsafe`.
#![deny(unsafe_code)]

pub mod mech;
pub mod specimens;

#[allow(unsafe_code)]
pub mod fmi2;
