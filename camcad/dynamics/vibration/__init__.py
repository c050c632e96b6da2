"""Cams at speed: the elastic follower train, its periodic response, speed maps and polydyne cams.

A linear lumped train (single or two masses, Rothbart 2004, ch. 13) driven by
the cam's lift; its periodic steady state is computed exactly per speed
(:mod:`camcad.dynamics.vibration._exact`), with free flight where a
spring-loaded follower leaves the cam; :mod:`~camcad.dynamics.vibration.polydyne`
makes the cam whose output follows the program exactly at one speed.
"""

from camcad.dynamics.vibration.analysis import VibrationResult, analyse_vibration
from camcad.dynamics.vibration.harmonics import acceleration_harmonics, resonances
from camcad.dynamics.vibration.polydyne import CompensatedMotion, compensate
from camcad.dynamics.vibration.response import (
    DEFAULT_STEP,
    Dwell,
    SpeedMap,
    TrainResponse,
    dwells,
    speed_map,
    train_response,
)
from camcad.dynamics.vibration.separation import Flight, HybridMotion, periodic_with_flight
from camcad.dynamics.vibration.spec import TrainModel, VibrationSpec
from camcad.dynamics.vibration.train import Train, train_from_specs

__all__ = [
    "DEFAULT_STEP",
    "CompensatedMotion",
    "Dwell",
    "Flight",
    "HybridMotion",
    "SpeedMap",
    "Train",
    "TrainModel",
    "TrainResponse",
    "VibrationResult",
    "VibrationSpec",
    "acceleration_harmonics",
    "analyse_vibration",
    "compensate",
    "dwells",
    "periodic_with_flight",
    "resonances",
    "speed_map",
    "train_from_specs",
    "train_response",
]
