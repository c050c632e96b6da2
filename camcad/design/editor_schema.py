"""A JSON Schema of the design file, from the loader's own rules, for editors (``camcad schema``).

Editors that read JSON Schema for TOML (VS Code with Even Better TOML, any
editor with the Taplo language server) then complete keys, offer the allowed
words and flag a value out of range while the file is typed. The schema is
generated from the same rules :func:`camcad.design.parse_design` checks (one
per key in :mod:`camcad.design.schema`): the type and the enum members come
from the rule, the range and unit from the rule's own refusal of values it
cannot accept ("allowed: 0.1 to 10000 mm"), so the two cannot drift apart.
Cross-field checks (a face width that covers the contact's travel, a lift
that closes) remain the loader's: the schema catches what one key alone can.
"""

from __future__ import annotations

import re
from typing import Any

from camcad.design.schema import _SECTIONS  # the loader's rules, read only
from camcad.motion.laws import LAWS

__all__ = ["design_json_schema"]

_KINDS = {
    "float": {"type": "number"},
    "int": {"type": "integer"},
    "bool": {"type": "boolean"},
    "str": {"type": "string"},
    "strlist": {"type": "array", "items": {"type": "string"}},
    "floatlist": {"type": "array", "items": {"type": "number"}},
}
_PROBES = (-1e300, 1e300, -1.0, 0.0)
_NUMBER = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
_UNITS = {"degrees": "°", "mm": "mm", "rpm": "rpm", "N": "N", "MPa": "MPa", "kg": "kg"}


def _refusals(rule: Any) -> list[str]:
    said = []
    for probe in _PROBES:
        value: float | int = int(probe) if rule.kind == "int" and abs(probe) < 1e18 else probe
        try:
            text = rule.check(value)
        except (TypeError, ValueError, OverflowError):
            continue
        if text:
            said.append(text)
    return said


def _range(text: str) -> tuple[dict[str, Any], str]:
    """JSON Schema bounds and the allowed text of a rule's refusal ("allowed: 0.1 to 10000 mm")."""
    allowed = text.split("allowed:", 1)[1].strip().rstrip(")") if "allowed:" in text else text
    allowed = allowed.removeprefix("must be ").strip()
    n = _NUMBER
    bounds: dict[str, Any] = {}
    if m := re.fullmatch(rf"(0, or )?({n}) to ({n})\b.*", allowed):
        bounds = {"minimum": float(m.group(2)), "maximum": float(m.group(3))}
        if m.group(1):
            return {"anyOf": [{"const": 0}, bounds]}, allowed
    elif m := re.fullmatch(rf"over ({n}) up to ({n})\b.*", allowed):
        bounds = {"exclusiveMinimum": float(m.group(1)), "maximum": float(m.group(2))}
    elif m := re.fullmatch(rf"in ([\[(])({n}), ({n})([\])]).*", allowed):
        lo, hi = float(m.group(2)), float(m.group(3))
        bounds = {"minimum" if m.group(1) == "[" else "exclusiveMinimum": lo}
        bounds["maximum" if m.group(4) == "]" else "exclusiveMaximum"] = hi
    return bounds, allowed


def _property(rule: Any) -> dict[str, Any]:
    if rule.enum is not None:
        return {"enum": [str(m.value) for m in rule.enum], "description": "one of the listed words"}
    prop: dict[str, Any] = dict(_KINDS.get(rule.kind, {}))
    if rule.check is None or rule.kind not in ("float", "int"):
        return prop
    said = _refusals(rule)
    text = next((t for t in said if "allowed" in t), said[0] if said else "")
    bounds, allowed = _range(text)
    if "anyOf" in bounds:
        prop["anyOf"] = [{**_KINDS[rule.kind], **b} for b in bounds["anyOf"]]
        prop.pop("type", None)
    else:
        prop.update(bounds)
    if allowed:
        prop["description"] = f"allowed: {allowed}"
    return prop


def _motion_item() -> dict[str, Any]:
    params: dict[str, Any] = {}
    for info in LAWS.values():
        for p in info.parameters:
            params.setdefault(p.name, {"type": "number", "description": f"{info.name}: {p.allowed}"})
    return {
        "type": "object",
        "description": "one segment of the motion program, in order from φ = 0",
        "properties": {
            "kind": {"enum": ["rise", "return", "dwell", "table"]},
            "angle": {
                "type": "number",
                "exclusiveMinimum": 0,
                "maximum": 360,
                "description": "degrees of cam rotation",
            },
            "lift": {
                "anyOf": [{"type": "number", "exclusiveMinimum": 0}, {"const": "close"}],
                "description": 'mm (degrees of swing for an arm), or "close"',
            },
            "law": {"enum": [*LAWS, "table"], "description": "see `camcad laws`"},
            "velocity": {
                "type": "number",
                "description": "constant-velocity only: instead of lift, per second",
            },
            "start": {"type": "object", "description": 'blend start values { v, a, j } or "match"'},
            "end": {"type": "object", "description": 'blend end values { v, a, j } or "match"'},
            "file": {
                "type": "string",
                "description": "kind = 'table': the CSV of angle [°], lift[, velocity]",
            },
            "noise": {"type": "number", "description": "kind = 'table': measurement noise σ (mm)"},
            **params,
        },
        "required": ["kind"],
        "additionalProperties": False,
    }


def design_json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a camcad design file."""
    properties: dict[str, Any] = {}
    for section, rules in _SECTIONS.items():
        props = {key: _property(rule) for key, rule in rules.items()}
        required = [key for key, rule in rules.items() if rule.required]
        table: dict[str, Any] = {"type": "object", "properties": props, "additionalProperties": False}
        if required:
            table["required"] = required
        properties[section] = table
    properties["motion"] = {"type": "array", "minItems": 1, "items": _motion_item()}
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "camcad design file",
        "description": "A disc cam: [cam], [follower], [[motion]] and optional tables (see the README).",
        "type": "object",
        "properties": properties,
        "required": ["cam", "motion"],
        "additionalProperties": False,
    }
