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
    """Pass counts over ``tests``; an xfail counts as passed (it does so under control too).

    A failing test in which qc_control refused a nonlinear system (the one
    refusal, until the nonlinear engine lands) is counted apart, as
    ``pending_nonlinear``: ``rate_linear`` leaves those out, ``rate`` does not.
    """
    outcomes = result["outcomes"]
    passed = [t for t in tests if outcomes.get(t) in ("passed", "xfailed")]
    failed = {t: outcomes.get(t, "not run") for t in tests if t not in passed}
    refused = set(result.get("refused_nonlinear", []))
    pending = {t: o for t, o in failed.items() if t in refused}
    other = {t: o for t, o in failed.items() if t not in refused}
    diffs = {t: d for t, d in result.get("relative_difference", {}).items() if t in tests}
    worst = max(diffs.items(), key=lambda kv: kv[1]) if diffs else (None, 0.0)
    return {
        "passed": len(passed),
        "total": len(tests),
        "rate": len(passed) / len(tests),
        "pending_nonlinear": pending,
        "failed": other,
        "rate_linear": len(passed) / (len(tests) - len(pending)),
        "compared": len(diffs),
        "max_relative_difference": worst[1],
        "worst_test": worst[0],
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
    n_pending = len(s["pending_nonlinear"])
    print(f"{s['passed']} of {s['total']} peer tests pass ({100 * s['rate']:.1f}%)")
    print(
        f"{s['passed']} of {s['total'] - n_pending} ({100 * s['rate_linear']:.1f}%) without the "
        f"{n_pending} that need the nonlinear engine (issue 11)"
    )
    print(
        f"largest relative difference from control over {s['compared']} tests: "
        f"{s['max_relative_difference']:.3g} ({s['worst_test']})"
    )
    for test, outcome in s["failed"].items():
        print(f"  {outcome:8s} {test}")
    for test, outcome in s["pending_nonlinear"].items():
        print(f"  {outcome:8s} {test}   [nonlinear: issue 11]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
