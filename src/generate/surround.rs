//! The woven surround: the graded coarse membrane with a square hole that carries the
//! waves on around a dense patch (a girder zone, a fine membrane, the reduced or the
//! yarn-level woven patch), the ties from the patch's boundary to the hole's edges, and
//! the centre-line node sets through both; around a woven patch, the membrane's
//! properties from the paper's §3 ratios to the yarns ([`SurroundParams`]) and its
//! failure ([`fail_membranes`]).
//!
//! The coarse membrane is a tensor-product grid of lines: uniform at spacing h_c across
//! the centre, then growing by the ratio r out to the outer boundary, with the centre
//! square [−c, c]² left as a hole. Every node of the dense zone on the hole's boundary is
//! tied to the coarse edge it lies on, so no node hangs without a tie. With quarter
//! symmetry the model is [0, ·]² with symmetry planes x = 0 and y = 0.

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::model::{ElementKind, Model, PartProps, SymmetryPlane, Tie};

/// The most mesh lines each way a graded zone may have (10⁶ elements at most).
const MAX_LINES: usize = 1000;

/// Line positions ≥ 0: uniform h_c up to `c`, then growing by `ratio` to `outer`.
pub fn graded_lines(c: f64, hc: f64, outer: f64, ratio: f64) -> Result<Vec<f64>> {
    if !(ratio >= 1.0 && ratio.is_finite()) {
        return Err(WeftError::input(format!(
            "the coarse cells' growth ratio (--growth) is {ratio}"
        ))
        .expected("a finite ratio ≥ 1 (1: uniform cells)"));
    }
    let flags = "the sizes come from --length (the outer size), --centre-length or --spacing \
                 and --yarns (the centre), and --coarsening";
    let n = (c / hc).round() as usize;
    if !(c > 0.0 && c.is_finite() && hc > 0.0) || n == 0 || ((n as f64) * hc - c).abs() > 1e-9 * c {
        return Err(WeftError::input(format!(
            "the centre half-size {c} m is not a multiple of the coarse spacing {hc} m"
        ))
        .expected("a coarse spacing that divides the centre zone")
        .hint(flags));
    }
    if !(outer > c && outer.is_finite()) {
        return Err(WeftError::input(format!(
            "outer half-size {outer} m is not larger than the centre half-size {c} m"
        ))
        .expected("outer > centre, finite")
        .hint(flags));
    }
    let mut v: Vec<f64> = (0..=n).map(|k| k as f64 * hc).collect();
    let (mut x, mut h) = (c, hc);
    while x + h * ratio < outer - 0.5 * h * ratio {
        h *= ratio;
        x += h;
        v.push(x);
        if v.len() > MAX_LINES {
            return Err(WeftError::input(format!(
                "the graded mesh out to {outer} m would have more than {MAX_LINES} lines \
                 each way"
            ))
            .expected("an outer size a few hundred centre cells across at most")
            .hint(flags));
        }
    }
    // The last cell ends on the boundary.
    if (outer - x) > 1e-12 {
        v.push(outer);
    }
    Ok(v)
}

/// Membrane properties for the coarse zone.
#[derive(Debug, Clone, Serialize)]
pub struct MembraneProps {
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub shear_modulus: f64,
    pub thickness: f64,
    pub density: f64,
}

impl MembraneProps {
    pub(crate) fn part(&self) -> PartProps {
        PartProps {
            youngs_modulus_1: Some(self.youngs_modulus),
            youngs_modulus_2: Some(self.youngs_modulus),
            poisson_ratio_12: Some(self.poisson_ratio),
            shear_modulus_12: Some(self.shear_modulus),
            thickness: Some(self.thickness),
            density: Some(self.density),
            ..Default::default()
        }
    }
}

