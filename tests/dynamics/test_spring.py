"""The return spring: rate by the coil (Hren et al., eq. 13) or given directly."""

from __future__ import annotations

import pytest

from camcad.design import DynamicsSpec
from camcad.dynamics import Spring, coil_spring_rate, spring_from_spec


def test_coil_rate_of_table1_by_hand():
    """k = G d⁴/(8 n D³) = 79000·625/(8·12.5·15625) = 49 375 000/1 562 500 = 31.6 N/mm."""
    k = coil_spring_rate(wire_diameter=5.0, coil_diameter=25.0, active_coils=12.5, shear_modulus=79000.0)
    assert k == pytest.approx(31.6, rel=1e-15)


def test_coil_spring_with_preload_deflection():
    spec = DynamicsSpec(
        wire_diameter=5.0,
        coil_diameter=25.0,
        active_coils=12.5,
        shear_modulus=79000.0,
        preload_deflection=10.0,
    )
    spring = spring_from_spec(spec)
    assert spring.rate == pytest.approx(31.6)
    assert spring.preload == pytest.approx(316.0)  # F_p(s = 0) = k·y1
    assert spring.preload_deflection == pytest.approx(10.0)
    assert spring.force([0.0, 10.0]).tolist() == pytest.approx([316.0, 632.0])


def test_coil_spring_without_deflection_uses_the_preload():
    spec = DynamicsSpec(
        wire_diameter=5.0, coil_diameter=25.0, active_coils=12.5, shear_modulus=79000.0, spring_preload=50.0
    )
    assert spring_from_spec(spec) == Spring(rate=pytest.approx(31.6), preload=50.0)


def test_rate_and_preload_given_directly():
    spring = spring_from_spec(DynamicsSpec(spring_rate=2.5, spring_preload=40.0))
    assert spring == Spring(rate=2.5, preload=40.0)
    assert Spring().preload_deflection == 0.0
