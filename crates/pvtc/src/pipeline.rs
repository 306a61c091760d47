//! The streaming G-code compile as two threads: the front end (read, parse, interpret)
//! on a scoped thread of its own, the planner and the writer on the calling thread,
//! which owns the output (a `Target` is not `Send`).
//!
//! The front end's [`ToolpathSink`] calls (elements, contour ends, events, path
//! tolerances) are recorded in batches of [`BATCH_CALLS`] and handed over a bounded
//! channel holding at most [`BATCHES_IN_FLIGHT`] full batches; the calling thread
//! replays each batch, in order, into its own sink and sends the emptied vector back
//! for the front end to fill again. The calling thread makes the batches (and the
//! caller opens the input, its read buffer included) before the front end's thread
//! starts, so that thread allocates no batch in steady state; about
//! `BATCHES_IN_FLIGHT + 2` batches of 47 KB exist at once. The receiving sink sees
//! exactly the calls, in exactly the order, that it would see on one thread, so the
//! planned pieces, the written bytes and every diagnostic are the same; a planning
//! failure stops nothing on the front end's side, which goes on collecting every
//! G-code diagnostic as on one thread.
//!
//! One thread only ([`threaded`] says no) inside a rayon worker, where `pvtc compile`
//! with several inputs already runs one file per core, and where this process may use
//! one core. Planning and writing share the calling thread: a thread between them would
//! need the planner's pieces in an owned form (a `SegmentRef` borrows its storage).
//!
//! Owns the batching and the threads. It must not parse, plan or write: the front end
//! and the receiving sink do, each on its thread.

use pvt_core::{Element, EventKind, Motion, ToolpathSink};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::Mutex;

/// Calls in one batch (184 bytes each): a batch's hand-over wakes the other thread
/// (some microseconds), about 4,000 times for 10⁶ lines at 256 (25,000 context
/// switches at 128, 5,000 at 512), while the batches in flight stay at about 0.25 MB
/// (0.5 MB more peak RSS at 512).
pub const BATCH_CALLS: usize = 256;

/// Full batches the channel holds while the planner is busy: two, so that the front end
/// keeps reading while the planner replays one batch and the next waits.
pub const BATCHES_IN_FLIGHT: usize = 2;

/// One [`ToolpathSink`] call, recorded.
#[derive(Debug, Clone)]
enum Call {
    Element(Motion, Element),
    EndContour,
    Event(EventKind, u32),
    PathTolerance(f64),
}

impl Call {
    /// Makes the call on `sink`, from where the call lies in its batch (moving a
    /// 184-byte call out first was a copy per element on the planner's thread).
    fn replay(&self, sink: &mut dyn ToolpathSink) {
        match self {
            Call::Element(motion, element) => sink.element(*motion, element),
            Call::EndContour => sink.end_contour(),
            Call::Event(event, line) => sink.event(event, *line),
            Call::PathTolerance(tolerance) => sink.path_tolerance(*tolerance),
        }
    }
}

/// The front end's sink: records calls into the open batch and sends it when full.
struct Batcher {
    batch: Vec<Call>,
    full: SyncSender<Vec<Call>>,
    emptied: Receiver<Vec<Call>>,
    /// False once the receiving side has gone (it panicked): later calls are dropped.
    open: bool,
}

impl Batcher {
    fn record(&mut self, call: Call) {
        if !self.open {
            return;
        }
        self.batch.push(call);
        if self.batch.len() == BATCH_CALLS {
            self.send();
        }
    }

    /// Sends the open batch and opens an emptied one (a new one while none has come
    /// back yet).
    fn send(&mut self) {
        let batch = std::mem::take(&mut self.batch);
        self.open = self.full.send(batch).is_ok();
        self.batch = self
            .emptied
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(BATCH_CALLS));
    }

    /// Sends what is left.
    fn flush(&mut self) {
        if self.open && !self.batch.is_empty() {
            self.send();
        }
    }
}

impl ToolpathSink for Batcher {
    fn element(&mut self, motion: Motion, element: &Element) {
        self.record(Call::Element(motion, *element));
    }
    fn end_contour(&mut self) {
        self.record(Call::EndContour);
    }
    fn event(&mut self, event: &EventKind, line: u32) {
        self.record(Call::Event(event.clone(), line));
    }
    fn path_tolerance(&mut self, tolerance: f64) {
        self.record(Call::PathTolerance(tolerance));
    }
}

