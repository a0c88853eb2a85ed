"""Accelerometer (and gyro) CSV files as recorders write them, read into a `Signal`.

Accepted: `,` `;` tab or whitespace between cells (sniffed from the header line), a decimal
comma (with `;`, tab or whitespace delimiters; with `,` in quoted cells, `"0,12"`), a UTF-8
byte-order mark (Excel's "CSV UTF-8"), comment lines (`#`) and blank lines, cells in double
quotes (`"0"`, as spreadsheets write them; a delimiter within them is no cell's end), units
in the header (`t [s]`, `AccZ (g)`, `wx[deg/s]`), quoted header cells and
channels named by their range (enDAQ's `"X (100g)"`: g), common column names (`time`, `AccX`,
`gyro_x`, `X`, ...) or an explicit mapping, files without gyro columns (Ω = 0), and
single-axis records (`CsvFormat.axis`: one acceleration column along a stated sensor axis, the
others 0). Units: time s, ms, us, ns; acceleration m/s², g (9.80665 m/s²), mm/s²;
angular rate rad/s, deg/s. Every error names the file, the row (its line number in the file)
and the column. The values are specific force in the sensor frame, as an IMU reports them.
The file's text, its cells and their numbers are read as every CSV here is (`io.csv_cells`);
this module knows a recorder's columns, units and layouts.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mount_twin.io.csv_cells import (
    TIME_NS,
    cell_value,
    check_increasing,
    check_width,
    fail,
    read_csv_text,
    same_unit,
    split_cells,
    time_cells_ns,
    unquoted,
)
from mount_twin.io.signals import Signal
from mount_twin.scene.description import STANDARD_GRAVITY

G = STANDARD_GRAVITY
ROLES = ("t", "ax", "ay", "az", "wx", "wy", "wz")
ALIASES: dict[str, tuple[str, ...]] = {
    "t": ("t", "time", "timestamp", "time_s", "sec", "seconds"),
    "ax": ("ax", "accx", "acc_x", "accel_x", "acceleration_x", "a_x", "x"),
    "ay": ("ay", "accy", "acc_y", "accel_y", "acceleration_y", "a_y", "y"),
    "az": ("az", "accz", "acc_z", "accel_z", "acceleration_z", "a_z", "z"),
    "wx": ("wx", "gx", "gyrox", "gyro_x", "omega_x", "rate_x", "w_x"),
    "wy": ("wy", "gy", "gyroy", "gyro_y", "omega_y", "rate_y", "w_y"),
    "wz": ("wz", "gz", "gyroz", "gyro_z", "omega_z", "rate_z", "w_z"),
}
"""Header names (lower case, spaces as _) taken for each role without a mapping (enDAQ's
exports name their axes X, Y, Z)."""
RANGE_UNIT = re.compile(r"^(\d+)g$")
"""An accelerometer channel named by its range, as enDAQ's exports do (`X (100g)`): in g."""
UNITS: dict[str, dict[str, float]] = {
    "time": {u: 1 / (10**9 // ns) for u, ns in TIME_NS.items()},  # 1 / 1000 is the float 1e-3
    "accel": {"m/s^2": 1.0, "m/s2": 1.0, "m/s²": 1.0, "mps2": 1.0, "g": G, "mm/s^2": 1e-3},
    "gyro": {"rad/s": 1.0, "deg/s": math.pi / 180, "°/s": math.pi / 180, "dps": math.pi / 180},
}
"""Unit name → factor to SI, per quantity."""
QUANTITY = {"t": "time", **dict.fromkeys(ROLES[1:4], "accel"), **dict.fromkeys(ROLES[4:], "gyro")}
UNIT_APART = re.compile(r"\s+(?![\[(])")
"""Whitespace between header cells: not that before a bracketed unit (`Time [ms]`)."""
HEADER_CELL = re.compile(r"^\s*(.*?)\s*(?:[\[(]\s*(.*?)\s*[\])])?\s*$")
DECIMAL_COMMA = re.compile(r"^[+-]?\d*,\d+(?:[eE][+-]?\d+)?$")
"""A number written with a decimal comma (`0,12`, `-1,5e3`)."""
THOUSANDS = re.compile(r"^[+-]?[1-9]\d{0,2}(?:,\d{3})+$")
"""A whole number with commas between groups of three digits (`1,234`), as a spreadsheet
with thousands separators quotes it: a decimal comma or not, the text does not say."""


@dataclass(frozen=True)
class CsvFormat:
    """What the file does not say itself (None: sniff it or take it from the header).

    Attributes:
        delimiter: between cells; None: `;`, tab or `,` as the header has them, else spaces.
        decimal: '.' or ','; None: ',' if the numbers have one (`_sniffed_decimal`).
        columns: role (t, ax, ay, az, wx, wy, wz) → header name, for names not recognised.
        units: quantity (time, accel, gyro) → unit, overriding the header's.
        axis: 'x', 'y' or 'z' for a single-axis record: its one acceleration column (mapped
            as that axis's role, e.g. az=Accel, else the only column besides time) is along
            that sensor axis; the other axes read 0. None: three axes.
    """

    delimiter: str | None = None
    decimal: str | None = None
    columns: dict[str, str] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    axis: str | None = None


@dataclass(frozen=True)
class Imported:
    """The signal read, and what was assumed or found, to tell the user (`notes`).

    Attributes:
        signal: the record; its `t` (s) a float per time cell, as near as a float holds it
            (some 240 ns off from the epoch on).
        notes: what was assumed or found.
        stamps_ns: the time cells exactly, int64 ns (`time_ns`): what the header stamps are
            made of, `signal.t` being too coarse for a record timed from the epoch.
    """

    signal: Signal
    notes: list[str]
    stamps_ns: np.ndarray


def read_recorder_csv(path: str | Path, fmt: CsvFormat = CsvFormat()) -> Imported:
    """Read a recorder's CSV (see the module docstring); every error names file, row, column."""
    path = Path(path)
    lines = [
        (n, line)
        for n, line in enumerate(read_csv_text(path).splitlines(), 1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not lines:
        raise fail(path, "", "no header line (the file is empty or only comments)")
    header_row, header = lines[0]
    delimiter = fmt.delimiter or next((d for d in (";", "\t", ",") if d in header), None)
    names, header_units = _header(header, delimiter)
    if fmt.axis is None:
        roles = _roles(path, header_row, names, fmt.columns)
    else:
        roles = _single_axis_roles(path, header_row, names, fmt)
    data = lines[1:]
    if not data:
        raise fail(path, f"row {header_row}", "a header but no data rows")
    decimal = fmt.decimal or _sniffed_decimal([line for _, line in data[:50]], delimiter)
    units = {
        role: _unit(QUANTITY[role], header_units[col], fmt.units) for role, col in roles.items()
    }
    scale, notes = _factors(path, header_row, names, roles, units)
    columns = [(col, scale[role]) for role, col in roles.items()]
    values, time_cells = _values(path, data, names, delimiter, decimal, columns)
    t, rows, t_name = values[:, 0], [row for row, _ in data], names[roles["t"]]
    check_increasing(path, t, rows, t_name)
    stamps_ns, rounding = time_cells_ns(path, rows, t_name, time_cells, units["t"], decimal)
    check_increasing(path, stamps_ns, rows, t_name)  # two times within a ns of each other
    accel_role = f"a{fmt.axis or 'x'}"
    accel, gyro, found = _motion(values, fmt.axis, names[roles[accel_role]])
    notes += found
    shown = [r for r in ("t", accel_role, "wx") if r in roles]
    given = {r: bool(fmt.units.get(QUANTITY[r]) or header_units[roles[r]]) for r in shown}
    notes.append(_units_note({r: units[r] for r in shown}, given))
    notes += rounding
    if decimal == ",":
        notes.append("decimal comma")
    return Imported(Signal(t, accel, gyro), notes, stamps_ns)


def _units_note(units: dict[str, str], given: dict[str, bool]) -> str:
    """'units: time s, accel g, ...' of the roles' `units`, saying which of them were assumed
    (not `given` by the header nor an override) and how to say them."""
    text = "units: " + ", ".join(f"{QUANTITY[r]} {u}" for r, u in units.items())
    assumed = [QUANTITY[r] for r in units if not given[r]]
    if assumed:
        options = ", ".join(f"--{q}-unit" for q in assumed)
        text += f" ({', '.join(assumed)} assumed: the header gives no unit; say it with {options})"
    return text


def _sniffed_decimal(lines: list[str], delimiter: str | None) -> str:
    """',' where the data `lines` (the first ones) write numbers with a decimal comma, else
    '.'. Between `;`, tabs or spaces: any comma. Between commas, a comma can only be in a
    quoted cell, and decides only where it is no thousands separator (`"0,12"`, `"0,001"`,
    `"12,5"`; `"1,234"` may be either: a cell that is no number then, named with the option)."""
    if delimiter != ",":
        return "," if any("," in line for line in lines) else "."
    cells = (unquoted(cell) for line in lines for cell in split_cells(line, ","))
    decimal_comma = (c for c in cells if DECIMAL_COMMA.match(c) and not THOUSANDS.match(c))
    return "," if next(decimal_comma, None) is not None else "."


def _unit(quantity: str, header_unit: str, overrides: dict[str, str]) -> str:
    """The unit of a column of `quantity`: the override (`CsvFormat.units`), else the header's,
    else the SI one."""
    return overrides.get(quantity) or header_unit or next(iter(UNITS[quantity]))


def _factors(
    path: Path, header_row: int, names: list[str], roles: dict[str, int], units: dict[str, str]
) -> tuple[dict[str, float], list[str]]:
    """Factor to SI per role from its unit, and the note that an accelerometer range in the
    header (`100g`) was read as g; an unknown unit is an error."""
    notes: list[str] = []
    scale = {}
    for role, col in roles.items():
        quantity, unit = QUANTITY[role], units[role]
        factor = next((f for u, f in UNITS[quantity].items() if same_unit(u, unit)), None)
        if factor is None and quantity == "accel" and RANGE_UNIT.match(unit.lower()):
            factor = G
            if not any(n.startswith("accelerometer range") for n in notes):
                notes.append(f"accelerometer range {unit!r} in the header: values read in g")
        if factor is None:
            known = ", ".join(UNITS[quantity])
            where = f"row {header_row}, column {names[col]}"
            raise fail(path, where, f"unknown {quantity} unit {unit!r} (known: {known})")
        scale[role] = factor
    return scale, notes


def _values(
    path: Path,
    data: list[tuple[int, str]],
    names: list[str],
    delimiter: str | None,
    decimal: str,
    columns: list[tuple[int, float]],
) -> tuple[np.ndarray, list[str]]:
    """The data rows' (line number, text) cells of `columns` (index, factor to SI), in SI
    units, (rows, columns), every cell checked to be a finite number, in SI units too; and
    the first column's cells as written (time's, for its exact stamps)."""
    values = np.empty((len(data), len(columns)))
    first = []
    for i, (row, line) in enumerate(data):
        cells = split_cells(line, delimiter)
        check_width(path, row, cells, names, delimiter)
        for j, (col, factor) in enumerate(columns):
            try:
                values[i, j] = cell_value(path, row, names[col], cells[col], factor, decimal)
            except ValueError as err:
                if decimal == "," or "," not in cells[col]:
                    raise
                hint = (
                    "a decimal comma? say `mount-twin import-csv --decimal ,` (thousands "
                    "separators are not read)"
                )
                raise ValueError(f"{err}: {hint}") from None
        first.append(cells[columns[0][0]])
    return values, first


def _motion(
    values: np.ndarray, axis: str | None, accel_column: str
) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Specific force (n, 3) m/s² and angular velocity (n, 3) rad/s from the SI `values` (t,
    then the acceleration columns, then any gyro's), and notes on what was taken as 0. `axis`:
    a single-axis record's sensor axis, whose one column is `accel_column`."""
    notes = []
    if axis is not None:
        accel = np.zeros((values.shape[0], 3))
        accel[:, "xyz".index(axis)] = values[:, 1]
        notes.append(f"single axis: {accel_column} along the sensor's {axis}, the others 0")
    else:
        accel = values[:, 1:4]
    if values.shape[1] == 7:
        gyro = values[:, 4:7]
    else:
        gyro = np.zeros_like(accel)
        notes.append("no gyro columns: angular velocity taken as 0")
    return accel, gyro, notes


def _header(line: str, delimiter: str | None) -> tuple[list[str], list[str]]:
    """Column names (lower case, spaces as _) and units ('' where none) of the header line;
    between spaces, a unit in brackets stays with the name before it (`Time [ms]  AccZ [g]`)."""
    names, units = [], []
    for raw in split_cells(line, delimiter) if delimiter else UNIT_APART.split(line.strip()):
        cell = raw.strip().strip('"')  # quoted cells: enDAQ's "X (100g)"
        match = HEADER_CELL.match(cell)
        name, unit = (match.group(1), match.group(2) or "") if match else (cell, "")
        names.append(name.strip().strip('"').lower().replace(" ", "_"))
        units.append(unit)
    return names, units


def _single_axis_roles(path: Path, row: int, names: list[str], fmt: CsvFormat) -> dict[str, int]:
    """t and the one acceleration column of a single-axis record (see CsvFormat.axis), in
    that order."""
    role = f"a{fmt.axis}"
    found = _roles(path, row, names, fmt.columns, required=("t",))
    t = found["t"]
    if role in found:
        col = found[role]
    else:
        rest = [i for i in range(len(names)) if i != t]
        if len(rest) != 1:
            raise fail(
                path,
                f"row {row}",
                f"a single-axis record needs one acceleration column besides time; the header "
                f"has {', '.join(names)}: name it with `mount-twin import-csv --columns "
                f"{role}=NAME`",
            )
        (col,) = rest
    return {"t": t, role: col}


def _roles(
    path: Path,
    row: int,
    names: list[str],
    mapping: dict[str, str],
    required: tuple[str, ...] = ROLES[:4],
) -> dict[str, int]:
    """Role → column index: the mapping's names, else the first alias present."""
    roles: dict[str, int] = {}
    for role in ROLES:
        wanted = [mapping[role].lower().replace(" ", "_")] if role in mapping else ALIASES[role]
        found = next((names.index(n) for n in wanted if n in names), None)
        if found is not None:
            roles[role] = found
        elif role in mapping:
            raise fail(
                path,
                f"row {row}",
                f"no column {mapping[role]!r} (for {role}); the header has {', '.join(names)}",
            )
    missing = [r for r in required if r not in roles]
    if missing:
        raise fail(
            path,
            f"row {row}",
            f"no column for {', '.join(missing)}: the header has {', '.join(names)}; name "
            "them t, ax, ay, az (wx, wy, wz), or map them with `mount-twin import-csv "
            "--columns t=Time,ax=...`",
        )
    gyro = [r for r in ROLES[4:] if r in roles]
    if gyro and len(gyro) != 3:
        raise fail(
            path, f"row {row}", f"gyro columns {gyro} without the others: give all three or none"
        )
    return roles
