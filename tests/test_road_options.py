"""One set of road options for every model (issue 23 item 4).

``--road KIND`` with ``--road-height``, ``--road-length``, ``--speed`` ...
and one ``[scenario.road]`` table drive the quarter, the nonlinear, the half
and the full car alike; the old spellings are read with a deprecation
warning naming the new one; ``--help`` shows which options apply to which
model; a command offers only the models it runs; an error names the option
as the user gave it. The roads are checked against the 1 − cos bump written
out here, not against `qc_control.ride.road`.
"""

import argparse
import math

import numpy as np
import pytest

from qc_control.cli import parser as cli
from qc_control.cli.console import main
from qc_control.cli.parser import build_parser, scenario_from_args
from qc_control.ride.road import Bump as BumpRoad
from qc_control.ride.road import NoRoad
from qc_control.studies.scenario import Scenario

MODELS = ("quarter", "half", "full", "nonlinear")
#: The bump every model is driven over below: 8 cm high, 2 m long, at 10 m/s.
HEIGHT, LENGTH, SPEED = 0.08, 2.0, 10.0
BUMP = ["--road", "bump", "--road-height", "0.08", "--road-length", "2", "--speed", "10"]


def closed_form_bump(t, t0):
    """z = H/2 · (1 − cos(2π x / L)) for 0 <= x = V (t − t0) <= L, else 0."""
    x = SPEED * (np.asarray(t) - t0)
    inside = (x >= 0) & (x <= LENGTH)
    return np.where(inside, HEIGHT / 2 * (1 - np.cos(2 * np.pi * x / LENGTH)), 0.0)


def scenario_of(argv):
    """The Scenario the command line ``argv`` describes, without running it."""
    return scenario_from_args(build_parser().parse_args(argv))


@pytest.mark.parametrize("model", MODELS)
def test_one_bump_spelling_drives_every_model(model):
    sc = scenario_of(["report", "--model", model, *BUMP])
    # the nonlinear car's own bump is met at 0.1 s; a road of its kind keeps that t0
    t0 = 0.1 if model == "nonlinear" else BumpRoad().t0
    assert sc.model == model
    assert sc.road == BumpRoad(height=HEIGHT, length=LENGTH, speed=SPEED, t0=t0)
    T = sc.time_grid()
    zr, _ = sc.road_input(T)
    front = np.atleast_2d(zr)[0]
    # the front wheel (the only one on a quarter car) sees the bump sampled exactly
    np.testing.assert_allclose(front, closed_form_bump(T, t0), rtol=0, atol=1e-15)
    if model in ("half", "full"):
        v = sc.vehicle
        rear = np.atleast_2d(zr)[-1]
        # the rear wheel meets it (a + b)/V later; sampled between grid points, its
        # error is at most linear interpolation's, H/2 (2π/L)^2 (V h)^2 / 8
        bound = HEIGHT / 2 * (2 * math.pi / LENGTH) ** 2 * (SPEED * sc.h) ** 2 / 8
        expected = closed_form_bump(T, t0 + (v.a + v.b) / SPEED)
        np.testing.assert_allclose(rear, expected, rtol=0, atol=bound)


@pytest.mark.parametrize("model", MODELS)
def test_one_road_table_for_every_model(model):
    text = (
        f'[scenario]\nmodel = "{model}"\n\n[scenario.road]\nkind = "bump"\n'
        f"height = {HEIGHT}\nlength = {LENGTH}\nspeed = {SPEED}\n"
    )
    assert Scenario.from_toml_string(text) == scenario_of(["report", "--model", model, *BUMP])


def test_the_nonlinear_cars_default_stays_the_lift_off_bump():
    # the default: a 20 cm, 8 m bump at 20 m/s (met at 0.1 s, over 0-0.8 s at 2 ms)
    sc = scenario_of(["report", "--model", "nonlinear"])
    assert sc.road == BumpRoad(height=0.2, length=8.0, speed=20.0, t0=0.1)
    assert (sc.t_end, sc.h) == (0.8, 0.002)
    # a height alone changes the height of that bump only
    sc = scenario_of(["report", "--model", "nonlinear", "--road-height", "0.3"])
    assert sc.road == BumpRoad(height=0.3, length=8.0, speed=20.0, t0=0.1)
    assert scenario_of(["report", "--model", "nonlinear", "--road", "none"]).road == NoRoad()


