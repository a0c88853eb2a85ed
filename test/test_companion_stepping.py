"""How the error estimate's companion steps an interval across an event's crossing, in the
compiled loop's own pass (kernel.hpp `halved`): halved by the twin's own method where a joint's
faces switched (friction bounds, whose switches make a step cost what its stages cost), by its
own higher-order method where another event crossed (a contact, whose errors follow the twin's
beside the twin's own method). engine/companion.py says what each read and cost."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mount_twin.engine import companion
from mount_twin.engine.companion import Companion, new_companion
from mount_twin.engine.driver import published_buffers
from mount_twin.engine.kernel import Integrator, Loop, RunOptions, Samples, new_watch, run_samples
from mount_twin.integrate.stepper import new_stepper
from mount_twin.kinds import COMPANION_TREATMENTS, KINDS, N_EVENTS, bolted_joint, shear_key
from mount_twin.model.assemble import Model, assemble, initial_state
from mount_twin.physics.dynamics import INPUT_SIZE
from mount_twin.scene.loader import load_scene_file

GENSET = Path(__file__).resolve().parent.parent / "config" / "genset_bolted_keyed.scene.yaml"
DOPRI54_ROWS = 7
"""Stage rows Dormand–Prince writes in the companion's work array; Verner's pair writes 9."""


def _treatments(model: Model) -> np.ndarray:
    """(non-linear mounts, N_EVENTS): each event's companion treatment, as the driver builds it
    from the kinds' EVENT_COMPANION."""
    table = np.zeros((len(model.nonlinear_slots), N_EVENTS))
    for i, slot in enumerate(model.nonlinear_slots):
        kind = KINDS[model.scene.mounts[slot].kind]
        table[i, : len(kind.EVENTS)] = [COMPANION_TREATMENTS[t] for t in kind.EVENT_COMPANION]
    return table


def _one_interval_crossing(model: Model, crossed: tuple[int, int]) -> Companion:
    """The companion after `run_samples` stepped the genset at rest under gravity over one
    0.1 ms interval under Dormand–Prince, estimate on, where the event `crossed` (non-linear
    mount, event index), below 0 at rest, read ≥ 0 at the sample before (a crossing back), and
    the companion's own slip function of the first joint held at the start (an event it is
    integrated over: not carried). Its work rows past Dormand–Prince's are NaN before."""
    g = np.array([0.0, 0.0, model.scene.input.g])
    y = initial_state(model, g)
    n, k = model.n_state, len(model.nonlinear_slots)
    twin = new_stepper("dopri54", n, 1e-6, 1e-9, 100)
    integ = Integrator(twin.method, twin.settings, twin.work2d, twin.work1d, twin.result)
    treatments = _treatments(model)
    comp = new_companion(
        "dopri54",
        n,
        1e-6,
        1e-9,
        100,
        model.new_scratch(),
        model.n_mounts,
        treatments,
        model.tangent_rate,
    )
    companion.restart(comp, y)
    joint = next(i for i in range(k) if treatments[i, 0] == COMPANION_TREATMENTS["switching"])
    comp.g[joint, bolted_joint.EVENTS.index("joint_slipped")] = 0.0
    comp.work2d[DOPRI54_ROWS:] = np.nan
    watch = new_watch(k, N_EVENTS, n)
    watch.y_prev[:] = y
    watch.g_prev[crossed] = 1.0
    opts = RunOptions(zero_order=False, decimation=1, chain=False)
    loop = Loop(
        integ, model.arrays, model.new_scratch(), np.zeros(INPUT_SIZE), y, opts, watch, comp
    )
    samples = Samples(np.array([0.0, 1e-4]), np.tile(g, (2, 1)), np.zeros((2, 3)))
    out = published_buffers(2, np.zeros(1, np.int64), np.zeros((model.n_mounts, 6)), np.zeros(0))
    assert run_samples(loop, samples, out) == (1, 0)
    assert watch.g[crossed] < 0.0, "the event was to cross back below 0 over the interval"
    return comp


def _first(model: Model, kind_name: str) -> int:
    """The index among the non-linear mounts of the first mount of kind `kind_name`."""
    kinds = [model.scene.mounts[slot].kind for slot in model.nonlinear_slots]
    return kinds.index(kind_name)


def test_a_joints_crossing_is_halved_by_the_twins_own_method() -> None:
    """A joint's slip function crossing: Dormand–Prince (its 7 stage rows alone) at twice its
    fewest steps (4), not Verner's pair (which wrote its rows 8 and 9)."""
    model = assemble(load_scene_file(GENSET))
    slip = bolted_joint.EVENTS.index("joint_slipped")
    comp = _one_interval_crossing(model, (_first(model, "bolted_joint"), slip))
    assert np.isnan(comp.work2d[DOPRI54_ROWS:]).all()
    assert comp.result[1] >= 2 * comp.switching_min_steps == 4


def test_a_contacts_crossing_is_halved_by_the_companions_own_method() -> None:
    """A key's contact function crossing (a contact, carried where it holds): Verner's pair, the
    companion's own method, at twice its fewest steps (2)."""
    model = assemble(load_scene_file(GENSET))
    contact = shear_key.EVENTS.index("key_contact")
    comp = _one_interval_crossing(model, (_first(model, "shear_key"), contact))
    assert np.isfinite(comp.work2d[DOPRI54_ROWS:]).all()
    assert comp.result[1] >= 2
