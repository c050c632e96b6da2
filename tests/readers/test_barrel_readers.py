"""A barrel cam's files opened in real programs (issue 36).

- LinuxCNC's ``rs274`` runs cam.ngc; from its canonical moves alone each pass is rebuilt
  (X, Y, A linear within a block), mapped to the developed plane of a station t
  (u = t·φ + y, w = z with φ = −A, y = −Y, z = X: the program's header convention) and
  measured: the finishing cutter of the roller's diameter leaves each wall within the
  program's tolerance of the exact developed wall (geometry/barrel_limits) at the groove's
  bottom, pitch and top stations; no roughing cutter comes nearer a wall than the stock;
- FreeCAD reads cam.step as one valid solid of the quadrature's volume;
- admesh finds one clean part in cam.stl;
- LibreCAD prints profile.dxf.
"""

from __future__ import annotations

import json
import math
import re
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camcad.export.gcode.barrel import render_barrel_program
from camcad.geometry.barrel_limits import developed_walls
from camcad.toolpath.barrel import BarrelToolpath, BarrelToolpathOptions, plan_barrel
from tests.barrel_cases import CASES, barrel_volume
from tests.readers.conftest import require, run

pytestmark = pytest.mark.slow
NAMES = list(CASES)
_CALL = re.compile(r"([A-Z_]+)\((.*)\)")


@cache
def planned(name: str) -> BarrelToolpath:
    c = CASES[name]
    return plan_barrel(c.program, c.follower, c.options, BarrelToolpathOptions())


def canon_passes(canon: str) -> list[dict]:
    """The feed moves of each pass as (x, y, z, a) rows, with its kind from the pass comment."""
    passes: list[dict] = []
    pos = np.zeros(4)
    for line in canon.splitlines():
        m = _CALL.search(line.split("N.....", 1)[-1])
        if not m:
            continue
        name, args = m.group(1), m.group(2)
        if name == "COMMENT" and args.startswith('"pass '):
            kind = re.match(r'"pass \d+/\d+: (.*) at Z', args).group(1)
            passes.append({"kind": kind, "moves": []})
        elif name in ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE"):
            end = np.array([float(v) for v in args.split(",")[:4]])
            if name == "STRAIGHT_FEED" and passes:
                passes[-1]["moves"].append((pos.copy(), end))
            pos = end
        elif name == "ARC_FEED":
            raise AssertionError("a barrel program has no arcs")
    return passes


def rs274_passes(folder: Path, tp: Any, *, name: str, rough_diameter: float) -> tuple[list[dict], str]:
    """Write ``tp``'s program and a tool table (T1 the rougher, T2 the 16 mm finisher) into ``folder``,
    run rs274 on them (no message but "executing", to PROGRAM_END) and return its canonical passes,
    one per planned pass and of its kind, and the program's text."""
    rs274 = require("rs274")
    text = render_barrel_program(tp, name=name)
    (folder / "cam.ngc").write_text(text, encoding="ascii")
    table = f"T1 P1 Z0 D{rough_diameter:g} ;rough\nT2 P2 Z0 D16 ;finish\n"
    (folder / "tools.tbl").write_text(table, encoding="ascii")
    proc = run([rs274, "-t", "tools.tbl", "-g", "cam.ngc", "canon.txt"], cwd=folder)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = [s for s in (proc.stdout + proc.stderr).splitlines() if s.strip() and s.strip() != "executing"]
    assert not lines
    canon = (folder / "canon.txt").read_text(encoding="ascii")
    assert "PROGRAM_END" in canon
    passes = canon_passes(canon)
    assert [p["kind"] for p in passes] == [p.kind for p in tp.passes]
    return passes, text


def centres(moves, station: float, spacing: float = 0.02) -> tuple[np.ndarray, float]:
    """The tool axis at ``station`` in the developed plane, dense along each block; and the tip Z."""
    out, tips = [], set()
    for start, end in moves:
        if start[3] == end[3] and start[0] == end[0]:
            continue  # the plunge
        tips.add(end[2])
        length = math.hypot(math.radians(end[3] - start[3]) * station, end[0] - start[0])
        n = max(2, math.ceil(length / spacing))
        f = np.arange(n)[:, None] / n
        x, y, a = (start[[0, 1, 3]] + f * (end[[0, 1, 3]] - start[[0, 1, 3]])).T
        out.append(np.column_stack((station * -np.radians(a) + -y, x)))
    (tip,) = tips
    return np.concatenate(out), tip


