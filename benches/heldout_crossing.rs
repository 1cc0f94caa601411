//! Third held-out robustness set (`cargo bench --bench heldout_crossing`, issue 41): films over
//! two families of **crossing** supports, from a generator of its own, written and committed
//! before any tuning against it. Neither `benches/heldout.rs` (parallel arches) nor
//! `benches/robustness.rs` (the scenarios the solver's heuristics were tuned on) has a film
//! meeting supports that cross. Every model is written as a model file (JSON, read by
//! [`Model::from_json`] as a user's file is, which validates it) and runs with the default
//! solver settings and the FMU's default increments per step, one `step_to_motion` per
//! communication step as the FMU does. The table gives per family how many paths converge,
//! Newton iterations per increment, cut-backs, the time and the first failure; a second table
//! the steps whose `stabilization_ratio()` is above `STABILIZATION_BOUND`.
//!
//! It reads only the public API that is expected to outlive the solver's internals:
//! `Model::from_json`, `Analysis::new`, `SolverSettings::default()`, `Analysis::state`,
//! `LoadLevels`, `step_to_motion`, and of the `StepReport` its `iterations`, `cutbacks` and
//! `stabilization_ratio()`.
//!
//! # Families (seeded: the same paths on every run)
//!
//! * **grid** (30 paths): a panel 2–4.5 m × 1.5–3.5 m (structured grid, 3–5 cells between
//!   x-arches, 3–7 between y-tubes, fewer where it would pass 600 triangles; interior nodes off
//!   the supports jittered by up to 0.15 of a cell) over 1–3 parabolic tube arches along x (rise 0.1–0.4 m, half-span
//!   0.55–0.75 of the panel's length, so they reach past the rails) and 1–3 tubes along y,
//!   straight or arched (rise 0.03–0.2 m), their tops 0–0.08 m above the x-arches where they
//!   cross them; tube radius 0.015–0.05 m; μ 0–0.6, either friction law, per family of
//!   supports; normal penalty 2e7 or 2e8 N/m; prestress 0.5–3 MPa (not always equal both ways)
//!   or none (one path in four); linear (`"none"`) or tension-field film. The rails on the
//!   edges x = 0 and x = lx are lowered (30–90 % of the clearance to the arches at the rails),
//!   moved (in x: −2 % … +3 % of lx each, in y: up to ±5 % of ly, shearing the panel) and, with a
//!   hinge on the east rail in half of the paths, turned (a twist about x through its middle,
//!   within the clearance, or a yaw of ±0.04 rad about z), each action over its own run of 1–3
//!   stages; 5, 10, 20, 40 or 80 steps in all.
//! * **saddle** (10): a hypar-like panel 1.5–3 m square-ish (≤ 512 triangles), held only at its
//!   four corners by groups (a corner triangle of six nodes each), over a single crossing pair
//!   of tubes (along x through its middle and along y through its middle, each straight or
//!   arched, their tops 0.01–0.1 m apart); the panel is lowered by 0.02–0.15 m, then (or at
//!   once) two opposite corners raised by 0.05–0.3 m and the other two lowered as much;
//!   prestress 0.5–3 MPa (none in one path in five); 5–40 steps.
//! * **snow-suction** (12): a grid panel (1–2 arches along x, 1–2 tubes along y) lowered onto its
//!   crossing supports, then a follower pressure towards −z cycled: snow 200–1200 Pa down,
//!   suction 200–1000 Pa up, released; self-weight (ρ 1750 kg/m³, g −9.81 m/s²) in half of
//!   them; 5–20 steps lowering, 2–10 steps each load stage.
//! * **plastic** (8): a grid panel (1–2 arches, 1–2 tubes) of the elasto-plastic film
//!   (`material.plasticity`, ETFE-like hardening from 14–18 MPa initial yield, temperature
//!   10–40 °C in half of them) lowered onto its supports, then its rails pulled apart by
//!   2–5 % of lx each (4–10 % nominal strain, past first yield at about 2 %), half of them then
//!   moved back in by half of that; 10–40 steps in all.
//!
//! Options (after `--`): `--family NAME` (repeatable), `--quick` (every 5th path),
//! `--name TEXT` (only the paths whose name contains TEXT; repeatable: any of them),
//! `--failures` (every failed path), `--threads N`, `--check` (exit 1 unless every path run
//! converges), `--list` (the paths and their sizes, validated, not run), `--write DIR` (the model
//! files and, beside each, its stages as `*.stages.json`, not run), `--seed N` (another set from
//! the same generator).
//!
//! Every model is validated before anything runs: a model that fails to validate is a bug of
//! this generator, reported as such (exit status 3), never counted as a solver failure.

