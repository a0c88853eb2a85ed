"""Static equilibrium holds at any stiffness: stiff, light scenes load (an absolute residual
threshold refused them), the equilibrium matches the closed form, and a DOF no mount holds is
still refused."""

from __future__ import annotations

import math

import numpy as np
import pytest
from physics_helpers import base_scene, mount

from mount_twin.errors import ModelError
from mount_twin.model import newton
from mount_twin.model.assemble import assemble, initial_state
from mount_twin.scene.loader import scene_from_dict

CORNERS = [(0.4, 0.3), (-0.4, 0.3), (-0.4, -0.3), (0.4, -0.3)]


def _model(mass: float, k: float, stiffness_axes: tuple[float, float, float] = (1, 1, 1)):
    """`mass` on four equal isotropic (or as given) mounts in the plane of the CG."""
    kx, ky, kz = (k * a for a in stiffness_axes)
    mounts = [
        mount(f"m{i}", (x, y, 0.5), (kx, ky, kz, 0, 0, 0)) for i, (x, y) in enumerate(CORNERS)
    ]
    data = base_scene(mass, [0.0, 0.0, 0.5], [mass * 0.1] * 3 + [0.0] * 3, mounts)
    return assemble(scene_from_dict(data, "<equilibrium test>"))


@pytest.mark.parametrize(("mass", "k"), [(1.0, 1e10), (10.0, 1e11), (10.0, 1e9), (1e4, 1e5)])
@pytest.mark.parametrize(
    ("magnitude", "tilt"), [(m, t) for m in (8.0, 9.80665, 11.5) for t in (0.0, 0.2, -0.35)]
)
def test_the_equilibrium_of_stiff_light_scenes_is_found_and_is_the_closed_form(
    mass: float, k: float, magnitude: float, tilt: float
) -> None:
    """Isotropic mounts in the CG's plane, symmetric: the body translates by m·f/(4k) against
    the specific force f (the mounts push it back toward f), without rotating."""
    f = magnitude * np.array([0.0, math.sin(tilt), math.cos(tilt)])
    y = initial_state(_model(mass, k), f)
    np.testing.assert_allclose(y[:3], -mass * f / (4.0 * k), rtol=1e-6, atol=1e-300)
    assert np.abs(y[3:6]).max() <= 1e-12


def test_a_dof_no_mount_holds_is_still_refused_at_load() -> None:
    """Mounts stiff along z only: nothing holds x, and assembly (which solves the nominal
    start state) refuses the scene by naming it."""
    with pytest.raises(ModelError, match="DOF x is not held by any mount"):
        _model(10.0, 1e9, (0.0, 0.0, 1.0))


def test_a_start_on_a_turning_deck_rests_relative_to_it() -> None:
    """A deck turning steadily at 1.4 rad/s about z (a turntable; sensor on the axis reads g):
    started at the equilibrium that includes the centrifugal load, the pump stays put relative
    to the deck; the equilibrium without it differs by far more than the motion that follows."""
    from io_helpers import batch, default_model, engine_for

    omega = np.array([0.0, 0.0, 1.4])
    n = 1000
    gyro = np.tile(omega, (n, 1))
    engine = engine_for()
    out = engine.push(batch(1.0 + np.arange(n) * 1e-3, gyro=gyro))
    drift = np.abs(out.pose[:, :3] - out.pose[0, :3]).max()
    g_up = np.array([0.0, 0.0, 9.80665])
    shift = np.abs(
        initial_state(default_model(), g_up, omega)[:3] - initial_state(default_model(), g_up)[:3]
    ).max()
    assert shift > 1e-6  # m: the centrifugal load moves the equilibrium
    assert drift < 1e-4 * shift


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
