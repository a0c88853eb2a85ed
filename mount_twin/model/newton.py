"""Damped Newton's method for a small square system r(x) = 0: the start equilibrium's fast
path.

The start's equilibrium is a handful of coordinates on mounts that are linear or piecewise
linear near rest: Newton lands and polishes in three Jacobians (0.2 ms on the genset, its
Jacobians in compiled code), where scipy's trust-region least squares spent 1.5–3 ms of
bookkeeping on its evaluations, a tenth of the engine's time on a 0.25 s shock record. Where
Newton does not get there (a singular Jacobian away from a root), it says so and the
caller falls back on the robust solver.

A contact far stiffer than the mounts (a snubber, a key or a bolt that bears; k_s 1e5–1e7
times k) makes r piecewise smooth with a jump in its tangent, which plain damping does not
cross: halving a step from the soft side creeps along the contact's edge (the step k_s/k
times too long at each), and |r|, mixing the pieces, has a false minimum on the edge, where
least squares stalls too. `solve` follows the Newton steps of the piece it lands on instead
(semismooth Newton: each piece's own tangent; for a stiffening contact they fall
monotonically from the stiff side), and near a root within a difference step of an edge
takes a finer Jacobian. A load continuation would meet the same edge at one of its loads,
and scaling r by the tangent does not remove a tangent that jumps. A continuation in the
contacts' stiffness is the caller's (`model.assemble.CONTINUATION`), where Newton does not get
there: a root within a difference step of several stiff contacts' edges, reached from a
plateau.

Between a tangent and its jump r may be flat: a body within a key's clearance, or a bolted
joint's face sliding at its friction bound μ·F_K, whatever the slide, until the shank bears on
its hole past the clearance (a heel past the friction bound). Newton's step there is singular,
or across the plateau by orders of magnitude where faces slide along different directions;
`find` leaves the plateau on an anchor spring (`anchored`) from where `solve` stopped on it.
The root itself may lie on a plateau along some direction (heeled onto keys along x, the body
still within the clearances of those along y): J is singular there, and the root is taken.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

Landing = tuple[np.ndarray, np.ndarray]
"""Where a step lands, and r there."""
Found = tuple[np.ndarray, np.ndarray, np.ndarray]
"""A root x, r(x) there (within the tolerance), and J = ∂r/∂x there."""
Fine = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""∂r/∂x at x by a finer difference step, given how far the last Newton step from x reached
along each x_c (`central`'s `reach`)."""
MAX_ITERATIONS = 20
MAX_HALVINGS = 8
"""Backtracking: the Newton step is halved at most this often while |r| does not decrease."""


def solve(
    residual: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    tolerance: Callable[[np.ndarray], np.ndarray],
    halvings: int = MAX_HALVINGS,
    fine: Fine | None = None,
    limit: np.ndarray | None = None,
) -> Found | None:
    """x with |r(x)| ≤ tolerance(J) component-wise (J = jacobian(x) = ∂r/∂x), from x0,
    polished until a Newton step no longer reduces |r| (the rounding floor, where the
    least-squares solver also ends); returns (x, r(x), J at x), or None where Newton does not
    get there (singular J outside the tolerance: within it, x is a root where the body rests
    free along a direction, a neutral equilibrium, such as along keys' clearances while other
    keys bear; no decrease of |r| outside the tolerance in `halvings` halvings of
    the step, not finite, or outside it after MAX_ITERATIONS).

    r piecewise smooth, a contact's stiffness k_s switching on at a kink (the module's note):

    - where the Newton step, across a kink onto the stiffer piece, does not decrease |r|: the
      Newton steps from where it landed, each with the Jacobian there, while |r| falls, to
      below |r(x)| (`_ahead`), before halving the step;
    - where the step misses the root by half |r| or more, outside the tolerance, and at each
      of those steps from where it landed: also the step with `fine` (∂r/∂x by a finer
      difference step), the better taken. A root within a difference step of a kink (a
      contact bearing k_s·δ, δ under the step: 1 N on 1e9 N/m) has a Jacobian that averages
      the two pieces, and Newton with it crawls or cycles.

    Where each step of `jacobian` lands within half |r| neither is tried. Each step is
    shortened along itself where it would move an x_c by more than limit_c (`_limited`)."""
    return _solve(residual, jacobian, x0, tolerance, halvings, fine, limit)[0]


