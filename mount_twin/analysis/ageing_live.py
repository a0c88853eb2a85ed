"""Mounts that age, live: the deck and body IMU streams cut into windows of `ageing.window_s`
of body stamps, each re-fitted (`ageing.fit_window`) once both streams have passed its end, and
judged against the scene's `ageing` bands as a `mount_twin: ageing` diagnostics status.

The windows are `track`'s: from the first body sample's stamp plus `ageing.LEAD_S`, the deck's
record taken from `LEAD_S` before each window's start. A window is cut by stamps alone, so
its fit is the same live and in a replay; a fit takes seconds, so the node runs the jobs
(`WindowJob`, `run_job`) in a worker process and publishes each report when it is done,
stamped with the window's last body stamp.

Where the stamps jump back by more than input.back_jump_reset_s (a bag played with --loop, a
recorder's clock set back), the twin restarts, and so does the tracker: each stream's n-th
run is paired with the other's, the window open at the jump is fitted (up to the last sample
both streams have in the run, known once one stream has left it and the other has reached
that stamp) if it spans half a window, else dropped and counted, and the windows start again
from the new run's first body sample plus the lead; a stream's samples of a run the tracker
is done with (the other stream jumped back, it did not) are not kept. Where the other stream
never jumps back with it (`stamp_runs.Apart`: its stamps went on past the jump by more than
back_jump_reset_s), the runs never pair again: once the run is done, a WARN says which stream
jumped back and when (a `WindowJob` with `apart`), and no sample of a later run is kept. Each
report says the jumps before its window and the windows dropped so far (`run_job`).

The samples that pair with no sample of the other stream (`AgeingTracker.counts`: a stream's
samples of a run past the last stamp the other has in it, and those of a run after the streams
went apart) are counted per stream; the end of the stream (`AgeingTracker.finish`) reports
them, where there are any. Only there: the count of a run is complete once its samples stop
coming, which depends on how the two streams come interleaved, and every report must be the
same live and in a replay.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mount_twin.analysis.ageing import LEAD_S, Band, WindowFit, fit_window
from mount_twin.engine.batch import LEVEL_NAMES, OK, WARN, HealthReport, HealthStatus
from mount_twin.engine.body_counts import RESETS
from mount_twin.engine.stamp_runs import Apart
from mount_twin.io.signals import Signal
from mount_twin.scene.description import Scene

NAME = "mount_twin: ageing"
DROPPED = "windows_dropped_at_jump_back"
"""The count of windows open where the stamps jumped back that held less than half a window
(not fitted), in every report's values beside RESETS (the jumps back before its window)."""
CUT_BY_JUMP = "the last window before the stamps jumped back"
"""How a window cut short by a jump back is said."""
UNPAIRED = ("deck_samples_unpaired", "body_samples_unpaired")
"""The counts of the deck's and of the body IMU's samples that paired with no sample of the
other stream (`AgeingTracker.counts`), in the end of the stream's report and a replay's
summary."""


@dataclass(frozen=True)
class WindowJob:
    """One window to re-fit: the scene (with its `ageing`), the (foundation, body) records
    (s on the twin's time base), the window's span (s) and its last body stamp (ns); the
    stamps' jumps back before it (the tracker restarted at each), the windows dropped so far
    (open at a jump, too short to fit), and whether it is one cut short by a jump."""

    scene: Scene
    records: tuple[Signal, Signal]
    span: tuple[float, float]
    stamp_ns: int
    restarts: int = 0
    dropped: int = 0
    cut: bool = False
    apart: str = ""
    """Not a window: the streams' stamps jumped back apart (`Apart`), said as a WARN."""
    unpaired: tuple[int, int] | None = None
    """Not a window: the end of the stream, the samples of the deck and of the body IMU
    that paired with no sample of the other stream (`UNPAIRED`); said with `apart` (a WARN)
    where the streams jumped back apart, else at OK."""


