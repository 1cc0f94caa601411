//! Fuzz harness for the FMU state deserializer and the model loader (issue 12), bounded and
//! deterministic (xorshift, fixed seed) so that it runs in CI with every `cargo test`.
//!
//! TEST GOAL: for every mutated input the FMU either refuses it with an error, or accepts it and
//! the next step gives finite outputs or a Discard. Never fmi2OK with a non-finite output.
//!
//! INPUTS
//! * states: genuine serialized states of the ParallelArch specimen (after 0, 2 and 4 steps of a
//!   ramp of `frame.dz`), mutated by bit flips (CRC left as is), payload byte changes and JSON
//!   number replacements with the length and CRC recomputed (forgeries that pass the format
//!   checks), and structured edits of the decoded snapshot (scaled or replaced displacements,
//!   slip histories, group displacements, friction, statuses, sizes, load levels, phase, times,
//!   variable values), serialized again;
//! * models: the 2 × 2-cell pressed-node patch (also with a `loads` section: pressure, nodal
//!   force, density and gravity) and the specimen as JSON, mutated by replaced
//!   numbers (indices and values: 0, ±1, huge, tiny, subnormal, random), deleted fields,
//!   truncated or emptied arrays, and strings with control characters.
//!
//! Driven through the safe `Instance` API with the phase checks of the C boundary
//! (`allowed::DO_STEP`), as `fmi2DeSerializeFMUstate` + `fmi2SetFMUstate` + `fmi2DoStep` and
//! `fmi2Instantiate` + initialization + `fmi2DoStep` do. The counts are printed (run with
//! `--nocapture`).

use membrane_contact::fmi2::instance::{Instance, allowed};
use membrane_contact::fmi2::logger::Logger;
use membrane_contact::fmi2::resources::Source;
use membrane_contact::fmi2::state::{self, Snapshot};
use membrane_contact::fmi2::types::{FMI2_LAST_SUCCESSFUL_TIME, Status};
use membrane_contact::fmi2::variables::{Causality, Value, VarType};
use membrane_contact::mech::{GapStatus, Model};
use membrane_contact::specimens::ParallelArch;
use serde_json::Value as Json;

const STATE_CASES: usize = 1200;
const MODEL_CASES: usize = 500;

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A number a fuzzer likes: 0, ±1, huge, tiny, subnormal, a power of ten, or random.
    fn number(&mut self) -> f64 {
        let sign = if self.next() & 1 == 0 { 1.0 } else { -1.0 };
        sign * match self.below(9) {
            0 => 0.0,
            1 => 1.0,
            2 => 1e308,
            3 => 1e-308,
            4 => 5e-324,
            5 => 10f64.powi(self.below(600) as i32 - 300),
            6 => self.below(200) as f64,
            7 => 1e150,
            _ => self.unit() * 10.0,
        }
    }
}

#[derive(Default, Debug)]
struct Counts {
    run: usize,
    refused: usize,
    accepted_finite: usize,
    accepted_discard: usize,
    accepted_step_error: usize,
    accepted_non_finite: usize,
}

impl Counts {
    fn print(&self, what: &str) {
        println!(
            "{what}: {} cases run, {} refused with an error, {} accepted and the next step finite, \
             {} accepted and the next step Discarded, {} accepted and the next step refused with an error, \
             {} accepted and non-finite",
            self.run,
            self.refused,
            self.accepted_finite,
            self.accepted_discard,
            self.accepted_step_error,
            self.accepted_non_finite
        );
    }
}

/// Every Real output of the instance, and whether reading them succeeded.
fn outputs(inst: &mut Instance) -> Option<Vec<f64>> {
    let vrs: Vec<u32> = inst
        .description()
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output && v.var_type == VarType::Real)
        .map(|v| v.value_reference)
        .collect();
    let mut out = vec![f64::NAN; vrs.len()];
    inst.get_real(&vrs, &mut out).ok().map(|()| out)
}

