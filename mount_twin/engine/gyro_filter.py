"""How the foundation's angular rate Ω and acceleration Ω′ are taken from a sampled gyro.

The twin holds the input between samples (first order: Ω linear in t), so Ω′ is the slope of Ω
between two samples. A gyro's white noise σ (rad/s RMS) sampled at fs becomes slope noise of
about √2·σ·fs in Ω′: 0.004 rad/s at 20 kHz is ~110 rad/s², which a bolted machine answers with
metres per second squared at its mounts, and joint-slip alarms on a record at rest.

Policies (scene key `input.gyro_filter`):

- ``linear_phase`` (default): Ω passes a symmetric (linear-phase) FIR low-pass, which delays
  every frequency by the same N samples, and the specific force f is delayed by those N
  samples too (`engine/delay_line.py`): Ω, Ω′ and f then describe one deck motion, the motion
  N samples ago, and the twin publishes it at the stamps it happened at, N samples late
  (N ≈ 3.0 / (stopband − passband) s: 38 ms by default, at any sample rate). The
  filter is flat to 2·FLATNESS up to `input.gyro_passband_hz` (default 20 Hz: ship motion, hull
  whipping) and attenuates by 2·FLATNESS from `input.gyro_stopband_hz` (default 100 Hz) on, so
  Ω′'s noise is bounded by the stopband, not the sampling rate. A causal filter on Ω alone
  cannot do this: at 20 Hz an error of 1e-3 needs less than 8 µs of lag, and any lag of Ω
  against f is a deck whose rotation disagrees with its acceleration.
- ``none``: Ω as sampled, no latency (exact for clean, e.g. simulated, input).
- ``ignore``: Ω = Ω′ = 0, the foundation's rotation neglected (accelerometer-only records).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.polynomial.polynomial import polyval

from mount_twin import _core

FLATNESS = 2e-5
"""Design ripple δ of the Kaiser window (Kaiser's formulas give about δ in both bands; measured
at 0.4-20 kHz: |H − 1| ≤ 3.5e-5 up to the passband edge, |H| ≤ 2.5e-5 from the stopband edge,
so Ω is flat to 1e-4 as the twin's 1e-3 force budget needs)."""
MIN_RATE_SHARE = 4.0
"""A sample rate below this many times the stopband edge is too low for the filter: raw Ω."""


class Design(NamedTuple):
    """The filter for a sample rate: `half` (N + 1,) taps h[N], h[N ± 1], ... h[N ± N] (the
    centre first; the FIR is symmetric, so it delays by exactly N samples); `rate_hz` the
    sample rate it was designed for; `note` why it is raw (half = [1.0], N = 0), else ''."""

    half: np.ndarray
    rate_hz: float
    note: str

    @property
    def delay(self) -> int:
        """N, the delay in samples."""
        return self.half.shape[0] - 1

    @property
    def delay_s(self) -> float:
        """The delay in seconds at the design rate."""
        return self.delay / self.rate_hz


I0_SERIES = np.array([1.0 / math.factorial(k) ** 2 for k in range(32)])
"""Coefficients of I₀(x) = Σ (x²/4)ᵏ / (k!)² in x²/4: 32 terms reach rounding for β ≤ 20 (the
designs here take β ≈ 9.4: the 24th term is 1e-17 of the sum)."""


def kaiser_window(m: int, beta: float) -> np.ndarray:
    """numpy's `kaiser(m, beta)`, I₀(β·√(1 − r²)) / I₀(β) on r ∈ [−1, 1], by the power series of
    I₀ in Horner form: the same window to 3e-15, at a third of the time of `np.i0`'s
    Chebyshev code (a quarter of a millisecond of every engine's start)."""
    if m == 1:
        return np.ones(1)
    r = 2.0 * np.arange(m) / (m - 1) - 1.0
    quarter_sq = 0.25 * beta * beta * (1.0 - r * r)
    return polyval(quarter_sq, I0_SERIES) / polyval(0.25 * beta * beta, I0_SERIES)


def design(rate_hz: float, passband_hz: float, stopband_hz: float) -> Design:
    """The Kaiser-window low-pass for `rate_hz` (Kaiser 1974: attenuation A = −20 log10 δ,
    β = 0.1102 (A − 8.7), order M = (A − 7.95) / (2.285 Δω) over the transition Δω), ideal
    cut-off mid-transition, taps scaled to a DC gain of exactly 1 (a constant rate, the deck at
    rest, passes unchanged). Raw (N = 0, with a note) below MIN_RATE_SHARE × the stopband."""
    if not rate_hz >= MIN_RATE_SHARE * stopband_hz:
        note = (
            f"sample rate {rate_hz:.4g} Hz is below {MIN_RATE_SHARE:g} × input.gyro_stopband_hz "
            f"({stopband_hz:g} Hz): the gyro is taken raw (no filter, no delay)"
        )
        return Design(np.ones(1), rate_hz, note)
    return Design(_half_taps(rate_hz, passband_hz, stopband_hz).copy(), rate_hz, "")


@lru_cache(maxsize=32)
def _half_taps(rate_hz: float, passband_hz: float, stopband_hz: float) -> np.ndarray:
    """`design`'s taps h[N], h[N ± 1], ... h[N ± N] for a rate it filters, computed once a
    process per (rate, bands): every engine of a sweep or a bench on one record designs the
    same filter (0.06–0.15 ms each). Never handed out: `design` gives each caller a copy."""
    attenuation = -20.0 * math.log10(FLATNESS)
    beta = 0.1102 * (attenuation - 8.7)
    transition = 2.0 * math.pi * (stopband_hz - passband_hz) / rate_hz
    n = math.ceil((attenuation - 7.95) / (2.285 * transition) / 2.0)
    cutoff = (passband_hz + stopband_hz) / rate_hz  # 2 fc / fs
    k = np.arange(-n, n + 1)
    taps = cutoff * np.sinc(cutoff * k) * kaiser_window(2 * n + 1, beta)
    taps /= taps.sum()
    half = taps[n:].copy()
    half.flags.writeable = False
    return half


def response(half: np.ndarray, frequency_hz: np.ndarray, rate_hz: float) -> np.ndarray:
    """The zero-phase gain H(f) = h[N] + 2 Σ h[N + j] cos(2π f j / fs) of the filter (real:
    the phase is the pure delay of N samples)."""
    j = np.arange(1, half.shape[0])
    arg = 2.0 * math.pi * np.outer(frequency_hz, j) / rate_hz
    return half[0] + 2.0 * np.cos(arg) @ half[1:]


fir_rows = _core.fir_rows
"""fir_rows(raw, half, out): out[i, k] = h[N]·raw[i, k + N] + Σ_j h[N + j]·(raw[i, k + N − j]
+ raw[i, k + N + j]), j = 1..N in that order, for k < out.shape[1]: the filtered rate of the
sample at raw[:, k + N] (rad/s; per axis i, rows (3, ·) so the loop over k runs on contiguous
memory).

Each output sums the same terms in the same order whatever samples surround it, so any
batching gives the same bits."""
