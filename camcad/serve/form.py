"""The design as a form: fields grouped as in the TOML, with units and allowed ranges from the schema.

The fields, their labels, units and hints come from the loader's one rule
table through its JSON Schema (:func:`camcad.design.editor_schema.design_json_schema`:
each rule's own statement of what it allows, "0.1 to 10000 mm"; each enum's
members), the motion editor's keys and law parameters from the same schema and
the law registry (:func:`motion_info`). The form's values go back through :func:`design_data`
into a TOML-like mapping that :func:`camcad.design.parse_design` validates,
so the designer accepts exactly what ``camcad build`` accepts and shows the
loader's own error message next to the field it names. :func:`toml_text`
writes the mapping back as TOML.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from camcad.design.editor_schema import design_json_schema  # the loader's rule table, as JSON Schema
from camcad.design.toml_text import toml_text as design_toml_text
from camcad.motion.laws import LAWS

__all__ = ["Field", "Group", "design_data", "form_groups", "label", "motion_info", "toml_text", "unit_of"]

_SECTION_ORDER = ("cam", "follower", "motion", "dynamics", "fit", "gcode", "dxf", "mesh", "tables")
_INT = re.compile(r"[+-]?\d+")
_KIND_OF_TYPE = {"number": "float", "integer": "int", "boolean": "bool", "string": "str"}
_UNIT_WORDS = {"degrees": "°", "degree": "°"}
_KEY_UNITS = (("_deg", "°"), ("_rpm", "rpm"), ("_mm", "mm"))
_MOTION_KEYS = ("kind", "angle", "lift", "law", "velocity", "file", "noise")
_MOTION_LABELS = {
    "kind": "Segment kind",
    "angle": "Span",
    "lift": "Lift",
    "law": "Motion law",
    "velocity": "Velocity",
    "file": "Point table (CSV)",
    "noise": "Gauge noise σ",
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
    label: str = ""  # the key in words, e.g. "Base radius"
    unit: str = ""  # "mm", "°", "rpm" (from the rule's own statement of what it allows)
    required: bool = False  # a required choice offers no "(default)"


@dataclass(frozen=True, slots=True, kw_only=True)
class Group:
    """A TOML table: the keys the design sets, then the keys left at their defaults."""

    title: str  # "cam", "motion[0]"
    fields: tuple[Field, ...]
    more: tuple[Field, ...] = ()


@functools.cache
def _schema() -> dict[str, Any]:
    return design_json_schema()


def label(key: str) -> str:
    """A design key in words: ``max_pressure_angle`` → "Max pressure angle", ``speed_rpm`` → "Speed"."""
    for suffix, _ in _KEY_UNITS:
        if key.endswith(suffix) and len(key) > len(suffix):
            key = key[: -len(suffix)]
            break
    words = key.replace("_", " ").strip()
    return words[:1].upper() + words[1:]


def unit_of(key: str, allowed: str) -> str:
    """The unit a key is given in: from the rule's own "allowed" text ("0.1 to 10000 mm"), else its name."""
    text = re.sub(r"\s*\([^()]*\)\s*$", "", allowed).strip()
    last = text.rsplit(" ", 1)[-1] if " " in text else ""
    if last and not re.fullmatch(r"[-+\d.e()\[\],]+", last):
        return _UNIT_WORDS.get(last, last)
    return next((u for suffix, u in _KEY_UNITS if key.endswith(suffix)), "")


def _hint(prop: Mapping[str, Any]) -> str:
    """What a key allows, in the rule's own words (its JSON Schema description)."""
    if "enum" in prop:
        return ", ".join(str(m) for m in prop["enum"])
    text = str(prop.get("description", ""))
    if "allowed:" in text:
        return text.split("allowed:", 1)[1].strip()
    kind = _kind(prop)
    return {
        "bool": "true or false",
        "strlist": "comma-separated",
        "floatlist": "comma-separated numbers",
    }.get(kind, text)


def _kind(prop: Mapping[str, Any]) -> str:
    if "enum" in prop:
        return "enum"
    kind = prop.get("type") or next((b.get("type") for b in prop.get("anyOf", ()) if "type" in b), "")
    if kind == "array":
        return "floatlist" if prop.get("items", {}).get("type") == "number" else "strlist"
    return _KIND_OF_TYPE.get(str(kind), "str")


