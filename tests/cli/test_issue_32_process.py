"""Issue 32, the command line as a process: one escaped line per error, signals at any moment, a full
disk while the report is written, an OUTDIR on another file system, and nothing but camcad's lines.

The subprocess cases run ``python -m camcad`` with this checkout first on ``PYTHONPATH``
(:func:`tests.cli.test_environment.environment`).
"""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from camcad.cli import main
from tests.cli.test_environment import HARMONIC, environment, tree
from tests.conftest import ROOT

TABLE_DESIGN = """
[cam]
name = "table"
base_radius = 45.0
thickness = 12.0

[follower]
type = "translating-roller"
roller_radius = 10.0

[[motion]]
kind = "table"
law = "table"
file = {file}
noise = 0.005
"""


@pytest.fixture
def outdir(tmp_path: Path) -> Path:
    """``tmp/out`` holding a file of an earlier build."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text('{"old": true}\n')
    return out


# --------------------------------------------------------------------------- one line per error


@pytest.mark.parametrize(
    "name",
    ["a\ncamcad: error: forged.csv", "a\rcamcad: error: forged.csv", "a\x1b[2Kb.csv", "a\u2028b.csv"],
    ids=["newline", "carriage-return", "escape-sequence", "line-separator"],
)
def test_a_control_character_in_a_table_path_cannot_forge_a_second_error_line(name, tmp_path, capsys):
    design = tmp_path / "d.toml"
    quoted = '"' + "".join(c if c.isprintable() else f"\\u{ord(c):04x}" for c in name) + '"'  # TOML
    design.write_text(TABLE_DESIGN.format(file=quoted), encoding="utf-8")
    assert main(["check", str(design)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("camcad: error: motion[0].file")
    assert lines[0].isprintable()
    # the escaped name, as Python would write it, is in the line: the user still sees which file
    assert name.encode("unicode_escape").decode("ascii") in lines[0]


def test_a_control_character_in_a_design_path_is_escaped(tmp_path, capsys):
    code = main(["check", str(tmp_path / "gone\ncamcad: error: forged.toml")])
    lines = capsys.readouterr().err.splitlines()
    assert code == 2
    assert len(lines) == 1 and lines[0].startswith("camcad: error: "), lines
    assert "gone\\ncamcad: error: forged.toml" in lines[0]


# --------------------------------------------------------------------------- a full disk


@pytest.mark.parametrize("forked", [True, False], ids=["report-forked", "report-in-process"])
def test_a_disk_that_fills_while_the_report_is_written_names_report_html(
    forked, tmp_path, outdir, capsys, monkeypatch
):
    """ENOSPC when report.html is flushed: exit 2 naming OUTDIR/report.html, OUTDIR as it was."""
    import camcad.pipeline as pipeline

    real_fsync = os.fsync

    def fsync(fd: int) -> None:  # the disk fills as the report's bytes reach it
        if "report" in os.readlink(f"/proc/self/fd/{fd}"):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync)  # a forked child inherits the patch
    if not forked:
        monkeypatch.setattr(pipeline, "_can_fork", lambda: False)
    elif not pipeline._can_fork():
        pytest.skip("the report is drawn in a forked child only on Linux with 2+ CPUs")
    before = tree(tmp_path)
    code = main(["build", str(HARMONIC), "-o", str(outdir), "-q", "--only", "tables,report"])
    err = capsys.readouterr().err.splitlines()
    assert code == 2
    assert err == [
        f"camcad: error: --output: cannot write {outdir / 'report.html'}: no space left on device; "
        "free space on that disk or choose another --output"
    ]
    assert tree(tmp_path) == before


# --------------------------------------------------------------------------- nothing but camcad's lines

# A home folder this user may not read. The tests run as root, whom no folder mode stops, so the
# script makes every path below HOME answer as it does for another user with HOME at mode 000.
_UNREADABLE_HOME = """
import os, pathlib, sys
home = pathlib.Path(os.environ["HOME"])
real_exists = pathlib.Path.exists

