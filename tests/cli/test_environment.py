"""Issue 12: the build against its environment: signals, collisions, concurrency, HOME, pipes, repeatability.

Most cases run ``python -m camcad`` in a subprocess with this checkout first
on ``PYTHONPATH``. "Unchanged" is checked on the whole parent folder, hidden
files included, so nothing may be left beside the output folder either.
"""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

import camcad
from camcad.cli import main
from camcad.design import load_design
from camcad.errors import CamcadError, DesignError, OutputError
from tests.conftest import ROOT

SAMPLES = ROOT / "samples"
VAP = SAMPLES / "quintero_vap_b01.toml"  # the slowest build (toolpath): room to interrupt it
HARMONIC = SAMPLES / "quintero_harmonic.toml"
OFFSET = SAMPLES / "offset_roller.toml"

# Valid, but the offset roller's profile is not star-shaped, so lift.csv (a table) has no polar radius.
NOT_STAR_SHAPED = """
[cam]
name = "not star-shaped"
base_radius = 20.0
thickness = 8.0

[follower]
type = "translating-roller"
roller_radius = 5.0
offset = 20.0

[[motion]]
kind = "rise"
angle = 60.0
lift = 40.0
law = "cycloidal"

[[motion]]
kind = "dwell"
angle = 120.0

[[motion]]
kind = "return"
angle = 60.0
lift = 40.0
law = "cycloidal"

[[motion]]
kind = "dwell"
angle = 120.0
"""


def environment(**changes: str | None) -> dict[str, str]:
    """This process's environment with the checkout on PYTHONPATH; ``None`` removes a variable."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    for name, value in changes.items():
        if value is None:
            env.pop(name, None)
        else:
            env[name] = value
    return env


def camcad_cli(*args: str, env: dict[str, str] | None = None, cwd: Path | None = None):
    """Run ``python -m camcad ARGS``; return the completed process (text output)."""
    return subprocess.run(
        [sys.executable, "-m", "camcad", *args],
        capture_output=True,
        text=True,
        env=env or environment(),
        cwd=cwd,
        timeout=60,
        check=False,
    )


def tree(folder: Path) -> dict[str, bytes | None]:
    """Every file and folder below ``folder``, hidden ones too: contents, ``None`` for folders."""
    return {
        str(p.relative_to(folder)): None if p.is_dir() else p.read_bytes() for p in sorted(folder.rglob("*"))
    }


def files(folder: Path) -> dict[str, bytes]:
    return {name: data for name, data in tree(folder).items() if data is not None}


@pytest.fixture
def outdir(tmp_path: Path) -> Path:
    """``tmp/out`` holding a file of an earlier build."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text('{"old": true}\n')
    (out / "notes.txt").write_text("mine\n")
    return out


def wait_for_staging(parent: Path, name: str, proc: subprocess.Popen) -> Path:
    """Wait until ``proc`` has made its staging folder for ``name`` in ``parent`` (it is then mid-build)."""
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:
        found = list(parent.glob(f".{name}.camcad-*"))
        if found:
            return found[0]
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.01)
    proc.kill()
    raise AssertionError("the build never made its staging folder")


# --------------------------------------------------------------------------- all or nothing


