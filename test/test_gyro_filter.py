"""How Ω and Ω′ come from a sampled gyro (`input.gyro_filter`).

The default, `linear_phase`, low-passes Ω with a symmetric FIR and delays f by the same N
samples, so the twin integrates one consistent deck motion N samples late. Checked against
independent truth: the filter's gain measured by filtering sines (against its design band), the
rotating decks against the raw-gyro twin (`none`, exact on clean input: its agreement with an
independent formulation is test_physics_rotating_foundation.py's), gyro noise at rest against
"no mount event", and every accepted sample answered once, at its own stamp, in any batching.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml
from io_helpers import DATA_DIR, batch, engine_for, scene_with, split

from mount_twin.analysis.deck_motion import SHIP, DeckMotion, deck_samples, rolling
from mount_twin.commands.common import share_dir
from mount_twin.engine.batch import OutputBatch, SampleBatch
from mount_twin.engine.delay_line import LARGE, conditioned_rates
from mount_twin.engine.gyro_filter import FLATNESS, design, fir_rows, kaiser_window
from mount_twin.errors import SceneError
from mount_twin.scene.description import Scene
from mount_twin.scene.loader import load_scene_file, scene_from_dict

RESTING = DATA_DIR / "water_entry_rest_20khz_excerpt.csv"
PASSBAND_HZ, STOPBAND_HZ = 20.0, 100.0


def _gain(rate_hz: float, frequency_hz: float) -> float:
    """|H| measured: a unit sine filtered by the designed taps (`fir_rows`), its amplitude
    after the filter's start, by least squares on sin and cos."""
    half = design(rate_hz, PASSBAND_HZ, STOPBAND_HZ).half
    n = half.shape[0] - 1
    k = np.arange(2 * n + 4000)
    x = np.sin(2.0 * math.pi * frequency_hz * k / rate_hz)
    raw = np.repeat(x[None, :], 3, axis=0)
    out = np.empty((3, k.shape[0] - 2 * n))
    fir_rows(raw, half, out)
    centre = k[n : n + out.shape[1]]  # output k answers raw sample k + N: no phase left
    phase = 2.0 * math.pi * frequency_hz * centre / rate_hz
    basis = np.column_stack([np.sin(phase), np.cos(phase)])
    (a, b), *_ = np.linalg.lstsq(basis, out[0], rcond=None)
    assert abs(b) <= 1e-9, "a symmetric FIR delays by exactly N samples"
    return float(a)


@pytest.mark.parametrize("rate_hz", [1000.0, 10_000.0])
def test_gain_is_flat_in_the_passband_and_stops_in_the_stopband(rate_hz: float) -> None:
    for f in (0.5, 5.0, 12.0, PASSBAND_HZ):
        assert abs(_gain(rate_hz, f) - 1.0) <= 2.0 * FLATNESS, f"{f} Hz"
    for f in (STOPBAND_HZ, 170.0, 0.37 * rate_hz):
        assert abs(_gain(rate_hz, f)) <= 2.0 * FLATNESS, f"{f} Hz"
    half = design(rate_hz, PASSBAND_HZ, STOPBAND_HZ).half
    assert half[0] + 2.0 * half[1:].sum() == pytest.approx(1.0, abs=1e-14), "DC passes exactly"


def test_each_design_has_taps_of_its_own() -> None:
    """The taps are designed once a process per (rate, bands): a caller writing into its
    design's taps changes no later design, and each can be filtered with (`fir_rows` takes
    writable arrays only)."""
    first = design(4000.0, PASSBAND_HZ, STOPBAND_HZ).half
    first[:] = 0.0
    later = design(4000.0, PASSBAND_HZ, STOPBAND_HZ).half
    assert later[0] + 2.0 * later[1:].sum() == pytest.approx(1.0, abs=1e-14), "DC passes"
    fir_rows(np.ones((3, 2 * later.shape[0] - 1)), later, np.empty((3, 1)))


