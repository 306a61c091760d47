//! `pvtc.stream`: a program in chunks of at most `chunk` pieces, planned on a thread of
//! its own while Python takes them, for feeding a controller's buffer.
//!
//! Owns the hand-over: a channel without room, so that the planner blocks once it has
//! filled a chunk until Python takes the last one (at most two chunks are held: the one
//! Python has, the one being filled), and the end of the stream (its warnings, or the
//! failure that stopped it). It must not plan or cut chunks: [`pvtc::embed`] does.

use crate::errors::{guard, internal, raise, warn_all, Diagnostic};
use crate::program::{Origin, Plan, Program};
use pvtc::embed::Pieces;
use pvtc::Failure;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Arc, Mutex};

/// What the planning thread hands over.
pub enum Message {
    /// The next chunk.
    Chunk(Pieces),
    /// The end: the warnings and notes, or the failure that stopped the stream.
    End(Result<Vec<miette::Report>, Failure>),
    /// The planning thread panicked, with this payload's text.
    Panic(String),
}

/// The chunks of a program as it is planned: an iterator of `Program`s, each starting
/// where the last ended (`start` and `start_velocity`), at most `chunk` pieces each.
/// `made` counts the chunks the planner has filled: at most one more than taken.
#[pyclass(module = "pvtc")]
pub struct Chunks {
    receiver: Mutex<Option<Receiver<Message>>>,
    plan: Plan,
    made: Arc<AtomicUsize>,
}

impl Chunks {
    /// Starts `work` on a thread of its own, handing chunks to the returned iterator
    /// through its sink (`false`: nobody takes them any more).
    pub fn start<F>(plan: Plan, work: F) -> Chunks
    where
        F: FnOnce(&mut dyn FnMut(Pieces) -> bool) -> Result<Vec<miette::Report>, Failure>
            + Send
            + 'static,
    {
        let (sender, receiver) = sync_channel::<Message>(0);
        let made = Arc::new(AtomicUsize::new(0));
        let counter = Arc::clone(&made);
        std::thread::spawn(move || run(sender, counter, work));
        Chunks {
            receiver: Mutex::new(Some(receiver)),
            plan,
            made,
        }
    }
}

/// The planning thread: `work` into the channel, then its end (or its panic).
fn run<F>(sender: SyncSender<Message>, made: Arc<AtomicUsize>, work: F)
where
    F: FnOnce(&mut dyn FnMut(Pieces) -> bool) -> Result<Vec<miette::Report>, Failure>,
{
    let chunks = sender.clone();
    let mut sink = move |pieces: Pieces| {
        made.fetch_add(1, Ordering::SeqCst);
        chunks.send(Message::Chunk(pieces)).is_ok()
    };
    let ended = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(&mut sink)));
    let message = match ended {
        Ok(end) => Message::End(end),
        Err(payload) => Message::Panic(
            payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_default(),
        ),
    };
    // Nobody may be listening any more: then there is nothing to tell.
    let _ = sender.send(message);
}

#[pymethods]
impl Chunks {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__(&self, py: Python<'_>) -> PyResult<Option<Program>> {
        guard(|| {
            let received = py.detach(|| {
                let guard = self.receiver.lock().unwrap_or_else(|e| e.into_inner());
                guard.as_ref().map(|r| r.recv())
            });
            let message = match received {
                None => return Ok(None),
                Some(Ok(message)) => message,
                Some(Err(_)) => {
                    self.close();
                    return Err(internal(&"the planning thread stopped without a word"));
                }
            };
            match message {
                Message::Chunk(pieces) => {
                    let plan = Plan {
                        origin: Origin::Chunk,
                        ..self.plan.clone()
                    };
                    Program::new(py, pieces, plan, Vec::new()).map(Some)
                }
                Message::End(end) => {
                    self.close();
                    let warnings = end.map_err(|f| raise(py, f))?;
                    warn_all(py, &Diagnostic::all(&warnings))?;
                    Ok(None)
                }
                Message::Panic(text) => {
                    self.close();
                    Err(internal(&text))
                }
            }
        })
    }

    /// Chunks the planner has filled so far (taken, or waiting to be): at most one more
    /// than the chunks taken.
    #[getter]
    fn made(&self) -> usize {
        self.made.load(Ordering::SeqCst)
    }

    /// Stops the stream: the planner stops handing chunks on.
    fn close(&self) {
        let mut guard = self.receiver.lock().unwrap_or_else(|e| e.into_inner());
        *guard = None;
    }
}

/// `chunk` as a count of at least one piece.
pub fn chunk_size(chunk: i64) -> PyResult<usize> {
    usize::try_from(chunk)
        .ok()
        .filter(|n| *n >= 1)
        .ok_or_else(|| {
            PyValueError::new_err(format!("chunk must be at least 1 piece, not {chunk}"))
        })
}
