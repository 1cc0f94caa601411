//! `membrane-contact`: runs a parallel-arch specimen or a model file through the core solver,
//! stepping the forced displacement to its target, and prints the slip at every gap beside the
//! paper's Table 1, the equivalent-stress range and the Newton statistics.

use std::io::{IsTerminal, Write};
use std::process::ExitCode;

use membrane_contact::mech::element::state_counts;
use membrane_contact::mech::model::ElementSelection;
use membrane_contact::mech::specimen::{OBSERVED_GAPS, table1};
use membrane_contact::mech::vtk;
use membrane_contact::mech::{
    Analysis, FrictionLaw, IterationMatrix, LoadLevels, Model, ParallelArch, Results,
    SolverSettings,
};

/// `println!` for the results on standard output, through [`print_line`]: a reader that closes
/// the pipe early (`… | head`) ends the program quietly instead of a panic.
macro_rules! out {
    ($($arg:tt)*) => { print_line(format_args!($($arg)*)) };
}

/// Writes one line to standard output. A closed pipe ends the program with status 0 and no
/// message (the reader wanted no more, as with `head`); another write error ends it with
/// status 1 and the error on stderr.
fn print_line(args: std::fmt::Arguments<'_>) {
    let mut stdout = std::io::stdout().lock();
    let written = stdout
        .write_fmt(args)
        .and_then(|()| stdout.write_all(b"\n"));
    match written {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(0),
        Err(e) => {
            eprintln!("error: standard output: {e}");
            std::process::exit(1)
        }
    }
}

const USAGE: &str = "\
usage: membrane-contact specimen [--height MM] [options]
       membrane-contact model FILE.json [options]
       membrane-contact export-specimen [--height MM] [--refine N] [--friction-law L]   (prints the model JSON)

Runs the analysis: every boundary group is moved to its target displacement, and every load
(pressures, nodal forces, self-weight) raised from zero to its model-file value, in --steps steps.

