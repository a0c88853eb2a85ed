"""`mount-twin replay` with a body IMU: from the input bag's body_sensor.topic or from another
bag (`--body`), the same messages; the summary and its JSON say what became of the body
IMU's messages and carry the agreement's worst window; a body bag for a scene without a
body_sensor is refused."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from io_helpers import (
    AGEING_PUMP,
    DATA_DIR,
    ageing_bag,
    pump_scene_file,
    read_raw,
    statuses_named,
    unprovided_imu,
)

from mount_twin import load_scene_file
from mount_twin.analysis.ageing_live import NAME as AGEING
from mount_twin.cli import main
from mount_twin.engine.agreement import NAME
from mount_twin.engine.batch import ERROR, OK
from mount_twin.io.messages import IMU
from mount_twin.io.output_bag import OutputBag
from mount_twin.io.output_encoding import imu_messages
from mount_twin.io.signals import ship_motion

RATE = 200.0
STAMP0 = 1_700_000_000_000_000_000
BODY_TOPIC = "/machine/imu"
BODY_OUT = ("/mount_twin/body_imu/predicted", "/mount_twin/body_imu/residual")


def _scene(tmp: Path, body: bool = True) -> Path:
    sensor = {"topic": BODY_TOPIC, "position": [0.8, 0.3, 1.0], "window_s": 2.0}
    return pump_scene_file(tmp, body_sensor=sensor if body else None)


def _streams() -> dict[str, list[tuple[int, bytes]]]:
    """(stamp ns, raw) of 6 s of deck motion and of a body IMU 2 ms after each deck sample."""
    deck = ship_motion(rate_hz=RATE, total=6.0)
    ns = STAMP0 + np.round(deck.t * 1e9).astype(np.int64)
    body = deck.accel + np.random.default_rng(4).normal(0.0, 0.05, deck.accel.shape)
    return {
        "/deck/imu": imu_messages(ns, deck.accel, deck.gyro, "deck_imu"),
        BODY_TOPIC: imu_messages(ns + 2_000_000, body, deck.gyro, ""),
    }


def _bags(tmp: Path) -> None:
    """in_both: deck and body IMU; deck: the deck's alone; body: the body IMU's alone."""
    streams = _streams()
    for name, topics in (("in_both", streams), ("deck", ["/deck/imu"]), ("body", [BODY_TOPIC])):
        with OutputBag(tmp / name, dict.fromkeys(topics, IMU)) as bag:
            bag.write(
                sorted(((t, s, r) for t in topics for s, r in streams[t]), key=lambda m: m[1])
            )


def _replay(tmp: Path, name: str, *extra: str) -> tuple[int, dict]:
    out = tmp / f"out_{name}"
    args = ["replay", str(tmp / name), "--scene", str(_scene(tmp)), "-o", str(out)]
    code = main([*args, "--no-progress", "--json", str(tmp / f"{name}.json"), *extra])
    return code, json.loads((tmp / f"{name}.json").read_text(encoding="utf-8"))


def test_a_body_imu_in_the_bag_or_in_its_own_bag_is_compared_alike(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _bags(tmp_path)
    code, both = _replay(tmp_path, "in_both")
    assert code == 0
    said = capsys.readouterr().out
    assert f"body IMU {BODY_TOPIC}: 1200 received, " in said and NAME in said
    code, apart = _replay(tmp_path, "deck", "--body", str(tmp_path / "body"))
    assert code == 0
    for summary in (both, apart):
        counts = summary["body_sensor"]["counts"]
        assert counts["received"] == counts["accepted"] == 1200
        assert counts["compared"] + counts["unanswered"] == 1200 and counts["compared"] > 1150
        assert NAME in summary["diagnostics_worst"]
    assert both["diagnostics_worst"][NAME] == apart["diagnostics_worst"][NAME]
    got = [read_raw(tmp_path / f"out_{n}") for n in ("in_both", "deck")]
    for topic in BODY_OUT:
        assert len(got[0][topic]) == both["body_sensor"]["counts"]["compared"]
        assert got[0][topic] == got[1][topic]


def _marked_bag(tmp: Path, name: str, marks: dict[str, slice]) -> None:
    """`_streams` into bag `tmp/name`, the body messages `marks[field]` marking that reading
    (linear_acceleration, angular_velocity) not provided (covariance[0] = -1, REP-145)."""
    streams = _streams()
    stamps, raws = (list(a) for a in zip(*streams[BODY_TOPIC], strict=True))
    for field, where in marks.items():
        raws[where] = unprovided_imu(raws[where], field)
    streams[BODY_TOPIC] = list(zip(stamps, raws, strict=True))
    with OutputBag(tmp / name, {"/deck/imu": IMU, BODY_TOPIC: IMU}) as bag:
        bag.write(
            sorted(((t, s, r) for t, m in streams.items() for s, r in m), key=lambda m: m[1])
        )


def test_body_readings_marked_not_provided_are_counted_in_the_summary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """10 body messages whose acceleration and 20 whose rate the IMU marks not provided
    (covariance[0] = -1, REP-145) were rejected, compared on neither reading. Each is now
    compared on the other: the summary's line and its JSON counts say on how many samples each
    reading was compared, and the marks."""
    marks = {"linear_acceleration": slice(300, 310), "angular_velocity": slice(700, 720)}
    _marked_bag(tmp_path, "marked", marks)
    code, summary = _replay(tmp_path, "marked")
    assert code == 0
    counts = summary["body_sensor"]["counts"]
    assert (counts["unprovided_acceleration"], counts["unprovided_angular_velocity"]) == (10, 20)
    assert counts["received"] == counts["accepted"] == 1200
    compared = counts["compared"]
    assert compared + counts["unanswered"] == 1200
    assert (counts["compared_specific_force"], counts["compared_rate"]) == (
        compared - 10,
        compared - 20,
    )
    said = capsys.readouterr().out
    assert (
        f"1200 received, {compared} compared with the twin (specific force on {compared - 10}, "
        f"rate on {compared - 20}; marked not provided: acceleration 10, angular_velocity 20), "
        "not compared: unanswered " in said
    )
    assert len(read_raw(tmp_path / "out_marked")[BODY_OUT[1]]) == compared


def test_an_accelerometer_only_body_imu_is_judged_in_a_replay(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every body message marks its rate not provided (an accelerometer alone): every one was
    rejected, no window judged, the run a WARN saying so. Now every window is judged on the
    specific force on all its samples, its rate said not provided (in its values and message,
    and the worst's in the JSON); the summary's line counts the marks."""
    _marked_bag(tmp_path, "accel_only", {"angular_velocity": slice(None)})
    code, summary = _replay(tmp_path, "accel_only")
    assert code == 0
    counts = summary["body_sensor"]["counts"]
    assert counts["received"] == counts["accepted"] == counts["unprovided_angular_velocity"]
    assert counts["compared_specific_force"] == counts["compared"] > 1150
    assert counts["compared_rate"] == counts["rejected_no_reading"] == 0
    windows = statuses_named(
        [r for _, r in read_raw(tmp_path / "out_accel_only")["/diagnostics"]], NAME
    )
    assert len(windows) == 3  # of 2 s over 6 s
    for _, _, message, values in windows:
        n = values["samples"]
        assert values["samples_specific_force"] == n and values["samples_rate"] == "0"
        assert all(values[f"nrms_{a}"] == "not judged" for a in ("wx", "wy", "wz"))
        assert all(values[f"nrms_broadband_{a}"] == "n/a" for a in ("wx", "wy", "wz"))
        assert any(values[f"nrms_{a}"] != "not judged" for a in ("fx", "fy", "fz"))
        assert f"; rate not judged: not provided in {n} of {n} samples" in message
    assert sum(int(v["samples"]) for *_, v in windows) == counts["compared"]
    worst = summary["diagnostics_worst"][NAME]["message"]
    assert worst.startswith("model and machine ") and "rate not judged" in worst
    said = capsys.readouterr().out
    assert f"(specific force on {counts['compared']}, rate on 0; marked not provided: " in said


