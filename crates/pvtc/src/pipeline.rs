//! The streaming G-code compile on two threads. Where it plans
//! ([`planner_aside`]), the planner runs on a scoped thread of its own, and the front
//! end (read, parse, interpret) and the writer (the PMAC splitter, the checks, the
//! totals and the format's writer) on the calling thread, which owns the output (a
//! `Target` is not `Send`); `--format toolpath`, which plans nothing, runs the front end
//! on a thread of its own and the writer on the calling one ([`in_two_threads`]).
//!
//! The front end's [`ToolpathSink`] calls (elements, contour ends, events, path
//! tolerances) are recorded in batches of [`BATCH_CALLS`]; the receiving thread
//! replays each batch, in order, into its own sink and hands the emptied vector back
//! for the front end to fill again. The receiving sink sees exactly the calls, in
//! exactly the order, that it would see on one thread, so the planned pieces, the
//! written bytes and every diagnostic are the same; a planning failure stops nothing on
//! the front end's side, which goes on collecting every G-code diagnostic as on one
//! thread.
//!
//! The planner's [`PieceSink`] calls (contour starts, pieces, events) go to the writer
//! the same way, owned ([`Pieces`]: a 16-byte record a call, the numbers flat at the
//! program's axis count, the events aside), in batches of [`BATCH_PIECES`] records; a
//! pool of [`PIECE_BATCHES`] batches, made on the calling thread before the planner's
//! starts, goes round, the planner waiting for an emptied one rather than making one, so
//! the hand-over's memory is fixed (128 KB on three axes). The calling thread writes the
//! pieces that have arrived each time it hands the planner a batch of calls, and writes
//! them as they come while the planner has [`CALLS_AHEAD`] batches queued, so the
//! thread that has less to do (the planner on straight lines, the front end and writer
//! on a pocket of arcs, whose every line is several pieces) waits for the other, and
//! neither waits for work the other holds. The writer replays each batch in order, so
//! it sees the calls of one thread; its refusals and failed writes are kept as on one
//! thread (later pieces dropped) and reported once the planner has finished, its first
//! error before them.
//!
//! One thread only ([`threaded`] says no) inside a rayon worker, where `pvtc compile`
//! with several inputs already runs one file per core, and where this process may use
//! one core.
//!
//! Owns the batching and the threads. It must not parse, plan or write: the front end,
//! the planner and the writer do, each on its thread.

use pvt_core::{Element, EventKind, Motion, PieceSink, ProgramEvent, SegmentRef, ToolpathSink};
use std::collections::VecDeque;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Condvar, Mutex, MutexGuard};

/// Calls in one batch (184 bytes each): a batch's hand-over wakes the other thread
/// (some microseconds), about 4,000 times for 10⁶ lines at 256 (25,000 context
/// switches at 128, 5,000 at 512), while the batches in flight stay at about 0.25 MB
/// (0.5 MB more peak RSS at 512).
pub const BATCH_CALLS: usize = 256;

/// Full batches [`in_two_threads`]' channel holds while the writer is busy: two, so that
/// the front end keeps reading while the writer replays one batch and the next waits.
pub const BATCHES_IN_FLIGHT: usize = 2;

/// Full call batches [`planner_aside`] queues for the planner: four, so that the front
/// end goes on reading while the planner gathers a window, which takes several batches
/// before it hands on a piece (at two, the calling thread stopped about 700 times on 10⁶
/// straight lines, for tens of milliseconds in all). 188 KB of calls at most.
pub const CALLS_AHEAD: usize = 4;

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

/// What holds the front end's calls in batches for another thread: [`Batcher`] and
/// [`FrontDesk`], each the front end's sink through [`Recorder`].
trait CallBatches {
    /// The open batch, or none once the receiving side has gone (it panicked): later
    /// calls are dropped.
    fn open_batch(&mut self) -> Option<&mut Vec<Call>>;
    /// Hands the open batch (full, or the last) over and opens another.
    fn hand_over(&mut self);
}

