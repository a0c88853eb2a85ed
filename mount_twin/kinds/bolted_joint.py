"""Bolted joint (VDI 2230 joint diagram) with bolt plasticity, fracture, friction and bearing.

Local axes: z along the bolt, positive where the machine foot lifts off the foundation (the joint
opens); x, y span the joint face. Deflections d (m) and rates v (m/s) are the foot's motion in
these axes from the preloaded rest position.

Axial (joint diagram): bolt force F_S = F_V + k_S·(u − e_p) (never compressive), clamp force
F_K = max(F_V − k_P·u, 0); the force on the body is F_K − F_S. While the joint is closed the
bolt takes Φ = k_S/(k_S + k_P) of an external load F_A; it opens at F_A = F_V/(1 − Φ), after
which the bolt alone carries it. The bolt is bilinear elasto-plastic: past F_y (hardened by
plastic elongation e_p) only the fraction α of k_S remains, ė_p = (1 − α)·u̇; e_p stays after
unloading and lowers the preload. At F_u, or at the ultimate plastic elongation, it breaks for
good (a discrete state, switched between input samples).

Shear: stick spring k_τ in series with a slip s_p; the friction force never exceeds μ·F_K and
slides (ṡ_p along the stick deflection e = d − s_p) at that bound; past the hole clearance the
shank bears with k_b (until the bolt breaks). Sliding obeys the consistency condition of
rate-independent friction under a moving bound: ṡ_p = λ̇·e/|e| with λ̇ = max(0, e·ḋ/|e| −
μ·Ḟ_K/k_τ), so k_τ·|e| stays on μ·F_K while the clamp force changes (Ḟ_K = −k_P·u̇ while the
joint is closed); with the joint open (or μ = 0) nothing holds the face and the stick point moves
with the foot (ṡ_p = ḋ). The bound's rate matters: without it (|e| frozen while sliding) a rising
clamp force makes the face stick, catch up and slide again at every step, a sliding mode that
chattered thousands of times per 0.1 ms on the genset's shock and made an adaptive step's cost
grow as 1/tolerance; a falling one left the spring loaded above the bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # only annotations: importing mount_twin.scene here is a cycle
    from mount_twin.scene.reader import Reader

KIND = "bolted_joint"
EVENTS = ("bolt_yielded", "joint_opened", "joint_slipped", "bolt_fractured")
"""Monitored events, in the order `monitor` fills them (signed: ≥ 0 means it happened)."""
EVENT_ERROR = (True, True, False, True)
"""Whether each event is an ERROR (a limit passed) rather than a WARN."""
EVENT_STIFFENS = (False, False, False, False)
"""Whether each event can make the scene stiffer (`auto` then looks at it again): a joint that
yields, opens, slips or breaks only loses stiffness."""
EVENT_COMPANION = ("switching",) * 4
"""How the error estimate's companion takes an interval that starts with each event holding
(`kinds.COMPANION_TREATMENTS`, `engine.companion`): integrated, by the twin's own method where
the twin's tolerance bound its steps, over any that starts with a bolt flowing, a joint open, a
face slipping or a bolt broken (a face switching between sticking and sliding inside the
steps: there a higher order saves few steps). Carried through them, the genset
under two synthesised 30 g shocks read 0.51–2.09 of its true force error (0.88–1.40 with
flowing and open joints integrated, 0.89–1.23 with all), and under its own shock bag at rtol
1e-6 and 1e-7 2.0 and 3.5 times its true attitude error with slipping faces carried: the yaw
their slide left in the companion was ten times the reference's (0.86–1.07 with them
integrated, at the same cost, 1.2–1.65×: `python3 bench/error_estimate.py --cases genset`).
Those figures were taken while the companion was the twin's mirror (`engine.companion`); with
the sign right, all four carried read the genset 0.96–1.42 of its force error at rtol 1e-3 …
1e-9 but 3.7 times its attitude error at 1e-7, at 1.24–1.88× against 1.31–1.63×."""
EVENT_SWITCHES = (False, False, False, True)
"""Whether each event is a discrete switch of `update` (the bolt breaking): one that a start's
monitors make is reported as that event at the start; the others holding at a start are
states there, not events."""
STATES = ("plastic_elongation", "slip_x", "slip_y", "fractured")
RESTUCK = ("slip_x", "slip_y")
"""States a restart sets to zero before its equilibrium: the joint face's stick point, where it
stuck relative to a pose the restart discards. Kept, it would start the face loaded to its
friction bound (the frame of a machine that slid before a gap pulled sideways while "at rest",
and with broken bolts no equilibrium: friction at its bound holds no yaw). Where the restart's
pose then slides the face, `settle` puts the stick point back on the bound. Plastic elongation
and fracture are damage, and stay."""
ROTATIONAL = False
"""A single bolt carries no moment: `load` reads no local rotation or rate and gives no couple."""

PARAMETERS = {
    "bolt_stiffness": ("double", "Bolt stiffness k_S, N/m"),
    "clamp_stiffness": ("double", "Clamped-parts stiffness k_P, N/m"),
    "preload": ("double", "Preload F_V, N"),
    "yield_force": ("double", "Bolt yield force F_y = R_p0.2·A_s, N"),
    "hardening": ("double", "Post-yield tangent as a fraction α of k_S (default 0.02)"),
    "ultimate_force": ("double", "Bolt fracture force F_u, N"),
    "ultimate_plastic_elongation": ("double", "Plastic elongation at fracture, m (2.0e-3)"),
    "friction": ("double", "Joint-face friction coefficient μ (0.15)"),
    "shear_stiffness": ("double", "Stick stiffness of the joint face, N/m (1.0e+9)"),
    "hole_clearance": ("double", "Bolt hole clearance, m (1.0e-3)"),
    "bearing_stiffness": ("double", "Shank bearing stiffness past the clearance, N/m (5.0e+8)"),
    "axial_damping": ("double", "Axial damping, N·s/m (0.0)"),
    "shear_damping": ("double", "Shear damping, N·s/m (0.0)"),
}
"""ROS parameters of the kind, mounts.<name>.<key>: (type, description)."""

# parameter columns
KS, KP, FV, FY, ALPHA, FU, EPU, MU, KT, CLEAR, KB, CAX, CSH = range(13)
N_PAR = 13
CONTACT_STIFFNESS = (KB,)
"""Parameter columns of stiffnesses acting only past a clearance (the shank bearing on its
hole), which the start's equilibrium may soften and restore (`model.assemble.CONTINUATION`)."""


