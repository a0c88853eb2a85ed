"""ROS parameters in the Nav2 style ↔ scene mapping.

ROS 2 parameters are flat (dotted names, scalars and homogeneous flat arrays, no list of
mappings). Mounts are therefore given as `mount_names: [fl, fr, ...]` plus one namespace per
mount (`mounts.fl.position`, ...). This module turns such a flat set into the nested mapping the
scene loader validates, so a params YAML and a scene YAML go through one loader.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator, Mapping
from typing import Any, NamedTuple

from mount_twin.errors import SceneError
from mount_twin.integrate.methods import METHODS
from mount_twin.kinds import KINDS
from mount_twin.scene.description import Scene, SceneOrigin
from mount_twin.scene.loader import load_scene_file, scene_from_dict
from mount_twin.scene.reader import Used, shown
from mount_twin.scene.yaml_reading import read_scene_yaml

PARAMETERS: dict[str, tuple[str, str]] = {
    "scene_file": (
        "string",
        "Scene YAML file; when set, the other scene parameters given override its values",
    ),
    "name": ("string", "Scene name"),
    "frames.foundation": ("string", "frame_id of the foundation frame F"),
    "frames.body": ("string", "frame_id of the body frame B (origin at the CG)"),
    "frames.mount_prefix": (
        "string",
        "Prefix of the mount frame ids: a mount's frame is mount_prefix + its name",
    ),
    "body.mass": ("double", "Body mass, kg"),
    "body.cg": ("double_array", "CG at the reference pose [x, y, z], m, in F"),
    "body.inertia": (
        "double_array",
        "Inertia about the CG in B [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], kg·m²",
    ),
    "dofs": ("string", "Free DOFs, space-separated: a subset of x y z alpha gamma delta"),
    "mount_names": ("string_array", "Mount names; each has a namespace mounts.<name>"),
    "input.msg_type": ("string", "sensor_msgs/msg/Imu or geometry_msgs/msg/AccelStamped"),
    "input.topic": ("string", "Input topic"),
    "input.frame_id": ("string", "Expected header.frame_id of the input; empty accepts any"),
    "input.sensor_rpy": ("double_array", "Sensor frame → F as fixed-axis roll, pitch, yaw, rad"),
    "input.sensor_position": ("double_array", "Accelerometer position [x, y, z], m, in F"),
    "input.includes_gravity": ("bool", "Acceleration is specific force (+g up at rest)"),
    "input.g": ("double", "Gravity added along +z of F when includes_gravity is false, m/s²"),
    "input.hold": ("string", "Input between samples: first_order or zero_order"),
    "input.max_gap_s": ("double", "A longer stamp gap is handled per gap_policy, s"),
    "input.gap_policy": ("string", "reset (restart at equilibrium) or bridge"),
    "input.back_jump_reset_s": ("double", "A stamp going back by more than this resets, s"),
    "input.gyro_filter": ("string", "Ω and Ω′ from the gyro: linear_phase, none or ignore"),
    "input.gyro_passband_hz": ("double", "linear_phase gyro filter flat up to this, Hz"),
    "input.gyro_stopband_hz": ("double", "linear_phase gyro filter stops from this, Hz"),
    "input.accel_range_m_s2": ("double", "Accelerometer full scale (0: unknown), m/s²"),
    "input.gyro_range_rad_s": ("double", "Gyro full scale (0: unknown), rad/s"),
    "body_sensor.topic": ("string", "Topic of an IMU on the body (sensor_msgs/Imu)"),
    "body_sensor.frame_id": ("string", "Expected header.frame_id of the body IMU; empty: any"),
    "body_sensor.position": ("double_array", "Body IMU position at the reference pose, m, in F"),
    "body_sensor.orientation_rpy": (
        "double_array",
        "Body IMU axes relative to B as fixed-axis roll, pitch, yaw, rad",
    ),
    "ageing.window_s": ("double", "Mounts that age: each re-fit's window of body stamps, s"),
    "ageing.fit": ("string_array", "Mounts that age: scales re-fitted (stiffness, damping, …)"),
    "ageing.warn": ("double_array", "Mounts that age: WARN outside this scale band [low, high]"),
    "ageing.error": ("double_array", "Mounts that age: ERROR outside this scale band [low, high]"),
    "body_sensor.lag_s": ("double", "Body IMU stamps behind the foundation IMU's, s"),
    "body_sensor.window_s": ("double", "Body IMU comparison: judged window, s"),
    "body_sensor.band_hz": ("double_array", "Body IMU comparison: judged band [low, high], Hz"),
    "body_sensor.warn_nrms": ("double", "Body IMU comparison: WARN past this NRMS in the band"),
    "body_sensor.axes": ("string_array", "Body IMU comparison: axes judged (fx … wz)"),
    "body_sensor.error_nrms": ("double", "Body IMU comparison: ERROR past this NRMS in the band"),
    "initial_state.mode": ("string", "equilibrium or given"),
    "initial_state.gravity": ("string", "Equilibrium gravity: first_sample or nominal"),
    "initial_state.pose": ("double_array", "[X, Y, Z] m, [α, γ, δ] rad: start pose, frozen DOFs"),
    "initial_state.velocity": ("double_array", "[X', Y', Z'] m/s, [α', γ', δ'] rad/s (given)"),
    "initial_state.gravity_samples": ("integer", "Start gravity: mean of this many samples"),
    "initial_state.gravity_window_s": ("double", "Start gravity: and of this long after, s"),
    "initial_state.gravity_tolerance": ("double", "Start check: WARN past | |f0| − g | / g"),
    "initial_state.tilt_tolerance_rad": ("double", "Start check: WARN past this tilt of f0, rad"),
    "integration.method": ("string", "Stepper: auto (by stiffness), " + ", ".join(METHODS)),
    "integration.rtol": ("double", "Relative tolerance of the stepper"),
    "integration.atol": ("double", "Absolute tolerance of the stepper (m, rad, m/s, rad/s)"),
    "integration.max_substeps": ("integer", "Most substeps between two input samples"),
    "integration.error_estimate": ("bool", "Estimate the error live (sampled, linearised)"),
    "outputs.pose": ("bool", "Publish PoseStamped"),
    "outputs.angles": ("bool", "Publish α, γ, δ as Vector3Stamped, rad"),
    "outputs.wrenches": ("bool", "Publish one WrenchStamped per mount"),
    "outputs.tf": ("bool", "Publish the body pose on /tf (frames.foundation → frames.body)"),
    "outputs.decimation": ("integer", "Publish every Nth sample; wrenches hold their peaks"),
    "outputs.diagnostics_period_s": ("double", "Diagnostics period in stamp time, s"),
    "outputs.tilt_warn_rad": ("double", "Tilt from vertical past which diagnostics warn, rad"),
    "outputs.alarm_margin": ("double", "A mount warns past utilisation 1 − alarm_margin"),
}
"""Every scene parameter the node declares: flat name → (ROS type, description)."""

COMMON_MOUNT_PARAMETERS: dict[str, tuple[str, str]] = {
    "kind": ("string", "Mount kind: linear, " + ", ".join(KINDS)),
    "position": ("double_array", "Attachment point [x, y, z], m, in F at the reference pose"),
    "orientation_rpy": ("double_array", "Mount axes relative to F, roll, pitch, yaw, rad"),
}
LINEAR_PARAMETERS: dict[str, tuple[str, str]] = {
    "stiffness": ("double_array", "[kx, ky, kz] N/m, [krx, kry, krz] N·m/rad, mount axes"),
    "damping": ("double_array", "[cx, cy, cz] N·s/m, [crx, cry, crz] N·m·s/rad, mount axes"),
    "rated_travel": ("double_array", "Allowed deflection [dx, dy, dz] m, mount axes (0: none)"),
    "rated_load": ("double_array", "Allowed force [Fx, Fy, Fz] N, mount axes (0: none)"),
}


def mount_parameters(kind: str) -> dict[str, tuple[str, str]]:
    """Parameters of a mount of `kind`, declared as mounts.<name>.<key> (unknown kinds get
    the common ones, so the loader can name the bad kind)."""
    own = LINEAR_PARAMETERS if kind == "linear" else getattr(KINDS.get(kind), "PARAMETERS", {})
    return {**COMMON_MOUNT_PARAMETERS, **own}


MOUNT_PARAMETERS = mount_parameters("linear")
"""Parameters of a linear mount."""


def parameter_description(name: str, effective: Mapping[str, Any]) -> str:
    """The description (with its unit) of a flat scene parameter, from the tables the loader is
    tested against; `effective` gives the mounts' kinds."""
    if name in PARAMETERS:
        return PARAMETERS[name][1]
    _, mount, key = name.split(".", 2)
    return mount_parameters(str(effective.get(f"mounts.{mount}.kind", "linear")))[key][1]


