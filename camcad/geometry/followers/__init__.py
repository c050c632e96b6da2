"""Followers: one module each, describing the contact element for the generic envelope.

A follower module holds a frozen dataclass satisfying :class:`Follower`: given
the motion at some cam angles it returns its contact element in the machine
frame (a roller centre or a face line, with three φ-derivatives), and it says
how it is guided (:class:`~camcad.geometry.envelope.Guide`). Everything else
(profile, normals, curvature, pressure angle, undercut, offsets for tools,
sizing) is done once, for every follower, by :mod:`camcad.geometry.envelope`
and :class:`~camcad.geometry.cam.Cam`. See "Adding a follower" in docs/reference/architecture.md.
"""

from __future__ import annotations

from camcad.geometry.followers.base import Follower, FollowerSketch
from camcad.geometry.followers.oscillating_flat import OscillatingFlat
from camcad.geometry.followers.oscillating_roller import OscillatingRoller
from camcad.geometry.followers.translating_flat import TranslatingFlat
from camcad.geometry.followers.translating_roller import TranslatingRoller

__all__ = [
    "Follower",
    "FollowerSketch",
    "OscillatingFlat",
    "OscillatingRoller",
    "TranslatingFlat",
    "TranslatingRoller",
]
