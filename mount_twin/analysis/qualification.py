"""A shock qualification: its plan (design spectra per axis, synthesis, pass criteria), the
results of each synthesised input, and the judgement over them.

A plan file (YAML, the scene files' rules: unknown keys refused, errors name the key path):

    spectra:                  # design spectra (frequency_hz,accel_g CSV, maximax), per axis
      z: vertical.csv         #   of the input sensor; paths relative to the plan
      y: athwartship.csv
    damping: 0.05             # ζ of the spectra (or q: 10)
    seeds: 3                  # synthesised inputs per axis
    first_seed: 0
    rate_hz: 20000.0
    tolerance_db: [-1.5, 3.0] # every frequency of every input within this band of the design
    head_s: 0.05              # rest before each shock, s
    criteria:
      max_utilisation: 1.0    # FAIL where a mount's utilisation passes this
      fail_on: error          # FAIL on any ERROR (a limit passed), or on any WARN too: warn

The verdict: FAILED if any run's integration failed (its figures are not the machine's: not
judged), FAIL if a criterion is broken in any run, else PASS.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mount_twin.analysis.design_margin import TOLERANCE_DB
from mount_twin.analysis.srs import damping_ratio
from mount_twin.engine.health_texts import ratio_text
from mount_twin.scene.reader import Reader
from mount_twin.scene.yaml_reading import read_scene_yaml

AXES = ("x", "y", "z")
FAIL_ON = ("error", "warn")


@dataclass(frozen=True)
class Plan:
    """What a qualification runs and how it judges (module docstring; SI units, dB, Hz)."""

    spectra: dict[str, str]
    damping: float = 0.05
    seeds: int = 3
    first_seed: int = 0
    rate_hz: float = 20000.0
    tolerance_db: tuple[float, float] = TOLERANCE_DB
    head_s: float = 0.05
    max_utilisation: float = 1.0
    fail_on: str = "error"
    source: str = "<command line>"

    @property
    def inputs(self) -> list[tuple[str, int]]:
        """(axis, seed) of every input, axis by axis."""
        seeds = range(self.first_seed, self.first_seed + self.seeds)
        return [(axis, seed) for axis in self.spectra for seed in seeds]

    def as_dict(self) -> dict[str, Any]:
        """The plan as a JSON-able mapping (the report and --json show it)."""
        return {
            "source": self.source,
            "spectra": self.spectra,
            "damping": self.damping,
            "seeds": self.seeds,
            "first_seed": self.first_seed,
            "rate_hz": self.rate_hz,
            "tolerance_db": list(self.tolerance_db),
            "head_s": self.head_s,
            "criteria": {"max_utilisation": self.max_utilisation, "fail_on": self.fail_on},
        }


def load_plan(path: str | Path) -> Plan:
    """Read and check a plan file; errors name the file and the key path."""
    path = Path(path)
    top = Reader(read_scene_yaml(path), str(path))
    spectra = top.sub("spectra", optional=False)
    axes = [a for a in spectra.data if a in AXES]
    if not axes or len(axes) != len(spectra.data):
        raise top.error("spectra", f"give a design CSV per axis, axes among {', '.join(AXES)}")
    files = {a: str((path.parent / spectra.string(a)).resolve()) for a in axes}
    for axis, file in files.items():
        if not Path(file).is_file():
            raise spectra.error(axis, f"no such file: {file}")
    spectra.finish()
    if top.has("damping") and top.has("q"):
        raise top.error("q", "give the damping as damping (ζ) or as q, not both")
    given = "q" if top.has("q") else "damping"
    try:
        zeta = damping_ratio(top.number("damping", 0.05) if given == "damping" else None, _q(top))
    except ValueError as err:
        raise top.error(given, str(err)) from err
    low_db, high_db = top.vector("tolerance_db", 2, TOLERANCE_DB)
    if not low_db < 0.0 < high_db:
        raise top.error(
            "tolerance_db", f"expected [LOW, HIGH] dB, LOW < 0 < HIGH, got {[low_db, high_db]}"
        )
    criteria = top.sub("criteria")
    plan = Plan(
        files,
        zeta,
        top.integer("seeds", 3, lo=1, hi=1000),
        top.integer("first_seed", 0),
        top.positive("rate_hz", 20000.0),
        (low_db, high_db),
        top.number("head_s", 0.05, lo=0.0),
        criteria.positive("max_utilisation", 1.0),
        criteria.choice("fail_on", FAIL_ON, "error"),
        str(path),
    )
    criteria.finish()
    top.finish()
    return plan


def _q(top: Reader) -> float | None:
    """The plan's quality factor, if it gives one."""
    return top.positive("q") if top.has("q") else None


