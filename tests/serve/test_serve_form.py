"""The designer's form and server against the loader: TOML read back by tomllib and load_design,
hints equal to the loader's own refusals, numbers equal to the Python API, loopback and JSON only."""

from __future__ import annotations

import http.client
import io
import json
import math
import shutil
import sys
import zipfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from camcad.design import load_design, parse_design
from camcad.errors import DesignError
from camcad.pipeline import analyse
from camcad.serve.form import design_data, form_groups, toml_text
from camcad.serve.payload import evaluate
from tests.conftest import serving

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

SAMPLES = Path(__file__).resolve().parents[2] / "samples"
PLAIN = sorted(p for p in SAMPLES.glob("*.toml") if "file =" not in p.read_text())


def _data(path: Path) -> dict:
    return tomllib.loads(path.read_text(encoding="utf-8"))


@pytest.mark.parametrize("path", PLAIN, ids=[p.stem for p in PLAIN])
def test_toml_round_trip_loads_to_the_same_design(path, tmp_path):
    """toml_text(data) read by tomllib is the same mapping, and load_design gives the same Design."""
    data = _data(path)
    text = toml_text(data, header="test")
    assert tomllib.loads(text) == data
    copy = tmp_path / path.name
    copy.write_text(text, encoding="utf-8")
    for name in ("profile.csv",):  # a design may refer to a file beside it
        if (path.parent / name).exists():
            shutil.copy(path.parent / name, tmp_path / name)
    assert replace(load_design(copy), source="") == replace(load_design(path), source="")


def test_hints_are_what_the_loader_allows():
    """Each numeric field's hint is the range the loader states when it refuses a value out of it."""
    data = _data(SAMPLES / "quintero_vap_b01.toml")
    checked = 0
    for group in form_groups(data):
        if group.title.startswith("motion"):
            continue
        for field in group.fields:
            if field.kind not in ("float", "int") or not field.hint:
                continue
            for bad in (-1e300, 1e300):
                try:
                    text = str(int(bad) if field.kind == "int" else bad)
                    parse_design(design_data(data, {field.path: text}))
                except DesignError as err:
                    if err.path == field.path and "allowed" in err.message:
                        assert field.hint in err.message, (field.path, field.hint, err.message)
                        checked += 1
                        break
    assert checked >= 8


def test_empty_input_restores_the_default_and_text_is_refused_by_name():
    data = _data(SAMPLES / "quintero_vap_b01.toml")
    assert "bore" not in design_data(data, {"cam.bore": ""})["cam"]
    out = evaluate(design_data(data, {"cam.base_radius": "4o"}))
    assert out["ok"] is False
    assert out["errors"] == [{"field": "cam.base_radius", "message": "expected a number, got '4o'"}]


def test_payload_numbers_equal_the_python_api():
    """The cards and drawing after an edit equal analyse() of the same design through the API."""
    data = design_data(_data(SAMPLES / "quintero_vap_b01.toml"), {"cam.base_radius": "55"})
    out = evaluate(data)
    assert out["ok"], out["errors"]
    api = analyse(parse_design(data), fit=False, toolpath=False)
    summary = api.summary()
    alpha_max = summary["geometry"]["pressure_angle_max_deg"]
    assert out["summary"]["geometry"]["pressure_angle_max_deg"] == alpha_max
    assert f"{summary['geometry']['pressure_angle_max_deg']:.2f}°" in out["cards"]
    radius = float(np.hypot(*np.asarray(api.geometry.profile.point).T).max())
    assert out["drawing"]["profile_radius_max"] == pytest.approx(radius, abs=1e-12)
    alpha = next(c for c in out["charts"] if c["key"] == "pressure")["series"][0]["y"]
    sampled = np.degrees(np.abs(api.geometry.pressure_angle)).max()
    assert max(map(abs, alpha)) == pytest.approx(sampled, abs=0.05)
    assert out["drawing"]["base_radius"] == 55


@pytest.fixture
def server(tmp_path):
    with serving(tmp_path) as (srv, _, design):
        yield srv, design


def _request(srv, method, path, body=None, *, host="127.0.0.1", kind="application/json"):
    conn = http.client.HTTPConnection("127.0.0.1", srv.server_address[1], timeout=60)
    headers = {"Host": f"{host}:{srv.server_address[1]}", "Content-Type": kind, "X-Camcad-Token": srv.token}
    conn.request(method, path, body=None if body is None else json.dumps(body), headers=headers)
    response = conn.getresponse()
    return response.status, response.getheader("Content-Type"), response.read()


def test_server_answers_loopback_json_only(server):
    srv, _ = server
    assert srv.server_address[0] == "127.0.0.1"
    status, kind, page = _request(srv, "GET", "/")
    assert status == 200 and kind.startswith("text/html") and b'name="cam.base_radius"' in page
    assert _request(srv, "GET", "/", host="evil.example")[0] == 403  # DNS rebinding
    assert _request(srv, "POST", "/api/analyse", {"values": {}}, kind="text/plain")[0] == 415
    status, _, body = _request(srv, "POST", "/api/analyse", {"values": {"cam.base_radius": "-5"}})
    assert status == 200 and json.loads(body)["errors"][0]["field"] == "cam.base_radius"


