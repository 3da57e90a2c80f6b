"""Solution: what a fit hands to products (estimates, covariances, residuals, history).

Arrays on ``grid`` (TDB s) hold absolute parameter values in registry order;
covariances are (K, n, n). ``residuals`` has one row per observation: ``time``,
``group``, ``prefit`` (observed - computed on the last iteration's reference),
``postfit`` (after the smoothed correction), ``innovation`` and
``innovation_sigma`` (filter prediction), ``sigma`` (weight used) and ``flags``.
"""

from __future__ import annotations

import hashlib
import io
import json
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

_ARRAYS = ("grid", "filtered_x", "filtered_P", "smoothed_x", "smoothed_P", "smoothed_P_consider")


def checksum(*arrays) -> str:
    """SHA-256 of the arrays' bytes (inputs fingerprint)."""
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


@dataclass
class Solution:
    names: list
    grid: np.ndarray
    filtered_x: np.ndarray
    filtered_P: np.ndarray
    smoothed_x: np.ndarray
    smoothed_P: np.ndarray
    smoothed_P_consider: np.ndarray
    residuals: pd.DataFrame
    history: list = field(default_factory=list)
    converged: bool = False
    inputs: dict = field(default_factory=dict)

    @property
    def x0(self) -> np.ndarray:
        """Smoothed parameter vector at the arc epoch."""
        return self.smoothed_x[0]

    @property
    def P0(self) -> np.ndarray:
        """Its covariance including consider-parameter effects."""
        return self.smoothed_P_consider[0]

    def parameters(self) -> pd.DataFrame:
        """Epoch estimate and sigma per parameter."""
        return pd.DataFrame({"name": self.names, "estimate": self.x0,
                             "sigma": np.sqrt(np.diag(self.P0))}).set_index("name")

    def states(self, spacecraft: str, smoothed: bool = True):
        """(grid, states (K, 6) m and m/s, covariances (K, 6, 6)) of one spacecraft."""
        idx = [self.names.index(f"{spacecraft}.{a}") for a in ("x", "y", "z", "vx", "vy", "vz")]
        x = self.smoothed_x if smoothed else self.filtered_x
        P = self.smoothed_P_consider if smoothed else self.filtered_P
        return self.grid, x[:, idx], P[:, idx][:, :, idx]

    def save(self, path) -> None:
        """Write atomically to one ``.npz`` (arrays, residual columns, history as JSON)."""
        from parsers.atomic import write_bytes

        meta = {"names": list(self.names), "history": self.history,
                "converged": self.converged, "inputs": self.inputs}
        cols = {f"res_{c}": _plain(self.residuals[c].to_numpy()) for c in self.residuals.columns}
        buf = io.BytesIO()
        np.savez(buf, meta=json.dumps(meta, default=_jsonable), **{a: getattr(self, a) for a in _ARRAYS}, **cols)
        write_bytes(path, buf.getvalue())

    @classmethod
    def load(cls, path) -> "Solution":
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            res = pd.DataFrame({k[4:]: z[k] for k in z.files if k.startswith("res_")})
            return cls(names=meta["names"], residuals=res, history=meta["history"],
                       converged=meta["converged"], inputs=meta["inputs"],
                       **{a: z[a] for a in _ARRAYS})


def _plain(a: np.ndarray) -> np.ndarray:
    """Object columns (labels) as fixed-width strings, so no pickling is needed."""
    return a.astype(str) if a.dtype == object else a


def _jsonable(o):
    if isinstance(o, np.generic):
        return o.item()
    raise TypeError(f"not JSON serializable: {type(o)}")
