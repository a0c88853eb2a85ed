"""ROS 2 messages ↔ engine data, through the rosbags typestore pinned to Jazzy.

The one place that (de)serializes: the live node moves raw CDR bytes and calls these functions,
the bag replay calls them too, so live and offline runs share every conversion. Field names are
the .msg names, the same in rosbags and rclpy.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from dataclasses import fields as dataclass_fields
from functools import cached_property, lru_cache, partial
from itertools import chain
from operator import attrgetter
from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_typestore

from mount_twin.engine.batch import HealthReport, OutputBatch, SampleBatch
from mount_twin.engine.body_check import BodyComparison
from mount_twin.io.fixed_layout import FixedLayout, split_rows
from mount_twin.io.raw_rows import RawRows
from mount_twin.physics import pose_row
from mount_twin.physics.rotations import quaternion_from_matrix, rpy_matrix
from mount_twin.scene.description import Outputs, Scene

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
_T = TYPESTORE.types
IMU, ACCEL = "sensor_msgs/msg/Imu", "geometry_msgs/msg/AccelStamped"
POSE, VECTOR3, WRENCH = (
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/Vector3Stamped",
    "geometry_msgs/msg/WrenchStamped",
)
DIAGNOSTICS = "diagnostic_msgs/msg/DiagnosticArray"
TF = "tf2_msgs/msg/TFMessage"
"""Type of /tf and /tf_static (known to rosbags' Jazzy typestore; no tf2_msgs install needed)."""
TF_TOPIC = "/tf"
"""Body pose transforms, one TFMessage per published row (volatile, like tf2_ros' broadcaster)."""
TF_STATIC_TOPIC = "/tf_static"
"""Mount frames, one TFMessage for all mounts; publish it latched (transient_local, depth 1)."""


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
serializes it twice) nor cached (`_layout` kept 256 of them: 100 kB ids held 25 MB)."""
ONE_BY_ONE_MAX = 8
"""Most messages a decode first tries one by one against the layout of the frame_id last seen
(`FixedLayout.unpack_one`): a live node's wake-up takes one message or a few. Measured
2026-11-27 (Imu, best of 5 timeit runs, a loaded machine): 1, 2 and 8 messages 5.6, 7.7 and
18.8 µs this way, 43-49 µs through rosbags (the first message) and the numpy pass."""
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
    tried one by one against the layout of the frame_id last seen, without rosbags or the
    numpy pass (one message: ~200 → ~15 µs). Frame ids past LAYOUT_FRAME_MAX
    characters, and every message once LAYOUT_SCANS is spent, go through rosbags alone.
    """
    n = len(raws)
    if 0 < n <= ONE_BY_ONE_MAX and msgtype in _LAST_FRAME:
        frame = _LAST_FRAME[msgtype]
        layout, want = _layout(msgtype, frame), _INPUT_WANT[msgtype]
        ones = [layout.unpack_one(raw, want) for raw in raws]
        read = [one for one in ones if one is not None]
        if len(read) == n:
            return _decoded_rows(read, msgtype, frame)
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
            layout = _layout(msgtype, msg.header.frame_id)
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
        _LAST_FRAME[msgtype] = msg.header.frame_id
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


def _header(stamp_ns: int, frame_id: str) -> Any:
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    return _T["std_msgs/msg/Header"](
        stamp=_T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec), frame_id=frame_id
    )


def _vector3(x: float, y: float, z: float) -> Any:
    # float(): rclpy's converters abort on numpy scalars or ints in float64 fields.
    return _T["geometry_msgs/msg/Vector3"](x=float(x), y=float(y), z=float(z))


def _time_fields(v: Sequence[float]) -> Any:
    return _T["builtin_interfaces/msg/Time"](sec=int(v[0]), nanosec=int(v[1]))


def _hdr(v: Sequence[float], frame_id: str) -> Any:
    return _T["std_msgs/msg/Header"](stamp=_time_fields(v), frame_id=frame_id)


def _build_imu(frame_id: str, v: Sequence[float]) -> Any:
    """Imu from [sec, nanosec, a(3), ω(3), orientation xyzw(4), its 3 covariances(27)]."""
    return _T[IMU](
        header=_hdr(v, frame_id),
        orientation=_T["geometry_msgs/msg/Quaternion"](
            x=float(v[8]), y=float(v[9]), z=float(v[10]), w=float(v[11])
        ),
        orientation_covariance=np.array(v[12:21], dtype=np.float64),
        angular_velocity=_vector3(*v[5:8]),
        angular_velocity_covariance=np.array(v[21:30], dtype=np.float64),
        linear_acceleration=_vector3(*v[2:5]),
        linear_acceleration_covariance=np.array(v[30:39], dtype=np.float64),
    )


