"""Type aliases shared by the annotations of the package's modules."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeAlias

import numpy as np

ArrayLike: TypeAlias = Sequence[float] | np.ndarray
"""Numbers given as a sequence of floats or a NumPy array (narrower than ``numpy.typing.ArrayLike``)."""
