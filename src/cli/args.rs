//! The command line (clap): commands, their options, and the checks clap can make on them
//! (numbers, ranges, names). What a value means is checked where it is used (the solver
//! settings by `SolverSettings::validate`, the model by `Model::validate`).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use membrane_contact::mech::patterning::contact_stiffness::ContactStiffness;
use membrane_contact::mech::patterning::element_compensation::{SETTLING_CYCLES, SETTLING_RATIO};
use membrane_contact::mech::results::vtk::Encoding;
use membrane_contact::mech::solve::DEFAULT_INCREMENTS_PER_STEP;
use membrane_contact::mech::{FrictionLaw, IterationMatrix};
use membrane_contact::specimens::parallel_arch::SpecimenContact;

/// Geometrically nonlinear ETFE membrane analysis with friction gap elements (Bui & Kawabata's
/// method): runs a parallel-arch specimen or a model file, stepping every boundary group to its
/// target and every load to its value, and prints slips, reactions, stresses and Newton
/// statistics.
#[derive(Debug, Parser)]
#[command(name = "membrane-contact", version, max_term_width = 100)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Runs a parallel-arch specimen of the paper (§4) and compares it with Table 1.
    Specimen {
        #[command(flatten)]
        specimen: SpecimenArgs,
        #[command(flatten)]
        run: RunArgs,
    },
    /// Runs a model file (docs/model-format.md).
    Model {
        /// The model file (JSON).
        file: PathBuf,
        #[command(flatten)]
        run: RunArgs,
    },
    /// Imports a mesh (gmsh 2.2/4.1 ASCII or binary, or any format meshio reads) with a mapping
    /// file into a model file, gaps generated along arches (python/README-import.md). Runs the
    /// Python importer `membrane_contact.mesh` (meshio): the checkout's for the checkout's build,
    /// the interpreter's (the wheel's) when installed.
    Import {
        /// The mesh file (.msh, or another format meshio reads).
        mesh: PathBuf,
        /// The mapping file (JSON): physical groups → element sets, supports, groups, gaps, …
        mapping: PathBuf,
        /// The model file to write (default: standard output).
        #[arg(short, long, value_name = "FILE")]
        output: Option<PathBuf>,
        /// The Python interpreter with the package and meshio (default: $MEMBRANE_CONTACT_PYTHON,
        /// else the python beside this program (a venv it was pip-installed into), else the
        /// checkout's .venv/bin/python, else python3).
        #[arg(long, value_name = "PATH")]
        python: Option<PathBuf>,
    },
    /// Checks a model file without running it: validates it, prints what looks wrong
    /// (warnings on standard error) and how each pressure set faces (standard output).
    Check {
        /// The model file (JSON).
        file: PathBuf,
    },
    /// Finds the shape in which the film carries its prestress (the model's, or --prestress)
    /// with the boundary held where the model puts it (updated reference strategy,
    /// docs/mechanics.md "Form finding and patterning"); writes the model with the found
    /// geometry and the target prestress.
    FormFind {
        /// The model file (JSON).
        file: PathBuf,
        /// The model file to write (default: standard output).
        #[arg(short, long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// Target prestress `SX,SY[,TXY]` in MPa in each element's frame (e1 along the model's
        /// `frame_axis`, or --warp, projected; global X without either); default: the model's
        /// `material.prestress`.
        #[arg(long, value_name = "SX,SY[,TXY]", value_parser = parse_prestress, allow_negative_numbers = true)]
        prestress: Option<[f64; 3]>,
        /// The warp direction `AX,AY,AZ`: each element's e1 is it projected on the element, so
        /// `--prestress SW,SF` is an orthotropic target (warp SW, fill SF); written to the found
        /// model as its `frame_axis`.
        #[arg(long, value_name = "AX,AY,AZ", value_parser = parse_direction, allow_negative_numbers = true)]
        warp: Option<[f64; 3]>,
        /// Start from the force density shape (Schek 1974) instead of the model's geometry.
        #[arg(long)]
        force_density_start: bool,
        /// Largest out-of-balance force accepted, relative to t·|σ|·(mean edge length).
        #[arg(long, value_name = "TOL", default_value_t = 1e-4)]
        tolerance: f64,
        /// Most reference updates.
        #[arg(long, value_name = "N", default_value_t = 5000)]
        max_steps: usize,
        /// Find the shape against the model's curved supports (tubes, arches; frictionless):
        /// the updated reference strategy with the homotopy λ > 0, each step solved by the
        /// analysis (docs/mechanics.md "Form finding and patterning").
        #[arg(long)]
        on_supports: bool,
        /// With --on-supports: the share λ of the film's elasticity kept in each step.
        #[arg(long, value_name = "LAMBDA", default_value_t = 0.01)]
        homotopy: f64,
        /// With --on-supports: the largest |σ − σ*|/|σ*| of a step's equilibrium accepted.
        #[arg(long, value_name = "TOL", default_value_t = 1e-3)]
        stress_tolerance: f64,
        /// With --on-supports: how the curved supports' penalties are read: `auto` (per metre of
        /// contact line where a support's nodes lie in a row along it, else per node),
        /// `per-length` or `per-node` (docs/mechanics.md "Contact stiffness in the design loop").
        #[arg(long, value_name = "BASIS", default_value = "auto", value_parser = parse_contact_stiffness)]
        contact_stiffness: ContactStiffness,
    },
    /// Cuts a (form found) model's film into strips along seams, flattens each with the least
    /// distortion, compensates it and prints each strip's size and distortion
    /// (docs/mechanics.md "Form finding and patterning").
    Pattern {
        /// The model file (JSON).
        file: PathBuf,
        /// A seam plane through a point with a normal (m); repeat for more seams.
        #[arg(long, value_name = "PX,PY,PZ,NX,NY,NZ", value_parser = parse_plane, allow_negative_numbers = true)]
        seam_plane: Vec<[f64; 6]>,
        /// A seam along a line of mesh nodes; repeat for more seams.
        #[arg(long, value_name = "N1,N2,…")]
        seam_nodes: Vec<String>,
        /// Geodesic seams from this line of boundary nodes: straightest geodesics (Polthier &
        /// Schmies 1998) perpendicular to a transverse one, --strip-width apart along it; repeat
        /// for more start lines. A line across the film (boundary to boundary) is itself a seam,
        /// with the others on both sides of it. The film is split along the seams (nodes added
        /// where they cross its triangles' edges), so the strips' outlines follow them.
        #[arg(long, value_name = "N1,N2,…", requires = "strip_width")]
        geodesic_from: Vec<String>,
        /// The width (m, along the surface) between the geodesic seams of --geodesic-from: one
        /// for every start line, or one per start line in their order.
        #[arg(
            long,
            value_name = "W",
            requires = "geodesic_from",
            allow_negative_numbers = true
        )]
        strip_width: Vec<f64>,
        /// `prestress` (the strain of the model's prestress, D⁻¹σ, along and across each strip) or
        /// the compensation in percent, `C` or `CX,CY` (along, across).
        #[arg(long, value_name = "prestress|C[,C]", default_value = "prestress")]
        compensation: String,
        /// Write the strips' outlines with their dimensions as SVG (mm).
        #[arg(long, value_name = "FILE")]
        svg: Option<PathBuf>,
        /// Write the strips' outlines as DXF (R12, mm; one layer per strip) for a cutting
        /// plotter or CAD.
        #[arg(long, value_name = "FILE")]
        dxf: Option<PathBuf>,
        /// Compensate by erection: erect the cut with the model's own supports, contacts and
        /// friction (the analysis), correct each strip's compensation by the prestress missed,
        /// at most N erections (0: none); the compensation given is the first.
        #[arg(long, value_name = "N", default_value_t = 0)]
        erect: usize,
        /// With --erect: correct every triangle's reference lengths (its cut metric) by the
        /// prestress it missed, not each strip's two compensations; the tolerance is then the
        /// largest error of the triangles away from the rails, and the triangles friction holds
        /// on a support (whose stress does not follow their cut) are named.
        #[arg(long)]
        by_element: bool,
        /// Stop the erections when the area-mean prestress error is below this (percent; with
        /// --by-element: the largest error away from the rails).
        #[arg(long, value_name = "PERCENT", default_value_t = 1.0)]
        erect_tolerance: f64,
        /// The erection path of a roof: the rails (the model's boundary groups) start UP m above
        /// and IN m inward (horizontally, towards the film) of their places, the film laid on
        /// its supports, and are pulled down and out to them; without it the cut is laid at
        /// its fitted reference and the rails drawn straight to their places. Repeat for a
        /// winding path: the rails go through each waypoint in turn, then to their places
        /// (`--rail-path 0.10,0.03 --rail-path 0,0.03`: down, then out).
        /// A waypoint below or outside the rails' places has negative numbers
        /// (`--rail-path -0.001,-0.0003`).
        #[arg(long, value_name = "UP,IN", value_parser = parse_pair, allow_hyphen_values = true)]
        rail_path: Vec<[f64; 2]>,
        /// Settle the film after the rail path: the rails pass their places by AMPLITUDE m along
        /// the last leg, come back short of them by RATIO times that, and so on, CYCLES
        /// waypoints in all, then end at their places (friction then holds the film at a
        /// nearly even tension instead of the capstan's fall from the rails). AMPLITUDE `auto`
        /// (or `auto` alone: ratio 0.7, 12 waypoints): half the length change the target
        /// prestress asks of the longest strip, reported.
        #[arg(long, value_name = "AMPLITUDE,RATIO,CYCLES", value_parser = parse_settle, requires = "rail_path", allow_hyphen_values = true)]
        settle: Option<(Option<f64>, f64, usize)>,
        /// How the curved supports' penalties are read in the erections: `auto` (per metre of
        /// contact line where a support's nodes lie in a row along it, else per node),
        /// `per-length` or `per-node` (docs/mechanics.md "Contact stiffness in the design loop").
        #[arg(long, value_name = "BASIS", default_value = "auto", value_parser = parse_contact_stiffness)]
        contact_stiffness: ContactStiffness,
        /// Increments of each erection.
        #[arg(long, value_name = "N", default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..))]
        erect_increments: u32,
        /// Write the erection model: the film's compensated reference geometry (fitted to the
        /// cut strips), no prestress, each held node driven back to its place by its own group.
        #[arg(long, value_name = "FILE")]
        erection_model: Option<PathBuf>,
        /// With --erect: write the model of every erection the compensation makes to this
        /// folder (`erection-K.json`, K = 0, 1, …), before it is erected: models a study (or
        /// `membrane-contact model`, or `fmu-pack`) can run on their own.
        #[arg(long, value_name = "DIR")]
        erection_models: Option<PathBuf>,
        /// Write what the strip lines and erection lines say as JSON (for scripts: the Python
        /// package's `membrane_contact.design.pattern` reads it).
        #[arg(long, value_name = "FILE")]
        report: Option<PathBuf>,
    },
    /// Prints a specimen as a model file (JSON) on standard output.
    ExportSpecimen {
        #[command(flatten)]
        specimen: SpecimenArgs,
        /// Also write the specimen's frame path as a staged table (FMU input names, one row per
        /// step) for `--path` or an FMU master.
        #[arg(long, value_name = "FILE")]
        path_out: Option<std::path::PathBuf>,
        /// Steps of the table written by --path-out.
        #[arg(long, value_name = "N", default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..))]
        steps: u32,
        /// Friction law of every gap.
        #[arg(long, value_name = "LAW", value_parser = parse_friction_law)]
        friction_law: Option<FrictionLaw>,
    },
}

