"""The trade-off of a sweep: the largest peak mount force and the largest utilisation of each
case against the first varied value, one line per input (and per value of the other
variations), in the sweep's order."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from mount_twin.sweeps.runner import (
    FAILED,
    column_units,
    columns,
    largest_peak_force,
    largest_utilisation,
    setting_text,
    value_text,
)
from mount_twin.sweeps.spec import SweepSpec

MARKS = {"OK": "o", "WARN": "s", "ERROR": "v"}
"""A case's marker by its verdict."""
OTHER_MARK = "x"
"""The marker of a case whose verdict MARKS does not name."""


Point = tuple[float, float, float, str]
"""A case on a line: the first varied value (or its place, `places`), its largest peak mount
force (kN), its largest utilisation (NaN: no mount rated) and its verdict."""


def places(rows: list[dict[str, Any]], spec: SweepSpec) -> dict[str, int] | None:
    """Where each first varied value goes on the x axis when one is no number (a position, a
    switch, a method's name): its place in the sweep file's values, by its text in the table
    (`setting_text`; one the file no longer has, after them). None where every value is a
    number: the axis is then the values'."""
    values = spec.variations[0].values if spec.variations else ()
    if all(_is_number(v) for v in values):
        return None
    at = {setting_text(v): i for i, v in enumerate(values)}
    key = columns(spec)[2]
    for r in rows:
        at.setdefault(str(r[key]), len(at))
    return at


def trade_off(rows: list[dict[str, Any]], spec: SweepSpec) -> dict[str, list[Point]]:
    """The plot's lines: per input (in the sweep file's order) and values of the other
    variations (in their order), its cases by the first varied value; FAILED cases left out."""
    varied = columns(spec)[2 : 2 + len(spec.variations)]
    names = [m["name"] for m in spec.base["mounts"]]
    order = {c.name: i for i, c in enumerate(spec.inputs)}

    def line_key(r: dict[str, Any]) -> tuple:
        others = tuple(_sortable(r[k]) for k in varied[1:])
        return (order.get(r["input"], len(order)), str(r["input"]), *others)

    at = places(rows, spec)
    units = column_units(spec)
    lines: dict[str, list[Point]] = {}
    for r in sorted(rows, key=line_key):
        if r["verdict"] == FAILED or not varied:
            continue
        label = " ".join([r["input"], *(f"{k}={value_text(k, r[k], units)}" for k in varied[1:])])
        lines.setdefault(label, []).append(
            (
                float(r[varied[0]]) if at is None else float(at[str(r[varied[0]])]),
                largest_peak_force(r, names) * 1e-3,
                largest_utilisation(r, names),
                r["verdict"],
            )
        )
    for points in lines.values():
        points.sort()
    return lines


def _verdict_order(verdict: str) -> tuple[int, str]:
    """A verdict as a sort key: those of MARKS in its order (OK, WARN, ERROR), then any other."""
    order = list(MARKS)
    return (order.index(verdict) if verdict in order else len(order), verdict)


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _sortable(value: Any) -> tuple[int, float, str]:
    """A varied value as a sort key: numbers by value, before anything else by its text."""
    if _is_number(value):
        return (0, float(value), "")
    return (1, 0.0, str(value))


def plot_sweep(rows: list[dict[str, Any]], spec: SweepSpec, png: str | Path) -> Path:
    """Write the plot of `trade_off`: the force above, the utilisation below (its limit, 1,
    dashed; that panel only where a mount is rated); its title counts the FAILED cases left
    out."""
    import matplotlib.lines

    from mount_twin.figure_files import pyplot, save_png

    plt = pyplot()
    lines = trade_off(rows, spec)
    rated = any(not math.isnan(p[2]) for points in lines.values() for p in points)
    fig, axes = plt.subplots(2 if rated else 1, 1, figsize=(8, 8 if rated else 5), sharex=True)
    panels = list(axes) if rated else [axes]
    for label, points in lines.items():
        for ax, column in zip(panels, (1, 2), strict=False):
            line = ax.plot([p[0] for p in points], [p[column] for p in points], label=label)[0]
            for p in points:
                ax.plot(p[0], p[column], MARKS.get(p[3], OTHER_MARK), color=line.get_color())
    verdicts = [  # the markers' shapes by verdict, of the verdicts drawn
        matplotlib.lines.Line2D(
            [], [], color="0.3", linestyle="", marker=MARKS.get(v, OTHER_MARK), label=v
        )
        for v in sorted({p[3] for points in lines.values() for p in points}, key=_verdict_order)
    ]
    if rated:
        panels[1].axhline(1.0, color="0.4", lw=1, ls="--")
    ylabels = ("largest peak mount force [kN]", "largest utilisation [-]")
    for ax, ylabel in zip(panels, ylabels, strict=False):
        ax.set_ylabel(ylabel)
        # ticks that read the values: close ones were ticked as an offset (48 … 54 under
        # "1e−6+7.8535"), which reads as 54 kN
        ax.ticklabel_format(axis="y", useOffset=False)
        ax.grid(True, alpha=0.3)
        handles, _ = ax.get_legend_handles_labels()
        ax.legend(handles=handles + verdicts, fontsize=7)  # the lines, then the markers' shapes
    varied = columns(spec)[2 : 2 + len(spec.variations)]
    xlabel = varied[0] if varied else "case"
    if (unit := column_units(spec).get(xlabel)) is not None:
        xlabel += f" [{unit}]"
    panels[-1].set_xlabel(xlabel)
    if (at := places(rows, spec)) is not None:
        panels[-1].set_xticks(list(at.values()), list(at), fontsize=8)
    failed = sum(r["verdict"] == FAILED for r in rows)  # no figures to draw
    left_out = f"; {failed} FAILED case{'s' * (failed != 1)} not drawn" if failed else ""
    panels[0].set_title(f"{Path(spec.source).name}{left_out}", fontsize=9)
    return save_png(fig, png)
