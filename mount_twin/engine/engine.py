"""TwinEngine: validates input samples, advances the twin, and produces outputs and health.

Knows nothing of ROS or files: adapters decode messages into `SampleBatch` and encode the
`OutputBatch` it returns. Bad samples are counted, reported and skipped; the twin keeps running.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mount_twin.engine.batch import OutputBatch, SampleBatch
from mount_twin.engine.health import HealthWindow
from mount_twin.engine.kernel import run_samples
from mount_twin.integrate.stepper import STATUS_TEXT, STEPPERS
from mount_twin.model.assemble import Model, initial_state
from mount_twin.physics.dynamics import INPUT_SIZE, evaluate

ACCEPT, RESTART = "accept", "restart"
"""Sample classes besides the rejection reasons: take it, or restart the twin at it."""


@dataclass
class _Run:
    """Accepted samples to integrate in one go; `restart`: the first one starts a new state."""

    index: list[int]
    restart: bool


class TwinEngine:
    """Streaming twin of one model.

    Args:
        model: the assembled scene.
        clock: wall clock for the real-time factor, s (injectable for tests).
    """

    def __init__(self, model: Model, clock: Callable[[], float] = time.perf_counter) -> None:
        scene = model.scene
        self.model = model
        self.scene = scene
        self._clock = clock
        integ = scene.integration
        self.stepper = STEPPERS[integ.method](
            model.n_state, integ.rtol, integ.atol, integ.max_substeps
        )
        self._scratch = model.new_scratch()
        self._u = np.zeros(INPUT_SIZE)
        self._y = np.zeros(model.n_state)
        self._peak = np.zeros((model.n_mounts, 6))
        self._counter = np.zeros(1, dtype=np.int64)
        self._last: tuple[float, np.ndarray, np.ndarray] | None = None
        self._gravity_up = np.array([0.0, 0.0, scene.input.g])
        self.counts: Counter[str] = Counter()
        self.health = HealthWindow(scene, self.stepper.name)
        self._warm_up()

    def _warm_up(self) -> None:
        """Load (or compile) the kernels now, not at the first live sample."""
        model, st = self.model, self.stepper
        t = np.array([0.0, 1e-3])
        f = np.tile(self._gravity_up, (2, 1))
        n, nm = 2, model.n_mounts
        y = np.zeros(model.n_state)
        run_samples(
            st.method,
            st.settings.copy(),
            st.work2d.copy(),
            st.work1d.copy(),
            st.result.copy(),
            model.arrays,
            model.new_scratch(),
            np.zeros(INPUT_SIZE),
            y,
            t,
            f,
            np.zeros((2, 3)),
            False,
            1,
            np.zeros(1, dtype=np.int64),
            np.zeros((nm, 6)),
            np.zeros((n, 10)),
            np.zeros((n, nm, 6)),
            np.zeros(n, dtype=np.bool_),
            np.zeros((n, 3)),
        )

    @property
    def state(self) -> np.ndarray:
        """Current state vector (copy); names in `model.state_names`."""
        return self._y.copy()

    @property
    def running(self) -> bool:
        """True once a sample has started the twin (and no failure has stopped it since)."""
        return self._last is not None

    def count(self, what: str, n: int = 1) -> None:
        """Count events found outside the engine (e.g. undecodable messages) with its own."""
        self.counts[what] += n

    def push(self, batch: SampleBatch) -> OutputBatch:
        """Process samples in arrival order; return what is to be published for them."""
        wall0 = self._clock()
        f, w = self._to_foundation(batch)
        parts: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        for run in self._runs(batch, f, w):
            parts.extend(self._integrate(run, batch.stamps, f, w))
        stamps = np.concatenate([p[0] for p in parts]) if parts else np.zeros(0)
        pose = np.concatenate([p[1] for p in parts]) if parts else np.zeros((0, 10))
        wrenches = (
            np.concatenate([p[2] for p in parts])
            if parts
            else np.zeros((0, self.model.n_mounts, 6))
        )
        self.health.add_outputs(stamps, pose)
        reports = self.health.due(self._clock() - wall0, self.counts)
        return OutputBatch(stamps, pose, wrenches, reports)

    def _to_foundation(self, batch: SampleBatch) -> tuple[np.ndarray, np.ndarray]:
        """Specific force (m/s²) and Ω (rad/s) in F, per sample."""
        rot = self.model.sensor_rotation
        f = batch.accel @ rot.T
        if not self.scene.input.includes_gravity:
            f = f + self._gravity_up
        return f, batch.gyro @ rot.T

    def _runs(self, batch: SampleBatch, f: np.ndarray, w: np.ndarray) -> list[_Run]:
        """Classify each sample; group the accepted ones into runs split at restarts."""
        spec = self.scene.input
        finite = (
            np.isfinite(batch.stamps) & np.isfinite(f).all(axis=1) & np.isfinite(w).all(axis=1)
        )
        runs: list[_Run] = []
        last_t = self._last[0] if self._last is not None else None
        for i in range(len(batch)):
            self.counts["received"] += 1
            t = float(batch.stamps[i])
            if not finite[i]:
                verdict = "non_finite"
            elif spec.frame_id and batch.frame_ids[i] != spec.frame_id:
                verdict = "wrong_frame"
            elif last_t is None:
                verdict = RESTART
            elif t == last_t:
                verdict = "duplicate_stamp"
            elif t < last_t - spec.back_jump_reset_s:
                self.counts["reset_stamp_jumped_back"] += 1
                verdict = RESTART
            elif t < last_t:
                verdict = "stamp_went_back"
            elif t - last_t > spec.max_gap_s:
                self.counts["gaps"] += 1
                verdict = RESTART if spec.gap_policy == "reset" else ACCEPT
            else:
                verdict = ACCEPT
            if verdict not in (ACCEPT, RESTART):
                self.counts[f"rejected_{verdict}"] += 1
                continue
            self.counts["accepted"] += 1
            last_t = t
            if verdict == RESTART or not runs:
                runs.append(_Run([i], verdict == RESTART))
            else:
                runs[-1].index.append(i)
        return runs

    def _integrate(
        self, run: _Run, stamps: np.ndarray, f: np.ndarray, w: np.ndarray
    ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Integrate one run; on a stepper failure restart at the next sample."""
        out = []
        index = run.index
        if run.restart or self._last is None:
            out.append(self._start(index[0], stamps, f, w))
            index = index[1:]
        while index:
            t0, f0, w0 = self._last  # type: ignore[misc]
            t = np.concatenate([[t0], stamps[index]])
            ff = np.vstack([f0, f[index]])
            ww = np.vstack([w0, w[index]])
            n, nm = t.shape[0], self.model.n_mounts
            pose, wrenches = np.zeros((n, 10)), np.zeros((n, nm, 6))
            publish, step_log = np.zeros(n, dtype=np.bool_), np.zeros((n, 3))
            st = self.stepper
            done, status = run_samples(
                st.method,
                st.settings,
                st.work2d,
                st.work1d,
                st.result,
                self.model.arrays,
                self._scratch,
                self._u,
                self._y,
                t,
                ff,
                ww,
                self.scene.input.hold == "zero_order",
                self.scene.outputs.decimation,
                self._counter,
                self._peak,
                pose,
                wrenches,
                publish,
                step_log,
            )
            self.health.add_steps(step_log[1 : done + 1])
            if done > 0:
                self._last = (float(t[done]), ff[done], ww[done])
            keep = np.flatnonzero(publish[: done + 1])
            out.append((t[keep], pose[keep], wrenches[keep]))
            if status == 0:
                break
            self.counts["integration_failures"] += 1
            self.health.failure(float(t[done + 1]), STATUS_TEXT.get(status, f"status {status}"))
            self._last = None
            rest = index[done + 1 :]
            if not rest:
                break
            out.append(self._start(rest[0], stamps, f, w))
            index = rest[1:]
        return out

    def _start(
        self, i: int, stamps: np.ndarray, f: np.ndarray, w: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Re)start the twin at sample i; its outputs are published."""
        init = self.scene.initial
        gravity = f[i] if init.gravity == "first_sample" else self._gravity_up
        if self._last is not None or self.counts["starts"]:
            self.counts["restarts"] += 1
        self.counts["starts"] += 1
        self._y = initial_state(self.model, gravity)
        self.stepper.reset()
        self._peak[:] = 0.0
        self._counter[0] = 0
        self._last = (float(stamps[i]), f[i].copy(), w[i].copy())
        pose, wrenches = np.zeros((1, 10)), np.zeros((1, self.model.n_mounts, 6))
        ct = evaluate(self._y, self.model.arrays, self._scratch, pose[0], wrenches[0])
        if not math.isfinite(ct):
            msg = f"{self.scene.source}: initial_state.pose is off the α/γ/δ chart"
            raise ValueError(msg)
        return np.array([stamps[i]]), pose, wrenches
