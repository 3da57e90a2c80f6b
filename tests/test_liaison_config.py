"""Scenario configurations: file entries relative to the TOML, ``base`` merging, cycles refused."""

from pathlib import Path

import re

import pytest

from odpipe.liaison.config import KEYS, load_config
from odpipe.operations.schema import ConfigError

RUNS = Path(__file__).parents[1] / "runs"


def test_paths_resolve_beside_the_configuration(tmp_path):
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "g.txt").write_text("field\n")
    (tmp_path / "m.cof").write_text("field\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "a.toml").write_text(f'scenario = "ground"\n[truth]\ngravity_file = "../data/g.txt"\n'
                                             f'[filter]\ngravity_file = "{tmp_path / "m.cof"}"\nmax_iter = 3\n')
    cfg = load_config(tmp_path / "sub" / "a.toml")
    assert cfg["truth"]["gravity_file"] == str(tmp_path / "sub" / "../data/g.txt")
    assert cfg["filter"] == {"gravity_file": str(tmp_path / "m.cof"), "max_iter": 3}


def test_base_merges_tables_and_replaces_the_rest(tmp_path):
    (tmp_path / "e.txt").write_text("field\n")
    (tmp_path / "base.toml").write_text('scenario = "dowr"\nseed = 1\nearth_gravity = "e.txt"\n'
                                        '[clock]\na0_s = 1.0\na1 = 2.0\n[[simulation]]\nname = "A"\n')
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "over.toml").write_text('base = "../base.toml"\nseed = 2\n[clock]\na1 = 3.0\n'
                                                '[[simulation]]\nname = "B"\n')
    cfg = load_config(tmp_path / "sub" / "over.toml")
    assert cfg["seed"] == 2 and cfg["clock"] == {"a0_s": 1.0, "a1": 3.0}
    assert [s["name"] for s in cfg["simulation"]] == ["B"]
    assert cfg["earth_gravity"] == str(tmp_path / "e.txt")      # relative to the base's folder
    assert "base" not in cfg


def test_base_cycle_is_an_error(tmp_path):
    (tmp_path / "a.toml").write_text('base = "b.toml"\nscenario = "turan"\n')
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


def test_every_shipped_scenario_configuration_loads():
    for path in sorted(RUNS.glob("liaison_*.toml")):
        assert load_config(path)["scenario"] in KEYS, path


@pytest.mark.parametrize("text, key, reason", [
    ('scenario = "baseline"\narc_day = 9.0\n', "arc_day", "unknown key (allowed: arc_days, cadence_s, compare_day"),
    ('scenario = "baseline"\n[filter]\nmax_iter = 5\nmaxiter = 5\n', "filter.maxiter",
     "unknown key (allowed: apriori_pos_m, apriori_vel_mps, block_h"),
    ('scenario = "dowr"\n[[simulation]]\nname = "A"\n[[simulation]]\nname = "B"\nintegratr = "RK4"\n',
     "simulation[1].integratr", "unknown key (allowed: final_iter, integrator"),
    ('scenario = "doppler"\n[band.S]\nsigma_mps = 1e-3\nbias = 0\n', "band.S.bias",
     "unknown key (allowed: bias_mps, sigma_mps)"),
    ('scenario = "doppler"\n[montecarlo]\nruns = 3\n', "montecarlo", "unknown key"),  # doppler has no Monte Carlo
    ('scenario = "doppler"\ngravity_file = "absent.txt"\n', "gravity_file", "absent.txt does not exist"),
    ('scenario = "dopler"\n', "scenario", "must be one of baseline, turan, doppler, dowr, ground, ground_mesh, "
                                           "got 'dopler'"),
])
def test_a_key_the_scenario_does_not_read_is_refused(tmp_path, text, key, reason):
    (tmp_path / "s.toml").write_text(text)
    with pytest.raises(ConfigError) as err:
        load_config(tmp_path / "s.toml")
    assert err.value.key == key and reason in err.value.reason, err.value
    line = next(i for i, ln in enumerate(text.splitlines(), 1) if ln.lstrip("[").startswith(key.split(".")[-1].split("[")[0]))
    assert str(err.value).startswith(f"{tmp_path / 's.toml'}:{line}: [{key}] ")


def test_a_wrong_key_in_a_base_names_the_base(tmp_path):
    (tmp_path / "base.toml").write_text('scenario = "turan"\n[lunar]\necc = 0.4\ninc = 56.2\n')
    (tmp_path / "over.toml").write_text('base = "base.toml"\n[lunar]\necc = 0.3\n')
    with pytest.raises(ConfigError, match=r"^" + re.escape(f"{tmp_path / 'base.toml'}:4: [lunar.inc] unknown key")):
        load_config(tmp_path / "over.toml")
