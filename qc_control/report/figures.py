"""Figures of a method comparison. Each function returns a matplotlib Figure.

They draw numbers already in the `MethodComparison`; none is recomputed
here except the stability-region contours, which are drawings of R(z).
They use `matplotlib.figure.Figure` directly (no pyplot state, no show()).

Conventions, so that a projected figure reads at a glance:

- legends sit outside the axes (``fig.legend(loc="outside ...")``), so they
  never cover data;
- methods with the same trajectory (``cmp.coincident``, e.g. Midpoint and
  Heun on a linear system) are drawn dashed over each other, and the figure
  says that they coincide;
- outputs are looked up by label (`qc_control.report.plotting.output_signal`),
  never by position.
"""

from __future__ import annotations

import math
import textwrap
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle
from matplotlib.ticker import NullFormatter

from ..models.registry import model_for_params, model_for_system
from ..numerics.stability import stability_boundary
from ..studies import columns as col
from .findings import coincidence_groups
from .plotting import output_signal, output_unit

__all__ = [
    "reference_figure",
    "method_figure",
    "overlay_figure",
    "error_figure",
    "convergence_figure",
    "work_precision_figure",
    "stability_figure",
    "transmissibility_figure",
    "coincidence_note",
    "step_ticks",
]

_MM = 1e3
_CYCLE = (
    "tab:blue",
    "tab:orange",
    "tab:green",
    "tab:red",
    "tab:purple",
    "tab:brown",
    "tab:pink",
    "tab:olive",
)
#: Line styles of the 1st, 2nd, ... member of a group of coinciding methods.
_OVERLAY_STYLES = ("-", (0, (5, 4)), (0, (1, 2.5)), (0, (8, 3, 1, 3)))
_MARKERS = ("o", "s", "^", "v", "D")
#: Exact responses: two greys and two styles, under the methods' colours.
_EXACT: dict[str, dict[str, Any]] = {
    "body": {"color": "0.55", "lw": 4.0, "ls": "-", "alpha": 0.7},
    "wheel": {"color": "0.8", "lw": 4.0, "ls": (0, (2, 1)), "alpha": 0.9},
}


def _colors(methods):
    return {m: _CYCLE[i % len(_CYCLE)] for i, m in enumerate(methods)}


def _rank(cmp) -> dict[str, int]:
    """Each method's place in its group of coinciding methods (0: drawn solid)."""
    rank = {name: 0 for name in cmp.responses}
    for group in coincidence_groups(cmp):
        for i, name in enumerate(group):
            rank[name] = i
    return rank


def coincidence_note(cmp) -> str:
    """'midpoint = heun (≤ 1e-12 m apart)' for every group of coinciding methods."""
    return "; ".join(
        " = ".join(group) + " (same trajectory, ≤ 1e-12 m apart)"
        for group in coincidence_groups(cmp)
    )


def _style(cmp, name, rank=None) -> dict:
    rank = _rank(cmp) if rank is None else rank
    return {
        "ls": _OVERLAY_STYLES[rank[name] % len(_OVERLAY_STYLES)],
        "zorder": 2 + rank[name],
    }


def _legend(fig, note: str = "", **kw):
    """A figure legend outside the axes, on the right, with ``note`` as its title."""
    kw.setdefault("loc", "outside right upper")
    kw.setdefault("fontsize", "small")
    if note:
        kw.update(title=note.replace("; ", "\n").replace(" (", "\n("), title_fontsize="small")
    return fig.legend(**kw)


def body_wheel_road(cmp) -> tuple[str, str | None, str | None]:
    """(body displacement, wheel displacement, first road input) labels:
    ``xs``, ``xu``, ``zr`` on a quarter car, ``z``, ``xu_front``, ``zr_front``
    on a half car. The wheel is the model's registry entry's ``wheel_disp``
    (None when the model has no entry or no such output: the body alone)."""
    model = getattr(cmp, "model", None)
    outputs = list(cmp.system.output_labels)
    body = model.body_disp if model is not None else "xs"
    # the signals decide first: the quarter and the nonlinear car share a parameter class
    entry = model_for_system(cmp.system)
    if entry is None and model is not None:
        entry = model_for_params(model.params)
    wheel = None if entry is None else entry.wheel_disp
    wheel = wheel if wheel in outputs else None
    roads = model.road_inputs() if model is not None else ["zr"]
    road = next((r for r in roads if r in cmp.system.input_labels), None)
    return body, wheel, road


