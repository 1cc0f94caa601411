//! `fmu-pack`: packs the FMI 2.0 (or, with `--fmi-version 3`, 3.0) Co-Simulation FMU.
//!
//! ```text
//! fmu-pack                       → target/fmu/ParallelArch.fmu (the paper's specimen, 300 mm)
//! fmu-pack path/to/model.json    → target/fmu/<model name>.fmu
//! fmu-pack model.json --out DIR  → DIR/<model name>.fmu
//! fmu-pack model.json -o FILE    → FILE (any name ending in .fmu)
//! fmu-pack --platforms linux64,win64,aarch64-linux   → one FMU with three binaries
//! fmu-pack --fmi-version 3       → target/fmu/ParallelArch_fmi3.fmu (FMI 3.0)
//! ```
//!
//! The archive holds
//! * `modelDescription.xml`, rendered from `modelDescription.xml.in` and the variable table of
//!   the model (`membrane_contact::fmi2::description`);
//! * `binaries/linux64/<modelIdentifier>.so`, a copy of the crate's cdylib (the newer of
//!   `target/release/libmembrane_contact.so` and `target/release/deps/…`: `cargo run --bin
//!   fmu-pack` refreshes only the latter; an `fmu-pack` installed from the Python wheel in
//!   `PREFIX/bin` ships `PREFIX/lib/membrane-contact/libmembrane_contact.so`);
//! * with `--platforms`, the cross-built libraries as well, each in its platform folder (see
//!   [`PLATFORMS`]): `binaries/win64/<modelIdentifier>.dll` from cargo's
//!   `target/x86_64-pc-windows-gnu/release/membrane_contact.dll`,
//!   `binaries/aarch64-linux/<modelIdentifier>.so` from `target/aarch64-unknown-linux-gnu/…`, and
//!   so on (`tests/platforms.sh` builds them). The modelDescription and its GUID are the same for
//!   every set of platforms;
//! * `resources/parallel_arch.json` or `resources/model.json`, from which `fmi2Instantiate`
//!   rebuilds the model, the variable table and the GUID;
//! * `documentation/index.html`.
//!
//! With `--fmi-version 3` the description is the FMI 3.0 one rendered from the same variable
//! table (`membrane_contact::fmi3::description`, its instantiation token the 2.0 GUID), the
//! archive has `terminalsAndIcons/terminalsAndIcons.xml` (a terminal per boundary group,
//! `membrane_contact::fmi3::terminals`), the binaries go to FMI 3.0's `<arch>-<os>` folders
//! (`x86_64-linux`, …), and the default file name
//! is `<modelIdentifier>_fmi3.fmu`, so that it never replaces the FMI 2.0 FMU. The library is
//! the same: it exports both interfaces.
//!
//! A model file that does not validate is refused before anything is written; one that looks
//! wrong (`mech::summary::model_warnings`: E in MPa, …) is packed with the warnings on stderr.
//! The FMU goes to `-o FILE`, else into `--out DIR`, else into `target/fmu` when this program
//! runs from cargo's target directory, else (an installed `fmu-pack`) the current directory.
//!
//! **The built-in specimen FMU is not replaced by a user model** (issue 17): a model file whose
//! name is `ParallelArch` (what `membrane-contact export-specimen` prints) would land on
//! `target/fmu/ParallelArch.fmu`, the specimen FMU with the `archHeight` parameter that the
//! examples and the tests use. A user model is refused when its FMU would go to that path
//! (however given: default, `--out target/fmu` or `-o`), or onto any existing file that holds
//! the specimen (`resources/parallel_arch.json`), with a message proposing `-o FILE`, `--out
//! DIR` or another `name`; `--force` replaces it anyway.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::SystemTime;

use membrane_contact::fmi2::description::{Description, describe, documentation_html};
use membrane_contact::fmi2::resources::{SPECIMEN_FILE, Source};
use membrane_contact::mech::Model;
use membrane_contact::specimens::ParallelArch;
use membrane_contact::specimens::parallel_arch::MODEL_NAME;
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

const USAGE: &str = "\
usage: fmu-pack [MODEL.json] [--out DIR | -o FILE] [--force] [--platforms LIST]
                [--library [PLATFORM=]PATH]... [--fmi-version 2|3]

Packs an FMI 2.0 (or 3.0) Co-Simulation FMU. Without MODEL.json it packs the paper's parallel-arch
specimen (ParallelArch.fmu); with it, an FMU of that model, named after the model's `name`.

