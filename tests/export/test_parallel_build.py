"""The report drawn in a forked child while the parent writes the other files (camcad.pipeline.build).

Independent truths: the same build run serially (``parallel=False``) gives
the same bytes in every file; the output folder's contents before a failed
build; the operating system's own record of the child (reaped: no such
process afterwards).
"""

from __future__ import annotations

import os
import pickle

import pytest

import camcad.pipeline as pipeline
import camcad.report
from camcad.design import load_design
from camcad.errors import DesignLimitError, ExportError
from camcad.pipeline import build
from tests.conftest import ROOT

pytestmark = pytest.mark.skipif(
    not pipeline._can_fork(), reason="the report is forked only on Linux with 2+ CPUs"
)

SAMPLE = ROOT / "samples" / "quintero_harmonic.toml"


@pytest.fixture
def children(monkeypatch):
    """The pids of the children forked by build()."""
    pids: list[int] = []
    start = pipeline._Background.__init__

    def spy(self, fn):
        start(self, fn)
        pids.append(self._pid)  # in the parent: the child's pid

    monkeypatch.setattr(pipeline._Background, "__init__", spy)
    return pids


def _reaped(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


def test_a_parallel_build_writes_the_same_bytes_as_a_serial_one(tmp_path, children):
    design = load_design(SAMPLE)
    forked = build(design, tmp_path / "forked")
    assert len(children) == 1 and _reaped(children[0])
    serial = build(design, tmp_path / "serial", parallel=False)
    assert len(children) == 1  # the serial build forked nothing
    names = sorted(p.name for p in (tmp_path / "forked").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "serial").iterdir())
    assert "report.html" in names and "cam.ngc" in names
    for name in names:
        assert (tmp_path / "forked" / name).read_bytes() == (tmp_path / "serial" / name).read_bytes(), name
    assert [p.name for p in forked.files] == [p.name for p in serial.files]
    assert forked.analysis.timings["report"] > 0.0


def _old_folder(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("old")
    (out / "report.html").write_text("old report")
    return out


def _contents(folder):
    return {p.name: p.read_bytes() for p in folder.iterdir()}


def test_an_error_in_the_forked_report_is_raised_and_the_folder_left_as_is(tmp_path, monkeypatch, children):
    out = _old_folder(tmp_path)
    before = _contents(out)

    def fails(analysis, path):
        raise DesignLimitError("the report refused to draw")

    monkeypatch.setattr(camcad.report, "write_report", fails)
    with pytest.raises(DesignLimitError, match="the report refused to draw"):
        build(load_design(SAMPLE), out)
    assert _contents(out) == before
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no staging folder left beside it
    assert len(children) == 1 and _reaped(children[0])


def test_an_exception_that_cannot_travel_comes_back_by_name_and_text(tmp_path, monkeypatch):
    class Unpicklable(Exception):
        def __reduce__(self):
            raise pickle.PicklingError("no")

    def fails(analysis, path):
        raise Unpicklable("a lock in the figure")

    monkeypatch.setattr(camcad.report, "write_report", fails)
    with pytest.raises(ExportError, match="report: Unpicklable: a lock in the figure"):
        build(load_design(SAMPLE), tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_a_failure_in_the_parent_stops_and_reaps_the_report_child(tmp_path, monkeypatch, children):
    out = _old_folder(tmp_path)
    before = _contents(out)

    def fails(analysis, folder):
        raise ExportError("disk full while writing the tables")

    monkeypatch.setattr(pipeline, "write_tables", fails)
    with pytest.raises(ExportError, match="disk full"):
        build(load_design(SAMPLE), out)
    assert len(children) == 1 and _reaped(children[0])
    assert _contents(out) == before
    assert [p.name for p in tmp_path.iterdir()] == ["out"]