def _build_accel(frame_id: str, v: Sequence[float]) -> Any:
    """AccelStamped from [sec, nanosec, linear(3), angular(3)]."""
    accel = _T["geometry_msgs/msg/Accel"](linear=_vector3(*v[2:5]), angular=_vector3(*v[5:8]))
    return _T[ACCEL](header=_hdr(v, frame_id), accel=accel)


def _build_pose(frame_id: str, v: Sequence[float]) -> Any:
    """PoseStamped from [sec, nanosec, position(3), quaternion xyzw(4)]."""
    pose = _T["geometry_msgs/msg/Pose"](
        position=_T["geometry_msgs/msg/Point"](x=float(v[2]), y=float(v[3]), z=float(v[4])),
        orientation=_T["geometry_msgs/msg/Quaternion"](
            x=float(v[5]), y=float(v[6]), z=float(v[7]), w=float(v[8])
        ),
    )
    return _T[POSE](header=_hdr(v, frame_id), pose=pose)


def _build_vector3(frame_id: str, v: Sequence[float]) -> Any:
    """Vector3Stamped from [sec, nanosec, x, y, z]."""
    return _T[VECTOR3](header=_hdr(v, frame_id), vector=_vector3(*v[2:5]))


def _build_wrench(frame_id: str, v: Sequence[float]) -> Any:
    """WrenchStamped from [sec, nanosec, force(3), torque(3)]."""
    wrench = _T["geometry_msgs/msg/Wrench"](force=_vector3(*v[2:5]), torque=_vector3(*v[5:8]))
    return _T[WRENCH](header=_hdr(v, frame_id), wrench=wrench)


def _transform_stamped(parent: str, child: str, v: Sequence[float]) -> Any:
    """TransformStamped parent → child from [sec, nanosec, translation(3), rotation xyzw(4)]."""
    return _T["geometry_msgs/msg/TransformStamped"](
        header=_hdr(v, parent),
        child_frame_id=child,
        transform=_T["geometry_msgs/msg/Transform"](
            translation=_vector3(*v[2:5]),
            rotation=_T["geometry_msgs/msg/Quaternion"](
                x=float(v[5]), y=float(v[6]), z=float(v[7]), w=float(v[8])
            ),
        ),
    )


def _build_tf(parent: str, child: str, v: Sequence[float]) -> Any:
    """TFMessage of one transform parent → child, from the fields of `_transform_stamped`."""
    return _T[TF](transforms=[_transform_stamped(parent, child, v)])


_BUILDERS: dict[str, tuple[Callable[..., Any], int]] = {
    IMU: (_build_imu, 37),
    ACCEL: (_build_accel, 6),
    POSE: (_build_pose, 7),
    VECTOR3: (_build_vector3, 3),
    WRENCH: (_build_wrench, 6),
    TF: (_build_tf, 7),
}
"""Builder and number of float64 fields (after sec, nanosec) of each fixed-layout type; the
builders take the message's frame ids first (TF: parent, child; the others: header.frame_id)."""

_INPUT_WANT = {IMU: (*range(8), 30, 21), ACCEL: range(5)}
"""Fields an input decode reads: sec, nanosec, acceleration (and for Imu ω, then
linear_acceleration_covariance[0] and angular_velocity_covariance[0])."""
_LAST_FRAME: dict[str, str] = {}
"""Input type → frame_id of the last message decoded through its layout (a cache)."""


@lru_cache(maxsize=256)
def _layout(msgtype: str, *frames: str) -> FixedLayout:
    """Layout of `msgtype` with these frame ids (see `_BUILDERS`)."""
    build, n_floats = _BUILDERS[msgtype]
    return FixedLayout.probe(
        partial(build, *frames),
        ["<i4", "<u4"] + ["<f8"] * n_floats,
        partial(TYPESTORE.serialize_cdr, typename=msgtype),
    )


def _pack(
    msgtype: str,
    frames: str | tuple[str, ...],
    sec: np.ndarray,
    nsec: np.ndarray,
    values: np.ndarray,
) -> list[bytes]:
    """Messages of one type and frame id(s) for stamps (sec, nanosec) and rows of float fields."""
    frames = (frames,) if isinstance(frames, str) else frames
    return _layout(msgtype, *frames).pack([sec, nsec, values])


