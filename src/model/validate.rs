//! Checks of a whole model ([`Model::validate`]) and of one part ([`validate_part`]):
//! every id, reference and property, with errors that name the table, the column, the
//! row and the offending value.

use std::collections::HashMap;

use super::kinds::ElementKind;
use super::types::{Analysis, ElementBlock, Model, TimeLaw};
use super::validate_parts::validate_part;
use super::yarn::HALF;
use crate::error::{Result, WeftError};

/// A model that has passed [`Model::validate`]: only [`Model::validated`] makes one, and
/// it gives the model out read-only (to change it, take it back with
/// [`ValidatedModel::into_model`] and validate again), so a stage that holds one need
/// not check the model again ([`crate::solver::Solver::from_validated`]).
#[derive(Debug, Clone)]
pub struct ValidatedModel(Model);

impl std::ops::Deref for ValidatedModel {
    type Target = Model;
    fn deref(&self) -> &Model {
        &self.0
    }
}

impl ValidatedModel {
    /// The model, to change (it must be validated again).
    pub fn into_model(self) -> Model {
        self.0
    }
}

impl Model {
    /// The model, checked ([`Model::validate`]).
    pub fn validated(self) -> Result<ValidatedModel> {
        self.validate()?;
        Ok(ValidatedModel(self))
    }

    /// Check ids, references and properties. Errors name the part, element or node and
    /// the value (rows refer to the tables' row order).
    pub fn validate(&self) -> Result<()> {
        self.validate_node_ids()?;
        self.validate_initial_displacement()?;
        self.validate_coordinates()?;
        self.validate_parts()?;
        self.validate_elements()?;
        self.validate_node_sets()?;
        self.validate_loads()?;
        self.validate_initial_velocities()?;
        self.validate_projectiles()?;
        self.validate_ties()?;
        self.validate_symmetry()?;
        self.validate_element_columns()?;
        self.validate_link_frames()?;
        self.validate_sliding_links()?;
        self.validate_contacts()?;
        validate_analysis(&self.analysis)
    }

    /// Node ids: unique.
    fn validate_node_ids(&self) -> Result<()> {
        let mut seen = HashMap::new();
        for (row, id) in self.node_id.iter().enumerate() {
            if let Some(first) = seen.insert(*id, row) {
                return Err(WeftError::input(format!(
                    "duplicate node id `{id}` (first at row {first})"
                ))
                .in_file("nodes.parquet")
                .in_column("node_id")
                .at_row(row)
                .expected("unique node ids")
                .hint("renumber the nodes or merge coincident ones"));
            }
        }
        Ok(())
    }

    /// Initial displacements: none, or one finite value per node and axis.
    fn validate_initial_displacement(&self) -> Result<()> {
        if !self.initial_displacement.is_empty()
            && self.initial_displacement.len() != self.coords.len()
        {
            return Err(WeftError::input(format!(
                "{} initial displacements for {} nodes",
                self.initial_displacement.len(),
                self.coords.len()
            ))
            .in_file("nodes.parquet")
            .expected("columns ux0, uy0, uz0 on every row, or none"));
        }
        for (row, u) in self.initial_displacement.iter().enumerate() {
            for (c, v) in ["ux0", "uy0", "uz0"].iter().zip(u) {
                if !v.is_finite() {
                    return Err(WeftError::input(format!(
                        "node `{}` has non-finite initial displacement `{v}`",
                        self.node_id[row]
                    ))
                    .in_file("nodes.parquet")
                    .in_column(*c)
                    .at_row(row)
                    .expected("a finite displacement in m, or null for 0"));
                }
            }
        }
        Ok(())
    }

    /// Coordinates: finite.
    fn validate_coordinates(&self) -> Result<()> {
        for (row, x) in self.coords.iter().enumerate() {
            for (c, v) in ["x", "y", "z"].iter().zip(x) {
                if !v.is_finite() {
                    return Err(WeftError::input(format!(
                        "node `{}` has non-finite coordinate `{v}`",
                        self.node_id[row]
                    ))
                    .in_file("nodes.parquet")
                    .in_column(*c)
                    .at_row(row)
                    .expected("a finite coordinate in m"));
                }
            }
        }
        Ok(())
    }

