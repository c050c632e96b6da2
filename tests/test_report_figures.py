"""The report's pictures against independent truths: the fit's certificate and knots, the exact
tool-centre curve, the manifold3d mesh; the compare text in 100 columns; bytes across processes."""

import hashlib
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from camcad._plots.chart import Panel, Series, _m4, line_chart, nice_ticks
from camcad._plots.shop import fit_error_along_profile, project_oblique, solid_faces, toolpath_layers
from camcad.design import load_design
from camcad.export.mesh import build_solid
from camcad.pipeline import analyse
from camcad.report import compare_table, compare_text

SAMPLES = Path(__file__).resolve().parents[1] / "samples"


@pytest.fixture(scope="module")
def built():
    return analyse(load_design(SAMPLES / "quintero_vap_b01.toml"))


def test_fit_error_within_certificate_and_knots_at_the_joints(built):
    """Sampled error ≤ the certified bound (and reaches most of it); a knot at every motion joint."""
    phi, error, knots = fit_error_along_profile(built.cam, built.fit)
    assert np.all(np.abs(error) <= built.fit.max_error * (1 + 1e-9))
    assert np.abs(error).max() >= 0.5 * built.fit.max_error  # the picture shows the real error
    # the distance to the curve measured independently: nearest of 2·10⁶ curve points
    curve = built.fit.curve.evaluate(np.linspace(0.0, 1.0, 2_000_000, endpoint=False))
    dist, _ = cKDTree(curve).query(np.asarray(built.cam.profile(phi).point))
    assert np.allclose(np.abs(error), dist, atol=2e-4)  # spacing ≈ 0.2 µm: nearest point within 0.1 µm
    for bp in built.cam.program.breakpoints:
        gap = np.abs((knots - bp.phi + math.pi) % (2 * math.pi) - math.pi).min()
        assert gap < math.radians(0.05), f"no knot at the joint {math.degrees(bp.phi):.2f}°"


def test_toolpath_layers_follow_the_exact_tool_centre_curve(built):
    """Finishing moves lie within the certified deviation of cam.offset_curve(φ, r_tool), leads, tabs too."""
    path = built.toolpath
    layers = toolpath_layers(path)
    passes = len(path.levels) + 1
    assert len(layers["lead"]) == 2 * passes  # one lead in and one lead out per pass
    below = sum(1 for z in path.levels if z < path.tab_top) + 1 if path.tab_top is not None else 0
    assert len(layers["tab"]) >= path.spec.tab_count * below > 0
    phi = np.linspace(0, 2 * math.pi, 400_000, endpoint=False)
    exact = np.asarray(built.cam.offset_curve(phi, path.tool_radius).point)
    tree = cKDTree(exact)
    finish = np.vstack(layers["finishing"])
    dist, _ = tree.query(finish)
    assert dist.max() <= path.max_deviation + 2e-3
    rough = np.vstack(layers["roughing"])
    dist_rough, _ = tree.query(rough)
    assert dist_rough.min() > 0.5 * (path.rough_offset - path.tool_radius)  # roughing leaves the stock


def test_solid_view_outline_matches_the_mesh(built):
    """The drawn solid's projected extent equals that of the STL mesh (manifold3d) in the same view."""
    design = built.design
    solid = build_solid(built.fit, design.plate(), design.mesh, cam=built.cam)
    screen, _ = project_oblique(np.asarray(solid.mesh.vertices))
    faces = solid_faces(built)
    drawn = np.vstack([faces["top"], *faces["walls"]])
    assert np.allclose(drawn.min(axis=0), screen.min(axis=0), atol=0.05)
    assert np.allclose(drawn.max(axis=0), screen.max(axis=0), atol=0.05)


def test_compare_text_fits_100_columns():
    """Four long-named designs: every line ≤ 100 columns, every value and every name shown."""
    paths = sorted(SAMPLES.glob("quintero_*"))
    analyses = [analyse(load_design(p), fit=False, toolpath=False) for p in paths]
    text = compare_text(analyses)
    assert max(len(line) for line in text.splitlines()) <= 100
    for row in compare_table(analyses)[1:]:
        line = next(ln for ln in text.splitlines() if ln.startswith(row[0]))
        assert line.split()[-len(row) + 1 :] == row[1:]
    for a in analyses:
        assert a.design.cam.name in text


