//! Linear statics on the same model: K u = F at the reference configuration.
//!
//! Each element's stiffness is the central finite difference of its own internal-force
//! kernel at the reference positions, K_e = −∂f/∂x (so statics and dynamics share one
//! definition of every element; the kernels are smooth there, and the difference step
//! 10⁻⁶ × the element size gives K_e to about 10⁻⁹ relative). Tension-only trusses and
//! no-compression membranes are taken as linear (a linear solve cannot be unilateral);
//! links contribute their springs, not their dashpots or sliders. Loads are the
//! amplitudes F of `loads.parquet` (the time laws are ignored). Fixed directions and
//! symmetry planes remove degrees of freedom; a tied slave's degrees of freedom are
//! expressed through its masters (u_s = Σ w_a u_a), so K and F are condensed with the
//! same weights the dynamics use. A degree of freedom without stiffness and without load
//! (the out-of-plane direction of a flat membrane) is held and counted; one with a load
//! is an error. The system is solved by sparse Cholesky (nalgebra-sparse), which also
//! detects mechanisms (a matrix that is not positive definite).

use std::time::Instant;

use nalgebra::{DMatrix, DVector};
use nalgebra_sparse::factorization::CscCholesky;
use nalgebra_sparse::{CooMatrix, CscMatrix};

use std::collections::HashMap;

use super::ties::Tie;
use super::{beam, link, membrane, truss, Solver};
use crate::error::{Result, WeftError};
use crate::model::Model;

/// What a static solve reports.
#[derive(Debug, Clone)]
pub struct StaticReport {
    /// Displacement of every node [m].
    pub u: Vec<[f64; 3]>,
    /// Free degrees of freedom solved for.
    pub dofs: usize,
    /// Degrees of freedom without stiffness or load, held at zero.
    pub held: usize,
    /// Non-zeros in the factorised matrix.
    pub nonzeros: usize,
    pub assemble_seconds: f64,
    pub solve_seconds: f64,
}

/// Central-difference stiffness of a force kernel over `N` nodes.
fn fd_stiffness<const N: usize>(
    x0: &[[f64; 3]; N],
    h: f64,
    f: impl Fn(&[[f64; 3]; N]) -> [[f64; 3]; N],
) -> Vec<f64> {
    let n = 3 * N;
    let mut k = vec![0.0; n * n];
    for j in 0..n {
        let (mut xp, mut xm) = (*x0, *x0);
        xp[j / 3][j % 3] += h;
        xm[j / 3][j % 3] -= h;
        let (fp, fm) = (f(&xp), f(&xm));
        for i in 0..n {
            k[i * n + j] = -(fp[i / 3][i % 3] - fm[i / 3][i % 3]) / (2.0 * h);
        }
    }
    // Symmetrise: the exact tangent of a hyperelastic element is symmetric.
    for i in 0..n {
        for j in 0..i {
            let a = 0.5 * (k[i * n + j] + k[j * n + i]);
            k[i * n + j] = a;
            k[j * n + i] = a;
        }
    }
    k
}

/// The equations of the free degrees of freedom: each node direction that is neither
/// fixed nor a tied slave's has one, then each free axis of a beam node's rotation (after
/// the translations). A slave's directions are expressed through its masters
/// (u_s = Σ w_a u_a).
struct Dofs<'a> {
    /// Equation of each node's direction (usize::MAX: none).
    eq: Vec<[usize; 3]>,
    /// Equation of each rotational node's axis (usize::MAX: none).
    eqr: Vec<[usize; 3]>,
    /// Number of equations.
    neq: usize,
    /// The tie of each slave node.
    slave: HashMap<usize, usize>,
    ties: &'a [Tie],
}

/// One degree of freedom's equations and weights (none: it is held).
type DofMap = Vec<(usize, f64)>;

