"""``qc-control explore``: the course's interactive explorer, a Panel page on the library.

Move the step and watch Euler's response swell and blow up past h_max
while RK4 holds: the page shows each chosen method's response over
python-control's exact one, the error against time, the convergence
figure with the current step marked, the stability regions with every
mode's ``hλ``, the modal table, each method's numerical frequency and
damping at h, and the numbers a hand-in asks for. Every number comes from
the library: `qc_control.studies.quick.quick_comparison` at the current
step, `qc_control.studies.quick.error_ladder` for the convergence figure,
`qc_control.numerics.stability.stability_boundary` for the regions, and a
`Scenario` for the run, its checks (a run over `EXPLORE_MAX_STEPS` steps is
refused with the command line's message), its TOML and its command.

The figures are Bokeh's (Panel's own), updated in place: a redraw sends
new columns to the browser, and no image is rendered on the server. Every
script, style and font is served by the local Panel server: the page needs
no internet. Panel is imported only here, when the page is made
(``pip install "qc-control[explore]"``); the rest of the package does not
need it.
"""

from __future__ import annotations

import dataclasses
import functools
import html
import io
import socket
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd

from ..models.modal import modal_analysis
from ..models.quarter import QuarterCarParams
from ..numerics.messages import install_hint
from ..numerics.methods import TABLEAUS
from ..numerics.stability import stability_boundary
from ..numerics.steps import whole_step
from ..studies import columns as col
from ..studies.compare import DEFAULT_METHODS
from ..studies.quick import QuickComparison, error_ladder, ladder_steps, quick_comparison
from ..studies.scenario import Scenario
from ..studies.scenario_toml import CLI_ROADS, MAX_STEPS, ScenarioError, road_from_mapping

__all__ = [
    "explorer",
    "serve",
    "PRESETS",
    "EXPLORE_MAX_STEPS",
    "scenario_of",
    "ExplorerUnavailable",
]

#: The longest run the page accepts, steps t_end/h (the issue's bound): python-control's
#: exact response, a Python loop, takes some 5 s over a million samples and each method
#: a quarter of a second; a longer run is refused with the Scenario's message.
EXPLORE_MAX_STEPS = 1_000_000

#: Named vehicles: the seed's car (Table 1) and illustrative others, for a first look.
PRESETS: dict[str, dict[str, float]] = {
    "seed's car (Table 1)": {"ms": 301.2, "mu": 100.0, "ks": 30000.0, "ku": 29530.0, "zeta": 0.25},
    "seed's car, lightly damped": {
        "ms": 301.2,
        "mu": 100.0,
        "ks": 30000.0,
        "ku": 29530.0,
        "zeta": 0.1,
    },
    "family car (stiff tire)": {
        "ms": 400.0,
        "mu": 45.0,
        "ks": 22000.0,
        "ku": 200000.0,
        "zeta": 0.3,
    },
    "sports car": {"ms": 300.0, "mu": 35.0, "ks": 45000.0, "ku": 250000.0, "zeta": 0.4},
}
_SEED = next(iter(PRESETS))

#: The fixed window of the stability figure (z = hλ): every explicit tableau's
#: region fits (RK4 reaches -2.79), and the modes move through it as h grows.
_REGION_X = (-5.0, 1.0)
_REGION_Y = (-4.0, 4.0)
_COLORS = ("#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2")


class ExplorerUnavailable(ImportError):
    """Panel is not installed: ``pip install "qc-control[explore]"``."""


def _panel():
    """Panel, imported on first use, or a clear error saying which extra installs it."""
    try:
        import panel as pn  # the explore extra: only the page needs it
    except ImportError:
        raise ExplorerUnavailable(
            f"qc-control explore needs Panel, which is not installed: {install_hint('explore')}"
        ) from None
    return pn


def _road_fields() -> dict[str, Any]:
    """Every road parameter of every kind, once, with the kinds that take it."""
    found: dict[str, Any] = {}
    for kind, cls in CLI_ROADS.items():
        for f in dataclasses.fields(cls):
            if f.name != "band":  # the ISO band: a setting for specialists, left at its default
                found.setdefault(f.name, (f, []))[1].append(kind)
    return found


