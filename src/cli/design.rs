//! The design commands (issue 46): `form-find` (the shape that carries a target prestress).

use std::path::{Path, PathBuf};
use std::time::Instant;

use membrane_contact::mech::Model;
use membrane_contact::mech::formfinding::force_density::force_density_shape;
use membrane_contact::mech::formfinding::form_found_model;
use membrane_contact::mech::formfinding::update_reference::{UpdateSettings, find_shape};

/// What `form-find` is asked.
pub struct FormFindArgs<'a> {
    pub file: &'a Path,
    pub out: Option<&'a PathBuf>,
    pub prestress: Option<[f64; 3]>,
    pub force_density_start: bool,
    pub settings: UpdateSettings,
}

/// Reads a model file.
pub fn read_model(file: &Path) -> Result<Model, String> {
    let name = file.display();
    let text = std::fs::read_to_string(file).map_err(|e| format!("{name}: {e}"))?;
    Model::from_json(&text).map_err(|e| format!("{name}: {e}"))
}

/// Writes `text` to `out`, or to standard output.
pub fn write_text(out: Option<&PathBuf>, text: &str) -> Result<(), String> {
    match out {
        Some(file) => std::fs::write(file, text).map_err(|e| format!("{}: {e}", file.display())),
        None => {
            print!("{text}");
            Ok(())
        }
    }
}

/// `membrane-contact form-find FILE`: the found shape as a model file, a summary on stderr.
pub fn form_find(a: FormFindArgs<'_>) -> Result<(), String> {
    let model = read_model(a.file)?;
    let prestress = a.prestress.unwrap_or(model.material.prestress);
    if !model.gaps.is_empty() || !model.curved_supports.is_empty() {
        eprintln!(
            "warning: form finding does not take gaps or curved supports into account: their film nodes are free"
        );
    }
    let started = Instant::now();
    let start = if a.force_density_start {
        force_density_shape(&model).map_err(|e| e.to_string())?
    } else {
        model.nodes.clone()
    };
    let found = find_shape(&model, start, prestress, a.settings).map_err(|e| e.to_string())?;
    let moved = found
        .nodes
        .iter()
        .zip(&model.nodes)
        .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    eprintln!(
        "form found: {} reference updates, out-of-balance {:.2e} of t·|σ|·L̄, largest node move {:.4} m, {:.2?}",
        found.steps,
        found.residuals.last().copied().unwrap_or(0.0),
        moved,
        started.elapsed()
    );
    let result = form_found_model(&model, found.nodes, prestress);
    write_text(a.out, &(result.to_json() + "\n"))
}
