"""Every script in examples/ runs and writes what it says, with the numbers it should.

Each example runs once per run of the suite: in the docs build, where the
gallery runs it with an output folder under the build directory as its
argument (conftest's ``docs_build``), and the tests here read what it wrote
and printed there (the printed lines from the gallery page's output
blocks). One example also runs with no argument, as ``python
examples/NAME.py`` runs it (in this process, with the script's own argv and
a fresh working directory), to check where it writes then. Every test checks something specific
in what the example produced: file names and image sizes, and printed
numbers against an independent computation in the test (numpy's matrix
power for Euler's trajectory, eigenvalues of a matrix assembled here, the
ISO 8608 class scaling).
"""

import csv
import re
import runpy
import struct
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
from conftest import gallery_run

ROOT = Path(__file__).parent.parent
EXAMPLES = {p.stem: p for p in sorted((ROOT / "examples").glob("*.py"))}
PNG = b"\x89PNG\r\n\x1a\n"

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("docs")]


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) in pixels from the PNG header."""
    data = path.read_bytes()
    assert data[:8] == PNG, path
    return struct.unpack(">II", data[16:24])


def seed_A():
    """The seed's A, assembled here from M, C, K (Table 1; cs = 2ζ√(ks·ms), ζ = 0.25)."""
    return quarter_car_A(301.2, 100.0, 30000.0, 29530.0, 0.25)


def quarter_car_A(ms, mu, ks, ku, zeta):
    cs = 2 * zeta * np.sqrt(ks * ms)
    M = np.diag([ms, mu])
    C = np.array([[cs, -cs], [-cs, cs]])
    K = np.array([[ks, -ks], [-ks, ks + ku]])
    Minv = np.linalg.inv(M)
    # states [vs, vu, xs, xu]
    return np.block([[-Minv @ C, -Minv @ K], [np.eye(2), np.zeros((2, 2))]])


def test_there_are_the_documented_examples():
    assert set(EXAMPLES) >= {
        "four_methods",
        "seed_paper",
        "custom_method",
        "modal_analysis",
        "design_sweep",
        "road_comfort",
        "half_car_pitch",
        "full_car_roll",
    }


