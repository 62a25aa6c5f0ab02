//! `woven-reduced`: the reduced woven model of the paper's §5. Warp and weft yarns as
//! truss chains on the crossing lines, joined at every crossing by a link (springs,
//! dashpots, an optional friction slider), inside the graded equivalent membrane of
//! [`super::surround`] whose properties follow from the yarns by the paper's §3 ratios,
//! tied to the yarns on the patch's boundary; a rigid projectile at the centre. A
//! pretensioned model starts balanced, relaxed or unbalanced ([`PretensionStart`]).

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::generate::reduced_failure::{
    check_membrane_strain, fail_membranes, fail_rods, tag_layer, ReducedFailure,
};
use crate::generate::surround::{
    centre_line_sets, coarse_membrane, graded_lines, hold_outer_edge, tie_to_hole, Coarse,
    MembraneProps,
};
use crate::model::{Analysis, ElementKind, Model, PartProps, ProjectileShape, ProjectileSpec};

/// The equivalent membrane around the reduced woven patch, from the paper's §3 ratios to
/// the yarns: the membrane's properties follow the yarn parameters (the woven patch's
/// surface density 2ρA/p, the yarn modulus E_y).
#[derive(Debug, Clone, Serialize)]
pub struct SurroundParams {
    /// Surface density of the membrane / surface density of the woven patch, ρ_m s/(2ρA/p)
    /// [–] (the paper's §3: 0.8).
    pub density_ratio: f64,
    /// Young's modulus of the membrane / Young's modulus of the yarn, E_m/E_y [–] (the
    /// paper's §3: 0.3).
    pub modulus_ratio: f64,
    /// Shear modulus of the membrane / its Young's modulus, G_m/E_m [–] (the paper's §3:
    /// 0.0042).
    pub shear_ratio: f64,
    /// Poisson's ratio ν of the (isotropic in-plane) membrane [–] (0: the woven patch's
    /// yarn families do not couple).
    pub poisson_ratio: f64,
    /// Membrane thickness s [m]; `None`: 2A/p, the yarns' material spread over the
    /// spacing (the thickness only sets ρ_m = ratio·(2ρA/p)/s: s ρ_m and s E_m are what
    /// the membrane's waves see).
    pub thickness: Option<f64>,
    /// Failure strain of the membrane along both fibre directions (None: it cannot fail,
    /// as in the paper's studies); see [`crate::generate::reduced_failure::fail_membranes`].
    pub failure_strain: Option<f64>,
}

impl Default for SurroundParams {
    /// [`SurroundParams::paper`].
    fn default() -> Self {
        SurroundParams::paper()
    }
}

impl SurroundParams {
    /// The paper's §3 ratios: 0.8, 0.3, 0.0042; ν = 0; s = 2A/p.
    pub fn paper() -> SurroundParams {
        SurroundParams {
            density_ratio: 0.8,
            modulus_ratio: 0.3,
            shear_ratio: 0.0042,
            poisson_ratio: 0.0,
            thickness: None,
            failure_strain: None,
        }
    }
}

/// How a pretensioned reduced model starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum PretensionStart {
    /// In equilibrium: the yarns carry E·A·ε₀ and the surrounding membrane the same
    /// tension per unit length, N = E·A·ε₀/p in both directions, as an initial stress N/s
    /// (a uniformly pre-stressed sheet held at its outer edge), so that the yarn ends
    /// pull on a membrane that pulls back as much. Exact for straight yarns (no crimp).
    Balanced,
    /// Balanced, then relaxed: the crimped crossings, which a pretension presses against
    /// their links, settle by dynamic relaxation (local damping, `Solver::relax`, the
    /// projectile set aside, the links' sliders held stuck so that the start owes
    /// nothing to a slip the run would not inherit, and unilateral normals relaxed as
    /// two-way springs, then checked to be all in compression, where the two laws
    /// agree: the kink at contact made the damped relaxation chatter without
    /// converging, measured), and the settled positions become the model's initial
    /// displacements u₀. For crimped yarns.
    Relaxed,
    /// The yarns alone pre-strained (the membrane unstressed): an unbalanced start that
    /// pulls the membrane in and rings (the behaviour before the fix, kept to compare).
    Unbalanced,
}

