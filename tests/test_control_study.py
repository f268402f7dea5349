"""The controller comparison, its report and ``qc-control control-report``.

References: the passive row against python-control's exact response
(control.forced_response; the LTI engine substepped to RK4 at h|λ| <= 0.1
is within 1e-6 of it, bound 1e-5 relative); the invariant point of the
body-acceleration transmissibility, |body_acc/zr| = ku/ms at
f = √(ku/mu)/2π for any force acting between body and wheel (Hedrick &
Butsuen 1990), to 1e-9 relative.
"""

import math
import tracemalloc

import control
import numpy as np
import pytest
from reports_shared import quick_figures, without_pdf  # noqa: F401  (fixtures)

import qc_control as qc
from qc_control.cli.parser import run
from qc_control.models.controllers import HINF_AVAILABLE
from qc_control.numerics.limits import ResourceLimitError
from qc_control.report.control import transmissibility_chart, write_control_report
from qc_control.ride import road
from qc_control.studies import control_study
from qc_control.studies.control_study import compare_controllers

P = qc.QuarterCarParams()
F_INV = math.sqrt(P.ku / P.mu) / (2 * math.pi)
DESIGNS = ["passive (seed)", "skyhook", "skyhook semi-active", "LQR"]


@pytest.fixture(scope="module")
def cmp():
    return compare_controllers(
        P, designs=DESIGNS, road_duration=3.0, bump_duration=3.0, freqs_hz=[0.5, F_INV, 8.0]
    )


def test_passive_row_matches_the_exact_response(cmp):
    T = np.arange(0.0, 3.0 + 0.0025, 0.005)
    zr = road.iso8608(T, "C", speed=20.0, seed=0)
    model = qc.quarter_car_model(P, road=True)
    exact = qc.ride_metrics(control.forced_response(model.system, T, zr), model)
    for col in ("rms_body_acc [m/s²]", "rms_tire_load / static [-]", "rms_susp_travel [m]"):
        assert cmp.table.loc["passive (seed)", f"road: {col}"] == pytest.approx(
            exact[col], rel=1e-5
        )


def test_actuator_power_signs(cmp):
    t = cmp.table
    assert t.loc["passive (seed)", "road: rms actuator force [N]"] == 0.0
    assert t.loc["skyhook semi-active", "road: mean actuator power [W]"] <= 0.0  # dissipates
    assert t.loc["skyhook semi-active", "road: rms actuator force [N]"] > 0.0


def test_invariant_point_holds_for_every_linear_design(cmp):
    assert set(cmp.transmissibility) == {"passive (seed)", "skyhook", "LQR"}
    for name, mags in cmp.transmissibility.items():
        assert mags["body_acc"][1] == pytest.approx(P.ku / P.ms, rel=1e-9), name


def test_exact_metrics_and_the_front(cmp):
    """The passive row of the exact table against the Gobbi & Mastinu closed form (1e-9).

    (The issue quotes 1.25911 m/s² unbounded for the seed car on class C at 20 m/s.)
    """
    assert list(cmp.exact.index) == ["passive (seed)", "skyhook", "LQR"]
    q = 2 * math.pi**2 * 0.1**2 * 256e-6 * 20.0  # ISO 8608 class C (Gd(n0) = 256e-6 m³), 20 m/s
    var = q * (P.cs**2 * P.ku + P.ks**2 * (P.ms + P.mu)) / (2 * P.cs * P.ms**2)
    acc = cmp.exact.loc["passive (seed)", "rms_body_acc [m/s²]"]
    assert acc == pytest.approx(math.sqrt(var), rel=1e-9)
    assert round(acc, 5) == 1.25911
    assert {"skyhook", "LQR"} <= set(cmp.pareto.markers.index)


def test_report_files_and_axes(cmp, tmp_path):
    out = write_control_report(cmp, tmp_path / "r", formats=("md", "html", "csv"))
    names = {p.name for p in out.iterdir()}
    assert {"report.md", "report.html", "control_table.csv", "transmissibility.csv"} <= names
    assert {"transmissibility_body_acc.png", "transmissibility_tire_defl.png"} <= names
    assert {"pareto.png", "exact_metrics.csv"} <= names
    md = (out / "report.md").read_text(encoding="utf-8")
    assert "skyhook semi-active" in md and "Figure 2" in md
    ax = transmissibility_chart(cmp, "tire_defl").axes[0]
    assert ax.get_xlabel() == "frequency [Hz]" and "[m/m]" in ax.get_ylabel()
    assert len(ax.get_lines()) == 3  # one curve per linear design


@pytest.mark.slow
# the command's status, page and output, not its pictures or PDF (0.65 of its 1.5 CPU-s)
@pytest.mark.usefixtures("quick_figures", "without_pdf")
def test_cli_control_report(tmp_path, capsys):
    out = tmp_path / "cr"
    argv = ["control-report", "--designs", "passive (seed),skyhook", "--out", str(out)]
    argv += ["--road-duration", "2", "--bump-duration", "2", "-q"]
    assert run(argv) == 0
    assert (out / "report.html").exists()
    assert "skyhook" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv, match",
    [
        (["--designs", "magic"], "--designs: unknown design 'magic'"),
        (["--speed", "-1"], "speed"),
    ],
)
def test_cli_control_report_bad_input(tmp_path, capsys, argv, match):
    assert run(["control-report", "--out", str(tmp_path / "x"), "-q", *argv]) == 2
    assert match in capsys.readouterr().err


