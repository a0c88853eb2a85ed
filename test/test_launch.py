"""The launch file builds its description where launch_ros is installed (a sourced Jazzy).

launch and launch_ros are not on the package registry, so this test skips in a plain venv and
in CI; `colcon test` on a Jazzy machine runs it.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

pytest.importorskip("launch_ros")
pytest.importorskip("ament_index_python")

LAUNCH_FILE = Path(__file__).resolve().parents[1] / "launch" / "mount_twin.launch.py"


def test_launch_file_declares_its_arguments_and_the_node(monkeypatch: pytest.MonkeyPatch) -> None:
    from launch.actions import DeclareLaunchArgument
    from launch_ros.actions import Node

    share = LAUNCH_FILE.parents[1]
    monkeypatch.setattr(
        "ament_index_python.packages.get_package_share_directory", lambda _pkg: str(share)
    )
    spec = importlib.util.spec_from_file_location("mount_twin_launch", LAUNCH_FILE)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    description = module.generate_launch_description()
    args = {a.name for a in description.entities if isinstance(a, DeclareLaunchArgument)}
    assert args == {"params_file", "use_sim_time"}
    nodes = [e for e in description.entities if isinstance(e, Node)]
    assert len(nodes) == 1
