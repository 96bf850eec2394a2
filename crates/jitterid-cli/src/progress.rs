//! A progress bar on stderr, drawn only when stderr is a terminal.

use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
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
