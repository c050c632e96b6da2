"""The live designer in a real browser: headless Chromium against ``camcad serve`` on a free loopback port.

Checked against the Python API on the same design: after the base radius is
typed into the page, the key numbers and the drawing show what
``analyse()`` computes for that design, a figure is redrawn with the new
values, an invalid value shows the loader's own message next to its field,
and Save writes a file ``load_design`` reads back. No horizontal scroll at
500 and 1600 px.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from camcad.design import load_design
from camcad.errors import DesignError
from camcad.pipeline import analyse
from tests.conftest import serving
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
    raise AssertionError(f"timed out waiting for {what}")


def _shown(browser) -> dict:
    return browser.execute_script(
        """
        const card = label => [...document.querySelectorAll('#cards .card')]
          .find(c => c.querySelector('.label').textContent.toLowerCase() === label);
        const svg = document.querySelector('#cam-drawing svg');
        const chart = document.querySelector('#chart-pressure svg');
        return {
          revision: +document.body.dataset.revision, state: document.body.dataset.state,
          alpha: card('max pressure angle').querySelector('.value').textContent,
          base: card('base radius').querySelector('.value').textContent,
          radius: +svg.dataset.profileRadiusMax, chart_max: +chart.dataset.ymax,
          chart_path: chart.querySelector('path[data-series]').getAttribute('d'),
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
    assert after["chart_path"] != before["chart_path"]


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


@pytest.mark.parametrize("width", [500, 1600])
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
    assert "changed on disk since it was loaded" in browser.find_element("id", "general-error").text
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
