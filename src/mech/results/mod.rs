//! Results of a converged state and what is made of them.
//!
//! | file | what |
//! |---|---|
//! | [`fields`] | [`Results`]: gaps, reactions, moments, cables, curved contacts, stresses, points, sets |
//! | `gather` | `Analysis::results`: the results gathered at the converged state |
//! | [`summary`] | output points and field summaries over element sets |
//! | [`contact_warnings`] | penetrations and contact forces far outside the model's scale |
//! | [`warnings`] | warnings about a model that looks wrong and results beyond its assumptions |
//! | [`lines`] | reactions per unit length along boundary groups and support sets |
//! | [`finite`] | finiteness check of reported results |
//! | [`vtk`] | VTK text of the deformed film and its stresses (Fig. 6) |

pub mod contact_warnings;
pub mod fields;
pub mod finite;
mod gather;
pub mod lines;
pub mod summary;
pub mod vtk;
pub mod warnings;

pub use fields::{GapResult, PlasticSummary, Results};
