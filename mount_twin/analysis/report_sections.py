"""The report page's sections as HTML: the verdict and provenance, the input's spectra, the
modes, the mount forces, the displacement line, the peaks and the events."""

from __future__ import annotations

import html
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from mount_twin.analysis.design_margin import TOLERANCE_DB, DesignCheck, check_design
from mount_twin.analysis.figures import (
    DISPLACEMENT,
    LABELS,
    displacement_from_start,
    peak_magnitudes,
    peak_text,
    utilisation_text,
)
from mount_twin.analysis.html_page import fingerprint, png, produced_by, scene_section
from mount_twin.analysis.html_page import table as html_table
from mount_twin.analysis.modes_text import (
    damping_text,
    effective_mass_text,
    energy_share_text,
    frequency_text,
)
from mount_twin.analysis.report_plots import draw_forces, draw_srs
from mount_twin.analysis.run_verdict import RunVerdict
from mount_twin.engine.estimate import NOT_INTEGRATED
from mount_twin.engine.health_texts import NOT_DESIGNED, why_none
from mount_twin.errors import ModelError
from mount_twin.io.bag_metadata import partial_marker
from mount_twin.io.output_tables import Event, Table
from mount_twin.io.output_topics import WRENCHES_OUTPUT
from mount_twin.scene.description import STANDARD_GRAVITY, Scene

if TYPE_CHECKING:
    from mount_twin.analysis.srs import Spectrum


WINDOW_S = 0.05
"""Half-width of the zoom around the first event, s."""


def provenance_section(
    verdict: RunVerdict,
    integration: dict[str, str],
    output_bag: str | Path,
    input_path: str | Path | None,
    scene: Scene | None,
    input_note: str = "",
    recorded: dict[str, str] | None = None,
    scene_check: str = "",
) -> list[str]:
    """The verdict, what produced the page from what (with `input_note` on the input bag:
    what of it was left out), the input and the solver's settings and estimated error
    (`integration`: the last integration status' values), and the scene as loaded with
    whether it is the run's (`scene_check`: `check_scene`'s); without the scene, what of the
    input and the solver the bag records (`recorded`: the last input status' values;
    `_recorded_settings`)."""
    partial = partial_marker(output_bag)
    rows = [
        ["verdict (worst over the run)", verdict.text],
        *([["partial run", f"the bag stops early: {partial}"]] if partial else []),
        ["produced by", produced_by()],
        ["output bag", f"{output_bag} ({fingerprint(Path(output_bag))})"],
    ]
    if input_path is not None:
        rows.append(["input bag", f"{input_path} ({fingerprint(Path(input_path))})"])
        if input_note:
            rows.append(["input samples left out", input_note])
    # the status names the scene's method until one runs (`auto`: until it chooses)
    ran = (
        f"no method ran: {why_none(verdict.nothing)}"
        if verdict.nothing
        else f"ran: {integration.get('method', '?')}"
    )
    if scene is None:
        rows += _recorded_settings(recorded, integration, ran)
    else:
        spec, integ = scene.input, scene.integration
        # the gyro filter's latency is set by its design, at the first accepted samples' rate
        latency_s = integration.get("latency_s", "?")
        latency = (
            f"no latency figure: {why_none(verdict.nothing)}"
            if verdict.nothing
            else f"no latency figure: {NOT_DESIGNED}"
            if latency_s == "n/a"
            else f"latency {latency_s} s"
        )
        rows += [
            ["scene", f"{scene.name} from {scene.source}"],
            *([["scene checked", scene_check]] if scene_check else []),
            ["input", f"{spec.topic} ({spec.msg_type}), frame {spec.frame_id or 'any'}"],
            [
                "input conditioning",
                f"gyro_filter {spec.gyro_filter} ({latency}), hold {spec.hold}, "
                f"gaps > {spec.max_gap_s:g} s: {spec.gap_policy}",
            ],
            [
                "solver",
                f"{integ.method} ({ran}), rtol {integ.rtol:g}, "
                f"atol {integ.atol:g}, error estimate {'on' if integ.error_estimate else 'off'}",
            ],
        ]
    if est := integration.get("est_force_error_rel_run"):
        rows.append(
            [
                "estimated integration error over the run",
                NOT_INTEGRATED  # NaN: no interval estimated
                if est == "nan"
                else f"mount forces {est} of the largest, "
                f"attitude {integration.get('est_attitude_error_rad_run', '?')} rad",
            ]
        )
    heading = f"Verdict: {verdict.text}" + (" (partial run)" if partial else "")
    out = [f"<h2>{html.escape(heading)}</h2>", html_table(["", ""], rows)]
    if scene is not None:
        out += scene_section(scene)
    return out