def test_save_writes_a_design_the_loader_reads(server):
    srv, design = server
    status, _, body = _request(srv, "POST", "/api/save", {"values": {"cam.base_radius": "52.5"}})
    assert status == 200 and json.loads(body)["saved"] == str(design)
    assert load_design(design).cam.base_radius == 52.5
    status, _, body = _request(srv, "POST", "/api/save", {"values": {"cam.base_radius": "0"}})
    assert json.loads(body)["saved"] is None and load_design(design).cam.base_radius == 52.5


def test_build_returns_the_shop_files(server):
    srv, _ = server
    status, kind, body = _request(srv, "POST", "/api/build", {"values": {"cam.base_radius": "45"}})
    assert status == 200 and kind == "application/zip"
    names = set(zipfile.ZipFile(io.BytesIO(body)).namelist())
    assert {"cam.ngc", "profile.dxf", "cam.stl", "report.html", "summary.json"} <= names
    summary = json.loads(zipfile.ZipFile(io.BytesIO(body)).read("summary.json"))
    assert summary["geometry"]["profile_radius_min_mm"] == pytest.approx(45.0)
    assert math.isfinite(summary["fit"]["max_error_mm"])


def test_labels_units_and_hints_come_from_the_schema():
    """Each field's hint is the schema's "allowed" text, its unit the word that text ends with."""
    from camcad.design.editor_schema import design_json_schema

    schema = design_json_schema()["properties"]
    data = _data(SAMPLES / "quintero_vap_b01.toml")
    fields = {f.path: f for g in form_groups(data) for f in (*g.fields, *g.more)}
    base = fields["cam.base_radius"]
    assert (base.label, base.unit, base.required) == ("Base radius", "mm", True)
    assert schema["cam"]["properties"]["base_radius"]["description"] == f"allowed: {base.hint}"
    assert (fields["cam.max_pressure_angle"].unit, fields["cam.speed_rpm"].label) == ("°", "Speed")
    assert fields["cam.rotation"].unit == "" and fields["cam.rotation"].choices == ("ccw", "cw")
    assert all("_" not in f.label for f in fields.values())
    assert not any(g.title.startswith("motion") for g in form_groups(data))  # the motion is the editor's


def test_a_whole_motion_program_from_the_editor():
    """motion.count rebuilds the tables: order, new segments, law parameters; blends kept only by source."""
    data = _data(SAMPLES / "quintero_vap_b01.toml")
    data["motion"][0] = {
        "kind": "rise",
        "angle": 150.0,
        "lift": 30.0,
        "law": "polynomial",
        "start": {"a": 0.0},
    }
    values = {
        "motion.count": "4",
        "motion[0].kind": "dwell", "motion[0].angle": "30",
        "motion[1].kind": "rise", "motion[1].angle": "120", "motion[1].lift": "30",
        "motion[1].law": "polynomial", "motion[1].source": "0",
        "motion[2].kind": "dwell", "motion[2].angle": "90",
        "motion[3].kind": "return", "motion[3].angle": "120", "motion[3].lift": "close",
        "motion[3].law": "dudley", "motion[3].degree": "7", "motion[3].source": "0",
    }  # fmt: skip
    motion = design_data(data, values)["motion"]
    assert motion == [
        {"kind": "dwell", "angle": 30},
        {"kind": "rise", "angle": 120, "lift": 30, "law": "polynomial", "start": {"a": 0.0}},
        {"kind": "dwell", "angle": 90},
        {"kind": "return", "angle": 120, "lift": "close", "law": "dudley", "degree": 7},
    ]
    design = parse_design(design_data(data, values))
    assert [round(math.degrees(s.span), 9) for s in design.motion] == [30, 120, 90, 120]
    assert design.motion[3].law.describe() == parse_design(
        {**data, "motion": [{"kind": "rise", "angle": 240, "lift": 30, "law": "dudley", "degree": 7},
                            {"kind": "return", "angle": 120, "lift": 30, "law": "dudley", "degree": 7}]}
    ).motion[1].law.describe()  # fmt: skip


def test_a_table_upload_writes_only_new_plain_files_beside_the_design(server):
    srv, design = server
    folder = design.parent
    text = (SAMPLES / "measured_lift.csv").read_text(encoding="utf-8")

    def upload(name, body=text):
        status, _, answer = _request(srv, "POST", "/api/table", {"table": {"name": name, "text": body}})
        return status, json.loads(answer)

    status, out = upload("gauge.csv")
    assert status == 200 and out["saved"] == "gauge.csv" and out["rows"] == 360
    assert (folder / "gauge.csv").read_text(encoding="utf-8") == text
    assert upload("gauge.csv")[0] == 200  # its own file: written again
    (folder / "mine.csv").write_text("kept\n", encoding="utf-8")
    status, out = upload("mine.csv")
    assert status == 422 and "already exists" in out["errors"][0]["message"]
    assert (folder / "mine.csv").read_text(encoding="utf-8") == "kept\n"
    (folder / "link.csv").symlink_to(folder / "mine.csv")
    assert upload("link.csv")[0] == 422 and (folder / "mine.csv").read_text(encoding="utf-8") == "kept\n"
    for name in ("../out.csv", "/tmp/x.csv", "a/b.csv", ".hidden.csv", "x.txt", "x.csv\n"):
        status, out = upload(name)
        assert status == 422 and "allowed" in out["errors"][0]["message"], name
    assert not (folder.parent / "out.csv").exists()
    status, out = upload("bad.csv", "angle,lift\n0,abc\n")
    assert status == 422 and not (folder / "bad.csv").exists()
