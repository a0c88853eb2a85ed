"""`calibrate`: the twin as the model of a recorded pair. Synthetic truth made by the twin with
known changes is recovered; what a record cannot identify is refused by name; on the real
shake-table pair, calibrating on one run improves the prediction of the other."""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest
from io_helpers import DATA_DIR, ROOT
from scipy.interpolate import CubicSpline
from scipy.signal import butter, csd, sosfiltfilt, welch

from mount_twin import load_scene_file
from mount_twin.analysis import calibration as cal_mod
from mount_twin.analysis import calibration_parameters
from mount_twin.analysis.calibration_records import STILL_FOUNDATION, still_record
from mount_twin.cli import main
from mount_twin.commands.calibrate import FITTED, ON_REQUEST
from mount_twin.io.signals import SeaState, Signal, half_sine_shock, ship_motion
from mount_twin.io.xsens_csv import read_xsens_csv
from mount_twin.scene.description import BodySensor

RATE = 200.0
TRUTH = {"stiffness": 0.7, "damping": 1.5, "yaw": math.radians(30.0), "lag": 0.012}
SHAKE = DATA_DIR / "shake_table_1story"


def _pump():
    scene = load_scene_file(ROOT / "config/pump_8_mounts.scene.yaml")
    return dataclasses.replace(
        scene,
        body_sensor=BodySensor(position=(0.8, 0.3, 1.0)),
        input=dataclasses.replace(scene.input, gyro_filter="none"),
    )


def _pair(scene, foundation: Signal, truth: dict[str, float]) -> tuple[Signal, Signal]:
    """The body record the changed machine gives (its recorder `lag` late), and both records
    with 0.01 m/s² of sensor noise (a MEMS IMU's, per sample at this rate)."""
    t, f = cal_mod.predict(calibration_parameters.calibrated_scene(scene, truth), foundation)
    rng = np.random.default_rng(1)
    tb = t[t > 0.05]
    fb = CubicSpline(t, f, axis=0)(tb - truth.get("lag", 0.0))
    body = Signal(tb, fb + rng.normal(0.0, 0.01, fb.shape), np.zeros_like(fb))
    noisy = foundation.accel + rng.normal(0.0, 0.01, foundation.accel.shape)
    return Signal(foundation.t, noisy, foundation.gyro), body


def _vibrating_deck() -> Signal:
    """20 s of ship motion with the machinery's broadband vibration (1-40 Hz, 0.3 m/s² RMS)."""
    sea = ship_motion(rate_hz=RATE, total=20.0)
    sos = butter(4, [1.0, 40.0], btype="band", fs=RATE, output="sos")
    vib = sosfiltfilt(sos, np.random.default_rng(5).normal(0, 1, sea.accel.shape), axis=0)
    return Signal(sea.t, sea.accel + 0.3 * vib / vib.std(axis=0), sea.gyro)


def test_the_parameters_the_command_offers_are_the_fits() -> None:
    assert FITTED == calibration_parameters.PARAMETERS
    assert ON_REQUEST == calibration_parameters.ON_REQUEST


def test_twenty_seconds_of_ship_motion_recover_the_changed_machine() -> None:
    """Ship motion with the machinery's broadband vibration (1-40 Hz, 0.3 m/s² RMS) under a
    pump whose mounts all lost 30 % of their stiffness, with 1.5 times their damping, whose
    body IMU is yawed 30° and recorded 12 ms late: each is recovered within 2 % (the angle
    within 0.5°, the lag within a sample)."""
    cal = cal_mod.calibrate(_pump(), *_pair(_pump(), _vibrating_deck(), TRUTH))
    assert not cal.refused
    assert cal.values["stiffness"] == pytest.approx(0.7, rel=0.02)
    assert cal.values["damping"] == pytest.approx(1.5, rel=0.02)
    assert abs(math.degrees(cal.values["yaw"] - TRUTH["yaw"])) < 0.5
    assert abs(cal.values["lag"] - TRUTH["lag"]) < 1.0 / RATE
    assert cal.nrms_after < 0.1 < cal.nrms_before
    for name, sigma in cal.sigma.items():  # the 1σ says how well, and the truth is within 5σ
        assert abs(cal.values[name] - TRUTH[name]) < 5 * sigma + 1e-3 * abs(TRUTH[name])


