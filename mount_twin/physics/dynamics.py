"""Equations of motion on the free generalized coordinates, in the moving foundation frame F.

State y = [q_f, q_f', z] where q_f is the free subset of q = (X, Y, Z, α, γ, δ) (m, rad) in the
order of `DOF_NAMES` and z the internal states of the mounts that have them (mount_twin.kinds);
frozen coordinates keep the values in `ModelArrays.q_fixed`. The CG velocity
is r' = (X', Y', Z') and the body angular velocity relative to F is ω = B(α, γ)·(α', γ', δ'), both
linear in q'. Projecting Newton–Euler on q_f (Kane's method) gives, exactly for any subset,

    translation:  q_t'' = F/m − f_s − [2Ω×r' + Ω'×(r − s) + Ω×(Ω×(r − s))]   (physics notes §6)
    rotation:     (Jᵀ I J) q_r'' = Jᵀ [M − ω_a × I ω_a − I(B' q_r' − ω×Ωᴮ + RᵀΩ')],  J = B[:, free]

With all three rotations free J = B is square and invertible on the chart, and the rotation
rows are q_r'' = B⁻¹·I⁻¹·[…]: the core solves them so (B⁻¹ in closed form), and factors the
reduced mass matrix Jᵀ I J only for fewer free rotations.

with f_s the specific force at sensor point s, Ω the foundation angular velocity (in F),
Ωᴮ = RᵀΩ, ω_a = ω + Ωᴮ the absolute angular velocity and M the mount moment about the CG (in B).

Input over one sample interval is u = [t0, f0, ḟ, Ω0, Ω̇] (13 floats): f(t) = f0 + ḟ·(t − t0) and
Ω(t) = Ω0 + Ω̇·(t − t0); a zero-order hold passes zero slopes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mount_twin import _core

OK = 0
OFF_CHART = 1
"""Right-hand-side status: the attitude left the chart (cos θ ≤ COS_TILT_MIN)."""

COS_TILT_MIN = _core.COS_TILT_MIN
"""cos θ below which the state counts as off the chart (1e-6): B grows like 1/cos θ and the
reduced mass matrix loses positive definiteness in floating point long before cos θ reaches
zero."""

INPUT_SIZE = _core.INPUT_SIZE
"""Floats of the input u (13)."""


class ModelArrays(NamedTuple):
    """Flat arrays of an assembled scene, as the compiled core reads them (SI, frames as named;
    src/core/model.hpp is its view of them, and the core checks every field's dtype and shape
    at each call).

    Linear mounts are the lin_ arrays (zero-length if none); all other kinds are `nl`, None for
    a scene without them (the core then skips their loop).
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
    lin_per_rating: np.ndarray  # (n, 6): 1/rated travel (1/m), then 1/rated load (1/N), along
    # the mount's axes x, y, z; 0 where unrated (`engine.kernel.Published.lin_util`)
    nl: NonLinearMounts | None  # the other kinds; None compiles their code away
    rotation_read: bool  # a mount reads the body's rotation vector (linear ones, rotational kinds)


class NonLinearMounts(NamedTuple):
    """Mounts of the kinds in mount_twin.kinds (k of them), as the core reads them."""

    kind: np.ndarray  # int64 (k,): kind code
    point: np.ndarray  # (k, 3) m, attachment point from the CG, in B
    axes: np.ndarray  # (k, 3, 3) mount axes Q (columns) in F
    slot: np.ndarray  # int64 (k,): index in the scene
    state: np.ndarray  # int64 (k,): offset of the mount's internal states in y (−1: none)
    par: np.ndarray  # (k, N_PAR) parameter rows, columns per kind
    rotational: np.ndarray  # bool (k,): the kind has a rotational law (its ROTATIONAL)
    aligned: np.ndarray  # bool (k,): the mount's axes are F's (axes[i] = I: nothing to rotate)


