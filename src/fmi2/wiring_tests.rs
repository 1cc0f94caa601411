//! Every parameter and input of the variable table reaches the solver (issue 23, item 2).
//!
//! TEST GOAL: each variable of causality parameter or input, set alone to a value other than
//! the one it has in the run, changes the FMU's outputs exactly as the same edit of the model
//! file (or of the solver settings) changes the core's results: after one `fmi2DoStep`, every
//! output equals, to 1e-12 relative, the core run on the edited model. The variables are read
//! from the table itself, so a new one cannot be left out, and the edit is found from the
//! variable's NAME ([`edit`]), never from the FMU's binding: a variable wired to the wrong
//! field (prestress X and Y swapped, a gap's `kn` ignored) gives outputs that differ. A
//! variable with no edit in [`edit`] fails the test, and so does a change no output can see,
//! unless [`UNSEEN`] says why.
//!
//! MODELS: the specimen (its `archHeight` regenerates it), the specimen with a cable along its
//! x = 0 edge, the specimen on curved supports, `examples/circular_membrane.json` (pressure,
//! nodal force, density, gravity) and `examples/hinged_panel.json` (a hinge angle; its
//! prestress `[0.5, 0, 0]` MPa and hinge axis along y make x and y differ). The specimens are
//! not symmetric under x ↔ y either (arches along y, at x = ±0.4 m).
//!
//! BOUNDARY CONDITIONS: the specimens' frame lowered by 50 mm under self-weight, the panel's
//! rail turned by 0.1 rad, the membrane under its file's loads; two increments per step.
//!
//! SAFETY: the FMU is driven through the harness of `tests/mod.rs` (its soundness comment holds);
//! the `unsafe` calls here pass the harness's live instance and plain numbers.

use std::path::Path;

use serde_json::Value as Json;

use super::exports::{
    fmi2_enter_initialization_mode, fmi2_exit_initialization_mode, fmi2_setup_experiment,
};
use super::resources::Source;
use super::tests::{Fmu, Log, Unpacked};
use super::types::*;
use super::variables::{Causality, Value, VarType, Variable};
use crate::mech::elements::triangle::state_counts;
use crate::mech::model::CableSpec;
use crate::mech::{Analysis, LoadLevels, Model, Results, SolverSettings, StepReport};
use crate::specimens::ParallelArch;
use crate::specimens::parallel_arch::SpecimenContact;

/// Variables whose change no output can show, and why (each is still set and the outputs
/// still compared with the core's).
const UNSEEN: [(&str, &str); 4] = [
    (
        "solver.threads",
        "the assembly is bit-identical for every thread count, by design",
    ),
    (
        "results.directory",
        "not an analysis parameter: checked below by the files it asks for",
    ),
    (
        "results.vtkFormat",
        "not an analysis parameter: writes nothing without results.directory (tests/vtk_output.rs checks the ascii files)",
    ),
    (
        "solver.stabilization",
        "the strategy table's rows after Newton: no run here refuses its smallest increment, so it \
         never acts (tests/robustness.rs: a path it carries is refused with it off)",
    ),
];

/// Relative agreement required between the FMU and the core run.
const SAME: f64 = 1e-12;
/// Relative change of some output that shows a variable was seen by the solver: far above
/// [`SAME`], so that a mis-wired variable cannot pass the comparison.
const SEEN: f64 = 1e-8;

/// The core run an FMU run must equal: the model file and the solver settings as JSON
/// documents, and the increments of the step.
struct CoreRun {
    model: Json,
    settings: Json,
    increments: usize,
}

/// Sets `pointer` of `doc` to `x`: an array element that exists, or an object's member (added
/// when the file omits it, as it omits defaults).
fn put(doc: &mut Json, pointer: &str, x: Json) -> Result<(), String> {
    let (parent, key) = pointer.rsplit_once('/').expect("a JSON pointer");
    match doc.pointer_mut(parent) {
        Some(Json::Object(o)) => {
            o.insert(key.into(), x);
            Ok(())
        }
        Some(Json::Array(a)) => {
            let slot = key.parse::<usize>().ok().and_then(|i| a.get_mut(i));
            *slot.ok_or_else(|| format!("no element {pointer}"))? = x;
            Ok(())
        }
        _ => Err(format!("no {parent} in the document")),
    }
}

