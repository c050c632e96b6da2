"""Every shipped sample opens in the designer: ``/api/analyse`` answers 200 with strict JSON (issue 31).

``samples/rotary_plate.toml`` has a jump-free speed range with no upper end (inf); the answer
carries it as null, as ``summary.json`` does, instead of refusing the non-finite number.
"""

from __future__ import annotations

import http.client
import json
import math
import threading

import pytest

from tests.conftest import ROOT

SAMPLES = sorted((ROOT / "samples").glob("*.toml"))


def _strict(text: str) -> object:
    def refuse(name: str) -> float:
        raise ValueError(f"non-finite JSON number {name}")

    return json.loads(text, parse_constant=refuse)


@pytest.mark.parametrize("sample", SAMPLES, ids=lambda p: p.stem)
def test_every_sample_analyses_in_the_designer(sample, tmp_path):
    from camcad.serve import make_server

    srv, _ = make_server(sample, port=0)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        conn = http.client.HTTPConnection("127.0.0.1", srv.server_address[1], timeout=120)
        headers = {
            "Host": f"127.0.0.1:{srv.server_address[1]}",
            "Content-Type": "application/json",
            "X-Camcad-Token": srv.token,
        }
        conn.request("POST", "/api/analyse", body=json.dumps({"values": {}}), headers=headers)
        response = conn.getresponse()
        body = response.read().decode("utf-8")
    finally:
        srv.shutdown()
        srv.server_close()
    assert response.status == 200, body[:300]
    answer = _strict(body)
    assert isinstance(answer, dict) and answer.get("ok") is True, body[:300]
    if sample.stem == "rotary_plate":
        from camcad.design import load_design
        from camcad.pipeline import analyse

        speeds = analyse(load_design(sample), strict=False, toolpath=False).summary()["dynamics"][
            "speed_range_rpm"
        ]
        assert math.isinf(speeds[1])  # independent of the server: the range has no upper end
        assert answer["summary"]["dynamics"]["speed_range_rpm"] == [speeds[0], None]


def test_designer_draws_the_second_plate_and_the_driving_flank():
    """Plate 2's force and stress are its own DynamicsResult's arrays (own roller radius, issue 31);
    a groove's force splits by the flank that drives (the sign of the contact force)."""
    import numpy as np
    import tomllib

    from camcad.design import load_design
    from camcad.pipeline import analyse
    from camcad.serve.payload import evaluate

    path = ROOT / "samples" / "indexing_conjugate.toml"
    text = path.read_text(encoding="utf-8").replace(
        "roller_radius = 14.0        # mm, the second roller", "roller_radius = 8.0"
    )
    page = evaluate(tomllib.loads(text))
    charts = {c["key"]: c for c in page["charts"]}
    design = load_design(path)
    from camcad.design.schema import parse_design

    analysis = analyse(parse_design(tomllib.loads(text)), fit=False, toolpath=False, strict=False)
    dyn2 = analysis.parts[1].dynamics  # the second plate, its own roller
    grid = np.degrees(np.asarray(analysis.parts[1].geometry.phi))
    for key, name, values in (
        ("force", "F plate 2", dyn2.contact_force),
        ("stress", "σ plate 2", dyn2.hertz_stress),
    ):
        phi = np.asarray(charts[key]["phi_deg"], dtype=float)  # each chart on its own angles
        index = np.searchsorted(grid, phi - 1e-4)
        np.testing.assert_allclose(grid[index], phi, atol=1e-4)  # samples of the grid, not interpolated
        series = {s["label"]: s["y"] for s in charts[key]["series"]}
        assert name in series
        np.testing.assert_allclose(series[name], np.asarray(values)[index], atol=1e-6)
    stress = {s["label"]: np.asarray(s["y"], dtype=float) for s in charts["stress"]["series"]}
    assert (
        stress["σ plate 2"].max() > stress["σ plate 1"].max()
    )  # the 8 mm roller bears harder than the 14 mm
    assert design.conjugate.roller_radius == 14.0

    groove = evaluate(tomllib.loads((ROOT / "samples" / "groove_rocker.toml").read_text(encoding="utf-8")))
    force = {s["label"]: s["y"] for s in next(c for c in groove["charts"] if c["key"] == "force")["series"]}
    signed, inner, outer = force["F"], force["F inner flank drives"], force["F outer flank drives (|F|)"]
    for f, i, o in zip(signed, inner, outer, strict=True):
        assert (i == f and o is None) if f >= 0 else (i is None and o == -f)
    assert any(o is not None for o in outer) and any(i is not None for i in inner)
