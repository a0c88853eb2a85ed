"""TwinEngine input health: empty pushes, non-finite samples without numpy warnings, samples lost
(estimated from stamp holes, and reported by adapters), wrong frame_ids named, and the report a
live node publishes when its input stalls.

Every expected count is constructed by the test (holes cut, frames set), never read back from the
engine.
"""

from __future__ import annotations

import gc
import math
import tracemalloc
import warnings
from collections import Counter

import numpy as np
import pytest
from io_helpers import batch, default_model, default_scene, scene_with, split

from mount_twin.engine.batch import ERROR, OK, WARN, HealthReport, HealthStatus, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.health import WRONG_FRAMES_COUNTED, _median
from mount_twin.io.messages import DIAGNOSTICS_TOPIC
from mount_twin.io.output_encoding import imu_messages
from mount_twin.model.assemble import assemble
from mount_twin.scene import Scene
from mount_twin.stream import TwinStream

RATE = 1000.0  # Hz
DT = 1.0 / RATE  # s


def engine(scene: Scene | None = None) -> TwinEngine:
    """A fresh engine whose wall clock stands still, so its reports are deterministic."""
    model = default_model() if scene is None or scene == default_scene() else assemble(scene)
    return TwinEngine(model, clock=lambda: 0.0)


def ramp(n: int, t0: float = 0.0) -> np.ndarray:
    """n stamps at RATE from t0, s."""
    return t0 + np.arange(n) / RATE


def push_all(eng: TwinEngine, parts: list[SampleBatch]) -> list[HealthReport]:
    """Push each part; return every report, in order."""
    return [r for p in parts for r in eng.push(p).health]


def status(report: HealthReport, which: str = "input") -> HealthStatus:
    (st,) = [s for s in report.statuses if s.name == f"mount_twin: {which}"]
    return st


def without(stamps: np.ndarray, holes: list[int]) -> np.ndarray:
    return np.delete(stamps, holes)


# --------------------------------------------------------------------------- empty batches


def empty_batch(malformed: bool = False) -> SampleBatch:
    """No samples; `malformed`: 1-D accel and gyro, as a decoder may build them from nothing."""
    shape = (0,) if malformed else (0, 3)
    return SampleBatch(np.zeros(0), np.zeros(shape), np.zeros(shape), [])


@pytest.mark.parametrize("malformed", [False, True], ids=["shaped", "flat"])
def test_empty_push_before_the_start_changes_nothing(malformed: bool) -> None:
    eng = engine()
    out = eng.push(empty_batch(malformed))
    assert len(out) == 0 and out.sample.shape == (0,) and out.health == []
    assert out.pose.shape == (0, 10) and out.wrenches.shape == (0, 8, 6)
    assert dict(eng.counts) == {} and not eng.running
    flushed = eng.flush()
    assert len(flushed) == 0 and flushed.health == []
    # and the twin then starts as if the empty push never happened
    got = eng.push(batch(ramp(5))).pose
    np.testing.assert_array_equal(got, engine().push(batch(ramp(5))).pose)


@pytest.mark.parametrize("malformed", [False, True], ids=["shaped", "flat"])
def test_empty_push_into_a_running_twin_changes_nothing(malformed: bool) -> None:
    scene = scene_with(outputs={"diagnostics_period_s": 0.05})
    eng, ref = engine(scene), engine(scene)
    first, second = batch(ramp(120)), batch(ramp(120, t0=0.12))
    eng.push(first)
    ref.push(first)
    counts, state = eng.counts.copy(), eng.state
    out = eng.push(empty_batch(malformed))
    assert len(out) == 0 and out.health == [] and out.wrenches.shape == (0, 8, 6)
    assert eng.counts == counts and eng.running
    np.testing.assert_array_equal(eng.state, state)
    a, b = eng.push(second), ref.push(second)
    np.testing.assert_array_equal(a.pose, b.pose)
    assert [(r.stamp, r.statuses) for r in a.health] == [(r.stamp, r.statuses) for r in b.health]


# --------------------------------------------------------------------------- no numpy warnings


