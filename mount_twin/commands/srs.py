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
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, NamedTuple

if TYPE_CHECKING:
    from pathlib import Path

    import numpy as np

    from mount_twin.analysis.design_margin import DesignCheck
    from mount_twin.analysis.srs import Spectrum
    from mount_twin.scene.description import Scene

NAME = "srs"
HELP = "shock response spectra (maximax, primary, residual, pseudo-velocity) of a record"
AXES = ("x", "y", "z")
SPECTRA = ("maximax", "primary", "residual", "pseudo_velocity", "positive", "negative")
"""The CSV's columns after frequency_hz, in this order (suffixed _x, _y, _z with --axis all)."""
TABLE = ("maximax", "primary", "residual", "pseudo_velocity")
"""The printed table's spectra for one axis."""
TABLE_ALL = ("maximax", "pseudo_velocity")
"""The printed table's spectra per axis with --axis all (the CSV has them all)."""
TOLERANCE_DB = (-1.5, 3.0)
"""--tolerance-db's default (`mount_twin.analysis.design_margin.TOLERANCE_DB`, which a test
holds equal: this module does not import numpy before it runs)."""
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
    t, accel, name, unit = _record(args)
    if design is not None and unit != "m/s²":
        msg = f"--design is a spectrum in g: {name} is a force (N)"
        raise ValueError(msg)
    axes = axes_of(args)
    if not args.response:
        _check_channels(accel, axes, t, name)
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
    columns = _spectrum_columns(spectra, unit) + _margin_columns(freqs, checks)
    q_text = f"{1 / (2 * zeta):g}" if zeta > 0.0 else "∞"
    print(
        f"{name}: {len(t)} samples at {rate:.6g} Hz, axis {args.axis}, ζ = {zeta:g} (Q = {q_text})"
    )
    if record.note:
        print(record.note)
    what = "gravity and bias" if unit == "m/s²" else "static load"
    print(f"{what} taken out ({removed}): {', '.join(f'{v:.6g}' for v in offset)} {unit}")
    _print_table(freqs, columns, len(axes) == 1, spectra[axes[0]].accurate, ACCURATE_SHARE * rate)
    for axis, check in checks.items():
        print(f"design {args.design}, axis {axis} maximax: {check.summary()}")
    if args.csv:
        _write_csv(args.csv, freqs, columns)
        print(f"csv: {args.csv} (units: {', '.join(sorted({c.unit for c in columns}))})")
    if args.json:
        _write_json(args, freqs, columns, checks, rate, zeta)
        print(f"json: {args.json}")
    if args.plot:
        title = f"SRS of {name}, ζ = {zeta:g}, {removed} taken out"
        band = (low, high) if design is not None else None
        clipped = _plot(args.plot, spectra, design, band, title, ACCURATE_SHARE * rate, unit)
        print(f"plot: {args.plot}" + (f" ({clipped})" if clipped else ""))
    return EXIT_OUT_OF_TOLERANCE if any(not c.passed for c in checks.values()) else 0


def _check_channels(values: np.ndarray, axes: tuple[str, ...], t: np.ndarray, name: str) -> None:
    """Refuse a record whose channel of an axis asked for holds a value not finite (a dead or
    damaged channel has no spectrum, and a design judged without it would pass on the other
    axes), naming the axis, how many and the first (sample, t s from the record's start)."""
    import numpy as np

    from mount_twin.commands.common import refuse_not_finite

    for axis in axes:
        refuse_not_finite(
            np.isfinite(values[:, AXES.index(axis)]),
            "values",
            f"{name}: axis {axis} has",
            lambda i: f"at sample {i} (t = {t[i]:.6g} s)",
            "a damaged or dead channel has no spectrum",
        )


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


def _spectrum_columns(spectra: dict[str, Spectrum], unit: str) -> list[Column]:
    """Every spectrum (SPECTRA) of each axis: of a record in m/s², in g (pseudo-velocity in
    m/s); of a force in N, in N (pseudo-velocity in N·s). The names are suffixed with the axis
    where there are several."""
    from mount_twin.io.csv_import import G

    shown, scale, pv_unit = ("g", G, "m/s") if unit == "m/s²" else (unit, 1.0, f"{unit}·s")
    return [
        Column(
            kind,
            kind if len(spectra) == 1 else f"{kind}_{axis}",
            pv_unit if kind == "pseudo_velocity" else shown,
            getattr(s, kind) / (1.0 if kind == "pseudo_velocity" else scale),
        )
        for axis, s in spectra.items()
        for kind in SPECTRA
    ]


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


