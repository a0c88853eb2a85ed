"""A topic's messages from a rosbag2 sqlite3 file that rosbags cannot open (a recorder killed
mid-write), up to the first unreadable row: `io.input_bag` reads a damaged bag's .db3 files
with it, as `io.mcap_salvage` reads its .mcap files."""

from __future__ import annotations

import shutil
import sqlite3
import struct
import tempfile
from contextlib import suppress
from pathlib import Path

from mount_twin.io.mcap_salvage import Salvage


def salvage_sqlite(db: Path, topic: str) -> Salvage:
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
