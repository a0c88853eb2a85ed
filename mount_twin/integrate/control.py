"""Step-size control shared by the embedded methods (inlined into each method's `advance`).

The classic controller (Hairer, Nørsett & Wanner I, §II.4): after a step with error norm err
(≤ 1 accepted), the next step is h·min(max_factor, max(MIN_FACTOR, SAFETY·err^(−1/(q+1))))
for an error estimate of order q; a step whose right-hand side or error was NaN or infinite is
shrunk by the most. A run of steps gives up with a status of `integrate.methods` when it has
taken MAX_SUBSTEPS or when the step falls below MIN_STEP_FRACTION of the input interval.
"""

from __future__ import annotations

from numba import njit

from mount_twin.integrate.methods import (
    LEFT_CHART,
    NOT_FINITE,
    STEP_TOO_SMALL,
    SUCCESS,
    TOO_MANY_STEPS,
)
from mount_twin.integrate.settings import CHAINED, JACOBIAN_AGE, PHI_STEP, STEP
from mount_twin.physics.dynamics import rhs

SAFETY, MIN_FACTOR = 0.9, 0.2
OFF_CHART_SHRINK = 0.25
"""A step whose right-hand side failed (off the chart, NaN) is retried this much shorter."""
MIN_STEP_FRACTION = 1e-12
"""A step shorter than this fraction of the interval is a failure."""


@njit(cache=True, inline="always")
def step_factor(err: float, not_finite: bool, order: int, max_factor: float) -> float:
    """The next step over this one after an error norm err of an order-`order` estimate."""
    if not_finite:
        return MIN_FACTOR
    if err == 0.0:
        return max_factor
    return min(max_factor, max(MIN_FACTOR, SAFETY * err ** (-1.0 / (order + 1))))


@njit(cache=True, inline="always")
def give_up(
    steps: int, max_steps: float, too_small: bool, not_finite: bool, off_chart: bool
) -> int:
    """SUCCESS to go on, else the status to stop with: too many steps, or a step too small to
    go on with (NaN or inf, the chart's edge, or plain underflow, as the last rejection says)."""
    if steps >= max_steps:
        return NOT_FINITE if not_finite else TOO_MANY_STEPS
    if too_small:
        if not_finite:
            return NOT_FINITE
        return LEFT_CHART if off_chart else STEP_TOO_SMALL
    return SUCCESS


@njit(cache=True, inline="always")
def trial_step(t: float, t1: float, h: float, h_max: float, span: float) -> tuple[float, bool]:
    """The step to try from t toward the interval's end t1 (the proposal h, at most h_max),
    and whether it is the interval's last (then it ends exactly at t1)."""
    step = min(h, h_max)
    last = t + step >= t1 - 1e-12 * span
    return (t1 - t if last else step), last


@njit(cache=True, inline="always")
def next_proposal(step: float, h: float, factor: float, last: bool) -> float:
    """The proposal after an accepted step: from a full step, not from a last step clipped
    to the interval (that one keeps the proposal it had)."""
    return step * factor if (not last or step >= h) else h


@njit(cache=True, inline="always")
def forget(settings):
    """Forget a stepper's history (after its state jumped: a start, a restart, a resync): the
    step proposal, the chained last stage, the Jacobian held and its matrix functions."""
    settings[STEP] = 0.0
    settings[CHAINED] = 0.0
    settings[JACOBIAN_AGE] = 0.0
    settings[PHI_STEP] = 0.0


@njit(cache=True, inline="always")
def conclude(y, y_new, t, t1, step, h, last, err, not_finite, order, max_factor, m, s, u, k, rows):
    """End a step of a method that restarts from f(t, y) (no FSAL: the linearising ones): accept
    it if err ≤ 1 and the right-hand side at (t + step, y_new) is defined (y ← y_new, and
    k[rows[0]] ← f there, for the next step and for the outputs; k[rows[1]] is scratch), else
    reject it. Returns (t, the next step to try, accepted)."""
    factor = step_factor(err, not_finite, order, max_factor)
    t_new = t1 if last else t + step
    if err <= 1.0 and rhs(t_new, y_new, m, s, u, k[rows[1]]) == 0:
        for r in range(y.shape[0]):
            y[r] = y_new[r]
            k[rows[0], r] = k[rows[1], r]
        return t_new, next_proposal(step, h, factor, last), True
    return t, step * min(1.0, factor), False
