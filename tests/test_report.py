"""The written report: files, links, HTML images, atomic writes, section order,
number formats, the self-contained HTML, the PDF, numbering, and the figures."""

import base64
import dataclasses
import re
import shutil
import subprocess
import types
from html.parser import HTMLParser

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from reports_shared import placeholder_figures, untimed, without_pdf  # noqa: F401  (fixtures)

import qc_control as qc
from qc_control.cli.console import main
from qc_control.report import (
    MARKER,
    ReportError,
    build_blocks,
    comparison,
    figure_specs,
    figures,
    write_report,
)
from qc_control.report.document import fmt, table_cells, to_markdown

# one worker builds the module's report fixtures, built again on each worker otherwise
pytestmark = pytest.mark.xdist_group("test_report")

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def cmp():
    return qc.compare_methods(qc.QuarterCarParams(), np.linspace(0, 3, 301), repeats=1)


@pytest.fixture(scope="module")
def report(cmp, tmp_path_factory):
    return write_report(cmp, tmp_path_factory.mktemp("r") / "report", command="qc-control report")


@pytest.mark.slow
def test_files_and_figure_count(report, cmp):
    pngs = sorted(report.glob("*.png"))
    assert len(pngs) == len(cmp.methods) + 6  # per-method + reference + 5 comparison figures
    for png in pngs:
        assert png.read_bytes()[:8] == PNG and png.stat().st_size > 10_000, png.name
    for name in (
        "report.md",
        "report.html",
        "report.pdf",
        "methods.csv",
        "convergence.csv",
        "cost_to_reach.csv",
        "modes.csv",
        "numerical_modes.csv",
        MARKER,
    ):
        assert (report / name).exists(), name


def test_figure_functions_return_labelled_figures(cmp):
    for make in (
        figures.reference_figure,
        figures.overlay_figure,
        figures.error_figure,
        figures.convergence_figure,
        figures.work_precision_figure,
        figures.stability_figure,
        lambda c: figures.method_figure(c, "rk4"),
    ):
        fig = make(cmp)
        assert isinstance(fig, Figure)
        for ax in fig.axes:
            assert ax.get_xlabel() and ax.lines or ax.collections
        assert all(ax.get_xlabel() for ax in fig.axes)


def test_method_figure_is_the_seeds_style(cmp):
    ax = figures.method_figure(cmp, "euler").axes[0]
    styles = {line.get_label(): (line.get_color(), line.get_linestyle()) for line in ax.lines}
    assert styles["suspension (sprung mass) xs"] == ("r", "-")
    assert styles["wheel xu"] == ("b", "--")
    assert "[mm]" in ax.get_ylabel() and "[s]" in ax.get_xlabel()


@pytest.mark.slow
def test_every_markdown_link_resolves(report):
    text = (report / "report.md").read_text()
    links = re.findall(r"\]\(([^)]+)\)", text)
    assert len(links) >= 9
    for link in links:
        assert (report / link).is_file(), link


class _Images(HTMLParser):
    def __init__(self):
        super().__init__()
        self.srcs, self.tags = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag == "img":
            self.srcs.append(dict(attrs)["src"])


@pytest.mark.slow
def test_html_opens_and_its_images_load(report):
    parser = _Images()
    parser.feed((report / "report.html").read_text(encoding="utf-8"))
    parser.close()
    assert parser.tags[:2] == ["html", "head"] and "table" in parser.tags
    assert parser.srcs
    for src in parser.srcs:  # embedded: the page needs no other file
        assert base64.b64decode(src.split(",", 1)[1])[:8] == PNG, src[:40]


@pytest.mark.slow
def test_sections_in_the_issues_order(report):
    text = (report / "report.md").read_text()
    order = [
        "## Problem card",
        "## All methods against the reference",
        "## Per-method responses",
        "## Accuracy",
        "## Convergence",
        "## Work and precision",
        "## Stability and numerical modes",
        "## Findings",
        "## Reproduce",
    ]
    positions = [text.index(h) for h in order]
    assert positions == sorted(positions)
    assert "qc-control report" in text.split("## Reproduce")[1]
    assert "python-control" in text.split("## Reproduce")[1]


