"""`mount-twin srs BAG_OR_CSV`: shock response spectra of a recorded foundation motion.

The record is a bag's sensor_msgs/Imu or geometry_msgs/AccelStamped topic (mcap or sqlite3
directory, an .mcap/.db3 file, a ROS 1 .bag) or a recorder CSV (read as `import-csv` reads it),
one or every axis of the sensor frame. An Imu reports specific force, +g along the up axis at
rest: gravity (and the sensor's bias) is taken out before the spectra, per axis, as the mean of
the record's head (`--gravity mean-head`, the first `--head` seconds, which must be quiet: the
default, averaging the noise down), its first sample (`first`), or not at all (`none`: a
record's constant is then a step, whose spectrum is about twice the constant). The filter runs
at one rate: recorder jitter is taken as such or resampled, and what is not one sampled signal
refused (`mount_twin.analysis.sampling`). Spectra: see `mount_twin.analysis.srs`.
The record is read in `srs_record`, the table and files written in `srs_outputs`; --axis,
--design and --tolerance-db are taken as `report`, `synthesize` and `qualify` take them
(`design_options`).
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from mount_twin.commands.design_options import (
    AXES,
    add_axis_argument,
    add_design_arguments,
    axes_of,
    tolerance_of,
)
from mount_twin.commands.srs_outputs import (
    margin_columns,
    plot,
    print_table,
    spectrum_columns,
    write_csv,
    write_json,
)
from mount_twin.commands.srs_record import check_channels, read_record

if TYPE_CHECKING:
    import numpy as np

    from mount_twin.analysis.design_margin import DesignCheck
    from mount_twin.analysis.srs import Spectrum

NAME = "srs"
HELP = "shock response spectra (maximax, primary, residual, pseudo-velocity) of a record"
OCTAVE, FMIN_HZ = "1/6", 5.0
"""--octave's and --fmin's defaults (--fmax's is fs/10, of the record)."""
SPACING = ("octave", "fmin", "fmax")
"""The options of the frequencies' spacing, which --freqs replaces."""
EXIT_OUT_OF_TOLERANCE = 4
EXIT_STATUS = (
    "exit status: 0 done (with --design: every axis within the tolerance); 2 bad input; "
    f"{EXIT_OUT_OF_TOLERANCE} a spectrum out of the design's tolerance somewhere, or the design "
    "reaching past its frequencies"
)


def _per_octave(text: str) -> float:
    """`1/6` (or `0.1667`: a fraction of an octave) → 6 frequencies per octave."""
    num, _, den = text.partition("/")
    try:
        step = float(num) / float(den) if den else float(num)
    except (ValueError, ZeroDivisionError):
        step = 0.0
    if not 0.0 < step <= 1.0:
        msg = f"{text!r} is not a fraction of an octave (1/N, e.g. 1/6, or a number in (0, 1])"
        raise argparse.ArgumentTypeError(msg)
    return 1.0 / step


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", help="a bag (its Imu/AccelStamped topic) or a recorder CSV")
    parser.add_argument("--topic", help="the bag's topic (default: its only Imu/AccelStamped)")
    add_axis_argument(parser, "sensor axis")
    damping = parser.add_mutually_exclusive_group()
    damping.add_argument("--damping", type=float, help="damping ratio ζ (default 0.05)")
    damping.add_argument("--q", type=float, help="quality factor Q = 1/(2ζ), instead of ζ")
    parser.add_argument(
        "--freqs",
        type=float,
        nargs="+",
        metavar="HZ",
        help="natural frequencies, Hz, instead of --octave, --fmin and --fmax",
    )
    # The spacing parses to None when not given (its defaults applied in `_frequencies`), so
    # that one given beside --freqs is refused, not set aside without a word.
    parser.add_argument(
        "--octave",
        type=_per_octave,
        metavar="1/N",
        help=f"fractional-octave spacing from --fmin to --fmax (default {OCTAVE})",
    )
    parser.add_argument("--fmin", type=float, help=f"lowest frequency, Hz (default {FMIN_HZ:g})")
    parser.add_argument(
        "--fmax",
        type=float,
        help="highest frequency, Hz (default: fs/10, where the filter is accurate)",
    )
    parser.add_argument(
        "--gravity",
        choices=["mean-head", "first", "none"],
        default="mean-head",
        help="take out gravity and bias: the mean of the first --head seconds (quiet, before "
        "the shock), the first sample, or nothing",
    )
    parser.add_argument(
        "--head", type=float, default=0.01, help="quiet head of the record for mean-head, s"
    )
    parser.add_argument(
        "--csv",
        metavar="FILE",
        help="frequency_hz, then maximax, primary, residual (g), pseudo_velocity (m/s), "
        "positive, negative (g); with --response mount:NAME, N and N·s; suffixed _x, _y, _z "
        "with --axis all",
    )
    parser.add_argument(
        "--plot",
        metavar="PNG",
        help="the spectra against Hz, log-log, in g (N with --response mount:NAME)",
    )
    parser.add_argument(
        "--response",
        metavar="WHAT",
        help="spectra of the twin's response instead of the record: cg (the CG's specific "
        "force, F axes) or mount:NAME (its force, N, its axes); INPUT is then the twin's "
        "output bag, or an input bag replayed in memory; needs --scene",
    )
    parser.add_argument("--scene", help="the twin's scene YAML, for --response")
    add_design_arguments(
        parser,
        "each axis's maximax is judged against it, the margins in the table, --csv and --json, "
        "a PASS/FAIL line, exit 4 on FAIL",
    )
    parser.add_argument("--json", metavar="FILE", help="the spectra, margins and verdict as JSON")


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from mount_twin.analysis.sampling import uniform
    from mount_twin.analysis.srs import ACCURATE_SHARE, damping_ratio, gravity_offset, srs
    from mount_twin.commands.common import check_targets
    from mount_twin.io.design_spectrum import read_design_table

    check_targets(
        plot=args.plot,
        json=args.json,
        csv=args.csv,
        reads=(args.input, args.scene, args.design),
    )
    if args.freqs and (spacing := [f"--{o}" for o in SPACING if getattr(args, o) is not None]):
        msg = (
            f"--freqs with {', '.join(spacing)}: give the frequencies (--freqs) or their "
            f"spacing ({', '.join('--' + o for o in SPACING)}), not both"
        )
        raise ValueError(msg)
    if args.plot:
        from mount_twin.commands.extras import require

        require("matplotlib", "--plot")
    zeta = damping_ratio(args.damping, args.q)
    low, high = tolerance_of(args)
    design = read_design_table(args.design) if args.design else None
    t, accel, name, unit = read_record(args)
    if design is not None and unit != "m/s²":
        msg = f"--design is a spectrum in g: {name} is a force (N)"
        raise ValueError(msg)
    axes = axes_of(args)
    if not args.response:
        check_channels(accel, axes, t, name)
    record = uniform(t, accel, args.input)
    t, accel, rate = record.t, record.values, record.rate_hz
    offset, removed = gravity_offset(t, accel, args.gravity, args.head)
    freqs = _frequencies(args, rate)
    frozen = [a for a in axes if np.isnan(accel[:, AXES.index(a)]).all()]  # --response cg
    if frozen:
        said = (
            f"the scene freezes {', '.join(frozen)}: a constraint holds the body there and "
            "publishes no force, so no spectrum"
        )
        if len(frozen) == len(axes):
            raise ValueError(f"--axis {args.axis}: {said}")
        print(f"--axis {args.axis}: {said}")
        axes = tuple(a for a in axes if a not in frozen)
    spectra = {
        axis: srs(accel[:, AXES.index(axis)] - offset[AXES.index(axis)], rate, freqs, zeta)
        for axis in axes
    }
    checks = _design_checks(freqs, spectra, design, (low, high))
    columns = spectrum_columns(spectra, unit) + margin_columns(freqs, checks)
    q_text = f"{1 / (2 * zeta):g}" if zeta > 0.0 else "∞"
    print(
        f"{name}: {len(t)} samples at {rate:.6g} Hz, axis {args.axis}, ζ = {zeta:g} (Q = {q_text})"
    )
    if record.note:
        print(record.note)
    what = "gravity and bias" if unit == "m/s²" else "static load"
    print(f"{what} taken out ({removed}): {', '.join(f'{v:.6g}' for v in offset)} {unit}")
    print_table(freqs, columns, len(axes) == 1, spectra[axes[0]].accurate, ACCURATE_SHARE * rate)
    for axis, check in checks.items():
        print(f"design {args.design}, axis {axis} maximax: {check.summary()}")
    if args.csv:
        write_csv(args.csv, freqs, columns)
        print(f"csv: {args.csv} (units: {', '.join(sorted({c.unit for c in columns}))})")
    if args.json:
        write_json(args, freqs, columns, checks, rate, zeta)
        print(f"json: {args.json}")
    if args.plot:
        title = f"SRS of {name}, ζ = {zeta:g}, {removed} taken out"
        band = (low, high) if design is not None else None
        clipped = plot(args.plot, spectra, design, band, title, ACCURATE_SHARE * rate, unit)
        print(f"plot: {args.plot}" + (f" ({clipped})" if clipped else ""))
    return EXIT_OUT_OF_TOLERANCE if any(not c.passed for c in checks.values()) else 0


def _frequencies(args: argparse.Namespace, rate_hz: float) -> np.ndarray:
    """The natural frequencies, Hz: --freqs, else --octave spacing (default OCTAVE) from --fmin
    (default FMIN_HZ) to --fmax (default: where the filter is accurate at `rate_hz`)."""
    import numpy as np

    from mount_twin.analysis.srs import ACCURATE_SHARE, octave_frequencies

    nyquist = 0.5 * rate_hz
    fmin = FMIN_HZ if args.fmin is None else args.fmin
    fmax = ACCURATE_SHARE * rate_hz if args.fmax is None else args.fmax
    given = [("--freqs", f) for f in args.freqs or ()] or [("--fmin", fmin), ("--fmax", fmax)]
    for flag, f in given:
        if not 0.0 < f < nyquist:
            msg = (
                f"{flag} {f:g} Hz: a natural frequency lies above 0 Hz and below half the "
                f"record's sampling rate ({nyquist:g} Hz)"
            )
            raise ValueError(msg)
    if args.freqs:
        return np.array(args.freqs)
    if fmin > fmax:
        said = f"{fmax:g} Hz" if args.fmax is not None else f"default fs/10 = {fmax:g} Hz"
        msg = f"--fmin {fmin:g} Hz: above --fmax ({said})"
        raise ValueError(msg)
    return octave_frequencies(fmin, fmax, args.octave or _per_octave(OCTAVE))


def _design_checks(
    freqs: np.ndarray,
    spectra: dict[str, Spectrum],
    design: tuple[list[float], list[float]] | None,
    band_db: tuple[float, float],
) -> dict[str, DesignCheck]:
    """Each axis's maximax (g) judged against the design (Hz, g) within `band_db` (dB); none
    without a design."""
    from mount_twin.analysis.design_margin import check_design
    from mount_twin.io.csv_import import G

    if design is None:
        return {}
    return {
        axis: check_design(freqs, s.maximax / G, *design, band_db) for axis, s in spectra.items()
    }
