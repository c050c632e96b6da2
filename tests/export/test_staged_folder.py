"""All-or-nothing output folders: files appear only when the whole block succeeds."""

from __future__ import annotations

import errno
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from camcad.errors import OutputError
from camcad.export import atomic
from camcad.export.atomic import atomic_write, staged_folder

try:
    import fcntl
except ImportError:  # pragma: no cover
    fcntl = None


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


def tree(folder):
    """Every file and folder below ``folder`` (hidden ones too): file contents, ``None`` for folders."""
    return {
        str(p.relative_to(folder)): None if p.is_dir() else p.read_bytes() for p in sorted(folder.rglob("*"))
    }


@pytest.fixture
def filled(tmp_path):
    """``out/`` with old files sorted before and after a folder named like an output."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.csv").write_text("old a")
    (out / "keep.txt").write_text("keep")
    (out / "summary.json").mkdir()
    (out / "summary.json" / "inside").write_text("x")
    return out


def test_a_folder_in_the_way_is_found_before_any_file_moves(tmp_path, filled, monkeypatch):
    before = tree(tmp_path)
    real_replace, moved_in = os.replace, []

    def replace(src, dst):
        if Path(dst).parent == filled:
            moved_in.append(dst)
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(OutputError) as info, staged_folder(filled) as staging:
        (staging.path / "a.csv").write_text("new a")  # sorted before the collision
        (staging.path / "summary.json").write_text("{}")
        (staging.path / "z.csv").write_text("new z")
    message = str(info.value)
    assert message.startswith("--output: ")
    assert str(filled / "summary.json") in message
    assert "folder" in message and "remove or rename" in message
    assert ".camcad-" not in message
    assert info.value.exit_code == 2
    assert moved_in == [], "a file was moved in before the collision was found"
    assert tree(tmp_path) == before


def test_an_error_in_the_middle_of_the_move_puts_every_replaced_file_back(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    for name in ("a.csv", "b.csv", "c.csv"):
        (out / name).write_text(f"old {name}")
    before = tree(tmp_path)
    real_replace = os.replace

    def replace(src, dst):
        if Path(dst).name == "c.csv" and Path(dst).parent == out:
            raise OSError(errno.ENOSPC, "No space left on device", str(src))
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(OutputError, match="no space left on device") as info, staged_folder(out) as staging:
        for name in ("a.csv", "b.csv", "c.csv", "d.csv"):
            (staging.path / name).write_text(f"new {name}")
    assert str(out / "c.csv") in str(info.value)
    assert tree(tmp_path) == before


@pytest.mark.parametrize(
    ("code", "words"),
    [(errno.ENOSPC, "free space"), (errno.EACCES, "writable"), (errno.EEXIST, "remove or rename")],
    ids=["ENOSPC", "EACCES", "EEXIST"],
)
def test_an_os_error_while_writing_names_the_real_path_and_a_way_out(tmp_path, code, words):
    out = tmp_path / "out"

    def writer(tmp):
        tmp.write_text("part")
        raise OSError(code, os.strerror(code), str(tmp))

    with pytest.raises(OutputError) as info, staged_folder(out) as staging:
        atomic_write(staging.path / "cam.ngc", writer)
    message = str(info.value)
    assert message.startswith(f"--output: cannot write {out / 'cam.ngc'}: {os.strerror(code).lower()}")
    assert words in message and ".camcad-" not in message and ".tmp" not in message
    assert isinstance(info.value, OSError) and info.value.errno == code
    assert list(tmp_path.iterdir()) == []


def test_nested_new_folder_appears_at_once_or_not_at_all(tmp_path, monkeypatch):
    out = tmp_path / "a" / "b" / "c" / "d"
    with pytest.raises(KeyboardInterrupt), staged_folder(out) as staging:
        (staging.path / "x.csv").write_text("x")
        raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []

    def rename(src, dst):  # another program made ``d`` in the meantime
        raise OSError(errno.EEXIST, "File exists", str(src), str(dst))

    with monkeypatch.context() as patch:
        patch.setattr(os, "rename", rename)
        with pytest.raises(OutputError, match="file exists; remove or rename it") as info:
            with staged_folder(out) as staging:
                (staging.path / "x.csv").write_text("x")
    assert str(out) in str(info.value)
    assert list(tmp_path.iterdir()) == [], "created parents or the staging folder were left"
    with staged_folder(out) as staging:
        (staging.path / "x.csv").write_text("x")
    assert tree(tmp_path) == {"a": None, "a/b": None, "a/b/c": None, "a/b/c/d": None, "a/b/c/d/x.csv": b"x"}


def test_staging_folders_of_dead_processes_are_removed(tmp_path):
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True
    )
    dead_pid = int(dead.stdout)
    out = tmp_path / "out"
    stale = tmp_path / f".out.camcad-{dead_pid}-0123abcd"
    live = tmp_path / f".other.camcad-{os.getppid()}-0123abcd"  # the parent of this process runs
    unrelated = tmp_path / ".out.camcad-notes"
    for folder in (stale, live, unrelated):
        folder.mkdir()
        (folder / "cam.ngc").write_text("x")
    with staged_folder(out) as staging:
        (staging.path / "x.csv").write_text("x")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([live.name, unrelated.name, "out"])


@pytest.mark.skipif(fcntl is None, reason="no file locks on this platform")
def test_a_second_build_waits_for_the_lock_and_gives_up_with_a_clear_error(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.csv").write_text("old")
    lock = tmp_path / ".out.camcad-lock"
    fd = os.open(lock, os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)  # another build is moving its files in
    monkeypatch.setattr(atomic, "LOCK_WAIT_S", 0.2)
    try:
        start = time.monotonic()
        with pytest.raises(OutputError, match="another camcad build") as info, staged_folder(out) as staging:
            (staging.path / "a.csv").write_text("new")
        assert 0.2 <= time.monotonic() - start < 5.0
        assert str(out) in str(info.value)
        assert (out / "a.csv").read_text() == "old"
    finally:
        os.close(fd)
    with staged_folder(out) as staging:  # a lock file left by a killed build is taken over and removed
        (staging.path / "a.csv").write_text("new")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert (out / "a.csv").read_text() == "new"


def test_an_os_error_of_the_move_itself_names_the_output_folder(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.csv").write_text("old")
    before = tree(tmp_path)
    real_mkdir = Path.mkdir

    def mkdir(self, *args, **kwargs):
        if self.parent.name.startswith(".out.camcad-"):  # camcad's own bookkeeping inside the staging folder
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(self))
        return real_mkdir(self, *args, **kwargs)

    monkeypatch.setattr(Path, "mkdir", mkdir)
    with pytest.raises(OutputError) as info, staged_folder(out) as staging:
        (staging.path / "a.csv").write_text("new")
    assert str(info.value).startswith(f"--output: cannot write {out}: no space left on device; free space")
    assert tree(tmp_path) == before


@pytest.fixture
def other_file_system(tmp_path):
    """A fresh folder on /dev/shm (tmpfs), when that is another file system than ``tmp_path``'s."""
    import shutil
    import tempfile

    shm = Path("/dev/shm")
    if not shm.is_dir() or not os.access(shm, os.W_OK):
        pytest.skip("no writable /dev/shm")
    if os.stat(shm).st_dev == os.stat(tmp_path).st_dev:
        pytest.skip("/dev/shm is on the same file system as the test's temporary folder")
    folder = Path(tempfile.mkdtemp(dir=shm, prefix="camcad-test-"))
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


