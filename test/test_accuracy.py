"""`mount-twin accuracy`: its error figures are the run's true errors (a one-DOF case with an
independent solution), and the command writes its table, CSV and plot."""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

import numpy as np
import pytest
from io_helpers import CONFIG, ROOT, read_raw, scene_with, unprovided_imu
from physics_helpers import base_scene, mount
from scipy.integrate import solve_ivp

from mount_twin.analysis import accuracy as accuracy_module
from mount_twin.analysis.accuracy import (
    NAN,
    REPRODUCED,
    Accuracy,
    compare,
    raw_gyro,
    reference_input,
    reference_run,
    run_at,
)
from mount_twin.cli import main
from mount_twin.commands.accuracy import _table, _unresolved
from mount_twin.engine.batch import SampleBatch
from mount_twin.errors import MountTwinError
from mount_twin.io.input_samples import read_samples
from mount_twin.io.messages import IMU, TYPESTORE
from mount_twin.io.output_bag import write_bag
from mount_twin.scene.loader import load_scene_file, scene_from_dict

G = 9.80665
MASS, F_N, ZETA = 10.0, 200.0, 0.05  # kg, Hz, −: a stiff bounce against a 1 kHz record
OMEGA = 2.0 * math.pi * F_N
K_EACH, C_EACH = MASS * OMEGA**2 / 4.0, 2.0 * ZETA * MASS * OMEGA / 4.0
RATE = 1000.0


def _case() -> tuple:
    corners = [(0.3, 0.2), (-0.3, 0.2), (-0.3, -0.2), (0.3, -0.2)]
    mounts = [
        mount(f"m{i}", (x, y, 0.0), (K_EACH, K_EACH, K_EACH, 0, 0, 0), (C_EACH,) * 3 + (0,) * 3)
        for i, (x, y) in enumerate(corners)
    ]
    data = base_scene(MASS, [0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 0, 0, 0], mounts, dofs=["z"])
    data["input"]["frame_id"] = "deck_imu"
    scene = scene_from_dict(data, "<accuracy test>")
    t = 1.0 + np.arange(300) / RATE
    fz = G + np.where((t > 1.05) & (t < 1.061), 300.0 * np.sin(math.pi * (t - 1.05) / 0.011), 0.0)
    accel = np.column_stack([np.zeros_like(t), np.zeros_like(t), fz])
    samples = SampleBatch(t, accel, np.zeros_like(accel), ["deck_imu"] * t.shape[0])
    return scene, samples


def _truth(samples: SampleBatch) -> np.ndarray:
    """z(t) of z'' = −(k/m) z − (c/m) z' − f_z(t), f_z linear between samples, from rest at
    z = −m·f_z(0)/k (scipy, rtol 1e-12, steps ≤ a quarter interval)."""
    t, fz = samples.stamps, samples.accel[:, 2]
    k, c = 4 * K_EACH, 4 * C_EACH

    def rhs(tt: float, y: np.ndarray) -> list[float]:
        return [y[1], -(k / MASS) * y[0] - (c / MASS) * y[1] - np.interp(tt, t, fz)]

    sol = solve_ivp(
        rhs,
        (t[0], t[-1]),
        [-MASS * fz[0] / k, 0.0],
        t_eval=t,
        rtol=1e-12,
        atol=1e-16,
        max_step=0.25 / RATE,
        method="DOP853",
    )
    return sol.y[0]


@pytest.mark.parametrize("rtol", [1e-3, 1e-5])
def test_the_reported_error_is_the_true_error(rtol: float) -> None:
    scene, samples = _case()
    truth = _truth(samples)
    ref = reference_run(scene, samples, 100_000)
    run = run_at(scene, samples, rtol, 100_000)
    reported = compare(run, ref, 0.3).position_error_m
    true = np.abs(run.out.position[:, 2] - truth).max()
    assert true > 1e-9, "the run must have an error worth measuring"
    assert 0.9 < reported / true < 1.1, (reported, true)
    assert np.abs(ref.out.position[:, 2] - truth).max() < 0.01 * true