/// Sets every group input to `scale` × its model target, and every load input (pressure,
/// nodal force) to `scale` × its start value (the model's), and steps from the instance's time;
/// classifies the outcome.
fn step_and_classify(inst: &mut Instance, scale: f64, counts: &mut Counts) {
    if !allowed::DO_STEP.allows(inst.phase()) {
        // The C boundary refuses fmi2DoStep in this phase: only the outputs can be read.
        match outputs(inst) {
            Some(o) if o.iter().all(|v| v.is_finite()) => counts.accepted_finite += 1,
            Some(_) => counts.accepted_non_finite += 1,
            None => counts.accepted_step_error += 1,
        }
        return;
    }
    let model = inst.description().model.clone();
    let inputs: Vec<(u32, f64)> = inst
        .description()
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Input && v.name != "mu")
        .map(|v| {
            let (prefix, axis) = v.name.rsplit_once('.').expect("prefixed input");
            let target = match model.groups.iter().find(|g| g.name == prefix) {
                Some(g) => {
                    let axis = ["dx", "dy", "dz"]
                        .iter()
                        .position(|a| *a == axis)
                        .expect("axis");
                    g.target[axis]
                }
                None => match v.start {
                    Some(Value::Real(x)) => x,
                    _ => panic!("input {} has no real start", v.name),
                },
            };
            (v.value_reference, scale * target)
        })
        .collect();
    for (vr, x) in inputs {
        if inst.set_real(&[vr], &[x]).is_err() {
            counts.accepted_step_error += 1;
            return;
        }
    }
    let t = inst
        .get_real_status(FMI2_LAST_SUCCESSFUL_TIME)
        .unwrap_or(0.0);
    match inst.do_step(t, 0.01) {
        Ok(()) => match outputs(inst) {
            Some(o) if o.iter().all(|v| v.is_finite()) => counts.accepted_finite += 1,
            _ => counts.accepted_non_finite += 1,
        },
        Err(f) if f.status == Status::Warning => counts.accepted_finite += 1,
        Err(f) if f.status == Status::Discard => {
            // The outputs after a Discard are those of the kept state: finite too.
            match outputs(inst) {
                Some(o) if o.iter().all(|v| v.is_finite()) => counts.accepted_discard += 1,
                _ => counts.accepted_non_finite += 1,
            }
        }
        Err(_) => counts.accepted_step_error += 1,
    }
}

fn specimen_instance() -> Instance {
    let mut inst = Instance::from_source(
        Source::ParallelArch(ParallelArch::default()),
        Logger::silent(),
    )
    .unwrap();
    inst.setup_experiment(0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    let mu = vr(&inst, "mu");
    inst.set_real(&[mu], &[0.2]).unwrap();
    inst.exit_initialization_mode().unwrap();
    inst
}

fn vr(inst: &Instance, name: &str) -> u32 {
    let v = inst.description().variables.iter().find(|v| v.name == name);
    v.expect("variable").value_reference
}

/// Splits a serialized state into (header up to the payload length, payload) and frames a new
/// payload with its length and CRC-32 recomputed.
fn reframe(bytes: &[u8], payload: &[u8]) -> Vec<u8> {
    let guid_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut out = bytes[..16 + guid_len].to_vec();
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    crc.update(&out);
    crc.update(payload);
    out.extend_from_slice(&crc.finalize().to_le_bytes());
    out.extend_from_slice(payload);
    out
}

fn payload(bytes: &[u8]) -> &[u8] {
    let guid_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    &bytes[16 + guid_len + 12..]
}

/// Replaces one JSON number token of `text` by `with`.
fn replace_number(text: &str, rng: &mut Rng, with: f64) -> String {
    let starts: Vec<usize> = text
        .char_indices()
        .filter(|&(i, c)| {
            (c.is_ascii_digit() || c == '-')
                && !text[..i].ends_with(|p: char| p.is_ascii_alphanumeric() || p == '.' || p == '-')
        })
        .map(|(i, _)| i)
        .collect();
    if starts.is_empty() {
        return text.to_string();
    }
    let at = starts[rng.below(starts.len())];
    let end = text[at + 1..]
        .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '-' | '+')))
        .map_or(text.len(), |e| at + 1 + e);
    format!("{}{:e}{}", &text[..at], with, &text[end..])
}

