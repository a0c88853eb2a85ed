"""`newton.solve` and `newton.anchored` on closed-form residuals, apart from any scene.

Truths by hand: the root of a piecewise-linear r with a tangent jump of 1e5–1e9 (a contact far
stiffer than its mount) on its stiff piece, from either side, with the exact one-sided tangents
and with central differences whose step straddles the kink; a 2-D system with a kink in one
coordinate (Cramer's rule on the stiff piece); a cubic (Cardano's formula) and a smooth 2-D
system; a clearance, free until it bears (`anchored`), and a root free within another
clearance (a neutral rest: its Jacobian singular there, taken). None where Newton cannot get
there: a singular Jacobian away from a root, no root.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from mount_twin.model import newton

EPS = float(np.finfo(float).eps)
K_SOFT, EDGE, LOAD = 1.0, 1e-3, 1.0 + 1e-3
"""The soft piece's stiffness (r's units per x's), the kink's position, and the load, which
exceeds K_SOFT·EDGE by 1: the stiff piece K bears 1/(K_SOFT + K) past the edge."""
COARSE, FINE = 1e-7, 1e-12
"""Relative central-difference steps: the compiled Jacobian's (straddling a kink 1e-8 or less
from the root) and the finer one's."""
Field = Callable[[np.ndarray], np.ndarray]


def _floor(jac: np.ndarray) -> np.ndarray:
    """The residual accepted: the rounding floor of a row's largest term on x of order 1."""
    return 64.0 * EPS * np.abs(jac).max(axis=1)


def _kinked(stiff: float) -> Field:
    """r(x) = LOAD − K_SOFT·x − stiff·⟨x − EDGE⟩ (1-D): a mount, and a contact past EDGE."""
    return lambda x: LOAD - K_SOFT * x - stiff * np.maximum(x - EDGE, 0.0)


def _jacobians(residual: Field, tangent: Field, kind: str) -> tuple[Field, newton.Fine | None]:
    """(jacobian, fine) of `solve`: each piece's own `tangent`, or central differences of
    step COARSE with the FINE ones beside."""
    if kind == "tangent":
        return tangent, None
    return (
        lambda x: newton.central(residual, x, COARSE),
        lambda x, reach: newton.central(residual, x, FINE, reach),
    )


@pytest.mark.parametrize("kind", ["tangent", "differences"])
@pytest.mark.parametrize("start", [0.0, -0.5, 1.0, 50.0])
@pytest.mark.parametrize("stiff", [1e5, 1e7, 1e9])
def test_a_root_on_the_stiff_side_of_a_kink_is_found_from_either_side(
    stiff: float, start: float, kind: str
) -> None:
    """r = LOAD − K_SOFT·x − K·⟨x − EDGE⟩, K 1e5–1e9 times K_SOFT: by hand the root is x* =
    EDGE + (LOAD − K_SOFT·EDGE)/(K_SOFT + K), 1e-5–1e-9 past the kink (within the COARSE step
    from 1e8 on). From the soft side (x0 ≤ 0) the first step overshoots into the contact by
    K/K_SOFT; from the stiff side (x0 = 1, 50) it lands on the stiff piece. Found to the
    rounding of x* (a few ulp), with J the stiff piece's tangent there."""
    residual = _kinked(stiff)

    def tangent(x: np.ndarray) -> np.ndarray:
        return np.array([[-K_SOFT - (stiff if x[0] > EDGE else 0.0)]])

    jacobian, fine = _jacobians(residual, tangent, kind)
    found = newton.solve(residual, jacobian, np.array([start]), _floor, fine=fine)
    assert found is not None
    x, r, jac = found
    root = EDGE + (LOAD - K_SOFT * EDGE) / (K_SOFT + stiff)
    np.testing.assert_allclose(x, [root], rtol=4.0 * EPS, atol=0.0)
    assert abs(r[0]) <= _floor(jac)[0]
    if kind == "tangent":
        np.testing.assert_allclose(jac, [[-K_SOFT - stiff]], rtol=0.0)


