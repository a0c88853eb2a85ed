"""Command line: `mount-twin replay|demo|generate|import-csv`."""

# Imports beyond the standard library wait until a command runs: numba, numpy and rosbags take
# seconds to import, and `--help` or a mistyped argument must answer at once (tested).

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from mount_twin.errors import MountTwinError

if TYPE_CHECKING:
    from mount_twin.io.signals import Signal
    from mount_twin.replay import ReplaySummary

DEFAULT_SCENE = "pump_8_mounts.scene.yaml"
DEFAULT_BAG = "ship_motion_1khz"
FAIL_ON = ("never", "warn", "error")
"""`replay --fail-on` choices; the index of warn and error is their diagnostics level."""


def share_dir() -> Path:
    """Where config/ and bags/ are: the source tree, or share/mount_twin of an install."""
    here = Path(__file__).resolve().parent
    # An editable or source checkout has config/ beside the package; a colcon install has
    # <prefix>/share/mount_twin above <prefix>/lib/pythonX.Y/site-packages/mount_twin.
    for candidate in (here.parent, *(p / "share" / "mount_twin" for p in here.parents)):
        if (candidate / "config" / DEFAULT_SCENE).exists():
            return candidate
    msg = "cannot find mount_twin's config/ and bags/ (source tree or share/mount_twin)"
    raise MountTwinError(msg)


