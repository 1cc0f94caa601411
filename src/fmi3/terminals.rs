//! `terminalsAndIcons/terminalsAndIcons.xml` of the FMI 3.0 FMU (FMI 3.0 §2.4.9): one connector
//! per boundary group and per chamber, so that a tool connects film and structure, or film and
//! inflation unit, by one terminal instead of hand-made connections.
//!
//! Each terminal is named after its group or chamber, `matchingRule="plug"` (connected terminals
//! have the same members, connected by member name), each member `variableKind="signal"`:
//! * a group's, `terminalKind` [`KIND`]: its displacement inputs `dx`, `dy`, `dz` and reaction
//!   outputs `Rx`, `Ry`, `Rz` (those of them the group has);
//! * a chamber's, `terminalKind` [`PNEUMATIC_KIND`]: its inputs `supplyPressure`, `sealed`,
//!   `heating` and outputs `pressure`, `volume`, `temperature`, `mass`.

use std::fmt::Write;

use crate::fmi2::description::{Description, attribute_text};

/// The `terminalKind` of a group's terminal.
pub const KIND: &str = "membrane-contact.translational";

/// The `terminalKind` of a chamber's terminal.
pub const PNEUMATIC_KIND: &str = "membrane-contact.pneumatic";

/// The members of a group's terminal, in order.
const MEMBERS: [&str; 6] = ["dx", "dy", "dz", "Rx", "Ry", "Rz"];

/// The members of a chamber's terminal, in order.
const CHAMBER_MEMBERS: [&str; 7] = [
    "supplyPressure",
    "sealed",
    "heating",
    "pressure",
    "volume",
    "temperature",
    "mass",
];

/// The file's text, or `None` for a model without boundary groups or chambers.
pub fn terminals_and_icons(d: &Description) -> Option<String> {
    let names: Vec<&str> = d.variables.iter().map(|v| v.name.as_str()).collect();
    let mut terminals = String::new();
    let groups = d.model.groups.iter().map(|g| {
        let what = "its displacement inputs and reaction outputs";
        (&g.name, KIND, "boundary group", what, &MEMBERS[..])
    });
    let chambers = d.model.chambers.iter().map(|c| {
        let what = "its supply, valve and heating inputs and its air's outputs";
        (
            &c.name,
            PNEUMATIC_KIND,
            "chamber",
            what,
            &CHAMBER_MEMBERS[..],
        )
    });
    for (owner, kind, role, what, all) in groups.chain(chambers) {
        let members: Vec<&str> = (all.iter().copied())
            .filter(|m| names.contains(&format!("{owner}.{m}").as_str()))
            .collect();
        if members.is_empty() {
            continue;
        }
        let name = attribute_text(owner);
        let _ = writeln!(
            terminals,
            "    <Terminal name=\"{name}\" matchingRule=\"plug\" terminalKind=\"{kind}\" \
             description=\"{role} '{name}': {what}\">"
        );
        for m in members {
            let _ = writeln!(
                terminals,
                "      <TerminalMemberVariable variableName=\"{name}.{m}\" memberName=\"{m}\" \
                 variableKind=\"signal\"/>"
            );
        }
        terminals.push_str("    </Terminal>\n");
    }
    (!terminals.is_empty()).then(|| {
        format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiTerminalsAndIcons fmiVersion=\"3.0\">\n  \
             <Terminals>\n{terminals}  </Terminals>\n</fmiTerminalsAndIcons>\n"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi2::description::describe;
    use crate::fmi2::resources::Source;
    use crate::mech::Model;

    /// The cushion's chamber `air` has a pneumatic terminal with its seven members, each an
    /// FMU variable of that name, after the translational terminal of its group `rim`.
    #[test]
    fn a_chamber_has_a_pneumatic_terminal_with_its_inputs_and_outputs() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/cushion_air.json"
        ))
        .unwrap();
        let d = describe(&Source::Model(Model::from_json(&text).unwrap())).unwrap();
        let xml = terminals_and_icons(&d).unwrap();
        assert_eq!(xml.matches("<Terminal ").count(), 2, "{xml}");
        assert!(xml.contains("<Terminal name=\"rim\" matchingRule=\"plug\" terminalKind=\"membrane-contact.translational\""));
        assert!(xml.contains(
            "<Terminal name=\"air\" matchingRule=\"plug\" terminalKind=\"membrane-contact.pneumatic\""
        ));
        for m in CHAMBER_MEMBERS {
            let line = format!("variableName=\"air.{m}\" memberName=\"{m}\"");
            assert!(xml.contains(&line), "{m}: {xml}");
            assert!(
                d.variables.iter().any(|v| v.name == format!("air.{m}")),
                "{m}"
            );
        }
    }
}
