"""Dormand–Prince 5(4) with error control, advancing across one input-sample interval.

The method is its coefficient table and one free compiled function (scipy `integrate/_ivp`
shape). It calls the model's right-hand side directly (a compiled function passed as an
argument would make it and every caller uncacheable), inlined in the stage loop
(`dynamics.rhs_inlined`). The state advances with the 5th-order solution; the embedded
4th-order one estimates the local error. Error norm: RMS of err / (atol + rtol·|y|).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from mount_twin.integrate.control import (
    MIN_STEP_FRACTION,
    OFF_CHART_SHRINK,
    give_up,
    next_proposal,
    step_factor,
    trial_step,
)
from mount_twin.integrate.methods import (
    SUCCESS,
)
from mount_twin.integrate.settings import ATOL, CHAINED, MAX_SUBSTEPS, MIN_STEPS, RTOL, STEP
from mount_twin.physics.compiled import kernel
from mount_twin.physics.dynamics import rhs, rhs_inlined

C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
A = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [1 / 5, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3 / 40, 9 / 40, 0.0, 0.0, 0.0, 0.0],
        [44 / 45, -56 / 15, 32 / 9, 0.0, 0.0, 0.0],
        [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0, 0.0],
        [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0.0],
        [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84],
    ]
)
B = A[6].copy()
E = np.array([71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40])
"""5th-order weights minus the embedded 4th-order weights (the last stage is FSAL)."""
FSAL = True
"""The last stage is evaluated at (t + h, y_new): it is the next step's first."""
ORDER = 4
"""Order of the error estimate (the step-size controller's exponent is −1/(ORDER + 1))."""
MAX_FACTOR = 10.0


def _advance(y, t0, t1, settings, m, s, u, k, y_new, result) -> int:
    """Advance y (in place) from t0 to t1 s with input u held over the interval.

    The signature is every stepper's: (y, t0, t1, settings, model arrays, scratch, input,
    2-D work, 1-D work, result).

    Args:
        settings: [first trial step s (0: the whole interval; updated to the next proposal),
            rtol, atol, most substeps, chain flag, fewest steps] (`integrate.settings`). On
            success the last right-hand side evaluated is the one at (t1, y), in k[0] (FSAL),
            and the flag is set to 1: callers may take outputs from the scratch, and, having
            moved k[0] to the next interval's input, leave the flag at 1 so that the next call
            starts from it; else they set 0.
        k: (7, n) stage work array; y_new: (n,) work array.
        result: out (3,): largest accepted error norm, accepted and rejected step counts.

    Returns:
        A status of `integrate.methods`: SUCCESS, TOO_MANY_STEPS, STEP_TOO_SMALL, LEFT_CHART (the
        steps shrank because the right-hand side kept failing) or NOT_FINITE (they shrank
        because its values stayed NaN or infinite, e.g. a mount kind code without a law); y is
        left at the last accepted time on failure.
    """
    h, rtol, atol = settings[STEP], settings[RTOL], settings[ATOL]
    max_steps = settings[MAX_SUBSTEPS]
    n = y.shape[0]
    span = t1 - t0
    h = span if h <= 0.0 else h
    h_max = span / settings[MIN_STEPS]  # caps the steps taken, not the proposal carried on
    t = t0
    err_max, n_acc, n_rej = 0.0, 0, 0
    rhs_failed = False
    not_finite = False  # the last rejection was for NaN or inf (stage state or error norm)
    if settings[CHAINED] == 0.0:  # else the caller put dy/dt at (t0, y) for this input in k[0]
        rhs_failed = rhs(t, y, m, s, u, k[0]) != 0
    settings[CHAINED] = 0.0  # set again below on success: k[0] is then dy/dt at (t1, y)
    while t < t1:
        # a step too small, or the start state itself off the chart (no step can help)
        too_small = h < MIN_STEP_FRACTION * span or (rhs_failed and n_acc == 0 and t == t0)
        status = give_up(n_acc + n_rej, max_steps, too_small, not_finite, rhs_failed)
        if status != SUCCESS:
            settings[STEP], result[0], result[1], result[2] = h, err_max, n_acc, n_rej
            return status
        step, last = trial_step(t, t1, h, h_max, span)
        ok = True
        for stage in range(1, 7):
            for i in range(n):
                y_new[i] = y[i]
            for j in range(stage):  # row by row: the inner loop runs along k[j], vectorised
                a = step * A[stage, j]
                if a != 0.0:
                    for i in range(n):
                        y_new[i] += a * k[j, i]
            if rhs_inlined(t + C[stage] * step, y_new, m, s, u, k[stage]) != 0:
                ok = False
                break
        rhs_failed = not ok
        if rhs_failed:
            # a NaN stage state also reads as off the chart: tell them apart (only on failure)
            not_finite = False
            for i in range(n):
                if not math.isfinite(y_new[i]):
                    not_finite = True
            h = step * OFF_CHART_SHRINK
            n_rej += 1
            continue
        # y_new holds the 5th-order solution (the last stage row equals B).
        err = 0.0
        for i in range(n):
            e = 0.0
            for j in range(7):
                e += E[j] * k[j, i]
            scale = atol + rtol * max(abs(y[i]), abs(y_new[i]))
            err += (step * e / scale) ** 2
        err = math.sqrt(err / n)
        # NaN or inf: rejected below and shrunk by the most; if it persists, NOT_FINITE
        not_finite = not math.isfinite(err)
        factor = step_factor(err, not_finite, ORDER, MAX_FACTOR)
        if err <= 1.0:
            t = t1 if last else t + step
            for i in range(n):
                y[i] = y_new[i]
                k[0, i] = k[6, i]
            err_max = max(err_max, err)
            n_acc += 1
            h = next_proposal(step, h, factor, last)
        else:
            h = step * min(1.0, factor)
            n_rej += 1
    settings[STEP], result[0], result[1], result[2] = h, err_max, n_acc, n_rej
    settings[CHAINED] = 1.0
    return SUCCESS


advance = kernel(_advance)
"""Dormand–Prince across one input interval (see `_advance`)."""
advance_inlined = njit(cache=True, inline="always")(_advance)
"""`advance` inlined into `integrate.stepper.advance`, the one call per input interval: a call
passes the model's and the scratch's arrays (~100 ns a sample on the genset)."""
