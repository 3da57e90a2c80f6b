import numpy as np

from parsers import ParseError, table


def test_build_fills_missing_values():
    df = table.build(2, epoch=np.array(["2012-04-08T00:00", "2012-04-08T00:01"], dtype="datetime64[ns]"),
                     observable="doppler_2way", value=[1.0, 2.0])
    table.validate(df)
    assert df["station_tx"].tolist() == ["", ""]
    assert df["record"].tolist() == [-1, -1]
    assert df["flags"].tolist() == [0, 0]  # rows are used until an editor flags them
    assert np.isnan(df["sigma"]).all()


def test_parse_error_names_the_place():
    err = ParseError("x.odf", "bad data type 99", offset=2016, record=7)
    assert str(err) == "x.odf, byte 2016, record 7: bad data type 99"


def test_parse_error_survives_pickling():
    import copy
    import pickle

    err = ParseError("x.odf", "bad data type 99", offset=2016, record=7)
    for back in (pickle.loads(pickle.dumps(err)), copy.deepcopy(err)):
        assert str(back) == str(err) and back.offset == 2016 and back.record == 7


def test_readers_refuse_an_unknown_errors_mode_before_reading(tmp_path):
    import pytest
    from parsers import odf, utdf

    missing = tmp_path / "not_read.bin"  # never opened: the mode is checked first
    for reader in (odf, utdf):
        with pytest.raises(ValueError, match="errors must be 'raise' or 'report'"):
            reader.read(missing, errors="skip")


def test_non_finite_values_are_flagged_invalid_and_repeated_samples_duplicate():
    from parsers import table as tt
    t = tt.build(4, epoch=np.array(["2020-01-01T00:00:00"] * 2 + ["2020-01-01T00:00:01"] * 2, "datetime64[ns]"),
                 observable="range", value=np.array([1.0, np.nan, np.inf, 1.0]), flags=np.array([0, 0, 32, 0]))
    assert t["flags"].tolist() == [0, tt.INVALID, tt.INVALID | 32, 0]
    tt.flag_duplicates(t)
    assert t["flags"].tolist() == [0, tt.INVALID | tt.DUPLICATE, tt.INVALID | 32, tt.DUPLICATE]
    from odpipe.preprocess.flags import Flag
    assert (Flag.INVALID, Flag.DUPLICATE) == (tt.INVALID, tt.DUPLICATE)
