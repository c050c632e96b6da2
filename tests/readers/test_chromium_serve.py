"""The live designer in a real browser: headless Chromium against ``camcad serve`` on a free loopback port.

Checked against the Python API on the same design: after the base radius is
typed into the page, the key numbers and the drawing show what
``analyse()`` computes for that design, a figure is redrawn with the new
values, an invalid value shows the loader's own message next to its field,
and Save writes a file ``load_design`` reads back. No horizontal scroll at
400, 500 and 1600 px.

The designer's editing (issue 37), each checked against the loader and the
Python API on the file the page saved: every shipped sample opens valid with
its cam family drawn (a groove as a groove, both plates of a pair) and its
cards agreeing with the banner; segments added, dragged and deleted are the
[[motion]] tables tomllib reads back and the cam ``analyse()`` rebuilds; an
uploaded table is written beside the design byte for byte and its points
drawn; follower and family switch; invalid input marks every card and chart
out of date; a pinned design's curves are overlaid; TAB reaches every control
and every control has a name.
"""

from __future__ import annotations

import shutil
import sys
import threading
import time
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from camcad.design import load_design
from camcad.errors import DesignError
from camcad.pipeline import analyse
from tests.conftest import ROOT, serving
from tests.readers.browser import chromium

pytestmark = pytest.mark.slow

WAIT = 60.0  # s, for one analysis to come back under a loaded CI machine
SETTLED = "document.body.dataset.busy === '0'"  # every change typed has been analysed and drawn


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    with serving(tmp_path_factory.mktemp("serve")) as (_, url, design):
        yield url, design


@pytest.fixture(scope="module")
def browser():
    with chromium() as driver:
        yield driver


def _wait_for(browser, condition: str, what: str) -> None:
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        if browser.execute_script(f"return Boolean({condition})"):
            return
        time.sleep(0.05)
    status = browser.execute_script("return document.getElementById('status').textContent")
    raise AssertionError(f"timed out waiting for {what} (status: {status!r})")


def _shown(browser) -> dict:
    return browser.execute_script(
        """
        const card = label => [...document.querySelectorAll('#cards .card')]
          .find(c => c.querySelector('.label').firstChild.textContent.toLowerCase() === label);
        const svg = document.querySelector('#cam-drawing svg');
        const chart = document.querySelector('#chart-pressure');
        return {
          revision: +document.body.dataset.revision, state: document.body.dataset.state,
          alpha: card('max pressure angle').querySelector('.value').textContent,
          base: card('base radius').querySelector('.value').textContent,
          radius: +svg.dataset.profileRadiusMax, chart_max: +chart.dataset.ymax,
          chart_data: JSON.stringify(plots.pressure.u.data[1]),
        };
        """
    )


def _api(design):
    result = analyse(design, fit=False, toolpath=False)
    alpha = result.summary()["geometry"]["pressure_angle_max_deg"]
    radius = float(np.hypot(*np.asarray(result.geometry.profile.point).T).max())
    sampled = float(np.degrees(result.geometry.pressure_angle).max())
    return alpha, radius, sampled


def test_editing_the_base_radius_updates_numbers_drawing_and_figures(browser, served):
    url, path = served
    browser.set_window_size(1600, 1200)
    browser.get(url)
    _wait_for(browser, f"document.body.dataset.state === 'ok' && {SETTLED}", "the first analysis")
    before = _shown(browser)
    design = load_design(path)
    alpha, radius, sampled = _api(design)
    assert before["alpha"] == f"{alpha:.2f}°"
    assert before["radius"] == pytest.approx(radius, abs=1e-3)
    assert before["chart_max"] == pytest.approx(sampled, abs=0.05)

    field = browser.find_element("name", "cam.base_radius")
    field.clear()
    field.send_keys("55")
    _wait_for(browser, f"+document.body.dataset.revision > {before['revision']} && {SETTLED}", "the edit")
    after = _shown(browser)
    wider = replace(design, cam=replace(design.cam, base_radius=55.0))
    alpha55, radius55, sampled55 = _api(wider)
    assert after["base"] == "55.000 mm"
    assert after["alpha"] == f"{alpha55:.2f}°" and alpha55 < alpha  # a bigger cam: a smaller angle
    assert after["radius"] == pytest.approx(radius55, abs=1e-3) and radius55 > radius
    assert after["chart_max"] == pytest.approx(sampled55, abs=0.05)
    assert after["chart_data"] != before["chart_data"]


