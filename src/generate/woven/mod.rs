//! `woven`: the yarn-level plain-weave patch (the paper's §2 reference model; Barauskas &
//! Abraitienė, IJIE 34(7), 2007): every yarn a band of orthotropic membrane quads whose
//! nodal thickness follows the lenticular cross-section, warp along x, weft along y,
//! crimped over and under each other, yarn–yarn contact with friction within and between
//! layers, a rigid projectile against the band faces.
//!
//! Glossary: p yarn spacing; w, h yarn width and thickness; R = (w² + h²)/(4h) the radius
//! of the two circular arcs of the lenticular section; t(y) = 2(√(R² − y²) − R + h/2) the
//! thickness at distance y from the band's centre line (0 at the edges, h at the centre);
//! A = 2[R² acos((R − h/2)/R) − (R − h/2)√(R² − (R − h/2)²)] its exact area (≈ (2/3)wh);
//! a the crimp amplitude: the warp at y_j = jp follows z = (−1)^j a cos(πx/p), the weft at
//! x_i = ip follows z = −(−1)^i a cos(πy/p), so that they alternate over and under at
//! every crossing (a plain weave, symmetric about x = 0 and y = 0: the quarter model has
//! symmetry planes there, through the centre lines of the middle yarns). The full patch
//! has its yarns at (j + ½)p and the phase x − p/2, so that its crests too lie at the
//! crossings.
//!
//! Discretisation: `per_spacing` quads per spacing along, `across` quads across the width.
//! A one-point quad takes the mean of its nodal thicknesses, which under-integrates the
//! lenticular profile (by 25 % with 2 quads across, 6 % with 4): the nodal thicknesses are
//! scaled by A/A_h so that the band's area, hence its mass and axial stiffness E·A, are
//! exact; the contact envelope is then that much thicker at the centre line (reported as
//! `thickness_scale`). Crimp: by default a = t_c/2 + 1 nm, with t_c the (scaled) centre
//! thickness, so that crossing yarns just touch at their centre lines; a larger
//! `crimp_amplitude` leaves a gap that a formed weave would close.
//!
//! Chains (`yarn_model`, the second representation): each yarn the chain of its band's
//! centre-line nodes joined by trusses of the band's exact section A (A/2 on a symmetry
//! plane), so the same mass and axial stiffness E·A; their contact thickness is t_c, the
//! band's centre thickness (nodes and segments); the default crimp amplitude is the
//! smallest at which the straight chords leaving a crossing stay t_c + 2 nm from the node
//! above them ([`chain_touching_amplitude`]: 0.5 % above t_c/2); the projectile's nose
//! grows by t_c/2 about the same centre, since it meets the chains' nodes.
//!
//! The yarns start stress-free in this geometric crimp; `weft-form` (`crate::form`) forms
//! the weave by contact equilibrium under a residual tension.

mod params;
mod section;
mod yarns;

pub use params::{Edge, StrengthPer, Surround, WovenBandParams, YarnFailure, YarnModel};
pub use section::{chain_touching_amplitude, Lenticular};
use section::{crimp_amplitude, crimp_of, Section};
use yarns::{add_layer, insert_sets, Built, Weave};

use crate::error::{Result, WeftError};
use crate::generate::failure::check_delay_and_damping;
use crate::generate::surround::{
    coarse_membrane_at, fail_membranes, graded_lines, tie_to_hole, MembraneProps, Sheet,
};
use crate::model::contacts::{ContactDef, Slave};
use crate::model::striker::check_striking_speed;
use crate::model::{Analysis, ElementKind, Model, ProjectileSpec, SymmetryPlane};

/// What the generator reports besides the model.
#[derive(Debug, Clone)]
pub struct WovenInfo {
    /// Nodal thickness scale A/A_h (see the module docs).
    pub thickness_scale: f64,
    /// Crimp amplitude used [m] and the resulting crimp (path length/spacing − 1).
    pub crimp_amplitude: f64,
    pub crimp: f64,
    /// Exact section area [m²] and areal density of one layer [kg/m²].
    pub area: f64,
    pub areal_density: f64,
    /// The yarns' contact thickness: the bands' centre thickness t_c [m].
    pub contact_thickness: f64,
    /// The distance between layers' mid-planes [m].
    pub layer_pitch: f64,
}

