"""Shock response spectra: the peak absolute acceleration of single-DOF oscillators on a base
whose acceleration is the record, per natural frequency (ISO 18431-4).

Each oscillator x″ + 2ζωx′ + ω²x = −a(t) (x relative to the base, absolute acceleration
ÿ = −(2ζωx′ + ω²x)) is run by Smallwood's ramp-invariant recursive filter (D. O. Smallwood,
"An improved recursive formula for calculating shock response spectra", Shock and Vibration
Bulletin 51, 1981), exact for a base acceleration linear between samples, damped or not. With
T = 1/fs, E = e^(−ζωT), K = ω_d·T, C = E cos K, S' = E sin K / K:

    y[n] = (1 − S')·x[n] + 2(S' − C)·x[n−1] + (E² − S')·x[n−2] + 2C·y[n−1] − E²·y[n−2]

The oscillator starts at rest one sample before the record, the base acceleration rising
linearly from 0 then to the first sample (as in ISO 18431-4 and pyyeti): a record that does not
start at 0 gets a step (remove gravity first). The record is followed by zeros for at least one
period of the lowest frequency, ceil(fs/f_min) samples, in which the free vibration reaches its
largest peak; the base acceleration falls linearly from the last sample to 0 over the first
of them. Spectra, all of the absolute acceleration y sampled at the record's instants:

- `primary`: max |y| during the record (its samples);
- `residual`: max |y| after it (the zeros);
- `maximax`: max(primary, residual); `positive`, `negative`: max y, −min y over both (or 0);
- `pseudo_velocity`: maximax/ω (PV from the absolute acceleration, not ω·max|x|: the two are
  equal undamped and differ by a term of order ζ otherwise).

Accuracy: the peaks are picked at the samples, so a peak between two samples is missed by at
most 1 − cos(πf/fs) (1.2 % at f = fs/20, 4.9 % at fs/10), and a sampled smooth input taken as
linear between samples loses up to 1 − sinc²(f/fs) of a sine at f (0.8 % at fs/20, 3.2 % at
fs/10): together at most 2 % up to fs/20, 8 % at fs/10 (the usual minimum of 10 samples per
period). `accurate` flags the frequencies up to fs/10; from fs/2 up they are refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter

ACCURATE_SHARE = 0.1
"""Largest natural frequency as a share of the sampling rate reported as accurate."""
DEFAULT_DAMPING = 0.05
"""Damping ratio ζ when neither ζ nor Q is given (Q = 10, the usual shock practice)."""


@dataclass(frozen=True)
class Spectrum:
    """Spectra at `frequency_hz` (accelerations in the input's units, PV in input units · s)."""

    frequency_hz: np.ndarray
    maximax: np.ndarray
    primary: np.ndarray
    residual: np.ndarray
    positive: np.ndarray
    negative: np.ndarray
    pseudo_velocity: np.ndarray
    accurate: np.ndarray
    """False where f > ACCURATE_SHARE · fs (see the module docstring)."""


def damping_ratio(damping: float | None = None, q: float | None = None) -> float:
    """ζ from a damping ratio or a quality factor Q = 1/(2ζ) (at most one; neither: 0.05)."""
    if damping is not None and q is not None:
        msg = f"give the damping as ζ or as Q, not both (ζ = {damping}, Q = {q})"
        raise ValueError(msg)
    if q is not None:
        if not q > 0.5:
            msg = f"Q = {q}: an SRS oscillator is underdamped, Q > 0.5"
            raise ValueError(msg)
        return 1.0 / (2.0 * q)
    zeta = DEFAULT_DAMPING if damping is None else damping
    if not 0.0 <= zeta < 1.0:
        msg = f"ζ = {zeta}: an SRS oscillator is underdamped, 0 ≤ ζ < 1"
        raise ValueError(msg)
    return zeta


def octave_frequencies(f_min_hz: float, f_max_hz: float, per_octave: float = 6) -> np.ndarray:
    """f_min·2^(k/per_octave), k = 0, 1, …, up to f_max (Hz): 1/per_octave octave steps."""
    if not 0.0 < f_min_hz <= f_max_hz or not per_octave > 0.0:
        msg = (
            f"octave spacing needs 0 < f_min ≤ f_max and steps per octave > 0 "
            f"(f_min = {f_min_hz} Hz, f_max = {f_max_hz} Hz, per octave {per_octave})"
        )
        raise ValueError(msg)
    n = math.floor(per_octave * math.log2(f_max_hz / f_min_hz) + 1e-9)
    return f_min_hz * 2.0 ** (np.arange(n + 1) / per_octave)


def absolute_acceleration_filters(
    frequency_hz: np.ndarray, rate_hz: float, damping: float
) -> tuple[np.ndarray, np.ndarray]:
    """Smallwood's coefficients (b, a), each (len(frequency_hz), 3), for scipy's lfilter."""
    w = 2.0 * np.pi * np.asarray(frequency_hz, dtype=float)
    k = w * math.sqrt(1.0 - damping**2) / rate_hz
    e = np.exp(-damping * w / rate_hz)
    c = e * np.cos(k)
    sp = e * np.sin(k) / k
    b = np.stack([1.0 - sp, 2.0 * (sp - c), e * e - sp], axis=1)
    a = np.stack([np.ones_like(c), -2.0 * c, e * e], axis=1)
    return b, a


def srs(
    accel: np.ndarray,
    rate_hz: float,
    frequency_hz: np.ndarray,
    damping: float | None = None,
    *,
    q: float | None = None,
) -> Spectrum:
    """The spectra of a base acceleration `accel` (n,) sampled at `rate_hz` (Hz), at natural
    frequencies `frequency_hz` (Hz), damping ratio ζ = `damping` or quality factor `q`."""
    zeta = damping_ratio(damping, q)
    x = np.asarray(accel, dtype=float)
    f = np.atleast_1d(np.asarray(frequency_hz, dtype=float))
    if x.ndim != 1 or x.size == 0 or not np.all(np.isfinite(x)):
        msg = f"the record must be a non-empty 1-D array of finite values (shape {x.shape})"
        raise ValueError(msg)
    if not rate_hz > 0.0:
        msg = f"the sampling rate must be positive ({rate_hz} Hz)"
        raise ValueError(msg)
    if f.ndim != 1 or f.size == 0:
        msg = f"natural frequencies must be a non-empty 1-D array (shape {f.shape})"
        raise ValueError(msg)
    if not np.all(f > 0.0) or not np.all(f < 0.5 * rate_hz):
        msg = (
            f"natural frequencies must lie between 0 and half the sampling rate "
            f"({0.5 * rate_hz:g} Hz); got {f.min():g} to {f.max():g} Hz"
        )
        raise ValueError(msg)
    n = x.size
    padded = np.concatenate([x, np.zeros(math.ceil(rate_hz / f.min()))])
    b, a = absolute_acceleration_filters(f, rate_hz, zeta)
    primary, residual, positive, negative = (np.empty(f.size) for _ in range(4))
    for k in range(f.size):
        y = lfilter(b[k], a[k], padded)
        primary[k] = np.abs(y[:n]).max()
        residual[k] = np.abs(y[n:]).max()
        positive[k] = max(float(y.max()), 0.0)
        negative[k] = -min(float(y.min()), 0.0)
    maximax = np.maximum(primary, residual)
    return Spectrum(
        frequency_hz=f,
        maximax=maximax,
        primary=primary,
        residual=residual,
        positive=positive,
        negative=negative,
        pseudo_velocity=maximax / (2.0 * np.pi * f),
        accurate=f <= ACCURATE_SHARE * rate_hz,
    )


GRAVITY_MODES = ("mean-head", "first", "none")
"""How `gravity_offset` finds the constant to take out of a record."""
HEAD_S = 0.01
"""Default quiet head of a record for `mean-head`, s."""


QUIET_SHARE = 0.1
"""A quiet head strays from its mean by at most this share of what the whole record does: the
shock itself in it would be taken out of the record as gravity (a 60 ms head over the bundled
genset's 50 ms rest and 5 ms pulse took 28 m/s² for gravity)."""
QUIET_FLOOR_M_S2 = 5.0
"""Straying this far (m/s², about half a g) is quiet whatever the record: a MEMS IMU's noise
peaks (2.1 m/s² in test/data/water_entry_rest_20khz_excerpt.csv) on a record at rest."""


def gravity_offset(
    t: np.ndarray, accel: np.ndarray, mode: str = "mean-head", head_s: float = HEAD_S
) -> tuple[np.ndarray, str]:
    """The per-axis constant (m/s²) to take out of a record (t s, accel (n, 3) m/s²) before its
    spectra, and how it was found: `mean-head`, the mean over the first head_s s (which must be
    quiet, QUIET_SHARE and QUIET_FLOOR_M_S2, else ValueError: gravity and bias, the noise
    averaged down); `first`, the first sample; `none`, zero
    (a constant is then a step)."""
    if mode == "none":
        return np.zeros(3), "nothing"
    if mode == "first":
        return accel[0], "the first sample"
    if mode != "mean-head":
        msg = f"gravity mode {mode!r}: choose from {', '.join(GRAVITY_MODES)}"
        raise ValueError(msg)
    if not head_s > 0.0:
        msg = f"head_s (srs --head) {head_s} s: the quiet head must be longer than 0"
        raise ValueError(msg)
    count = int(np.count_nonzero(t - t[0] < head_s))
    if count == len(t):
        msg = (
            f"head_s (srs --head) {head_s:g} s: the whole record ({t[-1] - t[0]:.4g} s); the "
            "head is the quiet part before the shock, its mean gravity and bias"
        )
        raise ValueError(msg)
    mean = accel[:count].mean(axis=0)
    axes = np.isfinite(mean)  # an axis of NaN (a frozen DOF's response) has no spectrum
    off = accel[:, axes] - mean[axes]
    head_spread = float(np.linalg.norm(off[:count], axis=1).max())
    spread = float(np.linalg.norm(off, axis=1).max())
    if head_spread > max(QUIET_SHARE * spread, QUIET_FLOOR_M_S2):
        msg = (
            f"head_s (srs --head) {head_s:g} s: not quiet: its samples stray {head_spread:.4g} "
            f"m/s² from their mean, {head_spread / spread:.2g} of the whole record's "
            f"{spread:.4g} (at most {QUIET_SHARE:g}, or {QUIET_FLOOR_M_S2:g} m/s²): a shorter "
            "head, before the shock, or --gravity first or none"
        )
        raise ValueError(msg)
    return mean, f"the mean of the first {count} samples"
