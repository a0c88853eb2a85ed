"""`mount-twin qualify SCENE (--spectrum TABLE.csv | --plan PLAN.yaml) -o DIR`: a resiliently
mounted machine against a shock specification, in the time domain.

Synthesises inputs that meet the design spectra (`mount-twin synthesize`: `--seeds` per axis),
replays each through the twin on the scene (its output bag beside its input bag in DIR), on a
Dask cluster where dask is installed (`--workers`, `--scheduler`; else one after the other), and
judges the machine on the worst over the inputs, per mount: the largest force, travel and
utilisation (bolt F/F_y, rubber deflection/rated, key F/allowable, linear ratings) with its
margin, the mount events; with the twin's own error estimate. The plan, its criteria and the
verdict: `mount_twin.analysis.qualification`. Exit 0 PASS, 4 FAIL, 6 FAILED (an integration
failed: not judged).
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from mount_twin.commands.common import positive_int
from mount_twin.commands.synthesize import add_synthesis_arguments

if TYPE_CHECKING:
    from pathlib import Path

    from mount_twin.analysis.qualification import InputRun, Plan

NAME = "qualify"
HELP = "qualify the scene's machine against a shock spectrum: synthesise, run, judge each mount"
EXIT_FAIL, EXIT_FAILED = 4, 6
EXIT_STATUS = (
    f"exit status: 0 PASS; 2 bad input; {EXIT_FAIL} FAIL (a criterion broken in some run); "
    f"{EXIT_FAILED} FAILED (an integration failed: not judged)"
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML")
    parser.add_argument(
        "-o", "--output", required=True, help="directory (new) of the input and output bags"
    )
    add_synthesis_arguments(parser, required=False)
    # The synthesis options beside --spectrum, which a --plan sets instead, parse to None here
    # (their defaults kept aside), so that one given beside --plan is seen, not ignored.
    alone = argparse.ArgumentParser(add_help=False)
    add_synthesis_arguments(alone, required=False)
    defaults = {k: v for k, v in vars(alone.parse_args([])).items() if k != "spectrum"}
    parser.set_defaults(synthesis_defaults=defaults, **dict.fromkeys(defaults))
    for action in parser._actions:  # their help says the defaults set aside
        if defaults.get(action.dest) is not None and "default" not in (action.help or ""):
            action.help = (
                f"{action.help} (default: {defaults[action.dest]}; with --plan, the plan's)"
            )
    parser.add_argument(
        "--plan",
        metavar="YAML",
        help="a qualification plan (spectra per axis, synthesis, criteria) instead of --spectrum",
    )
    parser.add_argument("--json", metavar="FILE", help="the verdict and per-mount results")
    parser.add_argument("--report", metavar="HTML", help="a report to hand over, one file")
    parser.add_argument(
        "--workers",
        type=positive_int,
        help="local Dask workers (default: one per core, at most one per input; 1: no cluster)",
    )
    parser.add_argument("--scheduler", help="a Dask scheduler's address (bags on shared disk)")


def plan_of(args: argparse.Namespace) -> Plan:
    """The plan: --plan's file, or the synthesis options of the command line."""
    from mount_twin.analysis.qualification import Plan, load_plan
    from mount_twin.analysis.srs import damping_ratio
    from mount_twin.commands.design_options import tolerance_of

    if (args.plan is None) == (args.spectrum is None):
        msg = "give either --spectrum (one axis, options on the command line) or --plan"
        raise ValueError(msg)
    given = [o for o in args.synthesis_defaults if getattr(args, o) is not None]
    if args.plan is not None:
        if given:
            flags = ", ".join("--" + o.replace("_", "-") for o in given)
            msg = f"{flags}: the plan sets the synthesis; give it there, or --spectrum"
            raise ValueError(msg)
        return load_plan(args.plan)
    args = argparse.Namespace(
        **{
            **vars(args),
            **{o: v for o, v in args.synthesis_defaults.items() if o not in given},
        }
    )
    zeta = damping_ratio(args.damping, args.q)
    return Plan(
        {args.axis: args.spectrum},
        zeta,
        args.seeds,
        args.first_seed,
        args.rate,
        tolerance_of(args),
        args.head,
    )