def test_one_mount_at_70_percent_is_told_from_the_seven_intact_ones() -> None:
    """The issue's case: one mount of the pump's eight (fl) at 0.7× stiffness, the damping
    1.5×, the IMU yawed 30° and 12 ms late; a stiffness scale per mount. fl is found at 0.7
    and the other seven at 1, each within 2 %; yaw within 0.5°, lag within a sample."""
    truth = {"stiffness:fl": 0.7, "damping": 1.5, "yaw": TRUTH["yaw"], "lag": TRUTH["lag"]}
    mounts = [m.name for m in _pump().mounts]
    fit = (*(f"stiffness:{m}" for m in mounts), "damping", "yaw", "lag")
    cal = cal_mod.calibrate(_pump(), *_pair(_pump(), _vibrating_deck(), truth), fit)
    assert not cal.refused
    for m in mounts:
        want = 0.7 if m == "fl" else 1.0
        assert cal.values[f"stiffness:{m}"] == pytest.approx(want, rel=0.02), m
    assert cal.values["damping"] == pytest.approx(1.5, rel=0.02)
    assert abs(math.degrees(cal.values["yaw"] - truth["yaw"])) < 0.5
    assert abs(cal.values["lag"] - truth["lag"]) < 1.0 / RATE


def _one_shock() -> Signal:
    """One naval-style double half-sine, 5 g for 20 ms then its rebound, shared 0.4 athwartships
    and 0.3 fore-aft, 2.5 s of record at 200 Hz."""
    shock = half_sine_shock(
        peak=50.0, duration=0.02, rate_hz=RATE, pre=0.3, total=2.5, lateral=0.4, rebound=10.0
    )
    accel = shock.accel.copy()
    accel[:, 0] += 0.3 * (accel[:, 2] - accel[-1, 2])
    return Signal(shock.t, accel, shock.gyro)


@pytest.mark.parametrize("per_mount", [False, True], ids=["all_mounts", "mount_by_mount"])
def test_one_shock_recovers_the_changed_machine(per_mount: bool) -> None:
    """The issue's second record: one shock instead of 20 s of ship motion. Every mount (or,
    with a scale per mount, fl alone) at 0.7× stiffness, damping 1.5×, the IMU yawed 30° and
    12 ms late, 0.01 m/s² of noise: each recovered within 2 % (yaw 0.5°, lag a sample)."""
    mounts = [m.name for m in _pump().mounts]
    truth = {**TRUTH, "stiffness:fl": 0.7} if per_mount else TRUTH
    truth = {k: v for k, v in truth.items() if not (per_mount and k == "stiffness")}
    fit = (*(f"stiffness:{m}" for m in mounts), "damping", "yaw", "lag") if per_mount else FITTED
    cal = cal_mod.calibrate(_pump(), *_pair(_pump(), _one_shock(), truth), fit)
    assert not cal.refused
    for name in fit:
        want = truth.get(name, 1.0)
        if name == "yaw":
            assert abs(math.degrees(cal.values[name] - want)) < 0.5
        elif name == "lag":
            assert abs(cal.values[name] - want) < 1.0 / RATE
        else:
            assert cal.values[name] == pytest.approx(want, rel=0.02), name


def test_the_body_imus_whole_mounting_is_found_from_one_shock() -> None:
    """The sensor also rolled 2°, pitched −3° and 5, −4, 3 cm off its nominal position, fitted
    with the rest from one shock: every angle within 0.5°, every offset within 5 mm, the
    scales within 2 %, the lag within a sample."""
    truth = {**TRUTH, "roll": math.radians(2.0), "pitch": math.radians(-3.0)}
    truth |= {"sensor_x": 0.05, "sensor_y": -0.04, "sensor_z": 0.03}
    fit = (*FITTED, "roll", "pitch", "sensor_x", "sensor_y", "sensor_z")
    cal = cal_mod.calibrate(_pump(), *_pair(_pump(), _one_shock(), truth), fit)
    assert not cal.refused
    for name in ("roll", "pitch", "yaw"):
        assert abs(math.degrees(cal.values[name] - truth[name])) < 0.5, name
    for name in ("sensor_x", "sensor_y", "sensor_z"):
        assert abs(cal.values[name] - truth[name]) < 0.005, name
    assert cal.values["stiffness"] == pytest.approx(0.7, rel=0.02)
    assert cal.values["damping"] == pytest.approx(1.5, rel=0.02)
    assert abs(cal.values["lag"] - truth["lag"]) < 1.0 / RATE
    assert cal.scene.body_sensor is not None
    assert cal.scene.body_sensor.position == pytest.approx(
        (0.8 + cal.values["sensor_x"], 0.3 + cal.values["sensor_y"], 1.0 + cal.values["sensor_z"])
    )


