"""The parameter tables of a run report: each row at the precision its sigma carries."""

import re

import pandas as pd

from odpipe.operations.report import html_table
from odpipe.products.parameters import report_tables


def _cells(params):
    return {caption.split(" (")[0]: re.findall(r"<td>([^<]*)</td>", html_table(t, f))
            for caption, t, f in report_tables(params)}


def test_each_row_to_its_sigmas_second_digit_never_finer_than_the_group():
    params = pd.DataFrame({
        "name": ["x", "y", "vx", "bias.range.DSS-14", "srp_scale", "cd", "emp[0].R", "181.osc_y0"],
        "kind": ["state", "state", "state", "bias", "dynamic", "dynamic", "stochastic", "clock"],
        "apriori": [1737123.4567, 2.5, 1620.123456, 0.0, 1.0, 2.2, 0.0, 0.0],
        "estimate": [1737150.98765, 2.71828, 1620.0012345, 1.23456, 1.0234567, 2.2, 1.2345e-9, 3.4567e-12],
        "sigma": [68.3, 0.25, 0.0234, 0.0004, 0.0123, 1.2e-9, 3e-10, 1.6e-12]})
    cells = _cells(params)
    # a priori, estimate, change, sigma per row: a 68-m sigma gives metres, 0.25 m gives cm, 0.4 mm stops at the mm
    assert cells["positions, station coordinates and range biases"] == [
        "1737123", "1737151", "28", "68", "2.50", "2.72", "0.22", "0.25", "0.000", "1.235", "1.235", "0.00040"]
    assert cells["velocities"] == ["1620.123", "1620.001", "-0.122", "0.023"]
    # a sigma far below the group's resolution in powers of ten, not fourteen decimals
    assert cells["scale factors"] == ["1.000", "1.023", "0.023", "0.012", "2.20000", "2.20000", "0.00000", "1.2e-09"]
    assert cells["fractional frequency offsets"] == ["0", "3.457e-12", "3.457e-12", "1.6e-12"]
    assert cells["stochastic and polynomial accelerations"] == ["0", "1.235e-09", "1.235e-09", "3e-10"]


def test_a_zero_sigma_keeps_the_groups_resolution():
    params = pd.DataFrame({"name": ["x"], "kind": ["state"], "apriori": [1.0], "estimate": [1.23456], "sigma": [0.0]})
    assert _cells(params)["positions, station coordinates and range biases"] == ["1.000", "1.235", "0.235", "0.000"]
