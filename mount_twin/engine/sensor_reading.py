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
differences (`Differences`: second order, exact for the twin's smooth outputs to the square of
the step).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mount_twin.engine.reading_screen import rotated
from mount_twin.physics.rotations import (
    quaternion_matrices,
    quaternion_matrix_entries,
    rpy_matrices,
    rpy_matrix,
)
from mount_twin.scene.description import BodySensor, Scene


def _products(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(k, 3) rows m_k · v_k of (k, 3, 3) matrices and (k, 3) vectors, as elementwise products
    summed in one order: each row's bits are the same whatever the batch (einsum's and BLAS's
    kernels may change with the size), so the live stream equals the whole record's."""
    return m[:, :, 0] * v[:, 0:1] + m[:, :, 1] * v[:, 1:2] + m[:, :, 2] * v[:, 2:3]


_NEXT, _AFTER = np.array([1, 2, 0]), np.array([2, 0, 1])
"""Each axis's next and the one after it (x → y, z; y → z, x; z → x, y)."""
_PAIRS = tuple(zip(_NEXT.tolist(), _AFTER.tolist(), strict=True))
"""The same, as (next, after) of each axis."""


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k, 3) rows a_k × b_k: the products np.cross forms, in its order (the same bits), at a
    sixth of its cost on a few rows (its moveaxis and broadcasting cost ~10 µs a call)."""
    return a.take(_NEXT, 1) * b.take(_AFTER, 1) - a.take(_AFTER, 1) * b.take(_NEXT, 1)


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
    """Σᵢ Qᵢ fᵢ / m, mount by mount in scene order (the same bits per row whatever the batch):
    each mount's Qᵢ fᵢ as `rotated` forms it, all mounts at once, then summed in order from
    zero (a running sum: accumulate adds one term after another, never pairwise)."""
    f = wrenches[:, :, :3, None]  # (k, n, 3, 1): Qᵢ fᵢ = Σⱼ fᵢⱼ (column j of Qᵢ)
    terms = np.zeros((wrenches.shape[0], wrenches.shape[1] + 1, 3))  # a zero, then each mount's
    each = terms[:, 1:]
    np.multiply(f[:, :, 0], mount_axes[:, :, 0], out=each)
    each += f[:, :, 1] * mount_axes[:, :, 1]
    each += f[:, :, 2] * mount_axes[:, :, 2]
    return np.add.accumulate(terms, axis=1)[:, -1] / mass


def cg_specific_force(scene: Scene, wrenches: np.ndarray) -> np.ndarray:
    """(k, 3) specific force of the CG in F, m/s², from the scene's (k, n, 6) mount wrenches
    (force on the body in each mount's axes first; the axes fixed in F).

    The mounts are the only forces on the body besides gravity, so Newton gives it exactly:
    m (a − g) = Σᵢ Qᵢ fᵢ, Qᵢ mount i's axes in F (fixed in F, `docs/physics.md` §7). It is
    what an accelerometer at the CG reads (+g up at rest). The wrenches must be every
    sample's: decimated rows hold each component's peak, not a simultaneous wrench."""
    return _specific_force(_mount_axes(scene), scene.body.mass, wrenches)


class Differences:
    """d/dt along the first axis at k ≥ 3 stamps `t` (s): second-order differences on the
    actual spacing, three-point central inside and one-sided at both ends (np.gradient's
    edge_order=2 formulas, without its switch to the uniform formula where the spacing is
    exactly even, which would make a row's bits depend on the rows around it). Each row's
    three weights are taken once for every quantity differenced at these stamps (s⁻¹)."""

    def __init__(self, t: np.ndarray) -> None:
        k = t.shape[0]
        dx = np.diff(t)
        h1, h2 = dx[:-1], dx[1:]
        s = h1 + h2
        w = np.empty((k, 3))
        w[1:-1, 0], w[1:-1, 1], w[1:-1, 2] = -h2 / (h1 * s), (h2 - h1) / (h1 * h2), h1 / (h2 * s)
        # the ends' rows, on the spacing of the rows inside next to them (as Python floats: the
        # same IEEE operations); a weight subtracted in np.gradient's formula is added negated
        # here (x − c·f = x + (−c)·f, bit for bit)
        a1, a2, z1, z2 = float(h1[0]), float(h2[0]), float(h1[-1]), float(h2[-1])
        w[0] = (-(2.0 * a1 + a2) / (a1 * (a1 + a2)), (a1 + a2) / (a1 * a2), -w[1, 2])
        w[-1] = (-w[-2, 0], -((z1 + z2) / (z1 * z2)), (2.0 * z2 + z1) / (z2 * (z1 + z2)))
        self._weights = w
        centre = np.arange(k)
        centre[0], centre[-1] = 1, k - 2
        self._rows = centre[:, None] + np.arange(-1, 2)

    def of(self, f: np.ndarray) -> np.ndarray:
        """d f/dt, f (k, ...) at the stamps."""
        w = self._weights.reshape(self._weights.shape + (1,) * (f.ndim - 1))
        rows = self._rows
        return (
            w[:, 0] * f.take(rows[:, 0], 0)
            + w[:, 1] * f.take(rows[:, 1], 0)
            + w[:, 2] * f.take(rows[:, 2], 0)
        )


def relative_rate(d_dt: Differences, rotation: np.ndarray) -> np.ndarray:
    """(k, 3) angular velocity of the body relative to F, rad/s, in F's axes, from (k, 3, 3)
    attitudes at the stamps of `d_dt`: the skew part of Ṙ Rᵀ."""
    dr = d_dt.of(rotation)

    def w(i: np.ndarray, j: np.ndarray) -> np.ndarray:  # (Ṙ Rᵀ)_ij, three (i, j) at once
        p = dr.take(i, 1) * rotation.take(j, 1)
        return p[:, :, 0] + p[:, :, 1] + p[:, :, 2]

    # axis by axis: (2, 1) − (1, 2), (0, 2) − (2, 0), (1, 0) − (0, 1)
    return 0.5 * (w(_AFTER, _NEXT) - w(_NEXT, _AFTER))


def predicted_reading(
    geometry: SensorGeometry,
    stamps: np.ndarray,
    pose: tuple[np.ndarray, np.ndarray],
    wrenches: np.ndarray,
    foundation_rate: np.ndarray,
    rows: slice = slice(None),
) -> tuple[np.ndarray, np.ndarray]:
    """(specific force m/s², angular rate rad/s), each (k, 3) in the sensor's axes, of the body
    sensor (`geometry`) at k rows: `stamps` (s), `pose` (CG positions (k, 3) in F, quaternions
    (k, 4) x, y, z, w of body → F), (k, n, 6) mount `wrenches`, and the foundation's rate
    (k, 3), rad/s in F (zeros where the scene neglects it); of those `rows` of them (a slice,
    step 1; all by default). Row by row the same bits whatever rows come with it, but for the
    differences' neighbours, and whichever are asked for: one row with two on each side (the
    live stream's wake-up of one message, `body_prediction.Lead`) is `_inner_row`'s, the same
    arithmetic on the five rows it reads."""
    start, stop, _ = rows.indices(stamps.shape[0])
    if stop - start == 1 and start >= 2 and stop + 2 <= stamps.shape[0]:
        near, around = slice(start - 2, stop + 2), slice(start - 1, stop + 1)
        return _inner_row(
            geometry, stamps[near], pose[1][near], wrenches[start:stop], foundation_rate[around]
        )
    rotation = quaternion_matrices(pose[1])
    f_cg = _specific_force(geometry.mount_axes, geometry.mass, wrenches)
    d_dt = Differences(stamps)
    omega = foundation_rate + relative_rate(d_dt, rotation)
    alpha = d_dt.of(omega) + _cross(foundation_rate, omega)
    r = _products(rotation, np.broadcast_to(geometry.arm, omega.shape))
    f_p = f_cg + _cross(alpha, r) + _cross(omega, _cross(omega, r))
    to_body = np.swapaxes(rotation, 1, 2)  # R_kᵀ: F → B
    to_sensor = geometry.axes.T  # Rₛᵀ: B → the sensor's axes
    return (
        rotated(_products(to_body, f_p), to_sensor)[rows],
        rotated(_products(to_body, omega), to_sensor)[rows],
    )


# One row as Python floats: each function below is the scalar form of the numpy kernel it
# names, the same IEEE operations in the same order (so the same bits: `predicted_reading`
# holds them to each other, test_sensor_reading_bits.py), at a third of its numpy calls' cost
# on the live stream's one row. Vectors are lists of 3 floats, matrices of 9 (row by row).
Vector = list[float]


def _inner_row(
    geometry: SensorGeometry,
    stamps: np.ndarray,
    quaternions: np.ndarray,
    wrenches: np.ndarray,
    foundation_rate: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """`predicted_reading` of the middle row of five (`stamps` (5,) s, `quaternions` (5, 4);
    its (1, n, 6) `wrenches`; the (3, 3) foundation's rate of it and the rows on either side),
    each (1, 3): the rates at it and beside it by central differences, as the five rows'
    `Differences` take them."""
    t = stamps.tolist()
    rotation = [quaternion_matrix_entries(q) for q in quaternions.tolist()]
    rate = foundation_rate.tolist()
    weights = [_central_weights(t, k) for k in (1, 2, 3)]
    omega = [
        _added(
            rate[k - 1],
            _relative_rate(_differenced(weights[k - 1], rotation[k - 1 : k + 2]), rotation[k]),
        )
        for k in (1, 2, 3)
    ]
    middle, turn = omega[1], rotation[2]
    alpha = _added(_differenced(weights[1], omega), _crossed(rate[1], middle))
    r = _times(turn, geometry.arm.tolist())
    f_cg = _specific_force(geometry.mount_axes, geometry.mass, wrenches)[0].tolist()
    f_p = _added(_added(f_cg, _crossed(alpha, r)), _crossed(middle, _crossed(middle, r)))
    axes = geometry.axes.ravel().tolist()  # Rₛ: to its transpose, as `rotated` by Rₛᵀ
    return (
        np.array([_times_transposed(axes, _times_transposed(turn, f_p))]),
        np.array([_times_transposed(axes, _times_transposed(turn, middle))]),
    )


def _central_weights(t: list[float], k: int) -> tuple[float, float, float]:
    """`Differences`' weights (s⁻¹) of row k inside stamps `t` (s)."""
    h1, h2 = t[k] - t[k - 1], t[k + 1] - t[k]
    s = h1 + h2
    return -h2 / (h1 * s), (h2 - h1) / (h1 * h2), h1 / (h2 * s)


def _differenced(w: tuple[float, float, float], f: list[list[float]]) -> list[float]:
    """`Differences.of` at a row inside: weights `w` on the three rows `f` around it."""
    return [w[0] * a + w[1] * b + w[2] * c for a, b, c in zip(*f, strict=True)]


def _relative_rate(dr: list[float], rotation: list[float]) -> Vector:
    """`relative_rate` of one row: Ṙ `dr` and R `rotation`."""

    def w(i: int, j: int) -> float:  # (Ṙ Rᵀ)_ij
        row, column = dr[3 * i : 3 * i + 3], rotation[3 * j : 3 * j + 3]
        return row[0] * column[0] + row[1] * column[1] + row[2] * column[2]

    return [0.5 * (w(a, n) - w(n, a)) for n, a in _PAIRS]


def _added(a: Vector, b: Vector) -> Vector:
    return [x + y for x, y in zip(a, b, strict=True)]


def _crossed(a: Vector, b: Vector) -> Vector:
    """`_cross` of one row."""
    return [a[n] * b[m] - a[m] * b[n] for n, m in _PAIRS]


def _times(m: list[float], v: Vector) -> Vector:
    """`_products` of one row: m v."""
    return [m[3 * i] * v[0] + m[3 * i + 1] * v[1] + m[3 * i + 2] * v[2] for i in range(3)]


def _times_transposed(m: list[float], v: Vector) -> Vector:
    """`_products` by the transpose (and `rotated`) of one row: mᵀ v."""
    return [m[i] * v[0] + m[3 + i] * v[1] + m[6 + i] * v[2] for i in range(3)]
