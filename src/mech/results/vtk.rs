//! VTK output of the deformed film (the paper's Fig. 6): ParaView- and meshio-readable XML
//! unstructured grids (`.vtu`) per state, one for the film and one for the gaps, and a `.pvd`
//! collection of each over pseudo-time. Bytes only; the caller writes the files.
//!
//! The film and the gaps are separate grids so that no array carries placeholders (a colour
//! range over von Mises stress sees triangles only):
//!
//! * **film** ([`Block::Film`]): points are the deformed node positions, cells the triangles
//!   (VTK type 5). Point data `displacement`, `reaction` (N: the restraint force on a supported,
//!   symmetry or group node) and `line_reaction` (N/m: reaction per unit length along the
//!   boundary groups and support sets, [`crate::mech::results::lines`]; 0 off them). Cell data `von_mises`, `principal_1`,
//!   `principal_2` (Pa), `stress` (σx, σy, τxy in the element frame), `strain` (Green–Lagrange
//!   εx, εy, γxy in the element frame), `principal_strain_1`, `principal_strain_2`,
//!   `wrinkling_state` (0 taut, 1 wrinkled, 2 slack) and `tension_direction` (unit vector along
//!   the tension rays of a wrinkled triangle, global axes, deformed film; zero when taut or slack);
//!   an elasto-plastic film adds `equivalent_plastic_strain` and `thickness` (m).
//! * **gaps** ([`Block::Gaps`]): points are the deformed positions of the gaps' film nodes
//!   (point `k` for gap `k`) followed by their support points (point `G + k`), cells one line
//!   (VTK type 3) per gap from film node to support. Cell data `film_node` (index of the gap's
//!   node in the film grid), `gap_slip_x`, `gap_slip_y` (m), `gap_normal_force`,
//!   `gap_friction_force` (N) and `gap_status` (0 open, 1 stick, 2 slip). Written only when the
//!   model has gaps ([`Block::of`]).
//! * **contacts** ([`Block::Contacts`]): for the curved supports, points are the deformed
//!   contact nodes (point `k`) followed by their closest points on the support surface (point
//!   `C + k`), one line per contact; cell data `film_node`, `contact_slip` (arc length slid along the
//!   support in contact), `contact_travel` (along the support since the start), `contact_slip_across`, `contact_gap` (m), `contact_normal_force`,
//!   `contact_friction_force` (N), `contact_status`. Written only when the model has curved
//!   supports.
//! * **cables** ([`Block::Cables`]): one line per cable segment between its deformed nodes (two
//!   points each); cell data `cable` (index in the model), `cable_strain` (Green),
//!   `cable_axial_force` (N, tension only). Written only when the model has cables.
//!
//! [`Encoding::Ascii`] writes the values as text in the `DataArray` elements;
//! [`Encoding::Binary`] writes them after the XML as `<AppendedData encoding="raw">`: a `_`, then
//! per array a UInt64 byte count and the little-endian values, each `DataArray` giving the offset
//! of its block from the first byte after the `_` (the VTK XML format with
//! `header_type="UInt64"`). Raw appended data is not well-formed XML; VTK, ParaView and meshio
//! read it.

use std::fmt::Write;
use std::str::FromStr;

use crate::mech::model::{GapSupport, Model};
use crate::mech::results::Results;

/// How the values of the data arrays are stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// As text inside the XML (readable, about three times the size).
    Ascii,
    /// Raw little-endian bytes appended after the XML.
    #[default]
    Binary,
}

impl Encoding {
    /// The name of the setting (`ascii`, `binary`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Ascii => "ascii",
            Self::Binary => "binary",
        }
    }
}

impl FromStr for Encoding {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "ascii" => Ok(Self::Ascii),
            "binary" => Ok(Self::Binary),
            other => Err(format!("unknown VTK format '{other}' (ascii or binary)")),
        }
    }
}

/// The grids of a state, each in its own files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    /// The film triangles.
    Film,
    /// The gap lines.
    Gaps,
    /// The curved-support contacts: a line from each contact node to its closest point on the
    /// support.
    Contacts,
    /// The edge cables' segments.
    Cables,
}

impl Block {
    /// Every block, in file order.
    pub const ALL: [Block; 4] = [Block::Film, Block::Gaps, Block::Contacts, Block::Cables];

