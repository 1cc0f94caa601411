//! The design commands (issue 46): `form-find` (the shape that carries a target prestress) and
//! `pattern` (its cutting pattern).

use std::path::{Path, PathBuf};
use std::time::Instant;

use membrane_contact::mech::Model;
use membrane_contact::mech::formfinding::contact::{ContactSettings, find_shape_with_contact};
use membrane_contact::mech::formfinding::force_density::force_density_shape;
use membrane_contact::mech::formfinding::form_found_model;
use membrane_contact::mech::formfinding::update_reference::{UpdateSettings, find_shape};
use membrane_contact::mech::patterning::contact_stiffness::{
    ContactStiffness, SupportStiffness, support_stiffnesses, with_node_stiffnesses,
};
use membrane_contact::mech::patterning::cut::{Compensation, CutStrip, cut_pattern};
use membrane_contact::mech::patterning::element_compensation::{
    ContactEnd, ElementSettings, ErectContacts, away_from_rails, compensate_elements,
    erect_through, rail_waypoints, settling_amplitude, settling_waypoints,
};
use membrane_contact::mech::patterning::erection::compensate_by_erection;
use membrane_contact::mech::patterning::geodesic::geodesic_seams;
use membrane_contact::mech::patterning::outline::{OutlineLabel, boundary_edges, dxf, svg};
use membrane_contact::mech::patterning::reference::{erection_model, reference_geometry};
use membrane_contact::mech::patterning::seams::{
    SeamPlane, strips_by_node_lines, strips_by_planes,
};
use membrane_contact::mech::patterning::split::{SNAP, SplitFilm, split_along};

/// What `form-find` is asked.
pub struct FormFindArgs<'a> {
    pub file: &'a Path,
    pub out: Option<&'a PathBuf>,
    pub prestress: Option<[f64; 3]>,
    /// The warp direction: the model's `frame_axis` for the target and the found model.
    pub warp: Option<[f64; 3]>,
    pub force_density_start: bool,
    pub settings: UpdateSettings,
    /// Against the curved supports (frictionless), with these settings.
    pub on_supports: Option<ContactSettings>,
    /// How the curved supports' penalties are read ([`ContactStiffness`]).
    pub contact_stiffness: ContactStiffness,
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
    let mut model = read_model(a.file)?;
    if let Some(warp) = a.warp {
        model.frame_axis = Some(warp);
        model
            .validate()
            .map_err(|e| format!("{}: --warp: {e}", a.file.display()))?;
    }
    let prestress = a.prestress.unwrap_or(model.material.prestress);
    if !model.gaps.is_empty() || (a.on_supports.is_none() && !model.curved_supports.is_empty()) {
        eprintln!(
            "warning: form finding does not take gaps (or, without --on-supports, curved supports) into account: their film nodes are free"
        );
    }
    let started = Instant::now();
    let start = if a.force_density_start {
        force_density_shape(&model).map_err(|e| e.to_string())?
    } else {
        model.nodes.clone()
    };
    if let Some(settings) = a.on_supports {
        if !(settings.homotopy > 0.0 && settings.homotopy.is_finite()) {
            return Err(format!(
                "--homotopy {}: must be positive",
                settings.homotopy
            ));
        }
        // The found model keeps the file's penalties; the steps take them per node.
        let stiffness = support_stiffnesses(&model, a.contact_stiffness)?;
        if let Some(line) = stiffness_line(&stiffness) {
            eprintln!("{line}");
        }
        let contact_model = with_node_stiffnesses(model.clone(), &stiffness);
        let found = find_shape_with_contact(&contact_model, start, prestress, settings)
            .map_err(|e| e.to_string())?;
        eprintln!(
            "form found on the supports: {} reference updates, stress within {:.2e} of the target, {} nodes touching, {:.2?}",
            found.moves.len(),
            found.deviations.last().copied().unwrap_or(0.0),
            found.touching.len(),
            started.elapsed()
        );
        let result = form_found_model(&model, found.nodes, prestress);
        return write_text(a.out, &(result.to_json() + "\n"));
    }
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

