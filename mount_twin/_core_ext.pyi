# Types of the compiled core (src/core, built by setup.py); docstrings live in the bindings
# (`help(mount_twin._core.rhs)`). Units and layouts: the Python modules that re-export these.
from typing import Any

import numpy as np

_A = np.ndarray[Any, Any]

SETTING_SLOTS: tuple[int, ...]
STATUSES: tuple[int, ...]
METHOD_IDS: tuple[int, ...]
POSE_ROW: tuple[int, int, int, int]
FIGURE_SLOTS: tuple[int, ...]
ESTIMATOR_SLOTS: tuple[int, ...]
ERROR_ROWS: tuple[int, ...]
CARRY_SLOTS: tuple[int, ...]
TREATMENTS: dict[str, int]
KICK_LIMIT: float
ENGAGED_CHECK_EVERY: float
PERIOD_SHARE: float
BOUND_PERIOD_SHARE: float
SPIKE_RATIO: float
OUTPUT_STRIDE_MAX: float
AT_EVENT: int
INPUT_SIZE: int
SOURCE_SHA256: str
COS_TILT_MIN: float
CENTRAL_STEP: float
KIND_NAMES: tuple[str, ...]
N_PAR: int
N_EVENTS: int

def kind_load(
    code: int, p: _A, y: _A, o: int, d: _A, v: _A, phi: _A, w: _A, dydt: _A, f: _A, c: _A
) -> None: ...
def kind_monitor(code: int, p: _A, y: _A, y0: _A, o: int, d: _A, v: _A, g: _A) -> float: ...
def kind_update(code: int, p: _A, y: _A, o: int, d: _A) -> bool: ...
def kind_carries(code: int) -> bool: ...
def kind_carry(code: int, p: _A, y: _A, y0: _A, yt: _A, o: int, d: _A, dt: _A) -> None: ...
def rhs(t: float, y: _A, m: Any, s: Any, u: _A, dydt: _A) -> int: ...
def body_motion(y: _A, m: Any, s: Any) -> float: ...
def evaluate(y: _A, m: Any, s: Any, pose: _A, wrenches: _A) -> float: ...
def outputs(y: _A, m: Any, s: Any, pose: _A, wrenches: _A) -> None: ...
def mount_wrenches(y: _A, m: Any, s: Any, wrenches: _A) -> None: ...
def mount_deflections(y: _A, m: Any, s: Any, d: _A) -> float: ...
def linear_utilisation(y: _A, m: Any, s: Any, wrenches: _A, peak: _A) -> None: ...
def mount_monitors(y: _A, y0: _A, nl: Any, s: Any, g: _A, util: _A) -> bool: ...
def rhs_after_rate_step(m: Any, s: Any, d_wdot: _A, dydt: _A) -> None: ...
def central_columns(
    y: _A, t: float, m: Any, s: Any, u: _A, plus: _A, minus: _A, jac: _A
) -> bool: ...
def advance(
    method: int,
    y: _A,
    t0: float,
    t1: float,
    settings: _A,
    m: Any,
    s: Any,
    u: _A,
    work2d: _A,
    work1d: _A,
    result: _A,
) -> int: ...

advance_fixed = advance

def dopri54_advance(
    y: _A, t0: float, t1: float, settings: _A, m: Any, s: Any, u: _A, k: _A, y_new: _A, result: _A
) -> int: ...
def ros34pw2_advance(
    y: _A, t0: float, t1: float, settings: _A, m: Any, s: Any, u: _A, k: _A, y_new: _A, result: _A
) -> int: ...
def exprb32_advance(
    y: _A, t0: float, t1: float, settings: _A, m: Any, s: Any, u: _A, k: _A, y_new: _A, result: _A
) -> int: ...
def verner65_advance(
    y: _A, t0: float, t1: float, settings: _A, m: Any, s: Any, u: _A, k: _A, y_new: _A, result: _A
) -> int: ...
def forget(settings: _A) -> None: ...
def phi_functions(k: _A, n: int, h: float, b: Any) -> bool: ...

class Loop:
    def __init__(
        self,
        integ: Any,
        m: Any,
        s: Any,
        u: _A,
        y: _A,
        opts: Any,
        watch: Any,
        estimate: Any,
    ) -> None: ...

def run_samples(loop: Loop, samples: Any, out: Any) -> tuple[int, int]: ...
def close_estimate(loop: Loop) -> None: ...
def fir_rows(raw: _A, half: _A, out: _A) -> None: ...
def expm(a: _A, scale: float) -> _A: ...
def method_tables() -> dict[str, dict[str, Any]]: ...
def work_rows(method: int, n: int) -> int: ...
