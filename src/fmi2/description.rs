//! `modelDescription.xml` and `documentation/index.html`, rendered from the variable table.
//!
//! [`describe`] fills the top-level `modelDescription.xml.in` template (embedded at compile
//! time). The generated parts are written with quick-xml's writer:
//! * `<UnitDefinitions>`: the units the table uses ([`UNITS`]);
//! * `<LogCategories>`: the logger's [`CATEGORIES`];
//! * `<ModelVariables>`: one ScalarVariable per table row, in value-reference order;
//! * `<ModelStructure>`: `<Outputs>` = every output, depending on the inputs (a step moves the
//!   model to the inputs' values); `<InitialUnknowns>` = the same outputs (all `calculated`),
//!   depending on the parameters (the initial state is the undeformed, prestressed film; not on
//!   `results.directory`, which only says where the VTK files go).
//!
//! The GUID is the UUID v5 (OID namespace) of the rendered text with the GUID field left as it
//! is in the template followed by the model as its model file (JSON), formatted `{…}`: two FMUs
//! whose interfaces agree but whose models differ (an initial gap, a node position) never share
//! a GUID, so a saved state of one is refused by the other (the state header carries the GUID). `fmu-pack` writes the XML; `fmi2Instantiate` renders it
//! again from the FMU's resources and compares GUIDs, so a binary and an XML that disagree on the
//! interface refuse to run together.

use crate::mech::results::lines::{ReactionLine, reaction_lines};
use std::io;

use quick_xml::Writer;
use quick_xml::escape::escape;
use quick_xml::events::{BytesText, Event};
use uuid::Uuid;

use super::logger::CATEGORIES;
use super::resources::Source;
use super::scalar_variable::{Causality, Value, Variable};
use super::variables::{Kind, UNITS, check_names, variables};
use crate::mech::Model;

/// The template (top-level `modelDescription.xml.in`).
pub const TEMPLATE: &str = include_str!("../../modelDescription.xml.in");

/// An FMU's interface: its model, variable table, GUID and rendered description.
#[derive(Clone, Debug)]
pub struct Description {
    /// `modelIdentifier` (= `modelName` = the model's name).
    pub model_identifier: String,
    /// `{xxxxxxxx-xxxx-5xxx-xxxx-xxxxxxxxxxxx}`.
    pub guid: String,
    /// The complete `modelDescription.xml`.
    pub xml: String,
    /// The variable table.
    pub variables: Vec<Variable>,
    /// The model at the start values of the parameters.
    pub model: Model,
    /// Its reaction lines (groups, then support sets; `mech::results::lines`): the FMI 3.0
    /// interface's per-line arrays, worked out once.
    pub reaction_lines: Vec<ReactionLine>,
}