def test_an_invalid_value_shows_the_fields_message(browser, served):
    url, path = served
    browser.get(url)
    _wait_for(browser, f"document.body.dataset.state === 'ok' && {SETTLED}", "the first analysis")
    field = browser.find_element("name", "cam.base_radius")
    field.clear()
    field.send_keys("-5")
    _wait_for(browser, f"document.body.dataset.state === 'invalid' && {SETTLED}", "the error")
    with pytest.raises(DesignError) as caught:
        load_design_with(path, base_radius=-5)
    message = browser.execute_script(
        "return document.querySelector('.err[data-for=\"cam.base_radius\"]').textContent"
    )
    assert caught.value.path == "cam.base_radius" and message == caught.value.message
    assert field.get_attribute("aria-invalid") == "true"


def load_design_with(path: Path, **cam) -> None:
    """Load the design file with [cam] values replaced, through the loader (raises its DesignError)."""
    import tomllib

    from camcad.design import parse_design

    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data["cam"].update(cam)
    parse_design(data)


@pytest.mark.parametrize("width", [400, 500, 1600])
def test_no_horizontal_scroll(browser, served, width):
    url, _ = served
    browser.set_window_size(width, 900)
    browser.get(url)
    _wait_for(browser, f"document.body.dataset.state === 'ok' && {SETTLED}", "the first analysis")
    scroll, client = browser.execute_script(
        "return [document.scrollingElement.scrollWidth, document.scrollingElement.clientWidth]"
    )
    assert scroll <= client


def test_save_button_writes_the_design(browser, served):
    url, path = served
    browser.set_window_size(1600, 1200)
    browser.get(url)
    _wait_for(browser, f"document.body.dataset.state === 'ok' && {SETTLED}", "the first analysis")
    field = browser.find_element("name", "cam.base_radius")
    field.clear()
    field.send_keys("61.5")
    browser.find_element("id", "save").click()
    _wait_for(browser, "document.getElementById('status').textContent.startsWith('saved')", "the save")
    assert load_design(path).cam.base_radius == 61.5


def test_save_refused_when_the_file_changed_on_disk_shows_why(browser, served):
    """An edit made on disk while the page is open is not overwritten: 409, and the page says so."""
    url, path = served
    browser.set_window_size(1600, 1200)
    browser.get(url)
    _wait_for(browser, f"document.body.dataset.state === 'ok' && {SETTLED}", "the first analysis")
    edited = path.read_text(encoding="utf-8") + "# edited in another editor while the page was open\n"
    path.write_text(edited, encoding="utf-8")
    field = browser.find_element("name", "cam.base_radius")
    field.clear()
    field.send_keys("47")
    browser.find_element("id", "save").click()
    _wait_for(browser, "document.getElementById('status').textContent.startsWith('not saved')", "the refusal")
    assert browser.find_element("id", "status").text == "not saved: the file changed on disk"
    # the explanation stays on the page after the next analysis (which clears the field errors)
    assert "changed on disk since it was loaded" in browser.find_element("id", "notice").text
    assert path.read_text(encoding="utf-8") == edited
    # reloading the page loads the file as it is now; Save then writes it, the comment kept
    browser.get(url)
    _wait_for(browser, f"document.body.dataset.state === 'ok' && {SETTLED}", "the reload")
    field = browser.find_element("name", "cam.base_radius")
    field.clear()
    field.send_keys("47")
    browser.find_element("id", "save").click()
    _wait_for(browser, "document.getElementById('status').textContent.startsWith('saved')", "the save")
    assert load_design(path).cam.base_radius == 47.0
    assert path.read_text(encoding="utf-8").endswith("# edited in another editor while the page was open\n")