    /// Parts: unique ids, and each part's properties ([`validate_part`]).
    fn validate_parts(&self) -> Result<()> {
        let mut part_ids = HashMap::new();
        for (row, p) in self.parts.iter().enumerate() {
            if let Some(first) = part_ids.insert(p.id, row) {
                return Err(WeftError::input(format!(
                    "duplicate part id `{}` (first at row {first})",
                    p.id
                ))
                .in_file("parts.parquet")
                .in_column("part_id")
                .at_row(row)
                .expected("unique part ids"));
            }
            validate_part(p).map_err(|e| e.in_file("parts.parquet").at_row(row))?;
        }
        Ok(())
    }

    /// Elements: ids unique across all element tables, each of its part's kind, a
    /// two-node element on two distinct nodes, a truss of non-zero length.
    fn validate_elements(&self) -> Result<()> {
        let mut elem_ids: HashMap<i64, ElementKind> = HashMap::new();
        for (kind, b) in &self.elements {
            let file = format!("elements_{}.parquet", kind.name());
            let npe = kind.nodes_per_element();
            for (row, id) in b.id.iter().enumerate() {
                if let Some(k) = elem_ids.insert(*id, *kind) {
                    return Err(WeftError::input(format!(
                        "duplicate element id `{id}` (also a {} element)",
                        k.name()
                    ))
                    .in_file(&file)
                    .in_column("element_id")
                    .at_row(row)
                    .expected("element ids unique across all element tables"));
                }
                let p = &self.parts[b.part[row]];
                if p.kind != *kind {
                    return Err(WeftError::input(format!(
                        "element `{id}` refers to part `{}` of kind `{}`",
                        p.id,
                        p.kind.name()
                    ))
                    .in_file(&file)
                    .in_column("part_id")
                    .at_row(row)
                    .expected(format!("a part of kind `{}`", kind.name())));
                }
                let ns = &b.nodes[row * npe..(row + 1) * npe];
                if npe == 2 && ns[0] == ns[1] {
                    return Err(WeftError::input(format!(
                        "element `{id}` joins node `{}` to itself",
                        self.node_id[ns[0]]
                    ))
                    .in_file(&file)
                    .in_column("n2")
                    .at_row(row)
                    .expected("two distinct nodes"));
                }
                if *kind == ElementKind::Hex {
                    self.validate_hex(*id, ns, &file, row)?;
                }
                if *kind == ElementKind::Truss {
                    let (a, c) = (self.coords[ns[0]], self.coords[ns[1]]);
                    let l = ((c[0] - a[0]).powi(2) + (c[1] - a[1]).powi(2) + (c[2] - a[2]).powi(2))
                        .sqrt();
                    if l <= 0.0 {
                        return Err(WeftError::input(format!(
                            "truss `{id}` has zero length: nodes `{}` and `{}` coincide",
                            self.node_id[ns[0]], self.node_id[ns[1]]
                        ))
                        .in_file(&file)
                        .at_row(row)
                        .expected("a truss between distinct positions")
                        .hint("use a link between coincident nodes"));
                    }
                }
            }
        }
        Ok(())
    }

