"""A stage's Knob reaches the user as its TOML path (issue 33: no stage hard-codes one).

The stages name a :class:`camcad.knobs.Knob`; ``camcad.design.paths`` maps it
where errors and findings leave the core. Checked here against the texts a
user reads: the CLI's error line and ``summary.json``'s findings.
"""

from __future__ import annotations

import json

import pytest

from camcad.design.paths import PATHS, named_error, named_finding, path_of
from camcad.dynamics.film import LubricationSpec
from camcad.errors import DesignError, DesignLimitError
from camcad.findings import Finding, Severity
from camcad.knobs import Knob, TableKey


def test_a_knob_shows_its_path_and_a_table_key_its_table_and_key():
    assert path_of(Knob.BASE_RADIUS) == "cam.base_radius"
    assert path_of(TableKey(Knob.LUBRICATION_TABLE, "viscosity_Pa_s")) == "lubrication.viscosity_Pa_s"
    assert path_of("motion[2].angle") == "motion[2].angle"  # a path already
    with pytest.raises(DesignError) as err:
        LubricationSpec(
            viscosity_Pa_s=-1.0,
            pressure_viscosity_coefficient=2e-8,
            roughness_cam_um=0.4,
            roughness_follower_um=0.2,
        )
    assert (
        str(named_error(err.value))
        == "lubrication.viscosity_Pa_s: must be a positive number [Pa·s], got -1.0"
    )


def test_a_limit_error_gets_its_path_in_front_once():
    err = DesignLimitError("the face is too narrow", field=Knob.FACE_WIDTH)
    assert str(named_error(err)) == "follower.face_width: the face is too narrow"
    assert err.message == "the face is too narrow" and named_error(err).field == "follower.face_width"


def test_a_finding_that_leads_with_its_field_reads_as_before_and_naming_twice_changes_nothing():
    found = Finding(
        kind="x", severity=Severity.HARD, field=Knob.PIVOT_DISTANCE, message="too close", field_first=True
    )
    named = named_finding(found)
    assert (named.field, named.message, named.field_first) == (
        "follower.pivot_distance",
        "follower.pivot_distance: too close",
        False,
    )
    assert named_finding(named) == named
    assert found.summary()["field"] == "pivot distance"  # unnamed, it says the quantity in words
    plain = Finding(kind="y", severity=Severity.SOFT, field=Knob.MAX_PRESSURE_ANGLE, message="too steep")
    assert named_finding(plain).message == "too steep"


def test_every_path_is_unique_and_every_knob_has_one():
    assert set(PATHS) == set(Knob) and len(set(PATHS.values())) == len(PATHS)


def test_the_analysis_names_a_stage_finding_by_its_path(tmp_path):
    """A narrow flat face: geometry blames Knob.FACE_WIDTH; summary.json says follower.face_width."""
    from camcad.design import load_design
    from camcad.pipeline import analyse
    from tests.conftest import ROOT

    text = (ROOT / "samples" / "rocker_flat.toml").read_text(encoding="utf-8")
    assert "face_width = 170.0" in text
    design = tmp_path / "narrow.toml"
    design.write_text(text.replace("face_width = 170.0", "face_width = 40.0"), encoding="utf-8")
    summary = analyse(load_design(design), fit=False, toolpath=False, strict=False).summary()
    (hit,) = [f for f in summary["findings"] if f["kind"] == "face width"]
    assert hit["field"] == "follower.face_width" and hit["message"].startswith("follower.face_width: 40 mm")
    json.dumps(summary)  # JSON-ready: no Knob left in it
    with pytest.raises(DesignLimitError) as err:  # strict: the error leaves the pipeline with the path
        analyse(load_design(design), fit=False, toolpath=False, strict=True)
    assert err.value.field == "follower.face_width" and str(err.value).startswith(
        "follower.face_width: 40 mm"
    )
