//! FMU states: what `fmi2GetFMUstate` saves, and the byte format of `fmi2SerializeFMUstate`.
//!
//! A [`Snapshot`] holds everything a restored instance needs to continue exactly as the original
//! would: the phase, every variable value (parameters, inputs, the last outputs and solver
//! statistics), the time, the experiment setup, the converged [`AnalysisState`], and the VTK
//! output written so far (step count and the states written, so the `.pvd` files continue from
//! the state).
//!
//! Serialized form (little endian), version 6 (version 5 had no curved-support contacts, version
//! 4 no group angles, version 3 either no
//! load levels or VTK file names instead of state numbers, version 2 neither, version 1 no String values and no VTK
//! output; older states are refused, as they came from an FMU with another GUID anyway):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `MCFMI2ST` |
//! | 4 | format version |
//! | 4 + n | GUID length and GUID (UTF-8): a state only goes back into the same FMU |
//! | 8 | payload length |
//! | 4 | CRC-32 of all preceding bytes and the payload |
//! | payload | the snapshot as JSON (serde_json with exact float round trip) |

//!
//! A state read back is checked as strictly as a model file ([`check_analysis_state`]): sizes that
//! fit the model, finite values, magnitudes bounded by the model's size, `μ` in
//! `[0, MAX_FRICTION]`, finite load levels of the model's sizes, and gap statuses that the gap law gives again at the stored state.

use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};

use super::phase::Phase;
use super::scalar_variable::Value;
use crate::mech::elements::curved_contact::SurfaceContacts;
use crate::mech::model::{GapSupport, Hinge, MAX_FRICTION};
use crate::mech::{AnalysisState, Model};

/// Everything needed to continue an instance exactly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    pub phase: Phase,
    /// One value per variable of the table (outputs: the last computed ones).
    pub values: Vec<Value>,
    /// Whether `mu` has been set (only then does it override the model's friction).
    pub mu_set: bool,
    pub time: f64,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    /// Whether the outputs in `values` belong to the current analysis state.
    pub outputs_fresh: bool,
    /// The converged state, when an analysis exists.
    pub analysis: Option<AnalysisState>,
    /// Successful steps since initialization (the number of the next VTK file).
    pub steps: usize,
    /// The states written as VTK since initialization: `(time, state number)` (the `.pvd`
    /// entries).
    pub vtk_steps: Vec<(f64, usize)>,
}

const MAGIC: &[u8; 8] = b"MCFMI2ST";
const VERSION: u32 = 7;

/// The serialized bytes of `snapshot` for the FMU with `guid`.
pub fn serialize(snapshot: &Snapshot, guid: &str) -> Vec<u8> {
    let payload =
        serde_json::to_vec(snapshot).expect("a snapshot holds only finite numbers and serializes");
    let mut out = Vec::with_capacity(payload.len() + guid.len() + 32);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(guid.len() as u32).to_le_bytes());
    out.extend_from_slice(guid.as_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    crc.update(&out);
    crc.update(&payload);
    out.extend_from_slice(&crc.finalize().to_le_bytes());
    out.extend_from_slice(&payload);
    out
}

/// Reads serialized bytes back; refuses foreign, truncated or corrupt buffers with a message.
pub fn deserialize(bytes: &[u8], guid: &str) -> Result<Snapshot, String> {
    let mut r = Reader { bytes, at: 0 };
    if r.take(MAGIC.len()).ok() != Some(MAGIC.as_slice()) {
        return Err("not a serialized state of a membrane-contact FMU (wrong magic bytes)".into());
    }
    let version = r.u32()?;
    if version != VERSION {
        return Err(format!(
            "serialized state format version {version}; this FMU reads version {VERSION}"
        ));
    }
    let guid_len = r.u32()? as usize;
    let their_guid = r.take(guid_len)?;
    if their_guid != guid.as_bytes() {
        return Err(format!(
            "the state was serialized by another FMU (GUID {}); this one is {guid}",
            String::from_utf8_lossy(their_guid)
        ));
    }
    let payload_len = r.u64()?;
    let header_end = r.at;
    let stored_crc = r.u32()?;
    let remaining = (bytes.len() - r.at) as u64;
    if remaining != payload_len {
        return Err(format!(
            "serialized state has {remaining} payload bytes, its header says {payload_len}"
        ));
    }
    let payload = &bytes[r.at..];
    let mut crc = crc32fast::Hasher::new();
    crc.update(&bytes[..header_end]);
    crc.update(payload);
    if crc.finalize() != stored_crc {
        return Err("serialized state is corrupt (checksum mismatch)".into());
    }
    serde_json::from_slice(payload).map_err(|e| format!("serialized state payload: {e}"))
}

