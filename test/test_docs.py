"""The README and docs/ say what runs: every `mount-twin` command in them parses with the
command line as written and names files that exist, their Python examples run, their scene
excerpt is the bundled scene's, and their links point at files of the repository."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
import yaml
from io_helpers import ROOT

from mount_twin.cli import build_parser

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
REPO_DIRS = ("config/", "bags/", "test/data/", "docs/", "bench/")
"""A command argument starting with one of these names a file of the repository."""
FENCE = re.compile(r"```(\w+)\n(.*?)```", re.S)


def _commands(page: Path) -> list[str]:
    """The `mount-twin …` command lines of a page (indented or fenced code), comments cut."""
    found = []
    for line in page.read_text(encoding="utf-8").splitlines():
        text = line.strip()
        for part in text.split(" && "):
            if part.startswith("mount-twin "):
                found.append(part.split("  #")[0].split(" # ")[0].strip())
    return found


COMMANDS = [(p.relative_to(ROOT).as_posix(), c) for p in PAGES for c in _commands(p)]


def test_the_pages_hold_commands() -> None:
    assert len(COMMANDS) > 25
    assert {p for p, _ in COMMANDS} >= {"README.md", "docs/offline.md"}


@pytest.mark.parametrize(("page", "command"), COMMANDS)
def test_every_command_parses_and_names_files_that_exist(page: str, command: str) -> None:
    """Optional parts written `[--flag VALUE]` are taken as given; placeholders in capitals
    (IN_BAG, SCENE) are any text to the parser."""
    args = shlex.split(command.replace("[", "").replace("]", ""))[1:]
    parser, _ = build_parser()
    try:
        parser.parse_args(args)
    except SystemExit as stop:  # --version and --help exit 0 once parsed
        if stop.code != 0:
            pytest.fail(f"{page}: `{command}` does not parse (exit {stop.code})")
    for arg in args:
        if arg.startswith(REPO_DIRS):
            assert (ROOT / arg).exists(), f"{page}: `{command}` names {arg}, which is not there"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_the_python_examples_run(page: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    for lang, code in FENCE.findall(page.read_text(encoding="utf-8")):
        if lang == "python":
            exec(compile(code, str(page), "exec"), {})


def test_the_readme_scene_excerpt_is_the_bundled_scene() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    (excerpt,) = [code for lang, code in FENCE.findall(text) if lang == "yaml"]
    shown = yaml.safe_load(excerpt)
    bundled = yaml.safe_load((ROOT / "config/pump_8_mounts.scene.yaml").read_text("utf-8"))
    assert shown["mounts"] == bundled["mounts"][: len(shown["mounts"])]
    for key in ("name", "frames", "body", "dofs"):
        assert shown[key] == bundled[key], key


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_links_point_at_files_of_the_repository(page: Path) -> None:
    for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", page.read_text(encoding="utf-8")):
        if "://" in target:
            continue
        assert (page.parent / target).exists(), f"{page.name}: link to {target}, not there"


def test_the_diagnostics_keys_the_pages_name_are_the_ones_the_twin_reports() -> None:
    """A renamed diagnostics key (est_resyncs became est_failed_checks) fails here, not in a
    user's dashboard: every `est_…` key a page names is one the integration status carries."""
    import numpy as np

    from mount_twin import SampleBatch, TwinEngine, assemble, load_scene_file

    engine = TwinEngine(assemble(load_scene_file(ROOT / "config/pump_8_mounts.scene.yaml")))
    t = np.arange(2000) * 1e-3
    rest = np.tile([0.0, 0.0, 9.80665], (t.size, 1))
    out = engine.run(SampleBatch(t, rest, np.zeros((t.size, 3)), ["deck_imu"] * t.size))
    reported = {k for s in out.health[-1].statuses for k in s.values}
    named = {k for page in PAGES for k in re.findall(r"`(est_[a-z_]+)`", page.read_text())}
    assert named and named <= reported, sorted(named - reported)


