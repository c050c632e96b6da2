"""The report and the compare page in a real browser: headless Chromium at three widths and in print.

Checked against the browser's own layout: no horizontal scroll from 400 to
1600 px (``scrollWidth ≤ clientWidth``), every image decoded
(``naturalWidth > 0``), no table wider than its page; printed to PDF on A4
and Letter (Chrome DevTools ``Page.printToPDF``) the page count is small and
``pdftotext`` finds the cam drawing's caption and the key numbers on page 1.
"""

from __future__ import annotations

import base64
import shutil
import subprocess
from pathlib import Path

import pytest

from camcad.design import load_design
from camcad.pipeline import analyse
from camcad.report import write_compare, write_report
from tests.readers.browser import chromium

pytestmark = pytest.mark.slow

SAMPLES = Path(__file__).resolve().parents[2] / "samples"
WIDTHS = (400, 500, 800, 1024, 1400, 1600)  # the issue's widths and the brief's
PAPERS = {"A4": (8.27, 11.69), "Letter": (8.5, 11.0)}
MAX_PAGES = 8

_LAYOUT = """
const root = document.scrollingElement;
const images = [...document.images];
const tables = [...document.querySelectorAll('table')].filter(t => !t.parentElement.closest('table'));
return {
  scroll: root.scrollWidth, client: root.clientWidth,
  images: images.length, broken: images.filter(i => !(i.complete && i.naturalWidth > 0)).length,
  overflowing: tables.filter(t => t.getBoundingClientRect().right > root.clientWidth + 1
                                   && !t.closest('.scroll')).length,
};
"""


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pages")
    out = {"report": write_report(analyse(load_design(SAMPLES / "quintero_vap_b01.toml")), folder / "r.html")}
    for name, stem in (("tappet", "hren_tappet"), ("rocker", "rocker_flat")):  # flat faces: slide and arm
        out[name] = write_report(
            analyse(load_design(SAMPLES / f"{stem}.toml"), toolpath=False), folder / f"{name}.html"
        )
    paths = sorted(SAMPLES.glob("quintero_*"))
    analyses = [analyse(load_design(p), fit=False, toolpath=False) for p in paths]
    out["compare"] = write_compare(analyses, folder / "compare.html")
    return out


@pytest.fixture(scope="module")
def browser():
    with chromium() as driver:
        yield driver


@pytest.mark.parametrize("name", ["report", "tappet", "rocker", "compare"])
@pytest.mark.parametrize("width", WIDTHS)
def test_no_horizontal_scroll_and_every_image_loads(browser, pages, name, width):
    browser.set_window_size(width, 900)
    browser.get(pages[name].as_uri())
    layout = browser.execute_script(_LAYOUT)
    assert layout["scroll"] <= layout["client"], f"{name} scrolls sideways at {width} px: {layout}"
    assert layout["images"] >= 6 and layout["broken"] == 0, layout
    assert layout["overflowing"] == 0, layout


def _pdf(browser, path: Path, paper: tuple[float, float]) -> bytes:
    browser.get(path.as_uri())
    width, height = paper
    out = browser.execute_cdp_cmd(
        "Page.printToPDF", {"paperWidth": width, "paperHeight": height, "printBackground": True}
    )
    return base64.b64decode(out["data"])


@pytest.mark.parametrize("paper", sorted(PAPERS))
def test_print_is_short_with_drawing_and_key_numbers_on_page_one(browser, pages, paper, tmp_path):
    if shutil.which("pdftotext") is None or shutil.which("pdfinfo") is None:
        pytest.skip("pdftotext/pdfinfo not installed (apt-get install poppler-utils)")
    pdf = tmp_path / "report.pdf"
    pdf.write_bytes(_pdf(browser, pages["report"], PAPERS[paper]))
    info = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True, check=True).stdout
    count = int(next(line.split()[-1] for line in info.splitlines() if line.startswith("Pages:")))
    assert 2 <= count <= MAX_PAGES, f"{count} pages on {paper}"
    first = subprocess.run(
        ["pdftotext", "-f", "1", "-l", "1", str(pdf), "-"], capture_output=True, text=True, check=True
    ).stdout
    flat = " ".join(first.split())
    assert "Cam profile (to scale)" in flat  # the drawing's caption
    for label in ("MAX PRESSURE ANGLE", "BASE RADIUS", "MAX CONTACT FORCE", "NURBS FIT", "13.53°"):
        assert label in flat, f"{label} not on page 1 ({paper})"
    # the tables are not clipped: the joint table's last column (the meaning) is printed in full
    text = subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True, check=True).stdout
    assert "what it means for the machine" in " ".join(text.split())


def test_printed_fe_case_table_keeps_words_whole_and_its_last_column(tmp_path):
    """Issue 31: in print the FE load-case table wrapped "where" one letter per line and clipped its last
    column, and the "value" header wrapped. Printed by ``chromium --headless --print-to-pdf``, read back
    by pdftotext: every header word and every word of the "where" cells is whole, the last column's
    header and every case's value in it are on the page, and page 1 goes on into the plots."""
    pytest.importorskip("gmsh")
    pytest.importorskip("skfem")
    binary = shutil.which("chromium") or shutil.which("chromium-browser")
    if binary is None or shutil.which("pdftotext") is None:
        pytest.skip("chromium or pdftotext not installed")
    from camcad.report_tables import fmt, label, split_unit

    analysis = analyse(load_design(SAMPLES / "fea_plate.toml"), fea=True, toolpath=False)
    page = write_report(analysis, tmp_path / "report.html")
    pdf = tmp_path / "report.pdf"
    run = subprocess.run(
        [binary, "--headless", "--no-sandbox", "--disable-gpu", "--no-pdf-header-footer",
         f"--print-to-pdf={pdf}", page.as_uri()],
        capture_output=True, text=True, timeout=180,
    )  # fmt: skip
    assert pdf.is_file(), run.stderr[-2000:]
    text = subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True, check=True).stdout
    words = set(text.split())
    cases = analysis.summary()["fea"]["cases"]
    keys = list(cases[0])
    for key in keys:  # header words, e.g. "reaction", "moment", "[N·mm]"
        for word in label(key).split():
            assert word in words, f"header word {word!r} of {key!r} broken or missing"
    for case in cases:
        for word in str(case.get("von_mises_max_where", "")).replace(",", " ").split():
            assert word in words or f"{word}," in words, word
        last = fmt(case.get(keys[-1]), split_unit(keys[-1])[1])
        assert all(part in text for part in last.replace(",", " ").split()), (keys[-1], last)
    assert "value" in words  # the quantity tables' header, unbroken
    # page 1 is filled: the first plot follows the key numbers (it left 40 % of the page empty)
    first = subprocess.run(["pdftotext", "-f", "1", "-l", "1", str(pdf), "-"], capture_output=True, text=True)
    assert "Follower motion." in first.stdout
