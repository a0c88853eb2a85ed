"""A bag's input topic read in chunks of raw CDR messages: a plain mcap file through
`io.mcap_reader`, any other bag rosbags can read through rosbags (mcap or sqlite3; ROS 1
converted to the ROS 2 messages of the same names), and a bag rosbags cannot open, or that is
damaged past some message, from its storage files up to the damage (`io.mcap_salvage`,
`io.sqlite_salvage`). Also the bag's storage files in recording order, and what rosbags'
reader is to open."""

from __future__ import annotations

import dataclasses
import re
import struct
from collections import Counter
from collections.abc import Generator, Iterator, Sequence
from contextlib import suppress
from itertools import accumulate
from pathlib import Path
from types import TracebackType
from typing import Any

from rosbags.highlevel import AnyReader

from mount_twin.errors import BagError, DamagedBagError
from mount_twin.io.mcap_reader import Batch, plain_messages
from mount_twin.io.mcap_salvage import Salvage, salvage
from mount_twin.io.messages import TYPESTORE
from mount_twin.io.raw_rows import joined, nbytes
from mount_twin.io.sqlite_salvage import salvage_sqlite


class InputBag:
    """The input topic of a bag, read in chunks of raw CDR messages.

    A bag rosbags cannot open (a recorder killed mid-write leaves its last file cut short and no
    metadata.yaml) is read from its storage files directly, in order, up to the first damage.

    Args:
        path: bag directory, or one storage file (.mcap, .db3, ROS 1 .bag).
        topic: input topic.
        msgtype: expected message type; a different one is an error naming both.
        keys: what sets the topic and the type, for errors.
    """

    def __init__(
        self,
        path: str | Path,
        topic: str,
        msgtype: str,
        keys: tuple[str, str] = ("input.topic; `replay --topic` overrides it", "input.msg_type"),
    ) -> None:
        self.path = Path(path)
        self.topic = topic
        self.msgtype = msgtype
        self._salvage: Salvage | None = None
        self.last_log_ns = 0
        """The log time (ns, the recorder's clock) of the topic's last message read (0: none
        yet): at the end of the chunks, when the input ended."""
        try:
            self._reader = _open_reader(reader_paths(self.path))
        except Exception as err:
            files = storage_files(self.path)
            if not files:
                raise _not_a_bag(self.path, err) from err
            try:  # the storage files of a directory without (a readable) metadata.yaml
                self._reader = _open_reader(files)
            except Exception:
                self._open_damaged(files, err)
                return
        conns = [c for c in self._reader.connections if c.topic == topic]
        self.count = sum(c.msgcount for c in conns)
        if not self.count:
            have = _topic_list(self._reader)
            self._reader.close()  # after listing: a closed reader has no connections
            what = "no message on topic" if conns else "no topic"
            msg = f"{self.path}: {what} {topic!r} ({keys[0]}); the bag has: {have or 'no topic'}"
            raise BagError(msg)
        wrong = [c.msgtype for c in conns if c.msgtype != msgtype]
        if wrong:
            self._reader.close()
            msg = f"{self.path}: topic {topic!r} has type {wrong[0]}, {keys[1]} says {msgtype}"
            raise BagError(msg)
        self._conns = conns
        self.ros1 = not self._reader.is2
        """A ROS 1 bag: its messages are converted to the ROS 2 (Jazzy) CDR the twin reads."""

    def _open_damaged(self, files: list[Path], err: Exception) -> None:
        """After rosbags could not open the bag: read the topic's messages from its storage files
        up to the first damage, or raise BagError naming the bag."""
        self._salvage = _salvage(files, self.topic)
        if not self._salvage.messages:
            why = (
                f"no message of {self.topic} comes before its damage ({self._salvage.damage})"
                if self._salvage.damage
                else f"its storage files hold no message of {self.topic}"
            )
            unmarked = self.path.is_dir() and not (self.path / "metadata.yaml").exists()
            cause = "no metadata.yaml" if unmarked else err  # rosbags names the directory
            msg = f"{self.path}: cannot open bag ({cause}), and {why}"
            raise BagError(msg) from err
        if self._salvage.msgtype and self._salvage.msgtype != self.msgtype:
            msg = (
                f"{self.path}: topic {self.topic!r} has type {self._salvage.msgtype}, "
                f"input.msg_type says {self.msgtype}"
            )
            raise BagError(msg)
        self.count = len(self._salvage.messages)
        self.ros1 = False

    def chunks(self, size: int) -> Iterator[Sequence[bytes]]:
        """Raw messages of the topic in log-time order, `size` at a time, fewer where they
        reach CHUNK_MAX_BYTES (1 MB frame ids: 2 GB a chunk): lists of bytes, or `RawRows`
        where a plain mcap chunk holds them as rows of one length. From a damaged bag,
        those before the damage, then DamagedBagError saying how many and up to which log
        time."""
        if self._salvage is not None:
            yield from self._salvaged_chunks(self._salvage, 0, size)
            return
        parts: list[Sequence[bytes]] = []  # read, not yet yielded
        read, last, held, count = 0, None, 0, 0
        batches = self._batches()
        while True:
            try:
                times, raws = next(batches)
            except StopIteration:
                break
            except Exception as err:  # rosbags' readers raise their own types on damage
                yield from _pieces(joined(parts), size, everything=True)
                rest = self._salvage_after(read)
                if rest is not None:
                    yield from self._salvaged_chunks(rest, read, size)
                msg = (
                    f"{self.path}: damaged after {read} of {self.count} messages of "
                    f"{self.topic}{_up_to(last)}: {err}"
                )
                raise DamagedBagError(msg) from err
            if self.ros1:
                raws = [self._ros1_to_cdr(raw) for raw in raws]
            parts.append(raws)
            read, last, held, count = (
                read + len(raws),
                int(times[-1]),
                held + nbytes(raws),
                count + len(raws),
            )
            self.last_log_ns = last
            if count >= size or held >= CHUNK_MAX_BYTES:
                left = yield from _pieces(joined(parts), size)
                parts, held, count = [left] if len(left) else [], nbytes(left), len(left)
        yield from _pieces(joined(parts), size, everything=True)
        if read < self.count:  # records lost without an error: zeroed or overwritten bytes
            msg = (
                f"{self.path}: damaged: its index lists {self.count} messages of {self.topic}, "
                f"only {read} could be read: those lost inside the file were skipped"
            )
            raise DamagedBagError(msg)

    def _batches(self) -> Iterator[Batch]:
        """The topic's log times and raw messages in log-time order, in batches: a chunk's from
        a bag of one plain mcap file (`io.mcap_reader`), one at a time from rosbags
        otherwise."""
        files = storage_files(self.path)
        if not self.ros1 and len(files) == 1 and files[0].suffix == ".mcap":
            with suppress(ValueError, struct.error, UnicodeDecodeError, OSError):
                plain = plain_messages(files[0], self.topic)
                if plain is not None:
                    return plain
        return (([log_time], [raw]) for _, log_time, raw in self._reader.messages(self._conns))

    def _salvage_after(self, read: int) -> Salvage | None:
        """After rosbags failed past `read` messages: the messages after those (in file order,
        the order rosbags read them in) that the mcap files hold before a damage found record
        by record (rosbags reads an mcap chunk whole, so a damaged record loses the chunk's
        messages before it), or None if no damage is found that way."""
        files = [f for f in storage_files(self.path) if f.suffix == ".mcap"]
        found = _salvage(files, self.topic)
        if not found.damage or len(found.messages) <= read:
            return None
        return Salvage(found.messages[read:], found.msgtype, found.damage)

    def _salvaged_chunks(self, salvaged: Salvage, before: int, size: int) -> Iterator[list[bytes]]:
        """The salvaged messages, `size` at a time, then DamagedBagError if they end at a
        damage (`before`: messages of the topic read before them)."""
        raws = [raw for _, raw in salvaged.messages]
        for k in range(0, len(raws), size):
            self.last_log_ns = salvaged.messages[min(k + size, len(raws)) - 1][0]
            yield raws[k : k + size]
        if salvaged.damage:
            msg = (
                f"{self.path}: damaged ({salvaged.damage}); the {before + len(raws)} messages "
                f"of {self.topic} before the damage{_up_to(salvaged.messages[-1][0])} were "
                "read"
            )
            raise DamagedBagError(msg)

    def _ros1_to_cdr(self, raw: bytes) -> bytes:
        """A ROS 1 message as CDR of the ROS 2 message of the same name; one that cannot be
        read becomes empty, which the stream counts as undecodable."""
        try:
            ros2 = _as_ros2(self._reader.deserialize(raw, self.msgtype))
        except Exception:  # any malformed ROS 1 message: counted downstream, never raised
            return b""
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