def _heading_anchors(page: Path) -> set[str]:
    """The anchors GitHub makes of a page's headings: lower case, spaces as hyphens, other
    punctuation dropped."""
    headings = re.findall(r"^#+ (.+)$", page.read_text(encoding="utf-8"), re.M)
    return {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-") for h in headings}


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_link_anchors_name_headings_of_their_pages(page: Path) -> None:
    """node.md's [Scene](scene.md#scene) and benchmarks.md's [Keeping up](node.md#as-a-ros-2-
    package) led to the top of the page: neither heading exists."""
    text = page.read_text(encoding="utf-8")
    for target, anchor in re.findall(r"\]\(([^)#:]*)#([^)]+)\)", text):
        linked = page.parent / target if target else page
        if linked.suffix == ".md":
            assert anchor in _heading_anchors(linked), f"{page.name}: {target}#{anchor}"


def test_the_sweep_case_ids_offline_md_prints_are_the_bundled_sweeps() -> None:
    """A case id hashes the base scene: after an edit of the pump the printed summary named
    ids (658cd7036e59, …) that `mount-twin sweep config/sweep_pump.yaml` no longer writes, so a
    reader could not find its rows in the CSV. Each id printed is the case of its input and
    stiffness scale."""
    from mount_twin.sweeps.cases import expand
    from mount_twin.sweeps.spec import load_sweep

    text = (ROOT / "docs/offline.md").read_text(encoding="utf-8")
    printed = []
    for line in text.splitlines():
        case = re.search(r"case ([0-9a-f]{12}) \(.*stiffness \(scale\) = ([\d.]+)\)", line)
        name = re.search(r"half_sine_\d+", line)
        if case and name:
            printed.append((name[0], case[1], float(case[2])))
    cases = {
        (case.input.name, case.settings[0][2]): case.case_id
        for case in expand(load_sweep(ROOT / "config/sweep_pump.yaml"))
    }
    assert len(printed) == 5
    for name, case_id, scale in printed:
        assert cases[(name, scale)] == case_id, (name, scale)


def _scene_rows() -> dict[str, str]:
    """scene.md's key table: each key path of a row's first cell (`input.max_gap_s`,
    `gap_policy` → input.gap_policy) mapped to its row."""
    rows = {}
    for line in (ROOT / "docs/scene.md").read_text(encoding="utf-8").splitlines():
        keys = re.findall(r"`([\w.\[\]]+)`", line.split("|")[1]) if line.startswith("| `") else []
        if not keys:
            continue
        first, *others = keys
        section = first.rsplit(".", 1)[0]
        for key in (first, *(f"{section}.{name}" for name in others)):
            rows[key] = line
    return rows


def _default_texts(value: object) -> list[str]:
    """How a page may write a default: `true`, `first_order`, empty, 0.5, 1e-6, 1.309."""
    if isinstance(value, bool):
        return [f"`{str(value).lower()}`"]
    if isinstance(value, (int, float)):
        return [f"{value:g}", f"{value:.4g}", re.sub(r"e-0(\d)", r"e-\1", f"{value:g}")]
    return [f"`{value}`"] if value else ["empty"]


def test_scene_md_gives_every_scalar_default() -> None:
    """README promises every key's default in scene.md; the table gave no unit or default for
    `outputs.diagnostics_period_s`, `input.max_gap_s`, `integration.rtol` … (20 of them)."""
    import dataclasses

    from mount_twin.scene.description import (
        Frames,
        InitialState,
        InputSpec,
        Integration,
        Outputs,
    )

    rows = _scene_rows()
    sections = {
        "input": InputSpec,
        "initial_state": InitialState,
        "integration": Integration,
        "outputs": Outputs,
        "frames": Frames,
    }
    missing = []
    for section, cls in sections.items():
        for field in dataclasses.fields(cls):
            if isinstance(field.default, tuple):  # vectors: their rows give the components
                continue
            row = rows.get(f"{section}.{field.name}", "")
            if not any(text in row for text in _default_texts(field.default)):
                missing.append(f"{section}.{field.name} = {field.default!r}")
    assert not missing, missing


def test_the_resampling_offline_md_quotes_is_the_bundled_shocks() -> None:
    """offline.md quoted `resampled: 206 of 19998 steps` from a record the repository no longer
    holds; `srs` on the bundled water-entry shock says 34 of 4999, the off-median steps of its
    time column counted here."""
    import numpy as np

    text = (ROOT / "docs/offline.md").read_text(encoding="utf-8")
    ((off, steps),) = re.findall(r"`resampled: (\d+) of (\d+) steps are off the median", text)
    t = np.loadtxt(
        ROOT / "test/data/water_entry_shock_20khz_excerpt.csv",
        delimiter=",",
        skiprows=1,
        usecols=0,
    )
    step = np.diff(t)
    median = np.median(step)
    off_median = int((np.abs(step - median) > 0.005 * median).sum())  # srs: 0.5 % of it
    assert (int(off), int(steps)) == (off_median, step.size)
