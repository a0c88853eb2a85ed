"""Assemble a Scene into the flat arrays the compiled core reads, and find its start state."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from mount_twin.errors import ModelError, require
from mount_twin.kinds import CODES, KINDS, N_EVENTS, N_PAR, check_dispatch
from mount_twin.model import newton
from mount_twin.model.loading import VirginAxes, virgin_axes
from mount_twin.model.ratings import start_ratings
from mount_twin.physics.dynamics import (
    INPUT_SIZE,
    OK,
    ModelArrays,
    NonLinearMounts,
    Scratch,
    mount_deflections,
    mount_monitors,
    new_scratch,
    rhs,
)
from mount_twin.physics.jacobian import STEP as CENTRAL_STEP
from mount_twin.physics.jacobian import central_columns
from mount_twin.physics.rotations import rpy_matrices, rpy_matrix
from mount_twin.scene.built import check_built
from mount_twin.scene.description import DOF_NAMES, LinearMount, Mount, Scene
from mount_twin.scene.statics import (
    fastest_rate,
    linear_stiffness,
    loose_dofs,
    piecewise_mounts,
    statics,
)


@dataclass(frozen=True)
class Model:
    """A scene ready to integrate.

    Attributes:
        scene: the description it was built from, with the warnings of its start
            (`model.ratings`).
        arrays: the core's arrays.
        state_names: name of each state entry (q of free DOFs, then their rates).
        sensor_rotation: 3×3 rotation of the input sensor frame into F.
        nominal_state: the start state of a new machine under nominal gravity (the scene's
            input.g along +z of F): its given motion, or its static equilibrium, solved at
            assembly so that a scene whose mounts cannot hold the body fails at load. The
            twin starts here when no equilibrium holds under its first samples.
    """

    scene: Scene
    arrays: ModelArrays
    state_names: tuple[str, ...]
    sensor_rotation: np.ndarray
    nominal_state: np.ndarray

    @property
    def n_state(self) -> int:
        """Length of the state vector."""
        return len(self.state_names)

    @property
    def nonlinear_slots(self) -> list[int]:
        """Scene index of each mount of a kind in mount_twin.kinds, in the core's order."""
        nl = self.arrays.nl
        return [] if nl is None else nl.slot.tolist()

    @property
    def n_mounts(self) -> int:
        """Number of mounts."""
        return len(self.scene.mounts)

    def new_scratch(self) -> Scratch:
        """Work arrays for the core."""
        return new_scratch(self.n_state)

    @cached_property
    def piecewise(self) -> bool:
        """Whether some mount's force law has pieces its motion moves between
        (`scene.statics.piecewise_mounts`)."""
        return bool(piecewise_mounts(self.scene))

    @cached_property
    def kinked(self) -> bool:
        """Whether some mount's law has kinks inside an interval that none of its events marks
        (its kind's `kinked`: a Bouc–Wen state's rate, with |ẋ|; `engine.companion`
        KINKED_CHECK)."""
        return any(KINDS[m.kind].kinked(m) for m in self._nonlinear_mounts)

    @cached_property
    def linear_stiffness(self) -> bool:
        """Whether the body's stiff modes are its linear mounts' (`scene.statics.
        linear_stiffness`): the exponential method is exact on the linear part and steps the
        non-linear remainder explicitly, so `auto` takes it for a stiff scene only where this
        holds, and the error estimate's companion beside a Rosenbrock twin too
        (`engine.companion.own_method`)."""
        return linear_stiffness(self.scene, self.tangent_rate)

    @property
    def _nonlinear_mounts(self) -> tuple[Mount, ...]:
        """The mounts of a kind in mount_twin.kinds, in the core's order (`nonlinear_slots`)."""
        return tuple(self.scene.mounts[i] for i in self.nonlinear_slots)

    @cached_property
    def tangent_rate(self) -> float:
        """The fastest mode (rad/s) of the body on its mounts' nominal tangents (keys and
        frictionless joints' shanks bearing, bolted joints closed, snubbers open;
        `scene.statics`), free DOFs only; 0 if it is not a number. `integration.method: auto`
        weighs it at every start (`engine.auto_method`): taken once per model, not at each
        engine's start (0.1–0.2 ms each)."""
        return fastest_rate(self.scene)


