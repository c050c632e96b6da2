"""All-or-nothing output folders: files appear only when the whole block succeeds."""

from __future__ import annotations

import pytest

from camcad.errors import OutputError
from camcad.export.atomic import staged_folder


def test_success_moves_every_file_and_leaves_nothing_temporary(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("old")
    (out / "a.csv").write_text("old")
    with staged_folder(out) as staging:
        (staging.path / "a.csv").write_text("new")
        (staging.path / "b.dxf").write_text("new")
        assert not (out / "b.dxf").exists()
    assert {p.name: p.read_text() for p in out.iterdir()} == {
        "keep.txt": "old",
        "a.csv": "new",
        "b.dxf": "new",
    }
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_failure_leaves_the_folder_exactly_as_it_was(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.csv").write_text("old")
    with pytest.raises(RuntimeError), staged_folder(out) as staging:
        (staging.path / "a.csv").write_text("half")
        raise RuntimeError("stage failed")
    assert (out / "a.csv").read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_a_new_folder_is_only_created_on_success(tmp_path):
    out = tmp_path / "deep" / "out"
    with pytest.raises(ValueError), staged_folder(out):
        raise ValueError
    assert not out.exists()
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="--output"), staged_folder(blocker / "out"):
        pass