impl<'a> Dofs<'a> {
    /// The equations of a solver's model (the translations, then the rotations).
    fn new(s: &'a Solver) -> Dofs<'a> {
        let nn = s.x0.len();
        // Degree-of-freedom maps: node direction → [(equation, weight)].
        let mut eq = vec![[usize::MAX; 3]; nn];
        let mut neq = 0;
        let slave: HashMap<usize, usize> =
            s.op.ties
                .ties
                .iter()
                .enumerate()
                .map(|(k, t)| (t.slave, k))
                .collect();
        for i in 0..nn {
            if slave.contains_key(&i) {
                continue;
            }
            for d in 0..3 {
                if s.fixed[i] & (1 << d) == 0 {
                    eq[i][d] = neq;
                    neq += 1;
                }
            }
        }
        // Rotations of beam nodes, after the translations.
        let mut eqr = vec![[usize::MAX; 3]; s.state.rot.node.len()];
        for (k, e) in eqr.iter_mut().enumerate() {
            for d in 0..3 {
                if s.state.rot.fixed[k] & (1 << d) == 0 {
                    e[d] = neq;
                    neq += 1;
                }
            }
        }
        Dofs {
            eq,
            eqr,
            neq,
            slave,
            ties: &s.op.ties.ties,
        }
    }

    /// Axis `d` of rotational node `k`.
    fn rotation(&self, k: usize, d: usize) -> DofMap {
        if self.eqr[k][d] == usize::MAX {
            vec![]
        } else {
            vec![(self.eqr[k][d], 1.0)]
        }
    }

    /// Direction `d` of node `i` (a slave's: its masters' free directions, weighted).
    fn node(&self, i: usize, d: usize) -> DofMap {
        let eq = &self.eq;
        match self.slave.get(&i) {
            Some(&k) => {
                let t = &self.ties[k];
                t.masters
                    .iter()
                    .zip(&t.w)
                    .filter(|(&a, _)| eq[a][d] != usize::MAX)
                    .map(|(&a, &wa)| (eq[a][d], wa))
                    .collect()
            }
            None if eq[i][d] != usize::MAX => vec![(eq[i][d], 1.0)],
            None => vec![],
        }
    }

    /// The three directions of each of `nodes`, in order.
    fn nodes(&self, nodes: &[usize]) -> Vec<DofMap> {
        (0..3 * nodes.len())
            .map(|p| self.node(nodes[p / 3], p % 3))
            .collect()
    }

    /// The node and direction of equation `i` (of a translation).
    fn of_equation(&self, i: usize) -> (usize, usize) {
        (0..self.eq.len())
            .flat_map(|a| (0..3).map(move |d| (a, d)))
            .find(|&(a, d)| self.eq[a][d] == i)
            .unwrap_or((0, 0))
    }

    /// The load vector: the amplitudes F of the loads (their time laws ignored).
    fn loads(&self, loads: &[crate::model::Load]) -> Vec<f64> {
        let mut f = vec![0.0; self.neq];
        for ld in loads {
            for d in 0..3 {
                for (i, w) in self.node(ld.node, d) {
                    f[i] += w * ld.force[d];
                }
            }
        }
        f
    }
}

/// The stiffness matrix as triplets (row, column, value), in assembly order (the order in
/// which duplicates are summed).
struct Triplets<'d> {
    dofs: &'d Dofs<'d>,
    trip: Vec<(usize, usize, f64)>,
}

impl Triplets<'_> {
    /// An element stiffness `ke` over the degrees of freedom `maps`.
    fn add_maps(&mut self, maps: &[DofMap], ke: &[f64]) {
        let n = maps.len();
        for p in 0..n {
            for q in 0..n {
                let v = ke[p * n + q];
                if v == 0.0 {
                    continue;
                }
                for &(i, wi) in &maps[p] {
                    for &(j, wj) in &maps[q] {
                        self.trip.push((i, j, wi * wj * v));
                    }
                }
            }
        }
    }

    /// An element stiffness `ke` over the translations of `nodes`.
    fn add_element(&mut self, nodes: &[usize], ke: &[f64]) {
        let maps = self.dofs.nodes(nodes);
        self.add_maps(&maps, ke);
    }
}

/// The equations kept in the solve: those with stiffness (`keep[i]`: the kept index of
/// equation i, usize::MAX when held), how many, and how many are held at zero.
struct Kept {
    keep: Vec<usize>,
    n: usize,
    held: usize,
}

impl Kept {
    /// K and F over the kept equations.
    fn system(&self, trip: Vec<(usize, usize, f64)>, f: &[f64]) -> (CscMatrix<f64>, DVector<f64>) {
        let (keep, n) = (&self.keep, self.n);
        let mut coo = CooMatrix::new(n, n);
        for (i, j, v) in trip {
            let (a, b) = (keep[i], keep[j]);
            if a != usize::MAX && b != usize::MAX {
                coo.push(a, b, v);
            }
        }
        let rhs = DVector::from_iterator(
            n,
            (0..f.len())
                .filter(|&i| keep[i] != usize::MAX)
                .map(|i| f[i]),
        );
        (CscMatrix::from(&coo), rhs)
    }
}

impl Solver {
    /// Solve the linear static problem of `m` (the model this solver was built from).
    pub fn solve_static(&self, m: &Model) -> Result<StaticReport> {
        let t0 = Instant::now();
        let dofs = Dofs::new(self);
        let mut k = Triplets {
            dofs: &dofs,
            trip: Vec::new(),
        };
        self.add_stiffness(&mut k);
        let f = dofs.loads(&m.loads);
        let kept = self.hold_unresisted(&k.trip, &f, &dofs)?;
        let (csc, rhs) = kept.system(k.trip, &f);
        let nonzeros = csc.nnz();
        let t1 = Instant::now();
        let chol = self.factor(&csc, &kept, &dofs)?;
        let sol = chol.solve(&rhs);
        let u = displacements(&sol, &kept, &dofs)?;
        Ok(StaticReport {
            u,
            dofs: kept.n,
            held: kept.held,
            nonzeros,
            assemble_seconds: (t1 - t0).as_secs_f64(),
            solve_seconds: t1.elapsed().as_secs_f64(),
        })
    }

