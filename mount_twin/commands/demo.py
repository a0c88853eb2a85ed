"""`mount-twin demo`: the bundled bag through the bundled default scene."""

from __future__ import annotations

import argparse

from mount_twin.commands.common import DEFAULT_BAG, DEFAULT_SCENE, share_dir
from mount_twin.commands.replay import ReplayOptions, add_plot_argument, replay_and_report

NAME = "demo"
HELP = "replay the bundled bag through the bundled default scene"
STOPS_AT_CHECKPOINTS = True


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", default="demo_out", help="output bag directory (new)")
    add_plot_argument(parser)


def run(args: argparse.Namespace) -> int:
    share = share_dir()
    return replay_and_report(
        share / "config" / DEFAULT_SCENE,
        share / "bags" / DEFAULT_BAG,
        args.output,
        ReplayOptions(chunk=2000, progress=True, plot=args.plot, fail_on="never"),
    )
