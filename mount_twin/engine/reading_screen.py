"""A sample's readings screened: which are readable (every component within ±READING_LIMIT),
which its message marks not provided (REP-145: disregarded), the rejection a sample earns by
its readings alone, and readings rotated from the sensor's axes into F. The intake screens
each pushed sample by them; the streams beside the twin's (the ageing tracker, the body IMU,
the record's analyses) take the same screen, so they leave out what the twin did not take."""

from __future__ import annotations

import numpy as np

READING_LIMIT = 1e150
"""Largest |component| of an accepted reading, m/s² or rad/s: a larger one (a garbled message) is
rejected as non_finite, and the rotation into F cannot overflow."""


def rotated(rows: np.ndarray, rot: np.ndarray) -> np.ndarray:
    """rows (n, 3) · rotᵀ, as three elementwise products: each row's bits are the same whatever
    the batch (a BLAS product may pick its kernel by size), and no BLAS thread wakes to spin
    beside the compiled loop on a two-core machine."""
    return rows[:, 0:1] * rot[:, 0] + rows[:, 1:2] * rot[:, 1] + rows[:, 2:3] * rot[:, 2]


def any_axis(mask: np.ndarray) -> np.ndarray:
    """(n,) rows of an (n, 3) bool mask with any axis true: three elementwise operations,
    which cost a quarter of numpy's reduction along so short a last axis."""
    return mask[:, 0] | mask[:, 1] | mask[:, 2]


def all_axes(mask: np.ndarray) -> np.ndarray:
    """(n,) rows of an (n, 3) bool mask with every axis true (see `any_axis`)."""
    return mask[:, 0] & mask[:, 1] & mask[:, 2]


def readable(accel: np.ndarray, gyro: np.ndarray) -> np.ndarray:
    """(n,) which samples' (n, 3) readings (m/s², rad/s) are all within ±READING_LIMIT (NaN
    and ±inf are not): the others the intake rejects as non_finite."""
    return all_axes(np.abs(accel) <= READING_LIMIT) & all_axes(np.abs(gyro) <= READING_LIMIT)


def provided(
    accel: np.ndarray, gyro: np.ndarray, unprovided: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """The (n, 3) readings with those their message marks not provided (`unprovided`, (n, 2):
    acceleration, angular velocity; REP-145: to be disregarded) zeroed: never read as values,
    nor judged as not finite; the sample's screening says whether it can do without them."""
    if unprovided is None:
        return accel, gyro
    return np.where(unprovided[:, :1], 0.0, accel), np.where(unprovided[:, 1:], 0.0, gyro)


def disregarded(unprovided: np.ndarray | None, n: int, reads_rate: bool = True) -> np.ndarray:
    """(n,) which samples lack a reading that is read: their acceleration marked not provided,
    or (`reads_rate`) their angular velocity (`unprovided`, (n, 2), None: none is marked)."""
    if unprovided is None:
        return np.zeros(n, bool)
    return unprovided[:, 0] | (unprovided[:, 1] & reads_rate)


def reading_rejections(
    accel: np.ndarray, gyro: np.ndarray, unprovided: np.ndarray | None, reads_rate: bool
) -> np.ndarray:
    """(n,) the rejection each sample earns at the intake by its readings alone ('' none), as
    `Intake` judges them, first first: non_finite (a reading not within ±READING_LIMIT, those
    marked not provided disregarded: `provided`), no_acceleration, no_angular_velocity (where
    the twin `reads_rate`; `unprovided` as `disregarded` takes it). For an analysis of a record
    to leave out what the twin did not take."""
    n = accel.shape[0]
    reasons = np.full(n, "", dtype=object)
    if unprovided is not None:
        reasons[unprovided[:, 1] & reads_rate] = "no_angular_velocity"
        reasons[unprovided[:, 0]] = "no_acceleration"
    reasons[~readable(*provided(accel, gyro, unprovided))] = "non_finite"
    return reasons