/// Applies what setting the variable `name` to `value` means, found from its name only: the
/// model file's field (JSON pointer), a solver setting, or the increments per step.
fn edit(run: &mut CoreRun, name: &str, value: &Value) -> Result<(), String> {
    let x = match value {
        Value::Real(x) => Json::from(*x),
        Value::Integer(x) => Json::from(*x),
        Value::Boolean(x) => Json::from(*x),
        Value::String(x) => Json::from(x.as_str()),
    };
    let (prefix, suffix) = name.rsplit_once('.').unwrap_or(("", name));
    let position = |list: &str| {
        run.model[list]
            .as_array()
            .and_then(|items| items.iter().position(|item| item["name"] == prefix))
    };
    let loads = |list: &str| {
        run.model["loads"][list]
            .as_array()
            .and_then(|items| items.iter().position(|item| item["name"] == prefix))
    };
    let axis = |names: [&str; 3]| names.iter().position(|n| *n == suffix);
    // Every gap and curved support (the friction inputs apply to both).
    let every_contact = |run: &mut CoreRun, field: &str, x: Json| -> Result<(), String> {
        for list in ["gaps", "curved_supports"] {
            let n = run.model[list].as_array().map_or(0, Vec::len);
            for i in 0..n {
                put(&mut run.model, &format!("/{list}/{i}/{field}"), x.clone())?;
            }
        }
        Ok(())
    };
    let model_field = match (prefix, suffix) {
        // The specimen's model is generated from it (`core_run`).
        ("", "archHeight") => return Ok(()),
        // The FMU applies `mu` once set; the models here have one μ, which is its start.
        ("", "mu") => return every_contact(run, "friction", x),
        ("", "frictionLaw") if x == "" => return Ok(()),
        ("", "frictionLaw") => return every_contact(run, "friction_law", x),
        ("film", "E") => "/material/youngs_modulus".to_string(),
        ("film", "nu") => "/material/poisson_ratio".into(),
        ("film", "thickness") => "/material/thickness".into(),
        ("film", "prestressX") => "/material/prestress/0".into(),
        ("film", "prestressY") => "/material/prestress/1".into(),
        ("film", "prestressXY") => "/material/prestress/2".into(),
        ("film", "density") => "/material/density".into(),
        ("film", "temperature") => "/material/temperature".into(),
        ("film", "wrinkling") => {
            let law = if x == true { "tension-field" } else { "none" };
            return put(&mut run.model, "/material/wrinkling", law.into());
        }
        ("gravity", _) if axis(["x", "y", "z"]).is_some() => {
            format!("/loads/gravity/{}", axis(["x", "y", "z"]).unwrap())
        }
        ("solver", "incrementsPerStep") => {
            run.increments = x.as_u64().ok_or("incrementsPerStep")? as usize;
            return Ok(());
        }
        ("solver", setting) => {
            let (field, x) = match setting {
                "displacementTolerance" => ("displacement_tolerance", x),
                "residualTolerance" => ("residual_tolerance", x),
                "maxIterations" => ("max_iterations", x),
                "maxCutbacks" => ("max_cutbacks", x),
                "stabilization" => ("stabilization", x),
                "threads" => ("threads", x),
                "useJuRowlands" if x == true => ("iteration_matrix", "JuRowlands".into()),
                "useJuRowlands" => ("iteration_matrix", "Consistent".into()),
                _ => return Err(format!("{name}: no solver setting")),
            };
            return put(&mut run.settings, &format!("/{field}"), x);
        }
        // Not analysis parameters: nothing to edit (see UNSEEN).
        ("results", "directory" | "vtkFormat") => return Ok(()),
        (_, "kn" | "ks") if position("gaps").is_some() => format!(
            "/gaps/{}/{}",
            position("gaps").unwrap(),
            if suffix == "kn" {
                "normal_stiffness"
            } else {
                "tangential_stiffness"
            }
        ),
        (_, "dx" | "dy" | "dz") if position("groups").is_some() => format!(
            "/groups/{}/target/{}",
            position("groups").unwrap(),
            axis(["dx", "dy", "dz"]).unwrap()
        ),
        (_, "angle") if position("groups").is_some() => {
            format!("/groups/{}/hinge/target_angle", position("groups").unwrap())
        }
        (_, "pressure") if loads("pressures").is_some() => {
            format!("/loads/pressures/{}/pressure", loads("pressures").unwrap())
        }
        (_, "supplyPressure") if position("chambers").is_some() => {
            format!("/chambers/{}/pressure", position("chambers").unwrap())
        }
        (_, "sealed") if position("chambers").is_some() => {
            format!("/chambers/{}/sealed", position("chambers").unwrap())
        }
        (_, "heating") if position("chambers").is_some() => {
            format!("/chambers/{}/heating", position("chambers").unwrap())
        }
        // A flow integrated over the steps, into a sealed chamber only: no model-file field
        // (the cushion's one step inflates from the supply; see its test's unseen list).
        (_, "massFlow") if position("chambers").is_some() => return Ok(()),
        (_, "Fx" | "Fy" | "Fz") if loads("forces").is_some() => format!(
            "/loads/forces/{}/force/{}",
            loads("forces").unwrap(),
            axis(["Fx", "Fy", "Fz"]).unwrap()
        ),
        _ => {
            return Err(format!(
                "variable {name} has no edit of the model file or solver settings: add one to `edit`"
            ));
        }
    };
    put(&mut run.model, &model_field, x)
}

