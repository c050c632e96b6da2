"""The batch Monte Carlo (:mod:`camcad.inspect.batch`) and the contact stress of a made cam.

Truths: every figure of the certified quadratics against the made cams
re-solved one at a time (:func:`camcad.inspect.tolerance.variant_figures` on a
single variant), within the bound :func:`certify` reports; the Monte-Carlo
mean and σ of a dwell error that is exactly linear in the errors (a radial
roller at a dwell: lift error = δ_form + δ_roller − δ_centre, by the pitch
circle's radius) against the analytical propagation σ² = Σσ_k²; one made
cam's contact stress against the Hertz formula worked by hand from its own
lift, acceleration, pressure angle and the offset profile's radius; chunked
evaluation against unchunked (the same bytes).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camcad.dynamics.energy import STANDARD_GRAVITY
from camcad.geometry.cam import Cam
from camcad.geometry.made import made_motion
from camcad.geometry.sensitivity import Tol
from camcad.inspect.batch import certify, response, stencil
from camcad.inspect.tolerance import Distribution, Tolerance, draw, made_stress, variant_figures
from tests.conftest import make_design

LOADED = {
    "dynamics": {
        "follower_mass": 0.8,
        "spring_rate": 2.0,
        "spring_preload": 100.0,
        "contact_width": 15.0,
    },
    "cam": {"speed_rpm": 300.0},
}


@pytest.fixture(scope="module")
def loaded():
    design = make_design(offset=8.0, extra=LOADED)
    return design, Cam.from_design(design), design.dynamics_setup()


@pytest.fixture(scope="module")
def fitted(loaded):
    _, cam, setup = loaded
    return response(cam, TOLS, setup=setup)


TOLS = (
    Tolerance(tol=Tol.FORM, value=0.02),
    Tolerance(tol=Tol.ROLLER_RADIUS, value=0.01, distribution=Distribution.NORMAL),
    Tolerance(tol=Tol.ECCENTRICITY, value=0.03),
    Tolerance(tol=Tol.PHASE, value=math.radians(0.1)),
)


def test_stencil_is_the_centre_the_axes_and_the_diagonals():
    x = stencil(3)
    assert x.shape == (1 + 6 + 12, 3)
    assert len({tuple(r) for r in x}) == x.shape[0]
    assert np.all(np.abs(x) <= 1.0) and np.all(np.sum(np.abs(x), axis=1) <= 2.0)


def test_quadratics_agree_with_made_cams_re_solved_one_at_a_time(loaded, fitted):
    """The certificate's bound holds on variants it did not see, each re-solved alone."""
    _, cam, setup = loaded
    drawn = draw(TOLS, samples=400, seed=7)
    cert = certify(cam, fitted, drawn, setup=setup, count=16)
    seen = set(cert.indices)
    others = [i for i in range(400) if i not in seen][:2]
    bound = {
        "dwell": cert.dwell,
        "acceleration": cert.acceleration,
        "pressure_angle": cert.pressure_angle,
        "stress": cert.stress,
    }
    # what the quadratics claim: the dwell to 1e-7 mm, the peaks to 1e-6 of their size
    assert bound["dwell"] < 1e-7
    worst = dict.fromkeys(bound, 0.0)
    for i in others:
        one = {p: v[i : i + 1] for p, v in drawn.items()}
        exact = variant_figures(cam, one, setup=setup)
        approx = fitted.figures(one)
        for key, e, a in zip(bound, exact, approx, strict=True):
            worst[key] = max(worst[key], float(np.max(np.abs(np.asarray(e) - np.asarray(a)))))
        assert abs(approx[1][0] - exact[1][0]) <= 1e-6 * exact[1][0]
        assert abs(approx[3][0] - exact[3][0]) <= 1e-6 * exact[3][0]
    for key, got in worst.items():
        assert got <= 2.0 * bound[key] + 1e-12, (key, got, bound[key])
    # and the figures move: the quadratics are not the design's constants
    figs = fitted.figures(drawn)
    assert np.std(figs[0][:, 0]) > 1e-3 and np.std(figs[3]) > 1e-3


def test_monte_carlo_of_an_exactly_linear_dwell_error_matches_the_propagation():
    """Radial roller at a dwell: s = R_pitch + δ_form + δ_roller − δ_centre − R_pitch0, exactly."""
    cam = Cam.from_design(make_design(offset=0.0))
    tols = (
        Tolerance(tol=Tol.FORM, value=0.02),  # uniform: σ = t/√3
        Tolerance(tol=Tol.ROLLER_RADIUS, value=0.015, distribution=Distribution.NORMAL),  # σ = t/3
        Tolerance(tol=Tol.CENTRE_DISTANCE, value=0.01),
    )
    n = 200_000
    fitted = response(cam, tols)
    figs = fitted.figures(draw(tols, samples=n, seed=11))
    sigma = math.sqrt((0.02 / math.sqrt(3.0)) ** 2 + (0.015 / 3.0) ** 2 + (0.01 / math.sqrt(3.0)) ** 2)
    for k in range(figs[0].shape[1]):
        err = figs[0][:, k]
        assert abs(float(np.mean(err))) < 4.0 * sigma / math.sqrt(n)
        assert float(np.std(err, ddof=1)) == pytest.approx(sigma, rel=4.0 / math.sqrt(2.0 * n))


