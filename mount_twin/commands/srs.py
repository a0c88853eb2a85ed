"""`mount-twin srs BAG_OR_CSV`: shock response spectra of a recorded foundation motion."""

from __future__ import annotations

import argparse

NAME = "srs"
HELP = "shock response spectra (maximax, primary, residual, pseudo-velocity) of a record"
G = 9.80665


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", help="a bag (its Imu/AccelStamped topic) or a recorder CSV")
    parser.add_argument("--topic", help="the bag's topic (default: its only Imu/AccelStamped)")
    parser.add_argument("--axis", choices=["x", "y", "z"], default="z", help="sensor axis")
    damping = parser.add_mutually_exclusive_group()
    damping.add_argument("--damping", type=float, default=0.05, help="damping ratio ζ")
    damping.add_argument("--q", type=float, help="quality factor Q = 1/(2ζ), instead of ζ")
    parser.add_argument("--freqs", type=float, nargs="+", help="natural frequencies, Hz")
    parser.add_argument(
        "--per-octave", type=int, default=6, help="frequencies per octave without --freqs"
    )
    parser.add_argument("--fmin", type=float, default=10.0, help="lowest frequency, Hz")
    parser.add_argument("--fmax", type=float, default=2000.0, help="highest frequency, Hz")
    parser.add_argument(
        "--gravity",
        choices=["first", "none"],
        default="first",
        help="subtract the first sample (a record starting at rest: gravity and sensor bias), "
        "or nothing",
    )
    parser.add_argument(
        "--csv",
        metavar="FILE",
        help="frequency_hz, maximax, primary, residual (g), pseudo_velocity (m/s)",
    )
    parser.add_argument("--plot", metavar="PNG", help="the spectra in g against Hz, log-log")
    parser.add_argument(
        "--design", metavar="CSV", help="a design spectrum to plot against (frequency_hz,accel_g)"
    )


def run(args: argparse.Namespace) -> int:
    import csv
    from pathlib import Path

    import numpy as np

    from mount_twin.analysis.srs import octave_frequencies, srs

    if args.plot:
        from mount_twin.commands.extras import require

        require("matplotlib", "--plot")
    t, accel, name = _record(args)
    a = accel[:, "xyz".index(args.axis)]
    if args.gravity == "first":
        a = a - a[0]
    rate = (len(t) - 1) / float(t[-1] - t[0])
    if np.ptp(np.diff(t)) > 0.01 * np.mean(np.diff(t)):
        msg = f"{args.input}: the samples are not evenly spaced (an SRS needs a fixed rate)"
        raise ValueError(msg)
    zeta = 1.0 / (2.0 * args.q) if args.q else args.damping
    freqs = (
        np.array(args.freqs)
        if args.freqs
        else octave_frequencies(args.fmin, args.fmax, args.per_octave)
    )
    s = srs(a, rate, freqs, zeta)
    print(f"{name}, axis {args.axis}, {rate:.6g} Hz, ζ = {zeta:g} (Q = {1 / (2 * zeta):g})")
    print(f"{'f Hz':>9} {'maximax g':>10} {'primary g':>10} {'residual g':>10} {'PV m/s':>9}")
    for k in range(freqs.size):
        flag = "" if s.accurate[k] else "  (f > fs/10: less accurate)"
        print(
            f"{freqs[k]:>9.4g} {s.maximax[k] / G:>10.4g} {s.primary[k] / G:>10.4g} "
            f"{s.residual[k] / G:>10.4g} {s.pseudo_velocity[k]:>9.4g}{flag}"
        )
    if args.csv:
        with Path(args.csv).open("w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["frequency_hz", "maximax", "primary", "residual", "pseudo_velocity"])
            for k in range(freqs.size):
                w.writerow(
                    [
                        repr(float(v))
                        for v in (
                            freqs[k],
                            s.maximax[k] / G,
                            s.primary[k] / G,
                            s.residual[k] / G,
                            s.pseudo_velocity[k],
                        )
                    ]
                )
        print(f"csv: {args.csv} (accelerations in g, pseudo-velocity in m/s)")
    if args.plot:
        _plot(s, args, name, zeta)
        print(f"plot: {args.plot}")
    return 0


def _record(args: argparse.Namespace):  # type: ignore[no-untyped-def]
    """(stamps s, specific force (n, 3) m/s² in the sensor frame, a name) of the input."""
    from pathlib import Path

    path = Path(args.input)
    if path.suffix.lower() == ".csv":
        from mount_twin.io.csv_import import read_recorder_csv

        sig = read_recorder_csv(path).signal
        return sig.t, sig.accel, path.name
    from mount_twin.io.bag_info import bag_info
    from mount_twin.io.input_samples import read_input
    from mount_twin.io.messages import ACCEL, IMU
    from mount_twin.scene.description import InputSpec

    topics = [t for t in bag_info(path).topics if t.msgtype in (IMU, ACCEL)]
    chosen = [t for t in topics if t.name == args.topic] if args.topic else topics
    if len(chosen) != 1:
        have = ", ".join(f"{t.name} ({t.msgtype})" for t in topics) or "none"
        msg = f"{path}: give --topic: the bag's Imu/AccelStamped topics are {have}"
        raise ValueError(msg)
    decoded = read_input(path, InputSpec(msg_type=chosen[0].msgtype, topic=chosen[0].name))
    return (
        (decoded.stamps_ns - decoded.stamps_ns[0]) * 1e-9,
        decoded.accel,
        f"{path.name} {chosen[0].name}",
    )


def _plot(s, args: argparse.Namespace, name: str, zeta: float) -> None:  # type: ignore[no-untyped-def]
    import csv

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.5))
    for label, values in (
        ("maximax", s.maximax),
        ("primary", s.primary),
        ("residual", s.residual),
    ):
        ax.loglog(s.frequency_hz, values / G, label=label)
    if args.design:
        with open(args.design, encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
        ax.loglog(
            [float(r["frequency_hz"]) for r in rows],
            [float(r["accel_g"]) for r in rows],
            "k--",
            label=f"design ({args.design})",
        )
    top = float(s.maximax.max()) / G
    ax.set_ylim(top * 1e-3, top * 2.0)  # the residual of a short record falls off to nothing
    ax.set_xlabel("natural frequency [Hz]")
    ax.set_ylabel("peak absolute acceleration [g]")
    ax.set_title(f"SRS of {name}, axis {args.axis}, ζ = {zeta:g}", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.plot, dpi=110)
    plt.close(fig)
