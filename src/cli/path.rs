//! Staged load paths for the command line: a CSV table whose rows are steps and whose columns
//! are the FMU's input names, read through the FMU's variable table (the one place that says
//! which input moves what), so a table drives the CLI exactly as a master drives the FMU.
//!
//! ```csv
//! time, frame.dz, rail.angle, snow.pressure
//! 0.5,  -0.05,    0.02,       0
//! 1.0,  -0.10,    0.05,      -100
//! ```
//!
//! A UTF-8 byte-order mark (spreadsheets write one) is skipped. Blank lines and lines starting
//! with `#` are skipped; cells are trimmed. Every cell is checked as `fmi2SetReal` checks the
//! input ([`Variable::check_value`]: `mu` in `[0, 10]`, …); a Boolean input (a chamber's valve
//! `<chamber>.sealed`) is written 0 or 1. An input without a
//! column keeps its FMU start value (a group's displacement and angle 0, a load the model
//! file's, reached in the first step as by the FMU); `mu` applies from the first row when it has
//! a column. The optional first column `time` (increasing) is the pseudo-time of the VTK
//! collection and the time over which a row's `<chamber>.massFlow` (kg/s) feeds a sealed chamber
//! (and its orifices pass air); without it, row k of N is at k/N.

use membrane_contact::fmi2::variables::{
    Causality, Kind, StepInputs, Value, VarType, Variable, message_real, step_inputs, variables,
};
use membrane_contact::mech::Model;

/// The steps of a staged load path.
#[derive(Clone, Debug, PartialEq)]
pub struct StagedPath {
    /// Pseudo-time at the end of each step.
    pub times: Vec<f64>,
    /// What each step asks for.
    pub steps: Vec<StepInputs>,
    /// Each step's input values, in the order of the FMU's variable table (empty for a ramp):
    /// the chambers' mass flows, which the step integrates over its length.
    pub values: Vec<Vec<Value>>,
}

/// Reads a staged path for `model` from the CSV `text` (`source` names it in errors).
pub fn read(text: &str, model: &Model, source: &str) -> Result<StagedPath, String> {
    let table = variables(model, Kind::Model);
    // The mark is invisible: left on, it would be read as part of the first column's name.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (header_line, header) = lines
        .next()
        .ok_or_else(|| format!("{source}: no header line (the FMU's input names)"))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let has_time = names.first() == Some(&"time");
    if let Some(k) = names.iter().skip(1).position(|&n| n == "time") {
        return Err(if has_time {
            format!("{source} line {header_line}: column 'time' appears twice")
        } else {
            format!(
                "{source} line {header_line}: column 'time' is column {}; it must be the first \
                 column (the pseudo-time of each row), or left out",
                k + 2
            )
        });
    }
    let columns: Vec<usize> = names[usize::from(has_time)..]
        .iter()
        .map(|name| column(&table, name, names.as_slice()))
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{source} line {header_line}: {e}"))?;
    let mu_given = columns.iter().any(|&c| table[c].name == "mu");
    let mut values: Vec<Value> = table
        .iter()
        .map(|v| v.start.clone().unwrap_or(Value::Real(0.0)))
        .collect();
    let (mut times, mut rows, mut row_values) = (Vec::new(), Vec::new(), Vec::new());
    for (line, row) in lines {
        let cells: Vec<&str> = row.split(',').map(str::trim).collect();
        if cells.len() != names.len() {
            return Err(format!(
                "{source} line {line}: {} cells, the header has {} columns",
                cells.len(),
                names.len()
            ));
        }
        let at = |k: usize| format!("{source} line {line}, column '{}'", names[k]);
        let number = |k: usize| -> Result<f64, String> {
            let v: f64 = cells[k]
                .parse()
                .map_err(|_| format!("{}: '{}' is not a number", at(k), cells[k]))?;
            if !v.is_finite() {
                return Err(format!("{}: {v} is not finite", at(k)));
            }
            Ok(v)
        };
        // An input's cell: a Boolean input (a chamber's valve) is 0 or 1; each passes the
        // FMU's own check of the value (fmi2SetReal's, fmi2SetBoolean's).
        let input = |k: usize, var: &Variable| -> Result<Value, String> {
            let value = match var.var_type {
                VarType::Boolean => match cells[k] {
                    "0" => Value::Boolean(false),
                    "1" => Value::Boolean(true),
                    cell => {
                        return Err(format!(
                            "{}: '{cell}' is not 0 or 1 (a Boolean input)",
                            at(k)
                        ));
                    }
                },
                _ => Value::Real(number(k)?),
            };
            var.check_value(&value)
                .map_err(|e| format!("{}: {e}", at(k)))?;
            Ok(value)
        };
        if has_time {
            let t = number(0)?;
            if let Some(&last) = times.last()
                && t <= last
            {
                return Err(format!(
                    "{source} line {line}: time {} does not increase (the row before is at {})",
                    message_real(t),
                    message_real(last)
                ));
            }
            times.push(t);
        }
        for (k, &c) in columns.iter().enumerate() {
            values[c] = input(k + usize::from(has_time), &table[c])?;
        }
        rows.push(step_inputs(model, &table, &values, mu_given));
        row_values.push(values.clone());
    }
    if rows.is_empty() {
        return Err(format!("{source}: no steps (only a header)"));
    }
    if !has_time {
        let n = rows.len() as f64;
        times = (1..=rows.len()).map(|k| k as f64 / n).collect();
    }
    Ok(StagedPath {
        times,
        steps: rows,
        values: row_values,
    })
}

