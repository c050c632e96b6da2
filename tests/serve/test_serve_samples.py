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
