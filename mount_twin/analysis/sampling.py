"""A record's samples on one uniform grid, as filters running at one rate need them.

Recorders stamp their samples with jitter: the bundled real 20 kHz records step 50 µs but for a
few steps of 30 to 61 µs. Within `JITTER_SHARE` of the median step, the stamps are taken as
jitter of a uniform clock (the record as sampled, at its mean rate). Beyond it, the samples are
taken as where the stamps put them and resampled onto a uniform grid at the median step by a
cubic spline (not-a-knot) through every sample: exact at the grid points that are sample points,
an interpolation error of about (2πf·Δt)⁴/384 of a component at f elsewhere (4e-4 at f = fs/10,
the highest frequency an SRS reports as accurate; test_srs holds a jittered record's spectra to
1e-3 of the exact ones). What is not one sampled signal is refused, saying why: stamps that do
not increase, or a hole (a step past `HOLE_SHARE` of the median: samples are missing there and
nothing can be interpolated across it honestly).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

JITTER_SHARE = 0.005
"""Steps within this share of the median are jitter of a uniform clock: not resampled."""
HOLE_SHARE = 1.5
"""A step longer than this many median steps is a hole: refused."""


@dataclass(frozen=True)
class Uniform:
    """A record on a uniform grid: `rate_hz`, stamps `t` (s), samples `values` (n, ...), and
    `note`: how it was made uniform ('' if taken as sampled)."""

    rate_hz: float
    t: np.ndarray
    values: np.ndarray
    note: str


def uniform(t: np.ndarray, values: np.ndarray, source: str) -> Uniform:
    """`values` (n, ...) sampled at stamps `t` (s) on a uniform grid (see the module).

    Raises:
        ValueError: naming `source`, for fewer than two samples, stamps that do not increase,
            or a hole.
    """
    n = len(t)
    if n < 2:
        msg = f"{source}: {n} sample(s): a spectrum needs a record"
        raise ValueError(msg)
    steps = np.diff(t)
    if not (steps > 0.0).all():
        k = int(np.argmax(steps <= 0.0)) + 1
        msg = (
            f"{source}: not one sampled signal: stamp {k} ({t[k]:.9g} s) does not come after "
            f"the one before ({t[k - 1]:.9g} s)"
        )
        raise ValueError(msg)
    median = float(np.median(steps))
    if steps.max() > HOLE_SHARE * median:
        k = int(np.argmax(steps))
        msg = (
            f"{source}: a hole of {steps[k]:.6g} s after {t[k]:.9g} s ({steps[k] / median:.3g} "
            f"times the {median:.6g} s step): samples are missing; cut the record there"
        )
        raise ValueError(msg)
    off = np.abs(steps - median) > JITTER_SHARE * median
    if not off.any():
        return Uniform((n - 1) / float(t[-1] - t[0]), t, values, "")
    from scipy.interpolate import CubicSpline

    intervals = round(float(t[-1] - t[0]) / median)
    grid = np.linspace(float(t[0]), float(t[-1]), intervals + 1)
    rate_hz = intervals / float(t[-1] - t[0])
    note = (
        f"resampled: {int(off.sum())} of {n - 1} steps are off the median {median:.6g} s by "
        f"more than {JITTER_SHARE:.1%} ({steps.min():.6g} to {steps.max():.6g} s); a cubic "
        f"spline through every sample onto a uniform grid at {rate_hz:.6g} Hz"
    )
    return Uniform(rate_hz, grid, CubicSpline(t, values, axis=0)(grid), note)
