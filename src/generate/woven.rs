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

use std::collections::BTreeMap;

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::model::contacts::{ContactDef, Slave};
use crate::model::{
    Analysis, ElementKind, Model, PartProps, ProjectileShape, ProjectileSpec, SymmetryPlane,
};

/// Edge condition of the yarn ends at the patch edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Edge {
    /// Every node of a yarn end held in x, y and z.
    Clamped,
    /// Only the centre-line node of a yarn end held (the band can turn about it).
    Pinned,
    /// Nothing held.
    Free,
}

/// How a yarn is represented.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum YarnModel {
    /// A band of orthotropic membrane quads with the lenticular nodal thickness (the
    /// paper's reference; contact on the band faces).
    Band,
    /// A chain of trusses along the band's centre line, of the band's section and mass,
    /// with the band's centre thickness t_c as contact thickness (nodes and segments; the
    /// issue's "beam chain with a contact radius"): 4–6 × faster, for studies that need
    /// no yarn width (measured against the bands in the README).
    Chain,
}

/// Parameters of the yarn-level patch; every default is a documented aramid plain weave
/// (docs/theory.md, "Material data and defaults" and "The yarn-level woven patch").
#[derive(Debug, Clone, Serialize)]
pub struct WovenBandParams {
    /// Yarns per side: of the quarter (the middle yarn, on the symmetry plane, counted
    /// once) or of the full patch (even).
    pub yarns: usize,
    /// Quarter model with symmetry planes x = 0, y = 0.
    pub quarter: bool,
    /// Yarn spacing p [m]: 1 mm, the reduced model's (10 yarns/cm; docs/theory.md,
    /// "Material data and defaults": ≈ 8.5).
    pub spacing: f64,
    /// Yarn width w [m] and thickness h [m]: 0.8 mm × 0.124 mm, a lenticular area of
    /// 6.6·10⁻⁸ m², the reduced model's yarn area (190 g/m² with p = 1 mm).
    pub width: f64,
    pub thickness: f64,
    /// Crimp amplitude a [m] (None: crossing yarns just touch).
    pub crimp_amplitude: Option<f64>,
    /// Quads per spacing along a yarn (≥ 4) and across its width (≥ 2, even).
    pub per_spacing: usize,
    pub across: usize,
    /// Bands (the reference) or truss chains.
    pub yarn_model: YarnModel,
    /// Yarn material: E along the yarn [Pa] (Kevlar 29 class, 70–90 GPa), E across and
    /// the in-plane shear modulus [Pa] (a bundle of filaments: small; assumed E/50 and
    /// E/100), density [kg/m³].
    pub modulus: f64,
    pub transverse_modulus: f64,
    pub shear_modulus: f64,
    pub density: f64,
    /// Yarn–yarn Coulomb friction (docs/theory.md, "Material data and defaults": 0.1–0.2).
    pub friction: f64,
    /// Yarns carry no compressive stress (tension field).
    pub tension_field: bool,
    /// Layers, and the clearance between them [m].
    pub layers: usize,
    pub layer_gap: f64,
    pub edge: Edge,
    /// Projectile: 9 mm, 8 g, round-nosed at 400 m/s (docs/theory.md, "Material data and
    /// defaults": 360–430 m/s); friction against the yarns.
    pub projectile_shape: ProjectileShape,
    pub projectile_radius: f64,
    pub projectile_mass: f64,
    pub projectile_velocity: f64,
    pub projectile_friction: f64,
    /// Simulated time [s] (the paper's Fig. 4: 6·10⁻⁵ s) and output interval [s].
    pub end_time: f64,
    pub output_interval: f64,
    /// Safety factor on the stable step (0.9, the solver's default: the yarns under the
    /// nose, which do not fail, stiffen as they stretch; 0.8 carries the §3 models to
    /// 60 µs).
    pub dt_safety: f64,
    /// The paper's §3 combined model: the patch's yarn ends tied to a graded orthotropic
    /// membrane around it (None: the patch alone, its ends held by `edge`).
    pub surround: Option<Surround>,
}

