"""The record `mount-twin srs` computes spectra of: a bag's Imu or AccelStamped topic or a
recorder CSV (specific force, m/s², sensor frame), or with --response the twin's response (from
its output bag, or from the input bag replayed in memory); a channel asked for that holds a value
not finite is refused. Standard library only until called (`mount_twin.commands`).
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from mount_twin.commands.design_options import AXES

if TYPE_CHECKING:
    from pathlib import Path

    import numpy as np

    from mount_twin.scene.description import Scene


def check_channels(values: np.ndarray, axes: tuple[str, ...], t: np.ndarray, name: str) -> None:
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


def read_record(args: argparse.Namespace) -> tuple[np.ndarray, np.ndarray, str, str]:
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
    """`read_record` of --response: from the twin's output bag at `path` (its wrench topics), or
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
