"""Starting `mount-twin`: help and argument errors answer without importing the compiled core or
numpy; bag errors come before the twin is built."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from io_helpers import run_python

from mount_twin.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
HEAVY = re.compile(r"\|\s*(mount_twin\._core|numpy|scipy|rosbags|yaml)(\.|$)")
"""A line of `-X importtime` that imports one of the slow packages."""


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    """`python -X importtime -m mount_twin.cli ARGS`, the console script's entry point."""
    return run_python("-X", "importtime", "-m", "mount_twin.cli", *args)


def _heavy_imports(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if HEAVY.search(line)]


@pytest.mark.parametrize("args", [("--help",), ("replay", "--help"), ("generate", "--help")])
def test_help_answers_without_importing_numerics(args: tuple[str, ...]) -> None:
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
        # counts below 1: `replay --chunk 0` looped for ever, `qualify --workers -1` hung
        (("replay", "b", "--scene", "s", "-o", "o", "--chunk", "0"), "--chunk: must be ≥ 1"),
        (("qualify", "s", "--plan", "p", "-o", "o", "--workers", "-1"), "--workers: must be ≥ 1"),
        (("sweep", "s", "-o", "o", "--workers", "0"), "--workers: must be ≥ 1, got 0"),
        (("accuracy", "s", "b", "--max-substeps", "0"), "--max-substeps: must be ≥ 1, got 0"),
        (("build-tf2-msgs", "--jobs", "x"), "--jobs/-j: 'x' is not an integer"),
        # numpy's "expected non-negative integer", naming no option
        (("synthesize", "--spectrum", "s", "-o", "o", "--first-seed", "-5"), "--first-seed: must"),
    ],
)
def test_an_argument_error_exits_2_without_importing_numerics(
    args: tuple[str, ...], says: str
) -> None:
    done = _cli(*args)
    assert done.returncode == 2
    assert "usage: mount-twin" in done.stderr and says in done.stderr
    assert _heavy_imports(done.stderr) == []


def test_bag_errors_come_before_the_twin_is_built(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
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
    assert not (tmp_path / "o").exists()


def test_version_is_the_package_version_without_importing_numerics() -> None:
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


def test_a_reader_that_closes_the_pipe_ends_the_command_quietly_with_141() -> None:
    """`mount-twin srs BAG | head -1` printed "mount-twin: error: [Errno 32] Broken pipe" and
    exited 2, as for bad input."""
    child = subprocess.Popen(
        [sys.executable, "-m", "mount_twin.cli", "info", str(ROOT / "bags" / "ship_motion_1khz")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=ROOT,
    )
    assert child.stdout is not None and child.stderr is not None
    child.stdout.close()  # gone before anything is written
    err = child.stderr.read().decode()
    assert child.wait(timeout=60) == 141
    assert err == ""


def _help(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    """`mount-twin ARGS --help`, its whitespace made single spaces."""
    with pytest.raises(SystemExit):
        main([*args, "--help"])
    return " ".join(capsys.readouterr().out.split())


SIGNALS = {130, 141, 143}
"""SIGINT, SIGPIPE, SIGTERM: 128 + the signal's number (signal(7)), from any command."""
OWN_EXIT_STATUSES = {
    "replay": {0, 2, 3, 4, 5, 6},
    "demo": {0, 2, 3, 5, 6},
    "report": {0, 2, 3, 4, 6},
    "srs": {0, 2, 4},
    "qualify": {0, 2, 4, 6},
    "calibrate": {0, 2},
    "track": {0, 1, 2, 4},
    "sweep": {0, 2, 6},
}
"""What each command's `run` can return (read from its code: `verdict`, `run_exit_status`, the
verdict maps; 5 where an input bag is replayed up to a damage); any other command 0 or 2."""


@pytest.mark.parametrize("command", sorted(build_parser()[1]))
def test_every_commands_help_lists_the_exit_statuses_it_returns(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """`replay --help` left out 141 (a reader that closed the pipe: the test above), and most
    commands listed no exit status, or not the signals'."""
    helped = _help(capsys, command)
    listed = helped[helped.index("exit status: ") :]
    codes = {int(c) for c in re.findall(r"(?:^exit status: |; )(\d+) ", listed)}
    assert codes == OWN_EXIT_STATUSES.get(command, {0, 2}) | SIGNALS


def test_qualify_help_shows_the_synthesis_defaults(capsys: pytest.CaptureFixture[str]) -> None:
    """qualify parses --seeds, --rate, --axis to None (to see one given beside --plan), so its
    help showed no default; they are synthesize's: 3 seeds at 20 kHz along z."""
    helped = _help(capsys, "qualify")
    for said in ("one per seed (default: 3;", "Hz (default: 20000.0;", "shock (default: z;"):
        assert said in helped
    synth = _help(capsys, "synthesize")
    for said in ("one per seed (default: 3)", "Hz (default: 20000.0)", "shock (default: z)"):
        assert said in synth


def test_import_csv_offset_help_says_the_stamp_in_one_formula(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """It read "added to the time in ns (the CSV's time cells exactly as written) for the
    header stamp, ns (a stamp of 0 means unset in ROS)"."""
    helped = _help(capsys, "import-csv")
    assert "--offset NS header stamp = NS + the CSV's time, ns" in helped
