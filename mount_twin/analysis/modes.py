"""Natural frequencies and mode shapes of the body on its mounts, about its static equilibrium.

The stiffness and damping are the twin's own: its right-hand side linearised (central
differences) about the static equilibrium under nominal gravity, so every mount kind enters by
its tangent stiffness there, and the preload of the weight adds its geometric stiffness. The
same about the unstressed reference pose without gravity gives the stiffness without that
geometric part (`geometric=False`). With the mass matrix M (m for translations; Bᵀ·I·B for the
angles α, γ, δ, B the chart's kinematic matrix) the linearisation gives K = −M·∂q″/∂q and
C = −M·∂q″/∂q′. Modes solve K·φ = ω²·M·φ (scipy.linalg.eigh), mass-normalised (φᵀMφ = 1).

Per mode: frequency (Hz); modal damping ζ = φᵀCφ/(2ω) (the proportional-damping
approximation); the kinetic energy fraction in each DOF, φ_j·(Mφ)_j (they sum to 1); effective
modal masses along x, y, z of F (kg) and about them (kg·m²), which sum over the modes to the
body's mass and inertia. Per mount: its static wrench and the deflection of its attachment
point from the unstressed position, in its axes. The elastic centre: the point about which the
translational and rotational stiffness are least coupled (least squares), against the CG.
Internal states of the mounts (slip, hysteresis, …) are held at their equilibrium values.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh

from mount_twin.engine.linear_rating import matrices_from_quaternions
from mount_twin.model.assemble import Model, assemble, gravity_input, initial_state
from mount_twin.physics import pose_row
from mount_twin.physics.dynamics import evaluate, rhs
from mount_twin.physics.rotations import rpy_matrix
from mount_twin.scene.description import DOF_NAMES, Scene

PHYSICAL = (1.0, 1.0, 1.0, 1.0, -1.0, 1.0)
"""Small changes of (x, y, z, α, γ, δ) as (translation, rotation vector) in F: pitch = −γ."""


@dataclass(frozen=True)
class Mode:
    """One mode (units in the module docstring; DOFs by name)."""

    frequency_hz: float
    damping_ratio: float
    shape: dict[str, float]
    energy_fraction: dict[str, float]
    effective_mass_kg: dict[str, float]
    effective_inertia_kg_m2: dict[str, float]


@dataclass(frozen=True)
class MountLoad:
    """A mount's static force (N) and couple (N·m) in its axes, and the deflection (m) of its
    attachment point from the unstressed position along them."""

    name: str
    force_n: tuple[float, float, float]
    couple_nm: tuple[float, float, float]
    deflection_m: tuple[float, float, float]


@dataclass(frozen=True)
class Modes:
    """The modal analysis of a scene."""

    dofs: tuple[str, ...]
    modes: list[Mode]
    mounts: list[MountLoad]
    mass_matrix: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    cg_m: tuple[float, float, float]
    elastic_centre_m: tuple[float, float, float] | None


def _jacobian(model: Model, y0: np.ndarray, u: np.ndarray) -> np.ndarray:
    """∂(dy/dt)/∂y of the coordinates and rates, by central differences."""
    nf = len(model.scene.dofs)
    s = model.new_scratch()
    out = np.zeros((2 * nf, 2 * nf))
    plus, minus = np.zeros(model.n_state), np.zeros(model.n_state)
    for k in range(2 * nf):
        h = 1e-7 * max(1.0, abs(y0[k]))
        y = y0.copy()
        y[k] += h
        rhs(0.0, y, model.arrays, s, u, plus)
        y[k] -= 2 * h
        rhs(0.0, y, model.arrays, s, u, minus)
        out[:, k] = (plus[: 2 * nf] - minus[: 2 * nf]) / (2 * h)
    return out


def mass_matrix(scene: Scene, angles: np.ndarray) -> np.ndarray:
    """M of the free DOFs at chart angles (α, γ, δ) rad."""
    a, g = angles[0], angles[1]
    ct = np.sqrt(np.cos(g) ** 2 - np.sin(a) ** 2)
    b = np.array(
        [
            [np.cos(a) / ct, np.sin(a) * np.sin(g) / (np.cos(g) * ct), np.sin(g)],
            [0.0, -ct / np.cos(g), np.sin(a)],
            [0.0, np.sin(a) / np.cos(g), ct],
        ]
    )
    ixx, iyy, izz, ixy, ixz, iyz = scene.body.inertia
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    full = np.zeros((6, 6))
    full[:3, :3] = scene.body.mass * np.eye(3)
    full[3:, 3:] = b.T @ inertia @ b
    idx = [DOF_NAMES.index(d) for d in scene.dofs]
    return full[np.ix_(idx, idx)]


def modes(scene: Scene, *, geometric: bool = True) -> Modes:
    """The modal analysis (see the module docstring) of `scene`."""
    model = assemble(scene)
    nf = len(scene.dofs)
    g_up = np.array([0.0, 0.0, scene.input.g])
    y_eq = initial_state(model, g_up)
    if geometric:
        y_lin, u = y_eq, gravity_input(0.0, g_up)
    else:
        unloaded = dataclasses.replace(scene.initial, mode="given", velocity=(0.0,) * 6)
        y_lin = initial_state(assemble(dataclasses.replace(scene, initial=unloaded)), g_up)
        u = gravity_input(0.0, np.zeros(3))
    angles = np.zeros(3)
    for k, d in enumerate(scene.dofs):
        if d in ("alpha", "gamma", "delta"):
            angles[("alpha", "gamma", "delta").index(d)] = y_lin[k]
    m = mass_matrix(scene, angles)
    jac = _jacobian(model, y_lin, u)
    k_mat = -m @ jac[nf:, :nf]
    c_mat = -m @ jac[nf:, nf:]
    k_sym, c_sym = 0.5 * (k_mat + k_mat.T), 0.5 * (c_mat + c_mat.T)
    w2, phi = eigh(k_sym, m)
    found = []
    sign = np.array([PHYSICAL[DOF_NAMES.index(d)] for d in scene.dofs])
    for i in range(nf):
        v = phi[:, i]
        omega = float(np.sqrt(max(w2[i], 0.0)))
        mv = m @ v
        energy = v * mv
        rigid = np.zeros((6, nf))
        for k, d in enumerate(scene.dofs):
            rigid[DOF_NAMES.index(d), k] = sign[k]
        gamma_p = rigid @ mv  # participation along x, y, z and about x, y, z of F
        found.append(
            Mode(
                frequency_hz=omega / (2 * np.pi),
                damping_ratio=float(v @ c_sym @ v / (2 * omega)) if omega > 0 else float("nan"),
                shape=dict(zip(scene.dofs, v.tolist(), strict=True)),
                energy_fraction=dict(
                    zip(scene.dofs, (energy / energy.sum()).tolist(), strict=True)
                ),
                effective_mass_kg={
                    a: float(gamma_p[j] ** 2) for j, a in enumerate("xyz") if rigid[j].any()
                },
                effective_inertia_kg_m2={
                    a: float(gamma_p[3 + j] ** 2)
                    for j, a in enumerate("xyz")
                    if rigid[3 + j].any()
                },
            )
        )
    return Modes(
        scene.dofs,
        found,
        _mount_loads(scene, model, y_eq),
        m,
        k_sym,
        c_sym,
        tuple(float(v) for v in scene.body.cg),  # type: ignore[arg-type]
        _elastic_centre(scene, k_sym),
    )


def _mount_loads(scene: Scene, model: Model, y: np.ndarray) -> list[MountLoad]:
    pose, wrenches = np.zeros(pose_row.WIDTH), np.zeros((model.n_mounts, 6))
    evaluate(y, model.arrays, model.new_scratch(), pose, wrenches)
    rot = matrices_from_quaternions(pose[None, pose_row.QUATERNION_COLS])[0]
    q = pose[pose_row.POSITION_COLS] - np.array(scene.body.cg)
    out = []
    for i, mt in enumerate(scene.mounts):
        p = np.array(mt.position) - np.array(scene.body.cg)
        d = rpy_matrix(*mt.orientation_rpy).T @ (q + rot @ p - p)
        w = wrenches[i]
        out.append(
            MountLoad(mt.name, tuple(w[:3].tolist()), tuple(w[3:].tolist()), tuple(d.tolist()))
        )  # type: ignore[arg-type]
    return out


def _elastic_centre(scene: Scene, k: np.ndarray) -> tuple[float, float, float] | None:
    """The point e (m, F) about which the translation–rotation coupling of K is least: with
    K in (translation, rotation vector) about the CG, the coupling about e is
    K_tr + K_tt·[e]×; e minimises its Frobenius norm. None unless all six DOFs are free."""
    if len(scene.dofs) != 6:
        return None
    s = np.diag(PHYSICAL)
    kk = s @ k @ s
    ktt, ktr = kk[:3, :3], kk[:3, 3:]
    rows, rhs_v = [], []
    for j in range(3):  # K_tt·[e]× column j = K_tt·(e × unit_j) = −K_tt·[unit_j]×·e
        unit = np.eye(3)[j]
        skew = np.array([[0, -unit[2], unit[1]], [unit[2], 0, -unit[0]], [-unit[1], unit[0], 0]])
        rows.append(-ktt @ skew)
        rhs_v.append(-ktr[:, j])
    e, *_ = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs_v), rcond=None)
    return tuple((np.array(scene.body.cg) + e).tolist())  # type: ignore[return-value]
