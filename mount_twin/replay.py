"""Offline adapter: replay a bag's input topic through the twin into an mcap bag."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import nullcontext
from dataclasses import dataclass, replace
from itertools import chain
from pathlib import Path

import numpy as np
from tqdm import tqdm

from mount_twin.analysis.ageing_live import WindowJob, run_job
from mount_twin.analysis.figures import displacement_from_start, mount_travel, peak_magnitudes
from mount_twin.engine.batch import HealthReport, HealthStatus, OutputBatch
from mount_twin.engine.tilt import tilt_from_quaternions
from mount_twin.errors import BagError, DamagedBagError, require
from mount_twin.io.input_bag import InputBag
from mount_twin.io.messages import DIAGNOSTICS_TOPIC, IMU, NODE_NAME, TF, TF_STATIC_TOPIC, resolve
from mount_twin.io.output_bag import LATCHED_QOS, OutputBag, check_new_bag
from mount_twin.io.output_encoding import Encoded, RowBlock, encode_report, static_transforms
from mount_twin.io.output_topics import output_types
from mount_twin.io.scene_record import SCENE_TOPIC, STRING, scene_message, scene_metadata
from mount_twin.physics.rotations import quaternion_matrices
from mount_twin.replay_summary import ReplaySummary, keep_worst
from mount_twin.scene.description import Scene
from mount_twin.stream import TwinStream


def _until_damage(
    chunks: Iterator[Sequence[bytes]], damage: list[DamagedBagError]
) -> Iterator[Sequence[bytes]]:
    """The chunks up to a damaged bag's damage, which is put in `damage` rather than raised."""
    try:
        yield from chunks
    except DamagedBagError as err:
        damage.append(err)


def _checked(
    chunks: Iterator[Sequence[bytes]], checkpoint: Callable[[], None] | None
) -> Iterator[Sequence[bytes]]:
    """The chunks, `checkpoint` called before each (a stop noted ends the replay there: a
    body IMU's bag, however much of it is left past the input's end, is not read to its end
    first)."""
    for chunk in chunks:
        if checkpoint is not None:
            checkpoint()
        yield chunk


@dataclass
class _Figures:
    """Figures of the published rows so far: per mount peak |F| (N) and |M| (N·m) and travel
    (m; of mounts at `points`, m in F, under a body whose scene CG is `cg`), largest tilt (rad)
    and CG displacement from the first published position (m), first and last stamps (s,
    engine time)."""

    peak: np.ndarray
    cg: np.ndarray
    points: np.ndarray
    travel: np.ndarray
    tilt: float = 0.0
    disp: float = 0.0
    first_stamp: float | None = None
    last_stamp: float | None = None
    start: np.ndarray | None = None

    def add(self, batch: OutputBatch) -> None:
        """Fold in a batch of published rows (an empty one changes nothing)."""
        if not len(batch):
            return
        self.first_stamp = batch.stamps[0] if self.first_stamp is None else self.first_stamp
        start = batch.position[0].copy() if self.start is None else self.start
        self.start = start
        self.last_stamp = batch.stamps[-1]
        np.maximum(self.peak, peak_magnitudes(batch.wrenches), out=self.peak)
        rotation = quaternion_matrices(batch.quaternion)
        travel = mount_travel(batch.position, rotation, self.cg, self.points)
        np.maximum(self.travel, travel, out=self.travel)
        self.disp = max(self.disp, displacement_from_start(batch.position, start))
        self.tilt = max(self.tilt, float(tilt_from_quaternions(batch.quaternion).max()))

    @property
    def span_s(self) -> float:
        """Stamps spanned by the rows, s (0 without rows)."""
        if self.first_stamp is None or self.last_stamp is None:
            return 0.0
        return float(self.last_stamp - self.first_stamp)


