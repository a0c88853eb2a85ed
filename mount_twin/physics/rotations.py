"""Rotation helpers: fixed-axis roll-pitch-yaw, rotation vector, quaternion (x, y, z, w)."""

from __future__ import annotations

import math

import numpy as np


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


def rotation_vector(rot: np.ndarray, quat: np.ndarray, out: np.ndarray) -> None:
    """Rotation vector (axis × angle, rad) of `rot`; `quat` is scratch of length 4."""
    quaternion_from_matrix(rot, quat)
    sin_half = math.sqrt(quat[0] ** 2 + quat[1] ** 2 + quat[2] ** 2)
    # angle / sin(angle/2), with its limit 2 as the angle goes to zero
    scale = 2.0 * math.atan2(sin_half, quat[3]) / sin_half if sin_half > 1e-12 else 2.0
    for i in range(3):
        out[i] = scale * quat[i]


def couple_map(phi: np.ndarray, quat: np.ndarray, out: np.ndarray) -> None:
    """J(φ)⁻ᵀ = 1 + ½[φ]× + c·[φ]×², c = 1/θ² − cot(θ/2)/(2θ), θ = |φ| (rad): the inverse
    transpose of the left Jacobian of SO(3) at the rotation vector φ of a rotation whose
    quaternion (x, y, z, w), w ≥ 0, is `quat` (as `rotation_vector` left it).

    A body turned by δθ (in F, small) changes φ by J(φ)⁻¹·δθ, and φ changes at J(φ)⁻¹·ω for
    an angular velocity ω in F. So a mount law giving a generalized force g conjugate to φ (a
    spring −K·φ: the gradient of ½ φᵀKφ) exerts the couple J(φ)⁻ᵀ·g on the body, and it
    conserves energy at any rotation; at small φ the map is 1 + O(φ).
    """
    angle_sq = phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2
    if angle_sq < 1e-4:  # series: the closed form cancels; next term θ⁶/1209600 < 1e-18
        c = 1.0 / 12.0 + angle_sq / 720.0 + angle_sq**2 / 30240.0
    else:
        angle = math.sqrt(angle_sq)
        sin_half = math.sqrt(quat[0] ** 2 + quat[1] ** 2 + quat[2] ** 2)
        c = 1.0 / angle_sq - quat[3] / (2.0 * angle * sin_half)
    for i in range(3):
        for j in range(3):
            out[i, j] = c * phi[i] * phi[j]
        out[i, i] += 1.0 - c * angle_sq
    out[0, 1] -= 0.5 * phi[2]
    out[1, 0] += 0.5 * phi[2]
    out[0, 2] += 0.5 * phi[1]
    out[2, 0] -= 0.5 * phi[1]
    out[1, 2] -= 0.5 * phi[0]
    out[2, 1] += 0.5 * phi[0]
