"""What a study runs when a car drives a `qc_control.road.Road`.

Every study that takes ``road=`` (`qc_control.compare_methods`,
`qc_control.sweep`, `qc_control.compare_controllers`, a `Scenario`) turns the
road into the car's inputs here, by one rule:

- a car whose registry entry reads its road as a function of time (the
  nonlinear car, `ModelEntry.road_function`) gets the road itself, evaluated
  at every stage with its jumps, unless the road has no closed form (an
  ISO 8608 road, which is sampled);
- otherwise the road is sampled on ``T`` in the car's road layout
  (`qc_control.road.Road.wheel_inputs`): one wheel, or the rear wheels a
  wheelbase ``a + b`` later, or four corners with two tracks.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import control
import numpy as np

from ..models.quarter import as_params
from ..models.registry import model_for_params
from ..models.vehicle import VehicleModel
from ..ride.road import ISO8608Road, NoRoad, Road, as_road

__all__ = ["road_problem", "road_inputs"]


def _params_of(sys, params) -> Any:
    """The parameters behind ``sys``: its own, those given, or ``sys`` itself."""
    if isinstance(sys, VehicleModel):
        return sys.params
    if isinstance(sys, control.InputOutputSystem):
        return params
    return as_params(sys) if sys is None or isinstance(sys, dict) else sys


def road_problem(
    sys,
    road: Road,
    T,
    params=None,
    *,
    entry=None,
    options: Mapping[str, Any] | None = None,
) -> tuple[Any, np.ndarray | None, str]:
    """``(sys, U, description)``: the car and its inputs on ``road`` over ``T``.

    Parameters
    ----------
    sys : parameters, VehicleModel or control system
        The car as a study takes it. Parameters of a registered model come
        back as its `VehicleModel`, with its road inputs under a road (or,
        when it reads its road as a function of time, built on the road).
    road : qc_control.road.Road
    T : array_like
        The time grid [s].
    params : optional
        The parameters behind a bare system (its wheelbase and track).
    entry : ModelEntry, optional
        The registered model ``sys`` is parameters of, when more than one
        takes the same parameters (the linear and the nonlinear quarter car);
        found from the parameters' class without.
    options : mapping, optional
        Build options of the model (`ModelEntry.model`: the nonlinear car's
        ``tire``, ``bump_stop``), when ``sys`` is parameters.

    Returns
    -------
    sys
        ``sys``, or the model built from its parameters.
    U : ndarray or None
        The road samples in the car's layout; None for `NoRoad` or when the
        model reads the road itself.
    description : str
        The road in words (`Road.describe`, with the rear wheels' delay).
    """
    road = as_road(road)
    p = _params_of(sys, params)
    if entry is None and p is not None:
        entry = model_for_params(p)
    built = isinstance(sys, (VehicleModel, control.InputOutputSystem))
    if entry is not None and not built:
        if entry.road_function and not isinstance(road, (NoRoad, ISO8608Road)):
            model = entry.model(p, road=road, **(options or {}))
            return model, None, road.describe() + " (the road as a function of time)"
        sys = entry.model(p, road=not isinstance(road, NoRoad), **(options or {}))
    U, description = road_inputs(road, T, entry, p)
    return sys, U, description


def road_inputs(road: Road, T, entry=None, params=None) -> tuple[np.ndarray | None, str]:
    """``(samples on T, description)`` of ``road`` in the layout of a registered
    model (``entry``, a `ModelEntry`; one wheel without), its wheelbase and
    track read from ``params``; ``(None, '')`` for `NoRoad`."""
    layout = entry.road_layout if entry is not None else "single"
    if layout == "single":
        return road.wheel_inputs(T)
    track = params.track_front if layout == "corners" else None
    return road.wheel_inputs(T, layout, wheelbase=params.a + params.b, track=track)
