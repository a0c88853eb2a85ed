"""`mount-twin info`: a bag's topics with types and counts, a scene's content."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from io_helpers import CONFIG, ROOT

from mount_twin.cli import main


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
        "integration: auto (by stiffness: at the first sample interval, again after a "
        "contact), rtol 1e-06" in out
    )
    assert "error estimate on" in out


def test_an_unreadable_bag_is_an_error_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["info", str(tmp_path / "nothing")]) == 2
    assert f"{tmp_path / 'nothing'}: cannot read the bag" in capsys.readouterr().err
