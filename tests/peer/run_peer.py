"""Run python-control's own tests with its responses routed to qc_control.

python-control 0.10.2 ships its test suite inside the package
(``control/tests``). This script runs the test files that call its time
responses in a separate pytest process, with the `qc_route` plugin
replacing them by ``qc_control``'s (RK4 at ``h·|λ|max <= 0.01``), and
scores the tests that call them, as recorded from a run of unmodified
python-control (``--record``). Two routings:

``two`` (the issue's measure)
    ``control.initial_response`` and ``control.forced_response``; the
    callers are listed in ``peer_tests.txt``;
``all``
    also ``control.step_response`` and ``control.impulse_response``;
    listed in ``peer_tests_all.txt``.

Usage::

    python tests/peer/run_peer.py [--funcs all]            # score, list the failures
    python tests/peer/run_peer.py --record [--funcs all]   # rewrite the list from control
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import control

HERE = Path(__file__).resolve().parent
CONTROL_DIR = Path(control.__file__).resolve().parent
LISTS = {"two": HERE / "peer_tests.txt", "all": HERE / "peer_tests_all.txt"}
KNOWN_FAILURES = HERE / "known_failures.txt"

#: The test files of python-control 0.10.2 that call the two functions.
FILES = [
    "timeresp",
    "trdata",
    "iosys",
    "nlsys",
    "timeplot",
    "ctrlplot",
    "discrete",
    "modelsimp",
    "bspline",
    "flatsys",
    "statesp",
]


def run(mode: str = "qc", tests: list[str] | None = None, funcs: str = "two") -> dict:
    """Run the peer tests; the `qc_route` plugin's JSON report.

    Parameters
    ----------
    mode : {'qc', 'record'}
        Route to qc_control, or call python-control and record the callers.
    tests : list of str, optional
        Node ids to run (relative to the control package); by default every
        test in `FILES`.
    funcs : {'two', 'all'}
        Which of control's responses to route (see the module docstring).
    """
    with tempfile.TemporaryDirectory() as tmp:
        report = Path(tmp) / "report.json"
        ini = Path(tmp) / "pytest.ini"
        # python-control's tests run under their own defaults, not this project's
        # (no --doctest-modules, no warnings-as-errors for qc_control).
        ini.write_text("[pytest]\n", encoding="utf-8")
        env = dict(os.environ)
        env.update(
            QC_PEER_MODE=mode,
            QC_PEER_FUNCS=funcs,
            QC_PEER_REPORT=str(report),
            PYTHONPATH=os.pathsep.join(filter(None, [str(HERE), env.get("PYTHONPATH")])),
            MPLBACKEND="Agg",
        )
        cmd = [
            sys.executable,
            "-m",
            "pytest",
            "-c",
            str(ini),
            "--rootdir",
            str(CONTROL_DIR),
            "-p",
            "qc_route",
            "-p",
            "no:cacheprovider",
            "-q",
            "--tb=no",
            "-W",
            "ignore::DeprecationWarning",
        ]
        if tests is None:
            cmd += [str(CONTROL_DIR / "tests" / f"{name}_test.py") for name in FILES]
        else:
            cmd += [str(CONTROL_DIR / t) for t in tests]
        proc = subprocess.run(cmd, cwd=tmp, env=env, capture_output=True, text=True)
        if not report.exists():
            raise RuntimeError(
                f"the peer run wrote no report (exit {proc.returncode}):\n"
                f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
            )
        result = json.loads(report.read_text(encoding="utf-8"))
        result["returncode"] = proc.returncode
        return result


def read_list(path: Path) -> list[str]:
    """Node ids in a checked-in list (``#`` starts a comment)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    return [
        line.split("  #")[0].strip() for line in lines if line.strip() and not line.startswith("#")
    ]


def score(result: dict, tests: list[str]) -> dict:
    """Pass counts over all of ``tests``; an xfail counts as passed (it does so under control too).

    Differences from python-control are kept in two measures: LTI calls
    against control's exact (matrix-exponential) answer, and calls on a
    nonlinear system against control's answer with solve_ivp at a tight
    tolerance (`qc_route.TIGHT_IVP`). ``nonlinear`` lists the tests in which
    a nonlinear system went through qc_control's nonlinear engine.
    """
    outcomes = result["outcomes"]
    passed = [t for t in tests if outcomes.get(t) in ("passed", "xfailed")]
    failed = {t: outcomes.get(t, "not run") for t in tests if t not in passed}

    def worst_of(key):
        diffs = {t: d for t, d in result.get(key, {}).items() if t in tests}
        worst = max(diffs.items(), key=lambda kv: kv[1]) if diffs else (None, 0.0)
        return len(diffs), worst

    n_lti, worst = worst_of("relative_difference")
    n_nl, worst_nl = worst_of("relative_difference_nonlinear")
    return {
        "passed": len(passed),
        "total": len(tests),
        "rate": len(passed) / len(tests),
        "failed": failed,
        "nonlinear": sorted(set(result.get("nonlinear", [])) & set(tests)),
        "compared": n_lti + n_nl,
        "max_relative_difference": worst[1],
        "worst_test": worst[0],
        "compared_nonlinear": n_nl,
        "max_relative_difference_nonlinear": worst_nl[1],
        "worst_test_nonlinear": worst_nl[0],
    }


def record(funcs: str) -> list[str]:
    """The tests that call the routed functions and pass under python-control itself."""
    result = run("record", funcs=funcs)
    ok = ("passed", "xfailed")
    return [t for t in result["called"] if result["outcomes"].get(t) in ok]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--record", action="store_true", help="rewrite the list of callers")
    parser.add_argument("--funcs", choices=("two", "all"), default="two")
    args = parser.parse_args(argv)
    path = LISTS[args.funcs]
    if args.record:
        called = record(args.funcs)
        names = "initial_response, forced_response" + (
            ", step_response, impulse_response" if args.funcs == "all" else ""
        )
        header = (
            f"# python-control {control.__version__}: the tests that call control.{{{names}}}\n"
            "# and pass under python-control itself. Written by\n"
            f"# `python tests/peer/run_peer.py --record --funcs {args.funcs}`; do not edit.\n"
        )
        path.write_text(header + "\n".join(called) + "\n", encoding="utf-8")
        print(f"{len(called)} tests written to {path}")
        return 0
    tests = read_list(path)
    s = score(run("qc", tests, args.funcs), tests)
    print(f"{s['passed']} of {s['total']} peer tests pass ({100 * s['rate']:.1f}%)")
    print(f"{len(s['nonlinear'])} of them simulate a nonlinear system (qc's nonlinear engine)")
    print(
        f"largest relative difference from control's exact answer over "
        f"{s['compared'] - s['compared_nonlinear']} tests (LTI): "
        f"{s['max_relative_difference']:.3g} ({s['worst_test']})"
    )
    print(
        f"largest relative difference from control with a tight solve_ivp over "
        f"{s['compared_nonlinear']} tests (nonlinear): "
        f"{s['max_relative_difference_nonlinear']:.3g} ({s['worst_test_nonlinear']})"
    )
    for test, outcome in s["failed"].items():
        print(f"  {outcome:8s} {test}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
