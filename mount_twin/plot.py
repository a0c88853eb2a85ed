"""Plot a replay's output bag: CG displacement, attitude angles, mount forces and (with a body
IMU) its measured specific force against the twin's, over time."""

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
    reported |F|: ERROR red triangles, WARN orange dots; with a body IMU comparison in the bag,
    its measured specific force against the twin's prediction below."""
    from mount_twin.figure_files import pyplot, save_png

    plt = pyplot()

    tables = {t.name: t for t in read_output_bag(bag)}
    body = "body_imu_predicted" in tables and "body_imu_residual" in tables
    fig, axes = plt.subplots(4 if body else 3, 1, sharex=True, figsize=(10, 12 if body else 9))
    if "pose" in tables:
        pose = tables["pose"].columns
        for axis in "xyz":
            rows = pose[f"{axis}_m"]
            axes[0].plot(pose["t_s"], (rows - rows[0]) * 1e3, label=f"CG {axis} - start")
    if "angles" in tables:
        angles = tables["angles"].columns
        for name in ("alpha", "gamma", "delta"):
            axes[1].plot(angles["t_s"], angles[f"{name}_rad"], label=name)
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
    if body:  # the body IMU: measured (the prediction plus the residual) against the twin,
        # each about its mean (gravity and biases out, as the comparison takes them); a sample
        # that does not provide the specific force (its residual NaN) is a hole
        predicted = tables["body_imu_predicted"].columns
        residual = tables["body_imu_residual"].columns
        for axis in "xyz":
            twin = predicted[f"f{axis}_m_s2"]
            measured = twin + residual[f"f{axis}_m_s2"]
            given = np.isfinite(measured)
            centre = measured[given].mean() if given.any() else 0.0
            t = predicted["t_s"]
            line = axes[3].plot(t, measured - centre, lw=0.8, label=f"measured {axis}")
            colour = line[0].get_color()
            axes[3].plot(t, twin - twin.mean(), "--", color=colour, lw=0.8, label=f"twin {axis}")
        axes[3].set_ylabel("body IMU specific force\nabout its mean [m/s²]")
    axes[0].set_ylabel("displacement [mm]")
    axes[1].set_ylabel("attitude angle [rad]")
    axes[2].set_ylabel("|mount force| [N]")
    axes[-1].set_xlabel("time from first output [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=7, ncol=4)
    fig.suptitle(title or str(bag))
    return save_png(fig, png)