DIAGNOSTICS_TOPIC = "/diagnostics"


@dataclass(frozen=True)
class Stream:
    """One topic of a per-row output.

    Attributes:
        topic: name before resolution ('~' is the node's namespace/name; remappable in ROS,
            resolved by `resolve` for bags).
        msgtype: its message type, one of the fixed-layout types of `_BUILDERS`.
        frames: the frame id(s) its messages carry (a transform's parent and child).
        values: the float fields of its messages from an OutputBatch, one row per message.
        table: the table a bag reader files its messages under (`io.output_tables`), or None
            (not read back: /tf).
    """

    topic: str
    msgtype: str
    frames: tuple[str, ...]
    values: Callable[[OutputBatch], np.ndarray]
    table: str | None

    @cached_property
    def layout(self) -> FixedLayout:
        """Its messages' layout (`_layout`), looked up once: a live sample encodes each
        topic's one message on its own."""
        return _layout(self.msgtype, *self.frames)


@dataclass(frozen=True)
class Readback:
    """A topic the bag reader files into a table (`output_table`, then `export`, `report`,
    the plots).

    Attributes:
        topic: its topic before resolution ('~' is the node's namespace/name); `{mount}`
            stands for each mount's name (one stream per mount).
        msgtype: its message type.
        table: the table its messages are read into (`{mount}` as in topic), or None: not read
            back.
        columns: the table's numeric columns, unit in the name.
        fields: the message field (dotted path) each column is read from, in column order.
    """

    topic: str
    msgtype: str
    table: str | None
    columns: tuple[str, ...]
    fields: tuple[str, ...]

    def __post_init__(self) -> None:
        """Refuse a readback (or output) registered half-way, at import, naming what is
        missing."""
        missing = _output_gaps(self)
        if missing:
            name = f"{self.flag!r} ({self.topic})" if isinstance(self, Output) else self.topic
            msg = f"io.messages: output {name}: {'; '.join(missing)}"
            raise ValueError(msg)

    @cached_property
    def _getter(self) -> Callable[[Any], Any]:
        return attrgetter(*self.fields)

    def read(self, msg: Any) -> tuple[float, ...]:
        """A message's values in column order (deserialized: rosbags' message classes)."""
        got = self._getter(msg)
        return tuple(got) if len(self.fields) > 1 else (got,)

    @property
    def per_mount(self) -> bool:
        """One stream per mount."""
        return "{mount}" in self.topic

    def table_of(self, topic: str, msgtype: str) -> str | None:
        """The table a resolved topic of msgtype is read into, if it is this output's: its
        topic after the node's namespace and name ('~'), a mount's name where `{mount}` is."""
        if self.table is None or msgtype != self.msgtype:
            return None
        head, _, tail = self.topic.lstrip("~").partition("{mount}")
        pattern = re.escape(head) + (
            "(?P<mount>[^/]+)" + re.escape(tail) if self.per_mount else ""
        )
        found = re.search(pattern + "$", topic)
        return None if found is None else self.table.format(**found.groupdict())


@dataclass(frozen=True)
class Output(Readback):
    """What one per-row output is, declared once: the writer (`output_streams`), the bag reader
    (`output_table`, then `export`, `report`, dashboards) and `info` read it.

    Attributes (besides `Readback`'s):
        flag: its switch in `scene.outputs`.
        frames: the frame id(s) its messages carry, from the scene (and the mount's name).
        values: its rows' float fields from an OutputBatch (and the mount's index).
    """

    flag: str
    frames: Callable[[Scene, str], tuple[str, ...]]
    values: Callable[[OutputBatch, int], np.ndarray]

    def streams(self, scene: Scene) -> list[Stream]:
        """Its streams for `scene`."""
        names = [m.name for m in scene.mounts] if self.per_mount else [""]
        return [
            Stream(
                self.topic.format(mount=name),
                self.msgtype,
                self.frames(scene, name),
                self._values_of(i),
                None if self.table is None else self.table.format(mount=name),
            )
            for i, name in enumerate(names)
        ]

    def _values_of(self, i: int) -> Callable[[OutputBatch], np.ndarray]:
        """Its rows' values for the i-th mount (or the one stream)."""
        return lambda out: self.values(out, i)


