"""The parameters a calibration fits (`analysis.calibration`), and the scene a set of their
values makes (`calibrated_scene`): scale factors on the linear mounts' stiffness and damping (of
every mount, or of a group: `stiffness:A+B`), the body sensor's angles (rad), position offset (m
in F) and lag (s), a scale factor on the body's mass and inertia, and the CG's offset (m in F).
"""

from __future__ import annotations

import dataclasses
from typing import cast

from mount_twin.scene.description import BodySensor, LinearMount, Scene, Vec3, Vec6

PARAMETERS = ("stiffness", "damping", "yaw", "lag")
"""What `calibrate` fits unless told otherwise."""
ON_REQUEST = ("roll", "pitch", "sensor_x", "sensor_y", "sensor_z", "mass", "cg_x", "cg_y", "cg_z")
"""What it fits when named too: the rest of the body sensor's mounting."""
ANGLES = ("roll", "pitch", "yaw")
OFFSETS = ("sensor_x", "sensor_y", "sensor_z")
CG_OFFSETS = ("cg_x", "cg_y", "cg_z")
MOUNT_SCALES = ("stiffness", "damping")


def _times(values: Vec6, factor: float) -> Vec6:
    """Six values, each times `factor`."""
    return cast("Vec6", tuple(factor * v for v in values))


def is_mount_scale(name: str) -> bool:
    """Whether a parameter is a stiffness or damping scale (of all mounts or of a group)."""
    return name.partition(":")[0] in MOUNT_SCALES


def is_scale(name: str) -> bool:
    """Whether a parameter is a scale factor (fitted as a logarithm): a mount scale or mass."""
    return is_mount_scale(name) or name == "mass"


def scaled_mounts(name: str, scene: Scene) -> list[str]:
    """The linear mounts a scale parameter applies to: all of them, or those `name` lists
    after its colon, joined by `+`. Raises ValueError naming a mount the scene lacks, or one
    whose kind has no stiffness and damping scales (a bolt, a key, rubber with its own law),
    or an empty name in the group."""
    linear = [m.name for m in scene.mounts if isinstance(m, LinearMount)]
    _, colon, group = name.partition(":")
    listed = group.split("+") if colon else linear
    if colon and not all(listed):
        msg = f"{name}: a group names its mounts, stiffness:A+B (damping:A+B)"
        raise ValueError(msg)
    wrong = [m for m in listed if m not in linear]
    if not listed:
        msg = f"{name}: the scene has no linear mount to scale"
        raise ValueError(msg)
    if wrong:
        msg = f"{name}: {', '.join(wrong)} is no linear mount of the scene ({', '.join(linear)})"
        raise ValueError(msg)
    return listed


def calibrated_scene(scene: Scene, values: dict[str, float]) -> Scene:
    """`scene` with its linear mounts' stiffness and damping scaled (every scale parameter in
    `values` multiplies the mounts it names), its body sensor yawed and its lag lengthened by
    `values` (missing parameters: nominal)."""
    names = [m.name for m in scene.mounts]
    factor = {(kind, m): 1.0 for kind in ("stiffness", "damping") for m in names}
    for name, value in values.items():
        if is_mount_scale(name):
            for m in scaled_mounts(name, scene):
                factor[name.partition(":")[0], m] *= value
    mounts = tuple(
        dataclasses.replace(
            m,
            stiffness=_times(m.stiffness, factor["stiffness", m.name]),
            damping=_times(m.damping, factor["damping", m.name]),
        )
        if isinstance(m, LinearMount)
        else m
        for m in scene.mounts
    )
    sensor = scene.body_sensor or BodySensor()
    turned = tuple(
        a + values.get(n, 0.0) for a, n in zip(sensor.orientation_rpy, ANGLES, strict=True)
    )
    moved = tuple(p + values.get(n, 0.0) for p, n in zip(sensor.position, OFFSETS, strict=True))
    mounted = dataclasses.replace(
        sensor,
        orientation_rpy=cast("Vec3", turned),
        position=cast("Vec3", moved),
        lag_s=sensor.lag_s + values.get("lag", 0.0),
    )
    mass = values.get("mass", 1.0)
    cg = tuple(c + values.get(n, 0.0) for c, n in zip(scene.body.cg, CG_OFFSETS, strict=True))
    body = dataclasses.replace(
        scene.body,
        mass=scene.body.mass * mass,
        inertia=_times(scene.body.inertia, mass),
        cg=cast("Vec3", cg),
    )
    return dataclasses.replace(scene, body=body, mounts=mounts, body_sensor=mounted)
