"""Study configurations: strict schemas per scenario (key and line of each problem), paths relative to the
file that sets them, ``base`` merging, cycles refused, and the generated reference."""

import dataclasses
import re
import typing
from pathlib import Path

import pytest

from odpipe.studies.scenarios import DOCUMENTED, KINDS, load_config, load_scenario
from odpipe.operations.reference import field_comments, sections
from odpipe.operations.schema import ConfigError

ROOT = Path(__file__).parents[1]
RUNS = ROOT / "runs"


def test_paths_resolve_beside_the_configuration(tmp_path):
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "g.txt").write_text("field\n")
    (tmp_path / "m.cof").write_text("field\n")
    (tmp_path / "sub").mkdir()
    ground = (RUNS / "study_ground_and_crosslink.toml").read_text()
    ground = ground.replace('"../../shared/data/gravity/tudat/ggm02c.txt"', '"../data/g.txt"')
    ground = ground.replace('"../../shared/data/gravity/brahe/GGM05S.gfc"', f'"{tmp_path / "m.cof"}"')
    (tmp_path / "sub" / "a.toml").write_text(ground)
    cfg = load_config(tmp_path / "sub" / "a.toml")
    assert cfg["truth"]["gravity_file"] == str((tmp_path / "data" / "g.txt").resolve())
    assert cfg["filter"]["gravity_file"] == str(tmp_path / "m.cof")
    assert load_scenario(tmp_path / "sub" / "a.toml").truth.gravity_file == (tmp_path / "data" / "g.txt").resolve()


def test_base_merges_tables_and_replaces_the_rest(tmp_path):
    (tmp_path / "e.txt").write_text("field\n")
    text = (RUNS / "study_dro_leo_dowr.toml").read_text()
    for name in ("tudat/ggm02c.txt", "gmat/LP165P.cof"):
        text = text.replace(f'"../../shared/data/gravity/{name}"', '"e.txt"')
    (tmp_path / "base.toml").write_text(text)
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "over.toml").write_text(
        'base = "../base.toml"\nseed = 2\n[clock]\na1 = 3.0\n[[simulation]]\nname = "B"\nmode = "DOWR"\n'
        'model = "A"\nplan = [{type = "dowr", every_h = 24}]\nsnc_mps2 = {DRO = 1e-10, LEO = 1e-8}\n'
        'paper = {clock_ns = 1.0, DRO = {pos_m = 1.0, vel_mps = 1e-6}, LEO = {pos_m = 1.0, vel_mps = 1e-3}}\n')
    cfg = load_config(tmp_path / "sub" / "over.toml")
    base = load_config(RUNS / "study_dro_leo_dowr.toml")
    assert cfg["seed"] == 2 and cfg["clock"] == dict(base["clock"], a1=3.0)
    assert [s["name"] for s in cfg["simulation"]] == ["B"]
    assert cfg["earth_gravity"] == str(tmp_path / "e.txt")      # relative to the base's folder
    assert "base" not in cfg


def test_base_cycle_is_an_error(tmp_path):
    (tmp_path / "a.toml").write_text('base = "b.toml"\nscenario = "formation_observability"\n')
    (tmp_path / "b.toml").write_text('base = "a.toml"\n')
    with pytest.raises(ValueError, match="cycle"):
        load_config(tmp_path / "a.toml")


def test_the_integrator_study_runs_on_the_dowr_set_up():
    base, study = load_config(RUNS / "study_dro_leo_dowr.toml"), load_config(RUNS / "study_dro_leo_dowr_integrators.toml")
    assert study["scenario"] == "dro_leo_dowr" and study["clock"] == base["clock"]
    assert [s["name"] for s in study["simulation"]] == ["Simu. 1", "Simu. 3", "Simu. 4", "Simu. 5"]


def test_malformed_toml_names_the_file_and_line(tmp_path):
    (tmp_path / "bad.toml").write_text('seed = 1\n[clock\na0 = 1.0\n')
    with pytest.raises(ValueError, match=r"bad\.toml.*line 2"):
        load_config(tmp_path / "bad.toml")


def test_every_shipped_scenario_configuration_loads():
    paths = sorted(RUNS.glob("study_*.toml"))
    assert len(paths) == 8
    for path in paths:
        assert load_config(path)["scenario"] in KINDS, path


def _copy(tmp_path, name, old="", new="", base=None) -> Path:
    """runs/NAME.toml into tmp_path (its data paths made absolute) with ``old`` replaced by ``new``."""
    text = (RUNS / name).read_text().replace('"../../shared/', f'"{RUNS}/../../shared/')
    if old:
        assert old in text, old
        text = text.replace(old, new, 1)
    path = tmp_path / (base or name)
    path.write_text(text)
    return path


def _line(path: Path, key: str) -> int:
    """The first line of ``path`` that sets the last part of ``key`` found there (a key or a table header)."""
    lines = path.read_text().splitlines()
    for part in reversed(key.split(".")):
        name = re.escape(part.split("[")[0])
        found = [i for i, ln in enumerate(lines, 1) if re.match(rf"\[*{name}\]?\s*[=\]]", ln)]
        if found:
            return found[0]
    raise LookupError(key)