def _open(
    scene: Scene,
    input_path: str | Path,
    output_path: str | Path,
    checkpoint: Callable[[], None] | None,
) -> tuple[InputBag, TwinStream]:
    """The input bag, opened, and the twin, built once the output bag is known to be new; the
    input bag is closed again if that fails or `checkpoint` raises."""
    bag = InputBag(input_path, scene.input.topic, scene.input.msg_type)
    try:
        check_new_bag(output_path)
        stream = TwinStream(scene, blocks=True)
        if checkpoint is not None:  # a signal while the twin was built: no output bag yet
            checkpoint()
    except BaseException:
        bag.close()
        raise
    return bag, stream


def _encoded(scene: Scene, report: HealthReport, job: WindowJob) -> bytes:
    return encode_report(scene, report, job.stamp_ns)[2]


BODY_KEYS = ("body_sensor.topic; `replay --body` reads another bag", "a body_sensor (an IMU)")


def _body_bag(
    scene: Scene, input_path: str | Path, body_path: str | Path | None
) -> InputBag | None:
    """The body IMU's bag: `body_path`'s body_sensor.topic, else the input bag's if it has it
    (None: no body_sensor, or no such topic in the input bag)."""
    sensor = scene.body_sensor
    if sensor is None:
        if body_path is not None:
            msg = f"{body_path}: the scene has no body_sensor to compare it with"
            raise BagError(msg)
        return None
    if body_path is not None:
        return InputBag(body_path, sensor.topic, IMU, BODY_KEYS)
    try:
        return InputBag(input_path, sensor.topic, IMU, BODY_KEYS)
    except BagError as err:
        if "no topic" in str(err) or "no message" in str(err):
            return None  # the replay's summary says the body IMU was not in the bag
        raise


