"""Point tables: a known law sampled with noise is recovered; spikes are flagged; the file format.

Independent truth: the closed-form 4-5-6-7 program the table was sampled
from, and noise of a known σ drawn with fixed seeds.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.design import parse_design
from camcad.errors import DesignError
from camcad.motion.laws import make_law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec
from camcad.motion.table import parse_table_text, smooth_table

RAD = math.radians
SIGMA = 0.005  # mm


def truth() -> MotionProgram:
    """Rise 10 mm over 120° (4-5-6-7), dwell 60°, return, dwell: C3, jerk continuous."""
    law = make_law("poly-4567")
    return MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=RAD(120), lift=10, law=law),
            SegmentSpec(kind=SegmentKind.DWELL, span=RAD(60)),
            SegmentSpec(kind=SegmentKind.RETURN, span=RAD(120), lift=10, law=law),
            SegmentSpec(kind=SegmentKind.DWELL, span=RAD(60)),
        ]
    )


def noisy_table(seed: int, step_deg: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    phi = np.radians(np.arange(0.0, 360.0, step_deg))
    rng = np.random.default_rng(seed)
    return phi, truth().evaluate(phi).s + rng.normal(0.0, SIGMA, phi.size)


def table_program(phi, lift, **kw) -> MotionProgram:
    law = smooth_table(phi, lift, noise=SIGMA, **kw)
    return MotionProgram.from_segments([SegmentSpec(kind=SegmentKind.TABLE, span=2 * math.pi, law=law)])


@pytest.mark.parametrize("seed", range(5))
def test_noisy_table_recovers_the_law_within_the_noise(seed):
    """The docs' bounds: s within 2σ, v within 1.5 % of peak |v|, a within 25 % of peak |a| (1° table)."""
    phi, lift = noisy_table(seed)
    prog = table_program(phi, lift)
    dense = np.linspace(0.0, 2 * math.pi, 20_001)
    got, want = prog.evaluate(dense), truth().evaluate(dense)
    assert np.max(np.abs(got.s - want.s)) <= 2 * SIGMA
    assert np.max(np.abs(got.v - want.v)) <= 0.015 * np.max(np.abs(want.v))
    assert np.max(np.abs(got.a - want.a)) <= 0.25 * np.max(np.abs(want.a))
    fit = prog.segments[0].law.fit
    assert 0.9 * SIGMA <= fit.rms <= 1.1 * SIGMA  # Σ (r/σ)² ≈ m
    assert fit.flags == ()  # nothing implausible in clean noise of the stated size


def test_table_is_smooth_to_the_jerk_everywhere_including_the_seam():
    """A periodic quintic: s, v, a, j equal on both sides of 0° and continuous between samples."""
    phi, lift = noisy_table(7)
    prog = table_program(phi, lift)
    left, right = prog.evaluate(0.0, side="left"), prog.evaluate(0.0, side="right")
    for k in "svaj":
        assert_allclose(getattr(left, k), getattr(right, k), rtol=1e-9, atol=1e-9)
    assert [bp.continuity for bp in prog.breakpoints] == [3]
    knots = np.array(prog.smooth_knots)
    assert knots.size > 10
    for phi in knots:  # at the spline's knots nothing jumps either (one-sided limits)
        left, right = prog.evaluate(phi, side="left"), prog.evaluate(phi, side="right")
        for k in "svaj":
            assert_allclose(getattr(left, k), getattr(right, k), rtol=1e-9, atol=1e-9)
    x = np.linspace(0, 2 * math.pi, 200_001)
    j = prog.evaluate(x).j
    assert np.max(np.abs(np.diff(j))) < 1e-2 * np.max(np.abs(j))  # no jump between dense samples


def test_velocity_is_the_derivative_of_the_displacement():
    """v, a, j of the table law against central differences of its own s."""
    phi, lift = noisy_table(3)
    prog = table_program(phi, lift)
    x = np.linspace(0.1, 6.0, 40)
    h = 1e-5
    m, mp, mm = prog.evaluate(x), prog.evaluate(x + h), prog.evaluate(x - h)
    for lo, hi in (("s", "v"), ("v", "a"), ("a", "j")):
        fd = (getattr(mp, lo) - getattr(mm, lo)) / (2 * h)
        assert_allclose(getattr(m, hi), fd, atol=1e-4 * (1 + np.max(np.abs(fd))))


