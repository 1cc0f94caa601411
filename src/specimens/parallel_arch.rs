//! The paper's parallel-steel-arch specimens (§4), as a 1/4 model generator.
//!
//! # Assumptions (the one place they are written)
//!
//! The paper's Figs. 2–5 (dimensions, mesh, measured boundary movements) and its ref. [6] are
//! not available. Every number below is therefore an assumption; each has its source or reason.
//!
//! | quantity | value | source / reason |
//! |---|---|---|
//! | film `E` | 1.0 GPa | ETFE data sheets give 0.8–1.1 GPa (Galliot & Luchsinger 2011; AGC/etferoof sheets: ≈1100 MPa); round value |
//! | film `ν` | 0.43 | literature range 0.42–0.45 for ETFE foil |
//! | film thickness `t` | 250 µm | the foil of Kawabata's published uniaxial tests (MSAJ seminar 2012); Taiyo Kogyo 250 µm ≈ 440 g/m² |
//! | prestress `σ0` | 0.5 MPa isotropic | the film is laid flat and fixed hand-tight; a small tension (≈2.5 % of the 21 MPa first yield) also gives a flat membrane its out-of-plane stiffness |
//! | `k_n` | `1000 · E · t` (N/m) | §4.4 "three orders higher than the ETFE film", read as the film's membrane stiffness `E·t` |
//! | `k_s` | `0.1 · k_n` | §4.4 (S.H. Lee's recommendation; Nastran PGAP `KT ≥ 0.1 KA`) |
//! | `μ` | 0.2 | §4.4, Asahi Glass technical report [8] |
//! | friction law | isotropic Coulomb cone (default); `friction_law: sliding-direction` gives the paper's own law | §2.2, §4.3–4.4 slide along the arch (local x) only; the default stays the cone so that earlier results and figures are unchanged — ask for the paper's law to reproduce the paper |
//! | arch span | 1.6 m (half span 0.8 m) | assumed; rises 200/300/400 mm give span/rise 8, 5.3, 4 |
//! | arch spacing | 0.8 m (arches at `x = ±0.4 m`) | assumed |
//! | outside frame | 2.0 m × 2.0 m (1/4 model 1.0 m × 1.0 m) | assumed; the frame is 0.2 m beyond the arch feet |
//! | film start position | flat at the crown height `z = H` | §4.1: the flat film is put on the arches and the frame |
//! | forced displacement | frame lowered in `Z` to `dz = −H/2` | §4.1 gives only "in Z step by step until the target"; lowering by half the rise keeps the film strain near the ≈2 % of the measured slips (21 mm over 0.8 m for 300 mm). Peak von Mises stress at the target: 14.7 MPa (200 mm), 32.6 MPa (300 mm, 22 of 200 elements above ETFE's ≈21 MPa first yield, next to the crown), 57.9 MPa (400 mm): like the paper's, the linear-elastic film is beyond its range there. Only `G1…G4` touch the arch at this target |
//! | frame in-plane movement | none (`dx = dy = 0`) | the measured X/Y movements of ref. [6] are not available; they are FMU inputs |
//! | crown-to-foot reconstruction (`frame_path: wrapped`, issue 10 item 3) | every frame node follows the film **wrapped over the arch to its foot and extended by `ε`** ([`FramePath::Wrapped`]): at stage `t` the film's line over the arch follows the arch circle to the angle `t·θ_foot` and leaves it along its tangent; first half: a frame node of flat position `(X, Y)` is at arc length `Y` along that line (`t·θ_foot` grows to the foot); second half: the boundary is extended, arc length `(1 + e) Y` and `x = X + e (X − x_arch)` beyond the arch line (`e` grows to `ε`; the film between the arches is not pulled across the pipes, whose contact nodes would otherwise slide `0.4 ε` sideways off a 24 mm pipe); one boundary group per frame node (`node<k>`), as the paper drives its nodes 1*–31* one by one with the movements measured in [6] | the paper's §1, §4.1 "extending the boundary", §4.2 nodes 1*–31*; [6] is not available, so the path is built from the geometry: it keeps the film taut (prestress plus `tε` both ways) at every stage for a frictionless film, touches the arch from crown to foot at the end (every observed point in contact), lowers the `Y = 1` frame edge below the foot, and has one unknown, the boundary extension `ε` (no default: the comparison is made at several values and `ε` is identified from Table 1 and reported as such). The wrapped specimens use the **tension-field film** (`wrinkling: tension-field`): while the film is wound, the film between the arch and the frame is briefly compressed; a foil wrinkles there, and the linear film of the paper buckles numerically (Newton stalls in the first step of 10- or 20-step paths; with the tension-field film they converge). At the end the film is in biaxial tension and the two laws agree |
//! | mesh | 10 × 10 cells × refinement, each cell two triangles: 200 triangles, 121 nodes | §4.2 gives 200 triangles |
//! | forced-displacement nodes | 21 (both outer edges) | the paper's 31 cannot come from a 200-triangle structured mesh held on its two outer edges (`nx·ny = 100` and `nx + ny = 30` has no integer solution); without its Fig. 4 we keep the structured mesh |
//! | gaps `G1…G9` | film nodes on the arch line `x = 0.4`, `y = 0, 0.1, …, 0.8` (crown to foot); support = the fixed arch point on the radius through the node; `g0` = the initial distance | §4.2, §4.3 |
//! | gap frame | `z` from the arch centre to the contact point, `x` = arch tangent towards the foot, `y = z × x` | §4.3 |
//! | observed points 1–5 | `G1` (crown) and `G2, G4, G6, G8` | §4.4 maps points 2–5 to `G2, G4, G6, G8`; point 1 reads 0 at the crown |
//! | contact model | the paper's fixed-frame gaps (default); `contact: curved-support` puts the same nine film nodes in node-to-surface contact with the arch itself (`mech/elements/curved_contact`): a ring of radius `R − r_p` about the arch's axis with a tube of radius `r_p`, so that its outer surface is the arch line the gaps use; slip is then the arc length along the arch | §4.3–4.4 and the conclusions name the fixed frames as the model's limit; issue 10 |
//! | pipe radius `r_p` | 24.3 mm | the arches are steel pipes of unknown size; 48.6 mm is the common Japanese structural/scaffold tube (JIS G 3444 STK400 φ48.6); only the curved-support model uses it (the gaps see the arch line) |

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::mech::elements::curved_contact::{Centreline, CurvedSupport};
use crate::mech::elements::gap::{FrictionLaw, GapFrame};
use crate::mech::elements::material::{DEFAULT_WRINKLING_REGULARISATION, Material, Wrinkling};
use crate::mech::elements::plasticity::{Plasticity, etfe_datasheet_hardening};
use crate::mech::model::{Axis, BoundaryGroup, GapSpec, GapSupport, Model, Symmetry};

