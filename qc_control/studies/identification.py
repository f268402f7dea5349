"""Grey-box identification of the quarter car from measured records.

`identify` fits the quarter car's parameters by output error: the model is
simulated exactly (`qc_control.numerics.exact`) under the measured inputs
(road ``zr``, force ``fa``) and `scipy.optimize.least_squares` minimises the
misfit of the measured outputs, each output's residual divided by that
output's RMS so that a displacement and an acceleration weigh alike.
Physical parameters are fitted as logarithms (they stay positive, and their
steps are relative), except the tire damping ``cu``, fitted as it is with a
bound at 0: a tire without damping is a car the fit must reach, and a
logarithm reaches 0 only by running away to minus infinity (its interval
then of zero width, or an overflow). Input gains, which may be negative (a
force channel of the opposite sign), are fitted as they are.

What the records can determine is stated, not guessed. Scaling every mass,
stiffness and damping by one factor leaves the response to the road
unchanged and scales the response to a force by its inverse; with the road
as the only input, or a force of unknown gain, only the ratios ``ks/ms``,
``cs/ms``, ``ku/ms``, ``mu/ms`` (the Golden Car's form) are determined. The
fit then holds ``ms`` at its start value, reports the ratios with their
intervals, and names the absolute values undetermined until a mass is fixed.
A Jacobian that is rank deficient for any other reason is reported the same
way.

For a long sine-sweep or random rig test, ``domain="frequency"`` fits the
car's exact response to the records' transmissibility instead (the
multi-input H1 estimate, each frequency weighted by its coherence; see
`qc_control.studies.frequency_identification`): the record's start then
does not matter, at the price of records long enough to resolve the body's
resonance (a few hundred seconds for 0.1 Hz bins).

Uncertainty comes from the Jacobian at the optimum (Ljung, *System
Identification*, 2nd ed., §9.3): the parameters' covariance is the sandwich
``(JᵀJ)⁻¹ (Σᵢ σᵢ² JᵢᵀJᵢ) (JᵀJ)⁻¹`` with ``σᵢ²`` the residual variance of
output ``i``, which is ``σ² (JᵀJ)⁻¹`` for one output and stays right when
the outputs' noise levels differ from their RMS weights.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
import scipy.optimize
import scipy.stats

from ..models.quarter import QuarterCarParams, quarter_car_abcd, quarter_car_model
from ..models.registry import MODELS, ModelEntry
from ..models.vehicle import VehicleModel
from ..numerics.checks import ParameterError, choice, nonnegative, positive
from ..numerics.exact import exact_outputs
from ..numerics.reference import rest_state
from ..numerics.threads import one_blas_thread
from .frequency_identification import (
    Transmissibility,
    bin_weights,
    check_band,
    sampled_response,
    transmissibility,
)
from .measurement import INPUT_LABELS, Measurement

__all__ = [
    "identify",
    "Identification",
    "PHYSICAL",
    "OUTPUT_LABELS",
    "simulate_quarter",
    "nrmse_fit",
    "whiteness",
]

#: The quarter car's physical parameters that identification can fit.
PHYSICAL = ("ms", "mu", "ks", "ku", "cs", "cu")
#: What a fit leaves free by default: every physical parameter. The tire damping is
#: bounded below by 0, so a car without it is fitted as well as one with it.
DEFAULT_FREE = PHYSICAL
#: Parameters fitted as they are, bounded below by 0 (the rest as logarithms).
LINEAR = ("cu",)
#: An estimate more than this factor from its start has run away: the records hold
#: nothing that pins it (e.g. a stiffness whose spring the outputs never see).
RUNAWAY_FACTOR = 1e3
#: The outputs the identified quarter car can be compared on.
OUTPUT_LABELS = ("xs", "xu", "susp_travel", "tire_defl", "body_acc", "wheel_acc")
#: A tire damping's start [N·s/m] when it is free and no start is given: a
#: tire's damping is a few hundred N·s/m, far below the suspension's.
CU_START = 100.0
#: Two-sided 95 % quantile of the normal distribution.
Z95 = 1.959963984540054
#: A direction of the (column-scaled) Jacobian whose singular value is below
#: this fraction of the largest is one the data does not determine: finite
#: differences in double precision resolve about 1e-8 of a residual, so an
#: exact symmetry shows as 1e-8 or less, and a determined parameter far above.
RANK_TOLERANCE = 1e-6
#: Lags of the residuals' autocorrelation checked for whiteness.
WHITENESS_LAGS = 25
#: The misfit of a bin or sample whose response overflowed (an absurd trial car), and
#: the largest one counted: a sound car's weighted misfits are of order 1, and a
#: square beyond 1e308 would overflow the optimiser's cost.
UNPHYSICAL_MISFIT = 1e12
#: The frequency fit's bins should be at most this fraction of the body
#: resonance's half-power width: the H1 estimate's leakage bias grows as the
#: square of their ratio (Bendat & Piersol, §8.5.4), and on a seed-like car
#: (0.74 Hz wide) a third of the width gave 0.5 % in ks where two thirds gave 3 %.
LEAKAGE_FRACTION = 0.35
_UNITS = {"ms": "kg", "mu": "kg", "ks": "N/m", "ku": "N/m", "cs": "N·s/m", "cu": "N·s/m"}


def nrmse_fit(measured: np.ndarray, simulated: np.ndarray) -> float:
    """The NRMSE fit [%] as MATLAB's ``compare`` reports it.

    ``100 (1 - ‖y - ŷ‖ / ‖y - mean(y)‖)``: 100 is a perfect fit, 0 is no
    better than the mean, and it is negative for a worse one.

    Examples
    --------
    >>> import numpy as np
    >>> y = np.sin(np.linspace(0, 6, 100))
    >>> nrmse_fit(y, y), round(nrmse_fit(y, np.zeros(100) + y.mean()), 6)
    (100.0, 0.0)
    """
    y, yhat = np.asarray(measured, dtype=float), np.asarray(simulated, dtype=float)
    spread = np.linalg.norm(y - y.mean())
    if spread == 0:
        return float("nan")
    return float(100.0 * (1.0 - np.linalg.norm(y - yhat) / spread))


def whiteness(residual: np.ndarray, lags: int = WHITENESS_LAGS) -> tuple[float, bool]:
    """The fraction of autocorrelation lags 1..``lags`` outside ±1.96/√N, and whether
    the residual passes as white.

    Each lag of a white residual falls outside the band with probability 5 %,
    so a count of lags outside is binomial: the residual passes unless the
    count is beyond that binomial's 99th percentile (4 of 25 lags), which a
    white residual exceeds once in a hundred records; a model error shows as
    a run of many lags outside.
    """
    e = np.asarray(residual, dtype=float) - np.mean(residual)
    n = e.size
    denom = float(e @ e)
    if denom == 0 or n <= lags:
        return 0.0, True
    r = np.array([e[:-k] @ e[k:] / denom for k in range(1, lags + 1)])
    outside = int(np.sum(np.abs(r) > Z95 / math.sqrt(n)))
    return outside / lags, outside <= scipy.stats.binom.ppf(0.99, lags, 0.05)


def _quarter_matrices(values: Mapping[str, float]):
    """``A, B, C, D`` of the quarter car with inputs ``[zr, fa]`` and outputs
    `OUTPUT_LABELS` (the wheel's acceleration as the second row of ``A x + B u``)."""
    A, B, C, D = quarter_car_abcd(
        values["ms"],
        values["mu"],
        values["ks"],
        values["ku"],
        values["cs"],
        road=True,
        actuator=True,
        cu=values["cu"],
    )
    C = np.concatenate([C, A[None, 1, :]])
    D = np.concatenate([D, B[None, 1, :]])
    return A, B, C, D


def simulate_quarter(
    values: Mapping[str, float],
    measurement: Measurement,
    outputs: Sequence[str],
    gains: Mapping[str, float] | None = None,
    x0: np.ndarray | None = None,
) -> np.ndarray:
    """The quarter car's outputs, exact, under a measurement's inputs.

    Parameters
    ----------
    values : mapping
        ``ms, mu, ks, ku, cs, cu``.
    measurement : Measurement
        Its ``zr`` and ``fa`` are the inputs (zero where absent), each times
        its gain.
    outputs : sequence of str
        Labels among `OUTPUT_LABELS`.
    gains : mapping, optional
        ``{input: gain}``: the model's input is ``gain × recorded``.
    x0 : array, shape (4,), optional
        The initial state; by default the car at rest in equilibrium with
        the first input samples.

    Returns
    -------
    ndarray, shape (len(outputs), N)
    """
    gains = gains or {}
    A, B, C, D = _quarter_matrices(values)
    N = len(measurement)
    U = np.zeros((2, N))
    for i, label in enumerate(INPUT_LABELS):
        if label in measurement.signals:
            U[i] = gains.get(label, 1.0) * measurement[label]
    rows = [OUTPUT_LABELS.index(k) for k in outputs]
    if x0 is None:  # at rest: x' = 0 under the first input
        x0 = rest_state(A, B, U[:, 0])
    y = exact_outputs(A, B, C[rows], D[rows], measurement.dt, U, x0)
    if values["cu"] and "wheel_acc" in outputs:
        # the wheel's acceleration is q' + (cu/mu) zr' (the state q hides the road's rate):
        # the one place the recorded road is differentiated, for this output only
        zr_rate = np.gradient(U[0], measurement.dt)
        y[list(outputs).index("wheel_acc")] += values["cu"] / values["mu"] * zr_rate
    return y


def _decode(name: str, theta: float) -> float:
    """A physical value from its fitted coordinate (module note: ``cu`` as it is)."""
    return float(theta) if name in LINEAR else float(np.exp(theta))


def _encode(name: str, value: float) -> float:
    return float(value) if name in LINEAR else math.log(value)


@dataclass
class _Problem:
    """What the optimiser varies and how the values of the car follow from it."""

    measurement: Measurement
    outputs: tuple[str, ...]
    base: dict[str, float]  # every physical value (the fixed ones final)
    free: tuple[str, ...]  # physical parameters fitted (as logarithms)
    gains: tuple[str, ...]  # inputs whose gain is fitted
    estimate_x0: bool
    weights: np.ndarray  # 1 / RMS of each measured output

    def names(self) -> list[str]:
        x0 = ["x0_vs", "x0_vu", "x0_xs", "x0_xu"] if self.estimate_x0 else []
        return list(self.free) + [f"gain_{g}" for g in self.gains] + x0

    def unpack(self, theta: np.ndarray):
        values = dict(self.base)
        k = len(self.free)
        with np.errstate(over="ignore"):  # a runaway trial step: an inf car, flagged later
            values.update((n, _decode(n, v)) for n, v in zip(self.free, theta[:k]))
        gains = dict(zip(self.gains, theta[k : k + len(self.gains)]))
        x0 = theta[k + len(self.gains) :] if self.estimate_x0 else None
        return values, gains, x0

    def simulate(self, theta: np.ndarray) -> np.ndarray:
        values, gains, x0 = self.unpack(theta)
        return simulate_quarter(values, self.measurement, self.outputs, gains, x0)

    def measured(self) -> np.ndarray:
        return np.stack([self.measurement[k] for k in self.outputs])

    def lower_bounds(self) -> np.ndarray:
        """0 for a parameter fitted as it is (``cu``), none for the rest."""
        low = np.full(len(self.names()), -np.inf)
        low[[i for i, n in enumerate(self.free) if n in LINEAR]] = 0.0
        return low

    def solve(self, residuals, theta0: np.ndarray):
        """`scipy.optimize.least_squares` of ``residuals`` from ``theta0`` (trust region,
        the bounds of `lower_bounds`)."""
        return scipy.optimize.least_squares(
            residuals,
            theta0,
            bounds=(self.lower_bounds(), np.inf),
            method="trf",
            x_scale="jac",
            xtol=1e-12,
            ftol=1e-12,
        )

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        # a trial car the model refuses (modes 1e7 apart) or whose response overflows: a
        # huge finite misfit makes the trust region reject that step, where a NaN would
        # end the fit in the SVD of a Jacobian ("array must not contain infs or NaNs")
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                e = (self.simulate(theta) - self.measured()) * self.weights[:, None]
        except ValueError:
            return np.full(self.weights.size * len(self.measurement), UNPHYSICAL_MISFIT)
        return np.clip(
            np.nan_to_num(e, nan=UNPHYSICAL_MISFIT), -UNPHYSICAL_MISFIT, UNPHYSICAL_MISFIT
        ).ravel()


@dataclass
class Identification:
    """The result of `identify`.

    Attributes
    ----------
    params : QuarterCarParams
        The identified car (undetermined values at their start, see
        ``undetermined``).
    model : VehicleModel
        The identified car with inputs ``zr`` and ``fa``.
    gains : dict
        ``{input: gain}``: the model's input is ``gain × recorded``.
    x0 : ndarray
        The initial state used (at rest, or estimated).
    table : pandas.DataFrame
        One row per fitted quantity: ``estimate``, ``std_error``,
        ``ci_low``, ``ci_high`` (95 %; from 0 for ``cu``, bounded there),
        ``unit``, ``determined``, and ``intervals``: ``'95 %'``, or
        ``'unreliable'`` when a residual is not white or a parameter ran away.
    correlation : pandas.DataFrame
        The estimates' correlation matrix.
    fit : pandas.Series
        NRMSE fit [%] of each output.
    whiteness : pandas.DataFrame
        Per output: the fraction of autocorrelation lags outside the 95 %
        band and whether the residual passes as white.
    undetermined : tuple of str
        Parameters the records do not determine.
    ratios : pandas.DataFrame or None
        When absolute values are undetermined, the ratios that are:
        ``ks/ms``, ``cs/ms``, ``ku/ms``, ``mu/ms`` (and ``cu/ms``, gains
        over ``ms``) with 95 % intervals.
    notes : list of str
        What the fit assumed or could not do, in words.
    outputs : tuple of str
    success : bool
        The optimiser converged and no parameter ran away (see ``notes``).
    nfev : int
        Residual evaluations the optimiser made.
    """

    params: QuarterCarParams
    model: VehicleModel
    gains: dict[str, float]
    x0: np.ndarray
    table: pd.DataFrame
    correlation: pd.DataFrame
    fit: pd.Series
    whiteness: pd.DataFrame
    undetermined: tuple[str, ...]
    ratios: pd.DataFrame | None
    notes: list[str]
    outputs: tuple[str, ...]
    success: bool
    nfev: int
    values: dict[str, float] = field(repr=False, default_factory=dict)
    #: The records' transmissibility a frequency-domain fit fitted (None in the time domain).
    transmissibility: Transmissibility | None = field(repr=False, default=None)

    def simulate(self, measurement: Measurement, *, at_rest: bool = True) -> np.ndarray:
        """The identified car's outputs under ``measurement``'s inputs, ``(outputs, N)``.

        The record is taken to start at rest (``at_rest``), as a held-out
        one is; False starts from the identified ``x0``.
        """
        x0 = None if at_rest else self.x0
        return simulate_quarter(self.values, measurement, self.outputs, self.gains, x0)

    def validate(self, other: Measurement) -> pd.Series:
        """The fit [%] of each output on a second, held-out measurement."""
        missing = [k for k in self.outputs if k not in other.signals]
        if missing:
            raise ValueError(f"the validation record lacks the output(s) {missing}")
        y = self.simulate(other)
        fits = {k: nrmse_fit(other[k], y[i]) for i, k in enumerate(self.outputs)}
        return pd.Series(fits, name="fit [%]")

    def __str__(self) -> str:
        lines = ["Identified quarter car", self.table.to_string(float_format="{:.6g}".format)]
        if self.ratios is not None:
            lines += ["Determined ratios", self.ratios.to_string(float_format="{:.6g}".format)]
        lines += ["Fit [%]", self.fit.to_string(float_format="{:.2f}".format)]
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)


