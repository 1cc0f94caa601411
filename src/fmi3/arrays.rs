//! The FMI 3.0 interface's arrays: the film's fields at the converged state, the very arrays
//! the VTK files of `results.directory` hold (`mech::results::vtk`), read with
//! `fmi3GetFloat64`/`fmi3GetInt32` like any variable. Their sizes are structural parameters
//! (`UInt64`, fixed: the mesh is the FMU's).
//!
//! | variable | type | size | VTK field |
//! |---|---|---|---|
//! | `film.nodeCount` | UInt64 structural parameter | | number of film nodes |
//! | `film.gapCount` | UInt64 structural parameter | | number of gaps |
//! | `film.displacement` | Float64 output, m | nodeCount × 3 | film `displacement` |
//! | `film.reaction` | Float64 output, N | nodeCount × 3 | film `reaction` (0 at free components) |
//! | `film.gapSlipX`, `film.gapSlipY` | Float64 output, m | gapCount | gaps `gap_slip_x`, `gap_slip_y` |
//! | `film.gapNormalForce` | Float64 output, N | gapCount | gaps `gap_normal_force` |
//! | `film.gapStatus` | Int32 output | gapCount | gaps `gap_status` |
//! | `film.lineReaction` | Float64 output, N/m | nodeCount × 3 | film `line_reaction` (along groups and supports) |
//! | `film.contactCount` | UInt64 structural parameter | | number of curved-support contacts |
//! | `film.contactSlip` | Float64 output, m | contactCount | contacts `contact_slip` |
//! | `film.contactNormalForce` | Float64 output, N | contactCount | contacts `contact_normal_force` |
//! | `film.contactStatus` | Int32 output | contactCount | contacts `contact_status` |
//! | `<line>.linePoints` | UInt64 structural parameter | | nodes of the reaction line of a group or support set |
//! | `<line>.lineReaction` | Float64 output, N/m | linePoints × 3 | film `line_reaction` at the line's nodes, in order along it (the line's own share where lines meet) |
//! | `<line>.linePosition` | Float64 output, m | linePoints × 3 | the film file's points at the line's nodes |
//! | `<line>.lineArc` | Float64 output, m | linePoints | arc length from the line's first node (reference geometry; lines that are one chain of edges only) |
//!
//! Their value references follow the FMI 2.0 table's last one, so the scalars keep theirs, and
//! each field has its own whether the model has it or not (a model without gaps has no gap
//! arrays and no `film.gapCount`, one without curved supports no contact arrays). The lines'
//! (`mech::results::lines`: groups, then support sets, each joined by film edges) follow, four
//! references per line, the arc's reserved where a line is no chain.

use crate::fmi2::description::Description;
use crate::mech::results::lines::{ReactionLine, reaction_lines};
use crate::mech::results::vtk::{deformed, line_reaction_field_of};
use crate::mech::{Model, Results};

/// One array (or structural parameter) of the 3.0 interface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    NodeCount,
    GapCount,
    Displacement,
    Reaction,
    GapSlipX,
    GapSlipY,
    GapNormalForce,
    GapStatus,
    LineReaction,
    ContactCount,
    ContactSlip,
    ContactNormalForce,
    ContactStatus,
    /// The nodes of reaction line k (a structural parameter).
    RailPoints(usize),
    /// Reaction per unit length at each node of line k.
    RailReaction(usize),
    /// Position of each node of line k.
    RailPosition(usize),
    /// Arc length of each node of line k.
    RailArc(usize),
}

/// References per reaction line: points, reaction, position, arc.
const PER_LINE: u32 = 4;

