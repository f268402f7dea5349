"""Findings written from the numbers of a MethodComparison (no fixed verdicts)."""

from __future__ import annotations

import math

from ..studies import columns as col
from ..studies.timing import same_work
from .document import fmt, sentence

__all__ = ["findings", "coincidence_groups"]

_KIND = {
    "confirmed": "confirmed by a run at that count",
    "interpolated": "an estimate, interpolated between the refinements, not checked by a run",
    "extrapolated": "an estimate, extrapolated from its order, not checked by a run",
    "missed": "not reached by the runs from its estimate",
    "unreached": "not reached",
}


def _count(cmp, tol: float, method: str) -> str:
    """A quoted cost: the confirmed count as it is, an estimate as "about" it."""
    cost = fmt(int(cmp.cost.loc[tol, method]))
    return cost if cmp.cost_kind.loc[tol, method] == "confirmed" else f"about {cost}"


def _cheapest(cmp) -> list[str]:
    """The cheapest method for each target, and the others' counts: the study's
    numbers (confirmed, or estimates called so), as the summary and Table 7 quote them."""
    out = []
    body = cmp.model.body_disp if getattr(cmp, "model", None) is not None else "xs"
    for tol in cmp.cost.index:
        costs = cmp.cost.loc[tol].dropna().sort_values()
        if costs.empty:
            continue
        best = costs.index[0]
        tied = [m for m, v in costs.items() if v == costs.iloc[0]]
        others = ", ".join(f"{m} {_count(cmp, tol, m)}" for m in costs.index if m not in tied)
        who = " and ".join(tied)
        kind = cmp.cost_kind.loc[tol, best]
        out.append(
            f"Cheapest to reach {fmt(tol)} m (max |{body} error|): {who}, "
            f"{_count(cmp, tol, best)} RHS evaluations ({_KIND[kind]})"
            + (f"; the others need {others}." if others else ".")
        )
    return out


def _step_limits(cmp) -> list[str]:
    t = cmp.table
    out = []
    if "euler" in t.index:
        row = t.loc["euler"]
        if row[col.H_MAX] > 0:
            out.append(
                f"Euler's step limit is h = {fmt(row[col.H_MAX])} s, set by the "
                f"{row[col.LIMITED_BY]} mode (|1 + hλ| ≤ 1, i.e. h ≤ −2·Re λ/|λ|²); the chosen "
                f"h = {fmt(cmp.h)} s is {fmt(100 * cmp.h / row[col.H_MAX])}% of it."
            )
        else:  # Re λ = 0: the limit −2·Re λ/|λ|² is zero
            out.append(
                f"Euler has no stable step: the {row[col.LIMITED_BY]} mode is undamped "
                "(Re λ = 0), so |1 + hλ| > 1 for every h > 0 and its amplitude grows at any step."
            )
    others = [f"{m} {fmt(r[col.H_MAX])} s" for m, r in t.iterrows() if m != "euler"]
    if others:
        out.append("The other limits: " + ", ".join(others) + ".")
    unstable = [m for m, r in t.iterrows() if not r[col.STABLE]]
    if unstable:
        out.append(
            f"At h = {fmt(cmp.h)} s {', '.join(unstable)} "
            f"{'is' if len(unstable) == 1 else 'are'} beyond the stability limit: "
            "the response grows instead of decaying, and its errors mean nothing."
        )
    return out


def _groups(pairs) -> list[list[str]]:
    """Connected groups of coincident methods, in first-seen order."""
    groups: list[list[str]] = []
    for a, b in pairs:
        hit = [g for g in groups if a in g or b in g]
        merged = [m for g in hit for m in g]
        merged += [m for m in (a, b) if m not in merged]
        groups = [g for g in groups if g not in hit] + [merged]
    return groups


def coincidence_groups(cmp) -> list[list[str]]:
    """Groups of methods with the same trajectory (``cmp.coincident``), each in
    the comparison's method order."""
    order = {name: i for i, name in enumerate(cmp.responses)}
    return [sorted(g, key=order.__getitem__) for g in _groups(cmp.coincident)]


def _coincidence(cmp) -> list[str]:
    out = []
    orders = cmp.table[col.ORDER]
    for group in coincidence_groups(cmp):
        gap = max(v for k, v in cmp.coincident.items() if set(k) <= set(group))
        names = ", ".join(group[:-1]) + " and " + group[-1]
        p = int(orders[group[0]])
        apart = (
            "identical to the last bit"
            if gap == 0
            else f"at most {fmt(gap)} m apart in any state, rounding error"
        )
        powers = [f"(hA)^{k}/{math.factorial(k)}" for k in range(2, p + 1)]
        taylor = " + ".join(["I", "hA", *powers])
        out.append(
            f"{names} give the same trajectory ({apart}). On a linear system the free step "
            f"of every method of order {p} with {p} stages is the same polynomial of hA, "
            f"the first terms of exp(hA): x ← ({taylor})·x"
            + (
                ", and an input linear within each step enters them alike (Midpoint's "
                "u(t + h/2) is Heun's (u(t) + u(t + h))/2)"
                if {"midpoint", "heun"} <= set(group)
                else ""
            )
            + ". They can differ on nonlinear systems or inputs that curve within a step."
        )
    present = set(cmp.table.index)
    if {"midpoint", "heun"} <= present and not any(
        {"midpoint", "heun"} <= set(g) for g in coincidence_groups(cmp)
    ):
        out.append("midpoint and heun differ here by more than 1e-12 m.")
    return out