def _write_signal(
    sig: Signal, out: str, topic: str, frame_id: str, start_ns: int, storage: str
) -> int:
    """Write `sig` as sensor_msgs/Imu messages stamped start_ns + t into a new bag."""
    import numpy as np

    from mount_twin.io.bag import write_bag
    from mount_twin.io.messages import IMU, imu_messages

    stamps = start_ns + np.rint(sig.t * 1e9).astype(np.int64)
    return write_bag(
        out, topic, IMU, iter(imu_messages(stamps, sig.accel, sig.gyro, frame_id)), storage
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit status."""
    parser = argparse.ArgumentParser(prog="mount-twin", description=__doc__)
    sub = parser.add_subparsers(dest="cmd", required=True)
    rp = sub.add_parser("replay", help="replay a bag through the twin into an mcap bag")
    rp.add_argument("input", help="input bag (mcap or sqlite3)")
    rp.add_argument("--scene", required=True, help="scene YAML")
    rp.add_argument("-o", "--output", required=True, help="output bag directory (new)")
    rp.add_argument("--chunk", type=int, default=2000, help="messages per engine batch")
    rp.add_argument("--no-progress", action="store_true")
    rp.add_argument("--plot", metavar="PNG", help="also plot the outputs into this PNG")
    rp.add_argument(
        "--fail-on",
        choices=FAIL_ON,
        default="never",
        help="exit 4 if the worst diagnostics level of the run reaches this (default: never)",
    )
    dm = sub.add_parser("demo", help="replay the bundled bag through the bundled default scene")
    dm.add_argument("-o", "--output", default="demo_out", help="output bag directory (new)")
    dm.add_argument("--plot", metavar="PNG", help="also plot the outputs into this PNG")
    gen = sub.add_parser("generate", help="write a bag of a generated foundation motion")
    gen.add_argument("kind", choices=["half-sine", "ship-motion"])
    gen.add_argument("-o", "--output", required=True)
    gen.add_argument("--topic", default="/imu/data")
    gen.add_argument("--frame-id", default="deck_imu")
    gen.add_argument("--rate", type=float, help="sampling rate, Hz")
    gen.add_argument("--duration", type=float, help="record length, s")
    gen.add_argument("--peak", type=float, default=150.0, help="half-sine peak, m/s²")
    gen.add_argument("--pulse", type=float, default=0.008, help="half-sine duration, s")
    gen.add_argument(
        "--rebound",
        type=float,
        default=0.0,
        help="peak of a downward half-sine right after the pulse, m/s², lasting "
        "peak·pulse/rebound so the deck ends at rest (naval double half-sine; 0: none)",
    )
    gen.add_argument(
        "--lateral",
        type=float,
        default=0.0,
        help="share of the vertical half-sine(s) also applied along +y of F (athwartships)",
    )
    gen.add_argument(
        "--start", type=int, default=1_700_000_000_000_000_000, help="first stamp, ns"
    )
    gen.add_argument("--storage", choices=["mcap", "sqlite3"], default="mcap")
    imp = sub.add_parser("import-csv", help="CSV t,ax,ay,az,wx,wy,wz → sensor_msgs/Imu bag")
    imp.add_argument("csv")
    imp.add_argument("-o", "--output", required=True)
    imp.add_argument("--topic", default="/imu/data")
    imp.add_argument("--frame-id", default="imu_link")
    imp.add_argument("--offset", type=int, default=0, help="added to t·1e9 for the stamp, ns")
    imp.add_argument("--storage", choices=["mcap", "sqlite3"], default="mcap")
    args = parser.parse_args(argv)
    try:
        return _run(args)
    except (MountTwinError, ValueError, OSError) as err:
        print(f"mount-twin: error: {err}", file=sys.stderr)
        return 2


def _verdict(summary: ReplaySummary, fail_on: str) -> int:
    """The exit status of a replay: 3 if no input sample was accepted (saying why), 4 if the
    run's worst diagnostics level reached `fail_on`, else 0."""
    if not summary.counts.get("accepted", 0):
        rejected = {k: v for k, v in summary.counts.items() if k.startswith("rejected_") and v}
        why = (
            f"{summary.counts.get('received', 0)} received, rejected: {rejected}"
            if rejected
            else "the input topic holds no message"
        )
        if summary.wrong_frame_id is not None:
            why += f"; the bag's header.frame_id is {summary.wrong_frame_id!r}: see input.frame_id"
        print(f"mount-twin: error: no input sample was accepted ({why})", file=sys.stderr)
        return 3
    if fail_on != "never" and summary.worst_level >= FAIL_ON.index(fail_on):
        from mount_twin.engine.batch import LEVEL_NAMES

        level = LEVEL_NAMES[summary.worst_level]
        print(f"mount-twin: diagnostics reached {level} (--fail-on {fail_on})", file=sys.stderr)
        return 4
    return 0


def _run(args: argparse.Namespace) -> int:
    """Carry out a parsed command line."""
    if args.cmd in ("replay", "demo"):
        from mount_twin.replay import replay
        from mount_twin.scene.loader import load_scene_file

        if args.cmd == "demo":
            share = share_dir()
            scene_path, bag = share / "config" / DEFAULT_SCENE, share / "bags" / DEFAULT_BAG
            chunk, progress = 2000, True
        else:
            scene_path, bag, chunk, progress = (
                args.scene,
                args.input,
                args.chunk,
                not args.no_progress,
            )
        summary = replay(
            load_scene_file(scene_path), bag, args.output, chunk=chunk, progress=progress
        )
        print(summary.text())
        if args.plot:
            from mount_twin.plot import plot_output_bag  # matplotlib only when asked for

            png = plot_output_bag(
                args.output,
                args.plot,
                Path(scene_path).name,
                summary.events,
                summary.origin_s,
            )
            print(f"plot: {png}")
        return _verdict(summary, getattr(args, "fail_on", "never"))
    from mount_twin.io.signals import half_sine_shock, read_csv, ship_motion

    if args.cmd == "generate":
        if args.kind == "half-sine":
            sig = half_sine_shock(
                peak=args.peak,
                duration=args.pulse,
                rate_hz=args.rate or 10000.0,
                total=args.duration or 0.4,
                lateral=args.lateral,
                rebound=args.rebound,
            )
        else:
            sig = ship_motion(rate_hz=args.rate or 1000.0, total=args.duration or 5.0)
        n = _write_signal(sig, args.output, args.topic, args.frame_id, args.start, args.storage)
    else:
        sig = read_csv(args.csv)
        n = _write_signal(sig, args.output, args.topic, args.frame_id, args.offset, args.storage)
    print(f"wrote {n} sensor_msgs/msg/Imu messages on {args.topic} to {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
