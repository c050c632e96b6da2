import base64
import math
import re
import subprocess
import sys
from dataclasses import replace
from html.parser import HTMLParser
from pathlib import Path
from xml.etree import ElementTree

import pytest

from camcad.design import load_design
from camcad.pipeline import analyse, build
from camcad.report import (
    alerts_html,
    compare_table,
    key_numbers_html,
    render_compare,
    render_report,
    write_compare,
    write_report,
)
from camcad.report_tables import fmt, label, quantity_rows, split_unit

SAMPLES = Path(__file__).resolve().parents[1] / "samples"
N_REPORT_PLOTS = 7  # profile, motion, pressure angle, curvature, dynamics, fit error, solid (no toolpath)
SVG_NS = "{http://www.w3.org/2000/svg}"


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


def assert_svg(src: str | None) -> bytes:
    """An embedded SVG that an XML parser reads, with drawn paths and text kept as text."""
    prefix = "data:image/svg+xml;base64,"
    assert src is not None and src.startswith(prefix)
    data = base64.b64decode(src[len(prefix) :], validate=True)
    root = ElementTree.fromstring(data)
    assert root.tag == f"{SVG_NS}svg"
    assert len(root.findall(f".//{SVG_NS}path")) > 10  # a real plot, not an empty canvas
    return data


def test_figure_labels_are_text(page):
    """Axis labels stay text in the SVG (crisp in print, found by pdftotext), with a generic font fallback."""
    src = next(i["src"] for i in parse(page).images if i["alt"] == "Cam profile (to scale)")
    root = ElementTree.fromstring(assert_svg(src))
    texts = ["".join(t.itertext()) for t in root.iter(f"{SVG_NS}text")]
    assert "x [mm]" in texts and "y [mm]" in texts


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
        assert_svg(image["src"])
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
    assert "limits broken" not in text  # the sample meets every limit; its notes are the joints' jumps


def test_report_tables_show_every_summary_number_in_words(analysis, page):
    """Every number of summary.json is in the tables under a human label with its unit; no raw keys."""
    text = parse(page).plain
    summary = analysis.summary()
    for section in ("motion", "geometry", "dynamics", "fit"):
        for key, value in summary[section].items():
            if key == "joints" or key.endswith(("_angle_deg", "_side")):
                continue
            assert label(key) in text or label(key).replace("[mm]", "[µm]") in text, key
            assert "_" not in key or key not in text, f"raw key {key} shown"
            if isinstance(value, float) and abs(value) >= 0.01:
                assert fmt(value, split_unit(key)[1]) in text, (key, value)
    assert "max |a| [mm/rad²]" in text and "a_max_abs" not in text
    for joint in summary["motion"]["joints"]:
        assert f"{joint['angle_deg']:.2f}" in text


def test_labels_and_precision():
    """Labels carry units; numbers have 4 significant digits, angles 0.01°, tiny lengths in µm."""
    assert label("a_max_abs_mm_per_rad2") == "max |a| [mm/rad²]"
    assert label("torque_max_Nmm") == "max input torque [N·mm]"
    assert label("something_new_MPa") == "something new [MPa]"
    assert fmt(0.000794357) == "0.0007944" and fmt(151.419) == "151.4" and fmt(13.53477, "°") == "13.53"
    section = {"max_error_mm": 0.000794357, "torque_max_Nmm": 151.4}
    section |= {"torque_max_angle_deg": 123.03, "torque_max_side": "after joint"}
    rows = quantity_rows(section)
    assert rows == [("certified max error [µm]", "0.7944", ""),
                    ("max input torque [N·mm]", "151.4", "at 123.0° (just after joint)")]  # fmt: skip


def test_acceleration_jumps_reach_the_banner_with_the_force_step():
    """Harmonic rise into a dwell: a(β⁻) = −π²h/(2β²) (Norton 2009, §8.3), a jump the banner states in N.

    The force step is m·Δa·ω² by hand from the design's mass and speed.
    """
    design = load_design(SAMPLES / "quintero_harmonic.toml")
    rise, dwell = design.motion[0], design.motion[1]
    assert rise.kind.value == "rise" and dwell.kind.value == "dwell"
    da = math.pi**2 * rise.lift / (2.0 * rise.span**2)  # mm/rad², from −π²h/(2β²) to 0
    omega = 2.0 * math.pi * design.cam.speed_rpm / 60.0
    step = design.dynamics.follower_mass * da * 1e-3 * omega**2  # N
    page = parse(render_report(analyse(design, fit=False, toolpath=False))).plain
    banner = page[: page.index("Plots")]
    at = f"φ = {math.degrees(rise.span):.1f}°"
    assert f"acceleration jumps by {float(f'{da:.3g}'):g} mm/rad² at {at}" in banner
    assert f"steps by {float(f'{step:.3g}'):g} N at {design.cam.speed_rpm:g} rpm" in banner
    assert "what it means for the machine" in page


