import base64
import math
import subprocess
import sys
from dataclasses import replace
from html.parser import HTMLParser
from pathlib import Path

import pytest

from camcad.design import load_design
from camcad.pipeline import analyse
from camcad.report import compare_table, render_compare, render_report, write_compare, write_report

SAMPLES = Path(__file__).resolve().parents[1] / "samples"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
N_REPORT_PLOTS = 5  # profile, motion, pressure angle, curvature, dynamics


class _Page(HTMLParser):
    """Collects the text, the tags and the attributes of a page; fails on unbalanced tags."""

    VOID = frozenset({"meta", "img", "br", "hr", "link", "input"})

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.text: list[str] = []
        self.tags: list[str] = []
        self.images: list[dict[str, str | None]] = []
        self.attrs: list[tuple[str, str | None]] = []
        self.stack: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.attrs += attrs
        if tag == "img":
            self.images.append(dict(attrs))
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        assert self.stack and self.stack[-1] == tag, f"unbalanced </{tag}> (open: {self.stack[-3:]})"
        self.stack.pop()

    def handle_data(self, data):
        self.text.append(data)

    @property
    def plain(self) -> str:
        return " ".join(" ".join(self.text).split())


def parse(page: str) -> _Page:
    parser = _Page()
    parser.feed(page)
    parser.close()
    assert not parser.stack, f"unclosed tags: {parser.stack}"
    return parser


def assert_png(src: str | None) -> None:
    prefix = "data:image/png;base64,"
    assert src is not None and src.startswith(prefix)
    data = base64.b64decode(src[len(prefix) :], validate=True)
    assert data.startswith(PNG_SIGNATURE)
    assert len(data) > 10_000  # a real plot, not an empty canvas


def assert_offline(page: str) -> None:
    lowered = page.lower()
    assert "http://" not in lowered and "https://" not in lowered
    assert "<script" not in lowered and "<link" not in lowered and "@import" not in lowered
    assert "url(" not in lowered


@pytest.fixture(scope="module")
def analysis():
    return analyse(load_design(SAMPLES / "quintero_vap_b01.toml"), toolpath=False)


@pytest.fixture(scope="module")
def page(analysis):
    return render_report(analysis)


@pytest.fixture(scope="module")
def warned():
    """A design with a markup-like name and a pressure-angle limit it breaks."""
    design = load_design(SAMPLES / "quintero_vap_b01.toml")
    cam = replace(design.cam, name='<b>tight</b> & "limit"', max_pressure_angle=math.radians(10.0))
    return analyse(replace(design, cam=cam), fit=False, toolpath=False)


def test_report_parses_with_name_and_plots(analysis, page):
    parsed = parse(page)
    assert parsed.tags[0] == "html"
    assert analysis.design.cam.name in parsed.plain
    assert len(parsed.images) == N_REPORT_PLOTS
    for image in parsed.images:
        assert_png(image["src"])
        assert image["alt"]


def test_report_is_self_contained(page):
    assert_offline(page)
    parsed = parse(page)
    sources = [v for k, v in parsed.attrs if k in {"src", "href"}]
    assert all(v is not None and v.startswith("data:") for v in sources)


def test_report_shows_key_numbers(analysis, page):
    summary = analysis.summary()
    text = parse(page).plain
    assert f"{summary['geometry']['pressure_angle_max_deg']:.2f}°" in text
    assert f"limit {math.degrees(analysis.geometry.max_pressure_angle):.2f}°" in text
    assert f"{summary['motion']['lift_mm']:.3f} mm" in text
    assert f"{summary['geometry']['curvature_radius_min_mm']:.3f} mm" in text
    assert f"{summary['dynamics']['torque_max_Nmm']:.2f} N·mm" in text
    assert f"{summary['dynamics']['contact_force_max_N']:.3f} N" in text
    assert f"{summary['dynamics']['hertz_stress_max_MPa']:.2f} MPa" in text
    assert f"{summary['fit']['control_points']} control points" in text
    assert "No warnings" in text


def test_report_tables_cover_every_summary_section(analysis, page):
    text = parse(page).plain
    summary = analysis.summary()
    for section in ("motion", "geometry", "dynamics", "fit"):
        for key in summary[section]:
            if key not in {"warnings", "joints"}:
                assert key in text, f"{section}.{key} missing from the tables"
    for joint in summary["motion"]["joints"]:
        assert joint["text"] in text


