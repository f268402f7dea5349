"""The column names of a method comparison's frames, named once.

`qc_control.studies.compare` writes its `MethodComparison`'s frames under
these names, and everything that reads them (the timing and cost studies,
the report's summary, findings, tables and figures) reads them from here:
renaming a column is one change. Units are part of a name, SI (``[s]``,
``[m]``) or as the table shows them (``[ms]``).

Three frames:

- ``table``, one row per method (index `METHOD`): its cost at h, its wall
  times, its errors (`max_error`, `rms_error`, `final_error` of each
  output), its observed order and its step limit and numerical modes;
- ``convergence``, long form, one row per method and refinement
  (`CONVERGENCE`, the fields of `qc_control.studies.compare.ConvergencePoint`,
  then the timing rounds' `TIME_LOW`, `TIME_HIGH` and `CPU` on a linear car;
  a nonlinear study's long form adds `EVENTS`);
- ``cost`` and ``cost_kind``, indexed by `TOLERANCE`, a column per method.
"""

from __future__ import annotations

__all__ = [
    "METHOD", "ORDER", "STAGES", "STEP", "STEPS", "RHS_EVALS", "WALL_TIME", "WALL_MIN",
    "WALL_MAX", "CPU_TIME", "LTI_ENGINE", "PER_CONTROL", "TIME_COLUMNS", "OBSERVED_ORDER",
    "OBSERVED_ORDER_EVENTS", "OBSERVED_ORDER_NO_EVENTS", "H_MAX", "LIMITED_BY", "STABLE",
    "max_error", "rms_error", "final_error", "freq_error", "zeta_error", "LEVEL", "H", "NFEV",
    "TIME", "ERROR", "CONVERGENCE", "TIME_LOW", "TIME_HIGH", "CPU", "EVENTS", "WITH_EVENTS",
    "WITHOUT_EVENTS", "TOLERANCE",
]  # fmt: skip

# --- the table: one row per method ------------------------------------------

#: The index of the table (and a column of the convergence study): the method's name.
METHOD = "method"
#: The method's theoretical order and its stages per step.
ORDER, STAGES = "order", "stages"
#: The step of the run at h [s], its steps over the span, and its right-hand-side evaluations.
STEP, STEPS, RHS_EVALS = "h [s]", "steps", "RHS evals"
#: Wall times of the run at h: the median of the timing rounds, their lowest and
#: highest (the machine's spread), this process's CPU time (`qc_control.studies.timing`).
WALL_TIME, WALL_MIN, WALL_MAX = "wall time [ms]", "wall min [ms]", "wall max [ms]"
CPU_TIME = "CPU time [ms]"
#: The LTI engine's time for the same trajectory, and the wall time over control's exact call.
LTI_ENGINE, PER_CONTROL = "LTI engine [ms]", "time / control"
#: The wall-time columns of a linear comparison's table, in the table's order.
TIME_COLUMNS = [WALL_TIME, WALL_MIN, WALL_MAX, CPU_TIME, LTI_ENGINE, PER_CONTROL]
#: The order observed from the errors at h, h/2, h/4 (a nonlinear car: with and without events).
OBSERVED_ORDER = "observed order"
OBSERVED_ORDER_EVENTS = "observed order (events)"
OBSERVED_ORDER_NO_EVENTS = "observed order (no events)"
#: The method's largest stable step [s], the mode that sets it, and whether h is within it.
H_MAX, LIMITED_BY, STABLE = "h_max [s]", "limited by", "stable"


def max_error(label: str, unit: str) -> str:
    """The column of an output's largest absolute error: ``max |xs err| [m]``."""
    return f"max |{label} err| [{unit}]"


def rms_error(label: str, unit: str) -> str:
    """The column of an output's root-mean-square error: ``rms xs err [m]``."""
    return f"rms {label} err [{unit}]"


def final_error(label: str, unit: str) -> str:
    """The column of an output's absolute error at the last time: ``final |xs err| [m]``."""
    return f"final |{label} err| [{unit}]"


def freq_error(mode: str) -> str:
    """The column of a mode's damped-frequency error as a method sees it [%]."""
    return f"{mode} freq err [%]"


def zeta_error(mode: str) -> str:
    """The column of a mode's damping error as a method sees it (ζ_h − ζ)."""
    return f"{mode} zeta err"


# --- the convergence study: long form ---------------------------------------

#: The refinement (h / 2**level), its step [s], the run's RHS evaluations, its wall
#: time [s] and its largest body-displacement error [m].
LEVEL, H, NFEV, TIME, ERROR = "level", "h", "nfev", "time", "error"
#: A row of the convergence study: `qc_control.studies.compare.ConvergencePoint`'s fields.
CONVERGENCE = (METHOD, LEVEL, H, STEPS, NFEV, TIME, ERROR, STABLE)
#: The lowest and highest wall time of the rounds [s], and the median CPU time [s].
TIME_LOW, TIME_HIGH, CPU = "time_low", "time_high", "cpu_time"
#: A nonlinear car's long form: whether the run stepped to each event.
EVENTS = "events"
#: A nonlinear car's orders (`NonlinearStudy.orders`): with and without events.
WITH_EVENTS, WITHOUT_EVENTS = "with events", "without events"

# --- the costs to reach each accuracy -----------------------------------------

#: The index of ``cost`` and ``cost_kind``: the accuracy [m] in the body displacement.
TOLERANCE = "tolerance [m]"