/// How the relaxed start ([`PretensionStart::Relaxed`]) is stopped. Why these: the
/// crossings settle in a few hundred steps (their link springs are the model's stiffest
/// parts, and set the step); the test window of 200 steps and the free rest probe of
/// 2000 steps (≈ 10 µs at the default model's 5 ns step, long against a crossing's
/// period ≈ 30 ns) are far longer.
const RELAX_MAX_STEPS: u64 = 1_000_000;
const RELAX_CHECK_EVERY: u64 = 200;
const RELAX_PROBE_STEPS: u64 = 2000;
/// Residual force ≤ 10⁻⁴ of the yarn tension E·A·ε₀; kinetic energy ≤ 10⁻⁸ of the work
/// the relaxation took; left alone at rest, no node moves more than 10⁻³ of the crimp.
const RELAX_FORCE_TOLERANCE: f64 = 1e-4;
const RELAX_KINETIC_TOLERANCE: f64 = 1e-8;
const RELAX_CREEP_TOLERANCE: f64 = 1e-3;

/// Where the reduced patch meets its membrane surround.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Interface {
    /// On the last crossing line (x = c = np): the yarns along it are halved (the membrane
    /// carries the other half of their strip) and its crossings lie flat on the membrane.
    Crossing,
    /// As the yarn-level patch tied by `woven --membrane-length`: every crossing line
    /// 0 … np a full yarn (halved only on a symmetry plane), crimped, and the rods run on
    /// half a spacing past the last crossing to the membrane's edge at c = (n + ½)p, where
    /// their ends are tied; the membrane's cells there are p/2 wide. Quarter models only.
    BandEnds,
}

/// `woven-reduced`: the reduced woven model of the paper's §5.
#[derive(Debug, Clone, Serialize)]
pub struct WovenParams {
    /// Yarns per side of the full patch (even).
    pub yarns: usize,
    /// Yarn spacing p [m].
    pub spacing: f64,
    /// Yarn: E [Pa], ρ [kg/m³], cross-section area [m²], tension only.
    pub yarn_modulus: f64,
    pub yarn_density: f64,
    pub yarn_area: f64,
    pub tension_only: bool,
    /// Initial yarn strain (pretension) ε₀.
    pub pretension_strain: f64,
    /// How a pretensioned model starts (ignored when ε₀ = 0).
    pub pretension_start: PretensionStart,
    /// Crimp: z offset ± of warp and weft nodes at the crossings [m].
    pub crimp: f64,
    /// Links: k_x = k_y, k_z [N/m], c_x, c_y, c_z [N·s/m], slip force [N] (None: none).
    pub k_xy: f64,
    pub k_z: f64,
    pub c_xy: f64,
    pub c_z: f64,
    pub slip_force: Option<f64>,
    /// Coulomb friction coefficient μ of the links (slip at μ·N, N the normal spring's
    /// compressive force) [–]; `None`: none. Not with `slip_force`.
    pub friction: Option<f64>,
    /// The links' normal spring pushes the yarns apart and never pulls them together.
    pub unilateral: bool,
    /// The links act in the crossing's local frame (the two yarn directions and their
    /// normal, following the fabric) instead of global x, y, z.
    pub local_frame: bool,
    /// The links' ends slide along their yarns when the links slip
    /// ([`crate::solver::sliding_link`]), in the frame of the yarns' tangents there.
    pub sliding: bool,
    /// Whole model side [m], coarse membrane growth ratio, quarter symmetry.
    pub length: f64,
    pub growth: f64,
    pub quarter: bool,
    /// Where the patch meets the membrane.
    pub interface: Interface,
    /// The equivalent membrane around the patch, relative to the yarns.
    pub surround: SurroundParams,
    /// Projectile: flat-nosed by default.
    pub projectile_shape: ProjectileShape,
    pub projectile_radius: f64,
    pub projectile_mass: f64,
    pub projectile_velocity: f64,
    /// Projectile–yarn Coulomb friction μ (0: frictionless, the paper's reduced model).
    pub projectile_friction: f64,
    pub end_time: f64,
    pub output_interval: f64,
    /// Safety factor on the stable step [–], 0 < f ≤ 1 (the model's `dt_safety`; 0.9 by
    /// default): the projectile's contact penalty is κ m*/Δt².
    pub dt_safety: f64,
    /// A deformable bullet of hexahedra instead of the rigid projectile (diameter twice
    /// `projectile_radius`, mass `projectile_mass`, at `projectile_velocity`, friction
    /// `projectile_friction`; its faces and nodes in contact with the yarns' trusses, of
    /// contact thickness √(4A/π)): [`crate::generate::bullet`]. None: rigid.
    pub bullet: Option<crate::generate::bullet::BulletParams>,
    /// The rods' failure (none by default, as in the paper's §5).
    pub failure: ReducedFailure,
    /// End the run at the projectile's outcome (analysis.parquet's `stop_on_outcome`: a
    /// ballistic sweep's runs).
    pub stop_on_outcome: bool,
}

impl Default for WovenParams {
    /// [`WovenParams::paper`].
    fn default() -> Self {
        WovenParams::paper()
    }
}

