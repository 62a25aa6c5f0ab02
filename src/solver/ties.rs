//! Tied interfaces: a slave node on a master edge (2 nodes), triangle (3) or quad (4)
//! moves with its masters, x_s = Σ w_a x_a (+ the offset a formed model's initial
//! displacements give it), v_s = Σ w_a v_a, with the weights of its
//! reference position on the master entity; its mass and every force on it go to the
//! masters with the same weights (so momentum is exchanged exactly and the work of the
//! slave's forces is the work on the masters).

use super::vec3::{add, dot, sub};
use crate::error::{Result, WeftError};
use crate::model::Model;

/// One tied slave.
#[derive(Debug, Clone)]
pub struct Tie {
    pub slave: usize,
    pub masters: Vec<usize>,
    /// Interpolation weights, ≥ 0, summing to 1.
    pub w: Vec<f64>,
    /// x_s − Σ w_a x_a kept from the initial state: the initial displacements' difference
    /// u₀,s − Σ w_a u₀,a (a formed model whose tied nodes moved apart while forming; zero
    /// without initial displacements).
    pub offset: [f64; 3],
}

/// Weights of a point on a master edge (2 nodes: projection), triangle (barycentric) or
/// quad (inverse bilinear map), and the distance of the point from the master entity.
pub fn tie_weights(p: &[f64; 3], m: &[[f64; 3]]) -> (Vec<f64>, f64) {
    let lerp_err = |w: &[f64]| {
        let q: [f64; 3] = std::array::from_fn(|d| (0..m.len()).map(|a| w[a] * m[a][d]).sum());
        let e = sub(p, &q);
        dot(&e, &e).sqrt()
    };
    match m.len() {
        2 => {
            let e = sub(&m[1], &m[0]);
            let t = dot(&sub(p, &m[0]), &e) / dot(&e, &e);
            let w = vec![1.0 - t, t];
            let d = lerp_err(&w);
            (w, d)
        }
        3 => {
            let (e1, e2, r) = (sub(&m[1], &m[0]), sub(&m[2], &m[0]), sub(p, &m[0]));
            let (a, b, c) = (dot(&e1, &e1), dot(&e1, &e2), dot(&e2, &e2));
            let (d1, d2) = (dot(&r, &e1), dot(&r, &e2));
            let det = a * c - b * b;
            let (u, v) = ((c * d1 - b * d2) / det, (a * d2 - b * d1) / det);
            let w = vec![1.0 - u - v, u, v];
            let d = lerp_err(&w);
            (w, d)
        }
        _ => {
            // Newton on the bilinear map x(ξ, η) = Σ N_a x_a, least squares in 3-D.
            let (mut xi, mut eta) = (0.0f64, 0.0f64);
            let sh = |xi: f64, eta: f64| {
                [
                    0.25 * (1.0 - xi) * (1.0 - eta),
                    0.25 * (1.0 + xi) * (1.0 - eta),
                    0.25 * (1.0 + xi) * (1.0 + eta),
                    0.25 * (1.0 - xi) * (1.0 + eta),
                ]
            };
            for _ in 0..30 {
                let n = sh(xi, eta);
                let x: [f64; 3] = std::array::from_fn(|d| (0..4).map(|a| n[a] * m[a][d]).sum());
                let dxi: [f64; 3] = std::array::from_fn(|d| {
                    0.25 * (-(1.0 - eta) * m[0][d] + (1.0 - eta) * m[1][d] + (1.0 + eta) * m[2][d]
                        - (1.0 + eta) * m[3][d])
                });
                let deta: [f64; 3] = std::array::from_fn(|d| {
                    0.25 * (-(1.0 - xi) * m[0][d] - (1.0 + xi) * m[1][d]
                        + (1.0 + xi) * m[2][d]
                        + (1.0 - xi) * m[3][d])
                });
                let r = sub(p, &x);
                let (a, b, c) = (dot(&dxi, &dxi), dot(&dxi, &deta), dot(&deta, &deta));
                let (g1, g2) = (dot(&r, &dxi), dot(&r, &deta));
                let det = a * c - b * b;
                if det.abs() < f64::MIN_POSITIVE {
                    break;
                }
                xi += (c * g1 - b * g2) / det;
                eta += (a * g2 - b * g1) / det;
            }
            let w = sh(xi, eta).to_vec();
            let d = lerp_err(&w);
            (w, d)
        }
    }
}

/// Every tie of a model.
#[derive(Debug, Clone, Default)]
pub struct Ties {
    pub ties: Vec<Tie>,
    /// Whether each node is a slave.
    pub is_slave: Vec<bool>,
}

