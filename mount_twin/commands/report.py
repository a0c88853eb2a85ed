"""`mount-twin report OUT_BAG -o report.html`: one self-contained HTML page of a replay."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

from mount_twin.commands.design_options import (
    add_axis_argument,
    add_design_arguments,
    axes_of,
    tolerance_of,
)
from mount_twin.commands.replay import EXIT_FAIL_ON, FAIL_ON, run_exit_status

if TYPE_CHECKING:
    import numpy as np

    from mount_twin.analysis.report import ReportPage
    from mount_twin.io.input_decoding import Decoded
    from mount_twin.io.output_tables import Table
    from mount_twin.scene.description import InputSpec, Scene

NAME = "report"
HELP = "one HTML page of a replay: input and response, signed mount forces, utilisation, events"
EXIT_STATUS = (
    "exit status: 0 done; 2 bad input, a failed write (the message names the file), a "
    "--scene that is not the run's (without --other-scene), or "
    "--fail-on on a bag without diagnostics; 3 the run accepted no input sample; 4 the run's "
    "diagnostics reached --fail-on, or with --design a spectrum out of the design's "
    "tolerance somewhere; 6 the run FAILED (its integration failed), whatever --fail-on says. "
    "3, 4 and 6 are the replay's for the run, and the page is written; a partial run is "
    "warned of on stderr"
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag", help="output bag of `mount-twin replay`")
    parser.add_argument("-o", "--output", default="report.html", help="HTML file to write")
    parser.add_argument("--scene", help="the replay's scene YAML (mount kinds, names)")
    parser.add_argument(
        "--other-scene",
        action="store_true",
        help="draw with --scene even where it is not the run's (its digest, which the replay "
        "records in the output bag's metadata, differs): the page and stderr say so",
    )
    parser.add_argument(
        "--input", metavar="BAG", help="the replay's input bag (plotted beside the response)"
    )
    add_design_arguments(
        parser,
        "the input's spectra (--input) are judged against it: the design on their plot, the "
        "margins in their table, a PASS/FAIL line per axis, exit 4 on FAIL",
    )
    add_axis_argument(parser, "the axis of F whose input spectrum --design judges (as srs does)")
    parser.add_argument(
        "--fail-on",
        choices=FAIL_ON,
        default="never",
        help="exit 4 if the worst diagnostics level of the run reaches this (default: never); "
        "a FAILED run exits 6 whatever this says",
    )


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from mount_twin.commands.extras import require

    require("matplotlib", "mount-twin report")
    from mount_twin.analysis.report import write_report
    from mount_twin.commands.common import check_targets, load_scene, warn_if_partial
    from mount_twin.io.design_spectrum import read_design_table
    from mount_twin.io.output_tables import read_output_bag

    check_targets(output=args.output, reads=(args.bag, args.scene, args.input, args.design))
    tolerance = tolerance_of(args)
    if args.other_scene and not args.scene:
        msg = "--other-scene draws with the scene --scene gives: it needs --scene"
        raise ValueError(msg)
    if args.design and not args.input:
        msg = "--design judges the input's spectra: it needs --input (and --scene)"
        raise ValueError(msg)
    design = read_design_table(args.design) if args.design else None
    scene = load_scene(args.scene) if args.scene else None
    tables = read_output_bag(args.bag)
    if scene is not None:
        scene = _as_replayed(scene, tables)
    samples, note = None, ""
    if args.input:
        if scene is None:
            msg = "--input needs --scene (its input topic, sensor frame and gravity convention)"
            raise ValueError(msg)
        from mount_twin.io.input_samples import read_input
        from mount_twin.physics.rotations import rpy_matrix

        keys = ("the topic the run read: is this its input bag?", "input.msg_type")
        decoded = read_input(args.input, scene.input, keys)
        decoded, note = taken_input(args.input, scene.input, decoded)
        if note:
            print(note)
        f = decoded.accel @ rpy_matrix(*scene.input.sensor_rpy).T
        if not scene.input.includes_gravity:
            f[:, 2] += scene.input.g
        samples = (decoded.stamps_ns, f)
    name = Path(args.input).name if args.input else ""
    warn_if_partial(args.bag)
    out = write_report(
        args.bag,
        args.output,
        bag_tables=tables,
        input_samples=samples,
        scene=scene,
        input_name=name,
        input_path=args.input,
        input_note=note,
        design=design,
        design_axes=axes_of(args),
        tolerance_db=tolerance,
        design_name=Path(args.design).name if args.design else "",
        other_scene=args.other_scene,
    )
    if (checked := out.scene_check) is not None and (checked.differs or not checked.by_digest):
        print(f"mount-twin: warning: --scene {args.scene}: {checked.page_text}", file=sys.stderr)
    print(f"report: {out.path}")
    return _exit_status(out, args.fail_on)


def _as_replayed(scene: Scene, tables: list[Table]) -> Scene:
    """The scene with the input topic its run read and the header.frame_id it expected there
    (`replay --topic`, `--frame-id` may have replaced the scene's), as the output bag's input
    status records them (`tables`: the bag's; a bag written before the frame_id was recorded
    leaves the scene's): the input bag is read from that topic, and the page names both."""
    from dataclasses import replace

    from mount_twin.io.output_tables import input_values

    diagnostics = next((t for t in tables if t.name == "diagnostics"), None)
    values, spec = input_values(diagnostics), scene.input
    topic, frame_id = values.get("topic", spec.topic), values.get("frame_id", spec.frame_id)
    return replace(scene, input=replace(spec, topic=topic, frame_id=frame_id))


def _exit_status(out: ReportPage, fail_on: str) -> int:
    """The run's exit status as `mount-twin replay` gave it (`run_exit_status`), else 4 where
    the design judged a spectrum FAIL."""
    v = out.verdict
    if v.worst_level is None and fail_on != "never":
        msg = f"--fail-on {fail_on}: the bag holds no diagnostics to judge"
        raise ValueError(msg)
    status = run_exit_status(v.nothing, v.failure, v.worst_level or 0, fail_on)
    if status == 0 and out.design_passed is False:
        print("mount-twin: the input's spectra FAIL the design (--design)", file=sys.stderr)
        return EXIT_FAIL_ON
    return status


def taken_input(path: str, spec: InputSpec, decoded: Decoded) -> tuple[Decoded, str]:
    """The input's samples the replay takes as far as their readings tell, and what was left
    out ('' if nothing). The intake rejects a sample with a reading not finite, or marked not
    provided (REP-145: its acceleration, or the rate the twin reads), and goes on
    (`reading_screen.reading_rejections`): such samples before the first it takes or after its last
    are left out here too, and said (how many for each reason, at which end, the first). One
    between taken samples is refused (ValueError naming the bag, the topic, the sample and
    what it lacks): the input's spectra take the samples as evenly spaced, and would join
    those around the hole. So is a record the replay takes no sample of."""
    from collections import Counter

    import numpy as np

    from mount_twin.engine.count_texts import counted_text
    from mount_twin.engine.reading_screen import reading_rejections

    reasons = reading_rejections(decoded.accel, decoded.gyro, decoded.unprovided, spec.reads_rate)
    ok = reasons == ""
    left = np.flatnonzero(~ok)
    if not left.size:
        return decoded, ""
    n, taken = ok.shape[0], np.flatnonzero(ok)
    inside = left[(left > taken[0]) & (left < taken[-1])] if taken.size else left
    where = (
        f"{path}: {spec.topic}: {left.size} of {n} samples the replay rejects "
        f"({counted_text(Counter(reasons[left].tolist()))})"
    )
    if not taken.size:
        msg = f"{where}, every one: the first, {_sample_text(decoded, int(left[0]), reasons)}"
        raise ValueError(msg)
    if inside.size:
        msg = (
            f"{where}; {_sample_text(decoded, int(inside[0]), reasons)}, between samples it "
            "takes: the input's spectra take its samples as evenly spaced"
        )
        raise ValueError(msg)
    ends = []
    if before := int(taken[0]):
        ends.append(f"{before} before the first it takes (samples 0–{before - 1})")
    if after := n - 1 - int(taken[-1]):
        ends.append(f"{after} after its last (samples {n - after}–{n - 1})")
    note = (
        f"{where} left out, as the replay skips them: {', '.join(ends)}; the first: "
        f"{_sample_text(decoded, int(left[0]), reasons)}; the input's plot and spectra are of "
        f"the other {taken.size}"
    )
    return decoded.select(ok), note


def _sample_text(decoded: Decoded, i: int, reasons: np.ndarray) -> str:
    """What sample i of the record lacks for the intake (`reasons[i]`, its rejection), with its
    place and time from the first sample: a reading not finite, with its axis and value, or
    one its message marks not provided."""
    from mount_twin.engine.reading_screen import READING_LIMIT, provided

    t = (int(decoded.stamps_ns[i]) - int(decoded.stamps_ns[0])) * 1e-9
    at = f"sample {i} (t = {t:.6g} s from the first)"
    if reasons[i] != "non_finite":
        what = "acceleration" if reasons[i] == "no_acceleration" else "angular velocity"
        return f"{at} marks its {what} not provided (covariance[0] = -1, REP-145)"
    marked = None if decoded.unprovided is None else decoded.unprovided[i : i + 1]
    accel, gyro = provided(decoded.accel[i : i + 1], decoded.gyro[i : i + 1], marked)
    readings = [*accel[0].tolist(), *gyro[0].tolist()]  # a placeholder not provided is not read
    k = next(j for j, v in enumerate(readings) if not abs(v) <= READING_LIMIT)
    return f"{at} has {('accel', 'gyro')[k // 3]} {'xyz'[k % 3]} {readings[k]!r}"
