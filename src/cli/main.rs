//! `membrane-contact`: runs a parallel-arch specimen or a model file through the core solver,
//! stepping the boundary groups and loads to their targets (a linear ramp, or a staged table of
//! FMU inputs, [`path`]), and prints the slip at every gap (beside the paper's Table 1 for a
//! specimen), reactions, stresses and the Newton statistics; options in [`args`].

use std::io::{IsTerminal, Write};
use std::process::ExitCode;

use membrane_contact::mech::elements::temperature;
use membrane_contact::mech::elements::triangle::state_counts;
use membrane_contact::mech::model::ElementSelection;
use membrane_contact::mech::results::summary::mpa;
use membrane_contact::mech::results::vtk;
use membrane_contact::mech::solve::IncrementObserver;
use membrane_contact::mech::{
    Analysis, FrictionLaw, LoadLevels, Model, Results, SettingNames, SolverSettings, StepReport,
};
use membrane_contact::specimens::ParallelArch;
use membrane_contact::specimens::parallel_arch::{FramePath, OBSERVED_GAPS, etfe_plastic, table1};
use nalgebra::Vector3;

mod args;
mod design;
mod path;
mod report;

use args::{Cli, Command, RunArgs, SpecimenArgs};
use clap::Parser;
use membrane_contact::fmi2::variables::{Kind, StepInputs, supplied_air, variables};
use path::StagedPath;

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

/// Where the model comes from, and what the run compares with.
#[allow(clippy::large_enum_variant)] // one per run; the specimen holds a material's inline hardening table
enum Source<'a> {
    /// A parallel-arch specimen of height `height_mm` (compared with Table 1).
    Specimen { spec: ParallelArch, height_mm: f64 },
    /// A model file.
    File(&'a std::path::Path),
}

fn specimen(args: &SpecimenArgs, law: Option<FrictionLaw>) -> Result<ParallelArch, String> {
    let defaults = ParallelArch::default();
    let mut spec = ParallelArch {
        refinement: args.refine as usize,
        friction_law: law.unwrap_or_default(),
        contact: args.contact,
        target_dz_per_height: args
            .target_dz_per_height
            .unwrap_or(defaults.target_dz_per_height),
        frame_path: args
            .wrap
            .map_or(FramePath::Lowered, |extension| FramePath::Wrapped {
                extension,
            }),
        ..ParallelArch::with_height(args.height / 1000.0)
    };
    if args.plastic {
        spec.material = etfe_plastic(spec.material);
    }
    spec.check()?;
    Ok(spec)
}

/// The targets of each step: the staged table's rows, the specimen's frame path, or the model
/// file's targets and loads reached linearly in `--steps` steps.
fn load_path(
    model: &Model,
    spec: Option<&ParallelArch>,
    o: &RunArgs,
) -> Result<StagedPath, String> {
    if let Some(file) = &o.path {
        let source = file.display().to_string();
        let text = std::fs::read_to_string(file).map_err(|e| format!("{source}: {e}"))?;
        return path::read(&text, model, &source);
    }
    let steps = o.steps.unwrap_or(20) as usize;
    let loads = LoadLevels::of_model(model);
    let times = (1..=steps)
        .map(|k| k as f64 / steps as f64)
        .collect::<Vec<_>>();
    let rows = times
        .iter()
        .map(|&f| StepInputs {
            targets: match spec {
                Some(spec) => spec.boundary_targets(model, f),
                None => model
                    .groups
                    .iter()
                    .map(|g| g.target.map(|v| v * f))
                    .collect(),
            },
            angles: model
                .groups
                .iter()
                .map(|g| g.hinge.as_ref().map_or(0.0, |h| h.target_angle * f))
                .collect(),
            loads: loads.scaled(f),
            mu: None,
            sealed: model.chambers.iter().map(|c| c.sealed).collect(),
        })
        .collect::<Vec<_>>();
    let values = vec![vec![]; rows.len()];
    Ok(StagedPath {
        times,
        steps: rows,
        values,
    })
}

/// The options that a failed step's advice names. Each `--path` row is one step, split into
/// `--increments` increments; without `--path`, `--steps` makes each step smaller.
fn setting_names(o: &RunArgs) -> SettingNames {
    SettingNames {
        max_iterations: "--max-iterations",
        finer_increments: if o.path.is_some() {
            "raise --increments"
        } else {
            "raise --steps"
        },
        residual_tolerance: "--residual-tolerance",
        displacement_tolerance: "--displacement-tolerance",
        consistent_tangent: "--matrix consistent",
        isotropic_friction: "--friction-law isotropic (or \"friction_law\": \"isotropic\" on those supports or gaps in the model file)",
    }
}

