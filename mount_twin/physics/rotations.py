"""Rotation helpers: fixed-axis roll-pitch-yaw, quaternion (x, y, z, w) of a matrix (the core has
the rotation vector and its couple map: src/core/physics/rotations.hpp)."""

from __future__ import annotations

import math

import numpy as np


def angle_text(rad: float, spec: str = ".4g") -> str:
    """An angle for a human: rad first, degrees beside to read ("0.001723 rad (0.09872 deg)"),
    both by `spec`."""
    return f"{rad:{spec}} rad ({math.degrees(rad):{spec}} deg)"


def rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Rotation Rz(yaw)·Ry(pitch)·Rx(roll), rad (REP-103 fixed-axis roll, pitch, yaw)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def rpy_matrices(angles: list[tuple[float, float, float]]) -> np.ndarray:
    """(n, 3, 3) `rpy_matrix` of each (roll, pitch, yaw), rad; (0, 3, 3) for none."""
    return np.array([rpy_matrix(*a) for a in angles]).reshape(-1, 3, 3)


def point_displacements(shift: np.ndarray, rotation: np.ndarray, arms: np.ndarray) -> np.ndarray:
    """Displacements (k, n, 3), m in F, of the body points at `arms` (n, 3: m from the CG, in F
    at the reference pose, where B's axes are F's) in k poses: the CG displaced by `shift`
    (k, 3), m in F, the body turned by `rotation` (k, 3, 3), body → F. shift + R·a − a, as the
    core's `point_motion`."""
    return shift[:, None, :] + np.einsum("kij,nj->kni", rotation, arms) - arms


def quaternion_from_matrix(rot: np.ndarray, out: np.ndarray) -> None:
    """Unit quaternion (x, y, z, w), w ≥ 0, of a rotation matrix (Shepperd's method)."""
    tr = rot[0, 0] + rot[1, 1] + rot[2, 2]
    if tr > max(rot[0, 0], rot[1, 1], rot[2, 2]):
        s = 2.0 * math.sqrt(1.0 + tr)
        out[3] = 0.25 * s
        out[0] = (rot[2, 1] - rot[1, 2]) / s
        out[1] = (rot[0, 2] - rot[2, 0]) / s
        out[2] = (rot[1, 0] - rot[0, 1]) / s
    elif rot[0, 0] >= rot[1, 1] and rot[0, 0] >= rot[2, 2]:
        s = 2.0 * math.sqrt(1.0 + rot[0, 0] - rot[1, 1] - rot[2, 2])
        out[3] = (rot[2, 1] - rot[1, 2]) / s
        out[0] = 0.25 * s
        out[1] = (rot[0, 1] + rot[1, 0]) / s
        out[2] = (rot[0, 2] + rot[2, 0]) / s
    elif rot[1, 1] >= rot[2, 2]:
        s = 2.0 * math.sqrt(1.0 + rot[1, 1] - rot[0, 0] - rot[2, 2])
        out[3] = (rot[0, 2] - rot[2, 0]) / s
        out[0] = (rot[0, 1] + rot[1, 0]) / s
        out[1] = 0.25 * s
        out[2] = (rot[1, 2] + rot[2, 1]) / s
    else:
        s = 2.0 * math.sqrt(1.0 + rot[2, 2] - rot[0, 0] - rot[1, 1])
        out[3] = (rot[1, 0] - rot[0, 1]) / s
        out[0] = (rot[0, 2] + rot[2, 0]) / s
        out[1] = (rot[1, 2] + rot[2, 1]) / s
        out[2] = 0.25 * s
    if out[3] < 0.0:
        for i in range(4):
            out[i] = -out[i]


_ENTRIES = (
    ((1, 1), (2, 2), 1.0),  # 1 − 2 (y y + z z)
    ((0, 1), (3, 2), -1.0),  # 2 (x y − w z)
    ((0, 2), (3, 1), 1.0),  # 2 (x z + w y)
    ((0, 1), (3, 2), 1.0),  # 2 (x y + w z)
    ((0, 0), (2, 2), 1.0),  # 1 − 2 (x x + z z)
    ((1, 2), (3, 0), -1.0),  # 2 (y z − w x)
    ((0, 2), (3, 1), -1.0),  # 2 (x z − w y)
    ((1, 2), (3, 0), 1.0),  # 2 (y z + w x)
    ((0, 0), (1, 1), 1.0),  # 1 − 2 (x x + y y)
)
"""The rotation matrix's entries, row by row, of a quaternion (x, y, z, w: 0–3): the pairs
(i, j) of its two products q_i q_j and the sign the second takes."""
_FIRST = np.array([4 * i + j for (i, j), _, _ in _ENTRIES])
_SECOND = np.array([4 * i + j for _, (i, j), _ in _ENTRIES])
_SIGN = np.array([sign for _, _, sign in _ENTRIES])
_DIAGONAL = np.array([0, 4, 8])


def quaternion_matrices(quat: np.ndarray) -> np.ndarray:
    """(k, 3, 3) rotation matrices of (k, 4) unit quaternions (x, y, z, w): the entries
    1 − 2 (y² + z²), 2 (x y − w z), … each from the products q_i q_j of all pairs, formed once
    (a difference p − q as p + (−q), the same bits)."""
    k = quat.shape[0]
    products = (quat[:, :, None] * quat[:, None, :]).reshape(k, 16)
    twice = 2 * (products.take(_FIRST, 1) + _SIGN * products.take(_SECOND, 1))
    twice[:, _DIAGONAL] = 1 - twice[:, _DIAGONAL]
    return twice.reshape(k, 3, 3)


def quaternion_matrix_entries(quat: list[float]) -> list[float]:
    """The rotation matrix's 9 entries, row by row, of one unit quaternion (x, y, z, w) as
    Python floats: `quaternion_matrices`' arithmetic (the same bits), at a fraction of its
    numpy calls' cost for one."""
    m = [2.0 * (quat[i] * quat[j] + s * (quat[k] * quat[n])) for (i, j), (k, n), s in _ENTRIES]
    m[0], m[4], m[8] = 1.0 - m[0], 1.0 - m[4], 1.0 - m[8]
    return m
