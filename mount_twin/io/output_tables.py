"""An output bag (what `replay` writes, or a recording of the node) as column tables.

One table per output: `pose` (CG position m, quaternion x, y, z, w of body → F), `angles`
(α, γ, δ rad), one `mount_<name>` per mount (force N and couple N·m on the body, mount axes)
`diagnostics` (one row per status per report; `values` holds its key-values as JSON) and
`events` (one row per mount event group of a report: its first event's stamp, mount, event,
level, count, largest |F|).
Every table starts with the integer header stamp `stamp_ns` and `t_s`, seconds from the bag's
first output stamp. Column names carry their unit.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader

from mount_twin.engine.batch import event_level
from mount_twin.engine.health_texts import INPUT, INTEGRATION
from mount_twin.errors import BagError
from mount_twin.io.bag_info import require_existing
from mount_twin.io.input_bag import reader_paths
from mount_twin.io.messages import DIAGNOSTICS, TYPESTORE
from mount_twin.io.output_topics import BODY_READBACKS, OUTPUTS, Readback, output_table
from mount_twin.kinds.events import EVENT_IS_ERROR
from mount_twin.textfiles import replacing_all

LEVELS = {0: "OK", 1: "WARN", 2: "ERROR", 3: "STALE"}
DIAGNOSTICS_TABLE, EVENTS_TABLE = "diagnostics", "events"
EVENT = re.compile(r"(\w+) ×(\d+) \(first (\d+\.\d+) s, \|F\| max ([\d.e+-]+) N\)")
"""An event group in a mount status message (engine.health_texts.events_text)."""


@dataclass(frozen=True)
class Table:
    """Named columns of equal length: `stamp_ns` (int64) and `t_s` first."""

    name: str
    columns: dict[str, np.ndarray]

    def __len__(self) -> int:
        return int(self.columns["stamp_ns"].shape[0])


def read_output_bag(path: str | Path) -> list[Table]:
    """The output tables of a bag (errors name the bag), in the order of `io.output_topics.OUTPUTS`
    (each output's tables by name), then diagnostics and events; `t_s` counts from the earliest
    stamp of any of them. Each topic is filed by what the registry says it is
    (`io.output_topics.output_table`); other topics are left out."""
    stamps: dict[str, list[int]] = {}
    rows: dict[str, list[tuple[Any, ...]]] = {}
    columns_of: dict[str, Readback | None] = {}
    rank: dict[str, int] = {}
    require_existing(path)
    try:
        with AnyReader(reader_paths(Path(path)), default_typestore=TYPESTORE) as reader:
            tables_of: dict[int, tuple[str, Readback | None]] = {}
            for c in reader.connections:
                if c.msgtype == DIAGNOSTICS:
                    tables_of[c.id] = (DIAGNOSTICS_TABLE, None)
                elif (found := output_table(c.topic, c.msgtype)) is not None:
                    tables_of[c.id] = found
                else:
                    continue
                name, output = tables_of[c.id]
                columns_of[name] = output
                rank[name] = _rank(c.msgtype, c.topic)
            conns = [c for c in reader.connections if c.id in tables_of]
            # (no connection list would mean every connection to rosbags)
            for conn, _, raw in reader.messages(connections=conns) if conns else ():
                msg: Any = reader.deserialize(raw, conn.msgtype)
                stamp = int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)
                name, output = tables_of[conn.id]
                if output is None:  # diagnostics
                    for st in msg.status:
                        stamps.setdefault(name, []).append(stamp)
                        level = LEVELS.get(int(st.level), str(st.level))
                        pairs = json.dumps({kv.key: kv.value for kv in st.values})
                        rows.setdefault(name, []).append((st.name, level, st.message, pairs))
                else:
                    stamps.setdefault(name, []).append(stamp)
                    rows.setdefault(name, []).append(output.read(msg))
    except Exception as err:  # rosbags raises its own types for unreadable bags
        msg_text = f"{path}: cannot read the output bag: {err}"
        raise BagError(msg_text) from err
    if not stamps:
        msg_text = f"{path}: no mount_twin output in the bag (pose, angles, wrenches, diagnostics)"
        raise BagError(msg_text)
    origin = min(s[0] for s in stamps.values())
    tables = []
    for name in sorted(stamps, key=lambda n: (rank[n], n)):
        ns = np.array(stamps[name], dtype=np.int64)
        columns: dict[str, np.ndarray] = {"stamp_ns": ns, "t_s": (ns - origin) * 1e-9}
        output = columns_of[name]
        if output is None:  # diagnostics
            for k, col in enumerate(("status", "level", "message", "values")):
                columns[col] = np.array([r[k] for r in rows[name]], dtype=object)
        else:
            values = np.array(rows[name], dtype=float).reshape(-1, len(output.columns))
            columns.update(zip(output.columns, values.T, strict=True))
        tables.append(Table(name, columns))
        if output is None:
            tables.append(events_table(tables[-1], origin))
    return tables


def table_names() -> list[str]:
    """Every table `read_output_bag` can return, in its order; `<mount>` stands for each
    mount's name (`export --help` lists them: a test holds its list equal)."""
    readbacks = (*OUTPUTS, *BODY_READBACKS)
    named = [r.table.format(mount="<mount>") for r in readbacks if r.table is not None]
    return [*named, DIAGNOSTICS_TABLE, EVENTS_TABLE]


def _rank(msgtype: str, topic: str) -> int:
    """A table's place: its output's in OUTPUTS, diagnostics after them."""
    return next(
        (i for i, out in enumerate(OUTPUTS) if out.table_of(topic, msgtype) is not None),
        len(OUTPUTS),
    )


@dataclass(frozen=True)
class Event:
    """A mount event group of one diagnostics period: time from the first output (s)."""

    mount: str
    event: str
    count: int
    t_s: float
    force_n: float
    level: str


def events_of(diagnostics: Table, origin_ns: int) -> list[Event]:
    """Mount event groups of the diagnostics' mount statuses, in time order; each at its own
    kind's level (the mount status' level is that of its worst event in the period). Read in
    full from the status's values (`<event>.count`, `.first_stamp_ns`, `.force_max_N`), or
    where a bag recorded before those has none, from its message (µs, 4 digits)."""
    out = []
    c = diagnostics.columns
    for status, message, pairs in zip(c["status"], c["message"], c["values"], strict=True):
        if not status.startswith("mount_twin: mount "):
            continue
        values = json.loads(pairs)
        for name, count, first, force_text in EVENT.findall(message):
            if f"{name}.first_stamp_ns" in values:
                t = (int(values[f"{name}.first_stamp_ns"]) - origin_ns) * 1e-9
                force = float(values[f"{name}.force_max_N"])
            else:
                t, force = float(first) - origin_ns * 1e-9, float(force_text)
            out.append(
                Event(
                    status.removeprefix("mount_twin: mount "),
                    name,
                    int(count),
                    t,
                    force,
                    event_level(EVENT_IS_ERROR[name]),
                )
            )
    return sorted(out, key=lambda e: e.t_s)


def integration_values(diagnostics: Table | None) -> dict[str, str]:
    """The key-values of the run's last integration status (`failures_total`, the error
    estimate, …); empty where the bag holds none."""
    return _last_values(diagnostics, INTEGRATION)


def input_values(diagnostics: Table | None) -> dict[str, str]:
    """The key-values of the run's last input status (the counts over the run: `received`,
    `accepted`, `rejected_<reason>`, …; `last_wrong_frame_id`); empty where the bag holds
    none."""
    return _last_values(diagnostics, INPUT)


def _last_values(diagnostics: Table | None, name: str) -> dict[str, str]:
    """The key-values of the last status called `name`; empty where the bag holds none."""
    if diagnostics is None:
        return {}
    c = diagnostics.columns
    rows = [v for s, v in zip(c["status"], c["values"], strict=True) if s == name]
    return json.loads(rows[-1]) if rows else {}


def events_table(diagnostics: Table, origin_ns: int) -> Table:
    """`events`: one row per mount event group of a diagnostics period (`events_of`): the
    stamp of its first event, mount, event, level, count and the largest |F| (N)."""
    events = events_of(diagnostics, origin_ns)
    first_ns = np.array([origin_ns + round(e.t_s * 1e9) for e in events], dtype=np.int64)
    return Table(
        EVENTS_TABLE,
        {
            "stamp_ns": first_ns,
            "t_s": np.array([e.t_s for e in events]),
            "mount": np.array([e.mount for e in events], dtype=object),
            "event": np.array([e.event for e in events], dtype=object),
            "level": np.array([e.level for e in events], dtype=object),
            "count": np.array([e.count for e in events], dtype=np.int64),
            "force_max_N": np.array([e.force_n for e in events]),
        },
    )


def write_tables(tables: list[Table], directory: str | Path, fmt: str = "csv") -> list[Path]:
    """Write each table as DIRECTORY/<name>.csv (or .parquet, with pyarrow); returns the
    files. All or none (`textfiles.replacing_all`): each is written beside its place and all
    are put in place once every one is written, replacing the files of the same names; a
    failure (a full disk, a directory where a table goes, a signal) leaves the directory as it
    was, not the first tables looking finished. The directory is made, with those missing
    above it, and removed with them if no table is written."""
    out_dir = Path(directory)
    files = []
    with replacing_all() as replace:
        for table in tables:
            path = out_dir / f"{table.name}.{fmt}"
            tmp = replace(path)
            if fmt == "parquet":
                import pyarrow as pa
                import pyarrow.parquet as pq

                columns = {
                    k: v.tolist() if v.dtype == object else v for k, v in table.columns.items()
                }
                pq.write_table(pa.table(columns), tmp)
            else:
                _write_csv(table, tmp)
            files.append(path)
    return files


def _write_csv(table: Table, path: Path) -> None:
    import csv

    names = list(table.columns)
    with path.open("w", encoding="utf-8", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(names)
        for row in zip(*(table.columns[n].tolist() for n in names), strict=True):
            writer.writerow(row)
