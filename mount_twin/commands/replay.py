"""`mount-twin replay BAG --scene SCENE -o OUT`: a bag through the twin into an output bag."""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from mount_twin.commands.common import positive_int

if TYPE_CHECKING:
    from mount_twin.replay_summary import ReplaySummary

NAME = "replay"
HELP = "replay a bag through the twin into an mcap bag"
STOPS_AT_CHECKPOINTS = True
"""SIGINT and SIGTERM stop the replay between chunks (mount_twin.commands.stopping)."""
STOPPED_OUTPUT = "holds the output so far, marked partial in its metadata"
"""What its output bag holds when a signal or a damaged input stopped it (mount_twin.cli)."""
FAIL_ON = ("never", "warn", "error")
"""`--fail-on` choices; the index of warn and error is their diagnostics level."""
EXIT_STATUS = (
    "exit status: 0 done; 2 bad input or configuration, or a failed write (the message names "
    "the file; a run that failed too, 3 to 6, says so before it); 3 no input sample "
    "accepted, or too few to start the twin (initial_state.gravity_samples); 4 diagnostics "
    "reached --fail-on; 5 input bag damaged part-way: the messages before the damage are "
    "replayed (a failure before it is said on stderr too), and the output bag is finished and "
    "marked partial in its metadata (custom_data mount_twin.partial: why, and up to which "
    "stamp); 6 FAILED: the integration failed at least once (the summary says how often and "
    "why), whatever --fail-on says: after a failure the twin restarts at an equilibrium or "
    "stops following, so its figures are no longer the motion the record drove"
)
"""The replay's own exit statuses (`verdict`, mount_twin.cli's EXIT_DAMAGED; the cli adds the
signals'), in its --help."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "input",
        help="input bag: a rosbag2 directory (mcap or sqlite3), one .mcap or .db3 file, or a "
        "ROS 1 .bag",
    )
    parser.add_argument("--scene", required=True, help="scene YAML")
    parser.add_argument("-o", "--output", required=True, help="output bag directory (new)")
    parser.add_argument("--topic", help="input topic (default: the scene's input.topic)")
    parser.add_argument(
        "--body",
        metavar="BAG",
        help="the body IMU's bag (its body_sensor.topic; default: the input bag's, if it has it)",
    )
    parser.add_argument(
        "--frame-id",
        help="expected header.frame_id, '' for any (default: the scene's input.frame_id)",
    )
    parser.add_argument(
        "--chunk", type=positive_int, default=2000, help="messages per engine batch"
    )
    parser.add_argument("--no-progress", action="store_true")
    add_plot_argument(parser)
    parser.add_argument("--json", metavar="FILE", help="also write the summary as JSON")
    parser.add_argument(
        "--fail-on",
        choices=FAIL_ON,
        default="never",
        help="exit 4 if the worst diagnostics level of the run reaches this (default: never); "
        "a FAILED run (the integration failed) exits 6 whatever this says",
    )


def add_plot_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--plot", metavar="PNG", help="also plot the outputs into this PNG")


@dataclass(frozen=True)
class ReplayOptions:
    """How `replay_and_report` runs: messages per engine batch, whether to show progress, a PNG
    to plot the outputs into and a file for the summary as JSON (None: neither), the
    `--fail-on` level, and the body IMU's bag (None: the input bag's body_sensor.topic)."""

    chunk: int = 2000
    progress: bool = True
    plot: str | None = None
    json_path: str | None = None
    fail_on: str = "never"
    body: str | None = None


def run(args: argparse.Namespace) -> int:
    overrides = {
        k: v for k, v in (("topic", args.topic), ("frame_id", args.frame_id)) if v is not None
    }
    options = ReplayOptions(
        chunk=args.chunk,
        progress=not args.no_progress,
        plot=args.plot,
        json_path=args.json,
        fail_on=args.fail_on,
        body=args.body,
    )
    return replay_and_report(args.scene, args.input, args.output, options, overrides)


def replay_and_report(
    scene_path: str | Path,
    bag: str | Path,
    output: str,
    options: ReplayOptions = ReplayOptions(),
    input_overrides: dict[str, str] | None = None,
) -> int:
    """Replay, print the summary (and plot), and return the exit status (see `verdict`).
    `input_overrides`: scene `input` fields replaced (topic, frame_id), checked like the
    scene's own."""
    from mount_twin.commands.common import check_targets, load_scene
    from mount_twin.errors import DamagedBagError
    from mount_twin.replay import replay

    check_targets(json=options.json_path, plot=options.plot, reads=(scene_path, bag, options.body))
    scene = load_scene(scene_path, input_overrides)
    from mount_twin.commands.stopping import checkpoint

    try:
        summary = replay(
            scene,
            bag,
            output,
            chunk=options.chunk,
            progress=options.progress,
            checkpoint=checkpoint,
            body_path=options.body,
        )
    except DamagedBagError as err:  # exit 5, after the summary of what came before it (a
        # failed write of it raises from here: cli.main says the damage beside it, exit 2)
        if err.summary is not None:
            up_to = _as_set(err.summary, input_overrides)
            try:
                _report(up_to, scene_path, output, options)
            finally:
                if up_to.failure:  # said too: the exit status names the damage alone
                    print(f"mount-twin: error: {up_to.failure}", file=sys.stderr)
        raise
    summary = _as_set(summary, input_overrides)
    try:
        _report(summary, scene_path, output, options)
    finally:  # said even where a write failed (exit 2), which would hide it
        status = verdict(summary, options.fail_on)
    return status


