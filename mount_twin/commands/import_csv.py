"""`mount-twin import-csv FILE -o OUT`: a recorder's CSV as a sensor_msgs/Imu bag."""

from __future__ import annotations

import argparse

from mount_twin.io.epoch import DEFAULT_START_NS

NAME = "import-csv"
HELP = (
    "a recorder's CSV (time, acceleration, optional gyro; units, ; and decimal comma) or a "
    "Movella/Xsens DOT export → Imu bag"
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("csv", help="CSV file (see mount_twin.io.csv_import for what is read)")
    parser.add_argument("-o", "--output", required=True, help="output bag directory (new)")
    parser.add_argument(
        "--topic", default="/deck/imu", help="topic to write (the bundled scenes' input)"
    )
    parser.add_argument("--frame-id", default="deck_imu", help="header.frame_id to write")
    parser.add_argument(
        "--offset",
        type=int,
        metavar="NS",
        default=DEFAULT_START_NS,
        help="header stamp = NS + the CSV's time, ns (0 if that time is since the epoch)",
    )
    parser.add_argument("--delimiter", help="between cells (default: sniffed from the header)")
    parser.add_argument("--decimal", choices=[".", ","], help="decimal mark (default: sniffed)")
    parser.add_argument(
        "--columns",
        metavar="ROLE=NAME,...",
        help="header names for t, ax, ay, az, wx, wy, wz, e.g. t=Time,ax=AccX (default: "
        "recognised names)",
    )
    parser.add_argument("--time-unit", help="s, ms, us or ns (default: from the header, else s)")
    parser.add_argument(
        "--accel-unit", help="m/s^2, g or mm/s^2 (default: from the header, else m/s^2)"
    )
    parser.add_argument(
        "--gyro-unit", help="rad/s or deg/s (default: from the header, else rad/s)"
    )
    parser.add_argument(
        "--single-axis",
        choices=["x", "y", "z"],
        help="a single-axis record: its one acceleration column is along this sensor axis "
        "(the others 0); name the column with --columns az=NAME if time is not alone beside it",
    )
    parser.add_argument(
        "--storage", choices=["mcap", "sqlite3"], default="mcap", help="bag storage format"
    )


def run(args: argparse.Namespace) -> int:
    from mount_twin.commands.common import write_signal
    from mount_twin.io.csv_import import CsvFormat, read_recorder_csv
    from mount_twin.io.xsens_csv import is_xsens_csv, read_xsens_csv

    columns = {}
    for pair in (args.columns or "").split(","):
        if pair.strip():
            role, sep, name = pair.partition("=")
            if not sep or role.strip() not in ("t", "ax", "ay", "az", "wx", "wy", "wz"):
                msg = f"--columns: {pair!r} is not ROLE=NAME with ROLE one of t, ax … wz"
                raise ValueError(msg)
            columns[role.strip()] = name.strip()
    units = {
        q: u
        for q, u in (
            ("time", args.time_unit),
            ("accel", args.accel_unit),
            ("gyro", args.gyro_unit),
        )
        if u
    }
    delimiter = "\t" if args.delimiter in ("\\t", "tab") else args.delimiter
    fmt = CsvFormat(delimiter, args.decimal, columns, units, args.single_axis)
    if is_xsens_csv(args.csv):  # its own layout: the device clock, Acc_*, Gyr_* in deg/s
        _refuse_format_options(args)
        imported = read_xsens_csv(args.csv)
    else:
        imported = read_recorder_csv(args.csv, fmt)
    n = write_signal(
        imported.signal,
        args.output,
        args.topic,
        args.frame_id,
        args.offset,
        args.storage,
        imported.stamps_ns,
    )
    print(f"wrote {n} sensor_msgs/msg/Imu messages on {args.topic} to {args.output}")
    for note in imported.notes:
        print(f"  {note}")
    return 0


FORMAT_OPTIONS = (
    "delimiter",
    "decimal",
    "columns",
    "time_unit",
    "accel_unit",
    "gyro_unit",
    "single_axis",
)
"""The options (argparse's names) saying how a recorder CSV is laid out (`CsvFormat`): none
applies to a Movella/Xsens DOT export, whose layout is its own."""


def _refuse_format_options(args: argparse.Namespace) -> None:
    """ValueError (exit 2) naming the FORMAT_OPTIONS given for a Movella/Xsens DOT export:
    they had been ignored without a word."""
    given = ["--" + o.replace("_", "-") for o in FORMAT_OPTIONS if getattr(args, o) is not None]
    if given:
        msg = (
            f"{args.csv}: a Movella/Xsens DOT export's layout is read as is (SampleTimeFine µs, "
            f"Acc_* m/s², Gyr_* deg/s): {', '.join(given)} do not apply to it; leave them out"
        )
        raise ValueError(msg)