/// The paper's §3 equivalent membrane around a woven patch, relative to the patch's yarns
/// (both woven generators' surround: `woven --membrane-length`, `woven-reduced`): its
/// surface density from the patch's, its moduli from the yarns', its thickness, and its
/// failure. Defaults: the paper's fitted §3 ratios ([`SurroundParams::paper`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurroundParams {
    /// Surface density of the membrane / surface density of the woven patch, ρ_m s/(2ρA/p)
    /// [–] (per layer; the paper's §3: 0.8).
    pub density_ratio: f64,
    /// Young's modulus of the membrane E₁ = E₂ / Young's modulus of the yarn, E_m/E_y [–]
    /// (the paper's §3: 0.3).
    pub modulus_ratio: f64,
    /// Shear modulus of the membrane / its Young's modulus, G₁₂/E_m [–] (the paper's §3:
    /// 0.0042).
    pub shear_ratio: f64,
    /// Poisson's ratio ν of the (isotropic in-plane) membrane [–] (0: the woven patch's
    /// yarn families do not couple).
    pub poisson_ratio: f64,
    /// Membrane thickness s [m], an assumption (the paper states none); `None`: 2A/p per
    /// layer, the yarns' section per unit width of both families, so that the membrane's
    /// stress is the yarns' at the same strain when E_m = E/2. The thickness only sets
    /// ρ_m = ratio·(2ρA/p)/s: s ρ_m and s E_m are what the membrane's waves see.
    pub thickness: Option<f64>,
    /// Failure strain of the membrane along both fibre directions (None: it cannot fail,
    /// as in the paper's studies); see [`fail_membranes`].
    pub failure_strain: Option<f64>,
}

impl Default for SurroundParams {
    /// [`SurroundParams::paper`].
    fn default() -> Self {
        SurroundParams::paper()
    }
}

impl SurroundParams {
    /// The paper's §3 ratios: 0.8, 0.3, 0.0042; ν = 0; s = 2A/p; no failure.
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

    /// The membrane's properties around a patch of yarns of modulus `yarn_modulus` and of
    /// `surface_density` [kg/m²] (one layer's): s (`default_thickness` unless given),
    /// ρ_m = r_ρ (surface density)/s, E_m = r_E E_y, G_m = r_G E_m.
    pub fn props(
        &self,
        yarn_modulus: f64,
        surface_density: f64,
        default_thickness: f64,
    ) -> MembraneProps {
        let s = self.thickness.unwrap_or(default_thickness);
        let e_m = self.modulus_ratio * yarn_modulus;
        MembraneProps {
            youngs_modulus: e_m,
            poisson_ratio: self.poisson_ratio,
            shear_modulus: self.shear_ratio * e_m,
            thickness: s,
            density: self.density_ratio * surface_density / s,
        }
    }

    /// Ratios > 0, a thickness > 0 where given, −1 < ν < 1, a failure strain > 0 where
    /// given; each refusal names its `--membrane-…` flag.
    pub fn check(&self) -> Result<()> {
        for (name, v) in [
            ("membrane-density-ratio", self.density_ratio),
            ("membrane-modulus-ratio", self.modulus_ratio),
            ("membrane-shear-ratio", self.shear_ratio),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(WeftError::input(format!("--{name} = `{v}`")).expected("a ratio > 0"));
            }
        }
        if let Some(t) = self.thickness {
            if !(t > 0.0 && t.is_finite()) {
                return Err(WeftError::input(format!("--membrane-thickness = `{t}`"))
                    .expected("a thickness > 0 in m"));
            }
        }
        let nu = self.poisson_ratio;
        if !(nu > -1.0 && nu < 1.0) {
            return Err(WeftError::input(format!("--membrane-poisson = `{nu}`"))
                .expected("−1 < ν < 1 (an isotropic membrane, ν² < 1)"));
        }
        match self.failure_strain {
            Some(e) if !(e > 0.0 && e.is_finite()) => Err(WeftError::input(format!(
                "--membrane-failure-strain = `{e}`"
            ))
            .expected("a failure strain > 0 of the membrane's fibre directions (the yarns': 0.036)")
            .hint("leave it out for a membrane that cannot fail")),
            _ => Ok(()),
        }
    }
}

/// Every membrane quad part of `m` (the surround: parts named `coarse_membrane…`) fails
/// at `strain` along either fibre direction, after the failure `delay` [s], and is then
/// removed (OpenRadioss' /FAIL/FABRIC with NDIR = 1). Keeping an element whose one
/// direction has failed (NDIR = 2) leaves a quad with no stiffness along that direction,
/// which the nose then stretches without bound (a Green strain of 9 within 110 µs,
/// measured), and its stable step with it.
pub fn fail_membranes(m: &mut Model, strain: f64, delay: f64) {
    for part in m
        .parts
        .iter_mut()
        .filter(|q| q.kind == ElementKind::Quad && q.name.starts_with("coarse_membrane"))
    {
        part.props.failure_strain = Some(strain);
        part.props.failure_strain_2 = Some(strain);
        part.props.failure_delay = Some(delay);
    }
}