impl WovenParams {
    /// The paper's §5 model (docs/theory.md, "The paper's studies" and "Material data and
    /// defaults"): aramid yarns 1 mm apart (E = 80 GPa, ρ = 1440 kg/m³, 190 g/m²
    /// together: A = 6.6·10⁻⁸ m² per yarn), links at the fitted k_x = k_y = 3.8661·10⁶ N/m,
    /// k_z = 5.2448·10⁹ N/m (the paper's N/mm values, its exponents corrected), a 9 mm, 8 g
    /// flat-nosed projectile at 400 m/s; the equivalent membrane from the paper's §3
    /// ratios ([`SurroundParams::paper`]).
    pub fn paper() -> WovenParams {
        WovenParams {
            yarns: 20,
            spacing: 1e-3,
            yarn_modulus: 80e9,
            yarn_density: 1440.0,
            yarn_area: 6.6e-8,
            tension_only: true,
            pretension_strain: 0.0,
            pretension_start: PretensionStart::Balanced,
            crimp: 0.0,
            k_xy: 3.8661e6,
            k_z: 5.2448e9,
            c_xy: 0.0,
            c_z: 0.0,
            slip_force: None,
            friction: None,
            unilateral: false,
            local_frame: false,
            sliding: false,
            length: 0.1,
            growth: 1.25,
            quarter: true,
            interface: Interface::Crossing,
            surround: SurroundParams::paper(),
            projectile_shape: ProjectileShape::Flat,
            projectile_radius: 4.5e-3,
            projectile_mass: 8e-3,
            projectile_velocity: 400.0,
            projectile_friction: 0.0,
            end_time: 5e-5,
            output_interval: 1e-6,
            dt_safety: 0.9,
            bullet: None,
            failure: ReducedFailure::default(),
            stop_on_outcome: false,
        }
    }

    /// Surface density of the woven patch, 2ρA/p [kg/m²]: two yarn families, one yarn of
    /// section A per spacing p each.
    pub fn patch_surface_density(&self) -> f64 {
        2.0 * self.yarn_density * self.yarn_area / self.spacing
    }

    /// The surrounding membrane's properties from the yarns and the ratios of
    /// [`SurroundParams`]: s (2A/p unless given), ρ_m = r_ρ (2ρA/p)/s, E_m = r_E E_y,
    /// G_m = r_G E_m.
    pub fn membrane(&self) -> MembraneProps {
        let r = &self.surround;
        let s = r.thickness.unwrap_or(2.0 * self.yarn_area / self.spacing);
        let e_m = r.modulus_ratio * self.yarn_modulus;
        MembraneProps {
            youngs_modulus: e_m,
            poisson_ratio: r.poisson_ratio,
            shear_modulus: r.shear_ratio * e_m,
            thickness: s,
            density: r.density_ratio * self.patch_surface_density() / s,
        }
    }

    /// Yarn tension per unit width of the patch at the pretension, N = E A ε₀/p [N/m].
    pub fn pretension_per_width(&self) -> f64 {
        self.yarn_modulus * self.yarn_area * self.pretension_strain / self.spacing
    }

