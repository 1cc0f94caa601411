//! Held-out robustness set (`cargo bench --bench heldout`, issue 19): load paths the solver was
//! not tuned on. Its models come from this file's own random builder, written as model files
//! (JSON, read by [`Model::from_json`] as a user's file is), not from
//! `membrane_contact::mech::scenarios` (the generator the solver's heuristics were tuned
//! against, `benches/robustness.rs`). Every path runs with the default solver settings and the
//! FMU's default increments per step, one `step_to_motion` per communication step as the FMU
//! does; the table gives per family how many paths converge, Newton iterations per increment,
//! cut-backs, the time and the first failure.
//!
//! # Families (seeded: the same paths on every run)
//!
//! * **arches**: random panels (2–5 m × 1.5–3 m, jittered structured triangulation) over 1–4
//!   parallel tube arches (curved supports, parabolic, rise 0.1–0.35 m, μ 0–0.5, either friction
//!   law), prestress 0.5–3 MPa (not always equal both ways), the wrinkling entry absent or
//!   tension-field; the two short edges are rails lowered (and moved in or out, one of them
//!   possibly turned about a hinge) in 1–3 stages, 5…160 steps in all.
//! * **reversal**: a panel of the arches family lowered onto its arches, then a follower
//!   pressure `p` reversed: suction lifting the film off, pressure pushing it back, suction
//!   again, released (contacts opening and closing under load).
//! * **slack**: unstressed films (no prestress): a clamped rectangle or disc under its own weight,
//!   a strip lifted somewhere along its middle line, a panel whose rails are lowered onto arches.
//! * **steps**: step counts swept 5, 10, 20, 40, 80, 160 on a 3 m × 2 m panel over two arches
//!   with one rail turned about a hinge (linear film as given, and tension-field), and on
//!   `examples/hinged_panel.json`.
//!
//! Options (after `--`): `--family NAME` (repeatable), `--quick` (every 5th path),
//! `--name TEXT` (only the paths whose name contains TEXT; repeatable: any of them),
//! `--failures` (every failed path), `--threads N`, `--check` (exit 1 unless every path run
//! converges), `--list` (the paths, not run), `--write DIR` (the model files and, beside each,
//! its stages as `*.stages.json`, not run), `--seed N` (another set from the same generator:
//! paths this set never showed, to check that a gain is not particular to it), `--advice` (after
//! the tables, every refused path again with the change its refusal advises: the isotropic law
//! on the supports it names, or four times the increments per step; a table of how many then
//! converge, per class).
//!
//! After the family table, a table of the refusals by class ([`failure_class`]): what the
//! refusal's message says stopped the last attempt of the refused increment.

use std::fmt::Write as _;
use std::time::Instant;

use membrane_contact::fmi2::variables::DEFAULT_INCREMENTS_PER_STEP;
use membrane_contact::mech::solve::{STRATEGIES, StepReport};
use membrane_contact::mech::{Analysis, LoadLevels, Model, SolverSettings};
use serde_json::{Value, json};

#[path = "common/options.rs"]
mod options;
use options::{PathOptions, on_threads};