    /// The blocks written for `model`: the film, the gaps if it has any, the curved-support
    /// contacts if it has any (a grid without cells is valid VTK, but meshio 5.3 cannot read it).
    pub fn of(model: &Model) -> Vec<Block> {
        let mut blocks = vec![Self::Film];
        if !model.gaps.is_empty() {
            blocks.push(Self::Gaps);
        }
        if !model.curved_supports.is_empty() {
            blocks.push(Self::Contacts);
        }
        if !model.cables.is_empty() {
            blocks.push(Self::Cables);
        }
        blocks
    }

    /// The block's part of the file names (`film`, `gaps`, `contacts`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Film => "film",
            Self::Gaps => "gaps",
            Self::Contacts => "contacts",
            Self::Cables => "cables",
        }
    }
}

/// The `.vtu` file name of `block` at state number `step`: `<prefix>_<block>_NNNN.vtu`.
pub fn state_file_name(prefix: &str, block: Block, step: usize) -> String {
    format!("{prefix}_{}_{step:04}.vtu", block.name())
}

/// The `.pvd` file name of `block`'s collection: `<prefix>_<block>.pvd`.
pub fn collection_file_name(prefix: &str, block: Block) -> String {
    format!("{prefix}_{}.pvd", block.name())
}

/// The `.vtu` bytes of `block` for one state (`displacement`: three per node).
pub fn grid(
    block: Block,
    model: &Model,
    displacement: &[f64],
    results: &Results,
    encoding: Encoding,
) -> Vec<u8> {
    match block {
        Block::Film => film_grid(model, displacement, results, encoding),
        Block::Gaps => gap_grid(model, displacement, results, encoding),
        Block::Contacts => contact_grid(model, displacement, results, encoding),
        Block::Cables => cable_grid(model, displacement, encoding),
    }
}

/// The cables `.vtu` of one state: a line per segment between its deformed nodes, with the
/// cable's index, the segment's Green strain and axial force (tension only, `cable.rs`).
pub fn cable_grid(model: &Model, displacement: &[f64], encoding: Encoding) -> Vec<u8> {
    use nalgebra::Vector3;
    let film = deformed(model, displacement);
    let at = |n: usize| Vector3::new(film[3 * n], film[3 * n + 1], film[3 * n + 2]);
    let (mut starts, mut ends): (Vec<f64>, Vec<f64>) = (vec![], vec![]);
    let (mut cable, mut strain, mut force) = (vec![], vec![], vec![]);
    for (c, spec) in model.cables.iter().enumerate() {
        for pair in spec.nodes.windows(2) {
            let (a, b) = (at(pair[0]), at(pair[1]));
            let l0 =
                (Vector3::from(model.nodes[pair[0]]) - Vector3::from(model.nodes[pair[1]])).norm();
            starts.extend(a.iter());
            ends.extend(b.iter());
            cable.push(c as i64);
            strain.push(((a - b).norm_squared() - l0 * l0) / (2.0 * l0 * l0));
            force.push(crate::mech::elements::cable::axial_force(
                &a,
                &b,
                l0,
                spec.youngs_modulus * spec.area,
                spec.prestress_force,
            ));
        }
    }
    starts.extend(ends);
    lines(
        starts,
        vec![
            ("cable", 1, Values::I64(cable)),
            ("cable_strain", 1, Values::F64(strain)),
            ("cable_axial_force", 1, Values::F64(force)),
        ],
        Some("cable_axial_force"),
    )
    .encode(encoding)
}

/// The contacts `.vtu` of one state: a line per curved-support contact from its (deformed)
/// film node to its closest point on the support's surface, with the contact results.
pub fn contact_grid(
    model: &Model,
    displacement: &[f64],
    results: &Results,
    encoding: Encoding,
) -> Vec<u8> {
    let film = deformed(model, displacement);
    let nodes: Vec<usize> = model
        .curved_supports
        .iter()
        .flat_map(|s| s.nodes.iter().copied())
        .collect();
    let count = nodes.len();
    let cr = &results.surface_contacts;
    let mut points: Vec<f64> = nodes
        .iter()
        .flat_map(|&n| [film[3 * n], film[3 * n + 1], film[3 * n + 2]])
        .collect();
    points.extend(cr.iter().flat_map(|c| c.contact_point));
    let cell = |f: &dyn Fn(usize) -> f64| Values::F64((0..count).map(f).collect());
    lines(
        points,
        vec![
            (
                "film_node",
                1,
                Values::I64(nodes.iter().map(|&n| n as i64).collect()),
            ),
            ("contact_slip", 1, cell(&|k| cr[k].slip)),
            ("contact_travel", 1, cell(&|k| cr[k].travel)),
            ("contact_slip_across", 1, cell(&|k| cr[k].slip_across)),
            ("contact_gap", 1, cell(&|k| cr[k].gap)),
            ("contact_normal_force", 1, cell(&|k| cr[k].normal_force)),
            ("contact_friction_force", 1, cell(&|k| cr[k].friction_force)),
            (
                "contact_status",
                1,
                Values::I32(cr.iter().map(|c| c.status as i32).collect()),
            ),
        ],
        Some("contact_normal_force"),
    )
    .encode(encoding)
}

