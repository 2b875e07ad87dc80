"""Input checks of the Python layer: every value is checked here, with a ValueError naming
it, before it reaches the extension (which checks again)."""

from __future__ import annotations

import math
import numbers
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

#: The most samples, events or parameter values one call returns (as in the extension).
MAX_OUTPUT = 100_000_000

ArrayLike = Union[Sequence[float], npt.NDArray[np.float64]]


def number(name: str, value: Any) -> float:
    """A finite real number."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number (got {type(value).__name__})")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite (got {v})")
    return v


def positive(name: str, value: Any) -> float:
    """A finite number > 0."""
    v = number(name, value)
    if not v > 0.0:
        raise ValueError(f"{name} must be > 0 (got {v})")
    return v


def integer(name: str, value: Any, lo: int = 0, hi: int = 2**32 - 1) -> int:
    """An integer in [lo, hi]."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer (got {type(value).__name__})")
    v = int(value)
    if not lo <= v <= hi:
        raise ValueError(f"{name} must be in [{lo}, {hi}] (got {v})")
    return v


def floats(name: str, value: Any) -> npt.NDArray[np.float64]:
    """The numbers of ``value`` as a float array of any shape. Text is refused, not read as
    a number (numpy would take ``"0"`` for ``0.0``), and so are objects that are not
    numbers."""
    try:
        raw = value if isinstance(value, np.ndarray) else np.asarray(value)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name} must hold numbers: {e}") from None
    if raw.dtype.kind not in "biuf":
        raise TypeError(f"{name} must hold numbers (got entries of type {raw.dtype})")
    return raw.astype(np.float64, copy=False)


def vector(name: str, value: Any, n: Optional[int] = None) -> list[float]:
    """A 1-D vector of finite floats (of length n if given)."""
    a = floats(name, value)
    if a.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional (got shape {a.shape})")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name} has {a.shape[0]} components; the system's state has {n}")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"{name}[{i}] = {a[i]} is not finite")
    return [float(x) for x in a]


def array(name: str, value: Any, max_len: int = MAX_OUTPUT) -> npt.NDArray[np.float64]:
    """A contiguous 1-D float array of finite values."""
    if isinstance(value, np.ndarray) and value.size > max_len:
        # Refused before the copy: a broadcast view can stand for more memory than exists.
        raise ValueError(f"{name} has {value.size} values; at most {max_len}")
    a = np.ascontiguousarray(floats(name, value))
    if a.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional (got shape {a.shape})")
    if a.shape[0] > max_len:
        raise ValueError(f"{name} has {a.shape[0]} values; at most {max_len}")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"{name}[{i}] = {a[i]} is not finite")
    return a


def tolerances(rtol: Any, atol: Any, n: int) -> tuple[float, Optional[list[float]]]:
    """rtol in (0, 1); atol None, a number (every component) or one per component, > 0."""
    r = positive("rtol", rtol)
    if r >= 1.0:
        raise ValueError(f"rtol must be < 1 (got {r})")
    if atol is None:
        return r, None
    if isinstance(atol, numbers.Real) and not isinstance(atol, bool):
        a = [positive("atol", atol)] * n
    else:
        a = vector("atol", atol, n)
        for i, x in enumerate(a):
            if not x > 0.0:
                raise ValueError(f"atol[{i}] must be > 0 (got {x})")
    return r, a
