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
//! Where the writer's piece lines are a pure function of the piece ([`PieceWriter`]'s
//! [`PieceLines`]: PMAC text), the planner's thread writes them ahead while it would
//! wait, for calls or for an emptied batch (`PlannerDesk::write_ahead`): its open
//! batch's, then the queued batches' but the first, one lent out at a time
//! (`Desk::lend`), up to [`LINES_AHEAD`] a batch; the writer takes each piece with
//! its line. With calls to read, the calling thread leaves queued the batches whose
//! lines are not all written while the planner keeps up with the calls and two emptied
//! batches are left (`FrontDesk::writes_now`), so the formatting falls to whichever
//! thread has time for it.
//!
//! One thread only ([`threaded`] says no) inside a rayon worker, where `pvtc compile`
//! with several inputs already runs one file per core, and where this process may use
//! one core.
//!
//! Owns the batching and the threads. It must not parse, plan or write: the front end,
//! the planner and the writer do, each on its thread.

use pvt_core::{Element, EventKind, Motion, PieceSink, ProgramEvent, SegmentRef, ToolpathSink};
use pvt_emit::{PieceLine, PieceLines};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Condvar, Mutex, MutexGuard};

/// The writer's side of [`planner_aside`]: a [`PieceSink`] that may take a piece with its
/// line already written, on the planner's thread while it waited for the front end.
pub trait PieceWriter: PieceSink {
    /// How the planner's thread writes piece lines ahead of this writer; none (the
    /// default) where it writes none.
    fn piece_lines(&self) -> Option<PieceLines> {
        None
    }
    /// Takes `piece`, whose line `line` holds, as [`PieceSink::piece`] takes it (the
    /// default calls that).
    fn piece_with_line(&mut self, piece: &SegmentRef<'_>, line: PieceLine<'_>) {
        let _ = line;
        self.piece(piece);
    }
}

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
    PathControl(pvt_core::PathControl),
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
            Call::PathControl(control) => sink.path_control(control),
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
    fn path_control(&mut self, control: &pvt_core::PathControl) {
        self.record(Call::PathControl(*control));
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

/// Emptied piece batches the calling thread keeps ready for the planner while it leaves
/// full ones queued, for the planner's thread to write their lines ahead while it waits
/// for calls (`FrontDesk::writes_now`).
pub const EMPTIED_BATCHES_KEPT: usize = 2;

/// Lines of the longest kind a piece batch has room for, written ahead: half its
/// pieces' (on straight lines the two threads share the formatting about evenly), so
/// that the room, which the batch keeps, adds at most 18 KB to each of the
/// [`PIECE_BATCHES`] on three axes; the writer writes the other lines.
pub const LINES_AHEAD: usize = BATCH_PIECES / 2;

/// Records the planner's thread writes ahead at a time while it waits for the front
/// end's calls, before it looks for them again: a batch of calls that arrives meanwhile
/// waits for at most these lines (some microseconds).
pub const WRITE_AHEAD_STEP: usize = 32;

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
    /// The lines written ahead ([`PlannerDesk::write_ahead`]), one after another, in
    /// room for [`LINES_AHEAD`] lines made when the first is written ahead (none in a
    /// batch that never has one: a route whose planner is the slower thread): its length
    /// only grows, [`Pieces::text_len`] says how much is text.
    text: Vec<u8>,
    text_len: usize,
    /// How the first records' lines were written ahead, a [`LineAhead`] a record.
    ahead: Vec<LineAhead>,
    /// Where the first record not yet written ahead has its numbers.
    ahead_numbers: usize,
}

/// The piece whose numbers on `dim` axes `numbers` starts with: its end, then its
/// velocities.
#[inline]
fn piece_at(numbers: &[f64], dim: usize, duration: f64, line: u32) -> SegmentRef<'_> {
    let (end, velocity) = numbers[..2 * dim].split_at(dim);
    SegmentRef {
        end,
        velocity,
        duration,
        line,
    }
}