def scenario_of(values: dict[str, Any]) -> Scenario:
    """The `Scenario` of the page's values: the vehicle, start, road, grid and methods.

    ``h`` [ms] is moved to the nearest step that divides ``t_end``
    (`qc_control.numerics.steps.whole_step`); a run of more than `MAX_STEPS`
    steps is given ``max_steps = EXPLORE_MAX_STEPS``, so that longer ones are
    refused with the command line's message. Raises `ScenarioError` for a
    bad value.
    """
    empty = [k for k in ("ms", "mu", "ks", "ku", "zeta", "h", "t_end") if values[k] is None]
    if empty:
        raise ScenarioError(f"{empty[0]} must be given: the box is empty", None, empty[0])
    vehicle = {k: float(values[k]) for k in ("ms", "mu", "ks", "ku", "zeta")}
    kind = values["road"]
    road = {"kind": kind}
    for name, (_, kinds) in _road_fields().items():
        if kind in kinds:
            road[name] = values[f"road_{name}"]
    t_end = float(values["t_end"])
    h = float(values["h"]) * 1e-3
    if not (np.isfinite(h) and h > 0 and np.isfinite(t_end) and t_end > 0):
        raise ScenarioError(
            f"h and t_end must be times > 0, got h = {values['h']!r} ms and t_end = {t_end!r} s",
            "scenario",
            "h",
        )
    h = whole_step(t_end, h)
    steps = round(t_end / h)
    return Scenario(
        vehicle=QuarterCarParams(**vehicle),
        road=road_from_mapping(road),
        x0=tuple(float(values[k]) for k in ("vs0", "vu0", "xs0", "xu0")),
        t_end=t_end,
        h=h,
        methods=tuple(values["methods"]),
        max_steps=MAX_STEPS if steps <= MAX_STEPS else EXPLORE_MAX_STEPS,
    )


#: The convergence ladders computed, by what they depend on (not h): a change of the
#: step reuses its ladder.
_LADDERS: dict[tuple, pd.DataFrame] = {}


def _ladder(sc: Scenario, vehicle) -> pd.DataFrame:
    """The convergence figure's errors over a ladder of steps up to what the road allows."""
    key = (sc.vehicle, sc.x0, sc.road, sc.t_end, sc.methods)
    if key not in _LADDERS:
        if len(_LADDERS) >= 32:
            _LADDERS.clear()
        steps = ladder_steps(sc.t_end, h_range=(1e-4, min(0.2, sc.road.largest_step())))
        _LADDERS[key] = error_ladder(
            vehicle, sc.t_end, sc.x0, lambda T: sc.road_input(T)[0], sc.methods, steps
        )
    return _LADDERS[key]


@functools.lru_cache(maxsize=32)
def _boundary(method: str) -> list[np.ndarray]:
    x = np.linspace(*_REGION_X, 301)
    y = np.linspace(*_REGION_Y, 401)
    return stability_boundary(method, x, y)


# ------------------------------------------------------------------ the page


def _figures():
    """The four Bokeh figures, the exact response's source, the modes' points, the
    current-h line and the legends; each method's lines are added when it is first
    chosen (`_method_lines`): a figure paints every renderer it holds, used or not."""
    from bokeh.models import ColumnDataSource, Legend, Range1d, Span  # with Panel
    from bokeh.plotting import figure  # Bokeh comes with Panel (the explore extra)

    tools = "pan,wheel_zoom,box_zoom,reset,save"
    common = dict(height=300, sizing_mode="stretch_width", tools=tools, output_backend="canvas")
    response = figure(title="Response", x_axis_label="t [s]", **common)
    response.y_range = Range1d(-0.06, 0.06)
    error = figure(title="Error against time", x_axis_label="t [s]", y_axis_type="log", **common)
    error.y_range = Range1d(1e-16, 1.0)
    conv = figure(
        title="Convergence: max body error over the run (current h marked)",
        x_axis_label="h [s]",
        y_axis_label="max |xs error| [m]",
        x_axis_type="log",
        y_axis_type="log",
        **common,
    )
    conv.y_range = Range1d(1e-15, 10.0)
    region = figure(
        title="Stability regions |R(hλ)| ≤ 1, with hλ of each mode",
        x_axis_label="Re hλ [-]",
        y_axis_label="Im hλ [-]",
        match_aspect=True,
        **common,
    )
    region.x_range, region.y_range = Range1d(*_REGION_X), Range1d(*_REGION_Y)
    exact = ColumnDataSource({"t": [], "y": []})
    line = response.line("t", "y", source=exact, color="black", line_width=3, alpha=0.5)
    points = ColumnDataSource({"x": [], "y": [], "mode": []})
    region.scatter("x", "y", source=points, color="black", size=9, marker="circle_x")
    now = Span(location=1e-3, dimension="height", line_color="gray", line_dash="dotted")
    conv.add_layout(now)
    figs = {"response": response, "error": error, "conv": conv, "region": region}
    legends = {}
    for key, fig in figs.items():
        legend = Legend(items=[], location="top_right", click_policy="hide")
        fig.add_layout(legend, "right")
        legends[key] = (legend, {"exact (python-control)": [line]} if key == "response" else {})
    shared = {"exact": exact, "points": points, "now": now, "legends": legends}
    return figs, shared


