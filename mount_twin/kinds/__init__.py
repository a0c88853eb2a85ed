"""Mount kinds besides the linear one: each module is one place for a kind's scene keys and
checks (`read`), its parameter row (`pack`), internal states, force law (`load`), event
functions (`monitor`) and discrete switches between samples (`update`).

The compiled dispatchers below select a kind by its code; adding a kind is a new module, a line
in KINDS and a branch in each dispatcher. The integrator and the engine never change.
"""

from __future__ import annotations

from types import ModuleType

from numba import njit

from mount_twin.kinds import bolted_joint, elastomer, shear_key

KINDS: dict[str, ModuleType] = {
    elastomer.KIND: elastomer,
    bolted_joint.KIND: bolted_joint,
    shear_key.KIND: shear_key,
}
"""Kind name → module, in code order (the code of a kind is its index here)."""
CODES = {name: i for i, name in enumerate(KINDS)}
N_PAR = max(k.N_PAR for k in KINDS.values())
N_EVENTS = max(len(k.EVENTS) for k in KINDS.values())
ELASTOMER, BOLTED_JOINT, SHEAR_KEY = (CODES[k] for k in KINDS)


@njit(cache=True, inline="always")
def kind_load(code, p, y, o, d, v, phi, w, dydt, f, c) -> None:
    """The kind's `load`: local force f and couple c on the body; internal rates into dydt."""
    if code == ELASTOMER:
        elastomer.load(p, y, o, d, v, phi, w, dydt, f, c)
    elif code == BOLTED_JOINT:
        bolted_joint.load(p, y, o, d, v, phi, w, dydt, f, c)
    else:
        shear_key.load(p, y, o, d, v, phi, w, dydt, f, c)


@njit(cache=True, inline="always")
def kind_monitor(code, p, y, y0, o, d, v, g) -> float:
    """The kind's `monitor`: event functions into g (y0: state at the previous sample);
    returns the utilisation."""
    if code == ELASTOMER:
        return elastomer.monitor(p, y, y0, o, d, v, g)
    if code == BOLTED_JOINT:
        return bolted_joint.monitor(p, y, y0, o, d, v, g)
    return shear_key.monitor(p, y, y0, o, d, v, g)


@njit(cache=True, inline="always")
def kind_update(code, p, y, o, d) -> None:
    """The kind's `update`: discrete switches between samples."""
    if code == BOLTED_JOINT:
        bolted_joint.update(p, y, o, d)