@pytest.mark.parametrize("name", NAMES)
def test_rs274_runs_the_program_and_the_finish_cuts_the_exact_walls(name, tmp_path):
    c, tp = CASES[name], planned(name)
    passes, _ = rs274_passes(tmp_path, tp, name=name, rough_diameter=10.0)
    o, spec = c.options, tp.options
    r_w = o.roller_radius + 0.5 * o.clearance
    phi = np.linspace(0.0, 2.0 * math.pi, 100_001)
    motion = c.program.evaluate(phi)
    worst = {}
    for t in (o.bottom_radius, o.pitch_station, o.barrel_radius):
        walls = developed_walls(motion, c.follower, o, t)
        period = np.array([2.0 * math.pi * t, 0.0])
        pitch = np.vstack((walls.pitch.point - period, walls.pitch.point, walls.pitch.point + period))
        pitch_tree = cKDTree(pitch)
        for p in passes:
            pts, tip = centres(p["moves"], t)
            if p["kind"] == "rough":
                assert tip >= o.bottom_radius + spec.stock - 1e-4
                if t < tip:
                    continue  # above the tip only
                d, _ = pitch_tree.query(pts)
                # the cutter stays the stock inside both walls (less the pitch polyline's sag)
                assert d.max() + 0.5 * spec.rough_diameter <= r_w - spec.stock + spec.tolerance + 1e-3
                continue
            assert tip == pytest.approx(o.bottom_radius, abs=1e-4)
            wall = walls.upper.point if p["kind"] == "finish upper" else walls.lower.point
            tree = cKDTree(np.vstack((pts - period, pts, pts + period)))
            d, _ = tree.query(wall)
            worst[(t, p["kind"])] = float(np.max(np.abs(d - o.roller_radius)))
    assert len(worst) == 6
    print(name, {f"{t:g} {k}": round(v, 5) for (t, k), v in worst.items()})
    # 4-decimal words move the axis by < 1e-4 mm (X, Y; A·R at R = 70 mm), the c/2 shift at the pitch station
    # misses the normal elsewhere by (c/2)(1 − cos Δβ) < 2e-4 mm here
    assert max(worst.values()) <= spec.tolerance + 3e-4, worst


@cache
def step_file(name: str, folder: Path) -> Path:
    from camcad.export.barrel_step import barrel_shape, barrel_step_bytes
    from camcad.fit.surface import fit_barrel_walls

    c = CASES[name]
    solid = barrel_shape(fit_barrel_walls(c.program, c.follower, c.options), c.options)
    path = folder / "cam.step"
    path.write_bytes(barrel_step_bytes(solid, name=name))
    return path


FREECAD_SCRIPT = """
import json, Part
shape = Part.read("cam.step")
print("RESULT " + json.dumps(dict(solids=len(shape.Solids), valid=shape.isValid(), volume=shape.Volume,
    bsplines=sum(type(f.Surface).__name__ == "BSplineSurface" for f in shape.Faces))))
"""


@pytest.mark.parametrize("name", ["indexer"])
def test_freecad_reads_the_barrel_step_as_one_valid_solid(name, tmp_path):
    pytest.importorskip("OCP")
    program = require("freecadcmd")
    step_file(name, tmp_path)
    (tmp_path / "script.py").write_text(FREECAD_SCRIPT, encoding="utf-8")
    result = run([program, "script.py"], cwd=tmp_path)
    lines = [s for s in result.stdout.splitlines() if s.startswith("RESULT ")]
    assert len(lines) == 1, (result.stdout + result.stderr)[-3000:]
    got = json.loads(lines[0][len("RESULT ") :])
    assert got["solids"] == 1 and got["valid"]
    assert got["bsplines"] >= 2
    # Shape.Volume is OpenCASCADE's fixed Gauss rule, about 1e-4 short on these B-spline walls (its
    # adaptive rule, test_barrel_outputs.py, agrees with the quadrature to 0.05 mm³)
    assert got["volume"] == pytest.approx(barrel_volume(CASES[name]), rel=2e-4)


