"""Point tables: a known law sampled with noise is recovered; spikes are flagged; the file format.

Independent truth: the closed-form 4-5-6-7 program the table was sampled
from, and noise of a known σ drawn with fixed seeds.
"""

from __future__ import annotations

import math

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
    """README's bounds: s within 2σ, v within 1.5 % of peak |v|, a within 25 % of peak |a| (1° table)."""
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
