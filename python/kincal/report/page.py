"""The HTML report pages of kincal (`kincal diagnose`, its five-bar form, `kincal demo`): one page
skeleton with one stylesheet, tables, and figures (PNG files beside the page, embedded by
reference). Every page sets ``data-images-loaded="loaded/total"`` on its body once the browser has
loaded it, so a headless browser can check that every figure shows."""

from __future__ import annotations

import contextlib
import html
import os
import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Iterator, Sequence, Union

from .. import _core

if TYPE_CHECKING:
    from matplotlib.colors import LogNorm

STYLE = """body{font-family:sans-serif;max-width:980px;margin:2em auto;color:#222;line-height:1.4}
table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #ccc;padding:3px 8px}
table.num td,table.num th{text-align:right}
table.lab td:first-child{text-align:left}
img{max-width:100%}code{background:#f3f3f3}"""

# counts the figures that loaded (checked by the demo test in a headless browser)
_IMAGES_LOADED = """window.addEventListener("load", () => { const i = [...document.images];
document.body.setAttribute("data-images-loaded", i.filter(x => x.complete && x.naturalWidth > 0).length + "/" + i.length);
});"""


def esc(text: Any) -> str:
    """Text (any value, by str) escaped for HTML."""
    return html.escape(str(text))


def page(title: str, body: str) -> str:
    """A whole HTML page: ``title`` in the head, ``body`` (HTML) as it is."""
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{esc(title)}</title>
<style>{STYLE}</style>
<script>{_IMAGES_LOADED}</script></head><body>
{body.rstrip()}
</body></html>
"""


def table(header: Sequence[Any], rows: Iterable[Sequence[Any]], numeric: bool = False, labelled: bool = False,
          text: Sequence[int] = ()) -> str:
    """A table of escaped cells; ``numeric``: the cells right-aligned (columns of numbers);
    ``labelled``: with ``numeric``, the first column (the rows' names) left-aligned; ``text``: with
    ``numeric``, these columns (0-based) left-aligned too (names among numbers)."""
    left = ' style="text-align:left"'
    h = "".join(f"<th{left if k in text else ''}>{esc(x)}</th>" for k, x in enumerate(header))
    b = "".join("<tr>" + "".join(f"<td{left if k in text else ''}>{esc(x)}</td>" for k, x in enumerate(r)) + "</tr>"
                for r in rows)
    cls = (' class="num lab"' if labelled else ' class="num"') if numeric else ""
    return f"<table{cls}><tr>{h}</tr>{b}</table>"


def error_norm(values: Any) -> LogNorm:
    """The colour scale of error maps drawn side by side (before and after a calibration or a
    diagnosis): logarithmic and shared, so a map of microns beside one of millimetres is neither
    one colour nor misread as the same size; from the largest finite value down to the smallest
    positive one, but no lower than a thousandth of the largest."""
    from matplotlib.colors import LogNorm
    import numpy as np
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    hi = float(np.max(v)) if v.size and np.max(v) > 0 else 1.0
    pos = v[v > 0]
    # a value at or below the bottom (an error of exactly 0 too) is drawn in the bottom colour
    return LogNorm(vmin=max(float(np.min(pos)) if pos.size else hi, hi * 1e-3), vmax=hi, clip=True)


def figure(src: str, alt: str) -> str:
    """A figure: the image file ``src`` (relative to the page)."""
    return f'<figure><img src="{esc(src)}" alt="{esc(alt)}"></figure>'


def write(path: Union[str, Path], title: str, body: str) -> None:
    """The page written atomically to ``path``."""
    _core.write_file_atomic(str(path), page(title, body))


def check_folder(out: Union[str, Path]) -> None:
    """An error, before any work, when ``out`` cannot be an output folder (a file stands there)."""
    if Path(out).exists() and not Path(out).is_dir():
        raise ValueError(f"{out}: is a file, not a folder (the output folder's name is taken; nothing was written)")


@contextlib.contextmanager
def staged_folder(out: Union[str, Path], owned: Sequence[str] = ()) -> Iterator[Path]:
    """A folder of outputs written whole or not at all: the files go into a hidden folder inside
    ``out`` (created; the same file system, so moving them is a rename), and only once every one is
    written (and none of their names is taken by a folder in ``out``) are they moved into ``out``.
    On any error ``out`` is left as it was (removed again if this call created it). ``owned``: glob
    patterns of the files this tool writes a varying number of (step3.png): those of an earlier run
    that this one did not write are removed, so the folder shows one run."""
    folder = Path(out)
    check_folder(folder)
    created = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=".kincal-staging.", dir=folder))
    done = False
    try:
        yield stage
        names = sorted(p.name for p in stage.iterdir())
        taken = [n for n in names if (folder / n).is_dir()]
        if taken:
            raise ValueError(f"{folder / taken[0]} is a folder: it is in the way of the file of that name "
                             "(nothing was written)")
        for n in names:
            os.replace(stage / n, folder / n)
        for pattern in owned:
            for old in folder.glob(pattern):
                if old.is_file() and old.name not in names:
                    old.unlink()
        done = True
    finally:
        shutil.rmtree(stage, ignore_errors=True)
        if created and not done:
            shutil.rmtree(folder, ignore_errors=True)