/// Name, FMI 3.0 type, unit, description of each field, in value-reference order (a new field
/// goes at the end: the value references of the others stay).
#[rustfmt::skip]
const FIELDS: [(Field, &str, &str, &str, &str); 13] = [
    (Field::NodeCount, "film.nodeCount", "UInt64", "", "number of film nodes: the rows of film.displacement, film.reaction and film.lineReaction"),
    (Field::GapCount, "film.gapCount", "UInt64", "", "number of gaps: the size of the film.gap* arrays"),
    (Field::Displacement, "film.displacement", "Float64", "m", "displacement of every film node (x, y, z per node), the VTK film field 'displacement'"),
    (Field::Reaction, "film.reaction", "Float64", "N", "restraint force on every film node (x, y, z; 0 at free components), the VTK film field 'reaction'"),
    (Field::GapSlipX, "film.gapSlipX", "Float64", "m", "slip of every gap along its local x, the VTK gaps field 'gap_slip_x'"),
    (Field::GapSlipY, "film.gapSlipY", "Float64", "m", "slip of every gap along its local y, the VTK gaps field 'gap_slip_y'"),
    (Field::GapNormalForce, "film.gapNormalForce", "Float64", "N", "normal force of every gap, the VTK gaps field 'gap_normal_force'"),
    (Field::GapStatus, "film.gapStatus", "Int32", "", "status of every gap (0 open, 1 stick, 2 slip), the VTK gaps field 'gap_status'"),
    (Field::LineReaction, "film.lineReaction", "Float64", "N/m", "reaction per unit length of every film node along the boundary groups and support sets (x, y, z; 0 elsewhere), the VTK film field 'line_reaction'"),
    (Field::ContactCount, "film.contactCount", "UInt64", "", "number of curved-support contacts: the size of the film.contact* arrays"),
    (Field::ContactSlip, "film.contactSlip", "Float64", "m", "slip of every curved-support contact along its support, the VTK contacts field 'contact_slip'"),
    (Field::ContactNormalForce, "film.contactNormalForce", "Float64", "N", "normal force of every curved-support contact, the VTK contacts field 'contact_normal_force'"),
    (Field::ContactStatus, "film.contactStatus", "Int32", "", "status of every curved-support contact (0 open, 1 stick, 2 slip), the VTK contacts field 'contact_status'"),
];

/// A converged state as the arrays read it: what the VTK writer is given.
pub struct State {
    /// Film nodes (the rows of the nodal fields).
    pub nodes: usize,
    /// The displacement vector (3 per film node first).
    pub displacement: Vec<f64>,
    /// The results of the state.
    pub results: Results,
    /// `line_reaction` of the VTK film file.
    pub line_reaction: Vec<f64>,
    /// The reaction lines of the model.
    pub lines: Vec<ReactionLine>,
    /// The film file's points (three per node).
    pub points: Vec<f64>,
}

impl State {
    /// The state of `model` at `displacement` with `results`.
    pub fn new(model: &Model, displacement: Vec<f64>, results: Results) -> Self {
        let lines = reaction_lines(model).0;
        let nodes = model.nodes.len();
        let line_reaction = line_reaction_field_of(nodes, &lines, &results);
        let points = deformed(model, &displacement);
        Self {
            nodes,
            displacement,
            results,
            line_reaction,
            lines,
            points,
        }
    }
}

/// A reaction line as the arrays size it: name, what it is (`group`, `support set`), nodes,
/// whether it is one chain of edges (has an arc length).
#[derive(Clone, Debug)]
struct Line {
    name: String,
    label: &'static str,
    points: usize,
    chain: bool,
}

/// The arrays of one FMU: where their value references start, and the sizes.
#[derive(Clone, Debug)]
pub struct Arrays {
    base: u32,
    nodes: usize,
    gaps: usize,
    contacts: usize,
    lines: Vec<Line>,
}

impl Arrays {
    /// The arrays of the FMU `d` describes.
    pub fn of(d: &Description) -> Self {
        let last = d.variables.iter().map(|v| v.value_reference).max();
        Self {
            base: last.map_or(0, |v| v + 1),
            nodes: d.model.nodes.len(),
            gaps: d.model.gaps.len(),
            contacts: d.model.curved_supports.iter().map(|s| s.nodes.len()).sum(),
            lines: d
                .reaction_lines
                .iter()
                .map(|l| Line {
                    name: l.name.clone(),
                    label: l.kind.label(),
                    points: l.nodes.len(),
                    chain: l.position.is_some(),
                })
                .collect(),
        }
    }

