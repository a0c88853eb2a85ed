"""`rhs_after_rate_step` (the sample-to-sample chaining of the stepper's last stage) against a
fresh right-hand side evaluated with the new input."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from io_helpers import default_scene

from mount_twin.model.assemble import assemble
from mount_twin.physics.dynamics import INPUT_SIZE, OK, rhs, rhs_after_rate_step


@pytest.mark.parametrize(
    "dofs",
    [("x", "y", "z", "alpha", "gamma", "delta"), ("z", "alpha", "gamma"), ("x", "y"), ("delta",)],
    ids=["6dof", "z_alpha_gamma", "x_y", "delta_only"],
)
def test_moving_the_last_stage_to_a_new_rate_equals_a_fresh_right_hand_side(dofs) -> None:
    scene = dataclasses.replace(default_scene(), dofs=dofs)
    model = assemble(scene)
    rng = np.random.default_rng(5)
    nf = len(dofs)
    for _ in range(20):
        y = np.zeros(model.n_state)
        y[:nf] = rng.normal(0.0, 0.01, nf)
        y[nf:] = rng.normal(0.0, 0.2, nf)
        t, t0 = 0.37, 0.36  # a sample inside the old interval's input, at its end
        u_old = np.zeros(INPUT_SIZE)
        u_old[0] = t0
        u_old[1:4] = rng.normal(0.0, 1.0, 3) + np.array([0.0, 0.0, 9.81])
        u_old[4:7] = rng.normal(0.0, 50.0, 3)
        u_old[7:10] = rng.normal(0.0, 0.1, 3)
        u_old[10:13] = rng.normal(0.0, 2.0, 3)
        # The new interval starts at t with the same specific force and Ω there, a new Ω'.
        u_new = np.zeros(INPUT_SIZE)
        u_new[0] = t
        u_new[1:4] = u_old[1:4] + u_old[4:7] * (t - t0)
        u_new[4:7] = rng.normal(0.0, 50.0, 3)
        u_new[7:10] = u_old[7:10] + u_old[10:13] * (t - t0)
        u_new[10:13] = rng.normal(0.0, 2.0, 3)

        s = model.new_scratch()
        chained = np.zeros(model.n_state)
        assert rhs(t, y, model.arrays, s, u_old, chained) == OK
        before = chained.copy()
        rhs_after_rate_step(model.arrays, s, u_new[10:13] - u_old[10:13], chained)
        fresh = np.zeros(model.n_state)
        assert rhs(t, y, model.arrays, model.new_scratch(), u_new, fresh) == OK
        scale = np.abs(fresh).max()
        np.testing.assert_allclose(chained, fresh, rtol=0, atol=1e-12 * scale)
        # and the step matters: without it the chained stage would be this far off
        assert np.abs(before - fresh).max() > 1e-6 * scale
