"""Natural frequencies and mode shapes of the body on its mounts, about its static equilibrium.

Everything comes from the twin itself, so every mount kind enters as it is simulated:

- Equilibrium: the model's own solver (`static_equilibrium`) under the scene's nominal gravity
  (specific force g along +z of F, foundation at rest), as the twin starts a new machine: the
  mounts' internal states at zero but the hysteretic ones on their loading curves
  (`model.loading`), then made admissible at its pose as every start's are
  (`model.assemble.settle`): a joint face the weight slid has its stick point on its friction
  bound, where it holds a small motion across the slide with its stick stiffness k_τ (about
  the stick point zero, a face past its bound, it held it with μ·F_K over the slide: a wall-hung
  block's lateral mode 15.7 Hz where it is 24.5).
- Linearisation: central differences (`model.stiffness.jacobian`) of the twin's right-hand side
  about it give ∂q″/∂q, ∂q″/∂q′, ∂q″/∂s and ∂s′/∂q′ (q: the free coordinates, m and rad; s: the
  mounts' internal states). The kinds expose no closed tangent, so this is how elastomers,
  bolted joints (closed joint k_S + k_P, stuck face k_τ) and shear keys (nothing inside their
  clearance) enter: by their tangent at equilibrium; a law with a kink exactly there (a key
  with zero clearance and no load) enters with the mean of its two slopes. Internal states are
  rate-independent (Bouc–Wen z, slip, plastic elongation): at rest s′ = S·q′, so for small
  motions s − s_eq = S·(q − q_eq), and their forces add to the stiffness (a Bouc–Wen axis at z
  adds (1 − a)·k₀·(A − γ·|z|ⁿ) to its tangent a·F_el′: the mean of its loading and unloading
  slopes, A − (β + γ)·|z|ⁿ and A + (β − γ)·|z|ⁿ, which meet at z = 0).
- Matrices, in the generalized coordinates q (the twin's: X, Y, Z of the CG and the chart angles
  α, γ, δ; units kg, kg·m², N/m, N/rad, N·m/rad, N·s/m, N·m·s/rad): with P (6×n) the map from
  q′ to the CG velocity and the angular velocity in F at equilibrium (P = blockdiag(1, R·B), R
  the attitude, B the chart's kinematic matrix; on a level pose α, γ, δ turn about x, −y, z of
  F), M = Pᵀ·diag(m·1, R·I·Rᵀ)·P (the mass matrix about the CG in F's axes, in q),
  K = −M·(∂q″/∂q + ∂q″/∂s·S) and C = −M·∂q″/∂q′.
- Geometric stiffness: K, the tangent of the loaded twin, includes the preload's geometric
  stiffness K_geo = Pᵀ·[0 0; 0 Σᵢ (F₀ᵢ·aᵢ)·1 − aᵢ·F₀ᵢᵀ]·P (physics notes §7; F₀ᵢ the static
  force of mount i on the body and aᵢ its lever arm from the CG, both in F at equilibrium): the
  weight carried on arms that turn with the body, ≈ −m·g·h in roll and pitch for a CG h above
  the mounts. `geometric=False` takes K − K_geo, the elastic stiffness alone: Σ Tᵢᵀ·kᵢ·Tᵢ of the
  mounts' tangent k-matrices moved to the CG (Tᵢ = [1, −[aᵢ]×]) plus their rotational springs.
- Modes: K·φ = ω²·M·φ on the symmetric part of K (scipy.linalg.eigh), φᵀ·M·φ = 1; a negative
  ω² (an equilibrium the weight's geometric stiffness makes unstable) is reported as a negative
  frequency −√|ω²|/2π. `stiffness_asymmetry` says how far K is from symmetric (a law that is
  not the gradient of an energy; rotational springs are, at any rotation: `linear_mount`).
- Damping: ζᵢ = φᵢᵀ·C·φᵢ/(2ωᵢ), the proportional-damping approximation (exact when the
  modes' damping does not couple them); `complex_modes` are the exact eigenvalues λ of the
  linearised first-order system with the full K and C: frequency |λ|/2π and ζ = −Re λ/|λ| of
  every oscillating pair (Im λ > 0; overdamped, real λ are not listed).
- Per mode: kinetic energy fraction of each coordinate, φⱼ·(M·φ)ⱼ (they sum to 1; a negative one
  is energy exchanged through a product of inertia); the shape in F (CG translation, m, and
  rotation about x, y, z of F, rad: P·φ); effective modal masses along x, y, z of F (kg) and
  effective inertias about the axes of F through the CG (kg·m²): Lⱼ² with Lⱼ = φᵀ·Pᵀ·M_F·eⱼ the
  participation in a rigid motion of the foundation along eⱼ. Over all modes they sum to the
  body's mass (inertia about that axis) where the free coordinates make that rigid motion.
- Per mount: its static force and couple on the body, and the deflection of its attachment
  point from its unstressed position, in its own axes (the force in F too).
- Stiffness centre, from the elastic stiffness: with the compliance of the CG motion to a
  wrench about the CG in F, C_F = P·(K − K_geo)⁻¹·Pᵀ (rotation blocks C_rt, C_rr), a force along
  axis j through a point e (offset from the CG) turns the body by C_rt·eⱼ + C_rr·(e × eⱼ). For
  each free translation, the "force line" along j is where that turning has no component about
  the two other axes (z: the vertical stiffness centre, under which a vertical load makes a
  pure bounce). The elastic centre, where a force along any direction moves the body without
  turning it, needs [e]× = −G with G = C_rr⁻¹·C_rt (m): it exists exactly when G is
  skew-symmetric; otherwise the least-squares point e = −vee(skew G) is given with the
  residual ‖sym G‖ (m, Frobenius; 0 for an exact elastic centre). Positions are at the
  reference pose, in F.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import eig, eigh, solve

from mount_twin.model.assemble import (
    Model,
    assemble,
    gravity_input,
    settle,
    static_equilibrium,
)
from mount_twin.model.stiffness import jacobian
from mount_twin.physics.chart import kinematic_matrix, rotation_matrix
from mount_twin.physics.dynamics import evaluate
from mount_twin.physics.pose_row import WIDTH
from mount_twin.physics.rotations import rpy_matrix
from mount_twin.scene.description import DOF_NAMES, Scene

F_AXES = ("x", "y", "z", "rot_x", "rot_y", "rot_z")
"""Components of a motion in F: CG translation along x, y, z (m), rotation about them (rad)."""
RESOLVED = 1.0e-9
"""|ω²| below this fraction of the largest is zero: the central differences' rounding."""

