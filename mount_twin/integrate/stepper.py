"""Steppers behind one interface: advance the state across one input interval.

A stepper is a compiled free function with the uniform signature of `dopri54.advance` (the
core's, src/core/integrate/) plus this small holder of its settings and work arrays (scipy
`integrate/_ivp` shape). Numerical failure is returned as a status
(`integrate.methods.STATUS_TEXT`); misuse raises. `advance` below switches on the method id, in
the core (src/core/integrate/stepper.hpp): a new method is an entry in
`integrate.methods.METHODS`, its header and a branch there, and the engine is untouched.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mount_twin import _core
from mount_twin.errors import ModelError
from mount_twin.integrate.methods import (
    AUTO,
    METHODS,
    STATUS_TEXT,
    Method,
)
from mount_twin.integrate.settings import (
    ATOL,
    HOLD_AFTER_REJECT,
    MAX_SUBSTEPS,
    MIN_STEPS,
    N_SETTINGS,
    RTOL,
)

__all__ = [
    "METHODS",
    "STATUS_TEXT",
    "Stepper",
    "advance",
    "advance_fixed",
    "dormand_prince",
    "new_stepper",
    "switch",
]


def check_methods(methods: dict[str, Method]) -> None:
    """Raise ModelError unless the core dispatches every method of `methods` with the work rows
    its entry says: a method registered without its branch in the core (which would load, then
    fail every interval with UNKNOWN_METHOD) is refused at import, by name."""
    for name, m in methods.items():
        rows = _core.work_rows(m.id, 1)
        if rows < 0:
            msg = f"integration method {name!r} (id {m.id}) has no branch in the core's advance"
            raise ModelError(msg)
        if rows != m.work_rows(1):
            msg = f"integration method {name!r}: the core needs {rows} work rows, its entry says"
            msg += f" {m.work_rows(1)}"
            raise ModelError(msg)


check_methods(METHODS)


@dataclass
class Stepper:
    """A compiled stepper with its settings and work arrays for one state length.

    Attributes:
        name: scene name of the method.
        method: its id for `advance`.
        settings: (N_SETTINGS,) by the slots of `integrate.settings` (STEP, RTOL, ATOL,
            MAX_SUBSTEPS, CHAINED, MIN_STEPS).
        work2d, work1d: the method's work arrays.
        result: last advance's [largest accepted error norm, accepted, rejected substeps].
    """

    name: str
    method: int
    settings: np.ndarray
    work2d: np.ndarray
    work1d: np.ndarray
    result: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def reset(self) -> None:
        """Forget the step-size history and any Jacobian (after a restart of the state)."""
        forget(self.settings)


def new_stepper(
    method: str,
    n: int,
    rtol: float,
    atol: float,
    max_substeps: int,
    min_steps: int = 1,
    *,
    hold_after_reject: bool = False,
) -> Stepper:
    """A stepper of `method` (a name in METHODS, or AUTO: work arrays for any method, running
    dopri54 until `switch`) for n states; atol in the state's units (m, rad, m/s, rad/s); at
    least `min_steps` steps per input interval; `hold_after_reject`: no step accepted right
    after a rejection proposes a longer one (`integrate.settings` HOLD_AFTER_REJECT)."""
    if method not in METHODS and method != AUTO:
        msg = f"unknown integration method {method!r}; choose from {', '.join(METHODS)}"
        raise ValueError(msg)
    if n <= 0 or not rtol > 0.0 or not atol > 0.0 or not 1 <= min_steps <= max_substeps:
        msg = (
            f"bad stepper settings: n={n}, rtol={rtol}, atol={atol}, max={max_substeps}, "
            f"min={min_steps}"
        )
        raise ValueError(msg)
    spec = METHODS["dopri54" if method == AUTO else method]
    rows = max(m.work_rows(n) for m in METHODS.values()) if method == AUTO else spec.work_rows(n)
    settings = np.zeros(N_SETTINGS)
    settings[RTOL], settings[ATOL], settings[MAX_SUBSTEPS] = rtol, atol, float(max_substeps)
    settings[MIN_STEPS] = float(min_steps)
    settings[HOLD_AFTER_REJECT] = float(hold_after_reject)
    return Stepper(spec.name, spec.id, settings, np.zeros((rows, n)), np.zeros(n))


def tighter_arrays(
    method: str,
    n: int,
    rtol: float,
    atol: float,
    max_substeps: int,
    divisor: float,
    min_steps: int,
    *,
    hold_after_reject: bool = False,
) -> tuple[int, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(method id, settings, work2d, work1d, result) of a stepper like the twin's (`method`,
    rtol, atol, max_substeps) at its tolerances over `divisor` and at least `min_steps` steps
    per interval (up to min_steps × max_substeps; `hold_after_reject` as `new_stepper`): the
    error estimate's own stepper, the leading fields of `engine.kernel.Integrator` and of the
    estimate's arrays."""
    own = new_stepper(
        method,
        n,
        rtol / divisor,
        atol / divisor,
        min_steps * max_substeps,
        min_steps,
        hold_after_reject=hold_after_reject,
    )
    return own.method, own.settings, own.work2d, own.work1d, own.result


def switch(st: Stepper, method: str) -> None:
    """Run `method` (a name in METHODS) with st from now on, its step history forgotten; st's
    work arrays must hold it (a stepper made for AUTO holds any)."""
    spec = METHODS[method]
    n = st.work1d.shape[0]
    if st.work2d.shape[0] < spec.work_rows(n):
        msg = f"stepper work arrays hold {st.work2d.shape[0]} rows, {method} needs more"
        raise ValueError(msg)
    st.name, st.method = spec.name, spec.id
    st.reset()


def dormand_prince(n: int, rtol: float, atol: float, max_substeps: int) -> Stepper:
    """Adaptive explicit Runge–Kutta 5(4) for non-stiff scenes (rubber mounts)."""
    return new_stepper("dopri54", n, rtol, atol, max_substeps)


advance = _core.advance
"""advance(method, y, t0, t1, settings, m, s, u, work2d, work1d, result) -> status: advance y
from t0 to t1 (s) with the stepper `method` (its id; UNKNOWN_METHOD for an id no method has,
nothing touched); the core checks the work arrays hold the method (`Method.work_rows`)."""
advance_fixed = _core.advance_fixed
"""advance_fixed(method, y, t0, t1, settings, m, s, u, work2d, work1d, result) -> status:
`advance` by settings[MIN_STEPS] equal steps of an explicit method, every one taken (no error
control; the proposal settings[STEP] untouched); result [largest error norm, steps, 0];
UNKNOWN_METHOD for a method that is not explicit (nothing touched)."""
forget = _core.forget
"""forget(settings): forget a stepper's history (after its state jumped: a start, a restart, a
resync): the step proposal, the chained last stage, the Jacobian held and its matrix functions."""
