"""The scene a replay ran, written into its output bag as the node publishes it (`~/scene`,
latched) and in its metadata as separate keys; read back with rosbags and PyYAML, held to the
scene file loaded on its own."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest
import yaml
from io_helpers import CONFIG, ROOT, without_scene_topic
from rosbags.highlevel import AnyReader
from rosbags.interfaces import QosDurability, QosReliability

from mount_twin.cli import main
from mount_twin.io.messages import TYPESTORE
from mount_twin.scene.description import scene_digest, scene_value
from mount_twin.scene.loader import load_scene_file

PUMP = CONFIG / "pump_8_mounts.scene.yaml"
TOPIC = "/mount_twin/scene"


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(the run's scene file, its output bag): the pump replayed from its own directory with
    the scene given relative and --topic given (the scene's own /deck/imu)."""
    d = tmp_path_factory.mktemp("scene_record")
    (d / "run.scene.yaml").write_text(PUMP.read_text(encoding="utf-8"), encoding="utf-8")
    bag = ROOT / "bags" / "half_sine_shock_10khz"
    args = ["replay", str(bag), "--scene", "run.scene.yaml", "--topic", "/deck/imu"]
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(d)
        assert main([*args, "-o", "out", "--no-progress"]) == 0
    return d / "run.scene.yaml", d / "out"


def test_the_replay_writes_its_scene_on_the_scene_topic_once_latched(
    run: tuple[Path, Path],
) -> None:
    """One std_msgs/String on /mount_twin/scene, offered reliable, transient local, depth 1
    (as /tf_static), its JSON the scene's digest (that of the file loaded here), its file's
    absolute path, the --topic given and a value that hashes to the digest and holds the
    file's mass (1200 kg)."""
    scene_file, bag = run
    with AnyReader([bag], default_typestore=TYPESTORE) as reader:
        (conn,) = [c for c in reader.connections if c.topic == TOPIC]
        messages = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages([conn])]
    assert conn.msgtype == "std_msgs/msg/String"
    (qos,) = conn.ext.offered_qos_profiles
    assert qos.durability == QosDurability.TRANSIENT_LOCAL
    assert qos.reliability == QosReliability.RELIABLE and qos.depth == 1
    (msg,) = messages
    record = json.loads(msg.data)
    assert set(record) == {"sha256", "file", "overrides", "value"}
    assert record["sha256"] == scene_digest(load_scene_file(PUMP))
    assert record["file"] == str(scene_file) and Path(record["file"]).is_absolute()
    assert record["overrides"] == {"input.topic": "/deck/imu"}
    text = json.dumps(record["value"], sort_keys=True, separators=(",", ":"))
    assert hashlib.sha256(text.encode()).hexdigest() == record["sha256"]
    assert record["value"]["body"]["mass"] == 1200.0
    assert [m["name"] for m in record["value"]["mounts"]][:2] == ["fl", "fr"]


def test_the_replays_metadata_records_file_overrides_and_digest_apart(
    run: tuple[Path, Path],
) -> None:
    """The scene file and what the command line put over it were one text, which `report`
    parsed back; they are separate keys (with the text kept), the file absolute."""
    scene_file, bag = run
    meta = yaml.safe_load((bag / "metadata.yaml").read_text(encoding="utf-8"))
    custom = meta["rosbag2_bagfile_information"]["custom_data"]
    assert custom["mount_twin.scene_file"] == str(scene_file)
    assert json.loads(custom["mount_twin.scene_overrides"]) == {"input.topic": "/deck/imu"}
    assert custom["mount_twin.scene_sha256"] == scene_digest(load_scene_file(PUMP))
    assert custom["mount_twin.scene"] == "run.scene.yaml (with input topic from the command line)"


def test_the_replays_metadata_records_the_value_its_digest_hashes(run: tuple[Path, Path]) -> None:
    """With the ~/scene topic left out of a bag, its metadata held the digest alone: a scene
    that differs could be told, but not where. It holds the value too, the very text the
    digest is the sha256 of (hashed here by hashlib), with the file's mass and mount names."""
    _, bag = run
    meta = yaml.safe_load((bag / "metadata.yaml").read_text(encoding="utf-8"))
    custom = meta["rosbag2_bagfile_information"]["custom_data"]
    text = custom["mount_twin.scene_value"]
    assert hashlib.sha256(text.encode()).hexdigest() == custom["mount_twin.scene_sha256"]
    value = json.loads(text)
    file = yaml.safe_load(PUMP.read_text(encoding="utf-8"))
    assert value["body"]["mass"] == file["body"]["mass"] == 1200.0
    assert [m["name"] for m in value["mounts"]] == [m["name"] for m in file["mounts"]]


def test_a_metadata_value_that_does_not_hash_to_its_digest_is_refused(
    run: tuple[Path, Path], tmp_path: Path
) -> None:
    """A scene value in the metadata changed after it was hashed is no record of the run."""
    from mount_twin.errors import BagError
    from mount_twin.io.bag_metadata import custom_data
    from mount_twin.io.scene_record import recorded_scene

    _, bag = run
    custom = custom_data(bag)
    assert '"mass":1200.0' in custom["mount_twin.scene_value"]
    changed = custom["mount_twin.scene_value"].replace('"mass":1200.0', '"mass":1500.0')
    filtered = without_scene_topic(bag, tmp_path / "filtered", custom)
    assert recorded_scene(filtered) is not None
    damaged = {**custom, "mount_twin.scene_value": changed}
    with pytest.raises(BagError, match=r"mount_twin\.scene_value in its metadata is no scene"):
        recorded_scene(without_scene_topic(bag, tmp_path / "damaged", damaged))


