"""The `mount-twin` command line: demo, generate, import-csv, replay, and its error exits."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml
from io_helpers import DATA_DIR, ROOT, SCENE_FILE, read_bag, run_python, stamp_ns
from rosbags.highlevel import AnyReader

from mount_twin.cli import main
from mount_twin.io.messages import IMU, TYPESTORE

WATER_ENTRY = DATA_DIR / "water_entry_shock_20khz_excerpt.csv"


def _scene_file(tmp_path: Path, **input_changes: object) -> Path:
    data = yaml.safe_load(SCENE_FILE.read_text(encoding="utf-8"))
    data["input"].update(input_changes)
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def test_a_scene_with_stiffness_in_n_per_mm_is_run_with_its_warning_on_stderr(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every command that loads a scene says what the loader found implausible (here `info`)."""
    data = yaml.safe_load(SCENE_FILE.read_text(encoding="utf-8"))
    for m in data["mounts"]:
        m["stiffness"] = [v / 1000.0 for v in m["stiffness"][:3]] + m["stiffness"][3:]
    path = tmp_path / "soft.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    assert main(["info", str(path)]) == 0
    err = capsys.readouterr().err
    assert f"mount-twin: warning: {path}: mounts: under its weight" in err
    assert "stiffness in N/mm, or mass in g?" in err
    assert main(["info", str(SCENE_FILE)]) == 0
    assert "warning" not in capsys.readouterr().err  # the bundled scene is plausible


