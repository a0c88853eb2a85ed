"""`mount-twin report`: one self-contained page; its events and peaks are the replay's own."""

from __future__ import annotations

import csv
import dataclasses
import hashlib
import html
import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from io_helpers import CONFIG, ROOT, read_bag, read_raw, unprovided_imu, without_scene_topic

from mount_twin.cli import main
from mount_twin.io.output_tables import Table, events_of, input_values, read_output_bag
from mount_twin.model.scene_file import OVERRIDDEN
from mount_twin.replay import replay
from mount_twin.scene.loader import load_scene_file

GENSET = CONFIG / "genset_bolted_keyed.scene.yaml"
BAG = ROOT / "bags" / "genset_shock_10khz"


@pytest.fixture(scope="module")
def genset_run(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("report") / "out"
    summary = replay(load_scene_file(GENSET), BAG, out, progress=False)
    return out, summary


def test_events_in_the_report_are_the_engines_first_events_per_period(genset_run) -> None:
    out, summary = genset_run
    tables = {t.name: t for t in read_output_bag(out)}
    origin = int(tables["pose"].columns["stamp_ns"][0])
    events = events_of(tables["diagnostics"], origin)
    assert events, "the genset shock opens joints"
    # Each reported group is named by its first event: that event exists in the engine's log.
    for e in events:
        same = [
            x
            for x in summary.events
            if x.mount == e.mount
            and x.event == e.event
            and abs(summary.origin_s + x.stamp - (origin * 1e-9 + e.t_s)) < 2e-6
        ]
        assert same, e
        assert e.level == same[0].level, f"{e}: the engine's event says {same[0].level}"


def test_each_event_in_the_report_has_its_own_level_not_its_periods(genset_run) -> None:
    """A slip is a WARN (bolted_joint: the joint holds by friction again), even in a period
    whose mount status is an ERROR for a bolt that yielded or a joint that opened."""
    out, _ = genset_run
    tables = {t.name: t for t in read_output_bag(out)}
    events = events_of(tables["diagnostics"], int(tables["pose"].columns["stamp_ns"][0]))
    slips = [e for e in events if e.event == "joint_slipped"]
    assert slips and all(e.level == "WARN" for e in slips), slips
    opened = [e for e in events if e.event == "joint_opened"]
    assert opened and all(e.level == "ERROR" for e in opened), opened


def test_the_page_is_self_contained_with_plots_tables_and_names(
    genset_run, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, _ = genset_run
    page = tmp_path / "r.html"
    args = ["report", str(out), "--scene", str(GENSET), "--input", str(BAG), "-o", str(page)]
    assert main(args) == 0
    text = page.read_text(encoding="utf-8")
    assert "genset_bolted_keyed" in text and "genset_shock_10khz" in text
    assert len(re.findall(r'src="data:image/png;base64,', text)) >= 4
    assert 'src="http' not in text and "<script" not in text  # one file, nothing fetched
    assert "Around the first event: foot_" in text and "joint_opened" in text
    assert "Shock response spectra of the input" in text and "Modes (about the static" in text
    # It opens with the verdict (the replay's own), what produced it from what, the settings
    # and the scene as loaded, every value with its meaning and unit.
    _, summary = genset_run
    head = text[: text.index("Input and response")]
    assert f"<h2>Verdict: {summary.verdict}</h2>" in head
    assert "produced by</td><td>mount_twin 0.1.0, " in head and "input bag</td><td>" in head
    # Each of the bag's files with its sha256 as `sha256sum` prints it (a 16-hex digest over
    # names and sums was labelled sha256, and no one could check it).
    sums = ", ".join(
        f"{f.name} {hashlib.sha256(f.read_bytes()).hexdigest()}" for f in sorted(BAG.iterdir())
    )
    assert f"genset_shock_10khz (sha256 {sums})" in head
    assert "gyro_filter linear_phase" in head and "rtol 1e-06" in head
    assert "<td>body.mass</td><td>3000.0</td><td>Body mass, kg</td>" in head
    # The peak table holds each mount's largest |F| of the bag.
    _, msgs = read_bag(out)
    f = max(
        np.linalg.norm([m.wrench.force.x, m.wrench.force.y, m.wrench.force.z])
        for _, m in msgs["/mount_twin/mounts/foot_fl/wrench"]
    )
    row = re.search(r"<td>foot_fl</td><td>bolted_joint</td><td>([^<]*)</td>", text)
    assert row and float(row.group(1)) == pytest.approx(f, rel=1e-3)


def test_input_without_scene_is_refused(genset_run, capsys: pytest.CaptureFixture[str]) -> None:
    out, _ = genset_run
    assert "--input needs --scene" in _refused(["report", str(out), "--input", str(BAG)], capsys)


def test_utilisation_series_come_from_the_diagnostics(genset_run) -> None:
    from mount_twin.analysis.report_plots import utilisation_of

    out, summary = genset_run
    tables = {t.name: t for t in read_output_bag(out)}
    series = utilisation_of(tables["diagnostics"])
    for name, peak in summary.utilisation_max.items():
        assert np.max(series[name][1]) == pytest.approx(peak, rel=1e-3), name


def _refused(args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """What `mount-twin <args>` says on stderr, having asserted that it exits 2 (refused)."""
    assert main(args) == 2
    return capsys.readouterr().err


def _margins(page: str) -> list[float]:
    """The 'margin z dB' column of the spectra table of a report page."""
    table = page[page.index("<th>margin z dB</th>") :]
    table = table[: table.index("</table>")]
    rows = re.findall(r"<tr>(.*?)</tr>", table)
    cells = [re.findall(r"<td>([^<]*)</td>", r) for r in rows]
    return [float(c[-1]) for c in cells if c and c[-1] != "–"]


def test_a_design_spectrum_judges_the_inputs_spectra(genset_run, tmp_path: Path) -> None:
    """With --design (--axis all), the input's spectra are judged: a PASS/FAIL line per axis
    and each axis's margin 20 log10(spectrum/design) in the table. Doubling the design lowers
    every margin by 20 log10 2 = 6.02 dB, and a design far below the record is exceeded on
    every axis."""
    out, _ = genset_run
    pages = []
    for name, level_g in (("d1", 10.0), ("d2", 20.0), ("tiny", 1e-3)):
        table = tmp_path / f"{name}.csv"
        table.write_text(f"frequency_hz,accel_g\n10,{level_g}\n1000,{level_g}\n", "utf-8")
        page = tmp_path / f"{name}.html"
        args = ["report", str(out), "--scene", str(GENSET), "--input", str(BAG), "-o", str(page)]
        code = main([*args, "--design", str(table), "--axis", "all"])
        pages.append(page.read_text(encoding="utf-8"))
        spectra = pages[-1].split("<h2>Shock response")[1]
        assert code == (4 if ": FAIL" in spectra else 0), name  # as srs --design exits
    one, two, tiny = pages
    for axis in "xyz":
        assert f"<b>design d1.csv</b>, axis {axis}: " in one  # it named no file
    m1, m2 = _margins(one), _margins(two)
    assert len(m1) >= 5 and len(m1) == len(m2)
    assert np.allclose(np.subtract(m1, m2), 20.0 * np.log10(2.0), atol=0.011)  # 2-decimal cells
    spectra = tiny.split("<h2>Shock response")[1]
    assert spectra.count(": FAIL") == 3 and "PASS" not in spectra  # x: no input there, short
    assert re.search(
        r"axis z: 0 of \d+ frequencies within -1.5/\+3 dB[^<]*: FAIL: over by", spectra
    )


def test_a_design_judges_the_axes_axis_names_as_srs_does(
    genset_run, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`srs --design --axis z` judges the vertical; `report --design` had no --axis and judged
    x, y and z against the one design, so a vertical design failed any record with nothing
    fore-aft (the genset's shock: "no response" along x), exit 4. It takes srs's --axis
    (default z): the design made of the record's own vertical spectrum (`srs --csv`) passes
    along z in both, its line the same in both, and fails along all three."""
    out, _ = genset_run
    capsys.readouterr()
    spectrum = tmp_path / "z.csv"
    assert main(["srs", str(BAG), "--axis", "z", "--csv", str(spectrum)]) == 0
    rows = list(csv.DictReader(spectrum.open(encoding="utf-8")))
    design = tmp_path / "vertical.csv"
    design.write_text(
        "frequency_hz,accel_g\n" + "".join(f"{r['frequency_hz']},{r['maximax']}\n" for r in rows),
        encoding="utf-8",
    )
    lines = {}
    for axis in ("x", "z"):
        capsys.readouterr()
        code = main(["srs", str(BAG), "--design", str(design), "--axis", axis])
        line = re.search(
            rf"^design {re.escape(str(design))}, axis {axis} maximax: (.*)$",
            capsys.readouterr().out,
            re.M,
        )
        assert line, axis
        lines[axis] = line.group(1)
        assert code == (0 if axis == "z" else 4), (axis, lines[axis])
    args = ["report", str(out), "--scene", str(GENSET), "--input", str(BAG), "--design"]
    for given, judged, status in (
        ([], "z", 0),
        (["--axis", "z"], "z", 0),
        (["--axis", "all"], "xyz", 4),
    ):
        page = tmp_path / f"{'_'.join(given) or 'default'}.html"
        assert main([*args, str(design), *given, "-o", str(page)]) == status, given
        text = html.unescape(page.read_text(encoding="utf-8"))
        said = dict(re.findall(r"<p><b>design vertical.csv</b>, axis (\w): ([^<]*)</p>", text))
        assert list(said) == list(judged), given
        assert re.findall(r"<th>margin (\w) dB</th>", text) == list(judged), given
        for axis in set(said) & set(lines):
            assert said[axis] == lines[axis], (given, axis)


def test_a_design_needs_the_input(genset_run, capsys: pytest.CaptureFixture[str]) -> None:
    out, _ = genset_run
    table = Path(__file__).parent / "data"  # any path: refused before it is read
    err = _refused(["report", str(out), "--design", str(table / "none.csv")], capsys)
    assert "--design judges the input's spectra: it needs --input" in err


def test_with_its_scene_the_report_lists_the_mounts_in_the_scenes_order(tmp_path: Path) -> None:
    """The pump's scene names ml1, mr1, ml2, mr2 in that order (the replay's summary's); the
    bag's topics sort ml1, ml2, mr1, mr2, the order without the scene."""
    pump = CONFIG / "pump_8_mounts.scene.yaml"
    out = tmp_path / "out"
    replay(load_scene_file(pump), ROOT / "bags" / "ship_motion_1khz", out, progress=False)
    order = {}
    for label, extra in (("scene", ["--scene", str(pump)]), ("bag", [])):
        page = tmp_path / f"{label}.html"
        assert main(["report", str(out), *extra, "-o", str(page)]) == 0
        table = page.read_text(encoding="utf-8").split("Peaks (largest")[1].split("</table>")[0]
        order[label] = re.findall(r"<tr><td>([^<]+)</td>", table)
    scene = [m.name for m in load_scene_file(pump).mounts]
    assert order["scene"] == scene == ["fl", "fr", "ml1", "mr1", "ml2", "mr2", "rl", "rr"]
    assert order["bag"] == sorted(scene)


def test_another_scenes_mounts_are_refused_naming_both(
    genset_run, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The pump's scene on the genset's bag: its name, kinds, modes and scene table headed the
    genset's numbers, exit 0."""
    out, _ = genset_run
    page = tmp_path / "wrong.html"
    pump = CONFIG / "pump_8_mounts.scene.yaml"
    err = _refused(["report", str(out), "--scene", str(pump), "-o", str(page)], capsys)
    assert (
        "scene pump_8_mounts (report --scene): its mounts (fl, fr, ml1, mr1, ml2, mr2, rl, rr)"
        in err
    )
    assert "(foot_fl, foot_fr, foot_ml, foot_mr, foot_rl, foot_rr, key_x, key_y)" in err
    assert not page.exists()


def _pump_input(path: Path, n: int = 10_000, bad: slice = slice(0)) -> Path:
    """A pump input bag (/deck/imu, frame deck_imu) of `n` samples at 1 kHz: a 5 g, 11 ms
    vertical half-sine in its first second, then at rest; the samples `bad` with every accel
    reading NaN."""
    from mount_twin.io.messages import IMU
    from mount_twin.io.output_bag import write_bag
    from mount_twin.io.output_encoding import imu_messages
    from mount_twin.io.signals import half_sine_shock

    shock = half_sine_shock(peak=50.0, duration=0.011, rate_hz=1000.0, total=1.0)
    accel = np.tile([0.0, 0.0, 9.80665], (n, 1))
    accel[:1000] = shock.accel[:n]
    accel[bad] = np.nan
    stamps = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 1_000_000
    messages = imu_messages(stamps, accel, np.zeros_like(accel), "deck_imu")
    write_bag(path, "/deck/imu", IMU, iter(messages))
    return path


def test_an_input_marking_accelerations_not_provided_inside_is_refused_naming_the_bag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The replay disregards 3 samples whose acceleration the IMU marks not provided
    (covariance[0] = -1, REP-145, zeros in it); the input's spectra took their zeros as
    readings, a hole in the shock. Between samples the replay takes, leaving them out would
    join those around them: refused, as a sample not finite there is, naming the bag, the
    topic, how many and the first."""
    from mount_twin.io.messages import IMU
    from mount_twin.io.output_bag import write_bag

    pump = str(CONFIG / "pump_8_mounts.scene.yaml")
    (msgs,) = read_raw(_pump_input(tmp_path / "plain", 2000), ["/deck/imu"]).values()
    ns, raws = zip(*msgs[1500:1503], strict=True)
    marked = [
        *msgs[:1500],
        *zip(ns, unprovided_imu(list(raws), "linear_acceleration"), strict=True),
        *msgs[1503:],
    ]
    write_bag(tmp_path / "marked", "/deck/imu", IMU, iter(marked))
    out = tmp_path / "out"
    assert (
        main(
            ["replay", str(tmp_path / "marked"), "--scene", pump, "-o", str(out), "--no-progress"]
        )
        == 0
    )
    assert "no_acceleration 3" in capsys.readouterr().out
    page = tmp_path / "r.html"
    args = [
        "report",
        str(out),
        "--scene",
        pump,
        "--input",
        str(tmp_path / "marked"),
        "-o",
        str(page),
    ]
    err = _refused(args, capsys)
    assert (
        f"{tmp_path / 'marked'}: /deck/imu: 3 of 2000 samples the replay rejects "
        "(no_acceleration 3); sample 1500 (t = 1.5 s from the first) marks its acceleration "
        "not provided (covariance[0] = -1, REP-145), between samples it takes" in err
    ), err
    assert not page.exists()


def _spectra_table(page: str) -> str:
    """The input's spectra table of a report page."""
    part = page[page.index("<h2>Shock response spectra") :]
    return part[part.index("<table") : part.index("</table>")]


def test_an_inputs_samples_not_finite_after_the_others_are_skipped_as_the_replay_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The input's last 9000 samples NaN: the replay skips them, and the report had refused
    the input with srs's "the record must be a non-empty 1-D array of finite values (shape
    (10000,))", naming no bag nor axis. It skips them too, saying how many and where in its
    output and on the page; its spectra are those of a bag of the first 1000 samples alone."""
    pump = str(CONFIG / "pump_8_mounts.scene.yaml")
    tail = _pump_input(tmp_path / "tail_nan", bad=slice(1000, None))
    first = _pump_input(tmp_path / "first_second", n=1000)
    out = tmp_path / "out"
    assert main(["replay", str(tail), "--scene", pump, "-o", str(out), "--no-progress"]) == 0
    assert "rejected: non_finite 9000" in capsys.readouterr().out
    pages = {}
    for bag in (tail, first):
        page = tmp_path / f"{bag.name}.html"
        args = ["report", str(out), "--scene", pump, "--input", str(bag), "-o", str(page)]
        assert main(args) == 0
        pages[bag.name] = page.read_text(encoding="utf-8")
    said = (
        f"{tail}: /deck/imu: 9000 of 10000 samples the replay rejects (non_finite 9000) left "
        "out, as the replay skips them: 9000 after its last (samples 1000–9999)"
    )
    assert said in capsys.readouterr().out
    assert "sample 1000 (t = 1 s from the first) has accel x nan" in pages["tail_nan"]
    assert "samples not finite" not in pages["first_second"]
    assert _spectra_table(pages["tail_nan"]) == _spectra_table(pages["first_second"])
    assert re.search(r"<td>[1-9][\d.]*</td>", _spectra_table(pages["tail_nan"]))  # the shock


def test_an_inputs_samples_the_replay_rejects_at_its_ends_are_left_out_whatever_the_reason(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The input's first 5 samples NaN and its last 3 marking their acceleration not provided
    (REP-145): the replay rejects both kinds and takes the rest. The report skipped the NaN
    ones but refused the record for the marked ones (exit 2). It leaves both out now, saying
    how many of each and at which end, and its spectra are those of a bag of samples 5–1996
    alone."""
    from mount_twin.io.messages import IMU
    from mount_twin.io.output_bag import write_bag

    pump = str(CONFIG / "pump_8_mounts.scene.yaml")
    holed = _pump_input(tmp_path / "holed", 2000, bad=slice(0, 5))
    (msgs,) = read_raw(holed, ["/deck/imu"]).values()
    ns, raws = zip(*msgs[1997:], strict=True)
    ends = tmp_path / "ends"
    marked = zip(ns, unprovided_imu(list(raws), "linear_acceleration"), strict=True)
    write_bag(ends, "/deck/imu", IMU, iter([*msgs[:1997], *marked]))
    middle = tmp_path / "middle"
    write_bag(middle, "/deck/imu", IMU, iter(msgs[5:1997]))
    out = tmp_path / "out"
    assert main(["replay", str(ends), "--scene", pump, "-o", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "non_finite 5" in printed and "no_acceleration 3" in printed  # what the twin took
    pages = {}
    for bag in (ends, middle):
        page = tmp_path / f"{bag.name}.html"
        args = ["report", str(out), "--scene", pump, "--input", str(bag), "-o", str(page)]
        assert main(args) == 0
        pages[bag.name] = html.unescape(page.read_text(encoding="utf-8"))
    said = (
        f"{ends}: /deck/imu: 8 of 2000 samples the replay rejects (non_finite 5, "
        "no_acceleration 3) left out, as the replay skips them: 5 before the first it takes "
        "(samples 0–4), 3 after its last (samples 1997–1999); the first: sample 0 (t = 0 s "
        "from the first) has accel x nan; the input's plot and spectra are of the other 1992"
    )
    assert said in capsys.readouterr().out
    assert said in pages["ends"]
    assert "left out" not in pages["middle"]
    assert _spectra_table(pages["ends"]) == _spectra_table(pages["middle"])
    assert re.search(r"<td>[1-9][\d.]*</td>", _spectra_table(pages["ends"]))  # the shock


def test_an_inputs_sample_not_finite_between_finite_ones_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One NaN sample inside the record: the spectra take the samples as evenly spaced, and
    dropping it would join its neighbours. Refused, naming the bag, the topic, the sample and
    its axis (it was srs's "the record must be … finite values (shape (10000,))")."""
    pump = str(CONFIG / "pump_8_mounts.scene.yaml")
    holed = _pump_input(tmp_path / "holed", bad=slice(500, 501))
    out = tmp_path / "out"
    assert main(["replay", str(holed), "--scene", pump, "-o", str(out), "--no-progress"]) == 0
    capsys.readouterr()
    page = tmp_path / "r.html"
    args = ["report", str(out), "--scene", pump, "--input", str(holed), "-o", str(page)]
    err = _refused(args, capsys)
    assert (
        f"{holed}: /deck/imu: 1 of 10000 samples the replay rejects (non_finite 1); sample 500 "
        "(t = 0.5 s from the first) has accel x nan, between samples it takes" in err
    ), err
    assert not page.exists()


def test_a_run_replayed_with_topic_reports_its_input_from_that_topic(tmp_path: Path) -> None:
    """`replay --topic /hull/imu` ran the record on /hull/imu; `report --input` of that run read
    the scene's /deck/imu instead, refused the bag (exit 2) and told the user to pass
    `replay --topic`, an option `report` has not. The page reads the topic the run read, and
    says it."""
    pump = CONFIG / "pump_8_mounts.scene.yaml"
    bag, out, page = tmp_path / "hull_bag", tmp_path / "out", tmp_path / "page.html"
    generate = ["generate", "half-sine", "-o", str(bag), "--peak", "150", "--pulse", "0.008"]
    assert main([*generate, "--topic", "/hull/imu", "--frame-id", "hull_imu"]) == 0
    replay_args = ["replay", str(bag), "--scene", str(pump), "-o", str(out), "--no-progress"]
    assert main([*replay_args, "--topic", "/hull/imu", "--frame-id", "hull_imu"]) == 0
    report = ["report", str(out), "--scene", str(pump), "--input", str(bag), "-o", str(page)]
    assert main(report) == 0
    text = html.unescape(page.read_text(encoding="utf-8"))
    assert "/hull/imu (sensor_msgs/msg/Imu)" in text  # the run's input, as the page names it
    said = "/hull/imu (the run's, from `replay --topic`; the file's: /deck/imu)"
    assert re.findall(r">([^<>]*/deck/imu[^<>]*)<", text) == [said]
    assert "Shock response spectra of the input" in text  # the record was read


def test_an_input_axis_without_motion_shows_no_infinite_margin(genset_run, tmp_path) -> None:
    """The genset's shock has nothing fore-aft (x): its spectrum there is 0, and the page read
    "short by inf dB" and a margin column of "-inf". It says the axis has no response."""
    out, _ = genset_run
    table = tmp_path / "d.csv"
    table.write_text("frequency_hz,accel_g\n10,10\n1000,10\n", "utf-8")
    page = tmp_path / "p.html"
    args = ["report", str(out), "--scene", str(GENSET), "--input", str(BAG), "-o", str(page)]
    assert main([*args, "--design", str(table), "--axis", "all"]) == 4
    spectra = html.unescape(page.read_text(encoding="utf-8")).split("<h2>Shock response")[1]
    spectra = spectra[: spectra.index("<h2>", 1)]
    assert "inf" not in spectra and "nan" not in spectra
    assert re.search(
        r"axis x: 0 of \d+ frequencies [^<]*: FAIL: no response at 10–905.1 Hz", spectra
    )
    rows = re.findall(r"<tr>(.*?)</tr>", spectra[spectra.index("<th>margin x dB</th>") :])
    x_cells = [re.findall(r"<td>([^<]*)</td>", r)[-3] for r in rows[1:]]
    assert set(x_cells) == {"–", "no response"}


PUMP = CONFIG / "pump_8_mounts.scene.yaml"


def _pump_replayed(tmp_path_factory: pytest.TempPathFactory, bag: str) -> Path:
    """The pump's output bag of the bundled `bag`, replayed by the command line."""
    out = tmp_path_factory.mktemp(bag) / "out"
    path = ROOT / "bags" / bag
    assert main(["replay", str(path), "--scene", str(PUMP), "-o", str(out), "--no-progress"]) == 0
    return out


@pytest.fixture(scope="module")
def pump_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The pump's output bag of the bundled half-sine shock."""
    return _pump_replayed(tmp_path_factory, "half_sine_shock_10khz")


def _table_rows(page: str, heading: str) -> list[list[str]]:
    """The data rows' cells of the first table after the heading that starts with `heading`."""
    part = page[page.index(f"<h2>{heading}") :]
    part = part[part.index("<table") : part.index("</table>")]
    rows = re.findall(r"<tr>(.*?)</tr>", part)[1:]
    return [re.findall(r"<td>([^<]*)</td>", row) for row in rows]


def test_the_reports_effective_masses_read_as_modes_prints_them(
    pump_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The pump is symmetric about its x-z plane: its lateral-roll modes move no mass fore-aft
    or vertically. `modes` printed those masses 0.0, the report 1.268e-25 kg (the eigenvectors'
    round-off, to four significant figures). Both now show every effective mass alike."""
    capsys.readouterr()
    assert main(["modes", str(PUMP)]) == 0
    printed = capsys.readouterr().out.splitlines()
    head = next(i for i, line in enumerate(printed) if "effective mass kg along" in line)
    by_modes = [line.split()[2:5] for line in printed[head + 2 : head + 8]]
    page = tmp_path / "r.html"
    assert main(["report", str(pump_run), "--scene", str(PUMP), "-o", str(page)]) == 0
    rows = _table_rows(page.read_text(encoding="utf-8"), "Modes (about the static")
    assert [r[4:7] for r in rows] == by_modes
    lateral = [r for r in rows if r[3].split()[0] in ("y", "alpha")]
    assert len(lateral) == 2, rows  # lateral-roll, and roll-lateral
    for r in lateral:
        assert (r[4], r[6]) == ("0.0", "0.0"), r  # x and z: none, by symmetry
        assert float(r[5]) > 0.0, r


def test_the_reports_mode_frequencies_read_as_modes_prints_them(
    pump_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`modes` printed the pump's yaw mode at 12.315 Hz and its surge mode at 7.830 Hz, the
    report's modes table 12.32 and 7.83 (four significant figures): the same mode read two
    ways. Both give every frequency to 1 mHz."""
    capsys.readouterr()
    assert main(["modes", str(PUMP)]) == 0
    printed = capsys.readouterr().out.splitlines()
    head = next(i for i, line in enumerate(printed) if line.split()[:3] == ["mode", "f", "Hz"])
    by_modes = [line.split()[1] for line in printed[head + 2 : head + 8]]
    page = tmp_path / "r.html"
    assert main(["report", str(pump_run), "--scene", str(PUMP), "-o", str(page)]) == 0
    rows = _table_rows(page.read_text(encoding="utf-8"), "Modes (about the static")
    assert [r[1] for r in rows] == by_modes
    assert all(re.fullmatch(r"\d+\.\d{3}", f) for f in by_modes), by_modes


def test_the_reports_damping_and_energy_shares_read_as_modes_prints_them(
    pump_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch
) -> None:
    """An undamped mode's ζ = φᵀCφ/2ω comes out of round-off of either sign: at −1e-19 the
    report's modes table printed "-0.00" (its own format) where `modes` printed 0.00. Both
    print ζ and the dominant DOF's energy share by one rule, a rounded zero without a sign.
    The pump's modes, its first mode's damping replaced by that round-off."""
    from mount_twin.analysis import modes as modal

    real = modal.modes(load_scene_file(PUMP))
    first = dataclasses.replace(real.modes[0], damping_ratio=-1e-19)
    rounded = dataclasses.replace(real, modes=(first, *real.modes[1:]))
    monkeypatch.setattr(modal, "modes", lambda *args, **kwargs: rounded)
    capsys.readouterr()
    assert main(["modes", str(PUMP)]) == 0
    printed = capsys.readouterr().out.splitlines()
    head = next(i for i, line in enumerate(printed) if line.split()[:3] == ["mode", "f", "Hz"])
    by_modes = [line.split()[2:6] for line in printed[head + 2 : head + 8]]  # ζ, DOF, share, %
    page = tmp_path / "r.html"
    assert main(["report", str(pump_run), "--scene", str(PUMP), "-o", str(page)]) == 0
    rows = _table_rows(page.read_text(encoding="utf-8"), "Modes (about the static")
    assert [[r[2], *r[3].split()] for r in rows] == by_modes
    for r, m in zip(rows, rounded.modes, strict=True):
        assert float(r[2]) == pytest.approx(100 * m.damping_ratio, abs=0.005), r
        dof, share, _ = r[3].split()
        assert dof == max(m.energy_fraction, key=m.energy_fraction.__getitem__), r
        assert float(share) == pytest.approx(100 * m.energy_fraction[dof], abs=0.5), r
    assert rows[0][2] == "0.00"  # not -0.00


def test_the_reports_peak_loads_read_as_the_replay_summary_prints_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The pump's front mounts under the bundled shock: the replay's summary printed their
    peak |F| as 10848.2 N, the report's peaks table as 1.085e+04 (and |M| 0.9 against
    0.9104 N·m): the same figure in two forms. Both print every mount's peak |F| and |M| as
    the summary does; each is the bag's own largest magnitude, to the digits shown."""
    out, page = tmp_path / "out", tmp_path / "r.html"
    bag = ROOT / "bags" / "half_sine_shock_10khz"
    capsys.readouterr()
    assert main(["replay", str(bag), "--scene", str(PUMP), "-o", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    by_summary = {
        name: [force, couple]
        for name, force, couple in re.findall(r"^ +(\w+): +([\d.]+) +([\d.]+)$", printed, re.M)
    }
    utilisation = dict(re.findall(r"^ +(\w+): ([\d.]+)$", printed, re.M))
    assert main(["report", str(out), "--scene", str(PUMP), "-o", str(page)]) == 0
    rows = _table_rows(page.read_text(encoding="utf-8"), "Peaks (")
    assert {r[0]: r[2:4] for r in rows} == by_summary
    # the utilisation too: the page printed 3 significant figures (0.99983 read "1", the
    # ERROR limit, for a mount at WARN), the summary 3 decimals with the digits that keep it
    assert {r[0]: r[4] for r in rows} == utilisation
    _, msgs = read_bag(out)
    for name, (force, couple) in by_summary.items():
        wrench = [m.wrench for _, m in msgs[f"/mount_twin/mounts/{name}/wrench"]]
        f = max(np.linalg.norm([w.force.x, w.force.y, w.force.z]) for w in wrench)
        c = max(np.linalg.norm([w.torque.x, w.torque.y, w.torque.z]) for w in wrench)
        for cell, value in ((force, f), (couple, c)):
            last = 10.0 ** -len(cell.partition(".")[2])  # the last digit shown
            assert abs(float(cell) - value) <= 0.5 * last * (1 + 1e-9), (name, cell, value)
    assert list(by_summary) == [m.name for m in load_scene_file(PUMP).mounts]


def test_peak_couples_print_to_significant_figures_as_forces_do(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The pump's mounts put a couple of 0.91 N·m on the body (500 N·m/rad about each axis):
    the replay's summary and the report printed every one of them "0.9", to 0.1 N·m, one
    significant figure where a force has five. Every peak |F| and |M| is printed to four
    significant figures at least (a force keeps its 0.1 N), in the summary and the report
    alike, each the summary JSON's figure to the digits shown."""
    doc_path = tmp_path / "summary.json"
    bag = ROOT / "bags" / "half_sine_shock_10khz"
    out = tmp_path / "out"
    args = ["replay", str(bag), "--scene", str(PUMP), "-o", str(out)]
    capsys.readouterr()
    assert main([*args, "--no-progress", "--json", str(doc_path)]) == 0
    printed = capsys.readouterr().out
    doc = json.loads(doc_path.read_text(encoding="utf-8"))["mounts"]
    by_summary = {
        name: [force, couple]
        for name, force, couple in re.findall(r"^ +(\w+): +([\d.]+) +([\d.]+)$", printed, re.M)
    }
    page = tmp_path / "r.html"
    assert main(["report", str(out), "--scene", str(PUMP), "-o", str(page)]) == 0
    rows = _table_rows(page.read_text(encoding="utf-8"), "Peaks (")
    assert {r[0]: r[2:4] for r in rows} == by_summary
    assert set(by_summary) == set(doc)
    for name, cells in by_summary.items():
        values = (doc[name]["peak_force_magnitude_N"], doc[name]["peak_couple_magnitude_Nm"])
        assert 0.1 < values[1] < 10.0, values  # a couple that 0.1 N·m resolved to one figure
        for cell, value in zip(cells, values, strict=True):
            whole, _, decimals = cell.partition(".")
            assert len((whole + decimals).lstrip("0")) >= 4 and len(decimals) >= 1, cell
            shown = 10.0 ** -len(decimals)
            assert abs(float(cell) - value) <= 0.5 * shown * (1 + 1e-9), (name, cell, value)


@pytest.mark.parametrize("value", [1e-18, 3.3e-7, 0.012345, 0.9104, 10848.24])
def test_a_peak_is_printed_to_its_digits_but_never_finer_than_a_tenth_of_a_milli(
    value: float,
) -> None:
    """A couple of round-off (1e-18 N·m: a symmetric machine's) printed to four significant
    figures in positional notation read 0.000000000000000001000: a peak goes to 4 decimals at
    most, and is the value to within half its last digit."""
    from mount_twin.analysis.figures import peak_text

    cell = peak_text(value)
    decimals = cell.partition(".")[2]
    assert "e" not in cell and 1 <= len(decimals) <= 4, cell
    assert abs(float(cell) - value) <= 0.5 * 10.0 ** -len(decimals) * (1 + 1e-9), cell


def test_the_reports_figures_are_labelled_in_words_with_their_units(
    pump_run: Path, tmp_path: Path
) -> None:
    """The page labelled its figures with the JSON's keys: a paragraph
    "max_cg_displacement_from_start_m (CG): 0.00815331" and peak columns
    "peak_force_magnitude_N", "peak_couple_magnitude_Nm". It says them in words, units after."""
    page = tmp_path / "r.html"
    assert main(["report", str(pump_run), "--scene", str(PUMP), "-o", str(page)]) == 0
    text = html.unescape(page.read_text(encoding="utf-8"))
    for key in ("max_cg_displacement_from_start_m", "peak_force_magnitude_N", "_Nm"):
        assert key not in text
    peaks = text[text.index("<h2>Peaks (") :]
    head = re.findall(r"<th>([^<]*)</th>", peaks[: peaks.index("</tr>")])
    assert head == [
        "mount",
        "kind",
        "peak force |F|, N",
        "peak couple |M|, N·m",
        "utilisation max",
    ]
    moved = re.search(r"<p>max CG displacement from start, m: ([^<]*)</p>", text)
    assert moved and 0.0 < float(moved.group(1)) < 0.1, moved  # the pump moves mm, not m


@pytest.mark.parametrize(("expected", "named"), [("hull_imu", "hull_imu"), ("", "any")])
def test_a_run_replayed_with_frame_id_is_reported_with_the_frame_it_expected(
    tmp_path: Path, expected: str, named: str
) -> None:
    """`replay --frame-id hull_imu` (or '', any frame) ran a record from the hull's IMU; the
    output bag did not record the frame the run expected, and the page's input row named the
    scene's deck_imu, which would have rejected every sample. The run's input status records
    it, and the page names it."""
    bag, out, page = tmp_path / "hull_bag", tmp_path / "out", tmp_path / "page.html"
    generate = ["generate", "half-sine", "-o", str(bag), "--peak", "150", "--pulse", "0.008"]
    assert main([*generate, "--frame-id", "hull_imu"]) == 0
    replay_args = ["replay", str(bag), "--scene", str(PUMP), "-o", str(out), "--no-progress"]
    assert main([*replay_args, "--frame-id", expected]) == 0
    diagnostics = next(t for t in read_output_bag(out) if t.name == "diagnostics")
    assert input_values(diagnostics)["frame_id"] == expected
    report = ["report", str(out), "--scene", str(PUMP), "--input", str(bag), "-o", str(page)]
    assert main(report) == 0
    text = html.unescape(page.read_text(encoding="utf-8"))
    assert "<td>input</td><td>/deck/imu (sensor_msgs/msg/Imu), frame " + named + "</td>" in text
    said = "(the run's, from `replay --frame-id`; the file's: deck_imu)"
    assert f"<td>input.frame_id</td><td>{named} {said}</td>" in text


@pytest.fixture(scope="module")
def pump_ship_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The pump's output bag of the bundled ship motion."""
    return _pump_replayed(tmp_path_factory, "ship_motion_1khz")


def test_without_its_scene_the_report_names_what_the_bag_records_of_the_input_and_solver(
    pump_ship_run: Path, tmp_path: Path
) -> None:
    """The output bag's input status records the topic the run read and the frame it expected,
    its integration status the method that ran and the tolerances: the page without --scene
    left out the input and solver rows altogether. It names them now, and says the rest of the
    settings need --scene (the scene file, read here, is the truth it must agree with)."""
    import yaml

    scene = yaml.safe_load(PUMP.read_text(encoding="utf-8"))
    page = tmp_path / "page.html"
    assert main(["report", str(pump_ship_run), "-o", str(page)]) == 0
    rows = dict(_table_rows(html.unescape(page.read_text(encoding="utf-8")), "Verdict"))
    topic, frame = scene["input"]["topic"], scene["input"]["frame_id"]
    assert (topic, frame) == ("/deck/imu", "deck_imu")
    assert rows["input"].startswith(f"{topic}, frame {frame}")
    assert "--scene" in rows["input"]
    integ = scene["integration"]
    assert f"rtol {integ['rtol']:g}, atol {integ['atol']:g}" in rows["solver"]
    assert "--scene" in rows["solver"]


def test_a_run_shorter_than_a_diagnostics_period_draws_one_point_per_mount(
    tmp_path: Path,
) -> None:
    """A 0.05 s record under diagnostics_period_s 0.1 has one period, reported once at the
    input's end: its utilisation figure drew each mount's one peak as a flat line across the
    whole run, as if measured all along. It draws one point per reported period, at the
    report's stamp."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from mount_twin.analysis.report_plots import draw_utilisation, utilisation_of

    bag, out = tmp_path / "in", tmp_path / "out"
    generate = ["generate", "ship-motion", "-o", str(bag), "--rate", "1000"]
    assert main([*generate, "--duration", "0.05"]) == 0
    scene = load_scene_file(PUMP)
    outputs = dataclasses.replace(scene.outputs, diagnostics_period_s=0.1)
    replay(dataclasses.replace(scene, outputs=outputs), bag, out, progress=False)
    diagnostics = next(t for t in read_output_bag(out) if t.name == "diagnostics")
    utilisation = utilisation_of(diagnostics)
    assert sorted(utilisation) == sorted(m.name for m in scene.mounts)
    fig = Figure()
    draw_utilisation(fig, utilisation, {})
    (ax,) = fig.axes
    drawn = {
        str(line.get_label()): (line.get_xdata(), line.get_ydata())
        for line in ax.get_lines()
        if line.get_label() in utilisation
    }
    assert sorted(drawn) == sorted(utilisation)
    for name, (x, y) in drawn.items():
        # 0.05 s of input is less than one period: one report, at the last sample (0.049 s
        # after the first at 1 kHz), holding the period's peak
        assert len(x) == len(y) == 1, name
        assert float(x[0]) == pytest.approx(0.049, abs=1e-9)
        assert float(y[0]) == float(utilisation[name][1][0])


def test_without_its_scene_a_run_that_accepted_no_sample_names_the_method_set_as_recorded(
    tmp_path: Path,
) -> None:
    """A run whose every input sample was rejected (the record's frame is hull_imu, the pump's
    scene expects deck_imu) never chose a method: its integration status names the method the
    scene set (the pump's `auto`) until one runs. The page without --scene printed it and then
    sent the reader to --scene for "the method the scene set", which it had just printed: it
    says the method is the one set, that none ran and why, and needs no --scene for it."""
    import yaml

    bag, out, page = tmp_path / "hull_bag", tmp_path / "out", tmp_path / "page.html"
    generate = ["generate", "half-sine", "-o", str(bag), "--peak", "150", "--pulse", "0.008"]
    assert main([*generate, "--frame-id", "hull_imu"]) == 0
    replay_args = ["replay", str(bag), "--scene", str(PUMP), "-o", str(out), "--no-progress"]
    assert main(replay_args) == 3  # no input sample accepted
    assert main(["report", str(out), "-o", str(page)]) == 3  # no input sample accepted
    rows = dict(_table_rows(html.unescape(page.read_text(encoding="utf-8")), "Verdict"))
    integ = yaml.safe_load(PUMP.read_text(encoding="utf-8"))["integration"]
    assert integ["method"] == "auto"
    assert rows["solver"] == (
        f"auto (the method set; no method ran: no input sample was accepted), "
        f"rtol {integ['rtol']:g}, atol {integ['atol']:g}, error estimate on "
        "(as the run's integration status records them)"
    )


def _utilisation_drawn(
    monkeypatch: pytest.MonkeyPatch, report_args: list[str]
) -> tuple[dict[str, tuple[np.ndarray, np.ndarray, list[int]]], str]:
    """The utilisation figure `report_args` draws, per mount: the line's x (s) and y, and the
    indices of the points it marks; and the page's text."""
    from mount_twin.analysis import report

    drawn: dict[str, tuple[np.ndarray, np.ndarray, list[int]]] = {}
    draw = report.draw_utilisation

    def keep(fig: Any, *args: Any, **kwargs: Any) -> None:
        draw(fig, *args, **kwargs)
        for line in fig.axes[0].get_lines():
            x, y = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
            marked = line.get_markevery()
            indices = list(range(len(x)))
            if isinstance(marked, slice):
                indices = indices[marked]
            drawn[str(line.get_label()).split(" ")[0]] = (x, y, indices)

    monkeypatch.setattr(report, "draw_utilisation", keep)
    assert main(report_args) == 0
    page = Path(report_args[report_args.index("-o") + 1])
    return drawn, html.unescape(page.read_text(encoding="utf-8"))


def test_with_its_scene_the_first_utilisation_report_steps_over_its_period(
    pump_ship_run: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each report holds the peak of the diagnostics period ending at its stamp: the figure
    drew the step into each from the report before, but the first as a marker alone. With the
    scene its period is known (the pump's diagnostics_period_s 1 s): the ship record's first
    sample is the first output (t 0), its first report is due one period later, at 1 s, and
    its step spans 0 to 1 s. Only the reports are marked, not the step's start."""
    import yaml

    period = yaml.safe_load(PUMP.read_text(encoding="utf-8"))["outputs"]["diagnostics_period_s"]
    assert period == 1.0
    page = tmp_path / "page.html"
    args = ["report", str(pump_ship_run), "--scene", str(PUMP), "-o", str(page)]
    drawn, _ = _utilisation_drawn(monkeypatch, args)
    mounts = yaml.safe_load(PUMP.read_text(encoding="utf-8"))["mounts"]
    assert sorted(n for n in drawn if not n.startswith("rated")) == sorted(
        m["name"] for m in mounts
    )
    for name, (x, y, marked) in drawn.items():
        if name.startswith("rated"):
            continue
        # 5 s at 1 kHz: reports at 1, 2, 3, 4 s and at the last sample, 4.999 s
        assert x.tolist() == pytest.approx([0.0, 1.0, 2.0, 3.0, 4.0, 4.999], abs=1e-9), name
        assert y[0] == y[1], name  # the first period's peak, held from its start
        assert marked == [1, 2, 3, 4, 5], name


def test_without_its_scene_the_first_utilisation_report_is_a_marker_said_so(
    pump_ship_run: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Without the scene the first period's length is not known: the first report stays a
    marker at its stamp, and the page says why its step is not drawn."""
    page = tmp_path / "page.html"
    drawn, text = _utilisation_drawn(monkeypatch, ["report", str(pump_ship_run), "-o", str(page)])
    x, _, marked = drawn["fl"]
    assert x.tolist() == pytest.approx([1.0, 2.0, 3.0, 4.0, 4.999], abs=1e-9)
    assert marked == [0, 1, 2, 3, 4]
    note = text[text.index("<h2>Utilisation</h2>") :]
    note = note[: note.index("<h2>", 4)]
    assert "the first report's period is not drawn" in note and "--scene" in note


def test_the_first_utilisation_step_starts_a_period_before_its_report_or_at_the_first_output() -> (
    None
):
    """The first step spans the period before the first report, clipped at the first output
    (t 0): a report at 2.5 s of a 1 s period starts at 1.5 s, one at 0.049 s at 0."""
    from mount_twin.analysis.report_plots import utilisation_lines

    series = {
        "late": (np.array([2.5, 3.5]), np.array([0.3, 0.4])),
        "short": (np.array([0.049]), np.array([0.7])),
    }
    lines = utilisation_lines(series, 1.0)
    assert lines["late"][0].tolist() == pytest.approx([1.5, 2.5, 3.5])
    assert lines["late"][1].tolist() == [0.3, 0.3, 0.4]
    assert lines["short"][0].tolist() == pytest.approx([0.0, 0.049])
    assert lines["short"][1].tolist() == [0.7, 0.7]
    unknown = utilisation_lines(series, None)
    assert unknown["late"][0].tolist() == [2.5, 3.5]


def _pump_scene(path: Path, change: Any = None) -> Path:
    """The pump's scene written to `path` by yaml (its comments, order and layout gone), with
    `change(data)` applied to its mapping first."""
    import yaml

    data = yaml.safe_load(PUMP.read_text(encoding="utf-8"))
    if change is not None:
        change(data)
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def _set(*keys: Any, value: Any) -> Any:
    """A change setting data[keys[0]][keys[1]]... to `value`."""

    def change(data: Any) -> None:
        for key in keys[:-1]:
            data = data[key]
        data[keys[-1]] = value

    return change


OTHER_VALUES = {
    "a mount's stiffness": _set("mounts", 0, "stiffness", 2, value=2.4e6),
    "the mass": _set("body", "mass", value=1500.0),
    "the diagnostics period": _set("outputs", "diagnostics_period_s", value=0.25),
    "a rating": _set("mounts", 3, "rated_load", value=[6000.0, 6000.0, 4500.0]),
}


@pytest.mark.parametrize("what", OTHER_VALUES)
def test_a_scene_with_the_runs_mounts_and_another_value_is_refused_naming_both(
    pump_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], what: str
) -> None:
    """The pump's mounts, one value changed: only the mount names were compared, so another
    scene's period drew the utilisation's first step, and its name, modes and scene table
    headed the run's numbers, exit 0. The replay records its scene's digest in the output
    bag's metadata: refused, exit 2, naming both scene files; --other-scene draws with it all
    the same, and the page and stderr say it is not the run's."""
    other = _pump_scene(tmp_path / "other.scene.yaml", OTHER_VALUES[what])
    page = tmp_path / "r.html"
    args = ["report", str(pump_run), "--scene", str(other), "-o", str(page)]
    err = _refused(args, capsys)
    assert (
        f"{other}: scene pump_8_mounts is not the one {pump_run} was replayed with, {PUMP}" in err
    )
    assert not page.exists()
    assert main([*args, "--other-scene"]) == 0
    assert "NOT the run's, drawn with on request (--other-scene)" in capsys.readouterr().err
    text = html.unescape(page.read_text(encoding="utf-8"))
    assert f"NOT the run's, drawn with on request (--other-scene): {other}: scene" in text


def _old_bag(pump_run: Path, out: Path, scene: str) -> Path:
    """The pump's run as a replay wrote it before the scene's topic and separate keys: its
    metadata naming `scene` as the one text (file and overrides) it was replayed with."""
    from mount_twin.io.bag_metadata import SCENE_DIGEST_KEY, SCENE_KEY, custom_data

    digest = custom_data(pump_run)[SCENE_DIGEST_KEY]
    return without_scene_topic(pump_run, out, {SCENE_KEY: scene, SCENE_DIGEST_KEY: digest})


STIFFER_DIFFERS = (
    "it differs in mounts[0].stiffness[2]: 2400000.0 here, 1200000.0 in the run's scene"
)
"""What a refused scene with mount fl's z stiffness doubled says (the pump's is 1.2e6)."""


def test_a_refused_scene_names_the_values_it_differs_in_where_an_old_bags_file_tells(
    pump_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A refused scene said only that "a value differs". In a bag written before the replay
    recorded its scene's value, where the run's scene file still loads to the recorded
    digest, the message names each value that differs, with both values (mount fl's z
    stiffness: the file's 1.2e6, 2.4e6 here); read past the input settings the command line
    replaced; else it says why it cannot."""
    other = _pump_scene(tmp_path / "other.scene.yaml", OTHER_VALUES["a mount's stiffness"])
    args = ["--scene", str(other), "-o", str(tmp_path / "r.html")]
    copy = _pump_scene(tmp_path / "copy.scene.yaml")
    # the run's file named as a replay with --topic names it (its topic is the run's)
    bag = _old_bag(pump_run, tmp_path / "old", str(copy) + OVERRIDDEN.format("topic"))
    err = _refused(["report", str(bag), *args], capsys)
    assert f"{STIFFER_DIFFERS} (the run's scene as its file {copy} loads it)" in err
    _pump_scene(copy, _set("body", "mass", value=1500.0))
    assert (
        f"the run's scene file {copy} has changed since: cannot say which value differs"
        in _refused(["report", str(bag), *args], capsys)
    )
    copy.unlink()
    assert (
        f"the run's scene file is not found at {copy} (as recorded): cannot say which value "
        "differs" in _refused(["report", str(bag), *args], capsys)
    )


def test_an_old_bags_relative_scene_file_is_found_from_the_bags_directory(
    pump_run: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """An old bag records the scene file as the replay was given it, relative to where it
    ran: `report` run from another directory said the file was not found. Not found from
    here, it is looked for from the bag's directory, and the message says so."""
    ran, elsewhere = tmp_path / "ran", tmp_path / "elsewhere"
    (ran / "config").mkdir(parents=True)
    elsewhere.mkdir()
    _pump_scene(ran / "config" / "run.scene.yaml")
    bag = _old_bag(pump_run, ran / "out", "config/run.scene.yaml")
    other = _pump_scene(tmp_path / "other.scene.yaml", OTHER_VALUES["a mount's stiffness"])
    monkeypatch.chdir(elsewhere)
    args = ["report", str(bag), "--scene", str(other), "-o", str(tmp_path / "r.html")]
    found = ran / "config" / "run.scene.yaml"
    assert (
        f"{STIFFER_DIFFERS} (the run's scene as its file {found} loads it: "
        "config/run.scene.yaml found from the bag's directory, not found at "
        f"{elsewhere}/config/run.scene.yaml (config/run.scene.yaml from here))"
        in _refused(args, capsys)
    )
    found.unlink()
    assert (
        f"the run's scene file is not found at {elsewhere}/config/run.scene.yaml "
        f"(config/run.scene.yaml from here) nor {found} (config/run.scene.yaml from the bag's "
        "directory): cannot say which value differs" in _refused(args, capsys)
    )


def test_a_moved_runs_scene_file_is_found_by_the_path_the_replay_was_given(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A bag whose metadata records the scene file's absolute path but not its value (written
    before the value was; its ~/scene topic filtered out), its project directory moved: the
    absolute path was the only one looked at, "not found". The path the replay was given
    (config/run.scene.yaml) is looked for after it, from here and from the bag's directory,
    and the messages name each path tried."""
    from mount_twin.io.bag_metadata import SCENE_VALUE_KEY, custom_data

    ran, moved = tmp_path / "ran", tmp_path / "moved"
    (ran / "config").mkdir(parents=True)
    _pump_scene(ran / "config" / "run.scene.yaml")
    monkeypatch.chdir(ran)
    bag = ROOT / "bags" / "half_sine_shock_10khz"
    replayed = ["replay", str(bag), "--scene", "config/run.scene.yaml", "-o", "out"]
    assert main([*replayed, "--no-progress"]) == 0
    custom = {k: v for k, v in custom_data("out").items() if k != SCENE_VALUE_KEY}
    without_scene_topic(ran / "out", ran / "bags" / "filtered", custom)
    ran.rename(moved)
    monkeypatch.chdir(moved)
    other = _pump_scene(tmp_path / "other.scene.yaml", OTHER_VALUES["a mount's stiffness"])
    args = ["report", "bags/filtered", "--scene", str(other), "-o", str(tmp_path / "r.html")]
    recorded, found = ran / "config" / "run.scene.yaml", moved / "config" / "run.scene.yaml"
    assert (
        f"{STIFFER_DIFFERS} (the run's scene as its file {found} loads it: "
        f"config/run.scene.yaml found from here, not found at {recorded} (as recorded))"
        in _refused(args, capsys)
    )
    found.unlink()
    assert (
        f"the run's scene file is not found at {recorded} (as recorded), {found} "
        f"(config/run.scene.yaml from here) nor {moved}/bags/config/run.scene.yaml "
        "(config/run.scene.yaml from the bag's directory): cannot say which value differs"
        in _refused(args, capsys)
    )


def test_a_refused_scene_names_its_differences_from_the_bags_scene_with_the_file_gone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The replay writes its scene's value into its bag (~/scene): a refused scene's
    differences are named from it, the run's scene file moved away and `report` run from
    another directory (which had said the file was not found, and nothing of the values)."""
    ran, elsewhere = tmp_path / "ran", tmp_path / "elsewhere"
    ran.mkdir()
    elsewhere.mkdir()
    _pump_scene(ran / "run.scene.yaml")
    monkeypatch.chdir(ran)
    bag = ROOT / "bags" / "half_sine_shock_10khz"
    replayed = ["replay", str(bag), "--scene", "run.scene.yaml", "-o", "out", "--no-progress"]
    assert main(replayed) == 0
    (ran / "run.scene.yaml").unlink()
    monkeypatch.chdir(elsewhere)
    other = _pump_scene(tmp_path / "other.scene.yaml", OTHER_VALUES["a mount's stiffness"])
    args = ["report", "../ran/out", "--scene", str(other), "-o", "r.html"]
    err = _refused(args, capsys)
    assert "is not the one ../ran/out was replayed with, run.scene.yaml" in err
    assert f"{STIFFER_DIFFERS} (the run's scene as its /mount_twin/scene topic records it)" in err


def test_a_refused_scene_names_its_differences_from_the_metadata_with_the_topic_dropped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A replay's bag whose user filtered its ~/scene topic out (the metadata kept), the run's
    scene file moved away: the metadata held the digest alone, so a refused scene was only
    said to differ ("not found: cannot say which value differs"). It holds the value too: the
    values that differ are named from it."""
    from mount_twin.io.bag_metadata import custom_data

    monkeypatch.chdir(tmp_path)
    run_file = _pump_scene(tmp_path / "run.scene.yaml")
    bag = ROOT / "bags" / "half_sine_shock_10khz"
    replayed = ["replay", str(bag), "--scene", str(run_file), "-o", "out", "--no-progress"]
    assert main(replayed) == 0
    filtered = without_scene_topic(tmp_path / "out", tmp_path / "filtered", custom_data("out"))
    run_file.unlink()
    other = _pump_scene(tmp_path / "other.scene.yaml", OTHER_VALUES["a mount's stiffness"])
    err = _refused(["report", str(filtered), "--scene", str(other), "-o", "r.html"], capsys)
    assert f"is not the one {filtered} was replayed with, {run_file}" in err
    assert (
        f"{STIFFER_DIFFERS} (the run's scene as its metadata (mount_twin.scene_sha256, "
        "mount_twin.scene_value) records it)" in err
    )


def test_other_scene_needs_a_scene(pump_run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    err = _refused(["report", str(pump_run), "--other-scene"], capsys)
    assert "--other-scene draws with the scene --scene gives: it needs --scene" in err


def test_the_runs_scene_rewritten_is_still_its_own(
    pump_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The digest is of the scene's values, not of its file's bytes: the pump's scene written
    out again without its comments, in another order, is the run's."""
    same = _pump_scene(tmp_path / "same.scene.yaml")
    assert same.read_text(encoding="utf-8") != PUMP.read_text(encoding="utf-8")
    page = tmp_path / "r.html"
    assert main(["report", str(pump_run), "--scene", str(same), "-o", str(page)]) == 0
    assert "warning" not in capsys.readouterr().err
    assert f"the run's: its digest is the one {pump_run} records" in html.unescape(
        page.read_text(encoding="utf-8")
    )


def _recorded(pump_run: Path, tmp_path: Path) -> Path:
    """The pump's run as a bag without mount_twin's custom_data, as `ros2 bag record` of the
    node's topics writes one: its ~/scene topic the node's only record of its scene."""
    import shutil

    import yaml

    bag = tmp_path / "recorded"
    shutil.copytree(pump_run, bag)
    meta = yaml.safe_load((bag / "metadata.yaml").read_text(encoding="utf-8"))
    assert meta["rosbag2_bagfile_information"].pop("custom_data")  # the replay's: the scene
    (bag / "metadata.yaml").write_text(yaml.safe_dump(meta), encoding="utf-8")
    return bag


def test_a_recording_of_the_nodes_topics_is_checked_by_its_scene_topics_digest(
    pump_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A recording of the node's topics was checked by its mount names, rtol and atol only:
    a scene of another mass passed. The node's ~/scene (as the replay writes it) gives the
    digest and the value: refused, naming the mass (the pump's 1200 kg, 1500 here)."""
    bag = _recorded(pump_run, tmp_path)
    heavy = _pump_scene(tmp_path / "heavy.scene.yaml", OTHER_VALUES["the mass"])
    page = tmp_path / "r.html"
    err = _refused(["report", str(bag), "--scene", str(heavy), "-o", str(page)], capsys)
    assert f"is not the one {bag} was run with, {PUMP}: its digest" in err
    assert "differs from the one its /mount_twin/scene topic records" in err
    assert "it differs in body.mass: 1500.0 here, 1200.0 in the run's scene" in err
    assert main(["report", str(bag), "--scene", str(PUMP), "-o", str(page)]) == 0
    assert f"the run's: its digest is the one {bag} records" in html.unescape(
        page.read_text(encoding="utf-8")
    )


def test_without_a_digest_a_scene_is_checked_by_the_settings_the_bag_records(
    pump_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A recording of the node's topics records no digest of its scene; its integration
    status records the solver's rtol and atol. A scene with another atol is refused, naming
    it and both values; one differing elsewhere cannot be told apart, and stderr and the page
    say what it was checked by."""
    bag = without_scene_topic(pump_run, tmp_path / "recorded", {})
    page = tmp_path / "r.html"
    loose = _pump_scene(tmp_path / "loose.scene.yaml", _set("integration", "atol", value=1e-7))
    err = _refused(["report", str(bag), "--scene", str(loose), "-o", str(page)], capsys)
    assert (
        f"{loose}: scene pump_8_mounts is not the one {bag} was run with: its integration.atol "
        "is 1e-07, the run's 1e-09" in err
    )
    assert not page.exists()
    heavy = _pump_scene(tmp_path / "heavy.scene.yaml", OTHER_VALUES["the mass"])
    assert main(["report", str(bag), "--scene", str(heavy), "-o", str(page)]) == 0
    said = (
        "by its mount names, integration.rtol, integration.atol only: "
        f"{bag} records no digest of its scene (a recording of the node's topics without its "
        "~/scene"
    )
    assert said in capsys.readouterr().err
    assert said in html.unescape(page.read_text(encoding="utf-8"))


@pytest.mark.parametrize("gyro_filter", ["linear_phase", "ignore"])
def test_the_readings_rejections_are_those_the_twin_counts(gyro_filter: str) -> None:
    """What `report --input` leaves out is what the twin rejects: per reason, the twin's own
    counters of the same samples (a NaN acceleration, an absurd rate, an acceleration marked
    not provided with NaN in its place, a rate marked not provided, read or not)."""
    from collections import Counter

    from mount_twin.engine.batch import SampleBatch
    from mount_twin.engine.engine import TwinEngine
    from mount_twin.engine.reading_screen import reading_rejections
    from mount_twin.model.assemble import assemble

    scene = load_scene_file(PUMP)
    scene = dataclasses.replace(
        scene, input=dataclasses.replace(scene.input, gyro_filter=gyro_filter, frame_id="")
    )
    n = 60
    accel = np.tile([0.0, 0.0, 9.80665], (n, 1))
    gyro = np.zeros((n, 3))
    unprovided = np.zeros((n, 2), dtype=bool)
    accel[10, 1] = np.nan
    gyro[20, 2] = 1e200
    unprovided[30, 0], accel[30] = True, np.nan
    unprovided[40, 1], gyro[40] = True, np.nan
    unprovided[50] = True
    batch = SampleBatch(np.arange(n) * 1e-3 + 1.0, accel, gyro, ["imu"] * n, unprovided)
    engine = TwinEngine(assemble(scene))
    engine.run(batch)
    reasons = reading_rejections(accel, gyro, unprovided, scene.input.reads_rate)
    counted = {k.removeprefix("rejected_"): v for k, v in engine.counts.items() if v}
    expected = Counter(r for r in reasons.tolist() if r)
    assert {k: counted[k] for k in expected} == expected
    assert counted["accepted"] == n - sum(expected.values())
    assert (
        reasons[[10, 20, 30, 50]].tolist()
        == ["non_finite", "non_finite"] + ["no_acceleration"] * 2
    )
    assert reasons[40] == ("no_angular_velocity" if gyro_filter != "ignore" else "")


def _figure() -> Any:
    """A matplotlib Figure on the Agg canvas, drawn into as the page's `png` does."""
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    return Figure(figsize=(10, 4))


def _legend_texts(ax: Any) -> list[str]:
    legend = ax.get_legend()
    return [] if legend is None else [t.get_text() for t in legend.get_texts()]


def test_the_srs_figures_legend_gives_the_damping() -> None:
    """The spectra's damping was in the section heading only: a figure copied out of the page
    did not say which ζ its curves are of. Its legend says ζ."""
    from mount_twin.analysis.report_plots import draw_srs
    from mount_twin.analysis.srs import srs

    rate, freqs = 1000.0, np.array([10.0, 20.0, 40.0])
    pulse = np.sin(np.pi * np.arange(20) / 20.0)  # a 20 ms half-sine
    spectra = {"z": srs(pulse, rate, freqs, 0.1)}
    fig = _figure()
    draw_srs(fig, spectra, 0.1, None)
    legend = fig.axes[0].get_legend()
    assert legend.get_title().get_text() == "ζ = 0.1 (10 %)"


def test_the_event_windows_line_colours_are_named_in_a_legend() -> None:
    """The window around the first event marks WARN events orange and ERROR events red, and
    nothing said so. A legend names each level drawn, in its line's colour."""
    from matplotlib.colors import to_rgba

    from mount_twin.analysis.report_plots import draw_forces
    from mount_twin.io.output_tables import Event

    t = np.linspace(0.0, 0.2, 201)
    zero = np.zeros_like(t)
    mount = Table(
        "a",
        {"stamp_ns": (t * 1e9).astype(np.int64), "t_s": t, "fx_N": zero, "fy_N": zero, "fz_N": t},
    )
    events = [
        Event("a", "joint_slipped", 1, 0.10, 1.0, "WARN"),
        Event("a", "joint_opened", 1, 0.12, 1.0, "ERROR"),
    ]
    fig = _figure()
    draw_forces(fig, {"a": mount}, events, (0.05, 0.15))
    named = {}
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is not None:
            for text, handle in zip(legend.get_texts(), legend.legend_handles, strict=True):
                named[text.get_text()] = to_rgba(handle.get_color(), 1.0)
    vertical = {  # the events' lines: x constant, by their time
        float(line.get_xdata()[0]): to_rgba(line.get_color(), 1.0)
        for line in fig.axes[0].get_lines()
        if len(set(line.get_xdata())) == 1
    }
    assert vertical[0.10] == named["WARN event"]
    assert vertical[0.12] == named["ERROR event"]
    assert named["WARN event"] != named["ERROR event"]


def test_the_utilisation_legend_is_beside_the_plot_not_over_its_rating_line() -> None:
    """Inside the axes the legend sat over the "rated (1)" line and the peaks near it. It is
    beside them: its box and the plotting area's do not meet."""
    from mount_twin.analysis.report_plots import draw_utilisation

    t = np.array([0.1, 0.2, 0.3])
    utilisation = {f"m{k}": (t, np.array([0.95, 1.0, 0.9])) for k in range(8)}
    fig = _figure()
    draw_utilisation(fig, utilisation, {}, 0.1)
    fig.tight_layout()
    fig.canvas.draw()
    (ax,) = fig.axes
    legend = ax.get_legend().get_window_extent()
    assert "rated (1)" in _legend_texts(ax)
    assert not legend.overlaps(ax.get_window_extent())


def test_the_attitude_is_drawn_in_radians_as_the_bag_records_it() -> None:
    """The guide gives angles in rad everywhere, the bag and the JSON too; the report drew the
    attitude in degrees. Its axis is in rad, each curve the bag's angle as it is."""
    from mount_twin.analysis.report_plots import draw_response

    t = np.linspace(0.0, 1.0, 11)
    stamps = (t * 1e9).astype(np.int64)
    pose = {"stamp_ns": stamps, "t_s": t, **{f"{a}_m": 0.0 * t for a in "xyz"}}
    angles = {"stamp_ns": stamps, "t_s": t}
    angles |= {f"{n}_rad": k * 0.01 * t for k, n in enumerate(("alpha", "gamma", "delta"), 1)}
    fig = _figure()
    tables = {"pose": Table("pose", pose), "angles": Table("angles", angles)}
    draw_response(fig, tables, None, 0, "")
    attitude = fig.axes[-1]
    assert attitude.get_ylabel() == "attitude [rad]"
    for line in attitude.get_lines():
        assert np.array_equal(line.get_ydata(), angles[f"{line.get_label()}_rad"])


def test_a_scene_equal_to_the_runs_but_for_a_zeros_sign_says_so() -> None:
    """Digests hash the values' JSON text, where -0.0 is not 0.0 though the numbers are equal:
    the list of differences was empty and the message ended in "it differs in ". So from
    the run's file, and from its value as the bag's ~/scene carries it (JSON)."""
    from mount_twin.analysis.scene_check import _differing
    from mount_twin.io.scene_record import RecordedScene, scene_text
    from mount_twin.scene.description import scene_digest

    path = CONFIG / "pump_8_mounts.scene.yaml"
    run = load_scene_file(path)
    x, y, z = run.body.cg
    assert y == 0.0 and math.copysign(1.0, y) > 0  # the bundled pump's cg y is +0.0
    here = dataclasses.replace(run, body=dataclasses.replace(run.body, cg=(x, -0.0, z)))
    assert scene_digest(here) != scene_digest(run)
    digest, value = scene_digest(run), json.loads(scene_text(run))["value"]
    for recorded in (
        RecordedScene(digest, "its metadata", str(path), str(path)),
        RecordedScene(digest, "its /mount_twin/scene topic", str(path), value=value),
    ):
        text = _differing(here, recorded, "out")
        assert "differ only as the digest writes them" in text, text
