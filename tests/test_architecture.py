"""Data flows one way, and no camcad module depends on itself through others.

The layers are those of the README's architecture section, bottom first::

    shared bottom (_typing, _version, errors, angles, extremes, findings, roots, units)
      < motion < geometry < dynamics < inspect < fea < fit < toolpath < export
      < design
      < analysis, report, report_tables, _plots < pipeline < explore
      < cli, serve, api, __init__, __main__

A module imports camcad code only from its own layer or below. The design
schema (``camcad/design.py``, later ``design/``) sits above the stages: only
``analysis``, ``report``, ``_plots``, ``pipeline`` and ``cli`` (and ``design``
itself) may import it; the stages that still do are listed, each with its
reason, in ``KNOWN_DESIGN_IMPORTS``, which may only shrink.

Imports are read with :mod:`ast` (nothing is imported). Those under
``if TYPE_CHECKING:`` are type hints only and are not counted; imports inside
functions run, so they are.
"""

from __future__ import annotations

import ast
import functools
import re
from collections.abc import Iterable, Mapping
from pathlib import Path

from tests.conftest import ROOT

PACKAGE = ROOT / "camcad"

# Layer of each top-level name under camcad/ (a module or a package), bottom first.
LAYER_ORDER: tuple[frozenset[str], ...] = (
    frozenset(
        {
            "_typing",
            "_version",
            "_lazy",
            "errors",
            "angles",
            "extremes",
            "findings",
            "knobs",
            "roots",
            "units",
        }
    ),
    frozenset({"motion"}),
    frozenset({"geometry"}),
    frozenset({"dynamics"}),
    # camcad/inspect/ (issue 38): tolerance statistics and inspection of a made cam; it needs the
    # exact envelope (geometry) and the motion laws, and nothing of fit/toolpath/export, which may
    # later use it (a compensated profile goes to the fit and the tool path)
    frozenset({"inspect"}),
    frozenset({"fea"}),  # camcad/fea/ (issue 22): the plate's FE check, from geometry, plate and dynamics
    frozenset({"fit"}),
    frozenset({"toolpath"}),  # camcad/toolpath/ (issue 13): the arc-spline tool paths
    frozenset({"export"}),
    frozenset({"design"}),  # the schema sits above every stage
    frozenset({"analysis", "report", "report_tables", "_plots"}),
    frozenset({"pipeline"}),
    frozenset({"explore"}),  # camcad/explore/ (issue 20): optimize, sweep, Pareto; analyses through pipeline
    # serve/ (issue 19): the live designer; api: the Python API (issue 39)
    frozenset({"cli", "serve", "api", "__init__", "__main__"}),
)
LAYERS: dict[str, int] = {name: rank for rank, names in enumerate(LAYER_ORDER) for name in names}
DESIGN_READERS_FROM = LAYERS["analysis"]  # this layer and those above may import design

# Stage modules that import camcad.design. The list only shrinks: a module that stops
# importing design must leave it, and a module not in it may not start. It is empty.
KNOWN_DESIGN_IMPORTS: dict[str, str] = {}

# Import cycles, each as the sorted tuple of its modules. The list only shrinks: a new
# cycle fails, and so does an entry whose cycle is gone. It is empty.
KNOWN_CYCLES: dict[tuple[str, ...], str] = {}


# A cam family (plate, groove, conjugate; barrel later) is one module under geometry/families/: no
# code elsewhere asks which family a cam is. The files that still do are listed, each with its
# reason; the list only shrinks (an entry whose branch is gone fails too). It is empty.
FAMILY_HOME = PACKAGE / "geometry" / "families"
FAMILY_BRANCH = re.compile(
    r"CamStyle\.(?:GROOVE|CONJUGATE|BARREL)\b"  # a family named by its enum member (PLATE is the default)
    r"|(?:\bis|==|!=)\s*(?:not\s+)?CamStyle\.PLATE\b"
    r"|\.style\s+(?:is|==|!=)"  # a family told apart by comparing the style
    r"|\.style\.value\s*(?:==|!=)"
    r"|\bcamcad\.positive\b|\bfrom\s+camcad\s+import\s+positive\b"  # the second pipeline, gone
    # a family told apart by the type of what it yields (a part's check, its family object)
    r"|\bisinstance\([^)]*\b(?:Plate|Groove|Conjugate|Barrel|Linear)\w*"
    r"|\btype\([^)]*\)\s*(?:is|==|!=)\s*(?:not\s+)?(?:Plate|Groove|Conjugate|Barrel|Linear)\w*"
    # or by its registry entry or its name
    r"|(?:\bis|==|!=)\s*(?:not\s+)?(?:PLATE|GROOVE|CONJUGATE|BARREL|LINEAR)\b"
    r"|\bfamily\.name\s*(?:==|!=|in\b|not\s+in\b)"
)
KNOWN_FAMILY_BRANCHES: dict[str, str] = {}  # empty