/// Which specimen.
#[derive(Debug, Args)]
pub struct SpecimenArgs {
    /// Arch height in mm (Table 1 has 200, 300 and 400).
    #[arg(
        allow_negative_numbers = true,
        long,
        value_name = "MM",
        default_value_t = 300.0
    )]
    pub height: f64,
    /// Mesh refinement factor (1: 200 triangles).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub refine: u32,
    /// Contact between film and arch: gaps (the paper's fixed-frame gap elements) or
    /// curved-support (node-to-surface contact with the arch pipe; slip along the arch).
    #[arg(long, value_name = "MODEL", default_value = "gaps", value_parser = parse_contact)]
    pub contact: SpecimenContact,
    /// Frame target dz as a multiple of the arch height (default -0.5: lowered by H/2).
    #[arg(
        allow_negative_numbers = true,
        long,
        value_name = "X",
        conflicts_with = "wrap"
    )]
    pub target_dz_per_height: Option<f64>,
    /// Wrap the film over the arch from crown to foot instead of lowering the frame: every frame
    /// node follows the wrapped film extended by the strain EPS (0 ..= 0.1), one boundary group
    /// per frame node (the crown-to-foot reconstruction, docs/mechanics.md).
    #[arg(long, value_name = "EPS")]
    pub wrap: Option<f64>,
    /// Give the film ETFE's elasto-plastic behaviour (finite-strain J2 with the documented
    /// data-sheet curve at 23 °C, docs/mechanics.md "Plastic film") instead of the linear film.
    #[arg(long)]
    pub plastic: bool,
}

