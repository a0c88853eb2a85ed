"""Equations of motion on the free generalized coordinates, in the moving foundation frame F.

State y = [q_f, q_f', z] where q_f is the free subset of q = (X, Y, Z, α, γ, δ) (m, rad) in the
order of `DOF_NAMES` and z the internal states of the mounts that have them (mount_twin.kinds);
frozen coordinates keep the values in `ModelArrays.q_fixed`. The CG velocity
is r' = (X', Y', Z') and the body angular velocity relative to F is ω = B(α, γ)·(α', γ', δ'), both
linear in q'. Projecting Newton–Euler on q_f (Kane's method) gives, exactly for any subset,

    translation:  q_t'' = F/m − f_s − [2Ω×r' + Ω'×(r − s) + Ω×(Ω×(r − s))]   (physics notes §6)
    rotation:     (Jᵀ I J) q_r'' = Jᵀ [M − ω_a × I ω_a − I(B' q_r' − ω×Ωᴮ + RᵀΩ')],  J = B[:, free]

with f_s the specific force at sensor point s, Ω the foundation angular velocity (in F),
Ωᴮ = RᵀΩ, ω_a = ω + Ωᴮ the absolute angular velocity and M the mount moment about the CG (in B).

Input over one sample interval is u = [t0, f0, ḟ, Ω0, Ω̇] (13 floats): f(t) = f0 + ḟ·(t − t0) and
Ω(t) = Ω0 + Ω̇·(t − t0); a zero-order hold passes zero slopes.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from mount_twin.kinds import kind_load, kind_monitor, kind_update
from mount_twin.physics import pose_row
from mount_twin.physics.chart import kinematic_matrix, kinematic_matrix_rate, rotation_from_chart
from mount_twin.physics.compiled import kernel
from mount_twin.physics.gate import skip_if_none
from mount_twin.physics.linear_mount import linear_mount_load, point_motion
from mount_twin.physics.rotations import couple_map, quaternion_from_matrix, rotation_vector

OK = 0
OFF_CHART = 1
"""Right-hand-side status: the attitude left the chart (cos θ ≤ COS_TILT_MIN)."""

COS_TILT_MIN = 1.0e-6
"""cos θ below which the state counts as off the chart: B grows like 1/cos θ and the reduced
mass matrix loses positive definiteness in floating point long before cos θ reaches zero."""

INPUT_SIZE = 13


class ModelArrays(NamedTuple):
    """Flat arrays of an assembled scene, as the compiled kernels read them (SI, frames as named).

    Linear mounts are the lin_ arrays (zero-length if none); all other kinds are `nl`, None for
    a scene without them, so that numba compiles no trace of them into its kernels (measured
    before the kernels dropped numba's runtime, their mere presence made the linear right-hand
    side ~40 % slower).
    """

    mass: float  # kg
    inertia: np.ndarray  # (3, 3) kg·m², about the CG, in B
    cg_ref: np.ndarray  # (3,) m, CG at the reference pose, in F
    sensor_position: np.ndarray  # (3,) m, in F
    free_trans: np.ndarray  # int64 (nt,): free indices among X, Y, Z
    free_rot: np.ndarray  # int64 (nr,): free indices among α, γ, δ
    q_fixed: np.ndarray  # (6,) values of the frozen coordinates (free ones overwritten)
    lin_point: np.ndarray  # (n, 3) m, attachment point from the CG, in B
    lin_axes: np.ndarray  # (n, 3, 3) mount axes Q (columns) in F
    lin_k_t: np.ndarray  # (n, 3, 3) N/m in F
    lin_c_t: np.ndarray  # (n, 3, 3) N·s/m in F
    lin_k_r: np.ndarray  # (n, 3, 3) N·m/rad in F
    lin_c_r: np.ndarray  # (n, 3, 3) N·m·s/rad in F
    lin_slot: np.ndarray  # int64 (n,): each linear mount's index in the scene (wrench row)
    nl: NonLinearMounts | None  # the other kinds; None compiles their code away
    rotation_read: bool  # a mount reads the body's rotation vector (linear ones, rotational kinds)


class NonLinearMounts(NamedTuple):
    """Mounts of the kinds in mount_twin.kinds (k of them), as the kernels read them."""

    kind: np.ndarray  # int64 (k,): kind code
    point: np.ndarray  # (k, 3) m, attachment point from the CG, in B
    axes: np.ndarray  # (k, 3, 3) mount axes Q (columns) in F
    slot: np.ndarray  # int64 (k,): index in the scene
    state: np.ndarray  # int64 (k,): offset of the mount's internal states in y (−1: none)
    par: np.ndarray  # (k, N_PAR) parameter rows, columns per kind
    rotational: np.ndarray  # bool (k,): the kind has a rotational law (its ROTATIONAL)
    aligned: np.ndarray  # bool (k,): the mount's axes are F's (axes[i] = I: nothing to rotate)


class Scratch(NamedTuple):
    """Preallocated work arrays, so the kernels allocate nothing per call.

    Which call fills which fields, and who may read them after it (a field holds what its
    last writer left; nothing else is promised):

    - `body_motion(y)` fills q, qd, trig, rot, kin, omega, omega_f, and phi with its
      quaternion quat, its rate phi_rate and the couple map where a mount reads them
      (`ModelArrays.rotation_read`; else phi, phi_rate and the map are NaN and quat is left,
      for `outputs` to take): read by the mount laws and the rest of `rhs` at that y.
    - `mount_loads` (inside `rhs`) fills arm, force, couple, loc, total_force, total_moment,
      sink: read by `rhs` itself.
    - `rhs(t, y, u)` fills all of the above, then f_s, big_w, big_w_dot, rel, w_x_rel,
      kin_rate, moment_b, w_b, w_dot_b, acc, w_abs, h, i_w, rhs_rot and mass_rot (the
      Cholesky factor of Jᵀ I J). `outputs(y)` may follow only if that last `rhs` was at y
      (the stepper's last stage is: first same as last); `rhs_after_rate_step` moves that
      last stage to a new Ω' through the factored mass_rot.
    - `run_samples` fills rate_step (the jump of Ω' at a sample): read by
      `rhs_after_rate_step`.
    - `mount_wrenches`, `mount_monitors`, `outputs` and `evaluate` (which calls `body_motion`
      first) overwrite arm, force, couple, loc and sink; their results go to the caller's
      arrays.
    """

    q: np.ndarray  # (6,)
    trig: np.ndarray  # (6,) sin α, sin γ, sin δ, cos α, cos γ, cos δ
    qd: np.ndarray  # (6,)
    rot: np.ndarray  # (3, 3)
    kin: np.ndarray  # (3, 3) B
    kin_rate: np.ndarray  # (3, 3) dB/dt
    omega: np.ndarray  # (3,) ω in B
    omega_f: np.ndarray  # (3,) R·ω in F
    phi: np.ndarray  # (3,) rotation vector of R, rad, F
    phi_rate: np.ndarray  # (3,) its rate J(φ)⁻¹·R·ω, rad/s
    couple_map: np.ndarray  # (3, 3) J(φ)⁻ᵀ: a force conjugate to φ → its couple in F
    quat: np.ndarray  # (4,)
    arm: np.ndarray  # (3,)
    force: np.ndarray  # (3,)
    couple: np.ndarray  # (3,)
    total_force: np.ndarray  # (3,) N, in F
    total_moment: np.ndarray  # (3,) N·m about the CG, in F
    f_s: np.ndarray  # (3,) specific force at the sensor, F
    big_w: np.ndarray  # (3,) foundation angular velocity Ω, F
    big_w_dot: np.ndarray  # (3,) Ω', F
    rel: np.ndarray  # (3,) r − s, F
    w_x_rel: np.ndarray  # (3,) Ω × (r − s), F
    moment_b: np.ndarray  # (3,) mount moment, B
    w_b: np.ndarray  # (3,) Ωᴮ = RᵀΩ
    w_dot_b: np.ndarray  # (3,) RᵀΩ'
    acc: np.ndarray  # (3,) ω_a' − B q''
    w_abs: np.ndarray  # (3,) ω_a, B
    h: np.ndarray  # (3,) projected moment residual, B
    i_w: np.ndarray  # (3,) I·ω_a, B
    mass_rot: np.ndarray  # (3, 3) reduced rotational mass matrix
    rhs_rot: np.ndarray  # (3,)
    rate_step: np.ndarray  # (3,) jump of Ω' at a sample, rad/s², F
    loc: np.ndarray  # (6, 3) local deflection, rate, rotation, rate, force, couple of a mount
    sink: np.ndarray  # (n_state,) internal-state rates nobody needs (outputs, monitors)


def new_scratch(n_state: int) -> Scratch:
    """Fresh work arrays for one model with `n_state` states."""
    return Scratch(
        q=np.zeros(6),
        trig=np.zeros(6),
        qd=np.zeros(6),
        rot=np.eye(3),
        kin=np.zeros((3, 3)),
        kin_rate=np.zeros((3, 3)),
        omega=np.zeros(3),
        omega_f=np.zeros(3),
        phi=np.zeros(3),
        phi_rate=np.zeros(3),
        couple_map=np.eye(3),
        quat=np.zeros(4),
        arm=np.zeros(3),
        force=np.zeros(3),
        couple=np.zeros(3),
        total_force=np.zeros(3),
        total_moment=np.zeros(3),
        f_s=np.zeros(3),
        big_w=np.zeros(3),
        big_w_dot=np.zeros(3),
        rel=np.zeros(3),
        w_x_rel=np.zeros(3),
        moment_b=np.zeros(3),
        w_b=np.zeros(3),
        w_dot_b=np.zeros(3),
        acc=np.zeros(3),
        w_abs=np.zeros(3),
        h=np.zeros(3),
        i_w=np.zeros(3),
        mass_rot=np.zeros((3, 3)),
        rhs_rot=np.zeros(3),
        rate_step=np.zeros(3),
        loc=np.zeros((6, 3)),
        sink=np.zeros(n_state),
    )


@njit(cache=True, inline="always")
def body_motion(y: np.ndarray, m: ModelArrays, s: Scratch) -> float:
    """Fill s.q, s.qd, s.trig, s.rot, s.kin, s.omega, s.omega_f, s.phi from y; s.phi, its
    quaternion s.quat, its rate s.phi_rate and s.couple_map (`rotations.couple_map`) only where
    a mount reads the rotation vector (m.rotation_read; NaN else, and `outputs` takes the
    quaternion itself).

    Returns cos θ (NaN off the chart, i.e. at or below COS_TILT_MIN). Kernels bind scratch
    arrays to locals once: every attribute access on a tuple of arrays costs a reference-count
    round trip in numba.
    """
    q, qd, trig, rot, kin, omega, omega_f = s.q, s.qd, s.trig, s.rot, s.kin, s.omega, s.omega_f
    free_trans, free_rot, q_fixed = m.free_trans, m.free_rot, m.q_fixed
    nt, nr = free_trans.shape[0], free_rot.shape[0]
    nf = nt + nr
    for i in range(6):  # explicit loops: numba's slice assignment costs ~100 ns each
        q[i] = q_fixed[i]
        qd[i] = 0.0
    for k in range(nt):
        q[free_trans[k]] = y[k]
        qd[free_trans[k]] = y[nf + k]
    for k in range(nr):
        q[3 + free_rot[k]] = y[nt + k]
        qd[3 + free_rot[k]] = y[nf + nt + k]
    for i in range(3):
        trig[i] = math.sin(q[3 + i])
        trig[3 + i] = math.cos(q[3 + i])
    sa, sg, sd, ca, cg, cd = trig[0], trig[1], trig[2], trig[3], trig[4], trig[5]
    ct = rotation_from_chart(sa, sg, cg, sd, cd, rot)
    if not ct > COS_TILT_MIN:
        return math.nan
    kinematic_matrix(sa, ca, sg, cg, ct, kin)
    for i in range(3):
        omega[i] = kin[i, 0] * qd[3] + kin[i, 1] * qd[4] + kin[i, 2] * qd[5]
    for i in range(3):
        omega_f[i] = rot[i, 0] * omega[0] + rot[i, 1] * omega[1] + rot[i, 2] * omega[2]
    phi, phi_rate, cmap = s.phi, s.phi_rate, s.couple_map
    if m.rotation_read:
        rotation_vector(rot, s.quat, phi)
        couple_map(phi, s.quat, cmap)
        for i in range(3):  # φ′ = J⁻¹·R·ω, J⁻¹ the transpose of the map
            phi_rate[i] = (
                cmap[0, i] * omega_f[0] + cmap[1, i] * omega_f[1] + cmap[2, i] * omega_f[2]
            )
    else:
        for i in range(3):
            phi[i] = math.nan
            phi_rate[i] = math.nan
            for j in range(3):
                cmap[i, j] = math.nan
    return ct


@njit(cache=True, inline="always")
def _into_axes(nl: NonLinearMounts, i: int, x0: float, x1: float, x2: float, out) -> None:
    """out = Qᵢᵀ·x: a vector of F in mount i's axes (copied where they are F's)."""
    if nl.aligned[i]:
        out[0], out[1], out[2] = x0, x1, x2
        return
    axes = nl.axes
    for j in range(3):
        out[j] = axes[i, 0, j] * x0 + axes[i, 1, j] * x1 + axes[i, 2, j] * x2


@njit(cache=True, inline="always")
def _out_of_axes(nl: NonLinearMounts, i: int, local, out) -> None:
    """out = Qᵢ·local: a vector of mount i's axes in F (copied where they are F's)."""
    if nl.aligned[i]:
        out[0], out[1], out[2] = local[0], local[1], local[2]
        return
    axes = nl.axes
    for j in range(3):
        out[j] = axes[i, j, 0] * local[0] + axes[i, j, 1] * local[1] + axes[i, j, 2] * local[2]


@njit(cache=True, inline="always")
def _local_motion(i: int, nl: NonLinearMounts, s: Scratch) -> None:
    """Deflection, rate, rotation vector φ and its rate φ′ of non-linear mount i in its axes
    into s.loc[:4] (φ and φ′ NaN where its kind has no rotational law: it must not read
    them); its lever arm R·p into s.arm."""
    rot, q, qd, omega_f, phi, arm, loc = s.rot, s.q, s.qd, s.omega_f, s.phi, s.arm, s.loc
    phi_rate = s.phi_rate
    d0, d1, d2, e0, e1, e2 = point_motion(i, nl.point, rot, q, qd, omega_f, arm)
    _into_axes(nl, i, d0, d1, d2, loc[0])
    _into_axes(nl, i, e0, e1, e2, loc[1])
    if nl.rotational[i]:
        _into_axes(nl, i, phi[0], phi[1], phi[2], loc[2])
        _into_axes(nl, i, phi_rate[0], phi_rate[1], phi_rate[2], loc[3])
    else:
        for j in range(3):
            loc[2, j] = math.nan
            loc[3, j] = math.nan


@njit(cache=True, inline="always")
def _nl_load(i: int, y: np.ndarray, nl: NonLinearMounts, s: Scratch, dydt: np.ndarray) -> None:
    """Load of non-linear mount i in its axes into s.loc[4:6] (the couple as the kind gives
    it, a generalized force conjugate to φ: `_nl_couple` turns it into the couple on the body);
    its state rates into dydt."""
    _local_motion(i, nl, s)
    loc = s.loc
    kind_load(
        nl.kind[i],
        nl.par[i],
        y,
        nl.state[i],
        loc[0],
        loc[1],
        loc[2],
        loc[3],
        dydt,
        loc[4],
        loc[5],
    )


@njit(cache=True, inline="always")
def mount_loads(y: np.ndarray, m: ModelArrays, s: Scratch, dydt: np.ndarray) -> None:
    """Sum the mount loads on the body into s.total_force and s.total_moment (F, about the CG);
    internal-state rates of the mounts that have them into dydt."""
    total_f, total_m = s.total_force, s.total_moment
    arm, f, c = s.arm, s.force, s.couple
    rot, q, qd, omega_f = s.rot, s.q, s.qd, s.omega_f
    phi, phi_rate, cmap = s.phi, s.phi_rate, s.couple_map
    point, k_t, c_t, k_r, c_r = m.lin_point, m.lin_k_t, m.lin_c_t, m.lin_k_r, m.lin_c_r
    for j in range(3):
        total_f[j] = 0.0
        total_m[j] = 0.0
    for i in range(point.shape[0]):
        linear_mount_load(
            i, point, k_t, c_t, k_r, c_r, rot, q, qd, omega_f, phi, phi_rate, cmap, arm, f, c
        )
        _add_load(arm, f, c, total_f, total_m)
    nl_loads(y, m.nl, s, dydt)


@kernel
def _nl_loads(y: np.ndarray, nl: NonLinearMounts, s: Scratch, dydt: np.ndarray) -> None:
    """Add the non-linear mounts' loads to the totals; their state rates into dydt."""
    total_f, total_m = s.total_force, s.total_moment
    arm, f, c, loc = s.arm, s.force, s.couple, s.loc
    for i in range(nl.kind.shape[0]):
        _nl_load(i, y, nl, s, dydt)
        _out_of_axes(nl, i, loc[4], f)  # back from mount axes to F
        if nl.rotational[i]:
            _nl_couple(i, nl, s, c)
        else:
            c[0], c[1], c[2] = 0.0, 0.0, 0.0
        _add_load(arm, f, c, total_f, total_m)