fn run(source: Source<'_>, o: &RunArgs) -> Result<(), String> {
    let model = load_model(&source, o)?;
    let settings = solver_settings(o);
    if let Some(mu) = o.mu {
        // The FMU's own check of its `mu` input: the CLI accepts exactly what the FMU accepts.
        path::check_input(&model, "mu", mu).map_err(|e| format!("--mu: {e}"))?;
    }
    for w in membrane_contact::mech::results::warnings::model_warnings(&model) {
        eprintln!("warning: {w}");
    }
    let spec = match &source {
        Source::Specimen { spec, .. } => Some(spec),
        Source::File(_) => None,
    };
    let path = load_path(&model, spec, o)?;
    let height_mm = match source {
        Source::Specimen { height_mm, .. } => Some(height_mm),
        Source::File(_) => None,
    };
    let table = variables(&model, Kind::Model);
    let mut analysis = Analysis::new(model, settings).map_err(|e| e.to_string())?;
    if let Some(mu) = o.mu {
        analysis.set_friction(mu)?;
    }
    let mut writers = StepWriters::create(o, &mut analysis)?;
    let mut progress = Progress::new(
        !o.quiet && std::io::stderr().is_terminal(),
        path.steps.len(),
    );
    let logged_step = log_increments(o, &mut analysis, path.steps.len());
    let mut tally = Tally::default();
    let count = path.steps.len();
    // The contact warnings of the last step (said with its number, not again at the end).
    let mut last_contacts = vec![];
    for (k, (inputs, &time)) in path.steps.iter().zip(&path.times).enumerate() {
        let step = k + 1;
        logged_step.store(step, std::sync::atomic::Ordering::Relaxed);
        if let Some(mu) = inputs.mu {
            analysis.set_friction(mu)?;
        }
        // A chamber's valve closes (or opens) as the step starts, as in the FMU.
        let valves = analysis.state().chambers.iter().map(|c| c.sealed);
        if !valves.eq(inputs.sealed.iter().copied()) {
            analysis
                .set_chambers_sealed(&inputs.sealed)
                .map_err(|e| format!("step {step}/{count}: {e}"))?;
        }
        // The path's time: the step's length moves air through the orifices, and feeds the
        // sealed chambers their `<chamber>.massFlow` (the FMU's running total of air supplied).
        let h = time - if k == 0 { 0.0 } else { path.times[k - 1] };
        let air = supplied_air(&analysis, &table, &path.values[k], &inputs.sealed, h)
            .map_err(|e| format!("step {step}/{count}: {e}"))?;
        let loads = LoadLevels {
            time,
            air,
            ..inputs.loads.clone()
        };
        let report = match analysis.step_to_motion(
            &inputs.targets,
            &inputs.angles,
            &loads,
            o.increments as usize,
        ) {
            Ok(report) => report,
            Err(e) => {
                // What was reached stands: the summary of the last converged state, then the error.
                progress.finish();
                let done = if k == 0 { 0.0 } else { path.times[k - 1] };
                out!(
                    "step {step}/{count} failed; the last converged state (step {k}, time {done}):"
                );
                let results = analysis.results();
                report(height_mm, &analysis, &results);
                return Err(format!(
                    "step {step}/{count}: {}",
                    e.message(&setting_names(o))
                ));
            }
        };
        tally.record(step, &report);
        let results = writers.write(o, (step, time), inputs, &report, &mut analysis)?;
        last_contacts = contact_step_warnings(&mut analysis, results.as_ref());
        for w in &last_contacts {
            eprintln!("warning: step {step}: {w}");
        }
        progress.step(step);
    }
    progress.finish();
    let elapsed = progress.started.elapsed();
    let results = analysis.results();
    membrane_contact::mech::check_results(analysis.model(), &results, None)
        .map_err(|e| format!("the results are not finite ({e}): refused"))?;
    report(height_mm, &analysis, &results);
    writers
        .outputs
        .finish(&analysis, &results, elapsed.as_secs_f64())?;
    for w in membrane_contact::mech::results::warnings::result_warnings(analysis.model(), &results)
    {
        if !last_contacts.contains(&w) {
            eprintln!("warning: {w}");
        }
    }
    tally.print(count, elapsed, &analysis);
    if o.vtk.is_some() {
        writers.print_vtk(o);
    }
    Ok(())
}

/// Where the converged steps' results go besides the summary: the CSV files, the line
/// reactions and report, the VTK states.
struct StepWriters {
    csv: CsvFiles,
    outputs: report::Outputs,
    /// The (time, step) of each VTK state written.
    vtk_steps: Vec<(f64, usize)>,
    vtk_written: VtkWritten,
}