/// Measured sliding along the arch at the final step (mm), the paper's Table 1 (points 1–5).
pub const TABLE1_CSV: &str = include_str!("../../data/table1_sliding.csv");

/// Gap names of the observed points 1–5 (§4.4).
pub const OBSERVED_GAPS: [&str; 5] = ["G1", "G2", "G4", "G6", "G8"];

/// Parameters of a parallel-arch specimen; [`Default`] holds the documented assumptions.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ParallelArch {
    /// Arch rise `H` (m): 0.2, 0.3, 0.4 in the paper.
    pub arch_height: f64,
    /// Half span of each arch (m).
    pub arch_half_span: f64,
    /// Distance of each arch from the centre line, half the arch spacing (m).
    pub arch_offset: f64,
    /// Half size of the outside frame in X (m).
    pub frame_half_x: f64,
    /// Half size of the outside frame in Y (m).
    pub frame_half_y: f64,
    /// Film material.
    pub material: Material,
    /// `k_n / (E t)`.
    pub normal_penalty_factor: f64,
    /// `k_s / k_n`.
    pub tangential_penalty_ratio: f64,
    /// Friction coefficient `μ`.
    pub friction: f64,
    /// Friction law of every gap (the paper's is [`FrictionLaw::SlidingDirection`]).
    pub friction_law: FrictionLaw,
    /// Target frame displacement in Z as a multiple of `H` (negative: lowered).
    pub target_dz_per_height: f64,
    /// Mesh refinement factor (1 gives the paper's 200 triangles).
    pub refinement: usize,
    /// Contact model between film and arch.
    pub contact: SpecimenContact,
    /// Radius of the arch pipes (m), for [`SpecimenContact::CurvedSupport`].
    pub pipe_radius: f64,
    /// How the frame moves from the flat film to the target.
    pub frame_path: FramePath,
}