def _inverse(rated: tuple[float, ...]) -> list[float]:
    """1/rating per axis, 0 where unrated (0)."""
    return [1.0 / v if v > 0.0 else 0.0 for v in rated]


def assemble(scene: Scene) -> Model:
    """Build the core's arrays of `scene` and solve its nominal start state (done once, at
    load; raises ModelError where the mounts cannot hold the body, SceneError for a value of
    a scene built in code that no loader would have taken: `scene.built`). The model's scene
    adds to its warnings the mounts past their ratings at that start, where the loader left
    them to it (`model.ratings`)."""
    require(scene, Scene, "assemble(scene)")
    check_built(scene)
    body = scene.body
    inertia = np.array(body.inertia_tensor())
    cg = np.array(body.cg)
    mounts = scene.mounts
    axes = rpy_matrices([mt.orientation_rpy for mt in mounts])

    lin = [i for i, mt in enumerate(mounts) if isinstance(mt, LinearMount)]
    other = [i for i, mt in enumerate(mounts) if not isinstance(mt, LinearMount)]
    stiffness = np.array([mounts[i].stiffness for i in lin]).reshape(-1, 6)  # type: ignore[union-attr]
    damping = np.array([mounts[i].damping for i in lin]).reshape(-1, 6)  # type: ignore[union-attr]
    lin_axes = axes[lin].reshape(-1, 3, 3)
    free = [DOF_NAMES.index(d) for d in scene.dofs]
    names = [*scene.dofs, *(f"{d}_dot" for d in scene.dofs)]
    offsets = []
    for i in other:
        own = KINDS[mounts[i].kind].state_names(mounts[i])
        offsets.append(len(names) if own else -1)
        names.extend(own)
    points = np.array([mt.position for mt in mounts]).reshape(-1, 3) - cg
    nl = _nonlinear(mounts, other, points, axes, offsets) if other else None
    arrays = ModelArrays(
        mass=float(body.mass),
        inertia=inertia,
        cg_ref=cg,
        sensor_position=np.array(scene.input.sensor_position),
        free_trans=np.array([i for i in free if i < 3], dtype=np.int64),
        free_rot=np.array([i - 3 for i in free if i >= 3], dtype=np.int64),
        q_fixed=np.array(scene.initial.pose, dtype=float),
        lin_point=points[lin].reshape(-1, 3),
        lin_axes=lin_axes,
        lin_k_t=in_f(lin_axes, stiffness[:, :3]),
        lin_c_t=in_f(lin_axes, damping[:, :3]),
        lin_k_r=in_f(lin_axes, stiffness[:, 3:]),
        lin_c_r=in_f(lin_axes, damping[:, 3:]),
        lin_slot=np.array(lin, dtype=np.int64),
        lin_per_rating=np.array(
            [_inverse((*mounts[i].rated_travel, *mounts[i].rated_load)) for i in lin]  # type: ignore[union-attr]
        ).reshape(-1, 6),
        nl=nl,
        rotation_read=bool(lin) or (nl is not None and bool(nl.rotational.any())),
    )
    unsolved = Model(scene, arrays, tuple(names), rpy_matrix(*scene.input.sensor_rpy), np.empty(0))
    start = initial_state(unsolved, np.array([0.0, 0.0, scene.input.g]))
    found = start_ratings(scene, arrays, start)
    if found:  # a scene assembled twice (the command line's, then the engine's) says them once
        scene = replace(scene, warnings=tuple(dict.fromkeys((*scene.warnings, *found))))
    return replace(unsolved, scene=scene, nominal_state=start)


