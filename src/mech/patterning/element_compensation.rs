//! Friction-aware compensation element by element (issue 46, step 3): a fixed point on the
//! reference metric of every triangle.
//!
//! Each triangle `t` of the found film has a target stress-free metric `M_t` (2×2, in the found
//! triangle's local frame: the metric its cut shape should have; at the start the metric of the
//! compensated cut, `M = FᵀF` with `F` the map of the found triangle onto its cut triangle). The
//! strips are flattened to these metrics in the least-squares sense (`relax::relax_flat` on the
//! stress-free shapes `x = M^{1/2} X`, whose shape gradients are `M^{-1/2} ∇N`), fitted in space
//! (`reference`), erected by the analysis, and each metric is corrected by the strain its element
//! misses,
//!
//! `M_t ← M_t − 2 F_tᵀ ΔE_t F_t`, `ΔE_t = D⁻¹(σ_target − S_t)` (a tensor: `γ/2` off the diagonal),
//!
//! with `S_t` the second Piola–Kirchhoff stress after erection in the frame of the erection
//! model's triangle (its reference) and `F_t` the map of the found triangle's frame onto that
//! triangle's frame. Why: the erected strain is `E = ½(F_xᵀF_x − G)` in the reference's
//! coordinates, so if the erected shape did not move when the reference does (a film held by its
//! boundary and pressed onto its supports nearly does not), the reference metric `G − 2ΔE` gives
//! the strain `E + ΔE` and the stress `S + DΔE = σ_target`: the step is exact to first order.
//! Friction makes the erected shape depend on the reference (a stuck node keeps the place where
//! it first touched, a sliding one carries `μN` whatever the cut), so the step is repeated; an
//! element whose error does not halve in the last step and that touches a node friction holds
//! on a support at the end (sticking, or sliding against friction) is reported as held by
//! friction. The iteration stops when the largest error grows (the corrections do not converge)
//! and keeps the best cut.

use nalgebra::{Matrix2, Matrix3x2, SymmetricEigen, Vector3};

use super::compensate::align;
use super::cut::{Compensation, CutStrip, cut_pattern};
use super::outline::bounds;
use super::reference::{erection_model, reference_geometry};
use super::relax::{StrainTerm, relax_flat};
use super::{StripTriangle, flat_gradient};
use crate::mech::elements::curved_contact::SurfaceContact;
use crate::mech::elements::gap::GapStatus;
use crate::mech::elements::triangle::ElementStress;
use crate::mech::model::Model;
use crate::mech::{Analysis, SolverSettings};

/// What an erection gives the correction.
#[derive(Clone, Debug, PartialEq)]
pub struct Erected {
    /// Strain and stress of each triangle after erection (in the erection model's frames).
    pub elements: Vec<ElementStress>,
    /// Per node: in contact and held by friction at the end, on a curved support or a gap:
    /// sticking, or sliding against a friction force.
    pub frictional: Vec<bool>,
    /// Every contact node of the curved supports at the end, in the supports' order.
    pub contacts: Vec<ContactEnd>,
}

/// A contact node of a curved support at the end of an erection.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactEnd {
    /// The film node.
    pub node: usize,
    /// The index of the curved support.
    pub support: usize,
    /// Open, sticking or sliding.
    pub status: GapStatus,
    /// Normal force (N).
    pub normal_force: f64,
    /// Friction force along the support (`ξ1`) and across it (`ξ2`) (N): against the slip.
    pub friction: [f64; 2],
    /// Arc length slid along the support while in contact (m).
    pub slip: f64,
}

/// Erects a model by the analysis and returns its stresses and the nodes friction holds.
pub type ErectContacts<'a> = dyn FnMut(Model) -> Result<Erected, String> + 'a;

/// Erects `model` by the project's analysis (every group to its target in `increments`) and
/// reports which nodes friction holds on a curved support or gap at the end.
pub fn erect_with_contacts(model: Model, increments: usize) -> Result<Erected, String> {
    erect_along(model, increments, &[])
}