/// A graded orthotropic membrane around a quarter patch (the paper's §3: a small woven
/// patch coupled to a membrane whose ρ, E and G carry the waves on). The band ends at
/// x = c and y = c, c = (N − ½)p, are tied to the membrane's inner edge (each end node to
/// the membrane edge it lies on, linear weights); the membrane is clamped at its outer
/// edge; `edge` no longer applies. Membrane cells are p/2 at the patch and grow by
/// `growth` outwards. Defaults: the paper's fitted §3 ratios.
#[derive(Debug, Clone, Serialize)]
pub struct Surround {
    /// Outer half-size of the model [m] (the reference patch's: 60 mm for 60 yarns).
    pub length: f64,
    /// Growth ratio of the membrane cells away from the patch (≥ 1).
    pub growth: f64,
    /// Membrane areal density / the patch's (all layers; paper 0.8).
    pub density_ratio: f64,
    /// Membrane E₁ = E₂ / the yarns' E (paper 0.3).
    pub modulus_ratio: f64,
    /// Membrane G₁₂ / its E (paper 0.0042).
    pub shear_ratio: f64,
    /// Membrane thickness [m]. An assumption (the paper states none): None takes 2A/p per
    /// layer, the yarns' cross-section per unit width of both families, so that the
    /// membrane's stress is the yarns' at the same strain when E_m = E/2.
    pub thickness: Option<f64>,
}

impl Default for Surround {
    /// The paper's §3 ratios around the 60 × 60-yarn reference patch, out to 60 mm
    /// ([`Surround::paper`]).
    fn default() -> Self {
        Surround::paper(0.06)
    }
}

impl Surround {
    /// The paper's §3 ratios around a patch, out to `length`.
    pub fn paper(length: f64) -> Surround {
        Surround {
            length,
            growth: 1.2,
            density_ratio: 0.8,
            modulus_ratio: 0.3,
            shear_ratio: 0.0042,
            thickness: None,
        }
    }
}

impl Default for WovenBandParams {
    fn default() -> Self {
        WovenBandParams {
            // The paper's 120 × 120 reference (Fig. 2b) as a quarter. A 10 × 10 quarter
            // (its small patch) alone, clamped, at 400 m/s strains its yarns beyond 50 %
            // within 16 µs (no failure is modelled) and the run breaks down: it is meant to
            // be tied into a membrane (the §3 study).
            yarns: 60,
            quarter: true,
            spacing: 1e-3,
            width: 0.8e-3,
            thickness: 0.124e-3,
            crimp_amplitude: None,
            per_spacing: 4,
            across: 2,
            yarn_model: YarnModel::Band,
            modulus: 80e9,
            transverse_modulus: 1.6e9,
            shear_modulus: 0.8e9,
            density: 1440.0,
            friction: 0.15,
            tension_field: false,
            layers: 1,
            layer_gap: 0.01e-3,
            edge: Edge::Clamped,
            projectile_shape: ProjectileShape::Round,
            projectile_radius: 4.5e-3,
            projectile_mass: 8e-3,
            projectile_velocity: 400.0,
            projectile_friction: 0.1,
            end_time: 6e-5,
            output_interval: 1e-6,
            dt_safety: 0.9,
            surround: None,
        }
    }
}

/// The lenticular section: arc radius R, thickness at y, exact area.
#[derive(Debug, Clone, Copy)]
pub struct Lenticular {
    pub w: f64,
    pub h: f64,
    pub r: f64,
}

