"""Start and restart: samples gathered toward a start, the start checked and the twin put there.

A start (the first sample, a gap reset, a stamp jumping back, a stepper failure) takes the
mean specific force of `initial_state.gravity_samples` samples, the last the start sample, and
of those within `gravity_window_s` after it (`start_takes`) as gravity where the scene starts at
equilibrium under the input, checks it (its magnitude against the scene's g, its tilt, whether
the samples' mean held still),
and puts the twin in the state `restart.start_state` gives: the mounts' damage kept, at rest in
the machine's own equilibrium; none where it has none, and the twin then follows no more until
a later restart finds one.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from mount_twin.engine.batch import ERROR, WARN
from mount_twin.engine.delay_line import STAMP_SLACK_S, Run
from mount_twin.engine.driver import CoreDriver
from mount_twin.engine.health import HealthWindow
from mount_twin.engine.restart import start_state
from mount_twin.engine.rows import BatchRows, Part
from mount_twin.model.assemble import Model
from mount_twin.physics.rotations import angle_text
from mount_twin.scene.description import STANDARD_GRAVITY, InitialState, InputSpec

REST_BLOCKS = 8
"""The start samples are judged at rest in this many consecutive parts (each sample alone
where they are fewer): on the real 20 kHz record at rest a 50 ms window's samples lie up to
0.25 g from their mean (its noise), its eighths' means within 0.041 g of it
(bench/start_gravity.py)."""


def at_rest(gathered: np.ndarray, tolerance: float) -> tuple[int, float]:
    """The leading samples of `gathered` (specific forces, m/s²) at rest, by REST_BLOCKS
    consecutive parts: each part's mean within `tolerance` (m/s²) of the mean of those before
    it, up to the first that is not (a shock's, or a drift's). Returns (samples at rest, how
    far the first part not at rest lies from their mean m/s²; 0 where all are)."""
    parts = np.array_split(gathered, min(REST_BLOCKS, gathered.shape[0]))
    taken, total = parts[0].shape[0], parts[0].sum(axis=0)
    for part in parts[1:]:
        part_sum = part.sum(axis=0)  # over its count: np.mean's own reduction
        off = float(np.linalg.norm(part_sum / part.shape[0] - total / taken))
        if off > tolerance:
            return taken, off
        taken, total = taken + part.shape[0], total + part_sum
    return taken, 0.0


def start_hint(spec: InputSpec, magnitude: float) -> str:
    """Why a start specific force of `magnitude` (m/s²) may be off the scene's g (`input.g`):
    the likeliest cause."""
    g, earth = spec.g, abs(magnitude - STANDARD_GRAVITY) < 0.25 * STANDARD_GRAVITY
    if g == 0.0 and earth:
        return "the scene has no gravity (input.g: 0): is the input a sensor at rest on Earth?"
    if earth and abs(g - STANDARD_GRAVITY) > 0.25 * STANDARD_GRAVITY:
        return f"the scene's gravity is input.g: {g:.4g} m/s²: is the input a sensor on Earth?"
    if not spec.includes_gravity and abs(magnitude - 2.0 * g) < 0.25 * g:
        return "input.includes_gravity is false, so g was added: does the input include it?"
    return (
        "a start on a shock or spike, free fall, or a sensor bias? "
        "initial_state.gravity_window_s averages the start"
    )


def start_notes(
    spec: InputSpec, init: InitialState, f0: np.ndarray
) -> tuple[float, float, list[tuple[int, str]]]:
    """Start checks on the start specific force f0 (m/s², F): its magnitude against the
    scene's g (`input.g`) and its angle from +z of F (where g > 0), in units of g (of standard
    gravity at g = 0: `InputSpec.g_scale`). Returns (|f0| m/s², tilt rad, [(level, note)]).
    An implausible sag (units?) is the scene's load-time warning (scene.checks), not
    repeated."""
    g, unit, magnitude = spec.g, spec.g_scale, float(np.linalg.norm(f0))
    tilt = math.atan2(math.hypot(f0[0], f0[1]), f0[2]) if g > 0.0 else 0.0
    off = abs(magnitude - g) / unit
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
    return magnitude, tilt, notes


def start_takes(init: InitialState) -> tuple[int, float]:
    """What a start's gravity is the mean of: `gravity_samples` samples (the last the start
    sample) and those within `gravity_window_s` (s) after it, where the scene starts at
    equilibrium under the first samples; else the start sample alone (1, 0.0)."""
    if init.mode == "equilibrium" and init.gravity == "first_sample":
        return init.gravity_samples, init.gravity_window_s
    return 1, 0.0


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
        self._takes = start_takes(model.scene.initial)
        """(samples, s): what a start's gravity is the mean of (`start_takes`)."""
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

    def gather(self, run: Run, stamps: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Take a run's samples (frame rows: stamps s, specific forces m/s² in F) toward a
        start: `initial_state.gravity_samples` of them, the start sample their last, and the
        run's samples within `gravity_window_s` after it, released or still in the gyro
        filter's delay (`Run.ahead`: `GyroDelay` holds a run back until they have come, or it
        ended); a restart after a stepper failure takes the start sample alone.

        Returns the run's samples from the start sample on (none while still gathering) and
        the specific forces (m/s², F) the start's gravity is the mean of.
        """
        if run.restart:  # a gap or a stamp jump: gravity is gathered again
            self._gathered, self._failed = [], False
        takes, window_s = (1, 0.0) if self._failed else self._takes
        need = takes - len(self._gathered)
        taken = run.index[:need]
        if need > len(taken):
            self._gathered.extend(f[taken])
            self._health.gathering = (len(self._gathered), takes)
            return run.index[:0], np.empty((0, 3))
        self._health.gathering = None
        after = run.index[len(taken) - 1 :]
        following = np.concatenate([after, run.ahead])  # the start sample, then its window's
        times = stamps[following]
        end = (
            np.searchsorted(times, times[0] + window_s + STAMP_SLACK_S, "right") if window_s else 1
        )
        self._gathered.extend(f[taken[:-1]])
        gathered = np.concatenate([np.reshape(self._gathered, (-1, 3)), f[following[:end]]])
        self._gathered = []
        return after, gathered

    def start(
        self, i: int, frame: tuple[np.ndarray, np.ndarray, np.ndarray], gathered: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """(Re)start the twin at sample i of `frame` (stamps s, f m/s² and Ω rad/s in F per
        sample), under the mean specific force of `gathered` (m/s², F; `gather`'s), of its
        leading samples at rest (`at_rest`: a shock among them ends them; fewer than
        `initial_state.gravity_samples` is a WARN), as gravity and sample i's rotation rate
        (as the gyro policy takes it) where the scene starts at equilibrium under the input.
        A restart keeps the mounts' damage (fracture, plastic elongation, hysteresis) and
        starts the machine as it is at rest in its own equilibrium (`restart.start_state`).
        Returns the start's outputs (pose row, wrenches); None: it has none, and the twin
        follows no more (nothing published) until a later restart finds one."""
        stamps, f, w = frame
        driver, counts = self._driver, self._counts
        failed, self._failed = self._failed, False
        internal = driver.y[2 * len(self.model.scene.dofs) :].copy()
        damage = internal if counts["starts"] and np.isfinite(internal).all() else None
        if driver.last is not None or counts["starts"]:
            counts["restarts"] += 1
        counts["starts"] += 1
        stamp = float(stamps[i])
        scene = self.model.scene
        rest, off = at_rest(gathered, scene.initial.gravity_tolerance * scene.input.g_scale)
        f0 = gathered[:rest].mean(axis=0)
        w0 = w[i].copy()
        nominal = self.model.nominal_state
        start = start_state(self.model, nominal, self._gravity_up, f0, w0, damage)
        magnitude, tilt, notes = start_notes(scene.input, scene.initial, f0)
        if rest < (1 if failed else self._takes[0]):  # fewer than asked for
            notes.append(
                (
                    WARN,
                    f"not at rest over the {gathered.shape[0]} start samples: the start took "
                    f"the first {rest}, the mean of the next part is {off:.3g} m/s² from theirs",
                )
            )
        self._health.start_checked(stamp, magnitude, tilt, notes)
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
