"""Build a validated `Scene` from a nested mapping (a scene YAML file or ROS parameters).

A file's YAML is read in `scene.yaml_reading`; the ROS names a scene gives (mount names, topics,
frame ids) are read by the rules of `scene.ros_names`, positions and angles within the ranges of
`scene.geometry_reading`. Each mount is read by `scene.mount_reading`, the optional body IMU
sections (`body_sensor`, `ageing`) by `scene.body_imu_reading`; the other sections are read here.
"""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path
from typing import Any

from mount_twin.errors import SceneError
from mount_twin.integrate.methods import AUTO, METHODS
from mount_twin.scene.body_imu_reading import read_ageing, read_body_sensor
from mount_twin.scene.checks import check_scene
from mount_twin.scene.description import (
    DOF_NAMES,
    GYRO_FILTERS,
    RTOL_RANGE,
    Body,
    Frames,
    InitialState,
    InputSpec,
    Integration,
    Outputs,
    Scene,
    SceneOrigin,
    scene_value,
)
from mount_twin.scene.geometry_reading import read_angles, read_pose, read_position
from mount_twin.scene.mount_reading import read_mount
from mount_twin.scene.reader import Reader, Used, shown
from mount_twin.scene.ros_names import read_frame_id, read_header_frame_id, read_topic
from mount_twin.scene.yaml_reading import read_scene_yaml

INPUT_TYPES = ("sensor_msgs/msg/Imu", "geometry_msgs/msg/AccelStamped")
START_TILT_MAX_RAD = 1.55
"""Largest tilt θ of a given start pose, rad (88.8°): the chart degenerates at π/2."""

MAX_MOUNTS = 1000
"""Most mounts a scene takes (a machine has a few dozen; more is generated garbage)."""
STEPPERS = (AUTO, *METHODS)


def load_scene_file(path: str | Path) -> Scene:
    """Read and validate a scene YAML file; errors name the file and key path, and what looks
    mistaken is in the Scene's `warnings`; its `origin` is the file's absolute path."""
    origin = SceneOrigin(os.path.abspath(path))
    return scene_from_dict(read_scene_yaml(path), str(path), refuse_unheld=True, origin=origin)


def scene_from_dict(
    data: Any,
    source: str,
    *,
    mount_paths: list[str] | None = None,
    record: Used | None = None,
    refuse_unheld: bool = False,
    origin: SceneOrigin | None = None,
) -> Scene:
    """Validate a scene mapping (the layout of config/*.scene.yaml), then the scene as a whole
    (`mount_twin.scene.checks`): what cannot work is a SceneError, what looks mistaken is in
    the returned Scene's `warnings`.

    Args:
        data: the mapping.
        source: file or parameter set, named in errors.
        mount_paths: key path of each mount in errors (default mounts[i]).
        record: if given, receives every value used (given or defaulted) and the bounds each
            number was checked against, by key path.
        refuse_unheld: a free DOF no mount holds is a SceneError (for a start at equilibrium)
            instead of a warning: what scene files and parameter sets get. Off for scenes built
            in code, such as tests of a single mount's law.
        origin: where it came from, as fields (default: no file, nothing put over it); with a
            file, its `value` is set to the scene's.
    """
    refuse_parameters_file(data, source)
    top = Reader(data, source, record=record)
    body = _body(top.sub("body", optional=False))
    dofs = _dofs(top)
    mounts_raw = top.raw("mounts")
    if not isinstance(mounts_raw, list) or not mounts_raw:
        raise top.error("mounts", f"expected a non-empty list of mounts, got {shown(mounts_raw)}")
    if len(mounts_raw) > MAX_MOUNTS:
        raise top.error("mounts", f"{len(mounts_raw)} mounts: at most {MAX_MOUNTS} are accepted")
    paths = mount_paths or [f"mounts[{i}]" for i in range(len(mounts_raw))]
    mounts = tuple(
        read_mount(Reader(m, source, path, record=record))
        for path, m in zip(paths, mounts_raw, strict=True)
    )
    names = [m.name for m in mounts]
    for i, name in enumerate(names):
        if names.index(name) != i:
            raise SceneError(source, f"{paths[i]}.name", f"duplicate mount name {shown(name)}")
    scene = Scene(
        name=top.string("name", "scene"),
        body=body,
        mounts=mounts,
        dofs=dofs,
        input=_input(top.sub("input")),
        initial=_initial(top.sub("initial_state"), dofs),
        integration=_integration(top.sub("integration")),
        outputs=_outputs(top.sub("outputs")),
        frames=_frames(top.sub("frames")),
        body_sensor=read_body_sensor(top.sub("body_sensor")) if top.has("body_sensor") else None,
        ageing=read_ageing(top.sub("ageing"), mounts) if top.has("ageing") else None,
        source=source,
    )
    top.finish()
    warnings = check_scene(scene, paths, refuse_unheld=refuse_unheld)
    if origin is not None and origin.file is not None:  # what changes made in code differ from
        origin = dataclasses.replace(origin, value=scene_value(scene))
    return dataclasses.replace(
        scene, warnings=warnings, mount_paths=tuple(paths), origin=origin or SceneOrigin()
    )


