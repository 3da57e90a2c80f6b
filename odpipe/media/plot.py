"""Per-pass media delay plot (PNG) for the report."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from parsers.atomic import save_figure  # noqa: E402


def plot_pass_delays(table: pd.DataFrame, pass_id: int, path) -> Path:
    """Troposphere, ionosphere and total correction (m) of one calibrated pass against UTC; returns the PNG path."""
    rows = table[table["pass_id"] == pass_id].sort_values("epoch")
    if rows.empty:
        raise ValueError(f"no rows in pass {pass_id}")
    fig, ax = plt.subplots(figsize=(8, 4))
    for col, style in (("tropo_m", "-"), ("iono_m", "--"), ("media_m", ":")):
        ax.plot(rows["epoch"], rows[col], style, label=col)
    unit = "m change over count" if str(rows["observable"].iloc[0]).startswith("doppler") else "m"
    ax.set_ylabel(unit)
    ax.set_xlabel("UTC")
    ax.set_title(f"pass {pass_id}: {rows['station_rx'].iloc[0]} {rows['observable'].iloc[0]}")
    ax.legend()
    ax.grid(True, alpha=0.3)
    note = "; ".join(sorted({p for v in rows["media_note"] for p in str(v).split("; ") if p}))
    if note:
        fig.text(0.01, 0.01, note, fontsize=7)
    fig.autofmt_xdate()
    path = Path(path)
    save_figure(path, fig, dpi=100)
    plt.close(fig)
    return path
