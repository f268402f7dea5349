"""The controller comparison report (``qc-control control-report``).

Presentation only: every number comes from the
`qc_control.studies.control_study.ControlComparison`. One table (bump and road
metrics per design) and two transmissibility figures, one per signal (body
acceleration and tire deflection against frequency), every linear design
on each.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from typing import TYPE_CHECKING

import pandas as pd

from ..models.controllers import HINF_AVAILABLE
from ..numerics.messages import install_hint
from .document import Code, Heading, Image, Paragraph, Table
from .writer import FORMATS, FigureSpec, write_document

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["write_control_report", "control_blocks", "control_figures", "TITLE"]

TITLE = "Quarter car: passive, semi-active and active suspensions compared"

_SIGNALS = {
    "body_acc": ("body acceleration", "|body_acc / zr| [(m/s²)/m]"),
    "tire_defl": ("tire deflection", "|tire_defl / zr| [m/m]"),
}


def transmissibility_chart(cmp, signal: str) -> Figure:
    """One signal's |H(f)| from the road height, every linear design on one chart."""
    from matplotlib.figure import Figure  # heavy and optional: only when plotting

    what, ylabel = _SIGNALS[signal]
    fig = Figure(figsize=(8, 5), layout="constrained")
    ax = fig.subplots()
    styles = ["-", "--", "-.", ":"]
    for i, (name, mags) in enumerate(cmp.transmissibility.items()):
        ax.loglog(cmp.freqs_hz, mags[signal], ls=styles[i // 10 % 4], lw=1.4, label=name)
    ax.set(
        xlabel="frequency [Hz]",
        ylabel=ylabel,
        title=f"Transmissibility from the road to the {what}",
    )
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize="small")
    return fig


def control_figures(cmp) -> list[FigureSpec]:
    """The report's figures, numbered in order: one transmissibility chart per
    signal (when a linear design was compared), then the Pareto front."""
    specs: list[FigureSpec] = []
    for signal in _SIGNALS if cmp.transmissibility else ():
        what = _SIGNALS[signal][0]
        specs.append(
            FigureSpec(
                f"transmissibility_{signal}.png",
                f"Figure {len(specs) + 1}",
                f"|{signal}/zr| of every linear design against frequency: the {what} "
                "per metre of road height (control.frequency_response).",
                functools.partial(transmissibility_chart, cmp, signal),
            )
        )
    if cmp.pareto is not None:
        specs.append(
            FigureSpec(
                "pareto.png",
                f"Figure {len(specs) + 1}",
                "Passive designs (cs × ks around the car) by exact RMS body acceleration and "
                "tire load on the road's white road velocity, the non-dominated ones coloured by "
                "RMS travel; the passive optima and the linear controllers marked.",
                lambda: cmp.pareto.figure,
            )
        )
    return specs


def unavailable_designs(run: Iterable[str] = ()) -> dict[str, str]:
    """The designs not in ``run`` that need an optional extra not installed,
    each with the install hint: a report lists them rather than drop them."""
    if HINF_AVAILABLE or "H∞" in run:
        return {}
    return {"H∞": f"not run: it needs slycot, {install_hint('robust')}"}


def _design_table(cmp) -> pd.DataFrame:
    missing = unavailable_designs(cmp.designs)
    what = {**cmp.designs, **missing}
    return pd.DataFrame({"what": list(what.values())}, index=pd.Index(list(what), name="design"))


def _ecu_blocks(cmp, table: pd.DataFrame) -> list:
    """The controllers on a clock: force and travel at every tick, solve times, penalty."""
    cols = [c for c in table.columns if c.startswith("ecu: ")]
    if not cols:
        return []
    rows = table[cols].dropna(how="all")
    if rows.empty:
        return []
    return [
        Heading("Controllers on a clock"),
        Table(
            rows.rename(columns=lambda c: c[len("ecu: ") :]),
            "Sampled-data designs: the largest force commanded at any tick and the largest "
            "suspension travel over each run (the force limit is hard: no tick exceeds it), "
            "the QP's solve time per tick (median and worst, wall time on this machine) and "
            "the ticks on which the soft travel limit's penalty was active (listed in the "
            "notes when any).",
            "Table 2b",
        ),
    ]


def control_blocks(cmp, command: str | None = None) -> list:
    """The report as document blocks (see `qc_control.report.document`)."""
    p, bump, road = cmp.params, cmp.bump, cmp.road
    table = cmp.table.copy()
    bump_cols = [c for c in table.columns if c.startswith("bump: ")]
    road_cols = [c for c in table.columns if c.startswith("road: ")]
    blocks: list = [
        Paragraph(
            f"One quarter car (ms = {p.ms:g} kg, mu = {p.mu:g} kg, ks = {p.ks:g} N/m, "
            f"ku = {p.ku:g} N/m, cs = {p.cs:.0f} N·s/m) with each suspension design, "
            f"run by {cmp.method} at a fixed step: over a {bump['height'] * 100:g} cm, "
            f"{bump['length']:g} m 1 − cos bump at {bump['speed']:g} m/s for "
            f"{bump['duration']:g} s (h = {cmp.dt['bump'] * 1e3:g} ms) and over an ISO 8608 "
            f"class {road['road_class']} road at {road['speed']:g} m/s for "
            f"{road['duration']:g} s (h = {cmp.dt['road'] * 1e3:g} ms, seed {road['seed']}). "
            "Linear loops are substepped to the accuracy rule of qc_control.auto_step."
        ),
        Heading("Designs"),
        Table(_design_table(cmp), "What each design is.", "Table 1"),
        Heading("Bump"),
        Table(
            table[bump_cols].rename(columns=lambda c: c[len("bump: ") :]),
            "Peak body acceleration, peak suspension travel and the 2 % settling time of the "
            f"body displacement (a settling time near {bump['duration']:g} s: not settled "
            "within the run).",
            "Table 2",
        ),
        Heading("ISO 8608 road"),
        Table(
            table[road_cols].rename(columns=lambda c: c[len("road: ") :]),
            "RMS and ISO 2631-1 Wk-weighted RMS body acceleration, RMS travel, RMS dynamic "
            "tire load over the static load, RMS actuator force and mean actuator power "
            "⟨fa·(vs − vu)⟩ (positive: the actuator supplies energy; a semi-active damper "
            "only dissipates).",
            "Table 3",
        ),
        *_ecu_blocks(cmp, table),
        Heading("Transmissibility"),
    ]
    specs = control_figures(cmp)
    charts = [s for s in specs if s.name.startswith("transmissibility_")]
    blocks += [Image(spec.name, spec.caption, spec.label) for spec in charts]
    if not charts:
        blocks.append(
            Paragraph(
                "No linear design was compared: a semi-active loop is nonlinear and has no "
                "transmissibility."
            )
        )
    if not cmp.exact.empty:
        blocks += [
            Heading("Exact stationary metrics"),
            Table(
                cmp.exact,
                "Linear designs on the road's white road velocity (ISO 8608 of waviness 2 at "
                "constant speed): stationary RMS from a Lyapunov equation over the unbounded "
                "band, no simulation. Semi-active designs are nonlinear: Table 3 only.",
                "Table 4",
            ),
        ]
    blocks += [Image(spec.name, spec.caption, spec.label) for spec in specs[len(charts) :]]
    if cmp.notes:
        blocks.append(Heading("Notes"))
        blocks += [Paragraph(note) for note in cmp.notes]
    if command:
        blocks += [Heading("Reproduce"), Code(command, wrap=True)]
    return blocks


def write_control_report(
    cmp, out_dir, formats=FORMATS, *, command: str | None = None, overwrite: bool = True
):
    """Write the controller comparison into ``out_dir`` (as `qc_control.write_report` does).

    Files: ``report.md``/``.html``/``.pdf`` per ``formats``, the two
    transmissibility PNGs and the Pareto front's, and with ``'csv'``
    ``control_table.csv`` (every number of Tables 2 and 3),
    ``transmissibility.csv`` and ``exact_metrics.csv``. A comparison of
    semi-active designs alone has neither transmissibility nor exact
    metrics: their figures and files are left out.
    """

    def tables() -> dict[str, pd.DataFrame]:
        cols = {
            f"|{sig}/zr| {name}": mags[sig]
            for sig in _SIGNALS
            for name, mags in cmp.transmissibility.items()
        }
        found = {
            "control_table.csv": cmp.table,
            "transmissibility.csv": pd.DataFrame(cols, index=pd.Index(cmp.freqs_hz, name="f [Hz]")),
            "exact_metrics.csv": cmp.exact,
        }
        return {name: frame for name, frame in found.items() if not frame.columns.empty}

    return write_document(
        out_dir,
        TITLE,
        lambda: control_blocks(cmp, command),
        control_figures(cmp),
        tables,
        formats,
        command=command,
        overwrite=overwrite,
    )
