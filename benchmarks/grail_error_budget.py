"""Error budget of the GRAIL-B daily-arc overlaps (issue #24 item 1), by difference of solutions.

For each term, the two arcs of one overlap (default 04-10 / 04-11) are refitted with that model
changed, 04-10 from the nightly's own 04-09 a priori and 04-11 chained from the changed 04-10; the
term's contribution is (A' - A) - (B' - B) over the overlap, in R/I/C
(:func:`odpipe.analysis.error_budget.term_contribution`). The formal sigma of the nightly arcs
(data noise and stochastic accelerations) comes from their OEM covariances. Terms:

* ``field_glgm3`` / ``field_lp165p``: the lunar field GLGM-3 (150x150) or LP165P (to 150) instead of lpe200;
* ``ionosphere``: a Klobuchar-size S-band ionosphere (:mod:`odpipe.analysis.klobuchar`) in the media
  correction, where the nightly has none;
* ``troposphere``: the DSN seasonal troposphere 2 % larger (about 5 cm at zenith);
* ``srp``: Cr*A 50 % larger (its scale is estimated, sigma 0.5).

    nice .venv/bin/python benchmarks/grail_error_budget.py --base out/grail_loo/base [--terms field_glgm3,...]

Needs the base variant's runs (``benchmarks/grail_loo.py``); two fits of 2-3 min per term.
"""

from __future__ import annotations

import argparse
import os
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pandas as pd

import odpipe.pipeline.run as pipeline_run
from grail_arcs import PAIRS, run_variant, trajectory
from odpipe.analysis.error_budget import earth_elevation_deg, formal_sigma, term_contribution
from odpipe.environment.ephemeris import Ephemeris
from odpipe.analysis.klobuchar import KlobucharIonosphere
from odpipe.analysis.overlap import compare
from odpipe.media.model import MediaModel

GRAVITY = Path(__file__).resolve().parents[2] / "shared" / "data" / "gravity"
TROPOSPHERE_SCALE = 1.02


class _ScaledTroposphere(MediaModel):
    def troposphere(self, *args, **kwargs):
        delay, label = super().troposphere(*args, **kwargs)
        return delay * TROPOSPHERE_SCALE, label


def _with_klobuchar(calibrations, ionex, *args):
    """The run's media model (its arguments as ``odpipe run`` passes them) with a Klobuchar ionosphere where
    the run has no IONEX maps."""
    return MediaModel(calibrations, ionex if ionex is not None else KlobucharIonosphere(), *args)


# name -> (config overrides, media model class used by the run or None)
TERMS = {
    "field_glgm3": ({"dynamics.gravity.file": f'"{GRAVITY / "tudat" / "glgm3150.txt"}"'}, None),
    "ionosphere": ({}, _with_klobuchar),
    "troposphere": ({}, _ScaledTroposphere),
    "field_lp165p": ({"dynamics.gravity.file": f'"{GRAVITY / "gmat" / "LP165P.cof"}"'}, None),
    "srp": ({"dynamics.srp.cr_area": "7.5"}, None),
}


@contextmanager
def _media(model):
    saved = pipeline_run.MediaModel
    pipeline_run.MediaModel = model or saved
    try:
        yield
    finally:
        pipeline_run.MediaModel = saved


def geometry(base: Path) -> pd.DataFrame:
    """Per overlap of the nightly arcs: the Earth's elevation above the orbit plane at its middle, the
    overlap seen and the formal sigma, R/I/C (m)."""
    eph, rows = Ephemeris.open("de421"), []
    for a, b in PAIRS:
        oa, ob = (base / n / "current" / "trajectory.oem" for n in (a, b))
        if not (oa.exists() and ob.exists()):
            continue
        s = compare(trajectory(base, a), trajectory(base, b), "", 60.0).statistics()
        mid = 0.5 * (s["t_start_tdb"] + s["t_end_tdb"])
        row = {"overlap": f"{a[-5:]} - {b[-5:]}", "earth_above_plane_deg": float(earth_elevation_deg(
            trajectory(base, a), eph, np.array([mid]))[0])}
        row |= {f"seen_{c}": s[f"pos_{c}_rms"] for c in ("radial", "intrack", "crosstrack", "3d")}
        row |= {f"formal_{c}": v for c, v in formal_sigma(oa, ob).items()}
        rows.append(row)
    return pd.DataFrame(rows)


def variant_terms(base: Path, variants) -> pd.DataFrame:
    """Contributions to every nightly overlap of settings changed in leave-one-out variants (folders beside
    ``base``, e.g. the field to degree 100, other stochastic accelerations): (A' - A) - (B' - B), R/I/C (m)."""
    rows = []
    for v in variants:
        for a, b in PAIRS:
            runs = [base.parent / v / n / "current" / "trajectory.oem" for n in (a, b)]
            if all(r.exists() for r in runs) and all((base / n / "current").exists() for n in (a, b)):
                rows.append({"term": v, "overlap": f"{a[-5:]} - {b[-5:]}", **term_contribution(
                    trajectory(base, a), trajectory(base, b), trajectory(base.parent / v, a),
                    trajectory(base.parent / v, b))})
    return pd.DataFrame(rows)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=Path, default=Path("out/grail_loo/base"))
    ap.add_argument("--out", type=Path, default=Path("out/grail_budget"))
    ap.add_argument("--pair", default="grail_b_2012_04_10,grail_b_2012_04_11")
    ap.add_argument("--terms", default=",".join(TERMS))
    ap.add_argument("--variants", default="", help="leave-one-out variants beside --base to difference (no fits)")
    args = ap.parse_args(argv)
    base, out = args.base.resolve(), args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    geo = geometry(base)
    geo.to_csv(out / "geometry.csv", index=False)
    print(geo.round(2).to_string(index=False), flush=True)
    if args.variants:
        terms = variant_terms(base, args.variants.split(","))
        terms.to_csv(out / "variant_terms.csv", index=False)
        print(terms.round(2).to_string(index=False), flush=True)
        return
    a, b = args.pair.split(",")
    source = "grail_b_2012_04_09" if a == "grail_b_2012_04_10" else None
    rows = []
    seen = compare(trajectory(base, a), trajectory(base, b), "", 60.0).statistics()
    rows.append({"term": "overlap seen", "radial": seen["pos_radial_rms"], "intrack": seen["pos_intrack_rms"],
                 "crosstrack": seen["pos_crosstrack_rms"], "3d": seen["pos_3d_rms"]})
    rows.append({"term": "formal (data noise + stochastic accelerations)",
                 **formal_sigma(base / a / "current" / "trajectory.oem", base / b / "current" / "trajectory.oem")})
    for term in args.terms.split(","):
        overrides, media = TERMS[term]
        folder = out / term
        if source is not None and not (folder / source).exists():
            folder.mkdir(parents=True, exist_ok=True)
            os.symlink(base / source, folder / source)
        with _media(media):
            result = run_variant(folder, overrides, base.parent / "start", arcs=(a, b))
        if all(isinstance(r, dict) for r in result.values()):
            rows.append({"term": term, **term_contribution(trajectory(base, a), trajectory(base, b),
                                                           trajectory(folder, a), trajectory(folder, b))})
        else:
            rows.append({"term": term, "failed": "; ".join(str(r) for r in result.values())})
        table = pd.DataFrame(rows)
        table.to_csv(out / f"budget_{a[-5:]}_{b[-5:]}.csv", index=False)
        print(table.round(2).to_string(index=False), flush=True)


if __name__ == "__main__":
    main()
