"""Independent reference helpers for the physics tests (not a conftest: import explicitly).

Everything here is written from the physics notes (docs/physics.md) and textbook
mechanics, without calling the package's numerics, so the tests compare the twin against an
independent truth. The only package calls are thin drivers (scene building, stepping).
"""

from __future__ import annotations

import copy
import math
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from mount_twin.integrate import stepper as stepper_mod
from mount_twin.model.assemble import Model, assemble
from mount_twin.physics.dynamics import INPUT_SIZE, OK, rhs
from mount_twin.scene import scene_from_dict

G = 9.80665


# ----------------------------------------------------------------------------- linear algebra
def skew(v: np.ndarray) -> np.ndarray:
    """[v]× such that [v]× w = v × w."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def vee(m: np.ndarray) -> np.ndarray:
    """Inverse of `skew` on the skew part of m."""
    a = 0.5 * (m - m.T)
    return np.array([a[2, 1], a[0, 2], a[1, 0]])


def inertia_tensor(ixx, iyy, izz, ixy, ixz, iyz) -> np.ndarray:
    """Tensor from URDF-ordered elements (off-diagonals are the tensor's entries)."""
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float)


def rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """REP-103 fixed-axis roll, pitch, yaw = Rz(yaw)·Ry(pitch)·Rx(roll), via scipy."""
    return Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_matrix()


# ----------------------------------------------------------------------------- attitude chart
def chart_to_matrix_ref(alpha: float, gamma: float, delta: float) -> np.ndarray:
    """R(α, γ, δ) built from the notes §2 as REP-103 yaw = δ, pitch = −γ,
    roll = atan2(sin α, cos θ),
    cos θ = √(cos²γ − sin²α) (positive on the chart)."""
    ct = math.sqrt(math.cos(gamma) ** 2 - math.sin(alpha) ** 2)
    roll = math.atan2(math.sin(alpha), ct)
    return rpy(roll, -gamma, delta)


def matrix_to_chart_ref(rot: np.ndarray) -> tuple[float, float, float]:
    """(α, γ, δ) of R from the notes §2 definitions."""
    return math.asin(rot[2, 1]), math.asin(rot[2, 0]), math.atan2(rot[1, 0], rot[0, 0])


def kinematic_matrix_ref(alpha: float, gamma: float) -> np.ndarray:
    """B(α, γ) of the notes §3, ω = B·[α', γ', δ'] (ω relative to F, in B)."""
    sa, ca, sg, cg = math.sin(alpha), math.cos(alpha), math.sin(gamma), math.cos(gamma)
    ct = math.sqrt(cg * cg - sa * sa)
    return np.array(
        [
            [ca / ct, sa * sg / (cg * ct), sg],
            [0.0, -ct / cg, sa],
            [0.0, sa / cg, ct],
        ]
    )


def rotation_angle_between(r1: np.ndarray, r2: np.ndarray) -> float:
    """Angle (rad) of r1ᵀ r2, robust near zero."""
    return float(np.linalg.norm(Rotation.from_matrix(r1.T @ r2).as_rotvec()))


# ----------------------------------------------------------------------------- scenes
def base_scene(
    mass: float,
    cg: list[float],
    inertia: list[float],
    mounts: list[dict[str, Any]],
    dofs: list[str] | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-13,
    initial: dict[str, Any] | None = None,
    max_substeps: int = 100000,
) -> dict[str, Any]:
    """A scene mapping in the layout of config/*.scene.yaml."""
    data: dict[str, Any] = {
        "name": "physics_test",
        "body": {"mass": mass, "cg": list(cg), "inertia": list(inertia)},
        "mounts": copy.deepcopy(mounts),
        "dofs": list(dofs or ["x", "y", "z", "alpha", "gamma", "delta"]),
        "input": {"includes_gravity": True, "hold": "first_order", "max_gap_s": 10.0},
        "initial_state": initial or {"mode": "equilibrium", "gravity": "first_sample"},
        "integration": {"rtol": rtol, "atol": atol, "max_substeps": max_substeps},
    }
    return data