@pytest.mark.parametrize("kind", ["tangent", "differences"])
@pytest.mark.parametrize("start", [(0.0, 0.0), (0.8, -0.3), (-1.0, 2.0)])
@pytest.mark.parametrize("stiff", [1e5, 1e9])
def test_a_2d_root_past_a_kink_in_one_coordinate_is_cramers(
    stiff: float, start: tuple[float, float], kind: str
) -> None:
    """r = F − A·x − K·⟨x₀ − EDGE⟩·e₀, A = [[2, 1], [1, 3]] coupling the coordinates, F =
    (1, 0.5): the soft root A⁻¹F = (0.5, 0) lies past the kink, so the root is on the stiff
    piece, (A + K·e₀e₀ᵀ)·x = F + K·EDGE·e₀, by Cramer's rule x₀ = (3(1 + K·EDGE) − 0.5)/D,
    x₁ = ((2 + K)·0.5 − (1 + K·EDGE))/D, D = 3(2 + K) − 1."""
    a, f = np.array([[2.0, 1.0], [1.0, 3.0]]), np.array([1.0, 0.5])
    e0 = np.array([1.0, 0.0])

    def residual(x: np.ndarray) -> np.ndarray:
        return f - a @ x - stiff * max(x[0] - EDGE, 0.0) * e0

    def tangent(x: np.ndarray) -> np.ndarray:
        return -a - (stiff if x[0] > EDGE else 0.0) * np.outer(e0, e0)

    jacobian, fine = _jacobians(residual, tangent, kind)
    found = newton.solve(residual, jacobian, np.array(start), _floor, fine=fine)
    assert found is not None
    det = 3.0 * (2.0 + stiff) - 1.0
    root = [
        (3.0 * (1.0 + stiff * EDGE) - 0.5) / det,
        ((2.0 + stiff) * 0.5 - (1.0 + stiff * EDGE)) / det,
    ]
    assert root[0] > EDGE
    x, r, jac = found
    np.testing.assert_allclose(x[0], root[0], rtol=4.0 * EPS)
    # x₁ to its row's floor over its tangent, 64·ε·3/3: |r| stops falling there, at the
    # rounding of K·x₀ (K·ulp(x₀), 2e-10 at 1e9), far above row 1's
    np.testing.assert_allclose(x[1], root[1], rtol=0.0, atol=64.0 * EPS)
    assert (np.abs(r) <= _floor(jac)).all()


def test_a_cubic_root_is_cardanos() -> None:
    """x³ − 2x − 5 = 0 (Wallis's): one real root, by Cardano's formula with p = −2, q = −5,
    x = ∛(−q/2 + √(q²/4 + p³/27)) + ∛(−q/2 − √(q²/4 + p³/27)); from x0 = 3, with its exact
    derivative 3x² − 2. To a few ulp (Cardano's own rounding)."""
    found = newton.solve(
        lambda x: x**3 - 2.0 * x - 5.0,
        lambda x: np.diag(3.0 * x**2 - 2.0),
        np.array([3.0]),
        _floor,
    )
    assert found is not None
    p, q = -2.0, -5.0
    d = math.sqrt(q * q / 4.0 + p**3 / 27.0)
    root = math.cbrt(-q / 2.0 + d) + math.cbrt(-q / 2.0 - d)
    np.testing.assert_allclose(found[0], [root], rtol=4.0 * EPS)
    np.testing.assert_allclose(found[2], [[3.0 * root**2 - 2.0]], rtol=1e-14)


def test_newton_polishes_a_non_linear_root_and_declines_what_it_cannot_solve() -> None:
    """The start's fast path: on a smooth system with a known root it lands at the rounding
    floor and returns the Jacobian at the root; on a singular system, and on one with no root,
    it returns None (the caller then falls back on least squares)."""

    def cubic(x: np.ndarray) -> np.ndarray:  # root (1, −2)
        return np.array([x[0] ** 3 + x[0] - 2.0, x[0] * x[1] + 2.0])

    def cubic_jacobian(x: np.ndarray) -> np.ndarray:
        return np.array([[3.0 * x[0] ** 2 + 1.0, 0.0], [x[1], x[0]]])

    def tight(jac: np.ndarray) -> np.ndarray:
        return np.full(jac.shape[0], 1e-12)

    found = newton.solve(cubic, cubic_jacobian, np.array([3.0, 0.5]), tight)
    assert found is not None
    x, r, jac = found
    np.testing.assert_allclose(x, [1.0, -2.0], rtol=0.0, atol=4e-16)
    assert np.abs(r).max() <= 4e-16
    np.testing.assert_allclose(jac, [[4.0, 0.0], [-2.0, 1.0]], rtol=0.0, atol=1e-12)
    twice = np.array([[1.0, 1.0], [2.0, 2.0]])
    singular = newton.solve(lambda x: twice @ x - 1.0, lambda x: twice, np.zeros(2), tight)
    assert singular is None
    no_root = newton.solve(lambda x: x**2 + 1.0, lambda x: np.diag(2.0 * x), np.ones(1), tight)
    assert no_root is None


