"""`mount-twin import-csv` reads the files recorders write: units, delimiters, decimal comma,
BOM, comments, column names or a mapping, accelerometer-only; errors name file, row, column."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from io_helpers import CONFIG, DATA_DIR, read_bag, stamp_ns

from mount_twin.cli import main
from mount_twin.io.csv_cells import time_ns
from mount_twin.io.csv_import import CsvFormat, read_recorder_csv
from mount_twin.io.xsens_csv import read_xsens_csv

G = 9.80665


def _write(tmp_path: Path, text: str, name: str = "rec.csv") -> Path:
    path = tmp_path / name
    path.write_bytes(text.encode("utf-8"))
    return path


def test_excel_export_with_bom_semicolons_decimal_comma_and_units(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "\ufeff# exported by a recorder\n\n"
        "Time [ms];AccX [g];AccY [g];AccZ [g];GyroX [deg/s];GyroY [deg/s];GyroZ [deg/s]\n"
        "0,0;0,0;0,5;1,0;90;0;-180\n"
        "0,5;0,1;0,0;2,0;0;45;0\n",
    )
    got = read_recorder_csv(path).signal
    np.testing.assert_allclose(got.t, [0.0, 0.0005], rtol=0, atol=1e-15)
    np.testing.assert_allclose(got.accel, [[0, 0.5 * G, G], [0.1 * G, 0, 2 * G]], rtol=1e-15)
    np.testing.assert_allclose(got.gyro, [[math.pi / 2, 0, -math.pi], [0, math.pi / 4, 0]])


def test_plain_csv_in_si_with_common_names_and_tabs(tmp_path: Path) -> None:
    path = _write(tmp_path, "time\taccel_x\taccel_y\taccel_z\n0.0\t1\t2\t3\n0.01\t4\t5\t6\n")
    imported = read_recorder_csv(path)
    np.testing.assert_array_equal(imported.signal.accel, [[1, 2, 3], [4, 5, 6]])
    np.testing.assert_array_equal(imported.signal.gyro, np.zeros((2, 3)))
    assert "no gyro columns: angular velocity taken as 0" in imported.notes


def test_an_endaq_export_with_quoted_headers_and_range_units(tmp_path: Path) -> None:
    """enDAQ writes `"Time (s)","X (100g)",...`: quoted cells, axes X, Y, Z, the channel named
    by its range, values in g."""
    path = _write(
        tmp_path,
        '"Time (s)","X (100g)","Y (100g)","Z (100g)"\n'
        "1700000000.0,0.01,-0.02,1.0\n1700000000.0001,0.5,0.25,3.0\n",
    )
    imported = read_recorder_csv(path)
    np.testing.assert_allclose(imported.signal.accel / G, [[0.01, -0.02, 1.0], [0.5, 0.25, 3.0]])
    assert "accelerometer range '100g' in the header: values read in g" in imported.notes


def test_a_single_axis_record_is_read_along_its_stated_axis(tmp_path: Path) -> None:
    """One acceleration column (HR-SHM style) along a stated sensor axis, the others 0: the
    only column besides time, or the one mapped to that axis."""
    path = _write(tmp_path, "time [s],accel [g]\n0,1.0\n0.001,1.5\n")
    got = read_recorder_csv(path, CsvFormat(axis="z"))
    np.testing.assert_allclose(got.signal.accel, [[0, 0, G], [0, 0, 1.5 * G]], rtol=1e-15)
    assert "single axis: accel along the sensor's z, the others 0" in got.notes
    two = _write(tmp_path, "t,temperature,shock\n0,20,3.0\n0.001,20,4.0\n", "two.csv")
    with pytest.raises(ValueError, match="needs one acceleration column besides time"):
        read_recorder_csv(two, CsvFormat(axis="x"))
    mapped = read_recorder_csv(two, CsvFormat(columns={"ax": "shock"}, axis="x"))
    np.testing.assert_allclose(mapped.signal.accel, [[3.0, 0, 0], [4.0, 0, 0]])
    out = tmp_path / "bag"
    assert main(["import-csv", str(path), "-o", str(out), "--single-axis", "z"]) == 0


def test_a_column_mapping_and_unit_overrides(tmp_path: Path) -> None:
    path = _write(tmp_path, "stamp,vert,lat,long\n1000,1,0,0\n2000,2,0,0\n")
    fmt = CsvFormat(
        columns={"t": "stamp", "az": "vert", "ay": "lat", "ax": "long"},
        units={"time": "us", "accel": "g"},
    )
    got = read_recorder_csv(path, fmt).signal
    np.testing.assert_allclose(got.t, [1e-3, 2e-3], rtol=1e-15)
    np.testing.assert_allclose(got.accel[:, 2], [G, 2 * G], rtol=1e-15)


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("t,ax,ay,az\n0,1,2,3\n0.1,1,,3\n", "row 3, column ay: '' is not a number"),
        ("t,ax,ay,az\n0,1,2,3\n0.1,1,nan,3\n", "row 3, column ay: 'nan' is not finite"),
        (
            "t,ax [g],ay,az\n0,1,2,3\n0.1,1e308,0,3\n",
            "row 3, column ax: '1e308' is beyond a float in SI units (×9.80665)",
        ),
        ("# c\nt,ax,ay,az\n0,1,2,3\n0,1,2,3\n", "row 4, column t: time does not increase"),
        ("t,ax,ay,az\n0,1,2,3\n0.1,1,2\n", "row 3: 3 cells where the header has 4"),
        ("time,a,b,c\n0,1,2,3\n", "row 1: no column for ax, ay, az: the header has time, a, b, c"),
        ("t [h],ax,ay,az\n0,1,2,3\n", "row 1, column t: unknown time unit 'h'"),
        ("t,ax,ay,az,wx\n0,1,2,3,4\n", "gyro columns ['wx'] without the others"),
        ("t,ax,ay,az\n", "row 1: a header but no data rows"),
        ("# only a comment\n", "no header line"),
    ],
)
def test_every_error_names_file_row_and_column(tmp_path: Path, text: str, says: str) -> None:
    path = _write(tmp_path, text)
    with pytest.raises(ValueError, match=None) as err:
        read_recorder_csv(path)
    assert str(err.value).startswith(f"{path}: ")
    assert says in str(err.value)


def test_the_bundled_sample_imports_and_replays_through_the_default_scene(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The two commands of docs/offline.md, as written there (topic and frame are import-csv's
    defaults, the bundled scenes' input). The replay finds nothing to say of the input: the
    sample had its half-sine's peak midway between two samples, read twice alike, which the
    twin warns of as a clipped or stuck sensor."""
    bag, out = tmp_path / "shock_bag", tmp_path / "out"
    assert main(["import-csv", str(CONFIG / "sample_shock.csv"), "-o", str(bag)]) == 0
    said = capsys.readouterr().out
    assert "wrote 1000 sensor_msgs/msg/Imu messages on /deck/imu" in said
    assert "units: time ms, accel g" in said and "decimal comma" in said
    _, msgs = read_bag(bag)
    imu = msgs["/deck/imu"]
    assert stamp_ns(imu[1][1]) - stamp_ns(imu[0][1]) == 200_000  # 0.2 ms
    peak = max(m.linear_acceleration.z for _, m in imu)
    assert peak == pytest.approx(11.0 * G, rel=1e-3)  # 1 g + the 10 g pulse, sampled
    scene = str(CONFIG / "pump_8_mounts.scene.yaml")
    assert main(["replay", str(bag), "--scene", scene, "-o", str(out), "--no-progress"]) == 0
    said = capsys.readouterr().out
    assert "1000 received, 1000 accepted" in said
    assert "OK    mount_twin: input: ok" in said, said


