"""How Ω and Ω′ come from a sampled gyro (`input.gyro_filter`): the low-pass against its closed
forms, the policies in the engine, and no false alarm from real gyro noise at rest."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from io_helpers import batch, engine_for, scene_with, split

from mount_twin.commands.common import share_dir
from mount_twin.engine.gyro_filter import GyroConditioner, lowpass_rows, section_time_constant
from mount_twin.scene.loader import load_scene_file

RESTING = (
    Path(__file__).resolve().parents[2] / "shared/data/real/water_entry_rest_to_impact_20khz.csv"
)


def test_step_response_is_the_critically_damped_closed_form_at_any_stamp_spacing() -> None:
    """Two equal first-order sections from rest under a unit step held from t = 0:
    y(t) = 1 − e^(−t/τ)(1 + t/τ), whatever the (irregular) stamps in between."""
    tau = section_time_constant(50.0)
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(1e-5, 1e-3, 400))
    w = np.ones((t.shape[0], 3))
    state = np.zeros((2, 3))
    lowpass_rows(t, w, state, 0.0, tau)
    exact = 1.0 - np.exp(-t / tau) * (1.0 + t / tau)
    np.testing.assert_allclose(w[:, 0], exact, rtol=0, atol=1e-14)


@pytest.mark.parametrize("cutoff_hz", [20.0, 50.0, 200.0])
def test_gain_at_the_cutoff_is_minus_3_db(cutoff_hz: float) -> None:
    """|H(f)| = 1/(1 + (2πfτ)²) for two sections; 1/√2 at the cutoff (sampled at 20 kHz)."""
    fs = 20_000.0
    t = np.arange(1, int(2.0 * fs)) / fs
    x = np.sin(2.0 * math.pi * cutoff_hz * t)
    w = np.repeat(x[:, None], 3, axis=1)
    lowpass_rows(t, w, np.zeros((2, 3)), 0.0, section_time_constant(cutoff_hz))
    settled = w[t > 1.0, 0]
    assert settled.max() == pytest.approx(1.0 / math.sqrt(2.0), rel=2e-3)


def test_slope_noise_of_the_filtered_rate_falls_by_orders_of_magnitude() -> None:
    """White gyro noise σ at 20 kHz: the slope Ω′ between samples has RMS √2·σ·fs unfiltered;
    filtered at 50 Hz it is bounded by the cutoff, not the sampling rate."""
    fs, sigma = 20_000.0, 0.004
    rng = np.random.default_rng(2)
    t = np.arange(1, 40_001) / fs
    raw = sigma * rng.standard_normal((t.shape[0], 3))
    slope_raw = np.diff(raw[:, 0]) * fs
    assert slope_raw.std() == pytest.approx(math.sqrt(2.0) * sigma * fs, rel=0.02)
    w = raw.copy()
    GyroConditioner("lowpass", 50.0).rows(t, w, 0.0)
    assert (np.diff(w[20_000:, 0]) * fs).std() < slope_raw.std() / 100.0


def _noisy_rest(n: int, rate_hz: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = 1.0 + np.arange(n) / rate_hz
    return t, 0.004 * rng.standard_normal((n, 3))


@pytest.mark.parametrize("policy", ["lowpass", "none", "ignore"])
def test_any_batching_gives_the_same_numbers(policy: str) -> None:
    t, gyro = _noisy_rest(600, 1000.0, 3)
    scene = scene_with(input={"gyro_filter": policy})
    whole = engine_for(scene).push(batch(t, gyro=gyro))
    engine = engine_for(scene)
    parts = [engine.push(b) for b in split(batch(t, gyro=gyro), [1, 7, 250, 3, 100])]
    np.testing.assert_array_equal(np.concatenate([p.pose for p in parts]), whole.pose)
    np.testing.assert_array_equal(np.concatenate([p.wrenches for p in parts]), whole.wrenches)


def test_ignore_equals_a_zero_gyro_and_none_differs() -> None:
    t, gyro = _noisy_rest(300, 1000.0, 4)
    zero = engine_for(scene_with(input={"gyro_filter": "none"})).push(batch(t))
    ignored = engine_for(scene_with(input={"gyro_filter": "ignore"})).push(batch(t, gyro=gyro))
    raw = engine_for(scene_with(input={"gyro_filter": "none"})).push(batch(t, gyro=gyro))
    np.testing.assert_array_equal(ignored.pose, zero.pose)
    assert np.abs(raw.pose - zero.pose).max() > 0.0


@pytest.mark.skipif(not RESTING.exists(), reason="../shared/data/real is absent")
def test_real_gyro_noise_at_rest_raises_no_false_alarm_by_default() -> None:
    """The bolted genset under 0.28 s of a real 20 kHz record at rest (gravity on +x of the
    sensor, ~0.004 rad/s gyro noise): unfiltered, the slope noise makes its joints slip (>100
    events); with the default filter, none."""
    data = np.loadtxt(RESTING, delimiter=",", skiprows=1, max_rows=5600)
    genset = load_scene_file(share_dir() / "config" / "genset_bolted_keyed.scene.yaml")
    counts = {}
    for policy in ("none", genset.input.gyro_filter):
        scene = scene_with(
            genset,
            input={"frame_id": "", "sensor_rpy": (0.0, -math.pi / 2, 0.0), "gyro_filter": policy},
        )
        engine = engine_for(scene)
        engine.push(batch(data[:, 0] + 1.0, data[:, 1:4], data[:, 4:7], ""))
        counts[policy] = len(engine.events)
    assert genset.input.gyro_filter == "lowpass"
    assert counts["lowpass"] == 0
    assert counts["none"] > 100
