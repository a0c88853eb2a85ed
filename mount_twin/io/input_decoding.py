"""Input messages (sensor_msgs/Imu, geometry_msgs/AccelStamped) decoded into the engine's
samples: stamps, sensor-frame vectors, frame ids; rosbags for the first of each frame_id, its
fixed layout (`io.fixed_layout`) for the rest, and the stamps' time base."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import islice
from typing import Any

import numpy as np

from mount_twin.engine.batch import SampleBatch
from mount_twin.io.messages import ACCEL, IMU, TYPESTORE, layout_of
from mount_twin.io.raw_rows import RawRows


@dataclass(frozen=True)
class TimeBase:
    """Stamps as float seconds from an integer-second origin, so float64 keeps ~1e-11 s
    resolution near the origin (an epoch stamp as float64 would keep only ~0.2 µs).

    The conversion is one way: outputs reuse the integer input stamps (`encode_outputs`), so
    no stamp is ever rebuilt from float seconds.
    """

    origin_ns: int

    @classmethod
    def at(cls, stamp_ns: int) -> TimeBase:
        """A base at the whole second before `stamp_ns`."""
        return cls(stamp_ns - stamp_ns % 1_000_000_000)

    def seconds(self, stamp_ns: np.ndarray) -> np.ndarray:
        """Float seconds since the origin."""
        return (stamp_ns - self.origin_ns) * 1e-9


def stamp_ns(header: Any) -> int:
    """header.stamp as integer nanoseconds."""
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)  # type: ignore[attr-defined]


@dataclass
class Decoded:
    """Raw input messages decoded: stamps (ns), sensor-frame vectors and frame ids.

    `undecodable` counts messages that were not valid CDR of the expected type; `position`
    gives each decoded message's place among the raw messages (int64; None: they are all of
    them, in order); `unprovided`, per decoded message (n, 2) bool, whether its acceleration
    and its angular velocity are marked not provided (an Imu's covariance[0] = -1, REP-145:
    to be disregarded; None: every reading is provided).
    """

    stamps_ns: np.ndarray
    accel: np.ndarray
    gyro: np.ndarray
    frame_ids: list[str]
    undecodable: int = 0
    position: np.ndarray | None = None
    unprovided: np.ndarray | None = None

    def select(self, keep: np.ndarray) -> Decoded:
        """The messages where `keep` (bool, per decoded message) is True."""
        frames = [f for f, k in zip(self.frame_ids, keep.tolist(), strict=True) if k]
        places = self.places()[keep]
        return Decoded(
            self.stamps_ns[keep],
            self.accel[keep],
            self.gyro[keep],
            frames,
            self.undecodable,
            places,
            None if self.unprovided is None else self.unprovided[keep],
        )

    def places(self) -> np.ndarray:
        """Each decoded message's place among the raw messages (int64)."""
        if self.position is None:
            return np.arange(self.stamps_ns.shape[0])
        return self.position

    def batch(self, base: TimeBase) -> SampleBatch:
        """Engine samples with stamps in seconds from `base`."""
        seconds = base.seconds(self.stamps_ns)
        return SampleBatch(seconds, self.accel, self.gyro, self.frame_ids, self.unprovided)


LAYOUT_FRAME_MAX = 256
"""Longest frame_id (characters) whose messages are read through a layout: a longer one (no
sensor's; a hostile publisher's) is decoded by rosbags alone, neither probed (a probe
serializes it twice) nor cached (`layout_of` kept 256 of them: 100 kB ids held 25 MB)."""
ONE_BY_ONE_MAX = 24
"""Most messages a decode first tries one by one against the layout of a frame_id recently seen
(`RECENT_FRAMES`; `FixedLayout.unpack_one`, about 3.6 + 1.8 n µs for n Imu messages) rather than
in bulk (rosbags for the first message and one numpy pass, about 43 + 0.2 n µs): a live node's
wake-up takes one message or a few. Set from `python3
bench/bench_decode.py --repeats 9 --number 1000` (the two ways alternately, best CPU time of 9
runs of 1000 calls), 2026-11-28, three runs: one by one was the faster at every n up to 24
(0.95-0.99 of bulk there), no faster from 26 in two runs of three and from 28 in all; 24 is the
largest n it won in every run."""
LAYOUT_SCANS = 4
"""Most rows a decode of n messages scans against layouts, in units of n (each new frame_id's
layout scans every message still pending): past it the rest is decoded one by one, in time
linear in the messages. A publisher varying its frame_id at every message made it quadratic:
1000 messages with ids of 100 000 characters took 57 s to decode, one batch of a live node."""


