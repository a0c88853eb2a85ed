"""The compiled core (src/core, `mount_twin._core`) and the Python side agree on every number
they share, and the core refuses what does not fit instead of reading the wrong memory.

The Python modules name the slots, codes and layouts (settings, statuses, method ids, pose
rows, the error estimate's figures, the kinds); the core has its own copies as C++ constants.
An edit on one side alone fails here, not as wrong physics.
"""

from __future__ import annotations

import importlib
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from io_helpers import CONFIG, default_scene

from mount_twin import _core, core_sources
from mount_twin.engine import estimate, kernel
from mount_twin.integrate import methods, settings
from mount_twin.kinds import KINDS, N_EVENTS, N_PAR
from mount_twin.model.assemble import assemble, initial_state
from mount_twin.physics import dynamics, pose_row
from mount_twin.scene.description import DOF_NAMES


def test_the_settings_slots_are_the_cores() -> None:
    names = ("STEP", "RTOL", "ATOL", "MAX_SUBSTEPS", "CHAINED", "MIN_STEPS", "JACOBIAN_AGE")
    later = ("PHI_STEP", "HOLD_AFTER_REJECT", "N_SETTINGS")
    python = tuple(getattr(settings, n) for n in (*names, *later))
    assert python == _core.SETTING_SLOTS


def test_the_statuses_and_method_ids_are_the_cores() -> None:
    statuses = ("SUCCESS", "TOO_MANY_STEPS", "STEP_TOO_SMALL", "LEFT_CHART", "NOT_FINITE")
    python = tuple(getattr(methods, n) for n in (*statuses, "UNKNOWN_METHOD"))
    assert python == _core.STATUSES
    assert tuple(m.id for m in methods.METHODS.values()) == _core.METHOD_IDS


def test_the_layouts_are_the_cores() -> None:
    assert (pose_row.POSITION, pose_row.QUATERNION, pose_row.ANGLES, pose_row.WIDTH) == (
        _core.POSE_ROW
    )
    figures = ("FORCE_ERROR", "ATTITUDE_ERROR", "FORCE_SCALE", "FAILURES", "UNCARRIED")
    assert tuple(getattr(estimate, n) for n in (*figures, "N_FIGURES")) == _core.FIGURE_SLOTS
    assert tuple(range(len(figures) + 1)) == _core.FIGURE_SLOTS
    assert (dynamics.INPUT_SIZE, kernel.AT_EVENT) == (13, -100)


def test_the_kinds_are_the_cores() -> None:
    assert tuple(_core.KIND_NAMES) == tuple(KINDS)
    assert (_core.N_PAR, _core.N_EVENTS) == (N_PAR, N_EVENTS)


@pytest.fixture(scope="module")
def pump():
    model = assemble(default_scene())
    u = np.zeros(dynamics.INPUT_SIZE)
    u[3] = 9.80665
    return model, initial_state(model, u[1:4]), u


def test_the_right_hand_sides_statuses_are_the_pythons(pump) -> None:
    """The core's rhs answers dynamics.OK on the chart and dynamics.OFF_CHART past its edge
    (|α| + |γ| ≥ π/2: the body tilted 90°)."""
    model, y, u = pump
    s, dydt = model.new_scratch(), np.zeros_like(y)
    assert dynamics.rhs(0.0, y, model.arrays, s, u, dydt) == dynamics.OK
    names = [d for d in DOF_NAMES if d in model.scene.dofs]  # y's order of the free DOFs
    tilted = y.copy()
    tilted[names.index("alpha")] = 0.8
    tilted[names.index("gamma")] = 0.8
    assert dynamics.rhs(0.0, tilted, model.arrays, s, u, dydt) == dynamics.OFF_CHART != dynamics.OK


def test_a_wrong_array_is_refused_naming_it(pump) -> None:
    """dtype, length, dimensions and contiguity are checked at the call, by name."""
    model, y, u = pump
    s, dydt = model.new_scratch(), np.zeros_like(y)
    assert dynamics.rhs(0.0, y, model.arrays, s, u, dydt) == dynamics.OK
    with pytest.raises(TypeError, match=r"^u: dtype int32"):
        dynamics.rhs(0.0, y, model.arrays, s, u.astype(np.int32), dydt)
    with pytest.raises(ValueError, match=r"^dydt: length 3 where"):
        dynamics.rhs(0.0, y, model.arrays, s, u, np.zeros(3))
    with pytest.raises(ValueError, match=r"^y: array is not C-contiguous"):
        dynamics.rhs(0.0, np.zeros(2 * y.size)[::2], model.arrays, s, u, dydt)
    with pytest.raises(ValueError, match=r"^ModelArrays\.lin_k_t: shape"):
        bad = model.arrays._replace(lin_k_t=model.arrays.lin_k_t[:1].copy())
        dynamics.rhs(0.0, y, bad, s, u, dydt)
    with pytest.raises(ValueError, match=r"rot: shape \(2, 3\)"):
        dynamics.rhs(0.0, y, model.arrays, s._replace(rot=np.zeros((2, 3))), u, dydt)
    with pytest.raises(ValueError, match=re.escape("y: length 3 is shorter than the model's")):
        dynamics.rhs(0.0, np.zeros(3), model.arrays, s, u, np.zeros(3))
    with pytest.raises(ValueError, match=r"^y: array is read-only"):
        frozen = y.copy()
        frozen.flags.writeable = False
        dynamics.rhs(0.0, frozen, model.arrays, s, u, dydt)


