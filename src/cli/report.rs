//! Engineering outputs of a run: reactions per unit length along boundary groups and support
//! sets (`--line-reactions FILE`, CSV, every step; [`membrane_contact::mech::results::lines`]) and a run
//! report (`--report FILE.md`, Markdown): the model, the load steps, the reactions of every step,
//! the line reactions, extreme stresses, wrinkled and slack areas, the slips along every support,
//! the warnings and the solver's statistics of the run.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use membrane_contact::fmi2::variables::StepInputs;
use membrane_contact::mech::elements::temperature::{
    REFERENCE_TEMPERATURE, flow_stress_factor, modulus_factor,
};
use membrane_contact::mech::results::lines::{ReactionLine, reaction_lines};
use membrane_contact::mech::results::warnings::{model_warnings, result_warnings};
use membrane_contact::mech::{Analysis, Model, Results, StepReport, WrinklingState};

/// The header of the `--line-reactions` CSV.
pub const LINE_REACTIONS_HEADER: &str = "step,time,line,kind,node,x_m,y_m,z_m,s_m,tributary_m,\
     Rx_N,Ry_N,Rz_N,qx_N_per_m,qy_N_per_m,qz_N_per_m,q_N_per_m";

/// What one converged step did and reached.
struct StepRecord {
    step: usize,
    time: f64,
    increments: usize,
    iterations: usize,
    cutbacks: usize,
    targets: Vec<[f64; 3]>,
    pressures: Vec<f64>,
    reactions: Vec<[f64; 3]>,
    support_reactions: Vec<[f64; 3]>,
}

/// The line-reaction table and the run report of a run, fed step by step.
pub struct Outputs {
    lines: Vec<ReactionLine>,
    notes: Vec<String>,
    csv: Option<(std::fs::File, String)>,
    report: Option<std::path::PathBuf>,
    steps: Vec<StepRecord>,
    /// Result warnings with the first step that gave each.
    warnings: Vec<(usize, String)>,
}

impl Outputs {
    /// Opens the line-reaction CSV (header written) and notes the report's path; prints on
    /// stderr why a group or support set has no line reactions when either output is asked for.
    pub fn create(
        model: &Model,
        line_csv: Option<&Path>,
        report: Option<&Path>,
    ) -> Result<Self, String> {
        let (lines, notes) = if line_csv.is_some() || report.is_some() {
            reaction_lines(model)
        } else {
            (vec![], vec![])
        };
        for n in &notes {
            eprintln!("note: {n}");
        }
        let csv = match line_csv {
            Some(path) => {
                let name = path.display().to_string();
                let mut f = std::fs::File::create(path).map_err(|e| format!("{name}: {e}"))?;
                writeln!(f, "{LINE_REACTIONS_HEADER}").map_err(|e| format!("{name}: {e}"))?;
                Some((f, name))
            }
            None => None,
        };
        Ok(Self {
            lines,
            notes,
            csv,
            report: report.map(Path::to_path_buf),
            steps: vec![],
            warnings: vec![],
        })
    }

    /// Whether the outputs need the results of every step.
    pub fn wants_results(&self) -> bool {
        self.csv.is_some() || self.report.is_some()
    }

