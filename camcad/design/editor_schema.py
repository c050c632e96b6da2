"""A JSON Schema of the design file, from the loader's own rules, for editors (``camcad schema``).

Editors that read JSON Schema for TOML (VS Code with Even Better TOML, any
editor with the Taplo language server) then complete keys, offer the allowed
words and flag a value out of range while the file is typed. The schema is
generated from the same rule table :func:`camcad.design.parse_design` checks
(one rule per key in :mod:`camcad.design.tables`, and one per law parameter):
the type and the words come from the rule, the bounds (open or closed, "0 or
a range", odd integers, list lengths) from the JSON Schema keywords each
check declares beside its test, so the two cannot drift apart.
The ``[follower]`` keys, their descriptions and which keys each ``type``
requires or refuses come from the follower modules' declarations (the
registry, :data:`camcad.geometry.followers.FOLLOWER_TYPES`), as the loader's do.
Cross-field checks (a face width that covers the contact's travel, a lift
that closes) remain the loader's: the schema catches what one key alone can.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from camcad.design.rules import _Rule
from camcad.design.tables import (  # the loader's rules, read only
    _BARREL_RULES,
    _BOUNDARY_RULE,
    _LAW_RULES,
    _MOTION_RULES,
    _RIB_RULES,
    _SECTIONS,
    _TABLE_ANGLE_RULE,
)
from camcad.geometry.followers import DEFAULT_FOLLOWER, FOLLOWER_TYPES, follower_keys

__all__ = ["design_json_schema", "rule_schema"]

_KINDS: dict[str, dict[str, Any]] = {
    "float": {"type": "number"},
    "int": {"type": "integer"},
    "bool": {"type": "boolean"},
    "str": {"type": "string"},
    "strlist": {"type": "array", "items": {"type": "string"}},
    "floatlist": {"type": "array", "items": {"type": "number"}},
}


def _merge(base: dict[str, Any], extra: Mapping[str, Any]) -> dict[str, Any]:
    """``base`` with the keywords of ``extra``; ``items`` are merged one level down."""
    out = dict(base)
    for key, value in extra.items():
        if key == "items" and isinstance(out.get("items"), dict):
            out["items"] = {**out["items"], **value}
        else:
            out[key] = value
    return out


def rule_schema(rule: _Rule) -> dict[str, Any]:
    """The JSON Schema of one key: its rule's type, words, and the keywords its check declares."""
    if rule.enum is not None:
        return {"enum": [str(m.value) for m in rule.enum], "description": "one of the listed words"}
    prop = dict(_KINDS[rule.kind])
    if rule.check is not None:
        prop = _merge(prop, rule.check.schema)
        if "anyOf" in prop:  # "0, or lo to hi": the type goes into each branch
            kind = prop.pop("type")
            prop["anyOf"] = [{"type": kind, **branch} for branch in prop["anyOf"]]
        if rule.check.allowed:
            prop["description"] = f"allowed: {rule.check.allowed}"
    return prop


def _or_word(schema: dict[str, Any], word: str, description: str) -> dict[str, Any]:
    return {"anyOf": [schema, {"const": word}], "description": description}