# Issue 28 item 10: any valid selection runs; an empty one is refused up front.


@pytest.mark.parametrize("alone", ["skyhook semi-active", "LQR"])
def test_one_design_alone_gives_its_row_of_the_full_comparison(cmp, alone):
    """A semi-active loop alone has no linear design: the exact table and the
    transmissibility are empty (they were a pandas 'No objects to concatenate').
    Its numbers are those it has among the others: each design's runs are its
    own (equal to 1e-12 relative: the same arithmetic, in the same order)."""
    one = compare_controllers(
        P, designs=[alone], road_duration=3.0, bump_duration=3.0, freqs_hz=[0.5, F_INV, 8.0]
    )
    assert list(one.table.index) == [alone]
    np.testing.assert_allclose(one.table.loc[alone], cmp.table.loc[alone], rtol=1e-12)
    linear = alone == "LQR"
    assert list(one.transmissibility) == ([alone] if linear else [])
    assert list(one.exact.index) == ([alone] if linear else [])
    assert one.pareto is not None  # the passive front does not need a controller


def test_a_semi_active_report_leaves_out_what_it_has_not(tmp_path):
    """No transmissibility figures or files without a linear design; the front is Figure 1."""
    one = compare_controllers(P, designs=["skyhook semi-active"], road_duration=1.0)
    out = write_control_report(one, tmp_path / "r", formats=("md", "csv"))
    names = {p.name for p in out.iterdir()}
    assert {"control_table.csv", "pareto.png", "report.md"} <= names
    assert not {"transmissibility.csv", "exact_metrics.csv"} & names
    assert not any(n.startswith("transmissibility_") for n in names)
    md = (out / "report.md").read_text(encoding="utf-8")
    assert "Figure 1: Passive designs" in md and "Figure 2" not in md


@pytest.mark.parametrize(
    "designs, error, words",
    [
        ([], ValueError, "designs must name at least one design; choose from ["),
        ((), ValueError, "'skyhook semi-active'"),
        ("skyhook", TypeError, "designs must be a sequence of design names, got 'skyhook'"),
        (["skyhook", "sky hook"], ValueError, "unknown design 'sky hook'; choose from"),
    ],
)
def test_a_bad_selection_is_refused_naming_the_choices(monkeypatch, designs, error, words):
    monkeypatch.setattr(control_study, "_run", lambda *a: pytest.fail("ran a bad selection"))
    with pytest.raises(error) as info:
        compare_controllers(designs=designs)
    assert words in str(info.value)


# Issue 28 item 4: a run too long for memory is refused before any grid is made.


@pytest.mark.parametrize(
    "kwargs, samples",
    [
        # 1e7 s of road at 5 ms and the default 15 s bump at 2 ms, each with its end point
        ({"road_duration": 1e7}, 1e7 / 0.005 + 15 / 0.002 + 2),
        ({"road_duration": 1e5}, 1e5 / 0.005 + 15 / 0.002 + 2),
        ({"bump_duration": 1e300}, 1e300 / 0.002 + 10 / 0.005 + 2),
    ],
)
def test_a_run_too_long_for_memory_is_refused_before_computing(monkeypatch, kwargs, samples):
    """The 1e7 s road was a 14.9 GiB np.arange and a traceback; 1e5 s computed for 33 s."""
    monkeypatch.setenv("QC_CONTROL_MAX_MEMORY", "16G")  # the same verdict on every machine
    monkeypatch.setattr(control_study, "_run", lambda *a: pytest.fail("computed"))
    monkeypatch.setattr(control_study.np, "arange", lambda *a, **k: pytest.fail("made a grid"))
    with pytest.raises(ResourceLimitError) as info:
        compare_controllers(**kwargs)
    text = str(info.value)
    assert f"a controller comparison over {samples:.3g} samples" in text
    assert "use a shorter road_duration or bump_duration" in text


@pytest.mark.slow
@pytest.mark.parametrize(
    "design, road_duration", [("H∞", 400.0), ("passive (seed)", 400.0), ("ADD", 40.0)]
)
def test_the_memory_estimate_bounds_the_measured_peak(monkeypatch, design, road_duration):
    """The estimate handed to check_memory is at least the peak Python allocation
    that tracemalloc measures over the whole comparison (numpy reports its arrays
    to tracemalloc), for the heaviest linear loop, the plain car and the heaviest
    semi-active one."""
    if design == "H∞" and not HINF_AVAILABLE:
        pytest.skip("H∞ needs slycot")
    estimates = []
    monkeypatch.setattr(control_study, "check_memory", lambda n, *a: estimates.append(n))
    tracemalloc.start()
    try:
        compare_controllers(designs=[design], road_duration=road_duration, bump_duration=2.0)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert len(estimates) == 1 and estimates[0] >= peak, (estimates, peak)
