"""Our mcap writer and plain-bag reader against rosbags, the reference for both: the bag we
write reads back through rosbags as the bag rosbags writes of the same messages (connections,
QoS, hashes, counts, metadata, messages in order), and through the record-by-record salvage
reader; our reader yields a topic's messages as rosbags' reader does, on bags rosbags wrote
(one chunk or many, one topic or several, frame ids of one length or of several, zstd), and
leaves to rosbags what it does not read (chunks overlapping in time)."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import yaml
from io_helpers import read_raw
from mcap.reader import make_reader
from mcap.stream_reader import StreamReader
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer

from mount_twin.errors import DamagedBagError
from mount_twin.io import mcap_writer
from mount_twin.io.bag_metadata import PARTIAL_KEY
from mount_twin.io.input_bag import InputBag
from mount_twin.io.input_decoding import decode_inputs
from mount_twin.io.mcap_reader import plain_messages
from mount_twin.io.mcap_salvage import salvage
from mount_twin.io.messages import IMU, TYPESTORE
from mount_twin.io.output_bag import LATCHED_QOS, OutputBag
from mount_twin.io.output_encoding import RowBlock, imu_messages
from mount_twin.io.raw_rows import RawRows, joined

POSE, DIAG = "geometry_msgs/msg/PoseStamped", "diagnostic_msgs/msg/DiagnosticArray"
T0 = 1_700_000_000_000_000_000


def _imu(
    n: int, frame: str, start_ns: int = T0, step_ns: int = 1_000_000
) -> list[tuple[int, bytes]]:
    rng = np.random.default_rng(len(frame) + n)
    ns = start_ns + step_ns * np.arange(n, dtype=np.int64)
    return imu_messages(ns, rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), frame)


def _mixed(n: int) -> list[tuple[str, int, bytes]]:
    """Three topics interleaved in time, ties between topics included, frame ids of several
    lengths on one topic."""
    deck = [("/deck/imu", t, r) for t, r in _imu(n, "deck_imu")]
    body = [("/body/imu", t, r) for t, r in _imu(n, "b", step_ns=2_000_000)]
    other = [("/other/imu", t, r) for t, r in _imu(n // 3, "a_much_longer_frame_id", T0 + 500)]
    return sorted(deck + body + other, key=lambda m: m[1])


def _rosbags_bag(
    path: Path, messages: list[tuple[str, int, bytes]], *, zstd: bool = False
) -> None:
    w = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    if zstd:
        w.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with w:
        conns = {}
        for topic in dict.fromkeys(t for t, _, _ in messages):
            conns[topic] = w.add_connection(topic, IMU, typestore=TYPESTORE)
        for topic, t, raw in messages:
            w.write(conns[topic], t, raw)


def _connections(path: Path) -> list[tuple[object, ...]]:
    with AnyReader([path], default_typestore=TYPESTORE) as r:
        return [
            (c.topic, c.msgtype, c.digest, c.msgcount, c.ext.offered_qos_profiles, c.msgdef)
            for c in r.connections
        ]


def _in_order(path: Path) -> list[tuple[str, int, bytes]]:
    with AnyReader([path], default_typestore=TYPESTORE) as r:
        return [(c.topic, t, bytes(raw)) for c, t, raw in r.messages()]


@pytest.mark.parametrize("chunk_bytes", [1 << 20, 4096])
def test_our_bag_reads_back_through_rosbags_as_rosbags_own(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, chunk_bytes: int
) -> None:
    monkeypatch.setattr(mcap_writer, "CHUNK_BYTES", chunk_bytes)
    messages = _mixed(3000)
    ours, theirs = tmp_path / "ours", tmp_path / "theirs"
    topics = dict.fromkeys(dict.fromkeys(t for t, _, _ in messages), IMU)
    with OutputBag(ours, topics, {"/body/imu": [LATCHED_QOS]}) as bag:
        for k in range(0, len(messages), 777):  # batches across chunk ends
            bag.write(messages[k : k + 777])
    with Writer(theirs, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conns = {
            t: w.add_connection(
                t,
                IMU,
                typestore=TYPESTORE,
                offered_qos_profiles=[LATCHED_QOS] * (t == "/body/imu"),
            )
            for t in topics
        }
        for topic, t, raw in messages:
            w.write(conns[topic], t, raw)
    assert _connections(ours) == _connections(theirs)
    assert _in_order(ours) == _in_order(theirs) == messages
    with AnyReader([ours]) as a, AnyReader([theirs]) as b:
        assert (a.start_time, a.end_time, a.message_count) == (
            b.start_time,
            b.end_time,
            b.message_count,
        )
    chunks = salvage(ours / "ours.mcap", "/deck/imu")  # record by record, no summary
    assert not chunks.damage and chunks.msgtype == IMU
    assert chunks.messages == [(t, r) for topic, t, r in messages if topic == "/deck/imu"]


def test_our_bag_passes_the_mcap_projects_own_reader_crcs_and_indexes_checked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The reference implementation (Foxglove's `mcap`): every record read in order with the
    checksums validated, and the indexed reader (chunk and message indexes, summary) giving
    the messages in log-time order with the statistics' counts."""
    monkeypatch.setattr(mcap_writer, "CHUNK_BYTES", 8192)
    messages = _mixed(2000)
    topics = dict.fromkeys(dict.fromkeys(t for t, _, _ in messages), IMU)
    with OutputBag(tmp_path / "ours", topics) as bag:
        bag.write(messages)
    file = tmp_path / "ours" / "ours.mcap"
    with file.open("rb") as f:
        kinds = Counter(type(r).__name__ for r in StreamReader(f, validate_crcs=True).records)
    assert kinds["Message"] == len(messages)
    assert kinds["ChunkIndex"] > 10 and kinds["Footer"] == 1
    with file.open("rb") as f:
        reader = make_reader(f, validate_crcs=True)
        stats = reader.get_summary().statistics
        got = [(c.topic, m.log_time, m.data) for _, c, m in reader.iter_messages()]
    assert got == messages and stats.message_count == len(messages)
    assert stats.channel_message_counts == dict(
        Counter(list(topics).index(t) + 1 for t, _, _ in messages)
    )