use std::time::Instant;

use membrane_contact::fmi2::variables::DEFAULT_INCREMENTS_PER_STEP;
use membrane_contact::mech::solve::report::STABILIZATION_BOUND;
use membrane_contact::mech::{Analysis, LoadLevels, Model, SolverSettings};
use serde_json::{Value, json};

#[path = "common/options.rs"]
#[allow(dead_code)] // `finish` prints the total row last; this bench prints its own
mod options;
use options::{PathOptions, on_threads};

/// xorshift64* seeded through a splitmix64 scramble: deterministic, so the set is the same on
/// every run (a generator of its own, not heldout.rs's).
struct Draw(u64);

impl Draw {
    fn new(seed: u64) -> Self {
        let mut z = seed ^ 0xD1B5_4A32_D192_ED03;
        z = (z ^ (z >> 33)).wrapping_mul(0xFF51_AFD7_ED55_8CCD);
        z = (z ^ (z >> 33)).wrapping_mul(0xC4CE_B9FE_1A85_EC53);
        Self((z ^ (z >> 33)) | 1)
    }
    fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in `[a, b)`.
    fn real(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform integer in `a..=b`.
    fn int(&mut self, a: usize, b: usize) -> usize {
        a + (self.next() % (b - a + 1) as u64) as usize
    }
    fn one_of<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.int(0, items.len() - 1)]
    }
    fn coin(&mut self, p: f64) -> bool {
        self.real(0.0, 1.0) < p
    }
}

/// One stage: every group to `targets` (translation) and `angles`, the pressures to
/// `pressure` and gravity to `gravity`, linearly over `steps` communication steps.
#[derive(Clone, Debug)]
struct Stage {
    targets: Vec<[f64; 3]>,
    angles: Vec<f64>,
    pressure: Vec<f64>,
    gravity: [f64; 3],
    steps: usize,
}

#[derive(Clone, Debug)]
struct Path {
    family: &'static str,
    name: String,
    model: Value,
    stages: Vec<Stage>,
}

/// A structured `nx × ny` film over `[0, lx] × [0, ly]` at height `z`; interior nodes off the
/// rows `rows` and columns `cols` (those on supports) jittered in plane by up to `jitter` of a
/// cell.
struct Mesh {
    nx: usize,
    ny: usize,
    dx: f64,
    dy: f64,
    nodes: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
}