/// How far a displacement may be from the start, in diagonals of the model's bounding box
/// (nodes and gap support points): a film that has moved farther is not a state the solver
/// reached. Slip histories and increments are relative displacements: twice that.
pub const MAX_DISPLACEMENT_IN_DIAGONALS: f64 = 10.0;

/// Diagonal of the bounding box of the model's nodes and gap support points (m), at least 1 mm.
pub fn model_size(model: &Model) -> f64 {
    let points = model
        .nodes
        .iter()
        .copied()
        .chain(model.gaps.iter().filter_map(|g| match g.support {
            GapSupport::Point(p) => Some(p),
            GapSupport::Node(_) => None,
        }));
    let (lo, hi) = points.fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(&Vector3::from(p)), hi.sup(&Vector3::from(p))),
    );
    (hi - lo).norm().max(1e-3)
}

/// Checks a (deserialized) analysis state against `model`: sizes, finite and bounded values,
/// `μ ∈ [0, MAX_FRICTION]`, and each gap's stored status and slip history against the gap's
/// own law ([`GapLaw::check_committed`](crate::mech::elements::gap::GapLaw::check_committed), the
/// law the solver evaluates, under either friction law), and each curved-support contact's
/// status and anchor likewise ([`SurfaceContacts::check_committed`]).
pub fn check_analysis_state(model: &Model, state: &AnalysisState) -> Result<(), String> {
    check_sizes(model, state)?;
    let size = model_size(model);
    check_values(model, state, size)?;
    check_laws(model, state, size)
}

/// The sizes of a state's vectors against `model`'s.
fn check_sizes(model: &Model, state: &AnalysisState) -> Result<(), String> {
    let (n, gaps, groups) = (model.dof_count(), model.gaps.len(), model.groups.len());
    let sizes = [
        ("displacements", state.displacement.len(), n),
        ("slip histories", state.plastic_slip.len(), gaps),
        ("group displacements", state.boundary.len(), groups),
        ("group angles", state.angles.len(), groups),
        (
            "curved-support contacts",
            state.contacts.len(),
            model.curved_supports.iter().map(|s| s.nodes.len()).sum(),
        ),
        ("friction coefficients", state.friction.len(), gaps),
        ("gap statuses", state.status.len(), gaps),
    ];
    for (what, have, want) in sizes {
        if have != want {
            return Err(format!("the state has {have} {what}, the model {want}"));
        }
    }
    let loads = &state.loads;
    let load_sizes = [
        (
            "pressure levels",
            loads.pressure.len(),
            model.loads.pressures.len(),
        ),
        (
            "nodal force levels",
            loads.force.len(),
            model.loads.forces.len(),
        ),
        (
            "chamber supply levels",
            loads.chambers.len(),
            model.chambers.len(),
        ),
        (
            "chamber heating levels",
            loads.heating.len(),
            model.chambers.len(),
        ),
        ("chambers' air", state.chambers.len(), model.chambers.len()),
    ];
    for (what, have, want) in load_sizes {
        if have != want {
            return Err(format!("the state has {have} {what}, the model {want}"));
        }
    }
    for (c, spec) in state.chambers.iter().zip(&model.chambers) {
        let numbers = [c.constant, c.pressure, c.volume];
        if !numbers.iter().all(|v| v.is_finite()) || (c.sealed && !(c.constant > 0.0)) {
            return Err(format!(
                "the state's air of chamber '{}' is not finite or not positive",
                spec.name
            ));
        }
    }
    if let Some(v) = loads.values().find(|v| !v.is_finite()) {
        return Err(format!(
            "the state's load levels hold {v}, not a finite number"
        ));
    }
    if !(state.last_increment.is_empty() || state.last_increment.len() == n) {
        return Err(format!(
            "the state's last increment has {} values, the model {n} DOFs",
            state.last_increment.len()
        ));
    }
    let loads_len = loads.path().count();
    if !(state.last_load_increment.is_empty() || state.last_load_increment.len() == loads_len) {
        return Err(format!(
            "the state's last load increment has {} values, the model {loads_len} load levels",
            state.last_load_increment.len()
        ));
    }
    Ok(())
}

