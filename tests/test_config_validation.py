"""Run configurations are checked whole at load: ``odpipe run`` on a wrong one writes nothing, exits 2
and says in one line every problem with its key and line."""

import re
from pathlib import Path

import pytest

from odpipe.cli import main
from odpipe.pipeline.config import load_config
from odpipe.operations.schema import ConfigError, key_line

TRACKING = Path(__file__).resolve().parents[1] / "fixtures" / "trk234" / "sample.tnf"  # a TRK-2-34 file

GOOD = f"""[run]
name = "arc"
output = "out"

[arc]
spacecraft = "1"
start = "2020-01-01T00:00:00"
end = "2020-01-02T00:00:00"

[data]
files = ["{TRACKING}"]

[dynamics]
center = "earth"

[initial_state]
epoch = "2020-01-01T00:00:00"
state = [7.0e6, 0.0, 0.0, 0.0, 7.5e3, 0.0]

[estimation]
sigma_position = 1000.0
data_sigma = {{ range = 2.0, doppler_2way = 1e-4 }}

[products]
step = 60.0
"""


def _write(tmp_path, text, name="arc.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _run(path, capsys) -> tuple[int, str]:
    code = main(["run", str(path)])
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1, err  # one line, never a traceback
    return code, err[0]


def _line(text, needle) -> int:
    return next(i for i, ln in enumerate(text.splitlines(), start=1) if needle in ln)


def test_the_good_configuration_loads(tmp_path):
    cfg = load_config(_write(tmp_path, GOOD))
    assert cfg.data.files == [TRACKING] and cfg.run.output == tmp_path / "out"


@pytest.mark.parametrize("old, new, key, reason", [
    ('start = "2020-01-01T00:00:00"', 'start = "2020-13-01T00:00:00"', "arc.start",
     "'2020-13-01T00:00:00' is not a valid time: month out of range"),
    ('end = "2020-01-02T00:00:00"', 'end = "2019-02-30"', "arc.end",
     "'2019-02-30' is not a valid time: day out of range"),
    ('end = "2020-01-02T00:00:00"', 'end = "2019-12-31T00:00:00"', "arc.end",
     "2019-12-31T00:00:00 is not after the start 2020-01-01T00:00:00"),
    ('epoch = "2020-01-01T00:00:00"', 'epoch = "yesterday"', "initial_state.epoch",
     "'yesterday' is not a UTC ISO time (YYYY-MM-DDTHH:MM:SS)"),
    ("sigma_position = 1000.0", "sigma_position = nan", "estimation.sigma_position", "nan must be positive and finite"),
    ("range = 2.0,", "range = -2.0,", "estimation.data_sigma.range", "-2.0 must be positive and finite"),
    ("step = 60.0", "step = 0", "products.step", "0.0 must be positive and finite"),
    ('name = "arc"', 'name = "../../x"', "run.name", "'../../x' is not a plain name"),
    ("state = [7.0e6, 0.0, 0.0, 0.0, 7.5e3, 0.0]", "state = [7.0e6, 0.0, 0.0, 0.0, 7.5e3, inf]",
     "initial_state.state", "needs 6 finite numbers (m, m/s)"),
    ('center = "earth"', 'center = "earth"\nmas = 5.0', "dynamics.mas", "unknown key (allowed: center, drag, ephemeris"),
    ("sigma_position = 1000.0", "sigma_position = 1000.0\noscillator_sigma = { X = [1e-6, 1e-12], Q = [1e-5, 1e-10] }",
     "estimation.oscillator_sigma.Q", "'Q' is not a band (S, X, Ka)"),
    ("sigma_position = 1000.0", "sigma_position = 1000.0\noscillator_sigma = [1e-6]", "estimation.oscillator_sigma",
     "[1e-06] must be two sigmas: [y0, y1 (1/s)]"),
])
def test_one_bad_value_names_its_key_and_line(tmp_path, capsys, old, new, key, reason):
    text = GOOD.replace(old, new)
    assert text != GOOD
    path = _write(tmp_path, text)
    code, line = _run(path, capsys)
    assert code == 2
    where = _line(text, new.splitlines()[-1])
    assert line.startswith(f"error: {path}:{where}: [{key}] {reason}"), line
    assert not (tmp_path / "out").exists() and not (tmp_path.parent / "x").exists()  # nothing written


def test_every_problem_in_one_error(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("not tracking data\n")
    text = (GOOD.replace('name = "arc"', 'name = "../x"')
            .replace('start = "2020-01-01T00:00:00"', 'start = "2020-01-01T25:00:00"')
            .replace(f'files = ["{TRACKING}"]', 'files = ["notes.txt", "absent.odf", "."]')
            .replace("sigma_position = 1000.0", "sigma_position = -1.0\nedit_k = [inf, 0.0]")
            .replace("step = 60.0", "step = 60.0\nspk = 1"))
    path = _write(tmp_path, text)
    code, line = _run(path, capsys)
    assert code == 2
    head, _, rest = line.partition(": 8 problems: ")
    assert head == f"error: {path}"
    files = _line(text, "files =")
    assert rest.split("; ") == [  # by line; the end is checked against the start once both are times
        f"line {_line(text, 'name =')} [run.name] '../x' is not a plain name (no '/', '\\', '.' or '..'): "
        "it must stay inside the output folder",
        f"line {_line(text, 'start =')} [arc.start] '2020-01-01T25:00:00' is not a valid time: hours out of range",
        f"line {files} [data.files] {tmp_path / 'notes.txt'} is not a tracking file (no reader recognises it)",
        f"line {files} [data.files] {tmp_path / 'absent.odf'} does not exist",
        f"line {files} [data.files] {tmp_path} is not a file",
        f"line {_line(text, 'sigma_position')} [estimation.sigma_position] -1.0 must be positive and finite",
        f"line {_line(text, 'edit_k')} [estimation.edit_k[1]] 0.0 must be positive",
        f"line {_line(text, 'spk = 1')} [products.spk] expected bool, got 1",
    ]


def test_files_of_the_wrong_kind_are_refused(tmp_path, capsys):
    plan = tmp_path / "plan.csv"
    plan.write_text("name,epoch,frame,dv1,dv2,dv3\nM1,2020-01-01T12:00:00,ICRF,0.1,0,0\n")
    text = GOOD.replace(f'files = ["{TRACKING}"]', f'files = ["{plan}"]').replace(
        "sigma_position = 1000.0", f'maneuver_plan = "{TRACKING}"')
    path = _write(tmp_path, text)
    code, line = _run(path, capsys)
    assert code == 2
    assert line == (f"error: {path}: 2 problems: "
                    f"line {_line(text, 'files =')} [data.files] {plan} is not a tracking file "
                    "(recognised as parsers.maneuvers); "
                    f"line {_line(text, 'maneuver_plan')} [estimation.maneuver_plan] {TRACKING} is not a "
                    "maneuver plan file (recognised as parsers.trk234)")


def test_malformed_and_undecodable_files(tmp_path, capsys):
    text = GOOD.replace("[arc]", "[arc")
    code, line = _run(_write(tmp_path, text), capsys)
    assert code == 2 and re.match(rf"error: {tmp_path / 'arc.toml'}:{_line(text, '[arc')}: not valid TOML: ", line)
    raw = GOOD.encode().replace(b'"1"', b'"\xe9"')
    (tmp_path / "arc.toml").write_bytes(raw)
    code, line = _run(tmp_path / "arc.toml", capsys)
    assert (code, line) == (2, f"error: {tmp_path / 'arc.toml'}: not UTF-8 text (byte offset {raw.index(0xE9)})")


def test_key_line_finds_keys_tables_and_inline_entries():
    text = ('[run]\nname = "a"\n[estimation]\n"data_sigma" = { range = 1 }\n[[dynamics.gravity]]\n'
            'body = "moon"\nfile = "m"\n[[dynamics.gravity]]\nfile = "x"\n')
    assert key_line(text, "run.name") == 2
    assert key_line(text, "estimation.data_sigma.range") == 4
    assert key_line(text, "dynamics.gravity[0].body") == 6
    assert key_line(text, "dynamics.gravity[1].file") == 9  # the second [[dynamics.gravity]]
    assert key_line(text, "dynamics.gravity[1].degree") == 8  # missing there: its header
    assert key_line(text, "arc.start") is None
    assert key_line(text, "run.output") == 1  # a missing key: its table


def test_config_error_keeps_the_first_problem_for_callers(tmp_path):
    path = _write(tmp_path, GOOD.replace("step = 60.0", "step = -1.0\nplots = 3"))
    with pytest.raises(ConfigError) as err:
        load_config(path)
    assert err.value.key == "products.step" and err.value.reason == "-1.0 must be positive and finite"
    assert [p.key for p in err.value.problems] == ["products.step", "products.plots"]