/// What [`coarse_membrane`] returns: for each side of the hole (x = c, y = c, and for a
/// full model x = −c, y = −c), its boundary nodes ordered along it; and the outer boundary.
pub(crate) struct Coarse {
    /// (fixed coordinate axis, value, nodes ordered by the other coordinate)
    pub(crate) hole_sides: Vec<(usize, f64, Vec<usize>)>,
    /// Outer boundary nodes.
    pub(crate) outer: Vec<usize>,
}

/// The coarse graded membrane with a hole: quads (part 90, `coarse_membrane`, element ids
/// from 10⁶) on the grid of lines `pos` (mirrored for a full model), none inside the
/// centre square of half-size `c`; node ids from `first_id`.
pub(crate) fn coarse_membrane(
    m: &mut Model,
    pos: &[f64],
    quarter: bool,
    c: f64,
    props: &MembraneProps,
    first_id: i64,
) -> Coarse {
    coarse_membrane_at(m, pos, quarter, c, props, first_id, &Sheet::default())
}

/// Which membrane sheet of a stack: its height, part id and name, and its first element id.
#[derive(Debug, Clone)]
pub(crate) struct Sheet {
    pub(crate) z: f64,
    pub(crate) part_id: i64,
    pub(crate) name: String,
    pub(crate) first_element: i64,
}

impl Default for Sheet {
    /// The single sheet: z = 0, part 90 `coarse_membrane`, elements from 10⁶.
    fn default() -> Self {
        Sheet {
            z: 0.0,
            part_id: 90,
            name: "coarse_membrane".into(),
            first_element: 1_000_000,
        }
    }
}

/// [`coarse_membrane`] as one sheet of a stack (a multi-layer fabric's surround: a sheet
/// per layer, at its height).
pub(crate) fn coarse_membrane_at(
    m: &mut Model,
    pos: &[f64],
    quarter: bool,
    c: f64,
    props: &MembraneProps,
    first_id: i64,
    sheet: &Sheet,
) -> Coarse {
    let lines: Vec<f64> = if quarter {
        pos.to_vec()
    } else {
        pos.iter()
            .rev()
            .map(|x| -x)
            .chain(pos[1..].iter().cloned())
            .collect()
    };
    let k = lines.len();
    let inside = |x: f64| x.abs() < c - 1e-12;
    let mut used = vec![false; k * k];
    let mut cells = vec![];
    for j in 0..k - 1 {
        for i in 0..k - 1 {
            let (xm, ym) = (
                0.5 * (lines[i] + lines[i + 1]),
                0.5 * (lines[j] + lines[j + 1]),
            );
            if inside(xm) && inside(ym) {
                continue;
            }
            cells.push((i, j));
            for (a, b) in [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)] {
                used[b * k + a] = true;
            }
        }
    }
    let mut idx = vec![usize::MAX; k * k];
    let mut nid = first_id;
    for j in 0..k {
        for i in 0..k {
            if used[j * k + i] {
                idx[j * k + i] = m.add_node(nid, [lines[i], lines[j], sheet.z]);
                nid += 1;
            }
        }
    }
    let part = m.add_part(sheet.part_id, &sheet.name, ElementKind::Quad, props.part());
    let mut eid = sheet.first_element;
    for (i, j) in cells {
        m.add_element(
            eid,
            part,
            &[
                idx[j * k + i],
                idx[j * k + i + 1],
                idx[(j + 1) * k + i + 1],
                idx[(j + 1) * k + i],
            ],
        );
        eid += 1;
    }
    let near = |a: f64, b: f64| (a - b).abs() < 1e-9 * c.max(1e-12);
    let mut hole_sides = vec![];
    let sides: Vec<(usize, f64)> = if quarter {
        vec![(0, c), (1, c)]
    } else {
        vec![(0, c), (1, c), (0, -c), (1, -c)]
    };
    for (axis, v) in sides {
        let mut ns: Vec<usize> = (0..k * k)
            .filter(|&q| idx[q] != usize::MAX)
            .map(|q| idx[q])
            .filter(|&n| {
                near(m.coords[n][axis], v)
                    && m.coords[n][1 - axis].abs() <= c + 1e-12
                    && (!quarter || m.coords[n][1 - axis] >= -1e-12)
            })
            .collect();
        ns.sort_by(|&a, &b| m.coords[a][1 - axis].total_cmp(&m.coords[b][1 - axis]));
        hole_sides.push((axis, v, ns));
    }
    let lo = lines[0];
    let hi = lines[k - 1];
    let outer = (0..k * k)
        .filter(|&q| idx[q] != usize::MAX)
        .map(|q| idx[q])
        .filter(|&n| {
            let x = m.coords[n];
            (!quarter && (near(x[0], lo) || near(x[1], lo))) || near(x[0], hi) || near(x[1], hi)
        })
        .collect();
    Coarse { hole_sides, outer }
}