impl Lenticular {
    pub fn new(w: f64, h: f64) -> Lenticular {
        Lenticular {
            w,
            h,
            r: (w * w + h * h) / (4.0 * h),
        }
    }
    /// t(y) = 2(√(R² − y²) − R + h/2), clamped at 0.
    pub fn thickness(&self, y: f64) -> f64 {
        let y = y.abs().min(0.5 * self.w);
        (2.0 * ((self.r * self.r - y * y).sqrt() - self.r + 0.5 * self.h)).max(0.0)
    }
    /// A band of `across` quads across the width: the node offsets from the centre line,
    /// their thickness t(y) scaled so that the one-point quads (mean of their nodal
    /// thicknesses) carry exactly [`Self::area`], and that scale.
    pub fn band(&self, across: usize) -> (Vec<f64>, Vec<f64>, f64) {
        let offs: Vec<f64> = (0..=across)
            .map(|k| -0.5 * self.w + self.w * k as f64 / across as f64)
            .collect();
        let t: Vec<f64> = offs.iter().map(|&y| self.thickness(y)).collect();
        let dy = self.w / across as f64;
        let trapezoid: f64 = (0..across).map(|k| 0.5 * dy * (t[k] + t[k + 1])).sum();
        let scale = self.area() / trapezoid;
        (offs, t.iter().map(|x| x * scale).collect(), scale)
    }
    /// Exact area of the two circular segments of chord w and height h/2.
    pub fn area(&self) -> f64 {
        let d = self.r - 0.5 * self.h;
        2.0 * (self.r * self.r * (d / self.r).acos() - d * (self.r * self.r - d * d).sqrt())
    }
}

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
    if !(p.projectile_velocity.is_finite() && p.projectile_velocity >= 0.0) {
        return bad(
            "projectile-velocity",
            p.projectile_velocity.to_string(),
            "a speed ≥ 0 in m/s",
        );
    }
    Ok(())
}

/// The crimp amplitude at which truss chains of contact thickness t just touch: a node at
/// a crossing, z = a, lies t + 2 nm from the crossing yarn's chords, which leave its node
/// at z = −a along the cosine (z = −a cos(πs/p) at s = p/n). At a = t/2, the centre
/// lines' distance at the crossing, the chords rising from the lower node come within
/// 0.7 µm of the upper one (the default weave); the bands' curved faces do not.
pub fn chain_touching_amplitude(t: f64, p: f64, per_spacing: usize) -> f64 {
    use crate::solver::contact::projectile::closest_on_segment;
    let s = p / per_spacing as f64;
    // Distance from (0, 0, a) to the chord from (0, 0, −a) to (s, 0, −a cos(πs/p)).
    let dist = |a: f64| {
        let (node, c0) = ([0.0, 0.0, a], [0.0, 0.0, -a]);
        let c1 = [s, 0.0, -a * (std::f64::consts::PI * s / p).cos()];
        let u = closest_on_segment(&node, &c0, &c1);
        let foot: [f64; 3] = std::array::from_fn(|d| c0[d] + u * (c1[d] - c0[d]));
        crate::solver::vec3::norm(&crate::solver::vec3::sub(&node, &foot))
    };
    let want = t + 2e-9;
    let (mut lo, mut hi) = (0.5 * t, t);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if dist(mid) < want {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
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
    add_projectile(&mut m, p, &weave.section, built.top);
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
        ..Analysis::default()
    };
    let area = weave.section.lens.area();
    let info = WovenInfo {
        thickness_scale: weave.section.scale,
        crimp_amplitude: amp,
        crimp,
        area,
        areal_density: 2.0 * p.density * area * (1.0 + crimp) / p.spacing,
        contact_thickness: weave.section.t_centre,
    };
    if let Some(s) = &p.surround {
        surround(&mut m, p, s, &info)?;
    }
    m.validate()?;
    Ok((m, info))
}

/// The band's cross-section as the mesh carries it.
struct Section {
    lens: Lenticular,
    /// Quads across the width (`across`).
    na: usize,
    /// Offsets of the nodes across the band from its centre line, and their nodal
    /// thicknesses scaled by `scale` = A/A_h (see [`Lenticular::band`]).
    offs: Vec<f64>,
    t_node: Vec<f64>,
    scale: f64,
    /// The (scaled) centre thickness t_c: the chains' contact thickness too.
    t_centre: f64,
    /// Truss chains instead of bands.
    chain: bool,
}

impl Section {
    fn new(p: &WovenBandParams) -> Section {
        let lens = Lenticular::new(p.width, p.thickness);
        // Offsets across the band and the trapezoid area of the nodal profile.
        let na = p.across;
        let (offs, t_node, scale) = lens.band(na);
        let t_centre = t_node[na / 2];
        Section {
            lens,
            na,
            offs,
            t_node,
            scale,
            t_centre,
            chain: p.yarn_model == YarnModel::Chain,
        }
    }
}

