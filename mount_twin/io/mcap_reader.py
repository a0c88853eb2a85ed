"""One topic's messages of an intact, indexed mcap file, read a chunk at a time in log-time
order: the order rosbags' reader yields them in, at a fraction of its per-message cost (it
parses each record through a few small reads; here one `struct` call walks a record, and a
chunk of one IMU of one frame_id, its records all of one length, is read in one numpy pass).

Only the plain case is read here, the case of every bag a recorder or rosbags writes in time
order: a summary with chunk indexes whose chunks do not overlap in time. Within a chunk the
messages are sorted by log time, stably (as rosbags does). Anything else (no summary, chunks
that overlap, a split bag) is left to rosbags (`plain_messages` returns None); a chunk found
damaged while reading raises ValueError (`io.input_bag` then salvages what the file holds).
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from itertools import pairwise
from operator import itemgetter
from pathlib import Path
from typing import BinaryIO

import numpy as np

from mount_twin.io.mcap_format import (
    CHANNEL,
    CHUNK_HEAD,
    CHUNK_INDEX,
    FOOTER,
    MAGIC,
    MESSAGE,
    MESSAGE_HEAD,
    MESSAGE_HEAD_DTYPE,
    decompress,
    read_string,
)
from mount_twin.io.raw_rows import RawRows

_FOOTER_BYTES = 9 + 20 + len(MAGIC)


@dataclass(frozen=True)
class _ChunkAt:
    """A chunk as its index gives it: time span (ns), where it is and how it is stored."""

    start: int
    end: int
    offset: int
    length: int
    compression: str


def _summary(f: BinaryIO, size: int) -> tuple[dict[int, str], list[_ChunkAt]] | None:
    """Channel id → topic and the chunk indexes, from the file's summary; None without one."""
    if size < len(MAGIC) * 2 + _FOOTER_BYTES:
        return None
    f.seek(size - _FOOTER_BYTES)
    tail = f.read(_FOOTER_BYTES)
    if tail[-len(MAGIC) :] != MAGIC or tail[0] != FOOTER:
        return None
    summary_at, offsets_at, _ = struct.unpack_from("<QQI", tail, 9)
    if not summary_at or not len(MAGIC) <= summary_at <= size - _FOOTER_BYTES:
        return None
    f.seek(summary_at)
    body = f.read((offsets_at or size - _FOOTER_BYTES) - summary_at)
    topics: dict[int, str] = {}
    chunks: list[_ChunkAt] = []
    at = 0
    while at + 9 <= len(body):
        op = body[at]
        (length,) = struct.unpack_from("<Q", body, at + 1)
        rec = at + 9
        if op == CHANNEL:
            (cid,) = struct.unpack_from("<H", body, rec)
            topics[cid], _ = read_string(body, rec + 4)
        elif op == CHUNK_INDEX:
            start, end, offset, chunk_length = struct.unpack_from("<QQQQ", body, rec)
            (map_bytes,) = struct.unpack_from("<I", body, rec + 32)
            compression, _ = read_string(body, rec + 36 + map_bytes + 8)
            chunks.append(_ChunkAt(start, end, offset, chunk_length, compression))
        at = rec + length
    return topics, chunks


def _in_order(chunks: list[_ChunkAt]) -> bool:
    """Whether reading the chunks one after the other yields log-time order as rosbags' merge
    of them does (ties between chunks go to the one earlier in the file)."""
    for a, b in pairwise(chunks):
        if b.start < a.end or (b.start == a.end and b.offset < a.offset):
            return False
    return True


Batch = tuple[Sequence[int] | np.ndarray, Sequence[bytes]]
"""A chunk's messages of the topic: their log times (ns) and raw CDR, in log-time order."""


