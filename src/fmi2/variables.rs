//! The variable table: the one description of the FMU's interface.
//!
//! [`variables`] derives it from the model (gap and group names become name prefixes). Both the
//! C functions (value-reference lookup, in `values.rs`) and `modelDescription.xml` (in
//! `description.rs`) are built from it, when the FMU is packed and again when it is instantiated.
//! What one variable is (type, causality, value, binding): `scalar_variable.rs`.
//!
//! Why this file is above 800 lines: it is the table, one list in the order of the XML: the
//! [`variables`] function calls one function per family of variables (the inputs of each kind,
//! the parameters, the outputs of each element kind) in that order, and those follow it in the
//! same order; with them the names the table reserves and the inputs it gives a step. A new
//! family is one function and one call at its place in the list.
//!
//! Value references are the positions in the table (0-based), unique over all types; the
//! ModelStructure `index` of a variable is its value reference + 1.
//!
//! | name | type | causality | unit | meaning |
//! |---|---|---|---|---|
//! | `time` | Real | independent | | pseudo-time of the load path |
//! | `mu` | Real | input | 1 | friction coefficient of every gap and curved-support contact (applied once set; models with gaps or curved supports only) |
//! | `<group>.dx/.dy/.dz` | Real | input | m | displacement of the group reached at the end of a step (prescribed components only) |
//! | `<group>.angle` | Real | input | rad | angle of a hinged group about its axis reached at the end of a step |
//! | `<pressureSet>.pressure` | Real | input | Pa | follower pressure of the set reached at the end of a step (start: the model's) |
//! | `<forceSet>.Fx/.Fy/.Fz` | Real | input | N | force on each node of the set reached at the end of a step (start: the model's) |
//! | `archHeight` | Real | parameter | m | ParallelArch only: the model is regenerated from it |
//! | `film.E`, `film.nu`, `film.thickness`, `film.prestressX/Y/XY` | Real | parameter | Pa, 1, m, Pa | film |
//! | `film.wrinkling` | Boolean | parameter | | tension-field film (start: the model's `wrinkling`) |
//! | `film.density` | Real | parameter | kg/m3 | film density for self-weight (start: the model's) |
//! | `film.temperature` | Real | parameter | (°C) | film temperature in [0, 50]; E and the hardening table scale from 23 °C (start: the model's) |
//! | `gravity.x/.y/.z` | Real | parameter | m/s2 | gravity on the film's mass, ramped in over the first step (start: the model's) |
//! | `<gap>.kn`, `<gap>.ks` | Real | parameter | N/m | gap penalties |
//! | `frictionLaw` | String | parameter | | `isotropic` or `sliding-direction` for every gap and curved support; start: the model's when uniform, else "" (each keeps its own) |
//! | `solver.*Tolerance`, `solver.maxIterations`, `solver.maxCutbacks`, `solver.incrementsPerStep`, `solver.useJuRowlands`, `solver.stabilization` | | parameter | | Newton settings |
//! | `solver.threads` | Integer | parameter | | threads of the element assembly and the factorization (0: automatic); results identical for every count |
//! | `results.directory` | String | parameter | | VTK output of every communication step ("": none) |
//! | `results.vtkFormat` | String | parameter | | `binary` (raw appended, the default) or `ascii` VTK files |
//! | `<gap>.slip/.slipY/.normalForce/.frictionForce` | Real | output | m, N | gap results |
//! | `<gap>.frictionX/.frictionY` | Real | output | N | friction force on the film, local x, y (signed) |
//! | `<gap>.status` | Integer | output | | 0 open, 1 stick, 2 slip |
//! | `<group>.Rx/.Ry/.Rz` | Real | output | N | total reaction of the group (prescribed components only) |
//! | `<group>.moment` | Real | output | N.m | moment of a hinged group's reaction about its axis |
//! | `solver.iterations/.cutbacks/.residual` | | output | | Newton statistics of the last step |
//! | `film.maxEquivalentStress` | Real | output | Pa | largest element von Mises stress |
//! | `film.wrinkledElements/.slackElements` | Integer | output | | element counts (0 without wrinkling) |
//! | `film.yieldedElements` | Integer | output | | elasto-plastic film only: triangles with plastic strain |
//! | `film.minThickness` | Real | output | m | elasto-plastic film only: smallest current thickness |
//! | `<support set>.Rx/.Ry/.Rz` | Real | output | N | total reaction of a named support set |
//! | `reactions.Rx/.Ry/.Rz` | Real | output | N | sum of all restraint forces (supports, symmetry, groups) |
//! | `<cable>.maxForce` | Real | output | N | largest axial force of a tension-only cable |
//! | `<support>.node<v>.slip/.normalForce/.frictionForce/.status` | Real, Integer | output | m, N | node-to-surface contact on a curved support: arc length slid along it, forces, status |
//! | `<orifice>.massFlow` | Real | output | kg/s | air through an orifice averaged over the last step (moved mass / step), positive from its `from` chamber to its `to` |
//! | `<point>.ux/.uy/.uz` | Real | output | m | displacement of a named output point |
//! | `<set>.maxPrincipalStress/.minPrincipalStress/.maxEquivalentStress/.maxStrain/.compressedArea` | Real | output | Pa, 1, m2 | field summary of a named element set |
//! | `<set>.maxPlasticStrain` | Real | output | 1 | elasto-plastic film only: largest equivalent plastic strain of a named element set |
//!
//! The elasto-plastic film's outputs come last, so that an elastic model's table is unchanged.

