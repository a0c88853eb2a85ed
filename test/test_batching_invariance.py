"""Output never depends on how the input is batched, on the scenes where that is hardest.

The bundled genset switches (bolted joints slip and open, keys close) and runs `auto`, which
ends a compiled run at a stiffening event to look at the scene again; with the deck rotating,
the gyro conditioning carries state across those stops. One batch, one sample per push and
ragged pieces must give the same numbers bit for bit, and the same events, counts and method
choices (a live node's batches are whatever its executor delivers); replays of every bundled
bag in chunks of 7 and of 100000 messages write the same bags.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from io_helpers import ROOT, comparable_messages, push_all, read_raw, scene_with, split, stamp_ns

from mount_twin.engine.batch import OutputBatch, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.input_samples import read_samples
from mount_twin.io.messages import IMU, TYPESTORE
from mount_twin.io.output_bag import write_bag
from mount_twin.model.assemble import assemble
from mount_twin.replay import replay
from mount_twin.scene import load_scene_file

GENSET = ROOT / "config" / "genset_bolted_keyed.scene.yaml"


def _rolling_shock() -> SampleBatch:
    """The bundled genset shock record with the deck rolling and pitching (rad/s)."""
    scene = load_scene_file(GENSET)
    b = read_samples(ROOT / "bags" / "genset_shock_10khz", scene.input)
    t = b.stamps - b.stamps[0]
    b.gyro[:, 0] += 0.4 * np.sin(2.0 * np.pi * 30.0 * t)
    b.gyro[:, 1] += 0.2 * np.sin(2.0 * np.pi * 12.0 * t + 0.3)
    return b


def _run(pieces: list[int] | None) -> tuple[OutputBatch, TwinEngine]:
    scene = load_scene_file(GENSET)
    assert scene.integration.method == "auto" and scene.input.gyro_filter != "none"
    engine = TwinEngine(assemble(scene))
    full = _rolling_shock()
    joined, _ = push_all(engine, [full] if pieces is None else split(full, pieces))
    return joined, engine


@pytest.fixture(scope="module")
def reference() -> tuple[OutputBatch, TwinEngine]:
    return _run(None)


@pytest.mark.parametrize(
    "pieces",
    [[1] * 2500, [7] * 400, [3, 1, 50, 7, 200, 1, 1, 99, 238, 1000, 13]],
    ids=["one_sample_each", "sevens", "ragged"],
)
def test_a_switching_rotating_scene_gives_the_same_bits_in_any_batching(
    reference: tuple[OutputBatch, TwinEngine], pieces: list[int]
) -> None:
    want, ref_engine = reference
    stiffening = [e for e in ref_engine.events if ref_engine.stiffens(e)]
    assert len(stiffening) >= 2, "the record must make auto look again mid-run"
    got, engine = _run(pieces)
    np.testing.assert_array_equal(got.stamps, want.stamps)
    np.testing.assert_array_equal(got.pose, want.pose)
    np.testing.assert_array_equal(got.wrenches, want.wrenches)
    assert engine.events == ref_engine.events
    assert engine.counts == ref_engine.counts
    assert engine.health.method == ref_engine.health.method
    np.testing.assert_array_equal(engine.state, ref_engine.state)


@pytest.mark.parametrize(
    ("scene_file", "bag"),
    [
        ("genset_bolted_keyed.scene.yaml", "genset_shock_10khz"),
        ("pump_8_mounts.scene.yaml", "ship_motion_1khz"),
        ("pump_8_mounts.scene.yaml", "half_sine_shock_10khz"),
    ],
)
def test_replays_in_chunks_of_7_and_100000_write_the_same_bags(
    tmp_path: Path, scene_file: str, bag: str
) -> None:
    scene = load_scene_file(ROOT / "config" / scene_file)
    bags = {}
    for chunk in (7, 100_000):
        out = tmp_path / f"out_{chunk}"
        replay(scene, ROOT / "bags" / bag, out, chunk=chunk, progress=False)
        bags[chunk] = comparable_messages(out)
    assert bags[7].keys() == bags[100_000].keys()
    for topic, messages in bags[100_000].items():
        assert bags[7][topic] == messages, f"{topic} differs between chunks of 7 and 100000"


def _without_wall_time(reports: list) -> list:
    """(stamp, sample, rows, statuses) of each report, the wall-clock figures left out."""
    return [
        (
            r.stamp,
            r.sample,
            r.rows,
            [
                (
                    s.name,
                    s.level,
                    s.message,
                    {k: v for k, v in s.values.items() if k != "real_time_factor"},
                )
                for s in r.statuses
            ],
        )
        for r in reports
    ]


def _held_at_the_end() -> SampleBatch:
    """1 s of the pump's ship motion whose last stamp jumps: held back, then never confirmed."""
    scene = load_scene_file(ROOT / "config" / "pump_8_mounts.scene.yaml")
    b = read_samples(ROOT / "bags" / "ship_motion_1khz", scene.input)
    b = SampleBatch(b.stamps[:1000].copy(), b.accel[:1000], b.gyro[:1000], b.frame_ids[:1000])
    b.stamps[-1] += 0.05
    return b


def _never_accepted() -> SampleBatch:
    """Readings that are all NaN: received, none accepted (the final report says ENDED)."""
    t = np.arange(20) * 1e-3
    nan = np.full((20, 3), np.nan)
    return SampleBatch(t, nan, nan, ["deck_imu"] * 20)