def _shown(value: Any) -> str:
    """A TOML value as the text of an input."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ", ".join(_shown(v) for v in value)
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return repr(value)
    return str(value)


def _field(section: str, key: str, prop: Mapping[str, Any], value: Any, *, required: bool) -> Field:
    hint = _hint(prop)
    return Field(
        path=f"{section}.{key}",
        key=key,
        kind=_kind(prop),
        value="" if value is None else _shown(value),
        choices=tuple(str(m) for m in prop.get("enum", ())),
        hint=hint,
        label=label(key),
        unit=unit_of(key, hint) if _kind(prop) in ("float", "int") else "",
        required=required,
    )


def motion_info() -> dict[str, Any]:
    """What the page's motion editor needs: each motion key's label and hint, each law's parameters.

    From the schema of a ``[[motion]]`` table and the law registry (:data:`camcad.motion.laws.LAWS`).
    """
    props = _schema()["properties"]["motion"]["items"]["properties"]
    keys = {
        key: {"label": _MOTION_LABELS[key], "hint": str(props.get(key, {}).get("description", ""))}
        for key in _MOTION_KEYS
    }
    keys["angle"]["unit"] = "°"
    keys["noise"]["unit"] = "mm"
    kinds = [str(k) for k in props["kind"]["enum"]]
    laws = {
        name: {
            "summary": info.summary,
            "parameters": [
                {"name": p.name, "label": label(p.name), "allowed": p.allowed, "required": p.default is None}
                for p in info.parameters
            ],
        }
        for name, info in LAWS.items()
    }
    return {"keys": keys, "kinds": kinds, "laws": laws}


def form_groups(data: Mapping[str, Any]) -> list[Group]:
    """The form of a design mapping: one group per table in TOML order (the motion is the page's editor)."""
    groups = []
    root = _schema()
    schema = root["properties"]
    conditional = _conditional_required(root, data)
    sections = [s for s in _SECTION_ORDER if s in schema and s != "motion"]
    sections += [s for s in schema if s not in sections and s != "motion"]
    for section in sections:
        table = data.get(section, {})
        if not isinstance(table, Mapping):
            continue
        props = schema[section]["properties"]
        required = set(schema[section].get("required", ())) | conditional.get(section, set())
        given = tuple(
            _field(section, k, props[k], v, required=k in required) for k, v in table.items() if k in props
        )
        more = tuple(
            _field(section, k, p, None, required=k in required) for k, p in props.items() if k not in table
        )
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


_MOTION_PATH = re.compile(r"motion\[(\d{1,3})\]\.([A-Za-z0-9_-]{1,60})")
_TEXT_KEYS = ("kind", "law", "file")
_ADAPTIVE = ("polynomial", "inclined-sine")  # the laws that take start/end blend tables


def _motion_value(key: str, text: Any) -> Any:
    """A motion input converted: words stay words, ``lift = "close"`` stays, numbers become numbers."""
    if isinstance(text, bool):
        return text
    text = str(text).strip()
    if text == "":
        return None
    if key in _TEXT_KEYS or text == "close":
        return text
    return _number(text)


def _motion(base: list[Any], values: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The ``[[motion]]`` tables the page's editor sends: ``motion.count`` tables from ``motion[i].key``.

    ``motion[i].source`` names the file's table a segment came from (its start/end blend tables are kept
    while its law takes them); a new segment has none.
    """
    count = _number(str(values["motion.count"]).strip())
    if not isinstance(count, int) or not 0 <= count <= 1000:
        count = 0
    tables: list[dict[str, Any]] = [{} for _ in range(count)]
    for path, text in values.items():
        match = _MOTION_PATH.fullmatch(path)
        if not match or int(match.group(1)) >= count or match.group(2) == "source":
            continue
        value = _motion_value(match.group(2), text)
        if value is not None:
            tables[int(match.group(1))][match.group(2)] = value
    for i, table in enumerate(tables):
        source = _number(str(values.get(f"motion[{i}].source", "")).strip())
        if isinstance(source, int) and 0 <= source < len(base) and table.get("law") in _ADAPTIVE:
            for key in ("start", "end"):
                if isinstance(base[source], Mapping) and isinstance(base[source].get(key), Mapping):
                    table[key] = dict(base[source][key])
    return tables


def form_fields(base: Mapping[str, Any]) -> dict[str, Field]:
    """Every field of the form of ``base`` (:func:`form_groups`) by its path."""
    return {f.path: f for g in form_groups(base) for f in (*g.fields, *g.more)}


def design_data(
    base: Mapping[str, Any], values: Mapping[str, Any], fields: Mapping[str, Field] | None = None
) -> dict[str, Any]:
    """The design mapping with the form's ``values`` (path → input text) applied to ``base``.

    Paths not in ``values`` keep their value from ``base``; an empty input
    removes the key (the default applies). With ``motion.count`` the values
    hold the whole motion program (``motion[i].key``; see :func:`_motion`);
    without it a ``motion[i].key`` edits that key of the file's segment, its
    blend tables kept. ``fields`` is :func:`form_fields` of ``base`` when the
    caller keeps it (the server does, once per file loaded: the schema's work
    is not redone on every edit).
    """
    out: dict[str, Any] = {k: (dict(v) if isinstance(v, Mapping) else v) for k, v in base.items()}
    base_motion = list(base.get("motion", []))
    out["motion"] = [dict(t) if isinstance(t, Mapping) else t for t in base_motion]
    if "motion.count" in values:
        out["motion"] = _motion(base_motion, values)
    if fields is None:
        fields = form_fields(base)
    for path, text in values.items():
        match = _MOTION_PATH.fullmatch(path)
        if match and "motion.count" not in values:
            index, key = int(match.group(1)), match.group(2)
            if index < len(out["motion"]) and isinstance(out["motion"][index], dict):
                value = _motion_value(key, text)
                if value is None:
                    out["motion"][index].pop(key, None)
                else:
                    out["motion"][index][key] = value
            continue
        field = fields.get(path)
        if field is None:
            continue
        value = _value(field, text)
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


def _conditional_required(root: Mapping[str, Any], data: Mapping[str, Any]) -> dict[str, set[str]]:
    """The keys a style requires (the schema's ``allOf`` of if ``cam.style`` = … then/else), per table.

    A barrel requires ``barrel_radius`` and ``length`` and every other style
    ``base_radius``, a rib ``rib_width``: the JSON Schema states each as a
    condition on the style (one style, ``const``, or several, ``enum``).
    """
    cam = data.get("cam", {})
    style = cam.get("style", "plate") if isinstance(cam, Mapping) else "plate"
    out: dict[str, set[str]] = {}
    for rule in root.get("allOf", ()):
        chosen = rule["if"]["properties"]["cam"]["properties"]["style"]
        branch = rule["then"] if style in chosen.get("enum", [chosen.get("const")]) else rule["else"]
        for section, table in branch["properties"].items():
            out.setdefault(section, set()).update(table.get("required", ()))
    return out
