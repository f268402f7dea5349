"""Benchmarks, side by side in one run: qc_control against python-control and scipy.

    python benchmarks/run.py            # full run, writes benchmarks/RESULTS.md
    python benchmarks/run.py --quick    # smoke mode (CI): small sizes, same code paths
    python benchmarks/run.py --loop     # only qc.integrate against hand-written loops

Every speed is a ratio measured in this run on this machine (medians of runs
timed in turns, with their spread, or best of several repeats where a table
says so), because the machines are shared and noisy; absolute times are
printed for context only. Benchmarks are not tests: nothing here fails on a
slow machine.
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as dt
import os
import platform
import statistics
import sys
import time
import tracemalloc
from pathlib import Path

import control
import numpy as np
import scipy
from scipy.integrate import solve_ivp

import qc_control as qc
from qc_control.numerics import threads
from qc_control.studies.compare import best_time
from qc_control.studies.sweeps import DEFAULT_METRICS, design_grid, sweep

# the sections kept in modules of their own, beside this script (run as a script or by
# runpy, which puts no folder on the path)
sys.path.insert(0, str(Path(__file__).resolve().parent))
from explore_redraw import browser_redraw_benchmark  # noqa: E402
from mpc_solvers import mpc_solvers_benchmark  # noqa: E402
from shared import g, other_cores_busy, section, table, titled  # noqa: E402
from skyhook_car import car_with_skyhook  # noqa: E402

X0 = np.array([0.0, 0.0, 0.05, 0.0])

#: One untimed call before the timed ones (caches, fresh memory pages). The smoke
#: run (``--quick``, `main`) turns it off: its times are never read, and a warm-up
#: repeats the same call on the same code path (in the smoke run, a third of the
#: CPU time of the timed benchmarks).
WARMUP = True


def best_of(fn, repeats: int) -> float:
    """Best of ``repeats`` timed calls after one untimed warm-up call (`WARMUP`)."""
    return best_time(fn, repeats, warmup=WARMUP)


def in_turns(fn_a, fn_b, rounds: int, measure) -> tuple[list[float], list[float], list[float]]:
    """``rounds`` times of ``fn_a`` and of ``fn_b`` taken in turns, and each round's ratio.

    After one untimed call of each (`WARMUP`), the two are measured in turns (a b, b a,
    a b, ...), so that a drift of the machine's load reaches both sides alike;
    ``measure(fn)`` gives one time. Returns ``(a's times, b's times, b / a per
    round)``.
    """
    if WARMUP:
        fn_a()
        fn_b()
    times: tuple[list[float], list[float]] = ([], [])
    for r in range(rounds):
        for side in (0, 1) if r % 2 == 0 else (1, 0):
            times[side].append(measure((fn_a, fn_b)[side]))
    return times[0], times[1], [b / a for a, b in zip(*times)]


def cpu_time(fn) -> float:
    """This process's CPU time of one call (other processes count on neither side)."""
    start = time.process_time()
    fn()
    return time.process_time() - start


def wall_time(fn) -> float:
    """The wall time of one call."""
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def paired_runs(fn_a, fn_b, repeats: int) -> tuple[list[float], list[float], list[float]]:
    """CPU times of ``fn_a`` and ``fn_b``, one call each in turns (`in_turns`):
    each pair's ratio ``b / a`` compares two runs made within a fraction of a second."""
    return in_turns(fn_a, fn_b, repeats, cpu_time)


def round_times(
    fn_a, fn_b, rounds: int, calls: int
) -> tuple[list[float], list[float], list[float]]:
    """Per round, the best wall time of ``calls`` consecutive calls of ``fn_a``,
    then of ``fn_b`` (`in_turns`), and their ratio.

    For calls of a millisecond or less. Within a round each function runs
    warm, as a loop over designs runs it, and its best time is its own cost
    (Python's ``timeit`` advice: the slower calls measure other processes, and
    the first call after the other function's, with cold caches and heap);
    across rounds, the spread of the ratios shows how far the machine moved.
    Timing single calls in turns (`paired_runs`) would charge a 0.5 ms call
    for the 40 ms call before it.
    """
    return in_turns(fn_a, fn_b, rounds, lambda fn: min(wall_time(fn) for _ in range(calls)))


def paired_medians(fn_a, fn_b, repeats: int) -> tuple[float, float, float]:
    """Median CPU times of ``fn_a`` and ``fn_b``, and the median of their ratios
    (`paired_runs`)."""
    a, b, ratios = paired_runs(fn_a, fn_b, repeats)
    return statistics.median(a), statistics.median(b), statistics.median(ratios)


def timed_runs(fn, repeats: int) -> list[float]:
    """Wall times [s] of ``repeats`` calls after one untimed warm-up (`WARMUP`)."""
    if WARMUP:
        fn()
    return [wall_time(fn) for _ in range(repeats)]


def med_spread(times: list[float], scale: float = 1.0) -> str:
    """``median (min–max)`` of ``times · scale``, three significant figures."""
    xs = sorted(t * scale for t in times)
    return f"{g(statistics.median(xs))} ({g(xs[0])}–{g(xs[-1])})"


def peak_memory(fn) -> float:
    """Peak memory [MB] that ``fn`` allocates above what is live when it starts
    (tracemalloc: numpy's buffers included), from one run."""
    tracemalloc.start()
    tracemalloc.reset_peak()
    base = tracemalloc.get_traced_memory()[0]
    try:
        fn()
        return (tracemalloc.get_traced_memory()[1] - base) / 1e6
    finally:
        tracemalloc.stop()


def slope(xs, ys) -> float:
    """Least-squares slope of log y against log x."""
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


def sweep_comparison(T, quick: bool):
    """Free and road-step sweeps of the ks × ζ grid against loops of control calls.

    Medians of 5 runs on each side (one in the smoke mode), side by side
    (alternating). The loop's time per design does not depend on the design, so each run times
    every 10th design and scales by 10 (stated in the table).
    """
    n_ks, n_zeta = (4, 5) if quick else (40, 25)
    grid = {"ks": np.linspace(15e3, 45e3, n_ks), "zeta": np.linspace(0.1, 0.6, n_zeta)}
    designs = design_grid(grid)
    every = 1 if quick else 10
    subset = designs[::every]
    U = np.where(T >= 0.5, 0.05, 0.0)
    free_sys = [qc.quarter_car(qc.QuarterCarParams(**d)) for d in subset]
    road_sys = [qc.quarter_car(qc.QuarterCarParams(**d), road=True) for d in subset]
    X0r = np.zeros(4)
    cases = {
        "free (released from 5 cm)": (
            lambda: sweep(grid, T, X0, progress=False),
            lambda: [control.initial_response(s, T, X0) for s in free_sys],
            "≥ 300",
        ),
        "5 cm road step": (
            lambda: sweep(grid, T, X0r, U=U, progress=False),
            lambda: [control.forced_response(s, T, U, X0r) for s in road_sys],
            "≥ 100",
        ),
    }
    runs = 1 if quick else 5  # the smoke mode: one repeat (--help), same code paths
    rows = []
    for name, (ours, theirs, target) in cases.items():
        t_ours, t_loop, ratios = in_turns(ours, theirs, runs, wall_time)
        t_loop, ratios = [t * every for t in t_loop], [r * every for r in ratios]
        rows.append(
            [
                name,
                str(len(designs)),
                med_spread(t_ours),
                med_spread(t_loop),
                med_spread(ratios),
                target,
            ]
        )
    head = [
        "workload",
        "designs",
        "qc.sweep [s]",
        f"loop of control calls [s] (1 in {every} designs timed, × {every})",
        "ratio",
        "target",
    ]
    return head, rows, len(designs)


