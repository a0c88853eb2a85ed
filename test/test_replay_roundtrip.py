"""Bag in → replay → bag out, read back with rosbags; the live (per-message) path gives the same.

Input bags are generated with the CLI (`generate ship-motion`) in mcap and sqlite3.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from io_helpers import ROOT, read_bag, read_raw, scene_with, stamp_ns

from mount_twin.cli import main
from mount_twin.errors import BagError
from mount_twin.io.input_decoding import decode_inputs
from mount_twin.io.messages import DIAGNOSTICS, IMU, NODE_NAME, POSE, TF, VECTOR3, WRENCH, resolve
from mount_twin.io.scene_record import STRING
from mount_twin.replay import replay
from mount_twin.stream import TwinStream

DURATION = 0.5
PERIOD = 0.1  # diagnostics period, s: several reports in 0.5 s of stamps


def _scene():
    return scene_with(outputs={"diagnostics_period_s": PERIOD})


@pytest.fixture(scope="module")
def bags(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Input bags (mcap, sqlite3) of the same ship motion, and their replayed outputs."""
    d = tmp_path_factory.mktemp("replay")
    paths: dict[str, Path] = {}
    for storage in ("mcap", "sqlite3"):
        src = d / f"in_{storage}"
        rc = main(
            [
                "generate",
                "ship-motion",
                "-o",
                str(src),
                "--topic",
                "/deck/imu",
                "--frame-id",
                "deck_imu",
                "--duration",
                str(DURATION),
                "--storage",
                storage,
            ]
        )
        assert rc == 0, f"generate --storage {storage} failed"
        dst = d / f"out_{storage}"
        summary = replay(_scene(), src, dst, progress=False)
        assert summary.counts["accepted"] == 500
        paths[f"in_{storage}"], paths[f"out_{storage}"] = src, dst
    return paths


@pytest.fixture(scope="module")
def input_stamps(bags: dict[str, Path]) -> list[int]:
    types, msgs = read_bag(bags["in_mcap"])
    assert types == {"/deck/imu": IMU}
    return [stamp_ns(m) for _, m in msgs["/deck/imu"]]


def expected_types() -> dict[str, str]:
    scene = _scene()
    types = {
        f"/{NODE_NAME}/pose": POSE,
        f"/{NODE_NAME}/angles": VECTOR3,
        "/diagnostics": DIAGNOSTICS,
        "/tf": TF,
        "/tf_static": TF,
        f"/{NODE_NAME}/scene": STRING,
    }
    types.update({f"/{NODE_NAME}/mounts/{m.name}/wrench": WRENCH for m in scene.mounts})
    return types


def header_stamps(msg) -> list[int]:
    """header.stamp (ns) of a message, or of each transform of a TFMessage."""
    if hasattr(msg, "transforms"):
        return [stamp_ns(t) for t in msg.transforms]
    return [stamp_ns(msg)]


def test_generated_input_bags_hold_the_requested_imu_messages(bags: dict[str, Path]) -> None:
    for storage in ("mcap", "sqlite3"):
        types, msgs = read_bag(bags[f"in_{storage}"])
        assert types == {"/deck/imu": IMU}
        assert len(msgs["/deck/imu"]) == 500
        assert {m.header.frame_id for _, m in msgs["/deck/imu"]} == {"deck_imu"}
        assert [t for t, _ in msgs["/deck/imu"]] == [stamp_ns(m) for _, m in msgs["/deck/imu"]]
    assert (bags["in_sqlite3"] / "in_sqlite3.db3").exists() or list(
        bags["in_sqlite3"].glob("*.db3")
    )
    assert list(bags["in_mcap"].glob("*.mcap"))


def test_replay_writes_every_output_topic_with_its_type(bags: dict[str, Path]) -> None:
    types, msgs = read_bag(bags["out_mcap"])
    assert types == expected_types()
    for topic in expected_types():
        assert msgs.get(topic), f"no messages on {topic}"


def test_each_output_topic_carries_the_input_stamps(
    bags: dict[str, Path], input_stamps: list[int]
) -> None:
    _, msgs = read_bag(bags["out_mcap"])
    for topic in expected_types():
        if topic == "/tf_static":  # once, before the outputs, at the first input stamp
            ((log_time, static),) = msgs[topic]
            assert log_time == input_stamps[0]
            assert set(header_stamps(static)) == {input_stamps[0]}
            continue
        if topic == f"/{NODE_NAME}/scene":  # the same, with no header
            ((log_time, _),) = msgs[topic]
            assert log_time == input_stamps[0]
            continue
        got = [s for _, m in msgs[topic] for s in header_stamps(m)]
        assert [t for t, _ in msgs[topic]] == got, f"{topic}: log time must equal header.stamp"
        if topic == "/diagnostics":
            assert set(got) <= set(input_stamps), "diagnostics must be stamped with an input stamp"
        else:
            assert got == input_stamps, f"{topic}: stamps differ from the input header stamps"


