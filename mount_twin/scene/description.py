"""Plain, frozen description of a scene: a rigid body on compliant mounts.

Frames (see shared physics notes §1): the foundation frame F (REP-103, z up) and the body frame B
(origin at the centre of gravity, aligned with F at the reference pose). All positions given in a
scene are coordinates in F at the reference pose, in metres; angles are radians.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import Any

from mount_twin.kinds.bolted_joint import BoltedJoint
from mount_twin.kinds.elastomer import Elastomer
from mount_twin.kinds.shear_key import ShearKey

DOF_NAMES: tuple[str, ...] = ("x", "y", "z", "alpha", "gamma", "delta")
STANDARD_GRAVITY = 9.80665
"""m/s²: the unit of the checks scaled by g in a scene without gravity (`InputSpec.g_scale`)."""
GYRO_FILTERS = ("linear_phase", "none", "ignore")
"""`input.gyro_filter` choices (mount_twin.engine.gyro_filter applies them)."""
"""Generalized coordinates: CG displacement X, Y, Z (m, F) and the chart angles α, γ, δ (rad)."""

Vec3 = tuple[float, float, float]
Vec6 = tuple[float, float, float, float, float, float]


@dataclass(frozen=True)
class Body:
    """Rigid body.

    Attributes:
        mass: kg.
        cg: centre of gravity at the reference pose, m, in F.
        inertia: tensor elements about the CG in B, kg·m², ordered (Ixx, Iyy, Izz, Ixy, Ixz, Iyz)
            as in URDF (off-diagonal entries are the tensor's, i.e. minus the products of inertia).
    """

    mass: float
    cg: Vec3
    inertia: Vec6

    def inertia_tensor(self) -> tuple[Vec3, Vec3, Vec3]:
        """The 3×3 inertia tensor about the CG in B, kg·m², rows."""
        ixx, iyy, izz, ixy, ixz, iyz = self.inertia
        return ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz))


@dataclass(frozen=True)
class LinearMount:
    """Six-component Kelvin–Voigt mount (physics notes §7).

    Attributes:
        name: unique name; its frame id is frames.mount_prefix + name (`Frames.mount_frame`).
        position: attachment point, m, in F at the reference pose, where the body point and the
            foundation point coincide and the mount is unstressed.
        orientation_rpy: mount axes relative to F as fixed-axis roll, pitch, yaw, rad.
        stiffness: (kx, ky, kz) N/m and (krx, kry, krz) N·m/rad along the mount axes.
        damping: (cx, cy, cz) N·s/m and (crx, cry, crz) N·m·s/rad along the mount axes.
        rated_travel: (dx, dy, dz) m, the allowed deflection of the attachment point from its
            unstressed position along each mount axis (bottoming, tearing); 0: unrated axis.
        rated_load: (Fx, Fy, Fz) N, the allowed force along each mount axis; 0: unrated axis.
            Utilisation is the largest |deflection|/rated_travel and |force|/rated_load; its
            status is WARN from 1 − outputs.alarm_margin and ERROR past 1, as for other kinds.
    """

    name: str
    position: Vec3
    orientation_rpy: Vec3
    stiffness: Vec6
    damping: Vec6
    kind: str = "linear"
    rated_travel: Vec3 = (0.0, 0.0, 0.0)
    rated_load: Vec3 = (0.0, 0.0, 0.0)


Mount = LinearMount | Elastomer | BoltedJoint | ShearKey
"""Union of the mount kinds (mount_twin.kinds holds all but the linear one)."""


@dataclass(frozen=True)
class InputSpec:
    """Foundation motion input.

    Attributes:
        msg_type: 'sensor_msgs/msg/Imu' or 'geometry_msgs/msg/AccelStamped'.
        topic: input topic name.
        frame_id: expected header.frame_id; empty accepts any.
        sensor_rpy: rotation of the sensor frame into F as fixed-axis roll, pitch, yaw, rad.
        sensor_position: accelerometer position, m, in F.
        includes_gravity: True if the acceleration is specific force (Imu: +g up at rest).
        g: gravity magnitude, m/s², added along +z of F when includes_gravity is False; 0 is
            a scene without gravity (a test rig, a textbook case).
        hold: input between samples, 'first_order' (linear) or 'zero_order'.
        max_gap_s: a larger stamp gap is a gap, handled per gap_policy.
        gap_policy: 'reset' (restart at equilibrium) or 'bridge' (integrate across the gap).
        back_jump_reset_s: a stamp going back by more than this resets the twin (bag --loop);
            smaller steps back are skipped.
        gyro_filter: how Ω and Ω′ are taken from the gyro: 'linear_phase' (Ω low-passed
            and f delayed alike: outputs come N samples late), 'none' or 'ignore' (see
            mount_twin.engine.gyro_filter).
        gyro_passband_hz: the 'linear_phase' filter is flat (to 4e-5) up to this, Hz.
        gyro_stopband_hz: ... and attenuates (to 4e-5) from this on, Hz; the transition sets
            the delay: about 3.0 / (stopband − passband) s (38 ms by default).
        accel_range_m_s2, gyro_range_rad_s: the sensor's full scale (0: unknown); a reading at
            it is counted as saturated (clipped: the true peak was higher).
    """

    msg_type: str = "sensor_msgs/msg/Imu"
    topic: str = "/imu/data"
    frame_id: str = ""
    sensor_rpy: Vec3 = (0.0, 0.0, 0.0)
    sensor_position: Vec3 = (0.0, 0.0, 0.0)
    includes_gravity: bool = True
    g: float = 9.80665
    hold: str = "first_order"
    max_gap_s: float = 0.5
    gap_policy: str = "reset"
    back_jump_reset_s: float = 1.0
    gyro_filter: str = "linear_phase"
    gyro_passband_hz: float = 20.0
    gyro_stopband_hz: float = 100.0
    accel_range_m_s2: float = 0.0
    gyro_range_rad_s: float = 0.0

    @property
    def reads_rate(self) -> bool:
        """Whether the twin reads the gyro (Ω and Ω′ from it): every `gyro_filter` but
        'ignore', which neglects the foundation's rotation (Ω = 0)."""
        return self.gyro_filter != "ignore"

    @property
    def g_scale(self) -> float:
        """The acceleration (m/s²) the checks scaled by g take as their unit: g, or standard
        gravity in a scene without gravity (a start check then asks for |f₀| within the
        tolerance of 0 in units of STANDARD_GRAVITY)."""
        return self.g if self.g > 0.0 else STANDARD_GRAVITY


@dataclass(frozen=True)
class InitialState:
    """Start of a run.

    Attributes:
        mode: 'equilibrium' (static equilibrium under gravity) or 'given' (pose and velocity).
        gravity: for 'equilibrium', 'first_sample' (the first measured specific force) or
            'nominal' (g along +z of F).
        pose: (X, Y, Z) m and (α, γ, δ) rad, for 'given'; also the values of frozen DOFs.
        velocity: (X', Y', Z') m/s and (α', γ', δ') rad/s, for 'given'.
        gravity_samples, gravity_window_s: for 'first_sample', the start gravity is the mean
            specific force of `gravity_samples` accepted samples from each (re)start, the twin
            starting at the last of them (those before it are taken but not integrated), and
            of the samples within `gravity_window_s` (s) after that one; of their leading
            samples at rest only (`engine.starts.at_rest`: a shock among them ends them). The
            default window, 0.05 s, averages a real sensor's noise (the 20 kHz water-entry
            record at rest: the start tilt 0.067 rad rms off from one sample, 0.0047 rad from
            50 ms, bench/start_gravity.py), is short beside a ship's motions and comparable
            with the gyro filter's 38 ms delay.
        gravity_tolerance: start check: | |f₀| − g | / g past this is a WARN, past three times
            this an ERROR (a start on a shock, free fall, a bias, g added twice), −; at g = 0
            the unit is standard gravity (`InputSpec.g_scale`).
        tilt_tolerance_rad: start check: the angle of f₀ from +z of F past this is a WARN,
            past three times this an ERROR (a sensor frame turned wrong), rad; not checked at
            g = 0 (no direction to expect).
    """

    mode: str = "equilibrium"
    gravity: str = "first_sample"
    pose: Vec6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    velocity: Vec6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    gravity_samples: int = 1
    gravity_window_s: float = 0.05
    gravity_tolerance: float = 0.1
    tilt_tolerance_rad: float = 0.35


RTOL_RANGE = (1.0e-13, 0.1)
"""The relative tolerances a stepper is given (integration.rtol, `accuracy --rtol`): tighter
is round-off, looser no error control."""


@dataclass(frozen=True)
class Integration:
    """Stepper settings: method name (or "auto", see `integrate.methods.choose`), relative and
    absolute tolerance (atol in the state's units: m, rad, m/s, rad/s), substep limit per
    sample, and whether the error is estimated live (`engine.estimator`)."""

    method: str = "auto"
    rtol: float = 1.0e-6
    atol: float = 1.0e-9
    max_substeps: int = 10000
    error_estimate: bool = True


@dataclass(frozen=True)
class Outputs:
    """What is published.

    Attributes:
        pose, angles, wrenches: publish PoseStamped, α/γ/δ Vector3Stamped, per-mount WrenchStamped.
        tf: publish the body pose on /tf (tf2_msgs/TFMessage: frames.foundation → frames.body,
            the CG position in m and the body attitude, the numbers of the PoseStamped).
        decimation: publish every Nth accepted input sample; wrench components hold their peak
            (largest magnitude, with sign) over the interval. A run's last sample is published
            at its end (a restart, the stream's end) with the peaks since the row before.
        diagnostics_period_s: stamp-time period of DiagnosticArray messages, s.
        tilt_warn_rad: tilt of body z from vertical past which diagnostics warn.
        alarm_margin: a mount warns once its utilisation passes 1 − alarm_margin.
    """

    pose: bool = True
    angles: bool = True
    wrenches: bool = True
    tf: bool = True
    decimation: int = 1
    diagnostics_period_s: float = 1.0
    tilt_warn_rad: float = 1.3089969389957472  # 75°
    alarm_margin: float = 0.1


@dataclass(frozen=True)
class Frames:
    """Frame ids written into output headers and transforms.

    Attributes:
        foundation: the foundation frame F (parent of every transform published).
        body: the body frame B, origin at the CG (child of F on /tf).
        mount_prefix: a mount's frame is mount_prefix + its name (`mount_frame`): the
            header.frame_id of its WrenchStamped and the child of F on /tf_static (origin at the
            mount's position, axes its orientation_rpy), e.g. "pump/" gives "pump/fl".
    """

    foundation: str = "foundation"
    body: str = "body"
    mount_prefix: str = ""

    def mount_frame(self, mount_name: str) -> str:
        """Frame id of the mount named `mount_name`: mount_prefix + mount_name."""
        return self.mount_prefix + mount_name


SENSOR_AXES = ("fx", "fy", "fz", "wx", "wy", "wz")
"""An IMU's axes as the body sensor comparison names them: specific force along x, y, z (m/s²),
then rate about them (rad/s), in the sensor's axes."""


@dataclass(frozen=True)
class BodySensor:
    """An IMU on the machine's body: what shows what the body really did (`calibrate`).

    Attributes:
        topic: its topic (sensor_msgs/Imu).
        frame_id: its header.frame_id ("": any).
        position: its position at the reference pose, m, in F (as the mounts' are).
        orientation_rpy: its axes relative to the body frame B, fixed-axis roll, pitch, yaw,
            rad (B is parallel to F at the reference pose).
        lag_s: its stamps behind the foundation IMU's, s: a sample stamped t measured the
            motion at t − lag_s (the recorders' or drivers' latency; `calibrate` fits it).
        window_s: the live comparison's window, s: its agreement is judged window by window.
        band_hz: (low, high) Hz, the band the comparison is judged in (the mounting's modes
            and below, `mount-twin modes`); the broadband figure is reported beside it.
        warn_nrms, error_nrms: normalised RMS error (‖pred − meas‖ / ‖meas‖ in the band, per
            axis, means out) past which the comparison WARNs, ERRORs.
        axes: the sensor axes judged (`SENSOR_AXES`; a scene that models fewer DOFs than the
            machine moves in judges those it models).
    """

    topic: str = "/machine/imu"
    frame_id: str = ""
    position: Vec3 = (0.0, 0.0, 0.0)
    orientation_rpy: Vec3 = (0.0, 0.0, 0.0)
    lag_s: float = 0.0
    window_s: float = 10.0
    band_hz: tuple[float, float] = (0.0, 10.0)
    warn_nrms: float = 0.3
    error_nrms: float = 0.6
    axes: tuple[str, ...] = SENSOR_AXES


def ageing_bands_problem(warn: tuple[float, float], error: tuple[float, float]) -> str | None:
    """What is wrong with an ageing judgement's bands of scale factors (low, high), or None:
    each must have 0 ≤ low < high, and `error` must hold `warn`."""
    for name, (low, high) in (("warn", warn), ("error", error)):
        if not 0.0 <= low < high:
            return f"{name} band [{low:g}, {high:g}]: expected 0 ≤ low < high"
    if not (error[0] <= warn[0] and warn[1] <= error[1]):
        return f"{list(error)} must hold the warn band {list(warn)}"
    return None


@dataclass(frozen=True)
class Ageing:
    """Live tracking of mounts that age: the calibration re-fitted window by window on the
    deck and body IMUs (`analysis.ageing`), each window judged against a band.

    Attributes:
        window_s: each fit's window of body stamps, s (after a 2 s lead that settles the twin).
        fit: the scales re-fitted: stiffness, damping (all linear mounts), or stiffness:A+B
            (damping:…) for a group or one mount.
        warn, error: (low, high) scale factors on the scene's values: a scale whose 3σ
            interval lies wholly outside `warn` is a WARN, outside `error` an ERROR.
    """

    window_s: float = 60.0
    fit: tuple[str, ...] = ("stiffness", "damping")
    warn: tuple[float, float] = (0.85, 1.15)
    error: tuple[float, float] = (0.75, 1.25)


@dataclass(frozen=True)
class SceneWarning:
    """A scene value that loads but is likely a mistake (units, a message type's convention),
    found at load and kept on the Scene for the command or node to report.

    Attributes:
        source: file or parameter set, as in SceneError.
        path: key path of the value.
        message: what is implausible and the likely mistake.
    """

    source: str
    path: str
    message: str

    def __str__(self) -> str:
        return f"{self.source}: {self.path}: {self.message}"


@dataclass(frozen=True)
class SceneOrigin:
    """Where a scene came from, as separate fields (a replay records them in its output bag,
    the node publishes them on ~/scene: `io.scene_record`).

    Attributes:
        file: the scene file's absolute path; None: no file (a parameter set alone, a scene
            built in code).
        overrides: what was put over the file's values, by flat parameter name
            (`input.topic`: `replay --topic`, `--frame-id`; the node's parameters given beside
            `scene_file`); empty without a file.
        value: the value the file and `overrides` built (`scene_value`; the loader sets it),
            which a scene changed since in code (`dataclasses.replace`, which keeps `origin`)
            differs from: a record of it names those changes too (`io.scene_record`); None
            without a file.
    """

    file: str | None = None
    overrides: Mapping[str, Any] = field(default_factory=dict)
    value: Mapping[str, Any] | None = field(default=None, repr=False)  # a few kB of JSON


@dataclass(frozen=True)
class Scene:
    """A complete scene; `source` names the file or parameter set it came from (a text for
    messages; `origin` the same as fields), `warnings` what the loader found implausible in it,
    and the assembly at its start (`model.ratings`), and `mount_paths` the key path of each
    mount in messages, as the loader named them (none of these is part of its value: two
    scenes that differ only in them are equal)."""

    name: str
    body: Body
    mounts: tuple[Mount, ...]
    dofs: tuple[str, ...] = DOF_NAMES
    input: InputSpec = field(default_factory=InputSpec)
    initial: InitialState = field(default_factory=InitialState)
    integration: Integration = field(default_factory=Integration)
    outputs: Outputs = field(default_factory=Outputs)
    frames: Frames = field(default_factory=Frames)
    body_sensor: BodySensor | None = None
    ageing: Ageing | None = None
    source: str = "<memory>"
    warnings: tuple[SceneWarning, ...] = field(default=(), compare=False)
    mount_paths: tuple[str, ...] = field(default=(), compare=False)
    origin: SceneOrigin = field(default_factory=SceneOrigin, compare=False)

    def mount_path(self, i: int) -> str:
        """Key path of mount i in messages: as its loader named it (mounts.<name> in a
        parameter set), else mounts[i]."""
        if len(self.mount_paths) == len(self.mounts):
            return self.mount_paths[i]
        return f"mounts[{i}]"


NOT_THE_VALUE = ("source", "warnings", "mount_paths", "origin")
"""Fields of a Scene that are not part of its value (`Scene`): left out of its digest."""


def scene_digest(scene: Scene) -> str:
    """sha256 (hex) of the scene's value: every field two scenes are compared by but the file
    it came from (`source`), as sorted JSON (floats as Python writes them back exactly). Two
    files that set the same values (however commented, ordered, or with defaults written out)
    give the same digest; one value changed, another. The node publishes it on ~/scene and a
    replay records it in its output bag (`io.scene_record`), for `report --scene` to check its
    scene against."""
    return value_digest(scene_value(scene))


def value_digest(value: Mapping[str, Any]) -> str:
    """sha256 (hex) of a scene's value (`scene_value`, or the same read back from JSON: the
    text hashed is the same), as `scene_digest` gives it: of its `value_text`."""
    return hashlib.sha256(value_text(value).encode()).hexdigest()


def value_text(value: Mapping[str, Any]) -> str:
    """A scene's value as the text `value_digest` hashes: JSON, keys sorted, no spaces."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"))


def scene_value(scene: Scene) -> dict[str, Any]:
    """The scene's value as `scene_digest` hashes it: its fields (nested dataclasses as dicts)
    but those `NOT_THE_VALUE`."""
    return {k: v for k, v in asdict(scene).items() if k not in NOT_THE_VALUE}


def value_differences(here: Any, there: Any, path: str = "") -> list[tuple[str, Any, Any]]:
    """Where two values (dicts, lists or tuples of them, leaves) differ: (key path, value
    here, value there) of each differing leaf, in `here`'s key order (then `there`'s extra
    keys), a dict's key as `.key`, an item as `[i]`. A key one lacks is `None` on that side;
    sequences of unequal length, or values of another shape, differ as a whole at `path`."""
    if isinstance(here, dict) and isinstance(there, dict):
        keys = [*here, *(k for k in there if k not in here)]
        return [
            d
            for k in keys
            for d in value_differences(here.get(k), there.get(k), f"{path}.{k}" if path else k)
        ]
    sequences = (list, tuple)
    if isinstance(here, sequences) and isinstance(there, sequences) and len(here) == len(there):
        return [
            d
            for i, (a, b) in enumerate(zip(here, there, strict=True))
            for d in value_differences(a, b, f"{path}[{i}]")
        ]
    return [] if here == there else [(path, here, there)]


def scene_differences(here: Scene, there: Scene | Mapping[str, Any]) -> list[tuple[str, Any, Any]]:
    """`value_differences` of two scenes' values (`scene_value`; `there` may be a value as
    read back from JSON, its tuples lists), a mount's key path as `here` names it
    (`Scene.mount_path`: `mounts.<name>` in a parameter set)."""
    value = scene_value(there) if isinstance(there, Scene) else there
    found = value_differences(scene_value(here), value)
    return [(_named(here, path), a, b) for path, a, b in found]


def _named(scene: Scene, path: str) -> str:
    """`path` with a mount's `mounts[i]` as the scene names it (`Scene.mount_path`)."""
    head, sep, rest = path.partition("]")
    if head.startswith("mounts[") and sep:
        return scene.mount_path(int(head.removeprefix("mounts["))) + rest
    return path
