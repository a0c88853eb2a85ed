"""`mount-twin calibrate SCENE --foundation IN --body IN -o calibrated.scene.yaml`: identify the
parameters a data sheet does not give from a recorded pair (the foundation's IMU, the body's),
with the twin as the model (`mount_twin.analysis.calibration`). IN: a bag (the scene's input
topic, or its body_sensor.topic), a recorder CSV (as `import-csv` reads it) or a Movella/Xsens
DOT CSV export (stamps on the device clock, which synchronised sensors share).
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path

    from mount_twin.analysis.calibration import Calibration
    from mount_twin.io.input_decoding import TimeBase
    from mount_twin.io.signals import Signal
    from mount_twin.scene.description import Scene

NAME = "calibrate"
HELP = "fit mount stiffness and damping scales, the body IMU's yaw and lag to a recorded pair"
EXIT_STATUS = "exit status: 0 calibrated; 2 bad input (a refused parameter is said, not an error)"


FITTED = ("stiffness", "damping", "yaw", "lag")
"""`analysis.calibration_parameters.PARAMETERS` (a test holds them equal: numpy is not imported
to build the command line)."""
ON_REQUEST = ("roll", "pitch", "sensor_x", "sensor_y", "sensor_z", "mass", "cg_x", "cg_y", "cg_z")
"""`analysis.calibration_parameters.ON_REQUEST` (held equal likewise)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML (with its body_sensor)")
    parser.add_argument("--foundation", required=True, help="the foundation's record")
    parser.add_argument("--body", required=True, help="the body IMU's record")
    parser.add_argument("-o", "--output", required=True, help="the calibrated scene YAML (new)")
    parser.add_argument(
        "--fit",
        nargs="+",
        default=list(FITTED),
        metavar="PARAMETER",
        help=f"what to fit, among {', '.join(FITTED)} (the default) and "
        f"{', '.join(ON_REQUEST)} (the body IMU's mounting: angles added to its orientation_rpy, "
        "offsets to its position; the body's mass and inertia scaled, its CG offset); "
        "stiffness:fl+fr (or damping:…) scales only those mounts, to fit groups or single "
        "mounts apart",
    )
    parser.add_argument("--plot", metavar="PNG", help="the body record against the prediction")


FOUNDATION_KEYS = ("input.topic", "input.msg_type")
BODY_KEYS = ("body_sensor.topic", "a body_sensor (an IMU)")
"""What sets each record's topic and type, for a bag's errors (`InputBag`)."""


def _is_csv(path: str) -> bool:
    """Whether a record is a CSV (else a bag), by its name."""
    from pathlib import Path

    return Path(path).suffix.lower() == ".csv"


def _read_record(
    path: str,
    topic: str,
    msg_type: str,
    base: TimeBase | None,
    keys: tuple[str, str],
    reads_rate: bool = True,
) -> tuple[Signal, TimeBase | None]:
    """A record: an Xsens DOT CSV, a recorder CSV (their stamps as written), or a bag's `topic`
    (stamps in seconds from `base`, else from its first stamp's whole second: the base
    returned, for the other record of a pair to share). A bag's sample not finite is refused,
    as a CSV's cell is: named, with how many; so is one whose message marks a reading the fit
    reads (its rate if `reads_rate`) not provided (REP-145)."""
    from mount_twin.io.input_decoding import TimeBase
    from mount_twin.io.signals import Signal
    from mount_twin.io.xsens_csv import read_csv_record

    if _is_csv(path):
        return read_csv_record(path), base
    from mount_twin.commands.common import refuse_not_finite
    from mount_twin.engine.reading_screen import readable
    from mount_twin.io.input_samples import read_input, refuse_unprovided
    from mount_twin.scene.description import InputSpec

    decoded = read_input(path, InputSpec(msg_type=msg_type, topic=topic), keys)
    why = "a fit needs every sample it compares"
    refuse_unprovided(decoded, f"{path}: {topic}:", reads_rate, why)
    refuse_not_finite(
        readable(decoded.accel, decoded.gyro),
        "samples",
        f"{path}: {topic}:",
        lambda i: f"its message {i} (stamp {int(decoded.stamps_ns[i])} ns)",
        "a fit needs every sample it compares",
    )
    base = base or TimeBase.at(int(decoded.stamps_ns[0]))
    return Signal(base.seconds(decoded.stamps_ns), decoded.accel, decoded.gyro), base


def read_pair(args: argparse.Namespace) -> tuple[Scene, Signal, Signal]:
    """The scene (it must have a body_sensor) and its (foundation, body) records, on one
    clock, from `args.scene`, `args.foundation` and `args.body`; a record that does not move
    (`calibration_records.still_record`: a still foundation, a body still beside its foundation's
    motion) is refused, naming its file (and a bag's topic), as a pair that does not overlap
    on one clock is (`calibration_records.overlap_problem`), naming both."""
    from mount_twin.analysis.calibration_records import overlap_problem, still_record
    from mount_twin.commands.common import load_scene
    from mount_twin.io.messages import IMU

    scene = load_scene(args.scene)
    if scene.body_sensor is None:
        msg = f"{args.scene}: no body_sensor: where is the body's IMU and how is it turned?"
        raise ValueError(msg)
    spec = scene.input
    foundation, base = _read_record(
        args.foundation, spec.topic, spec.msg_type, None, FOUNDATION_KEYS, spec.reads_rate
    )
    body, _ = _read_record(args.body, scene.body_sensor.topic, IMU, base, BODY_KEYS)
    named = (f"--body {args.body}", f"--foundation {args.foundation}'s")
    if apart := overlap_problem(foundation, body, named):
        raise ValueError(apart)
    if still := still_record(foundation, body):
        path, topic = {
            "foundation": (args.foundation, spec.topic),
            "body": (args.body, scene.body_sensor.topic),
        }[still.record]
        msg = f"{path}: {still.why}" if _is_csv(path) else f"{path}: {topic}: {still.why}"
        raise ValueError(msg)
    return scene, foundation, body


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from mount_twin.analysis.calibration import calibrate
    from mount_twin.commands.common import check_targets

    check_targets(
        plot=args.plot, output=args.output, reads=(args.scene, args.foundation, args.body)
    )
    out = Path(args.output)
    if out.exists():
        msg = f"{out}: exists; calibrate writes a new scene file"
        raise ValueError(msg)
    scene, foundation, body = read_pair(args)
    cal = calibrate(scene, foundation, body, tuple(args.fit))
    lines = describe(cal)
    print("\n".join(lines))
    _write_scene(args.scene, out, cal, lines)
    print(f"calibrated scene: {out}")
    if args.plot:
        _plot(args.plot, scene, cal, foundation, body)
        print(f"plot: {args.plot}")
    return 0


