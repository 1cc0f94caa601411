//! The jack's model descriptions are generated from its variable table (`DESCRIPTION`):
//! `fmu/jack/modelDescription.xml` and `modelDescription3.xml`, the files the packer ships,
//! are those texts to the byte. The
//! file is the hand-written one of version 0.1 unchanged, so the GUID, value references,
//! causalities, units, start values and dependencies are the same.

fmi_glue::committed_description_tests!(hydraulic_jack::DESCRIPTION, "hydraulic-jack-fmu");
