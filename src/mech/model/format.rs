//! The model: mesh, material, constraints, gap elements and prescribed boundary groups, read
//! from a JSON model file (format in `docs/model-format.md`) and validated before any analysis.
//!
//! Validation names the offending item: an unknown node index, a degenerate triangle, `E ≤ 0`,
//! `ν` outside `[0, 0.5)`, `η` outside `[0, 1)`, `μ < 0`, a non-orthonormal gap frame, a duplicate
//! name, a node that is both constrained and prescribed, a control character in text bound for
//! modelDescription.xml, a rigid-body mode no restraint holds ([`super::restraint`], checked by `validate.rs`). Nothing here
//! panics on user input.

use std::fmt;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::mech::elements::curved_contact::CurvedSupport;
use crate::mech::elements::gap::{FrictionLaw, GapFrame, GapLaw};
use crate::mech::elements::triangle::{DegenerateTriangle, Material, MembraneTriangle};

/// A global axis, used for supports and symmetry planes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Global X.
    X,
    /// Global Y.
    Y,
    /// Global Z.
    Z,
}

impl Axis {
    /// Component index 0, 1 or 2.
    pub fn index(self) -> usize {
        self as usize
    }
}

/// Fixed DOFs of one node (displacement zero in the listed axes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Support {
    /// Node index.
    pub node: usize,
    /// Fixed components.
    pub fixed: Vec<Axis>,
    /// Reaction set: supports with the same name report their summed reaction (FMU outputs
    /// `<name>.Rx/.Ry/.Rz`); none: the support only counts in the total `reactions.*`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
}

/// A symmetry plane normal to a global axis: the normal displacement of its nodes is zero.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Symmetry {
    /// Name of the plane (for messages).
    pub name: String,
    /// Normal of the plane.
    pub normal: Axis,
    /// Nodes on the plane.
    pub nodes: Vec<usize>,
}

/// What node B of a gap is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GapSupport {
    /// A node of the model (its DOFs take part in the gap).
    Node(usize),
    /// A fixed point in space (a rigid support).
    Point([f64; 3]),
}

/// A friction gap element as written in a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GapSpec {
    /// Name (an identifier: it becomes the FMU variable prefix).
    pub name: String,
    /// Node A, on the film.
    pub film_node: usize,
    /// Node B: a support node or a fixed point.
    pub support: GapSupport,
    /// Local frame, fixed during the analysis (§4.3).
    pub frame: GapFrame,
    /// Initial gap `g0 ≥ 0` (m).
    #[serde(default)]
    pub initial_gap: f64,
    /// Normal penalty `k_n` (N/m).
    pub normal_stiffness: f64,
    /// Tangential penalty `k_s` (N/m).
    pub tangential_stiffness: f64,
    /// Friction coefficient `μ ≥ 0`.
    pub friction: f64,
    /// How the gap slides: `"isotropic"` (default) or `"sliding-direction"` (the paper's §2.2).
    #[serde(default)]
    pub friction_law: FrictionLaw,
}

/// Largest difference between a gap's `initial_gap` and the distance its geometry gives, as a
/// fraction of the model's size (bounding-box diagonal), that validation accepts: 0.2 mm on a
/// 2 m model, above the rounding of hand-written coordinates; beyond it the two contradict each
/// other and the model is refused. Smaller differences (above 1e-6 of the size) are warned
/// about ([`crate::mech::results::warnings::model_warnings`]).
pub const GAP_GEOMETRY_TOLERANCE: f64 = 1e-4;

impl GapSpec {
    /// The gap its geometry gives (m): the distance along the frame's z from the support (point
    /// or node B) to the film node A, `z · (X_A − X_B)` (§4.3; the gap closes when
    /// `g0 + z · (u_A − u_B) < 0`, so `g0` should equal it). Node indices must exist.
    pub fn geometric_gap(&self, nodes: &[[f64; 3]]) -> f64 {
        let support = match self.support {
            GapSupport::Point(p) => p,
            GapSupport::Node(b) => nodes[b],
        };
        let a = nodes[self.film_node];
        (0..3).map(|c| (a[c] - support[c]) * self.frame.z[c]).sum()
    }