/// A state's values: finite, within reach of a model of `size` (m), μ and angles in range.
fn check_values(model: &Model, state: &AnalysisState, size: f64) -> Result<(), String> {
    let reach = MAX_DISPLACEMENT_IN_DIAGONALS * size;
    let bounded = |what: &str, values: &mut dyn Iterator<Item = f64>, limit: f64| match values
        .enumerate()
        .find(|(_, v)| !(v.abs() <= limit))
    {
        None => Ok(()),
        Some((i, v)) => Err(format!(
            "the state's {what} [{i}] = {v:e} m is not finite or beyond {limit:e} m \
                 ({MAX_DISPLACEMENT_IN_DIAGONALS}× the model's {size:.3} m size)"
        )),
    };
    bounded(
        "displacement",
        &mut state.displacement.iter().copied(),
        reach,
    )?;
    bounded(
        "group displacement",
        &mut state.boundary.iter().flatten().copied(),
        reach,
    )?;
    for ((g, &angle), group) in state.angles.iter().enumerate().zip(&model.groups) {
        if !angle.is_finite()
            || angle.abs() > Hinge::MAX_ANGLE
            || (group.hinge.is_none() && angle != 0.0)
        {
            return Err(format!(
                "the state's angle of group [{g}] '{}' is {angle} rad: not finite, beyond two turns, or the group has no hinge",
                group.name
            ));
        }
    }
    for (k, c) in state.contacts.iter().enumerate() {
        let values = [c.anchor[0], c.anchor[1], c.angle, c.origin];
        if values
            .iter()
            .any(|v| !v.is_finite() || v.abs() > 1e3 * reach.max(1.0))
            || !(c.friction >= 0.0 && c.friction <= MAX_FRICTION)
        {
            return Err(format!(
                "the state's curved-support contact [{k}] holds {values:?} with μ = {}: not finite, \
                 beyond the model's reach, or μ outside [0, {MAX_FRICTION}]",
                c.friction
            ));
        }
    }
    bounded(
        "slip history",
        &mut state.plastic_slip.iter().flatten().copied(),
        2.0 * reach,
    )?;
    bounded(
        "last increment",
        &mut state.last_increment.iter().copied(),
        2.0 * reach,
    )?;
    if let Some((g, mu)) = state
        .friction
        .iter()
        .enumerate()
        .find(|(_, mu)| !(**mu >= 0.0 && **mu <= MAX_FRICTION))
    {
        return Err(format!(
            "the state's friction coefficient of gap '{}' is {mu}, not in [0, {MAX_FRICTION}]",
            model.gaps[g].name
        ));
    }
    Ok(())
}