def test_the_core_was_built_from_the_sources_beside_it() -> None:
    """The extension carries the fingerprint of src/core it was built from; `_core` imported."""
    assert core_sources.fingerprint() == _core.SOURCE_SHA256


def test_a_core_older_than_its_sources_is_refused_at_import(tmp_path: Path) -> None:
    """An edit to any core source after the build makes the import fail and say how to
    rebuild, instead of running the old core."""
    copy = tmp_path / "core"
    shutil.copytree(core_sources.SOURCE_DIR, copy)
    built = core_sources.fingerprint(copy)
    core_sources.check_fresh(built, copy)
    header = copy / "physics" / "dynamics.hpp"
    header.write_text(header.read_text().replace("1.0e-6", "1.0e-7"))
    with pytest.raises(ImportError, match=r"built from other sources.*pip install -e \."):
        core_sources.check_fresh(built, copy)
    core_sources.check_fresh("anything", tmp_path / "no_sources_here")  # an installed copy


def test_kinds_the_core_does_not_know_are_refused_by_name() -> None:
    """A kind added to KINDS without its port (or ported in another order) fails the check
    the package runs at import, naming both lists and what to do."""
    from mount_twin.kinds import KindContractError, check_core

    check_core(KINDS)
    crossed = dict(reversed(KINDS.items()))
    with pytest.raises(KindContractError, match=r"port the kind to src/core/kinds/"):
        check_core(crossed)


@pytest.mark.parametrize("name", list(methods.METHODS))
def test_each_methods_tables_are_the_cores(name: str) -> None:
    """The coefficient tables and constants the core steps with are its Python module's (the
    ones the order-condition tests check), value for value; and its work rows per state count."""
    module = importlib.import_module(methods.METHODS[name].module)
    core = _core.method_tables()[name]
    assert {"ORDER", "MAX_FACTOR"} <= set(core)
    for key, value in core.items():
        mine = np.asarray(getattr(module, key))
        np.testing.assert_array_equal(np.asarray(value), mine, err_msg=f"{name}.{key}")
    spec = methods.METHODS[name]
    for n in (1, 6, 24):
        assert _core.work_rows(spec.id, n) == spec.work_rows(n)
    assert _core.work_rows(max(_core.METHOD_IDS) + 1, 6) == -1


def test_the_loop_refuses_work_arrays_too_small_for_the_method(pump) -> None:
    """The loop checks the stepper's work rows against its method when it is bound, before
    any run: a dopri54-sized array handed to ros34pw2 is refused by name, not overrun."""
    from mount_twin.engine.kernel import Integrator, Loop, RunOptions, new_watch
    from mount_twin.integrate.stepper import new_stepper

    model, y, u = pump
    small = new_stepper("dopri54", model.n_state, 1e-6, 1e-9, 100)
    rows = methods.METHODS["ros34pw2"].work_rows(model.n_state)
    integ = Integrator(methods.ROS34PW2, small.settings, small.work2d, small.work1d, small.result)
    watch = new_watch(0, N_EVENTS, model.n_state)
    opts = RunOptions(False, 1, False)
    args = (model.arrays, model.new_scratch(), u.copy(), y.copy(), opts, watch)
    with pytest.raises(
        ValueError, match=rf"Integrator\.work2d: 7 rows where method 1 needs {rows}"
    ):
        Loop(integ, *args, None)


def test_the_loop_refuses_a_companion_switching_to_a_method_its_stage_does_not_serve() -> None:
    """Where a joint's faces switch the companion steps by its switching method in its own
    arrays, its chained first stage carried over (kernel.hpp `companion_advance`): only the
    explicit first-same-as-last pairs share that stage, so a linearising method beside Verner's
    pair is refused by name when the loop is bound, not stepped from a stage it does not mean."""
    from mount_twin.engine.companion import new_companion
    from mount_twin.engine.kernel import Loop, RunOptions, new_watch
    from mount_twin.integrate.stepper import new_stepper
    from mount_twin.scene.loader import load_scene_file

    model = assemble(load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml"))
    n, k = model.n_state, len(model.nonlinear_slots)
    u = np.zeros(dynamics.INPUT_SIZE)
    u[3] = 9.80665
    twin = new_stepper("dopri54", n, 1e-6, 1e-9, 100)
    comp = new_companion(
        "auto",
        n,
        1e-6,
        1e-9,
        100,
        model.new_scratch(),
        model.n_mounts,
        np.zeros((k, N_EVENTS)),
        1.0,
        linear_stiffness=model.linear_stiffness,
        kinked=model.kinked,
    )
    args = (model.arrays, model.new_scratch(), u, initial_state(model, u[1:4]))
    integ = kernel.Integrator(twin.method, twin.settings, twin.work2d, twin.work1d, twin.result)
    rest = (RunOptions(False, 1, False), new_watch(k, N_EVENTS, n))
    Loop(integ, *args, *rest, comp)  # Verner's pair, Dormand–Prince's where the faces switch
    with pytest.raises(ValueError, match=r"Companion\.switching_method 1 at 2\.0+ steps beside"):
        Loop(integ, *args, *rest, comp._replace(switching_method=methods.ROS34PW2))