def _has_field(msgtype: str, path: str) -> bool:
    """Whether the dotted field path exists in `msgtype` (the typestore's definitions)."""
    node: Any = msgtype  # a type's name, then each field's (node type, subtype) subtype
    for name in path.split("."):
        fields = dict(TYPESTORE.fielddefs[node][1]) if node in TYPESTORE.fielddefs else {}
        if name not in fields:
            return False
        node = fields[name][1]
    return True


def _output_gaps(out: Readback) -> list[str]:
    """What a readback's or an output's declaration lacks or contradicts (empty: complete)."""
    gaps = []
    if isinstance(out, Output) and out.flag not in {f.name for f in dataclass_fields(Outputs)}:
        gaps.append(f"no switch {out.flag!r} in scene.outputs (mount_twin.scene.description)")
    if out.msgtype not in _BUILDERS:
        gaps.append(f"no builder for {out.msgtype} in _BUILDERS")
    if len(out.columns) != len(out.fields):
        gaps.append(f"{len(out.columns)} columns but {len(out.fields)} fields to read them from")
    if (out.table is None) != (not out.columns):
        gaps.append("a table needs columns, and columns a table")
    if out.table is not None and ("{mount}" in out.table) != out.per_mount:
        gaps.append("the table and the topic must both name {mount}, or neither")
    gaps.extend(
        f"{out.msgtype} has no field {f}" for f in out.fields if not _has_field(out.msgtype, f)
    )
    return gaps


def _pose_fields(out: OutputBatch, i: int) -> np.ndarray:
    return out.pose[:, pose_row.POSE_COLS]


POSE_COLUMNS = ("x_m", "y_m", "z_m", "qx", "qy", "qz", "qw")
"""The pose table's numeric columns: CG position (m, F), quaternion x, y, z, w (body → F)."""
POSE_FIELDS = tuple(f"pose.position.{a}" for a in "xyz") + tuple(
    f"pose.orientation.{a}" for a in "xyzw"
)

POSE_OUTPUT = Output(
    flag="pose",
    topic="~/pose",
    msgtype=POSE,
    table="pose",
    columns=POSE_COLUMNS,
    fields=POSE_FIELDS,
    frames=lambda sc, _: (sc.frames.foundation,),
    values=_pose_fields,
)
ANGLES_OUTPUT = Output(
    flag="angles",
    topic="~/angles",
    msgtype=VECTOR3,
    table="angles",
    columns=("alpha_rad", "gamma_rad", "delta_rad"),
    fields=tuple(f"vector.{a}" for a in "xyz"),
    frames=lambda sc, _: (sc.frames.foundation,),
    values=lambda out, i: out.angles,
)
WRENCHES_OUTPUT = Output(
    flag="wrenches",
    topic="~/mounts/{mount}/wrench",
    msgtype=WRENCH,
    table="mount_{mount}",
    columns=("fx_N", "fy_N", "fz_N", "tx_Nm", "ty_Nm", "tz_Nm"),
    fields=tuple(f"wrench.{p}.{a}" for p in ("force", "torque") for a in "xyz"),
    frames=lambda sc, name: (sc.frames.mount_frame(name),),
    values=lambda out, i: out.wrenches[:, i],
)
TF_OUTPUT = Output(
    flag="tf",
    topic=TF_TOPIC,
    msgtype=TF,
    table=None,
    columns=(),
    fields=(),
    frames=lambda sc, _: (sc.frames.foundation, sc.frames.body),
    values=_pose_fields,
)
OUTPUTS: tuple[Output, ...] = (POSE_OUTPUT, ANGLES_OUTPUT, WRENCHES_OUTPUT, TF_OUTPUT)
"""The per-row outputs, in the order their messages follow each other (each flag is one of
`scene.outputs`: tested to be the same set). A new output is a builder in `_BUILDERS` for a new
message type, an entry here and its flag in the scene's `Outputs`: its table is then read back
under its own name."""


def output_streams(scene: Scene) -> list[Stream]:
    """Every per-row output topic the scene enables, in publishing order."""
    return [st for out in OUTPUTS if getattr(scene.outputs, out.flag) for st in out.streams(scene)]