def test_report_lists_every_warning_escaped(warned):
    assert warned.warnings, "the 10° limit should be exceeded"
    page = render_report(warned)
    parsed = parse(page)
    assert "<b>tight</b>" not in page
    assert warned.design.cam.name in parsed.plain
    for warning in warned.warnings:
        assert " ".join(warning.split()) in parsed.plain
    assert "Design limits violated" in parsed.plain
    # the warnings come before the plots
    assert page.index('id="warnings"') < page.index('id="plots"')
    assert "not run" in parsed.plain  # no fit
    assert len(parsed.images) == N_REPORT_PLOTS


def test_render_is_deterministic(analysis, page):
    assert render_report(analysis) == page


def test_write_report_matches_render(analysis, page, tmp_path):
    out = write_report(analysis, tmp_path / "report.html")
    assert out == tmp_path / "report.html"
    assert out.read_text(encoding="utf-8") == page


def test_report_draws_without_pyplot():
    code = (
        "import sys; from camcad.design import load_design; from camcad.pipeline import analyse; "
        "from camcad.report import render_report; "
        f"a = analyse(load_design({str(SAMPLES / 'hren_tappet.toml')!r}), fit=False, toolpath=False); "
        "render_report(a); assert 'matplotlib.pyplot' not in sys.modules, 'pyplot was imported'"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr


@pytest.fixture(scope="module")
def quintero():
    stems = ["quintero_vap_b01", "quintero_harmonic", "quintero_poly4567", "quintero_vap_b02"]
    assert sorted(p.stem for p in SAMPLES.glob("quintero_*.toml")) == sorted(stems)
    return {stem: analyse(load_design(SAMPLES / f"{stem}.toml"), toolpath=False) for stem in stems}


def test_compare_table_orders_pressure_angles(quintero):
    analyses = list(quintero.values())
    table = compare_table(analyses)
    assert table[0] == ["quantity", *(a.design.cam.name for a in analyses)]
    assert all(len(row) == len(analyses) + 1 for row in table)
    assert all(isinstance(cell, str) for row in table for cell in row)
    labels = [row[0] for row in table[1:]]
    assert len(labels) == 10
    row = next(r for r in table if r[0].startswith("max pressure angle"))
    alpha = dict(zip(quintero, map(float, row[1:]), strict=True))
    assert alpha["quintero_vap_b01"] < alpha["quintero_harmonic"] < alpha["quintero_poly4567"]
    lift = next(r for r in table if r[0].startswith("lift"))
    assert set(lift[1:]) == {"30.000"}


def test_render_compare(quintero, tmp_path):
    analyses = list(quintero.values())
    page = render_compare(analyses)
    assert_offline(page)
    parsed = parse(page)
    for analysis in analyses:
        assert analysis.design.cam.name in parsed.plain
    for row in compare_table(analyses):
        assert " ".join(row) in " ".join(parsed.plain.split())
    assert parsed.images
    for image in parsed.images:
        assert_png(image["src"])
    out = write_compare(analyses, tmp_path / "compare.html")
    assert out.read_text(encoding="utf-8") == page


def test_render_compare_needs_a_design():
    with pytest.raises(ValueError, match="at least one"):
        render_compare([])


class _Program:
    """Stands in for the rendered G-code program: only its summary is rendered."""

    def summary(self):
        return {
            "blocks": 1234,
            "arcs": 56,
            "cutting_length_mm": 812.5,
            "max_deviation_mm": 0.004,
            "passes": [{"z_mm": -3.0, "kind": "rough"}, {"z_mm": -6.0, "kind": "<finish>"}],
            "tool": {"diameter_mm": 10.0, "number": 1},
        }


def test_report_renders_gcode_section(analysis):
    page = render_report(replace(analysis, gcode=_Program()))
    parsed = parse(page)
    assert 'id="table-gcode"' in page
    assert "<finish>" not in page and "<finish>" in parsed.plain
    for key in ("blocks", "1234", "cutting_length_mm", "812.5", "max_deviation_mm", "diameter_mm"):
        assert key in parsed.plain
