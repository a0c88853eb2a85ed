"""Damped Newton's method for a small square system r(x) = 0, with a forward-difference
Jacobian: the start equilibrium's fast path.

The start's equilibrium is a handful of coordinates on mounts that are linear or piecewise
linear near rest: Newton lands and polishes in three Jacobians (about 25 evaluations, 0.5 ms on
the genset), where scipy's trust-region least squares spent 1.5–3 ms of bookkeeping on the same
evaluations, a tenth of the engine's time on a 0.25 s shock record. Where Newton does not get
there (a singular Jacobian: a DOF no mount holds; a kink it cycles on), it says so and the
caller falls back on the robust solver.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

MAX_ITERATIONS = 20
MAX_HALVINGS = 8
"""Backtracking: the Newton step is halved at most this often while |r| does not decrease."""
FD_STEP = 1.4901161193847656e-08
"""√ε: the forward-difference step, relative to max(1, |x_i|) (as scipy's '2-point')."""


def fd_jacobian(
    residual: Callable[[np.ndarray], np.ndarray], x: np.ndarray, r: np.ndarray
) -> np.ndarray:
    """∂r/∂x at x by forward differences (r = residual(x) given)."""
    jac = np.empty((r.shape[0], x.shape[0]))
    for c in range(x.shape[0]):
        probe = x.copy()
        probe[c] += FD_STEP * max(1.0, abs(x[c]))
        jac[:, c] = (residual(probe) - r) / (probe[c] - x[c])
    return jac


def solve(
    residual: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    tolerance: Callable[[np.ndarray], np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """x with |r(x)| ≤ tolerance(J) component-wise, from x0, polished until a Newton step no
    longer reduces |r| (the rounding floor, where the least-squares solver also ends); returns
    (x, r(x), J at x), or None where Newton does not get there (singular J, no decrease of |r|
    outside the tolerance, not finite, or MAX_ITERATIONS)."""
    x = np.array(x0, dtype=float)
    r = residual(x)
    for _ in range(MAX_ITERATIONS):
        if not np.isfinite(r).all():
            return None
        jac = fd_jacobian(residual, x, r)
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
