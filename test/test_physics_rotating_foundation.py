"""Moving foundation (notes §6): the frame terms of a foundation turning about an axis.

1. A free body (mount of zero stiffness) seen from a foundation spinning up about a fixed axis
   through the sensor point: its inertial motion is a straight CG line and a torque-free tumble
   (independent quaternion integration), so its motion in F is those rotated back by the
   foundation angle ψ(t) = Ω0 t + ½ Ω̇ t². Exercises Coriolis, centrifugal and Euler forces, the
   sensor lever arm, and ω_abs = ω_rel + RᵀΩ in Euler's equations.
2. Foundation turning at constant Ω about z: steady relative offset.

Truth: for a translating body with isotropic horizontal stiffness k, the steady state in the
rotating frame satisfies k x = m Ω² (r + x), so x = m Ω² r / (k − m Ω²) exactly (≈ m Ω² r / k for
small Ω). For the full 6-DOF body, my own nonlinear equilibrium (scipy least_squares on the §7
mount model): mount force = m [f_s + Ω×(Ω×(c + r))] and mount moment = R (ω_a × I ω_a) with
ω_a = RᵀΩ, the steady body spinning with the foundation. Damped mounts let the transient die out.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from physics_helpers import (
    G,
    base_scene,
    build,
    chart_to_matrix_ref,
    inertia_tensor,
    integrate_twin,
    kinematic_matrix_ref,
    mount,
    mount_frames,
    mount_wrench_ref,
    rotation_angle_between,
    torque_free_reference,
)
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine


@pytest.mark.parametrize(
    ("axis", "omega0", "omega_dot", "omega_abs0"),
    [
        # spin-up about z under a body tumbling in space
        ((0.0, 0.0, 1.0), 0.0, 0.5, (0.9, -0.7, 2.5)),
        # constant spin about a tilted axis, body at rest in space
        ((0.25, -0.15, 1.0), 1.5, 0.0, (0.0, 0.0, 0.0)),
        # both, and a slowing spin
        ((-0.1, 0.2, 1.0), 1.0, -0.2, (0.3, 0.2, -0.8)),
    ],
)
def test_free_body_seen_from_a_turning_foundation_moves_as_in_space_rotated_back(
    axis, omega0, omega_dot, omega_abs0
):
    n = np.array(axis) / np.linalg.norm(axis)
    omega_abs0 = np.array(omega_abs0)
    inertia6 = [2.0, 3.0, 4.0, 0.15, -0.1, 0.2]
    cg, sensor = np.array([0.4, -0.3, 0.5]), np.array([0.1, 0.2, -0.1])
    v_rel0 = np.array([0.2, 0.1, -0.05])  # CG velocity relative to F, m/s
    # at t = 0 R = I, so ω_rel = ω_abs − Ω(0) in B = F
    omega_rel0 = omega_abs0 - n * omega0
    rates0 = np.linalg.solve(kinematic_matrix_ref(0.0, 0.0), omega_rel0)
    data = base_scene(
        10.0,
        list(cg),
        inertia6,
        [mount("nothing", list(cg), [0.0] * 6)],
        initial={"mode": "given", "pose": [0.0] * 6, "velocity": [*v_rel0, *rates0]},
    )
    data["input"]["sensor_position"] = list(sensor)
    model = build(data)
    duration = 3.0
    times = np.linspace(0.0, duration, 61)
    u = np.zeros(13)
    u[7:10], u[10:13] = n * omega0, n * omega_dot  # specific force zero: the sensor is at rest
    ys = integrate_twin(
        model, np.concatenate([np.zeros(6), v_rel0, rates0]), times, u, rtol=1e-10, atol=1e-12
    )

    inertia = inertia_tensor(*inertia6)
    ref = torque_free_reference(inertia, omega_abs0, times)
    rho0 = cg - sensor
    v_space = v_rel0 + np.cross(n * omega0, rho0)
    worst_pos, worst_att, tilt = 0.0, 0.0, 0.0
    for j, t in enumerate(times):
        psi = omega0 * t + 0.5 * omega_dot * t**2
        back = Rotation.from_rotvec(-psi * n).as_matrix()  # R_FEᵀ
        rho_f = back @ (rho0 + v_space * t)
        worst_pos = max(worst_pos, np.max(np.abs(cg + ys[j, :3] - sensor - rho_f)))
        rot_ref = back @ Rotation.from_quat(ref.y[:4, j]).as_matrix()
        rot_twin = chart_to_matrix_ref(*ys[j, 3:6])
        worst_att = max(worst_att, rotation_angle_between(rot_twin, rot_ref))
        tilt = max(tilt, math.acos(rot_ref[2, 2]))
    assert worst_pos < 1e-8, f"CG off the rotated straight line by {worst_pos:.3g} m"
    assert worst_att < 1e-8, (
        f"attitude off the rotated torque-free reference by {worst_att:.3g} rad"
    )
    assert tilt > 0.05, "the case should tilt the body relative to F"


def spin(model, omega_z: float, gravity: float, duration: float, rate: float = 1000.0):
    t = np.arange(round(duration * rate) + 1) / rate
    accel = np.tile([0.0, 0.0, gravity], (t.size, 1))
    gyro = np.tile([0.0, 0.0, omega_z], (t.size, 1))
    out = TwinEngine(model).run(SampleBatch(t, accel, gyro, ["deck_imu"] * t.size))
    assert len(out) == t.size
    return out.pose


@pytest.mark.parametrize("omega_z", [1.0, 3.0, -3.0])
def test_translating_body_settles_where_spring_force_balances_centripetal_load(omega_z):
    mass, radius, k_each = 100.0, 0.8, 1.0e5
    cg = [radius, 0.0, 0.3]
    mounts = [
        mount(
            f"m{i}",
            [radius + dx, dy, 0.0],
            [k_each, k_each, 3e5, 0, 0, 0],
            [1500.0, 1500.0, 1500.0, 0, 0, 0],
        )
        for i, (dx, dy) in enumerate([(0.3, 0.2), (0.3, -0.2), (-0.3, 0.2), (-0.3, -0.2)])
    ]
    model = build(base_scene(mass, cg, [8.0, 12.0, 15.0, 0, 0, 0], mounts, dofs=["x", "y"]))
    pose = spin(model, omega_z, 0.0, duration=3.0)
    k = 4 * k_each
    exact = mass * omega_z**2 * radius / (k - mass * omega_z**2)
    small_omega = mass * omega_z**2 * radius / k
    x, y = pose[-1, 0] - radius, pose[-1, 1]
    assert x == pytest.approx(exact, rel=1e-9), f"steady offset {x!r} m, expected {exact!r} m"
    assert abs(y) < 1e-9 * exact
    # the small-Ω closed form m Ω² r / k holds to O(m Ω² / k)
    assert x == pytest.approx(small_omega, rel=2 * mass * omega_z**2 / k)


@pytest.mark.parametrize("gravity", [0.0, G])
def test_six_dof_body_settles_at_the_independent_rotating_frame_equilibrium(gravity):
    mass, omega_z = 100.0, 2.0
    cg = [0.8, 0.3, 0.35]
    inertia6 = [8.0, 12.0, 15.0, 0.5, -1.0, 0.3]
    damping = [1500, 1500, 2000, 5, 5, 5]
    mounts = [
        mount("a", [1.2, 0.6, 0.0], [1e5, 1e5, 2e5, 30, 30, 30], damping, rpy_=(-0.3, 0, 0)),
        mount("b", [1.2, 0.0, 0.0], [1e5, 1.2e5, 2e5, 30, 30, 30], damping, rpy_=(0.3, 0, 0)),
        mount("c", [0.4, 0.6, 0.0], [1e5, 1e5, 2e5, 0, 0, 0], damping),
        mount("d", [0.4, 0.0, 0.0], [1e5, 1e5, 2e5, 0, 0, 0], damping, rpy_=(0, 0.2, 0.1)),
    ]
    data = base_scene(mass, cg, inertia6, mounts)
    pose = spin(build(data), omega_z, gravity, duration=4.0)

    frames, inertia, c = mount_frames(data), inertia_tensor(*inertia6), np.array(cg)
    big_w, f_s = np.array([0.0, 0.0, omega_z]), np.array([0.0, 0.0, gravity])

    def residual(x):
        r, rot = x[:3], Rotation.from_rotvec(x[3:]).as_matrix()
        force, moment, _ = mount_wrench_ref(frames, r, rot)
        w_a = rot.T @ big_w
        return np.concatenate(
            [
                force - mass * (f_s + np.cross(big_w, np.cross(big_w, c + r))),
                moment - rot @ np.cross(w_a, inertia @ w_a),
            ]
        ) / (mass * 10.0)

    sol = least_squares(residual, np.zeros(6), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.max(np.abs(sol.fun)) < 1e-12
    r_ref, rot_ref = sol.x[:3], Rotation.from_rotvec(sol.x[3:]).as_matrix()
    r_twin = pose[-1, :3] - c
    rot_twin = Rotation.from_quat(pose[-1, 3:7]).as_matrix()
    offset = np.linalg.norm(r_ref)
    assert offset > 5e-4, "the centripetal load should shift the body visibly"
    np.testing.assert_allclose(r_twin, r_ref, rtol=0, atol=1e-9 * offset)
    tilt_ref = np.linalg.norm(sol.x[3:])
    err = rotation_angle_between(rot_twin, rot_ref)
    assert err < 1e-9 * tilt_ref + 1e-14, f"attitude off by {err:.3g} rad (tilt {tilt_ref:.3g})"
    # the published chart angles describe the same attitude
    assert math.asin(rot_twin[2, 1]) == pytest.approx(pose[-1, 7], abs=1e-12)