/// The rails' start offsets of the erection path: each node of the `found` model's
/// boundary groups starts `up` (m, +z) above and `inward` (m, horizontally from its group's
/// centroid towards the film's: across a straight rail) from its place, and is pulled down and
/// out to it.
pub fn rail_start_offsets(found: &Model, up: f64, inward: f64) -> Vec<(usize, [f64; 3])> {
    let centroid = |nodes: &mut dyn Iterator<Item = usize>| {
        let (mut c, mut n) = ([0.0; 2], 0.0);
        for v in nodes {
            c = [c[0] + found.nodes[v][0], c[1] + found.nodes[v][1]];
            n += 1.0;
        }
        c.map(|c| c / f64::max(n, 1.0))
    };
    let film = centroid(&mut (0..found.nodes.len()));
    let mut offsets = Vec::new();
    for g in &found.groups {
        let rail = centroid(&mut g.nodes.iter().copied());
        let (dx, dy) = (film[0] - rail[0], film[1] - rail[1]);
        let d = dx.hypot(dy).max(f64::MIN_POSITIVE);
        offsets.extend(
            g.nodes
                .iter()
                .map(|&v| (v, [inward * dx / d, inward * dy / d, up])),
        );
    }
    offsets
}

/// The waypoints of a winding erection path: for each `[up, inward]` of `path` the rails'
/// offsets there ([`rail_start_offsets`]); the rails pass through them in turn and end at their
/// places (the bay: `[[0.10, 0.03], [0.0, 0.03]]`, down, then out).
pub fn rail_waypoints(found: &Model, path: &[[f64; 2]]) -> Vec<Vec<(usize, [f64; 3])>> {
    path.iter()
        .map(|&[up, inward]| rail_start_offsets(found, up, inward))
        .collect()
}

/// The most waypoints [`settling_waypoints`] takes (reversals far below the stick springs' travel
/// change nothing).
pub const MAX_SETTLING_CYCLES: usize = 1000;

/// The rails' waypoints `[up, in]` of a path that settles the film on its frictional supports:
/// `path`, then `cycles` waypoints past and short of the rails' places in turn along the last
/// waypoint's direction, the first `amplitude` (m) past them, each next `ratio` (0 < ratio < 1)
/// times the one before, `w_k = (−1)^{k+1} amplitude ratioᵏ d` with `d` the last waypoint's
/// unit direction; the rails then end at their places. Each reversal slides the film back over a
/// shorter arc than the one before, so the last state sticks with a tension nearly even along the
/// supports instead of the capstan's fall (docs/mechanics.md, "Settling the film").
pub fn settling_waypoints(
    path: &[[f64; 2]],
    amplitude: f64,
    ratio: f64,
    cycles: usize,
) -> Result<Vec<[f64; 2]>, String> {
    let Some(&[up, inward]) = path.last() else {
        return Err("settling: give the erection path to settle after (--rail-path)".into());
    };
    let length = up.hypot(inward);
    if !(length.is_finite() && length > 0.0) {
        return Err(format!(
            "settling: the last waypoint [{up}, {inward}] has no direction to settle along"
        ));
    }
    if !(amplitude.is_finite() && amplitude > 0.0) {
        return Err(format!(
            "settling: amplitude {amplitude} m is not a positive length"
        ));
    }
    if !(ratio > 0.0 && ratio < 1.0) {
        return Err(format!("settling: ratio {ratio} is not between 0 and 1"));
    }
    if cycles > MAX_SETTLING_CYCLES {
        return Err(format!(
            "settling: {cycles} cycles, more than {MAX_SETTLING_CYCLES} (each is a leg of the erection)"
        ));
    }
    let d = [up / length, inward / length];
    let mut waypoints = path.to_vec();
    let mut a = -amplitude;
    for _ in 0..cycles {
        waypoints.push(d.map(|c| a * c));
        a *= -ratio;
    }
    Ok(waypoints)
}

/// The ratio of the settling the design loop takes when it chooses the amplitude (`--settle auto`).
pub const SETTLING_RATIO: f64 = 0.7;