def reader_paths(path: Path) -> list[Path]:
    """What rosbags' AnyReader is to open for the bag at `path`: the path, or, for a rosbag2
    directory whose name ends in .bag (`ros2 bag record -o run.bag` makes one), its storage
    files: AnyReader takes any name ending in .bag for a ROS 1 file ("Is a directory")."""
    if path.suffix == ".bag" and path.is_dir():
        return storage_files(path) or [path]
    return [path]


def _open_reader(paths: list[Path]) -> AnyReader:
    reader = AnyReader(paths, default_typestore=TYPESTORE)
    reader.open()
    return reader


def _topic_list(reader: AnyReader) -> str:
    """The reader's topics as 'topic (type, N messages)', sorted."""
    counts: Counter[tuple[str, str]] = Counter()
    for c in reader.connections:
        counts[c.topic, c.msgtype] += c.msgcount
    return ", ".join(f"{t} ({m}, {n} messages)" for (t, m), n in sorted(counts.items()))


def _up_to(log_time_ns: int | None) -> str:
    return "" if log_time_ns is None else f" (up to log time {log_time_ns} ns)"


CHUNK_MAX_BYTES = 32 << 20
"""Most bytes of raw messages in one chunk (2000 Imu messages with short frame ids: 0.7 MB)."""
STORAGE_IDS = {".mcap": "mcap", ".db3": "sqlite3"}
"""rosbag2 storage files that can be read without the bag's metadata.yaml, by suffix: their
storage identifier (metadata.yaml's `storage_identifier`, `ros2 bag info`'s "Storage id")."""
STORAGE_SUFFIXES = tuple(STORAGE_IDS)