impl StepWriters {
    /// Opens the CSV files and the outputs, and with `--vtk` writes state 0000.
    fn create(o: &RunArgs, analysis: &mut Analysis) -> Result<Self, String> {
        let csv = CsvFiles::create(o, analysis.model().material.plasticity.is_some())?;
        let outputs = report::Outputs::create(
            analysis.model(),
            o.line_reactions.as_deref(),
            o.report.as_deref(),
        )?;
        let (vtk_steps, vtk_written) = start_vtk(o, analysis)?;
        Ok(Self {
            csv,
            outputs,
            vtk_steps,
            vtk_written,
        })
    }

    /// Writes a converged step's results (its number and time) where they are wanted;
    /// returns them, or `None` where nothing wants them.
    fn write(
        &mut self,
        o: &RunArgs,
        (step, time): (usize, f64),
        inputs: &StepInputs,
        report: &StepReport,
        analysis: &mut Analysis,
    ) -> Result<Option<Results>, String> {
        let results = (self.csv.any() || o.vtk.is_some() || self.outputs.wants_results())
            .then(|| analysis.results());
        if let (Some(dir), Some(results)) = (&o.vtk, &results) {
            self.vtk_steps.push((time, step));
            write_vtk(
                dir,
                analysis,
                results,
                &self.vtk_steps,
                o.vtk_format,
                &mut self.vtk_written,
            )?;
        }
        if let Some(results) = &results {
            self.csv.write_step(step, time, analysis.model(), results)?;
            self.outputs
                .step(step, time, inputs, report, analysis, results)?;
        }
        Ok(results)
    }

    /// Prints what the VTK files took.
    fn print_vtk(&self, o: &RunArgs) {
        let written = &self.vtk_written;
        out!(
            "VTK ({}): {} .vtu files, {:.2} MB, {:.1} ms to encode and write",
            o.vtk_format.name(),
            written.files,
            written.bytes as f64 / 1e6,
            written.seconds * 1e3
        );
    }
}

/// Reads the run's model (the specimen's, or the file's) and sets `--friction-law` on it.
fn load_model(source: &Source<'_>, o: &RunArgs) -> Result<Model, String> {
    let mut model = match source {
        Source::Specimen { spec, .. } => spec.model()?,
        Source::File(file) => {
            let name = file.display();
            let text = std::fs::read_to_string(file).map_err(|e| format!("{name}: {e}"))?;
            Model::from_json(&text).map_err(|e| format!("{name}: {e}"))?
        }
    };
    if let Some(law) = o.friction_law {
        model.set_friction_law(law);
    }
    Ok(model)
}

/// The solver settings: the defaults, with the options given.
fn solver_settings(o: &RunArgs) -> SolverSettings {
    let defaults = SolverSettings::default();
    SolverSettings {
        iteration_matrix: o.matrix.into(),
        max_iterations: o.max_iterations.unwrap_or(defaults.max_iterations),
        max_cutbacks: o.max_cutbacks.unwrap_or(defaults.max_cutbacks),
        displacement_tolerance: o
            .displacement_tolerance
            .unwrap_or(defaults.displacement_tolerance),
        residual_tolerance: o.residual_tolerance.unwrap_or(defaults.residual_tolerance),
        stabilization: !o.no_stabilization,
        threads: o.threads,
        ..defaults
    }
}

/// With `--vtk`: creates its folder and writes state 0000; returns the steps written so far
/// and what they took.
fn start_vtk(
    o: &RunArgs,
    analysis: &mut Analysis,
) -> Result<(Vec<(f64, usize)>, VtkWritten), String> {
    let (mut vtk_steps, mut vtk_written) = (Vec::new(), VtkWritten::default());
    if let Some(dir) = &o.vtk {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        // State 0000: the undeformed, prestressed film (as the FMU writes at initialization).
        vtk_steps.push((0.0, 0));
        let results = analysis.results();
        write_vtk(
            dir,
            analysis,
            &results,
            &vtk_steps,
            o.vtk_format,
            &mut vtk_written,
        )?;
    }
    Ok((vtk_steps, vtk_written))
}

/// With `--log-increments`: logs each increment on standard error; returns the step number
/// the log's lines belong to (set before each step).
fn log_increments(
    o: &RunArgs,
    analysis: &mut Analysis,
    steps: usize,
) -> std::sync::Arc<std::sync::atomic::AtomicUsize> {
    let logged_step = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    if o.log_increments {
        let step = logged_step.clone();
        let started = std::time::Instant::now();
        analysis.observe_increments(IncrementObserver::new(move |note| {
            let k = step.load(std::sync::atomic::Ordering::Relaxed);
            let t = started.elapsed().as_secs_f64();
            eprintln!("step {k}/{steps} ({t:.1} s): {note}");
        }));
    }
    logged_step
}

