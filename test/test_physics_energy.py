"""Conservation of energy on undamped linear mounts: the twin's 6-DOF motion after a large
initial displacement and spin, foundation at rest under gravity, keeps
E = ½·m·|q̇|² + ½·ωᵀIω + Σ (½·dᵀK_t·d + ½·φᵀK_r·φ) + m·g·z constant (d = q + R·p − p per
mount, φ the rotation vector of R, scipy's).

Anisotropic rotational springs turned far (0.4 rad) check that the couple is the gradient of
½·φᵀK_r·φ: the couple −K_r·φ, conservative only for isotropic K_r, drifted there by 6.4e3 J of
7.4e4 J in 4 s. E is computed here from the chart (notes §2, §3), not from the twin's code.
"""

from __future__ import annotations

import numpy as np
import pytest
from physics_helpers import (
    G,
    base_scene,
    build,
    chart_to_matrix_ref,
    gravity_u,
    integrate_twin,
    kinematic_matrix_ref,
    mount,
    mount_frames,
)
from scipy.spatial.transform import Rotation

MASS = 900.0
INERTIA = [180.0, 260.0, 300.0, 12.0, -20.0, 6.0]  # Ixx Iyy Izz Ixy Ixz Iyz, kg·m²
ANISOTROPIC = (4e5, 5e5, 1.3e6, 2e4, 6e4, 1.2e5)  # N/m, N·m/rad: rotational 1 : 3 : 6
ROTATIONAL_MOUNTS = [
    mount("a", (0.7, 0.45, -0.3), ANISOTROPIC, rpy_=(0.3, 0.0, 0.2)),
    mount("b", (-0.6, -0.5, -0.35), ANISOTROPIC, rpy_=(-0.4, 0.1, 0.0)),
]
MOUNTS = [
    mount("a", (0.7, 0.45, -0.3), (4e5, 5e5, 1.3e6, 0, 0, 0), rpy_=(0.3, 0.0, 0.2)),
    mount("b", (0.6, -0.5, -0.35), (6e5, 3e5, 1.1e6, 0, 0, 0), rpy_=(-0.4, 0.1, 0.0)),
    mount("c", (-0.8, 0.4, -0.25), (5e5, 5e5, 0.9e6, 0, 0, 0), rpy_=(0.0, -0.3, 0.5)),
    mount("d", (-0.7, -0.45, -0.3), (3e5, 6e5, 1.4e6, 0, 0, 0)),
    mount("e", (0.0, 0.0, 0.4), (2e5, 2e5, 2e5, 0, 0, 0), rpy_=(0.2, 0.2, 0.2)),
]


def _energy(data: dict, y: np.ndarray, g: float = G) -> float:
    """E of state y = (q, q̇) (notes: q = x, y, z m, α, γ, δ rad) under gravity g (m/s²)."""
    q, qd = y[:6], y[6:12]
    ixx, iyy, izz, ixy, ixz, iyz = INERTIA
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    omega = kinematic_matrix_ref(q[3], q[4]) @ qd[3:]  # in B
    rot = chart_to_matrix_ref(*q[3:])
    phi = Rotation.from_matrix(rot).as_rotvec()
    kinetic = 0.5 * MASS * qd[:3] @ qd[:3] + 0.5 * omega @ inertia @ omega
    elastic = 0.0
    for fr in mount_frames(data):
        d = q[:3] + rot @ fr["p"] - fr["p"]
        elastic += 0.5 * d @ fr["kt"] @ d + 0.5 * phi @ fr["kr"] @ phi
    return kinetic + elastic + MASS * g * q[2]


@pytest.mark.parametrize("spin", [0.0, 2.0])
def test_energy_is_conserved_without_damping(spin: float) -> None:
    initial = {
        "mode": "given",
        "pose": [0.006, -0.004, 0.01, 0.05, -0.04, 0.06],
        "velocity": [0.05, 0.02, -0.08, 0.3 * spin, -0.2 * spin, 0.5 * spin],
    }
    data = base_scene(MASS, [0.05, 0.02, 0.0], INERTIA, MOUNTS, initial=initial)
    model = build(data)
    y0 = np.array([*initial["pose"], *initial["velocity"]])
    times = np.linspace(0.0, 2.0, 401)
    states = integrate_twin(model, y0, times, gravity_u(), 1e-11, 1e-14)
    energy = np.array([_energy(data, y) for y in states])
    swing = np.ptp([0.5 * MASS * y[8] ** 2 for y in states])  # energy that moves about
    assert swing > 1.0, "the motion exchanges energy between forms"
    assert np.abs(energy - energy[0]).max() < 1e-8 * swing


def test_anisotropic_rotational_springs_conserve_energy_at_finite_rotation() -> None:
    """No gravity, turned 0.4 rad and let go: the rotational springs trade 7e4 J with the
    spin; the energy keeps to the integration tolerance."""
    initial = {"mode": "given", "pose": [0.0, 0.0, 0.0, 0.3, -0.25, 0.4], "velocity": [0.0] * 6}
    data = base_scene(MASS, [0.0, 0.0, 0.0], INERTIA, ROTATIONAL_MOUNTS, initial=initial)
    data["input"]["g"] = 0.0
    model = build(data)
    times = np.linspace(0.0, 4.0, 801)
    y0 = np.array([*initial["pose"], *initial["velocity"]])
    states = integrate_twin(model, y0, times, gravity_u((0.0, 0.0, 0.0)), 1e-12, 1e-14)
    energy = np.array([_energy(data, y, 0.0) for y in states])
    angle = [Rotation.from_matrix(chart_to_matrix_ref(*y[3:6])).magnitude() for y in states]
    assert min(angle) < 0.1 and max(angle) > 0.4, "the springs swing the body through rest"
    assert energy[0] > 1e4
    assert np.abs(energy - energy[0]).max() < 1e-9 * energy[0]
