"""The package's architecture, checked from its source (issue 38): one-way layers, no import cycle, no private
name taken from another module; and the README's architecture section and its picture, against the tree.

Every import that runs counts: at the top of a module, inside a function or a method; only the imports under
``if TYPE_CHECKING:`` (types, never executed) are left out. Each rule is a function over a folder of source, so
that each can be shown to fail on a planted violation (the last tests).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

import scara_pin as sp

ROOT = Path(sp.__file__).parent
REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tools"))  # tools/layers.py: the layers' table and picture

# The layers, lowest first. A module may import its own layer and those below, never one above (STYLE.md:
# description -> model -> kinematics -> cell -> workspace -> motion -> job -> viz -> the facade -> cli).
LAYERS: tuple[tuple[str, ...], ...] = (
    ("_typing", "_version", "errors", "signals", "units", "summary"),
    ("limits", "files", "urdf_rules"),
    ("description",),
    ("_checks", "tables", "_urdf_checks", "symbolic"),  # symbolic: the model in CasADi (cell and motion use it)
    ("model", "chain", "ik_results"),  # the robot's model: Pinocchio, frames, limits, the injected IK and its results
    ("kinematics",),
    ("calibration",),  # beside kinematics: imports description, model, kinematics; nothing lower imports it
    ("cell",),  # the robot's collision model, the obstacles and their distances
    ("workspace", "lint"),
    ("motion",),
    ("job",),  # a program of moves: above motion, below the pictures and the command line
    ("sweep",),  # many jobs on a cluster: above the job, below the pictures
    ("viz",),
    ("robots",),  # the facade: the user's Robot (model + geometry + pictures) and load_robot
    ("cli",),
    ("__init__",),
)


def _module_name(path: Path, root: Path) -> str:
    """``scara_pin.motion.jump.nlp`` for .../scara_pin/motion/jump/nlp.py (a package: its ``__init__``)."""
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts)


def _is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def runtime_imports(path: Path, root: Path) -> list[tuple[int, str, tuple[str, ...]]]:
    """(line, imported module, names) of every import of the package's own modules that runs in ``path``.

    Relative imports and absolute ones naming the package; the imports under ``if TYPE_CHECKING:`` are left out.
    ``names``: what a ``from`` import takes (empty for ``import x``).
    """
    tree = ast.parse(path.read_text(encoding="utf-8"))
    me = _module_name(path, root)
    pkg = me.split(".") if _is_package(path) else me.split(".")[:-1]
    if _is_package(path):
        pkg = pkg[:-1]  # .../__init__ -> the package itself
    skipped: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skipped.update(id(n) for stmt in node.body for n in ast.walk(stmt))
    out = []
    top = root.name
    for node in ast.walk(tree):
        if id(node) in skipped:
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg[: len(pkg) - (node.level - 1)] if node.level > 1 else pkg
                target = ".".join(base + ([node.module] if node.module else []))
            elif node.module and (node.module == top or node.module.startswith(top + ".")):
                target = node.module
            else:
                continue
            out.append((node.lineno, target, tuple(a.name for a in node.names)))
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name == top or a.name.startswith(top + "."):
                    out.append((node.lineno, a.name, ()))
    return out


def _modules(root: Path) -> dict[str, Path]:
    """Every module of the package by dotted name (a package by its own name, for its ``__init__``)."""
    out = {}
    for f in sorted(root.rglob("*.py")):
        name = _module_name(f, root)
        if _is_package(f):
            name = name[: -len(".__init__")]
        out[name] = f
    return out


def _resolve(target: str, names: tuple[str, ...], modules: dict[str, Path]) -> list[str]:
    """The modules an import reaches: ``from .cell import scene`` reaches ``cell.scene`` when that is a module."""
    out = []
    subs = [f"{target}.{n}" for n in names if f"{target}.{n}" in modules]
    if len(subs) < len(names) or not names:
        t = target
        while t and t not in modules:
            t = t.rpartition(".")[0]
        if t:
            out.append(t)
    return out + subs


def layer_violations(root: Path, layers: tuple[tuple[str, ...], ...] = LAYERS) -> list[str]:
    """Every import of a higher layer, as ``file:line imports target (dst is above src)``."""
    layer = {name: k for k, names in enumerate(layers) for name in names}
    top = root.name
    bad = []
    for f in sorted(root.rglob("*.py")):
        rel = f.relative_to(root).with_suffix("").parts
        src = rel[0] if rel != ("__init__",) else "__init__"
        if src not in layer:
            bad.append(f"{f.relative_to(root.parent)}: not in any layer (add it to LAYERS)")
            continue
        for line, target, _ in runtime_imports(f, root):
            parts = target.split(".")
            dst = parts[1] if len(parts) > 1 else "__init__"
            if parts[0] != top or dst not in layer:
                continue
            if layer[dst] > layer[src]:
                bad.append(f"{f.relative_to(root.parent)}:{line} imports {target} ({dst} is above {src})")
    return bad


def import_cycles(root: Path) -> list[list[str]]:
    """The strongly connected components of more than one module in the graph of runtime imports (Tarjan)."""
    modules = _modules(root)
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for m, f in modules.items():
        for _, target, names in runtime_imports(f, root):
            for dst in _resolve(target, names, modules):
                if dst != m:
                    graph[m].add(dst)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:  # iterative enough for this package's depth
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def private_imports(root: Path) -> list[str]:
    """Every ``from <another module of the package> import _name`` (a module's private name taken by another)."""
    modules = _modules(root)
    bad = []
    for m, f in modules.items():
        for line, target, names in runtime_imports(f, root) + _type_imports(f, root):
            for n in names:
                if n.startswith("_") and not n.startswith("__") and f"{target}.{n}" not in modules:
                    if target != m:
                        bad.append(f"{f.relative_to(root.parent)}:{line} takes {n} from {target}")
    return sorted(set(bad))


def _type_imports(path: Path, root: Path) -> list[tuple[int, str, tuple[str, ...]]]:
    """The imports under ``if TYPE_CHECKING:`` (a private name is private there too)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    me = _module_name(path, root)
    pkg = me.split(".")[:-1]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for sub in ast.walk(node):
                if isinstance(sub, ast.ImportFrom) and sub.level:
                    base = pkg[: len(pkg) - (sub.level - 1)] if sub.level > 1 else pkg
                    out.append((sub.lineno, ".".join(base + ([sub.module] if sub.module else [])),
                                tuple(a.name for a in sub.names)))  # fmt: skip
    return out


def long_modules(root: Path, limit: int = 1000) -> list[str]:
    """Modules over ``limit`` lines."""
    out = []
    for f in sorted(root.rglob("*.py")):
        n = len(f.read_text(encoding="utf-8").splitlines())
        if n > limit:
            out.append(f"{f.relative_to(root.parent)}: {n} lines")
    return out


# ---------------------------------------------------------------------------------------------- the package
def test_layers_import_only_downward() -> None:
    """No module imports a higher layer, at the top or inside a function (the order above, no exception)."""
    bad = layer_violations(ROOT)
    assert not bad, "\n".join(bad)


def test_the_layers_are_in_the_order_the_design_says() -> None:
    """model below cell below motion below viz below the facade below cli (issue 38: the order is the design)."""
    order = [name for names in LAYERS for name in names]
    chain = ["model", "cell", "motion", "viz", "robots", "cli"]
    assert [order.index(n) for n in chain] == sorted(order.index(n) for n in chain)
    assert {n for names in LAYERS for n in names} >= {p.name for p in ROOT.iterdir() if p.is_dir()
                                                     and (p / "__init__.py").is_file()}  # fmt: skip


def test_no_import_cycle() -> None:
    """No two modules of the package import each other, directly or around a circle (imports in functions too)."""
    cycles = import_cycles(ROOT)
    assert not cycles, "\n".join(" <-> ".join(c) for c in cycles)


def test_no_module_takes_another_modules_private_name() -> None:
    """``from .x import _name`` across modules is refused (ruff's PLC2701 does not see relative imports)."""
    bad = private_imports(ROOT)
    assert not bad, f"{len(bad)} private imports:\n" + "\n".join(bad)


def test_no_module_is_over_a_thousand_lines() -> None:
    assert not long_modules(ROOT), long_modules(ROOT)


# ---------------------------------------------------------------------------------------------- the rules fail
def _plant(tmp_path: Path, files: dict[str, str]) -> Path:
    root = tmp_path / "scara_pin"
    for rel, text in files.items():
        f = root / rel
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(text, encoding="utf-8")
    for d in [root, *[p for p in root.rglob("*") if p.is_dir()]]:
        (d / "__init__.py").touch()
    return root


def test_the_layer_rule_fails_on_a_planted_upward_import(tmp_path: Path) -> None:
    root = _plant(tmp_path, {"model.py": "def f():\n    from .motion import jump\n", "motion/jump.py": "X = 1\n"})
    bad = layer_violations(root)
    assert len(bad) == 1 and "model.py:2 imports scara_pin.motion" in bad[0], bad
    # under TYPE_CHECKING it names a type only: allowed
    root = _plant(tmp_path / "b", {"model.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
                                   "    from .motion import jump\n", "motion/jump.py": "X = 1\n"})  # fmt: skip
    assert layer_violations(root) == []


def test_the_cycle_rule_fails_on_a_planted_circle(tmp_path: Path) -> None:
    root = _plant(tmp_path, {"motion/a.py": "from .b import g\ndef f():\n    pass\n",
                             "motion/b.py": "def g():\n    from .a import f\n"})  # fmt: skip
    assert import_cycles(root) == [["scara_pin.motion.a", "scara_pin.motion.b"]]
    root = _plant(tmp_path / "b", {"motion/a.py": "from .b import g\n", "motion/b.py": "def g():\n    pass\n"})
    assert import_cycles(root) == []


def test_the_private_rule_fails_on_a_planted_private_import(tmp_path: Path) -> None:
    root = _plant(tmp_path, {"motion/a.py": "def f():\n    from .b import _g\n", "motion/b.py": "def _g():\n    pass\n",
                             "motion/c.py": "from . import _helpers\n", "motion/_helpers.py": "X = 1\n"})  # fmt: skip
    assert private_imports(root) == ["scara_pin/motion/a.py:2 takes _g from scara_pin.motion.b"]


def test_the_length_rule_fails_on_a_planted_long_module(tmp_path: Path) -> None:
    root = _plant(tmp_path, {"motion/a.py": "x = 1\n" * 1001})
    assert long_modules(root) == ["scara_pin/motion/a.py: 1001 lines"]


# ---------------------------------------------------------------------------------------------- the README, the picture
def _layer_tables() -> tuple[list[tuple[str, list[str]]], list[tuple[str, list[str]]]]:
    """(the layers of the tree, regenerated from LAYERS and the source; the layers the README's section lists)."""
    import layers

    readme = (REPO / "README.md").read_text(encoding="utf-8")
    return layers.structure(layers.table(LAYERS, ROOT)), layers.readme_layers(readme)


def test_the_readme_lists_the_layers_and_the_modules_of_the_tree() -> None:
    """README's "Architecture" table: every layer present, lowest first, with exactly its modules and packages."""
    tree, readme = _layer_tables()
    assert readme == tree
    assert len(tree) >= 10 and ("model", ["model.py", "chain.py", "ik_results.py"]) in tree


def test_the_layers_picture_is_the_trees(tmp_path: Path) -> None:
    """docs/layers.png carries the table it was drawn from (its metadata): the same layers and names as the tree.

    The picture is regenerated into tmp_path by the script and both tables compared (the line counts are left
    out: they change with every edit; `python tools/layers.py` redraws the committed one).
    """
    import layers

    rows = layers.table(LAYERS, ROOT)
    layers.draw(rows, tmp_path / "layers.png")
    fresh = layers.structure(layers.picture_table(tmp_path / "layers.png"))
    committed = layers.structure(layers.picture_table(REPO / "docs" / "layers.png"))
    assert fresh == layers.structure(rows)
    assert committed == fresh, "docs/layers.png is out of date: run python tools/layers.py"


def test_the_readme_check_fails_on_a_new_package_without_its_line(tmp_path: Path) -> None:
    """A package added to a layer (and to the tree) but not to the README is a difference; one in no layer, refused."""
    import layers

    tree, readme = _layer_tables()
    files = {f"{name}/__init__.py" if name.endswith("/") else name: "" for _, names in tree for name in names}
    root = _plant(tmp_path, {**files, "newpkg/a.py": "X = 1\n"})
    plus = tuple((*layer, "newpkg") if layer[0] == "viz" else layer for layer in LAYERS)
    grown = layers.structure(layers.table(plus, root))
    listed = {name for _, names in readme for name in names}
    assert grown != readme and [name for _, names in grown for name in names if name not in listed] == ["newpkg/"]
    with pytest.raises(ValueError, match="newpkg"):
        layers.table(LAYERS, root)
    section = "# x\n\n## Architecture\n\n| layer | names | what |\n|---|---|---|\n| 1 a | `m.py`, `p/` | the `w` |\n"
    assert layers.readme_layers(section) == [("a", ["m.py", "p/"])]
