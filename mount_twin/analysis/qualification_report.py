"""The page a qualification hands over: one self-contained HTML file that opens with the
verdict, then the plan and its criteria, what produced it (software, date, file fingerprints), the
inputs' spectra against the design, each input's run, per mount the worst figures with their
margins, and the scene as loaded."""

from __future__ import annotations

import html
import math
from pathlib import Path
from typing import Any

from mount_twin.analysis.html_page import fingerprint, page, png, produced_by, scene_section, table
from mount_twin.analysis.log_labels import plain_log_labels
from mount_twin.analysis.qualification import InputRun, Plan
from mount_twin.io.design_spectrum import read_design_table
from mount_twin.scene.description import Scene
from mount_twin.textfiles import write_text


def write_qualification_report(
    path: str | Path, scene: Scene, plan: Plan, runs: list[InputRun], doc: dict[str, Any]
) -> Path:
    """Write the page of a qualification (`analysis.qualification.judge`'s `doc`)."""
    sections = [
        f"<h1>Shock qualification of {html.escape(scene.name)}</h1>",
        *_verdict_section(scene, plan, doc),
        *_spectra_section(plan, runs),
        "<h2>Inputs run through the twin</h2>",
        _runs_table(doc),
        "<h2>Per mount, the worst over the inputs</h2>",
        _mounts_table(doc),
        *scene_section(scene),
    ]
    out = Path(path)
    write_text(out, page(f"qualification of {scene.name}", sections))
    return out


def _verdict_section(scene: Scene, plan: Plan, doc: dict[str, Any]) -> list[str]:
    """The verdict and why, the plan, the criteria, the solver and its estimated error."""
    integ = scene.integration
    why = [
        *doc["why"]["failed"],
        *(f"{k}: {'; '.join(v)}" for k, v in doc["why"]["broken"].items()),
    ]
    estimate = doc["estimated_force_error_rel"]
    rows = [
        ["verdict", doc["verdict"]],
        ["why", "; ".join(why) or "every criterion met in every input"],
        ["produced by", produced_by()],
        ["scene", f"{scene.name} from {scene.source} ({fingerprint(Path(scene.source))})"],
        *(
            [f"design spectrum, axis {axis}", f"{file} ({fingerprint(Path(file))})"]
            for axis, file in plan.spectra.items()
        ),
        [
            "synthesis",
            f"{plan.seeds} inputs per axis (seeds {plan.first_seed}…"
            f"{plan.first_seed + plan.seeds - 1}), ζ = {plan.damping:g}, {plan.rate_hz:g} Hz, "
            f"tolerance {plan.tolerance_db[0]:+g}/{plan.tolerance_db[1]:+g} dB, "
            f"{plan.head_s:g} s of rest first",
        ],
        [
            "criteria",
            f"utilisation ≤ {plan.max_utilisation:g} for every rated mount; no "
            f"{'ERROR' if plan.fail_on == 'error' else 'WARN or ERROR'} in any run; "
            "no failed integration",
        ],
        [
            "solver",
            f"{integ.method}, rtol {integ.rtol:g}, atol {integ.atol:g}, error estimate "
            f"{'on' if integ.error_estimate else 'off'}",
        ],
        [
            "estimated integration error",
            "off"
            if estimate is None
            else f"mount forces {estimate:.2g} of the largest (worst input)",
        ],
    ]
    return [f"<h2>Verdict: {html.escape(doc['verdict'])}</h2>", table(["", ""], rows)]


def _spectra_section(plan: Plan, runs: list[InputRun]) -> list[str]:
    """Per axis, each input's maximax against the design and its tolerance band."""

    def draw(fig: Any) -> None:
        axes = fig.subplots(1, len(plan.spectra), squeeze=False)[0]
        low, high = (10.0 ** (db / 20.0) for db in plan.tolerance_db)
        for ax, (axis, file) in zip(axes, plan.spectra.items(), strict=True):
            freqs, design = read_design_table(file)
            ax.loglog(freqs, design, "k--", label="design")
            ax.loglog(freqs, [v * low for v in design], "k:", lw=1.0, label="tolerance")
            ax.loglog(freqs, [v * high for v in design], "k:", lw=1.0)
            for r in runs:
                if r.axis == axis:
                    ax.loglog(*r.spectrum, lw=1.2, label=f"seed {r.seed}")
            ax.set_title(f"axis {axis}: maximax of the inputs (ζ = {plan.damping:g})", fontsize=9)
            ax.set_xlabel("natural frequency [Hz]")
            ax.set_ylabel("peak absolute acceleration [g]")
            plain_log_labels(ax, "y")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)

    width = 6.0 * len(plan.spectra)
    return ["<h2>The inputs' spectra against the design</h2>", png(draw, (width, 4.5))]


def _runs_table(doc: dict[str, Any]) -> str:
    """One row per input: its spectrum's margins, the twin's verdict and its output bag."""
    rows = [
        [
            r["input"],
            f"{r['spectrum_margin_db'][0]:+.2f} / {r['spectrum_margin_db'][1]:+.2f}",
            r["verdict"] + (f" ({r['failure']})" if r["failure"] else ""),
            r["output_bag"],
        ]
        for r in doc["runs"]
    ]
    head = ["input (axis/seed)", "spectrum margin dB (low / high)", "twin", "output bag"]
    return table(head, rows)


def _mounts_table(doc: dict[str, Any]) -> str:
    """One row per mount: worst force, travel and utilisation, the margin, the events."""
    rows = []
    for name, m in doc["mounts"].items():
        u = m.get("utilisation_max")
        rows.append(
            [
                name,
                f"{m.get('force_max_N', math.nan):.1f} ({m.get('force_max_N_input', '')})",
                f"{1e3 * m.get('travel_max_m', math.nan):.3f} ({m.get('travel_max_m_input', '')})",
                "unrated" if u is None else f"{u:.3f} ({m['utilisation_max_input']})",
                "" if u is None else f"{m['margin']:+.3f}",
                ", ".join(f"{k} ×{n}" for k, n in m["events"].items()) or "none",
            ]
        )
    head = ["mount", "max |F| N (input)", "travel mm (input)", "utilisation", "margin", "events"]
    return table(head, rows)
