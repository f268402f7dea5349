"""The comparison report: Markdown, HTML, PDF, CSV and PNG from a MethodComparison.

Presentation only: every number comes from the `MethodComparison`.
``report.html`` embeds its figures (it can be mailed or uploaded alone) and
``report.pdf`` is drawn with matplotlib (no browser needed); figures and
tables are numbered, the seed's four methods as its Figures 3-6. When the
comparison carries its `Scenario`, ``scenario.toml`` is written beside the
report and the "Reproduce" section gives the exact command.
The report is built in a temporary directory beside the target and moved
into place, so a failure never leaves a half-written report.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime as _dt
import functools
import os
import platform
import re
import shutil
import signal
import tempfile
import threading
import warnings
from collections.abc import Callable
from importlib.metadata import version
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

import filelock
import numpy as np
import pandas as pd

from .document import Code, Heading, Image, Paragraph, Table, fmt, to_html, to_markdown
from .figures import (
    convergence_figure,
    error_figure,
    method_figure,
    overlay_figure,
    reference_figure,
    stability_figure,
    transmissibility_figure,
    work_precision_figure,
)
from .findings import findings
from .nonlinear import nonlinear_blocks, nonlinear_figures, nonlinear_tables, reference_text
from .pdf import to_pdf
from .peers import peer_blocks, peer_figures, peer_tables
from .summary import summary

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "check_target",
    "report_lock",
    "write_report",
    "report_title",
    "write_document",
    "build_blocks",
    "figure_specs",
    "FigureSpec",
    "ReportError",
    "MARKER",
    "FORMATS",
    "SEED_FIGURES",
]

#: A file that marks a directory as a qc-control report (safe to replace).
MARKER = ".qc-control-report"
FORMATS = ("md", "html", "pdf", "csv")
TITLE = "Quarter car: fixed-step methods against the exact response"
#: The vehicle a title names, by its number of wheels (`VehicleModel.corners`).
_VEHICLES = {1: "Quarter car", 2: "Half car", 4: "Full car"}
#: The seed paper's figure numbers of its four methods (and their order there).
SEED_FIGURES = {"euler": 3, "midpoint": 4, "rk4": 5, "heun": 6}
#: Resolution of the PNG figures (the HTML and the PDF embed them).
DPI = 150


class ReportError(ValueError):
    """The report cannot be written where it was asked to go."""


def report_title(cmp) -> str:
    """The report's title: the vehicle it ran, and what the methods are measured against.

    The vehicle is named by its number of wheels (one: quarter, two: half,
    four: full car). A nonlinear run is measured against solve_ivp at tight
    tolerance, not an exact response; a car closed by a clocked controller is
    named as such.

    Parameters
    ----------
    cmp : MethodComparison

    Returns
    -------
    str
        For example ``"Half car: fixed-step methods against the exact response"``.
    """
    model = getattr(cmp, "model", None)
    vehicle = _VEHICLES.get(len(model.corners), "Vehicle") if model is not None else "Quarter car"
    if getattr(cmp, "nonlinear", None) is not None:
        return f"Nonlinear {vehicle.lower()}: fixed-step methods against a solve_ivp reference"
    if getattr(cmp, "sampled_car", None) is not None:
        vehicle += " under a sampled-data controller"
    return f"{vehicle}: fixed-step methods against the exact response"


def _body(cmp) -> str:
    """The label of the body displacement the errors are measured on (``xs``, ``z``)."""
    model = getattr(cmp, "model", None)
    return model.body_disp if model is not None else "xs"


def _versions() -> dict[str, str]:
    """The installed versions behind the numbers, from the distributions' metadata."""
    names = {
        "qc_control": "qc-control",
        "python-control": "control",
        "numpy": "numpy",
        "scipy": "scipy",
        "matplotlib": "matplotlib",
        "pandas": "pandas",
    }
    found = {label: version(dist) for label, dist in names.items()}
    return {
        **found,
        "python": platform.python_version(),
        "machine": f"{platform.system()} {platform.machine()}",
    }


#: The widest line of a printed matrix [characters]: what the PDF's code font
#: (7.5 pt) holds across the page, so that a row is never wrapped mid-way.
_MATRIX_WIDTH = 96


