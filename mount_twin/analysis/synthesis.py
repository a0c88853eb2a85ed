"""Acceleration time histories whose shock response spectrum meets a design spectrum.

The sum of wavelets (D. O. Smallwood's method, as in NASA-HDBK-7005 and the usual
shock-synthesis tools): one wavelet per natural frequency f_m of the spectrum,

    w_m(t) = A_m · sin(ω_m (t − τ_m) / N_m) · sin(ω_m (t − τ_m)),  τ_m ≤ t ≤ τ_m + N_m/(2 f_m)

with N_m an odd number of half-cycles ≥ 3. Each wavelet integrates to zero velocity and to zero
displacement over its span (the half-sine envelope's ends make both integrals vanish for odd
N), so the sum starts and ends at rest, as a shock machine's table must. The amplitudes are
iterated: A_m ← A_m · (design(f_m) / SRS(f_m)) until the maximax spectrum is within ±CLOSE_DB
of the design at every f_m, or, within the tolerance band, no closer in 10 more iterations (or
`max_iterations`); the closest history within the band is returned. The delays τ_m and the
half-cycle counts N_m are drawn from a seeded generator: each seed gives another time history
of the same spectrum.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mount_twin.analysis.design_margin import TOLERANCE_DB, DesignCheck, check_design
from mount_twin.analysis.srs import octave_frequencies, srs
from mount_twin.io.signals import MAX_SAMPLES, Signal
from mount_twin.scene.description import STANDARD_GRAVITY as G

CLOSE_DB = 0.5
"""The iteration goes on past the tolerance until every margin is within ±this (dB), or it
stops improving: a spectrum on the tolerance's edge meets it, but barely."""


@dataclass(frozen=True)
class Synthesis:
    """A synthesised shock: stamps `t` (s) from 0, `accel` (m/s²), its spectrum's `check`
    against the design (maximax, in g), and the `iterations` taken."""

    t: np.ndarray
    accel: np.ndarray
    check: DesignCheck
    iterations: int

    @property
    def velocity(self) -> np.ndarray:
        """m/s, the trapezoidal integral of `accel` from rest."""
        dt = float(self.t[1] - self.t[0])
        return np.concatenate([[0.0], np.cumsum(0.5 * (self.accel[1:] + self.accel[:-1]) * dt)])

    @property
    def displacement(self) -> np.ndarray:
        """m, the trapezoidal integral of `velocity` from rest."""
        v = self.velocity
        dt = float(self.t[1] - self.t[0])
        return np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * dt)])


def wavelets(
    t: np.ndarray, freqs: np.ndarray, halves: np.ndarray, delays: np.ndarray
) -> np.ndarray:
    """(len(freqs), len(t)): each unit wavelet at its frequency (Hz), odd half-cycle count and
    delay (s), zero outside its span."""
    out = np.zeros((freqs.shape[0], t.shape[0]))
    for m, (f, n, tau) in enumerate(zip(freqs, halves, delays, strict=True)):
        s = t - tau
        on = (s >= 0.0) & (s <= n / (2.0 * f))
        w = 2.0 * math.pi * f
        out[m, on] = np.sin(w * s[on] / n) * np.sin(w * s[on])
    return out


def synthesize(
    design_hz: list[float] | np.ndarray,
    design_g: list[float] | np.ndarray,
    rate_hz: float,
    *,
    damping: float = 0.05,
    seed: int = 0,
    per_octave: float = 6.0,
    tolerance_db: tuple[float, float] = TOLERANCE_DB,
    max_iterations: int = 200,
) -> Synthesis:
    """A time history at `rate_hz` whose maximax SRS (ζ = `damping`) is within `tolerance_db`
    of the design table (Hz, g; log-log) at 1/`per_octave`-octave frequencies over its range.

    The record lasts until the longest wavelet has ended, plus one period of the lowest
    frequency at rest. Raises ValueError if the design reaches past rate/10 (the SRS is not
    accurate there) or the iteration does not meet the tolerance.
    """
    design_hz = np.asarray(design_hz, float)
    if design_hz[-1] > 0.1 * rate_hz:
        msg = (
            f"the design reaches {design_hz[-1]:g} Hz: a rate of at least "
            f"{10 * design_hz[-1]:g} Hz is needed (the SRS is accurate to rate/10)"
        )
        raise ValueError(msg)
    freqs = octave_frequencies(float(design_hz[0]), float(design_hz[-1]), per_octave)
    target = check_design(freqs, np.ones_like(freqs), design_hz, design_g).design
    rng = np.random.default_rng(seed)
    # 3 to 11 half-cycles (the low frequencies the fewest: they are the longest), delays
    # within the first tenth of a second so the wavelets overlap as a shock does
    halves = np.array([2 * int(rng.integers(1, 6)) + 1 for _ in freqs], dtype=float)
    halves[freqs < 4.0 * freqs[0]] = 3.0
    delays = rng.uniform(0.0, 0.1, freqs.shape[0]) * (freqs[0] / freqs) ** 0.5
    span = float(np.max(delays + halves / (2.0 * freqs))) + 1.0 / float(freqs[0])
    t = np.arange(math.ceil(span * rate_hz) + 1) / rate_hz
    basis = wavelets(t, freqs, halves, delays)
    amplitude = target * G / 5.0
    best: Synthesis | None = None
    for iteration in range(1, max_iterations + 1):
        accel = amplitude @ basis
        got = srs(accel, rate_hz, freqs, damping).maximax / G
        check = check_design(freqs, got, design_hz, design_g, tolerance_db)
        spread = float(np.abs(check.margin_db).max())
        if check.passed and (best is None or spread < np.abs(best.check.margin_db).max()):
            best = Synthesis(t, accel, check, iteration)
        if best is not None and (spread <= CLOSE_DB or iteration - best.iterations >= 10):
            return best  # close, or no closer in 10 more iterations
        amplitude = amplitude * (target / got)
    if best is not None:
        return best
    msg = (
        f"the synthesis (seed {seed}) did not meet the design in {max_iterations} iterations: "
        f"{check.summary()}"  # which names the band (it had also said "within (-1.5, 3.0) dB")
    )
    raise ValueError(msg)


def imu_record(shock: Synthesis, rate_hz: float, axis: str, head_s: float) -> Signal:
    """The shock as an Imu at rest reads it: +g on z throughout, `head_s` of rest first (the
    start checks, the SRS's gravity head), then the shock along the sensor's `axis`. At most
    MAX_SAMPLES samples, as any generated signal (ValueError)."""
    head = round(head_s * rate_hz)
    n = head + shock.t.shape[0]
    if n > MAX_SAMPLES:
        msg = (
            f"{head_s:g} s of rest and {shock.t[-1]:.3g} s of shock at {rate_hz:g} Hz: {n:.4g} "
            f"samples, more than a generated signal may have (MAX_SAMPLES, {MAX_SAMPLES})"
        )
        raise ValueError(msg)
    accel = np.zeros((n, 3))
    accel[:, 2] = G
    accel[head:, "xyz".index(axis)] += shock.accel
    return Signal(np.arange(n) / rate_hz, accel, np.zeros((n, 3)))