/// What `pattern` is asked.
pub struct PatternArgs<'a> {
    pub file: &'a Path,
    pub seam_planes: &'a [[f64; 6]],
    pub seam_nodes: &'a [String],
    /// Geodesic seams: the start lines' nodes and the strip widths (m; one for all, or one per
    /// line).
    pub geodesic: (&'a [String], &'a [f64]),
    pub compensation: &'a str,
    pub svg: Option<&'a PathBuf>,
    pub dxf: Option<&'a PathBuf>,
    pub erection_model: Option<&'a PathBuf>,
    /// Erections at most, the mean error to stop at, increments per erection.
    pub erect: (usize, f64, usize),
    /// Correct each triangle's reference metric, not each strip's compensation.
    pub by_element: bool,
    /// The rails' offsets `[up, in]` (m) at each waypoint of the erection path.
    pub rail_path: &'a [[f64; 2]],
    /// Settling after the rail path: amplitude (m; None: [`settling_amplitude`]), ratio, cycles
    /// ([`settling_waypoints`]).
    pub settle: Option<(Option<f64>, f64, usize)>,
    /// How the curved supports' penalties are read in the erections ([`ContactStiffness`]).
    pub contact_stiffness: ContactStiffness,
    /// A folder to write each erection's model to (`erection-K.json`), as the loop erects it.
    pub erection_models: Option<&'a PathBuf>,
    /// Where to write the report as JSON.
    pub report: Option<&'a PathBuf>,
}

/// `prestress`, or `C` / `CX,CY` in percent.
fn compensation(text: &str) -> Result<Compensation, String> {
    if text == "prestress" {
        return Ok(Compensation::Prestress);
    }
    let v: Vec<f64> = text
        .split(',')
        .map(|p| {
            p.trim()
                .parse::<f64>()
                .map_err(|e| format!("--compensation {p:?}: {e}"))
        })
        .collect::<Result<_, _>>()?;
    match v[..] {
        [c] => Ok(Compensation::Uniform([c / 100.0; 2])),
        [cx, cy] => Ok(Compensation::Uniform([cx / 100.0, cy / 100.0])),
        _ => Err("--compensation: prestress, C or CX,CY (percent)".into()),
    }
}

/// The geodesic seams from each start line of `a` (one line on stderr each), the film split
/// along them: the split film and its strips.
fn geodesic_split(model: &Model, a: &PatternArgs<'_>) -> Result<Option<SplitFilm>, String> {
    let (lines, widths) = a.geodesic;
    if lines.is_empty() {
        return Ok(None);
    }
    if widths.len() != 1 && widths.len() != lines.len() {
        return Err(format!(
            "--strip-width: one width for every --geodesic-from, or one per start line ({} lines, {} widths)",
            lines.len(),
            widths.len()
        ));
    }
    let mut all = Vec::new();
    for (k, line) in lines.iter().enumerate() {
        let width = widths[k.min(widths.len() - 1)];
        let line = node_line(model, line, "--geodesic-from")?;
        let seams =
            geodesic_seams(model, &line, width).map_err(|e| format!("--geodesic-from: {e}"))?;
        let lengths: Vec<String> = (seams.seams.iter())
            .map(|s| format!("{:.4}", s.last().map_or(0.0, |g| g.length)))
            .collect();
        let inside = match seams.start_seam {
            Some(k) => format!(" (the start line, inside the film, is seam {k})"),
            None => String::new(),
        };
        eprintln!(
            "geodesic seams: {} seams {width} m apart along a transverse geodesic of {:.4} m, lengths {} m{inside}",
            seams.seams.len(),
            seams.transverse.last().map_or(0.0, |g| g.length),
            lengths.join(", ")
        );
        all.extend(seams.seams);
    }
    let split = split_along(model, &all, SNAP).map_err(|e| format!("--geodesic-from: {e}"))?;
    eprintln!(
        "split along the seams: {} nodes and {} triangles added",
        split.model.nodes.len() - model.nodes.len(),
        split.model.triangles.len() - model.triangles.len()
    );
    Ok(Some(split))
}

