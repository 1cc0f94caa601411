//! The variable table of a model of scalars and the `modelDescription.xml` it generates: the
//! one source of the interface (value references, causalities, units, start values, the
//! dependencies of ModelStructure).

use std::fmt::Write;

/// `causality`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    Input,
    Output,
}

/// `variability`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Fixed,
    Tunable,
    /// Changes only at communication points: the variability of a Boolean input.
    Discrete,
    Continuous,
}

/// A variable's type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    /// `Real` (FMI 2.0) / `Float64` (FMI 3.0).
    Real,
    /// `Boolean`: the model holds it as 0 or 1 among its reals; it has no unit.
    Boolean,
}

/// One Real (FMI 2.0) / Float64 (FMI 3.0) or Boolean scalar.
#[derive(Clone, Copy, Debug)]
pub struct Variable {
    pub name: &'static str,
    pub vr: u32,
    pub var_type: VarType,
    pub causality: Causality,
    pub variability: Variability,
    pub unit: &'static str,
    /// The start value (inputs and parameters; a Boolean's 0 or 1); outputs have none
    /// (`initial` calculated).
    pub start: Option<f64>,
    pub description: &'static str,
}

/// An output and the value references it depends on (ModelStructure).
#[derive(Clone, Copy, Debug)]
pub struct Dependencies {
    pub output: u32,
    pub on: &'static [u32],
}

/// What a model's `modelDescription.xml` is made of.
#[derive(Clone, Copy, Debug)]
pub struct Description {
    pub model_name: &'static str,
    pub model_identifier: &'static str,
    /// The GUID (FMI 2.0), also the instantiation token (FMI 3.0).
    pub token: &'static str,
    pub description: &'static str,
    pub generation_tool: &'static str,
    pub can_get_and_set_fmu_state: bool,
    /// `canSerializeFMUstate` (the model implements `ScalarModel::to_numbers`); written only
    /// where true.
    pub can_serialize_fmu_state: bool,
    pub provides_directional_derivative: bool,
    /// Unit name and the attributes of its `<BaseUnit>` (`kg="1" m="1" s="-2"`).
    pub units: &'static [(&'static str, &'static str)],
    /// Declared log categories: name, description (empty: none).
    pub log_categories: &'static [(&'static str, &'static str)],
    /// `startTime`, `stopTime`, `stepSize`.
    pub default_experiment: Option<(f64, f64, f64)>,
    /// In the order of `<ModelVariables>`.
    pub variables: &'static [Variable],
    pub outputs: &'static [Dependencies],
    pub initial_unknowns: &'static [Dependencies],
}

impl Variable {
    /// Its attributes as both versions write them: name to description (FMI 2.0's
    /// `ScalarVariable`), and unit and start (FMI 2.0's `Real`, `Boolean`: start alone); FMI
    /// 3.0's `Float64` and `Boolean` have both.
    fn attributes(&self) -> (String, String) {
        if self.var_type == VarType::Boolean {
            let start = self
                .start
                .map_or(String::new(), |s| format!("start=\"{}\"", s != 0.0));
            return (self.head(), start);
        }
        let start = self
            .start
            .map_or(String::new(), |s| format!(" start=\"{s}\""));
        (
            self.head(),
            format!("unit=\"{}\"{start}", escape(self.unit)),
        )
    }

    /// The attributes from name to description.
    fn head(&self) -> String {
        format!(
            "name=\"{}\" valueReference=\"{}\" causality=\"{}\" variability=\"{}\" description=\"{}\"",
            escape(self.name),
            self.vr,
            causality(self.causality),
            variability(self.variability),
            escape(self.description)
        )
    }

    /// The element's name: FMI 2.0's (inside `ScalarVariable`) and FMI 3.0's.
    fn element(&self) -> (&'static str, &'static str) {
        match self.var_type {
            VarType::Real => ("Real", "Float64"),
            VarType::Boolean => ("Boolean", "Boolean"),
        }
    }
}

