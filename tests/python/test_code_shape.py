"""The code's shape, read from the source as a new maintainer would (issue 31): no file outside the
tests over 500 lines (python/kincal, cpp/, benchmarks' own sources), no function over 100 lines
(Python: every def, methods and nested ones included, from its `def` line to its last; C++: every
function defined at namespace level, from the line its declaration starts on to its closing brace at
column 0, the style every file here follows; a lambda counts with its enclosing function, and member
functions defined inside a class or struct body are not measured)."""

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