    /// Records converged step `step` (at `time`, reached with `inputs` as `stats` says).
    pub fn step(
        &mut self,
        step: usize,
        time: f64,
        inputs: &StepInputs,
        stats: &StepReport,
        analysis: &Analysis,
        results: &Results,
    ) -> Result<(), String> {
        let model = analysis.model();
        if let Some((f, name)) = self.csv.as_mut() {
            for line in &self.lines {
                for r in line.reactions(results) {
                    let x = model.nodes[r.node];
                    let q = r.per_length;
                    writeln!(
                        f,
                        "{step},{time},{},{},{},{},{},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
                        line.name,
                        line.kind.label().replace(' ', "_"),
                        r.node,
                        x[0],
                        x[1],
                        x[2],
                        r.position.map_or(String::new(), |s| format!("{s}")),
                        r.tributary,
                        r.reaction[0],
                        r.reaction[1],
                        r.reaction[2],
                        q[0],
                        q[1],
                        q[2],
                        (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt()
                    )
                    .map_err(|e| format!("{name}: {e}"))?;
                }
            }
        }
        if self.report.is_some() {
            self.steps.push(StepRecord {
                step,
                time,
                increments: stats.iterations.len(),
                iterations: stats.total_iterations(),
                cutbacks: stats.cutbacks,
                targets: inputs.targets.clone(),
                pressures: inputs.loads.pressure.clone(),
                reactions: results.reactions.clone(),
                support_reactions: results.support_reactions.clone(),
            });
            for w in result_warnings(model, results) {
                if !self.warnings.iter().any(|(_, v)| *v == w) {
                    self.warnings.push((step, w));
                }
            }
        }
        Ok(())
    }

    /// Writes the report of the run (nothing without `--report`). `elapsed`: seconds of the run.
    pub fn finish(
        &self,
        analysis: &Analysis,
        results: &Results,
        elapsed: f64,
    ) -> Result<(), String> {
        let Some(path) = &self.report else {
            return Ok(());
        };
        let text = self.markdown(analysis, results, elapsed);
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
    }

    fn markdown(&self, analysis: &Analysis, results: &Results, elapsed: f64) -> String {
        let model = analysis.model();
        let mut s = String::new();
        let _ = writeln!(s, "# Run report: {}\n", model.name);
        if !model.description.is_empty() {
            let _ = writeln!(s, "{}\n", model.description);
        }
        model_section(&mut s, model);
        self.steps_section(&mut s, model);
        self.reactions_section(&mut s, model);
        self.line_section(&mut s, model, results);
        stress_section(&mut s, model, results);
        slip_section(&mut s, model, results);
        self.warnings_section(&mut s, model);
        self.solver_section(&mut s, analysis, elapsed);
        s
    }

    fn steps_section(&self, s: &mut String, model: &Model) {
        let _ = writeln!(s, "## Load steps\n");
        let mut head = "| step | time | increments | cut-backs | iterations |".to_string();
        let mut rule = "|---:|---:|---:|---:|---:|".to_string();
        for g in &model.groups {
            let _ = write!(head, " {} target (m) |", g.name);
            rule.push_str("---|");
        }
        for p in &model.loads.pressures {
            let _ = write!(head, " {} (Pa) |", p.name);
            rule.push_str("---:|");
        }
        let _ = writeln!(s, "{head}\n{rule}");
        for r in &self.steps {
            let _ = write!(
                s,
                "| {} | {} | {} | {} | {} |",
                r.step,
                num(r.time),
                r.increments,
                r.cutbacks,
                r.iterations
            );
            for t in &r.targets {
                let _ = write!(s, " ({}, {}, {}) |", num(t[0]), num(t[1]), num(t[2]));
            }
            for p in &r.pressures {
                let _ = write!(s, " {} |", num(*p));
            }
            s.push('\n');
        }
        s.push('\n');
    }

    fn reactions_section(&self, s: &mut String, model: &Model) {
        let _ = writeln!(s, "## Reactions\n");
        let sets = model.support_sets();
        let owners = model
            .groups
            .iter()
            .map(|g| format!("group `{}`", g.name))
            .chain(sets.iter().map(|n| format!("support set `{n}`")));
        let mut any = false;
        for (k, owner) in owners.enumerate() {
            any = true;
            let _ = writeln!(
                s,
                "### Reaction of {owner} (N)\n\n| step | Rx | Ry | Rz |\n|---:|---:|---:|---:|"
            );
            for r in &self.steps {
                let v = if k < model.groups.len() {
                    r.reactions[k]
                } else {
                    r.support_reactions[k - model.groups.len()]
                };
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} |",
                    r.step,
                    num(v[0]),
                    num(v[1]),
                    num(v[2])
                );
            }
            s.push('\n');
        }
        if !any {
            let _ = writeln!(s, "No boundary groups or named support sets.\n");
        }
    }

    fn line_section(&self, s: &mut String, model: &Model, results: &Results) {
        let _ = writeln!(
            s,
            "## Reactions per unit length (last step)\n\n\
             Each node's reaction divided by its tributary length (half its film edges along the \
             line, reference geometry); q · tributary summed over a line gives its reaction.\n"
        );
        for line in &self.lines {
            let rows = line.reactions(results);
            let total: [f64; 3] =
                std::array::from_fn(|c| rows.iter().map(|r| r.per_length[c] * r.tributary).sum());
            let _ = writeln!(
                s,
                "### {} `{}`: {} nodes, length {} m, Σ q·l = ({}, {}, {}) N\n",
                line.kind.label(),
                line.name,
                line.nodes.len(),
                num(line.length()),
                num(total[0]),
                num(total[1]),
                num(total[2])
            );
            let _ = writeln!(
                s,
                "| node | x (m) | y (m) | z (m) | s (m) | tributary (m) | qx (N/m) | qy (N/m) | qz (N/m) | \\|q\\| (N/m) |\n\
                 |---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
            );
            for r in rows {
                let (x, q) = (model.nodes[r.node], r.per_length);
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    r.node,
                    num(x[0]),
                    num(x[1]),
                    num(x[2]),
                    r.position.map_or("–".into(), num),
                    num(r.tributary),
                    num(q[0]),
                    num(q[1]),
                    num(q[2]),
                    num((q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt())
                );
            }
            s.push('\n');
        }
        for n in &self.notes {
            let _ = writeln!(s, "- {n}");
        }
        if self.lines.is_empty() && self.notes.is_empty() {
            let _ = writeln!(s, "No boundary groups or named support sets.");
        }
        s.push('\n');
    }

    fn warnings_section(&self, s: &mut String, model: &Model) {
        let _ = writeln!(s, "## Warnings\n");
        let before = model_warnings(model);
        for w in &before {
            let _ = writeln!(s, "- model: {w}");
        }
        for (step, w) in &self.warnings {
            let _ = writeln!(s, "- from step {step}: {w}");
        }
        if before.is_empty() && self.warnings.is_empty() {
            let _ = writeln!(s, "None.");
        }
        s.push('\n');
    }

    fn solver_section(&self, s: &mut String, analysis: &Analysis, elapsed: f64) {
        let increments: usize = self.steps.iter().map(|r| r.increments).sum();
        let iterations: usize = self.steps.iter().map(|r| r.iterations).sum();
        let cutbacks: usize = self.steps.iter().map(|r| r.cutbacks).sum();
        let [lu, ldlt, redone, gmres] = analysis.factorization_counts();
        let _ = writeln!(
            s,
            "## Solver\n\n| quantity | value |\n|---|---:|\n| steps | {} |\n| increments | {increments} |\n\
             | cut-backs | {cutbacks} |\n| Newton iterations | {iterations} |\n\
             | iterations per increment | {:.1} |\n| LU factorizations | {lu} |\n\
             | LDLᵀ factorizations | {ldlt} |\n| redone by LU | {redone} |\n| GMRES solves | {gmres} |\n\
             | time | {:.1} ms |",
            self.steps.len(),
            iterations as f64 / increments.max(1) as f64,
            elapsed * 1e3
        );
    }
}

