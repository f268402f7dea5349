"""The explorer (``qc-control explore``) in a real browser, and its command.

One server (``qc-control explore --no-browser --port 0``, a subprocess, as a
student starts it) serves every browser test of this module, and one tab on
it is loaded once for them (a load is the costly part): each test finds it as
it opened, the entries of the test before undone (`Page.back_to_load`, which
checks every box against its value at the load), or a new tab where they
cannot be. They share an xdist group. Chromium is Debian's (tests/browser.py),
with every request that leaves 127.0.0.1 aborted and recorded. The page's numbers are checked
against independent references: the Euler limit of the body mode from its
closed form ``h = -2 Re λ / |λ|²``, the modes from `qc_control.modal_analysis`,
and the report that the exported TOML reruns.

What a redraw shows is checked here, never how long it takes: the redraw's
time in the browser is the benchmark's (benchmarks/run.py --only explore,
benchmarks/explore_redraw.py), through the same helpers (tests/browser.py).
"""

import importlib.util
import subprocess
import sys
from pathlib import Path

import browser as chromium
import control
import numpy as np
import pandas as pd
import pytest
from qc_control.road import Bump
from reports_shared import placeholder_figures, untimed, without_pdf  # noqa: F401  (fixtures)

import qc_control as qc
from qc_control.cli.console import main
from qc_control.studies.scenario import Scenario

ROOT = Path(__file__).parent.parent
browser = chromium.browser  # the module-scoped fixture

# found, not imported: every worker collects this module, and importing Panel
# and Bokeh costs each of them seconds that only the explorer's tests need
if importlib.util.find_spec("panel") is None:
    pytest.skip("the explore extra (in the test extra) installs Panel", allow_module_level=True)

#: An HTML table's rows as lists of cell texts.
TABLE = "t => Array.from(t.rows).map(r => Array.from(r.cells).map(c => c.innerText.trim()))"


@pytest.fixture(scope="module")
def server():
    """``qc-control explore --no-browser --port 0``: its address, once it says it."""
    try:
        with chromium.explorer_server() as url:
            yield url
    except RuntimeError as error:
        pytest.fail(str(error))


#: The value of every input and select on the page, in document order (Playwright's
#: CSS engine reaches into the widgets' shadow roots).
VALUES = "els => els.map(e => e.value)"


class Page:
    """One tab on the explorer, with what it blocked, what failed and what it logged."""

    def __init__(self, browser, url: str, width: int = 1280):
        self.blocked: list[str] = []
        self.failed: list[str] = []
        self.errors: list[str] = []
        self.context = browser.new_context(viewport={"width": width, "height": 900})
        self.context.route("**/*", chromium.only_local(self.blocked))
        self.tab = self.context.new_page()
        self.tab.on("requestfailed", lambda r: self.failed.append(f"{r.url}: {r.failure}"))
        self.tab.on("pageerror", lambda e: self.errors.append(str(e)))
        self.tab.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.tab.goto(url, wait_until="networkidle")
        self.tab.wait_for_function(f"({chromium.STAMP})() >= 1", timeout=60_000)
        self.tab.locator(".qc-status p").first.wait_for(timeout=60_000)
        #: what the load itself blocked, failed and logged, for the test of the load
        self.at_load = (tuple(self.blocked), tuple(self.failed), tuple(self.errors))
        self.loaded = self.inputs()  # every box as the page opened
        self.preset = self.tab.locator(".qc-preset select").input_value()
        self.entered: dict[str, str] = {}  # each box entered, and its text before, in order

    def inputs(self) -> list[str]:
        return self.tab.locator("input, select").evaluate_all(VALUES)

    def stamp(self) -> int:
        return self.tab.evaluate(chromium.STAMP)

    def enter(self, css: str, value) -> None:
        """Type ``value`` into the input of the widget ``css``, press Enter, wait
        until the redraw is painted."""
        self.entered.setdefault(css, self.tab.locator(f"{css} input").input_value())
        chromium.entered(self.tab, css, value)

    def back_to_load(self) -> bool:
        """Undo the entries, the last entered box first (through states that the
        test went through itself, none heavier), and a preset that an entry turned
        to custom; True when no error was logged since the test began and every box
        holds its value as the page opened, on which the page's figures and tables
        are redrawn."""
        preset = self.tab.locator(".qc-preset select")
        if preset.input_value() != self.preset:  # it sets the vehicle's five values at once
            self._redrawn(lambda: preset.select_option(self.preset))
        for css, text in reversed(self.entered.items()):
            box = self.tab.locator(f"{css} input")
            if float(box.input_value()) != float(text):
                self._redrawn(lambda: (box.fill(text), box.press("Enter")))
        self.entered.clear()
        return not self.errors and self.inputs() == self.loaded

    def _redrawn(self, change) -> None:
        """Make the ``change`` and wait until the server's redraw has reached the page."""
        before = self.stamp()
        change()
        self.tab.wait_for_function(f"({chromium.STAMP})() > {before}", timeout=60_000)

    def text(self, css: str) -> str:
        """The text of the HTML pane ``css`` (its paragraphs and preformatted blocks)."""
        return "\n".join(self.tab.locator(f"{css} p, {css} pre").all_inner_texts())

    def curve(self, name: str, axis: str = "y") -> np.ndarray:
        js = f"() => Array.from(Bokeh.documents[0].get_model_by_name('{name}').data.{axis})"
        return np.array(self.tab.evaluate(js), dtype=float)

    def table(self, css: str) -> pd.DataFrame:
        """The HTML table of the pane ``css``: its header row, and one row per index."""
        rows = self.tab.locator(f"{css} table").first.evaluate(TABLE)
        # pandas' second header row holds only the index's name: not a row of numbers
        header = rows[0]
        body = [r for r in rows[1:] if len(r) == len(header) and any(r[1:])]
        frame = pd.DataFrame([r[1:] for r in body], index=[r[0] for r in body], columns=header[1:])
        for column in frame.columns:
            try:
                frame[column] = pd.to_numeric(frame[column])
            except ValueError:  # words: the mode that limits, a verdict
                pass
        return frame

    def close(self):
        self.context.close()


