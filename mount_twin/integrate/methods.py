"""The integration methods and the statuses of a step: the one list of both.

The scene loader offers `METHODS` as `integration.method`; `integrate.stepper` builds its
factories and its compiled switch from it; every method's compiled `advance` returns one of the
statuses below and the engine reports `STATUS_TEXT` of a failure. Pure Python (no numba): the
scene loader imports it.

Adding a method: a module with its coefficient table and compiled `advance` (see `dopri54`), an
entry here, and a branch in `stepper.advance` (test/test_integrate_methods.py checks the tables
and that every method here is dispatched).
"""

from __future__ import annotations

from dataclasses import dataclass

SUCCESS = 0
TOO_MANY_STEPS = 1
STEP_TOO_SMALL = 2
LEFT_CHART = 3
NOT_FINITE = 4
UNKNOWN_METHOD = -1

STATUS_TEXT: dict[int, str] = {
    SUCCESS: "ok",
    TOO_MANY_STEPS: "too many substeps in one input interval",
    STEP_TOO_SMALL: "step size underflow",
    LEFT_CHART: "attitude left the α/γ/δ chart (tilt reached 90°)",
    NOT_FINITE: "the right-hand side stayed non-finite (NaN/inf) down to the smallest step",
    UNKNOWN_METHOD: "unknown stepper",
}
"""Status of a stepper's `advance` → the text the engine reports on a failure."""


@dataclass(frozen=True)
class Method:
    """An explicit embedded Runge–Kutta method.

    Attributes:
        name: scene name (`integration.method`).
        id: its branch in the compiled `stepper.advance`.
        module: the module holding its tables (C, A, B, E as numpy arrays; ORDER, the order of
            the error estimate; FSAL) and its compiled `advance`.
        order: order of the solution it propagates.
        stages: rows of its stage work array (stages, the FSAL one included).
        summary: one line for parameter descriptions.
    """

    name: str
    id: int
    module: str
    order: int
    stages: int
    summary: str


METHODS: dict[str, Method] = {
    m.name: m
    for m in (
        Method(
            "dopri54",
            0,
            "mount_twin.integrate.dopri54",
            5,
            7,
            "adaptive Dormand–Prince 5(4) inside each sample interval",
        ),
    )
}
"""Methods by scene name; ids are distinct (test/test_integrate_methods.py)."""

DOPRI54 = METHODS["dopri54"].id
