"""`mount-twin export OUT_BAG --csv DIR`: an output bag's series as tables."""

from __future__ import annotations

import argparse
from pathlib import Path

NAME = "export"
TABLES = (
    "pose",
    "angles",
    "mount_<mount>",
    "body_imu_predicted",
    "body_imu_residual",
    "diagnostics",
    "events",
)
"""The tables export can write (`io.output_tables.table_names`: a test holds them equal; it is
not imported to build the command line)."""
HELP = f"write the tables an output bag holds as CSV (or Parquet): {', '.join(TABLES)}"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "bag", help="output bag of `mount-twin replay` (or a recording of the node)"
    )
    target = parser.add_mutually_exclusive_group(required=True)
    target.add_argument(
        "--csv", metavar="DIR", help="one CSV per table into DIR (made if missing); all or none"
    )
    target.add_argument(
        "--parquet", metavar="DIR", help="one Parquet file per table into DIR (needs pyarrow)"
    )


def run(args: argparse.Namespace) -> int:
    from mount_twin.commands.common import warn_if_partial
    from mount_twin.io.output_tables import read_output_bag, write_tables

    fmt, directory = ("parquet", args.parquet) if args.parquet else ("csv", args.csv)
    if fmt == "parquet":
        from mount_twin.commands.extras import require

        require("pyarrow", "--parquet")
    _check_directory(f"--{fmt}", directory)
    tables = read_output_bag(args.bag)
    warn_if_partial(args.bag)
    for path, table in zip(write_tables(tables, directory, fmt), tables, strict=True):
        print(f"{path}: {len(table)} rows, columns {', '.join(table.columns)}")
    return 0


def _check_directory(flag: str, path: str) -> None:
    """ValueError naming `flag` where no directory of tables can be at `path` (export creates it
    or writes into it): a file there, or in place of a directory above it, or a dangling
    symlink at or above it (`textfiles.directory_refusal`). Checked before the bag is read,
    which had been read whole to fail there ("/dev/full: File exists", "LINK: File exists")."""
    from mount_twin.textfiles import directory_refusal

    if not (why := directory_refusal(path)):
        return
    said = "exists, not a directory" if Path(path).exists() else why
    msg = f"{flag} {path}: {said}; export writes one file per table into a directory"
    raise ValueError(msg)
