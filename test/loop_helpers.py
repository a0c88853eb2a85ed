"""One input interval through the compiled loop itself (`engine.kernel.run_samples`), for tests
that check what the loop does at a sample, not what the driver around it does; and the error
estimate's companion as those tests build it."""

from __future__ import annotations

import numpy as np

from mount_twin.engine.companion import Companion, new_companion
from mount_twin.engine.driver import published_buffers
from mount_twin.engine.kernel import Integrator, Loop, RunOptions, Samples, Watch, run_samples
from mount_twin.integrate.stepper import Stepper, new_stepper
from mount_twin.kinds import N_EVENTS
from mount_twin.model.assemble import Model
from mount_twin.physics.dynamics import INPUT_SIZE

INTERVAL_S = 1e-4
"""The interval stepped: one sample at 10 kHz."""


def companion_of(
    model: Model,
    method: str,
    kick_rate: float = 1.0,
    treatments: np.ndarray | None = None,
) -> Companion:
    """A companion of `model`'s twin by `method` at rtol 1e-6, atol 1e-9, 100 substeps, with
    the body's fastest tangent mode `kick_rate` (rad/s) and the event `treatments` (non-linear
    mounts, N_EVENTS; default all 0)."""
    k = len(model.nonlinear_slots)
    return new_companion(
        method,
        model.n_state,
        1e-6,
        1e-9,
        100,
        model.new_scratch(),
        model.n_mounts,
        np.zeros((k, N_EVENTS)) if treatments is None else treatments,
        kick_rate,
        linear_stiffness=model.linear_stiffness,
        kinked=model.kinked,
    )


def step_one_interval(
    model: Model,
    state: np.ndarray,
    g: np.ndarray,
    watch: Watch,
    *,
    chain: bool,
    estimate: Companion | None = None,
) -> Stepper:
    """The twin's Dormand–Prince stepper (rtol 1e-6, atol 1e-9) after `run_samples` stepped
    `state` (in place) over one INTERVAL_S interval under the constant specific force g (m/s²,
    F) and no rotation of the foundation, with `watch` and the error estimate `estimate`
    (None: off); `chain`: the first stage chained from the sample's rate step."""
    twin = new_stepper("dopri54", model.n_state, 1e-6, 1e-9, 100)
    integ = Integrator(twin.method, twin.settings, twin.work2d, twin.work1d, twin.result)
    opts = RunOptions(zero_order=False, decimation=1, chain=chain)
    loop = Loop(
        integ,
        model.arrays,
        model.new_scratch(),
        np.zeros(INPUT_SIZE),
        state,
        opts,
        watch,
        estimate,
    )
    samples = Samples(np.array([0.0, INTERVAL_S]), np.tile(g, (2, 1)), np.zeros((2, 3)))
    nm = model.n_mounts
    out = published_buffers(2, np.zeros(1, np.int64), np.zeros((nm, 6)), np.zeros(0))
    assert run_samples(loop, samples, out) == (1, 0)
    return twin