@njit(cache=True, inline="always")
def _nl_couple(i: int, nl: NonLinearMounts, s: Scratch, c: np.ndarray) -> None:
    """c = J(φ)⁻ᵀ·Qᵢ·s.loc[5]: the couple on the body (F) of the generalized force non-linear
    mount i gave in its axes (`linear_mount`'s module docstring says why)."""
    cmap = s.couple_map
    _out_of_axes(nl, i, s.loc[5], c)
    c0, c1, c2 = c[0], c[1], c[2]
    for j in range(3):
        c[j] = cmap[j, 0] * c0 + cmap[j, 1] * c1 + cmap[j, 2] * c2


@njit(cache=True, inline="always")
def _add_load(arm, f, c, total_f, total_m) -> None:
    total_f[0] += f[0]
    total_f[1] += f[1]
    total_f[2] += f[2]
    total_m[0] += arm[1] * f[2] - arm[2] * f[1] + c[0]
    total_m[1] += arm[2] * f[0] - arm[0] * f[2] + c[1]
    total_m[2] += arm[0] * f[1] - arm[1] * f[0] + c[2]


@kernel
def mount_wrenches(y: np.ndarray, m: ModelArrays, s: Scratch, wrenches: np.ndarray) -> None:
    """Each mount's force (N) and own couple (N·m) on the body, in its axes: wrenches[i]."""
    arm, f, c = s.arm, s.force, s.couple
    rot, q, qd, omega_f = s.rot, s.q, s.qd, s.omega_f
    phi, phi_rate, cmap = s.phi, s.phi_rate, s.couple_map
    point, k_t, c_t, k_r, c_r = m.lin_point, m.lin_k_t, m.lin_c_t, m.lin_k_r, m.lin_c_r
    axes, slot = m.lin_axes, m.lin_slot
    for i in range(point.shape[0]):
        linear_mount_load(
            i, point, k_t, c_t, k_r, c_r, rot, q, qd, omega_f, phi, phi_rate, cmap, arm, f, c
        )
        row = slot[i]
        for j in range(3):
            wrenches[row, j] = axes[i, 0, j] * f[0] + axes[i, 1, j] * f[1] + axes[i, 2, j] * f[2]
            wrenches[row, 3 + j] = (
                axes[i, 0, j] * c[0] + axes[i, 1, j] * c[1] + axes[i, 2, j] * c[2]
            )
    nl_wrenches(y, m.nl, s, wrenches)