/// The strips the seams cut (planes, then node lines within them, then geodesic seams; none:
/// the whole film), on the film split along the geodesic seams (the model returned).
fn strips(model: Model, a: &PatternArgs<'_>) -> Result<(Model, Vec<Vec<usize>>), String> {
    let planes: Vec<SeamPlane> = a
        .seam_planes
        .iter()
        .map(|p| SeamPlane {
            point: [p[0], p[1], p[2]],
            normal: [p[3], p[4], p[5]],
        })
        .collect();
    let lines: Vec<Vec<usize>> = a
        .seam_nodes
        .iter()
        .map(|l| node_line(&model, l, "--seam-nodes"))
        .collect::<Result<_, _>>()?;
    let mut partitions = vec![
        strips_by_planes(&model, &planes),
        strips_by_node_lines(&model, &lines),
    ];
    let model = match geodesic_split(&model, a)? {
        None => model,
        Some(split) => {
            // The planes' and node lines' strips hold the pieces of their triangles.
            for partition in &mut partitions {
                let mut part = vec![usize::MAX; model.triangles.len()];
                for (k, strip) in partition.iter().enumerate() {
                    strip.iter().for_each(|&t| part[t] = k);
                }
                let mut pieces = vec![Vec::new(); partition.len()];
                for (t, &p) in split.parent.iter().enumerate() {
                    pieces[part[p]].push(t);
                }
                *partition = pieces;
            }
            partitions.push(split.strips.clone());
            split.model
        }
    };
    // A strip is a set of triangles in the same part of every partition (the same side of
    // every plane, connected across non-seam edges, between the same geodesic seams).
    let mut strips: Vec<Vec<usize>> = partitions.remove(0);
    for partition in &partitions {
        let mut next = Vec::new();
        for p in &strips {
            for l in partition {
                let both: Vec<usize> = p
                    .iter()
                    .copied()
                    .filter(|t| l.binary_search(t).is_ok())
                    .collect();
                if !both.is_empty() {
                    next.push(both);
                }
            }
        }
        strips = next;
    }
    Ok((model, strips))
}

/// The nodes `N1,N2,…` of `text`, each a node of `model` (`option` names the option in errors).
fn node_line(model: &Model, text: &str, option: &str) -> Result<Vec<usize>, String> {
    text.split(',')
        .map(|n| match n.trim().parse::<usize>() {
            Ok(v) if v < model.nodes.len() => Ok(v),
            _ => Err(format!("{option}: {n:?} is not a node of the model")),
        })
        .collect()
}

/// The erection iterations, one line each on stdout; the last erection's compensation and the
/// erections as JSON (mean and largest prestress error, each strip's compensation).
fn compensate_with_erections(
    model: &Model,
    strips: Vec<Vec<usize>>,
    start: Compensation,
    (iterations, tolerance): (usize, f64),
    erect: &mut ErectContacts<'_>,
) -> Result<(Compensation, Vec<serde_json::Value>), String> {
    let mut erect = |m: Model| erect(m).map(|e| e.elements);
    let history =
        compensate_by_erection(model, strips, start, (iterations, tolerance), &mut erect)?;
    for (k, h) in history.iter().enumerate() {
        let worst = (0..h.element_errors.len())
            .max_by(|&i, &j| h.element_errors[i].total_cmp(&h.element_errors[j]));
        let per_strip: Vec<String> = h
            .compensation
            .iter()
            .map(|c| format!("{:.3}/{:.3}", 100.0 * c[0], 100.0 * c[1]))
            .collect();
        println!(
            "erection {k}: prestress error mean {:.3} %, max {:.3} % (triangle {}), compensation % {}",
            100.0 * h.mean_error,
            100.0 * h.max_error,
            worst.unwrap_or(0),
            per_strip.join(" ")
        );
    }
    let last = history.last().ok_or("no erection was made")?;
    let report = history
        .iter()
        .map(|h| {
            serde_json::json!({
                "mean_error": h.mean_error,
                "max_error": h.max_error,
                "compensation": h.compensation,
            })
        })
        .collect();
    Ok((Compensation::PerStrip(last.compensation.clone()), report))
}