    fn check(&self) -> Result<()> {
        if self.yarns < 2 || !self.yarns.is_multiple_of(2) {
            return Err(WeftError::input(format!("--yarns = `{}`", self.yarns))
                .expected("an even number ≥ 2 (a crossing at the centre)"));
        }
        if self.interface == Interface::BandEnds && !self.quarter {
            return Err(
                WeftError::input("--interface band-ends with --full".to_string())
                    .expected("a quarter model (the band ends of a full patch lie on both sides)")
                    .hint("leave out --full, or use --interface crossing"),
            );
        }
        let r = &self.surround;
        let mut positive = vec![
            ("spacing", "m", self.spacing),
            ("yarn-modulus", "Pa", self.yarn_modulus),
            ("yarn-density", "kg/m³", self.yarn_density),
            ("yarn-area", "m²", self.yarn_area),
            ("k-z", "N/m", self.k_z),
            ("k-xy", "N/m", self.k_xy),
            ("projectile-mass", "kg", self.projectile_mass),
            ("projectile-radius", "m", self.projectile_radius),
            ("membrane-density-ratio", "", r.density_ratio),
            ("membrane-modulus-ratio", "", r.modulus_ratio),
            ("membrane-shear-ratio", "", r.shear_ratio),
        ];
        if let Some(t) = r.thickness {
            positive.push(("membrane-thickness", "m", t));
        }
        for (n, unit, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return Err(WeftError::input(format!("--{n} = `{v}`")).expected(format!(
                    "a value > 0{}",
                    if unit.is_empty() {
                        String::new()
                    } else {
                        format!(" in {unit}")
                    }
                )));
            }
        }
        self.failure.check()?;
        check_membrane_strain(r.failure_strain)?;
        let nu = r.poisson_ratio;
        if !(nu > -1.0 && nu < 1.0) {
            return Err(WeftError::input(format!("--membrane-poisson = `{nu}`"))
                .expected("−1 < ν < 1 (an isotropic membrane, ν² < 1)"));
        }
        if !(self.dt_safety > 0.0 && self.dt_safety <= 1.0) {
            return Err(
                WeftError::input(format!("--dt-safety = `{}`", self.dt_safety))
                    .expected("a safety factor 0 < f ≤ 1 on the stable step"),
            );
        }
        if !(self.projectile_velocity >= 0.0 && self.projectile_velocity.is_finite()) {
            return Err(WeftError::input(format!(
                "--projectile-velocity = `{}`",
                self.projectile_velocity
            ))
            .expected("a speed ≥ 0 in m/s (the projectile moves along −z, towards the patch)"));
        }
        if !(self.crimp >= 0.0 && self.crimp < self.spacing) {
            return Err(
                WeftError::input(format!("--crimp = `{}`", self.crimp)).expected(format!(
                    "an offset 0 ≤ a < the spacing {} m (warp and weft at ±a, alternating)",
                    self.spacing
                )),
            );
        }
        let pf = self.projectile_friction;
        if !(pf >= 0.0 && pf.is_finite()) {
            return Err(WeftError::input(format!("--projectile-friction = `{pf}`"))
                .expected("a Coulomb coefficient μ ≥ 0"));
        }
        if let Some(mu) = self.friction {
            if !(mu >= 0.0 && mu.is_finite()) {
                return Err(WeftError::input(format!("--link-friction = `{mu}`"))
                    .expected("a Coulomb coefficient μ ≥ 0"));
            }
            if let Some(f) = self.slip_force {
                return Err(WeftError::input(format!(
                    "--link-friction = `{mu}` and --slip-force = `{f}` together"
                ))
                .expected("one slip law: Coulomb friction μ·N or a constant slip force")
                .hint("drop one of the two"));
            }
        }
        Ok(())
    }
}

/// The reduced woven model: the patch's yarns and links inside the graded membrane tied
/// to the patch's boundary, the projectile, the node sets and the analysis; relaxed
/// before the start when [`PretensionStart::Relaxed`].
pub fn woven_reduced(p: &WovenParams) -> Result<Model> {
    p.check()?;
    let membrane = p.membrane();
    let layout = Layout::new(p);
    let pos = graded_lines(layout.c, layout.hc, 0.5 * p.length, p.growth)?;
    let mut m = Model::default();
    let yarns = add_yarn_nodes(&mut m, p, &layout);
    let parts = add_parts(&mut m, p);
    let yarn_of = add_yarns_and_links(&mut m, p, &layout, &yarns, &parts);
    let coarse = coarse_membrane(&mut m, &pos, p.quarter, layout.c, &membrane, 1_000_000);
    tag_layer(&mut m, &yarn_of);
    if p.pretension_strain != 0.0 && p.pretension_start == PretensionStart::Balanced {
        prestress_membrane(&mut m, p, &membrane);
    }
    let interface = tie_boundary(&mut m, &layout, &yarns, &coarse)?;
    hold_outer_edge(&mut m, &coarse, p.quarter, p.length);
    if p.bullet.is_none() {
        add_projectile(&mut m, p);
    }
    m.node_sets.insert("reference".into(), yarns.warp.clone());
    m.node_sets.insert("interface".into(), interface);
    centre_line_sets(&mut m, &yarns.warp, layout.c);
    m.analysis = Analysis {
        end_time: p.end_time,
        output_interval: p.output_interval,
        dt_safety: p.dt_safety,
        stop_on_outcome: p.stop_on_outcome,
        ..Default::default()
    };
    m.validate()?;
    if p.pretension_strain != 0.0 && p.pretension_start == PretensionStart::Relaxed {
        relax_start(&mut m, p)?;
    }
    let delay = p
        .failure
        .delay_for(p.spacing, p.yarn_modulus, p.yarn_density);
    if p.failure.strain > 0.0 {
        fail_rods(
            &mut m,
            &[parts.yarn, parts.half_yarn],
            p.failure.strain,
            delay,
        );
    }
    if let Some(e) = p.surround.failure_strain {
        fail_membranes(&mut m, e, delay);
    }
    if let Some(b) = &p.bullet {
        add_bullet(&mut m, p, b, &parts)?;
    }
    Ok(m)
}

