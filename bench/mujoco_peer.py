"""MuJoCo as a peer of the twin (bench/peers.py): the scene posed to MuJoCo, run on the same input.

The model (MJCF generated from the twin's Scene, not a hand-written file):

- the body: three slide joints along F's axes and a ball joint at the CG (not a free joint: a
  free joint's stiffness is one scalar for translation and rotation together), mass and full
  inertia tensor of the scene;
- each linear mount: one spatial tendon per local axis with stiffness or damping, from a site at
  the attachment point on the body to an anchor site ANCHOR_LENGTH metres along that axis on the
  foundation, springlength = that length. Its length is L − a·d + |d_⊥|²/(2L) for a
  displacement d of the attachment point, so it pulls with −k·(a·d)·a, the mount's force along
  a, and adds terms of order 1/L: a lateral stiffness T/L (T its tension, mostly the static
  load: about 1.5 kN on a pump mount's vertical tendon, over L = 1 km 1.5 N/m against the
  mount's 5e5 N/m; the same as saying its pull turns with the tendon, by |d_⊥|/L) and
  k·|d_⊥|²/(2L) (6e-4 N at a millimetre). Measured on the pump against the twin: 7.3e-7 of the
  peak mount force at 1 km, 7.4e-8 at 10 km, 7.3e-6 at 100 m (∝ 1/L). A longer tendon loses
  digits: its length rounds to ε·L, ε·L·k ≈ 3e-7 N at 1 km (1.5e-10 of the pump's peak force,
  the floor of MuJoCo's converged solution) but 1.5e-9 at 10 km, the twin's own error; hence
  1 km. The mount's force component j is read as the tendon's pull k·(ℓ − L) + c·ℓ̇;
- the mounts' rotational stiffness and damping: the twin's couple −J⁻ᵀ·(Q K_r Qᵀ φ + Q C_r Qᵀ φ′)
  (φ the rotation vector of R, φ′ = J⁻¹ω, J its left Jacobian: `physics/linear_mount.py`) is,
  summed over mounts whose K_r and C_r are isotropic, exactly a ball joint's spring (J⁻ᵀφ = φ;
  MuJoCo's ball spring is the rotation vector of the joint's quaternion) and its damper to
  second order in the angle (J⁻ᵀJ⁻¹ = 1 − [φ]×²/12 + …: 1e-7 of the damping couple at the
  pump's milliradians). Anisotropic sums (no such joint in MuJoCo) are refused. Modelled, not
  dropped: the pump's 8 × 500 N·m/rad left out would change its mount forces by 4.3e-4 of the
  peak;
- the foundation: the model stays in the moving deck frame F, as the twin does. The specific
  force f(t) and rate Ω(t) are held linear between samples as the twin holds them; the body
  gets −m·f(t) at its CG (the same as gravity −f(t): a uniform field on one body) and the
  fictitious forces and moments of the rotating frame (physics notes §6: Coriolis, Euler and
  centrifugal on the CG; in the Euler equations the absolute rate ω + RᵀΩ) as xfrc_applied.
  MuJoCo holds xfrc_applied and gravity constant over a step; they are set either in a control
  callback at every stage of the integrator, at the stage's own time and state (`hold="stage"`,
  the default: RK4 keeps its order), or once before each mj_step at the step's midpoint time
  and its initial state (`hold="step"`: what a plain stepping loop does; the state-dependent
  terms are then first order). Gravity itself is left at zero: model gravity enters MuJoCo's
  bias forces before the control callback runs, so setting it there would lag a stage. The
  fictitious terms are not negligible on the ship record (|Ω| ≤ 0.07 rad/s): without them the
  pump's forces differ by 6.4e-3 of the peak.
- start: static equilibrium under the first sample's f and Ω (Ω′ = 0), solved on MuJoCo's own
  accelerations from the twin's equilibrium, as the twin starts.

Limits: linear mounts only. No bolted joint (opening, slip, yield, fracture), no shear-key
clearance, no elastomer law: `closed_joints` poses a bolted scene as its linearised closed joint
(bolt and clamp in parallel axially, the stuck face in shear) without its keys, which is a
different model, valid only while no joint opens or slips and no key closes its clearance. On
the genset's shock record they do (its twin reference: feet pulled to −135 kN past the
120 kN opening load, key_y bearing 206 kN): there the closed-joint reference differs from the
full one by 0.85 of the peak force, so only its cost is comparable, not its answer.
MuJoCo also has no input between steps (gravity and xfrc_applied are held over a step: Python
sets them, per stage here, at a cost the figures include) and no moving base (the fictitious
terms are ours).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Protocol

import mujoco
import numpy as np
from scipy.optimize import least_squares

from mount_twin.kinds.bolted_joint import BoltedJoint
from mount_twin.kinds.shear_key import ShearKey
from mount_twin.model.assemble import assemble, in_f, initial_state
from mount_twin.physics.chart import rotation_matrix
from mount_twin.physics.rotations import rpy_matrix
from mount_twin.scene.description import DOF_NAMES, LinearMount, Scene

try:  # the peer's frame-load callback runs at every MuJoCo step: compiled where numba is there
    from numba import njit
except ImportError:  # (the `bench` extra installs it); plain Python otherwise, the same numbers

    def njit(**_options: object):  # type: ignore[no-redef]
        return lambda fn: fn


ANCHOR_LENGTH = 1000.0
"""Tendon length from a mount's attachment point to its anchor on the foundation, m."""
INTEGRATORS = {
    "Euler": mujoco.mjtIntegrator.mjINT_EULER,
    "RK4": mujoco.mjtIntegrator.mjINT_RK4,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
}
AXES = "xyz"
BODY = 1
"""MuJoCo body id of the machine (0 is the world)."""