def _damping(cmp) -> list[str]:
    first = cmp.modes.modes[0]  # body bounce, or a car's lowest body mode
    if math.isfinite(first.zeta_nominal):  # the quarter car
        body, wheel = cmp.modes.body, cmp.modes.wheel
        text = (
            f"Nominal against modal damping: the nominal ratio cs/(2·√(ks·ms)) = "
            f"{fmt(body.zeta_nominal)}, but the modes have ζ = {fmt(body.zeta)} (body bounce, "
            f"{fmt(body.fn)} Hz) and ζ = {fmt(wheel.zeta)} (wheel hop, {fmt(wheel.fn)} Hz)."
        )
    else:
        text = (
            "Modal damping: "
            + ", ".join(f"ζ = {fmt(m.zeta)} ({m.name}, {fmt(m.fn)} Hz)" for m in cmp.modes.modes)
            + "."
        )
    out = [text]
    for m, nm in cmp.numerical_modes.items():
        b = nm.loc[first.name]
        label = first.name.replace(" ", "-")  # "body-bounce" on a quarter car
        worst = nm["freq error [%]"].abs().idxmax()
        sign = "adds" if b["zeta error"] > 0 else "removes"
        out.append(
            f"{m} at h = {fmt(cmp.h)} s {sign} damping: {label} ζ {fmt(b['zeta'])} → "
            f"{fmt(b['zeta_h'])} (Δζ = {b['zeta error']:+.2g}); its largest frequency error is "
            f"{fmt(nm.loc[worst, 'freq error [%]'])}% ({worst})."
        )
    return out


def _orders(cmp) -> list[str]:
    t = cmp.table
    parts = [f"{m} {fmt(r[col.OBSERVED_ORDER])} (theory {r[col.ORDER]})" for m, r in t.iterrows()]
    out = ["Observed orders from h, h/2, h/4: " + ", ".join(parts) + "."]
    off = [
        m
        for m, r in t.iterrows()
        if math.isfinite(r[col.OBSERVED_ORDER]) and abs(r[col.OBSERVED_ORDER] - r[col.ORDER]) > 0.15
    ]
    if off:
        out.append(
            f"{', '.join(off)}: more than 0.15 from theory, so h = {fmt(cmp.h)} s is not "
            "yet in the asymptotic range there; the convergence table shows the slope "
            "settling at finer steps."
        )
    return out


def _ride(cmp) -> list[str]:
    if cmp.ride is None:
        return []
    ride = cmp.ride
    key = "rms_body_acc_wk [m/s²]"
    ref = float(ride.loc["reference", key])
    off = cmp.ride_error["rms_body_acc_wk [% off]"]
    parts = [f"{m} {v:+.2g}%" for m, v in off.items()]
    # one column per wheel: "lift_off" on a quarter car, "lift_off front" on a half car
    wheels = [
        c[len("lift_off") :] for c in ride.columns if c.startswith("lift_off") and "[" not in c
    ]
    lifted = [
        w.strip() or "the wheel" for w in wheels if bool(ride.loc["reference", f"lift_off{w}"])
    ]
    tire = [
        f"{fmt(float(ride.loc['reference', f'rms_tire_load / static{w} [-]']))}" for w in wheels
    ]
    return [
        f"On this road the exact Wk-weighted body acceleration is {fmt(ref)} m/s² RMS "
        f"(ISO 2631-1); at h = {fmt(cmp.h)} s the methods give it "
        + ", ".join(parts)
        + ". "
        + (
            "The dynamic tire load exceeds the static wheel load"
            + ("" if len(wheels) == 1 else f" ({', '.join(lifted)})")
            + ": the wheel would lift off, which this linear model does not represent."
            if lifted
            else f"The RMS dynamic tire load is {' and '.join(tire)} of the static wheel load"
            + ("" if len(wheels) == 1 else f" ({', '.join(w.strip() for w in wheels)})")
            + ", and the wheel never lifts off."
        )
    ]


def _comfort(cmp) -> list[str]:
    """The ISO 2631-1 assessment's leading sentence (the additional methods' where
    they are the assessment, else a_v and Annex C's words), pointing to its section."""
    comfort = getattr(cmp, "comfort", None)
    if comfort is None:
        return []
    lead = comfort.verdict[0]
    return [f"Assessed as ISO 2631-1:1997 does (section Ride comfort): {sentence(lead)}"]


def _same_work(cmp) -> list[str]:
    """Methods that make the same evaluations do the same work: whatever their times
    say, within the spread of the timing rounds or beyond it, the difference is the
    machine's (its load changed between the rounds), not the methods'."""
    out = []
    for pair in same_work(cmp.table):
        a, b = (f"{fmt(t * 1e3)} ms" for t in pair.times)
        head = (
            f"{pair.first} and {pair.second} make the same {fmt(pair.evaluations)} RHS "
            f"evaluations; their wall times ({a} and {b}) "
        )
        out.append(
            head + "differ by less than the spread of the timing rounds: the difference is "
            "the machine's noise, not the methods'."
            if pair.noise
            else head + "differ by more than the spread of the timing rounds, yet the same "
            "evaluations are the same work: the difference is the machine's noise (its load "
            "changed between the rounds), not the methods'. Compare them by their evaluations."
        )
    return out


def findings(cmp) -> list[str]:
    """Sentences that state what the numbers of ``cmp`` show."""
    return (
        _cheapest(cmp)
        + _same_work(cmp)
        + _step_limits(cmp)
        + _coincidence(cmp)
        + _damping(cmp)
        + _orders(cmp)
        + _ride(cmp)
        + _comfort(cmp)
    )
