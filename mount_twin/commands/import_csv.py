"""`mount-twin import-csv FILE -o OUT`: a recorder's CSV as a sensor_msgs/Imu bag."""

from __future__ import annotations

import argparse

NAME = "import-csv"
HELP = "CSV t,ax,ay,az,wx,wy,wz → sensor_msgs/Imu bag"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("csv")
    parser.add_argument("-o", "--output", required=True)
    parser.add_argument("--topic", default="/imu/data", help="topic to write")
    parser.add_argument("--frame-id", default="imu_link", help="header.frame_id to write")
    parser.add_argument("--offset", type=int, default=0, help="added to t·1e9 for the stamp, ns")
    parser.add_argument(
        "--storage", choices=["mcap", "sqlite3"], default="mcap", help="bag storage format"
    )


def run(args: argparse.Namespace) -> int:
    from mount_twin.commands.common import write_signal
    from mount_twin.io.signals import read_csv

    sig = read_csv(args.csv)
    n = write_signal(sig, args.output, args.topic, args.frame_id, args.offset, args.storage)
    print(f"wrote {n} sensor_msgs/msg/Imu messages on {args.topic} to {args.output}")
    return 0
