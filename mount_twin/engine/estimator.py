"""The live error estimate of a model of linear mounts: local errors measured on a sample of the
intervals, carried forward by the linearised dynamics (a model with non-linear mounts takes
`engine.companion`: measured on those at rtol 1e-6, this one read 0.92 of the true error on the
bolted genset at 2.8–3.3× the engine's time against the companion's 2.1×, because an engaged mount
has it check every ENGAGED_CHECK_EVERY intervals and linearise at each; checked every 8 or 32
there without linearising again, it cost 1.7–1.9× and over-read rubber hitting snubbers
17–260×; on 64 and 256 Bouc–Wen mounts, whose states pass DENSE_MAX, it read 0.27 and 0.62:
docs/scene.md "Error estimate").

The published solution's global error e obeys, interval by interval, eₙ₊₁ = Φₙ·eₙ + ℓₙ: the
error carried from before by the step map's derivative Φₙ, plus the local error ℓₙ the
interval commits (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.3, the "Lady Windermere's
fan"). The estimate follows that recursion with

- Φ ≈ exp(h·J): J = ∂f/∂y by forward differences at the twin's state over the carried states
  (the body's, and the mounts' internal states that move there: a Bouc–Wen z, a joint while it
  slips; not a stuck joint's), taken again after a mount's event, at every check while a mount
  is engaged, and every LINEARISE_EVERY × CHECK_EVERY intervals of regular checks, a span that
  doubles at each linearisation that finds J within JACOBIAN_KEEP of the one the propagator
  came from, up to LINEARISE_MAX × CHECK_EVERY (the bundled pump under its 5 s of ship motion
  linearises 12 times where it did 79, the estimate the same to three figures); its
  exponential by scaling and squaring (`src/core/linalg.hpp`), computed again only where J
  moved by more than JACOBIAN_KEEP; one matrix-vector product per interval;
- ℓ measured, not modelled: from the twin's state at the interval's start, a checking stepper
  (the twin's method, the exponential one for a Rosenbrock twin: CHECKED_BY; at rtol and atol
  over TOLERANCE_DIVISOR, less below rtol 1e-8: `check_divisor`; at least MIN_STEPS steps)
  runs the same interval under the same held input; the twin's end state less the check's is the
  twin's local error (to within the check's own, TOLERANCE_DIVISOR or 2⁵ times smaller). An
  embedded pair's error estimate would not do: it is the error of the lower-order solution,
  not of the one the twin carries;
- ℓ measured on a sample of the intervals: every interval that is *special* — a mount switched
  or an event function changed sign (a non-smooth law: contact, slip, a joint opening), the
  twin rejected a step, or its error norm spiked above SPIKE_RATIO × its running mean — counts
  for itself; otherwise one interval in CHECK_EVERY (in ENGAGED_CHECK_EVERY while a mount is
  engaged: in contact, slipping, open, where its stiffness moves with the state and the
  linearisation with it; a quarter of the fastest mode's period where the twin's steps are
  bound by its tolerance, below) is measured and stands for those since the last, in proportion
  to the twin's error norms (within 1 and their count: a shock's onset after quiet intervals is
  not counted as many loud ones). The intervals it stands for are taken to have committed as
  much, in phase (ℓₙ = hᵖ⁺¹·ψ(yₙ) follows the motion: carried to a later time, the local errors
  of a free oscillation arrive in phase), each damped by the intervals since: on the body's
  states it adds Σ_{j<k} Dʲ·ℓ for k intervals, D = exp(h/2·∂v̇/∂v) (what an interval leaves of
  each lightly damped mode, e^(−ζωh); `add_local_error` in src/core/engine/estimator.hpp).
  Counted undamped (k·ℓ), a mode that loses a third to two thirds of its error an interval
  (2.6–5 kHz on stiff mounts at 1 kHz) over-counted at least 6.8× (13× with checks 32 apart),
  nearly k over the 1.6–4.2 intervals its error lasts (6.8 and, damped, 1.22 times the
  reference's resolution there: the exponential twin's error on that scene is below what a
  reference resolves, test/test_error_estimate.py). Local errors add up in phase over a share
  of the fastest mode's period only, and over a smaller one where the twin takes more than one
  step an interval (its steps bound by its tolerance, not by the input). On the pump (fastest
  mode 122 rad/s, bounded at 157 rad/s from the Jacobian held: `fastest_rate`) checks 32 apart
  over-read 3.05× at 1 kHz and rtol 1e-9 (2 steps an interval, a period of 51 intervals; 1, 4,
  8, 16 apart: 0.86, 0.72, 0.95, 1.74); at lower sample rates, one step an interval, 2.13 at
  333 Hz and 3.49 at 100 Hz (5 intervals a period: 1, 2, 4, 8, 16 apart 0.98, 0.86, 0.62, 1.05,
  2.02), more steps, up to 6.16 at 250 Hz and rtol 1e-6 (1, 2, 3, 4, 8 apart: 0.95, 1.08, 1.15,
  1.42, 2.08). A check therefore stands for PERIOD_SHARE (one) of the fastest period at most,
  BOUND_PERIOD_SHARE (a quarter) where the twin took more than one step: on the pump 32 and 10
  intervals at 1 kHz, 4 and 1 at 100 Hz. At 100, 250, 333, 500 Hz and 1 kHz, rtol 1e-3 … 1e-10,
  it now reads 0.62–1.13 of the true force error (0.54–1.00 of the attitude's; 53dca9c:
  0.85–6.16), at 1.16–1.32× the engine at 1 kHz (`python3 bench/error_estimate.py --cases
  pump_ship_motion --rtol 1e-8 3e-9 1e-9 1e-10`; the lower rates are
  test/test_error_estimate.py's `_pump(every)`, tested at 250 Hz and rtol 1e-6, 100 Hz and
  1e-3, 1 kHz and 1e-9). Where the samples do not resolve the fastest mode (ωh > 2π: the stiff
  scene's 33) there is no such limit: the damped count already gives that mode's error the few
  intervals it lasts. The shipped pump, 32 intervals a check at 1 kHz, is not affected;
- under an exponential twin (exprb32, `auto`'s choice for stiff linear-mount scenes), a check's
  own Jacobian and φ functions of half the interval (two steps) were most of its cost (the
  φ functions' squarings), and the twin had just made the same. A regular check therefore comes
  early, from CHECK_EVERY / 4 intervals pending, at the first interval whose Jacobian the twin
  took at its start, and borrows it with the φ functions of half the step that the twin kept
  (src/core/integrate/exprb32.hpp HALF): the same numbers the check would have made (but
  where a check's step is rejected: the borrowed Jacobian is then renewed there). The
  twin renews its Jacobian at least every JACOBIAN_MAX_AGE (20) intervals, so checks come
  about that often (`BORROWED` counts them), and linearisations as often as before (they
  count check periods, not checks). On the stiff scene the estimate's cost fell from 1.3–1.4×
  to 1.14–1.15× the engine (bench/error_estimate.py).

The published outputs' errors are ∂(forces, angles)/∂y · e (sensitivities differenced with J),
folded into the figures every OUTPUT_TURN of the fastest mode's turn and as a run ends. Cost
per interval: one matrix-vector product (the propagator's over the carried states), and every
few intervals the output sensitivities' (both held transposed, so the rows' sums advance side
by side); per check, the check's steps and k products by the body's D (nf × nf); per
linearisation, n + 1 right-hand sides, and two exponentials (the propagator's, D's) where J
moved. Engine time with it over without: 1.15–1.18× on the pump since the span and the stride
above (1.23–1.27× before them, alternating, 2026-11-29; `python3 bench/bench_engine.py`),
1.15–1.19× earlier (1.16–1.24× before JACOBIAN_KEEP, when under perf the interval's
bookkeeping and products were 5 % of the samples and the linearisations' exponentials 3 %;
2026-11-26), 2.1–2.8× where the twin rejects steps every interval (docs/scene.md "Error
estimate", bench/error_estimate.py).
The engaged-mount and internal-state handling below works for any model (measured on the
non-linear scenes above) though the engine gives those the companion. It never touches the
twin's state: the published numbers are identical with it on or off
(test/test_error_estimate.py).

What it does not see: an overdamped mode (ζ > 1, more damping than mounts have) keeps its
error longer than D says (its slow root decays at ω/(2ζ), not ζω), so the intervals a check
stands for count less there than they should; the state jump of a mount's discrete switch is
carried as the identity
(its derivative, that of a slip or a plastic set, is not differenced); internal states that do
not move where it linearised hold their error; beyond DENSE_MAX carried states, moving internal
states are measured into each check's local error but their error is held, not carried: the
figures say how many did not fit (`uncarried_states`, a lower bound), and /diagnostics with them.

Its figures, kept as `engine.estimate` lays them out, are running maxima since the engine last
read them (see there).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mount_twin import _core
from mount_twin.engine.estimate import N_FIGURES
from mount_twin.integrate.methods import METHODS
from mount_twin.integrate.stepper import forget, tighter_arrays
from mount_twin.physics.dynamics import Scratch

TOLERANCE_DIVISOR = 32.0
"""The checking stepper's rtol and atol are the twin's over this."""
MIN_STEPS = 2
"""The checking stepper's fewest steps per input interval."""
CHECK_RTOL_FLOOR = 3e-10
"""The checking stepper's rtol is not taken below this (`check_divisor`): near 1e-11 a stepper
hunts on round-off (the exponential method at 3e-11 took 85 steps per interval where it takes
one at 1e-10), and a check costing a hundred intervals made the estimate 10× the engine."""
FLOOR_DIVISOR = 4.0
"""The smallest divisor the floor leaves: the check stays 4× tighter than the twin at least."""