UNIT = re.compile(
    r"(?<![\w'/·])(?:1/)?(?:kg|rad|Hz|N|m|s)(?:[·/](?:kg|rad|Hz|N|m|s)|[²³ⁿᵖ])*(?![\w/·])"
)
"""An SI unit as the descriptions above write one: kg, m, N/m, N·m·s/rad, m/s², 1/mⁿ, Hz."""
NUMERIC_TYPES = ("double", "double_array", "integer")


def stated_unit(entry: tuple[str, str]) -> str | None:
    """The unit a parameter's (type, description) states: the one SI unit its description
    names, or None for no number (`outputs.angles`, a switch, names rad) or a description that
    names none (a ratio, a count) or several (a linear mount's stiffness, N/m along its axes
    and N·m/rad about them)."""
    units = set(UNIT.findall(entry[1])) if entry[0] in NUMERIC_TYPES else set()
    return units.pop() if len(units) == 1 else None


def flatten(tree: Mapping[str, Any], prefix: str = "") -> Iterator[tuple[str, Any]]:
    """Dotted (name, value) pairs of a nested mapping, as rcl reads a params YAML."""
    for key, value in tree.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            yield from flatten(value, f"{name}.")
        else:
            yield name, value


def parameter_types(flat: Mapping[str, Any]) -> dict[str, str]:
    """Every scene parameter a node can take for the mounts named in `flat` (their kinds read
    from `mounts.<name>.kind`, default linear): flat name → ROS type."""
    types = {name: ptype for name, (ptype, _) in PARAMETERS.items()}
    names = flat.get("mount_names", ())
    for mount in names if isinstance(names, (list, tuple)) else ():
        kind = flat.get(f"mounts.{mount}.kind", "linear")
        for key, (ptype, _) in mount_parameters(str(kind)).items():
            types[f"mounts.{mount}.{key}"] = ptype
    return types


