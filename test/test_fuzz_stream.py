"""Hostile input streams, fuzzed (hypothesis, derandomized): stamps going back, duplicated,
glitched forward, jumping by 10⁶ s, bursts, NaN/inf and absurd readings, wrong frames, and
damaged CDR bytes. Whatever comes, the twin raises nothing, publishes nothing non-finite,
accounts for every sample (received = accepted + rejected), and gives the same numbers however
the samples are batched."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from io_helpers import batch, default_scene, engine_for, fuzz_settings, split

from mount_twin.engine.batch import OutputBatch
from mount_twin.io.output_encoding import imu_messages
from mount_twin.stream import TwinStream

G = 9.80665
FUZZ = fuzz_settings(200, deadline=None)

MUTATIONS = st.sampled_from(
    [
        "back_small",
        "back_far",
        "duplicate",
        "glitch",
        "jump_huge",
        "burst",
        "nan",
        "inf",
        "spike",
        "huge_reading",
        "wrong_frame",
    ]
)


@st.composite
def streams(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str], list[int]]:
    """(stamps s, accel, gyro, frame_ids, batch sizes) of a mutated 1 kHz record at rest."""
    n = draw(st.integers(20, 400))
    stamps = 1.0 + np.arange(n) * 1e-3
    accel = np.tile([0.0, 0.0, G], (n, 1))
    gyro = np.zeros((n, 3))
    frames = ["deck_imu"] * n
    for what, at in draw(st.lists(st.tuples(MUTATIONS, st.integers(0, n - 1)), max_size=12)):
        if what == "back_small":
            stamps[at] -= 5e-3
        elif what == "back_far":
            stamps[at:] -= 3.0
        elif what == "duplicate" and at > 0:
            stamps[at] = stamps[at - 1]
        elif what == "glitch":
            stamps[at] += draw(st.sampled_from([0.003, 0.018, 0.05, 0.3, 0.99, 2.5]))
        elif what == "jump_huge":
            stamps[at:] += 1e6
        elif what == "burst":
            stamps[at : at + 10] = stamps[at]
        elif what in ("nan", "inf"):
            (accel if draw(st.booleans()) else gyro)[at, draw(st.integers(0, 2))] = float(what)
        elif what == "spike":
            accel[at, 2] += draw(st.sampled_from([50.0, 500.0, -300.0]))
        elif what == "huge_reading":
            accel[at, 0] = 1e200
        elif what == "wrong_frame":
            frames[at] = "imu_link"
    sizes = draw(st.lists(st.integers(1, 120), min_size=1, max_size=8))
    return stamps, accel, gyro, frames, sizes


def _rows(outs: list[OutputBatch]) -> list[np.ndarray]:
    return [np.concatenate([getattr(o, k) for o in outs]) for k in ("stamps", "pose", "wrenches")]


def _accounted(counts) -> int:
    return counts["accepted"] + sum(v for k, v in counts.items() if k.startswith("rejected_"))


@FUZZ
@given(streams())
def test_any_stream_is_accounted_finite_and_batching_invariant(case) -> None:
    stamps, accel, gyro, frames, sizes = case
    whole_engine = engine_for()
    whole = [whole_engine.push(batch(stamps, accel, gyro, frames))]
    whole_engine.flush()
    parted_engine = engine_for()
    parts = [parted_engine.push(b) for b in split(batch(stamps, accel, gyro, frames), sizes)]
    parted_engine.flush()
    for got, want in zip(_rows(parts), _rows(whole), strict=True):
        np.testing.assert_array_equal(got, want)
        assert np.isfinite(got).all()
    for engine in (whole_engine, parted_engine):
        assert engine.counts["received"] == stamps.shape[0] == _accounted(engine.counts)
        assert np.isfinite(engine.state).all()


@FUZZ
@given(
    st.lists(
        st.tuples(
            st.integers(0, 399),
            st.sampled_from(["flip", "truncate", "extend", "zero", "random"]),
            st.integers(0, 255),
        ),
        max_size=25,
    ),
    st.lists(st.integers(1, 50), min_size=1, max_size=6),
    st.lists(st.tuples(st.integers(0, 399), st.sampled_from([0, -5_000_000_000])), max_size=4),
)
def test_damaged_cdr_bytes_are_counted_never_raised(damage, sizes, unset_stamps) -> None:
    """Bytes damaged, and stamps unset (0) or before 1970, in any mix within one message batch."""
    scene = default_scene()
    n = 400
    stamps_ns = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 1_000_000
    for at, stamp in unset_stamps:
        stamps_ns[at] = stamp
    raws = [
        bytearray(raw)
        for _, raw in imu_messages(
            stamps_ns, np.tile([0.0, 0.0, G], (n, 1)), np.zeros((n, 3)), scene.input.frame_id
        )
    ]
    rng = np.random.default_rng(len(damage))
    for at, how, byte in damage:
        raw = raws[at]
        if not raw:  # truncated to nothing by an earlier change
            continue
        if how == "flip":
            raw[byte % len(raw)] ^= 0xFF
        elif how == "truncate":
            del raw[byte % len(raw) :]
        elif how == "extend":
            raw.extend(bytes([byte]) * 40)
        elif how == "zero":
            raw[4 : 4 + byte % 40] = bytes(len(raw[4 : 4 + byte % 40]))
        else:
            raws[at] = bytearray(rng.integers(0, 256, byte, dtype=np.uint8).tobytes())
    stream = TwinStream(scene)
    out: list[tuple[str, int, bytes]] = []
    i = 0
    for size in [*sizes, n]:
        out += stream.process([bytes(r) for r in raws[i : i + size]])
        i += size
        if i >= n:
            break
    out += stream.finish()
    counts = stream.engine.counts
    assert counts["received"] == n == _accounted(counts)
    assert all(stamp > 0 for _, stamp, _ in out)