@pytest.mark.slow
def test_findings_are_written_from_the_numbers(report, cmp):
    text = (report / "report.md").read_text().split("## Findings")[1]
    assert f"{cmp.table.loc['euler', 'h_max [s]']:.4g} s" in text
    assert "midpoint and heun give the same trajectory" in text
    for tol in (0.001, 1e-06, 1e-09):
        assert f"Cheapest to reach {tol:.4g} m" in text
    assert f"{cmp.modes.body.zeta:.4g}" in text and "0.25" in text


def test_refuses_a_directory_that_is_not_a_report(cmp, tmp_path):
    (tmp_path / "mine.txt").write_text("keep me")
    with pytest.raises(ReportError, match="not a qc-control report"):
        write_report(cmp, tmp_path)
    assert (tmp_path / "mine.txt").read_text() == "keep me"


@pytest.mark.slow
@pytest.mark.usefixtures("placeholder_figures")  # what is replaced is the directory
def test_replaces_its_own_report(cmp, tmp_path):
    """An earlier report is replaced; a file a user put inside it is not deleted
    (issue 14 item 18): the run is refused naming it, and goes once it is moved."""
    out = tmp_path / "rep"
    # the figures and the Markdown: the files of every format are listed and replaced
    # alike, and the PDF (1.2 CPU-s a write, with blank figures) is not what is
    # checked (tests/test_report_safety.py replaces reports of every format)
    write_report(cmp, out, formats=("md",))
    (out / "notes.png").write_bytes(b"mine")
    with pytest.raises(ReportError, match="it holds 'notes.png', which qc-control did not"):
        write_report(cmp, out, formats=("md",))
    assert (out / "notes.png").read_bytes() == b"mine"
    (out / "notes.png").unlink()
    write_report(cmp, out, formats=("md",))
    assert (out / "report.md").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]


@pytest.mark.slow
@pytest.mark.usefixtures("placeholder_figures")  # the files kept or dropped, not their pixels
def test_a_failure_leaves_no_partial_output(cmp, tmp_path, monkeypatch):
    out = tmp_path / "rep"
    # an earlier report of every format but the PDF (what is kept is its list of
    # files); the run that fails stops at its figures, before any document
    write_report(cmp, out, formats=("md", "html", "csv"))
    before = sorted(p.name for p in out.iterdir())

    def broken():
        raise RuntimeError("disk full")

    drawn = comparison.figure_specs  # the last figure fails as it is drawn
    monkeypatch.setattr(
        comparison,
        "figure_specs",
        lambda c: [
            dataclasses.replace(spec, make=broken) if spec.name == "stability.png" else spec
            for spec in drawn(c)
        ],
    )
    with pytest.raises(RuntimeError, match="disk full"):
        write_report(cmp, out)
    assert sorted(p.name for p in out.iterdir()) == before  # old report intact
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]  # no temp dirs left
    with pytest.raises(RuntimeError):
        write_report(cmp, tmp_path / "fresh")
    assert not (tmp_path / "fresh").exists()


def test_unknown_format(cmp, tmp_path):
    with pytest.raises(ValueError, match="unknown report format 'docx'"):
        write_report(cmp, tmp_path / "r", formats=("md", "docx"))


@pytest.mark.slow
# the command's output and files, not its pictures or PDF (1.2 CPU-s with blank
# figures; tests/test_wheel.py and tests/test_portable.py read the command's PDF)
@pytest.mark.usefixtures("placeholder_figures", "without_pdf")
def test_cli_report_writes_and_prints(tmp_path, capsys):
    out = tmp_path / "rep"
    assert (
        main(["report", "--out", str(out), "--t-end", "1", "--h", "0.01", "--methods", "heun,rk4"])
        == 0
    )
    captured = capsys.readouterr()
    assert "rk4" in captured.out and str(out) in captured.out
    assert "heun" in captured.err  # progress on stderr
    assert len(list(out.glob("method_*.png"))) == 2


