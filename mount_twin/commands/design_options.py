"""The options of a design spectrum that `srs`, `report`, `synthesize` and `qualify` take alike:
--axis (the axes computed and judged), --design (its CSV) and --tolerance-db (the band about it,
dB), with the checks of what they give. Standard library only, as a command module's imports
(`mount_twin.commands`).
"""

from __future__ import annotations

import argparse

AXES = ("x", "y", "z")
TOLERANCE_DB = (-1.5, 3.0)
"""--tolerance-db's default (`mount_twin.analysis.design_margin.TOLERANCE_DB`, which a test
holds equal: this module does not import numpy before it runs)."""


def add_axis_argument(parser: argparse.ArgumentParser, what: str) -> None:
    """--axis x|y|z|all, default z (`axes_of` reads it): the axis `what`, or all three. `srs`
    (the sensor axes it computes and judges) and `report` (the axes of F its --design judges)
    take it the same way: a design names one axis unless `all` is asked for."""
    parser.add_argument(
        "--axis", choices=[*AXES, "all"], default="z", help=f"{what}, or all three"
    )


def axes_of(args: argparse.Namespace) -> tuple[str, ...]:
    """The axes --axis names (`add_axis_argument`), in AXES' order."""
    return AXES if args.axis == "all" else (args.axis,)


def add_design_arguments(parser: argparse.ArgumentParser, judged: str) -> None:
    """--design CSV (what is `judged` against it) and --tolerance-db LOW HIGH: `srs` and
    `report` take a design spectrum the same way."""
    parser.add_argument(
        "--design",
        metavar="CSV",
        help=f"a design spectrum (frequency_hz,accel_g): {judged}",
    )
    add_tolerance_argument(parser, "the band about the design spectrum")


def add_tolerance_argument(parser: argparse.ArgumentParser, what: str) -> None:
    """--tolerance-db LOW HIGH (dB about a design spectrum; `tolerance_of` checks it): `srs`,
    `report`, `synthesize` and `qualify` take it the same way."""
    parser.add_argument(
        "--tolerance-db",
        type=float,
        nargs=2,
        metavar=("LOW", "HIGH"),
        default=TOLERANCE_DB,
        help=f"{what}, dB (default -1.5 3)",
    )


def tolerance_of(args: argparse.Namespace) -> tuple[float, float]:
    """--tolerance-db, checked: LOW < 0 < HIGH."""
    low, high = args.tolerance_db
    if not low < 0.0 < high:
        msg = f"--tolerance-db {low:g} {high:g}: needs LOW < 0 < HIGH (dB about the design)"
        raise ValueError(msg)
    return low, high