def _status(fit: WindowFit) -> HealthStatus:
    """A window's fit as a diagnostics status."""
    shown = ", ".join(f"{n} ×{v:.3f} ± {fit.sigma[n]:.2g}" for n, v in fit.values.items())
    span = f"{fit.start_s:.1f}–{fit.end_s:.1f} s"
    message = f"{span}: {shown or 'nothing identified'}" + (f" — {fit.why}" if fit.why else "")
    if fit.refused:
        message += "; not identified: " + ", ".join(fit.refused)
    values = {"window_start_s": f"{fit.start_s:.3f}", "window_end_s": f"{fit.end_s:.3f}"}
    for name, value in fit.values.items():
        values[name] = f"{value:.4f}"
        values[f"{name}_sigma"] = f"{fit.sigma[name]:.3g}"
    values.update({f"{name}_refused": why for name, why in fit.refused.items()})
    return HealthStatus(NAME, LEVEL_NAMES.index(fit.level), message, values)


def run_job(job: WindowJob) -> HealthReport:
    """The window's fit as a diagnostics report (a plain function of plain data: it runs in a
    worker process live). A window the twin cannot follow is a WARN saying why. Its values
    say the stamps' jumps back before the window (RESETS) and the windows dropped at them so
    far (DROPPED), its message too where not 0; the end of the stream's, the samples that
    paired with none of the other stream's (UNPAIRED)."""
    ageing = job.scene.ageing
    assert ageing is not None
    band = Band(ageing.warn, ageing.error)
    try:
        if job.unpaired is not None:
            status = _unpaired_status(job.unpaired, job.apart)
        elif job.apart:
            status = HealthStatus(NAME, WARN, job.apart, {})
        else:
            status = _status(fit_window(job.scene, job.records, job.span, ageing.fit, band))
    except ValueError as err:
        span = f"{job.span[0]:.1f}–{job.span[1]:.1f} s"
        status = HealthStatus(NAME, WARN, f"{span}: not fitted: {err}", {})
    if job.cut:
        status.message += f" ({CUT_BY_JUMP})"
    if job.restarts:
        status.message += (
            f"; the stamps jumped back {job.restarts}× before it, the tracker restarted"
        )
    if job.dropped:
        status.message += (
            f"; {job.dropped} window(s) open at a jump held less than half a window: not fitted"
        )
    status.values.update({RESETS: str(job.restarts), DROPPED: str(job.dropped)})
    return HealthReport(job.stamp_ns * 1e-9, -1, [status])


_NONE = Signal(np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3)))
_NO_RECORDS = (_NONE, _NONE)
"""The records of a job that is not a window (`WindowJob.apart`, `unpaired`)."""


def _unpaired_status(unpaired: tuple[int, int], apart: str) -> HealthStatus:
    """The end of the stream's report: the deck's and the body's samples that paired with
    none of the other stream's (`apart`: where the streams jumped back apart, said, WARN)."""
    deck, body = unpaired
    message = (
        f"at the end of the stream: {deck} deck and {body} body IMU samples paired with no "
        "sample of the other stream (one stream's stamps jumped back, the other's not): "
        "not fitted"
    )
    if apart:
        message += f"; {apart}"
    values = {key: str(n) for key, n in zip(UNPAIRED, unpaired, strict=True)}
    return HealthStatus(NAME, WARN if apart else OK, message, values)


class _Run:
    """A stream's samples of one run (stamps ns and s, accel, gyro), its oldest part dropped
    as it goes."""

    def __init__(self) -> None:
        self.parts: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self.first_t: float | None = None
        self.last_t = -math.inf

    def add(self, ns: np.ndarray, t: np.ndarray, accel: np.ndarray, gyro: np.ndarray) -> None:
        if t.shape[0]:
            self.parts.append((ns, t, accel, gyro))
            self.first_t = float(t[0]) if self.first_t is None else self.first_t
            self.last_t = float(t[-1])

    def after(self, t: float) -> int:
        """How many of its samples are stamped after `t` (s)."""
        return sum(int((p[1] > t).sum()) for p in self.parts)

    def cut(self, start: float, end: float) -> tuple[Signal, int]:
        """The samples in [start, end) and the last one's stamp (ns); those before `start`
        dropped for good."""
        ns, t, accel, gyro = (np.concatenate(a) for a in zip(*self.parts, strict=True))
        self.parts = [(ns[t >= start], t[t >= start], accel[t >= start], gyro[t >= start])]
        keep = (t >= start) & (t < end)
        last = int(ns[keep][-1]) if keep.any() else 0
        return Signal(t[keep], accel[keep], gyro[keep]), last


