"""Followers: one module each, describing the contact element for the generic envelope.

A follower module holds a frozen dataclass satisfying :class:`Follower`: given
the motion at some cam angles it returns its contact element in the machine
frame (a roller centre or a face line, with three φ-derivatives), and it says
how it is guided (:class:`~camcad.geometry.envelope.Guide`). Everything else
(profile, normals, curvature, pressure angle, undercut, offsets for tools,
sizing) is done once, for every follower, by :mod:`camcad.geometry.envelope`
and :class:`~camcad.geometry.cam.Cam`.

The module also declares what its ``follower.type`` means, as a
:class:`FollowerType` named ``TYPE``: its TOML keys (entries of the loader's
rules), required keys, lift unit, cross-field check, and how it is built.
:data:`FOLLOWER_TYPES` is the registry: every module of this package that
declares a ``TYPE`` is found here, so a new kind of follower is one new
module. See "Adding a follower" in docs/reference/architecture.md.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Mapping
from types import MappingProxyType

from camcad.geometry.followers._arm import arm_swing, turning_point
from camcad.geometry.followers.base import Follower, FollowerKey, FollowerSketch, FollowerType, Lift, Words
from camcad.geometry.followers.oscillating_flat import OscillatingFlat
from camcad.geometry.followers.oscillating_roller import OscillatingRoller
from camcad.geometry.followers.translating_flat import TranslatingFlat
from camcad.geometry.followers.translating_roller import TranslatingRoller

__all__ = [
    "DEFAULT_FOLLOWER",
    "FOLLOWER_TYPES",
    "Follower",
    "FollowerKey",
    "FollowerSketch",
    "FollowerType",
    "Lift",
    "OscillatingFlat",
    "OscillatingRoller",
    "TranslatingFlat",
    "TranslatingRoller",
    "Words",
    "arm_swing",
    "follower_keys",
    "turning_point",
]


def _discover() -> dict[str, FollowerType]:
    """Every ``TYPE`` declared by a module of this package, in the order the types state."""
    found: list[FollowerType] = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        declared = getattr(importlib.import_module(f"{__name__}.{info.name}"), "TYPE", None)
        if isinstance(declared, FollowerType):
            found.append(declared)
    found.sort(key=lambda t: (t.order, t.word))
    out: dict[str, FollowerType] = {}
    for kind in found:
        assert kind.word not in out, f"two follower modules declare type = {kind.word!r}"
        out[kind.word] = kind
    return out


FOLLOWER_TYPES: Mapping[str, FollowerType] = MappingProxyType(_discover())
"""The registry: TOML ``follower.type`` → the kind its module declares, in the order of the README's table."""

(DEFAULT_FOLLOWER,) = (t for t in FOLLOWER_TYPES.values() if t.default)
"""The kind a ``[follower]`` table without ``type`` means."""


def follower_keys() -> dict[str, FollowerKey]:
    """Every ``[follower]`` key any kind takes (besides ``type``), in registry order; one declaration each.

    Two kinds that share a key share its declaration (:mod:`camcad.geometry.followers.base`),
    so the loader has one rule per key.
    """
    out: dict[str, FollowerKey] = {}
    for kind in FOLLOWER_TYPES.values():
        for key in kind.keys:
            assert out.setdefault(key.name, key) == key, f"follower.{key.name} is declared two ways"
    return out
