"""Small-motion statics of a scene about its reference pose, from each mount's nominal tangent:
cheap enough to run at every load (1000 mounts, half of them elastomers, in 80 ms), and
independent of the model.

Coordinates (physics notes §7): u = (X, Y, Z, θx, θy, θz), the CG's displacement in F (m) and
the body's small rotation about the axes of F (rad); at the reference pose the chart angles
α, γ, δ turn the body about x, −y and z of F, so θ names them alpha, gamma, delta (the sign of
γ does not matter to anything here). With aᵢ the lever arm of mount i (its position minus the
CG, in F), Tᵢ = [1, −[aᵢ]×] its attachment point's displacement, kᵢ = Qᵢ·diag(k_t)·Qᵢᵀ and
Qᵢ·diag(k_r)·Qᵢᵀ its tangents in F:
- elastic stiffness K = Σ Tᵢᵀ·kᵢ·Tᵢ plus the rotational springs;
- static sag under the nominal weight W = (0, 0, −m·g, 0, 0, 0): K·u = W on the free DOFs
  (least squares if K is singular), each mount's deflection Tᵢ·u and force −kᵢ·Tᵢ·u;
- geometric stiffness of that preload, Σ (F₀ᵢ·aᵢ)·1 − aᵢ·F₀ᵢᵀ, in the rotational block: the
  weight's restoring (or overturning) moment on arms that turn with the body. It holds a
  pendulum's swing, which no mount stiffness holds.
- a direction of the free DOFs is unheld when neither holds it: it is in the null space of the
  elastic stiffness and the geometric stiffness has no component along it (a body on mounts
  all at one point turns freely about the vertical through it). A direction along which the
  total stiffness is negative is overturned: the weight topples the body there.
- the body's fastest mode on the tangents (`fastest_rate`), and whether its stiff modes are its
  linear mounts' alone (`linear_stiffness`: no law with pieces, the non-linear mounts soft),
  the rule by which `integration.method: auto` takes the exponential method and the loader
  warns where it is asked for by name against it.

Nominal tangent of each kind (`nominal_tangent`), what a kind counts as at its unstressed pose:
- linear: its stiffness;
- elastomer: a·F_el′(0) + (1 − a)·k₀·A per axis (the force table's slope at 0 or k₁, with
  Bouc–Wen hysteresis at z = 0), its rotational stiffness; snubbers are open;
- bolted joint: the closed joint k_S + k_P along the bolt and the stuck face k_τ across it
  (friction, clamped by the preload or the weight), or without friction the shank bearing k_b,
  even with a clearance, as a key; no rotational stiffness (one bolt carries no moment);
- shear key: its stiffness along its stiff axes, even with a clearance: a key, like a
  frictionless face in its hole's clearance, lets the body move by the clearance, not drift
  (within it the body rests free: a neutral equilibrium, held at the clearance's edge).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mount_twin.kinds import KINDS
from mount_twin.physics.rotations import rpy_matrices
from mount_twin.scene.description import DOF_NAMES, LinearMount, Mount, Scene

RESOLVED = 1.0e-10
"""An eigenvalue of a mass-scaled stiffness (ω², rad²/s²) within this fraction of the largest
is zero: a DOF held 10⁵ times more loosely in frequency than the stiffest is not held (sums
over 1000 mounts round at ~1e-13)."""

AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Tangent:
    """A mount's nominal tangent in its local axes: stiffness (kx, ky, kz) N/m and
    (krx, kry, krz) N·m/rad, and the key each value comes from (for messages)."""

    stiffness: tuple[float, ...]
    keys: tuple[str, ...]


@dataclass(frozen=True)
class Statics:
    """The scene's small-motion statics about its reference pose (see the module docstring).
    A mount too soft to carry the weight at all (stiffness ~1e-300) makes sag, deflection,
    force and stiffness non-finite: `finite` says whether they are numbers.

    Attributes:
        tangents: each mount's nominal tangent, in the order of scene.mounts.
        elastic: 6×6 stiffness of the mounts over (X, Y, Z, θx, θy, θz) (N/m, N, N·m/rad).
        geometric: 6×6 geometric stiffness of the weight's preload (rotational block only, not
            symmetric in general), N·m/rad.
        mass: 6×6 diag(m, m, m) and the inertia tensor (kg, kg·m²).
        sag: (6,) static displacement u under the nominal weight, frozen DOFs at 0 (m, rad).
        deflection: (n, 3) each mount's attachment point displacement in its local axes, m.
        force: (n, 3) each mount's static force on the body in its local axes, N.
    """

    tangents: tuple[Tangent, ...]
    elastic: np.ndarray
    geometric: np.ndarray
    mass: np.ndarray
    sag: np.ndarray
    deflection: np.ndarray
    force: np.ndarray

    @property
    def finite(self) -> bool:
        """True if every figure is a finite number."""
        return all(np.isfinite(a).all() for a in (self.geometric, self.sag, self.force))


def nominal_tangent(mount: Mount) -> Tangent:
    """The nominal tangent of `mount` at its unstressed pose (module docstring): a linear
    mount's stiffness, or what its kind's module says (`nominal_tangent`, a name every kind
    must define: `kinds.MODULE_NAMES`)."""
    if isinstance(mount, LinearMount):
        return Tangent(mount.stiffness, tuple(f"stiffness[{j}]" for j in range(6)))
    return Tangent(*KINDS[mount.kind].nominal_tangent(mount))


def _skew(v: np.ndarray) -> np.ndarray:
    """[v]× of each row of v, (n, 3) → (n, 3, 3)."""
    out = np.zeros((*v.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    return out - np.swapaxes(out, -1, -2)


def statics(scene: Scene) -> Statics:
    """The small-motion statics of `scene` under its nominal weight m·input.g along −z of F."""
    body, mounts = scene.body, scene.mounts
    mass = np.zeros((6, 6))
    mass[:3, :3] = body.mass * np.eye(3)
    mass[3:, 3:] = body.inertia_tensor()
    axes = rpy_matrices([m.orientation_rpy for m in mounts])
    tangents = tuple(nominal_tangent(m) for m in mounts)
    k = np.array([t.stiffness for t in tangents])
    k_t = np.einsum("nij,nj,nkj->nik", axes, k[:, :3], axes)
    k_r = np.einsum("nij,nj,nkj->nik", axes, k[:, 3:], axes)
    arm = np.array([m.position for m in mounts]) - np.array(body.cg)
    # T = [1, −S] with S = [a]×, so Tᵀ·k·T = [[k, −k·S], [S·k, −S·k·S]]
    s = _skew(arm)
    elastic = np.zeros((6, 6))
    elastic[:3, :3] = k_t.sum(axis=0)
    elastic[:3, 3:] = -(k_t @ s).sum(axis=0)
    elastic[3:, :3] = (s @ k_t).sum(axis=0)
    elastic[3:, 3:] = (k_r - s @ k_t @ s).sum(axis=0)
    free = [DOF_NAMES.index(d) for d in scene.dofs]
    weight = np.array([0.0, 0.0, -body.mass * scene.input.g, 0.0, 0.0, 0.0])
    sag = np.zeros(6)
    with np.errstate(all="ignore"):  # overflow is reported by Statics.finite
        sag[free] = np.linalg.lstsq(elastic[np.ix_(free, free)], weight[free], rcond=None)[0]
        deflection = sag[:3] - s @ sag[3:]  # in F, (n, 3)
        force = -np.einsum("nij,nj->ni", k_t, deflection)
        geometric = np.zeros((6, 6))
        geometric[3:, 3:] = np.einsum("ni,ni", force, arm) * np.eye(3) - arm.T @ force
    return Statics(
        tangents=tangents,
        elastic=elastic,
        geometric=geometric,
        mass=mass,
        sag=sag,
        deflection=np.einsum("nji,nj->ni", axes, deflection),
        force=np.einsum("nji,nj->ni", axes, force),
    )


def fastest_rate(scene: Scene) -> float:
    """The fastest mode (rad/s) of the body of `scene` on its mounts' nominal tangents
    (`statics`), free DOFs only; 0 if it is not a number."""
    st = statics(scene)
    if not st.finite:
        return 0.0
    free = [DOF_NAMES.index(d) for d in scene.dofs]
    k, m = st.elastic[np.ix_(free, free)], st.mass[np.ix_(free, free)]
    omega2 = np.linalg.eigvals(np.linalg.solve(m, k))
    return float(np.sqrt(np.abs(omega2).max()))


NONLINEAR_SHARE = 0.1
"""`linear_stiffness`: the non-linear mounts alone move the body at most this share of its
fastest rate. 10 kg on 4 × 1e9 N/m beside a 1e4 N/m Bouc–Wen elastomer (a share of 1.6e-3) is
4.2e-9 of the largest force off by the exponential method at rtol 1e-3 … 1e-9, 4.0e-4 … 2.8e-7 by
the Rosenbrock; on four 1e9 N/m Bouc–Wen elastomers of strong hysteresis (share 1) the
exponential method's estimate read 0.06 of its error at rtol 1e-3, and at 1e-9 it was 3.6e-6 off
where the Rosenbrock was 3.3e-7 (docs/scene.md)."""


def piecewise_mounts(scene: Scene) -> list[int]:
    """The mounts whose force law has pieces their motion moves between (their kind's
    `piecewise`: a contact, a joint's faces; linear mounts have none), by index."""
    return [
        i
        for i, m in enumerate(scene.mounts)
        if not isinstance(m, LinearMount) and KINDS[m.kind].piecewise(m)
    ]


def linear_stiffness(scene: Scene, fastest: float | None = None) -> bool:
    """Whether the body's stiff modes are its linear mounts': no mount's law has pieces
    (`piecewise_mounts`), and on its non-linear mounts alone the body's fastest mode is at most
    NONLINEAR_SHARE of its fastest on all of them (`fastest`, rad/s, where the caller holds
    it; else `fastest_rate`). Where it holds the exponential method is exact on the stiff part
    (`Model.linear_stiffness`)."""
    if piecewise_mounts(scene):
        return False
    nonlinear = tuple(m for m in scene.mounts if not isinstance(m, LinearMount))
    if not nonlinear:
        return True
    alone = fastest_rate(replace(scene, mounts=nonlinear))
    return alone <= NONLINEAR_SHARE * (fastest_rate(scene) if fastest is None else fastest)


def loose_dofs(st: Statics, dofs: tuple[str, ...]) -> tuple[dict[str, float], dict[str, float]]:
    """The free `dofs` that nothing holds and those the weight overturns (module docstring),
    each DOF with its kinetic-energy share in those directions (1: the DOF alone; below 1: a
    direction coupling several). Stiffnesses are scaled by the mass matrix's diagonal, so
    their eigenvalues are ω² (rad²/s²), and taken symmetric. Needs `st.finite`."""
    free = [DOF_NAMES.index(d) for d in dofs]
    scale = np.outer(*[1.0 / np.sqrt(np.diag(st.mass)[free])] * 2)
    elastic, geometric = (
        0.5 * (k[np.ix_(free, free)] + k[np.ix_(free, free)].T) * scale
        for k in (st.elastic, st.geometric)
    )
    lam, vec = np.linalg.eigh(elastic)
    total = np.linalg.eigh(elastic + geometric)
    tol = RESOLVED * max(np.abs(lam).max(), np.abs(total.eigenvalues).max())
    null = vec[:, np.abs(lam) <= tol]
    mu, along = np.linalg.eigh(null.T @ geometric @ null)
    unheld = null @ along[:, np.abs(mu) <= tol]
    return _shares(dofs, unheld), _shares(dofs, total.eigenvectors[:, total.eigenvalues < -tol])


def _shares(dofs: tuple[str, ...], vectors: np.ndarray) -> dict[str, float]:
    """Each DOF's summed squared component in `vectors` (columns), largest first, above 0.5 %."""
    share = (vectors**2).sum(axis=1)
    order = np.argsort(-share, kind="stable")
    return {dofs[i]: float(share[i]) for i in order if share[i] > 0.005}
