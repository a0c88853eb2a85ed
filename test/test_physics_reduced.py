"""A reduced scene (dofs z, α, γ: x, y, δ keyed) against the full 6-DOF scene whose x, y and δ are
held by very stiff springs (notes §5: the reduced model must agree with that limit).

The keys are exact realizations of the holonomic constraints x = y = δ = 0 in the stiff limit:
one mount at the CG with only k_x (d = r, no lever arm), and two mounts at the CG height, ±L along
x from the CG, with only k_y: their y deformations y ± L sin δ cos γ vanish only if y = 0 and
δ = 0. (A rotational spring about z would hold the rotation vector's z component instead, which
differs from δ at second order.) Both scenes see the same rolling and pitching deck through
TwinEngine; the discrepancy must vanish like 1/k_key.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from physics_helpers import G, base_scene, build, mount, rpy

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine

MASS = 200.0
CG = [0.02, 0.01, 0.4]
INERTIA6 = [20.0, 30.0, 35.0, 1.0, -2.0, 0.5]
MOUNTS = [
    mount(
        "fl",
        [0.5, 0.35, 0.0],
        [1e5, 1e5, 3e5, 50, 50, 50],
        [100, 100, 300, 1, 1, 1],
        rpy_=(-0.4, 0.0, 0.0),
    ),
    mount(
        "fr",
        [0.5, -0.35, 0.0],
        [1e5, 1e5, 3e5, 50, 50, 50],
        [100, 100, 300, 1, 1, 1],
        rpy_=(0.4, 0.0, 0.0),
    ),
    mount("rl", [-0.5, 0.35, 0.0], [1.2e5, 1e5, 2.5e5, 0, 0, 0], [100, 100, 300, 0, 0, 0]),
    mount(
        "rr",
        [-0.5, -0.35, 0.0],
        [1.2e5, 1e5, 2.5e5, 0, 0, 0],
        [100, 100, 300, 0, 0, 0],
        rpy_=(0.0, 0.2, 0.0),
    ),
]
KEY_ARM = 0.5  # m
COMPARED = {"z": 2, "alpha": 7, "gamma": 8}  # pose columns


def keys(k_key: float) -> list[dict]:
    x, y, z = CG
    return [
        mount("key_x", [x, y, z], [k_key, 0, 0, 0, 0, 0]),
        mount("key_y_front", [x + KEY_ARM, y, z], [0, k_key, 0, 0, 0, 0]),
        mount("key_y_rear", [x - KEY_ARM, y, z], [0, k_key, 0, 0, 0, 0]),
    ]


def deck_motion(rate: float = 1000.0, duration: float = 1.5) -> SampleBatch:
    """Deck attitude Rx(φ)·Ry(θ) relative to the earth, sensed at the rotation centre (origin of
    F): Ω in F = Ry(θ)ᵀ(φ', 0, 0) + (0, θ', 0), specific force Rᵀ(0, 0, g) plus an 8 Hz heave."""
    t = np.arange(round(duration * rate) + 1) / rate
    a_r, w_r, a_p, w_p = 0.05, 2 * math.pi * 1.5, 0.03, 2 * math.pi * 2.3
    phi, phi_d = a_r * (1 - np.cos(w_r * t)), a_r * w_r * np.sin(w_r * t)
    th, th_d = a_p * (1 - np.cos(w_p * t)), a_p * w_p * np.sin(w_p * t)
    accel, gyro = np.zeros((t.size, 3)), np.zeros((t.size, 3))
    for j in range(t.size):
        ry = rpy(0.0, th[j], 0.0)
        accel[j] = (rpy(phi[j], 0.0, 0.0) @ ry).T @ np.array([0.0, 0.0, G])
        gyro[j] = ry.T @ np.array([phi_d[j], 0.0, 0.0]) + np.array([0.0, th_d[j], 0.0])
    accel[:, 2] += 0.5 * np.sin(2 * math.pi * 8.0 * t)
    return SampleBatch(t, accel, gyro, ["deck_imu"] * t.size)


def run(data: dict, batch: SampleBatch) -> np.ndarray:
    out = TwinEngine(build(data)).run(batch)
    assert len(out) == len(batch)
    return out.pose


@pytest.fixture(scope="module")
def batch():
    return deck_motion()


@pytest.fixture(scope="module")
def reduced_pose(batch):
    data = base_scene(
        MASS, CG, INERTIA6, MOUNTS, dofs=["z", "alpha", "gamma"], rtol=1e-10, atol=1e-13
    )
    return run(data, batch)


def full_pose(batch, k_key: float) -> np.ndarray:
    data = base_scene(MASS, CG, INERTIA6, MOUNTS + keys(k_key), rtol=1e-8, atol=1e-11)
    return run(data, batch)


def discrepancy(reduced: np.ndarray, full: np.ndarray) -> dict[str, float]:
    """Largest difference per compared coordinate, relative to its peak excursion."""
    out = {}
    for name, col in COMPARED.items():
        peak = np.max(np.abs(reduced[:, col] - reduced[0, col]))
        out[name] = float(np.max(np.abs(full[:, col] - reduced[:, col])) / peak)
    return out


def test_reduced_scene_matches_the_full_scene_with_very_stiff_keys(batch, reduced_pose):
    full = full_pose(batch, 1e11)
    rel = discrepancy(reduced_pose, full)
    # the deck really moves the body in all three compared coordinates
    assert np.ptp(reduced_pose[:, 2]) > 1e-4 and np.ptp(reduced_pose[:, 7:9], axis=0).min() > 1e-4
    assert max(rel.values()) < 5e-5, f"reduced vs stiff-key full model: {rel}"
    # the keys do hold x, y and δ of the full model
    np.testing.assert_allclose(full[:, 0:2], np.tile(CG[:2], (len(batch), 1)), rtol=0, atol=1e-7)
    assert np.max(np.abs(full[:, 9])) < 1e-8


def test_reduced_scene_is_the_limit_of_stiffer_and_stiffer_keys(batch, reduced_pose):
    """Ten times stiffer keys, ten times closer (±20 %)."""
    soft = discrepancy(reduced_pose, full_pose(batch, 1e9))
    stiff = discrepancy(reduced_pose, full_pose(batch, 1e10))
    for name in COMPARED:
        ratio = soft[name] / stiff[name]
        assert 8.0 < ratio < 12.0, (
            f"{name}: discrepancy {soft[name]:.3g} at k=1e9 and {stiff[name]:.3g} at k=1e10 "
            f"(ratio {ratio:.3g}, expected ~10 for a 1/k constraint error)"
        )
