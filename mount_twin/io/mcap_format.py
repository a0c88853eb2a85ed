"""MCAP's record layout (mcap.dev/spec), shared by our reader, writer and salvage: after the
8-byte magic, records of opcode (u8), length (u64, little-endian) and body. Strings and byte
arrays are a u32 length and the bytes; maps a u32 byte length and the entries.

Header 0x01 (profile, library), Footer 0x02 (summary start u64, summary offset start u64, crc
u32), Schema 0x03 (id u16, name, encoding, data), Channel 0x04 (id u16, schema id u16, topic,
message encoding, metadata), Message 0x05 (channel u16, sequence u32, log time u64, publish time
u64, data), Chunk 0x06 (start u64, end u64, uncompressed size u64, crc u32, compression,
records), Message Index 0x07, Chunk Index 0x08 (start u64, end u64, chunk offset u64, chunk
length u64, message index offsets, message index length u64, compression, compressed size u64,
uncompressed size u64), Statistics 0x0B, Metadata 0x0C, Metadata Index 0x0D, Summary Offset
0x0E, Data End 0x0F.
"""

from __future__ import annotations

import struct

import numpy as np

MAGIC = b"\x89MCAP0\r\n"
HEADER, FOOTER, SCHEMA, CHANNEL, MESSAGE, CHUNK = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
MESSAGE_INDEX, CHUNK_INDEX, STATISTICS, METADATA = 0x07, 0x08, 0x0B, 0x0C
METADATA_INDEX, SUMMARY_OFFSET, DATA_END = 0x0D, 0x0E, 0x0F

MESSAGE_HEAD = struct.Struct("<BQHIQQ")
"""A message record's opcode, length, channel, sequence, log and publish time."""
MESSAGE_HEAD_DTYPE = np.dtype(
    [
        ("op", "u1"),
        ("length", "<u8"),
        ("channel", "<u2"),
        ("sequence", "<u4"),
        ("log_time", "<u8"),
        ("publish_time", "<u8"),
    ]
)
"""MESSAGE_HEAD as a numpy record (packed: no padding; tested the same size)."""
CHUNK_HEAD = 28
"""A chunk body's bytes before its compression string (start, end, size, crc)."""


def pack_string(s: str | bytes) -> bytes:
    """A string or byte array as MCAP stores it."""
    raw = s.encode() if isinstance(s, str) else s
    return struct.pack("<I", len(raw)) + raw


def read_string(body: bytes | memoryview, at: int) -> tuple[str, int]:
    """The string at `at` in `body`, and where the bytes after it start."""
    (n,) = struct.unpack_from("<I", body, at)
    return bytes(body[at + 4 : at + 4 + n]).decode(), at + 4 + n


def record(op: int, body: bytes) -> bytes:
    """One record: opcode, length, body."""
    return struct.pack("<BQ", op, len(body)) + body


def decompress(compression: str, data: bytes) -> bytes:
    """A chunk's records from its stored bytes (uncompressed, or lz4 or zstd where those modules
    are installed)."""
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