def _as_names(
    values: Iterable[str] | None, what: str, allowed: Sequence[str], argument: str
) -> tuple[str, ...]:
    """``values`` as names among ``allowed``, each once; a refusal names ``argument``."""
    names = tuple(values or ())
    for i, name in enumerate(names):
        if name not in allowed:
            raise ParameterError(
                argument,
                name,
                f"one of {', '.join(allowed)}",
                message=f"{what} {name!r} is not one of {', '.join(allowed)}",
            )
        if name in names[:i]:
            raise ParameterError(
                argument, name, "each name once", message=f"{what} {name!r} is given twice"
            )
    return names


def _positive_values(values: Mapping[str, Any] | None, what: str) -> dict[str, float]:
    """``values`` checked: known names, each a finite value > 0 in its unit (>= 0 for
    the parameters fitted as they are, ``cu``)."""
    out = {}
    for name, value in (values or {}).items():
        choice(f"{what} parameter", name, PHYSICAL)
        check = nonnegative if name in LINEAR else positive
        out[name] = check(name, value, _UNITS[name], description=f"{what} value")
    return out


def _setup(
    measurement, free, fixed, start, gains, outputs, entry
) -> tuple[dict, tuple, tuple, tuple]:
    """Checked arguments: the start values, free parameters, gains and outputs."""
    if not isinstance(measurement, Measurement):
        raise TypeError(f"measurement must be a Measurement, got {type(measurement).__name__}")
    if not measurement.inputs:
        raise ValueError("the measurement has no input: record the road zr or the force fa")
    fixed_values = _positive_values(fixed, "fixed")
    start_values = _positive_values(start, "start")
    free_names = _as_names(
        DEFAULT_FREE if free is None else free, "free parameter", PHYSICAL, "free"
    )
    both = [n for n in free_names if n in fixed_values] if free is not None else []
    if both:
        raise ValueError(f"{both[0]!r} is both free and fixed: give it in one of them")
    free_names = tuple(n for n in free_names if n not in fixed_values)
    gain_names = _as_names(gains, "gain", measurement.inputs, "gains")
    if not free_names and not gain_names:
        raise ValueError("nothing to fit: every parameter is fixed and no gain is free")
    outs = _as_names(
        [k for k in measurement.outputs if k in OUTPUT_LABELS] if outputs is None else outputs,
        "output",
        [k for k in measurement.outputs if k in OUTPUT_LABELS],
        "outputs",
    )
    if not outs:
        raise ValueError(
            f"the measurement has no output the model gives; expected one of {OUTPUT_LABELS}"
        )
    for k in measurement.inputs:
        if np.ptp(measurement[k]) == 0:  # a dead channel: S_uu singular, or no excitation
            raise ValueError(
                f"input {k!r} is constant ({float(measurement[k][0]):.6g} throughout): a dead "
                f"channel? leave it out of the records (--map without {k})"
            )
    for k in outs:
        x = measurement[k]
        if np.ptp(x) == 0:  # nothing to fit to, and a whiteness test of a constant
            raise ValueError(
                f"output {k!r} is constant ({float(x[0]):.6g} throughout): a dead sensor? "
                "leave it out (outputs=[...], --outputs)"
            )
    seed = entry.params()
    base = {n: float(getattr(seed, n)) for n in PHYSICAL}
    if "cu" in free_names:
        base["cu"] = CU_START
    base.update(start_values)
    base.update(fixed_values)
    _check_sampling(measurement, base)
    return base, free_names, gain_names, outs


