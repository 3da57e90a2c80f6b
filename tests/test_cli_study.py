"""``odpipe study`` takes several configurations (``odpipe study runs/study_*.toml``): all are checked
before any runs, each runs into its own folder, one failing does not stop the others; ``odpipe liaison``
(its former name) is the same command. The scenario itself is replaced here by a stand-in (the real
runs: tests/test_study_*.py)."""

import json
from pathlib import Path

import pytest

import odpipe.studies.halo_geo_crtbp
from odpipe.cli import main

RUNS = Path(__file__).resolve().parents[1] / "runs"


@pytest.fixture
def scenario(monkeypatch):
    """The baseline scenario's run replaced: writes report.md with its seed, fails when the seed is 13."""
    ran = []

    def fake(cfg, out, log=print):
        log(f"seed {cfg['seed']}")
        if cfg["seed"] == 13:
            raise ValueError(f"seed {cfg['seed']}: an unlucky value")
        ran.append(cfg["seed"])
        (out / "report.md").write_text(f"seed {cfg['seed']}\n")
        return {}
    monkeypatch.setattr(odpipe.studies.halo_geo_crtbp, "run", fake)
    return ran


def _configs(tmp_path, *seeds):
    text = (RUNS / "study_halo_geo_crtbp.toml").read_text()
    paths = []
    for s in seeds:
        p = tmp_path / f"study_{s}.toml"
        p.write_text(text.replace("seed = 2012", f"seed = {s}"))
        paths.append(p)
    return paths


def test_several_configurations_run_into_their_own_folders(tmp_path, capsys, scenario):
    paths = _configs(tmp_path, 1, 2)
    assert main(["study", *map(str, paths), "-o", str(tmp_path / "out")]) == 0
    out = capsys.readouterr()
    assert out.out.splitlines() == [f"report: {tmp_path / 'out' / p.stem / 'report.md'}" for p in paths]
    assert scenario == [1, 2] and "seed 1\n" in out.err
    for p in paths:
        assert json.loads((tmp_path / "out" / p.stem / "manifest.json").read_text())["config"] == str(p)


def test_one_failing_scenario_does_not_stop_the_others(tmp_path, capsys, scenario):
    paths = _configs(tmp_path, 13, 2)
    assert main(["study", *map(str, paths), "-o", str(tmp_path / "out")]) == 4
    out = capsys.readouterr()
    assert out.out.splitlines() == [f"report: {tmp_path / 'out' / 'study_2' / 'report.md'}"]
    assert f"error: {paths[0]}: seed 13: an unlucky value" in out.err.splitlines()
    assert scenario == [2]


def test_a_wrong_configuration_stops_all_before_any_runs(tmp_path, capsys, scenario):
    paths = _configs(tmp_path, 1, 2)
    paths[1].write_text(paths[1].read_text().replace("cadence_s = 100.0", "cadence_s = 100.0\ncadense_s = 100.0"))
    assert main(["study", *map(str, paths), "-o", str(tmp_path / "out")]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith(f"error: {paths[1]}:6: [cadense_s] unknown key (allowed: arc_days, cadence_s,")
    assert scenario == [] and not (tmp_path / "out").exists()


def test_the_former_name_runs_the_same_command(tmp_path, capsys, scenario):
    (path,) = _configs(tmp_path, 5)
    assert main(["liaison", str(path), "-o", str(tmp_path / "out")]) == 0
    assert capsys.readouterr().out.splitlines() == [f"report: {tmp_path / 'out' / 'report.md'}"]
    assert scenario == [5]