impl Mesh {
    #[allow(clippy::too_many_arguments)]
    fn new(
        (lx, ly): (f64, f64),
        (nx, ny): (usize, usize),
        z: f64,
        rows: &[usize],
        cols: &[usize],
        jitter: f64,
        d: &mut Draw,
    ) -> Self {
        let (dx, dy) = (lx / nx as f64, ly / ny as f64);
        let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            for i in 0..=nx {
                let free =
                    i > 0 && i < nx && j > 0 && j < ny && !rows.contains(&j) && !cols.contains(&i);
                let (ex, ey) = if free {
                    (d.real(-jitter, jitter), d.real(-jitter, jitter))
                } else {
                    (0.0, 0.0)
                };
                nodes.push([(i as f64 + ex) * dx, (j as f64 + ey) * dy, z]);
            }
        }
        let id = |i: usize, j: usize| j * (nx + 1) + i;
        let mut triangles = Vec::with_capacity(2 * nx * ny);
        // diagonals alternating in a union-jack pattern (every quad split towards its
        // panel-centre corner), unlike heldout.rs's checkerboard
        for j in 0..ny {
            for i in 0..nx {
                let (a, b, c, e) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if (2 * i + 1 < nx) == (2 * j + 1 < ny) {
                    triangles.extend([[a, b, c], [a, c, e]]);
                } else {
                    triangles.extend([[a, b, e], [b, c, e]]);
                }
            }
        }
        Self {
            nx,
            ny,
            dx,
            dy,
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
    /// Row `j` without the nodes of the columns in `skip`.
    fn row_without(&self, j: usize, skip: &[usize]) -> Vec<usize> {
        (0..=self.nx)
            .filter(|i| !skip.contains(i))
            .map(|i| self.id(i, j))
            .collect()
    }
    /// Column `i` without the nodes in `skip`.
    fn column_without(&self, i: usize, skip: &[usize]) -> Vec<usize> {
        self.column(i)
            .into_iter()
            .filter(|n| !skip.contains(n))
            .collect()
    }
}

/// ETFE film: `E` 800 MPa, ν 0.45, 250 µm; `prestress` (Pa) in x and y, the wrinkling entry and
/// an optional density.
fn film(prestress: [f64; 2], wrinkling: &str, density: Option<f64>) -> Value {
    let mut m = json!({
        "youngs_modulus": 800e6, "poisson_ratio": 0.45, "thickness": 250e-6,
        "prestress": [prestress[0], prestress[1], 0.0], "wrinkling": wrinkling,
    });
    if let Some(rho) = density {
        m["density"] = json!(rho);
    }
    m
}

/// A tube's contact data: penalties from `kn`, friction `mu` under `law`.
fn tube(name: String, centreline: Value, radius: f64, nodes: Vec<usize>, c: &Contact) -> Value {
    json!({
        "name": name, "centreline": centreline, "tube_radius": radius, "nodes": nodes,
        "normal_stiffness": c.kn, "tangential_stiffness": 0.1 * c.kn,
        "friction": c.mu, "friction_law": c.law,
    })
}

#[derive(Clone, Copy)]
struct Contact {
    kn: f64,
    mu: f64,
    law: &'static str,
}

fn contact(d: &mut Draw) -> Contact {
    Contact {
        kn: 1000.0 * 800e6 * 250e-6 * d.one_of(&[0.1, 1.0]),
        mu: d.real(0.0, 0.6),
        law: d.one_of(&["isotropic", "sliding-direction"]),
    }
}

/// A panel between rails on its edges x = 0 (`railW`) and x = lx (`railE`, optionally hinged)
/// over `along_x` parabolic arches along x and `along_y` tubes along y (straight or arched).
struct Crossing {
    model: Value,
    lx: f64,
    ly: f64,
    /// Height of the film above the highest tube top, and of the x-arches' tops at the rails:
    /// the rails may go down by less than `clearance` without passing under an arch.
    clearance: f64,
    /// Whether the east rail has a hinge, and about which axis (`'x'` twist, `'z'` yaw).
    hinge: Option<char>,
    triangles: usize,
    summary: String,
}

struct CrossingSpec {
    along_x: usize,
    along_y: usize,
    prestress: [f64; 2],
    wrinkling: &'static str,
    density: Option<f64>,
    plasticity: Option<Value>,
    hinge: bool,
    /// A follower pressure set `snow` towards −z on every triangle.
    pressure: bool,
}

fn crossing(d: &mut Draw, s: &CrossingSpec) -> Crossing {
    let lx = d.real(2.0, 4.5);
    let ly = d.real(1.5, 3.5);
    let per_y = d.int(3, 5);
    let ny = per_y * (s.along_x + 1);
    let per_x = d.int(3, 7);
    let mut nx = per_x * (s.along_y + 1);
    while nx * ny > 300 && nx > s.along_y + 1 {
        nx -= s.along_y + 1;
    }
    let per_x = nx / (s.along_y + 1);
    let rows: Vec<usize> = (1..=s.along_x).map(|k| k * per_y).collect();
    let cols: Vec<usize> = (1..=s.along_y).map(|k| k * per_x).collect();
    // x-arches: crown at x = lx/2, height `ha`; half-span `la` beyond the rails
    let ha = d.real(0.1, 0.4);
    let la = d.real(0.55, 0.75) * lx;
    let arch_x = |x: f64| ha * (1.0 - ((x - lx / 2.0) / la).powi(2));
    let ra: f64 = d.one_of(&[0.015, 0.025, 0.05]);
    let rb: f64 = d.one_of(&[0.015, 0.025, 0.05]);
    // y-tubes: their tops 0–0.08 m above the x-arches where they cross them
    let straight = d.coin(0.5);
    let hb = d.real(0.03, 0.2);
    let lb = d.real(0.55, 0.8) * ly;
    let tops: Vec<f64> = cols
        .iter()
        .map(|&i| {
            let y_top = arch_x(i as f64 * lx / nx as f64) + d.real(0.0, 0.08);
            // an arched tube is lower away from its crown: raise its crown so that it still
            // crosses above the x-arches near them
            if straight { y_top } else { y_top + 0.5 * hb }
        })
        .collect();
    let top = tops.iter().copied().fold(ha, f64::max);
    let gap = d.real(0.0, 0.02);
    let z = top + ra.max(rb) + gap;
    let mesh = Mesh::new((lx, ly), (nx, ny), z, &rows, &cols, 0.15, d);
    let ca = contact(d);
    let cb = contact(d);
    let rails = [0, nx];
    let mut supports = Vec::new();
    for (k, &j) in rows.iter().enumerate() {
        let y = j as f64 * mesh.dy;
        supports.push(tube(
            format!("archX{}", k + 1),
            json!({"parabola": {"apex": [lx / 2.0, y, ha], "up": [0, 0, 1], "along": [1, 0, 0],
                "half_span": la, "rise": ha}}),
            ra,
            mesh.row_without(j, &rails),
            &ca,
        ));
    }
    for (k, &i) in cols.iter().enumerate() {
        let x = i as f64 * mesh.dx;
        let centreline = if straight {
            json!({"line": {"point": [x, 0.0, tops[k]], "axis": [0, 1, 0]}})
        } else {
            json!({"parabola": {"apex": [x, ly / 2.0, tops[k]], "up": [0, 0, 1],
                "along": [0, 1, 0], "half_span": lb, "rise": hb}})
        };
        supports.push(tube(
            format!("tubeY{}", k + 1),
            centreline,
            rb,
            mesh.column(i),
            &cb,
        ));
    }
    let hinge = s.hinge.then(|| d.one_of(&['x', 'z']));
    let mut east = json!({"name": "railE", "nodes": mesh.column(nx), "target": [0, 0, 0]});
    if let Some(axis) = hinge {
        let a = if axis == 'x' { [1, 0, 0] } else { [0, 0, 1] };
        east["hinge"] = json!({"point": [lx, ly / 2.0, z], "axis": a});
    }
    let mut material = film(s.prestress, s.wrinkling, s.density);
    if let Some(p) = &s.plasticity {
        for (k, v) in p.as_object().unwrap() {
            material[k] = v.clone();
        }
    }
    let mut model = json!({
        "name": "HeldOutCrossing",
        "nodes": mesh.nodes, "triangles": mesh.triangles,
        "material": material,
        "groups": [{"name": "railW", "nodes": mesh.column(0), "target": [0, 0, 0]}, east],
        "curved_supports": supports,
        "outputs": {"points": [{"name": "centre", "node": mesh.id(nx / 2, ny / 2)}],
                    "element_sets": [{"name": "film", "elements": "all"}]},
    });
    if s.pressure {
        model["loads"] = json!({"pressures": [{"name": "snow", "elements": "all",
            "pressure": 0.0, "towards": "-z"}]});
    }
    let summary = format!(
        "{lx:.2}x{ly:.2}m {}x{} X-arches={} rise={ha:.2} μ={:.2} {} Y-{}={} μ={:.2} {}",
        nx,
        ny,
        s.along_x,
        ca.mu,
        short(ca.law),
        if straight { "lines" } else { "arches" },
        s.along_y,
        cb.mu,
        short(cb.law)
    );
    Crossing {
        model,
        lx,
        ly,
        clearance: z - ra - arch_x(0.0),
        hinge,
        triangles: 2 * nx * ny,
        summary,
    }
}

fn short(law: &str) -> &'static str {
    if law == "isotropic" { "iso" } else { "slide" }
}