thread_local! {
    /// Front ends this thread has run on threads of their own.
    static THREADS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// How many front ends this thread has run on a thread of their own (the evidence tests
/// take that a compile took the two-thread route).
pub fn front_end_threads() -> usize {
    THREADS.with(std::cell::Cell::get)
}

/// Whether a compile on this thread runs its front end on a thread of its own: not
/// inside a rayon worker (batch compiles already fill the cores, one file each), nor on
/// a machine with one core.
pub fn threaded() -> bool {
    rayon::current_thread_index().is_none()
        && std::thread::available_parallelism().is_ok_and(|n| n.get() > 1)
}

/// Runs `front` (a front end pushing into the sink it is given) on a scoped thread of
/// its own, replaying its calls into `sink` on this thread as they arrive, and returns
/// what `front` returns. Should no thread start, `front` runs here, into `sink`.
pub fn in_two_threads<R, F>(front: F, sink: &mut dyn ToolpathSink) -> R
where
    R: Send,
    F: FnOnce(&mut dyn ToolpathSink) -> R + Send,
{
    // Where the front end waits until its thread takes it, or this one when none starts.
    let waiting = Mutex::new(Some(front));
    std::thread::scope(|scope| {
        let (full, arrived) = sync_channel(BATCHES_IN_FLIGHT);
        let (give_back, emptied) = sync_channel(BATCHES_IN_FLIGHT + 3);
        // Every batch the front end needs is made here, so that its thread allocates
        // none (a thread's first allocations open a heap of its own).
        for _ in 0..BATCHES_IN_FLIGHT + 1 {
            let _ = give_back.try_send(Vec::with_capacity(BATCH_CALLS));
        }
        let mut batcher = Batcher {
            batch: Vec::with_capacity(BATCH_CALLS),
            full,
            emptied,
            open: true,
        };
        let waiting = &waiting;
        let spawned = std::thread::Builder::new()
            .name("pvtc front end".into())
            .spawn_scoped(scope, move || {
                let front = take(waiting).expect("the front end runs once");
                let result = front(&mut batcher);
                batcher.flush();
                result
            });
        let Ok(thread) = spawned else {
            let front = take(waiting).expect("no thread took the front end");
            return front(sink);
        };
        THREADS.with(|threads| threads.set(threads.get() + 1));
        for mut batch in arrived.iter() {
            for call in &batch {
                call.replay(sink);
            }
            batch.clear();
            // The front end may have finished and dropped its end: the batch goes.
            let _ = give_back.try_send(batch);
        }
        match thread.join() {
            Ok(result) => result,
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
}

/// Takes the front end out of its slot (a poisoned lock holds it all the same).
fn take<F>(waiting: &Mutex<Option<F>>) -> Option<F> {
    waiting.lock().unwrap_or_else(|e| e.into_inner()).take()
}

#[cfg(test)]
mod tests {
    use super::*;
    use pvt_core::{ElementKind, Position, Span};

    /// Records every call it receives, in words.
    #[derive(Default)]
    struct Log(Vec<String>);

    impl ToolpathSink for Log {
        fn element(&mut self, motion: Motion, element: &Element) {
            self.0.push(format!("{motion:?} {element:?}"));
        }
        fn end_contour(&mut self) {
            self.0.push("end".into());
        }
        fn event(&mut self, event: &EventKind, line: u32) {
            self.0.push(format!("{event:?} {line}"));
        }
        fn path_tolerance(&mut self, tolerance: f64) {
            self.0.push(format!("tolerance {tolerance}"));
        }
    }

    /// A front end pushing `n` lines, with a contour end, an event and a tolerance every
    /// so often; it returns the thread it ran on.
    fn front(n: usize) -> impl FnOnce(&mut dyn ToolpathSink) -> std::thread::ThreadId + Send {
        move |sink| {
            for i in 0..n {
                let at = |i: usize| -> Position {
                    let mut p = [0.0; pvt_core::AXIS_COUNT];
                    p[0] = i as f64;
                    p
                };
                let element = Element {
                    kind: ElementKind::Line,
                    start: at(i),
                    end: at(i + 1),
                    feed: 10.0,
                    span: Span {
                        line: i as u32 + 1,
                        ..Span::default()
                    },
                };
                sink.element(Motion::Feed, &element);
                if i % 300 == 7 {
                    sink.end_contour();
                    sink.event(&EventKind::Dwell { seconds: 0.5 }, i as u32);
                    sink.path_tolerance(0.001 * i as f64);
                }
            }
            std::thread::current().id()
        }
    }

    #[test]
    fn the_receiving_sink_gets_every_call_in_order_from_another_thread() {
        // Batch sizes either side of a boundary: none, one short, exact, and many.
        for n in [0, 1, BATCH_CALLS - 2, BATCH_CALLS, 10 * BATCH_CALLS + 17] {
            let mut alone = Log::default();
            front(n)(&mut alone);
            let mut piped = Log::default();
            let ran_on = in_two_threads(front(n), &mut piped);
            assert_ne!(ran_on, std::thread::current().id());
            assert_eq!(piped.0, alone.0, "{n} elements");
            assert!(alone.0.len() >= n);
        }
    }

    #[test]
    fn a_panicking_front_end_panics_the_caller() {
        let mut log = Log::default();
        let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            in_two_threads(|_: &mut dyn ToolpathSink| panic!("front end"), &mut log)
        }));
        assert!(caught.is_err());
    }
}