def _module_name(path: Path) -> str:
    """``camcad/fit/curve.py`` -> ``camcad.fit.curve``; a package is named by its folder."""
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@functools.cache
def _sources() -> dict[str, tuple[Path, ast.Module]]:
    """Every camcad module: its name -> (path, parsed source)."""
    paths = sorted(PACKAGE.rglob("*.py"))
    return {_module_name(p): (p, ast.parse(p.read_text(encoding="utf-8"))) for p in paths}


def runtime_imports(tree: ast.Module, *, module: str, is_package: bool, known: Iterable[str]) -> set[str]:
    """The camcad modules ``module`` imports when it runs (``if TYPE_CHECKING:`` excluded).

    ``from camcad.fit import curve`` names the module ``camcad.fit.curve`` when it
    is one of ``known``, else (a name defined in the package) ``camcad.fit``.
    Relative imports are resolved against ``module``.
    """
    known = set(known)
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skip |= {id(n) for child in node.body for n in ast.walk(child)}
    package = module if is_package else module.rpartition(".")[0]
    out: set[str] = set()
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                source = ".".join([*base, node.module] if node.module else base)
            else:
                source = node.module or ""
            for alias in node.names:
                if f"{source}.{alias.name}" in known:
                    out.add(f"{source}.{alias.name}")
                elif source == "camcad" or source.startswith("camcad."):
                    out.add(source)
        elif isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name == "camcad" or a.name.startswith("camcad.")}
    out.discard(module)
    return out


@functools.cache
def import_graph() -> dict[str, frozenset[str]]:
    """Runtime import graph of every camcad module."""
    sources = _sources()
    return {
        name: frozenset(
            runtime_imports(tree, module=name, is_package=path.name == "__init__.py", known=sources)
        )
        for name, (path, tree) in sources.items()
    }


