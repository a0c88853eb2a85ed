"""Single vertical DOF under a half-sine base shock, pushed through TwinEngine (notes §6, §8).

With z the CG displacement in F and f_s = g + a(t) the measured specific force, the twin solves
m z'' = −k z − c z' − m f_s. Relative to the static sag z_s = −m g / k, x = z − z_s obeys
x'' + 2ζω_n x' + ω_n² x = −a(t). Truth:
- the exact sampled-data response to the input the engine actually integrates (linear or held
  between samples), from the matrix exponential of the augmented system [x, x', u, u'];
- the closed-form response to the continuous half-sine (steady state plus homogeneous part during
  the pulse, free decay after it), itself checked against the Duhamel integral by quad.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from physics_helpers import G, base_scene, build, mount
from scipy.integrate import quad
from scipy.linalg import expm

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.signals import half_sine_shock

MASS, FN, ZETA = 50.0, 40.0, 0.05  # kg, Hz, damping ratio
WN = 2 * math.pi * FN
WD = WN * math.sqrt(1 - ZETA**2)
K, C = MASS * WN**2, 2 * ZETA * WN * MASS
CG_Z = 0.25
PEAK, PULSE, PRE, RATE, TOTAL = 150.0, 0.008, 0.01, 20000.0, 0.15
OMEGA_P = math.pi / PULSE


def closed_form_half_sine(t: np.ndarray) -> np.ndarray:
    """x(t) for x'' + 2ζω_n x' + ω_n² x = −PEAK sin(Ω(t − PRE)) on [PRE, PRE + PULSE], else 0."""
    gain = -PEAK / (WN**2 - OMEGA_P**2 + 2j * ZETA * WN * OMEGA_P)  # steady state of e^{iΩt}

    def xp(s):
        return (gain * np.exp(1j * OMEGA_P * s)).imag

    def vp(s):
        return (1j * OMEGA_P * gain * np.exp(1j * OMEGA_P * s)).imag

    a0 = -xp(0.0)
    b0 = (-vp(0.0) + ZETA * WN * a0) / WD

    def during(s):
        return xp(s) + np.exp(-ZETA * WN * s) * (a0 * np.cos(WD * s) + b0 * np.sin(WD * s))

    def during_v(s):
        e = np.exp(-ZETA * WN * s)
        homog = a0 * np.cos(WD * s) + b0 * np.sin(WD * s)
        homog_v = WD * (-a0 * np.sin(WD * s) + b0 * np.cos(WD * s))
        return vp(s) + e * (homog_v - ZETA * WN * homog)

    x_end, v_end = during(PULSE), during_v(PULSE)
    tau = np.asarray(t, dtype=float) - PRE
    out = np.zeros_like(tau)
    inside = (tau > 0.0) & (tau <= PULSE)
    out[inside] = during(tau[inside])
    after = tau > PULSE
    s = tau[after] - PULSE
    out[after] = np.exp(-ZETA * WN * s) * (
        x_end * np.cos(WD * s) + (v_end + ZETA * WN * x_end) / WD * np.sin(WD * s)
    )
    return out


def duhamel(t: float) -> float:
    """x(t) = −∫ a(τ) h(t − τ) dτ, h(t) = e^{−ζω_n t} sin(ω_d t)/ω_d, by adaptive quadrature."""
    tau = t - PRE
    if tau <= 0.0:
        return 0.0

    def integrand(s):
        return (
            PEAK
            * math.sin(OMEGA_P * s)
            * math.exp(-ZETA * WN * (tau - s))
            * math.sin(WD * (tau - s))
            / WD
        )

    return -quad(integrand, 0.0, min(tau, PULSE), epsabs=1e-16, epsrel=1e-13, limit=200)[0]