@pytest.mark.parametrize(
    "args, words",
    [
        (["--h", "0"], "--h must be a finite number > 0 s, got 0.0"),
        (["--h", "0.03"], "must be a whole number"),
        (["--x0", "0,0,x,0"], "--x0 must be 4 comma-separated numbers"),
        (["--methods", "euler,rk5"], "unknown method 'rk5'"),
        (["--ms", "0"], "ms (sprung mass) must be a finite number > 0 kg"),
    ],
)
def test_cli_report_bad_input(args, words, tmp_path, capsys):
    out = tmp_path / "rep"
    assert main(["report", "--out", str(out), *args]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1
    assert not out.exists()


def test_cli_report_bad_scenario_key(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text("ms = 300.0\n[scenario]\nstep = 0.01\n")
    assert main(["report", "--config", str(cfg), "--out", str(tmp_path / "r")]) == 2
    assert "unknown [scenario] key 'step'" in capsys.readouterr().err


def test_cli_refuses_foreign_directory(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("x")
    assert main(["report", "--out", str(tmp_path)]) == 2
    assert "refusing to overwrite" in capsys.readouterr().err


@pytest.mark.slow
# its text and files, not its pictures, times or PDF (which holds the same text)
@pytest.mark.usefixtures("placeholder_figures", "untimed", "without_pdf")
def test_road_report_has_the_ride_section(tmp_path, capsys):
    out = tmp_path / "road"
    assert (
        main(
            [
                "report",
                "--road",
                "iso8608",
                "--road-class",
                "B",
                "--speed",
                "15",
                "--t-end",
                "4",
                "--methods",
                "heun,rk4",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    text = (out / "report.md").read_text()
    assert "## Road and ride" in text and "class B road at 15 m/s" in text
    assert (out / "transmissibility.png").exists() and (out / "reference.png").exists()
    assert "On this road the exact Wk-weighted" in text
    assert "rms_body_acc_wk" in text
    # 15 m/s: the band needs h <= 1/(2*15*2.83) = 11.8 ms, so the default 10 ms stands
    assert "h = 0.01 s" in capsys.readouterr().err


@pytest.mark.parametrize(
    "args, words",
    [
        (["--road", "gravel"], "--road must be one of step, bump, sine, iso8608"),
        (
            ["--road", "iso8608", "--road-class", "Z"],
            "--road-class must be an ISO 8608 class, one of A, B, C, D, E, F, G, H, got 'Z'",
        ),
        (["--road", "iso8608", "--speed", "-3"], "--speed must be a finite number > 0 m/s"),
        (["--road", "iso8608", "--h", "0.01"], "too coarse for an ISO 8608 road at 20 m/s"),
        (["--road", "step", "--road-class", "B"], "--road-class 'B' does not apply to a step road"),
    ],
)
def test_road_cli_bad_input(args, words, tmp_path, capsys):
    assert main(["report", "--out", str(tmp_path / "r"), *args]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1


# --- issue 13: tables, hand-in formats, numbering, scenario, figures ---------------------


@pytest.mark.parametrize(
    "value, text",
    [
        (30000.0, "30000"),  # not 3e+04
        (29530.0, "29530"),  # not 2.953e+04
        (1502.997, "1503"),
        (301.2, "301.2"),
        (0.25, "0.25"),
        (12345.6, "12346"),
        (9999.95, "10000"),  # .4g would say 1e+04
        (8455572.0, "8455572"),
        (1.917e-4, "0.0001917"),
        (2.276e-07, "2.276e-07"),
        (1e-06, "1e-06"),
        (1e20, "1e+20"),
        (6.829 + 0j, "6.829"),  # a real number held as complex prints as real
        (-0.4622 + 6.8138j, "-0.4622 + 6.814j"),
        (np.float64(30000.0), "30000"),
        (np.int64(4000), "4000"),
        (np.complex128(0.25 + 0j), "0.25"),
        (float("nan"), "–"),
        (float("inf"), "∞"),
        (True, "yes"),
        ("body bounce", "body bounce"),
    ],
)
def test_fmt(value, text):
    assert fmt(value) == text


def test_cells_are_formatted_per_column_not_upcast():
    frame = pd.DataFrame(
        {"eigenvalue": [-0.46 + 6.81j, -9.5 + 23.2j], "fn [Hz]": [1.087, 3.997], "n": [1, 2]},
        index=pd.Index(["body", "wheel"], name="mode"),
    )
    assert frame.values.dtype == complex  # what upcasting did to every cell
    head, body, numeric = table_cells(frame)
    assert head == ["mode", "eigenvalue", "fn [Hz]", "n"]
    assert body[0] == ["body", "-0.46 + 6.81j", "1.087", "1"]
    assert numeric == [False, True, True, True]


@pytest.mark.slow
def test_modes_and_parameters_print_real_numbers_as_real(report, cmp):
    text = (report / "report.md").read_text(encoding="utf-8")
    assert "+ 0j" not in text and "e+04" not in text
    body = next(line for line in text.splitlines() if line.startswith("| body bounce"))
    cells = [c.strip() for c in body.strip("|").split("|")]
    assert cells[2:4] == [f"{cmp.modes.body.wn:.4g}", f"{cmp.modes.body.fn:.4g}"]
    ks = next(line for line in text.splitlines() if line.startswith("| ks "))
    assert "| 30000 |" in ks
    cs = next(line for line in text.splitlines() if line.startswith("| cs "))
    assert "| 1503 |" in cs


class _Cells(HTMLParser):
    """Table cells of an HTML page: [(tag, class, text)] per row."""

    def __init__(self):
        super().__init__()
        self.rows, self._cell = [], None

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self._cell = [tag, dict(attrs).get("class", ""), ""]

    def handle_data(self, data):
        if self._cell is not None:
            self._cell[2] += data

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.rows[-1].append(tuple(self._cell))
            self._cell = None


@pytest.mark.slow
def test_html_aligns_text_left_and_numbers_right(report):
    html = (report / "report.html").read_text(encoding="utf-8")
    assert re.search(r"\.num \{[^}]*text-align: right", html)
    assert re.search(r"\.text \{[^}]*text-align: left", html)
    parser = _Cells()
    parser.feed(html)
    row = next(r for r in parser.rows if r and r[0][2] == "ks")
    assert [c[1] for c in row] == ["text", "text", "num", "text"]  # symbol quantity value unit
    assert row[2][2] == "30000"
    md = (report / "report.md").read_text(encoding="utf-8")
    assert "|:---|:---|---:|:---|" in md  # the same alignment in Markdown


@pytest.mark.slow
def test_html_is_self_contained(report, tmp_path):
    alone = tmp_path / "mailed" / "report.html"
    alone.parent.mkdir()
    alone.write_bytes((report / "report.html").read_bytes())  # without the PNG files
    parser = _Images()
    parser.feed(alone.read_text(encoding="utf-8"))
    assert len(parser.srcs) == len(list(report.glob("*.png")))
    for src in parser.srcs:
        assert src.startswith("data:image/png;base64,"), src[:40]
        assert base64.b64decode(src.split(",", 1)[1])[:8] == PNG
    html = alone.read_text(encoding="utf-8")
    assert not re.search(r'(?:src|href)="(?!data:)', html)  # no link to another file


@pytest.mark.slow
def test_pdf_is_written_without_a_browser(report, cmp):
    data = (report / "report.pdf").read_bytes()
    assert data[:5] == b"%PDF-" and data.rstrip().endswith(b"%%EOF")
    pages = len(re.findall(rb"/Type\s*/Page\b(?!s)", data))
    assert pages >= 5
    assert len(re.findall(rb"/Subtype\s*/Image", data)) >= len(list(report.glob("*.png")))
    if shutil.which("pdftotext"):  # poppler, where installed: the PDF's own text
        text = subprocess.run(
            ["pdftotext", "-layout", str(report / "report.pdf"), "-"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        for words in ("Figure 3: euler", "Figure 6: heun", "Table 1: Vehicle parameters"):
            assert words in text
        assert "30000" in text and "+ 0j" not in text


def _labels(text, kind):
    return [int(n) for n in re.findall(rf"^\*{kind} (\d+):", text, re.M)]


@pytest.mark.slow
def test_figures_and_tables_are_numbered_as_in_the_seed(report):
    text = (report / "report.md").read_text(encoding="utf-8")
    figures = _labels(text, "Figure")
    assert figures == list(range(1, len(figures) + 1))  # in order, no gaps
    seed = re.findall(r"^\*Figure ([3-6]): (\w+):", text, re.M)
    assert seed == [("3", "euler"), ("4", "midpoint"), ("5", "rk4"), ("6", "heun")]
    tables = _labels(text, "Table")
    assert tables == list(range(1, len(tables) + 1)) and len(tables) >= 7


def test_seed_numbers_kept_when_only_some_seed_methods_run():
    cmp = qc.compare_methods(  # the figures' numbers and the words: no wall time is read
        qc.QuarterCarParams(), np.linspace(0, 1, 101), methods=("heun", "rk4"), timing=False
    )
    labels = {spec.name: spec.label for spec in figure_specs(cmp)}
    assert labels["method_rk4.png"] == "Figure 5" and labels["method_heun.png"] == "Figure 6"
    assert labels["reference.png"] == "Figure 1" and labels["error.png"] == "Figure 7"
    text = to_markdown("t", build_blocks(cmp))
    assert "numbers of the seed's methods not run here are left out" in text


def test_numbered_in_order_without_seed_methods():
    ralston = qc.ButcherTableau(
        "ralston", a=[[0, 0], [2 / 3, 0]], b=[1 / 4, 3 / 4], c=[0, 2 / 3], order=2
    )
    cmp = qc.compare_methods(  # the figures' numbers: no wall time is read
        qc.QuarterCarParams(), np.linspace(0, 1, 101), methods=(ralston,), timing=False
    )
    assert [s.number for s in figure_specs(cmp)] == list(range(1, 8))
    assert figure_specs(cmp)[2].label == "Figure 3" and "ralston" in figure_specs(cmp)[2].name


class _Scenario:
    """What the report needs of a qc_control Scenario (CONTRACTS item 4)."""

    def to_toml(self):
        return 'ms = 350.0\n\n[scenario]\nroad = "bump"\nheight = 0.1\nspeed = 15.0\n'

    def command(self):
        return "qc-control report --config rep/scenario.toml --out rep"


@pytest.mark.slow
@pytest.mark.usefixtures("placeholder_figures")
def test_scenario_toml_beside_the_report_and_its_command(cmp, tmp_path):
    with_scenario = dataclasses.replace(cmp, scenario=_Scenario())
    out = write_report(with_scenario, tmp_path / "rep", formats=("md",), command="ignored")
    assert (out / "scenario.toml").read_text(encoding="utf-8") == _Scenario().to_toml()
    reproduce = (out / "report.md").read_text(encoding="utf-8").split("## Reproduce")[1]
    assert _Scenario().command() in reproduce and "ignored" not in reproduce


@pytest.mark.slow
@pytest.mark.usefixtures("placeholder_figures")
def test_reproduce_never_claims_a_command_it_does_not_have(cmp, tmp_path):
    out = write_report(cmp, tmp_path / "rep", formats=("md",))
    reproduce = (out / "report.md").read_text(encoding="utf-8").split("## Reproduce")[1]
    assert "compare_methods(None)" not in reproduce
    assert "no command can redo it" in reproduce
    assert not (out / "scenario.toml").exists()


# --- figures ------------------------------------------------------------------------------


def _drawn(fig):
    FigureCanvasAgg(fig)
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def _all_figures(cmp):
    return {
        "reference": figures.reference_figure(cmp),
        "overlay": figures.overlay_figure(cmp),
        "method": figures.method_figure(cmp, "euler"),
        "error": figures.error_figure(cmp),
        "convergence": figures.convergence_figure(cmp),
        "work_precision": figures.work_precision_figure(cmp),
        "stability": figures.stability_figure(cmp),
    }


@pytest.mark.slow
@pytest.mark.parametrize("h", [0.01, 0.025])  # 0.025 s: Euler unstable, growing to 80 mm
def test_legends_never_cover_data(h):
    cmp = qc.compare_methods(qc.QuarterCarParams(), np.linspace(0, 5, round(5 / h) + 1), repeats=1)
    for name, fig in _all_figures(cmp).items():
        renderer = _drawn(fig)
        legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
        assert legends, name
        for legend in legends:
            box = legend.get_window_extent(renderer)
            for ax in fig.axes:
                assert not box.overlaps(ax.get_window_extent(renderer)), (name, ax.get_title())


@pytest.mark.slow
def test_midpoint_and_heun_are_shown_to_coincide(cmp):
    assert ("midpoint", "heun") in cmp.coincident
    drawn = _all_figures(cmp)  # each figure made once, not all seven for each name
    for name in ("overlay", "error", "convergence", "work_precision"):
        fig = drawn[name]
        lines = {ln.get_label(): ln for ln in fig.axes[0].lines}
        mid, heun = lines["midpoint"], lines["heun"]
        assert mid.get_linestyle() == "-" and heun.get_linestyle() == "--", name
        assert heun.get_zorder() > mid.get_zorder(), name  # drawn over it
        title = fig.legends[0].get_title().get_text()
        assert "midpoint = heun" in title and "1e-12 m" in title, name
    heun_title = figures.method_figure(cmp, "heun").axes[0].get_title()
    assert "same trajectory as midpoint" in heun_title


def test_wall_time_points_are_never_joined_out_of_order(cmp):
    conv = cmp.convergence.copy()
    conv["time"] = conv["time"].to_numpy()[::-1]  # times that fall as work grows
    noisy = dataclasses.replace(cmp, convergence=conv)
    fig = figures.work_precision_figure(noisy)
    work, wall = fig.axes
    for line in work.lines:
        assert np.all(np.diff(line.get_xdata()) > 0), line.get_label()  # joined by RHS evals
    for line in wall.lines:
        x = np.asarray(line.get_xdata())
        joined = line.get_linestyle() not in ("None", "none", "", " ")
        assert not joined or np.all(np.diff(x) >= 0), line.get_label()


def test_slope_labels_stand_off_their_guides(cmp):
    fig = figures.convergence_figure(cmp)
    renderer = _drawn(fig)
    ax = fig.axes[0]
    labels = [t for t in ax.texts if "h^" in t.get_text()]
    guides = [ln for ln in ax.lines if ln.get_linestyle() == ":"]
    assert len(labels) == len(guides) == 3  # h^1, h^2 (midpoint = heun), h^4
    for text in labels:
        box = text.get_window_extent(renderer)
        for guide in guides:
            x, y = (np.asarray(v, dtype=float) for v in guide.get_data())
            xs = np.geomspace(x.min(), x.max(), 400)
            ys = np.exp(np.interp(np.log(xs), np.log(x[::-1]), np.log(y[::-1])))
            points = ax.transData.transform(np.column_stack([xs, ys]))
            inside = (
                (points[:, 0] > box.x0)
                & (points[:, 0] < box.x1)
                & (points[:, 1] > box.y0)
                & (points[:, 1] < box.y1)
            )
            assert not inside.any(), text.get_text()


def test_stability_figure_zooms_on_the_modes(cmp):
    fig = figures.stability_figure(cmp)
    hl = cmp.h * np.array([m.eigenvalue for m in cmp.modes.modes])
    reach = np.max(np.abs(hl))
    zooms = [ax for ax in fig.axes if np.diff(ax.get_xlim())[0] <= 3 * reach]
    assert zooms, "no axes shows the hλ near the origin at their own scale"
    (x0, x1), (y0, y1) = zooms[0].get_xlim(), zooms[0].get_ylim()
    for z in np.concatenate([hl, hl.conj()]):
        assert x0 < z.real < x1 and y0 < z.imag < y1


def test_exact_xs_and_xu_are_told_apart(cmp):
    ax = figures.method_figure(cmp, "rk4").axes[0]
    lines = {ln.get_label(): ln for ln in ax.lines}
    xs, xu = lines["exact xs"], lines["exact xu"]
    assert (xs.get_color(), xs.get_linestyle()) != (xu.get_color(), xu.get_linestyle())
    assert xs.get_color() != xu.get_color() and xs.get_linestyle() != xu.get_linestyle()


def _shuffled(resp, order):
    """The same response with its outputs stored in another order (labels follow)."""
    labels = list(resp.output_labels)
    y = np.asarray(resp.outputs)
    return types.SimpleNamespace(
        time=resp.time,
        outputs=y[[labels.index(n) for n in order]],
        output_labels=list(order),
        method=getattr(resp, "method", None),
    )


def test_figures_look_outputs_up_by_label(cmp):
    order = ["body_acc", "tire_defl", "susp_travel", "xu", "xs"]
    shuffled = dataclasses.replace(
        cmp,
        reference=_shuffled(cmp.reference, order),
        responses={m: _shuffled(r, order) for m, r in cmp.responses.items()},
    )
    xs = cmp.responses["euler"].outputs[list(cmp.responses["euler"].output_labels).index("xs")]
    lines = {ln.get_label(): ln for ln in figures.method_figure(shuffled, "euler").axes[0].lines}
    np.testing.assert_array_equal(lines["suspension (sprung mass) xs"].get_ydata(), xs * 1e3)
    lines = {ln.get_label(): ln for ln in figures.overlay_figure(shuffled).axes[0].lines}
    np.testing.assert_array_equal(lines["euler"].get_ydata(), xs * 1e3)