def _print_table(
    freqs: np.ndarray,
    columns: list[Column],
    one_axis: bool,
    accurate: np.ndarray,
    accurate_hz: float,
) -> None:
    """The printed table (TABLE's spectra of `one_axis`, else TABLE_ALL's of each axis), a `*`
    on the frequencies where the filter is not `accurate` (above `accurate_hz`, Hz) and a note
    on them."""
    shown = [c for c in columns if c.kind in (TABLE if one_axis else TABLE_ALL)]
    print(f"{'f Hz':>9}" + "".join(f" {c.label:>{c.width}}" for c in shown))
    for k, fk in enumerate(freqs):
        cells = "".join(f" {c.values[k]:>{c.width}.4g}" for c in shown)
        print(f"{fk:>9.4g}{cells}{'' if accurate[k] else '  *'}")
    if not accurate.all():
        print(f"* above fs/10 = {accurate_hz:g} Hz the filter is less accurate (peaks picked low)")


def _margin_columns(freqs: np.ndarray, checks: dict[str, DesignCheck]) -> list[Column]:
    """With a design: the design (g) and each axis's margin (dB) at every frequency, NaN
    where the design does not reach."""
    import numpy as np

    out: list[Column] = []
    for axis, check in checks.items():
        judged = np.isin(freqs, check.frequency_hz)
        if not out:
            design = np.full(freqs.shape, np.nan)
            design[judged] = check.design
            out.append(Column("design", "design_g", "g", design))
        margin = np.full(freqs.shape, np.nan)
        margin[judged] = check.margin_db
        name = "margin_db" if len(checks) == 1 else f"margin_db_{axis}"
        out.append(Column("margin", name, "dB", margin))
    return out


def _write_json(
    args: argparse.Namespace,
    freqs: np.ndarray,
    columns: list[Column],
    checks: dict[str, DesignCheck],
    rate_hz: float,
    zeta: float,
) -> None:
    """The spectra (as --csv has them), and with a design the verdict and its bands."""
    from mount_twin.commands.common import json_text
    from mount_twin.textfiles import write_text

    doc = {
        "input": args.input,
        "axis": args.axis,
        "rate_hz": rate_hz,
        "damping": zeta,
        "frequency_hz": [float(f) for f in freqs],
        "spectra": {c.name: [float(v) for v in c.values] for c in columns},
        "units": {c.name: c.unit for c in columns},
        "design": args.design,
        "tolerance_db": list(args.tolerance_db) if checks else None,
        "verdict": ("PASS" if all(c.passed for c in checks.values()) else "FAIL")
        if checks
        else None,
        "axes": {
            axis: {
                "passed": c.passed,
                "summary": c.summary(),
                "judged": int(c.frequency_hz.shape[0]),
                "not_judged": c.skipped,
                "design_not_reached_hz": [list(r) for r in c.unreached],
                "out_of_band": [
                    {"from_hz": f0, "to_hz": f1, "kind": kind, "worst_db": worst}
                    for f0, f1, kind, worst in c.bands()
                ],
            }
            for axis, c in checks.items()
        },
    }
    write_text(args.json, json_text(doc))


class Column(NamedTuple):
    """One spectrum of one axis as written: `values` in `unit`."""

    kind: str
    name: str
    unit: str
    values: np.ndarray

    @property
    def label(self) -> str:
        """The table's heading: name (PV for pseudo_velocity) and unit."""
        return f"{self.name.replace('pseudo_velocity', 'PV')} {self.unit}"

    @property
    def width(self) -> int:
        """The table's column width."""
        return max(10, len(self.label))


def _record(args: argparse.Namespace) -> tuple[np.ndarray, np.ndarray, str, str]:
    """(stamps s, (n, 3) values, a name, their unit) of the input: the record's specific force
    (m/s², sensor frame), or with --response the twin's response (`_response`)."""
    from pathlib import Path

    path = Path(args.input)
    if args.response or args.scene:
        return _response(args, path)
    if path.suffix.lower() == ".csv":
        from mount_twin.io.xsens_csv import read_csv_record

        sig = read_csv_record(path)
        return sig.t, sig.accel, path.name, "m/s²"
    from mount_twin.io.bag_info import bag_info
    from mount_twin.io.input_samples import read_input, refuse_unprovided
    from mount_twin.io.messages import ACCEL, IMU
    from mount_twin.scene.description import InputSpec

    topics = bag_info(path).topics
    inputs = [t for t in topics if t.msgtype in (IMU, ACCEL)]
    chosen = [t for t in inputs if t.name == args.topic] if args.topic else inputs
    if len(chosen) != 1:
        have = ", ".join(f"{t.name} ({t.msgtype})" for t in topics) or "none"
        want = f"no Imu/AccelStamped topic {args.topic}" if args.topic else "give --topic"
        msg = f"{path}: {want}; the bag's topics: {have}"
        raise ValueError(msg)
    (topic,) = chosen
    decoded = read_input(path, InputSpec(msg_type=topic.msgtype, topic=topic.name))
    why = "a spectrum takes every sample's acceleration as a reading, evenly spaced"
    refuse_unprovided(decoded, f"{path}: {topic.name}:", False, why)
    t = (decoded.stamps_ns - decoded.stamps_ns[0]) * 1e-9
    return t, decoded.accel, f"{path.name} {topic.name}", "m/s²"


