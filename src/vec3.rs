//! Small fixed-size vector helpers on `[f64; 3]`, shared by every kernel.
//!
//! Each is written out component by component, in the order a hand-written kernel
//! would use, so replacing a local copy by these changes no result bit.

pub type Vec3 = [f64; 3];
/// A 3 × 3 matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

#[inline(always)]
pub fn add(a: &mut Vec3, b: &Vec3) {
    a[0] += b[0];
    a[1] += b[1];
    a[2] += b[2];
}

#[inline(always)]
pub fn sub(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
pub fn dot(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The triple product [p, q, r] = p·(q × r).
#[inline(always)]
pub fn triple(p: &Vec3, q: &Vec3, r: &Vec3) -> f64 {
    dot(p, &cross(q, r))
}

/// y += s x.
#[inline(always)]
pub fn axpy(y: &mut Vec3, s: f64, x: &Vec3) {
    y[0] += s * x[0];
    y[1] += s * x[1];
    y[2] += s * x[2];
}

#[inline(always)]
pub fn scale(a: &Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
pub fn norm(a: &Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// a/|a|, or `None` for the zero vector.
#[inline(always)]
pub fn unit(a: Vec3) -> Option<Vec3> {
    let n = dot(&a, &a).sqrt();
    (n > 0.0).then(|| [a[0] / n, a[1] / n, a[2] / n])
}

/// Matrix times vector.
#[inline(always)]
pub fn mv(r: &Mat3, v: &Vec3) -> Vec3 {
    std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

/// Σ w_a x_a over the first `w.len()` points.
#[inline(always)]
pub fn lerp_points(w: &[f64], x: &[Vec3]) -> Vec3 {
    std::array::from_fn(|d| (0..w.len()).map(|a| w[a] * x[a][d]).sum())
}