@pytest.mark.parametrize("outputs", [1, 7, 8, 9, 15, 16, 17, 23, 24, 31, 33, 250])
def test_the_filter_sums_in_its_documented_order_at_any_lane_width(outputs: int) -> None:
    """`fir_rows` bit for bit against NumPy's elementwise sums in the order it documents
    (h[N]·r[k], then + h[N + j]·(r[k − j] + r[k + j]) for j = 1..N): the same bits whether
    an output falls in a block of AVX2's lanes, of SSE2's pairs or alone, so neither the
    batching nor the processor changes a filtered rate."""
    half = design(2000.0, PASSBAND_HZ, STOPBAND_HZ).half
    n = half.shape[0] - 1
    raw = np.random.default_rng(outputs).standard_normal((3, outputs + 2 * n))
    expected = half[0] * raw[:, n : n + outputs]
    for j in range(1, n + 1):
        expected = expected + half[j] * (
            raw[:, n - j : n - j + outputs] + raw[:, n + j : n + j + outputs]
        )
    out = np.empty((3, outputs))
    fir_rows(raw, half, out)
    np.testing.assert_array_equal(out.view(np.int64), expected.view(np.int64))


@pytest.mark.parametrize(("m", "beta"), [(1, 5.0), (2, 5.0), (77, 9.4), (751, 9.4), (41, 0.0)])
def test_the_window_is_numpys_kaiser(m: int, beta: float) -> None:
    """The power-series window against numpy's Chebyshev-series I₀ (its independent code)."""
    np.testing.assert_allclose(kaiser_window(m, beta), np.kaiser(m, beta), rtol=0, atol=1e-14)


def test_latency_is_about_38_ms_at_any_rate_and_raw_below_four_times_the_stopband() -> None:
    for rate in (1000.0, 10_000.0, 20_000.0):
        d = design(rate, PASSBAND_HZ, STOPBAND_HZ)
        assert 0.037 <= d.delay_s <= 0.038 and not d.note
    low = design(300.0, PASSBAND_HZ, STOPBAND_HZ)
    assert low.delay == 0 and "300 Hz is below 4 × input.gyro_stopband_hz" in low.note


def _scene(base: Scene | None = None, **fields: object) -> Scene:
    return scene_with(base, input={"frame_id": "", **fields})


def _pump_off_cg(policy: str) -> Scene:
    return _scene(sensor_position=(0.6, -0.35, -0.25), gyro_filter=policy)


@pytest.mark.parametrize(
    ("motion", "duration_s"),
    [
        (rolling(0.05, 1.0), 6.0),
        (rolling(0.02, 5.0), 4.0),
        (rolling(0.005, 20.0), 3.0),
        (SHIP, 20.0),
    ],
    ids=["roll-1Hz", "roll-5Hz", "roll-20Hz", "ship-6dof"],
)
def test_a_rotating_deck_matches_the_raw_gyro_twin(motion: DeckMotion, duration_s: float) -> None:
    """The pump, its sensor off the CG, on a noise-free deck (at rest at both ends): the
    default twin against the raw-gyro twin at the same stamps, ≤ 1e-3 of the peak mount
    force and ≤ 1e-4 rad of attitude (the old 50 Hz low-pass: 5e-2 … 3.9e-1)."""
    samples = deck_samples(motion, 1000.0, duration_s)
    raw = engine_for(_pump_off_cg("none")).run(samples)
    default = scene_with(input={"frame_id": "", "sensor_position": (0.6, -0.35, -0.25)})
    assert default.input.gyro_filter == "linear_phase"
    got = engine_for(default).run(samples)
    np.testing.assert_array_equal(got.stamps, samples.stamps)
    np.testing.assert_array_equal(raw.stamps, samples.stamps)
    force, force_raw = got.wrenches[:, :, :3], raw.wrenches[:, :, :3]
    assert np.abs(force - force_raw).max() <= 1e-3 * np.abs(force_raw).max()
    assert np.abs(got.angles - raw.angles).max() <= 1e-4
    # the deck's rotation matters: neglecting it is far off
    ignored = engine_for(_pump_off_cg("ignore")).run(samples)
    assert np.abs(ignored.wrenches[:, :, :3] - force_raw).max() > 3e-2 * np.abs(force_raw).max()


def _genset(**fields: object) -> Scene:
    return _scene(
        load_scene_file(share_dir() / "config" / "genset_bolted_keyed.scene.yaml"), **fields
    )


def test_real_gyro_noise_at_rest_raises_no_mount_event_by_default() -> None:
    """The bolted genset under 0.28 s of a real 20 kHz record at rest (gravity on +x of the
    sensor, ~0.004 rad/s of gyro noise): raw, the slope noise makes its joints slip (> 100
    events); by default none."""
    data = np.loadtxt(RESTING, delimiter=",", skiprows=1)
    samples = SampleBatch(data[:, 0] + 1.0, data[:, 1:4], data[:, 4:7], [""] * data.shape[0])
    turned = (0.0, -math.pi / 2, 0.0)
    default = engine_for(_genset(sensor_rpy=turned))
    default.run(samples)
    assert default.counts["mount_events"] == 0
    raw = engine_for(_genset(sensor_rpy=turned, gyro_filter="none"))
    raw.run(samples)
    assert raw.counts["mount_events"] > 100


