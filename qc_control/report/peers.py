"""The peers' section of a method comparison: work–precision in evaluations and in time.

Presentation only: every number comes from ``cmp.peers`` (a
`qc_control.studies.peers.WorkPrecision`) and ``cmp.ride_cost`` (a
`qc_control.studies.ride_cost.RideCost`). The figures use
`matplotlib.figure.Figure` directly (no pyplot state, no show()).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..studies import columns as col
from ..studies.scenarios import peak_table
from .document import Heading, Image, Paragraph, Table, fmt

__all__ = ["peer_figures", "peer_blocks", "peer_tables", "peer_findings", "peers_figure"]
__all__ += ["ride_cost_blocks", "ride_cost_findings"]

#: Marker per kind of run: fixed-step methods (a step ladder), peers and adaptive pairs
#: (a tolerance ladder).
_MARKERS = {"method": "o", "solver": "s", "adaptive": "^"}
_LINES = {"method": "-", "solver": "--", "adaptive": ":"}


def peers_figure(cmp, by: str) -> Figure:
    """The largest absolute body error against RHS evaluations (``by='evaluations'``) or wall time
    (``by='time'``), log-log: each method over its steps, each peer over its tolerances."""
    study = cmp.peers
    runs = study.runs
    fig = Figure(figsize=(7.5, 4.8), layout="constrained")
    ax = fig.subplots()
    names = list(dict.fromkeys(runs["name"]))
    # an error 1000x the response itself is a divergence, not a precision: left out
    # (a log axis cannot draw the 1e300 m of an unstable step either)
    diverged = 1e3 * float(np.max(np.abs(np.asarray(cmp.reference.outputs)[_body_row(cmp)])))
    for i, name in enumerate(names):
        rows = runs[runs["name"] == name]
        kind = rows["kind"].iloc[0]
        x = rows[by].astype(float) * (1e3 if by == "time" else 1.0)
        ok = np.isfinite(x) & (rows["error"] > 0) & (rows["error"] < diverged) & (x > 0)
        if not ok.any():
            continue
        ax.loglog(
            x[ok],
            rows["error"][ok],
            ls=_LINES[kind],
            marker=_MARKERS[kind],
            color=f"C{i % 10}",
            ms=4 if kind != "solver" or not rows["default"].any() else 8,
            label=f"{name} ({'h ladder' if kind == 'method' else 'rtol ladder'})",
        )
    ax.axhline(study.tolerance, color="0.4", lw=0.8, ls=":", label=f"{fmt(study.tolerance)} m")
    ax.set_xlabel("RHS evaluations" if by == "evaluations" else "wall time [ms]")
    ax.set_ylabel(f"max |{cmp.model.body_disp} error| [m]")
    ax.grid(True, which="both", alpha=0.3)
    fig.legend(loc="outside right upper", fontsize="small")
    return fig


def peer_figures(cmp) -> list[tuple[str, str, Callable[[], Figure]]]:
    """The section's figures as ``(file, caption, make)``; none without peers."""
    if getattr(cmp, "peers", None) is None:
        return []
    what = (
        "each fixed-step method over h, h/2, ..., h/32 (solid, circles), each peer over "
        "rtol 1e-3 ... 1e-10 (dashed, squares; python-control's default call is the large "
        "square), each adaptive qc pair over the same tolerances (dotted, triangles); "
        "diverged runs are left out"
    )
    return [
        (
            "peers_evaluations.png",
            f"Work and precision in right-hand-side evaluations: {what}",
            lambda: peers_figure(cmp, "evaluations"),
        ),
        (
            "peers_time.png",
            f"Work and precision in wall time (machine-dependent): {what}",
            lambda: peers_figure(cmp, "time"),
        ),
    ]