/// A number with six significant digits (plain between 1e-3 and 1e7, else scientific).
pub fn num(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 {
        "0".into()
    } else if !(1e-3..1e7).contains(&a) {
        format!("{x:.5e}")
    } else {
        let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    }
}

fn model_section(s: &mut String, model: &Model) {
    let m = &model.material;
    let contacts: usize = model.curved_supports.iter().map(|c| c.nodes.len()).sum();
    let _ = writeln!(
        s,
        "## Model\n\n| item | value |\n|---|---|\n| nodes | {} |\n| triangles | {} |\n| gaps | {} |\n\
         | curved supports | {} ({contacts} contact nodes) |\n| cables | {} |\n| boundary groups | {} |\n\
         | support sets | {} |\n| supported nodes | {} |\n| symmetry planes | {} |\n\
         | Young's modulus | {} Pa |\n| Poisson's ratio | {} |\n| thickness | {} m |\n\
         | prestress (σx, σy, τxy) | ({}, {}, {}) Pa |\n| wrinkling | {:?} |\n| yield stress | {} |\n",
        model.nodes.len(),
        model.triangles.len(),
        model.gaps.len(),
        model.curved_supports.len(),
        model.cables.len(),
        model.groups.len(),
        model.support_sets().len(),
        model.supports.len(),
        model.symmetry.len(),
        num(m.youngs_modulus),
        num(m.poisson_ratio),
        num(m.thickness),
        num(m.prestress[0]),
        num(m.prestress[1]),
        num(m.prestress[2]),
        m.wrinkling,
        m.yield_stress
            .map_or("none".into(), |y| format!("{} Pa", num(y)))
    );
    if m.temperature != REFERENCE_TEMPERATURE {
        let _ = writeln!(
            s,
            "| temperature | {} °C: E × {:.4}, yield and flow stresses × {:.4} (given at 23 °C) |",
            num(m.temperature),
            modulus_factor(m.temperature),
            flow_stress_factor(m.temperature)
        );
    }
}

