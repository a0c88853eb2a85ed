"""A rigid deck's motion as its IMU reads it: specific force and angular rate, sensor frame.

For checks of how the twin takes a moving foundation (`input.gyro_filter`): the deck turns by
fixed-axis roll φ, pitch θ, yaw ψ (R = Rz(ψ) Ry(θ) Rx(φ), deck → world, z up) and its sensor
point moves by (surge, sway, heave) in the world, each a sum of sine waves faded in and out by a
raised cosine, so the deck is at rest at both ends (a twin starts at equilibrium). Everything is
closed form: Ω = (φ′ − ψ′ sin θ, θ′ cos φ + ψ′ cos θ sin φ, −θ′ sin φ + ψ′ cos θ cos φ) in the
deck frame, f = Rᵀ (a + g ẑ) with a the sensor point's acceleration; no finite difference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mount_twin.engine.batch import SampleBatch
from mount_twin.scene.description import STANDARD_GRAVITY


@dataclass(frozen=True)
class Wave:
    """amplitude · sin(2π frequency t + phase): rad for an angle, m for a displacement."""

    amplitude: float
    frequency_hz: float
    phase_rad: float = 0.0


@dataclass(frozen=True)
class DeckMotion:
    """Waves per degree of freedom: angles (roll, pitch, yaw) and the sensor point's
    displacement (surge, sway, heave), all faded in and out over `fade_s` (s)."""

    angles: tuple[tuple[Wave, ...], tuple[Wave, ...], tuple[Wave, ...]]
    displacement: tuple[tuple[Wave, ...], tuple[Wave, ...], tuple[Wave, ...]] = ((), (), ())
    fade_s: float = 1.0


def rolling(amplitude_rad: float, frequency_hz: float, fade_s: float = 1.0) -> DeckMotion:
    """A deck rolling about x through its sensor."""
    return DeckMotion(((Wave(amplitude_rad, frequency_hz),), (), ()), fade_s=fade_s)


SHIP = DeckMotion(
    (
        (Wave(0.08, 1.0 / 3.0), Wave(0.01, 1.3, 0.4)),
        (Wave(0.04, 1.0 / 2.2, 1.0),),
        (Wave(0.02, 0.12, 0.3),),
    ),
    ((Wave(0.3, 0.15),), (Wave(0.5, 1.0 / 3.0, 2.0),), (Wave(1.2, 1.0 / 2.2, 0.5),)),
    fade_s=2.0,
)
"""A ship's deck in a seaway: roll (3 s period), pitch (2.2 s), yaw, surge, sway and heave."""


def _envelope(t: np.ndarray, duration_s: float, fade_s: float) -> tuple[np.ndarray, ...]:
    """The fade e(t) (0 at both ends, 1 between the fades) and its first two derivatives."""
    rise = t < fade_s
    fall = t > duration_s - fade_s
    tau = np.where(fall, duration_s - t, np.where(rise, t, fade_s))
    sign = np.where(fall, -1.0, 1.0)
    k = math.pi / fade_s
    ramp = rise | fall
    e = np.where(ramp, 0.5 * (1.0 - np.cos(k * tau)), 1.0)
    de = np.where(ramp, sign * 0.5 * k * np.sin(k * tau), 0.0)
    dde = np.where(ramp, 0.5 * k * k * np.cos(k * tau), 0.0)
    return e, de, dde


def _signal(waves: tuple[Wave, ...], t: np.ndarray, envelope: tuple[np.ndarray, ...]):
    """The faded sum of `waves` at t and its first two derivatives."""
    e, de, dde = envelope
    x, dx, ddx = np.zeros_like(t), np.zeros_like(t), np.zeros_like(t)
    for w in waves:
        omega = 2.0 * math.pi * w.frequency_hz
        s = w.amplitude * np.sin(omega * t + w.phase_rad)
        c = w.amplitude * omega * np.cos(omega * t + w.phase_rad)
        x += e * s
        dx += de * s + e * c
        ddx += dde * s + 2.0 * de * c - e * omega * omega * s
    return x, dx, ddx


def deck_samples(
    motion: DeckMotion,
    rate_hz: float,
    duration_s: float,
    start_s: float = 1.0,
    g: float = STANDARD_GRAVITY,
) -> SampleBatch:
    """The deck IMU's samples at `rate_hz` over `duration_s` (stamps from `start_s`, s):
    specific force (m/s²) and angular rate (rad/s) in the deck frame, frame_id ''."""
    t = np.arange(round(duration_s * rate_hz) + 1) / rate_hz
    env = _envelope(t, duration_s, motion.fade_s)
    (phi, dphi, _), (theta, dtheta, _), (psi, dpsi, _) = (
        _signal(w, t, env) for w in motion.angles
    )
    accel = np.stack([_signal(w, t, env)[2] for w in motion.displacement], axis=1)
    accel[:, 2] += g
    cf, sf, ct, st, cp, sp = (
        np.cos(phi),
        np.sin(phi),
        np.cos(theta),
        np.sin(theta),
        np.cos(psi),
        np.sin(psi),
    )
    # rows of R = Rz(ψ) Ry(θ) Rx(φ); f = Rᵀ a_world, component j = Σ_i R[i, j] a_i
    rot = np.empty((t.shape[0], 3, 3))
    rot[:, 0] = np.stack([cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf], axis=1)
    rot[:, 1] = np.stack([sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf], axis=1)
    rot[:, 2] = np.stack([-st, ct * sf, ct * cf], axis=1)
    force = np.einsum("nij,ni->nj", rot, accel)
    gyro = np.stack(
        [
            dphi - dpsi * st,
            dtheta * cf + dpsi * ct * sf,
            -dtheta * sf + dpsi * ct * cf,
        ],
        axis=1,
    )
    return SampleBatch(start_s + t, force, gyro, [""] * t.shape[0])