/// How the frame moves the film's boundary (the paper's measured movements, ref. [6], are not
/// available; see the assumptions table).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub enum FramePath {
    /// The whole frame lowered in Z to `target_dz_per_height · H` (one group, `frame`).
    #[default]
    Lowered,
    /// Every frame node follows the film wrapped over the arch from crown to foot and extended
    /// by `extension` (a strain, both directions): one group per frame node, `node<k>`.
    Wrapped {
        /// The boundary extension `ε` reached at the end (≥ 0, at most 0.1).
        extension: f64,
    },
}

/// How the film touches the arch in a specimen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpecimenContact {
    /// The paper's nine node-to-point gap elements with fixed frames (§4.2–4.3).
    #[default]
    Gaps,
    /// The same nine film nodes in node-to-surface contact with the arch pipe (`mech/elements/curved_contact`).
    CurvedSupport,
}

impl std::str::FromStr for SpecimenContact {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "gaps" => Ok(Self::Gaps),
            "curved-support" | "curved" => Ok(Self::CurvedSupport),
            other => Err(format!(
                "unknown contact model '{other}' (gaps or curved-support)"
            )),
        }
    }
}

impl Default for ParallelArch {
    fn default() -> Self {
        Self {
            arch_height: 0.3,
            arch_half_span: 0.8,
            arch_offset: 0.4,
            frame_half_x: 1.0,
            frame_half_y: 1.0,
            material: Material {
                youngs_modulus: 1.0e9,
                poisson_ratio: 0.43,
                thickness: 250e-6,
                prestress: [0.5e6, 0.5e6, 0.0],
                density: 0.0,
                wrinkling: Wrinkling::None,
                wrinkling_regularisation: DEFAULT_WRINKLING_REGULARISATION,
                yield_stress: None,
                plasticity: None,
                temperature: 23.0,
            },
            normal_penalty_factor: 1000.0,
            tangential_penalty_ratio: 0.1,
            friction: 0.2,
            friction_law: FrictionLaw::Isotropic,
            target_dz_per_height: -0.5,
            refinement: 1,
            contact: SpecimenContact::Gaps,
            pipe_radius: 0.0243,
            frame_path: FramePath::Lowered,
        }
    }
}

/// `material` with ETFE's elasto-plastic behaviour: finite-strain J2 with the documented data-sheet
/// curve at 23 °C (`docs/mechanics.md` "Plastic film"); everything else unchanged.
pub fn etfe_plastic(material: Material) -> Material {
    Material {
        plasticity: Some(Plasticity {
            hardening: etfe_datasheet_hardening(),
        }),
        ..material
    }
}

/// Number of gap elements along the half arch.
pub const GAP_COUNT: usize = 9;

/// The specimen model's name, hence the built-in FMU's model identifier (`ParallelArch.fmu`).
pub const MODEL_NAME: &str = "ParallelArch";
const CELLS: usize = 10;

impl ParallelArch {
    /// The default specimen with arch rise `height` (m).
    pub fn with_height(height: f64) -> Self {
        Self {
            arch_height: height,
            ..Self::default()
        }
    }

    /// Arch radius `R = (H² + (S/2)²) / 2H`.
    pub fn arch_radius(&self) -> f64 {
        (self.arch_height.powi(2) + self.arch_half_span.powi(2)) / (2.0 * self.arch_height)
    }

