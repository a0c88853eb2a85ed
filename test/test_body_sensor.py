"""The body IMU's predicted reading (`engine.sensor_reading`) against an independent formulation:
on a foundation that translates without turning, a point of the body reads the input's specific
force plus the second derivative of its own position in F (differentiated numerically from the
published poses), whatever the body's rotation."""

from __future__ import annotations

import math

import numpy as np
from io_helpers import ROOT

from mount_twin import SampleBatch, TwinEngine, assemble, load_scene_file
from mount_twin.engine.sensor_reading import SensorGeometry, predicted_reading
from mount_twin.physics.rotations import quaternion_matrices, rpy_matrix
from mount_twin.scene.description import BodySensor

G = 9.80665


def _shock(rate: float, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """A 12 ms half-sine of 80 m/s² along y and 120 m/s² along z of the sensor, after 20 ms at
    rest (the pump then sways and rocks on its tilted mounts)."""
    t = np.arange(round(rate * duration)) / rate
    pulse = np.where((t > 0.02) & (t < 0.032), np.sin(math.pi * (t - 0.02) / 0.012), 0.0)
    accel = np.zeros((t.size, 3))
    accel[:, 1] = 80.0 * pulse
    accel[:, 2] = G + 120.0 * pulse
    return t, accel


def test_the_predicted_reading_is_the_points_own_acceleration() -> None:
    model = assemble(load_scene_file(ROOT / "config/pump_8_mounts.scene.yaml"))
    scene = model.scene
    t, accel = _shock(20_000.0, 0.25)
    out = TwinEngine(model).run(SampleBatch(t, accel, np.zeros_like(accel), ["deck_imu"] * t.size))
    sensor = BodySensor(position=(0.9, -0.4, 1.1), orientation_rpy=(0.3, -0.2, 1.0))
    pose = (out.position, out.quaternion)
    f, w = predicted_reading(
        SensorGeometry.of(scene, sensor), out.stamps, pose, out.wrenches, np.zeros((t.size, 3))
    )
    # Independent: the point's position in F, differentiated twice, plus the input.
    rotation = quaternion_matrices(out.quaternion)
    arm = np.array(sensor.position) - np.array(scene.body.cg)
    point = out.position + np.einsum("kij,j->ki", rotation, arm)
    acc = np.gradient(np.gradient(point, t, axis=0, edge_order=2), t, axis=0, edge_order=2)
    f_in = np.einsum("ij,kj->ki", model.sensor_rotation, accel)
    to_f = np.einsum("kij,jl->kil", rotation, rpy_matrix(*sensor.orientation_rpy))
    got = np.einsum("kij,kj->ki", to_f, f)
    # Differences are second order where the motion is smooth: not at the ends (one-sided)
    # nor at the pulse's corners, where the input's slope jumps.
    inner = np.ones(t.size, dtype=bool)
    inner[:10] = inner[-10:] = False
    for corner in (0.02, 0.032):
        inner &= np.abs(t - corner) > 3.5 / 20_000.0
    want = (f_in + acc)[inner]
    peak = np.abs(want - [0.0, 0.0, G]).max()
    np.testing.assert_allclose(got[inner], want, rtol=0, atol=2e-4 * peak)
    # The rotation's terms matter here: leaving them out errs by far more than that.
    rigid = f_in + np.gradient(np.gradient(out.position, t, axis=0), t, axis=0)
    assert np.abs(rigid[inner] - want).max() > 50 * 2e-4 * peak
    # The rate is the body's, in the sensor's axes: q' = ½ q ⊗ (ω_B, 0) with ω_B = Rₛ ω_sensor,
    # against the quaternions differentiated.
    q = out.quaternion
    omega_b = np.einsum("ij,kj->ki", rpy_matrix(*sensor.orientation_rpy), w)
    vec, scalar = q[:, :3], q[:, 3:]
    q_dot = 0.5 * np.concatenate(
        [scalar * omega_b + np.cross(vec, omega_b), -(vec * omega_b).sum(axis=1, keepdims=True)], 1
    )
    want_dot = np.gradient(q, t, axis=0, edge_order=2)
    assert np.abs(omega_b).max() > 0.1  # rad/s: the pump rocks
    np.testing.assert_allclose(
        q_dot[inner], want_dot[inner], rtol=0, atol=1e-4 * np.abs(q_dot).max()
    )
