"""The live error estimate is an error: within a small factor of the true error of the published
mount forces and attitude (against a reference run at rtol 1e-12 on the input refined 8×,
itself tied to scipy in test_accuracy.py), on smooth, stiff and non-smooth scenes (where
sampling the intervals over-counts, measuring them all comes within 1.1×); it never touches
the published numbers; it is on /diagnostics and WARNs when the forces are off by more than a
percent."""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
import yaml
from io_helpers import CONFIG, DATA_DIR, ROOT, default_scene, split
from kinds_helpers import kind_mount
from loop_helpers import companion_of
from physics_helpers import base_scene, mount

from mount_twin import _core
from mount_twin.analysis.accuracy import (
    RESOLVED,
    measure,
    raw_gyro,
    reference_run,
    resolution,
    run_at,
)
from mount_twin.analysis.synthesis import imu_record, synthesize
from mount_twin.engine import companion
from mount_twin.engine import driver as driver_module
from mount_twin.engine.batch import WARN, SampleBatch
from mount_twin.engine.companion import new_companion
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.estimator import (
    BORROWED,
    CHECK_RTOL_FLOOR,
    CHECKS,
    EXPONENTIALS,
    FASTEST_RATE,
    FLOOR_DIVISOR,
    JACOBIAN_KEEP,
    LINEARISATIONS,
    LINEARISE_EVERY,
    N_CARRIED,
    OUTPUT_STRIDE_MAX,
    OUTPUT_TURN,
    PROPAGATOR_STEP,
    TOLERANCE_DIVISOR,
    Estimator,
    check_divisor,
    new_estimator,
)
from mount_twin.engine.health_texts import INTEGRATION
from mount_twin.integrate.methods import (
    DOPRI54,
    EXPRB32,
    METHODS,
    ROS34PW2,
    VERNER65,
    choose,
)
from mount_twin.integrate.settings import HOLD_AFTER_REJECT, MAX_SUBSTEPS, MIN_STEPS
from mount_twin.integrate.stepper import new_stepper
from mount_twin.io.input_samples import read_samples
from mount_twin.model.assemble import Model, assemble
from mount_twin.replay import replay
from mount_twin.scene import statics as statics_module
from mount_twin.scene.checks import check_scene
from mount_twin.scene.description import Scene
from mount_twin.scene.loader import load_scene_file, scene_from_dict
from mount_twin.sweeps import runner as sweep_runner

G = 9.80665
CORNERS = [(0.4, 0.3), (-0.4, 0.3), (-0.4, -0.3), (0.4, -0.3)]
FACTOR = 2.0
"""The estimate is asserted within this factor of the true error, where no case says otherwise."""


def _ship_motion(scene: Scene, seconds: float) -> tuple[Scene, SampleBatch]:
    samples = read_samples(ROOT / "bags" / "ship_motion_1khz", scene.input)
    return raw_gyro(scene), samples.part(slice(int(seconds * 1000) + 1))


def _with_pump_input(data: dict) -> Scene:
    pump = default_scene().input
    data["input"] = {"topic": pump.topic, "frame_id": pump.frame_id, "msg_type": pump.msg_type}
    return scene_from_dict(data, "<error estimate test>")