def memory_and_spectral(T, quick: bool):
    """Peak memory of 10,000-design sweeps, and the spectral sweep's time."""
    n = 10 if quick else 100
    grid = {"ks": np.linspace(15e3, 45e3, n), "zeta": np.linspace(0.1, 0.6, n)}
    U = np.where(T >= 0.5, 0.05, 0.0)
    rows = []
    for name, fn in (
        ("free", lambda: sweep(grid, T, X0, progress=False)),
        ("5 cm road step", lambda: sweep(grid, T, np.zeros(4), U=U, progress=False)),
    ):
        times = timed_runs(fn, 1 if not quick else 1)
        rows.append([name, str(n * n), str(T.size), med_spread(times), g(peak_memory(fn))])
    road = qc.ISO8608Road("C", speed=20.0)
    spectral = lambda: sweep(grid, road=road)  # noqa: E731
    times = timed_runs(spectral, 1 if quick else 5)
    rows.append(
        [
            "spectral, ISO 8608 C at 20 m/s (exact)",
            str(n * n),
            "–",
            med_spread(times),
            g(peak_memory(spectral)),
        ]
    )
    # the spectral sweep against one design at a time
    result = sweep(grid, road=road).metrics
    worst = 0.0
    for i in range(0, n * n, max(1, n * n // 25)):
        d = {k: result.loc[i, k] for k in ("ms", "mu", "ks", "ku", "cs")}
        single = qc.ride_metrics_spectral(d, road, exact=True)
        for col in ("rms_body_acc [m/s²]", "rms_susp_travel [m]", "rms_tire_load / static [-]"):
            worst = max(worst, abs(result.loc[i, col] / single[col] - 1))
    head = ["sweep", "designs", "samples", "time [s], median (min–max)", "peak memory [MB]"]
    return head, rows, worst


def scaling(quick: bool, out_dir: Path):
    """Time and peak memory against designs and samples (road step, RK4),
    with log-log plots and fitted slopes."""
    designs_axis = [10, 100] if quick else [100, 1000, 10_000, 100_000]
    samples_axis = [101, 1001] if quick else [1001, 10_001, 100_001, 1_000_001]
    base_samples, base_designs = (101, 10) if quick else (1001, 100)

    def run(m, N):
        T = np.linspace(0.0, (N - 1) * 1e-3, N)
        U = np.where(T >= 0.05 * T[-1], 0.05, 0.0)
        ks = np.linspace(15e3, 45e3, m)
        fn = lambda: sweep({"ks": ks}, T, np.zeros(4), U=U, progress=False)  # noqa: E731
        times = timed_runs(fn, 3 if m * N <= 10**7 and not quick else 1)
        return statistics.median(times), peak_memory(fn)

    by_designs = [run(m, base_samples) for m in designs_axis]
    by_samples = [run(base_designs, N) for N in samples_axis]
    rows = []
    for label, axis, data in (
        (f"designs (at {base_samples} samples)", designs_axis, by_designs),
        (f"samples (at {base_designs} designs)", samples_axis, by_samples),
    ):
        t = [d[0] for d in data]
        mem = [d[1] for d in data]
        rows.append(
            [
                label,
                ", ".join(str(a) for a in axis),
                ", ".join(g(x) for x in t),
                g(slope(axis, t), 2),
                ", ".join(g(x) for x in mem),
                g(slope(axis, mem), 2),
            ]
        )
    if not quick:
        import matplotlib

        matplotlib.use("Agg")
        from matplotlib.figure import Figure

        fig = Figure(figsize=(9, 3.8), layout="constrained")
        for ax, axis, data, what in zip(
            fig.subplots(1, 2),
            (designs_axis, samples_axis),
            (by_designs, by_samples),
            ("designs", "samples"),
        ):
            ax.loglog(axis, [d[0] for d in data], "o-", label="time [s]")
            ax.loglog(axis, [d[1] for d in data], "s--", label="peak memory [MB]")
            ax.set(xlabel=what, title=f"road-step sweep against {what}")
            ax.grid(alpha=0.3, which="both")
            ax.legend()
        fig.savefig(out_dir / "scaling.png", dpi=110)
    head = ["against", "values", "time [s]", "time slope", "peak memory [MB]", "memory slope"]
    return head, rows


def dask_comparison(quick: bool, m: int = 100_000, chunk: int = 5_000):
    """A 100,000-design road-step sweep on a two-worker Dask LocalCluster
    against one process: wall-clock speed-up, and the overhead per chunk in
    CPU time (every process's CPU time during the Dask run, the client's and
    the workers', less the single process's), which a loaded machine does not
    inflate as it does wall time. Twice: with Dask's default worker
    environment, and with `qc_control.studies.sweeps.DASK_WORKER_ENV` (the allocator
    settings that spare the page faults of Dask's ``MALLOC_TRIM_THRESHOLD_``)."""
    if quick:  # starting a cluster takes seconds: not in the smoke run
        return None
    try:
        import dask
        from dask.distributed import Client, LocalCluster
    except ImportError:
        return None
    from qc_control.studies.sweeps import DASK_WORKER_ENV

    T = np.linspace(0.0, 1.0, 1001)
    U = np.where(T >= 0.1, 0.05, 0.0)
    grid = {"ks": np.linspace(15e3, 45e3, m // 100), "zeta": np.linspace(0.1, 0.6, 100)}

    def run(executor=None):
        return sweep(grid, T, np.zeros(4), U=U, chunk_size=chunk, executor=executor, progress=False)

    run()  # warm-up
    cpu0, wall0 = time.process_time(), time.perf_counter()
    run()
    cpu1, t1 = time.process_time() - cpu0, time.perf_counter() - wall0
    chunks = -(-m // chunk)
    default_env = dask.config.get("distributed.nanny.pre-spawn-environ")
    rows = []
    saved = dict(os.environ)
    for label, env in (
        ("Dask's default", default_env),
        ("DASK_WORKER_ENV", {**default_env, **DASK_WORKER_ENV}),
    ):
        # the nanny copies its pre-spawn environment into this process's
        # os.environ, which then overrides the next cluster's config: restore it
        os.environ.clear()
        os.environ.update(saved)
        with (
            dask.config.set({"distributed.nanny.pre-spawn-environ": env}),
            LocalCluster(
                n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
            ) as cluster,
            Client(cluster) as client,
        ):
            pool = client.get_executor()
            sweep({"ks": [2e4]}, T, np.zeros(4), U=U, executor=pool, progress=False)  # imports
            before = sum(client.run(time.process_time).values())
            cpu0, wall0 = time.process_time(), time.perf_counter()
            run(pool)
            client_cpu, t2 = time.process_time() - cpu0, time.perf_counter() - wall0
            workers_cpu = sum(client.run(time.process_time).values()) - before
        os.environ.clear()
        os.environ.update(saved)
        overhead = (client_cpu + workers_cpu - cpu1) / chunks
        rows.append(
            [
                label,
                str(m),
                str(chunk),
                str(chunks),
                g(t1),
                g(t2),
                g(t1 / t2),
                f"{g(cpu1)} / {g(workers_cpu)} + {g(client_cpu)}",
                g(overhead * 1e3),
            ]
        )
    head = [
        "worker environment",
        "designs",
        "chunk",
        "chunks",
        "one process [s]",
        "LocalCluster, 2 workers [s]",
        "speed-up (wall)",
        "CPU: one process / workers + client [s]",
        "overhead per chunk [ms CPU]",
    ]
    return head, rows


# -- hand-written loops: what a student writes, the yardstick for the generic stepper
def hand_loop(step):
    """A student's fixed-step loop around one method's step: ``step(f, h)`` gives
    the step ``x(t) -> x(t + h)``, with its fractions of h worked out once."""

    def run(f, T, x):
        out = np.empty((T.size, x.size))
        out[0] = x
        h = T[1] - T[0]
        advance = step(f, h)
        t = T[0]
        for i in range(T.size - 1):
            x = advance(t, x)
            t += h
            out[i + 1] = x
        return out

    return run


def euler_step(f, h):
    return lambda t, x: x + h * f(t, x)


def midpoint_step(f, h):
    h2 = h / 2
    return lambda t, x: x + h * f(t + h2, x + h2 * f(t, x))


def heun_step(f, h):
    h2 = h / 2

    def step(t, x):
        k1 = f(t, x)
        k2 = f(t + h, x + h * k1)
        return x + h2 * (k1 + k2)

    return step


def rk4_step(f, h):
    h2, h6 = h / 2, h / 6

    def step(t, x):
        k1 = f(t, x)
        k2 = f(t + h2, x + h2 * k1)
        k3 = f(t + h2, x + h2 * k2)
        k4 = f(t + h, x + h * k3)
        return x + h6 * (k1 + 2 * k2 + 2 * k3 + k4)

    return step


HAND = {
    m: hand_loop(step)
    for m, step in (
        ("euler", euler_step),
        ("midpoint", midpoint_step),
        ("heun", heun_step),
        ("rk4", rk4_step),
    )
}


def loop_comparison(f, T, repeats: int):
    """``qc.integrate`` against the hand-written loops: header, rows, and a caption."""
    rows = []
    for m, hand in HAND.items():
        t_hand, t_gen, ratio = paired_medians(
            lambda: hand(f, T, X0), lambda: qc.integrate(f, T, X0, m), repeats
        )
        rows.append([m, g(t_hand * 1e3), g(t_gen * 1e3), g(ratio)])
    head = ["method", "hand loop [ms]", "qc.integrate [ms]", "ratio (target ≤ 1.2)"]
    text = (
        "Both call the same Python `f(t, x) = A @ x`; the hand loop is a student's, a loop "
        "around one step function per method. `qc.integrate` is a plain loop over "
        "the tableau as data (no generated code): the non-zero h·a_ij, h·b_i and c_i·h once "
        f"per step size. CPU times, medians of {repeats} runs of each timed in turns; the "
        "ratio is the median of the ratios of the pairs."
    )
    return head, rows, text


def interconnect_benchmark(quick: bool) -> tuple[list[str], list[str], list[list[str]]]:
    """Issue 11 item 2: RK4 at h = 1 ms on car + skyhook against control's default solve_ivp.

    Returns ``(markdown lines, head, rows)``. Times are paired CPU-time medians
    (`paired_medians`); errors are against RK4 at h = 1/32 ms on the same
    system and road (see the comment on why not solve_ivp).
    """
    t_end = 1.0 if quick else 10.0
    T = np.linspace(0.0, t_end, int(round(t_end / 1e-3)) + 1)
    zr = qc.road.iso8608(T, "C", 20.0, seed=1)
    cl = car_with_skyhook()
    ours = qc.input_output_response(cl, T, zr, 0.0)
    theirs = control.input_output_response(cl, T, zr, 0.0)
    # The clipped skyhook's force jumps where vs·(vs - vu) changes sign, which makes
    # an adaptive solver at tight tolerance crawl (minutes for 10 s, through control
    # or by hand); the reference is RK4 at 1/32 of the step on the same system, whose
    # error is first order at the jumps: about 1/32 of that at 1 ms.
    fine = np.linspace(0.0, t_end, 32 * (T.size - 1) + 1)
    tight = qc.input_output_response(cl, fine, np.interp(fine, T, zr), 0.0).states[:, ::32]
    scale = float(np.max(np.abs(tight)))
    err_ours = float(np.max(np.abs(ours.states - tight))) / scale
    err_theirs = float(np.max(np.abs(theirs.states - tight))) / scale
    t_fast, t_control, ratio = paired_medians(
        lambda: qc.input_output_response(cl, T, zr, 0.0),
        lambda: control.input_output_response(cl, T, zr, 0.0),
        1 if quick else 5,
    )
    t_rhs = best_of(lambda: qc.input_output_response(cl, T, zr, 0.0, fast=False), 1)
    head = [
        "run",
        "time [s]",
        "× faster than control (target ≥ 5)",
        "max state error / max state",
    ]
    rows = [
        ["qc RK4 h = 1 ms, fast path", g(t_fast), g(ratio), g(err_ours)],
        ["qc RK4 h = 1 ms, sys._rhs", g(t_rhs), g(t_control / t_rhs), g(err_ours)],
        ["control.input_output_response (RK45 defaults)", g(t_control), "1", g(err_theirs)],
    ]
    text = (
        f"The seed car (`control.ss`) and a clipped skyhook (`control.nlsys`) joined by "
        f"`control.interconnect`, on an ISO 8608 class C road at 20 m/s, 0-{t_end:g} s. "
        "Times: paired CPU-time medians; errors against RK4 at h = 1/32 ms (the skyhook's "
        "force jumps, which makes solve_ivp at tight tolerance take minutes)."
    )
    return titled("Nonlinear interconnection: car + clipped skyhook", text, head, rows)


def nonlinear_sweep_benchmark(quick: bool) -> tuple[list[str], list[str], list[list[str]]]:
    """Issue 11 item 7: 1,000 nonlinear designs stepped at once against a loop of
    `control.input_output_response`, RK4 at h = 1 ms, on ISO 8608 roads.

    The car: the seed's body (301.2 kg) on a 40 kg wheel with a 200 kN/m
    unilateral tire, bump and rebound stops (5 cm, 8 cm; 1e5 N/m, 1e7 N/m³),
    a ks × cs grid. ``qc.sweep`` computes its default metrics (streamed); the loop
    only calls control (systems built beforehand) on a sample of designs spread
    over the grid, scaled to all. Paired CPU-time medians (`paired_medians`).
    Returns ``(markdown lines, head, rows)``.
    """
    t_end = 1.0 if quick else 10.0
    T = np.linspace(0.0, t_end, int(round(t_end / 1e-3)) + 1)
    n_ks, n_cs = (5, 4) if quick else (40, 25)
    base = qc.QuarterCarParams(ms=301.2, mu=40.0, ks=30000.0, ku=2e5, cs=1500.0)
    stop = qc.BumpStop(0.05, 1e5, 1e7, clearance_rebound=0.08)
    model = qc.nonlinear_quarter_car_model(base, bump_stop=stop)
    grid = {"ks": np.linspace(15e3, 45e3, n_ks), "cs": np.linspace(500.0, 3000.0, n_cs)}
    designs = design_grid(grid, base)
    picks = np.linspace(0, len(designs) - 1, 4).round().astype(int).tolist()
    systems = [model.rebuild(designs[i]).system for i in picks]
    x0 = np.zeros(4)
    repeats = 1 if quick else 5
    head = [
        "road (20 m/s)",
        "designs",
        "lifted off / hit a stop",
        "qc.sweep, nonlinear [s]",
        f"control loop [s] ({len(picks)} designs timed, scaled)",
        "ratio (target ≥ 300)",
        "batch vs qc.input_output_response (rel.)",
    ]
    rows = []
    for road_class in ("C", "D"):
        zr = qc.road.iso8608(T, road_class, 20.0, seed=1)
        result = sweep(grid, T, x0, zr, model=model, progress=False)
        m = result.metrics
        lifted = int((m["lift_off_duration [s]"] > 0).sum())
        stopped = int((m["peak_susp_travel [m]"] > stop.clearance_bound).sum())
        picked = sweep([designs[i] for i in picks], T, x0, zr, model=model, states=True)
        gap = max(
            float(np.max(np.abs(picked.states[j] - r.states)) / np.max(np.abs(r.states)))
            for j, r in enumerate(qc.input_output_response(s, T, zr, x0) for s in systems)
        )
        t_ours, t_loop, ratio = paired_medians(
            lambda: sweep(grid, T, x0, zr, model=model, progress=False),
            lambda: [control.input_output_response(s, T, zr, x0) for s in systems],
            repeats,
        )
        scale = len(designs) / len(picks)
        rows.append(
            [
                f"ISO 8608 class {road_class}",
                str(len(designs)),
                f"{lifted} / {stopped}",
                g(t_ours),
                g(t_loop * scale),
                g(ratio * scale),
                g(gap, 2),
            ]
        )
    text = (
        f"{len(designs)} designs of the nonlinear quarter car (ks × cs grid; body 301.2 kg, "
        "wheel 40 kg, unilateral tire 200 kN/m with gravity, bump and rebound stops at 5 and "
        "8 cm), RK4 at h = 1 ms, "
        f"0-{t_end:g} s, on ISO 8608 roads at 20 m/s. `qc.sweep(..., "
        "model=qc.nonlinear_quarter_car_model(...))` steps them together "
        "(`qc_control.studies.nlsweep`, "
        "with the car's compiled steps, `qc_control.models.nlkernel`) "
        "and streams its default metrics; the loop calls `control.input_output_response` "
        "(solve_ivp RK45 at its defaults) on designs spread over the grid, scaled to all. "
        "CPU times, paired medians; the last column is the largest state difference of the "
        "batch against `qc.input_output_response` on the timed designs."
    )
    return titled("Nonlinear design sweeps: all designs stepped at once", text, head, rows)


def mpc_benchmark(quick: bool) -> tuple[list[str], list[str], list[list[str]]]:
    """Issue 25: one MPC step against python-control's, and a closed loop with preview.

    The measured problem: the seed car with the force as input, ZOH at 10 ms,
    horizon 20, Q = diag(1, 1, 1e4, 1e4), R = 1e-6, |fa| <= 500 N, from a few
    initial states; ``qc.mpc_controller(...).solve`` (condensed QP, DAQP)
    against ``control.optimal.solve_optimal_trajectory`` (SLSQP) on the same
    discrete system (``control.c2d``), wall times side by side, and both
    optimal costs. Quick mode: horizon 5 (python-control's solve takes
    seconds at 20) and a 1 s closed loop.
    """
    import control.optimal as opt

    horizon = 5 if quick else 20
    dt, limit = 0.01, 500.0
    Q = np.diag([1.0, 1.0, 1e4, 1e4])
    car = qc.quarter_car_model(road=True, actuator=True)
    sys = car.system
    j = sys.input_labels.index("fa")
    d = control.c2d(control.ss(sys.A, sys.B[:, [j]], np.eye(4), 0), dt, "zoh")
    cost = opt.quadratic_cost(d, Q, 1e-6)
    cons = [opt.input_range_constraint(d, [-limit], [limit])]
    mpc = qc.mpc_controller(car, dt, horizon, Q=Q, R=1e-6, limits={"fa": limit})
    starts = [[0.0, 0.0, 0.05, 0.0], [0.5, 0.0, 0.05, 0.0]][: 1 if quick else 2]
    rows = []
    for x0 in starts:
        t0 = time.perf_counter()
        pc = opt.solve_optimal_trajectory(
            d, np.arange(horizon + 1) * dt, x0, cost, cons, print_summary=False
        )
        t_pc = time.perf_counter() - t0
        ours = [mpc.solve(x0) for _ in range(21)][1:]  # after one warm-up solve
        t_ours = statistics.median(s.solve_time for s in ours)
        rows.append(
            [
                str(x0),
                g(t_ours * 1e3),
                g(t_pc * 1e3),
                g(t_pc / t_ours),
                f"{ours[0].cost:.9g}",
                f"{pc.cost:.9g}",
            ]
        )
    head = [
        "x0 [vs, vu, xs, xu]",
        "qc MPC solve [ms]",
        "solve_optimal_trajectory [ms]",
        "× faster (target ≥ 1000)",
        "qc cost",
        "python-control cost",
    ]
    t_end = 1.0 if quick else 10.0
    T = np.arange(0.0, t_end + 0.0025, 0.005)
    zr = qc.road.iso8608(T, "C", speed=20.0, seed=0)
    law = qc.mpc_controller(car, dt, 50, limits={"fa": 1000.0, "susp_travel": 0.08}, preview=0.5)
    loop = qc.closed_loop(car, law)
    t_loop = best_of(lambda: qc.input_output_response(loop.system, T, zr), 1)
    solves = np.asarray(law.log.solve_times) * 1e3
    md = section(
        "Model predictive control (issue 25)",
        f"One control step of the measured problem (horizon {horizon}, ZOH 10 ms, "
        "Q = diag(1, 1, 1e4, 1e4), R = 1e-6, |fa| ≤ 500 N): qc's condensed QP (DAQP, "
        "median wall time of 20 warm solves) against python-control's "
        "solve_optimal_trajectory (one call), and both optimal costs.",
        head,
        rows,
    ) + [
        f"A {t_end:g} s closed loop at 100 Hz on the class C road at 20 m/s, MPC with "
        f"0.5 s preview (horizon 50, |fa| ≤ 1 kN, travel ≤ 8 cm soft), RK4 at 5 ms: "
        f"{g(t_loop)} s (target < 1 s for 10 s); solve per tick median "
        f"{g(float(np.median(solves)))} ms, worst {g(float(solves.max()))} ms.",
        "",
    ]
    rows.append(["closed loop, preview 0.5 s", g(t_loop * 1e3), "", "", "", ""])
    return md, head, rows


def identification_benchmark(quick: bool):
    """Issue 26: ``qc.identify`` of six parameters (mu, ks, ku, cs, cu and the force's
    gain, ms weighed) from 30 s of rig records at 500 Hz (smoke: 5 s), noise-free, from a
    start 20-30 % off; the records come from python-control's exact response.

    Returns the Markdown lines, the table's head and rows, and the target missed (if)."""
    import scipy.signal

    from qc_control.studies.measurement import Measurement

    true = dict(ms=320.0, mu=45.0, ks=22000.0, ku=190000.0, cs=1800.0, cu=150.0)
    fs, duration = 500.0, (5.0 if quick else 30.0)
    t = np.arange(int(duration * fs) + 1) / fs
    rng = np.random.default_rng(26)
    sos = scipy.signal.butter(2, [0.5, 20.0], "bandpass", fs=fs, output="sos")
    ramp = np.minimum(t / 0.5, 1.0)
    zr = scipy.signal.sosfiltfilt(sos, rng.normal(size=t.size)) * ramp
    zr *= 0.004 / np.std(zr)
    fa = 300.0 * scipy.signal.chirp(t, 0.5, t[-1], 15.0, phi=-90.0) * ramp
    car = qc.quarter_car(qc.QuarterCarParams(**true), road=True, actuator=True)
    y = control.forced_response(car, t, np.vstack([zr, fa])).outputs
    labels = list(car.output_labels)
    record = Measurement(
        t, zr=zr, fa=-fa, **{k: y[labels.index(k)] for k in ("susp_travel", "body_acc")}
    )
    start = dict(mu=35.0, ks=28000.0, ku=150000.0, cs=1400.0, cu=100.0)
    kwargs = dict(free=list(start), fixed={"ms": 320.0}, start=start, gains=["fa"])
    ident = qc.identify(record, **kwargs)  # warm-up, and the accuracy
    times = timed_runs(lambda: qc.identify(record, **kwargs), 1 if quick else 3)
    cpu = min(cpu_time(lambda: qc.identify(record, **kwargs)) for _ in range(1 if quick else 3))
    worst = max(abs(ident.table.loc[k, "estimate"] / true[k] - 1) for k in start)
    gain_err = abs(ident.gains["fa"] + 1.0)
    head = ["record", "parameters", "wall time [s]", "CPU time [s]", "nfev", "worst error"]
    rows = [
        [
            f"{duration:g} s at {fs:g} Hz ({t.size} samples × 2 outputs)",
            "mu, ks, ku, cs, cu, gain_fa",
            med_spread(times),
            g(cpu),
            str(ident.nfev),
            f"{g(max(worst, gain_err))} (relative)",
        ]
    ]
    lines = [
        "## Identification (issue 26)",
        "",
        "`qc.identify` by output error with the exact response per evaluation; target "
        "under 5 s for six parameters from 30 s at 500 Hz.",
        "",
        table(head, rows),
        "",
    ]
    wall = statistics.median(times)
    late = [f"the identification took {wall:.2f} s (target under 5)"] if wall > 5 else []
    return lines, head, rows, ([] if quick else late)


def work_precision_benchmark(quick: bool) -> tuple[list[str], list[str], list[list[str]]]:
    """RK4's ladder and the solve_ivp peers to reach 1e-6 m, on the seed car and the
    stiff car (a 1e7 N/m damper top mount), free response, ratios side by side."""
    from qc_control.models.quarter import quarter_car_model
    from qc_control.studies.compare import compare_methods
    from qc_control.studies.peers import RTOLS, SOLVERS

    t_end = 1.0 if quick else 10.0
    T = np.linspace(0.0, t_end, round(t_end / 0.01) + 1)
    rtols = (1e-3, 1e-6) if quick else RTOLS
    cases = {
        "seed car": (quarter_car_model(), (0.0, 0.0, 0.05, 0.0)),
        "stiff car": (quarter_car_model(mount_stiffness=1e7), (0.0, 0.0, 0.05, 0.0, 0.05)),
    }
    best = {}
    for label, (model, x0) in cases.items():
        cmp = compare_methods(
            model, T, x0, methods=("rk4",), solvers=SOLVERS, rtols=rtols, repeats=1
        )
        best[label] = cmp.peers.best_per_name(1e-6)
    names = list(dict.fromkeys(n for frame in best.values() for n in frame.index))
    head = ["run"] + [f"{c} {w}" for c in cases for w in ("evals", "ms", "evals/rk4", "time/rk4")]
    rows = []
    for name in names:
        row = [name]
        for label in cases:
            frame = best[label]
            if name not in frame.index or "rk4" not in frame.index:
                row += ["-"] * 4
                continue
            r, rk4 = frame.loc[name], frame.loc["rk4"]
            row += [
                str(int(r["evaluations"])),
                g(1e3 * r["time"]),
                g(r["evaluations"] / rk4["evaluations"]),
                g(r["time"] / rk4["time"]),
            ]
        rows.append(row)
    lines = [
        "## Work and precision: fixed-step RK4 against the solvers people use",
        "",
        f"Free response from the body at 5 cm, 0-{t_end:g} s on {T.size} samples; each "
        "run's cheapest setting that reaches 1e-6 m in xs against the exact response "
        "(RK4: h, h/2, ..., h/32 from 10 ms, stepped one step at a time; solve_ivp: rtol "
        f"{', '.join(f'{r:g}' for r in rtols)} with atol = rtol·max|x_i|; 'control': "
        "input_output_response at its defaults, shown when it reaches 1e-6 m). Stiff car: "
        "the seed's damper on a 1e7 N/m top mount (a real mode at -6,633 1/s; RK4 is "
        "stable only below 0.42 ms).",
        "",
        table(head, rows),
        "",
    ]
    return lines, head, rows


def explore_benchmark(quick: bool) -> tuple[list[str], list[list[str]]]:
    """Issue 27: the explorer's redraw on the server, on the seed's scenario (10 s at
    1 ms, four methods and the exact response), h moved between 1 and 0.99 ms: the
    library's part (`quick_comparison`), the convergence ladder (redone when the
    vehicle or the start changes) and the whole callback with the figures' and tables'
    updates (Panel's models, without the browser; `browser_redraw_benchmark` times
    the browser's part, from the key to the painted figures)."""
    from qc_control.cli.explore import explorer
    from qc_control.studies.quick import error_ladder, ladder_steps, quick_comparison
    from qc_control.studies.scenario import Scenario

    repeats = 1 if quick else 15
    sc = Scenario(t_end=10.0, h=0.001)
    model, T, U, _ = sc.problem()
    page = explorer().explorer_page
    steps = ladder_steps(sc.t_end)
    flip = iter([0.99, 1.0] * repeats)

    def redraw():
        page.widgets["h"].value = next(flip)

    parts = {
        "quick_comparison (python-control's exact + 4 methods + tables)": lambda: quick_comparison(
            model, T, sc.x0, U, sc.methods
        ),
        "error_ladder (12 steps, 0.5-200 ms)": lambda: error_ladder(
            model, sc.t_end, sc.x0, lambda T: None, sc.methods, steps
        ),
        "the whole redraw on the server (h changed)": redraw,
    }
    head = ["part", "median [ms]", "spread"]
    rows = [
        [name, *med_spread(timed_runs(fn, repeats), 1e3).split(" ", 1)]
        for name, fn in parts.items()
    ]
    return head, rows


@contextlib.contextmanager
def blas_threads_of_the_machine():
    """The library's one-BLAS-thread limit (qc_control.numerics.threads) turned
    off, so that the choice it makes is measured beside it."""
    one = threads._OneThread
    enter, leave = one.__enter__, one.__exit__
    one.__enter__, one.__exit__ = (lambda self: self), (lambda self, *exc: False)
    try:
        yield
    finally:
        one.__enter__, one.__exit__ = enter, leave


def interleaved(fns: dict, rounds: int, calls: int) -> dict:
    """Per function, the median over ``rounds`` of the best of ``calls`` wall
    times; the functions take turns within each round (`round_times`' reasoning)."""
    if WARMUP:
        for fn in fns.values():
            fn()
    times: dict = {name: [] for name in fns}
    for r in range(rounds):
        order = list(fns) if r % 2 == 0 else list(reversed(fns))
        for name in order:
            times[name].append(min(wall_time(fns[name]) for _ in range(calls)))
    return {name: statistics.median(ts) for name, ts in times.items()}


def busy_benchmark(quick: bool):
    """A single response and a 1,000-design sweep, quiet and with the other cores
    busy, each with the library's one BLAS thread and with the machine's count.

    Returns the section's markdown lines, the table, and the targets missed:
    on the busy machine each keeps 2/3 of its quiet speed, and one response
    stays ≥ 60× control.forced_response measured beside it (issue 40).
    """
    n = 1001 if quick else 10001
    T = np.linspace(0.0, 10.0, n)
    U = np.where(T >= 0.5, 0.05, 0.0)
    car = qc.quarter_car(road=True)
    side = (4, 5) if quick else (40, 25)
    grid = {"ks": np.linspace(15e3, 45e3, side[0]), "zeta": np.linspace(0.1, 0.6, side[1])}
    designs = side[0] * side[1]
    rounds, calls = (1, 1) if quick else (7, 5)
    work = {
        "response": lambda: qc.forced_response(car, T, U, np.zeros(4), method="rk4"),
        "control": lambda: control.forced_response(car, T, U, np.zeros(4)),
        "sweep": lambda: sweep(grid, T, np.zeros(4), U=U, progress=False),
    }
    light = {"response": work["response"], "sweep": work["sweep"]}
    found: dict = {}
    for busy in (False, True):
        with other_cores_busy(busy):
            found[busy, "one"] = interleaved(work, rounds, calls if not quick else 1)
            with blas_threads_of_the_machine():
                found[busy, "all"] = interleaved(light, rounds, calls)
    cores = os.cpu_count() or 2
    rows, missed = [], []
    for key, label in (
        ("response", "qc.forced_response, RK4"),
        ("sweep", f"qc.sweep, {designs:,} designs"),
    ):
        for limit, how in (
            ("one", "one BLAS thread (the library's)"),
            ("all", f"{cores} BLAS threads"),
        ):
            quiet, loaded = found[False, limit][key], found[True, limit][key]
            kept = quiet / loaded
            target = "≥ 0.67" if limit == "one" else ""
            rows.append([label, how, g(quiet * 1e3), g(loaded * 1e3), g(kept), target])
            if limit == "one" and not quick and kept < 2 / 3:
                missed.append(
                    f"{label} kept {g(kept)} of its quiet speed when busy (target ≥ 0.67)"
                )
    ratio = {b: found[b, "one"]["control"] / found[b, "one"]["response"] for b in (False, True)}
    rows.append(
        ["control.forced_response", "", g(found[False, "one"]["control"] * 1e3),
         g(found[True, "one"]["control"] * 1e3), "", ""]
    )  # fmt: skip
    rows.append(
        [
            "× control (response)",
            "one BLAS thread",
            g(ratio[False]),
            g(ratio[True]),
            "",
            "≥ 60 busy",
        ]
    )
    if not quick and ratio[True] < 60:
        missed.append(f"one response on a busy machine: {g(ratio[True])}× control (target ≥ 60)")
    head = ["workload", "BLAS", "quiet [ms]", "busy [ms]", "speed kept", "target"]
    lines = section(
        "Quiet and busy",
        f"The road step on {n:,} samples; busy: one CPU-bound process on each of the "
        f"other {max(1, cores - 1)} core(s). Median of {rounds} rounds, the best of "
        f"{calls} calls in each, the workloads in turns. 'speed kept' is quiet time / "
        "busy time.",
        head,
        rows,
    )
    return lines, head, rows, missed


def take(md: list[str], lines: list[str], head, rows) -> None:
    """A section into RESULTS.md's lines, and its table on the terminal as it comes."""
    md.extend(lines)
    print("\n" + table(head, rows))


def put(md: list[str], title: str, text: str, head, rows, *notes: str) -> None:
    """A section made here, with any paragraphs that read its table."""
    take(md, section(title, text, head, rows, *notes), head, rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke mode: small sizes, 1 repeat")
    ap.add_argument(
        "--out",
        default=None,
        help="where to write RESULTS.md "
        "(default benchmarks/RESULTS.md; --quick writes nothing unless given)",
    )
    ap.add_argument(
        "--loop",
        action="store_true",
        help="only the generic stepper against the hand-written loops (full size); "
        "prints its table, writes nothing",
    )
    ap.add_argument(
        "--only",
        choices=["interconnect", "mpc", "identify", "peers", "explore", "busy"],
        default=None,
        help="run one benchmark alone and print its table (writes nothing); "
        "'interconnect': car + clipped skyhook, qc RK4 against control.input_output_response",
    )
    args = ap.parse_args(argv)
    quick = args.quick
    global WARMUP
    WARMUP = not quick
    alone = {
        "interconnect": lambda: table(*interconnect_benchmark(quick)[1:]),
        "mpc": lambda: "\n".join(mpc_benchmark(quick)[0] + mpc_solvers_benchmark(quick)[0]),
        "identify": lambda: table(*identification_benchmark(quick)[1:3]),
        "peers": lambda: table(*work_precision_benchmark(quick)[1:]),
        "explore": lambda: (
            table(*explore_benchmark(quick))
            + "\n\n"
            + "\n".join(browser_redraw_benchmark(quick)[0])
        ),
        "busy": lambda: table(*busy_benchmark(quick)[1:3]),
    }
    if args.only is not None:
        print(alone[args.only]())
        return 0
    repeats = 1 if quick else 7
    n_samples = 1001 if quick else 10001  # the default grid: 0-10 s at 1 ms
    T = np.linspace(0.0, 10.0, n_samples)
    h = T[1] - T[0]
    sys_free = qc.quarter_car()
    sys_road = qc.quarter_car(road=True)
    U = np.where(T >= 0.5, 0.05, 0.0)  # a 5 cm road step at 0.5 s
    A = np.asarray(sys_free.A)
    f = lambda t, x: A @ x  # noqa: E731
    if args.loop:
        head, rows, text = loop_comparison(f, T, 15)
        print(f"{text}\n{n_samples} samples, h = {h * 1e3:g} ms\n\n{table(head, rows)}")
        return 0
    md = ["# qc_control benchmarks", ""]
    say = print

    say(
        f"qc_control benchmarks ({'quick smoke mode' if quick else 'full'}): "
        f"{n_samples} samples, h = {h * 1e3:g} ms, {repeats} repeats"
    )

    # -- the problem and its reference
    exact_free = control.initial_response(sys_free, T, X0)
    lam, V = np.linalg.eig(A)
    closed = (V @ (np.linalg.solve(V, X0.astype(complex))[:, None] * np.exp(np.outer(lam, T)))).real
    ref_err = float(np.max(np.abs(exact_free.states - closed)))
    md += [
        "## Problem",
        "",
        f"The seed's quarter car, body released from 5 cm (X0 = [0, 0, 0.05, 0]), 0-10 s "
        f"on {n_samples} samples (h = {h * 1e3:g} ms); forced case: a 5 cm road step at "
        "0.5 s with `quarter_car(road=True)`.",
        "",
        "## Reference",
        "",
        f"`control.initial_response` / `forced_response` (matrix exponential, exact for "
        f"inputs linear between samples). Against the modal closed form V·exp(Λt)·V⁻¹·x0 "
        f"the free reference is within {g(ref_err)} m.",
        "",
    ]

    # -- 1. LTI engine and generic stepper against control, every method
    # each method's response and control's, in alternating rounds of consecutive calls
    rounds = 1 if quick else 5
    rows, lti_times, control_free, control_road = [], {}, [], []
    for m in qc.METHODS:
        t_lf, c_free, r_free = round_times(
            lambda: qc.initial_response(sys_free, T, X0, method=m),
            lambda: control.initial_response(sys_free, T, X0),
            rounds,
            repeats,
        )
        t_lr, c_road, r_road = round_times(
            lambda: qc.forced_response(sys_road, T, U, X0, method=m),
            lambda: control.forced_response(sys_road, T, U, X0),
            rounds,
            repeats,
        )
        control_free += c_free
        control_road += c_road
        t_gf = best_of(
            lambda: qc.initial_response(sys_free, T, X0, method=m, engine="generic"),
            max(1, repeats // 3),
        )
        lti = qc.initial_response(sys_free, T, X0, method=m)
        gen = qc.initial_response(sys_free, T, X0, method=m, engine="generic")
        gap = float(np.max(np.abs(lti.states - gen.states)) / np.max(np.abs(gen.states)))
        lti_times[m] = statistics.median(t_lf)
        rows.append(
            [
                m,
                g(statistics.median(t_lf) * 1e3),
                med_spread(r_free),
                g(statistics.median(t_lr) * 1e3),
                med_spread(r_road),
                g(t_gf * 1e3),
                g(gap, 2),
            ]
        )
    t_ci, t_cf = statistics.median(control_free), statistics.median(control_road)
    head = [
        "method",
        "LTI free [ms]",
        "× control.initial_response",
        "LTI road step [ms]",
        "× control.forced_response",
        "generic free [ms]",
        "LTI vs generic (rel.)",
    ]
    md += [
        "## Results",
        "",
        "### The LTI engine against python-control",
        "",
        f"control.initial_response: {g(t_ci * 1e3)} ms; control.forced_response "
        f"(road step): {g(t_cf * 1e3)} ms (medians). Each method's response and control's "
        f"in {rounds} alternating rounds of {repeats} consecutive calls each, wall time: a "
        "round's time is the best of its calls (`round_times`), the times below the "
        "median over rounds, the ratio columns the median (min–max) of the rounds' ratios.",
        "",
        table(head, rows),
        "",
    ]
    say(f"\ncontrol.initial_response {t_ci * 1e3:.3g} ms, forced_response {t_cf * 1e3:.3g} ms")
    say(table(head, rows))
    missed = [
        f"{row[0]}'s single {kind} response, {row[col]}x control, is below its target ≥ 60"
        for row in rows
        for kind, col in (("free", 2), ("road-step", 4))
        if float(row[col].split()[0]) < 60
    ]

    # -- 2. generic stepper against hand-written loops (Python f)
    head, rows, text = loop_comparison(f, T, 1 if quick else 15)
    put(
        md,
        "The generic stepper against a hand-written loop",
        text,
        head,
        rows,
    )

    # -- 3. work-precision: each method over h; solve_ivp over rtol
    rows = []
    wp_T = {}
    for hh in [0.01, 0.005] if quick else [0.01, 0.005, 0.002, 0.001, 0.0005]:
        Th = np.linspace(0, 10, int(round(10 / hh)) + 1)
        ex = control.initial_response(sys_free, Th, X0).outputs[0]
        wp_T[hh] = (Th, ex)
        for m in qc.METHODS:
            r = qc.initial_response(sys_free, Th, X0, method=m)
            err = float(np.max(np.abs(r.outputs[0] - ex)))
            t_run = best_of(lambda: qc.initial_response(sys_free, Th, X0, method=m), repeats)
            rows.append([m, f"h = {hh * 1e3:g} ms", g(err), str(r.nfev), g(t_run * 1e3)])
    ivp = {}
    Tq, exq = wp_T[min(wp_T)]
    for solver in ("RK45", "DOP853"):
        for k in [4, 8] if quick else [4, 6, 8, 10, 12]:
            rtol = 10.0**-k
            sol = solve_ivp(f, (0, 10), X0, method=solver, t_eval=Tq, rtol=rtol, atol=rtol * 1e-2)
            err = float(np.max(np.abs(sol.y[2] - exq)))
            t_run = best_of(
                lambda: solve_ivp(
                    f, (0, 10), X0, method=solver, t_eval=Tq, rtol=rtol, atol=rtol * 1e-2
                ),
                repeats,
            )
            ivp[(solver, k)] = (err, t_run, sol.nfev)
            rows.append([solver, f"rtol = 1e-{k}", g(err), str(sol.nfev), g(t_run * 1e3)])
    head = ["method", "setting", "max |xs error| [m]", "RHS evaluations", "time [ms]"]
    put(
        md,
        "Work and precision",
        "Error against control's exact response over "
        "0-10 s; solve_ivp evaluated at the finest grid's points (t_eval).",
        head,
        rows,
    )

    # solve_ivp at the tolerance that first reaches RK4's error on the default grid
    rk4_err = float(
        np.max(
            np.abs(
                qc.initial_response(sys_free, T, X0, method="rk4").outputs[0]
                - exact_free.outputs[0]
            )
        )
    )
    rows = []
    for solver in ("RK45", "DOP853"):
        reached = sorted((k, v) for (s, k), v in ivp.items() if s == solver and v[0] <= rk4_err)
        if reached:
            k, (err, t_run, nfev) = reached[0]
            rows.append(
                [solver, f"1e-{k}", g(err), str(nfev), g(t_run * 1e3), g(t_run / lti_times["rk4"])]
            )
        else:
            rows.append([solver, "none tried", "–", "–", "–", "–"])
    head = [
        "solver",
        "rtol reaching RK4's error",
        "error [m]",
        "RHS evaluations",
        "time [ms]",
        "× qc RK4 (LTI)",
    ]
    md += [
        f"solve_ivp at the loosest tried tolerance whose error is at most RK4's on the "
        f"default grid ({g(rk4_err)} m):",
        "",
        table(head, rows),
        "",
    ]
    say("\n" + table(head, rows))

    # -- 4. sweeps against loops of control calls, memory, spectral, scaling, Dask
    head, rows, n_designs = sweep_comparison(T, quick)
    missed += [
        f"the {row[0]} sweep's ratio, {row[4]}, is below its target {row[5]}"
        for row in rows
        if float(row[4].split()[0]) < float(row[5].split()[-1])
    ]
    put(
        md,
        "Design sweeps",
        f"{n_designs} designs (ks × ζ grid), RK4 at h = {h * 1e3:g} ms, {n_samples} samples; "
        f"the sweep computes its {len(DEFAULT_METRICS)} default metrics per design "
        f"({', '.join(DEFAULT_METRICS)}), streamed; the loop only calls control (systems "
        f"built beforehand). Medians of {1 if quick else 5} runs on each side, alternating, "
        "with (min–max); "
        "the ratio is the median of the runs' ratios.",
        head,
        rows,
        "What bounds the forced sweep: per sample and design, the road's effect inside a "
        "block is one product of (L+1) input samples with the design's p·L coefficients "
        "(2(L+1)p flops, L = 16, p = 4 outputs read) and the carries' part is 2np flops; "
        "both run as small per-design BLAS products, and the streamed reductions (sums of "
        "squares, peaks, the settling time's excursions, lift-off counts) read every "
        "sample once. The free sweep has no input product, and most of its samples are "
        "never computed: its RMS values come from the block Gram form of the step map, "
        "the stream stops once a modal bound on every later output (`lti.TailBound`) "
        "shows that no later sample can move a peak, a lift-off count or the largest "
        "excursion (after about 1–2 segments of 640 samples here), and the settling "
        "time comes from a backward search from where the bound proves the body inside "
        "its 2 % band. What remains is per chunk: validating designs, building each "
        "chunk's step maps, power tables, Gram sums and eigendecompositions.",
    )

    head, rows, worst = memory_and_spectral(T, quick)
    missed += [
        f"the {row[0]} sweep of {row[1]} designs peaked at {row[4]} MB (target ≤ 500 MB)"
        for row in rows
        if float(row[4]) > 500
    ]
    if float(rows[-1][3].split()[0]) > 1.0:
        missed.append(f"the spectral sweep took {rows[-1][3]} s (target ≤ 1 s)")
    put(
        md,
        "10,000 designs: peak memory, and the spectral sweep",
        "Peak memory by tracemalloc (numpy's buffers included) above what was live before "
        "the call; times of one run for the simulated sweeps and median (min–max) of 5 for "
        "the spectral one (`qc.sweep(grid, road=qc.ISO8608Road('C', speed=20))`: batched "
        "Lyapunov equations, exact over the unbounded band). Targets: ≤ 500 MB, spectral "
        f"≤ 1 s. Spectral sweep against one design at a time: largest relative difference "
        f"{g(worst, 2)} (target ≤ 1e-9).",
        head,
        rows,
    )

    head, rows = scaling(quick, Path(__file__).parent)
    put(
        md,
        "Scaling",
        "Road-step sweeps (RK4, h = 1 ms, default metrics): time (median of 3 runs, 1 for "
        "the largest) and peak memory against the number of designs and of samples; the "
        "slope is that of the least-squares line in log-log "
        + ("(plot: `benchmarks/scaling.png`)." if not quick else "(quick mode: no plot)."),
        head,
        rows,
        "Time is linear in both (slope near 1) once the fixed costs (validating designs, "
        "building each chunk's powers) are amortised. Memory grows with the samples only "
        "through the input itself (T, U and its padded copy: 24 bytes a sample); a chunk "
        "holds a segment of outputs (~1 MB) and a run of block carries (~2 MB) whatever the "
        "length. It grows with the designs through what is kept per design: the parameters, "
        "their matrices and the result table (about 1 kB a design).",
    )
    if not quick:
        md += ["![scaling](scaling.png)", ""]

    dask_rows = dask_comparison(quick)
    if dask_rows is not None:
        head, rows = dask_rows
        put(
            md,
            "Distributed: Dask LocalCluster",
            "A road-step sweep (1001 samples) on a two-worker `LocalCluster` (one thread "
            "each) against one process, chunks of `chunk_size` designs sent with "
            "`client.get_executor()`. The overhead per chunk is CPU time: the client's and "
            "the workers' during the Dask run, less the single process's, per chunk "
            "(pickling each chunk's matrices and results, scheduling, and the workers' "
            "allocator). Dask's nanny starts workers with `MALLOC_TRIM_THRESHOLD_=65536`, "
            "which makes glibc map every block above 128 kB afresh: each chunk's "
            "megabyte-sized arrays then cost page faults, which is most of the default "
            "row's overhead; `qc_control.studies.sweeps.DASK_WORKER_ENV` keeps them in the heap "
            "(second row; a negative overhead means the workers' allocator beat the "
            "single process's). The wall-clock "
            "speed-up is bounded by the cores actually free: on this 2-core machine shared "
            "with other work, less than two.",
            head,
            rows,
        )
    lines, head, rows = interconnect_benchmark(quick)
    take(md, lines, head, rows)
    missed += [
        f"car + skyhook, {row[0]}: {row[2]}x control (target ≥ 5)"
        for row in rows
        if "fast path" in row[0] and float(row[2]) < 5
    ]
    lines, head, rows = nonlinear_sweep_benchmark(quick)
    take(md, lines, head, rows)
    missed += [
        f"the nonlinear sweep on {row[0]}: {row[5]}x a loop of control (target ≥ 300)"
        for row in rows
        if float(row[5]) < 300
    ]
    lines, head, rows = mpc_benchmark(quick)
    md += lines
    say("\n" + "\n".join(lines))
    missed += [
        f"MPC step from {row[0]}: {row[3]}x solve_optimal_trajectory (target ≥ 1000)"
        for row in rows[:-1]
        if not quick and float(row[3]) < 1000
    ]
    lines, head, rows, late = mpc_solvers_benchmark(quick)
    take(md, lines, head, rows)
    missed += late

    lines, head, rows, late = busy_benchmark(quick)
    take(md, lines, head, rows)
    missed += late

    lines, head, rows = browser_redraw_benchmark(quick)
    md += lines
    say("\n" + "\n".join(lines))
    missed += [
        f"the explorer's median redraw in the browser, {row[2]} ms {row[0]}, is over 300 ms"
        for row in rows
        if not quick and row[0] == "quiet" and float(row[2]) > 300
    ]

    lines, head, rows, late = identification_benchmark(quick)
    take(md, lines, head, rows)
    missed += late

    lines, head, rows = work_precision_benchmark(quick)
    take(md, lines, head, rows)

    md += [
        "## What failed",
        "",
        "Nothing raised. solve_ivp's error at loose tolerances includes the interpolation "
        "of its dense output at t_eval; that is how it is used.",
        "",
        *(
            [f"Targets missed in this run: {'; '.join(missed)}.", ""]
            if missed
            else ["Every target above was met in this run.", ""]
        ),
        "## Conclusion",
        "",
        "Ratios above are this run's; the targets are ≥ 60× control for single "
        "responses (issue 15), ≤ 1.2× a hand loop for the generic stepper, ≥ 300× "
        "(free) and ≥ 100× (road step) a loop of control calls for the sweeps, ≤ 500 MB "
        "for 10,000 designs and ≤ 1 s for a 10,000-design spectral sweep (issue 15); "
        "≥ 5× control's `input_output_response` for the car + skyhook at a fixed step "
        "and ≥ 300× a loop of it for 1,000 nonlinear designs (issue 11).",
        "",
        "## Versions and command",
        "",
        f"python {platform.python_version()}, qc_control {qc.__version__}, python-control "
        f"{control.__version__}, numpy {np.__version__}, scipy {scipy.__version__}; "
        f"{platform.system()} {platform.machine()}, {platform.processor() or 'cpu'}; "
        f"{dt.datetime.now().isoformat(timespec='seconds')}.",
        "",
        "```",
        "python benchmarks/run.py" + (" --quick" if quick else ""),
        "```",
        "",
    ]
    out = args.out or (None if quick else str(Path(__file__).with_name("RESULTS.md")))
    if out:
        Path(out).write_text("\n".join(md), encoding="utf-8")
        say(f"\nwrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