/// Newton iteration matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Matrix {
    /// The consistent tangent (quadratic convergence).
    Consistent,
    /// The paper's symmetric Ju–Rowlands matrix (converges linearly: give it
    /// --max-iterations 3000).
    #[value(name = "ju-rowlands", alias = "jr")]
    JuRowlands,
}

impl From<Matrix> for IterationMatrix {
    fn from(m: Matrix) -> Self {
        match m {
            Matrix::Consistent => IterationMatrix::Consistent,
            Matrix::JuRowlands => IterationMatrix::JuRowlands,
        }
    }
}

/// How to run an analysis and what to write.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Friction coefficient of every gap (default: the model's; 0.2 for specimens).
    #[arg(allow_negative_numbers = true, long, value_name = "X")]
    pub mu: Option<f64>,
    /// Friction law of every gap: isotropic (Coulomb cone) or sliding-direction (the paper's
    /// §2.2: slides along the gap's local x only). Default: the model's.
    #[arg(long, value_name = "LAW", value_parser = parse_friction_law)]
    pub friction_law: Option<FrictionLaw>,
    /// Load steps from the start to the targets of the model file (default 20).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..), conflicts_with = "path")]
    pub steps: Option<u32>,
    /// A staged load path instead of the linear ramp: a CSV table, one row per step, whose
    /// columns are FMU input names (<group>.dx/dy/dz/angle, <set>.pressure, <set>.Fx/Fy/Fz,
    /// mu, <chamber>.supplyPressure/heating/massFlow, <chamber>.sealed as 0 or 1: the valve
    /// closes as the step starts) and an optional first column time (a massFlow acts over the
    /// step's length); inputs without a column keep their FMU start values.
    #[arg(long, value_name = "TABLE.csv")]
    pub path: Option<PathBuf>,
    /// Iteration matrix.
    #[arg(long, value_enum, default_value_t = Matrix::Consistent)]
    pub matrix: Matrix,
    /// Newton iterations per increment before it is halved (default 100).
    #[arg(long, value_name = "N")]
    pub max_iterations: Option<usize>,
    /// The smallest number of increments a step is cut into: the largest increment is 1/N of a
    /// step (the FMU's solver.incrementsPerStep, with the same default); the controller sizes
    /// the increments below it by their Newton iterations and halves a refused one.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_INCREMENTS_PER_STEP as u32, value_parser = clap::value_parser!(u32).range(1..))]
    pub increments: u32,
    /// Halvings of an increment before a step fails (default 12).
    #[arg(long, value_name = "N")]
    pub max_cutbacks: Option<usize>,
    /// Relative Newton tolerance on the corrections (default 1e-5; docs/mechanics.md).
    #[arg(allow_negative_numbers = true, long, value_name = "X")]
    pub displacement_tolerance: Option<f64>,
    /// Relative Newton tolerance on the residual (default 1e-5).
    #[arg(allow_negative_numbers = true, long, value_name = "X")]
    pub residual_tolerance: Option<f64>,
    /// No viscous stabilization: a step whose smallest increment Newton refuses is refused
    /// (the answer then carries no damping force; docs/mechanics.md "The nonlinear method")
    #[arg(long)]
    pub no_stabilization: bool,
    /// Threads of the element assembly and the LDLᵀ factorization (0 = automatic: the idle
    /// cores, one below 100 000 triangles and 2^24 factor values; results are identical for
    /// every count).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
    /// Write the gap results of every step as CSV.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Write the element results (stresses, strains, wrinkling state) of every step as CSV.
    #[arg(long, value_name = "FILE")]
    pub elements_csv: Option<PathBuf>,
    /// Write the layer contacts' results (gap, normal force, contact pressure, friction, slip
    /// and status of every slave node) of every step as CSV.
    #[arg(long, value_name = "FILE")]
    pub layer_contacts_csv: Option<PathBuf>,
    /// Write each chamber's pressure, volume, temperature, air mass and valve of every step as
    /// CSV.
    #[arg(long, value_name = "FILE")]
    pub chambers_csv: Option<PathBuf>,
    /// Write the reactions per unit length along every boundary group and named support set
    /// of every step as CSV (N/m: each node's reaction over its tributary length, half its film
    /// edges along the line).
    #[arg(long, value_name = "FILE")]
    pub line_reactions: Option<PathBuf>,
    /// Write a run report (Markdown): model, load steps, reactions, reactions per unit length,
    /// extreme stresses, wrinkled areas, slips along the supports, warnings, solver statistics.
    #[arg(long, value_name = "FILE.md")]
    pub report: Option<PathBuf>,
    /// Write every step as VTK: DIR/<model>_film_NNNN.vtu, DIR/<model>_gaps_NNNN.vtu and a
    /// .pvd of each for ParaView (the FMU's numbering: 0000 is the initial state).
    #[arg(long, value_name = "DIR")]
    pub vtk: Option<PathBuf>,
    /// VTK encoding: binary (raw appended data) or ascii.
    #[arg(long, value_name = "F", default_value = "binary", value_parser = parse_encoding)]
    pub vtk_format: Encoding,
    /// No progress line on the terminal.
    #[arg(long)]
    pub quiet: bool,
    /// A line on standard error as each increment ends, on a terminal or not (a log file, a
    /// batch job): the step, the share of it reached, how the increment was solved or why it
    /// was refused, its iterations and residual, the cut-backs so far.
    #[arg(long)]
    pub log_increments: bool,
}