/// What the steps took: Newton iterations, increments, cut-backs and viscous stabilization.
#[derive(Default)]
struct Tally {
    /// The Newton iterations of each step.
    iterations: Vec<usize>,
    cutbacks: usize,
    increments: usize,
    /// Increments solved with the viscous stabilization on.
    stabilized: usize,
    /// The step of the largest ratio of the stabilization's work to the strain energy: (step,
    /// ratio, energy, dissipated).
    stabilization: Option<(usize, f64, f64, f64)>,
}

impl Tally {
    /// Adds a converged step's report, warning of its stabilization and dissipation.
    fn record(&mut self, step: usize, report: &StepReport) {
        self.cutbacks += report.cutbacks;
        self.stabilized += report.stabilized;
        for w in [report.stabilization_warning(), report.dissipation_warning()]
            .into_iter()
            .flatten()
        {
            eprintln!("warning: step {step}: {w}");
        }
        if report.stabilized > 0 {
            let ratio = report.dissipation_ratio();
            if self.stabilization.is_none_or(|(_, r, _, _)| ratio > r) {
                self.stabilization = Some((
                    step,
                    ratio,
                    report.stabilization_energy,
                    report.stabilization_dissipated,
                ));
            }
        }
        self.increments += report.iterations.len();
        self.iterations.push(report.total_iterations());
    }

    /// Prints the Newton statistics of the `count` steps, the stabilization's and the linear
    /// solves'.
    fn print(&self, count: usize, elapsed: std::time::Duration, analysis: &Analysis) {
        let (iterations, increments) = (&self.iterations, self.increments);
        let (cutbacks, stabilized) = (self.cutbacks, self.stabilized);
        let total: usize = iterations.iter().sum();
        out!(
            "\nNewton: {count} steps, {increments} increments, {cutbacks} cut-backs, \
             {total} iterations ({:.1} per increment), iterations per step {:?}; {:.1} ms",
            total as f64 / increments.max(1) as f64,
            iterations,
            elapsed.as_secs_f64() * 1e3
        );
        if let Some((step, ratio, energy, dissipated)) = self.stabilization {
            out!(
                "stabilization: {stabilized} increments viscously stabilized; largest work taken \
                 out {dissipated:.3e} J at step {step} ({ratio:.2e} of the strain energy; bound \
                 {}), {energy:.3e} J left in its answer",
                membrane_contact::mech::solve::DISSIPATION_BOUND
            );
        }
        let [lu, ldlt, redone, gmres] = analysis.factorization_counts();
        let pivoted = analysis.solve_profile().lu_pivoted;
        out!(
            "linear solves: {lu} LU ({pivoted} with global pivoting), {ldlt} LDLᵀ, {gmres} GMRES \
             on the symmetric part's LDLᵀ, {redone} of these redone by LU"
        );
    }
}

/// A progress line on the terminal (only there: a pipe or a file gets none): the step, its
/// share and, after the first step, the time left at the pace so far.
struct Progress {
    shown: bool,
    steps: usize,
    started: std::time::Instant,
}

impl Progress {
    fn new(shown: bool, steps: usize) -> Self {
        Self {
            shown,
            steps,
            started: std::time::Instant::now(),
        }
    }

    fn step(&mut self, step: usize) {
        if !self.shown {
            return;
        }
        let elapsed = self.started.elapsed().as_secs_f64();
        let left = elapsed / step as f64 * (self.steps - step) as f64;
        eprint!(
            "\rstep {step}/{} ({:.0}%), {elapsed:.1} s, about {left:.1} s left   ",
            self.steps,
            100.0 * step as f64 / self.steps as f64
        );
    }

    fn finish(&self) {
        if self.shown {
            eprintln!();
        }
    }
}

/// The CSV outputs of a run: gap results and element results of every step.
struct CsvFiles {
    gaps: Option<(std::fs::File, String)>,
    elements: Option<(std::fs::File, String)>,
    layers: Option<(std::fs::File, String)>,
    chambers: Option<(std::fs::File, String)>,
}

