"""`mount-twin accuracy SCENE BAG`: the twin's error against its run time, per tolerance."""

from __future__ import annotations

import argparse
import math
import sys
from itertools import pairwise
from typing import TYPE_CHECKING

from mount_twin.commands.common import positive_int

if TYPE_CHECKING:
    from mount_twin.analysis.accuracy import Accuracy, ReferenceInput, Run

NAME = "accuracy"
HELP = "error against run time of the twin on a scene and bag, per tolerance (work-precision)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML")
    parser.add_argument("bag", help="input bag (the scene's input.topic)")
    parser.add_argument(
        "--rtol",
        type=float,
        nargs="+",
        help="relative tolerances to measure (default: 1e-3 to 1e-8; atol = rtol·1e-3)",
    )
    parser.add_argument(
        "--max-substeps",
        type=positive_int,
        default=100_000,
        help="per input interval (default: 100000)",
    )
    parser.add_argument("--csv", metavar="FILE", help="write the table as CSV")
    parser.add_argument("--plot", metavar="PNG", help="work-precision diagram (the plot extra)")


def run(args: argparse.Namespace) -> int:
    from mount_twin.analysis.accuracy import (
        DEFAULT_RTOLS,
        REFINE,
        compare,
        measure,
        reference_input,
        reference_run,
        resolution,
    )
    from mount_twin.commands.common import check_targets, load_scene
    from mount_twin.errors import MountTwinError
    from mount_twin.io.input_decoding import TimeBase
    from mount_twin.io.input_samples import provided_input
    from mount_twin.scene.description import RTOL_RANGE

    lo, hi = RTOL_RANGE
    for rtol in args.rtol or ():
        if not lo <= rtol <= hi:
            msg = f"--rtol: {rtol!r} is outside [{lo:g}, {hi:g}] (integration.rtol's range)"
            raise ValueError(msg)
    check_targets(csv=args.csv, plot=args.plot, reads=(args.scene, args.bag))
    if args.plot:
        from mount_twin.commands.extras import require

        require("matplotlib", "--plot")
    scene = load_scene(args.scene)
    decoded, note = provided_input(args.bag, scene.input)  # the reference holds each value
    if note:
        print(note, file=sys.stderr)
    samples = decoded.batch(TimeBase.at(int(decoded.stamps_ns[0])))
    duration = float(samples.stamps[-1] - samples.stamps[0])
    print(
        f"{scene.name}: {len(samples)} samples over {duration:.3f} s from {args.bag}",
        file=sys.stderr,
    )
    record = reference_input(scene, samples, args.max_substeps)
    ref = reference_run(scene, record.samples, args.max_substeps)
    why = ""
    try:
        resolved: Accuracy | None = resolution(scene, record.samples, args.max_substeps, ref)
    except MountTwinError as err:  # the second grid's reference failed where the first did not
        resolved, why = None, str(err)
    effect: Accuracy | None = None  # the conditioning's, where the reference took it
    if record.conditioned and scene.input.gyro_filter != "none":
        effect = compare(reference_run(scene, samples, args.max_substeps), ref, duration)
    rows = []
    for rtol in args.rtol or DEFAULT_RTOLS:
        print(f"  rtol {rtol:g} ...", file=sys.stderr, flush=True)
        rows.append(measure(scene, samples, rtol, args.max_substeps, ref))
    print(_reference_text(ref, record, scene.input.gyro_filter, effect))
    if resolved is None:
        print(
            f"resolution: not measured (the reference on the input refined {REFINE + 1}×: {why})"
        )
    else:
        print(
            f"resolution: the reference differs from one on the input refined {REFINE + 1}× by "
            f"{resolved.force_error:.2e} of the largest force, "
            f"{resolved.attitude_error_rad:.2e} rad of attitude"
        )
    print(_table(rows))
    unresolved = "" if resolved is None else _unresolved(rows, resolved)
    if unresolved:
        print(unresolved)
    if args.csv:
        _write_csv(rows, args.csv)
        print(f"csv: {args.csv}")
    if args.plot:
        _plot(rows, ref, resolved, effect, args.plot, f"{scene.name} on {args.bag}")
        print(f"plot: {args.plot}")
    return 0


def _reference_text(
    ref: Run, record: ReferenceInput, gyro_filter: str, effect: Accuracy | None
) -> str:
    """What the reference is, what its input's rate is, and the gyro conditioning's effect."""
    from mount_twin.analysis.accuracy import REFINE

    head = f"reference: the same twin at rtol {ref.rtol:g}, atol {ref.atol:g}, on the input "
    head += f"refined {REFINE}×"
    if gyro_filter == "none":
        return f"{head} (gyro_filter none)"
    if not record.conditioned:
        return (
            f"{head}, the gyro as recorded: the record conditioned beforehand does not give "
            f"the twin's run ({record.reproduction:.2g} off: samples rejected, or a restart "
            f"splitting it), so the errors include the gyro conditioning's (gyro_filter "
            f"{gyro_filter})"
        )
    same = (
        "bit for bit"
        if record.reproduction == 0.0
        else f"to {record.reproduction:.2g} (the rounding of the sensor's rotation)"
    )
    lines = [
        f"{head}, the gyro as the twin takes it (gyro_filter {gyro_filter}, applied to the "
        f"record beforehand; the twin on that record gives its run {same}): the errors are "
        "the integration's"
    ]
    if effect is not None:
        lines.append(
            f"gyro conditioning ({gyro_filter}): the reference on the gyro as recorded differs "
            f"by {effect.force_error:.2e} of the largest force, {effect.attitude_error_rad:.2e} "
            "rad of attitude (the conditioning's effect, not an integration error)"
        )
    return "\n".join(lines)