/// How a record's line was written ahead: where its text ends in [`Pieces::text`], and
/// its note, for a piece written; nothing for a contour start, an event, or a piece the
/// writer writes itself.
#[derive(Debug, Clone, Copy)]
enum LineAhead {
    Written { end: u32, whole_ms: bool },
    None,
}

impl Pieces {
    /// An empty batch with room for [`BATCH_PIECES`] pieces on `dim` axes, and for
    /// noting how `lines` wrote each ahead ([`Pieces::text`] is made with the first).
    fn with_capacity(dim: usize, lines: Option<&PieceLines>) -> Pieces {
        Pieces {
            dim,
            numbers: Vec::with_capacity(BATCH_PIECES * 2 * dim),
            records: Vec::with_capacity(BATCH_PIECES),
            events: Vec::new(),
            text: Vec::new(),
            text_len: 0,
            ahead: Vec::with_capacity(if lines.is_some() { BATCH_PIECES } else { 0 }),
            ahead_numbers: 0,
        }
    }

    fn clear(&mut self) {
        self.numbers.clear();
        self.records.clear();
        self.events.clear();
        self.text_len = 0;
        self.ahead.clear();
        self.ahead_numbers = 0;
    }

    /// Whether every record's line has been written ahead (or found not to be).
    fn all_ahead(&self) -> bool {
        self.ahead.len() == self.records.len()
    }

    /// Writes ahead the lines of up to `count` records after those written ahead, with
    /// `lines`; false when there were none to write.
    fn write_ahead(&mut self, lines: &PieceLines, count: usize) -> bool {
        let (from, dim, room) = (self.ahead.len(), self.dim, lines.room());
        let to = self.records.len().min(from.saturating_add(count));
        for record in &self.records[from..to] {
            let ahead = match *record {
                Record::Contour { .. } => {
                    self.ahead_numbers += dim;
                    LineAhead::None
                }
                Record::Event => LineAhead::None,
                Record::Piece { duration, line } => {
                    let at = self.ahead_numbers;
                    self.ahead_numbers += 2 * dim;
                    let piece = piece_at(&self.numbers[at..], dim, duration, line);
                    let start = self.text_len;
                    if self.text.capacity() == 0 {
                        self.text.reserve_exact(LINES_AHEAD * room);
                    }
                    // The batch's room, zeroed as lines first reach it.
                    if self.text.len() < start + room && start + room <= self.text.capacity() {
                        self.text.resize(start + room, 0);
                    }
                    match self.text.get_mut(start..start + room) {
                        Some(slot) => match lines.write(&piece, slot) {
                            Some((len, whole_ms)) => {
                                self.text_len += len;
                                LineAhead::Written {
                                    end: self.text_len as u32,
                                    whole_ms,
                                }
                            }
                            None => LineAhead::None,
                        },
                        None => LineAhead::None,
                    }
                }
            };
            self.ahead.push(ahead);
        }
        to > from
    }