def _poison(b: SampleBatch, rows: list[int], huge: bool) -> None:
    """Spoil the given rows in turn: NaN/inf in accel, gyro, stamp; `huge`: also a finite accel
    that would overflow once rotated into F (a sensor yawed by 45°)."""
    spoils = [
        lambda i: b.accel.__setitem__((i, 0), np.nan),
        lambda i: b.accel.__setitem__((i, 2), -np.inf),
        lambda i: b.gyro.__setitem__((i, 1), np.inf),
        lambda i: b.gyro.__setitem__((i, 0), np.nan),
        lambda i: b.stamps.__setitem__(i, np.nan),
        lambda i: b.stamps.__setitem__(i, np.inf),
        lambda i: b.accel.__setitem__(i, [np.inf, np.nan, -np.inf]),
    ]
    if huge:
        spoils.append(lambda i: b.accel.__setitem__(i, [1.7e308, 1.7e308, 1.0]))
    for k, i in enumerate(rows):
        spoils[k % len(spoils)](i)


@pytest.mark.parametrize("yawed", [False, True], ids=["aligned", "yawed"])
@pytest.mark.parametrize("pieces", [[400], [1] * 400, [3, 50, 1, 146, 200]])
def test_non_finite_samples_raise_no_numpy_warning(pieces: list[int], yawed: bool) -> None:
    full = batch(ramp(400))
    bad = [0, 1, 17, 90, 91, 92, 250, 251, 252, 253, 254, 255, 256, 257, 258, 399]
    _poison(full, bad, yawed)
    only_bad = batch(ramp(8, t0=1.0))
    _poison(only_bad, list(range(8)), yawed)
    rpy = (0.0, 0.0, math.pi / 4 if yawed else 0.0)
    eng = engine(scene_with(input={"sensor_rpy": rpy}, outputs={"diagnostics_period_s": 0.05}))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        before = eng.push(only_bad)  # nothing accepted yet
        assert len(before) == 0 and not eng.running
        out = [eng.push(p) for p in split(full, pieces)]
        after = eng.push(only_bad)  # running, a batch of only bad samples
        assert len(after) == 0
        eng.flush()
        eng.report_stalled(1.0)
    assert eng.counts["rejected_non_finite"] == 8 + len(bad) + 8
    assert eng.counts["accepted"] == 400 - len(bad)
    assert eng.counts["integration_failures"] == 0
    assert all(np.isfinite(o.pose).all() and np.isfinite(o.wrenches).all() for o in out)


# --------------------------------------------------------------------------- lost samples

# Default scene: diagnostics every 1.0 s of stamps. The first report is due at the first accepted
# stamp >= 1.0 s, so it covers stamps 0 … 1.000 s: 1001 samples minus those cut.


def test_holes_in_the_stamps_are_counted_as_lost() -> None:
    holes = [100, 300, 500, *range(700, 705)]  # 3 single holes, a run of 5: 8 lost
    st = without(ramp(2500), holes)
    reports = engine().push(batch(st)).health
    assert len(reports) == 2
    first, second = status(reports[0]), status(reports[1])
    assert first.level == WARN
    accepted = 1001 - 8
    share = 100.0 * 8 / (accepted + 8)
    assert first.message == (
        f"~8 samples lost in this period ({share:.1f} %, from stamp gaps at a 1.000 ms nominal "
        "interval)"
    )
    assert first.values["lost_in_period"] == "8" and first.values["lost_estimated"] == "8"
    assert float(first.values["nominal_interval_s"]) == pytest.approx(DT, rel=1e-9)
    assert first.values["accepted"] == str(accepted)
    assert (second.level, second.message) == (OK, "ok")
    assert second.values["lost_in_period"] == "0" and second.values["lost_estimated"] == "8"


def test_the_input_rate_is_the_inputs_own_over_its_stamps() -> None:
    """rate_hz: the samples the window's stamp intervals lead into (rejected ones too: see the
    stall test) over the intervals' sum. It read the accepted count over
    the outputs' span, which the gyro delay shifts and which holds one interval fewer than
    samples: 1040.5, 1001.0, ..., 964.3 Hz for the bundled 1 kHz bag."""
    whole = [status(r).values["rate_hz"] for r in engine().push(batch(ramp(3500))).health]
    assert whole == ["1000.0"] * 3  # 1000 intervals of 1 ms in each window (none into the start)
    holes = [100, 300, 500, *range(700, 705)]  # 8 lost: 992 intervals over the same 1.000 s
    cut = [
        status(r).values["rate_hz"]
        for r in engine().push(batch(without(ramp(2500), holes))).health
    ]
    assert cut == ["992.0", "1000.0"]