def _solve(
    residual: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    tolerance: Callable[[np.ndarray], np.ndarray],
    halvings: int,
    fine: Fine | None,
    limit: np.ndarray | None,
) -> tuple[Found | None, np.ndarray]:
    """`solve`'s result, and the last x it took (x0 where it took none): where it did not get
    there, the place it stopped (`find` leaves a plateau of r from there)."""
    x = np.array(x0, dtype=float)
    r = residual(x)
    for _ in range(MAX_ITERATIONS):
        if not np.isfinite(r).all():
            return None, x
        jac = jacobian(x)
        within = bool((np.abs(r) <= tolerance(jac)).all())
        landing = _newton_step(residual, x, r, jac, limit)
        if landing is None:  # a root where J is singular is a neutral rest: taken
            return ((x, r, jac) if within else None), x
        norm = float(np.linalg.norm(r))
        landed, r_landed = landing
        best = landing if within else _or_fine(residual, fine, x, r, landing, limit)
        if best is not None and np.linalg.norm(best[1]) < norm:
            x, r = best
            continue
        if within:  # at the floor: polished
            return (x, r, jac), x
        ahead = _ahead(residual, jacobian, fine, landed, r_landed, norm, limit)
        if ahead is not None:
            x, r = ahead
            continue
        halved = _halved(residual, x, r, landed - x, halvings)
        if halved is None:
            return None, x
        x, r = halved
    # still decreasing at the floor (rounding lets |r| creep down): within is within
    jac = jacobian(x)
    return ((x, r, jac) if (np.abs(r) <= tolerance(jac)).all() else None), x


REACH_SHARE = 1e-2
"""`central`'s difference step along x_c, at least this share of the reach given there."""


def central(
    residual: Callable[[np.ndarray], np.ndarray],
    x: np.ndarray,
    step: float,
    reach: np.ndarray | None = None,
) -> np.ndarray:
    """∂r/∂x at x by central differences, of step `step`·max(1, |x_c|) along x_c, or
    REACH_SHARE·|reach_c| where that is longer (reach: how far the last Newton step from x
    went along each x_c). A step relative to x alone is good near a kink; far past one, where
    r is a stiff contact's force on a deep penetration, its rounding (ε·|r|/step) grows with
    the depth, and the Newton step back lands off by depth² times ε/step: inside the contact's
    edge again, where the root is 1e-11 past it (a key 1e11 times the other stiffnesses). A step
    of a share of the reach is far from that kink, which is where the step back goes, and
    rounds |reach|/REACH_SHARE times less."""
    columns = []
    for c in range(x.shape[0]):
        up, down = x.copy(), x.copy()
        h = step * max(1.0, abs(x[c]))
        if reach is not None:
            h = max(h, REACH_SHARE * abs(reach[c]))
        up[c] += h
        down[c] -= h
        columns.append((residual(up) - residual(down)) / (up[c] - down[c]))
    return np.column_stack(columns)


def _ahead(
    residual: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    fine: Fine | None,
    x: np.ndarray,
    r: np.ndarray,
    norm: float,
    limit: np.ndarray | None,
) -> Landing | None:
    """Newton steps from x (r there, |r| ≥ `norm`), each with the Jacobian where it starts, while
    |r| falls, to the first (x, r) with |r| below `norm`; None where |r| stops falling first
    (at most MAX_ITERATIONS steps). Each step as `solve`'s: with `fine` too where `jacobian`'s
    misses by half |r| (these steps end within a difference step of the kinks they crossed:
    two contacts there, `jacobian` averaging both, crawled by a few % a step), and halved
    while it does not decrease |r|, at most MAX_HALVINGS times: on the stiff piece the step of
    its own tangent is a direction along which |r| falls, but a full one can cross further
    kinks (shanks that bear past clearances of their own as the body turns)."""
    for _ in range(MAX_ITERATIONS):
        landed = _newton_step(residual, x, r, jacobian(x), limit)
        found = _or_fine(residual, fine, x, r, landed, limit, norm)
        if found is not None and not np.linalg.norm(found[1]) < np.linalg.norm(r):
            found = _halved(residual, x, r, found[0] - x, MAX_HALVINGS)
        if found is None:
            return None
        x, r = found
        if np.linalg.norm(r) < norm:
            return x, r
    return None


def _halved(
    residual: Callable[[np.ndarray], np.ndarray],
    x: np.ndarray,
    r: np.ndarray,
    step: np.ndarray,
    halvings: int,
) -> Landing | None:
    """(x + s, its r) for the first s of `step`/2, `step`/4, ... (at most `halvings` of them)
    where |r| is below |r(x)|; None where none is."""
    norm = np.linalg.norm(r)
    for _ in range(halvings):
        step = step * 0.5
        r_new = residual(x + step)
        if np.linalg.norm(r_new) < norm:
            return x + step, r_new
    return None


def _newton_step(
    residual: Callable[[np.ndarray], np.ndarray],
    x: np.ndarray,
    r: np.ndarray,
    jac: np.ndarray,
    limit: np.ndarray | None,
) -> Landing | None:
    """(x + s, its r) for the Newton step s from x (r there) with `jac`, `_limited`; None where
    singular."""
    try:
        x_new = x + _limited(np.linalg.solve(jac, -r), limit)
    except np.linalg.LinAlgError:
        return None
    return x_new, residual(x_new)


def _limited(step: np.ndarray, limit: np.ndarray | None) -> np.ndarray:
    """`step` shortened along itself so that no |step_c| passes limit_c (None: no limit)."""
    if limit is None:
        return step
    over = float(np.max(np.abs(step) / limit))
    return step / over if over > 1.0 else step


