"""An output bag (what `replay` writes, or a recording of the node) as column tables.

One table per output: `pose` (CG position m, quaternion x, y, z, w of body → F), `angles`
(α, γ, δ rad), one `mount_<name>` per mount (force N and couple N·m on the body, mount axes)
and `diagnostics` (one row per status per report; `values` holds its key-values as JSON).
Every table starts with the integer header stamp `stamp_ns` and `t_s`, seconds from the bag's
first output stamp. Column names carry their unit.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader

from mount_twin.errors import BagError
from mount_twin.io.messages import DIAGNOSTICS, POSE, TYPESTORE, VECTOR3, WRENCH

COLUMNS = {
    POSE: ("x_m", "y_m", "z_m", "qx", "qy", "qz", "qw"),
    VECTOR3: ("alpha_rad", "gamma_rad", "delta_rad"),
    WRENCH: ("fx_N", "fy_N", "fz_N", "tx_Nm", "ty_Nm", "tz_Nm"),
}
"""Numeric columns per output message type, after stamp_ns and t_s."""
LEVELS = {0: "OK", 1: "WARN", 2: "ERROR", 3: "STALE"}


@dataclass(frozen=True)
class Table:
    """Named columns of equal length: `stamp_ns` (int64) and `t_s` first."""

    name: str
    columns: dict[str, np.ndarray]

    def __len__(self) -> int:
        return int(self.columns["stamp_ns"].shape[0])


def table_name(topic: str, msgtype: str) -> str:
    """`pose`, `angles`, `mount_<name>` (from …/mounts/<name>/wrench) or `diagnostics`."""
    if msgtype == WRENCH:
        parts = topic.strip("/").split("/")
        return f"mount_{parts[-2]}" if len(parts) >= 2 else topic.strip("/")
    return {POSE: "pose", VECTOR3: "angles", DIAGNOSTICS: "diagnostics"}[msgtype]


def _row(msg: Any) -> tuple[float, ...]:
    if hasattr(msg, "pose"):
        p, q = msg.pose.position, msg.pose.orientation
        return (p.x, p.y, p.z, q.x, q.y, q.z, q.w)
    if hasattr(msg, "wrench"):
        f, t = msg.wrench.force, msg.wrench.torque
        return (f.x, f.y, f.z, t.x, t.y, t.z)
    v = msg.vector
    return (v.x, v.y, v.z)


def read_output_bag(path: str | Path) -> list[Table]:
    """The output tables of a bag (errors name the bag), in topic order; `t_s` counts from the
    earliest stamp of any of them."""
    stamps: dict[str, list[int]] = {}
    rows: dict[str, list[tuple[Any, ...]]] = {}
    kinds: dict[str, str] = {}
    wanted = {POSE, VECTOR3, WRENCH, DIAGNOSTICS}
    try:
        with AnyReader([Path(path)], default_typestore=TYPESTORE) as reader:
            conns = [c for c in reader.connections if c.msgtype in wanted]
            # (no connection list would mean every connection to rosbags)
            for conn, _, raw in reader.messages(connections=conns) if conns else ():
                msg: Any = reader.deserialize(raw, conn.msgtype)
                stamp = int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)
                name = table_name(conn.topic, conn.msgtype)
                kinds[name] = conn.msgtype
                if conn.msgtype == DIAGNOSTICS:
                    for st in msg.status:
                        stamps.setdefault(name, []).append(stamp)
                        level = LEVELS.get(int(st.level), str(st.level))
                        pairs = json.dumps({kv.key: kv.value for kv in st.values})
                        rows.setdefault(name, []).append((st.name, level, st.message, pairs))
                else:
                    stamps.setdefault(name, []).append(stamp)
                    rows.setdefault(name, []).append(_row(msg))
    except Exception as err:  # rosbags raises its own types for unreadable bags
        msg_text = f"{path}: cannot read the output bag: {err}"
        raise BagError(msg_text) from err
    if not stamps:
        msg_text = f"{path}: no mount_twin output in the bag (pose, angles, wrenches, diagnostics)"
        raise BagError(msg_text)
    origin = min(s[0] for s in stamps.values())
    tables = []
    order = {POSE: 0, VECTOR3: 1, WRENCH: 2, DIAGNOSTICS: 3}
    for name in sorted(stamps, key=lambda n: (order[kinds[n]], n)):
        ns = np.array(stamps[name], dtype=np.int64)
        columns: dict[str, np.ndarray] = {"stamp_ns": ns, "t_s": (ns - origin) * 1e-9}
        if kinds[name] == DIAGNOSTICS:
            for k, col in enumerate(("status", "level", "message", "values")):
                columns[col] = np.array([r[k] for r in rows[name]], dtype=object)
        else:
            values = np.array(rows[name], dtype=float)
            columns.update(zip(COLUMNS[kinds[name]], values.T, strict=True))
        tables.append(Table(name, columns))
    return tables


def write_tables(tables: list[Table], directory: str | Path, fmt: str = "csv") -> list[Path]:
    """Write each table as DIRECTORY/<name>.csv (or .parquet, with pyarrow); returns the
    files. The directory is created; existing files of the same names are replaced."""
    out_dir = Path(directory)
    out_dir.mkdir(parents=True, exist_ok=True)
    files = []
    for table in tables:
        path = out_dir / f"{table.name}.{fmt}"
        if fmt == "parquet":
            import pyarrow as pa
            import pyarrow.parquet as pq

            columns = {k: v.tolist() if v.dtype == object else v for k, v in table.columns.items()}
            pq.write_table(pa.table(columns), path)
        else:
            _write_csv(table, path)
        files.append(path)
    return files


def _write_csv(table: Table, path: Path) -> None:
    import csv

    names = list(table.columns)
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(names)
        for row in zip(*(table.columns[n].tolist() for n in names), strict=True):
            writer.writerow(row)
