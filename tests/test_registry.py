"""A vehicle model plugs in at one place: its registry entry.

This file defines a model that qc_control does not know, a quarter car with
a seated driver (3 DOF, 6 states), registers it through the public hook
``qc.register_model`` and runs it through ``qc.compare_methods``,
``qc.sweep``, ``qc.write_report`` and ``qc-control report --config`` with no
change to ``qc_control/``. The numbers are held to independent references:
the eigenvalues of the mass, damping and stiffness matrices assembled here
spring by spring, and python-control's exact responses, with RK4's error
bounded by its modal closed form.

The driver's values: a 75 kg driver on a seat cushion of 60 kN/m and
1200 N·s/m, so that the driver bounces on the cushion at
√(60000/75)/2π = 4.5 Hz with a damping ratio 1200/(2√(60000·75)) = 0.28,
the seated person's vertical resonance of 4-6 Hz (apparent mass) and its
damping ratio of 0.2-0.5 (M. J. Griffin, *Handbook of Human Vibration*,
Academic Press, 1990, ch. 8; ISO 5982:2019, Table 2). The car under the
seat is the seed's quarter car (Table 1).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import shlex
import sys
from dataclasses import dataclass, fields

import control
import numpy as np
import pandas as pd
import pytest
import scipy.linalg
from reports_shared import placeholder_figures, quick_figures, untimed  # noqa: F401  (fixtures)

import qc_control as qc
from qc_control.cli.console import main
from qc_control.cli.parser import build_parser, scenario_from_args
from qc_control.models.registry import MODELS, vehicle_model

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

#: Standard gravity [m/s²] (ISO 80000-3), for the static wheel load.
G = 9.80665
STATES = ("vd", "vs", "vu", "xd", "xs", "xu")
OUTPUTS = ("xd", "xs", "xu", "susp_travel", "tire_defl", "driver_acc", "body_acc")
UNITS = {
    **{s: "m/s" for s in STATES[:3]},
    **{s: "m" for s in STATES[3:]},
    "susp_travel": "m",
    "tire_defl": "m",
    "driver_acc": "m/s²",
    "body_acc": "m/s²",
    "zr": "m",
}


@dataclass(frozen=True)
class SeatedCarParams:
    """A quarter car with a driver on a seat cushion [SI units]."""

    md: float = 75.0  # driver (and cushion) [kg]
    kd: float = 60000.0  # cushion stiffness [N/m]
    cd: float = 1200.0  # cushion damping [N·s/m]
    ms: float = 301.2  # sprung mass [kg], the seed's Table 1
    mu: float = 100.0  # unsprung mass [kg]
    ks: float = 30000.0  # suspension stiffness [N/m]
    cs: float = 1503.0  # suspension damping [N·s/m]
    ku: float = 29530.0  # tire stiffness [N/m]

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            damping = f.name.startswith("c")
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{f.name} must be a finite number, got {value!r}")
            if value < 0 or (value == 0 and not damping):
                raise ValueError(f"{f.name} must be > 0, got {value!r}")
            object.__setattr__(self, f.name, float(value))

    @classmethod
    def from_mapping(cls, values):
        names = [f.name for f in fields(cls)]
        unknown = sorted(set(values) - set(names))
        if unknown:
            raise ValueError(f"unknown parameter {unknown[0]!r}; expected one of {names}")
        return cls(**dict(values))

    def to_dict(self, *, changing=None):
        return dataclasses.asdict(self)

    def table(self):
        meaning = {
            "md": ("driver mass", "kg"),
            "kd": ("seat cushion stiffness", "N/m"),
            "cd": ("seat cushion damping", "N·s/m"),
            "ms": ("sprung mass", "kg"),
            "mu": ("unsprung mass", "kg"),
            "ks": ("suspension stiffness", "N/m"),
            "cs": ("suspension damping", "N·s/m"),
            "ku": ("tire stiffness", "N/m"),
        }
        return [(n, *meaning[n][:1], getattr(self, n), meaning[n][1]) for n in meaning]


def seated_car_model(params=None, *, road=False, cushion_scale=1.0) -> qc.VehicleModel:
    """The seated quarter car as a VehicleModel, its A written from Newton's law per mass.

    ``cushion_scale`` scales the cushion's stiffness and damping (a worn cushion: < 1).
    """
    p = SeatedCarParams() if params is None else params
    md, kd, cd, ms, mu, ks, cs, ku = (getattr(p, f.name) for f in fields(p))
    kd, cd = kd * cushion_scale, cd * cushion_scale
    # rows: md·ad = kd(xs - xd) + cd(vs - vd); ms·as = -that - ks(xs - xu) - cs(vs - vu);
    # mu·au = ks(xs - xu) + cs(vs - vu) - ku(xu - zr); states [vd, vs, vu, xd, xs, xu]
    acc = np.array(
        [
            [-cd / md, cd / md, 0, -kd / md, kd / md, 0],
            [cd / ms, -(cd + cs) / ms, cs / ms, kd / ms, -(kd + ks) / ms, ks / ms],
            [0, cs / mu, -cs / mu, 0, ks / mu, -(ks + ku) / mu],
        ]
    )
    A = np.vstack([acc, np.hstack([np.eye(3), np.zeros((3, 3))])])
    B = np.array([[0.0], [0.0], [ku / mu], [0.0], [0.0], [0.0]])
    C = np.vstack(
        [np.eye(6)[3:], [0, 0, 0, 0, 1, -1], [0, 0, 0, 0, 0, 1], acc[0], acc[1]],
    )
    D = np.zeros((7, 1))
    D[4, 0] = -1.0  # tire_defl = xu - zr
    inputs = ["zr"] if road else []
    sys = control.ss(
        A,
        B if road else np.zeros((6, 0)),
        C,
        D if road else np.zeros((7, 0)),
        states=list(STATES),
        inputs=inputs,
        outputs=list(OUTPUTS),
        name="seated_car",
    )
    corner = qc.Corner(
        "", "susp_travel", "tire_defl", "zr" if road else None, ku, (md + ms + mu) * G
    )
    return qc.VehicleModel(
        sys,
        p,
        UNITS,
        qc.SignalRoles("driver_acc", "xs", (corner,)),
        functools.partial(seated_car_model, road=road, cushion_scale=cushion_scale),
    )


def _scale(value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise ValueError(f"cushion_scale must be a number > 0, got {value!r}")
    return float(value)


ENTRY = qc.ModelEntry(
    "seated",
    SeatedCarParams,
    seated_car_model,
    "a quarter car with a driver on a seat cushion",
    options=(
        qc.ModelOption(
            "cushion_scale", 1.0, _scale, "scales the cushion's stiffness and damping", parse=float
        ),
    ),
    wheel_disp="xu",
)


@pytest.fixture
def seated():
    """The model registered for one test, and taken away after it."""
    entry = qc.register_model(ENTRY)
    yield entry
    qc.unregister_model(entry.name)


def _mck(p: SeatedCarParams):
    """M, C, K of the three masses [driver, body, wheel], assembled element by element."""
    M = np.diag([p.md, p.ms, p.mu])
    K, Cm = np.zeros((3, 3)), np.zeros((3, 3))
    # each spring (damper) between masses i and j adds k [[1, -1], [-1, 1]]; the tire
    # joins the wheel to the ground
    for i, j, k, c in ((0, 1, p.kd, p.cd), (1, 2, p.ks, p.cs)):
        for a, b, s in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
            K[a, b] += s * k
            Cm[a, b] += s * c
    K[2, 2] += p.ku
    return M, Cm, K


def _rk4_bound(sys, x0, T, h, label) -> float:
    """The largest |RK4 - exact| of output ``label`` over ``T`` from the modal closed form.

    On ``x' = Ax`` RK4 gives ``x_n = R(hA)^n x0`` with
    ``R(z) = 1 + z + z²/2 + z³/6 + z⁴/24``; in eigen coordinates
    ``x0 = Σ v_i c_i``, so the output error is
    ``Σ_i (C v_i c_i)(R(hλ_i)^n - e^{λ_i t_n})``, bounded by the sum of its moduli.
    """
    lam, V = np.linalg.eig(sys.A)
    c = np.linalg.solve(V, x0)
    row = np.asarray(sys.C)[list(sys.output_labels).index(label)]
    z = h * lam
    R = 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24
    n = np.round(T / h)[:, None]
    gap = np.abs(R[None, :] ** n - np.exp(lam[None, :] * T[:, None]))
    return float(np.max(gap @ np.abs((row @ V) * c)))


def test_registration_is_undone_after_each_test(seated):
    assert "seated" in MODELS and qc.get_model("seated") is ENTRY
    with pytest.raises(ValueError, match="a model named 'seated' is registered already"):
        qc.register_model(ENTRY)


def test_its_option_goes_from_toml_and_command_line_to_the_model(seated):
    sc = qc.Scenario.from_mapping({"scenario": {"model": "seated", "cushion_scale": 0.5}})
    assert sc.option("cushion_scale") == 0.5
    # a worn cushion: the model's cushion is that of kd/2 and cd/2
    half = SeatedCarParams(kd=30000.0, cd=600.0)
    np.testing.assert_array_equal(sc.vehicle_model().system.A, seated.model(half).system.A)
    assert qc.Scenario.from_toml_string(sc.to_toml()) == sc
    assert "--cushion-scale 0.5" in sc.command()
    args = build_parser().parse_args(shlex.split(sc.command())[1:])
    assert scenario_from_args(args) == sc
    with pytest.raises(qc.ScenarioError, match="cushion_scale must be a number > 0, got -1"):
        qc.Scenario(model="seated", model_options={"cushion_scale": -1})
    with pytest.raises(qc.ScenarioError, match="cushion_scale = 2.0 applies to the seated car"):
        qc.Scenario(model_options={"cushion_scale": 2.0})


def test_no_other_test_sees_it():
    assert "seated" not in MODELS
    with pytest.raises(qc.ScenarioError, match="model must be one of"):
        qc.Scenario(model="seated")


def test_eigenvalues_against_the_assembled_mck(seated):
    p = SeatedCarParams(md=80.0, kd=50000.0)
    model = seated.model(p)
    M, Cm, K = _mck(p)
    # the quadratic eigenproblem (λ²M + λC + K)q = 0 in its first-order companion form
    Minv = np.linalg.inv(M)
    companion = np.block([[np.zeros((3, 3)), np.eye(3)], [-Minv @ K, -Minv @ Cm]])
    expected = np.sort_complex(np.linalg.eigvals(companion))
    got = np.sort_complex(np.linalg.eigvals(model.system.A))
    # two assemblies of the same 6×6 problem: they agree to rounding, a few ulps of the
    # largest |λ| (~40 1/s); 1e-9 relative leaves room for the eigen-solver's conditioning
    np.testing.assert_allclose(got, expected, rtol=1e-9)
    # one mode is the driver's on the cushion: near √(kd/md), shifted by the coupling
    assert np.any(np.isclose(np.abs(got), math.sqrt(p.kd / p.md), rtol=0.2))


def test_compare_methods_against_control(seated):
    model = seated.model()
    T = np.linspace(0.0, 3.0, 301)  # h = 0.01 s
    X0 = seated.free_start(model.params)
    assert X0 == (0.0, 0.0, 0.0, 0.0, 0.05, 0.0)  # the body released from 5 cm
    cmp = qc.compare_methods(model, T, X0, methods=["euler", "rk4"], timing=False)
    exact = control.initial_response(model.system, T, X0)
    # the comparison's reference is python-control's exact response: same to rounding
    np.testing.assert_allclose(cmp.reference.outputs, exact.outputs, rtol=0, atol=1e-12)
    y = exact.outputs[list(OUTPUTS).index("driver_acc")]
    rk4 = cmp.responses["rk4"].outputs[list(OUTPUTS).index("driver_acc")]
    bound = _rk4_bound(model.system, np.array(X0), T, 0.01, "driver_acc")
    # RK4's error is its modal closed form; 1e-9 m/s² more for rounding in the sums
    assert np.max(np.abs(rk4 - y)) <= bound * (1 + 1e-6) + 1e-9
    assert 0 < bound < 0.05 * np.max(np.abs(y))  # a meaningful bound: a few % at most
    assert cmp.table.loc["rk4", "observed order"] == pytest.approx(4.0, abs=0.3)


def test_sweep_against_control(seated):
    T = np.linspace(0.0, 2.0, 401)  # h = 0.005 s
    X0 = (0.0, 0.0, 0.0, 0.0, 0.05, 0.0)
    designs = [{"kd": kd, "cd": cd} for kd in (40000.0, 80000.0) for cd in (600.0, 1800.0)]
    designs = [SeatedCarParams(**d).to_dict() for d in designs]
    result = qc.sweep(designs, T, X0, model=seated.model(), metrics=["rms_body_acc"])
    assert result.errors.empty
    for row, d in zip(result.metrics.itertuples(index=False), designs):
        model = seated.model(SeatedCarParams(**d))
        acc = control.initial_response(model.system, T, X0).outputs[OUTPUTS.index("driver_acc")]
        rms = math.sqrt(np.trapezoid(acc**2, T) / T[-1])
        # |rms(a) - rms(b)| <= max|a - b|, RK4's modal bound at h = 0.005 s
        bound = _rk4_bound(model.system, np.array(X0), T, 0.005, "driver_acc")
        assert abs(row[list(result.metrics.columns).index("rms_body_acc [m/s²]")] - rms) <= (
            bound * (1 + 1e-6) + 1e-9
        )


def test_vehicle_model_builds_each_registered_model_from_its_parameters(seated):
    half, p = qc.HalfCarParams(), SeatedCarParams(md=80.0)
    for params, built in (
        (half, qc.half_car_model(half, road=True)),
        (p, seated_car_model(p, road=True)),
        ({"ks": 25e3}, qc.quarter_car_model(qc.QuarterCarParams(ks=25e3), road=True)),
        (None, qc.quarter_car_model(road=True)),
    ):
        model = vehicle_model(params, road=True)
        assert model.system.input_labels == built.system.input_labels
        for k in "ABCD":
            assert np.array_equal(getattr(model.system, k), getattr(built.system, k))


def test_ride_metrics_of_its_parameters_go_through_its_entry(seated):
    """The ride metrics take the seated car's parameters as they take a quarter
    car's: the registry builds its model, no branch in the ride layer names it."""
    p = SeatedCarParams(cd=900.0)
    model = seated.model(p, road=True)
    T = np.linspace(0.0, 2.0, 401)
    resp = control.forced_response(model.system, T, qc.road.step(T, height=0.02, t0=0.2))
    names = ["rms_body_acc", "peak_susp_travel", "rms_tire_load / static"]
    assert qc.ride_metrics(resp, p, names).equals(qc.ride_metrics(resp, model, names))
    # The exact stationary RMS of the driver's acceleration on white road velocity of
    # intensity q, from a Lyapunov equation solved here by scipy (Bartels-Stewart) on
    # the car's own matrices: with x̃ = x + A⁻¹B zr the road velocity w enters as
    # A⁻¹B w, and an acceleration has no static gain from the road height. Two
    # backward-stable solves of a well-conditioned 6×6 equation: 1e-9 relative.
    q = qc.road.iso8608_intensity("C", 20.0)
    A, B, C = (np.asarray(getattr(model.system, k)) for k in "ABC")
    Bw = np.linalg.solve(A, B)
    P = scipy.linalg.solve_continuous_lyapunov(A, -Bw @ Bw.T)
    c = C[OUTPUTS.index("driver_acc")]
    expected = math.sqrt(q * c @ P @ c)
    got = qc.ride_metrics_spectral(p, qc.road.ISO8608Road("C", speed=20.0), exact=True)
    assert got["rms_body_acc [m/s²]"] == pytest.approx(expected, rel=1e-9)