/// The front end's sink: records each call into the open batch, handed over when full.
struct Recorder<B>(B);

impl<B: CallBatches> Recorder<B> {
    fn record(&mut self, call: Call) {
        let Some(batch) = self.0.open_batch() else {
            return;
        };
        batch.push(call);
        if batch.len() == BATCH_CALLS {
            self.0.hand_over();
        }
    }
}

impl<B: CallBatches> ToolpathSink for Recorder<B> {
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

/// [`in_two_threads`]' batches: sent over a bounded channel, the emptied ones coming back.
struct Batcher {
    batch: Vec<Call>,
    full: SyncSender<Vec<Call>>,
    emptied: Receiver<Vec<Call>>,
    open: bool,
}

impl CallBatches for Batcher {
    fn open_batch(&mut self) -> Option<&mut Vec<Call>> {
        self.open.then_some(&mut self.batch)
    }

    /// Sends the open batch and opens an emptied one (a new one while none has come
    /// back yet).
    fn hand_over(&mut self) {
        let batch = std::mem::take(&mut self.batch);
        self.open = self.full.send(batch).is_ok();
        self.batch = self
            .emptied
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(BATCH_CALLS));
    }
}

impl Batcher {
    /// Sends what is left.
    fn flush(&mut self) {
        if self.open && !self.batch.is_empty() {
            self.hand_over();
        }
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

/// Whether a compile on this thread runs on two (its planner, or where it plans nothing
/// its front end, on a thread of its own): not inside a rayon worker (batch compiles
/// already fill the cores, one file each), nor on a machine with one core.
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
        let mut batcher = Recorder(Batcher {
            batch: Vec::with_capacity(BATCH_CALLS),
            full,
            emptied,
            open: true,
        });
        let waiting = &waiting;
        let spawned = std::thread::Builder::new()
            .name("pvtc front end".into())
            .spawn_scoped(scope, move || {
                let front = take(waiting).expect("the front end runs once");
                let result = front(&mut batcher);
                batcher.0.flush();
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

/// Pieces (records: pieces, contour starts and events alike) in one batch of the
/// planner's hand-over to the writer. A piece costs a 16-byte record and two axis counts
/// of numbers (64 bytes on three axes, 112 on six), so a batch is 16 KB on three axes
/// and 10⁶ pieces are about 4,000 hand-overs.
pub const BATCH_PIECES: usize = 256;

/// Piece batches in all, made before the planner's thread starts and passed round: the
/// planner fills one, the writer replays one, and the others wait full on the desk (or
/// emptied, on their way back). The planner waits for an emptied batch rather than make
/// one, so the hand-over holds at most these (128 KB on three axes) and the planner's
/// thread allocates none. Eight small batches rather than four large ones, so that
/// where the planner has the more to do (a pocket of arcs) the writer hands each batch
/// back sooner and the planner runs ahead of a writer waking from a wait: with four of
/// 512, on this virtual machine under load, the planner stopped for a waking writer 261
/// times in a 1.1 s compile of `generate pocket 100000`, 0.4 s in all.
pub const PIECE_BATCHES: usize = 8;

/// What one [`PieceSink`] call of the planner's was, without its numbers: a batch keeps
/// those flat, in the order of its records.
#[derive(Debug, Clone, Copy)]
enum Record {
    /// A contour starting at the next axis count of numbers.
    Contour { motion: Motion, line: u32 },
    /// A piece ending at the next axis count of numbers, its velocities after them.
    Piece { duration: f64, line: u32 },
    /// The batch's next event.
    Event,
}

/// A batch of the planner's output, owned: its records (16 bytes each), their numbers
/// flat at the program's axis count, and its events.
#[derive(Debug, Default)]
pub struct Pieces {
    dim: usize,
    numbers: Vec<f64>,
    records: Vec<Record>,
    events: Vec<ProgramEvent>,
}

impl Pieces {
    /// An empty batch with room for [`BATCH_PIECES`] pieces on `dim` axes.
    fn with_capacity(dim: usize) -> Pieces {
        Pieces {
            dim,
            numbers: Vec::with_capacity(BATCH_PIECES * 2 * dim),
            records: Vec::with_capacity(BATCH_PIECES),
            events: Vec::new(),
        }
    }

    fn clear(&mut self) {
        self.numbers.clear();
        self.records.clear();
        self.events.clear();
    }

    /// Makes the batch's calls on `sink`, in their order, from where they lie.
    fn replay(&self, sink: &mut dyn PieceSink) {
        let dim = self.dim;
        let mut at = 0;
        let mut events = self.events.iter();
        for record in &self.records {
            match *record {
                Record::Contour { motion, line } => {
                    sink.contour(motion, &self.numbers[at..at + dim], line);
                    at += dim;
                }
                Record::Piece { duration, line } => {
                    let (end, velocity) = self.numbers[at..at + 2 * dim].split_at(dim);
                    sink.piece(&SegmentRef {
                        end,
                        velocity,
                        duration,
                        line,
                    });
                    at += 2 * dim;
                }
                Record::Event => sink.event(events.next().expect("an event per record")),
            }
        }
    }
}

/// What the two threads of [`planner_aside`] hand each other, under one lock: the front
/// end's full call batches for the planner, the planner's full piece batches for the
/// writer, the emptied batches of both on their way back, and whether each side has
/// ended. One lock and one condition for both ways, so that a thread waiting for room
/// on one side is woken by work arriving on the other.
#[derive(Default)]
struct Desk {
    calls: VecDeque<Vec<Call>>,
    emptied_calls: Vec<Vec<Call>>,
    pieces: VecDeque<Pieces>,
    emptied_pieces: Vec<Pieces>,
    /// The front end has sent its last call (or this thread has gone).
    calls_end: bool,
    /// The planner has sent its last piece (or its thread has gone).
    pieces_end: bool,
    /// The writer takes no more pieces (this thread has gone).
    writer_gone: bool,
    /// Threads waiting on the condition: a change wakes them, and only then (a wake-up
    /// is a system call).
    waiting: u8,
}

/// The [`Desk`] and its one condition.
#[derive(Default)]
struct Mailbox {
    desk: Mutex<Desk>,
    changed: Condvar,
}

impl Mailbox {
    fn desk(&self) -> MutexGuard<'_, Desk> {
        self.desk.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits for a change to the desk.
    fn wait<'a>(&self, mut desk: MutexGuard<'a, Desk>) -> MutexGuard<'a, Desk> {
        desk.waiting += 1;
        let mut desk = self.changed.wait(desk).unwrap_or_else(|e| e.into_inner());
        desk.waiting -= 1;
        desk
    }

    /// Tells the threads waiting that the desk (still locked) has changed.
    fn changed(&self, desk: &Desk) {
        if desk.waiting > 0 {
            self.changed.notify_all();
        }
    }

    /// The front end's next full call batch, waiting for it; `None` once it has ended.
    fn next_calls(&self) -> Option<Vec<Call>> {
        let mut desk = self.desk();
        loop {
            if let Some(batch) = desk.calls.pop_front() {
                self.changed(&desk);
                return Some(batch);
            }
            if desk.calls_end {
                return None;
            }
            desk = self.wait(desk);
        }
    }
}

/// The calling thread's side of [`planner_aside`]: the front end's call batches (its
/// sink through [`Recorder`]), queued for the planner; whenever it queues one, it
/// writes the planner's pieces that have arrived into the writer (waiting for them only
/// while the planner has calls enough queued).
struct FrontDesk<'a> {
    batch: Vec<Call>,
    mailbox: &'a Mailbox,
    writer: &'a mut dyn PieceSink,
    /// False once the planner has gone before the calls ended (it panicked): later
    /// calls are dropped.
    open: bool,
}

impl CallBatches for FrontDesk<'_> {
    fn open_batch(&mut self) -> Option<&mut Vec<Call>> {
        self.open.then_some(&mut self.batch)
    }