use crate::mech::model::PressureKind;
use crate::mech::{LoadLevels, Model, SolverSettings};

/// The types of one variable (defined in `scalar_variable.rs`), also under this module's path.
pub use super::scalar_variable::{
    Binding, Causality, SummaryQuantity, Value, VarType, Variability, Variable, article,
    format_real, message_real,
};

/// What the FMU is built from, as far as the variable table is concerned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// The paper's parallel-arch specimen: adds the `archHeight` parameter.
    ParallelArch { arch_height: f64 },
    /// A user model file.
    Model,
}

/// Units used by the table, with their SI base-unit exponents `(kg, m, s)`.
pub const UNITS: [(&str, [i32; 5]); 14] = [
    ("m", [0, 1, 0, 0, 0]),
    ("m2", [0, 2, 0, 0, 0]),
    ("m3", [0, 3, 0, 0, 0]),
    ("m/s2", [0, 1, -2, 0, 0]),
    ("kg/m3", [1, -3, 0, 0, 0]),
    ("N", [1, 1, -2, 0, 0]),
    ("N.m", [1, 2, -2, 0, 0]),
    ("Pa", [1, -1, -2, 0, 0]),
    ("N/m", [1, 0, -2, 0, 0]),
    ("rad", [0, 0, 0, 0, 1]),
    ("K", [0, 0, 0, 1, 0]),
    ("kg", [1, 0, 0, 0, 0]),
    ("1", [0, 0, 0, 0, 0]),
    ("kg/s", [1, 0, -1, 0, 0]),
];

/// Top-level names the table uses; gap and group names must differ from them.
pub const RESERVED_NAMES: [&str; 9] = [
    "time",
    "reactions",
    "gravity",
    "mu",
    "frictionLaw",
    "archHeight",
    "film",
    "solver",
    "results",
];

/// Default of `solver.incrementsPerStep`: the core's
/// [`crate::mech::solve::DEFAULT_INCREMENTS_PER_STEP`], the CLI's default too.
pub const DEFAULT_INCREMENTS_PER_STEP: i32 = crate::mech::solve::DEFAULT_INCREMENTS_PER_STEP as i32;

/// Checks that the model's gap, group, pressure-set and force-set names can prefix variable names.
pub fn check_names(model: &Model) -> Result<(), String> {
    let names = model
        .gaps
        .iter()
        .map(|g| ("gap", &g.name))
        .chain(model.groups.iter().map(|g| ("boundary group", &g.name)))
        .chain(
            model
                .loads
                .pressures
                .iter()
                .map(|p| ("pressure set", &p.name)),
        )
        .chain(model.loads.forces.iter().map(|f| ("force set", &f.name)))
        .chain(
            model
                .outputs
                .points
                .iter()
                .map(|p| ("output point", &p.name)),
        )
        .chain(
            model
                .outputs
                .element_sets
                .iter()
                .map(|e| ("element set", &e.name)),
        );
    let support_sets = model.support_sets();
    let names = names
        .chain(support_sets.iter().map(|n| ("support set", n)))
        .chain(model.cables.iter().map(|c| ("cable", &c.name)))
        .chain(
            model
                .curved_supports
                .iter()
                .map(|c| ("curved support", &c.name)),
        );
    for (kind, name) in names {
        if RESERVED_NAMES.contains(&name.as_str()) {
            return Err(format!(
                "{kind} '{name}': the name is reserved for an FMU variable ({}); rename it",
                RESERVED_NAMES.join(", ")
            ));
        }
    }
    Ok(())
}

/// Each chamber's inputs: the supply's pressure, the valve, the heating.
fn chamber_inputs(table: &mut TableBuilder, model: &Model) {
    for (k, c) in model.chambers.iter().enumerate() {
        table.input(
            &format!("{}.supplyPressure", c.name),
            c.pressure,
            "Pa",
            &format!(
                "gauge pressure the supply holds in chamber '{}', reached at the end of a step \
                 (ignored while its air is enclosed)",
                c.name
            ),
            Binding::ChamberSupply(k),
        );
        table.push(
            &format!("{}.sealed", c.name),
            VarType::Boolean,
            Causality::Input,
            Some(Value::Boolean(c.sealed)),
            None,
            &format!(
                "true: the air of chamber '{}' is enclosed at its pressure and volume when the next \
                 step starts and follows Boyle's law; false: a supply holds supplyPressure",
                c.name
            ),
            Binding::ChamberSealed(k),
        );
        table.input(
            &format!("{}.heating", c.name),
            c.heating,
            "K",
            &format!(
                "temperature rise of the air in chamber '{}' above its reference {} K (the sun), \
                 reached at the end of a step",
                c.name, c.temperature
            ),
            Binding::ChamberHeating(k),
        );
        table.input(
            &format!("{}.massFlow", c.name),
            0.0,
            "kg/s",
            &format!(
                "air mass flow into chamber '{}' while its air is enclosed (negative: leakage \
                 out), integrated over each step: the step adds massFlow times its size, ramped \
                 in with the step's other loads (ignored while a supply holds the pressure)",
                c.name
            ),
            Binding::ChamberMassFlow(k),
        );
    }
}

