//! What adds force and stiffness to the film: the membrane triangle and its film law, edge
//! cables, friction gaps, node-to-surface contact on curved supports and external loads.
//! A new material goes into [`material`] (its law) and [`triangle`] (its element).
//!
//! | file | what |
//! |---|---|
//! | [`triangle`] | CST membrane triangle, eqs. (2.2)–(2.7) |
//! | [`material`] | film law, eq. (2.3), and its tension-field (wrinkling) option |
//! | [`cable`] | tension-only edge cables (2-node truss segments along triangle edges) |
//! | [`chamber`] | enclosed gas chambers: volume by the divergence theorem, gas law, pneumatic stiffness |
//! | [`gap`] | friction gap element, eqs. (2.8), (2.9), (2.13) |
//! | [`curved_contact`] | node-to-surface friction contact on rigid curved supports (and, in `surface`, their geometry) |
//! | [`layer_contact`] | film-to-film node-to-surface friction contact between two layers (issue 43) |
//! | [`load`] | follower pressure, self-weight, nodal forces and their load stiffness |
//! | [`plasticity`] | elasto-plastic film law: finite-strain plane-stress J2 with a hardening table (issue 20) |
//! | [`temperature`] | ETFE's modulus and flow stress between 0 and 50 °C (`material.temperature`, issue 20) |

pub mod cable;
pub mod chamber;
pub mod curved_contact;
pub mod gap;
pub mod layer_contact;
pub mod load;
pub mod material;
pub mod orifice;
pub mod plasticity;
pub mod temperature;
pub mod triangle;