def check_divisor(rtol: float) -> float:
    """The twin's rtol (and atol) over this is the checking stepper's: TOLERANCE_DIVISOR,
    less where that would take the check below CHECK_RTOL_FLOOR, never below FLOOR_DIVISOR.
    (With the MIN_STEPS halving, a check 4× tighter measures the twin's local error to within
    a quarter where the twin's steps are bound by its tolerance, to within 2^-p where they are
    bound by the input interval, as at these tolerances they mostly are.)"""
    return min(TOLERANCE_DIVISOR, max(FLOOR_DIVISOR, rtol / CHECK_RTOL_FLOOR))


CHECKED_BY = {"ros34pw2": "exprb32"}
"""The checking stepper's method where it is not the twin's. The Rosenbrock steps over a stiff
mode (ωh ≫ 1) by damping it, L-stably, and that damping is its error there; a check by the same
method at rtol/32 damps it too, and read 0.27 of the true error on the stiff scene at rtol 1e-3.
The exponential method is exact on the linear part, so it sees that error: 1.00 of it at rtol
1e-3, 1e-6 and 1e-9, at 1.1–2.6× the engine where the Rosenbrock's own checks cost 1.3–7.8×
(they took its tolerance-bound steps, up to 138 an interval; bench/error_estimate.py). The
estimator serves models of linear mounts: the smooth dynamics the exponential method needs."""
_CHECKED_BY_ID = {METHODS[twin].id: METHODS[check].id for twin, check in CHECKED_BY.items()}