/// The crimp amplitude a: the given one, which must be at least t_c/2, or by default the
/// one at which crossing yarns just touch (bands: t_c/2 + 1 nm; chains:
/// [`chain_touching_amplitude`]).
fn crimp_amplitude(p: &WovenBandParams, s: &Section) -> Result<f64> {
    let t_centre = s.t_centre;
    let amp = p.crimp_amplitude.unwrap_or_else(|| {
        if s.chain {
            chain_touching_amplitude(t_centre, p.spacing, p.per_spacing)
        } else {
            0.5 * t_centre + 1e-9
        }
    });
    if amp < 0.5 * t_centre {
        return Err(WeftError::input(format!(
            "--crimp-amplitude = `{amp}` m is below half the yarns' centre thickness {:.4e} m",
            0.5 * t_centre
        ))
        .expected("a ≥ t_c/2: crossing yarns would start inside each other")
        .hint("leave --crimp-amplitude out for yarns that just touch"));
    }
    Ok(amp)
}

/// Crimp of z = a cos(πx/p): ∫₀^p √(1 + k² sin²) dx / p − 1, by Simpson's rule.
fn crimp_of(amp: f64, spacing: f64) -> f64 {
    let k_c = std::f64::consts::PI * amp / spacing;
    let n = 2000;
    let f = |x: f64| (1.0 + (k_c * (std::f64::consts::PI * x).sin()).powi(2)).sqrt();
    let s: f64 = (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * f(i as f64 / n as f64)
        })
        .sum();
    s / (3.0 * n as f64) - 1.0
}

/// What every yarn is built from: the parameters, the band's section, the crimp
/// amplitude, and where the yarns lie.
struct Weave<'a> {
    p: &'a WovenBandParams,
    section: Section,
    amp: f64,
    /// The yarns' indices j = first … last of each family.
    first: i64,
    last: i64,
    /// The yarns run from `lo` to `hi` along their length, in `n_along` elements.
    lo: f64,
    hi: f64,
    n_along: usize,
    /// Along-index of each crossing: the other family's yarn centre lines.
    crossing_at: BTreeMap<usize, i64>,
}