def test_a_spike_is_flagged_at_its_angle():
    """One point off by 12σ: its lift residual and the table's acceleration there are flagged."""
    phi, lift = noisy_table(1)
    lift = lift.copy()
    lift[200] += 12 * SIGMA
    law = smooth_table(phi, lift, noise=SIGMA)
    angles = {round(math.degrees(f.angle), 6) for f in law.fit.flags}
    kinds = {f.quantity for f in law.fit.flags if round(math.degrees(f.angle)) == 200}
    assert 200.0 in angles
    assert {"lift", "acceleration"} <= kinds
    assert all(abs(math.degrees(f.angle) - 200.0) <= 2.0 for f in law.fit.flags)
    text = law.fit.flags[0].describe()
    assert "the stated noise explains" in text


def test_velocity_column_residual_against_the_law():
    phi, lift = noisy_table(2)
    v = truth().evaluate(phi).v
    law = smooth_table(phi, lift, noise=SIGMA, velocity=v)
    assert law.fit.velocity_residual is not None
    assert np.max(np.abs(law.fit.velocity_residual)) <= 0.015 * np.max(np.abs(v))


def test_parse_header_comments_separators_and_closing_row():
    rows = "\n".join(f"{a};{10 * math.sin(math.radians(a)) ** 2:.6f}" for a in range(0, 361, 15))
    text = "# measured 2026-11-26\nangle_deg;lift_mm\n" + rows + "\n"
    angle, _, velocity = parse_table_text(text)
    assert angle.size == 24 and velocity is None  # the 360° row repeats 0° and is dropped
    assert_allclose(np.degrees(angle[[0, -1]]), [0, 345])


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("0,1\n10,2\n5,3\n" + "".join(f"{20 + i},0\n" for i in range(12)), "angles must increase"),
        ("0,1\n1,x\n", "line 2, field 2: expected a number"),
        ("0,1\n1,2\n", "at least 12"),
        ("".join(f"{i * 30},{i}\n" for i in range(12)) + "360,5\n", "must repeat the row at 0°"),
        ("".join(f"{i * 30},{i},{i}\n" for i in range(11)) + "350,1\n", "different numbers of columns"),
    ],
    ids=["not-increasing", "text", "too-few", "bad-closing-row", "ragged"],
)
def test_bad_tables_name_the_field(text, words):
    with pytest.raises(DesignError) as err:
        parse_table_text(text, where="motion[0].file")
    assert err.value.path == "motion[0].file"
    assert words in err.value.message


def test_design_reads_the_table_relative_to_the_design_file(tmp_path):
    phi, lift = noisy_table(4, step_deg=2.0)
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "lift.csv").write_text(
        "angle_deg,lift_mm\n"
        + "".join(f"{math.degrees(p):.6f},{s:.6f}\n" for p, s in zip(phi, lift, strict=True))
    )
    data = {
        "cam": {"base_radius": 50, "thickness": 10},
        "follower": {"roller_radius": 10},
        "motion": [{"kind": "table", "file": "data/lift.csv", "noise": SIGMA}],
    }
    design = parse_design(data, source=str(tmp_path / "cam.toml"))
    prog = MotionProgram.from_segments(design.motion)
    assert prog.lift == pytest.approx(10.0, abs=2 * SIGMA)
    with pytest.raises(DesignError) as err:
        parse_design(
            data | {"motion": [{"kind": "table", "file": "nope.csv", "noise": SIGMA}]},
            source=str(tmp_path / "cam.toml"),
        )
    assert err.value.path == "motion[0].file"
    with pytest.raises(DesignError) as err:
        parse_design(
            data | {"motion": [{"kind": "table", "file": "data/lift.csv"}]}, source=str(tmp_path / "cam.toml")
        )
    assert err.value.path == "motion[0].noise"
    with pytest.raises(DesignError) as err:
        parse_design(
            data
            | {
                "motion": [
                    {"kind": "table", "file": "data/lift.csv", "noise": SIGMA},
                    {"kind": "dwell", "angle": 10},
                ]
            },
            source=str(tmp_path / "cam.toml"),
        )
    assert err.value.path == "motion[0].kind"


# ---------------------------------------------------------------------------
# issue 32: what a table file may be, and what an error may show of it


def _table_design(file: str) -> dict:
    return {
        "cam": {"base_radius": 50, "thickness": 10},
        "follower": {"roller_radius": 10},
        "motion": [{"kind": "table", "file": file, "noise": SIGMA}],
    }


def _good_rows(lift=lambda a: 5 * (1 - math.cos(math.radians(a)))) -> str:
    return "angle_deg,lift_mm\n" + "".join(f"{a},{lift(a):.6f}\n" for a in range(0, 360, 10))