def test_admesh_finds_one_clean_part(tmp_path):
    from camcad.export.barrel_mesh import barrel_mesh, barrel_stl_bytes
    from tests.readers.test_admesh import MUST_BE_ZERO, admesh_report

    admesh = require("admesh")
    c = CASES["arm"]
    mesh = barrel_mesh(c.program, c.follower, c.options)
    (tmp_path / "cam.stl").write_bytes(barrel_stl_bytes(mesh))
    result = run([admesh, "cam.stl"], cwd=tmp_path)
    text = result.stdout + result.stderr
    report = admesh_report(text)
    assert report["Number of parts"] == [1.0], text
    assert report["Number of facets"] == [len(mesh.faces)] * 2, text
    for key in MUST_BE_ZERO:
        assert report[key] == [0.0], f"{key}: {report.get(key)}\n{text}"
    assert report["Volume"][0] == pytest.approx(barrel_volume(c), rel=1e-3)


def test_librecad_prints_the_developed_groove(tmp_path):
    from camcad.export.barrel_dxf import developed_groove, write_developed_dxf
    from tests.readers.test_librecad import dxf2pdf

    c = CASES["indexer"]
    path = tmp_path / "profile.dxf"
    write_developed_dxf(developed_groove(c.program, c.follower, c.options), path, length=c.options.length)
    pdf = dxf2pdf(path, tmp_path / "print")
    assert pdf.exists() and pdf.stat().st_size > 1000
    assert pdf.read_bytes().startswith(b"%PDF")


def test_freecad_and_admesh_read_the_rib(tmp_path):
    """The rib cam: FreeCAD reads its STEP as one valid solid, admesh its STL as one clean part."""
    pytest.importorskip("OCP")
    from camcad.export.barrel_mesh import barrel_mesh, barrel_stl_bytes
    from camcad.export.barrel_step import barrel_shape, barrel_step_bytes
    from camcad.fit.surface import fit_barrel_walls
    from tests.barrel_cases import RIB
    from tests.readers.test_admesh import MUST_BE_ZERO, admesh_report

    freecad, admesh = require("freecadcmd"), require("admesh")
    solid = barrel_shape(fit_barrel_walls(RIB.program, RIB.follower, RIB.options), RIB.options)
    (tmp_path / "cam.step").write_bytes(barrel_step_bytes(solid, name="rib"))
    (tmp_path / "script.py").write_text(FREECAD_SCRIPT, encoding="utf-8")
    result = run([freecad, "script.py"], cwd=tmp_path)
    lines = [s for s in result.stdout.splitlines() if s.startswith("RESULT ")]
    assert len(lines) == 1, (result.stdout + result.stderr)[-3000:]
    got = json.loads(lines[0][len("RESULT ") :])
    assert got["solids"] == 1 and got["valid"] and got["bsplines"] >= 2
    assert got["volume"] == pytest.approx(barrel_volume(RIB), rel=2e-4)
    mesh = barrel_mesh(RIB.program, RIB.follower, RIB.options)
    (tmp_path / "cam.stl").write_bytes(barrel_stl_bytes(mesh))
    text = run([admesh, "cam.stl"], cwd=tmp_path)
    report = admesh_report(text.stdout + text.stderr)
    assert report["Number of parts"] == [1.0]
    for key in MUST_BE_ZERO:
        assert report[key] == [0.0], key
    assert report["Volume"][0] == pytest.approx(barrel_volume(RIB), rel=1e-3)


def _positions(moves, spacing: float, radius: float) -> tuple[np.ndarray, float]:
    """Tool positions (x, y, a) dense along each feed block (X, Y, A linear within it), and the tip Z."""
    out, tips = [], set()
    for start, end in moves:
        if start[3] == end[3] and start[0] == end[0]:
            continue  # the plunge
        tips.add(end[2])
        length = math.hypot(math.radians(end[3] - start[3]) * radius, end[0] - start[0], end[1] - start[1])
        n = max(2, math.ceil(length / spacing))
        f = np.arange(n)[:, None] / n
        out.append(start[[0, 1, 3]] + f * (end[[0, 1, 3]] - start[[0, 1, 3]]))
    (tip,) = tips
    return np.concatenate(out), tip


