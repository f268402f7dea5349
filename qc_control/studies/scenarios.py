"""Two runs where the choice of integrator decides the answer: the pothole and the stiff car.

**The pothole.** The seed's car at rest meets a 5 cm deep, 0.3 m long
(1 − cos) pothole at t = 1 s at 20 m/s, sampled at 1 ms over 0–3 s.
``control.forced_response`` (exact for an input linear between samples)
gives a peak body displacement of 2.743 mm and a peak suspension travel of
2.552 mm. ``control.input_output_response`` at its defaults (solve_ivp RK45,
rtol 1e-3, atol 1e-6) starts from rest with a long step and steps over the
pothole: every state stays 0 (python-control issue #1152 is the same
failure on a delayed impulse). A fixed step cannot step over a sample.

**The stiff car.** The seed's damper on a rubber top mount
(`qc_control.models.quarter.mounted_abcd`, a Maxwell element) of 1e7 N/m:
a real mode at -6,633 1/s beside the body's -0.46 ± 6.8j, so RK4's step
limit falls from 109 ms to 0.42 ms, on 60 s of an ISO 8608 class C road at
20 m/s. The exact reference is ``control.forced_response`` on the same
sampled road; an L-stable implicit method steps it at 5 ms.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..models.quarter import quarter_car_model
from ..models.vehicle import VehicleModel
from ..numerics import checks
from ..numerics import methods as catalogue
from ..numerics.methods import METHODS
from ..ride import road as roads
from .compare import DEFAULT_METHODS, MethodComparison, compare_methods
from .peers import SOLVERS
from .ride_cost import RIDE_TARGET, RideCost, ride_cost

__all__ = [
    "POTHOLE",
    "STIFF_CAR",
    "Pothole",
    "StiffCar",
    "pothole_road",
    "pothole_comparison",
    "stiff_car_model",
    "stiff_car_methods",
    "stiff_car_comparison",
    "stiff_car_ride_cost",
    "peak_table",
]

#: L-stable implicit tableaus the stiff car's comparison adds when they are known by name.
_L_STABLE = ("backward_euler", "sdirk2", "radau2", "radau3")


class _Grid:
    """A run's ``grid = (t_end, h)`` [s] by name."""

    grid: tuple[float, float]

    @property
    def t_end(self) -> float:
        """The run's span [s]."""
        return self.grid[0]

    @property
    def h(self) -> float:
        """The sample spacing [s]."""
        return self.grid[1]


@dataclass(frozen=True)
class Pothole(_Grid):
    """The pothole run: a 1 − cos dip met at ``t0`` [s] at ``speed`` [m/s].

    Attributes
    ----------
    depth, length : float
        [m]; the road goes down by ``depth`` over ``length``.
    speed : float
        [m/s].
    t0 : float
        When the wheel reaches the pothole [s].
    grid : (float, float)
        The run's span ``t_end`` and sample spacing ``h`` [s].
    """

    depth: float = 0.05
    length: float = 0.3
    speed: float = 20.0
    t0: float = 1.0
    grid: tuple[float, float] = (3.0, 0.001)

    def road(self) -> dict:
        """The road as the Scenario's table: a bump of negative height."""
        shape = dict(height=-self.depth, length=self.length, speed=self.speed, t0=self.t0)
        return {"kind": "bump", **shape}

    def describe(self) -> str:
        """The pothole in words, for the report."""
        depth, length = f"{self.depth * 100:g} cm", f"{self.length:g} m"
        return f"a {depth} deep, {length} long 1 − cos pothole met at t = {self.t0:g} s at " + (
            f"{self.speed:g} m/s"
        )


@dataclass(frozen=True)
class StiffCar(_Grid):
    """The stiff car's run: the mount, the road and the step.

    Attributes
    ----------
    mount_stiffness : float
        The damper's top mount [N/m].
    road_class : str
        ISO 8608 class.
    speed : float
        [m/s].
    seed : int
        The road's random phases.
    grid : (float, float)
        ``t_end`` and ``h`` [s]; h = 5 ms samples the standard band at 20 m/s
        (limit 8.8 ms).
    """

    mount_stiffness: float = 1e7
    road_class: str = "C"
    speed: float = 20.0
    seed: int = 0
    grid: tuple[float, float] = (60.0, 0.005)

    def road(self) -> dict:
        """The road as the Scenario's table."""
        return dict(kind="iso8608", road_class=self.road_class, speed=self.speed, seed=self.seed)


#: The defaults of the two runs.
POTHOLE = Pothole()
STIFF_CAR = StiffCar()


def pothole_road(T, depth: float = 0.05, length: float = 0.3, speed: float = 20.0, t0: float = 1.0):
    """The pothole's road height [m] on ``T`` [s]: a 1 − cos bump of height ``-depth``."""
    depth = checks.positive("depth", depth, "m", description="the pothole's depth")
    return roads.bump(T, height=-depth, length=length, speed=speed, t0=t0)


