"""One self-contained HTML page of a replay: plots, peaks, utilisation and events.

Built from the output bag (every series, and the diagnostics with their values), and if given
the input bag (the foundation's specific force beside the response) and the scene (mount kinds,
names in titles). Pictures are PNGs embedded as base64, so the page is one file that opens
anywhere. matplotlib is imported here only (the `plot` extra).
"""

from __future__ import annotations

import html
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from mount_twin.analysis.design_margin import TOLERANCE_DB, DesignCheck, check_design
from mount_twin.analysis.figures import (
    DISPLACEMENT,
    LABELS,
    PEAK_COUPLE,
    PEAK_FORCE,
    displacement_from_start,
    peak_label,
    peak_magnitudes,
    peak_text,
    utilisation_text,
)
from mount_twin.analysis.html_page import (
    fingerprint,
    frame_id_setting,
    page,
    png,
    produced_by,
    scene_section,
)
from mount_twin.analysis.html_page import table as html_table
from mount_twin.analysis.log_labels import plain_log_labels
from mount_twin.analysis.modes_text import (
    damping_text,
    effective_mass_text,
    energy_share_text,
    frequency_text,
)
from mount_twin.engine.batch import FAILED, LEVEL_NAMES, OK
from mount_twin.engine.estimate import NOT_INTEGRATED
from mount_twin.engine.health import (
    INTEGRATION,
    NEVER_STARTED,
    NOT_DESIGNED,
    UTILISATION_KEY,
    why_none,
)
from mount_twin.engine.intake import nothing_accepted
from mount_twin.errors import ModelError, MountTwinError
from mount_twin.io.bag import partial_marker
from mount_twin.io.messages import WRENCHES_OUTPUT
from mount_twin.io.output_tables import (
    Event,
    Table,
    events_of,
    input_values,
    integration_values,
)
from mount_twin.io.scene_record import RecordedScene, recorded_scene
from mount_twin.model.scene_file import read_scene
from mount_twin.scene.description import (
    STANDARD_GRAVITY,
    Scene,
    scene_differences,
    scene_digest,
    scene_value,
)
from mount_twin.textfiles import write_text

if TYPE_CHECKING:
    from mount_twin.analysis.srs import Spectrum

WINDOW_S = 0.05
"""Half-width of the zoom around the first event, s."""
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


def _nothing_accepted(diagnostics: Table | None, scene: Scene | None) -> str:
    """Why no input sample of the run was accepted, as its replay's summary says it, from the
    counts of its last input status ('' if some were, or the bag holds no counts), pointing at
    what set the frame id it expected (`frame_id_setting`: the run of `scene`; without it,
    the frame the status records)."""
    values = input_values(diagnostics)
    counts = {
        k: int(v)
        for k, v in values.items()
        if (k in ("received", "accepted") or k.startswith("rejected_")) and v.isdigit()
    }
    if counts.get("accepted") != 0:  # some were, or no counts: the scene's file is not read
        return ""
    setting = frame_id_setting(scene, values.get("frame_id"))
    return nothing_accepted(counts, values.get("last_wrong_frame_id"), setting)


def _followed_nothing(diagnostics: Table | None, scene: Scene | None) -> str:
    """Why the twin followed none of the input, as its replay says it ('' if it did): no input
    sample accepted (`_nothing_accepted`), or too few to start it, which the stream's last
    integration status says (`health.NEVER_STARTED`). Either has no figures, and exits 3."""
    if nothing := _nothing_accepted(diagnostics, scene):
        return nothing
    if diagnostics is None:
        return ""
    c = diagnostics.columns
    said = [m for st, m in zip(c["status"], c["message"], strict=True) if st == INTEGRATION]
    return said[-1] if said and said[-1].startswith(NEVER_STARTED) else ""