# every example takes its folder from report.outputs.output_folder (test_example_outputs.py);
# the cheapest one is run bare, as a student runs it: argv is the script's alone
# (in this process: a new interpreter would only add its start-up and imports)
@pytest.mark.parametrize("name", ["modal_analysis"])
def test_without_an_argument_it_writes_beside_the_caller_and_says_where(
    name, tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("sys.argv", [str(EXAMPLES[name])])
    runpy.run_path(str(EXAMPLES[name]), run_name="__main__")
    stdout = capsys.readouterr().out
    folder = tmp_path / f"{name}_output"
    assert [p.name for p in tmp_path.iterdir()] == [folder.name]  # nothing else in the cwd
    assert list(folder.glob("*.png"))
    assert f"writing into {folder.resolve()}" in stdout


def test_four_methods(docs_build):
    stdout, out = gallery_run(docs_build, "four_methods")
    rows = re.findall(r"(\w+)\s+max \|xs error\| = (\S+) m with (\d+) RHS evaluations", stdout)
    errors = {m: float(e) for m, e, _ in rows}
    nfev = {m: int(n) for m, _, n in rows}
    assert list(errors) == ["euler", "midpoint", "heun", "rk4"]
    assert nfev == {"euler": 1000, "midpoint": 2000, "heun": 2000, "rk4": 4000}  # stages·steps
    assert errors["rk4"] < errors["midpoint"] == errors["heun"] < errors["euler"]
    # Euler independently: x_n = (I + hA)^n x0 against expm(A t) x0, 1000 steps of 0.01 s
    A, x0, h = seed_A(), np.array([0.0, 0.0, 0.05, 0.0]), 0.01
    step, exact_step = np.eye(4) + h * A, scipy.linalg.expm(h * A)
    xe, xx, worst = x0.copy(), x0.copy(), 0.0
    for _ in range(1000):
        xe, xx = step @ xe, exact_step @ xx
        worst = max(worst, abs(xe[2] - xx[2]))
    # printed to 4 significant digits: 5e-4 relative, and expm's recurrence adds < 1e-12 m
    assert errors["euler"] == pytest.approx(worst, rel=5e-4)
    for name, size in (("four_methods.png", (960, 624)), ("four_methods_body_acc.png", (960, 624))):
        assert png_size(out / name) == size  # 8 × 5.2 in at 120 dpi
        assert (out / name).stat().st_size > 20_000


def test_seed_paper(docs_build):
    stdout, out = gallery_run(docs_build, "seed_paper")
    names = sorted(p.name for p in out.glob("*.png"))
    assert names == [
        "seed_figure_3_euler.png",
        "seed_figure_4_midpoint.png",
        "seed_figure_5_rk4.png",
        "seed_figure_6_heun.png",
    ]
    ranking = re.findall(r"\d\. (\w+)\s+(\S+) m .*observed order (\S+)\)", stdout)
    assert [m for m, _, _ in ranking][0] == "rk4" and ranking[-1][0] == "euler"
    orders = {m: float(p) for m, _, p in ranking}
    # the observed slope over h, h/2, h/4 is within 0.2 of the order at h = 0.01 s
    for method, p in {"euler": 1, "midpoint": 2, "heun": 2, "rk4": 4}.items():
        assert abs(orders[method] - p) < 0.2, (method, orders[method])


def test_custom_method_writes_a_full_report(docs_build):
    _, out = gallery_run(docs_build, "custom_method")
    report = out / "custom_report"
    with open(report / "methods.csv", newline="", encoding="utf-8") as fh:
        rows = {r["method"]: r for r in csv.DictReader(fh)}
    assert list(rows) == ["euler", "midpoint", "heun", "ralston", "rk4", "3/8-rule"]
    assert [int(r["order"]) for r in rows.values()] == [1, 2, 2, 2, 4, 4]
    assert abs(float(rows["ralston"]["observed order"]) - 2) < 0.1
    assert abs(float(rows["3/8-rule"]["observed order"]) - 4) < 0.2
    md = (report / "report.md").read_text(encoding="utf-8")
    # the seed's four keep Figures 3-6; added methods follow them
    for label in ("Figure 3: euler", "Figure 6: heun", "Figure 7: ralston", "Figure 8: 3/8-rule"):
        assert label in md
    html = (report / "report.html").read_text(encoding="utf-8")
    assert html.count('src="data:image/png;base64,') == len(list(report.glob("*.png")))
    assert (report / "report.pdf").read_bytes()[:5] == b"%PDF-"


def test_modal_analysis(docs_build):
    stdout, out = gallery_run(docs_build, "modal_analysis")
    # the body mode of the seed's car, independently: the slower pair of A's eigenvalues
    lam = np.linalg.eigvals(seed_A())
    body = min(lam[lam.imag > 0], key=abs)
    assert f"{abs(body) / (2 * np.pi):.4g}" in stdout.split("body bounce")[1].split("\n")[0]
    zeta = float(re.search(r"At ku/ks = 1000 the body's ζ is (\S+) ", stdout).group(1))
    lam = np.linalg.eigvals(quarter_car_A(301.2, 100.0, 30000.0, 1000 * 30000.0, 0.25))
    body = min(lam[lam.imag > 0], key=abs)
    assert zeta == pytest.approx(-body.real / abs(body), abs=5e-5)  # printed to 4 decimals
    assert png_size(out / "modal_tire_stiffness.png") == (770, 495)  # 7 × 4.5 in at 110 dpi


def test_road_comfort(docs_build):
    stdout, out = gallery_run(docs_build, "road_comfort")
    with open(out / "road_comfort.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    head, body = rows[0], rows[1:]
    assert len(body) == 12  # classes A-D at 10, 20, 30 m/s
    comfort = {(r[0], float(r[1])): float(r[2]) for r in body}
    assert head[2].startswith("comfort")
    # ISO 8608: each class has 4x the PSD of the one before, so 2x the RMS response
    for v in (10.0, 20.0, 30.0):
        for lo, hi in ("AB", "BC", "CD"):
            assert comfort[(hi, v)] / comfort[(lo, v)] == pytest.approx(2.0, rel=1e-9)
    sim = re.search(r"Wk RMS (\S+) m/s², tire load (\S+) \(spectral: (\S+), (\S+)\)", stdout)
    wk_sim, tire_sim, wk_psd, tire_psd = map(float, sim.groups())
    # a 90 s record of a random road: its RMS is within a few % of the spectral value
    assert wk_sim == pytest.approx(wk_psd, rel=0.05)
    assert tire_sim == pytest.approx(tire_psd, rel=0.05)
    assert png_size(out / "road_comfort.png")[0] == 1100  # 10 in at 110 dpi


def test_design_sweep(docs_build):
    stdout, out = gallery_run(docs_build, "design_sweep")
    with open(out / "design_sweep.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 1000  # 40 stiffnesses x 25 damping ratios
    acc = [c for c in rows[0] if c.startswith("rms_body_acc")][0]
    best = min(rows, key=lambda r: float(r[acc]))
    printed = re.search(r"ks = (\d+) N/m, zeta = (\S+), RMS body acceleration (\S+) m/s²", stdout)
    assert int(printed.group(1)) == round(float(best["ks"]))
    assert float(printed.group(3)) == pytest.approx(float(best[acc]), abs=5e-4)
    # the softest spring is the most comfortable on a road step
    assert float(best["ks"]) == pytest.approx(15e3)
    assert png_size(out / "design_sweep.png") == (880, 495)  # 8 × 4.5 in at 110 dpi


def test_half_car_pitch(docs_build):
    """The printed peaks against python-control's exact response of the same bump,
    and the wheelbase-filtering frequencies from the wheelbase and the speed."""
    import control

    import qc_control as qc

    stdout, out = gallery_run(docs_build, "half_car_pitch")
    car = qc.HalfCarParams(seat_x=0.3)
    L = car.a + car.b
    T = np.linspace(0.0, 3.0, 3001)
    sys_ = qc.half_car(car, road=True)
    for speed in (5.0, 20.0):
        U = qc.road.axle_inputs(T, qc.road.bump(T, 0.05, 1.0, speed, 0.2), L, speed)
        y = control.forced_response(sys_, T, U, 0.0).outputs
        pitch = np.degrees(np.max(np.abs(y[sys_.output_labels.index("theta")])))
        line = re.search(rf"at\s+{speed:.1f} m/s .*peak pitch (\S+) deg", stdout)
        # printed to 3 decimals; RK4 at 1 ms is 1e-9 rad off
        assert float(line.group(1)) == pytest.approx(pitch, abs=6e-4)
    dips = re.findall(
        r"\|pitch_acc/zr\| dips to \S+ at \S+ Hz \(wheelbase filtering: (\S+) Hz", stdout
    )
    assert [float(d) for d in dips] == pytest.approx([15.0 / L, 30.0 / L], abs=6e-4)
    assert png_size(out / "half_car_bump.png") == (880, 550)  # 8 × 5 in at 110 dpi
    assert png_size(out / "half_car_wheelbase_filtering.png") == (880, 495)


def test_full_car_roll(docs_build):
    """The roll frequencies against the eigenvalues of A, and the peak roll
    against python-control's exact response."""
    import dataclasses

    import control

    import qc_control as qc

    stdout, out = gallery_run(docs_build, "full_car_roll")
    plain = qc.FullCarParams()
    barred = dataclasses.replace(plain, arb_front=20e3, arb_rear=8e3)
    T = np.linspace(0.0, 3.0, 3001)
    left = qc.road.bump(T, 0.05, 1.0, 10.0, 0.2)
    U = qc.road.corner_inputs(T, left, np.zeros_like(T), plain.a + plain.b, 10.0)
    peaks = {}
    for name, car in (("no anti-roll bars", plain), ("anti-roll bars", barred)):
        sys_ = qc.full_car(car, road=True)
        phi = control.forced_response(sys_, T, U, 0.0).outputs[sys_.output_labels.index("phi")]
        peaks[name] = np.degrees(np.max(np.abs(phi)))
        line = re.search(rf"^{name}: roll mode (\S+) Hz.*peak roll (\S+) deg", stdout, re.M)
        assert float(line.group(2)) == pytest.approx(peaks[name], abs=6e-4)  # 3 decimals
        # the roll frequency is one of |λ|/2π of A's eigenvalues
        lam = np.linalg.eigvals(np.asarray(sys_.A))
        assert np.min(np.abs(np.abs(lam) / (2 * np.pi) - float(line.group(1)))) < 6e-4
    assert peaks["anti-roll bars"] > peaks["no anti-roll bars"]
    assert png_size(out / "full_car_roll.png") == (880, 550)


def test_no_example_or_library_figure_calls_show():
    files = list(EXAMPLES.values()) + [
        *(ROOT / "qc_control" / "report").glob("*.py"),
        ROOT / "qc_control" / "report" / "plotting.py",
    ]
    for path in files:
        text = path.read_text(encoding="utf-8")
        assert ".show(" not in text, path
        assert "import matplotlib.pyplot" not in text, path


def test_active_suspension(docs_build):
    stdout, out = gallery_run(docs_build, "active_suspension")
    p = qc_params()
    printed = float(re.search(r"cs = (\S+) N·s/m", stdout).group(1))
    assert printed == pytest.approx(p.ks * np.sqrt((p.ms + p.mu) / p.ku), abs=0.05)  # closed form
    with open(out / "control_table.csv", newline="", encoding="utf-8") as fh:
        rows = {r["design"]: r for r in csv.DictReader(fh)}
    acc = "road: rms_body_acc [m/s²]"
    assert float(rows["skyhook"][acc]) < float(rows["passive (seed)"][acc])
    for name in ("transmissibility_body_acc", "transmissibility_tire_defl"):
        assert png_size(out / f"{name}.png") == (800, 500)  # 8 × 5 in at 100 dpi
    assert png_size(out / "pareto.png") == (800, 600)


def qc_params():
    from qc_control import QuarterCarParams

    return QuarterCarParams()


def test_lift_off(docs_build):
    from scipy.integrate import solve_ivp

    stdout, out = gallery_run(docs_build, "lift_off")
    assert png_size(out / "lift_off.png") == (700, 500)  # 7 × 5 in at 100 dpi
    # the lift-off time, by solve_ivp on the equations written out here (seed car, gravity)
    ms, mu, ks, ku, cs, g = (
        301.2,
        100.0,
        30000.0,
        29530.0,
        0.25 * 2 * np.sqrt(30000 * 301.2),
        9.80665,
    )
    delta0 = (ms + mu) * g / ku

    def road(t):
        s = t - 0.1
        return 0.1 * (1 - np.cos(2 * np.pi * s / 0.4)) if 0 <= s <= 0.4 else 0.0

    def rhs(t, x):
        vs, vu, xs, xu = x
        f = ks * (xs - xu) + cs * (vs - vu)
        tire = max(0.0, ku * (delta0 - xu + road(t)))
        return [-f / ms, (f + tire - ku * delta0) / mu, vs, vu]

    def contact(t, x):
        return delta0 - x[3] + road(t)

    contact.terminal = True
    sol = solve_ivp(
        rhs, (0.1, 0.8), [0, 0, 0, 0], method="DOP853", rtol=1e-12, atol=1e-12, events=contact
    )
    printed = re.search(r"contact lost and regained at t = (\S+) s, (\S+) s", stdout)
    # printed to 1e-5 s; RK4 with events at 1/16 ms locates it to ~1e-12 s
    assert float(printed.group(1)) == pytest.approx(sol.t_events[0][0], abs=1e-5)
    rows = {
        m.group(1): [float(p) for p in m.group(2).split()]
        for m in re.finditer(r"events=(\w+)\s+errors .*observed orders\s+(.*)", stdout)
    }
    assert min(rows["True"]) >= 3.5  # order 4 recovered (measured 4.01, 4.00)
    assert max(rows["False"]) < 3.0  # collapsed without events (measured 1.77, 2.15)
