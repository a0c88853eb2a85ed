"""ROS 2 message types through the rosbags typestore pinned to Jazzy: the types' and topics'
names, the node's name its private topics resolve against, and each fixed-layout type's message
built from its fields, with its layout (`io.fixed_layout`).

With `input_decoding` (input messages → engine samples), `output_topics` (the outputs
declared) and `output_encoding` (engine outputs → messages), the one place that
(de)serializes: the live node moves raw CDR bytes and calls these functions, the bag replay
calls them too, so live and offline runs share every conversion. Field names are the .msg
names, the same in rosbags and rclpy.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import lru_cache, partial
from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_typestore

from mount_twin.io.fixed_layout import FixedLayout

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


def stamped_header(stamp_ns: int, frame_id: str) -> Any:
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


def transform_stamped(parent: str, child: str, v: Sequence[float]) -> Any:
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
    """TFMessage of one transform parent → child, from the fields of `transform_stamped`."""
    return _T[TF](transforms=[transform_stamped(parent, child, v)])


BUILDERS: dict[str, tuple[Callable[..., Any], int]] = {
    IMU: (_build_imu, 37),
    ACCEL: (_build_accel, 6),
    POSE: (_build_pose, 7),
    VECTOR3: (_build_vector3, 3),
    WRENCH: (_build_wrench, 6),
    TF: (_build_tf, 7),
}
"""Builder and number of float64 fields (after sec, nanosec) of each fixed-layout type; the
builders take the message's frame ids first (TF: parent, child; the others: header.frame_id)."""


@lru_cache(maxsize=256)
def layout_of(msgtype: str, *frames: str) -> FixedLayout:
    """Layout of `msgtype` with these frame ids (see `BUILDERS`)."""
    build, n_floats = BUILDERS[msgtype]
    return FixedLayout.probe(
        partial(build, *frames),
        ["<i4", "<u4"] + ["<f8"] * n_floats,
        partial(TYPESTORE.serialize_cdr, typename=msgtype),
    )


def pack_messages(
    msgtype: str,
    frames: str | tuple[str, ...],
    sec: np.ndarray,
    nsec: np.ndarray,
    values: np.ndarray,
) -> list[bytes]:
    """Messages of one type and frame id(s) for stamps (sec, nanosec) and rows of float fields."""
    frames = (frames,) if isinstance(frames, str) else frames
    return layout_of(msgtype, *frames).pack([sec, nsec, values])


DIAGNOSTICS_TOPIC = "/diagnostics"


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