def _pieces(
    pending: Sequence[bytes], size: int, *, everything: bool = False
) -> Generator[Sequence[bytes], None, Sequence[bytes]]:
    """Yield `size` messages at a time of `pending`, fewer where they reach CHUNK_MAX_BYTES;
    return what is left short of a piece (nothing with `everything`)."""
    at = 0
    while len(pending) - at >= size or (everything and at < len(pending)):
        piece = pending[at : at + size]
        if nbytes(piece) >= CHUNK_MAX_BYTES:
            held = accumulate(map(len, piece))
            piece = piece[: next(k for k, h in enumerate(held) if h >= CHUNK_MAX_BYTES) + 1]
        yield piece
        at += len(piece)
    return pending[at:]


def storage_files(path: Path) -> list[Path]:
    """The rosbag2 storage files of the bag at `path` (itself, if it is one) in recording order:
    rosbag2 numbers split files NAME_0, NAME_1, ..."""
    if path.is_dir():
        return sorted(
            (f for f in path.iterdir() if f.suffix in STORAGE_SUFFIXES), key=_split_index
        )
    return [path] if path.suffix in STORAGE_SUFFIXES and path.is_file() else []


def _not_a_bag(path: Path, err: Exception) -> BagError:
    """Why `path`, which rosbags could not open (`err`) and which has no storage file, is no
    bag."""
    if path.is_dir():
        why = (
            f"no metadata.yaml and no {' or '.join(STORAGE_SUFFIXES)} file"
            if any(path.iterdir())
            else "an empty directory"
        )
    elif not path.exists():
        why = "no such file or directory"
    elif path.suffix == ".bag":
        why = f"{err} (`rosbag reindex` rebuilds a ROS 1 bag's index)"
    else:
        why = str(err)
    return BagError(f"{path}: cannot open bag: {why}")


def _split_index(file: Path) -> tuple[int, str]:
    number = re.search(r"_(\d+)$", file.stem)
    return (int(number.group(1)) if number else -1, file.name)


def _salvage(files: list[Path], topic: str) -> Salvage:
    """`topic`'s messages from storage files read in order, up to the first damage."""
    out = Salvage()
    for file in files:
        part = salvage(file, topic) if file.suffix == ".mcap" else salvage_sqlite(file, topic)
        out.messages += part.messages
        out.msgtype = out.msgtype or part.msgtype
        if part.damage:
            out.damage = part.damage
            break
    return out


def _as_ros2(value: Any) -> Any:
    """A deserialized ROS 1 message (or field value) as the ROS 2 (Jazzy) message of the same
    name: the fields ROS 2 has are copied, those it lacks (header.seq) dropped."""
    name = getattr(value, "__msgtype__", None)
    if name is None:
        return [_as_ros2(v) for v in value] if isinstance(value, list) else value
    cls: Any = TYPESTORE.types[name]
    return cls(**{f.name: _as_ros2(getattr(value, f.name)) for f in dataclasses.fields(cls)})
