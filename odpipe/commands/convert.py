"""``odpipe convert``: any readable tracking file to Parquet or CCSDS TDM."""

from __future__ import annotations

from pathlib import Path

NAME = "convert"
HELP = "convert a tracking file to TrackingTable Parquet (.parquet) or CCSDS TDM (.tdm/.kvn KVN, .xml XML)"
TDM_SYNTAX = {".tdm": "kvn", ".kvn": "kvn", ".xml": "xml"}


def add_arguments(parser) -> None:
    parser.add_argument("input", help="tracking file in any readable format, or TrackingTable Parquet")
    parser.add_argument("-o", "--output", required=True, help="OUT.parquet, OUT.tdm, OUT.kvn or OUT.xml")
    parser.add_argument("--errors", choices=("raise", "report"), default="raise",
                        help="on a corrupt record: stop, or skip it and report")


def load(path, errors: str = "raise") -> TrackingData:
    """TrackingData from a TrackingTable Parquet file or any file a reader recognises."""
    from odpipe.commands._inputs import read_table   # the readers' imports: not for `odpipe convert --help`
    from parsers import formats
    from parsers.table import TrackingData

    if str(path).endswith(".parquet"):
        return TrackingData(*read_table(path))
    data = formats.read_any(path, errors=errors)
    if not isinstance(data, TrackingData):
        raise ValueError(f"{path} is not tracking data")
    return data


def run(args) -> int:
    suffix = Path(args.output).suffix.lower()
    if suffix != ".parquet" and suffix not in TDM_SYNTAX:
        raise ValueError(f"{args.output}: cannot write {suffix!r} files: name OUT.parquet, OUT.tdm, OUT.kvn or OUT.xml")
    from odpipe.preprocess import store

    data = load(args.input, args.errors)  # a ParseError, or a file with no tracking data: the CLI's one line
    if suffix == ".parquet":
        if data.meta.get("format") == "TDM":   # the fit's observables: Doppler, the ramps beside the table
            from odpipe.products.tdm import doppler_from_tdm

            data, left = doppler_from_tdm(data)
            if left:
                print(f"{left} RECEIVE_FREQ rows kept as received frequency (no reference to make Doppler of)")
        written = store.write(args.output, data.table, data.ramps)
    else:
        from odpipe.products.tdm import to_tdm
        from parsers import tdm

        if "segments" not in data.meta:  # not read from a TDM: map the table onto TDM keywords
            data, skipped = to_tdm(data)
            if len(skipped):
                print(f"not written (no TDM keyword, or no value): {skipped['observable'].value_counts().to_dict()}")
        tdm.write(args.output, data, syntax=TDM_SYNTAX[suffix])
        written = [args.output]
    print(f"{_counts(data.table)} -> {', '.join(map(str, written))}; {len(data.report)} records reported unreadable")
    return 0


def _counts(table) -> str:
    """'N rows', or for TDM data lines 'N rows (M observations, K ramp lines)': a TDM holds the uplink's ramps
    as TRANSMIT_FREQ/TRANSMIT_FREQ_RATE lines beside the observations."""
    if "keyword" not in table.columns:
        return f"{len(table)} rows"
    ramp = int(table["keyword"].astype(str).str.startswith("TRANSMIT_FREQ").sum())
    return f"{len(table)} rows ({len(table) - ramp} observations, {ramp} ramp lines)"
