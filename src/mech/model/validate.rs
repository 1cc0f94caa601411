//! Validation of a model: every item is checked before any analysis, and the first problem
//! found is named (an unknown node index, a degenerate triangle, `E ≤ 0`, `ν` outside `[0, 0.5)`,
//! `η` outside `[0, 1)`, a temperature outside 0–50 °C, `μ < 0`, a non-orthonormal gap frame, a duplicate name, a node both
//! constrained and prescribed, a control character in text bound for modelDescription.xml, a
//! rigid-body mode no restraint holds ([`crate::mech::model::restraint`]). Nothing here panics on user input.

use std::collections::HashSet;

use crate::mech::elements::chamber::ChamberGeometry;

use nalgebra::Vector3;

use super::format::*;
use crate::mech::elements::curved_contact::Centreline;
use crate::mech::elements::curved_contact::SurfaceContact;
use crate::mech::elements::gap::FrictionLaw;
use crate::mech::elements::temperature::{TEMPERATURE_RANGE, in_range};
use crate::mech::elements::triangle::{AXIS_NORMAL_COSINE, MembraneTriangle};

impl Model {
    /// The `frame_axis`, when given: a finite direction, not within 5.7° of any triangle's
    /// normal ([`AXIS_NORMAL_COSINE`]).
    fn check_frame_axis(&self) -> Result<(), ModelError> {
        let Some(axis) = self.frame_axis else {
            return Ok(());
        };
        let a = Vector3::from(axis);
        if !(a.iter().all(|v| v.is_finite()) && a.norm() > 0.0) {
            return Err(ModelError::FrameAxis {
                message: format!("{axis:?} is not a direction (finite, not zero)"),
            });
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            let x = tri.map(|v| Vector3::from(self.nodes[v]));
            let normal = (x[1] - x[0]).cross(&(x[2] - x[0])).normalize();
            if normal.dot(&a.normalize()).abs() >= AXIS_NORMAL_COSINE {
                return Err(ModelError::FrameAxis {
                    message: format!(
                        "{axis:?} is within 5.7° of the normal of triangle {t} {tri:?}: its \
                         projection there gives no direction"
                    ),
                });
            }
        }
        Ok(())
    }

    /// Checks every item; the first problem found is returned.
    pub fn validate(&self) -> Result<(), ModelError> {
        self.validate_nodes()?;
        self.validate_material()?;
        self.validate_triangles()?;
        self.check_frame_axis()?;
        let mut names = HashSet::new();
        let constrained = self.validate_supports(&mut names)?;
        self.validate_groups(&mut names, &constrained)?;
        self.validate_gaps(&mut names)?;
        self.validate_loads(&mut names)?;
        self.validate_outputs(&mut names)?;
        self.validate_cables(&mut names)?;
        self.validate_curved_supports(&mut names)?;
        self.validate_chambers(&mut names)?;
        self.validate_orifices(&mut names)?;
        self.validate_layers(&mut names)?;
        self.validate_layer_contacts(&mut names)?;
        self.validate_text()?;
        crate::mech::model::restraint::check(self)
    }

    /// Checks that there are nodes and triangles, that the name is an identifier and every node finite.
    fn validate_nodes(&self) -> Result<(), ModelError> {
        if self.nodes.is_empty() || self.triangles.is_empty() {
            return Err(ModelError::Empty {
                message: "needs at least one node and one triangle".into(),
            });
        }
        if !is_identifier(&self.name) {
            return Err(ModelError::Name {
                item: format!("model name '{}'", self.name),
                message: "must be an identifier ([A-Za-z_][A-Za-z0-9_]*)".into(),
            });
        }
        for (i, p) in self.nodes.iter().enumerate() {
            if p.iter().any(|v| !v.is_finite()) {
                return Err(ModelError::NotFinite {
                    item: format!("node {i}"),
                });
            }
        }
        Ok(())
    }

    /// An unknown-node error unless `node` is a node of the model; `item` names what refers to it.
    fn check_node(&self, item: &dyn Fn() -> String, node: usize) -> Result<(), ModelError> {
        let n = self.nodes.len();
        if node < n {
            Ok(())
        } else {
            Err(ModelError::UnknownNode {
                item: item(),
                node,
                node_count: n,
            })
        }
    }