@pytest.mark.parametrize(
    ("scene_file", "record"),
    [
        ("genset_bolted_keyed.scene.yaml", _rolling_shock),
        ("pump_8_mounts.scene.yaml", _held_at_the_end),
        ("pump_8_mounts.scene.yaml", _never_accepted),
    ],
    ids=["genset_rolling_shock", "pump_held_at_the_end", "never_accepted"],
)
def test_run_in_one_frame_equals_a_push_then_a_flush(scene_file: str, record) -> None:
    """`run` drains the gyro delay into the push's own frame: the same rows, reports and
    counts as `push` then `flush`, joined."""
    samples = record()
    model = assemble(load_scene_file(ROOT / "config" / scene_file))
    a, b = TwinEngine(model), TwinEngine(model)
    got = a.run(samples)
    want = b.push(samples).then(b.flush(), len(samples))
    for field in ("stamps", "sample", "pose", "wrenches"):
        np.testing.assert_array_equal(getattr(got, field), getattr(want, field), err_msg=field)
    assert got.health and _without_wall_time(got.health) == _without_wall_time(want.health)
    assert a.counts == b.counts


def _alike_in_chunks(scene, bag: Path, tmp_path: Path) -> dict:
    """The output bag of `bag` replayed in chunks of 100000 (`comparable_messages`), checked to
    be the same in chunks of 1 and 7."""
    bags = {}
    for chunk in (1, 7, 100_000):
        out = tmp_path / f"out_{chunk}"
        replay(scene, bag, out, chunk=chunk, progress=False)
        bags[chunk] = comparable_messages(out)
    for chunk in (1, 7):
        assert bags[chunk] == bags[100_000], f"chunks of {chunk} differ from one of 100000"
    return bags[100_000]


def test_messages_the_engine_cannot_take_count_where_they_came_in_any_chunking(
    tmp_path: Path,
) -> None:
    """Messages that are not valid CDR, or carry an unset stamp, are counted at their place in
    the stream, between the samples around them: replays in chunks of 1, 7 and 100000 write the
    same bags, and no period reads them as samples lost. Counted before a batch's push, all of
    a batch's were credited to its first interval and period (a live node reported 94 then 91
    rejected for the same stream, and ~3 samples lost where none was)."""
    scene = load_scene_file(ROOT / "config" / "pump_8_mounts.scene.yaml")
    (msgs,) = read_raw(ROOT / "bags" / "ship_motion_1khz", ["/deck/imu"]).values()
    msgs = msgs[:2500]
    garbage = list(range(100, 2500, 10))
    for i in garbage:
        msgs[i] = (msgs[i][0], bytes(204))  # not a valid Imu
    zero = 1005  # header.stamp unset
    msg = TYPESTORE.deserialize_cdr(msgs[zero][1], IMU)
    msg.header.stamp.sec = msg.header.stamp.nanosec = 0
    msgs[zero] = (msgs[zero][0], bytes(TYPESTORE.serialize_cdr(msg, IMU)))
    bag = tmp_path / "bad"
    write_bag(bag, "/deck/imu", IMU, iter(msgs))
    whole = _alike_in_chunks(scene, bag, tmp_path)
    inputs = [
        dict(values)
        for _, statuses in whole["/diagnostics"]
        for name, _, _, values in statuses
        if name == "mount_twin: input"
    ]
    assert int(inputs[-1]["rejected_undecodable"]) == len(garbage)
    assert int(inputs[-1]["rejected_zero_stamp"]) == 1
    assert all(int(v["lost_estimated"]) == 0 for v in inputs)


def test_a_decimated_replay_publishes_each_runs_last_sample_at_its_stamp_in_any_chunking(
    tmp_path: Path,
) -> None:
    """With outputs.decimation 7, a run's last sample is published at its end (a restart
    after a gap of rejected samples, the end of the bag) with the peaks since the row before:
    at its own input stamp, in the same bytes whether it was pushed 600 messages before the
    restart (chunks of 1) or in the same push."""
    scene = load_scene_file(ROOT / "config" / "pump_8_mounts.scene.yaml")
    scene = scene_with(scene, outputs={"decimation": 7})
    (msgs,) = read_raw(ROOT / "bags" / "ship_motion_1khz", ["/deck/imu"]).values()
    msgs = msgs[:2500]
    for i in range(1200, 1800):  # another sensor's frame: rejected, then a gap resets
        msg = TYPESTORE.deserialize_cdr(msgs[i][1], IMU)
        msg.header.frame_id = "another_imu"
        msgs[i] = (msgs[i][0], bytes(TYPESTORE.serialize_cdr(msg, IMU)))
    bag = tmp_path / "rejected_stretch"
    write_bag(bag, "/deck/imu", IMU, iter(msgs))
    stamps = [stamp_ns(TYPESTORE.deserialize_cdr(raw, IMU)) for _, raw in msgs]
    whole = _alike_in_chunks(scene, bag, tmp_path)
    (pose_topic,) = [t for t in whole if t.endswith("/pose")]
    published = [stamp for stamp, _ in whole[pose_topic]]
    # each run: its start, every 7th sample after it, and its last (1199 before the
    # restart at 1800, 2499 at the end; neither is a 7th)
    rows = [*range(0, 1200, 7), 1199, *range(1800, 2500, 7), 2499]
    assert published == [stamps[i] for i in rows]
