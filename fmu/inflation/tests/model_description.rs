//! The inflation unit's model descriptions are generated from its variable table (`DESCRIPTION`):
//! `fmu/inflation/modelDescription.xml` and `modelDescription3.xml`, the files the packer ships,
//! are those texts to the byte.

fmi_glue::committed_description_tests!(inflation_unit::DESCRIPTION, "inflation-unit-fmu");
