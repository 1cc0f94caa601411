//! The jack's model description is generated from its variable table (`DESCRIPTION`):
//! `fmu/jack/modelDescription.xml`, the file the packer ships, is that text to the byte. The
//! file is the hand-written one of version 0.1 unchanged, so the GUID, value references,
//! causalities, units, start values and dependencies are the same.

#[test]
fn the_committed_description_is_the_generated_one() {
    let committed = include_str!("../modelDescription.xml");
    assert_eq!(
        committed,
        hydraulic_jack::model_description(),
        "regenerate fmu/jack/modelDescription.xml: \
         cargo test --release -p hydraulic-jack-fmu --test model_description -- --ignored"
    );
}

/// Writes `fmu/jack/modelDescription.xml` from the table (run after changing it).
#[test]
#[ignore]
fn write_the_committed_description() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/modelDescription.xml");
    std::fs::write(path, hydraulic_jack::model_description()).unwrap();
}