def describe(cal: Calibration) -> list[str]:
    """Each parameter with its 1σ or why it is refused, and the residual before and after;
    every figure in its unit (a scale factor as ×value, its 1σ a plain number): the 1σ had
    none ("lag: 18.89 ms ± 0.29 (1σ)")."""
    from mount_twin.analysis.calibration_parameters import is_scale

    lines = []
    for name, value in cal.values.items():
        if name in cal.sigma:
            sigma = cal.sigma[name]
            spread = f"{sigma:.2g}" if is_scale(name) else _in_unit(name, sigma, ".2g")
            lines.append(f"{name}: {_in_unit(name, value, '.4g')} ± {spread} (1σ)")
        elif name in cal.refused:
            kept = _in_unit(name, value, "g")
            lines.append(f"{name}: refused, {cal.refused[name]}; kept at {kept}")
    lines.append(
        f"body sensor, normalised RMS error: {cal.nrms_before:.3f} before, {cal.nrms_after:.3f}"
        " after"
    )
    return lines


def _in_unit(name: str, value: float, spec: str) -> str:
    """Parameter `name`'s `value` (SI) formatted by `spec` in its unit: an angle in
    rad with degrees beside, a lag in ms, an offset in mm, or a scale factor ×1.23."""
    from mount_twin.analysis.calibration_parameters import ANGLES, is_scale
    from mount_twin.physics.rotations import angle_text

    if name in ANGLES:
        return angle_text(value, spec)
    if is_scale(name):
        return f"×{value:{spec}}"
    return f"{value * 1e3:{spec}} {'ms' if name == 'lag' else 'mm'}"  # the rest: s and m


def _write_scene(source: str, out: Path, cal: Calibration, lines: list[str]) -> None:
    """The scene file with the calibrated values, and what was fitted as a comment on top."""
    import yaml

    from mount_twin.scene.yaml_reading import read_scene_yaml
    from mount_twin.textfiles import write_text

    data = read_scene_yaml(source)
    for raw, mount in zip(data["mounts"], cal.scene.mounts, strict=True):
        if raw.get("kind", "linear") == "linear":
            raw["stiffness"] = list(mount.stiffness)  # type: ignore[union-attr]
            raw["damping"] = list(mount.damping)  # type: ignore[union-attr]
    body = cal.scene.body
    data["body"].update(mass=body.mass, cg=list(body.cg), inertia=list(body.inertia))
    sensor = cal.scene.body_sensor
    if sensor is not None:
        written = data.setdefault("body_sensor", {})
        written["orientation_rpy"] = list(sensor.orientation_rpy)
        written["position"] = list(sensor.position)
        written["lag_s"] = sensor.lag_s
    head = [f"# calibrated from {source} by mount-twin calibrate", *(f"# {ln}" for ln in lines)]
    text = "\n".join(head) + "\n" + yaml.safe_dump(data, sort_keys=False)
    write_text(out, text)


def _plot(png: str, scene: Scene, cal: Calibration, foundation: Signal, body: Signal) -> None:
    """The body record's axes against the prediction, nominal and calibrated, each about its
    mean (the sensor's axes: its x is not F's where the body sensor is turned)."""
    from scipy.interpolate import CubicSpline

    from mount_twin.analysis.calibration import predict
    from mount_twin.figure_files import pyplot, save_png

    plt = pyplot()

    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 8))
    shown = [(scene, "nominal", "tab:gray"), (cal.scene, "calibrated", "tab:red")]
    for i, ax in enumerate(axes):
        ax.plot(
            body.t - body.t[0],
            body.accel[:, i] - body.accel[:, i].mean(),
            "k",
            lw=1.0,
            label="measured",
        )
        for sc, label, colour in shown:
            t, f = predict(sc, foundation)
            lag = sc.body_sensor.lag_s if sc.body_sensor else 0.0
            p = CubicSpline(t, f[:, i])(body.t - lag)
            ax.plot(body.t - body.t[0], p - p.mean(), color=colour, lw=0.8, label=label)
        ax.set_ylabel(f"body IMU specific force\nalong its {'xyz'[i]}, about its mean [m/s²]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper right")
    axes[0].set_title(
        f"body sensor: NRMS {cal.nrms_before:.3f} nominal, {cal.nrms_after:.3f} calibrated",
        fontsize=9,
    )
    axes[-1].set_xlabel("time from the body record's first sample [s]")
    save_png(fig, png, dpi=100)
