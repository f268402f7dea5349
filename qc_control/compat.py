"""python-control's private names that qc_control relies on, behind one door.

qc_control answers python-control's calls with python-control's own rules:
the same keyword aliases and their errors, the same default time grid, the
same checks of inputs and initial states, and the same evaluation of a
nonlinear system's right-hand side and outputs with its current parameters.
Those rules live in names python-control does not publish (they start with
an underscore, or are attributes its documentation does not list), so they
may change in any release. Every use in qc_control goes through this module,
and ``tests/test_compat.py`` checks each name against python-control's public
behaviour. When python-control changes, this module is the one place to adapt.

Written against python-control 0.10.2 (``control>=0.10.2,<0.11``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, NamedTuple

import numpy as np
from control.config import _process_kwargs, _process_param
from control.nlsys import _process_vector_argument
from control.timeresp import _check_convert_array, _default_time_vector, _timeresp_aliases

__all__ = [
    "TIMERESP_ALIASES",
    "InterconnectionMaps",
    "check_convert_array",
    "current_params",
    "default_time_vector",
    "interconnection_maps",
    "output_function",
    "process_time_response_kwargs",
    "process_time_response_param",
    "process_vector_argument",
    "state_derivative",
    "update_params",
]

#: The keyword aliases of python-control's time responses
#: (``control.timeresp._timeresp_aliases``): for each parameter name, the
#: aliases and the legacy names it accepts, ``{"timepts": (["T"], []),
#: "inputs": (["U"], ["u"]), ...}``. qc relies on the keys ``timepts``,
#: ``inputs``, ``initial_state``, ``return_states``, ``evaluation_times``
#: and ``timepts_num``.
TIMERESP_ALIASES: Mapping[str, tuple[list[str], list[str]]] = _timeresp_aliases


def process_time_response_kwargs(kwargs: dict) -> None:
    """Map a time response's aliases in ``kwargs`` to their names, in place.

    python-control's ``config._process_kwargs`` with `TIMERESP_ALIASES`:
    an alias (``T``) is renamed to its parameter (``timepts``), a legacy
    name warns (`PendingDeprecationWarning`), and two names for one
    parameter raise `TypeError`, as in python-control's own responses.
    """
    _process_kwargs(kwargs, _timeresp_aliases)


def process_time_response_param(name: str, value: Any, kwargs: dict, sigval: Any = None) -> Any:
    """The value of a time response's parameter ``name``, by python-control's rules.

    python-control's ``config._process_param`` with `TIMERESP_ALIASES`: the
    value given as ``name`` or any alias of it in ``kwargs`` (which are
    removed), else ``value``; `TypeError` when two of them are given and
    ``value`` differs from the signature's default ``sigval``.
    """
    return _process_param(name, value, kwargs, _timeresp_aliases, sigval=sigval)


def check_convert_array(in_obj, legal_shapes: list, err_msg_start: str, squeeze=False):
    """``in_obj`` as an array of one of ``legal_shapes``, by python-control's rules.

    python-control's ``timeresp._check_convert_array``: a number is spread
    to a legal shape; a list or array of another shape raises `ValueError`
    whose message starts with ``err_msg_start`` (the same message
    python-control gives for the same input).
    """
    return _check_convert_array(in_obj, legal_shapes, err_msg_start, squeeze=squeeze)


def default_time_vector(sysdata, N=None, tfinal=None, is_step: bool = True) -> np.ndarray:
    """The time grid python-control chooses when a response is given no times.

    python-control's ``timeresp._default_time_vector``: for an LTI system,
    a grid from 0 whose final time and number of points follow from the
    system's poles (``tfinal``, when given, is the final time); for a list of
    systems, the longest such grid. qc uses it so that ``T=None`` or a final
    time gives exactly the grid `control.step_response` would use.
    """
    return _default_time_vector(sysdata, N=N, tfinal=tfinal, is_step=is_step)


def process_vector_argument(arg, name: str, size: int | None) -> tuple[np.ndarray, int]:
    """``(vector, length)``: a state or input argument by python-control's rules.

    python-control's ``nlsys._process_vector_argument``, as
    `control.input_output_response` reads ``X0``: a list or tuple is
    flattened and stacked, a number is spread to ``size``, and a short
    vector is padded with zeros (with a `UserWarning` when its last value is
    not zero).
    """
    return _process_vector_argument(arg, name, size)


def update_params(sys, params: dict | None) -> None:
    """Set the parameters ``sys``'s update and output functions will be called with.

    python-control's ``NonlinearIOSystem._update_params``: the system's own
    ``params`` updated by ``params``, for itself and, in an interconnection,
    for every subsystem. python-control calls it at the start of a response;
    qc calls it before `state_derivative` or `output_function` is used.
    """
    sys._update_params(params)


def current_params(sys, default: dict | None = None) -> dict:
    """The parameters `update_params` last set on ``sys`` (``default`` if none).

    python-control's ``NonlinearIOSystem._current_params``: the dictionary
    passed as the last argument of the system's ``updfcn`` and ``outfcn``.
    """
    return getattr(sys, "_current_params", {} if default is None else default)


def state_derivative(sys) -> Callable[[float, np.ndarray, np.ndarray], np.ndarray]:
    """``f(t, x, u)``: ``sys``'s state derivative as python-control evaluates it.

    python-control's ``NonlinearIOSystem._rhs`` (bound): ``updfcn(t, x, u,
    current_params)`` as a flat array; for an interconnection, with every
    subsystem's input resolved from the others' outputs. Get it once, then
    call it at every stage (call `update_params` first).
    """
    return sys._rhs


def output_function(sys) -> Callable[[float, np.ndarray, np.ndarray], np.ndarray]:
    """``g(t, x, u)``: ``sys``'s outputs as python-control evaluates them.

    python-control's ``NonlinearIOSystem._out`` (bound): ``outfcn(t, x, u,
    current_params)`` as a flat array, or the state itself when the system
    has no output function (call `update_params` first).
    """
    return sys._out


class InterconnectionMaps(NamedTuple):
    """How a `control.InterconnectedSystem` wires its subsystems.

    With the subsystems' inputs ``u``, outputs ``y`` (each stacked in the
    order of ``syslist``), the external inputs ``w`` and outputs ``z``:
    ``u = connect @ y + inputs @ w`` and ``z = outputs @ [y; u]``.
    """

    syslist: list
    #: ``(sum of subsystem inputs, sum of subsystem outputs)``
    connect: np.ndarray
    #: ``(sum of subsystem inputs, external inputs)``
    inputs: np.ndarray
    #: ``(external outputs, sum of subsystem outputs + sum of subsystem inputs)``
    outputs: np.ndarray


def interconnection_maps(sys) -> InterconnectionMaps:
    """The subsystems and connection matrices of a `control.InterconnectedSystem`.

    python-control's ``syslist``, ``connect_map``, ``input_map`` and
    ``output_map`` attributes (not in its documentation), as float arrays of
    the shapes `InterconnectionMaps` states.
    """
    return InterconnectionMaps(
        list(sys.syslist),
        np.asarray(sys.connect_map, dtype=float),
        np.asarray(sys.input_map, dtype=float),
        np.asarray(sys.output_map, dtype=float),
    )
