"""Dynamics: contact force, drive torque, follower jump and contact stress.

Two models: the energy method of Quintero & Vanegas (2016, eqs. 15-19) and the
guided flat tappet with friction of Hren et al. (eqs. 13-29); the Hertz
line-contact stress applies to both. :func:`analyse_dynamics` dispatches on
``[dynamics].model``.
"""

from camcad.dynamics.contact import (
    contact_curvature,
    effective_modulus,
    hertz_half_width,
    hertz_stress,
)
from camcad.dynamics.energy import (
    STANDARD_GRAVITY,
    FollowerLoad,
    contact_force,
    input_torque,
)
from camcad.dynamics.jump import covering_arc, loss_runs, min_preload, speed_limits
from camcad.dynamics.model import analyse_dynamics
from camcad.dynamics.results import CSV_HEADER, DynamicsResult
from camcad.dynamics.spring import Spring, coil_spring_rate, spring_from_spec
from camcad.dynamics.tappet import GuidedTappet, TappetForces, tappet_forces, travel_sign

__all__ = [
    "CSV_HEADER",
    "STANDARD_GRAVITY",
    "DynamicsResult",
    "FollowerLoad",
    "GuidedTappet",
    "Spring",
    "TappetForces",
    "analyse_dynamics",
    "coil_spring_rate",
    "contact_curvature",
    "contact_force",
    "covering_arc",
    "effective_modulus",
    "hertz_half_width",
    "hertz_stress",
    "input_torque",
    "loss_runs",
    "min_preload",
    "speed_limits",
    "spring_from_spec",
    "tappet_forces",
    "travel_sign",
]
