"""`mount-twin generate half-sine|ship-motion -o OUT`: a bag of a generated foundation motion."""

from __future__ import annotations

import argparse

from mount_twin.io.epoch import DEFAULT_START_NS

NAME = "generate"
HELP = "write a bag of a generated foundation motion"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("kind", choices=["half-sine", "ship-motion"])
    parser.add_argument("-o", "--output", required=True)
    parser.add_argument(
        "--topic", default="/deck/imu", help="(default: /deck/imu, the bundled scenes' input)"
    )
    parser.add_argument(
        "--frame-id", default="deck_imu", help="header.frame_id (default: deck_imu)"
    )
    parser.add_argument(
        "--rate",
        type=float,
        help="sampling rate, Hz (default: 10000 for half-sine, 1000 for ship-motion)",
    )
    parser.add_argument(
        "--duration",
        type=float,
        help="record length, s (default: 0.4 for half-sine, 5 for ship-motion)",
    )
    parser.add_argument("--peak", type=float, default=150.0, help="half-sine peak, m/s²")
    parser.add_argument("--pulse", type=float, default=0.008, help="half-sine duration, s")
    parser.add_argument(
        "--rebound",
        type=float,
        default=0.0,
        help="peak of a downward half-sine right after the pulse, m/s², lasting "
        "peak·pulse/rebound so the deck ends at rest (naval double half-sine; 0: none)",
    )
    parser.add_argument(
        "--lateral",
        type=float,
        default=0.0,
        help="share of the vertical half-sine(s) also applied along +y of F (athwartships)",
    )
    parser.add_argument("--start", type=int, default=DEFAULT_START_NS, help="first stamp, ns")
    parser.add_argument(
        "--storage", choices=["mcap", "sqlite3"], default="mcap", help="bag storage format"
    )


def _given(value: float | None, default: float) -> float:
    """The option's value where given (0 too: refused by the signal, not replaced), else the
    kind's default."""
    return default if value is None else value


def run(args: argparse.Namespace) -> int:
    from mount_twin.commands.common import write_signal
    from mount_twin.io.signals import half_sine_shock, ship_motion

    if args.kind == "half-sine":
        sig = half_sine_shock(
            peak=args.peak,
            duration=args.pulse,
            rate_hz=_given(args.rate, 10000.0),
            total=_given(args.duration, 0.4),
            lateral=args.lateral,
            rebound=args.rebound,
        )
    else:
        sig = ship_motion(rate_hz=_given(args.rate, 1000.0), total=_given(args.duration, 5.0))
    n = write_signal(sig, args.output, args.topic, args.frame_id, args.start, args.storage)
    print(f"wrote {n} sensor_msgs/msg/Imu messages on {args.topic} to {args.output}")
    return 0
