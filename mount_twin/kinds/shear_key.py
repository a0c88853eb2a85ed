"""Shear key: stiff along its shear axes, free along the others, with an optional clearance.

Along each local axis with a stiffness k > 0 the key pushes back only past the clearance:
F = −sign(d)·max(k·(|d| − clearance) + c·sign(d)·ḋ, 0) in contact (it never pulls); no force
along free axes. With an engagement height h > 0, a foot lifted along local z by more than h has
cleared the key, which then holds nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # only annotations: importing mount_twin.scene here is a cycle
    from mount_twin.scene.reader import Reader

KIND = "shear_key"
EVENTS = ("key_contact", "key_overload")
EVENT_ERROR = (False, True)
EVENT_STIFFENS = (True, False)
"""A key that closes its clearance stiffens the scene (`auto` looks again); overload is in
contact."""
EVENT_COMPANION = ("carried", "carried")
"""How the error estimate's companion takes an interval that starts with each event holding
(`kinds.COMPANION_TREATMENTS`): carried. A key bears linearly past its clearance, so the kick
taken at the interval's start holds through it, and a key stiffer than its reach is
integrated by the reach (`engine.companion`)."""
EVENT_SWITCHES = (False, False)
"""No event is a discrete switch (`update` never switches): a key past its allowable force at
a start is a state there, not an event."""
STATES: tuple[str, ...] = ()
RESTUCK: tuple[str, ...] = ()
"""States a restart sets to zero (none: all of this kind's states are kept)."""
ROTATIONAL = False
"""A key carries no moment: `load` reads no local rotation or rate and gives no couple."""

PARAMETERS = {
    "stiffness": ("double_array", "[kx, ky, kz] N/m along the key axes; 0 leaves an axis free"),
    "damping": ("double_array", "[cx, cy, cz] N·s/m in contact (zeros)"),
    "clearance": ("double", "Clearance before the key bears, m (0.0)"),
    "allowable_force": ("double", "Allowable key force, N (0.0: not monitored)"),
    "engagement_height": ("double", "Lift along local z that clears the key, m (0.0: never)"),
}
"""ROS parameters of the kind, mounts.<name>.<key>: (type, description)."""

# parameter columns: stiffness (3), damping (3), clearance, allowable force, engagement height
K0, C0, CLEAR, FALLOW, HEIGHT = 0, 3, 6, 7, 8
N_PAR = 9
CONTACT_STIFFNESS = (K0, K0 + 1, K0 + 2)
"""Parameter columns of stiffnesses acting only past a clearance (all of a key's), which the
start's equilibrium may soften and restore (`model.assemble.CONTINUATION`)."""


@dataclass(frozen=True)
class ShearKey:
    """Attributes: stiffness (N/m) and damping (N·s/m) per local axis (0: free axis), clearance
    (m), allowable_force (N, 0: not monitored), engagement_height (m, 0: always engaged)."""

    name: str
    position: tuple[float, float, float]
    orientation_rpy: tuple[float, float, float]
    stiffness: tuple[float, float, float]
    damping: tuple[float, float, float]
    clearance: float
    allowable_force: float
    engagement_height: float = 0.0
    kind: str = KIND


def read(r: Reader, name: str, position: tuple, rpy: tuple) -> ShearKey:
    """Parse and check the kind's keys."""
    key = ShearKey(
        name=name,
        position=position,
        orientation_rpy=rpy,
        stiffness=r.vector("stiffness", 3, lo=0.0),
        damping=r.vector("damping", 3, (0.0, 0.0, 0.0), lo=0.0),
        clearance=r.number("clearance", 0.0, lo=0.0),
        allowable_force=r.number("allowable_force", 0.0, lo=0.0),
        engagement_height=r.number("engagement_height", 0.0, lo=0.0),
    )
    r.finish()
    if not any(k > 0.0 for k in key.stiffness):
        raise r.error("stiffness", f"a key needs at least one stiff axis, got {key.stiffness!r}")
    return key


def pack(k: ShearKey) -> np.ndarray:
    """Parameter row of one key."""
    return np.array(
        [*k.stiffness, *k.damping, k.clearance, k.allowable_force, k.engagement_height]
    )


def piecewise(k: ShearKey) -> bool:
    """Whether the mount's force law has pieces its motion moves between (`Model.piecewise`):
    a key's does, open within its clearance and bearing past it."""
    return True


def kinked(k: ShearKey) -> bool:
    """Whether the mount's law has kinks inside an interval that none of its events marks
    (`Model.kinked`): none, its bearing's switch is its event."""
    return False


def nominal_tangent(k: ShearKey) -> tuple[tuple[float, ...], tuple[str, ...]]:
    """Stiffness at the unstressed pose, (kx, ky, kz) N/m then (krx, kry, krz) N·m/rad (none: a
    key has no rotational law), and the scene key each value comes from: its bearing stiffness
    per axis, counted whatever the clearance (a key that closes must be stable closed)."""
    keys = tuple(f"stiffness[{j}]" for j in range(3))
    rot = tuple(f"rotational_stiffness[{j}]" for j in range(3))
    return (*k.stiffness, 0.0, 0.0, 0.0), (*keys, *rot)


def state_names(_k: ShearKey) -> tuple[str, ...]:
    """A key has no internal state."""
    return ()


def load(p, y, o, d, v, phi, w, dydt, f, c) -> None:
    """Force f (N) on the body in local axes; a key has no couple and no states."""
    engaged = _engaged(p, d)
    for j in range(3):
        f[j] = 0.0
        c[j] = 0.0
        k = p[K0 + j]
        if k > 0.0 and engaged:
            pen = abs(d[j]) - p[CLEAR]
            if pen > 0.0:
                side = 1.0 if d[j] > 0.0 else -1.0
                # contact pushes, never pulls: damping cannot hold a key face that separates
                f[j] = -side * max(k * pen + p[C0 + j] * side * v[j], 0.0)


def monitor(p, y, y0, o, d, v, g) -> float:
    """Contact (penetration past the clearance, m) and overload; returns |F|/allowable."""
    pen = -1.0
    force = 0.0
    engaged = _engaged(p, d)
    for j in range(3):
        if p[K0 + j] > 0.0 and engaged:
            pj = abs(d[j]) - p[CLEAR]
            pen = max(pen, pj)
            force = max(force, p[K0 + j] * max(pj, 0.0))
    g[0] = pen if p[CLEAR] > 0.0 else -1.0
    if p[FALLOW] > 0.0:
        g[1] = force / p[FALLOW] - 1.0
        return force / p[FALLOW]
    g[1] = -1.0
    return 0.0


def _engaged(p, d) -> bool:
    """Whether the foot is still low enough for the key to hold it."""
    return p[HEIGHT] <= 0.0 or d[2] <= p[HEIGHT]


def settle(p, y, o, d) -> None:
    """A key has no internal state to settle at a start."""


def carry(p, y, y0, yt, o, d, dt) -> None:
    """The error estimate's companion after its carried error's kick (bolted_joint.carry):
    a key has no internal state."""


def update(p, y, o, d) -> bool:
    """No discrete state: never switches."""
    return False