    /// Every element's stiffness into `k`, family by family (trusses, links, framed
    /// links, sliding links, triangles, quads, beams).
    fn add_stiffness(&self, k: &mut Triplets) {
        let x0 = &self.x0;
        let g = &self.op.el.truss;
        for e in 0..g.id.len() {
            let [a, b] = g.nodes[e].map(|v| v as usize);
            let ke = fd_stiffness(&[x0[a], x0[b]], 1e-6 * g.l0[e], |x| {
                let f2 = truss::force(&x[0], &x[1], g.k[e], g.l0[e], false);
                [[-f2[0], -f2[1], -f2[2]], f2]
            });
            k.add_element(&[a, b], &ke);
        }
        let l = &self.op.el.link;
        for e in 0..l.id.len() {
            let [a, b] = l.nodes[e].map(|v| v as usize);
            let ke = fd_stiffness(&[x0[a], x0[b]], 1e-6, |x| {
                let f2 = link::elastic_force(
                    &link::rel_disp(&x[0], &x[1], &l.d0[e]),
                    &l.props[e],
                    &[0.0; 2],
                );
                [[-f2[0], -f2[1], -f2[2]], f2]
            });
            k.add_element(&[a, b], &ke);
        }
        let l = &self.op.el.framed_link;
        for e in 0..l.id.len() {
            let nodes: [usize; 6] = l.nodes[e].map(|v| v as usize);
            let xe: [[f64; 3]; 6] = std::array::from_fn(|k| x0[nodes[k]]);
            let h = 1e-6 * l.chords[e][0].min(l.chords[e][1]);
            let ke = fd_stiffness(&xe, h, |x| l.reference_forces(e, x));
            k.add_element(&nodes, &ke);
        }
        self.add_sliding_links(k);
        add_membranes(&self.op.el.tri, x0, k);
        add_membranes(&self.op.el.quad, x0, k);
        self.add_beams(k);
    }

    /// Sliding links: stuck at their reference anchors, on their window nodes (a short
    /// window's padding repeats its last node, whose padding slots carry no force).
    fn add_sliding_links(&self, k: &mut Triplets) {
        use super::sliding_link::WIN;
        let (x0, l) = (&self.x0, &self.op.el.sliding_link);
        for e in 0..l.id.len() {
            let nodes: [usize; 2 * WIN] = l.nodes[e].map(|v| v as usize);
            let xe: [[f64; 3]; 2 * WIN] = std::array::from_fn(|k| x0[nodes[k]]);
            let chord = super::vec3::norm(&super::vec3::sub(&xe[1], &xe[0]));
            let ke = fd_stiffness(&xe, 1e-6 * chord, |x| {
                let xs = [
                    std::array::from_fn(|k| x[k]),
                    std::array::from_fn(|k| x[WIN + k]),
                ];
                l.reference_forces(e, &xs)
            });
            k.add_element(&nodes, &ke);
        }
    }

    /// Beams, over their nodes' translations and rotations.
    fn add_beams(&self, k: &mut Triplets) {
        let (x0, bg) = (&self.x0, &self.op.el.beam);
        for e in 0..bg.id.len() {
            let [a, b] = bg.nodes[e].map(|v| v as usize);
            let [ra, rb] = bg.rot[e].map(|v| v as usize);
            let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            // Unknowns [x₁, x₂, φ₁, φ₂]; φ a rotation increment of the node.
            let ke = fd_stiffness(
                &[x0[a], x0[b], [0.0; 3], [0.0; 3]],
                1e-6 * bg.props[e].l0,
                |u| {
                    let (r1, r2) = (beam::rotate(&eye, &u[2]), beam::rotate(&eye, &u[3]));
                    beam::forces(&u[0], &u[1], &r1, &r2, &bg.props[e])
                },
            );
            let mut maps = k.dofs.nodes(&[a, b]);
            for r in [ra, rb] {
                for d in 0..3 {
                    maps.push(k.dofs.rotation(r, d));
                }
            }
            k.add_maps(&maps, &ke);
        }
    }

