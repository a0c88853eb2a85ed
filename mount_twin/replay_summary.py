"""What a replay did (`ReplaySummary`): its counts, figures, mount events, the body IMU's and
the ageing tracker's counts, the worst diagnostics over the run and the verdict, as the
command's text and as JSON-ready data; and which status of each name is kept as its worst
(`keep_worst`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from mount_twin.analysis.ageing_live import DROPPED, UNPAIRED
from mount_twin.analysis.ageing_live import NAME as AGEING_STATUS
from mount_twin.analysis.figures import (
    DISPLACEMENT,
    PEAK_COUPLE,
    PEAK_FORCE,
    TRAVEL,
    peak_label,
    peak_text,
    utilisation_text,
)
from mount_twin.engine import count_texts
from mount_twin.engine.agreement import FIELDS
from mount_twin.engine.agreement import NAME as BODY_STATUS
from mount_twin.engine.batch import (
    FAILED,
    LEVEL_NAMES,
    OK,
    HealthReport,
    HealthStatus,
    MountEvent,
)
from mount_twin.engine.body_counts import RESETS, UNPROVIDED, not_compared
from mount_twin.engine.estimate import NOT_INTEGRATED, ErrorEstimate
from mount_twin.engine.health_texts import (
    EVENTS_KEY,
    INTEGRATION,
    NOT_DESIGNED,
    NOW_KEY,
    UTILISATION_KEY,
    why_none,
)
from mount_twin.physics.rotations import angle_text


def _estimate_text(est: ErrorEstimate | None) -> str:
    if est is None:
        return "estimated integration error: not estimated (integration.error_estimate: false)"
    if not est.estimated:
        return f"estimated integration error: {NOT_INTEGRATED}"
    forces = (
        f"{est.force_error_rel:.2g} of the largest ({est.force_error_n:.3g} N)"
        if math.isfinite(est.force_error_rel)
        else f"{est.force_error_n:.3g} N (no mount carried a force to relate it to)"
    )
    text = (
        f"estimated integration error: mount forces {forces}, "
        f"attitude {est.attitude_error_rad:.2g} rad, over the run"
    )
    if est.lower_bound:
        text += (
            f" (a lower bound: {est.failed_checks} intervals not measured, "
            f"{est.uncarried_states} states not carried)"
        )
    return text


def _accuracy_text(est: ErrorEstimate | None) -> str:
    """The JSON's word on where its accuracy figures are: as `_estimate_text` says where
    nothing was estimated (it had read "estimated live" beside figures of 0)."""
    if est is None:
        return (
            "not estimated live (integration.error_estimate: false); "
            "`mount-twin accuracy SCENE BAG` measures it"
        )
    if not est.estimated:
        return NOT_INTEGRATED
    return "estimated live: error_estimate, over the run"


@dataclass
class ReplaySummary:
    """What a replay did: counts, figures and per-mount peaks (`analysis.figures`)."""

    input_bag: str
    output_bag: str
    counts: dict[str, int]
    written: int
    stamp_span_s: float
    wall_s: float
    peaks: dict[str, np.ndarray] = field(default_factory=dict)  # peak |F| N, |M| N·m
    tilt_max_rad: float = 0.0
    displacement_max_m: float = 0.0  # from the first published position
    worst: dict[str, HealthStatus] = field(default_factory=dict)
    events: list[MountEvent] = field(default_factory=list)
    utilisation_max: dict[str, float] = field(default_factory=dict)
    origin_s: int = 0  # whole seconds to add to event stamps to get header stamps
    wrong_frame_id: str | None = None  # the last header.frame_id rejected as wrong (kept_text)
    start_s: float = 0.0  # engine seconds of the first output (event times count from it)
    error_estimate: ErrorEstimate | None = None  # the live estimate over the run (None: off)
    failure: str = ""  # how often the integration failed and why ('' if never)
    # samples, s: outputs after their input (gyro delay; None: the filter never designed)
    latency: tuple[int, float] | None = (0, 0.0)
    travel_max_m: dict[str, float] = field(default_factory=dict)  # per mount (`figures.TRAVEL`)
    body_counts: dict[str, int] | None = None  # the body IMU's (None: no body_sensor)
    body_topic: str = ""
    damaged: str = ""  # the input's damage, where the replay stopped at it ('' if none)
    decimation: int = 1  # outputs.decimation: what the peaks are (`figures.peak_label`)
    frame_id_setting: str = "input.frame_id"  # what set the frame id expected, to point at
    never_started: str = ""  # why the twin never started (`HealthWindow.never_started`)
    ageing_counts: dict[str, int] | None = None  # the ageing tracker's (None: no ageing)

    @property
    def worst_level(self) -> int:
        """The worst diagnostics level of the whole run (OK, WARN, ERROR: 0, 1, 2)."""
        return max((s.level for s in self.worst.values()), default=OK)

    @property
    def verdict(self) -> str:
        """FAILED if the integration failed (any failure: the twin then restarted at an
        equilibrium or stopped following, so from there on its figures are not the motion the
        record drove), else the worst diagnostics level's name."""
        return FAILED if self.failure else LEVEL_NAMES[self.worst_level]

    def nothing_accepted(self) -> str:
        """Why no input sample was accepted ('' if some were): the rejection counts, and the
        bag's header.frame_id when it is the wrong one, pointing at what set the one expected."""
        return count_texts.nothing_accepted(
            self.counts, self.wrong_frame_id, self.frame_id_setting
        )

    def followed_nothing(self) -> str:
        """Why the run has no motion and no mount loads ('' if it has): no input sample was
        accepted, or the twin never started (`never_started`); either exits 3 (`verdict`)."""
        return self.nothing_accepted() or self.never_started

    @property
    def real_time_factor(self) -> float:
        """Stamp time processed per wall second; NaN where no stamp time was processed (a run
        that answered no sample: its 0.0 had read as a twin that could not keep up)."""
        if self.stamp_span_s > 0.0 and self.wall_s > 0.0:
            return self.stamp_span_s / self.wall_s
        return math.nan

    def _speed_text(self) -> str:
        """'real-time factor 11.0', or why there is none."""
        rtf = self.real_time_factor
        if math.isnan(rtf):
            return "no real-time factor (no stamp time processed)"
        return f"real-time factor {rtf:.1f}"

    def text(self) -> str:
        """Human-readable summary."""
        c = self.counts
        lines = [
            f"replayed {self.input_bag} -> {self.output_bag}",
            *([f"  input damaged, replayed up to the damage: {d}"] if (d := self.damaged) else []),
            *([f"  {nothing}"] if (nothing := self.followed_nothing()) else []),
            *([f"  {FAILED}: {self.failure}"] if self.failure else []),
            f"  input samples: {c.get('received', 0)} received, {c.get('accepted', 0)} accepted, "
            f"rejected: {count_texts.counted_text(c, 'rejected_')}, gaps: {c.get('gaps', 0)}, "
            f"restarts: {c.get('restarts', 0)}, integration failures: "
            f"{c.get('integration_failures', 0)}",
            *(
                [
                    f"  not followed: {not_followed} samples, nothing published for them "
                    f"({c.get('starts_without_equilibrium', 0)} starts found no equilibrium; "
                    "the integration status says why)"
                ]
                if (not_followed := c.get("samples_not_followed", 0))
                else []
            ),
            f"  {self.written} messages written over {self.stamp_span_s:.3f} s of stamps in "
            f"{self.wall_s:.2f} s wall: {self._speed_text()}",
            f"  {_estimate_text(self.error_estimate)}",
            f"  latency: {self._latency_text(nothing)}",
        ]
        if nothing:
            lines.append(f"  motion and mount loads: none, {why_none(self.followed_nothing())}")
        else:
            lines += self._figure_lines()
        lines.append(
            f"  mount events: {len(self.events)} (times from the first output, as the plots'; "
            "stamp: the header stamp)"
            if self.events
            else "  mount events: none"
        )
        for (mount, event), same in _grouped(self.events).items():
            lines.append(
                f"    {same[0].level:5} {mount:>12} {event:<16} ×{len(same):<5} "
                f"first {same[0].stamp - self.start_s:.6f} s "
                f"(stamp {self.origin_s + same[0].stamp:.6f} s)  "
                f"|F| max {max(e.force for e in same):.4g} N"
            )
        lines += self._body_lines()
        lines += self._ageing_lines()
        lines.append(f"  diagnostics, worst over the run: {LEVEL_NAMES[self.worst_level]}")
        lines += [
            f"    {LEVEL_NAMES[s.level]:5} {s.name}: {s.message}" for s in self.worst.values()
        ]
        lines.append(f"  verdict: {self.verdict}")
        return "\n".join(lines)

    def _latency_text(self, nothing: str) -> str:
        """How late the outputs follow their input; no figure where the run followed nothing
        (`nothing`: why) or the gyro filter, designed at the accepted samples' rate, never was."""
        if nothing:
            return f"no figure, {why_none(self.followed_nothing())}"
        if self.latency is None:
            return f"no figure, {NOT_DESIGNED}"
        samples, seconds = self.latency
        return (
            f"outputs {samples} samples ({seconds * 1e3:.1f} ms) after their input, at its "
            "stamps (input.gyro_filter; none: no latency)"
        )

    def _figure_lines(self) -> list[str]:
        """The run's motion, peak mount loads and utilisations (a run that accepted samples)."""
        lines = [
            f"  max CG displacement from the first published position "
            f"{self.displacement_max_m * 1e3:.3f} mm, max tilt {angle_text(self.tilt_max_rad)}",
            f"  peak mount loads ({peak_label(self.decimation)}):",
            f"{'':18}{'|F| [N]':>10} {'|M| [N·m]':>10}",  # over `{name:>12}: ` and the figures
        ]
        for name, peak in self.peaks.items():
            lines.append(f"    {name:>12}: " + " ".join(f"{peak_text(v):>10}" for v in peak))
        if self.utilisation_max:
            lines.append(
                "  peak utilisation (bolt F/F_y, rubber deflection/rated, key F/allowable, "
                "linear travel/rated_travel or F/rated_load):"
            )
            lines += [
                f"    {n:>12}: {utilisation_text(u)}" for n, u in self.utilisation_max.items()
            ]
        return lines

    def _body_lines(self) -> list[str]:
        """What became of the body IMU's messages (none without a body_sensor)."""
        c = self.body_counts
        if c is None:
            return []
        if not c.get("received", 0):
            return [f"  body IMU {self.body_topic}: no message (not in the bag; --body names one)"]
        compared = c.get("compared", 0)
        fields = {f: c.get(f"compared_{f}", 0) for f in FIELDS}
        marked = {k: c.get(k, 0) for k in UNPROVIDED}
        on = ""
        if any(marked.values()):  # which readings it was compared on, and the marks
            on = " (" + ", ".join(f"{f.replace('_', ' ')} on {n}" for f, n in fields.items())
            on += f"; marked not provided: {count_texts.counted_text(marked, 'unprovided_')})"
        jumps = c.get(RESETS, 0)
        restarted = f"; its stamps jumped back {jumps}×, the comparison restarted" if jumps else ""
        return [
            f"  body IMU {self.body_topic}: {c['received']} received, {compared} compared with "
            f"the twin{on}, not compared: {count_texts.counted_text(not_compared(c))}{restarted} "
            f"(its agreement: {BODY_STATUS} below)"
        ]

    def _ageing_lines(self) -> list[str]:
        """The ageing tracker's counts (none without an ageing section)."""
        c = self.ageing_counts
        if c is None:
            return []
        deck, body = (c[k] for k in UNPAIRED)
        return [
            f"  ageing tracker: the stamps jumped back {c[RESETS]}× (it restarted), "
            f"{c[DROPPED]} windows open at a jump dropped (under half a window), samples "
            f"paired with none of the other stream's: deck {deck}, body IMU {body} "
            f"(its fits and counts: {AGEING_STATUS} below)"
        ]

    def to_dict(self) -> dict[str, object]:
        """The summary as JSON-ready data, units in the key names; event times `t_s` count
        from the first output, `stamp_s` are header stamps."""
        util = self.utilisation_max
        known = not self.followed_nothing()  # else no figures: null, not a machine at rest
        latency = self.latency if known else None
        return {
            "input_bag": self.input_bag,
            "output_bag": self.output_bag,
            "verdict": self.verdict,
            "failure": self.failure or None,
            "input_damaged": self.damaged or None,
            "nothing_accepted": self.nothing_accepted() or None,
            "never_started": self.never_started or None,
            "diagnostics_worst_level": LEVEL_NAMES[self.worst_level],
            "counts": dict(self.counts),
            "stamp_span_s": self.stamp_span_s,
            "wall_s": self.wall_s,
            "real_time_factor": None if math.isnan(rtf := self.real_time_factor) else rtf,
            DISPLACEMENT: self.displacement_max_m if known else None,
            "max_tilt_rad": self.tilt_max_rad if known else None,
            "latency_samples": None if latency is None else latency[0],
            "latency_s": None if latency is None else latency[1],
            "error_estimate": self.error_estimate.as_dict() if self.error_estimate else None,
            "body_sensor": None
            if self.body_counts is None
            else {"topic": self.body_topic, "counts": dict(self.body_counts)},
            "ageing": None if self.ageing_counts is None else {"counts": dict(self.ageing_counts)},
            "mounts": {
                name: {
                    PEAK_FORCE: float(peak[0]) if known else None,
                    PEAK_COUPLE: float(peak[1]) if known else None,
                    TRAVEL: self.travel_max_m.get(name) if known else None,
                    "utilisation_max": util.get(name) if known else None,
                }
                for name, peak in self.peaks.items()
            },
            "events": [
                {
                    "mount": e.mount,
                    "event": e.event,
                    "level": e.level,
                    "t_s": e.stamp - self.start_s,
                    "stamp_s": self.origin_s + e.stamp,
                    "force_N": e.force,
                }
                for e in self.events
            ],
            "diagnostics_worst": {
                name: {"level": LEVEL_NAMES[st.level], "message": st.message}
                for name, st in self.worst.items()
            },
            "accuracy": _accuracy_text(self.error_estimate),
        }