def _check_sampling(measurement: Measurement, base: Mapping[str, float]) -> None:
    """Refuse records sampled below the start car's body mode (its lowest natural
    frequency), naming the time column: a time column in ms read as seconds samples
    a thousand times too slowly, and the fit then overflows with a message of scipy's
    ("array must not contain infs or NaNs") that names nothing of the records."""
    A, _, _, _ = _quarter_matrices(base)
    body = float(np.min(np.abs(np.linalg.eigvals(A)))) / (2 * np.pi)
    nyquist = 0.5 / measurement.dt
    if nyquist < body:
        column = getattr(measurement, "time_column", "t")
        raise ValueError(
            f"the records are sampled every {measurement.dt:.6g} s ({1 / measurement.dt:.3g} "
            f"Hz): too slowly for a car whose body mode is near {body:.2g} Hz. Is the time "
            f"column {column!r} in ms? Give its unit (units={{{column!r}: 'ms'}}, --units "
            f"{column}=ms)"
        )


def _scale_free(base, free, gains, measurement) -> bool:
    """Whether the records leave the absolute scale undetermined (see the module's note)."""
    pinned = any(base[n] > 0 and n not in free for n in PHYSICAL)
    force_known = "fa" in measurement.inputs and "fa" not in gains
    return not pinned and not force_known