/// The supplied-air levels ([`LoadLevels::air`]) a step of size `h` ends at: the converged
/// state's plus each sealed chamber's `<chamber>.massFlow` (in `values`, by `table`) times `h`
/// (`sealed`: the valves as the step will have them). Err names a chamber whose air would be
/// gone (a mass that is not positive: more let out than it holds) or a level that is not finite.
pub fn supplied_air(
    analysis: &crate::mech::Analysis,
    table: &[Variable],
    values: &[Value],
    sealed: &[bool],
    h: f64,
) -> Result<Vec<f64>, String> {
    let (model, state) = (analysis.model(), analysis.state());
    let mut air: Vec<f64> = (0..model.chambers.len())
        .map(|k| state.loads.air.get(k).copied().unwrap_or(0.0))
        .collect();
    for (v, x) in table.iter().zip(values) {
        let (Binding::ChamberMassFlow(k), &Value::Real(flow)) = (v.binding, x) else {
            continue;
        };
        if !sealed.get(k).copied().unwrap_or(false) || flow == 0.0 {
            continue;
        }
        let (spec, gas) = (&model.chambers[k], &state.chambers[k]);
        let law = crate::mech::elements::chamber::GasLaw {
            kappa: spec.kappa,
            atmosphere: spec.atmosphere,
            temperature: spec.temperature,
        };
        let mass = law.mass(gas.pressure, gas.volume, gas.temperature);
        let added = flow * h;
        if !(mass + added > 0.0 && (air[k] + added).is_finite()) {
            return Err(format!(
                "{} = {} kg/s over the step of {} s would leave {} kg of air in chamber '{}' \
                 (it holds {} kg): the mass must stay positive; the state before the step is kept",
                v.name,
                message_real(flow),
                message_real(h),
                message_real(mass + added),
                spec.name,
                message_real(mass)
            ));
        }
        air[k] += added;
    }
    Ok(air)
}

/// Each chamber's outputs (the air's pressure, volume, temperature and mass), then each
/// orifice's mass flow.
fn chamber_outputs(table: &mut TableBuilder, model: &Model) {
    for (k, c) in model.chambers.iter().enumerate() {
        table.output(
            &format!("{}.pressure", c.name),
            "Pa",
            &format!("gauge pressure of the air in chamber '{}'", c.name),
            Binding::ChamberPressure(k),
        );
        table.output(
            &format!("{}.volume", c.name),
            "m3",
            &format!("volume of chamber '{}'", c.name),
            Binding::ChamberVolume(k),
        );
        table.output(
            &format!("{}.temperature", c.name),
            "K",
            &format!("temperature of the air in chamber '{}'", c.name),
            Binding::ChamberTemperature(k),
        );
        table.output(
            &format!("{}.mass", c.name),
            "kg",
            &format!("mass of the air in chamber '{}' (ideal gas)", c.name),
            Binding::ChamberMass(k),
        );
    }
    for (k, o) in model.orifices.iter().enumerate() {
        table.output(
            &format!("{}.massFlow", o.name),
            "kg/s",
            &format!(
                "mass flow through orifice '{}' averaged over the last step, positive from \
                 chamber '{}' to '{}'",
                o.name, o.from, o.to
            ),
            Binding::OrificeMassFlow(k),
        );
    }
}

/// What the inputs ask of the next step: where the groups go (translations and hinge angles),
/// the load levels, and `μ` (only once it has been set).
#[derive(Clone, Debug, PartialEq)]
pub struct StepInputs {
    pub targets: Vec<[f64; 3]>,
    pub angles: Vec<f64>,
    /// Pressures and nodal forces from the inputs; gravity from the model (a parameter).
    pub loads: LoadLevels,
    pub mu: Option<f64>,
    /// Whether each chamber's air is to be enclosed from this step on.
    pub sealed: Vec<bool>,
}

/// Reads the step's targets from the input values of `table` (`values[i]` belongs to
/// `table[i]`): the one place that says which input moves what, for the FMU and the CLI's
/// staged load tables alike. `mu_set`: whether `mu` was given (until then each gap keeps its
/// own friction coefficient).
pub fn step_inputs(
    model: &Model,
    table: &[Variable],
    values: &[Value],
    mu_set: bool,
) -> StepInputs {
    let mut inputs = StepInputs {
        targets: vec![[0.0; 3]; model.groups.len()],
        angles: vec![0.0; model.groups.len()],
        loads: LoadLevels::zero(model),
        mu: None,
        sealed: model.chambers.iter().map(|c| c.sealed).collect(),
    };
    inputs.loads.gravity = model.loads.gravity;
    for (v, x) in table.iter().zip(values) {
        match (v.binding, x) {
            (Binding::GroupDisplacement { group, axis }, &Value::Real(x)) => {
                inputs.targets[group][axis] = x
            }
            (Binding::GroupAngle(group), &Value::Real(x)) => inputs.angles[group] = x,
            (Binding::Pressure(set), &Value::Real(x)) => inputs.loads.pressure[set] = x,
            (Binding::ChamberSupply(k), &Value::Real(x)) => inputs.loads.chambers[k] = x,
            (Binding::ChamberSealed(k), &Value::Boolean(b)) => inputs.sealed[k] = b,
            (Binding::ChamberHeating(k), &Value::Real(x)) => inputs.loads.heating[k] = x,
            (Binding::NodalForce { set, axis }, &Value::Real(x)) => {
                inputs.loads.force[set][axis] = x
            }
            (Binding::Friction, &Value::Real(x)) if mu_set => inputs.mu = Some(x),
            _ => {}
        }
    }
    inputs
}