impl Description {
    /// The variable of value reference `vr`.
    pub fn variable(&self, vr: u32) -> Option<&'static Variable> {
        self.variables.iter().find(|v| v.vr == vr)
    }

    /// The 1-based index of `vr` in `<ModelVariables>`.
    fn index(&self, vr: u32) -> usize {
        let i = self.variables.iter().position(|v| v.vr == vr);
        i.expect("ModelStructure names a variable of the table") + 1
    }

    /// The FMI 2.0 `modelDescription.xml`.
    pub fn fmi2_xml(&self) -> String {
        let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            x,
            "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{}\" guid=\"{}\"\n  description=\"{}\"\n  generationTool=\"{}\" variableNamingConvention=\"structured\" numberOfEventIndicators=\"0\">",
            escape(self.model_name),
            escape(self.token),
            escape(self.description),
            escape(self.generation_tool)
        );
        let flags = [
            ("canHandleVariableCommunicationStepSize", true),
            ("canGetAndSetFMUstate", self.can_get_and_set_fmu_state),
            ("canSerializeFMUstate", self.can_serialize_fmu_state),
            ("canNotUseMemoryManagementFunctions", true),
            (
                "providesDirectionalDerivative",
                self.provides_directional_derivative,
            ),
        ];
        let _ = write!(
            x,
            "  <CoSimulation modelIdentifier=\"{}\"",
            self.model_identifier
        );
        // The first flag on the element's line, the others on a continuation line.
        for (k, (flag, _)) in flags.iter().filter(|(_, on)| *on).enumerate() {
            let gap = if k == 1 { "\n    " } else { " " };
            let _ = write!(x, "{gap}{flag}=\"true\"");
        }
        x.push_str("/>\n");
        self.units_and_categories(&mut x);
        x.push_str("  <ModelVariables>\n");
        for (i, v) in self.variables.iter().enumerate() {
            let (head, unit) = v.attributes();
            let _ = writeln!(
                x,
                "    <!-- {} --><ScalarVariable {head}><{} {unit}/></ScalarVariable>",
                i + 1,
                v.element().0
            );
        }
        x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
        for (tag, list) in [
            ("Outputs", self.outputs),
            ("InitialUnknowns", self.initial_unknowns),
        ] {
            let _ = writeln!(x, "    <{tag}>");
            for d in list {
                let _ = writeln!(x, "      <Unknown {}/>", self.unknown(d));
            }
            let _ = writeln!(x, "    </{tag}>");
        }
        x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
        x
    }

    /// The value reference of the FMI 3.0 description's independent variable `time` (FMI 3.0
    /// requires one): the one after the table's last.
    pub fn time_vr(&self) -> u32 {
        self.variables.iter().map(|v| v.vr + 1).max().unwrap_or(0)
    }

    /// The FMI 3.0 `modelDescription.xml`: the same table as Float64 (and Boolean) variables, `time` added
    /// ([`Self::time_vr`]), the token as `instantiationToken`, dependencies by value reference.
    pub fn fmi3_xml(&self) -> String {
        let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            x,
            "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"{}\" instantiationToken=\"{}\"\n  description=\"{}\"\n  generationTool=\"{}\" variableNamingConvention=\"structured\">",
            escape(self.model_name),
            escape(self.token),
            escape(self.description),
            escape(self.generation_tool)
        );
        let _ = writeln!(
            x,
            "  <CoSimulation modelIdentifier=\"{}\" canHandleVariableCommunicationStepSize=\"true\"\n    canGetAndSetFMUState=\"{}\"{} providesDirectionalDerivatives=\"{d}\" providesAdjointDerivatives=\"{d}\" hasEventMode=\"false\"/>",
            self.model_identifier,
            self.can_get_and_set_fmu_state,
            if self.can_serialize_fmu_state {
                " canSerializeFMUState=\"true\""
            } else {
                ""
            },
            d = self.provides_directional_derivative
        );
        self.units_and_categories(&mut x);
        x.push_str("  <ModelVariables>\n");
        let _ = writeln!(
            x,
            "    <Float64 name=\"time\" valueReference=\"{}\" causality=\"independent\" variability=\"continuous\" description=\"simulation time\"/>",
            self.time_vr()
        );
        for v in self.variables {
            let (head, unit) = v.attributes();
            let _ = writeln!(x, "    <{} {head} {unit}/>", v.element().1);
        }
        x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
        for (tag, list) in [
            ("Output", self.outputs),
            ("InitialUnknown", self.initial_unknowns),
        ] {
            for d in list {
                let on: Vec<String> = d.on.iter().map(|vr| vr.to_string()).collect();
                let _ = writeln!(
                    x,
                    "    <{tag} valueReference=\"{}\" dependencies=\"{}\"/>",
                    d.output,
                    on.join(" ")
                );
            }
        }
        x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
        x
    }

    /// Whether `dir/modelDescription.xml` and `dir/modelDescription3.xml` (a model FMU's
    /// committed descriptions, the files its packer ships) are [`Self::fmi2_xml`] and
    /// [`Self::fmi3_xml`] to the byte; with `write`, writes them so. Err names the file that
    /// differs and the command that regenerates it (`regenerate`).
    pub fn committed(&self, dir: &str, write: bool, regenerate: &str) -> Result<(), String> {
        for (file, generated) in [
            ("modelDescription.xml", self.fmi2_xml()),
            ("modelDescription3.xml", self.fmi3_xml()),
        ] {
            let path = format!("{dir}/{file}");
            if write {
                std::fs::write(&path, generated).map_err(|e| format!("{path}: {e}"))?;
            } else if std::fs::read_to_string(&path).map_err(|e| format!("{path}: {e}"))?
                != generated
            {
                return Err(format!(
                    "{path} is not the generated text: regenerate it: {regenerate}"
                ));
            }
        }
        Ok(())
    }

    /// `<UnitDefinitions>`, `<LogCategories>`, `<DefaultExperiment>`.
    fn units_and_categories(&self, x: &mut String) {
        if !self.units.is_empty() {
            x.push_str("  <UnitDefinitions>\n");
            for (name, base) in self.units {
                let base = if base.is_empty() {
                    String::new()
                } else {
                    format!(" {base}")
                };
                let _ = writeln!(
                    x,
                    "    <Unit name=\"{}\"><BaseUnit{base}/></Unit>",
                    escape(name)
                );
            }
            x.push_str("  </UnitDefinitions>\n");
        }
        if !self.log_categories.is_empty() {
            x.push_str("  <LogCategories>\n");
            for (name, description) in self.log_categories {
                let description = if description.is_empty() {
                    String::new()
                } else {
                    format!(" description=\"{}\"", escape(description))
                };
                let _ = writeln!(x, "    <Category name=\"{name}\"{description}/>");
            }
            x.push_str("  </LogCategories>\n");
        }
        if let Some((start, stop, step)) = self.default_experiment {
            let _ = writeln!(
                x,
                "  <DefaultExperiment startTime=\"{start}\" stopTime=\"{stop}\" stepSize=\"{step}\"/>"
            );
        }
    }

    /// The attributes of an `<Unknown>`: index and dependencies (indices, ascending).
    fn unknown(&self, d: &Dependencies) -> String {
        let mut on: Vec<usize> = d.on.iter().map(|&vr| self.index(vr)).collect();
        on.sort_unstable();
        let list: Vec<String> = on.iter().map(|i| i.to_string()).collect();
        let mut a = format!(
            "index=\"{}\" dependencies=\"{}\"",
            self.index(d.output),
            list.join(" ")
        );
        if !on.is_empty() {
            let _ = write!(
                a,
                " dependenciesKind=\"{}\"",
                vec!["dependent"; on.len()].join(" ")
            );
        }
        a
    }
}

