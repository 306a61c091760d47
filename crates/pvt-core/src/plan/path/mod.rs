//! The path planner: motion that follows the programmed geometry within a tolerance.
//!
//! Owns the choice of knots (points on the true elements), the speed at each knot, and
//! the piece between two knots, for one rest-to-rest contour. It must not parse, print or
//! flatten through chords: it reads the elements themselves ([`curve`]).
//!
//! # The guarantee
//! Each piece runs from knot `a` to knot `b` on one element `c(φ)`. The planner defines a
//! reference motion `φ(t)`, quadratic in time (constant parameter acceleration, so
//! constant tangential acceleration on a line or circle), and gives the piece the exact
//! position and velocity of `c(φ(t))` at both ends. Cubic Hermite interpolation of a
//! smooth function then errs by at most `max|d⁴c(φ(t))/dt⁴|·T⁴/384`, and with
//! `|dⁿc/dφⁿ| ≤ Dₙ` and `φ''' = 0`:
//!
//! ```text
//! |H(t) − c(φ(t))| ≤ T⁴/384 · (D₄·ω⁴ + 6·D₃·ω²·|ω'| + 3·D₂·ω'²)  +  4/27 · T · (|Δv_a| + |Δv_b|)
//! ```
//!
//! where `ω` is the largest parameter rate of the piece, `ω'` its parameter acceleration,
//! and `Δv` the difference between a knot's velocity and the element's own velocity there
//! (non-zero only at a junction passed at speed, where the velocity points along the
//! bisector of the two tangents; the Hermite basis functions of the end velocities peak
//! at 4/27). Every piece is split until this bound is within the path tolerance, so the
//! motion at every instant is within the tolerance of the programmed point `c(φ(t))`:
//! it stays near the geometry and it covers all of it. A line has `Dₙ = 0`: a piece whose
//! velocities lie along the line stays on it exactly.
//!
//! # Speeds
//! Each knot's speed is capped by the feed, by each axis' velocity and (with limits) by
//! each axis' share of the centripetal acceleration; a junction is passed at speed when
//! its tangents meet within [`TANGENT_ANGLE`] (without limits) or at the speed its
//! adjacent pieces' lateral acceleration allows (with limits), and otherwise is a stop.
//! A backward and a forward pass bound the change of speed between knots by the
//! tangential acceleration that is left. Lines get trapezoid knots (accelerate, cruise,
//! decelerate). Finally every piece's per-axis velocity and acceleration peaks are
//! computed in closed form; where one exceeds a limit the speeds of its knots are lowered
//! and the passes run again.
//!
//! # Jerk
//! With a jerk limit on some axis (jerk mode; without one nothing below applies and the
//! pieces are those described above), the planner bounds, on every axis `i` with a
//! limit `Jᵢ`:
//! - each piece's own jerk, the constant third derivative `6·a₃` of its cubic, by `Jᵢ`:
//!   a piece over it has its knots slowed by the cube root of the excess (its jerk
//!   scales with the cube of its speeds);
//! - the step of the acceleration at every knot, `|a(T) of the piece before − a(0) of
//!   the piece after|`, by `Jᵢ·Tₛ`, and at the contour's start and end against rest
//!   (`a = 0`) by half of it, so that two contours run straight on (no dwell between)
//!   step by at most `Jᵢ·Tₛ` where they meet; with `Tₛ` the servo period ([`PathOptions::servo_period`]: the machine
//!   file's `servo_period`, else [`crate::defaults::SERVO_PERIOD_S`]): a servo loop
//!   that spreads the step over one period sees at most the jerk limit;
//! - and, as without, every velocity and acceleration limit and the path tolerance.
//!
//! Every knot inside an element carries zero parameter acceleration, and a piece whose
//! speed changes is an S-curve in its parameter over the same time `T = 2·span/(wa + wb)`: jerk `+j`,
//! constant acceleration `A`, jerk `−j`, with `A` the smaller root of `T = Δw/A + A/j`
//! (two ramps of jerk `4·Δw/T²` when the middle would be under 1 % of `T`). The path jerk
//! `j` is 0.99 (on a line) or 0.9 (on an arc, whose turn adds jerk) of the least
//! `Jᵢ/|tᵢ|` over the axes the piece moves (`tᵢ` its share of the tangent). Each part's reference motion `φ(t)` is a cubic, and the part's cubic
//! runs from the exact position and velocity of `c(φ)` at its ends, with the error bound
//! of "Quantization" below; on a line the parts are the S-curve itself, so the
//! acceleration is continuous. A piece whose whole speed change at constant
//! acceleration would step the acceleration by at most a quarter of `j·Tₛ` stays one
//! cubic. At a junction passed at speed between two curves whose rates `ρ = |dc/dφ|`
//! change (two parts of a Bézier), zero parameter acceleration would leave each side the
//! tangential acceleration `g·v²`, `g = ρ'/ρ²`, which differ: there each piece beside
//! the junction starts (or ends) with the parameter acceleration that gives both sides
//! their mean, in three parts whose parameter acceleration is linear on each (ramps of
//! at least a third of its time) and takes the two inner values that meet its end rate
//! and its span, so each part's `φ(t)` is again a cubic with the bound below. The
//! passes and the trapezoid knots use the S-curve's shortest distance from
//! `va` to `vb`, `(va + vb)/2·(Δv/a + a/j)` when `Δv ≥ a²/j`, else `(va + vb)·√(Δv/j)`:
//! the passes invert it in closed form (a cubic in `√Δv`, a quadratic in `Δv`), the
//! trapezoid's peak by a fixed number of bisections.
//!
//! A corner blend is a pulse of acceleration, at rest in acceleration at both of its
//! knots, so that it does not step against the lines beside it: from `L` before the
//! corner at `va` along `t₁` to `L` after it at `vb` along `t₂`, its acceleration is
//! `s(t)·(vb·t₂ − va·t₁)` with `s` the triangle of area 1 over `T = L/va + L/vb` whose apex
//! is at `θ·T`, `θ = (2vb − va)/(va + vb)` (the only such pulse that meets both lines at
//! `L`; it needs `va/2 < vb < 2va`, and the passes keep the ratio within 1.5). Its
//! acceleration is linear on `[0, θT]` and on `[θT, T]`, so it is two cubics, exact. With
//! `u = t/T` it runs at `C − A(u)·t₁ + E(u)·t₂`, `A` falling from `L` to 0 and `E` rising
//! from 0 to `L`, so the corner blend's bound holds: within `2·A(u*)·sin(α/2)` of the
//! lines and the corner, `u*` where `A = E`; `L·sin(α/2)/3` at equal speeds, and `L` is
//! sized for that (at most 0.49 of either line). At equal speeds its acceleration peaks at
//! `v²·|t₂ᵢ − t₁ᵢ|/L` and its jerk is `v³·|t₂ᵢ − t₁ᵢ|/L²` on axis `i`: the blend's cap
//! keeps both within the limits, the jerk within 0.5 of it, and the passes let it change
//! speed as an S-curve over `2L` at 0.45 of the least jerk limit. Its cost is on dense
//! chords of a curve of radius `R`, where `L` is about half a chord `c ≈ √(8·R·tol)`: its
//! cap `∛(0.5·Jᵢ·L²·R/c)` is below the curve's own, `√(Aᵢ·R)`.
//!
//! A line and a plane circle that meet at a tangent are joined by a *curvature
//! transition* ([`transition`]), planned as a corner blend is: on the exact geometry the
//! acceleration steps by `v²/R` at the junction, so the step bound would allow at most
//! `√(Jᵢ·Tₛ·R)` there (11 mm/s into an arc of 5 mm with `Jᵢ·Tₛ` = 25 mm/s²). The
//! transition leaves the line `L_a` before the junction and joins the circle
//! `L_b = 0.3·(L_a + L_b)` after it; its acceleration is linear in time on two parts, from
//! the line's (zero) through a middle value to the circle's (`v²/R`, normal), so it is two
//! cubics that are the motion itself, continuous in acceleration at its middle, and
//! neither of its knots steps (against the circle's next piece, only by that piece's own
//! interpolation, as at any knot of an arc). Its two speeds are equal (the passes give
//! it a speed ratio of 1), so its path does not depend on the speed: its distance from
//! the line and the circle is bounded once, at 0.9 of the path tolerance (sampled with a
//! margin for the distance's second derivative between samples, see [`transition`]),
//! which sizes `L_a + L_b` (about `√(80·R·tol)`, at most 0.45 of either element), and
//! its acceleration and jerk are `v²` and `v³` times their values at unit speed, which
//! give its cap (0.95 of each limit; its jerk is about `1.5·v³/(R·(L_a + L_b))`). With
//! the mill's limits and a tolerance of 0.5 µm a line enters an arc of 5 mm at about
//! 38 mm/s. Its knots are marked as a corner blend's (`Knot::blend`): a window is never
//! cut at its first knot nor inside it, on a grid either, and the resampled grid measures
//! it against the path tolerance. The stretched grid's plans (`narrow`) have none.
//!
//! What still steps (a junction passed at speed, a change of
//! curvature `v²·Δκ`, the interpolation of a curve) grows with the square of the
//! speeds: every knot's step is computed in closed form from the two cubics beside it,
//! and where it exceeds the bound the knot's cap is lowered by the square root of the
//! excess (a blend beside it, and an S-curve or blend whose inner point steps, have both
//! their knots lowered) and the contour is planned again. The cost: speed changes take longer
//! (the ramps, and the return to zero tangential acceleration at every knot, on arcs
//! too), and corners and the curvature jumps no transition smooths are taken slower (an
//! arc into an arc of another radius, a helix or a Bézier part, `|Δκ|` apart, at most at
//! `√(Jᵢ·Tₛ/|Δκ|)`).
//!
//! ## Windows under a jerk limit
//! Every knot carries zero tangential acceleration, so a window's start state is the
//! knot's position, its velocity along the element's tangent and the acceleration of
//! the written piece's end (its normal part; the tangential part is zero): the full
//! `(p, v, a)` the next window's first piece starts from. A window is never cut at a
//! curvature transition's first knot nor between its two parts (a window's first piece
//! must start from a knot of an element); the knot that ends a transition carries the
//! circle's `v²/R`, and a cut there is refused by the half-step check below as at any
//! knot of an arc at speed. A contour streams in windows
//! ([`PathStream`]) with these changes:
//! - The window is planned to rest at its end, with no closed-form caps. The cut is at
//!   or before the *stop horizon* (`Knots::stop_horizon`): the last knot `h` at which
//!   the backward pass from rest at the last known knot (the window's last element's
//!   end depends on what follows), run without caps over the window's own pieces,
//!   each an S-curve at its own tangential acceleration and path jerk (the passes'
//!   `reach`, over any number of short elements), reaches the highest feed of the
//!   elements up to `h`. Claim: every speed at or before `h` is the one the whole
//!   contour's passes give it. The backward pass sets `vᵢ = min(capᵢ, reachᵢ(vᵢ₊₁))`;
//!   where the stop at the window's end binds at a knot `m > h`, `vₘ` is at least the
//!   uncapped pass's value there, and `reach` grows with its argument, so at `h` the
//!   bound it carries back is at least the uncapped pass's value, the feed, which no
//!   speed exceeds; the same holds at every knot before `h` (the pass's value only
//!   grows backward, the feed up to it only shrinks). The forward pass starts at the
//!   same fixed start. The window's speeds up to `h` are the whole contour's (the
//!   repairs are local to pieces and the knots beside them: tested, a windowed plan
//!   within 2 % of the whole one's time).
//! - The window's length is bounded: with no horizon in its second half it is planned
//!   again at twice its size, up to [`JERK_WINDOW_GROWTH`] times the stream's window;
//!   then it is cut where [`Knots::cut`] leaves the closed-form S-curve stop
//!   `v·(v/a + a/j)` of the highest feed (`scurve_stop`) after it, slower there than
//!   the whole contour, never wrong. Each plan emits at least half its knots, so a
//!   contour of `N` elements costs `O(N)` element plans (a factor 2 for the doublings),
//!   and the held elements are at most `JERK_WINDOW_GROWTH` windows. The next window is
//!   planned at the size this one had: it holds all of this one's known path after the
//!   cut, so it has the same room to bring its fixed start to rest.
//! - The cut knot `k` (`Knots::room_to_slow`): the passes bring its speed to rest on
//!   known path through every planned speed after it (the same backward pass from rest
//!   at knots `k + 1, k + 2, k + 4, …`, capped at the planned speeds: a row's reversal
//!   within the stop counts; on a grid at the least share's limits);
//!   the next window's first piece before its trapezoid knots (to the next knot that
//!   ends an element or starts a corner blend) does not slow and does not end in a
//!   corner blend (a blend's cap differs between the limit shares a grid's windows plan
//!   at), or lies on a line with room for an S-curve from its speed to any lower one
//!   (`scurve_stop`: a deceleration that fills its piece exactly cannot be met, within
//!   rounding, without slowing the fixed start); on a grid the piece after the cut
//!   lasts at least a quantum (a shorter one is rounding noise in its cubic's
//!   accelerations). On a raster of short lines at its feed every junction qualifies.
//! - The step where two windows meet: the written piece before the cut ends with an
//!   acceleration within half the step bound on every axis (checked at the cut), and the
//!   next window's first piece starts within the other half (checked against rest, as a
//!   contour's start is), so the step is within `max_jerk · servo_period`. Every
//!   written piece is checked in its own window against every limit, its jerk and the
//!   tolerance, and the next window starts exactly at its end state.
//!
//! A trapezoid on a line whose start is already at its peak speed (a window's fixed start
//! at its cap, within a rounding error of it) has no rise knot: the rise's S-curve
//! length, `(va + vb)·√(Δv/j)`, is far larger than the speed's rounding, and a knot
//! there began a piece of nanoseconds that the repairs slowed to rest.
//!
//! On a quantum grid the jerk-limited plan is resampled in time (see "Resampling in
//! time" below), and the resampled pieces are checked against the same bounds: each
//! piece's jerk and every grid knot's acceleration step, from the cubics beside it.
//! Where only the stretched grid converges, each knot's piece (its S-curve's or
//! blend's parts joined: a blend is one cubic there, within the triangle bound
//! `L·sin(α/2)` that sizes blends on a grid) gets whole quanta, at least three when it spans 1.5 quanta or more, and each
//! knot's velocity is divided by the larger stretch beside it, as without a jerk limit.
//! A piece that is not a blend and not at rest is then three parts of whole quanta
//! (ramp, middle, ramp) whose parameter acceleration is linear on each part, zero at
//! both knots, and takes the two inner values that meet the new end rates and the span
//! in the new time: the motion stays C² in the parameter, each part's `φ(t)` is a cubic
//! with the bound below, and the same step check and repairs run on the grid. Trapezoid
//! cruises shorter than three quanta are left out there (the piece decelerates from its
//! peak instead), since a shorter piece would be stretched, and the velocities beside
//! it divided, by far more.
//!
//! # Quantization
//! With a quantum `q` (`--quantize`), the planned pieces go onto the grid here, before
//! they are emitted, and are checked again: piece `i` of planned time `Tᵢ` gets `nᵢ`
//! whole quanta (as the grid rounds `Tᵢ`, at least one), its stretch is `kᵢ = nᵢq/Tᵢ`, and
//! each knot's velocity is divided by `K = max(kᵢ₋₁, kᵢ)`, the larger stretch beside it
//! (the contour's first and last, at rest, by their one piece's). Positions do not move. The reference
//! motion of a piece becomes the cubic `φ(t)` in the parameter with the knots' new rates
//! `w/K` at its ends over `nᵢq`; since `K ≥ kᵢ` it is monotone (the Hermite ratios
//! `α + β ≤ 2`), so `c(φ(t))` stays on the piece's part of the element, and with
//! `φ'''' = 0` the error bound above gains one term and reads
//!
//! ```text
//! T⁴/384 · (D₄·ω⁴ + 6·D₃·ω²·|φ''| + 3·D₂·φ''² + 4·D₂·ω·|φ'''|)  +  4/27 · T · (|Δv_a| + |Δv_b|)/K
//! ```
//!
//! with `ω` and `|φ''|` the closed-form peaks of the cubic `φ`. A corner blend keeps its
//! bound: its inner control points only move towards its ends. Every piece's closed-form
//! peaks are checked; a piece over a limit gets more quanta (which lowers the velocities
//! beside it), and a piece still over a limit, or over the tolerance, is slowed or split
//! in the plan and the whole contour is planned and put on the grid again. This
//! stretched grid is for a contour planned whole (one window, see "Streaming on a
//! grid"): a window's first velocity, already written, could not be divided again.
//!
//! ## Resampling in time
//! There is a second way onto the grid ([`resample`]). Without a jerk limit each contour
//! takes the one with the shorter total time, the stretched grid above when they are
//! within half a quantum of each other (both totals are whole quanta); under a jerk
//! limit the resampled grid is tried first and the stretched one only where it does not
//! converge. Stretching each piece divides a knot's velocity by the larger stretch
//! beside it, so on dense chords (pieces of a few quanta, corner blends under one)
//! neighbouring stretches differ widely and the repairs slow the motion far below the
//! plan; resampling keeps it:
//! 1. The contour is planned again, settled and un-gridded, at
//!    [`resample::RESAMPLE_SHARE`] (0.8) of the path and corner tolerances, and at each
//!    of [`resample::ACCELERATION_SHARES`] of the acceleration limits in turn (the
//!    shortest result wins); under a jerk limit at 0.95 of the tolerances and with
//!    [`resample::Shares`]' shares of the acceleration limits, the step bound and the
//!    jerk. Its motion `x_p(t)` is C¹ piecewise cubic; each planned piece is within its
//!    error bound `eᵢ` of the programmed point `c(φ(t))` at every instant (as above).
//! 2. It is scaled uniformly in time by `s = ⌈T/q⌉·q/T ≥ 1`, so that its total is whole
//!    quanta: the same path, velocities divided by `s`, accelerations by `s²`, and the
//!    same error bounds.
//! 3. Grid knots are the planned knots' scaled times rounded to the nearest quantum,
//!    duplicates dropped, with the contour's ends at 0 and `⌈T/q⌉`; each piece is the
//!    cubic Hermite `H` through the position and velocity of the scaled `x_p` at its two
//!    grid knots, over their whole quanta (so the motion stays C¹, from rest to rest).
//! 4. Tolerance: on each sub-interval between planned knots both `x_p` and `H` are
//!    cubics, so per axis the largest `|x_p − H|` is exact (at the ends or where the
//!    difference's derivative vanishes); the Euclidean norm of the per-axis maxima bounds
//!    the distance, and the motion is within `eᵢ + max|x_p − H|` of `c(φ(t))`. Where that
//!    sum exceeds the path tolerance (a corner blend's: the corner tolerance) the interval
//!    gets a grid knot in its middle; the sum is the piece's error bound. An interval
//!    over more than three elements is split too: a piece names one source line, the
//!    middle element's, and `check` looks for its motion near that line's elements and
//!    their neighbours.
//! 5. Limits: every resampled piece's closed-form per-axis velocity and acceleration
//!    peaks (and jerk) are checked as every other piece's. Under a jerk limit so is the
//!    acceleration step at every grid knot (against rest at the contour's ends by half
//!    the bound), less the room the written positions' rounding takes beside it: a
//!    Hermite piece through a motion whose jerk changes by `Δj` inside it misses the
//!    motion's end acceleration by at most `4/27·|Δj|·T`, so a knot over its bound gets
//!    grid knots one quantum away on each side (intervals of two quanta or more), and
//!    where both intervals beside it are one quantum the plan is slowed there. Where
//!    one is over (or an interval of one quantum is over the tolerance), the planned
//!    knots its interval covers have their speed caps lowered by the excess, the plan is
//!    settled and resampled again. When no
//!    share converges within its rounds (all together a fifth of [`MAX_ROUNDS`], so that
//!    a contour that does not converge costs little) the contour takes the stretched
//!    grid.
//!
//! Under a jerk limit the plan's acceleration is continuous along each S-curve and
//! steps at knots only by what the step bound allows, so the resampled acceleration
//! stays within `8/27·Jᵢ·q` of it (the first plans take that share of the acceleration
//! limits off); a step `Δa` inside a quantum adds up to `1.5·Δa/q` to a resampled
//! piece's jerk, and a jerk change up to `16/27·Δj·q` to a grid knot's step. Where the
//! first plan does not converge (grids of several servo periods, or finer than one),
//! the later ones take a lower jerk and step bound so that these fit.
//!
//! ## Streaming on a grid
//! A contour that fills the window ([`WINDOW_ELEMENTS`]) on a grid, with or without a
//! jerk limit, is resampled window by window, in the same bounded memory as without a grid; a
//! shorter one is planned whole at its end as above, so its pieces are unchanged.
//! 1. Each window's plan is made as in step 1 of "Resampling in time", at the shares of
//!    [`resample::Shares`] in turn, and the first that converges is taken (the whole
//!    contour takes the shortest). The tries start at the share the last window
//!    converged at, then take those before it: a long contour whose windows converge
//!    only at a later share (a dense raster at the whole jerk) does not spend each
//!    window's rounds on the shares before it again. Its knots are capped as [`PathStream`]'s windows
//!    are, at the least tangential acceleration of every share, so the next window,
//!    whatever share it converges at, can stop from any knot this one cuts at. Under a
//!    jerk limit each share's plan takes the step and jerk shares of the whole contour's
//!    plans, and the stopping distance and the room after a cut are the S-curve's of
//!    "Windows under a jerk limit", at the least acceleration and jerk of every share.
//! 2. The window is cut at a grid time `τ = g·q` of the window (its start is on the
//!    grid): the last at or before the knot the stopping distance chooses that is a
//!    cuttable knot's time, or that lies inside a planned piece that follows one element
//!    at speed (no corner blend), inside a line with at least the stopping distance from
//!    its speed (at that least acceleration) left after it: whatever the next window's
//!    repairs ask of the knots after it, its fixed first knot can come to rest on that
//!    line, so its plan settles as a contour's start does (a cut before a short line's
//!    blend did not: the blend slowed, the fixed knot could not). Under a jerk limit a
//!    time inside a piece that ends at a corner (a junction whose direction is not the
//!    element's tangent) must leave the piece at least [`Knots::turn_time`] after it, the
//!    time a cubic needs to turn the velocity onto the corner's direction within the
//!    jerk: a cut 1.9 ms before a kinked arc's end left the next window a piece that
//!    broke the jerk limit at any speed its fixed knot allowed. Without a jerk limit,
//!    where there is no such time, the window ends at its last knot at rest (an exact
//!    stop; a line between two stops is one piece from rest to rest, with no room
//!    inside): the next window starts at rest, as a contour does, and this one's last
//!    grid interval holds the stop to the next whole quantum, as at a contour's end
//!    (step 5), so the stream is at most a quantum a window slower there than the
//!    contour planned whole. A contour whose first window has no such time or knot is
//!    held whole. There a knot is inserted on the piece's own reference
//!    motion: at `φ(u)` with the speed `φ'(u)·|c'|`, `u = τ − tᵢ`. The two pieces beside
//!    it have the same reference motion over `u` and `T − u`, so their error bounds are
//!    within the piece's, and the plan's motion reaches the inserted knot at `τ`
//!    exactly, with the knot's position and velocity.
//! 3. The plan's pieces up to that knot are resampled without scaling (`s = 1`), from
//!    the window's start to `τ`; the grid knots, the pieces, their exact deviation and
//!    every limit check are those of "Resampling in time", and a piece over a limit
//!    slows the window's plan (the inserted knot taken out first) as there. The pieces go
//!    out; the next window starts at the inserted knot with its speed fixed. Its first
//!    grid piece starts from the state the last one written ended in: both are the
//!    knot's position and its velocity along the element's tangent, computed from the
//!    same element, parameter and speed. Under a jerk limit the acceleration step at a window's
//!    first and last grid knots is checked against rest by half the bound, as at a
//!    contour's ends, so where two windows meet it is within the bound.
//! 4. Committed pieces never change: each is checked against the plan of its own
//!    window, which is within the tolerance of the path from its start to the cut, and
//!    every later window starts exactly where it ends. What a window cannot know (the
//!    elements after it) only bounds its speeds through the caps, as without a grid.
//! 5. The last window (the contour's end) is resampled unscaled too: its total is not
//!    whole quanta, so its last grid interval ends at the next whole quantum, and the
//!    reference motion holds the end point, at rest, for the rest of it: that part of
//!    the deviation is measured exactly too (the reference is a constant there).
//!
//! The pieces of a streamed contour differ from those of the contour planned whole: the
//! whole contour is scaled uniformly to whole quanta and takes the shortest of its
//! shares, or the stretched grid, which need its total. A window that converges at no
//! share holds the rest of the contour to its end (the whole contour, as above, where
//! nothing is out yet). Dense polylines under acceleration limits (lines shorter than
//! the stopping distance) find no cut and are held whole.
//!
//! Hermite resampling can ask more acceleration than the plan: where a short pulse of
//! acceleration (a blend of 0.8 ms) lies near an interval's end its end acceleration
//! reaches 4/3 of the pulse's. A plan at 0.75 of the acceleration limits absorbs that
//! and rarely needs a repair; one at 1.0 keeps full acceleration where few pulses fall
//! badly; 0.6 covers splines, whose interpolation adds more.

