"""What a bag holds, as `ros2 bag info` shows it: storage, span, and each topic's type and
message count."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from rosbags.highlevel import AnyReader

from mount_twin.errors import BagError
from mount_twin.io.bag import reader_paths
from mount_twin.io.messages import TYPESTORE


def require_existing(path: str | Path) -> None:
    """BagError naming `path` if nothing is there (rosbags says "The following paths are
    missing: [PosixPath(...)]")."""
    if not Path(path).exists():
        msg = f"{path}: no such file or directory"
        raise BagError(msg)


@dataclass(frozen=True)
class TopicInfo:
    """One topic: name, message type, message count."""

    name: str
    msgtype: str
    count: int


@dataclass(frozen=True)
class BagInfo:
    """A bag's path, first and last log time (ns), message count and topics."""

    path: Path
    start_ns: int
    end_ns: int
    messages: int
    topics: list[TopicInfo]

    def text(self) -> str:
        """A `ros2 bag info`-like listing; the start to the ns, in integers (a float holds
        an epoch stamp to some 240 ns only)."""
        span = (self.end_ns - self.start_ns) * 1e-9 if self.messages else 0.0
        lines = [
            f"bag:       {self.path}",
            f"duration:  {span:.6f} s",
            f"start:     {self.start_ns // 10**9}.{self.start_ns % 10**9:09d} s (log time)"
            if self.messages
            else "start:     none (no message)",
            f"messages:  {self.messages}",
            "topics:",
        ]
        width = max((len(t.name) for t in self.topics), default=0)
        lines += [f"  {t.name:<{width}}  {t.msgtype:<40} {t.count:>9}" for t in self.topics]
        return "\n".join(lines)


def bag_info(path: str | Path) -> BagInfo:
    """Read a bag's metadata (mcap, sqlite3 or ROS 1, as rosbags reads them); errors name it."""
    require_existing(path)
    try:
        with AnyReader(reader_paths(Path(path)), default_typestore=TYPESTORE) as reader:
            topics = sorted(
                (TopicInfo(c.topic, c.msgtype, c.msgcount) for c in reader.connections),
                key=lambda t: t.name,
            )
            return BagInfo(
                Path(path), reader.start_time, reader.end_time, reader.message_count, topics
            )
    except Exception as err:  # rosbags raises its own types for unreadable bags
        msg = f"{path}: cannot read the bag: {err}"
        raise BagError(msg) from err