DENSE_MAX = 64
"""The most states carried (the body's first, then the internal states that move)."""
CHECK_EVERY = 32
"""A measured interval counts for at most this many (one in CHECK_EVERY is measured)."""
ENGAGED_CHECK_EVERY = _core.ENGAGED_CHECK_EVERY
"""The same while a mount is engaged (the core's constant)."""
PERIOD_SHARE = _core.PERIOD_SHARE
"""A measured interval counts for at most this share of the fastest mode's period (where the
samples resolve it; the core's constant)."""
BOUND_PERIOD_SHARE = _core.BOUND_PERIOD_SHARE
"""The same where the twin took more than one step in the interval (the core's constant)."""
SPIKE_RATIO = _core.SPIKE_RATIO
"""An interval whose twin's error norm is above this multiple of its running mean is measured
on its own (the core's constant)."""
LINEARISE_EVERY = 2
"""Check periods (CHECK_EVERY intervals) of regular checks between linearisations at first: two
checks 32 apart, or the early ones that stand for as many intervals (a mount's event linearises
at once)."""
LINEARISE_MAX = 16
"""... and at most: each linearisation that finds the propagator held (the Jacobian within
JACOBIAN_KEEP of the one it came from) doubles the span to the next, one that does not sets it
back to LINEARISE_EVERY (src/core/engine/estimator.hpp `linearise_span`)."""
OUTPUT_STRIDE_MAX = _core.OUTPUT_STRIDE_MAX
"""The most intervals from one folding of the outputs' estimated errors to the next (the core's
constant)."""
OUTPUT_TURN = 0.5
"""rad: the outputs' estimated errors are folded into the figures each time the fastest mode
(bounded from the Jacobian held) has turned by this much, at most every OUTPUT_STRIDE_MAX
intervals, at every interval measured, and as a run ends (a restart, the stream's end:
`kernel.close_estimate`): a peak is read at cos(0.25) = 0.97 of its size at least
(src/core/engine/estimator.hpp `output_stride`; the pump at 1 kHz every 3 intervals)."""
JACOBIAN_KEEP = 1e-3
"""A linearisation keeps the propagator held (and the decay) while its fresh Jacobian is within
this share of the one they came from (Frobenius norms; the same carried states, the same
interval): a change δ moves a mode's frequency by about δ/2, and its carried error's phase by
less than 5e-3 rad over the intervals a mode with ζ = 0.1 keeps it. On the pump under ship
motion the Jacobian moves 1.6e-5–1.0e-4 between linearisations, and its exponentials were 3 %
of the engine's samples under perf (src/core/engine/estimator.hpp `propagator_holds`)."""
(
    CHECK_EVERY_SLOT,
    LINEARISE_EVERY_SLOT,
    LINEARISE_MAX_SLOT,
    JACOBIAN_KEEP_SLOT,
    OUTPUT_TURN_SLOT,
    LINEARISE_SPAN,
    OUTPUT_PENDING,
    PENDING,
    PENDING_NORM,
    PROPAGATOR_STEP,
    FASTEST_RATE,
    ERROR_NORM_MEAN,
    SINCE_LINEARISED,
    N_CARRIED,
    CHECKS,
    LINEARISATIONS,
    EXPONENTIALS,
    BORROWED,
    N_SLOTS,
) = _core.ESTIMATOR_SLOTS
"""Slots of `Estimator.state` (src/core/engine/estimator.hpp says what each keeps)."""
KEPT = [
    LINEARISE_SPAN,
    OUTPUT_PENDING,
    PENDING,
    PENDING_NORM,
    PROPAGATOR_STEP,
    FASTEST_RATE,
    ERROR_NORM_MEAN,
    SINCE_LINEARISED,
    N_CARRIED,
]
"""The slots a restart clears."""


