//! The FMI 3.0 Co-Simulation interface of the film: the shared glue's FMI 3.0 C layer
//! (`fmi_glue::export_fmi3!`) over the same [`Instance`] the FMI 2.0 functions drive (through
//! its `Core` implementation, `src/fmi2/core.rs`), and the 3.0 model description rendered from
//! the same variable table ([`description`]).
//!
//! One library carries both interfaces (`fmi2*` and `fmi3*` symbols); the archive says which
//! one an importer uses: `fmu-pack --fmi-version 3` writes the 3.0 description and puts the
//! library under `binaries/x86_64-linux/`. The instantiation token is the FMI 2.0 GUID, so an
//! FMU of either version refuses the resources of another model alike.
//!
//! What the 3.0 interface has: Float64/Int32/Boolean/String scalars with the FMI 2.0 value
//! references (which are unique across types, as 3.0 requires), the film's fields as arrays
//! sized by structural parameters ([`arrays`]), `fmi3DoStep` without early return (a refused
//! step returns `fmi3Discard` and keeps the last converged state, as in 2.0), FMU states and
//! their serialization, `fmi3GetDirectionalDerivative` and `fmi3GetAdjointDerivative`, both made
//! of J's columns (`fmi_glue::core::Columns`: the adjoint is the directional derivative's exact
//! transpose, at one held solve per known), but for an adjoint of reactions and point
//! displacements, which is one solve at any tangent (`Instance::adjoint_in_one_solve`;
//! `docs/fmu.md` says why not for the other outputs), a terminal per boundary group
//! ([`terminals`]). Checked against steps in `tests/derivatives.rs`.

pub mod arrays;
pub mod description;
pub mod terminals;

use crate::fmi2::instance::Instance;

fmi_glue::export_fmi3!(Instance);

#[cfg(test)]
mod tests;