/// The waypoints of the settling the design loop takes when it chooses the amplitude.
pub const SETTLING_CYCLES: usize = 12;

/// The settling amplitude the design loop chooses: half the length change the target prestress
/// asks of the longest strip, `a = ½ ε L`, with `ε` the larger normal strain of `D⁻¹σ_target`
/// (the prestress compensation, `σ(1 − ν)/E` biaxial) and `L` the longest distance across a `cut`
/// strip (m: between two of its flat nodes, whatever way the flattening turned it). Each rail's first pass then changes the film's tension at the rail by about the
/// target itself, far over the capstan's `e^{μθ} − 1` that the film must slide back over to reach
/// the crown, and far under yield (docs/mechanics.md, "Settling the film").
pub fn settling_amplitude(found: &Model, cut: &[CutStrip]) -> Result<f64, String> {
    let strain = found
        .material
        .elasticity()
        .try_inverse()
        .map(|c| c * Vector3::from(found.material.prestress))
        .map_or(0.0, |e| e.x.abs().max(e.y.abs()));
    let length = cut.iter().fold(0.0, |l: f64, c| {
        let flat = &c.strip.flat;
        (flat.iter().enumerate())
            .flat_map(|(i, p)| {
                flat[i + 1..]
                    .iter()
                    .map(move |q| (p[0] - q[0]).hypot(p[1] - q[1]))
            })
            .fold(l, f64::max)
    });
    let amplitude = 0.5 * strain * length;
    if amplitude.is_finite() && amplitude > 0.0 {
        Ok(amplitude)
    } else {
        Err(format!(
            "settling: the target prestress {:?} Pa asks no strain of the strips ({length} m) to size \
             the amplitude by: give --settle AMPLITUDE,RATIO,CYCLES",
            found.material.prestress
        ))
    }
}

/// Erects `model` (an [`super::reference::erection_model`], one group `node<k>` per held node)
/// in two stages: first each node `k` of `start` to its target plus its offset (the rails lifted
/// and drawn in: the film laid on the supports slack), then every group to its target (the rails
/// pulled down and out), `increments` each; with no offsets, one stage.
pub fn erect_along(
    model: Model,
    increments: usize,
    start: &[(usize, [f64; 3])],
) -> Result<Erected, String> {
    let waypoints = if start.is_empty() {
        vec![]
    } else {
        vec![start.to_vec()]
    };
    erect_through(model, increments, &waypoints)
}

