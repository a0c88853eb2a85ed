"""What an IMU on the machine's body should read, from the twin's outputs.

The body's specific force at its CG comes from the mount forces by Newton (exact,
`analysis.response.cg_specific_force`); at the sensor's point P, rigid-body kinematics adds the
rotation's terms:

    f_P = f_CG + α × r + ω × (ω × r),   r = R (p − c),

with ω = Ω_F + ω_rel the body's absolute angular velocity (the foundation's rate Ω_F and the
body's rate relative to F, from the published attitudes R), α its inertial derivative
(d/dt of ω's components in F, plus Ω_F × ω), p the sensor's position and c the CG at the
reference pose, all in the axes of F. The sensor reads them in its own axes: Rₛᵀ Rᵀ f_P and
Rₛᵀ Rᵀ ω, Rₛ its orientation in the body frame. Rates come from the attitudes by central
differences (second order; exact for the twin's smooth outputs to the square of the step).
"""

from __future__ import annotations

import numpy as np

from mount_twin.analysis.response import cg_specific_force
from mount_twin.physics.rotations import quaternion_matrices, rpy_matrix
from mount_twin.scene.description import BodySensor, Scene


def relative_rate(stamps: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """(k, 3) angular velocity of the body relative to F, rad/s, in F's axes, from (k, 3, 3)
    attitudes at `stamps` (s): the skew part of Ṙ Rᵀ, Ṙ by second-order differences."""
    dr = np.gradient(rotation, stamps, axis=0, edge_order=2)
    w = np.einsum("kij,klj->kil", dr, rotation)
    return 0.5 * np.stack(
        [w[:, 2, 1] - w[:, 1, 2], w[:, 0, 2] - w[:, 2, 0], w[:, 1, 0] - w[:, 0, 1]], 1
    )


def predicted_reading(
    scene: Scene,
    sensor: BodySensor,
    stamps: np.ndarray,
    pose: tuple[np.ndarray, np.ndarray],
    wrenches: np.ndarray,
    foundation_rate: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(specific force m/s², angular rate rad/s), each (k, 3) in the sensor's axes, of the body
    sensor at k rows: `stamps` (s), `pose` (CG positions (k, 3) in F, quaternions (k, 4)
    x, y, z, w of body → F), (k, n, 6) mount `wrenches`, and the foundation's rate (k, 3),
    rad/s in F (zeros where the scene neglects it)."""
    rotation = quaternion_matrices(pose[1])
    f_cg = cg_specific_force(scene, wrenches)
    omega = foundation_rate + relative_rate(stamps, rotation)
    alpha = np.gradient(omega, stamps, axis=0, edge_order=2) + np.cross(foundation_rate, omega)
    r = np.einsum("kij,j->ki", rotation, np.array(sensor.position) - np.array(scene.body.cg))
    f_p = f_cg + np.cross(alpha, r) + np.cross(omega, np.cross(omega, r))
    sensor_axes = rpy_matrix(*sensor.orientation_rpy)
    to_sensor = np.einsum("ji,klj->kil", sensor_axes, rotation)  # Rₛᵀ R_kᵀ
    return np.einsum("kij,kj->ki", to_sensor, f_p), np.einsum("kij,kj->ki", to_sensor, omega)
