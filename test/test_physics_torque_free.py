"""A torque-free asymmetric rigid body (mount of zero stiffness and damping, zero specific force).

Truth: conservation of kinetic energy ½ωᵀIω and of |angular momentum| (|R I ω| in F), and an
independent quaternion integration of Euler's equations with scipy's solve_ivp at rtol 1e-12.
The twin integrates on the α/γ/δ chart with its own DOPRI5 stepper (dormand_prince + advance).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from physics_helpers import (
    build,
    chart_to_matrix_ref,
    free_body,
    inertia_tensor,
    integrate_twin,
    kinematic_matrix_ref,
    rotation_angle_between,
    torque_free_reference,
)
from scipy.spatial.transform import Rotation

INERTIA6 = [2.0, 3.0, 4.0, 0.15, -0.1, 0.2]  # kg·m², asymmetric with products of inertia
OMEGA0 = np.array([0.9, -0.7, 2.5])  # rad/s in B: tumbles to ~42° of tilt, inside the chart
V0 = np.array([0.1, -0.2, 0.3])  # m/s: the CG must fly straight
DURATION = 6.0
TIMES = np.linspace(0.0, DURATION, 121)


@pytest.fixture(scope="module")
def tumble():
    """Twin run and quaternion reference on the same time grid."""
    inertia = inertia_tensor(*INERTIA6)
    chart_rates0 = np.linalg.solve(kinematic_matrix_ref(0.0, 0.0), OMEGA0)
    model = build(free_body(INERTIA6, OMEGA0, tuple(V0)))
    y0 = np.concatenate([np.zeros(6), V0, chart_rates0])
    ys = integrate_twin(model, y0, TIMES, np.zeros(13), rtol=1e-10, atol=1e-12)
    ref = torque_free_reference(inertia, OMEGA0, TIMES)
    rots = [chart_to_matrix_ref(*y[3:6]) for y in ys]
    omegas = [kinematic_matrix_ref(y[3], y[4]) @ y[9:12] for y in ys]
    return {
        "inertia": inertia,
        "ys": ys,
        "rots": rots,
        "omegas": omegas,
        "ref_rots": [Rotation.from_quat(q).as_matrix() for q in ref.y[:4].T],
        "ref_omegas": list(ref.y[4:].T),
    }


def test_the_tumble_reaches_a_large_tilt_inside_the_chart(tumble):
    tilt = max(math.degrees(math.acos(r[2, 2])) for r in tumble["rots"])
    chart_margin = max(abs(y[3]) + abs(y[4]) for y in tumble["ys"])
    assert 30.0 < tilt < 50.0, (
        f"tilt reached {tilt:.1f}°: the test no longer exercises large angles"
    )
    assert chart_margin < 0.95 * math.pi / 2


def test_kinetic_energy_is_conserved(tumble):
    inertia = tumble["inertia"]
    energy = np.array([0.5 * w @ inertia @ w for w in tumble["omegas"]])
    drift = np.max(np.abs(energy / energy[0] - 1.0))
    assert drift < 1e-8, f"kinetic energy drifted by {drift:.3g} (relative)"


def test_angular_momentum_magnitude_and_direction_in_space_are_conserved(tumble):
    inertia = tumble["inertia"]
    momentum = np.array(
        [r @ inertia @ w for r, w in zip(tumble["rots"], tumble["omegas"], strict=True)]
    )
    norm_drift = np.max(np.abs(np.linalg.norm(momentum, axis=1) / np.linalg.norm(momentum[0]) - 1))
    vector_drift = np.max(np.linalg.norm(momentum - momentum[0], axis=1)) / np.linalg.norm(
        momentum[0]
    )
    assert norm_drift < 1e-8, f"|R I ω| drifted by {norm_drift:.3g} (relative)"
    assert vector_drift < 1e-8, f"R I ω (in the inertial F) drifted by {vector_drift:.3g}"


def test_attitude_agrees_with_an_independent_quaternion_integration(tumble):
    errors = [
        rotation_angle_between(r, q)
        for r, q in zip(tumble["rots"], tumble["ref_rots"], strict=True)
    ]
    worst = max(errors)
    assert worst < 1e-8, f"attitude differs from the quaternion reference by {worst:.3g} rad"


def test_body_rates_agree_with_the_independent_euler_equations(tumble):
    worst = max(
        np.max(np.abs(w - w_ref))
        for w, w_ref in zip(tumble["omegas"], tumble["ref_omegas"], strict=True)
    )
    assert worst < 1e-8 * np.linalg.norm(OMEGA0), f"ω differs from the reference by {worst:.3g}"


def test_centre_of_gravity_moves_in_a_straight_line_without_forces(tumble):
    ys = tumble["ys"]
    expected = np.outer(TIMES, V0)
    np.testing.assert_allclose(ys[:, :3], expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ys[:, 6:9], np.tile(V0, (TIMES.size, 1)), rtol=0, atol=1e-13)