def _bouc_wen_grid(n: int, beta: float = 120.0, gamma: float = 80.0) -> tuple[Scene, SampleBatch]:
    """n Bouc–Wen elastomers (hysteresis β, γ) on a grid over 0.8 × 0.6 m, each 1/n of four's
    stiffness and damping, under 200 kg; 2 s of the pump's ship motion."""
    side = math.ceil(math.sqrt(n))
    mounts = [
        kind_mount(
            "elastomer",
            f"r{i}",
            (0.8 * (i % side) / (side - 1) - 0.4, 0.6 * (i // side) / (side - 1) - 0.3, 0.0),
            stiffness_linear=[4e5 / n, 4e5 / n, 8e5 / n],
            damping=[1200.0 / n, 1200.0 / n, 2000.0 / n],
            hysteresis={"ratio": 0.6, "beta": beta, "gamma": gamma},
        )
        for i in range(n)
    ]
    body = base_scene(200.0, [0.0, 0.0, 0.3], [20.0, 30.0, 40.0, 0.0, 0.0, 0.0], mounts)
    return _ship_motion(_with_pump_input(body), 2.0)


def _stiff_scene(method: str, *beside: dict) -> dict:
    """10 kg on 4 × 1e9 N/m at (±0.4, ±0.3) m (modes of 2–6 kHz), the mounts `beside` with
    them, integrated by `method`: the scene's dictionary."""
    mounts = [
        mount(f"m{i}", (x, y, 0.0), (1e9,) * 3 + (0,) * 3, (2e3,) * 3 + (0,) * 3)
        for i, (x, y) in enumerate(CORNERS)
    ]
    data = base_scene(10.0, [0.0, 0.0, 0.1], [1.0] * 3 + [0.0] * 3, [*mounts, *beside])
    data["integration"]["method"] = method
    return data


def _stiff_light(method: str = "dopri54") -> tuple[Scene, SampleBatch]:
    """10 kg on 4 × 1e9 N/m (modes of 2–6 kHz) under 1 kHz ship motion: Dormand–Prince runs
    at its stability limit, where a loose tolerance gives percent errors (`auto` would take
    the Rosenbrock here)."""
    return _ship_motion(_with_pump_input(_stiff_scene(method)), 1.0)


def _on_hysteretic_rubber(
    body: tuple[float, list[float], list[float]],
    stiffness_damping: tuple[list[float], list[float]],
    snubber: dict,
) -> Scene:
    """A body (mass kg, CG m, principal inertia kg·m²) on four Bouc–Wen elastomers at the
    corners (linear stiffness N/m and damping N·s/m per axis) with snubbers, pump input."""
    mounts = [
        kind_mount(
            "elastomer",
            f"r{i}",
            (x, y, 0.0),
            stiffness_linear=stiffness_damping[0],
            damping=stiffness_damping[1],
            hysteresis={"ratio": 0.6, "beta": 120.0, "gamma": 80.0},
            snubber=snubber,
        )
        for i, (x, y) in enumerate(CORNERS)
    ]
    mass, cg, inertia = body
    return _with_pump_input(base_scene(mass, cg, [*inertia, 0, 0, 0], mounts))


def _record(scene: Scene, t: np.ndarray, accel: np.ndarray) -> tuple[Scene, SampleBatch]:
    """The scene with its gyro raw, and a deck record of `accel` (m/s², F) at stamps t."""
    frames = [scene.input.frame_id] * t.shape[0]
    return raw_gyro(scene), SampleBatch(t, accel, np.zeros_like(accel), frames)


def _half_sine_record(scene: Scene) -> tuple[Scene, SampleBatch]:
    """`_record` of a 30 g, 5 ms vertical half-sine (30 % of it fore-aft) at 10 kHz, 0.2 s."""
    t = 1.0 + np.arange(2001) / 10_000.0
    pulse = np.where((t > 1.02) & (t < 1.025), 30 * G * np.sin(math.pi * (t - 1.02) / 0.005), 0.0)
    return _record(scene, t, np.column_stack([0.3 * pulse, np.zeros_like(t), G + pulse]))


def _rubber_on_snubbers() -> tuple[Scene, SampleBatch]:
    """200 kg on four hysteretic elastomers that hit their snubbers (3 mm gap, Hertzian
    contact) under a 30 g, 5 ms half-sine at 10 kHz: non-smooth in the state (|ẋ| of
    Bouc–Wen, contact onset)."""
    scene = _on_hysteretic_rubber(
        (200.0, [0.0, 0.0, 0.3], [20.0, 30.0, 40.0]),
        ([1e5, 1e5, 2e5], [300.0, 300.0, 500.0]),
        {"gap": 3e-3, "stiffness": 1e9, "exponent": 1.5, "axes": ["z"]},
    )
    return _half_sine_record(scene)


def _rubber_on_stiff_snubbers_1khz(stiffness: float) -> tuple[Scene, SampleBatch]:
    """`_rubber_on_snubbers` with snubbers of `stiffness` (N/m^1.5), the half-sine at 1 kHz:
    the contacts far stiffer than the open tangents the carried kick is held to
    (`Model.tangent_rate`), each over within a few samples."""
    scene = _on_hysteretic_rubber(
        (200.0, [0.0, 0.0, 0.3], [20.0, 30.0, 40.0]),
        ([1e5, 1e5, 2e5], [300.0, 300.0, 500.0]),
        {"gap": 3e-3, "stiffness": stiffness, "exponent": 1.5, "axes": ["z"]},
    )
    scene, samples = _half_sine_record(scene)
    return scene, samples.part(slice(None, None, 10))


def _hysteresis_snubbers_real_shock() -> tuple[Scene, SampleBatch]:
    """80 kg on four hysteretic elastomers with snubbers on every axis (2 mm gap, Hertzian),
    under a real shock: the water-entry record's 0.25 s around its 47 g impact (20 kHz,
    `test/data/water_entry_shock_20khz_excerpt.md`), its impact axis vertical, its first 2 ms
    (the sensor's bias in free fall) taken out. Every mount's snubber closes."""
    rec = np.loadtxt(DATA_DIR / "water_entry_shock_20khz_excerpt.csv", delimiter=",", skiprows=1)
    t, shock = rec[:, 0], rec[:, 1:4] - rec[:40, 1:4].mean(axis=0)
    accel = np.column_stack([shock[:, 1], shock[:, 2], G + shock[:, 0]])
    scene = _on_hysteretic_rubber(
        (80.0, [0.0, 0.0, 0.25], [8.0, 10.0, 12.0]),
        ([2e5, 2e5, 4e5], [400.0, 400.0, 800.0]),
        {"gap": 2e-3, "stiffness": 2e8, "exponent": 1.5, "axes": ["x", "y", "z"]},
    )
    return _record(scene, t, accel)


def _pump(every: int = 1) -> tuple[Scene, SampleBatch]:
    """The pump under 2 s of ship motion, the bag's every `every`th sample (1 kHz / every)."""
    scene, samples = _ship_motion(default_scene(), 2.0)
    return scene, samples.part(slice(None, None, every))


def _pump_half_sine() -> tuple[Scene, SampleBatch]:
    """The pump under a 30 g, 5 ms half-sine (30 % of it fore-aft) at 10 kHz, 0.2 s: an error
    of 1e-13 of the force, near round-off. Its checks' two steps ended a rounding of the time
    grid away from the twin's one (up to half an ulp of t): the state's rate times that, 1e-16
    s an interval, read as local error made the estimate 28× the true error (34× checked at
    every interval, 155× with four steps a check) until steps were taken as the grid holds
    them (`control.hpp` on_grid)."""
    return _half_sine_record(default_scene())


def _genset_synthesised_shock(seed: int) -> tuple[Scene, SampleBatch]:
    """The bundled genset under a vertical shock synthesised to a design rising to 60 g at
    300 Hz (10 Hz 2 g, 100 Hz 20 g, 300 and 1000 Hz 60 g; `mount-twin synthesize`'s defaults:
    20 kHz, ζ 0.05, 50 ms of rest first): its bolts flow and its joints open and slip."""
    scene = load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml")
    rate = 20_000.0
    shock = synthesize([10.0, 100.0, 300.0, 1000.0], [2.0, 20.0, 60.0, 60.0], rate, seed=seed)
    record = imu_record(shock, rate, "z", 0.05)
    return _record(scene, 1.0 + record.t, record.accel)


def _on_verner65(build: Callable[[], tuple[Scene, SampleBatch]]) -> tuple[Scene, SampleBatch]:
    """A case with its twin on `verner65`, the scene method its companion runs for
    Dormand–Prince (the companion of a Verner twin: Verner at two steps an interval)."""
    scene, samples = build()
    integration = dataclasses.replace(scene.integration, method="verner65")
    return dataclasses.replace(scene, integration=integration), samples


def _stiff_beside(
    soft: dict, method: str = "auto", seconds: float = 0.1
) -> tuple[Scene, SampleBatch]:
    """The stiff scene (`_stiff_light`) with a fifth, soft elastomer mount at the CG's foot
    (1e4 N/m: ρ·Δt stays the yaw mode's), its other keys `soft`, integrated by `method` under
    `seconds` of the ship motion."""
    fifth = kind_mount(
        "elastomer",
        "soft",
        (0.0, 0.0, 0.0),
        stiffness_linear=[1e4, 1e4, 1e4],
        damping=[10.0, 10.0, 10.0],
        **soft,
    )
    return _ship_motion(_with_pump_input(_stiff_scene(method, fifth)), seconds)


def _stiff_with_a_snubbed_mount() -> tuple[Scene, SampleBatch]:
    """The stiff scene with a soft elastomer on a snubber beside it: as stiff, its laws with
    pieces (the snubber's contact, though it never touches)."""
    return _stiff_beside(
        {"snubber": {"gap": 3e-3, "stiffness": 1e8, "exponent": 1.5, "axes": ["z"]}}
    )


def _stiff_hysteretic_mounts() -> tuple[Scene, SampleBatch]:
    """10 kg on four 1e9 N/m Bouc–Wen elastomers of strong hysteresis (β·x of order 1 at their
    µm deflections) at the stiff scene's corners, under 0.3 s of the ship motion: stiff, and its
    stiffness non-linear."""
    hysteresis = {"ratio": 0.6, "beta": 1e6, "gamma": 5e5}
    mounts = [
        kind_mount(
            "elastomer",
            f"r{i}",
            (x, y, 0.0),
            stiffness_linear=[1e9] * 3,
            damping=[2e3] * 3,
            hysteresis=hysteresis,
        )
        for i, (x, y) in enumerate(CORNERS)
    ]
    data = base_scene(10.0, [0.0, 0.0, 0.1], [1.0] * 3 + [0.0] * 3, mounts)
    data["integration"]["method"] = "auto"
    return _ship_motion(_with_pump_input(data), 0.3)


def _stiff_with_a_hysteretic_mount(method: str = "auto") -> tuple[Scene, SampleBatch]:
    """The stiff scene with a soft Bouc–Wen elastomer beside it: as stiff, non-linear, and no
    law with pieces."""
    hysteresis = {"ratio": 0.6, "beta": 120.0, "gamma": 80.0}
    return _stiff_beside({"hysteresis": hysteresis}, method, 0.3)


def _genset(bag: str = "genset_shock_10khz") -> tuple[Scene, SampleBatch]:
    """The bundled genset under a bundled 10 kHz bag (its shock, by default), as shipped."""
    scene = load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml")
    return scene, read_samples(ROOT / "bags" / bag, scene.input)


CASES = {
    "stiff_light": (_stiff_light, [1e-3, 1e-6, 1e-7]),
    "stiff_light_rosenbrock": (partial(_stiff_light, "ros34pw2"), [1e-3, 1e-6, 1e-9]),
    "stiff_light_exponential": (partial(_stiff_light, "exprb32"), [1e-3]),
    "stiff_hysteretic_rosenbrock": (
        partial(_stiff_with_a_hysteretic_mount, "ros34pw2"),
        [1e-3, 1e-6, 1e-9],
    ),
    "stiff_snubbed": (_stiff_with_a_snubbed_mount, [1e-3, 1e-4, 1e-6, 1e-9]),
    "stiff_bouc_wen": (_stiff_hysteretic_mounts, [1e-3, 1e-4, 1e-6, 1e-9]),
    "rubber_on_snubbers": (_rubber_on_snubbers, [1e-3, 1e-6]),
    "rubber_on_snubbers_verner65": (partial(_on_verner65, _rubber_on_snubbers), [1e-3, 1e-6]),
    "hysteresis_snubbers_real_shock": (_hysteresis_snubbers_real_shock, [1e-3, 1e-6]),
    "genset": (_genset, [1e-3, 1e-6, 1e-9]),
    "genset_half_sine": (partial(_genset, "half_sine_shock_10khz"), [1e-6]),
    "genset_synthesised_30g": (partial(_genset_synthesised_shock, 0), [1e-3, 1e-5]),
    "pump_ship_motion": (_pump, [1e-4, 1e-9]),
    "bouc_wen_4_ship_motion": (partial(_bouc_wen_grid, 4), [1e-9]),
    "bouc_wen_16_ship_motion": (partial(_bouc_wen_grid, 16), [3e-9]),
    "pump_250hz": (partial(_pump, 4), [1e-6]),
    "pump_100hz": (partial(_pump, 10), [1e-3]),
    "pump_half_sine_10khz": (_pump_half_sine, [1e-6]),
}
"""Each case's rtols are asserted within FACTOR, but UNRESOLVED's. Dormand–Prince's at 1e-7 (17
steps an interval, its modes unresolved at 1 kHz) read 2.84 under a fixed spacing for
tolerance-bound steps (reverted at a2ce250); the period's share leaves it alone. The
Rosenbrock's at 1e-3 read 0.27 while its checks were Rosenbrock steps too (they damp the stiff
modes as the twin does: 1.00 checked by the exponential method, `estimator.CHECKED_BY`). (Scenes
with non-linear mounts take the companion, `engine.companion`.) The genset under the synthesised
shock read 0.44 and 0.28 at rtol 1e-3 and 1e-5 while the companion crossed an event's switch
by one step, as the twin does (kernel.hpp `Stepping` HALVED). The Bouc–Wen grids at rtol 1e-9
and 3e-9 read 7.1 and 3.1 while the carried companion scaled, between its checks, the local
error measured at a rejection (kernel.hpp `add_local_error`). The stiff scene beside a snubbed
elastomer and on four stiff Bouc–Wen elastomers (`auto`: the Rosenbrock) read 0.28 and 0.29 at
rtol 1e-3, 0.18 and 0.08 at 1e-4, while the companion ran the Rosenbrock where the twin's steps
passed over the fastest mode (kernel.hpp `stepped_over`, Stepping EXACT)."""
UNRESOLVED = ("stiff_light_exponential",)
"""Cases whose error is below what the reference resolves (`analysis.accuracy.resolution`):
no truth to hold the estimate to (test below)."""
ATTITUDE_FLOOR_RAD = 1e-12
"""Attitude errors below this are the twin's own rounding (the stiff scenes' 1e-13 at every
rtol), not compared."""


@pytest.mark.parametrize(
    ("case", "rtol"),
    [(c, r) for c, (_, rtols) in CASES.items() if c not in UNRESOLVED for r in rtols],
)
def test_the_estimate_is_within_a_factor_two_of_the_true_error(case: str, rtol: float) -> None:
    """Where the reference resolves the error (`resolution`: a reference on another step grid
    differs from it by RESOLVED times less than the error)."""
    build, _ = CASES[case]
    scene, samples = build()
    ref = reference_run(scene, samples, 1_000_000)
    res = resolution(scene, samples, 1_000_000, ref)
    acc = measure(scene, samples, rtol, 100_000, ref)
    assert acc.failures == 0
    assert acc.force_error > RESOLVED * res.force_error, ("not resolved", acc, res)
    assert 1 / FACTOR < acc.est_force_error / acc.force_error < FACTOR, acc
    if acc.attitude_error_rad > max(ATTITUDE_FLOOR_RAD, RESOLVED * res.attitude_error_rad):
        assert 1 / FACTOR < acc.est_attitude_error_rad / acc.attitude_error_rad < FACTOR, acc


def _companions_made(mp: pytest.MonkeyPatch) -> list[companion.Companion]:
    """The companions the engine's driver makes from now on (its `new_companion` patched by
    `mp`), in the order it makes them."""
    made: list[companion.Companion] = []

    def keep(*args, **kwargs) -> companion.Companion:
        made.append(new_companion(*args, **kwargs))
        return made[-1]

    mp.setattr(driver_module, "new_companion", keep)
    return made


def test_a_bouc_wen_scenes_checks_take_two_half_steps_and_read_its_error_within_a_third() -> None:
    """Across a Bouc–Wen rate's kink (|ẋ| turning), one Verner step as long as the twin's is no
    small share of the twin's error, and the local error a check measures falls short: 16
    elastomers with the |ẋ| term alone (β = 200, γ = 0) under ship motion read 0.54 of their
    true attitude error at rtol 1e-6 with it, 1.14 checked by two Dormand–Prince half steps
    (`companion.KINKED_CHECK`; the companion integrated at every interval: 1.00). The genset,
    whose laws' switches are all events, keeps Verner's one step."""
    scene, samples = _bouc_wen_grid(16, beta=200.0, gamma=0.0)
    with pytest.MonkeyPatch.context() as mp:
        made = _companions_made(mp)
        for s, data in ((scene, samples), _genset()):
            TwinEngine(assemble(s)).run(data.part(slice(0, 3)))
    checks = [(c.check_method, c.check_steps) for c in made]
    assert checks == [companion.KINKED_CHECK, (VERNER65, 1)]
    ref = reference_run(scene, samples, 1_000_000)
    acc = measure(scene, samples, 1e-6, 100_000, ref)
    assert 0.75 < acc.est_force_error / acc.force_error < 1.33, acc
    assert 0.75 < acc.est_attitude_error_rad / acc.attitude_error_rad < 1.33, acc


def test_the_exponential_twins_stiff_error_is_below_what_a_reference_resolves() -> None:
    """10 kg on 4 × 1e9 N/m integrated by exprb32, exact on the linear part: its error against
    the reference, 4.2e-9 of the largest force at every rtol and at 1 kHz and 100 Hz alike, is
    what a second reference on another step grid differs by (one by ros34pw2 as well, measured:
    round-off of the position times 1e9 N/m). The true error is not known below that; the
    estimate claims no more than FACTOR times it (it read 6.8 times it while a check's local
    error counted undamped for the ~19 intervals since the last: `add_local_error`)."""
    scene, samples = CASES["stiff_light_exponential"][0]()
    ref = reference_run(scene, samples, 1_000_000)
    res = resolution(scene, samples, 1_000_000, ref)
    acc = measure(scene, samples, 1e-3, 100_000, ref)
    assert 1e-9 < res.force_error < 1e-8
    assert acc.force_error <= RESOLVED * res.force_error
    assert acc.est_force_error < FACTOR * res.force_error, (acc, res)


@pytest.mark.parametrize("case", ["pump_250hz"])
def test_measuring_every_interval_comes_within_ten_percent(case: str) -> None:
    """The carried error is right where a check stands for a few intervals of a period (the
    pump at 250 Hz: 0.95 measured every interval, 1.08 as configured): what the sampling adds
    is the weighting of the intervals a check stands for, not the linearised propagation or the
    local errors it carries."""
    scene, samples = CASES[case][0]()
    rtol = min(CASES[case][1])
    ref = reference_run(scene, samples, 1_000_000)
    every = partial(new_estimator, check_every=1)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(driver_module, "new_estimator", every)
        acc = measure(scene, samples, rtol, 100_000, ref)
    assert 0.9 < acc.est_force_error / acc.force_error < 1.1, acc


def _run_keeping_estimator(
    model: Model, samples: SampleBatch, **settings: float
) -> tuple[TwinEngine, Estimator]:
    """The engine after its run of `samples` on `model`, and its estimator's arrays
    (`new_estimator`'s keyword `settings` changed)."""
    made: list[Estimator] = []

    def keep(*args, **kwargs) -> Estimator:
        made.append(new_estimator(*args, **kwargs, **settings))
        return made[-1]

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(driver_module, "new_estimator", keep)
        engine = TwinEngine(model)
        engine.run(samples)
    return engine, made[0]


def _estimator_after(case: str, **settings: float) -> Estimator:
    """The estimator's arrays after the case's run as configured (`new_estimator`'s keyword
    `settings` changed)."""
    scene, samples = CASES[case][0]()
    return _run_keeping_estimator(assemble(scene), samples, **settings)[1]


def _checks_of(case: str) -> tuple[float, float]:
    """(checks, checks that took the twin's linearisation) of the case's run as configured."""
    est = _estimator_after(case)
    return float(est.state[CHECKS]), float(est.state[BORROWED])


def test_the_exponential_twins_checks_take_its_jacobian_and_half_step_phi_functions() -> None:
    """Where the twin is exponential, a regular check waits for an interval whose Jacobian the
    twin took at its start, and takes it with the half step's φ functions instead of making its
    own (their squarings were most of a check's cost); the estimate stays within FACTOR there
    (test above). Another twin's checks take nothing."""
    checks, borrowed = _checks_of("stiff_light_exponential")
    assert checks > 30 and borrowed >= 0.9 * checks, (checks, borrowed)
    checks, borrowed = _checks_of("stiff_light")
    assert checks > 30 and borrowed == 0.0, (checks, borrowed)


def test_the_check_is_tighter_than_the_twin_but_not_below_the_round_off_floor() -> None:
    """32× tighter at the shipped tolerances; at tight ones the check stops at the floor
    (the exponential method hunted at 3e-11: 85 steps an interval), yet stays 4× tighter."""
    for rtol in (1e-3, 1e-6, 1e-8):
        assert check_divisor(rtol) == TOLERANCE_DIVISOR
    for rtol in (3e-9, 1e-9, 1e-10, 1e-12):
        check = rtol / check_divisor(rtol)
        assert check >= min(CHECK_RTOL_FLOOR, rtol / FLOOR_DIVISOR) * (1 - 1e-12)
        assert check <= rtol / FLOOR_DIVISOR * (1 + 1e-12)


def test_the_propagator_is_the_matrix_exponential() -> None:
    """Against scipy's Padé exponential, on a stiff, lightly damped oscillator and a random
    matrix of norm 30 (eight squarings)."""
    rng = np.random.default_rng(7)
    k, c = 4e9 / 10.0, 2e3 / 10.0
    oscillator = np.array([[0.0, 1.0], [-k, -c]])
    for a, scale in ((oscillator, 1e-3), (rng.normal(size=(12, 12)), 30.0 / 12)):
        want = scipy.linalg.expm(scale * a)
        got = _core.expm(a, scale)
        np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-9 * abs(want).max())


@pytest.mark.parametrize("case", ["stiff_light_exponential", "pump_ship_motion"])
def test_the_decay_an_interval_is_how_much_of_each_mode_the_propagator_keeps(case: str) -> None:
    """`decay` is exp(h/2·J_vv) of the Jacobian held (scipy's exponential), and its eigenvalues
    are the moduli of the propagator's: what an interval leaves of each mode's error (0.37–0.76
    for the 2.6–5 kHz modes of the stiff scene at 1 kHz, 0.99 for the pump's), which a check
    standing for many intervals sums instead of counting each at full size."""
    est = _estimator_after(case)
    h = float(est.state[PROPAGATOR_STEP])
    nc, nf = int(est.state[N_CARRIED]), est.n_body // 2
    jac = est.jac[: nc * nc].reshape(nc, nc)
    decay = est.decay.reshape(nf, nf)
    want = scipy.linalg.expm(0.5 * h * jac[nf : 2 * nf, nf : 2 * nf])
    np.testing.assert_allclose(decay, want, rtol=1e-6, atol=1e-9)
    kept = np.sort(np.abs(np.linalg.eigvals(scipy.linalg.expm(h * jac[: 2 * nf, : 2 * nf]))))
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(decay).real), kept[::2], rtol=0.02)


