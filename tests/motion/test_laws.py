"""Tests of camcad.motion.laws: closed forms, papers 000 (VAP) and 003 (Dudley)."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from camcad.errors import DesignError
from camcad.motion._scca import _scca_evaluate
from camcad.motion.laws import (
    DUDLEY_MAX_DEGREE,
    LAWS,
    Cycloidal,
    Dudley,
    Harmonic,
    Law,
    LawInfo,
    ModifiedSine,
    ModifiedTrapezoid,
    Poly345,
    Poly4567,
    Vap,
    dudley_coefficients,
    dudley_matrix,
    make_law,
)

CASES: list[tuple[str, dict[str, object]]] = [
    ("constant-velocity", {}),
    ("harmonic", {}),
    ("cycloidal", {}),
    ("poly-345", {}),
    ("poly-4567", {}),
    *[("dudley", {"degree": n}) for n in (3, 5, 7, 9, 11)],
    ("modified-trapezoid", {}),
    ("modified-sine", {}),
    *[("modified-sine-cv", {"cv": c}) for c in (0.2, 0.5)],
    *[("vap", {"b": b}) for b in (0.1, 0.5, 0.9)],
]
LAWS_UNDER_TEST = [make_law(name, **params) for name, params in CASES]
IDS = [law.describe().replace(" ", "-") for law in LAWS_UNDER_TEST]
GRID = np.linspace(0.0, 1.0, 4001)


def _scales(law: Law) -> list[float]:
    """Max |y^(k)| over a dense grid, at least 1, for tolerances."""
    return [max(1.0, float(np.max(np.abs(d)))) for d in law.evaluate(GRID)]


def _fd7(f, x: float, h: float) -> float:
    """7-point central difference of f at x, truncation error O(h⁶)."""
    c = (-1.0, 9.0, -45.0, 0.0, 45.0, -9.0, 1.0)
    return sum(ci * float(f(x + k * h)) for ci, k in zip(c, range(-3, 4), strict=True)) / (60.0 * h)


# ------------------------------------------------------------------ every law


@pytest.mark.parametrize("law", LAWS_UNDER_TEST, ids=IDS)
def test_rise_reaches_both_ends(law: Law) -> None:
    y = law.evaluate([0.0, 1.0])[0]
    assert_allclose(y, [0.0, 1.0], rtol=0, atol=1e-15)


@pytest.mark.parametrize("law", LAWS_UNDER_TEST, ids=IDS)
@settings(max_examples=40, deadline=None)
@given(x=st.floats(0.0, 1.0))
def test_derivatives_match_finite_differences_of_own_lower_order(law: Law, x: float) -> None:
    h = 1e-3
    assume(3 * h <= x <= 1 - 3 * h)
    assume(all(abs(x - bp) > 3.5 * h for bp in law.breakpoints))
    derivs = law.evaluate(x)
    scales = _scales(law)
    for k in (1, 2, 3):
        fd = _fd7(lambda t, k=k: law.evaluate(t)[k - 1], x, h)
        assert_allclose(derivs[k], fd, rtol=1e-6, atol=1e-6 * scales[k], err_msg=f"order {k}")


@pytest.mark.parametrize("law", LAWS_UNDER_TEST, ids=IDS)
def test_rise_is_monotone(law: Law) -> None:
    y, y1, _, _ = law.evaluate(GRID)
    assert np.all(y1 >= 0.0)
    assert np.all(np.diff(y) >= -1e-15)


@pytest.mark.parametrize("law", LAWS_UNDER_TEST, ids=IDS)
def test_end_continuity_flags_match_evaluate(law: Law) -> None:
    scales = _scales(law)
    for x, flags in ((0.0, law.zero_at_start), (1.0, law.zero_at_end)):
        derivs = law.evaluate(x)
        for k in (1, 2, 3):
            if k in flags:
                assert abs(float(derivs[k])) <= 1e-12 * scales[k], (x, k)
            else:
                assert abs(float(derivs[k])) > 1e-6 * scales[k], (x, k)


@pytest.mark.parametrize("law", LAWS_UNDER_TEST, ids=IDS)
def test_point_symmetry_about_midpoint(law: Law) -> None:
    x = GRID[:2000]
    y, y1, y2, y3 = law.evaluate(x)
    m0, m1, m2, m3 = law.evaluate(1.0 - x)
    scales = _scales(law)
    assert_allclose(m0, 1.0 - y, rtol=0, atol=1e-14)
    assert_allclose(m1, y1, rtol=0, atol=1e-13 * scales[1])
    assert_allclose(m2, -y2, rtol=0, atol=1e-12 * scales[2])
    assert_allclose(m3, y3, rtol=0, atol=1e-12 * scales[3])


@pytest.mark.parametrize("law", LAWS_UNDER_TEST, ids=IDS)
def test_outputs_are_readonly_float64_of_input_shape(law: Law) -> None:
    x = np.linspace(0.0, 1.0, 12).reshape(3, 4)
    x_before = x.copy()
    for arr in law.evaluate(x):
        assert arr.shape == (3, 4)
        assert arr.dtype == np.float64
        assert not arr.flags.writeable
    assert_allclose(x, x_before, rtol=0, atol=0)
    for arr in law.evaluate(0.25):
        assert arr.shape == ()
        assert not arr.flags.writeable


# ------------------------------------------------------------- closed forms


@pytest.mark.parametrize(
    ("law", "peak"),
    [(Harmonic(), math.pi / 2), (Cycloidal(), 2.0), (Poly345(), 15 / 8), (Poly4567(), 35 / 16)],
    ids=["harmonic", "cycloidal", "poly-345", "poly-4567"],
)
def test_peak_velocity_closed_form(law: Law, peak: float) -> None:
    assert_allclose(law.evaluate(0.5)[1], peak, rtol=1e-15)
    assert np.max(law.evaluate(GRID)[1]) <= peak * (1 + 1e-15)


@pytest.mark.parametrize(
    ("law", "peak_v", "peak_a"),
    [(ModifiedTrapezoid(), 2.000, 4.888), (ModifiedSine(), 1.760, 5.528)],
    ids=["modified-trapezoid", "modified-sine"],
)
def test_scca_peaks_match_norton(law: Law, peak_v: float, peak_a: float) -> None:
    _, y1, y2, _ = law.evaluate(np.linspace(0.0, 1.0, 100_001))
    assert abs(np.max(y1) - peak_v) < 5e-4
    assert abs(np.max(np.abs(y2)) - peak_a) < 5e-4


@pytest.mark.parametrize(
    ("fractions", "law"),
    [((0.5, 0.0, 0.5), Cycloidal()), ((0.0, 0.0, 1.0), Harmonic())],
    ids=["cycloidal", "harmonic"],
)
def test_scca_family_reproduces_cycloidal_and_harmonic(fractions, law: Law) -> None:
    # Norton's SCCA: cycloidal is b = 0.5, c = 0, d = 0.5; harmonic is b = c = 0, d = 1.
    x = np.linspace(0.0, 1.0, 1001)
    for got, want in zip(_scca_evaluate(*fractions, x), law.evaluate(x), strict=True):
        assert_allclose(got, want, rtol=0, atol=1e-12)


def test_scca_breakpoints() -> None:
    assert ModifiedTrapezoid().breakpoints == (0.125, 0.375, 0.625, 0.875)
    assert ModifiedSine().breakpoints == (0.125, 0.875)


# --------------------------------------------------------------- VAP (paper 000)

BETA, RISE = 1.3, 7.0  # an arbitrary rise of 7 mm over 1.3 rad


def _vap_paper(b: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eqs. 4-8 of Quintero & Vanegas 2016 typed in literally, papers/README mapping."""
    tau, ym, ya = 2 * BETA, RISE / 2, RISE / 2
    xp = (x - 0.5) * BETA  # paper abscissa, |xp| ≤ τ/4
    h1 = np.arcsin(np.sin(2 * np.pi * xp / tau)) / np.pi  # eq. 5
    h2 = np.arcsin(np.sin(np.arccos(np.cos(2 * np.pi * xp / tau)))) / np.pi  # eq. 6
    ex = np.exp((1 - b) / b * (2 * h2 - 1))
    y = ym + 2 * ya / (1 - b) * h1 * (1 - b * ex)  # eq. 4
    k1 = np.where(np.floor(2 * xp / tau + 0.5) % 2 == 0, 1.0, -1.0)  # eq. 8
    dy = 4 * k1 * ya / ((1 - b) * tau) * (1 - (b + 2 * (1 - b) * h2) * ex)  # eq. 7
    return y, dy