    /// The constitutive constants of this gap.
    pub fn law(&self) -> GapLaw {
        GapLaw {
            normal_stiffness: self.normal_stiffness,
            tangential_stiffness: self.tangential_stiffness,
            friction: self.friction,
            initial_gap: self.initial_gap,
            friction_law: self.friction_law,
        }
    }
}

/// A named set of nodes that move together by an imposed displacement `(dx, dy, dz)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundaryGroup {
    /// Name (an identifier: it becomes the FMU variable prefix).
    pub name: String,
    /// Nodes of the group.
    pub nodes: Vec<usize>,
    /// Target displacement of a standard run (m); the CLI and the FMU's default experiment use it.
    #[serde(default)]
    pub target: [f64; 3],
    /// The components the group prescribes (e.g. `["z"]`: x and y stay free); omitted: all
    /// three. Its free components are ordinary film DOFs; their targets are ignored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub components: Option<Vec<Axis>>,
    /// A hinge: the group also turns as a rigid body about it (a rotating frame side is one
    /// group); omitted: the group only translates.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hinge: Option<Hinge>,
}

/// The axis a boundary group turns about: a node at `X` moves by
/// `t + (R(θ) − I)(X − p)`, with `R(θ)` the rotation by `θ` about `axis` (right-hand rule)
/// and `p` the hinge `point`; the hinge itself moves with the group's translation `t`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hinge {
    /// A point of the axis in the initial configuration (m).
    pub point: [f64; 3],
    /// Direction of the axis (any length but zero).
    pub axis: [f64; 3],
    /// Angle of a standard run (rad); the CLI turns the group to it. The FMU starts at 0 and
    /// follows its input `<group>.angle`.
    #[serde(default)]
    pub target_angle: f64,
}

impl Hinge {
    /// Largest angle accepted (rad): two full turns either way.
    pub const MAX_ANGLE: f64 = 4.0 * std::f64::consts::PI;

    /// The displacement `(R(θ) − I)(X − p)` of a node at `x` turned by `angle` (Rodrigues).
    pub fn displacement(&self, x: [f64; 3], angle: f64) -> [f64; 3] {
        let a = Vector3::from(self.axis).normalize();
        let r = Vector3::from(x) - Vector3::from(self.point);
        let s = angle.sin();
        // R r − r = sin θ (a × r) + (1 − cos θ) a × (a × r); 1 − cos θ = 2 sin²(θ/2) keeps
        // small angles exact.
        let ar = a.cross(&r);
        let one_minus_cos = 2.0 * (0.5 * angle).sin().powi(2);
        (s * ar + one_minus_cos * a.cross(&ar)).into()
    }
}

impl BoundaryGroup {
    /// Whether the group prescribes each of x, y, z.
    pub fn prescribes(&self) -> [bool; 3] {
        match &self.components {
            None => [true; 3],
            Some(axes) => std::array::from_fn(|c| axes.iter().any(|a| a.index() == c)),
        }
    }
}

/// Which triangles a pressure set covers: `"all"` or a list of triangle indices.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ElementSelection {
    /// Every triangle of the model (written `"all"`).
    All(AllElements),
    /// The listed triangles (0-based).
    List(Vec<usize>),
}

/// The word `"all"` of an [`ElementSelection`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum AllElements {
    /// Every triangle.
    #[serde(rename = "all")]
    All,
}

/// How a pressure set's value acts ([`PressureSet::kind`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PressureKind {
    /// Follower pressure: normal to the deformed film, per unit of its area.
    #[default]
    Follower,
    /// A dead load per unit of plan area: along `towards` (default `-z`, down), per unit of the
    /// triangles' initial area projected on the plane normal to it (snow: EN 1991-1-3 gives
    /// `s` per plan area); no stiffness.
    Plan,
}

impl PressureKind {
    fn is_follower(&self) -> bool {
        *self == Self::Follower
    }
}