def test_a_folder_named_like_an_output_stops_the_build_before_anything_moves(tmp_path, outdir, capsys):
    (outdir / "summary.json").unlink()
    (outdir / "summary.json").mkdir()  # sorted after motion.csv, points.csv, profile.csv ...
    (outdir / "motion.csv").write_text("old motion\n")
    before = tree(tmp_path)
    code = main(["build", str(HARMONIC), "-o", str(outdir), "-q", "--only", "tables"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1, err
    assert err[0].startswith("camcad: error: --output: ")
    assert str(outdir / "summary.json") in err[0] and "remove or rename" in err[0]
    assert tree(tmp_path) == before


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_mid_build_leaves_outdir_as_it_was_and_nothing_beside_it(sig, tmp_path, outdir):
    before = tree(tmp_path)
    proc = subprocess.Popen(
        [sys.executable, "-m", "camcad", "build", str(VAP), "-o", str(outdir), "-q"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=environment(),
    )
    wait_for_staging(tmp_path, "out", proc)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err.strip() == "camcad: interrupted"
    assert tree(tmp_path) == before


def test_a_killed_build_leaves_a_staging_folder_that_the_next_build_removes(tmp_path, outdir):
    proc = subprocess.Popen(
        [sys.executable, "-m", "camcad", "build", str(VAP), "-o", str(outdir), "-q"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=environment(),
    )
    staging = wait_for_staging(tmp_path, "out", proc)
    proc.kill()
    proc.wait(timeout=60)
    assert staging.is_dir()
    assert (outdir / "summary.json").read_text() == '{"old": true}\n'
    done = camcad_cli("build", str(HARMONIC), "-o", str(outdir), "-q", "--only", "tables")
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_failed_build_into_new_nested_folders_creates_none_of_them(tmp_path, capsys):
    design = tmp_path / "star.toml"
    design.write_text(NOT_STAR_SHAPED)
    before = tree(tmp_path)
    assert (
        main(["build", str(design), "-o", str(tmp_path / "a" / "b" / "c" / "d"), "-q", "--only", "tables"])
        == 3
    )
    assert tree(tmp_path) == before
    assert (
        main(["build", str(HARMONIC), "-o", str(tmp_path / "a" / "b" / "c" / "d"), "-q", "--only", "dxf"])
        == 0
    )
    assert {p.name for p in (tmp_path / "a" / "b" / "c" / "d").iterdir()} == {
        "profile.dxf",
        "profile_poly.dxf",
        "profile_arcs.dxf",
        "summary.json",
    }


def test_a_full_disk_names_the_output_file_and_what_to_do(tmp_path, outdir, capsys, monkeypatch):
    def fsync(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", fsync)
    before = tree(tmp_path)
    assert main(["build", str(HARMONIC), "-o", str(outdir), "-q", "--only", "tables"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    # the first file written is motion.csv: named where the user will look for it
    assert err[0] == (
        f"camcad: error: --output: cannot write {outdir / 'motion.csv'}: no space left on device; "
        "free space on that disk or choose another --output"
    )
    assert tree(tmp_path) == before


def test_file_exists_names_the_output_folder_and_what_to_do(tmp_path, capsys, monkeypatch):
    new = tmp_path / "new" / "out"

    def rename(src, dst):  # the new folder appeared while camcad built
        raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), str(src), str(dst))

    monkeypatch.setattr(os, "rename", rename)
    assert main(["build", str(HARMONIC), "-o", str(new), "-q", "--only", "tables"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert str(new) in err[0] and "file exists" in err[0] and "remove or rename it" in err[0]
    assert ".camcad-" not in err[0]
    assert list(tmp_path.iterdir()) == []


def test_two_builds_into_one_folder_give_one_builds_files_never_a_mix(tmp_path):
    """Two different designs at once into one folder; every file must come from the same one of them."""
    out = tmp_path / "out"
    only = ("-q", "--only", "tables,dxf")
    references = {}
    for sample in (HARMONIC, OFFSET):
        ref = tmp_path / f"ref_{sample.stem}"
        camcad.load(sample).build(ref, only=["tables", "dxf"])
        references[sample.stem] = files(ref)
    assert references["quintero_harmonic"].keys() == references["offset_roller"].keys()
    for _ in range(2):
        with ThreadPoolExecutor(2) as pool:
            runs = list(
                pool.map(lambda s: camcad_cli("build", str(s), "-o", str(out), *only), (HARMONIC, OFFSET))
            )
        assert [r.returncode for r in runs] == [0, 0], [r.stderr for r in runs]
        result = files(out)
        assert result in references.values(), sorted(
            (name, [stem for stem, ref in references.items() if ref[name] == data])
            for name, data in result.items()
        )
        assert sorted(p.name for p in tmp_path.iterdir()) == [
            "out",
            "ref_offset_roller",
            "ref_quintero_harmonic",
        ]


# --------------------------------------------------------------------------- exit codes


@pytest.mark.parametrize("only", ["tables", "dxf", "stl", "tables,report"])
def test_a_camcad_error_gives_its_documented_exit_code_whatever_only_says(only, tmp_path, capsys):
    star = tmp_path / "star.toml"
    star.write_text(NOT_STAR_SHAPED)
    code = main(["build", str(star), "-o", str(tmp_path / "o"), "-q", "--only", only])
    err = capsys.readouterr().err.strip().splitlines()
    if "tables" in only:  # lift.csv cannot be written: a design limit
        assert code == 3 and len(err) == 1 and err[0].startswith("camcad: design limit: ")
        assert "star-shaped" in err[0]
    else:
        assert code == 0, err
    bad = tmp_path / "bad.toml"
    bad.write_text(HARMONIC.read_text().replace("thickness = ", "thickness = -", 1))
    assert main(["build", str(bad), "-o", str(tmp_path / "o"), "-q", "--only", only]) == 2
    assert "cam.thickness" in capsys.readouterr().err


def test_exit_codes_are_defined_once_on_the_error_classes():
    from camcad import errors

    assert errors.exit_code(errors.DesignError("x", "y")) == errors.EXIT_INVALID == 2
    assert errors.exit_code(errors.UsageError("--only", "y")) == 2
    assert errors.exit_code(OutputError("out", "full")) == 2
    assert errors.exit_code(errors.DesignLimitError("j")) == errors.EXIT_LIMIT == 3
    assert errors.exit_code(errors.NotStarShapedError("s")) == 3
    assert errors.exit_code(errors.FitError("f", best_error=1.0, control_point_count=3)) == 3
    assert errors.exit_code(errors.ExportError("e")) == errors.EXIT_UNEXPECTED == 1
    assert errors.exit_code(PermissionError(13, "denied")) == 2
    assert errors.exit_code(KeyboardInterrupt()) == errors.EXIT_INTERRUPTED == 130
    assert issubclass(OutputError, CamcadError) and issubclass(OutputError, OSError)
    assert issubclass(errors.UsageError, DesignError)


# --------------------------------------------------------------------------- the user's environment


def _home_as_a_file(tmp_path: Path) -> dict[str, str]:
    home = tmp_path / "home"
    home.write_text("not a folder")
    return {"HOME": str(home)}


def _home_with_broken_ezdxf_files(tmp_path: Path) -> dict[str, str]:
    home = tmp_path / "home"
    (home / ".config" / "ezdxf").mkdir(parents=True)
    (home / ".config" / "ezdxf" / "ezdxf.ini").write_text("no section header\n")
    (home / ".cache" / "ezdxf").mkdir(parents=True)
    (home / ".cache" / "ezdxf" / "font_manager_cache.json").write_text("{not json")
    broken_ini = tmp_path / "elsewhere.ini"
    broken_ini.write_text("[core\n")
    return {"HOME": str(home), "EZDXF_CONFIG_FILE": str(broken_ini)}


HOMES = {  # name: (environment changes, outputs: the report draws with matplotlib)
    "unset": (lambda tmp_path: {"HOME": None, "XDG_CONFIG_HOME": None, "XDG_CACHE_HOME": None}, "dxf"),
    "missing": (lambda tmp_path: {"HOME": str(tmp_path / "gone"), "MPLCONFIGDIR": None}, "dxf"),
    "a_file": (_home_as_a_file, "dxf,report"),
    "broken_ezdxf_config_and_cache": (_home_with_broken_ezdxf_files, "dxf,report"),
}


@pytest.fixture(scope="module")
def reference_dxf(tmp_path_factory) -> dict[str, bytes]:
    out = tmp_path_factory.mktemp("reference") / "out"
    camcad.load(HARMONIC).build(out, only=["dxf"])
    return files(out)


@pytest.mark.parametrize("case", sorted(HOMES))
def test_the_users_home_folder_does_not_matter(case, tmp_path, reference_dxf):
    out = tmp_path / "out"
    changes, only = HOMES[case]
    done = camcad_cli(
        "build", str(HARMONIC), "-o", str(out), "-q", "--only", only, env=environment(**changes(tmp_path))
    )
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""  # no stray lines from ezdxf or matplotlib
    written = files(out)
    assert {name: written[name] for name in reference_dxf} == reference_dxf


def test_a_closed_stdout_pipe_ends_quietly(tmp_path):
    proc = subprocess.Popen(
        [sys.executable, "-m", "camcad", "laws"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=environment(),
    )
    proc.stdout.close()  # the reader is gone before camcad writes a line
    err = proc.stderr.read()
    proc.wait(timeout=60)
    assert err == b""
    assert proc.returncode == 141  # 128 + SIGPIPE, what a shell reports for `yes | head`
    shell = subprocess.run(
        ["sh", "-c", '"$0" -m camcad check "$1" | head -1', sys.executable, str(OFFSET)],
        capture_output=True,
        text=True,
        env=environment(),
        timeout=60,
        check=False,
    )
    assert shell.stderr == ""
    assert shell.stdout.splitlines() == [f"{load_design(OFFSET).cam.name} ({OFFSET})"]


def test_a_utf8_bom_at_the_start_of_a_design_file_is_accepted(tmp_path, capsys):
    design = tmp_path / "bom.toml"
    design.write_bytes(HARMONIC.read_bytes())
    plain = load_design(design)
    design.write_bytes(b"\xef\xbb\xbf" + HARMONIC.read_bytes())
    assert load_design(design) == plain
    assert main(["check", str(design)]) == 0


def test_the_python_api_raises_only_camcad_errors_for_unreadable_files(tmp_path):
    with pytest.raises(DesignError, match="cannot read design file"):
        camcad.load(tmp_path)  # a folder
    latin1 = tmp_path / "latin1.toml"
    latin1.write_bytes(HARMONIC.read_bytes().replace(b'name = "', b'name = "\xe9', 1))
    with pytest.raises(DesignError, match="cannot read design file"):
        camcad.load(latin1)
    with pytest.raises(DesignError, match="embedded null byte"):
        camcad.load(str(tmp_path / "a\0b.toml"))
    with pytest.raises(OutputError, match="NUL"):
        camcad.load(HARMONIC).build(tmp_path / "o\0ut", only=["dxf"])
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="--output") as info:
        camcad.load(HARMONIC).build(blocker / "out", only=["dxf"])
    assert isinstance(info.value, CamcadError) and isinstance(info.value, OSError)


# --------------------------------------------------------------------------- repeatability


def test_two_builds_are_byte_identical_whatever_the_hash_seed(tmp_path):
    outs = [tmp_path / "one", tmp_path / "two"]

    def run(pair):
        out, seed = pair
        return camcad_cli("build", str(OFFSET), "-o", str(out), "-q", env=environment(PYTHONHASHSEED=seed))

    with ThreadPoolExecutor(2) as pool:
        runs = list(pool.map(run, zip(outs, ["1", "4"], strict=True)))
    assert [r.returncode for r in runs] == [0, 0], [r.stderr for r in runs]
    one, two = files(outs[0]), files(outs[1])
    assert len(one) == 13  # the 11 of issue 8, profile_arcs.dxf and cam.step (issue 17)
    assert one.keys() == two.keys()
    assert [name for name in one if one[name] != two[name]] == []
    assert b"Timings" not in one["report.html"]


def test_timings_go_to_the_terminal_not_the_report(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["build", str(HARMONIC), "-o", str(out), "-q", "--timings", "--only", "tables,report"]) == 0
    lines = capsys.readouterr().out.splitlines()
    stages = [line.split()[0] for line in lines]
    assert stages == ["geometry", "dynamics", "fit", "tables", "report", "total"]
    seconds = [float(line.split()[1]) for line in lines]
    assert all(line.endswith(" s") for line in lines)
    assert seconds[-1] == pytest.approx(sum(seconds[:-1]), abs=0.003)
    assert "Timings" not in (out / "report.html").read_text()