def test_the_browser_blocks_nothing_and_the_page_needs_the_token(browser, served):
    """Under the server's Content-Security-Policy the page loads with no console error; no token: 403."""
    url, _ = served
    browser.get(url)
    _wait_for(browser, f"document.body.dataset.state === 'ok' && {SETTLED}", "the first analysis")
    browser.get_log("browser")  # what earlier tests left
    browser.refresh()
    _wait_for(browser, f"document.body.dataset.state === 'ok' && {SETTLED}", "the reload")
    severe = [e["message"] for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert severe == []
    browser.get(url.split("?")[0])
    assert "a valid token is required" in browser.find_element("tag name", "body").text


# ---------------------------------------------------------------- the designer's editing (issue 37)

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

SAMPLES = sorted((ROOT / "samples").glob("*.toml"))
OK = f"document.body.dataset.state === 'ok' && {SETTLED}"


@contextmanager
def _serve(folder: Path, sample: str):
    """``camcad serve`` on a copy of ``sample`` in ``folder`` (with the samples' tables beside it)."""
    from camcad.serve import make_server

    for csv in (ROOT / "samples").glob("*.csv"):
        shutil.copy(csv, folder / csv.name)
    design = folder / f"{sample}.toml"
    shutil.copy(ROOT / "samples" / f"{sample}.toml", design)
    srv, url = make_server(design, port=0)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        yield url, design
    finally:
        srv.shutdown()
        srv.server_close()


def _open(browser, url: str, width: int = 1400) -> None:
    browser.set_window_size(width, 1000)
    browser.get(url)
    _wait_for(browser, OK, "the first analysis")


def _edited(browser, action, what: str) -> None:
    """Run ``action`` and wait until the page has analysed and drawn what it changed."""
    before = browser.execute_script("return +document.body.dataset.revision")
    action()
    _wait_for(browser, f"+document.body.dataset.revision > {before} && {SETTLED}", what)


def _motion_saved(browser, design: Path) -> list:
    browser.find_element("id", "save").click()
    _wait_for(browser, "document.getElementById('status').textContent.startsWith('saved')", "the save")
    return tomllib.loads(design.read_text(encoding="utf-8"))["motion"]


@pytest.mark.parametrize("sample", [p.stem for p in SAMPLES])
def test_every_sample_opens_and_draws_its_family(browser, tmp_path, sample):
    """Valid on opening, no console error, groove/pair drawn, no red card unless the banner names a limit."""
    with _serve(tmp_path, sample) as (url, design):
        browser.get_log("browser")
        _open(browser, url)
        shown = browser.execute_script(
            """
            return {error: document.getElementById('general-error').textContent,
                    groove: !!document.getElementById('groove-outer'),
                    second: !!document.getElementById('second-plate'),
                    over: [...document.querySelectorAll('#cards .card.over .label')]
                      .map(c => c.firstChild.textContent),
                    ok_banner: !!document.querySelector('#alerts .alert.ok'),
                    points: (plots.s.chart.points || {phi_deg: []}).phi_deg.length,
                    radius: +document.querySelector('#cam-drawing svg').dataset.profileRadiusMax,
                    unnamed: [...document.querySelectorAll('#design-form input, #design-form select')]
                      .filter(e => !(e.labels.length && e.labels[0].textContent.trim())).map(e => e.id),
                    raw_labels: [...document.querySelectorAll('#design-form label')]
                      .filter(l => l.firstChild && /_/.test(l.firstChild.textContent)).length,
                    defaults: [...document.querySelectorAll('#motion-editor select option')]
                      .filter(o => o.value === '').length};
            """
        )
        assert [e["message"] for e in browser.get_log("browser") if e["level"] == "SEVERE"] == []
        result = analyse(load_design(design), fit=False, toolpath=False, strict=False)
        assert shown["error"] == ""
        assert shown["groove"] == (result.parts[0].part.pocket is not None)
        assert shown["second"] == any(r.part.made for r in result.parts[1:])
        assert shown["radius"] == pytest.approx(np.hypot(*np.asarray(result.geometry.profile.point).T).max())
        if shown["ok_banner"]:  # "No warnings": no limit broken, and no card may be red
            assert not result.findings and shown["over"] == []
        if shown["over"]:  # a red card names a limit the banner lists
            assert result.findings
        fit = getattr(result.design.motion[0].law, "fit", None)
        assert shown["points"] == (0 if fit is None else len(fit.angle))
        assert shown["unnamed"] == [] and shown["raw_labels"] == 0 and shown["defaults"] == 0


def _drag(browser, boundary: int, to_deg: float) -> None:
    """Drag the line after segment ``boundary`` on the displacement chart to ``to_deg`` with the mouse."""
    from selenium.webdriver.common.action_chains import ActionChains

    over = browser.find_element("css selector", "#chart-s .u-over")
    x0, x1, width, _height = browser.execute_script(
        """
        const u = plots.s.u, at = spans();
        return [u.valToPos(at[arguments[0]][1], 'x'), u.valToPos(arguments[1], 'x'), u.over.clientWidth,
                u.over.clientHeight];
        """,
        boundary,
        to_deg,
    )
    chain = ActionChains(browser)
    chain.move_to_element_with_offset(over, int(x0 - width / 2), 0).click_and_hold()
    chain.move_by_offset(int((x1 - x0) / 2), 0).move_by_offset(int(x1 - x0) - int((x1 - x0) / 2), 0)
    chain.release().perform()


def test_add_drag_delete_segments_save_and_rebuild(browser, tmp_path):
    """Add a segment, drag a boundary with the mouse, delete one: the saved tables and the cam rebuilt."""
    with _serve(tmp_path, "quintero_vap_b01") as (url, design):
        _open(browser, url)
        _edited(browser, lambda: browser.find_element("id", "seg-add").click(), "the new segment")
        _edited(browser, lambda: _drag(browser, 0, 160.0), "the drag")
        angles = browser.execute_script("return segments.map(s => +s.angle)")
        assert angles[0] == pytest.approx(160.0, abs=1.0) and sum(angles) == pytest.approx(360.0)
        _edited(browser, lambda: browser.find_element("id", "seg-1-delete").click(), "the deletion")
        motion = _motion_saved(browser, design)
        rise = angles[0] + angles[1]  # the deleted dwell's span went to the segment before it
        assert motion == [
            {"kind": "rise", "angle": pytest.approx(rise), "lift": 30.0, "law": "vap", "b": 0.1},
            {"kind": "return", "angle": 90.0, "lift": 30.0, "law": "vap", "b": 0.1},
            {"kind": "dwell", "angle": 30.0},
        ]
        result = analyse(load_design(design), fit=False, toolpath=False)
        alpha = result.summary()["geometry"]["pressure_angle_max_deg"]
        card = browser.execute_script(
            "return [...document.querySelectorAll('#cards .card')].find(c => c.querySelector('.label')"
            ".firstChild.textContent.toLowerCase() === 'max pressure angle')"
            ".querySelector('.value').textContent"
        )
        assert card == f"{alpha:.2f}°"
        smax = browser.execute_script("return +document.getElementById('chart-s').dataset.ymax")
        assert smax == pytest.approx(float(np.max(result.motion.s)), abs=1e-3)
        # undo brings the deleted segment back
        _edited(browser, lambda: browser.find_element("id", "undo").click(), "the undo")
        assert browser.execute_script("return segments.length") == 4


def _drag_point(browser, boundary: int, to_deg: float, to_lift: float) -> None:
    """Drag the blend point after segment ``boundary`` on the s chart to (``to_deg``, ``to_lift``)."""
    from selenium.webdriver.common.action_chains import ActionChains

    over = browser.find_element("css selector", "#chart-s .u-over")
    x0, y0, x1, y1, width, height = browser.execute_script(
        """
        const u = plots.s.u, b = camcadBlendPoints().find(b => b.k === arguments[0]);
        return [u.valToPos(b.x, 'x'), u.valToPos(b.y, 'y'), u.valToPos(arguments[1], 'x'),
                u.valToPos(arguments[2], 'y'), u.over.clientWidth, u.over.clientHeight];
        """,
        boundary,
        to_deg,
        to_lift,
    )
    dx, dy = round(x1) - round(x0), round(y1) - round(y0)
    chain = ActionChains(browser)
    chain.move_to_element_with_offset(over, round(x0 - width / 2), round(y0 - height / 2)).click_and_hold()
    chain.move_by_offset(dx // 2, dy // 2).move_by_offset(dx - dx // 2, dy - dy // 2)
    chain.release().perform()


def test_drag_a_blend_point_edits_angle_and_lift(browser, tmp_path):
    """A blend point dragged on the chart: the saved TOML, the rebuilt cam and the redrawn point agree;
    dragged below zero, the loader's own refusal shows under the lift it names."""
    with _serve(tmp_path, "quintero_vap_b01") as (url, design):
        _open(browser, url)
        start = browser.execute_script("return camcadBlendPoints()[0]")
        assert start["x"] == pytest.approx(150.0) and start["y"] == pytest.approx(30.0, abs=1e-6)
        _edited(browser, lambda: _drag_point(browser, 0, 140.0, 36.0), "the drag")
        assert browser.execute_script("return document.body.dataset.state") == "ok"
        pixel = browser.execute_script(  # one pixel of the chart in the lift's unit and in degrees
            "const u = plots.s.u; return [Math.abs(u.posToVal(0, 'y') - u.posToVal(1, 'y')),"
            " Math.abs(u.posToVal(1, 'x') - u.posToVal(0, 'x'))]"
        )
        motion = _motion_saved(browser, design)
        lift, angle = motion[0]["lift"], motion[0]["angle"]
        assert lift == pytest.approx(36.0, abs=2 * pixel[0] + 0.01)
        assert angle == pytest.approx(140.0, abs=2 * pixel[1] + 0.5)
        # the rest of the program stays: the dwell ends at 240°, the return falls by the new lift
        assert angle + motion[1]["angle"] == pytest.approx(240.0) and motion[1]["kind"] == "dwell"
        assert motion[2] == {"kind": "return", "angle": 120.0, "lift": lift, "law": "vap", "b": 0.1}
        result = analyse(load_design(design), fit=False, toolpath=False)
        assert float(np.max(result.motion.s)) == pytest.approx(lift, abs=1e-9)
        point = browser.execute_script("return camcadBlendPoints()[0]")
        assert point["x"] == pytest.approx(angle) and point["y"] == pytest.approx(lift, abs=1e-5)
        assert browser.execute_script("return +document.getElementById('chart-s').dataset.ymax") == (
            pytest.approx(lift, abs=1e-5)
        )
        # the point where the dwell ends: its level moves with the rise before it and the return after it
        _edited(browser, lambda: _drag_point(browser, 1, 250.0, lift - 6.0), "the dwell's end dragged")
        motion = _motion_saved(browser, design)
        lift2 = motion[0]["lift"]
        assert lift2 == pytest.approx(lift - 6.0, abs=2 * pixel[0] + 0.01) and motion[2]["lift"] == lift2
        assert motion[0]["angle"] == angle and motion[1]["angle"] + angle == pytest.approx(250.0, abs=1.0)
        assert motion[1]["angle"] + motion[2]["angle"] == pytest.approx(360.0 - angle)
        result = analyse(load_design(design), fit=False, toolpath=False)
        assert float(np.max(result.motion.s)) == pytest.approx(lift2, abs=1e-9)
        lift, angle = lift2, motion[0]["angle"]

        # below the base circle: the loader refuses, and the page says so under the field it names
        _edited(browser, lambda: _drag_point(browser, 0, angle, -12.0), "the refused drag")
        assert browser.execute_script("return document.body.dataset.state") == "invalid"
        shown = browser.execute_script(
            "return [0, 1, 2].map(i => (document.getElementById(`f-motion-${i}-lift`) || {}).value)"
        )
        data = tomllib.loads(design.read_text(encoding="utf-8"))
        data["motion"][0]["lift"], data["motion"][2]["lift"] = float(shown[0]), float(shown[2])
        assert float(shown[0]) < 0
        from camcad.design import parse_design

        with pytest.raises(DesignError) as caught:
            parse_design(data)
        message = browser.execute_script(
            "return document.querySelector(`.err[data-for='${arguments[0]}']`).textContent", caught.value.path
        )
        assert caught.value.path.startswith("motion[") and message == caught.value.message
        # Save refuses the invalid program; the file keeps the last saved one
        browser.find_element("id", "save").click()
        _wait_for(browser, "document.getElementById('status').textContent.startsWith('not saved')", "refusal")
        assert tomllib.loads(design.read_text(encoding="utf-8"))["motion"] == motion


def test_upload_a_table_switch_follower_and_family(browser, tmp_path):
    """An uploaded CSV is written beside the design as it was and drawn as points; the follower switches."""
    with _serve(tmp_path, "offset_roller") as (url, design):
        _open(browser, url)
        upload = tmp_path / "elsewhere"
        upload.mkdir()
        gauge = upload / "gauge.csv"
        shutil.copy(ROOT / "samples" / "measured_lift.csv", gauge)
        browser.find_element("id", "table-file").send_keys(str(gauge))
        _wait_for(browser, "!document.getElementById('table-save').disabled", "the file read")
        browser.find_element("id", "table-save").click()
        _wait_for(browser, "!!document.getElementById('f-motion-0-noise')", "the table segment")
        noise = browser.find_element("id", "f-motion-0-noise")
        _edited(browser, lambda: noise.send_keys("0.005"), "the table's analysis")
        assert browser.execute_script("return document.body.dataset.state") == "ok"
        assert (tmp_path / "gauge.csv").read_bytes() == gauge.read_bytes()
        points = browser.execute_script("return plots.s.chart.points.phi_deg.length")
        motion = _motion_saved(browser, design)
        assert motion == [{"kind": "table", "law": "table", "file": "gauge.csv", "noise": 0.005}]
        fit = load_design(design).motion[0].law.fit
        assert points == len(fit.angle) == 360
        # the same name again is refused: a file is never replaced by an upload it did not come from
        (tmp_path / "other.csv").write_text("0,0\n", encoding="utf-8")
        shutil.copy(gauge, upload / "other.csv")
        browser.find_element("id", "table-file").send_keys(str(upload / "other.csv"))
        _wait_for(browser, "!document.getElementById('table-save').disabled", "the file read")
        browser.find_element("id", "table-save").click()
        _wait_for(browser, "document.getElementById('table-err').textContent !== ''", "the refusal")
        assert "already exists" in browser.find_element("id", "table-err").text
        assert (tmp_path / "other.csv").read_text(encoding="utf-8") == "0,0\n"

    second = tmp_path / "second"
    second.mkdir()
    with _serve(second, "offset_roller") as (url, design):
        _open(browser, url)
        follower = browser.find_element("name", "follower.type")
        _edited(browser, lambda: follower.send_keys("oscillating-roller"), "the oscillating follower")
        data = tomllib.loads(design.read_text(encoding="utf-8"))
        data["follower"]["type"] = "oscillating-roller"
        with pytest.raises(DesignError) as caught:
            from camcad.design import parse_design

            parse_design(data)
        message = browser.execute_script(
            "return document.querySelector(`.err[data-for='${arguments[0]}']`).textContent", caught.value.path
        )
        assert browser.execute_script("return document.body.dataset.state") == "invalid"
        assert message == caught.value.message  # the loader's own words, under the field it names


def test_family_switch_draws_the_second_plate(browser, tmp_path):
    with _serve(tmp_path, "packaging_rocker") as (url, design):
        _open(browser, url)
        assert not browser.execute_script("return !!document.getElementById('second-plate')")
        browser.find_element("css selector", "#group-cam details summary").click()  # the keys at defaults
        style = browser.find_element("name", "cam.style")
        _edited(browser, lambda: style.send_keys("conjugate"), "the conjugate pair")
        assert browser.execute_script("return document.body.dataset.state") == "ok"
        assert browser.execute_script("return !!document.getElementById('second-plate')")
        _motion_saved(browser, design)
        result = analyse(load_design(design), fit=False, toolpath=False, strict=False)
        assert len(result.parts) == 2 and result.parts[1].part.made


def test_invalid_input_marks_everything_out_of_date_and_keeps_the_last_result(browser, served):
    url, _ = served
    _open(browser, url)
    field = browser.find_element("name", "cam.base_radius")
    before = browser.execute_script("return document.querySelector('#cam-drawing svg').outerHTML")
    field.clear()
    field.send_keys("-5")
    _wait_for(browser, f"document.body.dataset.state === 'invalid' && {SETTLED}", "the error")
    shown = browser.execute_script(
        """
        const seen = e => !!(e && e.offsetParent !== null);
        return {stale: seen(document.getElementById('stale')),
                ok_banner: !!document.querySelector('#alerts .alert.ok'),
                cards: [...document.querySelectorAll('#cards .card')]
                  .map(c => seen(c.querySelector('.stale-tag'))),
                charts: [...document.querySelectorAll('.chart h3')]
                  .map(h => seen(h.querySelector('.stale-tag'))),
                drawing: document.querySelector('#cam-drawing svg').outerHTML};
        """
    )
    assert shown["stale"] and not shown["ok_banner"]
    assert shown["cards"] and all(shown["cards"]) and shown["charts"] and all(shown["charts"])
    assert shown["drawing"] == before  # the last valid cam stays beside the error


def load_design_with_radius(path: Path, radius: float):
    """The design file with cam.base_radius replaced, through the loader."""
    from camcad.design import parse_design

    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data["cam"]["base_radius"] = radius
    return parse_design(data)


def test_compare_overlays_the_pinned_curves(browser, served):
    url, path = served
    _open(browser, url)
    before = browser.execute_script("return plots.pressure.u.data[1]")
    pinned_design = analyse(load_design(path), fit=False, toolpath=False)
    alpha = pinned_design.summary()["geometry"]["pressure_angle_max_deg"]
    pin_card = f"{float(f'{alpha:.6g}'):g} °"
    browser.find_element("id", "pin").click()
    field = browser.find_element("name", "cam.base_radius")
    field.clear()
    _edited(browser, lambda: field.send_keys("70"), "the edit")
    data = browser.execute_script("return plots.pressure.u.data")
    assert len(data) == 3  # φ, this design, the pinned one
    pinned = [y for y in data[2] if y is not None]
    assert max(pinned) == pytest.approx(max(y for y in before if y is not None), abs=1e-6)
    assert max(y for y in data[1] if y is not None) < max(pinned)  # a bigger cam: a smaller angle
    row = browser.execute_script(
        "return [...document.querySelectorAll("
        "'#compare-table tr[data-key=\"geometry.pressure_angle_max_deg\"] td')].map(td => td.textContent)"
    )
    now = analyse(load_design_with_radius(path, 70.0), fit=False, toolpath=False)
    assert row[1] == pin_card and float(row[2].split()[0]) == pytest.approx(
        now.summary()["geometry"]["pressure_angle_max_deg"], rel=1e-5
    )
    browser.find_element("id", "pin").click()
    assert len(browser.execute_script("return plots.pressure.u.data")) == 2


def test_tab_reaches_every_control_and_each_has_a_name(browser, served):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys

    url, _ = served
    _open(browser, url, width=400)
    controls = browser.execute_script(
        """
        const all = [...document.querySelectorAll('input, select, button, summary, a[href], [tabindex]')];
        const folded = e => e.tagName !== 'SUMMARY' && e.closest('details:not([open])');
        const shown = all.filter(e => !e.disabled && e.offsetParent !== null && e.tabIndex >= 0
                                      && !folded(e));
        shown.forEach((e, i) => { if (!e.id) e.id = 'ctl-' + i; });
        const named = e => (e.labels && e.labels.length && e.labels[0].textContent.trim())
          || e.getAttribute('aria-label') || e.textContent.trim();
        return {ids: shown.map(e => e.id), unnamed: shown.filter(e => !named(e)).map(e => e.id)};
        """
    )
    assert controls["unnamed"] == []
    browser.execute_script("document.activeElement.blur(); window.scrollTo(0, 0)")
    reached = set()
    for _ in range(len(controls["ids"]) + 5):
        ActionChains(browser).send_keys(Keys.TAB).perform()
        reached.add(browser.execute_script("return document.activeElement.id"))
    assert set(controls["ids"]) <= reached
    scroll, client = browser.execute_script(
        "return [document.scrollingElement.scrollWidth, document.scrollingElement.clientWidth]"
    )
    assert scroll <= client


def test_an_unbounded_speed_range_reads_no_upper_limit(browser, tmp_path):
    """rotary_plate keeps its follower on at every speed (the range's upper end is inf in camcad): the page
    says "no upper limit", in the glance and in the compare table, never inf, NaN or a blank; a bounded
    range (quintero_vap_b01) shows its upper speed as the analysis gives it."""
    import math

    with _serve(tmp_path, "rotary_plate") as (url, design):
        _open(browser, url)
        low, high = analyse(load_design(design), fit=False, toolpath=False, strict=False).summary()[
            "dynamics"
        ]["speed_range_rpm"]
        assert math.isinf(high)  # independent of the page: the range is unbounded above
        shown = browser.find_element("id", "speed-range-value").text
        assert shown == f"{float(f'{low:.4g}'):g} rpm to no upper limit"
        browser.find_element("id", "pin").click()
        field = browser.find_element("name", "cam.base_radius")
        field.clear()
        _edited(browser, lambda: field.send_keys("61"), "the edit")
        row = browser.execute_script(
            "return [...document.querySelectorAll("
            "'#compare-table tr[data-key=\"dynamics.speed_range_rpm\"] td')].map(td => td.textContent)"
        )
        assert row[1] == row[2] == shown
        text = browser.find_element("tag name", "main").text
        for word in ("inf", "Infinity", "NaN", "undefined", "null"):
            assert word not in text.replace("Information", ""), word
        browser.find_element("id", "pin").click()

    second = tmp_path / "bounded"
    second.mkdir()
    with _serve(second, "quintero_vap_b01") as (url, design):
        _open(browser, url)
        low, high = analyse(load_design(design), fit=False, toolpath=False).summary()["dynamics"][
            "speed_range_rpm"
        ]
        shown = browser.find_element("id", "speed-range-value").text
        assert shown == f"{float(f'{low:.4g}'):g} rpm to {float(f'{high:.4g}'):g} rpm"