fn check(p: &WovenBandParams) -> Result<()> {
    let bad = |name: &str, v: String, exp: &str| {
        Err(WeftError::input(format!("--{name} = `{v}`")).expected(exp.to_string()))
    };
    for (n, v) in [
        ("spacing", p.spacing),
        ("width", p.width),
        ("thickness", p.thickness),
        ("modulus", p.modulus),
        ("transverse-modulus", p.transverse_modulus),
        ("shear-modulus", p.shear_modulus),
        ("density", p.density),
        ("projectile-radius", p.projectile_radius),
        ("projectile-mass", p.projectile_mass),
        ("end-time", p.end_time),
        ("output-interval", p.output_interval),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            return bad(n, v.to_string(), "a finite value > 0");
        }
    }
    if !(p.yarns as f64 * p.spacing).is_finite() {
        return bad(
            "spacing",
            p.spacing.to_string(),
            "a spacing whose patch, yarns × spacing, is finite",
        );
    }
    if p.yarns == 0 || (!p.quarter && p.yarns % 2 != 0) {
        return bad(
            "yarns",
            p.yarns.to_string(),
            "≥ 1 (quarter), or even ≥ 2 (full patch)",
        );
    }
    if p.width >= p.spacing {
        return Err(WeftError::input(format!(
            "yarn width {} m is not below the spacing {} m",
            p.width, p.spacing
        ))
        .expected("w < p: neighbouring yarns would overlap")
        .hint("lower --width or raise --spacing"));
    }
    if p.thickness >= p.width {
        return Err(WeftError::input(format!(
            "yarn thickness {} m is not below its width {} m",
            p.thickness, p.width
        ))
        .expected("h < w: a lenticular section is flatter than a circle"));
    }
    if p.per_spacing < 4 || p.per_spacing % 2 != 0 {
        return bad(
            "per-spacing",
            p.per_spacing.to_string(),
            "an even number ≥ 4 (a node at every crossing and midway)",
        );
    }
    if p.across < 2 || p.across % 2 != 0 {
        return bad(
            "across",
            p.across.to_string(),
            "an even number ≥ 2 (a node on the centre line)",
        );
    }
    if p.layers == 0 {
        return bad("layers", "0".into(), "≥ 1");
    }
    for (flag, v, what) in [
        ("friction", p.friction, "a Coulomb coefficient ≥ 0"),
        (
            "projectile-friction",
            p.projectile_friction,
            "a Coulomb coefficient ≥ 0",
        ),
        ("layer-gap", p.layer_gap, "a clearance ≥ 0 in m"),
    ] {
        if !(v >= 0.0) {
            return bad(flag, v.to_string(), what);
        }
    }
    if !(p.dt_safety > 0.0 && p.dt_safety <= 1.0) {
        return bad(
            "dt-safety",
            p.dt_safety.to_string(),
            "a safety factor 0 < f ≤ 1 on the stable step",
        );
    }
    check_striking_speed("--projectile-velocity", p.projectile_velocity)?;
    check_failure(&p.failure)
}

/// The yarn failure's parameters: a finite failure strain ≥ 0 (0: none), a Weibull
/// modulus and gauge length > 0, a rate law with C ≥ 0 and ε̇₀ > 0, a delay ≥ 0 and a
/// contact damping in [0, 1].
fn check_failure(f: &YarnFailure) -> Result<()> {
    let bad = |name: &str, v: f64, exp: &str| {
        Err(WeftError::input(format!("--{name} = `{v}`")).expected(exp.to_string()))
    };
    if !(f.strain.is_finite() && f.strain >= 0.0) {
        return bad(
            "failure-strain",
            f.strain,
            "a failure strain ≥ 0 along the yarn (0: no failure; aramid yarn: 0.036)",
        );
    }
    if let Some(m) = f.weibull_modulus {
        if !(m.is_finite() && m > 0.0) {
            return bad(
                "weibull-modulus",
                m,
                "a Weibull modulus m > 0 (aramid yarns: 8–22), or leave it out for equal strengths",
            );
        }
        if f.strain == 0.0 {
            return Err(WeftError::input(format!(
                "--weibull-modulus {m} without a failure strain"
            ))
            .expected("--failure-strain > 0: the Weibull scale the strengths are drawn about"));
        }
    }
    if let Some(l) = f.gauge_length {
        if !(l.is_finite() && l > 0.0) {
            return bad("weibull-gauge-length", l, "a gauge length > 0 in m");
        }
    }
    if !(f.rate_coefficient.is_finite() && f.rate_coefficient >= 0.0) {
        return bad(
            "failure-rate-coefficient",
            f.rate_coefficient,
            "C ≥ 0 of ε_f(ε̇) = ε_f (1 + C ln(ε̇/ε̇₀))",
        );
    }
    if !(f.reference_rate.is_finite() && f.reference_rate > 0.0) {
        return bad("failure-reference-rate", f.reference_rate, "ε̇₀ > 0 in 1/s");
    }
    if let Some(l) = f.length {
        if !(l.is_finite() && l >= 0.0) {
            return bad(
                "failure-length",
                l,
                "a length ≥ 0 in m of yarn to average the strain over (0: none)",
            );
        }
    }
    check_delay_and_damping(f.delay, f.contact_damping)
}