fn reference_area(model: &Model, t: &[usize; 3]) -> f64 {
    let [a, b, c] = t.map(|v| model.nodes[v]);
    let u: [f64; 3] = std::array::from_fn(|k| b[k] - a[k]);
    let w: [f64; 3] = std::array::from_fn(|k| c[k] - a[k]);
    let n = [
        u[1] * w[2] - u[2] * w[1],
        u[2] * w[0] - u[0] * w[2],
        u[0] * w[1] - u[1] * w[0],
    ];
    0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
}

/// A table row of an extreme: what, (triangle, value), unit.
type Extreme = (&'static str, Option<(usize, f64)>, &'static str);

fn stress_section(s: &mut String, model: &Model, results: &Results) {
    let el = &results.elements;
    let arg = |f: &dyn Fn(usize) -> f64, max: bool| {
        (0..el.len()).fold(None, |best: Option<(usize, f64)>, i| {
            let v = f(i);
            match best {
                Some((_, b)) if (max && v <= b) || (!max && v >= b) => best,
                _ => Some((i, v)),
            }
        })
    };
    let strain = |i: usize| membrane_contact::mech::results::vtk::principal_strain(el[i].strain)[0];
    let rows: [Extreme; 4] = [
        (
            "largest major principal stress σ1",
            arg(&|i| el[i].principal[0], true),
            "Pa",
        ),
        (
            "smallest minor principal stress σ2",
            arg(&|i| el[i].principal[1], false),
            "Pa",
        ),
        (
            "largest von Mises stress",
            arg(&|i| el[i].von_mises, true),
            "Pa",
        ),
        ("largest major principal strain", arg(&strain, true), ""),
    ];
    let _ = writeln!(
        s,
        "## Stresses (last step)\n\n| quantity | value | triangle |\n|---|---:|---:|"
    );
    for (what, best, unit) in rows {
        if let Some((i, v)) = best {
            let _ = writeln!(s, "| {what} | {} {unit} | {i} |", num(v));
        }
    }
    let mut count = [0usize; 3];
    let mut area = [0.0; 3];
    let mut compressed = 0.0;
    for (t, e) in model.triangles.iter().zip(el) {
        let a = reference_area(model, t);
        let k = match e.state {
            WrinklingState::Taut => 0,
            WrinklingState::Wrinkled => 1,
            WrinklingState::Slack => 2,
        };
        count[k] += 1;
        area[k] += a;
        if e.principal[1] < 0.0 {
            compressed += a;
        }
    }
    let _ = writeln!(
        s,
        "\n### Wrinkled and slack film (last step)\n\n| state | triangles | reference area (m²) |\n|---|---:|---:|\n\
         | taut | {} | {} |\n| wrinkled | {} | {} |\n| slack | {} | {} |\n| σ2 < 0 (compressed) | | {} |\n",
        count[0],
        num(area[0]),
        count[1],
        num(area[1]),
        count[2],
        num(area[2]),
        num(compressed)
    );
}