def test_a_linearisation_keeps_the_propagator_while_the_jacobian_moves_less_than_1e_3() -> None:
    """On the pump under ship motion the Jacobian moves 1.6e-5–1.0e-4 between linearisations:
    within JACOBIAN_KEEP (1e-3) the propagator is computed once, and the span to the next
    linearisation doubles each time, to LINEARISE_MAX check periods; with 1e-6 the propagator
    is computed at every one, and the span stays LINEARISE_EVERY, as it does where it may not
    grow. The estimate is the same within 1 %, and the propagator held is exp(h·J) of the
    Jacobian held (scipy's exponential)."""
    kept, fresh, fixed = (
        _estimator_after("pump_ship_motion", **settings)
        for settings in (
            {"jacobian_keep": JACOBIAN_KEEP},
            {"jacobian_keep": 1e-6},
            {"linearise_max": LINEARISE_EVERY},
        )
    )
    assert fresh.state[LINEARISATIONS] == fixed.state[LINEARISATIONS] > 20
    assert kept.state[LINEARISATIONS] <= fixed.state[LINEARISATIONS] / 3
    assert kept.state[EXPONENTIALS] <= 2
    assert fresh.state[EXPONENTIALS] >= fresh.state[LINEARISATIONS]
    np.testing.assert_allclose(kept.e, fresh.e, rtol=1e-2, atol=1e-2 * abs(fresh.e).max())
    h, nc = float(kept.state[PROPAGATOR_STEP]), int(kept.state[N_CARRIED])
    jac, prop = kept.jac[: nc * nc].reshape(nc, nc), kept.prop[: nc * nc].reshape(nc, nc)
    np.testing.assert_allclose(prop.T, scipy.linalg.expm(h * jac), rtol=1e-6, atol=1e-9)