def _method_lines(figs, legends, method: str) -> dict[str, Any]:
    """A method's sources and lines in every figure, in its colour; its legend entries."""
    from bokeh.models import ColumnDataSource  # with Panel (the explore extra)

    i = list(TABLEAUS).index(method)
    color, dash = _COLORS[i % len(_COLORS)], ("solid" if i % 2 == 0 else "dashed")
    src = {
        k: ColumnDataSource({"x": [], "y": []}, name=f"{k}-{method}")
        for k in ("response", "error", "conv")
    }
    src["mark"] = ColumnDataSource({"x": [], "y": []})
    src["region"] = ColumnDataSource({"xs": [], "ys": []})
    style = dict(color=color, line_dash=dash)
    lines = {
        "response": figs["response"].line("x", "y", source=src["response"], **style),
        "error": figs["error"].line("x", "y", source=src["error"], **style),
        "conv": figs["conv"].line("x", "y", source=src["conv"], **style),
        "region": figs["region"].multi_line(
            "xs", "ys", source=src["region"], color=color, line_width=2
        ),
    }
    figs["conv"].scatter("x", "y", source=src["conv"], color=color, size=4)
    figs["conv"].scatter("x", "y", source=src["mark"], color=color, size=12, marker="diamond")
    for key, renderer in lines.items():
        legends[key][1][method] = [renderer]
    return src


def _legend_items(legends, chosen: list[str]):
    from bokeh.models import LegendItem  # with Panel (the explore extra)

    for legend, items in legends.values():
        keep = [name for name in items if name in chosen or name.startswith("exact")]
        legend.items = [LegendItem(label=name, renderers=items[name]) for name in keep]


@functools.lru_cache(maxsize=32)
def _modal_html(vehicle: QuarterCarParams) -> str:
    """The modal table of a vehicle (kept: it changes with the vehicle, not with h)."""
    return _table_html(modal_analysis(vehicle).to_frame())


def _table_html(frame: pd.DataFrame, digits: int = 4) -> str:
    """A frame as an HTML table, numbers to ``digits`` significant digits."""

    def number(v):
        if isinstance(v, (bool, np.bool_, str)):
            return str(v)
        if isinstance(v, complex):
            return f"{v.real:.{digits}g}{v.imag:+.{digits}g}j"
        return f"{v:.{digits}g}"

    return frame.to_html(formatters=dict.fromkeys(frame.columns, number), border=0)


