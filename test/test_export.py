"""`mount-twin export`: an output bag's series as CSV tables, exact to the bit and the
nanosecond, with times from the first output."""

from __future__ import annotations

import csv
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from io_helpers import CONFIG, ROOT, read_bag

from mount_twin.cli import main
from mount_twin.commands import export
from mount_twin.io.output_tables import Table, events_of, table_names
from mount_twin.replay import replay
from mount_twin.scene import load_scene_file


@pytest.fixture(scope="module")
def replayed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("export") / "out"
    args = ["replay", str(ROOT / "bags" / "half_sine_shock_10khz"), "--scene"]
    args += [str(CONFIG / "pump_8_mounts.scene.yaml"), "-o", str(out), "--no-progress"]
    assert main(args) == 0
    return out


def _csv(path: Path) -> list[dict[str, str]]:
    return list(csv.DictReader(path.open(encoding="utf-8")))


def test_tables_hold_every_message_exactly(replayed: Path, tmp_path: Path) -> None:
    assert main(["export", str(replayed), "--csv", str(tmp_path)]) == 0
    _, msgs = read_bag(replayed)
    pose = _csv(tmp_path / "pose.csv")
    want = msgs["/mount_twin/pose"]
    assert len(pose) == len(want)
    for row, (stamp, msg) in zip(pose, want, strict=True):
        assert int(row["stamp_ns"]) == stamp
        assert float(row["z_m"]) == msg.pose.position.z
        assert float(row["qw"]) == msg.pose.orientation.w
    first = int(pose[0]["stamp_ns"])
    assert float(pose[0]["t_s"]) == 0.0
    assert float(pose[-1]["t_s"]) == pytest.approx((int(pose[-1]["stamp_ns"]) - first) * 1e-9)
    wrench = _csv(tmp_path / "mount_fl.csv")
    fz = np.array([float(r["fz_N"]) for r in wrench])
    np.testing.assert_array_equal(
        fz, [m.wrench.force.z for _, m in msgs["/mount_twin/mounts/fl/wrench"]]
    )
    diag = _csv(tmp_path / "diagnostics.csv")
    assert {r["level"] for r in diag} <= {"OK", "WARN", "ERROR", "STALE"}
    assert {"mount_twin: input", "mount_twin: mount fl"} <= {r["status"] for r in diag}


def test_a_bag_without_outputs_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = ROOT / "bags" / "ship_motion_1khz"  # an input bag: no output in it
    assert main(["export", str(bag), "--csv", str(tmp_path)]) == 2
    assert f"{bag}: no mount_twin output in the bag" in capsys.readouterr().err


@pytest.fixture
def unread(monkeypatch: pytest.MonkeyPatch) -> None:
    """Reading an output bag is a failure: a target is to be checked before the bag is read."""

    def read(*_: object) -> None:
        raise AssertionError("the bag was read before its target was checked")

    monkeypatch.setattr("mount_twin.io.output_tables.read_output_bag", read)


@pytest.mark.usefixtures("unread")
@pytest.mark.parametrize("where", ["device", "file", "under_a_file"])
def test_a_target_that_cannot_be_a_directory_is_refused_naming_the_option_before_reading(
    replayed: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    where: str,
) -> None:
    """`export BAG --csv /dev/full` read the whole bag, then said "mount-twin: error:
    /dev/full: File exists", naming no option and not what was wrong (a file where the
    directory of tables goes; under a file, "Not a directory"). It says so first."""
    afile = tmp_path / "afile"
    afile.write_text("not a directory", encoding="utf-8")
    if where == "device" and not Path("/dev/full").exists():
        pytest.skip("no /dev/full")
    target = {"device": Path("/dev/full"), "file": afile, "under_a_file": afile / "tables"}[where]

    assert main(["export", str(replayed), "--csv", str(target)]) == 2
    said = f"{afile} is not a directory" if where == "under_a_file" else "exists, not a directory"
    want = f"mount-twin: error: --csv {target}: {said}; export writes one file per table into "
    assert capsys.readouterr().err == f"{want}a directory\n"
    assert afile.read_text(encoding="utf-8") == "not a directory"