def exact_sampled_response(t: np.ndarray, a: np.ndarray, first_order: bool) -> np.ndarray:
    """Exact x at the stamps for the input −a interpolated linearly (or held) between samples."""
    aug = np.zeros((4, 4))
    aug[:2, :2] = [[0.0, 1.0], [-(WN**2), -2 * ZETA * WN]]
    aug[1, 2] = -1.0  # x'' gets −a
    aug[2, 3] = 1.0  # a' is the slope
    x = np.zeros(t.size)
    state = np.zeros(2)
    cache: dict[float, np.ndarray] = {}
    for j in range(1, t.size):
        dt = t[j] - t[j - 1]
        key = round(dt, 15)
        if key not in cache:
            cache[key] = expm(aug * dt)
        slope = (a[j] - a[j - 1]) / dt if first_order else 0.0
        state = (cache[key] @ np.array([state[0], state[1], a[j - 1], slope]))[:2]
        x[j] = state[0]
    return x


@pytest.fixture(scope="module")
def signal():
    return half_sine_shock(PEAK, PULSE, RATE, PRE, TOTAL, G)


def run_twin(signal, hold: str) -> tuple[np.ndarray, np.ndarray]:
    data = base_scene(
        MASS,
        [0.1, -0.2, CG_Z],
        [1.0, 2.0, 2.5, 0.0, 0.0, 0.0],
        [mount("iso", [0.1, -0.2, 0.0], [1e5, 1e5, K, 10.0, 10.0, 10.0], [0, 0, C, 0, 0, 0])],
        dofs=["z"],
        rtol=1e-10,
        atol=1e-13,
    )
    data["input"]["hold"] = hold
    engine = TwinEngine(build(data))
    n = signal.t.size
    out = engine.run(SampleBatch(signal.t, signal.accel, signal.gyro, ["imu"] * n))
    assert len(out) == n, f"{len(out)} outputs for {n} samples"
    np.testing.assert_array_equal(out.stamps, signal.t)
    return out.stamps, out.pose[:, 2] - CG_Z


def test_closed_form_half_sine_response_matches_the_duhamel_integral():
    """Guards the reference itself."""
    times = np.array([0.011, 0.014, 0.0175, 0.018, 0.03, 0.1])
    cf = closed_form_half_sine(times)
    dq = np.array([duhamel(t) for t in times])
    np.testing.assert_allclose(cf, dq, rtol=0, atol=1e-12 * np.max(np.abs(dq)))


def test_twin_starts_at_the_static_sag_weight_over_stiffness(signal):
    _, z = run_twin(signal, "first_order")
    assert z[0] == pytest.approx(-MASS * G / K, rel=1e-9)


@pytest.mark.parametrize("hold", ["first_order", "zero_order"])
def test_relative_displacement_equals_the_exact_response_to_the_sampled_input(signal, hold):
    t, z = run_twin(signal, hold)
    x_twin = z + MASS * G / K
    x_ref = exact_sampled_response(t, signal.accel[:, 2] - G, hold == "first_order")
    peak = np.max(np.abs(x_ref))
    err = np.max(np.abs(x_twin - x_ref)) / peak
    assert peak > 1e-3, "the shock should move the body by millimetres"
    assert err < 1e-8, f"{hold}: twin differs from the exact sampled response by {err:.3g} of peak"


def test_relative_displacement_equals_the_closed_form_half_sine_response(signal):
    """First-order hold of a 20 kHz sampled sine is not the sine: the linear interpolation
    misses the arc by up to (dt²/8)·a'' ≈ 5e-5 of the pulse peak, hence 1e-4 of peak here."""
    t, z = run_twin(signal, "first_order")
    x_twin = z + MASS * G / K
    x_ref = closed_form_half_sine(t)
    peak = np.max(np.abs(x_ref))
    err = np.max(np.abs(x_twin - x_ref)) / peak
    assert err < 1e-4, f"twin differs from the closed-form half-sine response by {err:.3g} of peak"
    # and the peak value itself (shock spectrum point) to the same accuracy
    assert np.max(np.abs(x_twin)) == pytest.approx(peak, rel=1e-4)