/// Each gap's and curved-support contact's stored status and history against its own law.
fn check_laws(model: &Model, state: &AnalysisState, size: f64) -> Result<(), String> {
    SurfaceContacts::new(model)
        .check_committed(&state.displacement, &state.contacts, size)
        .map_err(|(k, e)| {
            let (support, node) = model
                .curved_supports
                .iter()
                .flat_map(|s| s.nodes.iter().map(move |&v| (&s.name, v)))
                .nth(k)
                .expect("one contact per node of a curved support");
            format!(
                "the state's status of node {node} on curved support '{support}' is {:?} with \
                 its stored displacements and anchor, but {e}",
                state.contacts[k].status
            )
        })?;
    let at = |v: usize| Vector3::from_fn(|c, _| state.displacement[3 * v + c]);
    for (g, spec) in model.gaps.iter().enumerate() {
        let ub = match spec.support {
            GapSupport::Node(b) => at(b),
            GapSupport::Point(_) => Vector3::zeros(),
        };
        let d = spec.frame.rotation() * (at(spec.film_node) - ub);
        let law = crate::mech::elements::gap::GapLaw {
            friction: state.friction[g],
            ..spec.law()
        };
        // 1e-6 of the Coulomb limit μN, or of the tangential force of 1e-9 of the model's size.
        let coulomb = law.friction * law.normal_stiffness * (-(spec.initial_gap + d.z)).max(0.0);
        let tolerance = 1e-6 * coulomb.max(law.tangential_stiffness * 1e-9 * size);
        law.check_committed(
            state.status[g],
            d,
            Vector2::from(state.plastic_slip[g]),
            tolerance,
        )
        .map_err(|e| {
            format!(
                "the state's status of gap '{}' is {:?} with its stored displacements and slip \
                 history, but {e}",
                spec.name, state.status[g]
            )
        })?;
    }
    Ok(())
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end
            .ok_or_else(|| format!("serialized state is truncated ({} bytes)", self.bytes.len()))?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }

    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::Analysis;
    use crate::specimens::ParallelArch;

    /// A real converged state (one step of the specimen), whatever fields it has.
    fn converged_state() -> AnalysisState {
        let spec = ParallelArch::default();
        let mut a = Analysis::new(spec.model().unwrap(), Default::default()).unwrap();
        a.step_to(&[[0.0, 0.0, 0.1 * spec.target()[2]]], 1).unwrap();
        a.state().clone()
    }

    fn snapshot() -> Snapshot {
        Snapshot {
            phase: Phase::StepComplete,
            values: vec![
                Value::Real(0.1 + 0.2),
                Value::Integer(-3),
                Value::Boolean(true),
                Value::Real(1e-300),
                Value::String("out dir/ä \"x\"".into()),
            ],
            mu_set: true,
            time: 0.35000000000000003,
            start_time: 0.0,
            stop_time: Some(1.0),
            outputs_fresh: true,
            analysis: Some(converged_state()),
            steps: 7,
            vtk_steps: vec![(0.0, 0), (0.1 + 0.2, 7)],
        }
    }

    const GUID: &str = "{00000000-0000-5000-8000-000000000000}";

    #[test]
    fn round_trip_is_exact() {
        let s = snapshot();
        let bytes = serialize(&s, GUID);
        assert_eq!(deserialize(&bytes, GUID).unwrap(), s);
    }

    #[test]
    fn foreign_and_corrupt_buffers_are_refused() {
        let bytes = serialize(&snapshot(), GUID);
        let check = |b: &[u8], expect: &str| {
            let err = deserialize(b, GUID).unwrap_err();
            assert!(err.contains(expect), "{expect}: {err}");
        };
        check(b"", "magic");
        check(b"garbage garbage garbage", "magic");
        check(&bytes[..bytes.len() - 1], "payload bytes");
        check(&bytes[..20], "truncated");
        let mut flipped = bytes.clone();
        *flipped.last_mut().unwrap() ^= 1;
        check(&flipped, "checksum");
        let mut version = bytes.clone();
        version[8] = 9;
        check(&version, "version 9");
        let other = serialize(&snapshot(), "{11111111-0000-5000-8000-000000000000}");
        check(&other, "another FMU");
    }
}