/// A pressure on a named set of triangles: a follower pressure (normal to the deformed film)
/// or a load per plan area ([`PressureKind`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureSet {
    /// Name (an identifier: it becomes the FMU variable prefix `<name>.pressure`).
    pub name: String,
    /// The triangles it acts on.
    pub elements: ElementSelection,
    /// Pressure of a standard run (Pa); positive pushes along the triangle normal
    /// `(x2 − x1) × (x3 − x1)` of its node order, or towards [`Self::towards`] when given.
    pub pressure: f64,
    /// The side a positive pressure pushes the film to, in world terms: each triangle's
    /// pressure is oriented so that it pushes along the side of its initial normal facing this
    /// direction, whatever its node order (`None`: the node order decides).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub towards: Option<Towards>,
    /// `"follower"` (default) or `"plan"`: a load per plan area along `towards` (default
    /// down, `-z`), positive along it.
    #[serde(default, skip_serializing_if = "PressureKind::is_follower")]
    pub kind: PressureKind,
}

/// The world direction a pressure set pushes the film to (`"towards"`): a vector or a signed
/// global axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "serde_json::Value", into = "serde_json::Value")]
pub enum Towards {
    /// A direction `[x, y, z]` (any length, not zero).
    Direction([f64; 3]),
    /// A signed global axis, `"+x"` … `"-z"`.
    Side(Side),
}

/// A signed global axis (`"+z"`: towards global +Z).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Side {
    /// +X.
    #[serde(rename = "+x")]
    PlusX,
    /// −X.
    #[serde(rename = "-x")]
    MinusX,
    /// +Y.
    #[serde(rename = "+y")]
    PlusY,
    /// −Y.
    #[serde(rename = "-y")]
    MinusY,
    /// +Z.
    #[serde(rename = "+z")]
    PlusZ,
    /// −Z.
    #[serde(rename = "-z")]
    MinusZ,
}

impl TryFrom<serde_json::Value> for Towards {
    type Error = String;

    fn try_from(value: serde_json::Value) -> Result<Self, String> {
        serde_json::from_value(value.clone())
            .map(Self::Direction)
            .or_else(|_| serde_json::from_value(value.clone()).map(Self::Side))
            .map_err(|_| {
                format!(
                    "towards {value} is neither a direction [x, y, z] nor one of \"+x\", \"-x\", \
                     \"+y\", \"-y\", \"+z\", \"-z\""
                )
            })
    }
}

impl From<Towards> for serde_json::Value {
    fn from(towards: Towards) -> Self {
        match towards {
            Towards::Direction(d) => serde_json::json!(d),
            Towards::Side(side) => serde_json::json!(side),
        }
    }
}

impl Towards {
    /// The direction as a vector (not normalised; a side is a unit axis).
    pub fn vector(self) -> [f64; 3] {
        match self {
            Self::Direction(d) => d,
            Self::Side(side) => {
                let (axis, sign) = match side {
                    Side::PlusX => (0, 1.0),
                    Side::MinusX => (0, -1.0),
                    Side::PlusY => (1, 1.0),
                    Side::MinusY => (1, -1.0),
                    Side::PlusZ => (2, 1.0),
                    Side::MinusZ => (2, -1.0),
                };
                std::array::from_fn(|c| if c == axis { sign } else { 0.0 })
            }
        }
    }
}

/// A dead force on each node of a named node set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceSet {
    /// Name (an identifier: it becomes the FMU variable prefix `<name>.Fx/.Fy/.Fz`).
    pub name: String,
    /// The nodes it acts on.
    pub nodes: Vec<usize>,
    /// Force on EACH node of a standard run, global axes (N).
    pub force: [f64; 3],
}

/// The gravity acceleration of the model file when none is given (m/s², global −Z).
pub const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

fn default_gravity() -> [f64; 3] {
    DEFAULT_GRAVITY
}

/// External loads of a model file (`"loads"`): applied over the same increments as the groups.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Follower pressures.
    #[serde(default)]
    pub pressures: Vec<PressureSet>,
    /// Nodal forces.
    #[serde(default)]
    pub forces: Vec<ForceSet>,
    /// Gravity acceleration acting on the film's mass (`material.density`) (m/s²).
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
}

