"""The twin's media calibrations against real TRK-2-23 files (issue #25): the simulated deviations have the
scatter of the real Cassini .TRO/.ION cards (2006), and the calibration errors their median FITSIG.

Measured (the four Cassini files in shared/data): zenith wet deviation 3.69 cm RMS, dry 2.27 cm, S-band
line-of-sight ionosphere 1.39 m; median FITSIG wet 1.25 mm, dry 0.25 mm, ionosphere 2.1 cm.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.stats import chi2

from odpipe.simulate.calibrations import QUADRATIC_RMS, ion_text, tro_text
from odpipe.simulate.case import load
from parsers.trk223 import CalibrationSet, parse_text, read_trk223

TWIN = Path(__file__).resolve().parents[1] / "runs" / "artemis_p2_twin.toml"
MODELS = {"wet": "WET NUPART", "dry": "DRY NUPART", "ion": "CHPART"}
# E[(1 + |N|)^2] = 2 + 2 sqrt(2/pi): the mean square of the ionosphere's c0 (odpipe.simulate.calibrations)
ION_RMS = np.sqrt(2 + 2 * np.sqrt(2 / np.pi) + (0.25 ** 2) * (1 / 3 + 1 / 5))


def _cards_rms(cards) -> tuple[float, float]:
    """(RMS over 25 points of each card's window of its values, median FITSIG) of cards (m)."""
    values = []
    for c in cards:
        t = c.start + (c.end - c.start) * np.linspace(0.0, 1.0, 25)
        kind = "doppler" if "range" not in c.data_types else "range"
        v, _ = CalibrationSet([c]).evaluate(c.model, c.network, t, spacecraft=None if c.scid < 0 else c.scid,
                                            kind=kind)
        values.append(v)
    v = np.concatenate(values)
    return float(np.sqrt(np.mean(v ** 2))), float(np.nanmedian([c.fitsig for c in cards]))


@pytest.fixture(scope="module")
def real(shared_data):
    files = sorted((shared_data / "cassini").glob("*.TRO")) + sorted((shared_data / "cassini").glob("*.ION"))
    cards = read_trk223(*files).cards
    return {k: _cards_rms([c for c in cards if c.model == m]) for k, m in MODELS.items()}


def test_twin_deviations_have_the_real_scatter(real):
    media = load(TWIN).media
    simulated = {"wet": media.sigma_wet_m * QUADRATIC_RMS, "dry": media.sigma_dry_m * QUADRATIC_RMS,
                 "ion": media.sigma_ion_m * ION_RMS}
    for k, (rms, _) in real.items():
        # 15 %: one season of one mission's cards against a simulated month; several-fold would fail
        assert abs(simulated[k] / rms - 1) < 0.15, (k, simulated[k], rms)


def test_twin_calibration_errors_are_the_real_fitsig(real):
    media = load(TWIN).media
    errors = {"wet": media.error_wet_m, "dry": media.error_dry_m, "ion": media.error_ion_m}
    for k, (_, fitsig) in real.items():
        assert abs(errors[k] / fitsig - 1) < 0.05, (k, errors[k], fitsig)   # rounded to 2-3 digits in the case


def test_true_delays_differ_from_the_written_cards_by_the_error():
    rng = np.random.default_rng(5)
    start = np.datetime64("2010-11-20T00:00:00", "ns")
    end = start + np.timedelta64(60, "D")
    written, true = tro_text(["DSS-24", "DSS-34", "DSS-54"], start, end, 0.03, 0.018, rng, 0.002, 0.0005)
    passes = [("DSS-24", start + np.timedelta64(k, "D"), start + np.timedelta64(k, "D") + np.timedelta64(4, "h"))
              for k in range(60)]
    ion_w, ion_t = ion_text(passes, 2, 0.73, rng, 0.021)
    for (w, t), model, error in (((written, true), "WET NUPART", 0.002), ((written, true), "DRY NUPART", 0.0005),
                                 ((ion_w, ion_t), "CHPART", 0.021)):
        cw = [c for c in parse_text(w) if c.model == model]
        ct = [c for c in parse_text(t) if c.model == model]
        assert all(abs(c.fitsig - error) < 5e-8 for c in cw)             # the written FITSIG states the error
        d = np.array([np.subtract(b.coefficients, a.coefficients) for a, b in zip(cw, ct)]).ravel()
        # coefficients ~ N(0, error / QUADRATIC_RMS), rounded to 0.1 mm on both sides (variance 2 x 1e-8/12)
        s2 = np.sum(d ** 2) / ((error / QUADRATIC_RMS) ** 2 + 2 * 1e-8 / 12)
        assert chi2.ppf(0.0005, d.size) < s2 < chi2.ppf(0.9995, d.size), (model, s2 / d.size)
