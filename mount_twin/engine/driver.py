"""The driver of the compiled core: the twin's state and the arrays the core loop works on.

`CoreDriver` holds the state vector, the stepper, the live error estimator, the mount watch
and the decimation state; `begin` puts the twin at a start state, `advance` runs one segment of
samples through `kernel.run_samples` and hands what the core logged (steps, error figures,
mount events) to the health window. Under `integration.method: auto` it makes the method choice
at each start's first interval, from the start state, and looks again after mount events that
may stiffen the scene (`auto_method`). Which samples to run, and what to do at a failure, is the
engine's business.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable
from operator import is_not
from typing import Any, NamedTuple

import numpy as np

from mount_twin.engine import companion, estimator
from mount_twin.engine.auto_method import (
    REEXAMINE_S,
    Choice,
    after_event,
    at_start,
)
from mount_twin.engine.batch import MountEvent
from mount_twin.engine.companion import Companion, new_companion
from mount_twin.engine.estimator import Estimator, new_estimator
from mount_twin.engine.health import HealthWindow
from mount_twin.engine.kernel import (
    Integrator,
    Loop,
    Published,
    RunOptions,
    Samples,
    close_estimate,
    new_watch,
    run_samples,
)
from mount_twin.engine.rows import BatchRows, Rows
from mount_twin.integrate.methods import AUTO
from mount_twin.integrate.stepper import new_stepper, switch
from mount_twin.kinds import COMPANION_TREATMENTS, KINDS, N_EVENTS
from mount_twin.model.assemble import Model
from mount_twin.physics import pose_row
from mount_twin.physics.dynamics import (
    INPUT_SIZE,
    evaluate,
    linear_utilisation,
    mount_monitors,
)

MAX_EVENTS = 100_000
"""Mount events kept in CoreDriver.events (later ones are counted only)."""


class Stepped(NamedTuple):
    """What one `CoreDriver.advance` did.

    done: index of the last sample of the segment done (0: none).
    status: 0 when all were done; `kernel.AT_EVENT` when the segment ended at sample `done`
        for `auto` to look again; else the stepper's failure at sample done + 1.
    rows: the published rows (views of the push's rows where the samples are consecutive).
    events: the mount events logged (those the core's log could hold).
    """

    done: int
    status: int
    rows: Rows
    events: list[MountEvent]


def published_buffers(
    n: int,
    counter: np.ndarray,
    peak: np.ndarray,
    linear_util: np.ndarray,
    rows: tuple[np.ndarray, np.ndarray] | None = None,
) -> Published:
    """Output buffers for a run of n rows, with the decimation state to carry (`counter`, the
    (n_mounts, 6) `peak`) and the linear mounts' utilisation to fold into; `rows`: the pose and
    wrench rows to write into (`BatchRows.of_run`), else new ones."""
    nm = peak.shape[0]
    pose, wrenches = rows or (np.empty((n, pose_row.WIDTH)), np.empty((n, nm, 6)))
    return Published(
        counter,
        peak,
        pose,
        wrenches,
        np.zeros(n, dtype=np.bool_),
        np.zeros((n, 3)),
        np.zeros((nm, 6)),
        np.ones(1),
        linear_util,
    )


def event_table(model: Model, name: str, code: Callable[[Any], float] = float) -> np.ndarray:
    """(non-linear mounts, N_EVENTS), in the core's order: each mount's kind's event table
    `name`, each entry as `code` gives it (a flag: 1.0 where true; 0 past its kind's events)."""
    slots = model.nonlinear_slots
    table = np.zeros((len(slots), N_EVENTS))
    for i, slot in enumerate(slots):
        kind = KINDS[model.scene.mounts[slot].kind]
        table[i, : len(kind.EVENTS)] = [code(v) for v in getattr(kind, name)]
    return table


def _new_estimator(model: Model, treatments: np.ndarray) -> Estimator | Companion | None:
    """The live error estimate's arrays (`engine.estimator` where the mounts are linear,
    `engine.companion` where some are not: see there), or None if the scene turns it off.
    `treatments`: (non-linear mounts, N_EVENTS), how the companion takes an interval that
    starts with the event holding (the core's code, COMPANION_TREATMENTS, of its kind's
    EVENT_COMPANION), the shape of the mount watch's event functions."""
    integ = model.scene.integration
    if not integ.error_estimate:
        return None
    arrays = model.arrays
    if arrays.nl is not None:
        return new_companion(
            integ.method,
            model.n_state,
            integ.rtol,
            integ.atol,
            integ.max_substeps,
            model.new_scratch(),
            model.n_mounts,
            treatments,
            model.tangent_rate,
            linear_stiffness=model.linear_stiffness,
            kinked=model.kinked,
        )
    return sampled_estimator(model)


def sampled_estimator(model: Model) -> Estimator:
    """The sampled estimate's arrays for `model` as its scene configures it (`engine.estimator`:
    the one for linear mounts; on non-linear ones `bench/error_estimate.py --sampled` measures
    it against the companion)."""
    integ, arrays = model.scene.integration, model.arrays
    return new_estimator(
        integ.method,
        integ.rtol,
        integ.atol,
        integ.max_substeps,
        model.new_scratch(),
        arrays.free_trans.shape[0] + arrays.free_rot.shape[0],
        model.n_mounts,
    )


class CoreDriver:
    """The twin's state and the core's arrays, for one model.

    Args:
        model: the assembled scene.
        health: the health window, where steps, error figures and mount events go.
        counts: the engine's counters (substeps, method_switches, mount_events, ...).
    """

    def __init__(self, model: Model, health: HealthWindow, counts: Counter[str]) -> None:
        scene = model.scene
        integ = scene.integration
        self.model = model
        self._health = health
        self._counts = counts
        self.stepper = new_stepper(
            integ.method, model.n_state, integ.rtol, integ.atol, integ.max_substeps
        )
        self._integ = self._integrator()
        self._scratch = model.new_scratch()
        self._u = np.zeros(INPUT_SIZE)
        self.y = np.zeros(model.n_state)
        """The state vector (names in `model.state_names`)."""
        self._peak = np.zeros((model.n_mounts, 6))
        self._counter = np.zeros(1, dtype=np.int64)
        self._tail_pose = np.zeros(pose_row.WIDTH)
        """The pose row of the last sample done, where decimation left it unpublished."""
        self.last: tuple[float, np.ndarray, np.ndarray] | None = None
        """(stamp s, f m/s², Ω rad/s in F) of the last sample done; None: not started."""
        self._event_meta = {
            slot: (scene.mounts[slot].name, KINDS[scene.mounts[slot].kind])
            for slot in model.nonlinear_slots
        }
        nl = model.arrays.nl
        self._own_states = [
            slice(int(o), int(o) + len(kind.state_names(scene.mounts[slot])))
            for o, (slot, (_, kind)) in zip(
                [] if nl is None else nl.state.tolist(), self._event_meta.items(), strict=True
            )
        ]
        """Each non-linear mount's internal states in y, in the core's order (empty: none)."""
        self._watch = new_watch(
            len(model.nonlinear_slots),
            N_EVENTS,
            model.n_state,
            event_table(model, "EVENT_STIFFENS"),
        )
        self.events: list[MountEvent] = []
        """Every mount event so far, in time order (the first MAX_EVENTS; the rest counted)."""
        lin_slots = model.arrays.lin_slot.tolist()
        self._lin_rated = np.flatnonzero(model.arrays.lin_per_rating.any(axis=1))
        """The rated linear mounts, as indices among the linear ones (the core's order)."""
        self.rated = np.array(
            [*model.nonlinear_slots, *(lin_slots[i] for i in self._lin_rated)], dtype=np.int64
        )
        """Mounts with a utilisation: the non-linear ones (their watch), then rated linear ones."""
        self._linear_util = np.zeros(len(lin_slots))
        """Every linear mount's peak utilisation since the window's last report (the core
        folds it in at every sample; unrated ones stay 0)."""
        self._util_max = np.zeros(self.rated.shape[0])
        # Chaining the stepper's last stage into the next interval needs a continuous input
        # (first-order hold); a discrete switch of the state between samples (a bolt breaking)
        # clears the flag in the compiled loop.
        self._options = RunOptions(
            scene.input.hold == "zero_order",
            scene.outputs.decimation,
            scene.input.hold == "first_order",
        )
        treatments = event_table(model, "EVENT_COMPANION", COMPANION_TREATMENTS.__getitem__)
        self.estimator = _new_estimator(model, treatments)
        self._loop: tuple[tuple[object, ...], Loop] | None = None
        """The arrays bound last, and their `Loop` (`_bound`)."""
        self._auto = integ.method == AUTO
        self._start_due = False
        """`auto` chooses at the first interval of the start just made (`choose_at_start`)."""
        self._chosen = False
        """`auto` has chosen before: a change is a switch (counted)."""

    def _integrator(self) -> Integrator:
        """The stepper's arrays as the core takes them."""
        st = self.stepper
        return Integrator(st.method, st.settings, st.work2d, st.work1d, st.result)

    def begin(
        self, y: np.ndarray, stamp: float, f: np.ndarray, w: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Put the twin at state y at sample `stamp` (s) under specific force f (m/s², F) and
        Ω w (rad/s, F): the stepper's history, the decimation and the error estimate start
        anew; under `auto` the method is chosen at the first interval (`choose_at_start`), and
        the next mount event that may stiffen the scene prompts a look however soon after the
        last one on the record (the stamps may have gone back). Returns the start's outputs:
        its pose row and (n_mounts, 6) wrenches."""
        if self._counter[0]:
            msg = "a run ends with its last sample published: close_run before begin"
            raise RuntimeError(msg)
        self.y = y
        self.stepper.reset()
        self._peak[:] = 0.0
        self.last = (stamp, f.copy(), w.copy())
        if self._auto:
            self._start_due = True
            self._watch.stop_after[0] = -math.inf
        outputs = self._start_outputs(stamp)
        if isinstance(self.estimator, Estimator):
            estimator.restart(self.estimator)
        elif self.estimator is not None:
            companion.restart(self.estimator, self.y)
        return outputs

    def _start_outputs(self, stamp: float) -> tuple[np.ndarray, np.ndarray]:
        """Outputs (pose row, wrenches) of the state at `stamp` (s); arms the mount monitors
        there and folds its utilisation into the window's (a start is published: a run that
        fails at its first interval still shows the load it started under). A discrete switch
        the start's monitors make (a bolt past its ultimate force breaks) is that mount's
        event at the start (`_log_start_switches`)."""
        model, y = self.model, self.y
        pose, wrenches = np.zeros(pose_row.WIDTH), np.zeros((model.n_mounts, 6))
        ct = evaluate(y, model.arrays, self._scratch, pose, wrenches)
        if not math.isfinite(ct):
            msg = f"{model.scene.source}: initial_state.pose is off the α/γ/δ chart"
            raise ValueError(msg)
        linear_utilisation(y, model.arrays, self._scratch, wrenches, self._linear_util)
        nl = model.arrays.nl
        if nl is not None:
            watch = self._watch
            watch.y_prev[:] = y
            if mount_monitors(y, y, nl, self._scratch, watch.g_prev, watch.util):
                self._log_start_switches(watch.y_prev, stamp, wrenches)
            np.maximum(watch.util_peak, watch.util, out=watch.util_peak)
        return pose, wrenches

    def _log_start_switches(self, before: np.ndarray, stamp: float, wrenches: np.ndarray) -> None:
        """Log the discrete switches the start's monitors just made, from state `before` to
        `self.y`, as the loop logs an event: at the start's `stamp` (s), with the mount's force
        magnitude at the start (`wrenches`, before the switch: the load it switched under).

        In the loop a switch is seen as its event function crossing 0 since the sample before;
        a start has no sample before, and its monitors leave the function past 0 in g_prev, so
        no crossing would ever show it. What a start reports is only what switched there: the
        mounts whose internal states the switch changed, under each event of its kind that is
        a switch (`EVENT_SWITCHES`) and holds. Conditions merely holding at the start (a key
        bearing, a joint open under preload, a bolt past its yield) are states, not events; a
        mount whose damage a restart kept (a bolt broken before) does not switch again."""
        watch, y = self._watch, self.y
        for i, (slot, (_, kind)) in enumerate(self._event_meta.items()):
            own = self._own_states[i]
            if np.array_equal(y[own], before[own]):
                continue
            for e, is_switch in enumerate(kind.EVENT_SWITCHES):
                if not (is_switch and watch.g_prev[i, e] >= 0.0):
                    continue
                k = int(watch.n_events[0])
                watch.n_events[0] += 1
                if k < watch.events.shape[0]:
                    r0, r1, r2 = wrenches[slot, :3].tolist()
                    force = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2)  # as the core's log takes it
                    watch.events[k] = (stamp, slot, e, force)
        self._drain_events()

    def _bound(self) -> Loop:
        """The core's loop over the arrays now held: the one bound before, unless one of them
        was replaced since (a start's y; a method switch's stepper and estimate)."""
        arrays = (
            self._integ,
            self.model.arrays,
            self._scratch,
            self._u,
            self.y,
            self._options,
            self._watch,
            self.estimator,
        )
        bound = self._loop
        if bound is None or any(map(is_not, arrays, bound[0])):
            self._loop = bound = (arrays, Loop(*arrays))
        return bound[1]

    def choose_at_start(self, stamp: float) -> None:
        """`auto`'s choice at a start (the first, or a restart: `begin`), at the interval from
        it into the sample at `stamp` (s), from the start state under the start sample's
        specific force; nothing where no start awaits its choice."""
        if self._start_due and self.last is not None:
            self._start_due = False
            start, f, _ = self.last
            choice = at_start(self.model, self.y, f, stamp - start, restart=self._chosen)
            self._use(choice)

    def advance(self, segment: Samples, index: np.ndarray, rows: BatchRows) -> Stepped:
        """Integrate through the samples of `segment` (row 0: the last one done), which are
        the push's samples `index`, publishing into `rows` where they are consecutive."""
        buf = published_buffers(
            len(segment.t), self._counter, self._peak, self._linear_util, rows.of_run(index)
        )
        done, status = run_samples(self._bound(), segment, buf)
        events = self._drain_events()
        self._counts["substeps"] += self._health.add_steps(buf.step_log[1 : done + 1])
        self._take_figures()
        if done > 0:
            # copies: the segment's rows may be the push's frame, which a later push reuses
            self.last = (float(segment.t[done]), segment.f[done].copy(), segment.w[done].copy())
            if self._counter[0]:
                self._tail_pose[:] = buf.pose[done]
        peaks = buf.wrench_abs_max, float(buf.cos_tilt_min[0])
        publish = buf.publish[: done + 1]  # never row 0: the previous sample
        if np.count_nonzero(publish) == done:  # every sample published: views of this run's
            done_rows = slice(1, done + 1)  # buffers
            published = Rows(index[:done], buf.pose[done_rows], buf.wrenches[done_rows], peaks)
        else:
            keep = np.flatnonzero(publish)
            published = Rows(index[keep - 1], buf.pose[keep], buf.wrenches[keep], peaks)
        return Stepped(done, status, published, events)

    def _take_figures(self) -> None:
        """The error estimate's figures since the last take into the health window (running
        maxima: the core's start again from nothing)."""
        if self.estimator is not None:
            self._health.add_estimate(self.estimator.figures)
            self.estimator.figures[:] = 0.0

    @property
    def tail_pending(self) -> bool:
        """Whether the last sample done is unpublished (decimation): `close_run` gives it."""
        return bool(self._counter[0])

    def close_run(self) -> tuple[np.ndarray, np.ndarray] | None:
        """End the run (a restart follows, or the stream ends): the outputs of its last sample
        done where decimation left it unpublished, its pose row (1, WIDTH) and as wrenches
        (1, n_mounts, 6) each component's largest magnitude since the row before; None where
        that sample was published. Decimation then counts afresh. The sampled estimate folds
        the outputs' errors its stride left unfolded into the figures (`kernel.close_estimate`)."""
        if isinstance(self.estimator, Estimator):
            close_estimate(self._bound())
            self._take_figures()
        if not self._counter[0]:
            return None
        pose, wrenches = self._tail_pose[None].copy(), self._peak[None].copy()
        self._peak[:] = 0.0
        self._counter[0] = 0
        return pose, wrenches

    def look_again(self, segment: Samples, j: int, events: list[MountEvent]) -> None:
        """`auto` at sample j of the segment just ended, which logged `events`, one of which
        may stiffen the scene (`auto_method`)."""
        t, f = segment.t, segment.f
        self._watch.stop_after[0] = t[j] + REEXAMINE_S
        event = next((e for e in reversed(events) if self.stiffens(e)), events[-1])
        choice = after_event(self.model, self.y, f[j], float(t[j] - t[j - 1]), event)
        if choice is not None:
            self._use(choice)

    def _use(self, choice: Choice) -> None:
        """Run `auto`'s choice from now on: the first, or a change at a restart or after a
        mount event (its step history forgotten; counted)."""
        self._health.method = choice.status
        if self._chosen:
            if choice.method == self.stepper.name:
                return
            self._counts["method_switches"] += 1
        self._chosen = True
        switch(self.stepper, choice.method)
        self._integ = self._integrator()
        if isinstance(self.estimator, Estimator):
            self.estimator = estimator.switch(self.estimator, self.stepper.method)
        elif self.estimator is not None:
            self.estimator = companion.switch(self.estimator, self.stepper.method)

    def stiffens(self, event: MountEvent) -> bool:
        """Whether a mount event may stiffen the scene (its kind's EVENT_STIFFENS)."""
        kind = next(k for name, k in self._event_meta.values() if name == event.mount)
        return bool(kind.EVENT_STIFFENS[kind.EVENTS.index(event.event)])

    def _drain_events(self) -> list[MountEvent]:
        """Move the core's event log into MountEvents (health window and `events`); returns
        the new ones (those the log could hold)."""
        watch = self._watch
        n = int(watch.n_events[0])
        if n == 0:
            return []
        cap = watch.events.shape[0]
        if n > cap:
            self._counts["mount_events_dropped"] += n - cap
        new = []
        for t, slot, e, force in watch.events[: min(n, cap)].tolist():
            name, kind = self._event_meta[int(slot)]
            new.append(MountEvent(t, name, kind.EVENTS[int(e)], force, kind.EVENT_ERROR[int(e)]))
        new.sort(key=lambda event: event.stamp)  # the log is by substep, then mount: in time
        watch.n_events[0] = 0
        self._counts["mount_events"] += len(new)
        room = MAX_EVENTS - len(self.events)
        self.events.extend(new[: max(room, 0)])
        self._health.add_events(new)
        return new

    def active(self) -> dict[str, list[tuple[str, bool]]]:
        """Conditions holding at the last sample, per mount: (event name, is an error)."""
        g = self._watch.g
        out = {}
        for k, slot in enumerate(self.model.nonlinear_slots):
            name, kind = self._event_meta[slot]
            out[name] = [
                (event, error)
                for event, error, value in zip(kind.EVENTS, kind.EVENT_ERROR, g[k], strict=False)
                if value >= 0.0
            ]
        return out

    def window_utilisation(self) -> np.ndarray:
        """Peak utilisation since the window's last end of the mounts in `rated`, in its
        order."""
        return np.concatenate([self._watch.util_peak, self._linear_util[self._lin_rated]])

    def end_window(self) -> None:
        """End the utilisation window: fold its peaks into the run's and start anew."""
        np.maximum(self._util_max, self.window_utilisation(), out=self._util_max)
        self._watch.util_peak[:] = 0.0
        self._linear_util[:] = 0.0

    def utilisation_max(self) -> np.ndarray:
        """Peak utilisation so far of the mounts in `rated`, in its order."""
        return np.maximum(self._util_max, self.window_utilisation())
