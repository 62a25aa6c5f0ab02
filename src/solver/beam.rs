//! Two-node 3-D corotational beam with a rectangular b × h section (Euler–Bernoulli).
//!
//! Glossary: x₁, x₂ node positions; R₁, R₂ node rotations (global, from the reference);
//! E₀ = [e₁⁰ e₂⁰ e₃⁰] the reference element frame (e₁⁰ along the beam, e₃⁰ along the
//! section height h: global z unless the beam is parallel to z, then global y; the width
//! b lies along e₂⁰); l, l₀ current and reference lengths.
//!
//! Element frame (Crisfield, *Non-linear FE Analysis of Solids and Structures*, vol. 2,
//! §17.3): e₁ = (x₂ − x₁)/l; with the node triads Tᵢ = Rᵢ E₀, q = ½(T₁e₂⁰ + T₂e₂⁰),
//! e₃ = e₁ × q/|e₁ × q|, e₂ = e₃ × e₁. Deformational rotations θᵢ = axial vector of the
//! skew part of Eᵀ Tᵢ (small: the element's rigid rotation is taken out, however large).
//! Local deformations: u = l − l₀, twist θ₂ₓ − θ₁ₓ, bending θᵢ_y, θᵢ_z.
//!
//! Validity: any rigid rotation, but small deformational rotations (θ from the skew part,
//! shears from equilibrium): the element stays energy-consistent to O(θ²); at local
//! rotations near 1 rad per element the energy balance of a run degrades by per cents.
//!
//! Local forces (linear, in the element frame): N = EA u/l₀; T = GJ (θ₂ₓ − θ₁ₓ)/l₀;
//! M₁ = EI/l₀ (4θ₁ + 2θ₂), M₂ = EI/l₀ (2θ₁ + 4θ₂) about y (EI_y = E b h³/12) and about z
//! (EI_z = E h b³/12); shear forces from moment equilibrium. On node 1: force
//! (N, −(M₁z + M₂z)/l, (M₁y + M₂y)/l), moment (T, −M₁y, −M₁z); on node 2: force
//! (−N, (M₁z + M₂z)/l, −(M₁y + M₂y)/l), moment (−T, −M₂y, −M₂z); rotated to global by
//! E. Strain energy ½EAu²/l₀ + ½GJφ²/l₀ + Σ_{y,z} EI/l₀ (2θ₁² + 2θ₁θ₂ + 2θ₂²). Torsion
//! constant of the rectangle (c ≤ a the short and long sides): J = a c³ (1/3 − 0.21 (c/a)
//! (1 − c⁴/(12a⁴))) (Roark's Formulas, table 10.1).

/// Constant properties of one beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamProps {
    pub l0: f64,
    pub ea: f64,
    pub gj: f64,
    /// E b h³/12: bending in the e₁–e₃ plane (about e₂).
    pub eiy: f64,
    /// E h b³/12: bending in the e₁–e₂ plane (about e₃).
    pub eiz: f64,
    /// Reference frame columns e₁⁰, e₂⁰, e₃⁰.
    pub e0: [[f64; 3]; 3],
}

pub use super::vec3::Mat3;
use super::vec3::{cross, dot, mv};

/// Torsion constant of a b × h rectangle (Roark).
pub fn torsion_constant(b: f64, h: f64) -> f64 {
    let (a, c) = (b.max(h), b.min(h));
    a * c.powi(3) * (1.0 / 3.0 - 0.21 * (c / a) * (1.0 - c.powi(4) / (12.0 * a.powi(4))))
}

