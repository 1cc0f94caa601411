//! membrane-contact: geometrically nonlinear ETFE membrane finite elements with friction gap
//! elements (Bui & Kawabata), and an FMI 2.0 Co-Simulation FMU around them.
//!
//! * [`mech`]: the mechanics core (no FMI, no `unsafe`);
//! * [`specimens`]: the paper's specimens and load-path scenarios, built on the core;
//! * [`fmi2`]: the FMI 2.0 glue, the only place with `unsafe`;
//! * [`fmi3`]: the FMI 3.0 Co-Simulation interface, the shared glue's C layer (`fmu/glue`)
//!   over the same instance.
#![deny(unsafe_code)]

pub mod mech;
pub mod specimens;

#[allow(unsafe_code)]
pub mod fmi2;

#[allow(unsafe_code)] // the exports the shared glue's macro writes (`fmi_glue::export_fmi3!`)
pub mod fmi3;