impl Default for LoadSpec {
    fn default() -> Self {
        Self {
            pressures: Vec::new(),
            forces: Vec::new(),
            gravity: DEFAULT_GRAVITY,
        }
    }
}

impl LoadSpec {
    /// Whether the section holds nothing but the default gravity (then it is not written).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// A node whose displacement is reported (FMU outputs `<name>.ux/.uy/.uz`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputPoint {
    /// Name (an identifier: the FMU variable prefix).
    pub name: String,
    /// The node (0-based).
    pub node: usize,
}

/// A named set of triangles whose field summary is reported (see `summary.rs`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElementSet {
    /// Name (an identifier: the FMU variable prefix `<name>.maxPrincipalStress`, …).
    pub name: String,
    /// Its triangles.
    pub elements: ElementSelection,
}

/// What a model reports beyond gaps and group reactions (`"outputs"`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Named output points.
    #[serde(default)]
    pub points: Vec<OutputPoint>,
    /// Named element sets with field summaries.
    #[serde(default)]
    pub element_sets: Vec<ElementSet>,
}

impl OutputSpec {
    /// Whether nothing is asked (then the section is not written).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty() && self.element_sets.is_empty()
    }
}

/// A tension-only cable through a chain of film nodes (see `cable.rs`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CableSpec {
    /// Name (an identifier: the FMU variable prefix `<name>.maxForce`).
    pub name: String,
    /// The film nodes it runs through, in order; each consecutive pair must be a triangle edge.
    pub nodes: Vec<usize>,
    /// Cross-section area (m²).
    pub area: f64,
    /// Young's modulus (Pa).
    pub youngs_modulus: f64,
    /// Axial force in the reference configuration (N), `≥ 0`.
    #[serde(default)]
    pub prestress_force: f64,
}

/// A complete membrane + gap model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Model {
    /// Model name (an identifier: it becomes the FMU's model identifier).
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// Node coordinates (m).
    pub nodes: Vec<[f64; 3]>,
    /// Triangles as three node indices each.
    pub triangles: Vec<[usize; 3]>,
    /// Film material, thickness and prestress.
    pub material: Material,
    /// Fixed DOFs.
    #[serde(default)]
    pub supports: Vec<Support>,
    /// Symmetry planes.
    #[serde(default)]
    pub symmetry: Vec<Symmetry>,
    /// Friction gap elements.
    #[serde(default)]
    pub gaps: Vec<GapSpec>,
    /// Prescribed boundary groups.
    #[serde(default)]
    pub groups: Vec<BoundaryGroup>,
    /// Pressures, nodal forces and gravity.
    #[serde(default, skip_serializing_if = "LoadSpec::is_default")]
    pub loads: LoadSpec,
    /// Output points and element sets.
    #[serde(default, skip_serializing_if = "OutputSpec::is_empty")]
    pub outputs: OutputSpec,
    /// Tension-only edge cables.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cables: Vec<CableSpec>,
    /// Rigid curved supports (cylinders, pipe arches) with node-to-surface friction contact
    /// whose frames follow the contact point ([`crate::mech::elements::curved_contact`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub curved_supports: Vec<CurvedSupport>,
    /// Closed volumes of gas bounded by film triangles (cushions;
    /// [`crate::mech::elements::chamber`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub chambers: Vec<ChamberSpec>,
    /// Orifices between two chambers, air flowing by the orifice equation (issue 43).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub orifices: Vec<OrificeSpec>,
    /// Film layers of their own thickness (a cushion's 250/100/250 µm layers); the triangles of
    /// no layer have the material's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub layers: Vec<Layer>,
    /// Pairs of film layers that may touch: node-to-surface friction contact between them
    /// ([`crate::mech::elements::layer_contact`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub layer_contacts: Vec<crate::mech::elements::layer_contact::LayerContactSpec>,
    /// The global direction whose projection on each triangle is its frame's e1, the axis the
    /// prestress, strains and stresses are given along (a warp direction); none: global X.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame_axis: Option<[f64; 3]>,
}