def test_the_old_options_are_the_new_ones_with_a_warning():
    new = scenario_of(["report", "--model", "nonlinear", "--road-height", "0.3", "--speed", "25"])
    with pytest.warns(DeprecationWarning) as caught:
        old = scenario_of(
            ["report", "--model", "nonlinear", "--bump-height", "0.3", "--speed", "25"]
        )
    assert old == new
    assert "--bump-height is deprecated" in str(caught[0].message)
    assert "use --road-height" in str(caught[0].message)


def test_the_old_keys_are_the_road_table_with_a_warning():
    table = '[scenario]\nmodel = "nonlinear"\n\n[scenario.road]\nheight = 0.3\nlength = 6.0\n'
    flat = '[scenario]\nmodel = "nonlinear"\nbump_height = 0.3\nbump_length = 6.0\n'
    with pytest.warns(DeprecationWarning) as caught:
        old = Scenario.from_toml_string(flat)
    assert old == Scenario.from_toml_string(table)
    assert old.road == BumpRoad(height=0.3, length=6.0, speed=20.0, t0=0.1)
    messages = [str(w.message) for w in caught]
    assert any(
        "[scenario] bump_height = 0.3 is deprecated" in m
        and "write height = 0.3 in a [scenario.road] table" in m
        for m in messages
    ), messages


def test_an_old_key_beside_the_table_or_off_a_bump_is_refused():
    with pytest.warns(DeprecationWarning), pytest.raises(ValueError) as err:
        Scenario.from_toml_string("[scenario]\nbump_height = 0.3\n[scenario.road]\nheight = 0.1\n")
    assert "bump_height and [scenario.road] height are the same value" in str(err.value)
    with pytest.warns(DeprecationWarning), pytest.raises(ValueError) as err:
        Scenario.from_toml_string('[scenario]\nroad = "sine"\nbump_length = 3.0\n')
    assert "[scenario] bump_length applies to a bump road, not to the road of kind 'sine'" in (
        str(err.value)
    )


def run_capturing(monkeypatch, argv):
    """Run ``qc-control argv`` with the report's work replaced; its Scenario or
    the controller study's vehicle is returned with the exit status."""
    seen = {}
    monkeypatch.setattr(cli, "_report", lambda args, sc, out: seen.setdefault("run", sc) and 0)
    monkeypatch.setattr(
        cli, "_control_report", lambda args, params, d, out: seen.setdefault("run", params) and 0
    )
    return main(argv), seen.get("run")


def test_the_cli_warns_in_one_line_naming_the_new_option(monkeypatch, capsys, tmp_path):
    out = str(tmp_path / "r")
    status, sc = run_capturing(
        monkeypatch, ["report", "--model", "nonlinear", "--bump-length", "6", "--out", out]
    )
    assert status == 0 and sc.road.length == 6.0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("qc-control: warning: --bump-length is depr")
    assert "use --road-length" in err