impl<'a> Weave<'a> {
    fn new(p: &'a WovenBandParams, section: Section, amp: f64) -> Weave<'a> {
        let (first, last) = if p.quarter {
            (0i64, p.yarns as i64 - 1)
        } else {
            (-(p.yarns as i64) / 2, p.yarns as i64 / 2 - 1)
        };
        let (lo, hi) = if p.quarter {
            (0.0, (p.yarns as f64 - 0.5) * p.spacing)
        } else {
            (
                -(p.yarns as f64) * 0.5 * p.spacing,
                p.yarns as f64 * 0.5 * p.spacing,
            )
        };
        let n_along = ((hi - lo) / p.spacing * p.per_spacing as f64).round() as usize;
        let crossing_at = (first..=last)
            .map(|jj| {
                (
                    ((yarn_centre(p, jj) - lo) / p.spacing * p.per_spacing as f64).round() as usize,
                    jj,
                )
            })
            .collect();
        Weave {
            p,
            section,
            amp,
            first,
            last,
            lo,
            hi,
            n_along,
            crossing_at,
        }
    }

    /// The centre line of yarn j (see [`yarn_centre`]).
    fn centre(&self, j: i64) -> f64 {
        yarn_centre(self.p, j)
    }

    /// The across-indices k0 ..= k1 of yarn j's nodes: all of a band's, the upper half of
    /// a band on a symmetry plane, a chain's centre line.
    fn across(&self, j: i64) -> (usize, usize) {
        let (na, chain) = (self.section.na, self.section.chain);
        // Across offsets: a yarn on a symmetry plane keeps its upper half.
        let k0 = if chain || (self.p.quarter && j == 0) {
            na / 2
        } else {
            0
        };
        let k1 = if chain { na / 2 } else { na };
        (k0, k1)
    }
}

/// Yarn centre lines at j·p (quarter) or (j + ½)·p (full, no yarn on x = 0).
fn yarn_centre(p: &WovenBandParams, j: i64) -> f64 {
    if p.quarter {
        j as f64 * p.spacing
    } else {
        (j as f64 + 0.5) * p.spacing
    }
}

/// (−1)^j.
fn sign(j: i64) -> f64 {
    if j.rem_euclid(2) == 0 {
        1.0
    } else {
        -1.0
    }
}

/// The band quads' properties: orthotropic, the material axis at `angle` (0 for the
/// warp, π/2 for the weft).
fn band_props(p: &WovenBandParams, t_centre: f64, angle: f64) -> PartProps {
    PartProps {
        youngs_modulus_1: Some(p.modulus),
        youngs_modulus_2: Some(p.transverse_modulus),
        shear_modulus_12: Some(p.shear_modulus),
        poisson_ratio_12: Some(0.0),
        density: Some(p.density),
        thickness: Some(t_centre),
        material_angle: Some(angle),
        // Tension-field yarns (no compression) would be closer to a bundle of filaments,
        // but that stress has no potential, and in crushed regions under the nose the
        // energy balance drifts (10.9 % at 57 µs in the 60 × 60 quarter, measured):
        // opt-in only.
        no_compression: Some(p.tension_field),
        ..Default::default()
    }
}

/// Chains: trusses of the band's exact section along its centre line (half of it
/// for a yarn on a symmetry plane, which carries half a band).
fn chain_props(p: &WovenBandParams, lens: &Lenticular) -> PartProps {
    PartProps {
        youngs_modulus: Some(p.modulus),
        density: Some(p.density),
        area: Some(lens.area()),
        tension_only: Some(p.tension_field),
        ..Default::default()
    }
}

/// What the yarns leave besides their nodes and elements: each layer's (warp, weft)
/// parts, the centre-line node sets of the first layer, the yarn-end nodes, the top of
/// the fabric, and the last node and element ids.
struct Built {
    parts: Vec<(usize, usize)>,
    axis_x: Vec<usize>,
    axis_x_weft: Vec<usize>,
    diagonal: Vec<usize>,
    diagonal_weft: Vec<usize>,
    edge_nodes: Vec<usize>,
    top: f64,
    nid: i64,
    eid: i64,
}

impl Built {
    fn new() -> Built {
        Built {
            parts: vec![],
            axis_x: vec![],
            axis_x_weft: vec![],
            diagonal: vec![],
            diagonal_weft: vec![],
            edge_nodes: vec![],
            top: f64::NEG_INFINITY,
            nid: 0,
            eid: 0,
        }
    }
}

/// One yarn: its family (0 warp along x, 1 weft along y), index j, part, layer and the
/// layer's mid-plane height.
#[derive(Clone, Copy)]
struct Yarn {
    fam: usize,
    j: i64,
    part: usize,
    layer: usize,
    zl: f64,
}

/// A layer at height `zl`: its warp and weft parts, then every warp yarn and every weft
/// yarn.
fn add_layer(m: &mut Model, w: &Weave, layer: usize, zl: f64, b: &mut Built) {
    let p = w.p;
    let (kind, warp_props, weft_props) = if w.section.chain {
        let chain = chain_props(p, &w.section.lens);
        (ElementKind::Truss, chain.clone(), chain)
    } else {
        (
            ElementKind::Quad,
            band_props(p, w.section.t_centre, 0.0),
            band_props(p, w.section.t_centre, std::f64::consts::FRAC_PI_2),
        )
    };
    let warp = m.add_part(
        2 * layer as i64 + 1,
        &format!("warp_{}", layer + 1),
        kind,
        warp_props,
    );
    let weft = m.add_part(
        2 * layer as i64 + 2,
        &format!("weft_{}", layer + 1),
        kind,
        weft_props,
    );
    b.parts.push((warp, weft));
    for (fam, part) in [(0, warp), (1, weft)] {
        for j in w.first..=w.last {
            let yarn = Yarn {
                fam,
                j,
                part,
                layer,
                zl,
            };
            let idx = add_yarn_nodes(m, w, yarn, b);
            if w.section.chain {
                add_chain_elements(m, w, yarn, &idx, b);
            } else {
                add_band_elements(m, w, yarn, &idx, b);
            }
        }
    }
}

/// A yarn's nodes, `idx[i][k]` at along-index i and across-index k (a chain's, and a band's
/// on a symmetry plane, from k = na/2): the yarn ends held as `edge` says, the crossing
/// nodes of the first layer gathered into the node sets.
fn add_yarn_nodes(m: &mut Model, w: &Weave, y: Yarn, b: &mut Built) -> Vec<Vec<usize>> {
    let (p, s) = (w.p, &w.section);
    let (na, n_along, j) = (s.na, w.n_along, y.j);
    let c = w.centre(j);
    let (k0, k1) = w.across(j);
    let mut idx = vec![vec![usize::MAX; na + 1]; n_along + 1];
    for i in 0..=n_along {
        let sa = w.lo + (w.hi - w.lo) * i as f64 / n_along as f64;
        // Warp (fam 0) follows (−1)^j a cos(π(x − x₀)/p); weft
        // −(−1)^j a cos(π(y − x₀)/p), x₀ a yarn centre line (0 in the quarter,
        // p/2 in the full patch), so that the crests lie at the crossings.
        let z = y.zl
            + if y.fam == 0 { sign(j) } else { -sign(j) }
                * w.amp
                * (std::f64::consts::PI * (sa - w.centre(0)) / p.spacing).cos();
        b.top = b.top.max(z + 0.5 * s.t_centre);
        for k in k0..=k1 {
            let r = c + s.offs[k];
            let x = if y.fam == 0 { [sa, r, z] } else { [r, sa, z] };
            b.nid += 1;
            let n = m.add_node(b.nid, x);
            idx[i][k] = n;
            let at_edge = (i == n_along) || (!p.quarter && i == 0);
            if at_edge {
                b.edge_nodes.push(n);
                let hold = match p.edge {
                    Edge::Clamped => true,
                    Edge::Pinned => k == na / 2,
                    Edge::Free => false,
                };
                if hold {
                    m.constraints.push((n, [true, true, true]));
                }
            }
        }
        // Crossing nodes: the centre-line node at each crossing position.
        if let Some(&other) = w.crossing_at.get(&i) {
            if y.layer == 0 {
                gather_crossing(b, y, other, idx[i][na / 2]);
            }
        }
    }
    idx
}

/// The first layer's crossing node `n` of yarn `y`, where the yarn `other` of the other
/// family crosses it, into the centre-line node sets.
fn gather_crossing(b: &mut Built, y: Yarn, other: i64, n: usize) {
    // The x axis line: the warp j = 0 and the wefts where they cross it.
    if y.fam == 0 && y.j == 0 {
        b.axis_x.push(n);
    }
    if y.fam == 1 && other == 0 {
        b.axis_x_weft.push(n);
    }
    if other == y.j {
        if y.fam == 0 {
            b.diagonal.push(n)
        } else {
            b.diagonal_weft.push(n)
        }
    }
}

/// A chain's trusses along the centre-line nodes (half the section on a symmetry plane).
fn add_chain_elements(m: &mut Model, w: &Weave, y: Yarn, idx: &[Vec<usize>], b: &mut Built) {
    let na = w.section.na;
    let half = w.p.quarter && y.j == 0;
    for i in 0..w.n_along {
        b.eid += 1;
        let ends = [idx[i][na / 2], idx[i + 1][na / 2]];
        if half {
            m.add_truss_with_area(b.eid, y.part, ends, 0.5 * w.section.lens.area());
        } else {
            m.add_element(b.eid, y.part, &ends);
        }
    }
}

/// A band's quads with their nodal thicknesses.
fn add_band_elements(m: &mut Model, w: &Weave, y: Yarn, idx: &[Vec<usize>], b: &mut Built) {
    let (na, t_node) = (w.section.na, &w.section.t_node);
    let (k0, _) = w.across(y.j);
    for i in 0..w.n_along {
        for k in k0..na {
            b.eid += 1;
            let q = if y.fam == 0 {
                [idx[i][k], idx[i + 1][k], idx[i + 1][k + 1], idx[i][k + 1]]
            } else {
                [idx[i][k], idx[i][k + 1], idx[i + 1][k + 1], idx[i + 1][k]]
            };
            let t = if y.fam == 0 {
                [t_node[k], t_node[k], t_node[k + 1], t_node[k + 1]]
            } else {
                [t_node[k], t_node[k + 1], t_node[k + 1], t_node[k]]
            };
            m.add_element_with_thickness(b.eid, y.part, &q, &t);
        }
    }
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
        segment_contact: !s.chain,
    });
}

