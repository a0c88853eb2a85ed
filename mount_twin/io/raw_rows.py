"""Raw messages of one length held as the rows of one byte array.

A chunk of a plain mcap file that holds one IMU of one frame id is a block of records of one
length (`io.mcap_reader`): its messages are the rows of that block, past each record's head.
`RawRows` hands them on as a `Sequence[bytes]` without making a bytes object per message (an
hour at 1 kHz is 3.6 million), and `io.input_decoding.decode_inputs` reads their numbers in one
numpy pass (`FixedLayout.unpack_rows`). Anything that wants bytes gets them, one message at a
time.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from itertools import chain
from typing import overload

import numpy as np

from mount_twin.io.fixed_layout import split_rows


@dataclass(frozen=True, eq=False)
class RawRows(Sequence[bytes]):
    """Messages of one length: `rows` (k, L) uint8, one message per row (a view is fine)."""

    rows: np.ndarray

    def __len__(self) -> int:
        return int(self.rows.shape[0])

    @overload
    def __getitem__(self, i: int) -> bytes: ...

    @overload
    def __getitem__(self, i: slice) -> RawRows: ...

    def __getitem__(self, i: int | slice) -> bytes | RawRows:
        if isinstance(i, slice):
            return RawRows(self.rows[i])
        return self.rows[i].tobytes()

    def __iter__(self) -> Iterator[bytes]:
        return iter(split_rows(np.ascontiguousarray(self.rows)))


def nbytes(raws: Sequence[bytes]) -> int:
    """The messages' total length, bytes."""
    return int(raws.rows.size) if isinstance(raws, RawRows) else sum(map(len, raws))


def joined(parts: Sequence[Sequence[bytes]]) -> Sequence[bytes]:
    """The parts' messages in order, as one sequence: `RawRows` where every message has the
    length of the `RawRows` among them (a list part of that length is made rows too), else a
    list of bytes (no parts: an empty list)."""
    if len(parts) == 1:
        return parts[0]
    widths = {p.rows.shape[1] for p in parts if isinstance(p, RawRows)}
    if len(widths) != 1:
        return list(chain.from_iterable(parts))
    (width,) = widths
    blocks = []
    for p in parts:
        if isinstance(p, RawRows):
            blocks.append(p.rows)
        elif all(len(raw) == width for raw in p):
            blocks.append(np.frombuffer(b"".join(p), np.uint8).reshape(-1, width))
        else:
            return list(chain.from_iterable(parts))
    return RawRows(np.concatenate(blocks))
