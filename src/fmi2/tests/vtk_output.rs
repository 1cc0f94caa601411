//! The results files through the exported functions: `results.directory` and
//! `results.vtkFormat`, the `.pvd` collections after a restored state and after Reset, and a
//! failed write.
//!
//! SAFETY of the `unsafe` blocks below: as in the harness (`tests/mod.rs`), each calls an
//! exported function the way an importer does, with an instance from [`Fmu`] (freed only in its
//! `Drop`), and pointers to live locals or NUL-terminated literals holding the announced number
//! of elements; the deliberately bad arguments are NULL pointers, which the functions must
//! reject without dereferencing.

use super::*;

/// The `(timestep, file)` entries of a `.pvd` (the format `vtk::collection` writes).
fn pvd_entries(path: &std::path::Path) -> Vec<(f64, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.starts_with("<?xml") && text.trim_end().ends_with("</VTKFile>"));
    let attribute = |line: &str, name: &str| -> String {
        let start = line.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
        line[start..][..line[start..].find('"').unwrap()].to_string()
    };
    text.lines()
        .filter(|l| l.starts_with("<DataSet "))
        .map(|l| {
            (
                attribute(l, "timestep").parse().unwrap(),
                attribute(l, "file"),
            )
        })
        .collect()
}

/// Checks that `dir` holds the listed `.vtu` files, each a complete VTK file.
fn assert_vtu_files(dir: &std::path::Path, entries: &[(f64, String)]) {
    for (_, file) in entries {
        let bytes = std::fs::read(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        let head = String::from_utf8_lossy(&bytes[..bytes.len().min(300)]).into_owned();
        assert!(head.contains("<UnstructuredGrid"), "{file}");
        assert!(bytes.ends_with(b"</VTKFile>\n"), "{file} is complete");
    }
}

/// The `.pvd` entries of the film and the gaps in `dir`, checked to list the same states.
fn film_and_gap_entries(dir: &std::path::Path) -> Vec<(f64, String)> {
    let film = pvd_entries(&dir.join("ParallelArch_film.pvd"));
    let gaps = pvd_entries(&dir.join("ParallelArch_gaps.pvd"));
    assert_eq!(film.len(), gaps.len());
    for ((t, f), (tg, g)) in film.iter().zip(&gaps) {
        assert_eq!(
            (t, g.as_str()),
            (tg, f.replace("_film_", "_gaps_").as_str())
        );
    }
    assert_vtu_files(dir, &film);
    assert_vtu_files(dir, &gaps);
    film
}

#[test]
fn results_directory_writes_every_step_as_vtk() {
    let (u, log) = (Unpacked::specimen("vtk"), Log::default());
    // Missing (two levels) and with a space: created at initialization.
    let dir = u.dir.parent().unwrap().join("vtk out/run 1");
    let fmu = Fmu::new(&u, &log);
    assert_eq!(fmu.initialized_with_output(&dir), 0, "{:?}", log.take());
    assert_eq!(fmu.string("results.directory"), dir.to_str().unwrap());
    fmu.ramp(0, 3, 10);
    let entries = film_and_gap_entries(&dir);
    let files: Vec<&str> = entries.iter().map(|(_, f)| f.as_str()).collect();
    assert_eq!(
        files,
        [
            "ParallelArch_film_0000.vtu",
            "ParallelArch_film_0001.vtu",
            "ParallelArch_film_0002.vtu",
            "ParallelArch_film_0003.vtu"
        ]
    );
    for (k, (t, _)) in entries.iter().enumerate() {
        assert!((t - k as f64 / 10.0).abs() < 1e-12, "entry {k}: t = {t}");
    }
    assert_eq!(entries[3].0, fmu.real("time"));
    assert!(!dir.join("ParallelArch_film.pvd.tmp").exists());
    // The default encoding is binary (raw appended data).
    let last = std::fs::read(dir.join("ParallelArch_film_0003.vtu")).unwrap();
    assert!(
        last.windows(29)
            .any(|w| w == b"<AppendedData encoding=\"raw\">")
    );
    // The parameter is fixed once initialized.
    assert_eq!(
        fmu.set_string("results.directory", "elsewhere"),
        Status::Error.raw()
    );
    assert!(log.contains(Status::Error, "results.directory is a fixed parameter"));
}

#[test]
fn vtk_format_ascii_writes_text_and_an_unknown_format_is_refused() {
    let (u, log) = (Unpacked::specimen("vtk ascii"), Log::default());
    let dir = u.dir.parent().unwrap().join("vtk ascii");
    let fmu = Fmu::new(&u, &log);
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    assert_eq!(fmu.string("results.vtkFormat"), "binary");
    assert_eq!(
        fmu.set_string("results.vtkFormat", "Binary"),
        Status::Error.raw()
    );
    assert!(log.contains(Status::Error, "unknown VTK format 'Binary'"));
    assert_eq!(fmu.string("results.vtkFormat"), "binary", "unchanged");
    assert_eq!(fmu.set_string("results.vtkFormat", "ascii"), 0);
    assert_eq!(
        fmu.set_string("results.directory", dir.to_str().unwrap()),
        0
    );
    assert_eq!(unsafe { fmi2_exit_initialization_mode(fmu.c) }, 0);
    fmu.ramp(0, 1, 10);
    for file in ["ParallelArch_film_0001.vtu", "ParallelArch_gaps_0001.vtu"] {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(
            text.contains("format=\"ascii\"") && !text.contains("AppendedData"),
            "{file}"
        );
    }
    assert_eq!(film_and_gap_entries(&dir).len(), 2);
}

#[test]
fn a_restored_state_continues_the_pvd_and_reset_starts_it_again() {
    let (u, log) = (Unpacked::specimen("vtk state"), Log::default());
    let dir = u.dir.parent().unwrap().join("vtk");
    let fmu = Fmu::new(&u, &log);
    assert_eq!(fmu.initialized_with_output(&dir), 0);
    fmu.ramp(0, 1, 10);
    let mut state: Fmi2FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2_get_fmu_state(fmu.c, &mut state) }, 0);
    fmu.ramp(1, 4, 10);
    assert_eq!(film_and_gap_entries(&dir).len(), 5);
    let long_branch = std::fs::read(dir.join("ParallelArch_film_0002.vtu")).unwrap();

    // Back to t = 0.1 (step 1) and another input: step 2 again, file 0002 rewritten.
    assert_eq!(unsafe { fmi2_set_fmu_state(fmu.c, state) }, 0);
    assert_eq!(fmu.set_real("frame.dz", -0.001), 0);
    assert_eq!(fmu.step(0.1, 0.1), 0);
    let entries = film_and_gap_entries(&dir);
    let files: Vec<&str> = entries.iter().map(|(_, f)| f.as_str()).collect();
    assert_eq!(
        files,
        [
            "ParallelArch_film_0000.vtu",
            "ParallelArch_film_0001.vtu",
            "ParallelArch_film_0002.vtu"
        ]
    );
    assert!((entries[2].0 - 0.2).abs() < 1e-12);
    assert_ne!(
        std::fs::read(dir.join("ParallelArch_film_0002.vtu")).unwrap(),
        long_branch
    );
    assert_eq!(unsafe { fmi2_free_fmu_state(fmu.c, &mut state) }, 0);

    // Reset: the parameter is back to "" (no output) and the list starts again.
    assert_eq!(unsafe { fmi2_reset(fmu.c) }, 0);
    assert_eq!(fmu.initialized_with_output(&dir), 0);
    assert_eq!(
        film_and_gap_entries(&dir),
        [(0.0, "ParallelArch_film_0000.vtu".to_string())]
    );
    assert_eq!(unsafe { fmi2_reset(fmu.c) }, 0);
    unsafe {
        assert_eq!(fmi2_setup_experiment(fmu.c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2_enter_initialization_mode(fmu.c), 0);
    }
    assert_eq!(fmu.string("results.directory"), "");
}

