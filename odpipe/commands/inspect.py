"""``odpipe inspect``: what is in a tracking file - format, span, counts, ramps, anomalies."""

from __future__ import annotations

import importlib
import logging

import pandas as pd

from parsers import formats
from parsers.errors import ParseReport
from parsers.table import TrackingData
from odpipe.errors import Exit, describe
from odpipe.commands._inputs import read_table
from odpipe.tracking import ramp_segments
from odpipe.preprocess.edit import duplicates, invalid
from odpipe.tracking.passes import assign_passes

NAME = "inspect"
HELP = "detect a file's format and summarize its contents and anomalies"
SHOWN_ERRORS = 5

_log = logging.getLogger(__name__)


def add_arguments(parser) -> None:
    parser.add_argument("files", nargs="+", help="tracking files (any readable format) or TrackingTable Parquet")


def _counts(table: pd.DataFrame, col: str) -> str:
    c = table[col].replace("", "-").value_counts().sort_index()
    return ", ".join(f"{k} {v}" for k, v in c.items())


def tracking_summary(data: TrackingData) -> list[str]:
    """Lines describing a TrackingData."""
    t = data.table
    out = [f"rows: {len(t)}"]
    if len(t):
        out.append(f"span: {t['epoch'].min()} .. {t['epoch'].max()} UTC")
        for col in ("observable", "station_tx", "station_rx", "spacecraft", "band_up", "band_down", "tag"):
            out.append(f"{col}: {_counts(t, col)}")
        ct = t.loc[t["count_time"] > 0, "count_time"].value_counts().sort_index()
        out.append("count times (s): " + (", ".join(f"{k:g} x{v}" for k, v in ct.items()) or "none"))
        out.append(f"ramped rows: {int(t['ramped'].sum())}")
        out.append(f"passes: {assign_passes(t, data.ramps)['pass_id'].nunique()}")
        out.append(f"rows the format marks invalid: {int(invalid(t).sum())}")
        out.append(f"duplicate samples: {int(duplicates(t).sum())}")
    rs = ramp_segments.store(data.ramps)
    if rs is not None:
        per = rs.segments.groupby("station").size()
        out.append("ramps: " + ", ".join(f"{k} {v}" for k, v in per.items()))
        kinds = rs.findings["kind"].value_counts()
        out.append("ramp findings: " + (", ".join(f"{k} {v}" for k, v in kinds.items()) or "none"))
    return out


def report_lines(report: ParseReport) -> list[str]:
    """The reader's skipped records, the first few spelled out."""
    lines = [f"unreadable records: {len(report)}"]
    lines += [f"  {e}" for e in list(report)[:SHOWN_ERRORS]]
    if len(report) > SHOWN_ERRORS:
        lines.append(f"  ... {len(report) - SHOWN_ERRORS} more")
    return lines


def summarize(path) -> list[str]:
    """Lines describing one file."""
    if str(path).endswith(".parquet"):
        table, ramps = read_table(path)
        return ["format: TrackingTable Parquet"] + tracking_summary(TrackingData(table, ramps))
    name = formats.detect(path)
    if name is None:
        raise formats.unrecognised(path)
    report = ParseReport()
    mod = importlib.import_module(name)
    if hasattr(mod, "describe"):  # a reader of something other than tracking data (CPF, SINEX)
        return [f"format: {name}"] + mod.describe(path)
    if name == "parsers.maneuvers":
        df = mod.read(path, errors="report", report=report)
        lines = [f"format: {name}", f"rows: {len(df)}"]
        if len(df):
            lines.append(f"span: {df['epoch'].min()} .. {df['epoch'].max()} UTC")
        if "kind" in df:
            lines.append("kinds: " + ", ".join(f"{k} {v}" for k, v in df["kind"].value_counts().items()))
        return lines + report_lines(report)
    data = mod.read(path, errors="report")
    note = []
    if data.meta.get("format") == "TDM":   # summarized as a run reads it: received frequencies as DSN Doppler
        from odpipe.products.tdm import doppler_from_tdm

        n_lines = len(data.table)
        data, left = doppler_from_tdm(data)
        note = [f"TDM lines: {n_lines}; shown as a run reads them: RECEIVE_FREQ_n as DSN Doppler, TRANSMIT_FREQ "
                f"lines as ramps" + (f", {left} RECEIVE_FREQ rows without a reference left as received frequency"
                                     if left else "")]
    return [f"format: {name}"] + note + tracking_summary(data) + report_lines(data.report)


def run(args) -> int:
    """Summaries on stdout; a file that cannot be read or recognised is one error line on stderr
    (the others are still summarized) and makes the status Exit.INPUT."""
    failed = 0
    for path in args.files:
        try:
            lines = summarize(path)
        except Exception as exc:
            code, line = describe(exc)
            if code == Exit.INTERNAL:
                raise
            failed += 1
            _log.error(line)
            continue
        print(f"== {path}")
        print("\n".join(lines))
    return Exit.INPUT if failed else Exit.OK