def _run_words(row: pd.Series) -> str:
    """One run in words: 'rk4 at h = 0.01 s' or 'LSODA at rtol 1e-06'."""
    if row["kind"] == "method":
        return f"{row['name']} at h = {fmt(row['h'])} s"
    if row["default"]:
        return f"python-control's default ({row['name']})"
    return f"{row['name']} at rtol {fmt(row['rtol'])}"


def peer_findings(cmp) -> list[str]:
    """Which run is cheapest to reach the tolerance, in evaluations and in time, and
    what python-control's default call achieves."""
    study = getattr(cmp, "peers", None)
    if study is None:
        return []
    tol, out = study.tolerance, []
    by_evals, by_time = study.cheapest("evaluations"), study.cheapest("time")
    if by_evals is None:
        out.append(f"No run reached {fmt(tol)} m in {cmp.model.body_disp}.")
    else:
        text = (
            f"Cheapest to reach {fmt(tol)} m in {cmp.model.body_disp}: in RHS evaluations, "
            f"{_run_words(by_evals)} ({fmt(by_evals['evaluations'])} evaluations, error "
            f"{fmt(by_evals['error'])} m)"
        )
        if by_time is not None:
            text += (
                f"; in wall time, {_run_words(by_time)} ({fmt(by_time['time'] * 1e3)} ms, "
                f"{fmt(by_time['evaluations'])} evaluations)"
            )
        out.append(text + ".")
    default = study.control_default()
    if default is not None:
        size = float(np.max(np.abs(np.asarray(cmp.reference.outputs)[_body_row(cmp)])))
        missed = math.isfinite(default["error"]) and default["error"] >= 0.99 * size > 0
        out.append(
            f"python-control's default call (control.input_output_response: solve_ivp RK45, "
            f"rtol 1e-3, atol 1e-6) is off by {fmt(default['error'])} m in "
            f"{cmp.model.body_disp} ({fmt(default['evaluations'])} evaluations, "
            f"{fmt(default['time'] * 1e3)} ms)"
            + (
                ": the whole response. Its first step, from rest, is long and steps over the "
                "input, so every state stays 0 (python-control issue #1152)."
                if missed
                else "."
            )
        )
    return out


def _body_row(cmp) -> int:
    return list(cmp.system.output_labels).index(cmp.model.body_disp)


def _best_table(cmp) -> Table:
    study = cmp.peers
    best = study.best_per_name()
    frame = pd.DataFrame(
        {
            "kind": best["kind"],
            col.STEP: best["h"],
            "rtol": best["rtol"],
            "atol": best["atol"],
            col.RHS_EVALS: best["evaluations"],
            col.WALL_TIME: 1e3 * best["time"].astype(float),
            "max |error| [m]": best["error"],
        }
    )
    return Table(
        frame,
        f"The cheapest run of each method and peer that reaches {fmt(study.tolerance)} m "
        f"(fewest evaluations; the names that never do are left out). {study.atol_rule}.",
    )


def _ride_setting(name: str, row: pd.Series) -> str:
    """One ride-cost run in words: 'rk4 at h = 0.0003125 s' or 'BDF at rtol 0.001'."""
    if row["kind"] == "method":
        return f"{name} at h = {fmt(row['h'])} s"
    if row["kind"] == "solver" and name == "control":
        return "python-control's default call"
    label = f"{name} (step-size control)" if row["kind"] == "adaptive" else name
    return f"{label} at rtol {fmt(row['rtol'])}"