mod curve;
mod knots;
mod piece;
mod pieces;
mod resample;
mod transition;

use super::PlanError;
use crate::axis::Axis;
use crate::limits::AxisLimits;
use crate::plan::quantize::Quantum;
use crate::program::{PvtContour, SegmentRef};
use crate::toolpath::Contour;
use std::collections::BTreeMap;
use std::ops::{Deref, DerefMut};

use crate::toolpath::Element;
use curve::Curve;
use knots::{KnotStorage, Knots, Start};

/// Largest angle between two elements' tangents that is passed at the feed when no
/// acceleration limits are given (2°); a sharper corner is an exact stop.
pub const TANGENT_ANGLE: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// Share of an axis' acceleration a piece's speed cap leaves to the centripetal part; the
/// rest is for speeding up and slowing down along the path.
const NORMAL_SHARE: f64 = 0.75;

/// Share of each limit the planner plans to: the rest absorbs the rounding of peaks
/// that a controller (or `check`) computes from the written positions of very short
/// pieces, where 6·Δp/T² and the velocity terms nearly cancel.
const PLAN_SHARE: f64 = 1.0 - 1e-5;

/// Most rounds of splitting pieces and lowering speeds before the planner gives up.
const MAX_ROUNDS: usize = 400;

/// What the path planner must honour.
#[derive(Debug, Clone, PartialEq)]
pub struct PathOptions {
    /// Path tolerance: the farthest the motion may be from the programmed geometry.
    pub tolerance: f64,
    /// Corner tolerance: how far a blend between two lines may round their corner
    /// (`None`: the path tolerance). With it, corners blend without a machine file too,
    /// at the speed the limits (if any) allow.
    pub corner_tolerance: Option<f64>,
    /// Per-axis limits; an axis not listed (or a limit left out) is not limited.
    pub limits: BTreeMap<Axis, AxisLimits>,
    /// Time grid of the piece times (`--quantize`), if any.
    pub quantum: Option<Quantum>,
    /// Servo period, seconds: with a jerk limit `J`, the acceleration step at a knot is
    /// bounded by `J·servo_period` on each axis (see "Jerk").
    pub servo_period: f64,
    /// The resolution `r` the positions are written with, program units (0: exactly).
    /// Each written position is then within `r/2` of the planned one, which moves the
    /// acceleration step a controller computes at a knot between pieces of `T_L` and
    /// `T_R` seconds by up to `6·r·(1/T_L² + 1/T_R²)` (and a step against rest by up to
    /// `6·r/T²`); under a jerk limit and on a quantum grid the planner keeps the planned
    /// step that far inside the bound, for pieces of at least one quantum. Without a grid
    /// it is not applied: a piece may be microseconds long, and a controller that takes
    /// whole quanta (PMAC) needs `--quantize` anyway.
    pub position_resolution: f64,
}