def srs_section(
    stamps_ns: np.ndarray,
    f: np.ndarray,
    design: tuple[list[float], list[float]] | None = None,
    tolerance_db: tuple[float, float] = TOLERANCE_DB,
    design_name: str = "",
    design_axes: tuple[str, ...] = ("z",),
) -> tuple[list[str], bool | None]:
    """The input's shock response spectra (5 % damping; gravity and bias taken out as
    `mount-twin srs` does by default, the mean of a quiet head), per axis of F; with a design
    spectrum (Hz, g), the design on the plot, and for each of `design_axes` its margin (dB) in
    the table and its PASS/FAIL line (`analysis.design_margin`, as `mount-twin srs --design
    --axis`). Also whether every axis judged passed (None: nothing judged)."""
    from mount_twin.analysis.srs import (
        DEFAULT_DAMPING,
        gravity_offset,
        octave_frequencies,
        srs,
    )

    t = (stamps_ns - stamps_ns[0]) * 1e-9
    rate = (len(t) - 1) / float(t[-1]) if len(t) > 1 and t[-1] > 0 else 0.0
    if rate <= 0.0:
        return [], None
    freqs = octave_frequencies(5.0, min(2000.0, rate / 10.0), 6)
    offset, removed = gravity_offset(t, f)
    spectra = {
        axis: srs(f[:, k] - offset[k], rate, freqs, DEFAULT_DAMPING)
        for k, axis in enumerate("xyz")
    }
    checks = (
        {
            a: check_design(freqs, spectra[a].maximax / STANDARD_GRAVITY, *design, tolerance_db)
            for a in design_axes
        }
        if design is not None
        else {}
    )
    head = ["f Hz", "x g", "y g", "z g", "PV z m/s"]
    head += [f"margin {a} dB" for a in checks]
    verdicts = [
        f"<p><b>design {html.escape(design_name)}</b>, axis {a}: {html.escape(c.summary())}</p>"
        for a, c in checks.items()
    ]
    sections = [
        f"<h2>Shock response spectra of the input (ζ = {DEFAULT_DAMPING * 100:g} %, "
        f"{html.escape(removed)} removed)</h2>",
        *verdicts,
        png(lambda fig: draw_srs(fig, spectra, DEFAULT_DAMPING, design, tuple(checks)), (9, 4.5)),
        html_table(head, _srs_rows(freqs, spectra, checks)),
    ]
    return sections, (all(c.passed for c in checks.values()) if checks else None)


def _srs_rows(
    freqs: np.ndarray, spectra: dict[str, Spectrum], checks: dict[str, DesignCheck]
) -> list[list[str]]:
    """Every third frequency's row: f (Hz), maximax per axis (g), pseudo-velocity of z (m/s),
    and the margin (dB; '–' where the design does not reach) of each axis `checks` judged."""
    z = spectra["z"]
    margins = {
        a: dict(zip(c.frequency_hz.tolist(), c.margin_db.tolist(), strict=True))
        for a, c in checks.items()
    }
    return [
        [
            f"{fk:.4g}",
            *(f"{spectra[a].maximax[k] / STANDARD_GRAVITY:.4g}" for a in "xyz"),
            f"{z.pseudo_velocity[k]:.4g}",
            *(_margin_cell(margins[a][fk]) if fk in margins[a] else "–" for a in checks),
        ]
        for k, fk in enumerate(freqs.tolist())
        if k % 3 == 0
    ]


def _margin_cell(margin_db: float) -> str:
    """A margin in dB for the spectra table; a spectrum of 0 (−∞ dB) has no response."""
    return f"{margin_db:+.2f}" if np.isfinite(margin_db) else "no response"


