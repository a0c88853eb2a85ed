"""`mount-twin demo`: the bundled bag through the bundled default scene."""

from __future__ import annotations

import argparse

from mount_twin.commands.common import DEFAULT_BAG, DEFAULT_SCENE, share_dir
from mount_twin.commands.replay import STOPPED_OUTPUT as REPLAY_STOPPED_OUTPUT
from mount_twin.commands.replay import ReplayOptions, add_plot_argument, replay_and_report

NAME = "demo"
HELP = "replay the bundled bag through the bundled default scene"
STOPS_AT_CHECKPOINTS = True
STOPPED_OUTPUT = REPLAY_STOPPED_OUTPUT
"""A stopped demo's output bag is the replay's: finished and marked partial."""
EXIT_STATUS = (
    "exit status: 0 done; 2 bad input or a failed write (the message names the file); 3 no "
    "input sample accepted; 5 the bundled bag damaged part-way (the output bag is finished and "
    "marked partial); 6 FAILED: the integration failed at least once (the summary says why)"
)
"""The replay's statuses (`replay.EXIT_STATUS`) but 4: the demo never fails on diagnostics."""


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