    /// Target displacement `(0, 0, dz)` of the frame group.
    pub fn target(&self) -> [f64; 3] {
        [0.0, 0.0, self.target_dz_per_height * self.arch_height]
    }

    /// Checks that the geometry is buildable (positive sizes, arch inside the frame).
    pub fn check(&self) -> Result<(), String> {
        let positive = |v: f64| v > 0.0 && v.is_finite();
        if !positive(self.arch_height) || !positive(self.arch_half_span) {
            return Err(format!(
                "arch height {} and half span {} must be > 0",
                self.arch_height, self.arch_half_span
            ));
        }
        if self.arch_height > self.arch_half_span {
            return Err(
                "arch height larger than the half span: not a shallow circular arch".into(),
            );
        }
        let dy = self.frame_half_y / CELLS as f64;
        if ((GAP_COUNT - 1) as f64 * dy - self.arch_half_span).abs() > 1e-9 * self.frame_half_y {
            return Err("the 9 gaps must reach the arch foot: frame_half_y must equal 1.25 × arch_half_span".into());
        }
        let column = self.arch_offset / (self.frame_half_x / CELLS as f64);
        if (column - column.round()).abs() > 1e-9 || column < 1.0 || column > (CELLS - 1) as f64 {
            return Err("arch_offset must fall on an interior grid line of the frame (a multiple of frame_half_x/10)".into());
        }
        if !(1..=400).contains(&self.refinement) {
            return Err(format!(
                "refinement {} must lie in 1..=400",
                self.refinement
            ));
        }
        if !(self.friction >= 0.0 && self.friction.is_finite()) {
            return Err(format!("friction {} must be ≥ 0", self.friction));
        }
        if !(self.pipe_radius > 0.0 && self.pipe_radius < self.arch_radius()) {
            return Err(format!(
                "pipe radius {} must be > 0 and below the arch radius",
                self.pipe_radius
            ));
        }
        if let FramePath::Wrapped { extension } = self.frame_path
            && !(0.0..=0.1).contains(&extension)
        {
            return Err(format!(
                "wrapped frame path: extension {extension} must lie in 0..=0.1 (a strain)"
            ));
        }
        if !(self.target_dz_per_height.is_finite() && self.target_dz_per_height.abs() <= 5.0) {
            return Err(format!(
                "target_dz_per_height {} must be finite and within ±5",
                self.target_dz_per_height
            ));
        }
        Ok(())
    }

    /// Target displacement of every boundary group (the model's order) at stage `t ∈ [0, 1]` of
    /// the frame path: `t` times the target when lowered, the wrapped film's boundary when
    /// wrapped. The model built by [`ParallelArch::model`] has its groups' targets at `t = 1`.
    pub fn boundary_targets(&self, model: &Model, t: f64) -> Vec<[f64; 3]> {
        match self.frame_path {
            FramePath::Lowered => model
                .groups
                .iter()
                .map(|_| self.target().map(|v| v * t))
                .collect(),
            FramePath::Wrapped { .. } => model
                .groups
                .iter()
                .map(|g| self.wrapped_displacement(model.nodes[g.nodes[0]], t))
                .collect(),
        }
    }

    /// Displacement of the film point of flat position `p` (at `z = H`) at stage `t` of the
    /// wrapped path: first half wound (`θ` from 0 to `θ_foot`), second half extended (`e` from 0
    /// to `ε`); `x = X + e (X − x_arch)` beyond the arch line; `(y, z)` at arc length `(1 + e) Y`
    /// along the film's line over the arch, which follows the arch circle to `θ` and then its
    /// tangent.
    fn wrapped_displacement(&self, p: [f64; 3], t: f64) -> [f64; 3] {
        let FramePath::Wrapped { extension } = self.frame_path else {
            return [0.0; 3];
        };
        let (r, h) = (self.arch_radius(), self.arch_height);
        // First half: wound onto the arch; second half: the boundary extended.
        let stretch = 1.0 + (2.0 * t - 1.0).clamp(0.0, 1.0) * extension;
        let theta = (2.0 * t).min(1.0) * (self.arch_half_span / r).asin();
        let s = stretch * p[1];
        let (y, z) = if s <= r * theta {
            (r * (s / r).sin(), h - r + r * (s / r).cos())
        } else {
            let free = s - r * theta;
            (
                r * theta.sin() + free * theta.cos(),
                h - r + r * theta.cos() - free * theta.sin(),
            )
        };
        // Across the arches the extension starts at the arch line: the film between the arches
        // is not pulled across the pipes (the film's nodes on them stay on their tops).
        let across = (stretch - 1.0) * (p[0] - self.arch_offset).max(0.0);
        [across, y - p[1], z - p[2]]
    }

