"""Tick labels of a log axis that spans little: plain numbers on its major and minor ticks."""

from __future__ import annotations

import math
from typing import Any

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
