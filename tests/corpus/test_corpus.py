"""The robustness corpus: one hostile or extreme design per file, run through the CLI (issue 12).

Each ``cases/*.toml`` starts with comment lines stating what must happen::

    # <what the case is about>
    # expect: exit=2 field=dxf.chord_tolerance [cmd=check|build|compare] [proc=sub]
    # says: <words the error line must contain>

``field=-`` means a file-level error that names no field. Every failing run
must print exactly one line on stderr, ``camcad: error: <field>: …`` or
``camcad: design limit: <field>: …``, and no traceback. Most cases run
in-process through :func:`camcad.cli.main`; ``proc=sub`` cases run as
``python -m camcad`` in a subprocess with a 60 s timeout. Build cases are
then checked file by file with independent readers: the G-code against the
same design under a plain name, the report with the standard-library HTML
parser, the DXF with ezdxf.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

from camcad.cli import main

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

CASES_DIR = Path(__file__).parent / "cases"
CASES = sorted(CASES_DIR.glob("*.toml"))
ROOT = Path(__file__).resolve().parents[2]


def _expectation(path: Path) -> dict[str, str]:
    """The ``# expect:`` and ``# says:`` header of a case file."""
    out: dict[str, str] = {}
    for line in path.read_text(encoding="utf-8").splitlines()[:5]:
        if line.startswith("# expect:"):
            out.update(item.split("=", 1) for item in line.removeprefix("# expect:").split())
        elif line.startswith("# says:"):
            out["says"] = line.removeprefix("# says:").strip()
    assert "exit" in out, f"{path.name}: no '# expect: exit=N' header"
    return out


def _argv(case: Path, cmd: str, outdir: Path) -> list[str]:
    if cmd == "build":
        return ["build", str(case), "-o", str(outdir / "out"), "-q", "--only", "gcode,dxf,report"]
    if cmd == "compare":
        return ["compare", str(case), str(case), "-o", str(outdir / "out")]
    return [cmd, str(case)]


def _run(
    case: Path, argv: list[str], subprocess_run: bool, capsys: pytest.CaptureFixture[str]
) -> tuple[int, str]:
    """Exit code and stderr of one CLI run."""
    if subprocess_run:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", "")) if p)
        proc = subprocess.run(
            [sys.executable, "-m", "camcad", *argv], capture_output=True, text=True, timeout=60, env=env
        )
        return proc.returncode, proc.stderr
    code = main(argv)
    return code, capsys.readouterr().err


