"""Scenario configurations: TOML whose file entries are relative to the configuration.

Entries named ``*_file`` or ``*_gravity`` (at any depth) hold paths; a relative one is taken
from the configuration's folder, so ``runs/liaison_*.toml`` point at ``../../shared/data``
and run from any working directory. ``base = "other.toml"`` starts from that configuration:
tables merge key by key, everything else (values, lists, arrays of tables) is replaced.

``scenario`` names one of :data:`KEYS`, the keys that scenario reads: a key it does not read
(a misspelling, a key of another scenario) is an error naming the file, key and line, as is
a file entry that names no readable file.
"""

from __future__ import annotations

from pathlib import Path

from odpipe.operations.schema import ConfigError, Problem, read_toml, readable

ANY = "any"  # a value, or a table of any keys (reference figures, names chosen by the configuration)
_CASE = {"liaison_gap_h": ANY, "ground_gap_h": ANY, "ground_offset_h": ANY}
_GROUND = {
    "epoch_utc": ANY, "arc_days": ANY, "interval_s": ANY, "count_time_s": ANY, "pass_h": ANY, "window_days": ANY,
    "mask_deg": ANY, "dsn": ANY, "geo_station": ANY, "seed": ANY, "state": ANY, "stations": ANY,
    "geo": {"lat_deg": ANY, "lon_deg": ANY},
    "srp": {"area_to_mass": ANY, "cr": ANY},
    "truth": {"gravity_file": ANY, "bodies": ANY, "earth_degree": ANY},
    "filter": {"gravity_file": ANY, "bodies": ANY, "earth_degree": ANY, "apriori_pos_m": ANY,
               "apriori_vel_mps": ANY, "srp_sigma": ANY, "acc_sigma_rtn": ANY, "acc_tau_s": ANY,
               "acc_batch_s": ANY, "sst_bias_m": ANY, "dsn_bias_m": ANY, "geo_bias_m": ANY, "block_s": ANY,
               "max_iter": ANY},
    "noise": {f"{link}_{kind}": ANY for link in ("dsn", "geo", "sst") for kind in ("range", "rate")},
    "cases": {"*": _CASE},
    "paper": ANY, "report": {"differences": ANY}, "sensitivity": {"acc_scale": ANY, "cases": ANY},
}
_HALO = {"x0": ANY, "vy0": ANY, "z_start": ANY, "z_stop": ANY, "dz": ANY}
KEYS = {  # scenario -> the keys its module (odpipe.liaison.<scenario>) reads; {"*": T}: tables of any name
    "baseline": {
        "arc_days": ANY, "cadence_s": ANY, "seed": ANY, "compare_day": ANY,
        "units": {"length_km": ANY, "gm_earth_km3s2": ANY, "gm_moon_km3s2": ANY},
        "noise": {"range_m": ANY, "range_rate_mps": ANY},
        "filter": {"apriori_pos_m": ANY, "apriori_vel_mps": ANY, "deviation_halo": ANY, "deviation_geo": ANY,
                   "snc_mps2": ANY, "block_h": ANY, "max_iter": ANY},
        "halo": {"period_days": ANY, **_HALO},
        "geo": {"inclination_deg": ANY, "phase_deg": ANY},
        "variant": [{"name": ANY, "halo": {"period_days": ANY, **_HALO},
                     "geo": {"inclination_deg": ANY, "phase_deg": ANY}}],
        "montecarlo": {"runs": ANY, "seed": ANY, "parallel": ANY},
        "paper": ANY,
    },
    "turan": {
        "units": {"length_km": ANY, "gm_earth_km3s2": ANY, "mu": ANY},
        "cadence": {"dt_tu": ANY},
        "noise": {"range_m": ANY, "range_rate_mps": ANY},
        "filter": {"apriori_pos_m": ANY, "apriori_vel_mps": ANY, "error_pos_m": ANY, "error_vel_mps": ANY,
                   "block_h": ANY, "max_iter": ANY},
        "halo": {"start": ANY, "north": ANY, "L1": {"periods_tu": ANY, **_HALO},
                 "L2": {"periods_tu": ANY, **_HALO}},
        "lunar": {"period_days": ANY, "ecc": ANY, "inc_deg": ANY, "raan_deg": ANY, "argp_deg": ANY,
                  "true_anomaly_deg": ANY, "phase_band_deg": ANY},
        "montecarlo": {"runs": ANY, "seed": ANY, "parallel": ANY, "workers": ANY, "columns": ANY},
        "sweep": {"range_m": ANY, "range_rate_mps": ANY, "snc_mps2": ANY},
        "paper": ANY,
    },
    "doppler": {
        "epoch_utc": ANY, "interval_s": ANY, "arc_days": ANY, "count_time_s": ANY, "seed": ANY, "bands": ANY,
        "gravity_file": ANY, "state": ANY, "deviation": ANY,
        "truth": {"bodies": ANY, "earth_degree": ANY},
        "filter": {"bodies": ANY, "earth_degree": ANY, "apriori_pos_m": ANY, "apriori_vel_mps": ANY,
                   "snc_sigma_mps2": ANY, "bias_sigma_los_mps": ANY, "max_iter": ANY, "stage_days": ANY,
                   "geo_cutoff_vx_mps": ANY},
        "band": {"*": {"sigma_mps": ANY, "bias_mps": ANY}},
        "paper": ANY,
    },
    "dowr": {
        "epoch_utc": ANY, "arc_days": ANY, "last_days": ANY, "converged_m": ANY, "seed": ANY,
        "earth_gravity": ANY, "moon_gravity": ANY, "sample_s": ANY, "pass_s": ANY, "batch_s": ANY,
        "paper_step_s": ANY, "block_s": ANY, "lookback_s": ANY, "stage_days": ANY, "max_iter": ANY,
        "final_iter": ANY, "dro_state_km": ANY,
        "leo_elements": {"a_km": ANY, "inc_deg": ANY, "raan_deg": ANY, "u_deg": ANY},
        "spacecraft": {"mass_kg": ANY, "area_m2": ANY, "cr": ANY, "cd": ANY, "n_bulge": ANY},
        "clock": {"a0_s": ANY, "a1": ANY, "a2_per_day": ANY, "sigma_y_1s": ANY, "leo_sigma_s": ANY,
                  "leo_tau_s": ANY, "lattice_s": ANY, "thermal_m": ANY, "delay_m": ANY},
        "apriori": {"pos_m": ANY, "vel_mps": ANY, "a0_s": ANY, "a1": ANY, "a2_per_day": ANY, "delay_m": ANY,
                    "cd": ANY, "cr": ANY},
        "model": {"*": {"earth_degree": ANY, "moon_degree": ANY, "estimate_dynamic": ANY}},
        "simulation": [{"name": ANY, "mode": ANY, "model": ANY, "integrator": ANY, "step_s": ANY,
                        "stage_days": ANY, "max_iter": ANY, "final_iter": ANY, "plan": [{"type": ANY, "every_h": ANY}],
                        "snc_mps2": ANY, "paper": ANY}],
        "montecarlo": {"parallel": ANY},
    },
    "ground": _GROUND,
    "ground_mesh": {**_GROUND, "mesh": {"gaps_h": ANY}, "offset": {"gaps_h": ANY}},
}


