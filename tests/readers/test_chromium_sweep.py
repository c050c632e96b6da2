"""The sweep's page in a real browser: headless Chromium at a phone's and a desktop's width.

Checked against the browser's own layout: both figures decoded
(``naturalWidth > 0``), no sideways scroll (``scrollWidth ≤ clientWidth``),
the table of the front's designs holds one row per ``pareto`` row of the table.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import tomllib

from camcad.explore import MEASURES, SweepPlan, grid_points, parse_variable
from camcad.explore.sweep import sweep
from tests.readers.browser import chromium

pytestmark = pytest.mark.slow

SAMPLE = Path(__file__).resolve().parents[2] / "samples" / "offset_roller.toml"

_LAYOUT = """
const root = document.scrollingElement;
const images = [...document.images];
return {
  scroll: root.scrollWidth, client: root.clientWidth, images: images.length,
  decoded: images.filter(i => i.complete && i.naturalWidth > 0).length,
  rows: document.querySelectorAll('table tr').length,
};
"""


@pytest.mark.parametrize("width", [500, 1600])
def test_sweep_page_in_chromium(width, tmp_path):
    data = tomllib.loads(SAMPLE.read_text(encoding="utf-8"))
    variables = tuple(
        parse_variable(g, data, flag="--grid", counted=True) for g in ("base_radius=40:80:5", "offset=0:20:3")
    )
    plan = SweepPlan(
        data=data,
        source=str(SAMPLE),
        variables=variables,
        points=tuple(grid_points(variables)),
        pareto=(MEASURES["base_radius"], MEASURES["contact_stress"]),
    )
    result = sweep(plan, tmp_path, fmt="csv", jobs=1)
    with chromium() as driver:
        driver.set_window_size(width, 1000)
        driver.get((tmp_path / "sweep.html").as_uri())
        layout = driver.execute_script(_LAYOUT)
    assert layout["images"] == layout["decoded"] == 2
    assert layout["scroll"] <= layout["client"]
    assert layout["rows"] == 1 + sum(r["pareto"] for r in result.rows)