@kernel
def _nl_wrenches(y: np.ndarray, nl: NonLinearMounts, s: Scratch, wrenches: np.ndarray) -> None:
    loc, c = s.loc, s.couple
    for i in range(nl.kind.shape[0]):
        _nl_load(i, y, nl, s, s.sink)
        if nl.rotational[i]:  # the couple on the body, in the mount's axes
            _nl_couple(i, nl, s, c)
            _into_axes(nl, i, c[0], c[1], c[2], loc[5])
        row = nl.slot[i]
        for j in range(3):
            wrenches[row, j] = loc[4, j]
            wrenches[row, 3 + j] = loc[5, j]


@kernel
def mount_monitors(
    y: np.ndarray,
    y0: np.ndarray,
    nl: NonLinearMounts,
    s: Scratch,
    g: np.ndarray,
    util: np.ndarray,
) -> bool:
    """Event functions g[i] and utilisation util[i] of each non-linear mount at state y (whose
    body motion `evaluate` or `rhs` has just computed; y0: the state at the previous sample,
    for trial functions); then their discrete switches. Returns whether one switched (y
    jumped)."""
    loc = s.loc
    switched = False
    for i in range(nl.kind.shape[0]):
        _local_motion(i, nl, s)
        code, p, o = nl.kind[i], nl.par[i], nl.state[i]
        util[i] = kind_monitor(code, p, y, y0, o, loc[0], loc[1], g[i])
        if kind_update(code, p, y, o, loc[0]):
            switched = True
    return switched


