//! Progress on stderr, drawn by [`indicatif`] only when stderr is a terminal: a bar for Monte
//! Carlo runs, the elapsed time of a single long fit, the designs a design search evaluated.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use jitterid::estimate::solver::{Progress as SolverProgress, ProgressHook};
use jitterid_study::design::{DesignObserver, DesignProgress};
use std::io::IsTerminal;
use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

/// Where progress is drawn: stderr at most `hz` times a second when it is a terminal (indicatif
/// also hides it when `TERM` is unset or `dumb`), nowhere otherwise.
fn stderr_target(hz: u8) -> ProgressDrawTarget {
    if std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr_with_hz(hz)
    } else {
        ProgressDrawTarget::hidden()
    }
}

/// Seconds since the bar started, with one decimal.
fn seconds(state: &ProgressState, w: &mut dyn std::fmt::Write) {
    let _ = write!(w, "{:.1} s", state.elapsed().as_secs_f64());
}

/// The time left at the mean pace so far, while some but not all runs are done.
fn time_left(state: &ProgressState, w: &mut dyn std::fmt::Write) {
    let (done, total) = (state.pos(), state.len().unwrap_or(0).max(1));
    if done > 0 && done < total {
        let secs = state.elapsed().as_secs_f64();
        let _ = write!(
            w,
            ", ~{:.0} s left",
            secs / done as f64 * (total - done) as f64
        );
    }
}

/// Counts finished realisations on a bar redrawn at most ten times a second:
/// `[#####     ] 12/40 runs, 3.1 s, ~8 s left`.
#[derive(Debug)]
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar for `total` items (silent unless stderr is a terminal).
    pub fn new(total: u64) -> Self {
        let style = ProgressStyle::with_template("[{bar:30}] {pos}/{len} runs, {seconds}{left}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("# ")
            .with_key("seconds", seconds)
            .with_key("left", time_left);
        let bar = ProgressBar::with_draw_target(Some(total), stderr_target(10)).with_style(style);
        Self { bar }
    }

    /// One more item done.
    pub fn tick(&self) {
        self.bar.inc(1);
    }

    /// Draws the final count and leaves the line.
    pub fn finish(&self) {
        self.bar.finish();
    }
}

/// The latest iteration and cost the solver of the running fit reported.
type Latest = Arc<Mutex<Option<SolverProgress>>>;

/// Where the solver of the one fit a [`Ticker`] watches reports to (none when no ticker runs,
/// so the many fits of a Monte Carlo study report nowhere).
static ACTIVE: Mutex<Option<Latest>> = Mutex::new(None);

/// A hook for the solver of the fit a [`Ticker`] is showing, if one is.
pub fn active_fit_hook() -> Option<ProgressHook> {
    let latest = ACTIVE.lock().ok()?.clone()?;
    Some(ProgressHook::new(move |p| {
        if let Ok(mut l) = latest.lock() {
            *l = Some(*p);
        }
    }))
}

/// The elapsed time of one long computation (a fit), with the solver's iteration and cost when
/// it reports them, drawn on stderr from one second on and only when stderr is a terminal; the
/// line is cleared when the computation ends.
#[derive(Debug)]
pub struct Ticker {
    bar: Option<ProgressBar>,
    stop: Option<mpsc::Sender<()>>,
    handle: Option<std::thread::JoinHandle<()>>,
}

/// How long a computation runs before the ticker shows it.
const TICKER_DELAY: Duration = Duration::from_secs(1);
/// How often the ticker redraws.
const TICKER_PERIOD: Duration = Duration::from_millis(250);

impl Ticker {
    /// Starts a ticker labelled `what` (silent unless stderr is a terminal).
    pub fn start(what: &str) -> Self {
        if !std::io::stderr().is_terminal() {
            return Self {
                bar: None,
                stop: None,
                handle: None,
            };
        }
        let latest: Latest = Arc::new(Mutex::new(None));
        if let Ok(mut active) = ACTIVE.lock() {
            *active = Some(latest.clone());
        }
        let solver = move |_: &ProgressState, w: &mut dyn std::fmt::Write| {
            if let Some(p) = latest.lock().ok().and_then(|l| *l) {
                let _ = write!(w, ", iteration {}, cost {:.6e}", p.iteration, p.cost);
            }
        };
        let style = ProgressStyle::with_template("{prefix}: {seconds}{solver}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner())
            .with_key("seconds", seconds)
            .with_key("solver", solver);
        // Hidden for the first second; a thread then shows it and indicatif redraws it.
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden())
            .with_style(style)
            .with_prefix(what.to_string());
        let (tx, rx) = mpsc::channel::<()>();
        let shown = bar.clone();
        let handle = std::thread::spawn(move || {
            if rx.recv_timeout(TICKER_DELAY) == Err(mpsc::RecvTimeoutError::Timeout) {
                shown.set_draw_target(stderr_target(20));
                shown.enable_steady_tick(TICKER_PERIOD);
            }
        });
        Self {
            bar: Some(bar),
            stop: Some(tx),
            handle: Some(handle),
        }
    }
}

impl Drop for Ticker {
    fn drop(&mut self) {
        // Closing the channel stops a thread still waiting to show the line; joining it and
        // then clearing the line makes the cleared line come before anything printed next.
        self.stop.take();
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
        if let Ok(mut active) = ACTIVE.lock() {
            *active = None;
        }
    }
}

/// The progress of `jitterid design` on stderr, only when stderr is a terminal: a spinner with
/// the designs evaluated, the grid's size, a robust design's prior draws and the elapsed
/// time, `design: 23 designs evaluated (grid 9), prior draw 3/8, 4.2 s` (`jitter-blind
/// design: …` during that search); the line is cleared when the design ends.
#[derive(Debug)]
pub struct DesignTicker {
    bar: Option<ProgressBar>,
}

impl DesignTicker {
    /// Starts the spinner (nothing unless stderr is a terminal).
    pub fn start() -> Self {
        if !std::io::stderr().is_terminal() {
            return Self { bar: None };
        }
        let style = ProgressStyle::with_template("{spinner} {msg}, {seconds}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner())
            .with_key("seconds", seconds);
        let bar = ProgressBar::with_draw_target(None, stderr_target(10))
            .with_style(style)
            .with_message("design: starting");
        bar.enable_steady_tick(TICKER_PERIOD);
        Self { bar: Some(bar) }
    }

    /// The observer that updates the spinner (a no-op when nothing is drawn).
    pub fn observer(&self) -> DesignObserver {
        let bar = self.bar.clone();
        // What the last evaluation said, so that a prior draw's line keeps it.
        let last = Mutex::new(String::from("design"));
        DesignObserver::new(move |p| {
            let Some(bar) = &bar else { return };
            let Ok(mut last) = last.lock() else { return };
            match *p {
                DesignProgress::Evaluated {
                    jitter_blind,
                    evaluations,
                    grid_points,
                } => {
                    // A multisine's descent has no grid to show.
                    let grid = match grid_points {
                        0 => String::new(),
                        g => format!(" (grid {g})"),
                    };
                    *last = format!(
                        "{}design: {evaluations} design{} evaluated{grid}",
                        if jitter_blind { "jitter-blind " } else { "" },
                        if evaluations == 1 { "" } else { "s" }
                    );
                    bar.set_message(last.clone());
                }
                DesignProgress::PriorDraw { done, total } => {
                    bar.set_message(format!("{last}, prior draw {done}/{total}"));
                }
            }
        })
    }
}

impl Drop for DesignTicker {
    fn drop(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}