def refuse_parameters_file(data: Any, source: str) -> None:
    """Raise SceneError where `data` is a ROS 2 parameters file (`NODE: ros__parameters: …`,
    the node's --params-file), not a scene: read as one it failed on its first key, `body:
    required key is missing`, which its `body` under `ros__parameters` contradicts."""
    if not isinstance(data, dict):
        return
    for node, section in data.items():
        if isinstance(section, dict) and "ros__parameters" in section:
            msg = (
                f"a ROS 2 parameters file ({node}: ros__parameters), which the node reads "
                "(--ros-args --params-file), not a scene file: give a scene YAML such as "
                "config/pump_8_mounts.scene.yaml, which the node also reads (-p scene_file:=PATH)"
            )
            raise SceneError(source, "", msg)


def _body(r: Reader) -> Body:
    mass = r.positive("mass")
    cg = read_position(r, "cg")
    inertia = r.vector("inertia", 6)
    ixx, iyy, izz, ixy, ixz, iyz = inertia
    tensor = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]
    if not _is_positive_definite(tensor):
        raise r.error("inertia", f"tensor is not positive definite: {list(inertia)}")
    if ixx + iyy < izz or iyy + izz < ixx or izz + ixx < iyy:
        raise r.error("inertia", f"violates the triangle inequality of a rigid body: {inertia!r}")
    r.finish()
    return Body(mass=mass, cg=cg, inertia=inertia)


def _is_positive_definite(a: list[list[float]]) -> bool:
    # Sylvester's criterion on the 3×3 leading minors.
    m1 = a[0][0]
    m2 = a[0][0] * a[1][1] - a[0][1] * a[1][0]
    m3 = (
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    )
    return m1 > 0.0 and m2 > 0.0 and m3 > 0.0


def _dofs(top: Reader) -> tuple[str, ...]:
    dofs = top.names("dofs", DOF_NAMES)
    for i, d in enumerate(dofs):
        if d not in DOF_NAMES:
            raise top.error(
                f"dofs[{i}]", f"unknown DOF {shown(d)}; choose from {', '.join(DOF_NAMES)}"
            )
        if dofs.index(d) != i:
            raise top.error(f"dofs[{i}]", f"DOF {d!r} listed twice")
    if not dofs:
        raise top.error("dofs", "at least one DOF must be free")
    return tuple(d for d in DOF_NAMES if d in dofs)


def _input(r: Reader) -> InputSpec:
    d = InputSpec()
    spec = InputSpec(
        msg_type=r.choice("msg_type", INPUT_TYPES, d.msg_type),
        topic=read_topic(r, "topic", d.topic),
        frame_id=read_header_frame_id(r, "frame_id", d.frame_id),
        sensor_rpy=read_angles(r, "sensor_rpy", d.sensor_rpy),
        sensor_position=read_position(r, "sensor_position", d.sensor_position),
        includes_gravity=r.boolean("includes_gravity", d.includes_gravity),
        g=r.number("g", d.g, lo=0.0),
        hold=r.choice("hold", ("first_order", "zero_order"), d.hold),
        max_gap_s=r.positive("max_gap_s", d.max_gap_s),
        gap_policy=r.choice("gap_policy", ("reset", "bridge"), d.gap_policy),
        back_jump_reset_s=r.number("back_jump_reset_s", d.back_jump_reset_s, lo=0.0),
        gyro_filter=_gyro_filter(r, d.gyro_filter),
        gyro_passband_hz=r.positive("gyro_passband_hz", d.gyro_passband_hz),
        gyro_stopband_hz=r.positive("gyro_stopband_hz", d.gyro_stopband_hz),
        accel_range_m_s2=r.number("accel_range_m_s2", d.accel_range_m_s2, lo=0.0),
        gyro_range_rad_s=r.number("gyro_range_rad_s", d.gyro_range_rad_s, lo=0.0),
    )
    if spec.gyro_stopband_hz <= spec.gyro_passband_hz:
        raise r.error(
            "gyro_stopband_hz",
            f"{spec.gyro_stopband_hz:g} Hz is not above gyro_passband_hz "
            f"({spec.gyro_passband_hz:g} Hz)",
        )
    r.finish()
    return spec