/// The yarn-level patch and what was derived.
pub fn woven(p: &WovenBandParams) -> Result<(Model, WovenInfo)> {
    check(p)?;
    let section = Section::new(p);
    let amp = crimp_amplitude(p, &section)?;
    // Layer pitch: a layer spans ±(a + t_c/2) about its mid-plane.
    let pitch = 2.0 * amp + section.t_centre + p.layer_gap;
    if p.layers > 1 && p.layer_gap <= 0.0 {
        return Err(
            WeftError::input("layers touch: --layer-gap is 0".to_string())
                .expected("a gap > 0 between layers"),
        );
    }
    let crimp = crimp_of(amp, p.spacing);
    let weave = Weave::new(p, section, amp);
    let mut m = Model::default();
    let mut built = Built::new();
    for layer in 0..p.layers {
        add_layer(&mut m, &weave, layer, -(layer as f64) * pitch, &mut built);
    }
    tag_yarns(&mut m, p, &weave, &built);
    add_contacts(&mut m, p, &weave.section, &built.parts);
    if p.quarter {
        for normal in [0, 1] {
            m.symmetry.push(SymmetryPlane {
                normal,
                position: 0.0,
                tolerance: 1e-9,
            });
        }
    }
    let yarn_parts: Vec<usize> = built.parts.iter().flat_map(|&(a, b)| [a, b]).collect();
    let back_ply = *built.parts.last().expect("at least one layer");
    match &p.bullet {
        None => add_projectile(&mut m, p, &weave.section, built.top),
        Some(b) => {
            let b = crate::generate::bullet::BulletParams {
                diameter: 2.0 * p.projectile_radius,
                mass: p.projectile_mass,
                ..b.clone()
            };
            crate::generate::bullet::add_to(
                &mut m,
                &b,
                [0.0, 0.0, built.top + 1e-4],
                p.projectile_velocity,
                p.quarter,
                p.projectile_friction,
                &yarn_parts,
            )?;
        }
    }
    insert_sets(&mut m, built);
    m.analysis = Analysis {
        end_time: p.end_time,
        output_interval: p.output_interval,
        dt_safety: p.dt_safety,
        history_sets: vec![
            "axis_x".into(),
            "axis_x_weft".into(),
            "diagonal".into(),
            "diagonal_weft".into(),
        ],
        stop_on_outcome: p.stop_on_outcome,
        variable_time_step: p.bullet.is_some(),
        ..Analysis::default()
    };
    if p.bullet.is_some() {
        m.analysis.history_sets.push("bullet".into());
    }
    let area = weave.section.lens.area();
    let info = WovenInfo {
        thickness_scale: weave.section.scale,
        crimp_amplitude: amp,
        crimp,
        area,
        areal_density: 2.0 * p.density * area * (1.0 + crimp) / p.spacing,
        contact_thickness: weave.section.t_centre,
        layer_pitch: pitch,
    };
    for &part in &yarn_parts {
        m.parts[part].props.ply_areal_density = Some(info.areal_density);
    }
    if let Some(s) = &p.surround {
        surround(&mut m, p, s, &info)?;
    }
    if let Some(b) = &p.backing {
        back_with_clay(&mut m, p, b, &weave.section, back_ply)?;
    }
    m.validate()?;
    Ok((m, info))
}