class _Record:
    """A stream's samples, by run: a stamp before the last one added starts a new run (the
    stream gives rising stamps but where they jump back by more than input.back_jump_reset_s,
    `stamp_verdicts.rising_or_back`: a bag played with --loop)."""

    def __init__(self) -> None:
        self.runs: dict[int, _Run] = {}
        self.run = 0
        """The run of the last sample added."""
        self.floor = 0
        """The first run kept (the tracker is done with those before)."""
        self.ceiling: int | None = None
        """The last run kept (None: all; the streams jumped back apart after it)."""
        self.unpaired = 0
        """Samples that pair with none of the other stream's, not kept: of runs before the
        floor, after the ceiling, or past the other stream's last stamp in their run
        (`AgeingTracker`)."""
        self.last_ns = 0
        """The stamp of the last sample added, ns."""

    def add(
        self,
        ns: np.ndarray,
        t: np.ndarray,
        accel: np.ndarray,
        gyro: np.ndarray,
        use: np.ndarray | None = None,
    ) -> None:
        """Samples (stamps ns and s, accel, gyro); of them, those `use` marks kept (all where
        None; the others only tell where a run starts)."""
        if not ns.shape[0]:
            return
        run = self.run + np.cumsum(ns < np.concatenate([[self.last_ns], ns[:-1]]))
        self.run, self.last_ns = int(run[-1]), int(ns[-1])
        if use is not None:
            ns, t, accel, gyro, run = ns[use], t[use], accel[use], gyro[use], run[use]
        unpaired = run < self.floor
        if self.ceiling is not None:
            unpaired |= run > self.ceiling
        self.unpaired += int(unpaired.sum())
        for r in np.unique(run[~unpaired]).tolist():
            k = run == r
            self.runs.setdefault(r, _Run()).add(ns[k], t[k], accel[k], gyro[k])

    def close_after(self, run: int) -> None:
        """Keep no sample of a run after `run`: those held dropped, counted `unpaired`."""
        self.ceiling = run
        for r in [r for r in self.runs if r > run]:
            self.unpaired += sum(p[0].shape[0] for p in self.runs.pop(r).parts)

    def of(self, run: int) -> _Run:
        """The samples of `run` (none yet: empty)."""
        return self.runs.setdefault(run, _Run())


