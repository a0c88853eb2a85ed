"""Start checks on the specific force the twin starts under (|f₀| against g, its angle from +z
of F, rest over the start samples) and the start gravity as the mean of N samples."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from io_helpers import DATA_DIR, REST, batch, engine_for, scene_with, split

from mount_twin.engine.batch import ERROR, OK, WARN, HealthStatus, SampleBatch
from mount_twin.model.assemble import assemble, initial_state
from mount_twin.scene.description import InitialState

G = 9.80665


def _input_status(accel: np.ndarray, **sections: dict) -> HealthStatus:
    """The input status of the one report of a short run from rest readings `accel` (n, 3)."""
    n = accel.shape[0]
    engine = engine_for(scene_with(**sections) if sections else None)
    (report,) = engine.run(batch(1.0 + np.arange(n) * 1e-3, accel)).health
    (status,) = [s for s in report.statuses if s.name == "mount_twin: input"]
    return status


def _steady(f0: np.ndarray, n: int = 20) -> np.ndarray:
    return np.tile(f0, (n, 1))


def _said_tilt(message: str) -> tuple[float, float]:
    """The start tilt a message gives, rad and the degrees beside: "0.5 rad (28.65 deg)"."""
    said = re.search(r"is (\S+) rad \((\S+) deg\) from \+z of F", message)
    assert said, message
    return float(said[1]), float(said[2])


def test_a_start_at_rest_passes_and_reports_its_figures() -> None:
    status = _input_status(_steady(REST))
    assert (status.level, status.message) == (OK, "ok")
    assert float(status.values["start_specific_force_m_s2"]) == pytest.approx(G)
    assert float(status.values["start_tilt_rad"]) == 0.0


def test_a_sensor_frame_turned_90_degrees_is_an_error_naming_sensor_rpy() -> None:
    status = _input_status(_steady(np.array([G, 0.0, 0.0])))
    assert status.level == ERROR
    assert "1.571 rad (90 deg) from +z of F (is input.sensor_rpy right?)" in status.message
    assert float(status.values["start_tilt_rad"]) == pytest.approx(math.pi / 2, rel=1e-5)


def test_a_moderate_tilt_is_a_warning() -> None:
    tilt = 0.5  # rad: past the 0.35 rad tolerance, within three times it
    status = _input_status(_steady(G * np.array([0.0, math.sin(tilt), math.cos(tilt)])))
    assert status.level == WARN
    assert _said_tilt(status.message) == pytest.approx((tilt, math.degrees(tilt)), rel=1e-3)


def test_a_start_on_a_shock_pulse_is_an_error() -> None:
    """The first sample 7.3 g (a record that starts on a shock's rise)."""
    accel = _steady(REST)
    accel[0] = [0.0, 0.0, 7.3 * G]
    status = _input_status(accel, initial={"gravity_window_s": 0.0})
    assert status.level == ERROR
    assert "|f0| = 71.59 m/s² is 7.3 g (a start on a shock or spike" in status.message


def test_free_fall_read_through_a_bias_is_a_warning_and_a_tilted_bias_an_error() -> None:
    """A record that starts in free fall (true specific force 0) read through a bias: 7.7 m/s²
    on z is 0.785 g (21 % short of g: WARN); the water-entry record's bias (6.0, −4.6, 1.7) m/s²
    is 0.790 g and 1.35 rad (77.3 deg) from +z (ERROR)."""
    status = _input_status(_steady(np.array([0.0, 0.0, 7.7])))
    assert status.level == WARN
    assert "|f0| = 7.7 m/s² is 0.785 g" in status.message
    status = _input_status(_steady(np.array([6.0, -4.6, 1.7])))
    assert status.level == ERROR
    assert "is 0.79 g" in status.message
    tilt = math.atan2(math.hypot(6.0, -4.6), 1.7)
    assert _said_tilt(status.message) == pytest.approx((tilt, math.degrees(tilt)), rel=1e-3)
    assert math.degrees(tilt) == pytest.approx(77.3, abs=0.05)


def test_gravity_added_twice_is_named() -> None:
    """An Imu record (gravity included) declared includes_gravity: false gets g added again."""
    status = _input_status(_steady(REST), input={"includes_gravity": False})
    assert status.level == ERROR
    assert "input.includes_gravity is false, so g was added" in status.message


def test_a_scene_without_gravity_checks_the_start_in_standard_gravity() -> None:
    """input.g: 0 (a test rig): no specific force at the start passes with no tilt to check;
    an input reading 1 g up (a sensor at rest on Earth) is an ERROR naming input.g, and a
    start 0.2 g off zero a WARN."""
    status = _input_status(_steady(np.zeros(3)), input={"g": 0.0})
    assert (status.level, status.message) == (OK, "ok")
    assert float(status.values["start_tilt_rad"]) == 0.0
    status = _input_status(_steady(REST), input={"g": 0.0})
    assert status.level == ERROR
    assert "is 1 g (standard) (the scene has no gravity (input.g: 0)" in status.message
    status = _input_status(_steady(np.array([0.2 * G, 0.0, 0.0])), input={"g": 0.0})
    assert status.level == WARN
    assert "is 0.2 g (standard) (a start on a shock or spike" in status.message


def test_the_start_gravity_is_the_mean_of_the_first_n_samples() -> None:
    """With gravity_samples N, nothing is published before the N-th sample, the twin starts
    there at the static equilibrium under the mean of the N readings."""
    rng = np.random.default_rng(5)
    n_start = 50
    accel = REST + rng.normal(0.0, 0.05, (200, 3))
    scene = scene_with(initial={"gravity_samples": n_start})
    engine = engine_for(scene)
    out = engine.run(batch(1.0 + np.arange(200) * 1e-3, accel))
    assert out.sample[0] == n_start - 1
    assert out.stamps[0] == pytest.approx(1.0 + (n_start - 1) * 1e-3)
    expected = initial_state(assemble(scene), accel[:n_start].mean(axis=0))
    reference = engine_for(scene_with(initial={"gravity_samples": 1}))
    reference.run(batch([1.0], accel[:n_start].mean(axis=0)[None, :]))
    np.testing.assert_allclose(reference.state, expected, rtol=0, atol=1e-15)
    assert engine.counts["accepted"] == 200


def test_a_pulse_among_the_start_samples_is_flagged_not_at_rest() -> None:
    accel = _steady(REST, 40)
    accel[10] = [0.0, 0.0, 3.0 * G]
    status = _input_status(accel, initial={"gravity_samples": 30, "gravity_window_s": 0.0})
    assert status.level == WARN
    assert "not at rest over the 30 start samples" in status.message


def test_a_gap_reset_while_gathering_starts_the_gathering_again() -> None:
    scene = scene_with(initial={"gravity_samples": 5})
    engine = engine_for(scene)
    stamps = np.concatenate([1.0 + np.arange(3) * 1e-3, 3.0 + np.arange(6) * 1e-3])
    out = engine.run(batch(stamps))
    assert out.stamps[0] == pytest.approx(3.0 + 4e-3)  # 5th sample after the gap


def test_a_start_without_equilibrium_under_the_input_is_not_called_a_stepper_failure() -> None:
    """A start under a specific force with no equilibrium (restart.start_state's fallback to
    nominal gravity) read "stepper failed and the twin restarted" beside "integration
    failures: 0, restarts: 0". It is an ERROR of its own wording; a failure beside it keeps
    its own."""
    from collections import Counter

    from mount_twin.engine.health import HealthWindow

    scene = scene_with()
    window = HealthWindow(scene, "auto")
    window.forced_start(0.5, "no static equilibrium under the start specific force 400 m/s²")
    report = window.report(1.0, 0, Counter(), np.full(len(scene.mounts), np.nan), {})
    (status,) = [s for s in report.statuses if s.name == "mount_twin: integration"]
    assert status.level == ERROR
    assert status.message == (
        "started away from equilibrium: 0.500000 s: no static equilibrium under the start "
        "specific force 400 m/s²"
    )
    window.failure(0.7, "step size too small")
    window.forced_start(0.8, "why")
    report = window.report(1.0, 0, Counter(), np.full(len(scene.mounts), np.nan), {})
    (status,) = [s for s in report.statuses if s.name == "mount_twin: integration"]
    assert status.message == (
        "stepper failed and the twin restarted: 0.700000 s: step size too small; "
        "started away from equilibrium: 0.800000 s: why"
    )


def _resting_record() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The real 20 kHz record at rest (test/data/water_entry_rest_20khz_excerpt.md: 0-0.28 s
    before release, gravity on +x of the sensor, ~0.5 m/s² of noise per axis and sample):
    stamps s (from 1 s), specific force m/s² and rate rad/s, sensor axes."""
    data = np.loadtxt(DATA_DIR / "water_entry_rest_20khz_excerpt.csv", delimiter=",", skiprows=1)
    return data[:, 0] + 1.0, data[:, 1:4], data[:, 4:7]


def _levelled(v: np.ndarray) -> tuple[float, float, float]:
    """sensor_rpy (fixed-axis roll, pitch, yaw; rad) turning v onto +z of F: the roll about x
    takes its y out (z' = hypot(vy, vz)), the pitch about y then its x."""
    return math.atan2(v[1], v[2]), math.atan2(-v[0], math.hypot(v[1], v[2])), 0.0


def test_a_noisy_real_record_starts_within_a_few_mrad_of_its_quiet_mean() -> None:
    """The start attitude on the real 20 kHz record at rest. Truth: its mean over the whole
    0.28 s at rest, turned onto +z of F by sensor_rpy, so the start tilt the input status
    gives is the start gravity's angle from the truth. One sample (the default before) was
    0.024 rad off here (0.067 rad rms over the record's start positions,
    bench/start_gravity.py: the body started leaning by that, every mount taking 2.4 % of
    the weight sideways); the default 50 ms window takes the mean of 1001 samples."""
    stamps, accel, gyro = _resting_record()
    truth = accel.mean(axis=0)
    scene = scene_with(input={"sensor_rpy": _levelled(truth), "frame_id": ""})
    engine = engine_for(scene)
    out = engine.run(SampleBatch(stamps, accel, gyro, [""] * stamps.shape[0]))
    assert out.stamps[0] == stamps[0] and len(out.stamps) == stamps.shape[0]  # all answered
    (report,) = out.health
    (status,) = [s for s in report.statuses if s.name == "mount_twin: input"]
    assert (status.level, status.message) == (OK, "ok")
    one_sample = math.atan2(np.linalg.norm(np.cross(accel[0], truth)), accel[0] @ truth)
    assert one_sample > 0.02
    window = accel[stamps <= stamps[0] + 0.05 + 1e-9].mean(axis=0)
    expected = math.atan2(np.linalg.norm(np.cross(window, truth)), window @ truth)
    assert float(status.values["start_tilt_rad"]) == pytest.approx(expected, abs=1e-5)
    assert expected < 0.005


def test_a_real_sensors_noise_over_the_start_samples_is_not_called_motion() -> None:
    """2000 start samples (0.1 s) of the real record at rest, every one within 0.25 g of
    their mean: the check read each sample's distance from the mean, past 0.1 g a WARN "not
    at rest" on a sensor at rest (on 100 % of its 5 ms or longer windows). Their parts' means
    (eighths) lie within 0.03 g of it: at rest, OK."""
    stamps, accel, gyro = _resting_record()
    spread = np.linalg.norm(accel[:2000] - accel[:2000].mean(axis=0), axis=1).max()
    assert 0.1 * G < spread < 0.3 * G
    engine = engine_for(scene_with(input={"sensor_rpy": (0.0, -math.pi / 2, 0.0)}))
    (report,) = engine.run(batch(stamps, accel, gyro)).health
    (status,) = [s for s in report.statuses if s.name == "mount_twin: input"]
    assert (status.level, status.message) == (OK, "ok")
    scene = scene_with(
        input={"sensor_rpy": (0.0, -math.pi / 2, 0.0)}, initial={"gravity_samples": 2000}
    )
    (report,) = engine_for(scene).run(batch(stamps, accel, gyro)).health
    (status,) = [s for s in report.statuses if s.name == "mount_twin: input"]
    assert (status.level, status.message) == (OK, "ok")


def test_the_start_does_not_average_across_a_shock() -> None:
    """At rest for 10 ms, then a 400 m/s² half-sine of 20 ms (10 kHz): the start gravity is
    the rest's, exactly g up, whether the start window or gravity_samples reach into the
    shock (200 samples: their mean was 2.5 g, an ERROR and the twin started leaning into the
    shock). Fewer samples than gravity_samples asked for is a WARN that says so: the 200 and
    the window after the 200th reach the record's end, 600 samples, whose first eighth (75,
    7.5 ms) is at rest and whose second holds the shock's rise."""
    t = 1.0 + np.arange(600) / 10_000.0
    up = G + np.where(t >= 1.01, 400.0 * np.sin(np.pi * np.clip(t - 1.01, 0.0, 0.02) / 0.02), 0.0)
    accel = np.column_stack([np.zeros(600), np.zeros(600), up])
    for initial, level in (({}, OK), ({"gravity_samples": 200}, WARN)):
        (report,) = engine_for(scene_with(initial=initial)).run(batch(t, accel)).health
        (status,) = [s for s in report.statuses if s.name == "mount_twin: input"]
        assert float(status.values["start_specific_force_m_s2"]) == pytest.approx(G, rel=1e-12)
        assert status.level == level, status.message
    assert "not at rest over the 600 start samples: the start took the first 75" in (
        status.message
    )


def test_a_scene_of_its_own_gravity_checks_the_start_against_it() -> None:
    """input.g 3.71 m/s² (Mars): a start at 3.71 m/s² passes; one at 1 g is 2.64 of the
    scene's g, an ERROR that names the likely cause, an Earth-bound sensor, not a shock."""
    mars = 3.71
    status = _input_status(_steady(np.array([0.0, 0.0, mars])), input={"g": mars})
    assert (status.level, status.message) == (OK, "ok")
    status = _input_status(_steady(REST), input={"g": mars})
    assert status.level == ERROR
    assert (
        f"|f0| = 9.807 m/s² is {G / mars:.3g} g (the scene's gravity is input.g: 3.71 m/s²: "
        "is the input a sensor on Earth?)" in status.message
    )


def test_the_start_hint_names_a_key_the_scene_reads() -> None:
    """It named `initial.gravity_samples`: no such key (the section is initial_state)."""
    accel = _steady(REST)
    accel[:] = [0.0, 0.0, 5.0 * G]
    status = _input_status(accel)
    said = re.search(r"(\w+)\.(\w+) averages the start", status.message)
    assert said, status.message
    assert said[1] == "initial_state"
    assert said[2] in {f.name for f in dataclasses.fields(InitialState)}


@pytest.mark.parametrize("sizes", [[1] * 3000, [7, 300, 1, 1, 2000], [5600]])
@pytest.mark.parametrize("gyro_filter", ["none", "linear_phase"])
def test_the_start_window_is_the_same_in_any_batching(sizes: list[int], gyro_filter: str) -> None:
    """The real record at rest with a gap (a reset: a second start) at 0.1 s, and pushed in
    pieces: every accepted sample answered once at its own stamp, the same numbers whatever
    the pieces (the delay line holds a start's run until its window has come); without the
    gyro filter's delay the window alone holds it back, released at the end."""
    stamps, accel, gyro = _resting_record()
    stamps = stamps + np.where(stamps >= 1.1, 1.0, 0.0)  # a 1 s gap: max_gap_s 0.5 resets
    scene = scene_with(input={"sensor_rpy": (0.0, -math.pi / 2, 0.0), "gyro_filter": gyro_filter})
    whole = engine_for(scene).run(batch(stamps, accel, gyro))
    engine = engine_for(scene)
    parts = [engine.push(part) for part in split(batch(stamps, accel, gyro), sizes)]
    parts.append(engine.flush())
    assert engine.counts["starts"] == 2
    stamps_out = np.concatenate([p.stamps for p in parts])
    np.testing.assert_array_equal(stamps_out, stamps)
    np.testing.assert_array_equal(np.concatenate([p.pose for p in parts]), whole.pose)
    np.testing.assert_array_equal(np.concatenate([p.wrenches for p in parts]), whole.wrenches)


def test_a_start_waits_for_the_longer_of_its_window_and_the_filters_delay_not_both() -> None:
    """1 kHz at rest, the gyro filter's delay N samples, the window 50 ms, one pushed at a
    time: the start needs its window's samples (stamps up to 50 ms after the start sample),
    and those the filter still holds go with it, so the first output comes with the first
    sample past the window, or with sample N + 1 (the start sample and one more released),
    whichever comes later. The window's samples were taken from the released ones alone: the
    first output waited for the window's end plus the filter's delay (88 ms, not 50)."""
    from mount_twin.engine.delay_line import delay_samples

    n = 200
    stamps = 1.0 + np.arange(n) * 1e-3
    scene = scene_with(input={"gyro_filter": "linear_phase"})
    delay = delay_samples(scene.input, 1000.0)
    assert 0 < delay < 50  # the case this test is about: the filter's delay below the window
    engine = engine_for(scene)
    first = next(
        k
        for k, part in enumerate(
            engine.push(b) for b in split(batch(stamps, _steady(REST, n)), [1] * n)
        )
        if part.stamps.shape[0]
    )
    past_window = int(np.argmax(stamps > stamps[0] + 0.05 + 1e-9))
    assert first == max(past_window, delay + 1)