def _motion_item() -> dict[str, Any]:
    params: dict[str, Any] = {}
    laws: list[dict[str, Any]] = []
    for law, rules in _LAW_RULES.items():
        for name, rule in rules.items():
            params.setdefault(name, {"type": _KINDS[rule.kind]["type"]})
        laws.append(
            {
                "if": {"properties": {"law": {"const": law}}, "required": ["law"]},
                "then": {"properties": {name: rule_schema(rule) for name, rule in rules.items()}},
            }
        )
    boundary = {
        "type": "object",
        "properties": {
            k: _or_word(rule_schema(_BOUNDARY_RULE), "match", "a number, or match") for k in "vaj"
        },
        "additionalProperties": False,
        "description": 'blend boundary values { v, a, j }: numbers or "match"',
    }
    props: dict[str, Any] = {key: rule_schema(rule) for key, rule in _MOTION_RULES.items()}
    props["lift"] = _or_word(props["lift"], "close", 'mm (degrees of swing for an arm), or "close"')
    table = {
        "if": {"properties": {"kind": {"const": "table"}}, "required": ["kind"]},
        "then": {"properties": {"angle": rule_schema(_TABLE_ANGLE_RULE), "law": {"const": "table"}}},
    }
    return {
        "type": "object",
        "description": "one segment of the motion program, in order from φ = 0",
        "properties": {**props, "start": boundary, "end": boundary, **params},
        "required": ["kind"],
        "additionalProperties": False,
        "allOf": [table, *laws],
    }


def _follower_kinds(props: dict[str, Any]) -> list[dict[str, Any]]:
    """Each follower type's own keys, as its module declares them: required ones, and no other kind's.

    One ``if type = … then`` per type of the registry (the default type also
    when ``type`` is absent); each key's description starts with its module's.
    """
    keys = follower_keys()
    for name, key in keys.items():
        said = props[name].get("description")
        props[name]["description"] = f"{key.description}; {said}" if said else key.description
    out = []
    for kind in FOLLOWER_TYPES.values():
        own = {k.name for k in kind.keys}
        chosen: dict[str, Any] = {"properties": {"type": {"const": kind.word}}, "required": ["type"]}
        if kind is DEFAULT_FOLLOWER:
            chosen = {"anyOf": [chosen, {"not": {"required": ["type"]}}]}
        then: dict[str, Any] = {"properties": {name: False for name in keys if name not in own}}
        if kind.required:
            then["required"] = list(kind.required)
        out.append({"if": chosen, "then": then})
    return out


def design_json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a camcad design file."""
    properties: dict[str, Any] = {}
    for section, rules in _SECTIONS.items():
        props = {key: rule_schema(rule) for key, rule in rules.items()}
        props |= {key: rule_schema(rule) for key, rule in _BARREL_RULES.get(section, {}).items()}
        props |= {key: rule_schema(rule) for key, rule in _RIB_RULES.get(section, {}).items()}
        # a barrel's size is its barrel_radius: base_radius is required on the other styles only
        required = [key for key, rule in rules.items() if rule.required and key != "base_radius"]
        table: dict[str, Any] = {"type": "object", "properties": props, "additionalProperties": False}
        if required:
            table["required"] = required
        if section == "follower":
            table["allOf"] = _follower_kinds(props)
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
        "allOf": [_barrel_keys(), _barrel_keys(("barrel-rib",), _RIB_RULES, plate=False)],
    }


def _barrel_keys(
    styles: tuple[str, ...] = ("barrel", "barrel-rib"),
    rules: dict[str, dict[str, _Rule]] = _BARREL_RULES,
    *,
    plate: bool = True,
) -> dict[str, Any]:
    """A barrel's keys required on its ``styles`` and refused on every other style (issue 36).

    With ``plate``, ``base_radius`` the other way round (a barrel's size is its
    barrel_radius); without, only ``rules`` (a rib's ``rib_width``).
    """
    style: dict[str, Any] = {"const": styles[0]} if len(styles) == 1 else {"enum": list(styles)}
    barrel = {"properties": {"cam": {"properties": {"style": style}, "required": ["style"]}}}

    def keys(required: bool) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for section, table in rules.items():
            if required:
                out[section] = {"required": [k for k, rule in table.items() if rule.required]}
            else:
                out[section] = {"properties": dict.fromkeys(table, False)}
        return out

    then = keys(True)
    otherwise = keys(False)
    if plate:
        then["cam"]["properties"] = {"base_radius": False}
        otherwise["cam"]["required"] = ["base_radius"]
    return {"if": barrel, "then": {"properties": then}, "else": {"properties": otherwise}}