/// The element-wise erections ([`compensate_elements`]), one line each on stdout, then the
/// triangles that stalled and those friction holds; the best erection's cut and the report.
fn compensate_by_elements(
    model: &Model,
    strips: Vec<Vec<usize>>,
    start: Compensation,
    (iterations, tolerance): (usize, f64),
    erect: &mut ErectContacts<'_>,
) -> Result<(Vec<CutStrip>, serde_json::Value), String> {
    let settings = ElementSettings {
        iterations,
        tolerance,
        counted: away_from_rails(model),
    };
    let outcome = compensate_elements(model, strips, start, &settings, erect)?;
    for (k, h) in outcome.history.iter().enumerate() {
        println!(
            "erection {k}: prestress error away from the rails mean {:.3} %, max {:.3} % (triangle {}), {} triangles yielded",
            100.0 * h.mean_error,
            100.0 * h.max_error.0,
            h.max_error.1,
            h.yielded
        );
    }
    if !outcome.stalled.is_empty() {
        println!(
            "not reached: {} triangles above {:.3} % whose error did not halve; {} of them held by friction on a support: {:?}",
            outcome.stalled.len(),
            100.0 * tolerance,
            outcome.held_by_friction.len(),
            outcome.held_by_friction
        );
    }
    let erections: Vec<serde_json::Value> = outcome
        .history
        .iter()
        .map(|h| {
            let outside = (0..h.element_errors.len())
                .filter(|&t| settings.counted[t] && h.element_errors[t] > tolerance)
                .count();
            serde_json::json!({
                "mean_error": h.mean_error,
                "max_error": h.max_error.0,
                "worst_triangle": h.max_error.1,
                "outside_tolerance": outside,
                "yielded": h.yielded,
                "compensation": h.compensation,
                "stress": h.stresses,
                "contacts": h.contacts.iter().map(|c| contact_json(model, c)).collect::<Vec<_>>(),
            })
        })
        .collect();
    let report = serde_json::json!({
        "erections": erections,
        "stalled": outcome.stalled,
        "held_by_friction": outcome.held_by_friction,
    });
    Ok((outcome.cut, report))
}

/// A contact node at the end of an erection as JSON: node, support (name), status, normal and
/// friction forces (N), slip (m).
fn contact_json(model: &Model, c: &ContactEnd) -> serde_json::Value {
    serde_json::json!({
        "node": c.node,
        "support": model.curved_supports.get(c.support).map(|s| s.name.as_str()),
        "status": c.status,
        "normal_force": c.normal_force,
        "friction": c.friction,
        "slip": c.slip,
    })
}

/// A cut strip as JSON: its triangles, size (m), compensation, distortion (strains) and its
/// outline (the compensated flat strip's boundary edges, m).
fn strip_json(model: &Model, c: &CutStrip) -> serde_json::Value {
    let outline: Vec<[[f64; 2]; 2]> = boundary_edges(model, &c.strip)
        .into_iter()
        .map(|[a, b]| [c.strip.flat[a], c.strip.flat[b]])
        .collect();
    serde_json::json!({
        "triangles": c.strip.triangles,
        "size": c.size,
        "compensation": c.compensation,
        "distortion": { "max": c.distortion.max_strain, "rms": c.distortion.rms_strain },
        "outline": outline,
    })
}

/// The rails' waypoints `[up, in]` of the erections: the rail path, settled where asked (the
/// amplitude chosen by [`settling_amplitude`] on the start's cut where not given, one line on
/// stderr), and the settling as JSON (null: none).
fn erection_path(
    model: &Model,
    strips: &[Vec<usize>],
    compensation: &Compensation,
    a: &PatternArgs<'_>,
) -> Result<(Vec<[f64; 2]>, serde_json::Value), String> {
    let Some((amplitude, ratio, cycles)) = a.settle else {
        return Ok((a.rail_path.to_vec(), serde_json::Value::Null));
    };
    let chosen = amplitude.is_none();
    let amplitude = match amplitude {
        Some(amplitude) => amplitude,
        None => settling_amplitude(
            model,
            &cut_pattern(model, strips.to_vec(), compensation.clone())?,
        )?,
    };
    let path = settling_waypoints(a.rail_path, amplitude, ratio, cycles)?;
    eprintln!(
        "settling: amplitude {:.4} mm ({}), ratio {ratio}, {cycles} waypoints",
        1e3 * amplitude,
        if chosen {
            "chosen: half the prestress's length change of the longest strip"
        } else {
            "given"
        }
    );
    let settle = serde_json::json!({
        "amplitude": amplitude, "ratio": ratio, "cycles": cycles, "chosen": chosen,
    });
    Ok((path, settle))
}

/// The curved supports' penalties per node in the design loop, one line (none without any).
fn stiffness_line(stiffness: &[SupportStiffness]) -> Option<String> {
    let supports: Vec<String> = (stiffness.iter())
        .map(|s| match s.tributary_length {
            Some(l) => format!(
                "{} per length × {l:.4} m: k_n {:.4e}, k_s {:.4e} N/m",
                s.name, s.normal_stiffness, s.tangential_stiffness
            ),
            None => format!(
                "{} per node: k_n {:.4e}, k_s {:.4e} N/m",
                s.name, s.normal_stiffness, s.tangential_stiffness
            ),
        })
        .collect();
    (!supports.is_empty()).then(|| format!("contact stiffness: {}", supports.join("; ")))
}