def test_without_the_body_topic_the_summary_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _bags(tmp_path)
    code, summary = _replay(tmp_path, "deck")
    assert code == 0
    assert f"body IMU {BODY_TOPIC}: no message" in capsys.readouterr().out
    assert summary["body_sensor"]["counts"].get("received", 0) == 0


def test_a_body_imu_never_compared_is_a_warning_not_silence(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every body message of another frame_id: no window was ever judged, so no status said
    anything, and the run read OK."""
    _bags(tmp_path)
    sensor = {"topic": BODY_TOPIC, "frame_id": "machine_imu", "position": [0.8, 0.3, 1.0]}
    scene = pump_scene_file(tmp_path, body_sensor=sensor)
    out, doc = tmp_path / "out", tmp_path / "s.json"
    args = ["replay", str(tmp_path / "in_both"), "--scene", str(scene), "-o", str(out)]
    assert main([*args, "--no-progress", "--json", str(doc)]) == 0
    summary = json.loads(doc.read_text(encoding="utf-8"))
    status = summary["diagnostics_worst"][NAME]
    assert summary["verdict"] == status["level"] == "WARN"
    assert status["message"].startswith("no window of the body IMU was judged over the run: ")
    assert "0 of 1200 messages compared" in status["message"]
    assert "rejected_wrong_frame_id 1200" in status["message"]
    said = capsys.readouterr().out  # the summary's line, in words (it printed a Python dict)
    assert (
        f"body IMU {BODY_TOPIC}: 1200 received, 0 compared with the twin, not compared: "
        "rejected_wrong_frame_id 1200 (its agreement:" in said
    )


def test_a_body_bag_for_a_scene_without_a_body_sensor_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _bags(tmp_path)
    args = ["replay", str(tmp_path / "deck"), "--scene", str(_scene(tmp_path, body=False))]
    code = main([*args, "-o", str(tmp_path / "o"), "--body", str(tmp_path / "body")])
    assert code == 2
    assert "no body_sensor" in capsys.readouterr().err


def test_mounts_that_age_are_tracked_window_by_window(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """With an `ageing` section (windows of 20 s), a replay re-fits the mounts' stiffness and
    damping window by window on the bag's deck and body IMU: the window before the mounts lose
    30 % of their stiffness (at 22 s) is OK, the one after an ERROR reading stiffness ×0.70
    (within 2 %), and the run's verdict is ERROR."""
    scene_path = pump_scene_file(tmp_path, **AGEING_PUMP)
    ageing_bag(tmp_path / "in", load_scene_file(scene_path), 42.5, 22.0, BODY_TOPIC)
    out = tmp_path / "out"
    args = ["replay", str(tmp_path / "in"), "--scene", str(scene_path), "-o", str(out)]
    assert main([*args, "--no-progress"]) == 0
    assert "verdict: ERROR" in capsys.readouterr().out
    raws = [raw for _, raw in read_raw(out)["/diagnostics"]]
    windows = [(s[1], s[3]) for s in statuses_named(raws, AGEING)]
    assert [level for level, _ in windows] == [OK, ERROR]
    assert [v["window_start_s"] for _, v in windows] == ["2.000", "22.000"]
    assert float(windows[0][1]["stiffness"]) == pytest.approx(1.0, abs=0.01)
    assert float(windows[1][1]["stiffness"]) == pytest.approx(0.7, rel=0.02)


def test_the_real_pair_calibrated_on_one_run_agrees_live_on_the_other(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The shake table's measured pair (Xsens DOT exports, imported to bags): calibrated on
    sine trial 1, the replay of trial 2 with its block IMU agrees along the shaking direction
    (fx, the axis the one-DOF scene judges: normalised RMS in 0-10 Hz below 0.1, every window
    OK), where the notebook's values disagree (above 0.2)."""
    shake = DATA_DIR / "shake_table_1story"
    scene = shake / "block.scene.yaml"
    calibrated = tmp_path / "calibrated.scene.yaml"
    pair = [str(shake / f"sine_2hz_trial1_{s}_excerpt.csv") for s in ("ground", "top")]
    args = ["calibrate", str(scene), "--foundation", pair[0], "--body", pair[1]]
    assert main([*args, "-o", str(calibrated)]) == 0
    for side, topic, frame in (
        ("ground", "/deck/imu", "table_imu"),
        ("top", BODY_TOPIC, "block_imu"),
    ):
        csv = str(shake / f"sine_2hz_trial2_{side}_excerpt.csv")
        out = str(tmp_path / side)
        assert main(["import-csv", csv, "-o", out, "--topic", topic, "--frame-id", frame]) == 0
    worst = {}
    for name, path in (("nominal", scene), ("calibrated", calibrated)):
        out = tmp_path / f"out_{name}"
        args = ["replay", str(tmp_path / "ground"), "--topic", "/deck/imu", "--scene", str(path)]
        assert main([*args, "-o", str(out), "--body", str(tmp_path / "top"), "--no-progress"]) == 0
        raws = [raw for _, raw in read_raw(out)["/diagnostics"]]
        windows = statuses_named(raws, NAME)
        assert windows and all(v["nrms_fy"] == "not judged" for _, _, _, v in windows)
        worst[name] = (
            max(lv for _, lv, _, _ in windows),
            max(float(v["nrms_fx"]) for *_, v in windows),
        )
    capsys.readouterr()
    assert worst["calibrated"][0] == OK and worst["calibrated"][1] < 0.1
    assert worst["nominal"][1] > 0.2


def test_the_body_imu_comparison_is_exported_and_plotted(tmp_path: Path) -> None:
    """`export` writes the prediction and the residual as tables (specific force m/s², rate
    rad/s, one row per compared sample); `replay --plot` adds the measured specific force
    against the twin's."""
    _bags(tmp_path)
    code, summary = _replay(tmp_path, "in_both", "--plot", str(tmp_path / "p.png"))
    assert code == 0 and (tmp_path / "p.png").stat().st_size > 20_000
    assert main(["export", str(tmp_path / "out_in_both"), "--csv", str(tmp_path / "csv")]) == 0
    compared = summary["body_sensor"]["counts"]["compared"]
    for name in ("body_imu_predicted", "body_imu_residual"):
        lines = (tmp_path / "csv" / f"{name}.csv").read_text(encoding="utf-8").splitlines()
        assert lines[0].split(",")[2:] == [
            "fx_m_s2",
            "fy_m_s2",
            "fz_m_s2",
            "wx_rad_s",
            "wy_rad_s",
            "wz_rad_s",
        ]
        assert len(lines) == 1 + compared


def test_a_bag_played_in_a_loop_is_compared_on_every_loop(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A recording of `ros2 bag play --loop`: both streams' header stamps jump back 6 s after
    the first 6 s (log times rising). The twin restarted, the body check did not: every body
    message of the second loop was rejected stamp_back. Now the body comparison restarts with
    the twin: the second loop's windows read the first's figures, and the restart is counted
    (the summary's line and JSON, the windows' values)."""
    streams = _streams()
    loops = [(t, s + k * 6_005_000_000, r) for k in (0, 1) for t in streams for s, r in streams[t]]
    with OutputBag(tmp_path / "looped", {"/deck/imu": IMU, BODY_TOPIC: IMU}) as bag:
        bag.write(sorted(loops, key=lambda m: m[1]))
    code, summary = _replay(tmp_path, "looped")
    assert code == 0
    counts = summary["body_sensor"]["counts"]
    assert counts["received"] == counts["accepted"] == 2400
    assert counts["rejected_stamp_back"] == 0 and counts["reset_stamp_jumped_back"] == 1
    assert counts["compared"] + counts["unanswered"] == 2400 and counts["compared"] > 2350
    said = capsys.readouterr().out
    assert "; its stamps jumped back 1×, the comparison restarted (its agreement: " in said
    raws = [raw for _, raw in read_raw(tmp_path / "out_looped")["/diagnostics"]]
    reset = "body_reset_stamp_jumped_back"  # the loop, in the order of stamps
    windows = sorted(statuses_named(raws, NAME), key=lambda w: (w[3][reset], w[0]))
    assert len(windows) == 6  # of 2 s over each loop's 6 s
    assert [v[reset] for *_, v in windows] == ["0"] * 3 + ["1"] * 3
    for (_, level, _, first), (_, again, _, second) in zip(windows[:3], windows[3:], strict=True):
        assert again == level == OK
        assert {k: v for k, v in second.items() if k != reset} == {
            k: v for k, v in first.items() if k != reset
        }


def test_a_stop_while_the_body_imus_rest_is_replayed_ends_it_at_the_next_chunk(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A body IMU bag running 5 s past the input's 1 s, replayed in chunks of 100 messages:
    the body's first two chunks (to 0.997 s) go in beside the input's, its ten others after
    the input's end. A stop (Ctrl-C, noted by the command line) while the first of those is
    compared ended the replay only once all ten were read and compared (no stop was looked
    at between them: a long body bag held a Ctrl-C for its whole length). Now the replay
    stops before the next: three body chunks taken in all, KeyboardInterrupt, the output
    bag marked partial."""
    from mount_twin.io.bag_metadata import partial_marker
    from mount_twin.replay import replay
    from mount_twin.stream import TwinStream

    streams = _streams()
    with OutputBag(tmp_path / "deck", {"/deck/imu": IMU}) as bag:
        bag.write([("/deck/imu", s, r) for s, r in streams["/deck/imu"][:200]])  # 0–0.995 s
    with OutputBag(tmp_path / "body", {BODY_TOPIC: IMU}) as bag:
        bag.write([(BODY_TOPIC, s, r) for s, r in streams[BODY_TOPIC]])  # 1200: 0.002–5.997 s
    calls = []
    process_body = TwinStream.process_body

    def counted(stream: TwinStream, raws: list[bytes]) -> list[tuple[str, int, bytes]]:
        calls.append(len(raws))
        return process_body(stream, raws)

    def checkpoint() -> None:
        if len(calls) >= 3:  # a stop noted while the third body chunk was compared
            raise KeyboardInterrupt

    monkeypatch.setattr(TwinStream, "process_body", counted)
    scene = load_scene_file(_scene(tmp_path))
    with pytest.raises(KeyboardInterrupt):
        replay(
            scene,
            tmp_path / "deck",
            tmp_path / "out",
            chunk=100,
            progress=False,
            checkpoint=checkpoint,
            body_path=tmp_path / "body",
        )
    assert calls == [100, 100, 100]
    assert partial_marker(tmp_path / "out").startswith("stopped by KeyboardInterrupt")
