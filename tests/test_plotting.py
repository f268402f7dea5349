"""qc_control.report.plotting: any named output of several responses over a reference."""

import ast
import types
from pathlib import Path

import control
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import qc_control as qc
from qc_control.report.plotting import OUTPUT_UNITS, output_signal, output_unit, plot_outputs

T = np.linspace(0.0, 3.0, 301)


@pytest.fixture(scope="module")
def runs():
    sys_ = qc.quarter_car(road=True)
    U = qc.road.step(T)
    exact = control.forced_response(sys_, T, U)  # the independent reference
    methods = {m: qc.forced_response(sys_, T, U, method=m) for m in qc.METHODS}
    return exact, methods


def _row(resp, label):
    return np.asarray(resp.outputs)[list(resp.output_labels).index(label)]


def test_overlays_the_named_output_with_units(runs):
    exact, methods = runs
    fig = plot_outputs(methods, "body_acc", reference=exact)
    assert isinstance(fig, Figure)
    top, bottom = fig.axes
    assert top.get_ylabel() == "body_acc [m/s²]" and bottom.get_xlabel() == "time [s]"
    assert bottom.get_yscale() == "log"
    lines = {ln.get_label(): ln for ln in top.lines}
    np.testing.assert_array_equal(lines["reference"].get_ydata(), _row(exact, "body_acc"))
    np.testing.assert_array_equal(lines["rk4"].get_ydata(), _row(methods["rk4"], "body_acc"))
    # the lower panel: |y - y_ref|, with exact zeros left out of the log axis
    gap = np.abs(_row(methods["euler"], "body_acc") - _row(exact, "body_acc"))
    drawn = np.asarray(bottom.lines[0].get_ydata())
    np.testing.assert_array_equal(drawn[gap > 0], gap[gap > 0])
    assert np.all(np.isnan(drawn[gap == 0]))


@pytest.mark.parametrize("name, unit", [("xs", "m"), ("susp_travel", "m"), ("tire_defl", "m")])
def test_every_quarter_car_output_has_its_unit(runs, name, unit):
    exact, methods = runs
    assert output_unit(name) == unit == OUTPUT_UNITS[name]
    fig = plot_outputs(methods, name)
    assert fig.axes[0].get_ylabel() == f"{name} [{unit}]" and len(fig.axes) == 1


def test_looked_up_by_label_not_position(runs):
    exact, methods = runs
    order = ["tire_defl", "body_acc", "xs", "susp_travel", "xu"]
    shuffled = types.SimpleNamespace(
        time=exact.time,
        outputs=np.asarray(exact.outputs)[[list(exact.output_labels).index(n) for n in order]],
        output_labels=order,
    )
    fig = plot_outputs({"control": shuffled}, "xs", difference=False)
    np.testing.assert_array_equal(fig.axes[0].lines[0].get_ydata(), _row(exact, "xs"))
    with pytest.raises(KeyError, match=r"no output 'pitch_acc'; its outputs are \['tire_defl'"):
        output_signal(shuffled, "pitch_acc")


def test_units_from_a_mapping_win():
    assert output_unit("pitch_acc") == ""
    assert output_unit("pitch_acc", {"pitch_acc": "rad/s²"}) == "rad/s²"
    assert output_unit("xs", {"xs": "mm"}) == "mm"


def test_coinciding_curves_are_dashed_and_named(runs):
    exact, methods = runs
    fig = plot_outputs(methods, "xs", reference=exact)
    lines = {ln.get_label(): ln for ln in fig.axes[0].lines}
    heun = next(label for label in lines if label.startswith("heun"))
    assert heun == "heun (= midpoint to 1e-12 m)"
    assert lines["midpoint"].get_linestyle() == "-" and lines[heun].get_linestyle() == "--"


def test_a_list_is_named_by_method_and_designs_by_key(runs):
    exact, methods = runs
    fig = plot_outputs(list(methods.values()), "xs")
    labels = [ln.get_label().split(" (=")[0] for ln in fig.axes[0].lines]
    assert labels == list(qc.METHODS)
    sys_soft = qc.quarter_car(qc.QuarterCarParams(ks=20e3), road=True)
    designs = {
        "ks = 20 kN/m": qc.forced_response(sys_soft, T, qc.road.step(T), method="rk4"),
        "ks = 30 kN/m": methods["rk4"],
    }
    fig = plot_outputs(designs, "susp_travel", title="two springs")
    assert [ln.get_label() for ln in fig.axes[0].lines] == list(designs)
    assert fig.axes[0].get_title() == "two springs"


def test_the_legend_is_outside_the_axes(runs):
    exact, methods = runs
    fig = plot_outputs(methods, "body_acc", reference=exact)
    FigureCanvasAgg(fig)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    box = fig.legends[0].get_window_extent(renderer)
    assert all(not box.overlaps(ax.get_window_extent(renderer)) for ax in fig.axes)


def test_bad_input_is_named(runs):
    exact, methods = runs
    with pytest.raises(TypeError, match="responses must be a mapping"):
        plot_outputs(42)
    with pytest.raises(ValueError, match="at least one response"):
        plot_outputs({})
    with pytest.raises(ValueError, match="difference=True needs a reference"):
        plot_outputs(methods, difference=True)


def test_matplotlib_is_imported_only_when_drawing():
    tree = ast.parse(
        (Path(qc.__file__).parent / "report" / "plotting.py").read_text(encoding="utf-8")
    )
    top = [n for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))]
    names = [a.name for n in top for a in n.names] + [
        n.module for n in top if isinstance(n, ast.ImportFrom)
    ]
    assert not any(str(name).startswith("matplotlib") for name in names)