def ride_cost_findings(cmp) -> list[str]:
    """The cost of each method and peer to bring the ride metric within the target."""
    cost = getattr(cmp, "ride_cost", None)
    if cost is None:
        return []
    best = cost.cheapest()
    reached = best[best["reached"]].sort_values("evaluations")
    missed = best[~best["reached"]]
    metric = cost.metric.split(" [")[0]
    parts = [
        f"{_ride_setting(name, row)}: {fmt(row['evaluations'])} evaluations, "
        f"{fmt(1e3 * row['time'])} ms ({row['error [%]']:+.2g} %)"
        for name, row in reached.iterrows()
    ]
    out = [
        f"Cost to bring the {metric} within {fmt(cost.target)} % of the exact "
        f"{fmt(cost.exact)} {cost.metric.split(' ')[-1].strip('[]')}, cheapest first: "
        + ("; ".join(parts) if parts else "no run reached it")
        + "."
    ]
    if not missed.empty:
        out.append(
            "Not within it on their ladders: "
            + "; ".join(
                f"{_ride_setting(name, row)} (the last tried"
                + (
                    f", {row['error [%]']:+.2g} %)"
                    if np.isfinite(row["error [%]"])
                    else ", diverged)"
                )
                for name, row in missed.iterrows()
            )
            + "."
        )
    return out


def ride_cost_blocks(cmp) -> list:
    """The ride-cost table and its findings (with ``cmp.ride_cost``)."""
    cost = getattr(cmp, "ride_cost", None)
    if cost is None:
        return []
    best = cost.cheapest().assign(time=lambda b: 1e3 * b["time"].astype(float))
    # the comparison's table's names for the same quantities (studies.columns)
    names = {"h": col.STEP, "evaluations": col.RHS_EVALS, "time": col.WALL_TIME}
    names["runs"] = "runs tried"
    columns = ["kind", "h", "rtol", "atol", "error [%]", "evaluations", "time", "reached", "runs"]
    frame = best[columns].rename(columns=names)
    return [
        Heading("The cost of a ride answer"),
        Table(
            frame,
            f"The cheapest setting of each method and peer whose {cost.metric} is within "
            f"{fmt(cost.target)} % of the exact {fmt(cost.exact)} (control.forced_response on "
            "the same sampled road): each fixed-step method over h, h/2, ... (at most h/64), "
            "each peer and adaptive pair over rtol 1e-3, 1e-4, ..., stopped at the first "
            "setting within the target (atol = rtol · max|x_i| per state; python-control's "
            "default call keeps its own). A linear car's fixed-step time is qc's default "
            "engine's, which gives the same trajectory as stepping.",
        ),
        *(Paragraph(text) for text in ride_cost_findings(cmp)),
    ]


def peer_blocks(cmp, figs: dict[str, Image]) -> list:
    """The section: both figures, the cheapest run per name, the findings; then the
    cost of a ride answer when the comparison holds one."""
    if getattr(cmp, "peers", None) is None:
        return ride_cost_blocks(cmp)
    return [
        Heading("The solvers people use"),
        Paragraph(
            "Each peer is run on the same problem (the same input, linear between samples) "
            "and measured against the same reference as the methods. RHS evaluations are "
            "counted at the right-hand side itself: scipy's nfev, plus n per finite-difference "
            "Jacobian that Radau and BDF build outside it (LSODA's are inside its nfev). "
            "The methods' times are those of qc's default engine (for a linear car the "
            "LTI engine, which gives the same trajectory as stepping), the peers' as they "
            "run; each is the median of its interleaved timing rounds."
        ),
        figs["peers_evaluations.png"],
        figs["peers_time.png"],
        _best_table(cmp),
        Table(
            peak_table(cmp),
            "What each run reports: the peaks of the exact response, of each method at h, "
            "and of each peer at its loosest tolerance (python-control's default call at "
            "its defaults)",
        ),
        *(Paragraph(text) for text in peer_findings(cmp)),
        *ride_cost_blocks(cmp),
    ]


def peer_tables(cmp) -> dict[str, pd.DataFrame]:
    """The CSV files of the section: every run, and every run of the ride cost."""
    study, cost = getattr(cmp, "peers", None), getattr(cmp, "ride_cost", None)
    tables = {} if study is None else {"work_precision.csv": study.runs.set_index("name")}
    if cost is not None:
        tables["ride_cost.csv"] = cost.runs.set_index("name")
    return tables
