"""`mount-twin dashboard SCENE`: PlotJuggler and Foxglove layouts for a scene's outputs."""

from __future__ import annotations

import argparse

NAME = "dashboard"
HELP = "write PlotJuggler (XML) and Foxglove (JSON) layouts plotting a scene's outputs"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML")
    parser.add_argument("--plotjuggler", metavar="XML", help="PlotJuggler layout file to write")
    parser.add_argument("--foxglove", metavar="JSON", help="Foxglove layout file to write")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from mount_twin.analysis.dashboards import foxglove_layout, plotjuggler_layout
    from mount_twin.commands.common import check_targets, load_scene
    from mount_twin.textfiles import write_text

    if not (args.plotjuggler or args.foxglove):
        msg = "give --plotjuggler XML and/or --foxglove JSON"
        raise ValueError(msg)
    if args.plotjuggler and args.foxglove and Path(args.plotjuggler) == Path(args.foxglove):
        msg = f"--plotjuggler and --foxglove name one file, {args.foxglove}: one would overwrite"
        raise ValueError(msg)
    check_targets(plotjuggler=args.plotjuggler, foxglove=args.foxglove, reads=(args.scene,))
    scene = load_scene(args.scene)
    for path, text in ((args.plotjuggler, plotjuggler_layout), (args.foxglove, foxglove_layout)):
        if path:
            write_text(path, text(scene))
            print(f"layout: {path}")
    return 0