def test_report_bytes_equal_across_processes(tmp_path):
    """Two processes render the same report byte for byte (SVG ids salted, no dates, no timings)."""
    code = (
        "import hashlib, sys; from camcad.design import load_design; from camcad.pipeline import analyse; "
        "from camcad.report import render_report; "
        f"a = analyse(load_design({str(SAMPLES / 'hren_tappet.toml')!r}), toolpath=False); "
        "print(hashlib.sha256(render_report(a).encode()).hexdigest())"
    )
    run = [sys.executable, "-c", code]
    runs = [subprocess.run(run, capture_output=True, text=True, timeout=120) for _ in "ab"]
    assert all(r.returncode == 0 for r in runs), runs[0].stderr
    assert runs[0].stdout == runs[1].stdout and len(runs[0].stdout.strip()) == 64
    assert hashlib  # the digest is computed in the child processes


@settings(max_examples=200, deadline=None)
@given(
    lo=st.floats(min_value=-1e6, max_value=1e6),
    span=st.floats(min_value=1e-6, max_value=1e7),
    most=st.integers(min_value=3, max_value=10),
)
@example(lo=879609.9999999999, span=1e-06, most=6)  # the last tick lies one ulp of 8.8e5 beyond hi
def test_nice_ticks_cover_the_range_evenly(lo, span, most):
    """Ticks lie in [lo, hi], at most about `most`, evenly spaced by 1, 2, 2.5 or 5 × 10^k, labels exact.

    [lo, hi] to float resolution: a few ulps of the range's magnitude besides 1e-9 of its span, since
    hi = lo + span and every tick k × step are rounded there (a span of 1e-6 at 8.8e5 is 8600 ulps).
    """
    hi = lo + span
    ticks, decimals = nice_ticks(lo, hi, most)
    slack = 1e-9 * span + 4.0 * math.ulp(max(abs(lo), abs(hi)))
    assert ticks and all(lo - slack <= t <= hi + slack for t in ticks)
    assert len(ticks) <= most + 2
    if len(ticks) > 1:
        step = round((ticks[-1] - ticks[0]) / (len(ticks) - 1), decimals + 2)  # float cancellation far from 0
        assert np.allclose(np.diff(ticks), step, rtol=1e-3)
        mantissa = step / 10 ** math.floor(math.log10(step) + 1e-9)
        assert min(abs(mantissa - m) for m in (1, 2, 2.5, 5, 10)) < 1e-4
        assert float(f"{step:.{decimals}f}") == pytest.approx(step, rel=1e-4)  # the labels show the step


@settings(max_examples=100, deadline=None)
@given(seed=st.integers(min_value=0, max_value=2**32 - 1), columns=st.integers(min_value=10, max_value=700))
def test_m4_keeps_every_columns_extremes(seed, columns):
    """Thinned curves keep each pixel column's lowest and highest value (brute force over all samples)."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(0.0, 360.0, 5000))
    y = np.cumsum(rng.normal(size=5000))
    y[rng.integers(0, 5000, 20)] = np.nan
    keep = _m4(x, y, columns)
    bucket = np.minimum(((x - x[0]) / (x[-1] - x[0]) * columns).astype(int), columns - 1)
    for b in np.unique(bucket):
        every = y[bucket == b]
        kept = y[keep][bucket[keep] == b]
        if np.isfinite(every).any():
            assert np.nanmin(kept) == np.nanmin(every) and np.nanmax(kept) == np.nanmax(every)


def test_line_chart_is_well_formed_svg_with_text():
    """The chart parses as XML, names its axes in text, and breaks the curve at a gap (two sub-paths)."""
    from xml.etree import ElementTree

    x = np.linspace(0.0, 360.0, 721)
    y = np.where((x > 100) & (x < 120), np.nan, np.sin(np.radians(x)))
    svg = line_chart([Panel(ylabel="s [mm]", series=[Series(x=x, y=y, color="#000")])], title="t <&>")
    root = ElementTree.fromstring(svg)
    texts = ["".join(t.itertext()) for t in root.iter("{http://www.w3.org/2000/svg}text")]
    assert "s [mm]" in texts and "cam angle φ [°]" in texts and "360" in texts
    curve = [p for p in root.iter("{http://www.w3.org/2000/svg}path") if p.get("stroke") == "#000"]
    assert len(curve) == 1 and curve[0].get("d").count("M") == 2
