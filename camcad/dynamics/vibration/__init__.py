"""Cams at speed: the elastic follower train, its periodic response, speed maps and polydyne cams.

A linear lumped train (single or two masses, Rothbart 2004, ch. 13) driven by
the cam's lift; its periodic steady state is computed exactly per speed
(:mod:`camcad.dynamics.vibration._exact`), with free flight where a
spring-loaded follower leaves the cam; :mod:`~camcad.dynamics.vibration.polydyne`
makes the cam whose output follows the program exactly at one speed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camcad._lazy import lazy_names

if TYPE_CHECKING:
    from camcad.dynamics.vibration.analysis import VibrationResult, analyse_vibration
    from camcad.dynamics.vibration.harmonics import acceleration_harmonics, resonances
    from camcad.dynamics.vibration.polydyne import (
        CompensatedMotion,
        check_compensable,
        compensate,
        compensated_program,
    )
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

_HOME = {
    "VibrationResult": "camcad.dynamics.vibration.analysis",
    "analyse_vibration": "camcad.dynamics.vibration.analysis",
    "acceleration_harmonics": "camcad.dynamics.vibration.harmonics",
    "resonances": "camcad.dynamics.vibration.harmonics",
    "CompensatedMotion": "camcad.dynamics.vibration.polydyne",
    "check_compensable": "camcad.dynamics.vibration.polydyne",
    "compensate": "camcad.dynamics.vibration.polydyne",
    "compensated_program": "camcad.dynamics.vibration.polydyne",
    "DEFAULT_STEP": "camcad.dynamics.vibration.response",
    "Dwell": "camcad.dynamics.vibration.response",
    "SpeedMap": "camcad.dynamics.vibration.response",
    "TrainResponse": "camcad.dynamics.vibration.response",
    "dwells": "camcad.dynamics.vibration.response",
    "speed_map": "camcad.dynamics.vibration.response",
    "train_response": "camcad.dynamics.vibration.response",
    "Flight": "camcad.dynamics.vibration.separation",
    "HybridMotion": "camcad.dynamics.vibration.separation",
    "periodic_with_flight": "camcad.dynamics.vibration.separation",
    "TrainModel": "camcad.dynamics.vibration.spec",
    "VibrationSpec": "camcad.dynamics.vibration.spec",
    "Train": "camcad.dynamics.vibration.train",
    "train_from_specs": "camcad.dynamics.vibration.train",
}
"""Where each public name lives: loaded on first use, so ``camcad.dynamics.vibration.spec`` (read by
``camcad.design`` for every design) loads neither the solvers nor SciPy."""

__getattr__ = lazy_names(__name__, _HOME)

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
    "check_compensable",
    "compensate",
    "compensated_program",
    "dwells",
    "periodic_with_flight",
    "resonances",
    "speed_map",
    "train_from_specs",
    "train_response",
]
