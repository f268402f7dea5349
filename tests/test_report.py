"""The written report: files, links, HTML images, atomic writes, section order."""

import re
from html.parser import HTMLParser

import numpy as np
import pytest
from matplotlib.figure import Figure

import qc_control as qc
from qc_control.console import main
from qc_control.report import MARKER, ReportError, figures, write_report

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def cmp():
    return qc.compare_methods(qc.QuarterCarParams(), np.linspace(0, 3, 301), repeats=1)


@pytest.fixture(scope="module")
def report(cmp, tmp_path_factory):
    return write_report(cmp, tmp_path_factory.mktemp("r") / "report", command="qc-control report")


def test_files_and_figure_count(report, cmp):
    pngs = sorted(report.glob("*.png"))
    assert len(pngs) == len(cmp.methods) + 5  # per-method + 5 comparison figures
    for png in pngs:
        assert png.read_bytes()[:8] == PNG and png.stat().st_size > 10_000, png.name
    for name in (
        "report.md",
        "report.html",
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


def test_html_opens_and_its_images_load(report):
    parser = _Images()
    parser.feed((report / "report.html").read_text(encoding="utf-8"))
    parser.close()
    assert parser.tags[:2] == ["html", "head"] and "table" in parser.tags
    assert parser.srcs
    for src in parser.srcs:
        assert (report / src).read_bytes()[:8] == PNG, src


def test_sections_in_the_issues_order(report):
    text = (report / "report.md").read_text()
    order = [
        "## Problem card",
        "## Per-method responses",
        "## All methods against the reference",
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


def test_replaces_its_own_report(cmp, tmp_path):
    out = tmp_path / "rep"
    write_report(cmp, out)
    (out / "stale.png").write_bytes(b"old")
    write_report(cmp, out)
    assert not (out / "stale.png").exists() and (out / "report.md").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]


def test_a_failure_leaves_no_partial_output(cmp, tmp_path, monkeypatch):
    out = tmp_path / "rep"
    write_report(cmp, out)
    before = sorted(p.name for p in out.iterdir())

    def broken(_):
        raise RuntimeError("disk full")

    monkeypatch.setattr("qc_control.report.stability_figure", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        write_report(cmp, out)
    assert sorted(p.name for p in out.iterdir()) == before  # old report intact
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]  # no temp dirs left
    with pytest.raises(RuntimeError):
        write_report(cmp, tmp_path / "fresh")
    assert not (tmp_path / "fresh").exists()


def test_unknown_format(cmp, tmp_path):
    with pytest.raises(ValueError, match="unknown report format 'pdf'"):
        write_report(cmp, tmp_path / "r", formats=("md", "pdf"))


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
        (["--ms", "0"], "ms (sprung mass) must be > 0 kg"),
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
    assert (out / "transmissibility.png").exists() and (out / "road.png").exists()
    assert "rms_body_acc_wk" in text and "On this road the exact Wk-weighted" in text
    # 15 m/s: the band needs h <= 1/(2*15*2.83) = 11.8 ms, so the default 10 ms stands
    assert "h = 0.01 s" in capsys.readouterr().err


@pytest.mark.parametrize(
    "args, words",
    [
        (["--road", "gravel"], "--road must be one of step, bump, sine, iso8608"),
        (["--road", "iso8608", "--road-class", "Z"], "unknown ISO 8608 road class 'Z'"),
        (["--road", "iso8608", "--speed", "-3"], "--speed must be a finite number > 0 m/s"),
        (["--road", "iso8608", "--h", "0.01"], "too coarse for an ISO 8608 road at 20 m/s"),
        (["--road", "step", "--road-class", "B"], "--road-class 'B' does not apply to a step road"),
    ],
)
def test_road_cli_bad_input(args, words, tmp_path, capsys):
    assert main(["report", "--out", str(tmp_path / "r"), *args]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1