def test_white_gyro_noise_at_20_khz_raises_no_mount_event_by_default() -> None:
    rng = np.random.default_rng(7)
    n = 6000
    t = 1.0 + np.arange(n) / 20_000.0
    samples = batch(t, gyro=0.02 * rng.standard_normal((n, 3)), frame_ids="")
    default = engine_for(_genset())
    out = default.run(samples)
    assert default.counts["mount_events"] == 0 and default.latency == 750
    assert len(out) == n
    raw = engine_for(_genset(gyro_filter="none"))
    raw.run(samples)
    assert raw.counts["mount_events"] > 100


def _concat(outs: list[OutputBatch]) -> OutputBatch:
    return OutputBatch(
        *(np.concatenate([getattr(o, k) for o in outs]) for k in ("stamps", "sample", "pose")),
        np.concatenate([o.wrenches for o in outs]),
    )


@pytest.mark.parametrize("sizes", [[1] * 120, [7] * 60, [1, 250, 3, 33, 100], [10_000]])
def test_every_accepted_sample_is_answered_once_at_its_stamp_in_any_batching(sizes) -> None:
    """A rolling deck with rejected samples among them, pushed in pieces and flushed: one row
    per accepted sample, its stamp, in order, the same bits as pushed whole. The last piece
    after the small ones is larger than the delay line appends where the samples it holds
    wait (`delay_line.LARGE`)."""
    samples = deck_samples(rolling(0.02, 5.0, fade_s=0.2), 1000.0, 6.0)
    assert len(samples) - 400 > LARGE
    samples.accel[[5, 77, 300, 5000]] = np.nan  # rejected
    whole_engine = engine_for(_scene())
    whole = whole_engine.run(samples)
    engine = engine_for(_scene())
    outs, seen = [], 0
    for piece in split(samples, sizes):
        out = engine.push(piece)
        out.sample = out.sample + seen  # positions in the whole record
        outs.append(out)
        seen += len(piece)
    tail = engine.flush()
    tail.sample = tail.sample + seen
    got = _concat([*outs, tail])
    kept = np.isfinite(samples.accel).all(axis=1)
    np.testing.assert_array_equal(got.sample, np.flatnonzero(kept))
    np.testing.assert_array_equal(got.stamps, samples.stamps[kept])
    np.testing.assert_array_equal(got.pose, whole.pose)
    np.testing.assert_array_equal(got.wrenches, whole.wrenches)
    assert engine.counts["accepted"] == len(got) == kept.sum()
    assert len(tail) == engine.latency == 38


def test_each_run_is_filtered_with_its_first_and_last_rates_held_beyond_it() -> None:
    """The delay line's Ω (`conditioned_rates`) against each run convolved (`np.convolve`, the
    full symmetric taps) with its first sample repeated N times before it and its last N
    times after it: a long run, a run shorter than N and one after it, restarted between."""
    rate_hz, n = 1000.0, 700
    t = np.arange(n) / rate_hz
    w = np.column_stack([0.1 + 0.05 * np.sin(2 * math.pi * f * t) for f in (3.0, 7.0, 11.0)])
    w += 1e-3 * np.random.default_rng(7).standard_normal(w.shape)
    restarts = [250, 280]
    got = conditioned_rates((PASSBAND_HZ, STOPBAND_HZ), t, w, restarts)
    half = design(rate_hz, PASSBAND_HZ, STOPBAND_HZ).half
    taps, delay = np.concatenate([half[:0:-1], half]), half.shape[0] - 1
    assert 280 - 250 < delay == 38
    for run in np.split(np.arange(n), restarts):
        x = w[run]
        held = np.concatenate([np.repeat(x[:1], delay, 0), x, np.repeat(x[-1:], delay, 0)])
        want = np.column_stack([np.convolve(held[:, i], taps, "valid") for i in range(3)])
        np.testing.assert_allclose(got[run], want, rtol=0.0, atol=1e-14)