/// The core run of `source` with every parameter and input of `table` at `values`.
fn core_run(source: &Source, table: &[Variable], values: &[Value]) -> CoreRun {
    let arch_height = table.iter().zip(values).find_map(|(v, x)| match x {
        Value::Real(h) if v.name == "archHeight" => Some(*h),
        _ => None,
    });
    let model = match (source, arch_height) {
        (Source::ParallelArch(spec), Some(arch_height)) => ParallelArch {
            arch_height,
            ..*spec
        }
        .model(),
        _ => source.model(),
    };
    let model = model.unwrap();
    let mut json = serde_json::to_value(&model).unwrap();
    // Written in full: the file omits loads at their defaults.
    json["loads"] = serde_json::to_value(&model.loads).unwrap();
    let mut run = CoreRun {
        model: json,
        settings: serde_json::to_value(SolverSettings::default()).unwrap(),
        increments: 0,
    };
    for (v, x) in table.iter().zip(values) {
        if matches!(v.causality, Causality::Parameter | Causality::Input) {
            edit(&mut run, &v.name, x).unwrap_or_else(|e| panic!("{e}"));
        }
    }
    run
}

/// One step of the core run: the model, its results and the step's report.
fn solve(run: &CoreRun) -> Result<(Model, Results, StepReport), String> {
    let model: Model = serde_json::from_value(run.model.clone()).map_err(|e| e.to_string())?;
    model.validate().map_err(|e| e.to_string())?;
    let settings = serde_json::from_value(run.settings.clone()).map_err(|e| e.to_string())?;
    let mut analysis = Analysis::new(model.clone(), settings).map_err(|e| e.to_string())?;
    let targets: Vec<[f64; 3]> = model.groups.iter().map(|g| g.target).collect();
    let angles: Vec<f64> = model
        .groups
        .iter()
        .map(|g| g.hinge.as_ref().map_or(0.0, |h| h.target_angle))
        .collect();
    let loads = LoadLevels::of_model(&model);
    let report = analysis
        .step_to_motion(&targets, &angles, &loads, run.increments)
        .map_err(|e| e.to_string())?;
    let results = analysis.results();
    crate::mech::check_results(&model, &results, Some(report.residual))?;
    Ok((model, results, report))
}

