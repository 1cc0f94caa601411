//! The model: mesh, material, constraints, gap elements, curved supports, cables, loads and
//! prescribed boundary groups, read from a JSON model file (format in `docs/model-format.md`)
//! and validated before any analysis.
//!
//! | file | what |
//! |---|---|
//! | [`format`](mod@format) | the model file's items (serde types), [`ModelError`], [`bounding_diagonal`] |
//! | [`free_edges`] | boundary edges a prestress pulls across that nothing holds (a warning) |
//! | `validate` | `Model::validate`: every item checked, the first problem named |
//! | [`restraint`] | rigid-body modes no restraint holds (singular models), found at validation |

pub mod format;
pub mod free_edges;
pub mod restraint;
mod validate;

pub use format::*;
pub use validate::check_xml_text;