def test_the_mass_and_cg_are_found_with_the_mounts_held() -> None:
    """A body 1.2× heavier (mass and inertia) with its CG 3, −2, 5 cm off, from one shock:
    the mass within 2 %, the CG within 5 mm; with stiffness and damping beside it the mass is
    refused before any fit, saying why (the three are one ratio to the body IMU)."""
    truth = {"mass": 1.2, "cg_x": 0.03, "cg_y": -0.02, "cg_z": 0.05, "lag": TRUTH["lag"]}
    fit = ("mass", "cg_x", "cg_y", "cg_z", "lag")
    cal = cal_mod.calibrate(_pump(), *_pair(_pump(), _one_shock(), truth), fit)
    assert not cal.refused
    assert cal.values["mass"] == pytest.approx(1.2, rel=0.02)
    for name in ("cg_x", "cg_y", "cg_z"):
        assert abs(cal.values[name] - truth[name]) < 0.005, name
    assert cal.scene.body.mass == pytest.approx(1.2 * _pump().body.mass, rel=0.02)
    with pytest.raises(ValueError, match="cannot fit mass with stiffness and damping"):
        cal_mod.calibrate(
            _pump(), *_pair(_pump(), _one_shock(), {}), ("stiffness", "damping", "mass")
        )


def test_a_group_naming_a_mount_the_scene_lacks_is_refused() -> None:
    with pytest.raises(ValueError, match=r"stiffness:fl\+nope: nope is no linear mount"):
        cal_mod.calibrate(
            _pump(), Signal(*[np.zeros(3)] * 3), Signal(*[np.zeros(3)] * 3), ("stiffness:fl+nope",)
        )


def test_records_that_do_not_overlap_on_one_clock_are_refused_saying_so() -> None:
    """A body record from another run: scipy had said "`x_scale` must be 'jac' or array_like
    with positive numbers", after numpy's warnings of a mean of nothing."""
    foundation, body = _pair(_pump(), ship_motion(rate_hz=RATE, total=5.0), {})
    later = Signal(body.t + 100.0, body.accel, body.gyro)
    with pytest.raises(ValueError, match=r"has 0 samples within the foundation's .* one clock"):
        cal_mod.calibrate(_pump(), foundation, later, ("stiffness",))


def test_what_the_record_cannot_identify_is_refused_by_name() -> None:
    """Slow roll and heave alone (no vibration near the mounts' modes): the body follows the
    deck, and what moves the mounts' stiffness and damping in the fit is the foundation
    sensor's noise, which the body never felt. The fit predicts the body no better than the
    nominal scene, and nothing of it is kept: every parameter is refused by name, with why,
    and held at its nominal value (it was: the machine is unchanged)."""
    foundation = ship_motion(rate_hz=RATE, total=20.0, sea=SeaState(vib_amp=0.0))
    cal = cal_mod.calibrate(_pump(), *_pair(_pump(), foundation, {}))
    assert {"stiffness", "damping", "lag"} <= set(cal.refused)
    assert all(
        "no better" in why or "barely" in why or "sample" in why for why in cal.refused.values()
    )
    assert cal.values["stiffness"] == 1.0 and cal.values["damping"] == 1.0
    assert cal.values["lag"] == 0.0 and cal.nrms_after <= cal.nrms_before