/// Lays the pack on the clay (`clay::clay_block`, part id 80): the clay's top a layer
/// gap below the back ply's surface (its lowest node less half the contact thickness),
/// the back ply's yarns and its membrane sheet against the clay's faces with the
/// yarns' friction, a deformable bullet's nodes against them with its own, and the
/// pack's edges free (the clay holds it; the standard's straps hold nothing in a shot's
/// fraction of a millisecond). The crater's profile is a history set.
fn back_with_clay(
    m: &mut Model,
    p: &WovenBandParams,
    b: &crate::generate::clay::Backing,
    s: &Section,
    (warp, weft): (usize, usize),
) -> Result<()> {
    let panel = p
        .surround
        .as_ref()
        .map_or((p.yarns as f64 - 0.5) * p.spacing, |s| s.length);
    if !(panel < b.block.half_width) {
        return Err(WeftError::input(format!(
            "the panel's half-size {panel} m is not inside the clay box's half-width {} m",
            b.block.half_width
        ))
        .expected("a panel smaller than the clay box")
        .hint("--clay-half-width, or a smaller --membrane-length"));
    }
    if !(panel > p.projectile_radius) {
        return Err(WeftError::input(format!(
            "the panel's half-size {panel} m is not larger than the projectile's radius {} m: the shot would miss the pack",
            p.projectile_radius
        ))
        .expected("a panel wider than the bullet")
        .hint("more --yarns, or --membrane-length for a panel beyond the woven patch"));
    }
    let zmin = m.coords.iter().map(|x| x[2]).fold(f64::INFINITY, f64::min);
    let top = zmin - 0.5 * s.t_centre - p.layer_gap.max(1e-5);
    m.constraints.clear();
    crate::generate::clay::clay_block(m, 80, &b.clay, &b.block, top)?;
    let clay = m.parts.len() - 1;
    let mut slaves = vec![warp, weft];
    let sheet = format!("coarse_membrane_{}", p.layers);
    slaves.extend(m.parts.iter().position(|q| q.name == sheet));
    let mut cid = m.contacts.iter().map(|c| c.id).max().unwrap_or(0);
    for part in slaves {
        cid += 1;
        let mut c = ContactDef::new(cid, Slave::Part(part), clay).with_friction(p.friction);
        if s.chain && (part == warp || part == weft) {
            // The chains' nodes carry the bands' centre thickness (as between yarns).
            c.slave_thickness = Some(s.t_centre);
        }
        c.master_thickness = Some(0.0);
        m.contacts.push(c);
    }
    // A deformable bullet that perforates the pack meets the clay: its nodes against the
    // clay's faces, with the projectile's friction (a rigid projectile meets every node,
    // the clay's among them).
    for name in ["bullet", "bullet_jacket"] {
        if let Some(part) = m.parts.iter().position(|q| q.name == name) {
            cid += 1;
            let mut c =
                ContactDef::new(cid, Slave::Part(part), clay).with_friction(p.projectile_friction);
            c.master_thickness = Some(0.0);
            m.contacts.push(c);
        }
    }
    m.analysis.history_sets.push("clay_profile".into());
    Ok(())
}

/// Each yarn element's layer and yarn (`layer`, `yarn` columns: the yarn's index within
/// its part, from 1), the yarn parts' failure law, and the elements' strengths.
fn tag_yarns(m: &mut Model, p: &WovenBandParams, w: &yarns::Weave, b: &Built) {
    let kind = if w.section.chain {
        ElementKind::Truss
    } else {
        ElementKind::Quad
    };
    let f = &p.failure;
    if f.strain > 0.0 {
        for &(warp, weft) in &b.parts {
            for part in [warp, weft] {
                let props = &mut m.parts[part].props;
                props.failure_strain = Some(f.strain);
                props.failure_delay = Some(p.failure_delay());
                if w.section.chain {
                    props.failure_length = f.length.filter(|&l| l > 0.0);
                }
                if f.rate_coefficient > 0.0 {
                    props.failure_rate_coefficient = Some(f.rate_coefficient);
                    props.failure_reference_rate = Some(f.reference_rate);
                }
            }
        }
    }
    let factors = f
        .weibull_modulus
        .map(|modulus| strength_factors(f, modulus, w, &b.tags));
    let blk = m.elements.get_mut(&kind).expect("the yarns' elements");
    blk.layer = b.tags.iter().map(|t| Some(t.layer as i64 + 1)).collect();
    blk.yarn = b.tags.iter().map(|t| Some(t.yarn)).collect();
    if let Some(fs) = factors {
        blk.failure_factor = fs;
    }
}