    /// Checks the material: E, ν, thickness, prestress, η, density, yield stress, temperature.
    fn validate_material(&self) -> Result<(), ModelError> {
        let m = &self.material;
        if !(m.youngs_modulus > 0.0 && m.youngs_modulus.is_finite()) {
            return Err(ModelError::Material {
                message: format!("E = {} must be > 0", message_number(m.youngs_modulus)),
            });
        }
        if !(m.poisson_ratio >= 0.0 && m.poisson_ratio < 0.5) {
            return Err(ModelError::Material {
                message: format!(
                    "ν = {} must lie in [0, 0.5)",
                    message_number(m.poisson_ratio)
                ),
            });
        }
        if !(m.thickness > 0.0 && m.thickness.is_finite()) {
            return Err(ModelError::Material {
                message: format!("thickness = {} must be > 0", message_number(m.thickness)),
            });
        }
        if m.prestress.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::Material {
                message: "prestress must be finite".into(),
            });
        }
        let eta = m.wrinkling_regularisation;
        if !(0.0..1.0).contains(&eta) {
            return Err(ModelError::Material {
                message: format!(
                    "wrinkling_regularisation = {} must lie in [0, 1)",
                    message_number(eta)
                ),
            });
        }
        if !(m.density >= 0.0 && m.density.is_finite()) {
            return Err(ModelError::Material {
                message: format!(
                    "density = {} must be ≥ 0 (kg/m³)",
                    message_number(m.density)
                ),
            });
        }
        if let Some(y) = m.yield_stress
            && !(y > 0.0 && y.is_finite())
        {
            return Err(ModelError::Material {
                message: format!("yield_stress = {} must be > 0 (Pa)", message_number(y)),
            });
        }
        if !in_range(m.temperature) {
            let [low, high] = TEMPERATURE_RANGE;
            return Err(ModelError::Material {
                message: format!(
                    "temperature = {} °C lies outside [{low}, {high}] °C, the range of ETFE's \
                     published temperature relation (docs/mechanics.md § \"Temperature\")",
                    message_number(m.temperature)
                ),
            });
        }
        Ok(())
    }

    /// Checks every triangle: known nodes, three distinct ones, not degenerate.
    fn validate_triangles(&self) -> Result<(), ModelError> {
        for (t, tri) in self.triangles.iter().enumerate() {
            for &v in tri {
                self.check_node(&|| format!("triangle {t}"), v)?;
            }
            let x = tri.map(|v| Vector3::from(self.nodes[v]));
            if tri[0] == tri[1]
                || tri[1] == tri[2]
                || tri[0] == tri[2]
                || MembraneTriangle::new(x).is_err()
            {
                return Err(ModelError::DegenerateTriangle {
                    triangle: t,
                    nodes: *tri,
                });
            }
        }
        Ok(())
    }

    /// Checks the support-set names and the supports' and symmetry planes' nodes; returns
    /// which DOFs of each node they fix.
    fn validate_supports(&self, names: &mut HashSet<String>) -> Result<Vec<[bool; 3]>, ModelError> {
        let mut constrained = vec![[false; 3]; self.nodes.len()];
        for name in self.support_sets() {
            check_name(names, "support set", &name)?;
        }
        for s in &self.supports {
            self.check_node(&|| "support".to_string(), s.node)?;
            for a in &s.fixed {
                constrained[s.node][a.index()] = true;
            }
        }
        for s in &self.symmetry {
            for &v in &s.nodes {
                self.check_node(&|| format!("symmetry plane '{}'", s.name), v)?;
                constrained[v][s.normal.index()] = true;
            }
        }
        Ok(constrained)
    }

    /// Checks the boundary groups (names join the namespace): their fields, known nodes, no
    /// node in two groups, none prescribed where `constrained` fixes it.
    fn validate_groups(
        &self,
        names: &mut HashSet<String>,
        constrained: &[[bool; 3]],
    ) -> Result<(), ModelError> {
        let mut in_group = vec![None::<&str>; self.nodes.len()];
        for g in &self.groups {
            check_name(names, "boundary group", &g.name)?;
            Self::validate_group_fields(g)?;
            let prescribed = g.prescribes();
            for &v in &g.nodes {
                self.check_node(&|| format!("boundary group '{}'", g.name), v)?;
                if let Some(other) = in_group[v] {
                    return Err(ModelError::Conflict {
                        node: v,
                        message: format!("is in boundary groups '{other}' and '{}'", g.name),
                    });
                }
                if (0..3).any(|c| constrained[v][c] && prescribed[c]) {
                    return Err(ModelError::Conflict {
                        node: v,
                        message: format!(
                            "is prescribed by group '{}' and also fixed by a support or symmetry plane",
                            g.name
                        ),
                    });
                }
                in_group[v] = Some(&g.name);
            }
        }
        Ok(())
    }

    /// Checks one boundary group's own fields: nodes listed, a finite target, its components
    /// and hinge.
    fn validate_group_fields(g: &BoundaryGroup) -> Result<(), ModelError> {
        if g.nodes.is_empty() {
            return Err(ModelError::Name {
                item: format!("boundary group '{}'", g.name),
                message: "has no nodes".into(),
            });
        }
        if g.target.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::NotFinite {
                item: format!("boundary group '{}' target", g.name),
            });
        }
        if let Some(axes) = &g.components {
            let listed = axes.len();
            if listed == 0 || g.prescribes().iter().filter(|&&p| p).count() != listed {
                return Err(ModelError::Name {
                    item: format!("boundary group '{}'", g.name),
                    message: "components must list each of \"x\", \"y\", \"z\" at most once, and at least one"
                        .into(),
                });
            }
        }
        if let Some(h) = &g.hinge {
            Self::validate_hinge(&g.name, h)?;
        }
        Ok(())
    }

    /// Checks a group's hinge: finite, a non-zero axis, a target angle within two turns.
    fn validate_hinge(group: &str, h: &Hinge) -> Result<(), ModelError> {
        let item = || format!("boundary group '{group}' hinge");
        if h.point.iter().chain(&h.axis).any(|v| !v.is_finite()) || !h.target_angle.is_finite() {
            return Err(ModelError::NotFinite { item: item() });
        }
        if Vector3::from(h.axis).norm() == 0.0 {
            return Err(ModelError::Name {
                item: item(),
                message: "axis is the zero vector".into(),
            });
        }
        if h.target_angle.abs() > Hinge::MAX_ANGLE {
            return Err(ModelError::Name {
                item: item(),
                message: format!(
                    "target_angle {} rad is beyond two full turns ({:.4} rad)",
                    h.target_angle,
                    Hinge::MAX_ANGLE
                ),
            });
        }
        Ok(())
    }

    /// Checks the gaps (names join the namespace), each by [`Self::validate_gap`].
    fn validate_gaps(&self, names: &mut HashSet<String>) -> Result<(), ModelError> {
        let size = crate::mech::model::bounding_diagonal(&self.nodes);
        for gap in &self.gaps {
            check_name(names, "gap", &gap.name)?;
            self.validate_gap(gap, size)?;
        }
        Ok(())
    }

    /// Checks one gap: its nodes or point, an orthonormal frame, positive stiffnesses, μ, and
    /// an initial gap the geometry agrees with (within a fraction of the model's `size`).
    fn validate_gap(&self, gap: &GapSpec, size: f64) -> Result<(), ModelError> {
        let bad = |message: String| ModelError::Gap {
            gap: gap.name.clone(),
            message,
        };
        self.check_node(&|| format!("gap '{}' film_node", gap.name), gap.film_node)?;
        match &gap.support {
            GapSupport::Node(b) => {
                self.check_node(&|| format!("gap '{}' support node", gap.name), *b)?;
                if *b == gap.film_node {
                    return Err(bad("support node equals film node".into()));
                }
            }
            GapSupport::Point(p) => {
                if p.iter().any(|v| !v.is_finite()) {
                    return Err(bad("support point is not finite".into()));
                }
            }
        }
        let frame_values = gap.frame.x.iter().chain(&gap.frame.y).chain(&gap.frame.z);
        if frame_values.clone().any(|v| !v.is_finite()) || gap.frame.orthonormality_error() > 1e-6 {
            return Err(bad(format!(
                "frame is not orthonormal and right-handed with y = z × x (error {:.2e})",
                gap.frame.orthonormality_error()
            )));
        }
        let positive = |v: f64| v > 0.0 && v.is_finite();
        if !positive(gap.normal_stiffness) {
            return Err(bad(format!(
                "normal_stiffness = {} must be > 0",
                gap.normal_stiffness
            )));
        }
        if !positive(gap.tangential_stiffness) {
            return Err(bad(format!(
                "tangential_stiffness = {} must be > 0",
                gap.tangential_stiffness
            )));
        }
        if !(gap.friction >= 0.0 && gap.friction <= MAX_FRICTION) {
            return Err(bad(format!(
                "friction μ = {} must lie in [0, {MAX_FRICTION}]",
                gap.friction
            )));
        }
        if !(gap.initial_gap >= 0.0 && gap.initial_gap.is_finite()) {
            return Err(bad(format!(
                "initial_gap = {} must be ≥ 0",
                gap.initial_gap
            )));
        }
        let distance = gap.geometric_gap(&self.nodes);
        let tolerance = GAP_GEOMETRY_TOLERANCE * size;
        if (distance - gap.initial_gap).abs() > tolerance {
            return Err(bad(format!(
                "initial_gap = {} m contradicts the geometry: the film node lies {distance:.6} m \
                 from the support along the gap's z (the difference is beyond {tolerance:.2e} m, \
                 {GAP_GEOMETRY_TOLERANCE} of the model's size{}); correct initial_gap, the \
                 support or the frame",
                gap.initial_gap,
                if distance < 0.0 {
                    ", and the node starts inside the support"
                } else {
                    ""
                }
            )));
        }
        Ok(())
    }

    /// Checks the text bound for modelDescription.xml: the description and symmetry-plane names.
    fn validate_text(&self) -> Result<(), ModelError> {
        check_xml_text("model description", &self.description)?;
        for s in &self.symmetry {
            check_xml_text(
                &format!("symmetry plane name '{}'", s.name.escape_debug()),
                &s.name,
            )?;
        }
        Ok(())
    }

    /// Checks an element selection: a non-empty list of existing triangles, each once.
    fn check_selection(&self, selection: &ElementSelection) -> Result<(), String> {
        let ElementSelection::List(list) = selection else {
            return Ok(());
        };
        if list.is_empty() {
            return Err("has no elements (write \"all\" for every triangle)".into());
        }
        let mut seen = HashSet::new();
        for &e in list {
            if e >= self.triangles.len() {
                return Err(format!(
                    "triangle {e} does not exist (the model has {} triangles, 0-based)",
                    self.triangles.len()
                ));
            }
            if !seen.insert(e) {
                return Err(format!("lists triangle {e} twice"));
            }
        }
        Ok(())
    }

    /// Checks the `outputs` section; its names join the gap and group namespace.
    fn validate_outputs(&self, names: &mut HashSet<String>) -> Result<(), ModelError> {
        for p in &self.outputs.points {
            check_name(names, "output point", &p.name)?;
            if p.node >= self.nodes.len() {
                return Err(ModelError::UnknownNode {
                    item: format!("output point '{}'", p.name),
                    node: p.node,
                    node_count: self.nodes.len(),
                });
            }
        }
        for set in &self.outputs.element_sets {
            check_name(names, "element set", &set.name)?;
            self.check_selection(&set.elements)
                .map_err(|message| ModelError::Output {
                    item: format!("element set '{}'", set.name),
                    message,
                })?;
        }
        Ok(())
    }

    /// Checks the `cables` section; cable names join the namespace.
    fn validate_curved_supports(&self, names: &mut HashSet<String>) -> Result<(), ModelError> {
        let mut in_triangle = vec![false; self.nodes.len()];
        for t in &self.triangles {
            for &v in t {
                if let Some(x) = in_triangle.get_mut(v) {
                    *x = true;
                }
            }
        }
        for s in &self.curved_supports {
            check_name(names, "curved support", &s.name)?;
            let bad = |message: String| ModelError::Gap {
                gap: format!("curved support '{}'", s.name),
                message,
            };
            let axis_line = match &s.centreline {
                Centreline::Parabola { .. } | Centreline::Polyline { .. } => None,
                Centreline::Line { point, axis } => Some((*point, *axis, None)),
                Centreline::Circle {
                    centre,
                    axis,
                    radius,
                    angles,
                    start_direction,
                } => {
                    if !(*radius > 0.0 && radius.is_finite()) {
                        return Err(bad(format!("centreline radius = {radius} must be > 0")));
                    }
                    let finite = angles
                        .iter()
                        .flatten()
                        .chain(start_direction.iter().flatten());
                    if finite.clone().any(|v| !v.is_finite()) {
                        return Err(bad("angles or start_direction not finite".into()));
                    }
                    if let Some([lo, hi]) = angles
                        && lo >= hi
                    {
                        return Err(bad(format!("angles [{lo}, {hi}] must increase")));
                    }
                    if let Some(d) = start_direction {
                        let (d, a) = (Vector3::from(*d), Vector3::from(*axis));
                        if (d - a * (a.dot(&d) / a.norm_squared())).norm()
                            < 1e-9 * d.norm().max(1.0)
                        {
                            return Err(bad("start_direction is parallel to the axis".into()));
                        }
                    }
                    Some((*centre, *axis, Some(*radius)))
                }
            };
            if let Some((point, axis, _)) = axis_line {
                if point.iter().chain(&axis).any(|v| !v.is_finite()) {
                    return Err(bad("centreline point or axis not finite".into()));
                }
                if Vector3::from(axis).norm() == 0.0 {
                    return Err(bad("centreline axis is the zero vector".into()));
                }
            }
            let positive = |v: f64| v > 0.0 && v.is_finite();
            for (what, v) in [
                ("tube_radius", s.tube_radius),
                ("normal_stiffness", s.normal_stiffness),
                ("tangential_stiffness", s.tangential_stiffness),
            ] {
                if !positive(v) {
                    return Err(bad(format!("{what} = {v} must be > 0")));
                }
            }
            if !(s.friction >= 0.0 && s.friction <= MAX_FRICTION) {
                return Err(bad(format!(
                    "friction μ = {} must lie in [0, {MAX_FRICTION}]",
                    s.friction
                )));
            }
            s.centreline.check(s.tube_radius).map_err(bad)?;
            if s.nodes.is_empty() {
                return Err(bad("lists no nodes".into()));
            }
            for &v in &s.nodes {
                let Some(x) = self.nodes.get(v) else {
                    return Err(ModelError::UnknownNode {
                        item: format!("curved support '{}'", s.name),
                        node: v,
                        node_count: self.nodes.len(),
                    });
                };
                if !in_triangle[v] {
                    return Err(bad(format!("node {v} belongs to no triangle")));
                }
                let x = Vector3::from(*x);
                if let Some((point, axis, ring)) = axis_line {
                    let (rel, a) = (x - Vector3::from(point), Vector3::from(axis).normalize());
                    let rho = (rel - a * a.dot(&rel)).norm();
                    if rho < 1e-9 * ring.unwrap_or(s.tube_radius) {
                        return Err(bad(format!(
                            "node {v} lies on the centreline's axis: its closest point is \
                             undefined"
                        )));
                    }
                }
                let distance = SurfaceContact::new(s, v).project(&x, 0.0).gap + s.tube_radius;
                if distance.is_nan() || distance < 1e-9 * s.tube_radius {
                    return Err(bad(format!(
                        "node {v} lies on the centreline: its normal is undefined"
                    )));
                }
            }
        }
        Ok(())
    }

    fn validate_cables(&self, names: &mut HashSet<String>) -> Result<(), ModelError> {
        if self.cables.is_empty() {
            return Ok(());
        }
        let edges = self.edge_triangles();
        for c in &self.cables {
            check_name(names, "cable", &c.name)?;
            let item = || format!("cable '{}'", c.name);
            let bad = |message: String| ModelError::Output {
                item: item(),
                message,
            };
            if c.nodes.len() < 2 {
                return Err(bad("needs at least two nodes".into()));
            }
            for &v in &c.nodes {
                if v >= self.nodes.len() {
                    return Err(ModelError::UnknownNode {
                        item: item(),
                        node: v,
                        node_count: self.nodes.len(),
                    });
                }
            }
            for (what, v) in [("area", c.area), ("youngs_modulus", c.youngs_modulus)] {
                if !(v > 0.0 && v.is_finite()) {
                    return Err(bad(format!("{what} = {v} must be > 0")));
                }
            }
            if !(c.prestress_force >= 0.0 && c.prestress_force.is_finite()) {
                return Err(bad(format!(
                    "prestress_force = {} must be ≥ 0 (N; a cable carries no compression)",
                    c.prestress_force
                )));
            }
            for pair in c.nodes.windows(2) {
                if !edges.contains_key(&[pair[0], pair[1]]) {
                    return Err(bad(format!(
                        "nodes {} and {} are not an edge of one triangle: a cable runs along film edges",
                        pair[0], pair[1]
                    )));
                }
            }
        }
        Ok(())
    }

    /// Checks the `chambers` section (names join the namespace): finite pressure, κ in
    /// [1, 5/3], a positive atmosphere, known triangles, and a boundary that closes and can
    /// be oriented ([`ChamberGeometry::new`]).
    fn validate_chambers(&self, names: &mut HashSet<String>) -> Result<(), ModelError> {
        for c in &self.chambers {
            check_name(names, "chamber", &c.name)?;
            let error = |message: String| ModelError::Load {
                item: format!("chamber '{}'", c.name),
                message,
            };
            if !c.pressure.is_finite() {
                return Err(error("pressure must be finite".into()));
            }
            if !(1.0..=5.0 / 3.0).contains(&c.kappa) {
                return Err(error(format!(
                    "kappa = {} must be within [1, 5/3]",
                    c.kappa
                )));
            }
            if !(c.atmosphere > 0.0 && c.atmosphere.is_finite()) {
                return Err(error(format!("atmosphere = {} must be > 0", c.atmosphere)));
            }
            if !(c.temperature > 0.0 && c.temperature.is_finite()) {
                return Err(error(format!(
                    "temperature = {} K must be > 0",
                    c.temperature
                )));
            }
            if !(c.heating.is_finite() && c.temperature + c.heating > 0.0) {
                return Err(error(format!(
                    "heating = {} K must leave the air above 0 K",
                    c.heating
                )));
            }
            if c.pressure + c.atmosphere <= 0.0 {
                return Err(error("the absolute pressure must be positive".into()));
            }
            self.check_selection(&c.elements).map_err(error)?;
            ChamberGeometry::new(self, c).map_err(error)?;
        }
        Ok(())
    }

    /// Checks the `orifices` section (names join the namespace): two different known chambers,
    /// a positive, finite area and a discharge coefficient in (0, 1].
    fn validate_orifices(&self, names: &mut HashSet<String>) -> Result<(), ModelError> {
        for o in &self.orifices {
            check_name(names, "orifice", &o.name)?;
            let error = |message: String| ModelError::Load {
                item: format!("orifice '{}'", o.name),
                message,
            };
            for end in [&o.from, &o.to] {
                if !self.chambers.iter().any(|c| &c.name == end) {
                    return Err(error(format!("'{end}' is not a chamber")));
                }
            }
            if o.from == o.to {
                return Err(error(format!(
                    "from and to are both chamber '{}': it must join two chambers",
                    o.from
                )));
            }
            if !(o.area > 0.0 && o.area.is_finite()) {
                return Err(error(format!("area = {} m² must be > 0", o.area)));
            }
            if !(o.discharge_coefficient > 0.0 && o.discharge_coefficient <= 1.0) {
                return Err(error(format!(
                    "discharge_coefficient = {} must be within (0, 1]",
                    o.discharge_coefficient
                )));
            }
        }
        Ok(())
    }

    /// Checks the `layers` section (names join the namespace): a positive, finite thickness,
    /// known triangles, and no triangle in two layers.
    fn validate_layers(&self, names: &mut HashSet<String>) -> Result<(), ModelError> {
        let mut owner: Vec<Option<&str>> = vec![None; self.triangles.len()];
        for l in &self.layers {
            check_name(names, "layer", &l.name)?;
            let error = |message: String| ModelError::Load {
                item: format!("layer '{}'", l.name),
                message,
            };
            if !(l.thickness > 0.0 && l.thickness.is_finite()) {
                return Err(error(format!(
                    "thickness = {} must be > 0 (m)",
                    message_number(l.thickness)
                )));
            }
            self.check_selection(&l.elements).map_err(error)?;
            for e in self.selected_triangles(&l.elements) {
                if let Some(other) = owner[e].replace(&l.name) {
                    return Err(error(format!(
                        "triangle {e} is also in layer '{other}': a triangle has one thickness"
                    )));
                }
            }
        }
        Ok(())
    }

    /// Checks the `layer_contacts` section (names join the namespace): known layers or
    /// triangles on both sides, no triangle on both, positive finite penalties and search
    /// reach, `μ ≥ 0`, and the isotropic friction law.
    fn validate_layer_contacts(&self, names: &mut HashSet<String>) -> Result<(), ModelError> {
        use crate::mech::elements::layer_contact::{LayerContactSpec, LayerSurface};
        for c in &self.layer_contacts {
            check_name(names, "layer contact", &c.name)?;
            let error = |message: String| ModelError::Load {
                item: format!("layer contact '{}'", c.name),
                message,
            };
            let mut sides = Vec::new();
            for (which, surface) in [("slave", &c.slave), ("master", &c.master)] {
                if let LayerSurface::Triangles(list) = surface {
                    self.check_selection(&ElementSelection::List(list.clone()))
                        .map_err(|m| error(format!("{which} {m}")))?;
                }
                let list = LayerContactSpec::triangles(self, surface)
                    .map_err(|m| error(format!("{which} {m}")))?;
                sides.push(list.into_iter().collect::<HashSet<_>>());
            }
            if let Some(t) = sides[0].intersection(&sides[1]).min() {
                return Err(error(format!(
                    "triangle {t} is in both the slave and the master layer"
                )));
            }
            for (what, v) in [
                ("normal_stiffness", c.normal_stiffness),
                ("tangential_stiffness", c.tangential_stiffness),
                ("search_distance", c.search_distance),
            ] {
                if !(v > 0.0 && v.is_finite()) {
                    return Err(error(format!("{what} = {} must be > 0", message_number(v))));
                }
            }
            if !(c.friction >= 0.0 && c.friction.is_finite()) {
                return Err(error(format!(
                    "friction = {} must be ≥ 0",
                    message_number(c.friction)
                )));
            }
            if c.friction_law != FrictionLaw::Isotropic {
                return Err(error(format!(
                    "friction_law '{}' has a sliding direction, which film on film has not: \
                     use 'isotropic'",
                    c.friction_law
                )));
            }
        }
        Ok(())
    }

    /// Checks the `loads` section; set names join the gap and group namespace.
    fn validate_loads(&self, names: &mut HashSet<String>) -> Result<(), ModelError> {
        let l = &self.loads;
        if l.gravity.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::NotFinite {
                item: "loads gravity".into(),
            });
        }
        for p in &l.pressures {
            check_name(names, "pressure set", &p.name)?;
            let item = || format!("pressure set '{}'", p.name);
            if !p.pressure.is_finite() {
                return Err(ModelError::NotFinite {
                    item: format!("{} pressure", item()),
                });
            }
            self.check_selection(&p.elements)
                .map_err(|message| ModelError::Load {
                    item: item(),
                    message,
                })?;
            crate::mech::elements::load::check_towards(self, p).map_err(|message| {
                ModelError::Load {
                    item: item(),
                    message,
                }
            })?;
        }
        for f in &l.forces {
            check_name(names, "force set", &f.name)?;
            let item = || format!("force set '{}'", f.name);
            if f.force.iter().any(|v| !v.is_finite()) {
                return Err(ModelError::NotFinite {
                    item: format!("{} force", item()),
                });
            }
            if f.nodes.is_empty() {
                return Err(ModelError::Load {
                    item: item(),
                    message: "has no nodes".into(),
                });
            }
            let mut seen = HashSet::new();
            for &v in &f.nodes {
                if v >= self.nodes.len() {
                    return Err(ModelError::UnknownNode {
                        item: item(),
                        node: v,
                        node_count: self.nodes.len(),
                    });
                }
                if !seen.insert(v) {
                    return Err(ModelError::Load {
                        item: item(),
                        message: format!("lists node {v} twice"),
                    });
                }
            }
        }
        Ok(())
    }
}