/// The film `.vtu` of one state: triangles, displacement, stresses, strains, wrinkling.
pub fn film_grid(
    model: &Model,
    displacement: &[f64],
    results: &Results,
    encoding: Encoding,
) -> Vec<u8> {
    let el = &results.elements;
    let tris = model.triangles.len();
    let cell = |f: &dyn Fn(usize) -> f64| Values::F64((0..tris).map(f).collect());
    let cell3 = |f: &dyn Fn(usize) -> [f64; 3]| Values::F64((0..tris).flat_map(f).collect());
    let principal_strains: Vec<[f64; 2]> = el.iter().map(|e| principal_strain(e.strain)).collect();
    let mut piece = Piece {
        points: deformed(model, displacement),
        connectivity: model
            .triangles
            .iter()
            .flatten()
            .map(|&n| n as i64)
            .collect(),
        offsets: (1..=tris as i64).map(|i| 3 * i).collect(),
        types: vec![5; tris],
        point_data: vec![
            (
                "displacement",
                3,
                Values::F64(displacement[..3 * model.nodes.len()].to_vec()),
            ),
            (
                "reaction",
                3,
                Values::F64(
                    (0..model.nodes.len())
                        .flat_map(|v| results.node_reactions.get(v).copied().unwrap_or([0.0; 3]))
                        .collect(),
                ),
            ),
            (
                "line_reaction",
                3,
                Values::F64(line_reaction_field(model, results)),
            ),
        ],
        cell_data: vec![
            ("von_mises", 1, cell(&|e| el[e].von_mises)),
            ("principal_1", 1, cell(&|e| el[e].principal[0])),
            ("principal_2", 1, cell(&|e| el[e].principal[1])),
            ("stress", 3, cell3(&|e| el[e].stress)),
            ("strain", 3, cell3(&|e| el[e].strain)),
            ("principal_strain_1", 1, cell(&|e| principal_strains[e][0])),
            ("principal_strain_2", 1, cell(&|e| principal_strains[e][1])),
            (
                "wrinkling_state",
                1,
                Values::I32(el.iter().map(|e| e.state as i32).collect()),
            ),
            ("tension_direction", 3, cell3(&|e| el[e].tension_direction)),
        ],
        point_vectors: Some("displacement"),
        cell_scalars: Some("von_mises"),
    };
    // An elasto-plastic film adds its plastic strain and thickness (an elastic one writes
    // exactly what it did).
    if el.iter().any(|e| e.plastic.is_some()) {
        let plastic = |e: usize| el[e].plastic.unwrap_or_default();
        piece.cell_data.push((
            "equivalent_plastic_strain",
            1,
            cell(&|e| plastic(e).equivalent_plastic_strain),
        ));
        piece
            .cell_data
            .push(("thickness", 1, cell(&|e| plastic(e).thickness)));
    }
    piece.encode(encoding)
}

/// Reaction per unit length of each node (N/m, three per node): its line reaction along the
/// boundary groups and support sets it belongs to ([`crate::mech::results::lines`]), summed; 0 elsewhere.
pub fn line_reaction_field(model: &Model, results: &Results) -> Vec<f64> {
    let lines = crate::mech::results::lines::reaction_lines(model).0;
    line_reaction_field_of(model.nodes.len(), &lines, results)
}

/// [`line_reaction_field`] of a model of `nodes` nodes whose reaction lines are `lines`.
pub fn line_reaction_field_of(
    nodes: usize,
    lines: &[crate::mech::results::lines::ReactionLine],
    results: &Results,
) -> Vec<f64> {
    let mut field = vec![0.0; 3 * nodes];
    for line in lines {
        for r in line.reactions(results) {
            for (c, q) in r.per_length.iter().enumerate() {
                field[3 * r.node + c] += q;
            }
        }
    }
    field
}

