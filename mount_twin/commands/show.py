"""`mount-twin show SCENE -o PNG`: a picture of the scene's layout (the plot extra)."""

from __future__ import annotations

import argparse

NAME = "show"
HELP = "draw a scene's layout (CG, mounts, their axes and lines of action, sensor) to a PNG"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML")
    parser.add_argument(
        "-o", "--output", default="scene.png", help="PNG to write (default: scene.png)"
    )


def run(args: argparse.Namespace) -> int:
    from mount_twin.commands.extras import require

    require("matplotlib", "mount-twin show")
    from mount_twin.analysis.layout_view import draw_layout
    from mount_twin.commands.common import check_targets, load_scene

    check_targets(output=args.output, figures=("output",), reads=(args.scene,))
    print(f"layout: {draw_layout(load_scene(args.scene), args.output)}")
    return 0