/// A model FMU's two tests of its committed descriptions ([`Description::committed`], files in
/// the package's folder): that they are the texts generated from `$description`, and, ignored,
/// one that writes them (`cargo test --release -p $package --test model_description --
/// --ignored`). Invoked in the package's `tests/model_description.rs`.
#[macro_export]
macro_rules! committed_description_tests {
    ($description:expr, $package:literal) => {
        /// How to regenerate the files.
        const REGENERATE: &str = concat!(
            "cargo test --release -p ",
            $package,
            " --test model_description -- --ignored"
        );

        #[test]
        fn the_committed_descriptions_are_the_generated_ones() {
            let dir = env!("CARGO_MANIFEST_DIR");
            $description.committed(dir, false, REGENERATE).unwrap();
        }

        /// Writes the files from the table (run after changing it).
        #[test]
        #[ignore]
        fn write_the_committed_descriptions() {
            let dir = env!("CARGO_MANIFEST_DIR");
            $description.committed(dir, true, REGENERATE).unwrap();
        }
    };
}

fn causality(c: Causality) -> &'static str {
    match c {
        Causality::Parameter => "parameter",
        Causality::Input => "input",
        Causality::Output => "output",
    }
}

fn variability(v: Variability) -> &'static str {
    match v {
        Variability::Fixed => "fixed",
        Variability::Tunable => "tunable",
        Variability::Discrete => "discrete",
        Variability::Continuous => "continuous",
    }
}

/// `text` escaped for a double-quoted attribute (`&`, `<`, `>`, `"`).
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