def _as_set(summary: ReplaySummary, input_overrides: dict[str, str] | None) -> ReplaySummary:
    """The summary pointing at what the user set: `replay --frame-id` where it replaced the
    scene's input.frame_id (a wrong frame id was set there, not in the scene)."""
    from mount_twin.model.scene_file import INPUT_OPTIONS

    if not input_overrides or "frame_id" not in input_overrides:
        return summary
    return replace(summary, frame_id_setting=INPUT_OPTIONS["input.frame_id"])


def _report(
    summary: ReplaySummary, scene_path: str | Path, output: str, options: ReplayOptions
) -> None:
    """Print the summary, write it as JSON and plot the outputs, as `options` ask."""
    print(summary.text())
    if options.json_path:
        from mount_twin.commands.common import json_text
        from mount_twin.textfiles import write_text

        text = json_text(summary.to_dict(), indent=2)
        write_text(options.json_path, text)
        print(f"json: {options.json_path}")
    if options.plot:
        from mount_twin.plot import plot_output_bag  # matplotlib only when asked for

        png = plot_output_bag(
            output, options.plot, Path(scene_path).name, summary.events, summary.origin_s
        )
        print(f"plot: {png}")


EXIT_NOTHING_ACCEPTED, EXIT_FAIL_ON, EXIT_FAILED = 3, 4, 6


def verdict(summary: ReplaySummary, fail_on: str) -> int:
    """The exit status of a replay (`run_exit_status`; the bag holds input samples, `InputBag`
    saw to it, so none accepted says why, as a twin that never started does)."""
    return run_exit_status(
        summary.followed_nothing(), summary.failure, summary.worst_level, fail_on
    )


def run_exit_status(nothing: str, failure: str, worst_level: int, fail_on: str) -> int:
    """The exit status of a run, saying why on stderr: 3 if no input sample was accepted or
    the twin never started (`nothing`: why), 6 if the integration failed (FAILED; `failure`:
    how often and why), 4 if its worst diagnostics level (an index in LEVEL_NAMES) reached
    `fail_on`, else 0."""
    if nothing:
        print(f"mount-twin: error: {nothing}", file=sys.stderr)
        return EXIT_NOTHING_ACCEPTED
    if failure:
        print(f"mount-twin: error: {failure}", file=sys.stderr)
        return EXIT_FAILED
    if fail_on != "never" and worst_level >= FAIL_ON.index(fail_on):
        from mount_twin.engine.batch import LEVEL_NAMES

        level = LEVEL_NAMES[worst_level]
        print(f"mount-twin: diagnostics reached {level} (--fail-on {fail_on})", file=sys.stderr)
        return EXIT_FAIL_ON
    return 0