/// The deformable bullet at the centre (after the relaxed start, which it takes no part
/// in), its tip 0.1 mm above the yarns' contact surface (the crimp plus the trusses'
/// contact radius √(A/π)), in contact with both yarn parts.
fn add_bullet(
    m: &mut Model,
    p: &WovenParams,
    b: &crate::generate::bullet::BulletParams,
    parts: &ReducedParts,
) -> Result<()> {
    let b = crate::generate::bullet::BulletParams {
        diameter: 2.0 * p.projectile_radius,
        mass: p.projectile_mass,
        ..b.clone()
    };
    let top = p.crimp + (p.yarn_area / std::f64::consts::PI).sqrt();
    crate::generate::bullet::add_to(
        m,
        &b,
        [0.0, 0.0, top + 1e-4],
        p.projectile_velocity,
        p.quarter,
        p.projectile_friction,
        &[parts.yarn, parts.half_yarn],
    )?;
    m.analysis.variable_time_step = true;
    m.validate()
}

/// Where the reduced patch's crossing lines and the membrane's hole lie.
struct Layout {
    /// The last crossing line's index n: crossing lines k = 0 … n each way (n = N/2 in a
    /// quarter, N in a full model).
    n: usize,
    /// The first crossing line's coordinate x₀ (0 in a quarter, −Np/2 in a full model);
    /// line k lies at x₀ + kp.
    x0: f64,
    /// Band ends ([`Interface::BandEnds`]): the yarns run on past the last crossing line
    /// to their ends on the membrane's edge.
    ends: bool,
    /// The membrane's hole: its half-size c and the size h_c of the membrane's first cells.
    c: f64,
    hc: f64,
}

impl Layout {
    fn new(p: &WovenParams) -> Layout {
        let ends = p.interface == Interface::BandEnds;
        let (n, x0) = if p.quarter {
            (p.yarns / 2, 0.0)
        } else {
            (p.yarns, -0.5 * p.yarns as f64 * p.spacing)
        };
        // The membrane's hole: the last crossing line, or half a spacing past it (band ends,
        // where the membrane's first cells are p/2 wide, as around the yarn-level patch).
        let (c, hc) = if ends {
            ((n as f64 + 0.5) * p.spacing, 0.5 * p.spacing)
        } else {
            (0.5 * p.yarns as f64 * p.spacing, p.spacing)
        };
        Layout { n, x0, ends, c, hc }
    }

    /// Crossings per line, n + 1.
    fn w(&self) -> usize {
        self.n + 1
    }

    /// The along-index at which a yarn's last element ends: the last crossing n, or with
    /// band ends n + 1 (the yarn's end on the membrane's edge).
    fn last(&self) -> usize {
        if self.ends {
            self.n + 1
        } else {
            self.n
        }
    }

    /// Halved: the yarns on a symmetry plane, and (crossing interface) those on the
    /// interface lines; with band ends the last crossing line is a full yarn.
    fn on_line(&self, k: usize) -> bool {
        k == 0 || (k == self.n && !self.ends)
    }
}

/// The warp lies over the weft where (i + j) is even (plain weave).
fn warp_on_top(i: usize, j: usize) -> bool {
    (i + j).is_multiple_of(2)
}

/// The yarns' nodes: warp and weft at each crossing (i, j), index j(n + 1) + i, and with
/// band ends the warp j's end at (c, jp) and the weft i's at (ip, c).
struct YarnNodes {
    warp: Vec<usize>,
    weft: Vec<usize>,
    warp_end: Vec<usize>,
    weft_end: Vec<usize>,
    /// The last crossing line's index n.
    n: usize,
}

impl YarnNodes {
    /// The warp j's node at i (i = n + 1: its end).
    fn warp_at(&self, i: usize, j: usize) -> usize {
        if i > self.n {
            self.warp_end[j]
        } else {
            self.warp[j * (self.n + 1) + i]
        }
    }

    /// The weft i's node at j (j = n + 1: its end).
    fn weft_at(&self, i: usize, j: usize) -> usize {
        if j > self.n {
            self.weft_end[i]
        } else {
            self.weft[j * (self.n + 1) + i]
        }
    }
}