def closed_joints(scene: Scene) -> tuple[Scene, list[str]]:
    """`scene` with each bolted joint replaced by its closed, stuck, elastic joint as a linear
    mount (axial k_S + k_P: the joint diagram while closed, F_K − F_S = −(k_S + k_P)·u; shear
    the stick stiffness k_τ; its dampers) and its shear keys left out; the names left out."""
    mounts: list = []
    dropped: list[str] = []
    for mt in scene.mounts:
        if isinstance(mt, BoltedJoint):
            k_shear, k_axial = mt.shear_stiffness, mt.bolt_stiffness + mt.clamp_stiffness
            mounts.append(
                LinearMount(
                    name=mt.name,
                    position=mt.position,
                    orientation_rpy=mt.orientation_rpy,
                    stiffness=(k_shear, k_shear, k_axial, 0.0, 0.0, 0.0),
                    damping=(mt.shear_damping, mt.shear_damping, mt.axial_damping, 0, 0, 0),
                )
            )
        elif isinstance(mt, ShearKey):
            dropped.append(mt.name)
        else:
            mounts.append(mt)
    name = scene.name + " (closed joints)"
    return dataclasses.replace(scene, name=name, mounts=tuple(mounts)), dropped


def _isotropic(total: np.ndarray, what: str) -> float:
    """The scalar c of a 3×3 sum that is c·I; ValueError otherwise."""
    c = float(np.trace(total)) / 3.0
    if np.abs(total - c * np.eye(3)).max() > 1e-9 * max(abs(c), 1.0):
        msg = f"MuJoCo: the mounts' summed {what} is not isotropic (a ball joint's is)"
        raise ValueError(msg)
    return c


def mjcf(scene: Scene, anchor_length: float = ANCHOR_LENGTH) -> str:
    """MJCF of `scene` (linear mounts, all six DOFs): see the module docstring."""
    if tuple(scene.dofs) != DOF_NAMES:
        msg = f"MuJoCo peer: only all six DOFs are posed, not {scene.dofs}"
        raise ValueError(msg)
    mounts = []
    for mt in scene.mounts:
        if not isinstance(mt, LinearMount):
            msg = f"MuJoCo has no {mt.kind} mount ({mt.name}): see closed_joints"
            raise ValueError(msg)
        mounts.append(mt)
    body = scene.body
    cg = np.array(body.cg)
    axes = np.array([rpy_matrix(*mt.orientation_rpy) for mt in mounts])
    k_r = _isotropic(in_f(axes, np.array([mt.stiffness[3:] for mt in mounts])).sum(0), "K_r")
    c_r = _isotropic(in_f(axes, np.array([mt.damping[3:] for mt in mounts])).sum(0), "C_r")

    def vec(v: np.ndarray | tuple) -> str:
        return " ".join(f"{float(x):.17g}" for x in v)

    anchors, sites, tendons = [], [], []
    for mt, q in zip(mounts, axes, strict=True):
        p = np.array(mt.position)
        sites.append(f'<site name="{mt.name}" pos="{vec(p - cg)}"/>')
        for j in range(3):
            k, c = mt.stiffness[j], mt.damping[j]
            if k == 0.0 and c == 0.0:
                continue
            name = f"{mt.name}_{AXES[j]}"
            anchors.append(f'<site name="{name}" pos="{vec(p + anchor_length * q[:, j])}"/>')
            tendons.append(
                f'<spatial name="{name}" stiffness="{k:.17g}" damping="{c:.17g}" '
                f'springlength="{anchor_length:.17g}">'
                f'<site site="{mt.name}"/><site site="{name}"/></spatial>'
            )
    slides = "".join(
        f'<joint name="{a}" type="slide" axis="{vec(np.eye(3)[i])}"/>' for i, a in enumerate(AXES)
    )
    nl = "\n"
    return f"""<mujoco model="{scene.name}">
  <option timestep="1e-4" gravity="0 0 0"><flag contact="disable"/></option>
  <worldbody>
    {nl.join(anchors)}
    <body name="machine" pos="{vec(cg)}">
      {slides}
      <joint name="rotation" type="ball" stiffness="{k_r:.17g}" damping="{c_r:.17g}"/>
      <inertial pos="0 0 0" mass="{body.mass:.17g}" fullinertia="{vec(body.inertia)}"/>
      {nl.join(sites)}
    </body>
  </worldbody>
  <tendon>
    {nl.join(tendons)}
  </tendon>
</mujoco>
"""