    /// Makes the batch's calls on `sink`, in their order, from where they lie, each
    /// piece with its line where it was written ahead.
    fn replay(&self, sink: &mut dyn PieceWriter) {
        let dim = self.dim;
        let (mut at, mut text_at) = (0, 0);
        let mut events = self.events.iter();
        for (i, record) in self.records.iter().enumerate() {
            match *record {
                Record::Contour { motion, line } => {
                    sink.contour(motion, &self.numbers[at..at + dim], line);
                    at += dim;
                }
                Record::Piece { duration, line } => {
                    let piece = piece_at(&self.numbers[at..], dim, duration, line);
                    match self.ahead.get(i) {
                        Some(&LineAhead::Written { end, whole_ms }) => {
                            let end = end as usize;
                            let text = &self.text[text_at..end];
                            text_at = end;
                            sink.piece_with_line(&piece, PieceLine { text, whole_ms });
                        }
                        _ => sink.piece(&piece),
                    }
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
    /// While the planner's thread writes lines ahead in a queued batch, taken out of
    /// [`Desk::pieces`]: how many batches are queued before it, which alone the writer
    /// may take meanwhile.
    lent: Option<usize>,
    /// Threads waiting on the condition: a change wakes them, and only then (a wake-up
    /// is a system call).
    waiting: u8,
}

impl Desk {
    /// Takes out, to write lines ahead in, the last queued piece batch with lines still
    /// to write, any but the first (which the writer is about to take); none where there
    /// is none (or one is lent already).
    fn lend(&mut self) -> Option<Pieces> {
        if self.lent.is_some() {
            return None;
        }
        let queued = &self.pieces;
        let at = (1..queued.len()).rev().find(|&i| !queued[i].all_ahead())?;
        self.lent = Some(at);
        self.pieces.remove(at)
    }

    /// Puts the batch [`Desk::lend`] took back in its place.
    fn give_back(&mut self, batch: Pieces) {
        let before = self.lent.take().unwrap_or(0);
        self.pieces.insert(before, batch);
    }

    /// The next full piece batch for the writer, in order: none while the next one is
    /// lent to the planner's thread.
    fn next_pieces(&mut self) -> Option<Pieces> {
        match &mut self.lent {
            Some(0) => None,
            Some(before) => {
                *before -= 1;
                self.pieces.pop_front()
            }
            None => self.pieces.pop_front(),
        }
    }
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
    /// While there is none, `idle` (with the desk unlocked) does some other work and
    /// says whether it did any: it is called until it does none before this waits.
    fn next_calls(&self, mut idle: impl FnMut() -> bool) -> Option<Vec<Call>> {
        let mut desk = self.desk();
        let mut idle_done = false;
        loop {
            if let Some(batch) = desk.calls.pop_front() {
                self.changed(&desk);
                return Some(batch);
            }
            if desk.calls_end {
                return None;
            }
            if idle_done {
                desk = self.wait(desk);
            } else {
                drop(desk);
                idle_done = !idle();
                desk = self.desk();
            }
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
    writer: &'a mut dyn PieceWriter,
    /// The planner's thread writes piece lines ahead ([`PieceWriter::piece_lines`]).
    lines_ahead: bool,
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
            desk = match desk.next_pieces() {
                Some(pieces) => self.write(desk, pieces),
                None => self.mailbox.wait(desk),
            };
        }
        while self.writes_now(&desk) {
            let Some(pieces) = desk.next_pieces() else {
                break;
            };
            desk = self.write(desk, pieces);
        }
    }

    /// Whether this thread, with calls to read, writes the next queued piece batch now:
    /// yes where no lines are written ahead, where the batch's lines all are, where the
    /// planner has calls queued beyond the batch just handed over (it is the busier
    /// thread, and will not wait), and where it would otherwise soon run out of emptied
    /// batches; else the batch waits for the planner's thread to write its lines while
    /// it waits for calls.
    fn writes_now(&self, desk: &Desk) -> bool {
        match desk.pieces.front() {
            None => false,
            Some(_) if !self.lines_ahead => true,
            Some(next) => {
                next.all_ahead()
                    || desk.calls.len() > 1
                    || desk.emptied_pieces.len() < EMPTIED_BATCHES_KEPT
            }
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
            desk = match desk.next_pieces() {
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
    /// How piece lines are written ahead (the open batch's and the queued ones'), while
    /// the planner waits; none where the writer takes no lines.
    lines: Option<PieceLines>,
}

impl<'a> PlannerDesk<'a> {
    /// Writes ahead the lines of the next [`WRITE_AHEAD_STEP`] records of the open batch,
    /// or where it has none, of a queued batch ([`PlannerDesk::write_ahead_queued`]);
    /// false when there were none to write.
    fn write_ahead(&mut self) -> bool {
        let Some(lines) = self.lines.as_ref().filter(|_| self.open) else {
            return false;
        };
        if self.batch.write_ahead(lines, WRITE_AHEAD_STEP) {
            return true;
        }
        self.write_ahead_queued(self.mailbox.desk()).1
    }

    /// Writes ahead the lines of the next [`WRITE_AHEAD_STEP`] records of the last queued
    /// batch with some, any but the first (which the writer is about to take), lent out
    /// of the `desk` meanwhile: the desk, locked again where it was unlocked, and whether
    /// there were lines to write. Where there were none the desk stays locked throughout,
    /// so a caller that then waits on it misses no change.
    fn write_ahead_queued(&self, mut desk: MutexGuard<'a, Desk>) -> (MutexGuard<'a, Desk>, bool) {
        let Some(lines) = self.lines.as_ref().filter(|_| self.open) else {
            return (desk, false);
        };
        let Some(mut batch) = desk.lend() else {
            return (desk, false);
        };
        drop(desk);
        batch.write_ahead(lines, WRITE_AHEAD_STEP);
        let mut desk = self.mailbox.desk();
        desk.give_back(batch);
        self.mailbox.changed(&desk);
        (desk, true)
    }

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
            desk = match self.write_ahead_queued(desk) {
                (desk, true) => desk,
                (desk, false) => self.mailbox.wait(desk),
            };
        }
    }
}

/// The planner's sink on its thread: the [`PlannerDesk`], shared with the wait for the
/// front end's calls, which writes lines ahead meanwhile.
struct SharedDesk<'d, 'a>(&'d RefCell<PlannerDesk<'a>>);

impl PieceSink for SharedDesk<'_, '_> {
    fn contour(&mut self, motion: Motion, start: &[f64], line: u32) {
        self.0.borrow_mut().contour(motion, start, line);
    }
    fn piece(&mut self, piece: &SegmentRef<'_>) {
        self.0.borrow_mut().piece(piece);
    }
    fn event(&mut self, event: &ProgramEvent) {
        self.0.borrow_mut().event(event);
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
    writer: &mut dyn PieceWriter,
) -> Result<(R, T), F>
where
    T: Send,
    F: FnOnce(&mut dyn ToolpathSink) -> R,
    P: FnOnce(&mut dyn PieceSink, Calls<'_>) -> T + Send,
{
    let mailbox = Mailbox::default();
    let lines = writer.piece_lines();
    {
        // Every piece batch the planner needs is made here, so that its thread allocates
        // none for the hand-over.
        let mut desk = mailbox.desk();
        desk.emptied_pieces = (1..PIECE_BATCHES)
            .map(|_| Pieces::with_capacity(dim, lines.as_ref()))
            .collect();
        desk.emptied_calls = (0..CALLS_AHEAD)
            .map(|_| Vec::with_capacity(BATCH_CALLS))
            .collect();
    }
    let lines_ahead = lines.is_some();
    let planner_desk = PlannerDesk {
        batch: Pieces::with_capacity(dim, lines.as_ref()),
        mailbox: &mailbox,
        open: true,
        lines,
    };
    std::thread::scope(|scope| {
        let mailbox = &mailbox;
        let planning = std::thread::Builder::new()
            .name("pvtc planner".into())
            .spawn_scoped(scope, move || {
                let planner_desk = RefCell::new(planner_desk);
                let mut calls = |sink: &mut dyn ToolpathSink| {
                    let idle = || planner_desk.borrow_mut().write_ahead();
                    while let Some(mut batch) = mailbox.next_calls(idle) {
                        for call in &batch {
                            call.replay(sink);
                        }
                        batch.clear();
                        mailbox.desk().emptied_calls.push(batch);
                    }
                };
                // The last batch goes, and the pieces end, as the desk is dropped.
                let planned = plan(&mut SharedDesk(&planner_desk), &mut calls);
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
            lines_ahead,
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

    impl PieceWriter for Written {}

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
        let mut fake = Fake {
            out: pieces,
            open: false,
            contours: 0,
        };
        let mut slow = Pausing::new(&mut fake, 64, 50);
        calls(&mut slow);
        slow.elements
    }

    /// A sink passing every call on, sleeping `micros` at every `every`-th element from
    /// the first.
    struct Pausing<'a> {
        next: &'a mut dyn ToolpathSink,
        elements: usize,
        every: usize,
        micros: u64,
    }

    impl<'a> Pausing<'a> {
        fn new(next: &'a mut dyn ToolpathSink, every: usize, micros: u64) -> Pausing<'a> {
            Pausing {
                next,
                elements: 0,
                every,
                micros,
            }
        }
    }

    impl ToolpathSink for Pausing<'_> {
        fn element(&mut self, motion: Motion, element: &Element) {
            if self.elements.is_multiple_of(self.every) {
                std::thread::sleep(std::time::Duration::from_micros(self.micros));
            }
            self.elements += 1;
            self.next.element(motion, element);
        }
        fn end_contour(&mut self) {
            self.next.end_contour();
        }
        fn event(&mut self, event: &EventKind, line: u32) {
            self.next.event(event, line);
        }
        fn path_tolerance(&mut self, tolerance: f64) {
            self.next.path_tolerance(tolerance);
        }
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
        impl PieceWriter for Slow {}
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
        impl PieceWriter for Refusing {}
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
    fn the_writer_takes_no_batch_past_one_lent() {
        // Batches told apart by their first record's line; the last `done` ones have
        // every line written ahead.
        let queued = |count: u32, done: u32| -> Desk {
            let mut desk = Desk::default();
            for line in 0..count {
                let mut batch = Pieces::with_capacity(DIM, None);
                batch.records.push(Record::Event);
                batch.records.push(Record::Piece {
                    duration: 1.0,
                    line,
                });
                if line >= count - done {
                    batch.ahead = vec![LineAhead::None; 2];
                }
                desk.pieces.push_back(batch);
            }
            desk
        };
        let first_line = |batch: Option<&Pieces>| match batch.map(|b| b.records[1]) {
            Some(Record::Piece { line, .. }) => Some(line),
            _ => None,
        };
        for (count, done, lent) in [
            (3, 0, Some(2)),
            (3, 1, Some(1)),
            (4, 2, Some(1)),
            (3, 2, None),
        ] {
            let mut desk = queued(count, done);
            let batch = desk.lend();
            assert_eq!(first_line(batch.as_ref()), lent, "{count} {done}");
            let Some(batch) = batch else {
                continue;
            };
            assert!(desk.lend().is_none(), "one lent at a time");
            // Only those before it go while it is lent, then it, then those after it.
            let mut order = Vec::new();
            while let Some(line) = first_line(desk.next_pieces().as_ref()) {
                order.push(line);
            }
            assert_eq!(order, (0..lent.unwrap()).collect::<Vec<_>>());
            desk.give_back(batch);
            while let Some(line) = first_line(desk.next_pieces().as_ref()) {
                order.push(line);
            }
            assert_eq!(order, (0..count).collect::<Vec<_>>());
        }
    }

    /// A PMAC writer behind the hand-over, counting the pieces that came with their line
    /// written ahead; slow at every `slow_every`-th piece where set.
    struct Pmac {
        writer: pvt_emit::pmac::PmacWriter<Vec<u8>>,
        with_line: usize,
        pieces: usize,
        slow_every: Option<usize>,
    }

    impl Pmac {
        fn new(slow_every: Option<usize>) -> Pmac {
            let mut writer = pvt_emit::pmac::PmacWriter::new(Vec::new());
            let options = pvt_emit::EmitOptions::default();
            let header = pvt_emit::Header {
                axes: &[pvt_core::Axis::X, pvt_core::Axis::Y, pvt_core::Axis::Z],
                units: pvt_core::Units::Millimetre,
                interpolation: pvt_core::Interpolation::Pvt,
                options: &options,
            };
            pvt_emit::ProgramWriter::begin(&mut writer, &header).unwrap();
            Pmac {
                writer,
                with_line: 0,
                pieces: 0,
                slow_every,
            }
        }

        fn text(mut self) -> String {
            pvt_emit::ProgramWriter::finish(&mut self.writer).unwrap();
            String::from_utf8(self.writer.into_inner()).unwrap()
        }

        fn counted(&mut self) {
            if self
                .slow_every
                .is_some_and(|k| self.pieces.is_multiple_of(k))
            {
                std::thread::sleep(std::time::Duration::from_micros(300));
            }
            self.pieces += 1;
        }
    }

    impl PieceSink for Pmac {
        fn contour(&mut self, motion: Motion, start: &[f64], _: u32) {
            pvt_emit::ProgramWriter::contour(&mut self.writer, motion, start).unwrap();
        }
        fn piece(&mut self, p: &SegmentRef<'_>) {
            self.counted();
            pvt_emit::ProgramWriter::segment(&mut self.writer, p).unwrap();
        }
        fn event(&mut self, event: &ProgramEvent) {
            pvt_emit::ProgramWriter::event(&mut self.writer, event).unwrap();
        }
    }

    impl PieceWriter for Pmac {
        fn piece_lines(&self) -> Option<PieceLines> {
            pvt_emit::ProgramWriter::piece_lines(&self.writer)
        }
        fn piece_with_line(&mut self, p: &SegmentRef<'_>, line: PieceLine<'_>) {
            self.counted();
            self.with_line += 1;
            pvt_emit::ProgramWriter::segment_with_line(&mut self.writer, p, line).unwrap();
        }
    }

    /// A stand-in planner whose pieces have times of no whole millisecond, some
    /// positions too large for a line written ahead (4.5·10⁶ units and more), contours
    /// and events.
    fn varied_plan(pieces: &mut dyn PieceSink, calls: Calls<'_>) {
        struct Varied<'a>(&'a mut dyn PieceSink, bool);
        impl ToolpathSink for Varied<'_> {
            fn element(&mut self, _: Motion, e: &Element) {
                let i = f64::from(e.span.line);
                if !self.1 {
                    self.0.contour(Motion::Feed, &[i, 0.0, 0.0], e.span.line);
                    self.1 = true;
                }
                let far = if e.span.line % 97 == 5 { 5e6 } else { 0.0 };
                self.0.piece(&SegmentRef {
                    end: &[i * 0.123_456_789_1, -i.sqrt(), far + 1.0 / (i + 1.0)],
                    velocity: &[e.feed, -0.5 * e.feed, 1e-7 * i],
                    duration: 0.000_7 * (1.0 + i % 13.0) + i * 1e-9,
                    line: e.span.line,
                });
            }
            fn end_contour(&mut self) {
                self.1 = false;
            }
            fn event(&mut self, event: &EventKind, line: u32) {
                self.0.event(&ProgramEvent {
                    before_contour: 0,
                    kind: event.clone(),
                    line,
                });
            }
            fn path_tolerance(&mut self, _: f64) {}
        }
        calls(&mut Varied(pieces, false));
    }

    /// `front(n)`, sleeping at every `pause_every`-th element from the first: the
    /// planner's thread waits for calls.
    fn slow_front(n: usize, pause_every: usize) -> impl FnOnce(&mut dyn ToolpathSink) {
        move |sink| {
            front(n)(&mut Pausing::new(sink, pause_every, 200));
        }
    }

    #[test]
    fn lines_written_ahead_are_the_lines_the_writer_writes() {
        let n = 12 * BATCH_PIECES + 77;
        let mut alone = Pmac::new(None);
        varied_plan(&mut alone, &mut |sink| {
            front(n)(sink);
        });
        assert_eq!((alone.pieces, alone.with_line), (n, 0));
        let alone = alone.text();
        assert!(alone.lines().filter(|l| l.starts_with("TA")).count() == n);
        // The planner waiting for a slow front end writes the open batch's lines and the
        // queued ones'; waiting for a slow writer, the queued batches' but the first.
        for slow_writer in [None, Some(BATCH_PIECES)] {
            let mut written = Pmac::new(slow_writer);
            // A slow writer, a front end that never waits; else a slow front end.
            let pause_every = if slow_writer.is_some() {
                usize::MAX
            } else {
                64
            };
            let front = slow_front(n, pause_every);
            if planner_aside(front, varied_plan, DIM, &mut written).is_err() {
                panic!("no thread started");
            }
            let with_line = written.with_line;
            assert_eq!(written.pieces, n);
            assert!(with_line >= n / 8, "{with_line} of {n} lines written ahead");
            assert!(written.text() == alone, "{slow_writer:?}");
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
