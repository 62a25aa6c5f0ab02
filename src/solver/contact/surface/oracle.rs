//! The oracle ([`SurfaceContact::oracle`]): every step's contact checked against each
//! side built alone, afresh, in a grid of its own at its own reach, whose narrow phase
//! skips no slave. The step itself shares each master surface's boxes and grid among its
//! sides, computes on lazy steps only the boxes its narrow phases can read, skips the
//! slaves that no candidate can reach yet and runs every side in one parallel loop: each
//! of these must give the same bits as the side alone (tests/contact_search.rs).

use super::{Side, SurfaceContact};

impl SurfaceContact {
    /// The oracle ([`SurfaceContact::oracle`]): the sides as they were before this
    /// step's narrow phase (`before`) get fresh lists of their own at `x` and a narrow phase
    /// that skips no slave; every slave's contact, state and reaction shares, and every
    /// chunk's energies and penetrated count, must be the same bits as this step's.
    pub(super) fn check_oracle(
        &self,
        before: Vec<Side>,
        x: &[[f64; 3]],
        v: &[[f64; 3]],
        dt: f64,
        dt_prev: f64,
    ) {
        for (k, mut r) in before.into_iter().enumerate() {
            let mb = &self.masters[r.surface];
            let sg = r.surface_grid(mb, r.build_reach(self.skin));
            r.build(x, self.skin, mb, &sg);
            r.narrow(mb, x, v, dt, dt_prev, false, None);
            if let Err(e) = same_results(&self.sides[k], &r) {
                panic!(
                    "contact oracle: the step differs from its side built alone at force \
                     evaluation {}, contact {} (side {k}): {e}",
                    self.evaluations, self.sides[k].contact_id
                );
            }
        }
    }
}

/// Whether two narrow phases of a side gave the same bits (the oracle): the slaves in
/// contact, their results, every slave's state, the reaction shares, and the chunks'
/// energies and penetrated counts.
fn same_results(a: &Side, b: &Side) -> std::result::Result<(), String> {
    let node = |si: u32| a.slaves[si as usize];
    if a.chunk_active != b.chunk_active {
        let (x, y): (Vec<u32>, Vec<u32>) = (
            a.chunk_active.iter().flatten().copied().collect(),
            b.chunk_active.iter().flatten().copied().collect(),
        );
        let only_a: Vec<u32> = x
            .iter()
            .filter(|s| !y.contains(s))
            .map(|&s| node(s))
            .collect();
        let only_b: Vec<u32> = y
            .iter()
            .filter(|s| !x.contains(s))
            .map(|&s| node(s))
            .collect();
        return Err(format!(
            "slaves in contact differ: only here node indices {only_a:?}, only in the side alone {only_b:?}"
        ));
    }
    let bits = |v: &[f64]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
    for &si in a.chunk_active.iter().flatten() {
        let (p, q) = (&a.out[si as usize], &b.out[si as usize]);
        let pv = [p.f[0], p.f[1], p.f[2], p.stored, p.dissipated, p.g];
        let qv = [q.f[0], q.f[1], q.f[2], q.stored, q.dissipated, q.g];
        if p.face != q.face || bits(&pv) != bits(&qv) {
            return Err(format!(
                "node index {}: {p:?} against the side alone's {q:?}",
                node(si)
            ));
        }
    }
    for (si, (p, q)) in a.state.iter().zip(&b.state).enumerate() {
        let pv = [p.ft[0], p.ft[1], p.ft[2], p.k, p.g0];
        let qv = [q.ft[0], q.ft[1], q.ft[2], q.k, q.g0];
        if bits(&pv) != bits(&qv) || a.held[si] != b.held[si] {
            return Err(format!(
                "node index {}: state {p:?} against the side alone's {q:?}",
                node(si as u32)
            ));
        }
    }
    for (ra, rb) in a.chunk_reactions.iter().zip(&b.chunk_reactions) {
        let same = ra.len() == rb.len()
            && ra
                .iter()
                .zip(rb)
                .all(|(p, q)| p.slave == q.slave && p.face == q.face && bits(&p.w) == bits(&q.w));
        if !same {
            return Err("reaction shares differ".into());
        }
    }
    for (ci, (p, q)) in a.chunk_sums.iter().zip(&b.chunk_sums).enumerate() {
        if p.stored.to_bits() != q.stored.to_bits()
            || p.dissipated.to_bits() != q.dissipated.to_bits()
            || p.penetrated != q.penetrated
        {
            return Err(format!("chunk {ci}: {p:?} against the side alone's {q:?}"));
        }
    }
    Ok(())
}