def plain_messages(file: Path, topic: str) -> Iterator[Batch] | None:
    """The messages of `topic` in `file` in log-time order, a chunk's at a time (a chunk
    without the topic gives none; a chunk of one length gives `RawRows`), or None where this
    reader does not apply (see the module docstring)."""
    with file.open("rb") as f:
        found = _summary(f, file.stat().st_size)
    if found is None:
        return None
    topics, chunks = found
    wanted = {cid for cid, name in topics.items() if name == topic}
    chunks.sort(key=lambda c: (c.start, c.offset))
    if not wanted or not chunks or not _in_order(chunks):
        return None
    return _messages(file, wanted, chunks)


def _messages(file: Path, wanted: set[int], chunks: list[_ChunkAt]) -> Iterator[Batch]:
    with file.open("rb") as f:
        for chunk in chunks:
            f.seek(chunk.offset)
            raw = f.read(chunk.length)
            if len(raw) != chunk.length or raw[0] != 0x06:
                msg = f"{file}: no chunk at byte {chunk.offset}, where the index puts one"
                raise ValueError(msg)
            records = _records(raw, chunk.compression, file, chunk.offset)
            uniform = _uniform(records, wanted)
            if uniform is not None:
                yield uniform
                continue
            messages = _topic_messages(records, wanted)
            messages.sort(key=itemgetter(0))  # stable: equal log times keep file order
            if messages:
                yield [t for t, _ in messages], [r for _, r in messages]


def _records(raw: bytes, compression: str, file: Path, offset: int) -> bytes:
    """A chunk record's message records, checked against its size and crc."""
    size, crc = struct.unpack_from("<QI", raw, 9 + 16)
    _, k = read_string(raw, 9 + CHUNK_HEAD)
    (stored,) = struct.unpack_from("<Q", raw, k)
    records = decompress(compression, raw[k + 8 : k + 8 + stored])
    if len(records) != size or (crc and zlib.crc32(records) != crc):
        msg = f"{file}: the chunk at byte {offset} does not match its size or checksum"
        raise ValueError(msg)
    return records


def _topic_messages(records: bytes, wanted: set[int]) -> list[tuple[int, bytes]]:
    """The (log time, data) of the message records of the `wanted` channels in `records`."""
    out = []
    at, end = 0, len(records)
    unpack = MESSAGE_HEAD.unpack_from
    while at < end:
        op = records[at]
        if op == MESSAGE and at + MESSAGE_HEAD.size <= end:
            _, length, cid, _, log_time, _ = unpack(records, at)
            if cid in wanted:
                out.append((log_time, records[at + MESSAGE_HEAD.size : at + 9 + length]))
        else:
            (length,) = struct.unpack_from("<Q", records, at + 1)
        at += 9 + length
    if at != end:
        msg = "a record runs past the end of its chunk"
        raise ValueError(msg)
    return out


def _uniform(records: bytes, wanted: set[int]) -> Batch | None:
    """The chunk's messages in log-time order (stably), at once, as `RawRows`, where `records`
    are messages of one wanted channel all of one length (a recording of one IMU: one frame
    id), after any other records before the first message, else None."""
    first = 0  # past the schema and channel records a writer puts before its first message
    while first + 9 <= len(records) and records[first] != MESSAGE:
        first += 9 + struct.unpack_from("<Q", records, first + 1)[0]
    if len(records) - first < MESSAGE_HEAD.size:
        return None
    _, length, cid, _, _, _ = MESSAGE_HEAD.unpack_from(records, first)
    stride = 9 + length
    if cid not in wanted or (len(records) - first) % stride:
        return None
    rows = np.frombuffer(records, np.uint8, offset=first).reshape(-1, stride)
    heads = rows[:, : MESSAGE_HEAD.size].copy().view(MESSAGE_HEAD_DTYPE)[:, 0]
    same = (heads["op"] == MESSAGE) & (heads["length"] == length) & (heads["channel"] == cid)
    if not same.all():
        return None
    times, data = heads["log_time"].astype(np.int64), rows[:, MESSAGE_HEAD.size :]
    if (np.diff(times) < 0).any():
        order = np.argsort(times, kind="stable")
        times, data = times[order], data[order]
    return times, RawRows(data)
