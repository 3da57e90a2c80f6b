"""TRK-2-23 reader: cards of the real Cassini .TRO/.ION files, evaluated by hand from their text."""

import numpy as np
import pytest

from parsers.errors import ParseError, ParseReport
from parsers.trk223 import CalibrationSet, complex_of, parse_text, read_trk223


def T(s):
    return np.datetime64(s, "ns")


@pytest.mark.realdata
def test_first_tro_card_evaluated_by_hand(shared_data):
    cs = read_trk223(shared_data / "cassini" / "S18TIGE2006_032_2006_059.TRO")
    assert len(cs) == 336
    # File line 2-4: ADJUST(ALL)BY NRMPOW(0.0078, 0.0131, -0.0451, -0.0315, 0.1334, 0.0473, -0.1519,
    # -0.0463, 0.0539, 0.0174) MODEL(WET NUPART) FROM(06/02/01,06:00:00.001) TO(06/02/01,18:00:00) DSN(C10)
    c = [0.0078, 0.0131, -0.0451, -0.0315, 0.1334, 0.0473, -0.1519, -0.0463, 0.0539, 0.0174]
    t0, t1 = 6 * 3600 + 0.001, 18 * 3600.0
    for sec in (t0, 9 * 3600.0, 12 * 3600.0 + 0.0005, 16 * 3600.0 + 1234.5, t1):
        x = 2 * (sec - t0) / (t1 - t0) - 1
        expected = 0.0
        for ci in reversed(c):                      # Horner, independent of the reader
            expected = expected * x + ci
        t = T("2006-02-01") + np.timedelta64(int(round(sec * 1e6)), "us")
        assert cs.zenith_delay("C10", t, "wet")[0] == pytest.approx(expected, abs=1e-12)
        assert cs.zenith_delay("DSS-14", t, "wet")[0] == pytest.approx(expected, abs=1e-12)
    assert cs.zenith_delay("C10", T("2006-02-01T12:00:00.0005"), "wet")[0] == pytest.approx(0.0078)
    assert cs.zenith_delay("C10", T("2006-02-01T18:00:00"), "wet")[0] == pytest.approx(sum(c))
    # FITSIG comment before the card is kept as its fit sigma (m)
    assert cs.cards[0].fitsig == pytest.approx(0.0012617)


@pytest.mark.realdata
def test_cards_outside_their_windows_are_never_used(shared_data):
    cs = read_trk223(shared_data / "cassini" / "S18TIGE2006_032_2006_059.TRO")
    # first card starts 06:00:00.001: one millisecond earlier nothing covers -> NaN, not 0
    assert np.isnan(cs.zenith_delay("C10", T("2006-02-01T06:00:00.000"), "dry")[0])
    # the next window (18:00:00.001 .. 06:00) takes over exactly after the first ends
    v, used = cs.evaluate("DRY NUPART", "DSS-25", np.array([T("2006-02-01T18:00:00"), T("2006-02-01T18:00:00.001")]))
    assert used[0] != used[1] and cs.cards[used[1]].line > cs.cards[used[0]].line
    # DRY card of C10 at 18:00:00.001: NRMPOW(-0.0174, ...) starts at x = -1
    c = cs.cards[used[1]].coefficients
    assert c[0] == -0.0174 and v[1] == pytest.approx(sum(ci * (-1.0) ** i for i, ci in enumerate(c)))


@pytest.mark.realdata
def test_const_cards_and_station_lists(shared_data):
    cs = read_trk223(shared_data / "cassini" / "S18TIGE2006_060_2006_080.TRO")
    # ADJUST(ALL)BY CONST(-0.0266) MODEL(WET NUPART)FROM(06/03/21,14:55:00.001)TO(06/03/26,00:00:00)DSN(C10)
    assert cs.zenith_delay("DSS-24", T("2006-03-23T07:00"), "wet")[0] == pytest.approx(-0.0266)
    # ... CONST(-0.0360) MODEL(DRY NUPART) ... DSN(C60)
    assert cs.zenith_delay("DSS-65", T("2006-03-25T23:59"), "dry")[0] == pytest.approx(-0.0360)
    assert np.isnan(cs.zenith_delay("DSS-65", T("2006-03-26T00:00:00.001"), "dry")[0])


@pytest.mark.realdata
def test_ion_card_line_of_sight_by_spacecraft_and_kind(shared_data):
    ci = read_trk223(shared_data / "cassini" / "S18TIGE2006_032_2006_059.ION")
    # ADJUST(DOPRNG)BY NRMPOW(0.7299, -0.0158, 0.5110, 1.2647, -2.0732, -1.0317, 4.6910, 0.1773, -2.4048)
    # MODEL(CHPART) FROM(06/02/01,00:50)TO(06/02/01,14:41)DSN(C10)SCID(82): at mid-window x = 0 -> 0.7299
    mid = T("2006-02-01T00:50") + (T("2006-02-01T14:41") - T("2006-02-01T00:50")) / 2
    assert ci.line_of_sight("DSS-14", 82, mid, "range")[0] == pytest.approx(0.7299)
    assert ci.line_of_sight("DSS-14", "82", mid, "doppler")[0] == pytest.approx(0.7299)
    assert np.isnan(ci.line_of_sight("DSS-14", 99, mid)[0])          # another spacecraft
    assert np.isnan(ci.line_of_sight("DSS-43", 82, T("2006-02-01T03:00"))[0])  # C40 starts 08:59


