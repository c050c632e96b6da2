"""Issue 31: samples that show ``[fea]`` (stress.vtu) and ``machine = "rotary"`` (a rotary program) build,
and every shipped sample opens with its comment header.

Independent readers: meshio reads stress.vtu back (a mesh with a von Mises field), and the rotary
program is checked by its words (G93 inverse-time feed, the A axis, X only in the plane);
``tests/readers/test_rs274_rotary.py`` runs rotary programs through LinuxCNC.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from camcad.cli import main
from tests.conftest import ROOT, SAMPLES


@pytest.mark.parametrize("path", SAMPLES, ids=[p.stem for p in SAMPLES])
def test_every_sample_opens_with_its_comment_header(path):
    lines = path.read_text(encoding="utf-8").splitlines()
    header = lines[: next(i for i, x in enumerate(lines) if not x.startswith("#"))]
    assert len(header) >= 3 and any("Shows:" in line for line in header), path.name


def test_the_fea_sample_writes_stress_vtu(tmp_path, capsys):
    pytest.importorskip("gmsh")
    pytest.importorskip("skfem")
    meshio = pytest.importorskip("meshio")
    out = tmp_path / "out"
    assert main(["build", str(ROOT / "samples" / "fea_plate.toml"), "-o", str(out), "-q"]) == 0
    mesh = meshio.read(out / "stress.vtu")
    assert len(mesh.points) > 100
    fields = {k.lower() for k in mesh.point_data} | {k.lower() for k in mesh.cell_data}
    assert any("mises" in k for k in fields), fields
    assert "Finite-element check" in (out / "report.html").read_text(encoding="utf-8")


def test_the_rotary_sample_writes_a_rotary_program(tmp_path):
    out = tmp_path / "out"
    assert (
        main(["build", str(ROOT / "samples" / "rotary_plate.toml"), "-o", str(out), "-q", "--only", "gcode"])
        == 0
    )
    text = (out / "cam.ngc").read_text(encoding="ascii")
    blocks = [line for line in text.splitlines() if line and not line.startswith("(")]
    assert any(re.match(r"G93\b", b) for b in blocks)
    cuts = [b for b in blocks if re.search(r"\bA-?\d", b)]
    assert len(cuts) > 50
    assert not any(re.search(r"\bY-?\d", b) for b in blocks)  # X and A only, no XY contour
    a = np.array([float(re.search(r"\bA(-?[\d.]+)", b).group(1)) for b in cuts])
    assert a.max() - a.min() >= 360.0 - 1e-6  # at least one whole revolution of the cam
