"""Issue 11.4: one rule for limits, the same in build and check.

Hard limits (undercut, a face narrower than the contact's travel, a velocity
jump, an unreachable fit tolerance) stop ``build`` with exit 3 and no files;
soft limits (pressure angle, contact stress, follower jump) are warnings, and
``build --strict`` turns them into exit 3; ``check`` exits 3 on either and
still prints its table.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camcad.cli import main
from camcad.design import parse_design
from camcad.geometry import Cam
from tests.cli.test_cli import HARMONIC, HREN, edit, snapshot

# a 30° harmonic rise is far too sharp for the 20 mm roller (see test_cli's BROKEN["undercut"])
UNDERCUT = edit(edit(HARMONIC, r"^angle = 150.0", "angle = 30.0"), r"^angle = 90.0", "angle = 210.0")
SOFT = edit(HARMONIC, r"^max_pressure_angle = .*$", "max_pressure_angle = 10.0")
CONSTANT_VELOCITY = HARMONIC.replace('law = "harmonic"', 'law = "constant-velocity"')


def narrow_face(width: float) -> str:
    return edit(HREN, r"^face_width = .*$", f"face_width = {width}")


def hren_face_needed() -> float:
    """2·(max |ds/dφ| + 1 mm margin) on 10^6 points: 003 eq. 27, r_m = |ds/dφ|."""
    import tomllib

    cam = Cam.from_design(parse_design(tomllib.loads(HREN)))
    v = cam.motion(np.linspace(0, 2 * math.pi, 1_000_000, endpoint=False)).v
    return 2 * (float(np.abs(v).max()) + 1.0)


def run(tmp_path, text: str, *args: str) -> int:
    design = tmp_path / "design.toml"
    design.write_text(text)
    return main([args[0], str(design), *args[1:]])


@pytest.mark.parametrize(
    ("text", "field"),
    [
        (UNDERCUT, "cam.base_radius"),
        (CONSTANT_VELOCITY, "motion[2].law"),  # the first jump, at 0°: the return ends moving
        (narrow_face(10.0), "follower.face_width"),
    ],
    ids=["undercut", "velocity-jump", "face-width"],
)
def test_hard_limits_stop_build_and_check(tmp_path, capsys, text, field):
    out = tmp_path / "out"
    assert run(tmp_path, text, "build", "-o", str(out), "-q") == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("camcad: design limit:") and field in err[0]
    assert snapshot(out) == {} and not out.exists()
    assert run(tmp_path, text, "check") == 3
    printed = capsys.readouterr().out
    assert "max pressure angle" in printed  # the table is still there
    assert "hard limit:" in printed and field in printed


def test_the_face_advice_is_the_width_needed(tmp_path, capsys):
    needed = hren_face_needed()
    assert run(tmp_path, narrow_face(round(needed - 0.05, 3)), "check") == 3
    assert f"face_width ≥ {math.ceil(needed * 100) / 100:.2f} mm" in capsys.readouterr().out
    assert run(tmp_path, narrow_face(round(needed + 0.05, 3)), "check") == 0


def test_a_velocity_jump_is_named_with_a_law_to_use(tmp_path, capsys):
    assert run(tmp_path, CONSTANT_VELOCITY, "build", "-o", str(tmp_path / "o"), "--only", "dxf") == 3
    err = capsys.readouterr().err
    assert "'constant-velocity'" in err and "cycloidal" in err and "velocity jump" in err


def test_soft_limits_warn_build_and_fail_strict_build_and_check(tmp_path, capsys):
    out = tmp_path / "out"
    assert run(tmp_path, SOFT, "build", "-o", str(out), "--only", "tables") == 0
    assert "warning: pressure angle reaches" in capsys.readouterr().err
    assert (out / "summary.json").exists()
    strict = tmp_path / "strict"
    assert run(tmp_path, SOFT, "build", "-o", str(strict), "--strict", "-q") == 3
    err = capsys.readouterr().err
    assert "--strict" in err and "cam.max_pressure_angle" in err
    assert not strict.exists()
    assert run(tmp_path, SOFT, "check") == 3
    assert "soft limit: pressure angle reaches" in capsys.readouterr().out


def test_an_unreachable_fit_tolerance_is_hard(tmp_path, capsys):
    text = HARMONIC.replace("[fit]", "[fit]\nmax_control_points = 8")
    assert run(tmp_path, text, "build", "-o", str(tmp_path / "o"), "-q") == 3
    assert "fit.max_control_points" in capsys.readouterr().err
    assert run(tmp_path, text, "check") == 3
    assert "hard limit: fit.max_control_points" in capsys.readouterr().out


def test_a_velocity_jump_has_no_finite_acceleration_peak():
    """Constant velocity between rests: v jumps at every segment end, so |a| peaks are impulses."""
    import tomllib

    from camcad.pipeline import analyse

    design = parse_design(tomllib.loads(CONSTANT_VELOCITY))
    motion = analyse(design, fit=False, toolpath=False, strict=False).summary()["motion"]
    starts = np.cumsum([0.0] + [seg.span for seg in design.motion])[:-1]
    moving = [i for i, seg in enumerate(design.motion) if seg.law is not None]
    ends = {round(math.degrees(starts[i]), 6) for i in moving}
    ends |= {round(math.degrees(starts[i] + design.motion[i].span) % 360.0, 6) for i in moving}
    assert set(motion["velocity_jumps_deg"]) == ends
    assert motion["a_max_abs_mm_per_rad2"] is None and motion["j_max_abs_mm_per_rad3"] is None


# Hren's tappet with the guides close to the cam (a_m = 20, b_m = 250 mm): the far guide's force N3
# turns negative over part of the rise, where eq. 25's friction direction no longer holds
GUIDE_FLIP = edit(edit(HREN, r"^a_m = .*$", "a_m = 20.0"), r"^b_m = .*$", "b_m = 250.0")


def test_a_note_is_a_finding_that_changes_no_exit_code(tmp_path, capsys):
    """What used to be a free warning string (the guide force changing side) is a NOTE finding."""
    import json

    import tomllib

    from camcad.pipeline import analyse

    out = tmp_path / "out"
    assert run(tmp_path, GUIDE_FLIP, "build", "-o", str(out), "--only", "tables", "--strict") == 0
    assert "note: guide force N3 changes side" in capsys.readouterr().err
    found = json.loads((out / "summary.json").read_text())["findings"]
    assert "warnings" not in json.loads((out / "summary.json").read_text())
    (note,) = found
    assert note["severity"] == "note" and note["field"] == "dynamics.model"
    assert note["message"].startswith("guide force N3 changes side between")
    # the note starts where the sampled far guide force is negative (the dynamics' own arrays)
    dyn = analyse(parse_design(tomllib.loads(GUIDE_FLIP)), fit=False, toolpath=False).dynamics
    i = int(np.argmin(np.abs(dyn.phi - math.radians(note["angle_deg"]))))
    assert dyn.guide_force_far[i] < 0.0 <= dyn.guide_force_near[i]
    assert run(tmp_path, GUIDE_FLIP, "check") == 0
    printed = capsys.readouterr().out
    assert "  note: guide force N3 changes side" in printed and "all design limits hold" in printed
    assert run(tmp_path, HREN, "check") == 0  # the paper's guides: N3 stays on its side, no note
    assert "note:" not in capsys.readouterr().out


# Hren's tappet with friction 0.5 everywhere and its guides 10 mm apart: eq. 25's denominator at φ = 0
# (s = v = 0, h = r_b = 50 mm) is f1·f3·b + b − f1·b·(f3 + f2) − f1·f3·a − a + f1·h·(f3 + f2)
# = 27.5 + 110 − 55 − 25 − 100 + 25 = −17.5 mm ≤ 0: the tappet self-locks
SELF_LOCKING = edit(
    edit(edit(HREN, r"^a_m = .*$", "a_m = 100.0"), r"^b_m = .*$", "b_m = 110.0"),
    r"^(f[123]) = .*$",
    r"\1 = 0.5",
    count=3,
)


def test_an_error_names_its_field_as_data_in_the_cli_and_the_designer(tmp_path, capsys):
    """The caller that knows the TOML path sets ``.field``; the CLI line and the designer's JSON show it."""
    import tomllib

    from camcad.errors import DesignLimitError
    from camcad.pipeline import analyse
    from camcad.serve.payload import evaluate

    design = parse_design(tomllib.loads(SELF_LOCKING))
    with pytest.raises(DesignLimitError) as caught:
        analyse(design, fit=False, toolpath=False, strict=False)
    assert caught.value.field == "dynamics.b_m"
    assert "denominator of Hren et al. eq. 25 is -17.5 mm" in caught.value.message
    assert run(tmp_path, SELF_LOCKING, "check") == 3
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line == f"camcad: design limit: dynamics.b_m: {caught.value.message}"
    page = evaluate(tomllib.loads(SELF_LOCKING))
    assert page["ok"] is False
    assert page["errors"] == [{"field": "dynamics.b_m", "message": caught.value.message}]
    # bad input: the field the schema named, the message without it
    bad = evaluate(tomllib.loads(edit(HREN, r"^base_radius = .*$", "base_radius = -5.0")))
    (error,) = bad["errors"]
    assert error["field"] == "cam.base_radius" and not error["message"].startswith("cam.base_radius")
