"""The step commands' bad inputs, as a user types them: numeric options out of range, an arc that ends
before it starts, corrupt and empty files. Each is one line naming the option or the file, exit status 2
(before these checks a count time of 0 or a negative gap ran with exit 0, and inf was an internal error)."""

import subprocess
import sys
from pathlib import Path

import pytest

from odpipe.cli import main

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "fixtures" / "trk234" / "sample.tnf"   # a TRK-2-34 file of 19 records


@pytest.fixture(scope="module")
def table(tmp_path_factory) -> Path:
    """The sample converted to a TrackingTable Parquet file, as `odpipe convert` writes it."""
    out = tmp_path_factory.mktemp("table") / "sample.parquet"
    assert main(["convert", str(SAMPLE), "-o", str(out)]) == 0
    return out


def _usage_error(argv, capsys) -> str:
    """The error line of a usage error (argparse's: the usage, then 'odpipe CMD: error: ...'), exit 2."""
    with pytest.raises(SystemExit) as done:
        main(argv)
    assert done.value.code == 2
    return capsys.readouterr().err.strip().splitlines()[-1]


@pytest.mark.parametrize("command, option, value, reason", [
    ("compress", "--count-time", "0", "0.0 must be positive and finite"),
    ("compress", "--count-time", "-60", "-60.0 must be positive and finite"),
    ("compress", "--count-time", "inf", "inf must be positive and finite"),
    ("compress", "--count-time", "nan", "nan must be positive and finite"),
    ("compress", "--count-time", "1min", "'1min' is not a number"),
    ("compress", "--max-gap", "-1", "-1.0 must be positive and finite"),
    ("edit", "--min-pass-samples", "-4", "-4 must be positive and finite"),
    ("edit", "--min-pass-samples", "2.5", "'2.5' is not an integer"),
    ("edit", "--blunder-k", "0", "0.0 must be positive and finite"),
])
def test_a_bad_number_is_a_usage_error_naming_the_option(table, tmp_path, capsys, command, option, value, reason):
    line = _usage_error([command, str(table), "-o", str(tmp_path / "out.parquet"), option, value], capsys)
    assert line == f"odpipe {command}: error: argument {option}: {reason}"
    assert not (tmp_path / "out.parquet").exists()


def test_numbers_of_the_other_commands(tmp_path, capsys):
    line = _usage_error(["overlap", "a.oem", "b.oem", "--step", "0"], capsys)
    assert line == "odpipe overlap: error: argument --step: 0.0 must be positive and finite"
    line = _usage_error(["simulate", str(ROOT / "runs" / "artemis_p2_like.toml"), "-o", str(tmp_path), "--days", "-1"],
                        capsys)
    assert line == "odpipe simulate: error: argument --days: -1.0 must be positive and finite"
    line = _usage_error(["demo", "-o", str(tmp_path), "--workers", "0"], capsys)   # it waited for ever on no worker
    assert line == "odpipe demo: error: argument --workers: 0 must be positive and finite"


def test_edit_refuses_an_arc_that_ends_before_it_starts(table, tmp_path, capsys):
    """It flagged every row outside_arc and exited 0."""
    assert main(["edit", str(table), "-o", str(tmp_path / "e.parquet"), "--no-elevation-mask",
                 "--arc", "2016-03-02", "2016-03-01"]) == 2
    assert capsys.readouterr().err.strip() == "error: --arc: END 2016-03-01 is not after START 2016-03-02"


def test_a_corrupt_parquet_file_is_one_line_naming_it_once(tmp_path, capsys):
    """Parquet magic at both ends, nothing valid between: pyarrow's text named the file a second time."""
    bad = tmp_path / "bad.parquet"
    bad.write_bytes(b"PAR1garbagePAR1")
    for command in (["inspect", str(bad)], ["compress", str(bad), "-o", str(tmp_path / "c.parquet")],
                    ["edit", str(bad), "-o", str(tmp_path / "e.parquet"), "--no-elevation-mask"]):
        assert main(command) == 2
        (line,) = capsys.readouterr().err.strip().splitlines()
        assert line.startswith(f"error: {bad}: not a readable Parquet file (") and line.count(str(bad)) == 1, line


def test_an_empty_file_is_said_to_be_empty(tmp_path):
    """As a user runs it: `odpipe inspect` and `odpipe convert` on a file of 0 bytes."""
    empty = tmp_path / "empty.odf"
    empty.write_bytes(b"")
    for args in (["inspect", str(empty)], ["convert", str(empty), "-o", str(tmp_path / "x.parquet")]):
        out = subprocess.run([sys.executable, "-m", "odpipe.cli", *args], capture_output=True, text=True, cwd=ROOT)
        assert out.returncode == 2 and out.stderr == f"error: {empty}: empty file (0 bytes)\n", out.stderr


def test_maneuvers_of_a_folder_that_does_not_exist(tmp_path, capsys):
    """It said 'no maneuvers.csv (did the run estimate maneuvers?)' of a mistyped run folder."""
    assert main(["maneuvers", str(tmp_path / "runs" / "typo")]) == 2
    assert capsys.readouterr().err.strip() == f"error: {tmp_path / 'runs' / 'typo'}: No such file or directory"


@pytest.mark.realdata
@pytest.mark.parametrize("option, value, reason", [("--span", "-1", "-1.0 must be positive and finite"),
                                                   ("--degree", "1", "1 must be at least 2")])
def test_apriori_options_are_checked_as_the_configuration_is(capsys, option, value, reason):
    """`odpipe apriori` on the GRAIL start arc: its overrides pass [initial_state.from_doppler]'s checks (a
    negative span was 'zero-size array to reduction operation', a negative degree 'negative dimensions')."""
    assert main(["apriori", str(ROOT / "runs" / "grail_b_2012_04_09_start.toml"), option, value]) == 2
    assert capsys.readouterr().err.strip() == f"error: {option}: {reason}"


def test_overlap_command_prints_its_means_to_three_figures(tmp_path, capsys):
    """Three straight-line arcs offset 0, 100 and 300 m cross-track (overlaps of 100 and 200 m, a known
    difference): `odpipe overlap` printed '150.000 ± 70.711 m' and velocities to 1e-4 mm/s; the mean to 3
    significant figures now, as the standard deviation (numerics.precision.plus_minus, as every report)."""
    import numpy as np

    from odpipe.products.oem import write_oem
    from odpipe.products.segments import EphemerisSegment

    t = 4e8 + np.arange(0.0, 7201.0, 60.0)
    x = np.column_stack([7e6 + 0 * t, 7.5e3 * (t - t[0]), 0 * t, 0 * t, 7.5e3 + 0 * t, 0 * t])
    paths = []
    for k, (lo, hi) in enumerate([(0, 80), (40, 121), (80, 121)]):
        shifted = x[lo:hi] + [0, 0, (0.0, 100.0, 300.0)[k], 0, 0, 0]
        paths.append(str(write_oem(tmp_path / f"a{k}.oem", [EphemerisSegment(t[lo:hi], shifted)], "SC", "-1")))
    assert main(["overlap", *paths, "-o", str(tmp_path / "out"), "--step", "60"]) == 0
    line = capsys.readouterr().out.splitlines()[0]
    assert line == "2 overlaps; position 3D RMS 150 ± 70.7 m, velocity 3D RMS 0.00 ± 0.00 mm/s", line
