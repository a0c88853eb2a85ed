"""The messages of a damaged mcap file up to the damage (a recorder killed mid-write, a copy cut
short): its records are read in order from the start, without the summary at the end that a
normal reader needs, until one is incomplete or unreadable.

The record layout: `io.mcap_format`; read here: Schema, Channel, Message and Chunk records.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from pathlib import Path

from mount_twin.io.mcap_format import (
    CHANNEL,
    CHUNK,
    CHUNK_HEAD,
    MAGIC,
    MESSAGE,
    SCHEMA,
    decompress,
    read_string,
)


@dataclass
class Salvage:
    """Messages of one topic read before the damage: (log time ns, raw), and where it stopped."""

    messages: list[tuple[int, bytes]] = field(default_factory=list)
    msgtype: str = ""
    damage: str = ""


def salvage(path: Path, topic: str) -> Salvage:
    """Read `topic`'s messages from the mcap file at `path` up to the first damage."""
    data = path.read_bytes()
    out = Salvage()
    if not data.startswith(MAGIC):
        out.damage = "no mcap magic at the start"
        return out
    schemas: dict[int, str] = {}
    wanted: set[int] = set()

    def records(buf: bytes, start: int, where: str) -> None:
        at = start
        while at < len(buf):
            if buf[at:] == MAGIC:  # the closing magic of an intact file
                return
            if at + 9 > len(buf):
                raise ValueError(f"{where}: a record header cut short at byte {at}")
            op = buf[at]
            (length,) = struct.unpack_from("<Q", buf, at + 1)
            body = buf[at + 9 : at + 9 + length]
            if len(body) < length:
                cut = f"{where}: a record (opcode {op:#04x}) cut short at byte {at}"
                if op == CHUNK:  # the messages of a chunk cut short, up to the cut
                    try:
                        compression, k = read_string(body, CHUNK_HEAD)
                        if compression == "":
                            records(bytes(body[k + 8 :]), 0, cut)
                    except (ValueError, struct.error, UnicodeDecodeError):
                        pass
                raise ValueError(cut)
            if op == SCHEMA:
                (sid,) = struct.unpack_from("<H", body, 0)
                schemas[sid], _ = read_string(body, 2)
            elif op == CHANNEL:
                cid, sid = struct.unpack_from("<HH", body, 0)
                name, _ = read_string(body, 4)
                if name == topic:
                    wanted.add(cid)
                    out.msgtype = schemas.get(sid, "")
            elif op == MESSAGE:
                (cid,) = struct.unpack_from("<H", body, 0)
                if cid in wanted:
                    (log_time,) = struct.unpack_from("<Q", body, 6)
                    out.messages.append((log_time, bytes(body[22:])))
            elif op == CHUNK:
                compression, k = read_string(body, CHUNK_HEAD)
                (n,) = struct.unpack_from("<Q", body, k)
                inner = decompress(compression, bytes(body[k + 8 : k + 8 + n]))
                records(inner, 0, f"chunk at byte {at}")
            at += 9 + length

    try:
        records(data, len(MAGIC), str(path))
    except (ValueError, struct.error, UnicodeDecodeError) as err:
        out.damage = str(err)
    return out