def run_input(scene_path: str, plan: Plan, axis: str, seed: int, out: str) -> InputRun:
    """Synthesise the input (axis, seed) of the plan, write it into `out`, replay it through
    the twin beside it, and return its figures (a Dask task: arguments and result pickle)."""
    from pathlib import Path

    from mount_twin.analysis.qualification import InputRun
    from mount_twin.analysis.synthesis import imu_record
    from mount_twin.commands.common import load_scene, write_signal
    from mount_twin.commands.synthesize import synthesis_of
    from mount_twin.engine.batch import LEVEL_NAMES
    from mount_twin.io.design_spectrum import read_design_table
    from mount_twin.io.epoch import DEFAULT_START_NS
    from mount_twin.replay import replay

    scene = load_scene(scene_path)
    spectrum = plan.spectra[axis]
    shock = synthesis_of(
        spectrum,
        read_design_table(spectrum),
        plan.rate_hz,
        damping=plan.damping,
        seed=seed,
        tolerance_db=plan.tolerance_db,
    )
    sig = imu_record(shock, plan.rate_hz, axis, plan.head_s)
    bag_in, bag_out = (
        Path(out) / f"input_{axis}_seed_{seed}",
        Path(out) / f"output_{axis}_seed_{seed}",
    )
    frame_id = scene.input.frame_id or "deck_imu"
    write_signal(sig, str(bag_in), scene.input.topic, frame_id, DEFAULT_START_NS, "mcap")
    s = replay(scene, bag_in, bag_out, progress=False)
    margin = shock.check.margin_db
    return InputRun(
        axis,
        seed,
        s.verdict,
        s.failure,
        str(bag_out),
        (float(margin.min()), float(margin.max())),
        (shock.check.frequency_hz.tolist(), shock.check.spectrum.tolist()),
        {name: float(peak[0]) for name, peak in s.peaks.items()},
        dict(s.utilisation_max),
        dict(s.travel_max_m),
        [(e.mount, e.event, e.level) for e in s.events],
        s.error_estimate.force_error_rel if s.error_estimate else float("nan"),
        [(st.name, LEVEL_NAMES[st.level], st.message) for st in s.worst.values() if st.level],
    )


def _runs(args: argparse.Namespace, plan: Plan, out: Path) -> list[InputRun]:
    """Every input of the plan, run on Dask where it is installed (and more than one input on
    more than one worker), else one by one in this process; in the plan's order."""
    import importlib.util
    import os

    inputs = plan.inputs
    n = len(inputs)
    runs: list[InputRun] = []
    no_dask = importlib.util.find_spec("dask") is None
    if no_dask or n == 1 or args.workers == 1:
        if n > 1:
            why = "dask is not installed" if no_dask else "--workers 1"
            print(f"  ({why}: one input after the other, in this process)")
        for axis, seed in inputs:
            runs.append(run_input(args.scene, plan, axis, seed, str(out)))
            _said(runs[-1], len(runs), n)
    else:
        from mount_twin.sweeps.cluster import dask_client, results_as_completed

        axes, seeds = (list(v) for v in zip(*inputs, strict=True))
        workers = min(n, args.workers or os.cpu_count() or 1)
        with dask_client(args.scheduler, workers) as client:
            lists = [[args.scene] * n, [plan] * n, axes, seeds, [str(out)] * n]
            for r in results_as_completed(client, run_input, *lists):
                runs.append(r)
                _said(r, len(runs), n)
    order = {key: i for i, key in enumerate(inputs)}
    return sorted(runs, key=lambda r: order[(r.axis, r.seed)])


def _said(r: InputRun, done: int, total: int) -> None:
    """One input's line of progress."""
    why = f" ({r.failure})" if r.failure else ""
    print(
        f"[{done}/{total}] {r.axis} seed {r.seed}: spectrum {r.margin_db[0]:+.2f}/"
        f"{r.margin_db[1]:+.2f} dB of the design; twin {r.verdict}{why} → {r.output_bag}",
        flush=True,
    )


def run(args: argparse.Namespace) -> int:
    from mount_twin.analysis.qualification import judge, verdict_text
    from mount_twin.commands.common import check_targets, json_text, load_scene, new_directory
    from mount_twin.textfiles import write_text

    check_targets(json=args.json, report=args.report, reads=(args.scene, args.spectrum, args.plan))
    plan = plan_of(args)
    scene = load_scene(args.scene)  # a bad scene fails here, before anything is synthesised
    for axis in plan.spectra:
        if axis not in scene.dofs:  # the mounts would carry their static load, and pass
            where = f"--axis {axis}" if args.plan is None else f"{plan.source}: spectra.{axis}"
            msg = (
                f"{where}: the scene freezes {axis} (dofs {', '.join(scene.dofs)}): a "
                "shock along it goes into a constraint whose force is not published; free it"
            )
            raise ValueError(msg)
    axes = ", ".join(plan.spectra)
    with new_directory(args.output, "qualify") as out:
        print(f"plan {plan.source}: {len(plan.inputs)} inputs ({axes}), ζ = {plan.damping:g}")
        runs = _runs(args, plan, out)
    doc = judge(runs, plan)
    print(verdict_text(doc))
    if args.json:
        write_text(args.json, json_text(doc))
        print(f"json: {args.json}")
    if args.report:
        from mount_twin.analysis.qualification_report import write_qualification_report

        write_qualification_report(args.report, load_scene(args.scene), plan, runs, doc)
        print(f"report: {args.report}")
    return {"PASS": 0, "FAIL": EXIT_FAIL, "FAILED": EXIT_FAILED}[doc["verdict"]]