def _or_fine(
    residual: Callable[[np.ndarray], np.ndarray],
    fine: Fine | None,
    x: np.ndarray,
    r: np.ndarray,
    landed: Landing | None,
    limit: np.ndarray | None,
    goal: float | None = None,
) -> Landing | None:
    """`landed` (x + s, r there: a Newton step from x, r at x; None: singular), or, where it
    misses by half |r| or more, the step with `fine` where that lands at a smaller |r|. With a
    `goal` (`_ahead`'s: the |r| to get below, from where a step crossed onto a stiffer piece),
    half the smaller of |r| and the goal, and `fine` with the reach of the step from x: there x
    is far past a kink, |r| the stiff piece's far larger force."""
    bar = float(np.linalg.norm(r)) if goal is None else min(float(np.linalg.norm(r)), goal)
    if fine is None or (landed is not None and np.linalg.norm(landed[1]) < 0.5 * bar):
        return landed
    reach = np.zeros_like(x) if goal is None or landed is None else landed[0] - x
    finer = _newton_step(residual, x, r, fine(x, reach), limit)
    if landed is None or (
        finer is not None and np.linalg.norm(finer[1]) < np.linalg.norm(landed[1])
    ):
        return finer
    return landed


ANCHORS = 10.0 ** -np.arange(2.0, 17.0, 2.0)
"""The anchor springs of `anchored`, relative to the stiffness scale, softest last."""
SINGULAR = 1e-9
"""Smallest singular value of an n × n J, relative to its largest and per unknown, below which
J counts as singular (the model's check that the mounts hold every DOF)."""
ANCHORED_HALVINGS = 60
"""Step halvings of `anchored`'s solves: a step across a clearance overshoots into the far
stiffer bearing by the ratio of the stiffnesses, and must be cut back to the edge."""


def find(
    residual: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    tolerance: Callable[[np.ndarray], np.ndarray],
    fine: Fine | None = None,
    limit: np.ndarray | None = None,
    scale: Callable[[], float] | None = None,
) -> Found | None:
    """`solve` from x0, and where it does not get there, `anchored` from where it stopped: on
    a plateau of r, where J is singular or nearly so (at x0 within a clearance; or where a step
    landed with the friction faces sliding at their bounds, μ·F_K whatever the slide, before the
    shanks bear on their holes: the Newton step there is singular, or, where the faces slide
    along different directions, so long that it crosses the clearance by orders of magnitude).
    None where neither gets there. Each step `_limited` by `limit`; `scale` as `anchored`'s."""
    found, stopped = _solve(residual, jacobian, x0, tolerance, MAX_HALVINGS, fine, limit)
    if found is not None:
        return found
    return anchored(residual, jacobian, stopped, tolerance, fine, limit, scale)


def anchored(
    residual: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    tolerance: Callable[[np.ndarray], np.ndarray],
    fine: Fine | None = None,
    limit: np.ndarray | None = None,
    scale: Callable[[], float] | None = None,
) -> Found | None:
    """`solve` where J is singular or nearly so at x0 and about it, as inside a clearance (a
    key's gap, where the body is free until it bears) or along faces sliding at their friction
    bounds (r then constant, not zero, until the shanks bear): r(x) − ε·(x − x0) = 0, whose
    anchor spring ε keeps J regular, for ε falling from 1e-2 to 1e-16 of |J|'s scale (its
    largest entry at x0; where J at x0 is 0, `scale()`'s, r's units per x's: a body within
    clearances along every direction, nothing else holding it, such as keys along z carrying
    the weight from within their clearance), each from the last solution; then `solve` itself
    from there (bearing, J is regular again), each with `fine` (a key bearing less than its
    stiffness times the difference step has its root within that step of the clearance's
    edge). Where J is regular about x0 the anchors only
    lead `solve` to its root. None where it does not get there (J at x0 is not finite, or 0
    without a `scale`; a step does not converge)."""
    jac0 = jacobian(x0)
    if not np.isfinite(jac0).all():
        return None
    largest = float(np.abs(jac0).max())
    if largest == 0.0 and scale is not None:
        largest = scale()
    if not largest > 0.0:
        return None
    x = np.array(x0, dtype=float)
    for eps in largest * ANCHORS:

        def pulled(z: np.ndarray, e: float = eps) -> np.ndarray:
            return residual(z) - e * (z - x0)

        pulled_fine = None if fine is None else _anchor(fine, eps)
        found = solve(
            pulled, _anchor(jacobian, eps), x, tolerance, ANCHORED_HALVINGS, pulled_fine, limit
        )
        if found is None:
            return None
        x = found[0]
    return solve(residual, jacobian, x, tolerance, ANCHORED_HALVINGS, fine, limit)


def _anchor(jacobian: Callable[..., np.ndarray], eps: float) -> Callable[..., np.ndarray]:
    """The Jacobian of `anchored`'s r(x) − ε·(x − x0): jacobian(x, ...) − ε·I (ε = `eps`, r's
    units per x's; the compiled Jacobian's or `fine`'s, with its reach)."""
    return lambda z, *reach: jacobian(z, *reach) - eps * np.eye(z.shape[0])
