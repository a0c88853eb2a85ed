"""Calibrate a scene on a recorded pair: the foundation's IMU in, the body's IMU out.

The twin is the model: it runs on the foundation record, predicts what the body sensor reads
(`engine.sensor_reading`), and `scipy.optimize.least_squares` moves the parameters a user cannot
read off a data sheet until the prediction matches the body record, in the time domain (the
twin's non-linear mounts and the recorders' clocks live there; a lag is a phase that grows
with frequency, which a time-domain fit takes as one number; the parameters and the scene
their values make: `analysis.calibration_parameters`):

- `stiffness`, `damping`: one scale factor each on every linear mount's stiffness and damping
  (fitted as logarithms: a scale stays positive); `stiffness:fl+fr` (or `damping:…`) scales
  only the mounts it names, so that groups (or single mounts) are fitted apart;
- `yaw`: the body sensor's rotation about the body's z axis, added to its orientation_rpy, rad;
  `roll` and `pitch` (on request) likewise;
- `sensor_x`, `sensor_y`, `sensor_z` (on request): the body sensor's position, m in F, added
  to body_sensor.position (seen through the rotation's terms α × r and ω × (ω × r): a body
  that barely turns leaves them refused);
- `mass` (on request): a scale factor on the body's mass and inertia (a uniformly heavier
  body); with `stiffness` and `damping` beside it the three are one ratio to the body IMU
  (scaling all three moves nothing it reads), so they are refused together: fit it with the
  mounts held;
- `cg_x`, `cg_y`, `cg_z` (on request): the CG's offset, m in F, added to body.cg;
- `lag`: the body recorder's clock behind the foundation's, s (its samples are the motion
  `lag` seconds before their stamps), added to the scene's body_sensor.lag_s.

Both signals are compared with their means taken out (gravity and the sensors' biases), each
axis in units of the measured signal's spread. Each parameter's uncertainty (1σ) comes from the
fit's Jacobian and residual (`(JᵀJ)⁻¹ s²`; the residual's own correlation makes it a lower
bound). A parameter the record cannot identify (relative 1σ past `MAX_REL_SIGMA`, an angle
past 2°, a lag past a sample) is refused by name and held at its nominal value, and the rest is
fitted again; a fit that predicts the body no better than the nominal scene is refused whole.
A record that does not move (`calibration_records.still_record`: a foundation's still deck, the
wrong topic or a record taken in harbour; a body's dead or disconnected sensor, another
machine's record) leaves nothing to fit: every parameter is refused, saying so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mount_twin.analysis.calibration_parameters import (
    ANGLES,
    CG_OFFSETS,
    MOUNT_SCALES,
    OFFSETS,
    ON_REQUEST,
    PARAMETERS,
    calibrated_scene,
    is_mount_scale,
    is_scale,
    scaled_mounts,
)
from mount_twin.analysis.calibration_records import compared, overlap_problem, still_record
from mount_twin.analysis.response import followed
from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.reading_screen import rotated
from mount_twin.engine.sensor_reading import SensorGeometry, predicted_reading
from mount_twin.io.signals import Signal
from mount_twin.physics.rotations import angle_text
from mount_twin.scene.description import BodySensor, Scene

MAX_POSITION_SIGMA_M = 0.01
"""A sensor position offset whose 1σ exceeds this (m) is not identified by the record."""
STIFFNESS_SCAN = tuple(np.geomspace(0.25, 4.0, 17).tolist())
"""Common factors on the mount stiffness scales tried before the local fit (`_start`): a
lightly damped mode moved past its own bandwidth matches the body no better either way, so the
misfit has a minimum at every few per cent of stiffness, and a fit from the nominal settled in
the nearest (0.84× ± 0.5 % on 12 s of the shake table, whose block is 1.23× as stiff)."""
MAX_REL_SIGMA = 0.05
"""A scale factor whose relative 1σ exceeds this is not identified by the record."""
MAX_YAW_SIGMA_RAD = math.radians(2.0)
NRMS_RESOLUTION = 1e-9
"""`nrms` of a measured signal whose spread about its mean is at most this share of its size
is undefined (nan): what is left after the mean is out is rounding, not motion."""


@dataclass(frozen=True)
class Calibration:
    """A fit's result.

    Attributes:
        values: parameter → value (stiffness and damping as scale factors, yaw rad, lag s);
            a refused parameter keeps its nominal value (1, 1, 0, 0).
        sigma: parameter → 1σ of the fitted ones, in the value's unit.
        refused: parameter → why the record cannot identify it.
        nrms_before, nrms_after: the body sensor's normalised RMS error (‖pred − meas‖ /
            ‖meas‖, means out, all axes) with the nominal scene and the calibrated one; nan
            where a record does not move (`still_record`: nothing is fitted).
        scene: the calibrated scene.
    """

    values: dict[str, float]
    sigma: dict[str, float]
    refused: dict[str, str]
    nrms_before: float
    nrms_after: float
    scene: Scene


def predict(scene: Scene, foundation: Signal) -> tuple[np.ndarray, np.ndarray]:
    """(stamps s, (k, 3) specific force m/s² in the body sensor's axes) of the scene's twin
    run on the foundation record. Raises ValueError where its integration failed."""
    frames = [scene.input.frame_id] * foundation.t.shape[0]  # the scene's input, all of it
    batch = SampleBatch(foundation.t, foundation.accel, foundation.gyro, frames)
    model, out = followed(scene, batch, "the foundation record")
    rate = np.zeros((len(out), 3))  # the foundation's Ω at the rows, rad/s in F
    if scene.input.reads_rate:
        gyro = np.stack([np.interp(out.stamps, foundation.t, w) for w in foundation.gyro.T], 1)
        rate = rotated(gyro, model.sensor_rotation)
    sensor = scene.body_sensor or BodySensor()
    pose = (out.position, out.quaternion)
    f, _ = predicted_reading(
        SensorGeometry.of(scene, sensor), out.stamps, pose, out.wrenches, rate
    )
    return out.stamps, f


def _at(stamps: np.ndarray, values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(k, 3) values at t, by cubic interpolation of their (stamps, values)."""
    from scipy.interpolate import CubicSpline

    return CubicSpline(stamps, values, axis=0)(t)


def nrms(predicted: np.ndarray, measured: np.ndarray) -> float:
    """‖p − m‖ / ‖m‖ with each axis' mean taken out of both; nan where the measured signal
    does not vary (‖m‖ at most `NRMS_RESOLUTION` of its size: a ratio to rounding)."""
    p = predicted - predicted.mean(axis=0)
    m = measured - measured.mean(axis=0)
    spread = float(np.linalg.norm(m))
    if not spread > NRMS_RESOLUTION * float(np.linalg.norm(measured)):
        return math.nan
    return float(np.linalg.norm(p - m) / spread)


def prediction_error(
    scene: Scene,
    records: tuple[Signal, Signal],
    axes: slice = slice(None),
    below_hz: float | None = None,
) -> float:
    """The body sensor's NRMS error (`nrms`) of the scene's twin on a (foundation, body) pair
    of records (the body recorder body_sensor.lag_s late): over its `axes`, and with both
    signals low-passed below `below_hz` (4th-order Butterworth, zero phase) where given."""
    problem = _Problem(scene, records[0], records[1], [])
    predicted = problem.predicted({})[:, axes]
    measured = problem.measured[:, axes]
    if below_hz is not None:
        from scipy.signal import butter, sosfiltfilt

        rate = 1.0 / float(np.median(np.diff(problem.t)))
        sos = butter(4, below_hz, fs=rate, output="sos")
        predicted, measured = (
            sosfiltfilt(sos, v - v.mean(axis=0), axis=0) for v in (predicted, measured)
        )
    return nrms(predicted, measured)


class _Problem:
    """The fit's residual as a function of the free parameters."""

    def __init__(self, scene: Scene, foundation: Signal, body: Signal, free: list[str]) -> None:
        self.scene, self.foundation, self.free = scene, foundation, free
        if problem := overlap_problem(foundation, body):
            raise ValueError(problem)
        keep = compared(foundation, body)
        self.t, self.measured = body.t[keep], body.accel[keep]
        self.scale = self.measured.std(axis=0) + 1e-12

    def values(self, x: np.ndarray) -> dict[str, float]:
        """Parameter values of the free vector x (scales as logarithms)."""
        out = {}
        for name, v in zip(self.free, x, strict=True):
            out[name] = math.exp(v) if is_scale(name) else float(v)
        return out

    def predicted(self, values: dict[str, float]) -> np.ndarray:
        """The body sensor's prediction at the measured stamps."""
        scene = calibrated_scene(self.scene, values)
        stamps, f = predict(scene, self.foundation)
        lag = scene.body_sensor.lag_s if scene.body_sensor else 0.0
        return _at(stamps, f, self.t - lag)

    def residual(self, x: np.ndarray) -> np.ndarray:
        p = self.predicted(self.values(x))
        p = p - p.mean(axis=0)
        m = self.measured - self.measured.mean(axis=0)
        return ((p - m) / self.scale).ravel()


def _too_uncertain(name: str, sigma: float, value: float, step_s: float) -> str | None:
    """Why a fitted parameter is not identified (None: it is)."""
    if not math.isfinite(sigma):
        return "the record does not move it at all (its 1σ is unbounded)"
    if is_scale(name) and sigma > MAX_REL_SIGMA * value:
        return f"1σ is {sigma / value:.0%} of its value (the record barely moves it)"
    if name in ANGLES and sigma > MAX_YAW_SIGMA_RAD:
        return f"1σ is {angle_text(sigma)}: the motion has no direction to tell it by"
    if name in (*OFFSETS, *CG_OFFSETS) and sigma > MAX_POSITION_SIGMA_M:
        return f"1σ is {sigma * 1e3:.0f} mm (the body barely turns: its point hardly matters)"
    if name == "lag" and sigma > step_s:
        return f"1σ is {sigma * 1e3:.1f} ms, more than a sample ({step_s * 1e3:.1f} ms)"
    return None


def _start(problem: _Problem) -> np.ndarray:
    """Where the local fit starts, in the fitted coordinates: the nominal, with every mount
    stiffness scale at the common factor of `STIFFNESS_SCAN` (refined once between its
    neighbours) whose prediction misses the body least."""
    x0 = np.zeros(len(problem.free))
    stiff = [i for i, n in enumerate(problem.free) if n.partition(":")[0] == "stiffness"]
    if not stiff:
        return x0

    def misfit(factor: float) -> float:
        x = x0.copy()
        x[stiff] = math.log(factor)
        try:
            return float(np.sum(problem.residual(x) ** 2))
        except ValueError:  # the twin failed on mounts that soft or stiff: not a start
            return math.inf

    best = min(STIFFNESS_SCAN, key=misfit)
    ratio = STIFFNESS_SCAN[1] / STIFFNESS_SCAN[0]
    best = min(best * ratio ** np.linspace(-1.0, 1.0, 9), key=misfit)
    x0[stiff] = math.log(best)
    return x0


def _fit(problem: _Problem, x0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The least-squares solution and its parameters' 1σ (in the fitted coordinates)."""
    from scipy.optimize import least_squares

    step = float(np.median(np.diff(problem.t)))
    scales = [0.1 if n != "lag" else step for n in problem.free]
    sol = least_squares(problem.residual, x0, x_scale=scales, diff_step=1e-4, method="trf")
    dof = max(sol.fun.size - sol.x.size, 1)
    return sol.x, _sigma(sol.jac, 2.0 * sol.cost / dof)


def _sigma(jac: np.ndarray, s2: float) -> np.ndarray:
    """Each parameter's 1σ from the residuals' Jacobian and variance s2: √diag((JᵀJ)⁻¹·s2),
    infinite for a parameter with a share in a direction the residuals do not move along (a
    pseudo-inverse gives it 0, and a sensor offset the motion cannot show passed as ± 0)."""
    _, sv, vt = np.linalg.svd(jac, full_matrices=False)
    seen = sv > sv.max(initial=0.0) * max(jac.shape) * np.finfo(float).eps
    variance = ((vt[seen] / sv[seen, None]) ** 2).sum(axis=0) * s2
    blind = (np.abs(vt[~seen]) > 1e-8).any(axis=0)
    return np.where(blind, np.inf, np.sqrt(variance))


def calibrate(
    scene: Scene, foundation: Signal, body: Signal, fit: tuple[str, ...] = PARAMETERS
) -> Calibration:
    """Fit `fit` (of PARAMETERS) so that the twin on `foundation` predicts `body` (module
    docstring); refuse, by name, what the record cannot identify (all of it where a record
    does not move: `still_record`)."""
    known = (*PARAMETERS, *ON_REQUEST)
    unknown = [
        n for n in fit if n.partition(":")[0] not in known or (":" in n and not is_mount_scale(n))
    ]
    if unknown:
        msg = (
            f"cannot fit {', '.join(unknown)}: the parameters are {', '.join(known)}, "
            "and stiffness:MOUNT+MOUNT… or damping:… for a group"
        )
        raise ValueError(msg)
    kinds = {n.partition(":")[0] for n in fit}
    if {"mass", *MOUNT_SCALES} <= kinds:
        msg = (
            "cannot fit mass with stiffness and damping: scaling all three alike moves nothing "
            "the body IMU reads; fit the mass with the mounts held, or the mounts with the mass"
        )
        raise ValueError(msg)
    for name in fit:
        if is_mount_scale(name):
            scaled_mounts(name, scene)
    nominal = {n: 1.0 if is_scale(n) else 0.0 for n in (*fit, "yaw", "lag")}
    if still := still_record(foundation, body):
        refused = dict.fromkeys(fit, still.why)
        return Calibration(nominal, {}, refused, math.nan, math.nan, calibrated_scene(scene, {}))
    free = list(fit)
    refused = {}
    step = float(np.median(np.diff(body.t)))
    fitted: dict[str, float] = {}  # the last fit, in its coordinates: where a refit starts
    while True:
        problem = _Problem(scene, foundation, body, free)
        if not free:
            values, sigma = {}, {}
            break
        x0 = np.array([fitted[n] for n in free]) if fitted else _start(problem)
        x, sigma_x = _fit(problem, x0)
        fitted = dict(zip(free, x.tolist(), strict=True))
        values = problem.values(x)
        sigma = {
            n: s * values[n] if is_scale(n) else float(s)
            for n, s in zip(free, sigma_x, strict=True)
        }
        why = {n: w for n in free if (w := _too_uncertain(n, sigma[n], values[n], step))}
        if not why:
            break
        refused.update(why)
        free = [n for n in free if n not in why]
    unfitted = _Problem(scene, foundation, body, [])
    before = nrms(unfitted.predicted({}), unfitted.measured)
    after = nrms(problem.predicted(values), problem.measured) if values else before
    if values and not after < before:
        # A fit that predicts the body worse than the nominal scene fitted the foundation
        # record's noise (or a model the machine is not): nothing it found is kept.
        said = f"the fit predicts the body no better (NRMS {before:.3g} → {after:.3g})"
        refused.update(dict.fromkeys(values, said))
        values, sigma, after = {}, {}, before
    full = {**nominal, **values}
    return Calibration(full, sigma, refused, before, after, calibrated_scene(scene, full))
