//! A progress bar on stderr for long runs: simulated time, rate and what
//! remains. The run stores the time it reached in an atomic
//! (`runtime::SimOptions::progress`); a thread polls it, so the
//! integration loop never waits on the terminal.
//!
//! On a terminal a bar, after the run has taken a second; elsewhere (a
//! log file, a cluster job) a plain line every ten seconds, so that a long
//! run is never silent. Nothing under `--quiet`, and short runs print
//! nothing extra.

use std::io::IsTerminal;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long a run goes before its bar appears.
const SHOW_AFTER: Duration = Duration::from_secs(1);
/// How often a run without a terminal says where it is.
const LINE_EVERY: Duration = Duration::from_secs(10);
/// The bar's resolution: t_end is this many ticks.
const TICKS: u64 = 1000;

/// A running progress display; `finish` (or drop) takes it down.
pub struct Progress {
    reached: Arc<AtomicU64>,
    done: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Progress {
    /// A display for a run from 0 to `t_end` (s), or None when `quiet`.
    pub fn start(label: &str, t_end: f64, quiet: bool) -> Option<Self> {
        if quiet || t_end.is_nan() || t_end <= 0.0 {
            return None;
        }
        let reached = Arc::new(AtomicU64::new(0f64.to_bits()));
        let done = Arc::new(AtomicBool::new(false));
        let (r, d, label) = (reached.clone(), done.clone(), label.to_string());
        let terminal = std::io::stderr().is_terminal();
        let thread = std::thread::spawn(move || match terminal {
            true => show(&label, t_end, &r, &d),
            false => lines(&label, t_end, &r, &d),
        });
        Some(Self {
            reached,
            done,
            thread: Some(thread),
        })
    }

    /// What the run writes its time to.
    pub fn cell(&self) -> Arc<AtomicU64> {
        self.reached.clone()
    }

    pub fn finish(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        self.done.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.stop();
    }
}

/// The polling loop: wait `SHOW_AFTER`, then redraw ten times a second.
fn show(label: &str, t_end: f64, reached: &AtomicU64, done: &AtomicBool) {
    let start = Instant::now();
    let tick = Duration::from_millis(100);
    while start.elapsed() < SHOW_AFTER {
        if done.load(Ordering::Relaxed) {
            return;
        }
        std::thread::sleep(tick);
    }
    let bar = ProgressBar::with_draw_target(Some(TICKS), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(
        "{prefix} [{bar:30}] {msg}, {elapsed} elapsed, about {eta} to go",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar.set_prefix(label.to_string());
    while !done.load(Ordering::Relaxed) {
        let t = f64::from_bits(reached.load(Ordering::Relaxed)).clamp(0.0, t_end);
        let wall = start.elapsed().as_secs_f64();
        bar.set_position((t / t_end * TICKS as f64) as u64);
        bar.set_message(format!(
            "t = {t:.3} of {t_end} s, {:.3} simulated s per s",
            t / wall.max(1e-9)
        ));
        std::thread::sleep(tick);
    }
    bar.finish_and_clear();
}

/// Without a terminal: a line every `LINE_EVERY`, polled ten times a second
/// so that the run's end is not held up.
fn lines(label: &str, t_end: f64, reached: &AtomicU64, done: &AtomicBool) {
    let start = Instant::now();
    let mut next = LINE_EVERY;
    while !done.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(100));
        let wall = start.elapsed();
        if wall < next {
            continue;
        }
        next += LINE_EVERY;
        let t = f64::from_bits(reached.load(Ordering::Relaxed)).clamp(0.0, t_end);
        let w = wall.as_secs_f64();
        eprintln!(
            "{label}: t = {t:.3} of {t_end} s ({:.1} %), {w:.0} s wall, {:.3} simulated s per s",
            100.0 * t / t_end,
            t / w
        );
    }
}
