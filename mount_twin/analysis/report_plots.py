"""The report page's figures of a replay: the input and response, the mount forces, the
utilisation per diagnostics period (and its series from the diagnostics), the input's shock
response spectra. Each draws into the matplotlib figure it is given (`html_page.png`)."""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from mount_twin.analysis.log_labels import plain_log_labels
from mount_twin.engine.batch import LEVEL_NAMES
from mount_twin.engine.health_texts import UTILISATION_KEY
from mount_twin.io.output_tables import Event, Table
from mount_twin.scene.description import STANDARD_GRAVITY

if TYPE_CHECKING:
    from mount_twin.analysis.srs import Spectrum


LEGEND_ROWS = 16
"""The most rows of the utilisation figure's legend before it takes another column."""


def utilisation_of(diagnostics: Table) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per mount with a rating: (report times s, peak utilisation in each period)."""
    series: dict[str, tuple[list[float], list[float]]] = {}
    c = diagnostics.columns
    for t, status, values in zip(c["t_s"], c["status"], c["values"], strict=True):
        u = json.loads(values).get(UTILISATION_KEY, "n/a")
        if status.startswith("mount_twin: mount ") and u != "n/a":
            times, utils = series.setdefault(status.removeprefix("mount_twin: mount "), ([], []))
            times.append(float(t))
            utils.append(float(u))
    return {k: (np.array(t), np.array(u)) for k, (t, u) in series.items()}


def draw_srs(
    fig: Any,
    spectra: dict[str, Spectrum],
    damping: float,
    design: tuple[list[float], list[float]] | None,
    judged: tuple[str, ...] = (),
) -> None:
    """The maximax spectra (g) of the axes with any response, and the design (Hz, g) if any,
    named with the axes it judges (`judged`), log-log against natural frequency (Hz); the
    legend gives the oscillators' damping ratio `damping`, as the page's heading does."""
    ax = fig.subplots()
    for axis, s in spectra.items():
        if s.maximax.max() > 0.0:
            ax.loglog(s.frequency_hz, s.maximax / STANDARD_GRAVITY, label=f"maximax, {axis} of F")
    if design is not None:
        ax.loglog(*design, "k--", label=f"design (judges {', '.join(judged)} of F)")
    ax.set_xlabel("natural frequency [Hz]")
    ax.set_ylabel("peak absolute acceleration [g]")
    plain_log_labels(ax, "y")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, title=f"ζ = {damping:g} ({damping * 100:g} %)", title_fontsize=7)


def draw_response(
    fig: Any,
    tables: dict[str, Table],
    input_samples: tuple[np.ndarray, np.ndarray] | None,
    origin_ns: int,
    input_name: str,
) -> None:
    """The input's specific force (g; with `input_samples`), the CG's displacement from its
    first published position (mm) and the attitude (rad), against time from the first output
    (s; it is at `origin_ns`)."""
    n = 3 if input_samples is not None else 2
    axes = fig.subplots(n, 1, sharex=True)
    k = 0
    if input_samples is not None:
        stamps, f = input_samples
        t = (stamps - origin_ns) * 1e-9
        for i, axis in enumerate("xyz"):
            axes[0].plot(t, f[:, i] / STANDARD_GRAVITY, label=f"{axis} of F")
        axes[0].set_ylabel("foundation specific force [g]")
        axes[0].set_title(f"input {input_name}", fontsize=9)
        k = 1
    pose = tables["pose"].columns
    for axis in "xyz":
        v = pose[f"{axis}_m"]
        axes[k].plot(pose["t_s"], (v - v[0]) * 1e3, label=f"CG {axis}")
    axes[k].set_ylabel("CG displacement from its\nfirst published position [mm]")
    ang = tables["angles"].columns
    for name in ("alpha", "gamma", "delta"):
        axes[k + 1].plot(ang["t_s"], ang[f"{name}_rad"], label=name)
    axes[k + 1].set_ylabel("attitude [rad]")
    axes[-1].set_xlabel("time from the first output [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")


def draw_forces(
    fig: Any,
    mounts: dict[str, Table],
    events: list[Event],
    window: tuple[float, float] | None = None,
) -> None:
    """Each mount's force components (kN, mount axes) against time from the first output (s):
    all of it, or within `window` (s) with the events there as lines, coloured by level
    (EVENT_COLOURS) and named so in a legend."""
    import matplotlib.lines

    axes = fig.subplots(3, 1, sharex=True)
    for name, table in mounts.items():
        c = table.columns
        keep = slice(None) if window is None else (c["t_s"] >= window[0]) & (c["t_s"] <= window[1])
        for i, comp in enumerate(("fx_N", "fy_N", "fz_N")):
            axes[i].plot(c["t_s"][keep], c[comp][keep] * 1e-3, label=name, linewidth=0.9)
    for i, comp in enumerate("xyz"):
        axes[i].set_ylabel(f"force along mount {comp} [kN]")
        axes[i].grid(True, alpha=0.3)
    if window is not None:
        shown = [e for e in events if window[0] <= e.t_s <= window[1]]
        for e in shown:
            for ax in axes:
                ax.axvline(e.t_s, color=_event_colour(e.level), alpha=0.4)
        axes[1].legend(  # what the lines' colours mean, the levels there
            handles=[
                matplotlib.lines.Line2D([], [], color=_event_colour(level), alpha=0.4)
                for level in _levels(shown)
            ],
            labels=[f"{level} event" for level in _levels(shown)],
            fontsize=7,
            loc="upper right",
            title="lines",
            title_fontsize=7,
        )
    axes[0].legend(fontsize=7, ncol=4, loc="upper right")
    axes[-1].set_xlabel("time from the first output [s]")


EVENT_COLOURS = {"ERROR": "red", "WARN": "orange"}
"""An event's line by its level (any other level: gray)."""


