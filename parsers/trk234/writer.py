"""Writing TRK-2-34 files: fresh record blocks with consistent headers, and the file itself."""

from __future__ import annotations

import numpy as np

from parsers.atomic import write_bytes
from parsers.table import TrackingData
from parsers.trk234 import layout
from parsers.trk234.sfdu import Block, join

# Header values the writer puts in new SFDUs. The reader checks only the label
# ("NJPL", data description id, length) and the format code, not these CHDO types.
AGG_CHDO_TYPE, PRI_CHDO_TYPE, TRK_CHDO_TYPE = 1, 2, 10
SEC_CHDO_TYPE = {"C123": 132, "C124": 133, "C125": 134, "C126": 135, "C127": 136}
MAJOR_DATA_CLASS, MINOR_DATA_CLASS = 6, 14


def new_block(format_code: int, n: int, n_obs: int = 0, index=None, **fields) -> Block:
    """``n`` zeroed SFDUs of ``format_code`` with label and CHDO headers filled in.

    ``fields`` set any other field by name (arrays of length n or scalars); ``obs`` takes
    a structured array of shape (n, n_obs) for formats 16/17. ``index`` gives the order
    of the SFDUs in the file (default 0..n-1).
    """
    dt = layout.dtype(format_code, n_obs)
    ddid = layout.CLASS_OF_FORMAT[format_code]
    total = dt.itemsize
    r = np.zeros(n, dtype=dt)
    r["control_auth_id"], r["sfdu_version_id"], r["sfdu_class_id"] = b"NJPL", b"2", b"I"
    r["label_spare"] = np.frombuffer(b"00", dtype="V2")[0]
    r["data_description_id"] = ddid.encode()
    r["sfdu_length"] = total - layout.LABEL_BYTES
    r["agg_chdo_type"], r["agg_chdo_length"] = AGG_CHDO_TYPE, total - 24
    r["pri_chdo_type"], r["pri_chdo_length"] = PRI_CHDO_TYPE, 4
    r["mjr_data_class"], r["mnr_data_class"], r["format_code"] = MAJOR_DATA_CLASS, MINOR_DATA_CLASS, format_code
    sec_bytes = layout.secondary_bytes(ddid)
    r["sec_chdo_type"], r["sec_chdo_length"] = SEC_CHDO_TYPE[ddid], sec_bytes - 4
    r["trk_chdo_type"] = TRK_CHDO_TYPE
    r["trk_chdo_length"] = total - layout.HEADER_BYTES - sec_bytes - 4
    if format_code in layout.REPEATED:
        r["num_obs"] = n_obs
    for name, value in fields.items():
        r[name] = value
    return Block(format_code, r, np.arange(n) if index is None else np.asarray(index, np.int64))


def write(path, blocks: list[Block] | TrackingData) -> None:
    """Write ``blocks`` (or a TrackingData's ``meta["blocks"]``) as one TRK-2-34 file, SFDUs in ``index`` order."""
    data = join(blocks.meta["blocks"] if isinstance(blocks, TrackingData) else blocks)
    write_bytes(path, data)
