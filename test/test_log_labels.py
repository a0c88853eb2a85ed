"""Log axes spanning little get plain tick labels; wide ones keep matplotlib's powers of ten."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.ticker import FormatStrFormatter, LogFormatterSciNotation

from mount_twin.analysis.log_labels import plain_log_labels


def test_a_narrow_log_axis_gets_plain_labels() -> None:
    fig, ax = plt.subplots()
    ax.loglog([1.0, 10.0], [2.5, 25.0])
    ax.set_ylim(2.5, 25.0)
    plain_log_labels(ax, "y")
    fig.canvas.draw()
    labels = [t.get_text() for t in ax.yaxis.get_minorticklabels() if t.get_text()]
    assert "3" in labels and "20" in labels, labels  # not 3×10⁰, 2×10¹
    plt.close(fig)


def test_a_wide_log_axis_keeps_its_powers_of_ten() -> None:
    fig, ax = plt.subplots()
    ax.loglog([1.0, 10.0], [1e-3, 1e2])
    ax.set_ylim(1e-3, 1e2)
    plain_log_labels(ax, "y")
    assert isinstance(ax.yaxis.get_major_formatter(), LogFormatterSciNotation)
    assert not isinstance(ax.yaxis.get_minor_formatter(), FormatStrFormatter)
    plt.close(fig)
