//! One ScalarVariable: its base type, causality and variability, its value, and what it stands
//! for in the core ([`Binding`]), with the check every value set or restored goes through
//! ([`Variable::check_value`]). Which variables an FMU has: the table in `variables.rs`.

use serde::{Deserialize, Serialize};

use crate::mech::model::MAX_FRICTION;

/// Base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
}

impl VarType {
    pub fn name(self) -> &'static str {
        match self {
            Self::Real => "Real",
            Self::Integer => "Integer",
            Self::Boolean => "Boolean",
            Self::String => "String",
        }
    }
}

/// `causality` (the ones this FMU uses).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    Input,
    Output,
    Independent,
}

impl Causality {
    pub fn name(self) -> &'static str {
        match self {
            Self::Parameter => "parameter",
            Self::Input => "input",
            Self::Output => "output",
            Self::Independent => "independent",
        }
    }
}

/// `variability` (the ones this FMU uses).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Fixed,
    Discrete,
    Continuous,
}

impl Variability {
    pub fn name(self) -> &'static str {
        match self {
            Self::Fixed => "fixed",
            Self::Discrete => "discrete",
            Self::Continuous => "continuous",
        }
    }
}

/// A value of any of the types (not `Copy`: a String owns its text).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Value {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(String),
}

impl Value {
    pub fn var_type(&self) -> VarType {
        match self {
            Self::Real(_) => VarType::Real,
            Self::Integer(_) => VarType::Integer,
            Self::Boolean(_) => VarType::Boolean,
            Self::String(_) => VarType::String,
        }
    }

    /// The value as written in a `start` attribute (shortest round-trip form for reals;
    /// strings as they are, the XML writer escapes them).
    pub fn to_xml(&self) -> String {
        match self {
            Self::Real(v) => format_real(*v),
            Self::Integer(v) => v.to_string(),
            Self::Boolean(v) => v.to_string(),
            Self::String(v) => v.clone(),
        }
    }
}

/// A real in `xs:double` form that parses back to the same bits (Rust's `{:?}` is the shortest
/// round-trip form; `1e-8` rather than `0.00000001`).
pub fn format_real(v: f64) -> String {
    format!("{v:?}")
}

/// A real for a message: plain between 1e-4 and 1e15 in magnitude (`0.25`, `11`), else in
/// `{:e}` form (`1e300`, `5e-324`), so that no huge or tiny value prints as hundreds of digits.
pub fn message_real(v: f64) -> String {
    crate::mech::model::message_number(v)
}

/// "n" before a word starting with a vowel sound ("an Integer"), else "".
pub fn article(t: VarType) -> &'static str {
    if t == VarType::Integer { "n" } else { "" }
}