/// The rails' motion: drop (both), x shift (positive inward) and y shift per rail, the east
/// rail's angle.
#[derive(Clone, Copy, Default)]
struct RailMotion {
    drop: f64,
    shift_x: [f64; 2],
    shift_y: [f64; 2],
    angle: f64,
}

/// Each action of the rails' motion runs over its own stages: the fraction of it done by the
/// end of stage `k` of `n`, for an action from stage `from` to stage `to` (0 ≤ from < to ≤ n).
fn fraction(k: usize, from: usize, to: usize) -> f64 {
    ((k as f64 - from as f64) / (to - from) as f64).clamp(0.0, 1.0)
}

fn rail_targets(m: &RailMotion, f: [f64; 3]) -> (Vec<[f64; 3]>, Vec<f64>) {
    let [fd, fs, fa] = f;
    (
        vec![
            [m.shift_x[0] * fs, m.shift_y[0] * fs, -m.drop * fd],
            [-m.shift_x[1] * fs, m.shift_y[1] * fs, -m.drop * fd],
        ],
        vec![0.0, m.angle * fa],
    )
}

/// Random wrinkling entry: the linear film or the tension-field film.
fn wrinkling(d: &mut Draw) -> &'static str {
    d.one_of(&["none", "tension-field"])
}

fn prestress(d: &mut Draw, none: f64) -> [f64; 2] {
    if d.coin(none) {
        return [0.0, 0.0];
    }
    let p1 = d.real(0.5e6, 3e6);
    let p2 = if d.coin(0.5) { p1 } else { d.real(0.5e6, 3e6) };
    [p1, p2]
}

