"""`mount-twin dashboard SCENE`: PlotJuggler and Foxglove layouts for a scene's outputs."""

from __future__ import annotations

import argparse
import re

NAME = "dashboard"
HELP = "write PlotJuggler (XML) and Foxglove (JSON) layouts plotting a scene's outputs"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML")
    parser.add_argument("--plotjuggler", metavar="XML", help="PlotJuggler layout file to write")
    parser.add_argument("--foxglove", metavar="JSON", help="Foxglove layout file to write")
    parser.add_argument(
        "--namespace",
        metavar="NS",
        type=_namespace,
        default="/",
        help="the node's namespace, as `--ros-args -r __ns:=NS` sets it (default /: none)",
    )
    parser.add_argument(
        "--node-name",
        metavar="NAME",
        type=_node_name,
        help="the node's name, as `--ros-args -r __node:=NAME` sets it (default mount_twin)",
    )


def _namespace(text: str) -> str:
    """argparse type of a node namespace as `-r __ns:=` takes it: '/', or an absolute name
    a topic could have (rcl refuses `__ns:=pump1`, `__ns:=/pump1/`, `__ns:=/1pump`)."""
    from mount_twin.scene.ros_names import topic_name_problem

    if not text.startswith("/"):
        problem = "not absolute: `-r __ns:=` takes one starting with '/' (/pump1)"
    else:
        problem = "" if text == "/" else topic_name_problem(text)
    if problem:
        msg = f"{text!r} is not a ROS namespace: {problem}"
        raise argparse.ArgumentTypeError(msg)
    return text


def _node_name(text: str) -> str:
    """argparse type of a node name as `-r __node:=` takes it (rmw_validate_node_name)."""
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]{0,254}", text):
        msg = (
            f"{text!r} is not a ROS node name: 1 to 255 ASCII letters, digits and '_', the "
            "first not a digit"
        )
        raise argparse.ArgumentTypeError(msg)
    return text


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from mount_twin.analysis.dashboards import foxglove_layout, plotjuggler_layout
    from mount_twin.commands.common import check_targets, load_scene
    from mount_twin.io.messages import NODE_NAME
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
            write_text(path, text(scene, args.namespace, args.node_name or NODE_NAME))
            print(f"layout: {path}")
    return 0
