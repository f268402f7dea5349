"""The nonlinear section of a method comparison: contact events, order, Midpoint vs Heun.

Presentation only: every number comes from ``cmp.nonlinear`` (a
`qc_control.studies.compare.NonlinearStudy`). The figures use
`matplotlib.figure.Figure` directly (no pyplot state, no show()).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..studies import columns as col
from .document import Heading, Image, Paragraph, Table, fmt
from .figures import body_wheel_road, convergence_axes
from .plotting import output_signal

__all__ = [
    "nonlinear_figures",
    "nonlinear_blocks",
    "nonlinear_tables",
    "reference_text",
    "event_convergence_figure",
    "parting_figure",
]

_MM = 1e3
#: What a switching function's new sign means, for the nonlinear car's labels.
_EVENT_WORDS = {
    "contact": {-1: "contact lost (the wheel leaves the road)", 1: "contact regained"},
    "bump stop": {-1: "bump stop engaged", 1: "bump stop released"},
    "rebound stop": {-1: "rebound stop engaged", 1: "rebound stop released"},
}


def _event_text(label: str, sign: int) -> str:
    words = _EVENT_WORDS.get(label)
    if words is not None:
        return words[sign]
    return f"{label}: {'rises through' if sign > 0 else 'falls through'} 0"


def _body(cmp) -> str:
    return cmp.model.body_disp if cmp.model is not None else "xs"


def _spans(ax, study) -> None:
    """Shade the reference's flights and mark every event on ``ax``."""
    for k, (up, down) in enumerate(study.airborne):
        end = down if math.isfinite(down) else ax.get_xlim()[1]
        ax.axvspan(
            up, end, color="tab:orange", alpha=0.15, lw=0, label="wheel airborne" if not k else None
        )
    for k, t in enumerate(study.t_events):
        ax.axvline(t, color="0.3", lw=0.8, ls=":", label="events (reference)" if not k else None)


def event_convergence_figure(cmp) -> Figure:
    """The largest body-displacement error against h, with events (solid) and without
    (dashed), log-log."""
    study = cmp.nonlinear
    conv = study.convergence
    fig = Figure(figsize=(7.5, 4.6), layout="constrained")
    ax = fig.subplots()
    colors = {t.name: f"C{i % 10}" for i, t in enumerate(cmp.methods)}
    for tab in cmp.methods:
        for events, style, marker in ((True, "-", "o"), (False, "--", "s")):
            rows = conv[(conv[col.METHOD] == tab.name) & (conv[col.EVENTS] == events)]
            rows = rows.sort_values(col.H, ascending=False)
            ok = np.isfinite(rows[col.ERROR]) & (rows[col.ERROR] > 0)
            if not ok.any():
                continue
            ax.loglog(
                rows[col.H][ok],
                rows[col.ERROR][ok],
                ls=style,
                marker=marker,
                mfc=colors[tab.name] if events else "none",
                color=colors[tab.name],
                label=f"{tab.name}, {'with' if events else 'without'} events",
            )
    ax.axhline(
        study.error_floor,
        color="0.5",
        lw=1.0,
        ls=":",
        label="10x the reference's own error (not fitted below)",
    )
    convergence_axes(ax, conv[col.H], _body(cmp), "With and without events")
    fig.legend(loc="outside right upper", fontsize="small")
    return fig