def in_f(axes: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Q·diag(values)·Qᵀ per mount: a diagonal law in mount axes, expressed in F."""
    return np.einsum("nij,nj,nkj->nik", axes, values, axes)


def _nonlinear(
    mounts: tuple, index: list[int], points: np.ndarray, axes: np.ndarray, offsets: list[int]
) -> NonLinearMounts:
    """Kernel arrays of the mounts at `index` (kinds of mount_twin.kinds), once the compiled
    dispatchers are known to run each kind's own law (`kinds.check_dispatch`, once a process)."""
    check_dispatch()
    par = np.zeros((len(index), N_PAR))
    for row, i in enumerate(index):
        own = KINDS[mounts[i].kind].pack(mounts[i])
        par[row, : own.shape[0]] = own
    return NonLinearMounts(
        kind=np.array([CODES[mounts[i].kind] for i in index], dtype=np.int64),
        point=points[index],
        axes=axes[index],
        slot=np.array(index, dtype=np.int64),
        state=np.array(offsets, dtype=np.int64),
        par=par,
        rotational=np.array([KINDS[mounts[i].kind].ROTATIONAL for i in index], dtype=np.bool_),
        aligned=np.array([np.array_equal(axes[i], np.eye(3)) for i in index], dtype=np.bool_),
    )


def gravity_input(
    t0: float, specific_force: np.ndarray, rate_rad_s: np.ndarray | None = None
) -> np.ndarray:
    """Input vector u of a foundation with the given specific force (m/s², F), at rest or
    turning steadily at `rate_rad_s` (Ω, rad/s, F; Ω′ = 0)."""
    u = np.zeros(INPUT_SIZE)
    u[0] = t0
    u[1:4] = specific_force
    if rate_rad_s is not None:
        u[7:10] = rate_rad_s
    return u


def initial_state(
    model: Model,
    specific_force: np.ndarray,
    rate_rad_s: np.ndarray | None = None,
    internal: np.ndarray | None = None,
) -> np.ndarray:
    """Start state: the scene's given pose and velocity, or static equilibrium.

    In equilibrium mode the free coordinates are those where all generalized accelerations vanish
    with the foundation under `specific_force` (m/s², F; +g·z for gravity), at rest or turning
    steadily at `rate_rad_s` (Ω, rad/s, F): the body then rests relative to the foundation,
    its mounts carrying the centrifugal load too (a deck that rolls at the first sample).
    `internal`: the mounts' internal states to start with (a restart keeps a broken bolt
    broken and a yielded one stretched); None: a new machine, its internal states zero but its
    hysteretic ones on their loading curves (`model.loading`) in equilibrium mode. Either way,
    the start's internal states are then made admissible at its pose (`settle`: a joint face
    that slid put on its friction bound).
    """
    scene = model.scene
    nf = len(scene.dofs)
    idx = [DOF_NAMES.index(d) for d in scene.dofs]
    y0 = np.zeros(model.n_state)  # internal mount states start at rest: no slip, no set
    y0[:nf] = np.array(scene.initial.pose)[idx]
    y0[nf : 2 * nf] = np.array(scene.initial.velocity)[idx]
    if internal is not None:
        y0[2 * nf :] = internal
    y = y0
    if scene.initial.mode != "given":
        y = static_equilibrium(model, y0, specific_force, rate_rad_s, loaded=internal is None)
    settle(model, y)
    return y


def settle(model: Model, y: np.ndarray) -> None:
    """Each non-linear mount's internal states in y made admissible at y's pose, in place (its
    kind's `settle` at its local deflection): a start's pose is found with the states it is
    given, which need not be states of the law there (a joint face's stick point zero where
    the pose deflects the face past its friction bound). The mounts' forces, and so an
    equilibrium, are unchanged (to rounding). Every start, a new machine's or a restart's,
    equilibrium or given, comes through `initial_state`, which calls this once."""
    nl = model.arrays.nl
    if nl is None:
        return
    d = np.empty((nl.kind.shape[0], 3))
    if not mount_deflections(y, model.arrays, model.new_scratch(), d) > 0.0:
        # the loader holds a given pose within the chart, an equilibrium is found on it
        raise ModelError("the start's pose is off the α/γ/δ chart: no mount deflections")
    kinds = list(KINDS.values())
    for row, code in enumerate(nl.kind.tolist()):
        kinds[code].settle(nl.par[row], y, int(nl.state[row]), d[row])


FINE_STEP = 1e-12
"""Relative central-difference step of the equilibrium's finer Jacobian (`newton.solve`'s
`fine`): under the penetration of a contact bearing 0.01 N on 1e10 N/m, where the compiled
step (CENTRAL_STEP, 1e-7) straddles the contact's edge; the accelerations' rounding (~1e-15
m/s²) then errs ~1e-3 s⁻² in entries of 1e2–1e9 s⁻². Good near an edge only: the rounding of
accelerations far from it (a deep contact, a body far out in a clearance) grows with them, so
`newton.solve` takes this Jacobian's step only where it lands better than the compiled one's."""


MAX_TURN = 0.1
"""rad: the most one Newton step of the equilibrium turns the body about an axis (`newton`'s
`limit`). The mounts' geometry is linear in the rotation only near the rest, a few thousandths
of a radian: on the plateau of friction faces that slid, which hold yaw only by the friction's
stiffness across its direction, μ·F_K/|e|, unlimited steps turned the body by radians and
landed on far roots of the mounts' laws, the body turned by π or by whole turns."""


CONTINUATION = 3
"""Decades by which the start's equilibrium softens the mounts' contact stiffnesses (each
kind's `CONTACT_STIFFNESS`: shanks bearing past a hole's clearance, keys, snubbers) where Newton
does not find it at once: solved with them 10⁻¹ times as stiff, else 10⁻² or 10⁻³, then
stiffened a decade at a time back to theirs, each solve from the last root. Stiff contacts that
bear past a clearance, approached from within it (from faces sliding at their friction
bounds, where nothing bears and Newton's step is singular or orders of magnitude long), have
their root within the Jacobian's difference step of every contact's edge (1 kN on 1e10 N/m:
1e-7 m): Newton's landings bear on some of them, the piece whose root lies elsewhere, and end
creeping along the edges. Softer, the root lies deeper past the edges (a decade per decade),
and as they stiffen it moves back towards them, each contact's penetration shrinking about as
1/k_c with its force nearly held, the same contacts bearing: each decade's Newton starts on
the piece of its root. Of 120 random heels onto bolted joints at 1e10 N/m, 11 were not found
before (`bench/start_heels.py`, seed 0)."""


def _contacts(nl: NonLinearMounts) -> np.ndarray:
    """Mask of `nl.par`: the mounts' contact stiffnesses (each kind's `CONTACT_STIFFNESS`
    columns) that are not 0."""
    mask = np.zeros(nl.par.shape, dtype=bool)
    for code, module in enumerate(KINDS.values()):
        mask[np.ix_(nl.kind == code, module.CONTACT_STIFFNESS)] = True
    return mask & (nl.par != 0.0)


def _softened(arrays: ModelArrays, contacts: np.ndarray, scale: float) -> ModelArrays:
    """`arrays` with the parameters at `contacts` (`_contacts`) times `scale`."""
    nl = arrays.nl
    assert nl is not None  # only scenes with contacts are softened
    return arrays._replace(nl=nl._replace(par=np.where(contacts, scale * nl.par, nl.par)))


def static_equilibrium(
    model: Model,
    y_guess: np.ndarray,
    specific_force: np.ndarray,
    rate_rad_s: np.ndarray | None = None,
    *,
    loaded: bool = False,
) -> np.ndarray:
    """State at rest relative to F where the free generalized accelerations vanish (Newton on
    the coordinates from those of `y_guess`, else from the contact stiffnesses softened and
    restored, `CONTINUATION`; least squares where Newton does not get there),
    the foundation turning at `rate_rad_s` (rad/s, F; None: not turning); internal mount
    states as in `y_guess`, but with `loaded` each hysteretic one on its axis's loading curve
    at the pose (`model.loading`: a new machine set down slowly)."""
    nf = len(model.scene.dofs)
    q_guess = y_guess[:nf]
    m, s = model.arrays, model.new_scratch()  # m: the arrays solved with (`CONTINUATION`)
    u = gravity_input(0.0, specific_force, rate_rad_s)
    y = np.zeros(model.n_state)
    y[2 * nf :] = y_guess[2 * nf :]
    dydt = np.zeros(model.n_state)
    by_q, work = np.empty((model.n_state, nf)), np.empty((2, model.n_state))
    virgin = virgin_axes(m) if loaded else None
    deflection = np.empty((0 if m.nl is None else m.nl.kind.shape[0], 3))

    def at(q: np.ndarray) -> None:
        """y at the pose q (its hysteretic states on their loading curves, where loaded)."""
        y[:nf] = q
        if virgin is not None:
            y[virgin.state] = virgin.z(virgin.deflections(y, m, s, deflection))

    def accelerations(q: np.ndarray) -> np.ndarray:
        at(q)
        if rhs(0.0, y, m, s, u, dydt) != OK:
            return np.full(nf, 1e6)
        return dydt[nf : 2 * nf].copy()

    def stiffness(q: np.ndarray) -> np.ndarray:
        """∂(accelerations)/∂q; NaN off the chart (Newton then gives up)."""
        if virgin is not None:
            return _loaded_stiffness(virgin, q, y, u, m, s, deflection)
        y[:nf] = q
        if not central_columns(y, 0.0, m, s, u, work[0], work[1], by_q):
            return np.full((nf, nf), np.nan)
        return by_q[nf : 2 * nf].copy()

    def fine_stiffness(q: np.ndarray, reach: np.ndarray) -> np.ndarray:
        """∂(accelerations)/∂q by the finer step FINE_STEP (`newton.central`'s `reach`)."""
        return newton.central(accelerations, q, FINE_STEP, reach)

    allowed_at = _allowed_residual(model, specific_force)
    turns = np.array([MAX_TURN if d in DOF_NAMES[3:] else np.inf for d in model.scene.dofs])

    def tangent_scale() -> float:
        """1/s²: the squared fastest mode on the mounts' nominal tangents, keys bearing
        (`Model.tangent_rate`), J's scale where nothing bears at the guess."""
        return model.tangent_rate**2

    def search(q0: np.ndarray) -> newton.Found | None:
        return newton.find(
            accelerations, stiffness, q0, allowed_at, fine_stiffness, turns, tangent_scale
        )

    found = search(q_guess)
    contacts = None if found is not None or m.nl is None else _contacts(m.nl)
    if contacts is not None and contacts.any():
        for decades in range(1, CONTINUATION + 1):
            q = q_guess
            for scale in 10.0 ** -np.arange(float(decades), -1.0, -1.0):
                m = _softened(model.arrays, contacts, scale)  # the closures above read m
                found = search(q)
                if found is None:
                    break
                q = found[0]
            m = model.arrays
            if found is not None:
                break
    if found is None:  # Newton did not get there: the robust solver says why
        from scipy.optimize import least_squares  # 0.2 s to import: only where Newton fails

        sol = least_squares(accelerations, q_guess, xtol=1e-15, ftol=1e-15, gtol=1e-15)
        found = sol.x, sol.fun, sol.jac
    q, residual, jac = found
    allowed = allowed_at(jac)
    if not (np.abs(residual) <= allowed).all():  # NaN (a non-finite load) fails too
        worst = int(np.nanargmax(np.abs(residual) / allowed)) if np.isfinite(residual).all() else 0
        at(q)
        there = _conditions(model, y, s) if rhs(0.0, y, m, s, u, dydt) == OK else ""
        msg = (
            f"{model.scene.source}: no static equilibrium found (residual "
            f"{abs(residual[worst]):.3g} m/s² or rad/s² on {model.scene.dofs[worst]}, where "
            f"rounding allows {allowed[worst]:.3g}){there}: check that the mounts hold every "
            "free DOF under this load"
        )
        raise ModelError(msg)
    _check_restrained(model, jac)
    at(q)
    return y.copy()


def _conditions(model: Model, y: np.ndarray, s: Scratch) -> str:
    """'; where it ends, <event> at <mount>, ...' of the mounts' conditions holding at y (s
    holding its body motion: the last `rhs` was at y), e.g. faces sliding at their friction
    bounds (`joint_slipped`) with nothing bearing; '' where none holds."""
    nl = model.arrays.nl
    if nl is None:
        return ""
    g = np.zeros((nl.slot.shape[0], N_EVENTS))
    mount_monitors(y.copy(), y, nl, s, g, np.zeros(nl.slot.shape[0]))
    held: dict[str, list[str]] = {}
    for row, slot in enumerate(model.nonlinear_slots):
        mount = model.scene.mounts[slot]
        for event, value in zip(KINDS[mount.kind].EVENTS, g[row], strict=False):
            if value >= 0.0:
                held.setdefault(event, []).append(mount.name)
    said = [f"{event} at {', '.join(names)}" for event, names in held.items()]
    return f"; where it ends, {'; '.join(said)}" if said else ""


def _loaded_stiffness(
    virgin: VirginAxes,
    q: np.ndarray,
    y: np.ndarray,
    u: np.ndarray,
    m: ModelArrays,
    s: Scratch,
    deflection: np.ndarray,
) -> np.ndarray:
    """∂(free generalized accelerations)/∂q with each hysteretic state on its loading curve,
    z = Z(x(q)): central differences along the curve's tangent (e_c, Z'(x)·∂x/∂q_c), as
    `central_columns` takes them along e_c (the same relative step); NaN off the chart. y:
    the state to move (left at q's states)."""
    nf = q.shape[0]
    y[:nf] = q
    z = virgin.z(virgin.deflections(y, m, s, deflection))
    slope = virgin.slope(z)
    jac = np.empty((nf, nf))
    dydt = np.empty(y.shape[0])
    for col in range(nf):
        h = (q[col] + CENTRAL_STEP * max(1.0, abs(q[col]))) - q[col]
        ends = []
        for sign in (1.0, -1.0):
            y[:nf] = q
            y[col] += sign * h
            ends.append(virgin.deflections(y, m, s, deflection))
        dz = slope * (ends[0] - ends[1]) / (2.0 * h)
        rates = []
        for sign in (1.0, -1.0):
            y[:nf] = q
            y[col] += sign * h
            y[virgin.state] = z + sign * h * dz
            if rhs(0.0, y, m, s, u, dydt) != OK:
                return np.full((nf, nf), np.nan)
            rates.append(dydt[nf : 2 * nf].copy())
        jac[:, col] = (rates[0] - rates[1]) / (2.0 * h)
    y[:nf] = q
    y[virgin.state] = z
    return jac


def _allowed_residual(
    model: Model, specific_force: np.ndarray
) -> Callable[[np.ndarray], np.ndarray]:
    """The residual accepted per free generalized acceleration (m/s² or rad/s²), given the
    Jacobian ∂(accelerations)/∂q there: 1e-9 of |specific force| (at least of 1 m/s²) plus
    the rounding floor of the arithmetic."""
    g = float(np.linalg.norm(specific_force))
    # Relative to what floating point can resolve: a mount force is k·(R·p − p) with lever arms
    # p of up to `reach` metres, so each acceleration carries a rounding floor of about
    # ε·reach·|∂a/∂q| (10 kg on 1e11 N/m mounts: ~1e-4 m/s²); an absolute threshold refused
    # stiff, light scenes whose equilibrium was as exact as their arithmetic.
    positions = [abs(v) for mt in model.scene.mounts for v in mt.position]
    reach = max(1.0, float(np.abs(model.arrays.cg_ref).max()), *positions)

    def allowed_at(jac: np.ndarray) -> np.ndarray:
        floor = 64.0 * np.finfo(float).eps * reach * np.abs(jac).max(axis=1)
        return 1e-9 * max(g, 1.0) + floor

    return allowed_at


def _check_restrained(model: Model, jac: np.ndarray) -> None:
    """Refuse a free DOF that no mount holds: the equilibrium's stiffness, ∂(generalized
    accelerations)/∂q, is then singular, and the body would drift under any input along it.
    The message names the DOF that dominates the unrestrained direction. A singular stiffness
    where the mounts' nominal tangents hold every DOF (`scene.statics`: a shear key and a
    frictionless bolted joint's shank count with their clearance) is a rest within a
    clearance, which the body leaves at contact: taken, as the loader takes the scene."""
    nf = jac.shape[0]
    scale = np.abs(jac).max()
    if not np.isfinite(scale) or scale == 0.0:
        free = ", ".join(model.scene.dofs)
        msg = f"{model.scene.source}: no mount holds the body: DOFs {free} are free"
        raise ModelError(msg)
    _, sigma, vt = np.linalg.svd(jac / scale)
    if sigma[-1] < newton.SINGULAR * sigma[0] * max(nf, 1):
        if not any(loose_dofs(statics(model.scene), model.scene.dofs)):
            return  # at rest within a clearance (a key's, a shank's): free there, not far
        dof = model.scene.dofs[int(np.argmax(np.abs(vt[-1])))]
        msg = (
            f"{model.scene.source}: DOF {dof} is not held by any mount (the mounts' stiffness "
            "has no component along it at the static equilibrium): give a mount stiffness "
            f"there, or leave {dof} out of `dofs`"
        )
        raise ModelError(msg)