/// A set of film triangles with a thickness of its own (the material's elasticity, prestress
/// and plasticity are the model's).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layer {
    /// Name (an identifier).
    pub name: String,
    /// Its triangles (each in at most one layer).
    pub elements: ElementSelection,
    /// Its thickness `t` (m).
    pub thickness: f64,
}

/// A closed volume of gas bounded by film triangles (issue 43): held at a gauge pressure by a
/// supply, or enclosed (`(p + p_a) V^κ = C`, [`crate::mech::elements::chamber::GasLaw`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChamberSpec {
    /// Name (an identifier).
    pub name: String,
    /// The film triangles that bound it (their node order need not agree: they are oriented
    /// out of the chamber by their shared edges).
    pub elements: ElementSelection,
    /// The rigid plane that closes the triangles' rim (the frame's plane), when they do not
    /// close the volume themselves.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closed_by_plane: Option<ClosingPlane>,
    /// Gauge pressure (Pa): the supply's of a standard run, or, `sealed`, the enclosed gas's
    /// in the reference geometry.
    pub pressure: f64,
    /// Whether the gas is enclosed from the start (else a supply holds `pressure` until
    /// `Analysis::seal_chambers`).
    #[serde(default)]
    pub sealed: bool,
    /// Polytropic exponent κ of the enclosed gas: 1 isothermal (default), 1.4 adiabatic air.
    #[serde(default = "default_kappa")]
    pub kappa: f64,
    /// Atmospheric pressure (Pa), default 101 325.
    #[serde(default = "default_atmosphere")]
    pub atmosphere: f64,
    /// The air's temperature in the reference state (K), default 293.15.
    #[serde(default = "default_air_temperature")]
    pub temperature: f64,
    /// The air's temperature rise in a standard run (K; the sun on a cushion), default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub heating: f64,
}

/// An opening between two chambers: air flows from the higher pressure to the lower by the
/// orifice equation `ṁ = C_d A √(2 ρ |Δp|)` ([`crate::mech::elements::chamber::orifice_flow`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrificeSpec {
    /// Name (an identifier).
    pub name: String,
    /// The chamber whose air flows out when its pressure is the higher (`Δp = p_from − p_to`).
    pub from: String,
    /// The other chamber.
    pub to: String,
    /// The opening's area `A` (m²).
    pub area: f64,
    /// The discharge coefficient `C_d` in (0, 1] (about 0.6 for a sharp-edged hole).
    pub discharge_coefficient: f64,
}

fn default_air_temperature() -> f64 {
    293.15
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// A plane closing a chamber: a point on it and its normal pointing into the chamber.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClosingPlane {
    /// A point of the plane (m).
    pub point: [f64; 3],
    /// Its normal, pointing into the chamber (any length, not zero).
    pub normal: [f64; 3],
}

fn default_kappa() -> f64 {
    1.0
}

fn default_atmosphere() -> f64 {
    101_325.0
}