class RunVerdict(NamedTuple):
    """A run's verdict as its output bag's diagnostics tell it.

    text: as the page heads it; worst_level: the worst diagnostics level over the run (index
    in LEVEL_NAMES; None: the bag holds no diagnostics); failure: how often the integration
    failed ('' if never: else the run is FAILED); nothing: why the twin followed none of the
    input ('' if it did: `_followed_nothing`)."""

    text: str
    worst_level: int | None
    failure: str
    nothing: str


def _verdict(diagnostics: Table | None, nothing: str) -> tuple[RunVerdict, dict[str, str]]:
    """The run's verdict from its diagnostics (FAILED if the integration ever failed, else the
    worst level of any status but the live-only `mount_twin: ros`, with `nothing`: why the
    twin followed none of the input, if it did not), and the last integration status' values."""
    if diagnostics is None or not len(diagnostics):
        return RunVerdict("no diagnostics in the bag", None, "", nothing), {}
    c = diagnostics.columns
    worst = OK
    for status, level in zip(c["status"], c["level"], strict=True):
        if status != "mount_twin: ros" and level in LEVEL_NAMES:
            worst = max(worst, LEVEL_NAMES.index(level))
    integration = integration_values(diagnostics)
    if failures := int(integration.get("failures_total", "0")):
        failure = f"{failures} integration failures"
        return RunVerdict(f"{FAILED} ({failure})", worst, failure, nothing), integration
    if nothing:
        return RunVerdict(f"{LEVEL_NAMES[worst]}: {nothing}", worst, "", nothing), integration
    return RunVerdict(LEVEL_NAMES[worst], worst, "", nothing), integration


