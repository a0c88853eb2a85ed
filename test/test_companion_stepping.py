"""How the error estimate's companion steps an interval across an event's crossing, in the
compiled loop's own pass (kernel.hpp `halved`): halved by the twin's own method where a joint's
faces switched (friction bounds, whose switches make a step cost what its stages cost), by its
own higher-order method where another event crossed (a contact, whose errors follow the twin's
beside the twin's own method). engine/companion.py says what each read and cost."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from loop_helpers import companion_of, step_one_interval

from mount_twin.engine import companion
from mount_twin.engine.companion import Companion
from mount_twin.engine.driver import event_table
from mount_twin.engine.kernel import new_watch
from mount_twin.integrate.methods import METHODS
from mount_twin.kinds import COMPANION_TREATMENTS, N_EVENTS, bolted_joint, shear_key
from mount_twin.model.assemble import Model, assemble, initial_state
from mount_twin.scene.loader import load_scene_file

GENSET = Path(__file__).resolve().parent.parent / "config" / "genset_bolted_keyed.scene.yaml"


def _dopri54_rows(model: Model) -> int:
    """Rows of the companion's work array Dormand–Prince writes (its stages); Verner's pair,
    the companion's own method beside it, writes more."""
    rows = METHODS["dopri54"].work_rows(model.n_state)
    assert METHODS["verner65"].work_rows(model.n_state) > rows
    return rows


def _one_interval_crossing(model: Model, crossed: tuple[int, int]) -> Companion:
    """The companion after `run_samples` stepped the genset at rest under gravity over one
    0.1 ms interval under Dormand–Prince, estimate on, where the event `crossed` (non-linear
    mount, event index), below 0 at rest, read ≥ 0 at the sample before (a crossing back), and
    the companion's own slip function of the first joint held at the start (an event it is
    integrated over: not carried). Its work rows past Dormand–Prince's are NaN before."""
    g = np.array([0.0, 0.0, model.scene.input.g])
    y = initial_state(model, g)
    n = model.n_state
    treatments = event_table(model, "EVENT_COMPANION", COMPANION_TREATMENTS.__getitem__)
    comp = companion_of(model, "dopri54", model.tangent_rate, treatments)
    companion.restart(comp, y)
    slip = bolted_joint.EVENTS.index("joint_slipped")
    comp.g[_first(model, "bolted_joint"), slip] = 0.0
    comp.work2d[_dopri54_rows(model) :] = np.nan
    watch = new_watch(len(model.nonlinear_slots), N_EVENTS, n)
    watch.y_prev[:] = y
    watch.g_prev[crossed] = 1.0
    step_one_interval(model, y, g, watch, chain=False, estimate=comp)
    assert watch.g[crossed] < 0.0, "the event was to cross back below 0 over the interval"
    return comp


def _first(model: Model, kind_name: str) -> int:
    """The index among the non-linear mounts of the first mount of kind `kind_name`."""
    kinds = [model.scene.mounts[slot].kind for slot in model.nonlinear_slots]
    return kinds.index(kind_name)


def test_a_joints_crossing_is_halved_by_the_twins_own_method() -> None:
    """A joint's slip function crossing: Dormand–Prince (its stage rows alone written) at twice
    its fewest steps (4), not Verner's pair (which writes rows past them)."""
    model = assemble(load_scene_file(GENSET))
    slip = bolted_joint.EVENTS.index("joint_slipped")
    comp = _one_interval_crossing(model, (_first(model, "bolted_joint"), slip))
    assert np.isnan(comp.work2d[_dopri54_rows(model) :]).all()
    assert comp.result[1] >= 2 * comp.switching_min_steps == 4


def test_a_contacts_crossing_is_halved_by_the_companions_own_method() -> None:
    """A key's contact function crossing (a contact, carried where it holds): Verner's pair, the
    companion's own method, at twice its fewest steps (2)."""
    model = assemble(load_scene_file(GENSET))
    contact = shear_key.EVENTS.index("key_contact")
    comp = _one_interval_crossing(model, (_first(model, "shear_key"), contact))
    assert np.isfinite(comp.work2d[_dopri54_rows(model) :]).all()
    assert comp.result[1] >= 2


def test_the_loop_refuses_an_exact_method_the_companions_arrays_do_not_hold() -> None:
    """The companion of Dormand–Prince has arrays for Verner's pair and Dormand–Prince alone:
    given the exponential method for the intervals its twin steps over (which only a Rosenbrock
    twin's companion takes, in arrays made for every method), the loop refuses it by name
    before any step, where the φ functions would have run past the arrays."""
    model = assemble(load_scene_file(GENSET))
    g = np.array([0.0, 0.0, model.scene.input.g])
    y = initial_state(model, g)
    comp = companion_of(model, "dopri54")._replace(exact_method=METHODS["exprb32"].id)
    assert comp.work2d.shape[0] < METHODS["exprb32"].work_rows(model.n_state)
    watch = new_watch(len(model.nonlinear_slots), N_EVENTS, model.n_state)
    with pytest.raises(ValueError, match=r"Companion\.exact_method"):
        step_one_interval(model, y, g, watch, chain=False, estimate=comp)


@pytest.mark.parametrize(
    ("method", "steps"), [("dopri54", 0), ("dopri54", 1.5), ("ros34pw2", 1), ("exprb32", 2)]
)
def test_the_loop_refuses_a_check_it_cannot_take(method: str, steps: float) -> None:
    """A carried interval's check takes `check_method` at `check_steps` equal steps: the loop
    refuses, by name and before any step, a count that is not a whole number of at least one,
    and a method that is not explicit first-same-as-last (whose stages the chained first one
    would not fit) or not in the companion's arrays."""
    model = assemble(load_scene_file(GENSET))
    g = np.array([0.0, 0.0, model.scene.input.g])
    y = initial_state(model, g)
    check = {"check_method": METHODS[method].id, "check_steps": steps}
    comp = companion_of(model, "dopri54")._replace(**check)
    watch = new_watch(len(model.nonlinear_slots), N_EVENTS, model.n_state)
    with pytest.raises(ValueError, match=r"Companion\.check_method"):
        step_one_interval(model, y, g, watch, chain=False, estimate=comp)
