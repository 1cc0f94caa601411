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
//!
//! Their value references follow the FMI 2.0 table's last one, so the scalars keep theirs; a
//! model without gaps has no gap arrays (and no `film.gapCount`).

use crate::fmi2::description::Description;
use crate::mech::Results;

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
}

/// Name, FMI 3.0 type, unit, description of each field, in value-reference order.
const FIELDS: [(Field, &str, &str, &str, &str); 8] = [
    (
        Field::NodeCount,
        "film.nodeCount",
        "UInt64",
        "",
        "number of film nodes: the rows of film.displacement and film.reaction",
    ),
    (
        Field::GapCount,
        "film.gapCount",
        "UInt64",
        "",
        "number of gaps: the size of the film.gap* arrays",
    ),
    (
        Field::Displacement,
        "film.displacement",
        "Float64",
        "m",
        "displacement of every film node (x, y, z per node), the VTK film field 'displacement'",
    ),
    (
        Field::Reaction,
        "film.reaction",
        "Float64",
        "N",
        "restraint force on every film node (x, y, z; 0 at free components), the VTK film field 'reaction'",
    ),
    (
        Field::GapSlipX,
        "film.gapSlipX",
        "Float64",
        "m",
        "slip of every gap along its local x, the VTK gaps field 'gap_slip_x'",
    ),
    (
        Field::GapSlipY,
        "film.gapSlipY",
        "Float64",
        "m",
        "slip of every gap along its local y, the VTK gaps field 'gap_slip_y'",
    ),
    (
        Field::GapNormalForce,
        "film.gapNormalForce",
        "Float64",
        "N",
        "normal force of every gap, the VTK gaps field 'gap_normal_force'",
    ),
    (
        Field::GapStatus,
        "film.gapStatus",
        "Int32",
        "",
        "status of every gap (0 open, 1 stick, 2 slip), the VTK gaps field 'gap_status'",
    ),
];

/// The arrays of one FMU: where their value references start, and the sizes.
#[derive(Clone, Copy, Debug)]
pub struct Arrays {
    base: u32,
    nodes: usize,
    gaps: usize,
}

impl Arrays {
    /// The arrays of the FMU `d` describes.
    pub fn of(d: &Description) -> Self {
        let last = d.variables.iter().map(|v| v.value_reference).max();
        Self {
            base: last.map_or(0, |v| v + 1),
            nodes: d.model.nodes.len(),
            gaps: d.model.gaps.len(),
        }
    }

    /// The fields this FMU has, with their value references.
    pub fn fields(&self) -> impl Iterator<Item = (u32, Field)> + '_ {
        let gaps = self.gaps > 0;
        (FIELDS.iter().zip(self.base..))
            .filter(move |((f, ..), _)| gaps || !f.is_gap())
            .map(|((f, ..), vr)| (vr, *f))
    }

    /// The field of value reference `vr`, if it is one of the arrays.
    pub fn field(&self, vr: u32) -> Option<Field> {
        self.fields().find(|(r, _)| *r == vr).map(|(_, f)| f)
    }

    /// The number of values of `field` (1 for a structural parameter).
    pub fn len(&self, field: Field) -> usize {
        match field {
            Field::NodeCount | Field::GapCount => 1,
            Field::Displacement | Field::Reaction => 3 * self.nodes,
            _ => self.gaps,
        }
    }

    /// The value of a structural parameter.
    pub fn count(&self, field: Field) -> Option<u64> {
        match field {
            Field::NodeCount => Some(self.nodes as u64),
            Field::GapCount => Some(self.gaps as u64),
            _ => None,
        }
    }

    /// The `<ModelVariables>` elements of the arrays and their structural parameters.
    pub fn xml_variables(&self) -> String {
        let vr_of = |f: Field| self.fields().find(|(_, g)| *g == f).map(|(r, _)| r);
        let mut xml = String::new();
        for (vr, field) in self.fields() {
            let (_, name, kind, unit, description) = FIELDS[field as usize];
            let unit = if unit.is_empty() {
                String::new()
            } else {
                format!(" unit=\"{unit}\"")
            };
            let head = format!(
                "    <{kind} name=\"{name}\" valueReference=\"{vr}\" description=\"{description}\""
            );
            xml.push_str(&match (self.count(field), field) {
                (Some(n), _) => format!("{head} causality=\"structuralParameter\" variability=\"fixed\" initial=\"exact\" start=\"{n}\"/>\n"),
                (None, Field::Displacement | Field::Reaction) => format!(
                    "{head} causality=\"output\" variability=\"continuous\" initial=\"calculated\"{unit}>\n      <Dimension valueReference=\"{}\"/>\n      <Dimension start=\"3\"/>\n    </{kind}>\n",
                    vr_of(Field::NodeCount).expect("always there")
                ),
                (None, _) => {
                    let variability = if kind == "Int32" { "discrete" } else { "continuous" };
                    format!(
                        "{head} causality=\"output\" variability=\"{variability}\" initial=\"calculated\"{unit}>\n      <Dimension valueReference=\"{}\"/>\n    </{kind}>\n",
                        vr_of(Field::GapCount).expect("gap arrays come with the count")
                    )
                }
            });
        }
        xml
    }

    /// The value references of the array outputs (for `<Output>` and `<InitialUnknown>`).
    pub fn outputs(&self) -> Vec<u32> {
        let outputs = self.fields().filter(|(_, f)| self.count(*f).is_none());
        outputs.map(|(vr, _)| vr).collect()
    }
}

impl Field {
    fn is_gap(self) -> bool {
        !matches!(
            self,
            Field::NodeCount | Field::Displacement | Field::Reaction
        )
    }

    /// The values of a Float64 field of a film of `nodes` nodes at the state of `displacement`
    /// and `results`, as the VTK writer takes them.
    pub fn float64(
        self,
        nodes: usize,
        displacement: &[f64],
        results: &Results,
    ) -> Option<Vec<f64>> {
        let gaps = &results.gaps;
        Some(match self {
            Field::Displacement => displacement[..3 * nodes].to_vec(),
            Field::Reaction => (0..nodes)
                .flat_map(|v| results.node_reactions.get(v).copied().unwrap_or([0.0; 3]))
                .collect(),
            Field::GapSlipX => gaps.iter().map(|g| g.slip_x).collect(),
            Field::GapSlipY => gaps.iter().map(|g| g.slip_y).collect(),
            Field::GapNormalForce => gaps.iter().map(|g| g.normal_force).collect(),
            _ => return None,
        })
    }

    /// The values of an Int32 field (the gaps' status codes, as the VTK writer writes them).
    pub fn int32(self, results: &Results) -> Option<Vec<i32>> {
        (self == Field::GapStatus).then(|| results.gaps.iter().map(|g| g.status as i32).collect())
    }
}
