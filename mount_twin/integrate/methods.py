"""The integration methods and the statuses of a step: the one list of both.

The scene loader offers `METHODS` (and AUTO) as `integration.method`; `integrate.stepper`
sizes its work arrays and builds its compiled switch from it; every method's compiled `advance`
returns one of the statuses below and the engine reports `STATUS_TEXT` of a failure. Pure
Python: the scene loader imports it.

Adding a method: a module with its coefficient table (see `dopri54`, `ros34pw2`, `exprb32`), its
compiled `advance` in the core (src/core/integrate/<method>.hpp, bound as `<method>_advance`; an
explicit first-same-as-last pair is only its `Table` struct, which `explicit_rk::advance` and
the bindings read, as dopri54.hpp's is), an entry here, and a branch in the core's
`integrate::advance` (and, for an explicit pair, in the bindings' `method_tables`). A method
here without that branch, or with other work rows than the core's, is refused at import
(`stepper.check_methods`); test/test_integrate_methods.py checks the tables and that every
method is dispatched, test/test_core_contract.py that the core has the same ids.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mount_twin.physics.rotations import angle_text

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
    LEFT_CHART: f"attitude left the α/γ/δ chart: tilt reached {angle_text(math.pi / 2)}",
    NOT_FINITE: "the right-hand side stayed non-finite (NaN/inf) down to the smallest step",
    UNKNOWN_METHOD: "unknown stepper",
}
"""Status of a stepper's `advance` → the text the engine reports on a failure."""


EXPLICIT, ROSENBROCK, EXPONENTIAL = "explicit", "rosenbrock", "exponential"
"""Families of methods: what a method's module holds (its tables) and which tests apply."""


@dataclass(frozen=True)
class Method:
    """An embedded method: explicit Runge–Kutta, linearly implicit (Rosenbrock) or exponential.

    Attributes:
        name: scene name (`integration.method`).
        id: its branch in the compiled `stepper.advance`.
        module: the module holding its tables (explicit: C, A, B, E as numpy arrays and FSAL;
            Rosenbrock: ALPHA, GAMMAS, GAMMA, B, B_HAT; all ORDER, the order of the error
            estimate; those that hold a Jacobian JACOBIAN_MAX_AGE) and its compiled `advance`.
        order: order of the solution it propagates.
        stages: fixed rows of its work array (explicit: the stages, the FSAL one included).
        square_blocks: further rows per state (n×n blocks: the Rosenbrock's J and LU, the
            exponential method's J, φ functions, their work and the half step's φ functions).
        family: EXPLICIT, ROSENBROCK or EXPONENTIAL (the last two hold a Jacobian, taken by
            finite differences, for stiff scenes).
        summary: one line for parameter descriptions.
    """

    name: str
    id: int
    module: str
    order: int
    stages: int
    summary: str
    square_blocks: int = 0
    family: str = EXPLICIT

    @property
    def holds_jacobian(self) -> bool:
        """Linearises the model (a Jacobian held across intervals)."""
        return self.family != EXPLICIT

    def work_rows(self, n: int) -> int:
        """Rows of n of the work array for n states."""
        return self.stages + self.square_blocks * n


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
        Method(
            "ros34pw2",
            1,
            "mount_twin.integrate.ros34pw2",
            3,
            10,
            "L-stable Rosenbrock-W 3(2) for stiff scenes (a Jacobian per sample interval)",
            square_blocks=2,
            family=ROSENBROCK,
        ),
        Method(
            "exprb32",
            2,
            "mount_twin.integrate.exprb32",
            3,
            7,
            "exponential Rosenbrock 3(2), exact on linear mounts (stiff, smooth scenes)",
            square_blocks=11,
            family=EXPONENTIAL,
        ),
        Method(
            "verner65",
            3,
            "mount_twin.integrate.verner65",
            6,
            9,
            "adaptive Verner 6(5) (the error estimate's companion of dopri54)",
        ),
    )
}
"""Methods by scene name; ids are distinct (test/test_integrate_methods.py)."""

DOPRI54 = METHODS["dopri54"].id
ROS34PW2 = METHODS["ros34pw2"].id
EXPRB32 = METHODS["exprb32"].id
VERNER65 = METHODS["verner65"].id

AUTO = "auto"
"""`integration.method: auto` (the default): `choose` decides at each start's first input
interval (the first start's and every restart's) and again after an event that may stiffen the
scene (`engine.auto_method` takes ρ)."""
STIFF_RHO_DT = 10.0
"""ρ·Δt (the body's fastest rate, rad/s, as `engine.auto_method` takes it, times the sample
interval, s) past which `auto` takes a method that does not step at the stiff modes' rate:
Dormand–Prince's stability reaches |hλ| ≈ 3.3 along the imaginary axis, so it would need at
least three steps per sample for stability alone. The bundled pump is at 0.12 (1 kHz), the
genset at 0.36 (10 kHz) and 3.6 (1 kHz), 10 kg on 4 × 1e9 N/m at 31.6 (1 kHz)."""


def choose(rho_dt: float, smooth: bool) -> str:
    """The method `auto` takes for a scene whose ρ·Δt (see STIFF_RHO_DT) is `rho_dt`: past it,
    on a `smooth` scene (its stiff modes its linear mounts': no mount's law has pieces, the
    non-linear mounts soft; `Model.linear_stiffness`) the exponential method, exact on the
    linear part (its modes resolved in one step per sample); where a mount's law has pieces
    (contact, slip, joints opening) or the non-linear mounts are stiff, the L-stable Rosenbrock,
    which damps what a switch rings: on a stiff contact the exponential method is the worst of
    the three (docs/scene.md, `bench/stiff_methods.py --case key`)."""
    if rho_dt <= STIFF_RHO_DT:
        return "dopri54"
    return "exprb32" if smooth else "ros34pw2"