/// The warp and weft nodes at every crossing, crimped ±a alternately, and the band ends.
fn add_yarn_nodes(m: &mut Model, p: &WovenParams, l: &Layout) -> YarnNodes {
    let (n, w, c, ends, x0) = (l.n, l.w(), l.c, l.ends, l.x0);
    let mut warp = vec![];
    let mut weft = vec![];
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (x0 + i as f64 * p.spacing, x0 + j as f64 * p.spacing);
            let boundary = !ends && ((x.abs() - c).abs() < 1e-12 || (y.abs() - c).abs() < 1e-12);
            // Plain weave: the warp passes over and under alternately; flat on the boundary.
            let z = if boundary {
                0.0
            } else if warp_on_top(i, j) {
                p.crimp
            } else {
                -p.crimp
            };
            warp.push(m.add_node((2 * (j * w + i) + 1) as i64, [x, y, z]));
            weft.push(m.add_node((2 * (j * w + i) + 2) as i64, [x, y, -z]));
        }
    }
    // Band ends: the warp on y = jp ends at (c, jp), the weft on x = ip at (ip, c), on the
    // membrane's plane z = 0 (where the yarn-level bands' crimp cos(πx/p) is zero).
    let (mut warp_end, mut weft_end) = (vec![], vec![]);
    if ends {
        let first = 2 * (w * w) as i64;
        for k in 0..=n {
            let t = k as f64 * p.spacing;
            warp_end.push(m.add_node(first + 1 + k as i64, [c, t, 0.0]));
            weft_end.push(m.add_node(first + 1 + (w + k) as i64, [t, c, 0.0]));
        }
    }
    YarnNodes {
        warp,
        weft,
        warp_end,
        weft_end,
        n,
    }
}

/// The patch's parts: full and half yarns; the links, and in a quarter model those on a
/// symmetry plane (half) and the centre crossing (a quarter).
struct ReducedParts {
    yarn: usize,
    half_yarn: usize,
    link: usize,
    half_link: usize,
    quarter_link: usize,
}

impl ReducedParts {
    /// The link part of the crossing (i, j).
    fn link_at(&self, quarter: bool, i: usize, j: usize) -> usize {
        match (quarter && i == 0, quarter && j == 0) {
            (true, true) => self.quarter_link,
            (true, false) | (false, true) => self.half_link,
            _ => self.link,
        }
    }
}

fn add_parts(m: &mut Model, p: &WovenParams) -> ReducedParts {
    let yarn = m.add_part(
        1,
        "yarns",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(p.yarn_modulus),
            density: Some(p.yarn_density),
            area: Some(p.yarn_area),
            tension_only: Some(p.tension_only),
            prestrain: (p.pretension_strain != 0.0).then_some(p.pretension_strain),
            ..Default::default()
        },
    );
    let link = m.add_part(
        2,
        "crossings",
        ElementKind::Link,
        PartProps {
            kx: Some(p.k_xy),
            ky: Some(p.k_xy),
            kz: Some(p.k_z),
            cx: Some(p.c_xy),
            cy: Some(p.c_xy),
            cz: Some(p.c_z),
            slip_force: p.slip_force,
            friction: p.friction,
            unilateral: p.unilateral.then_some(true),
            local_frame: p.local_frame.then_some(true),
            sliding: p.sliding.then_some(true),
            ..Default::default()
        },
    );
    // The yarns on the lines that bound the patch carry half a yarn: on a symmetry plane
    // (x = 0, y = 0 of a quarter) the other half belongs to the neighbouring quarter; on
    // the interface (x = ±c, y = ±c) the membrane carries the other half (each yarn
    // stands for a strip of width p, and the membrane starts at the line). Half the
    // area halves the mass, the axial stiffness and the pretension force alike.
    let half_yarn = m.add_part(
        3,
        "half_yarns",
        ElementKind::Truss,
        PartProps {
            area: Some(0.5 * p.yarn_area),
            ..m.parts[yarn].props.clone()
        },
    );
    let (half_link, quarter_link) = if p.quarter {
        let lp = m.parts[link].props.clone();
        (
            m.add_part(
                4,
                "crossings_on_symmetry",
                ElementKind::Link,
                scaled_link(0.5, &lp),
            ),
            m.add_part(
                5,
                "centre_crossing",
                ElementKind::Link,
                scaled_link(0.25, &lp),
            ),
        )
    } else {
        (link, link)
    };
    ReducedParts {
        yarn,
        half_yarn,
        link,
        half_link,
        quarter_link,
    }
}

/// In a quarter model, what lies on a symmetry plane is shared with the neighbouring
/// quarter: the links on one plane get half, the centre link a quarter of their
/// stiffness, damping and slip force (the friction coefficient is a ratio: the halved
/// normal stiffness halves N and so the slip force).
fn scaled_link(f: f64, base: &PartProps) -> PartProps {
    PartProps {
        kx: base.kx.map(|v| v * f),
        ky: base.ky.map(|v| v * f),
        kz: base.kz.map(|v| v * f),
        cx: base.cx.map(|v| v * f),
        cy: base.cy.map(|v| v * f),
        cz: base.cz.map(|v| v * f),
        slip_force: base.slip_force.map(|v| v * f),
        ..base.clone()
    }
}