def _refusal(data: dict, source: Path, **kw) -> DesignError:
    with pytest.raises(DesignError) as err:
        parse_design(data, source=str(source), **kw)
    return err.value


@pytest.mark.parametrize(
    ("file", "words"),
    [
        ("/dev/zero", "not a regular file"),
        ("/dev/urandom", "not a regular file"),
        ("/dev/null", "not a regular file"),
        (".", "it is a folder"),
    ],
    ids=["dev-zero", "dev-urandom", "dev-null", "folder"],
)
def test_only_a_regular_file_is_read(tmp_path, file, words):
    if not Path(file if file != "." else tmp_path).exists():
        pytest.skip(f"{file} is not on this system")
    err = _refusal(_table_design(file), tmp_path / "cam.toml")
    assert err.path == "motion[0].file" and words in err.message


def test_a_fifo_is_refused_without_blocking(tmp_path):
    """In a child process with a deadline: a blocking open would hang it, not the test run."""
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs on this system")
    os.mkfifo(tmp_path / "lift.csv")
    design = tmp_path / "cam.toml"
    design.write_text(
        '[cam]\nbase_radius = 50\n[follower]\nroller_radius = 10\n[[motion]]\nkind = "table"\n'
        'file = "lift.csv"\nnoise = 0.005\n'
    )
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2]))
    proc = subprocess.run(
        [sys.executable, "-m", "camcad", "check", str(design)],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )
    assert proc.returncode == 2
    fifo = repr(str(tmp_path / "lift.csv"))
    assert proc.stderr.splitlines() == [
        f"camcad: error: motion[0].file: cannot read {fifo}: it is not a regular file "
        "(a device, pipe or socket); allowed: a regular file"
    ]


def test_a_file_over_16_mib_is_refused_unread(tmp_path):
    from camcad.design.table_file import MAX_TABLE_BYTES

    with (tmp_path / "big.csv").open("wb") as f:  # sparse: no disk, and never read
        f.truncate(MAX_TABLE_BYTES + 1)
    err = _refusal(_table_design("big.csv"), tmp_path / "cam.toml")
    assert err.path == "motion[0].file" and f"at most {MAX_TABLE_BYTES} bytes (16 MiB)" in err.message
    (tmp_path / "ok.csv").write_text(_good_rows() + "#" * (MAX_TABLE_BYTES - 2000) + "\n")
    parse_design(_table_design("ok.csv"), source=str(tmp_path / "cam.toml"))  # just under: read


SECRET = "hunter2-sk-0123456789"


@pytest.mark.parametrize(
    "text",
    [
        f"root:x:0:0:{SECRET}\ndaemon:{SECRET}\n",  # /etc/passwd-like: the header, then a line of text
        f"angle,lift\n0,0\n10,{SECRET}\n",
        f"angle,lift\n0,0\n10 {SECRET} 1\n",
        f"0,0\n{SECRET}\n",
    ],
    ids=["passwd", "cell", "middle-cell", "whole-line"],
)
def test_errors_name_the_line_and_field_never_the_text(tmp_path, text):
    (tmp_path / "t.csv").write_text(text)
    err = _refusal(_table_design("t.csv"), tmp_path / "cam.toml")
    assert err.path == "motion[0].file" and "expected a number" in err.message
    assert SECRET not in str(err) and "hunter" not in str(err) and "root" not in str(err)
    assert re.search(r"line \d+, field \d+", err.message)


def test_a_file_that_is_not_utf8_is_refused_without_its_bytes(tmp_path):
    (tmp_path / "t.csv").write_bytes(b"0,0\n1,\xff\xfe" + SECRET.encode())
    err = _refusal(_table_design("t.csv"), tmp_path / "cam.toml")
    assert (
        "not UTF-8 text (byte offset 6)" in err.message and SECRET not in str(err) and "0xff" not in str(err)
    )


def test_confine_to_keeps_the_file_inside_the_folder(tmp_path):
    inside, outside = tmp_path / "designs", tmp_path / "secret"
    inside.mkdir()
    outside.mkdir()
    (inside / "lift.csv").write_text(_good_rows())
    (outside / "lift.csv").write_text(_good_rows())
    (inside / "link.csv").symlink_to(outside / "lift.csv")
    source = inside / "cam.toml"
    parse_design(_table_design("lift.csv"), source=str(source), confine_to=inside)
    for name in ("../secret/lift.csv", str(outside / "lift.csv"), "link.csv"):
        err = _refusal(_table_design(name), source, confine_to=inside)
        assert err.path == "motion[0].file" and "leads outside the design's folder" in err.message, name
        parse_design(_table_design(name), source=str(source))  # without confinement each is read
    assert not (inside / "nope.csv").exists()
    err = _refusal(_table_design("nope.csv"), source, confine_to=inside)
    assert "No such file" in err.message


