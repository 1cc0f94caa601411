//! The jack's model description is generated from its variable table (`DESCRIPTION`):
//! `fmu/jack/modelDescription.xml`, the file the packer ships, is that text to the byte. The
//! file is the hand-written one of version 0.1 unchanged, so the GUID, value references,
//! causalities, units, start values and dependencies are the same.

/// The committed files and the texts generated from the table: (file, committed, generated).
fn descriptions() -> [(&'static str, &'static str, String); 2] {
    [
        (
            "modelDescription.xml",
            include_str!("../modelDescription.xml"),
            hydraulic_jack::model_description(),
        ),
        (
            "modelDescription3.xml",
            include_str!("../modelDescription3.xml"),
            hydraulic_jack::model_description_fmi3(),
        ),
    ]
}

#[test]
fn the_committed_descriptions_are_the_generated_ones() {
    for (file, committed, generated) in descriptions() {
        assert_eq!(
            committed, generated,
            "regenerate fmu/jack/{file}: cargo test --release -p hydraulic-jack-fmu --test \
             model_description -- --ignored"
        );
    }
}

/// Writes `fmu/jack/modelDescription.xml` and `modelDescription3.xml` from the table (run after
/// changing it).
#[test]
#[ignore]
fn write_the_committed_descriptions() {
    for (file, _, generated) in descriptions() {
        let path = format!("{}/{file}", env!("CARGO_MANIFEST_DIR"));
        std::fs::write(path, generated).unwrap();
    }
}
