//! The surface contact's pure kernels, per face and per pair: a face's thickness gradient,
//! thickness box and envelope directions, the distance tests of the broad and narrow
//! phases, and the penalty force with Coulomb friction of a slave in contact (with its
//! history, [`SlaveState`]) and its release when it opens.

use crate::solver::vec3::{cross, dot, sub};

/// Gradient in the face's plane of its interpolated nodal thickness, at the face centre
/// (exact for a thickness linear over the face, as across a lenticular band's quads); zero
/// for a uniform thickness or a segment.
pub fn thickness_gradient(t: &[f64; 4], xa: &[[f64; 3]; 4], nf: usize) -> [f64; 3] {
    if nf < 3 || (0..nf).all(|a| t[a] == t[0]) {
        return [0.0; 3];
    }
    // Tangents and thickness derivatives in the face's parameters.
    let (xs, xe, ts, te) = if nf == 4 {
        (
            std::array::from_fn::<f64, 3, _>(|d| {
                0.25 * (-xa[0][d] + xa[1][d] + xa[2][d] - xa[3][d])
            }),
            std::array::from_fn::<f64, 3, _>(|d| {
                0.25 * (-xa[0][d] - xa[1][d] + xa[2][d] + xa[3][d])
            }),
            0.25 * (-t[0] + t[1] + t[2] - t[3]),
            0.25 * (-t[0] - t[1] + t[2] + t[3]),
        )
    } else {
        (
            sub(&xa[1], &xa[0]),
            sub(&xa[2], &xa[0]),
            t[1] - t[0],
            t[2] - t[0],
        )
    };
    let (a, b, c) = (dot(&xs, &xs), dot(&xs, &xe), dot(&xe, &xe));
    let det = a * c - b * b;
    if det <= 0.0 {
        return [0.0; 3];
    }
    // G = [x_ξ x_η] g⁻¹ [t_ξ, t_η]ᵀ with g the metric.
    let (u, v) = ((c * ts - b * te) / det, (a * te - b * ts) / det);
    let g: [f64; 3] = std::array::from_fn(|d| u * xs[d] + v * xe[d]);
    // A face crushed under the projectile (det → 0) would give an unbounded gradient:
    // the envelope's slope ½|G| is capped at 1 (a lenticular band's is ≤ 0.21; without
    // the cap the 60 × 60 impact went non-finite at 58 µs, measured).
    let m = dot(&g, &g).sqrt();
    if m > MAX_THICKNESS_GRADIENT {
        let s = MAX_THICKNESS_GRADIENT / m;
        [g[0] * s, g[1] * s, g[2] * s]
    } else {
        g
    }
}

/// Largest |∇t_F| the contact force takes (an envelope slope of 1).
pub const MAX_THICKNESS_GRADIENT: f64 = 2.0;

/// Friction coefficients of a definition.
#[derive(Debug, Clone, Copy)]
pub struct Friction {
    pub mu_s: f64,
    pub mu_d: f64,
    pub decay: f64,
}

/// Per-slave history.
#[derive(Debug, Clone, Copy, Default)]
pub struct SlaveState {
    /// Tangential (stick spring) force [N].
    pub ft: [f64; 3],
    /// Penalty of the last contact [N/m].
    pub k: f64,
    /// Initial penetration still being tracked [m].
    pub g0: f64,
}

