"""`mount-twin track SCENE --foundation IN --body IN`: the calibration re-fitted window by
window along a recorded pair, each window judged against a band (`mount_twin.analysis.ageing`):
mounts that harden, creep or loosen show as a stiffness or damping scale leaving 1. Exit 0 all
windows OK, 1 some WARN (a window whose fit refuses every scale is not judged: a WARN), 4 some
ERROR. A record that does not move (a still foundation, a dead body sensor) is refused at
load (`calibrate.read_pair`). The part of the records after the last whole window is fitted
in none: a warning says how much.
"""

from __future__ import annotations

import argparse

NAME = "track"
HELP = "re-fit the mounts' stiffness and damping window by window: flag mounts that age"
EXIT_WARN, EXIT_ERROR = 1, 4
EXIT_STATUS = f"exit status: 0 OK; {EXIT_WARN} WARN; 2 bad input; {EXIT_ERROR} ERROR"
BANDS = {"warn": (0.85, 1.15), "error": (0.75, 1.25)}
"""--warn and --error's defaults: `analysis.ageing.Band`'s (a test holds them equal; numpy is
not imported to build the command line)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="the calibrated scene YAML (with its body_sensor)")
    parser.add_argument("--foundation", required=True, help="the foundation's record")
    parser.add_argument("--body", required=True, help="the body IMU's record")
    parser.add_argument(
        "--window", type=float, help="window length, s (default: the scene's ageing, else 30)"
    )
    parser.add_argument(
        "--fit",
        nargs="+",
        metavar="SCALE",
        help="the scales re-fitted: stiffness, damping, or stiffness:fl+fr (damping:…) for a "
        "group or one mount (default: the scene's ageing.fit, else stiffness damping)",
    )
    for level, band in BANDS.items():
        parser.add_argument(
            f"--{level}",
            type=float,
            nargs=2,
            metavar=("LOW", "HIGH"),
            help=f"scale band outside which a window is judged {level.upper()} (default: the "
            f"scene's ageing.{level}, else {band[0]:g} {band[1]:g})",
        )


def run(args: argparse.Namespace) -> int:
    import sys

    from mount_twin.analysis.ageing import Band, left_over, track, window_table
    from mount_twin.commands.calibrate import read_pair
    from mount_twin.scene.description import Ageing

    scene, foundation, body = read_pair(args)
    ageing = scene.ageing or Ageing(window_s=30.0)
    band = Band(tuple(args.warn or ageing.warn), tuple(args.error or ageing.error))
    fit = tuple(args.fit or ageing.fit)
    window = ageing.window_s if args.window is None else args.window  # 0 is refused
    fits = track(scene, foundation, body, window, fit, band)
    print("\n".join(window_table(fits)))
    if dropped := left_over(fits, foundation, body, window):
        print(f"mount-twin: warning: {dropped}", file=sys.stderr)
    levels = {f.level for f in fits}
    return EXIT_ERROR if "ERROR" in levels else EXIT_WARN if "WARN" in levels else 0
