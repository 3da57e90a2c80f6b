"""Per-pass media delay plot (PNG) for the report."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from parsers.atomic import save_figure


def plot_pass_delays(table: pd.DataFrame, pass_id: int, path) -> Path:
    """Troposphere, ionosphere and total correction of one calibrated pass against UTC: range rows in m of
    delay, Doppler rows as the range-rate equivalent in mm/s (the delay's change over the count divided by
    the count time, :mod:`odpipe.media.apply`). A bare Agg figure with fixed margins (inches): the labels
    and the fallback note below the x axis never overlap. Returns the PNG path."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.dates import AutoDateLocator, DateFormatter, date2num
    from matplotlib.figure import Figure

    rows = table[table["pass_id"] == pass_id].sort_values("epoch")
    if rows.empty:
        raise ValueError(f"no rows in pass {pass_id}")
    doppler = str(rows["observable"].iloc[0]).startswith("doppler")
    scale = 1e3 / rows["count_time"].to_numpy(float) if doppler else 1.0
    fig = Figure(figsize=(8, 4.2))
    FigureCanvasAgg(fig)
    fig.subplots_adjust(left=1.0 / 8, right=0.97, top=1 - 0.4 / 4.2, bottom=0.95 / 4.2)
    ax = fig.subplots()
    t = date2num(rows["epoch"].to_numpy("datetime64[ns]"))
    for col, label, style in (("tropo_m", "troposphere", "-"), ("iono_m", "ionosphere", "--"),
                              ("media_m", "total", ":")):
        ax.plot(t, rows[col].to_numpy(float) * scale, style, label=label)
    ax.set_ylabel("range-rate correction (mm/s)" if doppler else "range delay (m)")
    ax.ticklabel_format(axis="y", useOffset=False)
    short = np.ptp(t) * 24 * 60 <= 20   # min: a short pass's ticks fall between whole minutes
    ax.xaxis.set_major_locator(AutoDateLocator(minticks=4, maxticks=8))   # whole minutes or seconds
    ax.xaxis.set_major_formatter(DateFormatter("%H:%M:%S" if short else "%H:%M"))   # the date: in the title
    ax.set_xlabel("time (UTC)")
    start = np.datetime64(rows["epoch"].iloc[0].to_datetime64(), "s")
    ax.set_title(f"pass {pass_id}: {rows['station_rx'].iloc[0]} {rows['observable'].iloc[0]}, from {start} UTC",
                 y=1.0)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    note = "; ".join(sorted({p for v in rows["media_note"] for p in str(v).split("; ") if p}))
    if note:
        fig.text(0.01, 0.1 / 4.2, note, fontsize=7)
    path = Path(path)
    save_figure(path, fig, dpi=100)
    return path