/// What the path planner achieved on a contour.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathReport {
    /// The largest per-piece error bound, program units.
    pub error_bound: f64,
    /// Largest relative change of the mid-piece speed that the quantum grid made.
    pub speed_change: f64,
}

/// A point or vector on the projected axes, held inline: the planner makes several for
/// every piece of every round, and a heap allocation each was about a third of a
/// compile's instructions. The axes are distinct, so there are at most
/// [`AXIS_COUNT`](crate::axis::AXIS_COUNT) of them.
#[derive(Clone, Copy)]
pub(super) struct Vector {
    values: [f64; crate::axis::AXIS_COUNT],
    len: usize,
}

impl Vector {
    /// `len` zeros (at most [`AXIS_COUNT`](crate::axis::AXIS_COUNT)).
    #[inline]
    pub fn zeros(len: usize) -> Vector {
        debug_assert!(len <= crate::axis::AXIS_COUNT, "{len} axes");
        Vector {
            values: [0.0; crate::axis::AXIS_COUNT],
            len: len.min(crate::axis::AXIS_COUNT),
        }
    }

    /// `f(0), …, f(len − 1)`, in that order (inlined: the planner makes several for
    /// every element, each a loop of a few axes).
    #[inline]
    pub fn from_fn(len: usize, mut f: impl FnMut(usize) -> f64) -> Vector {
        debug_assert!(len <= crate::axis::AXIS_COUNT, "{len} axes");
        let len = len.min(crate::axis::AXIS_COUNT);
        // A whole array of values, not one slot written at a time: the vector is then
        // made in registers where it is moved, not written and read back at once (a
        // wide read of narrow writes stalls the store buffer).
        Vector {
            values: std::array::from_fn(|i| if i < len { f(i) } else { 0.0 }),
            len,
        }
    }

    /// The values of `values` (at most [`AXIS_COUNT`](crate::axis::AXIS_COUNT)).
    #[inline]
    pub fn from_slice(values: &[f64]) -> Vector {
        Vector::from_fn(values.len(), |i| values[i])
    }
}

impl Deref for Vector {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.values[..self.len]
    }
}

impl DerefMut for Vector {
    fn deref_mut(&mut self) -> &mut [f64] {
        &mut self.values[..self.len]
    }
}

impl<'a> IntoIterator for &'a Vector {
    type Item = &'a f64;
    type IntoIter = std::slice::Iter<'a, f64>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl PartialEq for Vector {
    fn eq(&self, other: &Vector) -> bool {
        **self == **other
    }
}

impl std::fmt::Debug for Vector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

/// Per projected axis: velocity, acceleration and jerk limits (infinite where none).
#[derive(Debug, Clone)]
pub(super) struct AxisBounds {
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
    /// Bounds each piece's own (constant) jerk, `6·a₃` of its cubic.
    pub jerk: Vec<f64>,
    /// Bounds the step of the acceleration at a knot: `jerk·servo_period`.
    pub step: Vec<f64>,
    /// The servo period the steps are bounded over, seconds.
    pub servo_period: f64,
    /// The resolution positions are written with ([`PathOptions::position_resolution`])
    /// when piece times are on a grid, else 0 (see there).
    pub resolution: f64,
    /// The grid's quantum, seconds (0 without one): no piece on the grid is shorter.
    pub quantum: f64,
    /// No axis has a velocity or an acceleration limit: every speed cap is the feed and
    /// the tangential acceleration is unbounded (asked once, not per piece; a copy whose
    /// limits are scaled by positive shares keeps it, as infinite limits stay infinite).
    pub free: bool,
}