/// Normal and friction force of a slave in contact: the return-mapped tangential force
/// and the pair's output. `g` > 0 the penetration, `n` the normal, `k` the penalty,
/// `vt` the tangential relative velocity over the last step Δt^{n−½}.
#[inline]
pub fn pair_force(
    g: f64,
    n: &[f64; 3],
    k: f64,
    vt: &[f64; 3],
    dt_prev: f64,
    fr: &Friction,
    st: &mut SlaveState,
) -> ([f64; 3], f64, f64) {
    if !(k > 0.0) {
        // A pair whose nodes all have no mass of their own (tie slaves, whose mass their
        // masters carry) has no penalty: no force, and nothing stored or dissipated
        // (friction's μ f_n (|f_t*| − μ f_n)/k would be 0/0).
        st.ft = [0.0; 3];
        st.k = 0.0;
        return ([0.0; 3], 0.0, 0.0);
    }
    let fnorm = k * g;
    let mut stored = 0.5 * k * g * g;
    let mut diss = 0.0;
    let mut ft = [0.0; 3];
    if fr.mu_s > 0.0 {
        // Old tangential force, in the current tangent plane.
        let o = st.ft;
        let on = dot(&o, n);
        let mut trial = [o[0] - on * n[0], o[1] - on * n[1], o[2] - on * n[2]];
        for d in 0..3 {
            trial[d] -= k * vt[d] * dt_prev;
        }
        let vtm = dot(vt, vt).sqrt();
        let mu = friction_coefficient(fr, vtm);
        let limit = mu * fnorm;
        let tm = dot(&trial, &trial).sqrt();
        if tm > limit {
            let r = if tm > 0.0 { limit / tm } else { 0.0 };
            ft = [trial[0] * r, trial[1] * r, trial[2] * r];
            diss = limit * (tm - limit) / k;
        } else {
            ft = trial;
        }
        stored += dot(&ft, &ft) / (2.0 * k);
    }
    st.ft = ft;
    st.k = k;
    (
        [
            n[0] * fnorm + ft[0],
            n[1] * fnorm + ft[1],
            n[2] * fnorm + ft[2],
        ],
        stored,
        diss,
    )
}

/// μ = μ_d + (μ_s − μ_d) e^{−d_c|v_t|} at the tangential speed `vtm`. Without a static
/// excess (μ_s − μ_d = ±0, which holds only for equal finite coefficients, or zeros of
/// either sign) and with d_c|v_t| ≥ 0 (not NaN), e^{−d_c|v_t|} lies in [0, 1], so the
/// product is the excess itself (a zero of its sign) and the sum μ_d + (μ_s − μ_d) is the
/// formula bit for bit: the exponential is skipped (any other case, NaN and infinities
/// included, takes the formula).
#[inline]
fn friction_coefficient(fr: &Friction, vtm: f64) -> f64 {
    let excess = fr.mu_s - fr.mu_d;
    if excess == 0.0 && fr.decay * vtm >= 0.0 {
        fr.mu_d + excess
    } else {
        fr.mu_d + excess * (-fr.decay * vtm).exp()
    }
}

/// A slave opens: its stick spring is released, and what it stored is dissipated (the
/// returned work [J]).
#[inline]
pub(super) fn release(st: &mut SlaveState) -> f64 {
    let w = if st.k > 0.0 {
        dot(&st.ft, &st.ft) / (2.0 * st.k)
    } else {
        0.0
    };
    st.ft = [0.0; 3];
    st.k = 0.0;
    w
}