/// The node sets `axis_x`, `axis_x_weft`, `diagonal`, `diagonal_weft` and `edge`.
fn insert_sets(m: &mut Model, b: Built) {
    m.node_sets.insert("axis_x".into(), b.axis_x);
    m.node_sets.insert("axis_x_weft".into(), b.axis_x_weft);
    m.node_sets.insert("diagonal".into(), b.diagonal);
    m.node_sets.insert("diagonal_weft".into(), b.diagonal_weft);
    let mut edge_nodes = b.edge_nodes;
    edge_nodes.sort_unstable();
    m.node_sets.insert("edge".into(), edge_nodes);
}

/// Ties the quarter patch's yarn ends into a graded membrane (see [`Surround`]).
fn surround(m: &mut Model, p: &WovenBandParams, s: &Surround, info: &WovenInfo) -> Result<()> {
    use crate::generate::surround::{coarse_membrane, graded_lines, tie_to_hole, MembraneProps};
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
    for (name, v) in [
        ("membrane-density-ratio", s.density_ratio),
        ("membrane-modulus-ratio", s.modulus_ratio),
        ("membrane-shear-ratio", s.shear_ratio),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            return bad(name, v, "a ratio > 0");
        }
    }
    let layers = p.layers as f64;
    let thickness = s.thickness.unwrap_or(2.0 * info.area * layers / p.spacing);
    if !(thickness > 0.0 && thickness.is_finite()) {
        return bad("membrane-thickness", thickness, "a thickness > 0 in m");
    }
    let e_m = s.modulus_ratio * p.modulus;
    let props = MembraneProps {
        youngs_modulus: e_m,
        poisson_ratio: 0.0,
        shear_modulus: s.shear_ratio * e_m,
        thickness,
        density: s.density_ratio * info.areal_density * layers / thickness,
    };
    // The yarn ends are tied, not held.
    let ends = m.node_sets["edge"].clone();
    let is_end: std::collections::HashSet<usize> = ends.iter().copied().collect();
    m.constraints.retain(|(n, _)| !is_end.contains(n));
    let lines = graded_lines(c, 0.5 * p.spacing, s.length, s.growth)?;
    let first_id = m.node_id.iter().copied().max().unwrap_or(0) + 1;
    let patch_nodes = m.num_nodes();
    let coarse = coarse_membrane(m, &lines, true, c, &props, first_id);
    let tied = tie_to_hole(m, &coarse, &ends)?;
    for &o in &coarse.outer {
        m.constraints.push((o, [true, true, true]));
    }
    // The x axis line on both sides of the interface: the patch's crossings, then the
    // membrane's nodes on y = 0 beyond it.
    let mut axis: Vec<usize> = m.node_sets["axis_x"].clone();
    let mut beyond: Vec<usize> = (patch_nodes..m.num_nodes())
        .filter(|&n| m.coords[n][1].abs() < 1e-12 && m.coords[n][0] > c - 1e-12)
        .collect();
    beyond.sort_by(|&a, &b| m.coords[a][0].total_cmp(&m.coords[b][0]));
    axis.extend(beyond);
    m.node_sets.insert("axis_x_all".into(), axis);
    m.node_sets.insert("interface".into(), tied);
    m.analysis.history_sets.push("axis_x_all".into());
    Ok(())
}