@pytest.mark.parametrize("b", [0.05, 0.1, 0.2, 0.5, 0.9, 0.99])
def test_vap_matches_paper_eqs_4_and_7(b: float) -> None:
    x = np.linspace(0.0, 1.0, 801)
    y_paper, dy_paper = _vap_paper(b, x)
    y, y1, _, _ = Vap(b=b).evaluate(x)
    assert_allclose(RISE * y, y_paper, rtol=0, atol=1e-12 * RISE)
    assert_allclose(RISE / BETA * y1, dy_paper, rtol=1e-12, atol=1e-12 * RISE / BETA)


@pytest.mark.parametrize("b", [0.05, 0.1, 0.2, 0.5, 0.9, 0.99])
def test_vap_peak_slope_matches_eq_9(b: float) -> None:
    tau, ya = 2 * BETA, RISE / 2
    peak_paper = 4 * ya / ((1 - b) * tau) * (1 - b * np.exp((b - 1) / b))  # eq. 9
    peak = BETA / RISE * peak_paper  # normalised: y' = (β/h) ds/dφ
    law = Vap(b=b)
    assert_allclose(law.evaluate(0.5)[1], peak, rtol=1e-14)
    assert np.max(law.evaluate(GRID)[1]) <= peak * (1 + 1e-14)