nl_loads = skip_if_none(_nl_loads)
nl_wrenches = skip_if_none(_nl_wrenches)


def _rhs(
    t: float, y: np.ndarray, m: ModelArrays, s: Scratch, u: np.ndarray, dydt: np.ndarray
) -> int:
    """dy/dt at time t (s); returns OK or OFF_CHART."""
    ct = body_motion(y, m, s)
    if not ct > 0.0:
        return OFF_CHART
    mount_loads(y, m, s, dydt)
    nt, nr = m.free_trans.shape[0], m.free_rot.shape[0]
    nf = nt + nr
    for k in range(nf):
        dydt[k] = y[nf + k]
    tau = t - u[0]
    f_s, big_w, big_w_dot = s.f_s, s.big_w, s.big_w_dot
    for i in range(3):
        f_s[i] = u[1 + i] + u[4 + i] * tau
        big_w[i] = u[7 + i] + u[10 + i] * tau
        big_w_dot[i] = u[10 + i]
    if nt > 0:
        _translational(m, s, dydt, nf)
    if nr > 0 and not _rotational(m, s, ct, dydt, nf + nt):
        return OFF_CHART
    return OK


rhs = kernel(_rhs)
"""dy/dt at time t (s); returns OK or OFF_CHART. A function of its own: a call passes the
model's and the scratch's arrays (some 400 machine words), about 90 ns on the genset."""
rhs_inlined = njit(cache=True, inline="always")(_rhs)
"""`rhs` inlined into its caller, without the call: for the one call site that runs at every
stage of every step (Dormand–Prince's stage loop: the genset's right-hand side 0.50 → 0.40 µs)."""


