"""The trade-off of a sweep: the largest peak mount force of each case against the first varied
value, one line per input (and per value of the other variations)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mount_twin.sweeps.runner import FAILED, columns, largest_peak_force
from mount_twin.sweeps.spec import SweepSpec


def plot_sweep(rows: list[dict[str, Any]], spec: SweepSpec, png: str | Path) -> Path:
    """Write the plot; FAILED cases are left out."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    varied = columns(spec)[2 : 2 + len(spec.variations)]
    names = [m["name"] for m in spec.base["mounts"]]
    lines: dict[str, list[tuple[float, float, str]]] = {}
    for r in rows:
        if r["verdict"] == FAILED or not varied:
            continue
        label = " ".join([r["input"], *(f"{k}={r[k]}" for k in varied[1:])])
        peak = largest_peak_force(r, names)
        lines.setdefault(label, []).append((float(r[varied[0]]), peak, r["verdict"]))
    fig, ax = plt.subplots(figsize=(8, 5))
    marks = {"OK": "o", "WARN": "s", "ERROR": "v"}
    for label, points in sorted(lines.items()):
        points.sort()
        line = ax.plot([p[0] for p in points], [p[1] * 1e-3 for p in points], label=label)[0]
        for x, y, verdict in points:
            ax.plot(x, y * 1e-3, marks.get(verdict, "x"), color=line.get_color())
    ax.set_xlabel(varied[0] if varied else "case")
    ax.set_ylabel("largest peak mount force [kN]")
    ax.set_title(f"{Path(spec.source).name}: markers o OK, s WARN, v ERROR", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    out = Path(png)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