/// One structured edit of a decoded snapshot.
fn edit_snapshot(s: &mut Snapshot, rng: &mut Rng) {
    let factor = 10f64.powi(rng.below(320) as i32 - 10);
    let Some(a) = s.analysis.as_mut() else {
        s.time = rng.number();
        return;
    };
    match rng.below(15) {
        0 => a.displacement.iter_mut().for_each(|v| *v *= factor),
        13 => {
            // Load levels: a gravity component, or a pressure level the model has no set for.
            if rng.next() & 1 == 0 {
                a.loads.gravity[rng.below(3)] = rng.number();
            } else {
                a.loads.pressure.push(rng.number());
            }
        }
        1 => {
            let i = rng.below(a.displacement.len());
            a.displacement[i] = rng.number();
        }
        2 => a
            .plastic_slip
            .iter_mut()
            .flatten()
            .for_each(|v| *v *= factor),
        3 => {
            let i = rng.below(a.boundary.len());
            a.boundary[i][rng.below(3)] = rng.number();
        }
        4 => {
            let i = rng.below(a.friction.len());
            a.friction[i] = rng.number().abs();
        }
        5 => {
            let i = rng.below(a.status.len());
            a.status[i] = [GapStatus::Open, GapStatus::Stick, GapStatus::Slip][rng.below(3)];
        }
        6 => {
            let n = rng.below(a.displacement.len() + 10);
            a.displacement.resize(n, 0.0);
        }
        7 => a.last_increment.iter_mut().for_each(|v| *v *= factor),
        8 => {
            let n = rng.below(12);
            a.status.resize(n, GapStatus::Open);
            a.friction.resize(n, 0.2);
        }
        9 => {
            let i = rng.below(s.values.len());
            s.values[i] = match &s.values[i] {
                Value::Real(x) => {
                    Value::Real(x * factor * if rng.next() & 1 == 0 { 1.0 } else { -1.0 })
                }
                Value::Integer(_) => Value::Integer(rng.next() as i32 % 1000),
                Value::Boolean(b) => Value::Boolean(!b),
                // A control character in a path below the temporary directory: a mutated
                // `results.directory` must never write into the working tree.
                Value::String(_) => Value::String(
                    std::env::temp_dir()
                        .join("membrane-contact-fuzz\u{1}x")
                        .display()
                        .to_string(),
                ),
            };
        }
        10 => {
            s.time = rng.number();
            s.stop_time = Some(rng.number());
        }
        11 => {
            use membrane_contact::fmi2::instance::Phase::*;
            s.phase = [
                Instantiated,
                Initialization,
                StepComplete,
                StepFailed,
                Terminated,
                Fatal,
            ][rng.below(6)];
        }
        12 => {
            let i = rng.below(a.displacement.len());
            a.displacement[i] += 1e-3 * rng.number().clamp(-1e3, 1e3);
        }
        _ => s.analysis = None,
    }
}

