//! Finiteness of converged results: the last line of defence against reporting NaN or Inf as an
//! answer (issue 12). The solver rejects non-finite increments; callers that print or export
//! results (the CLI, the FMU) check them once more, so that no path reports a wrong number
//! as a success.

use crate::mech::model::Model;
use crate::mech::results::Results;

/// Whether every reported quantity of `results` (and the step's final residual) is finite; the
/// error names the first that is not, by gap, group or triangle.
pub fn check_results(
    model: &Model,
    results: &Results,
    residual: Option<f64>,
) -> Result<(), String> {
    let bad = |what: String, v: f64| (!v.is_finite()).then(|| format!("{what} = {v}"));
    let mut gaps = results.gaps.iter().zip(&model.gaps).flat_map(|(r, g)| {
        let name = &g.name;
        [
            bad(format!("gap {name} slip x"), r.slip_x),
            bad(format!("gap {name} slip y"), r.slip_y),
            bad(format!("gap {name} normal force"), r.normal_force),
            bad(format!("gap {name} friction force"), r.friction_force),
            bad(format!("gap {name} friction x"), r.friction[0]),
            bad(format!("gap {name} friction y"), r.friction[1]),
        ]
    });
    if let Some(p) = gaps.find_map(|p| p) {
        return Err(p);
    }
    for (r, g) in results.reactions.iter().zip(&model.groups) {
        for (c, axis) in ["x", "y", "z"].iter().enumerate() {
            if let Some(p) = bad(format!("reaction {axis} of group {}", g.name), r[c]) {
                return Err(p);
            }
        }
    }
    if let Some(e) = results
        .elements
        .iter()
        .position(|e| !e.von_mises.is_finite())
    {
        return Err(format!(
            "equivalent stress of triangle {e} = {}",
            results.elements[e].von_mises
        ));
    }
    let contacts = model
        .curved_supports
        .iter()
        .flat_map(|s| s.nodes.iter().map(move |v| (s, v)));
    for (r, (s, v)) in results.surface_contacts.iter().zip(contacts) {
        let values = [
            r.slip,
            r.travel,
            r.slip_across,
            r.gap,
            r.normal_force,
            r.friction_force,
        ];
        if let Some(x) = values
            .iter()
            .chain(&r.contact_point)
            .find(|x| !x.is_finite())
        {
            return Err(format!(
                "contact of node {v} on curved support {} = {x}",
                s.name
            ));
        }
    }
    for (r, c) in results.chambers.iter().zip(&model.chambers) {
        let values = [r.pressure, r.volume, r.temperature, r.mass];
        if let Some(x) = values.iter().find(|x| !x.is_finite()) {
            return Err(format!("air of chamber {} = {x}", c.name));
        }
    }
    for r in &results.orifices {
        if !r.mass_flow.is_finite() {
            return Err(format!("mass flow of orifice {} = {}", r.name, r.mass_flow));
        }
    }
    for (r, c) in results.cables.iter().zip(&model.cables) {
        if !r.max_force.is_finite() {
            return Err(format!("axial force of cable {} = {}", c.name, r.max_force));
        }
    }
    let sets = model.support_sets();
    for (r, name) in results.support_reactions.iter().zip(&sets) {
        if let Some(v) = r.iter().find(|v| !v.is_finite()) {
            return Err(format!("reaction of support set {name} = {v}"));
        }
    }
    if let Some(v) = results.total_reaction.iter().find(|v| !v.is_finite()) {
        return Err(format!("total reaction = {v}"));
    }
    for (p, spec) in results.points.iter().zip(&model.outputs.points) {
        if let Some(v) = p.iter().find(|v| !v.is_finite()) {
            return Err(format!("displacement of output point {} = {v}", spec.name));
        }
    }
    for (s, spec) in results.sets.iter().zip(&model.outputs.element_sets) {
        let values = [
            s.max_principal_stress,
            s.min_principal_stress,
            s.max_equivalent_stress,
            s.max_strain,
            s.compressed_area,
        ];
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(format!("field summary of element set {} = {v}", spec.name));
        }
    }
    match residual {
        Some(r) if !r.is_finite() => Err(format!("final residual = {r}")),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::Analysis;
    use crate::specimens::ParallelArch;

    #[test]
    fn each_non_finite_result_is_named_and_finite_ones_pass() {
        let spec = ParallelArch::default();
        let mut a = Analysis::new(spec.model().unwrap(), Default::default()).unwrap();
        a.step_to(&[[0.0, 0.0, 0.2 * spec.target()[2]]], 1).unwrap();
        let good = a.results();
        let model = a.model();
        check_results(model, &good, Some(1e-9)).unwrap();
        let breaks: Vec<(fn(&mut Results), &str)> = vec![
            (|r| r.gaps[4].slip_x = f64::NAN, "gap G5 slip x = NaN"),
            (
                |r| r.gaps[0].friction[1] = f64::INFINITY,
                "gap G1 friction y = inf",
            ),
            (
                |r| r.reactions[0][2] = f64::NAN,
                "reaction z of group frame = NaN",
            ),
            (|r| r.elements[7].von_mises = f64::NAN, "triangle 7"),
        ];
        for (f, expected) in breaks {
            let mut r = good.clone();
            f(&mut r);
            let e = check_results(model, &r, None).unwrap_err();
            assert!(e.contains(expected), "{e}");
        }
        let e = check_results(model, &good, Some(f64::NAN)).unwrap_err();
        assert!(e.contains("residual"), "{e}");
    }

    /// A chamber's air that is not finite (its volume gone to zero under a sealed gas) is named.
    #[test]
    fn a_chambers_non_finite_air_is_named() {
        let example = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/cushion_air.json");
        let model = Model::from_json(&std::fs::read_to_string(example).unwrap()).unwrap();
        let mut a = Analysis::new(model, Default::default()).unwrap();
        let good = a.results();
        check_results(a.model(), &good, None).unwrap();
        let mut r = good.clone();
        r.chambers[0].pressure = f64::INFINITY;
        let e = check_results(a.model(), &r, None).unwrap_err();
        assert!(e.contains("air of chamber air = inf"), "{e}");
    }
}
