"""The qc-control command: output and one-line errors with exit status 2."""

import subprocess
import sys

import pytest

from qc_control.cli import main


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "qc_control.cli", *args], capture_output=True, text=True, timeout=300
    )


def test_modes_prints_table():
    out = run("modes")
    assert out.returncode == 0, out.stderr
    assert "body bounce" in out.stdout and "1.087" in out.stdout


def test_modes_options_and_config(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text("ms = 400.0\nzeta = 0.3\n")
    assert main(["modes", "--config", str(cfg), "--ku", "1e12"]) == 0
    text = capsys.readouterr().out
    # rigid tire: body wn = sqrt(ks/ms) = sqrt(30000/400) = 8.660 rad/s
    assert "8.66" in text


@pytest.mark.parametrize(
    "args, words",
    [
        (["modes", "--ms", "-1"], "ms (sprung mass) must be > 0 kg, got -1.0"),
        (["modes", "--ku", "nan"], "ku must be finite, got nan"),
        (["modes", "--ms", "abc"], "--ms: invalid float value: 'abc'"),
        (["modes", "--config", "missing.toml"], "missing.toml"),
        (["modes", "--bogus"], "unrecognized arguments: --bogus"),
        ([], "command"),
    ],
)
def test_bad_input_one_line_exit_2(args, words, capsys):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1 and "Traceback" not in err


def test_bad_config_key_via_real_process(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text("ms = 400.0\nwheelbase = 2.5\n")
    out = run("modes", "--config", str(cfg))
    assert out.returncode == 2
    assert out.stderr.count("\n") == 1 and "'wheelbase'" in out.stderr
    assert "Traceback" not in out.stderr