def free_body(
    inertia: list[float], omega0: np.ndarray, v0: tuple[float, ...] = (0.0, 0.0, 0.0)
) -> dict[str, Any]:
    """A 10 kg body held by nothing (one mount of zero stiffness), CG 0.3 m above F's origin,
    started at the identity pose with CG velocity v0 (m/s, F) and body rate omega0 (rad/s,
    B): a torque-free flight under zero specific force."""
    rates = np.linalg.solve(kinematic_matrix_ref(0.0, 0.0), omega0)
    return base_scene(
        10.0,
        [0.0, 0.0, 0.3],
        inertia,
        [mount("nothing", [0.0, 0.0, 0.0], [0.0] * 6)],
        initial={"mode": "given", "pose": [0.0] * 6, "velocity": [*v0, *rates]},
    )


def build(data: dict[str, Any]) -> Model:
    """Validated, assembled model of a scene mapping."""
    return assemble(scene_from_dict(data, "<physics test>"))


def mount(name, position, stiffness, damping=None, rpy_=(0.0, 0.0, 0.0)) -> dict[str, Any]:
    """One linear mount mapping."""
    return {
        "name": name,
        "position": [float(v) for v in position],
        "orientation_rpy": [float(v) for v in rpy_],
        "stiffness": [float(v) for v in stiffness],
        "damping": [float(v) for v in (damping if damping is not None else [0.0] * 6)],
    }


# ----------------------------------------------------------------------------- driving the twin
def gravity_u(specific_force=(0.0, 0.0, G)) -> np.ndarray:
    """Input vector u of a foundation at rest with the given specific force."""
    u = np.zeros(INPUT_SIZE)
    u[1:4] = specific_force
    return u


def integrate_twin(
    model: Model, y0: np.ndarray, times: np.ndarray, u: np.ndarray, rtol: float, atol: float
) -> np.ndarray:
    """States of the twin at `times` (first = start) via the package's own stepper interface
    (dormand_prince + advance). u is one input for the whole run: f(t) = f0 + ḟ·(t − u[0]) and
    Ω(t) = Ω0 + Ω̇·(t − u[0])."""
    st = stepper_mod.dormand_prince(y0.shape[0], rtol, atol, 10_000_000)
    s = model.new_scratch()
    y = y0.astype(float).copy()
    out = np.zeros((times.shape[0], y.shape[0]))
    out[0] = y
    for j in range(1, times.shape[0]):
        status = stepper_mod.advance(
            st.method,
            y,
            times[j - 1],
            times[j],
            st.settings,
            model.arrays,
            s,
            u,
            st.work2d,
            st.work1d,
            st.result,
        )
        assert status == 0, f"stepper failed with status {status} at t={times[j - 1]}"
        out[j] = y
    return out


def twin_rhs(model: Model, y: np.ndarray, u: np.ndarray, t: float = 0.0) -> np.ndarray:
    """dy/dt of the twin."""
    s = model.new_scratch()
    dydt = np.zeros_like(y)
    status = rhs(t, y.astype(float).copy(), model.arrays, s, u, dydt)
    assert status == OK
    return dydt


