"""UTDF tables built from coded string columns (parsers.table.build/coded) without aliasing.

The UTDF reader gives its string columns as integer codes into a few labels; these
tests check the expanded strings against the record fields (pad ids, SIC, band code)
and that the table owns its arrays.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from parsers import table as tt
from parsers import utdf

LSUTDF = "utdf/LSUTDF_367501_119_2019_044_1555.trk"


@pytest.mark.realdata
def test_string_columns_follow_the_record_fields(shared_data):
    d = utdf.read(shared_data / LSUTDF)
    t, rec = d.table, d.meta["records"]
    str_dtype = pd.Series(["x"]).dtype
    for name in ("tag", "observable", "unit", "station_tx", "station_rx", "spacecraft", "band_up", "band_down",
                 "source"):
        assert t[name].dtype == str_dtype, name
    r = rec.loc[t["record"]]
    two_way = (r["transmit_freq_10hz"] > 0).to_numpy()
    assert (t["station_rx"].to_numpy() == ("PAD-" + r["rx_pad"].astype(str)).to_numpy()).all()
    assert (t["station_tx"].to_numpy() == np.where(two_way, "PAD-" + r["tx_pad"].astype(str), "")).all()
    assert (t["spacecraft"] == "3675").all()  # SIC 3675 (file name LSUTDF_367501_...)
    assert set(t["band_down"]) == {"S"} and set(t.loc[two_way, "band_up"]) == {"S"}  # band code 3
    unit_of = {"range": "s", "doppler_2way": "Hz", "doppler_1way": "Hz", "angle_az": "rad", "angle_el": "rad"}
    assert (t["unit"] == t["observable"].map(unit_of)).all()
    assert ((t["tag"] == "interval_end") == t["observable"].str.startswith("doppler")).all()


def test_coded_labels_may_repeat_and_missing_codes_give_empty():
    codes = np.array([2, 0, 1, 2, 3])
    col = tt.coded(codes, ["a", "b", "a", ""])
    t = tt.build(5, station_rx=col, tag=pd.Categorical.from_codes([0, -1, 0, -1, 0], ["receive"]), unit="Hz")
    assert t["station_rx"].tolist() == ["a", "a", "b", "a", ""]
    assert t["tag"].tolist() == ["receive", "", "receive", "", "receive"]
    assert t["unit"].tolist() == ["Hz"] * 5 and t["source"].tolist() == [""] * 5
    with pytest.raises(ValueError):
        tt.build(4, station_rx=col)


def test_build_copies_caller_arrays_and_build_owned_no_column_aliases_another():
    x = np.arange(4.0)
    t = tt.build(4, value=x, extra=x)
    t.loc[0, "value"] = 99.0
    assert x[0] == 0.0 and t.loc[0, "extra"] == 0.0
    y = np.arange(4.0)
    frozen = np.arange(4.0)
    frozen.flags.writeable = False
    t = tt.build_owned(4, value=y, sigma=y, count_time=frozen, uplink_hz=y[::-1])
    assert np.shares_memory(t["value"].to_numpy(), y)  # taken over, not copied
    t.loc[0, "value"] = 99.0
    assert t.loc[0, "sigma"] == 0.0  # the second use of y was copied
    t.loc[1, "count_time"] = t.loc[2, "uplink_hz"] = 7.0  # read-only input and a view were copied
    assert frozen[1] == 1.0 and y[1] == 1.0