@njit(cache=True)
def _frame_loads(
    t: float,
    u: np.ndarray,
    mass: float,
    inertia_b: np.ndarray,
    rel0: np.ndarray,
    qpos: np.ndarray,
    qvel: np.ndarray,
    out: np.ndarray,
    rotating: bool,
) -> None:
    """Force and moment (F, at the CG) of the moving frame on the body into out (6,): −m·f and,
    if `rotating`, the fictitious terms (physics notes §6). u: the input line as the twin's
    (t0, f0, f', Ω0, Ω'): f = f0 + f'·(t − t0); rel0: the CG's reference position from the
    accelerometer, m; qpos (CG displacement, quaternion w x y z of R), qvel (ṙ, ω in B)."""
    tau = t - u[0]
    if not rotating:
        for i in range(3):
            out[i] = -mass * (u[1 + i] + u[4 + i] * tau)
            out[3 + i] = 0.0
        return
    f, w, wd = np.empty(3), np.empty(3), np.empty(3)
    for i in range(3):
        f[i] = u[1 + i] + u[4 + i] * tau
        w[i] = u[7 + i] + u[10 + i] * tau
        wd[i] = u[10 + i]
    qw, qx, qy, qz = qpos[3], qpos[4], qpos[5], qpos[6]
    r = np.array(
        [
            [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)],
            [2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)],
            [2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)],
        ]
    )
    rel = rel0 + qpos[:3]
    v = qvel[:3].copy()
    om = r @ qvel[3:6].copy()  # ω relative to F, in F
    ifr = r @ inertia_b @ r.T  # inertia in F
    frame = 2.0 * np.cross(w, v) + np.cross(wd, rel) + np.cross(w, np.cross(w, rel))
    i_w, i_om = ifr @ w, ifr @ om
    moment = (
        ifr @ np.cross(om, w) - np.cross(om, i_w) - np.cross(w, i_om) - np.cross(w, i_w) - ifr @ wd
    )
    for i in range(3):
        out[i] = -mass * (f[i] + frame[i])
        out[3 + i] = moment[i]


@dataclass
class MujocoTwin:
    """A scene posed to MuJoCo, with its foundation input and mount-force readout.

    Attributes:
        scene: the (linear) scene posed.
        model, data: MuJoCo's.
        u: the input line of the current interval, as the twin's input vector u[:13].
        rotating: whether any Ω is nonzero in the record (else the fictitious terms are off).
    """

    scene: Scene
    model: mujoco.MjModel
    data: mujoco.MjData
    u: np.ndarray
    rotating: bool
    k: np.ndarray
    c: np.ndarray
    length0: float

    @classmethod
    def build(
        cls, scene: Scene, rotating: bool, anchor_length: float = ANCHOR_LENGTH
    ) -> MujocoTwin:
        model = mujoco.MjModel.from_xml_string(mjcf(scene, anchor_length))
        return cls(
            scene,
            model,
            mujoco.MjData(model),
            np.zeros(13),
            rotating,
            model.tendon_stiffness.copy(),
            model.tendon_damping.copy(),
            anchor_length,
        )

    def apply(self, t: float) -> None:
        """xfrc_applied of the machine at time t and the current state."""
        d, body = self.data, self.scene.body
        _frame_loads(
            t,
            self.u,
            body.mass,
            self._inertia,
            self._rel0,
            d.qpos,
            d.qvel,
            d.xfrc_applied[BODY],
            self.rotating,
        )

    def __post_init__(self) -> None:
        ixx, iyy, izz, ixy, ixz, iyz = self.scene.body.inertia
        self._inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        body, sensor = self.scene.body, self.scene.input.sensor_position
        self._rel0 = np.array(body.cg, dtype=float) - np.array(sensor, dtype=float)

    def tendon_forces(self) -> np.ndarray:
        """Each tendon's pull along its mount axis on the body, N (the mount's force component
        on the body, positive along the axis), at the current qpos, qvel: mj_fwdPosition and
        mj_fwdVelocity must have run."""
        d = self.data
        return self.k * (d.ten_length - self.length0) + self.c * d.ten_velocity

    def equilibrium(self, f0: np.ndarray, w0: np.ndarray) -> None:
        """Set qpos to MuJoCo's static equilibrium (relative to F turning at w0, Ω′ = 0) under
        specific force f0, from the twin's equilibrium; qvel = 0."""
        twin = assemble(self.scene)
        y = initial_state(twin, f0, w0)
        m, d = self.model, self.data
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, rotation_matrix(*y[3:6]).ravel())
        guess = np.concatenate([y[:3], quat])
        self.u[:] = 0.0
        self.u[1:4], self.u[7:10] = f0, w0
        d.qvel[:] = 0.0

        def pose(x: np.ndarray) -> None:
            d.qpos[:] = guess
            mujoco.mj_integratePos(m, d.qpos, x, 1.0)

        def accelerations(x: np.ndarray) -> np.ndarray:
            pose(x)
            self.apply(0.0)
            mujoco.mj_forward(m, d)
            return d.qacc.copy()

        sol = least_squares(accelerations, np.zeros(6), xtol=1e-15, ftol=1e-15, gtol=1e-15)
        pose(sol.x)
        self.apply(0.0)
        mujoco.mj_forward(m, d)