def decode_inputs(raws: Sequence[bytes | memoryview], msgtype: str) -> Decoded:
    """Decode sensor_msgs/Imu (linear_acceleration, angular_velocity) or
    geometry_msgs/AccelStamped (accel.linear; its accel.angular is an angular acceleration, not a
    rate, so Ω is taken as zero).

    An Imu's reading whose covariance[0] is -1 is marked not provided (`Decoded.unprovided`).

    rosbags decodes the first message of each frame_id; the messages that share its fixed layout
    are read in one numpy pass (`FixedLayout`; rows of `RawRows` as they lie), the rest one by
    one through rosbags. Up to ONE_BY_ONE_MAX messages (the live node's usual call) are first
    tried one by one against the layouts of the frame_ids last seen (`RECENT_FRAMES`: the first
    message tells which, if any), without rosbags or the numpy pass (one message: ~46 → ~5
    µs). Frame ids past LAYOUT_FRAME_MAX characters, and every message once LAYOUT_SCANS is
    spent, go through rosbags alone.
    """
    n = len(raws)
    if 0 < n <= ONE_BY_ONE_MAX:
        want = _INPUT_WANT[msgtype]
        for frame in _RECENT_FRAMES.get(msgtype, ()):
            layout = layout_of(msgtype, frame)
            # a first message of another layout (a second sensor's frame_id: a body IMU's
            # calls alternate with the deck's) tries the next frame_id, not every message
            if (first := layout.unpack_one(raws[0], want)) is None:
                continue
            ones = [first, *[layout.unpack_one(raw, want) for raw in islice(raws, 1, None)]]
            read = [one for one in ones if one is not None]
            if len(read) == n:
                return _decoded_rows(read, msgtype, frame)
            break
    stamps = np.zeros(n, dtype=np.int64)
    accel, gyro, covariance = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 2))
    frames = np.full(n, "", dtype=object)
    ok = np.zeros(n, dtype=bool)
    pending = np.ones(n, dtype=bool)
    batched = True
    scanned = 0
    while pending.any():
        i = int(np.argmax(pending))
        pending[i] = False
        try:
            msg: Any = TYPESTORE.deserialize_cdr(raws[i], msgtype)
        except Exception:  # any malformed CDR: counted, never raised
            continue
        ok[i] = True
        frames[i] = msg.header.frame_id
        stamps[i], accel[i], gyro[i], covariance[i] = _input_values(msg, msgtype)
        if not batched or len(msg.header.frame_id) > LAYOUT_FRAME_MAX:
            continue
        rest = np.flatnonzero(pending)
        scanned += rest.shape[0]
        if scanned > LAYOUT_SCANS * n:
            batched = False
            continue
        try:
            layout = layout_of(msgtype, msg.header.frame_id)
        except ValueError:  # a frame_id holding a probe's sentinel bytes: rosbags, one by one
            batched = False
            continue
        want = _INPUT_WANT[msgtype]
        if isinstance(raws, RawRows):  # i is the first pending: with all the rest, every row
            rows = raws.rows if rest.shape[0] == n - 1 else raws.rows[np.r_[i, rest]]
            match, cols = layout.unpack_rows(rows, want)
        else:
            match, cols = layout.unpack([raws[j] for j in (i, *rest.tolist())], want)
        if not match[0]:  # this writer's padding or extras differ: no batch for it
            batched = False
            continue
        _seen(msgtype, msg.header.frame_id)
        every = rest.shape[0] == n - 1 and bool(match.all())  # the usual: a slice, no index
        got: slice | np.ndarray = slice(1, n) if every else rest[match[1:]]
        pending[got] = False
        ok[got] = True
        frames[got] = frames[i]
        stamps[got] = cols[0][1:].astype(np.int64) * 1_000_000_000 + cols[1][1:]
        accel[got] = np.column_stack(cols[2:5])[1:]
        if msgtype == IMU:
            gyro[got] = np.column_stack(cols[5:8])[1:]
            covariance[got] = np.column_stack(cols[8:10])[1:]
    bad = n - int(ok.sum())
    return Decoded(
        stamps[ok],
        accel[ok],
        gyro[ok],
        frames[ok].tolist(),
        bad,
        np.flatnonzero(ok) if bad else None,
        _unprovided(covariance[ok]),
    )


