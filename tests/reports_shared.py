"""Fixtures of the tests that write reports where the report's pictures or
wall times are not what they check (imported by the test files that use them:
``from reports_shared import quick_figures``).

A report's cost is its figures (constrained layout, text, PNG and PDF
rendering: about 3-4 CPU-s a report) and, from the command line, the
comparison's wall-time runs. A test of what the report *says*, or of how its
files are written, needs neither at full cost:

- `quick_figures`: the figures drawn at 40 dpi instead of `report.writer.DPI`
  (150): the same artists, layout and files, fewer pixels.
- `placeholder_figures`: every figure of `write_report` drawn as a small
  blank figure, under its own file name, number and caption: for the tests of
  the writer's files, locks and faults (tests/test_report_safety.py), which
  read no figure. The figures themselves are checked by tests/test_report.py,
  tests/test_html_browser.py and tests/test_pdf_layout.py.
- `untimed`: the command's comparison run without its wall-time
  measurements (``compare_methods(timing=False)``), whose columns then hold
  NaN: for tests that read no time (a rerun changes the times anyway).
- `without_pdf`: ``qc-control report`` and ``qc-control control-report``
  write every file but ``report.pdf`` (with placeholder figures the PDF's
  layout is most of a report's cost): for tests that read the report's
  words, tables or other files. The PDF is checked by
  tests/test_pdf_layout.py, tests/test_report.py and the fault cases of
  tests/test_report_safety.py; the commands write theirs in tests/test_cli.py,
  tests/test_wheel.py and tests/test_portable.py (the last two read it).
"""

import dataclasses
import functools

import pytest
from matplotlib.figure import Figure
from qc_control.road import Bump

from qc_control import report as report_package
from qc_control.cli import parser as parser_module
from qc_control.report import comparison, writer
from qc_control.studies import scenario as scenario_module


@pytest.fixture
def quick_figures(monkeypatch):
    """What is checked is the text and the files, not the pictures: 40 dpi keeps it quick."""
    monkeypatch.setattr(writer, "DPI", 40)


def _blank() -> Figure:
    return Figure(figsize=(1.0, 1.0))


def use_placeholders(monkeypatch) -> None:
    """Draw each figure of `write_report` as a blank 1 x 1 in figure under its
    own name, number and caption (what `placeholder_figures` does)."""
    real = comparison.figure_specs

    def specs(cmp):
        return [dataclasses.replace(spec, make=_blank) for spec in real(cmp)]

    monkeypatch.setattr(comparison, "figure_specs", specs)
    monkeypatch.setattr(writer, "DPI", 40)


@pytest.fixture
def placeholder_figures(monkeypatch):
    """Each figure of `write_report` a blank figure under its own name."""
    use_placeholders(monkeypatch)


def use_untimed(monkeypatch) -> None:
    """Run `Scenario.run`'s comparison without wall-time runs (what `untimed` does)."""
    real = scenario_module.compare_methods
    monkeypatch.setattr(scenario_module, "compare_methods", functools.partial(real, timing=False))


@pytest.fixture
def untimed(monkeypatch):
    """The command's comparison without wall-time runs (the times are NaN)."""
    use_untimed(monkeypatch)


@pytest.fixture
def without_pdf(monkeypatch):
    """``qc-control report`` and ``control-report`` write every format but the PDF."""
    formats = tuple(f for f in report_package.FORMATS if f != "pdf")
    for name in ("write_report", "write_control_report"):
        real = getattr(parser_module, name)
        monkeypatch.setattr(parser_module, name, functools.partial(real, formats=formats))


def run_untimed(scenario):
    """``scenario.run()`` without its wall-time runs, for a module's fixture."""
    with pytest.MonkeyPatch.context() as monkeypatch:
        use_untimed(monkeypatch)
        return scenario.run()


#: The tests that read `half_car_report` (tests/test_html_browser.py and
#: tests/test_pdf_layout.py) carry this group, so that xdist runs them on one
#: worker and the report is written once per suite.
HALF_CAR_GROUP = "half-car-report"
_SHARED: dict[str, tuple] = {}


def half_car_report(tmp_path_factory) -> tuple:
    """The README's half car over a bump (``qc-control report --model half
    --road bump --speed 10 --t-end 2``): its comparison, and its report
    written once per process as HTML beside its PNG figures at the report's
    150 dpi (the figures the PDF embeds; the tables are the widest a report
    has: 25 error measures, 4 wheels' modes, 14 ride metrics, an 8-state A).
    """
    if "half" not in _SHARED:
        from qc_control.report import write_report
        from qc_control.studies.scenario import Scenario

        cmp = Scenario(model="half", road=Bump(speed=10.0), t_end=2.0).run()
        out = tmp_path_factory.mktemp("half-car") / "report"
        _SHARED["half"] = (cmp, write_report(cmp, out, formats=("html",)))
    return _SHARED["half"]
