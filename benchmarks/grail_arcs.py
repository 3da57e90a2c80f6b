"""The GRAIL-B nightly chain with settings overridden, for the leave-one-out and error-budget drivers.

Each variant writes its own run configurations (the nightly ones with some keys replaced and paths
made absolute) into ``OUT/<variant>/configs`` and runs them in this process with
:func:`odpipe.pipeline.run.run_config` (so numba compiles once), chained as the nightly is:
04-09 from the start-up fit, 04-10 from 04-09, 04-11 from 04-10, 04-08 from 04-09. A variant's
arcs that already have a complete run (``OUT/<variant>/<arc>/current``) are not run again, so an interrupted
driver resumes, and runs made elsewhere with the same settings (e.g. the nightly's own) can be copied in.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.analysis.overlap import compare, oem_trajectory
from odpipe.pipeline.run import run_config

RUNS = Path(__file__).resolve().parents[1] / "runs"
START = "grail_b_2012_04_09_start"
DAILY = ("grail_b_2012_04_08", "grail_b_2012_04_09", "grail_b_2012_04_10", "grail_b_2012_04_11")
SOURCE = {"grail_b_2012_04_09": START, "grail_b_2012_04_10": "grail_b_2012_04_09",
          "grail_b_2012_04_11": "grail_b_2012_04_10", "grail_b_2012_04_08": "grail_b_2012_04_09"}
ORDER = ("grail_b_2012_04_09", "grail_b_2012_04_10", "grail_b_2012_04_11", "grail_b_2012_04_08")
PAIRS = tuple(zip(DAILY[:-1], DAILY[1:]))


def _absolute_paths(text: str, folder: Path) -> str:
    """Relative quoted paths ("../x", "./x") made absolute against ``folder``."""
    return re.sub(r'"(\.\.?/[^"]*)"', lambda m: f'"{(folder / m.group(1)).resolve()}"', text)


def set_key(text: str, section: str, key: str, value: str) -> str:
    """``text`` with ``key = ...`` inside TOML table ``[section]`` (or ``[[section]]``) set to ``value``
    (a TOML literal), added at the table's end when absent. ValueError when the table is absent."""
    lines = text.splitlines()
    head = re.compile(r"^\s*\[\[?\s*" + re.escape(section) + r"\s*\]\]?\s*(#.*)?$")
    start = next((i for i, s in enumerate(lines) if head.match(s)), None)
    if start is None:
        raise ValueError(f"no [{section}] table")
    end = next((i for i in range(start + 1, len(lines)) if re.match(r"^\s*\[", lines[i])), len(lines))
    entry = re.compile(r"^\s*" + re.escape(key) + r"\s*=")
    for i in range(start + 1, end):
        if entry.match(lines[i]):
            lines[i] = f"{key} = {value}"
            break
    else:
        while end > start + 1 and not lines[end - 1].strip():
            end -= 1
        lines.insert(end, f"{key} = {value}")
    return "\n".join(lines) + "\n"


def variant_config(name: str, out: Path, overrides: dict, source_out: Path | None, source=SOURCE) -> Path:
    """Write arc ``name``'s configuration for a variant into ``out/configs``: output in ``out``, the
    a priori from ``source_out``'s run of the source arc (``source[name]``), ``overrides`` {"section.key":
    TOML literal}."""
    text = _absolute_paths((RUNS / f"{name}.toml").read_text(), RUNS)
    text = set_key(text, "run", "output", f'"{out}"')
    text = set_key(text, "products", "plots", "false")
    text = set_key(text, "products", "spk", "false")
    if source_out is not None:
        text = set_key(text, "initial_state", "from_oem",
                       f'"{source_out / source[name] / "current" / "trajectory.oem"}"')
    for dotted, value in overrides.items():
        section, key = dotted.rsplit(".", 1)
        text = set_key(text, section, key, value)
    path = out / "configs" / f"{name}.toml"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def run_variant(out: Path, overrides: dict, start_out: Path, arcs=ORDER, log=print, source=SOURCE) -> dict:
    """Run the ``arcs`` (chain order) of one variant, each from its ``source`` arc's run; {arc: run_config
    summary or the error text}."""
    results = {}
    for name in arcs:
        src = start_out if source[name] == START else out
        if source[name] != START and not isinstance(results.get(source[name], {}), dict):
            results[name] = f"source {source[name]} failed"
            continue
        if (out / name / "current" / "summary.json").exists():
            results[name] = {"status": "present"}
            continue
        cfg = variant_config(name, out, overrides, src, source)
        try:
            results[name] = run_config(cfg, progress=None)
            log(f"{out.name} {name}: {results[name]['status']}")
        except Exception as exc:  # a failed fit is a result of the variant, not the driver's end
            results[name] = f"{type(exc).__name__}: {exc}"
            log(f"{out.name} {name}: FAILED {results[name]}")
    return results


def run_start(out: Path) -> Path:
    """The start-up fit (04-09 from its Doppler a priori), as configured, into ``out`` (unless there)."""
    if not (out / START / "current" / "summary.json").exists():
        run_config(variant_config(START, out, {}, None), progress=None)
    return out


def arc_figures(out: Path, name: str) -> dict:
    """Post-fit RMS per station (mm/s), rows fitted and edited by the fit, of one arc's current run: two-way
    Doppler (``rms_mm_s.<station>``, ``fitted``, ``edited``) and, when fitted, one-way X band
    (``rms1w_mm_s.<station>``, ``fitted_1way``, ``edited_1way``) and S band (``rms1wS_mm_s.<station>``,
    ``fitted_1wayS``, ``edited_1wayS``)."""
    run = out / name / "current"
    res = pd.read_parquet(run / "residuals.parquet")
    band = pd.read_parquet(run / "tracking.parquet", columns=["band_down"])["band_down"].to_numpy()[res["row"]]
    row = {"arc": name}
    for obs, suffix, key, bands in (("doppler_2way", "", "rms_mm_s", ("S", "X")),
                                    ("doppler_1way", "_1way", "rms1w_mm_s", ("X",)),
                                    ("doppler_1way", "_1wayS", "rms1wS_mm_s", ("S",))):
        ok = (res["status"] == "") & (res["observable"] == obs) & np.isin(band, bands)
        if obs == "doppler_1way" and not ok.any():
            continue
        row[f"fitted{suffix}"] = int((ok & (res["flags"] == 0)).sum())
        row[f"edited{suffix}"] = int((ok & (res["flags"] != 0)).sum())
        for st, g in res[ok & (res["flags"] == 0)].groupby("station_rx"):
            row[f"{key}.{st}"] = float(np.sqrt(np.mean(g["postfit_los"] ** 2)) * 1e3)
    return row


def trajectory(out: Path, name: str):
    return oem_trajectory(out / name / "current" / "trajectory.oem")


def overlap_figures(out: Path, a: str, b: str, step: float = 60.0, out_b: Path | None = None) -> dict:
    """3D and R/I/C position RMS (m) of the overlap of arcs ``a`` (in ``out``) and ``b`` (in ``out_b``, default
    ``out``): a − b, a's axes."""
    s = compare(trajectory(out, a), trajectory(out_b or out, b), f"{a} - {b}", step).statistics()
    return {"a": a, "b": b, "pos_3d_rms": s["pos_3d_rms"], "radial": s["pos_radial_rms"],
            "intrack": s["pos_intrack_rms"], "crosstrack": s["pos_crosstrack_rms"], "hours": s["hours"]}
