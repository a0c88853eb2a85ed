"""Plot a replay's output bag: CG displacement, attitude angles and mount forces over time."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from mount_twin.engine.batch import MountEvent
from mount_twin.io.bag import read_topics
from mount_twin.io.messages import POSE, VECTOR3, WRENCH


def plot_output_bag(
    bag: str | Path,
    png: str | Path,
    title: str = "",
    events: Sequence[MountEvent] = (),
    origin_s: int = 0,
) -> Path:
    """Write a PNG of the output bag's pose, angles and per-mount force magnitudes, with the
    mount events (engine stamps + origin_s = header stamps, s) marked on the forces at their
    reported |F|: ERROR red triangles, WARN orange dots."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    series = read_topics(bag, {POSE, VECTOR3, WRENCH})
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 9))
    t0 = min(float(s[0][0]) for s in series.values() if s[0].size)
    for topic, (t, rows, msgtype) in sorted(series.items()):
        tt = t - t0
        if msgtype == POSE:
            for k, axis in enumerate("xyz"):
                axes[0].plot(tt, (rows[:, k] - rows[0, k]) * 1e3, label=f"CG {axis} - start")
        elif msgtype == VECTOR3:
            for k, name in enumerate(("alpha", "gamma", "delta")):
                axes[1].plot(tt, np.degrees(rows[:, k]), label=name)
        else:
            axes[2].plot(tt, np.linalg.norm(rows[:, :3], axis=1), label=topic.split("/")[-2])
    for error, marker, color in ((True, "v", "red"), (False, ".", "darkorange")):
        mine = [e for e in events if e.error == error]
        if mine:
            axes[2].plot(
                [origin_s + e.stamp - t0 for e in mine],
                [e.force for e in mine],
                marker=marker,
                color=color,
                linestyle="",
                label=f"{'ERROR' if error else 'WARN'} events: "
                + ", ".join(sorted({e.event for e in mine})),
            )
    axes[0].set_ylabel("displacement [mm]")
    axes[1].set_ylabel("angle [deg]")
    axes[2].set_ylabel("|mount force| [N]")
    axes[2].set_xlabel("time from first output [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=7, ncol=4)
    fig.suptitle(title or str(bag))
    fig.tight_layout()
    out = Path(png)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