def keep_worst(worst: dict[str, HealthStatus], report: HealthReport) -> None:
    """Keep, per status name, the first status of the highest level seen, except: of a mount's
    periods at that level that report only their utilisation (no event, no condition), the one
    of the largest (so it reads the summary's peak utilisation); of the integration status the
    latest: its estimated error is that of the run so far (`health.estimate_warning`), so the
    worst over the run is the summary's `error_estimate`."""
    for status in report.statuses:
        kept = worst.get(status.name)
        if kept is None or _outranks(status, kept):
            worst[status.name] = status


def _outranks(status: HealthStatus, kept: HealthStatus) -> bool:
    """Whether `status` replaces `kept`, of the same name, as its worst (`keep_worst`)."""
    if status.level != kept.level:
        return status.level > kept.level
    if status.name == INTEGRATION:
        return True
    quiet = _utilisation_only(status) and _utilisation_only(kept)
    return quiet and _utilisation(status) > _utilisation(kept)


def _utilisation_only(status: HealthStatus) -> bool:
    """Whether a mount's status reports its utilisation alone: no event, no condition."""
    values = status.values
    return values.get(EVENTS_KEY) == "0" and values.get(NOW_KEY) == "none"


def _utilisation(status: HealthStatus) -> float:
    """A mount status' utilisation over its period; −inf where unrated."""
    value = status.values.get(UTILISATION_KEY, "n/a")
    return -np.inf if value == "n/a" else float(value)


def _grouped(events: list[MountEvent]) -> dict[tuple[str, str], list[MountEvent]]:
    """Events by (mount, event), in order of first occurrence."""
    out: dict[tuple[str, str], list[MountEvent]] = {}
    for e in events:
        out.setdefault((e.mount, e.event), []).append(e)
    return out
