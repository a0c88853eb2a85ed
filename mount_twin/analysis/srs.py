"""Shock response spectra: the peak absolute acceleration of single-DOF oscillators on a base
whose acceleration is the record, per natural frequency (ISO 18431-4).

Each oscillator is run by Smallwood's ramp-invariant recursive filter (D. O. Smallwood, "An
improved recursive formula for calculating shock response spectra", Shock and Vibration
Bulletin 51, 1981): exact for a base acceleration linear between samples. With E = e^(−ζωT),
K = ω_d·T, C = E cos K, S' = E sin K / K:

    y[n] = (1 − S')·x[n] + 2(S' − C)·x[n−1] + (E² − S')·x[n−2] + 2C·y[n−1] − E²·y[n−2]

Spectra: `maximax` (largest |y| over the record and its residual), `primary` (during the
record), `residual` (after it: the record is followed by zeros long enough for the free
vibration's largest peak, 1.5 periods of the lowest frequency), and the pseudo-velocity
PV = maximax/ω. The filter is accurate while f ≲ fs/10; higher frequencies are flagged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter

ACCURATE_SHARE = 0.1
"""Largest natural frequency as a share of the sampling rate reported as accurate."""


@dataclass(frozen=True)
class Spectrum:
    """Spectra at `frequency_hz` (input units for accelerations; PV in input units · s)."""

    frequency_hz: np.ndarray
    maximax: np.ndarray
    primary: np.ndarray
    residual: np.ndarray
    pseudo_velocity: np.ndarray
    accurate: np.ndarray
    """False where f > ACCURATE_SHARE · fs (the ramp-invariant filter loses accuracy)."""


def octave_frequencies(f_min_hz: float, f_max_hz: float, per_octave: int = 6) -> np.ndarray:
    """f_min·2^(k/per_octave) up to f_max (Hz)."""
    n = math.floor(per_octave * math.log2(f_max_hz / f_min_hz) + 1e-9)
    return f_min_hz * 2.0 ** (np.arange(n + 1) / per_octave)


def srs(
    accel: np.ndarray, rate_hz: float, frequency_hz: np.ndarray, damping: float = 0.05
) -> Spectrum:
    """The spectra of a base acceleration `accel` (n,) sampled at `rate_hz`, damping ratio ζ."""
    f = np.asarray(frequency_hz, dtype=float)
    dt = 1.0 / rate_hz
    pad = np.zeros(math.ceil(1.5 * rate_hz / f.min()) + 2)
    x = np.concatenate([np.asarray(accel, dtype=float), pad])
    n = len(accel)
    maximax, primary, residual = (np.empty(f.size) for _ in range(3))
    for k, fk in enumerate(f):
        w = 2.0 * math.pi * fk
        wd = w * math.sqrt(1.0 - damping**2)
        e = math.exp(-damping * w * dt)
        kk = wd * dt
        c = e * math.cos(kk)
        sp = e * math.sin(kk) / kk
        y = lfilter([1.0 - sp, 2.0 * (sp - c), e * e - sp], [1.0, -2.0 * c, e * e], x)
        primary[k] = np.abs(y[:n]).max()
        residual[k] = np.abs(y[n:]).max()
        maximax[k] = max(primary[k], residual[k])
    return Spectrum(
        f, maximax, primary, residual, maximax / (2.0 * math.pi * f), f <= ACCURATE_SHARE * rate_hz
    )