Vec3 = tuple[float, float, float]
Line = tuple[float | None, float | None, float | None]


@dataclass(frozen=True)
class Mode:
    """One undamped mode.

    Attributes:
        frequency_hz: natural frequency, Hz (negative: unstable, −√|ω²|/2π).
        damping_ratio: φᵀCφ/(2ω), proportional-damping approximation (NaN if ω ≤ 0).
        shape: mass-normalised φ in the generalized coordinates (m or rad per √(kg) of modal
            mass, φᵀMφ = 1), by DOF name; its largest-energy component is positive.
        shape_in_f: P·φ, the same motion as CG translation (m) and rotation (rad) in F, by
            `F_AXES` name.
        energy_fraction: kinetic energy share φⱼ(Mφ)ⱼ of each DOF (sums to 1).
        effective_mass_kg: along x, y, z of F.
        effective_inertia_kg_m2: about the axes x, y, z of F through the CG.
    """

    frequency_hz: float
    damping_ratio: float
    shape: dict[str, float]
    shape_in_f: dict[str, float]
    energy_fraction: dict[str, float]
    effective_mass_kg: dict[str, float]
    effective_inertia_kg_m2: dict[str, float]

    @property
    def dominant_dof(self) -> str:
        """The DOF with the largest kinetic energy fraction."""
        return max(self.energy_fraction, key=self.energy_fraction.__getitem__)