def test_a_gap_reset_releases_the_delayed_samples_before_restarting() -> None:
    """A gap (> max_gap_s) restarts the twin: the samples before it are answered as at the
    end of a stream (the same bits as a record ending there), none lost."""
    first = deck_samples(rolling(0.02, 5.0, fade_s=0.2), 1000.0, 0.5)
    second = deck_samples(rolling(0.01, 3.0, fade_s=0.2), 1000.0, 0.5, start_s=3.0)
    both = SampleBatch.concat([first, second])
    engine = engine_for(_scene())
    out = engine.run(both)
    assert engine.counts["gaps"] == 1
    np.testing.assert_array_equal(out.stamps, both.stamps)
    alone = engine_for(_scene()).run(first)
    np.testing.assert_array_equal(out.pose[: len(first)], alone.pose)
    np.testing.assert_array_equal(out.wrenches[: len(first)], alone.wrenches)


def test_below_four_times_the_stopband_the_gyro_is_raw_and_diagnostics_say_so() -> None:
    samples = deck_samples(rolling(0.02, 1.0, fade_s=0.5), 300.0, 2.0)
    engine = engine_for(_scene())
    out = engine.run(samples)
    raw = engine_for(_scene(gyro_filter="none")).run(samples)
    np.testing.assert_array_equal(out.pose, raw.pose)
    assert engine.latency == 0
    integration = [s for r in out.health for s in r.statuses if s.name.endswith("integration")]
    assert "below 4 × input.gyro_stopband_hz" in integration[0].message
    assert integration[0].level == 1
    assert integration[-1].values["latency_samples"] == "0"


def test_diagnostics_give_the_latency() -> None:
    out = engine_for(_scene()).run(batch(1.0 + np.arange(3000) / 1000.0, frame_ids=""))
    values = [s.values for r in out.health for s in r.statuses if s.name.endswith("integration")]
    assert values[-1]["latency_samples"] == "38"
    assert float(values[-1]["latency_s"]) == pytest.approx(0.038)


def test_one_odd_first_interval_does_not_set_the_design() -> None:
    """A stamp one rounding step after the first (2e-16 s later, as sums of intervals give)
    set a 4.5e15 Hz design that asked for petabytes (a fuzz campaign found it): the design
    takes the median of the first intervals, 1 kHz here."""
    stamps = 1.0 + np.arange(500) / 1000.0
    stamps = np.concatenate([[1.006, np.nextafter(1.006, 2.0)], stamps[7:]])
    assert 0.0 < stamps[1] - stamps[0] < 1e-15
    engine = engine_for(_scene())
    out = engine.run(batch(stamps, frame_ids=""))
    assert engine.latency == 38
    assert len(out) == engine.counts["accepted"] == len(stamps)


def test_a_stream_faster_than_any_sensor_takes_the_gyro_raw_and_says_so() -> None:
    out = engine_for(_scene()).run(batch(1.0 + np.arange(50) * 1e-9, frame_ids=""))
    integration = [s for r in out.health for s in r.statuses if s.name.endswith("integration")]
    assert "above 1e+06 Hz: the gyro is taken raw" in integration[0].message
    assert integration[-1].values["latency_samples"] == "0"


def test_ignore_equals_a_zero_gyro_and_none_differs() -> None:
    t = 1.0 + np.arange(300) / 1000.0
    gyro = 0.004 * np.random.default_rng(4).standard_normal((300, 3))
    zero = engine_for(scene_with(input={"gyro_filter": "none"})).push(batch(t))
    ignored = engine_for(scene_with(input={"gyro_filter": "ignore"})).push(batch(t, gyro=gyro))
    raw = engine_for(scene_with(input={"gyro_filter": "none"})).push(batch(t, gyro=gyro))
    np.testing.assert_array_equal(ignored.pose, zero.pose)
    assert np.abs(raw.pose - zero.pose).max() > 0.0


@pytest.mark.parametrize(
    ("fields", "key", "text"),
    [
        ({"gyro_filter": "lowpass"}, "input.gyro_filter", "'lowpass' was removed"),
        ({"gyro_cutoff_hz": 50.0}, "input.gyro_cutoff_hz", "'linear_phase'"),
        ({"gyro_stopband_hz": 20.0}, "input.gyro_stopband_hz", "not above gyro_passband_hz"),
        ({"gyro_passband_hz": -1.0}, "input.gyro_passband_hz", ""),
    ],
)
def test_gyro_keys_are_checked_at_load_with_their_key_path(fields, key, text) -> None:
    path = share_dir() / "config" / "pump_8_mounts.scene.yaml"
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    data["input"].update(fields)
    with pytest.raises(SceneError, match=f"{key}: .*{text}"):
        scene_from_dict(data, "<test>")