REMOVED_LOWPASS = (
    "was removed: it delayed Ω but not the specific force (5-40 % of the mount force on a "
    "1-20 Hz rolling deck); the default 'linear_phase' filters Ω and delays f alike (set its "
    "band with gyro_passband_hz, gyro_stopband_hz), 'none' takes the gyro raw, without latency"
)


def _gyro_filter(r: Reader, default: str) -> str:
    """input.gyro_filter, with the removed 'lowpass' (and its gyro_cutoff_hz) named."""
    if r.has("gyro_cutoff_hz"):
        raise r.error("gyro_cutoff_hz", f"(of gyro_filter 'lowpass') {REMOVED_LOWPASS}")
    if r.raw("gyro_filter", default) == "lowpass":
        raise r.error("gyro_filter", f"'lowpass' {REMOVED_LOWPASS}")
    return r.choice("gyro_filter", GYRO_FILTERS, default)


def _refuse_unread_start(r: Reader, state: InitialState, dofs: tuple[str, ...]) -> None:
    """An equilibrium start is at rest and finds the free DOFs itself: a velocity, or a pose
    entry of a free DOF, given with it would be ignored without a word."""
    if any(state.velocity):
        raise r.error(
            "velocity",
            f"{list(state.velocity)}: read only with mode: given (an equilibrium start is at "
            "rest)",
        )
    for name, value in zip(DOF_NAMES, state.pose, strict=True):
        if name in dofs and value:
            raise r.error(
                "pose",
                f"{name} = {value!r} of a free DOF: read only with mode: given (an "
                "equilibrium start finds the free DOFs; pose holds the frozen DOFs' values)",
            )


def _initial(r: Reader, dofs: tuple[str, ...]) -> InitialState:
    d = InitialState()
    state = InitialState(
        mode=r.choice("mode", ("equilibrium", "given"), d.mode),
        gravity=r.choice("gravity", ("first_sample", "nominal"), d.gravity),
        pose=read_pose(r, "pose", d.pose),
        velocity=r.vector("velocity", 6, d.velocity),
        gravity_samples=r.integer("gravity_samples", d.gravity_samples, lo=1),
        gravity_window_s=r.number("gravity_window_s", d.gravity_window_s, lo=0.0),
        gravity_tolerance=r.number(
            "gravity_tolerance", d.gravity_tolerance, lo=0.0, hi=1.0, lo_open=True
        ),
        tilt_tolerance_rad=r.number(
            "tilt_tolerance_rad", d.tilt_tolerance_rad, lo=0.0, hi=math.pi / 2, lo_open=True
        ),
    )
    if state.mode == "equilibrium":
        _refuse_unread_start(r, state, dofs)
    alpha, gamma = state.pose[3], state.pose[4]
    cos_tilt = math.sqrt(max(math.cos(gamma) ** 2 - math.sin(alpha) ** 2, 0.0))
    if not (math.cos(gamma) > 0.0 and cos_tilt > math.cos(START_TILT_MAX_RAD)):
        raise r.error(
            "pose",
            f"α = {alpha!r}, γ = {gamma!r} rad tilt the body past {START_TILT_MAX_RAD} rad, "
            "where the α/γ/δ chart degenerates (it needs |α| + |γ| < π/2 with a margin)",
        )
    r.finish()
    return state


def _integration(r: Reader) -> Integration:
    d = Integration()
    spec = Integration(
        method=r.choice("method", STEPPERS, d.method),
        rtol=r.number("rtol", d.rtol, lo=RTOL_RANGE[0], hi=RTOL_RANGE[1]),
        atol=r.positive("atol", d.atol),
        max_substeps=r.integer("max_substeps", d.max_substeps, lo=1),
        error_estimate=r.boolean("error_estimate", d.error_estimate),
    )
    r.finish()
    return spec


def _outputs(r: Reader) -> Outputs:
    d = Outputs()
    spec = Outputs(
        pose=r.boolean("pose", d.pose),
        angles=r.boolean("angles", d.angles),
        wrenches=r.boolean("wrenches", d.wrenches),
        tf=r.boolean("tf", d.tf),
        decimation=r.integer("decimation", d.decimation, lo=1),
        diagnostics_period_s=r.positive("diagnostics_period_s", d.diagnostics_period_s),
        tilt_warn_rad=r.number("tilt_warn_rad", d.tilt_warn_rad, lo=0.0, hi=math.pi / 2),
        alarm_margin=r.number("alarm_margin", d.alarm_margin, lo=0.0, hi=1.0),
    )
    r.finish()
    return spec


def _frames(r: Reader) -> Frames:
    d = Frames()
    frames = Frames(
        foundation=read_frame_id(r, "foundation", d.foundation),
        body=read_frame_id(r, "body", d.body),
        mount_prefix=read_frame_id(r, "mount_prefix", d.mount_prefix, empty_ok=True),
    )
    r.finish()
    return frames