def test_more_than_one_percent_lost_is_an_error() -> None:
    holes = [i for start in (100, 300, 500, 700) for i in range(start, start + 5)]  # 20 lost
    eng = engine()
    (report, _) = eng.push(batch(without(ramp(2500), holes))).health
    st = status(report)
    assert st.level == ERROR
    assert st.message.startswith("~20 samples lost in this period (2.0 %, from stamp gaps")
    assert eng.counts["lost_estimated"] == 20


def test_jitter_without_holes_loses_nothing() -> None:
    rng = np.random.default_rng(3)
    st = np.cumsum(DT * (1.0 + rng.uniform(-0.1, 0.1, 5000)))
    eng = engine()
    reports = eng.push(batch(st)).health
    assert len(reports) >= 4
    for r in reports:
        s = status(r)
        assert (s.level, s.message, s.values["lost_in_period"]) == (OK, "ok", "0")
        assert float(s.values["nominal_interval_s"]) == pytest.approx(DT, rel=0.02)
    assert eng.counts["lost_estimated"] == 0


@pytest.mark.parametrize("n", [1, 2, 3, 998, 1001])
def test_the_window_median_is_numpys(n: int) -> None:
    """The lost-sample estimate's median (one partition) is np.median's number, for odd and
    even counts, with repeated values among them."""
    rng = np.random.default_rng(n)
    values = np.round(DT * (1.0 + rng.uniform(-0.1, 0.1, n)), 7)
    assert _median(values) == float(np.median(values))
    assert _median(values[::-1].copy()) == float(np.median(values))


def test_late_samples_stamped_by_the_host_are_not_lost() -> None:
    """A publisher that stamps at sending and stalls: a 4 ms step, then three samples crowding
    in 0.1 ms apart. Nothing is missing, so nothing is lost; a real hole among such stalls
    still counts once."""
    st = ramp(3000)
    for start in (200, 900, 1600, 2300):
        st[start : start + 3] = st[start + 3] - np.array([3e-4, 2e-4, 1e-4])  # late, crowded
    eng = engine()
    eng.push(batch(st))
    eng.flush()
    assert eng.counts["lost_estimated"] == 0
    eng = engine()
    eng.push(batch(without(st, [2700])))
    eng.flush()
    assert eng.counts["lost_estimated"] == 1


def test_jitter_with_single_holes_counts_each_hole_once() -> None:
    rng = np.random.default_rng(4)
    st = np.cumsum(DT * (1.0 + rng.uniform(-0.1, 0.1, 3000)))
    holes = [150, 400, 401, 402, 1500, 2100, 2700]  # 1 + 3 + 1 + 1 + 1
    eng = engine()
    eng.push(batch(without(st, holes)))
    eng.flush()
    assert eng.counts["lost_estimated"] == 7


def test_rejected_samples_are_not_lost_and_a_gap_is_input_lost() -> None:
    n = 2000
    b = batch(ramp(n))
    b.accel[200, 0] = np.nan  # received, rejected: not lost
    b.frame_ids[400] = "imu_link"
    b.stamps[601] = b.stamps[600]  # sample 601 came with a wrong stamp: rejected, not lost
    b.gyro[800:803, 2] = np.inf  # three in a row
    keep = np.ones(n, bool)
    keep[[1100, 1300, 1301]] = False  # 3 lost
    fids = [f for f, k in zip(b.frame_ids, keep, strict=True) if k]
    b = SampleBatch(b.stamps[keep], b.accel[keep], b.gyro[keep], fids)
    # 1.001 s from the last sample (1.999 s) without samples: a gap (and a restart), in which
    # a 1 kHz sensor sent 1000 samples that never came
    later = batch(ramp(600, t0=3.0))
    eng = engine()
    eng.push(SampleBatch.concat([b, later]))
    eng.flush()
    assert eng.counts["gaps"] == 1
    assert eng.counts["lost_estimated"] == 3 + 1000
    assert eng.counts["rejected_non_finite"] == 4