def reference_word(cmp) -> str:
    """What the methods are measured against: 'exact' on a linear car; on a
    nonlinear one, which has no exact solution, 'reference (solve_ivp)'."""
    return "exact" if getattr(cmp, "nonlinear", None) is None else "reference (solve_ivp)"


def _title(text: str, width: int = 60) -> str:
    """A figure title wrapped so that it never runs into the legend beside the axes."""
    return textwrap.fill(text, width)


def reference_figure(cmp) -> Figure:
    """The exact response the methods are measured against (and the road, if any)."""
    ref = cmp.reference
    body, wheel, road = body_wheel_road(cmp)
    fig = Figure(figsize=(8, 3.4), layout="constrained")
    ax = fig.subplots()
    if cmp.U is not None and road is not None:
        zr = np.asarray(cmp.U)[list(cmp.system.input_labels).index(road)]
        ax.plot(cmp.T, zr * _MM, color="tab:brown", lw=0.9, label=f"road {road}")
    word = reference_word(cmp)
    ax.plot(ref.time, output_signal(ref, body) * _MM, "r-", lw=1.3, label=f"body {body} ({word})")
    if wheel is not None:
        wheel_mm = output_signal(ref, wheel) * _MM
        ax.plot(ref.time, wheel_mm, "b--", lw=1.1, label=f"wheel {wheel} ({word})")
    free = "Free response: the " + ("exact solution" if word == "exact" else word)
    ax.set(xlabel="time [s]", ylabel="displacement [mm]")
    ax.set_title(_title(cmp.input_description or free), fontsize="medium")
    ax.grid(alpha=0.3)
    _legend(fig)
    return fig


def method_figure(cmp, method: str) -> Figure:
    """One method's displacements against time, as in the seed's Figures 3-6.

    The body displacement (``xs`` on a quarter car) in red (solid), the
    wheel's (the model entry's ``wheel_disp``, ``xu``) in blue (dashed); the
    exact ones (dark grey, solid; light grey, dashed) are drawn wide
    underneath.
    """
    resp, ref = cmp.responses[method], cmp.reference
    body, wheel, _ = body_wheel_road(cmp)
    fig = Figure(figsize=(8, 3.4), layout="constrained")
    ax = fig.subplots()
    drawn = [(body, "body", "r-", "suspension (sprung mass)")]
    if wheel is not None:
        drawn.append((wheel, "wheel", "b--", "wheel"))
    for name, style, _, _ in drawn:
        ax.plot(
            ref.time,
            output_signal(ref, name) * _MM,
            label=f"{reference_word(cmp)} {name}",
            **_EXACT[style],
        )
    for name, _, line, what in drawn:
        color, ls = line[0], line[1:]
        exact = output_signal(ref, name) * _MM
        values = output_signal(resp, name) * _MM
        _plot_cut(ax, resp.time, values, exact, f"{what} {name}", color=color, ls=ls, lw=1.2)
    title = f"{method}, h = {cmp.h:g} s"
    same = [g for g in coincidence_groups(cmp) if method in g]
    if same:
        others = " and ".join(m for m in same[0] if m != method)
        title += f"\nthe same trajectory as {others} (≤ 1e-12 m apart)"
    ax.set(xlabel="time [s]", ylabel="displacement [mm]", title=title)
    ax.grid(alpha=0.3)
    _legend(fig, loc="outside lower center", ncols=4)
    return fig


#: A method's curve is cut where it leaves this multiple of the exact
#: response's range (its largest magnitude): past it the method has diverged,
#: and drawing on would scale the axis so that every other curve is flat.
DIVERGED_RANGE = 10.0


def diverged_at(time, values, exact) -> int | None:
    """The index where ``values`` first leave `DIVERGED_RANGE` times the
    range of ``exact`` (or become inf or NaN); None if they never do."""
    span = float(np.max(np.abs(exact))) if np.size(exact) else 0.0
    if not span > 0 or not math.isfinite(span):
        return None
    with np.errstate(invalid="ignore"):
        outside = ~(np.abs(np.asarray(values)) <= DIVERGED_RANGE * span)
    return int(np.argmax(outside)) if outside.any() else None


def _plot_cut(ax, time, values, exact, label: str, **style) -> None:
    """Plot ``values`` against ``time``, cut and marked where they diverge."""
    cut = diverged_at(time, values, exact)
    if cut is None:
        ax.plot(time, values, label=label, **style)
        return
    kept = max(cut, 1)
    (line,) = ax.plot(
        time[:kept], values[:kept], label=f"{label}: diverged at t = {time[cut]:.3g} s", **style
    )
    ax.plot(time[kept - 1], values[kept - 1], "x", color=line.get_color(), ms=8, mew=2)
    ax.annotate(
        f"diverged at t = {time[cut]:.3g} s",
        (time[kept - 1], values[kept - 1]),
        xytext=(4, 4),
        textcoords="offset points",
        fontsize="small",
        color=line.get_color(),
    )


