"""The benchmark script runs (smoke mode only: speed is never a test), and
what it writes is checked: every section, ratios that are numbers, and the
accuracy columns against values computed here."""

import math
import re
import runpy
import sys
from pathlib import Path

import control
import numpy as np
import pytest

import qc_control as qc

SCRIPT = Path(__file__).parent.parent / "benchmarks" / "run.py"

#: slow: the quick benchmark run takes about 12 s. One xdist group: every test here
#: reads the one run of the module's fixture; spread over two workers, each worker
#: ran the benchmark script itself (measured: 13.6 s and 13.1 s of setup in a 2-worker run)
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("benchmarks")]


def _cells(line: str) -> list[str]:
    """A Markdown table row's cells; ``\\|`` is a pipe inside a cell."""
    cells = re.split(r"(?<!\\)\|", line.strip())[1:-1]
    return [cell.strip().replace("\\|", "|") for cell in cells]


def _table(text: str, column: str) -> list[dict[str, str]]:
    """The rows of the Markdown table whose header has ``column``."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        cells = _cells(line) if line.startswith("|") else []
        if column in cells:
            rows = []
            for row in lines[i + 2 :]:  # skip the |---| line
                if not row.startswith("|"):
                    break
                rows.append(dict(zip(cells, _cells(row))))
            return rows
    raise AssertionError(f"no table with a {column!r} column in RESULTS.md")


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """The script run as ``python benchmarks/run.py --quick --out DIR/RESULTS.md``
    runs it (as ``__main__``, up to its ``sys.exit``), but in this process: a new
    interpreter importing numpy, scipy, control and qc_control again cost 1.5 s of
    CPU, and no test reads a time the smoke run measures (only that each is a
    number), so sharing the process with the suite changes nothing that is checked."""
    out = tmp_path_factory.mktemp("bench") / "RESULTS.md"
    with pytest.MonkeyPatch.context() as mp, pytest.raises(SystemExit) as exit_:
        mp.setattr(sys, "argv", [str(SCRIPT), "--quick", "--out", str(out)])
        runpy.run_path(str(SCRIPT), run_name="__main__")
    assert exit_.value.code == 0
    return out.read_text(encoding="utf-8")


def test_benchmarks_quick_smoke(results):
    for section in (
        "## Problem",
        "## Reference",
        "## Results",
        "## What failed",
        "## Conclusion",
        "## Versions and command",
    ):
        assert section in results
    assert "× control.initial_response" in results and "### Design sweeps" in results
    for section in ("### 10,000 designs", "### Scaling"):
        assert section in results


def test_ratios_are_numbers(results):
    """Each ratio cell parses as a positive finite number (its size is the
    benchmark's business, never a test's)."""
    rows = _table(results, "× control.initial_response")
    assert {row["method"] for row in rows} >= {"euler", "midpoint", "heun", "rk4"}
    sweep = _table(results, "qc.sweep [s]")
    assert {row["workload"] for row in sweep} == {"free (released from 5 cm)", "5 cm road step"}
    ratios = [float(row["× control.initial_response"].split()[0]) for row in rows]
    ratios += [float(row["ratio"].split()[0]) for row in sweep]  # "median (min–max)"
    assert all(math.isfinite(r) and r > 0 for r in ratios), ratios
    # a fitted log-log slope: finite; its sign in the smoke mode's tiny sizes is noise
    slopes = [float(row["time slope"]) for row in _table(results, "time slope")]
    assert slopes and all(math.isfinite(s) for s in slopes), slopes


def test_spectral_sweep_agrees_with_single_designs(results):
    """The benchmark's own check of the spectral sweep against one design at a
    time is printed; it must meet the issue's 1e-9."""
    found = re.search(r"largest relative difference ([0-9.e+-]+)", results)
    assert found and float(found.group(1)) <= 1e-9