/// What a variable stands for: the instance reads and writes the core through this.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binding {
    Time,
    Friction,
    /// Input displacement of a group along axis 0, 1, 2.
    GroupDisplacement {
        group: usize,
        axis: usize,
    },
    /// Input angle of a hinged group about its axis.
    GroupAngle(usize),
    /// Input pressure of a pressure set.
    Pressure(usize),
    /// Input force per node of a force set along axis 0, 1, 2.
    NodalForce {
        set: usize,
        axis: usize,
    },
    /// Film density (self-weight).
    Density,
    /// Film temperature (°C).
    Temperature,
    /// Gravity component along axis 0, 1, 2.
    Gravity(usize),
    ArchHeight,
    YoungsModulus,
    PoissonRatio,
    Thickness,
    /// Prestress component 0 (x), 1 (y), 2 (xy).
    Prestress(usize),
    /// Tension-field film on (true) or off.
    Wrinkling,
    NormalStiffness(usize),
    TangentialStiffness(usize),
    /// Friction law of every gap (a String parameter; "" keeps each gap's own).
    FrictionLaw,
    DisplacementTolerance,
    ResidualTolerance,
    MaxIterations,
    MaxCutbacks,
    IncrementsPerStep,
    UseJuRowlands,
    /// The viscous stabilization's rows of the strategy table (true) or none.
    Stabilization,
    /// Threads of the element assembly (0: automatic).
    Threads,
    /// Directory of the VTK output (a String parameter; "" = none). Not a model parameter:
    /// it does not change the analysis, and no output depends on it.
    ResultsDirectory,
    /// Encoding of the VTK files (a String parameter, `binary` or `ascii`). Not a model
    /// parameter either.
    VtkFormat,
    SlipX(usize),
    SlipY(usize),
    NormalForce(usize),
    FrictionForce(usize),
    /// Friction force on the film along the gap's local axis 0 (x) or 1 (y).
    GapFriction {
        gap: usize,
        axis: usize,
    },
    GapStatus(usize),
    /// Total reaction of a group along axis 0, 1, 2.
    Reaction {
        group: usize,
        axis: usize,
    },
    /// Moment of a hinged group's reaction about its axis.
    HingeMoment(usize),
    Iterations,
    Cutbacks,
    Residual,
    StabilizationEnergy,
    StabilizationRatio,
    /// Increments solved with the viscous stabilization in the last step.
    StabilizedIncrements,
    /// The stabilization's work over the last step over the strain energy.
    DissipationRatio,
    MaxEquivalentStress,
    WrinkledElements,
    SlackElements,
    /// Elasto-plastic film only: the triangles that have yielded, the smallest thickness.
    YieldedElements,
    MinThickness,
    /// Elasto-plastic film only: an element set's largest equivalent plastic strain.
    SetMaxPlasticStrain(usize),
    /// Total reaction of a named support set along axis 0, 1, 2.
    SupportReaction {
        set: usize,
        axis: usize,
    },
    /// Sum of all restraint forces along axis 0, 1, 2.
    TotalReaction(usize),
    /// Largest axial force of a cable.
    CableForce(usize),
    /// Slip along the support, normal force, friction force and status of a curved-support
    /// contact (model order).
    SurfaceSlip(usize),
    SurfaceNormalForce(usize),
    SurfaceFrictionForce(usize),
    /// Input: the supply's gauge pressure of a chamber (ignored once its air is enclosed).
    ChamberSupply(usize),
    /// Input: whether a chamber's air is enclosed (its valve closed).
    ChamberSealed(usize),
    /// Input: a chamber's air temperature rise above its reference (K).
    ChamberHeating(usize),
    /// Input: air mass flow into a sealed chamber (kg/s), integrated over the step.
    ChamberMassFlow(usize),
    /// A chamber's air temperature (K).
    ChamberTemperature(usize),
    /// A chamber's air mass (kg).
    ChamberMass(usize),
    /// Gauge pressure of a chamber's air.
    ChamberPressure(usize),
    /// Volume of a chamber.
    ChamberVolume(usize),
    /// Total normal force of a layer contact (both passes).
    LayerNormalForce(usize),
    /// Largest slip between the layers of a layer contact.
    LayerMaxSlip(usize),
    /// Mass flow through an orifice over the last step (kg/s, positive from its `from` chamber
    /// to its `to`).
    OrificeMassFlow(usize),
    SurfaceStatus(usize),
    /// Displacement of an output point along axis 0, 1, 2.
    PointDisplacement {
        point: usize,
        axis: usize,
    },
    /// One quantity of an element set's field summary.
    SetSummary {
        set: usize,
        quantity: SummaryQuantity,
    },
}

/// The quantities of a [`crate::mech::results::summary::FieldSummary`], each an FMU output per element set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SummaryQuantity {
    MaxPrincipalStress,
    MinPrincipalStress,
    MaxEquivalentStress,
    MaxStrain,
    CompressedArea,
}

impl SummaryQuantity {
    /// Every quantity with its variable-name suffix, unit and description.
    pub const ALL: [(Self, &'static str, &'static str, &'static str); 5] = [
        (
            Self::MaxPrincipalStress,
            "maxPrincipalStress",
            "Pa",
            "largest major principal stress",
        ),
        (
            Self::MinPrincipalStress,
            "minPrincipalStress",
            "Pa",
            "smallest minor principal stress (negative: compressed)",
        ),
        (
            Self::MaxEquivalentStress,
            "maxEquivalentStress",
            "Pa",
            "largest von Mises stress",
        ),
        (
            Self::MaxStrain,
            "maxStrain",
            "1",
            "largest major principal Green-Lagrange strain",
        ),
        (
            Self::CompressedArea,
            "compressedArea",
            "m2",
            "reference area of the triangles wrinkled or slack (tension field) or with a negative minor principal stress",
        ),
    ];

    /// This quantity of `summary`.
    pub fn of(self, summary: &crate::mech::results::summary::FieldSummary) -> f64 {
        match self {
            Self::MaxPrincipalStress => summary.max_principal_stress,
            Self::MinPrincipalStress => summary.min_principal_stress,
            Self::MaxEquivalentStress => summary.max_equivalent_stress,
            Self::MaxStrain => summary.max_strain,
            Self::CompressedArea => summary.compressed_area,
        }
    }
}

/// One ScalarVariable.
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    pub name: String,
    pub value_reference: u32,
    pub var_type: VarType,
    pub causality: Causality,
    pub variability: Variability,
    /// Start value: parameters and inputs have one, outputs and `time` none.
    pub start: Option<Value>,
    pub unit: Option<&'static str>,
    pub description: String,
    pub binding: Binding,
}