fn grid_family(d: &mut Draw, count: usize) -> Vec<Path> {
    (0..count)
        .map(|k| {
            let pre = prestress(d, 0.25);
            let w = wrinkling(d);
            let spec = CrossingSpec {
                along_x: d.int(1, 3),
                along_y: d.int(1, 3),
                prestress: pre,
                wrinkling: w,
                density: None,
                plasticity: None,
                hinge: d.coin(0.5),
                pressure: false,
            };
            let c = crossing(d, &spec);
            let stages = d.int(1, 3);
            let total: usize = d.one_of(&[5, 10, 20, 40, 80]);
            let steps = total.div_ceil(stages).max(2);
            let drop = d.real(0.3, 0.9) * c.clearance;
            let mut m = RailMotion {
                drop,
                ..RailMotion::default()
            };
            if d.coin(0.7) {
                m.shift_x = [d.real(-0.02, 0.03) * c.lx, d.real(-0.02, 0.03) * c.lx];
            }
            if d.coin(0.4) {
                m.shift_y = [d.real(-0.05, 0.05) * c.ly, d.real(-0.05, 0.05) * c.ly];
            }
            match c.hinge {
                // a twist within what the drop left of the clearance at the rail's ends
                Some('x') => {
                    let room = 0.9 * (c.clearance - drop) / (c.ly / 2.0);
                    m.angle = d.real(-1.0, 1.0) * room.min(0.15).asin();
                }
                Some(_) => m.angle = d.real(-0.04, 0.04),
                None => {}
            }
            // the drop from stage 0 to some stage, the moves and the turn over their own runs
            let drop_to = d.int(1, stages);
            let move_from = d.int(0, stages - 1);
            let turn_from = d.int(0, stages - 1);
            let list: Vec<Stage> = (1..=stages)
                .map(|s| {
                    let (targets, angles) = rail_targets(
                        &m,
                        [
                            fraction(s, 0, drop_to),
                            fraction(s, move_from, stages),
                            fraction(s, turn_from, stages),
                        ],
                    );
                    Stage {
                        targets,
                        angles,
                        pressure: vec![],
                        gravity: [0.0; 3],
                        steps,
                    }
                })
                .collect();
            Path {
                family: "grid",
                name: format!(
                    "grid#{k} {} tri={} pre=({:.1},{:.1})MPa {w} drop={:.3} sx=({:.3},{:.3}) sy=({:.3},{:.3}) turn={} {stages}x{steps}",
                    c.summary,
                    c.triangles,
                    pre[0] / 1e6,
                    pre[1] / 1e6,
                    m.drop,
                    m.shift_x[0],
                    m.shift_x[1],
                    m.shift_y[0],
                    m.shift_y[1],
                    c.hinge.map_or("none".into(), |a| format!("{a}{:.3}", m.angle)),
                ),
                model: c.model,
                stages: list,
            }
        })
        .collect()
}