def _provenance_section(
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


def _srs_section(
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
        png(lambda fig: _draw_srs(fig, spectra, DEFAULT_DAMPING, design, tuple(checks)), (9, 4.5)),
        html_table(head, _srs_rows(freqs, spectra, checks)),
    ]
    return sections, (all(c.passed for c in checks.values()) if checks else None)


def _draw_srs(
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


def _modes_section(scene: Scene) -> list[str]:
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


def write_report(
    output_bag: str | Path,
    html_path: str | Path,
    *,
    bag_tables: list[Table],
    input_samples: tuple[np.ndarray, np.ndarray] | None = None,
    scene: Scene | None = None,
    input_name: str = "",
    input_path: str | Path | None = None,
    input_note: str = "",
    design: tuple[list[float], list[float]] | None = None,
    design_axes: tuple[str, ...] = ("z",),
    tolerance_db: tuple[float, float] = TOLERANCE_DB,
    design_name: str = "",
    other_scene: bool = False,
) -> ReportPage:
    """Write the report page of the output bag whose tables are `bag_tables` (`read_output_bag` of
    `output_bag`, which the page names, hashes and checks for a partial run). `input_samples`:
    (stamps ns, specific force (n, 3) m/s² in F) of the record, to plot beside the response, every
    value finite; `input_path`: the record's bag, hashed for its provenance; `input_note`: what of
    it was left out (its samples not finite), said beside it; `design` (Hz, g): a design spectrum
    the input's spectra along `design_axes` (of F; z, as `report --design` and `srs --design`
    judge by default) are judged against (within `tolerance_db`), named `design_name` (its file).
    The page opens with the verdict, what produced it and with what settings, and the scene as
    loaded (every value with its meaning and unit). A scene that is not the run's
    (`check_scene`) is a ValueError, or with `other_scene` drawn with all the same, the page
    saying so."""
    tables = {t.name: t for t in bag_tables}
    mounts = {k.removeprefix("mount_"): t for k, t in tables.items() if k.startswith("mount_")}
    origin = min(int(t.columns["stamp_ns"][0]) for t in tables.values() if len(t))
    diagnostics = tables.get("diagnostics")
    events = events_of(diagnostics, origin) if diagnostics else []
    utilisation = utilisation_of(diagnostics) if diagnostics else {}
    kinds = {m.name: m.kind for m in scene.mounts} if scene else {}
    checked = None
    if scene:
        _check_scene_is_the_bags(scene, set(mounts) or set(utilisation), output_bag)
        checked = check_scene(scene, output_bag, integration_values(diagnostics))
        if checked.differs and not other_scene:
            msg = f"{checked.text}: give the run's own scene (--other-scene: draw with this one)"
            raise ValueError(msg)
        # the scene's order, as the replay's summary has them (else the bag's topics')
        mounts = {m.name: mounts[m.name] for m in scene.mounts if m.name in mounts} | mounts
    title = f"{scene.name if scene else 'mount_twin'} — {Path(output_bag).name}"
    if input_name:
        title += f" (input {input_name})"
    sections = [f"<h1>{html.escape(title)}</h1>"]
    nothing = _followed_nothing(diagnostics, scene)
    verdict, integration = _verdict(diagnostics, nothing)
    sections += _provenance_section(
        verdict,
        integration,
        output_bag,
        input_path,
        scene,
        input_note,
        input_values(diagnostics),
        "" if checked is None else checked.page_text,
    )
    if "pose" in tables and "angles" in tables:
        sections += [
            "<h2>Input and response</h2>",
            png(
                lambda fig: _draw_response(fig, tables, input_samples, origin, input_name), (10, 8)
            ),
        ]
    sections += _forces_sections(mounts, events)
    if utilisation and not nothing:  # a run without motion: its 0 would read as at rest
        period_s = scene.outputs.diagnostics_period_s if scene else None
        sections += [
            "<h2>Utilisation</h2>",
            png(lambda fig: _draw_utilisation(fig, utilisation, kinds, period_s), (10, 4)),
        ]
        if period_s is None:
            sections.append(
                "<p>the first report's period is not drawn, only its marker: its length is the "
                "scene's outputs.diagnostics_period_s, which the bag does not record (--scene "
                "draws it)</p>"
            )
    design_passed = None
    if input_samples is not None:
        srs_sections, design_passed = _srs_section(
            *input_samples, design, tolerance_db, design_name, design_axes
        )
        sections += srs_sections
    if scene is not None:
        sections += _modes_section(scene)
    if "pose" in tables:
        sections.append(_displacement_line(tables["pose"]))
    sections += [
        f"<h2>Peaks ({peak_label(scene.outputs.decimation if scene else 1)})</h2>",
        f"<p>none: {html.escape(why_none(nothing))}</p>"
        if nothing
        else html_table(
            ["mount", "kind", LABELS[PEAK_FORCE], LABELS[PEAK_COUPLE], "utilisation max"],
            _peak_rows(mounts, kinds, utilisation),
        ),
        "<h2>Events</h2>",
        _eventstable(events) if events else "<p>none</p>",
    ]
    out = Path(html_path)
    write_text(out, page(title, sections))
    return ReportPage(out, verdict, design_passed, checked)


class SceneCheck(NamedTuple):
    """How far a scene was found to be its output bag's run's own (`check_scene`).

    text: how it was checked and what was found; differs: it is not the run's; by_digest: the
    bag recorded its scene's digest (else only the facts `text` names were compared)."""

    text: str
    differs: bool
    by_digest: bool

    @property
    def page_text(self) -> str:
        """The report page's line on it."""
        if self.differs:
            return f"NOT the run's, drawn with on request (--other-scene): {self.text}"
        return self.text


class ReportPage(NamedTuple):
    """A report written: its file, the run's verdict, whether the input's spectra passed the
    design (None: no design judged them), and how far its scene was checked to be the run's
    (None: no scene)."""

    path: Path
    verdict: RunVerdict
    design_passed: bool | None
    scene_check: SceneCheck | None = None


CHECKED_SETTINGS = ("rtol", "atol")
"""The scene's integration settings its run's integration status records (`health`)."""


def check_scene(scene: Scene, output_bag: str | Path, integration: dict[str, str]) -> SceneCheck:
    """Whether `scene` (with the input topic and frame the run read, as `report` gives it) is
    the one the run of `output_bag` ran (its mount names are checked before:
    `_check_scene_is_the_bags`). By the digest the bag records (`io.scene_record`: its
    `~/scene` topic, a replay's or the node's recorded, else its metadata): any value
    differing (a mount's stiffness, the mass, the diagnostics period, a rating) makes another,
    the values named (`_differing`). A bag that records none (a recording of the node's topics
    by a mount_twin that did not publish its scene, or a replay by one that did not record it)
    tells only some settings: the solver's tolerances its last integration status records
    (`integration`: its values), compared, the first that differs named."""
    recorded = recorded_scene(output_bag)
    if recorded is not None:
        digest = scene_digest(scene)
        ran = recorded.named
        if digest == recorded.sha256:
            text = f"the run's: its digest is the one {output_bag} records (sha256 {digest})"
            how = "its replay's" if recorded.replayed else "the run's"
            return SceneCheck(f"{text}, {how} of {ran}", False, True)
        verb = "replayed" if recorded.replayed else "run"
        text = (
            f"{scene.source}: scene {scene.name} is not the one {output_bag} was {verb} with, "
            f"{ran}: its digest (sha256 {digest}) differs from the one {recorded.where} "
            f"records ({recorded.sha256}); {_differing(scene, recorded, output_bag)}"
        )
        return SceneCheck(text, True, True)
    compared = [key for key in CHECKED_SETTINGS if key in integration]
    for key in compared:
        value = f"{getattr(scene.integration, key):g}"
        if integration[key] != value:
            text = (
                f"{scene.source}: scene {scene.name} is not the one {output_bag} was run with: "
                f"its integration.{key} is {value}, the run's {integration[key]} (as its "
                "integration status records it)"
            )
            return SceneCheck(text, True, False)
    facts = ", ".join(["its mount names", *(f"integration.{key}" for key in compared)])
    text = (
        f"by {facts} only: {output_bag} records no digest of its scene (a recording of the "
        "node's topics without its ~/scene, a replay by a mount_twin that did not record it, "
        "or a storage file without its metadata.yaml), so a scene "
        "differing in another value (a stiffness, the mass, the diagnostics period, a rating) "
        "is not told apart"
    )
    return SceneCheck(text, False, False)


SHOWN_DIFFERENCES = 3
"""How many of the values a scene differs from its run's in `check_scene` names."""


def _differing(scene: Scene, recorded: RecordedScene, output_bag: str | Path) -> str:
    """Which values `scene` differs in from the run's (`SHOWN_DIFFERENCES` of them, by key
    path: `scene_differences`): the value the bag records (`recorded`), else that of the run's
    scene file where it still loads to the recorded digest (`_run_value`); else why that
    cannot be said."""
    if recorded.value is not None:
        run, read = recorded.value, f"as {recorded.where} records it"
    else:
        found = _run_value(scene, recorded, output_bag)
        if isinstance(found, str):
            return f"{found}: cannot say which value differs"
        run, read = found
    found_values = scene_differences(scene, run)
    if not found_values:  # equal as numbers, not as the digest's JSON text
        return (
            "its values equal the run's as numbers and differ only as the digest writes them "
            "(-0.0 against 0.0, 1 against 1.0)"
        )
    shown = "; ".join(
        f"{key}: {here!r} here, {there!r} in the run's scene"
        for key, here, there in found_values[:SHOWN_DIFFERENCES]
    )
    more = len(found_values) - SHOWN_DIFFERENCES
    return (
        f"it differs in {shown}"
        + (f" (and {more} more values)" if more > 0 else "")
        + f" (the run's scene {read})"
    )


def _run_value(
    scene: Scene, recorded: RecordedScene, output_bag: str | Path
) -> tuple[dict[str, Any], str] | str:
    """The value of the run's scene as its file loads it today, with what was put over it
    (an override whose value the bag does not hold: `scene`'s, which has the run's input),
    and how it was read; or why it cannot be had. A relative path (a bag written before the
    replay recorded it absolute) is found from here, else from the bag's directory."""
    if recorded.file is None:
        return "the run's scene came from no file"
    found = _found(recorded.file, output_bag)
    if isinstance(found, str):
        return found
    path, how = found
    fields = {key.removeprefix("input."): value for key, value in recorded.overrides.items()}
    try:  # a replay's overrides are `input` fields
        run = read_scene(
            path, {k: getattr(scene.input, k) if v is None else v for k, v in fields.items()}
        )
    except (MountTwinError, ValueError, OSError) as err:
        return f"the run's scene file {path} no longer loads ({err})"
    if scene_digest(run) != recorded.sha256:
        return f"the run's scene file {path} has changed since"
    return scene_value(run), f"as its file {path}{how} loads it"


def _found(file: str, output_bag: str | Path) -> tuple[Path, str] | str:
    """The run's scene file recorded as `file`, and how it was found ('' for an absolute
    path; else ", FILE found from here" or "from the bag's directory"); or why it is not
    found. A relative path (a bag written before the replay recorded it absolute) is looked
    for from here, then from the bag's directory: where the replay ran if its `-o` named no
    directory."""
    path = Path(file)
    if path.is_absolute():
        return (path, "") if path.is_file() else f"the run's scene file {file} is not found"
    bases = {"here": Path.cwd(), "the bag's directory": Path(output_bag).resolve().parent}
    for name, base in bases.items():
        if (base / path).is_file():
            return base / path, f", {file} found from {name}"
    here, beside = bases.values()
    return (
        f"the run's scene file {file} is not found from here ({here}) nor from the bag's "
        f"directory ({beside})"
    )


def _check_scene_is_the_bags(scene: Scene, in_bag: set[str], output_bag: str | Path) -> None:
    """ValueError unless the bag's mounts (those it holds wrenches or statuses of) are the
    scene's: another scene's name, kinds, modes and scene table would head the bag's numbers."""
    names = [m.name for m in scene.mounts]
    if in_bag and in_bag != set(names):
        msg = (
            f"scene {scene.name} (report --scene): its mounts ({', '.join(names)}) are not "
            f"those of {output_bag} ({', '.join(sorted(in_bag))}): give the replay's own scene"
        )
        raise ValueError(msg)


def _draw_response(
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


def _draw_forces(
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


def _forces_sections(mounts: dict[str, Table], events: list[Event]) -> list[str]:
    """The mount forces over the run, and around the first event (± WINDOW_S)."""
    out = []
    if mounts:
        out += [
            "<h2>Mount forces (on the body, signed, in each mount's axes)</h2>",
            png(lambda fig: _draw_forces(fig, mounts, events), (10, 8)),
        ]
    if events:
        first = events[0]
        window = (first.t_s - WINDOW_S, first.t_s + WINDOW_S)
        out += [
            f"<h2>Around the first event: {html.escape(first.mount)} {html.escape(first.event)} "
            f"at {first.t_s:.6f} s (lines: events)</h2>",
            png(lambda fig: _draw_forces(fig, mounts, events, window), (10, 8)),
        ]
    return out


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


def _draw_utilisation(
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


def _displacement_line(pose: Table) -> str:
    """The CG's largest displacement from its first published position (m), a paragraph."""
    position = np.stack([pose.columns[f"{a}_m"] for a in "xyz"], axis=1)
    moved = displacement_from_start(position, position[0])
    return f"<p>{LABELS[DISPLACEMENT]}: {moved:.6g}</p>"


def _peak_rows(
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


def _eventstable(events: list[Event]) -> str:
    """The mount events: time from the first output (s), mount, event, count in the period,
    largest |F| (N) and level."""
    return html_table(
        ["time s", "mount", "event", "count in period", "|F| max N", "level"],
        [
            [f"{e.t_s:.6f}", e.mount, e.event, str(e.count), f"{e.force_n:.4g}", e.level]
            for e in events
        ],
    )
