"""ROS 2 messages ↔ engine data, through the rosbags typestore pinned to Jazzy.

The one place that (de)serializes: the live node moves raw CDR bytes and calls these functions,
the bag replay calls them too, so live and offline runs share every conversion. Field names are
the .msg names, the same in rosbags and rclpy.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from rosbags.typesys import Stores, get_typestore

from mount_twin.engine.batch import HealthReport, OutputBatch, SampleBatch
from mount_twin.scene.description import Scene

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
_T = TYPESTORE.types
IMU, ACCEL = "sensor_msgs/msg/Imu", "geometry_msgs/msg/AccelStamped"
POSE, VECTOR3, WRENCH = (
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/Vector3Stamped",
    "geometry_msgs/msg/WrenchStamped",
)
DIAGNOSTICS = "diagnostic_msgs/msg/DiagnosticArray"


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


def stamp_ns(header: object) -> int:
    """header.stamp as integer nanoseconds."""
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)  # type: ignore[attr-defined]


@dataclass
class Decoded:
    """Raw input messages decoded: stamps (ns), sensor-frame vectors and frame ids.

    `undecodable` counts messages that were not valid CDR of the expected type.
    """

    stamps_ns: np.ndarray
    accel: np.ndarray
    gyro: np.ndarray
    frame_ids: list[str]
    undecodable: int = 0

    def batch(self, base: TimeBase) -> SampleBatch:
        """Engine samples with stamps in seconds from `base`."""
        return SampleBatch(base.seconds(self.stamps_ns), self.accel, self.gyro, self.frame_ids)


def decode_inputs(raws: Sequence[bytes | memoryview], msgtype: str) -> Decoded:
    """Decode sensor_msgs/Imu (linear_acceleration, angular_velocity) or
    geometry_msgs/AccelStamped (accel.linear; its accel.angular is an angular acceleration, not a
    rate, so Ω is taken as zero)."""
    n = len(raws)
    stamps = np.zeros(n, dtype=np.int64)
    accel, gyro = np.zeros((n, 3)), np.zeros((n, 3))
    frames: list[str] = []
    keep = np.ones(n, dtype=bool)
    for i, raw in enumerate(raws):
        try:
            msg = TYPESTORE.deserialize_cdr(raw, msgtype)
        except Exception:
            keep[i] = False
            continue
        stamps[i] = stamp_ns(msg.header)
        frames.append(msg.header.frame_id)
        if msgtype == IMU:
            a, w = msg.linear_acceleration, msg.angular_velocity
            gyro[i] = (w.x, w.y, w.z)
        else:
            a = msg.accel.linear
        accel[i] = (a.x, a.y, a.z)
    return Decoded(stamps[keep], accel[keep], gyro[keep], frames, int(n - keep.sum()))


def _header(stamp_ns: int, frame_id: str) -> object:
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    return _T["std_msgs/msg/Header"](
        stamp=_T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec), frame_id=frame_id
    )


def _vector3(x: float, y: float, z: float) -> object:
    # float(): rclpy's converters abort on numpy scalars or ints in float64 fields.
    return _T["geometry_msgs/msg/Vector3"](x=float(x), y=float(y), z=float(z))


@dataclass(frozen=True)
class OutputTopics:
    """Output topic names before resolution ('~' is the node's namespace/name)."""

    pose: str
    angles: str
    wrenches: tuple[str, ...]
    diagnostics: str = "/diagnostics"


def output_topics(scene: Scene) -> OutputTopics:
    """The node's output names; remappable in ROS, resolved by `resolve` for bags."""
    return OutputTopics(
        "~/pose", "~/angles", tuple(f"~/mounts/{m.name}/wrench" for m in scene.mounts)
    )


def resolve(name: str, node_name: str, namespace: str = "/") -> str:
    """Resolve a private (~) or relative topic name as rclpy would, for a node without remaps."""
    ns = "/" + namespace.strip("/") if namespace.strip("/") else ""
    if name.startswith("~"):
        return f"{ns}/{node_name}{name[1:]}"
    return name if name.startswith("/") else f"{ns}/{name}"


def encode_outputs(
    scene: Scene, out: OutputBatch, stamps_ns: np.ndarray
) -> list[tuple[str, int, bytes]]:
    """CDR messages for an output batch as (unresolved topic, stamp ns, bytes), in the order the
    samples were processed; each diagnostics report follows the sample it was due at.

    Args:
        stamps_ns: (n,) header stamps of the pushed samples, integer ns; rows reuse them, so
            output stamps equal input stamps exactly however long the twin runs.

    Only the outputs the scene enables are built: unused outputs cost nothing.
    """
    topics = output_topics(scene)
    frames, opts = scene.frames, scene.outputs
    ser = TYPESTORE.serialize_cdr
    msgs: list[tuple[str, int, bytes]] = []
    reports = iter(out.health)
    report = next(reports, None)
    for k, (sample, stamp) in enumerate(
        zip(out.sample.tolist(), stamps_ns[out.sample].tolist(), strict=True)
    ):
        while report is not None and report.sample < sample:
            msgs.append(_diagnostics(report, int(stamps_ns[report.sample]), topics.diagnostics))
            report = next(reports, None)
        row = out.pose[k]
        if opts.pose:
            pose = _T["geometry_msgs/msg/Pose"](
                position=_T["geometry_msgs/msg/Point"](
                    x=float(row[0]), y=float(row[1]), z=float(row[2])
                ),
                orientation=_T["geometry_msgs/msg/Quaternion"](
                    x=float(row[3]), y=float(row[4]), z=float(row[5]), w=float(row[6])
                ),
            )
            msg = _T[POSE](header=_header(stamp, frames.foundation), pose=pose)
            msgs.append((topics.pose, stamp, ser(msg, POSE)))
        if opts.angles:
            msg = _T[VECTOR3](
                header=_header(stamp, frames.foundation), vector=_vector3(*row[7:10])
            )
            msgs.append((topics.angles, stamp, ser(msg, VECTOR3)))
        if opts.wrenches:
            for mount, topic, w in zip(
                scene.mounts, topics.wrenches, out.wrenches[k], strict=True
            ):
                wrench = _T["geometry_msgs/msg/Wrench"](
                    force=_vector3(*w[:3]), torque=_vector3(*w[3:])
                )
                msg = _T[WRENCH](header=_header(stamp, mount.name), wrench=wrench)
                msgs.append((topic, stamp, ser(msg, WRENCH)))
    while report is not None:
        msgs.append(_diagnostics(report, int(stamps_ns[report.sample]), topics.diagnostics))
        report = next(reports, None)
    return msgs


def _diagnostics(report: HealthReport, stamp_ns: int, topic: str) -> tuple[str, int, bytes]:
    msg = diagnostics_message(report, stamp_ns)
    return topic, stamp_ns, TYPESTORE.serialize_cdr(msg, DIAGNOSTICS)


def diagnostics_message(report: HealthReport, stamp_ns: int) -> object:
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
    """Unresolved topic → message type for every output the scene enables."""
    topics, opts = output_topics(scene), scene.outputs
    types = {topics.diagnostics: DIAGNOSTICS}
    if opts.pose:
        types[topics.pose] = POSE
    if opts.angles:
        types[topics.angles] = VECTOR3
    if opts.wrenches:
        types.update(dict.fromkeys(topics.wrenches, WRENCH))
    return types


def imu_messages(
    stamps_ns: np.ndarray, accel: np.ndarray, gyro: np.ndarray, frame_id: str
) -> list[tuple[int, bytes]]:
    """sensor_msgs/Imu messages (no orientation estimate: orientation_covariance[0] = −1)."""
    no_orientation = np.zeros(9)
    no_orientation[0] = -1.0
    unknown = np.zeros(9)
    quat = _T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
    out = []
    for stamp, a, w in zip(stamps_ns.tolist(), accel, gyro, strict=True):
        msg = _T[IMU](
            header=_header(stamp, frame_id),
            orientation=quat,
            orientation_covariance=no_orientation,
            angular_velocity=_vector3(*w),
            angular_velocity_covariance=unknown,
            linear_acceleration=_vector3(*a),
            linear_acceleration_covariance=unknown,
        )
        out.append((stamp, bytes(TYPESTORE.serialize_cdr(msg, IMU))))
    return out