@dataclass(frozen=True)
class BoltedJoint:
    """A bolted foot: see the module docstring; SI units, forces N, stiffnesses N/m.

    Attributes:
        bolt_stiffness: k_S. clamp_stiffness: k_P. preload: F_V.
        yield_force: F_y = R_p0.2·A_s. hardening: α, post-yield tangent as a fraction of k_S.
        ultimate_force: F_u. ultimate_plastic_elongation: e_p at fracture, m.
        friction: μ. shear_stiffness: k_τ of the stuck joint face.
        hole_clearance: m. bearing_stiffness: k_b of the shank in the hole.
        axial_damping, shear_damping: N·s/m.
    """

    name: str
    position: tuple[float, float, float]
    orientation_rpy: tuple[float, float, float]
    bolt_stiffness: float
    clamp_stiffness: float
    preload: float
    yield_force: float
    hardening: float
    ultimate_force: float
    ultimate_plastic_elongation: float
    friction: float
    shear_stiffness: float
    hole_clearance: float
    bearing_stiffness: float
    axial_damping: float
    shear_damping: float
    kind: str = KIND

    @property
    def phi(self) -> float:
        """Load factor Φ = k_S/(k_S + k_P)."""
        return self.bolt_stiffness / (self.bolt_stiffness + self.clamp_stiffness)

    @property
    def opening_load(self) -> float:
        """External axial load that opens the joint, F_V/(1 − Φ), N."""
        return self.preload / (1.0 - self.phi)


