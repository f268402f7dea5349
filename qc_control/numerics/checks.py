"""The one set of input checks: each refusal is a `ParameterError` naming the value.

Every parameter class, road kind, study and command-line option checks its
numbers here, so a bad value is refused in the same words wherever it is
given, and a caller (the command line, a TOML loader) reads *which*
parameter was wrong from the error's ``.name`` instead of parsing its text.

A parameter dataclass declares each field once, as a `Field` (what it is,
its SI unit, the range it must lie in), and validates from that declaration
with `check_fields`.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

__all__ = [
    "Field",
    "ParameterError",
    "check_fields",
    "instance_from",
    "blamed_field",
    "choice",
    "finite",
    "integer",
    "nonnegative",
    "number",
    "positive",
]


class ParameterError(ValueError):
    """A parameter's value is not one it may take.

    A `ValueError`, so code that catches those catches this too.

    Attributes
    ----------
    name : str
        The parameter, as the user spelled it (``"ks"``, ``"road.height"``).
    value : object
        The value given.
    expected : str
        What the value must be (``"a finite number > 0 N/m"``).
    """

    def __init__(
        self, name: str, value: Any, expected: str, *, description: str = "", message: str = ""
    ):
        self.name = name
        self.value = value
        self.expected = expected
        self.description = description
        what = f"{name} ({description})" if description else name
        # ``message`` words a refusal in its domain's terms ("unknown method
        # 'rk5'; known methods are ..."); it still names the value and what
        # was expected, and ``.name``/``.value`` say the same to a program
        super().__init__(message or f"{what} must be {expected}, got {value!r}")

    def __reduce__(self):  # errors cross process boundaries in sweeps
        return (_rebuild, (self.name, self.value, self.expected, self.description, str(self)))


def _rebuild(name, value, expected, description, message="") -> ParameterError:
    return ParameterError(name, value, expected, description=description, message=message)


def _real(value) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_)
    )


def _with_unit(text: str, unit: str) -> str:
    return f"{text} {unit}" if unit else text


def number(
    name: str,
    value,
    unit: str = "",
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
    allow_inf: bool = False,
    description: str = "",
) -> float:
    """``value`` as a float, refused unless a real number in ``[low, high]``.

    Parameters
    ----------
    name, unit, description : str
        How the error names the parameter and its SI unit.
    low, high : float, optional
        The bounds; ``low_open``/``high_open`` exclude them.
    allow_inf : bool
        Whether ``±inf`` is a value (a limit that is "none").
    """
    if low is None and high is None:
        want = "a number" if allow_inf else "a finite number"
    elif high is None:
        want = f"a {'' if allow_inf else 'finite '}number {'>' if low_open else '>='} {low:g}"
    elif low is None:
        want = f"a {'' if allow_inf else 'finite '}number {'<' if high_open else '<='} {high:g}"
    else:
        lo = "(" if low_open else "["
        hi = ")" if high_open else "]"
        want = f"a number in {lo}{low:g}, {high:g}{hi}"
    expected = _with_unit(want, unit)
    if not _real(value):
        raise ParameterError(name, value, expected, description=description)
    v = float(value)
    if math.isnan(v) or (math.isinf(v) and not allow_inf):
        raise ParameterError(name, value, expected, description=description)
    if low is not None and (v < low or (low_open and v == low)):
        raise ParameterError(name, value, expected, description=description)
    if high is not None and (v > high or (high_open and v == high)):
        raise ParameterError(name, value, expected, description=description)
    return v


def finite(name: str, value, unit: str = "", *, description: str = "") -> float:
    """A finite real number."""
    return number(name, value, unit, description=description)


def positive(
    name: str, value, unit: str = "", *, allow_inf: bool = False, description: str = ""
) -> float:
    """A real number > 0 (finite unless ``allow_inf``)."""
    return number(
        name, value, unit, low=0.0, low_open=True, allow_inf=allow_inf, description=description
    )


def nonnegative(
    name: str, value, unit: str = "", *, allow_inf: bool = False, description: str = ""
) -> float:
    """A real number >= 0 (finite unless ``allow_inf``)."""
    return number(name, value, unit, low=0.0, allow_inf=allow_inf, description=description)


def integer(name: str, value, *, minimum: int | None = None, maximum: int | None = None) -> int:
    """A whole number (``int`` or a NumPy integer, not a bool or a float)."""
    bounds = [] if minimum is None else [f">= {minimum}"]
    bounds += [] if maximum is None else [f"<= {maximum}"]
    expected = "a whole number" + (" " + " and ".join(bounds) if bounds else "")
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise ParameterError(name, value, expected)
    v = int(value)
    if (minimum is not None and v < minimum) or (maximum is not None and v > maximum):
        raise ParameterError(name, value, expected)
    return v


def choice(name: str, value, options: Iterable[Any]) -> Any:
    """One of ``options`` (compared by equality), returned as given."""
    options = tuple(options)
    try:
        if value in options:
            return value
    except TypeError:  # an unhashable or uncomparable value is simply not an option
        pass
    listed = ", ".join(repr(o) for o in options)
    raise ParameterError(name, value, f"one of {listed}")


#: How a `Field`'s kind bounds its value from below: ``(low, low_open)``.
_KINDS: dict[str, tuple[float | None, bool]] = {
    "positive": (0.0, True),
    "nonneg": (0.0, False),
    "finite": (None, False),
}


@dataclasses.dataclass(frozen=True)
class Field:
    """One parameter's declaration: what it is, its SI unit, its range.

    ``kind`` is ``"positive"`` (> 0), ``"nonneg"`` (>= 0) or ``"finite"``
    (any finite number, or from ``low``: a lower bound other than 0, as a
    growth factor's > 1); ``high`` adds an upper bound (a ratio in (0, 1]),
    ``low_open``/``high_open`` exclude the bounds, ``allow_inf`` lets the
    value be infinite (a clearance or a knee that is "none"). ``optional``
    lets the value be None (derived later, as ``zeta`` from ``cs``).

    Examples
    --------
    >>> Field("growth factor", "", "finite", low=1.0, low_open=True).check("max_factor", 10)
    10.0
    """

    description: str
    unit: str
    kind: str = "positive"
    optional: bool = False
    high: float | None = None
    high_open: bool = False
    allow_inf: bool = False
    low: float | None = None
    low_open: bool = False

    def __post_init__(self):
        choice("kind", self.kind, _KINDS)
        if self.low is not None and self.kind != "finite":
            raise ParameterError(
                "low", self.low, f"None with kind {self.kind!r}, whose lower bound is 0"
            )

    @property
    def bounds(self) -> dict[str, Any]:
        """The keyword arguments of `number` that enforce this declaration."""
        low, low_open = (self.low, self.low_open) if self.low is not None else _KINDS[self.kind]
        return {
            "low": low,
            "low_open": low_open,
            "high": self.high,
            "high_open": self.high_open,
            "allow_inf": self.allow_inf,
        }

    def holds(self, values) -> np.ndarray:
        """Elementwise, whether each number of the array ``values`` is in the
        declared range (`check`'s rule, for many designs at once; NaN never is)."""
        b = self.bounds
        a = np.asarray(values, dtype=float)
        with np.errstate(invalid="ignore"):
            ok = ~np.isnan(a) if b["allow_inf"] else np.isfinite(a)
            if b["low"] is not None:
                ok &= (a > b["low"]) if b["low_open"] else (a >= b["low"])
            if b["high"] is not None:
                ok &= (a < b["high"]) if b["high_open"] else (a <= b["high"])
        return ok

    def check(self, name: str, value) -> float | None:
        """``value`` as a float in the declared range (None if optional and
        None), or a `ParameterError` naming ``name``, the description and the unit."""
        if value is None and self.optional:
            return None
        return number(name, value, self.unit, description=self.description, **self.bounds)


def check_fields(obj, spec: Mapping[str, Field]) -> None:
    """Validate and coerce to float every field of a frozen dataclass ``obj``
    declared in ``spec``, refusing the first bad one by name."""
    for name, field in spec.items():
        object.__setattr__(obj, name, field.check(name, getattr(obj, name)))


def blamed_field(obj, expression: str) -> str:
    """The field of the dataclass ``obj`` a refused formula most likely blames.

    Of the fields ``expression`` reads (``ks`` and ``mu`` in
    ``'sqrt(ks/mu)'``; ``'Σks'``, a sum, is no one field), the one whose
    value lies the most orders of magnitude from its default,
    ``|log10(value/default)|``; the first field of ``obj`` if the formula
    reads none. A check across fields (a vehicle's time scales) refuses with
    a `ParameterError` naming it, the formula and every value staying in the
    text, so that a caller who reads ``.name`` is pointed at the parameter
    the user most likely mistyped.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass
    ... class Car:
    ...     ks: float = 3e4
    ...     mu: float = 100.0
    >>> blamed_field(Car(mu=1e-305), "ks/mu")
    'mu'
    """
    declared = {f.name: f.default for f in dataclasses.fields(obj)}
    read = [w for w in re.findall(r"(?<![Σ\w])\w+", expression) if w in declared]

    def distance(name: str) -> float:
        value, default = getattr(obj, name), declared[name]
        if not (_real(value) and _real(default)) or value == default:
            return 0.0
        if value == 0 or default == 0 or not math.isfinite(value / default):
            return math.inf
        return abs(math.log10(abs(value / default)))

    return max(read, key=distance) if read else next(iter(declared))


def instance_from(cls, values: Mapping[str, Any]):
    """``cls(**values)`` for a parameter dataclass ``cls``, an unknown key
    refused first: a `ParameterError` whose ``.name`` is the key (so that a
    command line or a TOML loader points at it), listing the parameters
    ``cls`` has. The ``from_mapping`` of every car's parameter class.
    """
    names = sorted(f.name for f in dataclasses.fields(cls))
    unknown = sorted(set(values) - set(names))
    if unknown:
        raise ParameterError(
            unknown[0],
            unknown[0],
            f"a parameter of {cls.__name__}: one of {names}",
            description="unknown parameter",
        )
    return cls(**dict(values))
