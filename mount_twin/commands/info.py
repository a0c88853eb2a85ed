"""`mount-twin info BAG|SCENE`: what a bag holds, or what a scene describes."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mount_twin.scene.description import Scene

NAME = "info"
HELP = (
    "show a bag's files, storage, span and topics (like `ros2 bag info`), or a scene's body, "
    "mounts, input and outputs"
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("path", help="a bag (directory or file), or a scene YAML (*.yaml)")


def run(args: argparse.Namespace) -> int:
    path = Path(args.path)
    if path.suffix in (".yaml", ".yml"):
        from mount_twin.commands.common import load_scene

        print(scene_text(load_scene(path)))
    else:
        from mount_twin.io.bag_info import bag_info

        print(bag_info(path).text())
    return 0


def scene_text(scene: Scene) -> str:
    """A scene in a few lines: body, DOFs, each mount, input (and the body IMU), integration,
    and every topic the node publishes with its type."""
    from mount_twin.io.messages import IMU, NODE_NAME, TF, TF_STATIC_TOPIC, resolve
    from mount_twin.io.output_topics import output_types
    from mount_twin.io.scene_record import SCENE_TOPIC, STRING

    b, i, g = scene.body, scene.input, scene.integration
    lines = [
        f"scene:   {scene.name} ({scene.source})",
        f"body:    {b.mass:g} kg, CG {list(b.cg)} m in F, inertia {list(b.inertia)} kg·m²",
        f"DOFs:    {', '.join(scene.dofs)}",
        f"mounts:  {len(scene.mounts)}",
    ]
    width = max(len(m.name) for m in scene.mounts)
    lines += [
        f"  {m.name:<{width}}  {m.kind:<13} at {list(m.position)} m, rpy "
        f"{list(m.orientation_rpy)} rad"
        for m in scene.mounts
    ]
    lines += [
        f"input:   {i.topic} ({i.msg_type}), frame_id {i.frame_id or '(any)'}, "
        f"gyro {i.gyro_filter}"
        + (
            f" {i.gyro_passband_hz:g}/{i.gyro_stopband_hz:g} Hz"
            if i.gyro_filter == "linear_phase"
            else ""
        ),
        *(
            [
                f"body IMU: {bs.topic} ({IMU}), frame_id {bs.frame_id or '(any)'}, at "
                f"{list(bs.position)} m, rpy {list(bs.orientation_rpy)} rad"
            ]
            if (bs := scene.body_sensor) is not None
            else []
        ),
        f"integration: {g.method}"
        + (
            " (by stiffness: at each start's first sample interval, again after a contact)"
            if g.method == "auto"
            else ""
        )
        + f", rtol {g.rtol:g}, atol {g.atol:g}, error estimate "
        + ("on" if g.error_estimate else "off"),
        f"outputs (node named {NODE_NAME}):",
        *(f"  {resolve(t, NODE_NAME):<40} {m}" for t, m in output_types(scene).items()),
        f"  {TF_STATIC_TOPIC:<40} {TF} (latched: the mount frames)",
        f"  {resolve(SCENE_TOPIC, NODE_NAME):<40} {STRING} (latched: the scene, its sha256)",
    ]
    return "\n".join(lines)