@njit(cache=True, inline="always")
def _cross(a: np.ndarray, b: np.ndarray, i: int) -> float:
    if i == 0:
        return a[1] * b[2] - a[2] * b[1]
    if i == 1:
        return a[2] * b[0] - a[0] * b[2]
    return a[0] * b[1] - a[1] * b[0]


@njit(cache=True, inline="always")
def _translational(m: ModelArrays, s: Scratch, dydt: np.ndarray, nf: int) -> None:
    """Free translational accelerations (physics notes §6) into dydt[nf:nf + nt]."""
    q, qd, f_s, w, w_dot = s.q, s.qd, s.f_s, s.big_w, s.big_w_dot
    rel, wxr, total_f = s.rel, s.w_x_rel, s.total_force
    cg_ref, sensor, free_trans = m.cg_ref, m.sensor_position, m.free_trans
    for i in range(3):
        rel[i] = cg_ref[i] + q[i] - sensor[i]
    for i in range(3):
        wxr[i] = _cross(w, rel, i)
    inv_mass = 1.0 / m.mass
    for k in range(free_trans.shape[0]):
        i = free_trans[k]
        frame = 2.0 * _cross(w, qd, i) + _cross(w_dot, rel, i) + _cross(w, wxr, i)
        dydt[nf + k] = total_f[i] * inv_mass - f_s[i] - frame


