"""Plot any named output of several responses over a reference.

`plot_outputs` overlays one output (body acceleration, say) of responses
from different methods, designs or controllers, with the reference drawn
underneath and, below it, each response's difference from the reference.
Signals are looked up by their labels, never by position, and their units
come from one small function, `output_unit`.

matplotlib is imported inside the functions that draw, so that
``import qc_control`` stays free of it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from ..models.quarter import UNITS

__all__ = ["plot_outputs", "output_signal", "output_unit", "OUTPUT_UNITS"]

#: The units `output_unit` knows without a model's: the quarter car's
#: (`qc_control.models.quarter.UNITS`, the one table; a `VehicleModel` carries
#: its own as ``model.units``).
OUTPUT_UNITS = UNITS

#: Line styles that keep coinciding curves visible: solid, then dashes over it.
_OVERLAYS = ("-", (0, (5, 4)), (0, (1, 2.5)), (0, (8, 3, 1, 3)))


def output_unit(label: str, units: Mapping[str, str] | None = None) -> str:
    """The unit of a signal, from ``units`` or the quarter car's table.

    Parameters
    ----------
    label : str
        A signal label, e.g. ``'body_acc'``.
    units : mapping, optional
        ``{label: unit}``; it wins over `OUTPUT_UNITS`.

    Returns
    -------
    str
        The unit, or ``''`` when it is not known.

    Examples
    --------
    >>> output_unit("body_acc")
    'm/s²'
    >>> output_unit("pitch_acc", {"pitch_acc": "rad/s²"})
    'rad/s²'
    """
    if units is not None and label in units:
        return str(units[label])
    return OUTPUT_UNITS.get(label, "")


def output_signal(response, label: str) -> np.ndarray:
    """One output of a `control.TimeResponseData`, looked up by its label.

    Parameters
    ----------
    response : control.TimeResponseData
    label : str

    Returns
    -------
    ndarray
        The output's samples, shape ``(len(response.time),)``.

    Raises
    ------
    KeyError
        If the response has no output of that label; the message lists the
        labels it has.
    """
    labels = list(response.output_labels)
    if label not in labels:
        raise KeyError(f"the response has no output {label!r}; its outputs are {labels}")
    y = np.asarray(response.outputs)
    if y.ndim == 1:  # a squeezed single-output response
        y = y[None, :]
    return y[labels.index(label)]


def _named(responses) -> dict:
    if isinstance(responses, Mapping):
        return {str(k): v for k, v in responses.items()}
    if isinstance(responses, Iterable) and not hasattr(responses, "outputs"):
        named = {}
        for i, resp in enumerate(responses):
            method = getattr(resp, "method", None)
            name = getattr(method, "name", None) or getattr(resp, "sysname", None) or f"#{i}"
            named[name if name not in named else f"{name} #{i}"] = resp
        return named
    raise TypeError(
        "responses must be a mapping {name: response} or a list of responses, "
        f"got {type(responses).__name__}"
    )


def _twins(curves: dict, tol: float) -> dict[str, list[str]]:
    """For each curve, the earlier curves it agrees with to ``tol``."""
    names = list(curves)
    return {
        name: [
            n
            for n in names[:i]
            if curves[n].shape == curves[name].shape
            and np.max(np.abs(curves[n] - curves[name]), initial=0.0) <= tol
        ]
        for i, name in enumerate(names)
    }


def plot_outputs(
    responses,
    output: str = "body_acc",
    reference=None,
    *,
    units: Mapping[str, str] | None = None,
    title: str | None = None,
    reference_label: str = "reference",
    difference: bool | None = None,
    coincide_tol: float = 1e-12,
):
    """Overlay one named output of several responses against a reference.

    Parameters
    ----------
    responses : mapping or list of control.TimeResponseData
        ``{name: response}``, e.g. `MethodComparison.responses`, or the
        responses of several designs or controllers. A list is named by
        each response's method (``resp.method.name``) or system name.
    output : str, default ``'body_acc'``
        The output's label (``xs``, ``xu``, ``susp_travel``, ``tire_defl``,
        ``body_acc`` for the quarter car).
    reference : control.TimeResponseData, optional
        Drawn wide and grey underneath, e.g. ``control.forced_response``'s
        exact response.
    units : mapping, optional
        ``{label: unit}`` for outputs `OUTPUT_UNITS` does not know.
    title : str, optional
    reference_label : str, default ``'reference'``
    difference : bool, optional
        Add a lower panel with ``|y − y_reference|`` on a log axis.
        Default: when a reference is given.
    coincide_tol : float, default 1e-12
        Curves that agree with an earlier one to this (in the output's
        unit) are drawn dashed over it, and the legend says so.

    Returns
    -------
    matplotlib.figure.Figure
        With labelled axes (time [s], the output with its unit), and a
        legend outside the axes so it never covers the data.

    Examples
    --------
    >>> import numpy as np, qc_control as qc
    >>> T = np.linspace(0, 2, 201)
    >>> sys = qc.quarter_car(road=True)
    >>> U = qc.road.step(T)
    >>> runs = {m: qc.forced_response(sys, T, U, method=m) for m in ("euler", "rk4")}
    >>> fig = plot_outputs(runs, "body_acc")
    >>> fig.axes[0].get_ylabel()
    'body_acc [m/s²]'
    """
    # matplotlib is heavy: imported here so that `import qc_control` does not load it
    from matplotlib.figure import Figure

    named = _named(responses)
    if not named:
        raise ValueError("responses must hold at least one response")
    curves = {name: output_signal(resp, output) for name, resp in named.items()}
    ref = None if reference is None else output_signal(reference, output)
    difference = ref is not None if difference is None else bool(difference)
    if difference and ref is None:
        raise ValueError("difference=True needs a reference")
    unit = output_unit(output, units)
    ylabel = f"{output} [{unit}]" if unit else output

    fig = Figure(figsize=(8, 5.2 if difference else 3.6), layout="constrained")
    if difference:
        top, bottom = fig.subplots(
            2, 1, sharex=True, gridspec_kw={"height_ratios": (3, 2)}, squeeze=True
        )
    else:
        top, bottom = fig.subplots(), None
    if ref is not None:
        top.plot(reference.time, ref, color="0.6", lw=4, alpha=0.6, label=reference_label)
    twins = _twins(curves, coincide_tol)
    for i, (name, resp) in enumerate(named.items()):
        style = _OVERLAYS[len(twins[name]) % len(_OVERLAYS)]
        label = name
        if twins[name]:
            label = f"{name} (= {twins[name][0]} to {coincide_tol:g}" + (
                f" {unit})" if unit else ")"
            )
        color = f"C{i % 10}"
        top.plot(resp.time, curves[name], color=color, lw=1.3, ls=style, label=label)
        if bottom is not None and ref is not None:
            n = min(curves[name].size, ref.size)
            gap = np.abs(curves[name][:n] - ref[:n])
            # exact zeros have no place on a log axis: left out, not clipped
            gap = np.where(gap > 0, gap, np.nan)
            bottom.semilogy(resp.time[:n], gap, color=color, lw=1, ls=style)
    if title is None:
        title = output if ref is None else f"{output} against {reference_label}"
    top.set(ylabel=ylabel, title=title)
    top.grid(alpha=0.3)
    last = top
    if bottom is not None:
        bottom.set(ylabel=f"|{output} − {reference_label}|" + (f" [{unit}]" if unit else ""))
        bottom.grid(alpha=0.3, which="both")
        last = bottom
    last.set_xlabel("time [s]")
    fig.legend(loc="outside right upper", fontsize="small")
    return fig