def test_accuracy_columns_match_an_independent_run(results):
    """Accuracy, unlike speed, is deterministic: RK4's error at h = 10 ms
    in the work-precision table equals the one computed here from
    python-control's exact response, and the LTI engine equals the
    step-by-step stepper to the 1e-12 its docstring promises."""
    sys_ = qc.quarter_car(qc.QuarterCarParams())
    T = np.linspace(0, 10, 1001)
    X0 = [0.0, 0.0, 0.05, 0.0]
    xs = list(sys_.output_labels).index("xs")
    exact = control.initial_response(sys_, T, X0).outputs[xs]
    rk4 = qc.initial_response(sys_, T, X0, method="rk4").outputs[xs]
    expected = np.max(np.abs(rk4 - exact))

    rows = _table(results, "max |xs error| [m]")
    (row,) = [r for r in rows if r["method"] == "rk4" and r["setting"] == "h = 10 ms"]
    # The table prints three significant figures: half a unit in the third.
    assert float(row["max |xs error| [m]"]) == pytest.approx(expected, rel=5e-3)

    for row in _table(results, "LTI vs generic (rel.)"):
        assert float(row["LTI vs generic (rel.)"]) < 1e-12, row


def test_interconnect_benchmark_table(results):
    """The car + skyhook rows: ratios are numbers, and the fast path and sys._rhs
    (the same trajectory to rounding) report the same error, below control's default
    RK45 (rtol 1e-3) on this discontinuous controller."""
    rows = {r["run"]: r for r in _table(results, "× faster than control (target ≥ 5)")}
    fast = rows["qc RK4 h = 1 ms, fast path"]
    rhs = rows["qc RK4 h = 1 ms, sys._rhs"]
    theirs = rows["control.input_output_response (RK45 defaults)"]
    for row in (fast, rhs):
        ratio = float(row["× faster than control (target ≥ 5)"])
        assert math.isfinite(ratio) and ratio > 0
    assert fast["max state error / max state"] == rhs["max state error / max state"]
    assert float(fast["max state error / max state"]) < float(theirs["max state error / max state"])


def test_nonlinear_sweep_benchmark_table(results):
    """The batched nonlinear sweep's rows: the ratio is a positive number, and the
    batch equals qc.input_output_response on the timed designs to rounding."""
    rows = _table(results, "qc.sweep, nonlinear [s]")
    assert [r["road (20 m/s)"] for r in rows] == ["ISO 8608 class C", "ISO 8608 class D"]
    for row in rows:
        ratio = float(row["ratio (target ≥ 300)"])
        assert math.isfinite(ratio) and ratio > 0
        assert float(row["batch vs qc.input_output_response (rel.)"]) < 1e-12


def test_the_work_precision_table_names_every_run_and_rk4_is_its_own_unit(results):
    """The benchmark's work–precision section (its ratios are its own business):
    every row names a run, and RK4's own ratios (evaluations and time against
    RK4) are 1 in both cars. Read from the module's one smoke run, which writes the
    section as ``--only peers`` prints it (the same `work_precision_benchmark` table)."""
    rows = _table(results, "seed car evals/rk4")
    assert all(row["run"] for row in rows)
    (rk4,) = [row for row in rows if row["run"] == "rk4"]
    columns = (
        "seed car evals/rk4",
        "seed car time/rk4",
        "stiff car evals/rk4",
        "stiff car time/rk4",
    )
    assert [rk4[c] for c in columns] == ["1"] * 4


def test_the_mpc_solvers_plan_the_exact_qp_solution_on_both_cases(results):
    """Issue 40: every QP solver, on the non-binding and the binding case, plans
    every tick within the issue's 1e-6 N of the exact QP solution that the
    benchmark makes by BVLS; the limit is active on some ticks of the binding
    case (the smoke run's 1 s) and on fewer of the other's."""
    rows = _table(results, "largest plan difference [N]")
    from_module = runpy.run_path(str(SCRIPT.with_name("mpc_solvers.py")))
    assert {r["solver"] for r in rows} == set(from_module["SOLVERS"])
    assert {r["case"].split(":")[0] for r in rows} == {"not binding", "binding"}
    for row in rows:
        assert float(row["largest plan difference [N]"]) <= 1e-6, row
        assert math.isfinite(float(row["solve median [ms]"]))
    share = {r["case"].split(":")[0]: float(r["ticks with the limit active"][:-1]) for r in rows}
    assert share["binding"] > share["not binding"]


def test_the_explorers_redraw_is_timed_by_the_benchmark_or_skipped_in_one_line(results):
    """The redraw's time left the suite (tests/test_explore.py checks what it shows):
    the benchmark either times it in the browser (positive numbers) or says in one
    line why it could not."""
    section = results.split("### The explorer's redraw in the browser", 1)[1]
    if section.lstrip().startswith("Skipped: "):
        return
    rows = _table(section, "median [ms]")
    assert rows and all(float(row["median [ms]"]) > 0 for row in rows)