/// The yarns' trusses and the crossings' links, numbered crossing by crossing: the warp
/// element leaving (i, j), the weft element, the link. Returns each truss's yarn, its
/// index within its part from 1: the warp on y = jp is j + 1, the weft on x = ip is
/// n + 2 + i (a rod's part holds warp and weft alike).
fn add_yarns_and_links(
    m: &mut Model,
    p: &WovenParams,
    l: &Layout,
    y: &YarnNodes,
    parts: &ReducedParts,
) -> Vec<i64> {
    let (n, last) = (l.n, l.last());
    let mut yarn_of = vec![];
    let mut eid = 1;
    for j in 0..=n {
        for i in 0..=n {
            if i < last {
                m.add_element(
                    eid,
                    if l.on_line(j) {
                        parts.half_yarn
                    } else {
                        parts.yarn
                    },
                    &[y.warp_at(i, j), y.warp_at(i + 1, j)],
                );
                yarn_of.push(j as i64 + 1);
                eid += 1;
            }
            if j < last {
                m.add_element(
                    eid,
                    if l.on_line(i) {
                        parts.half_yarn
                    } else {
                        parts.yarn
                    },
                    &[y.weft_at(i, j), y.weft_at(i, j + 1)],
                );
                yarn_of.push((n + 2 + i) as i64);
                eid += 1;
            }
            add_link(m, p, l, y, eid, parts.link_at(p.quarter, i, j), (i, j));
            eid += 1;
        }
    }
    yarn_of
}

/// The link `eid` of part `part` at the crossing (i, j), in the crossing's frame with
/// `local_frame`.
fn add_link(
    m: &mut Model,
    p: &WovenParams,
    l: &Layout,
    y: &YarnNodes,
    eid: i64,
    part: usize,
    (i, j): (usize, usize),
) {
    let k = j * l.w() + i;
    // Node 1 the lower yarn, node 2 the upper: the link's normal points from
    // node 1 to node 2, so that d_z < 0 presses them together (the unilateral
    // spring and Coulomb friction read it).
    let pair = if warp_on_top(i, j) {
        [y.weft[k], y.warp[k]]
    } else {
        [y.warp[k], y.weft[k]]
    };
    if !p.local_frame {
        m.add_element(eid, part, &pair);
        return;
    }
    // The frame: e₁ along the warp (the chord of its neighbours at i ∓ 1), the
    // normal ⟂ the weft (neighbours at j ∓ 1). At k = 0 (a symmetry plane, or
    // the interface of a full model) the chord to k + 2, at the same crimp
    // height: the mirrored neighbour's chord, level as symmetry asks (a
    // one-sided chord to k + 1 would tilt the normal by 2a/p and read the
    // crimp's pressure as a pull there, measured); at k = n the chord to n − 1
    // (those crossings are tied to the membrane), or with band ends the chord
    // from n − 1 to the band's end.
    let last = l.last();
    let chord = |k: usize| match k {
        0 => (0, 2.min(last)),
        k if k == last => (k - 1, k),
        k => (k - 1, k + 1),
    };
    let ((ia, ib), (ja, jb)) = (chord(i), chord(j));
    m.add_link_with_frame(
        eid,
        part,
        &pair,
        [
            y.warp_at(ia, j),
            y.warp_at(ib, j),
            y.weft_at(i, ja),
            y.weft_at(i, jb),
        ],
    );
}

/// The balanced start: the membrane carries the yarns' tension per unit width as a
/// uniform initial stress in both directions, in equilibrium with the yarn ends tied to
/// its hole (a yarn of tension E A ε₀ per strip of width p; half yarns on the lines).
fn prestress_membrane(m: &mut Model, p: &WovenParams, membrane: &MembraneProps) {
    let s0 = p.pretension_per_width() / membrane.thickness;
    let b = m
        .elements
        .get_mut(&ElementKind::Quad)
        .expect("the coarse membrane");
    b.stress0 = vec![[s0, s0, 0.0]; b.len()];
}

/// Every yarn node on the patch boundary (the yarn ends and the nodes of the yarns
/// that run along it) is tied to the membrane edge it lies on; returns the tied nodes.
fn tie_boundary(m: &mut Model, l: &Layout, y: &YarnNodes, coarse: &Coarse) -> Result<Vec<usize>> {
    let c = l.c;
    let on_boundary: Vec<usize> = y
        .warp
        .iter()
        .chain(y.weft.iter())
        .chain(y.warp_end.iter())
        .chain(y.weft_end.iter())
        .copied()
        .filter(|&n| {
            let x = m.coords[n];
            (x[0].abs() - c).abs() < 1e-12 || (x[1].abs() - c).abs() < 1e-12
        })
        .collect();
    tie_to_hole(m, coarse, &on_boundary)
}