def overlay_figure(cmp) -> Figure:
    """Every method's body displacement over the exact response."""
    colors, rank = _colors(cmp.responses), _rank(cmp)
    fig = Figure(figsize=(8, 3.6), layout="constrained")
    ax = fig.subplots()
    ref = cmp.reference
    body = body_wheel_road(cmp)[0]
    word = reference_word(cmp)
    ax.plot(ref.time, output_signal(ref, body) * _MM, color="k", lw=4, alpha=0.25, label=word)
    exact = output_signal(ref, body) * _MM
    for name, resp in cmp.responses.items():
        _plot_cut(
            ax,
            resp.time,
            output_signal(resp, body) * _MM,
            exact,
            name,
            color=colors[name],
            lw=1.2,
            **_style(cmp, name, rank),
        )
    ax.set(
        xlabel="time [s]",
        ylabel=f"body displacement {body} [mm]",
        title=f"All methods against the {word.split(' ')[0]} response, h = {cmp.h:g} s",
    )
    ax.grid(alpha=0.3)
    _legend(fig, coincidence_note(cmp))
    return fig


_ERROR_CEILING = 1e200  # [m] far beyond any physical error, far below float overflow


def error_figure(cmp) -> Figure:
    """``|xs error|`` against time on a log axis."""
    colors, rank = _colors(cmp.responses), _rank(cmp)
    fig = Figure(figsize=(8, 3.6), layout="constrained")
    ax = fig.subplots()
    body = body_wheel_road(cmp)[0]
    exact = output_signal(cmp.reference, body)
    clipped = False
    for name, resp in cmp.responses.items():
        n = resp.time.size
        with np.errstate(invalid="ignore", over="ignore"):  # a diverged run: inf, shown clipped
            err = np.abs(output_signal(resp, body) - exact[:n])
        err = np.where(err > 0, err, np.nan)  # exact zeros (t = 0) have no log
        # the log axis pads its range by a factor; past ~1e300 that overflows
        clipped |= bool(np.any(err > _ERROR_CEILING))
        err = np.minimum(err, _ERROR_CEILING)
        ax.semilogy(resp.time, err, color=colors[name], lw=1, label=name, **_style(cmp, name, rank))
    if clipped:
        ax.axhline(_ERROR_CEILING, color="0.5", lw=0.8, ls="--")
        ax.annotate(
            f"diverged: errors above {_ERROR_CEILING:.0e} m drawn on this line",
            (0.01, _ERROR_CEILING),
            xycoords=("axes fraction", "data"),
            va="top",
            fontsize="small",
            color="0.3",
        )
    ax.set(
        xlabel="time [s]",
        ylabel=f"|{body} − {body} exact| [m]",
        title=f"Error against time, h = {cmp.h:g} s",
    )
    ax.grid(alpha=0.3, which="both")
    _legend(fig, coincidence_note(cmp))
    return fig


def _slope_guide(ax, x, y0, p, color):
    """A dotted line of slope p, starting a little above the coarsest point,
    labelled ``h^p`` beside its middle, off the line (not struck through)."""
    x = np.asarray(x, dtype=float)
    y = y0 * (x / x[0]) ** p
    ax.loglog(x, y, ":", color=color, lw=1.2)
    mid = np.sqrt(x[0] * x[-1])
    ax.annotate(
        f"$h^{{{p}}}$",
        (mid, y0 * (mid / x[0]) ** p),
        color=color,
        fontsize="medium",
        xytext=(-6, 6),
        textcoords="offset points",
        ha="right",
        va="bottom",
    )