@one_blas_thread
def identify(
    measurement: Measurement,
    model: str = "quarter",
    *,
    free: Iterable[str] | None = None,
    fixed: Mapping[str, float] | None = None,
    start: Mapping[str, float] | None = None,
    gains: Iterable[str] = (),
    outputs: Iterable[str] | None = None,
    x0: str = "rest",
    domain: str = "time",
    resolution: float | None = None,
    band: tuple[float, float] | None = None,
) -> Identification:
    """Fit the quarter car to measured records by output error, or to their transmissibility.

    Parameters
    ----------
    measurement : Measurement
        Inputs ``zr`` and/or ``fa``; outputs among `OUTPUT_LABELS`.
    model : {'quarter'}
        The model fitted: a registered model whose entry names ``fit_parameters``
        (`qc_control.models.registry`), the quarter car with its tire
        damping ``cu``.
    free : iterable of str, optional
        Parameters to fit among ``ms, mu, ks, ku, cs, cu``; default all
        (less those ``fixed``). ``cu`` is fitted as it is, bounded by 0, and
        starts at `CU_START` unless given; the rest as logarithms.
    fixed : mapping, optional
        ``{name: value}`` held at known values (a weighed mass).
    start : mapping, optional
        ``{name: value}`` to start from; the seed's car otherwise.
    gains : iterable of str
        Inputs whose gain (scale and sign) is fitted too: the model's input
        is ``gain × recorded``. Starts at 1.
    outputs : iterable of str, optional
        The measured outputs fitted; default all that the model gives.
    x0 : {'rest', 'estimate'}
        The record starts at rest (in equilibrium with its first inputs),
        or its initial state is fitted too.
    domain : {'time', 'frequency'}
        Output error on the time records, or a fit of the records'
        transmissibility (multi-input H1 estimate, coherence-weighted;
        `qc_control.studies.frequency_identification`) for sine-sweep or
        random rig tests, where the start at rest does not matter.
    resolution : float, optional
        The frequency domain's bin spacing [Hz]; default 16 Welch averages.
    band : (float, float), optional
        The frequency domain's fitted frequencies [Hz]; default all but DC.

    Returns
    -------
    Identification

    Raises
    ------
    ValueError
        For an unknown model, parameter, gain or output, a value <= 0, a
        measurement without inputs or fitted outputs, a constant input or
        output, records sampled below the car's body mode (a time column in
        ms), a start with no finite response, or a fit that runs away to a
        car the model cannot hold. A fit that runs away to a car it can hold
        is returned with ``success`` False, its intervals marked unreliable
        and a note.
    """
    entry = _identifiable(model)
    choice("x0", x0, ("rest", "estimate"))
    choice("domain", domain, ("time", "frequency"))
    if domain == "frequency":
        if x0 != "rest":
            raise ValueError("x0='estimate' applies to the time domain only")
        return _identify_frequency(
            measurement, (free, fixed, start, gains, outputs, entry), resolution, band
        )
    if resolution is not None or band is not None:
        raise ValueError("resolution and band apply to domain='frequency' only")
    problem, theta0, pinned_for_scale = _problem(
        measurement, (free, fixed, start, gains, outputs, entry), x0 == "estimate"
    )
    notes = list(measurement.notes)
    _check_start(problem.simulate, theta0, problem)
    solution = problem.solve(problem.residuals, theta0)
    if not solution.success:
        notes.append(f"the optimiser stopped: {solution.message}")
    return _result(problem, solution, pinned_for_scale, notes)