/// The rigid projectile at the centre, its tip just above the crimp (a quarter of its
/// mass in a quarter model).
fn add_projectile(m: &mut Model, p: &WovenParams) {
    let share = if p.quarter { 0.25 } else { 1.0 };
    m.projectiles.push(ProjectileSpec {
        id: 1,
        shape: p.projectile_shape,
        radius: p.projectile_radius,
        length: 2.0 * p.projectile_radius,
        mass: share * p.projectile_mass,
        tip: [0.0, 0.0, p.crimp + 1e-5],
        axis: [0.0, 0.0, -1.0],
        velocity: [0.0, 0.0, -p.projectile_velocity],
        prescribed_velocity: false,
        contact_stiffness: None,
        friction: p.projectile_friction,
        contact_damping: p.failure.contact_damping(),
        segment_contact: true,
    });
}

/// The relaxed start: relax a copy of the model (no projectile, link sliders stuck) and
/// write its equilibrium as the initial displacements.
fn relax_start(m: &mut Model, p: &WovenParams) -> Result<()> {
    let mut r = m.clone();
    r.projectiles.clear();
    for part in r.parts.iter_mut().filter(|q| q.kind == ElementKind::Link) {
        part.props.slip_force = None;
        part.props.friction = None;
        part.props.unilateral = None;
    }
    let mut solver = crate::solver::Solver::new(&r)?;
    let tension = p.yarn_modulus * p.yarn_area * p.pretension_strain.abs();
    let stats = solver.relax(
        &crate::solver::relax::RelaxOptions {
            max_steps: RELAX_MAX_STEPS,
            min_steps: RELAX_CHECK_EVERY,
            check_every: RELAX_CHECK_EVERY,
            alpha: 0.8,
            kinetic_tolerance: RELAX_KINETIC_TOLERANCE,
            force_tolerance: RELAX_FORCE_TOLERANCE,
            force_scale: tension,
            creep_window: RELAX_PROBE_STEPS,
            creep_tolerance: RELAX_CREEP_TOLERANCE * p.crimp.abs().max(p.spacing * 1e-3),
            work_offset: 0.0,
            contact_damping: 0.0,
            hold_in_rest_test: vec![],
            probe_first: false,
        },
        &mut |_| {},
    )?;
    if !stats.converged {
        return Err(WeftError::input(format!(
            "the pretensioned model did not settle in {} steps (residual force {:.3e} N of the yarn tension {tension:.3e} N; a free node moved {:.3e} m at rest)",
            stats.steps, stats.residual, stats.creep
        ))
        .expected("an equilibrium of the crimped crossings under the pretension")
        .hint("check --crimp and --k-z, or start with --pretension-start balanced"));
    }
    check_unilateral_links(m, &solver, tension)?;
    m.initial_displacement = solver
        .state
        .x
        .iter()
        .zip(&m.coords)
        .map(|(x, x0)| [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]])
        .collect();
    m.validate()
}

/// A unilateral link found pulling at the equilibrium would let go at the start.
fn check_unilateral_links(m: &Model, solver: &crate::solver::Solver, tension: f64) -> Result<()> {
    let Some(b) = m.block(ElementKind::Link) else {
        return Ok(());
    };
    // The solver's three link families keep the table's order within each.
    let el = &solver.op.el;
    let (plain, framed, sliding) = (&el.link, &el.framed_link, &el.sliding_link);
    let (mut ip, mut ifr, mut isl) = (0, 0, 0);
    for e in 0..b.len() {
        let props = &m.parts[b.part[e]].props;
        let f = if props.sliding == Some(true) {
            isl += 1;
            sliding.normal_spring_force(isl - 1, &solver.state.x)
        } else if props.local_frame == Some(true) {
            ifr += 1;
            framed.normal_spring_force(ifr - 1, &solver.state.x)
        } else {
            ip += 1;
            plain.normal_spring_force(ip - 1, &solver.state.x)
        };
        if props.unilateral != Some(true) {
            continue;
        }
        if f < -RELAX_FORCE_TOLERANCE * tension {
            return Err(WeftError::input(format!(
                "unilateral link `{}` pulls its yarns together with {:.3e} N at the relaxed equilibrium",
                b.id[e], -f
            ))
            .expected("every unilateral link in compression at the pretensioned equilibrium")
            .hint("a crossing whose yarns separate under the pretension: use two-way links, or --pretension-start balanced"));
        }
    }
    Ok(())
}