def test_report_lists_every_warning_escaped(warned):
    assert warned.findings, "the 10° limit should be exceeded"
    page = render_report(warned)
    parsed = parse(page)
    assert "<b>tight</b>" not in page
    assert warned.design.cam.name in parsed.plain
    for finding in warned.findings:
        assert " ".join(finding.message.split()) in parsed.plain
    assert "Soft limits broken (1)" in parsed.plain  # the pressure angle, a soft limit
    assert "pressure angle (soft limit, cam.max_pressure_angle)" in parsed.plain
    # the warnings come before the plots
    assert page.index('id="warnings"') < page.index('id="plots"')
    assert "not run" in parsed.plain  # no fit
    assert len(parsed.images) == N_REPORT_PLOTS - 1  # no fit, no fit-error figure


EVIL_NAME = "<script>alert(\"x\")</script><img src=x onerror=alert(1)> \x01 & 'q'"


def test_a_script_in_the_design_name_is_inert(analysis):
    """The templates escape every value (autoescape): a name with markup stays text, in every page."""
    cam = replace(analysis.design.cam, name=EVIL_NAME)
    evil = replace(analysis, design=replace(analysis.design, cam=cam))
    for page in (render_report(evil), render_compare([evil, analysis])):
        assert_offline(page)  # no <script anywhere
        parsed = parse(page)
        assert "script" not in parsed.tags and "onerror" not in {name for name, _ in parsed.attrs}
        assert parsed.tags.count("img") == len(parsed.images)
        assert all(img["src"].startswith("data:image/") for img in parsed.images)  # only the figures
        shown = EVIL_NAME.replace("\x01", "\ufffd")  # a control character becomes U+FFFD
        assert " ".join(shown.split()) in parsed.plain
    fragments = key_numbers_html(evil) + alerts_html(evil)
    assert "<script" not in fragments and "onerror=" not in fragments.replace("onerror=alert", "")


def test_the_templates_ship_as_package_data():
    """Every file of camcad/templates is matched by pyproject's package data (so a wheel holds it)."""
    import fnmatch

    from camcad.design.schema import tomllib  # tomllib, or tomli on Python 3.10

    root = SAMPLES.parent
    config = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))
    patterns = config["tool"]["setuptools"]["package-data"]["camcad"]
    shipped = sorted((root / "camcad" / "templates").iterdir())
    assert {p.suffix for p in shipped} >= {".j2", ".css"}
    for path in shipped:
        rel = path.relative_to(root / "camcad").as_posix()
        assert any(fnmatch.fnmatch(rel, pat) for pat in patterns), rel
    assert any(dep.startswith("jinja2") for dep in config["project"]["dependencies"])


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
        assert_svg(image["src"])
    out = write_compare(analyses, tmp_path / "compare.html")
    assert out.read_text(encoding="utf-8") == page


def test_render_compare_needs_a_design():
    with pytest.raises(ValueError, match="at least one"):
        render_compare([])


def _count_blocks_and_arcs(text: str) -> tuple[int, int]:
    """Blocks (lines with a word outside comments) and arc moves (G2/G3 modal) of a G-code text."""
    blocks = arcs = 0
    mode = None
    for line in text.splitlines():
        words = re.findall(r"([A-Z])\s*([-+]?[0-9.]+)", re.sub(r"\(.*?\)|;.*", "", line).upper())
        if not words:
            continue
        blocks += 1
        for letter, number in words:
            if letter == "G" and float(number) in (0.0, 1.0, 2.0, 3.0):
                mode = int(float(number))
        if mode in (2, 3) and any(letter in "XYZ" for letter, _ in words):
            arcs += 1
    return blocks, arcs


def test_report_shows_the_programs_figures(analysis, tmp_path):
    """The G-code table of a built report: blocks and arcs as counted here in the cam.ngc beside it."""
    build(analysis.design, tmp_path, only=["gcode", "report"])
    blocks, arcs = _count_blocks_and_arcs((tmp_path / "cam.ngc").read_text(encoding="utf-8"))
    assert blocks > 100 and arcs > 50  # a real program, not an empty one
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert 'id="table-gcode"' in page
    table = page[page.index('id="table-gcode"') :]
    section = parse(table[table.index("<table>") : table.index("</table>") + 8]).plain
    assert f"blocks {blocks} " in section and f"arc moves {arcs} " in section
    for key in ("cutting_length_mm", "cycle_time_s", "max_deviation_mm"):
        assert label(key) in section or label(key).replace("[mm]", "[µm]") in section
