"""Damped Newton's method for a small square system r(x) = 0: the start equilibrium's fast
path.

The start's equilibrium is a handful of coordinates on mounts that are linear or piecewise
linear near rest: Newton lands and polishes in three Jacobians (0.2 ms on the genset, its
Jacobians in compiled code), where scipy's trust-region least squares spent 1.5–3 ms of
bookkeeping on its evaluations, a tenth of the engine's time on a 0.25 s shock record. Where
Newton does not get there (a singular Jacobian: a DOF no mount holds; a kink it cycles on), it
says so and the caller falls back on the robust solver.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

MAX_ITERATIONS = 20
MAX_HALVINGS = 8
"""Backtracking: the Newton step is halved at most this often while |r| does not decrease."""


def solve(
    residual: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    tolerance: Callable[[np.ndarray], np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """x with |r(x)| ≤ tolerance(J) component-wise (J = jacobian(x) = ∂r/∂x), from x0,
    polished until a Newton step no longer reduces |r| (the rounding floor, where the
    least-squares solver also ends); returns (x, r(x), J at x), or None where Newton does not
    get there (singular J, no decrease of |r| outside the tolerance, not finite, or
    MAX_ITERATIONS)."""
    x = np.array(x0, dtype=float)
    r = residual(x)
    for _ in range(MAX_ITERATIONS):
        if not np.isfinite(r).all():
            return None
        jac = jacobian(x)
        within = bool((np.abs(r) <= tolerance(jac)).all())
        try:
            step = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            return None
        norm = np.linalg.norm(r)
        for _ in range(MAX_HALVINGS + 1):
            x_new = x + step
            r_new = residual(x_new)
            if np.linalg.norm(r_new) < norm:
                break
            if within:  # at the floor: polished
                return x, r, jac
            step *= 0.5
        else:
            return None
        x, r = x_new, r_new
    return None