    /// Builds the 1/4 model (validated).
    pub fn model(&self) -> Result<Model, String> {
        self.check()?;
        let r = self.refinement;
        let n = CELLS * r;
        let h = self.arch_height;
        let (nodes, triangles) = self.mesh();
        let frame = grid_nodes(n, &|i, j| i == n || j == n);
        let symmetry = vec![
            Symmetry {
                name: "x0".into(),
                normal: Axis::X,
                nodes: grid_nodes(n, &|i, j| i == 0 && j < n),
            },
            Symmetry {
                name: "y0".into(),
                normal: Axis::Y,
                nodes: grid_nodes(n, &|i, j| j == 0 && i < n),
            },
        ];
        let (gaps, curved_supports) = self.contacts(&nodes);
        let groups = self.groups(frame, &nodes);
        let model = Model {
            loads: Default::default(),
            outputs: Default::default(),
            cables: vec![],
            curved_supports,
            chambers: vec![],
            layers: vec![],
            orifices: vec![],
            layer_contacts: vec![],
            frame_axis: None,
            name: MODEL_NAME.into(),
            description: format!(
                "1/4 model of the parallel steel arch specimen, arch height {:.0} mm, refinement {}",
                1000.0 * h,
                r
            ),
            nodes,
            triangles,
            material: match self.frame_path {
                FramePath::Lowered => self.material,
                // While it is wound, the film between the arch and the frame is briefly
                // compressed: a foil wrinkles there, the linear film buckles (assumptions table).
                FramePath::Wrapped { .. } => Material {
                    wrinkling: Wrinkling::TensionField,
                    ..self.material
                },
            },
            supports: vec![],
            symmetry,
            gaps,
            groups,
        };
        model.validate().map_err(|e| e.to_string())?;
        Ok(model)
    }