def replay(
    scene: Scene,
    input_path: str | Path,
    output_path: str | Path,
    *,
    chunk: int = 2000,
    progress: bool = True,
    checkpoint: Callable[[], None] | None = None,
    body_path: str | Path | None = None,
) -> ReplaySummary:
    """Replay `input_path`'s scene.input.topic into a new mcap bag at `output_path`.

    The output holds what the node publishes: the scene's outputs (`output_types`), and the
    mount frames on /tf_static and the scene on ~/scene (`io.scene_record`) once, before
    anything else, stamped with the first output's stamp (that of the first input sample the
    stream took: never an unset or pre-1970 one; none taken, the end's, the input's last log
    time) and offered latched (`LATCHED_QOS`) so `ros2 bag play` republishes them to late
    subscribers; its metadata records the scene too (`scene_metadata`: its source, file,
    overrides and digest), which `report --scene` checks its scene against. Both bags are
    checked before the twin is built. `checkpoint` is called once it is built and between chunks
    (the input's and the body IMU's), where stopping is safe: it may raise to stop the replay (a
    signal noted by the command line); once the output bag exists, it is then finished and
    marked partial.

    With a body_sensor, its IMU (body_sensor.topic of `body_path`, else of the input bag if it
    has it) is compared with the twin as the node compares it live (`TwinStream.process_body`):
    it is fed after each input chunk up to that chunk's last stamp. A `chunk` below 1 message
    is a ValueError, before anything is opened (0 had looped for ever on empty chunks).
    """
    require(scene, Scene, "replay(scene)")
    if isinstance(chunk, bool) or not isinstance(chunk, int) or chunk < 1:
        msg = f"chunk: must be an integer ≥ 1 message, got {chunk!r}"
        raise ValueError(msg)
    bag, stream = _open(scene, input_path, output_path, checkpoint)
    try:
        body_bag = _body_bag(scene, input_path, body_path)
    except BaseException:
        bag.close()
        raise
    types = output_types(scene) | {TF_STATIC_TOPIC: TF, SCENE_TOPIC: STRING}
    resolved = {t: resolve(t, NODE_NAME) for t in types}
    topics = {resolved[t]: msgtype for t, msgtype in types.items()}
    static_due = True
    n = len(scene.mounts)
    points = np.array([m.position for m in scene.mounts]).reshape(-1, 3)
    figures = _Figures(np.zeros((n, 2)), np.array(scene.body.cg), points, np.zeros(n))
    wall0 = time.perf_counter()
    worst: dict[str, HealthStatus] = {}
    with (
        bag,
        body_bag or nullcontext(),
        OutputBag(
            output_path,
            topics,
            {resolved[t]: [LATCHED_QOS] for t in (TF_STATIC_TOPIC, SCENE_TOPIC)},
            scene_metadata(scene),
        ) as out,
        tqdm(total=bag.count, unit="msg", disable=not progress, desc="replay", leave=False) as bar,
    ):
        # the chunks, then the end (also where a damaged bag ends): the outputs the gyro delay
        # holds and the last, partial diagnostics period
        damage: list[DamagedBagError] = []
        body_chunks = (
            _checked(_until_damage(body_bag.chunks(chunk), damage), checkpoint)
            if body_bag
            else iter(())
        )
        for raws in chain(_until_damage(bag.chunks(chunk), damage), [None]):
            if checkpoint is not None:
                checkpoint()
            outputs: list[Encoded]
            if raws is None:  # the body IMU's rest, then the end
                outputs = [m for b in body_chunks for m in stream.process_body(b)]
                outputs += stream.finish(bag.last_log_ns)  # where no input stamp came
            else:
                outputs = stream.process(raws)
                while stream.body_behind and (body := next(body_chunks, None)) is not None:
                    outputs += stream.process_body(body)
            if static_due and outputs:
                first = outputs[0]
                stamp = int(first.stamps_ns[0]) if isinstance(first, RowBlock) else first[1]
                once = (static_transforms(scene, stamp), scene_message(scene, stamp))
                out.write([(resolved[topic], at, data) for topic, at, data in once])
                static_due = False
            out.write(
                [
                    m.renamed(resolved) if isinstance(m, RowBlock) else (resolved[m[0]], *m[1:])
                    for m in outputs
                ]
            )
            if (batch := stream.last_outputs) is not None:
                figures.add(batch)
                for report in batch.health:
                    keep_worst(worst, report)
            for report in stream.take_body_reports():
                keep_worst(worst, report)
            for job in stream.take_ageing_jobs():  # a fit each: seconds
                report = run_job(job)
                out.write(
                    [(resolved[DIAGNOSTICS_TOPIC], job.stamp_ns, _encoded(scene, report, job))]
                )
                keep_worst(worst, report)
            bar.update(len(raws or ()))
        if stream.final_report is not None:
            keep_worst(worst, stream.final_report)
        written = out.written
        if damage:  # raised with the replay up to it (the bag is then marked partial)
            wall = time.perf_counter() - wall0
            up_to = _summary(scene, input_path, output_path, stream, figures, worst, written, wall)
            damage[0].summary = replace(up_to, damaged=str(damage[0]))
            raise damage[0]
    wall = time.perf_counter() - wall0
    return _summary(scene, input_path, output_path, stream, figures, worst, written, wall)


def _summary(
    scene: Scene,
    input_path: str | Path,
    output_path: str | Path,
    stream: TwinStream,
    figures: _Figures,
    worst: dict[str, HealthStatus],
    written: int,
    wall_s: float,
) -> ReplaySummary:
    """The summary of a replay that wrote `written` messages in `wall_s` seconds."""
    engine = stream.engine
    return ReplaySummary(
        str(input_path),
        str(output_path),
        dict(engine.counts),
        written,
        figures.span_s,
        wall_s,
        {m.name: figures.peak[i] for i, m in enumerate(scene.mounts)},
        figures.tilt,
        figures.disp,
        worst,
        list(engine.events),
        engine.utilisation_max,
        engine.health.origin_s,
        engine.health.last_wrong_frame_id,
        float(figures.first_stamp) if figures.first_stamp is not None else 0.0,
        engine.error_estimate,
        engine.failure_text,
        engine.health.latency,
        {m.name: float(figures.travel[i]) for i, m in enumerate(scene.mounts)},
        None if stream.body is None else dict(stream.body.counts),
        scene.body_sensor.topic if scene.body_sensor else "",
        decimation=scene.outputs.decimation,
        never_started=engine.health.never_started(engine.counts),
        ageing_counts=None if stream.ageing is None else stream.ageing.counts,
    )
