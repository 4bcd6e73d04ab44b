"""The code's shape, checked: no import circle among bridge's modules (imports inside functions count), no
private name of bridge used by a tool or a test, and a turbulence model advanced in one place only."""

from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def _modules(root: Path) -> dict[str, Path]:
    out = {}
    for path in (root / "bridge").rglob("*.py"):
        parts = path.relative_to(root).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def _type_checking_only(tree: ast.AST) -> set[int]:
    """ids of the import nodes under ``if TYPE_CHECKING:`` (types only: never run)."""
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            skip |= {id(n) for stmt in node.body for n in ast.walk(stmt)}
    return skip


def import_graph(root: Path = REPO) -> dict[str, set[str]]:
    """module -> the bridge modules it imports anywhere (module level or inside functions); importing
    ``a.b.c`` also imports the packages ``a.b`` and ``a`` (their ``__init__``)."""
    mods = _modules(root)
    edges: dict[str, set[str]] = {m: set() for m in mods}
    for mod, path in mods.items():
        tree = ast.parse(path.read_text())
        skip = _type_checking_only(tree)
        package = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            targets = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                    base = ".".join(up + ([node.module] if node.module else []))
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names]
            for t in targets:
                while t and t not in mods:
                    t = t.rpartition(".")[0]
                if not t.startswith("bridge"):
                    continue
                parts = t.split(".")
                for i in range(1, len(parts) + 1):
                    dep = ".".join(parts[:i])
                    if dep in mods and dep != mod and not mod.startswith(dep + "."):
                        edges[mod].add(dep)
    return edges


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
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

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def private_uses(path: Path) -> list[str]:
    """``from bridge... import _name`` and ``module._name`` (a bridge module imported under a name) in a file."""
    tree = ast.parse(path.read_text())
    found, modules, known = [], set(), _modules(REPO)
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "bridge":
            for a in node.names:
                if a.name.startswith("_") and not a.name.startswith("__"):
                    found.append(f"line {node.lineno}: from {node.module} import {a.name}")
                elif f"{node.module}.{a.name}" in known:
                    modules.add(a.asname or a.name)
        elif isinstance(node, ast.Import):
            modules |= {a.asname or a.name.split(".")[0] for a in node.names if a.name.split(".")[0] == "bridge"}
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
            base = node.value
            while isinstance(base, ast.Attribute):
                base = base.value
            if isinstance(base, ast.Name) and base.id in modules:
                found.append(f"line {node.lineno}: {ast.unparse(node)}")
        if isinstance(node, ast.Call) and ast.unparse(node.func).endswith("setattr") and len(node.args) >= 2:
            name = node.args[1]
            if isinstance(name, ast.Constant) and isinstance(name.value, str) and name.value.startswith("_") \
                    and not name.value.startswith("__"):
                found.append(f"line {node.lineno}: {ast.unparse(node)}")
    return found


def test_no_import_circle_among_bridges_modules():
    assert cycles(import_graph()) == []


def test_the_cycle_finder_finds_a_circle_through_a_function_level_import(tmp_path):
    pkg = tmp_path / "bridge"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from . import b\n")
    (pkg / "b.py").write_text("def f():\n    from .a import x\n")
    (pkg / "c.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .a import y\n")
    assert cycles(import_graph(tmp_path)) == [["bridge.a", "bridge.b"]]


def test_no_tool_or_test_uses_a_private_name_of_bridge():
    files = sorted((REPO / "tools").glob("*.py")) + sorted((REPO / "tests").rglob("*.py"))
    bad = {str(f.relative_to(REPO)): uses for f in files if (uses := private_uses(f))}
    assert bad == {}


def test_the_private_name_finder_sees_each_way_of_reaching_one(tmp_path):
    f = tmp_path / "t.py"
    f.write_text("from bridge.aero.stage import _hidden, run\nfrom bridge import cache\nimport bridge.cfd\n"
                 "cache._code\nbridge.cfd._grid\nmonkeypatch.setattr(cache, '_x', 1)\nrun._ok_not_a_module\n")
    assert len(private_uses(f)) == 4


def test_a_turbulence_model_is_advanced_in_one_place():
    """Only the flows' shared step (bridge/cfd/flow.py) calls a model's ``advance``; a model's own internals
    advance its transported scalars (``advance_pair``), never another model."""
    calls = []
    for path in (REPO / "bridge").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "advance":
                calls.append(f"{path.relative_to(REPO)}: {ast.unparse(node.func)}")
    assert calls == ["bridge/cfd/flow.py: self.turbulence.advance"]