class Scratch(NamedTuple):
    """Preallocated work arrays, so the core allocates nothing per call.

    Which call fills which fields, and who may read them after it (a field holds what its
    last writer left; nothing else is promised):

    - `body_motion(y)` fills q, qd, trig, rot, kin, omega, omega_f, and phi with its
      quaternion quat, its rate phi_rate and the couple map where a mount reads them
      (`ModelArrays.rotation_read`; else phi, phi_rate and the map are NaN and quat is left,
      for `outputs` to take): read by the mount laws and the rest of `rhs` at that y.
    - `mount_loads` (inside `rhs`) fills total_force, total_moment (the linear mounts' own
      couples summed through one law: it is linear in their K_r, C_r), and for the non-linear
      mounts sink (their internal-state rates go into dydt; their motion and loads are the
      core's locals).
    - `rhs(t, y, u)` fills all of the above, then f_s, big_w, big_w_dot, rel, w_x_rel,
      kin_rate, moment_b, w_b, w_dot_b, acc, w_abs, h, i_w, and with fewer than three free
      rotations rhs_rot and mass_rot (the Cholesky factor of Jᵀ I J; with three, B⁻¹·I⁻¹
      solves and they are left as they were). `outputs(y)` may follow only if that last `rhs`
      was at y (the stepper's last stage is: first same as last); `rhs_after_rate_step` moves
      that last stage to a new Ω' through the same solve (trig, rot, kin, mass_rot).
    - `run_samples` fills rate_step (the jump of Ω' at a sample): read by
      `rhs_after_rate_step`.
    - `mount_wrenches`, `mount_monitors`, `outputs` and `evaluate` (which calls `body_motion`
      first) overwrite sink where the model has non-linear mounts; their results go to the
      caller's arrays.
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
        sink=np.zeros(n_state),
    )


# The compiled implementations (src/core/physics/dynamics.hpp: the same equations, the
# operations in the order written above): the model's assembly, the analyses and the tests call
# them from Python; the loop (`engine.kernel.run_samples`) calls them inside the core.
body_motion = _core.body_motion
"""Fill s.q, s.qd, s.trig, s.rot, s.kin, s.omega, s.omega_f (and s.phi, s.quat, s.phi_rate,
s.couple_map where m.rotation_read, else NaN) from y; returns cos θ (NaN off the chart)."""
rhs = _core.rhs
"""rhs(t, y, m, s, u, dydt) -> OK | OFF_CHART: dy/dt at time t (s) under the input u."""
evaluate = _core.evaluate
"""evaluate(y, m, s, pose, wrenches) -> cos θ: outputs at state y (NaN off the chart, outputs
then untouched); pose: a `pose_row` row; wrenches (n, 6): each mount's force (N) and couple
(N·m) on the body, in its axes."""
outputs = _core.outputs
"""`evaluate` when s already holds the body motion at y (the last `rhs` was at y)."""
mount_wrenches = _core.mount_wrenches
"""mount_wrenches(y, m, s, wrenches): each mount's force (N) and couple (N·m), in its axes."""
mount_deflections = _core.mount_deflections
"""mount_deflections(y, m, s, d) -> cos θ: each non-linear mount's deflection (m) in its axes
at y into d (k, 3); NaN off the chart (d not written)."""
linear_utilisation = _core.linear_utilisation
"""linear_utilisation(y, m, s, wrenches, peak): fold each linear mount's utilisation at the
body motion of y that s holds (the largest over its axes of |travel| / rated travel and
|force| / rated load, `ModelArrays.lin_per_rating`) into peak, its running maxima."""
mount_monitors = _core.mount_monitors
"""mount_monitors(y, y0, nl, s, g, util) -> switched: event functions g[i] and utilisation
util[i] of each non-linear mount at y (its body motion just computed; y0 the state at the
previous sample), then their discrete switches; returns whether one switched (y jumped)."""
rhs_after_rate_step = _core.rhs_after_rate_step
"""rhs_after_rate_step(m, s, d_wdot, dydt): move dydt, the last `rhs` result (whose kinematics,
and with fewer than three free rotations factored reduced mass matrix, s holds), to an input
whose Ω' changed by d_wdot (rad/s², F): Ω' enters linearly, so this costs a few dozen flops
instead of a right-hand side."""