class _Page:
    """The explorer's widgets, figures and the one callback that redraws them."""

    def __init__(self, pn, values: dict[str, Any]):
        self.pn = pn
        self.values = values
        self.figs, self.shared = _figures()
        self.sources: dict[str, dict[str, Any]] = {}  # per method, once it was chosen
        self.widgets = _widgets(pn, values)
        # fixed heights: new text in a pane does not move the figures, which would
        # then be laid out and painted again
        scroll = {"overflow-y": "auto"}
        self.status = pn.pane.HTML(
            "", height=40, sizing_mode="stretch_width", css_classes=["qc-status"], styles=scroll
        )
        self.verdicts = pn.pane.HTML(
            "", height=110, sizing_mode="stretch_width", css_classes=["qc-verdicts"], styles=scroll
        )
        self.handin = pn.pane.HTML("", height=190, css_classes=["qc-handin"], styles=scroll)
        self.modal = pn.pane.HTML("", height=90, css_classes=["qc-modes"], styles=scroll)
        self.distortion = pn.pane.HTML("", height=300, css_classes=["qc-distortion"], styles=scroll)
        self.toml = pn.widgets.TextAreaInput(
            name="scenario.toml (qc-control report --config scenario.toml)",
            height=260,
            sizing_mode="stretch_width",
            css_classes=["qc-toml"],
        )
        self.command = pn.pane.HTML("", css_classes=["qc-command"], sizing_mode="stretch_width")
        self.redraws = 0
        self._quiet = False
        self._legend_methods: tuple[str, ...] = ()
        self.scenario: Scenario | None = None
        from bokeh.models import ColumnDataSource  # with Panel (the explore extra)

        # updated last in every redraw: a browser test waits for it (tests/test_explore.py)
        self.stamp = ColumnDataSource({"n": [0]}, name="qc-redraw-stamp")
        for w in self.widgets.values():
            w.param.watch(self._changed, "value")

    # --------------------------------------------------------------- redraw

    def _changed(self, event) -> None:
        name = event.obj.name_key
        if name == "log_h":  # the slider sets h, whose change redraws
            return
        self.values[name] = event.new
        if self._quiet:
            return
        self._quiet = True  # the values set below redraw once, at the end
        try:
            self._follow(name, event.new)
        finally:
            self._quiet = False
        self.redraw()

    def _follow(self, name: str, value) -> None:
        """What one change brings with it: a preset's values, the start under a road."""
        w = self.widgets
        if name == "h" and value and value > 0:
            w["log_h"].value = float(np.log10(value))
        elif name == "preset" and value in PRESETS:
            for key, number in PRESETS[value].items():
                w[key].value = number
        elif name in ("ms", "mu", "ks", "ku", "zeta"):
            chosen = PRESETS.get(self.values["preset"], {})
            if chosen and chosen.get(name) != value:
                w["preset"].value = "custom"
        elif name == "road":  # under a road the car starts at rest; free, it is released
            start = (0.0, 0.0, 0.0, 0.0) if value != "none" else (0.0, 0.0, 0.05, 0.0)
            for key, number in zip(("vs0", "vu0", "xs0", "xu0"), start):
                w[key].value = number
            self._show_road_fields()

    def _show_road_fields(self) -> None:
        for name, (_, kinds) in _road_fields().items():
            self.widgets[f"road_{name}"].visible = self.values["road"] in kinds

    def redraw(self) -> None:
        """Recompute from the current values and update every figure and table."""
        start = time.perf_counter()
        try:
            sc = scenario_of(self.values)
            vehicle, T, U, _ = sc.problem()
            quick = quick_comparison(vehicle, T, sc.x0, U, sc.methods)
            ladder = _ladder(sc, vehicle)
        except (ScenarioError, ValueError, TypeError) as exc:
            self.status.object = f'<p style="color:#b00">⚠ {_escape(str(exc))}</p>'
            self._stamp()
            return
        self.scenario = sc
        elapsed = time.perf_counter() - start
        with self.pn.io.hold():
            self._draw(sc, quick, ladder, vehicle)
            self.status.object = (
                f"<p>{sc.steps:,} steps of h = {1e3 * sc.h:.4g} ms over 0–{sc.t_end:g} s"
                f"{' on ' + sc.road.describe() if sc.road.describe() else ''}; "
                f"computed in {1e3 * elapsed:.0f} ms</p>"
            )
            self._stamp()

    def _stamp(self) -> None:
        self.redraws += 1
        self.stamp.data = {"n": [self.redraws]}

    def _draw(self, sc: Scenario, quick: QuickComparison, ladder, vehicle) -> None:
        label = self.values["output"]
        unit = vehicle.unit(label)
        labels = list(quick.reference.output_labels)
        row = labels.index(label)
        ref = np.asarray(quick.reference.outputs)[row]
        t, y = _shown(quick.T, ref)
        self.shared["exact"].data = {"t": t, "y": y}
        peak = float(np.max(np.abs(ref))) or 1.0
        response, error = self.figs["response"], self.figs["error"]
        response.y_range.start, response.y_range.end = -1.6 * peak, 1.6 * peak
        response.yaxis.axis_label = f"{label} [{unit}]"
        response.title.text = f"Response: {label} [{unit}], the methods over the exact response"
        error.yaxis.axis_label = f"|{label} error| [{unit}]"
        error.y_range.end = 10 * peak
        h = quick.h
        for method in sc.methods:
            if method not in self.sources:
                self.sources[method] = _method_lines(self.figs, self.shared["legends"], method)
        for method, src in self.sources.items():
            chosen = method in sc.methods
            self._draw_method(method, src, quick, ladder, row, chosen)
        if sc.methods != self._legend_methods:  # new legend items re-walk the whole document
            _legend_items(self.shared["legends"], list(sc.methods))
            self._legend_methods = sc.methods
        self.shared["now"].location = h
        lam = quick.scaled_eigenvalues
        self.shared["points"].data = {
            "x": np.concatenate([lam.real, lam.real]),
            "y": np.concatenate([lam.imag, -lam.imag]),
            "mode": [m.name for m in quick.modes.modes] * 2,
        }
        self._tables(sc, quick, label, unit)

    def _draw_method(self, method, src, quick, ladder, row, chosen) -> None:
        if not chosen:
            src.pop("ladder", None)
            for key in ("response", "error", "conv", "mark"):
                if len(src[key].data["x"]):
                    src[key].data = {"x": [], "y": []}
            if len(src["region"].data["xs"]):
                src["region"].data = {"xs": [], "ys": []}
            return
        for key, curves in (("response", quick.outputs), ("error", quick.errors)):
            t, y = _shown(quick.T, curves[method][row])
            src[key].data = {"x": t, "y": y}
        if src.get("ladder") is not ladder:  # a new ladder (not a new h): send it
            mine = ladder[ladder["method"] == method]
            src["conv"].data = {"x": mine["h"].to_numpy(), "y": mine["error"].to_numpy()}
            src["ladder"] = ladder
        at_h = quick.table.loc[method, col.max_error("xs", "m")]
        src["mark"].data = {"x": [quick.h], "y": [at_h]}
        if not len(src["region"].data["xs"]):
            curves = _boundary(method)
            src["region"].data = {
                "xs": [c.real for c in curves],
                "ys": [c.imag for c in curves],
            }

    def _tables(self, sc: Scenario, quick: QuickComparison, label: str, unit: str) -> None:
        table = quick.table
        err, xs_err = col.max_error(label, unit), col.max_error("xs", "m")
        handin = pd.DataFrame(
            {
                col.ORDER: table[col.ORDER],
                col.STEP: quick.h,
                col.RHS_EVALS: table[col.RHS_EVALS],
                err: table[err],
                xs_err: table[xs_err],
                col.H_MAX: table[col.H_MAX],
                col.LIMITED_BY: table[col.LIMITED_BY],
            }
        )
        handin = handin.loc[:, ~handin.columns.duplicated()]
        self.handin.object = _table_html(handin)
        self.verdicts.object = "".join(
            f'<p class="verdict" data-method="{m}" style="margin:2px 0"><b>{m}</b>: {verdict}</p>'
            for m, verdict in zip(sc.methods, table.loc[list(sc.methods), "verdict"].astype(str))
        )
        self.modal.object = _modal_html(sc.vehicle)
        distortion = pd.concat(
            {
                m: quick.numerical_modes[m][["fd_h [Hz]", "freq error [%]", "zeta_h", "zeta error"]]
                for m in sc.methods
            },
            names=["method", "mode"],
        )
        self.distortion.object = _table_html(distortion)

    # --------------------------------------------------------------- export

    def export(self, event=None) -> None:
        """Fill the TOML and the command of the current run (the Scenario's own)."""
        if self.scenario is None:
            return
        self.toml.value = self.scenario.to_toml()
        command = self.scenario.command(config="scenario.toml")
        self.command.object = (
            f"<pre>{_escape(command)}</pre><pre>{_escape(self.scenario.command())}</pre>"
        )

    def layout(self):
        pn = self.pn
        w = self.widgets
        export = pn.widgets.Button(name="Export scenario (TOML + command)", button_type="primary")
        export.on_click(self.export)
        download = pn.widgets.FileDownload(
            callback=lambda: _text_file(self.scenario.to_toml() if self.scenario else ""),
            filename="scenario.toml",
            label="Download scenario.toml",
        )
        road = [w["road"], *(w[f"road_{n}"] for n in _road_fields())]
        controls = pn.Column(
            "### Vehicle",
            w["preset"],
            *(w[k] for k in ("ms", "mu", "ks", "ku", "zeta")),
            "### Methods and step",
            w["methods"],
            w["log_h"],
            w["h"],
            w["t_end"],
            "### Start [m/s, m/s, m, m]",
            pn.Row(w["vs0"], w["vu0"]),
            pn.Row(w["xs0"], w["xu0"]),
            "### Road",
            *road,
            "### Output",
            w["output"],
            width=300,
        )
        figs = self.figs
        main = pn.Column(
            self.status,
            self.verdicts,
            pn.Row(pn.pane.Bokeh(figs["response"]), pn.pane.Bokeh(figs["error"])),
            pn.Row(pn.pane.Bokeh(figs["conv"]), pn.pane.Bokeh(figs["region"])),
            "### Numbers for the hand-in",
            self.handin,
            "### Modes (exact)",
            self.modal,
            "### Each method's view of the modes at h",
            self.distortion,
            "### From play to hand-in",
            pn.Row(export, download),
            self.command,
            self.toml,
            pn.pane.Bokeh(_stamp_holder(self.stamp)),
            sizing_mode="stretch_width",
        )
        return pn.Row(controls, main, sizing_mode="stretch_width")


