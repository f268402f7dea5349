"""Figures of a method comparison. Each function returns a matplotlib Figure.

They draw numbers already in the `MethodComparison`; none is recomputed
here except the stability-region contours, which are drawings of R(z).
They use `matplotlib.figure.Figure` directly (no pyplot state, no show()).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..stability import stability_function

__all__ = [
    "method_figure",
    "overlay_figure",
    "error_figure",
    "convergence_figure",
    "work_precision_figure",
    "stability_figure",
    "road_figure",
]

_MM = 1e3


def _colors(methods):
    cycle = [
        "tab:blue",
        "tab:orange",
        "tab:green",
        "tab:red",
        "tab:purple",
        "tab:brown",
        "tab:pink",
        "tab:olive",
    ]
    return {m: cycle[i % len(cycle)] for i, m in enumerate(methods)}


def method_figure(cmp, method: str) -> Figure:
    """One method's displacements against time, as in the seed's Figures 3-6.

    Sprung mass ``xs`` in red (solid), wheel ``xu`` in blue (dashed); the
    exact response is drawn faintly underneath.
    """
    resp, ref = cmp.responses[method], cmp.reference
    fig = Figure(figsize=(7.5, 3.6), layout="constrained")
    ax = fig.subplots()
    ax.plot(ref.time, ref.outputs[0] * _MM, color="0.8", lw=3, label="exact xs, xu")
    ax.plot(ref.time, ref.outputs[1] * _MM, color="0.8", lw=3)
    ax.plot(resp.time, resp.outputs[0] * _MM, "r-", lw=1.2, label="suspension (sprung mass) xs")
    ax.plot(resp.time, resp.outputs[1] * _MM, "b--", lw=1.2, label="wheel xu")
    ax.set(xlabel="time [s]", ylabel="displacement [mm]", title=f"{method}, h = {cmp.h:g} s")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", fontsize="small")
    return fig


def overlay_figure(cmp) -> Figure:
    """Every method's body displacement over the exact response."""
    colors = _colors(cmp.responses)
    fig = Figure(figsize=(7.5, 3.8), layout="constrained")
    ax = fig.subplots()
    ax.plot(
        cmp.reference.time,
        cmp.reference.outputs[0] * _MM,
        color="k",
        lw=3,
        alpha=0.25,
        label="exact (python-control)",
    )
    for name, resp in cmp.responses.items():
        ax.plot(resp.time, resp.outputs[0] * _MM, color=colors[name], lw=1, label=name)
    ax.set(
        xlabel="time [s]",
        ylabel="body displacement xs [mm]",
        title=f"All methods against the exact response, h = {cmp.h:g} s",
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", ncol=2)
    return fig


def error_figure(cmp) -> Figure:
    """|xs error| against time on a log axis."""
    colors = _colors(cmp.responses)
    fig = Figure(figsize=(7.5, 3.8), layout="constrained")
    ax = fig.subplots()
    for name, resp in cmp.responses.items():
        n = resp.time.size
        err = np.abs(resp.outputs[0] - cmp.reference.outputs[0, :n])
        ax.semilogy(resp.time[1:], np.maximum(err[1:], 1e-17), color=colors[name], lw=1, label=name)
    ax.set(
        xlabel="time [s]",
        ylabel="|xs − xs exact| [m]",
        title=f"Error against time, h = {cmp.h:g} s",
    )
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize="small", ncol=2)
    return fig


def _slope_guide(ax, x, y, p, color):
    """A dashed line of slope p through the coarsest point, labelled h^p."""
    x = np.asarray(x)
    ax.loglog(x, y * (x / x[0]) ** p, ":", color=color, lw=1)
    ax.annotate(
        f"h^{p}",
        (x[-1], y * (x[-1] / x[0]) ** p),
        color=color,
        fontsize="small",
        xytext=(4, 0),
        textcoords="offset points",
    )