def read(r: Reader, name: str, position: tuple, rpy: tuple) -> BoltedJoint:
    """Parse and check the kind's keys (units in `BoltedJoint`)."""
    joint = BoltedJoint(
        name=name,
        position=position,
        orientation_rpy=rpy,
        bolt_stiffness=r.positive("bolt_stiffness"),
        clamp_stiffness=r.positive("clamp_stiffness"),
        preload=r.number("preload", lo=0.0),
        yield_force=r.positive("yield_force"),
        hardening=r.number("hardening", 0.02, lo=0.0, hi=0.99),
        ultimate_force=r.positive("ultimate_force"),
        ultimate_plastic_elongation=r.positive("ultimate_plastic_elongation", 2.0e-3),
        friction=r.number("friction", 0.15, lo=0.0),
        shear_stiffness=r.positive("shear_stiffness", 1.0e9),
        hole_clearance=r.number("hole_clearance", 1.0e-3, lo=0.0),
        bearing_stiffness=r.number("bearing_stiffness", 5.0e8, lo=0.0),
        axial_damping=r.number("axial_damping", 0.0, lo=0.0),
        shear_damping=r.number("shear_damping", 0.0, lo=0.0),
    )
    r.finish()
    if not joint.preload < joint.yield_force < joint.ultimate_force:
        raise r.error(
            "yield_force",
            f"need preload < yield_force < ultimate_force, got {joint.preload!r}, "
            f"{joint.yield_force!r}, {joint.ultimate_force!r}",
        )
    return joint


def pack(j: BoltedJoint) -> np.ndarray:
    """Parameter row of one joint (columns as named above)."""
    row = np.zeros(N_PAR)
    row[[KS, KP, FV, FY, ALPHA, FU, EPU, MU, KT, CLEAR, KB, CAX, CSH]] = [
        j.bolt_stiffness,
        j.clamp_stiffness,
        j.preload,
        j.yield_force,
        j.hardening,
        j.ultimate_force,
        j.ultimate_plastic_elongation,
        j.friction,
        j.shear_stiffness,
        j.hole_clearance,
        j.bearing_stiffness,
        j.axial_damping,
        j.shear_damping,
    ]
    return row


def piecewise(j: BoltedJoint) -> bool:
    """Whether the mount's force law has pieces its motion moves between (`Model.piecewise`):
    a joint's does, its faces sticking, slipping and opening."""
    return True


def kinked(j: BoltedJoint) -> bool:
    """Whether the mount's law has kinks inside an interval that none of its events marks
    (`Model.kinked`): none, its faces' and its bolt's switches are its events."""
    return False


def nominal_tangent(j: BoltedJoint) -> tuple[tuple[float, ...], tuple[str, ...]]:
    """Stiffness at the unstressed pose, (kx, ky, kz) N/m then (krx, kry, krz) N·m/rad (none: a
    joint has no rotational law), and the scene key each value comes from: the stuck face's
    shear stiffness, or without friction the shank bearing on its hole, counted whatever the
    clearance, as a shear key's stiffness is (a frictionless face lets the body move by the
    clearance, not drift: it is held at the clearance's edge); axially, the bolt and the
    clamped parts together."""
    shear, key = j.shear_stiffness, "shear_stiffness"
    if j.friction == 0.0:
        shear, key = j.bearing_stiffness, "bearing_stiffness"
    axial = j.bolt_stiffness + j.clamp_stiffness
    rot = tuple(f"rotational_stiffness[{i}]" for i in range(3))
    return (shear, shear, axial, 0.0, 0.0, 0.0), (
        key,
        key,
        "bolt_stiffness + clamp_stiffness",
        *rot,
    )