def modes_section(scene: Scene) -> list[str]:
    """The scene's modes about its static equilibrium."""
    from mount_twin.analysis.modes import modes

    try:
        result = modes(scene)
    except (ModelError, np.linalg.LinAlgError) as err:  # no equilibrium or linearisation: said
        return ["<h2>Modes</h2>", f"<p>not computed: {html.escape(str(err))}</p>"]
    rows = []
    for i, m in enumerate(result.modes, 1):
        main_dof = m.dominant_dof
        rows.append(
            [
                str(i),
                frequency_text(m.frequency_hz),
                damping_text(m.damping_ratio),
                f"{main_dof} {energy_share_text(m.energy_fraction[main_dof])} %",
                *(effective_mass_text(m.effective_mass_kg[a]) for a in "xyz"),
            ]
        )
    head = [
        "mode",
        "f Hz",
        "ζ %",
        "dominant DOF (energy)",
        "m_eff x kg",
        "m_eff y kg",
        "m_eff z kg",
    ]
    return ["<h2>Modes (about the static equilibrium)</h2>", html_table(head, rows)]


def _recorded_settings(
    recorded: dict[str, str] | None, integration: dict[str, str], ran: str
) -> list[list[str]]:
    """The input and solver rows of a page without the scene: what the output bag records,
    the topic the run read and the frame it expected (`recorded`: the last input status'
    values), the method and tolerances (`integration`: the last integration status' values;
    `ran`: what ran), and that the rest (message type, input conditioning, the method set
    where one ran: the status then names it) needs --scene. A row the bag records nothing of
    is left out, not guessed."""
    rows = []
    if recorded and "topic" in recorded:
        frame = recorded.get("frame_id")
        said = "frame not recorded" if frame is None else f"frame {frame or 'any'}"
        rows.append(
            [
                "input",
                f"{recorded['topic']}, {said} (as the run's input status records them; "
                "message type and input conditioning: --scene)",
            ]
        )
    if "rtol" in integration:
        estimate = ", error estimate on" if "est_force_error_rel" in integration else ""
        # until one runs the status names the method set, which then needs no --scene
        method, none_ran = integration.get("method", "?"), not ran.startswith("ran")
        rows.append(
            [
                "solver",
                f"{f'{method} (the method set; {ran})' if none_ran else ran}, "
                f"rtol {integration['rtol']}, "
                f"atol {integration.get('atol', '?')}{estimate} (as the run's integration "
                f"status records them{'' if none_ran else '; the method the scene set: --scene'})",
            ]
        )
    return rows


def forces_sections(mounts: dict[str, Table], events: list[Event]) -> list[str]:
    """The mount forces over the run, and around the first event (± WINDOW_S)."""
    out = []
    if mounts:
        out += [
            "<h2>Mount forces (on the body, signed, in each mount's axes)</h2>",
            png(lambda fig: draw_forces(fig, mounts, events), (10, 8)),
        ]
    if events:
        first = events[0]
        window = (first.t_s - WINDOW_S, first.t_s + WINDOW_S)
        out += [
            f"<h2>Around the first event: {html.escape(first.mount)} {html.escape(first.event)} "
            f"at {first.t_s:.6f} s (lines: events)</h2>",
            png(lambda fig: draw_forces(fig, mounts, events, window), (10, 8)),
        ]
    return out


def displacement_line(pose: Table) -> str:
    """The CG's largest displacement from its first published position (m), a paragraph."""
    position = np.stack([pose.columns[f"{a}_m"] for a in "xyz"], axis=1)
    moved = displacement_from_start(position, position[0])
    return f"<p>{LABELS[DISPLACEMENT]}: {moved:.6g}</p>"


def peak_rows(
    mounts: dict[str, Table],
    kinds: dict[str, str],
    utilisation: dict[str, tuple[np.ndarray, np.ndarray]],
) -> list[list[str]]:
    """Per mount: name, kind, the largest |F| (N) and |M| (N·m) at one instant, and the
    largest utilisation (-; 'n/a' without a rating)."""
    rows = []
    for name, table in mounts.items():
        c = table.columns
        wrenches = np.stack([c[k] for k in WRENCHES_OUTPUT.columns], axis=1)[:, None, :]
        (force, couple), u = peak_magnitudes(wrenches)[0], utilisation.get(name)
        rows.append(
            [
                name,
                kinds.get(name, ""),
                peak_text(force),
                peak_text(couple),
                "n/a" if u is None else utilisation_text(float(u[1].max())),
            ]
        )
    return rows


def eventstable(events: list[Event]) -> str:
    """The mount events: time from the first output (s), mount, event, count in the period,
    largest |F| (N) and level."""
    return html_table(
        ["time s", "mount", "event", "count in period", "|F| max N", "level"],
        [
            [f"{e.t_s:.6f}", e.mount, e.event, str(e.count), f"{e.force_n:.4g}", e.level]
            for e in events
        ],
    )