def _response(args: argparse.Namespace, path: Path) -> tuple[np.ndarray, np.ndarray, str, str]:
    """`_record` of --response: from the twin's output bag at `path` (its wrench topics), or
    from the scene's input topic of `path` replayed in memory. A run whose integration failed
    is refused: its figures are not the machine's."""
    from mount_twin.analysis.response import check_response, response_of, wrenches_of
    from mount_twin.commands.common import load_scene, warn_if_partial
    from mount_twin.io.bag_info import bag_info
    from mount_twin.io.output_topics import output_table

    if not (args.response and args.scene):
        msg = "--response and --scene go together: the response of the twin on that scene"
        raise ValueError(msg)
    scene = load_scene(args.scene)
    check_response(args.response, scene)
    topics = bag_info(path).topics
    if any(output_table(t.name, t.msgtype) for t in topics):
        from mount_twin.io.output_tables import read_output_bag

        stamps, wrenches = wrenches_of(read_output_bag(path), scene, str(path))
        partial = " (partial)" if warn_if_partial(path) else ""
        source = f"{path.name} (output bag{partial})"
    else:
        stamps, wrenches = _replayed(scene, path)
        source = f"{path.name} replayed on {scene.name}"
    r = response_of(scene, stamps, wrenches, args.response)
    return r.t, r.values, f"{source}: {r.name}", r.unit


def _replayed(scene: Scene, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(stamps s, wrenches) of the scene's twin run on the input topic of the bag at `path`
    (the samples it disregards for a reading marked not provided left out, said on stderr)."""
    import sys

    from mount_twin.analysis.response import followed
    from mount_twin.io.input_decoding import TimeBase
    from mount_twin.io.input_samples import provided_input

    decoded, note = provided_input(path, scene.input)
    if note:
        print(note, file=sys.stderr)
    _, out = followed(scene, decoded.batch(TimeBase.at(int(decoded.stamps_ns[0]))), str(path))
    return out.stamps, out.wrenches


def _write_csv(path: str, freqs: np.ndarray, columns: list[Column]) -> None:
    """`frequency_hz` and one column per spectrum, every value to full precision."""
    import csv

    from mount_twin.textfiles import text_output

    with text_output(path, newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["frequency_hz", *(c.name for c in columns)])
        w.writerows(
            [repr(float(fk)), *(repr(float(c.values[k])) for c in columns)]
            for k, fk in enumerate(freqs)
        )


def _plot(
    png: str,
    spectra: dict[str, Spectrum],
    design: tuple[list[float], list[float]] | None,
    band_db: tuple[float, float] | None,
    title: str,
    accurate_hz: float,
    unit: str,
) -> str:
    """Maximax, primary and residual of one axis (maximax of each with all) in g (a force's in
    its `unit`), log-log, against the design spectrum; the frequencies above fs/10 shaded; the
    y axis takes in every curve (`fit_log_y`). What it leaves out, in words ("" if nothing)."""
    import textwrap

    from mount_twin.analysis.log_labels import fit_log_y
    from mount_twin.figure_files import pyplot, save_png
    from mount_twin.io.csv_import import G

    plt = pyplot()

    scale, ylabel = (
        (G, "peak absolute acceleration [g]")
        if unit == "m/s²"
        else (1.0, f"peak response [{unit}]")
    )
    fig, ax = plt.subplots(figsize=(8, 5.5))
    # maximax wide and pale under the primary and residual that make it up
    styles: dict[str, dict[str, float | str]] = {
        "maximax": {"lw": 4.0, "alpha": 0.4},
        "primary": {"ls": "--"},
        "residual": {"ls": ":"},
    }
    for axis, s in spectra.items():
        for kind in styles if len(spectra) == 1 else ("maximax",):
            ax.loglog(
                s.frequency_hz, getattr(s, kind) / scale, label=f"{kind}, {axis}", **styles[kind]
            )
    if design is not None:
        ax.loglog(*design, "k--", label="design")
        if band_db is not None:
            low, high = (10.0 ** (db / 20.0) for db in band_db)
            band = f"tolerance {band_db[0]:+g}/{band_db[1]:+g} dB"
            ax.loglog(design[0], [v * low for v in design[1]], "k:", lw=1.0, label=band)
            ax.loglog(design[0], [v * high for v in design[1]], "k:", lw=1.0)
    f_top = float(max(s.frequency_hz.max() for s in spectra.values()))
    if f_top > accurate_hz:
        ax.axvspan(accurate_hz, f_top, color="0.9", label="f > fs/10: less accurate")
    clipped = fit_log_y(ax, "g" if unit == "m/s²" else unit)
    ax.set_xlabel("natural frequency [Hz]")
    ax.set_ylabel(ylabel)
    # a long bag or mount name: two lines; what the y axis leaves out, under it
    ax.set_title("\n".join(textwrap.wrap(title, 90) + textwrap.wrap(clipped, 90)), fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save_png(fig, png)
    return clipped