def as_declared_types(flat: Mapping[str, Any]) -> dict[str, Any]:
    """`flat` with integers given for double (array) parameters taken as doubles, as a user
    means `body.mass: 1200` (rcl would refuse it; the scene loader then checks the rest)."""
    types = parameter_types(flat)
    out = dict(flat)
    for name, value in flat.items():
        ptype = types.get(name)
        if ptype == "double" and _is_int(value):
            out[name] = float(value)
        elif ptype == "double_array" and isinstance(value, (list, tuple)):
            out[name] = [float(v) if _is_int(v) else v for v in value]
    return out


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def scene_from_params(flat: Mapping[str, Any], source: str) -> Scene:
    """Validate a flat parameter set (dotted names → values) into a Scene.

    If `scene_file` is set and non-empty, the scene is that file's, with the other parameters
    given overriding its values (`effective_parameters`).
    """
    return effective_parameters(flat, source).scene


class Effective(NamedTuple):
    """A flat parameter set read: the Scene; every parameter value it uses, defaults included
    (what a node declares, so `ros2 param dump` shows the whole scene); and the closed
    interval [lo, hi] the loader checked each scalar number against (its declared range)."""

    scene: Scene
    values: dict[str, Any]
    bounds: dict[str, tuple[float, float]]


def effective_parameters(flat: Mapping[str, Any], source: str) -> Effective:
    """The Scene of a flat parameter set, the values it uses and their bounds (`Effective`).

    With `scene_file` set, the file is validated on its own first (errors name the file's key
    paths), then the other parameters override its values (errors name the parameter).
    """
    if not isinstance(flat, Mapping):
        raise SceneError(
            source, "", f"expected a mapping of parameter names to values, got {shown(flat)}"
        )
    scene_file = flat.get("scene_file", "")
    if not isinstance(scene_file, str):
        raise SceneError(source, "scene_file", f"expected a string, got {scene_file!r}")
    given = {k: v for k, v in flat.items() if k != "scene_file"}
    overrides = as_declared_types(given)  # what the file's values are overridden with
    if scene_file:
        from_file = load_scene_file(scene_file)
        source = f"{source} over {scene_file}" if given else str(scene_file)
        in_file = as_params(read_scene_yaml(from_file.source))
        if "mount_names" in given and list(given["mount_names"]) != in_file["mount_names"]:
            raise SceneError(
                source,
                "mount_names",
                f"{list(given['mount_names'])!r} differs from the mounts of scene_file "
                f"{in_file['mount_names']!r}: with a scene_file, parameters only override the "
                "values of its mounts",
            )
        given = {**in_file, **given}
    tree: dict[str, Any] = {}
    for name, value in as_declared_types(given).items():
        node = tree
        *parents, leaf = name.split(".")
        for part in parents:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise SceneError(source, name, f"{part!r} is both a value and a namespace")
        node[leaf] = value
    tree = _mounts_as_list(tree, source)
    names = [m["name"] for m in tree["mounts"]]
    used = Used()
    scene = scene_from_dict(
        tree,
        source,
        mount_paths=[f"mounts.{n}" for n in names],
        record=used,
        refuse_unheld=True,
        origin=SceneOrigin(os.path.abspath(scene_file), overrides) if scene_file else None,
    )
    types = parameter_types({**used.values, "mount_names": names})
    effective: dict[str, Any] = {"scene_file": str(scene_file), "mount_names": list(names)}
    for name, value in used.values.items():
        if types.get(name) == "string" and isinstance(value, (list, tuple)):
            effective[name] = " ".join(value)  # names (`Reader.names`): as a dump reloads
        elif name in types:
            effective[name] = list(value) if isinstance(value, tuple) else value
    bounds = {name: b for name, b in used.bounds.items() if name in types}
    return Effective(scene, as_declared_types(effective), bounds)


