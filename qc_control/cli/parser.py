"""The ``qc-control`` command: arguments become a `qc_control.Scenario`; the library runs it.

Exit status: 0 on success; 2 with one line on stderr for bad input (a bad
option or config value, an unusable ``--out``); 130 with one line on Ctrl-C;
1 with the traceback and a request to report it for anything else, which is
a bug in qc-control and is never passed off as a usage error. The last two
are `qc_control.cli.console`'s, the entry point that imports this module.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import warnings
from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import fields
from pathlib import Path
from typing import Any

import pandas as pd

from ..models.controllers import HINF_AVAILABLE
from ..models.modal import modal_analysis
from ..models.quarter import QuarterCarParams
from ..models.registry import MODELS, ModelOption, get_model, parameter_help, parameter_keys
from ..numerics.messages import install_hint
from ..report import ReportError, check_target, report_lock, report_path, write_report
from ..report.control import unavailable_designs, write_control_report
from ..ride.road import ISO8608Road
from ..studies.compare import ReferenceBudgetError
from ..studies.control_study import DESIGNS, compare_controllers
from ..studies.scenario import Scenario
from ..studies.scenario_command import command_line, option_flag, option_name, road_option
from ..studies.scenario_toml import (
    CLI_ROADS,
    DEFAULT_MODEL,
    ScenarioError,
    outside_level,
    road_from_mapping,
    run_keys,
    vehicle_config,
    vehicle_keys,
)
from .commands import COMMANDS, PROG, UsageError, error_line, top_level
from .measured import CommandTools as _CommandTools
from .measured import add_measured_commands

__all__ = ["run", "build_parser", "scenario_from_args", "summarise_warnings", "UsageError"]

#: ``--bump-height`` and ``--bump-length``: the nonlinear car's words of earlier versions for
#: the bump road's ``--road-height`` and ``--road-length`` (the same fields of the Scenario's
#: road), read for one more release with a deprecation warning naming the new spelling.
_BUMP_ALIASES = {"bump_height": "height", "bump_length": "length"}
#: The models ``control-report`` compares controllers on: the quarter car's linear model.
_CONTROL_MODELS = ("quarter",)


def _floats(text: str) -> list[float]:
    """``'a,b,c'`` as floats (the count is checked by the Scenario)."""
    try:
        return [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers, got {text!r}"
        ) from None


def _add_vehicle(
    parser: argparse.ArgumentParser, models: tuple[str, ...], scope: str = "runs"
) -> None:
    """``--model``, the ``models``' parameters and ``--config``.

    The parameters are listed in one argument group per set of models that
    takes them (every car's ``--ms``; the quarter and nonlinear car's
    ``--ks``; the full car's ``--track-front``), so a reader of ``--help``
    sees which apply to their model; a command offers only the models it runs
    (``scope`` says how, for the refusal of another: "compares controllers on").
    """
    group = parser.add_argument_group("vehicle")
    group.add_argument(
        "--model",
        type=_offered(f"{parser.prog.split()[-1]} {scope}", models),
        metavar="{" + ",".join(models) + "}",
        help="the vehicle: "
        + ", ".join(f"{name} ({get_model(name).description})" for name in models)
        + f"; default {DEFAULT_MODEL}",
    )
    group.add_argument(
        "--config",
        metavar="FILE.toml",
        help="TOML file: the vehicle's parameters at the top level and [scenario] model = "
        "NAME; for 'report' also the run's [scenario] keys and a [scenario.road] table (a "
        "report's scenario.toml), which the other commands do not read",
    )
    for users, keys in _by_models(
        {key: [m for m in names if m in models] for key, names in parameter_keys().items()}
    ).items():
        entry = get_model(users[0])
        title = "every car's" if len(users) == len(MODELS) > 1 else f"the {_cars(users)}'s"
        box = parser.add_argument_group(f"vehicle: {title} parameters (SI units)")
        for key in keys:
            box.add_argument(
                option_name(key),  # one spelling for options: --ks-front, as --t-end
                dest=key,
                type=float,
                metavar="X",
                help=f"{parameter_help(entry, key)}, overrides the config file",
            )


def _offered(command: str, models: tuple[str, ...]) -> Callable[[str], str]:
    """The reader of ``--model``: one of the ``models`` the ``command`` (its name
    and how it uses them) runs, else a complaint that says which it takes."""

    def model(text: str) -> str:
        if text in models:
            return text
        if text in MODELS:  # a model of the package that this command does not run
            raise argparse.ArgumentTypeError(
                f"{command} the {_cars(models)} only, got "
                f"--model {text}; the {text} car takes the passive tools (report, modes)"
            )
        raise argparse.ArgumentTypeError(
            f"invalid choice: {text!r} (choose from {', '.join(map(repr, models))})"
        )

    return model


def _by_models(users: dict[str, list[str]]) -> dict[tuple[str, ...], list[str]]:
    """Names grouped by the models that take them, in order of first appearance;
    names no offered model takes are left out."""
    groups: dict[tuple[str, ...], list[str]] = {}
    for name, models in users.items():
        if models:
            groups.setdefault(tuple(models), []).append(name)
    return groups


def _cars(models) -> str:
    """``'quarter and nonlinear car'``: models in a sentence."""
    return " and ".join(models) + " car"


def _add_road(parser: argparse.ArgumentParser) -> None:
    """One option per road parameter, read from the road kinds' fields: the same
    options for every model."""
    roads = [
        f"; the {name} car's: {road_from_mapping(entry.defaults.road or {}).describe()}"
        for name, entry in MODELS.items()
        if entry.defaults.road
    ]
    group = parser.add_argument_group(
        "road input, the same options for every model (default: none, the free response "
        "from --x0" + "".join(roads) + ")",
        "Each road parameter defaults to its function's default in qc_control.ride.road, except "
        "the speed, whose one default serves both bump and iso8608, and the parameters of a "
        "model's own default road, which a road of the same kind takes when not given.",
    )
    group.add_argument(
        "--road",
        dest="road_kind",
        metavar="KIND",
        help=f"{', '.join(CLI_ROADS)}; under a road the car starts at rest unless --x0 is given",
    )
    options: dict[str, list] = {}
    for kind, cls in CLI_ROADS.items():
        for f in fields(cls):
            options.setdefault(road_option(f), []).append((kind, f))
    types: dict[str, Callable[[str], Any]] = {
        "finite": float,
        "positive": float,
        "class": str,
        "seed": int,
        "band": _floats,
    }
    metavars = {"class": "A-H", "seed": "N", "band": "LO,HI"}
    for option, uses in options.items():
        f = uses[0][1]
        unit = f" [{f.metadata['unit']}]" if f.metadata["unit"] else ""
        defaults = ", ".join(f"{kind} {f.default!r}" for kind, f in uses)
        group.add_argument(
            option,
            dest=f"road_{f.name}",
            type=types[f.metadata["check"]],
            metavar=metavars.get(f.metadata["check"], "X"),
            help=f"{f.metadata['help']}{unit} (default: {defaults})",
        )
    for alias in _BUMP_ALIASES:  # deprecated: listed nowhere, still read
        group.add_argument(option_name(alias), type=float, help=argparse.SUPPRESS)


def _parse(option: ModelOption) -> Callable[[str], Any]:
    """The option's reader of text, its complaint in argparse's words."""

    def read(text: str):
        try:
            return option.parse(text)  # type: ignore[misc]  # only called when set
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    read.__name__ = option.name
    return read


def _add_model_options(parser: argparse.ArgumentParser) -> None:
    """Each registered model's own options (`ModelOption`), one group per set of
    models that takes them, with each model's default run."""
    users: dict[str, list[str]] = {}
    found: dict[str, ModelOption] = {}
    for entry in MODELS.values():
        for option in entry.options:
            users.setdefault(option.name, []).append(entry.name)
            found.setdefault(option.name, option)
    for models, names in _by_models(users).items():
        group = parser.add_argument_group(
            f"the {_cars(models)}'s options",
            "; ".join(f"{m} car's default run: {_default_run(m)}" for m in models),
        )
        for option in (found[n] for n in names):
            if isinstance(option.default, bool):
                group.add_argument(
                    option_flag(option.name, option.default),
                    dest=option.name,
                    action="store_false" if option.default else "store_true",
                    default=None,
                    help=f"not: {option.help}",
                )
                continue
            group.add_argument(
                option_name(option.name),
                type=str if option.parse is None else _parse(option),
                metavar=option.metavar,
                help=f"{option.help} (default {option.default})",
            )


def _default_run(name: str) -> str:
    """A model's default run in words, for ``--help``."""
    run = get_model(name).defaults
    road = run.road or {"kind": "none"}
    words = ", ".join(f"{k} {v}" for k, v in road.items() if k != "kind")
    return (
        f"0-{run.t_end:g} s at h = {run.h:g} s, road {road['kind']}"
        + (f" ({words})" if words else "")
        + ("; --road none for the free response" if run.road else "")
    )


def build_parser(model: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of ``qc-control``.

    Parameters
    ----------
    model : str, optional
        The model whose default run and state order ``report --help`` states
        (default the quarter car); every model's parameters and options are
        listed, grouped by the models that take them.
    """
    shown = model if model in MODELS else DEFAULT_MODEL
    parser, sub = top_level()
    modes = sub.add_parser("modes", help=COMMANDS["modes"], allow_abbrev=False)
    _add_vehicle(modes, tuple(MODELS))
    modes.set_defaults(run=_cmd_modes)
    _add_report(sub, shown)
    _add_control_report(sub, shown)
    add_measured_commands(sub, _CommandTools(UsageError, _check_out, _claimed))
    _add_explore(sub)
    return parser


def _add_explore(sub) -> None:
    """``qc-control explore``: the interactive explorer, served on 127.0.0.1."""
    explore = sub.add_parser("explore", help=COMMANDS["explore"], allow_abbrev=False)
    explore.add_argument(
        "--port",
        type=_port,
        default=5006,
        metavar="N",
        help="port on 127.0.0.1 (default 5006; 0: any free port)",
    )
    explore.add_argument(
        "--no-browser", action="store_true", help="serve the page without opening a browser"
    )
    explore.set_defaults(run=_cmd_explore)


def _port(text: str) -> int:
    try:
        port = int(text)
    except ValueError:
        port = -1
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port number 0-65535, got {text!r}")
    return port


def _cmd_explore(args) -> int:
    # the page's module imports Panel when it runs: the other commands never load it
    from .explore import ExplorerUnavailable, serve

    try:
        serve(port=args.port, show=not args.no_browser, say=lambda m: print(m, flush=True))
    except ExplorerUnavailable as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:  # the port is taken, or not ours to bind
        raise UsageError(f"--port {args.port}: cannot serve there: {exc.strerror or exc}") from None
    return 0


def _add_report(sub, shown: str) -> None:
    """``qc-control report``: the scenario's options."""
    report = sub.add_parser("report", help=COMMANDS["report"], allow_abbrev=False)
    _add_vehicle(report, tuple(MODELS))
    sc = report.add_argument_group(f"scenario (the {shown} car's default: {_default_run(shown)})")
    sc.add_argument(
        "--h",
        type=float,
        metavar="S",
        help="step size [s] (default the model's; under an ISO 8608 road, the largest of "
        "10, 5, 2, 1, 0.5, ... ms that samples the road)",
    )
    sc.add_argument("--t-end", type=float, metavar="S", help="end time [s]")
    sc.add_argument(
        "--x0",
        metavar=",".join(get_model(shown).model().system.state_labels).upper(),
        help="initial state, in the model's state order (default: the body released from "
        "5 cm; at rest under a road)",
    )
    sc.add_argument(
        "--methods", metavar="A,B,...", help="methods to compare (default euler,midpoint,heun,rk4)"
    )
    sc.add_argument(
        "--solvers",
        metavar="A,B,...",
        help="peers over rtol 1e-3 ... 1e-10: RK45, DOP853, LSODA, Radau, BDF (solve_ivp), "
        "control (input_output_response at its defaults)",
    )
    sc.add_argument(
        "--scenario",
        dest="kind",
        choices=("pothole", "stiff"),
        help="a run where the integrator decides the answer: the pothole, or the quarter car "
        "with a stiff damper top mount on an ISO 8608 road",
    )
    sc.add_argument(
        "--comfort",
        action="store_const",
        const=True,
        help="assess the exact ride to ISO 2631-1 in the report (per axis a_w, crest factor, "
        "MTVV, VDV; a_v, MSDV, Annex C's comfort words); needs a road",
    )
    sc.add_argument(
        "--seat-height",
        type=float,
        metavar="M",
        help="with --comfort, half/full car: the seat above the pitch and roll axes [m] "
        "(gives the fore-aft and lateral axes)",
    )
    sc.add_argument(
        "--exposure",
        type=float,
        metavar="H",
        help="with --comfort: daily exposure [h] for Annex B's health guidance (10 min-24 h)",
    )
    sc.add_argument(
        "--max-steps",
        type=int,
        metavar="N",
        help="refuse a run of more than N steps t_end/h per method (default 100000)",
    )
    _add_road(report)
    _add_model_options(report)
    report.add_argument(
        "--out",
        default="report",
        metavar="DIR",
        help="report directory (default report/); replaced only if it holds an earlier report",
    )
    report.add_argument(
        "-q", "--quiet", action="store_true", help="no progress lines on stderr, only the summary"
    )
    report.set_defaults(run=_cmd_report)


#: ``control-report``'s own options: (name, type, default, metavar, help).
_CONTROL_OPTIONS: tuple[tuple[str, Callable[[str], Any], Any, str, str], ...] = (
    ("road_class", str, "C", "A-H", "ISO 8608 class (default C)"),
    ("speed", float, 20.0, "M/S", "default 20"),
    ("road_duration", float, 10.0, "S", "road run [s] (default 10)"),
    ("bump_duration", float, 15.0, "S", "bump run [s] (default 15)"),
    ("method", str, "rk4", "NAME", "fixed-step method (default rk4)"),
    ("cmax", float, 4000.0, "N·S/M", "semi-active damper's largest damping (default 4000)"),
)


def _add_control_report(sub, shown: str) -> None:
    """``qc-control control-report``: the controller comparison's options."""
    ctl = sub.add_parser("control-report", help=COMMANDS["control-report"], allow_abbrev=False)
    _add_vehicle(ctl, _CONTROL_MODELS, "compares controllers on")
    ctl.add_argument(
        "--designs",
        metavar="A,B,...",
        help=f"designs to compare (default all: {', '.join(DESIGNS)}; 'hinf' for H∞, "
        "'lqr-sampled', 'mpc-preview-0.2' and 'mpc-preview-0.5' for the names with commas)",
    )
    for name, kind, default, metavar, help in _CONTROL_OPTIONS:
        ctl.add_argument(option_name(name), type=kind, default=default, metavar=metavar, help=help)
    ctl.add_argument("--out", default="control-report", metavar="DIR", help="report directory")
    ctl.add_argument("-q", "--quiet", action="store_true", help="no progress line on stderr")
    ctl.set_defaults(run=_cmd_control_report)


def scenario_from_args(args: argparse.Namespace):
    """The `qc_control.Scenario` of parsed arguments: ``--config``, then the options over it.

    The road options (``--road``, ``--road-height`` ...) over the config's road
    table become one `qc_control.road.Road` (`Scenario.from_mapping`), the road
    the Scenario is given.

    ``report`` reads the whole config; the other commands run no scenario and
    read only its vehicle (`vehicle_config`), so that a report's
    ``scenario.toml`` serves them too and its run's keys cannot be refused there.
    """
    doc: dict = {
        key: getattr(args, key) for key in vehicle_keys() if getattr(args, key, None) is not None
    }
    run = {k: getattr(args, k) for k in run_keys() if getattr(args, k, None) is not None}
    road, spelled = _road_options(args)
    if road:
        run["road"] = road
    if run:
        doc["scenario"] = run
    try:
        if not args.config:
            return Scenario.from_mapping({}, overrides=doc)
        if getattr(args, "command", "report") == "report":
            return Scenario.from_toml(args.config, overrides=doc)
        config = vehicle_config(args.config)
        return Scenario.from_mapping(config, overrides=doc, source=str(args.config))
    except ScenarioError as exc:
        raise UsageError(_in_options(exc, doc, spelled)) from None


def _road_options(args: argparse.Namespace) -> tuple[dict[str, Any], dict[str, str]]:
    """The road of the options, and the option each road key was given by.

    The deprecated ``--bump-height`` and ``--bump-length`` are read as
    ``--road-height`` and ``--road-length`` of a bump road, with a
    `DeprecationWarning` naming the new spelling.
    """
    road = {"kind": args.road_kind} if getattr(args, "road_kind", None) is not None else {}
    spelled = {"kind": "--road"} if road else {}
    for cls in CLI_ROADS.values():
        for f in fields(cls):
            value = getattr(args, f"road_{f.name}", None)
            if value is not None:
                road[f.name] = value
                spelled[f.name] = road_option(f)
    for alias, name in _BUMP_ALIASES.items():
        value = getattr(args, alias, None)
        if value is None:
            continue
        option, new = option_name(alias), option_name(f"road_{name}")
        if name in road:
            raise UsageError(f"{option} and {new} are the same value: give one")
        if road.get("kind", "bump") != "bump":
            raise UsageError(f"{option} applies to a bump road, not --road {road['kind']}")
        warnings.warn(
            f"{option} is deprecated and will be removed in the next release: use {new} "
            "(with --road bump; the nonlinear car's road is a bump by default)",
            DeprecationWarning,
            stacklevel=outside_level(),
        )
        road[name] = value
        road.setdefault("kind", "bump")
        spelled[name] = option
    return road, spelled


def _in_options(exc, doc: dict, spelled: Mapping[str, str]) -> str:
    """The error in the words of the command line: '--h must be ...' for a bad --h.

    ``spelled`` holds the option each road key was given by (``--bump-height``
    for ``height`` when the user wrote that).
    """

    key, section = exc.key, exc.section
    run = doc.get("scenario", {})
    if exc.source is not None:  # a value of the config file: its TOML key names it
        return str(exc)
    if section is None and key in doc and key != "scenario":
        option = option_name(key)
    elif section == "scenario" and key in run:
        option = _run_option(key)
    elif section == "scenario.road" and key in spelled:
        option = spelled[key]
    else:
        return str(exc)
    for lead in (f"{key} = ", f"{key}: ", f"{key} "):
        if exc.detail.startswith(lead):
            return option + lead[len(key) :].replace(" = ", " ") + exc.detail[len(lead) :]
    return str(exc)


#: ``[scenario]`` keys whose option is spelt otherwise (``kind`` is ``--scenario``).
_OPTION_OF = {"kind": "--scenario"}


def _run_option(key: str) -> str:
    """The option of a ``[scenario]`` key: ``--t-end``, or a model option's flag
    (``--no-events``) when the option is a boolean one."""
    if key in _OPTION_OF:
        return _OPTION_OF[key]
    flags = [o for e in MODELS.values() for o in e.options if o.name == key]
    if flags and isinstance(flags[0].default, bool):
        return option_flag(key, flags[0].default)
    return option_name(key)


def _cmd_modes(args) -> int:

    scenario = scenario_from_args(args)
    model = scenario.vehicle_model()
    # a nonlinear car has no matrix: its modes are those of the linear car of its parameters
    print(modal_analysis(model if hasattr(model.system, "A") else scenario.vehicle))
    return 0


def _check_out(out: str) -> Path:
    """``--out`` as a path the report can be written to, checked before any work.

    It must be an empty directory or an earlier report (the report writer's
    rule), or not exist yet; the directory that will hold it (the nearest
    existing ancestor) must be a directory this user can write in.
    """
    try:
        report_path(out)  # an empty name, a removed working directory
    except ReportError as exc:
        raise UsageError(str(exc)) from None
    path = Path(os.path.abspath(out))
    writable = lambda d: os.access(d, os.W_OK | os.X_OK)  # noqa: E731
    try:
        if path.exists():
            if not path.is_dir():
                raise UsageError(f"--out {out!r} is a file, not a report directory")
            try:  # the report's own rule: empty, or an earlier report holding only its files
                check_target(path)
            except ReportError as exc:  # in the words of the command line
                raise UsageError(str(exc).replace(repr(str(path)), repr(out))) from None
            # the new report replaces the old one by renames in the parent
            for d in (path.parent, path):
                if not writable(d):
                    raise UsageError(
                        f"--out {out!r} cannot be replaced: {str(d)!r} is not writable"
                    )
            return path
        ancestor = path.parent
        while not ancestor.exists():
            ancestor = ancestor.parent
        if not ancestor.is_dir():
            raise UsageError(f"--out {out!r} cannot be made: {str(ancestor)!r} is not a directory")
        if not writable(ancestor):
            raise UsageError(f"--out {out!r} cannot be made: {str(ancestor)!r} is not writable")
    except OSError as exc:
        raise UsageError(f"--out {out!r} cannot be checked: {exc.strerror}") from None
    return path


@contextlib.contextmanager
def _claimed(out: Path, given: str):
    """Hold ``--out``'s report lock from before the work until the report is written.

    A second run into the same place stops at once with one line, not after
    computing; runs into different directories, of one parent or not, go
    ahead together. Folders made on the way to ``--out`` for the lock file
    are removed again when the run writes nothing there.
    """
    made = [d for d in (out.parent, *out.parent.parents) if not d.exists()]
    stack = contextlib.ExitStack()
    try:
        stack.enter_context(report_lock(out))
    except ReportError as exc:
        raise UsageError(str(exc).replace(repr(str(out.resolve())), repr(given))) from None
    except OSError as exc:
        raise UsageError(f"--out {given!r} cannot be made: {exc.strerror or exc}") from None
    try:
        with stack:
            yield
    finally:
        for folder in made:  # the deepest first; one holding anything stays
            with contextlib.suppress(OSError):
                folder.rmdir()


def _cmd_report(args) -> int:
    scenario = scenario_from_args(args)
    out = _check_out(args.out)  # before the work, not after it
    with _claimed(out, args.out):
        return _report(args, scenario, out)


def _report(args, scenario: Scenario, out: Path) -> int:
    """Run the scenario and write its report into ``out`` (its lock held)."""

    say = (lambda message: None) if args.quiet else _progress
    for line in beyond_limit_warnings(scenario):  # before the work, even when quiet
        print(f"{PROG}: warning: {line}", file=sys.stderr, flush=True)
    if args.h is None and scenario.step_note():
        say(f"{PROG}: note: {scenario.step_note()}")
    road = scenario.road.describe()
    say(
        f"qc-control report: {', '.join(scenario.methods)} at h = {scenario.h:g} s over "
        f"0-{scenario.t_end:g} s" + (f" on {road}" if road else "") + "; each method is "
        "also run at h/2, h/4, ... for the convergence and cost figures"
    )
    try:
        cmp = scenario.run(progress=None if args.quiet else lambda m: _progress(f"  {m}"))
    except ReferenceBudgetError as exc:  # the scenario's system, not a bug: say what to change
        raise UsageError(str(exc)) from None
    try:
        path = write_report(cmp, out, command=scenario.command())
    except ReportError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        where = repr(exc.filename) if exc.filename else repr(args.out)
        raise UsageError(f"cannot write the report: {where}: {exc.strerror or exc}") from None
    with pd.option_context(
        "display.width", 160, "display.max_columns", 20, "display.float_format", "{:.4g}".format
    ):
        print(cmp.summary())
    print(
        f"\nwrote {path / 'report.html'} (one file, figures inside), {path / 'report.pdf'}, "
        f"report.md, the CSV tables, the figures and scenario.toml (the run, to redo it) "
        f"in {path}"
    )
    return 0


#: Short names on the command line: '--designs' splits on commas, which some names hold.
_DESIGN_ALIASES = {
    "hinf": "H∞",
    "h∞": "H∞",
    "lqr-sampled": "LQR, sampled",
    "mpc-preview-0.2": "MPC, preview 0.2 s",
    "mpc-preview-0.5": "MPC, preview 0.5 s",
}
_DESIGN_SHORT = {"H∞": "hinf", **{v: k for k, v in _DESIGN_ALIASES.items() if "," in v}}


def _designs(text: str | None) -> list[str]:
    if text is None:
        return [d for d in DESIGNS if d != "H∞" or HINF_AVAILABLE]
    names = [_DESIGN_ALIASES.get(n.strip().lower(), n.strip()) for n in text.split(",")]
    unknown = [n for n in names if n not in DESIGNS]
    if unknown:
        raise UsageError(f"--designs: unknown design {unknown[0]!r}; choose from {list(DESIGNS)}")
    if "H∞" in names and not HINF_AVAILABLE:
        raise UsageError(f"--designs: H∞ needs slycot: {install_hint('robust')}")
    return names


def _control_command(args, designs: list[str]) -> str:
    """The command line that redoes this control report."""
    options: list[tuple[str, str | None]] = []
    if getattr(args, "config", None):
        options.append(("--config", str(args.config)))
    for f in fields(QuarterCarParams):
        if getattr(args, f.name, None) is not None:
            options.append((option_name(f.name), repr(getattr(args, f.name))))
    options.append(("--designs", ",".join(_DESIGN_SHORT.get(d, d) for d in designs)))
    options += [(option_name(name), str(getattr(args, name))) for name, *_ in _CONTROL_OPTIONS]
    return command_line(["control-report"], [*options, ("--out", str(args.out))])


def _cmd_control_report(args) -> int:
    scenario = scenario_from_args(args)
    params = scenario.vehicle
    if scenario.model not in _CONTROL_MODELS or not isinstance(params, QuarterCarParams):
        # --model offers the quarter car only; another model comes from the config file
        raise UsageError(
            f"config file {args.config!r}: [scenario] model = {scenario.model!r}: "
            f"control-report compares controllers on the quarter car only; the "
            f"{scenario.model} car takes the passive tools (report, modes)"
        )
    designs = _designs(args.designs)
    out = _check_out(args.out)
    with _claimed(out, args.out):
        return _control_report(args, params, designs, out)


def _control_report(args, params: QuarterCarParams, designs: list[str], out: Path) -> int:
    """Compare the designs and write the report into ``out`` (its lock held)."""
    for design, why in unavailable_designs(designs).items():  # listed, not silently dropped
        print(f"{PROG}: warning: {design} {why}", file=sys.stderr, flush=True)
    if not args.quiet:
        _progress(f"qc-control control-report: {len(designs)} designs, bump and road runs")
    try:
        cmp = compare_controllers(
            params,
            designs=designs,
            road=ISO8608Road(args.road_class, speed=args.speed),
            road_duration=args.road_duration,
            bump_duration=args.bump_duration,
            method=args.method,
            cmax=args.cmax,
        )
    except ValueError as exc:  # the library names the bad value
        raise UsageError(str(exc)) from None
    command = _control_command(args, designs)
    try:
        path = write_control_report(cmp, out, command=command)
    except ReportError as exc:
        raise UsageError(str(exc)) from None
    with pd.option_context(
        "display.width", 200, "display.max_columns", 20, "display.float_format", "{:.4g}".format
    ):
        print(cmp.table)
    print(f"\nwrote {path / 'report.html'}, report.pdf, report.md, the CSV tables and figures")
    return 0


def beyond_limit_warnings(scenario: Scenario) -> list[str]:
    """One line per requested method whose stability limit the step exceeds.

    Each names the method, the step and the limit h_max, and what to change:
    such a method's response grows, so its errors measure the growth, not
    the method's accuracy.
    """
    lines = []
    for method, h_max in scenario.beyond_limits().items():
        if h_max > 0:
            lines.append(
                f"h = {scenario.h:g} s is beyond {method}'s stability limit h_max = {h_max:.3g} s "
                f"on this car ({100 * scenario.h / h_max:.0f}% of it): its response grows and "
                f"its errors mean nothing; give --h {h_max:.2g} or less, or leave {method} out "
                "of --methods"
            )
        else:  # an undamped mode on a method whose region holds no stretch of the imaginary axis
            lines.append(
                f"h = {scenario.h:g} s: {method} has no stable step on this car (h_max = 0 s, "
                f"an undamped mode): its response grows at every h; leave {method} out of "
                "--methods"
            )
    return lines


def _progress(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


#: numpy's floating-point warnings ("overflow encountered in exp"), in words
_FP_WORDS = {
    "overflow": "overflowed",
    "invalid value": "gave NaN",
    "divide by zero": "divided by zero",
    "underflow": "underflowed",
}


def summarise_warnings(caught) -> list[str]:
    """The run's warnings, each distinct one once, in words, with its count.

    numpy's floating-point warnings ("overflow encountered in square") are one
    line together: they come from a response that grew past float range, which
    the report already flags; a diverged run can raise dozens of them.
    """
    floating: Counter[str] = Counter()
    other: Counter[str] = Counter()
    for w in caught:
        text = " ".join(str(w.message).split())
        kind = text.split(" encountered in ")[0]
        if w.category is RuntimeWarning and kind in _FP_WORDS:
            floating[kind] += 1
        else:
            other[text] += 1
    lines = [text + (f" ({n} times)" if n > 1 else "") for text, n in other.items()]
    if floating:
        n = sum(floating.values())
        what = ", ".join(_FP_WORDS[k] for k in floating)
        lines.append(
            f"{n} floating-point operation{'s' if n > 1 else ''} {what}: a response "
            "grew beyond the range of floating point (a step beyond a stability limit, or an "
            "extreme design); the numbers it touched are inf or NaN"
        )
    return lines


def _model_named(argv: list[str]) -> str | None:
    """The ``--model`` of the command line, read ahead so that ``--help`` lists its options."""
    for i, word in enumerate(argv):
        if word == "--model" and i + 1 < len(argv):
            return argv[i + 1]
        if word.startswith("--model="):
            return word.partition("=")[2]
    return None


def run(argv: list[str]) -> int:
    """Run ``qc-control`` with the arguments ``argv``; returns the exit status.

    Bad input (a `UsageError` or `ScenarioError`) is one line on stderr and
    status 2. The entry point, `qc_control.cli.console.main`, handles Ctrl-C and
    internal errors around this call and around importing this module.
    """
    model = _model_named(argv)
    parser = build_parser() if model is None else build_parser(model)
    try:
        args = parser.parse_args(argv)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                return args.run(args)
            finally:
                for line in summarise_warnings(caught):
                    print(f"{PROG}: warning: {line}", file=sys.stderr)
    except SystemExit as exc:  # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    except (UsageError, ScenarioError) as exc:
        print(error_line(exc), file=sys.stderr)
        return 2