/// Why a model is rejected. Every variant names the offending item.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelError {
    /// The file is not valid JSON of the model format.
    Syntax { message: String },
    /// A reference to a node that does not exist.
    UnknownNode {
        item: String,
        node: usize,
        node_count: usize,
    },
    /// A node coordinate or a number that must be finite is not.
    NotFinite { item: String },
    /// A triangle with (near) zero area or repeated nodes.
    DegenerateTriangle { triangle: usize, nodes: [usize; 3] },
    /// A `frame_axis` that is not a direction, or lies (nearly) normal to a triangle.
    FrameAxis { message: String },
    /// A material constant out of range.
    Material { message: String },
    /// A gap constant out of range.
    Gap { gap: String, message: String },
    /// A name that is empty, not an identifier, or used twice.
    Name { item: String, message: String },
    /// A DOF that is constrained and prescribed, or prescribed twice.
    Conflict { node: usize, message: String },
    /// A node with free DOFs that belongs to no triangle (see [`super::restraint`]).
    Unconnected { node: usize },
    /// A film component with a rigid-body mode that no restraint holds (see [`super::restraint`]).
    Unrestrained {
        /// The component's first nodes.
        nodes: Vec<usize>,
        /// How many nodes it has.
        node_count: usize,
        /// The free motion in words ("can translate along Y").
        motion: String,
        /// Why the prestress, which would stiffen the motion, does not hold it.
        note: Option<String>,
    },
    /// Text that would go into modelDescription.xml holds a character XML cannot carry.
    Text { field: String, message: String },
    /// A load set out of range (unknown triangle, empty set, non-finite value).
    Load { item: String, message: String },
    /// An output element set out of range (unknown triangle, empty set).
    Output { item: String, message: String },
    /// Nothing to analyse.
    Empty { message: String },
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Syntax { message } => write!(f, "model file: {message}"),
            Self::UnknownNode {
                item,
                node,
                node_count,
            } => {
                write!(
                    f,
                    "{item}: node {node} does not exist (the model has {node_count} nodes, 0-based)"
                )
            }
            Self::NotFinite { item } => write!(f, "{item}: value is not a finite number"),
            Self::DegenerateTriangle { triangle, nodes } => {
                write!(
                    f,
                    "triangle {triangle} {nodes:?} is degenerate (zero area or repeated node)"
                )
            }
            Self::Material { message } => write!(f, "material: {message}"),
            Self::FrameAxis { message } => write!(f, "frame_axis: {message}"),
            Self::Gap { gap, message } => write!(f, "gap '{gap}': {message}"),
            Self::Name { item, message } => write!(f, "{item}: {message}"),
            Self::Conflict { node, message } => write!(f, "node {node}: {message}"),
            Self::Unconnected { node } => {
                write!(
                    f,
                    "node {node} has free DOFs but belongs to no triangle: only gaps act on it and their \
                     forces must balance, so they cannot hold it (singular system); hold it with a support, \
                     symmetry plane or boundary group"
                )
            }
            Self::Unrestrained {
                nodes,
                node_count,
                motion,
                note,
            } => {
                let listed: Vec<String> = nodes.iter().map(|v| v.to_string()).collect();
                let more = if *node_count > nodes.len() {
                    ", …"
                } else {
                    ""
                };
                write!(
                    f,
                    "the film part with nodes {}{more} ({node_count} nodes) {motion}: no support, symmetry \
                     plane, boundary group or gap restrains it (singular system)",
                    listed.join(", ")
                )?;
                match note {
                    Some(note) => write!(f, "; {note}"),
                    None => Ok(()),
                }
            }
            Self::Text { field, message } => write!(f, "{field}: {message}"),
            Self::Load { item, message } | Self::Output { item, message } => {
                write!(f, "{item}: {message}")
            }
            Self::Empty { message } => write!(f, "model: {message}"),
        }
    }
}

impl std::error::Error for ModelError {}

/// Largest friction coefficient accepted (model files, the FMU's `mu`, FMU states). Coulomb
/// coefficients of real contact pairs are below about 1.5 (ETFE on steel: 0.1–0.5, the paper
/// §4); at 10 a gap practically never slips, and larger values only risk overflowing `μN`.
pub const MAX_FRICTION: f64 = 10.0;

/// A real for a message: plain between 1e-4 and 1e15 in magnitude (`0.25`, `11`), else in
/// `{:e}` form (`1e308`, `5e-324`), so that no huge or tiny value prints as hundreds of digits
/// (`{}` of 1e308 is 309 of them) or as a zero.
pub fn message_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Whether `name` can be used as an FMU variable prefix and a C identifier.
pub fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The rows of fixed length of a model file: where they are, their length, what a row holds.
const FIXED_ROWS: [(&[&str], usize, &str); 3] = [
    (&["nodes"], 3, "[x, y, z] in m"),
    (&["triangles"], 3, "three node indices"),
    (
        &["material", "plasticity", "hardening"],
        2,
        "[equivalent plastic strain, flow stress in Pa]",
    ),
];