@pytest.mark.parametrize("case", CASES, ids=[c.stem for c in CASES])
def test_case(case: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    want = _expectation(case)
    cmd = want.get("cmd", "check")
    code, err = _run(case, _argv(case, cmd, tmp_path), want.get("proc") == "sub", capsys)
    assert "Traceback" not in err
    assert code == int(want["exit"]), err
    if code == 0:
        assert not any(line.startswith("camcad:") for line in err.splitlines()), err
    else:
        lines = err.splitlines()
        assert len(lines) == 1, err
        field = want["field"]
        prefix = r"camcad: (error|design limit): "
        if field == "-":
            assert re.match(prefix, lines[0]), lines[0]
        else:
            assert re.match(prefix + re.escape(field) + ": ", lines[0]), lines[0]
        if "says" in want:
            assert want["says"] in lines[0], lines[0]
    check = _OUTPUT_CHECKS.get(case.stem)
    if check is not None:
        check(case, tmp_path / "out", tmp_path)


def test_corpus_is_large_and_every_case_names_its_field():
    assert len(CASES) >= 40
    for case in CASES:
        want = _expectation(case)
        assert want["exit"] == "0" or "field" in want, case.name


# ---------------------------------------------------------------------------
# what the sanitised files must look like


def _name_of(case: Path) -> str:
    return tomllib.loads(case.read_text(encoding="utf-8"))["cam"]["name"]


def _blocks(program: str) -> list[str]:
    """The program with every whole-line comment left out."""
    return [line for line in program.splitlines() if not re.fullmatch(r"\([^()]*\)", line)]


def _check_gcode(case: Path, out: Path, tmp: Path) -> None:
    program = (out / "cam.ngc").read_text(encoding="ascii")
    for line in program.splitlines():
        without = re.sub(r"\([^()]*\)", "", line)  # RS274NGC comments do not nest
        assert "(" not in without and ")" not in without and ";" not in without, line
    # the same design under a plain name gives the same blocks: the name added none
    twin = tmp / "plain.toml"
    twin.write_text(re.sub(r'(?m)^name = ".*"$', 'name = "plain"', case.read_text(encoding="utf-8")))
    assert main(["build", str(twin), "-o", str(tmp / "plain"), "-q", "--only", "gcode"]) == 0
    assert _blocks(program) == _blocks((tmp / "plain" / "cam.ngc").read_text(encoding="ascii"))
    first = program.splitlines()[0]
    assert "M30" in first and "script" in first  # the whole name stayed in the first comment


class _Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[str] = []
        self.h1 = ""
        self._in_h1 = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        self._in_h1 = tag == "h1"

    def handle_endtag(self, tag: str) -> None:
        self._in_h1 = False if tag == "h1" else self._in_h1

    def handle_data(self, data: str) -> None:
        if self._in_h1:
            self.h1 += data


def _check_report(case: Path, out: Path, tmp: Path) -> None:
    page = _Page()
    page.feed((out / "report.html").read_text(encoding="utf-8"))
    assert "script" not in page.tags
    # shown as text, character for character (HTML reads a carriage return as a newline)
    assert page.h1 == _name_of(case).replace("\r\n", "\n").replace("\r", "\n")


def _check_dxf(case: Path, out: Path, tmp: Path) -> None:
    import ezdxf

    doc = ezdxf.readfile(out / "profile.dxf")
    assert not doc.audit().has_errors
    texts = [e.dxf.text for e in doc.modelspace().query("TEXT")]
    assert texts
    for text in texts:
        assert all(32 <= ord(c) < 127 for c in text), text
        assert "%%" not in text and "^" not in text, text
    (cam_line,) = (t for t in texts if t.startswith("CAM "))
    assert "M30" in cam_line and "script" in cam_line and "end" in cam_line


def _check_build(case: Path, out: Path, tmp: Path) -> None:
    _check_report(case, out, tmp)
    _check_dxf(case, out, tmp)
    _check_gcode(case, out, tmp)


def _check_compare(case: Path, out: Path, tmp: Path) -> None:
    page = _Page()
    page.feed((out / "compare.html").read_text(encoding="utf-8"))
    assert page.tags.count("img") == 7  # the profiles and one figure per quantity (issue 19)


_OUTPUT_CHECKS = {"hostile_name": _check_build, "mathtext_name": _check_compare}


# ---------------------------------------------------------------------------
# the sanitisers on their own, against the format's own rules

HOSTILE = [
    "evil)\nM30\n(",
    "a;b(c)d",
    "\x00\x07\x1b[31m\x7f",
    "MSG, hello",
    "  debug,x",
    "é ñ ü ⌀ µ ±",
    "$x^{$",
    "_hidden",
    "x" * 1000,
    "%%u%%%c ^J ^ ",
]


@pytest.mark.parametrize("text", HOSTILE, ids=range(len(HOSTILE)))
def test_gcode_comment_text_obeys_rs274(text):
    from camcad.export.gcode.writer import comment_text

    out = comment_text(text)
    assert all(32 <= ord(c) < 127 for c in out)
    assert not set("();") & set(out)
    assert len(out) <= 200
    # LinuxCNC acts on comments that begin with MSG, DEBUG, PRINT, LOG…, PROBE… or ABORT and a comma
    assert not re.match(r"\s*(msg|debug|print|log\w*|probe\w*|abort)\s*,", out, re.IGNORECASE)


@pytest.mark.parametrize("text", HOSTILE, ids=range(len(HOSTILE)))
def test_plot_text_renders_literally_in_a_legend(text):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.cbook import is_math_text
    from matplotlib.figure import Figure

    from camcad._plots import plot_text

    fig = Figure(figsize=(2, 1))
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1], label=plot_text(text))
    legend = ax.legend()
    FigureCanvasAgg(fig).draw()  # parses any mathtext: an unbalanced '$x^{$' would raise here
    (entry,) = legend.get_texts()  # a label starting with '_' would have been left out
    assert not is_math_text(entry.get_text())  # rendered as plain text, no mathtext


@pytest.mark.parametrize("text", HOSTILE, ids=range(len(HOSTILE)))
def test_dxf_text_survives_a_round_trip_through_ezdxf(text, tmp_path):
    import ezdxf

    from camcad.export.dxf import dxf_text

    out = dxf_text(text)
    assert all(32 <= ord(c) < 127 for c in out)
    assert "%%" not in out and "^" not in out and len(out) <= 250
    doc = ezdxf.new("R2010")
    doc.modelspace().add_text(out)
    doc.saveas(tmp_path / "t.dxf")
    (back,) = ezdxf.readfile(tmp_path / "t.dxf").modelspace().query("TEXT")
    assert back.dxf.text == out  # one TEXT, read back unchanged: nothing in it was a DXF escape