options:
  --out DIR        where to write <modelIdentifier>.fmu (default: target/fmu when run from
                   cargo's target directory, else the current directory)
  -o, --output FILE
                   the FMU file to write, any name ending in .fmu (instead of --out)
  --force          let a user model replace the built-in specimen FMU (target/fmu/ParallelArch.fmu,
                   or any file holding the specimen): refused without it
  --platforms LIST the binaries to ship, comma-separated FMI platform folders (default
                   linux64): linux64 (x86_64 Linux), win64 (x86_64 Windows), aarch64-linux
                   (Linux on ARM: FMI 2.0 has no name for it; FMI 3.0's and fmpy's tuple),
                   darwin64 (x86_64 macOS), aarch64-darwin (macOS on ARM). A platform other
                   than linux64 takes cargo's cross build of its target beside this program
                   (target/<target triple>/release/), e.g. `cargo build --release --lib
                   --target x86_64-pc-windows-gnu` for win64
  --library [PLATFORM=]PATH
                   the shared library to ship for PLATFORM (default linux64), instead of the
                   one found: for linux64 the newest libmembrane_contact.so next to this
                   program, in target/release or target/release/deps (for an fmu-pack installed
                   with pip, PREFIX/lib/membrane-contact/); repeatable
  --fmi-version 2|3
                   the FMI version of the FMU (default 2); a 3.0 FMU is named
                   <modelIdentifier>_fmi3.fmu by default, its binaries are in FMI 3.0's folders
                   (x86_64-linux, x86_64-windows, aarch64-linux, x86_64-darwin, aarch64-darwin)
  -h, --help       this text";

const LIBRARY: &str = "libmembrane_contact.so";

/// A platform an FMU can carry a binary for.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Platform {
    /// The folder under `binaries/` (FMI 2.0 §2.5 names linux64, win64 and darwin64; for ARM
    /// FMI 3.0's `<arch>-<os>`, which fmpy 0.3.32 reports as `fmpy.platform_tuple`).
    folder: &'static str,
    /// Rust's target triple, whose cross build is in `target/<triple>/release/`.
    triple: &'static str,
    /// The library's file name as cargo writes it.
    cargo_file: &'static str,
    /// The extension of `<modelIdentifier>.<ext>` in the FMU.
    extension: &'static str,
    /// The folder under `binaries/` in an FMI 3.0 FMU (`<arch>-<os>`, FMI 3.0 §2.5.1.1).
    fmi3_folder: &'static str,
}

/// Every platform `--platforms` knows, the host's (linux64) first.
const PLATFORMS: [Platform; 5] = [
    Platform {
        folder: "linux64",
        triple: "x86_64-unknown-linux-gnu",
        cargo_file: LIBRARY,
        extension: "so",
        fmi3_folder: "x86_64-linux",
    },
    Platform {
        folder: "win64",
        triple: "x86_64-pc-windows-gnu",
        cargo_file: "membrane_contact.dll",
        extension: "dll",
        fmi3_folder: "x86_64-windows",
    },
    Platform {
        folder: "aarch64-linux",
        triple: "aarch64-unknown-linux-gnu",
        cargo_file: LIBRARY,
        extension: "so",
        fmi3_folder: "aarch64-linux",
    },
    Platform {
        folder: "darwin64",
        triple: "x86_64-apple-darwin",
        cargo_file: "libmembrane_contact.dylib",
        extension: "dylib",
        fmi3_folder: "x86_64-darwin",
    },
    Platform {
        folder: "aarch64-darwin",
        triple: "aarch64-apple-darwin",
        cargo_file: "libmembrane_contact.dylib",
        extension: "dylib",
        fmi3_folder: "aarch64-darwin",
    },
];

fn platform(folder: &str) -> Result<Platform, String> {
    PLATFORMS
        .into_iter()
        .find(|p| p.folder == folder)
        .ok_or_else(|| {
            let known: Vec<&str> = PLATFORMS.iter().map(|p| p.folder).collect();
            format!("unknown platform '{folder}' (known: {})", known.join(", "))
        })
}