    /// The film's grid over the quarter frame at the arch height: its nodes (row by row) and
    /// two triangles per cell.
    fn mesh(&self) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
        let n = CELLS * self.refinement;
        let (dx, dy) = (self.frame_half_x / n as f64, self.frame_half_y / n as f64);
        let h = self.arch_height;
        let id = |i: usize, j: usize| grid_node(n, i, j);
        let mut nodes = Vec::with_capacity((n + 1) * (n + 1));
        for j in 0..=n {
            for i in 0..=n {
                nodes.push([i as f64 * dx, j as f64 * dy, h]);
            }
        }
        let mut triangles = Vec::with_capacity(2 * n * n);
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
        (nodes, triangles)
    }

    /// The film's contact with the arch at the film nodes above it: gap elements, or one
    /// curved support along the arch pipe.
    fn contacts(&self, nodes: &[[f64; 3]]) -> (Vec<GapSpec>, Vec<CurvedSupport>) {
        let r = self.refinement;
        let n = CELLS * r;
        let dx = self.frame_half_x / n as f64;
        let h = self.arch_height;
        let radius = self.arch_radius();
        let column = (self.arch_offset / dx).round() as usize;
        let kn = self.normal_penalty_factor * self.material.membrane_stiffness();
        let gaps: Vec<GapSpec> = (0..GAP_COUNT)
            .map(|k| {
                let node = grid_node(n, column, k * r);
                let a = Vector3::from(nodes[node]);
                let centre = Vector3::new(a.x, 0.0, h - radius);
                let to_film = a - centre;
                let normal = to_film / to_film.norm();
                let tangent = Vector3::new(0.0, normal.z, -normal.y);
                GapSpec {
                    name: format!("G{}", k + 1),
                    film_node: node,
                    support: GapSupport::Point((centre + normal * radius).into()),
                    frame: GapFrame::from_x_and_z(tangent, normal),
                    initial_gap: (to_film.norm() - radius).max(0.0),
                    normal_stiffness: kn,
                    tangential_stiffness: self.tangential_penalty_ratio * kn,
                    friction: self.friction,
                    friction_law: self.friction_law,
                }
            })
            .collect();
        match self.contact {
            SpecimenContact::Gaps => (gaps, vec![]),
            SpecimenContact::CurvedSupport => {
                let rp = self.pipe_radius;
                let foot = (self.arch_half_span / radius).asin();
                let support = CurvedSupport {
                    name: "arch".into(),
                    centreline: Centreline::Circle {
                        centre: [column as f64 * dx, 0.0, h - radius],
                        // About −x, from +z: the angle grows from the crown toward the foot (+y).
                        axis: [-1.0, 0.0, 0.0],
                        radius: radius - rp,
                        angles: Some([-0.1, foot + 0.1]),
                        start_direction: Some([0.0, 0.0, 1.0]),
                    },
                    tube_radius: rp,
                    nodes: gaps.iter().map(|g| g.film_node).collect(),
                    normal_stiffness: kn,
                    tangential_stiffness: self.tangential_penalty_ratio * kn,
                    friction: self.friction,
                    friction_law: self.friction_law,
                };
                (vec![], vec![support])
            }
        }
    }

    /// The boundary groups moving the `frame` nodes: one lowering them all, or one per node
    /// following the wrapped film.
    fn groups(&self, frame: Vec<usize>, nodes: &[[f64; 3]]) -> Vec<BoundaryGroup> {
        match self.frame_path {
            FramePath::Lowered => vec![BoundaryGroup {
                name: "frame".into(),
                nodes: frame,
                target: self.target(),
                components: None,
                hinge: None,
            }],
            FramePath::Wrapped { .. } => frame
                .iter()
                .map(|&v| BoundaryGroup {
                    name: format!("node{v}"),
                    nodes: vec![v],
                    target: self.wrapped_displacement(nodes[v], 1.0),
                    components: None,
                    hinge: None,
                })
                .collect(),
        }
    }
}

/// The index of node (`i`, `j`) of the (`n` + 1) × (`n` + 1) grid, numbered row by row.
fn grid_node(n: usize, i: usize, j: usize) -> usize {
    j * (n + 1) + i
}

/// The grid's nodes (`n` cells a side) whose (`i`, `j`) satisfy `pred`, row by row.
fn grid_nodes(n: usize, pred: &dyn Fn(usize, usize) -> bool) -> Vec<usize> {
    (0..=n)
        .flat_map(|j| (0..=n).map(move |i| (i, j)))
        .filter(|&(i, j)| pred(i, j))
        .map(|(i, j)| grid_node(n, i, j))
        .collect()
}

/// One row of the paper's Table 1.
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredSliding {
    /// Specimen label, e.g. `300_Spec`.
    pub specimen: String,
    /// Arch height (mm).
    pub arch_height_mm: f64,
    /// Sliding at observed points 1–5 (mm).
    pub points: [f64; 5],
}

/// The paper's Table 1, parsed from the CSV shipped in `data/`.
pub fn table1() -> Vec<MeasuredSliding> {
    TABLE1_CSV
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("specimen") && !l.trim().is_empty())
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let num = |i: usize| f.get(i).and_then(|v| v.trim().parse::<f64>().ok());
            Some(MeasuredSliding {
                specimen: f.first()?.to_string(),
                arch_height_mm: num(1)?,
                points: [num(2)?, num(3)?, num(4)?, num(5)?, num(6)?],
            })
        })
        .collect()
}
