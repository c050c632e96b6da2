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
from tests.cli.test_environment import HARMONIC, camcad_cli, environment, tree
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
