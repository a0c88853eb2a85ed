"""The statuses of a health window's report (input, integration, attitude, one per mount),
judged and worded from the figures the window gathered (`health.HealthWindow`, which builds
its report through them), with the limits they are judged against."""

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
    INPUT,
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
    lost_text,
    samples_text,
    seconds_text,
)
from mount_twin.physics.rotations import angle_text
from mount_twin.scene.description import Scene
from mount_twin.scene.reader import shown_text

LOST_ERROR = 0.01
"""Fraction of (accepted + lost) samples lost in a period past which the input is an ERROR."""
NOT_UNUSABLE = ("duplicate_stamp", "wrong_frame")
"""Rejection reasons that are not the sensor's readings unusable: a repeat, another sensor's."""
REJECTED_ERROR = 0.1
"""Fraction of the readings received in a period (`NOT_UNUSABLE` aside) rejected past which
the input is an ERROR: a sensor a tenth of whose readings are unusable is broken (a record 90 %
NaN read WARN, and its replay exited 0 under --fail-on error)."""
SATURATION_SHARE = 0.999
"""A reading at this share of `input.accel_range_m_s2` (or `gyro_range_rad_s`) is saturated."""
PLATEAU_G = 2.0
"""A reading repeated exactly, sample after sample, beyond this many g (`InputSpec.g_scale`) is a
plateau: a clipped or stuck sensor (real vibration never repeats to the last bit)."""
ENDED = math.inf
"""`HealthWindow.report`'s `stalled_s` when the input ended with no sample accepted since the
last report (`TwinEngine.flush`)."""
NAMED_FRAMES = 3
"""Wrong frame_ids named in a message (the rest are counted)."""


