"""The design file: its schema (``schema``) and the validated aggregate (``spec``).

A design is a TOML file with the tables ``[cam]``, ``[follower]``,
``[[motion]]``, ``[dynamics]``, ``[fit]``, ``[dxf]``, ``[mesh]``, ``[tables]``
and ``[gcode]``. :func:`load_design` turns it into a frozen :class:`Design`
or raises :class:`~camcad.errors.DesignError` naming the field path. Only the
layers above the stages (analysis, report, pipeline, cli) import this
package; each stage owns its options and receives only those.
"""

from __future__ import annotations

from camcad.design.schema import load_design, parse_design
from camcad.design.spec import CamSpec, Design, Dialect, Direction, GcodeSpec
from camcad.dynamics.spec import DynamicsModel, DynamicsSpec
from camcad.export.spec import DxfSpec, MeshSpec, TablesSpec
from camcad.fit.spec import FitSpec
from camcad.geometry.followers import FOLLOWER_TYPES, FollowerType
from camcad.geometry.spec import FollowerSpec, Rotation
from camcad.motion.segments import SegmentKind, SegmentSpec

__all__ = [
    "FOLLOWER_TYPES",
    "CamSpec",
    "Design",
    "Dialect",
    "Direction",
    "DxfSpec",
    "DynamicsModel",
    "DynamicsSpec",
    "FitSpec",
    "FollowerSpec",
    "FollowerType",
    "GcodeSpec",
    "MeshSpec",
    "Rotation",
    "SegmentKind",
    "SegmentSpec",
    "TablesSpec",
    "load_design",
    "parse_design",
]