def _identifiable(model: str) -> ModelEntry:
    """The registry's entry of ``model``, if `identify` can fit it (it names
    ``fit_parameters``)."""
    fits = [name for name, entry in MODELS.items() if entry.fit_parameters]
    entry = MODELS.get(model) if isinstance(model, str) else None
    if entry is None or not entry.fit_parameters:
        raise ParameterError("model", model, " or ".join(map(repr, fits)))
    return entry


def _problem(measurement, arguments, estimate_x0: bool) -> tuple[_Problem, np.ndarray, bool]:
    """The problem of `identify`'s ``arguments`` (``free, fixed, start, gains, outputs,
    entry``), its start, and whether ``ms`` is held for the scale (module note)."""
    base, free_names, gain_names, outs = _setup(measurement, *arguments)
    pinned = _scale_free(base, free_names, gain_names, measurement) and "ms" in free_names
    fitted = tuple(n for n in free_names if not (pinned and n == "ms"))
    rms = np.array([np.sqrt(np.mean(measurement[k] ** 2)) for k in outs])
    problem = _Problem(measurement, outs, base, fitted, gain_names, estimate_x0, 1.0 / rms)
    theta0 = np.concatenate(
        [[_encode(n, base[n]) for n in fitted], np.ones(len(gain_names)), np.zeros(4 * estimate_x0)]
    )
    if estimate_x0:  # start from rest in equilibrium with the first inputs
        theta0[len(fitted) + len(gain_names) :] = _rest_state(problem, theta0)
    return problem, theta0, pinned


def _check_start(respond, theta0: np.ndarray, problem: _Problem) -> None:
    """Refuse a start whose response to the records (``respond(theta0)``) is not finite,
    saying what to check (the optimiser's own message, "Residuals are not finite in the
    initial point", names none of the user's data)."""
    with np.errstate(all="ignore"):
        try:
            finite = bool(np.all(np.isfinite(respond(theta0))))
        except (ValueError, np.linalg.LinAlgError):  # a start car that cannot be built
            finite = False
    if not finite:
        values, _, _ = problem.unpack(theta0)
        start = ", ".join(f"{n}={values[n]:.6g}" for n in PHYSICAL)
        raise ValueError(
            f"the start car ({start}) gives no finite response to the records' inputs "
            f"{', '.join(problem.measurement.inputs)}: check their units and magnitudes "
            "(a road in mm read as metres), or give start values near the car (start=, --start)"
        )