def output_table(topic: str, msgtype: str) -> tuple[str, Readback] | None:
    """The table a resolved output topic of msgtype is read into, and its output (columns and
    fields), or None: not an output of the twin read back (another node's topic, /tf,
    diagnostics). The per-row outputs, then the body IMU comparison's (`BODY_READBACKS`)."""
    for out in (*OUTPUTS, *BODY_READBACKS):
        table = out.table_of(topic, msgtype)
        if table is not None:
            return table, out
    return None


NODE_NAME = "mount_twin"
"""The node's name, which its private (~) output topics resolve against: the live node's, as
with `ros2 run` and the default launch, and a replay's bag's."""


def resolve(name: str, node_name: str, namespace: str = "/") -> str:
    """Resolve a private (~) or relative topic name as rclpy would for the node `node_name` in
    `namespace` (what `-r __node:=` and `-r __ns:=` set; no topic remaps)."""
    ns = "/" + namespace.strip("/") if namespace.strip("/") else ""
    if name.startswith("~"):
        return f"{ns}/{node_name}{name[1:]}"
    return name if name.startswith("/") else f"{ns}/{name}"


@dataclass(frozen=True)
class RowBlock:
    """Per-row output messages in columns: row k holds, for each topic j in order, the message
    stamped stamps_ns[k] whose CDR bytes are rows[j][k] (`messages` lists them row by row, the
    order they are published in). A bag writer takes the block whole (`io.mcap_writer`).

    Attributes:
        topics: (m,) topic of each column (unresolved from `encode_output_blocks`; `renamed`).
        stamps_ns: (k,) int64 stamps, ns.
        rows: m arrays (k, L_j) uint8, each message of topic j one row of L_j bytes.
    """

    topics: tuple[str, ...]
    stamps_ns: np.ndarray
    rows: tuple[np.ndarray, ...]

    def messages(self) -> list[tuple[str, int, bytes]]:
        """(topic, stamp ns, CDR bytes) row by row."""
        k = len(self.stamps_ns)
        stamps = self.stamps_ns.tolist()
        columns = []
        for topic, rows in zip(self.topics, self.rows, strict=True):
            columns.append(zip([topic] * k, stamps, split_rows(rows), strict=True))
        return list(chain.from_iterable(zip(*columns, strict=True)))

    def renamed(self, names: dict[str, str]) -> RowBlock:
        """The block with each topic t as names[t]."""
        return RowBlock(tuple(names[t] for t in self.topics), self.stamps_ns, self.rows)


Encoded = tuple[str, int, bytes] | RowBlock
"""An encoded output: one message (topic, stamp ns, CDR bytes), or a block of per-row ones."""


def messages_of(encoded: Sequence[Encoded]) -> list[tuple[str, int, bytes]]:
    """The messages of encoded outputs one by one, in order."""
    out: list[tuple[str, int, bytes]] = []
    for item in encoded:
        if isinstance(item, RowBlock):
            out += item.messages()
        else:
            out.append(item)
    return out


def encode_outputs(
    scene: Scene,
    out: OutputBatch,
    stamps_ns: np.ndarray,
    streams: Sequence[Stream] | None = None,
) -> list[tuple[str, int, bytes]]:
    """`encode_output_blocks` message by message."""
    return messages_of(encode_output_blocks(scene, out, stamps_ns, streams))


PACK_ONE_MAX = 4
"""Most rows `encode_output_blocks` packs message by message (`FixedLayout.pack_one`, a
struct call each) rather than in blocks (`pack_rows`, numpy's per-call overhead a topic):
a live wake-up's one sample or few."""