@dataclass
class InputRun:
    """One synthesised input run through the twin.

    Attributes:
        axis, seed: which input.
        verdict: the replay's (OK, WARN, ERROR, FAILED); failure: why it FAILED ('' if not).
        output_bag: where its outputs are.
        margin_db: the input's spectrum against the design: (worst low, worst high) margin.
        spectrum: the input's maximax (frequencies Hz, values g) where the design covers.
        force_n, utilisation, travel_m: per mount, the largest |F| (N), utilisation (rated
            mounts only) and travel (m, `analysis.figures.TRAVEL`).
        events: (mount, event, level) of every mount event.
        estimate: the twin's estimated force error, of the largest force (NaN: off).
    """

    axis: str
    seed: int
    verdict: str
    failure: str
    output_bag: str
    margin_db: tuple[float, float]
    spectrum: tuple[list[float], list[float]]
    force_n: dict[str, float]
    utilisation: dict[str, float]
    travel_m: dict[str, float]
    events: list[tuple[str, str, str]] = field(default_factory=list)
    estimate: float = math.nan
    statuses: list[tuple[str, str, str]] = field(default_factory=list)
    """(name, level, message) of each diagnostics status that reached WARN or ERROR, at its
    worst over the run."""


def _broken(run: InputRun, plan: Plan) -> list[str]:
    """The criteria `run` breaks, in words."""
    out = []
    levels = ("ERROR",) if plan.fail_on == "error" else ("ERROR", "WARN")
    if run.verdict in levels:
        seen = Counter(f"{m} {e}" for m, e, level in run.events if level in levels)
        said = ", ".join(f"{k} ×{n}" for k, n in seen.items()) or "; ".join(
            f"{name}: {message}" for name, level, message in run.statuses if level in levels
        )
        out.append(f"diagnostics reached {run.verdict} ({said})")
    limit = plan.max_utilisation
    over = [f"{m} {ratio_text(u, '.3f', limit)}" for m, u in run.utilisation.items() if u > limit]
    if over:
        out.append(f"utilisation over {plan.max_utilisation:g}: {', '.join(over)}")
    return out


def judge(runs: list[InputRun], plan: Plan) -> dict[str, Any]:
    """The verdict over the runs and, per mount, the worst of each figure with the input that
    gave it, as a JSON-able document."""
    failed = [r for r in runs if r.verdict == "FAILED"]
    broken = {f"{r.axis}/{r.seed}": b for r in runs if (b := _broken(r, plan))}
    verdict = "FAILED" if failed else "FAIL" if broken else "PASS"
    mounts: dict[str, dict[str, Any]] = {}
    for r in runs:
        for name in r.force_n:
            m = mounts.setdefault(name, {"events": {}})
            for key, values in (
                ("force_max_N", r.force_n),
                ("utilisation_max", r.utilisation),
                ("travel_max_m", r.travel_m),
            ):
                value = values.get(name)
                if value is not None and (key not in m or value > m[key]):
                    m[key], m[f"{key}_input"] = value, f"{r.axis}/{r.seed}"
        for mount, event, level in r.events:
            key = f"{event} ({level})"
            events = mounts.setdefault(mount, {"events": {}})["events"]
            events[key] = events.get(key, 0) + 1
    for m in mounts.values():
        u = m.get("utilisation_max")
        m["margin"] = None if u is None else plan.max_utilisation - u
    estimates = [r.estimate for r in runs if not math.isnan(r.estimate)]
    return {
        "verdict": verdict,
        "why": {"failed": [f"{r.axis}/{r.seed}: {r.failure}" for r in failed], "broken": broken},
        "plan": plan.as_dict(),
        "runs": [
            {
                "input": f"{r.axis}/{r.seed}",
                "verdict": r.verdict,
                "failure": r.failure,
                "output_bag": r.output_bag,
                "spectrum_margin_db": list(r.margin_db),
            }
            for r in runs
        ],
        "mounts": mounts,
        "estimated_force_error_rel": max(estimates) if estimates else None,
    }


def reasons(doc: dict[str, Any]) -> list[str]:
    """Why the verdict is not PASS: the failed runs, then the criteria each run broke."""
    broken = [f"{k}: {'; '.join(v)}" for k, v in doc["why"]["broken"].items()]
    return [*doc["why"]["failed"], *broken]


def verdict_text(doc: dict[str, Any]) -> str:
    """The judgement as the printed table: the verdict, then per mount its worst figures."""
    runs = [f"{r['input']} {r['verdict']}" for r in doc["runs"]]
    lines = [
        f"qualification: {doc['verdict']} over {len(runs)} inputs ({', '.join(runs)})",
        f"  {'mount':>12} {'max |F| N':>12} {'travel mm':>9} {'utilisation':>11} {'margin':>7}"
        "  events (all inputs)",
    ]
    for name, m in doc["mounts"].items():
        u = m.get("utilisation_max")
        shown_u = "unrated" if u is None else f"{u:.3f}"
        shown_m = "" if u is None else f"{m['margin']:+.3f}"
        travel = 1e3 * m.get("travel_max_m", math.nan)
        events = ", ".join(f"{k} ×{n}" for k, n in m["events"].items()) or "none"
        lines.append(
            f"  {name:>12} {m.get('force_max_N', math.nan):12.1f} {travel:9.3f} {shown_u:>11}"
            f" {shown_m:>7}  {events}"
        )
    for why in [
        *doc["why"]["failed"],
        *(f"{k}: {'; '.join(v)}" for k, v in doc["why"]["broken"].items()),
    ]:
        lines.append(f"  {why}")
    if doc["estimated_force_error_rel"] is not None:
        lines.append(
            f"  the twin's estimated force error: at most {doc['estimated_force_error_rel']:.2g}"
            " of the largest force over the inputs"
        )
    return "\n".join(lines)
