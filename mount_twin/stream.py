"""One path for every sample, live or offline: raw CDR in, raw CDR out.

`TwinStream` is what both adapters drive: the rclpy node hands it each raw message it receives,
the bag replay hands it chunks of raw messages from a bag. Only the transport differs.
"""

from __future__ import annotations

import numpy as np

from mount_twin.engine.batch import HealthReport, OutputBatch
from mount_twin.engine.engine import TwinEngine
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
        self._held_ns = 0
        """Stamp (ns) of the sample the engine holds back (see TwinEngine.holding)."""
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
        held = self.engine.holding
        out = self.engine.push(decoded.batch(self.base))
        self.last_outputs = out
        # Rows and reports of the sample held back from the last push come as sample −1: the
        # stamps get its stamp appended, where index −1 finds it.
        stamps_ns = np.append(decoded.stamps_ns, self._held_ns) if held else decoded.stamps_ns
        if self.engine.holding and len(decoded.stamps_ns):
            self._held_ns = int(decoded.stamps_ns[-1])
        if len(out):
            self._last_ns = int(stamps_ns[out.sample[-1]])
        return encode_outputs(self.scene, out, stamps_ns)

    def stalled(self, waited_s: float, stamp_ns: int) -> list[tuple[str, int, bytes]]:
        """A report now, after `waited_s` (s) of the node's clock without any (live only),
        stamped `stamp_ns` (the clock: there is no input stamp to answer)."""
        return [encode_report(self.scene, self.engine.report_stalled(waited_s), stamp_ns)]

    def finish(self) -> list[tuple[str, int, bytes]]:
        """The last, partial diagnostics period (end of a bag, node shutdown), stamped with the
        last input stamp answered (none answered: the last received; none with a stamp: 0);
        nothing if that period is empty."""
        report = self.final_report = self.engine.flush()
        if report is None:
            return []
        return [encode_report(self.scene, report, self._last_ns or self._received_ns)]
