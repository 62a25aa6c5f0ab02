//! The gather of the contact forces onto the nodes is bit-identical on any thread count
//! also when it runs in parallel (`surface::gather`: per-chunk lists by fixed node block,
//! taken only with 2048 slaves or more in contact and more than one thread).
//!
//! Oracle: the one-thread run, whose gather adds every node's contributions directly in
//! the canonical order (side, chunk, slaves, reactions); the parallel gather must give
//! the same bits on 2 and 3 threads (3: blocks that do not divide evenly among threads).

use weft::generate::layers::{crossing_bands, CrossingBands};
use weft::solver::run_in_memory;

#[test]
fn the_parallel_gather_is_bit_identical_on_two_and_three_threads() {
    let m = crossing_bands(&CrossingBands::with_nodes(12_000));
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (s, out, _) = run_in_memory(&m).unwrap();
            (out.u, out.energy, s.operator().surfaces.active())
        })
    };
    let (u1, e1, active) = run(1);
    println!(
        "{} nodes, {active} slaves in contact at the end",
        m.num_nodes()
    );
    // The parallel path runs (at least at the last steps) only past 2048 slaves in contact.
    assert!(active >= 2048, "only {active} slaves in contact");
    for threads in [2, 3] {
        let (u, e, a) = run(threads);
        assert_eq!(a, active, "{threads} threads: slaves in contact");
        assert!(u == u1 && e == e1, "1 and {threads} threads differ");
    }
}