/// `SX,SY[,TXY]` in MPa → Pa.
fn parse_prestress(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>().map_err(|e| format!("{p:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y] => Ok([x * 1e6, y * 1e6, 0.0]),
        [x, y, t] => Ok([x * 1e6, y * 1e6, t * 1e6]),
        _ => Err("two or three numbers: SX,SY[,TXY] (MPa)".into()),
    }
}

/// `N` comma-separated numbers, or `expected` as the error.
fn parse_numbers<const N: usize>(s: &str, expected: &str) -> Result<[f64; N], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>().map_err(|e| format!("{p:?}: {e}")))
        .collect::<Result<_, _>>()?;
    v.try_into().map_err(|_| expected.to_string())
}

/// `AX,AY,AZ` → a direction (its length is not checked here: the model's validation does).
fn parse_direction(s: &str) -> Result<[f64; 3], String> {
    parse_numbers(s, "three numbers: AX,AY,AZ")
}

/// `PX,PY,PZ,NX,NY,NZ` → a plane's point and normal.
fn parse_plane(s: &str) -> Result<[f64; 6], String> {
    parse_numbers(s, "six numbers: PX,PY,PZ,NX,NY,NZ")
}

fn parse_pair(s: &str) -> Result<[f64; 2], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>().map_err(|e| format!("{p:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [a, b] if a.is_finite() && b.is_finite() => Ok([a, b]),
        _ => Err("two finite numbers: UP,IN".to_string()),
    }
}

