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
    halvings: int = MAX_HALVINGS,
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """x with |r(x)| ≤ tolerance(J) component-wise (J = jacobian(x) = ∂r/∂x), from x0,
    polished until a Newton step no longer reduces |r| (the rounding floor, where the
    least-squares solver also ends); returns (x, r(x), J at x), or None where Newton does not
    get there (singular J, no decrease of |r| outside the tolerance in `halvings` halvings of
    the step, not finite, or outside it after MAX_ITERATIONS)."""
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
        for _ in range(halvings + 1):
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
    # still decreasing at the floor (rounding lets |r| creep down): within is within
    jac = jacobian(x)
    return (x, r, jac) if (np.abs(r) <= tolerance(jac)).all() else None


ANCHORS = 10.0 ** -np.arange(2.0, 17.0, 2.0)
"""The anchor springs of `anchored`, relative to the stiffness scale, softest last."""
SINGULAR = 1e-9
"""Smallest singular value of an n × n J, relative to its largest and per unknown, below which
J counts as singular (`anchored`; the model's check that the mounts hold every DOF)."""
ANCHORED_HALVINGS = 60
"""Step halvings of `anchored`'s solves: a step across a clearance overshoots into the far
stiffer bearing by the ratio of the stiffnesses, and must be cut back to the edge."""


def anchored(
    residual: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    tolerance: Callable[[np.ndarray], np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """`solve` where J is singular at x0 and about it, as inside a clearance (a key's gap, where
    the body is free until it bears): r(x) − ε·(x − x0) = 0, whose anchor spring ε keeps J
    regular, for ε falling from 1e-2 to 1e-16 of |J|'s scale, each from the last solution;
    then `solve` itself from there (bearing, J is regular again). None where it does not get
    there (J at x0 is regular, 0 or not finite: no clearance to leave; a step does not
    converge)."""
    jac0 = jacobian(x0)
    scale = float(np.abs(jac0).max()) if np.isfinite(jac0).all() else 0.0
    if not scale > 0.0:
        return None
    sigma = np.linalg.svd(jac0 / scale, compute_uv=False)
    if sigma[-1] >= SINGULAR * sigma[0] * x0.shape[0]:
        return None
    x = np.array(x0, dtype=float)
    eye = np.eye(x.shape[0])
    for eps in scale * ANCHORS:

        def pulled(z: np.ndarray, e: float = eps) -> np.ndarray:
            return residual(z) - e * (z - x0)

        def pulled_jacobian(z: np.ndarray, e: float = eps) -> np.ndarray:
            return jacobian(z) - e * eye

        found = solve(pulled, pulled_jacobian, x, tolerance, ANCHORED_HALVINGS)
        if found is None:
            return None
        x = found[0]
    return solve(residual, jacobian, x, tolerance, ANCHORED_HALVINGS)
