"""What `mount-twin srs` writes of its spectra: the printed table, --csv, --json and --plot, each
spectrum of each axis a `Column`. Standard library only until called (`mount_twin.commands`).
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, NamedTuple

if TYPE_CHECKING:
    import numpy as np

    from mount_twin.analysis.design_margin import DesignCheck
    from mount_twin.analysis.srs import Spectrum

SPECTRA = ("maximax", "primary", "residual", "pseudo_velocity", "positive", "negative")
"""The CSV's columns after frequency_hz, in this order (suffixed _x, _y, _z with --axis all)."""
TABLE = ("maximax", "primary", "residual", "pseudo_velocity")
"""The printed table's spectra for one axis."""
TABLE_ALL = ("maximax", "pseudo_velocity")
"""The printed table's spectra per axis with --axis all (the CSV has them all)."""


def spectrum_columns(spectra: dict[str, Spectrum], unit: str) -> list[Column]:
    """Every spectrum (SPECTRA) of each axis: of a record in m/s², in g (pseudo-velocity in
    m/s); of a force in N, in N (pseudo-velocity in N·s). The names are suffixed with the axis
    where there are several."""
    from mount_twin.io.csv_import import G

    shown, scale, pv_unit = ("g", G, "m/s") if unit == "m/s²" else (unit, 1.0, f"{unit}·s")
    return [
        Column(
            kind,
            kind if len(spectra) == 1 else f"{kind}_{axis}",
            pv_unit if kind == "pseudo_velocity" else shown,
            getattr(s, kind) / (1.0 if kind == "pseudo_velocity" else scale),
        )
        for axis, s in spectra.items()
        for kind in SPECTRA
    ]


def print_table(
    freqs: np.ndarray,
    columns: list[Column],
    one_axis: bool,
    accurate: np.ndarray,
    accurate_hz: float,
) -> None:
    """The printed table (TABLE's spectra of `one_axis`, else TABLE_ALL's of each axis), a `*`
    on the frequencies where the filter is not `accurate` (above `accurate_hz`, Hz) and a note
    on them."""
    shown = [c for c in columns if c.kind in (TABLE if one_axis else TABLE_ALL)]
    print(f"{'f Hz':>9}" + "".join(f" {c.label:>{c.width}}" for c in shown))
    for k, fk in enumerate(freqs):
        cells = "".join(f" {c.values[k]:>{c.width}.4g}" for c in shown)
        print(f"{fk:>9.4g}{cells}{'' if accurate[k] else '  *'}")
    if not accurate.all():
        print(f"* above fs/10 = {accurate_hz:g} Hz the filter is less accurate (peaks picked low)")


def margin_columns(freqs: np.ndarray, checks: dict[str, DesignCheck]) -> list[Column]:
    """With a design: the design (g) and each axis's margin (dB) at every frequency, NaN
    where the design does not reach."""
    import numpy as np

    out: list[Column] = []
    for axis, check in checks.items():
        judged = np.isin(freqs, check.frequency_hz)
        if not out:
            design = np.full(freqs.shape, np.nan)
            design[judged] = check.design
            out.append(Column("design", "design_g", "g", design))
        margin = np.full(freqs.shape, np.nan)
        margin[judged] = check.margin_db
        name = "margin_db" if len(checks) == 1 else f"margin_db_{axis}"
        out.append(Column("margin", name, "dB", margin))
    return out


def write_json(
    args: argparse.Namespace,
    freqs: np.ndarray,
    columns: list[Column],
    checks: dict[str, DesignCheck],
    rate_hz: float,
    zeta: float,
) -> None:
    """The spectra (as --csv has them), and with a design the verdict and its bands."""
    from mount_twin.commands.common import json_text
    from mount_twin.textfiles import write_text

    doc = {
        "input": args.input,
        "axis": args.axis,
        "rate_hz": rate_hz,
        "damping": zeta,
        "frequency_hz": [float(f) for f in freqs],
        "spectra": {c.name: [float(v) for v in c.values] for c in columns},
        "units": {c.name: c.unit for c in columns},
        "design": args.design,
        "tolerance_db": list(args.tolerance_db) if checks else None,
        "verdict": ("PASS" if all(c.passed for c in checks.values()) else "FAIL")
        if checks
        else None,
        "axes": {
            axis: {
                "passed": c.passed,
                "summary": c.summary(),
                "judged": int(c.frequency_hz.shape[0]),
                "not_judged": c.skipped,
                "design_not_reached_hz": [list(r) for r in c.unreached],
                "out_of_band": [
                    {"from_hz": f0, "to_hz": f1, "kind": kind, "worst_db": worst}
                    for f0, f1, kind, worst in c.bands()
                ],
            }
            for axis, c in checks.items()
        },
    }
    write_text(args.json, json_text(doc))