impl CsvFiles {
    /// Opens the files; an elasto-plastic film's element rows get its plastic strain and
    /// thickness as two more columns.
    fn create(o: &RunArgs, plastic: bool) -> Result<Self, String> {
        let open = |path: &Option<std::path::PathBuf>, header: &str| -> Result<_, String> {
            let Some(path) = path else {
                return Ok(None);
            };
            let name = path.display().to_string();
            let mut f = std::fs::File::create(path).map_err(|e| format!("{name}: {e}"))?;
            writeln!(f, "{header}").map_err(|e| format!("{name}: {e}"))?;
            Ok(Some((f, name)))
        };
        Ok(Self {
            gaps: open(
                &o.csv,
                "step,fraction,gap,slip_x_mm,slip_y_mm,normal_force_N,friction_force_N,status",
            )?,
            layers: open(
                &o.layer_contacts_csv,
                "step,time,contact,node,triangle,gap_m,normal_force_N,pressure_Pa,\
                 friction_x_N,friction_y_N,friction_z_N,slip_mm,status",
            )?,
            chambers: open(
                &o.chambers_csv,
                "step,time,chamber,pressure_Pa,volume_m3,temperature_K,mass_kg,sealed",
            )?,
            elements: open(
                &o.elements_csv,
                &format!(
                    "step,time,element,node1,node2,node3,state,stress_x_Pa,stress_y_Pa,stress_xy_Pa,\
                     principal_1_Pa,principal_2_Pa,von_mises_Pa,strain_x,strain_y,strain_xy,\
                     principal_strain_1,principal_strain_2{}",
                    if plastic {
                        ",equivalent_plastic_strain,thickness_m"
                    } else {
                        ""
                    }
                ),
            )?,
        })
    }

    fn any(&self) -> bool {
        self.gaps.is_some()
            || self.elements.is_some()
            || self.layers.is_some()
            || self.chambers.is_some()
    }