/// Checks `value` for the FMU input `name` of `model` as `fmi2SetReal` does
/// ([`Variable::check_value`]): the command line's options that stand for an input (`--mu`)
/// accept exactly what the FMU accepts.
pub fn check_input(model: &Model, name: &str, value: f64) -> Result<(), String> {
    let table = variables(model, Kind::Model);
    match table
        .iter()
        .find(|v| v.name == name && v.causality == Causality::Input)
    {
        Some(v) => v.check_value(&Value::Real(value)),
        None => Err(format!(
            "the model has no input '{name}' (its FMU would have none){}",
            if name == "mu" {
                ": no gaps or curved supports, no friction coefficient to set"
            } else {
                ""
            }
        )),
    }
}

/// Writes the staged table of `steps` steps whose groups reach `targets_at(k / steps)` at step
/// `k` (columns `time` and every group's `.dx, .dy, .dz`), the form [`read`] reads back.
pub fn write(model: &Model, steps: usize, targets_at: impl Fn(f64) -> Vec<[f64; 3]>) -> String {
    let mut header = vec!["time".to_string()];
    for g in &model.groups {
        header.extend(["dx", "dy", "dz"].map(|c| format!("{}.{c}", g.name)));
    }
    let mut text = header.join(",") + "\n";
    for k in 1..=steps {
        let t = k as f64 / steps as f64;
        let mut cells = vec![t.to_string()];
        cells.extend(targets_at(t).iter().flatten().map(f64::to_string));
        text += &(cells.join(",") + "\n");
    }
    text
}