def pothole_comparison(
    run: Pothole = POTHOLE,
    *,
    params=None,
    methods: Sequence = DEFAULT_METHODS,
    solvers: Sequence[str] | None = SOLVERS,
    **options,
) -> MethodComparison:
    """The methods and the peers on the pothole (`compare_methods`, the car at rest).

    ``options`` go to `compare_methods` (``repeats``, ``timing``, ``rtols``...).
    """
    T = np.linspace(0.0, run.t_end, round(run.t_end / run.h) + 1)
    U = pothole_road(T, run.depth, run.length, run.speed, run.t0)
    model = quarter_car_model(params, road=True)
    return compare_methods(
        model,
        T,
        np.zeros(model.system.nstates),
        U=U,
        methods=methods,
        solvers=solvers,
        input_description=run.describe(),
        **options,
    )


def stiff_car_model(
    params=None, mount_stiffness: float = STIFF_CAR.mount_stiffness
) -> VehicleModel:
    """The quarter car with its damper on a top mount, with the road input."""
    return quarter_car_model(params, road=True, mount_stiffness=mount_stiffness)


def stiff_car_methods(names: Sequence[str] = DEFAULT_METHODS) -> tuple[str, ...]:
    """``names`` and the L-stable implicit tableaus known by name (`_L_STABLE`)."""
    known = getattr(catalogue, "TABLEAUS", METHODS)
    return tuple(dict.fromkeys([*names, *(n for n in _L_STABLE if n in known)]))


def stiff_car_comparison(
    run: StiffCar = STIFF_CAR,
    *,
    params=None,
    methods: Sequence | None = None,
    solvers: Sequence[str] | None = SOLVERS,
    ride_target: float | None = RIDE_TARGET,
    **options,
) -> MethodComparison:
    """The methods and the peers on the stiff car over an ISO 8608 road.

    ``methods`` default: the seed's four and the L-stable tableaus known by
    name (`stiff_car_methods`). The comparison's ``ride_error`` holds each
    method's Wk-weighted RMS body acceleration against the exact one [%];
    with ``ride_target`` [%] (None: skipped), ``ride_cost`` holds the
    cheapest setting of each method and peer within it (`stiff_car_ride_cost`).
    """
    T = np.linspace(0.0, run.t_end, round(run.t_end / run.h) + 1)
    U = roads.iso8608(T, run.road_class, run.speed, run.seed)
    model = stiff_car_model(params, run.mount_stiffness)
    cmp = compare_methods(
        model,
        T,
        np.zeros(model.system.nstates),
        U=U,
        methods=stiff_car_methods() if methods is None else methods,
        solvers=solvers,
        input_description=(
            f"an ISO 8608 class {run.road_class} road at {run.speed:g} m/s (seed {run.seed}), "
            f"damper top mount {run.mount_stiffness:.3g} N/m"
        ),
        **options,
    )
    if ride_target is not None:
        shared = {k: options[k] for k in ("rtols", "progress") if k in options}
        # the comparison is frozen: its ride cost makes a new one
        cmp = dataclasses.replace(cmp, ride_cost=stiff_car_ride_cost(cmp, ride_target, **shared))
    return cmp


def stiff_car_ride_cost(cmp: MethodComparison, target: float = RIDE_TARGET, **options) -> RideCost:
    """`qc_control.studies.ride_cost.ride_cost` of the comparison's methods and peers:
    the cheapest step or tolerance of each to bring the Wk-weighted RMS body
    acceleration within ``target`` % of the exact value on the same road.

    The adaptive qc pairs (embedded tableaus among the methods) and the
    explicit peers (RK45, DOP853, ``control``) are included, each stopped at
    its first tolerance within the target: on the 1e7 N/m mount their steps
    are bounded by stability, about 8e5 evaluations and 15-20 s per run on
    60 s of road. ``options`` go to `ride_cost` (``rtols``, ``halvings``...).
    """
    solvers = (
        ()
        if cmp.peers is None
        else tuple(dict.fromkeys(cmp.peers.runs["name"][cmp.peers.runs["kind"] == "solver"]))
    )
    return ride_cost(
        cmp.model,
        cmp.T,
        cmp.U,
        cmp.methods,
        X0=cmp.X0,
        h=cmp.h,
        solvers=solvers,
        target=target,
        **options,
    )


def peak_table(cmp: MethodComparison) -> pd.DataFrame:
    """The peak absolute body displacement and suspension travel [m] of the reference, of each
    method at h and of each peer's loosest run (``control``: its defaults)."""
    model = cmp.model
    labels = list(cmp.system.output_labels)
    body, travel = labels.index(model.body_disp), labels.index(model.corners[0].susp_travel)

    def peaks(outputs) -> dict:
        y = np.asarray(outputs, dtype=float).reshape(len(labels), -1)
        return {
            f"peak |{model.body_disp}| [m]": float(np.max(np.abs(y[body]))),
            f"peak |{labels[travel]}| [m]": float(np.max(np.abs(y[travel]))),
        }

    rows = {"reference": peaks(cmp.reference.outputs)}
    rows.update({name: peaks(resp.outputs) for name, resp in cmp.responses.items()})
    if cmp.peers is not None:
        for name, y in cmp.peers.loosest_outputs.items():
            rows[name] = peaks(y)
    frame = pd.DataFrame.from_dict(rows, orient="index")
    frame.index.name = "run"
    return frame
