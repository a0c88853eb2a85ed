"""`mount-twin synthesize --spectrum TABLE.csv -o DIR`: shock inputs that meet a design
spectrum, as Imu bags (see `mount_twin.analysis.synthesis`)."""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from typing import TYPE_CHECKING

from mount_twin.commands.common import (
    non_negative_float,
    non_negative_int,
    positive_float,
    positive_int,
)
from mount_twin.commands.design_options import add_tolerance_argument, tolerance_of
from mount_twin.io.epoch import DEFAULT_START_NS

if TYPE_CHECKING:
    from mount_twin.analysis.synthesis import Synthesis
    from mount_twin.io.signals import Signal

NAME = "synthesize"
HELP = "acceleration time histories whose SRS meets a design spectrum, written as input bags"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", required=True, help="directory of the bags (new)")
    add_synthesis_arguments(parser)
    parser.add_argument("--topic", default="/deck/imu", help="(the bundled scenes' input)")
    parser.add_argument("--frame-id", default="deck_imu", help="header.frame_id")
    parser.add_argument("--start", type=int, default=DEFAULT_START_NS, help="first stamp, ns")
    parser.add_argument(
        "--storage", choices=["mcap", "sqlite3"], default="mcap", help="bag storage format"
    )


def add_synthesis_arguments(parser: argparse.ArgumentParser, *, required: bool = True) -> None:
    """The options of a synthesis (also `qualify`'s, whose --plan may stand for them, so
    --spectrum is not `required` there): spectrum, seeds, rate, axis, damping, tolerance,
    head; a count, rate or duration out of its range is refused at parse, naming it."""
    parser.add_argument(
        "--spectrum",
        required=required,
        metavar="CSV",
        help="the design spectrum (frequency_hz,accel_g), maximax, interpolated log-log",
    )
    parser.add_argument(
        "--seeds", type=positive_int, default=3, help="time histories, one per seed"
    )
    parser.add_argument("--first-seed", type=non_negative_int, default=0, help="the first seed")
    parser.add_argument("--rate", type=positive_float, default=20000.0, help="sampling rate, Hz")
    parser.add_argument(
        "--axis", choices=["x", "y", "z"], default="z", help="sensor axis of the shock"
    )
    damping = parser.add_mutually_exclusive_group()
    damping.add_argument("--damping", type=float, help="damping ratio ζ (default 0.05)")
    damping.add_argument("--q", type=float, help="quality factor Q = 1/(2ζ), instead of ζ")
    add_tolerance_argument(parser, "the band about the design every frequency must meet")
    parser.add_argument(
        "--head",
        type=non_negative_float,
        default=0.05,
        help="rest before the shock, s (the start checks)",
    )


def synthesis_of(
    spectrum: str,
    design: tuple[list[float], list[float]],
    rate_hz: float,
    *,
    damping: float,
    seed: int,
    tolerance_db: tuple[float, float],
) -> Synthesis:
    """`analysis.synthesis.synthesize` of the `design` (Hz, g) read from the file `spectrum`,
    for synthesize and qualify: its refusal (a design it cannot meet, one past rate/10) names
    the file, where it had named the seed alone."""
    from mount_twin.analysis.synthesis import synthesize

    try:
        return synthesize(*design, rate_hz, damping=damping, seed=seed, tolerance_db=tolerance_db)
    except ValueError as err:
        msg = f"{spectrum}: {err}"
        raise ValueError(msg) from None


def synthesized(args: argparse.Namespace) -> Iterator[tuple[int, Synthesis, Signal]]:
    """Per seed of `args` (add_synthesis_arguments): the seed, the shock and its Imu record;
    the design spectrum and the plan printed first."""
    from mount_twin.analysis.srs import damping_ratio
    from mount_twin.analysis.synthesis import imu_record
    from mount_twin.io.design_spectrum import read_design_table

    low, high = tolerance_of(args)
    design = read_design_table(args.spectrum)
    zeta = damping_ratio(args.damping, args.q)
    print(
        f"{args.spectrum}: {len(design[0])} points, {design[0][0]:g}–{design[0][-1]:g} Hz, "
        f"ζ = {zeta:g}, tolerance {low:+g}/{high:+g} dB"
    )
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        shock = synthesis_of(
            args.spectrum, design, args.rate, damping=zeta, seed=seed, tolerance_db=(low, high)
        )
        yield seed, shock, imu_record(shock, args.rate, args.axis, args.head)


def describe(shock: Synthesis, args: argparse.Namespace) -> str:
    """One seed's shock in words: its length, peak, margin, iterations, end at rest."""
    import numpy as np

    from mount_twin.analysis.synthesis import G

    v, d = shock.velocity, shock.displacement
    return (
        f"{shock.t[-1]:.3f} s of shock after {args.head:g} s of rest, peak "
        f"{np.abs(shock.accel).max() / G:.4g} g along {args.axis}; {shock.check.summary()} "
        f"after {shock.iterations} iterations; at its end velocity "
        f"{abs(v[-1]) / np.abs(v).max():.1e} and displacement {abs(d[-1]) / np.abs(d).max():.1e}"
        " of their peaks"
    )


def run(args: argparse.Namespace) -> int:
    from mount_twin.commands.common import new_directory, write_signal

    with new_directory(args.output, "synthesize") as out:
        for seed, shock, sig in synthesized(args):
            bag = out / f"seed_{seed}"
            written = write_signal(
                sig, str(bag), args.topic, args.frame_id, args.start, args.storage
            )
            print(f"{bag}: {written} messages, {describe(shock, args)}")
    return 0