@dataclass(frozen=True)
class ComplexMode:
    """An eigenvalue pair λ of the damped linearisation: |λ|/2π (Hz) and ζ = −Re λ/|λ|."""

    frequency_hz: float
    damping_ratio: float


@dataclass(frozen=True)
class MountLoad:
    """A mount at the static equilibrium: its force (N) and couple (N·m) on the body and the
    deflection (m) of its attachment point from its unstressed position, in its own axes; the
    force also in F (N)."""

    name: str
    kind: str
    force_n: Vec3
    couple_nm: Vec3
    deflection_m: Vec3
    force_in_f_n: Vec3


@dataclass(frozen=True)
class StiffnessCentre:
    """Where the elastic stiffness is centred (module docstring), m, in F at the reference pose;
    nothing if the elastic stiffness leaves a DOF free.

    Attributes:
        force_lines_m: per free translation axis j: the line along j through which a force
            turns the body about neither other axis, as its two other coordinates (None on j);
            "z" is the vertical stiffness centre. Empty without a free rotation.
        point_m: the elastic centre (least squares), with all six DOFs free; else None.
        residual_m: ‖sym G‖, 0 where an exact elastic centre exists; None with point_m.
    """

    force_lines_m: dict[str, Line]
    point_m: Vec3 | None
    residual_m: float | None


@dataclass(frozen=True)
class Modes:
    """The modal analysis of a scene (module docstring).

    Attributes:
        dofs: the generalized coordinates, in the order of the matrices.
        geometric: whether `stiffness` includes the preload's geometric stiffness.
        modes: by increasing frequency.
        complex_modes: by increasing |λ|.
        mounts: in scene order.
        mass_matrix, stiffness, damping: M, K (as used: with or without K_geo; unsymmetrised),
            C (n×n, SI, generalized coordinates).
        geometric_stiffness: K_geo (n×n).
        to_f: P (6×n): generalized rates → CG velocity (m/s) and angular velocity (rad/s) in F.
        cg_m: CG at the reference pose, m, in F.
        centre: the stiffness centre.
    """

    dofs: tuple[str, ...]
    geometric: bool
    modes: tuple[Mode, ...]
    complex_modes: tuple[ComplexMode, ...]
    mounts: tuple[MountLoad, ...]
    mass_matrix: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    geometric_stiffness: np.ndarray
    to_f: np.ndarray
    cg_m: Vec3
    centre: StiffnessCentre

    @property
    def stiffness_asymmetry(self) -> float:
        """‖K − Kᵀ‖/‖K‖ (Frobenius): 0 for a conservative linearisation."""
        k = self.stiffness
        return float(np.linalg.norm(k - k.T) / np.linalg.norm(k))


