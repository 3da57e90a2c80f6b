"""Scenario configurations: file entries relative to the TOML, ``base`` merging, cycles refused."""

from pathlib import Path

import pytest

from odpipe.liaison.config import load_config

RUNS = Path(__file__).parents[1] / "runs"


def test_paths_resolve_beside_the_configuration(tmp_path):
    (tmp_path / "a.toml").write_text('gravity_file = "../data/g.txt"\n[m]\nmoon_gravity = "/abs/m.cof"\nname = "x"\n')
    cfg = load_config(tmp_path / "a.toml")
    assert cfg["gravity_file"] == str(tmp_path / "../data/g.txt")
    assert cfg["m"] == {"moon_gravity": "/abs/m.cof", "name": "x"}


def test_base_merges_tables_and_replaces_the_rest(tmp_path):
    (tmp_path / "base.toml").write_text('seed = 1\nearth_gravity = "e.txt"\n[clock]\na0 = 1.0\na1 = 2.0\n'
                                        '[[simulation]]\nname = "A"\n')
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "over.toml").write_text('base = "../base.toml"\nseed = 2\n[clock]\na1 = 3.0\n'
                                                '[[simulation]]\nname = "B"\n')
    cfg = load_config(tmp_path / "sub" / "over.toml")
    assert cfg["seed"] == 2 and cfg["clock"] == {"a0": 1.0, "a1": 3.0}
    assert [s["name"] for s in cfg["simulation"]] == ["B"]
    assert cfg["earth_gravity"] == str(tmp_path / "e.txt")      # relative to the base's folder
    assert "base" not in cfg


def test_base_cycle_is_an_error(tmp_path):
    (tmp_path / "a.toml").write_text('base = "b.toml"\n')
    (tmp_path / "b.toml").write_text('base = "a.toml"\n')
    with pytest.raises(ValueError, match="cycle"):
        load_config(tmp_path / "a.toml")


def test_the_integrator_study_runs_on_the_dowr_set_up():
    base, study = load_config(RUNS / "liaison_dowr.toml"), load_config(RUNS / "liaison_dowr_integrators.toml")
    assert study["scenario"] == "dowr" and study["clock"] == base["clock"]
    assert [s["name"] for s in study["simulation"]] == ["Simu. 1", "Simu. 3", "Simu. 4", "Simu. 5"]


def test_malformed_toml_names_the_file_and_line(tmp_path):
    (tmp_path / "bad.toml").write_text('seed = 1\n[clock\na0 = 1.0\n')
    with pytest.raises(ValueError, match=r"bad\.toml.*line 2"):
        load_config(tmp_path / "bad.toml")