/// The variable table of an FMU of `model`. Order: `time`, inputs, parameters, outputs; one
/// function per family of variables, called in the order of the XML.
pub fn variables(model: &Model, kind: Kind) -> Vec<Variable> {
    let mut table = TableBuilder::default();
    time_and_friction(&mut table, model);
    group_inputs(&mut table, model);
    pressure_inputs(&mut table, model);
    chamber_inputs(&mut table, model);
    force_inputs(&mut table, model);
    specimen_parameters(&mut table, kind);
    film_parameters(&mut table, model);
    gap_parameters(&mut table, model);
    solver_parameters(&mut table);
    gap_outputs(&mut table, model);
    group_outputs(&mut table, model);
    reaction_outputs(&mut table, model);
    curved_support_outputs(&mut table, model);
    cable_outputs(&mut table, model);
    chamber_outputs(&mut table, model);
    layer_contact_outputs(&mut table, model);
    point_outputs(&mut table, model);
    element_set_outputs(&mut table, model);
    solver_outputs(&mut table);
    film_outputs(&mut table, model);
    stabilization_outputs(&mut table);
    table.0
}

/// The axes of the components `x`, `y`, `z`.
const AXES: [&str; 3] = ["x", "y", "z"];

/// `time` and, with gaps or curved supports, the `mu` input.
fn time_and_friction(table: &mut TableBuilder, model: &Model) {
    let mu = model.gaps.first().map_or_else(
        || model.curved_supports.first().map_or(0.0, |s| s.friction),
        |g| g.friction,
    );
    table.push(
        "time",
        VarType::Real,
        Causality::Independent,
        None,
        None,
        "pseudo-time of the load path",
        Binding::Time,
    );
    // A model without gaps or curved supports has no friction to set: no `mu` input an
    // importer must feed.
    if !model.gaps.is_empty() || !model.curved_supports.is_empty() {
        table.input(
            "mu",
            mu,
            "1",
            "friction coefficient of every gap and curved-support contact; the model's own values apply until it is set",
            Binding::Friction,
        );
    }
}

/// Each boundary group's displacement inputs (prescribed components) and hinge angle.
fn group_inputs(table: &mut TableBuilder, model: &Model) {
    for (group, g) in model.groups.iter().enumerate() {
        let prescribed = g.prescribes();
        for (axis, a) in AXES.iter().enumerate().filter(|(c, _)| prescribed[*c]) {
            table.input(
                &format!("{}.d{a}", g.name),
                0.0,
                "m",
                &format!(
                    "displacement of boundary group '{}' along {a}, reached at the end of a step",
                    g.name
                ),
                Binding::GroupDisplacement { group, axis },
            );
        }
        if g.hinge.is_some() {
            table.input(
                &format!("{}.angle", g.name),
                0.0,
                "rad",
                &format!(
                    "angle of boundary group '{}' about its hinge axis (right-hand rule), reached at the end of a step",
                    g.name
                ),
                Binding::GroupAngle(group),
            );
        }
    }
}

/// Each pressure set's pressure input.
fn pressure_inputs(table: &mut TableBuilder, model: &Model) {
    for (set, p) in model.loads.pressures.iter().enumerate() {
        table.input(
            &format!("{}.pressure", p.name),
            p.pressure,
            "Pa",
            &match p.kind {
                PressureKind::Follower => format!(
                    "follower pressure on pressure set '{}' (positive {}), reached at the end of a \
                     step",
                    p.name,
                    match p.towards {
                        None => "along the triangles' normals".to_string(),
                        Some(t) => format!("pushes towards {:?}", t.vector()),
                    }
                ),
                PressureKind::Plan => format!(
                    "load per plan area on pressure set '{}' (positive along {:?}), reached at the \
                     end of a step",
                    p.name,
                    crate::mech::elements::load::plan_direction(p).as_slice()
                ),
            },
            Binding::Pressure(set),
        );
    }
}

/// Each force set's force inputs.
fn force_inputs(table: &mut TableBuilder, model: &Model) {
    for (set, f) in model.loads.forces.iter().enumerate() {
        for (axis, a) in ["Fx", "Fy", "Fz"].iter().enumerate() {
            table.input(
                &format!("{}.{a}", f.name),
                f.force[axis],
                "N",
                &format!(
                    "force on each node of force set '{}' along {}, reached at the end of a step",
                    f.name, AXES[axis]
                ),
                Binding::NodalForce { set, axis },
            );
        }
    }
}

/// The specimen's `archHeight` (none for a user model).
fn specimen_parameters(table: &mut TableBuilder, kind: Kind) {
    if let Kind::ParallelArch { arch_height } = kind {
        table.parameter(
            "archHeight",
            Value::Real(arch_height),
            Some("m"),
            "arch rise H; the specimen model is regenerated from it at initialization",
            Binding::ArchHeight,
        );
    }
}

