"""The qc-control command: output, one-line errors with exit status 2, and reproducible reports."""

import ast
import builtins
import logging
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import filelock
import pandas as pd
import pytest
from reports_shared import (  # noqa: F401  (fixtures)
    placeholder_figures,
    quick_figures,
    untimed,
    without_pdf,
)

import qc_control
from qc_control.cli import console
from qc_control.cli import parser as cli
from qc_control.cli.console import main
from qc_control.cli.parser import build_parser, scenario_from_args
from qc_control.ride.road import Bump as BumpRoad
from qc_control.studies import control_study
from qc_control.studies.scenario import Scenario
from qc_control.studies.scenario_toml import MAX_CONFIG_BYTES

#: Streams without end where the system has them (a large file stands in elsewhere).
DEVICES = [d for d in ("/dev/zero", "/dev/urandom") if Path(d).exists()]


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "qc_control.cli.console", *args],
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_modes_prints_table(capsys):
    # in-process: the real process's exit status is test_bad_input_via_real_process's
    assert main(["modes"]) == 0
    out = capsys.readouterr().out
    assert "body bounce" in out and "1.087" in out


def test_modes_options_and_config(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text("ms = 400.0\nzeta = 0.3\n")
    assert main(["modes", "--config", str(cfg), "--ku", "1e12"]) == 0
    text = capsys.readouterr().out
    # rigid tire: body wn = sqrt(ks/ms) = sqrt(30000/400) = 8.660 rad/s
    assert "8.66" in text


#: What a command's start spends most of its CPU importing (about 2 s of it):
#: the top level is answered without any of them.
#: What the command line's top level (--help, --version, a bad command) never
#: loads: each costs a tenth of a second or more on a cold start.
LIBRARY = ("scipy", "control", "matplotlib", "pandas")


def imported(importtime: str) -> set[str]:
    """The modules ``python -X importtime`` lists on stderr."""
    return {line.split("|")[-1].strip() for line in importtime.splitlines() if "|" in line}


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.startswith(f"qc-control {qc_control.__version__} (")
    # a real process, which lists what it imports: none of the library's heavy packages
    out = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "qc_control.cli.console", "--version"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0 and qc_control.__version__ in out.stdout
    assert imported(out.stderr).isdisjoint(LIBRARY), sorted(imported(out.stderr))


@pytest.mark.parametrize(
    "argv",
    [["--help"], ["-h", "report"], [], ["frobnicate"], ["--bogus"], ["--model", "x"]]
    + [["modes", "--help"], ["report", "-h", "--model", "half"]],  # the commands' own: whole
)
def test_the_top_level_answers_in_the_words_of_the_whole_parser(argv, capsys):
    """The entry point answers these before loading the library; the whole
    parser (`qc_control.cli.parser.run`) says the same, with the same status."""
    light = main(argv), capsys.readouterr()
    whole = cli.run(argv), capsys.readouterr()
    assert light == whole
    assert light[0] == 0 or light[1].err.count("\n") == 1  # help, or one error line


def test_the_top_level_is_answered_without_the_library():
    """--help and bad commands, in a fresh process, import none of `LIBRARY`."""
    code = (
        "import sys\n"
        "from qc_control.cli.console import main\n"
        "status = [main(a) for a in (['--help'], [], ['frobnicate'], ['--bogus', '-h'])]\n"
        f"print(status, sorted(m for m in {LIBRARY!r} if m in sys.modules), file=sys.stderr)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("usage: qc-control [-h] [--version]") == 2  # --help, --bogus -h
    assert out.stderr.splitlines()[-1] == "[0, 2, 2, 0] []", out.stderr


@pytest.fixture
def files(tmp_path, monkeypatch):
    """A working directory holding the files the bad vectors name."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "binary.toml").write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff\xfe")
    (tmp_path / "seed.toml").write_text("[scenario]\nseed = 3\n")
    (tmp_path / "step_class.toml").write_text('[scenario]\nroad = "step"\nroad_class = "C"\n')
    (tmp_path / "methods.toml").write_text("[scenario]\nmethods = 5\n")
    (tmp_path / "wheelbase.toml").write_text("ms = 400.0\nwheelbase = 2.5\n")
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    return tmp_path


def bad_input_cases(path: Path) -> list:
    """The cases of a transcript of bad command lines (``tests/data``): a line
    ``qc-control ARGS``, then the expected words indented; ``#`` lines comment."""
    cases = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("qc-control"):
            command = line
        elif line.startswith("    "):
            args = shlex.split(command)[1:]
            cases.append(pytest.param(args, line.strip(), id=command))
    return cases


BAD = bad_input_cases(Path(__file__).with_name("data") / "cli_bad_input.txt")


def _deprecation(line: str) -> bool:
    return line.startswith("qc-control: warning: ") and "is deprecated" in line


@pytest.mark.parametrize("args, words", BAD)
def test_bad_input_one_line_exit_2(files, monkeypatch, args, words, capsys):
    # nothing is computed for bad input: the checks come first
    monkeypatch.setattr(Scenario, "run", lambda *a, **k: pytest.fail("ran on bad input"))
    assert main(args) == 2
    err = capsys.readouterr().err
    assert words in err, err
    # a deprecated spelling (--bump-height, [scenario] seed) adds its one warning line first
    lines = err.splitlines(keepends=True)
    err = "".join(line for line in lines if not _deprecation(line))
    assert err.startswith("qc-control: error: ") and err.count("\n") == 1
    assert "Traceback" not in err


@pytest.mark.slow
def test_bad_input_via_real_process(files):
    out = run("report", "--road", "iso8608", "--seed", "-1")
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr == ("qc-control: error: --seed must be a whole number >= 0, got -1\n")


def test_unwritable_out_is_refused_before_computing(files, monkeypatch, capsys):
    # The process runs as root on CI, where chmod does not stop writes: the check's
    # own test of permissions (os.access) is made to say no for one directory.
    (files / "rodir").mkdir()
    real = os.access
    monkeypatch.setattr(
        cli.os, "access", lambda p, mode: False if str(p).endswith("rodir") else real(p, mode)
    )
    monkeypatch.setattr(Scenario, "run", lambda *a, **k: pytest.fail("computed first"))
    assert main(["report", "--out", "rodir/R"]) == 2
    assert "--out 'rodir/R' cannot be made:" in capsys.readouterr().err
    # an earlier report inside a read-only parent cannot be replaced either
    report = files / "rodir" / "R"
    report.mkdir()
    (report / ".qc-control-report").write_text("qc-control report\n\nfiles:\n")
    assert main(["report", "--out", "rodir/R"]) == 2
    assert "cannot be replaced:" in capsys.readouterr().err


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root may write anywhere")
def test_unwritable_out_for_real(files, capsys):
    (files / "rodir").mkdir(mode=0o555)
    assert main(["report", "--out", "rodir/R"]) == 2
    assert "is not writable" in capsys.readouterr().err


# ---------------------------------------------------- not a usage error


@pytest.mark.parametrize("error", [TypeError("boom"), KeyError("k"), ValueError("deep")])
def test_internal_error_is_not_a_usage_error(files, monkeypatch, error, capsys):
    def broken(*args, **kwargs):
        raise error

    monkeypatch.setattr("qc_control.studies.scenario.compare_methods", broken)
    status = main(["report", "--t-end", "1", "--methods", "rk4", "--out", "R"])
    err = capsys.readouterr().err
    assert status == 1  # never 2: a bug is not passed off as bad input
    assert "Traceback" in err and "internal error" in err and "please report it" in err
    assert not (files / "R").exists()


def test_a_spent_reference_budget_is_one_line(files, monkeypatch, capsys):
    """The nonlinear reference's budget running out is the scenario's doing
    (a jump without a switching function, a road too fast for the samples):
    one line naming it, exit 2, nothing written."""
    from qc_control.studies.compare import ReferenceBudgetError

    def stalled(*args, **kwargs):
        raise ReferenceBudgetError("the nonlinear reference spent its budget")

    monkeypatch.setattr("qc_control.studies.scenario.compare_methods", stalled)
    status = main(["report", "--quiet", "--t-end", "1", "--methods", "rk4", "--out", "R"])
    err = capsys.readouterr().err
    assert status == 2
    assert err == "qc-control: error: the nonlinear reference spent its budget\n"
    assert not (files / "R").exists()


def test_ctrl_c_is_one_line(files, monkeypatch, capsys):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(Scenario, "run", interrupted)
    assert main(["report", "--quiet", "--out", "R"]) == 130
    assert capsys.readouterr().err == "qc-control: interrupted\n"


def test_ctrl_c_during_imports_is_one_line(monkeypatch, capsys):
    real = builtins.__import__

    def importing(name, *args, **kwargs):
        if name in (
            "parser",
            "qc_control.cli.parser",
        ):  # the entry point imports the command's module
            raise KeyboardInterrupt
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", importing)
    assert main(["modes"]) == 130
    assert capsys.readouterr().err == "qc-control: interrupted\n"


def test_entry_point_imports_only_the_standard_library():
    """Everything heavy is imported inside main's handlers, so Ctrl-C there is one line.

    (A Ctrl-C while `import qc_control` itself runs, before main, is the package's own
    __init__'s to keep short: it loads names lazily.)
    """
    tree = ast.parse(Path(console.__file__).read_text(encoding="utf-8"))
    top = {
        alias.name.split(".")[0]
        for node in tree.body
        if isinstance(node, ast.Import)
        for alias in node.names
    } | {
        node.module.split(".")[0] if node.level == 0 and node.module else "qc_control"
        for node in tree.body
        if isinstance(node, ast.ImportFrom)
    }
    assert top <= set(sys.stdlib_module_names) | {"__future__"}, top


# ------------------------------------------------------------ reproduce


def methods_table(directory):
    """methods.csv without the wall times (the only numbers a rerun may change)."""
    table = pd.read_csv(directory / "methods.csv", index_col=0)
    timing = [c for c in table.columns if "time" in c.lower() or "[ms]" in c]
    assert timing  # the wall-time columns are found by name
    return table.drop(columns=timing)


def reproduce_line(directory) -> str:
    text = (directory / "report.md").read_text(encoding="utf-8")
    return next(line for line in text.splitlines() if line.startswith("qc-control report "))


@pytest.mark.slow
# the numbers, not the pictures, the times or the PDF (which holds the same words and tables)
@pytest.mark.usefixtures("placeholder_figures", "untimed", "without_pdf")
def test_report_reproduces_from_its_own_command_and_scenario_toml(files, capsys):
    """Issue 13: a custom car on a 10 cm bump at 15 m/s reproduces from its "Reproduce" line.

    The wall times are left out of the comparison (a rerun changes them), the
    figures are placeholders and no PDF is written: what must reproduce is
    every other number."""
    args = ["--ms", "350", "--zeta", "0.3", "--road", "bump", "--road-height", "0.1"]
    args += ["--speed", "15", "--t-end", "2", "--methods", "euler,rk4", "--out", "A"]
    assert main(["report", *args]) == 0
    capsys.readouterr()
    report = (files / "A" / "report.md").read_text(encoding="utf-8")
    assert "10 cm high" in report and "15 m/s" in report and "5 cm" not in report

    command = reproduce_line(files / "A")
    scenario = scenario_from_args(build_parser().parse_args(shlex.split(command)[1:]))
    assert scenario.vehicle.ms == 350.0 and scenario.road == BumpRoad(height=0.1, speed=15.0)
    # The report writer saves scenario.toml beside the report (the course stream's part);
    # until it does, the test saves the same text the writer will.
    toml = files / "A" / "scenario.toml"
    if not toml.exists():
        toml.write_text(scenario.to_toml(), encoding="utf-8")
    assert Scenario.from_toml(toml) == scenario

    assert main(["report", "--config", str(toml), "--out", "B"]) == 0
    assert main([*shlex.split(command)[1:], "--out", "C"]) == 0
    # the same computation on the same inputs: equal to the last bit (timings left out)
    for again in ("B", "C"):
        pd.testing.assert_frame_equal(
            methods_table(files / again), methods_table(files / "A"), check_exact=True
        )
        assert reproduce_line(files / again) == command
    assert re.search(r"--road bump --road-height 0\.1 .*--speed 15\.0", command)


# --- issue 14 item 20: warnings are summarised once, in words -----------------


def terminal(argv: list[str], process: bool, capfd, caplog) -> tuple[int, str]:
    """The exit status and all that ``qc-control`` shows on the terminal's stderr.

    A real process's own stderr; or, in-process, the stderr file descriptor
    (``capfd``) and its loggers' warnings (``caplog``: pytest takes the records
    that a process's logging prints to stderr), which must be none.
    """
    if process:
        done = run(*argv)
        return done.returncode, done.stderr
    status = main(argv)
    logged = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert not logged, logged
    return status, capfd.readouterr().err


@pytest.mark.parametrize(
    "args, words, process",
    [
        # tiny masses: every method diverges at h = 10 ms (44 RuntimeWarnings on 95cf135);
        # a real process, as a user runs it: its stderr is all the terminal shows
        (["--ms", "1e-6", "--mu", "1e-6", "--t-end", "1"], "beyond the stability limit", True),
        # undamped: Euler has no stable step ("∞% of it" and a divide-by-zero warning);
        # in-process (the process's part is the case above's)
        (["--zeta", "0", "--t-end", "1"], "Euler has no stable step", False),
    ],
    ids=["tiny masses", "undamped"],
)
@pytest.mark.slow
def test_degenerate_designs_report_without_a_warning_flood(
    tmp_path, args, words, process, capfd, caplog
):
    argv = ["report", *args, "--quiet", "--out", str(tmp_path / "R")]
    status, err = terminal(argv, process, capfd, caplog)
    assert status == 0, err
    # --quiet: no progress; the root causes are fixed, so the only lines left are
    # the one-line warnings, given before the run, of each method beyond its limit
    lines = err.splitlines()
    assert len(lines) <= 4, err
    assert all("stability limit" in line or "no stable step" in line for line in lines), err
    text = (tmp_path / "R" / "report.md").read_text()
    assert "∞%" not in text and "inf%" not in text  # (∞ as an error of a diverged run is right)
    assert "beyond the stability limit" in text  # the finding says what happened, in words
    # each design's own finding, in words (the report the user gets)
    assert words in text


def test_warning_summary_counts_each_distinct_warning_once():
    import warnings

    from qc_control.numerics.integrate import DivergenceWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for _ in range(44):
            warnings.warn("overflow encountered in square", RuntimeWarning, stacklevel=2)
        warnings.warn("divide by zero encountered in scalar divide", RuntimeWarning, stacklevel=2)
        for _ in range(3):
            warnings.warn("rk4 diverged at t = 0.2 s", DivergenceWarning, stacklevel=2)
    lines = cli.summarise_warnings(caught)
    assert lines[0] == "rk4 diverged at t = 0.2 s (3 times)"
    assert len(lines) == 2  # 45 floating-point warnings become one line
    assert lines[1].startswith("45 floating-point operations overflowed, divided by zero:")


def test_cli_prints_a_warning_summary_not_a_flood(monkeypatch, capsys, tmp_path):
    """Whatever still warns inside a command reaches stderr once, prefixed, in words."""
    import warnings

    def noisy(args):
        for _ in range(44):
            warnings.warn("overflow encountered in exp", RuntimeWarning, stacklevel=2)
        return 0

    parser = build_parser()
    real = parser.parse_args
    monkeypatch.setattr(cli, "build_parser", lambda: parser)

    def parse(argv):
        args = real(argv)
        args.run = noisy
        return args

    monkeypatch.setattr(parser, "parse_args", parse)
    assert cli.run(["modes"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("qc-control: warning: 44 floating-point")


# --- issue 11 item 6: the nonlinear car on the command line --------------------


def test_nonlinear_options_make_the_scenario(files):
    """--model nonlinear: the lift-off bump by default; the options land in the Scenario."""
    parse = lambda *words: scenario_from_args(build_parser().parse_args(["report", *words]))  # noqa: E731
    sc = parse("--model", "nonlinear")
    assert sc.road == BumpRoad(height=0.2, length=8.0, speed=20.0, t0=0.1)
    assert (sc.t_end, sc.h, sc.tire, sc.bump_stop, sc.events) == (
        0.8,
        0.002,
        "unilateral",
        None,
        True,
    )
    sc = parse(
        "--model", "nonlinear", "--road-height", "0.3", "--road-length", "6", "--speed", "25"
    )
    assert sc.road == BumpRoad(height=0.3, length=6.0, speed=25.0, t0=0.1)
    with pytest.warns(DeprecationWarning, match="--bump-length is deprecated.*--road-length"):
        old = parse("--model", "nonlinear", "--bump-length", "6", "--speed", "25")
    assert old.road == BumpRoad(height=0.2, length=6.0, speed=25.0, t0=0.1)
    sc = parse("--model", "nonlinear", "--tire", "linear", "--bump-stop", "0.05,1e5", "--no-events")
    assert (sc.tire, sc.bump_stop, sc.events) == ("linear", (0.05, 1e5), False)
    # the command and the TOML give the same scenario back, a free response included
    for each in (sc, parse("--model", "nonlinear", "--road", "none")):
        again = scenario_from_args(build_parser().parse_args(shlex.split(each.command())[1:]))
        assert again == each == Scenario.from_toml_string(each.to_toml())
    assert parse("--model", "nonlinear", "--road", "none").road.kind == "none"


@pytest.mark.slow
# its words, not its pictures (tests/test_compare_nonlinear.py draws them), times or PDF
@pytest.mark.usefixtures("placeholder_figures", "untimed", "without_pdf")
def test_nonlinear_report_from_the_command_line(files, capsys):
    assert main(["report", "--model", "nonlinear", "--quiet", "--out", "NL"]) == 0
    report = (files / "NL" / "report.md").read_text(encoding="utf-8")
    assert "Nonlinear system: events and order" in report and "contact regained" in report
    assert 'model = "nonlinear"' in (files / "NL" / "scenario.toml").read_text()


# ------------------------------- issue 28 items 4, 5, 9 and 10: exit 0, or 2 with one line


def one_line_error(capsys) -> str:
    """The run's stderr, checked to be one error line and no traceback."""
    err = capsys.readouterr().err
    assert err.startswith("qc-control: error: ") and err.count("\n") == 1, err
    assert "Traceback" not in err
    return err


def never(*args, **kwargs):
    pytest.fail("computed before refusing")


@pytest.fixture
def no_work(monkeypatch):
    """Both commands' computations fail the test if reached."""
    monkeypatch.setattr(Scenario, "run", never)
    monkeypatch.setattr(cli, "compare_controllers", never)


@pytest.mark.parametrize("duration", ["1e7", "1e5"])
def test_control_report_too_long_for_memory_is_refused_before_computing(
    files, monkeypatch, capsys, duration
):
    """Item 4: 1e7 s ended in 'Unable to allocate 14.9 GiB' and a traceback; 1e5 s
    computed for 33 s first. Refused before any run, leaving nothing behind."""
    monkeypatch.setenv("QC_CONTROL_MAX_MEMORY", "16G")  # the same verdict on every machine
    monkeypatch.setattr(control_study, "_run", never)
    before = set(files.iterdir())
    assert main(["control-report", "--road-duration", duration, "-q", "--out", "cr"]) == 2
    err = one_line_error(capsys)
    assert "a controller comparison over" in err and "of memory, more than the limit" in err
    assert set(files.iterdir()) == before  # no report, no lock file


@pytest.mark.parametrize("command", ["modes", "report", "control-report"])
@pytest.mark.parametrize("source", [*DEVICES, "big.toml", "deep.toml"])
def test_configs_that_are_not_text_are_one_line(files, no_work, capsys, command, source):
    """Item 5: a 200 kB TOML of 100k nested arrays (a RecursionError traceback),
    /dev/zero (read until MemoryError) and /dev/urandom (read without end); where
    a system has no such device, a file one byte over the limit stands for it."""
    (files / "big.toml").write_bytes(b"#" * (MAX_CONFIG_BYTES + 1))
    (files / "deep.toml").write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    assert main([command, "--config", source, *([] if command == "modes" else ["-q"])]) == 2
    err = one_line_error(capsys)
    assert f"config file {source!r} is not a scenario config" in err


@pytest.mark.parametrize("command", ["report", "control-report"])
def test_a_second_run_into_a_held_out_stops_before_computing(files, no_work, capsys, command):
    """Item 9: the second run computed everything and only then exited 2. The
    other run is this test holding the report's lock file (.R.lock beside R) as a
    run now does from before its computation to the end of its writing."""
    with filelock.FileLock(files / ".R.lock", timeout=0):
        assert main([command, "--out", "R", "-q"]) == 2
    err = one_line_error(capsys)
    assert "another qc-control run is writing a report into 'R'" in err
    assert not (files / "R").exists()


def test_folders_made_for_the_lock_are_removed_when_nothing_is_written(files, monkeypatch):
    """The lock file lives beside the report, so the folders on the way to --out
    are made before the run; a run that writes nothing leaves none of them."""

    def interrupted(*args, **kwargs):
        assert (files / "a" / "b" / ".R.lock").exists()  # held through the computation
        raise KeyboardInterrupt

    monkeypatch.setattr(Scenario, "run", interrupted)
    assert main(["report", "--out", "a/b/R", "-q"]) == 130
    assert not (files / "a").exists()


@pytest.mark.slow
@pytest.mark.usefixtures("quick_figures")  # the exit and the files, not the pictures
def test_runs_into_two_folders_of_one_parent_both_succeed(files, capsys):
    """Item 9: with the lock on the parent, '--out reps/one' and '--out reps/two'
    excluded each other. Each report has its own lock: while one is held (another
    run computing into reps/one), a run into reps/two writes its report."""
    (files / "reps").mkdir()
    argv = ["control-report", "--designs", "skyhook semi-active", "-q"]
    argv += ["--road-duration", "1", "--bump-duration", "1"]
    with filelock.FileLock(files / "reps" / ".one.lock", timeout=0):
        assert main([*argv, "--out", "reps/two"]) == 0
        assert main([*argv, "--out", "reps/one"]) == 2
    capsys.readouterr()
    assert main([*argv, "--out", "reps/one"]) == 0
    for name in ("one", "two"):
        assert (files / "reps" / name / "report.html").exists()
    assert sorted(p.name for p in (files / "reps").iterdir()) == ["one", "two"]


@pytest.mark.slow
def test_two_processes_into_two_folders_of_one_parent_both_succeed(files):
    """Item 9 as found: two commands started together into --out one and --out two."""
    argv = [sys.executable, "-m", "qc_control.cli.console", "control-report", "-q"]
    argv += ["--designs", "skyhook semi-active", "--road-duration", "1", "--bump-duration", "1"]
    runs = [
        subprocess.Popen([*argv, "--out", f"reps/{name}"], stderr=subprocess.PIPE, text=True)
        for name in ("one", "two")
    ]
    errors = [run.communicate(timeout=300)[1] for run in runs]
    assert [run.returncode for run in runs] == [0, 0], errors
    assert sorted(p.name for p in (files / "reps").iterdir()) == ["one", "two"]


@pytest.mark.usefixtures("quick_figures")  # the exit and the files, not the pictures
def test_control_report_of_a_semi_active_design_alone(files, capsys):
    """Item 10: a valid name that selects no linear design exited 2 with pandas'
    'No objects to concatenate' after computing. It writes its report."""
    argv = ["control-report", "--designs", "skyhook semi-active", "-q", "--out", "cr"]
    assert main([*argv, "--road-duration", "1", "--bump-duration", "1"]) == 0
    assert "skyhook semi-active" in capsys.readouterr().out
    assert (files / "cr" / "report.html").exists() and (files / "cr" / "pareto.png").exists()


@pytest.mark.parametrize(
    "designs, words",
    [("", "--designs: unknown design ''; choose from ["), (",", "unknown design ''")],
)
def test_control_report_empty_designs_are_refused(files, no_work, capsys, designs, words):
    assert main(["control-report", "--designs", designs, "-q"]) == 2
    assert words in one_line_error(capsys)


@pytest.mark.parametrize(
    "argv", [["--help"], ["report", "--help"], ["identify", "--help"], ["modes"]]
)
def test_output_survives_a_terminal_that_cannot_encode_it(argv):
    """Issue 39 item 9: Windows gives a piped or redirected stdout cp1252, which
    has no ∞ or √, and --help ended in a UnicodeEncodeError. In a fresh process
    with that encoding, each command exits 0 and what cannot be shown is spelt
    out (∞ as 'inf')."""
    env = {**os.environ, "PYTHONIOENCODING": "cp1252"}
    code = "import sys; from qc_control.cli.console import main; sys.exit(main(sys.argv[1:]))"
    out = subprocess.run(
        [sys.executable, "-c", code, *argv], capture_output=True, timeout=300, env=env
    )
    assert out.returncode == 0, out.stderr.decode("cp1252", "replace")
    text = out.stdout.decode("cp1252")  # every byte is cp1252
    assert text.strip() and b"Traceback" not in out.stderr


@pytest.mark.parametrize(
    "argv, spelt",
    [(["control-report", "--help"], "Hinf"), (["modes", "--help"], "cs/(2sqrt(ks*ms))")],
)
def test_output_survives_the_c_locale(argv, spelt):
    """Under the C locale without UTF-8 mode (LC_ALL=C PYTHONUTF8=0: a bare
    container, a cron job) stdout is ASCII with surrogateescape, not strict,
    and --help ended in a UnicodeEncodeError on its ∞. It exits 0 now, every
    byte ASCII, H∞ and √ spelt as `SPELLED` gives them."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONIOENCODING"}
    env.update(LC_ALL="C", PYTHONUTF8="0")
    code = "import sys; from qc_control.cli.console import main; sys.exit(main(sys.argv[1:]))"
    out = subprocess.run(
        [sys.executable, "-c", code, *argv], capture_output=True, timeout=300, env=env
    )
    assert out.returncode == 0, out.stderr.decode("ascii", "replace")
    assert b"Traceback" not in out.stderr
    assert spelt in out.stdout.decode("ascii")  # every byte is ASCII


def test_undecodable_bytes_of_a_path_are_written_back():
    """The C locale decodes a path's non-ASCII bytes to lone surrogates: they
    are written back as those very bytes (what ``surrogateescape`` does), so
    'wrote .../rép/report.html' names the folder as typed."""
    typed = "my rép".encode()  # UTF-8, as a terminal types it
    seen = typed.decode("ascii", "surrogateescape")  # what sys.argv holds under LC_ALL=C
    assert seen.encode("ascii", "qc-control-spell") == typed
    # a surrogate beside a character the code page lacks, last in the line (it
    # was read past the end: an IndexError): each by its own rule
    assert (seen + " ∞").encode("ascii", "qc-control-spell") == typed + b" inf"
    assert "H∞".encode("cp1252", "qc-control-spell") == b"Hinf"


def test_characters_a_code_page_lacks_are_spelt_out():
    from qc_control.cli.console import SPELLED

    line = "h ≤ 2.8/λ, ζ = 0.3, ‖e‖∞ < 1e−3 ⁻¹ ☃"
    assert line.encode("cp1252", "qc-control-spell") == (
        b"h <= 2.8/lambda, zeta = 0.3, ||e||inf < 1e-3 ^-1 ?"
    )
    # every spelling is itself plain ASCII
    assert all(v.isascii() for v in SPELLED.values())
