"""The run's peak figures, one definition each, for the replay summary and its JSON, the
report and the sweep's rows: each computes them here, named by the keys below (units in the
name).

- peak force: per mount, the largest magnitude |F| of its force vector at one instant (N); not
  per-component extremes, which come at different times and make no force that acted;
- peak couple: the same of its couple |M| (N·m);
- CG displacement: the largest distance of the CG from its first published position (m): the
  static equilibrium the twin starts at (`initial.mode: equilibrium`; with `given`, the given
  pose), so the static sag under gravity is not counted as motion.
"""

from __future__ import annotations

import numpy as np

PEAK_FORCE = "peak_force_magnitude_N"
PEAK_COUPLE = "peak_couple_magnitude_Nm"
DISPLACEMENT = "max_cg_displacement_from_start_m"


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
