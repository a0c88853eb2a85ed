"""One path for every sample, live or offline: raw CDR in, raw CDR out.

`TwinStream` is what both adapters drive: the rclpy node hands it each raw message it receives,
the bag replay hands it chunks of raw messages from a bag. Only the transport differs.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from mount_twin.engine.batch import ERROR, HealthReport, OutputBatch
from mount_twin.engine.body_check import BodyCheck, BodyComparison
from mount_twin.engine.body_counts import RESETS
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.health_texts import INPUT
from mount_twin.engine.input_status import ENDED
from mount_twin.engine.reading_screen import disregarded, provided, rotated
from mount_twin.engine.stamp_verdicts import rising_or_back
from mount_twin.errors import require
from mount_twin.io.input_decoding import Decoded, TimeBase, decode_inputs
from mount_twin.io.messages import IMU
from mount_twin.io.output_encoding import (
    Encoded,
    encode_body,
    encode_output_blocks,
    encode_outputs,
    encode_report,
)
from mount_twin.io.output_topics import output_streams
from mount_twin.model.assemble import assemble
from mount_twin.scene.description import Scene

if TYPE_CHECKING:
    from mount_twin.analysis.ageing_live import AgeingTracker, WindowJob


@dataclass
class _Kept:
    """What the stream keeps of the samples pushed whose outputs may still come
    (`TwinEngine.pending_ids`): their stream positions (increasing), integer header stamps
    (ns) and, with a body IMU, foundation rates (rad/s, F). A few samples, however long ago
    the oldest came (a run's last one, before a long stretch of rejected samples)."""

    ids: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    ns: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    rate: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def then(
        self, first_id: int, stamps_ns: np.ndarray, rate: np.ndarray | None, wanted: np.ndarray
    ) -> _Kept:
        """These and a push's samples (positions from `first_id`, stamps ns, rates rad/s
        where there is a body IMU, else None), as far as `wanted` (increasing positions, each
        of these or of the push: the engine's `pending_ids` after it)."""
        n = stamps_ns.shape[0]
        ns = np.concatenate([self.ns, stamps_ns])
        rates = self.rate if rate is None else np.concatenate([self.rate, rate])
        ids = np.concatenate([self.ids, np.arange(first_id, first_id + n, dtype=np.int64)])
        k = wanted.shape[0]
        if (
            k
            and k <= ids.shape[0]
            and int(ids[-k]) == int(wanted[0]) == int(wanted[-1]) - k + 1
            and int(ids[-1]) == int(wanted[-1])
        ):  # the last k, both the range a … a + k − 1 of k increasing integers (the gyro
            # delay's samples, the usual case): slices, without a search and three gathers
            last = slice(ids.shape[0] - k, None)
            return _Kept(ids[last], ns[last], rates if rate is None else rates[last])
        at = np.searchsorted(ids, wanted)
        if at.shape[0] and (at[-1] >= ids.shape[0] or (ids[at] != wanted).any()):
            msg = f"the engine may still answer samples {wanted.tolist()}, not all kept"
            raise RuntimeError(msg)
        return _Kept(ids[at], ns[at], rates if rate is None else rates[at])

    def renumbered(self, out: OutputBatch, first_id: int) -> OutputBatch:
        """`out` (positions relative to a push whose first sample is at `first_id`; negative:
        earlier samples) with its rows' and reports' earlier samples numbered into these kept
        ones, appended after the push's: −1 the last kept. Unchanged where these are the
        samples just before the push (no rejected sample since the oldest), the usual case.
        Raises RuntimeError for an earlier sample not kept (its stamp is lost: a mistake,
        never a guess)."""
        k = self.ids.shape[0]
        reported = [r.sample for r in out.health]
        oldest = min(int(out.sample.min()) if len(out) else 0, *reported, 0)
        if not k or (int(self.ids[0]) == first_id - k and int(self.ids[-1]) == first_id - 1):
            if oldest < -k:
                msg = f"outputs answer sample {first_id + oldest}, whose stamp was not kept"
                raise RuntimeError(msg)
            return out
        return replace(
            out,
            sample=self._index(out.sample, first_id),
            health=[
                replace(r, sample=int(self._index(np.array([r.sample]), first_id)[0]))
                for r in out.health
            ],
        )

    def _index(self, positions: np.ndarray, first_id: int) -> np.ndarray:
        """`renumbered`'s positions."""
        early = positions < 0
        if not early.any():
            return positions
        ids = first_id + positions[early]
        at = np.minimum(np.searchsorted(self.ids, ids), self.ids.shape[0] - 1)
        if (self.ids[at] != ids).any():
            msg = f"outputs answer samples {ids.tolist()} whose stamps were not kept"
            raise RuntimeError(msg)
        index = positions.copy()
        index[early] = at - self.ids.shape[0]
        return index


class TwinStream:
    """Decode → engine → encode for one scene.

    Attributes:
        engine: the streaming engine (counts, state, health).
        last_outputs: the engine's outputs of the last `process` or `finish` call, one
            OutputBatch however many pushes it took (for summaries and plots; None before
            any, or where the call pushed nothing).
        body: the body IMU's comparison with the twin (None: the scene has no body_sensor).
        body_reports: the body comparison's window reports not yet taken (`take_body_reports`;
            for summaries).
    """

    def __init__(self, scene: Scene, *, blocks: bool = False) -> None:
        require(scene, Scene, "TwinStream(scene)")
        self.blocks = blocks
        """Per-row outputs come as `RowBlock`s (a bag writer's) rather than message by message
        (a publisher's): the same bytes, in the same order (`messages_of`)."""
        self.engine = TwinEngine(assemble(scene))
        self.scene = self.engine.scene
        """`scene` as assembled: its warnings with those of its start (`model.ratings`)."""
        # rosbags generates a type's serializer at its first use and the output layouts are
        # probed then: ~40 ms that would otherwise delay the first live sample.
        self._streams = output_streams(scene)
        encode_outputs(scene, OutputBatch.empty(len(scene.mounts)), np.zeros(0, np.int64))
        self.base: TimeBase | None = None
        self.last_outputs: OutputBatch | None = None
        self._last_ns = 0
        self._received_ns = 0
        """Stamp (ns) of the last sample received with a stamp (> 0), accepted or not."""
        self._stalled_ns = 0
        """The stamp of the last stall report (ns, the node's clock; 0: none)."""
        self._kept = _Kept()
        self.final_report: HealthReport | None = None
        sensor = scene.body_sensor
        self.body = None if sensor is None else BodyCheck(scene, sensor)
        self.body_reports: list[HealthReport] = []
        self._body_waiting: list[Decoded] = []
        """Body samples that came before the first foundation sample set the time base."""
        self.ageing: AgeingTracker | None = None
        if scene.ageing is not None:  # scipy and the fit, only for a scene that tracks
            from mount_twin.analysis.ageing_live import AgeingTracker

            self.ageing = AgeingTracker(scene)
        self._ageing_jobs: list[WindowJob] = []
        self._ageing_last_ns = 0
        """The stamp of the last deck sample the ageing tracker took, ns."""
        self._back_ns = round(scene.input.back_jump_reset_s * 1e9)

    def process(self, raws: Sequence[bytes]) -> list[Encoded]:
        """Outputs for raw input messages, as (unresolved topic, stamp ns, CDR bytes), or blocks
        of them (`blocks`)."""
        decoded = decode_inputs(raws, self.scene.input.msg_type)
        good = decoded.stamps_ns > 0
        if not decoded.undecodable and good.all():
            return self._follow(decoded)
        # Messages the engine cannot take: not valid CDR; an unset header.stamp, which has no
        # time to place the sample at; one before 1970 (sec < 0, which builtin_interfaces/Time
        # allows), which cannot be written to a bag or answered. Each is counted where it
        # came, between the pushes of the samples around it, as a rejected sample is, so the
        # diagnostics period and the stamp interval it falls in do not depend on how the
        # messages were batched (counted before a batch's push, all were credited to its first
        # interval and its first period: a hole later read as samples lost).
        reason = np.full(len(raws), "undecodable", dtype=object)
        reason[decoded.places()] = np.where(
            good, "", np.where(decoded.stamps_ns == 0, "zero_stamp", "negative_stamp")
        )
        outputs: list[Encoded] = []
        merged: OutputBatch | None = None
        pushed = 0
        for start, stop in _runs(reason):
            if reason[start]:  # a run of messages rejected for the same reason
                self.engine.count("received", stop - start)
                self.engine.count(f"rejected_{reason[start]}", stop - start)
                continue
            part = decoded.select(_within(decoded, start, stop))
            self.last_outputs = None
            outputs += self._follow(part)
            if self.last_outputs is not None:
                got = self.last_outputs
                merged = got if merged is None else merged.then(got, pushed)
            pushed += stop - start
        self.last_outputs = merged
        return outputs

    def _follow(self, decoded: Decoded) -> list[Encoded]:
        """`process` of messages the engine takes (decoded, stamps > 0), pushed in one call."""
        if decoded.stamps_ns.shape[0]:
            self._received_ns = int(decoded.stamps_ns[-1])
        if self.base is None:
            if not decoded.stamps_ns.shape[0]:
                return []
            self.base = TimeBase.at(int(decoded.stamps_ns[0]))
            self.engine.health.origin_s = self.base.origin_ns // 1_000_000_000
        first_id = self.engine.pushed
        out = self.engine.push(decoded.batch(self.base))
        self.last_outputs = out
        # Rows of samples of earlier pushes (the gyro delay, a sample held back, a run's last
        # sample) come as negative samples: the stamps kept of them find them.
        rate = None if self.body is None else self._foundation_rate(decoded)
        kept = self._kept
        self._kept = kept.then(first_id, decoded.stamps_ns, rate, self.engine.pending_ids)
        numbered = kept.renumbered(out, first_id)
        msgs = self._encode(numbered, np.concatenate([decoded.stamps_ns, kept.ns]))
        if self.ageing is not None:
            self._track_foundation(decoded)
        if rate is None or self.body is None:
            return msgs
        rates = np.concatenate([rate, kept.rate])
        rows = self.body.add_rows(out.stamps, out.pose, out.wrenches, rates[numbered.sample])
        waiting, self._body_waiting = self._body_waiting, []
        return msgs + self._encode_body(rows) + [m for d in waiting for m in self._body_in(d)]

    @property
    def body_behind(self) -> bool:
        """Whether the body IMU's last accepted stamp is not past the foundation's last
        received one, each after its stamps' jumps back (a replay feeds the body stream until
        it is: a bag played with --loop, both its streams jumping back at each loop)."""
        if self.body is None:
            return True
        body = (self.body.counts[RESETS], self.body.last_ns)
        return body <= (self.engine.counts[RESETS], self._received_ns)

    def take_body_reports(self) -> list[HealthReport]:
        """The body comparison's window reports since the last call."""
        reports, self.body_reports = self.body_reports, []
        return reports

    def _track_foundation(self, decoded: Decoded) -> None:
        """Deck samples into the ageing tracker, those the twin's intake takes too: finite
        values, no reading the twin reads marked not provided (a rate marked so under
        input.gyro_filter: ignore is zeroed, not dropped: `reading_screen.disregarded`, `provided`;
        it had been dropped, the tracker's window then short of the twin's samples), the
        input's frame_id (if it names one) and rising stamps, or one more than
        input.back_jump_reset_s back (the twin restarts there, and the tracker with it)."""
        assert self.ageing is not None and self.base is not None
        accel, gyro = provided(decoded.accel, decoded.gyro, decoded.unprovided)
        good = np.isfinite(np.concatenate([accel, gyro], axis=1)).all(axis=1)
        good &= ~disregarded(decoded.unprovided, good.shape[0], self.scene.input.reads_rate)
        expected = self.scene.input.frame_id
        if expected:
            good &= np.array([f == expected for f in decoded.frame_ids], bool)
        keep, _ = rising_or_back(decoded.stamps_ns, good, self._ageing_last_ns, self._back_ns)
        if keep.any():
            ns = decoded.stamps_ns[keep]
            self._ageing_last_ns = int(ns[-1])
            t = self.base.seconds(ns)
            jobs = self.ageing.add_foundation(ns, t, accel[keep], gyro[keep])
            self._ageing_jobs += jobs

    def take_ageing_jobs(self) -> list[WindowJob]:
        """The ageing windows due since the last call (`analysis.ageing_live.run_job` fits
        one), oldest first."""
        jobs, self._ageing_jobs = self._ageing_jobs, []
        return jobs

    def _foundation_rate(self, decoded: Decoded) -> np.ndarray:
        """The foundation's rate Ω_F (rad/s, F) of each decoded sample: its gyro in F, or
        zeros where the scene ignores it (input.gyro_filter: ignore)."""
        if not self.scene.input.reads_rate:
            return np.zeros((decoded.stamps_ns.shape[0], 3))
        with np.errstate(invalid="ignore", over="ignore"):  # a rejected sample's inf: unused
            return rotated(decoded.gyro, self.engine.model.sensor_rotation)

    def process_body(self, raws: Sequence[bytes]) -> list[tuple[str, int, bytes]]:
        """The body IMU's raw messages (sensor_msgs/Imu): the prediction and residual at each
        sample the twin has answered, and the windows judged (none without a body_sensor).
        A message that cannot be compared is counted (BodyCheck.counts) and skipped: not
        valid CDR, an unset or pre-1970 stamp, a stamp not after the last (one more than
        input.back_jump_reset_s before it restarts the comparison), a value not finite, a
        header.frame_id other than body_sensor.frame_id, both readings marked not provided
        (REP-145; one marked so, the sample is compared on the other)."""
        if self.body is None:
            return []
        decoded = decode_inputs(raws, IMU)
        self.body.counts["received"] += len(raws)
        measured = np.concatenate([decoded.accel, decoded.gyro], axis=1)
        reason = np.full(len(raws), "undecodable", dtype=object)
        reason[decoded.places()] = self.body.screen(
            decoded.stamps_ns, measured, decoded.frame_ids, decoded.unprovided
        )
        stamps_ns = np.zeros(len(raws), np.int64)
        stamps_ns[decoded.places()] = decoded.stamps_ns
        out = self._encode_body(self.body.screened(stamps_ns, reason))
        # the rejected counted (their window: `screened`, by their place in the body stream),
        # the accepted compared once the time base exists
        for start, stop in _runs(reason):
            if reason[start]:
                self.body.reject(reason[start], stop - start)
            elif self.base is None:  # no foundation sample yet: the time base waits for it
                self._hold_body(decoded.select(_within(decoded, start, stop)))
            else:
                out += self._body_in(decoded.select(_within(decoded, start, stop)))
        return out

    def _hold_body(self, decoded: Decoded) -> None:
        """Accepted body samples held until the first foundation sample sets the time base:
        at most `body_matching.PENDING_LIMIT`, the oldest dropped (`BodyCheck.over_limit`)."""
        assert self.body is not None
        self._body_waiting.append(decoded)
        cut = self.body.over_limit(sum(d.stamps_ns.shape[0] for d in self._body_waiting))
        while cut:
            n = self._body_waiting[0].stamps_ns.shape[0]
            if n <= cut:
                self._body_waiting.pop(0)
                cut -= n
            else:
                self._body_waiting[0] = self._body_waiting[0].select(np.arange(n) >= cut)
                cut = 0

    def _body_in(self, decoded: Decoded) -> list[tuple[str, int, bytes]]:
        """Accepted body samples into the comparison, on the twin's time base (a reading
        marked not provided zeroed, `provided`: never read as a value); into the ageing
        tracker, whose fits read the specific force, those that provide it (the others tell
        it where the stamps jumped back: `BodyCheck.screen` took them)."""
        assert self.body is not None and self.base is not None
        accel, gyro = provided(decoded.accel, decoded.gyro, decoded.unprovided)
        n = decoded.stamps_ns.shape[0]
        present = ~(np.zeros((n, 2), bool) if decoded.unprovided is None else decoded.unprovided)
        t = self.base.seconds(decoded.stamps_ns)
        if self.ageing is not None:
            jobs = self.ageing.add_body(decoded.stamps_ns, t, accel, gyro, present[:, 0])
            self._ageing_jobs += jobs
        rows = self.body.add_body(
            decoded.stamps_ns, t, np.concatenate([accel, gyro], axis=1), present
        )
        return self._encode_body(rows)

    def _encode_body(self, rows: BodyComparison) -> list[tuple[str, int, bytes]]:
        """The comparison's messages; its reports kept in body_reports."""
        reports = [
            HealthReport(stamp_ns * 1e-9, -1, [status]) for stamp_ns, status in rows.reports
        ]
        self.body_reports += reports
        return encode_body(self.scene, rows)

    def _encode(self, out: OutputBatch, stamps_ns: np.ndarray) -> list[Encoded]:
        """The outputs encoded (in blocks or one by one: `blocks`), keeping the last stamp
        answered."""
        if len(out):
            self._last_ns = int(stamps_ns[out.sample[-1]])
        if self.blocks:
            return encode_output_blocks(self.scene, out, stamps_ns, self._streams)
        return [*encode_outputs(self.scene, out, stamps_ns, self._streams)]

    def stalled(self, waited_s: float, stamp_ns: int) -> list[tuple[str, int, bytes]]:
        """A report now, after `waited_s` (s) of the node's clock without any (live only),
        stamped `stamp_ns` (the clock: there is no input stamp to answer)."""
        self._stalled_ns = max(self._stalled_ns, stamp_ns)
        return [encode_report(self.scene, self.engine.report_stalled(waited_s), stamp_ns)]

    def ended_without_input(self, source: str, stamp_ns: int) -> list[tuple[str, int, bytes]]:
        """The last report of a live stream that never received an input message (`finish`
        has none to give: its period is empty), stamped `stamp_ns` (the node's clock) or the
        last stall report's stamp if later: the stall report's statuses, the input status an
        ERROR saying `no input received on <source>`, with its counts (received 0). Live only:
        a replay of a bag without input has no stamp to put it at (its summary says so)."""
        report = self.engine.report_stalled(ENDED)
        report.statuses = [
            replace(s, level=ERROR, message=f"no input received on {source}")
            if s.name == INPUT
            else s
            for s in report.statuses
        ]
        self.final_report = report
        return [encode_report(self.scene, report, self._end_ns(stamp_ns))]

    def finish(self, clock_ns: int = 0) -> list[Encoded]:
        """The end of the stream (end of a bag, node shutdown): the outputs the gyro delay
        still holds, then the last, partial diagnostics period, stamped `_end_ns(clock_ns)`
        (`clock_ns`, ns: the node's clock now; a replay's, the input bag's log time of its
        last input message, `InputBag.last_log_ns`: the recorder's clock when the input
        ended); no report if that period is empty. The
        ageing tracker's end (the samples it could not pair, `AgeingTracker.finish`) comes
        with `take_ageing_jobs`. The body comparison's reports of the end that have no body
        stamp to take (every body message lost) take that stamp too."""
        out = self.engine.flush()
        reports, out.health = out.health, []
        kept, self._kept = self._kept, _Kept()
        numbered = kept.renumbered(out, self.engine.pushed)
        msgs = self._encode(numbered, kept.ns)
        if self.body is not None:
            rates = kept.rate[numbered.sample] if len(out) else np.zeros((0, 3))
            msgs += self._encode_body(
                self.body.add_rows(out.stamps, out.pose, out.wrenches, rates)
            )
            self.body.counts["unanswered"] += sum(len(d.stamps_ns) for d in self._body_waiting)
            self._body_waiting = []
            msgs += self._encode_body(self.body.finish(self._end_ns(clock_ns)))
        if self.ageing is not None:  # the samples it could not pair, where any
            self._ageing_jobs += self.ageing.finish()
        self.last_outputs = out
        self.final_report = reports[0] if reports else None
        return msgs + [encode_report(self.scene, r, self._end_ns(clock_ns)) for r in reports]

    def _end_ns(self, clock_ns: int) -> int:
        """The stamp (ns) of the reports at the end of the stream: the last input stamp
        answered (none answered: the last received; none with a stamp: `clock_ns`, the node's
        clock, as its stall reports are stamped, or a replay's bag's, where 0 had taken
        /diagnostics back to 1970), or the last stall report's if later (/diagnostics never
        goes back)."""
        return max(self._last_ns or self._received_ns or clock_ns, self._stalled_ns)


def _runs(values: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) of each run of equal neighbours in `values`, in order."""
    if not values.shape[0]:
        return []
    cuts = np.flatnonzero(values[1:] != values[:-1]) + 1
    return list(pairwise([0, *cuts.tolist(), values.shape[0]]))


def _within(decoded: Decoded, start: int, stop: int) -> np.ndarray:
    """Which decoded messages came at places [start, stop) of the raw messages (bool)."""
    places = decoded.places()
    return (places >= start) & (places < stop)