def test_the_outputs_errors_folded_each_half_radian_of_the_fastest_mode_keep_their_peaks() -> None:
    """On the pump at 1 kHz the fastest mode, bounded at 157 rad/s from the Jacobian held, turns
    OUTPUT_TURN (0.5 rad) in 3 intervals: the outputs' errors are folded every third interval
    (and at every interval measured), and read at least cos(0.25) of what folding every
    interval reads, never more (the same error, sampled)."""
    est = _estimator_after("pump_ship_motion")
    h, rate = float(est.state[PROPAGATOR_STEP]), float(est.state[FASTEST_RATE])
    assert 2 <= math.floor(OUTPUT_TURN / (h * rate)) <= OUTPUT_STRIDE_MAX
    scene, samples = CASES["pump_ship_motion"][0]()
    strided = run_at(scene, samples, 1e-6, 100_000).estimate
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(driver_module, "new_estimator", partial(new_estimator, output_turn=0.0))
        every = run_at(scene, samples, 1e-6, 100_000).estimate
    assert strided is not None and every is not None
    for name in ("force_error_n", "attitude_error_rad"):
        ratio = getattr(strided, name) / getattr(every, name)
        assert math.cos(0.5 * OUTPUT_TURN) <= ratio <= 1.0, (name, ratio)
    assert strided.force_error_n != every.force_error_n


def test_a_runs_last_intervals_are_folded_as_it_ends() -> None:
    """The outputs' errors are folded every OUTPUT_TURN of the fastest mode's turn; as a run
    ends, those of the intervals since the last folding are folded too (estimator.hpp
    `close_run`): the run's figures are at least what its last state's error gives,
    ∂(forces, angles)/∂y · e over the carried states, here taken by numpy from the estimator's
    arrays. The pump's runs of its first 15 to 26 samples of ship motion end at every phase of
    the stride (3 intervals); in some the last state's error is the run's largest."""
    scene, samples = _pump()
    model = assemble(scene)
    largest_at_the_end = 0
    for n in range(15, 27):
        engine, est = _run_keeping_estimator(model, samples.part(slice(0, n)))
        nc, n_out = int(est.state[N_CARRIED]), est.out1.shape[0]
        sens = est.sens[: nc * n_out].reshape(nc, n_out)
        last = np.abs(sens.T @ est.e[est.carried[:nc].astype(int)])
        estimate = engine.error_estimate
        assert estimate is not None
        for figure, error in (
            (estimate.force_error_n, last[:-3].max()),
            (estimate.attitude_error_rad, last[-3:].max()),
        ):
            assert figure >= error * (1.0 - 1e-12), (n, figure, error)
            largest_at_the_end += figure <= error * (1.0 + 1e-12)
    assert largest_at_the_end >= 2


def test_the_core_refuses_a_span_cap_below_the_first_span() -> None:
    """LINEARISE_MAX below LINEARISE_EVERY would shrink the span where the propagator holds:
    the core refuses it by name before any interval."""
    with pytest.raises(ValueError, match="LINEARISE_MAX >= LINEARISE_EVERY"):
        _estimator_after("pump_ship_motion", linearise_max=LINEARISE_EVERY - 1)


@pytest.mark.parametrize("case", ["rubber_on_snubbers", "pump_ship_motion"])
def test_the_estimate_never_changes_what_is_published(case: str) -> None:
    """Bit for bit: the estimate has its own state, scratch and checking stepper."""
    scene, samples = CASES[case][0]()
    on, off = (run_at(scene, samples, 1e-5, 100_000, estimate=e) for e in (True, False))
    assert on.estimate is not None and off.estimate is None
    for field in ("wrenches", "position", "angles", "quaternion"):
        np.testing.assert_array_equal(getattr(on.out, field), getattr(off.out, field))


def _integration_status(scene: Scene, samples: SampleBatch):
    """The engine after the run, and its worst integration status of the run."""
    engine = TwinEngine(assemble(scene))
    reports = engine.run(samples).health
    statuses = [s for r in reports for s in r.statuses if s.name == "mount_twin: integration"]
    return engine, max(statuses, key=lambda s: s.level)


def test_a_loose_tolerance_on_a_stiff_scene_warns_with_the_estimate() -> None:
    scene, samples = _stiff_light()
    loose = dataclasses.replace(scene.integration, rtol=1e-3, atol=1e-6)
    engine, status = _integration_status(dataclasses.replace(scene, integration=loose), samples)
    estimate = engine.error_estimate
    assert estimate is not None and estimate.force_error_rel > 0.01
    assert status.level == WARN
    assert "estimated mount-force error" in status.message and "rtol" in status.message
    assert float(status.values["est_force_error_rel"]) > 0.01
    assert float(status.values["est_force_error_n"]) > 0.0


def test_the_bundled_scene_reports_a_tiny_estimate_and_it_can_be_turned_off() -> None:
    scene, samples = _pump()
    engine, status = _integration_status(scene, samples)
    assert status.level == 0
    assert 0.0 < float(status.values["est_force_error_rel"]) < 1e-6
    assert status.values["est_failed_checks"] == "0"
    assert status.values["est_uncarried_states"] == "0"
    off = dataclasses.replace(scene.integration, error_estimate=False)
    engine, status = _integration_status(dataclasses.replace(scene, integration=off), samples)
    assert engine.error_estimate is None
    assert not any(k.startswith("est_") for k in status.values)


