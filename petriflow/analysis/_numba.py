"""The compiler of the analysis kernels: ``numba.njit``, or nothing where numba is missing.

numba's on-disk cache is keyed by source file but re-imports the module by name when it
loads, so only a module imported under its installed name caches its compiled loops
(see :mod:`petriflow.analysis._kernel`).
"""

from __future__ import annotations

from typing import Callable

__all__ = ["njit"]


def njit(module: str) -> Callable:
    """The decorator that compiles the loops of ``module`` (its ``__name__``): numba's,
    cached on disk when ``module`` is the installed name, or the function unchanged
    (plain Python, the same results) without numba."""
    try:
        import numba
    except ImportError:  # pragma: no cover - exercised only where numba is missing
        return lambda function: function
    return numba.njit(cache=module.startswith("petriflow.analysis."), nogil=True)