def state_names(j: BoltedJoint) -> tuple[str, ...]:
    """Internal states of one joint (all joints have them)."""
    return tuple(f"{j.name}.{s}" for s in STATES)


def bolt_force(p: np.ndarray, u: float, e_p: float, broken: float) -> float:
    """Bolt tension F_S, N (0 once broken or slack)."""
    if broken > 0.5:
        return 0.0
    return max(p[FV] + p[KS] * (u - e_p), 0.0)


def clamp_force(p: np.ndarray, u: float) -> float:
    """Clamp force F_K = max(F_V − k_P·u, 0), N, at the axial deflection u (m): 0 once open."""
    return max(p[FV] - p[KP] * u, 0.0)


def hardening(p: np.ndarray) -> float:
    """The yield force's rise per metre of plastic elongation, N/m: α·k_S/(1 − α), so that the
    bolt flows along the post-yield tangent α·k_S."""
    return p[ALPHA] * p[KS] / (1.0 - p[ALPHA])


def yield_limit(p: np.ndarray, e_p: float) -> float:
    """Current yield force, N: linear hardening with the post-yield tangent α·k_S."""
    return p[FY] + hardening(p) * e_p


def yield_elongation(p: np.ndarray, u: float) -> float:
    """The plastic elongation (m) that puts the bolt on its yield line at the axial deflection
    u (m): F_V + k_S·(u − e_p) = F_y + hardening·e_p."""
    return (p[FV] + p[KS] * u - p[FY]) / (p[KS] + hardening(p))


def load(p, y, o, d, v, phi, w, dydt, f, c) -> None:
    """Force f and couple c (N, N·m) on the body in local axes; internal state rates into dydt.

    Args:
        p: (N_PAR,) parameters; y, dydt: state and its rate, this joint's states from o.
        d, v: (3,) local deflection (m) and rate (m/s); phi, w: local rotation (rad) and rate
            (rad/s), unused: a single bolt carries no moment.
    """
    e_p, sx, sy, broken = y[o], y[o + 1], y[o + 2], y[o + 3]
    u, ud = d[2], v[2]
    f_s = bolt_force(p, u, e_p, broken)
    f_k = clamp_force(p, u)
    flow = broken < 0.5 and f_s >= yield_limit(p, e_p) and ud > 0.0
    dydt[o] = (1.0 - p[ALPHA]) * ud if flow else 0.0
    dydt[o + 3] = 0.0
    # the dashpots act through the joint: not on a foot whose bolt broke and that left the deck
    joined = 1.0 if broken < 0.5 or f_k > 0.0 else 0.0
    f[2] = f_k - f_s - joined * p[CAX] * ud
    # shear: stick spring in series with slip, bounded by μ·F_K
    ex, ey = d[0] - sx, d[1] - sy
    tx, ty = p[KT] * ex, p[KT] * ey
    tau = math.sqrt(tx * tx + ty * ty)
    limit = p[MU] * f_k
    dydt[o + 1] = 0.0
    dydt[o + 2] = 0.0
    scale = 1.0
    if limit <= 0.0:
        # nothing holds the face (joint open, or no friction): the stick point moves with the
        # foot, e kept as it was (the bound fell to zero as the joint opened)
        scale = 0.0
        dydt[o + 1] = v[0]
        dydt[o + 2] = v[1]
    elif tau >= limit:
        scale = limit / tau
        # consistency: sliding keeps k_τ·|e| on the bound μ·F_K as the clamp force moves
        norm = tau / p[KT]
        rate = (ex * v[0] + ey * v[1]) / norm + p[MU] * p[KP] * ud / p[KT]
        if rate > 0.0:
            dydt[o + 1] = rate * ex / norm
            dydt[o + 2] = rate * ey / norm
    f[0] = -scale * tx - joined * p[CSH] * v[0]
    f[1] = -scale * ty - joined * p[CSH] * v[1]
    if broken < 0.5:
        s = math.sqrt(d[0] * d[0] + d[1] * d[1])
        bear = s - p[CLEAR]
        if bear > 0.0:
            f[0] -= p[KB] * bear * d[0] / s
            f[1] -= p[KB] * bear * d[1] / s
    c[0] = 0.0
    c[1] = 0.0
    c[2] = 0.0


