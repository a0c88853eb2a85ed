"""The checks a Scene built in code gets (`dataclasses.replace` on a loaded one, or one made by
hand), where no loader read its values: `model.assemble` runs them, so that what the loaders
refuse by its key path cannot reach the core as wrong physics (a mount turned by 30 "rad" for
30°, a negative mass that runs and fails at every sample).

They are the loaders' essential bounds, named by attribute path: every number finite, the mass
and the inertia's principal moments positive, stiffness and damping not negative, angles
within a turn, the DOFs and each mount's kind known and matching its type. A loaded scene
passes them by construction; the rest of the loaders' checks (`scene.checks`: statics, sag,
ratings) stay theirs.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator

import numpy as np

from mount_twin.errors import SceneError
from mount_twin.scene.description import DOF_NAMES, LinearMount, Scene
from mount_twin.scene.geometry_reading import ANGLE_LIMIT_RAD
from mount_twin.scene.mount_reading import MOUNT_KINDS

LAW_WORDS = ("stiffness", "damping")
"""A number whose field's name holds one of these is a law's coefficient: not negative (a
linear mount's `stiffness`, a bolt's `clamp_stiffness`, a snubber's `damping`, …)."""


def check_built(scene: Scene) -> None:
    """Raise SceneError (the scene's source, the attribute path) for a value no loader would
    have taken (module docstring)."""

    def error(path: str, msg: str) -> SceneError:
        return SceneError(scene.source, path, msg)

    for path, value in _numbers(scene, ""):
        if not math.isfinite(value):
            raise error(path, f"must be finite, got {value!r}")
        field_name = path.rsplit(".", 1)[-1].partition("[")[0]
        if value < 0.0 and any(word in field_name for word in LAW_WORDS):
            raise error(path, f"must be ≥ 0, got {value!r}")
    if not scene.body.mass > 0.0:
        raise error("body.mass", f"must be > 0 kg, got {scene.body.mass!r}")
    if not np.linalg.eigvalsh(np.array(scene.body.inertia_tensor())).min() > 0.0:
        raise error("body.inertia", f"not positive definite: {list(scene.body.inertia)!r}")
    if len(set(scene.dofs)) != len(scene.dofs) or not set(scene.dofs) <= set(DOF_NAMES):
        raise error("dofs", f"expected distinct names of {', '.join(DOF_NAMES)}, got {scene.dofs}")
    angles = {"input.sensor_rpy": scene.input.sensor_rpy}
    if scene.body_sensor is not None:
        angles["body_sensor.orientation_rpy"] = scene.body_sensor.orientation_rpy
    for i, mount in enumerate(scene.mounts):
        path = f"mounts[{i}]"
        if mount.kind not in MOUNT_KINDS or isinstance(mount, LinearMount) != (
            mount.kind == "linear"
        ):
            raise error(
                f"{path}.kind", f"{mount.kind!r} is not the kind of a {type(mount).__name__}"
            )
        angles[f"{path}.orientation_rpy"] = mount.orientation_rpy
    for path, rpy in angles.items():
        if max(abs(a) for a in rpy) > ANGLE_LIMIT_RAD:
            raise error(path, f"{list(rpy)!r}: beyond a turn: radians, not degrees")


def _numbers(value: object, path: str) -> Iterator[tuple[str, float]]:
    """(attribute path, number) of every number in `value`'s dataclasses and tuples."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        for field in dataclasses.fields(value):
            sub = f"{path}.{field.name}" if path else field.name
            yield from _numbers(getattr(value, field.name), sub)
    elif isinstance(value, tuple):
        for k, item in enumerate(value):
            yield from _numbers(item, f"{path}[{k}]")
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        yield path, float(value)