@pytest.mark.parametrize("name, old, new, key, reason", [
    ("study_halo_geo_crtbp.toml", "cadence_s = 100.0\n", "cadence_s = 100.0\narc_day = 9.0\n", "arc_day",
     "unknown key (allowed: arc_days, cadence_s, compare_day"),
    ("study_halo_geo_crtbp.toml", "max_iter = 5\n", "max_iter = 5\nmaxiter = 5\n", "filter.maxiter",
     "unknown key (allowed: apriori_pos_m, apriori_vel_mps, block_h"),
    ("study_halo_geo_crtbp.toml", "seed = 2012", 'seed = "2012"', "seed", "expected int, got '2012'"),
    ("study_halo_geo_crtbp.toml", "cadence_s = 100.0", "cadence_s = -100.0", "cadence_s", "-100.0 must be positive"),
    ("study_dro_leo_dowr.toml", 'name = "Simu. 6"\n', 'name = "Simu. 6"\nintegratr = "RK4"\n',
     "simulation[1].integratr", "unknown key (allowed: final_iter, integrator"),
    ("study_dro_leo_dowr.toml", 'plan = [{type = "dowr", every_h = 12}]', 'plan = [{type = "DOWR", every_h = 12}]',
     "simulation[0].plan[0].type", "expected one of ['dowr', 'oneway'], got 'DOWR'"),
    ("study_halo_geo_doppler.toml", "bias_mps = 2e-4\n", "bias_mps = 2e-4\nbias = 0\n", "band.S.bias",
     "unknown key (allowed: bias_mps, sigma_mps)"),
    ("study_halo_geo_doppler.toml", "[band.S]", "[montecarlo]\nruns = 3\n[band.S]", "montecarlo",
     "unknown key"),  # this study has no Monte Carlo
    ("study_halo_geo_doppler.toml", "data/gravity/tudat/ggm02c.txt", "absent.txt", "gravity_file",
     "absent.txt does not exist"),
    ("study_halo_geo_doppler.toml", 'scenario = "halo_geo_doppler"', 'scenario = "dopler"', "scenario",
     "must be one of halo_geo_crtbp, halo_geo_doppler, formation_observability, dro_leo_dowr, "
     "ground_and_crosslink, schedule_trade, got 'dopler'"),
])
def test_a_key_the_scenario_does_not_read_is_refused(tmp_path, name, old, new, key, reason):
    path = _copy(tmp_path, name, old, new)
    with pytest.raises(ConfigError) as err:
        load_config(path)
    assert err.value.key == key and reason in err.value.reason, err.value
    assert str(err.value).startswith(f"{path}:{_line(path, key)}: [{key}] "), err.value


def test_a_missing_scenario_is_named(tmp_path):
    path = _copy(tmp_path, "study_halo_geo_crtbp.toml", 'scenario = "halo_geo_crtbp"\n', "")
    with pytest.raises(ConfigError, match=r"^" + re.escape(f"{path}: [scenario] required key is missing (one of "
                                                           "halo_geo_crtbp, halo_geo_doppler,")):
        load_config(path)


def test_a_missing_key_is_named(tmp_path):
    path = _copy(tmp_path, "study_halo_geo_crtbp.toml", "seed = 2012\n", "")
    with pytest.raises(ConfigError, match=r"^" + re.escape(f"{path}: [seed] required key is missing") + "$"):
        load_config(path)


def test_a_wrong_key_in_a_base_names_the_base(tmp_path):
    base = _copy(tmp_path, "study_formation_observability.toml", "inc_deg = 56.2\n", "inc_deg = 56.2\ninc = 56.2\n",
                 base="base.toml")
    (tmp_path / "over.toml").write_text('base = "base.toml"\n[lunar]\necc = 0.3\n')
    with pytest.raises(ConfigError, match=r"^" + re.escape(f"{base}:{_line(base, 'inc')}: [lunar.inc] unknown key")):
        load_config(tmp_path / "over.toml")
    _copy(tmp_path, "study_formation_observability.toml", base="base.toml")
    (tmp_path / "over.toml").write_text('base = "base.toml"\n[lunar]\necc = "0.3"\n')
    with pytest.raises(ConfigError, match=r"^" + re.escape(f"{tmp_path / 'over.toml'}:3: [lunar.ecc] expected a number")):
        load_config(tmp_path / "over.toml")


def test_every_study_key_has_a_description():
    missing = [f"{name}: {key}.{f.name}" if key else f"{name}: {f.name}"
               for name, kind in DOCUMENTED.items() for key, cls in sections(kind) for f in dataclasses.fields(cls)
               if f.name != "scenario" and not field_comments(cls).get(f.name)
               and not (key == "" and dataclasses.is_dataclass(typing.get_type_hints(cls)[f.name]))]
    assert missing == []


def test_the_reference_documents_every_study():
    text = (ROOT / "docs" / "config.md").read_text()
    for name in KINDS:
        assert f"## Study `{name}`" in text
    assert "| `every_h` | number | `required` | h |" in text                  # [[simulation]] plan entries