@pytest.mark.usefixtures("unread")
@pytest.mark.parametrize("where", ["at_the_target", "above_the_target"])
def test_a_dangling_symlink_in_the_way_is_refused_naming_it_before_reading(
    replayed: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    where: str,
) -> None:
    """A symlink to a missing directory as the target (or above it) read as absent: the bag
    was read whole, then "mount-twin: error: LINK: File exists", naming no option and not
    why. It is refused first, naming the link and where it points; the link is left."""
    link = tmp_path / "tables"
    link.symlink_to(tmp_path / "missing")
    target = link if where == "at_the_target" else link / "csv"

    assert main(["export", str(replayed), "--csv", str(target)]) == 2
    err = capsys.readouterr().err
    said = f"{link} is a symlink to {tmp_path / 'missing'}, which does not exist"
    assert err.startswith(f"mount-twin: error: --csv {target}: {said}"), err
    assert link.is_symlink() and not (tmp_path / "missing").exists()


def _files(root: Path) -> dict[Path, bytes]:
    """Every file under `root` and its bytes."""
    return {p: p.read_bytes() for p in root.rglob("*") if p.is_file()}


def test_an_export_that_fails_part_way_leaves_the_directory_as_it_was(
    replayed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`export --csv DIR` into a directory holding a table's name as a directory (the last
    table's, events.csv): the tables before it were left in DIR, each looking finished (and
    the last export's pose.csv replaced), then exit 2. Now none of them is put in place until
    every one is written: DIR is left as it was, its own files untouched."""
    tables = tmp_path / "tables"
    tables.mkdir()
    (tables / "pose.csv").write_text("the last pose\n", encoding="utf-8")
    (tables / "notes.txt").write_text("mine\n", encoding="utf-8")
    (tables / "events.csv").mkdir()
    before = _files(tmp_path)

    assert main(["export", str(replayed), "--csv", str(tables)]) == 2
    err = capsys.readouterr().err
    assert err.endswith(
        f"mount-twin: error: {tables / 'events.csv'}: cannot write: Is a directory\n"
    )
    assert _files(tmp_path) == before
    assert sorted(p.name for p in tables.iterdir()) == ["events.csv", "notes.txt", "pose.csv"]


@pytest.mark.parametrize(
    ("stop", "status"),
    [(OSError(5, "Input/output error"), 2), (KeyboardInterrupt(), 130)],
    ids=["error", "ctrl-c"],
)
def test_an_export_whose_rename_fails_removes_the_tables_it_made_new(
    replayed: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    stop: BaseException,
    status: int,
) -> None:
    """Every table is written before the first is renamed into place; a rename failing after
    others (a race, or a Ctrl-C between two: here at the third) removes the tables those
    renames made new, and leaves no file being written; a table that was there before is
    replaced whole (the new pose)."""
    import os

    tables = tmp_path / "tables"
    tables.mkdir()
    (tables / "pose.csv").write_text("the last pose\n", encoding="utf-8")
    rename, calls = os.replace, []

    def third_fails(src: str | Path, dst: str | Path) -> None:
        calls.append(dst)
        if len(calls) == 3:
            raise stop
        rename(src, dst)

    monkeypatch.setattr(os, "replace", third_fails)
    assert main(["export", str(replayed), "--csv", str(tables)]) == status
    assert [Path(c).name for c in calls] == ["pose.csv", "angles.csv", "mount_fl.csv"]
    assert sorted(p.name for p in tables.iterdir()) == ["pose.csv"]
    _, msgs = read_bag(replayed)
    assert len(_csv(tables / "pose.csv")) == len(msgs["/mount_twin/pose"])


def test_an_export_into_a_new_directory_that_fails_leaves_nothing_it_made(
    replayed: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`export --csv a/b/tables` makes tables and the directories above it; one that fails
    on a table after the first (a full disk) removes the tables written so far and the
    directories it made, leaving what was there."""
    import errno

    from mount_twin.io import output_tables

    write, written = output_tables._write_csv, []

    def full_at_the_second(table: Table, path: Path) -> None:
        if written:
            raise OSError(errno.ENOSPC, "No space left on device")
        write(table, path)
        written.append(path)

    monkeypatch.setattr(output_tables, "_write_csv", full_at_the_second)
    (tmp_path / "kept").mkdir()
    tables = tmp_path / "kept" / "a" / "b" / "tables"
    assert main(["export", str(replayed), "--csv", str(tables)]) == 2
    assert written  # the first table was written before the failure
    assert list(tmp_path.rglob("*")) == [tmp_path / "kept"]

    monkeypatch.setattr(output_tables, "_write_csv", write)
    assert main(["export", str(replayed), "--csv", str(tables)]) == 0
    assert (tables / "pose.csv").is_file()


def test_a_table_that_is_a_dangling_symlink_makes_no_directory_where_it_points(
    replayed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The directories missing above an output are made above the path given, not through a
    symlink at it: DIR/pose.csv linked into a missing directory is refused as it was, naming
    it, and nothing is made where it points."""
    tables = tmp_path / "tables"
    tables.mkdir()
    (tables / "pose.csv").symlink_to(tmp_path / "elsewhere" / "pose.csv")

    assert main(["export", str(replayed), "--csv", str(tables)]) == 2
    err = capsys.readouterr().err
    pose = tables / "pose.csv"
    assert err.endswith(f"mount-twin: error: {pose}: cannot write: No such file or directory\n")
    assert sorted(tmp_path.rglob("*")) == [tables, pose]


def test_replay_summary_times_events_from_the_first_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The JSON's events and the printed summary's event lines: time from the first output
    (the plots' and the report's), with the header stamp beside it (the printed lines gave
    the stamp alone: "first 1700000000.051878 s")."""
    import json
    import re

    out, summary_file = tmp_path / "g", tmp_path / "g.json"
    args = ["replay", str(ROOT / "bags" / "genset_shock_10khz"), "--scene"]
    args += [str(CONFIG / "genset_bolted_keyed.scene.yaml"), "-o", str(out), "--no-progress"]
    assert main([*args, "--json", str(summary_file)]) == 0
    printed = capsys.readouterr().out
    doc = json.loads(summary_file.read_text(encoding="utf-8"))
    _, msgs = read_bag(out)
    first = msgs["/mount_twin/pose"][0][1].header.stamp
    first_s = first.sec + first.nanosec * 1e-9
    assert doc["verdict"] == "ERROR" and doc["events"]
    for e in doc["events"]:
        assert e["t_s"] == pytest.approx(e["stamp_s"] - first_s, abs=1e-6)
    lines = re.findall(r"×\d+ +first (\d+\.\d+) s \(stamp (\d+\.\d+) s\)", printed)
    assert lines
    for t, stamp in lines:
        assert 0.0 <= float(t) < 1.0 and float(t) == pytest.approx(
            float(stamp) - first_s, abs=2e-6
        )
    assert doc["counts"]["accepted"] == 2500
    f = max(
        math.hypot(m.wrench.force.x, m.wrench.force.y, m.wrench.force.z)
        for _, m in msgs["/mount_twin/mounts/foot_fl/wrench"]
    )
    assert doc["mounts"]["foot_fl"]["peak_force_magnitude_N"] == pytest.approx(f, rel=1e-12)
    # the live error estimate over the run, as docs/scene.md's genset figures put it (1.5e-3)
    est = doc["error_estimate"]
    assert 3e-4 < est["force_error_rel"] < 1e-2 and est["failed_checks"] == 0
    assert est["force_error_n"] > 0.0 and 0.0 < est["attitude_error_rad"] < 1e-5


def test_the_events_table_holds_every_mount_event_of_the_run(tmp_path: Path) -> None:
    """`events.csv`: per diagnostics period and mount event, its count, first stamp, level and
    largest |F|; summed over the periods, the counts are the replay's own event list; the
    rows in time order within the outputs' span (to the µs the message gives)."""
    out = tmp_path / "out"
    summary = replay(
        load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml"),
        ROOT / "bags" / "genset_shock_10khz",
        out,
        progress=False,
    )
    assert summary.events, "the case must have mount events"
    assert main(["export", str(out), "--csv", str(tmp_path / "t")]) == 0
    rows = _csv(tmp_path / "t" / "events.csv")
    counts: dict[tuple[str, str], int] = {}
    first: dict[tuple[str, str], int] = {}
    for r in rows:
        key = (r["mount"], r["event"])
        counts[key] = counts.get(key, 0) + int(r["count"])
        first.setdefault(key, int(r["stamp_ns"]))
        assert r["level"] in ("WARN", "ERROR") and float(r["force_max_N"]) > 0.0
    want: dict[tuple[str, str], int] = {}
    for e in summary.events:
        want[(e.mount, e.event)] = want.get((e.mount, e.event), 0) + 1
    assert counts == want
    # to the nanosecond and the bit (they were the message's µs and 4 digits: 135500.0 N)
    for key in want:
        mine = [e for e in summary.events if (e.mount, e.event) == key]
        assert first[key] == summary.origin_s * 10**9 + round(mine[0].stamp * 1e9)
        forces = [float(r["force_max_N"]) for r in rows if (r["mount"], r["event"]) == key]
        assert max(forces) == max(e.force for e in mine)
    pose = _csv(tmp_path / "t" / "pose.csv")
    stamps = [int(r["stamp_ns"]) for r in rows]
    assert stamps == sorted(stamps)
    assert int(pose[0]["stamp_ns"]) - 1000 <= min(first.values())
    assert max(stamps) <= int(pose[-1]["stamp_ns"]) + 1000


def test_events_of_a_bag_recorded_before_the_full_values_are_read_from_the_message() -> None:
    """Mount statuses without `<event>.first_stamp_ns` (a node before them): the message's
    µs and four digits."""
    diagnostics = Table(
        "diagnostics",
        {
            "stamp_ns": np.array([2_000_000_000]),
            "t_s": np.array([0.0]),
            "status": np.array(["mount_twin: mount fl"], dtype=object),
            "level": np.array(["ERROR"], dtype=object),
            "message": np.array(
                ["joint_opened ×3 (first 1.234567 s, |F| max 4.5e+04 N)"], dtype=object
            ),
            "values": np.array(['{"events": "3"}'], dtype=object),
        },
    )
    (event,) = events_of(diagnostics, 1_000_000_000)
    assert (event.mount, event.event, event.count) == ("fl", "joint_opened", 3)
    assert event.t_s == pytest.approx(0.234567, abs=1e-12) and event.force_n == 45000.0


def test_decimated_peaks_are_said_to_be_an_upper_bound_and_are_one(tmp_path: Path) -> None:
    """Decimated rows hold each component's peak: their |F| is not one that acted at one
    instant (foot_fl read 225859 N against 224390 N), and the summary said it was."""
    scene = load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml")
    bag = ROOT / "bags" / "genset_shock_10khz"
    full = replay(scene, bag, tmp_path / "full", progress=False)
    every_10 = dataclasses.replace(
        scene, outputs=dataclasses.replace(scene.outputs, decimation=10)
    )
    decimated = replay(every_10, bag, tmp_path / "dec", progress=False)
    assert "peak mount loads (largest magnitude at one instant)" in full.text()
    assert "(decimated: from each component's peak over 10 samples, an upper bound" in (
        decimated.text()
    )
    for name, peak in full.peaks.items():
        assert (decimated.peaks[name] >= peak).all()


def test_export_help_names_every_table_it_writes(
    replayed: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The help listed pose, angles, wrenches and diagnostics, not events.csv nor the body
    IMU's tables (written with a body_sensor: test_replay_body_imu)."""
    with pytest.raises(SystemExit):
        main(["export", "--help"])
    helped = " ".join(capsys.readouterr().out.split())
    for name in ("pose", "angles", "mount_<mount>", "diagnostics", "events"):
        assert name in helped
    for name in ("body_imu_predicted", "body_imu_residual"):
        assert name in helped
    assert main(["export", str(replayed), "--csv", str(tmp_path)]) == 0
    written = {p.stem for p in tmp_path.iterdir()}
    assert "events" in written
    for stem in written:
        assert (stem if not stem.startswith("mount_") else "mount_<mount>") in helped
    assert list(export.TABLES) == table_names()
