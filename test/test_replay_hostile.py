"""Replay of hostile input: stamps before 1970, bags damaged in many ways (each a real bag whose
bytes are edited), bags that are no bags, a full disk, and a signal before the output exists.

Signals mid-replay and an mcap cut short are in test_replay_stops.py; ROS 1 bags replayed and
the --topic/--frame-id overrides in test_replay_inputs.py.
"""

from __future__ import annotations

import html
import json
import shutil
import struct
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from io_helpers import (
    SCENE_FILE,
    comparable_diagnostics,
    default_scene,
    read_bag,
    read_raw,
    run_python,
    scene_with,
    stamp_ns,
    unprovided_imu,
)
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from mount_twin.cli import main
from mount_twin.errors import BagError
from mount_twin.io import input_bag as bag_module
from mount_twin.io.bag_metadata import PARTIAL_KEY
from mount_twin.io.input_bag import InputBag
from mount_twin.io.messages import IMU, POSE, TYPESTORE
from mount_twin.io.output_bag import OutputBag, write_bag
from mount_twin.io.output_encoding import imu_messages, messages_of
from mount_twin.replay import replay

N = 5000  # messages of a 5 s ship-motion bag at 1 kHz
POSES = "/mount_twin/pose"


@pytest.fixture(scope="module")
def ship(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """5 s of ship motion on /deck/imu, in mcap and in sqlite3."""
    d = tmp_path_factory.mktemp("ship")
    for storage in ("mcap", "sqlite3"):
        gen = ["generate", "ship-motion", "-o", str(d / storage), "--storage", storage]
        assert main(gen) == 0
    return {"mcap": d / "mcap", "sqlite3": d / "sqlite3"}


def _replay(bag: Path, out: Path) -> int:
    return main(["replay", str(bag), "--scene", str(SCENE_FILE), "-o", str(out), "--no-progress"])


def _one_message_bag(path: Path) -> Path:
    assert main(["generate", "ship-motion", "-o", str(path), "--duration", "0.001"]) == 0
    return path


def _edited_copy(bag: Path, dst: Path, edit: Callable[[bytes], bytes]) -> Path:
    """A copy of `bag` whose storage file's bytes are replaced by edit(bytes)."""
    shutil.copytree(bag, dst)
    (storage,) = [f for f in dst.iterdir() if f.suffix in (".mcap", ".db3")]
    storage.write_bytes(edit(storage.read_bytes()))
    return dst


def _partial(out: Path) -> str:
    """The partial marker in a finished output bag's metadata.yaml ('' if none)."""
    meta = yaml.safe_load((out / "metadata.yaml").read_text(encoding="utf-8"))
    return (meta["rosbag2_bagfile_information"].get("custom_data") or {}).get(PARTIAL_KEY, "")


def _damaged_count(err: str) -> int:
    """N of '... the N messages of /deck/imu before the damage ...'."""
    return int(err.split("; the ")[1].split(" messages", maxsplit=1)[0])


# --------------------------------------------------------------------------- stamps before 1970


def test_negative_and_zero_stamps_are_rejected_and_counted_and_never_reach_the_output(
    ship: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """sec = -5 on the first message (the one /tf_static used to be stamped with) and on
    another, and an unset stamp (0) on a third, in one chunk: each is counted, the replay goes
    on, and every output stamp is one taken (a zero with a negative stamp failed the replay)."""
    msgs = read_raw(ship["mcap"], ["/deck/imu"])["/deck/imu"][:500]
    for k, sec in ((0, -5), (100, -5), (200, 0)):
        m: Any = TYPESTORE.deserialize_cdr(msgs[k][1], IMU)
        m.header.stamp.sec = sec
        m.header.stamp.nanosec = 0
        msgs[k] = (msgs[k][0], bytes(TYPESTORE.serialize_cdr(m, IMU)))
    bag = tmp_path / "negative"
    write_bag(bag, "/deck/imu", IMU, iter(msgs))
    out = tmp_path / "out"
    assert _replay(bag, out) == 0
    summary = capsys.readouterr().out
    assert "zero_stamp 1" in summary and "negative_stamp 2" in summary
    _, got = read_bag(out)
    ((static_time, static),) = got["/tf_static"]
    first = stamp_ns(TYPESTORE.deserialize_cdr(msgs[1][1], IMU))
    assert static_time == stamp_ns(static.transforms[0]) == first
    assert len(got[POSES]) == 497 and min(t for t, _ in got[POSES]) == first
    assert _partial(out) == ""


def test_a_replay_whose_every_input_message_is_unusable_ends_at_the_inputs_last_log_time(
    ship: dict[str, Path], tmp_path: Path
) -> None:
    """Garbage, then a message stamped 0 and one before 1970, logged at 1.000, 1.250 and
    1.500 s past 1 700 000 000 s: no input stamp to take, and a replay has no clock, so its
    last report (input ERROR: none accepted) and /tf_static went out stamped 0 (1970). Now
    they take the input's last log time, 1 700 000 001.5 s, as the node takes its clock."""
    good = read_raw(ship["mcap"], ["/deck/imu"])["/deck/imu"][0][1]
    unusable = [b"\x00\x01garbage"]
    for sec in (0, -5):
        m: Any = TYPESTORE.deserialize_cdr(good, IMU)
        m.header.stamp.sec, m.header.stamp.nanosec = sec, 0
        unusable.append(bytes(TYPESTORE.serialize_cdr(m, IMU)))
    log0 = 1_700_000_001_000_000_000
    times = [log0, log0 + 250_000_000, log0 + 500_000_000]
    bag = tmp_path / "unusable"
    write_bag(bag, "/deck/imu", IMU, iter(zip(times, unusable, strict=True)))
    out = tmp_path / "out"
    assert _replay(bag, out) == 3  # nothing accepted
    _, got = read_bag(out)
    last = 1_700_000_001_500_000_000
    ((static_time, static),) = got["/tf_static"]
    assert static_time == stamp_ns(static.transforms[0]) == last
    reports = got["/diagnostics"]
    assert reports and all(t == stamp_ns(m) == last for t, m in reports), reports


def test_an_output_bag_refuses_a_stamp_before_1970_naming_it_and_stays_readable(
    tmp_path: Path,
) -> None:
    ((stamp, raw),) = read_raw(_one_message_bag(tmp_path / "one"))["/deck/imu"]
    out = tmp_path / "out"
    with OutputBag(out, {"/deck/imu": IMU}) as bag:
        bag.write([("/deck/imu", stamp, raw)])
        with pytest.raises(BagError, match=rf"{out}: /deck/imu: stamp -1 ns is before 1970"):
            bag.write([("/deck/imu", stamp + 1, raw), ("/deck/imu", -1, raw)])
    assert read_raw(out) == {"/deck/imu": [(stamp, raw)]}


def test_generate_with_a_start_before_1970_exits_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / "early"
    gen = ["generate", "ship-motion", "-o", str(bag), "--duration", "0.1", "--start", "-5"]
    assert main(gen) == 2
    assert f"{bag}: /deck/imu: stamp -5 ns is before 1970" in capsys.readouterr().err
    assert not bag.exists()


# --------------------------------------------------------------------------- damaged mcap


def _record_of(data: bytes, raw: bytes) -> int:
    """Offset of the mcap Message record holding `raw` (opcode, length u64, channel u16,
    sequence u32, log and publish times u64, then the data)."""
    at = data.find(raw)
    assert at > 0 and data.find(raw, at + 1) < 0
    return at - 31


def test_a_corrupted_mcap_record_stops_at_it_with_exit_5_after_the_messages_before_it(
    ship: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A record length overwritten inside the second chunk: rosbags fails on the whole chunk;
    read record by record, the 4000 messages before the damaged one are replayed."""
    raw = read_raw(ship["mcap"], ["/deck/imu"])["/deck/imu"][4000][1]

    def corrupt(data: bytes) -> bytes:
        at = _record_of(data, raw) + 1
        return data[:at] + (2**40).to_bytes(8, "little") + data[at + 8 :]

    bag = _edited_copy(ship["mcap"], tmp_path / "bad", corrupt)
    out = tmp_path / "out"
    assert _replay(bag, out) == 5
    err = capsys.readouterr().err
    assert f"{bag}: damaged (chunk at byte " in err and "(opcode 0x05) cut short" in err
    assert _damaged_count(err) == 4000 and "Traceback" not in err
    _, got = read_bag(out)
    assert len(got[POSES]) == 4000
    assert _partial(out).startswith("stopped by DamagedBagError")


def _zeroed_at_message_1000(bag: Path, dst: Path) -> Path:
    """A copy of `bag` with 4096 bytes zeroed from the record of its message 1000 on."""
    raw = read_raw(bag, ["/deck/imu"])["/deck/imu"][1000][1]

    def zero(data: bytes) -> bytes:
        at = _record_of(data, raw)
        return data[:at] + bytes(4096) + data[at + 4096 :]

    return _edited_copy(bag, dst, zero)


def test_bytes_zeroed_inside_an_mcap_chunk_are_no_silent_loss(
    ship: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """rosbags skips zeroed records without an error (its chunks carry no checksum when
    rosbags wrote them); our reader of plain bags walks every record of the chunk, stops at
    them, and the messages before them are replayed."""
    bag = _zeroed_at_message_1000(ship["mcap"], tmp_path / "zeroed")
    out, summary = tmp_path / "out", tmp_path / "s.json"
    args = ["replay", str(bag), "--scene", str(SCENE_FILE), "-o", str(out), "--no-progress"]
    assert main([*args, "--json", str(summary)]) == 5
    printed = capsys.readouterr()
    err = printed.err
    assert f"{bag}: damaged (chunk at byte " in err and "Traceback" not in err
    assert _damaged_count(err) == 1000
    _, got = read_bag(out)
    assert len(got[POSES]) == 1000
    assert _partial(out).startswith("stopped by DamagedBagError")
    # the replay up to the damage is summarised, saying so (nothing was printed or written)
    assert "  input damaged, replayed up to the damage: " in printed.out
    assert "1000 accepted" in printed.out and "verdict: " in printed.out
    data = json.loads(summary.read_text(encoding="utf-8"))
    assert data["counts"]["accepted"] == 1000
    assert data["input_damaged"].startswith(f"{bag}: damaged (chunk at byte ")


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full")
def test_a_summary_that_cannot_be_written_after_damage_still_names_the_damage(
    ship: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A replay stopped at damage (exit 5) whose `--json` cannot be written exits 2 (a failed
    write), and the damage was never said: stderr held the write error alone. Both are."""
    bag = _zeroed_at_message_1000(ship["mcap"], tmp_path / "zeroed")
    out = tmp_path / "out"
    args = ["replay", str(bag), "--scene", str(SCENE_FILE), "-o", str(out), "--no-progress"]
    assert main([*args, "--json", "/dev/full"]) == 2
    err = capsys.readouterr().err
    assert f"mount-twin: error: {bag}: damaged (chunk at byte " in err, err
    assert f"; {out} holds the output so far, marked partial in its metadata\n" in err
    assert _damaged_count(err) == 1000 and "Traceback" not in err
    assert err.endswith("mount-twin: error: /dev/full: cannot write: No space left on device\n")


def test_what_reads_a_partial_output_bag_says_it_is_partial(
    ship: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """report, export and srs --response read the output of a replay stopped at damage as if
    it were the whole run: the page to hand over said nothing of it."""
    out = tmp_path / "out"
    assert _replay(_zeroed_at_message_1000(ship["mcap"], tmp_path / "zeroed"), out) == 5
    capsys.readouterr()
    marker = _partial(out)
    page = tmp_path / "r.html"
    scene = ["--scene", str(SCENE_FILE)]
    assert main(["report", str(out), *scene, "-o", str(page)]) == 0
    text = page.read_text(encoding="utf-8")
    assert "(partial run)</h2>" in text and html.escape(marker) in text
    warning = f"mount-twin: warning: {out} is partial: {marker}"
    assert warning in capsys.readouterr().err
    assert main(["export", str(out), "--csv", str(tmp_path / "csv")]) == 0
    assert warning in capsys.readouterr().err
    assert main(["srs", str(out), "--response", "cg", *scene]) == 0
    assert warning in capsys.readouterr().err


def test_bytes_zeroed_where_rosbags_reads_are_caught_by_the_index_count(
    ship: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Where rosbags reads the bag (one our reader leaves to it), it skips the zeroed records
    without an error: the count against the bag's index catches the loss."""
    monkeypatch.setattr(bag_module, "plain_messages", lambda file, topic: None)
    bag = _zeroed_at_message_1000(ship["mcap"], tmp_path / "zeroed")
    out = tmp_path / "out"
    assert _replay(bag, out) == 5
    err = capsys.readouterr().err
    assert f"{bag}: damaged: its index lists {N} messages of /deck/imu, only " in err
    assert "could be read: those lost inside the file were skipped" in err
    assert _partial(out).startswith("stopped by DamagedBagError")


def test_a_killed_recorder_split_bag_is_read_in_file_order_up_to_the_cut(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """No metadata.yaml, NAME_9.mcap whole and NAME_10.mcap cut short (numbered, not
    alphabetical, order): all of the first file, then the second up to its cut."""
    rec = tmp_path / "rec"
    rec.mkdir()
    start = 1_700_000_000_000_000_000
    for i, (begin, keep) in enumerate([(start, 1.0), (start + 500_000_000, 0.5)]):
        part = tmp_path / f"part{i}"
        gen = ["generate", "ship-motion", "-o", str(part), "--duration", "0.5"]
        assert main([*gen, "--start", str(begin)]) == 0
        data = next(part.glob("*.mcap")).read_bytes()
        (rec / f"rec_{9 + i}.mcap").write_bytes(data[: int(len(data) * keep)])
    out = tmp_path / "out"
    assert _replay(rec, out) == 5
    err = capsys.readouterr().err
    assert f"{rec / 'rec_10.mcap'}: a record (opcode 0x06) cut short" in err
    n = _damaged_count(err)
    assert 500 < n < 1000
    _, got = read_bag(out)
    stamps = np.array([t for t, _ in got[POSES]])
    np.testing.assert_array_equal(stamps, start + np.arange(n) * 1_000_000)


def test_an_intact_mcap_without_metadata_yaml_replays_whole(
    ship: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / "no_meta"
    shutil.copytree(ship["mcap"], bag)
    (bag / "metadata.yaml").unlink()
    assert _replay(bag, tmp_path / "out") == 0
    assert f"{N} received, {N} accepted" in capsys.readouterr().out


# --------------------------------------------------------------------------- damaged sqlite3


def test_an_sqlite3_bag_cut_short_replays_its_readable_rows_then_exits_5(
    ship: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """rosbags cannot open it at all (it counts every row first); read row by row, the rows
    before the cut are replayed, and none of a page the cut left half."""
    bag = _edited_copy(ship["sqlite3"], tmp_path / "cut", lambda d: d[: int(len(d) * 0.6)])
    out = tmp_path / "out"
    assert _replay(bag, out) == 5
    err = capsys.readouterr().err
    assert f"{bag}: damaged (" in err and "messages of /deck/imu before the damage" in err
    n = _damaged_count(err)
    assert 0.5 * N < n < 0.6 * N
    _, got = read_bag(out)
    want = [t for t, _ in read_raw(ship["sqlite3"], ["/deck/imu"])["/deck/imu"][:n]]
    assert [t for t, _ in got[POSES]] == want


def _sqlite_header(page_size: int, pages: int) -> Callable[[bytes], bytes]:
    """An edit setting an sqlite file's header page size (1: 65536) and page count."""

    def edit(data: bytes) -> bytes:
        out = bytearray(data)
        struct.pack_into(">H", out, 16, page_size)
        struct.pack_into(">I", out, 28, pages)
        return bytes(out)

    return edit


def test_an_sqlite3_header_giving_a_huge_size_costs_no_memory(
    ship: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without metadata.yaml (so salvaged row by row), a header saying 64 GiB replays whole,
    one saying 256 TiB (no file system holds it) is an error naming the file: the salvage
    asked for that memory (a MemoryError traceback)."""
    bag = _edited_copy(ship["sqlite3"], tmp_path / "big", _sqlite_header(4096, 1 << 24))
    (bag / "metadata.yaml").unlink()
    assert _replay(bag, tmp_path / "out") == 0
    assert len(read_bag(tmp_path / "out")[1][POSES]) == N
    bag = _edited_copy(ship["sqlite3"], tmp_path / "huge", _sqlite_header(1, (1 << 32) - 1))
    (bag / "metadata.yaml").unlink()
    assert _replay(bag, tmp_path / "out2") == 2
    err = capsys.readouterr().err
    assert err.startswith(f"mount-twin: error: {bag}: cannot open bag") and ".db3: " in err
    assert not (tmp_path / "out2").exists()


@pytest.mark.parametrize(
    ("make", "said"),
    [
        (lambda p: None, "no such file or directory"),
        (lambda p: p.mkdir(), "an empty directory"),
        (lambda p: (p.mkdir(), (p / "notes.txt").write_text("x")), "no metadata.yaml and no"),
        (
            lambda p: (p.mkdir(), (p / "x.db3").write_bytes(b"not sqlite" * 100)),
            "no message of /deck/imu comes before its damage (",
        ),
        (  # a recorder killed before its first write: a MemoryError traceback before
            lambda p: (p.mkdir(), (p / "x.db3").write_bytes(b"")),
            "x.db3: empty file (0 bytes)",
        ),
    ],
    ids=["missing", "empty", "no-bag-files", "not-sqlite", "empty-db3"],
)
def test_what_is_no_bag_is_an_error_saying_why(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    make: Callable[[Path], object],
    said: str,
) -> None:
    bag = tmp_path / "bag"
    make(bag)
    assert _replay(bag, tmp_path / "out") == 2
    err = capsys.readouterr().err
    assert err.startswith(f"mount-twin: error: {bag}: cannot open bag") and said in err
    assert not (tmp_path / "out").exists()


def test_a_scene_beyond_the_size_limit_is_an_error_naming_it(
    ship: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--scene /dev/zero was read whole (a MemoryError traceback)."""
    out = tmp_path / "out"
    run = ["replay", str(ship["mcap"]), "--scene", "/dev/zero", "-o", str(out), "--no-progress"]
    assert main(run) == 2
    err = capsys.readouterr().err
    assert "/dev/zero: cannot read: larger than 16 MiB" in err
    assert "SCENE_MAX_BYTES" in err and not out.exists()


def test_messages_of_1_mb_frame_ids_are_read_in_bounded_chunks(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """2000 of them made one 2 GB chunk (a MemoryError traceback): chunks stop at
    CHUNK_MAX_BYTES, and the frame id the error names is cut short."""
    n, frame = 40, "f" * (1 << 20)
    stamps = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 1_000_000
    msgs = imu_messages(stamps, np.tile([0.0, 0.0, 9.81], (n, 1)), np.zeros((n, 3)), frame)
    bag = tmp_path / "frames"
    write_bag(bag, "/deck/imu", IMU, iter(msgs))
    with InputBag(bag, "/deck/imu", IMU) as reading:
        sizes = [len(c) for c in reading.chunks(2000)]
    assert sizes == [32, 8]  # 32 MiB of 1 MiB messages, then the rest
    assert _replay(bag, tmp_path / "out") == 3
    err = capsys.readouterr().err
    assert "rejected: wrong_frame 40; the bag's header.frame_id is 'fff" in err
    assert len(err) < 1000


# --------------------------------------------------------------------------- topics, ROS 1


def test_a_topic_without_messages_is_an_error_listing_the_bag_topics(tmp_path: Path) -> None:
    bag = tmp_path / "bag"
    ((stamp, raw),) = read_raw(_one_message_bag(tmp_path / "one"))["/deck/imu"]
    with Writer(bag, version=Writer.VERSION_LATEST, storage_plugin=StoragePlugin.MCAP) as w:
        w.add_connection("/deck/imu", IMU, typestore=TYPESTORE)
        other = w.add_connection("/imu/data", IMU, typestore=TYPESTORE)
        for k in range(3):
            w.write(other, stamp + k, raw)
    with pytest.raises(
        BagError,
        match=rf"{bag}: no message on topic '/deck/imu' \(input\.topic; `replay --topic` "
        r"overrides it\); the bag has: /deck/imu \(sensor_msgs/msg/Imu, 0 messages\), "
        r"/imu/data \(sensor_msgs/msg/Imu, 3 messages\)",
    ):
        InputBag(bag, "/deck/imu", IMU)


def _garbage_ros1_bag(path: Path) -> Path:
    ros1 = get_typestore(Stores.ROS1_NOETIC)
    with Ros1Writer(path) as writer:
        conn = writer.add_connection("/deck/imu", IMU, typestore=ros1)
        for k in range(3):
            writer.write(conn, 1_700_000_000_000_000_000 + k, b"\x01\x02\x03")
    return path


def test_an_unreadable_ros1_message_is_counted_never_raised(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert _replay(_garbage_ros1_bag(tmp_path / "in.bag"), tmp_path / "out") == 3
    assert "3 received, rejected: undecodable 3" in capsys.readouterr().err


def test_a_ros1_bag_cut_short_is_an_error_naming_it_and_the_repair(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = _garbage_ros1_bag(tmp_path / "in.bag")
    bag.write_bytes(bag.read_bytes()[:-100])
    assert _replay(bag, tmp_path / "out") == 2
    err = capsys.readouterr().err
    assert f"{bag}: cannot open bag: " in err and "`rosbag reindex`" in err


# --------------------------------------------------------------------------- output, stopping


def test_a_full_disk_names_the_output_bag_and_leaves_its_messages_readable(
    ship: dict[str, Path], tmp_path: Path
) -> None:
    """A file size limit (EFBIG, as a full disk's ENOSPC) in a real process: the error names
    the bag, no traceback, and the unfinished bag's messages can still be read."""
    out = tmp_path / "out"
    code = (
        "import resource, sys\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (2_000_000, 2_000_000))\n"
        "from mount_twin.cli import main\n"
        f"sys.exit(main(['replay', {str(ship['mcap'])!r}, '--scene', {str(SCENE_FILE)!r}, "
        f"'-o', {str(out)!r}, '--no-progress']))\n"
    )
    done = run_python("-c", code)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith(f"mount-twin: error: {out}: cannot write: File too large")
    assert "the bag is left unfinished" in done.stderr and "Traceback" not in done.stderr
    with InputBag(out, POSES, POSE) as unfinished:
        assert 0 < unfinished.count < N


def test_a_signal_while_the_kernels_load_stops_before_any_output_exists(
    ship: dict[str, Path], tmp_path: Path
) -> None:
    def signalled() -> None:
        raise KeyboardInterrupt

    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        replay(default_scene(), ship["mcap"], out, progress=False, checkpoint=signalled)
    assert not out.exists()


def test_replay_help_lists_the_exit_statuses(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["replay", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for status in ("3 no input sample accepted", "5 input bag damaged part-way", "130 SIGINT"):
        assert status in text


# --------------------------------------------------------------------------- readings not provided


@pytest.mark.parametrize("gyro_filter", ["linear_phase", "ignore"])
def test_readings_marked_not_provided_are_rejected_alike_in_any_batching(gyro_filter: str) -> None:
    """REP-145 (covariance[0] = -1): a sample without its acceleration is rejected; one
    without its rate too, unless the scene reads no rate (input.gyro_filter: ignore). The
    counts and outputs are the same message by message as in one batch."""

    from mount_twin.stream import TwinStream

    scene = scene_with(input={"gyro_filter": gyro_filter})
    n = 600
    stamps = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 1_000_000
    accel = np.tile([0.0, 0.0, 9.80665], (n, 1))
    good = [raw for _, raw in imu_messages(stamps, accel, np.zeros_like(accel), "deck_imu")]
    raws = [
        *good[:200],
        *unprovided_imu(good[200:210], "linear_acceleration"),
        *unprovided_imu(good[210:230], "angular_velocity"),
        *good[230:],
    ]
    runs = []
    for sizes in ([n], [1] * n):
        stream = TwinStream(scene)
        out, at = [], 0
        for size in sizes:
            out += stream.process(raws[at : at + size])
            at += size
        out += stream.finish()
        comparable = [
            (t, s, comparable_diagnostics(raw) if t == "/diagnostics" else raw)
            for t, s, raw in messages_of(out)
        ]
        runs.append((comparable, dict(stream.engine.counts)))
    (whole, counts), (single, _) = runs
    assert whole == single
    no_rate = 0 if gyro_filter == "ignore" else 20
    assert counts["rejected_no_acceleration"] == 10
    assert counts.get("rejected_no_angular_velocity", 0) == no_rate
    assert counts["accepted"] == n - 10 - no_rate and not counts.get("lost_estimated")