def _rest_state(problem: _Problem, theta: np.ndarray) -> np.ndarray:
    values, gains, _ = problem.unpack(theta)
    A, B, _, _ = _quarter_matrices(values)
    signals = problem.measurement.signals
    u0 = [gains.get(k, 1.0) * signals[k][0] if k in signals else 0.0 for k in INPUT_LABELS]
    return rest_state(A, B, u0)


def _covariance(n_out: int, J: np.ndarray, residual: np.ndarray):
    """The sandwich covariance (module note) and the directions not determined;
    the residual holds ``n_out`` outputs' blocks of equal length."""
    p = J.shape[1]
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0
    Js = J / norms  # column scaling: the rank test then sees directions, not units
    _, s, Vt = np.linalg.svd(Js, full_matrices=False)
    null = s < RANK_TOLERANCE * s[0]
    N = residual.size // n_out
    Jo = Js.reshape(n_out, N, p)
    eo = residual.reshape(n_out, N)
    sigma2 = np.sum(eo**2, axis=1) / max(N - p / n_out, 1.0)
    inv = np.linalg.pinv(Js.T @ Js, rcond=RANK_TOLERANCE**2)
    meat = sum(sigma2[i] * Jo[i].T @ Jo[i] for i in range(n_out))
    cov = inv @ meat @ inv / np.outer(norms, norms)
    # a parameter with a weight over 1 % in a null direction is not determined
    undetermined = np.any(np.abs(Vt[null]) > 0.01, axis=0) if null.any() else np.zeros(p, bool)
    return cov, undetermined


def _table(names, theta, cov, undetermined, n_physical) -> pd.DataFrame:
    se = np.sqrt(np.clip(np.diag(cov), 0, None))
    rows = []
    for i, name in enumerate(names):
        if i < n_physical and name in LINEAR:  # as it is, bounded by 0: so is its interval
            value, std = float(theta[i]), float(se[i])
            low, high = max(value - Z95 * std, 0.0), value + Z95 * std
            unit = _UNITS[name]
        elif i < n_physical:  # fitted as a logarithm: the interval is exp of a symmetric one
            # a runaway's logarithm may overflow exp: inf, flagged by _runaway
            with np.errstate(over="ignore"):
                value, low, high = np.exp(theta[i] + np.array([0.0, -Z95, Z95]) * se[i]).tolist()
            std = value * se[i]
            unit = _UNITS[name]
        else:
            value, std = float(theta[i]), float(se[i])
            low, high = value - Z95 * std, value + Z95 * std
            unit = "-" if name.startswith("gain_") else ("m/s" if name[3] == "v" else "m")
        rows.append((name, value, std, low, high, unit, not undetermined[i]))
    columns = ["parameter", "estimate", "std_error", "ci_low", "ci_high", "unit", "determined"]
    return pd.DataFrame(rows, columns=columns).set_index("parameter")


def _ratios(table: pd.DataFrame, ms: float) -> pd.DataFrame:
    """The ratios to ``ms`` (held at its start): each one's interval is its parameter's."""
    rows = []
    for name in table.index:
        if name.startswith("x0_"):
            continue
        row = table.loc[name]
        unit = {"mu": "-", "ks": "1/s²", "ku": "1/s²", "cs": "1/s", "cu": "1/s"}.get(name, "1/kg")
        rows.append((f"{name}/ms", row.estimate / ms, row.ci_low / ms, row.ci_high / ms, unit))
    columns = ["ratio", "estimate", "ci_low", "ci_high", "unit"]
    return pd.DataFrame(rows, columns=columns).set_index("ratio")


def _intervals_trusted(table: pd.DataFrame, white: pd.DataFrame, problem: _Problem, notes) -> None:
    """Mark the intervals unreliable when a residual is not white.

    The 95 % intervals assume residuals that are independent noise; a residual
    whose autocorrelation leaves the band (`whiteness`) holds what the model
    cannot represent, and the intervals are then too narrow: the shipped rig
    record fitted with its tire damping fixed at 0 puts mu at 40.7 kg within
    [40.62, 40.76] kg, the truth being 45. The table's ``intervals`` column
    and a note say so, and name the parameters held fixed that could be freed.
    """
    coloured = [str(k) for k, row in white.iterrows() if not bool(row["white"])]
    table["intervals"] = "unreliable" if coloured else "95 %"
    if not coloured:
        return
    held = [n for n in PHYSICAL if n not in problem.free]
    notes.append(
        f"the residuals of {', '.join(coloured)} are not white: the model misses something "
        "the records hold, so the 95 % intervals are too narrow to trust"
        + (f"; free a parameter held fixed ({', '.join(held)}), " if held else "; ")
        + "or check the records' units and channels"
    )