#[test]
fn mutated_states_are_refused_or_step_to_finite_outputs_or_discard() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut inst = specimen_instance();
    let guid = inst.description().guid.clone();
    let dz = vr(&inst, "frame.dz");
    let target = ParallelArch::default().target()[2];
    let mut genuine = Vec::new();
    for k in 0..=4 {
        if k % 2 == 0 {
            let h = inst.get_fmu_state(0).unwrap();
            genuine.push(inst.serialize_fmu_state(h).unwrap());
            inst.free_fmu_state(h).unwrap();
        }
        inst.set_real(&[dz], &[target * (k + 1) as f64 / 20.0])
            .unwrap();
        inst.do_step(k as f64 * 0.05, 0.05).unwrap();
    }
    let home = inst.get_fmu_state(0).unwrap();
    let mut counts = Counts::default();
    for case in 0..STATE_CASES {
        let base = &genuine[rng.below(genuine.len())];
        let bytes = match case % 4 {
            0 => {
                let mut b = base.clone();
                for _ in 0..1 + rng.below(4) {
                    let i = rng.below(b.len());
                    b[i] ^= 1 << rng.below(8);
                }
                b
            }
            1 => {
                let mut p = payload(base).to_vec();
                for _ in 0..1 + rng.below(3) {
                    let i = rng.below(p.len());
                    p[i] = b"0123456789.-e,]}[{\"x"[rng.below(20)];
                }
                reframe(base, &p)
            }
            2 => {
                let text = String::from_utf8(payload(base).to_vec()).unwrap();
                let with = rng.number();
                reframe(base, replace_number(&text, &mut rng, with).as_bytes())
            }
            _ => {
                let mut s = state::deserialize(base, &guid).unwrap();
                edit_snapshot(&mut s, &mut rng);
                state::serialize(&s, &guid)
            }
        };
        counts.run += 1;
        let handle = match inst.deserialize_fmu_state(&bytes, 0) {
            Ok(h) => h,
            Err(f) => {
                assert_eq!(f.status, Status::Error);
                assert!(!f.message.is_empty());
                counts.refused += 1;
                continue;
            }
        };
        if let Err(f) = inst.set_fmu_state(handle) {
            // fmi2DeSerializeFMUstate checks everything fmi2SetFMUstate does.
            panic!(
                "case {case}: accepted at deserialization, refused at set: {}",
                f.message
            );
        } else {
            step_and_classify(&mut inst, rng.unit(), &mut counts);
        }
        inst.free_fmu_state(handle).unwrap();
        inst.set_fmu_state(home).unwrap();
    }
    counts.print("FMU states");
    assert_eq!(counts.accepted_non_finite, 0, "{counts:?}");
    assert!(
        counts.refused > 0 && counts.accepted_finite > 0,
        "{counts:?}"
    );
}

/// One mutation of a model as JSON.
fn mutate_model(json: &mut Json, rng: &mut Rng) {
    // Collect the paths to every value.
    fn walk(v: &Json, path: &mut Vec<Json>, out: &mut Vec<Vec<Json>>) {
        out.push(path.clone());
        match v {
            Json::Object(m) => {
                for (k, x) in m {
                    path.push(Json::String(k.clone()));
                    walk(x, path, out);
                    path.pop();
                }
            }
            Json::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    path.push(Json::from(i));
                    walk(x, path, out);
                    path.pop();
                }
            }
            _ => {}
        }
    }
    let mut paths = Vec::new();
    walk(json, &mut Vec::new(), &mut paths);
    let path = &paths[1 + rng.below(paths.len() - 1)];
    let (last, parent) = path.split_last().unwrap();
    let mut node = &mut *json;
    for p in parent {
        node = match p {
            Json::String(k) => &mut node[k.as_str()],
            _ => &mut node[p.as_u64().unwrap() as usize],
        };
    }
    let choice = rng.below(6);
    match (node, last) {
        (Json::Object(m), Json::String(k)) if choice == 0 => {
            m.remove(k);
        }
        (Json::Array(a), _) if choice == 1 => {
            let n = rng.below(a.len() + 1);
            a.truncate(n);
        }
        (node, last) => {
            let slot = match last {
                Json::String(k) => &mut node[k.as_str()],
                _ => &mut node[last.as_u64().unwrap() as usize],
            };
            *slot = match (slot.clone(), choice) {
                (Json::Number(n), 2) => {
                    Json::from(n.as_f64().unwrap_or(0.0) as i64 + rng.below(5) as i64 - 2)
                }
                (Json::String(s), _) => Json::String(match rng.below(3) {
                    0 => format!("{s}\u{1}"),
                    1 => String::new(),
                    _ => format!("{s}_x"),
                }),
                // Emptied, or every entry duplicated.
                (Json::Array(a), 3) if a.len() % 2 == 0 => Json::Array(vec![]),
                (Json::Array(a), 3) => Json::Array(a.iter().chain(&a).cloned().collect()),
                _ => serde_json::Number::from_f64(rng.number()).map_or(Json::Null, Json::Number),
            };
        }
    }
}

