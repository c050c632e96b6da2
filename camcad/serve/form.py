"""The design as a form: fields grouped as in the TOML, with units and allowed ranges from the schema.

The fields and their hints come from the same rules the loader checks
(:mod:`camcad.design.schema`): each numeric rule is asked what it allows (its
own refusal of an impossible value states the range and unit), each enum
lists its members. The form's values go back through :func:`design_data`
into a TOML-like mapping that :func:`camcad.design.parse_design` validates,
so the designer accepts exactly what ``camcad build`` accepts and shows the
loader's own error message next to the field it names. :func:`toml_text`
writes the mapping back as TOML.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from camcad.design.schema import _SECTIONS  # the loader's own rules, read not changed
from camcad.design.toml_text import toml_text as design_toml_text
from camcad.motion.laws import LAWS

__all__ = ["Field", "Group", "design_data", "form_groups", "toml_text"]

_SECTION_ORDER = ("cam", "follower", "motion", "dynamics", "fit", "gcode", "dxf", "mesh", "tables")
_PROBES = (-1e300, 1e300, -1.0, 0.0)  # values every numeric rule refuses at least one of
_INT = re.compile(r"[+-]?\d+")
_MOTION_HINTS = {
    "kind": "rise, return or dwell",
    "angle": "degrees of cam rotation",
    "lift": 'mm (degrees of swing for an arm), or "close"',
    "law": ", ".join(LAWS),
}


@dataclass(frozen=True, slots=True, kw_only=True)
class Field:
    """One input: its TOML path, what it holds and what the schema allows."""

    path: str  # "cam.base_radius", "motion[0].lift"
    key: str
    kind: str  # float, int, bool, str, enum, strlist, floatlist, number (motion keys)
    value: str  # as shown in the input ("" when not set: the default applies)
    choices: tuple[str, ...] = ()
    hint: str = ""  # allowed values and unit, e.g. "0.1 to 10000 mm"


@dataclass(frozen=True, slots=True, kw_only=True)
class Group:
    """A TOML table: the keys the design sets, then the keys left at their defaults."""

    title: str  # "cam", "motion[0]"
    fields: tuple[Field, ...]
    more: tuple[Field, ...] = ()


def _hint(rule: Any) -> str:
    """What a rule allows, in its own words (asked by giving it values it must refuse)."""
    if rule.enum is not None:
        return ", ".join(str(m.value) for m in rule.enum)
    if rule.check is None or rule.kind not in ("float", "int"):
        return {
            "bool": "true or false",
            "strlist": "comma-separated",
            "floatlist": "comma-separated numbers",
        }.get(rule.kind, "")
    said = []
    for probe in _PROBES:
        try:
            text = rule.check(int(probe) if rule.kind == "int" and abs(probe) < 1e18 else probe)
        except (TypeError, ValueError, OverflowError):
            continue
        if text:
            said.append(text)
    for text in said:
        if "allowed:" in text:
            return text.split("allowed:", 1)[1].strip().rstrip(")")
    return said[0].removeprefix("must be ").strip() if said else ""


def _shown(value: Any) -> str:
    """A TOML value as the text of an input."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ", ".join(_shown(v) for v in value)
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return repr(value)
    return str(value)


def _field(section: str, key: str, rule: Any, value: Any) -> Field:
    return Field(
        path=f"{section}.{key}",
        key=key,
        kind=rule.kind,
        value="" if value is None else _shown(value),
        choices=tuple(str(m.value) for m in rule.enum) if rule.enum is not None else (),
        hint=_hint(rule),
    )


def _motion_group(index: int, table: Mapping[str, Any]) -> Group:
    fields = []
    law = LAWS.get(str(table.get("law", "")))
    params = {p.name: p.allowed for p in law.parameters} if law is not None else {}
    for key, value in table.items():
        if isinstance(value, Mapping):
            continue  # start/end blends stay as they are in the file
        choices: tuple[str, ...] = ()
        if key == "kind":
            choices = ("rise", "return", "dwell")
        elif key == "law":
            choices = tuple(LAWS)
        kind = "enum" if choices else ("str" if key == "file" else "number")
        hint = _MOTION_HINTS.get(key, str(params.get(key, "")))
        fields.append(Field(path=f"motion[{index}].{key}", key=key, kind=kind, value=_shown(value),
                            choices=choices, hint=hint))  # fmt: skip
    return Group(title=f"motion[{index}]", fields=tuple(fields))


def form_groups(data: Mapping[str, Any]) -> list[Group]:
    """The form of a design mapping: one group per table in TOML order, each [[motion]] its own group."""
    groups = []
    sections = [s for s in _SECTION_ORDER if s in _SECTIONS or s == "motion"]
    sections += [s for s in _SECTIONS if s not in sections]
    for section in sections:
        if section == "motion":
            groups += [_motion_group(i, t) for i, t in enumerate(data.get("motion", []))]
            continue
        table = data.get(section, {})
        if not isinstance(table, Mapping):
            continue
        rules = _SECTIONS[section]
        given = tuple(_field(section, k, rules[k], v) for k, v in table.items() if k in rules)
        more = tuple(_field(section, k, r, None) for k, r in rules.items() if k not in table)
        groups.append(Group(title=section, fields=given, more=more))
    return groups


def _number(text: str) -> Any:
    """The number a text holds (int for a whole number), or the text itself for the loader to refuse."""
    try:
        return int(text) if _INT.fullmatch(text) else float(text)
    except ValueError:
        return text


def _value(field: Field, text: Any) -> Any:
    """A form value converted by its field's kind; ``None`` for an empty input (the default applies)."""
    if isinstance(text, bool):
        return text
    text = str(text).strip()
    if text == "":
        return None
    if field.kind in ("float", "int", "number"):
        return text if text == "close" else _number(text)
    if field.kind == "bool":
        return {"true": True, "false": False}.get(text.lower(), text)
    if field.kind == "strlist":
        return [t.strip() for t in text.split(",") if t.strip()]
    if field.kind == "floatlist":
        return [_number(t.strip()) for t in text.split(",") if t.strip()]
    return text


def design_data(base: Mapping[str, Any], values: Mapping[str, Any]) -> dict[str, Any]:
    """The design mapping with the form's ``values`` (path → input text) applied to ``base``.

    Paths not in ``values`` keep their value from ``base``; an empty input
    removes the key (the default applies); a motion segment's nested tables
    (blends) are kept as they are.
    """
    out: dict[str, Any] = {k: (dict(v) if isinstance(v, Mapping) else v) for k, v in base.items()}
    out["motion"] = [dict(t) for t in base.get("motion", [])]
    fields = {f.path: f for g in form_groups(base) for f in (*g.fields, *g.more)}
    for path, text in values.items():
        field = fields.get(path)
        if field is None:
            continue
        value = _value(field, text)
        match = re.fullmatch(r"motion\[(\d+)\]\.(.+)", path)
        if match:
            table = out["motion"][int(match.group(1))]
            key = match.group(2)
        else:
            section, key = path.split(".", 1)
            table = out.setdefault(section, {})
        if value is None:
            table.pop(key, None)
        else:
            table[key] = value
    return {
        k: v for k, v in out.items() if not (isinstance(v, dict) and not v and k not in ("cam", "follower"))
    }


def toml_text(data: Mapping[str, Any], *, header: str = "") -> str:
    """The design mapping as TOML text in the form's table order (:mod:`camcad.design.toml_text`)."""
    order = [s for s in _SECTION_ORDER if s in data] + [s for s in data if s not in _SECTION_ORDER]
    return design_toml_text({s: data[s] for s in order}, header=header)