    /// Hold degrees of freedom without stiffness (and refuse loaded ones).
    fn hold_unresisted(
        &self,
        trip: &[(usize, usize, f64)],
        f: &[f64],
        dofs: &Dofs,
    ) -> Result<Kept> {
        let neq = dofs.neq;
        let mut diag = vec![0.0f64; neq];
        for &(i, j, v) in trip {
            if i == j {
                diag[i] += v;
            }
        }
        let dmax = diag.iter().cloned().fold(0.0, f64::max);
        let mut keep = vec![usize::MAX; neq];
        let mut n = 0;
        let mut held = 0;
        for i in 0..neq {
            if diag[i] > 1e-12 * dmax {
                keep[i] = n;
                n += 1;
            } else if f[i] != 0.0 {
                let (node, d) = dofs.of_equation(i);
                return Err(WeftError::input(format!(
                    "node `{}` is loaded along {} but nothing resists motion in that direction",
                    self.node_id[node],
                    ["x", "y", "z"][d]
                ))
                .in_file("loads.parquet")
                .expected("a load only where elements give stiffness")
                .hint("a flat membrane has no stiffness out of its plane in a linear static solve; fix that direction or load in-plane"));
            } else {
                held += 1;
            }
        }
        Ok(Kept { keep, n, held })
    }

    /// The Cholesky factor of K, or the error of a mechanism: a failed factorisation, or
    /// a pivot far below its diagonal.
    fn factor(&self, csc: &CscMatrix<f64>, kept: &Kept, dofs: &Dofs) -> Result<CscCholesky<f64>> {
        let chol = CscCholesky::factor(csc).map_err(|e| {
            WeftError::input(format!("the stiffness matrix is not positive definite ({e:?}): the model is a mechanism or is not held against rigid motion"))
                .expected("enough constraints to remove every rigid-body motion, and no mechanism (e.g. a pin-jointed grid in shear)")
                .hint("add constraints or symmetry planes; use rigid joints (beams) where the structure must carry shear")
        })?;
        // A singular matrix can slip through the factorisation with round-off pivots:
        // a pivot L_ii² far below K_ii means a mechanism.
        let l = chol.l();
        let mut worst = (f64::INFINITY, 0usize);
        for i in 0..kept.n {
            let kd = csc.get_entry(i, i).map(|e| e.into_value()).unwrap_or(0.0);
            let lii = l.get_entry(i, i).map(|e| e.into_value()).unwrap_or(0.0);
            let ratio = lii * lii / kd;
            if ratio < worst.0 {
                worst = (ratio, i);
            }
        }
        if worst.0 < 1e-10 {
            let eq_of = (0..dofs.neq)
                .find(|&k| kept.keep[k] == worst.1)
                .unwrap_or(0);
            let (node, d) = dofs.of_equation(eq_of);
            return Err(WeftError::input(format!(
                "the stiffness matrix is not positive definite (pivot ratio {:.1e} at node `{}`, direction {}): the model is a mechanism or is not held against rigid motion",
                worst.0,
                self.node_id[node],
                ["x", "y", "z"][d]
            ))
            .expected("enough constraints to remove every rigid-body motion, and no mechanism (e.g. a pin-jointed grid in shear)")
            .hint("add constraints or symmetry planes; use rigid joints (beams) where the structure must carry shear"));
        }
        Ok(chol)
    }
}

/// Membrane triangles or quads (linear: without their no-compression rule).
fn add_membranes<const N: usize>(
    grp: &super::membrane::MembraneGroup<N>,
    x0: &[[f64; 3]],
    k: &mut Triplets,
) {
    for e in 0..grp.id.len() {
        let nodes: [usize; N] = grp.nodes[e].map(|v| v as usize);
        let xe: [[f64; 3]; N] = std::array::from_fn(|a| x0[nodes[a]]);
        let mut mat = grp.material[e];
        mat.no_compression = false;
        let h = 1e-6 * grp.reference[e].area.sqrt();
        let ke = fd_stiffness(&xe, h, |x| {
            membrane::forces_with(
                x,
                &grp.reference[e],
                &mat,
                grp.thickness[e],
                grp.k_hg[e],
                0.0,
            )
        });
        k.add_element(&nodes, &ke);
    }
}

/// Every node's displacement from the solution over the kept equations (held ones zero,
/// a slave's from its masters), or an error when it is not finite.
fn displacements(sol: &DMatrix<f64>, kept: &Kept, dofs: &Dofs) -> Result<Vec<[f64; 3]>> {
    let mut full = vec![0.0; dofs.neq];
    for i in 0..dofs.neq {
        if kept.keep[i] != usize::MAX {
            full[i] = sol[(kept.keep[i], 0)];
        }
    }
    let u: Vec<[f64; 3]> = (0..dofs.eq.len())
        .map(|i| std::array::from_fn(|d| dofs.node(i, d).iter().map(|&(k, w)| w * full[k]).sum()))
        .collect();
    if u.iter().flatten().any(|v| !v.is_finite()) {
        return Err(WeftError::Numerical {
            what: "the static solution is not finite".into(),
            step: 0,
            time: 0.0,
            hint: Some(
                "the stiffness matrix is nearly singular: check constraints and properties".into(),
            ),
        });
    }
    Ok(u)
}
