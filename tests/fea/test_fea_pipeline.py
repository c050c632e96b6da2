"""The FE check through the design file, the command line, summary.json and stress.vtu.

Independent truths: meshio reads ``stress.vtu`` back (its quadratic triangles
and arrays), and the arrays restate the solution by definition (von Mises of
the written tensor, principal stresses as its eigenvalues by numpy); the
command line's exit codes follow the limit rule of the README (a soft limit
warns in ``build`` and exits 3 in ``check``); two builds give the same bytes.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from camcad.cli import main
from camcad.design import parse_design
from camcad.design.schema import tomllib  # tomllib, or tomli on Python 3.10
from camcad.errors import DesignError

pytest.importorskip("gmsh")
pytest.importorskip("skfem")
meshio = pytest.importorskip("meshio")

DESIGN = """
[cam]
name = "fea test"
base_radius = 40.0
thickness = 10.0
bore = 16.0
keyway_width = 5.0
keyway_depth = 2.3
speed_rpm = 200.0

[follower]
type = "translating-roller"
roller_radius = 12.0

[[motion]]
kind = "rise"
angle = 150.0
lift = 15.0
law = "cycloidal"

[[motion]]
kind = "dwell"
angle = 30.0

[[motion]]
kind = "return"
angle = 150.0
lift = 15.0
law = "cycloidal"

[[motion]]
kind = "dwell"
angle = 30.0

