"""The compiled per-sample loop: integrate a run of accepted samples and evaluate outputs (the
loop is the core's, src/core/engine/kernel.hpp; these are the arrays it works on).

One call handles a whole batch, so the Python-to-compiled call cost (µs) is paid once per batch,
not per sample; a live node passes batches of one through the same function.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mount_twin import _core


class Watch(NamedTuple):
    """Event watch over the non-linear mounts (k of them, NE event functions each).

    g_prev, g: (k, NE) event functions at the previous and this sample (≥ 0: happening).
    util, util_peak: (k,) utilisation now and its peak since the engine last read it.
    events: (cap, 4) log rows [crossing time s, mount index in the scene, event index, |force| N]
    n_events: (1,) rows written (may exceed cap: the excess is counted, not stored).
    y_prev: (n_state,) the state at the previous sample (trial states of the event functions).
    stop_after: (1,) stamp, s: a sample after it that logs an event that may stiffen the scene
        ends the run (status AT_EVENT) so that the engine can look at it again (`auto`);
        inf: never.
    stiffens: (k, NE) 1.0 where an event may stiffen the scene (the kinds' EVENT_STIFFENS).
    n_stiffening: (1,) such events logged so far (counted beyond the log's capacity too).
    """

    g_prev: np.ndarray
    g: np.ndarray
    util: np.ndarray
    util_peak: np.ndarray
    events: np.ndarray
    n_events: np.ndarray
    y_prev: np.ndarray
    stop_after: np.ndarray
    stiffens: np.ndarray
    n_stiffening: np.ndarray


AT_EVENT = _core.AT_EVENT
"""(−100) `run_samples`' status when it ended the run at a sample that logged an event (not a
failure; no stepper status has this value)."""


def new_watch(
    k: int, n_events: int, n_state: int, stiffens: np.ndarray | None = None, capacity: int = 4096
) -> Watch:
    """Empty watch for k mounts in a model of n_state states; `stiffens` (k, n_events): the
    events that may stiffen the scene (default none)."""
    return Watch(
        np.full((k, n_events), -1.0),
        np.full((k, n_events), -1.0),  # a kind with fewer events never writes the rest
        np.zeros(k),
        np.zeros(k),
        np.zeros((capacity, 4)),
        np.zeros(1, dtype=np.int64),
        np.zeros(n_state),
        np.full(1, np.inf),
        np.zeros((k, n_events)) if stiffens is None else stiffens.astype(float),
        np.zeros(1, dtype=np.int64),
    )


class Integrator(NamedTuple):
    """A stepper's id, settings and work arrays, as `integrate.stepper.advance` takes them."""

    method: int
    settings: np.ndarray
    work2d: np.ndarray
    work1d: np.ndarray
    result: np.ndarray


class Samples(NamedTuple):
    """The input of one run: row 0 is the last sample already done.

    t: (n,) stamps, s; f: (n, 3) specific force, m/s², F; w: (n, 3) foundation Ω, rad/s, F.
    """

    t: np.ndarray
    f: np.ndarray
    w: np.ndarray


class RunOptions(NamedTuple):
    """zero_order: hold each sample until the next instead of interpolating linearly.
    decimation: publish every Nth sample. chain: start each interval from the previous one's
    last stage when the stepper says it is there (settings[CHAINED]: first-order hold, and
    nothing else used the scratch since; `Stepper.reset` and a mount's discrete switch between
    samples clear it)."""

    zero_order: bool
    decimation: int
    chain: bool


class Published(NamedTuple):
    """What a run publishes, and the decimation's state carried from run to run.

    counter: (1,) samples since the last publish (carried).
    peak: (nm, 6) wrench components of largest magnitude since the last publish (carried).
    pose: out (n, pose_row.WIDTH) pose rows; wrenches: out (n, nm, 6) published wrenches.
    publish: out (n,) True where the sample is published.
    step_log: out (n, 3) per sample: error norm, accepted and rejected substeps.
    wrench_abs_max: out (nm, 6), zeros on entry: the largest |component| of the published
        wrenches (N, N·m), folded in while they are in cache (the health window's peaks).
    lin_util: (n_lin,) each linear mount's utilisation (its largest |travel|/rated travel and
        |force|/rated load over its axes, `ModelArrays.lin_per_rating`) folded in as a running
        maximum at every sample (carried; the reader resets it).
    cos_tilt_min: out (1,), 1 on entry: the smallest cos θ (R₃₃, body z against F's z) of the
        published poses.
    """

    counter: np.ndarray
    peak: np.ndarray
    pose: np.ndarray
    wrenches: np.ndarray
    publish: np.ndarray
    step_log: np.ndarray
    wrench_abs_max: np.ndarray
    cos_tilt_min: np.ndarray
    lin_util: np.ndarray


Loop = _core.Loop
"""Loop(integ, m, s, u, y, opts, watch, estimate): the arrays `run_samples` advances, converted
and checked once (dtype, shape against the model: a wrong one raises naming it), held so their
views stay valid. Their contents may change between runs; to replace an array or a tuple
(a start's new y, a method switch's stepper and estimate), bind a new Loop (`CoreDriver` does).
The model's arrays are read at binding: a model is never changed in place.

Args:
    integ: the stepper (`Integrator`); m, s: the model's arrays and scratch; u: the input
        vector the right-hand side reads (filled here per interval); y: the state.
    opts: `RunOptions`.
    watch: the non-linear mounts' event functions, utilisation peaks and event log
        (`Watch`, read only where the model has such mounts); events are located by linear
        interpolation inside the sample interval.
    estimate: the live error estimate's arrays: `engine.estimator.Estimator` (a model of linear
        mounts), `engine.companion.Companion` (with non-linear ones), or None (off).
"""
run_samples = _core.run_samples
"""run_samples(loop, samples, out) -> (done, status): advance the loop's y through samples
1..n−1 of `samples`; sample 0 is the last one already done (src/core/engine/kernel.hpp; the
loop releases the GIL).

Args:
    loop: a `Loop`.
    samples: `Samples`; out: `Published` (buffers of n rows), both checked at each call.

Returns:
    (index of the last sample done, status: 0 when all are done; AT_EVENT when the run ended
    at that sample because it logged an event that may stiffen the scene, past
    watch.stop_after; else the stepper's failure at the next sample).
"""
close_estimate = _core.close_estimate
"""close_estimate(loop): the run the loop advanced ends (a restart follows, or the stream ends).
The sampled estimate (`engine.estimator`) folds the outputs' errors of the intervals since it
last did into its figures (src/core/engine/estimator.hpp `close_run`); the companion folds at
every interval, and without an estimate there is nothing to fold."""