options:
  --height MM        arch height of the specimen in mm (200, 300, 400; default 300)
  --refine N         mesh refinement factor of the specimen (default 1: 200 triangles)
  --mu X             friction coefficient of every gap (default: the model's, 0.2 for specimens)
  --friction-law L   isotropic (Coulomb cone) or sliding-direction (the paper's §2.2: slides
                     along the gap's local x only) for every gap (default: the model's,
                     isotropic for specimens)
  --steps N          load steps to the target (default 20)
  --matrix M         consistent (default) or ju-rowlands (the paper's; converges linearly:
                     give it --max-iterations 3000)
  --max-iterations N Newton iterations per increment before it is halved (default 100)
  --increments N     largest increment = 1/N of a step (default 1; the FMU's
                     solver.incrementsPerStep); increments halve on failure and grow back
  --max-cutbacks N   halvings of an increment before a step fails (default 12)
  --displacement-tolerance X, --residual-tolerance X
                     relative Newton tolerances (default 1e-5 each; docs/mechanics.md)
  --no-line-search   plain Newton steps: about half the iterations when each step starts near
                     its answer (a prestressed film under a gradually raised pressure), but no
                     safeguard for a first step from a slack flat film or gaps opening/closing
  --csv FILE         write the gap results of every step as CSV
  --vtk DIR          write every step as VTK: DIR/<model>_film_NNNN.vtu (film) and
                     DIR/<model>_gaps_NNNN.vtu (gap lines), and a .pvd of each for ParaView
  --vtk-format F     binary (default: raw appended data, about half the size) or ascii
  --quiet            no progress indicator
  -h, --help         this text";

struct Options {
    command: String,
    file: Option<String>,
    height_mm: f64,
    refine: usize,
    mu: Option<f64>,
    friction_law: Option<FrictionLaw>,
    steps: usize,
    matrix: IterationMatrix,
    max_iterations: Option<usize>,
    max_cutbacks: Option<usize>,
    displacement_tolerance: Option<f64>,
    residual_tolerance: Option<f64>,
    increments: usize,
    line_search: bool,
    csv: Option<String>,
    vtk: Option<String>,
    vtk_format: vtk::Encoding,
    quiet: bool,
}

fn parse(args: &[String]) -> Result<Options, String> {
    let mut o = Options {
        command: String::new(),
        file: None,
        height_mm: 300.0,
        refine: 1,
        mu: None,
        friction_law: None,
        steps: 20,
        matrix: IterationMatrix::Consistent,
        max_iterations: None,
        max_cutbacks: None,
        displacement_tolerance: None,
        residual_tolerance: None,
        increments: 1,
        line_search: true,
        csv: None,
        vtk: None,
        vtk_format: vtk::Encoding::default(),
        quiet: false,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .cloned()
                .ok_or_else(|| format!("{name} needs a value"))
        };
        let number = |name: &str, v: String| {
            v.parse::<f64>()
                .map_err(|_| format!("{name}: '{v}' is not a number"))
        };
        match a.as_str() {
            "-h" | "--help" => return Err(String::new()),
            "--height" => o.height_mm = number("--height", value("--height")?)?,
            "--refine" => {
                o.refine = value("--refine")?
                    .parse()
                    .map_err(|_| "--refine needs a positive integer".to_string())?
            }
            "--mu" => o.mu = Some(number("--mu", value("--mu")?)?),
            "--friction-law" => {
                let law = value("--friction-law")?;
                o.friction_law = Some(law.parse().map_err(|e| format!("--friction-law: {e}"))?);
            }
            "--steps" => {
                o.steps = value("--steps")?
                    .parse()
                    .map_err(|_| "--steps needs a positive integer".to_string())?;
                if o.steps == 0 {
                    return Err("--steps must be at least 1".into());
                }
            }
            "--matrix" => {
                o.matrix = match value("--matrix")?.as_str() {
                    "consistent" => IterationMatrix::Consistent,
                    "ju-rowlands" | "jr" => IterationMatrix::JuRowlands,
                    other => {
                        return Err(format!(
                            "--matrix: unknown '{other}' (consistent or ju-rowlands)"
                        ));
                    }
                }
            }
            "--max-iterations" => {
                let n = value("--max-iterations")?
                    .parse()
                    .map_err(|_| "--max-iterations needs a positive integer".to_string())?;
                o.max_iterations = Some(n);
            }
            "--max-cutbacks" => {
                let n = value("--max-cutbacks")?
                    .parse()
                    .map_err(|_| "--max-cutbacks needs a non-negative integer".to_string())?;
                o.max_cutbacks = Some(n);
            }
            "--increments" => {
                o.increments = value("--increments")?
                    .parse()
                    .ok()
                    .filter(|&n| n >= 1)
                    .ok_or("--increments needs a positive integer")?;
            }
            "--displacement-tolerance" => {
                let v = value("--displacement-tolerance")?;
                o.displacement_tolerance = Some(number("--displacement-tolerance", v)?);
            }
            "--residual-tolerance" => {
                let v = value("--residual-tolerance")?;
                o.residual_tolerance = Some(number("--residual-tolerance", v)?);
            }
            "--no-line-search" => o.line_search = false,
            "--csv" => o.csv = Some(value("--csv")?),
            "--vtk" => o.vtk = Some(value("--vtk")?),
            "--vtk-format" => {
                o.vtk_format = value("--vtk-format")?
                    .parse()
                    .map_err(|e| format!("--vtk-format: {e}"))?
            }
            "--quiet" => o.quiet = true,
            s if s.starts_with('-') => return Err(format!("unknown option {s}")),
            s if o.command.is_empty() => o.command = s.to_string(),
            s if o.command == "model" && o.file.is_none() => o.file = Some(s.to_string()),
            s => return Err(format!("unexpected argument '{s}'")),
        }
    }
    Ok(o)
}

fn specimen(o: &Options) -> Result<ParallelArch, String> {
    let spec = ParallelArch {
        refinement: o.refine,
        friction_law: o.friction_law.unwrap_or_default(),
        ..ParallelArch::with_height(o.height_mm / 1000.0)
    };
    spec.check()?;
    Ok(spec)
}