    fn hand_over(&mut self) {
        self.queue_calls();
    }
}

impl<'a> FrontDesk<'a> {
    /// Queues the open batch for the planner, writing arrived pieces while the queue is
    /// full, then writes whatever pieces have arrived.
    fn queue_calls(&mut self) {
        let mut full = std::mem::take(&mut self.batch);
        let mut desk = self.mailbox.desk();
        loop {
            if desk.pieces_end {
                self.open = false;
                full.clear();
                self.batch = full;
                return;
            }
            if desk.calls.len() < CALLS_AHEAD {
                desk.calls.push_back(full);
                self.batch = desk
                    .emptied_calls
                    .pop()
                    .unwrap_or_else(|| Vec::with_capacity(BATCH_CALLS));
                self.mailbox.changed(&desk);
                break;
            }
            desk = match desk.pieces.pop_front() {
                Some(pieces) => self.write(desk, pieces),
                None => self.mailbox.wait(desk),
            };
        }
        while let Some(pieces) = desk.pieces.pop_front() {
            desk = self.write(desk, pieces);
        }
    }

    /// Writes `pieces` with the desk unlocked, and hands the emptied batch back: the
    /// desk, locked again.
    fn write(&mut self, desk: MutexGuard<'a, Desk>, mut pieces: Pieces) -> MutexGuard<'a, Desk> {
        drop(desk);
        pieces.replay(self.writer);
        pieces.clear();
        let mut desk = self.mailbox.desk();
        desk.emptied_pieces.push(pieces);
        self.mailbox.changed(&desk);
        desk
    }

    /// Sends the last calls and writes every piece until the planner has ended.
    fn finish(&mut self) {
        if self.open && !self.batch.is_empty() {
            self.queue_calls();
        }
        let mut desk = self.mailbox.desk();
        desk.calls_end = true;
        self.mailbox.changed(&desk);
        loop {
            desk = match desk.pieces.pop_front() {
                Some(pieces) => self.write(desk, pieces),
                None if desk.pieces_end => return,
                None => self.mailbox.wait(desk),
            };
        }
    }
}

/// Ends both sides when this thread leaves [`planner_aside`], however it leaves (a
/// panicking front end or writer included), so that the planner's thread, which the
/// scope then joins, waits for nothing.
struct LeavingDesk<'a>(&'a Mailbox);