/// Renders the description of an FMU of `source`.
pub fn describe(source: &Source) -> Result<Description, String> {
    let model = source.model()?;
    model.validate().map_err(|e| e.to_string())?;
    check_names(&model)?;
    let kind = match source {
        Source::ParallelArch(spec) => Kind::ParallelArch {
            arch_height: spec.arch_height,
        },
        Source::Model(_) => Kind::Model,
    };
    let table = variables(&model, kind);
    let generated = |f: fn(&mut Writer<Vec<u8>>, &[Variable]) -> io::Result<()>| -> String {
        let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
        f(&mut w, &table).expect("writing to a Vec cannot fail");
        let text = String::from_utf8(w.into_inner()).expect("the writer emits UTF-8");
        text.lines()
            .map(|l| format!("  {l}"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let parts = [
        ("MODEL_NAME", attribute_text(&model.name)),
        ("MODEL_IDENTIFIER", model.name.clone()),
        ("DESCRIPTION", attribute_text(&model.description)),
        ("VERSION", env!("CARGO_PKG_VERSION").to_string()),
        ("UNIT_DEFINITIONS", generated(write_units)),
        ("LOG_CATEGORIES", generated(write_log_categories)),
        ("MODEL_VARIABLES", generated(write_variables)),
        ("MODEL_STRUCTURE", generated(write_structure)),
    ];
    let render = |guid: &str| {
        fill(TEMPLATE, |key| match key {
            "GUID" => Some(guid),
            _ => parts
                .iter()
                .find(|(k, _)| *k == key)
                .map(|(_, v)| v.as_str()),
        })
    };
    let mut hashed = render("@GUID@")?.into_bytes();
    hashed.push(b'\n');
    hashed.extend_from_slice(model.to_json().as_bytes());
    let guid = format!("{{{}}}", Uuid::new_v5(&Uuid::NAMESPACE_OID, &hashed));
    let xml = render(&guid)?;
    Ok(Description {
        model_identifier: model.name.clone(),
        guid,
        xml,
        variables: table,
        reaction_lines: reaction_lines(&model).0,
        model,
    })
}

/// `text` escaped for an attribute value in double quotes: the five markup characters, and tab,
/// line feed and carriage return as character references (a parser would otherwise turn them
/// into spaces). Control characters never get here: `Model::validate` refuses them.
pub fn attribute_text(text: &str) -> String {
    escape(text)
        .replace('\t', "&#9;")
        .replace('\n', "&#10;")
        .replace('\r', "&#13;")
}

/// Replaces the `@KEY@` fields of `template` (keys: upper case and `_`); values are not scanned
/// again, and an `@` that opens no field stays as it is.
fn fill<'a>(template: &str, value: impl Fn(&str) -> Option<&'a str>) -> Result<String, String> {
    let mut out = String::with_capacity(template.len() * 2);
    let mut rest = template;
    while let Some(start) = rest.find('@') {
        out.push_str(&rest[..start]);
        let after = &rest[start + 1..];
        match after.find('@') {
            Some(end)
                if end > 0
                    && after[..end]
                        .chars()
                        .all(|c| c.is_ascii_uppercase() || c == '_') =>
            {
                let key = &after[..end];
                out.push_str(
                    value(key)
                        .ok_or_else(|| format!("modelDescription.xml.in: unknown field @{key}@"))?,
                );
                rest = &after[end + 1..];
            }
            _ => {
                out.push('@');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    Ok(out)
}

pub(crate) fn write_units(w: &mut Writer<Vec<u8>>, table: &[Variable]) -> io::Result<()> {
    write_units_used(w, &|name| table.iter().any(|v| v.unit == Some(name)))
}

/// `<UnitDefinitions>` of the units for which `used` is true (FMI 3.0: the table's and the
/// arrays').
pub(crate) fn write_units_used(
    w: &mut Writer<Vec<u8>>,
    used: &dyn Fn(&str) -> bool,
) -> io::Result<()> {
    w.create_element("UnitDefinitions")
        .write_inner_content(|w| {
            for (name, [kg, m, s, k, rad]) in UNITS {
                if !used(name) {
                    continue;
                }
                w.create_element("Unit")
                    .with_attribute(("name", name))
                    .write_inner_content(|w| {
                        let exponents = [("kg", kg), ("m", m), ("s", s), ("K", k), ("rad", rad)];
                        let exps: Vec<(&str, String)> = exponents
                            .iter()
                            .filter(|(_, e)| *e != 0)
                            .map(|(n, e)| (*n, e.to_string()))
                            .collect();
                        w.create_element("BaseUnit")
                            .with_attributes(exps.iter().map(|(n, e)| (*n, e.as_str())))
                            .write_empty()?;
                        if name == "rad" {
                            // Angles are read in degrees by people: tools may show them so.
                            w.create_element("DisplayUnit")
                                .with_attribute(("name", "deg"))
                                .with_attribute(("factor", "57.29577951308232"))
                                .write_empty()?;
                        }
                        Ok(())
                    })?;
            }
            Ok(())
        })?;
    Ok(())
}

pub(crate) fn write_log_categories(w: &mut Writer<Vec<u8>>, _: &[Variable]) -> io::Result<()> {
    w.create_element("LogCategories").write_inner_content(|w| {
        for (name, description) in CATEGORIES {
            w.create_element("Category")
                .with_attribute(("name", name))
                .with_attribute(("description", description))
                .write_empty()?;
        }
        Ok(())
    })?;
    Ok(())
}

fn write_variables(w: &mut Writer<Vec<u8>>, table: &[Variable]) -> io::Result<()> {
    w.create_element("ModelVariables")
        .write_inner_content(|w| {
            for v in table {
                w.write_event(Event::Comment(BytesText::from_escaped(format!(
                    " index {} ",
                    v.index()
                ))))?;
                let vr = v.value_reference.to_string();
                let mut e = w
                    .create_element("ScalarVariable")
                    .with_attribute(("name", v.name.as_str()))
                    .with_attribute(("valueReference", vr.as_str()))
                    .with_attribute(("description", v.description.as_str()))
                    .with_attribute(("causality", v.causality.name()))
                    .with_attribute(("variability", v.variability.name()));
                if let Some(initial) = v.initial() {
                    e = e.with_attribute(("initial", initial));
                }
                e.write_inner_content(|w| {
                    let start = v.start.as_ref().map(Value::to_xml);
                    let mut t = w.create_element(v.var_type.name());
                    if let Some(unit) = v.unit {
                        t = t.with_attribute(("unit", unit));
                    }
                    if let Some(start) = &start {
                        t = t.with_attribute(("start", start.as_str()));
                    }
                    t.write_empty()?;
                    Ok(())
                })?;
            }
            Ok(())
        })?;
    Ok(())
}

fn write_structure(w: &mut Writer<Vec<u8>>, table: &[Variable]) -> io::Result<()> {
    let indices = |keep: fn(&Variable) -> bool| {
        table
            .iter()
            .filter(|v| keep(v))
            .map(|v| v.index().to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let inputs = indices(|v| v.causality == Causality::Input);
    // `results.directory` only says where files go: no output depends on it.
    let parameters = indices(Variable::is_model_parameter);
    let outputs: Vec<String> = table
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| v.index().to_string())
        .collect();
    let unknowns = |w: &mut Writer<Vec<u8>>, element: &str, dependencies: &str| -> io::Result<()> {
        w.create_element(element).write_inner_content(|w| {
            for index in &outputs {
                w.create_element("Unknown")
                    .with_attribute(("index", index.as_str()))
                    .with_attribute(("dependencies", dependencies))
                    .write_empty()?;
            }
            Ok(())
        })?;
        Ok(())
    };
    w.create_element("ModelStructure")
        .write_inner_content(|w| {
            unknowns(w, "Outputs", &inputs)?;
            unknowns(w, "InitialUnknowns", &parameters)
        })?;
    Ok(())
}

/// `documentation/index.html`: what the FMU is, how to drive it, and the variable table.
pub fn documentation_html(d: &Description) -> String {
    let e = |s: &str| escape(s).into_owned();
    let m = &d.model;
    let mut rows = String::new();
    for v in &d.variables {
        rows.push_str(&format!(
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            e(&v.name),
            v.value_reference,
            v.var_type.name(),
            v.causality.name(),
            v.unit.unwrap_or(""),
            v.start.as_ref().map(Value::to_xml).unwrap_or_default(),
            e(&v.description)
        ));
    }
    let groups: String = m
        .groups
        .iter()
        .map(|g| {
            format!(
                "<li><code>{}</code>: {} nodes, target displacement {:?} m</li>\n",
                e(&g.name),
                g.nodes.len(),
                g.target
            )
        })
        .collect();
    format!(
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{id} — FMI 2.0 Co-Simulation FMU</title>
<style>body{{font-family:sans-serif;max-width:70em;margin:2em auto}}table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:2px 6px;text-align:left}}</style>
</head><body>
<h1>{id}</h1>
<p>{description}</p>
<p>An ETFE membrane (constant-strain triangles, geometrically nonlinear) sliding with Coulomb friction over
supports through friction gap elements, solved by Newton–Raphson with load increments and cut-backs
(<code>membrane-contact</code> {version}). FMI 2.0 Co-Simulation, GUID <code>{guid}</code>.</p>
<p>Model: {nodes} nodes, {triangles} triangles, {gaps} gaps. Boundary groups:</p>
<ul>
{groups}</ul>
<h2>How to drive it</h2>
<ul>
<li>Time is a pseudo-time (load parameter). The default experiment runs from 0 to 1 with step 0.05:
ramp each group's inputs <code>&lt;group&gt;.dx/.dy/.dz</code> to its target over [0, 1].</li>
<li>The inputs set before <code>fmi2DoStep</code> are the boundary displacements reached at the end of the step,
applied in <code>solver.incrementsPerStep</code> equal increments. Any step size works.</li>
<li>A step that cannot converge returns <code>fmi2Discard</code> and keeps the last converged state and time:
set a smaller change and call <code>fmi2DoStep</code> again from the same time.</li>
<li><code>mu</code> sets the friction coefficient of every gap from the next step on (the model's own values apply until it is set).</li>
<li><code>frictionLaw</code> (a String parameter, <code>fmi2SetString</code>): <code>isotropic</code> (Coulomb cone) or
<code>sliding-direction</code> (the paper's law: each gap slides along its local x only, y stays elastic) for every gap.</li>
<li>Parameters are fixed: set them before <code>fmi2ExitInitializationMode</code>, which builds the analysis
(and reports an invalid value with <code>fmi2Error</code>).</li>
<li>FMU states can be saved, restored and serialized (<code>canGetAndSetFMUstate</code>, <code>canSerializeFMUstate</code>).</li>
<li><code>results.directory</code> (set with <code>fmi2SetString</code> before <code>fmi2ExitInitializationMode</code>):
the instance writes <code>&lt;dir&gt;/{id}_film_NNNN.vtu</code> (film: displacement, stresses, strains, wrinkling) and
<code>&lt;dir&gt;/{id}_gaps_NNNN.vtu</code> (gap lines: slip, forces, status) for the initial state (0000) and after every step, and
rewrites <code>&lt;dir&gt;/{id}_film.pvd</code> and <code>&lt;dir&gt;/{id}_gaps.pvd</code> (open them in ParaView).
<code>results.vtkFormat</code>: <code>binary</code> (raw appended data, the default) or <code>ascii</code>.
A failed write returns <code>fmi2Warning</code>; the step is kept.</li>
</ul>
<h2>Variables</h2>
<table>
<tr><th>name</th><th>value reference</th><th>type</th><th>causality</th><th>unit</th><th>start</th><th>description</th></tr>
{rows}</table>
</body></html>
"#,
        id = e(&d.model_identifier),
        description = e(&m.description),
        version = env!("CARGO_PKG_VERSION"),
        guid = d.guid,
        nodes = m.nodes.len(),
        triangles = m.triangles.len(),
        gaps = m.gaps.len(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::specimens::ParallelArch;

    fn specimen() -> Description {
        describe(&Source::ParallelArch(ParallelArch::default())).unwrap()
    }

    #[test]
    fn guid_is_stable_and_filled_in() {
        let (a, b) = (specimen(), specimen());
        assert_eq!(a.guid, b.guid);
        assert_eq!(a.guid.len(), 38);
        assert!(a.xml.contains(&format!("guid=\"{}\"", a.guid)));
        assert!(!a.xml.contains('@'), "every field replaced");
        assert_eq!(a.model_identifier, "ParallelArch");
    }

    #[test]
    fn guid_changes_with_the_interface() {
        let a = specimen();
        let b = describe(&Source::ParallelArch(ParallelArch::with_height(0.2))).unwrap();
        assert_ne!(
            a.guid, b.guid,
            "a different start value is a different interface"
        );
    }

    #[test]
    fn guid_changes_with_the_model_content_behind_the_same_interface() {
        let model = ParallelArch::default().model().unwrap();
        let mut moved = model.clone();
        moved.gaps[2].initial_gap += 1e-4;
        let a = describe(&Source::Model(model)).unwrap();
        let b = describe(&Source::Model(moved)).unwrap();
        let interface = |d: &Description| d.xml.replace(&d.guid, "");
        assert_eq!(
            interface(&a),
            interface(&b),
            "the same variables and start values"
        );
        assert_ne!(a.guid, b.guid, "an initial gap is part of the model");
    }

    #[test]
    fn structure_lists_every_output_once() {
        let d = specimen();
        let outputs = d
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .count();
        let structure = &d.xml[d.xml.find("<ModelStructure>").unwrap()..];
        let outputs_part = &structure[..structure.find("</Outputs>").unwrap()];
        assert_eq!(outputs_part.matches("<Unknown ").count(), outputs);
        assert_eq!(structure.matches("<Unknown ").count(), 2 * outputs);
        // Element order required by the schema.
        let pos = |s: &str| d.xml.find(s).unwrap_or_else(|| panic!("{s}"));
        assert!(pos("<CoSimulation") < pos("<UnitDefinitions>"));
        assert!(pos("<UnitDefinitions>") < pos("<LogCategories>"));
        assert!(pos("<LogCategories>") < pos("<DefaultExperiment"));
        assert!(pos("<DefaultExperiment") < pos("<ModelVariables>"));
    }

    #[test]
    fn text_is_escaped() {
        let mut model = ParallelArch::default().model().unwrap();
        model.name = "My_model".into();
        model.description = "a <b> & \"c\" @GUID@ 100%".into();
        let d = describe(&Source::Model(model)).unwrap();
        assert!(
            d.xml
                .contains("description=\"a &lt;b&gt; &amp; &quot;c&quot; @GUID@ 100%\"")
        );
        let html = documentation_html(&d);
        assert!(html.contains("a &lt;b&gt;") && html.contains("<code>G1.slip</code>"));
    }

    /// The characters XML 1.0 allows (production `Char`).
    fn is_xml_char(c: char) -> bool {
        matches!(c, '\t' | '\n' | '\r' | '\u{20}'..='\u{D7FF}' | '\u{E000}'..='\u{FFFD}' | '\u{10000}'..)
    }

    /// Random descriptions (deterministic xorshift): markup characters, `@`, quotes, white
    /// space, C0/C1 controls, U+FFFE/U+FFFF, BMP and astral code points. Property: validation
    /// refuses exactly the strings with a character XML cannot carry, naming the field; for every
    /// other string the rendered modelDescription.xml holds only XML characters, parses with
    /// quick-xml to the end, and its `description` attribute reads back as the string.
    #[test]
    fn any_accepted_description_renders_well_formed_xml_that_reads_back() {
        let base = ParallelArch::default().model().unwrap();
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let (mut accepted, mut refused) = (0, 0);
        for _ in 0..300 {
            let len = next() % 24;
            let text: String = (0..len)
                .filter_map(|_| {
                    let r = next();
                    let code = match r % 24 {
                        0 => (r >> 8) as u32 % 0x20,
                        1 => 0x7f + (r >> 8) as u32 % 0x21,
                        2 | 7..=10 => [b'<', b'>', b'&', b'"', b'\'', b'@', b'%', b';']
                            [(r >> 8) as usize % 8] as u32,
                        3 => [0xFFFE, 0xFFFF, 0xFFFD, 0xE000, 0xD7FF][(r >> 8) as usize % 5],
                        4 | 11..=13 => 0x10000 + (r >> 8) as u32 % 0x100000,
                        5 | 14..=17 => (r >> 8) as u32 % 0xD800,
                        _ => 0x20 + (r >> 8) as u32 % 0x5f,
                    };
                    char::from_u32(code)
                })
                .collect();
            let mut model = base.clone();
            model.description = text.clone();
            let verdict = describe(&Source::Model(model));
            let allowed = text
                .chars()
                .all(|c| is_xml_char(c) && (!c.is_control() || matches!(c, '\t' | '\n' | '\r')));
            match verdict {
                Err(e) => {
                    refused += 1;
                    assert!(!allowed, "{text:?} refused: {e}");
                    assert!(e.starts_with("model description: character U+"), "{e}");
                }
                Ok(d) => {
                    accepted += 1;
                    assert!(allowed, "{text:?} accepted");
                    assert!(d.xml.chars().all(is_xml_char), "{text:?}");
                    let mut reader = quick_xml::Reader::from_str(&d.xml);
                    let mut read_back = None;
                    loop {
                        match reader
                            .read_event()
                            .unwrap_or_else(|e| panic!("{text:?}: {e}"))
                        {
                            quick_xml::events::Event::Eof => break,
                            quick_xml::events::Event::Start(e)
                                if e.name().0 == "fmiModelDescription" =>
                            {
                                let a = e.try_get_attribute("description").unwrap().unwrap();
                                read_back = Some(
                                    a.normalized_value(quick_xml::XmlVersion::Explicit1_0)
                                        .unwrap()
                                        .into_owned(),
                                );
                            }
                            _ => {}
                        }
                    }
                    assert_eq!(read_back.as_deref(), Some(text.as_str()));
                }
            }
        }
        assert!(
            accepted > 50 && refused > 50,
            "{accepted} accepted, {refused} refused"
        );
    }

    #[test]
    fn fill_handles_stray_at_signs() {
        let out = fill("a@b @X@ c@ x@@y", |k| (k == "X").then_some("1")).unwrap();
        assert_eq!(out, "a@b 1 c@ x@@y");
        assert!(fill("@NOPE@", |_| None).unwrap_err().contains("@NOPE@"));
    }
}