@njit(cache=True, inline="always")
def _rotational(m: ModelArrays, s: Scratch, ct: float, dydt: np.ndarray, first: int) -> bool:
    """Free rotational accelerations (projected Euler equations) into dydt[first:first + nr].

    Returns False if the reduced mass matrix is numerically singular (near the chart edge).
    """
    rot, kin, kin_rate, qd, omega, trig = s.rot, s.kin, s.kin_rate, s.qd, s.omega, s.trig
    w, w_dot, total_m = s.big_w, s.big_w_dot, s.total_moment
    moment_b, w_b, w_dot_b, acc = s.moment_b, s.w_b, s.w_dot_b, s.acc
    w_abs, h, i_w, mass_rot, rhs_rot = s.w_abs, s.h, s.i_w, s.mass_rot, s.rhs_rot
    inertia, free_rot = m.inertia, m.free_rot
    kinematic_matrix_rate(trig[0], trig[3], trig[1], trig[4], ct, qd[3], qd[4], kin_rate)
    # In B: mount moment, Ωᴮ = RᵀΩ and RᵀΩ'.
    for i in range(3):
        moment_b[i] = rot[0, i] * total_m[0] + rot[1, i] * total_m[1] + rot[2, i] * total_m[2]
        w_b[i] = rot[0, i] * w[0] + rot[1, i] * w[1] + rot[2, i] * w[2]
        w_dot_b[i] = rot[0, i] * w_dot[0] + rot[1, i] * w_dot[1] + rot[2, i] * w_dot[2]
    # ω_a' = B q'' + acc, with acc = B'q' − ω × Ωᴮ + RᵀΩ'
    for i in range(3):
        bdq = kin_rate[i, 0] * qd[3] + kin_rate[i, 1] * qd[4] + kin_rate[i, 2] * qd[5]
        acc[i] = bdq - _cross(omega, w_b, i) + w_dot_b[i]
        w_abs[i] = omega[i] + w_b[i]
    for i in range(3):
        i_w[i] = inertia[i, 0] * w_abs[0] + inertia[i, 1] * w_abs[1] + inertia[i, 2] * w_abs[2]
    for i in range(3):
        i_acc = inertia[i, 0] * acc[0] + inertia[i, 1] * acc[1] + inertia[i, 2] * acc[2]
        h[i] = moment_b[i] - _cross(w_abs, i_w, i) - i_acc
    # Reduced mass matrix Jᵀ I J and right side Jᵀ h, J = the free columns of B; its lower
    # triangle only (what the Cholesky factorisation reads), row a as (I·J_a)ᵀ J_b.
    nr = free_rot.shape[0]
    for a in range(nr):
        ca = free_rot[a]
        k0, k1, k2 = kin[0, ca], kin[1, ca], kin[2, ca]
        rhs_rot[a] = k0 * h[0] + k1 * h[1] + k2 * h[2]
        i0 = inertia[0, 0] * k0 + inertia[0, 1] * k1 + inertia[0, 2] * k2
        i1 = inertia[1, 0] * k0 + inertia[1, 1] * k1 + inertia[1, 2] * k2
        i2 = inertia[2, 0] * k0 + inertia[2, 1] * k1 + inertia[2, 2] * k2
        for b in range(a + 1):
            cb = free_rot[b]
            mass_rot[a, b] = i0 * kin[0, cb] + i1 * kin[1, cb] + i2 * kin[2, cb]
    if not _solve_spd(mass_rot, rhs_rot, nr):
        return False
    for a in range(nr):
        dydt[first + a] = rhs_rot[a]
    return True


