"""`mount-twin info`: a bag's topics with types and counts, a scene's content."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from io_helpers import CONFIG, ROOT
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer

from mount_twin.cli import main
from mount_twin.io.bag_info import _bytes_text, bag_info
from mount_twin.io.messages import IMU, TYPESTORE
from mount_twin.io.output_bag import OutputBag


def test_a_bag_lists_its_topics_types_and_counts(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["info", str(ROOT / "bags" / "genset_shock_10khz")]) == 0
    out = capsys.readouterr().out
    assert "messages:  2500" in out
    assert "/deck/imu  sensor_msgs/msg/Imu" in out and out.rstrip().endswith("2500")
    assert "duration:  0.249900 s" in out  # 2500 samples at 10 kHz: 2499 intervals


def test_a_scene_lists_its_mounts_input_and_resolved_outputs(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["info", str(CONFIG / "genset_bolted_keyed.scene.yaml")]) == 0
    out = capsys.readouterr().out
    assert "3000 kg" in out and "mounts:  8" in out
    assert re.search(r"^  key_y +shear_key +at \[0\.1, 0\.0, 0\.0\] m", out, re.MULTILINE)
    assert "/mount_twin/mounts/foot_fl/wrench" in out
    assert "input:   /deck/imu (sensor_msgs/msg/Imu), frame_id deck_imu" in out
    assert (
        "integration: auto (by stiffness: at each start's first sample interval, again after "
        "a contact), rtol 1e-06" in out
    )
    assert "error estimate on" in out


def test_a_scene_lists_every_topic_its_replay_writes_and_its_body_imu(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """/diagnostics, /tf_static and, with a body_sensor, its input topic and the prediction and
    residual topics were not listed."""
    out_bag = tmp_path / "out"
    genset = str(CONFIG / "genset_bolted_keyed.scene.yaml")
    bag = str(ROOT / "bags" / "genset_shock_10khz")
    assert main(["replay", bag, "--scene", genset, "-o", str(out_bag), "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["info", genset]) == 0
    listed = capsys.readouterr().out.split("outputs (node named mount_twin):\n")[1]
    topics = {line.split()[0]: line.split()[1] for line in listed.splitlines()}
    assert topics == {t.name: t.msgtype for t in bag_info(out_bag).topics}
    assert main(["info", str(ROOT / "test/data/shake_table_1story/block.scene.yaml")]) == 0
    out = capsys.readouterr().out
    assert f"body IMU: /machine/imu ({IMU}), frame_id block_imu, at [0.0, 0.0, 0.15] m" in out
    for topic in ("/mount_twin/body_imu/predicted", "/mount_twin/body_imu/residual"):
        assert re.search(f"^  {topic} +{IMU}$", out, re.MULTILINE)


def test_an_unreadable_bag_is_an_error_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not a bag")
    assert main(["info", str(junk)]) == 2
    assert f"{junk}: cannot read the bag" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["info", "export", "report"])
def test_a_missing_bag_is_named_plainly(
    tmp_path: Path, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """It read "The following paths are missing: [PosixPath('...')]" (rosbags' own text)."""
    missing = tmp_path / "nonexist"
    extra = {
        "export": ["--csv", str(tmp_path / "csv")],
        "report": ["-o", str(tmp_path / "r.html")],
    }
    assert main([command, str(missing), *extra.get(command, [])]) == 2
    err = capsys.readouterr().err
    assert f"mount-twin: error: {missing}: no such file or directory" in err
    assert "PosixPath" not in err


def test_a_bag_without_messages_has_no_start(tmp_path: Path) -> None:
    """Its start read 9223372036.854776382 s (rosbags' empty minimum)."""
    empty = tmp_path / "empty"
    with OutputBag(empty, {"/deck/imu": IMU}):
        pass
    text = bag_info(empty).text()
    assert "start:     none (no message)" in text and "922337" not in text


def test_a_bags_start_is_printed_to_the_nanosecond_it_has(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The start (the first stamp of the vehicle record in ../shared, 1432235498025043042 ns)
    was printed through a float: 1432235498.025043011 s, its last digits made up."""
    bag = tmp_path / "bag"
    start = "1432235498025043042"
    assert main(["generate", "half-sine", "-o", str(bag), "--start", start]) == 0
    capsys.readouterr()
    assert main(["info", str(bag)]) == 0
    assert "start:     1432235498.025043042 s (log time)" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("plugin", "storage", "suffix"),
    [(StoragePlugin.SQLITE3, "sqlite3", ".db3"), (StoragePlugin.MCAP, "mcap", ".mcap")],
)
def test_a_bag_shows_its_files_size_storage_and_end_like_ros2_bag_info(
    tmp_path: Path, plugin: StoragePlugin, storage: str, suffix: str
) -> None:
    """`ros2 bag info` prints Files, Bag size, Storage id, Start and End; info printed none
    of files, size, storage or end. Three String messages at stamps chosen here."""
    bag = tmp_path / "rec"
    stamps = [5_000_000_000, 5_250_000_001, 7_000_000_123]
    string = "std_msgs/msg/String"
    with Writer(bag, version=9, storage_plugin=plugin) as writer:
        conn = writer.add_connection("/chatter", string, typestore=TYPESTORE)
        for ns in stamps:
            msg = TYPESTORE.types[string](data="x")
            writer.write(conn, ns, TYPESTORE.serialize_cdr(msg, string))
    (file,) = [f for f in bag.iterdir() if f.suffix == suffix]
    size = file.stat().st_size
    text = bag_info(bag).text()
    assert f"files:     {file.name}\n" in text
    assert f"storage:   {storage}\n" in text
    assert f"({size} B)" in text or f"size:      {size} B" in text
    assert "start:     5.000000000 s (log time)" in text
    assert "end:       7.000000123 s (log time)" in text
    assert "duration:  2.000000 s" in text
    assert re.search(r"^  /chatter  std_msgs/msg/String +3$", text, re.MULTILINE)
    alone = bag_info(file)  # the storage file given alone: no metadata.yaml to say either
    assert (alone.files, alone.storage, alone.size) == ([file], storage, size)


def test_a_file_compressed_bag_shows_its_metadatas_files_and_storage(tmp_path: Path) -> None:
    """A bag compressed file by file (`ros2 bag record --compression-mode file`): its files
    end in .zstd, which no storage suffix matches; its metadata.yaml names them."""
    bag = tmp_path / "packed"
    string = "std_msgs/msg/String"
    writer = Writer(bag, version=9, storage_plugin=StoragePlugin.SQLITE3)
    writer.set_compression(CompressionMode.FILE, CompressionFormat.ZSTD)
    with writer:
        conn = writer.add_connection("/chatter", string, typestore=TYPESTORE)
        msg = TYPESTORE.serialize_cdr(TYPESTORE.types[string](data="x"), string)
        writer.write(conn, 5_000_000_000, msg)
    (packed,) = [f for f in bag.iterdir() if f.name.endswith(".zstd")]
    info = bag_info(bag)
    assert (info.files, info.storage, info.size) == ([packed], "sqlite3", packed.stat().st_size)


def test_a_bag_size_is_given_in_binary_units() -> None:
    """`ros2 bag info` gives the size in KiB/MiB; 3 MiB + 512 KiB is 3.5 MiB."""
    assert _bytes_text(3 * 2**20 + 2**19) == f"3.5 MiB ({3 * 2**20 + 2**19} B)"
    assert _bytes_text(1023) == "1023 B"
