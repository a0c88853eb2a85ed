"""Health of the running twin over a diagnostics period: input, integration, attitude."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from mount_twin.engine.batch import ERROR, OK, WARN, HealthReport, HealthStatus, MountEvent
from mount_twin.scene.description import Scene

PREFIX = "mount_twin"


def tilt_from_quaternions(quat: np.ndarray) -> np.ndarray:
    """Tilt θ of body z from the vertical of F, rad, for (k, 4) quaternions (x, y, z, w)."""
    r33 = 1.0 - 2.0 * (quat[:, 0] ** 2 + quat[:, 1] ** 2)
    return np.arccos(np.clip(r33, -1.0, 1.0))


class HealthWindow:
    """Accumulates figures between diagnostics and builds the reports when one is due."""

    def __init__(self, scene: Scene, method: str) -> None:
        self.scene = scene
        self.method = method
        self.period = scene.outputs.diagnostics_period_s
        self.origin_s = 0
        """Whole seconds to add to engine stamps in texts, so they read as header stamps."""
        self._next_due: float | None = None
        self._reset()
        self._last_counts: Counter[str] = Counter()

    def _reset(self) -> None:
        self.t_first = math.nan
        self.t_last = math.nan
        self.wall = 0.0
        self.err_max = 0.0
        self.substeps = 0
        self.samples = 0
        self.tilt_max = 0.0
        self.failures: list[tuple[float, str]] = []
        self.wrench_peak = np.zeros((len(self.scene.mounts), 6))
        self.events: list[MountEvent] = []

    @property
    def pending(self) -> bool:
        """Whether anything was recorded since the last report."""
        return bool(self.samples or self.events or self.failures or not math.isnan(self.t_last))

    def add_steps(self, step_log: np.ndarray) -> None:
        """Per-sample stepper figures: (error norm, accepted, rejected substeps)."""
        if step_log.shape[0]:
            self.err_max = max(self.err_max, float(step_log[:, 0].max()))
            self.substeps += int(step_log[:, 1].sum() + step_log[:, 2].sum())
            self.samples += step_log.shape[0]

    def add_outputs(self, stamps: np.ndarray, pose: np.ndarray, wrenches: np.ndarray) -> None:
        """Published rows: their stamps (s), poses and mount wrenches (N, N·m, mount axes)."""
        if stamps.shape[0] == 0:
            return
        np.maximum(self.wrench_peak, np.abs(wrenches).max(axis=0), out=self.wrench_peak)
        if math.isnan(self.t_first):
            self.t_first = float(stamps[0])
        self.t_last = float(stamps[-1])
        self.tilt_max = max(self.tilt_max, float(tilt_from_quaternions(pose[:, 3:7]).max()))

    def add_wall(self, wall_s: float) -> None:
        """Wall time spent on the samples of this window, s."""
        self.wall += wall_s

    def add_events(self, events: list[MountEvent]) -> None:
        """Mount events of this window."""
        self.events.extend(events)

    def failure(self, stamp: float, text: str) -> None:
        """A stepper failure (or a forced start) at `stamp` (s)."""
        self.failures.append((stamp, text))

    def tick(self, stamp: float) -> bool:
        """An accepted sample at `stamp` (s): is a report due once it is processed?

        Reports come one period of stamps apart; a stamp before the current window (a bag
        played in a loop) starts the cadence afresh.
        """
        if self._next_due is None or stamp < self._next_due - self.period:
            self._next_due = stamp + self.period
            return False
        if stamp < self._next_due:
            return False
        self._next_due = stamp + self.period
        return True

    def ticks(self, stamps: np.ndarray) -> list[int]:
        """`tick` for accepted samples in increasing order after the last ticked one: the
        positions after which reports are due (one search per report, not a loop per sample)."""
        due: list[int] = []
        start = 0
        if self._next_due is None:
            self._next_due = float(stamps[0]) + self.period
            start = 1
        while True:
            k = start + int(np.searchsorted(stamps[start:], self._next_due, side="left"))
            if k >= stamps.shape[0]:
                return due
            due.append(k)
            self._next_due = float(stamps[k]) + self.period
            start = k + 1

    def report(
        self,
        stamp: float,
        sample: int,
        counts: Counter[str],
        utilisation: np.ndarray,
        active: dict[str, list[tuple[str, bool]]],
    ) -> HealthReport:
        """Statuses at `stamp` (s), after pushed sample `sample`, for the window so far, which
        then starts anew.

        Counts are cumulative; rejections, gaps, stepper figures, mount peaks and events are
        this window's. `utilisation`: peak per non-linear mount, in model order; `active`: the
        conditions holding now per mount (event name, is an error), e.g. a broken bolt, which
        keep the mount's level after the events themselves have been reported.
        """
        new = counts - self._last_counts
        self._last_counts = counts.copy()
        span = self.t_last - self.t_first
        rejected = {k: v for k, v in counts.items() if k.startswith("rejected_")}
        new_rejected = sum(v for k, v in new.items() if k.startswith("rejected_"))
        inp = HealthStatus(
            f"{PREFIX}: input",
            WARN if new_rejected or new["gaps"] else OK,
            f"{new_rejected} samples rejected, {new['gaps']} gaps in this period"
            if new_rejected or new["gaps"]
            else "ok",
            {
                "topic": self.scene.input.topic,
                "rate_hz": f"{new['accepted'] / span:.1f}" if span > 0 else "n/a",
                **{k: str(counts[k]) for k in ("received", "accepted", "gaps", "restarts")},
                **{k: str(v) for k, v in sorted(rejected.items())},
                "reset_stamp_jumped_back": str(counts["reset_stamp_jumped_back"]),
            },
        )
        integ = self.scene.integration
        rtf = span / self.wall if self.wall > 0 and span > 0 else math.nan
        fail_text = "; ".join(f"{self.origin_s + t:.6f} s: {m}" for t, m in self.failures)
        step = HealthStatus(
            f"{PREFIX}: integration",
            ERROR if self.failures else OK,
            f"stepper failed and the twin restarted: {fail_text}" if self.failures else "ok",
            {
                "method": self.method,
                "rtol": f"{integ.rtol:g}",
                "atol": f"{integ.atol:g}",
                "error_norm_max": f"{self.err_max:.3g}",
                "substeps_per_sample": f"{self.substeps / self.samples:.2f}"
                if self.samples
                else "n/a",
                "real_time_factor": f"{rtf:.1f}",
                "failures_total": str(counts["integration_failures"]),
            },
        )
        warn = self.scene.outputs.tilt_warn_rad
        att = HealthStatus(
            f"{PREFIX}: attitude",
            WARN if self.tilt_max > warn else OK,
            f"tilt {math.degrees(self.tilt_max):.1f}° past {math.degrees(warn):.1f}°: the α/γ/δ "
            "chart degrades toward 90°"
            if self.tilt_max > warn
            else "ok",
            {"tilt_max_rad": f"{self.tilt_max:.6g}"},
        )
        mounts = self._mount_statuses(utilisation, active)
        self._reset()
        return HealthReport(stamp, sample, [inp, step, att, *mounts])

    def _mount_statuses(
        self, utilisation: np.ndarray, active: dict[str, list[tuple[str, bool]]]
    ) -> list[HealthStatus]:
        """One status per mount: peak wrench per axis, utilisation, events by name, and the
        conditions holding now."""
        util = dict.fromkeys((m.name for m in self.scene.mounts), math.nan)
        nonlinear = [m.name for m in self.scene.mounts if m.kind != "linear"]
        util.update(zip(nonlinear, utilisation.tolist(), strict=True))
        warn_at = 1.0 - self.scene.outputs.alarm_margin
        out = []
        for i, mount in enumerate(self.scene.mounts):
            mine = [e for e in self.events if e.mount == mount.name]
            now = active.get(mount.name, [])
            u = util[mount.name]
            if any(e.error for e in mine) or any(err for _, err in now) or u > 1.0:
                level = ERROR
            elif mine or now or u >= warn_at:
                level = WARN
            else:
                level = OK
            peak = self.wrench_peak[i]
            values = {
                f"peak_{axis}": f"{v:.6g}"
                for axis, v in zip(
                    ("fx_N", "fy_N", "fz_N", "tx_Nm", "ty_Nm", "tz_Nm"), peak, strict=True
                )
            }
            values["utilisation_max"] = "n/a" if math.isnan(u) else f"{u:.4g}"
            values["now"] = ", ".join(name for name, _ in now) or "none"
            text = _events_text(mine, u, self.origin_s)
            if now:
                text = f"now: {values['now']}" + ("" if text == "ok" else f"; {text}")
            out.append(HealthStatus(f"{PREFIX}: mount {mount.name}", level, text, values))
        return out


def _events_text(events: list[MountEvent], utilisation: float, origin_s: int) -> str:
    """'joint_opened ×3 (first 1.234567 s, |F| max 4.5e+04 N); …', or the utilisation."""
    if not events:
        return "ok" if not utilisation > 0.0 else f"utilisation {utilisation:.3g}"
    parts = []
    for name in dict.fromkeys(e.event for e in events):
        same = [e for e in events if e.event == name]
        parts.append(
            f"{name} ×{len(same)} (first {origin_s + same[0].stamp:.6f} s, "
            f"|F| max {max(e.force for e in same):.4g} N)"
        )
    return "; ".join(parts)
