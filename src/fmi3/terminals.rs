//! `terminalsAndIcons/terminalsAndIcons.xml` of the FMI 3.0 FMU (FMI 3.0 §2.4.9): a terminal per
//! boundary group, so that a tool connects film and structure by one mechanical connector
//! instead of six hand-made connections.
//!
//! Each terminal is named after its group, `matchingRule="plug"` (connected terminals have the
//! same members, connected by member name), `terminalKind` [`KIND`]; its members are the group's
//! displacement inputs `dx`, `dy`, `dz` and reaction outputs `Rx`, `Ry`, `Rz` (those of them the
//! group has), each `variableKind="signal"`.

use std::fmt::Write;

use crate::fmi2::description::{Description, attribute_text};

/// The `terminalKind` of a group's terminal.
pub const KIND: &str = "membrane-contact.translational";

/// The members of a group's terminal, in order.
const MEMBERS: [&str; 6] = ["dx", "dy", "dz", "Rx", "Ry", "Rz"];

/// The file's text, or `None` for a model without boundary groups.
pub fn terminals_and_icons(d: &Description) -> Option<String> {
    let names: Vec<&str> = d.variables.iter().map(|v| v.name.as_str()).collect();
    let mut terminals = String::new();
    for group in &d.model.groups {
        let members: Vec<&str> = (MEMBERS.iter().copied())
            .filter(|m| names.contains(&format!("{}.{m}", group.name).as_str()))
            .collect();
        if members.is_empty() {
            continue;
        }
        let name = attribute_text(&group.name);
        let _ = writeln!(
            terminals,
            "    <Terminal name=\"{name}\" matchingRule=\"plug\" terminalKind=\"{KIND}\" \
             description=\"boundary group '{name}': its displacement inputs and reaction outputs\">"
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
