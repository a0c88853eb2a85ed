"""Utilisation of linear mounts against their rated travel and load (`LinearMount.rated_*`).

The non-linear kinds watch their own limits inside the compiled loop; a linear mount has no
state of its own, so its utilisation is taken here from what the loop publishes: the force from
the published wrenches (peaks held across decimation, so no sample's peak is missed) and the
travel from the published poses (at the output rate: with `outputs.decimation` > 1 a travel
peak between published rows is not seen).
"""

from __future__ import annotations

import numpy as np

from mount_twin.physics import pose_row
from mount_twin.physics.rotations import rpy_matrix
from mount_twin.scene.description import LinearMount, Scene


def _inverse(rated: tuple[float, ...]) -> list[float]:
    """1/rating per axis, 0 where unrated (0)."""
    return [1.0 / v if v > 0.0 else 0.0 for v in rated]


def matrices_from_quaternions(quat: np.ndarray) -> np.ndarray:
    """(k, 3, 3) rotation matrices of (k, 4) unit quaternions (x, y, z, w)."""
    x, y, z, w = quat.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )


class LinearRatings:
    """The rated linear mounts of a scene and their utilisation from published rows.

    Attributes:
        slots: positions in scene.mounts of the linear mounts with a rating.
    """

    def __init__(self, scene: Scene) -> None:
        rated: list[tuple[int, LinearMount]] = [
            (i, m)
            for i, m in enumerate(scene.mounts)
            if isinstance(m, LinearMount) and (any(m.rated_travel) or any(m.rated_load))
        ]
        self.slots = [i for i, _ in rated]
        self._cg = np.array(scene.body.cg)
        self._point = np.array([m.position for _, m in rated]).reshape(-1, 3) - self._cg
        self._axes = np.array([rpy_matrix(*m.orientation_rpy) for _, m in rated]).reshape(-1, 3, 3)
        self._per_travel = np.array([_inverse(m.rated_travel) for _, m in rated]).reshape(-1, 3)
        self._per_load = np.array([_inverse(m.rated_load) for _, m in rated]).reshape(-1, 3)

    def utilisation(self, pose: np.ndarray, wrenches: np.ndarray) -> np.ndarray:
        """Peak utilisation (k,) over published rows: pose (r, pose_row.WIDTH), wrenches
        (r, n_mounts, 6) in mount axes (N, N·m)."""
        if not self.slots or pose.shape[0] == 0:
            return np.zeros(len(self.slots))
        rot = matrices_from_quaternions(pose[:, pose_row.QUATERNION_COLS])
        q = pose[:, pose_row.POSITION_COLS] - self._cg
        # d = q + R·p − p in F, then along the mount axes: Qᵀ·d (as matrix products: einsum
        # took a quarter of the pump's engine time).
        moved = np.matmul(rot, self._point.T).transpose(0, 2, 1) - self._point + q[:, None, :]
        axes = self._axes
        travel = (
            moved[:, :, 0, None] * axes[:, 0, :]
            + moved[:, :, 1, None] * axes[:, 1, :]
            + moved[:, :, 2, None] * axes[:, 2, :]
        )
        force = wrenches[:, self.slots, :3]
        util = np.maximum(np.abs(travel) * self._per_travel, np.abs(force) * self._per_load).max(
            axis=2
        )
        return util.max(axis=0)