fn saddle_family(d: &mut Draw, count: usize) -> Vec<Path> {
    (0..count)
        .map(|k| {
            let (lx, ly) = (d.real(1.5, 3.0), d.real(1.5, 3.0));
            let nx = 2 * d.int(4, 8);
            let ny = 2 * d.int(4, 8);
            let (im, jm) = (nx / 2, ny / 2);
            // the two tubes through the middle, their tops `sep` apart, either one higher
            let sep = d.real(0.01, 0.1);
            let x_higher = d.coin(0.5);
            let (top_x, top_y) = if x_higher { (0.0, -sep) } else { (-sep, 0.0) };
            let r = d.one_of(&[0.015, 0.025, 0.05]);
            let z = r + d.real(0.0, 0.01);
            let mesh = Mesh::new((lx, ly), (nx, ny), z, &[jm], &[im], 0.15, d);
            // corner groups: the corner's six nodes i + j ≤ 2 counted from it
            let corner = |ci: usize, cj: usize| -> Vec<usize> {
                let mut v = Vec::new();
                for a in 0..=2usize {
                    for b in 0..=(2 - a) {
                        let i = if ci == 0 { a } else { nx - a };
                        let j = if cj == 0 { b } else { ny - b };
                        v.push(mesh.id(i, j));
                    }
                }
                v
            };
            let corners = [corner(0, 0), corner(nx, 0), corner(nx, ny), corner(0, ny)];
            let held: Vec<usize> = corners.iter().flatten().copied().collect();
            let cx = contact(d);
            let cy = contact(d);
            let arched_x = d.coin(0.5);
            let arched_y = d.coin(0.5);
            let line_or_arch = |arched: bool, top: f64, along: [f64; 3], half: f64, d: &mut Draw| {
                let apex = [lx / 2.0, ly / 2.0, top];
                if arched {
                    let rise = d.real(0.05, 0.3);
                    json!({"parabola": {"apex": apex, "up": [0, 0, 1], "along": along,
                        "half_span": half * d.real(1.05, 1.4), "rise": rise}})
                } else {
                    json!({"line": {"point": apex, "axis": along}})
                }
            };
            let supports = vec![
                tube(
                    "tubeX".into(),
                    line_or_arch(arched_x, top_x, [1.0, 0.0, 0.0], lx / 2.0, d),
                    r,
                    mesh.row_without(jm, &[])
                        .into_iter()
                        .filter(|n| !held.contains(n))
                        .collect(),
                    &cx,
                ),
                tube(
                    "tubeY".into(),
                    line_or_arch(arched_y, top_y, [0.0, 1.0, 0.0], ly / 2.0, d),
                    r,
                    mesh.column_without(im, &held),
                    &cy,
                ),
            ];
            let pre = prestress(d, 0.2);
            let w = wrinkling(d);
            let names = ["SW", "SE", "NE", "NW"];
            let groups: Vec<Value> = corners
                .iter()
                .zip(names)
                .map(|(nodes, n)| json!({"name": n, "nodes": nodes, "target": [0, 0, 0]}))
                .collect();
            let model = json!({
                "name": "HeldOutSaddle",
                "nodes": mesh.nodes, "triangles": mesh.triangles,
                "material": film(pre, w, None),
                "groups": groups,
                "curved_supports": supports,
                "outputs": {"points": [{"name": "centre", "node": mesh.id(im, jm)}],
                            "element_sets": [{"name": "film", "elements": "all"}]},
            });
            let lower = d.real(0.02, 0.15);
            let warp = d.real(0.05, 0.3);
            let total = d.one_of(&[5, 10, 20, 40]);
            let staged = d.coin(0.5);
            // SW and NE raised, SE and NW lowered
            let warped = |f: f64| -> Vec<[f64; 3]> {
                [1.0, -1.0, 1.0, -1.0]
                    .iter()
                    .map(|s| [0.0, 0.0, -lower + s * warp * f])
                    .collect()
            };
            let stage = |targets, steps| Stage {
                targets,
                angles: vec![0.0; 4],
                pressure: vec![],
                gravity: [0.0; 3],
                steps,
            };
            let stages = if staged {
                let first = (total / 3).max(2);
                vec![
                    stage(warped(0.0), first),
                    stage(warped(1.0), (total - first).max(2)),
                ]
            } else {
                vec![stage(warped(1.0), total)]
            };
            Path {
                family: "saddle",
                name: format!(
                    "saddle#{k} {lx:.2}x{ly:.2}m {nx}x{ny} tri={} X-{} μ={:.2} {} Y-{} μ={:.2} {} {}-higher by {sep:.3} pre=({:.1},{:.1})MPa {w} lower={lower:.3} warp=±{warp:.3} {}",
                    2 * nx * ny,
                    if arched_x { "arch" } else { "line" },
                    cx.mu,
                    short(cx.law),
                    if arched_y { "arch" } else { "line" },
                    cy.mu,
                    short(cy.law),
                    if x_higher { "X" } else { "Y" },
                    pre[0] / 1e6,
                    pre[1] / 1e6,
                    stages
                        .iter()
                        .map(|s| s.steps.to_string())
                        .collect::<Vec<_>>()
                        .join("+")
                ),
                model,
                stages,
            }
        })
        .collect()
}

fn snow_suction_family(d: &mut Draw, count: usize) -> Vec<Path> {
    (0..count)
        .map(|k| {
            let pre = prestress(d, 0.15);
            let w = wrinkling(d);
            let weight = d.coin(0.5);
            let spec = CrossingSpec {
                along_x: d.int(1, 2),
                along_y: d.int(1, 2),
                prestress: pre,
                wrinkling: w,
                density: weight.then_some(1750.0),
                plasticity: None,
                hinge: false,
                pressure: true,
            };
            let c = crossing(d, &spec);
            let m = RailMotion {
                drop: d.real(0.4, 0.9) * c.clearance,
                shift_x: if d.coin(0.5) {
                    [d.real(0.0, 0.02) * c.lx; 2]
                } else {
                    [0.0; 2]
                },
                ..RailMotion::default()
            };
            let g = if weight { [0.0, 0.0, -9.81] } else { [0.0; 3] };
            let (targets, angles) = rail_targets(&m, [1.0; 3]);
            let lowering = d.one_of(&[5, 10, 20]);
            let snow = d.real(200.0, 1200.0);
            let suction = d.real(200.0, 1000.0);
            let mut stages = vec![Stage {
                targets,
                angles,
                pressure: vec![0.0],
                gravity: g,
                steps: lowering,
            }];
            let mut counts = vec![lowering.to_string()];
            for level in [snow, -suction, 0.0] {
                let steps = d.int(2, 10);
                counts.push(steps.to_string());
                stages.push(Stage {
                    pressure: vec![level],
                    steps,
                    ..stages[0].clone()
                });
            }
            Path {
                family: "snow-suction",
                name: format!(
                    "snow-suction#{k} {} tri={} pre=({:.1},{:.1})MPa {w} drop={:.3} snow={snow:.0}Pa suction={suction:.0}Pa {} steps={}",
                    c.summary,
                    c.triangles,
                    pre[0] / 1e6,
                    pre[1] / 1e6,
                    m.drop,
                    if weight { "self-weight" } else { "weightless" },
                    counts.join("+")
                ),
                model: c.model,
                stages,
            }
        })
        .collect()
}