def _runaway(problem: _Problem, values: Mapping[str, float]) -> list[str]:
    """The fitted parameters that ran away, each in words (empty: none).

    A parameter the records do not pin drifts where the optimiser's steps take it:
    a logarithm more than `RUNAWAY_FACTOR` from its start, or a tire damping above
    the wheel's critical damping on its tire ``2 √(ku mu)`` (a tire's damping ratio
    is a few per cent; Wong, *Theory of Ground Vehicles*, §1.6). Its interval is
    then of no use (zero width, or an overflow), and the car it implies is not one
    the rig holds. A value that is not finite cannot be reported at all.
    """
    found = []
    for name in problem.free:
        value, start = values[name], problem.base[name]
        if not math.isfinite(value):
            raise ValueError(
                f"the fit of {name} ran away to {value}: the records do not determine it; "
                f"fix it at a known value (fixed={{'{name}': ...}}, --fix {name}=...) or "
                "fit outputs that respond to it"
            )
        if name in LINEAR:
            critical = 2.0 * math.sqrt(values["ku"] * values["mu"])
            if value > critical:
                found.append(
                    f"{name} = {value:.4g} {_UNITS[name]}, above the wheel's critical damping "
                    f"on its tire (2√(ku mu) = {critical:.4g} {_UNITS[name]})"
                )
        elif not 1.0 / RUNAWAY_FACTOR <= value / start <= RUNAWAY_FACTOR:
            found.append(f"{name} = {value:.4g} {_UNITS[name]}, from a start of {start:.4g}")
    return found


def _flag_runaway(problem: _Problem, values, table: pd.DataFrame, notes) -> bool:
    """Mark the intervals unreliable and say so when a parameter ran away (`_runaway`);
    whether none did."""
    runaway = _runaway(problem, values)
    try:
        QuarterCarParams(**{n: values[n] for n in PHYSICAL})
    except ValueError as exc:  # modes 1e7 apart, or an overflow: no car to report
        found = f" ({'; '.join(runaway)})" if runaway else ""
        raise ValueError(
            f"the fit ran away{found} to a car the model cannot hold: {exc}. The records "
            "do not determine it: check the records' units (a road in mm read as metres: "
            "units={'zr': 'mm'}, --units zr=mm), fix a known mass (--fix ms=...) or fit "
            "outputs that respond to every parameter"
        ) from None
    if runaway:
        table["intervals"] = "unreliable"
        notes.append(
            f"the fit ran away: {'; '.join(runaway)}. The records do not pin "
            f"{'it' if len(runaway) == 1 else 'them'}, so the result is not a car the records "
            "determine: fix such a parameter at a known value (fixed=, --fix; a tire "
            "without damping: cu=0), or fit outputs that respond to it"
        )
    return not runaway


def _fit_and_whiteness(problem: _Problem, theta: np.ndarray) -> tuple[pd.Series, pd.DataFrame]:
    """The NRMSE fit [%] of each output and its residual's whiteness."""
    y = problem.simulate(theta)
    measured = problem.measured()
    fit = pd.Series(
        {k: nrmse_fit(measured[i], y[i]) for i, k in enumerate(problem.outputs)}, name="fit [%]"
    )
    white = [whiteness(measured[i] - y[i]) for i in range(len(problem.outputs))]
    return fit, pd.DataFrame(white, index=list(problem.outputs), columns=["lags_outside", "white"])


def _result(problem: _Problem, solution, pinned_for_scale, notes, covariance=None):
    """The `Identification` of a solved problem; ``covariance`` is ``(cov,
    undetermined)`` when the fit was not this problem's (the frequency domain)."""
    names = problem.names()
    theta = solution.x
    if covariance is None:
        covariance = _covariance(len(problem.outputs), solution.jac, solution.fun)
    cov, undetermined = covariance
    table = _table(names, theta, cov, undetermined, len(problem.free))
    sd = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    correlation = pd.DataFrame(cov / np.outer(sd, sd), index=names, columns=names)
    values, gains, x0 = problem.unpack(theta)
    settled = _flag_runaway(problem, values, table, notes)
    if x0 is None:
        x0 = _rest_state(problem, theta)
    fit, whiteness_table = _fit_and_whiteness(problem, theta)
    if settled:
        _intervals_trusted(table, whiteness_table, problem, notes)
    # at the bound: the trust region stays strictly inside it, so "0" is a value a
    # millionth of its own interval's width or less
    at_zero = table["estimate"].to_numpy(float) <= 1e-6 * table["ci_high"].to_numpy(float)
    bound = [n for n, z in zip(names, at_zero) if z and n in LINEAR and n in problem.free]
    if bound:
        notes.append(
            f"{', '.join(bound)} is at its bound 0: the records show no tire damping; its "
            "interval is one-sided, from 0"
        )
    undetermined_names = [n for n, u in zip(names, undetermined) if u]
    ratios = None
    if pinned_for_scale:
        undetermined_names = ["ms", *undetermined_names]
        ratios = _ratios(table, values["ms"])
        notes.append(
            "the records leave the absolute scale undetermined (the road is the only known "
            "input, or the force's gain is free): ms is held at "
            f"{values['ms']:.6g} kg and every other value follows it; the ratios to ms are "
            "determined. Fix a mass (fixed={'ms': ...}) for absolute values"
        )
    elif undetermined_names:
        notes.append(
            "the Jacobian is rank deficient: the records do not determine "
            + ", ".join(undetermined_names)
        )
    params = QuarterCarParams(**{n: values[n] for n in PHYSICAL})
    return Identification(
        params=params,
        model=quarter_car_model(params, road=True, actuator=True),
        gains=gains,
        x0=np.asarray(x0, dtype=float),
        table=table,
        correlation=correlation,
        fit=fit,
        whiteness=whiteness_table,
        undetermined=tuple(undetermined_names),
        ratios=ratios,
        notes=notes,
        outputs=problem.outputs,
        success=bool(solution.success) and settled,
        nfev=int(solution.nfev),
        values=values,
    )