def _stamp_holder(stamp):
    """A plot that holds the redraw stamp, so that it is part of the browser's document."""
    from bokeh.plotting import figure  # with Panel (the explore extra)

    holder = figure(width=10, height=10, toolbar_location=None, visible=False)
    holder.scatter("n", "n", source=stamp, alpha=0)
    return holder


#: A curve longer than this is drawn from its extremes per stretch (`_shown`).
_DRAWN = 1000


def _shown(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A curve as the browser draws it: the samples that a figure 500-1000 px wide
    can show apart, in single precision (a screen shows 3 digits).

    Over ``_DRAWN`` samples, the curve is cut into ``_DRAWN / 2`` stretches and each
    keeps its smallest and largest sample, in time order (min-max decimation): every
    peak, and a run that blew up (inf), is drawn as it is; what is dropped are
    samples between two others of the same stretch, which fall on the same pixel
    column. The numbers in the tables are the library's, from every sample.
    """
    t, y = np.asarray(t), np.asarray(y)
    if y.size > _DRAWN:
        per = y.size // (_DRAWN // 2)
        whole = per * (_DRAWN // 2)
        block = y[:whole].reshape(-1, per)
        base = np.arange(0, whole, per)
        with np.errstate(invalid="ignore"):
            keep = np.concatenate(
                [base + np.argmin(block, axis=1), base + np.argmax(block, axis=1)]
            )
        keep = np.unique(np.concatenate([keep, np.arange(whole, y.size), [0, y.size - 1]]))
        t, y = t[keep], y[keep]
    with np.errstate(over="ignore"):
        return t.astype(np.float32), y.astype(np.float32)


def _escape(text: str) -> str:
    return html.escape(text)


def _text_file(text: str):
    return io.StringIO(text)


def _widgets(pn, values: dict[str, Any]) -> dict[str, Any]:
    """One widget per value, named by its key (``name_key``), showing its unit."""
    from bokeh.models import CustomJSTickFormatter  # with Panel (the explore extra)

    W = pn.widgets
    w: dict[str, Any] = {
        "preset": W.Select(name="preset", options=[*PRESETS, "custom"], value=values["preset"]),
        "ms": W.FloatInput(name="ms: body mass [kg]", value=values["ms"], start=1e-6),
        "mu": W.FloatInput(name="mu: wheel mass [kg]", value=values["mu"], start=1e-6),
        "ks": W.FloatInput(name="ks: suspension stiffness [N/m]", value=values["ks"], step=1000),
        "ku": W.FloatInput(name="ku: tire stiffness [N/m]", value=values["ku"], step=1000),
        "zeta": W.FloatInput(
            name="zeta: nominal damping ratio [-]", value=values["zeta"], step=0.05
        ),
        "methods": W.MultiChoice(name="methods", options=list(TABLEAUS), value=values["methods"]),
        "log_h": W.FloatSlider(
            name="step h (log scale)",
            start=-1.0,
            end=float(np.log10(200.0)),
            step=0.001,
            value=float(np.log10(values["h"])),
            format=CustomJSTickFormatter(code="return (10 ** tick).toPrecision(3) + ' ms'"),
        ),
        "h": W.FloatInput(name="h [ms]", value=values["h"], start=0.1, end=200.0),
        "t_end": W.FloatInput(name="t_end [s]", value=values["t_end"], start=0.001),
        "vs0": W.FloatInput(name="vs [m/s]", value=values["vs0"], width=120),
        "vu0": W.FloatInput(name="vu [m/s]", value=values["vu0"], width=120),
        "xs0": W.FloatInput(name="xs [m]", value=values["xs0"], width=120),
        "xu0": W.FloatInput(name="xu [m]", value=values["xu0"], width=120),
        "road": W.Select(name="road", options=list(CLI_ROADS), value=values["road"]),
        "output": W.Select(
            name="output",
            options=["xs", "xu", "susp_travel", "tire_defl", "body_acc"],
            value=values["output"],
        ),
    }
    for name, (f, kinds) in _road_fields().items():
        unit = f" [{f.metadata['unit']}]" if f.metadata["unit"] else ""
        label = f"{f.metadata['help']}{unit}"
        value = values[f"road_{name}"]
        if isinstance(f.default, str):
            widget = W.Select(name=label, options=list("ABCDEFGH"), value=value)
        elif isinstance(f.default, int):
            widget = W.IntInput(name=label, value=value)
        else:
            widget = W.FloatInput(name=label, value=value)
        widget.visible = values["road"] in kinds
        w[f"road_{name}"] = widget
    for key, widget in w.items():
        widget.name_key = key
        widget.css_classes = [f"qc-{key}"]  # how a test (or a user's style) finds it
    w["log_h"].param.watch(lambda e: setattr(w["h"], "value", round(10**e.new, 4)), "value")
    return w


def default_values() -> dict[str, Any]:
    """The page's start: the seed's car released from 5 cm, 10 s at 1 ms, the four methods."""
    values: dict[str, Any] = {"preset": _SEED, **PRESETS[_SEED]}
    values.update(
        methods=list(DEFAULT_METHODS),
        h=1.0,
        t_end=10.0,
        vs0=0.0,
        vu0=0.0,
        xs0=0.05,
        xu0=0.0,
        road="none",
        output="xs",
    )
    for name, (f, _) in _road_fields().items():
        values[f"road_{name}"] = f.default
    return values


def explorer(**values):
    """The explorer as a Panel layout: in a notebook, or served by `serve`.

    Parameters
    ----------
    **values
        Start values by key (``ms=350.0``, ``h=20.0`` [ms], ``road='bump'``,
        ``methods=['euler', 'rk4']``); the rest are `default_values`.

    Returns
    -------
    panel.layout.Row
    """
    pn = _panel()
    if not pn.state.served:  # a notebook: load Panel's scripts into it (inline, no CDN)
        pn.extension()
    start = default_values()
    unknown = set(values) - set(start)
    if unknown:
        raise TypeError(f"explorer() got unknown values {sorted(unknown)}; known: {sorted(start)}")
    start.update(values)
    page = _Page(pn, start)
    layout = page.layout()
    _sync_url(pn, page)
    page.redraw()
    layout.explorer_page = page  # for tests and notebooks: the page behind the layout
    return layout


def _sync_url(pn, page: _Page) -> None:
    """Keep the page's values in its URL's query (a link opens with the same settings)."""
    location = pn.state.location
    if location is None:  # a notebook: no URL to keep
        return
    for key, widget in page.widgets.items():
        if key != "log_h":
            location.sync(widget, {"value": key})


def free_port(host: str = "127.0.0.1") -> int:
    """A port no one listens on now (the system's choice)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def serve(port: int = 5006, show: bool = True, say: Callable[[str], None] = print) -> None:
    """Serve the explorer on 127.0.0.1 until interrupted; ``say`` gets its address.

    ``port=0`` takes a free port. The page's scripts, styles and fonts come
    from this server: it needs no internet.
    """
    pn = _panel()
    port = free_port() if port == 0 else port
    origins = [f"127.0.0.1:{port}", f"localhost:{port}"]
    server = pn.serve(
        {"/": explorer},
        port=port,
        address="127.0.0.1",
        websocket_origin=origins,
        show=False,
        start=False,
        title="qc-control explorer",
    )
    url = f"http://127.0.0.1:{port}/"
    say(f"qc-control explore: serving {url} (Ctrl-C stops it)")
    if show:
        server.io_loop.add_callback(server.show, "/")
    server.io_loop.start()
