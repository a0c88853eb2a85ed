"""`mount-twin report OUT_BAG -o report.html`: one self-contained HTML page of a replay."""

from __future__ import annotations

import argparse

from mount_twin.commands.srs import add_design_arguments, tolerance_of

NAME = "report"
HELP = "one HTML page of a replay: input and response, signed mount forces, utilisation, events"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bag", help="output bag of `mount-twin replay`")
    parser.add_argument("-o", "--output", default="report.html", help="HTML file to write")
    parser.add_argument("--scene", help="the replay's scene YAML (mount kinds, names)")
    parser.add_argument(
        "--input", metavar="BAG", help="the replay's input bag (plotted beside the response)"
    )
    add_design_arguments(
        parser,
        "the input's spectra (--input) are judged against it: the design on their plot, the "
        "margins in their table, a PASS/FAIL line per axis",
    )


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from mount_twin.commands.extras import require

    require("matplotlib", "mount-twin report")
    from mount_twin.analysis.report import write_report
    from mount_twin.commands.common import load_scene, read_design_table, warn_if_partial

    tolerance = tolerance_of(args)
    if args.design and not args.input:
        msg = "--design judges the input's spectra: it needs --input (and --scene)"
        raise ValueError(msg)
    design = read_design_table(args.design) if args.design else None
    scene = load_scene(args.scene) if args.scene else None
    samples = None
    if args.input:
        if scene is None:
            msg = "--input needs --scene (its input topic, sensor frame and gravity convention)"
            raise ValueError(msg)
        from mount_twin.io.input_samples import read_input
        from mount_twin.physics.rotations import rpy_matrix

        decoded = read_input(args.input, scene.input)
        f = decoded.accel @ rpy_matrix(*scene.input.sensor_rpy).T
        if not scene.input.includes_gravity:
            f[:, 2] += scene.input.g
        samples = (decoded.stamps_ns, f)
    name = Path(args.input).name if args.input else ""
    warn_if_partial(args.bag)
    out = write_report(
        args.bag,
        args.output,
        input_samples=samples,
        scene=scene,
        input_name=name,
        input_path=args.input,
        design=design,
        tolerance_db=tolerance,
        design_name=Path(args.design).name if args.design else "",
    )
    print(f"report: {out}")
    return 0