    /// A hexahedron: eight distinct nodes, and det J > 0 at every corner (a positive
    /// volume everywhere: nodes 1–4 counter-clockwise seen from the face 5–8).
    fn validate_hex(&self, id: i64, ns: &[usize], file: &str, row: usize) -> Result<()> {
        let ids: Vec<String> = ns
            .iter()
            .map(|&n| format!("`{}`", self.node_id[n]))
            .collect();
        for a in 0..8 {
            if ns[a + 1..].contains(&ns[a]) {
                return Err(WeftError::input(format!(
                    "hexahedron `{id}` uses node `{}` twice (nodes {})",
                    self.node_id[ns[a]],
                    ids.join(", ")
                ))
                .in_file(file)
                .at_row(row)
                .expected(
                    "eight distinct nodes (degenerate hexahedra, wedges, are not supported)",
                ));
            }
        }
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| self.coords[ns[a]]);
        let j = crate::shape::hex8::jacobian_at_nodes(&x);
        if let Some(a) = (0..8).find(|&a| !(j[a] > 0.0)) {
            return Err(WeftError::input(format!(
                "hexahedron `{id}` (nodes {}) has a Jacobian determinant {:.3e} ≤ 0 at its node `{}` (n{})",
                ids.join(", "),
                j[a],
                self.node_id[ns[a]],
                a + 1
            ))
            .in_file(file)
            .at_row(row)
            .expected("a positive volume at every corner: n1–n4 counter-clockwise seen from n5–n8, the face n5–n8 above n1–n4 (LS-DYNA's order)")
            .hint("an inside-out element has its two faces swapped; a folded one, a corner pushed through the opposite face"));
        }
        Ok(())
    }

    /// Node sets: none empty.
    fn validate_node_sets(&self) -> Result<()> {
        for (name, set) in &self.node_sets {
            if set.is_empty() {
                return Err(WeftError::input(format!("node set `{name}` is empty"))
                    .in_file("node_sets.parquet")
                    .expected("at least one node per set"));
            }
        }
        Ok(())
    }

    /// Loads: a finite start, and a duration > 0 for the laws that have one.
    fn validate_loads(&self) -> Result<()> {
        for l in &self.loads {
            let ok = match &l.law {
                TimeLaw::SinePulse { start, duration } | TimeLaw::Ramp { start, duration } => {
                    start.is_finite() && *duration > 0.0
                }
                TimeLaw::Step { start } => start.is_finite(),
                TimeLaw::Tabulated { .. } => true,
            };
            if !ok {
                return Err(WeftError::input(format!(
                    "load `{}` ({}) has a non-positive duration",
                    l.id,
                    l.law.name()
                ))
                .in_file("loads.parquet")
                .in_column("duration")
                .expected("duration > 0 s for sine_pulse and ramp"));
            }
        }
        Ok(())
    }

    /// Initial velocities: zero along the fixed directions.
    fn validate_initial_velocities(&self) -> Result<()> {
        // A node both fixed and given an initial velocity in that direction is a
        // contradiction, not something to resolve silently.
        let mut fixed = vec![[false; 3]; self.num_nodes()];
        for (n, f) in &self.constraints {
            for d in 0..3 {
                fixed[*n][d] |= f[d];
            }
        }
        for (row, (n, v)) in self.initial_velocities.iter().enumerate() {
            for d in 0..3 {
                if fixed[*n][d] && v[d] != 0.0 {
                    return Err(WeftError::input(format!(
                        "node `{}` has fixed {} but initial velocity {} = {}",
                        self.node_id[*n],
                        ["x", "y", "z"][d],
                        ["vx", "vy", "vz"][d],
                        v[d]
                    ))
                    .in_file("initial_velocities.parquet")
                    .at_row(row)
                    .expected("zero initial velocity along fixed directions")
                    .hint("remove the constraint or the velocity"));
                }
            }
        }
        Ok(())
    }

    /// Projectiles: radius and mass > 0, length and friction ≥ 0, a stiffness > 0 when
    /// given, a non-zero axis.
    fn validate_projectiles(&self) -> Result<()> {
        for (row, p) in self.projectiles.iter().enumerate() {
            let bad = |col: &str, v: f64, exp: &str| {
                Err(
                    WeftError::input(format!("projectile `{}` has {col} = `{v}`", p.id))
                        .in_file("projectile.parquet")
                        .in_column(col)
                        .at_row(row)
                        .expected(exp.to_string()),
                )
            };
            if !(p.radius > 0.0 && p.radius.is_finite()) {
                return bad("radius", p.radius, "a radius > 0 in m");
            }
            if !(p.mass > 0.0 && p.mass.is_finite()) {
                return bad("mass", p.mass, "a mass > 0 in kg");
            }
            if !(p.length >= 0.0 && p.length.is_finite()) {
                return bad("length", p.length, "a length ≥ 0 in m");
            }
            if !(p.friction >= 0.0 && p.friction.is_finite()) {
                return bad("friction", p.friction, "μ ≥ 0");
            }
            if !(p.contact_damping >= 0.0 && p.contact_damping <= 1.0) {
                return bad(
                    "contact_damping",
                    p.contact_damping,
                    "a fraction 0 ≤ ζ ≤ 1 of the contact spring's critical damping",
                );
            }
            if let Some(k) = p.contact_stiffness {
                if !(k > 0.0 && k.is_finite()) {
                    return bad(
                        "contact_stiffness",
                        k,
                        "a stiffness > 0 in N/m, or null for the automatic one",
                    );
                }
            }
            let n = (p.axis[0].powi(2) + p.axis[1].powi(2) + p.axis[2].powi(2)).sqrt();
            if !(n > 0.0 && n.is_finite()) {
                return bad(
                    "axis_x",
                    n,
                    "a non-zero axis vector (axis_x, axis_y, axis_z)",
                );
            }
        }
        Ok(())
    }

    /// Ties: 2 to 4 distinct master nodes, none of them the slave or itself tied; each
    /// slave in one tie.
    fn validate_ties(&self) -> Result<()> {
        let mut slave_of = vec![false; self.num_nodes()];
        for t in &self.ties {
            slave_of[t.slave] = true;
        }
        let mut seen_slave = vec![false; self.num_nodes()];
        for (row, t) in self.ties.iter().enumerate() {
            let err = |what: String, exp: &str| {
                Err(WeftError::input(what)
                    .in_file("ties.parquet")
                    .at_row(row)
                    .expected(exp.to_string()))
            };
            let sid = self.node_id[t.slave];
            if !(2..=4).contains(&t.masters.len()) {
                return err(
                    format!("tie of node `{sid}` has {} masters", t.masters.len()),
                    "2 (an edge), 3 or 4 (a face) master nodes",
                );
            }
            if seen_slave[t.slave] {
                return err(
                    format!("node `{sid}` is tied twice"),
                    "each slave node in one tie",
                );
            }
            seen_slave[t.slave] = true;
            for (k, &mn) in t.masters.iter().enumerate() {
                if mn == t.slave || t.masters[..k].contains(&mn) {
                    return err(
                        format!("tie of node `{sid}` repeats node `{}`", self.node_id[mn]),
                        "distinct master nodes, none of them the slave",
                    );
                }
                if slave_of[mn] {
                    return err(
                        format!(
                            "master `{}` of the tie of node `{sid}` is itself tied",
                            self.node_id[mn]
                        ),
                        "masters that are not slaves of other ties (no chains)",
                    );
                }
            }
        }
        Ok(())
    }

    /// Symmetry planes: a finite position and a tolerance ≥ 0.
    fn validate_symmetry(&self) -> Result<()> {
        for (row, s) in self.symmetry.iter().enumerate() {
            if !(s.tolerance >= 0.0 && s.position.is_finite()) {
                return Err(WeftError::input(format!(
                    "symmetry plane has position {} and tolerance {}",
                    s.position, s.tolerance
                ))
                .in_file("symmetry.parquet")
                .at_row(row)
                .expected("a finite position and a tolerance ≥ 0 in m"));
            }
        }
        Ok(())
    }

    /// Per-element columns of the element tables, table by table: initial stresses,
    /// cross-section areas, nodal thicknesses, failure-strain factors, layers and yarns.
    fn validate_element_columns(&self) -> Result<()> {
        for (kind, b) in &self.elements {
            validate_initial_stress(*kind, b)?;
            validate_truss_areas(*kind, b)?;
            validate_nodal_thickness(*kind, b)?;
            validate_failure_factors(*kind, b)?;
            validate_layers_and_yarns(*kind, b)?;
        }
        Ok(())
    }
}