impl Variable {
    /// Whether the variable is a parameter of the analysis (everything but `results.*`):
    /// changing one rebuilds the analysis, and the outputs' initial values depend on them.
    pub fn is_model_parameter(&self) -> bool {
        self.causality == Causality::Parameter
            && !matches!(self.binding, Binding::ResultsDirectory | Binding::VtkFormat)
    }

    /// `initial` as written in the XML (`None`: omitted, the default applies).
    pub fn initial(&self) -> Option<&'static str> {
        match self.causality {
            Causality::Parameter => Some("exact"),
            Causality::Output => Some("calculated"),
            Causality::Input | Causality::Independent => None,
        }
    }

    /// Checks a value for this variable as `fmi2SetReal/Integer/Boolean/String` do (and
    /// `fmi2DeSerializeFMUstate` for every stored value): its type, a finite Real, `mu` in
    /// `[0, MAX_FRICTION]`, a String without NUL, a known friction law or VTK encoding. The
    /// message names the variable.
    pub fn check_value(&self, value: &Value) -> Result<(), String> {
        if value.var_type() != self.var_type {
            return Err(format!(
                "{} is a{} {}, not a{} {}",
                self.name,
                article(self.var_type),
                self.var_type.name(),
                article(value.var_type()),
                value.var_type().name()
            ));
        }
        match (self.binding, value) {
            (_, Value::Real(x)) if !x.is_finite() => Err(format!(
                "{} = {}: values must be finite",
                self.name,
                message_real(*x)
            )),
            (Binding::Friction, Value::Real(x)) if !(0.0..=MAX_FRICTION).contains(x) => {
                Err(format!(
                    "{} = {}: the friction coefficient must be ≥ 0 and ≤ {MAX_FRICTION}",
                    self.name,
                    message_real(*x)
                ))
            }
            (_, Value::String(text)) if text.contains('\0') => {
                Err(format!("{} holds a NUL character", self.name))
            }
            (Binding::FrictionLaw, Value::String(name)) if !name.is_empty() => name
                .parse::<crate::mech::FrictionLaw>()
                .map(drop)
                .map_err(|e| format!("{}: {e}", self.name)),
            (Binding::VtkFormat, Value::String(name)) => name
                .parse::<crate::mech::results::vtk::Encoding>()
                .map(drop)
                .map_err(|e| format!("{}: {e}", self.name)),
            _ => Ok(()),
        }
    }

    /// The ModelStructure index (1-based position in ModelVariables).
    pub fn index(&self) -> usize {
        self.value_reference as usize + 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_reals_are_short_for_every_magnitude() {
        let cases = [
            (1e300, "1e300"),
            (-1e300, "-1e300"),
            (11.0, "11"),
            (0.25, "0.25"),
            (0.0, "0"),
            (123456.5, "123456.5"),
            (1e15, "1e15"),
            (2.5e-7, "2.5e-7"),
            (5e-324, "5e-324"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
        ];
        for (v, text) in cases {
            assert_eq!(message_real(v), text);
        }
    }

    #[test]
    fn reals_round_trip_through_their_xml_form() {
        for v in [0.3, 1e-8, 2.5e8, 0.1 + 0.2, -0.0, 1.0, 123456789.123] {
            assert_eq!(
                Value::Real(v).to_xml().parse::<f64>().unwrap().to_bits(),
                v.to_bits()
            );
        }
    }
}