def test_the_command_writes_a_table_a_csv_and_a_plot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    table, png = tmp_path / "acc.csv", tmp_path / "acc.png"
    args = [
        "accuracy",
        str(CONFIG / "pump_8_mounts.scene.yaml"),
        str(ROOT / "bags" / "ship_motion_1khz"),
        "--rtol",
        "1e-3",
        "1e-9",
        "--csv",
        str(table),
        "--plot",
        str(png),
    ]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "reference: the same twin at rtol 1e-12" in out
    assert "gives its run bit for bit): the errors are the integration's" in out
    assert "resolution: the reference differs from one on the input refined 9× by" in out
    assert "not resolved" not in out  # the pump's errors are 1e-10–1e-9, its resolution 1e-13
    rows = list(csv.DictReader(table.open(encoding="utf-8")))
    assert [float(r["rtol"]) for r in rows] == [1e-3, 1e-9]
    # the runs take the gyro as shipped (linear_phase), and so does the reference: the figures
    # are the integration's error (1e-9 and 2e-10), which the live estimate estimates; they
    # read 1.03e-5 at every rtol, the gyro filter's effect, when the reference took it raw
    for r in rows:
        assert 1e-11 < float(r["force_error"]) < 1e-8
        assert 0.5 < float(r["est_force_error"]) / float(r["force_error"]) < 2.0
    (effect,) = re.findall(r"gyro conditioning \(linear_phase\): .* differs by (\S+) of", out)
    assert 1e-6 < float(effect) < 1e-4  # ship motion's roll and pitch, filtered at 20-100 Hz
    assert png.stat().st_size > 10_000


def _ship_motion_bag(bag: Path, keep: slice | np.ndarray, nan_gyro_at: int | None = None) -> Path:
    """The bundled ship-motion bag's messages `keep` written to `bag`, one of them (position
    among those kept) with a NaN gyro reading if `nan_gyro_at` is given."""
    (msgs,) = read_raw(ROOT / "bags" / "ship_motion_1khz", ["/deck/imu"]).values()
    kept = [msgs[i] for i in np.arange(len(msgs))[keep]]
    if nan_gyro_at is not None:
        t, raw = kept[nan_gyro_at]
        msg = TYPESTORE.deserialize_cdr(raw, IMU)
        msg.angular_velocity.x = math.nan
        kept[nan_gyro_at] = (t, bytes(TYPESTORE.serialize_cdr(msg, IMU)))
    write_bag(bag, "/deck/imu", IMU, iter(kept))
    return bag


def test_the_reference_takes_the_record_as_the_twin_takes_it(tmp_path: Path) -> None:
    """The twin of the raw gyro on the record conditioned beforehand gives the scene's twin's
    run bit for bit (the sensor's axes are F's): with the shipped filter, also across a gap
    past max_gap_s (0.5 s), after which the twin restarts and its delay line with it; with the
    gyro ignored, its rate zero."""
    scene = load_scene_file(CONFIG / "pump_8_mounts.scene.yaml")
    gap = _ship_motion_bag(tmp_path / "gap", np.r_[0:1000, 1600:3000])
    for gyro_filter, bag in (("linear_phase", gap), ("ignore", gap)):
        variant = scene_with(scene, input={"gyro_filter": gyro_filter})
        samples = read_samples(bag, variant.input)
        record = reference_input(variant, samples, 100_000)
        assert record.conditioned and record.reproduction == 0.0
        assert not np.array_equal(record.samples.gyro, samples.gyro)  # it was conditioned
        twin = run_at(variant, samples, 1e-4, 100_000, estimate=False)
        assert twin.out.stamps.shape[0] == 2400  # every sample answered, the restart's too
        again = run_at(raw_gyro(variant), record.samples, 1e-4, 100_000, estimate=False)
        np.testing.assert_array_equal(again.out.wrenches, twin.out.wrenches)
        np.testing.assert_array_equal(again.out.angles, twin.out.angles)