/// Initial stress of a block: on membranes only, one finite value per element and
/// component.
fn validate_initial_stress(kind: ElementKind, b: &ElementBlock) -> Result<()> {
    if b.stress0.is_empty() {
        return Ok(());
    }
    let file = format!("elements_{}.parquet", kind.name());
    if !matches!(kind, ElementKind::Tri | ElementKind::Quad) || b.stress0.len() != b.len() {
        return Err(WeftError::input(format!(
            "{} elements carry {} initial stresses for {} elements",
            kind.name(),
            b.stress0.len(),
            b.len()
        ))
        .in_file(file)
        .expected("initial stress columns s0_11, s0_22, s0_12 on tri and quad tables only"));
    }
    for (e, s) in b.stress0.iter().enumerate() {
        for (c, v) in ["s0_11", "s0_22", "s0_12"].iter().zip(s) {
            if !v.is_finite() {
                return Err(WeftError::input(format!(
                    "{} `{}` has initial stress {c} = `{v}`",
                    kind.name(),
                    b.id[e]
                ))
                .in_file(file.clone())
                .in_column(*c)
                .at_row(e)
                .expected("a finite stress in Pa, or null for 0"));
            }
        }
    }
    Ok(())
}

/// Cross-section areas of a block: on trusses only, one finite value > 0 per element.
fn validate_truss_areas(kind: ElementKind, b: &ElementBlock) -> Result<()> {
    if b.area.is_empty() {
        return Ok(());
    }
    let file = format!("elements_{}.parquet", kind.name());
    if kind != ElementKind::Truss || b.area.len() != b.len() {
        return Err(WeftError::input(format!(
            "{} elements carry {} cross-section areas for {} elements",
            kind.name(),
            b.area.len(),
            b.len()
        ))
        .in_file(file)
        .expected("an area column on the truss table only, one per element"));
    }
    for (e, &a) in b.area.iter().enumerate() {
        if !(a.is_finite() && a > 0.0) {
            return Err(WeftError::input(format!(
                "truss `{}` has cross-section area `{a}`",
                b.id[e]
            ))
            .in_file(file)
            .in_column("area")
            .at_row(e)
            .expected("an area > 0 in m², or null for the part's area"));
        }
    }
    Ok(())
}