/// The larger and the smaller of two numbers by one comparison, for the per-step box
/// computation and the box test: `f64::max`'s NaN rule took a third of the box test's
/// instructions. For finite values the same results; positions are finite whenever
/// contact runs (the model's coordinates are checked, and the integrator stops the run on
/// the step a position goes non-finite).
#[inline(always)]
pub(super) fn fmax(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// See [`fmax`].
#[inline(always)]
pub(super) fn fmin(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// The squared Euclidean distance from `p` to the box (lo, hi) = (b[0..3], b[3..6]),
/// without branches (the narrow phase's box test and the build's margins).
#[inline(always)]
pub(super) fn box_distance2(p: &[f64; 3], b: &[f64; 8]) -> f64 {
    let mut d2 = 0.0;
    for d in 0..3 {
        let e = fmax(fmax(b[d] - p[d], p[d] - b[d + 3]), 0.0);
        d2 += e * e;
    }
    d2
}

/// How far a slave at `p` is from a face's thickness box (Euclidean distance) or beyond
/// either of its envelope bounds, whichever is more [m] (see `Side::margin`).
#[inline(always)]
pub(super) fn excess(p: &[f64; 3], b: &[f64; 8], m: &[f32; 6], nf: usize) -> f64 {
    let e = box_distance2(p, b).sqrt();
    if nf < 3 {
        return e;
    }
    let m: [f64; 6] = std::array::from_fn(|k| m[k] as f64);
    let up = m[0] * p[0] + m[1] * p[1] + m[2] * p[2] - b[6];
    let dn = m[3] * p[0] + m[4] * p[1] + m[5] * p[2] - b[7];
    fmax(e, fmax(up, dn))
}

/// The empty thickness box, that of an eroded face and the start of the folds of
/// [`thickness_box`]: lo = +∞, hi = −∞ and envelope bounds −∞, so that
/// every box test and envelope filter rejects it.
pub(super) const DEAD_BOX: [f64; 8] = [
    f64::INFINITY,
    f64::INFINITY,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
];

/// The thickness box of a face (`nf` nodes `f` of nodal thicknesses `t`) at `x`: the
/// bounding box of the balls of radius t_a/2 about its nodes, (lo, hi); then the bounds
/// h = max_a (m·x_a + t_a/2) of those balls along the face's two envelope directions
/// `m` (m₊ then m₋).
#[inline]
pub(super) fn thickness_box(
    f: &[u32; 4],
    t: &[f64; 4],
    m: &[f32; 6],
    nf: usize,
    x: &[[f64; 3]],
) -> [f64; 8] {
    let m: [f64; 6] = std::array::from_fn(|k| m[k] as f64);
    let mut b = DEAD_BOX;
    for a in 0..nf {
        let (xa, r) = (&x[f[a] as usize], 0.5 * t[a]);
        for d in 0..3 {
            b[d] = fmin(b[d], xa[d] - r);
            b[d + 3] = fmax(b[d + 3], xa[d] + r);
        }
        b[6] = fmax(b[6], m[0] * xa[0] + m[1] * xa[1] + m[2] * xa[2] + r);
        b[7] = fmax(b[7], m[3] * xa[0] + m[4] * xa[1] + m[5] * xa[2] + r);
    }
    b
}

/// The unit directions m₊, m₋ of a face's envelope bounds (see
/// `MasterBoxes::set_directions_of`); zero where the face has no normal or the direction
/// is ill-defined (a zero direction never rejects: its bound is max_a t_a/2 ≥ 0).
pub(super) fn envelope_directions(
    f: &[u32; 4],
    t: &[f64; 4],
    nf: usize,
    x: &[[f64; 3]],
) -> [f32; 6] {
    let xf: [[f64; 3]; 4] =
        std::array::from_fn(|a| if a < nf { x[f[a] as usize] } else { [0.0; 3] });
    let n = if nf == 4 {
        cross(&sub(&xf[2], &xf[0]), &sub(&xf[3], &xf[1]))
    } else {
        cross(&sub(&xf[1], &xf[0]), &sub(&xf[2], &xf[0]))
    };
    let ln = dot(&n, &n).sqrt();
    if !ln.is_finite() || ln <= 0.0 {
        return [0.0; 6];
    }
    // Stored in single precision (half the memory traffic of the step's bounds), shrunk
    // by 2·10⁻⁷ first so that the rounded direction is still no longer than 1 (each
    // component rounds by at most 6·10⁻⁸ of itself): the bound stays sound.
    const SHRINK: f64 = 1.0 - 2e-7;
    let g = thickness_gradient(t, &xf, nf);
    let mut out = [0.0; 6];
    for (k, sign) in [1.0, -1.0].into_iter().enumerate() {
        let m: [f64; 3] = std::array::from_fn(|d| sign * n[d] / ln - 0.5 * g[d]);
        let l = dot(&m, &m).sqrt();
        // |m| ≥ 1 − ½|∇t_F| ≥ 0 (the gradient is capped at 2): a direction left nearly
        // undefined by cancellation is not used.
        if l > 1e-3 && l.is_finite() {
            for d in 0..3 {
                out[3 * k + d] = (SHRINK * m[d] / l) as f32;
            }
        }
    }
    out
}

/// The bounding box (lo, hi) of a face's `nf` nodes `f` at `x`.
pub(super) fn bbox(f: &[u32; 4], nf: usize, x: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &n in &f[..nf] {
        for d in 0..3 {
            lo[d] = lo[d].min(x[n as usize][d]);
            hi[d] = hi[d].max(x[n as usize][d]);
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use crate::solver::contact::{jittered_rectangle, uniform};

    /// The envelope bounds are sound: no point that penetrates a face by the narrow
    /// phase's own test (closest point q, |x_s − q| < (t_s + t_F)/2) lies beyond either
    /// bound by t_s/2 (the support-function argument in `Side::narrow_n`), over random
    /// warped quads and triangles with random nodal thicknesses (lenticular ones, zero
    /// ones) and slave thicknesses, the directions taken at other, earlier positions as
    /// between broad phases. And they reject what the thickness box cannot: over a flat
    /// quad thinning linearly from h to 0 across its width w, the envelope's top is the
    /// plane of slope s = h/(2w) through the thick edge's top (closed form), so a point
    /// h/4 above the thin edge lies outside it, though inside the box (which is h/2 high).
    #[test]
    fn envelope_bounds_hold_every_penetrating_point() {
        use super::{envelope_directions, thickness_box};
        use crate::solver::contact::closest::closest_on_face;
        let mut st = 5u64;
        let (mut penetrating, mut rejected, mut worst) = (0usize, 0usize, f64::NEG_INFINITY);
        for case in 0..60_000 {
            let nf = if case % 5 == 4 { 3 } else { 4 };
            let x = jittered_rectangle(0.4, 0.3, &mut st);
            let t: [f64; 4] = match case % 3 {
                0 => [0.2, 0.0, 0.0, 0.2],
                1 => std::array::from_fn(|_| 0.3 * uniform(&mut st)),
                _ => [0.1; 4],
            };
            let f = [0u32, 1, 2, 3];
            // Directions from positions a little away from the current ones.
            let earlier: Vec<[f64; 3]> = x
                .iter()
                .map(|a| std::array::from_fn(|d| a[d] + 0.05 * (uniform(&mut st) - 0.5)))
                .collect();
            let m32 = envelope_directions(&f, &t, nf, &earlier);
            let b = thickness_box(&f, &t, &m32, nf, &x);
            let m = m32.map(|v| v as f64);
            let xf: [[f64; 3]; 4] = std::array::from_fn(|a| x[a]);
            let ts = 0.2 * uniform(&mut st);
            for _ in 0..20 {
                let p: [f64; 3] = std::array::from_fn(|d| {
                    b[d] - 0.1 + (b[d + 3] - b[d] + 0.2) * uniform(&mut st)
                });
                let w = closest_on_face(&p, &xf, nf);
                let q: [f64; 3] = std::array::from_fn(|d| (0..nf).map(|a| w[a] * xf[a][d]).sum());
                let tf: f64 = (0..nf).map(|a| w[a] * t[a]).sum();
                let r: [f64; 3] = std::array::from_fn(|d| p[d] - q[d]);
                let c = 0.5 * (ts + tf);
                let beyond = (m[0] * p[0] + m[1] * p[1] + m[2] * p[2] - b[6])
                    .max(m[3] * p[0] + m[4] * p[1] + m[5] * p[2] - b[7])
                    - 0.5 * ts;
                if r[0] * r[0] + r[1] * r[1] + r[2] * r[2] < c * c {
                    penetrating += 1;
                    worst = worst.max(beyond);
                } else if beyond >= 0.0 {
                    rejected += 1;
                }
            }
        }
        // Measured: 306 935 penetrating points, the nearest 7.2e-4 inside its bound;
        // 486 367 of the others rejected.
        assert!(
            penetrating > 100_000 && rejected > 100_000,
            "{penetrating} {rejected}"
        );
        assert!(
            worst < 0.0,
            "a penetrating point beyond its bound by {worst:e}"
        );

        // The closed form: h = 0.1, w = 1, t = h at y = 0 and 0 at y = w.
        let (h, wd) = (0.1, 1.0);
        let x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, wd, 0.0],
            [0.0, wd, 0.0],
        ];
        let t = [h, h, 0.0, 0.0];
        let f = [0u32, 1, 2, 3];
        let m32 = envelope_directions(&f, &t, 4, &x);
        let b = thickness_box(&f, &t, &m32, 4, &x);
        let m = m32.map(|v| v as f64);
        let slope = h / (2.0 * wd);
        let top = [
            0.0,
            slope / (1.0 + slope * slope).sqrt(),
            1.0 / (1.0 + slope * slope).sqrt(),
        ];
        let k = if m[2] > 0.0 { 0 } else { 3 };
        // (Stored in single precision, shrunk by 2e-7: 2.6e-7 at most.)
        for d in 0..3 {
            assert!((m[k + d] - top[d]).abs() < 5e-7, "{m:?} against {top:?}");
        }
        let p = [0.5, wd, 0.25 * h];
        assert!(p[2] <= b[5], "inside the thickness box");
        let beyond = m[k] * p[0] + m[k + 1] * p[1] + m[k + 2] * p[2] - b[6 + k / 3];
        // (s w + h/4)/√(1 + s²) − h/2 = 0.02497 (closed form); measured error 1.7e-8, of the
        // single-precision directions.
        let expected = (slope * wd + 0.25 * h) / (1.0 + slope * slope).sqrt() - 0.5 * h;
        assert!(
            (beyond - expected).abs() < 1e-7 && beyond > 0.0,
            "{beyond} {expected}"
        );
    }

    /// The friction coefficient without its exponential (μ_s = μ_d) is bit for bit the
    /// formula μ_d + (μ_s − μ_d) e^{−d_c|v_t|}, over equal and unequal coefficients, decay
    /// coefficients and speeds including 0, negatives, infinities and NaN (the oracle: the
    /// formula itself, evaluated here).
    #[test]
    fn friction_coefficient_is_the_formula_bit_for_bit() {
        let specials = [
            0.0,
            -0.0,
            1e-300,
            0.15,
            0.2,
            1.0,
            3.5e2,
            1e308,
            -0.15,
            -1e3,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let mut checked = 0;
        let mut skipped = 0;
        for &mu_s in &specials {
            for &mu_d in &specials {
                for &decay in &specials {
                    for &vtm in &specials {
                        let fr = super::Friction { mu_s, mu_d, decay };
                        let formula = fr.mu_d + (fr.mu_s - fr.mu_d) * (-fr.decay * vtm).exp();
                        let got = super::friction_coefficient(&fr, vtm);
                        assert_eq!(
                            got.to_bits(),
                            formula.to_bits(),
                            "mu_s {mu_s}, mu_d {mu_d}, decay {decay}, |v_t| {vtm}"
                        );
                        checked += 1;
                        skipped += usize::from(mu_s - mu_d == 0.0 && decay * vtm >= 0.0);
                    }
                }
            }
        }
        // 13⁴ cases, of which the equal finite pairs (11 of 169) with d_c|v_t| ≥ 0 skip.
        assert_eq!(checked, 28561);
        assert!(skipped > 500, "{skipped} cases skipped the exponential");
    }

    /// A pair with no penalty (all its nodes massless: tie slaves) gives no force and
    /// nothing stored or dissipated, instead of friction's 0/0 (which made a patch tied
    /// into a membrane report NaN contact energy).
    #[test]
    fn a_pair_without_penalty_is_inert() {
        use super::{pair_force, Friction, SlaveState};
        let fr = Friction {
            mu_s: 0.2,
            mu_d: 0.15,
            decay: 0.0,
        };
        let mut st = SlaveState {
            ft: [0.1, 0.0, 0.0],
            k: 1.0,
            g0: 0.0,
        };
        let (f, stored, diss) = pair_force(
            1e-6,
            &[0.0, 0.0, 1.0],
            0.0,
            &[1.0, 0.0, 0.0],
            1e-8,
            &fr,
            &mut st,
        );
        assert_eq!((f, stored, diss), ([0.0; 3], 0.0, 0.0));
        assert_eq!((st.ft, st.k), ([0.0; 3], 0.0));
    }
}

/// A face a slave penetrates: the weights `w` of its foot q, the penetration `g` = c − |r|
/// (c = (t_s + t_F)/2), |r| and r = x_s − q, the face's in-plane thickness gradient (when
/// |r| > 0) and, for a slave on the mid-surface (|r| = 0), the face's unit normal. (A
/// solid's face behind which the slave lies gives g = c − s, |s| and |s| n instead, n its
/// outward normal: see [`super::solid`].)
pub(super) struct Hit {
    pub(super) w: [f64; 4],
    pub(super) g: f64,
    pub(super) dist: f64,
    pub(super) r: [f64; 3],
    pub(super) tg: [f64; 3],
    pub(super) flat: [f64; 3],
}