#[test]
fn a_failed_write_is_a_warning_and_the_step_stands() {
    let (u, log) = (Unpacked::specimen("vtk fail"), Log::default());
    // A directory below a regular file cannot be created.
    let blocker = u.dir.parent().unwrap().join("not a directory");
    std::fs::write(&blocker, "x").unwrap();
    let fmu = Fmu::new(&u, &log);
    let warning = Status::Warning.raw();
    assert_eq!(fmu.initialized_with_output(&blocker.join("vtk")), warning);
    let messages = log.take();
    assert!(
        messages.iter().any(|(s, c, m)| *s == warning
            && c == "logStatusWarning"
            && m.starts_with("fmi2ExitInitializationMode: VTK output at t = 0 failed")
            && m.contains("not a directory")),
        "{messages:?}"
    );
    assert_eq!(fmu.set_real("frame.dz", -0.01), 0);
    assert_eq!(fmu.step(0.0, 0.1), warning);
    assert!(log.contains(Status::Warning, "VTK output at t = 0.1 failed"));
    assert_eq!(fmu.real("time"), 0.1, "the step is kept");
    assert!(fmu.real("G9.slip") != 0.0);
    let mut status = -1;
    assert_eq!(
        unsafe { fmi2_get_status(fmu.c, FMI2_DO_STEP_STATUS, &mut status) },
        0
    );
    assert_eq!(status, 0);
    assert_eq!(fmu.step(0.1, 0.1), warning, "and the next step is taken");
}