class AgeingTracker:
    """The windows of the deck and body IMU streams, due once both pass their end; where the
    stamps jump back (each stream's n-th run paired with the other's n-th), the window open is
    fitted, up to the last sample both streams have in the run, once that is known (a stream
    has left the run, and the other reached its last stamp there), if it spans half a window,
    else dropped (counted); the windows start again from the new run's first body sample."""

    def __init__(self, scene: Scene) -> None:
        assert scene.ageing is not None
        self.scene = scene
        self._window_s = scene.ageing.window_s
        self._foundation, self._body = _Record(), _Record()
        self._run = 0
        """The run the windows are in."""
        self._start: float | None = None
        self.dropped = 0
        """Windows open at a jump back, too short to fit."""
        sensor = scene.body_sensor
        self._apart = Apart(scene.input.back_jump_reset_s, 0.0 if sensor is None else sensor.lag_s)
        self._origin_ns: int | None = None
        """The twin's time base's origin, ns (stamp ns − its seconds)."""

    @property
    def counts(self) -> dict[str, int]:
        """The stamps' jumps back the tracker restarted at (RESETS), the windows dropped at
        them (DROPPED), and the samples of the deck and of the body IMU that paired with no
        sample of the other stream (UNPAIRED): a stream's samples of a run stamped after the
        other's last sample in it (one stream jumped back, the other not yet or never), and
        every sample of a run after the streams jumped back apart."""
        deck, body = UNPAIRED
        return {
            RESETS: self._run,
            DROPPED: self.dropped,
            deck: self._foundation.unpaired,
            body: self._body.unpaired,
        }

    def finish(self) -> list[WindowJob]:
        """The end of both streams: where samples paired with none of the other stream's, a
        report saying how many (with the streams' jumping back apart, where they did), as a
        job; the last, partial window is not fitted."""
        unpaired = (self._foundation.unpaired, self._body.unpaired)
        if not sum(unpaired) or self._origin_ns is None:
            return []
        stamp_ns = max(self._foundation.last_ns, self._body.last_ns)
        end = (stamp_ns - self._origin_ns) * 1e-9
        apart = "" if self._apart.found is None else self._apart_message()
        return [
            WindowJob(
                self.scene,
                _NO_RECORDS,
                (end, end),
                stamp_ns,
                self._run,
                self.dropped,
                apart=apart,
                unpaired=unpaired,
            )
        ]

    def add_foundation(
        self, ns: np.ndarray, t: np.ndarray, accel: np.ndarray, gyro: np.ndarray
    ) -> list[WindowJob]:
        """Deck samples (stamps ns and s, sensor-frame accel m/s², gyro rad/s); the windows
        they complete."""
        self._apart.add("deck", t)
        self._foundation.add(ns, t, accel, gyro)
        return self._due(ns, t)

    def add_body(
        self,
        ns: np.ndarray,
        t: np.ndarray,
        accel: np.ndarray,
        gyro: np.ndarray,
        use: np.ndarray | None = None,
    ) -> list[WindowJob]:
        """Body IMU samples, as `add_foundation`'s; of them, those `use` marks fitted (all
        where None: the others, whose specific force is not provided, only tell where a run
        starts)."""
        self._apart.add("body", t)
        self._body.add(ns, t, accel, gyro, use)
        return self._due(ns, t)

    def _due(self, ns: np.ndarray, t: np.ndarray) -> list[WindowJob]:
        """The windows due, after samples stamped `ns`, `t` (s) came."""
        if self._origin_ns is None and ns.shape[0]:
            self._origin_ns = int(ns[0]) - round(float(t[0]) * 1e9)
        jobs = []
        while True:
            found = self._apart.found
            if found is not None and self._run > found[1] and self._body.ceiling is None:
                jobs.append(self._apart_job())
            if self._body.ceiling is not None:
                return jobs
            foundation, body = self._foundation.of(self._run), self._body.of(self._run)
            if self._start is None and body.first_t is not None:
                self._start = body.first_t + LEAD_S
            while (
                self._start is not None
                and min(foundation.last_t, body.last_t) >= self._start + self._window_s
            ):
                start, end = self._start, self._start + self._window_s
                self._start = end
                jobs += self._job(foundation, body, (start, end))
            records = ((self._foundation, foundation), (self._body, body))
            ended = [run.last_t for record, run in records if record.run > self._run]
            stop = min(foundation.last_t, body.last_t)
            if not ended or stop < min(ended):
                return jobs  # the run goes on in both streams, or in one behind the other
            if self._start is not None and stop > self._start:  # a window open at the jump
                if stop - self._start >= 0.5 * self._window_s:
                    jobs += self._job(foundation, body, (self._start, stop), cut=True)
                else:
                    self.dropped += 1
            self._run, self._start = self._run + 1, None
            for record, run in records:  # its samples past the other's last: unpaired
                record.unpaired += run.after(stop)
                record.runs.pop(self._run - 1)
                record.floor = self._run

    def _apart_job(self) -> WindowJob:
        """The streams jumped back apart and the run they paired last is done: nothing after
        it is kept (counted, `counts`); the WARN saying so, as a job."""
        assert self._apart.found is not None and self._origin_ns is not None
        _, run, end = self._apart.found
        for record in (self._foundation, self._body):
            record.close_after(run)
        stamp_ns = self._origin_ns + round(end * 1e9)
        return WindowJob(
            self.scene,
            _NO_RECORDS,
            (end, end),
            stamp_ns,
            run,
            self.dropped,
            apart=self._apart_message(),
        )

    def _apart_message(self) -> str:
        """How the streams jumped back apart, and what became of the tracking."""
        return self._apart.message() + ": not tracked from there on"

    def _job(
        self, foundation: _Run, body: _Run, span: tuple[float, float], cut: bool = False
    ) -> list[WindowJob]:
        """The job of the window `span` (s; `cut`: one cut short, its end the last sample
        both streams have), if both records hold more than 2 samples in it."""
        start, end = span
        stop = math.nextafter(end, math.inf) if cut else end
        deck, _ = foundation.cut(start - LEAD_S, stop)
        measured, stamp_ns = body.cut(start, stop)
        if deck.t.shape[0] <= 2 or measured.t.shape[0] <= 2:
            return []
        return [
            WindowJob(self.scene, (deck, measured), span, stamp_ns, self._run, self.dropped, cut)
        ]