@pytest.mark.parametrize("b", [0.1, 0.5, 0.9])
def test_vap_acceleration_jumps_at_ends_and_midpoint(b: float) -> None:
    # Against a dwell: y''(0) = 2(1 + b)/b; at x = 1/2, |X| in eq. 3 makes y'' jump
    # from +4 e^(-k) to -4 e^(-k), k = (1 - b)/b; evaluate returns the mean 0 there.
    k = (1 - b) / b
    law = Vap(b=b)
    y2 = law.evaluate([0.0, 1.0, 0.5 - 1e-12, 0.5, 0.5 + 1e-12])[2]
    assert_allclose(y2[:2], [2 * (1 + b) / b, -2 * (1 + b) / b], rtol=1e-14)
    assert_allclose(y2[2:], [4 * np.exp(-k), 0.0, -4 * np.exp(-k)], rtol=1e-9, atol=1e-15)
    assert law.breakpoints == (0.5,)


# ------------------------------------------------------------ Dudley (paper 003)


@pytest.mark.parametrize(("degree", "law"), [(5, Poly345()), (7, Poly4567())], ids=["n5", "n7"])
def test_dudley_reproduces_named_polynomials(degree: int, law: Law) -> None:
    x = np.linspace(0.0, 1.0, 1001)
    for got, want in zip(Dudley(degree=degree).evaluate(x), law.evaluate(x), strict=True):
        assert_allclose(got, want, rtol=0, atol=1e-12)


def _beta_coefficients(n: int) -> list[Fraction]:
    """c_p..c_n of y = I_x(p, p): c_(p+k) = (2p-1)!/((p-1)!)² (-1)^k C(p-1, k)/(p+k)."""
    p = (n + 1) // 2
    scale = Fraction(math.factorial(2 * p - 1), math.factorial(p - 1) ** 2)
    return [scale * (-1) ** k * math.comb(p - 1, k) / (p + k) for k in range(p)]