/// The first row of [`FIXED_ROWS`] of another length in the JSON `text`, named
/// (`material.plasticity.hardening[1]: 3 numbers, …`): serde_json reports a long row only as
/// "trailing characters at line 1 column 528", which names no item. None when the text is not
/// JSON or every such row has its length.
fn row_length_error(text: &str) -> Option<String> {
    let root: serde_json::Value = serde_json::from_str(text).ok()?;
    FIXED_ROWS.iter().find_map(|(path, length, holds)| {
        let rows = path
            .iter()
            .try_fold(&root, |v, key| v.get(key))?
            .as_array()?;
        rows.iter().enumerate().find_map(|(k, row)| {
            let given = row.as_array()?.len();
            (given != *length)
                .then(|| format!("{}[{k}]: {given} numbers; a row is {holds}", path.join(".")))
        })
    })
}

impl Model {
    /// Parses and validates a JSON model file.
    pub fn from_json(text: &str) -> Result<Self, ModelError> {
        let model: Model = serde_json::from_str(text).map_err(|e| ModelError::Syntax {
            message: row_length_error(text).unwrap_or_else(|| e.to_string()),
        })?;
        model.validate()?;
        Ok(model)
    }

    /// Serializes the model to pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a model always serializes")
    }

    /// For every triangle edge `[a, b]` (both orientations): a triangle that has it and the
    /// positions of `a` and `b` in that triangle. Built in one pass (cables look their segments
    /// up in it).
    pub fn edge_triangles(&self) -> std::collections::HashMap<[usize; 2], (usize, [usize; 2])> {
        let mut edges = std::collections::HashMap::with_capacity(3 * self.triangles.len());
        for (t, tri) in self.triangles.iter().enumerate() {
            for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                edges.entry([tri[i], tri[j]]).or_insert((t, [i, j]));
                edges.entry([tri[j], tri[i]]).or_insert((t, [j, i]));
            }
        }
        edges
    }

    /// The names of the support sets, in the order of their first support.
    pub fn support_sets(&self) -> Vec<String> {
        let mut sets: Vec<String> = vec![];
        for name in self.supports.iter().filter_map(|s| s.name.as_ref()) {
            if !sets.contains(name) {
                sets.push(name.clone());
            }
        }
        sets
    }

    /// Triangle `t` on the positions `x`, its frame along the model's [`Model::frame_axis`].
    pub fn element_on(
        &self,
        t: usize,
        x: &[[f64; 3]],
    ) -> Result<MembraneTriangle, DegenerateTriangle> {
        let tri = self.triangles[t];
        MembraneTriangle::new_along(tri.map(|v| Vector3::from(x[v])), self.frame_axis)
    }

    /// The triangles of `selection`.
    pub fn selected_triangles(&self, selection: &ElementSelection) -> Vec<usize> {
        match selection {
            ElementSelection::All(_) => (0..self.triangles.len()).collect(),
            ElementSelection::List(list) => list.clone(),
        }
    }

    /// Index of the gap named `name`.
    pub fn gap_index(&self, name: &str) -> Option<usize> {
        self.gaps.iter().position(|g| g.name == name)
    }

    /// The friction law of every gap and curved support when they all have the same one
    /// (`None`: mixed, or none of either).
    pub fn uniform_friction_law(&self) -> Option<FrictionLaw> {
        let mut laws = self
            .gaps
            .iter()
            .map(|g| g.friction_law)
            .chain(self.curved_supports.iter().map(|s| s.friction_law));
        let first = laws.next()?;
        laws.all(|l| l == first).then_some(first)
    }

    /// Gives every gap and curved support the friction law `law`.
    pub fn set_friction_law(&mut self, law: FrictionLaw) {
        for g in &mut self.gaps {
            g.friction_law = law;
        }
        for s in &mut self.curved_supports {
            s.friction_law = law;
        }
    }

    /// Number of DOFs (three per node).
    pub fn dof_count(&self) -> usize {
        3 * self.nodes.len()
    }
}

/// Diagonal of the axis-aligned bounding box of `nodes` (m): the length scale of validation,
/// warnings and the solver's tolerances.
pub fn bounding_diagonal(nodes: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in nodes {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt()
}
