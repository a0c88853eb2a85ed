"""One stamp glitched forward costs that one sample: the sample after a stamp jump is held until
the next one says whether the jump was real (a hole: taken) or a glitch (rejected)."""

from __future__ import annotations

import numpy as np
import pytest
from io_helpers import batch, default_scene, engine_for, split

from mount_twin.engine.batch import OutputBatch
from mount_twin.io.output_encoding import imu_messages
from mount_twin.stream import TwinStream

N, DT, K = 1500, 1e-3, 400  # samples, s, the glitched one
RNG = np.random.default_rng(7)
ACCEL = np.array([0.0, 0.0, 9.80665]) + RNG.normal(0.0, 0.3, (N, 3))
GYRO = RNG.normal(0.0, 0.01, (N, 3))
STAMPS = 1.0 + np.arange(N) * DT


def _push_all(stamps: np.ndarray, keep: np.ndarray | None = None, sizes=None) -> tuple:
    keep = np.ones(N, dtype=bool) if keep is None else keep
    engine = engine_for()
    b = batch(stamps[keep], ACCEL[keep], GYRO[keep])
    outs = [engine.push(part) for part in (split(b, sizes) if sizes else [b])]
    return engine, [*outs, engine.flush()]  # the flush: the rows the gyro delay holds


def _rows(outs: list[OutputBatch]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (
        np.concatenate([o.stamps for o in outs]),
        np.concatenate([o.pose for o in outs]),
        np.concatenate([o.wrenches for o in outs]),
    )


@pytest.mark.parametrize("jump_s", [0.003, 0.018, 0.3, 0.99, 2.5])
def test_a_glitched_stamp_costs_one_sample_and_the_rest_is_as_if_it_were_absent(
    jump_s: float,
) -> None:
    """3 and 18 intervals, 0.3 s (within max_gap_s), 0.99 s (a gap) and 2.5 s (a gap, and
    further than back_jump_reset_s): before, 2, 17, 299 and 989 valid samples were dropped or
    restarted."""
    glitched = STAMPS.copy()
    glitched[K] += jump_s
    engine, outs = _push_all(glitched)
    without = np.arange(N) != K
    _, ref = _push_all(STAMPS, without)
    for got, want in zip(_rows(outs), _rows(ref), strict=True):
        np.testing.assert_array_equal(got, want)
    c = engine.counts
    assert (c["received"], c["accepted"], c["rejected_stamp_glitch"]) == (N, N - 1, 1)
    assert c["restarts"] == 0 and c["gaps"] == 0


@pytest.mark.parametrize("sizes", [[1] * N, [K, 1, 5], [K + 1, 7], [K - 1, 1, 1, 300]])
def test_a_glitch_held_across_pushes_gives_the_same_numbers(sizes: list[int]) -> None:
    glitched = STAMPS.copy()
    glitched[K] += 0.3
    _, whole = _push_all(glitched)
    engine, parts = _push_all(glitched, sizes=sizes)
    for got, want in zip(_rows(parts), _rows(whole), strict=True):
        np.testing.assert_array_equal(got, want)
    assert engine.counts["rejected_stamp_glitch"] == 1


def test_a_real_hole_is_taken_after_one_sample_of_delay() -> None:
    """Samples K..K+299 lost (a 0.3 s hole): the sample after it is held until the next one
    confirms the jump, then both are taken; pushed one by one, its row comes once the gyro
    delay (N samples) has passed, as sample −N of that push, stamped with its own stamp."""
    keep = (np.arange(N) < K) | (np.arange(N) >= K + 300)
    engine, whole = _push_all(STAMPS, keep)
    assert engine.counts["accepted"] == keep.sum()
    assert engine.counts["rejected_stamp_glitch"] == 0
    _, parts = _push_all(STAMPS, keep, sizes=[1] * int(keep.sum()))
    for got, want in zip(_rows(parts), _rows(whole), strict=True):
        np.testing.assert_array_equal(got, want)
    assert len(parts[K]) == 0, "the sample after the hole is held: nothing taken"
    n = engine.latency
    assert parts[K + n].sample.tolist() == [-n]
    assert parts[K + n].stamps[0] == STAMPS[K + 300]


def test_a_record_ending_on_an_unconfirmed_jump_counts_it() -> None:
    stamps = STAMPS[:50].copy()
    stamps[-1] += 5.0
    engine = engine_for()
    out = engine.push(batch(stamps, ACCEL[:50], GYRO[:50]))
    assert engine.holding
    assert len(out) + len(engine.flush()) == 49
    assert engine.counts["rejected_unconfirmed_jump"] == 1
    assert engine.counts["received"] == 50


def test_the_stream_stamps_a_held_sample_with_its_own_input_stamp() -> None:
    """Live, one message per push: the pose answering the sample after a hole is published
    with the next message, stamped with that sample's header stamp to the nanosecond."""
    scene = default_scene()
    keep = (np.arange(N) < K) | (np.arange(N) >= K + 300)
    stamps_ns = 1_700_000_000_000_000_000 + np.arange(N, dtype=np.int64) * 1_000_000 + 123
    msgs = imu_messages(stamps_ns[keep], ACCEL[keep], GYRO[keep], scene.input.frame_id)
    stream = TwinStream(scene)
    pose_stamps = []
    for raws in [*([raw] for _, raw in msgs), None]:  # None: the end of the stream
        for topic, stamp, _ in stream.finish() if raws is None else stream.process(raws):
            if topic == "~/pose":
                pose_stamps.append(stamp)
    assert pose_stamps == stamps_ns[keep].tolist()