/// The table row of the input `name`, or an error that says what the name is instead.
fn column(table: &[Variable], name: &str, header: &[&str]) -> Result<usize, String> {
    if header.iter().filter(|&&n| n == name).count() > 1 {
        return Err(format!("column '{name}' appears twice"));
    }
    match table.iter().position(|v| v.name == name) {
        Some(i) if table[i].causality == Causality::Input => Ok(i),
        Some(i) => Err(format!(
            "column '{name}' is {} of the FMU, not an input: set it in the model file",
            match table[i].causality {
                Causality::Parameter => "a parameter",
                Causality::Output => "an output",
                _ => "not an input",
            }
        )),
        None => {
            let inputs: Vec<&str> = table
                .iter()
                .filter(|v| v.causality == Causality::Input)
                .map(|v| v.name.as_str())
                .collect();
            Err(format!(
                "unknown column '{name}'; the model's inputs are: time (first column), {}",
                inputs.join(", ")
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use membrane_contact::specimens::ParallelArch;

    fn specimen() -> Model {
        ParallelArch::default().model().unwrap()
    }

    #[test]
    fn rows_become_steps_and_missing_inputs_keep_their_start_values() {
        let path = read(
            "# lower the frame, then raise mu\ntime, frame.dz, mu\n0.5, -0.05, 0.2\n\n1.0, -0.15, 0.4\n",
            &specimen(),
            "t.csv",
        )
        .unwrap();
        assert_eq!(path.times, vec![0.5, 1.0]);
        assert_eq!(path.steps[1].targets[0], [0.0, 0.0, -0.15]);
        assert_eq!(path.steps[0].mu, Some(0.2));
        assert_eq!(path.steps[1].mu, Some(0.4));
        let without_time = read("frame.dx\n0.01\n0.02\n", &specimen(), "t.csv").unwrap();
        assert_eq!(without_time.times, vec![0.5, 1.0]);
        assert_eq!(without_time.steps[0].mu, None);
    }

    #[test]
    fn a_written_frame_path_reads_back_as_the_same_steps() {
        use membrane_contact::specimens::parallel_arch::FramePath;
        let spec = ParallelArch {
            frame_path: FramePath::Wrapped { extension: 0.02 },
            ..ParallelArch::default()
        };
        let model = spec.model().unwrap();
        let text = write(&model, 4, |t| spec.boundary_targets(&model, t));
        let path = read(&text, &model, "wrap.csv").unwrap();
        assert_eq!(path.times, vec![0.25, 0.5, 0.75, 1.0]);
        for (k, step) in path.steps.iter().enumerate() {
            let t = (k + 1) as f64 / 4.0;
            assert_eq!(step.targets, spec.boundary_targets(&model, t));
        }
        assert_eq!(model.groups.len(), 21);
        assert!(
            path.steps[3]
                .targets
                .iter()
                .any(|d| d[2] < -spec.arch_height)
        );
    }

    #[test]
    fn bad_tables_are_refused_naming_line_and_column() {
        let cases = [
            ("", "no header line"),
            ("frame.dz\n", "no steps"),
            (
                "frame.dq\n1\n",
                "unknown column 'frame.dq'; the model's inputs are: time",
            ),
            ("film.E\n1\n", "column 'film.E' is a parameter of the FMU"),
            ("G1.slip\n1\n", "column 'G1.slip' is an output of the FMU"),
            ("frame.dz, frame.dz\n1, 2\n", "appears twice"),
            (
                "frame.dz\nabc\n",
                "t.csv line 2, column 'frame.dz': 'abc' is not a number",
            ),
            ("frame.dz\nNaN\n", "NaN is not finite"),
            (
                "frame.dz, mu\n1\n",
                "line 2: 1 cells, the header has 2 columns",
            ),
            ("time, frame.dz\n1, 0\n1, 0\n", "time 1 does not increase"),
            (
                "frame.dz, time\n-0.1, 1\n",
                "t.csv line 1: column 'time' is column 2; it must be the first column",
            ),
            (
                "time, frame.dz, time\n1, 0, 1\n",
                "column 'time' appears twice",
            ),
            (
                "mu\n0.2\n11\n",
                "t.csv line 3, column 'mu': mu = 11: the friction coefficient must be ≥ 0 and ≤ 10",
            ),
            (
                "time, mu\n1, -1e300\n",
                "line 2, column 'mu': mu = -1e300: the friction",
            ),
        ];
        for (text, expected) in cases {
            let e = read(text, &specimen(), "t.csv").unwrap_err();
            assert!(e.contains(expected), "'{e}' lacks '{expected}'");
        }
    }

    #[test]
    fn a_chambers_valve_column_of_zeros_and_ones_opens_and_closes_it_per_step() {
        let model = Model::from_json(include_str!("../../examples/cushion_air.json")).unwrap();
        let path = read(
            "air.supplyPressure, air.sealed, air.heating\n300, 0, 0\n300, 1, 30\n300, 0, 0\n",
            &model,
            "t.csv",
        )
        .unwrap();
        let sealed: Vec<_> = path.steps.iter().map(|s| s.sealed[0]).collect();
        assert_eq!(sealed, [false, true, false]);
        assert_eq!(path.steps[1].loads.heating[0], 30.0);
        assert_eq!(path.steps[0].loads.chambers[0], 300.0);
        let e = read("air.sealed\ntrue\n", &model, "t.csv").unwrap_err();
        assert!(
            e.contains("t.csv line 2, column 'air.sealed': 'true' is not 0 or 1"),
            "{e}"
        );
    }

    #[test]
    fn a_byte_order_mark_before_the_header_is_skipped() {
        let text = "time, frame.dz, mu\n0.5, -0.05, 0.3\n";
        let marked = read(&format!("\u{feff}{text}"), &specimen(), "t.csv").unwrap();
        assert_eq!(marked, read(text, &specimen(), "t.csv").unwrap());
        assert_eq!(marked.times, vec![0.5]);
    }

    #[test]
    fn options_that_stand_for_an_input_pass_the_fmus_check_of_it() {
        let model = specimen();
        assert_eq!(check_input(&model, "mu", 10.0), Ok(()));
        let e = check_input(&model, "mu", 10.5).unwrap_err();
        assert_eq!(
            e,
            "mu = 10.5: the friction coefficient must be ≥ 0 and ≤ 10"
        );
        let mut free = model.clone();
        free.gaps.clear();
        let e = check_input(&free, "mu", 0.3).unwrap_err();
        assert!(e.contains("no gaps or curved supports"), "{e}");
    }
}