/// The gaps `.vtu` of one state: a line per gap from its film node to its support, with the
/// gap results.
pub fn gap_grid(
    model: &Model,
    displacement: &[f64],
    results: &Results,
    encoding: Encoding,
) -> Vec<u8> {
    let film = deformed(model, displacement);
    let node = |n: usize| [film[3 * n], film[3 * n + 1], film[3 * n + 2]];
    let gaps = model.gaps.len();
    let mut points: Vec<f64> = model.gaps.iter().flat_map(|g| node(g.film_node)).collect();
    points.extend(model.gaps.iter().flat_map(|g| match &g.support {
        GapSupport::Point(p) => *p,
        GapSupport::Node(b) => node(*b),
    }));
    let gp = &results.gaps;
    let cell = |f: &dyn Fn(usize) -> f64| Values::F64((0..gaps).map(f).collect());
    lines(
        points,
        vec![
            (
                "film_node",
                1,
                Values::I64(model.gaps.iter().map(|g| g.film_node as i64).collect()),
            ),
            ("gap_slip_x", 1, cell(&|k| gp[k].slip_x)),
            ("gap_slip_y", 1, cell(&|k| gp[k].slip_y)),
            ("gap_normal_force", 1, cell(&|k| gp[k].normal_force)),
            ("gap_friction_force", 1, cell(&|k| gp[k].friction_force)),
            (
                "gap_status",
                1,
                Values::I32(gp.iter().map(|g| g.status as i32).collect()),
            ),
        ],
        Some("gap_normal_force"),
    )
    .encode(encoding)
}

