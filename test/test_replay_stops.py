"""A replay stopped part-way leaves a readable bag marked partial, and says so with its exit
status: SIGINT (Ctrl-C) 130, SIGTERM 143, an input damaged part-way 5 (the messages before the
damage are replayed); a damaged mcap is read up to the damage."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from io_helpers import CONFIG, ROOT, read_bag
from rosbags.highlevel import AnyReader

from mount_twin.cli import main
from mount_twin.io.bag_metadata import PARTIAL_KEY
from mount_twin.io.mcap_writer import CHUNK_BYTES
from mount_twin.io.messages import TYPESTORE

PUMP = str(CONFIG / "pump_8_mounts.scene.yaml")


def _custom_data(bag: Path) -> dict[str, str]:
    import yaml

    meta = yaml.safe_load((bag / "metadata.yaml").read_text(encoding="utf-8"))
    return meta["rosbag2_bagfile_information"].get("custom_data") or {}


@pytest.fixture(scope="module")
def long_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    bag = tmp_path_factory.mktemp("long") / "ship_120s"
    assert main(["generate", "ship-motion", "-o", str(bag), "--duration", "120"]) == 0
    return bag


@pytest.mark.parametrize(
    ("sig", "code", "said"),
    [(signal.SIGINT, 130, "interrupted (SIGINT)"), (signal.SIGTERM, 143, "terminated (SIGTERM)")],
)
def test_a_signal_leaves_a_readable_bag_marked_partial(
    long_bag: Path, tmp_path: Path, sig: int, code: int, said: str
) -> None:
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "mount_twin.cli", "replay", str(long_bag), "--scene", PUMP]
    proc = subprocess.Popen(
        [*cmd, "-o", str(out), "--no-progress"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    deadline = time.monotonic() + 120.0
    mcap = out / "out.mcap"
    while not (mcap.exists() and mcap.stat().st_size > CHUNK_BYTES):  # well into the replay:
        assert time.monotonic() < deadline and proc.poll() is None, proc.communicate()
        time.sleep(0.01)  # its first chunk written, about 1 % of it (the whole takes seconds)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == code, err
    assert said in err and f"{out} holds the output so far, marked partial" in err
    assert "Traceback" not in err
    marker = _custom_data(out)[PARTIAL_KEY]
    assert marker.startswith("stopped by") and "outputs up to stamp" in marker
    with AnyReader([out], default_typestore=TYPESTORE) as reader:
        n = sum(1 for _ in reader.messages())
    assert 0 < n < 120_000 * 10  # readable, and stopped early


def _cut_copy(bag: Path, keep: Callable[[int], int]) -> Path:
    """A copy of the ship-motion bag at `bag` whose mcap keeps its first keep(size) bytes."""
    shutil.copytree(ROOT / "bags" / "ship_motion_1khz", bag)
    (mcap,) = bag.glob("*.mcap")
    data = mcap.read_bytes()
    mcap.write_bytes(data[: keep(len(data))])
    return bag


def test_a_truncated_mcap_is_replayed_up_to_the_damage(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = _cut_copy(tmp_path / "cut", lambda n: int(n * 0.6))  # a recorder killed mid-write
    out = tmp_path / "out"
    assert main(["replay", str(bag), "--scene", PUMP, "-o", str(out), "--no-progress"]) == 5
    err = capsys.readouterr().err
    assert f"{bag}: damaged (" in err and "messages of /deck/imu before the damage" in err
    n = int(err.split("the ")[1].split(" messages")[0])
    assert 2900 <= n <= 3010  # ~60 % of 5000, to the last whole message record
    _, msgs = read_bag(out)
    assert len(msgs["/mount_twin/pose"]) == n
    assert "DamagedBagError" in _custom_data(out)[PARTIAL_KEY]


def test_an_mcap_cut_before_any_message_is_an_error_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = _cut_copy(tmp_path / "stub", lambda n: 43)
    assert main(["replay", str(bag), "--scene", PUMP, "-o", str(tmp_path / "o")]) == 2
    assert f"{bag}: cannot open bag" in capsys.readouterr().err


def test_a_damaged_bag_whose_run_failed_says_both(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Exit 5 names the damage; the integration failures before it were said only in the
    summary's verdict (FAILED), not on stderr with the damage."""
    bag = _cut_copy(tmp_path / "cut", lambda n: int(n * 0.6))
    text = (CONFIG / "pump_8_mounts.scene.yaml").read_text(encoding="utf-8")
    failing = (
        text.replace("  method: auto ", "  method: dopri54 #")
        .replace("  max_substeps: 10000", "  max_substeps: 1")
        .replace("  rtol: 1.0e-6", "  rtol: 1.0e-13")
        .replace("  atol: 1.0e-9", "  atol: 1.0e-15")
    )
    scene = tmp_path / "failing.scene.yaml"
    scene.write_text(failing, encoding="utf-8")
    out = tmp_path / "out"
    assert main(["replay", str(bag), "--scene", str(scene), "-o", str(out), "--no-progress"]) == 5
    captured = capsys.readouterr()
    assert f"{bag}: damaged (" in captured.err and "integration failed " in captured.err
    assert "verdict: FAILED" in captured.out


@pytest.mark.parametrize("command", ["accuracy", "report"])
def test_an_analysis_of_a_truncated_mcap_exits_2_saying_it_analysed_none_of_it(
    tmp_path: Path, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """accuracy and report --input read their input whole: on a truncated mcap they printed
    nothing and wrote nothing, yet exited 5 saying "the N messages ... before the damage were
    processed", replay's word for a run summarised up to the damage."""
    bag = _cut_copy(tmp_path / "cut", lambda n: int(n * 0.6))
    page = tmp_path / "r.html"
    if command == "accuracy":
        args = ["accuracy", PUMP, str(bag), "--rtol", "1e-4"]
    else:
        run = tmp_path / "run"
        whole = str(ROOT / "bags" / "ship_motion_1khz")
        assert main(["replay", whole, "--scene", PUMP, "-o", str(run), "--no-progress"]) == 0
        args = ["report", str(run), "--scene", PUMP, "--input", str(bag), "-o", str(page)]
    capsys.readouterr()
    assert main(args) == 2
    captured = capsys.readouterr()
    assert captured.err.count("mount-twin: error: ") == 1, captured.err
    assert captured.err.startswith(f"mount-twin: error: {bag}: damaged (")
    assert "processed" not in captured.err
    assert captured.err.endswith(
        f"{bag} is damaged part-way, and this analysis reads its record whole: none of it was "
        "analysed (`mount-twin replay` runs what comes before the damage)\n"
    )
    assert not page.exists()