@pytest.fixture(scope="module")
def shared(browser, server):
    """The module's tab, loaded once: a load costs about 4 CPU-s (3 of them
    Chromium's, laying out Panel's page), a redraw a tenth of that."""
    kept: dict[str, Page] = {}
    yield kept
    if "page" in kept:
        kept["page"].close()


@pytest.fixture
def page(shared, browser, server):
    """The module's tab as it opened, for each test: the entries of the test
    before undone (`Page.back_to_load`), or a new tab where they cannot be;
    with this test's own records of blocked and failed requests and errors."""
    tab = shared.get("page")
    if tab is not None:
        try:
            as_loaded = tab.back_to_load()
        except Exception:  # a test that failed may leave the tab anywhere
            as_loaded = False
        if not as_loaded:
            tab.close()
            tab = None
    if tab is None:
        tab = shared["page"] = Page(browser, server)
    for records in (tab.blocked, tab.failed, tab.errors):
        records.clear()
    return tab


def verdict(page: Page, method: str) -> str:
    return page.tab.locator(f'.qc-verdicts p[data-method="{method}"]').inner_text()


@pytest.mark.slow
@pytest.mark.xdist_group("explore")
def test_the_page_loads_with_nothing_from_outside_and_no_error(page):
    blocked, failed, errors = page.at_load
    assert blocked == ()  # every script, style and font from 127.0.0.1
    assert failed == ()
    assert errors == ()
    assert "10,000 steps of h = 1 ms" in page.text(".qc-status")