def test_a_message_the_adapter_could_not_decode_is_rejected_not_lost() -> None:
    eng = engine()
    st = ramp(1500)
    eng.push(batch(st[:300]))
    eng.count("received")  # sample 300 arrived garbled: the stream counts it, the engine never
    eng.count("rejected_undecodable")  # sees it
    (report,) = eng.push(batch(st[301:])).health
    assert status(report).values["lost_in_period"] == "0"
    assert status(report).message == "1 samples rejected, 0 gaps in this period"


def test_rejections_and_losses_share_one_message() -> None:
    b = batch(without(ramp(1500), [10, 20, 30]))
    b.accel[500, 1] = np.nan
    (report,) = engine().push(b).health
    st = status(report)
    assert st.level == WARN
    assert st.message.startswith(
        "1 samples rejected, 0 gaps in this period; ~3 samples lost in this period (0.3 %, "
    )


def test_lost_counters_of_the_adapter_enter_the_period() -> None:
    eng = engine()
    eng.push(batch(ramp(500)))
    eng.count("lost_middleware", 4)  # DDS message-lost events the node counted
    (report,) = eng.push(batch(ramp(1000, t0=0.5))).health
    st = status(report)
    assert st.level == WARN
    assert st.message == "~4 samples lost in this period (0.4 %, reported lost_middleware 4)"
    assert (st.values["lost_in_period"], st.values["lost_middleware"]) == ("4", "4")
    assert st.values["lost_estimated"] == "0"
    # The same samples lost in DDS leave holes in the stamps: counted once, not twice.
    eng.count("lost_middleware", 5)
    (report,) = eng.push(batch(without(ramp(1000, t0=1.5), [100, 101, 102, 103, 104]))).health
    st = status(report)
    assert st.values["lost_in_period"] == "5" and st.values["lost_middleware"] == "9"
    assert "from stamp gaps at a 1.000 ms nominal interval; reported lost_middleware 5" in (
        st.message
    )


def _holey_stream() -> tuple[SampleBatch, int]:
    """3 s at ~1 kHz with jitter, holes, rejected samples and a reset gap; samples lost."""
    rng = np.random.default_rng(11)
    st = np.cumsum(DT * (1.0 + rng.uniform(-0.05, 0.05, 3000)))
    st[2000:] += 0.7  # a gap > max_gap_s = 0.5 s: a restart, and 700 samples lost
    holes = [50, 51, 333, 700, 701, 702, 703, 1200, 2500, 2990]  # 10 lost
    b = batch(without(st, holes))
    b.accel[900, 0] = np.nan
    b.frame_ids[1500] = "imu_link"
    return b, len(holes) + 700


def _reports(reports: list[HealthReport]) -> list[tuple[float, list[HealthStatus]]]:
    return [(r.stamp, r.statuses) for r in reports]


@pytest.mark.parametrize(
    "pieces",
    [[1] * 3000, [7] * 500, [1, 2, 999, 13, 1, 500, 1000]],
    ids=["one_sample_each", "sevens", "ragged"],
)
def test_lost_estimate_does_not_depend_on_how_samples_are_pushed(pieces: list[int]) -> None:
    full, lost = _holey_stream()
    scene = scene_with(outputs={"diagnostics_period_s": 0.05})
    ref = engine(scene)
    reference = [*push_all(ref, [full]), *ref.flush().health]
    eng = engine(scene)
    got = [*push_all(eng, split(full, pieces)), *eng.flush().health]
    # the gap's 0.7 s holds 700 samples at the nominal interval, ± 1 at a ±5 % jitter
    assert abs(ref.counts["lost_estimated"] - lost) <= 1
    assert eng.counts == ref.counts
    assert len(got) == len(reference) > 50
    assert _reports(got) == _reports(reference)  # messages and values bit for bit


# --------------------------------------------------------------------------- wrong frames