def as_params(tree: Mapping[str, Any]) -> dict[str, Any]:
    """A scene mapping (the layout of a scene YAML) as flat Nav2-style parameters."""
    flat = dict(flatten({k: v for k, v in tree.items() if k != "mounts"}))
    mounts = tree.get("mounts", [])
    flat["mount_names"] = [m["name"] for m in mounts]
    for m in mounts:
        rest = {k: v for k, v in m.items() if k != "name"}
        flat.update((f"mounts.{m['name']}.{k}", v) for k, v in flatten(rest))
    return flat


def _mounts_as_list(tree: dict[str, Any], source: str) -> dict[str, Any]:
    names = tree.pop("mount_names", None)
    if names is None:
        raise SceneError(
            source,
            "mount_names",
            "required parameter is missing (or give scene_file: a scene YAML, see "
            "config/params.yaml)",
        )
    if not isinstance(names, (list, tuple)) or not all(isinstance(n, str) for n in names):
        raise SceneError(source, "mount_names", f"expected a list of strings, got {names!r}")
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise SceneError(source, "mount_names", f"{twice[0]!r} listed twice")
    per_mount = tree.pop("mounts", {})
    if not isinstance(per_mount, dict):
        raise SceneError(source, "mounts", f"expected a namespace per mount, got {per_mount!r}")
    unknown = sorted(set(per_mount) - set(names))
    if unknown:
        raise SceneError(source, f"mounts.{unknown[0]}", "namespace not listed in mount_names")
    mounts = []
    for name in names:
        if name not in per_mount:
            raise SceneError(
                source, f"mounts.{name}", "mount listed in mount_names has no namespace"
            )
        if not isinstance(per_mount[name], dict):
            raise SceneError(
                source, f"mounts.{name}", f"expected its parameters, got {per_mount[name]!r}"
            )
        mounts.append({**per_mount[name], "name": name})
    tree["mounts"] = mounts
    return tree
