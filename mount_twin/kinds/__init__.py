"""Mount kinds besides the linear one: each module is one place for a kind's scene keys and
checks (`read`: every key read, then `Reader.finish`, then the checks across keys, so that a
misspelt key is named rather than the check it makes fail), its parameter row (`pack`; its
columns of stiffnesses acting only past a clearance or gap, `CONTACT_STIFFNESS`, which the
start's equilibrium softens and restores where it is not found at once), internal states (and
which of them a restart resets: `RESTUCK`), force law (`load`), event functions (`monitor`),
discrete switches between samples (`update`, which says whether it switched: the state then
jumped, and a stepper must not start from a stage it took before; `EVENT_SWITCHES` names the
events that are such a switch, which a start reports too, and none of which may stiffen the
scene: `auto` looks again at none a start makes; `EVENT_COMPANION` how the error estimate's
companion takes an interval that starts with each holding, one of COMPANION_TREATMENTS,
`engine.companion`), a start's internal states made admissible at its pose (`settle`, run once
a start's pose is found by `model.assemble.initial_state`: a face that slid put on its friction
bound), the error estimate's companion after its carried error's kick (`carry`: its
rate-independent states, a face's stick point, carried and returned onto its bound,
`engine.companion`) and its stiffness at the unstressed pose (`nominal_tangent`: statics, modes
and `auto`'s first choice read it), and whether a mount's law has pieces its motion moves
between (`piecewise`: a contact, a joint's faces; `auto` and the error estimate's companion
take the exponential method only for scenes with none, `Model.linear_stiffness`), and whether it
has kinks no event marks (`kinked`: a Bouc–Wen rate's |ẋ|; the companion's checks then take
shorter steps, `engine.companion`). A module's
`load`, `monitor`, `update` and `carry` are plain Python: the reference the compiled core's
port of the kind (src/core/kinds/<kind>.hpp) is held to; `settle` runs only in Python, at
starts.

The core's dispatchers (`kind_load`, `kind_monitor`, `kind_update`, `kind_carry` below) select
a kind by its
code; adding a kind is a new module here, a line in KINDS, its header in src/core/kinds/ with
a line in KIND_NAMES and a branch in each dispatcher of dispatch.hpp. The integrator and the
engine never change.

The contract is checked, so a forgotten step cannot run another kind's law:
- at import, every module in KINDS has the names of a kind (`MODULE_NAMES`), and the core knows
  the same kinds in the same code order (`check_core`);
- a code without a branch reaches each dispatcher's final `else`, which writes NaN (the force,
  the event functions and utilisation, the state): the stepper then fails with NOT_FINITE and
  the engine reports it, never another kind's answer;
- `check_dispatch` (run by `model.assemble` before the first model with such mounts) drives
  every code through every dispatcher on a sample input and compares with the kind's own
  `load`, `monitor`, `update` and `carry`; a missing or crossed branch is a
  `KindContractError` at load. It also holds a kind that declares `ROTATIONAL = False` to it:
  the right-hand side then leaves its local rotation and rate uncomputed (NaN) and takes no
  couple from it, so its `load` must give finite forces, rates and a zero couple with NaN there.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import ModuleType

import numpy as np

from mount_twin import _core
from mount_twin.errors import ModelError
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
ELASTOMER = CODES[elastomer.KIND]
BOLTED_JOINT = CODES[bolted_joint.KIND]
SHEAR_KEY = CODES[shear_key.KIND]

MODULE_NAMES = (
    "KIND",
    "EVENTS",
    "EVENT_ERROR",
    "EVENT_STIFFENS",
    "EVENT_SWITCHES",
    "EVENT_COMPANION",
    "ROTATIONAL",
    "RESTUCK",
    "PARAMETERS",
    "N_PAR",
    "CONTACT_STIFFNESS",
    "read",
    "pack",
    "state_names",
    "load",
    "monitor",
    "update",
    "settle",
    "carry",
    "nominal_tangent",
    "piecewise",
    "kinked",
)
"""What a kind module defines (see the module docstring of any kind)."""
COMPANION_TREATMENTS: dict[str, int] = _core.TREATMENTS
"""How the error estimate's companion takes an interval that starts with an event holding (a
kind's EVENT_COMPANION names one), and the core's code for it (kernel.hpp `Treatment`):
"carried", its error carried through it; "integrated", integrated over it by its own method;
"switching", integrated by the twin's own method where the twin's tolerance bound its steps,
else by its own (`engine.companion`). Where several hold, the core takes the highest code."""


class KindContractError(ModelError):
    """A kind module or the dispatchers break the kind contract (a programming error)."""


kind_load = _core.kind_load
"""kind_load(code, p, y, o, d, v, phi, w, dydt, f, c): the kind's `load` as the core runs it:
local force f and couple c on the body; internal rates into dydt. phi and w are the body's
rotation vector and its rate in the mount's axes, and c is taken as the generalized force
conjugate to phi (the right-hand side turns it into the couple on the body). An unknown code
writes NaN into f and c."""
kind_monitor = _core.kind_monitor
"""kind_monitor(code, p, y, y0, o, d, v, g) -> utilisation: the kind's `monitor` as the core
runs it: event functions into g (y0: state at the previous sample). An unknown code writes NaN
into g and returns NaN."""
kind_update = _core.kind_update
"""kind_update(code, p, y, o, d) -> switched: the kind's `update` as the core runs it: discrete
switches between samples. An unknown code writes NaN into the state (its own, or y[0] for a
kind without states; the next step fails) and returns True."""
kind_carries = _core.kind_carries
"""kind_carries(code) -> bool: whether the kind's `carry` returns anything (its CARRIES in the
core; an unknown code: True). The companion takes the carry, and the mount's motion it reads,
only for such a kind (test_kinds_contract holds that the others' write nothing)."""
kind_carry = _core.kind_carry
"""kind_carry(code, p, y, y0, yt, o, d, dt): the kind's `carry` as the core runs it: the error
estimate's companion after its carried error's kick (y after it, y0 before it, yt the twin's
state; d, dt their deflections). An unknown code writes NaN into y[max(o, 0)]."""


def check_modules(kinds: Mapping[str, ModuleType]) -> None:
    """Raise KindContractError unless every module defines `MODULE_NAMES` consistently."""
    for name, module in kinds.items():
        missing = [attr for attr in MODULE_NAMES if not hasattr(module, attr)]
        if missing:
            msg = f"kind {name!r} ({module.__name__}) lacks {', '.join(missing)}"
            raise KindContractError(msg)
        if name != module.KIND:
            msg = f"KINDS maps {name!r} to {module.__name__}, whose KIND is {module.KIND!r}"
            raise KindContractError(msg)
        if not all(0 <= col < module.N_PAR for col in module.CONTACT_STIFFNESS):
            msg = f"kind {name!r}: CONTACT_STIFFNESS names a column outside its N_PAR"
            raise KindContractError(msg)
        for table in ("EVENT_ERROR", "EVENT_STIFFENS", "EVENT_SWITCHES", "EVENT_COMPANION"):
            if len(getattr(module, table)) != len(module.EVENTS):
                msg = f"kind {name!r}: {table} and EVENTS differ in length"
                raise KindContractError(msg)
        if unknown := set(module.EVENT_COMPANION) - COMPANION_TREATMENTS.keys():
            msg = (
                f"kind {name!r}: EVENT_COMPANION holds {', '.join(sorted(map(repr, unknown)))}, "
                f"not one of {', '.join(COMPANION_TREATMENTS)}"
            )
            raise KindContractError(msg)
        for event, stiffens, switch in zip(
            module.EVENTS, module.EVENT_STIFFENS, module.EVENT_SWITCHES, strict=True
        ):
            if stiffens and switch:
                # A start's switches are logged outside the compiled loop
                # (`CoreDriver._log_start_switches`), which alone counts stiffening events and
                # ends a run for `auto` to look again: one at a start would go unexamined.
                msg = (
                    f"kind {name!r}: event {event!r} is a discrete switch that may stiffen the "
                    "scene; `auto` does not look again at a start's switches"
                )
                raise KindContractError(msg)


check_modules(KINDS)


def check_core(kinds: Mapping[str, ModuleType]) -> None:
    """Raise KindContractError unless the core knows exactly these kinds, in this code order
    and with these parameter and event counts (src/core/kinds/dispatch.hpp)."""
    names = tuple(kinds)
    n_par = max(m.N_PAR for m in kinds.values())
    n_events = max(len(m.EVENTS) for m in kinds.values())
    core = (tuple(_core.KIND_NAMES), _core.N_PAR, _core.N_EVENTS)
    if core != (names, n_par, n_events):
        msg = (
            f"the compiled core's kinds {core} differ from mount_twin.kinds' "
            f"{(names, n_par, n_events)}: port the kind to src/core/kinds/ (a header, a line in "
            "KIND_NAMES and a branch in each dispatcher of dispatch.hpp) and rebuild "
            "(pip install -e . or colcon build)"
        )
        raise KindContractError(msg)


check_core(KINDS)

_PROBE_STATE_OFFSET, _PROBE_STATES = 3, 16
"""Where the probe puts a kind's internal states, and the length of its state vector."""
_LOAD_ARGS = ("p", "y", "o", "d", "v", "phi", "w", "dydt", "f", "c")
_MONITOR_ARGS = ("p", "y", "y0", "o", "d", "v", "g")
_UPDATE_ARGS = ("p", "y", "o", "d")
_CARRY_ARGS = ("p", "y", "y0", "yt", "o", "d", "dt")
"""Arguments of a kind's load, monitor, update and carry (after the code, for the
dispatchers)."""


def probe_input(n_par: int, n_events: int, seed: int) -> dict[str, np.ndarray]:
    """A generic sample input: parameters in (0.1, 0.9) (no kind reads a code or a count from
    them as anything but 0), small deflections and rates, states in (0.1, 0.9)."""
    rng = np.random.default_rng(seed)
    return {
        "p": rng.uniform(0.1, 0.9, n_par),
        "y": rng.uniform(0.1, 0.9, _PROBE_STATES),
        "y0": rng.uniform(0.1, 0.9, _PROBE_STATES),
        "d": rng.uniform(-1.0e-3, 1.0e-3, 3),
        "v": rng.uniform(-1.0e-2, 1.0e-2, 3),
        "phi": rng.uniform(-1.0e-3, 1.0e-3, 3),
        "w": rng.uniform(-1.0e-2, 1.0e-2, 3),
        "dydt": np.full(_PROBE_STATES, 0.25),
        "f": np.full(3, 0.25),
        "c": np.full(3, 0.25),
        "g": np.full(n_events, 0.25),
        "yt": rng.uniform(0.1, 0.9, _PROBE_STATES),
        "dt": rng.uniform(-1.0e-3, 1.0e-3, 3),
    }


def dispatch_results(
    code: int, module: ModuleType, x: dict[str, np.ndarray]
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each dispatcher's outputs for `code` and the module's own function's outputs on the
    sample input x (unchanged): {dispatcher name: (dispatched, own)}."""
    found = {}
    for name, dispatcher, own, args, outs in (
        ("kind_load", kind_load, module.load, _LOAD_ARGS, ("f", "c", "dydt")),
        ("kind_monitor", kind_monitor, module.monitor, _MONITOR_ARGS, ("g",)),
        ("kind_update", kind_update, module.update, _UPDATE_ARGS, ("y",)),
        ("kind_carry", kind_carry, module.carry, _CARRY_ARGS, ("y",)),
    ):
        results = []
        for fn, lead in ((dispatcher, (code,)), (own, ())):
            arrays = {k: v.copy() for k, v in x.items()}
            ret = fn(*lead, *(_PROBE_STATE_OFFSET if a == "o" else arrays[a] for a in args))
            parts = [arrays[k] for k in outs]
            if ret is not None:
                parts.append(np.array([ret], dtype=float))
            results.append(np.concatenate(parts))
        found[name] = (results[0], results[1])
    return found


_checked: set[tuple[str, ...]] = set()
"""Kind lists of KINDS already checked in this process."""


def check_dispatch(kinds: Mapping[str, ModuleType] | None = None, samples: int = 2) -> None:
    """Raise KindContractError unless kind_load, kind_monitor, kind_update and kind_carry run,
    for the code of each kind in `kinds` (default KINDS; code = index), that kind's own
    function (same outputs to 1e-12, finite, on `samples` sample inputs): the core's port of
    each kind against its Python reference. Done once per process for KINDS (about a
    millisecond)."""
    kinds = KINDS if kinds is None else kinds
    key = tuple(kinds)
    if kinds is KINDS and key in _checked:
        return
    check_modules(kinds)
    n_par = max(m.N_PAR for m in kinds.values())
    n_events = max(len(m.EVENTS) for m in kinds.values())
    for seed in range(samples):
        x = probe_input(n_par, n_events, seed)
        for code, (name, module) in enumerate(kinds.items()):
            for dispatcher, (got, own) in dispatch_results(code, module, x).items():
                if not np.all(np.isfinite(own)):
                    msg = f"kind {name!r}: the probe input makes its own law non-finite: {own}"
                    raise KindContractError(msg)
                if got.shape != own.shape or not np.allclose(got, own, rtol=1e-12, atol=0.0):
                    msg = (
                        f"{dispatcher} with the code of kind {name!r} ({code}) does not run "
                        f"{module.__name__}: {got} instead of {own}; add or fix its branch in "
                        "mount_twin/kinds/__init__.py"
                    )
                    raise KindContractError(msg)
            if not module.ROTATIONAL:
                _check_not_rotational(name, module, x)
    if kinds is KINDS:
        _checked.add(key)


def _check_not_rotational(name: str, module: ModuleType, x: dict[str, np.ndarray]) -> None:
    """Raise KindContractError unless the kind's load, given NaN for the local rotation and its
    rate, gives finite forces and state rates and a zero couple."""
    arrays = {k: v.copy() for k, v in x.items()}
    arrays["phi"][:] = math.nan
    arrays["w"][:] = math.nan
    module.load(*(_PROBE_STATE_OFFSET if a == "o" else arrays[a] for a in _LOAD_ARGS))
    if not (
        np.isfinite(arrays["f"]).all()
        and np.isfinite(arrays["dydt"]).all()
        and (arrays["c"] == 0.0).all()
    ):
        msg = (
            f"kind {name!r} declares ROTATIONAL = False, but its load reads the local rotation "
            f"or its rate, or gives a couple (force {arrays['f']}, couple {arrays['c']}): "
            "declare ROTATIONAL = True"
        )
        raise KindContractError(msg)
