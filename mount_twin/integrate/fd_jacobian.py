"""The Jacobian ∂f/∂y and ∂f/∂t of the compiled right-hand side by forward differences, into
rows of a stepper's work array, and how long one is held: shared by the methods that linearise
(Rosenbrock, exponential).

Exact for linear mounts up to rounding. n + 1 evaluations for J, 1 for ∂f/∂t (the input's
slopes, new each interval). The rows are passed by index, (f, scratch, ∂f/∂t, first row of J),
so each method keeps its own layout. A Jacobian serves a method's `max_age` input intervals
(settings[JACOBIAN_AGE] counts them) and is taken afresh at a rejected step of an interval it
did not start; whatever a method computed from it (settings[PHI_STEP]) is forgotten with it.
"""

from __future__ import annotations

from numba import njit

from mount_twin.integrate.settings import JACOBIAN_AGE, PHI_STEP
from mount_twin.physics.compiled import kernel
from mount_twin.physics.dynamics import rhs

JAC_STEP = 1.4901161193847656e-08
"""√ε: the relative finite-difference step of the Jacobian columns (relative to |y_c|, or to
the caller's typical magnitude where y_c is smaller)."""


@kernel
def jacobian(y, t, m, s, u, k, typical, f_row, tmp_row, ft_row, j0) -> bool:
    """k[j0 : j0 + n] = ∂f/∂y at (t, y), then `time_derivative` into k[ft_row]; k[f_row] holds
    f(t, y) on entry, k[tmp_row] is scratch; column c is differenced over JAC_STEP·max(|y_c|,
    typical) (state units). False if an evaluation failed (off the chart)."""
    n = y.shape[0]
    for c in range(n):
        keep = y[c]
        d = JAC_STEP * max(abs(keep), typical)
        y[c] = keep + d
        d = y[c] - keep  # the step actually taken
        bad = rhs(t, y, m, s, u, k[tmp_row]) != 0
        y[c] = keep
        if bad:
            return False
        for r in range(n):
            k[j0 + r, c] = (k[tmp_row, r] - k[f_row, r]) / d
    return time_derivative(y, t, m, s, u, k, f_row, tmp_row, ft_row)


@kernel
def time_derivative(y, t, m, s, u, k, f_row, tmp_row, ft_row) -> bool:
    """k[ft_row] = ∂f/∂t at (t, y) by a forward difference; k[f_row] holds f(t, y) on entry,
    k[tmp_row] is scratch. False if the evaluation failed."""
    n = y.shape[0]
    dt = JAC_STEP * max(abs(t), 1.0)
    if rhs(t + dt, y, m, s, u, k[tmp_row]) != 0:
        return False
    for r in range(n):
        k[ft_row, r] = (k[tmp_row, r] - k[f_row, r]) / dt
    return True


@njit(cache=True, inline="always")
def linearise(y, t, m, s, u, k, typical, rows, settings, max_age) -> bool:
    """At an interval's start: f(t, y) into k[rows[0]], then J afresh if none is held or the one
    held has served `max_age` intervals, else only ∂f/∂t; the one held is aged. False if an
    evaluation failed (off the chart)."""
    f_row, tmp_row, ft_row, j0 = rows
    age = settings[JACOBIAN_AGE]
    fresh = age == 0.0 or age >= max_age
    if rhs(t, y, m, s, u, k[f_row]) != 0:
        return False
    if fresh:
        if not jacobian(y, t, m, s, u, k, typical, f_row, tmp_row, ft_row, j0):
            return False
        settings[PHI_STEP] = 0.0
    elif not time_derivative(y, t, m, s, u, k, f_row, tmp_row, ft_row):
        return False
    settings[JACOBIAN_AGE] = 1.0 if fresh else age + 1.0
    return True


@njit(cache=True, inline="always")
def renew_if_stale(y, t, m, s, u, k, typical, rows, settings) -> None:
    """After a rejected step (y unchanged, k[rows[0]] = f(t, y)): a Jacobian held from an
    earlier interval is taken afresh at (t, y)."""
    f_row, tmp_row, ft_row, j0 = rows
    if settings[JACOBIAN_AGE] > 1.0 and jacobian(
        y, t, m, s, u, k, typical, f_row, tmp_row, ft_row, j0
    ):
        settings[JACOBIAN_AGE] = 1.0
        settings[PHI_STEP] = 0.0
