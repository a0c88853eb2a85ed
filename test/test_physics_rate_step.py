"""`rhs_after_rate_step` (the sample-to-sample chaining of the stepper's last stage) against a
fresh right-hand side evaluated with the new input, on linear mounts and on the bolted, keyed
genset; and a discrete switch between samples (a bolt breaking) ending the chain."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from io_helpers import default_scene
from loop_helpers import step_one_interval

from mount_twin.engine.kernel import new_watch
from mount_twin.integrate.settings import CHAINED
from mount_twin.kinds import N_EVENTS, bolted_joint
from mount_twin.model.assemble import assemble, initial_state
from mount_twin.physics.dynamics import INPUT_SIZE, OK, rhs, rhs_after_rate_step
from mount_twin.scene.loader import load_scene_file

GENSET = Path(__file__).resolve().parent.parent / "config" / "genset_bolted_keyed.scene.yaml"


@pytest.mark.parametrize(
    "dofs",
    [("x", "y", "z", "alpha", "gamma", "delta"), ("z", "alpha", "gamma"), ("x", "y"), ("delta",)],
    ids=["6dof", "z_alpha_gamma", "x_y", "delta_only"],
)
def test_moving_the_last_stage_to_a_new_rate_equals_a_fresh_right_hand_side(dofs) -> None:
    _check_rate_step(dataclasses.replace(default_scene(), dofs=dofs), 0.01, 0.2)


def test_the_rate_step_holds_on_bolted_joints_and_keys_and_their_states() -> None:
    """The genset's mounts switch (stick, slip, bearing): Ω' still enters only the body's rows,
    and the mounts' internal-state rates, which depend on the motion, not on Ω', stay."""
    _check_rate_step(load_scene_file(GENSET), 2e-4, 0.05)


def _check_rate_step(scene, position: float, rate: float) -> None:
    """20 random states (positions ~`position` m or rad, rates ~`rate`) and input steps."""
    model = assemble(scene)
    rng = np.random.default_rng(5)
    nf = len(scene.dofs)
    for _ in range(20):
        y = np.zeros(model.n_state)
        y[:nf] = rng.normal(0.0, position, nf)
        y[nf : 2 * nf] = rng.normal(0.0, rate, nf)
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


def test_a_bolt_breaking_between_samples_ends_the_chain() -> None:
    """The stepper's last stage starts the next interval only while the state is continuous: a
    bolt that breaks between samples (its `update`, in the compiled loop's pass over the mounts
    at the sample, which takes their monitors with their outputs) clears the twin's chain flag,
    and nothing else does."""
    model = assemble(load_scene_file(GENSET))
    nl = model.arrays.nl
    g = np.array([0.0, 0.0, model.scene.input.g])
    y = initial_state(model, g)
    foot = int(nl.state[0])  # the first foot's internal states: plastic elongation first
    for broken in (False, True):
        if broken:
            y[foot] = nl.par[0, bolted_joint.EPU]  # at its ultimate plastic elongation
        state = y.copy()
        watch = new_watch(len(model.nonlinear_slots), N_EVENTS, model.n_state)
        watch.y_prev[:] = state
        settings = step_one_interval(model, state, g, watch, chain=True).settings
        assert state[foot + 3] == (1.0 if broken else 0.0)
        assert settings[CHAINED] == (0.0 if broken else 1.0)
