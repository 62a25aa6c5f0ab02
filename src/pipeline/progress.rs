//! The progress view of `weft run` on stderr: a bar for the stale instances, one bar per
//! running instance above it, and the run's lines (`run`, `done`, `FAIL`, ...) printed
//! above the bars; plain lines when stderr is not a terminal, nothing when quiet.

use std::collections::BTreeMap;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

/// The bars and where the run's lines go.
pub struct View {
    mp: MultiProgress,
    main: ProgressBar,
    /// The bar of each running instance.
    bars: BTreeMap<usize, ProgressBar>,
    /// Someone watches the bars: lines are printed above them.
    attended: bool,
    quiet: bool,
}

impl View {
    /// The view of a run with `stale` instances to run; `ticking`: the main bar's spinner
    /// turns by itself (not for a dry run).
    pub fn new(quiet: bool, stale: u64, ticking: bool) -> View {
        let mp = MultiProgress::with_draw_target(if quiet {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        });
        let attended = !quiet && !mp.is_hidden();
        let main = mp.add(ProgressBar::new(stale));
        main.set_style(
            ProgressStyle::with_template(
                "{spinner} stages [{bar:30}] {pos}/{len} {elapsed_precise} {msg}",
            )
            .expect("template"),
        );
        if ticking {
            main.enable_steady_tick(std::time::Duration::from_millis(250));
        }
        View {
            mp,
            main,
            bars: BTreeMap::new(),
            attended,
            quiet,
        }
    }

    /// A line of the run: above the bars, on stderr, or nowhere when quiet.
    pub fn say(&self, s: String) {
        if self.attended {
            let _ = self.mp.println(s);
        } else if !self.quiet {
            eprintln!("{s}");
        }
    }

    /// Instance `i` (`name`) started: its bar appears.
    pub fn started(&mut self, i: usize, name: &str) {
        let bar = self.mp.insert_before(&self.main, ProgressBar::new(1000));
        bar.set_style(
            ProgressStyle::with_template(
                "  {spinner} {msg:40!} [{bar:20}] {percent:>3}% {elapsed}",
            )
            .expect("template"),
        );
        bar.set_message(name.to_string());
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        self.bars.insert(i, bar);
    }

    /// Instance `i` is a fraction `f` done.
    pub fn progress(&self, i: usize, f: f64) {
        if let Some(b) = self.bars.get(&i) {
            b.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64);
        }
    }

    /// Instance `i` is over: the main bar counts it, its own bar goes.
    pub fn done(&mut self, i: usize) {
        self.main.inc(1);
        if let Some(b) = self.bars.remove(&i) {
            b.finish_and_clear();
            self.mp.remove(&b);
        }
    }

    /// The run is over: the bars go.
    pub fn finish(&self) {
        self.main.finish_and_clear();
    }
}