def parting_figure(cmp) -> Figure:
    """The reference's displacements, and the Midpoint-Heun difference against time (log)."""
    study = cmp.nonlinear
    ref = cmp.reference
    fig = Figure(figsize=(8, 5.2), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    body, wheel, _ = body_wheel_road(cmp)
    top.plot(ref.time, output_signal(ref, body) * _MM, "r-", lw=1.2, label=f"body {body}")
    if wheel is not None:
        top.plot(ref.time, output_signal(ref, wheel) * _MM, "b--", lw=1.1, label=f"wheel {wheel}")
    top.set(ylabel="displacement [mm]", title="Reference (solve_ivp DOP853)")
    top.grid(alpha=0.3)
    _spans(top, study)
    gap = np.asarray(study.parting_gap, dtype=float)
    shown = np.where(gap > 0, gap, np.nan)
    bottom.semilogy(cmp.T, shown, color="tab:purple", lw=1.1)
    bottom.set(
        xlabel="time [s]",
        ylabel="|midpoint − heun| [m]",
        title="Where Midpoint and Heun part (largest displacement difference)",
    )
    bottom.grid(alpha=0.3, which="both")
    for t in study.t_events:
        bottom.axvline(t, color="0.3", lw=0.8, ls=":")
    fig.legend(loc="outside right upper", fontsize="small")
    return fig


def nonlinear_figures(cmp) -> list[tuple[str, str, Callable[[], Figure]]]:
    """The section's figures as ``(file, caption, make)``; none for a linear comparison."""
    study = getattr(cmp, "nonlinear", None)
    if study is None:
        return []
    out = [
        (
            "events_convergence.png",
            f"Max |{_body(cmp)} error| against h, each method run with events (solid, "
            "filled) and without (dashed, open); the dotted line is 10x the "
            "reference's own error",
            lambda: event_convergence_figure(cmp),
        )
    ]
    if study.parting:
        out.append(
            (
                "parting.png",
                "Top: the reference's displacements, the wheel's flights shaded. Bottom: "
                "the largest difference between Midpoint's and Heun's displacements",
                lambda: parting_figure(cmp),
            )
        )
    return out


def reference_text(cmp) -> str:
    """The reference paragraph of a nonlinear comparison."""
    ref = cmp.nonlinear.reference
    return (
        f"Reference: {cmp.reference_name}; a nonlinear system has no exact solution. Its own "
        f"accuracy: it differs from {cmp.reference_description} by at most "
        f"{fmt(cmp.reference_error)} m in displacement ({fmt(ref.accuracy)} relative to the "
        f"largest state), as the matrix exponential's is stated for a linear car. It took "
        f"{fmt(cmp.reference_time * 1e3)} ms (a rough solve for the state scales, the "
        f"reference, and the tighter check; {fmt(ref.nfev)} right-hand-side evaluations "
        "for the reference itself)."
    )


def _orders_table(cmp) -> pd.DataFrame:
    study = cmp.nonlinear
    frame = pd.DataFrame({col.ORDER: [t.order for t in cmp.methods]}, index=study.orders.index)
    return pd.concat([frame, study.orders], axis=1)


def _errors_table(cmp) -> pd.DataFrame:
    conv = cmp.nonlinear.convergence
    names = [t.name for t in cmp.methods]
    frame = conv.pivot_table(index=col.H, columns=[col.EVENTS, col.METHOD], values=col.ERROR)
    frame = frame.sort_index(ascending=False)
    cols = [(ev, m) for ev in (True, False) for m in names if (ev, m) in frame.columns]
    frame = frame[cols]
    frame.columns = [f"{m} {'events' if ev else 'no events'}" for ev, m in cols]
    frame.index.name = col.STEP
    return frame


def _switching_text(study) -> str:
    """How the methods met the switching functions' kinks."""
    if not study.switching_labels:
        return (
            "The system has no switching functions (sys.switching), so its kinks (a "
            "clipped damper's, say) are stepped across: the methods ran without events."
        )
    how = (
        "The methods above stepped to each switching time (events=True): each crossing "
        "is located inside its step and stepped to exactly."
        if study.events
        else "The methods above stepped across the switching times (no events)."
    )
    return (
        f"The system's right-hand side has kinks where its switching functions "
        f"({', '.join(study.switching_labels)}) change sign. {how} The convergence "
        "study runs every method both ways."
    )


def _flight_text(up: float, down: float) -> str:
    """One flight of the wheel: when it leaves the road and when it lands."""
    landing = (
        f"lands at t = {fmt(down)} s: airborne for {fmt(down - up)} s."
        if math.isfinite(down)
        else "is still airborne at the end of the run."
    )
    return f"The wheel leaves the road at t = {fmt(up)} s and {landing}"


def _event_blocks(study) -> list:
    """The reference's events, what each means, and the wheel's flights."""
    if not study.t_events.size:
        if study.switching_labels:
            return [Paragraph("No switching function changed sign in the reference.")]
        return []
    events = pd.DataFrame(
        {
            "t [s]": study.t_events,
            "switching function": study.event_labels,
            "what happens": [
                _event_text(label, sign)
                for label, sign in zip(study.event_labels, study.event_signs)
            ],
        }
    )
    events.index = pd.RangeIndex(1, len(events) + 1, name="event")
    blocks: list = [Table(events, "The reference's events (where it restarted)")]
    return blocks + [Paragraph(_flight_text(up, down)) for up, down in study.airborne]


def _order_blocks(cmp, study) -> list:
    """The order observed with and without events, and the errors it is fitted to."""
    orders = _orders_table(cmp)
    blocks: list = [
        Table(
            orders,
            "Observed order with and without events: least-squares slope of log max |"
            f"{_body(cmp)} error| against log h over h, h/2 and h/4 (errors within 10x "
            f"the reference's own, {fmt(study.error_floor)} m, left out)",
        )
    ]
    if study.switching_labels and "rk4" in orders.index:
        with_ev, without = orders.loc["rk4", col.WITH_EVENTS], orders.loc["rk4", col.WITHOUT_EVENTS]
        blocks.append(
            Paragraph(
                f"RK4's observed order is {fmt(with_ev)} with events and {fmt(without)} "
                "without: across a kink every method loses its order, and stepping to the "
                "event restores it."
            )
        )
    blocks.append(
        Table(
            _errors_table(cmp),
            f"Max |{_body(cmp)} error| [m] at each h, with and without events",
        )
    )
    return blocks


def _parting_blocks(study, figs: dict[str, Image]) -> list:
    """Where Midpoint and Heun part, when both ran."""
    part = study.parting
    if not part:
        return []
    since = (
        f"They part at t = {fmt(part['from [s]'])} s (the first sample where they differ "
        f"by more than 1e-12 m)"
        if math.isfinite(part["from [s]"])
        else "They never differ by more than 1e-12 m"
    )
    return [
        Paragraph(
            "Midpoint and Heun give the same trajectory on a linear system with an input "
            "linear within each step; on a nonlinear right-hand side, or an input that "
            f"curves within a step, they part. {since}; their largest displacement "
            f"difference is {fmt(part['max [m]'])} m, at t = {fmt(part['at [s]'])} s."
        ),
        figs["parting.png"],
    ]


def nonlinear_blocks(cmp, figs: dict[str, Image]) -> list:
    """The section: events, order with and without them, where Midpoint and Heun part."""
    study = getattr(cmp, "nonlinear", None)
    if study is None:
        return []
    return [
        Heading("Nonlinear system: events and order"),
        Paragraph(_switching_text(study)),
        *_event_blocks(study),
        figs["events_convergence.png"],
        *_order_blocks(cmp, study),
        *_parting_blocks(study, figs),
        Paragraph(study.linearization_note),
    ]


def nonlinear_tables(cmp) -> dict[str, pd.DataFrame]:
    """The CSV files of the section."""
    study = getattr(cmp, "nonlinear", None)
    if study is None:
        return {}
    events = pd.DataFrame(
        {
            "t [s]": study.t_events,
            "switching function": study.event_labels,
            "sign after": study.event_signs,
        }
    )
    return {
        "nonlinear_convergence.csv": study.convergence.set_index(col.METHOD),
        "nonlinear_orders.csv": _orders_table(cmp),
        "events.csv": events,
    }