/// Refuses text that modelDescription.xml could not carry: control characters (tab, line feed
/// and carriage return excepted) and the non-characters U+FFFE, U+FFFF (XML 1.0 `Char`).
pub fn check_xml_text(field: &str, text: &str) -> Result<(), ModelError> {
    let bad = text.char_indices().find(|&(_, c)| {
        (c.is_control() && !matches!(c, '\t' | '\n' | '\r')) || matches!(c, '\u{FFFE}' | '\u{FFFF}')
    });
    match bad {
        None => Ok(()),
        Some((at, c)) => Err(ModelError::Text {
            field: field.to_string(),
            message: format!(
                "character U+{:04X} at byte {at} is a control character that modelDescription.xml cannot carry",
                c as u32
            ),
        }),
    }
}

fn check_name(names: &mut HashSet<String>, kind: &str, name: &str) -> Result<(), ModelError> {
    let item = format!("{kind} '{name}'");
    if !is_identifier(name) {
        return Err(ModelError::Name {
            item,
            message: "name must be an identifier ([A-Za-z_][A-Za-z0-9_]*)".into(),
        });
    }
    if !names.insert(name.to_string()) {
        return Err(ModelError::Name {
            item,
            message:
                "name is used twice (gap, group, load-set and output names share one namespace)"
                    .into(),
        });
    }
    Ok(())
}
