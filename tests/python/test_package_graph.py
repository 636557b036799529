"""The Python package's import graph, read from the source (python/kincal): no import cycle between
modules, none between the packages (calibration, diagnose, programs, standards, fivebar, report, io,
stats, cli, demo and the package's own __init__), and the layers the README's layout states. Every
import counts, those inside functions too; only `if TYPE_CHECKING:` blocks are skipped (they never
run). The old flat names (kincal.identify, ...) still reach the moved modules, with a warning."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

import kincal

ROOT = Path(__file__).resolve().parents[2] / "python" / "kincal"


def _modules() -> dict:
    out = {}
    for p in ROOT.rglob("*.py"):
        parts = ["kincal", *p.relative_to(ROOT).with_suffix("").parts]
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = p
    return out


def _module_names() -> set:
    """Every module of the package: its Python files and the compiled core (_core.pyi describes it)."""
    return set(_modules()) | {"kincal._core"}


def _type_checking_lines(tree: ast.AST) -> set:
    lines: set = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for sub in node.body:
                lines.update(range(sub.lineno, (sub.end_lineno or sub.lineno) + 1))
    return lines


def _graph() -> dict:
    """module -> the kincal modules it imports (a name of a package that is no module: the package)."""
    files = _modules()
    mods = _module_names()
    edges: dict = {m: set() for m in mods}
    for m, path in files.items():
        tree = ast.parse(path.read_text())
        skip = _type_checking_lines(tree)
        package = m if path.name == "__init__.py" else m.rpartition(".")[0]
        for node in ast.walk(tree):
            if getattr(node, "lineno", None) in skip:
                continue
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[: len(package.split(".")) - node.level + 1]
                    src = ".".join(base + ([node.module] if node.module else []))
                else:
                    src = node.module or ""
                targets = [f"{src}.{a.name}" if f"{src}.{a.name}" in mods else src for a in node.names]
            else:
                continue
            edges[m].update(t for t in targets if t in mods and t != m)
    return edges


def _cycles(edges: dict) -> list:
    """The strongly connected components with more than one node (Tarjan)."""
    index: dict = {}
    low: dict = {}
    stack: list = []
    on: set = set()
    out: list = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
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


def _package(module: str) -> str:
    parts = module.split(".")
    if module in ("kincal._core", "kincal.__main__"):  # the compiled core; `python -m kincal`, the command's door
        return module.split(".")[1]
    return parts[1] if len(parts) > 2 or (len(parts) == 2 and (ROOT / parts[1]).is_dir()) else "kincal"


def test_no_import_cycle_between_modules():
    edges = _graph()
    assert len(edges) > 40 and sum(len(v) for v in edges.values()) > 100  # the graph was read
    assert _cycles(edges) == []


def test_no_import_cycle_between_packages_and_the_layers_hold():
    pkg: dict = {}
    for m, targets in _graph().items():
        for t in targets:
            if _package(t) != _package(m):
                pkg.setdefault(_package(m), set()).add(_package(t))
    assert _cycles(pkg) == []
    # the foundations import no layer above them; nothing imports the command line or the demo
    for low in ("io", "stats", "report"):
        assert pkg.get(low, set()) <= {"_core", "io"}, (low, pkg.get(low))
    assert pkg.get("calibration", set()) <= {"_core", "kincal", "io", "stats"}, pkg.get("calibration")
    assert not any("cli" in v for k, v in pkg.items() if k not in ("cli", "__main__"))
    assert not any("demo" in v for k, v in pkg.items() if k not in ("cli", "demo"))


@pytest.mark.parametrize("old", sorted(kincal.MOVED))
def test_old_flat_names_reach_the_moved_modules(old):
    with pytest.warns(DeprecationWarning, match=f"kincal.{old} is now kincal.{kincal.MOVED[old]}"):
        mod = getattr(kincal, old)
    assert mod is importlib.import_module(f"kincal.{kincal.MOVED[old]}")
