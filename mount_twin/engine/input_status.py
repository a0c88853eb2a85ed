"""The input status of a health window's report: samples rejected, gaps, samples lost, a
stall, and readings at the sensor's range or repeated exactly, judged against the limits here
(`intake` flags the saturated and plateau readings by two of them); a part of
`health.HealthWindow` through `health_statuses.HealthStatuses`."""

from __future__ import annotations

import math
from collections import Counter

from mount_twin.engine.batch import ERROR, OK, WARN, HealthStatus
from mount_twin.engine.health_texts import INPUT, lost_text, seconds_text
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


class InputStatus:
    """The input status of a health window's report, built from the window's input figures
    declared here (`health.HealthWindow` holds them)."""

    scene: Scene
    origin_s: int
    wrong_frames: dict[str, None]
    wrong_frames_uncounted: bool
    last_wrong_frame_id: str | None
    starts: list[tuple[float, float, float, list[tuple[int, str]]]]

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
