"""Linear tolerance sensitivities against closed forms and against re-solving the made cam.

The second method (:func:`camcad.geometry.made.made_motion`) finds the contact
on the exact made curve by Newton's method; the linear method differentiates
the contact condition. They must agree to second order: the residual of the
linear prediction falls by 4 when the error halves.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.geometry.made import made_motion
from camcad.geometry.sensitivity import Tol, mount_of, pressure_angle_identity, sensitivities
from tests.conftest import SAMPLES
from tests.inspect.conftest import CAMS, sample_cam
from tests.named import raises_named

PHI = np.linspace(0.0, 2.0 * np.pi, 361, endpoint=False) + 1e-3


def test_nominal_resolve_gives_the_design_motion(any_cam):
    """No error: the re-solved motion is the program's s, v, a and the envelope's α."""
    m = any_cam.motion(PHI)
    made = made_motion(any_cam, PHI)
    scale = max(1.0, float(np.max(np.abs(m.s))))
    assert_allclose(made.lift, m.s, atol=1e-11 * scale)
    assert_allclose(made.velocity, m.v, atol=1e-11 * scale)
    finite = np.isfinite(made.acceleration)
    assert finite.any() or mount_of(any_cam).pivot is not None  # only a face on an arm lacks it
    assert_allclose(made.acceleration[finite], m.a[finite], atol=1e-10 * scale)
    assert_allclose(made.pressure_angle, any_cam.pressure_angle(PHI), atol=1e-12)


def test_identity_gives_the_envelope_pressure_angle(any_cam):
    """Kennedy's identity α = F(q, v) reproduces the envelope's pressure angle on the design."""
    mount = mount_of(any_cam)
    m = any_cam.motion(PHI)
    alpha = pressure_angle_identity(mount, m.s / mount.lift_scale, m.v / mount.lift_scale)
    assert_allclose(alpha, any_cam.pressure_angle(PHI), atol=1e-12)


def test_linear_agrees_with_resolve_to_second_order(any_cam):
    """Residual of the linear prediction ∝ δ²: it falls by 4 (3.6 to 4.4) as δ halves."""
    sens = sensitivities(any_cam, PHI)
    m = any_cam.motion(PHI)
    alpha0 = any_cam.pressure_angle(PHI)
    for k, tol in enumerate(sens.parameters):
        base = 2e-2 if tol is not Tol.PHASE else 2e-4
        residuals = []
        for delta in (base, base / 2):
            made = made_motion(any_cam, PHI, deltas={tol: delta})
            residuals.append(
                [
                    np.max(np.abs(made.lift - m.s - sens.lift[k] * delta)),
                    np.max(np.abs(made.velocity - m.v - sens.velocity[k] * delta)),
                    np.max(np.abs(made.pressure_angle - alpha0 - sens.pressure_angle[k] * delta)),
                ]
            )
        big, small = np.array(residuals)
        for what, b, s in zip(("lift", "velocity", "pressure angle"), big, small, strict=True):
            if b < 1e-11:  # exactly linear (a slide moved along its axis; a face's α ≡ 0)
                continue
            assert 3.6 < b / s < 4.4, (tol, what, b, s)


@pytest.mark.parametrize("name", ["offset-roller-ccw", "offset-roller-cw"])
def test_roller_on_a_slide_closed_forms(name):
    """δs = δn/cos α; δs = σ·tan α·δe; δs = −v·δ (keyway); δs = −δc; the roller acts as the form."""
    cam = CAMS[name]()
    sens = sensitivities(cam, PHI)
    m = cam.motion(PHI)
    alpha = cam.pressure_angle(PHI)
    assert_allclose(sens.lift[sens.row(Tol.FORM)], 1.0 / np.cos(alpha), rtol=1e-12)
    assert_allclose(sens.lift[sens.row(Tol.ROLLER_RADIUS)], 1.0 / np.cos(alpha), rtol=1e-12)
    assert_allclose(sens.lift[sens.row(Tol.ECCENTRICITY)], cam.sigma * np.tan(alpha), atol=1e-12)
    assert_allclose(sens.lift[sens.row(Tol.CENTRE_DISTANCE)], -1.0, atol=1e-12)
    assert_allclose(sens.lift[sens.row(Tol.PHASE)], -m.v, atol=1e-10)
    assert_allclose(sens.velocity[sens.row(Tol.PHASE)], -m.a, atol=1e-9)


def test_phase_closed_form_for_every_follower(any_cam):
    """A cam keyed δ late: δq = −v·δ and δv = −a·δ, arms in degrees, faces included."""
    sens = sensitivities(any_cam, PHI)
    m = any_cam.motion(PHI)
    scale = max(1.0, float(np.max(np.abs(m.a))))
    assert_allclose(sens.lift[sens.row(Tol.PHASE)], -m.v, atol=1e-10 * scale)
    assert_allclose(sens.velocity[sens.row(Tol.PHASE)], -m.a, atol=1e-9 * scale)


def test_translating_flat_closed_forms():
    """A face on a slide: δs = δn, the eccentricity moves nothing, α stays 0."""
    cam = CAMS["translating-flat"]()
    sens = sensitivities(cam, PHI)
    assert_allclose(sens.lift[sens.row(Tol.FORM)], 1.0, atol=1e-12)
    assert_allclose(sens.lift[sens.row(Tol.ECCENTRICITY)], 0.0, atol=1e-12)
    assert_allclose(sens.pressure_angle, 0.0, atol=1e-12)
    with raises_named(ValueError, match="roller_radius: does not apply"):
        sens.row(Tol.ROLLER_RADIUS)


def test_vectorised_variants_equal_one_by_one():
    """made_motion over variants (V,) gives the rows of V separate calls, exactly."""
    cam = CAMS["oscillating-roller"]()
    deltas = {Tol.ARM_LENGTH: np.array([0.01, -0.02, 0.0]), Tol.PHASE: np.array([1e-4, 0.0, -2e-4])}
    many = made_motion(cam, PHI, deltas=deltas)
    for i in range(3):
        one = made_motion(cam, PHI, deltas={k: float(v[i]) for k, v in deltas.items()})
        assert_allclose(many.lift[i], one.lift, rtol=0, atol=1e-12)
        assert_allclose(many.acceleration[i], one.acceleration, rtol=0, atol=1e-9)


def test_phase_is_exactly_a_late_motion(any_cam):
    """Not only to first order: a cam keyed δ late gives s(φ − δ), v(φ − δ), a(φ − δ) exactly."""
    delta = 0.05
    made = made_motion(any_cam, PHI, deltas={Tol.PHASE: delta})
    late = any_cam.motion(PHI - delta)
    scale = max(1.0, float(np.max(np.abs(late.a))))
    assert_allclose(made.lift, late.s, atol=1e-10 * scale)
    assert_allclose(made.velocity, late.v, atol=1e-10 * scale)
    finite = np.isfinite(made.acceleration)
    assert_allclose(made.acceleration[finite], late.a[finite], atol=1e-9 * scale)


def _applicable_or_error(read, cam):
    from camcad.errors import CamcadError

    try:
        return read(cam)
    except CamcadError as err:
        return (type(err), str(err))


@pytest.mark.parametrize("name", [*sorted(CAMS), *(f"sample:{p.stem}" for p in SAMPLES)])
def test_applicable_to_is_applicable_of_the_mount(name):
    """applicable_to (what [tolerance] checks its keys against) = applicable(mount_of(cam)), refusals too."""
    from camcad.geometry.sensitivity import applicable, applicable_to

    cam = sample_cam(name.removeprefix("sample:")) if name.startswith("sample:") else CAMS[name]()
    assert _applicable_or_error(applicable_to, cam) == _applicable_or_error(
        lambda c: applicable(mount_of(c)), cam
    )
