"""CSV text as the contract writes it (comma separated, one header row, floats in full precision),
and the header and extra columns of a CSV file as they are."""

from __future__ import annotations

import csv
from typing import Any, Iterable, Sequence

import numpy as np


def format_rows(header: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    """One header row and the rows: texts as they are, integers as integers, every other number in
    full precision (repr of a float)."""
    out = [",".join(header)]
    for r in rows:
        out.append(",".join(v if isinstance(v, str) else (str(v) if isinstance(v, (int, np.integer)) else repr(float(v)))
                            for v in r))
    return "\n".join(out) + "\n"


def header(path: str) -> list[str]:
    """The column names of a CSV file (stripped; empty for an empty file)."""
    with open(path, newline="", encoding="utf-8-sig") as f:  # a leading BOM (Excel) is no part of a name
        return [h.strip() for h in next(csv.reader(f), [])]


def text_columns(path: str, names: Sequence[str]) -> dict[str, list[str]]:
    """The columns of ``names`` a CSV has (e.g. pose, target), as texts row by row (blank lines
    skipped); the names it lacks are left out."""
    with open(path, newline="", encoding="utf-8-sig") as f:  # a leading BOM (Excel) is no part of a name
        rows = [r for r in csv.reader(f) if any(c.strip() for c in r)]
    if not rows:
        return {}
    head = [h.strip() for h in rows[0]]
    return {n: [r[head.index(n)].strip() for r in rows[1:]] for n in names if n in head}