    fn write_step(
        &mut self,
        step: usize,
        time: f64,
        model: &Model,
        results: &Results,
    ) -> Result<(), String> {
        if let Some((f, name)) = self.gaps.as_mut() {
            for (g, r) in model.gaps.iter().zip(&results.gaps) {
                writeln!(
                    f,
                    "{step},{time},{},{:.6},{:.6},{:.6},{:.6},{:?}",
                    g.name,
                    r.slip_x * 1e3,
                    r.slip_y * 1e3,
                    r.normal_force,
                    r.friction_force,
                    r.status
                )
                .map_err(|e| format!("{name}: {e}"))?;
            }
        }
        if let Some((f, name)) = self.layers.as_mut() {
            for c in &results.layer_contacts {
                let [fx, fy, fz] = c.friction;
                writeln!(
                    f,
                    "{step},{time},{},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:.6},{:?}",
                    c.name,
                    c.node,
                    c.triangle.map_or(String::new(), |t| t.to_string()),
                    c.gap,
                    c.normal_force,
                    c.pressure,
                    fx,
                    fy,
                    fz,
                    c.slip * 1e3,
                    c.status
                )
                .map_err(|e| format!("{name}: {e}"))?;
            }
        }
        if let Some((f, name)) = self.chambers.as_mut() {
            for c in &results.chambers {
                writeln!(
                    f,
                    "{step},{time},{},{:e},{:e},{:e},{:e},{}",
                    c.name,
                    c.pressure,
                    c.volume,
                    c.temperature,
                    c.mass,
                    u8::from(c.sealed)
                )
                .map_err(|e| format!("{name}: {e}"))?;
            }
        }
        if let Some((f, name)) = self.elements.as_mut() {
            for (i, (t, e)) in model.triangles.iter().zip(&results.elements).enumerate() {
                let [e1, e2] = vtk::principal_strain(e.strain);
                write!(
                    f,
                    "{step},{time},{i},{},{},{},{:?},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
                    t[0],
                    t[1],
                    t[2],
                    e.state,
                    e.stress[0],
                    e.stress[1],
                    e.stress[2],
                    e.principal[0],
                    e.principal[1],
                    e.von_mises,
                    e.strain[0],
                    e.strain[1],
                    e.strain[2],
                    e1,
                    e2
                )
                .map_err(|e| format!("{name}: {e}"))?;
                if let Some(p) = e.plastic {
                    write!(f, ",{:e},{:e}", p.equivalent_plastic_strain, p.thickness)
                        .map_err(|e| format!("{name}: {e}"))?;
                }
                writeln!(f).map_err(|e| format!("{name}: {e}"))?;
            }
        }
        Ok(())
    }
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
/// The contact warnings of the state a step reached
/// ([`membrane_contact::mech::results::contact_warnings`]), said after each step as the FMU
/// says them: from `results` when the step gathered them, else gathered here; none without
/// gaps or curved supports.
fn contact_step_warnings(analysis: &mut Analysis, results: Option<&Results>) -> Vec<String> {
    use membrane_contact::mech::results::contact_warnings::contact_warnings;
    let model = analysis.model();
    if model.gaps.is_empty() && model.curved_supports.is_empty() {
        return vec![];
    }
    match results {
        Some(r) => contact_warnings(analysis.model(), r),
        None => {
            let r = analysis.results();
            contact_warnings(analysis.model(), &r)
        }
    }
}

fn write_vtk(
    dir: &std::path::Path,
    analysis: &Analysis,
    results: &Results,
    steps: &[(f64, usize)],
    encoding: vtk::Encoding,
    written: &mut VtkWritten,
) -> Result<(), String> {
    let started = std::time::Instant::now();
    let model = analysis.model();
    let step = steps.last().map_or(0, |&(_, k)| k);
    let u = &analysis.state().displacement;
    for block in vtk::Block::of(model) {
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

/// Prints the film's temperature when it is not the reference (with the factors it applies),
/// then the load levels of the converged state (the model file's at the last step).
fn report_loads(analysis: &Analysis) {
    let model = analysis.model();
    let celsius = model.material.temperature;
    if celsius != temperature::REFERENCE_TEMPERATURE {
        out!(
            "film: at {celsius} °C: E × {:.4}, yield and flow stresses × {:.4} (given at 23 °C)",
            temperature::modulus_factor(celsius),
            temperature::flow_stress_factor(celsius)
        );
    }
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

/// `<name><separator> N nodes, N triangles, N gaps`.
fn size_line(model: &Model, separator: &str) -> String {
    format!(
        "{}{separator} {} nodes, {} triangles, {} gaps",
        model.name,
        model.nodes.len(),
        model.triangles.len(),
        model.gaps.len()
    )
}

/// Prints the results; `height_mm`: the specimen's, whose observed points are compared with
/// Table 1.
fn report(height_mm: Option<f64>, analysis: &Analysis, results: &Results) {
    let model = analysis.model();
    out!("{}", size_line(model, ":"));
    report_loads(analysis);
    report_contacts(model, results);
    report_reactions(analysis, results);
    report_contact_forces(model, results);
    report_stresses(model, results);
    if let Some(height_mm) = height_mm {
        report_observed(height_mm, model, results);
    }
}

/// Prints the gaps' and curved-support contacts' slips and forces, and the layer contacts.
fn report_contacts(model: &Model, results: &Results) {
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
    if !model.curved_supports.is_empty() {
        out!(
            "\n{:<14} {:>11} {:>11} {:>11} {:>10} {:>10}  status   (curved supports: slip = arc length slid in contact, travel = along the support since the start)",
            "contact",
            "slip mm",
            "travel mm",
            "across mm",
            "N (N)",
            "|T| (N)"
        );
    }
    let contacts = model
        .curved_supports
        .iter()
        .flat_map(|s| s.nodes.iter().map(move |v| format!("{}.node{v}", s.name)));
    for (name, c) in contacts.zip(&results.surface_contacts) {
        out!(
            "{name:<14} {:>11.3} {:>11.3} {:>11.3} {:>10.3} {:>10.3}  {:?}",
            c.slip * 1e3,
            c.travel * 1e3,
            c.slip_across * 1e3,
            c.normal_force,
            c.friction_force,
            c.status
        );
    }
    for line in membrane_contact::mech::elements::layer_contact::summary(model, results) {
        out!("{line}");
    }
}

/// Prints the reactions (groups with their hinge moments, support sets), the cables', chambers'
/// and orifices' states and the total reaction.
fn report_reactions(analysis: &Analysis, results: &Results) {
    let model = analysis.model();
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
    for c in &results.chambers {
        out!(
            "chamber {}: pressure {:.3} Pa, volume {:.6} m³ ({})",
            c.name,
            c.pressure,
            c.volume,
            if c.sealed {
                "enclosed air"
            } else {
                "held by its supply"
            }
        );
    }
    for o in &results.orifices {
        out!(
            "orifice {}: mass flow {:.6e} kg/s over the last increment",
            o.name,
            o.mass_flow
        );
    }
    let t = results.total_reaction;
    out!(
        "total reaction (supports, symmetry planes, groups): ({:.3}, {:.3}, {:.3}) N",
        t[0],
        t[1],
        t[2]
    );
}

/// Prints the contact forces on the film and their share of its loads, where it has contacts.
fn report_contact_forces(model: &Model, results: &Results) {
    let t = results.total_reaction;
    if !model.gaps.is_empty() || !results.surface_contacts.is_empty() {
        let (c, all) = (
            results.contact_force(model),
            results.film_support_force(model),
        );
        // The film's supports balance its loads: where those are ~0 the contacts only balance
        // the reactions, and no share is defined.
        let share = if all.norm() > 1e-3 * c.norm().max(Vector3::from(t).norm()) {
            format!(
                "carrying {:.1} % of the film's loads (along their resultant)",
                100.0 * c.dot(&all) / all.norm_squared()
            )
        } else {
            "balancing the reactions (no load on the film)".into()
        };
        out!(
            "contact forces on the film (gaps, curved supports): ({:.3}, {:.3}, {:.3}) N, {share}",
            c.x,
            c.y,
            c.z
        );
    }
}

/// Prints the stresses: the von Mises range, output points, element sets, plasticity, wrinkling.
fn report_stresses(model: &Model, results: &Results) {
    let (lo, hi) = results.von_mises_range();
    out!(
        "equivalent (von Mises) stress: {} … {} MPa",
        mpa(lo),
        mpa(hi)
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
            "element set {}: principal stress {} … {} MPa, von Mises ≤ {} MPa, \
             principal strain ≤ {:.6}, compressed area {:.6} m²",
            set.name,
            mpa(s.min_principal_stress),
            mpa(s.max_principal_stress),
            mpa(s.max_equivalent_stress),
            s.max_strain,
            s.compressed_area
        );
        if model.material.plasticity.is_some() {
            out!(
                "element set {}: equivalent plastic strain ≤ {:.6}",
                set.name,
                s.max_plastic_strain
            );
        }
    }
    if let Some(p) = results.plastic_summary() {
        out!(
            "plastic film: {} yielded elements, equivalent plastic strain ≤ {:.6}, smallest thickness {:.4e} m",
            p.yielded_elements,
            p.max_plastic_strain,
            p.min_thickness
        );
    }
    if !model.material.wrinkling.is_none() {
        let [taut, wrinkled, slack] = state_counts(&results.elements);
        println!("tension-field film: {taut} taut, {wrinkled} wrinkled, {slack} slack elements");
    }
}

/// Prints the specimen's observed points beside Table 1's for its `height_mm`.
fn report_observed(height_mm: f64, model: &Model, results: &Results) {
    let measured = table1()
        .into_iter()
        .find(|m| (m.arch_height_mm - height_mm).abs() < 1e-9);
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
        // G<k> is the k-th film node on the arch: its gap, or its curved-support contact.
        let slip = match model.gap_index(name) {
            Some(i) => results.gaps[i].slip_x,
            None => {
                let k: usize = name[1..].parse().unwrap_or(0);
                match results.surface_contacts.get(k.wrapping_sub(1)) {
                    Some(c) => c.slip,
                    None => continue,
                }
            }
        } * 1e3;
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

/// The `python` in this program's own directory: the environment's interpreter when the program
/// was installed into it from the wheel (`PREFIX/bin/membrane-contact`), which has the package.
fn beside_this_program() -> Option<std::path::PathBuf> {
    let python = std::env::current_exe().ok()?.parent()?.join("python");
    python.is_file().then_some(python)
}

/// True when this program is the checkout's own build (`target/<profile>/`), not a copy installed
/// from the wheel (which may sit in a venv inside the checkout, e.g. `target/wheel-venv/bin`).
fn built_in_checkout(root: &std::path::Path) -> bool {
    std::env::current_exe()
        .ok()
        .and_then(|exe| Some(exe.parent()?.parent()? == root.join("target")))
        .unwrap_or(false)
}

/// Runs the Python mesh importer (`python -m membrane_contact.mesh`): one implementation of
/// the import, on meshio, which reads gmsh 2.2 and 4.1 (the Rust crate mshio reads 4.1 only).
/// The checkout's build takes the package from the checkout's `python/` directory (ahead on
/// PYTHONPATH); the program installed from the wheel takes the interpreter's (the wheel's).
fn import(
    mesh: &std::path::Path,
    mapping: &std::path::Path,
    output: Option<&std::path::Path>,
    python: Option<&std::path::Path>,
) -> Result<(), String> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let python = python
        .map(std::path::PathBuf::from)
        .or_else(|| std::env::var_os("MEMBRANE_CONTACT_PYTHON").map(Into::into))
        .or_else(beside_this_program)
        .or_else(|| {
            let venv = root.join(".venv/bin/python");
            venv.is_file().then_some(venv)
        })
        .unwrap_or_else(|| "python3".into());
    let mut command = std::process::Command::new(&python);
    command
        .args(["-m", "membrane_contact.mesh"])
        .arg(mesh)
        .arg(mapping);
    if let Some(output) = output {
        command.arg("-o").arg(output);
    }
    if built_in_checkout(root) {
        let pythonpath = std::env::var_os("PYTHONPATH").unwrap_or_default();
        let mut paths = vec![root.join("python")];
        paths.extend(std::env::split_paths(&pythonpath));
        command.env(
            "PYTHONPATH",
            std::env::join_paths(paths).map_err(|e| e.to_string())?,
        );
    }
    let status = command.status().map_err(|e| {
        format!(
            "cannot run {} ({e}): give --python, or create the environment with bash fmu/prepare.sh",
            python.display()
        )
    })?;
    if status.success() {
        Ok(())
    } else {
        // The importer printed its error (naming the bad item) on stderr.
        Err(format!("the import failed ({status})"))
    }
}

/// `membrane-contact check FILE`: validates the model, prints its warnings on stderr (as a run
/// does), how each pressure set faces, what each chamber encloses and each layer's thickness on
/// stdout.
fn check(file: &std::path::Path) -> Result<(), String> {
    let name = file.display();
    let text = std::fs::read_to_string(file).map_err(|e| format!("{name}: {e}"))?;
    let model = Model::from_json(&text).map_err(|e| format!("{name}: {e}"))?;
    for w in membrane_contact::mech::results::warnings::model_warnings(&model) {
        eprintln!("warning: {w}");
    }
    out!("{}", size_line(&model, ": valid,"));
    for line in membrane_contact::mech::elements::load::orientation_report(&model) {
        out!("{line}");
    }
    for line in membrane_contact::mech::elements::chamber::chamber_report(&model) {
        out!("{line}");
    }
    for l in &model.layers {
        out!(
            "layer {}: {} triangles, thickness {:.1} µm (the material's: {:.1} µm)",
            l.name,
            model.selected_triangles(&l.elements).len(),
            l.thickness * 1e6,
            model.material.thickness * 1e6
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Specimen {
            specimen: args,
            run: o,
        } => specimen(args, o.friction_law).and_then(|spec| {
            run(
                Source::Specimen {
                    spec,
                    height_mm: args.height,
                },
                o,
            )
        }),
        Command::Model { file, run: o } => run(Source::File(file), o),
        Command::Check { file } => check(file),
        Command::Import {
            mesh,
            mapping,
            output,
            python,
        } => import(mesh, mapping, output.as_deref(), python.as_deref()),
        Command::FormFind {
            file,
            out,
            prestress,
            warp,
            force_density_start,
            tolerance,
            max_steps,
            on_supports,
            homotopy,
            stress_tolerance,
            contact_stiffness,
        } => design::form_find(design::FormFindArgs {
            file,
            out: out.as_ref(),
            prestress: *prestress,
            warp: *warp,
            force_density_start: *force_density_start,
            contact_stiffness: *contact_stiffness,
            on_supports: on_supports.then_some(
                membrane_contact::mech::formfinding::contact::ContactSettings {
                    tolerance: *stress_tolerance,
                    max_steps: *max_steps,
                    homotopy: *homotopy,
                    increments: 1,
                },
            ),
            settings: membrane_contact::mech::formfinding::update_reference::UpdateSettings {
                tolerance: *tolerance,
                max_steps: *max_steps,
            },
        }),
        Command::Pattern {
            file,
            seam_plane,
            seam_nodes,
            geodesic_from,
            strip_width,
            compensation,
            svg,
            dxf,
            erection_model,
            erection_models,
            erect,
            by_element,
            rail_path,
            settle,
            contact_stiffness,
            erect_tolerance,
            erect_increments,
            report,
        } => design::pattern(design::PatternArgs {
            file,
            seam_planes: seam_plane,
            seam_nodes,
            geodesic: (geodesic_from.as_slice(), strip_width.as_slice()),
            compensation,
            svg: svg.as_ref(),
            dxf: dxf.as_ref(),
            erection_model: erection_model.as_ref(),
            erection_models: erection_models.as_ref(),
            erect: (*erect, *erect_tolerance / 100.0, *erect_increments as usize),
            by_element: *by_element,
            rail_path: rail_path.as_slice(),
            settle: *settle,
            contact_stiffness: *contact_stiffness,
            report: report.as_ref(),
        }),
        Command::ExportSpecimen {
            specimen: args,
            path_out,
            steps,
            friction_law,
        } => specimen(args, *friction_law).and_then(|spec| {
            let model = spec.model()?;
            if let Some(file) = path_out {
                let table = path::write(&model, *steps as usize, |t| {
                    spec.boundary_targets(&model, t)
                });
                std::fs::write(file, table).map_err(|e| format!("{}: {e}", file.display()))?;
            }
            out!("{}", model.to_json());
            Ok(())
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