@pytest.mark.parametrize("n", [3, 5, 9, 15, 21, 41])
def test_dudley_coefficients_have_the_incomplete_beta_closed_form(n: int) -> None:
    # y' = x^(p-1)(1-x)^(p-1)/B(p, p) is the unique solution of eqs. 2-5 on [0, 1].
    want = [0.0] * ((n + 1) // 2) + [float(c) for c in _beta_coefficients(n)]
    assert_allclose(dudley_coefficients(n, 1.0, 1.0), want, rtol=1e-15, atol=0)


def test_dudley_table_1_scaled_solution_solves_eq_8_system_exactly() -> None:
    # Hren et al. Table 1: n = 9, φ2 = π/2, z = 10 mm. With eq. 8 built in rationals
    # from the float φ2, α_i = z c_i/φ2^i (the scaling dudley_coefficients uses)
    # solves A·x = b (eqs. 7, 9-11) exactly.
    n, p = 9, 5
    phi2, z = Fraction(math.pi / 2), Fraction(10)
    x = [z * c / phi2 ** (p + f) for f, c in enumerate(_beta_coefficients(n))]
    for e in range(1, p + 1):
        row = sum(
            phi2 ** (p + f - e) * math.perm(p + f - 1, e - 1) * x[f - 1] for f in range(1, p + 1)
        )  # eq. 8
        assert row == (z if e == 1 else 0)


def test_dudley_table_1_boundary_conditions_in_physical_units() -> None:
    # Hren et al. Table 1: n = 9, φ2 = π/2, z = 10 mm; eqs. 2, 4, 5 with u, v = 1..4.
    n, phi2, z = 9, math.pi / 2, 10.0
    alpha = dudley_coefficients(n, phi2, z)
    a_exact, phi_exact = [Fraction(float(a)) for a in alpha], Fraction(phi2)

    def deriv(v: int, at: Fraction) -> tuple[float, float]:
        terms = [a_exact[i] * math.perm(i, v) * at ** (i - v) for i in range(v, n + 1)]
        return float(sum(terms)), float(sum(abs(t) for t in terms))

    for v in range(5):
        scale = z / phi2**v
        at_zero, _ = deriv(v, Fraction(0))
        assert at_zero == 0.0  # eq. 2: α_0..α_4 are exactly 0
        at_end, spread = deriv(v, phi_exact)
        residual = abs(at_end - (z if v == 0 else 0.0))
        # eqs. 4, 5. The monomial form amplifies the rounding of α by
        # spread/scale (1471 for v = 0 up to 1.36e6 for v = 4), so 1e-12 relative
        # to z/φ2^v is reachable only for v ≤ 1; higher orders are held to the
        # rounding level of their terms.
        assert residual <= 1e-15 * spread, (v, residual / scale)
        if v <= 1:
            assert residual <= 1e-12 * scale, (v, residual / scale)
    # eq. 7 with the float matrix of eq. 8, row-wise relative to its terms
    a_mat = dudley_matrix(n, phi2)
    b_vec = a_mat @ alpha[(n + 1) // 2 :]
    spread = np.abs(a_mat) @ np.abs(alpha[(n + 1) // 2 :])
    assert_allclose(b_vec, [z, 0, 0, 0, 0], rtol=0, atol=1e-14 * spread.max())


def test_dudley_table_1_matches_normalised_law() -> None:
    n, phi2, z = 9, math.pi / 2, 10.0
    phi = np.linspace(0.0, phi2, 181)
    s = np.polynomial.polynomial.polyval(phi, dudley_coefficients(n, phi2, z))
    assert_allclose(s, z * Dudley(degree=n).evaluate(phi / phi2)[0], rtol=0, atol=1e-12 * z)


def test_dudley_matrix_entries_follow_eq_8() -> None:
    # p = 2 (n = 3): rows s(φ2) = α2 φ2² + α3 φ2³, s'(φ2) = 2 α2 φ2 + 3 α3 φ2².
    phi2 = 0.7
    assert_allclose(dudley_matrix(3, phi2), [[phi2**2, phi2**3], [2 * phi2, 3 * phi2**2]], rtol=1e-15)


# -------------------------------------------------------------- registry, errors


def test_registry_names_and_order() -> None:
    assert list(LAWS) == [
        "constant-velocity",
        "harmonic",
        "cycloidal",
        "poly-345",
        "poly-4567",
        "dudley",
        "modified-trapezoid",
        "modified-sine",
        "modified-sine-cv",
        "vap",
        "polynomial",
        "inclined-sine",
    ]
    for name, info in LAWS.items():
        assert isinstance(info, LawInfo)
        assert info.name == name
        assert info.summary
    assert [p.name for p in LAWS["vap"].parameters] == ["b"]
    assert LAWS["vap"].parameters[0].kind is float
    assert [p.name for p in LAWS["dudley"].parameters] == ["degree"]
    assert LAWS["dudley"].parameters[0].kind is int


@pytest.mark.parametrize(("name", "params"), CASES, ids=IDS)
def test_make_law_builds_the_registered_class(name: str, params: dict[str, object]) -> None:
    law = make_law(name, **params)
    assert law.name == name
    assert law == make_law(name, **params)
    assert hash(law) == hash(make_law(name, **params))


def test_describe_texts() -> None:
    assert make_law("cycloidal").describe() == "cycloidal"
    assert make_law("vap", b=0.1).describe() == "VAP b=0.1"
    assert make_law("dudley", degree=9).describe() == "Dudley n=9"


@pytest.mark.parametrize(
    ("name", "params", "path", "fragments"),
    [
        ("cycloid", {}, "law", ["'cycloid'", "did you mean 'cycloidal'?", "allowed:", "vap"]),
        ("vap", {"b": 1}, "b", ["b = 1 ", "0 < b < 1"]),
        ("vap", {"b": 0}, "b", ["b = 0 ", "0 < b < 1"]),
        ("vap", {"b": 1.5}, "b", ["b = 1.5 ", "0 < b < 1"]),
        ("vap", {"b": float("nan")}, "b", ["b = nan ", "0 < b < 1"]),
        ("vap", {"b": "0.1"}, "b", ["b = '0.1' ", "not a number"]),
        ("vap", {"b": True}, "b", ["b = True ", "not a number"]),
        ("vap", {}, "b", ["required", "0 < b < 1"]),
        ("vap", {"bb": 0.1}, "bb", ["'bb'", "did you mean 'b'?"]),
        ("vap", {"b": 0.1, "degree": 9}, "degree", ["'degree'", "allowed: b"]),
        ("dudley", {"degree": 4}, "degree", ["degree = 4 ", "odd integer"]),
        ("dudley", {"degree": 1}, "degree", ["degree = 1 ", "3 ≤ degree"]),
        ("dudley", {"degree": DUDLEY_MAX_DEGREE + 2}, "degree", ["degree = 101 ", "≤ 99"]),
        ("dudley", {"degree": True}, "degree", ["degree = True ", "not an integer"]),
        ("dudley", {"degree": 9.0}, "degree", ["degree = 9.0 ", "not an integer"]),
        ("dudley", {}, "degree", ["required", "odd integer"]),
        ("dudley", {"degre": 9}, "degre", ["did you mean 'degree'?"]),
        ("cycloidal", {"b": 0.1}, "b", ["'b'", "takes no parameters"]),
    ],
    ids=lambda v: None if not isinstance(v, str) else v,
)
def test_make_law_errors_name_field_and_value(
    name: str, params: dict[str, object], path: str, fragments: list[str]
) -> None:
    with pytest.raises(DesignError) as info:
        make_law(name, **params)
    assert info.value.path == path
    for fragment in fragments:
        assert fragment in info.value.message


def test_make_law_accepts_numpy_scalars() -> None:
    assert make_law("vap", b=np.float64(0.25)) == Vap(b=0.25)
    assert make_law("dudley", degree=np.int64(9)) == Dudley(degree=9)
    assert type(Dudley(degree=np.int64(9)).degree) is int


def test_direct_construction_is_validated() -> None:
    with pytest.raises(DesignError, match="b = 2"):
        Vap(b=2)
    with pytest.raises(DesignError, match="degree = 6"):
        Dudley(degree=6)
    with pytest.raises(DesignError) as info:
        dudley_coefficients(8, 1.0, 1.0)
    assert info.value.path == "n"
    with pytest.raises(DesignError) as info:
        dudley_matrix(9, 0.0)
    assert info.value.path == "phi2"


# ------------------------------------------------- modified sine with constant velocity


def _rothbart_ms(x: np.ndarray) -> np.ndarray:
    """The modified sine in Rothbart's three-piece closed form (Cam Design Handbook, ch. 2)."""
    k = 1.0 / (4.0 + math.pi)
    return np.where(
        x < 1 / 8,
        k * (math.pi * x - 0.25 * np.sin(4 * math.pi * x)),
        np.where(
            x < 7 / 8,
            k * (2 + math.pi * x - 2.25 * np.sin(4 * math.pi * x / 3 + math.pi / 3)),
            k * (4 + math.pi * x - 0.25 * np.sin(4 * math.pi * x)),
        ),
    )


@pytest.mark.parametrize("cv", [0.0, 0.25, 0.6])
def test_modified_sine_cv_against_rothbart_and_a_straight_middle(cv: float) -> None:
    """Accelerating part: Rothbart's MS over w = 1 − cv, scaled by A; then a line of the peak slope."""
    law = make_law("modified-sine-cv", cv=cv)
    w = 1.0 - cv
    peak = 4 * math.pi / (4 + math.pi)  # Rothbart's MS: y'(1/2) = π(1 + 3)/(4 + π)
    amp = 1.0 / (1.0 + cv * peak / w)
    x = np.linspace(0.0, 0.5 * w, 200)
    assert_allclose(law.evaluate(x)[0], amp * _rothbart_ms(x / w), atol=1e-14)
    mid = np.linspace(0.5 * w, 1 - 0.5 * w, 50)
    y, y1, y2, _ = law.evaluate(mid)
    assert_allclose(y1, amp * peak / w, rtol=1e-12)
    assert_allclose(y2, 0.0, atol=1e-12)
    if cv > 0.0:
        assert_allclose(np.diff(y) / np.diff(mid), amp * peak / w, rtol=1e-9)
    if cv == 0.0:
        assert_allclose(law.evaluate(GRID)[0], make_law("modified-sine").evaluate(GRID)[0], atol=1e-15)


def test_modified_sine_cv_rejects_a_share_outside_zero_to_one() -> None:
    for bad in (-0.1, 1.0, "half", True):
        with pytest.raises(DesignError) as err:
            make_law("modified-sine-cv", cv=bad)
        assert err.value.path == "cv"