fn run(o: &Options) -> Result<(), String> {
    let mut model = match o.command.as_str() {
        "specimen" => specimen(o)?.model()?,
        "export-specimen" => {
            out!("{}", specimen(o)?.model()?.to_json());
            return Ok(());
        }
        "model" => {
            let file = o.file.as_deref().ok_or("model: give the model file")?;
            let text = std::fs::read_to_string(file).map_err(|e| format!("{file}: {e}"))?;
            Model::from_json(&text).map_err(|e| format!("{file}: {e}"))?
        }
        "" => return Err(String::new()),
        other => return Err(format!("unknown command '{other}'")),
    };
    if let Some(law) = o.friction_law {
        model.set_friction_law(law);
    }
    let defaults = SolverSettings::default();
    let settings = SolverSettings {
        iteration_matrix: o.matrix,
        max_iterations: o.max_iterations.unwrap_or(defaults.max_iterations),
        max_cutbacks: o.max_cutbacks.unwrap_or(defaults.max_cutbacks),
        displacement_tolerance: o
            .displacement_tolerance
            .unwrap_or(defaults.displacement_tolerance),
        residual_tolerance: o.residual_tolerance.unwrap_or(defaults.residual_tolerance),
        line_search: o.line_search,
        ..defaults
    };
    for w in membrane_contact::mech::summary::model_warnings(&model) {
        eprintln!("warning: {w}");
    }
    let mut analysis = Analysis::new(model, settings).map_err(|e| e.to_string())?;
    if let Some(mu) = o.mu {
        analysis.set_friction(mu)?;
    }
    let targets: Vec<[f64; 3]> = analysis.model().groups.iter().map(|g| g.target).collect();
    let angles: Vec<f64> = analysis
        .model()
        .groups
        .iter()
        .map(|g| g.hinge.as_ref().map_or(0.0, |h| h.target_angle))
        .collect();
    let loads = LoadLevels::of_model(analysis.model());
    let mut csv = match &o.csv {
        Some(path) => {
            let mut f = std::fs::File::create(path).map_err(|e| format!("{path}: {e}"))?;
            writeln!(
                f,
                "step,fraction,gap,slip_x_mm,slip_y_mm,normal_force_N,friction_force_N,status"
            )
            .map_err(|e| e.to_string())?;
            Some((f, path.clone()))
        }
        None => None,
    };
    let (mut vtk_steps, mut vtk_written) = (Vec::new(), VtkWritten::default());
    if let Some(dir) = &o.vtk {
        std::fs::create_dir_all(dir).map_err(|e| format!("{dir}: {e}"))?;
        // State 0000: the undeformed, prestressed film (as the FMU writes at initialization).
        vtk_steps.push((0.0, 0));
        let results = analysis.results();
        write_vtk(
            dir,
            &analysis,
            &results,
            &vtk_steps,
            o.vtk_format,
            &mut vtk_written,
        )?;
    }
    let progress = !o.quiet && std::io::stderr().is_terminal();
    let started = std::time::Instant::now();
    let (mut iterations, mut cutbacks, mut enlarged, mut increments) = (Vec::new(), 0, 0, 0);
    for step in 1..=o.steps {
        let fraction = step as f64 / o.steps as f64;
        let target: Vec<[f64; 3]> = targets.iter().map(|t| t.map(|v| v * fraction)).collect();
        let angle: Vec<f64> = angles.iter().map(|a| a * fraction).collect();
        let report = analysis
            .step_to_motion(&target, &angle, &loads.scaled(fraction), o.increments)
            .map_err(|e| format!("step {step}/{}: {e}", o.steps))?;
        cutbacks += report.cutbacks;
        enlarged += report.enlarged;
        increments += report.iterations.len();
        iterations.push(report.total_iterations());
        let results = (o.csv.is_some() || o.vtk.is_some()).then(|| analysis.results());
        if let (Some(dir), Some(results)) = (&o.vtk, &results) {
            vtk_steps.push((fraction, step));
            write_vtk(
                dir,
                &analysis,
                results,
                &vtk_steps,
                o.vtk_format,
                &mut vtk_written,
            )?;
        }
        if progress {
            eprint!("\rstep {step}/{} ({:.0}%)", o.steps, 100.0 * fraction);
        }
        if let (Some((f, path)), Some(results)) = (csv.as_mut(), &results) {
            for (g, r) in analysis.model().gaps.iter().zip(&results.gaps) {
                writeln!(
                    f,
                    "{step},{fraction},{},{:.6},{:.6},{:.6},{:.6},{:?}",
                    g.name,
                    r.slip_x * 1e3,
                    r.slip_y * 1e3,
                    r.normal_force,
                    r.friction_force,
                    r.status
                )
                .map_err(|e| format!("{path}: {e}"))?;
            }
        }
    }
    if progress {
        eprintln!();
    }
    let elapsed = started.elapsed();
    let results = analysis.results();
    membrane_contact::mech::check_results(analysis.model(), &results, None)
        .map_err(|e| format!("the results are not finite ({e}): refused"))?;
    report(o, &analysis, &results);
    for w in membrane_contact::mech::summary::result_warnings(analysis.model(), &results) {
        eprintln!("warning: {w}");
    }
    let total: usize = iterations.iter().sum();
    out!(
        "\nNewton: {} steps, {increments} increments, {cutbacks} cut-backs, {enlarged} enlarged, \
         {total} iterations ({:.1} per increment), iterations per step {:?}; {:.1} ms",
        o.steps,
        total as f64 / increments.max(1) as f64,
        iterations,
        elapsed.as_secs_f64() * 1e3
    );
    if o.vtk.is_some() {
        out!(
            "VTK ({}): {} .vtu files, {:.2} MB, {:.1} ms to encode and write",
            o.vtk_format.name(),
            vtk_written.files,
            vtk_written.bytes as f64 / 1e6,
            vtk_written.seconds * 1e3
        );
    }
    Ok(())
}