/// The value the output `name` must have, found from its name in the core's results.
fn expected(name: &str, model: &Model, r: &Results, report: &StepReport) -> Value {
    let (prefix, suffix) = name
        .rsplit_once('.')
        .expect("outputs are <item>.<quantity>");
    let xyz = |names: [&str; 3]| names.iter().position(|n| *n == suffix);
    let reaction = |forces: &[f64; 3]| xyz(["Rx", "Ry", "Rz"]).map(|c| Value::Real(forces[c]));
    let position = |mut names: std::slice::Iter<'_, String>| names.position(|n| n == prefix);
    let integer = |n: usize| Value::Integer(n as i32);
    let value = if let Some(g) = model.gaps.iter().position(|g| g.name == prefix) {
        let g = &r.gaps[g];
        match suffix {
            "slip" => Some(Value::Real(g.slip_x)),
            "slipY" => Some(Value::Real(g.slip_y)),
            "normalForce" => Some(Value::Real(g.normal_force)),
            "frictionForce" => Some(Value::Real(g.friction_force)),
            // `friction` is the force on the support; the film feels the opposite.
            "frictionX" => Some(Value::Real(-g.friction[0])),
            "frictionY" => Some(Value::Real(-g.friction[1])),
            "status" => Some(integer(g.status as usize)),
            _ => None,
        }
    } else if let Some(g) = model.groups.iter().position(|g| g.name == prefix) {
        match suffix {
            "moment" => Some(Value::Real(r.moments[g])),
            _ => reaction(&r.reactions[g]),
        }
    } else if let Some(s) = position(model.support_sets().iter()) {
        reaction(&r.support_reactions[s])
    } else if let Some(c) = model.cables.iter().position(|c| c.name == prefix) {
        (suffix == "maxForce").then(|| Value::Real(r.cables[c].max_force))
    } else if let Some(p) = model.outputs.points.iter().position(|p| p.name == prefix) {
        xyz(["ux", "uy", "uz"]).map(|c| Value::Real(r.points[p][c]))
    } else if let Some(s) = model
        .outputs
        .element_sets
        .iter()
        .position(|s| s.name == prefix)
    {
        let s = &r.sets[s];
        match suffix {
            "maxPrincipalStress" => Some(s.max_principal_stress),
            "minPrincipalStress" => Some(s.min_principal_stress),
            "maxEquivalentStress" => Some(s.max_equivalent_stress),
            "maxStrain" => Some(s.max_strain),
            "compressedArea" => Some(s.compressed_area),
            "maxPlasticStrain" => Some(s.max_plastic_strain),
            _ => None,
        }
        .map(Value::Real)
    } else if let Some(c) = model.chambers.iter().position(|c| c.name == prefix) {
        match suffix {
            "pressure" => Some(Value::Real(r.chambers[c].pressure)),
            "volume" => Some(Value::Real(r.chambers[c].volume)),
            "temperature" => Some(Value::Real(r.chambers[c].temperature)),
            "mass" => Some(Value::Real(r.chambers[c].mass)),
            _ => None,
        }
    } else if let Some(c) = model.layer_contacts.iter().position(|c| c.name == prefix) {
        // Summed here over the slave nodes, not through `Totals`.
        let own = r.layer_contacts.iter().filter(|n| n.contact == c);
        match suffix {
            "normalForce" => Some(Value::Real(own.map(|n| n.normal_force).sum())),
            "maxSlip" => Some(Value::Real(own.map(|n| n.slip).fold(0.0, f64::max))),
            _ => None,
        }
    } else if let Some((support, node)) = prefix.split_once(".node") {
        // Curved-support contacts in model order: supports, then their nodes.
        let mut k = 0;
        let mut found = None;
        for s in &model.curved_supports {
            for v in &s.nodes {
                if s.name == support && v.to_string() == node {
                    found = Some(&r.surface_contacts[k]);
                }
                k += 1;
            }
        }
        found.and_then(|c| match suffix {
            "slip" => Some(Value::Real(c.slip)),
            "normalForce" => Some(Value::Real(c.normal_force)),
            "frictionForce" => Some(Value::Real(c.friction_force)),
            "status" => Some(integer(c.status as usize)),
            _ => None,
        })
    } else {
        let counts = state_counts(&r.elements);
        match (prefix, suffix) {
            ("reactions", _) => reaction(&r.total_reaction),
            ("solver", "iterations") => Some(integer(report.total_iterations())),
            ("solver", "cutbacks") => Some(integer(report.cutbacks)),
            ("solver", "residual") => Some(Value::Real(report.residual)),
            ("solver", "stabilizationEnergy") => Some(Value::Real(report.stabilization_energy)),
            ("solver", "stabilizationRatio") => Some(Value::Real(report.stabilization_ratio())),
            ("solver", "stabilizedIncrements") => Some(integer(report.stabilized)),
            ("solver", "dissipationRatio") => Some(Value::Real(report.dissipation_ratio())),
            ("film", "maxEquivalentStress") => Some(Value::Real(r.von_mises_range().1)),
            ("film", "wrinkledElements") => Some(integer(counts[1])),
            ("film", "slackElements") => Some(integer(counts[2])),
            ("film", "yieldedElements") => r.plastic_summary().map(|p| integer(p.yielded_elements)),
            ("film", "minThickness") => r.plastic_summary().map(|p| Value::Real(p.min_thickness)),
            _ => None,
        }
    };
    value.unwrap_or_else(|| panic!("output {name} has no expected value: add it to `expected`"))
}

/// The outputs (table order) the core run gives, or why it failed.
fn core_outputs(run: &CoreRun, table: &[Variable]) -> Result<Vec<Value>, String> {
    let (model, results, report) = solve(run)?;
    Ok(table
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| expected(&v.name, &model, &results, &report))
        .collect())
}

