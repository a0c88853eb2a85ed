"""Rosbag2 input (mcap or sqlite3, any rosbags can read) and mcap output."""

from __future__ import annotations

import dataclasses
import re
import shutil
import sqlite3
import struct
import tempfile
from collections import Counter
from collections.abc import Generator, Iterator, Mapping, Sequence
from contextlib import suppress
from itertools import accumulate
from pathlib import Path
from types import TracebackType
from typing import Any

import yaml
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
from mount_twin.io.mcap_reader import Batch, plain_messages
from mount_twin.io.mcap_salvage import Salvage, salvage
from mount_twin.io.mcap_writer import McapBagWriter
from mount_twin.io.messages import TYPESTORE
from mount_twin.io.output_encoding import Encoded, RowBlock
from mount_twin.io.raw_rows import joined, nbytes
from mount_twin.textfiles import directories_above, new_directory_refusal

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
        part = salvage(file, topic) if file.suffix == ".mcap" else _salvage_sqlite(file, topic)
        out.messages += part.messages
        out.msgtype = out.msgtype or part.msgtype
        if part.damage:
            out.damage = part.damage
            break
    return out


def _salvage_sqlite(db: Path, topic: str) -> Salvage:
    """`topic`'s messages from a rosbag2 sqlite3 file in the order they were written (row id),
    up to the first unreadable row. The file is read from a temporary copy extended with zeros
    (sparse: no memory, whatever the header says) to the size its header gives: sqlite refuses
    a file cut short, but reads the pages before the cut. A row whose cell is damaged reads as
    id 0 and NULLs: the rows of all topics are scanned, so that one stops the salvage too (the
    data of other topics is not fetched). An empty file (a recorder killed before its first
    write) is damage from its first byte."""
    out = Salvage()
    try:
        if not db.stat().st_size:
            out.damage = f"{db}: empty file (0 bytes)"
            return out
        with tempfile.TemporaryDirectory(prefix="mount-twin-salvage-") as tmp:
            copy = Path(tmp) / db.name
            shutil.copyfile(db, copy)
            # A header giving a size no file system holds lies: the copy is read as it is.
            with copy.open("r+b") as file, suppress(OSError):
                file.truncate(_sqlite_size(file.read(100), copy.stat().st_size))
            con = sqlite3.connect(f"file:{copy}?mode=ro&immutable=1", uri=True)
            try:
                _read_sqlite_rows(con, db, topic, out)
            finally:
                con.close()
    except sqlite3.DatabaseError as err:
        out.damage = f"{db}: {err}"
    except OSError as err:
        out.damage = f"{db}: cannot salvage: {err.strerror or err}"
    return out


def _read_sqlite_rows(con: sqlite3.Connection, db: Path, topic: str, out: Salvage) -> None:
    """Into `out`: `topic`'s type and messages from the rosbag2 database `con` (of file `db`),
    up to the first unreadable row."""
    topics = con.execute("SELECT id, type FROM topics WHERE name = ?", (topic,)).fetchall()
    out.msgtype = topics[0][1] if topics else ""
    wanted = {tid for tid, _ in topics}
    rows = con.execute(
        "SELECT id, topic_id, timestamp, CASE WHEN topic_id IN "
        "(SELECT id FROM topics WHERE name = ?) THEN data END FROM messages ORDER BY id",
        (topic,),
    )
    last_id = 0
    for row_id, topic_id, stamp, raw in rows:
        if row_id <= last_id or stamp is None or (topic_id in wanted and raw is None):
            out.damage = f"{db}: the row after id {last_id} is unreadable"
            return
        last_id = row_id
        if topic_id in wanted:
            out.messages.append((int(stamp), bytes(raw)))