/// The film's material parameters and gravity.
fn film_parameters(table: &mut TableBuilder, model: &Model) {
    let m = &model.material;
    let film: [(&str, f64, &str, &str, Binding); 6] = [
        (
            "E",
            m.youngs_modulus,
            "Pa",
            "Young's modulus of the film at 23 °C (film.temperature scales it)",
            Binding::YoungsModulus,
        ),
        (
            "nu",
            m.poisson_ratio,
            "1",
            "Poisson's ratio of the film",
            Binding::PoissonRatio,
        ),
        (
            "thickness",
            m.thickness,
            "m",
            "film thickness",
            Binding::Thickness,
        ),
        (
            "prestressX",
            m.prestress[0],
            "Pa",
            "initial stress σx of the film",
            Binding::Prestress(0),
        ),
        (
            "prestressY",
            m.prestress[1],
            "Pa",
            "initial stress σy of the film",
            Binding::Prestress(1),
        ),
        (
            "prestressXY",
            m.prestress[2],
            "Pa",
            "initial shear stress τxy of the film",
            Binding::Prestress(2),
        ),
    ];
    for (name, start, unit, description, binding) in film {
        table.parameter(
            &format!("film.{name}"),
            Value::Real(start),
            Some(unit),
            description,
            binding,
        );
    }
    table.parameter(
        "film.wrinkling",
        Value::Boolean(!m.wrinkling.is_none()),
        None,
        "true: tension-field film (no compression; elements taut, wrinkled or slack); false: linear elastic, the paper's",
        Binding::Wrinkling,
    );
    table.parameter(
        "film.density",
        Value::Real(m.density),
        Some("kg/m3"),
        "film density for self-weight (ETFE about 1750); 0: weightless",
        Binding::Density,
    );
    table.parameter(
        "film.temperature",
        Value::Real(m.temperature),
        None,
        "film temperature in °C, 0 to 50: E and the plastic film's flow stresses are given at 23 °C \
         and scaled by ETFE's published relation (docs/mechanics.md, Temperature)",
        Binding::Temperature,
    );
    for (axis, a) in AXES.iter().enumerate() {
        table.parameter(
            &format!("gravity.{a}"),
            Value::Real(model.loads.gravity[axis]),
            Some("m/s2"),
            &format!(
                "gravity acceleration along {a} acting on the film's mass; ramped in over the first step"
            ),
            Binding::Gravity(axis),
        );
    }
}

/// Each gap's penalty stiffnesses and the friction law of every contact.
fn gap_parameters(table: &mut TableBuilder, model: &Model) {
    for (i, g) in model.gaps.iter().enumerate() {
        table.parameter(
            &format!("{}.kn", g.name),
            Value::Real(g.normal_stiffness),
            Some("N/m"),
            &format!("normal penalty stiffness of gap '{}'", g.name),
            Binding::NormalStiffness(i),
        );
        table.parameter(
            &format!("{}.ks", g.name),
            Value::Real(g.tangential_stiffness),
            Some("N/m"),
            &format!("tangential penalty stiffness of gap '{}'", g.name),
            Binding::TangentialStiffness(i),
        );
    }
    table.parameter(
        "frictionLaw",
        Value::String(
            model
                .uniform_friction_law()
                .map_or(String::new(), |l| l.name().to_string()),
        ),
        None,
        "friction law of every gap and curved support: isotropic (Coulomb cone) or sliding-direction \
         (the paper's: slides along the gap's local x, or along the support, only); empty: each keeps the model file's",
        Binding::FrictionLaw,
    );
}