    /// The fields this FMU has, with their value references.
    pub fn fields(&self) -> impl Iterator<Item = (u32, Field)> + '_ {
        let fixed = (FIELDS.iter().zip(self.base..))
            .filter(|((f, ..), _)| self.count(f.sized_by()) != Some(0))
            .map(|((f, ..), vr)| (vr, *f));
        let first = self.base + FIELDS.len() as u32;
        let lines = self.lines.iter().enumerate().flat_map(move |(k, l)| {
            let vr = first + PER_LINE * k as u32;
            let fields = [
                Field::RailPoints(k),
                Field::RailReaction(k),
                Field::RailPosition(k),
                Field::RailArc(k),
            ];
            (vr..).zip(fields).take(if l.chain { 4 } else { 3 })
        });
        fixed.chain(lines)
    }

    /// The field of value reference `vr`, if it is one of the arrays.
    pub fn field(&self, vr: u32) -> Option<Field> {
        self.fields().find(|(r, _)| *r == vr).map(|(_, f)| f)
    }

    /// The value of a structural parameter.
    pub fn count(&self, field: Field) -> Option<u64> {
        match field {
            Field::NodeCount => Some(self.nodes as u64),
            Field::GapCount => Some(self.gaps as u64),
            Field::ContactCount => Some(self.contacts as u64),
            Field::RailPoints(k) => Some(self.lines[k].points as u64),
            _ => None,
        }
    }

    /// Name, FMI 3.0 type, unit and description of `field`.
    fn about(&self, field: Field) -> (String, &'static str, &'static str, String) {
        let line = |k: usize| &self.lines[k];
        let of = |k: usize| format!("{} '{}'", line(k).label, line(k).name);
        match field {
            Field::RailPoints(k) => (
                format!("{}.linePoints", line(k).name),
                "UInt64",
                "",
                format!(
                    "number of nodes on the reaction line of {}: the rows of its lineReaction and \
                     linePosition",
                    of(k)
                ),
            ),
            Field::RailReaction(k) => (
                format!("{}.lineReaction", line(k).name),
                "Float64",
                "N/m",
                format!(
                    "reaction per unit length at each node along {} in order along the line (x, \
                     y, z): the VTK film field 'line_reaction' there, its own share where lines meet",
                    of(k)
                ),
            ),
            Field::RailPosition(k) => (
                format!("{}.linePosition", line(k).name),
                "Float64",
                "m",
                format!(
                    "position of each node along {} (x, y, z, deformed): the VTK film file's points",
                    of(k)
                ),
            ),
            Field::RailArc(k) => (
                format!("{}.lineArc", line(k).name),
                "Float64",
                "m",
                format!(
                    "arc length of each node along {} from its first node (reference geometry)",
                    of(k)
                ),
            ),
            f => {
                let (_, name, kind, unit, description) = FIELDS[f.fixed_index()];
                (name.into(), kind, unit, description.into())
            }
        }
    }

    /// The `<ModelVariables>` elements of the arrays and their structural parameters.
    pub fn xml_variables(&self) -> String {
        let vr_of = |f: Field| self.fields().find(|(_, g)| *g == f).map(|(r, _)| r);
        let mut xml = String::new();
        for (vr, field) in self.fields() {
            let (name, kind, unit, description) = self.about(field);
            let head = format!(
                "    <{kind} name=\"{name}\" valueReference=\"{vr}\" description=\"{description}\""
            );
            if let Some(n) = self.count(field) {
                xml.push_str(&format!(
                    "{head} causality=\"structuralParameter\" variability=\"fixed\" \
                     initial=\"exact\" start=\"{n}\"/>\n"
                ));
                continue;
            }
            let unit = match unit {
                "" => String::new(),
                u => format!(" unit=\"{u}\""),
            };
            let size = vr_of(field.sized_by()).expect("an array comes with its size");
            let columns = match field {
                Field::RailReaction(_) | Field::RailPosition(_) => {
                    "\n      <Dimension start=\"3\"/>"
                }
                _ if field.sized_by() == Field::NodeCount => "\n      <Dimension start=\"3\"/>",
                _ => "",
            };
            let variability = if kind == "Int32" {
                "discrete"
            } else {
                "continuous"
            };
            xml.push_str(&format!(
                "{head} causality=\"output\" variability=\"{variability}\" initial=\"calculated\"{unit}>\n      \
                 <Dimension valueReference=\"{size}\"/>{columns}\n    </{kind}>\n"
            ));
        }
        xml
    }

    /// The units of the fields this FMU has.
    pub fn units(&self) -> Vec<&'static str> {
        let units = self.fields().map(|(_, f)| self.about(f).2);
        units.filter(|u| !u.is_empty()).collect()
    }

    /// The value references of the array outputs (for `<Output>` and `<InitialUnknown>`).
    pub fn outputs(&self) -> Vec<u32> {
        let outputs = self.fields().filter(|(_, f)| self.count(*f).is_none());
        outputs.map(|(vr, _)| vr).collect()
    }
}

