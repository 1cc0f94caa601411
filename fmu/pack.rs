//! `fmu-pack`: packs the FMI 2.0 Co-Simulation FMU.
//!
//! ```text
//! fmu-pack                       → target/fmu/ParallelArch.fmu (the paper's specimen, 300 mm)
//! fmu-pack path/to/model.json    → target/fmu/<model name>.fmu
//! ```
//!
//! The archive holds
//! * `modelDescription.xml`, rendered from `modelDescription.xml.in` and the variable table of
//!   the model (`membrane_contact::fmi2::description`);
//! * `binaries/linux64/<modelIdentifier>.so`, a copy of the crate's cdylib (the newer of
//!   `target/release/libmembrane_contact.so` and `target/release/deps/…`: `cargo run --bin
//!   fmu-pack` refreshes only the latter; an `fmu-pack` installed from the Python wheel in
//!   `PREFIX/bin` ships `PREFIX/lib/membrane-contact/libmembrane_contact.so`);
//! * `resources/parallel_arch.json` or `resources/model.json`, from which `fmi2Instantiate`
//!   rebuilds the model, the variable table and the GUID;
//! * `documentation/index.html`.
//!
//! A model file that does not validate is refused before anything is written; one that looks
//! wrong (`mech::summary::model_warnings`: E in MPa, …) is packed with the warnings on stderr.
//! The FMU goes to `--out DIR`, else to `target/fmu` when this program runs from cargo's target
//! directory, else (an installed `fmu-pack`) to the current directory.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::SystemTime;

use membrane_contact::fmi2::description::{Description, describe, documentation_html};
use membrane_contact::fmi2::resources::Source;
use membrane_contact::mech::{Model, ParallelArch};
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

const USAGE: &str = "\
usage: fmu-pack [MODEL.json] [--out DIR] [--library PATH]

Packs an FMI 2.0 Co-Simulation FMU. Without MODEL.json it packs the paper's parallel-arch
specimen (ParallelArch.fmu); with it, an FMU of that model, named after the model's `name`.

options:
  --out DIR        where to write <modelIdentifier>.fmu (default: target/fmu when run from
                   cargo's target directory, else the current directory)
  --library PATH   the shared library to ship (default: the newest libmembrane_contact.so
                   next to this program, in target/release or target/release/deps; for an
                   fmu-pack installed with pip, PREFIX/lib/membrane-contact/)
  -h, --help       this text";

const LIBRARY: &str = "libmembrane_contact.so";

struct Options {
    model: Option<PathBuf>,
    out: Option<PathBuf>,
    library: Option<PathBuf>,
}

fn parse(args: &[String]) -> Result<Options, String> {
    let mut o = Options {
        model: None,
        out: None,
        library: None,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .map(PathBuf::from)
                .ok_or_else(|| format!("{name} needs a value"))
        };
        match a.as_str() {
            "-h" | "--help" => return Err(String::new()),
            "--out" => o.out = Some(value("--out")?),
            "--library" => o.library = Some(value("--library")?),
            s if s.starts_with('-') => return Err(format!("unknown option {s}")),
            s if o.model.is_none() => o.model = Some(PathBuf::from(s)),
            s => {
                return Err(format!(
                    "unexpected argument '{s}' (one model file at most)"
                ));
            }
        }
    }
    Ok(o)
}

/// The source as the FMU will read it back from its resources (so that the XML written here
/// and the one `fmi2Instantiate` renders come from identical input), and its description.
/// Errors name the model file.
fn source(o: &Options) -> Result<(Source, Description), String> {
    let given = match &o.model {
        None => Source::ParallelArch(ParallelArch::default()),
        Some(path) => {
            let text =
                std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            Source::Model(Model::from_json(&text).map_err(|e| format!("{}: {e}", path.display()))?)
        }
    };
    let in_file = |e: String| match &o.model {
        Some(path) => format!("{}: {e}", path.display()),
        None => e,
    };
    let (name, text) = given.resource_file();
    let stored = Source::from_resource(name, &text).map_err(in_file)?;
    if stored != given {
        return Err(in_file(
            "the model does not survive its JSON round trip unchanged".into(),
        ));
    }
    let description = describe(&stored).map_err(in_file)?;
    Ok((stored, description))
}

/// Directory of this program (target/release).
fn program_dir() -> Result<PathBuf, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot locate fmu-pack itself: {e}"))?;
    Ok(exe
        .parent()
        .ok_or("fmu-pack has no parent directory")?
        .to_path_buf())
}