/// The `.pvd` collection text listing `(time, file name)` pairs.
pub fn collection(entries: &[(f64, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\">\n<Collection>\n",
    );
    for (t, file) in entries {
        let _ = writeln!(
            s,
            "<DataSet timestep=\"{t}\" part=\"0\" file=\"{}\"/>",
            xml_escape(file)
        );
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    s
}

/// Principal values `[e1 ≥ e2]` of a Voigt strain `[εx, εy, γxy]` (engineering shear).
pub fn principal_strain(strain: [f64; 3]) -> [f64; 2] {
    let centre = 0.5 * (strain[0] + strain[1]);
    let radius = (0.5 * (strain[0] - strain[1])).hypot(0.5 * strain[2]);
    [centre + radius, centre - radius]
}

/// The film's node positions `x + u` (three per node), the film file's points.
pub fn deformed(model: &Model, displacement: &[f64]) -> Vec<f64> {
    model
        .nodes
        .iter()
        .flatten()
        .zip(displacement)
        .map(|(x, u)| x + u)
        .collect()
}

/// The values of one data array.
enum Values {
    F64(Vec<f64>),
    I64(Vec<i64>),
    I32(Vec<i32>),
    U8(Vec<u8>),
}

impl Values {
    fn vtk_type(&self) -> &'static str {
        match self {
            Self::F64(_) => "Float64",
            Self::I64(_) => "Int64",
            Self::I32(_) => "Int32",
            Self::U8(_) => "UInt8",
        }
    }

    /// Appends the values as text, separated by spaces (floats round-trip exactly).
    fn write_ascii(&self, out: &mut String) {
        fn join<T: std::fmt::Display>(out: &mut String, values: &[T]) {
            for (i, v) in values.iter().enumerate() {
                let _ = write!(out, "{}{v}", if i == 0 { "" } else { " " });
            }
        }
        match self {
            Self::F64(v) => {
                for (i, x) in v.iter().enumerate() {
                    let sep = if i == 0 { "" } else { " " };
                    let _ = write!(out, "{sep}{x:e}");
                }
            }
            Self::I64(v) => join(out, v),
            Self::I32(v) => join(out, v),
            Self::U8(v) => join(out, v),
        }
    }

    /// Appends the UInt64 byte count and the little-endian values.
    fn write_raw(&self, out: &mut Vec<u8>) {
        let bytes = match self {
            Self::F64(v) => 8 * v.len(),
            Self::I64(v) => 8 * v.len(),
            Self::I32(v) => 4 * v.len(),
            Self::U8(v) => v.len(),
        };
        out.reserve(8 + bytes);
        out.extend_from_slice(&(bytes as u64).to_le_bytes());
        match self {
            Self::F64(v) => v
                .iter()
                .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
            Self::I64(v) => v
                .iter()
                .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
            Self::I32(v) => v
                .iter()
                .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
            Self::U8(v) => out.extend_from_slice(v),
        }
    }
}

/// One unstructured grid: geometry, cells and named arrays `(name, components, values)`.
/// A grid of line cells (VTK type 3): `points` holds the `n` start points followed by the `n`
/// end points, cell `k` joins point `k` to point `n + k` (gaps, contacts, cable segments).
fn lines(
    points: Vec<f64>,
    cell_data: Vec<(&'static str, usize, Values)>,
    cell_scalars: Option<&'static str>,
) -> Piece {
    let n = (points.len() / 6) as i64;
    Piece {
        points,
        connectivity: (0..n).flat_map(|k| [k, n + k]).collect(),
        offsets: (1..=n).map(|k| 2 * k).collect(),
        types: vec![3; n as usize],
        point_data: Vec::new(),
        cell_data,
        point_vectors: None,
        cell_scalars,
    }
}

struct Piece {
    /// Three coordinates per point.
    points: Vec<f64>,
    connectivity: Vec<i64>,
    offsets: Vec<i64>,
    types: Vec<u8>,
    point_data: Vec<(&'static str, usize, Values)>,
    cell_data: Vec<(&'static str, usize, Values)>,
    /// The active vectors of the point data and scalars of the cell data.
    point_vectors: Option<&'static str>,
    cell_scalars: Option<&'static str>,
}

impl Piece {
    fn encode(self, encoding: Encoding) -> Vec<u8> {
        let mut xml = String::with_capacity(match encoding {
            Encoding::Ascii => 24 * (self.points.len() + 12 * self.types.len()) + 4096,
            Encoding::Binary => 4096,
        });
        let mut appended = Vec::new();
        let mut array = |xml: &mut String, name: Option<&str>, components: usize, v: &Values| {
            let _ = write!(xml, "<DataArray type=\"{}\"", v.vtk_type());
            if let Some(name) = name {
                let _ = write!(xml, " Name=\"{name}\"");
            }
            if components > 1 {
                let _ = write!(xml, " NumberOfComponents=\"{components}\"");
            }
            match encoding {
                Encoding::Ascii => {
                    xml.push_str(" format=\"ascii\">\n");
                    v.write_ascii(xml);
                    xml.push_str("\n</DataArray>\n");
                }
                Encoding::Binary => {
                    let _ = writeln!(xml, " format=\"appended\" offset=\"{}\"/>", appended.len());
                    v.write_raw(&mut appended);
                }
            }
        };
        let cells = self.types.len();
        let _ = write!(
            xml,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
             byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n\
             <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{cells}\">\n<Points>\n",
            self.points.len() / 3
        );
        array(&mut xml, None, 3, &Values::F64(self.points));
        xml.push_str("</Points>\n<Cells>\n");
        array(
            &mut xml,
            Some("connectivity"),
            1,
            &Values::I64(self.connectivity),
        );
        array(&mut xml, Some("offsets"), 1, &Values::I64(self.offsets));
        array(&mut xml, Some("types"), 1, &Values::U8(self.types));
        xml.push_str("</Cells>\n");
        for (tag, attribute, active, arrays) in [
            ("PointData", "Vectors", self.point_vectors, &self.point_data),
            ("CellData", "Scalars", self.cell_scalars, &self.cell_data),
        ] {
            let _ = write!(xml, "<{tag}");
            if let Some(active) = active {
                let _ = write!(xml, " {attribute}=\"{active}\"");
            }
            xml.push_str(">\n");
            for (name, components, values) in arrays {
                array(&mut xml, Some(name), *components, values);
            }
            let _ = writeln!(xml, "</{tag}>");
        }
        xml.push_str("</Piece>\n</UnstructuredGrid>\n");
        let mut out = xml.into_bytes();
        if encoding == Encoding::Binary {
            out.reserve(appended.len() + 64);
            out.extend_from_slice(b"<AppendedData encoding=\"raw\">\n_");
            out.extend_from_slice(&appended);
            out.extend_from_slice(b"\n</AppendedData>\n");
        }
        out.extend_from_slice(b"</VTKFile>\n");
        out
    }
}

fn xml_escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn principal_strains_are_the_mohr_circle_extremes() {
        let [e1, e2] = principal_strain([0.03, 0.01, 0.02]);
        // centre 0.02, radius √(0.01² + 0.01²)
        assert!((e1 - (0.02 + 0.01 * 2f64.sqrt())).abs() < 1e-15);
        assert!((e1 + e2 - 0.04).abs() < 1e-15);
        assert_eq!(principal_strain([0.0, 0.0, 0.0]), [0.0, 0.0]);
    }

    #[test]
    fn encoding_names_parse_back() {
        for e in [Encoding::Ascii, Encoding::Binary] {
            assert_eq!(e.name().parse::<Encoding>(), Ok(e));
        }
        assert!("Binary".parse::<Encoding>().is_err());
    }
}