# ------------------------------------------------------------ the frequency domain


def quarter_response(values, frequency, outputs, inputs, dt: float) -> np.ndarray:
    """The quarter car's exact response ``(outputs, inputs, F)`` between samples ``dt``
    apart (`sampled_response`): what `simulate_quarter` gives, bin by bin.

    A tire damping's share of the wheel's acceleration is `simulate_quarter`'s
    central difference of the road, ``j sin(2πf Δt) / Δt`` in the frequency domain.
    """
    A, B, C, D = _quarter_matrices(values)
    columns = [INPUT_LABELS.index(k) for k in inputs]
    rows = [OUTPUT_LABELS.index(k) for k in outputs]
    H = sampled_response(A, B[:, columns], C[rows], D[np.ix_(rows, columns)], frequency, dt)
    if values["cu"] and "wheel_acc" in outputs and "zr" in inputs:
        rate = 1j * np.sin(2 * np.pi * np.asarray(frequency) * dt) / dt
        share = values["cu"] / values["mu"] * rate
        H[:, list(outputs).index("wheel_acc"), list(inputs).index("zr")] += share
    return np.transpose(H, (1, 2, 0))


@dataclass
class _FrequencyFit:
    """The misfit of the car's transmissibility to the estimate, each bin in its SDs."""

    problem: _Problem
    estimate: Transmissibility
    weights: np.ndarray  # (outputs, inputs, F): 1 / the SD of each bin's relative error

    def response(self, theta: np.ndarray) -> np.ndarray:
        """The car's transmissibility at the estimate's bins, its gains applied."""
        values, gains, _ = self.problem.unpack(theta)
        est, dt = self.estimate, self.problem.measurement.dt
        with np.errstate(over="ignore", invalid="ignore"):
            H = quarter_response(values, est.frequency, est.outputs, est.inputs, dt)
        return H * np.array([gains.get(k, 1.0) for k in est.inputs])[None, :, None]

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        # a trial step to an absurd car (a mode far beyond the sampling rate) overflows
        # exp(A dt), or the model refuses it (modes 1e7 apart): a huge finite misfit makes
        # the trust region reject that step, where a NaN would end the fit in its SVD
        try:
            e = (self.response(theta) - self.estimate.response) * self.weights
        except ValueError:
            return np.full(2 * self.estimate.response.size, UNPHYSICAL_MISFIT)
        r = np.stack([e.real, e.imag], axis=2).ravel()
        return np.clip(
            np.nan_to_num(r, nan=UNPHYSICAL_MISFIT), -UNPHYSICAL_MISFIT, UNPHYSICAL_MISFIT
        )


def _identify_frequency(measurement, arguments, resolution, band) -> Identification:
    """`identify` with ``domain='frequency'``: the car's exact response fitted to the
    records' multi-input H1 transmissibility, each bin weighted by its coherence
    (`qc_control.studies.frequency_identification`); ``arguments`` are `identify`'s
    ``free, fixed, start, gains, outputs, entry``."""
    problem, theta0, pinned = _problem(measurement, arguments, False)
    outs = problem.outputs
    lo_hi = check_band(band, measurement)
    estimate = transmissibility(measurement, measurement.inputs, outs, resolution=resolution)
    fit = _FrequencyFit(problem, estimate, bin_weights(estimate, lo_hi))
    notes = list(measurement.notes)
    notes.append(
        f"fitted in the frequency domain: the multi-input H1 transmissibility of "
        f"{', '.join(measurement.inputs)} to {', '.join(outs)}, {estimate.resolution:.4g} Hz "
        f"bins from {estimate.averages} Welch averages, {lo_hi[0]:g}–{lo_hi[1]:g} Hz, "
        f"each bin weighted by its coherence and by each input's own share of it"
    )
    _check_start(fit.response, theta0, problem)
    solution = problem.solve(fit.residuals, theta0)
    if not solution.success:
        notes.append(f"the optimiser stopped: {solution.message}")
    covariance = _covariance(len(outs), np.asarray(solution.jac), solution.fun)
    result = _result(problem, solution, pinned, notes, covariance=covariance)
    result.transmissibility = estimate
    width = _body_mode_width(result.values)
    if estimate.resolution > LEAKAGE_FRACTION * width:
        result.notes.append(
            f"the {estimate.resolution:.3g} Hz bins are coarse against the body resonance's "
            f"{width:.3g} Hz half-power width: Welch's leakage biases the estimates, the "
            f"more the coarser the bins (3 % in ks at half the width); a longer record and "
            f"a finer resolution "
            f"(<= {LEAKAGE_FRACTION * width:.2g} Hz) avoid it"
        )
    return result


def _body_mode_width(values: Mapping[str, float]) -> float:
    """The half-power width ``2 ζ f`` [Hz] of the car's body mode (the less damped
    of its two oscillatory modes is at the lower frequency for a car)."""
    A, _, _, _ = _quarter_matrices(values)
    poles = np.linalg.eigvals(A)
    body = min((p for p in poles if p.imag > 0), key=abs, default=None)
    if body is None:  # an overdamped body: no resonance to resolve
        return math.inf
    return float(-2 * body.real / (2 * np.pi))