class Record(Protocol):
    """The record as the peers take it (peers.Foundation): stamps t (s), specific force f and
    rate Ω w (F) at the samples; `line(j, u)` writes the input line of interval j into u."""

    @property
    def t(self) -> np.ndarray: ...
    @property
    def f(self) -> np.ndarray: ...
    @property
    def w(self) -> np.ndarray: ...
    def line(self, j: int, u: np.ndarray) -> None: ...


@dataclass(frozen=True)
class MujocoRun:
    """Mount forces (k, n_mounts, 3: N, on the body, mount axes) at the samples; wall time of
    the run (s), MuJoCo steps taken, and the wall time of as many steps alone (s: inputs frozen,
    no callback, no readout)."""

    forces: np.ndarray
    wall_s: float
    steps: int
    engine_s: float


def mujoco_run(
    twin: MujocoTwin, deck: Record, integrator: str, dt: float, hold: str = "stage"
) -> MujocoRun:
    """MuJoCo over the record, steps of at most dt landing on every sample, from the
    equilibrium at the first sample; forces at each sample. The wall time covers the stepping,
    the input and frame forces (per stage from a control callback if `hold` is "stage", else
    once per step at its midpoint time) and the force readout: what a user of MuJoCo pays to
    do what the twin does; not the equilibrium (the twin's start is not in its figure either)."""
    m, d = twin.model, twin.data
    t = deck.t
    mujoco.mj_resetData(m, d)
    m.opt.integrator = INTEGRATORS[integrator]
    twin.equilibrium(deck.f[0], deck.w[0])
    start_qpos = d.qpos.copy()
    forces = np.zeros((t.shape[0], m.ntendon))
    stage = hold == "stage"
    mujoco.mj_fwdPosition(m, d)
    mujoco.mj_fwdVelocity(m, d)
    forces[0] = twin.tendon_forces()
    u, steps = twin.u, 0
    if stage:
        mujoco.set_mjcb_control(lambda _m, _d: twin.apply(_d.time))
    t0 = time.perf_counter()
    try:
        for j in range(1, t.shape[0]):
            span = t[j] - t[j - 1]
            n = max(round(span / dt), 1)
            h = span / n
            deck.line(j, u)
            m.opt.timestep = h
            d.time = t[j - 1]
            if stage:
                mujoco.mj_step(m, d, n)
            else:
                for i in range(n):
                    twin.apply(t[j - 1] + (i + 0.5) * h)
                    mujoco.mj_step(m, d)
            steps += n
            mujoco.mj_fwdPosition(m, d)
            mujoco.mj_fwdVelocity(m, d)
            forces[j] = twin.tendon_forces()
    finally:
        mujoco.set_mjcb_control(None)
    wall = time.perf_counter() - t0
    d.qpos[:], d.qvel[:] = start_qpos, 0.0
    m.opt.timestep = (t[-1] - t[0]) / steps
    t0 = time.perf_counter()
    mujoco.mj_step(m, d, steps)
    engine = time.perf_counter() - t0
    return MujocoRun(_by_mount(twin, forces), wall, steps, engine)


def _by_mount(twin: MujocoTwin, forces: np.ndarray) -> np.ndarray:
    """(k, n_mounts, 3) from per-tendon forces (axes without a tendon carry none)."""
    m = twin.model
    names = [m.tendon(i).name for i in range(m.ntendon)]
    out = np.zeros((forces.shape[0], len(twin.scene.mounts), 3))
    for i, mt in enumerate(twin.scene.mounts):
        for j in range(3):
            name = f"{mt.name}_{AXES[j]}"
            if name in names:
                out[:, i, j] = forces[:, names.index(name)]
    return out
