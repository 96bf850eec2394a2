//! Progress on stderr, drawn only when stderr is a terminal: a bar for Monte Carlo runs, the
//! elapsed time of a single long fit.

use jitterid::estimate::solver::{Progress as SolverProgress, ProgressHook};
use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// Counts finished realisations and redraws a bar at most ten times a second.
#[derive(Debug)]
pub struct Progress {
    total: u64,
    done: AtomicU64,
    start: Instant,
    last: Mutex<Option<Instant>>,
    enabled: bool,
}

impl Progress {
    /// A bar for `total` items (silent unless stderr is a terminal).
    pub fn new(total: u64) -> Self {
        Self {
            total,
            done: AtomicU64::new(0),
            start: Instant::now(),
            last: Mutex::new(None),
            enabled: std::io::stderr().is_terminal(),
        }
    }

    /// One more item done.
    pub fn tick(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if !self.enabled {
            return;
        }
        let Ok(mut last) = self.last.lock() else {
            return;
        };
        let now = Instant::now();
        if done < self.total && last.is_some_and(|l| now - l < Duration::from_millis(100)) {
            return;
        }
        *last = Some(now);
        self.draw(done);
    }

    fn draw(&self, done: u64) {
        const WIDTH: u64 = 30;
        let total = self.total.max(1);
        let filled = (done.min(total) * WIDTH / total) as usize;
        let secs = self.start.elapsed().as_secs_f64();
        let eta = if done > 0 && done < total {
            format!(
                ", ~{:.0} s left",
                secs / done as f64 * (total - done) as f64
            )
        } else {
            String::new()
        };
        let mut err = std::io::stderr().lock();
        let _ = write!(
            err,
            "\r[{}{}] {done}/{total} runs, {secs:.1} s{eta}   ",
            "#".repeat(filled),
            " ".repeat(WIDTH as usize - filled)
        );
        let _ = err.flush();
    }

    /// Ends the bar's line.
    pub fn finish(&self) {
        if self.enabled {
            let _ = writeln!(std::io::stderr());
        }
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
                stop: None,
                handle: None,
            };
        }
        let (tx, rx) = mpsc::channel::<()>();
        let what = what.to_string();
        let latest: Latest = Arc::new(Mutex::new(None));
        if let Ok(mut active) = ACTIVE.lock() {
            *active = Some(latest.clone());
        }
        let handle = std::thread::spawn(move || {
            let start = Instant::now();
            if rx.recv_timeout(TICKER_DELAY) != Err(mpsc::RecvTimeoutError::Timeout) {
                return;
            }
            let drawn = loop {
                let mut line = format!("{what}: {:.1} s", start.elapsed().as_secs_f64());
                if let Some(p) = latest.lock().ok().and_then(|l| *l) {
                    line.push_str(&format!(", iteration {}, cost {:.6e}", p.iteration, p.cost));
                }
                let mut err = std::io::stderr().lock();
                let _ = write!(err, "\r{line}");
                let _ = err.flush();
                drop(err);
                if rx.recv_timeout(TICKER_PERIOD) != Err(mpsc::RecvTimeoutError::Timeout) {
                    break line.chars().count();
                }
            };
            let mut err = std::io::stderr().lock();
            let _ = write!(err, "\r{}\r", " ".repeat(drawn));
            let _ = err.flush();
        });
        Self {
            stop: Some(tx),
            handle: Some(handle),
        }
    }
}

impl Drop for Ticker {
    fn drop(&mut self) {
        // Closing the channel stops the thread; joining makes the cleared line come before
        // anything printed next.
        self.stop.take();
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
        if let Ok(mut active) = ACTIVE.lock() {
            *active = None;
        }
    }
}
