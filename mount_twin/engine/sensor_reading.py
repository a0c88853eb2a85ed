"""What an IMU on the machine's body should read, from the twin's outputs.

The body's specific force at its CG comes from the mount forces by Newton, with no
differentiation of the pose (`cg_specific_force`); at the sensor's point P, rigid-body
kinematics adds the rotation's terms:

    f_P = f_CG + α × r + ω × (ω × r),   r = R (p − c),

with ω = Ω_F + ω_rel the body's absolute angular velocity (the foundation's rate Ω_F and the
body's rate relative to F, from the published attitudes R), α its inertial derivative
(d/dt of ω's components in F, plus Ω_F × ω), p the sensor's position and c the CG at the
reference pose, all in the axes of F. The sensor reads them in its own axes: Rₛᵀ Rᵀ f_P and
Rₛᵀ Rᵀ ω, Rₛ its orientation in the body frame. Rates come from the attitudes by central
differences (`derivative`: second order, exact for the twin's smooth outputs to the square of
the step).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mount_twin.engine.intake import rotated
from mount_twin.physics.rotations import quaternion_matrices, rpy_matrices, rpy_matrix
from mount_twin.scene.description import BodySensor, Scene


def _products(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(k, 3) rows m_k · v_k of (k, 3, 3) matrices and (k, 3) vectors, as elementwise products
    summed in one order: each row's bits are the same whatever the batch (einsum's and BLAS's
    kernels may change with the size), so the live stream equals the whole record's."""
    return m[:, :, 0] * v[:, 0:1] + m[:, :, 1] * v[:, 1:2] + m[:, :, 2] * v[:, 2:3]


@dataclass(frozen=True)
class SensorGeometry:
    """What the prediction needs of the scene, taken once at load.

    Attributes:
        mount_axes: (n, 3, 3) each mount's axes in F (columns), fixed in F.
        mass: the body's mass, kg.
        arm: the sensor's point from the CG at the reference pose, m, in F.
        axes: the sensor's axes in the body frame B (columns, Rₛ).
    """

    mount_axes: np.ndarray
    mass: float
    arm: np.ndarray
    axes: np.ndarray

    @classmethod
    def of(cls, scene: Scene, sensor: BodySensor) -> SensorGeometry:
        """The geometry of `sensor` on `scene`'s body."""
        return cls(
            _mount_axes(scene),
            scene.body.mass,
            np.array(sensor.position) - np.array(scene.body.cg),
            rpy_matrix(*sensor.orientation_rpy),
        )


def _mount_axes(scene: Scene) -> np.ndarray:
    return rpy_matrices([m.orientation_rpy for m in scene.mounts])


def _specific_force(mount_axes: np.ndarray, mass: float, wrenches: np.ndarray) -> np.ndarray:
    """Σᵢ Qᵢ fᵢ / m, mount by mount in scene order (the same bits per row whatever the batch)."""
    total = np.zeros((wrenches.shape[0], 3))
    for i, q in enumerate(mount_axes):
        total += rotated(wrenches[:, i, :3], q)
    return total / mass


def cg_specific_force(scene: Scene, wrenches: np.ndarray) -> np.ndarray:
    """(k, 3) specific force of the CG in F, m/s², from the scene's (k, n, 6) mount wrenches
    (force on the body in each mount's axes first; the axes fixed in F).

    The mounts are the only forces on the body besides gravity, so Newton gives it exactly:
    m (a − g) = Σᵢ Qᵢ fᵢ, Qᵢ mount i's axes in F (fixed in F, `docs/physics.md` §7). It is
    what an accelerometer at the CG reads (+g up at rest). The wrenches must be every
    sample's: decimated rows hold each component's peak, not a simultaneous wrench."""
    return _specific_force(_mount_axes(scene), scene.body.mass, wrenches)


def derivative(t: np.ndarray, f: np.ndarray) -> np.ndarray:
    """d f/dt along the first axis at k ≥ 3 stamps `t` (s): second-order differences on the
    actual spacing, three-point central inside and one-sided at both ends (np.gradient's
    edge_order=2 formulas, without its switch to the uniform formula where the spacing is
    exactly even, which would make a row's bits depend on the rows around it)."""
    dx = np.diff(t).reshape((-1,) + (1,) * (f.ndim - 1))
    h1, h2 = dx[:-1], dx[1:]
    out = np.empty_like(f)
    out[1:-1] = (
        -h2 / (h1 * (h1 + h2)) * f[:-2]
        + (h2 - h1) / (h1 * h2) * f[1:-1]
        + h1 / (h2 * (h1 + h2)) * f[2:]
    )
    h1, h2 = dx[0], dx[1]
    out[0] = (
        -(2.0 * h1 + h2) / (h1 * (h1 + h2)) * f[0]
        + (h1 + h2) / (h1 * h2) * f[1]
        - h1 / (h2 * (h1 + h2)) * f[2]
    )
    h1, h2 = dx[-2], dx[-1]
    out[-1] = (
        h2 / (h1 * (h1 + h2)) * f[-3]
        - (h1 + h2) / (h1 * h2) * f[-2]
        + (2.0 * h2 + h1) / (h2 * (h1 + h2)) * f[-1]
    )
    return out


def relative_rate(stamps: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """(k, 3) angular velocity of the body relative to F, rad/s, in F's axes, from (k, 3, 3)
    attitudes at `stamps` (s): the skew part of Ṙ Rᵀ, Ṙ by second-order differences."""
    dr = derivative(stamps, rotation)

    def w(i: int, j: int) -> np.ndarray:  # (Ṙ Rᵀ)_ij
        return (
            dr[:, i, 0] * rotation[:, j, 0]
            + dr[:, i, 1] * rotation[:, j, 1]
            + dr[:, i, 2] * rotation[:, j, 2]
        )

    return 0.5 * np.stack([w(2, 1) - w(1, 2), w(0, 2) - w(2, 0), w(1, 0) - w(0, 1)], 1)


def predicted_reading(
    geometry: SensorGeometry,
    stamps: np.ndarray,
    pose: tuple[np.ndarray, np.ndarray],
    wrenches: np.ndarray,
    foundation_rate: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(specific force m/s², angular rate rad/s), each (k, 3) in the sensor's axes, of the body
    sensor (`geometry`) at k rows: `stamps` (s), `pose` (CG positions (k, 3) in F, quaternions
    (k, 4) x, y, z, w of body → F), (k, n, 6) mount `wrenches`, and the foundation's rate
    (k, 3), rad/s in F (zeros where the scene neglects it). Row by row the same bits whatever
    rows come with it, but for the differences' neighbours."""
    rotation = quaternion_matrices(pose[1])
    f_cg = _specific_force(geometry.mount_axes, geometry.mass, wrenches)
    omega = foundation_rate + relative_rate(stamps, rotation)
    alpha = derivative(stamps, omega) + np.cross(foundation_rate, omega)
    r = _products(rotation, np.broadcast_to(geometry.arm, omega.shape))
    f_p = f_cg + np.cross(alpha, r) + np.cross(omega, np.cross(omega, r))
    to_body = np.swapaxes(rotation, 1, 2)  # R_kᵀ: F → B
    to_sensor = geometry.axes.T  # Rₛᵀ: B → the sensor's axes
    return (
        rotated(_products(to_body, f_p), to_sensor),
        rotated(_products(to_body, omega), to_sensor),
    )
