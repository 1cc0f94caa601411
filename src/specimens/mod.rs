//! Specimens and load paths built on the mechanics core, outside it: the parallel-arch
//! specimens of the reference paper (§4), the FMU's and the CLI's default model, and the
//! load-path generators of the benchmarks and tests. A library module (not behind a cargo
//! feature) because the FMU and the CLI build their default model from [`ParallelArch`], and
//! the benches and tests reach the scenarios without feature flags.
//!
//! | file | what |
//! |---|---|
//! | [`parallel_arch`] | the parallel-arch specimens of §4 and every assumption about them |
//! | [`scenarios`] | load-path generators (specimen family, arch panel, cylinder strip, arch edge) |

pub mod parallel_arch;
pub mod scenarios;

pub use parallel_arch::ParallelArch;
