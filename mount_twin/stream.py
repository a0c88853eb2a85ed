"""One path for every sample, live or offline: raw CDR in, raw CDR out.

`TwinStream` is what both adapters drive: the rclpy node hands it each raw message it receives,
the bag replay hands it chunks of raw messages from a bag. Only the transport differs.
"""

from __future__ import annotations

import numpy as np

from mount_twin.engine.batch import HealthReport, OutputBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.errors import require
from mount_twin.io.messages import TimeBase, decode_inputs, encode_outputs, encode_report
from mount_twin.model.assemble import assemble
from mount_twin.scene.description import Scene


class TwinStream:
    """Decode → engine → encode for one scene.

    Attributes:
        engine: the streaming engine (counts, state, health).
        last_outputs: the engine's last OutputBatch (for summaries and plots).
    """

    def __init__(self, scene: Scene) -> None:
        require(scene, Scene, "TwinStream(scene)")
        self.scene = scene
        self.engine = TwinEngine(assemble(scene))
        # rosbags generates a type's serializer at its first use and the output layouts are
        # probed then: ~40 ms that would otherwise delay the first live sample.
        encode_outputs(scene, OutputBatch.empty(len(scene.mounts)), np.zeros(0, np.int64))
        self.base: TimeBase | None = None
        self.last_outputs: OutputBatch | None = None
        self._last_ns = 0
        self._received_ns = 0
        """Stamp (ns) of the last sample received with a stamp (> 0), accepted or not."""
        self._tail_ns = np.zeros(0, np.int64)
        """Stamps (ns) of the last samples pushed that later outputs may answer
        (`TwinEngine.lookback`: the gyro delay, a sample held back), oldest first."""
        self.final_report: HealthReport | None = None

    def process(self, raws: list[bytes]) -> list[tuple[str, int, bytes]]:
        """Outputs for raw input messages, as (unresolved topic, stamp ns, CDR bytes)."""
        decoded = decode_inputs(raws, self.scene.input.msg_type)
        if decoded.undecodable:
            self.engine.count("received", decoded.undecodable)
            self.engine.count("rejected_undecodable", decoded.undecodable)
        # An unset header.stamp has no time to place the sample at; one before 1970 (sec < 0,
        # which builtin_interfaces/Time allows) cannot be written to a bag or answered.
        # Both masks are taken before either selects: each is of the messages as decoded.
        for reason, bad in (
            ("zero_stamp", decoded.stamps_ns == 0),
            ("negative_stamp", decoded.stamps_ns < 0),
        ):
            if bad.any():
                self.engine.count("received", int(bad.sum()))
                self.engine.count(f"rejected_{reason}", int(bad.sum()))
        if (decoded.stamps_ns <= 0).any():
            decoded = decoded.select(decoded.stamps_ns > 0)
        if decoded.stamps_ns.shape[0]:
            self._received_ns = int(decoded.stamps_ns[-1])
        if self.base is None:
            if not decoded.stamps_ns.shape[0]:
                return []
            self.base = TimeBase.at(int(decoded.stamps_ns[0]))
            self.engine.health.origin_s = self.base.origin_ns // 1_000_000_000
        out = self.engine.push(decoded.batch(self.base))
        self.last_outputs = out
        # Rows of samples of earlier pushes (the gyro delay, a sample held back) come as
        # negative samples: the earlier stamps appended find them (−1: the last one).
        stamps_ns = np.concatenate([decoded.stamps_ns, self._tail_ns])
        tail = np.concatenate([self._tail_ns, decoded.stamps_ns])
        self._tail_ns = tail[tail.shape[0] - self.engine.lookback :]
        return self._encode(out, stamps_ns)

    def _encode(self, out: OutputBatch, stamps_ns: np.ndarray) -> list[tuple[str, int, bytes]]:
        """encode_outputs, keeping the last stamp answered."""
        if len(out):
            self._last_ns = int(stamps_ns[out.sample[-1]])
        return encode_outputs(self.scene, out, stamps_ns)

    def stalled(self, waited_s: float, stamp_ns: int) -> list[tuple[str, int, bytes]]:
        """A report now, after `waited_s` (s) of the node's clock without any (live only),
        stamped `stamp_ns` (the clock: there is no input stamp to answer)."""
        return [encode_report(self.scene, self.engine.report_stalled(waited_s), stamp_ns)]

    def finish(self) -> list[tuple[str, int, bytes]]:
        """The end of the stream (end of a bag, node shutdown): the outputs the gyro delay
        still holds, then the last, partial diagnostics period, stamped with the last input
        stamp answered (none answered: the last received; none with a stamp: 0); no report if
        that period is empty."""
        out = self.engine.flush()
        reports, out.health = out.health, []
        msgs = self._encode(out, self._tail_ns)
        self._tail_ns = self._tail_ns[:0]
        self.last_outputs = out
        self.final_report = reports[0] if reports else None
        stamp_ns = self._last_ns or self._received_ns
        return msgs + [encode_report(self.scene, r, stamp_ns) for r in reports]
