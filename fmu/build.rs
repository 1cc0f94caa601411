//! Build script of the package (see `build = "fmu/build.rs"` in Cargo.toml).
//!
//! Links the FMU's shared library with `-z nodelete`: importers (fmpy, FMIL) `dlclose` the
//! library after `fmi2FreeInstance`; with `nodelete` the code stays mapped, so thread-local
//! destructors or anything else still referring to it cannot jump into unmapped memory.

fn main() {
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!("cargo::rustc-cdylib-link-arg=-Wl,-z,nodelete");
    }
    println!("cargo::rerun-if-changed=fmu/build.rs");
}