class Estimator(NamedTuple):
    """The estimate's arrays (the core's loop works on them: `estimate_interval` in
    src/core/engine/estimator.hpp). n states, at most np carried, nm mounts; matrices are
    flat buffers (row-major, of the size the carried states need).

    method, settings, work2d, work1d, result: the checking stepper (`integrate.stepper`).
    y: (n,) the check's state; s: its scratch; y_start, y_end: (n,) the twin's state at an
    interval's start and after its step; e: (n,) the estimated error of the twin's state.
    carried: (np,) indices of the carried states (float); n_body: the body's states, always
    carried. jac, prop: (np²,) ∂f/∂y and exp(h·∂f/∂y) over them (prop transposed); decay:
    (n_free²,) exp(h/2·∂v̇/∂v), the body's modes' damping over an interval; work:
    (2np²,); sens: (np·(3nm + 3),) ∂(mount forces N, α γ δ rad)/∂y, transposed (a carried
    state's row of outputs). f0, f1: (n,); out0, out1: (3nm + 3,); ec, pc: (np,); wrenches:
    (nm, 6): work. state: (N_SLOTS,). figures: (N_FIGURES,) running maxima, reset by the
    reader.
    """

    method: int
    settings: np.ndarray
    work2d: np.ndarray
    work1d: np.ndarray
    result: np.ndarray
    y: np.ndarray
    s: Scratch
    y_start: np.ndarray
    y_end: np.ndarray
    e: np.ndarray
    carried: np.ndarray
    n_body: int
    jac: np.ndarray
    prop: np.ndarray
    decay: np.ndarray
    work: np.ndarray
    sens: np.ndarray
    f0: np.ndarray
    f1: np.ndarray
    out0: np.ndarray
    out1: np.ndarray
    ec: np.ndarray
    pc: np.ndarray
    wrenches: np.ndarray
    state: np.ndarray
    figures: np.ndarray