@pytest.mark.parametrize("sparse", [False, True], ids=["dev-zero", "sparse-2GB"])
def test_a_file_beyond_the_size_limit_is_an_error_naming_it_read_no_further(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], sparse: bool
) -> None:
    """/dev/zero and a 2 GB sparse file were read whole (a MemoryError traceback)."""
    path = Path("/dev/zero")
    if sparse:
        path = tmp_path / "sparse.csv"
        with path.open("wb") as fh:
            fh.truncate(2 << 30)
    assert main(["import-csv", str(path), "-o", str(tmp_path / "bag")]) == 2
    err = capsys.readouterr().err
    assert f"{path}: cannot read: larger than 256 MiB" in err and "CSV_MAX_BYTES" in err
    assert not (tmp_path / "bag").exists()


XSENS_COLUMNS = ["PacketCounter", "SampleTimeFine", "Euler_X", "Euler_Y", "Euler_Z"]
XSENS_COLUMNS += ["Acc_X", "Acc_Y", "Acc_Z", "Gyr_X", "Gyr_Y", "Gyr_Z"]


@pytest.mark.parametrize(
    ("line", "column", "cell", "says"),
    [
        (501, "Acc_Z", "nan", "'nan' is not finite"),
        (1200, "Gyr_X", "inf", "'inf' is not finite"),
        (20, "Acc_X", "abc", "'abc' is not a number"),
        (700, "Gyr_Z", "", "'' is not a number"),
        (900, "SampleTimeFine", "2528767462", "time does not increase"),
    ],
)
def test_an_xsens_exports_bad_cell_is_named_by_its_row_and_column(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    line: int,
    column: str,
    cell: str,
    says: str,
) -> None:
    """The shake table's block record (a Movella/Xsens DOT export) with one cell spoilt, at a
    line of the file and a column: import-csv said only "SampleTimeFine does not increase, or
    a value is not a number" (and a cell that was no number, Python's "could not convert
    string to float"). It names the line and the column, as a recorder CSV's error does."""
    lines = (DATA_DIR / "shake_table_1story/sine_2hz_trial1_top_excerpt.csv").read_text()
    rows = lines.splitlines()
    cells = rows[line - 1].split(",")
    cells[XSENS_COLUMNS.index(column)] = cell
    rows[line - 1] = ",".join(cells)
    path = _write(tmp_path, "\n".join(rows) + "\n", "top_bad.csv")
    assert main(["import-csv", str(path), "-o", str(tmp_path / "bag")]) == 2
    err = capsys.readouterr().err
    assert f"{path}: row {line}, column {column}: {says}" in err, err
    assert not (tmp_path / "bag").exists()