/// splitmix64: a small deterministic generator, so that the set is the same on every run.
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[a, b)`.
    fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform integer in `a..=b`.
    fn int(&mut self, a: usize, b: usize) -> usize {
        a + (self.next() % (b - a + 1) as u64) as usize
    }
    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.int(0, items.len() - 1)]
    }
    fn chance(&mut self, p: f64) -> bool {
        self.uniform(0.0, 1.0) < p
    }
}

/// Step counts of the sweep.
const STEP_COUNTS: [usize; 6] = [5, 10, 20, 40, 80, 160];

/// One stage: every group to `targets` (translation) and `angles`, the pressures to
/// `pressure` and gravity to `gravity`, linearly over `steps` communication steps.
#[derive(Clone, Debug)]
struct Stage {
    targets: Vec<[f64; 3]>,
    angles: Vec<f64>,
    pressure: Vec<f64>,
    /// Nodal forces of each force set (`None`: kept).
    force: Option<Vec<[f64; 3]>>,
    gravity: [f64; 3],
    steps: usize,
}

/// One stage without pressures to `targets`, `angles` and `gravity` in `steps` steps.
fn single(targets: Vec<[f64; 3]>, angles: Vec<f64>, gravity: [f64; 3], steps: usize) -> Vec<Stage> {
    vec![Stage {
        targets,
        angles,
        pressure: vec![],
        force: None,
        gravity,
        steps,
    }]
}

#[derive(Clone, Debug)]
struct HeldOut {
    family: &'static str,
    name: String,
    model: Value,
    stages: Vec<Stage>,
}

/// A film on a structured grid `nx × ny` cells over `[0, lx] × [0, ly]` at height `z`; interior
/// nodes off the columns in `keep` jittered in plane by up to `jitter` of a cell.
struct Grid {
    nx: usize,
    ny: usize,
    nodes: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
}

impl Grid {
    fn new(
        lx: f64,
        ly: f64,
        (nx, ny): (usize, usize),
        z: f64,
        keep: &[usize],
        jitter: f64,
        r: &mut Random,
    ) -> Self {
        let (dx, dy) = (lx / nx as f64, ly / ny as f64);
        let mut nodes = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                let inner = i > 0 && i < nx && j > 0 && j < ny && !keep.contains(&i);
                let (ex, ey) = if inner {
                    (r.uniform(-jitter, jitter), r.uniform(-jitter, jitter))
                } else {
                    (0.0, 0.0)
                };
                nodes.push([(i as f64 + ex) * dx, (j as f64 + ey) * dy, z]);
            }
        }
        let id = |i: usize, j: usize| j * (nx + 1) + i;
        let mut triangles = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if (i + j) % 2 == 0 {
                    triangles.extend([[a, b, c], [a, c, d]]);
                } else {
                    triangles.extend([[a, b, d], [b, c, d]]);
                }
            }
        }
        Self {
            nx,
            ny,
            nodes,
            triangles,
        }
    }
    fn id(&self, i: usize, j: usize) -> usize {
        j * (self.nx + 1) + i
    }
    fn column(&self, i: usize) -> Vec<usize> {
        (0..=self.ny).map(|j| self.id(i, j)).collect()
    }
}

fn material(prestress: [f64; 2], wrinkling: Option<&str>, density: Option<f64>) -> Value {
    let mut m = json!({
        "youngs_modulus": 800e6, "poisson_ratio": 0.45, "thickness": 250e-6,
        "prestress": [prestress[0], prestress[1], 0.0],
    });
    if let Some(w) = wrinkling {
        m["wrinkling"] = json!(w);
    }
    if let Some(d) = density {
        m["density"] = json!(d);
    }
    m
}

/// A panel over `arches` tube arches along y with rails on the short edges `railW` (x = 0) and
/// `railE` (x = lx, optionally with a hinge about its bottom line): the model and its grid.
struct Panel {
    model: Value,
    lx: f64,
}

fn panel(r: &mut Random, arches: usize, prestress: [f64; 2], wrinkling: Option<&str>) -> Panel {
    let lx = r.uniform(2.0, 5.0);
    let ly = r.uniform(1.5, 3.0);
    let per = r.int(2, 4); // cells between arches
    let nx = per * (arches + 1);
    let ny = r.int(8, 14);
    let rise = r.uniform(0.1, 0.35).min(0.3 * ly);
    let tube = r.pick(&[0.02, 0.03, 0.05]);
    let columns: Vec<usize> = (1..=arches).map(|k| k * per).collect();
    let grid = Grid::new(lx, ly, (nx, ny), rise + tube, &columns, 0.15, r);
    let mu = r.uniform(0.0, 0.5);
    let law = r.pick(&["isotropic", "sliding-direction"]);
    let kn = 1000.0 * 800e6 * 250e-6 * r.pick(&[0.1, 1.0]);
    let supports: Vec<Value> = columns
        .iter()
        .enumerate()
        .map(|(k, &i)| {
            let x = i as f64 * lx / nx as f64;
            json!({
                "name": format!("tube{}", k + 1),
                "centreline": {"parabola": {"apex": [x, ly / 2.0, rise], "up": [0, 0, 1],
                    "along": [0, 1, 0], "half_span": ly / 2.0, "rise": rise}},
                "tube_radius": tube, "nodes": grid.column(i),
                "normal_stiffness": kn, "tangential_stiffness": 0.1 * kn,
                "friction": mu, "friction_law": law,
            })
        })
        .collect();
    let mut east = json!({"name": "railE", "nodes": grid.column(nx), "target": [0, 0, 0]});
    if r.chance(0.3) {
        east["hinge"] = json!({"point": [lx, 0.0, rise + tube], "axis": [0, 1, 0]});
    }
    let model = json!({
        "name": "HeldOutPanel",
        "nodes": grid.nodes, "triangles": grid.triangles,
        "material": material(prestress, wrinkling, None),
        "groups": [{"name": "railW", "nodes": grid.column(0), "target": [0, 0, 0]}, east],
        "curved_supports": supports,
        "loads": {"pressures": [{"name": "wind", "elements": "all", "pressure": 0.0, "towards": "+z"}]},
    });
    Panel { model, lx }
}

/// Whether the model's group `g` has a hinge.
fn hinged(model: &Value, g: usize) -> bool {
    model["groups"][g].get("hinge").is_some()
}

/// Stages lowering both rails by `drop` (m), each moved in x by `shift` (m, positive inward),
/// the hinged one also turned by `angle`, in `stages` stages of `steps` steps each.
fn lowering(
    model: &Value,
    drop: f64,
    shift: f64,
    angle: f64,
    stages: usize,
    steps: usize,
) -> Vec<Stage> {
    (1..=stages)
        .map(|k| {
            let f = k as f64 / stages as f64;
            Stage {
                targets: vec![[shift * f, 0.0, -drop * f], [-shift * f, 0.0, -drop * f]],
                angles: vec![0.0, if hinged(model, 1) { angle * f } else { 0.0 }],
                pressure: vec![0.0],
                force: None,
                gravity: [0.0; 3],
                steps,
            }
        })
        .collect()
}

fn arches_family(r: &mut Random, count: usize) -> Vec<HeldOut> {
    (0..count)
        .map(|k| {
            let arches = 1 + k % 4;
            let p1 = r.uniform(0.5e6, 3e6);
            let p2 = if r.chance(0.5) { p1 } else { r.uniform(0.5e6, 3e6) };
            let wrinkling = r.pick(&[None, Some("tension-field")]);
            let pnl = panel(r, arches, [p1, p2], wrinkling);
            let drop = r.uniform(0.1, 0.4);
            let shift = r.uniform(-0.01, 0.03) * pnl.lx;
            let angle = r.uniform(-0.12, 0.12);
            let stages = r.int(1, 3);
            let steps = (r.pick(&STEP_COUNTS) / stages).max(2);
            let stages_list = lowering(&pnl.model, drop, shift, angle, stages, steps);
            HeldOut {
                family: "arches",
                name: format!(
                    "arches#{k} n={arches} pre=({:.1},{:.1})MPa {} drop={drop:.2} shift={shift:.3} angle={angle:.3} {stages}x{steps}",
                    p1 / 1e6,
                    p2 / 1e6,
                    wrinkling.unwrap_or("default")
                ),
                model: pnl.model,
                stages: stages_list,
            }
        })
        .collect()
}

fn reversal_family(r: &mut Random, count: usize) -> Vec<HeldOut> {
    (0..count)
        .map(|k| {
            let arches = 1 + (k + 2) % 4;
            let p = r.uniform(0.5e6, 3e6);
            let wrinkling = r.pick(&[None, Some("tension-field")]);
            let pnl = panel(r, arches, [p, p], wrinkling);
            let drop = r.uniform(0.1, 0.35);
            let steps = r.pick(&STEP_COUNTS[..4]);
            let mut stages = lowering(&pnl.model, drop, 0.0, 0.0, 1, steps);
            let last = stages[0].clone();
            let wind = r.uniform(100.0, 600.0);
            for level in [wind, -wind, wind, 0.0] {
                stages.push(Stage {
                    pressure: vec![level],
                    steps: r.int(2, 8),
                    ..last.clone()
                });
            }
            HeldOut {
                family: "reversal",
                name: format!(
                    "reversal#{k} n={arches} pre={:.1}MPa {} drop={drop:.2} wind=±{wind:.0}Pa steps={steps}",
                    p / 1e6,
                    wrinkling.unwrap_or("default")
                ),
                model: pnl.model,
                stages,
            }
        })
        .collect()
}

fn slack_family(r: &mut Random, count: usize) -> Vec<HeldOut> {
    let g = [0.0, 0.0, -9.81];
    (0..count)
        .map(|k| {
            let wrinkling = r.pick(&[None, Some("tension-field")]);
            let steps = r.pick(&STEP_COUNTS);
            let w = wrinkling.unwrap_or("default");
            match k % 3 {
                0 => {
                    // a clamped rectangle under its own weight
                    let (lx, ly) = (r.uniform(0.5, 2.0), r.uniform(0.5, 2.0));
                    let (nx, ny) = (r.int(6, 14), r.int(6, 14));
                    let grid = Grid::new(lx, ly, (nx, ny), 0.0, &[], 0.2, r);
                    let mut rim = Vec::new();
                    for j in 0..=ny {
                        for i in 0..=nx {
                            if i == 0 || j == 0 || i == nx || j == ny {
                                rim.push(grid.id(i, j));
                            }
                        }
                    }
                    let density = r.uniform(500.0, 3000.0);
                    HeldOut {
                        family: "slack",
                        name: format!("slack#{k} rectangle {lx:.2}x{ly:.2} m self-weight ρ={density:.0} {w} steps={steps}"),
                        model: json!({
                            "name": "HeldOutSlackRectangle",
                            "nodes": grid.nodes, "triangles": grid.triangles,
                            "material": material([0.0, 0.0], wrinkling, Some(density)),
                            "groups": [{"name": "rim", "nodes": rim, "target": [0, 0, 0]}],
                        }),
                        stages: single(vec![[0.0; 3]], vec![0.0], g, steps),
                    }
                }
                1 => {
                    // a strip lifted along a cross line
                    let (lx, ly) = (r.uniform(1.0, 3.0), r.uniform(0.05, 0.4));
                    let (nx, ny) = (2 * r.int(5, 15), r.int(1, 3));
                    let grid = Grid::new(lx, ly, (nx, ny), 0.0, &[], 0.0, r);
                    let at = r.int(nx / 4, 3 * nx / 4);
                    let mut ends = grid.column(0);
                    ends.extend(grid.column(nx));
                    let lift = r.uniform(0.02, 0.12) * lx;
                    HeldOut {
                        family: "slack",
                        name: format!("slack#{k} strip {lx:.2} m lifted {lift:.3} m at column {at}/{nx} {w} steps={steps}"),
                        model: json!({
                            "name": "HeldOutSlackStrip",
                            "nodes": grid.nodes, "triangles": grid.triangles,
                            "material": material([0.0, 0.0], wrinkling, None),
                            "groups": [{"name": "ends", "nodes": ends, "target": [0, 0, 0]},
                                       {"name": "lift", "nodes": grid.column(at), "target": [0, 0, 0]}],
                        }),
                        stages: single(vec![[0.0; 3], [0.0, 0.0, lift]], vec![0.0, 0.0], [0.0; 3], steps),
                    }
                }
                _ => {
                    // an unstressed panel lowered onto its arches
                    let arches = r.int(1, 4);
                    let pnl = panel(r, arches, [0.0, 0.0], wrinkling);
                    let drop = r.uniform(0.1, 0.3);
                    let shift = r.uniform(0.0, 0.02) * pnl.lx;
                    HeldOut {
                        family: "slack",
                        name: format!("slack#{k} panel n={arches} unstressed drop={drop:.2} shift={shift:.3} {w} steps={steps}"),
                        stages: lowering(&pnl.model, drop, shift, 0.0, 1, steps),
                        model: pnl.model,
                    }
                }
            }
        })
        .collect()
}

/// The 3 m × 2 m panel over two arches at x = 1, 2 m (rise 0.2 m), clamped at x = 0, its edge
/// x = 3 m turned about a hinge along its bottom line by the angle that lowers it 0.2 m.
fn hinged_arch_panel(wrinkling: Option<&str>, steps: usize) -> HeldOut {
    let mut r = Random(7);
    let grid = Grid::new(3.0, 2.0, (30, 24), 0.2, &[10, 20], 0.0, &mut r);
    let kn = 1000.0 * 800e6 * 250e-6;
    let supports: Vec<Value> = [10, 20]
        .iter()
        .enumerate()
        .map(|(k, &i)| {
            json!({
                "name": format!("arch{}", k + 1),
                "centreline": {"parabola": {"apex": [i as f64 / 10.0, 1.0, 0.2], "up": [0, 0, 1],
                    "along": [0, 1, 0], "half_span": 0.75, "rise": 0.2}},
                "tube_radius": 0.001, "nodes": grid.column(i).into_iter()
                    .filter(|&n| (grid.nodes[n][1] - 1.0).abs() <= 0.75 + 1e-9).collect::<Vec<_>>(),
                "normal_stiffness": kn, "tangential_stiffness": 0.1 * kn, "friction": 0.2,
            })
        })
        .collect();
    // the hinge axis along x through the corner y = 0 of the edge x = 3: the edge turns down
    let model = json!({
        "name": "HeldOutHingedPanel",
        "nodes": grid.nodes.iter().map(|p| [p[0], p[1], p[2] + 0.001]).collect::<Vec<_>>(),
        "triangles": grid.triangles,
        "material": material([0.5e6, 0.5e6], wrinkling, None),
        "supports": grid.column(0).into_iter().map(|n| json!({"node": n, "fixed": ["x", "y", "z"]}))
            .collect::<Vec<_>>(),
        "groups": [{"name": "rail", "nodes": grid.column(30), "target": [0, 0, 0],
                    "hinge": {"point": [3.0, 0.0, 0.201], "axis": [1, 0, 0]}}],
        "curved_supports": supports,
    });
    let angle = -(0.2f64 / 2.0).asin();
    HeldOut {
        family: "steps",
        name: format!(
            "steps hinged arch panel {} steps={steps}",
            wrinkling.unwrap_or("default")
        ),
        model,
        stages: single(vec![[0.0; 3]], vec![angle], [0.0; 3], steps),
    }
}

fn steps_family() -> Vec<HeldOut> {
    let mut out = Vec::new();
    for steps in STEP_COUNTS {
        out.push(hinged_arch_panel(None, steps));
        out.push(hinged_arch_panel(Some("tension-field"), steps));
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/hinged_panel.json"
        ))
        .expect("examples/hinged_panel.json");
        let model: Value = serde_json::from_str(&text).expect("the example parses");
        let hinge = &model["groups"][0]["hinge"];
        let gravity = model["loads"]["gravity"]
            .as_array()
            .map_or([0.0, 0.0, -9.81], |g| {
                std::array::from_fn(|c| g[c].as_f64().unwrap())
            });
        let target: [f64; 3] =
            std::array::from_fn(|c| model["groups"][0]["target"][c].as_f64().unwrap_or(0.0));
        out.push(HeldOut {
            family: "steps",
            name: format!("steps examples/hinged_panel.json steps={steps}"),
            stages: vec![Stage {
                targets: vec![target],
                angles: vec![hinge["target_angle"].as_f64().unwrap_or(0.0)],
                pressure: model["loads"]["pressures"].as_array().map_or(vec![], |a| {
                    a.iter()
                        .map(|p| p["pressure"].as_f64().unwrap_or(0.0))
                        .collect()
                }),
                force: model["loads"]["forces"].as_array().map(|a| {
                    a.iter()
                        .map(|f| std::array::from_fn(|c| f["force"][c].as_f64().unwrap_or(0.0)))
                        .collect()
                }),
                gravity,
                steps,
            }],
            model,
        });
    }
    out
}

/// Every path of the set, in a fixed order.
/// The seed of the held-out set (`--seed` draws another set from the same generator).
const SEED: u64 = 0x1915_2026;

fn held_out_set(seed: u64) -> Vec<HeldOut> {
    let mut r = Random(seed);
    let mut set = arches_family(&mut r, 40);
    set.extend(reversal_family(&mut r, 24));
    set.extend(slack_family(&mut r, 30));
    set.extend(steps_family());
    set
}

#[derive(Clone, Debug, Default)]
struct Outcome {
    steps_done: usize,
    steps: usize,
    iterations: usize,
    increments: usize,
    max_increment: usize,
    cutbacks: usize,
    /// Increments solved with the viscous stabilization on.
    stabilized: usize,
    /// Steps whose artificial energy left exceeds `STABILIZATION_BOUND` of the strain energy.
    over_bound: usize,
    seconds: f64,
    error: Option<String>,
    /// Per row of the strategy table, then the step-end release rounds: increments converged,
    /// their iterations, increments refused, their iterations.
    by_row: [[usize; 4]; ROWS],
}

/// The rows of [`Outcome::by_row`]: the strategy table's and the release rounds'.
const ROWS: usize = STRATEGIES.len() + 1;

impl Outcome {
    /// Adds a converged step's attempts to [`Self::by_row`].
    fn add_attempts(&mut self, report: &StepReport) {
        for a in &report.attempts {
            let row = if a.from == 1.0 && a.to == 1.0 {
                ROWS - 1
            } else {
                a.strategy
            };
            let k = if a.converged { 0 } else { 2 };
            self.by_row[row][k] += 1;
            self.by_row[row][k + 1] += a.iterations;
        }
    }
}

/// Prints the iterations spent per row of the strategy table, converged and refused.
fn print_rows(results: &[Outcome]) {
    println!(
        "\n| row | increments converged | their iterations | refused | their iterations |\n|---|---|---|---|---|"
    );
    for row in 0..ROWS {
        let sum = |k: usize| results.iter().map(|r| r.by_row[row][k]).sum::<usize>();
        let name = STRATEGIES.get(row).map_or("step-end release", |s| s.name);
        println!(
            "| {name} | {} | {} | {} | {} |",
            sum(0),
            sum(1),
            sum(2),
            sum(3)
        );
    }
}

fn run(path: &HeldOut, increments: usize) -> Outcome {
    let start = Instant::now();
    let mut o = Outcome {
        steps: path.stages.iter().map(|s| s.steps).sum(),
        ..Outcome::default()
    };
    let model = match Model::from_json(&path.model.to_string()) {
        Ok(m) => m,
        Err(e) => {
            o.error = Some(format!("model refused: {e}"));
            return o;
        }
    };
    let mut analysis = match Analysis::new(model, SolverSettings::default()) {
        Ok(a) => a,
        Err(e) => {
            o.error = Some(format!("setup: {e}"));
            return o;
        }
    };
    if std::env::var_os("HELDOUT_LOG_INCREMENTS").is_some() {
        let name = path.name.clone();
        analysis.observe_increments(membrane_contact::mech::solve::IncrementObserver::new(
            move |note| eprintln!("{name}: {note}"),
        ));
    }
    'stages: for stage in &path.stages {
        let s = analysis.state().clone();
        let target_loads = LoadLevels {
            pressure: stage.pressure.clone(),
            force: stage.force.clone().unwrap_or_else(|| s.loads.force.clone()),
            gravity: stage.gravity,
            chambers: vec![],
            heating: vec![],
            air: vec![],
            time: 0.0,
        };
        for k in 1..=stage.steps {
            let f = k as f64 / stage.steps as f64;
            let lerp = |a: f64, b: f64| a + (b - a) * f;
            let targets: Vec<[f64; 3]> = s
                .boundary
                .iter()
                .zip(&stage.targets)
                .map(|(a, b)| std::array::from_fn(|c| lerp(a[c], b[c])))
                .collect();
            let angles: Vec<f64> = s
                .angles
                .iter()
                .zip(&stage.angles)
                .map(|(a, b)| lerp(*a, *b))
                .collect();
            let loads = s.loads.interpolate(&target_loads, f);
            match analysis.step_to_motion(&targets, &angles, &loads, increments) {
                Ok(report) => {
                    o.steps_done += 1;
                    o.iterations += report.total_iterations();
                    o.increments += report.iterations.len();
                    o.cutbacks += report.cutbacks;
                    o.stabilized += report.stabilized;
                    o.add_attempts(&report);
                    o.over_bound += usize::from(
                        report.stabilization_warning().is_some()
                            || report.dissipation_ratio() > 1.0,
                    );
                    o.max_increment = o
                        .max_increment
                        .max(report.iterations.iter().copied().max().unwrap_or(0));
                }
                Err(e) => {
                    o.error = Some(format!("step {}/{}: {e}", o.steps_done + 1, o.steps));
                    break 'stages;
                }
            }
        }
    }
    o.seconds = start.elapsed().as_secs_f64();
    o
}

const FAMILIES: [&str; 4] = ["arches", "reversal", "slack", "steps"];

fn main() {
    let (mut list, mut write, mut names) = (false, None, Vec::<String>::new());
    let mut advice = false;
    let mut seed = SEED;
    let o = PathOptions::parse(&FAMILIES, |flag, rest| match flag {
        "--name" => {
            names.push(rest.next().ok_or("--name needs a text")?);
            Ok(true)
        }
        "--list" => {
            list = true;
            Ok(true)
        }
        "--advice" => {
            advice = true;
            Ok(true)
        }
        "--write" => {
            write = Some(rest.next().ok_or("--write needs a directory")?);
            Ok(true)
        }
        "--seed" => {
            let text = rest.next().ok_or("--seed needs a number")?;
            seed = text.parse().map_err(|e| format!("--seed {text}: {e}"))?;
            Ok(true)
        }
        _ => Ok(false),
    });
    let o = o.unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2);
    });
    let increments = usize::try_from(DEFAULT_INCREMENTS_PER_STEP).unwrap();
    let stride = if o.quick { 5 } else { 1 };
    let set = held_out_set(seed);
    let paths: Vec<HeldOut> = o
        .families
        .iter()
        .flat_map(|f| {
            set.iter()
                .filter(|p| p.family == f.as_str())
                .filter(|p| names.is_empty() || names.iter().any(|n| p.name.contains(n.as_str())))
                .step_by(stride)
                .cloned()
                .collect::<Vec<_>>()
        })
        .collect();
    if list {
        for p in &paths {
            println!("{}", p.name);
        }
        return;
    }
    if let Some(dir) = &write {
        std::fs::create_dir_all(dir).expect("--write: the directory");
        for (k, p) in paths.iter().enumerate() {
            let file = format!("{dir}/{}_{k}.json", p.family);
            std::fs::write(&file, p.model.to_string()).expect("--write: a file");
            let stages: Vec<Value> = p
                .stages
                .iter()
                .map(|s| {
                    json!({"targets": s.targets, "angles": s.angles, "pressure": s.pressure,
                        "force": s.force, "gravity": s.gravity, "steps": s.steps})
                })
                .collect();
            let staged = format!("{dir}/{}_{k}.stages.json", p.family);
            std::fs::write(&staged, Value::from(stages).to_string()).expect("--write: a file");
            println!("{file}: {}", p.name);
        }
        return;
    }
    println!(
        "## held-out robustness: {} load paths, default solver settings, {increments} increments per step, {} threads\n",
        paths.len(),
        o.threads
    );
    let wall = Instant::now();
    let results = on_threads(&paths, o.threads, |p| run(p, increments));
    let wall = wall.elapsed().as_secs_f64();
    println!(
        "| family | paths | converged | % | iterations / increment (mean) | max per increment | cut-backs | steps converged | path s | first failure |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    // Per family: converged paths, those with every step within the stabilization bound, and
    // the increments solved with the viscous stabilization on (printed after the table).
    let mut bound_rows = Vec::new();
    let mut total = (0, 0, 0, 0, 0, 0.0);
    for f in &o.families {
        let sel: Vec<(&HeldOut, &Outcome)> = paths
            .iter()
            .zip(&results)
            .filter(|(p, _)| p.family == f.as_str())
            .collect();
        let n = sel.len();
        let ok = sel.iter().filter(|(_, r)| r.error.is_none()).count();
        let plain = sel
            .iter()
            .filter(|(_, r)| r.error.is_none() && r.over_bound == 0)
            .count();
        let stabilized: usize = sel.iter().map(|(_, r)| r.stabilized).sum();
        let it: usize = sel.iter().map(|(_, r)| r.iterations).sum();
        let inc: usize = sel.iter().map(|(_, r)| r.increments).sum();
        let cut: usize = sel.iter().map(|(_, r)| r.cutbacks).sum();
        let max = sel.iter().map(|(_, r)| r.max_increment).max().unwrap_or(0);
        let done: usize = sel.iter().map(|(_, r)| r.steps_done).sum();
        let all: usize = sel.iter().map(|(_, r)| r.steps).sum();
        let cpu: f64 = sel.iter().map(|(_, r)| r.seconds).sum();
        let first = sel
            .iter()
            .find_map(|(p, r)| r.error.as_ref().map(|e| format!("{}: {e}", p.name)))
            .unwrap_or_else(|| "–".into());
        let mut first_short = String::new();
        let _ = write!(
            first_short,
            "{}",
            first
                .chars()
                .take(400)
                .collect::<String>()
                .replace('|', "/")
        );
        println!(
            "| {f} | {n} | {ok} | {:.1} | {:.2} | {max} | {cut} | {done}/{all} | {cpu:.1} | {first_short} |",
            100.0 * ok as f64 / n.max(1) as f64,
            it as f64 / inc.max(1) as f64
        );
        bound_rows.push(format!("| {f} | {ok} | {plain} | {stabilized} |"));
        total = (
            total.0 + n,
            total.1 + ok,
            total.2 + it,
            total.3 + inc,
            total.4 + cut,
            total.5 + cpu,
        );
    }
    println!(
        "\n| family | converged | of them every step within the stabilization bound | increments viscously stabilized |\n|---|---|---|---|"
    );
    for row in &bound_rows {
        println!("{row}");
    }
    print_rows(&results);
    let over: Vec<String> = paths
        .iter()
        .zip(&results)
        .filter(|(_, r)| r.error.is_none() && r.over_bound > 0)
        .map(|(p, r)| format!("{} ({} steps)", p.name, r.over_bound))
        .collect();
    if !over.is_empty() {
        println!(
            "\nconverged with steps above the stabilization bound: {}",
            over.join(", ")
        );
    }
    let failed: Vec<(String, String)> = paths
        .iter()
        .zip(&results)
        .filter_map(|(p, r)| r.error.clone().map(|e| (p.name.clone(), e)))
        .collect();
    if !failed.is_empty() {
        println!("\n| refusal class | paths | of them |\n|---|---|---|");
        for class in CLASSES {
            let of: Vec<&str> = failed
                .iter()
                .filter(|(_, e)| failure_class(e) == class)
                .map(|(n, _)| n.split(' ').next().unwrap_or(n))
                .collect();
            if !of.is_empty() {
                println!("| {class} | {} | {} |", of.len(), of.join(", "));
            }
        }
    }
    o.finish(total, 1, wall, &failed);
    if advice && !failed.is_empty() {
        follow_advice(&paths, &results, increments, o.threads);
    }
}

/// A path changed as a refusal advises, its increments per step and what was changed.
type Advised = (HeldOut, usize, String);

/// The change a refusal's advice names, applied to its path (`--advice`): the isotropic law
/// on the supports of the named sliding-direction contacts, otherwise four times the
/// increments per step ("move the inputs by less per step"). `None` where the advice names
/// nothing to apply.
fn advised(path: &HeldOut, message: &str, increments: usize) -> Option<Advised> {
    if failure_class(message) == CLASSES[1] {
        let named = message
            .split("lifting off with more than μN across: ")
            .nth(1)?
            .split([')', ';'])
            .next()?;
        let supports: Vec<&str> = named
            .split(", ")
            .filter_map(|c| c.rsplit_once('.').map(|(s, _)| s))
            .collect();
        let mut changed = path.clone();
        let list = changed.model.get_mut("curved_supports")?.as_array_mut()?;
        let mut count = 0;
        for s in list.iter_mut() {
            if supports.iter().any(|n| s["name"] == *n) {
                s["friction_law"] = json!("isotropic");
                count += 1;
            }
        }
        (count > 0).then(|| {
            (
                changed,
                increments,
                format!("isotropic law on {count} supports"),
            )
        })
    } else if message.contains("raise the increments per step") {
        Some((
            path.clone(),
            4 * increments,
            format!("{} increments per step", 4 * increments),
        ))
    } else {
        None
    }
}

/// Runs every refused path again with the change its refusal advises ([`advised`]) and prints,
/// per refusal class, how many then converge: the advice measured on the cases that produced it
/// (issue 19 item 3).
fn follow_advice(paths: &[HeldOut], results: &[Outcome], increments: usize, threads: usize) {
    let tries: Vec<(&str, &str, Option<Advised>)> = paths
        .iter()
        .zip(results)
        .filter_map(|(p, r)| {
            let e = r.error.as_deref()?;
            Some((failure_class(e), p.name.as_str(), advised(p, e, increments)))
        })
        .collect();
    let outcomes = on_threads(&tries, threads, |(_, _, t)| {
        t.as_ref().map(|(path, n, _)| run(path, *n))
    });
    println!(
        "\n### The refusals' advice followed\n\n| refusal class | refused | advice applied | converged after it | of them |\n|---|---|---|---|---|"
    );
    for class in CLASSES {
        let rows: Vec<usize> = (0..tries.len()).filter(|&i| tries[i].0 == class).collect();
        if rows.is_empty() {
            continue;
        }
        let applied = rows.iter().filter(|&&i| tries[i].2.is_some()).count();
        let gained: Vec<&str> = rows
            .iter()
            .filter(|&&i| outcomes[i].as_ref().is_some_and(|o| o.error.is_none()))
            .map(|&i| tries[i].1.split(' ').next().unwrap_or(tries[i].1))
            .collect();
        println!(
            "| {class} | {} | {applied} | {} | {} |",
            rows.len(),
            gained.len(),
            gained.join(", ")
        );
    }
    for (i, (_, name, t)) in tries.iter().enumerate() {
        let what = t
            .as_ref()
            .map_or("nothing to apply", |(_, _, w)| w.as_str());
        let result = match &outcomes[i] {
            Some(o) => o.error.as_deref().unwrap_or("converged").to_string(),
            None => "–".into(),
        };
        println!(
            "- {name} ({what}): {}",
            result.chars().take(300).collect::<String>()
        );
    }
}

/// The refusal classes of [`failure_class`], in table order.
const CLASSES: [&str; 10] = [
    "singular matrix",
    "sliding-direction lift-off",
    "contact status chatter",
    "wrinkling-state flips",
    "linear film in compression",
    "stall, forces balanced",
    "stall",
    "iteration limit",
    "film did not settle under the damping",
    "diverged or other",
];

/// The class of a refusal from its message: the first of these that it reports (a stall that
/// names chattering gaps is chatter, one that names compressed elements is compression).
fn failure_class(message: &str) -> &'static str {
    if message.contains("singular Newton matrix") {
        CLASSES[0]
    } else if message.contains("lifting off with more than μN across") {
        CLASSES[1]
    } else if message.contains("contacts changing status") {
        CLASSES[2]
    } else if message.contains("changing wrinkling state") {
        CLASSES[3]
    } else if message.contains("in compression") {
        CLASSES[4]
    } else if message.contains("no progress") && message.contains("the residual met its tolerance")
    {
        CLASSES[5]
    } else if message.contains("no progress") {
        CLASSES[6]
    } else if message.contains("iteration limit") {
        CLASSES[7]
    } else if message.contains("the film did not settle") {
        CLASSES[8]
    } else {
        CLASSES[9]
    }
}
