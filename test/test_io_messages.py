"""Messages ↔ engine data through the Jazzy typestore: decoding, encoding, time base, frames."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest
from io_helpers import REST, G, batch, default_scene, engine_for, scene_with, stamp_ns

from mount_twin.engine.batch import ERROR, OK, WARN, HealthReport, HealthStatus, OutputBatch
from mount_twin.engine.intake import Intake
from mount_twin.io.input_decoding import TimeBase, decode_inputs
from mount_twin.io.messages import (
    ACCEL,
    DIAGNOSTICS,
    IMU,
    POSE,
    TF,
    TYPESTORE,
    VECTOR3,
    WRENCH,
    resolve,
)
from mount_twin.io.output_encoding import encode_outputs, imu_messages
from mount_twin.io.output_topics import (
    ANGLES_OUTPUT,
    OUTPUTS,
    WRENCHES_OUTPUT,
    output_streams,
    output_table,
    output_types,
)
from mount_twin.stream import TwinStream

T = TYPESTORE.types
START_NS = 1_700_000_000_123_456_789


def accel_messages(stamps: np.ndarray, linear: np.ndarray, frame_id: str) -> list[bytes]:
    out = []
    for stamp, a in zip(stamps.tolist(), linear, strict=True):
        sec, nanosec = divmod(stamp, 1_000_000_000)
        header = T["std_msgs/msg/Header"](
            stamp=T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec), frame_id=frame_id
        )
        vec = T["geometry_msgs/msg/Vector3"]
        accel = T["geometry_msgs/msg/Accel"](
            linear=vec(x=float(a[0]), y=float(a[1]), z=float(a[2])),
            angular=vec(x=0.5, y=0.5, z=0.5),
        )
        out.append(bytes(TYPESTORE.serialize_cdr(T[ACCEL](header=header, accel=accel), ACCEL)))
    return out


def rng_signal(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    stamps = START_NS + np.cumsum(rng.integers(900_000, 1_100_000, n)).astype(np.int64)
    accel = REST + rng.normal(0.0, 0.5, (n, 3))
    gyro = rng.normal(0.0, 0.05, (n, 3))
    return stamps, accel, gyro


# --------------------------------------------------------------------------- decoding


def test_imu_messages_decode_back_to_the_same_stamps_vectors_and_frames() -> None:
    stamps, accel, gyro = rng_signal(50)
    raws = [raw for _, raw in imu_messages(stamps, accel, gyro, "deck_imu")]
    dec = decode_inputs(raws, IMU)
    assert dec.undecodable == 0
    np.testing.assert_array_equal(dec.stamps_ns, stamps)
    np.testing.assert_array_equal(dec.accel, accel)  # float64 through CDR: bit exact
    np.testing.assert_array_equal(dec.gyro, gyro)
    assert dec.frame_ids == ["deck_imu"] * 50


@pytest.mark.parametrize("n", [1, 2, 5, 8, 9, 24, 25])
def test_a_wake_ups_few_messages_decode_as_rosbags_reads_them(n: int) -> None:
    """A live wake-up's few messages are read one by one against the last layout: each must
    give what rosbags reads from it, each reading marked not provided (-1: the first's
    acceleration, the last's angular velocity) marked so, and a message of another frame_id
    among them decoded too."""
    stamps, accel, gyro = rng_signal(n)
    unprovided = np.zeros((n, 2), bool)
    unprovided[0, 0] = unprovided[-1, 1] = True
    decode_inputs(
        [raw for _, raw in imu_messages(stamps[:1], accel[:1], gyro[:1], "deck_imu")], IMU
    )
    for frames in (["deck_imu"] * n, ["deck_imu"] * (n - 1) + ["other"]):
        raws = [
            raw
            for i, frame in enumerate(frames)
            for _, raw in imu_messages(
                stamps[i : i + 1], accel[i : i + 1], gyro[i : i + 1], frame, unprovided[i : i + 1]
            )
        ]
        truth = [TYPESTORE.deserialize_cdr(raw, IMU) for raw in raws]
        dec = decode_inputs(raws, IMU)
        assert dec.undecodable == 0 and dec.frame_ids == [m.header.frame_id for m in truth]
        np.testing.assert_array_equal(
            dec.stamps_ns, [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in truth]
        )
        a = [
            [m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z]
            for m in truth
        ]
        w = [[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for m in truth]
        np.testing.assert_array_equal(dec.accel, a)
        np.testing.assert_array_equal(dec.gyro, w)
        np.testing.assert_array_equal(dec.stamps_ns, stamps)
        assert dec.unprovided is not None
        np.testing.assert_array_equal(dec.unprovided, unprovided)
        assert dec.accel.flags.c_contiguous and dec.gyro.flags.c_contiguous


@pytest.mark.parametrize(("n", "through_rosbags"), [(1, 0), (9, 0), (24, 0), (25, 1)])
def test_a_wake_up_of_up_to_24_messages_is_read_without_rosbags(
    monkeypatch: pytest.MonkeyPatch, n: int, through_rosbags: int
) -> None:
    """rosbags' decode of a call's first message and the numpy pass after it cost as much as
    reading 26-28 Imu messages one by one (`python3 bench/bench_decode.py`): a wake-up of up to
    24 messages of the frame_id last seen is read one by one, rosbags never called; one of 25
    in bulk, rosbags reading its first message (the same values either way: the test above)."""
    stamps, accel, gyro = rng_signal(n)
    raws = [raw for _, raw in imu_messages(stamps, accel, gyro, "deck_imu")]
    decode_inputs(raws[:1], IMU)  # the frame_id seen
    calls = []
    deserialize = TYPESTORE.deserialize_cdr

    def counted(raw: Any, msgtype: str) -> Any:
        calls.append(msgtype)
        return deserialize(raw, msgtype)

    monkeypatch.setattr(TYPESTORE, "deserialize_cdr", counted)
    dec = decode_inputs(raws, IMU)
    np.testing.assert_array_equal(dec.stamps_ns, stamps)
    assert len(calls) == through_rosbags


def test_a_second_sensors_messages_are_read_one_by_one_too(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A body IMU's calls alternate with the deck's, each of the other frame_id than the one
    last seen: each call went in bulk (rosbags reading its first message), and before that
    tried all its messages against the wrong layout (a pair of calls of 16 took 1.6× the CPU
    of a decode that tried none). The frame_ids recently seen are tried on the first message
    alone: once both sensors have been seen, neither call reaches rosbags, each tries one
    wrong layout at most, and every message decodes to its own frame_id and stamp."""
    from mount_twin.io import fixed_layout, input_decoding

    stamps, accel, gyro = rng_signal(16)
    deck = [raw for _, raw in imu_messages(stamps, accel, gyro, "deck_imu")]
    body = [raw for _, raw in imu_messages(stamps, accel, gyro, "body_imu")]
    monkeypatch.setattr(input_decoding, "_RECENT_FRAMES", {})
    decode_inputs(deck, IMU)
    decode_inputs(body, IMU)  # both seen, the body's the latest
    tried, calls = [], []
    unpack_one, deserialize = fixed_layout.FixedLayout.unpack_one, TYPESTORE.deserialize_cdr

    def counted(self: Any, raw: Any, want: Any) -> Any:
        one = unpack_one(self, raw, want)
        tried.append(one is not None)
        return one

    def counted_rosbags(raw: Any, msgtype: str) -> Any:
        calls.append(msgtype)
        return deserialize(raw, msgtype)

    monkeypatch.setattr(fixed_layout.FixedLayout, "unpack_one", counted)
    monkeypatch.setattr(TYPESTORE, "deserialize_cdr", counted_rosbags)
    for raws, frame in [(deck, "deck_imu"), (body, "body_imu")] * 2:
        dec = decode_inputs(raws, IMU)
        assert dec.frame_ids == [frame] * 16
        np.testing.assert_array_equal(dec.stamps_ns, stamps)
    assert calls == []
    wrong = tried.count(False)
    assert wrong <= 4  # one wrong layout a call at most, on its first message
    assert len(tried) == 4 * 16 + wrong


def _scans(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    """Count the layouts probed and the rows their unpacks scan (FixedLayout's), from no
    layout known (the messages to decode made before: their making probes layouts)."""
    from mount_twin.io import fixed_layout, input_decoding, messages

    seen = {"rows": 0, "probes": 0}
    unpack, probe = fixed_layout.FixedLayout.unpack, fixed_layout.FixedLayout.probe.__func__

    def counted_unpack(self: Any, raws: Any, want: Any) -> Any:
        seen["rows"] += len(raws)
        return unpack(self, raws, want)

    def counted_probe(cls: Any, *args: Any) -> Any:
        seen["probes"] += 1
        return probe(cls, *args)

    monkeypatch.setattr(fixed_layout.FixedLayout, "unpack", counted_unpack)
    monkeypatch.setattr(fixed_layout.FixedLayout, "probe", classmethod(counted_probe))
    messages.layout_of.cache_clear()
    monkeypatch.setattr(input_decoding, "_RECENT_FRAMES", {})
    return seen


def _one_frame_each(frame_ids: list[str]) -> tuple[np.ndarray, list[bytes]]:
    """Imu messages at rest, 1 ms apart, one per frame id: their stamps (ns) and bytes."""
    stamps = START_NS + np.arange(len(frame_ids), dtype=np.int64) * 1_000_000
    raws = [
        raw
        for stamp, frame_id in zip(stamps, frame_ids, strict=True)
        for _, raw in imu_messages(stamp[None], REST[None], np.zeros((1, 3)), frame_id)
    ]
    return stamps, raws


def test_a_frame_id_in_every_message_decodes_in_linear_time(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Each new frame_id's layout scanned every message still pending: 1000 messages with
    distinct ids of 100 000 characters took 57 s to decode (one batch of a live node). Now at
    most 4 × the messages are scanned; every message still decodes to its own frame id."""
    ids = [f"f{i:05d}" for i in range(3000)]
    stamps, raws = _one_frame_each(ids)
    seen = _scans(monkeypatch)
    dec = decode_inputs(raws, IMU)
    assert dec.frame_ids == ids and dec.undecodable == 0
    np.testing.assert_array_equal(dec.stamps_ns, stamps)
    assert seen["rows"] <= 4 * 3000
    # three sensors interleaved on one topic still go through their layouts, one scan each
    three = [("a", "bb", "ccc")[i % 3] for i in range(3000)]
    stamps, raws = _one_frame_each(three)
    seen = _scans(monkeypatch)
    dec = decode_inputs(raws, IMU)
    assert dec.frame_ids == three
    np.testing.assert_array_equal(dec.stamps_ns, stamps)
    assert seen["rows"] == 3000 + 2000 + 1000  # each layout scans its message and the rest


def test_a_frame_id_no_sensor_has_is_decoded_without_a_layout(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A 100 000-character frame_id was probed (serialized twice) and its layout cached, 256
    of them held; now such messages are decoded by rosbags alone, one by one or batched."""
    ids = [f"{i:03d}" + "x" * 100_000 for i in range(20)]
    _, raws = _one_frame_each(ids)
    seen = _scans(monkeypatch)
    for chunk in ([raws], [[r] for r in raws]):
        frames = [f for part in chunk for f in decode_inputs(part, IMU).frame_ids]
        assert frames == ids
    assert seen["probes"] == 0


def test_imu_messages_say_no_orientation_estimate() -> None:
    ((_, raw),) = imu_messages(np.array([START_NS]), REST[None], np.zeros((1, 3)), "f")
    msg = TYPESTORE.deserialize_cdr(raw, IMU)
    assert msg.orientation_covariance[0] == -1.0
    assert (msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w) == (
        0.0,
        0.0,
        0.0,
        1.0,
    )


def test_accel_stamped_decodes_linear_acceleration_and_no_rate() -> None:
    stamps, accel, _ = rng_signal(20)
    dec = decode_inputs(accel_messages(stamps, accel, "deck_imu"), ACCEL)
    assert dec.undecodable == 0
    np.testing.assert_array_equal(dec.stamps_ns, stamps)
    np.testing.assert_array_equal(dec.accel, accel)
    np.testing.assert_array_equal(dec.gyro, np.zeros((20, 3)))  # accel.angular is not a rate


def test_undecodable_bytes_are_counted_not_raised() -> None:
    stamps, accel, gyro = rng_signal(4)
    good = [raw for _, raw in imu_messages(stamps, accel, gyro, "deck_imu")]
    raws = [good[0], b"", b"\x00\x01\x00\x00garbage", good[1], good[2][:20], good[3]]
    dec = decode_inputs(raws, IMU)
    assert dec.undecodable == 3
    np.testing.assert_array_equal(dec.stamps_ns, stamps[[0, 1, 3]])
    assert len(dec.frame_ids) == 3
    np.testing.assert_array_equal(dec.accel, accel[[0, 1, 3]])


def test_stream_counts_undecodable_messages_and_warns_on_diagnostics() -> None:
    scene = scene_with(outputs={"diagnostics_period_s": 0.01})
    stream = TwinStream(scene)
    stamps, accel, gyro = rng_signal(40)
    raws = [raw for _, raw in imu_messages(stamps, accel, gyro, "deck_imu")]
    first = stream.process(raws[:20])
    second = stream.process([b"not cdr", *raws[20:]])
    counts = stream.engine.counts
    assert (counts["received"], counts["accepted"], counts["rejected_undecodable"]) == (41, 40, 1)
    assert len(first) > 0 and len(second) > 0
    reports = stream.last_outputs.health
    assert len(reports) >= 1
    inputs = [s for r in reports for s in r.statuses if s.name == "mount_twin: input"]
    assert [s.level for s in inputs] == [WARN] + [OK] * (len(inputs) - 1), "WARN once, then OK"
    assert inputs[0].message == "1 samples rejected, 0 gaps in this period"
    assert inputs[0].values["rejected_undecodable"] == "1"


def test_stream_with_only_undecodable_input_outputs_nothing() -> None:
    stream = TwinStream(default_scene())
    assert stream.process([b"x", b"y"]) == []
    assert stream.engine.counts["rejected_undecodable"] == 2


# --------------------------------------------------------------------------- gravity


def test_accel_stamped_without_gravity_gets_g_added_on_z_of_f() -> None:
    n = 300
    stamps = START_NS + np.arange(n, dtype=np.int64) * 1_000_000
    rng = np.random.default_rng(3)
    motion = rng.normal(0.0, 0.3, (n, 3))  # foundation acceleration, gravity removed
    imu_scene = scene_with(outputs={"diagnostics_period_s": 100.0})
    accel_scene = scene_with(
        input={"msg_type": ACCEL, "includes_gravity": False, "g": G},
        outputs={"diagnostics_period_s": 100.0},
    )
    imu_raws = [
        raw for _, raw in imu_messages(stamps, motion + REST, np.zeros((n, 3)), "deck_imu")
    ]
    acc_raws = accel_messages(stamps, motion, "deck_imu")
    imu_out = TwinStream(imu_scene)
    acc_out = TwinStream(accel_scene)
    imu_msgs = imu_out.process(imu_raws)
    acc_msgs = acc_out.process(acc_raws)
    poses = [(imu_out.last_outputs.pose, acc_out.last_outputs.pose)]
    imu_msgs += imu_out.finish()  # the end: the rows the gyro delay holds
    acc_msgs += acc_out.finish()
    poses.append((imu_out.last_outputs.pose, acc_out.last_outputs.pose))
    # pose, angles, /tf, 8 wrenches per sample, then the final report
    assert len(imu_msgs) == len(acc_msgs) == n * (3 + 8) + 1
    np.testing.assert_allclose(
        np.concatenate([acc for _, acc in poses]),
        np.concatenate([imu for imu, _ in poses]),
        rtol=0,
        atol=1e-12,
        err_msg="AccelStamped + g on z must move the twin exactly as Imu with gravity included",
    )


def test_includes_gravity_false_uses_the_configured_g() -> None:
    lunar = 1.62
    scene = scene_with(input={"includes_gravity": False, "g": lunar})
    engine = engine_for(scene)
    intake = Intake(engine.model, engine.health, engine.counts)
    f, _, _ = intake.screen(batch([0.0, 0.001], accel=np.zeros((2, 3))))
    np.testing.assert_array_equal(f, [[0.0, 0.0, lunar]] * 2)


# --------------------------------------------------------------------------- time base


@pytest.mark.parametrize(
    "span_s", [1.0, 3600.0, 86400.0, 7 * 86400.0], ids=["1s", "1h", "1day", "1week"]
)
def test_time_base_resolves_sample_intervals(span_s: float) -> None:
    """The engine integrates over float-second intervals: a week in, 1 kHz intervals must still be
    exact to well under a nanosecond (an epoch stamp in float64 would be off by ~0.1 µs)."""
    rng = np.random.default_rng(7)
    stamps = START_NS + np.sort(rng.integers(0, int(span_s * 1e9), 100_000)).astype(np.int64)
    base = TimeBase.at(int(stamps[0]))
    assert base.origin_ns % 1_000_000_000 == 0 and 0 <= stamps[0] - base.origin_ns < 1_000_000_000
    err = np.abs(np.diff(base.seconds(stamps)) - np.diff(stamps) * 1e-9)
    assert err.max() < 2.5e-10


def test_stream_output_stamps_stay_exact_for_a_node_running_a_year() -> None:
    """A live node keeps the base of its first message; outputs a year later (float seconds
    there resolve only ~4 ns) must still carry the input stamps to the nanosecond."""
    year_ns = 365 * 86400 * 1_000_000_000
    stream = TwinStream(scene_with(outputs={"diagnostics_period_s": 100.0}))
    first, accel, gyro = rng_signal(1)
    stream.process([raw for _, raw in imu_messages(first, accel, gyro, "deck_imu")])
    stamps, accel, gyro = rng_signal(300, seed=2)
    stamps = stamps + year_ns + np.arange(300) * 3  # odd ns everywhere
    msgs = stream.process([raw for _, raw in imu_messages(stamps, accel, gyro, "deck_imu")])
    msgs += stream.finish()  # the end: the rows the gyro delay holds
    assert stream.engine.counts["gaps"] == 1  # the year between them: a restart, not a failure
    pose_stamps = [s for topic, s, _ in msgs if topic == "~/pose"]
    assert pose_stamps == [*first.tolist(), *stamps.tolist()]  # the first: at the restart


def test_stream_output_stamps_equal_input_stamps_exactly() -> None:
    stamps, accel, gyro = rng_signal(200)
    stream = TwinStream(scene_with(outputs={"diagnostics_period_s": 100.0}))
    msgs = stream.process([raw for _, raw in imu_messages(stamps, accel, gyro, "deck_imu")])
    msgs += stream.finish()  # the end: the rows the gyro delay holds
    pose_stamps = [s for topic, s, _ in msgs if topic == "~/pose"]
    assert pose_stamps == stamps.tolist()


# --------------------------------------------------------------------------- encoding


def _one_row_batch(scene, stamp_s: float = 0.25, health=None) -> OutputBatch:
    nm = len(scene.mounts)
    pose = np.array(
        [[0.051, -0.002, 0.498, 0.001, 0.002, 0.003, np.sqrt(1 - 14e-6), 0.002, 0.004, 0.006]]
    )
    wrenches = np.arange(nm * 6, dtype=float).reshape(1, nm, 6) * 1.5 - 20.0
    return OutputBatch(np.array([stamp_s]), np.array([0]), pose, wrenches, health or [])


@pytest.mark.parametrize("n_rows", [1, 3, 9])  # a live sample, a live wake-up's few, a block
def test_encoded_outputs_have_the_right_topics_types_frames_and_values(n_rows: int) -> None:
    scene = default_scene()
    one = _one_row_batch(scene, stamp_s=0.123456789)
    k = np.arange(n_rows)
    want = START_NS + 123_456_789 + k * 1_000_001
    out = OutputBatch(
        one.stamps + k * 1.000001e-3,
        k,
        one.pose + k[:, None] * 1e-3,
        one.wrenches - k[:, None, None] * 3.0,
        [],
    )
    msgs = encode_outputs(scene, out, want)
    wrench_topics = [f"~/mounts/{m.name}/wrench" for m in scene.mounts]
    types = output_types(scene)
    assert [t for t, _, _ in msgs] == ["~/pose", "~/angles", *wrench_topics, "/tf"] * n_rows
    for j, (topic, stamp, raw) in enumerate(msgs):
        row = j // (len(wrench_topics) + 3)
        want_ns = int(want[row])
        msg = TYPESTORE.deserialize_cdr(raw, types[topic])
        stamped = msg.transforms[0] if types[topic] == TF else msg
        assert stamp == want_ns and stamp_ns(stamped) == want_ns
        if topic == "~/pose":
            assert (
                types[topic] == POSE and msg.header.frame_id == scene.frames.foundation == "deck"
            )
            p, q = msg.pose.position, msg.pose.orientation
            assert [p.x, p.y, p.z, q.x, q.y, q.z, q.w] == out.pose[row, :7].tolist()
        elif topic == "~/angles":
            assert types[topic] == VECTOR3 and msg.header.frame_id == "deck"
            assert [msg.vector.x, msg.vector.y, msg.vector.z] == out.pose[row, 7:].tolist()
        elif topic == "/tf":
            assert types[topic] == TF and len(msg.transforms) == 1
            tf = msg.transforms[0]
            assert (tf.header.frame_id, tf.child_frame_id) == ("deck", "pump")
            p, q = tf.transform.translation, tf.transform.rotation
            assert [p.x, p.y, p.z, q.x, q.y, q.z, q.w] == out.pose[row, :7].tolist()
        else:
            i = wrench_topics.index(topic)
            assert types[topic] == WRENCH and msg.header.frame_id == scene.mounts[i].name
            f, c = msg.wrench.force, msg.wrench.torque
            assert [f.x, f.y, f.z, c.x, c.y, c.z] == out.wrenches[row, i].tolist()


def test_the_output_registry_has_one_entry_per_output_flag_of_a_scene() -> None:
    """A registry entry without its scene flag (or a flag without an entry) fails here."""
    flags = {
        f.name for f in dataclasses.fields(default_scene().outputs) if isinstance(f.default, bool)
    }
    assert len(OUTPUTS) == len(flags) and {out.flag for out in OUTPUTS} == flags
    for out in OUTPUTS:
        only = scene_with(outputs={k: k == out.flag for k in flags})
        names = [(st.topic, st.msgtype, st.frames) for st in output_streams(only)]
        assert names == [(st.topic, st.msgtype, st.frames) for st in out.streams(only)]
        assert names  # every flag brings at least one topic


@pytest.mark.parametrize(
    ("change", "says"),
    [
        ({"flag": "accel"}, r"output 'accel' \(~/angles\): no switch 'accel' in scene\.outputs"),
        ({"msgtype": "geometry_msgs/msg/TwistStamped"}, r"no builder for geometry_msgs/msg/Twist"),
        ({"fields": ("vector.x", "vector.y")}, r"3 columns but 2 fields to read them from"),
        (
            {"fields": ("vector.x", "vector.y", "vector.w")},
            r"Vector3Stamped has no field vector\.w",
        ),
        ({"table": None}, r"a table needs columns, and columns a table"),
        ({"table": "angles_{mount}"}, r"the table and the topic must both name \{mount\}"),
    ],
)
def test_an_output_registered_half_way_fails_at_import_naming_what_is_missing(
    change: dict, says: str
) -> None:
    """A new quantity declared without its scene switch, its message builder or a readable
    field is refused when the registry is built, not when a bag is read back wrong."""
    with pytest.raises(ValueError, match=says):
        dataclasses.replace(ANGLES_OUTPUT, **change)


def test_a_bag_is_read_back_by_the_registry_not_by_message_type() -> None:
    """Each topic is filed under its output's table with its declared columns: a Vector3Stamped
    on another topic (a quantity added later, another node's) is not mixed into `angles`, and a
    mount named like a table is still a mount."""
    scene = default_scene()
    for st in output_streams(scene):
        resolved = resolve(st.topic, "mount_twin")
        found = output_table(resolved, st.msgtype)
        for out in OUTPUTS:
            assert len(out.fields) == len(out.columns)
        if st.table is None:
            assert found is None
        else:
            assert found is not None and found[0] == st.table
    assert output_table("/mount_twin/angles", VECTOR3) == ("angles", ANGLES_OUTPUT)
    assert output_table("/mount_twin/accel", VECTOR3) is None
    assert output_table("/mount_twin/angles", WRENCH) is None
    assert output_table("/ns/twin/mounts/pose/wrench", WRENCH) == ("mount_pose", WRENCHES_OUTPUT)
    assert output_table("/mount_twin/mounts/a/b/wrench", WRENCH) is None


def test_output_names_resolve_under_the_node_name_and_namespace() -> None:
    scene = default_scene()
    topics = list(output_types(scene))
    assert [resolve(t, "mount_twin") for t in topics] == [
        "/diagnostics",
        "/mount_twin/pose",
        "/mount_twin/angles",
        *(f"/mount_twin/mounts/{m.name}/wrench" for m in scene.mounts),
        "/tf",
    ]
    assert resolve("/diagnostics", "mount_twin", "/ship") == "/diagnostics"
    assert resolve("~/pose", "mount_twin", "/ship/") == "/ship/mount_twin/pose"
    assert resolve("rel", "mount_twin", "/ship") == "/ship/rel"


def test_disabled_outputs_are_neither_encoded_nor_declared() -> None:
    scene = scene_with(outputs={"pose": False, "wrenches": False, "tf": False})
    msgs = encode_outputs(scene, _one_row_batch(scene), np.array([START_NS]))
    assert [t for t, _, _ in msgs] == ["~/angles"]
    assert output_types(scene) == {"/diagnostics": DIAGNOSTICS, "~/angles": VECTOR3}


def test_diagnostics_are_encoded_with_levels_names_and_values() -> None:
    scene = default_scene()
    report = HealthReport(
        0.25,
        0,
        [
            HealthStatus("mount_twin: input", WARN, "2 samples rejected", {"received": "10"}),
            HealthStatus("mount_twin: integration", ERROR, "failed", {}),
            HealthStatus("mount_twin: attitude", OK, "ok", {"tilt_max_rad": "0.01"}),
        ],
        rows=1,  # due after the batch's one row
    )
    msgs = encode_outputs(scene, _one_row_batch(scene, 0.25, [report]), np.array([START_NS]))
    diag = [(s, raw) for t, s, raw in msgs if t == "/diagnostics"]
    assert len(diag) == 1
    stamp, raw = diag[0]
    assert stamp == START_NS
    assert msgs[-1][0] == "/diagnostics", "a report follows the outputs of the sample it is due at"
    msg = TYPESTORE.deserialize_cdr(raw, DIAGNOSTICS)
    assert stamp_ns(msg) == stamp
    assert [(s.name, s.level, s.message, s.hardware_id) for s in msg.status] == [
        ("mount_twin: input", WARN, "2 samples rejected", "mount_twin"),
        ("mount_twin: integration", ERROR, "failed", "mount_twin"),
        ("mount_twin: attitude", OK, "ok", "mount_twin"),
    ]
    assert [(kv.key, kv.value) for kv in msg.status[0].values] == [("received", "10")]