fn plastic_family(d: &mut Draw, count: usize) -> Vec<Path> {
    (0..count)
        .map(|k| {
            let yield_stress = d.real(14e6, 18e6);
            let hardening = json!([
                [0.0, yield_stress],
                [0.02, yield_stress * 1.2],
                [0.15, yield_stress * 1.5],
                [1.0, yield_stress * 2.5]
            ]);
            let mut plasticity = json!({"plasticity": {"hardening": hardening}});
            let temperature = d.coin(0.5).then(|| d.real(10.0, 40.0));
            if let Some(t) = temperature {
                plasticity["temperature"] = json!(t);
            }
            let pre = prestress(d, 0.25);
            let w = wrinkling(d);
            let spec = CrossingSpec {
                along_x: d.int(1, 2),
                along_y: d.int(1, 2),
                prestress: pre,
                wrinkling: w,
                density: None,
                plasticity: Some(plasticity),
                hinge: false,
                pressure: false,
            };
            let c = crossing(d, &spec);
            let drop = d.real(0.3, 0.8) * c.clearance;
            let pull = d.real(0.02, 0.05) * c.lx;
            let back = d.coin(0.5);
            let total = d.one_of(&[10, 20, 40]);
            let n = if back { 3 } else { 2 };
            let steps = (total / n).max(2);
            let at = |sx: f64| Stage {
                targets: vec![[-sx, 0.0, -drop], [sx, 0.0, -drop]],
                angles: vec![0.0, 0.0],
                pressure: vec![],
                gravity: [0.0; 3],
                steps,
            };
            let mut stages = vec![at(0.0), at(pull)];
            if back {
                stages.push(at(0.5 * pull));
            }
            Path {
                family: "plastic",
                name: format!(
                    "plastic#{k} {} tri={} σy={:.1}MPa T={} pre=({:.1},{:.1})MPa {w} drop={drop:.3} pull={pull:.3}{} {n}x{steps}",
                    c.summary,
                    c.triangles,
                    yield_stress / 1e6,
                    temperature.map_or("23".into(), |t| format!("{t:.0}")),
                    pre[0] / 1e6,
                    pre[1] / 1e6,
                    if back { " then back by half" } else { "" }
                ),
                model: c.model,
                stages,
            }
        })
        .collect()
}

/// The seed of the set (`--seed` draws another set from the same generator).
const SEED: u64 = 0x4_1C20_55ED;

/// Every path of the set, in a fixed order (each family from its own stream, so that a family's
/// paths do not depend on the others').
fn crossing_set(seed: u64) -> Vec<Path> {
    let mut set = grid_family(&mut Draw::new(seed), 30);
    set.extend(saddle_family(&mut Draw::new(seed.wrapping_add(1)), 10));
    set.extend(snow_suction_family(
        &mut Draw::new(seed.wrapping_add(2)),
        12,
    ));
    set.extend(plastic_family(&mut Draw::new(seed.wrapping_add(3)), 8));
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
    /// Steps whose `stabilization_ratio()` is above `STABILIZATION_BOUND`.
    over_bound: usize,
    /// The largest `stabilization_ratio()` of a step.
    max_ratio: f64,
    seconds: f64,
    error: Option<String>,
}