@pytest.mark.parametrize("chunk_bytes", [1 << 20, 5000])
def test_rows_written_as_a_block_make_the_same_file_as_one_by_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, chunk_bytes: int
) -> None:
    """A block of rows (a replay's outputs) and the same messages one by one, row by row:
    byte-equal files, with chunks cut inside rows (5000 bytes) or not."""
    monkeypatch.setattr(mcap_writer, "CHUNK_BYTES", chunk_bytes)
    k = 500
    deck, body = _imu(k, "deck_imu"), _imu(k, "body_frame_longer")
    stamps = np.array([t for t, _ in deck], np.int64)
    rows = tuple(
        np.frombuffer(b"".join(r for _, r in m), np.uint8).reshape(k, -1) for m in (deck, body)
    )
    block = RowBlock(("/deck/imu", "/body/imu"), stamps, rows)
    topics = {"/deck/imu": IMU, "/body/imu": IMU, "/diagnostics": IMU}
    extra = ("/diagnostics", int(stamps[-1]), body[0][1])
    one_by_one = [*block.messages(), extra]
    assert one_by_one[:4] == [
        ("/deck/imu", deck[0][0], deck[0][1]),
        ("/body/imu", body[0][0], body[0][1]),
        ("/deck/imu", deck[1][0], deck[1][1]),
        ("/body/imu", body[1][0], body[1][1]),
    ]
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    with OutputBag(tmp_path / "a" / "bag", topics) as a:
        a.write([RowBlock(block.topics, stamps[:200], tuple(r[:200] for r in rows))])
        a.write([RowBlock(block.topics, stamps[200:], tuple(r[200:] for r in rows)), extra])
    with OutputBag(tmp_path / "b" / "bag", topics) as b:
        b.write(one_by_one[:7])
        b.write(one_by_one[7:])
    one = (tmp_path / "a" / "bag" / "bag.mcap").read_bytes()
    assert one == (tmp_path / "b" / "bag" / "bag.mcap").read_bytes()
    assert _in_order(tmp_path / "a" / "bag") == one_by_one


def test_a_partial_bag_says_why_in_its_metadata_and_an_empty_one_reads(tmp_path: Path) -> None:
    with OutputBag(tmp_path / "partial", {"/deck/imu": IMU}) as bag:
        bag.write([("/deck/imu", t, r) for t, r in _imu(5, "deck_imu")])
        bag.mark_partial("stopped by SIGINT")
    with AnyReader([tmp_path / "partial"]) as r:
        assert r.message_count == 5
    info = yaml.safe_load((tmp_path / "partial" / "metadata.yaml").read_text())
    why = info["rosbag2_bagfile_information"]["custom_data"][PARTIAL_KEY]
    assert why.startswith("stopped by SIGINT; outputs up to stamp")
    with OutputBag(tmp_path / "empty", {"/deck/imu": IMU}):
        pass
    assert read_raw(tmp_path / "empty") == {}


@pytest.mark.parametrize("zstd", [False, True])
@pytest.mark.parametrize("topic", ["/deck/imu", "/other/imu"])
def test_the_plain_reader_yields_what_rosbags_yields(
    tmp_path: Path, topic: str, zstd: bool
) -> None:
    """Many chunks (9000 messages), the topic alone in none of them; /other/imu's frame ids of
    several lengths take the record-by-record path, /deck/imu's chunks too (other topics among
    them)."""
    messages = _mixed(9000)
    messages += [("/other/imu", t + 10**6, r) for t, r in _imu(50, "x" * 40, messages[-1][1])]
    _rosbags_bag(tmp_path / "bag", messages, zstd=zstd)
    plain = plain_messages(tmp_path / "bag" / "bag.mcap", topic)
    assert plain is not None
    got = _flat(plain)
    assert got == read_raw(tmp_path / "bag")[topic]
    with InputBag(tmp_path / "bag", topic, IMU) as bag:
        assert [r for c in bag.chunks(1000) for r in c] == [r for _, r in got]


