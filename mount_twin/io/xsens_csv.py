"""Movella/Xsens DOT CSV exports (Xsens DOT app, "sep=," first), read into a `Signal`.

Layout: a preamble (`sep=,`, `DeviceTag:`, versions, `StartTime:`, a copyright line, a blank
line), then `PacketCounter,SampleTimeFine,...` with `SampleTimeFine` the device clock in µs
(32-bit, wrapping), `Acc_X/Y/Z` specific force in m/s² (+g on z at rest) and `Gyr_X/Y/Z` in
deg/s, in the sensor's frame. The export's first data row is all zeros (no sample): dropped.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from mount_twin.io.csv_import import CSV_MAX_BYTES, read_recorder_csv
from mount_twin.io.signals import Signal
from mount_twin.textfiles import FileTooLargeError, read_limited

CLOCK_WRAP_US = 2**32
ACCEL = ("Acc_X", "Acc_Y", "Acc_Z")
GYRO = ("Gyr_X", "Gyr_Y", "Gyr_Z")


def is_xsens_csv(path: str | Path) -> bool:
    """Whether the file starts as an Xsens DOT export does (its first 4 kB read, no more: a
    device or a huge file is not read whole here)."""
    with open(path, "rb") as fh:
        head = fh.read(4096).decode("utf-8-sig", errors="replace").splitlines()
    return len(head) > 1 and head[0].strip().startswith("sep=") and head[1].startswith("DeviceTag")


def read_xsens_csv(path: str | Path) -> tuple[Signal, str]:
    """The record (stamps s on the device clock, SampleTimeFine: two synchronised sensors'
    records share it; specific force m/s², rate rad/s, sensor frame) and its device tag;
    errors name the file and what is missing."""
    path = Path(path)
    try:
        lines = read_limited(path, CSV_MAX_BYTES, "CSV_MAX_BYTES", "utf-8-sig").splitlines()
    except FileTooLargeError as err:
        msg = f"{path}: cannot read: {err}"
        raise ValueError(msg) from err
    tag = next((ln.split(",", 1)[1] for ln in lines if ln.startswith("DeviceTag:")), "")
    start = next((i for i, ln in enumerate(lines) if ln.startswith("PacketCounter,")), None)
    if start is None:
        msg = f"{path}: no header row PacketCounter,SampleTimeFine,...: not an Xsens DOT export"
        raise ValueError(msg)
    rows = list(csv.DictReader(lines[start:]))
    missing = [c for c in ("SampleTimeFine", *ACCEL, *GYRO) if rows and c not in rows[0]]
    if not rows or missing:
        msg = f"{path}: no data rows, or no column {', '.join(missing)}"
        raise ValueError(msg)
    rows = [r for r in rows if any(float(r[c]) != 0.0 for c in (*ACCEL, *GYRO))]
    clock = np.unwrap(np.array([float(r["SampleTimeFine"]) for r in rows]), period=CLOCK_WRAP_US)
    t = clock * 1e-6
    accel = np.array([[float(r[c]) for c in ACCEL] for r in rows])
    gyro = np.radians(np.array([[float(r[c]) for c in GYRO] for r in rows]))
    if not (np.diff(t) > 0.0).all() or not math.isfinite(float(accel.sum() + gyro.sum())):
        msg = f"{path}: SampleTimeFine does not increase, or a value is not a number"
        raise ValueError(msg)
    return Signal(t, accel, gyro), tag


def read_csv_record(path: str | Path) -> Signal:
    """A CSV record, whichever of the two it is: an Xsens DOT export (stamps on its device
    clock) or a recorder CSV (`csv_import`: its stamps as written, units from its header)."""
    return read_xsens_csv(path)[0] if is_xsens_csv(path) else read_recorder_csv(path).signal