/// Pin the coarse zone's outer edge; a quarter model gets the symmetry planes x = 0, y = 0.
pub(crate) fn hold_outer_edge(m: &mut Model, coarse: &Coarse, quarter: bool, length: f64) {
    for &o in &coarse.outer {
        m.constraints.push((o, [true, true, true]));
    }
    if quarter {
        for normal in [0, 1] {
            m.symmetry.push(SymmetryPlane {
                normal,
                position: 0.0,
                tolerance: 1e-9 * length,
            });
        }
    }
}

/// Tie every listed fine node lying on a hole side to the coarse edge it lies on.
pub(crate) fn tie_to_hole(m: &mut Model, coarse: &Coarse, fine: &[usize]) -> Result<Vec<usize>> {
    let mut tied = vec![];
    for &f in fine {
        let x = m.coords[f];
        let mut done = false;
        for (axis, v, ns) in &coarse.hole_sides {
            if (x[*axis] - v).abs() > 1e-9 * v.abs().max(1e-12) {
                continue;
            }
            let s = x[1 - axis];
            let k = ns.windows(2).position(|w| {
                m.coords[w[0]][1 - axis] <= s + 1e-12 && s <= m.coords[w[1]][1 - axis] + 1e-12
            });
            if let Some(k) = k {
                m.ties.push(Tie {
                    slave: f,
                    masters: vec![ns[k], ns[k + 1]],
                });
                tied.push(f);
                done = true;
                break;
            }
        }
        if !done {
            return Err(WeftError::input(format!(
                "node `{}` at {:?} is on no side of the coarse zone's hole",
                m.node_id[f], x
            ))
            .expected("the dense zone's boundary on the coarse grid's hole"));
        }
    }
    Ok(tied)
}

/// `axis_x` (y = 0) and `diagonal` (x = y), ordered by x: the dense zone's nodes inside
/// the centre square of half-size c, the coarse zone's beyond it (where both have a node
/// on the hole boundary, the dense zone's).
pub(crate) fn centre_line_sets(m: &mut Model, dense: &[usize], c: f64) {
    let dense_set: std::collections::HashSet<usize> = dense.iter().copied().collect();
    let cand: Vec<usize> = (0..m.num_nodes())
        .filter(|&n| {
            let x = m.coords[n];
            dense_set.contains(&n) || x[0].abs() > c + 1e-12 || x[1].abs() > c + 1e-12
        })
        .collect();
    let mut set = |name: &str, on: &dyn Fn(&[f64; 3]) -> bool| {
        let mut v: Vec<usize> = cand.iter().copied().filter(|&n| on(&m.coords[n])).collect();
        v.sort_by(|&a, &b| m.coords[a][0].total_cmp(&m.coords[b][0]));
        v.dedup_by(|a, b| (m.coords[*a][0] - m.coords[*b][0]).abs() < 1e-12);
        m.node_sets.insert(name.into(), v);
    };
    set("axis_x", &|x| x[1].abs() < 1e-12 && x[0] >= -1e-12);
    set("diagonal", &|x| {
        (x[0] - x[1]).abs() < 1e-12 && x[0] >= -1e-12
    });
}