def _two_sensors(n: int, t0: float = 0.0) -> SampleBatch:
    """deck_imu at RATE and imu_link interleaved half a period later, on one topic."""
    ours = batch(ramp(n, t0))
    theirs = batch(ramp(n, t0) + DT / 2, frame_ids="imu_link")
    order = np.argsort(np.concatenate([ours.stamps, theirs.stamps]), kind="stable")
    both = SampleBatch.concat([ours, theirs])
    return SampleBatch(
        both.stamps[order], both.accel[order], both.gyro[order], [both.frame_ids[i] for i in order]
    )


def test_wrong_frame_rejections_name_the_expected_and_the_seen_frame() -> None:
    eng = engine()
    reports = push_all(eng, split(_two_sensors(1500), [333] * 10))
    clean = push_all(eng, [batch(ramp(2000, t0=1.5))])  # reports at 2.0 s and a clean 3.0 s
    # First period: deck_imu stamps 0 … 1.000 s, and the 1000 imu_link ones between them.
    st = status(reports[0])
    assert st.level == WARN
    assert st.message == (
        "1000 samples rejected (wrong_frame 1000: expected frame_id 'deck_imu', got 'imu_link'), "
        "0 gaps in this period"
    )
    assert st.values["last_wrong_frame_id"] == "imu_link"
    assert st.values["rejected_wrong_frame"] == "1000"
    assert st.values["lost_in_period"] == "0", "the other sensor's samples are no holes"
    after = status(clean[-1])
    assert (after.level, after.message) == (OK, "ok")
    assert after.values["last_wrong_frame_id"] == "imu_link"


@pytest.mark.parametrize(("every", "level"), [(20, WARN), (5, ERROR), (1, ERROR)])
def test_a_sensor_whose_readings_are_unusable_is_an_error(every: int, level: int) -> None:
    """Past a tenth of a period's readings rejected (not a stamp repeated, nor another
    sensor's on the topic) the input is an ERROR: a record 90 % NaN read WARN, and its replay
    exited 0 under --fail-on error. One in 20 stays a WARN."""
    b = batch(ramp(2500))
    bad = np.arange(1100, 2500)[::every]  # from the second period on
    b.accel[bad, 2] = np.nan
    reports = engine().run(b).health
    assert status(reports[0]).level == OK
    ends = [r.stamp for r in reports[:-1]] + [b.stamps[-1]]  # each window's last stamp
    for before, end, report in zip(ends[:-1], ends[1:], reports[1:], strict=True):
        window = (b.stamps > before) & (b.stamps <= end)
        n = int(np.isnan(b.accel[window, 2]).sum())
        share = n / int(window.sum())
        st = status(report)
        assert st.level == (ERROR if share > 0.1 else WARN)
        said = f"{n} samples rejected, " + (
            f"{share:.3g} of the readings, " if share > 0.1 else ""
        )
        assert st.message.startswith(said)
    assert max(status(r).level for r in reports) == level


def test_several_wrong_frames_are_all_named() -> None:
    b = batch(ramp(1500))
    b.frame_ids[10] = "a"
    b.frame_ids[20] = "b"
    b.frame_ids[30] = "a"
    (report,) = engine().push(b).health
    st = status(report)
    assert st.message.startswith(
        "3 samples rejected (wrong_frame 3: expected frame_id 'deck_imu', got 'a', 'b')"
    )
    assert st.values["last_wrong_frame_id"] == "a"


def _report_size(report: HealthReport) -> int:
    """Characters of a report's texts: names, messages, keys and values."""
    return sum(
        len(s.name) + len(s.message) + sum(len(k) + len(v) for k, v in s.values.items())
        for s in report.statuses
    )


def test_a_huge_wrong_frame_id_is_shortened_in_every_report() -> None:
    """A hostile 100 000-character frame_id is named shortened, with its length, in the period
    that rejected it and in the value every later report carries: it had been repeated in full,
    450 kB of diagnostics per report."""
    huge = "x" * 100_000
    b = batch(ramp(1500))
    b.frame_ids[10] = huge
    reports = push_all(eng := engine(), [b])
    reports += push_all(eng, [batch(ramp(2000, t0=1.5))])  # two clean periods after it
    assert len(reports) == 3
    for report in reports:
        # eight mounts and three other statuses, each at most a few hundred characters
        assert _report_size(report) < 8000
    st = status(reports[0])
    assert "expected frame_id 'deck_imu', got 'xxx" in st.message
    assert "(shortened, 100000 characters)" in st.message
    for report in reports:
        value = status(report).values["last_wrong_frame_id"]
        assert value.startswith("'xxx") and value.endswith("(shortened, 100000 characters)")


