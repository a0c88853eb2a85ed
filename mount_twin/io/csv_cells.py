"""A CSV file's text, cells and numbers as every importer here reads them (recorder CSVs,
`io.csv_import`; Xsens DOT exports, `io.xsens_csv`; design spectra, `io.design_spectrum`): the
file's text up to CSV_MAX_BYTES, a line split into cells outside double quotes, a cell's number
(a decimal point or comma) in SI units, a time cell exactly in int64 ns, rows as wide as the
header and times that increase. Every error is a ValueError naming the file, then the row (its
line number in the file) and the column.
"""

from __future__ import annotations

import math
import re
import unicodedata
from decimal import (
    MAX_EMAX,
    MAX_PREC,
    MIN_EMIN,
    ROUND_HALF_EVEN,
    Context,
    Decimal,
    InvalidOperation,
)
from pathlib import Path

import numpy as np

from mount_twin.textfiles import MIB, FileTooLargeError, read_limited

TIME_NS = {"s": 10**9, "sec": 10**9, "ms": 10**6, "us": 10**3, "µs": 10**3, "ns": 1}
"""Time unit → nanoseconds in one, exactly: a stamp is the time cell's decimal text times this
(`time_ns`), never a float's approximation of it."""
EXACT = Context(prec=MAX_PREC, Emax=MAX_EMAX, Emin=MIN_EMIN)
"""Decimal arithmetic that rounds nothing (a product has the digits it needs)."""
INT64_MAX = 2**63 - 1


CSV_MAX_BYTES = 256 * MIB
"""Largest CSV imported: ~2.5 million rows of seven columns (45 min at 1 kHz); reading one
takes some 10 times its size in memory."""


def fail(path: Path, where: str, what: str) -> ValueError:
    """A ValueError naming the file, then `where` in it (none: the file as a whole)."""
    return ValueError(f"{path}: {where}: {what}" if where else f"{path}: {what}")


def split_cells(line: str, delimiter: str | None) -> list[str]:
    """A line's cells as written (quotes kept): split at `delimiter` outside double quotes
    (`"0,12","9,81"`: two cells), or at runs of whitespace where it is None. A line whose
    quotes do not pair is split at every delimiter, its cells then named as written."""
    if delimiter is None:
        return line.split()
    parts = line.split('"')
    if len(parts) % 2 == 0:  # an odd number of quotes: none is taken as quoting
        return line.split(delimiter)
    cells = [""]
    for k, part in enumerate(parts):
        if k % 2:  # within quotes
            cells[-1] += f'"{part}"'
        else:
            first, *rest = part.split(delimiter)
            cells[-1] += first
            cells.extend(rest)
    return cells


SPLIT_PIECE = re.compile(r"^[+-]?\d+(?:[eE][+-]?\d+)?$")
"""Half of a number split at an unquoted decimal comma (`-0` and `5`, `1` and `5e1`)."""
SPLIT_DECIMAL_COMMA = (
    "decimal commas between commas? A comma-separated file cannot hold an unquoted decimal "
    "comma unambiguously (`0,12` is two cells); export with ';' as the separator (or quote "
    'the cells, "0,12"), then `mount-twin import-csv --decimal ,`'
)
"""Why a comma-separated row of digits has too many cells: its numbers' decimal commas split
each in two; which comma is which, the text does not say (nor is it guessed)."""


def check_width(
    path: Path, row: int, cells: list[str], header: list[str], delimiter: str | None = None
) -> None:
    """ValueError naming the file and the row (its line number) where the row's `cells` are
    not as many as the `header`'s (a cell split by a stray delimiter shifts the rest); with
    `SPLIT_DECIMAL_COMMA` where the `delimiter` is ',' and the cells, up to twice as many as
    the header's, are all digits: numbers split at their decimal commas."""
    if len(cells) == len(header):
        return
    what = f"{len(cells)} cells where the header has {len(header)}"
    split = len(header) < len(cells) <= 2 * len(header)
    if delimiter == "," and split and all(SPLIT_PIECE.match(unquoted(c)) for c in cells):
        what += f": {SPLIT_DECIMAL_COMMA}"
    raise fail(path, f"row {row}", what)


POINT_WITH_COMMA = (
    "has a '.' where the decimal mark is ',': a thousands separator (not read), or a decimal "
    "point (say `mount-twin import-csv --decimal .`)?"
)
"""Why a number with a '.' is refused where the numbers have a decimal comma: `1.000` is a
thousand in the locales that write `0,5`, not one."""