/// Weibull strength factors ε/ε₀ = (L₀/L)^{1/m}(−ln(1 − u))^{1/m}, one per element: u drawn
/// per yarn (keyed by layer, family and yarn) or per element (keyed by its id), L the
/// yarn's or the element's length along the patch, L₀ the gauge length (the yarn's by
/// default) (docs/theory.md, "Failure, perforation and the ballistic limit").
fn strength_factors(
    f: &YarnFailure,
    modulus: f64,
    w: &yarns::Weave,
    tags: &[yarns::Tag],
) -> Vec<f64> {
    let yarn_length = w.length();
    let element_length = yarn_length / w.elements_along() as f64;
    let gauge = f.gauge_length.unwrap_or(yarn_length);
    tags.iter()
        .map(|t| {
            let (u, length) = match f.per {
                StrengthPer::Yarn => {
                    let key = ((t.layer as u64) << 40) | ((t.family as u64) << 32) | t.yarn as u64;
                    (crate::random::uniform(f.seed, key), yarn_length)
                }
                StrengthPer::Element => (
                    crate::random::uniform(f.seed, t.element as u64),
                    element_length,
                ),
            };
            crate::random::weibull(u, modulus, 1.0, gauge, length)
        })
        .collect()
}

/// Contact: warp against weft in each layer, and every yarn of a layer against every
/// yarn of the next; all two-way, with yarn–yarn friction.
fn add_contacts(m: &mut Model, p: &WovenBandParams, s: &Section, parts: &[(usize, usize)]) {
    let mut cid = 0;
    let mut contact = |m: &mut Model, a: usize, b: usize| {
        cid += 1;
        let mut c = ContactDef::new(cid, Slave::Part(a), b).with_friction(p.friction);
        c.two_way = true;
        if s.chain {
            // The band's centre thickness: unformed crossings just touch, as the bands'.
            c.slave_thickness = Some(s.t_centre);
            c.master_thickness = Some(s.t_centre);
        }
        m.contacts.push(c);
    };
    for l in 0..p.layers {
        let (w, f) = parts[l];
        contact(m, f, w);
        if l + 1 < p.layers {
            let (w2, f2) = parts[l + 1];
            for a in [w, f] {
                for b in [w2, f2] {
                    contact(m, b, a);
                }
            }
        }
    }
}

/// The projectile above the fabric's `top`, on the centre (a quarter of its mass in a
/// quarter model).
fn add_projectile(m: &mut Model, p: &WovenBandParams, s: &Section, top: f64) {
    let share = if p.quarter { 0.25 } else { 1.0 };
    // The projectile meets the chains' nodes, which carry no contact thickness of their
    // own: its nose grows by t_c/2 (the sum of the nose and a yarn's contact radius, the
    // Minkowski sum, so that it meets the yarns' surfaces where the bands' would), and
    // its tip sits t_c/2 lower (the same nose centre).
    let grow = if s.chain { 0.5 * s.t_centre } else { 0.0 };
    m.projectiles.push(ProjectileSpec {
        id: 1,
        shape: p.projectile_shape,
        radius: p.projectile_radius + grow,
        length: 2.0 * p.projectile_radius,
        mass: share * p.projectile_mass,
        tip: [0.0, 0.0, top - grow + 1e-6],
        axis: [0.0, 0.0, -1.0],
        velocity: [0.0, 0.0, -p.projectile_velocity],
        prescribed_velocity: false,
        contact_stiffness: None,
        friction: p.projectile_friction,
        contact_damping: p.contact_damping(),
        segment_contact: !s.chain,
    });
}

/// Ties the quarter patch's yarn ends into a graded membrane (see [`Surround`]): one
/// sheet per layer, the node sets `interface` (the tied ends) and `axis_x_all`, and the
/// membrane's failure.
fn surround(m: &mut Model, p: &WovenBandParams, s: &Surround, info: &WovenInfo) -> Result<()> {
    let c = check_surround(p, s)?;
    // Each sheet carries one layer's share: one layer's surface density, and the yarns'
    // section per unit width 2A/p as its default thickness.
    let props = s
        .membrane
        .props(p.modulus, info.areal_density, 2.0 * info.area / p.spacing);
    // The yarn ends are tied, not held.
    let ends = m.node_sets["edge"].clone();
    let is_end: std::collections::HashSet<usize> = ends.iter().copied().collect();
    m.constraints.retain(|(n, _)| !is_end.contains(n));
    let lines = graded_lines(c, 0.5 * p.spacing, s.length, s.growth)?;
    let patch_nodes = m.num_nodes();
    let mut tied = Vec::new();
    for layer in 0..p.layers {
        let z = -(layer as f64) * info.layer_pitch;
        tied.extend(add_sheet(m, layer, z, &lines, c, &props, &ends)?);
    }
    let axis = axis_through_surround(m, patch_nodes, c);
    m.node_sets.insert("axis_x_all".into(), axis);
    m.node_sets.insert("interface".into(), tied);
    if let Some(e) = s.membrane.failure_strain {
        fail_membranes(m, e, p.failure_delay());
    }
    m.analysis.history_sets.push("axis_x_all".into());
    Ok(())
}