impl Drop for LeavingDesk<'_> {
    fn drop(&mut self) {
        let mut desk = self.0.desk();
        desk.calls_end = true;
        desk.writer_gone = true;
        self.0.changed(&desk);
    }
}

/// The planner's sink on its thread: records pieces into the open batch and queues it
/// for the writer when full, waiting for an emptied one; what is left goes, and the
/// pieces end, when it is dropped (after the planner's last piece, its first error, or
/// its panic).
struct PlannerDesk<'a> {
    batch: Pieces,
    mailbox: &'a Mailbox,
    /// False once the writer has gone (this thread panicked): later pieces are dropped.
    open: bool,
}

impl PlannerDesk<'_> {
    /// Queues the open batch when it is full, and waits for an emptied one.
    fn recorded(&mut self) {
        if self.batch.records.len() < BATCH_PIECES {
            return;
        }
        let mut desk = self.mailbox.desk();
        desk.pieces.push_back(std::mem::take(&mut self.batch));
        self.mailbox.changed(&desk);
        loop {
            if desk.writer_gone {
                self.open = false;
                return;
            }
            if let Some(emptied) = desk.emptied_pieces.pop() {
                self.batch = emptied;
                return;
            }
            desk = self.mailbox.wait(desk);
        }
    }
}

impl PieceSink for PlannerDesk<'_> {
    fn contour(&mut self, motion: Motion, start: &[f64], line: u32) {
        if self.open {
            assert_eq!(start.len(), self.batch.dim, "a start on every axis");
            self.batch.numbers.extend_from_slice(start);
            self.batch.records.push(Record::Contour { motion, line });
            self.recorded();
        }
    }
    fn piece(&mut self, piece: &SegmentRef<'_>) {
        if self.open {
            let dim = self.batch.dim;
            assert!(piece.end.len() == dim && piece.velocity.len() == dim);
            self.batch.numbers.extend_from_slice(piece.end);
            self.batch.numbers.extend_from_slice(piece.velocity);
            self.batch.records.push(Record::Piece {
                duration: piece.duration,
                line: piece.line,
            });
            self.recorded();
        }
    }
    fn event(&mut self, event: &ProgramEvent) {
        if self.open {
            self.batch.events.push(event.clone());
            self.batch.records.push(Record::Event);
            self.recorded();
        }
    }
}

