"""Dynamics: contact force, drive torque, follower jump and contact stress.

Two models: the energy method of Quintero & Vanegas (2016, eqs. 15-19) and the
guided flat tappet with friction of Hren et al. (eqs. 13-29); the Hertz
line-contact stress applies to both. :func:`analyse_dynamics` dispatches on
``[dynamics].model``.

On top of the rigid dynamics: the track roller's rating life and the track's
surface fatigue (:mod:`~camcad.dynamics.life`), the lubricant film
(:mod:`~camcad.dynamics.film`), the contact's rolling and sliding speeds
(:mod:`~camcad.dynamics.rolling`) and the drive (:mod:`~camcad.dynamics.drive`).
"""

from camcad.dynamics.contact import (
    contact_curvature,
    effective_modulus,
    hertz_half_width,
    hertz_stress,
)
from camcad.dynamics.drive import (
    CharacteristicValues,
    DriveMode,
    DriveResult,
    DriveSpec,
    analyse_drive,
    characteristic_values,
    segment_characteristics,
)
from camcad.dynamics.energy import (
    STANDARD_GRAVITY,
    FollowerLoad,
    contact_force,
    input_torque,
)
from camcad.dynamics.film import FilmResult, LubricationSpec, analyse_film
from camcad.dynamics.jump import covering_arc, loss_runs, min_preload, speed_limits
from camcad.dynamics.life import LifeSpec, LoadStressLine, RollerLife, TrackLife, roller_life, track_life
from camcad.dynamics.model import analyse_dynamics
from camcad.dynamics.results import DynamicsResult
from camcad.dynamics.rolling import ContactMotion, contact_motion
from camcad.dynamics.spring import Spring, coil_spring_rate, spring_from_spec
from camcad.dynamics.tappet import GuidedTappet, TappetForces, tappet_forces, travel_sign

__all__ = [
    "STANDARD_GRAVITY",
    "CharacteristicValues",
    "ContactMotion",
    "DriveMode",
    "DriveResult",
    "DriveSpec",
    "DynamicsResult",
    "FilmResult",
    "FollowerLoad",
    "GuidedTappet",
    "LifeSpec",
    "LoadStressLine",
    "LubricationSpec",
    "RollerLife",
    "Spring",
    "TappetForces",
    "TrackLife",
    "analyse_drive",
    "analyse_dynamics",
    "analyse_film",
    "characteristic_values",
    "coil_spring_rate",
    "contact_curvature",
    "contact_force",
    "contact_motion",
    "covering_arc",
    "effective_modulus",
    "hertz_half_width",
    "hertz_stress",
    "input_torque",
    "loss_runs",
    "min_preload",
    "roller_life",
    "segment_characteristics",
    "speed_limits",
    "spring_from_spec",
    "tappet_forces",
    "track_life",
    "travel_sign",
]
