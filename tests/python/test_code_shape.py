"""The code's shape, read from the source as a new maintainer would (issue 31): no file outside the
tests over 500 lines (python/kincal, cpp/, benchmarks' own sources), no function over 100 lines
(Python: every def, methods and nested ones included, from its `def` line to its last; C++: every
function defined at namespace level, from the line its declaration starts on to its closing brace at
column 0, the style every file here follows; a lambda counts with its enclosing function, and member
functions defined inside a class or struct body are not measured); and no effect named in code
outside its own file and the registry (issue 31: the code asks an effect's kind)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MAX_FILE, MAX_FUNCTION = 500, 100


def _sources() -> list[Path]:
    files = list((ROOT / "python" / "kincal").rglob("*.py"))
    for ext in ("*.cpp", "*.hpp"):
        files += (ROOT / "cpp").rglob(ext)
        files += [p for p in (ROOT / "benchmarks").rglob(ext) if "third_party" not in p.parts]
    return sorted(files)


def _python_functions(path: Path) -> list[tuple[str, int, int]]:
    tree = ast.parse(path.read_text())
    return [(n.name, n.lineno, (n.end_lineno or n.lineno) - n.lineno + 1) for n in ast.walk(tree)
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]


_NOT_A_FUNCTION = re.compile(r"^(//|#|namespace\b|}|using\b|template\b|struct\b|class\b|enum\b|typedef\b|extern\b)")


def cpp_functions(text: str) -> list[tuple[str, int, int]]:
    """(first line of the declaration, its line, length in lines) of every function defined at namespace
    level: a line at column 0 with a '(' whose body opens at the end of it or of one of the next lines and
    closes with a '}' alone at column 0. A body that closes on its opening line is one line."""
    lines = text.split("\n")
    out = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if line and not line[0].isspace() and "(" in line and not _NOT_A_FUNCTION.match(line):
            j = i
            while j < len(lines) and not lines[j].rstrip().endswith(("{", ";")) and not lines[j].rstrip().endswith("}"):
                j += 1
            if j < len(lines) and lines[j].rstrip().endswith("{"):
                k = j + 1
                while k < len(lines) and lines[k] != "}":
                    k += 1
                out.append((line.strip(), i + 1, k - i + 1))
                i = k
        i += 1
    return out


def test_the_counter_of_cpp_functions_counts_what_it_should():
    text = ("namespace {\n\nint one(int a) { return a; }\n\nvoid two(int a,\n         int b) {\n  if (a) {\n"
            "    b = 1;\n  }\n}\n\n}  // namespace\n\nstruct S {\n  int f() {\n    return 1;\n  }\n};\n"
            "double three() {\n  return 3;\n}\n")
    assert [(name.split("(")[0], line, n) for name, line, n in cpp_functions(text)] == [
        ("void two", 5, 6), ("double three", 19, 3)]


def test_no_file_outside_the_tests_over_500_lines():
    long = [(str(p.relative_to(ROOT)), n) for p in _sources() if (n := len(p.read_text().splitlines())) > MAX_FILE]
    assert not long, long


def test_no_function_over_100_lines():
    long = []
    for p in _sources():
        funcs = _python_functions(p) if p.suffix == ".py" else cpp_functions(p.read_text())
        long += [(str(p.relative_to(ROOT)), name[:60], line, n) for name, line, n in funcs if n > MAX_FUNCTION]
    assert not long, long


def _effect_names() -> set[str]:
    import kincal

    return {k.name for k in kincal._core.effect_kinds()}


def _compared_names(tree: ast.AST, names: set[str]) -> list[tuple[int, str]]:
    """(line, name) of every comparison (==, !=, in, not in) of a value with an effect's name written
    as a string, alone or in a tuple, list or set."""
    out = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Compare):
            continue
        if not any(isinstance(op, (ast.Eq, ast.NotEq, ast.In, ast.NotIn)) for op in node.ops):
            continue
        for operand in [node.left, *node.comparators]:
            items = operand.elts if isinstance(operand, (ast.Tuple, ast.List, ast.Set)) else [operand]
            out += [(node.lineno, i.value) for i in items
                    if isinstance(i, ast.Constant) and isinstance(i.value, str) and i.value in names]
    return out


def test_the_comparison_finder_finds_names_in_every_form():
    tree = ast.parse('a == "backlash"\nif "drift" != b: pass\nc in ("x", "joint_map")\nd == "other"\n')
    assert _compared_names(tree, {"backlash", "drift", "joint_map"}) == [(1, "backlash"), (2, "drift"),
                                                                         (3, "joint_map")]


def test_no_effect_is_compared_by_its_name_outside_the_registry():
    """Python asks an effect's kind (Effect.kind, effect_kind(name): gravity_loaded_only, harmonic,
    ordered, needs, reads_dir, of_instrument), and C++ its id, never its name: adding an effect touches
    its own file and the registry line only (README, "Adding an effect")."""
    names = _effect_names()
    offences = []
    for path in (ROOT / "python" / "kincal").rglob("*.py"):
        offences += [f"{path.relative_to(ROOT)}:{line}: {name}" for line, name in
                     _compared_names(ast.parse(path.read_text()), names)]
    quoted = "|".join(re.escape(n) for n in sorted(names))
    pattern = re.compile(rf'(==|!=)\s*"({quoted})"|"({quoted})"\s*(==|!=)')
    for path in (ROOT / "cpp").rglob("*.[ch]pp"):
        if path.parent.name == "effects":  # the effects' own files and the registry
            continue
        for k, line in enumerate(path.read_text().split("\n"), 1):
            if pattern.search(line):
                offences.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
    assert not offences, "effects compared by name:\n" + "\n".join(offences)