def encode_output_blocks(
    scene: Scene,
    out: OutputBatch,
    stamps_ns: np.ndarray,
    streams: Sequence[Stream] | None = None,
) -> list[Encoded]:
    """CDR messages for an output batch, in the order the samples were processed: blocks of
    per-row messages (`RowBlock`), each diagnostics report (topic, stamp ns, bytes) after the
    rows published before it was due (`HealthReport.rows`).

    Args:
        stamps_ns: (n,) header stamps of the pushed samples, integer ns; rows reuse them, so
            output stamps equal input stamps exactly however long the twin runs.
        streams: `output_streams(scene)`, where the caller keeps them (a live stream encodes
            each sample on its own: building them took a tenth of its encoding).

    Per published row, in this order: pose, angles, one wrench per mount (header.frame_id =
    the mount's frame, `Frames.mount_frame`), /tf (frames.foundation → frames.body, the pose's
    numbers). Only the outputs the scene enables are built: unused outputs cost nothing.
    """
    stamps = stamps_ns[out.sample]
    if streams is None:
        streams = output_streams(scene)
    topics = tuple(st.topic for st in streams)
    if len(stamps) <= PACK_ONE_MAX:  # a live wake-up's few samples: struct, not numpy
        values = [st.values(out).tolist() for st in streams]  # (k, m) each
        per_row: list[list[Encoded]] = []
        for r, stamp in enumerate(stamps.tolist()):
            head = divmod(stamp, 1_000_000_000)
            per_row.append(
                [
                    (st.topic, stamp, st.layout.pack_one([*head, *v[r]]))
                    for st, v in zip(streams, values, strict=True)
                ]
            )
    else:
        sec, nsec = np.divmod(stamps, 1_000_000_000)
        rows = tuple(st.layout.pack_rows([sec, nsec, st.values(out)]) for st in streams)

    def block(a: int, b: int) -> list[Encoded]:
        if b <= a or not topics:
            return []
        if len(stamps) <= PACK_ONE_MAX:
            return [m for row in per_row[a:b] for m in row]
        return [RowBlock(topics, stamps[a:b], tuple(r[a:b] for r in rows))]

    encoded: list[Encoded] = []
    done = 0  # rows encoded
    for report in out.health:  # each before the first row at or after its `rows`
        upto = max(done, min(report.rows, len(stamps)))
        encoded += block(done, upto)
        encoded.append(encode_report(scene, report, int(stamps_ns[report.sample])))
        done = upto
    return encoded + block(done, len(stamps))


def encode_report(scene: Scene, report: HealthReport, stamp_ns: int) -> tuple[str, int, bytes]:
    """A health report as (unresolved topic, stamp ns, DiagnosticArray CDR bytes)."""
    msg = diagnostics_message(report, stamp_ns)
    return DIAGNOSTICS_TOPIC, stamp_ns, bytes(TYPESTORE.serialize_cdr(msg, DIAGNOSTICS))


def diagnostics_message(report: HealthReport, stamp_ns: int) -> Any:
    """diagnostic_msgs/DiagnosticArray of a health report (level is a byte: int in rosbags)."""
    status_t, kv_t = _T["diagnostic_msgs/msg/DiagnosticStatus"], _T["diagnostic_msgs/msg/KeyValue"]
    statuses = [
        status_t(
            level=s.level,
            name=s.name,
            message=s.message,
            hardware_id="mount_twin",
            values=[kv_t(key=k, value=v) for k, v in s.values.items()],
        )
        for s in report.statuses
    ]
    return _T[DIAGNOSTICS](header=_header(stamp_ns, ""), status=statuses)


def output_types(scene: Scene) -> dict[str, str]:
    """Unresolved topic → message type for every output the scene enables (diagnostics first;
    the body IMU's prediction and residual last, with a body_sensor)."""
    body = {BODY_PREDICTED_TOPIC: IMU, BODY_RESIDUAL_TOPIC: IMU} if scene.body_sensor else {}
    return {
        DIAGNOSTICS_TOPIC: DIAGNOSTICS,
        **{st.topic: st.msgtype for st in output_streams(scene)},
        **body,
    }


BODY_PREDICTED_TOPIC = "~/body_imu/predicted"
"""The twin's prediction of each body IMU sample (sensor_msgs/Imu, its stamp and axes)."""
BODY_RESIDUAL_TOPIC = "~/body_imu/residual"
"""The body IMU's sample minus the prediction (sensor_msgs/Imu, its stamp and axes)."""
_BODY_COLUMNS = ("fx_m_s2", "fy_m_s2", "fz_m_s2", "wx_rad_s", "wy_rad_s", "wz_rad_s")
_BODY_FIELDS = tuple(
    f"{v}.{a}" for v in ("linear_acceleration", "angular_velocity") for a in "xyz"
)
BODY_READBACKS = (
    Readback(BODY_PREDICTED_TOPIC, IMU, "body_imu_predicted", _BODY_COLUMNS, _BODY_FIELDS),
    Readback(BODY_RESIDUAL_TOPIC, IMU, "body_imu_residual", _BODY_COLUMNS, _BODY_FIELDS),
)
"""The body IMU comparison's topics, read back as tables (specific force, rate; its axes)."""


def body_frame_id(scene: Scene) -> str:
    """The frame id of the body IMU's prediction and residual: its own, else <frames.body>_imu."""
    sensor = scene.body_sensor
    return (sensor.frame_id if sensor else "") or f"{scene.frames.body}_imu"