def twin_jacobian(model: Model, y0: np.ndarray, u: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """Central-difference state Jacobian of the twin's rhs at y0."""
    n = y0.shape[0]
    jac = np.zeros((n, n))
    for k in range(n):
        yp, ym = y0.copy(), y0.copy()
        yp[k] += h
        ym[k] -= h
        jac[:, k] = (twin_rhs(model, yp, u) - twin_rhs(model, ym, u)) / (2 * h)
    return jac


def natural_frequencies_from_jacobian(jac: np.ndarray) -> np.ndarray:
    """Sorted |Im λ| of an undamped second-order system's state Jacobian, one per mode (rad/s)."""
    lam = np.linalg.eigvals(jac)
    im = np.sort(np.abs(lam.imag))
    return im[1::2]  # each mode appears as a ±iω pair


# ------------------------------------------------------------------------- independent mount model
def mount_frames(scene_data: dict[str, Any]) -> list[dict[str, np.ndarray]]:
    """Per mount: attachment point p from the CG (m), K_t, K_r (F) from the scene mapping, §7."""
    cg = np.array(scene_data["body"]["cg"], dtype=float)
    out = []
    for mt in scene_data["mounts"]:
        q = rpy(*mt["orientation_rpy"])
        k = np.array(mt["stiffness"], dtype=float)
        out.append(
            {
                "p": np.array(mt["position"], dtype=float) - cg,
                "kt": q @ np.diag(k[:3]) @ q.T,
                "kr": q @ np.diag(k[3:]) @ q.T,
            }
        )
    return out


def inverse_left_jacobian(phi: np.ndarray) -> np.ndarray:
    """J_l⁻¹(φ) of SO(3): log(exp([θ]×)·exp([φ]×)) = φ + J_l⁻¹(φ)·θ + O(θ²), the inverse left
    Jacobian (Solà, Deray and Atchuthan, "A micro Lie theory for state estimation in robotics",
    2018, appendix on SO(3))."""
    angle = float(np.linalg.norm(phi))
    w = skew(phi)
    if angle < 1e-8:
        return np.eye(3) - 0.5 * w
    coef = 1.0 / angle**2 - (1.0 + math.cos(angle)) / (2.0 * angle * math.sin(angle))
    return np.eye(3) - 0.5 * w + coef * w @ w


def spring_couple_ref(kr: np.ndarray, rot: np.ndarray) -> np.ndarray:
    """Couple (N·m, F) of a rotational spring of stiffness kr (F) on a body at attitude R: minus
    the gradient of ½ φᵀ·kr·φ (φ the rotation vector of R) over a small turn θ of the body in
    F, −J_l⁻ᵀ(φ)·kr·φ (notes §7)."""
    phi = Rotation.from_matrix(rot).as_rotvec()
    return -inverse_left_jacobian(phi).T @ kr @ phi


def spring_tangent_ref(kr: np.ndarray, rot: np.ndarray, h: float = 1e-7) -> np.ndarray:
    """−∂(couple)/∂θ of `spring_couple_ref` at R (N·m/rad, F), θ a small turn in F: central
    differences over exp([θ]×)·R."""
    out = np.zeros((3, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        plus, minus = (
            spring_couple_ref(kr, Rotation.from_rotvec(s * e).as_matrix() @ rot) for s in (1, -1)
        )
        out[:, k] = (minus - plus) / (2 * h)
    return out


def mount_wrench_ref(
    frames, r: np.ndarray, rot: np.ndarray
) -> tuple[np.ndarray, np.ndarray, list]:
    """Static mount load on the body (force, moment about the CG, both in F) for CG displacement r
    and attitude R (notes §7), plus each mount's force."""
    f_tot, m_tot, forces = np.zeros(3), np.zeros(3), []
    for fr in frames:
        arm = rot @ fr["p"]
        d = r + arm - fr["p"]
        f = -fr["kt"] @ d
        forces.append(f)
        f_tot += f
        m_tot += np.cross(arm, f) + spring_couple_ref(fr["kr"], rot)
    return f_tot, m_tot, forces


# -------------------------------------------------------------------------- torque-free reference
def quaternion_euler_rhs(inertia: np.ndarray):
    """d/dt of (quaternion x, y, z, w of the attitude; ω in the body) for a torque-free rigid
    body in an inertial frame: q' = ½ q ⊗ (ω, 0), I ω' = −ω × I ω."""

    def f(_t, x):
        qx, qy, qz, qw = x[:4]
        w = x[4:]
        dq = 0.5 * np.array(
            [
                qw * w[0] + qy * w[2] - qz * w[1],
                qw * w[1] + qz * w[0] - qx * w[2],
                qw * w[2] + qx * w[1] - qy * w[0],
                -qx * w[0] - qy * w[1] - qz * w[2],
            ]
        )
        dw = np.linalg.solve(inertia, -np.cross(w, inertia @ w))
        return np.concatenate([dq, dw])

    return f


def torque_free_reference(inertia: np.ndarray, omega0: np.ndarray, times: np.ndarray):
    """Tight DOP853 solution of `quaternion_euler_rhs` from the identity attitude with body rate
    omega0 (rad/s), sampled at `times` (s)."""
    ref = solve_ivp(
        quaternion_euler_rhs(inertia),
        (0.0, float(times[-1])),
        np.concatenate([[0.0, 0.0, 0.0, 1.0], omega0]),
        t_eval=times,
        rtol=1e-12,
        atol=1e-14,
        method="DOP853",
    )
    assert ref.success, ref.message
    return ref