[dynamics]
follower_mass = 1.0
spring_rate = 5.0
spring_preload = 200.0
"""
FEA = "\n[fea]\nangles = [45.0]\ncontact_divisions = 6\n"


def _write(folder: Path, text: str, name: str = "cam.toml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("fea-build")
    design = _write(folder, DESIGN + FEA)
    assert main(["build", str(design), "-o", str(folder / "out"), "-q", "--only", "fea,tables"]) == 0
    return folder / "out"


def test_only_fea_writes_the_stress_file_and_the_summary(built: Path):
    assert sorted(p.name for p in built.iterdir() if p.name.endswith((".vtu", ".json"))) == [
        "stress.vtu",
        "summary.json",
    ]
    fea = json.loads((built / "summary.json").read_text())["fea"]
    labels = [c["label"] for c in fea["cases"]]
    assert "listed" in labels and any("peak contact force" in s for s in labels)
    assert fea["von_mises_max_MPa"] == max(c["von_mises_max_MPa"] for c in fea["cases"])
    assert fea["plane"] == "stress"  # 10 mm thick, 110 mm across: a thin plate
    for case in fea["cases"]:
        np.testing.assert_allclose(case["reaction_N"], -np.array(case["applied_N"]), atol=1e-6)


def test_stress_vtu_reads_back_in_meshio(built: Path):
    mesh = meshio.read(built / "stress.vtu")
    fea = json.loads((built / "summary.json").read_text())["fea"]
    assert [c.type for c in mesh.cells] == ["triangle6"] and len(mesh.cells[0].data) == fea["elements"]
    assert len(mesh.points) == fea["nodes"] and np.all(mesh.points[:, 2] == 0.0)
    for i, case in enumerate(fea["cases"], start=1):
        u = mesh.point_data[f"case{i}_displacement_mm"]
        stress = mesh.point_data[f"case{i}_stress_MPa"]  # XX, YY, ZZ, XY, YZ, XZ
        vm = mesh.point_data[f"case{i}_von_mises_MPa"]
        principal = mesh.point_data[f"case{i}_principal_stress_MPa"]
        assert u.shape == (len(mesh.points), 3) and np.all(u[:, 2] == 0.0)
        sx, sy, sz, txy = stress[:, 0], stress[:, 1], stress[:, 2], stress[:, 3]
        assert np.all(stress[:, 4:] == 0.0) and np.all(sz == 0.0)  # plane stress
        expected = np.sqrt(0.5 * ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2) + 3.0 * txy**2)
        np.testing.assert_allclose(vm, expected, rtol=1e-12, atol=1e-9)
        tensors = np.zeros((len(sx), 3, 3))
        tensors[:, 0, 0], tensors[:, 1, 1], tensors[:, 2, 2] = sx, sy, sz
        tensors[:, 0, 1] = tensors[:, 1, 0] = txy
        np.testing.assert_allclose(principal, np.linalg.eigvalsh(tensors)[:, ::-1], atol=1e-9 * vm.max())
        # nodal averages never exceed the peak over the elements' own nodes
        assert vm.max() <= case["von_mises_max_MPa"] * (1 + 1e-9)


def test_builds_are_byte_identical_and_default_build_needs_the_table(built: Path, tmp_path: Path):
    design = _write(tmp_path, DESIGN + FEA)
    # again in a fresh process with another hash seed
    env = dict(os.environ, PYTHONHASHSEED="12345")
    command = [sys.executable, "-m", "camcad", "build", str(design), "-o", str(tmp_path / "again"), "-q"]
    subprocess.run([*command, "--only", "fea"], env=env, check=True, timeout=300)
    digest = [
        hashlib.sha256((p / "stress.vtu").read_bytes()).hexdigest() for p in (built, tmp_path / "again")
    ]
    assert digest[0] == digest[1]
    plain = _write(tmp_path, DESIGN, "plain.toml")
    assert main(["build", str(plain), "-o", str(tmp_path / "plain"), "-q", "--only", "tables"]) == 0
    assert not (tmp_path / "plain" / "stress.vtu").exists()
    assert "fea" not in json.loads((tmp_path / "plain" / "summary.json").read_text())


def test_check_fea_and_the_allowable_stress(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    plain = _write(tmp_path, DESIGN)
    assert main(["check", str(plain), "--fea"]) == 0
    out = capsys.readouterr().out
    assert "FE max von Mises" in out and "FE case 1" in out
    low = _write(tmp_path, DESIGN + FEA + "allowable_stress = 50.0\n", "low.toml")
    assert main(["check", str(low)]) == 3
    out = capsys.readouterr().out
    assert "soft limit: FE von Mises stress" in out and "exceeds the allowable 50 MPa" in out
    # build warns but writes; the finding names the field to change
    assert main(["build", str(low), "-o", str(tmp_path / "low"), "-q", "--only", "fea"]) == 0
    findings = json.loads((tmp_path / "low" / "summary.json").read_text())["findings"]
    assert [f["field"] for f in findings if f["kind"] == "von Mises stress"] == ["fea.allowable_stress"]
    assert main(["build", str(low), "-o", str(tmp_path / "strict"), "-q", "--only", "fea", "--strict"]) == 3


def _design(extra: str) -> None:
    parse_design(tomllib.loads(DESIGN + extra))


@pytest.mark.parametrize(
    ("extra", "field", "words"),
    [
        ("[fea]\nplane = 'flat'\n", "fea.plane", "allowed: auto, stress, strain"),
        ("[fea]\nangles = [400.0]\n", "fea.angles", "0 to 360"),
        ("[fea]\nangles = 45.0\n", "fea.angles", "list of numbers"),
        ("[fea]\nkeyway_fillet = 3.0\n", "fea.keyway_fillet", "does not fit the keyway"),
        ("[fea]\ncontact_divisions = 1\n", "fea.contact_divisions", "2 to 64"),
        ("[fea]\nmesh_sise = 1.0\n", "fea.mesh_sise", "did you mean 'mesh_size'"),
    ],
    ids=["plane", "angle-range", "angle-list", "fillet", "divisions", "typo"],
)
def test_bad_fea_tables_name_the_field(extra: str, field: str, words: str):
    with pytest.raises(DesignError) as err:
        _design(extra)
    assert err.value.path == field and words in str(err.value)


def test_fea_needs_a_bore():
    data = tomllib.loads(DESIGN + "[fea]\n")
    data["cam"].update(bore=0.0, keyway_width=0.0, keyway_depth=0.0)
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert err.value.path == "cam.bore"


def test_a_mesh_too_fine_is_refused_before_meshing_naming_the_smallest_size():
    """Issue 32: mesh_size = 0.001 ran for minutes; now an exit 2 at once, naming the size allowed.

    Independent: the ring of the base circle outside the bore, π(r_b² − r_bore²), filled with
    equilateral triangles of area (√3/4)·h², and the bound of 30 000 triangles.
    """
    import time

    from camcad.fea.mesh import MAX_ELEMENTS

    area = math.pi * (40.0**2 - 8.0**2)
    smallest = math.sqrt(area / (math.sqrt(3.0) / 4.0 * MAX_ELEMENTS))
    start = time.perf_counter()
    with pytest.raises(DesignError) as err:
        _design("[fea]\nmesh_size = 0.001\n")
    assert time.perf_counter() - start < 5.0
    assert err.value.path == "fea.mesh_size"
    assert f"mesh_size ≥ {smallest:.3g} mm" in err.value.message
    _design(f"[fea]\nmesh_size = {smallest * 1.0001}\n")  # just above: accepted by the loader
    with pytest.raises(DesignError):
        _design(f"[fea]\nmesh_size = {smallest * 0.9999}\n")


def test_the_whole_plate_bounds_the_mesh_before_gmsh_runs(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    """Past the loader's base-circle bound, mesh_plate bounds the element count on the plate's area."""
    design = _write(tmp_path, DESIGN + "\n[fea]\nmesh_size = 0.65\n")
    assert main(["build", str(design), "-o", str(tmp_path / "out"), "-q", "--only", "fea"]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("camcad: error: fea.mesh_size: 0.65 mm") and "for this plate" in line
    assert not (tmp_path / "out").exists()