def modes(scene: Scene, *, geometric: bool = True) -> Modes:
    """The modal analysis of `scene` about its static equilibrium (module docstring); with
    `geometric` False the stiffness leaves out the preload's geometric stiffness."""
    model = assemble(scene)
    nf = len(scene.dofs)
    g_up = np.array([0.0, 0.0, scene.input.g])
    y_eq = static_equilibrium(model, np.zeros(model.n_state), g_up, loaded=True)
    settle(model, y_eq)  # as every start of the twin: a face the weight slid on its bound
    jac = jacobian(model, y_eq, gravity_input(0.0, g_up))
    q, v, s = slice(0, nf), slice(nf, 2 * nf), slice(2 * nf, model.n_state)
    q6 = model.arrays.q_fixed.copy()
    q6[[DOF_NAMES.index(d) for d in scene.dofs]] = y_eq[:nf]
    rot, to_f = _chart_map(scene, q6)
    mass_f = np.zeros((6, 6))
    mass_f[:3, :3] = model.arrays.mass * np.eye(3)
    mass_f[3:, 3:] = rot @ model.arrays.inertia @ rot.T
    mass = to_f.T @ mass_f @ to_f
    loads = _mount_loads(scene, model, y_eq, rot, q6[:3])
    k_geo = to_f.T @ _geometric_f(scene, rot, loads) @ to_f
    k_full = -mass @ (jac[v, q] + jac[v, s] @ jac[s, v])
    k_used = k_full if geometric else k_full - k_geo
    damping = -mass @ jac[v, v]
    return Modes(
        dofs=scene.dofs,
        geometric=geometric,
        modes=_modes(scene.dofs, mass, k_used, damping, to_f, mass_f),
        complex_modes=_complex_modes(mass, k_used, damping),
        mounts=loads,
        mass_matrix=mass,
        stiffness=k_used,
        damping=damping,
        geometric_stiffness=k_geo,
        to_f=to_f,
        cg_m=_vec3(scene.body.cg),
        centre=_centre(scene, k_full - k_geo, mass, to_f),
    )