def test_trig_series_and_additive_cards():
    text = ("ADJUST(DOPRNG) BY TRIG(86400., 2.0, 0.1, 0.05) MODEL(DRY NUPART) FROM(72/01/01,00:00) DSN(C40).\n"
            "ADJUST(ALL) BY CONST(0.25) MODEL(DRY NUPART) FROM(06/01/01,00:00) TO(06/01/02,00:00) DSN(43).\n")
    cs = CalibrationSet(parse_text(text))
    t = T("2006-01-01T06:00")                                   # quarter day: w = pi/2 past a whole day
    days = (t - T("1972-01-01")) / np.timedelta64(1, "s") / 86400.0
    w = 2 * np.pi * days
    trig = 2.0 + 0.1 * np.cos(w) + 0.05 * np.sin(w)
    assert trig == pytest.approx(2.05)
    assert cs.zenith_delay("DSS-43", t)[0] == pytest.approx(2.30)       # both cards add
    assert cs.zenith_delay("DSS-34", t)[0] == pytest.approx(2.05)       # station list excludes 34
    assert cs.cards[0].data_types == ("range", "doppler")


@pytest.mark.parametrize("card, words", [
    ("ADJUST(ALL) BY NRMPOW(0.1, x2) MODEL(DRY NUPART) FROM(06/01/01,00:00) TO(06/01/02,00:00) DSN(C10).",
     "coefficient"),
    ("ADJUST(ALL) BY SPLINE(0.1) MODEL(DRY NUPART) FROM(06/01/01,00:00) TO(06/01/02,00:00) DSN(C10).", "SPLINE"),
    ("ADJUST(ALL) BY NRMPOW(0.1) MODEL(DRY NUPART) FROM(06/01/01,00:00) DSN(C10).", "FROM and TO"),
    ("ADJUST(ALL) BY CONST(0.1) MODEL(DRY NUPART) FROM(06/13/01,00:00) TO(06/01/02,00:00) DSN(C10).", "month"),
    ("ADJUST(ALL) BY CONST(0.1) MODEL(HOT NUPART) FROM(06/01/01,00:00) TO(06/01/02,00:00) DSN(C10).", "model"),
])
def test_malformed_cards_raise_with_line(card, words):
    text = "# FITSIG= .001\nADJUST(ALL) BY CONST(0.1) MODEL(WET NUPART) FROM(06/01/01,00:00)\n" \
           "  TO(06/01/02,00:00) DSN(C10).\n" + card + "\n"
    with pytest.raises(ParseError) as info:
        parse_text(text, "bad.TRO")
    assert info.value.line == 4 and info.value.record == 1 and "bad.TRO" in str(info.value)
    assert words in str(info.value)
    report = ParseReport()
    assert len(parse_text(text, "bad.TRO", errors="report", report=report)) == 1 and len(report) == 1


def test_complex_of_station():
    assert [complex_of(s) for s in ("DSS-14", "25", 34, "DSS-43", "DSS-65", "C60", "BRKS")] == \
        ["C10", "C10", "C40", "C40", "C60", "C60", ""]


_CARD = ("ADJUST(ALL)BY CONST(0.002)MODEL(DRY NUPART)FROM(06/02/01,00:00)TO(06/02/02,00:00)DSN(C10).\n")


@pytest.mark.parametrize("fitsig", [".", "1e400", "nan", "", "9" * 5000])
def test_bad_fitsig_is_a_parse_error_and_reported(tmp_path, fitsig):
    p = tmp_path / "bad.tro"
    p.write_text(f"# FITSIG= {fitsig}\n{_CARD}# FITSIG= .0012\n{_CARD}")
    with pytest.raises(ParseError) as err:
        read_trk223(p)
    assert err.value.line == 1 and "FITSIG" in err.value.reason
    report = ParseReport()
    cs = read_trk223(p, errors="report", report=report)
    assert [e.line for e in report] == [1]
    assert np.isnan(cs.cards[0].fitsig) and cs.cards[1].fitsig == 0.0012  # both cards kept


@pytest.mark.parametrize("coef", ["1e400", "nan", "-inf"])
def test_non_finite_coefficient_is_a_parse_error(tmp_path, coef):
    p = tmp_path / "bad.tro"
    p.write_text(_CARD.replace("0.002", coef))
    with pytest.raises(ParseError, match="finite"):
        read_trk223(p)


@pytest.mark.parametrize("text", [b"", b"  \n", b"# FITSIG= .001\n", b"\xff" + _CARD.encode()])
def test_empty_or_not_ascii_is_a_parse_error_in_both_modes(tmp_path, text):
    p = tmp_path / "x.tro"
    p.write_bytes(text)
    for mode in ("raise", "report"):
        with pytest.raises(ParseError):
            read_trk223(p, errors=mode, report=ParseReport())


def test_long_word_in_the_scope_is_refused_in_linear_time(tmp_path):
    # found by benchmarks/bench_fuzz.py: a 200,000-letter word after a card hung the scope parser (quadratic)
    import time
    p = tmp_path / "long.tro"
    p.write_text(_CARD[:-2] + " " + "A" * 200_000 + ").\n")
    t = time.process_time()
    with pytest.raises(ParseError, match="unreadable scope"):
        read_trk223(p)
    assert time.process_time() - t < 1.0