class Column(NamedTuple):
    """One spectrum of one axis as written: `values` in `unit`."""

    kind: str
    name: str
    unit: str
    values: np.ndarray

    @property
    def label(self) -> str:
        """The table's heading: name (PV for pseudo_velocity) and unit."""
        return f"{self.name.replace('pseudo_velocity', 'PV')} {self.unit}"

    @property
    def width(self) -> int:
        """The table's column width."""
        return max(10, len(self.label))


def write_csv(path: str, freqs: np.ndarray, columns: list[Column]) -> None:
    """`frequency_hz` and one column per spectrum, every value to full precision."""
    import csv

    from mount_twin.textfiles import text_output

    with text_output(path, newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["frequency_hz", *(c.name for c in columns)])
        w.writerows(
            [repr(float(fk)), *(repr(float(c.values[k])) for c in columns)]
            for k, fk in enumerate(freqs)
        )


def plot(
    png: str,
    spectra: dict[str, Spectrum],
    design: tuple[list[float], list[float]] | None,
    band_db: tuple[float, float] | None,
    title: str,
    accurate_hz: float,
    unit: str,
) -> str:
    """Maximax, primary and residual of one axis (maximax of each with all) in g (a force's in
    its `unit`), log-log, against the design spectrum; the frequencies above fs/10 shaded; the
    y axis takes in every curve (`fit_log_y`). What it leaves out, in words ("" if nothing)."""
    import textwrap

    from mount_twin.analysis.log_labels import fit_log_y
    from mount_twin.figure_files import pyplot, save_png
    from mount_twin.io.csv_import import G

    plt = pyplot()

    scale, ylabel = (
        (G, "peak absolute acceleration [g]")
        if unit == "m/s²"
        else (1.0, f"peak response [{unit}]")
    )
    fig, ax = plt.subplots(figsize=(8, 5.5))
    # maximax wide and pale under the primary and residual that make it up
    styles: dict[str, dict[str, float | str]] = {
        "maximax": {"lw": 4.0, "alpha": 0.4},
        "primary": {"ls": "--"},
        "residual": {"ls": ":"},
    }
    for axis, s in spectra.items():
        for kind in styles if len(spectra) == 1 else ("maximax",):
            ax.loglog(
                s.frequency_hz, getattr(s, kind) / scale, label=f"{kind}, {axis}", **styles[kind]
            )
    if design is not None:
        ax.loglog(*design, "k--", label="design")
        if band_db is not None:
            low, high = (10.0 ** (db / 20.0) for db in band_db)
            band = f"tolerance {band_db[0]:+g}/{band_db[1]:+g} dB"
            ax.loglog(design[0], [v * low for v in design[1]], "k:", lw=1.0, label=band)
            ax.loglog(design[0], [v * high for v in design[1]], "k:", lw=1.0)
    f_top = float(max(s.frequency_hz.max() for s in spectra.values()))
    if f_top > accurate_hz:
        ax.axvspan(accurate_hz, f_top, color="0.9", label="f > fs/10: less accurate")
    clipped = fit_log_y(ax, "g" if unit == "m/s²" else unit)
    ax.set_xlabel("natural frequency [Hz]")
    ax.set_ylabel(ylabel)
    # a long bag or mount name: two lines; what the y axis leaves out, under it
    ax.set_title("\n".join(textwrap.wrap(title, 90) + textwrap.wrap(clipped, 90)), fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save_png(fig, png)
    return clipped