def test_output_frames_are_the_foundation_and_the_mount_names(bags: dict[str, Path]) -> None:
    scene = _scene()
    _, msgs = read_bag(bags["out_mcap"])
    for topic in (f"/{NODE_NAME}/pose", f"/{NODE_NAME}/angles"):
        assert {m.header.frame_id for _, m in msgs[topic]} == {scene.frames.foundation}
    for mount in scene.mounts:
        assert {
            m.header.frame_id for _, m in msgs[f"/{NODE_NAME}/mounts/{mount.name}/wrench"]
        } == {mount.name}


def test_replayed_values_are_finite_and_plausible(bags: dict[str, Path]) -> None:
    scene = _scene()
    _, msgs = read_bag(bags["out_mcap"])
    pos = np.array(
        [
            [m.pose.position.x, m.pose.position.y, m.pose.position.z]
            for _, m in msgs[f"/{NODE_NAME}/pose"]
        ]
    )
    quat = np.array(
        [
            [
                m.pose.orientation.x,
                m.pose.orientation.y,
                m.pose.orientation.z,
                m.pose.orientation.w,
            ]
            for _, m in msgs[f"/{NODE_NAME}/pose"]
        ]
    )
    assert np.isfinite(pos).all() and np.isfinite(quat).all()
    np.testing.assert_allclose(np.linalg.norm(quat, axis=1), 1.0, rtol=0, atol=1e-12)
    assert np.abs(pos - np.array(scene.body.cg)).max() < 0.01, (
        "ship motion moves the CG by mm, not cm"
    )
    for _, m in msgs["/diagnostics"]:
        assert all(s.level == 0 for s in m.status), [(s.name, s.message) for s in m.status]


def test_mcap_and_sqlite3_inputs_give_identical_outputs(bags: dict[str, Path]) -> None:
    a, b = read_raw(bags["out_mcap"]), read_raw(bags["out_sqlite3"])
    assert sorted(a) == sorted(b)
    for topic in a:
        if topic == "/diagnostics":  # carries the wall-clock real-time factor
            assert [t for t, _ in a[topic]] == [t for t, _ in b[topic]]
        else:
            assert a[topic] == b[topic], f"{topic} differs between mcap and sqlite3 input"


def _live(bag: Path) -> tuple[TwinStream, list[tuple[str, int, bytes]]]:
    """What the node would publish: each raw message through TwinStream.process on its own."""
    raws = [raw for _, raw in read_raw(bag, ["/deck/imu"])["/deck/imu"]]
    stream = TwinStream(_scene())
    out: list[tuple[str, int, bytes]] = []
    for raw in raws:
        out.extend((resolve(t, NODE_NAME), s, d) for t, s, d in stream.process([raw]))
    out.extend((resolve(t, NODE_NAME), s, d) for t, s, d in stream.finish())  # at shutdown
    return stream, out


def test_live_one_message_at_a_time_equals_the_chunked_replay(bags: dict[str, Path]) -> None:
    _, live = _live(bags["in_mcap"])
    replayed = read_raw(bags["out_mcap"])
    pose_live = decode_poses([d for t, _, d in live if t == f"/{NODE_NAME}/pose"])
    pose_bag = decode_poses([d for _, d in replayed[f"/{NODE_NAME}/pose"]])
    np.testing.assert_allclose(pose_live, pose_bag, rtol=0, atol=1e-12)
    for topic in expected_types():
        if topic in ("/diagnostics", "/tf_static", f"/{NODE_NAME}/scene"):  # the node's own
            continue
        live_topic = [(s, d) for t, s, d in live if t == topic]
        assert live_topic == replayed[topic], f"{topic}: live bytes differ from the replayed bag"


def test_the_last_partial_diagnostics_period_is_written_at_the_last_stamp(
    bags: dict[str, Path],
) -> None:
    """A bag rarely ends on a period boundary: what happened after the last report (a bolt
    breaking, say) must still reach /diagnostics, stamped with the last sample answered."""
    out = read_raw(bags["out_mcap"])
    last_pose = out[f"/{NODE_NAME}/pose"][-1][0]
    assert out["/diagnostics"][-1][0] == last_pose
    stream, _ = _live(bags["in_mcap"])
    assert stream.finish() == [], "nothing new after the final report"


def test_replay_writes_diagnostics_at_the_live_cadence(bags: dict[str, Path]) -> None:
    """/diagnostics in a replayed bag should be what the node publishes for the same input
    (one report per diagnostics_period_s of stamps), whatever the replay chunk size."""
    _, live = _live(bags["in_mcap"])
    live_stamps = [s for t, s, _ in live if t == "/diagnostics"]
    bag_stamps = [t for t, _ in read_raw(bags["out_mcap"], ["/diagnostics"])["/diagnostics"]]
    assert len(live_stamps) >= int(DURATION / PERIOD) - 1
    assert bag_stamps == live_stamps, (
        f"replay wrote {len(bag_stamps)} diagnostics, the live path {len(live_stamps)} for "
        f"{DURATION} s at diagnostics_period_s={PERIOD}: the cadence must not depend on the "
        "replay's chunk size"
    )