def _wrong_frame_messages(frame_ids: list[str], t0_ns: int = 10**18) -> list[bytes]:
    """Imu messages at rest at RATE, one per frame id, from `t0_ns`."""
    rest = np.array([[0.0, 0.0, 9.80665]])
    return [
        raw
        for i, frame_id in enumerate(frame_ids)
        for _, raw in imu_messages(np.array([t0_ns + i * 10**6]), rest, np.zeros((1, 3)), frame_id)
    ]


def test_a_period_keeps_no_hostile_frame_id_whole() -> None:
    """A period held every distinct wrong frame_id in full until its report, which names
    three, shortened: 100 kB frame ids at 10 kHz held about a gigabyte a second. 200 distinct
    ids of 50 000 characters (10 MB) through the node's path may leave no more than 1 MB held,
    and the stall report still names three, shortened, and counts the others."""
    stream = TwinStream(default_scene())
    stream.process(_wrong_frame_messages(["warm_up"] * 10))  # the first push's allocations
    ids = [f"{i:06d}" + "x" * 50_000 for i in range(200)]  # distinct in their shown head
    raws = _wrong_frame_messages(ids, t0_ns=10**18 + 10**8)
    gc.collect()
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        assert stream.process(raws) == []  # within the period: no report yet
        gc.collect()
        held = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert held < 1_000_000, f"{held} bytes held after the push"
    report = stream.engine.report_stalled(1.0)
    st = status(report)
    assert st.message.startswith(
        "no sample accepted for 1.0 s: 210 received, all rejected (wrong_frame 210: expected "
        "frame_id 'deck_imu', got 'warm_up', '000000xxx"
    )
    assert st.message.count("(shortened, 50006 characters)") == 2
    assert st.message.endswith(" and 198 more)")
    value = st.values["last_wrong_frame_id"]
    assert value.startswith("'000199xxx") and value.endswith("(shortened, 50006 characters)")


