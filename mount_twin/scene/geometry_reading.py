"""Positions (m, in F), angles (rad) and poses of a scene read within their plausible ranges:
a coordinate past REACH_M is millimetres, an angle past one turn degrees, refused by key."""

from __future__ import annotations

import math

from mount_twin.scene.description import Vec3, Vec6
from mount_twin.scene.reader import Reader

REACH_M = 1000.0
"""Largest |coordinate| of a position, m: a machine on a deck spans metres (mm, more likely)."""
ANGLE_LIMIT_RAD = 2.0 * math.pi
"""Largest |angle| of an orientation or start pose, rad: beyond one turn it is degrees."""


def read_position(r: Reader, key: str, default: Vec3 | None = None) -> Vec3:
    """A point in F, m, within REACH_M of the origin."""
    p = r.vector(key, 3, default)
    if max(abs(v) for v in p) > REACH_M:
        raise r.error(key, f"{list(p)} m is more than {REACH_M:g} m from F's origin: millimetres?")
    return p


def read_angles(r: Reader, key: str, default: Vec3 | None = None) -> Vec3:
    """Roll, pitch, yaw, rad, within one turn."""
    a = r.vector(key, 3, default)
    if max(abs(v) for v in a) > ANGLE_LIMIT_RAD:
        raise r.error(key, f"{list(a)} exceeds 2π: angles are in radians, not degrees")
    return a


def read_pose(r: Reader, key: str, default: Vec6) -> Vec6:
    """(X, Y, Z) m and (α, γ, δ) rad, in range like positions and angles."""
    pose = r.vector(key, 6, default)
    if max(abs(v) for v in pose[:3]) > REACH_M or max(abs(v) for v in pose[3:]) > ANGLE_LIMIT_RAD:
        raise r.error(key, f"{list(pose)}: positions beyond {REACH_M:g} m or angles beyond 2π")
    return pose
