"""What a bag holds, as `ros2 bag info` shows it: files, size, storage identifier, span, and
each topic's type and message count."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from rosbags.highlevel import AnyReader

from mount_twin.errors import BagError
from mount_twin.io.bag_metadata import bag_metadata
from mount_twin.io.input_bag import STORAGE_IDS, reader_paths, storage_files
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


ROS1_STORAGE = "ROS 1"
"""The storage shown for a ROS 1 .bag file (rosbag2 has no identifier for it)."""


@dataclass(frozen=True)
class BagInfo:
    """A bag's path, storage files, storage identifier, first and last message's log time (ns),
    message count and topics."""

    path: Path
    files: list[Path]
    storage: str
    start_ns: int
    end_ns: int
    messages: int
    topics: list[TopicInfo]

    @property
    def size(self) -> int:
        """The storage files' bytes together (`ros2 bag info`'s "Bag size")."""
        return sum(f.stat().st_size for f in self.files)

    def text(self) -> str:
        """A `ros2 bag info`-like listing; the start and end to the ns, in integers (a float
        holds an epoch stamp to some 240 ns only)."""
        span = (self.end_ns - self.start_ns) * 1e-9 if self.messages else 0.0
        base = self.path if self.path.is_dir() else self.path.parent
        lines = [
            f"bag:       {self.path}",
            f"files:     {', '.join(str(f.relative_to(base)) for f in self.files)}",
            f"size:      {_bytes_text(self.size)}",
            f"storage:   {self.storage}",
            f"duration:  {span:.6f} s",
            f"start:     {_stamp_text(self.start_ns)} s (log time)"
            if self.messages
            else "start:     none (no message)",
            f"end:       {_stamp_text(self.end_ns)} s (log time)"
            if self.messages
            else "end:       none (no message)",
            f"messages:  {self.messages}",
            f"topics:    {len(self.topics)}  (name, type, messages)",
        ]
        width = max((len(t.name) for t in self.topics), default=0)
        lines += [f"  {t.name:<{width}}  {t.msgtype:<40} {t.count:>9}" for t in self.topics]
        return "\n".join(lines)


def _stamp_text(ns: int) -> str:
    return f"{ns // 10**9}.{ns % 10**9:09d}"


def _bytes_text(n: int) -> str:
    """`n` bytes in binary units as `ros2 bag info` gives them (KiB, MiB, GiB), and exactly."""
    units = ("B", "KiB", "MiB", "GiB", "TiB")
    k = 0
    while k + 1 < len(units) and n >= 1024 ** (k + 1):
        k += 1
    return f"{n} B" if k == 0 else f"{n / 1024**k:.1f} {units[k]} ({n} B)"


def _storage(path: Path) -> tuple[list[Path], str]:
    """The bag's files and storage identifier, as its metadata.yaml gives them (a compressed
    bag's files too), else as the storage files' suffixes say (mcap or sqlite3), else a ROS 1
    .bag file."""
    meta = bag_metadata(path) if path.is_dir() else {}
    if storage := meta.get("storage_identifier"):
        return [path / f for f in meta.get("relative_file_paths") or []], str(storage)
    if files := storage_files(path):
        return files, "/".join(sorted({STORAGE_IDS[f.suffix] for f in files}))
    return ([path], ROS1_STORAGE) if path.is_file() else ([], "unknown")


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
                Path(path),
                *_storage(Path(path)),
                reader.start_time,
                reader.end_time - 1,  # rosbags' end is 1 ns after the last message
                reader.message_count,
                topics,
            )
    except Exception as err:  # rosbags raises its own types for unreadable bags
        msg = f"{path}: cannot read the bag: {err}"
        raise BagError(msg) from err
