"""The integration, attitude and mount statuses of a health window's report, judged and worded
from the figures the window gathered (`health.HealthWindow`, which builds its report through
them); the input status, and the limits it is judged against, are `input_status`'s."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable

import numpy as np

from mount_twin.engine.batch import ERROR, OK, WARN, HealthStatus, MountEvent
from mount_twin.engine.estimate import FORCE_SCALE, ErrorEstimate
from mount_twin.engine.health_texts import (
    ATTITUDE,
    EVENTS_KEY,
    INTEGRATION,
    MOUNT,
    NEVER_STARTED,
    NO_INTERVAL_RUN,
    NOT_COMPUTED,
    NOT_COMPUTED_HERE,
    NOT_PUBLISHED_HERE,
    NOT_RUN,
    NOT_RUN_HERE,
    NOW_KEY,
    PEAK_KEYS,
    TILT_KEY,
    UTILISATION_KEY,
    estimate_warning,
    event_values,
    events_text,
    samples_text,
)
from mount_twin.engine.input_status import InputStatus
from mount_twin.physics.rotations import angle_text


class HealthStatuses(InputStatus):
    """The statuses of a health window's report, built from its figures: a part of
    `health.HealthWindow`, which holds the figures declared here and calls these when a report
    is due (`HealthWindow.report`). The input's status comes from `InputStatus`, the
    integration's, the attitude's and the mounts' from here."""

    method: str
    published: bool
    wall: float
    err_max: float
    estimate: np.ndarray
    estimate_run: np.ndarray
    substeps: int
    samples: int
    intervals_run: int
    tilt_max: float
    failures: list[tuple[float, str]]
    forced: list[tuple[float, str]]
    wrench_peak: np.ndarray
    events: list[MountEvent]
    notes: list[str]
    stopped_at: float | None
    stopped_why: str
    gathering: tuple[int, int] | None
    latency: tuple[int, float] | None
    run_estimate: Callable[[], ErrorEstimate]

    def gathered_text(self) -> str:
        """'3 of the initial_state.gravity_samples 5 gathered toward a start', or '' where no
        start is gathered (`gathering`)."""
        if self.gathering is None:
            return ""
        k, n = self.gathering
        return f"{k} of the initial_state.gravity_samples {n} gathered toward a start"

    def never_started(self, counts: Counter[str]) -> str:
        """Why the twin never started though input samples were accepted ('' if it started,
        or none was accepted: NOT_RUN says that): NEVER_STARTED, the samples accepted and
        those gathered toward the start. Said at the input's end, a run's verdict."""
        n = counts["accepted"]
        if counts["starts"] or not n:
            return ""
        gathered = self.gathered_text()
        return f"{NEVER_STARTED}: {samples_text(n)} accepted{', ' if gathered else ''}{gathered}"

    def _not_computed(self, counts: Counter[str], new: Counter[str]) -> str | None:
        """Why this window computed no motion and no mount load, for the attitude and mount
        statuses (None: it did): it published no row and integrated no input interval. The
        input status carries a stall's ERROR, the integration status a stop's."""
        if self.published or self.samples:
            return None
        if not counts["accepted"]:
            return NOT_COMPUTED
        return f"{NOT_COMPUTED_HERE}: {self._idle_why(new)}"

    def _not_published(self) -> str | None:
        """Why this window, which integrated samples, has no tilt nor peak of its own (None: it
        published rows, the figures' source): `outputs.decimation` published none of them, and
        the peaks since the last row go into the next one (`driver.CoreDriver.close_run`)."""
        if self.published:
            return None
        d = self.scene.outputs.decimation
        return (
            f"{NOT_PUBLISHED_HERE}: {samples_text(self.samples)} integrated, outputs.decimation "
            f"{d} publishes one in {d}; their peak loads go into the next row published"
        )

    def _idle_why(self, new: Counter[str]) -> str:
        """Why this window integrated no input interval where samples were accepted before it
        or in it (`new`: this window's counts): none accepted in it, the twin follows no more,
        a start gathering its samples (`gathered_text`), or the gyro delay still holds them."""
        if not new["accepted"]:
            return "no input sample was accepted in it"
        if self.stopped_at is not None:
            return f"the twin follows no more since {self.origin_s + self.stopped_at:.6f} s"
        return self.gathered_text() or "none of its samples was integrated yet"

    def _integration_status(
        self, counts: Counter[str], new: Counter[str], span: float, ended: bool
    ) -> HealthStatus:
        """The integration status of this window (`span`: the stamp time its input intervals
        cover, s; over its wall time, the real-time factor): stepper failures and
        a stop (ERROR), notes on how the input is taken and an estimated error past
        WARN_FORCE_ERROR_REL (WARN); the solver's settings and figures as values ("n/a" where
        this window integrated no interval). Before any input interval is integrated, NOT_RUN
        or NO_INTERVAL_RUN, NOT_RUN_HERE for a later window that integrated none (`_not_run`);
        at the input's end (`ended`) a twin that never started is an ERROR (`never_started`)."""
        integ = self.scene.integration
        rtf = span / self.wall if self.wall > 0 and span > 0 else math.nan
        level, step_text = self._stepper_status(counts, new, ended)
        estimate = self._estimate_values()
        warning = estimate_warning(self.run_estimate()) if estimate else None
        for note in (*self.notes, warning):
            if note is not None:
                level = max(level, WARN)
                step_text = note + ("" if step_text == "ok" else f"; {step_text}")
        return HealthStatus(
            INTEGRATION,
            level,
            step_text,
            {
                "method": self.method,
                "rtol": f"{integ.rtol:g}",
                "atol": f"{integ.atol:g}",
                **estimate,
                "error_norm_max": f"{self.err_max:.3g}" if self.samples else "n/a",
                "substeps_per_sample": f"{self.substeps / self.samples:.2f}"
                if self.samples
                else "n/a",
                "real_time_factor": f"{rtf:.1f}",
                "failures_total": str(counts["integration_failures"]),
                "method_switches_total": str(counts["method_switches"]),
                "latency_samples": "n/a" if self.latency is None else str(self.latency[0]),
                "latency_s": "n/a" if self.latency is None else f"{self.latency[1]:.6g}",
            },
        )

    def _stepper_status(
        self, counts: Counter[str], new: Counter[str], ended: bool
    ) -> tuple[int, str]:
        """Level and text of the stepper in this window: ERROR with its failures and forced
        starts (stamps in s) or a stop, or a twin that never started by the input's end
        (`ended`), else OK (`_not_run` where this window integrated no interval)."""

        def listed(what: list[tuple[float, str]]) -> str:
            return "; ".join(f"{self.origin_s + t:.6f} s: {m}" for t, m in what)

        said = []
        if self.failures:
            said.append(f"stepper failed and the twin restarted: {listed(self.failures)}")
        if self.forced:
            said.append(f"started away from equilibrium: {listed(self.forced)}")
        if self.stopped_at is not None:
            step_text = (
                f"not following since {self.origin_s + self.stopped_at:.6f} s: "
                f"{self.stopped_why}; no pose, angles or wrenches until a restart (a gap or "
                "the stamps jumping back) finds a state to start from"
                + (f" ({'; '.join(said)})" if said else "")
            )
        elif ended and (never := self.never_started(counts)):
            said.append(never)
            step_text = "; ".join(said)
        else:
            step_text = "; ".join(said) or self._not_run(counts, new) or "ok"
        return (ERROR if said or self.stopped_at is not None else OK), step_text

    def _not_run(self, counts: Counter[str], new: Counter[str]) -> str | None:
        """Why this window integrated no input interval (None: it integrated one): NOT_RUN
        where no input sample was accepted, NO_INTERVAL_RUN where the run integrated none yet
        (one sample, or all gathered toward a start), else NOT_RUN_HERE and why
        (`_idle_why`)."""
        if self.samples:
            return None
        n = counts["accepted"]
        if not n:
            return NOT_RUN
        if not self.intervals_run:
            gathered = self.gathered_text()
            return (
                f"{NO_INTERVAL_RUN} ({samples_text(n)} accepted"
                f"{', ' if gathered else ''}{gathered})"
            )
        return f"{NOT_RUN_HERE}: {self._idle_why(new)}"

    def _attitude_status(self, no_rows: str | None) -> HealthStatus:
        """The attitude status of this window: WARN past `outputs.tilt_warn_rad` of tilt, where
        the α/γ/δ chart degrades; `no_rows` (`_not_computed`, `_not_published`: why it has no
        published row) at OK, tilt "n/a"."""
        if no_rows is not None:
            return HealthStatus(ATTITUDE, OK, no_rows, {TILT_KEY: "n/a"})
        warn = self.scene.outputs.tilt_warn_rad
        return HealthStatus(
            ATTITUDE,
            WARN if self.tilt_max > warn else OK,
            f"tilt {angle_text(self.tilt_max)} past outputs.tilt_warn_rad {warn:.4g}: the α/γ/δ "
            f"chart degrades toward {angle_text(math.pi / 2)}"
            if self.tilt_max > warn
            else "ok",
            {TILT_KEY: f"{self.tilt_max:.6g}"},
        )

    def _estimate_values(self) -> dict[str, str]:
        """The estimated errors of the period and, `_run`, of the run so far as diagnostic
        values (none: the estimate is off).

        The relative force error is the largest |ΔF| (of the period, of the run so far) over
        the largest |F| component of the run so far: the run's figure is the one the replay
        summary gives at the end (`TwinEngine.error_estimate`), and the period's never exceeds
        it."""
        if not self.scene.integration.error_estimate:
            return {}
        period = self.estimate.copy()
        period[FORCE_SCALE] = self.estimate_run[FORCE_SCALE]
        est, run = ErrorEstimate.of(period, self.samples), self.run_estimate()
        return {
            "est_force_error_rel": f"{est.force_error_rel:.2g}",
            "est_force_error_n": f"{est.force_error_n:.3g}",
            "est_attitude_error_rad": f"{est.attitude_error_rad:.2g}",
            "est_failed_checks": str(est.failed_checks),
            "est_uncarried_states": str(est.uncarried_states),
            "est_force_error_rel_run": f"{run.force_error_rel:.2g}",
            "est_force_error_n_run": f"{run.force_error_n:.3g}",
            "est_attitude_error_rad_run": f"{run.attitude_error_rad:.2g}",
        }

    def _mount_statuses(
        self,
        utilisation: np.ndarray,
        active: dict[str, list[tuple[str, bool]]],
        no_rows: str | None,
    ) -> list[HealthStatus]:
        """One status per mount: peak wrench per axis, utilisation (NaN: none), events by
        name, and the conditions holding now; `no_rows` (`_not_computed`, `_not_published`:
        why the window has no published row) said beside them, "ok" aside, the peaks "n/a"
        (the conditions holding keep their level)."""
        warn_at = 1.0 - self.scene.outputs.alarm_margin
        events: dict[str, list[MountEvent]] = {}
        for event in self.events:
            events.setdefault(event.mount, []).append(event)
        out = []
        for mount, u, peak in zip(
            self.scene.mounts, utilisation.tolist(), self.wrench_peak.tolist(), strict=True
        ):
            mine = events.get(mount.name, [])
            now = active.get(mount.name, [])
            if any(e.error for e in mine) or any(err for _, err in now) or u > 1.0:
                level = ERROR
            elif mine or now or u >= warn_at:
                level = WARN
            else:
                level = OK
            values = {
                key: "n/a" if no_rows else f"{v:.6g}"
                for key, v in zip(PEAK_KEYS, peak, strict=True)
            }
            values[UTILISATION_KEY] = "n/a" if math.isnan(u) else f"{u:.6g}"
            values[EVENTS_KEY] = str(len(mine))
            values.update(event_values(mine, self.origin_s))
            values[NOW_KEY] = ", ".join(name for name, _ in now) or "none"
            text = events_text(mine, u, self.origin_s)
            if no_rows:
                text = no_rows if text == "ok" else f"{text}; {no_rows}"
            if now:
                text = f"now: {values[NOW_KEY]}" + ("" if text == "ok" else f"; {text}")
            out.append(HealthStatus(MOUNT + mount.name, level, text, values))
        return out