def test_a_scene_changed_in_code_records_its_file_and_the_changes_over_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A scene loaded from a file, then changed in code (`dataclasses.replace`, as the Python
    API varies one) recorded that file with nothing over it: a file that does not load to the
    run's value. The record (~/scene and the metadata) names the file and each value changed,
    by key path; the file with those values written into it (by PyYAML here) loads to the
    recorded digest, hashed here by hashlib, and `report` takes it as the run's; the file
    alone is refused, naming the run's scene with the changes."""
    import dataclasses

    from mount_twin.replay import replay

    base = tmp_path / "base.scene.yaml"
    base.write_text(PUMP.read_text(encoding="utf-8"), encoding="utf-8")
    loaded = load_scene_file(base)
    fl = loaded.mounts[0]
    stiffer = dataclasses.replace(fl, stiffness=(*fl.stiffness[:2], 2.4e6, *fl.stiffness[3:]))
    scene = dataclasses.replace(
        loaded,
        mounts=(stiffer, *loaded.mounts[1:]),
        outputs=dataclasses.replace(loaded.outputs, diagnostics_period_s=0.1),
    )
    out = tmp_path / "out"
    replay(scene, ROOT / "bags" / "half_sine_shock_10khz", out, progress=False)
    with AnyReader([out], default_typestore=TYPESTORE) as reader:
        (conn,) = [c for c in reader.connections if c.topic == TOPIC]
        ((_, _, raw),) = list(reader.messages([conn]))
        record = json.loads(reader.deserialize(raw, conn.msgtype).data)
    changes = {"mounts[0].stiffness[2]": 2.4e6, "outputs.diagnostics_period_s": 0.1}
    assert record["file"] == str(base)
    assert record["overrides"] == changes
    meta = yaml.safe_load((out / "metadata.yaml").read_text(encoding="utf-8"))
    custom = meta["rosbag2_bagfile_information"]["custom_data"]
    assert custom["mount_twin.scene_file"] == str(base)
    assert json.loads(custom["mount_twin.scene_overrides"]) == changes
    named = f"{base} (with mounts[0].stiffness[2], outputs.diagnostics_period_s changed in code)"
    assert custom["mount_twin.scene"] == named
    data = yaml.safe_load(base.read_text(encoding="utf-8"))
    assert data["mounts"][0]["stiffness"][2] == 1.2e6
    data["mounts"][0]["stiffness"][2] = 2.4e6
    data["outputs"]["diagnostics_period_s"] = 0.1
    (tmp_path / "changed.scene.yaml").write_text(yaml.safe_dump(data), encoding="utf-8")
    value = scene_value(load_scene_file(tmp_path / "changed.scene.yaml"))
    text = json.dumps(value, sort_keys=True, separators=(",", ":"))
    assert hashlib.sha256(text.encode()).hexdigest() == record["sha256"]
    page = ["-o", str(tmp_path / "r.html")]
    assert main(["report", str(out), "--scene", str(tmp_path / "changed.scene.yaml"), *page]) == 0
    assert main(["report", str(out), "--scene", str(base), *page]) == 2
    assert (
        f"{base}: scene pump_8_mounts is not the one {out} was replayed with, {named}: its "
        "digest" in capsys.readouterr().err
    )


def test_a_scene_message_whose_value_does_not_hash_to_its_digest_is_refused(
    run: tuple[Path, Path], tmp_path: Path
) -> None:
    """A ~/scene whose value was changed after it was hashed is no record of the run."""
    from mount_twin.errors import BagError
    from mount_twin.io.output_bag import write_bag
    from mount_twin.io.scene_record import STRING, recorded_scene, scene_text

    record = json.loads(scene_text(load_scene_file(PUMP)))
    record["value"]["body"]["mass"] = 1500.0
    raw = TYPESTORE.serialize_cdr(TYPESTORE.types[STRING](data=json.dumps(record)), STRING)
    write_bag(tmp_path / "bag", TOPIC, STRING, iter([(1, bytes(raw))]))
    with pytest.raises(BagError, match=f"{TOPIC}: the scene's value does not hash to the sha256"):
        recorded_scene(tmp_path / "bag")


def test_a_recording_of_two_scenes_is_refused_naming_the_topic(tmp_path: Path) -> None:
    """A recording over two runs of the node (restarted with another scene) holds two
    ~/scene messages of different digests: no one scene is the run's."""
    from mount_twin.errors import BagError
    from mount_twin.io.output_bag import write_bag
    from mount_twin.io.scene_record import STRING, recorded_scene, scene_text

    texts = [
        scene_text(load_scene_file(f)) for f in (PUMP, CONFIG / "genset_bolted_keyed.scene.yaml")
    ]
    raws = [TYPESTORE.serialize_cdr(TYPESTORE.types[STRING](data=t), STRING) for t in texts]
    write_bag(
        tmp_path / "bag", TOPIC, STRING, iter([(k + 1, bytes(r)) for k, r in enumerate(raws)])
    )
    with pytest.raises(BagError, match=f"{TOPIC}: records 2 scenes .*more than one run"):
        recorded_scene(tmp_path / "bag")