/// Erects `model` along a winding path: each node `k` of the first waypoint goes to its target
/// plus its offset there, then on through every further waypoint's offsets, straight from one
/// to the next, and last every group to its target; `increments` per leg. Friction makes the
/// erected state depend on the legs (a node that sticks on one leg keeps its place into the
/// next); without it only the end counts.
///
/// A curved support's contact holds a node off the tube's surface on either side, so a node that
/// one Newton iteration carries past the tube's centreline ends on its far side: the film passes
/// through the support and settles in a wrong equilibrium (the vault bay at 48 × 16 cells, 40
/// increments a leg: the nodes beside the rails under their arches, every element away from the
/// rails at 2.3–3 times its target). After each leg the nodes are checked ([`passed_through_supports`]); where any
/// passed, the erection is run again with twice the increments, at most
/// [`PASSED_THROUGH_RETRIES`] times, then refused naming them.
pub fn erect_through(
    model: Model,
    increments: usize,
    waypoints: &[Vec<(usize, [f64; 3])>],
) -> Result<Erected, String> {
    let mut n = increments;
    for _ in 0..PASSED_THROUGH_RETRIES {
        match erect_through_once(model.clone(), n, waypoints)? {
            Ok(erected) => return Ok(erected),
            Err(_) => n *= 2,
        }
    }
    match erect_through_once(model, n, waypoints)? {
        Ok(erected) => Ok(erected),
        Err(through) => Err(format!(
            "erection: the film passed through its supports ({}) with {increments} to {n} \
             increments a leg: give more increments",
            through
                .iter()
                .map(|(s, v)| format!("{s} at node {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// Times [`erect_through`] doubles the increments of an erection that passed through a support.
pub const PASSED_THROUGH_RETRIES: usize = 2;

/// The curved supports' contact nodes of `model` at `positions` (every node's, m) whose normal
/// to their support points against the one at the model's own node positions (turned by more
/// than 90°): nodes carried through the support's tube, as (support name, node).
pub fn passed_through_supports(model: &Model, positions: &[[f64; 3]]) -> Vec<(String, usize)> {
    let mut through = Vec::new();
    for s in &model.curved_supports {
        for &v in &s.nodes {
            let c = SurfaceContact::new(s, v);
            let start = c.project(&Vector3::from(model.nodes[v]), 0.0);
            let end = c.project(&Vector3::from(positions[v]), start.parameter);
            if end.normal.dot(&start.normal) < 0.0 {
                through.push((s.name.clone(), v));
            }
        }
    }
    through
}

/// One erection along the legs with `increments` each; Ok(Err(nodes)) where a leg ended with
/// nodes through their supports ([`passed_through_supports`]).
fn erect_through_once(
    model: Model,
    increments: usize,
    waypoints: &[Vec<(usize, [f64; 3])>],
) -> Result<Result<Erected, Vec<(String, usize)>>, String> {
    let targets: Vec<[f64; 3]> = model.groups.iter().map(|g| g.target).collect();
    let mut legs = Vec::new();
    for offsets in waypoints.iter().filter(|w| !w.is_empty()) {
        let mut leg = targets.clone();
        for &(v, offset) in offsets {
            let name = format!("node{v}");
            let Some(g) = model.groups.iter().position(|g| g.name == name) else {
                return Err(format!(
                    "erection path: node {v} has no group {name} in the erection model"
                ));
            };
            (0..3).for_each(|c| leg[g][c] += offset[c]);
        }
        legs.push(leg);
    }
    let mut analysis = Analysis::new(model, SolverSettings::default())
        .map_err(|e| format!("erection model: {e}"))?;
    let through = |a: &Analysis| {
        let m = a.model();
        let x: Vec<[f64; 3]> = (0..m.nodes.len())
            .map(|v| (Vector3::from(m.nodes[v]) + a.node_displacement(v)).into())
            .collect();
        passed_through_supports(m, &x)
    };
    for (k, leg) in legs.iter().enumerate() {
        analysis
            .step_to(leg, increments)
            .map_err(|e| format!("erection, rails to waypoint {}: {e}", k + 1))?;
        let nodes = through(&analysis);
        if !nodes.is_empty() {
            return Ok(Err(nodes));
        }
    }
    analysis
        .step_to(&targets, increments)
        .map_err(|e| format!("erection: {e}"))?;
    let nodes = through(&analysis);
    Ok(if nodes.is_empty() {
        Ok(erected(&mut analysis))
    } else {
        Err(nodes)
    })
}

/// The stresses of an erected `analysis` and the nodes friction holds on a support.
fn erected(analysis: &mut Analysis) -> Erected {
    let results = analysis.results();
    let model = analysis.model();
    let held = |status: GapStatus, friction: f64| {
        status == GapStatus::Stick || (status == GapStatus::Slip && friction > 0.0)
    };
    let mut frictional = vec![false; model.nodes.len()];
    let contact_nodes = (model.curved_supports.iter().enumerate())
        .flat_map(|(k, s)| s.nodes.iter().map(move |&v| (k, v)));
    let mut contacts = Vec::new();
    for ((support, node), c) in contact_nodes.zip(&results.surface_contacts) {
        frictional[node] |= held(c.status, c.friction_force);
        contacts.push(ContactEnd {
            node,
            support,
            status: c.status,
            normal_force: c.normal_force,
            friction: c.friction,
            slip: c.slip,
        });
    }
    for (g, r) in model.gaps.iter().zip(&results.gaps) {
        frictional[g.film_node] |= held(r.status, r.friction_force);
    }
    Erected {
        elements: results.elements,
        frictional,
        contacts,
    }
}

/// The stress-free shape of metric `m` (in the frame of the 3-D triangle `t`) as a strain term:
/// `x = U X` with `U = M^{1/2}`, so `∇N = U⁻¹ ∇N_X` and the area is `det U · A`.
pub fn metric_term(t: &StripTriangle, m: &Matrix2<f64>) -> Option<StrainTerm> {
    let eigen = SymmetricEigen::new(*m);
    if !eigen.eigenvalues.iter().all(|&l| l > 0.0 && l.is_finite()) {
        return None;
    }
    let v = eigen.eigenvectors;
    let root = eigen.eigenvalues.map(f64::sqrt);
    let u_inv = v * Matrix2::from_diagonal(&root.map(|r| 1.0 / r)) * v.transpose();
    Some(StrainTerm {
        nodes: t.local,
        gradients: t.element.shape_gradients().map(|g| u_inv * g),
        area: t.element.area() * root.x * root.y,
    })
}

/// The metric `M = FᵀF` of every cut triangle in its found triangle's frame (`F` the map of the
/// found triangle onto the flat one), indexed by the model's triangles.
pub fn cut_metrics(found: &Model, cut: &[CutStrip]) -> Result<Vec<Matrix2<f64>>, String> {
    let mut metrics = vec![Matrix2::identity(); found.triangles.len()];
    for (k, c) in cut.iter().enumerate() {
        let elements = c
            .strip
            .elements(found, &found.nodes)
            .map_err(|e| format!("strip {k}: {e}"))?;
        for (e, &t) in elements.iter().zip(&c.strip.triangles) {
            let f = flat_gradient(e, &c.strip.flat);
            metrics[t] = f.transpose() * f;
        }
    }
    Ok(metrics)
}

/// Flattens each strip again to the target `metrics` (least strain, from its present flat
/// positions), turns it to its long axis ([`align`]) and updates its size and its compensation, `c_a = L_a/ℓ_a − 1` with `L_a` the
/// uncompensated length `uncut[k][a]` and `ℓ_a` the new one.
pub fn refit_strips(
    found: &Model,
    cut: &mut [CutStrip],
    metrics: &[Matrix2<f64>],
    uncut: &[[f64; 2]],
) -> Result<(), String> {
    for (k, c) in cut.iter_mut().enumerate() {
        let elements = c
            .strip
            .elements(found, &found.nodes)
            .map_err(|e| format!("strip {k}: {e}"))?;
        let terms = elements
            .iter()
            .zip(&c.strip.triangles)
            .map(|(e, &t)| {
                metric_term(e, &metrics[t]).ok_or_else(|| {
                    format!("strip {k}: triangle {t}: the corrected metric is not positive definite (the correction asks more than the film can shrink)")
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        relax_flat(&mut c.strip.flat, &terms, 100).map_err(|e| format!("strip {k}: {e}"))?;
        let local: Vec<[usize; 3]> = elements.iter().map(|e| e.local).collect();
        align(&mut c.strip.flat, &local);
        let b = bounds(&c.strip.flat);
        c.size = [b[2] - b[0], b[3] - b[1]];
        c.compensation = [0, 1].map(|a| uncut[k][a] / c.size[a] - 1.0);
    }
    Ok(())
}

/// The correction `−2 Fᵀ ΔE F` of triangle `t`'s target metric from its erected `stress`
/// (`ΔE = D⁻¹(σ_target − S)`, `F` the found triangle's frame onto the `reference` triangle's).
pub fn metric_correction(
    found: &Model,
    reference: &[[f64; 3]],
    t: usize,
    stress: &ElementStress,
) -> Option<Matrix2<f64>> {
    let tri = found.triangles[t];
    let on = |x: &[[f64; 3]]| found.element_on(t, x).ok();
    let (found_element, reference_element) = (on(&found.nodes)?, on(reference)?);
    let g = found_element.shape_gradients();
    let f3 = (0..3).fold(Matrix3x2::zeros(), |f, k| {
        f + Vector3::from(reference[tri[k]]) * g[k].transpose()
    });
    let (e1, e2) = reference_element.local_axes();
    let f = Matrix2::from_rows(&[(e1.transpose() * f3), (e2.transpose() * f3)]);
    let d_inv = found.material.elasticity().try_inverse()?;
    let target = Vector3::from(found.material.prestress);
    let deficit = d_inv * (target - Vector3::from(stress.stress));
    let de = Matrix2::new(deficit.x, 0.5 * deficit.z, 0.5 * deficit.z, deficit.y);
    Some(-2.0 * f.transpose() * de * f)
}

/// Each triangle's error `max(|σx − σx*|, |σy − σy*|)/max(|σx*|, |σy*|)` after erection.
pub fn element_errors(found: &Model, elements: &[ElementStress]) -> Vec<f64> {
    let target = found.material.prestress;
    let size = target[0].abs().max(target[1].abs()).max(f64::MIN_POSITIVE);
    elements
        .iter()
        .map(|e| {
            (e.stress[0] - target[0])
                .abs()
                .max((e.stress[1] - target[1]).abs())
                / size
        })
        .collect()
}

/// The triangles none of whose nodes a support or boundary group holds (away from the rails).
pub fn away_from_rails(found: &Model) -> Vec<bool> {
    let mut rail = vec![false; found.nodes.len()];
    found.supports.iter().for_each(|s| rail[s.node] = true);
    found
        .groups
        .iter()
        .flat_map(|g| g.nodes.iter())
        .for_each(|&v| rail[v] = true);
    found
        .triangles
        .iter()
        .map(|t| t.iter().all(|&v| !rail[v]))
        .collect()
}

/// Settings of [`compensate_elements`].
#[derive(Clone, Debug, PartialEq)]
pub struct ElementSettings {
    /// Erections at most.
    pub iterations: usize,
    /// Largest element error accepted over the `counted` elements.
    pub tolerance: f64,
    /// The triangles the error is taken over (all are corrected); e.g. [`away_from_rails`].
    pub counted: Vec<bool>,
}

/// One erection of the element-wise iteration.
#[derive(Clone, Debug, PartialEq)]
pub struct ElementIteration {
    /// Area-weighted mean error over the counted triangles.
    pub mean_error: f64,
    /// Largest error over the counted triangles, and that triangle.
    pub max_error: (f64, usize),
    /// Every triangle's error ([`element_errors`]).
    pub element_errors: Vec<f64>,
    /// Triangles with plastic strain after erection.
    pub yielded: usize,
    /// Each strip's overall compensation `[c_x, c_y]` (its cut lengths against the flat strip).
    pub compensation: Vec<[f64; 2]>,
    /// Every triangle's stress `[σx, σy, τxy]` after erection (Pa, the erection model's frames).
    pub stresses: Vec<[f64; 3]>,
    /// The curved supports' contact nodes at the end ([`Erected::contacts`]).
    pub contacts: Vec<ContactEnd>,
}

/// The outcome of [`compensate_elements`].
#[derive(Clone, Debug, PartialEq)]
pub struct ElementCompensation {
    /// Every erection.
    pub history: Vec<ElementIteration>,
    /// The cut of the erection with the smallest largest error.
    pub cut: Vec<CutStrip>,
    /// Counted triangles still above the tolerance whose error did not halve in the last step.
    pub stalled: Vec<usize>,
    /// Those of `stalled` that touch a node friction holds on a support (sticking, or sliding
    /// against friction): their stress is set by friction, not by their cut.
    pub held_by_friction: Vec<usize>,
}

fn record(
    found: &Model,
    settings: &ElementSettings,
    erected: &Erected,
    cut: &[CutStrip],
) -> ElementIteration {
    let errors = element_errors(found, &erected.elements);
    let (mut sum, mut area, mut max) = (0.0, 0.0, (0.0, 0));
    for (t, tri) in found.triangles.iter().enumerate() {
        if !settings.counted[t] {
            continue;
        }
        let p = tri.map(|v| Vector3::from(found.nodes[v]));
        let a = 0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm();
        sum += a * errors[t];
        area += a;
        if errors[t] > max.0 {
            max = (errors[t], t);
        }
    }
    let plastic = |e: &ElementStress| e.plastic.is_some_and(|p| p.equivalent_plastic_strain > 0.0);
    ElementIteration {
        mean_error: sum / area.max(f64::MIN_POSITIVE),
        max_error: max,
        yielded: erected.elements.iter().filter(|e| plastic(e)).count(),
        element_errors: errors,
        compensation: cut.iter().map(|c| c.compensation).collect(),
        stresses: erected.elements.iter().map(|e| e.stress).collect(),
        contacts: erected.contacts.clone(),
    }
}

/// Cuts the `strips` of the `found` model with the `start` compensation, then erects with
/// `erect`, corrects every triangle's target metric ([`metric_correction`]) and flattens the
/// strips again ([`refit_strips`]), until the largest counted error is within the tolerance, the
/// erections are spent, or the largest error grows (the corrections do not converge); returns
/// the best cut and reports the triangles that stalled and those held by friction.
pub fn compensate_elements(
    found: &Model,
    strips: Vec<Vec<usize>>,
    start: Compensation,
    settings: &ElementSettings,
    erect: &mut ErectContacts<'_>,
) -> Result<ElementCompensation, String> {
    if settings.counted.len() != found.triangles.len() {
        return Err(format!(
            "element compensation: {} counted flags for {} triangles",
            settings.counted.len(),
            found.triangles.len()
        ));
    }
    let mut cut = cut_pattern(found, strips, start)?;
    let uncut: Vec<[f64; 2]> = cut
        .iter()
        .map(|c| [0, 1].map(|a| c.size[a] * (1.0 + c.compensation[a])))
        .collect();
    let mut metrics = cut_metrics(found, &cut)?;
    let (mut history, mut sticking) = (Vec::new(), Vec::new());
    let mut best: Option<(f64, Vec<CutStrip>)> = None;
    for iteration in 0..settings.iterations {
        if iteration > 0 {
            refit_strips(found, &mut cut, &metrics, &uncut)?;
        }
        let reference = reference_geometry(found, &cut)?;
        let erected = erect(erection_model(found, reference.clone()))?;
        let now = record(found, settings, &erected, &cut);
        let worst = now.max_error.0;
        history.push(now);
        sticking = erected.frictional;
        // The largest error grew: the corrections do not converge (friction moves the film
        // where they push it); stop and keep the best cut.
        if best.as_ref().is_some_and(|b| worst > b.0) {
            break;
        }
        best = Some((worst, cut.clone()));
        if worst <= settings.tolerance {
            break;
        }
        for (t, m) in metrics.iter_mut().enumerate() {
            if let Some(dm) = metric_correction(found, &reference, t, &erected.elements[t]) {
                *m += dm;
            }
        }
    }
    let (stalled, held_by_friction) = diagnose(found, settings, &history, &sticking);
    Ok(ElementCompensation {
        history,
        cut: best.map_or(cut, |b| b.1),
        stalled,
        held_by_friction,
    })
}

/// The counted triangles above the tolerance whose error did not halve in the last step, and
/// those of them with a node that friction holds (`sticking`: [`Erected::frictional`]).
fn diagnose(
    found: &Model,
    settings: &ElementSettings,
    history: &[ElementIteration],
    sticking: &[bool],
) -> (Vec<usize>, Vec<usize>) {
    let [.., before, last] = history else {
        return (vec![], vec![]);
    };
    let stalled: Vec<usize> = (0..found.triangles.len())
        .filter(|&t| settings.counted[t])
        .filter(|&t| {
            let e = last.element_errors[t];
            e > settings.tolerance && e > 0.5 * before.element_errors[t]
        })
        .collect();
    let held = stalled
        .iter()
        .copied()
        .filter(|&t| found.triangles[t].iter().any(|&v| sticking[v]))
        .collect();
    (stalled, held)
}