/// What the VTK output of a run wrote: `.vtu` files, their bytes, and the time spent encoding
/// and writing them (`.pvd` files included).
#[derive(Default)]
struct VtkWritten {
    files: usize,
    bytes: usize,
    seconds: f64,
}

/// Writes the last state of `steps` (`(fraction, step)` pairs) as the film and gaps `.vtu` files
/// in `dir` and rewrites both `.pvd` collections.
fn write_vtk(
    dir: &str,
    analysis: &Analysis,
    results: &Results,
    steps: &[(f64, usize)],
    encoding: vtk::Encoding,
    written: &mut VtkWritten,
) -> Result<(), String> {
    let started = std::time::Instant::now();
    let (model, dir) = (analysis.model(), std::path::Path::new(dir));
    let step = steps.last().map_or(0, |&(_, k)| k);
    let u = &analysis.state().displacement;
    for &block in vtk::Block::of(model) {
        let file = dir.join(vtk::state_file_name(&model.name, block, step));
        let bytes = vtk::grid(block, model, u, results, encoding);
        std::fs::write(&file, &bytes).map_err(|e| format!("{}: {e}", file.display()))?;
        written.files += 1;
        written.bytes += bytes.len();
        let entries: Vec<(f64, String)> = steps
            .iter()
            .map(|&(t, k)| (t, vtk::state_file_name(&model.name, block, k)))
            .collect();
        let pvd = dir.join(vtk::collection_file_name(&model.name, block));
        std::fs::write(&pvd, vtk::collection(&entries))
            .map_err(|e| format!("{}: {e}", pvd.display()))?;
    }
    written.seconds += started.elapsed().as_secs_f64();
    Ok(())
}

/// Prints the load levels of the converged state (the model file's at the last step).
fn report_loads(analysis: &Analysis) {
    let model = analysis.model();
    let levels = &analysis.state().loads;
    for (set, p) in model.loads.pressures.iter().zip(&levels.pressure) {
        let count = match &set.elements {
            ElementSelection::All(_) => model.triangles.len(),
            ElementSelection::List(list) => list.len(),
        };
        out!(
            "load: pressure set {} at {:.6} Pa on {count} triangles",
            set.name,
            p
        );
    }
    for (set, f) in model.loads.forces.iter().zip(&levels.force) {
        out!(
            "load: force set {} at ({:.6}, {:.6}, {:.6}) N on each of {} nodes",
            set.name,
            f[0],
            f[1],
            f[2],
            set.nodes.len()
        );
    }
    let mass = analysis.loads().mass();
    if mass > 0.0 {
        let g = levels.gravity;
        out!(
            "load: self-weight {mass:.6} kg at gravity ({:.4}, {:.4}, {:.4}) m/s² = ({:.6}, {:.6}, {:.6}) N",
            g[0],
            g[1],
            g[2],
            mass * g[0],
            mass * g[1],
            mass * g[2]
        );
    }
}