@pytest.mark.parametrize("exists", [True, False], ids=["existing-target", "target-made-by-the-build"])
def test_an_outdir_linked_to_another_file_system_is_staged_beside_its_target(
    tmp_path, other_file_system, exists
):
    """OUTDIR -> /dev/shm/…: the files land in the link's target; the link stays; nothing left anywhere."""
    target = other_file_system / "real"
    if exists:
        target.mkdir()
        (target / "a.csv").write_text("old")
    link = tmp_path / "out"
    link.symlink_to(target, target_is_directory=True)
    with staged_folder(link) as staging:
        assert os.stat(staging.path).st_dev == os.stat(other_file_system).st_dev  # beside the target
        (staging.path / "a.csv").write_text("new")
        (staging.path / "b.dxf").write_text("new")
    assert link.is_symlink() and link.resolve() == target.resolve()
    assert {p.name: p.read_text() for p in target.iterdir()} == {"a.csv": "new", "b.dxf": "new"}
    assert [p.name for p in tmp_path.iterdir()] == ["out"]
    assert [p.name for p in other_file_system.iterdir()] == ["real"]


def test_a_failed_build_into_a_linked_outdir_leaves_it_as_it_was(tmp_path, other_file_system):
    target = other_file_system / "real"
    target.mkdir()
    (target / "a.csv").write_text("old")
    (tmp_path / "out").symlink_to(target, target_is_directory=True)
    with pytest.raises(RuntimeError), staged_folder(tmp_path / "out") as staging:
        (staging.path / "a.csv").write_text("half")
        raise RuntimeError("stage failed")
    assert {p.name: p.read_text() for p in target.iterdir()} == {"a.csv": "old"}
    assert [p.name for p in other_file_system.iterdir()] == ["real"]
