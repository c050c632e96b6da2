"""MkDocs hook: the design-file reference page, generated from ``camcad schema`` at build time.

The page is made from :func:`camcad.design.editor_schema.design_json_schema`,
the JSON Schema ``camcad schema`` prints, which is itself generated from the
loader's rule table: keys, types, bounds, units, defaults and descriptions
come from the one source the loader checks, so the page cannot drift from it.
Whatever fields the schema carries (``default``, ``description``, bounds,
``enum``) are shown; a field the schema gains later shows up without a
change here.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:  # the checkout's camcad, whatever else is installed
    sys.path.insert(0, str(ROOT))

PAGE = "reference/design-file.md"

INTRO = """# Design file reference

Generated from `camcad schema` (the JSON Schema of the design file, itself
generated from the loader's rule table) when the site is built. Units: lengths
mm, angles degrees, speed rpm, mass kg, force N, stress MPa. The loader also
checks what one key alone cannot (a face that covers the contact's travel, a
lift that closes); see the [guides](../guides/first-cam.md).

Editors that read JSON Schema for TOML complete and check these keys while you
type: `camcad schema > camcad.schema.json`, then point the editor at it.
"""


def _cell(text: object) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _number(value: float) -> str:
    return f"{value:g}"


def _type(prop: dict[str, Any]) -> str:
    if "enum" in prop:
        return "one of " + ", ".join(f"`{v}`" for v in prop["enum"])
    if "type" in prop:
        kind = prop["type"]
        if kind == "array":
            return f"list of {prop.get('items', {}).get('type', 'values')}"
        return str(kind)
    if "anyOf" in prop:
        kinds = {f"`{p['const']}`" if "const" in p else _type(p) for p in prop["anyOf"]}
        return " or ".join(sorted(kinds))
    return ""


def _bounds(prop: dict[str, Any]) -> str:
    if "anyOf" in prop:
        return " or ".join(b for b in (_bounds(p) for p in prop["anyOf"]) if b)
    parts = []
    signs = (("minimum", "≥"), ("exclusiveMinimum", ">"), ("maximum", "≤"), ("exclusiveMaximum", "<"))
    for key, sign in signs:
        if key in prop:
            parts.append(f"{sign} {_number(prop[key])}")
    return ", ".join(parts)


def _rows(props: dict[str, Any], required: list[str]) -> list[str]:
    """The table of one section; the default column only when the schema gives defaults."""
    defaults = any("default" in prop for prop in props.values())
    head = ["key", "type", "bounds", *(["default"] if defaults else []), "allowed, unit and meaning"]
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for key, prop in props.items():
        name = f"`{key}`" + (" (required)" if key in required else "")
        cells = [name, _cell(_type(prop)), _cell(_bounds(prop))]
        if defaults:
            cells.append("" if prop.get("default") is None else _cell(f"`{prop['default']}`"))
        cells.append(_cell(prop.get("description", "")))
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def _resolved(node: Any, schema: dict[str, Any]) -> Any:
    """``node`` with every local ``$ref`` (``#/$defs/…``) replaced by what it points at."""
    if isinstance(node, dict):
        if isinstance(node.get("$ref"), str) and node["$ref"].startswith("#/"):
            target: Any = schema
            for part in node["$ref"][2:].split("/"):
                target = target[part]
            rest = {k: v for k, v in node.items() if k != "$ref"}
            return _resolved({**target, **rest}, schema)
        return {k: _resolved(v, schema) for k, v in node.items()}
    if isinstance(node, list):
        return [_resolved(v, schema) for v in node]
    return node


def reference_markdown(schema: dict[str, Any]) -> str:
    """The reference page's Markdown for a design-file JSON Schema."""
    schema = _resolved(schema, schema)
    out = [INTRO]
    required = schema.get("required", [])
    for section, table in schema["properties"].items():
        if table.get("type") == "array":  # [[motion]]: an array of tables
            item = table["items"]
            out.append(f"## `[[{section}]]`\n")
            out.append(_cell(item.get("description", "")) + "\n")
            out += _rows(item["properties"], item.get("required", []))
        else:
            head = f"## `[{section}]`" + (" (required)" if section in required else "")
            out.append(head + "\n")
            if table.get("description"):
                out.append(_cell(table["description"]) + "\n")
            out += _rows(table.get("properties", {}), table.get("required", []))
        out.append("")
    return "\n".join(out) + "\n"


def on_files(files: Any, config: Any) -> Any:
    """Add the generated page to the site's files (before the navigation is built)."""
    from mkdocs.structure.files import File

    from camcad.design.editor_schema import design_json_schema

    files.append(File.generated(config, PAGE, content=reference_markdown(design_json_schema())))
    return files