def test_contact_stress_of_one_made_cam_by_hand(loaded):
    """σ = √(F·E*/(π·L·R*)), F = (m·a·ω² + m·g + k·s + F0)/cos α, 1/R* = 1/(ρ + δ_form) + 1/(r_f + δ_r)."""
    design, cam, setup = loaded
    d_form, d_roller, d_ecc = 0.015, -0.008, 0.02
    phi = np.radians([20.0, 75.0, 110.0, 240.0])
    made = made_motion(
        cam, phi, deltas={Tol.FORM: [d_form], Tol.ROLLER_RADIUS: [d_roller], Tol.ECCENTRICITY: [d_ecc]}
    )
    got = made_stress(made, setup)[0]
    dyn = design.dynamics
    omega = design.cam.speed_rpm * 2.0 * math.pi / 60.0
    s, a, alpha = made.lift[0], made.acceleration[0], made.pressure_angle[0]
    axial = dyn.follower_mass * a * omega**2 / 1000.0 + dyn.follower_mass * STANDARD_GRAVITY
    axial = axial + dyn.spring_rate * s + dyn.spring_preload
    force = axial / np.cos(alpha)
    # the made profile is the design's offset by δ_form; the design profile's radius at the made contact
    rho = cam.state(made.contact[0]).profile.rho + d_form
    kappa = 1.0 / rho + 1.0 / (design.follower.roller_radius + d_roller)
    e_star = 1.0 / (2.0 * (1.0 - dyn.cam_poisson**2) / dyn.cam_modulus)  # same steel both sides
    assert dyn.cam_modulus == dyn.follower_modulus and dyn.cam_poisson == dyn.follower_poisson
    by_hand = np.sqrt(force * e_star * kappa / (math.pi * 15.0))
    np.testing.assert_allclose(got, by_hand, rtol=1e-9)
    # a made cam's stress differs from the design's (the test sees the variant, not the nominal)
    nominal = made_stress(made_motion(cam, phi), setup)
    assert np.max(np.abs(got - nominal)) > 1e-3


def test_chunked_evaluation_gives_the_unchunked_bytes(fitted):
    drawn = draw(TOLS, samples=1000, seed=3)
    whole = fitted.figures(drawn, batch=10**6)
    small = fitted.figures(drawn, batch=7)
    for w, s in zip(whole, small, strict=True):
        assert np.asarray(w).tobytes() == np.asarray(s).tobytes()


def test_a_batch_gives_each_made_cam_the_bytes_it_gets_alone(loaded):
    """The exact re-solve vectorised over made cams: every figure byte-identical to one cam at a time."""
    _, cam, setup = loaded
    drawn = draw(TOLS, samples=30, seed=5)
    together = variant_figures(cam, drawn, setup=setup)
    for i in (0, 17):
        alone = variant_figures(cam, {p: v[i : i + 1] for p, v in drawn.items()}, setup=setup)
        for t, a in zip(together, alone, strict=True):
            assert np.asarray(t)[i].tobytes() == np.asarray(a)[0].tobytes()


def test_the_design_as_a_made_cam_has_the_analysis_peak_stress(loaded):
    """No error: the made cam's refined peak stress is `camcad check`'s true maximum (a second method)."""
    from camcad.pipeline import analyse

    design, cam, setup = loaded
    stress = variant_figures(cam, {Tol.FORM: np.zeros(1)}, setup=setup)[3][0]
    expected = analyse(design, fit=False, toolpath=False, strict=False).dynamics.hertz_stress_max.value
    assert stress == pytest.approx(expected, rel=1e-9)


def test_a_certificate_beyond_the_trust_is_refused(loaded, fitted):
    """The real certificate is trusted; one whose dwell or stress error is 0.2 % of the spread is not."""
    import dataclasses

    from camcad.inspect.batch import TRUST, untrusted

    _, cam, setup = loaded
    drawn = draw(TOLS, samples=300, seed=2)
    figs = fitted.figures(drawn)
    cert = certify(cam, fitted, drawn, setup=setup, count=8)
    assert untrusted(cert, figs, lift=20.0) == ()
    dwell_spread = float(np.min(np.std(figs[0], axis=0)))
    worse = dataclasses.replace(
        cert, dwell=2.0 * TRUST * dwell_spread, stress=2.0 * TRUST * float(np.std(figs[3]))
    )
    assert untrusted(worse, figs, lift=20.0) == ("dwell", "stress")


def test_quadratics_hold_for_every_follower_kind(any_cam):
    """Slide and arm, roller and face, both rotations: the certificate is trusted, the dwells to 1e-7."""
    from camcad.geometry.sensitivity import applicable, mount_of
    from camcad.inspect.batch import untrusted

    tols = [
        Tolerance(tol=t, value=math.radians(0.05) if t is Tol.PHASE else 0.02)
        for t in applicable(mount_of(any_cam))
    ]
    quad = response(any_cam, tols)
    drawn = draw(tols, samples=300, seed=1)
    cert = certify(any_cam, quad, drawn, count=4)
    lift = float(np.max(np.abs(any_cam.motion(any_cam.sample_phi(0.01)).s)))
    assert cert.dwell < 1e-7 * lift
    assert untrusted(cert, quad.figures(drawn), lift=lift) == ()