def test_fit_parameters_are_fields_of_its_parameters():
    from qc_control.studies.identification import PHYSICAL

    # the quarter car's entry names what identification fits today
    assert qc.get_model("quarter").fit_parameters == PHYSICAL
    assert ENTRY.fit_parameters == ()  # a model not identified
    with pytest.raises(qc.ParameterError) as err:
        dataclasses.replace(ENTRY, fit_parameters=("md", "nope"))
    assert err.value.name == "fit_parameters"


@pytest.mark.slow
@pytest.mark.usefixtures("quick_figures")  # which curves are drawn, not their pixels
def test_write_report_draws_its_wheel(seated, tmp_path):
    from qc_control.report.figures import method_figure, reference_figure

    model = seated.model()
    T = np.linspace(0.0, 2.0, 201)
    cmp = qc.compare_methods(model, T, seated.free_start(model.params), timing=False)
    path = qc.write_report(cmp, tmp_path / "report", formats=("md", "html", "csv"))
    assert {"report.md", "report.html", "methods.csv", "method_rk4.png"} <= {
        f.name for f in path.iterdir()
    }
    # the figures draw the body and the wheel the entry names (wheel_disp), not an 'xu' guess
    labels = [line.get_label() for line in reference_figure(cmp).axes[0].get_lines()]
    assert labels == ["body xs (exact)", "wheel xu (exact)"]
    labels = [line.get_label() for line in method_figure(cmp, "rk4").axes[0].get_lines()]
    assert "wheel xu" in labels and "suspension (sprung mass) xs" in labels