impl AxisBounds {
    fn new(axes: &[Axis], options: &PathOptions) -> AxisBounds {
        let (limits, servo_period) = (&options.limits, options.servo_period);
        let get = |f: fn(&AxisLimits) -> Option<f64>| -> Vec<f64> {
            axes.iter()
                .map(|a| {
                    limits
                        .get(a)
                        .and_then(f)
                        .map_or(f64::INFINITY, |l| l * PLAN_SHARE)
                })
                .collect()
        };
        let jerk = get(|l| l.jerk);
        let (velocity, acceleration) = (get(|l| l.velocity), get(|l| l.acceleration));
        let free = velocity
            .iter()
            .chain(&acceleration)
            .all(|&l| l == f64::INFINITY);
        AxisBounds {
            free,
            velocity,
            acceleration,
            step: jerk.iter().map(|j| j * servo_period).collect(),
            jerk,
            servo_period,
            resolution: options.quantum.map_or(0.0, |_| options.position_resolution),
            quantum: options.quantum.map_or(0.0, |q| q.seconds),
        }
    }

    /// True when some axis has a velocity or an acceleration limit: without one, no
    /// axis caps a junction's speed (every quotient of [`knots`]' caps is infinite).
    fn limits_speed(&self) -> bool {
        self.velocity
            .iter()
            .chain(&self.acceleration)
            .any(|&l| l != f64::INFINITY)
    }

    fn accelerates(&self) -> bool {
        self.acceleration.iter().any(|a| a.is_finite())
    }

    /// True when some axis has a jerk limit: speed changes are S-curves and the
    /// acceleration steps at knots are bounded (see "Jerk").
    pub fn jerk_mode(&self) -> bool {
        self.jerk.iter().any(|j| j.is_finite())
    }
}

/// Most elements the planner holds at once: the window is planned and emitted up to a
/// cut when it is full (see [`PathStream`]).
pub const WINDOW_ELEMENTS: usize = 1024;

/// Under a jerk limit a window with no cut (see "Windows under a jerk limit") is planned
/// again at twice its size up to this many times the stream's window ([`WINDOW_ELEMENTS`]
/// by default); beyond, it is cut where the closed-form stop allows, slower there than
/// the whole contour.
pub const JERK_WINDOW_GROWTH: usize = 8;

/// Without a grid or a jerk limit, the most pieces a window's plan is meant to hold: a
/// window whose plan made more is followed by one of fewer elements, in proportion (see
/// [`PathStream`]), so that elements that become many pieces each (the arcs of a pocket
/// at a fine tolerance) do not multiply the memory a window takes.
pub const WINDOW_PIECES: usize = 1024;

/// The path planner on a stream of elements, in bounded memory.
///
/// Elements are held in a window of at most [`WINDOW_ELEMENTS`]. When it is full, the
/// window is planned as if the contour stopped at its end, and the pieces up to a cut are
/// emitted: the last knot with at least the stopping distance (the highest feed braked at
/// the least tangential acceleration the limits leave) after it, or, when the window is
/// shorter than that, the knot halfway. A knot's speed never depends on anything beyond
/// its stopping distance, so the emitted pieces are those the whole contour would have
/// had; with a window shorter than the stopping distance they are slower, never wrong.
/// The window then starts at the cut with that knot's speed fixed. Without a grid or a
/// jerk limit the window is bounded by its pieces too: the first holds an eighth of
/// the window's elements, and each next one `E·WINDOW_PIECES/P` elements, where the last
/// plan made `P` pieces of `E` elements, within an eighth of the window and the window
/// ([`WINDOW_PIECES`]), and only where its known path is at least four stopping
/// distances (else at the window's full size). Where each window is longer than the
/// stopping distance, the emitted pieces do not depend on where the windows end. (On a
/// grid they do, and the window stays [`WINDOW_ELEMENTS`]: a window resampled through
/// an exact stop passes it at a few µm/s, one cut there starts at rest.) With a quantum the
/// window is cut at a grid time and resampled (see "Streaming on a grid" above); under a
/// jerk limit the cut is at or before the stop horizon, across any number of elements,
/// and a window without one grows (see "Windows under a jerk limit").
#[derive(Debug)]
pub struct PathStream {
    axes: Vec<Axis>,
    options: PathOptions,
    bounds: AxisBounds,
    curves: Vec<Curve>,
    /// The pieces of the window's last round and its knots' vectors, kept so that the
    /// next window's rounds reuse their storage rather than allocate it again.
    pieces: piece::Pieces,
    knot_storage: KnotStorage,
    /// The same for the windows on a grid, with the resampling's own vectors.
    grid_scratch: resample::Scratch,
    window: usize,
    /// The elements at which the window is planned: the window, or fewer where its
    /// pieces bound it (see [`WINDOW_PIECES`]).
    fill: usize,
    start: Start,
    report: PathReport,
    /// Pieces of this contour already went out through the grid's windows (see
    /// "Streaming on a grid"): its last window keeps its start.
    streamed: bool,
    /// The contour is held whole from here on: where a window on the grid did not
    /// converge or, before any went out, had no knot to cut at.
    hold: bool,
    /// On a grid, the window size at which a window with no knot to cut at is planned
    /// again: twice its size, so that a contour with no such knot costs a few plans of
    /// its length in all, not one per element.
    retry_at: usize,
    /// On a grid, the share of [`resample::Shares`] the last window converged at: the
    /// next window's tries start there (see "Streaming on a grid").
    grid_share: usize,
}

impl PathStream {
    /// A contour on `axes`, starting at rest.
    pub fn new(axes: &[Axis], options: &PathOptions) -> PathStream {
        PathStream::with_window(axes, options, WINDOW_ELEMENTS)
    }

    /// As [`PathStream::new`] with a window of `window` elements (at least 2).
    pub fn with_window(axes: &[Axis], options: &PathOptions, window: usize) -> PathStream {
        let window = window.max(2);
        let bounds = AxisBounds::new(axes, options);
        let fill = if options.quantum.is_none() && !bounds.jerk_mode() {
            least_fill(window)
        } else {
            window
        };
        PathStream {
            window,
            fill,
            axes: axes.to_vec(),
            bounds,
            options: options.clone(),
            curves: Vec::new(),
            pieces: piece::Pieces::default(),
            knot_storage: KnotStorage::default(),
            grid_scratch: resample::Scratch::default(),
            start: Start {
                param: 0.0,
                speed: 0.0,
                junction: None,
            },
            report: PathReport::default(),
            streamed: false,
            hold: false,
            retry_at: 0,
            grid_share: 0,
        }
    }