def cell_value(
    path: Path, row: int, column: str, cell: str, factor: float = 1.0, decimal: str = "."
) -> float:
    """A data cell's number times `factor` (to SI units), with a decimal comma where `decimal`
    is ',' and within one pair of double quotes or none (`unquoted`); ValueError naming the
    file, the row (its line number), the column and the cell as written where it is not a
    number (or has a '.' besides a decimal comma), not finite, or not finite once in SI
    units."""
    text, number = cell.strip(), unquoted(cell)
    if decimal == "," and "." in number:
        raise _cell_fail(path, row, column, f"{text!r} {POINT_WITH_COMMA}")
    try:
        v = float(number.replace(decimal, ".") if decimal == "," else number)
    except ValueError:
        raise _cell_fail(path, row, column, f"{text!r} is not a number") from None
    if not math.isfinite(v):
        raise _cell_fail(path, row, column, f"{text!r} is not finite")
    if not math.isfinite(v * factor):  # 1e308 g: finite, but not in m/s²
        what = f"{text!r} is beyond a float in SI units (×{factor:g})"
        raise _cell_fail(path, row, column, what)
    return v * factor


def unquoted(cell: str) -> str:
    """A cell's text without the spaces around it and one pair of double quotes around that,
    if it has them: spreadsheets quote cells (`"0"`)."""
    text = cell.strip()
    return text[1:-1] if len(text) > 1 and text[0] == text[-1] == '"' else text


def time_ns(cell: str, ns_per_unit: int, decimal: str = ".") -> tuple[int, bool]:
    """A time cell (as `cell_value` reads it: quoted or not, `decimal` its decimal mark) in
    whole ns: its decimal text times `ns_per_unit`, exactly, rounded half to even where it is
    finer than 1 ns; and whether it was rounded. ValueError where the text is no decimal
    number (or has a '.' besides a decimal comma), is not finite or is beyond an int64 of
    ns."""
    number = unquoted(cell)
    if decimal == "," and "." in number:
        msg = f"{cell.strip()!r} {POINT_WITH_COMMA}"
        raise ValueError(msg)
    try:
        value = Decimal(number.replace(",", ".") if decimal == "," else number)
    except InvalidOperation:
        msg = f"{cell.strip()!r} is not a decimal number"
        raise ValueError(msg) from None
    if not value.is_finite():
        msg = f"{cell.strip()!r} is not finite"
        raise ValueError(msg)
    ns = EXACT.multiply(value, ns_per_unit)  # in base 10, however long: no float between
    whole = ns.to_integral_value(ROUND_HALF_EVEN, EXACT)
    if abs(whole) > INT64_MAX:  # compared as a decimal: no int of 10**huge is made
        msg = f"{cell.strip()!r} is beyond the ±2**63 ns (292 years) a stamp holds"
        raise ValueError(msg)
    return int(whole), whole != ns


def time_cells_ns(
    path: Path, rows: list[int], column: str, cells: list[str], unit: str, decimal: str = "."
) -> tuple[np.ndarray, list[str]]:
    """The time `cells` (of the data `rows`, in `unit`) exactly in ns (`time_ns`), int64, and
    the note saying how many of them were rounded to the ns, if any was; ValueError naming the
    file, row and column of one that `time_ns` refuses. Any importer's stamps are read so."""
    ns_per_unit = next(ns for u, ns in TIME_NS.items() if same_unit(u, unit))
    stamps = np.empty(len(cells), dtype=np.int64)
    rounded = 0
    for i, (row, cell) in enumerate(zip(rows, cells, strict=True)):
        try:
            stamps[i], finer = time_ns(cell, ns_per_unit, decimal)
        except ValueError as err:
            raise _cell_fail(path, row, column, str(err)) from None
        rounded += finer
    if not rounded:
        return stamps, []
    return stamps, [f"time: {rounded} cells finer than 1 ns, rounded to the ns (half to even)"]


def _cell_fail(path: Path, row: int, column: str, what: str) -> ValueError:
    return fail(path, f"row {row}, column {column}", what)


def check_increasing(path: Path, t: np.ndarray, rows: list[int], column: str) -> None:
    """ValueError naming the file, the first row (of `rows`, the line numbers of t's samples)
    whose time `t` (s, or int ns) is not after the one before, and the time's column."""
    back = np.flatnonzero(np.diff(t) <= 0.0)
    if back.size:
        raise _cell_fail(path, rows[int(back[0]) + 1], column, "time does not increase")


def read_csv_text(path: Path) -> str:
    """The file's text (at most CSV_MAX_BYTES, UTF-8, a byte-order mark dropped); errors name
    the file (ValueError "FILE: ..."). Any CSV a command reads is read so."""
    try:
        # utf-8-sig drops a byte-order mark
        return read_limited(path, CSV_MAX_BYTES, "CSV_MAX_BYTES", "utf-8-sig")
    except FileTooLargeError as err:
        raise fail(path, "", f"cannot read: {err}") from err
    except OSError as err:
        raise fail(path, "", f"cannot read: {err.strerror}") from err
    except UnicodeDecodeError as err:
        raise fail(path, "", f"not UTF-8 text ({err.reason} at byte {err.start})") from err


def same_unit(a: str, b: str) -> bool:
    """Whether two unit names are one: case and spaces aside, and compatibility characters
    taken as what they stand for (NFKC: the micro sign µ as the Greek μ, ² as 2)."""

    def key(unit: str) -> str:
        return unicodedata.normalize("NFKC", unit).lower().replace(" ", "")

    return key(a) == key(b)