/// Where the wheel installs the library, relative to the directory of its programs
/// (`PREFIX/bin` → `PREFIX/lib/membrane-contact`; python/pyproject.toml puts it there).
const INSTALLED_LIBRARY_DIR: &str = "../lib/membrane-contact";

/// The newest `libmembrane_contact.so` next to this program (cargo's `target/release` or its
/// `deps/`), else the one installed beside it by the Python wheel.
fn find_library(dir: &Path) -> Result<PathBuf, String> {
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let installed = dir.join(INSTALLED_LIBRARY_DIR).join(LIBRARY);
    [dir.join(LIBRARY), dir.join("deps").join(LIBRARY)]
        .into_iter()
        .filter_map(|p| modified(&p).map(|t| (t, p)))
        .max_by_key(|(t, _): &(SystemTime, PathBuf)| *t)
        .map(|(_, p)| p)
        .or_else(|| installed.is_file().then_some(installed))
        .ok_or_else(|| {
            format!(
                "no {LIBRARY} in {dir}, {dir}/deps or {dir}/{INSTALLED_LIBRARY_DIR}: run `cargo build \
                 --release` first, reinstall the wheel, or pass --library",
                dir = dir.display()
            )
        })
}

/// The default output directory: `target/fmu` when this program runs from cargo's target
/// directory (`target/release`, whose parent cargo marks with `CACHEDIR.TAG`), else the current
/// directory (an installed `fmu-pack`, whose own directory is no place for FMUs).
fn default_out_dir(dir: &Path) -> PathBuf {
    match dir.parent() {
        Some(target) if target.join("CACHEDIR.TAG").is_file() => target.join("fmu"),
        _ => PathBuf::from("."),
    }
}

fn write_fmu(path: &Path, d: &Description, source: &Source, library: &[u8]) -> Result<(), String> {
    let io = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let tmp = path.with_extension("fmu.partial");
    let file = std::fs::File::create(&tmp).map_err(|e| io(&e))?;
    let mut zip = ZipWriter::new(file);
    let text = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Deflated)
        .unix_permissions(0o644);
    let binary = text.unix_permissions(0o755);
    let (resource_name, resource_text) = source.resource_file();
    let documentation = documentation_html(d);
    let entries: [(String, &[u8], SimpleFileOptions); 4] = [
        ("modelDescription.xml".into(), d.xml.as_bytes(), text),
        (
            format!("binaries/linux64/{}.so", d.model_identifier),
            library,
            binary,
        ),
        (
            format!("resources/{resource_name}"),
            resource_text.as_bytes(),
            text,
        ),
        (
            "documentation/index.html".into(),
            documentation.as_bytes(),
            text,
        ),
    ];
    for (name, bytes, options) in entries {
        zip.start_file(name.as_str(), options).map_err(|e| io(&e))?;
        zip.write_all(bytes).map_err(|e| io(&e))?;
    }
    zip.finish().map_err(|e| io(&e))?;
    std::fs::rename(&tmp, path).map_err(|e| io(&e))
}

fn run(o: &Options) -> Result<(), String> {
    let (source, description) = source(o)?;
    // What looks wrong in a model that validates (E in MPa, flipped pressure triangles, …): the
    // CLI's and the FMU's check, printed as the CLI prints it; the FMU is still packed.
    if let Source::Model(model) = &source {
        for w in membrane_contact::mech::summary::model_warnings(model) {
            eprintln!("warning: {w}");
        }
    }
    let dir = program_dir()?;
    let library_path = match &o.library {
        Some(p) => p.clone(),
        None => find_library(&dir)?,
    };
    let library =
        std::fs::read(&library_path).map_err(|e| format!("{}: {e}", library_path.display()))?;
    let out_dir = match &o.out {
        Some(d) => d.clone(),
        None => default_out_dir(&dir),
    };
    std::fs::create_dir_all(&out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let path = out_dir.join(format!("{}.fmu", description.model_identifier));
    write_fmu(&path, &description, &source, &library)?;
    let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    println!(
        "{}: {} variables, GUID {}, {:.1} MB (library {})",
        path.display(),
        description.variables.len(),
        description.guid,
        size as f64 / 1e6,
        library_path.display()
    );
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match parse(&args).and_then(|o| run(&o)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) if message.is_empty() => {
            println!("{USAGE}");
            ExitCode::SUCCESS
        }
        Err(message) => {
            eprintln!("fmu-pack: {message}");
            ExitCode::FAILURE
        }
    }
}