SLIP_FLOOR = 1e-12
"""m: the trial slip past the friction bound in one sample below which `monitor` sees no slip:
its slip function is k_τ·(|d − s_p| − SLIP_FLOOR) − μ·F_K. A face on its bound at rest (a
start that slid, `settle`) moves to and fro across the bound by the rounding of its pose, some
1e-15 m a sample: without the floor, 21 heels onto bolted joints at rest for 40 ms logged 442
`joint_slipped` events. A real slip passes 1e-12 m within a sample from 1e-8 m/s at 10 kHz
(a micrometre in two minutes), its onset then located later by 1e-12 m over its rate (1 ns at
1 mm/s). Open and unsheared, the function is below 0, as it must be: an opening is not a
slip."""


def monitor(p, y, y0, o, d, v, g) -> float:
    """Event functions into g (order of EVENTS; ≥ 0: happening); returns the utilisation
    F_S/F_y (1 at first yield).

    Yield and slip are judged on the trial state: plastic elongation and slip frozen at their
    values y0 of the previous sample. The actual yield and slip functions stay at zero while the
    bolt flows or the face slides, so between two samples only the trial ones, which grow with
    the deflection, locate the onset by interpolation. A frictionless face (μ = 0) has no
    grip to lose: it slides with the foot by design, and its slip function is −1 (it read the
    foot's travel in a sample, past 0 at any motion: `joint_slipped` WARNs on a joint whose
    shank alone is meant to hold it, and an event holding that made the error estimate's
    companion integrate every interval).
    """
    e_p, broken = y[o], y[o + 3]
    e_t, sx, sy = y0[o], y0[o + 1], y0[o + 2]
    u = d[2]
    g[0] = bolt_force(p, u, e_t, broken) - yield_limit(p, e_t) if broken < 0.5 else -1.0
    g[1] = p[KP] * u - p[FV]
    tx, ty = p[KT] * (d[0] - sx), p[KT] * (d[1] - sy)
    shear, bound = math.sqrt(tx * tx + ty * ty), p[MU] * clamp_force(p, u)
    g[2] = shear - bound - p[KT] * SLIP_FLOOR if p[MU] > 0.0 else -1.0  # frictionless: no grip
    f_s = bolt_force(p, u, e_p, broken)
    g[3] = 1.0 if broken > 0.5 else max(f_s / p[FU] - 1.0, e_p / p[EPU] - 1.0)
    return f_s / p[FY]


def settle(p, y, o, d) -> None:
    """A start's stick point made admissible at the deflection d (m, local axes), in y from o:
    the radial return of rate-independent friction. A start solves its pose with the stick
    point it is given (zero for a new machine and after `RESTUCK`), the face force clamped to
    μ·F_K where the pose deflects the face further than μ·F_K/k_τ; left there, the stick spring
    would hold k_τ·|e| far above the bound, and a foot moving back would keep the face at μ·F_K,
    sliding no more, until it had come back by |e| − μ·F_K/k_τ. Here, where k_τ·|e| > μ·F_K > 0
    (e = d − s_p), s_p ← d − (μ·F_K/k_τ)·e/|e|: on the bound along e, so that the face sticks
    at once on reversal and unloads by k_τ per metre. The face force, and so the start's
    equilibrium, is unchanged (to rounding).

    A face that nothing holds (the joint open, or μ = 0: μ·F_K = 0) keeps its stick point, as
    `load` keeps e while the joint is open: its force is zero whatever s_p.

    A face left on its bound is on the verge of sliding: `monitor` sees no slip in the rounding
    of a body at rest (SLIP_FLOOR)."""
    limit, ex, ey, tau = _face(p, y, o, d)
    if 0.0 < limit < tau:
        _onto_bound(y, o, d, ex, ey, limit / tau)