def exists(self, *args, **kwargs):
    if self == home or home in self.parents:
        raise PermissionError(13, "Permission denied", str(self))
    return real_exists(self, *args, **kwargs)

pathlib.Path.exists = exists
from camcad.cli import main
sys.exit(main(sys.argv[1:]))
"""

# A library warning inside a stage (SciPy's RuntimeWarning on a long table), raised on purpose.
_LIBRARY_WARNING = """
import sys, warnings
import camcad.pipeline as pipeline
real = pipeline.analyse

def analyse(*args, **kwargs):
    warnings.warn("invalid value encountered in divide", RuntimeWarning, stacklevel=1)
    return real(*args, **kwargs)

pipeline.analyse = analyse
from camcad.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _script(script: str, *args: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", script, *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        check=False,
    )


def test_an_unreadable_home_prints_nothing_of_ezdxfs_font_scan(tmp_path):
    """ezdxf's font scan at import printed one `Permission denied` line per font folder under HOME."""
    home = tmp_path / "home"
    (home / ".fonts").mkdir(parents=True)
    out = tmp_path / "out"
    env = environment(HOME=str(home), XDG_CONFIG_HOME=None, XDG_CACHE_HOME=None)
    done = _script(_UNREADABLE_HOME, "build", str(HARMONIC), "-o", str(out), "-q", "--only", "dxf", env=env)
    assert done.returncode == 0, done.stderr
    assert (done.stdout, done.stderr) == ("", "")  # -q: camcad itself prints nothing
    assert sorted(p.name for p in out.iterdir()) == [
        "profile.dxf",
        "profile_arcs.dxf",
        "profile_poly.dxf",
        "summary.json",
    ]


def test_a_library_warning_in_a_stage_stays_off_stderr(tmp_path):
    done = _script(_LIBRARY_WARNING, "check", str(HARMONIC), env=environment())
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert done.stdout.splitlines()[-1] == "all design limits hold"


# --------------------------------------------------------------------------- Ctrl-C at any moment

# ``python -m camcad`` after a hand-shake: the launcher says "go" once the interpreter has started, then
# runs the module as ``-m`` does. The interpreter's own start-up and its search for the package (a few
# ms, more on a loaded machine) come before any camcad code: Python's, not camcad's, so the delays
# start 40 ms after "go"; from there on the package, then camcad.cli, then the command import.
_LAUNCH = (
    "import runpy, sys; sys.stdout.write('go\\n'); sys.stdout.flush(); "
    "sys.argv[0] = '-m'; runpy._run_module_as_main('camcad')"
)


def _site_packages() -> list[str]:
    import site

    return [*site.getsitepackages(), site.getusersitepackages()]


def test_a_sigint_while_modules_import_is_one_line_and_exit_130():
    """At 10-500 ms after the interpreter started: one line and exit 130, never a traceback of camcad's.

    A signal that comes while Python itself still looks for the package (before camcad's first line)
    gets Python's own answer; on a loaded machine that can take tens of milliseconds, so those runs are
    told apart by their traceback holding no camcad frame, and most runs must land in camcad's code.
    """
    env = environment()
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *_site_packages()])  # -S: no .pth start-up
    clean, outcomes = 0, []
    delays = [0.01, 0.02, 0.04, 0.07, 0.1, 0.15, 0.2, 0.3, 0.5]
    for delay in delays:
        proc = subprocess.Popen(
            [sys.executable, "-S", "-c", _LAUNCH, "check", str(ROOT / "samples" / "quintero_vap_b01.toml")],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        assert proc.stdout.readline() == "go\n"
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
        outcomes.append((delay, proc.returncode, err[-300:]))
        assert out == "", (delay, out)
        if err == "camcad: interrupted\n" and proc.returncode == 130:
            clean += 1
            continue
        # Python's own window: it was still finding the package, no line of camcad had run
        assert "camcad" not in err and err.endswith("KeyboardInterrupt\n"), (delay, err)
        assert proc.returncode == -signal.SIGINT, (delay, proc.returncode)
    assert clean >= 5, outcomes  # the later delays land in camcad's imports or its command