def _rk4(A, B, T, U, x0):
    """RK4 written out, with the input linear between samples (as python-control reads U)."""
    h = T[1] - T[0]
    f = lambda x, u: A @ x + B @ u  # noqa: E731
    xs = [np.asarray(x0, dtype=float)]
    for n in range(T.size - 1):
        u0, u1 = U[:, n], U[:, n + 1]
        x = xs[-1]
        k1 = f(x, u0)
        k2 = f(x + h / 2 * k1, (u0 + u1) / 2)
        k3 = f(x + h / 2 * k2, (u0 + u1) / 2)
        k4 = f(x + h * k3, u1)
        xs.append(x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4))
    return np.array(xs).T


@pytest.mark.slow
@pytest.mark.usefixtures("placeholder_figures", "untimed")  # its numbers, not pictures or times
def test_scenario_and_cli_report_from_toml(seated, tmp_path, capsys):
    config = tmp_path / "seated.toml"
    config.write_text(
        'md = 80.0\nkd = 55000.0\n\n[scenario]\nmodel = "seated"\nt_end = 2.0\n'
        'methods = ["heun", "rk4"]\n\n[scenario.road]\nkind = "bump"\nheight = 0.05\n'
        "speed = 10.0\n",
        encoding="utf-8",
    )
    sc = qc.Scenario.from_toml(config)
    assert (sc.model, sc.vehicle.md, sc.vehicle.kd, sc.vehicle.cd) == (
        "seated",
        80.0,
        55000.0,
        1200.0,
    )
    assert sc.x0 == (0.0,) * 6  # at rest under a road
    assert qc.Scenario.from_toml_string(sc.to_toml()) == sc
    assert "--model seated" in sc.command() and "--md 80.0" in sc.command()
    out = tmp_path / "out"
    assert main(["report", "--config", str(config), "--out", str(out), "-q"]) == 0
    written = tomllib.loads((out / "scenario.toml").read_text(encoding="utf-8"))
    assert written["scenario"]["model"] == "seated" and written["md"] == 80.0
    # the report's RK4 error is RK4 (written out here) against control's exact response
    model = sc.vehicle_model(road=True)
    T = sc.time_grid()
    U = np.atleast_2d(sc.road_input(T)[0])
    exact = control.forced_response(model.system, T, U, X0=np.zeros(6))
    xs = OUTPUTS.index("xs")
    C = np.asarray(model.system.C)
    rk4 = C[xs] @ _rk4(np.asarray(model.system.A), np.asarray(model.system.B), T, U, np.zeros(6))
    table = pd.read_csv(out / "methods.csv", index_col="method")
    # two evaluations of one RK4 (the report's through R(hA)): rounding of 200 steps on a
    # signal of centimetres, far below 1e-12 m
    assert table.loc["rk4", "max |xs err| [m]"] == pytest.approx(
        np.max(np.abs(rk4 - exact.outputs[xs])), abs=1e-12
    )
    # and the observed orders are the methods' orders (Heun 2, RK4 4)
    assert table.loc["heun", "observed order"] == pytest.approx(2.0, abs=0.3)
    assert table.loc["rk4", "observed order"] == pytest.approx(4.0, abs=0.3)
    assert "error" not in capsys.readouterr().err