def _sqlite_size(header: bytes, size: int) -> int:
    """The size of an sqlite file of `size` bytes as its `header` (first 100 bytes) gives it
    (page size × page count), at least `size` rounded up to whole pages; `size` if the header
    is not sqlite's."""
    if len(header) < 100:
        return size
    (page,) = struct.unpack_from(">H", header, 16)
    page = 65536 if page == 1 else page
    if page < 512 or page & (page - 1):
        return size
    (pages,) = struct.unpack_from(">I", header, 28)
    return max(page * pages, -(-size // page) * page)


def _as_ros2(value: Any) -> Any:
    """A deserialized ROS 1 message (or field value) as the ROS 2 (Jazzy) message of the same
    name: the fields ROS 2 has are copied, those it lacks (header.seq) dropped."""
    name = getattr(value, "__msgtype__", None)
    if name is None:
        return [_as_ros2(v) for v in value] if isinstance(value, list) else value
    cls: Any = TYPESTORE.types[name]
    return cls(**{f.name: _as_ros2(getattr(value, f.name)) for f in dataclasses.fields(cls)})


PARTIAL_KEY = "mount_twin.partial"
"""custom_data key in an output bag's metadata.yaml present when the bag stops early."""
SCENE_KEY = "mount_twin.scene"
"""custom_data key in a replay's output bag's metadata.yaml: where its scene came from, as
text (the file as given, and the input settings the command line replaced: `Scene.source`;
and the values changed in code since: `io.scene_record.scene_name`)."""
SCENE_FILE_KEY = "mount_twin.scene_file"
"""custom_data key in a replay's output bag's metadata.yaml: its scene file's absolute path
(`Scene.origin`; '' for none)."""
SCENE_OVERRIDES_KEY = "mount_twin.scene_overrides"
"""custom_data key in a replay's output bag's metadata.yaml: what was put over its scene
file's values, a JSON object of flat parameter name (the command line's) or key path (a value
changed in code) → value (`io.scene_record.scene_overrides`)."""
SCENE_DIGEST_KEY = "mount_twin.scene_sha256"
"""custom_data key in a replay's output bag's metadata.yaml: its scene's digest
(`scene.description.scene_digest`), which `report --scene` checks its scene against."""
SCENE_VALUE_KEY = "mount_twin.scene_value"
"""custom_data key in a replay's output bag's metadata.yaml: its scene's value, the text its
digest hashes (`scene.description.value_text`), from which `report --scene` names the values a
scene differs in where the bag's ~/scene topic was left out."""


def custom_data(path: str | Path) -> dict[str, str]:
    """The custom_data of a bag's metadata.yaml ({} if it has none, or no metadata.yaml: a
    storage file given alone, or a bag a write failure left unfinished)."""
    custom = bag_metadata(path).get("custom_data") or {}
    if not isinstance(custom, dict):
        msg = f"{Path(path) / 'metadata.yaml'}: cannot read the bag's metadata: custom_data is "
        msg += f"not a mapping: {custom!r}"
        raise BagError(msg)
    return {str(k): str(v) for k, v in custom.items()}


def bag_metadata(path: str | Path) -> dict[str, Any]:
    """The rosbag2_bagfile_information of a bag's metadata.yaml ({} if it has no
    metadata.yaml: a storage file given alone, or a bag a write failure left unfinished);
    BagError naming the file if it cannot be read."""
    meta = Path(path) / "metadata.yaml"
    if not meta.is_file():
        return {}
    try:
        info = yaml.safe_load(meta.read_text(encoding="utf-8"))["rosbag2_bagfile_information"]
        if not isinstance(info, dict):
            raise TypeError(f"rosbag2_bagfile_information is not a mapping: {info!r}")
        return info
    except (
        OSError,
        UnicodeDecodeError,
        yaml.YAMLError,
        TypeError,
        KeyError,
        AttributeError,
    ) as err:
        msg = f"{meta}: cannot read the bag's metadata: {err}"
        raise BagError(msg) from err


def partial_marker(path: str | Path) -> str:
    """Why an output bag stops early, from its metadata.yaml (`PARTIAL_KEY`): '' if it does
    not, or has no metadata.yaml to say so (a storage file given alone)."""
    return custom_data(path).get(PARTIAL_KEY, "")


class OutputBag:
    """An mcap bag written by `io.mcap_writer`, message by message or in blocks of rows; log time
    = the message's stamp.

    Args:
        path: new bag directory (must not exist: an output bag is never overwritten); the
            directories missing above it are made (`textfiles.directories_above`).
        topics: resolved topic → message type.
        offered_qos: resolved topic → QoS profiles its publisher offered (recorded in the bag's
            metadata, replayed by `ros2 bag play`); topics not listed record none (the player's
            default, reliable and volatile).
        custom_data: key → text recorded in the bag's metadata (`ros2 bag info` shows them;
            a replay's scene: `io.scene_record.scene_metadata`).
    """

    def __init__(
        self,
        path: str | Path,
        topics: dict[str, str],
        offered_qos: Mapping[str, Sequence[Qos]] | None = None,
        custom_data: Mapping[str, str] | None = None,
    ) -> None:
        self.path = Path(path)
        check_new_bag(self.path)
        qos = {topic: list(profiles) for topic, profiles in (offered_qos or {}).items()}
        try:
            with directories_above(self.path):
                self._writer = McapBagWriter(self.path, topics, qos)
            self._writer.custom_data.update(custom_data or {})
        except OSError as err:
            msg = f"{self.path}: cannot create the bag: {err.strerror or err}"
            raise BagError(msg) from err
        self.written = 0
        self.last_stamp_ns: int | None = None
        self.partial: str | None = None
        """Why the bag is partial (then recorded in its metadata), or None: complete."""
        self._failed: OSError | None = None

    def write(self, encoded: Sequence[Encoded]) -> None:
        """Write serialized messages in order: each (topic, stamp ns, CDR bytes), or a block of
        rows of them (`RowBlock`, its topics resolved). A stamp before 1970 is refused before
        any of them is written; a failed write (a full disk) names the bag, which is then
        closed without its index (`close`)."""
        for item in encoded:
            if isinstance(item, RowBlock):
                if len(item.stamps_ns) and item.topics:
                    check_stamp(self.path, item.topics[0], int(item.stamps_ns.min()))
            else:
                check_stamp(self.path, item[0], item[1])
        try:
            singles: list[tuple[str, int, bytes]] = []
            for piece in encoded:
                if isinstance(piece, tuple):
                    singles.append(piece)
                    continue
                self._writer.write(singles)
                singles = []
                self._writer.write_rows(piece.topics, piece.stamps_ns, piece.rows)
            self._writer.write(singles)
        except OSError as err:
            self._failed = err
            msg = (
                f"{self.path}: cannot write: {err.strerror or err}, after {self._writer.durable} "
                f"messages; the bag is left unfinished (no index, no metadata.yaml)"
            )
            raise BagError(msg) from err
        for item in encoded:
            if isinstance(item, RowBlock):
                self.written += len(item.stamps_ns) * len(item.topics)
                if len(item.stamps_ns):
                    self.last_stamp_ns = int(item.stamps_ns[-1])
            else:
                self.written += 1
                self.last_stamp_ns = item[1]

    def mark_partial(self, reason: str) -> None:
        """Record in the bag's metadata (custom_data `mount_twin.partial`, which `ros2 bag
        info` shows) that it stops early, why, and at which stamp."""
        upto = (
            "nothing written"
            if self.last_stamp_ns is None
            else (f"outputs up to stamp {self.last_stamp_ns} ns")
        )
        self.partial = f"{reason}; {upto}"
        self._writer.custom_data[PARTIAL_KEY] = self.partial

    def close(self) -> None:
        """Finish the bag (writes its index and metadata); after a failed write, only close
        its file (the failure was said then)."""
        if self._failed is not None:
            self._abort()
            return
        try:
            self._writer.close()
        except OSError as err:
            self._abort()
            msg = f"{self.path}: cannot finish the bag: {err.strerror or err}"
            raise BagError(msg) from err

    def _abort(self) -> None:
        with suppress(OSError):  # flushing what is still buffered fails like the write did
            self._writer.abort()

    def __enter__(self) -> OutputBag:
        return self

    def __exit__(
        self, et: type[BaseException] | None, ev: BaseException | None, tb: TracebackType | None
    ) -> None:
        if et is not None and self.partial is None:  # stopped by an error or a signal
            self.mark_partial(f"stopped by {et.__name__}" + (f": {ev}" if str(ev) else ""))
        self.close()


def check_new_bag(path: str | Path) -> None:
    """Raise BagError if `path` exists (an output bag is always new: rosbags cannot overwrite)
    or no directory can be made there (`textfiles.new_directory_refusal`: a dangling symlink
    at or above it, a file above it)."""
    why = new_directory_refusal(path)
    if why == "exists":
        msg = f"{path}: output bag exists; choose another path or remove it"
        raise BagError(msg)
    if why:
        msg = f"{path}: cannot create the bag: {why}"
        raise BagError(msg)


LAST_STAMP_NS = (2**31 - 1) * 1_000_000_000 + 999_999_999
"""The last stamp a header holds: builtin_interfaces/Time's seconds are an int32, so 2**31 − 1 s
(2038-01-19T03:14:07Z); one later wraps to a negative second (1901–1970), silently."""


def check_stamp(path: str | Path, topic: str, stamp_ns: int) -> None:
    """Raise BagError if a bag cannot hold a message stamped `stamp_ns` (ns): one before 1970
    (a negative header.stamp.sec) would crash its writer and leave the file unreadable; one
    after LAST_STAMP_NS would be written with its header's seconds wrapped."""
    if stamp_ns < 0:
        msg = f"{path}: {topic}: stamp {stamp_ns} ns is before 1970: a bag cannot hold it"
        raise BagError(msg)
    if stamp_ns > LAST_STAMP_NS:
        msg = (
            f"{path}: {topic}: stamp {stamp_ns} ns is after 2038-01-19T03:14:07Z, the last "
            "a header holds (its seconds are an int32)"
        )
        raise BagError(msg)


def write_bag(
    path: str | Path,
    topic: str,
    msgtype: str,
    messages: Iterator[tuple[int, bytes]],
    storage: str = "mcap",
) -> int:
    """Write one topic's (stamp ns, CDR bytes) messages into a new bag; return the count. An
    existing `path` (`check_new_bag`) and a failed write (a full disk) name the bag. The
    directories missing above it are made; a write stopped before its first message removes
    the bag it began and them (`textfiles.directories_above`): an empty bag only blocked the
    rerun. One stopped later leaves the bag of the messages before, as rosbags closes it."""
    check_new_bag(path)
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    n, begun = 0, False
    with directories_above(path):
        try:
            with Writer(Path(path), version=Writer.VERSION_LATEST, storage_plugin=plugin) as w:
                begun = True  # the directory is this run's: Writer refuses one already there
                conn = w.add_connection(topic, msgtype, typestore=TYPESTORE)
                for stamp, raw in messages:
                    check_stamp(path, topic, stamp)
                    w.write(conn, stamp, raw)
                    n += 1
        except BaseException as err:
            removed = begun and n == 0
            if removed:
                shutil.rmtree(path, ignore_errors=True)
            if isinstance(err, OSError):
                msg = f"{path}: cannot write: {err.strerror or err}, after {n} messages"
                raise BagError(msg + ("; the bag begun is removed" if removed else "")) from err
            raise
    return n