#[test]
fn mutated_models_are_refused_or_step_to_finite_outputs_or_discard() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let patch = r#"{ "name": "Patch", "nodes": [[0,0,0], [0.1,0,0], [0.2,0,0], [0,0.1,0], [0.1,0.1,0],
        [0.2,0.1,0], [0,0.2,0], [0.1,0.2,0], [0.2,0.2,0]],
      "triangles": [[0,1,4], [0,4,3], [1,2,5], [1,5,4], [3,4,7], [3,7,6], [4,5,8], [4,8,7]],
      "material": { "youngs_modulus": 1e9, "poisson_ratio": 0.43, "thickness": 250e-6, "prestress": [5e5, 5e5, 0] },
      "gaps": [{ "name": "G", "film_node": 4, "support": { "point": [0.1, 0.1, -0.001] },
                 "frame": { "x": [1,0,0], "y": [0,1,0], "z": [0,0,1] }, "initial_gap": 0.001,
                 "normal_stiffness": 2.5e8, "tangential_stiffness": 2.5e7, "friction": 0.2 }],
      "groups": [{ "name": "rim", "nodes": [0, 1, 2, 3, 5, 6, 7, 8], "target": [0, 0, -0.01] }] }"#;
    let loaded = patch.replace(
        r#""prestress": [5e5, 5e5, 0] },"#,
        r#""prestress": [5e5, 5e5, 0], "density": 1750 },
      "loads": { "pressures": [{ "name": "top", "elements": "all", "pressure": 300 },
                               { "name": "gust", "elements": [2, 3], "pressure": -100 }],
                 "forces": [{ "name": "lamp", "nodes": [4], "force": [0.5, 0, -2] }],
                 "gravity": [0, 0, -9.81] },"#,
    );
    assert_ne!(loaded, patch);
    let specimen = ParallelArch::default().model().unwrap().to_json();
    let bases: Vec<Json> = [patch, loaded.as_str(), specimen.as_str()]
        .iter()
        .map(|t| serde_json::from_str(t).unwrap())
        .collect();
    let mut counts = Counts::default();
    for case in 0..MODEL_CASES {
        // Mostly the small patch (fast), plain or loaded; every fifth case the specimen.
        let base = if case % 5 == 4 { 2 } else { case % 2 };
        let mut json = bases[base].clone();
        for _ in 0..1 + rng.below(2) {
            mutate_model(&mut json, &mut rng);
        }
        counts.run += 1;
        let model = match Model::from_json(&json.to_string()) {
            Ok(m) => m,
            Err(e) => {
                assert!(!e.to_string().is_empty());
                counts.refused += 1;
                continue;
            }
        };
        // fmu-pack and fmi2Instantiate render the description: refused there, or instantiated.
        let mut inst = match Instance::from_source(Source::Model(model), Logger::silent()) {
            Ok(i) => i,
            Err(_) => {
                counts.refused += 1;
                continue;
            }
        };
        inst.setup_experiment(0.0, None).unwrap();
        inst.enter_initialization_mode().unwrap();
        if inst.exit_initialization_mode().is_err() {
            counts.refused += 1;
            continue;
        }
        step_and_classify(&mut inst, 0.25, &mut counts);
    }
    counts.print("model files");
    assert_eq!(counts.accepted_non_finite, 0, "{counts:?}");
    assert!(
        counts.refused > 0 && counts.accepted_finite > 0,
        "{counts:?}"
    );
}
