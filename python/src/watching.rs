//! Long work (a fit, a Monte Carlo study) on a worker thread, while the calling thread keeps
//! Python responsive: it waits without the GIL, looks for Python signals (Ctrl-C) every
//! [`SIGNAL_POLL`], and hands the work's progress to a Python callback. Signal handlers and
//! callbacks run on the calling thread only, never on a worker thread, and a fast call is not
//! slowed down: the wait ends as soon as the work does.

use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::time::Duration;

/// How often a waiting call looks for Ctrl-C (and any other Python signal).
pub const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// What the worker tells the waiting thread.
enum Message<E> {
    Progress(E),
    Done,
}

/// Where the work reports its progress: a handle that worker threads may share.
#[derive(Clone)]
pub struct Reporter<E>(Sender<Message<E>>);

impl<E> Reporter<E> {
    /// Hands `event` to the waiting thread (dropped if it has stopped listening).
    pub fn report(&self, event: E) {
        let _ = self.0.send(Message::Progress(event));
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
            let checked = match message {
                Ok(Message::Progress(event)) => on_event(event),
                Ok(Message::Done) | Err(RecvTimeoutError::Disconnected) => break,
                Err(RecvTimeoutError::Timeout) => Ok(()),
            }
            .and_then(|()| py.check_signals());
            if let Err(error) = checked {
                cancel.store(true, Ordering::Relaxed);
                let outcome = py.detach(|| worker.join()).ok();
                return Err(Stopped { error, outcome });
            }
        }
        Ok(py.detach(|| worker.join()).ok())
    })
}
