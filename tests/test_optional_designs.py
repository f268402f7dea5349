"""A design that needs an optional extra is listed with its install hint, on
the terminal and in the report's design table, never silently dropped
(issue: without slycot, H∞ vanished from control-report)."""

from types import SimpleNamespace

import pytest

from qc_control.cli import parser
from qc_control.report import control as control_report

HINT = 'pip install "qc-control[robust]" (from a clone: pip install -e ".[robust]")'


@pytest.fixture
def without_slycot(monkeypatch):
    monkeypatch.setattr(control_report, "HINF_AVAILABLE", False)
    monkeypatch.setattr(parser, "HINF_AVAILABLE", False)


def test_the_design_table_lists_hinf_with_the_install_hint(without_slycot):
    cmp = SimpleNamespace(designs={"passive": "the car's own damper", "skyhook": "ideal sky"})
    table = control_report._design_table(cmp)
    assert list(table.index) == ["passive", "skyhook", "H∞"]
    assert HINT in table.loc["H∞", "what"] and "slycot" in table.loc["H∞", "what"]


def test_with_slycot_nothing_is_listed_as_missing(monkeypatch):
    monkeypatch.setattr(control_report, "HINF_AVAILABLE", True)
    assert control_report.unavailable_designs(["passive"]) == {}
    cmp = SimpleNamespace(designs={"passive": "the car's own damper"})
    assert list(control_report._design_table(cmp).index) == ["passive"]


def test_the_terminal_says_so_before_the_run(without_slycot, monkeypatch, capsys, tmp_path):
    class Stop(Exception):
        pass

    def no_run(*args, **kwargs):
        raise Stop

    monkeypatch.setattr(parser, "compare_controllers", no_run)
    with pytest.raises(Stop):
        parser.run(["control-report", "--out", str(tmp_path / "c")])
    err = capsys.readouterr().err.splitlines()
    warned = [line for line in err if "warning" in line]
    assert warned == [f"qc-control: warning: H∞ not run: it needs slycot, {HINT}"]
    assert err.index(warned[0]) < next(i for i, e in enumerate(err) if "control-report:" in e)
