"""The package's array types, for annotations (``mypy --strict``).

Modules import these under ``if TYPE_CHECKING:`` (with ``from __future__ import annotations`` every
annotation stays a string): the import graph (tests/python/test_package_graph.py) has no edge to this
module, so the foundations (io, stats, report) keep importing nothing above them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: float arrays: joint angles, poses, points, residuals, Jacobians
FloatArray = NDArray[np.float64]
#: boolean masks of rows (folds, splits)
BoolArray = NDArray[np.bool_]
#: integer codes and indices (configurations, folds, lines)
IntArray = NDArray[np.int64]