fn run(path: &Path, increments: usize) -> Outcome {
    let start = Instant::now();
    let mut o = Outcome {
        steps: path.stages.iter().map(|s| s.steps).sum(),
        ..Outcome::default()
    };
    let model = Model::from_json(&path.model.to_string()).expect("validated before the run");
    let mut analysis = match Analysis::new(model, SolverSettings::default()) {
        Ok(a) => a,
        Err(e) => {
            o.error = Some(format!("setup: {e}"));
            o.seconds = start.elapsed().as_secs_f64();
            return o;
        }
    };
    'stages: for stage in &path.stages {
        let s = analysis.state().clone();
        let target = LoadLevels {
            pressure: stage.pressure.clone(),
            force: s.loads.force.clone(),
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
            let loads = s.loads.interpolate(&target, f);
            match analysis.step_to_motion(&targets, &angles, &loads, increments) {
                Ok(report) => {
                    o.steps_done += 1;
                    o.iterations += report.iterations.iter().sum::<usize>();
                    o.increments += report.iterations.len();
                    o.cutbacks += report.cutbacks;
                    o.max_increment = o
                        .max_increment
                        .max(report.iterations.iter().copied().max().unwrap_or(0));
                    let ratio = report.stabilization_ratio();
                    o.over_bound += usize::from(ratio > STABILIZATION_BOUND);
                    o.max_ratio = o.max_ratio.max(ratio);
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

const FAMILIES: [&str; 4] = ["grid", "saddle", "snow-suction", "plastic"];

fn main() {
    let (mut list, mut write, mut names) = (false, None, Vec::<String>::new());
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
    let set = crossing_set(seed);
    let paths: Vec<Path> = o
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
    // a model that does not validate is this generator's bug, not a solver failure
    let refused: Vec<String> = paths
        .iter()
        .filter_map(|p| {
            Model::from_json(&p.model.to_string())
                .err()
                .map(|e| format!("{}: {e}", p.name))
        })
        .collect();
    if list {
        for p in &paths {
            println!("{}", p.name);
        }
        println!(
            "\n{} paths, {} refused by validation",
            paths.len(),
            refused.len()
        );
    }
    if !refused.is_empty() {
        eprintln!("generator bug: models that do not validate:");
        for r in &refused {
            eprintln!("- {r}");
        }
        std::process::exit(3);
    }
    if list {
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
                        "gravity": s.gravity, "steps": s.steps})
                })
                .collect();
            let staged = format!("{dir}/{}_{k}.stages.json", p.family);
            std::fs::write(&staged, Value::from(stages).to_string()).expect("--write: a file");
            println!("{file}: {}", p.name);
        }
        return;
    }
    println!(
        "## held-out crossing supports (seed {seed}): {} load paths, default solver settings, {increments} increments per step, {} threads\n",
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
    let mut bound_rows = Vec::new();
    let mut total = (0, 0, 0, 0, 0, 0.0);
    for f in &o.families {
        let sel: Vec<(&Path, &Outcome)> = paths
            .iter()
            .zip(&results)
            .filter(|(p, _)| p.family == f.as_str())
            .collect();
        let n = sel.len();
        if n == 0 {
            continue; // a family left out by --name
        }
        let ok = sel.iter().filter(|(_, r)| r.error.is_none()).count();
        let within = sel
            .iter()
            .filter(|(_, r)| r.error.is_none() && r.over_bound == 0)
            .count();
        let over: usize = sel.iter().map(|(_, r)| r.over_bound).sum();
        let largest = sel.iter().map(|(_, r)| r.max_ratio).fold(0.0, f64::max);
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
            .unwrap_or_else(|| "–".into())
            .chars()
            .take(400)
            .collect::<String>()
            .replace('|', "/");
        println!(
            "| {f} | {n} | {ok} | {:.1} | {:.2} | {max} | {cut} | {done}/{all} | {cpu:.1} | {first} |",
            100.0 * ok as f64 / n.max(1) as f64,
            it as f64 / inc.max(1) as f64
        );
        bound_rows.push(format!(
            "| {f} | {ok} | {within} | {over} | {largest:.2e} |"
        ));
        total = (
            total.0 + n,
            total.1 + ok,
            total.2 + it,
            total.3 + inc,
            total.4 + cut,
            total.5 + cpu,
        );
    }
    // the total row under the family table (options.rs's `finish` prints it last)
    println!(
        "| **total** | {} | {} | {:.1} | {:.2} | | {} | | {:.1} | |",
        total.0,
        total.1,
        100.0 * total.1 as f64 / total.0.max(1) as f64,
        total.2 as f64 / total.3.max(1) as f64,
        total.4,
        total.5
    );
    println!(
        "\n| family | converged | of them every step within the stabilization bound ({STABILIZATION_BOUND:.0e}) | steps above the bound | largest stabilization ratio |\n|---|---|---|---|---|"
    );
    for row in &bound_rows {
        println!("{row}");
    }
    let over: Vec<String> = paths
        .iter()
        .zip(&results)
        .filter(|(_, r)| r.over_bound > 0)
        .map(|(p, r)| {
            let id = p.name.split(' ').next().unwrap_or(&p.name);
            format!("{id} ({} steps, largest {:.2e})", r.over_bound, r.max_ratio)
        })
        .collect();
    if !over.is_empty() {
        println!("\nsteps above the stabilization bound: {}", over.join(", "));
    }
    let failed: Vec<(String, String)> = paths
        .iter()
        .zip(&results)
        .filter_map(|(p, r)| r.error.clone().map(|e| (p.name.clone(), e)))
        .collect();
    o.conclude((total.0, total.1), wall, &failed);
}