/// Reference frame of a beam from its end positions.
pub fn reference_frame(x1: &[f64; 3], x2: &[f64; 3]) -> Option<[[f64; 3]; 3]> {
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l = dot(&d, &d).sqrt();
    if l <= 0.0 {
        return None;
    }
    let e1 = [d[0] / l, d[1] / l, d[2] / l];
    let up = if e1[2].abs() < 0.9 {
        [0.0, 0.0, 1.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e2 = cross(&up, &e1);
    let n = dot(&e2, &e2).sqrt();
    let e2 = [e2[0] / n, e2[1] / n, e2[2] / n];
    let e3 = cross(&e1, &e2);
    Some([e1, e2, e3])
}

/// Current element frame and deformational quantities.
struct Local {
    e: [[f64; 3]; 3],
    l: f64,
    th1: [f64; 3],
    th2: [f64; 3],
}

#[inline(always)]
fn local(x1: &[f64; 3], x2: &[f64; 3], r1: &Mat3, r2: &Mat3, p: &BeamProps) -> Local {
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l = dot(&d, &d).sqrt();
    let e1 = [d[0] / l, d[1] / l, d[2] / l];
    let t1: [[f64; 3]; 3] = std::array::from_fn(|k| mv(r1, &p.e0[k]));
    let t2: [[f64; 3]; 3] = std::array::from_fn(|k| mv(r2, &p.e0[k]));
    let q = [
        0.5 * (t1[1][0] + t2[1][0]),
        0.5 * (t1[1][1] + t2[1][1]),
        0.5 * (t1[1][2] + t2[1][2]),
    ];
    let c = cross(&e1, &q);
    let n = dot(&c, &c).sqrt();
    let e3 = [c[0] / n, c[1] / n, c[2] / n];
    let e2 = cross(&e3, &e1);
    let e = [e1, e2, e3];
    // θ from the skew part of Eᵀ T: (EᵀT)_ab = e_a · t_b.
    let theta = |t: &[[f64; 3]; 3]| {
        let m = |a: usize, b: usize| dot(&e[a], &t[b]);
        [
            0.5 * (m(2, 1) - m(1, 2)),
            0.5 * (m(0, 2) - m(2, 0)),
            0.5 * (m(1, 0) - m(0, 1)),
        ]
    };
    Local {
        th1: theta(&t1),
        th2: theta(&t2),
        e,
        l,
    }
}

/// Forces and moments on the two nodes: (f₁, f₂, m₁, m₂), global.
#[inline(always)]
pub fn forces(x1: &[f64; 3], x2: &[f64; 3], r1: &Mat3, r2: &Mat3, p: &BeamProps) -> [[f64; 3]; 4] {
    let lo = local(x1, x2, r1, r2, p);
    let (t1, t2) = (lo.th1, lo.th2);
    let n = p.ea * (lo.l - p.l0) / p.l0;
    let t = p.gj * (t2[0] - t1[0]) / p.l0;
    let (m1y, m2y) = (
        p.eiy / p.l0 * (4.0 * t1[1] + 2.0 * t2[1]),
        p.eiy / p.l0 * (2.0 * t1[1] + 4.0 * t2[1]),
    );
    let (m1z, m2z) = (
        p.eiz / p.l0 * (4.0 * t1[2] + 2.0 * t2[2]),
        p.eiz / p.l0 * (2.0 * t1[2] + 4.0 * t2[2]),
    );
    let vy = (m1z + m2z) / lo.l;
    let vz = (m1y + m2y) / lo.l;
    let loc = [
        [n, -vy, vz],
        [-n, vy, -vz],
        [t, -m1y, -m1z],
        [-t, -m2y, -m2z],
    ];
    let e = &lo.e;
    std::array::from_fn(|k| {
        std::array::from_fn(|i| e[0][i] * loc[k][0] + e[1][i] * loc[k][1] + e[2][i] * loc[k][2])
    })
}

/// Strain energy [J].
#[inline(always)]
pub fn energy(x1: &[f64; 3], x2: &[f64; 3], r1: &Mat3, r2: &Mat3, p: &BeamProps) -> f64 {
    let lo = local(x1, x2, r1, r2, p);
    let (t1, t2) = (lo.th1, lo.th2);
    let u = lo.l - p.l0;
    let phi = t2[0] - t1[0];
    let bend = |ei: f64, a: f64, b: f64| ei / p.l0 * (2.0 * a * a + 2.0 * a * b + 2.0 * b * b);
    0.5 * p.ea * u * u / p.l0
        + 0.5 * p.gj * phi * phi / p.l0
        + bend(p.eiy, t1[1], t2[1])
        + bend(p.eiz, t1[2], t2[2])
}

/// R ← exp([φ]×) R (Rodrigues), for a spatial rotation increment φ.
#[inline(always)]
pub fn rotate(r: &Mat3, phi: &[f64; 3]) -> Mat3 {
    let a = dot(phi, phi).sqrt();
    if a == 0.0 {
        return *r;
    }
    let k = [phi[0] / a, phi[1] / a, phi[2] / a];
    let (s, c) = a.sin_cos();
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    let q: Mat3 = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let kk: f64 = (0..3).map(|m| kx[i][m] * kx[m][j]).sum();
            (if i == j { 1.0 } else { 0.0 }) + s * kx[i][j] + (1.0 - c) * kk
        })
    });
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|m| q[i][m] * r[m][j]).sum()))
}