/// The outputs (table order) after one step of an instance with the variables of `table` at
/// `values` (those that differ from their start set before initialization), or the status
/// that stopped it.
fn fmu_outputs(u: &Unpacked, values: &[Value]) -> Result<Vec<Value>, String> {
    let log = Log::default();
    let fmu = Fmu::new(u, &log);
    let ok = |status: i32, what: &str| {
        if status == Status::Ok.raw() || status == Status::Warning.raw() {
            Ok(())
        } else {
            Err(format!("{what}: status {status}: {:?}", log.take()))
        }
    };
    // SAFETY: see the module doc.
    unsafe {
        ok(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), "setup")?;
        ok(fmi2_enter_initialization_mode(fmu.c), "enter")?;
    }
    for (v, x) in u.variables.iter().zip(values) {
        if v.start.as_ref() == Some(x) || v.start.is_none() {
            continue;
        }
        let status = match x {
            Value::Real(x) => fmu.set_real(&v.name, *x),
            Value::Integer(x) => fmu.set_integer(&v.name, *x),
            Value::Boolean(x) => fmu.set_boolean(&v.name, *x),
            Value::String(x) => fmu.set_string(&v.name, x),
        };
        assert_eq!(
            status,
            Status::Ok.raw(),
            "set {} = {x:?}: {:?}",
            v.name,
            log.take()
        );
    }
    // SAFETY: see the module doc.
    ok(unsafe { fmi2_exit_initialization_mode(fmu.c) }, "exit")?;
    ok(fmu.step(0.0, 1.0), "step")?;
    Ok(u.variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| match v.var_type {
            VarType::Real => Value::Real(fmu.real(&v.name)),
            VarType::Integer => Value::Integer(fmu.integer(&v.name)),
            t => panic!("output {} of type {t:?}", v.name),
        })
        .collect())
}

/// The largest relative difference between two output lists and where (1 where an integer
/// differs; two reals differ relatively to the larger of the two).
fn disagreement(a: &[Value], b: &[Value]) -> (f64, usize) {
    a.iter()
        .zip(b)
        .enumerate()
        .map(|(i, pair)| {
            let d = match pair {
                (Value::Real(a), Value::Real(b)) if a == b => 0.0,
                (Value::Real(a), Value::Real(b)) => (a - b).abs() / a.abs().max(b.abs()),
                (x, y) => f64::from(u8::from(x != y)),
            };
            (d, i)
        })
        .fold((0.0, 0), |m, d| if d.0 > m.0 { d } else { m })
}

/// Floors of [`changes`]'s scale per unit: a micrometre, a micronewton, a pascal, ... so that a
/// change must exceed [`SEEN`] times the floor (1e-14 m, 1e-14 N, ...), far above roundoff.
/// Without them a unit whose every output is roundoff around a zero (the slips of contacts
/// that never slid, ~1e-16 m) makes roundoff count as a change, and a variable no output sees
/// passes as seen (the curved specimen's `film.wrinkling` did, until an output in m that is
/// not zero joined the table).
const ROUNDOFF: [(&str, f64); 6] = [
    ("m", 1e-6),
    ("N", 1e-6),
    ("N.m", 1e-6),
    ("Pa", 1.0),
    ("m2", 1e-9),
    ("1", 1e-9),
];

/// How much each output moved: a real's difference relative to the largest output of its unit,
/// at least [`ROUNDOFF`] (so that roundoff around a zero does not count), 1 where an integer
/// differs.
fn changes(outputs: &[&Variable], a: &[Value], b: &[Value]) -> Vec<f64> {
    let scale = |unit: Option<&str>| {
        let floor = ROUNDOFF
            .iter()
            .find(|(u, _)| Some(*u) == unit)
            .map_or(0.0, |(_, f)| *f);
        outputs
            .iter()
            .zip(a)
            .chain(outputs.iter().zip(b))
            .filter(|(v, _)| v.unit == unit)
            .fold(floor, |m, (_, x)| match x {
                Value::Real(x) => m.max(x.abs()),
                _ => m,
            })
    };
    outputs
        .iter()
        .zip(a.iter().zip(b))
        .map(|(v, pair)| match pair {
            (Value::Real(x), Value::Real(y)) if x != y => (x - y).abs() / scale(v.unit),
            (x, y) => f64::from(u8::from(x != y)),
        })
        .collect()
}

/// The three outputs that moved most, for messages.
fn largest_changes(outputs: &[&Variable], a: &[Value], b: &[Value]) -> String {
    let mut moved: Vec<(f64, usize)> = changes(outputs, a, b).into_iter().zip(0..).collect();
    moved.sort_by(|x, y| y.0.total_cmp(&x.0));
    moved
        .iter()
        .take(3)
        .map(|&(_, i)| format!("{} {:?} vs {:?}", outputs[i].name, a[i], b[i]))
        .collect::<Vec<_>>()
        .join("; ")
}