def _matrix(name, M) -> str:
    """``M`` as aligned text, in blocks of whole columns that each fit
    `_MATRIX_WIDTH`: a 14-state A is two blocks of rows, never a row broken
    across lines (where its columns would no longer line up)."""
    M = np.atleast_2d(np.asarray(M, dtype=float))
    scale = float(np.max(np.abs(M))) if M.size else 0.0
    small = np.abs(M) <= 1e-12 * scale  # rounding residue of a zero entry
    cells = [["0" if z else f"{v:.6g}" for v, z in zip(row, zrow)] for row, zrow in zip(M, small)]
    width = max((len(c) for row in cells for c in row), default=1)
    per_block = max(1, (_MATRIX_WIDTH - 2) // (width + 2))
    blocks = []
    for start in range(0, M.shape[1], per_block):
        stop = min(start + per_block, M.shape[1])
        head = f"{name} =" if per_block >= M.shape[1] else f"{name}, columns {start + 1}–{stop} ="
        rows = ["  ".join(c.rjust(width) for c in row[start:stop]) for row in cells]
        blocks.append(head + "\n" + "\n".join("  " + r for r in rows))
    return "\n\n".join(blocks)


def _slug(name: str) -> str:
    """A method name as a safe file-name part ('3/8-rule' -> '3-8-rule')."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", name).strip("-.") or "method"


@dataclasses.dataclass(frozen=True)
class FigureSpec:
    """One figure of the report: its file, number, caption and how to draw it."""

    name: str
    label: str  # "Figure 3"
    caption: str
    make: Callable[[], Figure]

    @property
    def number(self) -> int:
        return int(self.label.split()[-1])


def _method_order(cmp) -> list[str]:
    """The seed's four in its order (Euler, Midpoint, RK4, Heun), then the others."""
    names = [tab.name for tab in cmp.methods]
    seed = [m for m in SEED_FIGURES if m in names]
    return seed + [m for m in names if m not in SEED_FIGURES]


class _FigureDraft(NamedTuple):
    """A figure before it is numbered; the seed's methods keep the seed's numbers."""

    name: str
    caption: str
    make: Callable[[], Figure]
    seed_number: int | None = None


def _reference_caption(cmp) -> str:
    if getattr(cmp, "nonlinear", None) is not None:
        what = (
            "The reference the methods are measured against: solve_ivp (DOP853, rtol "
            "1e-12, restarted at every event)"
        )
    elif getattr(cmp, "sampled_car", None) is not None:
        what = (
            "The exact response the methods are measured against: the car's matrix "
            "exponential between clock ticks, the controller updated at each tick"
        )
    else:
        what = (
            "The exact response the methods are measured against: python-control's "
            "matrix exponential"
        )
    under = getattr(cmp, "input_description", "")
    return what + (f", under {under}" if under else "")


def _response_figures(cmp) -> list[_FigureDraft]:
    """The reference, all methods over it, and each method alone."""
    drafts = [
        _FigureDraft("reference.png", _reference_caption(cmp), lambda: reference_figure(cmp)),
        _FigureDraft(
            "overlay.png",
            "All methods' body displacement over the "
            + ("exact response" if getattr(cmp, "nonlinear", None) is None else "reference"),
            lambda: overlay_figure(cmp),
        ),
    ]
    for name in _method_order(cmp):
        drafts.append(
            _FigureDraft(
                f"method_{_slug(name)}.png",
                f"{name}: displacement of the suspension (sprung mass, red solid) and of "
                f"the wheel (blue dashed) against the exact ones (dark grey, light "
                f"grey, dashed), h = {cmp.h:g} s",
                functools.partial(method_figure, cmp, name),
                SEED_FIGURES.get(name),
            )
        )
    return drafts


def _analysis_figures(cmp) -> list[_FigureDraft]:
    """Error in time, convergence, work against precision, stability regions."""
    return [
        _FigureDraft(
            "error.png",
            "Body-displacement error against time (log axis)",
            lambda: error_figure(cmp),
        ),
        _FigureDraft(
            "convergence.png",
            f"Max |{_body(cmp)} error| against h, with slope guides of each order",
            lambda: convergence_figure(cmp),
        ),
        _FigureDraft(
            "work_precision.png",
            f"Max |{_body(cmp)} error| against RHS evaluations (machine-independent) and against "
            "wall time (measured on this machine)",
            lambda: work_precision_figure(cmp),
        ),
        _FigureDraft(
            "stability.png",
            "Stability regions |R(z)| ≤ 1 with hλ of each mode, and a zoom on hλ",
            lambda: stability_figure(cmp),
        ),
    ]


def _ride_figures(cmp) -> list[_FigureDraft]:
    """The transmissibility, when the comparison ran on a road and has one."""
    if cmp.ride is None or getattr(cmp, "transmissibility", None) is None:
        return []
    return [
        _FigureDraft(
            "transmissibility.png",
            "Transmissibility from the road height zr (magnitude and phase); the "
            "circle is the invariant point √(ku/mu), where |body_acc/zr| = ku/ms for "
            "every damper",
            lambda: transmissibility_figure(cmp),
        )
    ]


def _numbered_figures(drafts: list[_FigureDraft]) -> list[FigureSpec]:
    """Number the figures in order; with a seed method present, 3-6 are the seed's."""
    seed_present = any(d.seed_number is not None for d in drafts)
    specs, count = [], 0
    for draft in drafts:
        if draft.seed_number is None:
            count += 1
            if seed_present and 3 <= count <= 6:
                count = 7
            number = count
        else:
            number = draft.seed_number
        specs.append(FigureSpec(draft.name, f"Figure {number}", draft.caption, draft.make))
    return specs


def figure_specs(cmp) -> list[FigureSpec]:
    """Every figure, in report order, numbered.

    Figure 1 is the exact response, Figure 2 all methods over it. When the
    comparison runs any of the seed's four methods, they keep the seed's
    numbers (Euler 3, Midpoint 4, RK4 5, Heun 6) and the other figures
    count on from 7; otherwise figures are numbered in order.
    """
    return _numbered_figures(
        [
            *_response_figures(cmp),
            *_analysis_figures(cmp),
            *(_FigureDraft(*figure) for figure in nonlinear_figures(cmp)),
            *(_FigureDraft(*figure) for figure in peer_figures(cmp)),
            *_ride_figures(cmp),
        ]
    )


def _scenario_text(cmp) -> str:
    t0, t1 = cmp.T[0], cmp.T[-1]
    x0 = ", ".join(fmt(v) for v in cmp.X0)
    described = getattr(cmp, "input_description", "")
    if cmp.U is None:
        # a road the model evaluates as a function of time is an input all the
        # same, though the system has no input signal: name it
        kind = f"response to {described}" if described else "free response (no input)"
    else:
        kind = f"forced response to the input(s) {', '.join(cmp.system.input_labels)}" + (
            f" ({described})" if described else ""
        )
    model = getattr(cmp, "model", None)
    # the states' units in order of first use: "m/s and m" on a quarter car
    units = (
        list(dict.fromkeys(model.unit(s) for s in cmp.system.state_labels))
        if model is not None
        else ["m/s", "m"]
    )
    unit_text = " and ".join([", ".join(units[:-1]), units[-1]] if len(units) > 1 else units)
    return (
        f"Scenario: {kind}, from X0 = [{x0}] (states {', '.join(cmp.system.state_labels)}; "
        f"{unit_text}), over {fmt(t0)}–{fmt(t1)} s with h = {fmt(cmp.h)} s "
        f"({cmp.table['steps'].iloc[0]} steps). SI units throughout."
    )


def _reproduce(cmp, command: str | None) -> list:
    scenario = getattr(cmp, "scenario", None)
    if scenario is not None:
        return [
            Paragraph(
                "The exact command that redoes this run; scenario.toml, beside this "
                "report, holds its whole scenario (vehicle, initial state, road, time "
                "span, step and methods):"
            ),
            Code(scenario.command(), wrap=True),
        ]
    if command:
        return [Code(command, wrap=True)]
    return [
        Paragraph(
            "This report was written from Python without a Scenario, so no command can "
            "redo it: rerun the code that called compare_methods. (A comparison built "
            "from a qc_control Scenario, as the qc-control command builds it, gives the "
            "exact command here and its scenario.toml beside the report.)"
        )
    ]


def _numbered(blocks: list) -> list:
    """Tables numbered in the order they appear."""
    out, count = [], 0
    for b in blocks:
        if isinstance(b, Table):
            count += 1
            b = dataclasses.replace(b, label=f"Table {count}")
        out.append(b)
    return out


def _system_blocks(cmp) -> list:
    """The system's A and B (a nonlinear one's linearisation) and its modes."""
    study = getattr(cmp, "nonlinear", None)
    blocks: list = []
    if study is not None:
        blocks.append(
            Paragraph(
                f"The system is nonlinear ({cmp.system.name}); A and B below are its "
                "linearisation at the static equilibrium (x = 0, u = 0)."
            )
        )
    car = getattr(cmp, "sampled_car", None)
    if car is not None:
        blocks.append(
            Paragraph(
                f"The system is a sampled-data loop ({cmp.system.name}): the controller "
                f"acts every {fmt(cmp.system.period)} s and holds its move. A and B below "
                "are the car's between the ticks, whose modes set the step limits."
            )
        )
    linear = (car if car is not None else cmp.system) if study is None else study.linearization
    B = np.asarray(linear.B)
    # a free response has no input: no "B = []"
    text = _matrix("A", linear.A) + ("\n\n" + _matrix("B", B) if B.size else "")
    blocks.append(Code(text))
    blocks.append(
        Table(
            cmp.modes.to_frame(),
            f"Modes from the eigenvalues of {'A' if study is None else 'the linearised A'} "
            "(eigenvalue, natural and damped frequency, modal and nominal damping, mode shape)",
        )
    )
    if cmp.modes.note:
        blocks.append(Paragraph(cmp.modes.note))
    return blocks


def _exact_reference_text(cmp) -> str:
    """The reference paragraph of a linear comparison."""
    return (
        f"Reference: {cmp.reference_name}, the exact solution for an input linear "
        f"between samples (matrix exponential). Its own accuracy: it differs from "
        f"{cmp.reference_description} by at most {fmt(cmp.reference_error)} m. "
        f"It took {fmt(cmp.reference_time * 1e3)} ms."
    )


def _problem_card(cmp, figs: dict[str, Image]) -> list:
    """The run, the vehicle, its system and modes, and the reference."""
    blocks: list = [Paragraph(_scenario_text(cmp)), Heading("Problem card")]
    if cmp.params is not None:
        frame = pd.DataFrame(cmp.params.table(), columns=["symbol", "quantity", "value", "unit"])
        blocks.append(Table(frame.set_index("symbol"), "Vehicle parameters"))
    blocks += _system_blocks(cmp)
    linear = getattr(cmp, "nonlinear", None) is None
    blocks.append(Paragraph(_exact_reference_text(cmp) if linear else reference_text(cmp)))
    blocks.append(figs["reference.png"])
    return blocks


def _response_blocks(cmp, figs: dict[str, Image]) -> list:
    """All methods over the reference, then each method's own figure."""
    blocks: list = [Heading("All methods against the reference"), figs["overlay.png"]]
    blocks.append(Heading("Per-method responses"))
    names = [tab.name for tab in cmp.methods]
    seed = [m for m in SEED_FIGURES if m in names]
    if seed:
        every = len(seed) == len(SEED_FIGURES)
        blocks.append(
            Paragraph(
                "Figures 3–6 keep the seed paper's numbers: Euler, Midpoint, RK4, Heun"
                + (
                    "."
                    if every
                    else "; the numbers of the seed's methods not run here are left out."
                )
            )
        )
    return blocks + [figs[f"method_{_slug(name)}.png"] for name in _method_order(cmp)]


def _by_measure(frame: pd.DataFrame, name: str) -> pd.DataFrame:
    """One row per measure and one column per method, when there are more measures
    than methods: a half car's 25 error measures then read down the page instead
    of running off it (or off a 1280 px screen), four or five columns wide."""
    return frame.T.rename_axis(name) if frame.shape[1] > frame.shape[0] else frame


def _accuracy_blocks(cmp, figs: dict[str, Image]) -> list:
    table = cmp.table
    accuracy = [c for c in table.columns if "err" in c and "freq" not in c and "zeta" not in c]
    return [
        Heading("Accuracy"),
        figs["error.png"],
        Table(
            _by_measure(table[accuracy], "error"),
            "Errors against the reference over the whole run",
        ),
    ]


def _convergence_blocks(cmp, figs: dict[str, Image]) -> list:
    """The error at each refinement of h, and the order observed from it."""
    conv = cmp.convergence.pivot(index="h", columns="method", values="error")
    conv = conv.sort_index(ascending=False)[[t.name for t in cmp.methods]]
    conv.index.name = "h [s]"
    finest = 2 ** int(cmp.convergence["level"].max())
    return [
        Heading("Convergence"),
        figs["convergence.png"],
        Table(conv, f"Max |{_body(cmp)} error| [m] at h, h/2, …, h/{finest}"),
        Table(
            cmp.table[["order", "observed order"]],
            "Observed order: least-squares slope of log error against log h over h, h/2 and h/4",
        ),
    ]


_COST_COLUMNS = [
    "stages",
    "steps",
    "RHS evals",
    "wall time [ms]",
    "LTI engine [ms]",
    "time / control",
]


def _cost_table(cmp) -> Table:
    """What each method's run at h cost: evaluations and wall time."""
    if getattr(cmp, "nonlinear", None) is not None:
        return Table(
            cmp.table[_COST_COLUMNS[:4]],
            f"Cost at h = {fmt(cmp.h)} s: wall time of one run through "
            "qc.input_output_response (depends on the machine; a nonlinear system has "
            "no LTI engine); steps include those ending at events",
        )
    return Table(
        cmp.table[_COST_COLUMNS],
        f"Cost at h = {fmt(cmp.h)} s (best of several runs; wall times depend on the "
        "machine): wall time of the step-by-step loop, as the seed runs it, and of "
        "qc_control's LTI engine, which computes the same trajectory; control's exact "
        f"response took {fmt(cmp.reference_time * 1e3)} ms",
    )


def _reach_table(cmp) -> Table:
    """RHS evaluations to reach each tolerance, and how each was found."""
    reach = cmp.cost.T.copy()
    reach.columns = [f"to {fmt(t)} m" for t in cmp.cost.index]
    kinds = cmp.cost_kind.T
    for col, tol in zip(reach.columns, cmp.cost.index):
        reach[col] = [f"{fmt(v)} ({k[0]})" for v, k in zip(reach[col], kinds[tol])]
    reach.index.name = "method"
    return Table(
        reach,
        f"RHS evaluations to reach each max |{_body(cmp)} error| "
        "(i: interpolated between refinements, e: extrapolated with "
        "e = C·h^p, never beyond h_max)",
    )


def _stability_blocks(cmp, figs: dict[str, Image]) -> list:
    table = cmp.table
    columns = ["h_max [s]", "limited by", "stable"] + [
        c for c in table.columns if "freq err" in c or "zeta err" in c
    ]
    return [
        Heading("Stability and numerical modes"),
        figs["stability.png"],
        Table(
            _by_measure(table[columns], "measure"),
            f"Step limit and each mode as the method sees it at h = {fmt(cmp.h)} s "
            "(frequency error of the damped frequency; zeta err = ζ_h − ζ)",
        ),
    ]


def _ride_blocks(cmp, figs: dict[str, Image]) -> list:
    """Under a road input: the transmissibility and the ride metrics."""
    if cmp.ride is None:
        return []
    blocks: list = [Heading("Road and ride")]
    if "transmissibility.png" in figs:
        blocks.append(figs["transmissibility.png"])
    return blocks + [
        Table(
            _by_measure(cmp.ride, "metric"),
            "Ride metrics of each method and of the exact reference "
            "(ISO 2631-1 Wk weighting; tire load over the static "
            "wheel load (ms + mu)·g)",
        ),
        Table(
            _by_measure(cmp.ride_error, "metric"),
            "Each method's ride metrics against the reference [%]",
        ),
    ]


def _reproduce_blocks(cmp, command: str | None) -> list:
    """The versions behind the numbers, and how to redo the run."""
    versions = ", ".join(f"{k} {v}" for k, v in _versions().items())
    written = _dt.datetime.now().isoformat(timespec="seconds")
    return [
        Heading("Reproduce"),
        Paragraph(f"Versions: {versions}. Written {written}."),
        *_reproduce(cmp, command),
    ]


def build_blocks(cmp, command: str | None = None) -> list:
    """The report as blocks, in the order: problem card, figures, findings, footer."""
    figs = {spec.name: Image(spec.name, spec.caption, spec.label) for spec in figure_specs(cmp)}
    return _numbered(
        [
            Heading("Summary"),
            *(Paragraph(text) for text in summary(cmp)),
            *_problem_card(cmp, figs),
            *_response_blocks(cmp, figs),
            *_accuracy_blocks(cmp, figs),
            *_convergence_blocks(cmp, figs),
            Heading("Work and precision"),
            figs["work_precision.png"],
            _cost_table(cmp),
            _reach_table(cmp),
            *_stability_blocks(cmp, figs),
            *_ride_blocks(cmp, figs),
            *nonlinear_blocks(cmp, figs),
            *peer_blocks(cmp, figs),
            Heading("Findings"),
            *(Paragraph(text) for text in findings(cmp)),
            *_reproduce_blocks(cmp, command),
        ]
    )


def _csv_tables(cmp) -> dict[str, pd.DataFrame]:
    nm = pd.concat(cmp.numerical_modes, names=["method"])
    cost = cmp.cost.copy()
    for name in cost.columns:
        cost[f"{name} kind"] = cmp.cost_kind[name]
    return {
        "methods.csv": cmp.table,
        "convergence.csv": cmp.convergence.set_index("method"),
        "cost_to_reach.csv": cost,
        "modes.csv": cmp.modes.to_frame(),
        "numerical_modes.csv": nm,
        **nonlinear_tables(cmp),
        **peer_tables(cmp),
    }


def _manifest(out: Path) -> set[str] | None:
    """The files an earlier report says it wrote (None for a report without a list)."""
    lines = (out / MARKER).read_text(encoding="utf-8", errors="replace").splitlines()
    if "files:" not in lines:
        return None
    return set(lines[lines.index("files:") + 1 :])


def check_target(out_dir, overwrite: bool = True) -> Path:
    """Where a report may go: a new or empty directory, or an earlier report.

    An earlier report is replaced only if it holds nothing but what
    qc-control wrote there (its `MARKER` lists the files): a file a user put
    inside it is never deleted. Raises `ReportError` naming the path, or the
    first foreign file.
    """
    out = Path(out_dir).resolve()
    if out.exists():
        if not out.is_dir():
            raise ReportError(f"{str(out)!r} exists and is not a directory")
        if any(out.iterdir()):
            if not (out / MARKER).exists():
                raise ReportError(
                    f"refusing to overwrite {str(out)!r}: it is not a qc-control "
                    f"report (no {MARKER} file); choose another --out"
                )
            if not overwrite:
                raise ReportError(f"{str(out)!r} already holds a report")
            listed = _manifest(out)
            if listed is not None:
                foreign = sorted(p.name for p in out.iterdir() if p.name not in listed | {MARKER})
                if foreign:
                    raise ReportError(
                        f"refusing to replace the report in {str(out)!r}: it holds "
                        f"{foreign[0]!r}, which qc-control did not write; move it out first"
                    )
    return out


def _lock_file(out: Path) -> Path:
    """The lock file beside the report directory ``out`` (see `write_document`)."""
    return out.parent / f".{out.name}.lock"


@contextlib.contextmanager
def _exclusive(out: Path):
    """Take the report's lock (`_lock_file`) for `report_lock`, or stop with one line.

    A second run into the same place stops with one clear line instead of
    racing. The lock file is removed while the lock is still held, so nothing
    is left behind: a run that opened the old file before the removal is
    refused its lock (filelock checks that the file it locked still has a
    name), and one that comes later locks a new file. Where a file cannot be
    removed while open (Windows), filelock removes it on release. A killed
    run leaves the file, unlocked: the next run takes it and removes it.
    """
    lock = filelock.FileLock(_lock_file(out), timeout=0)
    try:
        lock.acquire()
    except filelock.Timeout:
        raise ReportError(
            f"another qc-control run is writing a report into {str(out)!r}; wait for it "
            "to finish, or choose another --out"
        ) from None
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            _lock_file(out).unlink()
        lock.release()


#: The report locks this process holds, as (report directory, thread): a command takes
#: its report's lock before computing (`report_lock`), and the writer then runs under it.
_HELD: set[tuple[Path, int]] = set()


@contextlib.contextmanager
def report_lock(out_dir):
    """Hold the lock of the report ``out_dir`` (`_lock_file`, beside it) for a whole run.

    A command takes it before computing, so that a second run into the same
    report stops at once instead of after all its work; `write_document`
    under it does not lock again. Within one thread it is re-entrant; another
    thread or process is refused. The directory that will hold the report is
    created if missing (the lock file lives there).

    Yields
    ------
    Path
        The report directory, resolved.

    Raises
    ------
    ReportError
        If another run holds the lock.
    """
    out = Path(out_dir).resolve()
    key = (out, threading.get_ident())
    if key in _HELD:
        yield out
        return
    out.parent.mkdir(parents=True, exist_ok=True)
    with _exclusive(out), _interrupts_seen():
        _HELD.add(key)
        try:
            yield out
        finally:
            _HELD.discard(key)


#: Ctrl-C presses seen while a report lock is held (in the main thread).
_INTERRUPTED = threading.Event()


@contextlib.contextmanager
def _interrupts_seen():
    """Remember every Ctrl-C while a report is made, as well as raising it.

    A KeyboardInterrupt raised inside a weakref callback or a ``__del__``
    (matplotlib's figure teardown has both) is printed as "Exception ignored"
    and lost, and the run would go on to replace the earlier report. The
    flag it leaves makes `_write` stop before the swap. Only the main thread
    receives signals; Python's own handler still raises the interrupt.
    """
    if threading.current_thread() is not threading.main_thread():
        yield  # only the main thread receives signals: nothing to keep
        return
    # a flag an earlier report's Ctrl-C left belongs to that report, not this one
    _INTERRUPTED.clear()
    previous = signal.getsignal(signal.SIGINT)
    if not callable(previous):
        yield  # Ctrl-C ignored or left to the OS: nothing to keep
        return

    def remember(signum, frame):
        _INTERRUPTED.set()
        previous(signum, frame)

    signal.signal(signal.SIGINT, remember)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _recover(out: Path) -> None:
    """Finish what an interrupted run left beside ``out`` (the caller holds the lock).

    Its working copies (``.NAME.partial-*``) are removed. A report moved aside
    for a swap (``.NAME.old-*/NAME``) is put back when ``out`` is missing,
    and removed when the swap had completed: it is never lost.
    """
    for partial in out.parent.glob(f".{out.name}.partial-*"):
        shutil.rmtree(partial, ignore_errors=True)
    for old in sorted(out.parent.glob(f".{out.name}.old-*")):
        if (old / out.name).is_dir() and not out.exists():
            (old / out.name).rename(out)
        shutil.rmtree(old, ignore_errors=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_report(
    cmp, out_dir, formats=FORMATS, *, command: str | None = None, overwrite: bool = True
) -> Path:
    """Write the comparison report into ``out_dir``, atomically.

    Parameters
    ----------
    cmp : MethodComparison
    out_dir : path
        Created if missing. An existing directory is replaced only if it is
        empty or an earlier qc-control report (it holds `MARKER`).
    formats : iterable of {'md', 'html', 'pdf', 'csv'}
        PNG figures are always written; Markdown links to them, while
        ``report.html`` embeds them (self-contained) and ``report.pdf``
        (A4, drawn with matplotlib) holds them.
    command : str, optional
        The command that reproduces the report, printed in its footer when
        ``cmp`` carries no ``scenario`` (whose ``command()`` wins, and whose
        ``to_toml()`` is written to ``scenario.toml`` beside the report).
    overwrite : bool, default True
        Replace an earlier report in ``out_dir``.

    Returns
    -------
    Path
        The report directory.

    Raises
    ------
    ReportError
        If ``out_dir`` is a file or a directory that is not a report.
    ValueError
        For an unknown format.
    """
    scenario = getattr(cmp, "scenario", None)
    return write_document(
        out_dir,
        report_title(cmp),
        lambda: build_blocks(cmp, command),
        figure_specs(cmp),
        lambda: _csv_tables(cmp),
        formats,
        extra={"scenario.toml": scenario.to_toml()} if scenario is not None else None,
        command=command,
        overwrite=overwrite,
    )


def write_document(
    out_dir,
    title: str,
    blocks: Callable[[], list],
    figures=(),
    tables: Callable[[], dict[str, pd.DataFrame]] | None = None,
    formats=FORMATS,
    *,
    extra: dict[str, str] | None = None,
    command: str | None = None,
    overwrite: bool = True,
) -> Path:
    """Write a report's files into ``out_dir``, atomically (what `write_report` does).

    ``figures`` are `FigureSpec` (drawn first, as PNG), ``blocks()`` the
    document (Markdown, HTML, PDF per ``formats``), ``tables()`` the CSV
    files by name, ``extra`` more text files by name. The directory is built
    beside the target and swapped in under a lock; an existing directory is
    replaced only if it is an earlier report holding nothing foreign
    (`check_target`). The lock is the caller's when it holds `report_lock`.
    """
    formats = tuple(formats)
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise ValueError(
            f"unknown report format {bad[0] if bad else '(none)'!r}; "
            f"choose from {', '.join(FORMATS)}"
        )
    out = check_target(out_dir, overwrite)
    with report_lock(out):
        _recover(out)
        check_target(out, overwrite)  # again: recovery may have put a report back
        return _write(out, title, blocks, figures, tables, formats, extra, command)


def _write(out: Path, title, blocks_of, figures, tables_of, formats, extra, command) -> Path:
    """Build the report in a working copy and swap it in (see `write_document`)."""
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.partial-", dir=out.parent))
    os.chmod(tmp, 0o777 & ~_umask())  # a directory as the user's umask makes it, not 0700
    moved: Path | None = None
    try:
        for spec in figures:
            with warnings.catch_warnings():
                # errors of exactly 0 (a car at rest, an exact method) have no place
                # on a log axis: the curve is left out, which is what the figure means
                warnings.filterwarnings("ignore", "Data has no positive values", UserWarning)
                spec.make().savefig(tmp / spec.name, dpi=DPI)
        blocks = blocks_of()
        if "md" in formats:
            (tmp / "report.md").write_text(to_markdown(title, blocks), encoding="utf-8")
        if "html" in formats:
            (tmp / "report.html").write_text(to_html(title, blocks, tmp), encoding="utf-8")
        if "pdf" in formats:
            to_pdf(title, blocks, tmp, tmp / "report.pdf")
        if "csv" in formats and tables_of is not None:
            for name, frame in tables_of().items():
                frame.to_csv(tmp / name)
        for name, text in (extra or {}).items():
            (tmp / name).write_text(text, encoding="utf-8")
        written = sorted(p.name for p in tmp.iterdir())
        (tmp / MARKER).write_text(
            f"qc-control report\n{command or ''}\nfiles:\n" + "\n".join(written) + "\n",
            encoding="utf-8",
        )
        if _INTERRUPTED.is_set():  # a Ctrl-C that something swallowed: keep the earlier report
            raise KeyboardInterrupt
        if out.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old-", dir=out.parent))
            out.rename(old / out.name)
            moved = old
            tmp.rename(out)
            moved = None
            shutil.rmtree(old, ignore_errors=True)
        else:
            tmp.rename(out)
    except BaseException:
        # the earlier report goes back where it was; the unfinished one is dropped
        if moved is not None and not out.exists():
            (moved / out.name).rename(out)
            shutil.rmtree(moved, ignore_errors=True)
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out