/// The surround's flags: a quarter patch, a half-size beyond its yarn ends, a growth
/// ratio in [1, 3], the membrane's own ([`crate::generate::surround::SurroundParams`]).
/// Returns the half-size c = (N − ½)p of the patch, where the yarn ends lie.
fn check_surround(p: &WovenBandParams, s: &Surround) -> Result<f64> {
    if !p.quarter {
        return Err(WeftError::input("--membrane-length with --full".to_string())
            .expected("a quarter patch: a full patch's yarn ends lie at the crimp's crests, off the membrane's plane")
            .hint("leave out --full"));
    }
    let c = (p.yarns as f64 - 0.5) * p.spacing;
    let bad = |name: &str, v: f64, exp: &str| {
        Err(WeftError::input(format!("--{name} = `{v}`")).expected(exp.to_string()))
    };
    if !(s.length > c + 0.5 * p.spacing) || !s.length.is_finite() {
        return bad(
            "membrane-length",
            s.length,
            &format!("a half-size larger than the patch's {c:.4e} m + p/2"),
        );
    }
    if !(s.growth >= 1.0 && s.growth <= 3.0) {
        return bad("membrane-growth", s.growth, "a growth ratio in [1, 3]");
    }
    s.membrane.check()?;
    Ok(c)
}

/// The membrane sheet of `layer` at height `z` (the layer's mid-plane: the quarter's
/// edge lies where the crimp crosses it) on the graded `lines` around the hole of
/// half-size `c`, clamped at its outer edge, the layer's yarn `ends` tied to it; its
/// quads tagged with the layer (its energies and deflection go with it). Returns the
/// tied ends.
fn add_sheet(
    m: &mut Model,
    layer: usize,
    z: f64,
    lines: &[f64],
    c: f64,
    props: &MembraneProps,
    ends: &[usize],
) -> Result<Vec<usize>> {
    let sheet = if layer == 0 {
        Sheet::default()
    } else {
        Sheet {
            z,
            part_id: 90 + layer as i64,
            name: format!("coarse_membrane_{}", layer + 1),
            first_element: 1_000_000 + 200_000 * layer as i64,
        }
    };
    let first_id = m.node_id.iter().copied().max().unwrap_or(0) + 1;
    let before = m.elements.get(&ElementKind::Quad).map_or(0, |b| b.len());
    let coarse = coarse_membrane_at(m, lines, true, c, props, first_id, &sheet);
    let layer_ends: Vec<usize> = ends
        .iter()
        .copied()
        .filter(|&n| (m.coords[n][2] - z).abs() <= 1e-9)
        .collect();
    let tied = tie_to_hole(m, &coarse, &layer_ends)?;
    for &o in &coarse.outer {
        m.constraints.push((o, [true, true, true]));
    }
    let b = m
        .elements
        .get_mut(&ElementKind::Quad)
        .expect("the sheet's quads");
    b.layer.resize(before, None);
    b.layer.resize(b.len(), Some(layer as i64 + 1));
    Ok(tied)
}

/// The x axis line on both sides of the interface at x = c: the patch's crossings
/// (`axis_x`), then the membrane's nodes on y = 0 beyond it (those added after the
/// patch's first `patch_nodes`), ordered by x.
fn axis_through_surround(m: &Model, patch_nodes: usize, c: f64) -> Vec<usize> {
    let mut axis: Vec<usize> = m.node_sets["axis_x"].clone();
    let mut beyond: Vec<usize> = (patch_nodes..m.num_nodes())
        .filter(|&n| m.coords[n][1].abs() < 1e-12 && m.coords[n][0] > c - 1e-12)
        .collect();
    beyond.sort_by(|&a, &b| m.coords[a][0].total_cmp(&m.coords[b][0]));
    axis.extend(beyond);
    axis
}