/// Failure-strain factors of a block: on kinds that can fail, one finite value > 0 per
/// element.
fn validate_failure_factors(kind: ElementKind, b: &ElementBlock) -> Result<()> {
    if b.failure_factor.is_empty() {
        return Ok(());
    }
    let file = format!("elements_{}.parquet", kind.name());
    let can_fail = matches!(
        kind,
        ElementKind::Truss | ElementKind::Tri | ElementKind::Quad | ElementKind::Link
    );
    if !can_fail || b.failure_factor.len() != b.len() {
        return Err(WeftError::input(format!(
            "{} elements carry {} failure-strain factors for {} elements",
            kind.name(),
            b.failure_factor.len(),
            b.len()
        ))
        .in_file(file)
        .in_column("failure_strain_factor")
        .expected("the column on the truss, link, tri and quad tables only, one per element"));
    }
    for (e, &f) in b.failure_factor.iter().enumerate() {
        if !(f.is_finite() && f > 0.0) {
            return Err(WeftError::input(format!(
                "{} `{}` has failure_strain_factor `{f}`",
                kind.name(),
                b.id[e]
            ))
            .in_file(file)
            .in_column("failure_strain_factor")
            .at_row(e)
            .expected("a factor > 0 on the part's failure strain, or null for 1")
            .hint(
                "a generator's statistical strengths (--weibull-modulus) draw factors around 1",
            ));
        }
    }
    Ok(())
}

/// Layers and yarns of a block: one per element when the column is there, layers ≥ 1.
fn validate_layers_and_yarns(kind: ElementKind, b: &ElementBlock) -> Result<()> {
    let file = format!("elements_{}.parquet", kind.name());
    for (col, v) in [("layer", &b.layer), ("yarn", &b.yarn)] {
        if !v.is_empty() && v.len() != b.len() {
            return Err(WeftError::input(format!(
                "{} elements carry {} {col} values for {} elements",
                kind.name(),
                v.len(),
                b.len()
            ))
            .in_file(file)
            .in_column(col)
            .expected("one per element"));
        }
    }
    for (e, l) in b.layer.iter().enumerate() {
        if let Some(l) = l.filter(|&l| l < 1) {
            return Err(WeftError::input(format!(
                "{} `{}` is in layer `{l}`",
                kind.name(),
                b.id[e]
            ))
            .in_file(file)
            .in_column("layer")
            .at_row(e)
            .expected("a layer number ≥ 1 (1 = the strike face), or null"));
        }
    }
    Ok(())
}