class HealthStatuses:
    """The statuses of a health window's report, built from its figures: a part of
    `health.HealthWindow`, which holds the figures declared here and calls these when a report
    is due (`HealthWindow.report`)."""

    scene: Scene
    method: str
    origin_s: int
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
    wrong_frames: dict[str, None]
    wrong_frames_uncounted: bool
    last_wrong_frame_id: str | None
    starts: list[tuple[float, float, float, list[tuple[int, str]]]]
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

    def _input_status(
        self,
        new: Counter[str],
        counts: Counter[str],
        rate_hz: float,
        lost_from_stamps: int,
        nominal_s: float,
        stalled_s: float | None,
    ) -> HealthStatus:
        """The input status of this window: rejections and gaps (WARN; ERROR where the
        readings rejected, duplicates aside, pass REJECTED_ERROR of those received), lost samples
        (WARN, ERROR past LOST_ERROR of the samples due), a stall (ERROR)."""
        new_rejected = {
            k.removeprefix("rejected_"): v
            for k, v in sorted(new.items())
            if k.startswith("rejected_")
        }
        n_rejected = sum(new_rejected.values())
        # Adapter counters (lost_middleware, ...) and stamp holes see the same lost samples (a
        # message lost in DDS leaves a hole in the stamps): the larger figure is the estimate.
        reported = {
            k: v for k, v in sorted(new.items()) if k.startswith("lost_") and k != "lost_estimated"
        }
        lost = max(lost_from_stamps, sum(reported.values()))

        parts: list[str] = []
        level = OK
        all_rejected = False
        if stalled_s is not None:
            level = ERROR
            stall, all_rejected = self._stall_text(new, counts, new_rejected, stalled_s)
            parts.append(stall)
        for stamp, _, _, notes in self.starts:
            for note_level, text in notes:
                level = max(level, note_level)
                parts.append(f"start at {self.origin_s + stamp:.6f} s: {text}")
        if (n_rejected and not all_rejected) or new["gaps"]:
            # readings of the sensor the twin could not use (a duplicate stamp loses none,
            # another sensor's on the topic are not this one's)
            unseen = n_rejected - sum(new_rejected.get(r, 0) for r in NOT_UNUSABLE)
            share = unseen / (new["accepted"] + unseen) if unseen else 0.0
            level = max(level, ERROR if share > REJECTED_ERROR else WARN)
            detail = ""
            if "wrong_frame" in new_rejected:
                detail = f" ({self._reason('wrong_frame', new_rejected['wrong_frame'])})"
            if share > REJECTED_ERROR:
                detail += f", {share:.3g} of the readings"
            parts.append(
                f"{n_rejected} samples rejected{detail}, {new['gaps']} gaps in this period"
            )
        for finding in self._sensor_findings(new):
            level = max(level, WARN)
            parts.append(finding)
        if lost:
            share = lost / (new["accepted"] + lost)
            level = max(level, ERROR if share > LOST_ERROR else WARN)
            parts.append(lost_text(lost, share, lost_from_stamps, nominal_s, reported))
        values = self._input_values(counts, rate_hz, lost, nominal_s, stalled_s)
        return HealthStatus(INPUT, level, "; ".join(parts) or "ok", values)

    def _stall_text(
        self,
        new: Counter[str],
        counts: Counter[str],
        new_rejected: dict[str, int],
        stalled_s: float,
    ) -> tuple[str, bool]:
        """What a stall (`stalled_s`: s since the last report, or ENDED) found in this window,
        and whether every sample received was rejected (`new_rejected`: count per reason);
        `counts`: the run's, to say what came before the window at the stream's end."""
        waited = (
            "by the end of the input" if stalled_s == ENDED else f"for {seconds_text(stalled_s)}"
        )
        if not new["received"]:
            if stalled_s == ENDED and counts["received"]:  # not "over the run": the values
                # say what came before (a stall report took it)
                return (
                    f"no input received since the last report, {waited} ({counts['received']} "
                    f"received before it, {counts['accepted']} accepted)",
                    False,
                )
            return f"no input received {waited}", False
        if not new["accepted"]:
            all_rejected = sum(new_rejected.values()) > 0
            why = ", ".join(self._reason(r, n) for r, n in new_rejected.items())
            text = f"no sample accepted {waited}: {new['received']} received, " + (
                f"all rejected ({why})" if all_rejected else "none accepted"
            )
            return text, all_rejected
        # a stall report comes after a stall period without an accepted sample (the adapter's
        # condition): these came before it; the input stopped or paused (it read "input
        # stalled: only 499 samples accepted in 1.0 s" after the tail of a stream at full rate)
        n = new["accepted"]
        return f"no sample accepted {waited} ({n} before it in this period)", False

    def _sensor_findings(self, new: Counter[str]) -> list[str]:
        """Warnings on the readings of this window: samples at the sensor's range (clipped)
        and readings repeated exactly beyond PLATEAU_G (clipped or stuck)."""
        found = []
        if new["saturated"]:
            spec = self.scene.input
            ranges = " or ".join(
                f"{v:g} {unit}"
                for v, unit in ((spec.accel_range_m_s2, "m/s²"), (spec.gyro_range_rad_s, "rad/s"))
                if v > 0.0
            )
            found.append(
                f"{new['saturated']} samples at the sensor's range ({ranges}): clipped, the true "
                "peaks were higher"
            )
        if new["plateau"]:
            found.append(
                f"{new['plateau']} readings beyond {PLATEAU_G:g} g repeated exactly from the "
                "sample before "
                "(a clipped or stuck sensor?)"
            )
        return found

    def _input_values(
        self,
        counts: Counter[str],
        rate_hz: float,
        lost: int,
        nominal_s: float,
        stalled_s: float | None,
    ) -> dict[str, str]:
        """The input status' values: the topic and the header.frame_id expected there (the
        scene's, or what `replay --topic`, `--frame-id` put in their place: a report names the
        run's), the rate of this window (`_input_rate`), the cumulative counts, the samples
        `lost` in this window at the nominal interval `nominal_s` (s), the time since the last
        report (`stalled_s`, s) and the last start's specific force (m/s²) and tilt (rad)."""
        values = {
            "topic": self.scene.input.topic,
            "frame_id": self.scene.input.frame_id,
            "rate_hz": "n/a" if math.isnan(rate_hz) else f"{rate_hz:.1f}",
            **{k: str(counts[k]) for k in ("received", "accepted", "gaps", "restarts")},
            **{k: str(v) for k, v in sorted(counts.items()) if k.startswith("rejected_")},
            "reset_stamp_jumped_back": str(counts["reset_stamp_jumped_back"]),
            "saturated": str(counts["saturated"]),
            "plateau": str(counts["plateau"]),
            "lost_estimated": str(counts["lost_estimated"]),
            "lost_in_period": str(lost),
            "nominal_interval_s": "n/a" if math.isnan(nominal_s) else f"{nominal_s:.6g}",
            **{
                k: str(v)
                for k, v in sorted(counts.items())
                if k.startswith("lost_") and k != "lost_estimated"
            },
        }
        if counts["rejected_wrong_frame"] and self.last_wrong_frame_id is not None:
            values["last_wrong_frame_id"] = self.last_wrong_frame_id
        if stalled_s is not None and stalled_s != ENDED:
            values["since_last_report_s"] = f"{stalled_s:.6g}"
        if self.starts:
            _, magnitude, tilt, _ = self.starts[-1]
            values["start_specific_force_m_s2"] = f"{magnitude:.6g}"
            values["start_tilt_rad"] = f"{tilt:.6g}"
        return values

    def _reason(self, reason: str, n: int) -> str:
        """'non_finite 3', or for wrong frames "wrong_frame 3: expected frame_id 'a', got 'b'"."""
        if reason != "wrong_frame" or not self.wrong_frames:
            return f"{reason} {n}"
        seen = list(self.wrong_frames)
        got = ", ".join(shown_text(f) for f in seen[:NAMED_FRAMES])  # a hostile one shortened
        if len(seen) > NAMED_FRAMES:
            over = "over " if self.wrong_frames_uncounted else ""
            got += f" and {over}{len(seen) - NAMED_FRAMES} more"
        expected = shown_text(self.scene.input.frame_id)
        return f"{reason} {n}: expected frame_id {expected}, got {got}"
