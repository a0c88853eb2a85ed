"""The rclpy node of the twin: foundation IMU in through raw subscriptions, the twin's
outputs out through its byte publishers (`ros/outputs.py`), diagnostics when input stalls, the
problems only a live node sees, and the shutdown. Parameters: `ros/parameters.py`; the
process around it: `ros/process.py`.

Moves raw CDR bytes only (raw subscription, byte publishers) so that every (de)serialization is
the rosbags code the bag replay and the tests run.

Input is taken in bulk: each wake-up of the executor takes every message waiting in the
subscription's queue (`take_waiting`) and pushes them through the engine in one call, so the
node keeps up with kHz sensors; with `batch_period_s > 0` they are queued and processed on a
steady-clock timer instead. Diagnostics come from the engine at each period of input stamps; a
period of the node's clock (wall or sim time) without any report or accepted sample publishes a
report saying why (no input, all rejected and why), and problems only the live node can see
(a publisher of the wrong type, sim time without /clock) go out as `mount_twin: ros`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from rclpy.clock import Clock, ClockType
from rclpy.event_handler import QoSMessageLostInfo, SubscriptionEventCallbacks
from rclpy.exceptions import InvalidParameterTypeException
from rclpy.qos import HistoryPolicy, QoSPolicyKind, QoSProfile, ReliabilityPolicy
from rclpy.qos_overriding_options import QoSOverridingOptions
from rclpy.subscription import Subscription
from rclpy.timer import Timer

from mount_twin.engine.batch import ERROR, OK, HealthReport, HealthStatus
from mount_twin.engine.body_counts import MIDDLEWARE, STOPPED
from mount_twin.errors import MountTwinError
from mount_twin.io.messages import DIAGNOSTICS_TOPIC, IMU, NODE_NAME
from mount_twin.io.output_encoding import encode_report, messages_of
from mount_twin.ros.outputs import OutputNode, message_class
from mount_twin.ros.parameters import built_in_type_error, check_qos_overrides, configure
from mount_twin.ros.rclpy_private import take_waiting
from mount_twin.stream import TwinStream

if TYPE_CHECKING:
    from rclpy.parameter import Parameter

    from mount_twin.ros.ageing_fits import AgeingFits
    from mount_twin.ros.start import StopRequests

TAKE_LIMIT = 100_000
"""Most input messages taken in one wake-up."""
SHUTDOWN_CHUNK = 1000
"""Input messages processed in one call at shutdown, between which a second stop is seen."""
FIT_POLL_S = 0.2
"""Steady-clock period at which finished ageing fits are published."""
WATCH_PERIOD_S = 1.0
"""Steady-clock period of the checks only a live node can make (publisher types, /clock)."""
TIMER_MAX_S = 9.0e9
"""Longest period (s) an rclpy timer takes (int64 ns: 292 years), and one no node lives to see
end: a longer stall period (the scene takes any finite diagnostics period) waits this long."""


class MountTwinNode(OutputNode):
    """Foundation acceleration in; pose, α/γ/δ, mount wrenches, TF and diagnostics out.

    Raises:
        MountTwinError: a parameter, scene file or topic name is wrong (the message names it).
    """

    def __init__(self, args: Sequence[str] = (), **kwargs: Any) -> None:
        """`args`: the process's command line (its `-p` outrank a params file's section)."""
        try:
            super().__init__(NODE_NAME, **kwargs)
        except InvalidParameterTypeException as err:  # raised from rclpy's own declarations
            raise built_in_type_error(self, err) from err
        self.options, self.scene = configure(self, args)
        self.stream = TwinStream(self.scene)
        self._pubs = self._create_outputs()
        self._scene_pub = self._publish_scene()
        self._pending: list[bytes] = []
        self._sub = self._create_input()
        self._body_sub = self._create_body_input()
        check_qos_overrides(self)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._batch_timer: Timer | None = None
        if self.options.batch_period_s > 0.0:  # running while input comes (`_on_input`)
            self._batch_timer = self.create_timer(
                self.options.batch_period_s, self._drain, clock=steady
            )
            self._batch_timer.cancel()
        self._reports = 0
        self._accepted_at_tick = 0
        stall_s = min(self.options.stall_period(self.scene), TIMER_MAX_S)
        self.create_timer(stall_s, self._on_stall_period)
        self._problems: dict[str, str] = {}
        """Problems seen by events (kept); `_watch` adds the ones it finds each time."""
        self._reported: dict[str, str] = {}
        self._started = time.monotonic()
        self._sim_since: float | None = self._started if self._sim_time() else None
        """Steady time (s) since which use_sim_time is true (None: false): a /clock missing is
        counted from then, whether set at the start or later (`ros2 param set`)."""
        self.add_post_set_parameters_callback(self._on_parameters_set)
        self.create_timer(WATCH_PERIOD_S, self._watch, clock=steady)
        self._fits: AgeingFits | None = None
        if self.scene.ageing is not None:  # the fit's modules, only for a scene that tracks
            from mount_twin.ros.ageing_fits import AgeingFits

            self._fits = AgeingFits(self.scene)
            self.create_timer(FIT_POLL_S, self._publish_fits, clock=steady)
        self.get_logger().info(
            f"scene {self.scene.name!r} from {self.scene.source}: "
            f"{len(self.scene.mounts)} mounts, DOFs {list(self.scene.dofs)}; input "
            f"{self._sub.topic_name} ({self.scene.input.msg_type}, "
            f"{self._sub.qos_profile.reliability.name.lower()}, depth "
            f"{self.options.input_queue_depth}); "
            + (f"batches every {self.options.batch_period_s} s; " if self._batch_timer else "")
            + (f"body IMU {self._body_sub.topic_name}; " if self._body_sub else "")
            + "outputs "
            + ", ".join(p.topic_name for p in self._pubs.values())
        )
        for warning in self.stream.scene.warnings:  # implausible: units? the start's ratings?
            self.get_logger().warning(str(warning))

    def _create_input(self) -> Subscription:
        """The foundation IMU's raw subscription, with its message-lost and type events."""
        events = SubscriptionEventCallbacks(
            message_lost=self._on_lost, incompatible_type=self._on_incompatible_type
        )
        spec = self.scene.input
        return self._subscribe("input.topic", spec.topic, spec.msg_type, self._on_input, events)

    def _create_body_input(self) -> Subscription | None:
        """The body IMU's raw subscription (the scene's body_sensor; none without one)."""
        sensor = self.scene.body_sensor
        if sensor is None:
            return None
        events = SubscriptionEventCallbacks(message_lost=self._on_body_lost)
        return self._subscribe("body_sensor.topic", sensor.topic, IMU, self._on_body, events)

    def _subscribe(
        self,
        parameter: str,
        topic: str,
        msgtype: str,
        callback: Callable[[bytes], None],
        events: SubscriptionEventCallbacks,
    ) -> Subscription:
        """A raw input subscription: best effort (a sensor stream), keep last
        input_queue_depth, unless `qos_overrides.<topic>.subscription.reliability` (ROS 2's
        QoS override parameter) says reliable, for a publisher whose every message must count.
        A topic name rclpy refuses names `parameter`."""
        qos = QoSProfile(
            depth=self.options.input_queue_depth,
            reliability=ReliabilityPolicy.BEST_EFFORT,
            history=HistoryPolicy.KEEP_LAST,
        )
        override = f"qos_overrides.{self.resolve_topic_name(topic)}.subscription.reliability"
        try:
            return self._named(
                parameter,
                lambda: self.create_subscription(
                    message_class(msgtype),
                    topic,
                    callback,
                    qos,
                    raw=True,
                    event_callbacks=events,
                    qos_overriding_options=QoSOverridingOptions([QoSPolicyKind.RELIABILITY]),
                ),
            )
        except (RuntimeError, InvalidParameterTypeException) as err:  # rclpy's override check
            msg = f"{self.get_fully_qualified_name()}: {override}: expected 'best_effort' or "
            raise MountTwinError(f"{msg}'reliable' ({err})".replace("\n", " ")) from err

    def _on_input(self, raw: bytes) -> None:
        raws = [raw, *take_waiting(self._sub, TAKE_LIMIT)]
        if self._batch_timer is None:
            self._process(raws)
            return
        if self._batch_timer.is_canceled():  # the first message since the input paused
            self._batch_timer.reset()
        self._pending.extend(raws)

    def _on_body(self, raw: bytes) -> None:
        assert self._body_sub is not None
        self._process_body([raw, *take_waiting(self._body_sub, TAKE_LIMIT)])

    def _process_body(self, raws: list[bytes]) -> None:
        """Body IMU messages through the comparison; its outputs published."""
        self._publish(self.stream.process_body(raws))
        self._submit_fits()

    def _drain(self) -> None:
        """Process the batch; with none, stop the batch timer until input comes again (a
        timer running while no input comes woke the executor for nothing: a wake-up costs
        rclpy's executor about a millisecond of CPU, 20 % of a core at 5 ms)."""
        if self._pending:
            raws, self._pending = self._pending, []
            self._process(raws)
        elif self._batch_timer is not None:
            self._batch_timer.cancel()

    def _process(self, raws: list[bytes]) -> None:
        """Input through the twin; its outputs published, its diagnostics reports counted."""
        messages = messages_of(self.stream.process(raws))
        self._reports += sum(topic == DIAGNOSTICS_TOPIC for topic, _, _ in messages)
        self._publish(messages)
        self._submit_fits()

    def _submit_fits(self) -> None:
        """The ageing windows now due, to the worker process."""
        if self._fits is not None:
            for job in self.stream.take_ageing_jobs():
                self._fits.submit(job)

    def _publish_fits(self) -> None:
        """The ageing reports whose fits are done, in window order."""
        if self._fits is not None:
            self._publish(self._fits.done())

    def _on_stall_period(self) -> None:
        """A stall period of the node's clock (`stall_period_s`): if it brought no input
        report (stamp-driven) and no accepted sample, report now, saying why."""
        accepted = self.stream.engine.counts["accepted"]
        if self._reports == 0 and accepted == self._accepted_at_tick:
            now = self.get_clock().now().nanoseconds
            period = self.options.stall_period(self.scene)
            self._publish(self.stream.stalled(period, now))
        self._reports = 0
        self._accepted_at_tick = accepted

    def _on_lost(self, info: QoSMessageLostInfo) -> None:
        self.stream.engine.count("lost_middleware", int(info.total_count_change))

    def _on_body_lost(self, info: QoSMessageLostInfo) -> None:
        if self.stream.body is not None:
            self.stream.body.counts[MIDDLEWARE] += int(info.total_count_change)

    def _on_incompatible_type(self, _info: object) -> None:
        self._problems["incompatible_type"] = (
            f"a publisher on {self._sub.topic_name} has a type other than "
            f"{self.scene.input.msg_type}: it never connects"
        )

    def _sim_time(self) -> bool:
        return bool(self.get_parameter("use_sim_time").value)

    def _on_parameters_set(self, parameters: list[Parameter]) -> None:
        """use_sim_time switched on (or off) at run time: a missing /clock counts from now."""
        if any(p.name == "use_sim_time" for p in parameters):
            self._sim_since = time.monotonic() if self._sim_time() else None

    def _watch(self) -> None:
        """Problems only a live node sees, published as `mount_twin: ros` while they last."""
        found = dict(self._problems)
        expected = self.scene.input.msg_type
        for info in self.get_publishers_info_by_topic(self._sub.topic_name):
            if info.topic_type != expected:
                found[f"type {info.node_name}"] = (
                    f"publisher {info.node_namespace.rstrip('/')}/{info.node_name} sends "
                    f"{info.topic_type} on {self._sub.topic_name}, expected {expected}: it never "
                    "connects"
                )
        sim_since = self._sim_since
        waited = math.nan if sim_since is None else time.monotonic() - sim_since
        if self.get_clock().now().nanoseconds == 0 and waited > 2.0 * WATCH_PERIOD_S:
            found["clock"] = (
                f"use_sim_time is true and no /clock has come for {waited:.0f} s: diagnostics "
                "wait for it (play bags with `ros2 bag play --clock`)"
            )
        if not found and not self._reported:
            return
        for key, text in found.items():
            if key not in self._reported:  # once a problem: the clock's text counts seconds
                self.get_logger().warning(text)
        status = HealthStatus(
            f"{NODE_NAME}: ros", ERROR if found else OK, "; ".join(found.values()) or "ok", {}
        )
        report = HealthReport(math.nan, -1, [status])
        self._publish([encode_report(self.scene, report, self.get_clock().now().nanoseconds)])
        self._reported = found

    def finish(self, stops: StopRequests) -> bool:
        """Take what is still waiting, process the queue, publish the last, partial
        diagnostics period (where no input message ever came, a last report saying so, on
        which topic, at ERROR: a run that produced nothing never reads as fine), and wait (up
        to SHUTDOWN_ACK_S) until every reliable subscriber has acknowledged it all; a topic
        still unacknowledged then is named in a warning.

        A second stop (`stops.hurried`) skips what is left: the input and body IMU messages
        not yet processed (counted `lost_unprocessed_at_stop` in the last report, which still
        goes out with the gyro filter's delayed samples, and in the body comparison's last
        status), the ageing fits still running and the wait for acknowledgements, each said in
        a warning. True where it skipped any."""
        raws = [*self._pending, *take_waiting(self._sub, TAKE_LIMIT)]
        self._pending = []
        unprocessed = self._until_stopped(raws, self._process, stops, "input", self._sub)
        if unprocessed:  # the input's count named as the body's
            self.stream.engine.count(STOPPED, unprocessed)
        body_unprocessed = 0
        if self._body_sub is not None and self.stream.body is not None:
            body = take_waiting(self._body_sub, TAKE_LIMIT)
            body_unprocessed = self._until_stopped(
                body, self._process_body, stops, "body IMU", self._body_sub
            )
            self.stream.body.counts[STOPPED] += body_unprocessed
        now = self.get_clock().now().nanoseconds  # the end's stamp where no input has one
        self._publish(messages_of(self.stream.finish(now)))
        if not self.stream.engine.counts["received"]:  # nothing to report on: say so, ERROR
            life = time.monotonic() - self._started
            source = (
                f"{self._sub.topic_name} ({self.scene.input.msg_type}) over the node's life "
                f"({life:.1f} s)"
            )
            if unprocessed:
                source += f", {unprocessed} waiting at the second stop were not processed"
            self._publish(self.stream.ended_without_input(source, now))
        self._submit_fits()
        fits_cut = False
        if self._fits is not None:
            self._publish(self._fits.done(wait=True, give_up=lambda: stops.hurried))
            fits_cut = self._fits.not_waited_for > 0
            if fits_cut:
                self.get_logger().warning(
                    f"shutdown: stopped again: {self._fits.not_waited_for} ageing fits were not "
                    "waited for (their reports say so, ERROR)"
                )
        skipped = unprocessed > 0 or body_unprocessed > 0 or fits_cut
        return self._wait_for_acks(stops) or skipped

    def _until_stopped(
        self,
        raws: list[bytes],
        process: Callable[[list[bytes]], None],
        stops: StopRequests,
        what: str,
        sub: Subscription,
    ) -> int:
        """`process` the messages `raws` waiting at shutdown on `sub` (`what`: whose), in
        chunks of SHUTDOWN_CHUNK, until a second stop; how many were left unprocessed (said
        in a warning)."""
        for start in range(0, len(raws), SHUTDOWN_CHUNK):
            if stops.hurried:
                unprocessed = len(raws) - start
                self.get_logger().warning(
                    f"shutdown: stopped again: {unprocessed} {what} messages waiting on "
                    f"{sub.topic_name} were not processed"
                )
                return unprocessed
            process(raws[start : start + SHUTDOWN_CHUNK])
        return 0