/// Nodal thickness of a block: on membranes only, one finite value ≥ 0 per element node.
fn validate_nodal_thickness(kind: ElementKind, b: &ElementBlock) -> Result<()> {
    if b.thickness.is_empty() {
        return Ok(());
    }
    let npe = kind.nodes_per_element();
    let file = format!("elements_{}.parquet", kind.name());
    if !matches!(kind, ElementKind::Tri | ElementKind::Quad) || b.thickness.len() != npe * b.len() {
        return Err(WeftError::input(format!(
            "{} elements carry {} nodal thicknesses for {} elements",
            kind.name(),
            b.thickness.len(),
            b.len()
        ))
        .in_file(file)
        .expected(
            "nodal thickness columns t1… on tri and quad tables only, one per element node",
        ));
    }
    for (k, &t) in b.thickness.iter().enumerate() {
        if !(t.is_finite() && t >= 0.0) {
            return Err(WeftError::input(format!(
                "{} `{}` has nodal thickness `{t}` at its node {}",
                kind.name(),
                b.id[k / npe],
                k % npe + 1
            ))
            .in_file(file)
            .in_column(format!("t{}", k % npe + 1))
            .at_row(k / npe)
            .expected(
                "a thickness ≥ 0 in m (the element's mean > 0), or null for the part's thickness",
            ));
        }
    }
    Ok(())
}

impl Model {
    /// Sliding links: not in a frame of frame nodes as well, and each end on a yarn
    /// (a chain of trusses) other than the other end's.
    fn validate_sliding_links(&self) -> Result<()> {
        let Some(b) = self.block(ElementKind::Link) else {
            return Ok(());
        };
        let file = "elements_link.parquet";
        let mut nb = None;
        for e in 0..b.len() {
            let part = &self.parts[b.part[e]];
            if part.props.sliding != Some(true) {
                continue;
            }
            let nb = nb.get_or_insert_with(|| self.truss_neighbours());
            let (n1, n2) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
            let mut windows = vec![];
            for (col, n) in [("n1", n1), ("n2", n2)] {
                match self.yarn_window(nb, n, HALF) {
                    Ok(w) => windows.push(w),
                    Err(why) => {
                        return Err(WeftError::input(format!(
                            "sliding link `{}` of part `{}`: {why}",
                            b.id[e], part.name
                        ))
                        .in_file(file)
                        .in_column(col)
                        .at_row(e)
                        .expected("each end of a sliding link on a yarn: a chain of trusses through the node")
                        .hint(format!("join the node to its yarn's trusses, or set `sliding` of part `{}` to null", part.name)));
                    }
                }
            }
            if windows[0].nodes.contains(&n2) {
                return Err(WeftError::input(format!(
                    "sliding link `{}` of part `{}` joins nodes `{}` and `{}` of the same yarn",
                    b.id[e], part.name, self.node_id[n1], self.node_id[n2]
                ))
                .in_file(file)
                .in_column("n2")
                .at_row(e)
                .expected("the two ends on two yarns that cross"));
            }
        }
        Ok(())
    }