impl Drop for PlannerDesk<'_> {
    fn drop(&mut self) {
        let mut desk = self.mailbox.desk();
        if self.open && !self.batch.records.is_empty() {
            desk.pieces.push_back(std::mem::take(&mut self.batch));
        }
        desk.pieces_end = true;
        self.mailbox.changed(&desk);
    }
}

thread_local! {
    /// Planners this thread has run on threads of their own.
    static PLANNER_THREADS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// How many planners this thread has run on a thread of their own, writing their pieces
/// here (the evidence tests take that a compile took the planner's thread).
pub fn planner_threads() -> usize {
    PLANNER_THREADS.with(std::cell::Cell::get)
}

/// The calls of the front end, as the planner's thread receives them.
pub type Calls<'a> = &'a mut dyn FnMut(&mut dyn ToolpathSink);

/// Runs `front` (a front end pushing into the sink it is given) on this thread and
/// `plan` on a scoped thread of its own, and writes into `writer` on this thread, as
/// they arrive, the pieces on `dim` axes that `plan` puts into the sink it is given;
/// returns what `front` returns and what `plan` returns. `plan` gets the pieces' sink
/// and the front end's calls: calling those with a sink replays every call into it, in
/// order, until the front end has finished. This thread writes the pieces that have
/// arrived whenever it hands the planner a batch of calls, and only they while the
/// planner has [`CALLS_AHEAD`] batches waiting, so each of the two threads has
/// work while the other works. Should the planner's thread not start, nothing has run:
/// `front` comes back, for the caller to run on this thread.
pub fn planner_aside<R, T, F, P>(
    front: F,
    plan: P,
    dim: usize,
    writer: &mut dyn PieceSink,
) -> Result<(R, T), F>
where
    T: Send,
    F: FnOnce(&mut dyn ToolpathSink) -> R,
    P: FnOnce(&mut dyn PieceSink, Calls<'_>) -> T + Send,
{
    let mailbox = Mailbox::default();
    {
        // Every piece batch the planner needs is made here, so that its thread allocates
        // none for the hand-over.
        let mut desk = mailbox.desk();
        desk.emptied_pieces = (1..PIECE_BATCHES)
            .map(|_| Pieces::with_capacity(dim))
            .collect();
        desk.emptied_calls = (0..CALLS_AHEAD)
            .map(|_| Vec::with_capacity(BATCH_CALLS))
            .collect();
    }
    let mut planner_desk = PlannerDesk {
        batch: Pieces::with_capacity(dim),
        mailbox: &mailbox,
        open: true,
    };
    std::thread::scope(|scope| {
        let mailbox = &mailbox;
        let planning = std::thread::Builder::new()
            .name("pvtc planner".into())
            .spawn_scoped(scope, move || {
                let mut calls = |sink: &mut dyn ToolpathSink| {
                    while let Some(mut batch) = mailbox.next_calls() {
                        for call in &batch {
                            call.replay(sink);
                        }
                        batch.clear();
                        mailbox.desk().emptied_calls.push(batch);
                    }
                };
                // The last batch goes, and the pieces end, as the desk is dropped.
                let planned = plan(&mut planner_desk, &mut calls);
                drop(planner_desk);
                planned
            });
        let Ok(planning) = planning else {
            return Err(front);
        };
        let leaving = LeavingDesk(mailbox);
        PLANNER_THREADS.with(|threads| threads.set(threads.get() + 1));
        let mut desk = Recorder(FrontDesk {
            batch: Vec::with_capacity(BATCH_CALLS),
            mailbox,
            writer,
            open: true,
        });
        let read = front(&mut desk);
        desk.0.finish();
        drop(leaving);
        match planning.join() {
            Ok(planned) => Ok((read, planned)),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
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

    /// A stand-in planner: a contour per run of elements, a piece per element (its end,
    /// the feed as every velocity, its line as its time) and an event per event or
    /// tolerance, on `DIM` axes.
    struct Fake<'a> {
        out: &'a mut dyn PieceSink,
        open: bool,
        contours: usize,
    }

    const DIM: usize = 3;

    impl ToolpathSink for Fake<'_> {
        fn element(&mut self, motion: Motion, element: &Element) {
            if !self.open {
                self.out
                    .contour(motion, &element.start[..DIM], element.span.line);
                self.open = true;
            }
            self.out.piece(&SegmentRef {
                end: &element.end[..DIM],
                velocity: &[element.feed; DIM],
                duration: f64::from(element.span.line),
                line: element.span.line,
            });
        }
        fn end_contour(&mut self) {
            self.open = false;
            self.contours += 1;
        }
        fn event(&mut self, event: &EventKind, line: u32) {
            self.out.event(&ProgramEvent {
                before_contour: self.contours,
                kind: event.clone(),
                line,
            });
        }
        fn path_tolerance(&mut self, tolerance: f64) {
            self.event(&EventKind::Dwell { seconds: tolerance }, 0);
        }
    }

    /// Records every piece call it receives, every number exactly, and the threads they
    /// came on.
    #[derive(Default)]
    struct Written(Vec<String>, Vec<std::thread::ThreadId>);

    impl Written {
        fn on(&mut self, call: String) {
            self.0.push(call);
            let here = std::thread::current().id();
            if !self.1.contains(&here) {
                self.1.push(here);
            }
        }
    }

    impl PieceSink for Written {
        fn contour(&mut self, motion: Motion, start: &[f64], line: u32) {
            self.on(format!("contour {motion:?} {start:?} {line}"));
        }
        fn piece(&mut self, p: &SegmentRef<'_>) {
            self.on(format!(
                "piece {:?}",
                (p.end, p.velocity, p.duration, p.line)
            ));
        }
        fn event(&mut self, event: &ProgramEvent) {
            self.on(format!("event {event:?}"));
        }
    }

    /// The stand-in planner's run, returning the thread it ran on.
    fn plan(pieces: &mut dyn PieceSink, calls: Calls<'_>) -> std::thread::ThreadId {
        let mut fake = Fake {
            out: pieces,
            open: false,
            contours: 0,
        };
        calls(&mut fake);
        std::thread::current().id()
    }

    /// What the stand-in planner writes of `front(n)` on this thread alone.
    fn written_alone(n: usize) -> Written {
        let mut alone = Written::default();
        front(n)(&mut Fake {
            out: &mut alone,
            open: false,
            contours: 0,
        });
        alone
    }

    #[test]
    fn the_writer_gets_every_piece_in_order_on_this_thread_from_the_planners() {
        // Piece batches either side of a boundary: none, one short, exact, and many.
        let here = std::thread::current().id();
        for n in [0, 1, BATCH_PIECES - 2, BATCH_PIECES, 7 * BATCH_PIECES + 13] {
            let alone = written_alone(n);
            let mut written = Written::default();
            let Ok((read_on, planned_on)) = planner_aside(front(n), plan, DIM, &mut written) else {
                panic!("no thread started");
            };
            assert!(written.0 == alone.0, "{n} elements");
            // Independently: a piece per element, an event per event and tolerance.
            let pieces = written.0.iter().filter(|c| c.starts_with("piece"));
            assert_eq!(pieces.count(), n);
            assert_eq!(written.0.len(), alone.0.len());
            // Two threads: this one read and wrote, the planner's planned.
            assert_eq!(read_on, here);
            assert_ne!(planned_on, here);
            assert!(written.1.iter().all(|t| *t == here), "{n} elements");
        }
    }

    /// A stand-in planner slower than its front end and writer (every call waits), so
    /// that the front end finds the planner's queue full and writes while it waits.
    fn slow_plan(pieces: &mut dyn PieceSink, calls: Calls<'_>) -> usize {
        struct Slow<'a>(Fake<'a>, usize);
        impl ToolpathSink for Slow<'_> {
            fn element(&mut self, motion: Motion, element: &Element) {
                if self.1.is_multiple_of(64) {
                    std::thread::sleep(std::time::Duration::from_micros(50));
                }
                self.1 += 1;
                self.0.element(motion, element);
            }
            fn end_contour(&mut self) {
                self.0.end_contour();
            }
            fn event(&mut self, event: &EventKind, line: u32) {
                self.0.event(event, line);
            }
            fn path_tolerance(&mut self, tolerance: f64) {
                self.0.path_tolerance(tolerance);
            }
        }
        let mut slow = Slow(
            Fake {
                out: pieces,
                open: false,
                contours: 0,
            },
            0,
        );
        calls(&mut slow);
        slow.1
    }

    #[test]
    fn a_slow_planner_and_a_slow_writer_get_every_call_in_order() {
        let n = 9 * BATCH_CALLS + 5;
        let alone = written_alone(n);
        // The planner slower than this thread.
        let mut written = Written::default();
        let Ok((_, planned)) = planner_aside(front(n), slow_plan, DIM, &mut written) else {
            panic!("no thread started");
        };
        assert_eq!(planned, n);
        assert!(written.0 == alone.0);
        /// A writer that waits at every piece batch's start, slower than the planner.
        struct Slow(Written, usize);
        impl PieceSink for Slow {
            fn contour(&mut self, motion: Motion, start: &[f64], line: u32) {
                self.0.contour(motion, start, line);
            }
            fn piece(&mut self, p: &SegmentRef<'_>) {
                if self.1.is_multiple_of(BATCH_PIECES) {
                    std::thread::sleep(std::time::Duration::from_micros(300));
                }
                self.1 += 1;
                self.0.piece(p);
            }
            fn event(&mut self, event: &ProgramEvent) {
                self.0.event(event);
            }
        }
        let mut slow = Slow(Written::default(), 0);
        let n = 6 * BATCH_PIECES + 5;
        let alone = written_alone(n);
        assert!(planner_aside(front(n), plan, DIM, &mut slow).is_ok());
        assert!(slow.0 .0 == alone.0);
    }

    #[test]
    fn a_panicking_planner_or_writer_panics_the_caller() {
        let caught = std::panic::catch_unwind(|| {
            let mut written = Written::default();
            let plan = |_: &mut dyn PieceSink, _: Calls<'_>| panic!("planner");
            let _ = planner_aside(front(5 * BATCH_CALLS), plan, DIM, &mut written);
        });
        assert!(caught.is_err());
        /// Panics at its first piece.
        struct Refusing;
        impl PieceSink for Refusing {
            fn contour(&mut self, _: Motion, _: &[f64], _: u32) {}
            fn piece(&mut self, _: &SegmentRef<'_>) {
                panic!("writer");
            }
            fn event(&mut self, _: &ProgramEvent) {}
        }
        let caught = std::panic::catch_unwind(|| {
            let _ = planner_aside(front(20 * BATCH_PIECES), plan, DIM, &mut Refusing);
        });
        assert!(caught.is_err());
        // A front end panicking part way, the planner waiting for its calls.
        let caught = std::panic::catch_unwind(|| {
            let front = |sink: &mut dyn ToolpathSink| {
                front(3 * BATCH_CALLS)(sink);
                panic!("front end");
            };
            let _ = planner_aside(front, plan, DIM, &mut Written::default());
        });
        assert!(caught.is_err());
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
