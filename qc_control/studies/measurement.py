"""Measured time records: a rig's or a car's channels under the model's labels.

A `Measurement` holds named signals on one uniform time base, in SI units,
labelled as the quarter car labels its signals (``zr`` and ``fa`` in,
``xs``, ``susp_travel``, ``body_acc``, ``wheel_acc`` ... out). It is what
`qc_control.identify` fits and what `qc_control.compare_to_measurement`
checks a model against. Reading refuses what would silently corrupt a fit:
a NaN, a gap in time, time that goes backwards, a label the model does not
know; each message names the column and the row. A time base that is merely
uneven (a logger's jitter) is resampled to uniform, with a note.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..models.quarter import UNITS as QUARTER_UNITS

__all__ = [
    "Measurement",
    "SIGNAL_UNITS",
    "INPUT_LABELS",
    "UNIT_FACTORS",
    "TIME_FACTORS",
    "rig_record",
    "RIG_COLUMNS",
    "read_csv",
    "row_of",
]

#: The labels a measurement may hold and their SI units: the quarter car's
#: signals and the wheel's acceleration (an accelerometer on the hub).
SIGNAL_UNITS: dict[str, str] = {**QUARTER_UNITS, "wheel_acc": "m/s²"}
#: The labels that are the model's inputs (the rest are outputs).
INPUT_LABELS = ("zr", "fa")
#: Factors from the units a logger writes to SI (``units={'zr': 'mm'}``).
UNIT_FACTORS = {
    "m": 1.0,
    "cm": 1e-2,
    "mm": 1e-3,
    "um": 1e-6,
    "N": 1.0,
    "kN": 1e3,
    "m/s": 1.0,
    "mm/s": 1e-3,
    "m/s²": 1.0,
    "m/s^2": 1.0,
    "g": 9.80665,  # standard gravity, ISO 80000-3
}
#: Factors from the units a time column may be in to seconds (``units={'time_ms': 'ms'}``).
TIME_FACTORS = {"s": 1.0, "ms": 1e-3}
#: A sample interval more than this times the median one is a gap (a lost
#: stretch of record), not jitter: refused, since no resampling restores it.
GAP_FACTOR = 1.5
#: Sample intervals that differ from the median by less than this (relative)
#: are a uniform base as written by a logger with rounded time stamps.
JITTER = 1e-6


def _where(row: int, first_row, t=None) -> str:
    """``row 12`` (and its time) in the numbering of the source (a file's lines):
    ``first_row`` is the first row's number, or every row's (a file whose blank and
    comment lines were skipped between rows)."""
    at = f"row {row_of(first_row, row)}"
    return at if t is None else f"{at} (t = {t:.6g} s)"


def _check_time(t: np.ndarray, column: str, first_row) -> None:
    if t.ndim != 1 or t.size < 3:
        raise ValueError(f"time column {column!r} must be 1-D with at least 3 samples")
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise ValueError(f"time column {column!r} is not finite at {_where(bad[0], first_row)}")
    dt = np.diff(t)
    back = np.flatnonzero(dt <= 0)
    if back.size:
        i = back[0] + 1
        raise ValueError(
            f"time column {column!r} does not increase at {_where(i, first_row)}: "
            f"t = {t[i]:.6g} s after {t[i - 1]:.6g} s"
        )
    median = float(np.median(dt))
    gaps = np.flatnonzero(dt > GAP_FACTOR * median)
    if gaps.size:
        i = gaps[0]
        raise ValueError(
            f"time column {column!r} has a gap between {_where(i, first_row)} and "
            f"{_where(i + 1, first_row)}: {t[i]:.6g} s to {t[i + 1]:.6g} s, against a "
            f"sample interval of {median:.6g} s; split the record there"
        )


def _check_signal(label: str, values, n: int, column: str, first_row, t) -> np.ndarray:
    if label not in SIGNAL_UNITS:
        known = ", ".join(sorted(SIGNAL_UNITS))
        raise ValueError(f"unknown label {label!r} for column {column!r}; expected one of {known}")
    try:
        x = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"column {column!r} ({label}) must hold numbers") from None
    if x.shape != (n,):
        raise ValueError(
            f"column {column!r} ({label}) has shape {x.shape}, expected ({n},) like the time"
        )
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise ValueError(
            f"column {column!r} ({label}) is not a number at {_where(bad[0], first_row, t[bad[0]])}"
        )
    return x


def _unit_factor(label: str, unit: Any) -> float:
    if isinstance(unit, (int, float)) and not isinstance(unit, bool):
        # a factor of 0 turns the record into zeros, NaN into NaN: a fit to nothing
        if not math.isfinite(unit) or unit == 0:
            raise ValueError(
                f"the factor to SI of {label!r} must be a finite number other than 0, got {unit!r}"
            )
        return float(unit)
    if unit not in UNIT_FACTORS:
        raise ValueError(
            f"unit {unit!r} of {label!r} is not known; expected one of "
            f"{', '.join(UNIT_FACTORS)} or a factor to SI"
        )
    return UNIT_FACTORS[unit]


class Measurement:
    """Named time signals on a uniform time base, in SI units.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s], increasing. An uneven base (jitter beyond 1e-6 of
        the median interval, but no gap over 1.5 intervals) is resampled
        linearly to the uniform one with the same start, end and count;
        `notes` says so.
    units : mapping, optional
        ``{label: unit}`` of signals not in SI: a name from `UNIT_FACTORS`
        (``'mm'``, ``'kN'``, ``'g'``) or a factor to SI.
    **signals : array_like, shape (N,)
        The signals by label (`SIGNAL_UNITS`): ``zr``, ``fa`` (inputs),
        ``xs``, ``xu``, ``susp_travel``, ``tire_defl``, ``body_acc``,
        ``wheel_acc`` ...

    Raises
    ------
    ValueError
        For an unknown label or unit, a NaN, time that does not increase, or
        a gap; the message names the column and the row.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 1, 0.01)
    >>> m = Measurement(t, zr=np.zeros(t.size), body_acc=np.zeros(t.size))
    >>> m.inputs, m.outputs, m.dt
    (('zr',), ('body_acc',), 0.01)
    >>> Measurement(t, speed=t)
    Traceback (most recent call last):
    ...
    ValueError: unknown label 'speed' for column 'speed'; expected one of body_acc, ...
    """

    def __init__(self, t, units: Mapping[str, Any] | None = None, **signals):
        self._build(t, signals, units or {}, {k: k for k in signals}, "t", 0)

    def _build(self, t, signals, units, columns, time_column: str, first_row) -> None:
        units = dict(units)
        t = np.asarray(t, dtype=float)
        _check_time(t, time_column, first_row)
        if time_column in units and time_column not in signals:
            unit = units.pop(time_column)
            if unit not in TIME_FACTORS:
                raise ValueError(
                    f"unit {unit!r} of the time column {time_column!r} is not known; expected "
                    f"one of {', '.join(TIME_FACTORS)}"
                )
            t = t * TIME_FACTORS[unit]
        if not signals:
            raise ValueError("a measurement needs at least one signal")
        for label in units:
            if label not in signals:
                raise ValueError(f"units given for {label!r}, which is not among the signals")
        data = {}
        for label, values in signals.items():
            x = _check_signal(label, values, t.size, columns[label], first_row, t)
            data[label] = x * _unit_factor(label, units.get(label, 1.0))
        notes = []
        dt = np.diff(t)
        median = float(np.median(dt))
        if np.max(np.abs(dt - median)) > JITTER * median:
            uniform = np.linspace(t[0], t[-1], t.size)
            data = {k: np.interp(uniform, t, v) for k, v in data.items()}
            notes.append(
                f"the time base was uneven (intervals {dt.min():.6g} to {dt.max():.6g} s): "
                f"resampled linearly to a uniform {uniform[1] - uniform[0]:.6g} s"
            )
            t = uniform
        self.t = t
        self.signals = data
        self.columns = dict(columns)
        self.notes = tuple(notes)
        #: The time column's name in the source (``t`` for arrays), for messages.
        self.time_column = time_column

    @classmethod
    def from_frame(
        cls,
        frame: pd.DataFrame,
        *,
        time: str = "t",
        columns: Mapping[str, str] | None = None,
        scale: Mapping[str, float] | None = None,
        units: Mapping[str, Any] | None = None,
        first_row: int = 0,
    ) -> Measurement:
        """A measurement from a `pandas.DataFrame`.

        Parameters
        ----------
        frame : pandas.DataFrame
        time : str, default ``'t'``
            The time column [s].
        columns : mapping, optional
            ``{label: column}``; by default every column but the time one,
            each named by its label.
        scale : mapping, optional
            ``{label: factor}`` applied after reading (a sign or a
            calibration), on top of ``units``.
        units : mapping, optional
            As in `Measurement`; the time column's unit may be given too, by
            its name (``{'time_ms': 'ms'}``, `TIME_FACTORS`).
        first_row : int or array of int, default 0
            The number the messages give the first row (a file's line), or
            every row's.
        """
        names = list(map(str, frame.columns))
        if time not in names:
            raise ValueError(f"time column {time!r} is not among the columns {names}")
        if columns is None:
            columns = {c: c for c in names if c != time}
        for label, column in columns.items():
            if column not in names:
                raise ValueError(f"column {column!r} (for {label!r}) is not among {names}")
        factors = dict(units or {})
        for label, factor in (scale or {}).items():
            if label not in columns:
                raise ValueError(f"scale given for {label!r}, which is not among the signals")
            factors[label] = _unit_factor(label, factors.get(label, 1.0)) * _unit_factor(
                label, float(factor)
            )
        signals = {label: pd.to_numeric(frame[c], errors="coerce") for label, c in columns.items()}
        self = cls.__new__(cls)
        t = pd.to_numeric(frame[time], errors="coerce").to_numpy(dtype=float)
        self._build(t, signals, factors, columns, time, first_row)
        return self

    @classmethod
    def from_csv(cls, path, *, time: str = "t", columns=None, scale=None, units=None):
        """A measurement from a CSV file (a header line, then one row per sample).

        Rows in messages are the file's line numbers. See `from_frame` for
        the arguments.
        """
        frame, first_row = read_csv(path)
        return cls.from_frame(
            frame, time=time, columns=columns, scale=scale, units=units, first_row=first_row
        )

    @property
    def dt(self) -> float:
        """The sample interval [s]."""
        return float(self.t[1] - self.t[0])

    @property
    def labels(self) -> tuple[str, ...]:
        return tuple(self.signals)

    @property
    def inputs(self) -> tuple[str, ...]:
        """The signals that are model inputs (``zr``, ``fa``), in that order."""
        return tuple(k for k in INPUT_LABELS if k in self.signals)

    @property
    def outputs(self) -> tuple[str, ...]:
        """The signals that are model outputs."""
        return tuple(k for k in self.signals if k not in INPUT_LABELS)

    def __getitem__(self, label: str) -> np.ndarray:
        try:
            return self.signals[label]
        except KeyError:
            raise KeyError(f"no signal {label!r}; the measurement has {self.labels}") from None

    def __len__(self) -> int:
        return self.t.size

    def window(self, start: float, end: float) -> Measurement:
        """The part of the record from ``start`` to ``end`` [s] (a held-out stretch)."""
        keep = (self.t >= start) & (self.t <= end)
        if keep.sum() < 3:
            raise ValueError(f"the window {start}..{end} s holds fewer than 3 samples")
        other = Measurement.__new__(Measurement)
        other.t = self.t[keep]
        other.signals = {k: v[keep] for k, v in self.signals.items()}
        other.columns, other.notes = dict(self.columns), self.notes
        other.time_column = self.time_column
        return other

    def frame(self) -> pd.DataFrame:
        """The signals as a `pandas.DataFrame` indexed by time [s]."""
        return pd.DataFrame(self.signals, index=pd.Index(self.t, name="t"))

    def __repr__(self) -> str:
        return (
            f"Measurement({self.t.size} samples at {1 / self.dt:.6g} Hz, "
            f"{self.t[-1] - self.t[0]:.6g} s; {', '.join(self.labels)})"
        )


#: The shipped rig records' columns by label (``examples/make_rig_dataset.py``).
RIG_COLUMNS = {
    "zr": "base_mm",
    "fa": "force_N",
    "susp_travel": "travel_mm",
    "body_acc": "body_acc_ms2",
    "wheel_acc": "wheel_acc_ms2",
    "xs": "body_disp_mm",
}


def rig_record(part: str = "identification") -> Measurement:
    """The shipped rig test, a SIMULATED record (see ``examples/make_rig_dataset.py``).

    A quarter car with a damped tire on a rig, its base plate moving
    randomly and an actuator sweeping a force chirp; 1 % sensor noise, a
    drifting body displacement sensor and a force channel of the opposite
    sign to the model's ``fa``, as a real rig's records have.

    Parameters
    ----------
    part : {'identification', 'validation'}
        The 15 s record to fit, or the 8 s held-out one (200 Hz both).

    Examples
    --------
    >>> rig_record()
    Measurement(3001 samples at 200 Hz, 15 s; zr, fa, susp_travel, body_acc, wheel_acc, xs)
    """
    if part not in ("identification", "validation"):
        raise ValueError(f"part must be 'identification' or 'validation', got {part!r}")
    path = Path(__file__).parent.parent / "data" / f"rig_{part}.csv"
    units = {k: "mm" for k in ("zr", "susp_travel", "xs")}
    return Measurement.from_csv(path, time="time_s", columns=RIG_COLUMNS, units=units)


def _leading_comments(path: Path) -> int:
    """How many ``#`` lines precede the header of a CSV file."""
    count = 0
    with path.open(encoding="utf-8", errors="replace") as f:
        for line in f:
            if not line.startswith("#"):
                break
            count += 1
    return count


def _data_lines(path: Path) -> np.ndarray:
    """The file's line number (1 for the first) of each data row, as ``pandas.read_csv(...,
    comment='#')`` reads them: blank lines and ``#`` lines are skipped before the header
    and between rows, so a row's number is not its index plus a constant."""
    numbers = []
    with path.open(encoding="utf-8", errors="replace") as f:
        kept = (n for n, line in enumerate(f, start=1) if line.strip()[:1] not in ("", "#"))
        next(kept, None)  # the header
        numbers = list(kept)
    return np.array(numbers, dtype=int)


def read_csv(path) -> tuple[pd.DataFrame, Any]:
    """A CSV file of records (a header line, then one row per sample; ``#`` lines are
    comments) and the file's line number of each row, for messages.

    Returns
    -------
    frame : pandas.DataFrame
    lines : ndarray of int or int
        Each row's line number in the file (1 for the first line); the first
        row's number when the rows cannot be matched to lines one to one.

    Raises
    ------
    ValueError
        Naming the file, for one that cannot be read or is not UTF-8 text.
    """
    path = Path(path)
    try:
        frame = pd.read_csv(path, comment="#")
    except (OSError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise ValueError(f"cannot read {str(path)!r}: {exc}") from None
    except UnicodeDecodeError as exc:  # a logger's export in a Windows code page
        raise ValueError(
            f"{str(path)!r} is not UTF-8 text (byte {exc.object[exc.start]:#04x} at "
            f"position {exc.start}): save it as 'CSV UTF-8' and read it again"
        ) from None
    lines = _data_lines(path)
    return frame, (lines if lines.size == len(frame) else 2 + _leading_comments(path))


def row_of(lines, index: int) -> int:
    """The file's line number of row ``index`` (`read_csv`'s ``lines``)."""
    return int(lines[index]) if isinstance(lines, np.ndarray) else index + int(lines)
