"""What a comparison holds: `MethodComparison`, and `NonlinearStudy`, what a
nonlinear car adds. Both are frozen: every number is computed once, by the
study, before the result is built; the report only formats them.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np
import pandas as pd

from ...models.modal import ModalAnalysis
from ...ride.assessment import RideAssessment
from ...ride.comfort import Transmissibility
from .. import columns as col
from ..confirm import CostCheck
from ..peers import WorkPrecision
from ..ride_cost import RideCost
from .measures import (
    Reference,
)
from .nlreference import NonlinearReference
from .problem import (
    ComparisonProblem,
    Provenance,
)


@dataclass(frozen=True, eq=False)
class MethodComparison(ComparisonProblem):
    """The numbers of a method comparison. See `compare_methods`.

    Its problem (system, grid, start, input, step, methods) is that of
    `ComparisonProblem`. Frozen: every number is computed before it is
    built, once; what a later step adds (a stiff car's ``ride_cost``, the
    ``scenario`` a run came from) makes a new one with
    ``dataclasses.replace(cmp, ride_cost=...)``. Its column names are named
    in `qc_control.studies.columns`.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per method (index: method name); columns with units.
    modes : ModalAnalysis
        The exact modes (damping per mode).
    numerical_modes : dict[str, pandas.DataFrame]
        Per method, each mode's frequency and damping as the method sees it.
    convergence : pandas.DataFrame
        Long form: method, h, steps, nfev, time, error, for h, h/2, ..., h/32.
    cost : pandas.DataFrame
        RHS evaluations needed to reach each accuracy in `TOLERANCES`
        (index, max |xs error| in m) per method (columns).
    cost_kind : pandas.DataFrame
        For each entry of `cost`: ``'confirmed'`` (a run at that count
        reaches the accuracy, `cost_checks`), ``'missed'`` (runs from the
        estimate on did not: no cost), or the kind of an estimate no run
        checked (a nonlinear car; a run too long): ``'interpolated'``
        (log-log, between two refinements that bracket it) or
        ``'extrapolated'`` (``e = C h^p`` with the method's order p from
        the nearest refinement, and never a step beyond ``h_max``).
    coincident : dict
        ``{(a, b): max |x_a - x_b|}`` [m] over the states, for each pair of
        methods whose trajectories agree to 1e-12 m (e.g. Midpoint and
        Heun on linear systems).
    reference : control.TimeResponseData
        python-control's exact response on the grid.
    reference_error : float
        The reference's own accuracy [m]: its largest difference from an
        independent exact evaluation (see `compare_methods`).
    responses : dict[str, FixedStepResponse]
        Each method's response at the chosen h.
    ride : pandas.DataFrame or None
        Under a road input: `qc_control.ride_metrics` of the reference
        (first row) and of each method.
    ride_error : pandas.DataFrame or None
        Each method's ride metrics against the reference's [%].
    transmissibility : Transmissibility or None
        Under a road input: the road-to-ride frequency responses.
    scenario : Provenance or None
        The run this comparison came from, when it came from one (the
        command line's Scenario returns ``dataclasses.replace(cmp,
        scenario=self)``); the report prints its command and saves its TOML.
    nonlinear : NonlinearStudy or None
        On a nonlinear system: events, the order with and without them,
        where Midpoint and Heun part, the linearisation behind ``modes``.
    peers : WorkPrecision or None
        With ``solvers``: every run of the work–precision study (the
        fixed-step ladder, the peers and the adaptive pairs over the
        tolerances), `qc_control.studies.peers`.
    sampled_car : control.StateSpace or None
        On a sampled-data loop: the car between the ticks, whose modes and
        step limits the comparison reports (the controller acts only at the
        ticks); the reference is then `sampled_reference`.
    ride_cost : RideCost or None
        Given by the stiff car's run (`qc_control.studies.ride_cost`): each
        method's and peer's cheapest setting whose ride metric is within a
        target of the exact one, with its evaluations and time.
    cost_checks : list of CostCheck or None
        On a linear car: the run that checked each estimate of `cost`
        (`qc_control.studies.confirm`); `cost` then holds the confirmed
        counts, and `cost_kind` says 'confirmed' or 'missed' for them.
    comfort : RideAssessment or None
        With ``compare_methods(..., comfort=...)`` on a road: the exact
        reference's ride assessed to ISO 2631-1:1997
        (`qc_control.ride_assessment` of ``reference`` as the car's), per
        axis and whole, each number with its clause.
    """

    table: pd.DataFrame
    modes: ModalAnalysis
    numerical_modes: dict
    convergence: pd.DataFrame
    cost: pd.DataFrame
    cost_kind: pd.DataFrame
    coincident: dict
    reference: control.TimeResponseData
    reference_error: float
    reference_time: float
    reference_description: str
    reference_name: str
    responses: dict
    eigenvalues: np.ndarray
    input_description: str = ""
    ride: pd.DataFrame | None = None
    ride_error: pd.DataFrame | None = None
    transmissibility: Transmissibility | None = None
    scenario: Provenance | None = None
    nonlinear: NonlinearStudy | None = None
    peers: WorkPrecision | None = None
    sampled_car: control.StateSpace | None = None
    ride_cost: RideCost | None = None
    cost_checks: list[CostCheck] | None = None
    comfort: RideAssessment | None = None

    def summary(self) -> pd.DataFrame:
        """The headline columns of `table`, for a terminal."""
        model = self.model
        errors = [col.max_error(model.body_disp if model else "xs", "m")]
        if model is not None and len(model.corners) > 1:  # each corner's travel error
            errors += [col.max_error(c.susp_travel, "m") for c in model.corners]
        else:
            errors.append(col.max_error("xu", "m"))
        cols = [col.ORDER, col.RHS_EVALS, col.WALL_TIME, *errors, col.OBSERVED_ORDER, col.H_MAX]
        return self.table[[c for c in cols if c in self.table.columns]]


@dataclass(frozen=True, eq=False)
class Measured:
    """What the linear or the nonlinear path measured, for `_comparison` to assemble.

    ``linear`` is the system itself, or its linearisation at rest: its
    eigenvalues give the modes, the step limits and the numerical modes.
    ``orders`` holds the ``observed order`` column(s) of the table.
    """

    reference: Reference
    responses: dict
    linear: control.StateSpace
    modes: ModalAnalysis
    convergence: pd.DataFrame
    orders: pd.DataFrame
    times: pd.DataFrame
    transmissibility: Transmissibility | None = None
    nonlinear: NonlinearStudy | None = None


@dataclass(frozen=True, eq=False)
class NonlinearStudy:
    """What a comparison on a nonlinear system adds. See `compare_methods`.

    Attributes
    ----------
    events : bool
        Whether the methods' responses (``MethodComparison.responses``,
        ``.table``, ``.convergence``) located the switching times
        (``qc.input_output_response(..., events=True)``).
    switching_labels : tuple of str
        The system's switching functions (``sys.switching_labels``); empty
        when it has none (then the study with and without events is one).
    t_events, event_labels
        Where the reference's switching functions changed sign [s] and
        which (e.g. ``'contact'``: the wheel leaving or regaining the road).
    event_signs : tuple of int
        The sign each switching function has just after its event (+1 or
        -1): for ``'contact'`` -1 is contact lost, +1 regained; for a stop
        -1 is engaged, +1 released.
    airborne : tuple of (float, float)
        The reference's flights: each ``(contact lost, contact regained)``
        [s], the second NaN when the wheel is still in the air at the end.
    method_events : dict
        Per method, ``(t_events, event_labels)`` of its run at h with events.
    convergence : pandas.DataFrame
        Long form over both modes: method, events, level, h, steps, nfev,
        time, error (the largest absolute body-displacement error [m]), stable.
    orders : pandas.DataFrame
        Per method (index): ``with events`` and ``without events``, the
        least-squares slope of log error against log h over h, h/2, h/4
        (NaN without switching functions, or where the errors are within
        ``error_floor`` of the reference).
    parting : dict
        Where Midpoint and Heun part (when both ran): ``max [m]`` (their
        largest displacement difference), ``at [s]`` (its time), ``from [s]``
        (the first sample where they differ by more than 1e-12 m; NaN when
        they never do).
    parting_gap : ndarray or None
        Their displacement difference [m] at every sample of ``T``.
    reference : NonlinearReference
        The DOP853 reference on the finest grid (``T`` refined ``2**levels``
        times).
    error_floor : float
        Errors below this [m] (10x the reference's own error) are not used
        in an order fit.
    linearization : control.StateSpace
        The system linearised at the static equilibrium (``x = 0``,
        ``u = 0``; `control.linearize`): its modes and eigenvalues are the
        comparison's ``modes``, step limits and numerical modes.
    linearization_note : str
        What the linearisation is and where it does not hold.
    """

    events: bool
    switching_labels: tuple[str, ...]
    t_events: np.ndarray
    event_labels: tuple[str, ...]
    event_signs: tuple[int, ...]
    airborne: tuple[tuple[float, float], ...]
    method_events: dict
    convergence: pd.DataFrame
    orders: pd.DataFrame
    parting: dict
    parting_gap: np.ndarray | None
    reference: NonlinearReference
    error_floor: float
    linearization: control.StateSpace
    linearization_note: str
