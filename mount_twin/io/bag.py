"""Rosbag2 input (mcap or sqlite3, any rosbags can read) and mcap output."""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from types import TracebackType
from typing import Any

from rosbags.highlevel import AnyReader
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import StoragePlugin, Writer

from mount_twin.errors import BagError, DamagedBagError
from mount_twin.io.mcap_salvage import Salvage, salvage
from mount_twin.io.messages import TYPESTORE

_INFINITE = QosTime(9223372036, 854775807)
"""RMW_DURATION_INFINITE (sec, nsec), as a Jazzy recording stores a default deadline/lifespan."""

LATCHED_QOS = Qos(
    QosHistory.KEEP_LAST,
    1,
    QosReliability.RELIABLE,
    QosDurability.TRANSIENT_LOCAL,
    _INFINITE,
    _INFINITE,
    QosLiveliness.AUTOMATIC,
    _INFINITE,
    False,
)
"""Offered QoS of a latched topic (tf2_ros' static broadcaster: reliable, transient_local, depth
1): stored in the bag's metadata so `ros2 bag play` offers it again and republishes /tf_static to
late subscribers."""


class InputBag:
    """The input topic of a bag, read in chunks of raw CDR messages.

    Args:
        path: bag directory (or file rosbags accepts).
        topic: input topic.
        msgtype: expected message type; a different one is an error naming both.
    """

    def __init__(self, path: str | Path, topic: str, msgtype: str) -> None:
        self.path = Path(path)
        self.topic = topic
        self.msgtype = msgtype
        self._salvage: Salvage | None = None
        try:
            self._reader = AnyReader([self.path], default_typestore=TYPESTORE)
            self._reader.open()
        except Exception as err:
            self._open_damaged(err)
            return
        conns = [c for c in self._reader.connections if c.topic == topic]
        if not conns:
            have = ", ".join(
                sorted(
                    {
                        f"{c.topic} ({c.msgtype}, {c.msgcount} messages)"
                        for c in self._reader.connections
                    }
                )
            )
            self._reader.close()  # after listing: a closed reader has no connections
            msg = (
                f"{self.path}: no topic {topic!r} (input.topic; `replay --topic` overrides it); "
                f"the bag has: {have or 'no topic'}"
            )
            raise BagError(msg)
        wrong = [c.msgtype for c in conns if c.msgtype != msgtype]
        if wrong:
            self._reader.close()
            msg = (
                f"{self.path}: topic {topic!r} has type {wrong[0]}, input.msg_type says {msgtype}"
            )
            raise BagError(msg)
        self._conns = conns
        self.count = sum(c.msgcount for c in conns)
        self.ros1 = not self._reader.is2
        """A ROS 1 bag: its messages are converted to the ROS 2 (Jazzy) CDR the twin reads."""

    def _open_damaged(self, err: Exception) -> None:
        """After rosbags could not open the bag: read what an mcap file holds before its
        damage (`mcap_salvage`), or raise BagError naming the bag."""
        found = [self.path] if self.path.suffix == ".mcap" else sorted(self.path.glob("*.mcap"))
        if not found or not found[0].is_file():
            msg = f"{self.path}: cannot open bag: {err}"
            raise BagError(msg) from err
        self._salvage = salvage(found[0], self.topic)
        if not self._salvage.messages:
            msg = (
                f"{self.path}: cannot open bag ({err}), and no message of {self.topic} comes "
                f"before its damage ({self._salvage.damage or 'none found'})"
            )
            raise BagError(msg) from err
        if self._salvage.msgtype and self._salvage.msgtype != self.msgtype:
            msg = (
                f"{self.path}: topic {self.topic!r} has type {self._salvage.msgtype}, "
                f"input.msg_type says {self.msgtype}"
            )
            raise BagError(msg)
        self.count = len(self._salvage.messages)
        self.ros1 = False

    def chunks(self, size: int) -> Iterator[list[bytes]]:
        """Raw messages of the topic in log-time order, `size` at a time. From a damaged bag,
        those before the damage, then DamagedBagError."""
        if self._salvage is not None:
            raws = [raw for _, raw in self._salvage.messages]
            for k in range(0, len(raws), size):
                yield raws[k : k + size]
            msg = (
                f"{self.path}: damaged ({self._salvage.damage}); the {len(raws)} messages of "
                f"{self.topic} before the damage were replayed"
            )
            raise DamagedBagError(msg)
        chunk: list[bytes] = []
        done = 0
        messages = self._reader.messages(connections=self._conns)
        while True:
            try:
                _, _, raw = next(messages)
            except StopIteration:
                break
            except Exception as err:  # rosbags' readers raise their own types on damage
                if chunk:
                    yield chunk
                msg = (
                    f"{self.path}: damaged after {done + len(chunk)} of {self.count} messages "
                    f"of {self.topic}: {err}"
                )
                raise DamagedBagError(msg) from err
            chunk.append(self._ros1_to_cdr(raw) if self.ros1 else raw)
            if len(chunk) == size:
                yield chunk
                done += size
                chunk = []
        if chunk:
            yield chunk

    def _ros1_to_cdr(self, raw: bytes) -> bytes:
        """A ROS 1 message as the ROS 2 message of the same name, CDR-serialized: the fields
        the twin reads are copied (ROS 1's header.seq has no ROS 2 counterpart)."""
        msg: Any = self._reader.deserialize(raw, self.msgtype)
        t = TYPESTORE.types
        header = t["std_msgs/msg/Header"](
            stamp=t["builtin_interfaces/msg/Time"](
                sec=msg.header.stamp.sec, nanosec=msg.header.stamp.nanosec
            ),
            frame_id=msg.header.frame_id,
        )
        ros2: Any
        if self.msgtype == "sensor_msgs/msg/Imu":
            ros2 = t[self.msgtype](
                header=header,
                orientation=t["geometry_msgs/msg/Quaternion"](
                    x=msg.orientation.x,
                    y=msg.orientation.y,
                    z=msg.orientation.z,
                    w=msg.orientation.w,
                ),
                orientation_covariance=msg.orientation_covariance,
                angular_velocity=_vector3(msg.angular_velocity),
                angular_velocity_covariance=msg.angular_velocity_covariance,
                linear_acceleration=_vector3(msg.linear_acceleration),
                linear_acceleration_covariance=msg.linear_acceleration_covariance,
            )
        else:  # geometry_msgs/msg/AccelStamped
            ros2 = t[self.msgtype](
                header=header,
                accel=t["geometry_msgs/msg/Accel"](
                    linear=_vector3(msg.accel.linear), angular=_vector3(msg.accel.angular)
                ),
            )
        return bytes(TYPESTORE.serialize_cdr(ros2, self.msgtype))

    def close(self) -> None:
        """Close the bag."""
        if self._salvage is None:
            self._reader.close()

    def __enter__(self) -> InputBag:
        return self

    def __exit__(
        self, et: type[BaseException] | None, ev: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()


def _vector3(v: Any) -> Any:
    """A geometry_msgs/Vector3 of the ROS 2 typestore with v's x, y, z."""
    return TYPESTORE.types["geometry_msgs/msg/Vector3"](x=v.x, y=v.y, z=v.z)


PARTIAL_KEY = "mount_twin.partial"
"""custom_data key in an output bag's metadata.yaml present when the bag stops early."""


class OutputBag:
    """An mcap bag written topic by topic; log time = the message's stamp.

    Args:
        path: new bag directory (must not exist: rosbags refuses to overwrite).
        topics: resolved topic → message type.
        offered_qos: resolved topic → QoS profiles its publisher offered (recorded in the bag's
            metadata, replayed by `ros2 bag play`); topics not listed record none (the player's
            default, reliable and volatile).
    """

    def __init__(
        self,
        path: str | Path,
        topics: dict[str, str],
        offered_qos: Mapping[str, Sequence[Qos]] | None = None,
    ) -> None:
        self.path = Path(path)
        check_new_bag(self.path)
        self._writer = Writer(
            self.path, version=Writer.VERSION_LATEST, storage_plugin=StoragePlugin.MCAP
        )
        self._writer.open()
        qos = offered_qos or {}
        self._conns = {
            topic: self._writer.add_connection(
                topic, msgtype, typestore=TYPESTORE, offered_qos_profiles=qos.get(topic, ())
            )
            for topic, msgtype in topics.items()
        }
        self.written = 0
        self.last_stamp_ns: int | None = None
        self.partial: str | None = None
        """Why the bag is partial (then recorded in its metadata), or None: complete."""

    def write(self, topic: str, stamp_ns: int, raw: bytes | memoryview) -> None:
        """Write one serialized message; a failed write names the bag."""
        try:
            self._writer.write(self._conns[topic], stamp_ns, raw)
        except OSError as err:
            msg = f"{self.path}: cannot write: {err.strerror or err}"
            raise BagError(msg) from err
        self.written += 1
        self.last_stamp_ns = stamp_ns

    def mark_partial(self, reason: str) -> None:
        """Record in the bag's metadata (custom_data `mount_twin.partial`, which `ros2 bag
        info` shows) that it stops early, why, and at which stamp."""
        upto = (
            "nothing written"
            if self.last_stamp_ns is None
            else (f"outputs up to stamp {self.last_stamp_ns} ns")
        )
        self.partial = f"{reason}; {upto}"
        self._writer.set_custom_data(PARTIAL_KEY, self.partial)

    def close(self) -> None:
        """Finish the bag (writes its metadata)."""
        self._writer.close()

    def __enter__(self) -> OutputBag:
        return self

    def __exit__(
        self, et: type[BaseException] | None, ev: BaseException | None, tb: TracebackType | None
    ) -> None:
        if et is not None and self.partial is None:  # stopped by an error or a signal
            self.mark_partial(f"stopped by {et.__name__}" + (f": {ev}" if str(ev) else ""))
        self.close()


def check_new_bag(path: str | Path) -> None:
    """Raise BagError if `path` exists: an output bag is always new (rosbags cannot overwrite)."""
    if Path(path).exists():
        msg = f"{path}: output bag exists; choose another path or remove it"
        raise BagError(msg)


def write_bag(
    path: str | Path,
    topic: str,
    msgtype: str,
    messages: Iterator[tuple[int, bytes]],
    storage: str = "mcap",
) -> int:
    """Write one topic's (stamp ns, CDR bytes) messages into a new bag; return the count."""
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    n = 0
    with Writer(Path(path), version=Writer.VERSION_LATEST, storage_plugin=plugin) as writer:
        conn = writer.add_connection(topic, msgtype, typestore=TYPESTORE)
        for stamp, raw in messages:
            writer.write(conn, stamp, raw)
            n += 1
    return n