def _table(rows: list[Accuracy]) -> str:
    """The figures per rtol under a two-line head, each column's quantity over its unit: the
    force errors are ratios (of the largest force, of each mount's peak), which a head of
    `force err` alone let a reader take for newtons."""
    head = (
        f"{'rtol':>8} {'force err':>11} {'estimated':>11} {'peak err':>10} "
        f"{'attitude err':>13} {'estimated':>10} {'CG err':>10} {'wall':>9} "
        f"{'substeps':>10} {'failures':>8} {'est cost':>8}"
    )
    units = (
        f"{'':>8} {'of max |F|':>11} {'of max |F|':>11} {'of peaks':>10} "
        f"{'rad':>13} {'rad':>10} {'m':>10} {'s/s':>9} "
        f"{'per sample':>10} {'':>8} {'×':>8}"
    )
    lines = [head, units]
    for r in rows:
        lines.append(
            f"{r.rtol:>8.0e} {r.force_error:>11.2e} {r.est_force_error:>11.2e} "
            f"{r.peak_force_error:>10.2e} {r.attitude_error_rad:>13.2e} "
            f"{r.est_attitude_error_rad:>10.2e} {r.position_error_m:>10.2e} "
            f"{r.wall_s_per_sim_s:>9.4f} {r.substeps_per_sample:>10.2f} {r.failures:>8d} "
            f"{r.estimate_cost:>7.2f}×"
        )
    return "\n".join(lines)


def _unresolved(rows: list[Accuracy], resolved: Accuracy) -> str:
    """A line naming the rtols whose force or attitude error is within RESOLVED times the
    reference's resolution (not measured: at the reference's own error or round-off); ''
    where none is."""
    from mount_twin.analysis.accuracy import RESOLVED

    named = [
        f"{r.rtol:g} ({what})"
        for r in rows
        for what, err, floor in (
            ("force", r.force_error, resolved.force_error),
            ("attitude", r.attitude_error_rad, resolved.attitude_error_rad),
        )
        if err <= RESOLVED * floor
    ]
    if not named:
        return ""
    return (
        f"not resolved (within {RESOLVED:g}× the reference's resolution: the error and its "
        f"estimate are not compared there): rtol {', '.join(named)}"
    )


def _write_csv(rows: list[Accuracy], path: str) -> None:
    import csv
    import dataclasses

    from mount_twin.analysis.accuracy import Accuracy
    from mount_twin.textfiles import text_output

    with text_output(path, newline="") as fh:
        writer = csv.writer(fh)
        columns = [f.name for f in dataclasses.fields(Accuracy)]
        writer.writerow(columns)
        for r in rows:
            values = dataclasses.asdict(r)
            writer.writerow([f"{values[c]:.6g}" for c in columns])


def _label_levels(wall: list[float], close: float = 0.12) -> list[int]:
    """Per point, how many label rows up its label goes: points closer in log x than
    `close` of the plot's log span to the one before (in x order) stack their labels."""
    logs = [math.log10(w) for w in wall]
    span = max(max(logs) - min(logs), 1e-12)
    levels = [0] * len(wall)
    order = sorted(range(len(wall)), key=logs.__getitem__)
    for before, i in pairwise(order):
        if logs[i] - logs[before] < close * span:
            levels[i] = levels[before] + 1
    return levels


def _plot(
    rows: list[Accuracy],
    ref: Run,
    resolved: Accuracy | None,
    effect: Accuracy | None,
    png: str,
    title: str,
) -> None:
    from mount_twin.analysis.log_labels import plain_log_labels
    from mount_twin.figure_files import pyplot, save_png

    plt = pyplot()

    fig, ax = plt.subplots(figsize=(7, 5))
    wall = [r.wall_s_per_sim_s for r in rows]
    for name, label in (("force_error", "max mount force"), ("peak_force_error", "peak force")):
        err = [max(getattr(r, name), 1e-17) for r in rows]
        ax.loglog(wall, err, "o-", label=f"{label} error")
    est = [max(r.est_force_error, 1e-17) for r in rows]
    ax.loglog(wall, est, "x:", color="k", label="max mount force error, the twin's live estimate")
    floors = [] if resolved is None else [max(resolved.force_error, 1e-17)]
    for floor in floors:
        ax.axhline(floor, color="0.5", lw=1, ls="--", label="the reference's resolution (force)")
    if effect is not None:
        floors.append(max(effect.force_error, 1e-17))
        ax.axhline(
            floors[-1],
            color="tab:green",
            lw=1,
            ls="-.",
            label="the gyro conditioning's effect (force), not an integration error",
        )
    for r, level in zip(rows, _label_levels(wall), strict=True):
        ax.annotate(
            f"rtol {r.rtol:.0e}" + (f", {r.failures} failures" if r.failures else ""),
            (r.wall_s_per_sim_s, max(r.force_error, 1e-17)),
            fontsize=7,
            textcoords="offset points",
            xytext=(4, 4 + 9 * level),  # stacked where points crowd
        )
    shown = [
        max(getattr(r, n), 1e-17)
        for r in rows
        for n in ("force_error", "peak_force_error", "est_force_error")
    ] + floors
    ax.set_ylim(min(shown) / 3.0, max(shown) * 10.0)  # room for the labels inside the axes
    plain_log_labels(ax, "x")  # within a decade or so: plain labels, not 1.1×10⁻² crowding
    ax.set_xlabel("engine wall time per simulated second [s/s]")
    ax.set_ylabel(f"relative error against rtol {ref.rtol:.0e} [-]")
    ax.set_title(f"work-precision: {title}", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    save_png(fig, png)
