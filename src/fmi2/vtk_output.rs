//! The results files: ParaView VTK files of the converged states, written by the instance.
//!
//! * `results.directory` (String parameter, "" = off): after `fmi2ExitInitializationMode` and
//!   after every successful `fmi2DoStep` the instance writes `<dir>/<id>_film_NNNN.vtu` and
//!   `<dir>/<id>_gaps_NNNN.vtu` (NNNN = 0000 for the initial state, then the number of steps
//!   since initialization; encoded as `results.vtkFormat` says) and rewrites
//!   `<dir>/<id>_film.pvd` and `<dir>/<id>_gaps.pvd` listing every state written so far with its
//!   time (`<id>` = `modelIdentifier`; the directory is created if missing, a relative one is
//!   relative to the importer's working directory). A failed write is logged and returns
//!   `fmi2Warning`: the step (or initialization) itself stands. FMU states hold the step count
//!   and the list of states written, so after `fmi2SetFMUstate` the next step writes the files
//!   that follow the restored state (overwriting those of the abandoned branch) and the `.pvd`
//!   files list that branch only; until that step the `.pvd` files on disk are the old ones, and
//!   files of the abandoned branch beyond it stay on disk. `fmi2Reset` empties the list. Instances of one FMU writing to one directory overwrite each
//!   other's files: give each its own directory.

use std::path::{Path, PathBuf};

use super::instance::Instance;
use super::phase::{Failure, Outcome};
use super::scalar_variable::{Binding, Value};
use crate::mech::results::vtk;

impl Instance {
    /// The value of `results.directory`, `None` when it is empty (no output).
    pub(super) fn results_directory(&self) -> Option<PathBuf> {
        self.description
            .variables
            .iter()
            .zip(&self.values)
            .find_map(|(v, x)| match (v.binding, x) {
                (Binding::ResultsDirectory, Value::String(dir)) if !dir.is_empty() => {
                    Some(PathBuf::from(dir))
                }
                _ => None,
            })
    }

    /// The value of `results.vtkFormat` (checked when it was set).
    fn vtk_encoding(&self) -> vtk::Encoding {
        self.description
            .variables
            .iter()
            .zip(&self.values)
            .find_map(|(v, x)| match (v.binding, x) {
                (Binding::VtkFormat, Value::String(name)) => name.parse().ok(),
                _ => None,
            })
            .unwrap_or_default()
    }

    /// Writes the converged state as `<dir>/<id>_film_NNNN.vtu` and `<dir>/<id>_gaps_NNNN.vtu`
    /// (NNNN = steps since initialization) and rewrites `<dir>/<id>_film.pvd` and
    /// `<dir>/<id>_gaps.pvd`, if `results.directory` is set. A failure is a warning: the
    /// analysis, time and outputs stand; a state whose files could not be written is not listed.
    pub(super) fn write_results(&mut self) -> Outcome {
        let encoding = self.vtk_encoding();
        let (Some(dir), Some(built)) = (self.results_directory(), self.analysis.as_mut()) else {
            return Ok(());
        };
        let id = &self.description.model_identifier;
        let step = self.steps;
        let a = &mut built.analysis;
        let results = a.results();
        let written = std::fs::create_dir_all(&dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))
            .and_then(|()| {
                vtk::Block::of(a.model()).iter().try_for_each(|&block| {
                    let vtu = dir.join(vtk::state_file_name(id, block, step));
                    let u = &a.state().displacement;
                    std::fs::write(&vtu, vtk::grid(block, a.model(), u, &results, encoding))
                        .map_err(|e| format!("{}: {e}", vtu.display()))
                })
            });
        let outcome = written.and_then(|()| {
            self.vtk_steps.push((self.time, step));
            let blocks = vtk::Block::of(built.analysis.model());
            blocks.iter().try_for_each(|&block| {
                let entries: Vec<(f64, String)> = self
                    .vtk_steps
                    .iter()
                    .map(|&(t, k)| (t, vtk::state_file_name(id, block, k)))
                    .collect();
                let pvd = dir.join(vtk::collection_file_name(id, block));
                replace_file(&pvd, &vtk::collection(&entries))
                    .map_err(|e| format!("{}: {e}", pvd.display()))
            })
        });
        outcome.map_err(|e| {
            Failure::warning(format!(
                "VTK output at t = {} failed, the results are kept: {e}",
                self.time
            ))
        })
    }
}

/// Replaces `path` by `text` through a temporary file and a rename, so that a reader (ParaView
/// reloading the `.pvd`) never sees a half-written file.
fn replace_file(path: &Path, text: &str) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
}