def test_an_xsens_row_with_a_cell_too_many_is_refused_naming_it(tmp_path: Path) -> None:
    """A decimal comma in line 20's Acc_X (1,5) splits it in two: every later cell of the row
    had been read one column off (Acc_Y as 5, …), silently."""
    rows = (DATA_DIR / "shake_table_1story/sine_2hz_trial1_top_excerpt.csv").read_text()
    rows = rows.splitlines()
    cells = rows[19].split(",")
    cells[XSENS_COLUMNS.index("Acc_X")] = "1,5"
    rows[19] = ",".join(cells)
    path = _write(tmp_path, "\n".join(rows) + "\n", "top_comma.csv")
    with pytest.raises(ValueError, match=None) as err:
        read_xsens_csv(path)
    assert str(err.value) == f"{path}: row 20: 12 cells where the header has 11"


def test_a_csv_timed_from_the_epoch_is_refused_with_the_default_offset(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """enDAQ's exports time from the epoch: 1.7e9 s, plus the default offset of 1.7e9 s, is
    past 2**31 − 1 s, the last second a header (int32) holds. The bag had been written with
    header stamps wrapped to −894 967 296 s (1941), exit 0; --offset 0 writes it as recorded."""
    path = _write(tmp_path, '"Time (s)","X (100g)","Y (100g)","Z (100g)"\n1700000000.5,0,0,1\n')
    out = tmp_path / "bag"
    assert main(["import-csv", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "3400000000500000000 ns is after 2038-01-19T03:14:07Z" in err and "--offset" in err
    assert not out.exists()
    assert main(["import-csv", str(path), "-o", str(out), "--offset", "0"]) == 0
    _, msgs = read_bag(out)
    assert stamp_ns(msgs["/deck/imu"][0][1]) == 1_700_000_000_500_000_000


@pytest.mark.parametrize("micro", ["\u03bc", "\u00b5"], ids=["greek-mu", "micro-sign"])
def test_microseconds_are_read_with_either_mu(tmp_path: Path, micro: str) -> None:
    """The Greek small mu (U+03BC, what a Greek keyboard or Unicode normalisation gives) was
    an unknown time unit 'μs', the error listing a known 'µs' (the micro sign, U+00B5) that
    looks the same."""
    path = _write(tmp_path, f"t [{micro}s],ax,ay,az\n0,0,0,9.8\n1500,0,0,9.8\n")
    np.testing.assert_array_equal(read_recorder_csv(path).signal.t, [0.0, 1500e-6])
    got = read_recorder_csv(
        _write(tmp_path, "t,ax,ay,az\n0,0,0,9.8\n250,0,0,9.8\n", "u.csv"),
        CsvFormat(units={"time": f"{micro}s"}),
    ).signal
    np.testing.assert_array_equal(got.t, [0.0, 250e-6])


def test_a_whitespace_separated_header_keeps_each_unit_with_its_name(tmp_path: Path) -> None:
    """`Time [ms]  AccZ [g]` between spaces was split into 8 cells (each unit one), and the
    file refused: "row 2: 4 cells where the header has 8"."""
    path = _write(
        tmp_path, "Time [ms]  AccX [g]  AccY [g]  AccZ (g)\n0  0,0  0,0  1,0\n0,5  0,1  0,0  1,0\n"
    )
    got = read_recorder_csv(path)
    np.testing.assert_allclose(got.signal.t, [0.0, 0.0005], rtol=1e-15, atol=0)
    np.testing.assert_allclose(got.signal.accel, [[0, 0, G], [0.1 * G, 0, G]], rtol=1e-15)
    assert "units: time ms, accel g" in got.notes and "decimal comma" in got.notes


def test_units_the_header_does_not_give_are_said_to_be_assumed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A record in g with no unit in its header (1.0 on z at rest) is read in m/s², as
    documented; the note said "units: time s, accel m/s^2" as if the header had said so."""
    path = _write(tmp_path, "t,ax,ay,az,wx [deg/s],wy [deg/s],wz [deg/s]\n0,0,0,1.0,0,0,0\n")
    assert main(["import-csv", str(path), "-o", str(tmp_path / "bag")]) == 0
    said = capsys.readouterr().out
    assert (
        "units: time s, accel m/s^2, gyro deg/s (time, accel assumed: the header gives no "
        "unit; say it with --time-unit, --accel-unit)"
    ) in said
    stated = _write(tmp_path, "t [s],ax [g],ay [g],az [g]\n0,0,0,1.0\n", "stated.csv")
    assert "units: time s, accel g" in read_recorder_csv(stated).notes


def test_an_epoch_timed_10khz_record_is_stamped_to_the_nanosecond(tmp_path: Path) -> None:
    """A time cell 1700000000.0001 s had been parsed as a float (which holds an epoch time to
    ~240 ns) and stamped 1700000000000099840 ns; the 10 kHz steps jittered (99 840, 100 096
    ns). Each stamp is the offset plus the cell's decimal time in ns, exactly."""
    cells = [f"1700000000.{k:04d}" for k in range(20)]
    path = _write(tmp_path, "t [s],ax,ay,az\n" + "".join(f"{c},0,0,9.8\n" for c in cells))
    for offset in (0, 123):
        out = tmp_path / f"bag{offset}"
        assert main(["import-csv", str(path), "-o", str(out), "--offset", str(offset)]) == 0
        _, msgs = read_bag(out)
        stamps = [stamp_ns(m) for _, m in msgs["/deck/imu"]]
        # "1700000000.0001" s: 17000000000001 units of 0.1 ms, each 100 000 ns
        assert stamps == [offset + int(c.replace(".", "")) * 100_000 for c in cells]
    assert stamps[1] == 123 + 1_700_000_000_000_100_000


def test_time_in_ms_with_a_decimal_comma_is_exact_and_sub_ns_rounded_half_even(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The unit's factor is applied to the written decimal, not to a float: 0,0035005 ms is
    3500.5 ns, rounded half to even (3500), 0,0045015 ms is 4501.5 ns (4502); said."""
    times = ["1700000000000,0001", "1700000000000,0015", "1700000000000,0035005"]
    times += ["1700000000000,0045015", "1700000000000,01"]
    text = "Time [ms];AccX;AccY;AccZ\n" + "".join(f"{t};0;0;9,8\n" for t in times)
    path = _write(tmp_path, text)
    out = tmp_path / "bag"
    assert main(["import-csv", str(path), "-o", str(out), "--offset", "0"]) == 0
    said = capsys.readouterr().out
    assert "time: 2 cells finer than 1 ns, rounded to the ns (half to even)" in said, said
    _, msgs = read_bag(out)
    base = 1_700_000_000_000 * 1_000_000  # ms → ns
    expected = [base + 100, base + 1500, base + 3500, base + 4502, base + 10_000]
    assert [stamp_ns(m) for _, m in msgs["/deck/imu"]] == expected


@pytest.mark.parametrize(
    ("cell", "ns_per_unit", "decimal", "expected"),
    [
        ("1700000000.0001", 10**9, ".", (1_700_000_000_000_100_000, False)),
        ('"1700000000,0001"', 10**9, ",", (1_700_000_000_000_100_000, False)),
        ("1.7e9", 10**9, ".", (1_700_000_000_000_000_000, False)),
        ("-2.5E-3", 10**6, ".", (-2_500, False)),  # -2.5e-3 ms
        ("0.0000000005", 10**9, ".", (0, True)),  # 0.5 ns: to the even 0
        ("0.0000000015", 10**9, ".", (2, True)),  # 1.5 ns: to the even 2
        ("-0.0000000025", 10**9, ".", (-2, True)),
        ("-0.0000000015", 10**9, ".", (-2, True)),
        ("-0.0000000014", 10**9, ".", (-1, True)),
        ("1e-12", 10**9, ".", (0, True)),  # 0.001 ns
        ("1." + "0" * 100_000 + "1", 10**9, ".", (10**9, True)),  # long, and quick
        ("9223372036.854775807", 10**9, ".", (2**63 - 1, False)),  # the last int64 ns
        ("0.00000000250001", 10**9, ".", (3, True)),  # above the half
        ("1e-999999999", 10**9, ".", (0, True)),  # no 10**999999999 made
        ("0e999999999", 10**9, ".", (0, False)),
        ("1500", 10**3, ".", (1_500_000, False)),  # µs
        ("7", 1, ".", (7, False)),
    ],
)
def test_a_time_cell_is_read_exactly_in_ns(
    cell: str, ns_per_unit: int, decimal: str, expected: tuple[int, bool]
) -> None:
    assert time_ns(cell, ns_per_unit, decimal) == expected


@pytest.mark.parametrize(
    ("times", "says"),
    [
        # distinct as written and as floats, both 1 ns once rounded: not increasing
        (["0.0000000010", "0.0000000014"], "row 3, column t: time does not increase"),
        (["0", "1e10"], "row 3, column t: '1e10' is beyond the ±2**63 ns (292 years)"),
    ],
)
def test_times_not_increasing_in_ns_or_beyond_int64_are_refused(
    tmp_path: Path, times: list[str], says: str
) -> None:
    path = _write(tmp_path, "t,ax,ay,az\n" + "".join(f"{t},0,0,1\n" for t in times))
    with pytest.raises(ValueError, match=None) as err:
        read_recorder_csv(path)
    assert says in str(err.value), err.value


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (
            ["--columns", "t=Foo", "--time-unit", "ms", "--accel-unit", "g", "--decimal", ","],
            "--decimal, --columns, --time-unit, --accel-unit",
        ),
        (["--single-axis", "z", "--delimiter", ";", "--gyro-unit", "rad/s"], None),
    ],
)
def test_format_options_are_refused_for_an_xsens_export(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], options: list[str], named: str | None
) -> None:
    """A Movella/Xsens DOT export is read in its own layout: --columns, --time-unit,
    --accel-unit, --decimal (...) had been ignored without a word, exit 0."""
    path = DATA_DIR / "shake_table_1story/sine_2hz_trial1_top_excerpt.csv"
    out = tmp_path / "bag"
    assert main(["import-csv", str(path), "-o", str(out), *options]) == 2
    err = capsys.readouterr().err
    assert "Movella/Xsens DOT export" in err and "read as is" in err, err
    for option in options:
        if option.startswith("--"):
            assert option in err, err
    if named:
        assert named in err, err
    assert not out.exists()


def test_quoted_cells_are_read_as_the_numbers_they_hold(tmp_path: Path) -> None:
    """Spreadsheets quote cells: `"0"` had been refused ('"0"' is not a number)."""
    path = _write(tmp_path, '"t [s]","ax","ay","az [g]"\n"0","0","0","1"\n"0.5",0,"-1.5","2"\n')
    got = read_recorder_csv(path).signal
    np.testing.assert_array_equal(got.t, [0.0, 0.5])
    np.testing.assert_array_equal(got.accel, [[0, 0, G], [0, -1.5, 2 * G]])
    out = tmp_path / "bag"
    assert main(["import-csv", str(path), "-o", str(out), "--offset", "7"]) == 0
    _, msgs = read_bag(out)
    assert [stamp_ns(m) for _, m in msgs["/deck/imu"]] == [7, 7 + 500_000_000]


@pytest.mark.parametrize("cell", ['"abc"', '""0""', '"', '"1" 2'])
def test_a_quoted_cell_that_is_no_number_is_refused_naming_it(tmp_path: Path, cell: str) -> None:
    """One pair of quotes around a number, no more: the cell is named as written."""
    path = _write(tmp_path, f"t,ax,ay,az\n0,0,0,1\n0.1,0,{cell},1\n")
    with pytest.raises(ValueError, match=None) as err:
        read_recorder_csv(path)
    assert str(err.value) == f"{path}: row 3, column ay: {cell!r} is not a number"


def test_quoted_decimal_commas_between_commas_are_read_or_refused_naming_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A spreadsheet in a decimal-comma locale, saving with commas between cells, quotes its
    numbers: `"0,001","0,12",...`. Each such row had been split at every comma and refused as
    "row 2: 8 cells where the header has 4", naming neither a cell nor an option. The quotes
    keep a cell whole; the decimal comma is sniffed (or given with --decimal ,); where it is not
    (or `"1,234"`, a thousands separator as much as a decimal comma, is all there is), the cell
    is refused naming the file, row, column, cell and the option."""
    text = (
        '"t [s]","ax","ay","az"\n'
        '"1700000000,0001","0,12","-0,5","9,81"\n'
        '"1700000000,001","1,5e1","0","9,8"\n'
    )
    path = _write(tmp_path, text)
    for options in ([], ["--decimal", ","]):
        got = read_recorder_csv(path, CsvFormat(decimal=(options or [None, None])[1]))
        np.testing.assert_array_equal(got.signal.accel, [[0.12, -0.5, 9.81], [15.0, 0, 9.8]])
        assert "decimal comma" in got.notes
        out = tmp_path / f"bag{len(options)}"
        args = ["import-csv", str(path), "-o", str(out), "--offset", "0", *options]
        assert main(args) == 0
        _, msgs = read_bag(out)
        stamps = [stamp_ns(m) for _, m in msgs["/deck/imu"]]
        assert stamps == [1_700_000_000_000_100_000, 1_700_000_000_001_000_000]
    option = "`mount-twin import-csv --decimal ,`"
    with pytest.raises(ValueError, match=None) as err:
        read_recorder_csv(path, CsvFormat(decimal="."))
    assert str(err.value).startswith(
        f"{path}: row 2, column t: '\"1700000000,0001\"' is not a number: a decimal comma? "
        f"say {option}"
    ), err.value
    ambiguous = _write(tmp_path, 't,ax,ay,az\n"1,250",0,0,"9,810"\n"2,500",0,0,"9,810"\n', "a.csv")
    assert main(["import-csv", str(ambiguous), "-o", str(tmp_path / "bag")]) == 2
    said = capsys.readouterr().err
    assert f"{ambiguous}: row 2, column t: '\"1,250\"' is not a number" in said, said
    assert option in said and "thousands separators are not read" in said, said
    assert not (tmp_path / "bag").exists()
    got = read_recorder_csv(ambiguous, CsvFormat(decimal=","))
    np.testing.assert_array_equal(got.signal.t, [1.25, 2.5])


@pytest.mark.parametrize(
    ("text", "cell"),
    [
        ('t,ax,ay,az\n"1.000","0,12",0,"9,81"\n', '"1.000"'),  # sniffed from "0,12"
        ("t;ax;ay;az\n0;0,5;0;9,81\n0,5;1.250;0;9,81\n", "1.250"),
    ],
)
def test_a_point_where_the_numbers_have_a_decimal_comma_is_refused(
    tmp_path: Path, text: str, cell: str
) -> None:
    """Where `0,5` is a half, `1.000` is a thousand (a thousands separator): it had been read
    as 1, silently. It is refused naming the cell and what to say if the point is a decimal
    point."""
    path = _write(tmp_path, text)
    with pytest.raises(ValueError, match=None) as err:
        read_recorder_csv(path)
    assert str(err.value).startswith(f"{path}: row ")
    assert f"{cell!r} has a '.' where the decimal mark is ','" in str(err.value), err.value
    assert "`mount-twin import-csv --decimal .`" in str(err.value)
    with pytest.raises(ValueError, match=r"has a '\.' where the decimal mark is ','"):
        time_ns('"1.000,5"', 10**9, ",")


def test_an_xsens_export_is_stamped_with_its_clock_exactly_over_many_wraps(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """SampleTimeFine is a 32-bit µs counter, unwrapped into the device's time. It had been
    read as a float and stamped round(t · 1e9) with t = µs · 1e-6: from some 50 days of clock
    on, a float's seconds are coarser than the ns, and stamps came out 1–2 ns off. Each stamp
    is the offset plus the cell's µs and the whole wraps before it (2**32 µs each), exactly:
    here 5 000 samples 2 100 s (and a few µs) apart, 121 days, every ~2 wraps (unwrapped when
    a step back is more than half the period)."""
    wrap = 2**32
    clock_us = [2_528_763_256 + k * 2_100_000_000 + (k * k) % 997 for k in range(5_000)]
    cells = [us % wrap for us in clock_us]
    assert cells != sorted(cells) and clock_us[-1] > 120 * 86_400 * 10**6  # wrapped, 121 days
    head = ["PacketCounter,SampleTimeFine,Euler_X,Euler_Y,Euler_Z"]
    head += ["Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z"]
    text = "sep=,\nDeviceTag:,left leg\nFirmwareVersion:,2.2.1\nAppVersion:,2023.6.0\n"
    text += "StartTime: ,2025-04-02_17:17:54_000 PDT\n© Movella Technologies B. V. 2005-2025\n\n"
    text += ",".join(head) + "\n" + "0," + ",".join(["0"] * 10) + "\n"  # the all-zero row
    text += "".join(f"{k + 1},{c},0,0,0,0.1,0,9.81,1.5,0,0\n" for k, c in enumerate(cells))
    path = _write(tmp_path, text, "dot.csv")
    float_ns = np.rint(np.unwrap(np.array(cells, float), period=wrap) * 1e-6 * 1e9)
    off = float_ns - np.array(clock_us, float) * 1e3  # exact: both below 2**53
    assert np.abs(off).max() >= 1.0  # what the float would stamp, for this test's worth
    out = tmp_path / "bag"
    assert main(["import-csv", str(path), "-o", str(out), "--offset", "123"]) == 0
    said = capsys.readouterr().out
    assert "a Movella/Xsens DOT export (device left leg): stamps on its clock" in said, said
    _, msgs = read_bag(out)
    assert [stamp_ns(m) for _, m in msgs["/deck/imu"]] == [123 + us * 1000 for us in clock_us]
    imported = read_xsens_csv(path)
    assert imported.stamps_ns.tolist() == [us * 1000 for us in clock_us]
    np.testing.assert_allclose(imported.signal.t, np.array(clock_us) / 1e6, rtol=2**-52, atol=0)
    np.testing.assert_allclose(imported.signal.gyro[0], [1.5 * math.pi / 180, 0, 0], rtol=1e-15)


SPLIT_HINT = (
    "decimal commas between commas? A comma-separated file cannot hold an unquoted decimal "
    "comma unambiguously (`0,12` is two cells); export with ';' as the separator (or quote "
    'the cells, "0,12"), then `mount-twin import-csv --decimal ,`'
)


@pytest.mark.parametrize("before", [0, 60])
def test_unquoted_decimal_commas_between_commas_are_refused_naming_the_cause_and_fix(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], before: int
) -> None:
    """A European export saved with ',' between cells and unquoted decimal commas,
    `0,001,0,12,9,81,...`: each number is split in two. It had been refused only as "row 2:
    8 cells where the header has 4", naming neither cause nor fix; the numbers are not guessed.
    A row past the 50 the decimal mark is sniffed from is refused alike."""
    rows = "".join(f"{k}.5,0,0,9.5\n" for k in range(before))
    text = f"t,ax,ay,az\n{rows}0,001,0,12,-0,5,9,81\n"
    path = _write(tmp_path, text)
    out = tmp_path / "bag"
    assert main(["import-csv", str(path), "-o", str(out)]) == 2
    said = capsys.readouterr().err
    row = 2 + before
    assert f"{path}: row {row}: 8 cells where the header has 4: {SPLIT_HINT}" in said, said
    assert not out.exists()


@pytest.mark.parametrize(
    "line",
    ["0.1,1,2,3,4", "0,1,2,3,4,5,6,7,8", "0,a,b,1,2", "0,1,,2,3"],
)
def test_a_row_too_long_for_another_cause_is_refused_without_the_decimal_comma_hint(
    tmp_path: Path, line: str
) -> None:
    """A point in a piece, more than two pieces per cell, a piece that is no digits or an
    empty one: no decimal comma split, no hint."""
    path = _write(tmp_path, f"t,ax,ay,az\n{line}\n")
    with pytest.raises(ValueError, match=None) as err:
        read_recorder_csv(path)
    cells = line.count(",") + 1
    assert str(err.value) == f"{path}: row 2: {cells} cells where the header has 4"


def test_a_decimal_comma_past_the_sniffed_rows_names_the_option(tmp_path: Path) -> None:
    """The decimal mark is sniffed from the first 50 data rows; a decimal comma after them
    (between ';') is refused naming its cell and `--decimal ,`, and read with it."""
    rows = "".join(f"{k};0;0;9\n" for k in range(60))
    path = _write(tmp_path, f"t;ax;ay;az\n{rows}60;0,5;0;9\n")
    with pytest.raises(ValueError, match=None) as err:
        read_recorder_csv(path)
    assert str(err.value) == (
        f"{path}: row 62, column ax: '0,5' is not a number: a decimal comma? say "
        "`mount-twin import-csv --decimal ,` (thousands separators are not read)"
    )
    got = read_recorder_csv(path, CsvFormat(decimal=","))
    assert got.signal.accel[-1, 0] == 0.5
