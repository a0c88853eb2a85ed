"""The compiled per-sample loop: integrate a run of accepted samples and evaluate outputs.

One call handles a whole batch, so the Python-to-compiled call cost (µs) is paid once per batch,
not per sample; a live node passes batches of one through the same function.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from mount_twin.engine.companion import follow
from mount_twin.integrate.settings import CHAINED
from mount_twin.integrate.stepper import advance
from mount_twin.physics.compiled import kernel
from mount_twin.physics.dynamics import mount_monitors, outputs, rhs_after_rate_step
from mount_twin.physics.gate import skip_if_none


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


AT_EVENT = -100
"""`run_samples`' status when it ended the run at a sample that logged an event (not a
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


@kernel
def _watch(y, nl, s, watch, t0, t1, wrenches, settings) -> None:
    """Evaluate the event functions at t1; log each upward zero crossing since t0. A discrete
    switch (the state jumped) clears the stepper's chain flag (settings[CHAINED])."""
    g_prev, g, util, peak = watch.g_prev, watch.g, watch.util, watch.util_peak
    events, count = watch.events, watch.n_events
    y_prev = watch.y_prev
    if mount_monitors(y, y_prev, nl, s, g, util):
        settings[CHAINED] = 0.0
    for i in range(y.shape[0]):  # a loop: slice assignment may need a temporary (NRT)
        y_prev[i] = y[i]
    for i in range(g.shape[0]):
        peak[i] = max(peak[i], util[i])
        for e in range(g.shape[1]):
            g0, g1 = g_prev[i, e], g[i, e]
            g_prev[i, e] = g1
            if g0 < 0.0 <= g1:
                if watch.stiffens[i, e] > 0.0:
                    watch.n_stiffening[0] += 1
                k = count[0]
                count[0] += 1
                if k < events.shape[0]:
                    slot = nl.slot[i]
                    w = wrenches[slot]
                    events[k, 0] = t0 + (t1 - t0) * (-g0) / (g1 - g0)
                    events[k, 1] = slot
                    events[k, 2] = e
                    events[k, 3] = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])


watch_mounts = skip_if_none(_watch)


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


@kernel
def run_samples(integ, m, s, u, y, samples, opts, out, watch, companion) -> tuple[int, int]:
    """Advance y through samples 1..n−1 of `samples`; sample 0 is the last one already done.

    Args:
        integ: the stepper (`Integrator`); m, s: the model's arrays and scratch; u: the input
            vector the right-hand side reads (filled here per interval); y: the state.
        samples: `Samples`; opts: `RunOptions`; out: `Published` (buffers of n rows).
        watch: the non-linear mounts' event functions, utilisation peaks and event log
            (`Watch`); events are located by linear interpolation inside the sample interval.
        companion: the error estimate's companion solution (`engine.companion.Companion`), or
            None (compiled away).

    Returns:
        (index of the last sample done, status: 0 when all are done; AT_EVENT when the run ended
        at that sample because it logged an event that may stiffen the scene, past
        watch.stop_after; else the stepper's failure at the next sample).
    """
    t, f, w = samples.t, samples.f, samples.w
    method, settings, work2d, work1d = integ.method, integ.settings, integ.work2d, integ.work1d
    result = integ.result
    counter, peak, pose, wrenches = out.counter, out.peak, out.pose, out.wrenches
    publish, step_log, decimation = out.publish, out.step_log, opts.decimation
    abs_max, cos_tilt = out.wrench_abs_max, out.cos_tilt_min
    n, nm = t.shape[0], peak.shape[0]
    hold = 0.0 if opts.zero_order else 1.0
    d_wdot = s.rate_step
    for j in range(1, n):
        dt = t[j] - t[j - 1]
        u[0] = t[j - 1]
        for i in range(3):
            u[1 + i] = f[j - 1, i]
            u[4 + i] = hold * (f[j, i] - f[j - 1, i]) / dt
            u[7 + i] = w[j - 1, i]
            w_dot = hold * (w[j, i] - w[j - 1, i]) / dt
            d_wdot[i] = w_dot - u[10 + i]
            u[10 + i] = w_dot
        if opts.chain and settings[CHAINED] == 1.0:
            # First-order hold: the input is continuous at t[j − 1] but for Ω', so the last
            # stage of the previous interval, moved to the new Ω', starts this one. Live (one
            # sample per call) and replay (many) thus compute exactly the same numbers.
            rhs_after_rate_step(m, s, d_wdot, work2d[0])
        else:
            settings[CHAINED] = 0.0
        status = advance(method, y, t[j - 1], t[j], settings, m, s, u, work2d, work1d, result)
        if status != 0:
            return j - 1, status
        stiffening = watch.n_stiffening[0]
        step_log[j, 0], step_log[j, 1], step_log[j, 2] = result[0], result[1], result[2]
        outputs(y, m, s, pose[j], wrenches[j])  # the stepper's last right-hand side was at y
        watch_mounts(y, m.nl, s, watch, t[j - 1], t[j], wrenches[j], settings)
        follow(m, companion, u, t[j - 1], t[j], opts.chain, d_wdot, pose[j], wrenches[j], y)
        counter[0] += 1
        for a in range(nm):
            for b in range(6):
                if abs(wrenches[j, a, b]) > abs(peak[a, b]):
                    peak[a, b] = wrenches[j, a, b]
        publish[j] = counter[0] >= decimation
        if publish[j]:
            for a in range(nm):
                for b in range(6):
                    wrenches[j, a, b] = peak[a, b]
                    abs_max[a, b] = max(abs_max[a, b], abs(peak[a, b]))
                    peak[a, b] = 0.0
            counter[0] = 0
            cos_tilt[0] = min(cos_tilt[0], s.rot[2, 2])  # outputs() took pose[j] from s.rot
        if watch.n_stiffening[0] > stiffening and t[j] > watch.stop_after[0]:
            return j, AT_EVENT
    return n - 1, 0