// ---------------------------------------------------------------------------------------
// The beam family, which creates the rotational nodes ([`Rotations`]) of its ends.

use super::family::{
    for_chunks_of, Build, EnergyGroup, EnergyPartial, Family, ForceCtx, Per, StiffCtx, CHUNK,
};
pub use super::rotations::Rotations;
use crate::error::{Result, WeftError};
use crate::model::ElementKind;

/// Beams, struct-of-arrays; their nodes carry rotations.
#[derive(Debug, Clone, Default)]
pub struct BeamGroup {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; 2]>,
    /// Rotation indices of the two nodes.
    pub rot: Vec<[u32; 2]>,
    pub props: Vec<BeamProps>,
    /// End moments, two per beam [N·m].
    pub moments: Vec<[f64; 3]>,
    partials: Vec<EnergyPartial>,
}

impl Family for BeamGroup {
    const KIND: ElementKind = ElementKind::Beam;
    const SLOTS: usize = 2;
    const GROUP: EnergyGroup = EnergyGroup::Beam;
    fn rotational(&self) -> Option<(&[[u32; 2]], &[[f64; 3]])> {
        Some((&self.rot, &self.moments))
    }

    fn build(bd: &mut Build) -> Result<Self> {
        let m = bd.model;
        let mut g = BeamGroup::default();
        let Some(b) = m.block(ElementKind::Beam) else {
            return Ok(g);
        };
        for e in 0..b.len() {
            let p = &m.parts[b.part[e]].props;
            let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
            let e0 = reference_frame(&m.coords[a], &m.coords[c]).ok_or_else(|| {
                WeftError::input(format!("beam `{}` has zero length", b.id[e]))
                    .in_file("elements_beam.parquet")
                    .at_row(e)
                    .expected("two nodes at distinct positions")
            })?;
            let d = super::vec3::sub(&m.coords[c], &m.coords[a]);
            let l0 = dot(&d, &d).sqrt();
            let (em, rho, bw, hh) = (
                p.youngs_modulus.unwrap(),
                p.density.unwrap(),
                p.width.unwrap(),
                p.height.unwrap(),
            );
            let gm = em / (2.0 * (1.0 + p.poisson_ratio.unwrap_or(0.3)));
            let area = bw * hh;
            let me = rho * area * l0;
            // Lumped rotary inertia: each half of the beam as a rigid bar about its end
            // node's centre of mass, isotropic (J = ½ m (L² + b² + h²)/12).
            let jn = 0.5 * me * (l0 * l0 + bw * bw + hh * hh) / 12.0;
            let mut rids = [0u32; 2];
            for (k, &n) in [a, c].iter().enumerate() {
                bd.mass[n] += 0.5 * me;
                rids[k] = bd.rot.get_or_add(n);
                bd.rot.j[rids[k] as usize] += jn;
            }
            g.id.push(b.id[e]);
            g.nodes.push([a as u32, c as u32]);
            g.rot.push(rids);
            g.props.push(BeamProps {
                l0,
                ea: em * area,
                gj: gm * torsion_constant(bw, hh),
                eiy: em * bw * hh.powi(3) / 12.0,
                eiz: em * hh * bw.powi(3) / 12.0,
                e0,
            });
        }
        g.moments = vec![[0.0; 3]; 2 * g.id.len()];
        Ok(g)
    }
    fn len(&self) -> usize {
        self.id.len()
    }
    fn id(&self, e: usize) -> i64 {
        self.id[e]
    }
    fn slot_nodes(&self, e: usize) -> &[u32] {
        &self.nodes[e]
    }
    fn stiffness(&self, e: usize) -> f64 {
        self.props[e].ea / self.props[e].l0
    }
    fn forces(&mut self, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        let (x, rr) = (ctx.x, ctx.rot_r);
        let (nodes, rot, props) = (&self.nodes, &self.rot, &self.props);
        for_chunks_of(
            self.id.len(),
            (Per(fe, 2), Per(&mut self.moments[..], 2)),
            |ci, (out, mo)| {
                let e0 = ci * CHUNK;
                for (j, (f, m)) in out
                    .chunks_exact_mut(2)
                    .zip(mo.chunks_exact_mut(2))
                    .enumerate()
                {
                    let e = e0 + j;
                    let [a, b] = nodes[e];
                    let [ra, rb] = rot[e];
                    let r = forces(
                        &x[a as usize],
                        &x[b as usize],
                        &rr[ra as usize],
                        &rr[rb as usize],
                        &props[e],
                    );
                    f[0] = r[0];
                    f[1] = r[1];
                    m[0] = r[2];
                    m[1] = r[3];
                }
            },
        );
    }
    /// Row sums of M^{-1/2} K M^{-1/2}. A translational row carries the axial and
    /// bending-shear terms and the coupling 12EI/L² to the rotations (scaled by √(m/J)
    /// so that it adds to S/m); a rotational row carries 12EI/(L²√(mJ)) + (4 + 2)EI/(L J)
    /// + 2GJ/(L J). A node's bound is the larger of the two rows.
    fn stiffness_sums(&self, ctx: &StiffCtx, s: &mut [f64], _c: &mut [f64], rrow: &mut [f64]) {
        for (e, p) in self.props.iter().enumerate() {
            let [a, b] = self.nodes[e];
            let ei = p.eiy.max(p.eiz);
            let l = p.l0;
            for (n, o, rk) in [(a, b, self.rot[e][0]), (b, a, self.rot[e][1])] {
                let (n, o) = (n as usize, o as usize);
                let (mn, jn) = (ctx.mass[n].max(f64::MIN_POSITIVE), ctx.rot_j[rk as usize]);
                let wo = if ctx.fixed[o] == 0b111 { 1.0 } else { 2.0 };
                s[n] +=
                    wo * p.ea / l + 24.0 * ei / l.powi(3) + 12.0 * ei / (l * l) * (mn / jn).sqrt();
                rrow[n] += 12.0 * ei / (l * l * (mn * jn).sqrt())
                    + 6.0 * ei / (l * jn)
                    + 2.0 * p.gj / (l * jn);
            }
        }
    }
    /// The strain energy, summed serially (element order).
    fn energies(&mut self, ctx: &ForceCtx) -> &[EnergyPartial] {
        let (x, rr) = (ctx.x, ctx.rot_r);
        let e: f64 = (0..self.id.len())
            .map(|e| {
                let [a, b] = self.nodes[e];
                let [ra, rb] = self.rot[e];
                energy(
                    &x[a as usize],
                    &x[b as usize],
                    &rr[ra as usize],
                    &rr[rb as usize],
                    &self.props[e],
                )
            })
            .sum();
        self.partials.clear();
        self.partials.push([e, 0.0, 0.0, 0.0]);
        &self.partials
    }
}
