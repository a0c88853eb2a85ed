"""Movella/Xsens DOT CSV exports (Xsens DOT app, "sep=," first), read into a `Signal`.

Layout: a preamble (`sep=,`, `DeviceTag:`, versions, `StartTime:`, a copyright line, a blank
line), then `PacketCounter,SampleTimeFine,...` with `SampleTimeFine` the device clock in µs
(32-bit, wrapping), `Acc_X/Y/Z` specific force in m/s² (+g on z at rest) and `Gyr_X/Y/Z` in
deg/s, in the sensor's frame. The export's first data row is all zeros (no sample): dropped.
Stamps are read as a recorder CSV's are (`csv_cells.time_cells_ns`): each SampleTimeFine
cell exactly in ns, plus the whole wraps of the clock before it, in integers.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from mount_twin.io.csv_cells import (
    CSV_MAX_BYTES,
    TIME_NS,
    cell_value,
    check_increasing,
    check_width,
    time_cells_ns,
)
from mount_twin.io.csv_import import Imported, read_recorder_csv
from mount_twin.io.signals import Signal
from mount_twin.textfiles import FileTooLargeError, read_limited

CLOCK_WRAP_US = 2**32
"""SampleTimeFine's period, µs (a 32-bit counter): 71.6 min."""
ACCEL = ("Acc_X", "Acc_Y", "Acc_Z")
GYRO = ("Gyr_X", "Gyr_Y", "Gyr_Z")


def is_xsens_csv(path: str | Path) -> bool:
    """Whether the file starts as an Xsens DOT export does (its first 4 kB read, no more: a
    device or a huge file is not read whole here)."""
    with open(path, "rb") as fh:
        head = fh.read(4096).decode("utf-8-sig", errors="replace").splitlines()
    return len(head) > 1 and head[0].strip().startswith("sep=") and head[1].startswith("DeviceTag")


def read_xsens_csv(path: str | Path) -> Imported:
    """The record (on the device clock, SampleTimeFine: two synchronised sensors' records
    share it; specific force m/s², rate rad/s, sensor frame), its stamps exactly in int64 ns
    (`Imported.stamps_ns`) and a note naming its device; errors name the file, the row (its
    line number) and the column, as a recorder CSV's do (`csv_cells.cell_value`,
    `check_width`, `check_increasing`, `time_cells_ns`)."""
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
    reader = csv.reader(lines[start:])
    header = next(reader)
    columns = ("SampleTimeFine", *ACCEL, *GYRO)
    factors = (1.0, 1.0, 1.0, 1.0, *(math.pi / 180.0,) * 3)  # the gyro's deg/s to rad/s
    missing = [c for c in columns if c not in header]
    if missing:
        msg = f"{path}: row {start + 1}: no column {', '.join(missing)}"
        raise ValueError(msg)
    read = [(c, header.index(c), f) for c, f in zip(columns, factors, strict=True)]
    rows, values, times = [], [], []
    for cells in reader:
        row = start + reader.line_num  # the file's line number (the reader's are from 1)
        if not cells:
            continue  # a blank line
        check_width(path, row, cells, header)
        parsed = [cell_value(path, row, c, cells[i], f) for c, i, f in read]
        if any(v != 0.0 for v in parsed[1:]):  # the export's first row is all zeros
            rows.append(row)
            values.append(parsed[1:])
            times.append(cells[read[0][1]])
    if not values:
        msg = f"{path}: no data rows after the header (row {start + 1})"
        raise ValueError(msg)
    on_clock, notes = time_cells_ns(path, rows, "SampleTimeFine", times, "us")
    stamps = np.unwrap(on_clock, period=CLOCK_WRAP_US * TIME_NS["us"])  # int64: exact
    check_increasing(path, stamps, rows, "SampleTimeFine")
    data = np.array(values)
    signal = Signal(stamps / 1e9, data[:, :3].copy(), data[:, 3:].copy())
    device = f"a Movella/Xsens DOT export (device {tag or 'untagged'}): stamps on its clock"
    return Imported(signal, [device, *notes], stamps)


def read_csv_record(path: str | Path) -> Signal:
    """A CSV record, whichever of the two it is: an Xsens DOT export (stamps on its device
    clock) or a recorder CSV (`csv_import`: its stamps as written, units from its header)."""
    return (read_xsens_csv if is_xsens_csv(path) else read_recorder_csv)(path).signal
