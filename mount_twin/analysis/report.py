"""One self-contained HTML page of a replay: plots, peaks, utilisation and events.

Built from the output bag (every series, and the diagnostics with their values), and if given
the input bag (the foundation's specific force beside the response) and the scene (mount kinds,
names in titles). Pictures are PNGs embedded as base64, so the page is one file that opens
anywhere. The page's sections are `report_sections`, its figures `report_plots` (matplotlib:
the `plot` extra), the run's verdict `run_verdict`, the scene's check `scene_check`.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import NamedTuple

import numpy as np

from mount_twin.analysis.design_margin import TOLERANCE_DB
from mount_twin.analysis.figures import LABELS, PEAK_COUPLE, PEAK_FORCE, peak_label
from mount_twin.analysis.html_page import page, png
from mount_twin.analysis.html_page import table as html_table
from mount_twin.analysis.report_plots import draw_response, draw_utilisation, utilisation_of
from mount_twin.analysis.report_sections import (
    displacement_line,
    eventstable,
    forces_sections,
    modes_section,
    peak_rows,
    provenance_section,
    srs_section,
)
from mount_twin.analysis.run_verdict import RunVerdict, followed_nothing, verdict_of
from mount_twin.analysis.scene_check import SceneCheck, check_scene, check_scene_is_the_bags
from mount_twin.engine.health_texts import why_none
from mount_twin.io.output_tables import Table, events_of, input_values, integration_values
from mount_twin.scene.description import Scene
from mount_twin.textfiles import write_text


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
        check_scene_is_the_bags(scene, set(mounts) or set(utilisation), output_bag)
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
    nothing = followed_nothing(diagnostics, scene)
    verdict, integration = verdict_of(diagnostics, nothing)
    sections += provenance_section(
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
                lambda fig: draw_response(fig, tables, input_samples, origin, input_name), (10, 8)
            ),
        ]
    sections += forces_sections(mounts, events)
    if utilisation and not nothing:  # a run without motion: its 0 would read as at rest
        period_s = scene.outputs.diagnostics_period_s if scene else None
        sections += [
            "<h2>Utilisation</h2>",
            png(lambda fig: draw_utilisation(fig, utilisation, kinds, period_s), (10, 4)),
        ]
        if period_s is None:
            sections.append(
                "<p>the first report's period is not drawn, only its marker: its length is the "
                "scene's outputs.diagnostics_period_s, which the bag does not record (--scene "
                "draws it)</p>"
            )
    design_passed = None
    if input_samples is not None:
        srs_sections, design_passed = srs_section(
            *input_samples, design, tolerance_db, design_name, design_axes
        )
        sections += srs_sections
    if scene is not None:
        sections += modes_section(scene)
    if "pose" in tables:
        sections.append(displacement_line(tables["pose"]))
    sections += [
        f"<h2>Peaks ({peak_label(scene.outputs.decimation if scene else 1)})</h2>",
        f"<p>none: {html.escape(why_none(nothing))}</p>"
        if nothing
        else html_table(
            ["mount", "kind", LABELS[PEAK_FORCE], LABELS[PEAK_COUPLE], "utilisation max"],
            peak_rows(mounts, kinds, utilisation),
        ),
        "<h2>Events</h2>",
        eventstable(events) if events else "<p>none</p>",
    ]
    out = Path(html_path)
    write_text(out, page(title, sections))
    return ReportPage(out, verdict, design_passed, checked)


class ReportPage(NamedTuple):
    """A report written: its file, the run's verdict, whether the input's spectra passed the
    design (None: no design judged them), and how far its scene was checked to be the run's
    (None: no scene)."""

    path: Path
    verdict: RunVerdict
    design_passed: bool | None
    scene_check: SceneCheck | None = None