fn report(o: &Options, analysis: &Analysis, results: &Results) {
    let model = analysis.model();
    out!(
        "{}: {} nodes, {} triangles, {} gaps",
        model.name,
        model.nodes.len(),
        model.triangles.len(),
        model.gaps.len()
    );
    report_loads(analysis);
    if !model.gaps.is_empty() {
        out!(
            "\n{:<8} {:>11} {:>11} {:>10} {:>10}  status",
            "gap",
            "slip x mm",
            "slip y mm",
            "N (N)",
            "|T| (N)"
        );
    }
    for (g, r) in model.gaps.iter().zip(&results.gaps) {
        out!(
            "{:<8} {:>11.3} {:>11.3} {:>10.3} {:>10.3}  {:?}",
            g.name,
            r.slip_x * 1e3,
            r.slip_y * 1e3,
            r.normal_force,
            r.friction_force,
            r.status
        );
    }
    for (i, (g, r)) in model.groups.iter().zip(&results.reactions).enumerate() {
        out!(
            "reaction of group {}: ({:.3}, {:.3}, {:.3}) N",
            g.name,
            r[0],
            r[1],
            r[2]
        );
        if g.hinge.is_some() {
            out!(
                "moment of group {} about its hinge: {:.4} N·m at {:.6} rad",
                g.name,
                results.moments[i],
                analysis.state().angles[i]
            );
        }
    }
    for (name, r) in model.support_sets().iter().zip(&results.support_reactions) {
        out!(
            "reaction of support set {name}: ({:.3}, {:.3}, {:.3}) N",
            r[0],
            r[1],
            r[2]
        );
    }
    for (c, r) in model.cables.iter().zip(&results.cables) {
        out!(
            "cable {}: largest axial force {:.3} N, {} slack segments",
            c.name,
            r.max_force,
            r.slack_segments
        );
    }
    let t = results.total_reaction;
    out!(
        "total reaction (supports, symmetry planes, groups): ({:.3}, {:.3}, {:.3}) N",
        t[0],
        t[1],
        t[2]
    );
    let (lo, hi) = results.von_mises_range();
    out!(
        "equivalent (von Mises) stress: {:.3} … {:.3} MPa",
        lo / 1e6,
        hi / 1e6
    );
    for (p, u) in model.outputs.points.iter().zip(&results.points) {
        out!(
            "output point {} (node {}): displacement ({:.6}, {:.6}, {:.6}) m",
            p.name,
            p.node,
            u[0],
            u[1],
            u[2]
        );
    }
    for (set, s) in model.outputs.element_sets.iter().zip(&results.sets) {
        out!(
            "element set {}: principal stress {:.3} … {:.3} MPa, von Mises ≤ {:.3} MPa, \
             principal strain ≤ {:.6}, compressed area {:.6} m²",
            set.name,
            s.min_principal_stress / 1e6,
            s.max_principal_stress / 1e6,
            s.max_equivalent_stress / 1e6,
            s.max_strain,
            s.compressed_area
        );
    }
    if !model.material.wrinkling.is_none() {
        let [taut, wrinkled, slack] = state_counts(&results.elements);
        println!("tension-field film: {taut} taut, {wrinkled} wrinkled, {slack} slack elements");
    }
    if o.command == "specimen" {
        let measured = table1()
            .into_iter()
            .find(|m| (m.arch_height_mm - o.height_mm).abs() < 1e-9);
        out!("\nobserved points (paper §4.4: points 2–5 = G2, G4, G6, G8):");
        out!(
            "{:<6} {:<5} {:>14} {:>14} {:>10}",
            "point",
            "gap",
            "analysis mm",
            "Table 1 mm",
            "diff mm"
        );
        for (p, name) in OBSERVED_GAPS.iter().enumerate() {
            let Some(i) = model.gap_index(name) else {
                continue;
            };
            let slip = results.gaps[i].slip_x * 1e3;
            match &measured {
                Some(m) => out!(
                    "{:<6} {:<5} {:>14.2} {:>14.1} {:>10.2}",
                    p + 1,
                    name,
                    slip,
                    m.points[p],
                    slip - m.points[p]
                ),
                None => out!(
                    "{:<6} {:<5} {:>14.2} {:>14} {:>10}",
                    p + 1,
                    name,
                    slip,
                    "-",
                    "-"
                ),
            }
        }
        if measured.is_none() {
            out!("(Table 1 has only the 200, 300 and 400 mm specimens)");
        }
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match parse(&args).and_then(|o| run(&o)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) if message.is_empty() => {
            out!("{USAGE}");
            if args.iter().any(|a| a == "-h" || a == "--help") {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(2)
            }
        }
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
