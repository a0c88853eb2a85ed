"""Starting `mount-twin`: help and argument errors answer without importing numba; a cold kernel
cache is detected cheaply and a compile is announced on stderr."""

from __future__ import annotations

import hashlib
import importlib
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest
from io_helpers import run_python

from mount_twin.cli import main

ROOT = Path(__file__).resolve().parents[1]
HEAVY = re.compile(r"\|\s*(numba|numpy|scipy|rosbags|yaml)(\.|$)")
"""A line of `-X importtime` that imports one of the slow packages."""

replay_module = importlib.import_module("mount_twin.replay")


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    """`python -X importtime -m mount_twin.cli ARGS`, the console script's entry point."""
    return run_python("-X", "importtime", "-m", "mount_twin.cli", *args)


def _heavy_imports(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if HEAVY.search(line)]


@pytest.mark.parametrize("args", [("--help",), ("replay", "--help"), ("generate", "--help")])
def test_help_answers_without_importing_numba(args: tuple[str, ...]) -> None:
    done = _cli(*args)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: mount-twin")
    assert "import time:" in done.stderr, "-X importtime lists every import"
    assert _heavy_imports(done.stderr) == []


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (("bogus",), "invalid choice: 'bogus'"),
        (("replay", "in_bag"), "the following arguments are required: --scene, -o/--output"),
        (("generate", "half-sine", "-o", "x", "--rate", "fast"), "invalid float value: 'fast'"),
    ],
)
def test_an_argument_error_exits_2_without_importing_numba(
    args: tuple[str, ...], says: str
) -> None:
    done = _cli(*args)
    assert done.returncode == 2
    assert "usage: mount-twin" in done.stderr and says in done.stderr
    assert _heavy_imports(done.stderr) == []


# --------------------------------------------------------------------------- cold cache


def _keyed(directory: Path) -> str:
    """numba's cache sub-directory name for the sources in `directory`."""
    return f"{directory.name}_{hashlib.sha1(str(directory).encode()).hexdigest()}"


def test_a_kernel_cache_dir_without_index_files_is_cold(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    assert replay_module.kernel_cache_is_cold()
    engine_dir = Path(str(replay_module.__file__)).resolve().parent / "engine"
    keyed = tmp_path / _keyed(engine_dir)
    keyed.mkdir()
    tag = f"py{sys.version_info.major}{sys.version_info.minor}"
    (keyed / "kernel.run_samples-81.py27.nbi").touch()  # another Python's index: still cold
    assert replay_module.kernel_cache_is_cold()
    (keyed / f"kernel.run_samples-81.{tag}.nbi").touch()
    assert not replay_module.kernel_cache_is_cold()


def test_the_cache_is_warm_once_an_engine_was_built() -> None:
    """Guards the detection against a change of where numba keeps the kernels: once an engine
    exists in this process, its kernels are in the cache `kernel_cache_is_cold` looks at."""
    from mount_twin import TwinEngine, assemble, load_scene_file

    TwinEngine(assemble(load_scene_file(ROOT / "config" / "pump_8_mounts.scene.yaml")))
    assert not replay_module.kernel_cache_is_cold()


def test_a_cold_cache_is_announced_at_once(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(replay_module, "kernel_cache_is_cold", lambda: True)
    with replay_module.kernels_loading():
        assert capsys.readouterr().err == replay_module.COMPILE_NOTICE + "\n"
    assert "first run only" in replay_module.COMPILE_NOTICE
    with replay_module.kernels_loading(notice=False):
        pass
    assert capsys.readouterr().err == ""
    told: list[str] = []  # the node passes its logger: the notice goes there, not to stderr
    with replay_module.kernels_loading(say=told.append):
        assert told == [replay_module.COMPILE_NOTICE]
    assert capsys.readouterr().err == ""


def test_a_slow_load_from_a_warm_cache_is_announced_and_a_fast_one_is_not(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(replay_module, "kernel_cache_is_cold", lambda: False)
    monkeypatch.setattr(replay_module, "COMPILE_NOTICE_AFTER_S", 0.05)
    with replay_module.kernels_loading():
        pass
    time.sleep(0.2)
    assert capsys.readouterr().err == "", "a fast load says nothing, and its timer is cancelled"
    with replay_module.kernels_loading():
        time.sleep(1.0)  # a kernel compiling for a scene the cache has not seen
    assert capsys.readouterr().err == replay_module.COMPILE_NOTICE + "\n"


def test_bag_errors_come_before_the_compile_notice(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(replay_module, "kernel_cache_is_cold", lambda: True)
    assert main(["demo", "-o", str(tmp_path)]) == 2  # the output exists
    err = capsys.readouterr().err
    assert err == (
        f"mount-twin: error: {tmp_path}: output bag exists; choose another path or remove it\n"
    )
    scene = ROOT / "config" / "pump_8_mounts.scene.yaml"
    missing = tmp_path / "no_bag"
    assert main(["replay", str(missing), "--scene", str(scene), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"mount-twin: error: {missing}: cannot open bag")
    assert replay_module.COMPILE_NOTICE not in err
    assert not (tmp_path / "o").exists()


def test_version_is_the_package_version_without_importing_numba() -> None:
    """`--version` answers from the installed metadata, which matches package.xml."""
    done = _cli("--version")
    assert done.returncode == 0, done.stderr
    xml = (ROOT / "package.xml").read_text(encoding="utf-8")
    (declared,) = re.findall(r"<version>([^<]+)</version>", xml)
    assert done.stdout.strip() == f"mount-twin {declared}"
    assert _heavy_imports(done.stderr) == []


def test_every_option_with_a_default_says_it_in_help() -> None:
    """Like the ROS tools: `--help` of each command names every default."""
    import argparse

    from mount_twin.cli import build_parser

    parser, _ = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    for name, command in sub.choices.items():
        text = " ".join(command.format_help().split())  # unwrapped
        for action in command._actions:
            has_default = action.default not in (None, False, argparse.SUPPRESS, 0, 0.0)
            if action.option_strings and has_default and not action.required:
                assert (
                    "default" in (action.help or "") or f"(default: {action.default})" in text
                ), (
                    name,
                    action.dest,
                )


def test_a_missing_optional_dependency_is_named_with_its_extra() -> None:
    from mount_twin.commands.extras import EXTRAS, require
    from mount_twin.errors import MountTwinError

    EXTRAS["no_such_module_for_this_test"] = "plot"
    try:
        with pytest.raises(
            MountTwinError,
            match=r"--plot needs no_such_module_for_this_test, "
            r"which is not installed: pip install 'mount_twin\[plot\]'",
        ):
            require("no_such_module_for_this_test.pyplot", "--plot")
    finally:
        del EXTRAS["no_such_module_for_this_test"]
    require("numpy", "anything")  # installed: no error