@njit(cache=True, inline="always")
def _solve_spd(a: np.ndarray, b: np.ndarray, n: int) -> bool:
    """Solve a[:n, :n] x = b[:n] in place (Cholesky; a keeps its factor L in its lower
    triangle); False if a is not positive definite."""
    for j in range(n):
        d = a[j, j]
        for k in range(j):
            d -= a[j, k] ** 2
        if not d > 0.0:
            return False
        d = math.sqrt(d)
        a[j, j] = d
        for i in range(j + 1, n):
            e = a[i, j]
            for k in range(j):
                e -= a[i, k] * a[j, k]
            a[i, j] = e / d
    _cholesky_solve(a, b, n)
    return True


@njit(cache=True, inline="always")
def _cholesky_solve(low: np.ndarray, b: np.ndarray, n: int) -> None:
    """Solve L Lᵀ x = b[:n] in place, L the lower triangle of low."""
    for i in range(n):
        e = b[i]
        for k in range(i):
            e -= low[i, k] * b[k]
        b[i] = e / low[i, i]
    for i in range(n - 1, -1, -1):
        e = b[i]
        for k in range(i + 1, n):
            e -= low[k, i] * b[k]
        b[i] = e / low[i, i]


@kernel
def evaluate(
    y: np.ndarray, m: ModelArrays, s: Scratch, pose: np.ndarray, wrenches: np.ndarray
) -> float:
    """Outputs at state y; returns cos θ (NaN off the chart, outputs then untouched).

    Args:
        pose: out (pose_row.WIDTH,): a pose row (`physics/pose_row.py`).
        wrenches: out (n, 6): each mount's force (N) and couple (N·m) on the body, in its axes.
    """
    ct = body_motion(y, m, s)
    if not ct > 0.0:
        return math.nan
    outputs(y, m, s, pose, wrenches)
    return ct