def test_the_real_shake_table_pair_is_calibrated_on_one_run_and_predicts_the_other(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Calibrated on sine trial 1, the block's acceleration along the shaking direction in
    trial 2 is predicted better than by the notebook's values, broadband and below 10 Hz; the
    lag found is the pair's ~2 samples."""
    scene_path = SHAKE / "block.scene.yaml"
    out = tmp_path / "calibrated.scene.yaml"
    args = ["calibrate", str(scene_path), "-o", str(out), "--plot", str(tmp_path / "c.png")]
    ground, top = (str(SHAKE / f"sine_2hz_trial1_{s}_excerpt.csv") for s in ("ground", "top"))
    assert main([*args, "--foundation", ground, "--body", top]) == 0
    said = capsys.readouterr().out
    lag_ms = float(re.search(r"lag: ([\d.]+) ms", said).group(1))
    assert 1.5 / 120 * 1e3 < lag_ms < 2.5 / 120 * 1e3
    calibrated = load_scene_file(out)
    assert calibrated.mounts[0].stiffness[0] != load_scene_file(scene_path).mounts[0].stiffness[0]
    held_out = tuple(
        read_xsens_csv(SHAKE / f"sine_2hz_trial2_{side}_excerpt.csv").signal
        for side in ("ground", "top")
    )
    nominal = load_scene_file(scene_path)
    for below in (None, 10.0):  # the shaking direction: the sensors' x, broadband and < 10 Hz
        before = cal_mod.prediction_error(nominal, held_out, slice(0, 1), below)
        after = cal_mod.prediction_error(calibrated, held_out, slice(0, 1), below)
        assert after < 0.6 * before, (below, before, after)
    assert (tmp_path / "c.png").stat().st_size > 10_000


def test_the_stiffness_is_found_where_the_record_puts_the_mode_not_near_the_nominal(
    tmp_path: Path,
) -> None:
    """The first 12 s of the sine trial with the recorders' lag known: a fit from the notebook
    stiffness settled at 0.842× ± 0.5 % (NRMS 1.18 → 1.08), a mode at 18.3 Hz; the record's
    own transfer function (Welch, block over table along the shaking axis) peaks at 21.6 Hz
    (± its 0.47 Hz resolution), 1.08× the notebook's 19.96 Hz: 1.17× its stiffness."""
    cut = {}
    for side in ("ground", "top"):
        lines = (SHAKE / f"sine_2hz_trial1_{side}_excerpt.csv").read_text().splitlines()
        cut[side] = tmp_path / f"{side}.csv"
        cut[side].write_text("\n".join(lines[:1449]) + "\n")
    table, block = (read_xsens_csv(cut[side]).signal for side in ("ground", "top"))
    f, pxy = csd(table.accel[:, 0], block.accel[:, 0], fs=120.0, nperseg=256)
    _, pxx = welch(table.accel[:, 0], fs=120.0, nperseg=256)
    band = (f > 10.0) & (f < 40.0)
    peak_hz = float(f[band][np.argmax(np.abs(pxy / pxx)[band])])
    scene = load_scene_file(SHAKE / "block.scene.yaml")
    assert scene.body_sensor is not None
    lagged = dataclasses.replace(
        scene, body_sensor=dataclasses.replace(scene.body_sensor, lag_s=0.01869)
    )
    cal = cal_mod.calibrate(lagged, table, block, ("stiffness",))
    k = sum(m.stiffness[0] for m in cal.scene.mounts)  # N/m along x, the one free DOF
    mode_hz = math.sqrt(k / scene.body.mass) / (2.0 * math.pi)
    assert abs(mode_hz - peak_hz) < 0.03 * peak_hz + 0.47, (mode_hz, peak_hz, cal.values)
    assert cal.nrms_after < 0.8


def test_an_offset_the_motion_cannot_show_is_refused_not_fitted_to_zero_plus_or_minus_zero(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The block moves along x alone: the body IMU's y offset changes nothing it reads. The
    pseudo-inverse gave it 1σ = 0 and the command accepted "sensor_y: 0 mm ± 0"."""
    ground, top = (str(SHAKE / f"sine_2hz_trial1_{s}_excerpt.csv") for s in ("ground", "top"))
    args = ["calibrate", str(SHAKE / "block.scene.yaml"), "-o", str(tmp_path / "c.yaml")]
    assert (
        main([*args, "--foundation", ground, "--body", top, "--fit", "stiffness", "sensor_y"]) == 0
    )
    said = capsys.readouterr().out
    assert re.search(r"sensor_y.*refused.*does not move it at all", said), said


def _rewritten(side: str, out: Path, reading) -> Path:
    """The shake table's trial-1 record of `side` (ground or top) written to `out` with every
    data row's Acc and Gyr cells replaced by `reading()`'s six numbers (m/s², deg/s), the
    stamps kept."""
    lines = (SHAKE / f"sine_2hz_trial1_{side}_excerpt.csv").read_text().splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("PacketCounter,")) + 1
    for i in range(start + 1, len(lines)):  # the export's first data row is all zeros
        cells = lines[i].split(",")
        cells[5:11] = [repr(float(v)) for v in reading()]
        lines[i] = ",".join(cells)
    out.write_text("\n".join(lines) + "\n")
    return out


def _dead_top(tmp_path: Path) -> Path:
    """The shake table's block record (trial 1) as a sensor that died before it began: every
    data row's Acc and Gyr cells a constant 0, 0, 9.81 m/s² and 0 deg/s (the stamps kept)."""
    return _rewritten("top", tmp_path / "top_dead.csv", lambda: (0.0, 0.0, 9.81, 0.0, 0.0, 0.0))


STILL_NOISE = 0.01
"""m/s² per axis and sample: a MEMS IMU's noise; a still record's specific force varies by
√3 times this (RMS about its mean, all axes)."""


def _still_ground(tmp_path: Path) -> Path:
    """The shake table's table record (trial 1) as the table's sensor would read it standing
    still: gravity along its z and STILL_NOISE of white noise on each axis (0.05 deg/s on the
    gyro), the stamps kept: a foundation record that does not move (a still deck, the wrong
    topic, a record taken in harbour)."""
    rng = np.random.default_rng(11)
    return _rewritten(
        "ground",
        tmp_path / "ground_still.csv",
        lambda: (
            *(np.array([0.0, 0.0, 9.81]) + rng.normal(0.0, STILL_NOISE, 3)),
            *rng.normal(0.0, 0.05, 3),
        ),
    )


def _said_still(err: str, record: str) -> float:
    """The RMS (m/s²) a refusal says the `record` (foundation or body) record varies by."""
    found = re.search(
        rf"the {record} record does not move: its specific force varies by (\S+) m/s² RMS", err
    )
    assert found, err
    return float(found.group(1))


@pytest.mark.parametrize("command", ["calibrate", "track"])
def test_a_body_record_that_does_not_move_is_refused_at_load_naming_it(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A dead body IMU (a constant reading) against the moving shake table: calibrate had
    kept yaw and lag "± 0.77°", printed an NRMS of 1e14 and written the scene; track had read
    the window OK with every scale refused; both exited 0. Refused, exit 2, naming the file."""
    dead = _dead_top(tmp_path)
    out = tmp_path / "c.scene.yaml"
    ground = str(SHAKE / "sine_2hz_trial1_ground_excerpt.csv")
    files = ["--foundation", ground, "--body", str(dead)]
    tail = ["-o", str(out)] if command == "calibrate" else ["--window", "10"]
    assert main([command, str(SHAKE / "block.scene.yaml"), *files, *tail]) == 2
    err = capsys.readouterr().err
    assert f"{dead}: the body record does not move" in err, err
    assert not out.exists()


@pytest.mark.parametrize("command", ["calibrate", "track"])
def test_records_that_do_not_overlap_are_refused_at_load_naming_both_files(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The table of trial 1 (device clock 2528.77–2544.77 s) with the block of trial 2
    (2578.07–2594.07 s, 33 s after the first ended): the refusal said "the body record" and
    "the records", naming neither file. It names both, with their spans, exit 2."""
    out = tmp_path / "c.scene.yaml"
    ground = str(SHAKE / "sine_2hz_trial1_ground_excerpt.csv")
    top = str(SHAKE / "sine_2hz_trial2_top_excerpt.csv")
    tail = ["-o", str(out)] if command == "calibrate" else ["--window", "10"]
    args = [command, str(SHAKE / "block.scene.yaml"), "--foundation", ground, "--body", top]
    assert main([*args, *tail]) == 2
    err = capsys.readouterr().err
    assert (
        f"--body {top} (2578.07 to 2594.07 s) has 0 samples within --foundation {ground}'s" in err
    )
    assert "(2528.77 to 2544.77 s, 0.25 s off each end)" in err
    assert not out.exists()


@pytest.mark.parametrize("body", ["moving", "dead"])
@pytest.mark.parametrize("command", ["calibrate", "track"])
def test_a_foundation_record_that_does_not_move_is_refused_at_load_naming_it(
    command: str, body: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The table's sensor standing still (gravity and a MEMS IMU's noise) against the block's
    real record: calibrate printed every parameter refused, an NRMS of 1.000 before and after,
    wrote the scene and exited 0; track judged its one window "not judged" (exit 1; with other
    noise, stiffness ×1.25 ± 0.06, OK, exit 0). Against a dead block record, the body was
    blamed, "1e-12 of the foundation's (0.0174 m/s²)". Refused, exit 2, naming the file, the
    measure (√3 × the noise put in) and the threshold; the foundation is told before the body
    (a body is judged against its foundation's motion, and there is none)."""
    still = _still_ground(tmp_path)
    top = _dead_top(tmp_path) if body == "dead" else SHAKE / "sine_2hz_trial1_top_excerpt.csv"
    out = tmp_path / "c.scene.yaml"
    files = ["--foundation", str(still), "--body", str(top)]
    tail = ["-o", str(out)] if command == "calibrate" else ["--window", "10"]
    assert main([command, str(SHAKE / "block.scene.yaml"), *files, *tail]) == 2
    err = capsys.readouterr().err
    assert f"{still}: the foundation record does not move" in err, err
    assert _said_still(err, "foundation") == pytest.approx(math.sqrt(3.0) * STILL_NOISE, rel=0.1)
    assert f"at most {STILL_FOUNDATION:g} m/s²" in err, err
    assert "the body record" not in err, err
    assert not out.exists()


def test_a_still_bag_record_is_refused_naming_its_bag_and_topic(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The same records as bags (the foundation's on the scene's input topic, the body's on
    its body_sensor.topic): a still foundation's refusal names the bag and the topic it read
    (the wrong topic is one way to read a still deck), and so does a dead body's."""
    scene = str(SHAKE / "block.scene.yaml")
    bags = {}
    for name, csv_path, topic in (
        ("still", _still_ground(tmp_path), "/imu/data"),
        ("ground", SHAKE / "sine_2hz_trial1_ground_excerpt.csv", "/imu/data"),
        ("top", SHAKE / "sine_2hz_trial1_top_excerpt.csv", "/machine/imu"),
        ("dead", _dead_top(tmp_path), "/machine/imu"),
    ):
        bags[name] = tmp_path / f"{name}_bag"
        assert main(["import-csv", str(csv_path), "-o", str(bags[name]), "--topic", topic]) == 0
    capsys.readouterr()
    out = tmp_path / "c.scene.yaml"
    for foundation, body, record, named in (
        ("still", "top", "foundation", f"{bags['still']}: /imu/data"),
        ("ground", "dead", "body", f"{bags['dead']}: /machine/imu"),
    ):
        files = ["--foundation", str(bags[foundation]), "--body", str(bags[body])]
        assert main(["calibrate", scene, *files, "-o", str(out)]) == 2
        err = capsys.readouterr().err
        assert f"{named}: the {record} record does not move" in err, err
        assert not out.exists()


@pytest.mark.parametrize("body", ["moving", "still"])
def test_a_still_foundation_refuses_every_parameter(body: str) -> None:
    """Through the API (a window of track's or of the live tracker's): the pump's deck
    standing still, 0.01 m/s² of noise on gravity, under the body record of the pump on
    ship motion with vibration (another record's: the wrong topic) or a body as still as its
    deck. Both were "fitted": stiffness ×0.29 ± 0.01 and lag 2.6 ± 0.3 ms (the other record's
    truth: 0.7 and 12 ms), and stiffness ×0.028 ± 0.001, yaw 29.6° ± 0.7°. Every parameter is
    refused saying the foundation does not move, and held at its nominal value."""
    rng = np.random.default_rng(3)
    deck = _vibrating_deck()
    standing = np.array([0.0, 0.0, 9.80665]) + rng.normal(0.0, STILL_NOISE, deck.accel.shape)
    still = Signal(deck.t, standing, rng.normal(0.0, 1e-3, deck.gyro.shape))
    if body == "moving":
        _, record = _pair(_pump(), deck, TRUTH)
    else:
        noise = rng.normal(0.0, STILL_NOISE, deck.accel.shape)
        record = Signal(deck.t, np.array([0.0, 0.0, 9.80665]) + noise, np.zeros_like(noise))
    cal = cal_mod.calibrate(_pump(), still, record)
    assert set(cal.refused) == set(FITTED) and not cal.sigma
    assert all("the foundation record does not move" in why for why in cal.refused.values())
    assert cal.values == {"stiffness": 1.0, "damping": 1.0, "yaw": 0.0, "lag": 0.0}


def test_a_foundation_that_moves_a_little_more_than_the_threshold_is_not_still() -> None:
    """The threshold against known motion: a 1 Hz sway of amplitude a along x has an RMS of
    a/√2; at 1.2 times the threshold the foundation moves, at 0.8 times it does not (a body
    following it is never the one refused)."""
    t = np.arange(0.0, 10.0, 1.0 / RATE)
    for factor, still in ((1.2, False), (0.8, True)):
        sway = np.zeros((t.size, 3))
        sway[:, 0] = factor * STILL_FOUNDATION * math.sqrt(2.0) * np.sin(2 * math.pi * t)
        sway[:, 2] = 9.80665
        deck = Signal(t, sway, np.zeros_like(sway))
        said = still_record(deck, deck)
        assert (said is not None) == still, (factor, said)
        assert said is None or said.record == "foundation", said


def test_a_still_body_refuses_every_parameter_and_has_no_nrms() -> None:
    """Through the API (a window of track's, a body sensor that died mid-record): the pump
    on ship motion with vibration, its body record a constant. Nothing is fitted (the dead
    sensor had yaw and lag "fitted"), every parameter is refused saying the body does not
    move, and the normalised error, a ratio to no motion, is nan rather than ~1e14."""
    foundation = _vibrating_deck()
    constant = np.tile([0.0, 0.0, 9.81], (foundation.t.size, 1))
    still = Signal(foundation.t, constant, np.zeros_like(constant))
    cal = cal_mod.calibrate(_pump(), foundation, still)
    assert set(cal.refused) == set(FITTED) and not cal.sigma
    assert all("the body record does not move" in why for why in cal.refused.values())
    assert cal.values == {"stiffness": 1.0, "damping": 1.0, "yaw": 0.0, "lag": 0.0}
    assert math.isnan(cal.nrms_before) and math.isnan(cal.nrms_after)
    assert math.isnan(cal_mod.nrms(np.ones((50, 3)), np.tile([0.0, 0.0, 9.81], (50, 1))))


def test_a_bag_record_with_samples_not_finite_is_refused_naming_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A body bag with 20 NaN readings was taken for a body that does not move ("varies by
    nan m/s²"); a bag on another topic was told of `input.topic` and `replay --topic`, for the
    body's record of `calibrate`."""
    from io_helpers import read_raw

    from mount_twin.io.messages import IMU, TYPESTORE
    from mount_twin.io.output_bag import write_bag

    scene = str(SHAKE / "block.scene.yaml")
    ground, top = tmp_path / "ground", tmp_path / "top"
    for csv_path, bag, topic in (
        ("sine_2hz_trial1_ground_excerpt.csv", ground, "/imu/data"),
        ("sine_2hz_trial1_top_excerpt.csv", top, "/machine/imu"),
    ):
        assert main(["import-csv", str(SHAKE / csv_path), "-o", str(bag), "--topic", topic]) == 0
    ((topic, msgs),) = read_raw(top).items()
    for i in range(600, 620):
        msg = TYPESTORE.deserialize_cdr(msgs[i][1], IMU)
        msg.linear_acceleration.z = math.nan
        msgs[i] = (msgs[i][0], bytes(TYPESTORE.serialize_cdr(msg, IMU)))
    damaged = tmp_path / "top_nan"
    write_bag(damaged, topic, IMU, iter(msgs))
    capsys.readouterr()
    out = str(tmp_path / "cal.scene.yaml")
    for command in ("calibrate", "track"):
        args = [command, scene, "--foundation", str(ground), "--body", str(damaged)]
        assert main([*args, *(["-o", out] if command == "calibrate" else [])]) == 2
        err = capsys.readouterr().err
        assert (
            f"{damaged}: /machine/imu: 20 of {len(msgs)} samples not finite, the first its " in err
        )
    assert (
        main(["calibrate", scene, "--foundation", str(ground), "--body", str(ground), "-o", out])
        == 2
    )
    assert f"{ground}: no topic '/machine/imu' (body_sensor.topic);" in capsys.readouterr().err


def test_records_too_short_to_compare_are_refused_for_that_not_for_their_clocks() -> None:
    """0.4 s of both records on one clock: the fit compares the body samples from 0.25 s after
    the foundation record's start to 0.25 s before its end (EDGE_S), none of 0.4 s. It was
    told "the two records must overlap on one clock", which they do."""
    foundation, body = _pair(_pump(), ship_motion(rate_hz=RATE, total=0.4), {})
    assert body.t[0] < foundation.t[-1] and foundation.t[0] < body.t[-1]  # they overlap
    with pytest.raises(ValueError) as err:
        cal_mod.calibrate(_pump(), foundation, body, ("stiffness",))
    said = str(err.value)
    assert "overlap on one clock" not in said
    assert "0.395 s long" in said and "longer than 0.5 s" in said


def test_every_figure_calibrate_prints_carries_its_unit() -> None:
    """It printed "lag: 18.89 ms ± 0.29 (1σ)": the 1σ without its unit. A lag of 18.89 ms is
    0.01889 s; an angle of 1.672° is 0.02918 rad (printed in rad, degrees beside: "-1.672°" gave
    no rad), its 1σ 0.62° is 0.0108 rad; 12.3 mm is 0.0123 m; scales are factors."""
    from mount_twin.analysis.calibration import Calibration
    from mount_twin.commands.calibrate import describe

    cal = Calibration(
        {"stiffness": 1.23, "lag": 0.01889, "yaw": math.radians(-1.672), "sensor_x": 0.0123},
        {"stiffness": 0.0024, "lag": 0.00029, "yaw": math.radians(0.62), "sensor_x": 0.0004},
        {},
        1.035,
        0.587,
        load_scene_file(SHAKE / "block.scene.yaml"),
    )
    assert describe(cal)[:4] == [
        "stiffness: ×1.23 ± 0.0024 (1σ)",
        "lag: 18.89 ms ± 0.29 ms (1σ)",
        "yaw: -0.02918 rad (-1.672 deg) ± 0.011 rad (0.62 deg) (1σ)",
        "sensor_x: 12.3 mm ± 0.4 mm (1σ)",
    ]


def test_a_record_marking_a_reading_the_fit_reads_not_provided_is_refused(
    tmp_path: Path,
) -> None:
    """An Imu whose covariance[0] is -1 has no such reading (REP-145): the fit took its
    placeholder (zeros, a fixed rate) as a reading. A record marking one the fit reads is now
    refused, as one not finite is, naming the bag, the topic and how many; a rate the run
    does not read (input.gyro_filter: ignore) may be marked."""
    from io_helpers import unprovided_imu

    from mount_twin.commands.calibrate import BODY_KEYS, _read_record
    from mount_twin.io.messages import IMU
    from mount_twin.io.output_bag import write_bag
    from mount_twin.io.output_encoding import imu_messages

    sig = ship_motion(rate_hz=200.0, total=2.0)
    stamps = 10**18 + np.round(sig.t * 1e9).astype(np.int64)
    msgs = imu_messages(stamps, sig.accel, sig.gyro, "")
    for field in ("angular_velocity", "linear_acceleration"):
        ns, raws = zip(*msgs[50:54], strict=True)
        marked = [*msgs[:50], *zip(ns, unprovided_imu(list(raws), field), strict=True), *msgs[54:]]
        bag = tmp_path / field
        write_bag(bag, "/machine/imu", IMU, iter(marked))
        said = (
            f"{bag}: /machine/imu: 4 of 400 samples mark a reading not provided (covariance[0] "
            f"= -1, REP-145: acceleration {4 * (field == 'linear_acceleration')}, angular "
            f"velocity {4 * (field == 'angular_velocity')}), the first its message 50"
        )
        with pytest.raises(ValueError, match=re.escape(said)):
            _read_record(str(bag), "/machine/imu", IMU, None, BODY_KEYS)
        if field == "angular_velocity":  # a run that reads no rate
            record, _ = _read_record(str(bag), "/machine/imu", IMU, None, BODY_KEYS, False)
            assert record.t.shape[0] == 400
            np.testing.assert_array_equal(record.accel, sig.accel)
        else:
            with pytest.raises(ValueError, match=re.escape(said)):
                _read_record(str(bag), "/machine/imu", IMU, None, BODY_KEYS, False)


def test_the_plot_names_what_its_axes_hold(tmp_path: Path, monkeypatch) -> None:
    """The panels read `x [m/s²]` over `time [s]`: neither said that they hold the body IMU's
    specific force along its own axes, each about its mean, nor from when time counts."""
    import matplotlib.pyplot as plt

    from mount_twin.commands.calibrate import _plot

    shown = []
    close = plt.close
    monkeypatch.setattr(plt, "close", lambda fig=None: shown.append(fig) or close(fig))
    scene = load_scene_file(SHAKE / "block.scene.yaml")
    ground, top = (
        read_xsens_csv(SHAKE / f"sine_2hz_trial1_{side}_excerpt.csv").signal
        for side in ("ground", "top")
    )
    cal = cal_mod.Calibration({}, {}, {}, 1.0, 0.5, scene)  # the nominal scene, as fitted
    _plot(str(tmp_path / "c.png"), scene, cal, ground, top)
    (fig,) = shown
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == [
        f"body IMU specific force\nalong its {a}, about its mean [m/s²]" for a in "xyz"
    ]
    assert fig.axes[-1].get_xlabel() == "time from the body record's first sample [s]"


def test_an_angle_refused_as_too_uncertain_gives_its_1_sigma_in_rad() -> None:
    """The refusal read "1σ is 12.0°": the angle in degrees only. 12° is 0.2094 rad."""
    from mount_twin.analysis.calibration import _too_uncertain

    why = _too_uncertain("yaw", math.radians(12.0), 0.1, 0.005)
    assert why == "1σ is 0.2094 rad (12 deg): the motion has no direction to tell it by"
