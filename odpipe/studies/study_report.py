"""Study products: paper-vs-odpipe tables (CSV + Markdown) and convergence plots (PNG).

All files are written atomically into the run directory.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from parsers.atomic import save_figure, write_csv, write_text


def spread(ratios) -> dict:
    """The spread of odpipe/paper ratios over the choices a paper leaves open: min, median, max."""
    r = np.asarray(ratios, float).ravel()
    return {"ratio min": float(r.min()), "ratio median": float(np.median(r)), "ratio max": float(r.max())}


def _cell(v) -> str:
    if isinstance(v, (float, np.floating)):
        if not np.isfinite(v):
            return "-"
        return f"{v:.4g}" if abs(v) >= 1e-3 or v == 0 else f"{v:.3e}"
    return str(v)


def markdown_table(df: pd.DataFrame) -> str:
    """GitHub Markdown table of a DataFrame (floats to 4 significant digits, trailing zeros dropped; below 1e-3
    in powers of ten)."""
    lines = ["| " + " | ".join(map(str, df.columns)) + " |",
             "|" + "---|" * len(df.columns)]
    lines += ["| " + " | ".join(_cell(v) for v in row) + " |" for row in df.itertuples(index=False)]
    return "\n".join(lines) + "\n"


def write_table(out: Path, name: str, df: pd.DataFrame) -> str:
    """Write NAME.csv and return the Markdown rendering."""
    write_csv(Path(out) / f"{name}.csv", df, index=False)
    return markdown_table(df)


def write_markdown(out: Path, title: str, sections: list[tuple[str, str]]) -> Path:
    """report.md: a title and (heading, body) sections."""
    text = f"# {title}\n\n" + "\n".join(f"## {h}\n\n{b}\n" for h, b in sections)
    return write_text(Path(out) / "report.md", text)


def plot_convergence(out: Path, name: str, panels: list[dict], ylabel: str, ncols: int = 2) -> Path:
    """One log-scale panel per dict {title, t_days, curves: [(label, values, style)]}, ncols per row;
    a style's 't' overrides the panel's t_days for that curve, a panel's 'xlabel' the default "time (days)".
    Titles share the panel's width (about 70 characters at 5 in). The legend (of the first row's last panel)
    sits in that panel, or with more than 4 curves in a column of its own on the right, off the curves."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    nrows = -(-len(panels) // ncols)
    keyed = min(ncols, len(panels)) - 1                       # the panel whose curves the legend names
    side = 2.2 if len(panels[keyed]["curves"]) > 4 else 0.0   # inches: the legend's own column
    width, height = 5.0 * ncols + side, 3.3 * nrows
    fig, axes = plt.subplots(nrows, ncols, figsize=(width, height), squeeze=False)
    # fixed margins (inches: y label and ticks 0.8 left, tick labels 0.65 between columns, x label and the next
    # title 0.85 between rows) instead of a tight layout, which draws the whole figure once more before saving
    fig.subplots_adjust(left=0.8 / width, right=1.0 - (0.15 + side) / width, bottom=0.5 / height,
                        top=1.0 - 0.3 / height, wspace=0.65 / ((width - side - 0.95 - 0.65 * (ncols - 1)) / ncols),
                        hspace=0.85 / ((height - 0.8 - 0.85 * (nrows - 1)) / nrows))
    for ax, p in zip(axes.ravel(), panels):
        for label, y, style in p["curves"]:
            ax.semilogy(p["t_days"] if "t" not in style else style["t"], y,
                        **{k: v for k, v in style.items() if k != "t"}, label=label)
        for which in ("major", "minor"):
            getattr(ax.yaxis, f"set_{which}_formatter")(_plain_log_labels())
        ax.set_title(p["title"], fontsize=9)
        ax.set_xlabel(p.get("xlabel", "time (days)"))
        ax.grid(True, which="both", alpha=0.3)
    for row in axes:
        row[0].set_ylabel(ylabel)
    if side:
        axes.ravel()[keyed].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.03, 1.0), borderaxespad=0.0)
    else:
        axes.ravel()[keyed].legend(fontsize=7)
    for ax in axes.ravel()[len(panels):]:
        ax.set_visible(False)
    path = Path(out) / f"{name}.png"
    save_figure(path, fig, dpi=110)
    plt.close(fig)
    return path


def _plain_log_labels():
    """A log axis's tick labels as plain numbers (40, 0.5, 1e-05) on the ticks matplotlib labels, instead of
    its 4×10¹ (a panel spanning less than a decade labels its minor ticks too)."""
    from matplotlib.ticker import LogFormatterSciNotation

    class Plain(LogFormatterSciNotation):
        def __call__(self, x, pos=None):
            return f"{x:g}" if super().__call__(x, pos) else ""

    return Plain(labelOnlyBase=False)

