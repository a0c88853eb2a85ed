"""The run's peak figures, one definition each, for the replay summary and its JSON, the
report and the sweep's rows: each computes them here, named by the keys below (units in the
name).

- peak force: per mount, the largest magnitude |F| of its force vector at one instant (N); not
  per-component extremes, which come at different times and make no force that acted;
- peak couple: the same of its couple |M| (N·m);
- CG displacement: the largest distance of the CG from its first published position (m): the
  static equilibrium the twin starts at (`initial.mode: equilibrium`; with `given`, the given
  pose), so the static sag under gravity is not counted as motion;
- travel: per mount, the largest distance of its attachment point from its foundation point
  (m), d = r + R p − p (`docs/physics.md` §7: r the CG's displacement from the scene's CG, R the
  attitude, p the mount's position from the CG): the deflection a rubber mount's stroke, a
  snubber's gap or a key's clearance is measured against, static sag included.
"""

from __future__ import annotations

import math

import numpy as np

from mount_twin.engine.health_texts import ratio_text
from mount_twin.physics.rotations import point_displacements

PEAK_FORCE = "peak_force_magnitude_N"
PEAK_COUPLE = "peak_couple_magnitude_Nm"
DISPLACEMENT = "max_cg_displacement_from_start_m"
TRAVEL = "travel_max_m"
LABELS = {
    PEAK_FORCE: "peak force |F|, N",
    PEAK_COUPLE: "peak couple |M|, N·m",
    DISPLACEMENT: "max CG displacement from start, m",
}
"""The figures in words, with their units, where a person reads them (the report's page)."""


def peak_label(decimation: int) -> str:
    """What the peak |F|, |M| of rows published every `decimation` samples are: at
    decimation 1, the largest at one instant; above, each row holds each component's peak
    since the previous one (`OutputBatch.wrenches`), so theirs is an upper bound of it."""
    if decimation == 1:
        return "largest magnitude at one instant"
    return (
        f"decimated: from each component's peak over {decimation} samples, an upper bound of "
        "the largest magnitude at one instant"
    )


PEAK_DIGITS = 4
"""Significant figures of a printed peak |F| or |M| (the events' |F| max has as many)."""
PEAK_DECIMALS_MAX = 4
"""The finest a printed peak goes: 0.1 mN or mN·m (a couple of round-off, 1e-18 N·m on a
symmetric machine, reads 0.0000, not eighteen zeros and a 1)."""


def peak_text(value: float) -> str:
    """A peak |F| (N) or |M| (N·m) as the replay's summary, the report and the sweep print it:
    to PEAK_DIGITS significant figures, and at least to 0.1 (10848.2 N, not 1.085e+04), in
    positional notation, to PEAK_DECIMALS_MAX decimals at most. To 0.1 alone a small machine's
    couples read 0.9 N·m for 0.9104."""
    if not math.isfinite(value) or value == 0.0:
        return f"{value:.1f}"
    rounded = float(f"{value:.{PEAK_DIGITS - 1}e}")  # 0.099996 rounds to 0.1000, not 0.10000
    decimals = PEAK_DIGITS - 1 - math.floor(math.log10(abs(rounded)))
    return f"{value:.{min(max(1, decimals), PEAK_DECIMALS_MAX)}f}"


def utilisation_text(value: float) -> str:
    """A mount's peak utilisation as the replay's summary and the report print it: to 0.001,
    with more digits where rounding would carry it onto or across 1, the ERROR limit
    (`ratio_text`: 0.99983 reads 0.9998)."""
    return ratio_text(value, ".3f")


def peak_magnitudes(wrenches: np.ndarray) -> np.ndarray:
    """Per mount, the largest |F| (N) and |M| (N·m) of the (k, n, 6) wrenches (force, couple
    in mount axes) over their k rows: (n, 2); zeros for k = 0."""
    if not wrenches.shape[0]:
        return np.zeros((wrenches.shape[1], 2))
    force = np.linalg.norm(wrenches[..., :3], axis=-1).max(axis=0)
    couple = np.linalg.norm(wrenches[..., 3:], axis=-1).max(axis=0)
    return np.stack([force, couple], axis=1)


def displacement_from_start(position: np.ndarray, start: np.ndarray) -> float:
    """The largest |p − start| (m) of the (k, 3) CG positions, `start` the first published
    one; 0 for k = 0."""
    if not position.shape[0]:
        return 0.0
    return float(np.linalg.norm(position - start, axis=1).max())


def mount_travel(
    position: np.ndarray, rotation: np.ndarray, cg: np.ndarray, points: np.ndarray
) -> np.ndarray:
    """Per mount, the largest |d| (m) over k rows of CG positions (k, 3) in F and attitudes
    (k, 3, 3) body → F, for mounts at `points` (n, 3) in F and a scene CG `cg` (3,) (the
    reference pose, where every mount is unstressed); zeros for k = 0."""
    if not position.shape[0]:
        return np.zeros(points.shape[0])
    d = point_displacements(position - cg, rotation, points - cg)
    return np.linalg.norm(d, axis=2).max(axis=0)