fn slip_section(s: &mut String, model: &Model, results: &Results) {
    let _ = writeln!(s, "## Slips along the supports (last step)\n");
    if model.gaps.is_empty() && model.curved_supports.is_empty() {
        let _ = writeln!(s, "No gaps or curved supports.\n");
        return;
    }
    if !model.gaps.is_empty() {
        let _ = writeln!(
            s,
            "### Gaps\n\n| gap | film node | slip x (mm) | slip y (mm) | N (N) | \\|T\\| (N) | status |\n\
             |---|---:|---:|---:|---:|---:|---|"
        );
        for (g, r) in model.gaps.iter().zip(&results.gaps) {
            let mm = [r.slip_x, r.slip_y].map(|v| num(v * 1e3));
            let forces = [r.normal_force, r.friction_force].map(num);
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:?} |",
                g.name,
                g.film_node,
                [mm.join(" | "), forces.join(" | ")].join(" | "),
                r.status
            );
        }
        s.push('\n');
    }
    let mut contacts = results.surface_contacts.iter();
    for support in &model.curved_supports {
        let _ = writeln!(
            s,
            "### Curved support `{}`\n\nSlip: arc length slid while in contact; travel: along the support since the start.\n\n\
             | node | slip (mm) | travel (mm) | across (mm) | N (N) | \\|T\\| (N) | status |\n\
             |---:|---:|---:|---:|---:|---:|---|",
            support.name
        );
        for (&v, c) in support.nodes.iter().zip(contacts.by_ref()) {
            let mm = [c.slip, c.travel, c.slip_across].map(|v| num(v * 1e3));
            let forces = [c.normal_force, c.friction_force].map(num);
            let _ = writeln!(
                s,
                "| {v} | {} | {:?} |",
                [mm.join(" | "), forces.join(" | ")].join(" | "),
                c.status
            );
        }
        s.push('\n');
    }
}

#[cfg(test)]
mod tests {
    use super::{model_section, num};
    use membrane_contact::mech::Model;

    #[test]
    fn model_section_states_a_temperature_other_than_23_celsius_with_its_factors() {
        let mut model: Model = serde_json::from_str(
            r#"{"name": "M", "nodes": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "triangles": [[0, 1, 2]],
                "material": {"youngs_modulus": 1e9, "poisson_ratio": 0.4, "thickness": 1e-4}}"#,
        )
        .unwrap();
        let section = |model: &Model| {
            let mut s = String::new();
            model_section(&mut s, model);
            s
        };
        assert!(!section(&model).contains("temperature"));
        model.material.temperature = 0.0;
        assert!(
            section(&model).contains(
                "| temperature | 0 °C: E × 1.1300, yield and flow stresses × 1.2770 (given at 23 °C) |"
            ),
            "{}",
            section(&model)
        );
    }

    #[test]
    fn numbers_keep_six_significant_digits() {
        assert_eq!(num(1234.56789), "1234.57");
        assert_eq!(num(-0.0123456789), "-0.0123457");
        assert_eq!(num(2.5e-7), "2.50000e-7");
        assert_eq!(num(0.0), "0");
        assert_eq!(num(12.0), "12.0000");
    }
}
