"""The machine's body IMU against the twin, as a stream: at each body sample the twin's
prediction of that sample and the residual, and window by window how well they agree.

Three stages, a module each, fed in stamp order; each gives the same numbers however its
input comes batched, and whichever of the two streams comes first (live = replay), within
`body_matching.RETAIN_S`:

1. `body_prediction.Lead` predicts the body sensor at the twin's rows
   (`sensor_reading.predicted_reading`). Its rates and angular acceleration are central
   differences, so a row is predicted once the two rows after it are published (the run's
   first and last rows by one-sided differences): the prediction trails the twin by two rows.
2. `body_matching.Matcher`: a body sample stamped s measured the motion at s − lag_s; the
   prediction there is that row's where a row is at it, else interpolated linearly between
   the rows around it, once a row at or past it exists. A sample before the twin's first row,
   more than `RETAIN_S` behind the prediction, or between rows farther apart than
   input.max_gap_s (a gap, a restart) is counted and not compared.
3. `body_windows.Windows` judges the compared samples in windows of body_sensor.window_s of
   stamps (`agreement`), on a grid from the first compared sample, each field (specific
   force, rate) on the samples that provide it (a message may mark one reading not provided,
   REP-145); the last, partial window at the end of the stream if it spans half a window. A
   window with fewer than `agreement.MIN_SAMPLES` samples providing either field is judged
   with the next. Each counts the body messages not compared in it by their place in the body
   stream.

Where the twin restarts because the deck's stamps jumped back (more than
input.back_jump_reset_s: a bag played with --loop), its rows' stamps go back: the stages
restart with it, the body stream at its own jump back (`BodyCheck.screen`), each of its runs
matched with the twin's of the same rank (`Matcher`), the window open at the jump closed as
the stream's last is. Where only one of them jumps back (`stamp_runs.Apart`: the other's
stamps went on past the jump by more than back_jump_reset_s), the runs never pair again: a
WARN says so once, and the body samples past the pairing are counted `APART`, not held. The
counts' names and what they mean: `body_counts`.

Beside them, `body_refusals.Refusals` watches the body messages themselves, in windows of the
same length on their own stamps: a window in which every message was rejected (another
frame_id, …) is a WARN when the next begins, so that a body IMU the twin never takes shows
live, not only at the end of the stream. It depends on the body stream alone.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from mount_twin.engine.agreement import FIELDS, NAME
from mount_twin.engine.batch import WARN, HealthStatus
from mount_twin.engine.body_counts import APART, NOT_COMPARED, REJECTED, RESETS, UNPROVIDED
from mount_twin.engine.body_matching import PENDING_LIMIT, Matcher, Taken
from mount_twin.engine.body_prediction import Lead, TwinRows
from mount_twin.engine.body_refusals import Refusals
from mount_twin.engine.body_windows import Windows
from mount_twin.engine.reading_screen import provided
from mount_twin.engine.sensor_reading import SensorGeometry, predicted_reading
from mount_twin.engine.stamp_runs import Apart
from mount_twin.engine.stamp_verdicts import rising_or_back
from mount_twin.physics import pose_row
from mount_twin.scene.description import BodySensor, Scene


@dataclass
class BodyComparison:
    """The body IMU's samples compared, and the windows judged.

    Attributes:
        stamps_ns: (k,) the compared body samples' header stamps, ns.
        predicted: (k, 6) the twin's prediction: specific force (m/s²), rate (rad/s), in the
            sensor's axes.
        residual: (k, 6) measured − predicted (nan for a reading the sample does not provide).
        present: (k, 2) which readings (specific force, rate) each sample provides.
        reports: (stamp ns, status) of each window closed.
    """

    stamps_ns: np.ndarray
    predicted: np.ndarray
    residual: np.ndarray
    present: np.ndarray
    reports: list[tuple[int, HealthStatus]]

    @classmethod
    def none(cls, reports: list[tuple[int, HealthStatus]]) -> BodyComparison:
        """No sample compared; `reports`."""
        empty = np.zeros((0, 6))
        return cls(np.zeros(0, np.int64), empty, empty, np.zeros((0, 2), bool), reports)


class BodyCheck:
    """The body IMU against the twin (module docstring).

    Attributes:
        counts: body messages received, accepted and compared (and compared on each field,
            compared_<field> of `agreement.FIELDS`), the accepted ones marking a reading not
            provided (`UNPROVIDED`), and why others were not compared (`PROBLEMS`; the stream
            counts its rejections here too, as rejected_<reason>).
    """

    def __init__(self, scene: Scene, sensor: BodySensor) -> None:
        self.sensor = sensor
        compared = ("received", "accepted", "compared", *(f"compared_{f}" for f in FIELDS))
        self.counts: Counter[str] = Counter(
            dict.fromkeys((*compared, *NOT_COMPARED, *UNPROVIDED, RESETS), 0)
        )  # every key from the start: the order (of a WARN's values) never that of the feeding
        self._back_ns = round(scene.input.back_jump_reset_s * 1e9)
        self.last_ns = 0
        """The last accepted body stamp, ns (0: none yet)."""
        self._last_row_t = -np.inf
        """The stamp of the twin's last row, s."""
        self.seen_ns = 0
        """The latest stamp of any body message screened, ns (0: none with a stamp)."""
        self._accepted_screened = 0
        """Body messages screened and accepted so far, in the body stream's order."""

        geometry = SensorGeometry.of(scene, sensor)

        def predict(rows: TwinRows, kept: slice) -> np.ndarray:
            pose = (rows.pose[:, pose_row.POSITION_COLS], rows.pose[:, pose_row.QUATERNION_COLS])
            f, w = predicted_reading(geometry, rows.t, pose, rows.wrenches, rows.rate, kept)
            return np.concatenate([f, w], axis=1)

        self._lead = Lead(predict)
        self._apart = Apart(scene.input.back_jump_reset_s, sensor.lag_s)
        self._said_apart = False
        self._matcher = Matcher(sensor.lag_s, scene.input.max_gap_s, self.counts, self._apart)
        self._windows = Windows(sensor, self.counts)
        self._refusals = Refusals(sensor, self._back_ns)

    def screen(
        self,
        stamps_ns: np.ndarray,
        measured: np.ndarray,
        frame_ids: list[str],
        unprovided: np.ndarray | None = None,
    ) -> np.ndarray:
        """Why each body message (stamps ns, (k, 6) readings, header.frame_ids, and which
        readings (k, 2) its message marks not provided, `Decoded.unprovided`) cannot be
        compared ('' where it can; the caller counts the others with `reject`, at their place
        in the stream): an unset or pre-1970 stamp, a value not finite (a reading marked not
        provided is not read), a frame_id other than body_sensor.frame_id ("": any), both its
        acceleration and its rate marked not provided (REP-145: to be disregarded; a sample
        that provides one is compared on it), a stamp not after every one accepted before
        it, unless it is more than input.back_jump_reset_s before them (the body stream's run
        restarts, as the twin does where the deck's stamps jump back so: counted
        reset_stamp_jumped_back)."""
        expected = self.sensor.frame_id
        accel, rate = provided(measured[:, :3], measured[:, 3:], unprovided)
        marked = np.zeros((stamps_ns.shape[0], 2), bool) if unprovided is None else unprovided
        reasons = {
            "nonpositive_stamp": stamps_ns <= 0,
            "nonfinite": ~(np.isfinite(accel).all(axis=1) & np.isfinite(rate).all(axis=1)),
            "wrong_frame_id": np.array(
                [bool(expected) and f != expected for f in frame_ids], bool
            ),
            "no_reading": marked[:, 0] & marked[:, 1],
        }
        why = np.full(stamps_ns.shape[0], "", dtype=object)
        for reason, bad in reversed(reasons.items()):  # the first that applies, written last
            why[bad] = reason
        keep = why == ""
        taken, jumped = rising_or_back(stamps_ns, keep, self.last_ns, self._back_ns)
        why[keep & ~taken] = "stamp_back"
        self.counts[RESETS] += int(jumped.sum())
        keep = why == ""
        if keep.any():
            self.last_ns = int(stamps_ns[keep][-1])
        self.seen_ns = max(self.seen_ns, int(stamps_ns.max(initial=0)))
        return why

    def screened(self, stamps_ns: np.ndarray, why: np.ndarray) -> BodyComparison:
        """Every body message as it came (stamps ns, 0 where unknown; why each was rejected,
        '' where not): each rejected one marked at its place in the body stream, and the
        windows of stamps in which none was taken, reported (nothing compared)."""
        accepted = why == ""
        if not accepted.all():
            before = self._accepted_screened + np.cumsum(accepted) - accepted
            self._windows.mark(before[~accepted], why[~accepted])
        self._accepted_screened += int(accepted.sum())
        return BodyComparison.none(self._refusals.add(stamps_ns, why))

    def reject(self, reason: str, n: int) -> None:
        """Count n body messages not compared, because `reason` (one of REJECTED)."""
        if reason not in REJECTED:
            raise ValueError(f"body messages rejected for {reason!r}, not one of {REJECTED}")
        self.counts[f"rejected_{reason}"] += n

    def over_limit(self, held: int) -> int:
        """How many of `held` accepted body samples, held before the twin has a time base (no
        deck message yet: `TwinStream`), are past PENDING_LIMIT: the oldest, dropped and
        counted `dropped_waiting`, as those waiting for its predictions are (`Matcher`)."""
        cut = max(held - PENDING_LIMIT, 0)
        self.counts["dropped_waiting"] += cut
        self._matcher.taken += cut  # (their places in the body stream: before any it holds)
        return cut

    def add_rows(
        self, t: np.ndarray, pose: np.ndarray, wrenches: np.ndarray, rate: np.ndarray
    ) -> BodyComparison:
        """The twin's published rows: stamps (s), pose rows, wrenches and the foundation's
        rate (rad/s, F) at each; a row stamped before the one before it starts a new run of
        the twin (a restart where the deck's stamps jumped back)."""
        rows = TwinRows(t, pose, wrenches, rate)
        self._apart.add("deck", t)
        back = set(np.flatnonzero(t < np.concatenate([[self._last_row_t], t[:-1]])).tolist())
        if t.shape[0]:
            self._last_row_t = float(t[-1])
        for start, stop in pairwise([*sorted({0, *back}), t.shape[0]]):
            if start in back:  # the twin restarted (its stamps jumped back): its run ended
                self._matcher.add_predictions(*self._lead.finish())
                self._matcher.restart_rows()
            self._matcher.add_predictions(*self._lead.add(rows.part(start, stop)))
        return self._compared()

    def add_body(
        self, ns: np.ndarray, t: np.ndarray, measured: np.ndarray, present: np.ndarray
    ) -> BodyComparison:
        """Accepted body samples: stamps (ns and s on the twin's base), (k, 6) readings, which
        of them each provides ((k, 2): specific force, rate; `screen` takes none with
        neither)."""
        self.counts["accepted"] += int(ns.shape[0])
        for key, given in zip(UNPROVIDED, present.T, strict=True):
            self.counts[key] += int((~given).sum())
        self._apart.add("body", t)
        self._matcher.add_body(ns, t, measured, present)
        return self._compared()

    def finish(self, stamp_ns: int) -> BodyComparison:
        """The end of both streams: the last rows predicted, every sample left compared or
        counted, the last window judged. A WARN of the end (`Windows.finish`) is stamped with
        the latest body stamp seen, else (no body message read with a stamp: every one lost,
        say) `stamp_ns`, the twin's end (ns)."""
        self._matcher.add_predictions(*self._lead.finish())
        out = self._compared(final=True)
        out.reports += self._windows.finish(self.counts, self.seen_ns or stamp_ns)
        return out

    def _compared(self, final: bool = False) -> BodyComparison:
        taken = self._matcher.take(final)
        out = self._judged(taken) if taken.ns.shape[0] else BodyComparison.none([])
        stamp_ns = self._matcher.first_apart_ns
        if stamp_ns is not None and not self._said_apart:
            self._said_apart = True
            message = self._apart.message() + (
                f": the body IMU is not compared from there on (counted {APART})"
            )
            assert self._apart.found is not None
            first, _, end = self._apart.found
            values = {"jumped_back_first": first, "jumped_back_at_s": f"{end:.3f}"}
            out.reports.append((stamp_ns, HealthStatus(NAME, WARN, message, values)))
        return out

    def _judged(self, taken: Taken) -> BodyComparison:
        """Body samples taken out of the matcher: those compared counted, their residuals, and
        the windows they close."""
        compared = taken.compared()
        self.counts["compared"] += int(compared.ns.shape[0])
        present = compared.present
        for field, given in zip(FIELDS, present.sum(axis=0).tolist(), strict=True):
            self.counts[f"compared_{field}"] += given
        residual = compared.measured - compared.predicted
        if not present.all():
            residual[~np.repeat(present, 3, axis=1)] = np.nan
        reports = self._windows.add(taken, residual)
        return BodyComparison(compared.ns, compared.predicted, residual, compared.present, reports)
