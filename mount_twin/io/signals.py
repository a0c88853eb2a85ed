"""Foundation-motion signals for bundled bags and benchmarks, as an IMU at the origin of F sees
them: specific force (m/s², gravity included: +g up at rest) and angular velocity (rad/s)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mount_twin.scene.description import STANDARD_GRAVITY

MAX_SAMPLES = 10_000_000
"""Most samples a generated signal may have (rate × duration): 1000 s at 10 kHz, ~0.6 GB."""


def _sample_times(rate_hz: float, total: float) -> np.ndarray:
    """Sample times (s) of `total` s at `rate_hz`; ValueError unless that is 1 to MAX_SAMPLES
    samples at a positive rate."""
    if not 0.0 < rate_hz < math.inf:
        msg = f"rate must be > 0 Hz and finite, got {rate_hz!r}"
        raise ValueError(msg)
    if not 0.0 < total < math.inf:
        msg = f"duration must be > 0 s and finite, got {total!r}"
        raise ValueError(msg)
    n = total * rate_hz
    if not 1.0 <= round(n) <= MAX_SAMPLES:
        msg = (
            f"duration × rate must give 1 to {MAX_SAMPLES} samples (MAX_SAMPLES), got "
            f"{total!r} s × {rate_hz!r} Hz = {n:.4g}"
        )
        raise ValueError(msg)
    return np.arange(round(n)) / rate_hz


@dataclass(frozen=True)
class Signal:
    """Samples: t (n,) s from 0; accel (n, 3) specific force, m/s²; gyro (n, 3) rad/s."""

    t: np.ndarray
    accel: np.ndarray
    gyro: np.ndarray


MIN_PULSE_SAMPLES = 4
"""Fewest samples of a half-sine (and of its rebound): at 4 the sampled peak is at least
cos(π/8) = 0.92 of it; at fewer the pulse may fall between two samples and vanish."""


def _check_pulse_fits(
    duration: float, rebound_s: float, rate_hz: float, pre: float, total: float
) -> None:
    """ValueError unless the pulse (duration, s) and its rebound (rebound_s, s; 0: none) are
    sampled at least MIN_PULSE_SAMPLES times each at rate_hz and end by the record's end."""
    for what, span in (("pulse", duration), ("rebound", rebound_s)):
        if span and span * rate_hz < MIN_PULSE_SAMPLES:
            msg = (
                f"the {what}'s {span:.3g} s at {rate_hz:g} Hz is {span * rate_hz:.3g} samples: "
                f"give ≥ {MIN_PULSE_SAMPLES} (rate ≥ {MIN_PULSE_SAMPLES / span:.4g} Hz)"
            )
            raise ValueError(msg)
    end = pre + duration + rebound_s
    if end > total:
        what = "the pulse and its rebound end" if rebound_s else "the pulse ends"
        msg = f"{what} at {end:.4g} s, after the record's end at {total:.4g} s"
        raise ValueError(msg)


def half_sine_shock(
    peak: float = 150.0,
    duration: float = 0.008,
    rate_hz: float = 10000.0,
    pre: float = 0.05,
    total: float = 0.4,
    g: float = STANDARD_GRAVITY,
    *,
    lateral: float = 0.0,
    rebound: float = 0.0,
) -> Signal:
    """Vertical half-sine deck acceleration a(t) = peak·sin(π(t − pre)/duration) during the pulse,
    optionally followed by a rebound and shared with a lateral axis.

    With `rebound` > 0 a downward half-sine of that peak follows at once, lasting
    peak·duration/rebound so that the deck's velocity change 2·peak·duration/π is undone and the
    deck ends at rest, lifted: the double half-sine of naval shock specifications (an upward kick,
    then a longer, weaker deceleration). The lateral component (+y of F, athwartships) is
    `lateral`·a(t) throughout.

    Args:
        peak: m/s² (150 ≈ 15 g); duration: pulse length, s; rate_hz: sampling rate;
        pre: rest before the pulse, s; total: record length, s; g: m/s².
        lateral: share of a(t) along +y of F, −; rebound: peak of the downward half-sine, m/s²
            (0: none).
    """
    if not 0.0 < duration < math.inf:
        msg = f"pulse duration must be > 0 s and finite, got {duration!r}"
        raise ValueError(msg)
    if not math.isfinite(peak) or (rebound > 0.0 and not peak > 0.0):
        msg = (
            f"peak must be finite, and > 0 with a rebound (it undoes an upward kick), got {peak!r}"
        )
        raise ValueError(msg)
    if not 0.0 <= rebound < math.inf:
        msg = f"rebound must be ≥ 0 (the peak of a downward pulse), got {rebound!r} m/s²"
        raise ValueError(msg)
    if not math.isfinite(lateral):
        msg = f"the lateral share must be finite, got {lateral!r}"
        raise ValueError(msg)
    t = _sample_times(rate_hz, total)
    length = peak * duration / rebound if rebound > 0.0 else 0.0
    _check_pulse_fits(duration, length, rate_hz, pre, total)
    tau = t - pre
    a = np.where((tau >= 0.0) & (tau <= duration), peak * np.sin(math.pi * tau / duration), 0.0)
    if rebound > 0.0:
        tau2 = tau - duration
        inside = (tau2 > 0.0) & (tau2 <= length)
        a = a - np.where(inside, rebound * np.sin(math.pi * tau2 / length), 0.0)
    accel = np.zeros((t.size, 3))
    accel[:, 1] = lateral * a
    accel[:, 2] = g + a
    return Signal(t, accel, np.zeros((t.size, 3)))


@dataclass(frozen=True)
class SeaState:
    """A deck's motion for `ship_motion`: roll amplitude (rad) and period (s), heave amplitude
    (m) and period (s), hull vibration amplitude (m/s²) and frequency (Hz)."""

    roll_amp: float = 0.09
    roll_period: float = 8.0
    heave_amp: float = 0.5
    heave_period: float = 6.0
    vib_amp: float = 0.8
    vib_hz: float = 23.0


def ship_motion(
    rate_hz: float = 1000.0,
    total: float = 5.0,
    sea: SeaState = SeaState(),
    g: float = STANDARD_GRAVITY,
) -> Signal:
    """Rolling, heaving deck with hull vibration, sensed at the roll axis (origin of F).

    Roll φ = roll_amp·sin(2πt/roll_period) rad about x of F;
    heave z = heave_amp·sin(2πt/heave_period)
    m in the earth frame; vertical vibration vib_amp·sin(2π·vib_hz·t) m/s² along z of F
    (amplitudes and periods: `sea`).
    """
    t = _sample_times(rate_hz, total)
    wr, wh = 2 * math.pi / sea.roll_period, 2 * math.pi / sea.heave_period
    wv = 2 * math.pi * sea.vib_hz
    phi = sea.roll_amp * np.sin(wr * t)
    phi_dot = sea.roll_amp * wr * np.cos(wr * t)
    heave_acc = -sea.heave_amp * wh**2 * np.sin(wh * t)
    up = g + heave_acc  # earth-vertical specific force
    accel = np.zeros((t.size, 3))
    # Earth vertical seen from F rolled by φ about x: (0, sin φ, cos φ).
    accel[:, 1] = up * np.sin(phi)
    accel[:, 2] = up * np.cos(phi) + sea.vib_amp * np.sin(wv * t)
    gyro = np.zeros((t.size, 3))
    gyro[:, 0] = phi_dot
    return Signal(t, accel, gyro)