def convergence_figure(cmp) -> Figure:
    """Max ``|xs error|`` against h, log-log, with guides of slope p."""
    conv = cmp.convergence
    colors, rank = _colors(cmp.responses), _rank(cmp)
    fig = Figure(figsize=(7.5, 4.6), layout="constrained")
    ax = fig.subplots()
    for tab in cmp.methods:
        rows = conv[conv[col.METHOD] == tab.name].sort_values(col.H, ascending=False)
        ok = np.isfinite(rows[col.ERROR]) & (rows[col.ERROR] > 0)
        ax.loglog(
            rows[col.H][ok],
            rows[col.ERROR][ok],
            marker=_MARKERS[rank[tab.name] % len(_MARKERS)],
            mfc="none" if rank[tab.name] else colors[tab.name],
            color=colors[tab.name],
            label=tab.name,
            **_style(cmp, tab.name, rank),
        )
        if ok.any() and rank[tab.name] == 0:  # one guide per group of coinciding methods
            _slope_guide(
                ax,
                rows[col.H][ok].to_numpy(),
                rows[col.ERROR][ok].iloc[0] * 3,
                tab.order,
                colors[tab.name],
            )
    title = "Convergence (dotted: slope of the method's order)"
    convergence_axes(ax, conv[col.H], body_wheel_road(cmp)[0], title)
    _legend(fig, coincidence_note(cmp))
    return fig


def convergence_axes(ax, steps, output: str, title: str) -> None:
    """A convergence figure's axes: the steps tried as ticks, the largest error of ``output``."""
    step_ticks(ax, steps)
    ax.set(xlabel="step h [s]", ylabel=f"max |{output} error| [m]", title=title)
    ax.grid(alpha=0.3, which="both")


def step_ticks(ax, steps) -> None:
    """Ticks of a log step axis at the steps themselves, labelled ``3 s.f.``:
    log-axis minor labels crowd the 1.5 decades of a convergence study."""
    hs = np.sort(np.unique(np.asarray(steps, dtype=float)))[::-1]
    ax.set_xticks(hs, [f"{h:.3g}" for h in hs], fontsize="small")
    ax.xaxis.set_minor_formatter(NullFormatter())


def work_precision_figure(cmp) -> Figure:
    """Max ``|xs error|`` against RHS evaluations and against wall time.

    Left, each method's refinements are joined in order of work (RHS
    evaluations). Right, the measured wall times are drawn as points
    only: a timing is one measurement on a shared machine, and a line
    through noisy times would run back and forth.
    """
    conv = cmp.convergence
    colors, rank = _colors(cmp.responses), _rank(cmp)
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    left, right = fig.subplots(1, 2, sharey=True)
    for tab in cmp.methods:
        rows = conv[(conv[col.METHOD] == tab.name) & np.isfinite(conv[col.ERROR])]
        rows = rows.sort_values(col.NFEV, kind="stable")
        style = dict(
            color=colors[tab.name],
            marker=_MARKERS[rank[tab.name] % len(_MARKERS)],
            mfc="none" if rank[tab.name] else colors[tab.name],
            label=tab.name,
            **_style(cmp, tab.name, rank),
        )
        left.loglog(rows[col.NFEV], rows[col.ERROR], **style)
        # measured times are noisy: points only, so no line ever runs back in time
        right.loglog(rows[col.TIME] * 1e3, rows[col.ERROR], **{**style, "ls": "none"})
    left.set(
        xlabel="right-hand-side evaluations",
        ylabel=f"max |{body_wheel_road(cmp)[0]} error| [m]",
        title="Against work",
    )
    right.set(
        xlabel="wall time, step by step [ms]",
        title="Against wall time (this machine)",
    )
    for ax in (left, right):
        ax.grid(alpha=0.3, which="both")
        ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels would crowd
    handles, labels = left.get_legend_handles_labels()
    _legend(fig, coincidence_note(cmp), handles=handles, labels=labels)
    return fig


def _regions(ax, cmp, x, y, colors, rank):
    for tab in cmp.methods:
        style = _OVERLAY_STYLES[rank[tab.name] % len(_OVERLAY_STYLES)]
        for curve in stability_boundary(tab, x, y):
            ax.plot(curve.real, curve.imag, color=colors[tab.name], lw=1.5, ls=style)


def _modes(ax, cmp, size=6):
    for i, mode in enumerate(cmp.modes.modes):
        z = cmp.h * np.array([mode.eigenvalue, np.conj(mode.eigenvalue)])
        ax.plot(z.real, z.imag, _MARKERS[i % len(_MARKERS)], color="k", ms=size, mfc="none")


