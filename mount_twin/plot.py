"""Plot a replay's output bag: CG displacement, attitude angles and mount forces over time."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from mount_twin.engine.batch import MountEvent
from mount_twin.io.output_tables import read_output_bag


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

    tables = {t.name: t for t in read_output_bag(bag)}
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 9))
    if "pose" in tables:
        pose = tables["pose"].columns
        for axis in "xyz":
            rows = pose[f"{axis}_m"]
            axes[0].plot(pose["t_s"], (rows - rows[0]) * 1e3, label=f"CG {axis} - start")
    if "angles" in tables:
        angles = tables["angles"].columns
        for name in ("alpha", "gamma", "delta"):
            axes[1].plot(angles["t_s"], np.degrees(angles[f"{name}_rad"]), label=name)
    for name, table in tables.items():
        if name.startswith("mount_"):
            c = table.columns
            force = np.sqrt(c["fx_N"] ** 2 + c["fy_N"] ** 2 + c["fz_N"] ** 2)
            axes[2].plot(c["t_s"], force, label=name.removeprefix("mount_"))
    firsts = [int(t.columns["stamp_ns"][0]) for t in tables.values() if len(t.columns["stamp_ns"])]
    t0 = min(firsts, default=0) * 1e-9  # an empty table (no mount events) has no first stamp
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
