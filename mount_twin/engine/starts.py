"""Start and restart: samples gathered toward a start, the start checked and the twin put there.

A start (the first sample, a gap reset, a stamp jumping back, a stepper failure) takes the
mean specific force of `initial.gravity_samples` samples as gravity where the scene starts at
equilibrium under the input, checks it (its magnitude against g, its tilt, the samples' spread),
and puts the twin in the state `restart.start_state` gives: the mounts' damage kept, at rest in
the machine's own equilibrium; none where it has none, and the twin then follows no more until
a later restart finds one.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from mount_twin.engine.batch import ERROR, WARN
from mount_twin.engine.delay_line import Run
from mount_twin.engine.driver import CoreDriver
from mount_twin.engine.health import HealthWindow
from mount_twin.engine.restart import start_state
from mount_twin.engine.rows import BatchRows, Part
from mount_twin.model.assemble import Model
from mount_twin.physics.rotations import angle_text
from mount_twin.scene.description import STANDARD_GRAVITY, InitialState, InputSpec


def start_hint(spec: InputSpec, magnitude: float) -> str:
    """Why a start specific force of `magnitude` (m/s²) may be off g: the likeliest cause."""
    g = spec.g
    if g == 0.0 and abs(magnitude - STANDARD_GRAVITY) < 0.25 * STANDARD_GRAVITY:
        return "the scene has no gravity (input.g: 0): is the input a sensor at rest on Earth?"
    if not spec.includes_gravity and abs(magnitude - 2.0 * g) < 0.25 * g:
        return "input.includes_gravity is false, so g was added: does the input include it?"
    return (
        "a start on a shock or spike, free fall, or a sensor bias? "
        "initial.gravity_samples averages the start"
    )


def start_notes(
    spec: InputSpec, init: InitialState, f0: np.ndarray, gathered: np.ndarray
) -> tuple[float, float, list[tuple[int, str]]]:
    """Start checks on the start specific force f0 (m/s², F) and the samples it is the mean
    of: its magnitude against g, its angle from +z of F (where g > 0), and their spread (at
    rest?), in units of g (of standard gravity at g = 0: `InputSpec.g_scale`). Returns
    (|f0| m/s², tilt rad, [(level, note)]). An implausible sag (units?) is the scene's
    load-time warning (scene.checks), not repeated."""
    g, unit, magnitude = spec.g, spec.g_scale, float(np.linalg.norm(f0))
    tilt = math.atan2(math.hypot(f0[0], f0[1]), f0[2]) if g > 0.0 else 0.0
    off = abs(magnitude - g) / unit
    spread = float(np.linalg.norm(gathered - f0, axis=1).max())
    notes: list[tuple[int, str]] = []
    if off > init.gravity_tolerance:
        notes.append(
            (
                ERROR if off > 3.0 * init.gravity_tolerance else WARN,
                f"start specific force |f0| = {magnitude:.4g} m/s² is "
                f"{magnitude / unit:.3g} g{'' if g > 0.0 else ' (standard)'} "
                f"({start_hint(spec, magnitude)})",
            )
        )
    if tilt > init.tilt_tolerance_rad:
        notes.append(
            (
                ERROR if tilt > 3.0 * init.tilt_tolerance_rad else WARN,
                f"start specific force is {angle_text(tilt)} from +z of F "
                "(is input.sensor_rpy right?)",
            )
        )
    if spread > init.gravity_tolerance * unit:
        notes.append(
            (
                WARN,
                f"not at rest over the {gathered.shape[0]} start samples: they spread "
                f"{spread:.3g} m/s² about their mean",
            )
        )
    return magnitude, tilt, notes


class Starts:
    """Starts and restarts of one twin.

    Args:
        model: the assembled scene (its nominal start state, `Model.nominal_state`).
        driver: the core driver the twin runs on.
        health: the health window (start checks, fallbacks, stops).
        counts: the engine's counters (starts, restarts, starts_without_equilibrium, ...).
    """

    def __init__(
        self, model: Model, driver: CoreDriver, health: HealthWindow, counts: Counter[str]
    ) -> None:
        self.model = model
        self._driver = driver
        self._health = health
        self._counts = counts
        self._gravity_up = np.array([0.0, 0.0, model.scene.input.g])
        init = model.scene.initial
        self._start_samples = (
            init.gravity_samples
            if init.mode == "equilibrium" and init.gravity == "first_sample"
            else 1
        )
        self._gathered: list[np.ndarray] = []
        """Specific forces (m/s², F) of the samples taken so far toward the next start."""
        self._failed = False
        """The last run ended in a stepper failure: its restart takes the next sample alone,
        in this push or the next (a restart within a push does)."""

    def after_failure(self) -> None:
        """The stepper failed: the restart takes the next sample alone, wherever the push
        ends (gathering `gravity_samples` only at a push's end answered fewer samples the
        smaller the pushes)."""
        self._failed, self._gathered = True, []
        self._health.gathering = None

    def gather(self, run: Run, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Take a run's samples toward a start (`initial.gravity_samples` of them).

        Returns the run's samples from the start sample on (none while still gathering) and
        the specific forces (m/s², F) gathered for the start, the start sample's last.
        """
        if run.restart:  # a gap or a stamp jump: gravity is gathered again
            self._gathered, self._failed = [], False
        takes = 1 if self._failed else self._start_samples
        need = takes - len(self._gathered)
        taken = run.index[:need]
        self._gathered.extend(f[taken])
        if need > len(taken):
            self._health.gathering = (len(self._gathered), takes)
            return run.index[:0], np.empty((0, 3))
        self._health.gathering = None
        gathered, self._gathered = np.array(self._gathered), []
        return run.index[len(taken) - 1 :], gathered

    def start(
        self, i: int, frame: tuple[np.ndarray, np.ndarray, np.ndarray], gathered: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """(Re)start the twin at sample i of `frame` (stamps s, f m/s² and Ω rad/s in F per
        sample), under the mean specific force of `gathered` (m/s², F; sample i's last) as
        gravity and sample i's rotation rate (as the gyro policy takes it) where the scene
        starts at equilibrium under the input. A restart keeps the mounts' damage (fracture,
        plastic elongation, hysteresis) and starts the machine as it is at rest in its own
        equilibrium (`restart.start_state`). Returns the start's outputs (pose row, wrenches);
        None: it has none, and the twin follows no more (nothing published) until a later
        restart finds one."""
        stamps, f, w = frame
        driver, counts = self._driver, self._counts
        self._failed = False
        internal = driver.y[2 * len(self.model.scene.dofs) :].copy()
        damage = internal if counts["starts"] and np.isfinite(internal).all() else None
        if driver.last is not None or counts["starts"]:
            counts["restarts"] += 1
        counts["starts"] += 1
        stamp = float(stamps[i])
        f0 = gathered.mean(axis=0)
        w0 = w[i].copy()
        nominal = self.model.nominal_state
        start = start_state(self.model, nominal, self._gravity_up, f0, w0, damage)
        self._health.start_checked(
            stamp, *start_notes(self.model.scene.input, self.model.scene.initial, f0, gathered)
        )
        if start.state is None:
            self.stop_following(stamp, f"{start.note}{self._damage_text()}")
            counts["starts_without_equilibrium"] += 1
            return None
        if start.note is not None:
            counts["starts_at_nominal_gravity"] += 1
            self._health.forced_start(stamp, start.note)
        return driver.begin(start.state, stamp, f[i], w0)

    def started(
        self,
        out: list[Part],
        index: np.ndarray,
        frame: tuple[np.ndarray, np.ndarray, np.ndarray],
        gathered: np.ndarray,
        rows: BatchRows,
    ) -> bool:
        """Start at sample index[0] (`start`), its outputs into `rows` and onto `out`; False
        where no equilibrium holds: `index` is then counted as not followed."""
        i = int(index[0])
        outputs = self.start(i, frame, gathered)
        if outputs is None:
            self._counts["samples_not_followed"] += len(index)
            return False
        out.append(rows.put(i, *outputs))
        return True

    def _damage_text(self) -> str:
        """'; at the last sample: <mount> <condition>, ...' of the error conditions holding
        at the last sample (a broken bolt), or ''."""
        active = self._driver.active()
        held = [f"{m} {e}" for m, now in active.items() for e, error in now if error]
        return f"; at the last sample: {', '.join(held)}" if held else ""

    def stop_following(self, stamp: float, why: str) -> None:
        """Follow no more from `stamp` (s): nothing is published until a restart, and every
        report says why at ERROR."""
        self._health.stop(stamp, why)
        self._driver.last = None
