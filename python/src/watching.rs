//! Long work (a fit, a Monte Carlo study) on a worker thread, while the calling thread keeps
//! Python responsive: it waits without the GIL, looks for Python signals (Ctrl-C) every
//! [`SIGNAL_POLL`], and hands the work's progress to a Python callback. Signal handlers and
//! callbacks run on the calling thread only, never on a worker thread, and a fast call is not
//! slowed down: the wait ends as soon as the work does.
//!
//! A report waits until the calling thread has handled it: a callback sees each event before
//! the work goes on, and a callback that raises stops the work at its next check, whatever
//! the machine's load (with a report that did not wait, a fast fit could run several more
//! iterations before the exception was seen).

use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender, SyncSender};
use std::time::Duration;

/// How often a waiting call looks for Ctrl-C (and any other Python signal).
pub const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// What the worker tells the waiting thread.
enum Message<E> {
    /// An event, and where to say that it was handled.
    Progress(E, SyncSender<()>),
    Done,
}

/// Where the work reports its progress: a handle that worker threads may share.
#[derive(Clone)]
pub struct Reporter<E>(Sender<Message<E>>);

impl<E> Reporter<E> {
    /// Hands `event` to the waiting thread and waits until it has been handled (returns at
    /// once if the waiting thread has stopped listening).
    pub fn report(&self, event: E) {
        let (handled, wait) = mpsc::sync_channel(1);
        if self.0.send(Message::Progress(event, handled)).is_ok() {
            // An error is the acknowledgement dropped unsent: the waiting thread stopped
            // listening, and the work sees `cancel` at its next check.
            let _ = wait.recv();
        }
    }
}

/// How watched work ended when it did not run to its end on its own.
pub struct Stopped<T> {
    /// The Python exception that stopped it: the signal handler's (`KeyboardInterrupt`) or the
    /// progress callback's.
    pub error: PyErr,
    /// What the work returned once it had seen `cancel` (`None` if its thread panicked).
    pub outcome: Option<T>,
}

/// Runs `work` on a worker thread without the GIL, handing each event it reports to
/// `on_event` (with the GIL, on this thread) and checking Python's signals every
/// [`SIGNAL_POLL`] and after each event. When a signal handler or `on_event` raises, `cancel`
/// is set, the work is waited for (it is expected to see `cancel` soon) and the exception is
/// returned with the work's outcome.
pub fn run_watched<T: Send, E: Send>(
    py: Python<'_>,
    cancel: &AtomicBool,
    work: impl FnOnce(Reporter<E>) -> T + Send,
    mut on_event: impl FnMut(E) -> PyResult<()>,
) -> Result<Option<T>, Stopped<T>> {
    let (tx, rx) = mpsc::channel();
    std::thread::scope(|scope| {
        let worker = scope.spawn(move || {
            let done = tx.clone();
            let out = work(Reporter(tx));
            let _ = done.send(Message::Done);
            out
        });
        let mut rx = rx;
        loop {
            // A panicking worker drops its senders: the wait ends as `Disconnected`. The
            // receiver goes to the wait and back (it may be used by one thread at a time).
            let (back, message) = py.detach(move || {
                let message = rx.recv_timeout(SIGNAL_POLL);
                (rx, message)
            });
            rx = back;
            let (checked, handled) = match message {
                Ok(Message::Progress(event, handled)) => (on_event(event), Some(handled)),
                Ok(Message::Done) | Err(RecvTimeoutError::Disconnected) => break,
                Err(RecvTimeoutError::Timeout) => (Ok(()), None),
            };
            let checked = checked.and_then(|()| py.check_signals());
            if let Err(error) = checked {
                // The flag before the acknowledgement: the reporting thread, released, sees it.
                cancel.store(true, Ordering::Relaxed);
                drop(handled);
                // Reports queued behind this one carry their acknowledgements: dropping them
                // releases their threads, and later reports return at once.
                drop(rx);
                let outcome = py.detach(|| worker.join()).ok();
                return Err(Stopped { error, outcome });
            }
            if let Some(handled) = handled {
                let _ = handled.send(());
            }
        }
        Ok(py.detach(|| worker.join()).ok())
    })
}