impl Ties {
    /// Weights from the reference geometry; each slave's mass goes to its masters.
    pub fn build(m: &Model, mass: &mut [f64]) -> Result<Ties> {
        let mut ties = Vec::with_capacity(m.ties.len());
        let mut is_slave = vec![false; m.num_nodes()];
        for (row, t) in m.ties.iter().enumerate() {
            let mx: Vec<[f64; 3]> = t.masters.iter().map(|&a| m.coords[a]).collect();
            let (w, dist) = tie_weights(&m.coords[t.slave], &mx);
            let size = (1..mx.len())
                .map(|a| {
                    let d = sub(&mx[a], &mx[0]);
                    dot(&d, &d).sqrt()
                })
                .fold(0.0, f64::max);
            let tol = 1e-6 * size;
            if !(dist <= tol && w.iter().all(|&x| x >= -1e-9 && x <= 1.0 + 1e-9)) {
                return Err(WeftError::input(format!(
                    "tied node `{}` is not on its master {} (distance {dist:.3e} m, weights {w:?})",
                    m.node_id[t.slave],
                    if mx.len() == 2 { "edge" } else { "face" }
                ))
                .in_file("ties.parquet")
                .at_row(row)
                .expected(format!(
                    "the slave on the edge or face of its masters, within {tol:.1e} m"
                ))
                .hint(
                    "order the masters around the face, or tie the node to the entity it lies on",
                ));
            }
            let w: Vec<f64> = w.iter().map(|x| x.clamp(0.0, 1.0)).collect();
            let sum: f64 = w.iter().sum();
            let w: Vec<f64> = w.iter().map(|x| x / sum).collect();
            for (a, &mn) in t.masters.iter().enumerate() {
                mass[mn] += w[a] * mass[t.slave];
            }
            mass[t.slave] = 0.0;
            is_slave[t.slave] = true;
            let mut offset = [0.0; 3];
            if !m.initial_displacement.is_empty() {
                let u0 = &m.initial_displacement;
                for d in 0..3 {
                    offset[d] = u0[t.slave][d]
                        - t.masters
                            .iter()
                            .zip(&w)
                            .map(|(&a, wa)| wa * u0[a][d])
                            .sum::<f64>();
                }
            }
            ties.push(Tie {
                slave: t.slave,
                masters: t.masters.clone(),
                w,
                offset,
            });
        }
        Ok(Ties { ties, is_slave })
    }

    pub fn is_empty(&self) -> bool {
        self.ties.is_empty()
    }

    /// The tie of a slave node.
    pub fn of_slave(&self, n: usize) -> Option<&Tie> {
        self.ties.iter().find(|t| t.slave == n)
    }

    /// Transfers each slave's total force (`force_on(slave)`) to its masters, into `f`;
    /// the masters are pushed on `touched`.
    pub fn transfer(
        &self,
        force_on: impl Fn(usize, &[[f64; 3]]) -> [f64; 3],
        f: &mut [[f64; 3]],
        touched: &mut Vec<usize>,
    ) {
        for t in &self.ties {
            let fs = force_on(t.slave, f);
            for (a, &mn) in t.masters.iter().enumerate() {
                add(
                    &mut f[mn],
                    &[t.w[a] * fs[0], t.w[a] * fs[1], t.w[a] * fs[2]],
                );
                touched.push(mn);
            }
        }
    }

    /// Slaves follow their masters: x_s = Σ w_a x_a, v_s = Σ w_a v_a (and v^n into `vn`
    /// when given).
    pub fn update_slaves(
        &self,
        x: &mut [[f64; 3]],
        v: &mut [[f64; 3]],
        mut vn: Option<&mut [[f64; 3]]>,
    ) {
        for t in &self.ties {
            let mut xs = [0.0; 3];
            let mut vs = [0.0; 3];
            let mut vns = [0.0; 3];
            for (a, &mn) in t.masters.iter().enumerate() {
                for d in 0..3 {
                    xs[d] += t.w[a] * x[mn][d];
                    vs[d] += t.w[a] * v[mn][d];
                    if let Some(vn) = vn.as_deref() {
                        vns[d] += t.w[a] * vn[mn][d];
                    }
                }
            }
            x[t.slave] = [
                xs[0] + t.offset[0],
                xs[1] + t.offset[1],
                xs[2] + t.offset[2],
            ];
            v[t.slave] = vs;
            if let Some(vn) = vn.as_deref_mut() {
                vn[t.slave] = vns;
            }
        }
    }
}
