"""The body prediction's small kernels (`engine.sensor_reading`, `physics.rotations`), written
for few numpy calls a live call, against numpy's own and the textbook formulas, bit for bit, and
the live stream's one row as Python floats against the whole window's numpy arithmetic: the
live stream's output bytes must not depend on how they are computed."""

from __future__ import annotations

import numpy as np
import pytest

from mount_twin.engine.sensor_reading import (
    Differences,
    SensorGeometry,
    _cross,
    _specific_force,
    predicted_reading,
)
from mount_twin.physics.rotations import (
    quaternion_matrices,
    quaternion_matrix_entries,
    rpy_matrices,
    rpy_matrix,
)

RNG = np.random.default_rng(20261128)


def _rows(k: int, width: int = 3) -> np.ndarray:
    """Rows of very different magnitudes, with signed zeros."""
    rows = RNG.normal(size=(k, width)) * 10.0 ** RNG.integers(-8, 8, size=(k, width))
    rows[0, 0], rows[-1, -1] = -0.0, 0.0
    return rows


@pytest.mark.parametrize("k", [1, 5, 1000])
def test_the_cross_product_is_numpys_bit_for_bit(k: int) -> None:
    a, b = _rows(k), _rows(k)
    assert _cross(a, b).tobytes() == np.cross(a, b).tobytes()


@pytest.mark.parametrize("k", [3, 4, 5, 200])
@pytest.mark.parametrize("shape", [(), (3,), (3, 3)])
def test_the_differences_are_np_gradients_at_uneven_stamps(k: int, shape: tuple[int, ...]) -> None:
    # np.gradient's edge_order=2 formulas on uneven spacing are the ones Differences takes
    # (on exactly even spacing numpy switches to another formula, which Differences does not)
    t = 1e3 + np.cumsum(RNG.uniform(1e-4, 2e-3, k))
    f = RNG.normal(size=(k, *shape)) * 10.0 ** RNG.integers(-6, 6)
    expected = np.gradient(f, t, axis=0, edge_order=2)
    assert Differences(t).of(f).tobytes() == expected.tobytes()


def test_the_differences_are_exact_on_a_parabola() -> None:
    t = np.array([0.0, 0.001, 0.0025, 0.003, 0.0052])
    f = (3.0 * t**2 - 2.0 * t + 1.0)[:, None]
    assert np.allclose(Differences(t).of(f)[:, 0], 6.0 * t - 2.0, rtol=0.0, atol=1e-9)


@pytest.mark.parametrize("k", [0, 1, 7, 500])
def test_the_rotation_matrices_are_the_textbook_formulas_bit_for_bit(k: int) -> None:
    quat = RNG.normal(size=(k, 4))
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    if k:
        quat[0] = [0.0, -0.0, 0.0, 1.0]
    x, y, z, w = quat.T
    expected = np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    ).reshape(k, 3, 3)
    assert quaternion_matrices(quat).tobytes() == expected.tobytes()
    one_by_one = [quaternion_matrix_entries(q) for q in quat.tolist()]  # (the one-row path's)
    assert np.array(one_by_one).reshape(k, 3, 3).tobytes() == expected.tobytes()


@pytest.mark.parametrize("k", [1, 5, 300])
@pytest.mark.parametrize("n", [1, 8, 19])
def test_the_mounts_forces_are_summed_in_scene_order_from_zero(k: int, n: int) -> None:
    # Σᵢ Qᵢ fᵢ / m as Python floats, row by row: each mount's Qᵢ fᵢ = fᵢ₀ q₀ + fᵢ₁ q₁ + fᵢ₂ q₂
    # (q_j column j of Qᵢ), added one mount after another to 0.0 in scene order; a row whose
    # terms are all −0.0 sums to +0.0 so, where a sum started from its first term keeps −0.0
    axes = np.abs(RNG.normal(size=(n, 3, 3)))
    axes[0, :, 1] = 0.0
    wrenches = _rows(k * n, 6).reshape(k, n, 6)
    wrenches[0] = -0.0  # every product −0.0 (the axes ≥ 0), so every term
    mass = 812.5
    expected = np.zeros((k, 3))
    for row in range(k):
        for a in range(3):
            total = 0.0
            for i in range(n):
                f = wrenches[row, i, :3].tolist()
                q = axes[i, a, :].tolist()
                total = total + (f[0] * q[0] + f[1] * q[1] + f[2] * q[2])
            expected[row, a] = total / mass
    assert _specific_force(axes, mass, wrenches).tobytes() == expected.tobytes()


@pytest.mark.parametrize("k", [5, 6, 11])
@pytest.mark.parametrize("turning", [True, False])
def test_one_row_inside_a_window_is_the_windows_own_row_bit_for_bit(k: int, turning: bool) -> None:
    # the live stream's wake-up of one message asks for one row with two on each side, which
    # predicted_reading computes as Python floats on those five rows: at every such row of
    # windows of uneven stamps, tilted axes and mounts, the row of the whole window's numpy
    # arithmetic, to the bit (the foundation turning or not: zeros where the scene neglects it)
    n = 8
    geometry = SensorGeometry(
        rpy_matrices([(a, b, c) for a, b, c in RNG.uniform(-3.0, 3.0, (n, 3)).tolist()]),
        812.5,
        RNG.normal(size=3),
        rpy_matrix(*RNG.uniform(-3.0, 3.0, 3).tolist()),
    )
    for _ in range(20):
        t = 1e3 + np.cumsum(RNG.uniform(1e-4, 2e-3, k))
        quat = RNG.normal(size=(k, 4))
        quat /= np.linalg.norm(quat, axis=1, keepdims=True)
        pose = (RNG.normal(size=(k, 3)), quat)
        wrenches = _rows(k * n, 6).reshape(k, n, 6)
        rate = _rows(k) * 1e-3 if turning else np.zeros((k, 3))
        whole = predicted_reading(geometry, t, pose, wrenches, rate)
        for row in range(2, k - 2):
            one = predicted_reading(geometry, t, pose, wrenches, rate, slice(row, row + 1))
            for got, expected in zip(one, whole, strict=True):
                assert got.shape == (1, 3)
                assert got.tobytes() == expected[row : row + 1].tobytes(), (k, row)
        for rows in (slice(0, 1), slice(k - 2, k - 1), slice(2, None), slice(1, k - 1)):
            some = predicted_reading(geometry, t, pose, wrenches, rate, rows)
            for got, expected in zip(some, whole, strict=True):
                assert got.tobytes() == expected[rows].tobytes()