@kernel
def outputs(
    y: np.ndarray, m: ModelArrays, s: Scratch, pose: np.ndarray, wrenches: np.ndarray
) -> None:
    """`evaluate` when s already holds the body motion at y (the last `rhs` was at y)."""
    mount_wrenches(y, m, s, wrenches)
    q, quat, cg_ref = s.q, s.quat, m.cg_ref
    if not m.rotation_read:  # body_motion left it
        quaternion_from_matrix(s.rot, quat)
    for i in range(3):
        pose[pose_row.POSITION + i] = cg_ref[i] + q[i]
        pose[pose_row.ANGLES + i] = q[3 + i]
    for i in range(4):
        pose[pose_row.QUATERNION + i] = quat[i]


@kernel
def rhs_after_rate_step(m: ModelArrays, s: Scratch, d_wdot: np.ndarray, dydt: np.ndarray) -> None:
    """Move dydt, the right-hand side of the last `rhs` call (whose kinematics and factored
    reduced mass matrix s still holds), to an input whose Ω' changed by d_wdot (rad/s², F), with
    the state, Ω and the specific force unchanged: at a sample of a first-order-hold input only
    Ω' jumps, and this costs a few dozen flops instead of a right-hand side.

    Ω' enters linearly: −Ω' × (r − s) in the translational rows, and −I·RᵀΩ' in the projected
    Euler equations, whose reduced mass matrix Jᵀ I J is already factored.
    """
    nt, nr = m.free_trans.shape[0], m.free_rot.shape[0]
    nf = nt + nr
    rel = s.rel
    for k in range(nt):
        dydt[nf + k] -= _cross(d_wdot, rel, m.free_trans[k])
    if nr == 0:
        return
    rot, kin, inertia, b = s.rot, s.kin, m.inertia, s.rhs_rot
    dw_b, h = s.w_dot_b, s.h  # scratch reuse: the rate step in B, its moment
    for i in range(3):
        dw_b[i] = rot[0, i] * d_wdot[0] + rot[1, i] * d_wdot[1] + rot[2, i] * d_wdot[2]
    for i in range(3):
        h[i] = -(inertia[i, 0] * dw_b[0] + inertia[i, 1] * dw_b[1] + inertia[i, 2] * dw_b[2])
    for a in range(nr):
        ca = m.free_rot[a]
        b[a] = kin[0, ca] * h[0] + kin[1, ca] * h[1] + kin[2, ca] * h[2]
    _cholesky_solve(s.mass_rot, b, nr)
    for a in range(nr):
        dydt[nf + nt + a] += b[a]