def decode_poses(raws: list[bytes]) -> np.ndarray:
    from mount_twin.io.messages import TYPESTORE

    rows = []
    for raw in raws:
        m = TYPESTORE.deserialize_cdr(raw, POSE)
        p, q = m.pose.position, m.pose.orientation
        rows.append([p.x, p.y, p.z, q.x, q.y, q.z, q.w])
    return np.array(rows)


def test_replay_summary_reports_counts_and_real_time_factor(
    bags: dict[str, Path], tmp_path: Path
) -> None:
    summary = replay(_scene(), bags["in_sqlite3"], tmp_path / "out", progress=False)
    assert summary.counts["received"] == summary.counts["accepted"] == 500
    assert summary.written == 500 * (3 + 8) + 2 + len(  # 2: /tf_static, ~/scene
        read_raw(tmp_path / "out", ["/diagnostics"]).get("/diagnostics", [])
    )
    assert summary.stamp_span_s == pytest.approx(0.499, abs=1e-9)
    text = summary.text()
    assert "real-time factor" in text and "500 received, 500 accepted" in text
    assert set(summary.peaks) == {m.name for m in _scene().mounts}
    assert 0.0 < summary.displacement_max_m < 0.01


# --------------------------------------------------------------------------- errors


def test_wrong_input_topic_names_the_bag_and_the_topic(
    bags: dict[str, Path], tmp_path: Path
) -> None:
    scene = scene_with(_scene(), input={"topic": "/imu/data"})
    with pytest.raises(
        BagError,
        match=rf"{bags['in_mcap']}: no topic '/imu/data' \(input\.topic; `replay --topic` "
        r"overrides it\); the bag has: /deck/imu \(sensor_msgs/msg/Imu, 500 messages\)",
    ):
        replay(scene, bags["in_mcap"], tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists(), "no output bag may be left behind"


def test_wrong_input_type_names_the_bag_topic_and_both_types(
    bags: dict[str, Path], tmp_path: Path
) -> None:
    scene = scene_with(_scene(), input={"msg_type": "geometry_msgs/msg/AccelStamped"})
    with pytest.raises(
        BagError,
        match=rf"{bags['in_sqlite3']}: topic '/deck/imu' has type sensor_msgs/msg/Imu, "
        r"input\.msg_type says geometry_msgs/msg/AccelStamped",
    ):
        replay(scene, bags["in_sqlite3"], tmp_path / "out", progress=False)


def test_existing_output_path_is_refused_and_left_alone(
    bags: dict[str, Path], tmp_path: Path
) -> None:
    out = tmp_path / "taken"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    with pytest.raises(BagError, match=rf"{out}: output bag exists"):
        replay(_scene(), bags["in_mcap"], out, progress=False)
    assert [p.name for p in out.iterdir()] == ["keep.txt"]


def test_missing_input_bag_is_a_bag_error_naming_it(tmp_path: Path) -> None:
    missing = tmp_path / "no_such_bag"
    with pytest.raises(BagError, match=rf"{missing}: cannot open bag"):
        replay(_scene(), missing, tmp_path / "out", progress=False)


def test_input_samples_decoded_from_the_bag_match_the_generator(bags: dict[str, Path]) -> None:
    from mount_twin.io.signals import ship_motion

    raws = [raw for _, raw in read_raw(bags["in_sqlite3"], ["/deck/imu"])["/deck/imu"]]
    dec = decode_inputs(raws, IMU)
    sig = ship_motion(rate_hz=1000.0, total=DURATION)
    np.testing.assert_array_equal(dec.accel, sig.accel)
    np.testing.assert_array_equal(dec.gyro, sig.gyro)
    np.testing.assert_array_equal(
        dec.stamps_ns - dec.stamps_ns[0], np.arange(500, dtype=np.int64) * 1_000_000
    )


def test_replay_plot_of_a_run_without_mount_events_is_drawn(
    bags: dict[str, Path], tmp_path: Path
) -> None:
    """The pump on linear mounts logs no event: its empty events table has no first stamp
    (the plot's time origin once took one from every table and raised IndexError)."""
    scene = ROOT / "config/pump_8_mounts.scene.yaml"
    png = tmp_path / "run.png"
    args = ["replay", str(bags["in_mcap"]), "--scene", str(scene), "-o", str(tmp_path / "out")]
    assert main([*args, "--no-progress", "--plot", str(png)]) == 0
    assert png.stat().st_size > 10_000


def test_a_chunk_below_one_message_is_refused_before_anything_is_opened(
    bags: dict[str, Path], tmp_path: Path
) -> None:
    """0 had looped for ever on empty chunks (the command line refuses it at parse); 2.5 made
    the output bag, then failed in a slice, leaving it behind marked partial."""
    for chunk in (0, 2.5):
        with pytest.raises(
            ValueError, match=f"chunk: must be an integer ≥ 1 message, got {chunk}"
        ):
            replay(_scene(), bags["in_mcap"], tmp_path / "out", chunk=chunk, progress=False)
        assert not (tmp_path / "out").exists()
    with pytest.raises(TypeError, match=r"replay\(scene\): got a str, expected a Scene"):
        replay("pump.scene.yaml", bags["in_mcap"], tmp_path / "out", progress=False)