CLEARANCE = 5e-4
"""`_clearance`'s gap, x's units."""


def _clearance(stiff: float) -> Field:
    """r(x) = (LOAD − stiff·⟨x₀ − CLEARANCE⟩, 1 − x₁) (2-D): x₀ free within the clearance, a
    key past it; x₁ on a unit spring (its stiffness the scale of `anchored`'s anchors)."""
    return lambda x: np.array([LOAD - stiff * max(x[0] - CLEARANCE, 0.0), 1.0 - x[1]])


@pytest.mark.parametrize("stiff", [1e5, 1e7, 1e9, 1e10, 1e11])
def test_a_clearance_is_left_for_the_key_at_the_closed_form(stiff: float) -> None:
    """Free within CLEARANCE (J singular at x0 = 0: `solve` declines), a key of stiffness K
    past it: `anchored` rests on the key at x₀ = CLEARANCE + LOAD/K, 1e-5 to 1e-11 past the
    edge, x₁ = 1, with central differences (COARSE, and FINE beside): the COARSE step straddles
    the edge from 1e9 on. Before, `anchored` took no finer Jacobian and did not get there.
    From 1e10 on the first anchor's step lands 100 past the edge, where r is 1e12–1e13: the
    step back with COARSE's or FINE's Jacobian, rounded by ε·|r|/step, landed inside the edge
    again (6e-8 at 1e10), and neither Jacobian left it; the fine one there now steps a
    hundredth of the way back (`newton.central`'s reach)."""
    residual = _clearance(stiff)
    jacobian, fine = _jacobians(residual, residual, "differences")
    x0 = np.zeros(2)
    assert newton.solve(residual, jacobian, x0, _floor, fine=fine) is None
    found = newton.anchored(residual, jacobian, x0, _floor, fine)
    assert found is not None
    np.testing.assert_allclose(found[0], [CLEARANCE + LOAD / stiff, 1.0], rtol=4.0 * EPS)


def _two_clearances(stiff: float) -> Field:
    """r(x) = (LOAD − stiff·⟨x₀ − CLEARANCE⟩, −stiff·⟨|x₁| − CLEARANCE⟩·sign x₁, 1 − x₂) (3-D):
    two keys, each free within CLEARANCE, the load pressing only the first; x₂ on a unit
    spring (the scale of `anchored`'s anchors)."""
    return lambda x: np.array(
        [
            LOAD - stiff * max(x[0] - CLEARANCE, 0.0),
            -stiff * max(abs(x[1]) - CLEARANCE, 0.0) * math.copysign(1.0, x[1]),
            1.0 - x[2],
        ]
    )


@pytest.mark.parametrize("stiff", [1e5, 1e9])
def test_a_root_free_within_a_clearance_is_a_neutral_rest_and_taken(stiff: float) -> None:
    """Loaded onto one key, free within the other's clearance: every x₁ within it is a root
    (a neutral rest: J singular there, its column of x₁ zero), and the anchors, pulled to x0,
    keep x₁ where it started. By hand x = (CLEARANCE + LOAD/K, x0₁, 1), and J's row and
    column of x₁ zero. Before, the root reached, `solve`'s step there raised on the singular J
    and none was returned."""
    residual = _two_clearances(stiff)
    jacobian, fine = _jacobians(residual, residual, "differences")
    x0 = np.array([0.0, 0.2 * CLEARANCE, 0.0])
    found = newton.find(residual, jacobian, x0, _floor, fine)
    assert found is not None
    x, r, jac = found
    np.testing.assert_allclose(x, [CLEARANCE + LOAD / stiff, x0[1], 1.0], rtol=4.0 * EPS)
    assert (np.abs(r) <= _floor(jac)).all()
    assert (jac[:, 1] == 0.0).all() and (jac[1] == 0.0).all()  # free along x₁: singular