def _decoded_rows(rows: list[list], msgtype: str, frame: str) -> Decoded:
    """`decode_inputs` of messages all read through the layout of `frame`: their `_INPUT_WANT`
    fields, one list a message."""
    n = len(rows)
    stamps = np.array([int(r[0]) * 1_000_000_000 + int(r[1]) for r in rows], dtype=np.int64)
    accel = np.array([r[2:5] for r in rows])
    if msgtype != IMU:
        return Decoded(stamps, accel, np.zeros((n, 3)), [frame] * n, 0, None, None)
    gyro = np.array([r[5:8] for r in rows])
    unset = _unprovided(np.array([r[8:10] for r in rows]))
    return Decoded(stamps, accel, gyro, [frame] * n, 0, None, unset)


def _unprovided(covariance: np.ndarray) -> np.ndarray | None:
    """(n, 2) bool of the readings whose (n, 2) covariance[0] (acceleration's, angular
    velocity's) marks them not provided (-1, REP-145); None where none is."""
    unset = covariance == -1.0
    return unset if unset.any() else None


def _input_values(msg: Any, msgtype: str) -> tuple[int, tuple, tuple, tuple]:
    """(stamp ns, acceleration, angular velocity, their covariances' [0]) of one decoded input
    message (an AccelStamped has no covariance: 0)."""
    if msgtype == IMU:
        a, w = msg.linear_acceleration, msg.angular_velocity  # type: ignore[attr-defined]
        unset = (msg.linear_acceleration_covariance[0], msg.angular_velocity_covariance[0])  # type: ignore[attr-defined]
        return stamp_ns(msg.header), (a.x, a.y, a.z), (w.x, w.y, w.z), unset  # type: ignore[attr-defined]
    a = msg.accel.linear  # type: ignore[attr-defined]
    return stamp_ns(msg.header), (a.x, a.y, a.z), (0.0, 0.0, 0.0), (0.0, 0.0)  # type: ignore[attr-defined]


_INPUT_WANT = {IMU: (*range(8), 30, 21), ACCEL: range(5)}
"""Fields an input decode reads: sec, nanosec, acceleration (and for Imu ω, then
linear_acceleration_covariance[0] and angular_velocity_covariance[0])."""
RECENT_FRAMES = 4
"""Most frame_ids per input type whose layouts a call of up to ONE_BY_ONE_MAX messages tries
(`_RECENT_FRAMES`): the deck's and a body IMU's, whose calls alternate, and a few more."""
_RECENT_FRAMES: dict[str, list[str]] = {}
"""Input type → the frame_ids last decoded through their layouts, the latest first (a cache)."""


def _seen(msgtype: str, frame: str) -> None:
    """`frame` decoded through its layout: first of `_RECENT_FRAMES[msgtype]`."""
    recent = _RECENT_FRAMES.setdefault(msgtype, [])
    if frame in recent:
        recent.remove(frame)
    recent.insert(0, frame)
    del recent[RECENT_FRAMES:]
