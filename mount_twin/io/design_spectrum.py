"""A design shock spectrum, as a specification gives it: a `frequency_hz,accel_g` CSV table
(Hz, g), read for `srs --design`, `report --design`, `synthesize --spectrum` and a
qualification plan's spectra."""

from __future__ import annotations

import csv
import io
from itertools import pairwise
from pathlib import Path

from mount_twin.io.csv_cells import read_csv_text


def read_design_table(path: str) -> tuple[list[float], list[float]]:
    """A design spectrum's (frequencies Hz, accelerations g) from its `frequency_hz,accel_g`
    CSV; a file that is no text, or no table (a field past csv's limit), is an error naming
    it (`io.csv_cells.read_csv_text`: it had said "'utf-8' codec can't decode byte 0x89",
    or ended in csv's traceback)."""
    reader = csv.DictReader(io.StringIO(read_csv_text(Path(path))))
    try:
        if not {"frequency_hz", "accel_g"} <= set(reader.fieldnames or ()):
            msg = f"{path}: a design spectrum needs the columns frequency_hz and accel_g"
            raise ValueError(msg)
        rows = list(reader)
    except csv.Error as err:  # no ValueError: it had ended in a traceback, exit 1
        msg = f"{path}: not a CSV table ({err})"
        raise ValueError(msg) from None
    try:
        f = [float(r["frequency_hz"]) for r in rows]
        a = [float(r["accel_g"]) for r in rows]
    except (TypeError, ValueError) as err:
        msg = f"{path}: a design spectrum's values must be numbers ({err})"
        raise ValueError(msg) from None
    if len(f) < 2 or f[0] <= 0.0 or not all(f0 < f1 for f0, f1 in pairwise(f)):
        msg = f"{path}: frequency_hz must be at least two increasing frequencies above 0 Hz"
        raise ValueError(msg)
    if not all(v > 0.0 and v < float("inf") for v in a):
        msg = f"{path}: accel_g must be finite and above 0 g (the spectrum is log-log)"
        raise ValueError(msg)
    return f, a