def stability_figure(cmp) -> Figure:
    """Stability regions ``|R(z)| <= 1`` with hλ of each mode, and a zoom on hλ.

    Left: the regions in full (an implicit method's region is the outside
    of its curve, in the right half-plane). Right: the square around the origin that
    holds every hλ (outlined on the left), with the regions redrawn there,
    so that modes near the boundary can be told inside from outside.
    """
    colors, rank = _colors(cmp.responses), _rank(cmp)
    fig = Figure(figsize=(10.5, 4.8), layout="constrained")
    full, zoom = fig.subplots(1, 2)
    hl = cmp.h * np.array([m.eigenvalue for m in cmp.modes.modes])
    reach = float(np.max(np.abs(hl))) if hl.size else 0.1
    lim = max(3.2, 1.1 * reach)
    # an implicit method is unstable only on a bounded set of the right half-plane:
    # show that half-plane as far as the left one
    right = lim if any(tab.implicit for tab in cmp.methods) else 1.0
    x, y = np.linspace(-lim - 0.3, right, 500), np.linspace(-lim, lim, 500)
    _regions(full, cmp, x, y, colors, rank)
    _modes(full, cmp)
    # the zoom: a square around the origin that holds every hλ with a margin
    half = 1.3 * max(reach, 1e-6)
    cx = min(0.0, float(np.min(hl.real))) / 2 if hl.size else 0.0
    xs = np.linspace(cx - half, cx + half, 500)
    ys = np.linspace(-half, half, 500)
    _regions(zoom, cmp, xs, ys, colors, rank)
    _modes(zoom, cmp, size=8)
    full.add_patch(Rectangle((cx - half, -half), 2 * half, 2 * half, fill=False, ec="0.3", lw=0.8))
    for ax in (full, zoom):
        ax.axhline(0, color="0.6", lw=0.6)
        ax.axvline(0, color="0.6", lw=0.6)
        ax.set(xlabel="Re(hλ)", ylabel="Im(hλ)", aspect="equal")
    full.set_title("Stability regions |R(z)| ≤ 1")
    zoom.set(
        xlim=(cx - half, cx + half),
        ylim=(-half, half),
        title=f"Zoom: each mode's hλ at h = {cmp.h:g} s",
    )
    handles = [
        Line2D(
            [],
            [],
            color=colors[tab.name],
            ls=_OVERLAY_STYLES[rank[tab.name] % len(_OVERLAY_STYLES)],
            lw=1.5,
            label=f"{tab.name}: |R(z)| = 1" + (" (stable outside)" if tab.implicit else ""),
        )
        for tab in cmp.methods
    ]
    handles += [
        Line2D(
            [],
            [],
            ls="none",
            marker=_MARKERS[i % len(_MARKERS)],
            color="k",
            mfc="none",
            label=f"hλ, {mode.name}",
        )
        for i, mode in enumerate(cmp.modes.modes)
    ]
    note = "; ".join(" = ".join(g) + " (same R(z))" for g in coincidence_groups(cmp))
    _legend(fig, note, handles=handles)
    return fig


def transmissibility_figure(cmp) -> Figure:
    """Magnitude and phase from the road height zr to each ride signal.

    Drawn from ``cmp.transmissibility`` (frequencies and complex gains);
    the circle marks the invariant point √(ku/mu), where
    ``|body_acc/zr|`` = ku/ms for every damper.
    """
    tr = cmp.transmissibility
    fig = Figure(figsize=(10, 6.5), layout="constrained")
    axes = fig.subplots(2, 2, sharex=True).ravel()
    for ax, (name, h) in zip(axes, tr.response.items()):
        unit = output_unit(name, getattr(getattr(cmp, "model", None), "units", None))
        gain = f"({unit})/m" if "/" in unit else f"{unit}/m"
        ax.loglog(tr.freqs_hz, np.abs(h), color="tab:blue", lw=1.6)
        ax.set(title=f"{name} / zr", ylabel=f"|H| [{gain}]")
        ax.grid(alpha=0.3, which="both")
        twin = ax.twinx()
        twin.semilogx(tr.freqs_hz, np.degrees(np.unwrap(np.angle(h))), color="tab:orange", lw=0.9)
        twin.set_ylabel("phase [deg]", color="tab:orange")
        if name == "body_acc":
            ax.plot([tr.invariant_hz], [tr.invariant_gain], "ko", mfc="none", ms=8)
    for ax in axes[2:]:
        ax.set_xlabel("frequency [Hz]")
    handles = [
        Line2D([], [], color="tab:blue", lw=1.6, label="|H| (left axis)"),
        Line2D([], [], color="tab:orange", lw=0.9, label="phase (right axis)"),
    ]
    if np.isfinite(tr.invariant_hz):  # none with tire damping (see transmissibility)
        label = f"invariant point\n{tr.invariant_hz:.3g} Hz, |H| = ku/ms"
        handles.append(Line2D([], [], ls="none", marker="o", color="k", mfc="none", label=label))
    _legend(fig, handles=handles, loc="outside lower center", ncols=3)
    return fig