def new_estimator(
    method: str,
    rtol: float,
    atol: float,
    max_substeps: int,
    scratch: Scratch,
    n_free: int,
    n_mounts: int,
    check_every: int = CHECK_EVERY,
    jacobian_keep: float = JACOBIAN_KEEP,
    linearise_max: int = LINEARISE_MAX,
    output_turn: float = OUTPUT_TURN,
) -> Estimator:
    """The estimate of a twin integrated by `method` (a name, or AUTO: then `switch` it with
    the twin) at tolerances rtol, atol; `scratch`: fresh work arrays of the model (its n
    states); n_free: the body's free coordinates; check_every: see CHECK_EVERY (1 measures
    every interval: the reference the sampling is tested against); jacobian_keep: see
    JACOBIAN_KEEP (0 computes the propagator at every linearisation); linearise_max: see
    LINEARISE_MAX (LINEARISE_EVERY keeps the span where it starts); output_turn: see
    OUTPUT_TURN (0 folds the outputs' errors at every interval)."""
    n = scratch.sink.shape[0]
    check = CHECKED_BY.get(method, method)
    own = tighter_arrays(check, n, rtol, atol, max_substeps, check_divisor(rtol), MIN_STEPS)
    n_body = 2 * n_free
    slots = max(min(n, DENSE_MAX), n_body)
    n_out = 3 * n_mounts + 3
    state = np.zeros(N_SLOTS)
    state[CHECK_EVERY_SLOT] = check_every
    state[LINEARISE_EVERY_SLOT] = LINEARISE_EVERY
    state[LINEARISE_MAX_SLOT] = linearise_max
    state[OUTPUT_TURN_SLOT] = output_turn
    state[JACOBIAN_KEEP_SLOT] = jacobian_keep
    return Estimator(
        *own,
        np.zeros(n),
        scratch,
        np.zeros(n),
        np.zeros(n),
        np.zeros(n),
        np.zeros(slots),
        n_body,
        np.zeros(slots * slots),
        np.zeros(slots * slots),
        np.zeros(n_free * n_free),
        np.zeros(2 * slots * slots),
        np.zeros(n_out * slots),
        np.zeros(n),
        np.zeros(n),
        np.zeros(n_out),
        np.zeros(n_out),
        np.zeros(slots),
        np.zeros(slots),
        np.zeros((n_mounts, 6)),
        state,
        np.zeros(N_FIGURES),
    )


def switch(est: Estimator, method: int) -> Estimator:
    """The estimate of a twin now integrated by `method` (an id), checking with its method or
    `CHECKED_BY`'s (the work arrays were made for AUTO)."""
    forget(est.settings)
    return est._replace(method=_CHECKED_BY_ID.get(method, method))


def restart(est: Estimator) -> None:
    """Start again from nothing (a twin start or restart: its state was set, not integrated):
    no error carried, no intervals pending, linearised afresh at the next interval."""
    est.e[:] = 0.0
    est.state[KEPT] = 0.0
    forget(est.settings)
