"""`mount-twin qualify SCENE --spectrum TABLE.csv -o DIR`: a resiliently mounted machine
against a shock specification, in the time domain.

Synthesises `--seeds` inputs that meet the design spectrum (`mount-twin synthesize`), replays
each through the twin on the scene (its own output bag beside its input bag in DIR), and judges
the machine on the worst over the inputs, per mount: the largest force, the largest
utilisation (bolt F/F_y, rubber deflection/rated, key F/allowable, linear ratings) and its
margin 1 − utilisation, the mount events; with the twin's own error estimate. The verdict:
FAILED (exit 6) if an integration failed (no figure of that run can be trusted), FAIL (exit 4)
if any run reached ERROR (a limit passed: utilisation over 1, a bolt yielded or broke, a joint
opened, a key overloaded), else PASS (exit 0; WARNs are listed).
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from mount_twin.commands.synthesize import add_synthesis_arguments
from mount_twin.io.epoch import DEFAULT_START_NS

if TYPE_CHECKING:
    from mount_twin.replay import ReplaySummary

NAME = "qualify"
HELP = "qualify the scene's machine against a shock spectrum: synthesise, run, judge each mount"
EXIT_FAIL, EXIT_FAILED = 4, 6


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML")
    parser.add_argument(
        "-o", "--output", required=True, help="directory (new) of the input and output bags"
    )
    add_synthesis_arguments(parser)
    parser.add_argument("--json", metavar="FILE", help="the verdict and per-mount results")
    parser.epilog = (
        f"exit status: 0 PASS; 2 bad input; {EXIT_FAIL} FAIL (a limit passed in some run); "
        f"{EXIT_FAILED} FAILED (an integration failed: not judged)"
    )


def run(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from mount_twin.commands.common import load_scene, write_signal
    from mount_twin.commands.synthesize import describe, synthesized
    from mount_twin.replay import replay

    scene = load_scene(args.scene)
    out = Path(args.output)
    if out.exists():
        msg = f"{out}: exists; qualify writes a new directory"
        raise ValueError(msg)
    frame_id = scene.input.frame_id or "deck_imu"
    runs = []
    for seed, shock, sig in synthesized(args):
        out.mkdir(parents=True, exist_ok=True)
        bag_in, bag_out = out / f"input_seed_{seed}", out / f"output_seed_{seed}"
        write_signal(sig, str(bag_in), scene.input.topic, frame_id, DEFAULT_START_NS, "mcap")
        print(f"seed {seed}: {describe(shock, args)}")
        summary = replay(scene, bag_in, bag_out, progress=False)
        why = f" ({summary.failure})" if summary.failure else ""
        print(f"  replayed into {bag_out}: {summary.verdict}{why}")
        runs.append((seed, summary))
    result = judge(runs)
    print(result["text"])
    if args.json:
        Path(args.json).write_text(json.dumps(result["doc"], indent=1), encoding="utf-8")
        print(f"json: {args.json}")
    return {"PASS": 0, "FAIL": EXIT_FAIL, "FAILED": EXIT_FAILED}[result["doc"]["verdict"]]


def judge(runs: list[tuple[int, ReplaySummary]]) -> dict[str, Any]:
    """The worst over the runs per mount, the verdict, as text and as a JSON document."""
    verdicts = [s.verdict for _, s in runs]
    verdict = "FAILED" if "FAILED" in verdicts else "FAIL" if "ERROR" in verdicts else "PASS"
    mounts: dict[str, dict[str, Any]] = {}
    for seed, s in runs:
        for name, peak in s.peaks.items():
            m = mounts.setdefault(
                name,
                {
                    "force_max_N": 0.0,
                    "force_max_seed": seed,
                    "utilisation_max": None,
                    "utilisation_max_seed": None,
                    "events": {},
                },
            )
            if float(peak[0]) > m["force_max_N"]:
                m["force_max_N"], m["force_max_seed"] = float(peak[0]), seed
            u = s.utilisation_max.get(name)
            if u is not None and (m["utilisation_max"] is None or u > m["utilisation_max"]):
                m["utilisation_max"], m["utilisation_max_seed"] = u, seed
        for e in s.events:
            key = f"{e.event} ({e.level})"
            events = mounts.setdefault(e.mount, {"events": {}})["events"]
            events[key] = events.get(key, 0) + 1
    estimates = [s.error_estimate.force_error_rel for _, s in runs if s.error_estimate]
    lines = [
        f"qualification: {verdict} over {len(runs)} inputs ({', '.join(verdicts)})",
        f"  {'mount':>12} {'max |F| N':>12} {'utilisation':>11} {'margin':>7}  "
        "events (all inputs)",
    ]
    for name, m in mounts.items():
        u = m["utilisation_max"]
        m["margin"] = None if u is None else 1.0 - u
        shown_u = "unrated" if u is None else f"{u:.3f}"
        shown_m = "" if u is None else f"{1.0 - u:+.3f}"
        events = ", ".join(f"{k} ×{n}" for k, n in m["events"].items()) or "none"
        lines.append(f"  {name:>12} {m['force_max_N']:12.1f} {shown_u:>11} {shown_m:>7}  {events}")
    if estimates:
        lines.append(
            f"  the twin's estimated force error: at most {max(estimates):.2g} of the largest "
            "force over the inputs"
        )
    doc = {
        "verdict": verdict,
        "runs": [
            {"seed": seed, "verdict": s.verdict, "failure": s.failure, "output_bag": s.output_bag}
            for seed, s in runs
        ],
        "mounts": mounts,
        "estimated_force_error_rel": max(estimates) if estimates else None,
    }
    return {"text": "\n".join(lines), "doc": doc}
