"""Tilt θ of body z from the vertical of F, rad: from quaternions, or from cos θ (R₃₃)."""

from __future__ import annotations

import numpy as np


def tilt_from_quaternions(quat: np.ndarray) -> np.ndarray:
    """Tilt θ of body z from the vertical of F, rad, for (k, 4) quaternions (x, y, z, w)."""
    return tilt_from_cos(1.0 - 2.0 * (quat[:, 0] ** 2 + quat[:, 1] ** 2))  # R₃₃ = cos θ


def tilt_from_cos(cos_tilt: np.ndarray | float) -> np.ndarray:
    """Tilt θ, rad, from cos θ = R₃₃ (clipped to [−1, 1]: rounding may step past it)."""
    if isinstance(cos_tilt, float):  # a live push's one figure: np.clip of a float takes 2 µs
        return np.arccos(min(max(cos_tilt, -1.0), 1.0))  # NaN stays NaN, as np.clip keeps it
    return np.arccos(np.clip(cos_tilt, -1.0, 1.0))
