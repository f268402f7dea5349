"""Resource limits: refuse a run that cannot fit, before allocating it.

Every entry point that allocates in proportion to its input (samples,
designs, refinements) estimates the bytes first and calls `check_memory`.
The limit is half of the machine's physical memory, or the value of the
environment variable ``QC_CONTROL_MAX_MEMORY`` (bytes, or with a suffix
``K``, ``M``, ``G``, ``T``: ``"12G"``), read at each call so that it can
be raised for one run.
"""

from __future__ import annotations

import functools
import os

try:
    import psutil
except ImportError:  # pragma: no cover - a dependency, but see _physical_memory
    psutil = None

__all__ = ["ResourceLimitError", "memory_limit", "check_memory", "format_bytes", "ENV_VAR"]

#: The environment variable that sets the memory limit.
ENV_VAR = "QC_CONTROL_MAX_MEMORY"
_SUFFIX = {"": 1, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}


class ResourceLimitError(ValueError):
    """A run would need more memory than the limit allows (nothing was allocated)."""


def format_bytes(n: float) -> str:
    """``1.5 GiB``-style text for a byte count."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} TiB"  # pragma: no cover


def _physical_memory() -> int | None:
    """The machine's physical memory in bytes (None where it cannot be read).

    psutil reads it on Linux, macOS and Windows alike; where psutil cannot
    be imported (its Linux backend needs the POSIX-only ``resource``),
    ``os.sysconf`` gives it on POSIX systems.
    """
    if psutil is not None:
        try:
            return int(psutil.virtual_memory().total)
        except (OSError, RuntimeError):  # pragma: no cover - a platform psutil cannot read
            pass
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - neither
        return None


def memory_limit() -> tuple[int, str]:
    """The limit in bytes, and where it comes from (for error messages)."""
    text = os.environ.get(ENV_VAR, "").strip().upper().removesuffix("B").removesuffix("I")
    if text:
        suffix = text[-1] if text[-1] in _SUFFIX else ""
        try:
            value = float(text[: len(text) - len(suffix)]) * _SUFFIX[suffix]
        except ValueError:
            raise ResourceLimitError(
                f"{ENV_VAR}={os.environ[ENV_VAR]!r} is not a size; use bytes or e.g. '12G'"
            ) from None
        return int(value), f"{ENV_VAR}={os.environ[ENV_VAR]}"
    return _default_limit()


@functools.lru_cache(maxsize=1)
def _default_limit() -> tuple[int, str]:
    """Half the physical memory (read once: it does not change while we run)."""
    total = _physical_memory()
    if total is None:  # pragma: no cover
        return 2**63, "no limit known"
    return total // 2, f"half of this machine's {format_bytes(total)}"


def check_memory(nbytes: float, what: str, advice: str = "") -> None:
    """Raise `ResourceLimitError` if ``nbytes`` exceed the limit.

    Parameters
    ----------
    nbytes : float
        The estimated peak allocation.
    what : str
        The run, for the message ("an RK4 response of 100,000,001 samples").
    advice : str, optional
        How to make the run smaller ("use fewer samples").
    """
    limit, source = memory_limit()
    if nbytes > limit:
        raise ResourceLimitError(
            f"{what} needs about {format_bytes(nbytes)} of memory, more than the limit of "
            f"{format_bytes(limit)} ({source}); "
            + (f"{advice}, or " if advice else "")
            + f"set {ENV_VAR} to raise the limit"
        )