def _swept_distance(points: np.ndarray, phi: np.ndarray, pos: np.ndarray, tip: float, r_tip: float, k: float):
    """Signed distance of barrel-frame points from the body a tool sweeps through the positions.

    The tool at (X, Y, A): its axis is the radial line at barrel angle θ = −A offset by y = −Y across it
    at z = X (the program's header convention); its body is the surface of revolution of radius
    r_tip + k·(t − tip) at station t ≥ tip along the axis. A point's signed distance from the flank is
    (ρ − r(t))/√(1 + k²), ρ its distance from the axis; the min over the positions within 0.3 rad of
    the point's own angle is the distance from the swept body (+: outside, −: the tool cut into it).
    """
    theta = -np.radians(pos[:, 2])
    order = np.argsort(theta)
    theta, pos = theta[order], pos[order]
    out = np.full(len(points), np.inf)
    for i, (p, ph) in enumerate(zip(points, phi, strict=True)):
        lo, hi = np.searchsorted(theta, [ph - 0.3, ph + 0.3])
        th, x, y = theta[lo:hi], pos[lo:hi, 0], -pos[lo:hi, 1]
        c, s = np.cos(th), np.sin(th)
        t = p[0] * c + p[1] * s
        across = -p[0] * s + p[1] * c
        rho = np.hypot(across - y, p[2] - x)
        d = (rho - (r_tip + k * (t - tip))) / math.sqrt(1.0 + k * k)
        d[t < tip - 1e-9] = np.inf
        if d.size:
            out[i] = d.min()
    return out