@pytest.mark.slow
@pytest.mark.xdist_group("explore")
def test_euler_crosses_its_limit_at_19_8_ms_and_diverges_while_rk4_holds(page):
    body = qc.modal_analysis(qc.QuarterCarParams()).body.eigenvalue
    h_max = -2 * body.real / abs(body) ** 2  # Euler's |1 + hλ| = 1 on the body mode
    assert 0.0198 < h_max < 0.0199
    page.enter(".qc-h", 19.0)
    assert verdict(page, "euler").startswith("euler: stable")
    assert verdict(page, "rk4").startswith("rk4: stable")
    below = page.curve("response-euler")
    page.enter(".qc-h", 21.0)
    h = 10.0 / round(10.0 / 0.021)  # the page's step: a whole number over 10 s
    assert verdict(page, "euler") == f"euler: beyond its limit by {100 * (h / h_max - 1):.0f} %"
    assert verdict(page, "rk4").startswith("rk4: stable")
    above, rk4 = page.curve("response-euler"), page.curve("response-rk4")
    tail = lambda y: np.max(np.abs(y[-len(y) // 5 :]))  # the last 2 s
    early = lambda y: np.max(np.abs(y[len(y) // 5 : 2 * len(y) // 5]))  # 2-4 s
    assert tail(below) < early(below)  # inside the limit, Euler's response decays
    assert tail(above) > early(above)  # beyond it, it grows
    # RK4 decays as the car does: the body mode's e^(-0.46 t) over the 2.5 s between
    # the windows' peaks is 0.3; a fifth leaves room for where the peaks fall
    assert tail(rk4) < 0.5 * early(rk4)
    assert page.errors == []


@pytest.mark.slow
@pytest.mark.xdist_group("explore")
def test_a_new_body_mass_gives_modal_analysis_modes(page):
    page.enter(".qc-ms", 400.0)
    shown = page.table(".qc-modes")
    exact = qc.modal_analysis(qc.QuarterCarParams(ms=400.0)).to_frame()
    for column in ("fn [Hz]", "zeta [-]", "fd [Hz]"):
        # the page prints 4 significant digits: agreement to half a unit in the 4th
        np.testing.assert_allclose(shown[column], exact[column], rtol=5e-4)
    assert shown.loc["body bounce", "fn [Hz]"] != pytest.approx(1.087, rel=1e-3)  # it moved


@pytest.mark.slow
@pytest.mark.xdist_group("explore")
# its errors and RHS evaluations: no picture, wall time or PDF is read
@pytest.mark.usefixtures("placeholder_figures", "untimed", "without_pdf")
def test_the_exported_toml_reruns_with_the_report_and_its_errors(page, tmp_path):
    page.enter(".qc-t_end", 2.0)
    page.enter(".qc-h", 10.0)
    page.tab.get_by_role("button", name="Export scenario (TOML + command)").click()
    area = page.tab.locator(".qc-toml textarea")
    page.tab.wait_for_function(
        "el => el.value.length > 0", arg=area.element_handle(), timeout=10_000
    )
    # the command is a pane of its own: its update may land a message after the TOML's
    command = page.tab.locator(".qc-command p, .qc-command pre").filter(has_text="--config")
    command.first.wait_for(timeout=10_000)
    toml = area.input_value()
    expected = Scenario(t_end=2.0, h=0.01, x0=(0.0, 0.0, 0.05, 0.0))
    assert toml == expected.to_toml()
    assert "qc-control report --config scenario.toml" in page.text(".qc-command")
    assert expected.command() in page.text(".qc-command")
    config = tmp_path / "scenario.toml"
    config.write_text(toml, encoding="utf-8")
    # the page's command, by the entry point's function in this process: the
    # numbers are what is compared, not a new interpreter (a subprocess cost ~6 s of CPU),
    # nor the report's figures, wall times and PDF (blank, untimed and left out: ~7 CPU-s
    # less; the figures are checked by tests/test_report.py and tests/test_html_browser.py)
    status = main(["report", "--config", str(config), "--out", str(tmp_path / "r"), "-q"])
    assert status == 0
    report = pd.read_csv(tmp_path / "r" / "methods.csv", index_col=0)
    shown = page.table(".qc-handin")
    # the page prints 4 significant digits of the same numbers
    np.testing.assert_allclose(
        shown["max |xs err| [m]"], report.loc[shown.index, "max |xs err| [m]"], rtol=5e-4
    )
    assert (shown["RHS evals"] == report.loc[shown.index, "RHS evals"]).all()


@pytest.mark.slow
@pytest.mark.xdist_group("explore")
def test_the_url_carries_the_state(page, browser):
    page.enter(".qc-h", 21.0)
    page.tab.wait_for_function("() => location.search.includes('h=21')", timeout=10_000)
    again = Page(browser, page.tab.url)
    try:
        assert again.tab.locator(".qc-h input").input_value() == "21"
        assert "beyond its limit" in verdict(again, "euler")
    finally:
        again.close()


@pytest.mark.slow
@pytest.mark.xdist_group("explore")
def test_a_run_of_more_than_a_million_steps_is_refused_with_the_commands_message(page):
    # h first: 100,000 steps over the seed's 10 s (its convergence figure kept), where
    # t_end first would run 200,000 steps and a new convergence figure before the refusal
    page.enter(".qc-h", 0.1)
    page.enter(".qc-t_end", 200.0)
    text = page.text(".qc-status")
    with pytest.raises(ValueError) as refusal:
        Scenario(t_end=200.0, h=1e-4, max_steps=1_000_000)
    assert " ".join(str(refusal.value).split()) in " ".join(text.split())


@pytest.mark.slow
@pytest.mark.xdist_group("explore")
def test_a_redraw_of_the_seed_scenario_shows_the_new_step_and_its_response(page):
    """The seed's 10 s near 1 ms, as the benchmark redraws it (h 0.99 then 1 ms):
    each redraw says its step, and RK4's curve is python-control's exact response
    on the page's grid (a whole number of steps over 10 s) at the samples drawn."""
    assert "10,000 steps of h = 1 ms over 0–10 s" in page.text(".qc-status")
    car = qc.quarter_car()
    xs = list(car.output_labels).index("xs")
    for h_ms, steps in ((0.99, 10_101), (1.0, 10_000)):
        page.enter(".qc-h", h_ms)
        assert f"{steps:,} steps of h = {h_ms:g} ms over 0–10 s" in page.text(".qc-status")
        T = np.linspace(0.0, 10.0, steps + 1)
        exact = control.initial_response(car, T, [0.0, 0.0, 0.05, 0.0]).outputs[xs]
        t, y = page.curve("response-rk4", "x"), page.curve("response-rk4")
        drawn = np.rint(t / (10.0 / steps)).astype(int)  # the sample each point is
        assert drawn[0] == 0 and drawn[-1] == steps
        # the page draws single precision (7 digits of 0.05 m: 4e-9 m); RK4's own
        # error at h ≈ 1 ms is 2e-11 m (benchmarks/RESULTS.md): 1e-8 m holds both
        np.testing.assert_allclose(y, exact[drawn], rtol=0, atol=1e-8)


@pytest.mark.slow  # a fresh interpreter imports the package and Panel: about 2.5 s
def test_the_package_and_the_other_commands_do_not_import_panel():
    code = (
        "import sys, qc_control, qc_control.cli.parser, qc_control.cli.explore; "
        "qc_control.compare_methods; print('panel' in sys.modules)"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.strip() == "False"


def test_without_panel_the_command_says_which_extra_to_install(monkeypatch, capsys):
    # in this process: ``sys.modules['panel'] = None`` makes ``import panel`` raise
    # ImportError whether or not Panel was imported before (as where it is not
    # installed), and the explorer imports it only when the page is made
    monkeypatch.setitem(sys.modules, "panel", None)
    assert main(["explore", "--no-browser"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "qc-control: error: qc-control explore needs Panel, which is not installed: "
        'pip install "qc-control[explore]" (from a clone: pip install -e ".[explore]")'
    ]


def test_a_bad_port_is_one_line_and_status_2(capsys):
    # the entry point's own function, in this process: what is checked is its
    # status and its stderr, not a new interpreter (a subprocess cost ~4 s of CPU)
    assert main(["explore", "--port", "http"]) == 2
    assert capsys.readouterr().err.strip() == (
        "qc-control: error: argument --port: expected a port number 0-65535, got 'http'"
    )


def test_make_explore_installs_the_extra_and_runs_the_command():
    if subprocess.run(["make", "--version"], capture_output=True).returncode != 0:
        pytest.skip("no make on this machine")
    text = subprocess.run(
        ["make", "-n", "-B", "explore"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout
    assert "pip install --quiet -e '.[explore]'" in text
    assert "qc-control explore" in text
    assert "touch .venv/.installed-explore" in text


@pytest.mark.slow
def test_every_road_redraws_and_a_too_coarse_step_gets_the_scenarios_message():
    from qc_control.cli.explore import explorer

    page = explorer().explorer_page
    for road in ("step", "bump", "sine", "iso8608"):
        page.widgets["road"].value = road
        sc = page.scenario
        assert sc.road.kind == road and sc.x0 == (0.0, 0.0, 0.0, 0.0)  # at rest under a road
        assert sc.road.describe() in page.status.object
    page.widgets["road"].value = "bump"
    page.widgets["h"].value = 20.0  # the 1 m bump at 20 m/s lasts 50 ms: 4 steps need 12.5 ms
    with pytest.raises(ValueError) as refusal:
        Scenario(road=Bump(), h=0.02)
    assert html_text(str(refusal.value).split("] ", 1)[1]) in page.status.object
    page.widgets["h"].value = None
    assert "h must be given: the box is empty" in page.status.object


def html_text(text: str) -> str:
    import html

    return html.escape(text)
