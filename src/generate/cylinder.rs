//! Hexahedral meshes of bodies of revolution about the z axis, for the Taylor rod and
//! the deformable bullet: a quarter disk (x ≥ 0, y ≥ 0) in quads, extruded along z
//! through given stations with the radius of each station scaled (a round nose).
//!
//! The quarter disk of radius R is an O-grid: a square core [0, a]² (a = 0.45 R, n × n
//! cells) and two blocks of n × m cells that join the core's edges x = a and y = a to
//! the arcs θ ∈ [0, 45°] and [45°, 90°] by straight lines, so that no cell degenerates at
//! the axis and the cells at the rim are nearly square for m ≈ n. Points that coincide
//! (the blocks' shared edges) are one node: coordinates are keyed on a grid of R·10⁻⁹.

use std::collections::BTreeMap;

/// A planar mesh: points (x, y) and counter-clockwise quads (seen from +z).
#[derive(Debug, Clone, Default)]
pub struct Disk {
    pub points: Vec<[f64; 2]>,
    pub quads: Vec<[usize; 4]>,
    key: BTreeMap<(i64, i64), usize>,
    unit: f64,
}

impl Disk {
    pub(crate) fn point(&mut self, p: [f64; 2]) -> usize {
        let k = (
            (p[0] / self.unit).round() as i64,
            (p[1] / self.unit).round() as i64,
        );
        let n = self.points.len();
        *self.key.entry(k).or_insert_with(|| {
            self.points.push(p);
            n
        })
    }

    /// Add a structured block of (ni × nj) cells whose point (i, j) is `at(i, j)`,
    /// oriented so that its quads turn counter-clockwise.
    fn block(&mut self, ni: usize, nj: usize, at: impl Fn(usize, usize) -> [f64; 2]) {
        let mut ids = vec![vec![0; nj + 1]; ni + 1];
        for (i, row) in ids.iter_mut().enumerate() {
            for (j, id) in row.iter_mut().enumerate() {
                *id = self.point(at(i, j));
            }
        }
        for i in 0..ni {
            for j in 0..nj {
                let q = [ids[i][j], ids[i + 1][j], ids[i + 1][j + 1], ids[i][j + 1]];
                let p = q.map(|k| self.points[k]);
                let area2: f64 = (0..4)
                    .map(|a| {
                        let (u, v) = (p[a], p[(a + 1) % 4]);
                        u[0] * v[1] - v[0] * u[1]
                    })
                    .sum();
                self.quads.push(if area2 > 0.0 {
                    q
                } else {
                    [q[0], q[3], q[2], q[1]]
                });
            }
        }
    }
}

/// The quarter disk of radius `r`: n cells along the core's side and each 45° arc, m
/// cells from the core to the rim.
pub fn quarter_disk(r: f64, n: usize, m: usize) -> Disk {
    let a = 0.45 * r;
    let mut d = Disk {
        unit: r * 1e-9,
        ..Default::default()
    };
    let (nf, mf) = (n as f64, m as f64);
    d.block(n, n, |i, j| [a * i as f64 / nf, a * j as f64 / nf]);
    let lerp =
        |p: [f64; 2], q: [f64; 2], t: f64| [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
    let quarter = std::f64::consts::FRAC_PI_4;
    d.block(n, m, |j, k| {
        let th = quarter * j as f64 / nf;
        lerp(
            [a, a * j as f64 / nf],
            [r * th.cos(), r * th.sin()],
            k as f64 / mf,
        )
    });
    d.block(n, m, |i, k| {
        let th = quarter * i as f64 / nf;
        lerp(
            [a * i as f64 / nf, a],
            [r * th.sin(), r * th.cos()],
            k as f64 / mf,
        )
    });
    d
}

/// The disk extruded through the stations `z` (ascending), the points at station k
/// scaled radially by `scale[k]` (1 for a cylinder): nodes (x, y, z) in order station by
/// station, and hexahedra in LS-DYNA's order (n1–n4 the lower face counter-clockwise
/// seen from +z, n5–n8 above), layer by layer.
pub fn extrude(d: &Disk, z: &[f64], scale: &[f64]) -> (Vec<[f64; 3]>, Vec<[usize; 8]>) {
    let np = d.points.len();
    let mut nodes = Vec::with_capacity(np * z.len());
    for (k, &zk) in z.iter().enumerate() {
        for p in &d.points {
            nodes.push([scale[k] * p[0], scale[k] * p[1], zk]);
        }
    }
    let mut hexes = Vec::with_capacity(d.quads.len() * z.len().saturating_sub(1));
    for k in 0..z.len().saturating_sub(1) {
        for q in &d.quads {
            let lo = q.map(|i| k * np + i);
            let hi = q.map(|i| (k + 1) * np + i);
            hexes.push([lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]]);
        }
    }
    (nodes, hexes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quarter disk's quads tile the polygon inscribed in the quarter circle: 2n
    /// chords of angle π/(4n), area (R²/2)·2n·sin(π/(4n)) (elementary geometry), with
    /// each point once.
    #[test]
    fn quarter_disk_area_is_the_polygons() {
        let (r, n, m) = (1.0, 4, 4);
        let d = quarter_disk(r, n, m);
        let area: f64 = d
            .quads
            .iter()
            .map(|q| {
                let p = q.map(|k| d.points[k]);
                0.5 * (0..4)
                    .map(|a| {
                        let (u, v) = (p[a], p[(a + 1) % 4]);
                        u[0] * v[1] - v[0] * u[1]
                    })
                    .sum::<f64>()
            })
            .sum();
        // The inscribed polygon of 2n chords over the quarter: (R²/2)·2n·sin(π/(4n)).
        let th = std::f64::consts::FRAC_PI_4 / n as f64;
        let polygon = 0.5 * r * r * (2 * n) as f64 * th.sin();
        assert!((area - polygon).abs() < 1e-14, "{area} vs {polygon}");
        assert_eq!(d.quads.len(), n * n + 2 * n * m);
        // (n+1)² core points, and each block adds n+1 rows of m new points, less the
        // shared diagonal row of m.
        assert_eq!(d.points.len(), (n + 1) * (n + 1) + 2 * (n + 1) * m - m);
    }
}