/// `AMPLITUDE,RATIO,CYCLES` of `--settle`; AMPLITUDE `auto` (None), or `auto` alone.
fn parse_settle(s: &str) -> Result<(Option<f64>, f64, usize), String> {
    let expected =
        "AMPLITUDE,RATIO,CYCLES: a length (m) or auto, a ratio and a whole number; or auto";
    if s.trim() == "auto" {
        return Ok((None, SETTLING_RATIO, SETTLING_CYCLES));
    }
    let (amplitude, rest) = s.split_once(',').unwrap_or((s, ""));
    let amplitude = match amplitude.trim() {
        "auto" => None,
        a => Some(a.parse::<f64>().map_err(|_| format!("{a:?}: {expected}"))?),
    };
    let [r, n] = parse_numbers::<2>(rest, expected)?;
    if n < 0.0 || n.fract() != 0.0 {
        return Err(format!("{n} cycles: {expected}"));
    }
    Ok((amplitude, r, n as usize))
}

/// `--contact-stiffness`: auto, per-length or per-node.
fn parse_contact_stiffness(s: &str) -> Result<ContactStiffness, String> {
    s.parse()
}

fn parse_friction_law(s: &str) -> Result<FrictionLaw, String> {
    s.parse()
}

fn parse_contact(s: &str) -> Result<SpecimenContact, String> {
    s.parse()
}

fn parse_encoding(s: &str) -> Result<Encoding, String> {
    s.parse()
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn command_line_definition_is_consistent() {
        Cli::command().debug_assert();
    }
}