def test_rs274_runs_the_conical_program_and_the_tapered_cutter_sweeps_the_exact_walls(tmp_path):
    """A conical roller's groove: rs274's moves, the tools swept along them, against the exact 3-D walls.

    The tapered cutter's shape comes from the roller alone (taper k = r_f/t_p, apex on the barrel's
    axis, tip radius k·b + c/2 at the groove's bottom b); each exact wall point at the groove's bottom,
    pitch and top stations must lie on its swept body within the program's tolerance, from both walls
    with the one pass; every roughing pass stays at least the stock inside both walls.
    """
    from dataclasses import replace

    from camcad.geometry.barrel import RollerShape, barrel_walls

    rs274 = require("rs274")
    base = CASES["indexer"]
    o = replace(base.options, roller=RollerShape.CONICAL)
    spec = BarrelToolpathOptions(tolerance=0.005)
    tp = plan_barrel(base.program, base.follower, o, spec)
    text = render_barrel_program(tp, name="cone")
    t_p = o.barrel_radius - 0.5 * o.roller_length
    k = o.roller_radius / t_p
    b = o.barrel_radius - o.depth
    r_tip = k * b + 0.5 * o.clearance
    assert f"tip D{2 * r_tip:.4f} at Z{b:.4f}" in text
    assert f"half-angle {math.degrees(math.atan(k)):.4f} deg" in text
    (tmp_path / "cam.ngc").write_text(text, encoding="ascii")
    (tmp_path / "tools.tbl").write_text(f"T1 P1 Z0 D10 ;rough\nT2 P2 Z0 D{2 * r_tip:.4f} ;taper\n", "ascii")
    proc = run([rs274, "-t", "tools.tbl", "-g", "cam.ngc", "canon.txt"], cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    passes = canon_passes((tmp_path / "canon.txt").read_text(encoding="ascii"))
    assert [p["kind"] for p in passes] == ["rough"] * (len(passes) - 1) + ["finish both"]
    phi = np.linspace(0.0, 2.0 * math.pi, 241, endpoint=False) + 1e-3
    stations = np.array([b + 1e-3, t_p, o.barrel_radius])
    walls = barrel_walls(base.program.evaluate(phi), base.follower, o, stations)
    pts = np.concatenate([w.point.reshape(-1, 3) for w in (walls.upper, walls.lower)])
    ph = np.tile(np.repeat(phi, stations.size), 2)
    worst_rough = np.inf
    for p in passes:
        pos, tip = _positions(p["moves"], 0.05, o.barrel_radius)
        if p["kind"] == "finish both":
            assert tip == pytest.approx(b, abs=1e-4)
            d = _swept_distance(pts, ph, pos, tip, r_tip, k)
            print("cone finish", float(d.min()), float(d.max()))
            # 4-decimal words and 0.05 mm position spacing (a sampled minimum over by < 1e-4 mm)
            assert np.all(np.abs(d) <= spec.tolerance + 3e-4)
        else:
            d = _swept_distance(pts, ph, pos, tip, 0.5 * spec.rough_diameter, 0.0)
            worst_rough = min(worst_rough, float(d.min()))
    assert worst_rough >= spec.stock - spec.tolerance - 1e-4
    # roughing plans for the cylinder of the tip's radius: at the pitch station (the lowest measured above
    # the last level) it leaves the stock plus the cone's widening k·(t_p − b) there, no more
    assert worst_rough <= spec.stock + k * (t_p - b) + 0.05


def test_rs274_roughing_clears_the_groove_to_the_stock_and_the_flanks_estimate(tmp_path):
    """The roughing cutter's stepover passes, rebuilt from rs274's moves, in the developed plane.

    At the pitch station and the top (above every level's tip): every point across the groove within
    the stock of the walls is inside some roughing disc (the stepover leaves no ridge), and what the
    discs leave on each wall lies between the stock and the stock plus the outermost pass's flank
    error: its axis is δ = r_w − r_c − stock off the path along the pitch station's normal, so on the
    steepest flank it leaves δ(1 − cos(β_t − β_p)) more, tan β = s′/t (a 1 % margin for the turn's
    largest, just off the steepest point, as test_barrel_toolpath measures).
    """
    rs274 = require("rs274")
    c, tp = CASES["indexer"], planned("indexer")
    (tmp_path / "cam.ngc").write_text(render_barrel_program(tp, name="indexer"), encoding="ascii")
    (tmp_path / "tools.tbl").write_text("T1 P1 Z0 D10 ;rough\nT2 P2 Z0 D16 ;finish\n", encoding="ascii")
    proc = run([rs274, "-t", "tools.tbl", "-g", "cam.ngc", "canon.txt"], cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    rough = [
        p for p in canon_passes((tmp_path / "canon.txt").read_text(encoding="ascii")) if p["kind"] == "rough"
    ]
    o, spec = c.options, tp.options
    r_w, r_c = o.roller_radius + 0.5 * o.clearance, 0.5 * spec.rough_diameter
    reach = r_w - r_c - spec.stock
    shifts = sorted({round(p.shift, 9) for p in tp.passes if p.kind == "rough"})
    assert len(shifts) >= 2 and np.max(np.diff(shifts)) <= spec.stepover * spec.rough_diameter + 1e-12
    phi = np.linspace(0.0, 2.0 * math.pi, 20_001)
    motion = c.program.evaluate(phi)
    v_star = float(np.max(motion.v))
    for t in (o.pitch_station, o.barrel_radius):
        axes = [centres(p["moves"], t) for p in rough]
        pts = np.concatenate([a for a, tip in axes if tip <= t])
        period = np.array([2.0 * math.pi * t, 0.0])
        tree = cKDTree(np.vstack((pts - period, pts, pts + period)))
        walls = developed_walls(motion, c.follower, o, t)
        for wall in (walls.upper.point, walls.lower.point):
            left = tree.query(wall)[0] - r_c
            flank = reach * (1.0 - math.cos(math.atan(v_star / t) - math.atan(v_star / o.pitch_station)))
            assert left.min() >= spec.stock - spec.tolerance - 1e-3
            assert left.max() <= spec.stock + 1.01 * flank + spec.tolerance + 1e-3
        # across the groove, the pitch line and its offsets up to the stock from the walls: all cut
        for frac in np.linspace(-1.0, 1.0, 9):
            inside = walls.pitch.point + frac * (r_w - spec.stock - 0.05) * walls.pitch.normal
            assert tree.query(inside)[0].max() < r_c