@pytest.mark.parametrize(
    "argv, words",
    [
        # the option as given, not the field behind it
        (["report", "--model", "nonlinear", "--bump-length", "0"], "error: --bump-length must"),
        (["report", "--model", "nonlinear", "--road-length", "0"], "error: --road-length must"),
        (["report", "--model", "half", "--road", "bump", "--speed=-1"], "error: --speed must be a"),
        # 10 s / 0.03 s = 333.33 steps: the --h given, not a t_end nobody wrote
        (["report", "--h", "0.03"], "error: --h 0.03 s does not fit the default end time 10.0 s"),
        (["report", "--h", "1e-320"], "error: --h 1e-320 s over the default end time 10 s"),
        (["report", "--t-end", "1.234"], "error: --t-end 1.234 s must be a whole number"),
    ],
)
def test_errors_name_the_option_as_given(argv, words, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert words in err, err
    assert "[scenario]" not in err, err


def test_a_config_error_names_the_key_as_written(tmp_path, capsys):
    cfg = tmp_path / "old.toml"
    cfg.write_text('[scenario]\nmodel = "nonlinear"\nbump_length = -1.0\n')
    assert main(["report", "--config", str(cfg)]) == 2
    err = capsys.readouterr().err
    assert "[scenario] bump_length must be a finite number > 0 m, got -1.0" in err, err
    cfg.write_text('[scenario.road]\nkind = "bump"\nlength = 0.0\n')
    assert main(["report", "--config", str(cfg)]) == 2
    assert "[scenario.road] length must be a finite number > 0 m" in capsys.readouterr().err


def groups_of(command: str) -> dict[str, list[str]]:
    """The argument groups of a subcommand: title -> its option strings."""
    sub = next(
        a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)
    ).choices[command]
    return {
        g.title: [
            s for a in g._group_actions if a.help != argparse.SUPPRESS for s in a.option_strings
        ]
        for g in sub._action_groups
    }


def test_report_help_groups_the_vehicle_options_by_model(capsys):
    groups = groups_of("report")
    assert groups["vehicle: every car's parameters (SI units)"] == ["--ms"]
    quarter = groups["vehicle: the quarter and nonlinear car's parameters (SI units)"]
    assert "--ks" in quarter and "--ks-front" not in quarter
    axles = groups["vehicle: the half and full car's parameters (SI units)"]
    assert {"--ks-front", "--a", "--b", "--Iy"} <= set(axles) and "--ks" not in axles
    assert {"--track-front", "--Ix"} <= set(groups["vehicle: the full car's parameters (SI units)"])
    assert "--tire" in groups["the nonlinear car's options"]
    road = next(options for title, options in groups.items() if title.startswith("road input"))
    assert {"--road", "--road-height", "--road-length", "--speed"} <= set(road)
    # the deprecated spellings are read but not offered
    assert "--bump-height" not in main_help(capsys, ["report"])


def main_help(capsys, argv) -> str:
    assert main([*argv, "--help"]) == 0
    return capsys.readouterr().out


def test_control_report_offers_the_quarter_car_only(capsys):
    text = main_help(capsys, ["control-report"])
    for other in ("half", "full", "nonlinear", "--ks-front", "--track-front", "--tire"):
        assert other not in text, other
    assert "--model {quarter}" in text and "--ks " in text
    assert main(["control-report", "--model", "nonlinear"]) == 2
    err = capsys.readouterr().err
    assert "control-report compares controllers on the quarter car only" in err, err
    assert main(["control-report", "--ks-front", "1e4"]) == 2
    assert "unrecognized arguments: --ks-front" in capsys.readouterr().err


def test_control_report_reads_a_configs_vehicle_only(monkeypatch, capsys, tmp_path):
    cfg = tmp_path / "scenario.toml"
    # a report's run that control-report does not have: 1e12 steps, and a road
    cfg.write_text(
        'ms = 350.0\n[scenario]\nt_end = 1e9\nh = 0.001\n[scenario.road]\nkind = "step"\n'
    )
    status, params = run_capturing(
        monkeypatch, ["control-report", "--config", str(cfg), "--out", str(tmp_path / "c")]
    )
    assert status == 0 and params.ms == 350.0
    assert "--max-steps" not in capsys.readouterr().err
    cfg.write_text('[scenario]\nmodel = "nonlinear"\n')
    assert main(["control-report", "--config", str(cfg)]) == 2
    err = capsys.readouterr().err
    assert "[scenario] model = 'nonlinear': control-report compares controllers on the " in err


def test_modes_reads_a_configs_vehicle_only(tmp_path, capsys):
    cfg = tmp_path / "scenario.toml"
    cfg.write_text("ms = 400.0\nzeta = 0.3\n[scenario]\nt_end = 1e9\nh = 0.001\n")
    assert main(["modes", "--config", str(cfg), "--ku", "1e12"]) == 0
    # rigid tire: the body's wn = sqrt(ks/ms) = sqrt(30000/400) = 8.660 rad/s
    assert "8.66" in capsys.readouterr().out