def top_name(module: str) -> str:
    """The top-level name that places a module in a layer (``__init__`` for ``camcad``)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def layer_violations(graph: Mapping[str, Iterable[str]]) -> tuple[list[str], set[str]]:
    """Upward imports, and the modules below the design readers that import design."""
    upward: list[str] = []
    design_importers: set[str] = set()
    for module, targets in sorted(graph.items()):
        mine = top_name(module)
        assert mine in LAYERS, f"{module} is in no layer: add {mine!r} to LAYER_ORDER and the README"
        for target in sorted(targets):
            theirs = top_name(target)
            assert theirs in LAYERS, f"{target} is in no layer: add {theirs!r} to LAYER_ORDER and the README"
            if theirs == "design":
                if mine != "design" and LAYERS[mine] < DESIGN_READERS_FROM:
                    design_importers.add(module)
            elif LAYERS[theirs] > LAYERS[mine]:
                upward.append(f"{module} (layer {mine}) imports {target} (layer {theirs})")
    return upward, design_importers


def find_cycles(graph: Mapping[str, Iterable[str]]) -> set[tuple[str, ...]]:
    """Every import cycle a depth-first search meets, each as the sorted tuple of its modules.

    Each back edge u -> v of the DFS closes one cycle: the stack from v up to u.
    """
    edges = {u: sorted(vs) for u, vs in graph.items()}
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    stack: list[str] = []
    cycles: set[tuple[str, ...]] = set()

    def visit(u: str) -> None:
        state[u] = 1
        stack.append(u)
        for v in edges.get(u, ()):
            if state.get(v) == 1:
                cycles.add(tuple(sorted(stack[stack.index(v) :])))
            elif v not in state:
                visit(v)
        stack.pop()
        state[u] = 2

    for u in sorted(edges):
        if u not in state:
            visit(u)
    return cycles


def test_no_module_imports_a_higher_layer():
    upward, _ = layer_violations(import_graph())
    assert not upward, "\n".join(upward)


def test_only_the_known_stage_modules_import_design():
    _, importers = layer_violations(import_graph())
    new = sorted(importers - KNOWN_DESIGN_IMPORTS.keys())
    assert not new, f"stage modules must not import camcad.design (take per-stage options instead): {new}"
    gone = sorted(KNOWN_DESIGN_IMPORTS.keys() - importers)
    assert not gone, f"no longer import camcad.design: remove them from KNOWN_DESIGN_IMPORTS: {gone}"


def test_no_new_import_cycle():
    cycles = find_cycles(import_graph())
    new = sorted(cycles - KNOWN_CYCLES.keys())
    assert not new, f"import cycles among camcad modules: {new}"
    gone = sorted(KNOWN_CYCLES.keys() - cycles)
    assert not gone, f"these cycles are gone: remove them from KNOWN_CYCLES: {gone}"


def family_branches(sources: Mapping[str, str]) -> dict[str, list[str]]:
    """Each file (path from the root) and its lines that branch on a cam family."""
    found: dict[str, list[str]] = {}
    for name, text in sorted(sources.items()):
        lines = [line.strip() for line in text.splitlines() if FAMILY_BRANCH.search(line)]
        if lines:
            found[name] = lines
    return found


def test_no_cam_family_branch_outside_its_module():
    sources = {
        p.relative_to(ROOT).as_posix(): p.read_text(encoding="utf-8")
        for p in sorted(PACKAGE.rglob("*.py"))
        if FAMILY_HOME not in p.parents
    }
    found = family_branches(sources)
    new = {name: lines for name, lines in found.items() if name not in KNOWN_FAMILY_BRANCHES}
    assert not new, f"cam-family branches belong in camcad/geometry/families/: {new}"
    gone = sorted(KNOWN_FAMILY_BRANCHES.keys() - found.keys())
    assert not gone, f"no longer branch on a cam family: remove them from KNOWN_FAMILY_BRANCHES: {gone}"


# The checks themselves, on made-up modules: they must be able to fail.


def test_family_rule_flags_branches_and_the_second_pipeline():
    sources = {
        "camcad/a.py": "if design.cam.style is CamStyle.GROOVE:\n    pass\n",
        "camcad/b.py": "from camcad.positive import analyse_positive_drive\n",
        "camcad/c.py": "ok = spec.style.value == 'plate'\nx = CamStyle.CONJUGATE\n",
        "camcad/d.py": "family = family_of(design.cam.style)  # the registry: no branch\n",
        "camcad/e.py": "style: CamStyle = CamStyle.PLATE\nif cam.style is not CamStyle.PLATE:\n",
        "camcad/f.py": "if isinstance(check, GrooveAnalysis):\n    pass\nok = isinstance(x, (int, float))\n",
        "camcad/g.py": "if isinstance(fam, (PlateFamily, X)) or type(c) is ConjugateSpec:\n",
        "camcad/h.py": "if family is GROOVE or analysis.family.name == 'barrel':\n",
        "camcad/i.py": "margin = min(c.radius_margin for c in part.checks)  # data, no branch\n",
    }
    assert family_branches(sources) == {
        "camcad/a.py": ["if design.cam.style is CamStyle.GROOVE:"],
        "camcad/b.py": ["from camcad.positive import analyse_positive_drive"],
        "camcad/c.py": ["ok = spec.style.value == 'plate'", "x = CamStyle.CONJUGATE"],
        "camcad/e.py": ["if cam.style is not CamStyle.PLATE:"],
        "camcad/f.py": ["if isinstance(check, GrooveAnalysis):"],
        "camcad/g.py": ["if isinstance(fam, (PlateFamily, X)) or type(c) is ConjugateSpec:"],
        "camcad/h.py": ["if family is GROOVE or analysis.family.name == 'barrel':"],
    }


def _imports_of(source: str, module: str = "camcad.motion.laws", known: Iterable[str] = ()) -> set[str]:
    return runtime_imports(ast.parse(source), module=module, is_package=False, known=known)


def test_reader_counts_runtime_imports_only():
    source = (
        "from typing import TYPE_CHECKING\n"
        "import numpy\n"
        "from camcad.errors import SpecError\n"
        "from . import _lawbase\n"
        "from ..geometry import cam\n"
        "if TYPE_CHECKING:\n"
        "    from camcad.fit import ProfileFit\n"
        "def late():\n"
        "    import camcad.export.dxf\n"
    )
    found = _imports_of(source, known={"camcad.motion._lawbase", "camcad.geometry.cam"})
    assert found == {"camcad.errors", "camcad.motion._lawbase", "camcad.geometry.cam", "camcad.export.dxf"}


def test_layer_check_flags_upward_and_design_imports():
    graph = {
        "camcad.motion.laws": {"camcad.fit.curve", "camcad.errors"},
        "camcad.geometry.cam": {"camcad.design", "camcad.motion.laws"},
        "camcad.pipeline": {"camcad.design", "camcad.cli"},
        "camcad.design": {"camcad.motion.laws"},
    }
    upward, importers = layer_violations(graph)
    assert upward == [
        "camcad.motion.laws (layer motion) imports camcad.fit.curve (layer fit)",
        "camcad.pipeline (layer pipeline) imports camcad.cli (layer cli)",
    ]
    assert importers == {"camcad.geometry.cam"}


def test_layer_order_is_the_documented_chain():
    chain = ["motion", "geometry", "dynamics", "fea", "fit", "toolpath", "export", "design"]
    chain += ["analysis", "pipeline"]
    ranks = [LAYERS[name] for name in chain]
    assert ranks == sorted(set(ranks)), "each stage sits strictly above the one before it"
    assert LAYERS["report"] == LAYERS["_plots"] == LAYERS["analysis"]
    assert LAYERS["extremes"] < LAYERS["motion"] and LAYERS["cli"] == max(LAYERS.values())


def test_cycle_finder_finds_a_made_up_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set(), "e": {"e"}}
    assert find_cycles(graph) == {("a", "b", "c"), ("e",)}
    assert find_cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == set()


# Follower kinds (issue 33): a follower kind is its module under camcad/geometry/followers/. Nothing
# else asks which kind it is: no kind flags, no kind enum, no follower-type word in the code.

FOLLOWERS = PACKAGE / "geometry" / "followers"
FORBIDDEN_ATTRIBUTES = frozenset({"is_roller", "FollowerKind"})  # on anything
FORBIDDEN_KIND_FLAGS = frozenset({"roller", "oscillating"})  # as ``<...>.kind.roller``, ``kind.oscillating``
# The type words of the four kinds camcad started with; the registry's words are added at test time.
KNOWN_FOLLOWER_WORDS = ("translating-roller", "translating-flat", "oscillating-roller", "oscillating-flat")


def _docstrings(tree: ast.Module) -> set[int]:
    """The ids of the docstring constants of a module and its classes and functions."""
    out: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                out.add(id(body[0].value))
    return out


def follower_kind_uses(tree: ast.Module, words: Iterable[str]) -> list[str]:
    """Where a module asks which kind of follower it has: kind flags, the kind enum, type words.

    Each as ``line: what``. Docstrings (examples, prose) are not code and are not read.
    """
    words = tuple(words)
    skip = _docstrings(tree)
    out: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr in FORBIDDEN_ATTRIBUTES:
            out.append(f"{node.lineno}: .{node.attr}")
        elif isinstance(node, ast.Name) and node.id in FORBIDDEN_ATTRIBUTES:
            out.append(f"{node.lineno}: {node.id}")
        elif isinstance(node, ast.alias) and node.name in FORBIDDEN_ATTRIBUTES:
            out.append(f"{node.lineno}: import {node.name}")
        elif isinstance(node, ast.Attribute) and node.attr in FORBIDDEN_KIND_FLAGS:
            owner = node.value
            name = owner.attr if isinstance(owner, ast.Attribute) else getattr(owner, "id", "")
            if name == "kind":
                out.append(f"{node.lineno}: kind.{node.attr}")
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in skip:
            out += [f"{node.lineno}: {word!r}" for word in words if word in node.value]
    return out


def test_no_follower_kind_is_asked_for_outside_its_module():
    from camcad.geometry.followers import FOLLOWER_TYPES

    words = sorted({*KNOWN_FOLLOWER_WORDS, *FOLLOWER_TYPES})
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if FOLLOWERS in path.parents:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        found += [f"{path.relative_to(ROOT)}:{hit}" for hit in follower_kind_uses(tree, words)]
    assert not found, "ask the follower's module (its TYPE, its Follower object) instead:\n" + "\n".join(
        found
    )


def test_follower_kind_scan_flags_a_made_up_module():
    source = (
        '"""A docstring may say translating-roller."""\n'
        "from camcad.geometry.spec import FollowerKind\n"
        "def f(cam, design):\n"
        '    """So may this one: oscillating-flat."""\n'
        "    if cam.is_roller or design.follower.kind.oscillating:\n"
        '        return f"a {cam.kind.roller} translating-flat"\n'
        '    return design.follower.kind.word == "oscillating-roller" or FollowerKind\n'
    )
    hits = follower_kind_uses(ast.parse(source), KNOWN_FOLLOWER_WORDS)
    assert sorted(hits) == sorted(
        [
            "2: import FollowerKind",
            "5: .is_roller",
            "5: kind.oscillating",
            "6: kind.roller",
            "6: 'translating-flat'",
            "7: 'oscillating-roller'",
            "7: FollowerKind",
        ]
    )
    clean = "def f(cam):\n    return cam.has_pitch_curve and cam.follower_spec.kind.lift.angular\n"
    assert follower_kind_uses(ast.parse(clean), KNOWN_FOLLOWER_WORDS) == []


def test_every_follower_module_is_in_the_registry():
    """Each module of camcad/geometry/followers/ that declares a TYPE is found; words are unique."""
    from camcad.geometry.followers import FOLLOWER_TYPES

    declared = [
        p.stem
        for p in sorted(FOLLOWERS.glob("*.py"))
        if not p.stem.startswith("_") and re.search(r"^TYPE = FollowerType\(", p.read_text("utf-8"), re.M)
    ]
    assert len(declared) == len(FOLLOWER_TYPES) >= 5
    assert {k.word.replace("-", "_") for k in FOLLOWER_TYPES.values()} == set(declared)


# A name or a module whose own name starts with one underscore (``_SECTIONS``, ``plan._breaks``,
# ``motion/_lawbase.py``) is private to the package that holds it: that package's modules and its
# subpackages may import it, no other camcad module may (a name the others need is made public, or the
# code moves). ``camcad._typing`` and the like are private to ``camcad`` itself, so any camcad module
# may use them; ``camcad._plots._base`` only ``camcad._plots``.


def _is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def private_imports(sources: Mapping[str, tuple[ast.Module, bool]]) -> list[str]:
    """Each use of a private camcad name outside its package: ``module:line -> dotted.name``.

    ``sources`` maps a module's name to its parsed source and whether it is a package's
    ``__init__``. Every import counts (those under ``if TYPE_CHECKING:`` too), and so does an
    attribute of an imported camcad module (``plan._breaks`` after ``from camcad.toolpath import plan``).
    """
    packages = {name for name, (_, is_package) in sources.items() if is_package}
    found: list[str] = []
    for module, (tree, is_package) in sorted(sources.items()):
        package = module if is_package else module.rpartition(".")[0]

        def check(target: str, line: int, module: str = module, package: str = package) -> None:
            parts = target.split(".")
            for k in range(1, len(parts)):
                if not _is_private(parts[k]):
                    continue
                owner = ".".join(parts[:k])  # the module or package that defines parts[k]
                home = owner if owner in packages else owner.rpartition(".")[0]
                if package != home and not package.startswith(home + "."):
                    found.append(f"{module}:{line} -> {target}")
                    return

        bound: dict[str, str] = {}  # local name -> the camcad module it stands for
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                    source = ".".join([*base, node.module] if node.module else base)
                else:
                    source = node.module or ""
                if source != "camcad" and not source.startswith("camcad."):
                    continue
                for alias in node.names:
                    target = f"{source}.{alias.name}"
                    if target in sources:
                        bound[alias.asname or alias.name] = target
                    check(target, node.lineno)
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name == "camcad" or alias.name.startswith("camcad."):
                        bound[alias.asname or alias.name] = alias.name
                        check(alias.name, node.lineno)
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and _is_private(node.attr):
                value = ast.unparse(node.value)
                if value in bound:
                    check(f"{bound[value]}.{node.attr}", node.lineno)
    return sorted(set(found))


def test_no_private_name_is_used_outside_its_package():
    sources = {name: (tree, path.name == "__init__.py") for name, (path, tree) in _sources().items()}
    found = private_imports(sources)
    assert not found, "private names used outside their package (make them public, or move the code):\n" + (
        "\n".join(found)
    )


def test_private_rule_flags_names_modules_and_attributes_across_packages():
    def tree(text: str) -> ast.Module:
        return ast.parse(text)

    sources = {
        "camcad": (tree("def _exit(): pass\n"), True),
        "camcad._typing": (tree(""), False),
        "camcad.toolpath": (tree(""), True),
        "camcad.toolpath.plan": (tree("def _breaks(): pass\n"), False),
        "camcad.toolpath.groove": (tree("from camcad.toolpath.plan import _breaks\n"), False),  # sibling
        "camcad.toolpath.arcs": (tree("from ..plan import _breaks\n"), True),  # a subpackage
        "camcad.design": (tree(""), True),
        "camcad.design.tables": (tree("_SECTIONS = {}\n"), False),
        "camcad.design.editor": (tree("from camcad.design.tables import _SECTIONS\n"), False),
        "camcad.export": (tree(""), True),
        "camcad.export.a": (tree("from camcad.toolpath.plan import Toolpath, _breaks\n"), False),
        "camcad.export.b": (tree("from camcad.toolpath import plan\nx = plan._breaks(1)\n"), False),
        "camcad.export.c": (tree("import camcad.toolpath.plan\ncamcad.toolpath.plan._breaks()\n"), False),
        "camcad.export.d": (
            tree(
                "from typing import TYPE_CHECKING\n"
                "if TYPE_CHECKING:\n"
                "    from camcad.design.tables import _SECTIONS\n"
            ),
            False,
        ),
        "camcad.export.e": (tree("from camcad.toolpath._pieces import Piece\n"), False),  # a private module
        "camcad.export.f": (tree("from camcad._typing import FloatArray\nfrom camcad import _exit\n"), False),
        "camcad.export.g": (tree("from camcad.toolpath.plan import __all__, Toolpath\n"), False),  # dunder
    }
    assert private_imports(sources) == [
        "camcad.export.a:1 -> camcad.toolpath.plan._breaks",
        "camcad.export.b:2 -> camcad.toolpath.plan._breaks",
        "camcad.export.c:2 -> camcad.toolpath.plan._breaks",
        "camcad.export.d:3 -> camcad.design.tables._SECTIONS",
        "camcad.export.e:1 -> camcad.toolpath._pieces.Piece",
    ]


# No stage below the design layer writes a TOML path (``"cam.base_radius"``, ``f"drive.{name}"``): it
# names a ``camcad.knobs.Knob``, which ``camcad.design.paths`` maps to the path where errors and
# findings leave the core (issue 33). A follower's and a cam family's module declare their own
# schema keys, so theirs are their own data.
STAGES = ("motion", "geometry", "dynamics", "inspect", "fea", "fit", "toolpath", "export")
OWN_SCHEMA = (PACKAGE / "geometry" / "followers", PACKAGE / "geometry" / "families")
FILE_SUFFIXES = frozenset(
    {"step", "stl", "ngc", "dxf", "csv", "json", "html", "svg", "png", "py", "toml", "txt"}
)


@functools.cache
def _toml_path_pattern() -> re.Pattern[str]:
    from camcad.design.tables import _SECTIONS

    sections = "|".join(sorted(_SECTIONS, key=len, reverse=True))
    return re.compile(rf"(?<![\w.])({sections})\.([A-Za-z_]\w*|$)")


def toml_path_literals(tree: ast.Module) -> list[str]:
    """The TOML paths a module's code writes (string constants, f-string parts), as ``line: 'path'``.

    A table's name before a formatted key (``f"drive.{name}"``) counts. Docstrings (of a module,
    class, function or attribute) are prose, not code, and a file name (``cam.step``) is not a path.
    """
    skip = _docstrings(tree) | {
        id(node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
    }
    keyed: set[int] = set()  # f-string parts followed by a formatted value: "drive." counts there
    for node in ast.walk(tree):
        if isinstance(node, ast.JoinedStr):
            keyed |= {
                id(part)
                for part, after in zip(node.values, node.values[1:], strict=False)
                if isinstance(after, ast.FormattedValue)
            }
    out: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in skip:
            for hit in _toml_path_pattern().finditer(node.value):
                if hit.group(2) not in FILE_SUFFIXES and (hit.group(2) or id(node) in keyed):
                    out.append(f"{node.lineno}: {hit.group(0)!r}")
    return out


def stage_toml_paths(package: Path) -> list[str]:
    """Every TOML path written in the stage packages under ``package`` (a camcad tree)."""
    found = []
    for stage in STAGES:
        for path in sorted((package / stage).rglob("*.py")):
            if any(
                home.name == path.parent.name and path.parent.parent.name == "geometry" for home in OWN_SCHEMA
            ):
                continue
            tree = ast.parse(path.read_text(encoding="utf-8"))
            found += [f"{path.relative_to(package.parent)}:{hit}" for hit in toml_path_literals(tree)]
    return found


def test_no_stage_writes_a_toml_path():
    found = stage_toml_paths(PACKAGE)
    assert not found, "name a camcad.knobs.Knob (design/paths.py maps it):\n" + "\n".join(found)


def test_toml_path_scan_flags_literals_and_f_strings_but_not_prose_or_files():
    source = (
        '"""Raise cam.base_radius (a docstring is prose)."""\n'
        "from camcad.errors import DesignError\n"
        "def f(name, x):\n"
        '    """Says gcode.tool_diameter."""\n'
        '    open("cam.step")\n'
        "    if x:\n"
        '        raise DesignError("follower.roller_radius", "too small")\n'
        '    raise DesignError(f"drive.{name}", f"use a larger groove.depth than {x}")\n'
        "LIMIT = 3\n"
        '"""An attribute docstring may end with the cam."""\n'
        'WORDS = "a note about the cam."\n'
    )
    assert toml_path_literals(ast.parse(source)) == [
        "7: 'follower.roller_radius'",
        "8: 'drive.'",
        "8: 'groove.depth'",
    ]


def test_every_knob_has_one_toml_path_the_schema_knows():
    from camcad.design.paths import PATHS
    from camcad.design.tables import _BARREL_RULES, _SECTIONS
    from camcad.knobs import Knob

    assert set(PATHS) == set(Knob)
    assert len(set(PATHS.values())) == len(PATHS)  # one knob per path
    unknown = []
    for knob, path in PATHS.items():
        table, _, key = path.partition(".")
        if not key:
            assert table in _SECTIONS, knob  # a table whose keys a stage names itself (TableKey)
        elif key not in _SECTIONS.get(table, {}) and key not in _BARREL_RULES.get(table, {}):
            unknown.append(path)
    assert sorted(unknown) == sorted(KNOWN_PATHS_OUTSIDE_THE_SCHEMA)


# Paths the stages name that no schema rule states (the list only shrinks): options a stage has
# that the design file does not set yet.
KNOWN_PATHS_OUTSIDE_THE_SCHEMA = (
    "cam.rib_width",  # geometry/barrel.py: a barrel's rib width, not yet a [cam] key
    "gcode.stepover",  # toolpath/barrel.py: the barrel's roughing, not yet [gcode] keys
    "gcode.rough_diameter",
    "gcode.stock",
    "tolerance.weights",  # inspect/tolerance.py: the study's weights, given by the API, not the file
)