impl Field {
    /// The structural parameter that gives the field's (first) size; a parameter's own.
    fn sized_by(self) -> Field {
        use Field::*;
        match self {
            NodeCount | Displacement | Reaction | LineReaction => NodeCount,
            GapCount | GapSlipX | GapSlipY | GapNormalForce | GapStatus => GapCount,
            ContactCount | ContactSlip | ContactNormalForce | ContactStatus => ContactCount,
            RailPoints(k) | RailReaction(k) | RailPosition(k) | RailArc(k) => RailPoints(k),
        }
    }

    /// The row of a field of the film in `FIELDS`.
    fn fixed_index(self) -> usize {
        FIELDS
            .iter()
            .position(|f| f.0 == self)
            .expect("a field of the film")
    }

    /// The values of a Float64 field at a converged state, as the VTK writer takes them.
    pub fn float64(self, state: &State) -> Option<Vec<f64>> {
        let r = &state.results;
        let (gaps, contacts) = (&r.gaps, &r.surface_contacts);
        Some(match self {
            Field::Displacement => state.displacement[..3 * state.nodes].to_vec(),
            Field::Reaction => (0..state.nodes)
                .flat_map(|v| r.node_reactions.get(v).copied().unwrap_or([0.0; 3]))
                .collect(),
            Field::LineReaction => state.line_reaction.clone(),
            Field::GapSlipX => gaps.iter().map(|g| g.slip_x).collect(),
            Field::GapSlipY => gaps.iter().map(|g| g.slip_y).collect(),
            Field::GapNormalForce => gaps.iter().map(|g| g.normal_force).collect(),
            Field::ContactSlip => contacts.iter().map(|c| c.slip).collect(),
            Field::ContactNormalForce => contacts.iter().map(|c| c.normal_force).collect(),
            Field::RailReaction(k) => {
                let reactions = state.lines.get(k)?.reactions(r);
                reactions.iter().flat_map(|q| q.per_length).collect()
            }
            Field::RailPosition(k) => (state.lines.get(k)?.nodes.iter())
                .flat_map(|&v| state.points[3 * v..3 * v + 3].to_vec())
                .collect(),
            Field::RailArc(k) => state.lines.get(k)?.position.clone()?,
            _ => return None,
        })
    }

    /// The values of an Int32 field (status codes, as the VTK writer writes them).
    pub fn int32(self, state: &State) -> Option<Vec<i32>> {
        let r = &state.results;
        match self {
            Field::GapStatus => Some(r.gaps.iter().map(|g| g.status as i32).collect()),
            Field::ContactStatus => {
                Some(r.surface_contacts.iter().map(|c| c.status as i32).collect())
            }
            _ => None,
        }
    }
}
