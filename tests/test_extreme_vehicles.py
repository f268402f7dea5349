"""Half and full cars with extreme parameter values: refused by name, or analysed.

Every field of both cars is set, one at a time, to values far outside a
car's range (issue 28, item 3: 49 of 228 such ``modes`` runs ended in a
traceback). Each must either be refused by the constructor with a
ValueError, or give a modal table whose frequencies are finite and agree
with the eigenvalues of the model's matrix.
"""

import contextlib
import dataclasses
import io

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from qc_control.cli.parser import run
from qc_control.models.halfcar import FullCarParams, HalfCarParams
from qc_control.models.modal import modal_analysis
from qc_control.models.quarter import MAX_RATE_SPAN

EXTREMES = (1e-300, 1e-12, 1e10, 1e300, -1e300)


def _cases():
    for cls in (HalfCarParams, FullCarParams):
        for f in dataclasses.fields(cls):
            for value in EXTREMES:
                yield pytest.param(cls, f.name, value, id=f"{cls.kind}-{f.name}-{value:g}")


@pytest.mark.parametrize(("cls", "name", "value"), list(_cases()))
def test_an_extreme_value_is_refused_or_analysed(cls, name, value):
    try:
        params = cls(**{name: value})
    except ValueError as exc:
        assert str(exc), "a refusal says why"
        return
    model = params.model()
    table = modal_analysis(model)
    eig = np.linalg.eigvals(model.system.A)
    assert np.all(np.isfinite(eig))
    # each mode's eigenvalue is one of the matrix's: relative 1e-6 covers the
    # rounding of the slowest mode at the largest accepted span (about
    # eps·span, 2e-9, between two eigen-solvers), far below a wrong mode
    for mode in table.modes:
        assert np.isfinite(mode.fn) and mode.fn >= 0
        assert np.min(np.abs(eig - mode.eigenvalue)) <= 1e-6 * abs(mode.eigenvalue)


@pytest.mark.parametrize(
    ("cls", "kwargs", "words"),
    [
        (HalfCarParams, {"a": 1e-9, "b": 1e9}, "time scales span more than"),
        (FullCarParams, {"a": 1e10}, "time scales span more than"),
        (HalfCarParams, {"ks_front": 1e-12}, "sqrt(ks_front/mu_front)"),
        (FullCarParams, {"track_front": 1e-300}, "track_front"),
        (HalfCarParams, {"seat_x": 1e300}, "seat_x"),
        (FullCarParams, {"seat_y": -1e300}, "seat_y"),
        (FullCarParams, {"cs_rear": 1e300}, "cs_rear"),
    ],
)
def test_the_refusal_names_the_cause(cls, kwargs, words):
    with pytest.raises(ValueError) as info:
        cls(**kwargs)
    assert words in str(info.value)


def test_the_span_limit_is_the_quarter_cars():
    # a body mode 1e7 times slower than the wheel hop is refused; just inside is not
    base = HalfCarParams()
    hop = np.sqrt(base.ku_front / base.mu_front)
    with pytest.raises(ValueError, match="time scales span"):
        HalfCarParams(ks_front=base.mu_front * (hop / MAX_RATE_SPAN / 10) ** 2)


@pytest.mark.parametrize(
    "argv", [["--model", "full", "--a", "1e10"], ["--model", "half", "--seat-x", "1e300"]]
)
def test_the_command_line_refuses_in_one_line(argv):
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert run(["modes", *argv]) == 2
    assert err.getvalue().count("\n") == 1 and "Traceback" not in err.getvalue()


def _decades(cls):
    """Each field times 10^k, k in [-6, 6]: twelve decades around the default car."""
    defaults = cls()
    names = [f.name for f in dataclasses.fields(cls)]
    return st.fixed_dictionaries(
        {},
        optional={
            n: st.floats(-6.0, 6.0).map(lambda k, d=getattr(defaults, n): (d or 1.0) * 10.0**k)
            for n in names
        },
    )


@pytest.mark.parametrize("cls", [HalfCarParams, FullCarParams])
def test_any_car_across_twelve_decades_is_refused_or_analysed(cls):
    # hypothesis: several fields changed at once, each over twelve decades;
    # the same judgement as above, the modes against the matrix's eigenvalues
    @settings(max_examples=60, deadline=None, derandomize=True)
    @given(_decades(cls))
    def check(values):
        try:
            params = cls(**values)
        except ValueError as exc:
            assert str(exc)
            return
        model = params.model()
        eig = np.linalg.eigvals(model.system.A)
        for mode in modal_analysis(model).modes:
            assert np.min(np.abs(eig - mode.eigenvalue)) <= 1e-6 * abs(mode.eigenvalue)

    check()


def test_report_of_an_extreme_full_car_exits_2_before_computing(tmp_path):
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        status = run(["report", "--model", "full", "--a", "1e10", "--out", str(tmp_path / "r")])
    assert status == 2 and "time scales span" in err.getvalue()
    assert err.getvalue().count("\n") == 1
    assert not (tmp_path / "r" / "report.md").exists()