def test_the_genset_scene_file_loads_with_the_estimate_on_by_default() -> None:
    assert load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml").integration.error_estimate


def test_only_the_companion_holds_its_step_after_a_rejection() -> None:
    """The companion's stepper grows no step right after a rejection (HOLD_AFTER_REJECT: on
    the genset's sliding joints a step grown at once from one accepted with a tiny error is
    rejected again), a method switch included; the twin's stepper does not hold, so what it
    publishes is the plain controller's (bench/core_parity.py: bit for bit)."""
    model = assemble(load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml"))
    n = model.n_state
    comp = companion_of(model, "auto")
    assert comp.settings[HOLD_AFTER_REJECT] == 1.0
    assert companion.switch(comp, METHODS["exprb32"].id).settings[HOLD_AFTER_REJECT] == 1.0
    assert new_stepper("auto", n, 1e-6, 1e-9, 100).settings[HOLD_AFTER_REJECT] == 0.0


def test_the_companion_of_dormand_prince_is_one_step_of_verner_and_switches_with_the_twin() -> (
    None
):
    """Where the twin runs dopri54 the companion runs Verner's 6(5) pair at one step an interval
    at least (a different solution of a smaller error for 8 right-hand sides a step, where one
    step of the twin's own method would be the twin again), and dopri54 at two steps at least
    over an interval where a joint's faces switch (`switching_method`); where auto
    moves the twin to a linearising method the companion runs that method at two steps at
    least, and back; beside the Rosenbrock it has the exponential method for the intervals
    whose twin steps pass over the fastest mode (`exact_method`). Its work arrays, made for
    auto, hold every method; its step limit stays the twin's per step of its fewest."""
    model = assemble(load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml"))
    n = model.n_state
    own = companion_of(model, "dopri54")
    assert (own.method, own.settings[MIN_STEPS], own.settings[MAX_SUBSTEPS]) == (VERNER65, 1, 100)
    assert (own.switching_method, own.switching_min_steps) == (DOPRI54, 2)
    comp = companion_of(model, "auto")
    assert (comp.method, comp.settings[MIN_STEPS]) == (VERNER65, 1.0)
    for twin, method, fewest in ((ROS34PW2, ROS34PW2, 2), (DOPRI54, VERNER65, 1)):
        comp = companion.switch(comp, twin)
        assert (comp.method, comp.settings[MIN_STEPS]) == (method, fewest)
        assert (comp.switching_method, comp.switching_min_steps) == (twin, 2)
        assert comp.settings[MAX_SUBSTEPS] == 100 * fewest
    assert comp.work2d.shape[0] >= max(m.work_rows(n) for m in METHODS.values())
    ros = companion_of(model, "ros34pw2")
    assert (ros.method, ros.settings[MIN_STEPS]) == (ROS34PW2, 2.0)
    assert (ros.switching_method, ros.switching_min_steps) == (ROS34PW2, 2)
    # where the twin's steps pass over the fastest mode: the exponential method, in its arrays
    assert ros.exact_method == EXPRB32 and comp.exact_method == -1
    assert ros.work2d.shape[0] >= max(m.work_rows(n) for m in METHODS.values())
    assert companion.switch(comp, ROS34PW2).exact_method == EXPRB32


def test_the_companion_of_a_rosenbrock_twin_on_stiff_linear_mounts_is_exact_on_them() -> None:
    """Where the stiff modes are the linear mounts' (`Model.linear_stiffness`: no law with
    pieces, the non-linear mounts soft) the companion of a ros34pw2 twin is exprb32 at one step
    an interval (EXACT_ON_LINEAR), also where `auto` moves the twin there (it does not on such
    a scene: it takes exprb32 itself), and dopri54's is still Verner's pair; elsewhere,
    ros34pw2 at two steps (above)."""
    model = assemble(_stiff_with_a_hysteretic_mount()[0])
    assert model.linear_stiffness
    ros = companion_of(model, "ros34pw2")
    assert (ros.method, ros.settings[MIN_STEPS]) == (EXPRB32, 1.0)
    assert (ros.switching_method, ros.switching_min_steps) == (EXPRB32, 1)
    assert ros.exact_method == -1  # its own already
    comp = companion_of(model, "auto")
    assert comp.method == VERNER65
    comp = companion.switch(comp, ROS34PW2)
    assert (comp.method, comp.settings[MIN_STEPS], comp.switching_method) == (EXPRB32, 1, EXPRB32)


def test_the_stiff_modes_are_the_linear_mounts_where_no_law_has_pieces_and_the_rest_is_soft() -> (
    None
):
    """`Model.piecewise`: linear mounts, a Bouc–Wen elastomer and one on a force table (PCHIP,
    its slope continuous) have none; an elastomer's snubber (touching or not), a shear key, a
    bolted joint have. `Model.linear_stiffness` holds where none has and the non-linear mounts
    alone move the body at most NONLINEAR_SHARE of its fastest rate: the stiff scene beside a
    1e4 N/m elastomer (rate share √(1e4/(4·1e9)) in x, 1.6e-3), not four stiff Bouc–Wen
    elastomers alone (share 1); a scene of linear mounts (the pump) always."""
    table = {"z": {"deflection": [-1e-3, 0.0, 1e-3], "force": [-20.0, 0.0, 10.0]}}
    for build, piecewise, linear in (
        (_pump, False, True),
        (_stiff_with_a_hysteretic_mount, False, True),
        (partial(_stiff_beside, {"force_table": table}), False, True),
        (_stiff_hysteretic_mounts, False, False),
        (_stiff_with_a_snubbed_mount, True, False),
        (_soft_beside_a_stiff_key, True, False),
        (_genset, True, False),
    ):
        model = assemble(build()[0])
        assert (model.piecewise, model.linear_stiffness) == (piecewise, linear), build


def test_the_exponential_method_asked_for_where_auto_would_not_take_it_is_warned_of() -> None:
    """`integration.method: exprb32` on a scene whose stiff modes are not its linear mounts'
    alone draws a load warning on integration.method saying why (a law with pieces, naming the
    first such mount; stiff non-linear mounts): there it was measured far off (the light body
    beside the stiff key at rtol 1e-6: 0.31 of the largest force, `bench/stiff_methods.py`).
    None where its stiff modes are the linear mounts' (the stiff scene, and beside it a soft
    Bouc–Wen elastomer), nor for another method on the same scenes. The loader says it: the
    bundled genset's file with the method changed."""

    def warned(scene: Scene, method: str) -> list[str]:
        scene = dataclasses.replace(
            scene, integration=dataclasses.replace(scene.integration, method=method)
        )
        paths = [scene.mount_path(i) for i in range(len(scene.mounts))]
        found = check_scene(scene, paths, refuse_unheld=False)
        return [w.message for w in found if w.path == "integration.method"]

    for build, why in (
        (_stiff_light, None),
        (_stiff_with_a_hysteretic_mount, None),
        (_stiff_hysteretic_mounts, "its non-linear mounts are stiff"),
        (_soft_beside_a_stiff_key, "the law of {} has pieces"),
        (_genset, "the law of {} (and 7 more mounts) has pieces"),
    ):
        scene = build()[0]
        assert warned(scene, "auto") == warned(scene, "ros34pw2") == [], build
        found = warned(scene, "exprb32")
        if why is None:
            assert found == [], build
            continue
        pieces = [i for i, m in enumerate(scene.mounts) if m.kind in ("shear_key", "bolted_joint")]
        said = why.format(*(scene.mount_path(i) for i in pieces[:1]))
        assert len(found) == 1 and said in found[0], found
    data = yaml.safe_load((CONFIG / "genset_bolted_keyed.scene.yaml").read_text(encoding="utf-8"))
    data["integration"]["method"] = "exprb32"
    loaded = scene_from_dict(data, "genset, exprb32")
    assert [str(w) for w in loaded.warnings if w.path == "integration.method"] == [
        f"genset, exprb32: integration.method: {warned(loaded, 'exprb32')[0]}"
    ]


def _companion_per_interval(
    scene: Scene, samples: SampleBatch, monkeypatch
) -> list[tuple[float, bool, float]]:
    """The scene's run pushed one sample at a time: after each interval from the start, (its
    end stamp, whether the companion's local error was measured there or the companion was
    integrated over it, its stepper's accepted and rejected steps then); the flush, which runs
    the samples the gyro delay held as one batch, is not counted."""
    made = _companions_made(monkeypatch)
    rows: list[tuple[float, bool, float]] = []
    run_samples = driver_module.run_samples

    def counted(loop, segment, out):
        done, status = run_samples(loop, segment, out)
        if done == 1:
            c = made[-1]  # measured or integrated: no carried interval since
            stepped = c.carry[companion.SINCE_CHECK] == 0.0
            rows.append((float(segment.t[1]), stepped, c.result[1] + c.result[2]))
        return done, status

    monkeypatch.setattr(driver_module, "run_samples", counted)
    engine = TwinEngine(assemble(scene))
    for one in split(samples, [1] * len(samples)):
        engine.push(one)
    engine.flush()
    return rows


def test_the_genset_companion_carries_its_error_and_measures_it_in_few_intervals(
    monkeypatch,
) -> None:
    """The bundled genset as shipped (dopri54 under auto at 10 kHz: h·ω of its fastest tangent
    mode 0.36, a period of 17 intervals): the companion is the twin plus its carried error, its
    stepper run only to measure the twin's local error, every half period (8 intervals) and
    where the twin's error norm spikes; before the shock (its first 50 ms) 62 of 373 intervals
    (measured), where the integrated companion stepped at every one."""
    scene, samples = _genset()
    rows = _companion_per_interval(scene, samples, monkeypatch)
    assert len(rows) > 1900
    t0 = float(samples.stamps[0])
    quiet = [stepped for t, stepped, _ in rows if t - t0 < 0.05]
    assert len(quiet) > 300
    assert sum(quiet) <= len(quiet) / 4


def test_at_1_khz_the_genset_companion_is_integrated_and_honest(monkeypatch) -> None:
    """The genset at 1 kHz under dopri54: h·ω of its fastest tangent mode is 3.6, past
    KICK_LIMIT (a symplectic Euler kick is unstable past 2: carried, it read 1e6 times the true
    error), so the companion is integrated over every interval, and reads its true error."""
    scene = dataclasses.replace(
        load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml"),
        integration=dataclasses.replace(
            load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml").integration,
            method="dopri54",
        ),
    )
    ship = read_samples(ROOT / "bags" / "ship_motion_1khz", scene.input)
    samples = split(ship, [400, len(ship) - 400])[0]
    assert assemble(scene).tangent_rate * 1e-3 > _core.KICK_LIMIT
    rows = _companion_per_interval(scene, samples, monkeypatch)
    assert len(rows) > 300 and all(stepped for _, stepped, _ in rows)
    ref = reference_run(scene, samples, 1_000_000)
    acc = measure(scene, samples, 1e-4, 100_000, ref)
    assert 1 / FACTOR < acc.est_force_error / acc.force_error < FACTOR, acc


@pytest.mark.parametrize(
    ("stiffness", "rtol"),
    [
        (1e9, 1e-3),
        (1e9, 3e-4),
        (1e9, 1e-5),
        (1e10, 3e-3),
        (1e10, 1e-3),
        (1e10, 7e-4),
        (1e10, 3e-5),
        (1e10, 1e-6),
        (1e11, 1e-3),
        (1e11, 1e-6),
    ],
)
def test_a_contact_past_the_kicks_reach_is_integrated_not_carried(
    stiffness: float, rtol: float
) -> None:
    """Snubbers far stiffer than the open tangents at 1 kHz: an interval whose kick meets a
    stiffness past its reach on some coordinate (h²·|Δaₖ| > KICK_LIMIT²·|eₖ|, kernel.hpp
    `in_reach`), in which a contact closes or opens (an event function changing sign), or that
    starts with a snubber in contact (elastomer.EVENT_COMPANION) is integrated. Carried, the
    estimate read 1.2e5, 123, 5e9 and 1e35 times the true error; with the reach taken over all
    coordinates at once and those intervals integrated, 14 for 1e10 at rtol 1e-6 (its attitude
    26); carried in contact where the reach let it, 2.22, 0.20 and 19.6 for 1e9 at rtol 1e-3,
    3e-4 and 1e-5 (attitude 48 at 1e-5), and 2.0 and 5.0 for 1e10 at 7e-4 and 3e-5 (attitude
    8.7 and 8.5): a Hertzian snubber stiffens through the interval past the kick taken at its
    start. And an interval carried while the companion met a snubber of its own inside it (its
    event function changing sign over it, where the twin's did not: the twin 32–33 % off in
    force at 1e10 and rtol 1e-3 and looser) is taken again, integrated: carried across, the
    attitude read 3.17 and 2.68 times its true error at rtol 3e-3 and 1e-3 (1.2–8.7 when
    contacts were carried too)."""
    scene, samples = _rubber_on_stiff_snubbers_1khz(stiffness)
    acc = measure(scene, samples, rtol, 100_000, reference_run(scene, samples, 1_000_000))
    assert 1 / FACTOR < acc.est_force_error / acc.force_error < FACTOR, acc
    assert 1 / FACTOR < acc.est_attitude_error_rad / acc.attitude_error_rad < FACTOR, acc


@pytest.mark.parametrize("case", ["rubber_on_snubbers", "hysteresis_snubbers_real_shock"])
def test_the_carried_companion_lies_on_the_references_side_of_the_twin(
    case: str, monkeypatch
) -> None:
    """At the run's last sample the companion's mount forces less the twin's point as the
    reference's less the twin's (the error, not its mirror image): the local errors were added
    as the twin's less the check's, which the estimate's magnitudes cannot see while the carry
    is linear (correlation −1.00 and −0.92 then), but which integrating the companion from the
    mirror over an interval half cancelled (docs/benchmarks.md)."""
    made = _companions_made(monkeypatch)
    scene, samples = CASES[case][0]()
    ref = reference_run(scene, samples, 1_000_000)
    run = run_at(scene, samples, 1e-6, 100_000, True)
    twin = run.out.wrenches[-1][:, :3]
    own = (made[-1].wrenches[:, :3] - twin).ravel()
    true = (ref.out.wrenches[-1][:, :3] - twin).ravel()
    assert own @ true > 0.9 * np.linalg.norm(own) * np.linalg.norm(true), (own, true)


def test_a_restart_zeroes_the_carried_error_and_measures_the_local_error_afresh() -> None:
    """A companion's restart: its state the twin's, carried again beside an explicit twin whose
    tangent rate is known (never without one, nor beside a linearising twin), no local error
    measured yet (the first interval measures one)."""
    model = assemble(load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml"))
    n = model.n_state
    for method, rate, carrying in (
        ("dopri54", 3e3, 1.0),
        ("dopri54", 0.0, 0.0),
        ("ros34pw2", 3e3, 0.0),
    ):
        comp = companion_of(model, method, rate)
        comp.carry[:] = 7.0
        comp.carry[companion.KICK_RATE] = rate
        y = np.linspace(0.0, 1.0, n)
        companion.restart(comp, y)
        assert np.array_equal(comp.y, y) and np.array_equal(comp.y_prev, y)
        assert comp.carry[companion.CARRYING] == carrying
        assert comp.carry[companion.CHECK_NORM] < 0.0
        assert comp.carry[companion.SINCE_CHECK] == 0.0 and comp.carry[companion.INTERVALS] == 0.0
        assert comp.carry[companion.KICK_RATE] == rate


def test_on_a_stiff_scene_the_linearising_methods_are_stable_where_explicit_ones_hunt() -> None:
    """10 kg on 4 × 1e9 N/m at rtol 1e-3: Dormand–Prince is held to ~14 steps per 1 ms sample
    by stability and is 9 % off; the L-stable ros34pw2 takes one step per sample and is within
    1e-3 (it damps the kHz ringing each input kink excites, see docs/scene.md); the exponential
    exprb32, exact on linear mounts, takes one step per sample and is within 1e-7. Every
    estimate is within FACTOR of its true error."""
    scene, samples = _stiff_light("auto")
    ref = reference_run(scene, samples, 1_000_000)
    got = {}
    for method in ("dopri54", "ros34pw2", "exprb32"):
        integ = dataclasses.replace(scene.integration, method=method)
        got[method] = measure(
            dataclasses.replace(scene, integration=integ), samples, 1e-3, 100_000, ref
        )
    explicit, rosenbrock, exponential = got["dopri54"], got["ros34pw2"], got["exprb32"]
    assert explicit.substeps_per_sample > 10 and explicit.force_error > 1e-2
    assert rosenbrock.substeps_per_sample < 1.5 and rosenbrock.force_error < 1e-3
    assert exponential.substeps_per_sample == 1.0 and exponential.force_error < 1e-7
    for acc in got.values():
        assert 1 / FACTOR < acc.est_force_error / acc.force_error < FACTOR, acc


def test_auto_takes_a_linearising_method_where_the_explicit_one_would_be_stability_bound() -> None:
    """ρ of 10 kg on 4 × 1e9 N/m at (±0.4, ±0.3) m is its yaw mode, √(4k(a² + b²)/I_zz) =
    31 623 rad/s (the mounts' plane holds no coupling to it): ρ·Δt = 31.6 at 1 kHz, past
    STIFF_RHO_DT. Its mounts are linear: the exponential method; with a snubbed elastomer
    beside them (a law with pieces in the right-hand side), the L-stable Rosenbrock; with a soft
    Bouc–Wen elastomer beside them (non-linear, no pieces), the exponential method again; on
    four stiff Bouc–Wen elastomers instead (their non-linear law the stiff part), the
    Rosenbrock. The bundled pump (modes below 20 Hz) stays explicit."""
    scene, samples = _stiff_light("auto")
    _, status = _integration_status(scene, samples)
    yaw = math.sqrt(4 * 1e9 * (0.4**2 + 0.3**2) / 1.0) * 1e-3
    assert status.values["method"] == f"exprb32 (auto: ρ·Δt = {yaw:.3g})"
    scene, samples = _stiff_with_a_snubbed_mount()
    _, status = _integration_status(scene, samples)
    assert status.values["method"].startswith("ros34pw2 (auto: ρ·Δt = 31.")
    scene, samples = _stiff_with_a_hysteretic_mount()
    _, status = _integration_status(scene, samples)
    assert status.values["method"].startswith("exprb32 (auto: ρ·Δt = 31.")
    scene, samples = _stiff_hysteretic_mounts()
    _, status = _integration_status(scene, samples)
    assert status.values["method"].startswith("ros34pw2 (auto: ρ·Δt = ")
    scene, samples = _pump()
    _, status = _integration_status(scene, samples)
    assert status.values["method"].startswith("dopri54 (auto: ρ·Δt = 0.1")


def _soft_beside(stop: dict) -> tuple[Scene, SampleBatch]:
    """5 kg on four soft mounts (1e4 N/m: ρ·Δt ≈ 0.3 at 1 kHz) beside `stop`, a mount 0.1 m
    below the CG that bears along x past 0.5 mm at 1e9 N/m, pushed into it by a 3 g, 50 ms
    lateral half-sine. Bearing, ρ = √(k(1/m + h²/I_yy)) (x and pitch couple): ρ·Δt = 17.3."""
    soft = [
        mount(f"m{i}", (x, y, 0.0), (1e4,) * 3 + (0,) * 3, (20.0,) * 3 + (0,) * 3)
        for i, (x, y) in enumerate(CORNERS)
    ]
    data = base_scene(5.0, [0.0, 0.0, 0.1], [0.1, 0.1, 0.1, 0.0, 0.0, 0.0], [*soft, stop])
    data["integration"]["method"] = "auto"
    t = np.arange(301) * 1e-3
    push = np.where((t > 0.02) & (t < 0.07), 3.0 * G * np.sin(math.pi * (t - 0.02) / 0.05), 0.0)
    accel = np.column_stack([push, np.zeros_like(t), np.full_like(t, G)])
    scene = _with_pump_input(data)
    frames = [scene.input.frame_id] * t.shape[0]
    return raw_gyro(scene), SampleBatch(1.0 + t, accel, np.zeros_like(accel), frames)


BEARING_RHO_DT = math.sqrt(1e9 * (1 / 5.0 + 0.1**2 / 0.1)) * 1e-3
"""ρ·Δt of `_soft_beside` once its stop bears (closed form, see there)."""


def _soft_beside_a_stiff_key() -> tuple[Scene, SampleBatch]:
    key = kind_mount(
        "shear_key",
        "key",
        (0.0, 0.0, 0.0),
        stiffness=[1e9, 0.0, 0.0],
        damping=[1e3, 0, 0],
        clearance=5e-4,
    )
    return _soft_beside(key)


def _snubber_on_x(gap: float, stiffness: float) -> dict:
    """A mount at the CG's foot of next to no stiffness of its own (1 N/m) with a linear
    snubber along x, `gap` m off, `stiffness` N/m past it."""
    return kind_mount(
        "elastomer",
        "snubbed",
        (0.0, 0.0, 0.0),
        stiffness_linear=[1.0, 1.0, 1.0],
        damping=[0.0, 0.0, 0.0],
        snubber={"gap": gap, "stiffness": stiffness, "exponent": 1.0, "axes": ["x"]},
    )


def _soft_beside_a_snubber() -> tuple[Scene, SampleBatch]:
    return _soft_beside(_snubber_on_x(5e-4, 1e9))


def _rho_dt(method: str) -> float:
    """ρ·Δt in an integration status' `method`, e.g. `ros34pw2 (auto: ρ·Δt = 17.3 ...)`."""
    return float(method.split("= ")[1].split(" ", maxsplit=1)[0].rstrip(",)"))


def test_auto_starts_a_light_body_beside_a_stiff_key_on_what_the_closed_key_needs() -> None:
    """The key's nominal tangent counts, clearance or not: ρ·Δt 17.3 (closed form) where the
    open clearance gives 0.3, so the Rosenbrock from the first sample. Against the reference
    it is within 1e-3 of the largest force and its estimate within 2×; Dormand–Prince, which
    the open clearance alone would have chosen, is 2e-2 off at the key's closing and
    estimates a tenth of that."""
    scene, samples = _soft_beside_a_stiff_key()
    # started at the first sample (no 50 ms start window held back): the choice is made at
    # the first interval, at rest, before the push at 20 ms
    initial = dataclasses.replace(scene.initial, gravity_window_s=0.0)
    engine = TwinEngine(assemble(dataclasses.replace(scene, initial=initial)))
    before, after = split(samples, [20])  # at rest: the push starts at 20 ms
    engine.push(before)
    start = engine.health.method
    assert start.startswith("ros34pw2 (auto: ρ·Δt = ") and start.endswith(", keys bearing)")
    assert float(start.split("= ")[1].split(",")[0]) == pytest.approx(BEARING_RHO_DT, rel=0.01)
    engine.push(after)
    assert engine.counts["method_switches"] == 0
    assert any(e.event == "key_contact" for e in engine.events)
    ref = reference_run(scene, samples, 1_000_000)
    got = {}
    for method in ("auto", "dopri54"):
        integ = dataclasses.replace(scene.integration, method=method)
        got[method] = measure(
            dataclasses.replace(scene, integration=integ), samples, 1e-6, 100_000, ref
        )
    assert got["auto"].force_error < 1e-3
    assert 1 / FACTOR < got["auto"].est_force_error / got["auto"].force_error < FACTOR
    assert got["dopri54"].force_error > 1e-2


def test_the_tangent_rate_is_the_body_on_its_springs_taken_once_per_model(monkeypatch) -> None:
    """What `auto` weighs at every start: a body free along z only, on four springs of k each,
    moves at ω = √(4k/m) rad/s; a model takes it once, not at each engine's start."""
    k, m = 2.0e6, 50.0
    mounts = [
        mount(f"m{i}", (x, y, 0.0), (1e5, 1e5, k, 0, 0, 0)) for i, (x, y) in enumerate(CORNERS)
    ]
    data = base_scene(m, [0.0, 0.0, 0.1], [1.0] * 3 + [0.0] * 3, mounts, dofs=["z"])
    model = assemble(scene_from_dict(data, "<tangent rate test>"))
    taken = []
    real = statics_module.statics
    monkeypatch.setattr(statics_module, "statics", lambda scene: taken.append(1) or real(scene))
    assert model.tangent_rate == pytest.approx(math.sqrt(4.0 * k / m), rel=1e-12)
    assert model.tangent_rate == pytest.approx(math.sqrt(4.0 * k / m), rel=1e-12)
    assert len(taken) == 1


def test_auto_looks_again_after_a_mount_event_the_same_live_and_replayed() -> None:
    """A snubber's contact has no nominal tangent (it is open at rest): the soft scene starts
    explicit; when the snubber touches (`snubber_contact`) `auto` takes ρ at that sample, now
    the snubber's (closed form), and switches to the Rosenbrock (a contact switches: not
    smooth). One push of the record and one push per sample make the same choice at the same
    sample and publish the same numbers, bit for bit."""
    scene, samples = _soft_beside_a_snubber()
    engine, status = _integration_status(scene, samples)
    contact = next(e for e in engine.events if e.event == "snubber_contact")
    assert status.values["method"].startswith("ros34pw2 (auto: ρ·Δt = ")
    assert status.values["method"].endswith("after snubber_contact of snubbed)")
    assert _rho_dt(status.values["method"]) == pytest.approx(BEARING_RHO_DT, rel=0.01)
    assert engine.counts["method_switches"] == 1 and engine.counts["integration_failures"] == 0
    assert 1.02 < contact.stamp < 1.07
    whole = TwinEngine(assemble(scene)).push(samples)
    live = TwinEngine(assemble(scene))
    parts = [live.push(one) for one in split(samples, [1] * len(samples))]
    np.testing.assert_array_equal(whole.wrenches, np.concatenate([p.wrenches for p in parts]))
    assert live.counts["method_switches"] == 1


SNUB_RATE_HZ = 100.0
SNUB_LATERAL = 2.0
"""m/s² along x of F: a heel of 11.8°, past what the soft mounts take within the snubber's gap."""


def _heeled_onto_a_snubber(
    method: str = "auto", stiffness: float = 1e7, seconds: float = 0.5, rtol: float = 1e-6
) -> tuple[Scene, Model, SampleBatch, SampleBatch]:
    """5 kg, CG 0.1 m above four corner mounts soft laterally (1e3 N/m in x and y, 1e4 N/m in
    z), beside a snubber 1 mm off along x at `stiffness` N/m (linear past the gap), at `rtol`
    (atol 1e-3 of it), under a 100 Hz input: upright for `seconds`, then after a 1 s gap (past
    `max_gap_s`, a restart) heeled by SNUB_LATERAL along x as long, with 0.3 m/s² of 5 Hz
    sway on it. The heel takes 4 N within the gap and presses the snubber with the other 6 N
    at equilibrium: the restart starts on it, with no contact to log (bench/restart_methods.py
    measures the methods there). Returns (scene, its model, upright, heeled)."""
    soft = [
        mount(f"m{i}", (x, y, 0.0), (1e3, 1e3, 1e4, 0, 0, 0), (20.0,) * 3 + (0,) * 3)
        for i, (x, y) in enumerate(CORNERS)
    ]
    snubbed = _snubber_on_x(1e-3, stiffness)
    data = base_scene(5.0, [0.0, 0.0, 0.1], [0.1, 0.1, 0.1, 0.0, 0.0, 0.0], [*soft, snubbed])
    data["integration"].update(method=method, rtol=rtol, atol=rtol * 1e-3)
    data["input"]["max_gap_s"] = 0.5
    data["initial_state"]["gravity_window_s"] = 0.0
    scene = raw_gyro(_with_pump_input(data))
    t = np.arange(round(seconds * SNUB_RATE_HZ)) / SNUB_RATE_HZ
    sway = 0.3 * np.sin(2.0 * math.pi * 5.0 * t)
    upright = np.column_stack([np.zeros_like(t), np.zeros_like(t), np.full_like(t, G)])
    heeled = np.column_stack(
        [SNUB_LATERAL + sway, np.zeros_like(t), np.full_like(t, math.sqrt(G**2 - SNUB_LATERAL**2))]
    )
    frames = [scene.input.frame_id] * t.shape[0]
    zero = np.zeros_like(upright)
    return (
        scene,
        assemble(scene),
        SampleBatch(1.0 + t, upright, zero, frames),
        SampleBatch(2.0 + seconds + t, heeled, zero, frames),
    )


def _pressed_rho(stiffness: float = 1e7) -> float:
    """ρ (rad/s) of `_heeled_onto_a_snubber` resting on its snubber of `stiffness` (N/m), by
    hand: its stiff mode is x and pitch coupled, the lateral springs (4·1e3 N/m and the
    snubber's) acting 0.1 m below the CG, on x − 0.1·θ, and the vertical ones (4·1e4 N/m at
    x = ±0.4 m) on the pitch alone; ρ² is the largest eigenvalue of M⁻¹K (the weight's
    geometric stiffness, ~5 N·m/rad against 1e5, left out)."""
    lateral = 4 * 1e3 + stiffness
    k = lateral * np.array([[1.0, -0.1], [-0.1, 0.01]]) + np.diag([0.0, 4 * 1e4 * 0.4**2])
    return math.sqrt(np.linalg.eigvals(np.diag([1 / 5.0, 1 / 0.1]) @ k).real.max())


def test_auto_chooses_again_at_a_restart_onto_a_pressed_snubber() -> None:
    """Upright, the scene is soft (ρ·Δt 2.5): explicit. The gap's restart starts resting on
    the snubber, which logs no contact (it touched before the first interval), and ρ·Δt there
    is 17.4 (closed form, `_pressed_rho`): `auto` chooses at the restart as at a first start,
    from the state it starts at, so the Rosenbrock, as a new twin started there chooses.
    Before, the upright start's explicit method went on (what each method costs there:
    docs/scene.md, bench/restart_methods.py)."""
    _, model, upright, heeled = _heeled_onto_a_snubber()
    engine = TwinEngine(model)
    engine.push(upright)
    assert engine.health.method.startswith("dopri54 (auto: ρ·Δt = 2.5")
    engine.push(heeled)
    rho_dt = _pressed_rho() / SNUB_RATE_HZ
    assert choose(rho_dt, smooth=False) == "ros34pw2"
    assert engine.health.method.startswith("ros34pw2 (auto: ρ·Δt = ")
    assert _rho_dt(engine.health.method) == pytest.approx(rho_dt, rel=0.01)
    assert engine.counts["restarts"] == 1 and engine.counts["method_switches"] == 1
    assert not engine.events  # no contact logged: the restart's own look
    fresh = TwinEngine(assemble(model.scene))
    fresh.push(heeled)
    assert engine.health.method == fresh.health.method.replace(")", ", at a restart)")


def test_auto_looks_again_after_a_restart_whose_stamps_went_back() -> None:
    """The snubber's contact (`_soft_beside_a_snubber`) twice, the second lap 2 s earlier on
    the record (a bag looped: a stamp going back past `back_jump_reset_s` restarts the twin).
    Each start chooses from its state (explicit, at rest and open) and each contact looks
    again (the Rosenbrock): three switches. A look's throttle is record time after it, and a
    restart starts it afresh: the second lap's contact falls before the first's throttle
    ended."""
    scene, samples = _soft_beside_a_snubber()
    lap = SampleBatch(samples.stamps - 2.0, samples.accel, samples.gyro, samples.frame_ids)
    engine = TwinEngine(assemble(scene))
    fields = ("stamps", "accel", "gyro")
    both = (np.concatenate([getattr(b, k) for b in (samples, lap)]) for k in fields)
    engine.run(SampleBatch(*both, [*samples.frame_ids, *lap.frame_ids]))
    contacts = [e.stamp for e in engine.events if e.event == "snubber_contact"]
    assert engine.counts["restarts"] == 1 and contacts[0] > 1.0 > contacts[-1]
    assert engine.counts["method_switches"] == 3
    assert engine.health.method.endswith("after snubber_contact of snubbed)")


def test_the_worst_estimate_over_a_replay_is_one_figure_in_summary_json_and_diagnostics(
    tmp_path: Path,
) -> None:
    """The run's largest |ΔF| over its largest |F| (the definition `mount-twin accuracy` uses)
    in the summary text, its JSON and the worst-over-the-run integration status alike; no
    period's figure exceeds it."""
    scene, _ = _stiff_light()
    loose = dataclasses.replace(scene.integration, rtol=1e-3, atol=1e-6)
    summary = replay(
        dataclasses.replace(scene, integration=loose),
        ROOT / "bags" / "ship_motion_1khz",
        tmp_path / "out",
        progress=False,
    )
    est = summary.error_estimate
    assert est is not None and est.force_error_rel > 0.01
    figure = f"{est.force_error_rel:.2g}"
    worst = summary.worst[INTEGRATION]
    assert worst.level == WARN
    assert f"estimated mount-force error {figure} of the largest force" in worst.message
    assert worst.values["est_force_error_rel_run"] == figure
    assert float(worst.values["est_force_error_rel"]) <= est.force_error_rel
    assert f"mount forces {figure} of the largest" in summary.text()
    data = json.loads(json.dumps(summary.to_dict()))
    assert data["error_estimate"]["force_error_rel"] == est.force_error_rel
    assert data["diagnostics_worst"][INTEGRATION]["message"] == worst.message
    assert "not estimated" not in data["accuracy"]


def test_a_sweep_row_reads_the_replays_estimate(tmp_path: Path) -> None:
    """A sweep's row (one push of the whole record) and the replay's summary (chunks of 2000)
    give the same estimate for the same run, to the bit."""
    scene, _ = _stiff_light()
    loose = dataclasses.replace(
        scene, integration=dataclasses.replace(scene.integration, rtol=1e-3)
    )
    bag = ROOT / "bags" / "ship_motion_1khz"
    row = sweep_runner._figures(loose, read_samples(bag, loose.input))
    summary = replay(loose, bag, tmp_path / "out", progress=False)
    assert summary.error_estimate is not None
    assert row["est_force_error_rel"] == summary.error_estimate.force_error_rel > 0.0