def test_a_record_the_twin_rejects_samples_of_is_referenced_as_recorded_and_said_so(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """A sample the twin rejects (a NaN reading) never reaches its delay line; the record
    conditioned beforehand filters it in: the reference then takes the gyro as recorded, and
    the command says that its errors include the conditioning's."""
    bag = _ship_motion_bag(tmp_path / "nan", slice(0, 2000), nan_gyro_at=700)
    scene = load_scene_file(CONFIG / "pump_8_mounts.scene.yaml")
    samples = read_samples(bag, scene.input)
    record = reference_input(scene, samples, 100_000)
    assert not record.conditioned and record.samples is samples
    assert record.reproduction > REPRODUCED
    args = ["accuracy", str(CONFIG / "pump_8_mounts.scene.yaml"), str(bag), "--rtol", "1e-6"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "so the errors include the gyro conditioning's (gyro_filter linear_phase)" in out
    assert "gyro conditioning (linear_phase): " not in out


def test_samples_marked_not_provided_are_left_out_as_the_twin_leaves_them_out(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """20 samples whose acceleration the IMU marks not provided (covariance[0] = -1, REP-145,
    zeros in it): the twin skips them, leaving no hole, but the reference, derived from the
    record, held their zeros as a free fall. Now both leave them out: the figures are those of
    the record without them, and the command names the bag and how many."""
    (msgs,) = read_raw(ROOT / "bags" / "ship_motion_1khz", ["/deck/imu"]).values()
    msgs = msgs[:1500]
    stamps, raws = zip(*msgs[700:720], strict=True)
    marked = [
        *msgs[:700],
        *zip(stamps, unprovided_imu(list(raws), "linear_acceleration"), strict=True),
        *msgs[720:],
    ]
    write_bag(tmp_path / "marked", "/deck/imu", IMU, iter(marked))
    write_bag(tmp_path / "kept", "/deck/imu", IMU, iter([*msgs[:700], *msgs[720:]]))
    scene = str(CONFIG / "pump_8_mounts.scene.yaml")
    tables, said = [], []
    for name in ("marked", "kept"):
        csv_path = tmp_path / f"{name}.csv"
        args = ["accuracy", scene, str(tmp_path / name), "--rtol", "1e-4", "--csv", str(csv_path)]
        assert main(args) == 0
        rows = csv.DictReader(csv_path.open(encoding="utf-8"))
        timed = ("wall_s_per_sim_s", "estimate_cost")  # the wall clock's
        tables.append([{k: v for k, v in r.items() if k not in timed} for r in rows])
        said.append(capsys.readouterr().err)
    assert tables[0] == tables[1]
    err = said[0]
    assert (
        f"{tmp_path / 'marked'}: /deck/imu: 20 of 1500 samples mark a reading not provided "
        "(covariance[0] = -1, REP-145: acceleration 20, angular velocity 0), the first its "
        f"message 700 (stamp {stamps[0]} ns): disregarded" in err
    ), err


def test_a_record_whose_every_sample_the_twin_rejects_is_refused_saying_why(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """It was numpy's "zero-size array to reduction operation maximum which has no identity"."""
    text = (CONFIG / "pump_8_mounts.scene.yaml").read_text(encoding="utf-8")
    scene = tmp_path / "s.scene.yaml"
    scene.write_text(text.replace("frame_id: deck_imu", "frame_id: elsewhere"), encoding="utf-8")
    bag = _ship_motion_bag(tmp_path / "few", slice(0, 200))
    assert main(["accuracy", str(scene), str(bag), "--rtol", "1e-4"]) == 2
    err = capsys.readouterr().err
    assert "mount-twin: error: " in err and "no input sample was accepted (200 received" in err


def test_errors_within_the_references_resolution_are_named_not_resolved() -> None:
    """The command names each rtol whose force or attitude error is within RESOLVED times what
    the reference resolves, and nothing where every error is above it."""
    resolved = _accuracy(1.0, force=1e-9, attitude=1e-12)
    rows = [
        _accuracy(1e-3, force=1e-5, attitude=1e-9),
        _accuracy(1e-9, force=2e-9, attitude=1e-9),
        _accuracy(1e-12, force=1e-5, attitude=3e-12),
    ]
    line = _unresolved(rows, resolved)
    assert line.endswith("rtol 1e-09 (force), 1e-12 (attitude)"), line
    assert _unresolved(rows[:1], resolved) == ""


def _accuracy(rtol: float, force: float, attitude: float) -> Accuracy:
    return Accuracy(rtol, force, 0.0, attitude, 0.0, 0.0, 1.0, 0, NAN, NAN, NAN)


def test_the_command_goes_on_where_the_second_reference_fails(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A reference on the other step grid that fails (a chattering law may fail on one grid and
    not the other) leaves the resolution unmeasured, said so; the table is still the runs'."""

    def fails(*args: object) -> None:
        raise MountTwinError("no reference: the stepper failed at every reference tolerance")

    monkeypatch.setattr(accuracy_module, "resolution", fails)
    args = [
        "accuracy",
        str(CONFIG / "pump_8_mounts.scene.yaml"),
        str(ROOT / "bags" / "ship_motion_1khz"),
    ]
    assert main([*args, "--rtol", "1e-3"]) == 0
    out = capsys.readouterr().out
    assert "resolution: not measured (the reference on the input refined 9×: no reference:" in out
    assert "1e-03" in out


@pytest.mark.parametrize(
    ("option", "named"),
    [
        (
            ["--rtol", "0"],
            "--rtol: 0.0 is outside [1e-13, 0.1]",
        ),  # the core's "bad stepper settings"
        (["--rtol", "1e-3", "0.5"], "--rtol: 0.5 is outside"),
    ],
)
def test_the_command_refuses_a_setting_no_run_takes_naming_the_option(
    option: list[str], named: str, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = str(ROOT / "bags" / "ship_motion_1khz")
    assert main(["accuracy", str(CONFIG / "pump_8_mounts.scene.yaml"), bag, *option]) == 2
    assert f"mount-twin: error: {named}" in capsys.readouterr().err


def test_the_table_heads_each_column_with_its_unit() -> None:
    """`force err 1.03e-09` read as newtons: the force errors are ratios (of the largest force,
    of each mount's peak), and every column's unit stands under its name, aligned with its
    figures."""
    row = Accuracy(1e-6, 2e-3, 9e-5, 4.8e-7, 3.2e-7, 0.1, 1.23, 0, 1.9e-3, 4.4e-7, 1.7)
    head, units, figures = _table([row]).splitlines()
    expected = {
        "force err": ("of max |F|", "2.00e-03"),
        "peak err": ("of peaks", "9.00e-05"),
        "attitude err": ("rad", "4.80e-07"),
        "CG err": ("m", "3.20e-07"),
        "wall": ("s/s", "0.1000"),
        "substeps": ("per sample", "1.23"),
    }
    for name, (unit, figure) in expected.items():
        end = head.index(name) + len(name)  # columns are right-aligned
        assert units[:end].endswith(unit), (name, units)
        assert figures[:end].endswith(figure), (name, figures)


def test_a_run_whose_stepper_fails_is_compared_where_it_answered_its_failures_counted() -> None:
    """At one substep per sample and rtol 1e-9 the stepper fails into the samples of the shock,
    each failure leaving that sample unanswered (the twin restarts at the next): the figures
    are the errors over the samples the run answered, against the independent solution there,
    and the failures are counted, not a refusal of the whole comparison."""
    scene, samples = _case()
    truth = _truth(samples)
    ref = reference_run(scene, samples, 100_000)
    run = run_at(scene, samples, 1e-9, 1)
    answered = np.isin(samples.stamps, run.out.stamps)
    assert run.failures > 0 and 0 < answered.sum() < len(samples)
    got = compare(run, ref, 0.3)
    true = np.abs(run.out.position[:, 2] - truth[answered]).max()
    assert got.failures == run.failures
    assert 0.9 < got.position_error_m / true < 1.1, (got.position_error_m, true)