def carry(p, y, y0, yt, o, d, dt) -> None:
    """The error estimate's companion after its carried error's kick (`engine.companion`): y
    its state after the kick, y0 the state the kick started from (the twin's new state plus the
    error before it), yt the twin's state; d, dt the companion's and the twin's deflections (m,
    local axes). Its rate-independent states follow the twin's regime, as a neighbouring
    solution does:

    - the bolt: where the twin's flows (F_S ≥ its yield force) or the companion's passes its
      own, the companion's plastic elongation is put on its hardening line at its u,
      e_p = (F_V + k_S·u − F_y)/(k_S + α·k_S/(1 − α)) (not below 0): a twin flowing beside an
      elastic companion would otherwise add the whole flow to the error (carried through, the
      genset under a 30 g shock read 8 times its true error);
    - the face: while μ·F_K > 0 the stick point is rate-independent: a sliding face's rate
      turns with e, whose length μ·F_K/k_τ goes to 0 as the joint opens, so an explicit kick
      of its error is unstable; its error is carried instead (s_p ← y0's), and where the twin's
      face is on its bound (k_τ·|e| ≥ μ·F_K: sliding, or at rest on the verge of it, where a
      start settles it) or the companion's passes its own, the companion's face is put on its
      bound along e, the radial return of `settle`: the backward Euler step of the slide law,
      stable at any step (taking the twin's slip past SLIP_FLOOR instead, which leaves out
      a face at rest on its bound or creeping, read the genset at rtol 1e-9 70 times its
      true error). An open face keeps its kick (ṡ_p = ḋ there).

    The intervals that start with any of the joint's events holding are integrated
    (EVENT_COMPANION): this returns what an interval that starts stuck, closed and elastic
    crosses into."""
    if y[o + 3] < 0.5 and yt[o + 3] < 0.5:
        flows = bolt_force(p, dt[2], yt[o], 0.0) >= yield_limit(p, yt[o])
        if flows or bolt_force(p, d[2], y[o], 0.0) > yield_limit(p, y[o]):
            y[o] = max(yield_elongation(p, d[2]), 0.0)
    if not p[MU] * clamp_force(p, d[2]) > 0.0:
        return
    y[o + 1], y[o + 2] = y0[o + 1], y0[o + 2]
    limit, ex, ey, tau = _face(p, y, o, d)
    twin_limit, _, _, twin_tau = _face(p, yt, o, dt)
    if tau > 0.0 and (0.0 < twin_limit <= twin_tau or tau > limit):
        _onto_bound(y, o, d, ex, ey, limit / tau)


def _face(p, y, o, d) -> tuple[float, float, float, float]:
    """(μ·F_K, N; e = d − s_p along x and y, m; k_τ·|e|, N) of the face at the deflection d
    (m, local axes) with the stick point in y from o."""
    ex, ey = d[0] - y[o + 1], d[1] - y[o + 2]
    return p[MU] * clamp_force(p, d[2]), ex, ey, p[KT] * math.sqrt(ex * ex + ey * ey)


def _onto_bound(y, o, d, ex, ey, scale) -> None:
    """The stick point in y from o moved to d − scale·e."""
    y[o + 1], y[o + 2] = d[0] - scale * ex, d[1] - scale * ey


def update(p, y, o, d) -> bool:
    """Between samples: a bolt at its ultimate load or elongation breaks, irreversibly.
    Returns whether it broke now."""
    if y[o + 3] < 0.5:
        f_s = bolt_force(p, d[2], y[o], 0.0)
        if f_s >= p[FU] or y[o] >= p[EPU]:
            y[o + 3] = 1.0
            return True
    return False