def encode_body(scene: Scene, rows: BodyComparison) -> list[tuple[str, int, bytes]]:
    """The body comparison as (unresolved topic, stamp ns, CDR bytes): per compared sample its
    prediction and residual (stamped as the sample; linear_acceleration the specific force,
    m/s², angular_velocity the rate, rad/s, in the sensor's axes; no orientation; a reading
    the sample does not provide marked so in the residual, REP-145, its value NaN), then each
    window's report on /diagnostics."""
    frame = body_frame_id(scene)
    msgs: list[tuple[str, int, bytes]] = []
    if rows.stamps_ns.shape[0]:
        off = rows.residual
        pairs = zip(
            imu_messages(rows.stamps_ns, rows.predicted[:, :3], rows.predicted[:, 3:], frame),
            imu_messages(rows.stamps_ns, off[:, :3], off[:, 3:], frame, ~rows.present),
            strict=True,
        )
        for (stamp, predicted), (_, residual) in pairs:
            msgs += [
                (BODY_PREDICTED_TOPIC, stamp, predicted),
                (BODY_RESIDUAL_TOPIC, stamp, residual),
            ]
    for stamp, status in rows.reports:
        msgs.append(encode_report(scene, HealthReport(stamp * 1e-9, -1, [status]), stamp))
    return msgs


def mount_quaternion(orientation_rpy: Sequence[float]) -> np.ndarray:
    """Unit quaternion (x, y, z, w), w ≥ 0, of a mount's axes relative to F.

    Args:
        orientation_rpy: the mount's fixed-axis roll, pitch, yaw, rad.

    The rotation is the model's (`rpy_matrix`, columns = mount axes in F): it takes a vector
    expressed in the mount's axes (a WrenchStamped of that mount) to the same vector in F.
    """
    quat = np.empty(4)
    quaternion_from_matrix(rpy_matrix(*orientation_rpy), quat)
    return quat


def static_transforms(scene: Scene, stamp_ns: int) -> tuple[str, int, bytes]:
    """The /tf_static message of the mount frames, as (topic, stamp ns, TFMessage CDR bytes).

    One TransformStamped per mount, in scene order: parent frames.foundation, child the mount's
    frame (`Frames.mount_frame`), translation the mount's position (m, in F at the reference
    pose), rotation its axes relative to F (`mount_quaternion`). These frames are fixed in F:
    the mount axes of the wrench outputs are those of the reference pose.

    Args:
        stamp_ns: header stamp of every transform, ns (the replay uses the first input stamp;
            tf2 ignores the stamps of static transforms).

    Publish once, latched: TF_STATIC_TOPIC with reliable, transient_local, keep-last depth 1
    (tf2_ros' static broadcaster QoS), so late RViz/Foxglove subscribers still get it.
    """
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    frames = scene.frames
    transforms = [
        _transform_stamped(
            frames.foundation,
            frames.mount_frame(m.name),
            [sec, nanosec, *m.position, *mount_quaternion(m.orientation_rpy)],
        )
        for m in scene.mounts
    ]
    raw = bytes(TYPESTORE.serialize_cdr(_T[TF](transforms=transforms), TF))
    return TF_STATIC_TOPIC, int(stamp_ns), raw


def imu_messages(
    stamps_ns: np.ndarray,
    accel: np.ndarray,
    gyro: np.ndarray,
    frame_id: str,
    unprovided: np.ndarray | None = None,
) -> list[tuple[int, bytes]]:
    """sensor_msgs/Imu messages (no orientation estimate: orientation_covariance[0] = −1; the
    acceleration, the angular velocity marked not provided alike where `unprovided`, (k, 2),
    says so: REP-145)."""
    k = stamps_ns.shape[0]
    extra = np.zeros((k, 31))  # orientation (x, y, z, w), then three covariances
    extra[:, 3] = 1.0
    extra[:, 4] = -1.0  # orientation_covariance[0]
    if unprovided is not None:
        extra[unprovided[:, 1], 13] = -1.0  # angular_velocity_covariance[0]
        extra[unprovided[:, 0], 22] = -1.0  # linear_acceleration_covariance[0]
    sec, nsec = np.divmod(stamps_ns, 1_000_000_000)
    values = np.hstack([accel, gyro, extra])
    return list(zip(stamps_ns.tolist(), _pack(IMU, frame_id, sec, nsec, values), strict=True))