@pytest.mark.parametrize(
    ("cell", "field"),
    [("1e300", 2), ("nan", 2), ("inf", 2), ("-1e5", 2), ("1e300", 3)],
    ids=["lift-1e300", "lift-nan", "lift-inf", "lift-negative-huge", "velocity-1e300"],
)
def test_table_values_are_bounded_like_every_length(cell, field):
    """1e300 made FITPACK fail with a SciPy internal error; now the line and field are named."""
    rows = [f"{a},{a / 100:.4f},0.0" for a in range(0, 360, 10)]
    a, s, v = rows[5].split(",")
    rows[5] = ",".join([a, cell, v] if field == 2 else [a, s, cell])
    with pytest.raises(DesignError) as err:
        parse_table_text("\n".join(rows), where="motion[0].file")
    assert err.value.message.startswith(f"line 6, field {field} (")
    assert "at most 10000" in err.value.message


@pytest.mark.parametrize("angle", ["-0.5", "360.5", "1e300"], ids=["negative", "past-360", "huge"])
def test_table_angles_outside_the_turn_name_the_line(angle):
    rows = [f"{a},0" for a in range(0, 360, 10)]
    rows.insert(3, f"{angle},0") if angle != "-0.5" else rows.insert(0, f"{angle},0")
    with pytest.raises(DesignError) as err:
        parse_table_text("\n".join(rows), where="motion[0].file")
    assert re.match(r"line \d+, field 1 \(angle", err.value.message), err.value.message


def test_the_trough_is_the_smallest_lift_by_brute_force():
    phi, lift = noisy_table(3)
    law = smooth_table(phi, lift - 0.2, noise=SIGMA)
    lowest, at = law.trough
    dense = np.linspace(0.0, 2 * math.pi, 400_001)
    s = law.evaluate(dense / (2 * math.pi))[0]
    assert lowest <= float(s.min()) + 1e-12 and lowest == pytest.approx(float(s.min()), abs=1e-9)
    assert float(law.evaluate(at / (2 * math.pi))[0]) == pytest.approx(lowest, abs=1e-12)


def test_a_table_below_the_base_circle_is_refused(tmp_path):
    """As a return below the base circle is (segments): after smoothing, past what the noise explains (4σ)."""
    (tmp_path / "low.csv").write_text(_good_rows(lambda a: 5 * (1 - math.cos(math.radians(a))) - 0.5))
    err = _refusal(_table_design("low.csv"), tmp_path / "cam.toml")
    assert err.path == "motion[0].file" and "below the base circle" in err.message
    assert "dips to -0.5" in err.message and "φ = 0.000°" in err.message
    (tmp_path / "noisy.csv").write_text(_good_rows(lambda a: 5 * (1 - math.cos(math.radians(a))) - 2 * SIGMA))
    parse_design(_table_design("noisy.csv"), source=str(tmp_path / "cam.toml"))  # within the noise: kept


def test_a_long_table_with_a_noise_below_its_scatter_is_refused_at_once(tmp_path):
    """A 36 000-row table rounded to 0.1 µm with noise 1e-6 ran for more than 10 minutes (issue 32).

    Independent: rounding to q scatters within ±q/2 (σ = q/√12 if uniform and independent; on a
    slowly varying law the rounding errors are correlated, so the estimate lies between that and q/2).
    """
    from camcad.motion.table import table_scatter

    phi = np.arange(36000) * 0.01
    lift = np.round(5 * (1 - np.cos(np.radians(phi))), 4)
    assert 1e-4 / math.sqrt(12) <= table_scatter(np.radians(phi), lift) <= 1e-4 / 2
    rows = "".join(f"{a:.2f},{s:.4f}\n" for a, s in zip(phi, lift, strict=True))
    (tmp_path / "lift.csv").write_text("angle,lift\n" + rows)
    data = _table_design("lift.csv")
    data["motion"][0]["noise"] = 1e-6
    err = _refusal(data, tmp_path / "cam.toml")
    assert err.path == "motion[0].noise" and "far below the table's own scatter" in err.message
    noisy, _ = noisy_table(5, step_deg=0.25)  # 1440 rows of noise σ: the estimate finds σ
    _, lift_noisy = noisy_table(5, step_deg=0.25)
    assert table_scatter(noisy, lift_noisy) == pytest.approx(SIGMA, rel=0.15)
