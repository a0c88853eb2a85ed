"""Bags written: a run's output bag (`OutputBag`: mcap by `io.mcap_writer`, message by
message or in blocks of rows, partial ones marked in their metadata), one topic's messages
into a new bag (`write_bag`, through rosbags), and what both check first: a new path, stamps
a header holds. `LATCHED_QOS`: the QoS a latched topic's publisher offers, recorded for
`ros2 bag play`."""

from __future__ import annotations

import shutil
from collections.abc import Iterator, Mapping, Sequence
from contextlib import suppress
from pathlib import Path
from types import TracebackType

from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import StoragePlugin, Writer

from mount_twin.errors import BagError
from mount_twin.io.bag_metadata import PARTIAL_KEY
from mount_twin.io.mcap_writer import McapBagWriter
from mount_twin.io.messages import TYPESTORE
from mount_twin.io.output_encoding import Encoded, RowBlock
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