def _event_colour(level: str) -> str:
    return EVENT_COLOURS.get(level, "gray")


def _levels(events: list[Event]) -> list[str]:
    """The levels of `events`, worst first."""
    rank = {name: k for k, name in enumerate(LEVEL_NAMES)}
    return sorted({e.level for e in events}, key=lambda v: -rank.get(v, len(rank)))


def utilisation_lines(
    utilisation: dict[str, tuple[np.ndarray, np.ndarray]], period_s: float | None
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each mount's utilisation figure line (`utilisation_of`: report times s from the first
    output, peaks), drawn as steps into each report's stamp: from the report before, and for
    the first, where the diagnostics period (`period_s`, the scene's) is known, from one period
    before its stamp or from the first output (t 0), whichever is later, the point prepended
    holding the first peak. Without the period the first report is its point alone."""
    if period_s is None:
        return dict(utilisation)
    return {
        name: (np.insert(t, 0, max(float(t[0]) - period_s, 0.0)), np.insert(u, 0, u[0]))
        for name, (t, u) in utilisation.items()
    }


def draw_utilisation(
    fig: Any,
    utilisation: dict[str, tuple[np.ndarray, np.ndarray]],
    kinds: dict[str, str],
    period_s: float | None = None,
) -> None:
    """Each rated mount's peak utilisation per diagnostics period (-) against time from the
    first output (s), and the rating (1): one marker per report, at its stamp, holding the peak
    of the period that ends there, the step into it spanning that period (`utilisation_lines`:
    the first's only where `period_s` is known; a step's start prepended is not marked)."""
    ax = fig.subplots()
    for name, (t, u) in utilisation_lines(utilisation, period_s).items():
        ax.plot(
            t,
            u,
            drawstyle="steps-pre",
            marker="o",
            markersize=3,
            markevery=None if period_s is None else slice(1, None),
            label=f"{name} ({kinds[name]})" if name in kinds else name,  # kinds: with a scene
        )
    ax.axhline(1.0, color="red", linestyle="--", label="rated (1)")
    ax.set_xlim(left=0.0)  # the run from its first output, however few reports it has
    ax.set_ylabel("peak utilisation of the\ndiagnostics period ending at • [-]")
    ax.set_xlabel("time from the first output [s]")
    ax.grid(True, alpha=0.3)
    # beside the plot, not in it: inside, it covered the rating line and the peaks near it
    ax.legend(
        fontsize=7,
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        ncol=math.ceil((len(utilisation) + 1) / LEGEND_ROWS),
    )
