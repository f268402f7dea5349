"""The comparison report's content: its blocks, tables and figures, from a MethodComparison.

Presentation only: every number comes from the `MethodComparison`. The
figures are numbered, the seed's four methods as its Figures 3-6, and so
are the tables. When the comparison carries its `Scenario`, the
"Reproduce" section gives the exact command (and `write_report` writes
``scenario.toml`` beside the report). The files themselves are written by
`write_document` (report/writer.py).
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import functools
import platform
import re
from collections.abc import Callable
from importlib.metadata import version
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import pandas as pd

from ..studies import columns as col
from .document import Code, Heading, Image, Paragraph, Table, fmt, sentence
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
from .peers import peer_blocks, peer_figures, peer_tables
from .summary import summary
from .writer import FORMATS, FigureSpec, write_document

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["write_report", "report_title", "build_blocks", "figure_specs", "SEED_FIGURES", "TITLE"]

TITLE = "Quarter car: fixed-step methods against the exact response"
#: The vehicle a title names, by its number of wheels (`VehicleModel.corners`).
_VEHICLES = {1: "Quarter car", 2: "Half car", 4: "Full car"}
#: The seed paper's figure numbers of its four methods (and their order there).
SEED_FIGURES = {"euler": 3, "midpoint": 4, "rk4": 5, "heun": 6}


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
    invariant = (
        "; the circle is the invariant point √(ku/mu), where |body_acc/zr| = ku/ms for every damper"
        if np.isfinite(cmp.transmissibility.invariant_hz)
        else ""
    )
    return [
        _FigureDraft(
            "transmissibility.png",
            "Transmissibility from the road height zr (magnitude and phase)" + invariant,
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
    conv = cmp.convergence.pivot(index=col.H, columns=col.METHOD, values=col.ERROR)
    conv = conv.sort_index(ascending=False)[[t.name for t in cmp.methods]]
    conv.index.name = col.STEP
    finest = 2 ** int(cmp.convergence[col.LEVEL].max())
    return [
        Heading("Convergence"),
        figs["convergence.png"],
        Table(conv, f"Max |{_body(cmp)} error| [m] at h, h/2, …, h/{finest}"),
        Table(
            cmp.table[[col.ORDER, col.OBSERVED_ORDER]],
            "Observed order: least-squares slope of log error against log h over h, h/2 and h/4",
        ),
    ]


_COST_COLUMNS = [col.STAGES, col.STEPS, col.RHS_EVALS, *col.TIME_COLUMNS]


def _cost_table(cmp, work_precision: str) -> Table:
    """What each method's run at h cost: evaluations and wall time, timed with the runs
    of the work-precision figure (labelled ``work_precision``): one measurement."""
    if getattr(cmp, "nonlinear", None) is not None:
        return Table(
            cmp.table[_COST_COLUMNS[:4]],
            f"Cost at h = {fmt(cmp.h)} s: wall time of one run through "
            "qc.input_output_response (depends on the machine; a nonlinear system has "
            f"no LTI engine), the run at h of {work_precision}; steps include those ending "
            "at events",
        )
    return Table(
        cmp.table[[c for c in _COST_COLUMNS if c in cmp.table.columns]],
        f"Cost at h = {fmt(cmp.h)} s (wall times depend on the machine): the step-by-step "
        f"loop, as the seed runs it, timed with every run of {work_precision} in interleaved "
        "rounds (median, lowest and highest, and this process's CPU time); qc_control's LTI "
        "engine, which computes the same trajectory; control's exact response took "
        f"{fmt(cmp.reference_time * 1e3)} ms",
    )


def _reach_table(cmp) -> Table:
    """RHS evaluations to reach each tolerance, and how each was found."""
    reach = cmp.cost.T.copy()
    reach.columns = [f"to {fmt(t)} m" for t in cmp.cost.index]
    kinds = cmp.cost_kind.T
    for column, tol in zip(reach.columns, cmp.cost.index):
        reach[column] = [f"{fmt(v)} ({k[0]})" for v, k in zip(reach[column], kinds[tol])]
    reach.index.name = col.METHOD
    estimates = (
        "; on a nonlinear car every cost is an estimate: there is no exact reference to "
        "run it against"
        if getattr(cmp, "nonlinear", None) is not None
        else ""
    )
    return Table(
        reach,
        f"RHS evaluations to reach each max |{_body(cmp)} error| "
        "(c: confirmed by a run at that count; estimates no run checked: i: interpolated "
        "between refinements, e: extrapolated with e = C·h^p, never beyond h_max; "
        f"m: missed by the runs from its estimate, u: unreached){estimates}",
    )


def _stability_blocks(cmp, figs: dict[str, Image]) -> list:
    table = cmp.table
    columns = [col.H_MAX, col.LIMITED_BY, col.STABLE] + [
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


#: The per-axis columns of the comfort table: (heading, attribute, clause key), the
#: RMS first; a shock's table leads with MTVV and VDV instead (`_axis_columns`).
_RMS_COLUMNS = (("a_w", "a_w", "a_w"), ("crest factor [-]", "crest_factor", "crest_factor"))
_SHOCK_COLUMNS = (
    ("MTVV", "mtvv", "mtvv"),
    ("VDV [unit·s^¼]", "vdv", "vdv"),
    ("MTVV/a_w [-]", "mtvv_ratio", None),
    ("VDV/(a_w T^¼) [-]", "vdv_ratio", None),
)


def _axis_columns(comfort) -> tuple:
    """The MTVV and VDV first where the additional methods are the assessment."""
    if comfort.additional_methods:
        return _SHOCK_COLUMNS + _RMS_COLUMNS
    return _RMS_COLUMNS + _SHOCK_COLUMNS


def _comfort_value(value) -> str:
    """A whole-ride value as text: a zone as its two ends, a missing one as a dash."""
    if value is None:
        return "–"
    if isinstance(value, tuple):
        return "–".join(fmt(v) for v in value)
    return fmt(value)


def _comfort_blocks(cmp) -> list:
    """The exact reference's ride assessed to ISO 2631-1:1997 (``cmp.comfort``): the
    verdict in words, a table per axis with units and the whole-ride numbers, each
    beside its clause. A shock (the additional methods are the assessment) leads
    with MTVV and VDV, in the verdict and in the table."""
    comfort = getattr(cmp, "comfort", None)
    if comfort is None:
        return []
    columns = _axis_columns(comfort)
    axes = pd.DataFrame(
        {
            "weighting": [a.weighting for a in comfort.axes.values()],
            "k": [a.k for a in comfort.axes.values()],
            "unit": [a.unit for a in comfort.axes.values()],
            **{
                head: [getattr(a, name) for a in comfort.axes.values()] for head, name, _ in columns
            },
        },
        index=pd.Index(list(comfort.axes), name="axis"),
    )
    first = next(iter(comfort.axes.values()))
    cited = "; ".join(
        f"{head.split(' [')[0]}: {first.clauses[key]}" for head, _, key in columns if key
    )
    summary = comfort.summary()
    whole = pd.DataFrame(
        {
            "value": [_comfort_value(v) for v in summary["value"]],
            "unit": summary["unit"],
            "clause": summary["clause"],
        },
        index=summary.index,
    )
    lead = (
        "MTVV and VDV first, the additional methods being the assessment (§6.2, §6.3.3): each"
        if comfort.additional_methods
        else "Each"
    )
    return [
        Heading("Ride comfort (ISO 2631-1:1997)"),
        Paragraph(
            "The exact reference's ride, assessed as ISO 2631-1:1997 does: "
            + " ".join(sentence(said) for said in comfort.verdict)
        ),
        Table(
            axes,
            f"{lead} seat axis, weighted by its Annex A curve, in its unit (m/s² for a "
            f"translation, rad/s² for a rotation; VDV in unit·s^¼) ({cited})",
        ),
        Table(whole, "The whole ride, each number beside the clause it follows"),
    ]


def _ride_blocks(cmp, figs: dict[str, Image]) -> list:
    """Under a road input: the comfort assessment (when the study made one), the
    transmissibility and the ride metrics."""
    if cmp.ride is None:  # a nonlinear car: no ride table, yet its assessment is shown
        return _comfort_blocks(cmp)
    blocks: list = [Heading("Road and ride")]
    if "transmissibility.png" in figs:
        blocks.append(figs["transmissibility.png"])
    return (
        _comfort_blocks(cmp)
        + blocks
        + [
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
    )


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
            _cost_table(cmp, figs["work_precision.png"].label),
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
    nm = pd.concat(cmp.numerical_modes, names=[col.METHOD])
    cost = cmp.cost.copy()
    for name in cost.columns:
        cost[f"{name} kind"] = cmp.cost_kind[name]
    return {
        "methods.csv": cmp.table,
        "convergence.csv": cmp.convergence.set_index(col.METHOD),
        "cost_to_reach.csv": cost,
        "modes.csv": cmp.modes.to_frame(),
        "numerical_modes.csv": nm,
        **nonlinear_tables(cmp),
        **peer_tables(cmp),
    }


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
