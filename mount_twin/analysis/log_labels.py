"""Log axes read whole: limits that take in every curve, and tick labels of one that spans
little (plain numbers on its major and minor ticks)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

NARROW_DECADES = 1.5
"""A log axis spanning fewer decades than this shows too few powers of ten to read: matplotlib
then labels its minor ticks as 2×10¹, 6×10⁰."""


def plain_log_labels(ax: Any, which: str) -> None:
    """Label the `which` ("x" or "y") log axis of a matplotlib Axes with plain numbers (%.3g) on
    its major and minor ticks where its limits span fewer than NARROW_DECADES decades; call it
    once the limits are set."""
    import matplotlib.ticker

    low, high = ax.get_xlim() if which == "x" else ax.get_ylim()
    if not (low > 0.0 and math.log10(high / low) < NARROW_DECADES):
        return
    axis = ax.xaxis if which == "x" else ax.yaxis
    axis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%.3g"))
    axis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%.3g"))
    ax.tick_params(axis=which, which="both", labelsize=7)  # major and minor alike


DECADES_MAX = 6
"""The most decades `fit_log_y` spans below its top: a residual spectrum falls off to round-off
(1e-16 g after a short record), which would squash every other curve into the top."""


def fit_log_y(ax: Any, unit: str) -> str:
    """Set the log y axis of a matplotlib Axes to take in every positive value of its lines,
    from half the smallest to twice the largest, over DECADES_MAX decades at most. What that
    floor leaves out, in words (each labelled line below it, down to its smallest, in `unit`),
    or "" if nothing."""
    values = {
        str(line.get_label()): np.asarray(line.get_ydata(), dtype=float) for line in ax.get_lines()
    }
    positive = {name: v[v > 0.0] for name, v in values.items() if (v > 0.0).any()}
    top = 2.0 * max(float(v.max()) for v in positive.values())
    floor = max(0.5 * min(float(v.min()) for v in positive.values()), top * 10.0**-DECADES_MAX)
    ax.set_ylim(floor, top)
    below = [
        f"{name} down to {float(v.min()):.3g} {unit}"
        for name, v in positive.items()
        if v.min() < floor and not name.startswith("_")  # "_child3": a line with no label
    ]
    if not below:
        return ""
    return f"not shown below {floor:.3g} {unit} ({DECADES_MAX} decades): {'; '.join(below)}"