def convergence_figure(cmp) -> Figure:
    """Max |xs error| against h, log-log, with guides of slope p."""
    conv = cmp.convergence
    colors = _colors(cmp.responses)
    fig = Figure(figsize=(6.5, 4.5), layout="constrained")
    ax = fig.subplots()
    for tab in cmp.methods:
        rows = conv[conv["method"] == tab.name]
        ok = np.isfinite(rows["error"])
        ax.loglog(rows["h"][ok], rows["error"][ok], "o-", color=colors[tab.name], label=tab.name)
        if ok.any():
            _slope_guide(
                ax,
                rows["h"][ok].to_numpy(),
                rows["error"][ok].iloc[0] * 1.6,
                tab.order,
                colors[tab.name],
            )
    ax.set(
        xlabel="step h [s]",
        ylabel="max |xs error| [m]",
        title="Convergence (dotted: slope of the method's order)",
    )
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize="small")
    return fig


def work_precision_figure(cmp) -> Figure:
    """Max |xs error| against RHS evaluations and against wall time."""
    conv = cmp.convergence
    colors = _colors(cmp.responses)
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    left, right = fig.subplots(1, 2, sharey=True)
    for tab in cmp.methods:
        rows = conv[(conv["method"] == tab.name) & np.isfinite(conv["error"])]
        left.loglog(rows["nfev"], rows["error"], "o-", color=colors[tab.name], label=tab.name)
        right.loglog(
            rows["time"] * 1e3, rows["error"], "o-", color=colors[tab.name], label=tab.name
        )
    left.set(
        xlabel="right-hand-side evaluations",
        ylabel="max |xs error| [m]",
        title="Error against work",
    )
    right.set(xlabel="wall time, step by step [ms]", title="Error against time")
    for ax in (left, right):
        ax.grid(alpha=0.3, which="both")
    left.legend(fontsize="small")
    return fig


def stability_figure(cmp) -> Figure:
    """Stability regions |R(z)| <= 1 with hλ of each mode marked."""
    colors = _colors(cmp.responses)
    fig = Figure(figsize=(6.5, 5.5), layout="constrained")
    ax = fig.subplots()
    x = np.linspace(-3.5, 1.0, 400)
    y = np.linspace(-3.2, 3.2, 400)
    Z = x[None, :] + 1j * y[:, None]
    handles = []
    styles = ["solid", "dashed", "dotted", "dashdot"]
    for i, tab in enumerate(cmp.methods):
        R = stability_function(tab)
        # distinct styles: methods with the same R(z) (midpoint, heun) stay visible
        cs = ax.contour(
            x,
            y,
            np.abs(R(Z)),
            levels=[1.0],
            colors=[colors[tab.name]],
            linewidths=1.5,
            linestyles=styles[i % len(styles)],
        )
        handles.append((cs.legend_elements()[0][0], f"{tab.name}: |R(z)| = 1"))
    markers = {"body bounce": "o", "wheel hop": "s"}
    for mode in cmp.modes.modes:
        for lam in (mode.eigenvalue, mode.eigenvalue.conjugate()):
            (pt,) = ax.plot(
                (cmp.h * lam).real,
                (cmp.h * lam).imag,
                markers[mode.name],
                color="k",
                ms=6,
                mfc="none",
            )
        handles.append((pt, f"h·λ, {mode.name}"))
    ax.axhline(0, color="0.6", lw=0.6)
    ax.axvline(0, color="0.6", lw=0.6)
    ax.set(
        xlabel="Re(hλ)",
        ylabel="Im(hλ)",
        aspect="equal",
        title=f"Stability regions; modes at h = {cmp.h:g} s",
    )
    ax.legend([h for h, _ in handles], [t for _, t in handles], fontsize="small", loc="upper left")
    return fig


def road_figure(cmp) -> Figure:
    """The road input zr against time, and the body's exact response to it."""
    ref = cmp.reference
    fig = Figure(figsize=(7.5, 3.6), layout="constrained")
    ax = fig.subplots()
    ax.plot(cmp.T, cmp.U[0] * _MM, color="0.3", lw=1, label="road zr")
    ax.plot(ref.time, ref.outputs[0] * _MM, "r-", lw=1, label="body xs (exact)")
    ax.set(xlabel="time [s]", ylabel="height [mm]", title=cmp.input_description or "Road input")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return fig