def _flat(plain) -> list[tuple[int, bytes]]:
    """(log time, raw) of each message of the reader's batches, in order."""
    return [(int(t), r) for times, raws in plain for t, r in zip(times, raws, strict=True)]


def test_raw_rows_are_their_messages_and_join_as_rows_where_lengths_agree() -> None:
    raws = [bytes([k]) * 5 for k in range(7)]
    rows = RawRows(np.frombuffer(b"".join(raws), np.uint8).reshape(7, 5))
    assert len(rows) == 7 and rows[3] == raws[3] and list(rows) == raws
    assert list(rows[2:5]) == raws[2:5] and isinstance(rows[2:5], RawRows)
    both = joined([rows[:3], raws[3:5], rows[5:]])
    assert isinstance(both, RawRows) and list(both) == raws
    mixed = joined([rows[:3], [b"short"[:4]]])
    assert isinstance(mixed, list) and mixed == [*raws[:3], b"shor"]


def test_rows_decode_as_their_bytes_do_with_frame_ids_of_one_length_and_an_odd_message() -> None:
    """decode_inputs on RawRows (read as they lie) equals it on the same messages as bytes:
    two frame ids of one length interleaved, one message whose last covariance is not the
    layout's zero (rosbags decodes it alone)."""
    a, b = _imu(30, "imu_a"), _imu(30, "imu_b", start_ns=T0 + 500_000)
    raws = [r for pair in zip(a, b, strict=True) for _, r in pair]
    raws[7] = raws[7][:-8] + b"\xff" * 8
    rows = RawRows(np.frombuffer(b"".join(raws), np.uint8).reshape(len(raws), -1))
    got, want = decode_inputs(rows, IMU), decode_inputs(raws, IMU)
    assert got.frame_ids == want.frame_ids and got.undecodable == want.undecodable
    for field in ("stamps_ns", "accel", "gyro"):
        np.testing.assert_array_equal(getattr(got, field), getattr(want, field))


def test_one_topic_of_one_frame_id_is_read_at_once_in_time_order(tmp_path: Path) -> None:
    """A chunk of one IMU whose stamps go back once: sorted by log time, stably."""
    msgs = _imu(4000, "deck_imu")
    msgs[10], msgs[11] = msgs[11], msgs[10]
    _rosbags_bag(tmp_path / "bag", [("/deck/imu", t, r) for t, r in msgs])
    plain = plain_messages(tmp_path / "bag" / "bag.mcap", "/deck/imu")
    assert plain is not None
    batches = list(plain)
    assert all(isinstance(raws, RawRows) for _, raws in batches), "one length: rows"
    got = _flat(batches)
    assert got == read_raw(tmp_path / "bag")["/deck/imu"] == sorted(msgs, key=lambda m: m[0])
    with InputBag(tmp_path / "bag", "/deck/imu", IMU) as bag:
        pieces = list(bag.chunks(1000))  # cut across the file's chunks, joined as rows
    assert all(isinstance(p, RawRows) for p in pieces)
    assert [r for p in pieces for r in p] == [r for _, r in got]


def test_chunks_that_overlap_in_time_are_left_to_rosbags(tmp_path: Path) -> None:
    early = _imu(3000, "deck_imu")
    late = _imu(3000, "deck_imu", start_ns=T0 + 500_000)  # between the early ones
    _rosbags_bag(tmp_path / "bag", [("/deck/imu", t, r) for t, r in early + late])
    assert plain_messages(tmp_path / "bag" / "bag.mcap", "/deck/imu") is None
    want = [r for _, r in read_raw(tmp_path / "bag")["/deck/imu"]]
    with InputBag(tmp_path / "bag", "/deck/imu", IMU) as bag:
        assert [r for c in bag.chunks(700) for r in c] == want


def test_a_chunk_that_fails_its_checksum_is_damage_and_the_rest_is_salvaged(
    tmp_path: Path,
) -> None:
    """(rosbags writes no checksum; we do, and read it.)"""
    msgs = _imu(9000, "deck_imu")
    with OutputBag(tmp_path / "bag", {"/deck/imu": IMU}) as out:
        out.write([("/deck/imu", t, r) for t, r in msgs])
    file = tmp_path / "bag" / "bag.mcap"
    data = bytearray(file.read_bytes())
    at = data.index(msgs[5000][1])  # a byte of a message's data, in the second chunk
    data[at + 30] ^= 0xFF
    file.write_bytes(bytes(data))
    read: list[bytes] = []
    with (
        InputBag(tmp_path / "bag", "/deck/imu", IMU) as bag,
        pytest.raises(DamagedBagError, match=r"damaged after .* checksum"),
    ):
        for chunk in bag.chunks(1000):
            read += chunk
    first = len(read)
    assert 0 < first < 5000 and read == [r for _, r in msgs[:first]]