    /// Link frame nodes: on link tables only, one set per link; every link whose part
    /// asks for `local_frame` has frame nodes that span a plane at the reference
    /// coordinates (e₁ = x_f2 − x_f1 ≠ 0, not parallel to x_f4 − x_f3).
    fn validate_link_frames(&self) -> Result<()> {
        for (kind, b) in &self.elements {
            let file = format!("elements_{}.parquet", kind.name());
            if !b.frame.is_empty() && (*kind != ElementKind::Link || b.frame.len() != b.len()) {
                return Err(WeftError::input(format!(
                    "{} elements carry {} frame-node sets for {} elements",
                    kind.name(),
                    b.frame.len(),
                    b.len()
                ))
                .in_file(file)
                .expected(
                    "frame node columns f1, f2, f3, f4 on the link table only, one set per link",
                ));
            }
        }
        let Some(b) = self.block(ElementKind::Link) else {
            return Ok(());
        };
        let file = "elements_link.parquet";
        for e in 0..b.len() {
            let part = &self.parts[b.part[e]];
            if part.props.local_frame != Some(true) {
                continue;
            }
            let Some(f) = b.frame.get(e) else {
                return Err(WeftError::input(format!(
                    "link `{}` of part `{}` asks for a local frame but the link table has no frame nodes",
                    b.id[e], part.name
                ))
                .in_file(file)
                .in_column("f1")
                .at_row(e)
                .expected("columns f1, f2, f3, f4: the nodes whose directions f2 − f1 and f4 − f3 span the crossing's plane")
                .hint("give the frame nodes, or set `local_frame` of the part to null (global axes)"));
            };
            let x = |k: usize| self.coords[f[k]];
            let sub = |a: [f64; 3], c: [f64; 3]| [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let (u, w) = (sub(x(0), x(1)), sub(x(2), x(3)));
            let cr = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let (nu, nw, nc) = (norm(u), norm(w), norm(cr));
            if !(nu > 0.0 && nw > 0.0 && nc > 1e-6 * nu * nw) {
                return Err(WeftError::input(format!(
                    "link `{}` has frame nodes `{}`, `{}`, `{}`, `{}` whose directions f2 − f1 and f4 − f3 do not span a plane (sine of their angle {:.1e})",
                    b.id[e],
                    self.node_id[f[0]],
                    self.node_id[f[1]],
                    self.node_id[f[2]],
                    self.node_id[f[3]],
                    if nu > 0.0 && nw > 0.0 { nc / (nu * nw) } else { 0.0 }
                ))
                .in_file(file)
                .in_column("f1")
                .at_row(e)
                .expected("two non-zero, non-parallel directions (the crossing's warp and weft)"));
            }
        }
        Ok(())
    }
}

/// The analysis settings: each within its range.
fn validate_analysis(a: &Analysis) -> Result<()> {
    let err = |col: &str, v: f64, exp: &str| {
        Err(WeftError::input(format!("analysis setting {col} = `{v}`"))
            .in_file("analysis.parquet")
            .in_column(col)
            .expected(exp.to_string()))
    };
    if !(a.end_time > 0.0 && a.end_time.is_finite()) {
        return err("end_time", a.end_time, "a time > 0 s");
    }
    if !(a.output_interval > 0.0 && a.output_interval <= a.end_time) {
        return err(
            "output_interval",
            a.output_interval,
            "0 < output_interval ≤ end_time (s)",
        );
    }
    if a.end_time / a.output_interval > 1e7 {
        return Err(WeftError::input(format!(
            "analysis settings end_time = `{}` s and output_interval = `{}` s give {:.3e} output samples",
            a.end_time,
            a.output_interval,
            a.end_time / a.output_interval
        ))
        .in_file("analysis.parquet")
        .in_column("output_interval")
        .expected("at most 10⁷ output samples")
        .hint("lengthen output_interval, or check end_time"));
    }
    if !(a.dt_safety > 0.0 && a.dt_safety <= 1.0) {
        return err("dt_safety", a.dt_safety, "0 < dt_safety ≤ 1");
    }
    if !(a.mass_damping >= 0.0 && a.mass_damping.is_finite()) {
        return err("mass_damping", a.mass_damping, "α ≥ 0 in 1/s");
    }
    if let Some(dt) = a.time_step {
        if !(dt > 0.0 && dt.is_finite()) {
            return err("time_step", dt, "a step > 0 s, or null for the stable step");
        }
    }
    if let Some(dt) = a.target_time_step {
        if !(dt > 0.0 && dt.is_finite()) {
            return err(
                "target_time_step",
                dt,
                "a step > 0 s, or null for no mass scaling",
            );
        }
    }
    if !(a.max_energy_error > 0.0) {
        return err("max_energy_error", a.max_energy_error, "a fraction > 0");
    }
    Ok(())
}