/// A value of `v` other than `x` that the model accepts, with the other variables it needs to
/// show (set in the run it is compared with as well).
fn changed(v: &Variable, x: &Value, directory: &Path) -> (Value, Vec<(&'static str, Value)>) {
    let alone = |x| (x, vec![]);
    match (v.name.as_str(), x) {
        // Tighter, with the other criterion loose so that this one decides.
        ("solver.displacementTolerance", Value::Real(x)) => (
            Value::Real(1e-3 * x),
            vec![("solver.residualTolerance", Value::Real(0.1))],
        ),
        ("solver.residualTolerance", Value::Real(x)) => (
            Value::Real(1e-3 * x),
            vec![("solver.displacementTolerance", Value::Real(0.1))],
        ),
        // So few that increments are cut back (and the step still converges).
        ("solver.maxIterations", _) => alone(Value::Integer(3)),
        // Cut-backs happen only when the iterations run out.
        ("solver.maxCutbacks", _) => (
            Value::Integer(1),
            vec![("solver.maxIterations", Value::Integer(6))],
        ),
        (_, Value::Real(x)) if *x != 0.0 => alone(Value::Real(0.8 * x)),
        (_, Value::Real(_)) => alone(Value::Real(match v.unit {
            Some("m") => 0.01,
            Some("rad") => 0.05,
            Some("Pa") => 1e5,
            Some("N") => 1.0,
            Some("m/s2") => 2.0,
            Some("kg/m3") => 1750.0,
            Some("K") => 10.0,
            Some("kg/s") => 1e-4,
            unit => panic!("{}: no change of a zero in {unit:?}", v.name),
        })),
        (_, Value::Integer(n)) if *n > 1 => alone(Value::Integer(n / 2)),
        (_, Value::Integer(n)) => alone(Value::Integer(n + 2)),
        (_, Value::Boolean(b)) => alone(Value::Boolean(!b)),
        ("frictionLaw", Value::String(law)) if law == "sliding-direction" => {
            alone(Value::String("isotropic".into()))
        }
        ("frictionLaw", _) => alone(Value::String("sliding-direction".into())),
        ("results.directory", _) => alone(Value::String(directory.to_str().unwrap().into())),
        ("results.vtkFormat", Value::String(f)) if f == "ascii" => {
            alone(Value::String("binary".into()))
        }
        ("results.vtkFormat", _) => alone(Value::String("ascii".into())),
        (name, x) => panic!("{name} = {x:?}: no other value known"),
    }
}

/// Sets each parameter and input of `source`'s table in turn (the others at `base` or their
/// start) and checks the FMU's outputs against the core run of the model edited the same way.
/// `unseen`: variables of this model whose change no output shows, and why.
fn check_every_variable(
    tag: &str,
    source: Source,
    base: &[(&str, Value)],
    unseen: &[(&str, &str)],
) {
    let u = Unpacked::new(tag, source.clone());
    let table = &u.variables;
    let outputs: Vec<&Variable> = table
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .collect();
    let mut values: Vec<Value> = table
        .iter()
        .map(|v| v.start.clone().unwrap_or(Value::Real(0.0)))
        .collect();
    let set = |values: &mut Vec<Value>, assignments: &[(&str, Value)]| {
        for (name, x) in assignments {
            values[u.vr(name) as usize] = x.clone();
        }
    };
    set(&mut values, base);
    // The FMU's outputs and the core's for `values`, checked equal.
    let agree = |what: &str, values: &[Value]| {
        let core = core_outputs(&core_run(&source, table, values), table);
        match (fmu_outputs(&u, values), &core) {
            (Ok(fmu), Ok(core)) => {
                let (d, i) = disagreement(&fmu, core);
                assert!(
                    d <= SAME,
                    "{tag}, {what}: output {} is {:?} from the FMU, {:?} from the core (FMU vs core, \
                     largest changes: {})",
                    outputs[i].name,
                    fmu[i],
                    core[i],
                    largest_changes(&outputs, &fmu, core)
                );
            }
            (Err(_), Err(_)) => {}
            (fmu, core) => panic!("{tag}, {what}: the FMU gives {fmu:?}, the core {core:?}"),
        }
        core
    };
    let base_outputs = agree("the base values", &values)
        .unwrap_or_else(|e| panic!("{tag}: the base run fails: {e}"));
    let directory = std::env::temp_dir().join(format!("mc wiring {tag} {}", std::process::id()));
    let mut not_seen = vec![];
    for (i, v) in table.iter().enumerate() {
        if !matches!(v.causality, Causality::Parameter | Causality::Input) {
            continue;
        }
        let (x, companions) = changed(v, &values[i], &directory);
        let mut before = values.clone();
        set(&mut before, &companions);
        let control = if companions.is_empty() {
            Ok(base_outputs.clone())
        } else {
            agree(&format!("{companions:?}"), &before)
        };
        let mut after = before.clone();
        after[i] = x;
        let what = format!("{} = {:?} (with {companions:?})", v.name, after[i]);
        let seen = match (agree(&what, &after), control) {
            (Ok(a), Ok(b)) => changes(&outputs, &a, &b).into_iter().any(|c| c > SEEN),
            (a, b) => a.is_ok() != b.is_ok(),
        };
        if !seen {
            not_seen.push(v.name.as_str());
        }
        if v.name == "results.directory" {
            let pvd = std::fs::read_dir(&directory)
                .unwrap()
                .filter_map(Result::ok)
                .any(|e| e.path().extension().is_some_and(|x| x == "pvd"));
            assert!(pvd, "{tag}: results.directory wrote no .pvd");
            std::fs::remove_dir_all(&directory).unwrap();
        }
    }
    let explained = |name: &&str| UNSEEN.iter().chain(unseen).any(|(n, _)| n == name);
    let unexplained: Vec<_> = not_seen.iter().filter(|n| !explained(n)).collect();
    assert!(
        unexplained.is_empty(),
        "{tag}: no output sees a change of {unexplained:?}"
    );
    let wrongly: Vec<_> = unseen
        .iter()
        .filter(|(n, _)| !not_seen.contains(n))
        .collect();
    assert!(
        wrongly.is_empty(),
        "{tag}: listed as unseen but seen: {wrongly:?}"
    );
}

/// The base values of a lowered specimen: self-weight on, the paper's friction law (its
/// elastic local y shows `ks` on a sliding gap), two increments, the frame lowered by `dz`.
fn lowered(dz: f64) -> Vec<(&'static str, Value)> {
    vec![
        ("frame.dz", Value::Real(dz)),
        ("frictionLaw", Value::String("sliding-direction".into())),
        ("film.density", Value::Real(1750.0)),
        ("gravity.z", Value::Real(-9.81)),
        ("solver.incrementsPerStep", Value::Integer(2)),
    ]
}

/// The frame lowered by 1.5 H: the film wraps the whole arch, every gap is closed (so that
/// each `kn` and `ks` shows).
const WRAPS_EVERY_GAP: f64 = -0.45;

fn example(file: &str) -> Model {
    let path = format!("{}/examples/{file}", env!("CARGO_MANIFEST_DIR"));
    Model::from_json(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn every_specimen_parameter_and_input_reaches_the_solver() {
    check_every_variable(
        "specimen",
        Source::ParallelArch(ParallelArch::default()),
        &lowered(WRAPS_EVERY_GAP),
        &[NEVER_WRINKLES],
    );
}

#[test]
fn every_parameter_and_input_of_a_specimen_on_curved_supports_reaches_the_solver() {
    let spec = ParallelArch {
        contact: SpecimenContact::CurvedSupport,
        ..ParallelArch::default()
    };
    // Lowered a little: the pipe contact converges slowly once deeper. No contact slides
    // there yet (every slip is roundoff, ~1e-16 m), and no element is compressed.
    check_every_variable(
        "curved",
        Source::Model(spec.model().unwrap()),
        &lowered(-0.03),
        &[NEVER_WRINKLES],
    );
}

/// Why a model without gaps or curved supports cannot show `frictionLaw`.
const NOTHING_SLIDES: (&str, &str) = ("frictionLaw", "no gap or curved support: nothing slides");
/// Why a film that nowhere compresses cannot show `film.wrinkling`.
const NEVER_WRINKLES: (&str, &str) = (
    "film.wrinkling",
    "no element is compressed: the tension field never acts",
);
/// Why a model without gaps or curved supports cannot show `solver.useJuRowlands`.
const NO_CONTACT_MATRIX: (&str, &str) = (
    "solver.useJuRowlands",
    "no gap or curved support: the Ju–Rowlands matrix is the consistent tangent there",
);

#[test]
fn every_parameter_and_input_of_the_circular_membrane_reaches_the_solver() {
    check_every_variable(
        "circular",
        Source::Model(example("circular_membrane.json")),
        &[("solver.incrementsPerStep", Value::Integer(2))],
        &[NOTHING_SLIDES, NEVER_WRINKLES, NO_CONTACT_MATRIX],
    );
}

/// `examples/cushion_air.json` (issue 43): the chamber's supply pressure and its valve reach
/// the solver (sealed at the flat start, the air encloses nothing: both refuse the step), and
/// its pressure and volume are the core's.
#[test]
fn every_parameter_and_input_of_the_cushion_with_a_chamber_reaches_the_solver() {
    check_every_variable(
        "cushion air",
        Source::Model(example("cushion_air.json")),
        &[("solver.incrementsPerStep", Value::Integer(2))],
        &[
            NOTHING_SLIDES,
            NEVER_WRINKLES,
            NO_CONTACT_MATRIX,
            (
                "air.massFlow",
                "air is fed into a sealed chamber only, and the one step here inflates from the \
                 supply (fmi2/tests/stepping.rs feeds a sealed chamber and checks its mass)",
            ),
        ],
    );
}

/// Two film layers pressed together by snow (`examples/two_layers_touching.json`): the layer
/// contact's outputs (`Touch.normalForce`, `Touch.maxSlip`) equal the core's.
#[test]
fn every_parameter_and_input_of_two_touching_layers_reaches_the_solver() {
    check_every_variable(
        "two layers",
        Source::Model(example("two_layers_touching.json")),
        &[("solver.incrementsPerStep", Value::Integer(2))],
        &[
            NOTHING_SLIDES,
            NEVER_WRINKLES,
            (
                "gravity.x",
                "the film has no density: gravity weighs nothing",
            ),
            (
                "gravity.y",
                "the film has no density: gravity weighs nothing",
            ),
            (
                "gravity.z",
                "the film has no density: gravity weighs nothing",
            ),
            (
                "solver.displacementTolerance",
                "the penalty contact of a flat layer reaches round-off in the same iterations at \
                 either tolerance",
            ),
            (
                "solver.residualTolerance",
                "the penalty contact of a flat layer reaches round-off in the same iterations at \
                 either tolerance",
            ),
            (
                "solver.useJuRowlands",
                "pressed without sliding, the layer contact's tangent is symmetric: both matrices \
                 are the same",
            ),
        ],
    );
}

/// The circular membrane with an elasto-plastic film that yields everywhere under its pressure
/// (initial yield 0.3 MPa): the plastic outputs (`film.yieldedElements`, `film.minThickness`,
/// `disc.maxPlasticStrain`) equal the core's, and every film parameter reaches the plastic film.
#[test]
fn every_parameter_and_input_of_a_yielding_circular_membrane_reaches_the_solver() {
    use crate::mech::elements::plasticity::{Hardening, Plasticity};
    let mut model = example("circular_membrane.json");
    model.material.yield_stress = None;
    model.material.prestress = [1e5, 1e5, 0.0];
    model.material.plasticity = Some(Plasticity {
        hardening: Hardening::new(vec![[0.0, 3e5], [1.0, 3e7]]).unwrap(),
    });
    let u = Unpacked::new("plastic table", Source::Model(model.clone()));
    for name in [
        "film.yieldedElements",
        "film.minThickness",
        "disc.maxPlasticStrain",
    ] {
        assert!(u.variables.iter().any(|v| v.name == name), "{name} missing");
    }
    // `film.wrinkling` is seen here although the converged film is nowhere compressed: a step's
    // second increment starts from the extrapolated iterate of the load path, on whose way to
    // equilibrium the tension field acts, so the outputs differ within the equilibrium
    // tolerance (above `SEEN`).
    check_every_variable(
        "plastic",
        Source::Model(model),
        &[("solver.incrementsPerStep", Value::Integer(2))],
        &[NOTHING_SLIDES, NO_CONTACT_MATRIX],
    );
}

#[test]
fn every_parameter_and_input_of_the_hinged_panel_reaches_the_solver() {
    check_every_variable(
        "hinged",
        Source::Model(example("hinged_panel.json")),
        &[
            ("rail.angle", Value::Real(0.1)),
            ("solver.incrementsPerStep", Value::Integer(2)),
        ],
        &[NOTHING_SLIDES, NO_CONTACT_MATRIX],
    );
}

#[test]
fn every_parameter_and_input_of_a_panel_with_an_edge_cable_reaches_the_solver() {
    let mut model = example("hinged_panel.json");
    // Its free edge y = 0, from the supported side to the rail: nodes 0..=10.
    model.cables.push(CableSpec {
        name: "hem".into(),
        nodes: (0..=10).collect(),
        area: 1e-5,
        youngs_modulus: 2e10,
        prestress_force: 50.0,
    });
    check_every_variable(
        "cable",
        Source::Model(model),
        &[
            ("rail.angle", Value::Real(0.1)),
            ("solver.incrementsPerStep", Value::Integer(2)),
        ],
        &[NOTHING_SLIDES, NO_CONTACT_MATRIX],
    );
}

/// A variable the table gains with no edit in [`edit`] stops the check with its name, and so
/// does a known suffix on an item that has no such variable.
#[test]
fn a_variable_without_a_model_edit_is_an_error_naming_it() {
    let mut run = core_run(&Source::Model(example("hinged_panel.json")), &[], &[]);
    let err = edit(&mut run, "film.colour", &Value::Real(1.0)).unwrap_err();
    assert!(
        err.contains("film.colour") && err.contains("no edit"),
        "{err}"
    );
    assert!(edit(&mut run, "rail.kn", &Value::Real(1.0)).is_err());
    assert!(edit(&mut run, "rail.angle", &Value::Real(0.2)).is_ok());
}