def _is_file_entry(key: str) -> bool:
    return key.endswith(("_file", "_gravity"))


def _resolve(node, base: Path):
    if isinstance(node, dict):
        return {k: (str(base / v) if isinstance(v, str) and _is_file_entry(k)
                    and not Path(v).is_absolute() else _resolve(v, base)) for k, v in node.items()}
    return node


def _merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def problems(node, template, key: str = "") -> list[Problem]:
    """What in ``node`` (a configuration's table) ``template`` (a :data:`KEYS` entry) does not allow,
    and file entries naming no readable file."""
    if template == ANY:
        return [Problem(key, why) for k, v in _walk(node, key) if _is_file_entry(k.rsplit(".", 1)[-1])
                and isinstance(v, str) and (why := readable(Path(v)))]
    if isinstance(template, list):
        if not isinstance(node, list):
            return [Problem(key, f"expected an array of tables, got {type(node).__name__}")]
        return [p for i, item in enumerate(node) for p in problems(item, template[0], f"{key}[{i}]")]
    if not isinstance(node, dict):
        return [Problem(key, f"expected a table, got {type(node).__name__}")]
    out = []
    for k, v in node.items():
        sub = f"{key}.{k}" if key else k
        if "*" in template:
            out += problems(v, template["*"], sub)
        elif k in template:
            out += problems(v, template[k], sub)
        else:
            out.append(Problem(sub, f"unknown key (allowed: {', '.join(sorted(template))})"))
    return out


def _walk(node, key):
    yield key, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _walk(v, f"{key}.{k}" if key else k)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _walk(v, f"{key}[{i}]")


def _read(path: Path, seen: tuple) -> tuple[dict, list]:
    """The merged configuration at ``path`` and its files as (path, text, own table) pairs, top first."""
    if path in seen:
        raise ConfigError(path, "base", "configuration bases form a cycle: "
                          + " -> ".join(p.name for p in (*seen, path)))
    data, text = read_toml(path)
    own = _resolve(data, path.parent)
    if "base" not in own:
        return own, [(path, text, own)]
    base, files = _read((path.parent / own["base"]).resolve(), (*seen, path))
    own = {k: v for k, v in own.items() if k != "base"}
    return _merge(base, own), [(path, text, own)] + files


def load_config(path) -> dict:
    """The scenario configuration at ``path`` on its ``base``, file entries resolved, every key checked
    against its scenario's (ConfigError naming the file, key and line)."""
    path = Path(path).resolve()
    cfg, files = _read(path, ())
    name = cfg.get("scenario")
    if name not in KEYS:
        raise ConfigError(path, "scenario", f"must be one of {', '.join(KEYS)}, got {name!r}").located(files[0][1])
    template = {**KEYS[name], "scenario": ANY}
    for file, text, own in files:
        found = problems(own, template)
        if found:
            raise ConfigError(file, problems=found).located(text)
    return cfg