/// The Newton settings and the VTK output's.
fn solver_parameters(table: &mut TableBuilder) {
    let solver = SolverSettings::default();
    let solver_parameters: [(&str, Value, Option<&'static str>, &str, Binding); 8] = [
        (
            "displacementTolerance",
            Value::Real(solver.displacement_tolerance),
            Some("1"),
            "Newton converges when the last correction is below this fraction of the largest displacement (increment or total)",
            Binding::DisplacementTolerance,
        ),
        (
            "residualTolerance",
            Value::Real(solver.residual_tolerance),
            Some("1"),
            "... and the out-of-balance force is below this fraction of the largest nodal force of the model",
            Binding::ResidualTolerance,
        ),
        (
            "maxIterations",
            Value::Integer(saturating_i32(solver.max_iterations)),
            None,
            "Newton iterations per increment before it is halved",
            Binding::MaxIterations,
        ),
        (
            "maxCutbacks",
            Value::Integer(saturating_i32(solver.max_cutbacks)),
            None,
            "halvings of an increment before the step is discarded",
            Binding::MaxCutbacks,
        ),
        (
            "incrementsPerStep",
            Value::Integer(DEFAULT_INCREMENTS_PER_STEP),
            None,
            "the smallest number of increments a communication step is cut into (the controller cuts \
             further where Newton needs it)",
            Binding::IncrementsPerStep,
        ),
        (
            "useJuRowlands",
            Value::Boolean(false),
            None,
            "true: the paper's symmetric Ju-Rowlands iteration matrix; false: the consistent tangent",
            Binding::UseJuRowlands,
        ),
        (
            "stabilization",
            Value::Boolean(solver.stabilization),
            None,
            "true: a step whose smallest increment Newton refuses is solved on with viscous \
             stabilization (a film without a unique equilibrium; its work over the step is judged against \
             the strain energy, solver.dissipationRatio); false: the step is discarded there",
            Binding::Stabilization,
        ),
        (
            "threads",
            Value::Integer(saturating_i32(solver.threads)),
            None,
            "threads of the element assembly and the LDLT factorization, ended before each call returns \
             (0: automatic, the idle cores, one on meshes below 100 000 triangles and factors below \
             2^24 values); the results are identical for every count",
            Binding::Threads,
        ),
    ];
    for (name, start, unit, description, binding) in solver_parameters {
        table.parameter(&format!("solver.{name}"), start, unit, description, binding);
    }
    table.parameter(
        "results.directory",
        Value::String(String::new()),
        None,
        "directory for VTK output of every communication step (film and gaps .vtu + .pvd); empty: none",
        Binding::ResultsDirectory,
    );
    table.parameter(
        "results.vtkFormat",
        Value::String(crate::mech::results::vtk::Encoding::default().name().into()),
        None,
        "encoding of the VTK files: binary (raw appended data, about half the size) or ascii",
        Binding::VtkFormat,
    );
}

/// Each gap's results and status.
fn gap_outputs(table: &mut TableBuilder, model: &Model) {
    for (i, g) in model.gaps.iter().enumerate() {
        let n = &g.name;
        table.output(
            &format!("{n}.slip"),
            "m",
            &format!("slip of gap '{n}' along its local x (film relative to the support)"),
            Binding::SlipX(i),
        );
        table.output(
            &format!("{n}.slipY"),
            "m",
            &format!("slip of gap '{n}' along its local y"),
            Binding::SlipY(i),
        );
        table.output(
            &format!("{n}.normalForce"),
            "N",
            &format!("normal contact force of gap '{n}'"),
            Binding::NormalForce(i),
        );
        table.output(
            &format!("{n}.frictionForce"),
            "N",
            &format!("friction force magnitude of gap '{n}'"),
            Binding::FrictionForce(i),
        );
        for (axis, a) in ["X", "Y"].iter().enumerate() {
            table.output(
                &format!("{n}.friction{a}"),
                "N",
                &format!(
                    "friction force on the film at gap '{n}' along the gap's local {}",
                    a.to_lowercase()
                ),
                Binding::GapFriction { gap: i, axis },
            );
        }
        table.push(
            &format!("{n}.status"),
            VarType::Integer,
            Causality::Output,
            None,
            None,
            &format!("status of gap '{n}': 0 open, 1 stick, 2 slip"),
            Binding::GapStatus(i),
        );
    }
}

/// Each boundary group's reactions (prescribed components) and hinge moment.
fn group_outputs(table: &mut TableBuilder, model: &Model) {
    for (group, g) in model.groups.iter().enumerate() {
        let prescribed = g.prescribes();
        for (axis, a) in ["Rx", "Ry", "Rz"]
            .iter()
            .enumerate()
            .filter(|(c, _)| prescribed[*c])
        {
            table.output(
                &format!("{}.{a}", g.name),
                "N",
                &format!(
                    "total reaction force of boundary group '{}' along {}",
                    g.name, AXES[axis]
                ),
                Binding::Reaction { group, axis },
            );
        }
        if g.hinge.is_some() {
            table.output(
                &format!("{}.moment", g.name),
                "N.m",
                &format!(
                    "moment of the reaction of boundary group '{}' about its hinge axis (the drive's torque on the film)",
                    g.name
                ),
                Binding::HingeMoment(group),
            );
        }
    }
}

/// Each support set's reactions and the total reaction.
fn reaction_outputs(table: &mut TableBuilder, model: &Model) {
    for (set, name) in model.support_sets().iter().enumerate() {
        for (axis, a) in ["Rx", "Ry", "Rz"].iter().enumerate() {
            table.output(
                &format!("{name}.{a}"),
                "N",
                &format!(
                    "total reaction of support set '{name}' along {} (its fixed components)",
                    AXES[axis]
                ),
                Binding::SupportReaction { set, axis },
            );
        }
    }
    for (axis, a) in ["Rx", "Ry", "Rz"].iter().enumerate() {
        table.output(
            &format!("reactions.{a}"),
            "N",
            &format!(
                "sum of all restraint forces on the film along {} (supports, symmetry planes, groups; not the gaps)",
                AXES[axis]
            ),
            Binding::TotalReaction(axis),
        );
    }
}

/// Each curved-support contact's results and status.
fn curved_support_outputs(table: &mut TableBuilder, model: &Model) {
    let mut contact = 0;
    for s in &model.curved_supports {
        for &v in &s.nodes {
            let prefix = format!("{}.node{v}", s.name);
            let outputs: [(&str, &'static str, String, Binding); 3] = [
                (
                    "slip",
                    "m",
                    format!(
                        "arc length node {v} has slid along curved support '{}' since the start",
                        s.name
                    ),
                    Binding::SurfaceSlip(contact),
                ),
                (
                    "normalForce",
                    "N",
                    format!(
                        "contact force between node {v} and curved support '{}'",
                        s.name
                    ),
                    Binding::SurfaceNormalForce(contact),
                ),
                (
                    "frictionForce",
                    "N",
                    format!(
                        "friction force on node {v} from curved support '{}'",
                        s.name
                    ),
                    Binding::SurfaceFrictionForce(contact),
                ),
            ];
            for (what, unit, description, binding) in outputs {
                table.output(&format!("{prefix}.{what}"), unit, &description, binding);
            }
            table.push(
                &format!("{prefix}.status"),
                VarType::Integer,
                Causality::Output,
                None,
                None,
                &format!(
                    "status of node {v} on curved support '{}': 0 open, 1 stick, 2 slip",
                    s.name
                ),
                Binding::SurfaceStatus(contact),
            );
            contact += 1;
        }
    }
}

/// Each cable's largest force.
fn cable_outputs(table: &mut TableBuilder, model: &Model) {
    for (cable, c) in model.cables.iter().enumerate() {
        table.output(
            &format!("{}.maxForce", c.name),
            "N",
            &format!("largest axial force of cable '{}' (0 when slack)", c.name),
            Binding::CableForce(cable),
        );
    }
}

/// Each layer contact's total normal force and largest slip.
fn layer_contact_outputs(table: &mut TableBuilder, model: &Model) {
    for (k, c) in model.layer_contacts.iter().enumerate() {
        table.output(
            &format!("{}.normalForce", c.name),
            "N",
            &format!(
                "total normal force between the layers of contact '{}'",
                c.name
            ),
            Binding::LayerNormalForce(k),
        );
        table.output(
            &format!("{}.maxSlip", c.name),
            "m",
            &format!("largest slip between the layers of contact '{}'", c.name),
            Binding::LayerMaxSlip(k),
        );
    }
}

/// Each output point's displacement.
fn point_outputs(table: &mut TableBuilder, model: &Model) {
    for (point, p) in model.outputs.points.iter().enumerate() {
        for (axis, a) in ["ux", "uy", "uz"].iter().enumerate() {
            table.output(
                &format!("{}.{a}", p.name),
                "m",
                &format!(
                    "displacement of output point '{}' (node {}) along {}",
                    p.name, p.node, AXES[axis]
                ),
                Binding::PointDisplacement { point, axis },
            );
        }
    }
}

/// Each element set's field summary.
fn element_set_outputs(table: &mut TableBuilder, model: &Model) {
    for (set, e) in model.outputs.element_sets.iter().enumerate() {
        for (quantity, suffix, unit, what) in SummaryQuantity::ALL {
            table.output(
                &format!("{}.{suffix}", e.name),
                unit,
                &format!("{what} of element set '{}'", e.name),
                Binding::SetSummary { set, quantity },
            );
        }
    }
}

/// The last step's Newton statistics and stabilization energy.
fn solver_outputs(table: &mut TableBuilder) {
    table.integer_output(
        "solver.iterations",
        "Newton iterations of the last step (all increments)",
        Binding::Iterations,
    );
    table.integer_output(
        "solver.cutbacks",
        "increments halved in the last step",
        Binding::Cutbacks,
    );
    table.output(
        "solver.residual",
        "N",
        "final free residual of the last step",
        Binding::Residual,
    );
    table.output(
        "solver.stabilizationEnergy",
        "N.m",
        "work of the viscous stabilization's force over the last increment of the last step: the force the \
         answer still carries (0 when the step ended without it)",
        Binding::StabilizationEnergy,
    );
    table.output(
        "solver.stabilizationRatio",
        "1",
        "solver.stabilizationEnergy over the film's elastic strain energy; above 2e-4 the step warns",
        Binding::StabilizationRatio,
    );
}

/// The film's stress and element-state outputs, the elasto-plastic film's last.
fn film_outputs(table: &mut TableBuilder, model: &Model) {
    table.output(
        "film.maxEquivalentStress",
        "Pa",
        "largest von Mises stress of the film elements",
        Binding::MaxEquivalentStress,
    );
    table.integer_output(
        "film.wrinkledElements",
        "number of wrinkled film elements (uniaxial tension; 0 without wrinkling)",
        Binding::WrinkledElements,
    );
    table.integer_output(
        "film.slackElements",
        "number of slack film elements (no stress; 0 without wrinkling)",
        Binding::SlackElements,
    );
    if model.material.plasticity.is_some() {
        table.integer_output(
            "film.yieldedElements",
            "number of film elements with a positive equivalent plastic strain",
            Binding::YieldedElements,
        );
        table.output(
            "film.minThickness",
            "m",
            "smallest current thickness of the film elements (plastic flow is isochoric)",
            Binding::MinThickness,
        );
        for (set, e) in model.outputs.element_sets.iter().enumerate() {
            table.output(
                &format!("{}.maxPlasticStrain", e.name),
                "1",
                &format!(
                    "largest equivalent plastic strain of element set '{}'",
                    e.name
                ),
                Binding::SetMaxPlasticStrain(set),
            );
        }
    }
}

/// The last step's stabilized increments and dissipation ratio.
fn stabilization_outputs(table: &mut TableBuilder) {
    table.integer_output(
        "solver.stabilizedIncrements",
        "increments of the last step solved with the viscous stabilization (solver.stabilization)",
        Binding::StabilizedIncrements,
    );
    table.output(
        "solver.dissipationRatio",
        "1",
        "work of the viscous stabilization over the last step over the film's strain energy (Abaqus' \
         ALLSD/ALLIE); above 0.05 the step warns, above 1 the warning says the state is the damping's",
        Binding::DissipationRatio,
    );
}

fn saturating_i32(v: usize) -> i32 {
    i32::try_from(v).unwrap_or(i32::MAX)
}

#[derive(Default)]
struct TableBuilder(Vec<Variable>);

impl TableBuilder {
    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        name: &str,
        var_type: VarType,
        causality: Causality,
        start: Option<Value>,
        unit: Option<&'static str>,
        description: &str,
        binding: Binding,
    ) {
        let variability = match (causality, var_type) {
            (Causality::Parameter, _) => Variability::Fixed,
            (_, VarType::Real) => Variability::Continuous,
            _ => Variability::Discrete,
        };
        self.0.push(Variable {
            name: name.to_string(),
            value_reference: self.0.len() as u32,
            var_type,
            causality,
            variability,
            start,
            unit,
            description: description.to_string(),
            binding,
        });
    }

    fn input(
        &mut self,
        name: &str,
        start: f64,
        unit: &'static str,
        description: &str,
        binding: Binding,
    ) {
        self.push(
            name,
            VarType::Real,
            Causality::Input,
            Some(Value::Real(start)),
            Some(unit),
            description,
            binding,
        );
    }

    fn parameter(
        &mut self,
        name: &str,
        start: Value,
        unit: Option<&'static str>,
        description: &str,
        binding: Binding,
    ) {
        self.push(
            name,
            start.var_type(),
            Causality::Parameter,
            Some(start),
            unit,
            description,
            binding,
        );
    }

    fn integer_output(&mut self, name: &str, description: &str, binding: Binding) {
        self.push(
            name,
            VarType::Integer,
            Causality::Output,
            None,
            None,
            description,
            binding,
        );
    }

    fn output(&mut self, name: &str, unit: &'static str, description: &str, binding: Binding) {
        self.push(
            name,
            VarType::Real,
            Causality::Output,
            None,
            Some(unit),
            description,
            binding,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::specimens::ParallelArch;
    use std::collections::HashSet;

    fn specimen_table() -> (Model, Vec<Variable>) {
        let model = ParallelArch::with_height(0.3).model().unwrap();
        let table = variables(&model, Kind::ParallelArch { arch_height: 0.3 });
        (model, table)
    }

    #[test]
    fn names_unique_and_value_references_are_positions() {
        let (_, table) = specimen_table();
        let names: HashSet<&str> = table.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names.len(), table.len());
        for (i, v) in table.iter().enumerate() {
            assert_eq!(v.value_reference as usize, i);
            assert_eq!(
                v.start.is_some(),
                matches!(v.causality, Causality::Parameter | Causality::Input),
                "{}",
                v.name
            );
            if let Some(s) = &v.start {
                assert_eq!(s.var_type(), v.var_type, "{}", v.name);
            }
            if v.var_type != VarType::Real {
                assert_ne!(v.variability, Variability::Continuous, "{}", v.name);
            }
            if let Some(u) = v.unit {
                assert!(
                    UNITS.iter().any(|(n, _)| *n == u),
                    "unit {u} of {} is declared",
                    v.name
                );
            }
        }
    }

    #[test]
    fn specimen_table_has_the_documented_variables() {
        let (model, table) = specimen_table();
        let find = |n: &str| {
            table
                .iter()
                .find(|v| v.name == n)
                .unwrap_or_else(|| panic!("{n} missing"))
        };
        assert_eq!(find("time").causality, Causality::Independent);
        assert_eq!(find("frame.dz").causality, Causality::Input);
        assert_eq!(find("archHeight").start, Some(Value::Real(0.3)));
        assert_eq!(
            find("G9.kn").start,
            Some(Value::Real(model.gaps[8].normal_stiffness))
        );
        assert_eq!(find("G1.status").var_type, VarType::Integer);
        assert_eq!(
            find("solver.incrementsPerStep").start,
            Some(Value::Integer(DEFAULT_INCREMENTS_PER_STEP))
        );
        assert_eq!(
            find("solver.useJuRowlands").start,
            Some(Value::Boolean(false))
        );
        assert_eq!(find("mu").start, Some(Value::Real(0.2)));
        let law = find("frictionLaw");
        assert_eq!(
            (law.var_type, law.start.clone()),
            (VarType::String, Some(Value::String("isotropic".into())))
        );
        assert!(law.is_model_parameter());
        // Gaps with different laws: the parameter starts empty (each keeps its own).
        let mut mixed = model.clone();
        mixed.gaps[0].friction_law = crate::mech::FrictionLaw::SlidingDirection;
        let start = |m: &Model| {
            let table = variables(m, Kind::Model);
            table
                .into_iter()
                .find(|v| v.name == "frictionLaw")
                .unwrap()
                .start
        };
        assert_eq!(start(&mixed), Some(Value::String(String::new())));
        mixed.set_friction_law(crate::mech::FrictionLaw::SlidingDirection);
        assert_eq!(
            start(&mixed),
            Some(Value::String("sliding-direction".into()))
        );
        let dir = find("results.directory");
        assert_eq!(
            (dir.var_type, dir.causality, dir.variability),
            (VarType::String, Causality::Parameter, Variability::Fixed)
        );
        assert_eq!(dir.start, Some(Value::String(String::new())));
        assert!(!dir.is_model_parameter() && find("film.E").is_model_parameter());
        let format = find("results.vtkFormat");
        assert_eq!(format.start, Some(Value::String("binary".into())));
        assert!(!format.is_model_parameter());
        let outputs = table
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .count();
        assert_eq!(
            outputs,
            9 * 7 + 3 + 3 + 7 + 3,
            "gaps, group and total reactions, statistics (with the stabilization energy and ratio, \
             the stabilized increments and the dissipation ratio), film"
        );
        assert_eq!(find("film.wrinkling").start, Some(Value::Boolean(false)));
        assert_eq!(find("film.slackElements").var_type, VarType::Integer);
        // A user model has no archHeight, but the same results.directory.
        let user = variables(&model, Kind::Model);
        assert!(user.iter().all(|v| v.name != "archHeight"));
        assert!(user.iter().any(|v| v.binding == Binding::ResultsDirectory));
    }

    #[test]
    fn reserved_names_are_refused() {
        let mut model = ParallelArch::default().model().unwrap();
        assert!(check_names(&model).is_ok());
        model.gaps[0].name = "solver".into();
        let err = check_names(&model).unwrap_err();
        assert!(err.contains("gap 'solver'"), "{err}");
    }
}