/// The curved supports' penalties per node in the design loop as JSON: name, tributary length
/// (m, null where per node), normal and tangential stiffness (N/m).
fn stiffness_json(stiffness: &[SupportStiffness]) -> serde_json::Value {
    (stiffness.iter())
        .map(|s| {
            serde_json::json!({
                "support": s.name,
                "tributary_length": s.tributary_length,
                "normal_stiffness": s.normal_stiffness,
                "tangential_stiffness": s.tangential_stiffness,
            })
        })
        .collect::<Vec<_>>()
        .into()
}

/// `membrane-contact pattern FILE`: one line per strip on stdout, the outlines as SVG.
pub fn pattern(a: PatternArgs<'_>) -> Result<(), String> {
    if a.by_element && a.erect.0 == 0 {
        return Err("--by-element corrects by erections: give --erect N (N ≥ 1)".into());
    }
    let started = Instant::now();
    let (model, strips) = strips(read_model(a.file)?, &a)?;
    let mut compensation = compensation(a.compensation)?;
    let mut report = serde_json::json!({ "erections": [] });
    let (path, settle) = erection_path(&model, &strips, &compensation, &a)?;
    let path = rail_waypoints(&model, &path);
    let stiffness = support_stiffnesses(&model, a.contact_stiffness)?;
    if let Some(line) = stiffness_line(&stiffness) {
        eprintln!("{line}");
    }
    let (iterations, tolerance, increments) = a.erect;
    let mut count = 0;
    // Each erection's model is written first (`--erection-models DIR`), then erected.
    let mut erect = |m: Model| {
        if let Some(dir) = a.erection_models {
            let file = dir.join(format!("erection-{count}.json"));
            write_text(Some(&file), &(m.to_json() + "\n"))?;
        }
        count += 1;
        erect_through(m, increments, &path)
    };
    let mut erect = |m: Model| erect(with_node_stiffnesses(m, &stiffness));
    if let Some(dir) = a.erection_models {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let cut = if iterations > 0 && a.by_element {
        let (cut, r) = compensate_by_elements(
            &model,
            strips,
            compensation,
            (iterations, tolerance),
            &mut erect,
        )?;
        report = r;
        cut
    } else {
        if iterations > 0 {
            let erections;
            (compensation, erections) = compensate_with_erections(
                &model,
                strips.clone(),
                compensation,
                (iterations, tolerance),
                &mut erect,
            )?;
            report["erections"] = erections.into();
        }
        cut_pattern(&model, strips, compensation)?
    };
    if let Some(file) = a.report {
        report["settle"] = settle;
        report["contact_stiffness"] = stiffness_json(&stiffness);
        report["strips"] = (cut.iter())
            .map(|c| strip_json(&model, c))
            .collect::<Vec<_>>()
            .into();
        write_text(Some(file), &(report.to_string() + "\n"))?;
    }
    for (k, c) in cut.iter().enumerate() {
        println!(
            "strip {k}: {} triangles, cut {:.4} × {:.4} m, compensation {:.3} % × {:.3} %, distortion max {:.3} %, rms {:.3} %",
            c.strip.triangles.len(),
            c.size[0],
            c.size[1],
            100.0 * c.compensation[0],
            100.0 * c.compensation[1],
            100.0 * c.distortion.max_strain,
            100.0 * c.distortion.rms_strain
        );
    }
    eprintln!("patterned: {} strips, {:.2?}", cut.len(), started.elapsed());
    if let Some(file) = a.erection_model {
        let reference = reference_geometry(&model, &cut)?;
        write_text(
            Some(file),
            &(with_node_stiffnesses(erection_model(&model, reference), &stiffness).to_json()
                + "\n"),
        )?;
    }
    let labels: Vec<OutlineLabel> = (0..cut.len())
        .map(|k| OutlineLabel {
            name: format!("strip {k}"),
            compensation: cut[k].compensation,
        })
        .collect();
    let strips: Vec<_> = cut.into_iter().map(|c| c.strip).collect();
    if let Some(file) = a.svg {
        write_text(Some(file), &svg(&model, &strips, &labels))?;
    }
    if let Some(file) = a.dxf {
        write_text(Some(file), &dxf(&model, &strips, &labels))?;
    }
    Ok(())
}