def test_distinct_wrong_frame_ids_are_counted_up_to_a_bound() -> None:
    """A period counts the distinct wrong frame_ids it names as 'N more' up to
    WRONG_FRAMES_COUNTED of them, and past that says 'over'; however the samples are pushed."""
    ids = [f"f{i:05d}" for i in range(WRONG_FRAMES_COUNTED + 200)]
    b = batch(ramp(len(ids)) / 10.0, frame_ids=ids)  # 10 kHz: all within a period
    more = WRONG_FRAMES_COUNTED - 3
    for parts in ([b], split(b, [7] * (len(ids) // 7 + 1))):
        eng = engine()
        assert push_all(eng, parts) == []
        said = status(eng.report_stalled(1.0)).message
        assert said.endswith(f"got 'f00000', 'f00001', 'f00002' and over {more} more)")
    eng = engine()
    assert eng.push(batch(ramp(500) / 10.0, frame_ids=ids[:500])).health == []
    said = status(eng.report_stalled(1.0)).message
    assert said.endswith("got 'f00000', 'f00001', 'f00002' and 497 more)")


# --------------------------------------------------------------------------- stalled input


def _names(report: HealthReport) -> list[str]:
    return [s.name for s in report.statuses]


def test_the_shutdown_report_after_a_stall_report_is_not_stamped_before_it() -> None:
    """An input stamped by another clock (a synthetic stream, a bag played without sim time)
    stalls: the stall report takes the node's clock, later than any input stamp. The final
    report took the last input stamp: /diagnostics went back in time at shutdown."""
    stream = TwinStream(default_scene())
    ns = 1_600_000_000 * 10**9 + np.arange(300) * 10**6
    rest = np.tile([0.0, 0.0, 9.80665], (300, 1))
    stream.process([raw for _, raw in imu_messages(ns, rest, np.zeros((300, 3)), "deck_imu")])
    clock_ns = 1_800_000_000 * 10**9
    stall = [
        stamp for topic, stamp, _ in stream.stalled(1.0, clock_ns) if topic == DIAGNOSTICS_TOPIC
    ]
    final = [stamp for topic, stamp, _ in stream.finish() if topic == DIAGNOSTICS_TOPIC]
    assert stall == [clock_ns] and final and min(final) >= clock_ns


def test_stall_before_any_input_says_nothing_was_received() -> None:
    eng = engine()
    report = eng.report_stalled(1.0)
    assert math.isnan(report.stamp) and report.sample == -1
    st = status(report)
    assert (st.level, st.message) == (ERROR, "no input received for 1.0 s")
    assert st.values["since_last_report_s"] == "1" and st.values["received"] == "0"
    assert status(report, "integration").level == OK
    normal = engine().push(batch(ramp(1001))).health[0]
    assert _names(report) == _names(normal), "the same statuses as a normal report"
    assert not eng.running and dict(eng.counts) == {}
    # The twin then starts and reports as usual.
    (later,) = eng.push(batch(ramp(1001, t0=5.0))).health
    assert status(later).level == OK and status(later).values["accepted"] == "1001"


@pytest.mark.parametrize("n_nan", [0, 3])
def test_stall_with_only_rejected_samples_says_why(n_nan: int) -> None:
    eng = engine()
    b = batch(ramp(1000), frame_ids="imu_link")
    b.accel[:n_nan, 0] = np.nan
    for p in split(b, [1] * 1000):
        assert eng.push(p).health == []
    report = eng.report_stalled(1.0)
    assert math.isnan(report.stamp) and report.sample == -1
    st = status(report)
    reasons = f"non_finite {n_nan}, " if n_nan else ""
    assert st.level == ERROR
    assert st.message == (
        f"no sample accepted for 1.0 s: 1000 received, all rejected ({reasons}wrong_frame "
        f"{1000 - n_nan}: expected frame_id 'deck_imu', got 'imu_link')"
    )
    assert st.values["last_wrong_frame_id"] == "imu_link"
    assert not eng.running


def test_the_end_after_a_stall_report_says_what_came_before_it() -> None:
    """Rejected samples only, a stall report that took them, then the stream's end: the last
    report read "no input received by the end of the input" beside values counting 50
    received."""
    eng = engine()
    eng.push(batch(ramp(50), frame_ids="imu_link"))
    assert status(eng.report_stalled(1.0)).message.startswith(
        "no sample accepted for 1.0 s: 50 received, all rejected"
    )
    (last,) = eng.flush().health
    st = status(last)
    assert st.level == ERROR
    assert st.message == (
        "no input received since the last report, by the end of the input "
        "(50 received before it, 0 accepted)"
    )
    assert st.values["received"] == "50" and st.values["accepted"] == "0"


def test_stall_of_a_running_twin_then_reports_continue() -> None:
    # the gyro raw: no delayed samples, so a flush right after the stall report has nothing new
    eng = engine(scene_with(input={"gyro_filter": "none"}))
    (first,) = eng.push(batch(ramp(1001))).health  # due at 1.000 s
    eng.push(batch(ramp(3, t0=1.001)))
    report = eng.report_stalled(1.0)
    assert report.stamp == pytest.approx(1.003, abs=1e-12) and report.sample == -1
    st = status(report)
    assert (st.level, st.message) == (
        ERROR,
        "no sample accepted for 1.0 s (3 before it in this period)",
    )
    assert st.values["accepted"] == "1004" and st.values["since_last_report_s"] == "1"
    flushed = eng.flush()
    assert len(flushed) == 0 and flushed.health == [], "the stall report closed the window"

    # Still nothing: the next stall says nothing came, stamped at the last accepted sample.
    again = eng.report_stalled(2.5)
    assert (status(again).level, status(again).message) == (
        ERROR,
        "no input received for 2.5 s",
    )
    assert again.stamp == report.stamp

    # Then rejected only, then input resumes in time: counts continue, the window restarted.
    eng.push(batch(ramp(50, t0=1.004), frame_ids="imu_link"))
    rejected = status(eng.report_stalled(1.0))
    assert rejected.message.startswith("no sample accepted for 1.0 s: 50 received, all rejected")
    reports = eng.push(batch(ramp(2000, t0=1.054))).health
    assert len(reports) == 1, "the cadence restarts at the first sample after the stall"
    assert reports[0].stamp == pytest.approx(1.054 + 1.0, abs=1e-9)
    st = status(reports[0])
    assert (st.level, st.message) == (OK, "ok")
    assert st.values["accepted"] == str(1001 + 3 + 1001)
    assert st.values["received"] == str(1001 + 3 + 50 + 1001)
    assert float(st.values["rate_hz"]) == pytest.approx(RATE, rel=2e-3)
    counts = eng.counts.copy()
    assert counts.pop("substeps") >= 1001 + 3 + 2000 - 1  # at least one per interval
    assert counts == Counter(
        received=1001 + 3 + 50 + 2000,
        accepted=1001 + 3 + 2000,
        rejected_wrong_frame=50,
        starts=1,
    )
    assert first.stamp == 1.0


def test_a_stall_after_input_says_it_computed_no_attitude_nor_mount_load() -> None:
    """A stall report of a twin that had run: no sample accepted in its period, no row
    published, yet its attitude and mount statuses read "ok" with a tilt and peaks of 0, as a
    machine at rest. They say nothing was computed in the period, and why, figures "n/a"; the
    period before, which published rows, reads as it did."""
    eng = engine(scene_with(input={"gyro_filter": "none"}))
    out = eng.push(batch(ramp(1001)))
    (due,) = out.health
    assert len(out) > 0  # rows published in the period before the stall
    accepted = eng.counts["accepted"]
    stalled = eng.report_stalled(1.0)
    assert eng.counts["accepted"] == accepted and len(eng.flush()) == 0  # nothing came since
    names = [s.name for s in due.statuses]
    assert names == [s.name for s in stalled.statuses]
    for name in names[2:]:  # attitude, then one per mount
        before, after = (next(s for s in r.statuses if s.name == name) for r in (due, stalled))
        assert before.message != after.message, name
        figures = [k for k in before.values if "peak" in k or "max" in k]
        assert figures and all(float(before.values[k]) >= 0.0 for k in figures), name
        assert after.level == OK, name
        assert after.message == "not computed in this period: no input sample was accepted in it"
        assert {after.values[k] for k in figures} == {"n/a"}, (name, after.values)


@pytest.mark.parametrize("pushed", [1001, 1])
def test_a_stall_says_its_period_integrated_nothing(pushed: int) -> None:
    """A stall report of a twin that had integrated (no sample accepted in its period, no
    interval integrated) read "integration: ok" beside stepper figures of "n/a". It says its
    period integrated nothing, and why; a run that never integrated an interval (one sample)
    still says so of the run."""
    eng = engine(scene_with(input={"gyro_filter": "none"}))
    eng.push(batch(ramp(pushed)))
    intervals, substeps = eng.health.intervals_run, eng.counts["substeps"]
    assert intervals == pushed - 1  # the first sample is the start
    stalled = eng.report_stalled(1.0)
    assert (eng.health.intervals_run, eng.counts["substeps"]) == (intervals, substeps)
    after = status(stalled, "integration")
    assert after.level == OK, after
    assert after.values["error_norm_max"] == after.values["substeps_per_sample"] == "n/a"
    if intervals:
        assert after.message == "not run in this period: no input sample was accepted in it"
    else:
        assert after.message == "not run: no input interval was integrated (1 sample accepted)"


def test_the_real_time_factor_is_the_input_time_over_the_wall_time() -> None:
    """real_time_factor: the stamp time the window's input intervals cover over the wall time
    spent on its samples. It took the outputs' span, which the gyro delay shifts and which
    holds one interval fewer than samples."""
    calls = iter(range(10**6))
    eng = TwinEngine(default_model(), clock=lambda: 1e-5 * next(calls))
    # one sample a push: the clock read twice around each, 10 µs of wall a sample
    reports = [r for t in ramp(3001) for r in eng.push(batch(np.array([t]))).health]
    figures = [status(r, "integration").values["real_time_factor"] for r in reports]
    # 1000 intervals of 1 ms a window; the first holds the start's sample too (1001 samples)
    assert figures == [f"{1.0 / 1001e-5:.1f}", "100.0", "100.0"]