def _chart_map(scene: Scene, q6: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Attitude R at coordinates q6 (m, rad) and P (6×n): q′ → (CG velocity, ω in F)."""
    alpha, gamma, delta = q6[3:]
    rot = rotation_matrix(alpha, gamma, delta)
    kin = np.empty((3, 3))
    sa, ca, sg, cg = math.sin(alpha), math.cos(alpha), math.sin(gamma), math.cos(gamma)
    kinematic_matrix(sa, ca, sg, cg, rot[2, 2], kin)
    full = np.zeros((6, 6))
    full[:3, :3] = np.eye(3)
    full[3:, 3:] = rot @ kin
    return rot, full[:, [DOF_NAMES.index(d) for d in scene.dofs]]


def _mount_loads(
    scene: Scene, model: Model, y: np.ndarray, rot: np.ndarray, shift: np.ndarray
) -> tuple[MountLoad, ...]:
    """Each mount's static wrench and deflection at state y (attitude rot, CG shift, m)."""
    wrenches = np.zeros((model.n_mounts, 6))
    evaluate(y, model.arrays, model.new_scratch(), np.zeros(WIDTH), wrenches)
    out = []
    for mt, w in zip(scene.mounts, wrenches, strict=True):
        axes = rpy_matrix(*mt.orientation_rpy)
        p = np.subtract(mt.position, scene.body.cg)
        out.append(
            MountLoad(
                name=mt.name,
                kind=mt.kind,
                force_n=_vec3(w[:3]),
                couple_nm=_vec3(w[3:]),
                deflection_m=_vec3(axes.T @ (shift + rot @ p - p)),
                force_in_f_n=_vec3(axes @ w[:3]),
            )
        )
    return tuple(out)


def _geometric_f(scene: Scene, rot: np.ndarray, loads: tuple[MountLoad, ...]) -> np.ndarray:
    """K_geo in F (6×6): Σ (F₀·a)·1 − a·F₀ᵀ in its rotation block."""
    k = np.zeros((6, 6))
    for mt, load in zip(scene.mounts, loads, strict=True):
        arm = rot @ np.subtract(mt.position, scene.body.cg)
        force = np.array(load.force_in_f_n)
        k[3:, 3:] += force @ arm * np.eye(3) - np.outer(arm, force)
    return k


def _modes(
    dofs: tuple[str, ...],
    mass: np.ndarray,
    stiffness: np.ndarray,
    damping: np.ndarray,
    to_f: np.ndarray,
    mass_f: np.ndarray,
) -> tuple[Mode, ...]:
    """Undamped modes of (M, sym K), with modal damping, energies and effective masses."""
    w2, phi = eigh(0.5 * (stiffness + stiffness.T), mass)
    found = []
    for i in range(len(dofs)):
        vec = phi[:, i]
        energy = vec * (mass @ vec)
        if vec[np.argmax(np.abs(energy))] < 0.0:
            vec = -vec
        resolved = abs(w2[i]) > RESOLVED * np.abs(w2).max()
        omega = math.copysign(math.sqrt(abs(w2[i])), w2[i]) if resolved else 0.0
        zeta = float(vec @ damping @ vec / (2.0 * omega)) if omega > 0.0 else math.nan
        participation = vec @ to_f.T @ mass_f
        found.append(
            Mode(
                frequency_hz=omega / (2.0 * math.pi),
                damping_ratio=zeta,
                shape=_named(dofs, vec),
                shape_in_f=_named(F_AXES, to_f @ vec),
                energy_fraction=_named(dofs, energy / energy.sum()),
                effective_mass_kg=_named("xyz", participation[:3] ** 2),
                effective_inertia_kg_m2=_named("xyz", participation[3:] ** 2),
            )
        )
    return tuple(found)


def _complex_modes(
    mass: np.ndarray, stiffness: np.ndarray, damping: np.ndarray
) -> tuple[ComplexMode, ...]:
    """Oscillating eigenvalue pairs of q″ = −M⁻¹(K·q + C·q′), by increasing |λ|."""
    n = mass.shape[0]
    state = np.zeros((2 * n, 2 * n))
    state[:n, n:] = np.eye(n)
    state[n:, :n] = -solve(mass, stiffness)
    state[n:, n:] = -solve(mass, damping)
    lam = eig(state, right=False)
    scale = float(np.abs(lam).max())
    pairs = sorted((x for x in lam if x.imag > 1e-9 * scale), key=abs)
    return tuple(ComplexMode(abs(x) / (2.0 * math.pi), -x.real / abs(x)) for x in pairs)


def _centre(
    scene: Scene, elastic: np.ndarray, mass: np.ndarray, to_f: np.ndarray
) -> StiffnessCentre:
    """Force lines and elastic centre of the elastic stiffness (module docstring); none if the
    mounts alone leave a DOF free (a body hanging below them, held in swing by its weight)."""
    sym = 0.5 * (elastic + elastic.T)
    w2 = eigh(sym, mass, eigvals_only=True)
    if w2[0] <= RESOLVED * w2[-1]:
        return StiffnessCentre({}, None, None)
    compliance = to_f @ solve(sym, to_f.T, assume_a="sym")
    c_rt, c_rr = compliance[3:, :3], compliance[3:, 3:]
    cg = np.array(scene.body.cg)
    lines: dict[str, Line] = {}
    free_rot = {"alpha", "gamma", "delta"} & set(scene.dofs)
    for j, axis in enumerate("xyz"):
        if axis not in scene.dofs or not free_rot:
            continue
        others = [k for k in range(3) if k != j]
        turn = c_rr @ _skew(np.eye(3)[j])  # the turning is C_rt·eⱼ − C_rr·[eⱼ]×·e
        e, *_ = np.linalg.lstsq(turn[others], c_rt[others, j], rcond=None)
        at = [None if k == j else float(cg[k] + e[k]) for k in range(3)]
        lines[axis] = (at[0], at[1], at[2])
    if len(scene.dofs) < 6:
        return StiffnessCentre(lines, None, None)
    g = solve(c_rr, c_rt, assume_a="sym")
    skew = 0.5 * (g - g.T)
    offset = -np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
    return StiffnessCentre(lines, _vec3(cg + offset), float(np.linalg.norm(0.5 * (g + g.T))))


def _skew(v: np.ndarray) -> np.ndarray:
    """[v]×: [v]×·w = v × w."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _named(names: tuple[str, ...] | str, values: np.ndarray) -> dict[str, float]:
    return {name: float(x) for name, x in zip(names, values, strict=True)}


def _vec3(values: np.ndarray | tuple[float, ...]) -> Vec3:
    x, y, z = (float(v) for v in values)
    return x, y, z
