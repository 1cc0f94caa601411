//! The phases, masks and failures: moved to the shared glue (`fmu/glue/src/phase.rs`), kept
//! under their former path `fmi2::phase`.

pub use fmi_glue::phase::*;