struct Options {
    model: Option<PathBuf>,
    out: Option<PathBuf>,
    file: Option<PathBuf>,
    force: bool,
    /// The platforms to ship, in the order given (default: linux64).
    platforms: Vec<Platform>,
    /// Libraries given with `--library`, by platform.
    libraries: Vec<(Platform, PathBuf)>,
    /// 2 or 3 (`--fmi-version`).
    fmi_version: u8,
}

fn parse(args: &[String]) -> Result<Options, String> {
    let mut o = Options {
        model: None,
        out: None,
        file: None,
        force: false,
        platforms: vec![PLATFORMS[0]],
        libraries: Vec::new(),
        fmi_version: 2,
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
            "-o" | "--output" => o.file = Some(value(a)?),
            "--force" => o.force = true,
            "--fmi-version" => {
                o.fmi_version = match value("--fmi-version")?.to_str() {
                    Some("2") | Some("2.0") => 2,
                    Some("3") | Some("3.0") => 3,
                    v => return Err(format!("--fmi-version {v:?}: 2 or 3")),
                }
            }
            "--platforms" => {
                let list = value("--platforms")?;
                let list = list.to_string_lossy();
                o.platforms.clear();
                for folder in list.split(',').map(str::trim).filter(|f| !f.is_empty()) {
                    let p = platform(folder)?;
                    if !o.platforms.contains(&p) {
                        o.platforms.push(p);
                    }
                }
                if o.platforms.is_empty() {
                    return Err("--platforms needs at least one platform".into());
                }
            }
            "--library" => {
                let given = value("--library")?;
                let text = given.to_string_lossy();
                let (p, path) = match text.split_once('=') {
                    Some((folder, path)) if PLATFORMS.iter().any(|p| p.folder == folder) => {
                        (platform(folder)?, PathBuf::from(path))
                    }
                    _ => (PLATFORMS[0], given.clone()),
                };
                o.libraries.retain(|(q, _)| *q != p);
                o.libraries.push((p, path));
            }
            s if s.starts_with('-') => return Err(format!("unknown option {s}")),
            s if o.model.is_none() => o.model = Some(PathBuf::from(s)),
            s => {
                return Err(format!(
                    "unexpected argument '{s}' (one model file at most)"
                ));
            }
        }
    }
    if o.out.is_some() && o.file.is_some() {
        return Err("give either --out DIR or -o FILE, not both".into());
    }
    if let Some((p, _)) = o.libraries.iter().find(|(p, _)| !o.platforms.contains(p)) {
        return Err(format!(
            "--library for {}, which --platforms does not name",
            p.folder
        ));
    }
    if let Some(file) = &o.file
        && file.extension().is_none_or(|e| e != "fmu")
    {
        return Err(format!(
            "-o {}: an FMU file name ends in .fmu (FMI 2.0 §2.3)",
            file.display()
        ));
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

/// The cross-built library of `platform` beside this program (`dir`, cargo's `target/release`):
/// `target/<triple>/release/<cargo file>`.
fn find_cross_library(dir: &Path, platform: Platform) -> Result<PathBuf, String> {
    let path = dir
        .join("..")
        .join(platform.triple)
        .join("release")
        .join(platform.cargo_file);
    if path.is_file() {
        Ok(path)
    } else {
        Err(format!(
            "no {} for {}: run `cargo build --release --lib --target {}` first (tests/platforms.sh \
             does), or pass --library {}=PATH",
            path.display(),
            platform.folder,
            platform.triple,
            platform.folder
        ))
    }
}

/// The default output directory: `target/fmu` when this program runs from cargo's target
/// directory (`target/release`, whose parent cargo marks with `CACHEDIR.TAG`), else the current
/// directory (an installed `fmu-pack`, whose own directory is no place for FMUs).
/// `target/fmu` when this program runs from cargo's target directory (`dir`, the program's
/// folder, inside a directory holding `CACHEDIR.TAG`); `None` for an installed `fmu-pack`.
fn cargo_target_fmu_dir(dir: &Path) -> Option<PathBuf> {
    dir.parent()
        .filter(|target| target.join("CACHEDIR.TAG").is_file())
        .map(|target| target.join("fmu"))
}

/// Writes the FMU: `libraries` holds each platform's library, in the order they are stored.
fn write_fmu(
    path: &Path,
    d: &Description,
    source: &Source,
    libraries: &[(Platform, Vec<u8>)],
    fmi_version: u8,
) -> Result<(), String> {
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
    let xml = match fmi_version {
        3 => membrane_contact::fmi3::description::model_description(d),
        _ => d.xml.clone(),
    };
    let binaries = libraries.iter().map(|(p, bytes)| {
        let folder = if fmi_version == 3 {
            p.fmi3_folder
        } else {
            p.folder
        };
        (
            format!("binaries/{folder}/{}.{}", d.model_identifier, p.extension),
            bytes.as_slice(),
            binary,
        )
    });
    let terminals = match fmi_version {
        3 => membrane_contact::fmi3::terminals::terminals_and_icons(d),
        _ => None,
    };
    let terminals = terminals.as_ref().map(|t| {
        let name = "terminalsAndIcons/terminalsAndIcons.xml".to_string();
        (name, t.as_bytes(), text)
    });
    let entries: Vec<(String, &[u8], SimpleFileOptions)> =
        std::iter::once(("modelDescription.xml".into(), xml.as_bytes(), text))
            .chain(binaries)
            .chain(terminals)
            .chain([
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
            ])
            .collect();
    for (name, bytes, options) in entries {
        zip.start_file(name.as_str(), options).map_err(|e| io(&e))?;
        zip.write_all(bytes).map_err(|e| io(&e))?;
    }
    zip.finish().map_err(|e| io(&e))?;
    std::fs::rename(&tmp, path).map_err(|e| io(&e))
}

/// Refuses to write the FMU of the user model `name` to `path` when that is where the built-in
/// specimen FMU goes (`specimen`: `target/fmu/ParallelArch.fmu`) or a file holding the specimen.
fn refuse_to_replace_the_specimen(
    path: &Path,
    specimen: Option<&Path>,
    name: &str,
) -> Result<(), String> {
    // Directories compared resolved (`--out target/fmu`, `-o ./target/fmu/…`); a file name as is.
    let resolved = |p: &Path| -> Option<PathBuf> {
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(std::fs::canonicalize(dir).ok()?.join(p.file_name()?))
    };
    let reserved = specimen.is_some_and(|s| resolved(s).is_some() && resolved(s) == resolved(path));
    let holds_specimen = path.is_file() && holds_the_specimen(path);
    if !(reserved || holds_specimen) {
        return Ok(());
    }
    let what = if holds_specimen {
        "that file holds"
    } else {
        "that path is reserved for"
    };
    Err(format!(
        "{}: refused to write the model '{name}' there: {what} the built-in specimen FMU \
         (ParallelArch with its archHeight parameter), which the examples and tests use. Write \
         yours elsewhere with -o FILE (e.g. -o {name}_model.fmu) or --out DIR, or give the model \
         another \"name\"; --force replaces the specimen FMU",
        path.display()
    ))
}

/// Whether the FMU at `path` was packed from the built-in specimen (`resources/parallel_arch.json`).
fn holds_the_specimen(path: &Path) -> bool {
    let entry = format!("resources/{SPECIMEN_FILE}");
    std::fs::File::open(path)
        .ok()
        .and_then(|f| zip::ZipArchive::new(f).ok())
        .is_some_and(|zip| zip.index_for_name(&entry).is_some())
}

fn run(o: &Options) -> Result<(), String> {
    let (source, description) = source(o)?;
    // What looks wrong in a model that validates (E in MPa, flipped pressure triangles, …): the
    // CLI's and the FMU's check, printed as the CLI prints it; the FMU is still packed.
    if let Source::Model(model) = &source {
        for w in membrane_contact::mech::results::warnings::model_warnings(model) {
            eprintln!("warning: {w}");
        }
    }
    let dir = program_dir()?;
    let mut libraries = Vec::new();
    let mut shipped = Vec::new();
    for &p in &o.platforms {
        let given = o
            .libraries
            .iter()
            .find(|(q, _)| *q == p)
            .map(|(_, l)| l.clone());
        let library_path = match given {
            Some(l) => l,
            None if p == PLATFORMS[0] => find_library(&dir)?,
            None => find_cross_library(&dir, p)?,
        };
        let bytes =
            std::fs::read(&library_path).map_err(|e| format!("{}: {e}", library_path.display()))?;
        shipped.push(match o.platforms.len() {
            1 => library_path.display().to_string(),
            _ => format!("{} {}", p.folder, library_path.display()),
        });
        libraries.push((p, bytes));
    }
    let cargo_fmu = cargo_target_fmu_dir(&dir);
    let suffix = if o.fmi_version == 3 { "_fmi3" } else { "" };
    let file_name = format!("{}{suffix}.fmu", description.model_identifier);
    let path = match (&o.file, &o.out) {
        (Some(file), _) => file.clone(),
        (None, Some(d)) => d.join(file_name),
        (None, None) => cargo_fmu
            .clone()
            .unwrap_or_else(|| PathBuf::from("."))
            .join(file_name),
    };
    let out_dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    if let Source::Model(model) = &source
        && !o.force
    {
        let specimen = cargo_fmu.map(|d| d.join(format!("{MODEL_NAME}.fmu")));
        refuse_to_replace_the_specimen(&path, specimen.as_deref(), &model.name)?;
    }
    write_fmu(&path, &description, &source, &libraries, o.fmi_version)?;
    let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    let (version, arrays) = match o.fmi_version {
        3 => {
            let arrays = membrane_contact::fmi3::arrays::Arrays::of(&description);
            (" FMI 3.0,", arrays.fields().count())
        }
        _ => ("", 0),
    };
    println!(
        "{}:{version} {} variables, GUID {}, {:.1} MB (library {})",
        path.display(),
        description.variables.len() + arrays,
        description.guid,
        size as f64 / 1e6,
        shipped.join("; ")
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

#[cfg(test)]
mod tests {
    use super::*;

    fn options(args: &[&str]) -> Result<Options, String> {
        parse(&args.iter().map(|a| a.to_string()).collect::<Vec<_>>())
    }

    #[test]
    fn every_platform_has_its_fmi3_folder_arch_then_os() {
        let folders: Vec<(&str, &str)> = PLATFORMS
            .iter()
            .map(|p| (p.folder, p.fmi3_folder))
            .collect();
        assert_eq!(
            folders,
            [
                ("linux64", "x86_64-linux"),
                ("win64", "x86_64-windows"),
                ("aarch64-linux", "aarch64-linux"),
                ("darwin64", "x86_64-darwin"),
                ("aarch64-darwin", "aarch64-darwin"),
            ]
        );
        for p in PLATFORMS {
            let (arch, os) = p.fmi3_folder.split_once('-').unwrap();
            assert!(
                p.triple.starts_with(arch) && p.triple.contains(os),
                "{}",
                p.triple
            );
        }
    }

    #[test]
    fn fmi_version_defaults_to_2_and_takes_only_2_or_3() {
        assert_eq!(options(&[]).unwrap().fmi_version, 2);
        assert_eq!(options(&["--fmi-version", "3"]).unwrap().fmi_version, 3);
        assert_eq!(options(&["--fmi-version", "2.0"]).unwrap().fmi_version, 2);
        for bad in ["1", "3.1", "x"] {
            let e = options(&["--fmi-version", bad]).err().unwrap();
            assert!(e.contains("2 or 3"), "{e}");
        }
    }

    #[test]
    fn platforms_default_to_linux64_and_keep_their_order() {
        let folders = |o: Options| o.platforms.iter().map(|p| p.folder).collect::<Vec<_>>();
        assert_eq!(folders(options(&[]).unwrap()), ["linux64"]);
        assert_eq!(
            folders(options(&["--platforms", "win64, aarch64-linux,win64"]).unwrap()),
            ["win64", "aarch64-linux"]
        );
        let e = options(&["--platforms", "win32"]).err().unwrap();
        assert!(
            e.contains("unknown platform 'win32'") && e.contains("darwin64"),
            "{e}"
        );
        assert!(options(&["--platforms", ","]).is_err());
    }

    #[test]
    fn a_library_names_its_platform() {
        let o = options(&[
            "--platforms",
            "linux64,win64",
            "--library",
            "win64=x.dll",
            "--library",
            "a.so",
        ])
        .unwrap();
        let given: Vec<_> = o
            .libraries
            .iter()
            .map(|(p, l)| (p.folder, l.to_str().unwrap()))
            .collect();
        assert_eq!(given, [("win64", "x.dll"), ("linux64", "a.so")]);
        let e = options(&["--library", "win64=x.dll"]).err().unwrap();
        assert!(e.contains("--platforms does not name"), "{e}");
        // a path holding '=' whose head is no platform is linux64's
        let o = options(&["--library", "dir=1/lib.so"]).unwrap();
        assert_eq!(o.libraries[0].1, PathBuf::from("dir=1/lib.so"));
    }
}
