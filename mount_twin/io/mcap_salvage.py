"""The messages of a damaged mcap file up to the damage (a recorder killed mid-write, a copy cut
short): its records are read in order from the start, without the summary at the end that a
normal reader needs, until one is incomplete or unreadable.

MCAP's record layout (mcap.dev/spec): after the 8-byte magic, records of opcode (1 byte), length
(uint64 LE) and body. Used here: Schema 0x03 (id u16, name, encoding, data), Channel 0x04 (id
u16, schema id u16, topic, message encoding, metadata), Message 0x05 (channel id u16, sequence
u32, log time u64, publish time u64, data) and Chunk 0x06 (start u64, end u64, uncompressed size
u64, crc u32, compression, records), whose records are read the same way (uncompressed, or lz4 or
zstd where those modules are installed). Strings are a uint32 length and UTF-8 bytes.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from pathlib import Path

MAGIC = b"\x89MCAP0\r\n"
SCHEMA, CHANNEL, MESSAGE, CHUNK = 0x03, 0x04, 0x05, 0x06


@dataclass
class Salvage:
    """Messages of one topic read before the damage: (log time ns, raw), and where it stopped."""

    messages: list[tuple[int, bytes]] = field(default_factory=list)
    msgtype: str = ""
    damage: str = ""


def _string(body: bytes, at: int) -> tuple[str, int]:
    (n,) = struct.unpack_from("<I", body, at)
    return body[at + 4 : at + 4 + n].decode(), at + 4 + n


def _decompress(compression: str, data: bytes, size: int) -> bytes:
    if compression == "":
        return data
    if compression == "lz4":
        import lz4.frame

        return bytes(lz4.frame.decompress(data))
    if compression == "zstd":
        from backports import zstd  # Python < 3.14; the standard library's compression.zstd after

        return bytes(zstd.decompress(data))
    msg = f"unknown chunk compression {compression!r}"
    raise ValueError(msg)


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
                        compression, k = _string(body, 28)
                        if compression == "":
                            records(bytes(body[k + 8 :]), 0, cut)
                    except (ValueError, struct.error, UnicodeDecodeError):
                        pass
                raise ValueError(cut)
            if op == SCHEMA:
                (sid,) = struct.unpack_from("<H", body, 0)
                schemas[sid], _ = _string(body, 2)
            elif op == CHANNEL:
                cid, sid = struct.unpack_from("<HH", body, 0)
                name, _ = _string(body, 4)
                if name == topic:
                    wanted.add(cid)
                    out.msgtype = schemas.get(sid, "")
            elif op == MESSAGE:
                (cid,) = struct.unpack_from("<H", body, 0)
                if cid in wanted:
                    (log_time,) = struct.unpack_from("<Q", body, 6)
                    out.messages.append((log_time, bytes(body[22:])))
            elif op == CHUNK:
                (size,) = struct.unpack_from("<Q", body, 16)
                compression, k = _string(body, 28)
                (n,) = struct.unpack_from("<Q", body, k)
                inner = _decompress(compression, bytes(body[k + 8 : k + 8 + n]), size)
                records(inner, 0, f"chunk at byte {at}")
            at += 9 + length

    try:
        records(data, len(MAGIC), str(path))
    except (ValueError, struct.error, UnicodeDecodeError) as err:
        out.damage = str(err)
    return out
