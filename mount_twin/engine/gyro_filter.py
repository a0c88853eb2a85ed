"""How the foundation's angular rate Ω and acceleration Ω′ are taken from a sampled gyro.

The twin holds the input between samples (first order: Ω linear in t), so Ω′ is the slope of Ω
between two samples. A gyro's white noise σ (rad/s RMS) sampled at fs becomes slope noise of
about √2·σ·fs in Ω′: 0.004 rad/s at 20 kHz is ~110 rad/s², which a bolted machine answers with
metres per second squared at its mounts, and joint-slip alarms on a record at rest.

Policies (scene key `input.gyro_filter`):

- ``lowpass`` (default): Ω passes a critically damped second-order low-pass (two equal
  first-order sections, advanced by their exact solution for a held input over the actual stamp
  interval, so it holds for irregular stamps and any batching) whose −3 dB frequency is
  `input.gyro_cutoff_hz` (default 50 Hz). Ω′ is then the slope of the filtered Ω, whose noise
  is bounded by the cutoff, not by the sampling rate. The price: Ω lags by
  2τ = 2·√(√2 − 1)/(2π·fc) (4.1 ms at 50 Hz) and rotation above the cutoff is attenuated.
  Ship roll, pitch and hull whipping (< 20 Hz) pass. On a real 47 g water entry with tumbling
  the default changes the peak mount force of the bundled pump by −2 % (`bench/gyro_noise.py`).
- ``none``: Ω as sampled (exact for clean, e.g. simulated, input).
- ``ignore``: Ω = Ω′ = 0, the foundation's rotation neglected (accelerometer-only records).
"""

from __future__ import annotations

import math

import numpy as np

from mount_twin.physics.compiled import kernel
from mount_twin.scene.description import GYRO_FILTERS

SECTION_SHARE = math.sqrt(math.sqrt(2.0) - 1.0)
"""Two equal first-order sections of corner fc/SECTION_SHARE are −3 dB at fc together."""


def section_time_constant(cutoff_hz: float) -> float:
    """Time constant τ (s) of each of the two sections for an overall −3 dB at `cutoff_hz`."""
    return SECTION_SHARE / (2.0 * math.pi * cutoff_hz)


@kernel
def lowpass_rows(t, w, state, t_prev, tau) -> None:
    """Filter gyro rows w (k, 3) rad/s at stamps t (k,) s in place, after the sample at
    `t_prev` s; `state` (2, 3) holds the two sections' outputs y1, y2 and is advanced.

    Over an interval Δt the input x is held at the new sample (as a sample-and-hold would), and
    the sections are advanced by their exact solution: with e = exp(−Δt/τ),
    y1 ← x + (y1 − x)·e and y2 ← x + ((y2 − x) + (y1 − x)·Δt/τ)·e (the old y1): a cascade that
    is exact for any stamp spacing, so irregular stamps and any batching give the same numbers.
    """
    before = t_prev
    for k in range(t.shape[0]):
        r = (t[k] - before) / tau
        e = math.exp(-r)
        before = t[k]
        for i in range(3):
            x = w[k, i]
            d1 = state[0, i] - x
            state[1, i] = x + (state[1, i] - x + d1 * r) * e
            state[0, i] = x + d1 * e
            w[k, i] = state[1, i]


class GyroConditioner:
    """Applies an `input.gyro_filter` policy to the Ω rows of accepted samples, in order.

    `start(w0)` at each (re)start: the filter is at rest at the start sample's rate, which is
    taken as it is (the start is a static equilibrium, Ω′ = 0). `rows(t, w, t_prev)` then
    conditions the next rows in place.
    """

    def __init__(self, policy: str, cutoff_hz: float) -> None:
        if policy not in GYRO_FILTERS:
            msg = f"gyro filter {policy!r} is not one of {GYRO_FILTERS}"
            raise ValueError(msg)
        self.policy = policy
        self.tau = section_time_constant(cutoff_hz)
        self._state = np.zeros((2, 3))

    def start(self, w0: np.ndarray) -> np.ndarray:
        """The start sample's Ω as used (rad/s, a copy), and the filter at rest there."""
        w0 = np.zeros(3) if self.policy == "ignore" else w0.copy()
        self._state[:] = w0
        return w0

    def rows(self, t: np.ndarray, w: np.ndarray, t_prev: float) -> None:
        """Condition rows w (k, 3) rad/s at stamps t (k,) s in place; t_prev: the last stamp
        conditioned."""
        if self.policy == "lowpass":
            lowpass_rows(t, w, self._state, t_prev, self.tau)
        elif self.policy == "ignore":
            w[:] = 0.0
