"""Data flows one way: a module imports camcad code only from its own layer or below.

The layers are those of the README's architecture section; imports under
``if TYPE_CHECKING:`` are type hints only and are not counted.
"""

from __future__ import annotations

import ast
from pathlib import Path

from tests.conftest import ROOT

LAYERS = {
    "_typing": 0, "_version": 0, "errors": 0, "angles": 0, "extremes": 0, "findings": 0,
    "motion": 1, "design": 1,
    "geometry": 2,
    "dynamics": 3, "fit": 3,
    "toolpath": 3.5,
    "export": 4,
    "analysis": 5,
    "report": 6, "_plots": 6,
    "pipeline": 7,
    "cli": 8, "__init__": 8, "__main__": 8,
}  # fmt: skip


def _runtime_imports(tree: ast.Module) -> list[str]:
    """Modules imported outside ``if TYPE_CHECKING:`` blocks."""
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skip |= {id(n) for child in node.body for n in ast.walk(child)}
    out = []
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.append(node.module)
        elif isinstance(node, ast.Import):
            out += [a.name for a in node.names]
    return [m for m in out if m == "camcad" or m.startswith("camcad.")]


def test_no_module_imports_a_higher_layer():
    upward = []
    for path in sorted((ROOT / "camcad").rglob("*.py")):
        mine = path.relative_to(ROOT / "camcad").with_suffix("").parts[0]
        for module in _runtime_imports(ast.parse(path.read_text())):
            target = module.split(".")[1] if "." in module else "__init__"
            assert target in LAYERS, f"{module} is in no layer: add it to LAYERS and the README"
            if LAYERS[target] > LAYERS[mine]:
                upward.append(f"{Path(path).relative_to(ROOT)} imports {module}")
    assert not upward, upward
