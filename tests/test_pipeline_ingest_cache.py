"""Ingest keeps the files a process read: the same file is parsed once, a changed file again."""

import os
import shutil

import pytest

from odpipe.pipeline import ingest as ingest_module
from odpipe.pipeline.ingest import ingest
from parsers.formats import read_any

A, B = "grail/grblugf2012_101_0350smmmv1.odf", "grail/grblugf2012_102_0055smmmv1.odf"


@pytest.mark.realdata
def test_a_changed_file_is_read_again_and_callers_cannot_change_the_kept_one(shared_data, tmp_path, monkeypatch):
    monkeypatch.setattr(ingest_module, "_READ", {})
    path = tmp_path / "day.odf"
    shutil.copyfile(shared_data / A, path)
    first = ingest([path])
    first.table.loc[0, "spacecraft"] = "changed by a caller"
    again = ingest([path])
    assert again.table.equals(read_any(path).table.sort_values("epoch", kind="stable").reset_index(drop=True))
    assert len(ingest_module._READ) == 1                      # parsed once
    shutil.copyfile(shared_data / B, path)
    st = path.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))   # a later file, even on a coarse clock
    other = ingest([path])
    assert len(other.table) == len(read_any(shared_data / B).table) != len(again.table)