    /// Adds the next element; emits pieces when the window is full.
    pub fn push(
        &mut self,
        element: &Element,
        emit: &mut dyn FnMut(&SegmentRef<'_>),
    ) -> Result<(), PlanError> {
        if self.axes.len() > crate::axis::AXIS_COUNT {
            // An axis given twice: a curve holds at most one value per axis.
            return Err(PlanError::UnsupportedOption {
                planner: "path",
                option: "an axis twice",
            });
        }
        check_element(element)?;
        Curve::push_new(element, &self.axes, &mut self.curves);
        let whole = self.hold;
        let full = self.curves.len() >= self.window.max(self.retry_at);
        let filled = |s: &Self| s.curves.len() >= s.fill.max(s.retry_at);
        if !whole && !full && filled(self) && !self.room_for_a_cut() {
            // Too short for a cut with a stop after it: planned at the full window.
            self.fill = self.window;
        }
        if !whole && (full || filled(self)) {
            if self.options.quantum.is_some() {
                self.stream_on_grid(false, emit)?;
            } else {
                self.plan(false, emit)?;
            }
        }
        Ok(())
    }

    /// Ends the contour at rest: emits every remaining piece and returns the report.
    pub fn finish(
        mut self,
        emit: &mut dyn FnMut(&SegmentRef<'_>),
    ) -> Result<PathReport, PlanError> {
        if self.curves.is_empty() {
        } else if self.streamed {
            self.stream_on_grid(true, emit)?;
        } else {
            self.plan(true, emit)?;
        }
        Ok(self.report)
    }

    /// Plans the window and emits up to the cut (all of it at the contour's end).
    fn plan(&mut self, last: bool, emit: &mut dyn FnMut(&SegmentRef<'_>)) -> Result<(), PlanError> {
        let (curves, bounds, tolerance) = (&self.curves, &self.bounds, self.options.tolerance);
        let not_met = PlanError::PathNotMet {
            line: curves[0].line,
        };
        let least = self.least_acceleration();
        let corner = self.options.corner_tolerance;
        let narrow = self.options.quantum.is_some();
        let storage = std::mem::take(&mut self.knot_storage);
        let mut knots = Knots::new(
            curves,
            bounds,
            tolerance,
            corner,
            &self.start,
            narrow,
            storage,
        );
        if bounds.jerk_mode() {
            knots.min_cruise = self.options.quantum.map_or(0.0, |q| 3.0 * q.seconds);
        }
        if !last && !bounds.jerk_mode() {
            knots.cap_for_window(curves, least);
        }
        // The pieces' storage of the last window, reused by every round of this one.
        let mut pieces = std::mem::take(&mut self.pieces);
        // Off a grid, where the tolerance is the only repair, the window's pieces are
        // written from their knots and bounds, never made (see `Knots::emit_ends`).
        let ends_only = self.options.quantum.is_none() && knots.tolerance_alone_repairs(bounds);
        let settle = |knots: &mut Knots, pieces: &mut piece::Pieces| match ends_only {
            true => settle_bounds(knots, curves, bounds, tolerance),
            false => settle_into(knots, curves, bounds, tolerance, pieces),
        };
        if !settle(&mut knots, &mut pieces) {
            return Err(not_met);
        }
        // Without a trapezoid knot the knots and caps are those just settled: a second
        // settle would make the same pieces.
        if knots.add_trapezoids(curves, bounds) {
            if !last && !bounds.jerk_mode() {
                knots.cap_for_window(curves, least);
            }
            if !settle(&mut knots, &mut pieces) {
                return Err(not_met);
            }
        }
        if let Some(quantum) = self.options.quantum {
            // On a grid a window is planned here at the contour's end only (streamed
            // windows are [`PathStream::stream_on_grid`]'s).
            debug_assert!(last, "a window on a grid is streamed");
            return self.emit_on_grid(knots, pieces, quantum, emit);
        }
        let count = if last {
            knots.knots.len() - 1
        } else {
            let cut = if bounds.jerk_mode() {
                jerk_cut(&mut knots, curves, &pieces, bounds, self.may_grow())
            } else {
                knots.cut(curves, self.stopping_distance())
            };
            match cut {
                Some(k) => k,
                None => {
                    if bounds.jerk_mode() {
                        // No stop on known path from the highest feed yet: planned
                        // again at twice the size (see "Windows under a jerk limit").
                        self.retry_at = 2 * self.curves.len();
                    }
                    self.pieces = pieces;
                    self.knot_storage = knots.into_storage();
                    return Ok(());
                }
            }
        };
        let (worst, planned) = if ends_only {
            knots.emit_ends(curves, count, emit);
            let errors = knots.scratch.errors.iter().copied();
            (
                worst_before(errors.enumerate(), count),
                knots.knots.len() - 1,
            )
        } else {
            knots.emit(curves, &pieces, count, emit);
            (worst_before(pieces.knots_and_errors(), count), pieces.len())
        };
        self.report.error_bound = self.report.error_bound.max(worst);
        if !last && !bounds.jerk_mode() && self.options.quantum.is_none() {
            let per_piece = self.curves.len() * WINDOW_PIECES / planned.max(1);
            self.fill = per_piece.clamp(least_fill(self.window), self.window);
        }
        self.pieces = pieces;
        if !last {
            let (element, start) = knots.start_after(count);
            self.retry_at = self.next_size();
            self.curves.drain(..element);
            self.start = start;
        }
        self.knot_storage = knots.into_storage();
        Ok(())
    }

    /// Plans the window on the grid of the stream's quantum and emits it up to a grid
    /// knot (all of it at the contour's end), as "Streaming on a grid" describes. A
    /// window that does not converge holds the contour from there on, to its end.
    fn stream_on_grid(
        &mut self,
        last: bool,
        emit: &mut dyn FnMut(&SegmentRef<'_>),
    ) -> Result<(), PlanError> {
        let Some(quantum) = self.options.quantum else {
            return self.plan(last, emit);
        };
        let grow = self.bounds.jerk_mode() && self.may_grow();
        let window = grid_window(
            &self.curves,
            &self.bounds,
            &self.options,
            &self.start,
            quantum,
            (last, grow, self.grid_share),
            &mut self.grid_scratch,
        );
        let w = match window {
            Window::Planned(w) => w,
            // Nothing out yet: the contour is held whole (planned as any at its end).
            Window::NoCut if !self.streamed && !grow => {
                self.hold = true;
                return Ok(());
            }
            Window::NoCut => {
                self.retry_at = 2 * self.curves.len();
                return Ok(());
            }
            Window::NotMet if last => {
                return Err(PlanError::PathNotMet {
                    line: self.curves[0].line,
                })
            }
            // Held to the contour's end: planned whole there when nothing is out yet,
            // else as the last window.
            Window::NotMet => {
                self.hold = true;
                return Ok(());
            }
        };
        let worst = w.pieces.errors().fold(0.0, f64::max);
        self.report.error_bound = self.report.error_bound.max(worst);
        self.report.speed_change = self.report.speed_change.max(w.speed_change);
        w.pieces.emit(&w.knots, &self.curves, w.count, emit);
        self.streamed = true;
        self.grid_share = w.share;
        if !last {
            let (element, start) = w.knots.start_after(w.count);
            self.retry_at = self.next_size();
            self.curves.drain(..element);
            self.start = start;
        }
        self.grid_scratch.give_back(w.knots, w.pieces);
        Ok(())
    }

    /// The whole contour's settled `pieces` of `knots` on the grid of `quantum`
    /// ([`PathStream::on_quantum_grid`]), emitted, with the report's error bound and
    /// speed change; the storage of the knots and pieces is kept for the next contour.
    fn emit_on_grid(
        &mut self,
        mut knots: Knots,
        pieces: piece::Pieces,
        quantum: Quantum,
        emit: &mut dyn FnMut(&SegmentRef<'_>),
    ) -> Result<(), PlanError> {
        let (change, chosen) = self.on_quantum_grid(&mut knots, pieces, quantum)?;
        self.report.speed_change = self.report.speed_change.max(change);
        let count = knots.knots.len() - 1;
        let worst = match &chosen {
            OnQuantumGrid::Stretched(pieces) => worst_before(pieces.knots_and_errors(), count),
            OnQuantumGrid::Resampled(pieces) => pieces.worst_before(count),
        };
        self.report.error_bound = self.report.error_bound.max(worst);
        match chosen {
            OnQuantumGrid::Stretched(pieces) => {
                knots.emit(&self.curves, &pieces, count, emit);
                self.pieces = pieces;
                self.knot_storage = knots.into_storage();
            }
            OnQuantumGrid::Resampled(pieces) => {
                pieces.emit(&knots, &self.curves, count, emit);
                self.grid_scratch.give_back(knots, pieces);
            }
        }
        Ok(())
    }

    /// The settled `pieces` of `knots` on the grid of `quantum` (see "Quantization"):
    /// resampled, or stretched piece by piece, whichever is shorter by half a quantum
    /// (the stretched one on a tie). Under a jerk limit the resampled grid is tried first
    /// and the stretched one only where it fails. Returns the speed change and the pieces;
    /// `knots` become those of the chosen plan. The resampling's plans fill the storage
    /// of the stream's grid windows.
    fn on_quantum_grid(
        &mut self,
        knots: &mut Knots,
        pieces: piece::Pieces,
        quantum: Quantum,
    ) -> Result<(f64, OnQuantumGrid), PlanError> {
        let (curves, bounds, tolerance) = (&self.curves, &self.bounds, self.options.tolerance);
        let not_met = PlanError::PathNotMet {
            line: curves[0].line,
        };
        let scratch = &mut self.grid_scratch;
        let (options, start) = (&self.options, &self.start);
        let mut resample = |bar| {
            let r = resample_contour(curves, bounds, options, start, quantum, bar, scratch);
            r.map(|(k, r)| (k, r.speed_change, OnQuantumGrid::Resampled(r.pieces)))
        };
        if bounds.jerk_mode() {
            if let Some((k, change, r)) = resample(f64::INFINITY) {
                *knots = k;
                return Ok((change, r));
            }
        }
        // The stretched grid's pieces and speed change (its plan dropped before the
        // second one is made).
        let grid = on_grid(knots, curves, bounds, tolerance, quantum, pieces).map(|g| {
            (
                pieces::mid_speed_change(&g.planned, &g.grid.pieces),
                g.grid.pieces,
            )
        });
        if bounds.jerk_mode() {
            return grid
                .map(|(change, g)| (change, OnQuantumGrid::Stretched(g)))
                .ok_or(not_met);
        }
        // The resampled grid where it is faster by at least half a quantum (both
        // totals are whole quanta), else the stretched one.
        let bar = grid.as_ref().map_or(f64::INFINITY, |(_, g)| {
            g.iter().map(|p| p.duration).sum::<f64>()
        });
        match (resample(bar), grid) {
            (Some((k, change, r)), _) => {
                *knots = k;
                Ok((change, r))
            }
            (None, Some((change, g))) => Ok((change, OnQuantumGrid::Stretched(g))),
            (None, None) => Err(not_met),
        }
    }

    /// The size the window after a cut is planned at: under a jerk limit the size this
    /// one had (grown where it had no cut), so that the next, which holds all of this
    /// one's known path after the cut, has at least that room to bring its fixed start to
    /// rest; without, the stream's window.
    fn next_size(&self) -> usize {
        if self.bounds.jerk_mode() {
            self.curves.len()
        } else {
            0
        }
    }

    /// Under a jerk limit, whether a window with no cut may be planned again at twice
    /// its size: below [`JERK_WINDOW_GROWTH`] windows.
    fn may_grow(&self) -> bool {
        self.curves.len() < JERK_WINDOW_GROWTH * self.window
    }

    /// Whether a window bounded by its pieces ([`WINDOW_PIECES`]) is long enough to be
    /// planned now: its known path (up to its last element) is at least four stopping
    /// distances, room for a cut with the stopping distance after it (else the window
    /// is planned at its full size).
    fn room_for_a_cut(&self) -> bool {
        let Some((_, known)) = self.curves.split_last() else {
            return false;
        };
        let consumed = known
            .first()
            .map_or(0.0, |c| c.length(0.0, self.start.param));
        let length: f64 = known.iter().map(|c| c.length(0.0, c.span)).sum();
        length - consumed >= 4.0 * self.stopping_distance()
    }

    /// The least tangential acceleration any piece has (see [`least_acceleration`]).
    fn least_acceleration(&self) -> f64 {
        least_acceleration(&self.bounds)
    }

    /// How far the highest feed of the window needs to come to rest at the least
    /// tangential acceleration (0 without acceleration limits).
    fn stopping_distance(&self) -> f64 {
        stopping_distance(&self.curves, self.least_acceleration())
    }
}

/// Plans one contour on `axes` so that its motion follows the elements within
/// `options.tolerance` and within every axis limit: [`PathStream`] fed the whole contour.
pub fn plan_path(
    contour: &Contour,
    axes: &[Axis],
    options: &PathOptions,
) -> Result<(PvtContour, PathReport), PlanError> {
    let first = contour
        .elements
        .first()
        .map(|e| crate::discretize::project(&e.start, axes))
        .unwrap_or_else(|| vec![0.0; axes.len()]);
    let mut out = PvtContour::new(contour.motion, first);
    let mut emit = |seg: &SegmentRef<'_>| out.push(seg.end, seg.velocity, seg.duration, seg.line);
    let mut stream = PathStream::new(axes, options);
    for element in &contour.elements {
        stream.push(element, &mut emit)?;
    }
    let report = stream.finish(&mut emit)?;
    Ok((out, report))
}

/// Plans speeds, splits pieces over the tolerance and slows pieces over a limit until
/// none is, into `pieces`, whose storage every round reuses (and the next window, where
/// the stream keeps it); false after [`MAX_ROUNDS`]. (The pieces follow from the
/// knots alone: `pieces` may hold anything before.) Where the tolerance is the only
/// repair, the rounds make the pieces' error bounds alone ([`settle_by_errors`]).
fn settle_into(
    knots: &mut Knots,
    curves: &[Curve],
    bounds: &AxisBounds,
    tolerance: f64,
    pieces: &mut piece::Pieces,
) -> bool {
    knots.forget_pieces();
    if knots.tolerance_alone_repairs(bounds) {
        return settle_by_errors(knots, curves, bounds, tolerance, pieces);
    }
    settle_by_pieces(knots, curves, bounds, tolerance, pieces)
}

/// [`settle_into`]'s rounds on whole pieces: every repair reads them.
fn settle_by_pieces(
    knots: &mut Knots,
    curves: &[Curve],
    bounds: &AxisBounds,
    tolerance: f64,
    pieces: &mut piece::Pieces,
) -> bool {
    for _ in 0..MAX_ROUNDS {
        knots.plan_speeds(curves, bounds);
        knots.pieces_again(curves, bounds, pieces);
        if knots.split_over(pieces, tolerance)
            || knots.slow_over(pieces, bounds)
            || knots.step_over(pieces, bounds)
        {
            continue;
        }
        return true;
    }
    false
}

/// [`settle_into`]'s rounds where the tolerance is the only repair
/// ([`Knots::tolerance_alone_repairs`]): [`settle_bounds`], and the pieces made once,
/// from the settled knots, each taking the time and bound its last round made
/// ([`Knots::pieces_from_bounds`]). A piece follows from its knots alone, so they are
/// those of [`settle_by_pieces`], whose rounds split the same knots (its other repairs
/// change nothing here), without a piece made and then split.
fn settle_by_errors(
    knots: &mut Knots,
    curves: &[Curve],
    bounds: &AxisBounds,
    tolerance: f64,
    pieces: &mut piece::Pieces,
) -> bool {
    let settled = settle_bounds(knots, curves, bounds, tolerance);
    if settled {
        knots.pieces_from_bounds(curves, bounds, pieces);
    }
    settled
}

/// The rounds where the tolerance is the only repair, which make no piece: a round
/// splits by the pieces' times and error bounds alone ([`Knots::errors_again`]), which
/// it leaves in the knots' scratch for every piece of the settled knots; false after
/// [`MAX_ROUNDS`]. Where every knot's speed is local ([`Knots::speeds_are_local`]:
/// always without limits) a round makes again only what the last changed
/// ([`Knots::settle_locally`]), up to a way that is not.
fn settle_bounds(knots: &mut Knots, curves: &[Curve], bounds: &AxisBounds, tolerance: f64) -> bool {
    knots.forget_pieces();
    knots.plan_speeds(curves, bounds);
    let mut first = 0;
    if knots.speeds_are_local() {
        match knots.settle_locally(curves, bounds, tolerance, MAX_ROUNDS) {
            None => return true,
            Some(round) => first = round,
        }
        knots.forget_pieces();
        knots.plan_speeds(curves, bounds);
    }
    settle_from_round(knots, curves, bounds, tolerance, first)
}

/// [`settle_bounds`]'s whole rounds from round `first` (each visits every knot), on
/// knots whose speeds [`Knots::plan_speeds`] has just planned.
fn settle_from_round(
    knots: &mut Knots,
    curves: &[Curve],
    bounds: &AxisBounds,
    tolerance: f64,
    first: usize,
) -> bool {
    for round in first..MAX_ROUNDS {
        if round > first {
            knots.plan_speeds(curves, bounds);
        }
        knots.errors_again(curves, bounds);
        if !knots.split_over_errors(tolerance) {
            return true;
        }
    }
    false
}

/// The largest error bound of the pieces, each given as its knot and error bound in
/// order, before the first from knot `count` on: what a window emits up to its cut.
fn worst_before(pieces: impl Iterator<Item = (usize, f64)>, count: usize) -> f64 {
    pieces
        .take_while(|&(knot, _)| knot < count)
        .map(|(_, error)| error)
        .fold(0.0, f64::max)
}

/// A whole contour on the grid: its pieces stretched to whole quanta, or resampled.
enum OnQuantumGrid {
    Stretched(piece::Pieces),
    Resampled(resample::GridPieces),
}

/// The planned pieces and the same on the grid.
struct OnGrid {
    planned: piece::Pieces,
    grid: pieces::Grid,
}

/// Puts the settled `pieces` on the quantum grid; where a piece on the grid is over the
/// tolerance it is split, where it is still over a limit it is slowed, and the window
/// is settled and put on the grid again. `None` after [`MAX_ROUNDS`].
fn on_grid(
    knots: &mut Knots,
    curves: &[Curve],
    bounds: &AxisBounds,
    tolerance: f64,
    quantum: Quantum,
    mut planned: piece::Pieces,
) -> Option<OnGrid> {
    for _ in 0..MAX_ROUNDS {
        let grid = knots.on_grid(curves, bounds, &planned, quantum);
        let changed = knots.split_over(&grid.pieces, tolerance)
            || knots.slow_over(&grid.pieces, bounds)
            || knots.step_over(&grid.pieces, bounds);
        if !changed {
            return Some(OnGrid { planned, grid });
        }
        if !settle_into(knots, curves, bounds, tolerance, &mut planned) {
            return None;
        }
    }
    None
}

/// The contour planned at [`resample::RESAMPLE_SHARE`] of the tolerances and at each of
/// [`resample::ACCELERATION_SHARES`] of the acceleration limits in turn, resampled onto
/// the grid of `quantum` (see "Quantization"): the last that is shorter in total time
/// than `bar` and every one before by at least half a quantum, or `None`. The plans
/// fill `scratch`'s storage (the resampled pieces of a beaten one go back to it).
#[allow(clippy::too_many_arguments)]
fn resample_contour(
    curves: &[Curve],
    bounds: &AxisBounds,
    options: &PathOptions,
    start: &Start,
    quantum: Quantum,
    mut bar: f64,
    scratch: &mut resample::Scratch,
) -> Option<(Knots, resample::Resampled)> {
    let shares = resample::Shares::new(bounds, quantum.seconds);
    let share = shares.tolerance;
    let tolerance = share * options.tolerance;
    let corner = options.corner_tolerance.map(|c| share * c);
    let tolerances = resample::Tolerances {
        path: options.tolerance,
        corner: options.corner_tolerance.unwrap_or(options.tolerance),
    };
    let mut best: Option<(Knots, resample::Resampled)> = None;
    for try_ in shares.tries {
        let planning = try_.planning(bounds, quantum.seconds);
        let storage = std::mem::take(&mut scratch.knots);
        let mut knots = Knots::new(curves, &planning, tolerance, corner, start, false, storage);
        let mut planned = std::mem::take(&mut scratch.planned);
        let settled = settle_into(&mut knots, curves, &planning, tolerance, &mut planned)
            && (!knots.add_trapezoids(curves, &planning)
                || settle_into(&mut knots, curves, &planning, tolerance, &mut planned));
        let r = settled
            .then(|| {
                let limits = resample::Limits {
                    planning: &planning,
                    bounds,
                    tolerance,
                    tolerances,
                    rounds: try_.rounds,
                };
                resample::resample(
                    &mut knots,
                    curves,
                    &limits,
                    quantum,
                    bar,
                    &mut planned,
                    scratch,
                )
            })
            .flatten();
        scratch.planned = planned;
        match r {
            Some(r) => {
                bar = r.pieces.durations().sum();
                // The plan it beats gives its storage to the next.
                if let Some((k, beaten)) = best.replace((knots, r)) {
                    scratch.give_back(k, beaten.pieces);
                }
            }
            None => scratch.knots = knots.into_storage(),
        }
    }
    best
}

/// A window of a contour on the grid (see "Streaming on a grid").
enum Window {
    /// Its pieces up to the grid knot it is cut at.
    Planned(GridWindow),
    /// No knot to cut at yet: wait for more elements.
    NoCut,
    /// No share of the limits converged.
    NotMet,
}

/// A window's resampled pieces: those of planned knots `0..count`, ending at knot
/// `count` on the grid (at the contour's end, all of them).
struct GridWindow {
    knots: Knots,
    pieces: resample::GridPieces,
    count: usize,
    speed_change: f64,
    /// The index of the share of [`resample::Shares`] it converged at.
    share: usize,
}

/// Plans a window of a streamed contour on the grid of `quantum` (see "Streaming on a
/// grid"): the shares of [`resample::Shares`] in turn from `first` (the share the last
/// window converged at), then those before it, the first that converges; each
/// plan capped (but at the contour's end) to stop before the window's last element at the
/// least tangential acceleration of every share, cut at a grid time at or before the
/// stopping-distance cut, and resampled from the window's start without scaling. Its
/// knots, plan and resampling fill `scratch`'s storage.
fn grid_window(
    curves: &[Curve],
    bounds: &AxisBounds,
    options: &PathOptions,
    start: &Start,
    quantum: Quantum,
    (last, grow, first): (bool, bool, usize),
    scratch: &mut resample::Scratch,
) -> Window {
    let q = quantum.seconds;
    let shares = resample::Shares::new(bounds, q);
    let tolerance = shares.tolerance * options.tolerance;
    let corner = options.corner_tolerance.map(|c| shares.tolerance * c);
    let tolerances = resample::Tolerances {
        path: options.tolerance,
        corner: options.corner_tolerance.unwrap_or(options.tolerance),
    };
    let least_share = shares
        .tries
        .iter()
        .map(|t| t.acceleration)
        .fold(1.0, f64::min);
    let least = least_share * least_acceleration(bounds);
    // Under a jerk limit the next window may converge at a lower jerk share: the room
    // after a cut is for the least acceleration and jerk of every share.
    let least_jerk_share = shares.tries.iter().map(|t| t.jerk).fold(1.0, f64::min);
    let jerk = least_jerk_share * least_jerk(bounds);
    let slowest = AxisBounds {
        acceleration: bounds
            .acceleration
            .iter()
            .map(|a| a * least_share)
            .collect(),
        jerk: bounds.jerk.iter().map(|j| j * least_jerk_share).collect(),
        ..bounds.clone()
    };
    let keep = if bounds.jerk_mode() {
        let fastest = curves.iter().map(|c| c.feed).fold(0.0, f64::max);
        scurve_stop(fastest, least, jerk)
    } else {
        stopping_distance(curves, least)
    };
    let stop = |v: f64| {
        if least.is_finite() {
            v * v / (2.0 * least)
        } else {
            0.0
        }
    };
    let room = |knots: &Knots, at: usize| {
        if bounds.jerk_mode() {
            knots.room_to_slow(curves, &slowest, at, q)
        } else {
            knots.room_to_stop(curves, at, &stop)
        }
    };
    let tries = shares.tries.len();
    let first = first.min(tries - 1);
    for share in (first..tries).chain(0..first) {
        let try_ = &shares.tries[share];
        // As the whole contour's plans (see [`resample_contour`]); without a jerk limit
        // the step and jerk are infinite, at any share.
        let planning = try_.planning(bounds, q);
        let storage = std::mem::take(&mut scratch.knots);
        let mut knots = Knots::new(curves, &planning, tolerance, corner, start, false, storage);
        let mut planned = std::mem::take(&mut scratch.planned);
        if !last && !bounds.jerk_mode() {
            knots.cap_for_window(curves, least);
        }
        let settled = settle_into(&mut knots, curves, &planning, tolerance, &mut planned) && {
            // Without a trapezoid knot a second settle would make the same pieces.
            !knots.add_trapezoids(curves, &planning) || {
                if !last && !bounds.jerk_mode() {
                    knots.cap_for_window(curves, least);
                }
                settle_into(&mut knots, curves, &planning, tolerance, &mut planned)
            }
        };
        if !settled {
            scratch.knots = knots.into_storage();
            scratch.planned = planned;
            continue;
        }
        for _ in 0..try_.rounds {
            let (count, inserted) = if last {
                (knots.knots.len() - 1, false)
            } else {
                let k = if bounds.jerk_mode() {
                    jerk_horizon(&mut knots, curves, &slowest, grow)
                } else {
                    knots.cut(curves, keep)
                };
                let Some(k) = k else {
                    scratch.knots = knots.into_storage();
                    scratch.planned = planned;
                    return Window::NoCut;
                };
                match grid_cut(&mut knots, curves, &planning, &mut planned, (k, &room), q) {
                    Some(cut) => cut,
                    None => {
                        scratch.knots = knots.into_storage();
                        scratch.planned = planned;
                        return Window::NoCut;
                    }
                }
            };
            // The pieces up to the cut, those resampled: any after it are made again
            // before the plan is read again (`settle_into` takes pieces holding anything).
            planned.truncate(planned.before_knot(count));
            match resample::resample_once(&knots, bounds, tolerances, q, &planned, false, scratch) {
                Ok(r) => {
                    scratch.planned = planned;
                    return Window::Planned(GridWindow {
                        knots,
                        pieces: r.pieces,
                        count,
                        speed_change: r.speed_change,
                        share,
                    });
                }
                Err(slow) => {
                    if inserted {
                        knots.remove(count);
                    }
                    for (range, factor) in slow {
                        knots.slow_knots(range, factor);
                    }
                    if !settle_into(&mut knots, curves, &planning, tolerance, &mut planned) {
                        break;
                    }
                }
            }
        }
        scratch.knots = knots.into_storage();
        scratch.planned = planned;
    }
    Window::NotMet
}

/// Whether a window may be cut at a knot: room after it for the next window's fixed
/// start (see [`grid_cut`]).
type RoomAfterCut<'a> = dyn Fn(&Knots, usize) -> bool + 'a;

/// Where a window of a streamed contour on the grid ends: the last grid time at or before
/// knot `k` ([`Knots::cut`]'s, or under a jerk limit [`jerk_horizon`]'s) that is a cuttable
/// knot's time or inside a piece that follows one element at speed, where a knot is
/// inserted (and `planned` made again up to it, with no piece after it), with room to
/// stop on its line at `least` ([`Knots::room_to_stop`]) and, under a jerk limit, time
/// left in the piece to turn onto the corner it ends at ([`Knots::turn_time`]); without a jerk limit, where
/// there is none, the last knot at rest up to `k`. The knot's index (the number of pieces before it) and whether it
/// was inserted.
fn grid_cut(
    knots: &mut Knots,
    curves: &[Curve],
    planning: &AxisBounds,
    planned: &mut piece::Pieces,
    (k, room): (usize, &RoomAfterCut<'_>),
    q: f64,
) -> Option<(usize, bool)> {
    // The pieces before knot `k` (under a jerk limit an S-curve is several parts).
    let before = planned.before_knot(k);
    let mut starts = Vec::with_capacity(before + 1);
    let mut t = 0.0;
    for duration in planned.durations().take(before) {
        starts.push(t);
        t += duration;
    }
    let slack = 1e-9 * q;
    let mut g = quanta_count(t, q);
    // A knot inserted inside a piece for an earlier grid time whose room failed: moved
    // to the next time inside a piece (the grid times fall, and so do their pieces),
    // removed before any other use of the knots, whose indices it shifts.
    let mut tried: Option<usize> = None;
    while g >= 1.0 {
        let tau = crate::plan::quantize::quanta_time(g, q);
        g -= 1.0;
        let piece_index = starts.partition_point(|&s| s <= tau + slack) - 1;
        let (piece, u) = (planned.at(piece_index), tau - starts[piece_index]);
        // A corner blend's or curvature transition's two parts meet inside it.
        let same_knot = |i: Option<usize>| {
            i.and_then(|i| planned.get(i))
                .is_some_and(|p| p.knot == piece.knot)
        };
        let at_knot = |end: usize| {
            let inside = match end {
                0 => same_knot(piece_index.checked_sub(1)),
                _ => same_knot(Some(piece_index + 1)),
            };
            !inside && piece.part.is_none_or(|p| p.at_knot[end])
        };
        if u <= slack || piece.duration - u <= slack {
            if let Some(at) = tried.take() {
                knots.remove(at);
            }
            let (end, at) = if u <= slack {
                (0, piece.knot)
            } else {
                (1, piece.knot + 1)
            };
            if at_knot(end) && at <= k && knots.cuttable(curves, at) && room(knots, at) {
                return Some((at, false));
            }
            continue;
        }
        let i = piece.knot;
        if knots.knots[i].blend.is_some() || piece.at_rest() || piece.part.is_some() {
            // Every grid time inside the piece is refused alike: on to its start.
            g = g.min(quanta_count(starts[piece_index], q) + 1.0);
            continue;
        }
        // Without a jerk limit the room is on a line only: a knot inside a piece of any
        // other curve would be inserted and removed again.
        if !planning.jerk_mode() && !curves[knots.knots[i].after.element].is_line() {
            // The piece's other grid times are inside it too: on to its start.
            g = g.min(quanta_count(starts[piece_index], q) + 1.0);
            continue;
        }
        if planning.jerk_mode() && piece.duration - u < knots.turn_time(i + 1, least_jerk(planning))
        {
            // Too little of the piece left after it to turn onto the corner it ends at:
            // on to an earlier grid time.
            continue;
        }
        let at = match tried.take() {
            Some(from) if from > i => knots.move_inside(curves, from, i, u, piece.duration),
            Some(from) => {
                knots.remove(from);
                knots.insert_inside(curves, i, u, piece.duration)
            }
            None => knots.insert_inside(curves, i, u, piece.duration),
        };
        if !room(knots, at) {
            tried = Some(at);
            continue;
        }
        // The pieces before knot `i` are those of the knots before it, unchanged: only
        // the piece from `i` to the new knot is made (the window ends there).
        knots.pieces_up_to(curves, planning, i..at, planned);
        return Some((at, true));
    }
    if let Some(at) = tried {
        knots.remove(at);
    }
    if planning.jerk_mode() {
        return None;
    }
    // No grid time to cut at: the last knot at rest (an exact stop), whose window ends
    // there and holds it to the next whole quantum, as a contour's end does.
    (1..=k)
        .rev()
        .find(|&at| knots.knots[at].speed == 0.0 && knots.cuttable(curves, at))
        .map(|at| (at, false))
}

/// The knot a window under a jerk limit is cut at or before: the last from which the
/// window's highest feed comes to rest on its known path ([`Knots::stop_horizon`]), so
/// the stop at the window's end bounds no speed up to it. `None`, so that the window
/// grows, when there is none or it lies in the window's first half (a cut there would
/// emit little of it) and `grow` allows; without `grow` (the window at its largest,
/// [`JERK_WINDOW_GROWTH`]), [`Knots::cut`]'s knot with the closed-form stop
/// [`scurve_stop`] after it: slower there than the whole contour, never wrong.
fn jerk_horizon(
    knots: &mut Knots,
    curves: &[Curve],
    bounds: &AxisBounds,
    grow: bool,
) -> Option<usize> {
    match knots.stop_horizon(curves, bounds) {
        Some(k) if !grow || 2 * k >= knots.knots.len() => Some(k),
        _ if grow => None,
        _ => {
            let fastest = curves.iter().map(|c| c.feed).fold(0.0, f64::max);
            let least = least_acceleration(bounds);
            knots.cut(curves, scurve_stop(fastest, least, least_jerk(bounds)))
        }
    }
}

/// Where a window under a jerk limit (without a grid) ends: the last knot at or before
/// [`jerk_horizon`]'s that may end a window ([`Knots::cuttable`]), whose speed the next
/// window's fixed start can bring to rest on known path ([`Knots::room_to_slow`], over
/// any number of elements), and where the piece before ends with an acceleration within
/// half the step bound on every axis: the next window's first piece starts within the
/// other half (it is checked against rest, as a contour's start is), so the step where
/// they meet is within the bound. `None` when there is no such knot.
fn jerk_cut(
    knots: &mut Knots,
    curves: &[Curve],
    pieces: &piece::Pieces,
    bounds: &AxisBounds,
    grow: bool,
) -> Option<usize> {
    let k = jerk_horizon(knots, curves, bounds, grow)?;
    (1..=k).rev().find(|&at| {
        let before = pieces.before_knot(at);
        if before == 0 || !knots.cuttable(curves, at) {
            return false;
        }
        let before = pieces.at(before - 1);
        let end = before.end_accelerations()[1];
        let within = end.iter().zip(&bounds.step).all(|(a, s)| {
            a.abs() <= 0.5 * s - 6.0 * bounds.resolution / (before.duration * before.duration)
        });
        within && knots.room_to_slow(curves, bounds, at, 0.0)
    })
}

/// The fewest elements a window bounded by its pieces holds ([`WINDOW_PIECES`]): an
/// eighth of the stream's window (at least 2).
fn least_fill(window: usize) -> usize {
    (window / 8).max(2)
}

/// The least path jerk of an S-curve anywhere on the path: a corner blend's share of the
/// least axis jerk limit (a line's and an arc's are higher); infinite without one.
fn least_jerk(bounds: &AxisBounds) -> f64 {
    let least = bounds.jerk.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    knots::BLEND_JERK_SHARE * least
}

/// A bound on the length an S-curve (tangential acceleration `a`, path jerk `j`) needs
/// from `v` to any lower speed: `v·(v/a + a/j)`. The S-curve's distance to `w < v` is
/// `(v + w)/2·(Δ/a + a/j)` with `Δ = v − w` when it reaches `a`, each factor at most
/// `v` and `v/a + a/j`; else `(v + w)·√(Δ/j) ≤ 2v·√(v/j) ≤ v·(v/a + a/j)` (the mean of
/// `v/a` and `a/j` is at least their geometric mean). The distance is not monotone in
/// `w` (slowing to `v/3` takes longer than stopping), so the bound is over every `w`.
pub(super) fn scurve_stop(v: f64, a: f64, j: f64) -> f64 {
    if !a.is_finite() {
        return 0.0;
    }
    let ramp = if j.is_finite() { a / j } else { 0.0 };
    v * (v / a + ramp)
}

/// Whole quanta in `t` seconds, rounded down (times within a billionth of a quantum of
/// a grid time count as on it).
fn quanta_count(t: f64, q: f64) -> f64 {
    (t / q + 1e-9).floor()
}

/// The least tangential acceleration any piece has: an axis' acceleration less the
/// share its speed caps leave to the centripetal part (infinite without limits).
fn least_acceleration(bounds: &AxisBounds) -> f64 {
    let least = bounds
        .acceleration
        .iter()
        .fold(f64::INFINITY, |a, &b| a.min(b));
    least * (1.0 - NORMAL_SHARE)
}

/// How far the highest feed of `curves` needs to come to rest at tangential
/// acceleration `least` (0 without acceleration limits).
fn stopping_distance(curves: &[Curve], least: f64) -> f64 {
    let fastest = curves.iter().map(|c| c.feed).fold(0.0, f64::max);
    if least.is_finite() {
        fastest * fastest / (2.0 * least)
    } else {
        0.0
    }
}

/// Refuses an element with a feed that is not positive or a coordinate that is not finite.
fn check_element(element: &Element) -> Result<(), PlanError> {
    let line = element.span.line;
    if !(element.feed.is_finite() && element.feed > 0.0) {
        return Err(PlanError::BadFeed {
            line,
            feed: element.feed,
        });
    }
    let finite = |p: &crate::axis::Position| p.iter().all(|x| x.is_finite());
    let controls_finite = match element.kind {
        crate::toolpath::ElementKind::Bezier(b) => {
            b.controls.iter().flatten().all(|x| x.is_finite())
        }
        _ => true,
    };
    if !finite(&element.start) || !finite(&element.end) || !controls_finite {
        return Err(PlanError::NonFinitePoint { line });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::Vector;

    /// More axes than there are (one given twice) is refused, not a panic.
    #[test]
    fn an_axis_twice_is_refused() {
        use crate::axis::Axis;
        use crate::toolpath::{Element, ElementKind, Span};
        let axes = [Axis::X; crate::axis::AXIS_COUNT + 1];
        let options = super::PathOptions {
            tolerance: 0.01,
            corner_tolerance: None,
            limits: Default::default(),
            quantum: None,
            servo_period: crate::defaults::SERVO_PERIOD_S,
            position_resolution: 0.0,
        };
        let mut stream = super::PathStream::new(&axes, &options);
        let mut end = [0.0; crate::axis::AXIS_COUNT];
        end[0] = 1.0;
        let element = Element {
            kind: ElementKind::Line,
            start: [0.0; crate::axis::AXIS_COUNT],
            end,
            feed: 10.0,
            span: Span::default(),
        };
        let result = stream.push(&element, &mut |_| {});
        assert!(
            matches!(
                result,
                Err(super::PlanError::UnsupportedOption {
                    planner: "path",
                    ..
                })
            ),
            "{result:?}"
        );
    }

    /// A settling whose rounds split pieces and slow knots keeps the pieces and speed-pass
    /// values of the knots a round did not change (`Knots::pieces_again`,
    /// `Knots::way_again`): its pieces are, bit for bit, those made afresh from its
    /// final knots, and it made fewer than it kept.
    #[test]
    fn a_settling_keeps_only_what_its_rounds_left_unchanged() {
        use super::knots::{KnotStorage, Knots, Start};
        use crate::axis::Axis;
        use crate::limits::AxisLimits;
        use crate::toolpath::{Arc, ArcDirection, ElementKind, Plane};
        let axes = [Axis::X, Axis::Y, Axis::Z];
        let limit = AxisLimits {
            velocity: Some(200.0),
            acceleration: Some(2000.0),
            jerk: None,
        };
        let options = test_options(None, &axes, Some(limit));
        let arc = |center: [f64; 2], direction| {
            ElementKind::Arc(Arc {
                plane: Plane::XY,
                center,
                direction,
                extra_turns: 0,
            })
        };
        // A pocket's stroke: lines and the arcs of its corners, both ways round.
        let mut elements = Vec::new();
        for row in 0..6 {
            let y = 2.0 * row as f64;
            let (from, to) = if row % 2 == 0 {
                (0.0, 10.0)
            } else {
                (10.0, 0.0)
            };
            elements.push(element(ElementKind::Line, at(from, y), at(to, y)));
            let (turn, side) = match row % 2 {
                0 => (ArcDirection::CounterClockwise, 10.0),
                _ => (ArcDirection::Clockwise, 0.0),
            };
            elements.push(element(
                arc([side, y + 1.0], turn),
                at(to, y),
                at(to, y + 2.0),
            ));
        }
        let mut curves = Vec::new();
        for e in &elements {
            super::Curve::push_new(e, &axes, &mut curves);
        }
        let bounds = super::AxisBounds::new(&axes, &options);
        let start = Start {
            param: 0.0,
            speed: 0.0,
            junction: None,
        };
        let storage = KnotStorage::default();
        let mut knots = Knots::new(&curves, &bounds, 1e-4, None, &start, false, storage);
        let first = knots.knots.len();
        let mut pieces = super::piece::Pieces::default();
        assert!(super::settle_into(
            &mut knots,
            &curves,
            &bounds,
            1e-4,
            &mut pieces
        ));
        assert!(knots.knots.len() > first, "no round split a piece");
        let mut fresh = super::piece::Pieces::default();
        knots.pieces_into(&curves, &bounds, &mut fresh);
        assert_eq!(format!("{pieces:?}"), format!("{fresh:?}"));
        // One more round by hand: the worse half of the pieces split.
        let worst = pieces.iter().map(|p| p.error).fold(0.0, f64::max);
        assert!(knots.split_over(&pieces, 0.5 * worst));
        knots.plan_speeds(&curves, &bounds);
        let made_at = knots.scratch.made_at.clone();
        let unchanged = |k: usize| {
            let (a, b) = (&knots.knots[k], &knots.knots[k + 1]);
            let i = a.last_round as usize;
            b.last_round as usize == i + 1
                && made_at[i].to_bits() == a.speed.to_bits()
                && made_at[i + 1].to_bits() == b.speed.to_bits()
        };
        let kept = (0..knots.knots.len() - 1).filter(|&k| unchanged(k)).count();
        assert!(kept > 0 && kept < knots.knots.len() - 1, "{kept} kept");
        knots.pieces_again(&curves, &bounds, &mut pieces);
        knots.pieces_into(&curves, &bounds, &mut fresh);
        assert_eq!(format!("{pieces:?}"), format!("{fresh:?}"));
    }

    /// A point in the XY plane, the other axes at 0.
    fn at(x: f64, y: f64) -> crate::axis::Position {
        let mut p = [0.0; crate::axis::AXIS_COUNT];
        (p[0], p[1]) = (x, y);
        p
    }

    /// An element of the settling's tests, at a feed of 150 units/s.
    fn element(
        kind: crate::toolpath::ElementKind,
        start: crate::axis::Position,
        end: crate::axis::Position,
    ) -> crate::toolpath::Element {
        crate::toolpath::Element {
            kind,
            start,
            end,
            feed: 150.0,
            span: crate::toolpath::Span::default(),
        }
    }

    /// Programs for the settling's tests, each with its corner tolerance: a pocket's
    /// circles with an exact stop at every step-over (whose pieces are split), and a
    /// polyline whose corners are corner blends under a corner tolerance.
    pub(super) fn rings_and_corners() -> Vec<(Vec<crate::toolpath::Element>, Option<f64>)> {
        use crate::toolpath::{Arc, ArcDirection, ElementKind, Plane};
        let half_circle = |r: f64, from: f64| {
            let kind = ElementKind::Arc(Arc {
                plane: Plane::XY,
                center: [0.0, 0.0],
                direction: ArcDirection::CounterClockwise,
                extra_turns: 0,
            });
            element(kind, at(from * r, 0.0), at(-from * r, 0.0))
        };
        let mut pocket = Vec::new();
        for ring in 1..5 {
            let r = ring as f64;
            if ring > 1 {
                pocket.push(element(ElementKind::Line, at(r - 1.0, 0.0), at(r, 0.0)));
            }
            pocket.push(half_circle(r, 1.0));
            pocket.push(half_circle(r, -1.0));
        }
        let corners = [(0.0, 0.0), (10.0, 0.0), (10.0, 5.0), (2.0, 6.0), (9.0, 9.0)];
        let polyline = corners
            .windows(2)
            .map(|w| element(ElementKind::Line, at(w[0].0, w[0].1), at(w[1].0, w[1].1)))
            .collect();
        vec![(pocket, None), (polyline, Some(0.01))]
    }

    /// The path options of [`rings_and_corners`]' tests: a tolerance of 0.1 µm, no grid,
    /// each axis limited by `limit` where one is given.
    pub(super) fn test_options(
        corner: Option<f64>,
        axes: &[crate::axis::Axis],
        limit: Option<crate::limits::AxisLimits>,
    ) -> super::PathOptions {
        super::PathOptions {
            tolerance: 1e-4,
            corner_tolerance: corner,
            limits: limit.map_or_else(Default::default, |l| axes.iter().map(|a| (*a, l)).collect()),
            quantum: None,
            servo_period: crate::defaults::SERVO_PERIOD_S,
            position_resolution: 0.0,
        }
    }

    /// Where the tolerance is the only repair, the rounds that split by the pieces'
    /// error bounds alone (`settle_by_errors`) settle the same knots and make the same
    /// pieces as the rounds on whole pieces (`settle_by_pieces`), bit for bit.
    #[test]
    fn settling_by_error_bounds_is_settling_by_pieces() {
        use super::knots::{KnotStorage, Knots, Start};
        use crate::axis::Axis;
        let axes = [Axis::X, Axis::Y, Axis::Z];
        let start = Start {
            param: 0.0,
            speed: 0.0,
            junction: None,
        };
        for (elements, corner) in rings_and_corners() {
            let options = test_options(corner, &axes, None);
            let mut curves = Vec::new();
            for e in &elements {
                super::Curve::push_new(e, &axes, &mut curves);
            }
            let bounds = super::AxisBounds::new(&axes, &options);
            let storage = KnotStorage::default;
            let knots = || Knots::new(&curves, &bounds, 1e-4, corner, &start, false, storage());
            let (mut by_errors, mut by_pieces) = (knots(), knots());
            assert!(by_errors.tolerance_alone_repairs(&bounds));
            let first = by_errors.knots.len();
            let (mut settled, mut made) = (
                super::piece::Pieces::default(),
                super::piece::Pieces::default(),
            );
            assert!(super::settle_by_errors(
                &mut by_errors,
                &curves,
                &bounds,
                1e-4,
                &mut settled
            ));
            assert!(super::settle_by_pieces(
                &mut by_pieces,
                &curves,
                &bounds,
                1e-4,
                &mut made
            ));
            if corner.is_some() {
                assert!(by_errors.knots.iter().any(|k| k.blend.is_some()));
            } else {
                assert!(by_errors.knots.len() > first, "no round split a piece");
            }
            assert_eq!(format!("{settled:?}"), format!("{made:?}"));
            assert_eq!(by_errors.settled_state(), by_pieces.settled_state());
        }
    }

    #[test]
    fn a_vector_is_its_first_len_values() {
        let v = Vector::from_fn(3, |i| i as f64 + 0.5);
        assert_eq!(&*v, &[0.5, 1.5, 2.5]);
        assert_eq!(format!("{v:?}"), "[0.5, 1.5, 2.5]");
        let mut w = Vector::zeros(3);
        assert_eq!(&*w, &[0.0; 3]);
        w.copy_from_slice(&v);
        assert_eq!(w, v);
        assert_ne!(Vector::zeros(2), Vector::zeros(3));
        assert_eq!(v.into_iter().sum::<f64>(), 4.5);
    }
}