def test_demo_replays_the_bundled_bag_and_prints_a_summary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "demo_out"
    assert main(["demo", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "real-time factor" in text
    assert "5000 received, 5000 accepted" in text and "integration failures: 0" in text
    assert "diagnostics, worst over the run: OK" in text
    assert "    OK    mount_twin: input: ok" in text
    # 1.0e-9 against a reference (docs/benchmarks.md): the estimate says as much
    est = re.search(r"estimated integration error: mount forces (\S+) of the largest", text)
    assert est is not None and 3e-10 < float(est.group(1)) < 3e-9
    assert list(out.glob("*.mcap")), "demo must write an mcap bag"
    with AnyReader([out], default_typestore=TYPESTORE) as reader:  # counts only: 50k messages
        counts = {c.topic: c.msgcount for c in reader.connections}
    assert counts["/mount_twin/pose"] == counts["/mount_twin/mounts/fl/wrench"] == 5000
    assert counts["/diagnostics"] >= 1


def test_demo_refuses_an_existing_output_with_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["demo", "-o", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("mount-twin: error: ") and f"{tmp_path}: output bag exists" in err


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_generate_half_sine_writes_the_requested_bag(
    tmp_path: Path, storage: str, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "hs"
    rc = main(
        [
            "generate",
            "half-sine",
            "-o",
            str(out),
            "--rate",
            "2000",
            "--duration",
            "0.1",
            "--peak",
            "100.0",
            "--pulse",
            "0.004",
            "--start",
            "5000000000",
            "--storage",
            storage,
            "--topic",
            "/t",
            "--frame-id",
            "f",
        ]
    )
    assert rc == 0
    assert "wrote 200 sensor_msgs/msg/Imu messages on /t" in capsys.readouterr().out
    types, msgs = read_bag(out)
    assert types == {"/t": IMU}
    stamps = [stamp_ns(m) for _, m in msgs["/t"]]
    assert stamps == [5_000_000_000 + k * 500_000 for k in range(200)]
    az = np.array([m.linear_acceleration.z for _, m in msgs["/t"]])
    assert az.max() == pytest.approx(9.80665 + 100.0, abs=1e-9)
    assert {m.header.frame_id for _, m in msgs["/t"]} == {"f"}


def test_import_csv_writes_one_imu_message_per_row(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    csv = tmp_path / "small.csv"
    rows = np.array(
        [
            [0.000, 0.1, 0.2, 9.8, 0.01, 0.02, 0.03],
            [0.001, 0.2, 0.3, 9.9, 0.02, 0.03, 0.04],
            [0.002, -0.1, 0.0, 9.7, 0.0, -0.01, 0.0],
            [0.0035, 1.5, -2.5, 12.25, 0.5, 0.25, -0.125],
        ]
    )
    csv.write_text(
        "t,ax,ay,az,wx,wy,wz\n"
        + "\n".join(",".join(repr(float(v)) for v in r) for r in rows)
        + "\n"
    )
    out = tmp_path / "bag"
    assert main(["import-csv", str(csv), "-o", str(out), "--offset", "1700000000000000000"]) == 0
    assert "wrote 4 sensor_msgs/msg/Imu messages on /deck/imu" in capsys.readouterr().out
    types, msgs = read_bag(out)
    assert types == {"/deck/imu": IMU}
    got = msgs["/deck/imu"]
    assert [stamp_ns(m) for _, m in got] == [
        1_700_000_000_000_000_000 + round(t * 1e9) for t in rows[:, 0]
    ]
    assert {m.header.frame_id for _, m in got} == {"deck_imu"}
    accel = [
        [m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z] for _, m in got
    ]
    gyro = [[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for _, m in got]
    np.testing.assert_array_equal(accel, rows[:, 1:4])
    np.testing.assert_array_equal(gyro, rows[:, 4:7])


def test_import_csv_with_a_wrong_header_exits_2_naming_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    csv = tmp_path / "bad.csv"
    csv.write_text("time,a1,a2,a3\n0.0,1.0,2.0,3.0\n")
    assert main(["import-csv", str(csv), "-o", str(tmp_path / "bag")]) == 2
    err = capsys.readouterr().err
    assert f"{csv}: row 1: no column for ax, ay, az: the header has time, a1, a2, a3" in err
    assert not (tmp_path / "bag").exists()


@pytest.mark.parametrize(
    "command",
    [
        ["generate", "ship-motion", "--duration", "0.01"],
        ["import-csv", "config/sample_shock.csv"],
    ],
    ids=lambda c: c[0],
)
def test_a_bag_writer_refuses_an_existing_output_with_exit_2_and_leaves_it(
    tmp_path: Path, command: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """generate and import-csv, like replay: a clear error, not rosbags' traceback
    (exit 1), and the existing bag as it was."""
    out = tmp_path / "bag"
    assert main(["generate", "ship-motion", "-o", str(out), "--duration", "0.01"]) == 0
    before = {f.name: f.read_bytes() for f in out.iterdir()}
    capsys.readouterr()
    args = [a if not a.startswith("config/") else str(ROOT / a) for a in command]
    assert main([*args, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("mount-twin: error: ") and f"{out}" in err and "exists" in err
    assert {f.name: f.read_bytes() for f in out.iterdir()} == before


@pytest.mark.parametrize(
    "command",
    [
        ["generate", "ship-motion", "--duration", "0.01"],
        ["import-csv", "config/sample_shock.csv"],
        ["replay", "bags/ship_motion_1khz", "--scene", "config/pump_8_mounts.scene.yaml"],
        ["synthesize", "--spectrum", "config/shock_spectrum_vertical.csv", "--seeds", "1"],
    ],
    ids=lambda c: c[0],
)
@pytest.mark.parametrize("where", ["at_the_output", "above_the_output"])
def test_a_dangling_symlink_where_an_output_directory_goes_is_refused_naming_it(
    tmp_path: Path, command: list[str], where: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """A symlink to a missing directory as -o (or above it) read as absent: generate and
    import-csv died with rosbags' traceback (exit 1, "exists already, not overwriting", also
    for the one above), replay and synthesize said "File exists". It is refused naming the
    link and where it points, and left as it was."""
    missing = tmp_path / "missing"
    link = tmp_path / "link"
    link.symlink_to(missing)
    out = link if where == "at_the_output" else link / "bag"
    args = [a if not a.startswith(("config/", "bags/")) else str(ROOT / a) for a in command]
    assert main([*args, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"mount-twin: error: {out}: "), err
    assert f"{link} is a symlink to {missing}, which does not exist" in err
    assert link.is_symlink() and not missing.exists()


def test_import_csv_of_a_missing_file_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["import-csv", str(tmp_path / "none.csv"), "-o", str(tmp_path / "bag")]) == 2
    assert "mount-twin: error:" in capsys.readouterr().err


def test_replay_with_a_bad_scene_path_exits_2_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / "in"
    assert main(["generate", "ship-motion", "-o", str(bag), "--duration", "0.01"]) == 0
    missing = tmp_path / "missing.scene.yaml"
    rc = main(
        ["replay", str(bag), "--scene", str(missing), "-o", str(tmp_path / "out"), "--no-progress"]
    )
    assert rc == 2
    err = capsys.readouterr().err
    assert err.startswith(f"mount-twin: error: {missing}: cannot read")
    assert not (tmp_path / "out").exists()


def test_replay_with_a_bad_scene_value_exits_2_naming_key_and_value(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = _scene_file(tmp_path, hold="cubic")
    rc = main(
        ["replay", str(tmp_path / "whatever"), "--scene", str(scene), "-o", str(tmp_path / "out")]
    )
    assert rc == 2
    assert (
        f"{scene}: input.hold: expected one of first_order, zero_order, got 'cubic'"
        in capsys.readouterr().err
    )


@pytest.mark.parametrize("text", ["", "[1, 2]\n", "input:\n"], ids=["empty", "list", "null"])
def test_a_scene_that_is_no_mapping_exits_2_with_input_flags_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str
) -> None:
    """--topic (and --frame-id) are merged into the file's input: on an empty file, a list or
    a null input that was an AttributeError's traceback and exit 1."""
    scene = tmp_path / "s.scene.yaml"
    scene.write_text(text, encoding="utf-8")
    out = str(tmp_path / "out")
    rc = main(["replay", "whatever", "--scene", str(scene), "--topic", "/deck/imu", "-o", out])
    assert rc == 2
    assert capsys.readouterr().err.startswith(f"mount-twin: error: {scene}")


def test_replay_of_a_bag_without_the_input_topic_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / "in"
    assert (
        main(
            ["generate", "ship-motion", "-o", str(bag), "--duration", "0.01", "--topic", "/other"]
        )
        == 0
    )
    rc = main(
        [
            "replay",
            str(bag),
            "--scene",
            str(SCENE_FILE),
            "-o",
            str(tmp_path / "out"),
            "--no-progress",
        ]
    )
    assert rc == 2
    assert f"{bag}: no topic '/deck/imu'" in capsys.readouterr().err


def test_replay_where_no_sample_is_accepted_exits_3_naming_the_frames(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The bag says imu_link, the scene expects deck_imu: an empty output is no success."""
    bag = tmp_path / "in"
    gen = ["generate", "ship-motion", "-o", str(bag), "--duration", "0.05", "--topic"]
    assert main([*gen, "/deck/imu", "--frame-id", "imu_link"]) == 0
    scene = _scene_file(tmp_path)
    out = ["-o", str(tmp_path / "out"), "--no-progress", "--json", str(tmp_path / "s.json")]
    assert main(["replay", str(bag), "--scene", str(scene), *out]) == 3
    printed = capsys.readouterr()
    assert "no input sample was accepted (50 received" in printed.err
    assert "rejected: wrong_frame 50" in printed.err and "frame_id is 'imu_link'" in printed.err
    # no figures: peaks of 0 N and a utilisation of 0 read as a machine at rest
    assert "motion and mount loads: none, no input sample was accepted" in printed.out
    assert "peak mount loads" not in printed.out and "peak utilisation" not in printed.out
    # nor a latency: the gyro filter is designed at the accepted samples' rate (it read
    # "outputs 0 samples (0.0 ms) after their input", as if they followed it at once)
    assert "  latency: no figure, no input sample was accepted\n" in printed.out
    summary = json.loads((tmp_path / "s.json").read_text(encoding="utf-8"))
    assert summary["max_cg_displacement_from_start_m"] is None
    assert summary["max_tilt_rad"] is None
    assert summary["latency_samples"] is None and summary["latency_s"] is None
    assert {v for m in summary["mounts"].values() for v in m.values()} == {None}


@pytest.mark.parametrize(("fail_on", "code"), [("never", 0), ("warn", 4), ("error", 4)])
def test_replay_fail_on_sets_the_exit_code_by_the_worst_level_of_the_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], fail_on: str, code: int
) -> None:
    """The genset shock opens joints (ERROR): the verdict is the worst level of the run."""
    genset = SCENE_FILE.parent / "genset_bolted_keyed.scene.yaml"
    bag = SCENE_FILE.parents[1] / "bags" / "genset_shock_10khz"
    args = ["replay", str(bag), "--scene", str(genset), "-o", str(tmp_path / "out")]
    assert main([*args, "--no-progress", "--fail-on", fail_on]) == code
    captured = capsys.readouterr()
    assert "diagnostics, worst over the run: ERROR" in captured.out
    assert "ERROR mount_twin: mount foot_fl: " in captured.out
    assert ("diagnostics reached ERROR" in captured.err) == (code == 4)


def test_unknown_subcommand_is_an_argparse_error() -> None:
    with pytest.raises(SystemExit, match="2"):
        main(["fly"])


def test_imported_small_csv_replays_through_a_scene_with_matching_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    n = 400
    t = np.arange(n) / 1000.0
    accel = np.tile([0.0, 0.0, 9.80665], (n, 1))
    accel[100:110, 2] += 50.0
    csv = tmp_path / "shock.csv"
    np.savetxt(
        csv,
        np.column_stack([t, accel, np.zeros((n, 3))]),
        delimiter=",",
        header="t,ax,ay,az,wx,wy,wz",
        comments="",
    )
    bag = tmp_path / "bag"
    assert main(["import-csv", str(csv), "-o", str(bag), "--offset", "1000000000"]) == 0
    scene = _scene_file(tmp_path, topic="/deck/imu", frame_id="deck_imu")
    out = tmp_path / "out"
    assert main(["replay", str(bag), "--scene", str(scene), "-o", str(out), "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert f"{n} received, {n} accepted" in text and "rejected: none" in text
    _, msgs = read_bag(out)
    assert [stamp_ns(m) for _, m in msgs["/mount_twin/pose"]] == [
        1_000_000_000 + k * 1_000_000 for k in range(n)
    ]


def test_water_entry_csv_imports_and_replays(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / "water_entry"
    assert main(["import-csv", str(WATER_ENTRY), "-o", str(bag)]) == 0
    assert "wrote 5000 sensor_msgs/msg/Imu messages on /deck/imu" in capsys.readouterr().out
    # Only the pose is needed here: keep the output small (20 kHz × 10 topics is 50k messages).
    data = yaml.safe_load(SCENE_FILE.read_text(encoding="utf-8"))
    data["input"].update(topic="/deck/imu", frame_id="deck_imu")
    data["outputs"].update(angles=False, wrenches=False, tf=False)
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["replay", str(bag), "--scene", str(scene), "-o", str(out), "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "5000 received, 5000 accepted" in text
    assert "gaps: 0, restarts: 0, integration failures: 0" in text
    _, msgs = read_bag(out)
    pos = np.array(
        [
            [m.pose.position.x, m.pose.position.y, m.pose.position.z]
            for _, m in msgs["/mount_twin/pose"]
        ]
    )
    assert pos.shape == (5000, 3) and np.isfinite(pos).all()
    disp = np.linalg.norm(pos - np.array(data["body"]["cg"]), axis=1).max()
    assert disp < 0.2, f"a 47 g, ms-long shock moved the CG by {disp} m"


def _refused(command: str, target: Path, out: Path, bag: Path | None = None) -> str:
    """Run `command` (bundled paths from the repository root) with X for `target`, OUT for
    `out` and BAG for `bag`, check that it exits 2, and return the long name of the option
    that took X."""
    words = command.split()
    given = {"X": str(target), "OUT": str(out), "BAG": str(bag)}
    args = [given.get(a, str(ROOT / a) if "/" in a else a) for a in words]
    assert main(args) == 2
    flag = words[words.index("X") - 1]
    return {"-o": "--output"}.get(flag, flag)


CALIBRATE = (
    "calibrate test/data/shake_table_1story/block.scene.yaml --foundation "
    "test/data/shake_table_1story/sine_2hz_trial1_ground_excerpt.csv --body "
    "test/data/shake_table_1story/sine_2hz_trial1_top_excerpt.csv -o OUT --plot X"
)


@pytest.mark.parametrize(
    "command",
    [
        "replay bags/ship_motion_1khz --scene config/pump_8_mounts.scene.yaml -o OUT --json X",
        "demo -o OUT --plot X",
        "accuracy config/pump_8_mounts.scene.yaml bags/ship_motion_1khz --csv X",
        "sweep config/sweep_pump.yaml -o OUT --plot X",
        CALIBRATE.replace("-o OUT --plot X", "-o X"),
        "qualify config/genset_bolted_keyed.scene.yaml --plan config/qualify_genset.yaml -o OUT "
        "--report X",
        "report BAG -o X",
    ],
    ids=lambda c: c.split()[0],
)
@pytest.mark.parametrize("where", ["under_a_file", "under_a_dangling_symlink", "symlink"])
def test_a_target_no_file_can_be_written_at_is_refused_before_the_work(
    tmp_path: Path,
    command: str,
    where: str,
    shock_out: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A --json under a file (where its directory goes, or one above it: no directory can be
    made there) or under a symlink to a missing directory: the replay ran to its end, then
    exit 2 (its verdict's exit status lost). So did one through a symlink into a missing
    directory (the link's own directory was checked, not its target's), and `report -o`
    anywhere: it read the bags first."""
    afile, link, missing = tmp_path / "afile", tmp_path / "link", tmp_path / "missing" / "x"
    afile.write_text("not a directory", encoding="utf-8")
    link.symlink_to(missing if where == "symlink" else missing.parent)
    target = {"under_a_file": afile / "a" / "x", "under_a_dangling_symlink": link / "x"}.get(
        where, link
    )

    def unread(*_: object) -> None:
        raise AssertionError("the bag was read before the target was checked")

    monkeypatch.setattr("mount_twin.io.output_tables.read_output_bag", unread)
    flag = _refused(command, target, tmp_path / "out", shock_out)
    err = capsys.readouterr().err
    said = {
        "under_a_file": f"{afile} is not a directory",
        "under_a_dangling_symlink": f"{link} is a symlink to {missing.parent}, which does not "
        "exist",
        "symlink": f"a symlink to {missing}: there is no directory {missing.parent}",
    }[where]
    assert f"mount-twin: error: {flag} {target}: {said}\n" in err
    assert sorted(tmp_path.iterdir()) == [afile, link]
    assert afile.read_text(encoding="utf-8") == "not a directory"


@pytest.mark.parametrize("name", ["figure.txt", "figure"])
@pytest.mark.parametrize(
    "command",
    [
        "replay bags/ship_motion_1khz --scene config/pump_8_mounts.scene.yaml -o OUT --plot X",
        "srs bags/genset_shock_10khz --plot X",
        "show config/pump_8_mounts.scene.yaml -o X",
        "accuracy config/pump_8_mounts.scene.yaml bags/ship_motion_1khz --plot X",
        "sweep config/sweep_pump.yaml -o OUT --plot X",
        CALIBRATE,
    ],
    ids=lambda c: c.split()[0],
)
def test_a_figure_without_a_format_matplotlib_writes_is_refused_before_the_work(
    tmp_path: Path, command: str, name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """`replay --plot x.txt` ran the replay, wrote its bag and JSON, then exited 2 with
    matplotlib's error naming neither the option nor the file; `show -o lay` wrote lay.png and
    printed `layout: lay`."""
    target = tmp_path / name
    flag = _refused(command, target, tmp_path / "out")
    err = capsys.readouterr().err
    assert f"mount-twin: error: {flag} {target}: a figure's file name ends in its format" in err
    assert not list(tmp_path.iterdir())  # neither the output nor the figure


def test_matplotlib_writes_every_figure_format_taken() -> None:
    from matplotlib.backend_bases import FigureCanvasBase

    from mount_twin.commands.common import FIGURE_FORMATS

    assert set(FIGURE_FORMATS) <= set(FigureCanvasBase.get_supported_filetypes())


@pytest.fixture(scope="module")
def shock_out(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An output bag: the pump's replay of the bundled half-sine shock."""
    out = tmp_path_factory.mktemp("shock") / "out"
    args = ["replay", str(ROOT / "bags" / "half_sine_shock_10khz"), "--scene", str(SCENE_FILE)]
    assert main([*args, "-o", str(out), "--no-progress"]) == 0
    return out


FULL = "/dev/full"
"""A device every write to fails with ENOSPC, as on a full disk."""


@pytest.mark.skipif(not Path(FULL).exists(), reason=f"no {FULL}")
@pytest.mark.parametrize(
    "command",
    [
        "replay bags/half_sine_shock_10khz --scene config/pump_8_mounts.scene.yaml -o OUT "
        "--no-progress --json X",
        "srs bags/genset_shock_10khz --json X",
        "srs bags/genset_shock_10khz --csv X",
        "report BAG -o X",
        "dashboard config/pump_8_mounts.scene.yaml --plotjuggler X",
        "dashboard config/pump_8_mounts.scene.yaml --foxglove X",
    ],
    ids=["replay-json", "srs-json", "srs-csv", "report", "plotjuggler", "foxglove"],
)
def test_a_text_output_that_cannot_be_written_exits_2_naming_it(
    tmp_path: Path,
    shock_out: Path,
    command: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Each printed "mount-twin: error: [Errno 28] No space left on device": no file named."""
    monkeypatch.chdir(ROOT)
    args = [
        {"X": FULL, "OUT": str(tmp_path / "out"), "BAG": str(shock_out)}.get(a, a)
        for a in command.split()
    ]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.endswith(f"mount-twin: error: {FULL}: cannot write: No space left on device\n")


LIMITED = (
    "import resource, sys\n"
    "resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))\n"
    "from mount_twin.cli import main\n"
    "sys.exit(main(sys.argv[1:]))\n"
)
"""A mount-twin process that cannot write a file beyond 4 KiB (EFBIG, as a full disk)."""


@pytest.mark.parametrize("existing", [False, True], ids=["new", "replaced"])
def test_an_output_the_disk_cannot_take_is_named_and_leaves_no_part_of_it(
    tmp_path: Path, shock_out: Path, existing: bool
) -> None:
    """A full disk left an 8192-byte r.html and an empty pose.csv, the error naming neither;
    a report that was there is left as it was, not truncated."""
    html, tables = tmp_path / "r.html", tmp_path / "tables"
    if existing:
        tables.mkdir()
        html.write_text("the last report", encoding="utf-8")
        (tables / "pose.csv").write_text("the last pose", encoding="utf-8")
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    report = run_python("-c", LIMITED, "report", str(shock_out), "-o", str(html))
    assert report.returncode == 2, report.stderr
    assert report.stderr.endswith(f"mount-twin: error: {html}: cannot write: File too large\n")
    export = run_python("-c", LIMITED, "export", str(shock_out), "--csv", str(tables))
    assert export.returncode == 2, export.stderr
    pose = tables / "pose.csv"
    assert export.stderr.endswith(f"mount-twin: error: {pose}: cannot write: File too large\n")
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before


def test_a_figure_the_disk_cannot_take_is_named_and_leaves_no_part_of_it(
    tmp_path: Path,
) -> None:
    """`show -o lay.png` on a full disk printed a bare errno, naming no file."""
    png = tmp_path / "lay.png"
    done = run_python("-c", LIMITED, "show", str(SCENE_FILE), "-o", str(png))
    assert done.returncode == 2, done.stderr
    assert done.stderr.endswith(f"mount-twin: error: {png}: cannot write: File too large\n")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    "command",
    [
        "replay bags/half_sine_shock_10khz --scene config/pump_8_mounts.scene.yaml -o OUT "
        "--no-progress --json X",
        "srs bags/genset_shock_10khz --csv X",
        "srs bags/genset_shock_10khz --plot X",
        "report BAG -o X",
        "show config/pump_8_mounts.scene.yaml -o X",
        "dashboard config/pump_8_mounts.scene.yaml --foxglove X",
    ],
    ids=["replay-json", "srs-csv", "srs-plot", "report", "show", "foxglove"],
)
def test_a_file_output_is_written_in_the_directories_it_makes_above_it(
    tmp_path: Path, shock_out: Path, command: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Output directories get the directories missing above them made (`ros2 bag record -o
    a/b/c`), and so does an output file now: `--json a/b/s.json` was refused, "there is no
    directory a/b"."""
    monkeypatch.chdir(ROOT)
    target = tmp_path / "a" / "b" / ("x.png" if "-plot" in command or "show" in command else "x")
    args = [
        {"X": str(target), "OUT": str(tmp_path / "out"), "BAG": str(shock_out)}.get(a, a)
        for a in command.split()
    ]
    assert main(args) == 0
    assert list((tmp_path / "a" / "b").iterdir()) == [target]
    assert target.stat().st_size > 0


@pytest.mark.parametrize(
    ("command", "written"),
    [
        (["report", "BAG", "-o", "X"], "X"),
        (["show", str(SCENE_FILE), "-o", "X.png"], "X.png"),
        (["export", "BAG", "--csv", "X"], "X/pose.csv"),
    ],
    ids=["report", "show", "export"],
)
def test_an_output_the_disk_cannot_take_leaves_no_directory_it_made(
    tmp_path: Path, shock_out: Path, command: list[str], written: str
) -> None:
    """An output in directories missing above it, which the disk cannot take (RLIMIT_FSIZE,
    as a full disk): the error names the file, and the directories made for it are removed
    with it; those that were there stay."""
    (tmp_path / "kept").mkdir()
    target = tmp_path / "kept" / "a" / "b" / "x"
    args = [a.replace("X", str(target)) if "X" in a else a for a in command]
    done = run_python("-c", LIMITED, *[str(shock_out) if a == "BAG" else a for a in args])
    assert done.returncode == 2, done.stderr
    failed = written.replace("X", str(target))
    assert done.stderr.endswith(f"mount-twin: error: {failed}: cannot write: File too large\n")
    assert list(tmp_path.rglob("*")) == [tmp_path / "kept"]


def test_an_output_replaced_keeps_its_mode_and_a_symlink_to_it(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """Written at a new name and renamed into place: the rename must not put a file in place
    of the link, nor a private file (a temporary file's 0600) in place of a shared one; a
    device (no file to rename over) is written to."""
    layout, link = tmp_path / "layout.xml", tmp_path / "link.xml"
    layout.write_text("old", encoding="utf-8")
    layout.chmod(0o640)
    link.symlink_to(layout.name)
    assert main(["dashboard", str(SCENE_FILE), "--plotjuggler", str(link)]) == 0
    assert link.is_symlink() and layout.read_text(encoding="utf-8").startswith("<?xml")
    assert layout.stat().st_mode & 0o777 == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["layout.xml", "link.xml"]
    assert main(["dashboard", str(SCENE_FILE), "--plotjuggler", "/dev/stdout"]) == 0
    assert capfd.readouterr().out.startswith("<?xml")


@pytest.mark.parametrize(
    "command",
    [
        "srs IN/ship_motion_1khz.mcap --csv IN/ship_motion_1khz.mcap",
        "srs IN --json IN/metadata.yaml",
        "report RUN -o RUN/out.mcap",
        "dashboard SCENE --foxglove SCENE",
        "replay IN --scene SCENE -o NEW --no-progress --json SCENE",
        "accuracy SCENE IN --rtol 1e-4 --csv IN/ship_motion_1khz.mcap",
    ],
    ids=["srs-csv", "srs-json", "report", "dashboard", "replay", "accuracy"],
)
def test_an_output_that_would_replace_an_input_is_refused_before_the_work(
    tmp_path: Path, shock_out: Path, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """`srs BAG.mcap --csv BAG.mcap` replaced the recording with its spectrum, `report RUN -o
    RUN/out.mcap` the run with a web page, `dashboard S --foxglove S` the scene with a
    layout: each exit 0, the input lost. Refused naming the option and the input, which is
    left as it was."""
    paths = {
        "IN": tmp_path / "in",
        "RUN": tmp_path / "out",
        "SCENE": tmp_path / "scene.yaml",
        "NEW": tmp_path / "new",
    }
    shutil.copytree(ROOT / "bags" / "ship_motion_1khz", paths["IN"])
    shutil.copytree(shock_out, paths["RUN"])
    shutil.copy(SCENE_FILE, paths["SCENE"])
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    words = command.split()
    parts = [w.partition("/") for w in words]
    args = [str(paths[head]) + sep + tail if head in paths else head for head, sep, tail in parts]
    assert main(args) == 2
    flag = {"-o": "--output"}.get(words[-2], words[-2])
    err = capsys.readouterr().err
    assert err.startswith(f"mount-twin: error: {flag} {args[-1]}: would replace "), err
    assert "which this command reads" in err
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before
    assert not paths["NEW"].exists()


def test_bags_in_directories_named_dot_bag_are_read_like_any_other(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`ros2 bag record -o run.bag` and our own writers make a rosbag2 directory of that name;
    rosbags' AnyReader takes any name ending in .bag for a ROS 1 file, and `info`, `export` and
    `report` failed on it with "Is a directory". 2000 Hz for 0.2 s is 400 samples, each one
    answered by the replay (decimation 1, its gyro delay flushed at the end)."""
    bag, out = tmp_path / "in.bag", tmp_path / "out.bag"
    gen = ["generate", "half-sine", "-o", str(bag), "--rate", "2000", "--duration", "0.2"]
    assert main(gen) == 0
    assert main(["info", str(bag)]) == 0
    assert "messages:  400\n" in capsys.readouterr().out
    main(["replay", "--scene", str(SCENE_FILE), str(bag), "-o", str(out), "--no-progress"])
    assert main(["export", str(out), "--csv", str(tmp_path / "tables")]) == 0
    with (tmp_path / "tables" / "pose.csv").open(encoding="utf-8") as fh:
        assert sum(1 for _ in fh) == 1 + 400
    assert main(["report", str(out), "-o", str(tmp_path / "r.html")]) == 0


def test_replay_makes_the_directories_missing_above_its_output_bag(tmp_path: Path) -> None:
    """`ros2 bag record -o a/b/c` and rosbags' Writer (which generate and import-csv write
    with) make the directories missing above a new bag, as `mkdir -p` does; replay refused
    them ("cannot create the bag"). It makes them; a replay refused before its bag is begun
    (a topic the input does not have) leaves none of them behind."""
    bag = ROOT / "bags" / "half_sine_shock_10khz"
    out = tmp_path / "a" / "b" / "out"
    replay = ["replay", str(bag), "--scene", str(SCENE_FILE), "-o", str(out), "--no-progress"]
    assert main([*replay, "--topic", "/no/such/topic"]) == 2
    assert not (tmp_path / "a").exists()
    assert main(replay) == 0
    assert read_bag(out)  # a readable bag, where it was asked for


def test_generate_failing_before_its_first_message_leaves_no_directory_it_made(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A generate whose first message cannot be written (a full disk) left the bag it had
    begun, empty, and the directories it made above it: a rerun was refused ("output bag
    exists") for a bag holding nothing. Having written nothing, it removes all it made."""
    import errno

    from rosbags.rosbag2 import Writer

    def full(*_: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Writer, "write", full)
    out = tmp_path / "a" / "b" / "out"
    assert main(["generate", "half-sine", "-o", str(out)]) == 2
    assert "No space left on device, after 0 messages" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_synthesize_stopped_removes_the_directories_it_made_above_its_output(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A synthesize that stops before its end removes its unfinished output directory; the
    directories it had made above it (it makes them, `mkdir -p`) stayed, empty."""
    from mount_twin.commands import synthesize

    def stopped(*_: object) -> None:
        raise ValueError("stopped before the first seed")

    monkeypatch.setattr(synthesize, "synthesized", stopped)
    (tmp_path / "kept").mkdir()
    out = tmp_path / "kept" / "a" / "b" / "out"
    spectrum = ROOT / "config" / "shock_spectrum_vertical.csv"
    assert main(["synthesize", "--spectrum", str(spectrum), "-o", str(out)]) == 2
    assert list(tmp_path.iterdir()) == [tmp_path / "kept"]  # what was there stays
    assert list((tmp_path / "kept").iterdir()) == []
