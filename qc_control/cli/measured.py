"""``qc-control identify`` and ``qc-control iri``: measured records on the command line.

``identify DATA.csv --map zr=COL,fa=COL,... [--validate TEST.csv] [--gains fa]
[--fix ms=320] [--start ks=25000] --out DIR`` fits the quarter car and
writes the report (`qc_control.report.identification`); ``iri PROFILE.csv
--x COL --z COL [--segment 100]`` prints a profile's International
Roughness Index. Bad input is one line and exit status 2, as for every
command (`qc_control.cli.parser`).
"""

from __future__ import annotations

import functools
import math
import shlex
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from ..report.identification import write_identification_report
from ..ride.roughness import IRISegments, iri
from ..studies.identification import DEFAULT_FREE, PHYSICAL, identify
from ..studies.measurement import Measurement, read_csv, row_of
from .commands import COMMANDS

__all__ = ["add_measured_commands", "CommandTools"]


class CommandTools(NamedTuple):
    """What the commands share with `qc_control.cli.parser` (which imports this
    module): its usage error, its ``--out`` check and its report lock."""

    usage_error: type[Exception]
    check_out: Callable[[str], Path]
    claimed: Callable[[Path, str], Any]


def _pairs(text: str | None, option: str, convert=str) -> dict:
    """``a=1,b=2`` as ``{'a': convert('1'), 'b': convert('2')}``."""
    out: dict = {}
    for item in filter(None, (text or "").split(",")):
        key, sep, value = item.partition("=")
        if not sep or not key.strip() or not value.strip():
            raise ValueError(f"{option} expects NAME=VALUE pairs separated by commas, got {item!r}")
        try:
            out[key.strip()] = convert(value.strip())
        except ValueError:
            raise ValueError(f"{option}: {key.strip()}={value.strip()!r} is not a number") from None
    return out


def _names(text: str | None) -> list[str] | None:
    return None if text is None else [n.strip() for n in text.split(",") if n.strip()]


def add_measured_commands(sub, tools: CommandTools) -> None:
    """Add ``identify`` and ``iri`` to the ``qc-control`` sub-parsers."""
    ident = sub.add_parser("identify", help=COMMANDS["identify"], allow_abbrev=False)
    ident.add_argument("data", metavar="DATA.csv", help="the records to fit (CSV, a header line)")
    ident.add_argument("--time", default="t", metavar="COL", help="time column [s] (default t)")
    ident.add_argument(
        "--map",
        required=True,
        metavar="zr=COL,fa=COL,...",
        help="columns by the model's labels (zr, fa; xs, xu, susp_travel, tire_defl, "
        "body_acc, wheel_acc)",
    )
    ident.add_argument("--units", metavar="zr=mm,...", help="units not SI (mm, kN, g, ...)")
    ident.add_argument("--scale", metavar="fa=-1,...", help="factors applied on reading")
    ident.add_argument("--validate", metavar="TEST.csv", help="a held-out record, same columns")
    ident.add_argument("--gains", metavar="fa,...", help="inputs whose gain and sign are fitted")
    ident.add_argument("--fix", metavar="ms=320,...", help="parameters held at known values")
    ident.add_argument("--start", metavar="ks=25000,...", help="start values")
    ident.add_argument(
        "--free",
        metavar="NAME,...",
        help=f"parameters fitted, of {','.join(PHYSICAL)} (default {','.join(DEFAULT_FREE)}, "
        "less those --fix holds; the tire damping cu is bounded below by 0, so a car "
        "without tire damping fits to cu = 0)",
    )
    ident.add_argument("--outputs", metavar="LABEL,...", help="outputs fitted (default all)")
    ident.add_argument(
        "--x0", choices=("rest", "estimate"), default="rest", help="initial state (default rest)"
    )
    ident.add_argument("--out", default="identify-report", metavar="DIR", help="report directory")
    ident.set_defaults(run=functools.partial(_cmd_identify, tools=tools))

    rough = sub.add_parser("iri", help=COMMANDS["iri"], allow_abbrev=False)
    rough.add_argument("profile", metavar="PROFILE.csv", help="the profile (CSV, a header line)")
    rough.add_argument("--x", required=True, metavar="COL", help="distance column [m]")
    rough.add_argument("--z", required=True, metavar="COL", help="elevation column [m]")
    rough.add_argument(
        "--z-scale", type=float, default=1.0, metavar="F", help="factor to metres (mm: 0.001)"
    )
    rough.add_argument("--segment", type=float, metavar="M", help="IRI per segment of M metres")
    rough.set_defaults(run=functools.partial(_cmd_iri, tools=tools))


def _read(path: str, args, columns: dict) -> Measurement:
    return Measurement.from_csv(
        path,
        time=args.time,
        columns=columns,
        units=_pairs(args.units, "--units", _unit),
        scale=_pairs(args.scale, "--scale", float),
    )


def _unit(text: str):
    try:
        return float(text)
    except ValueError:
        return text


def _command(args) -> str:
    words = ["qc-control", "identify", args.data, "--time", args.time, "--map", args.map]
    for option in ("units", "scale", "validate", "gains", "fix", "start", "free", "outputs"):
        value = getattr(args, option)
        if value is not None:
            words += [f"--{option}", value]
    words += ["--x0", args.x0, "--out", args.out]
    return shlex.join(words)


def _cmd_identify(args, tools: CommandTools) -> int:
    out = tools.check_out(args.out)
    try:
        columns = _pairs(args.map, "--map")
        record = _read(args.data, args, columns)
        held = _read(args.validate, args, columns) if args.validate else None
        result = identify(
            record,
            free=_names(args.free),
            fixed=_pairs(args.fix, "--fix", float),
            start=_pairs(args.start, "--start", float),
            gains=_names(args.gains) or (),
            outputs=_names(args.outputs),
            x0=args.x0,
        )
    except ValueError as exc:
        raise tools.usage_error(str(exc)) from None
    with tools.claimed(out, args.out):
        write_identification_report(result, record, out, validation=held, command=_command(args))
    print(result)
    if held is not None:
        fit = result.validate(held)
        print("Validation fit [%]\n" + fit.to_string(float_format="{:.2f}".format))
    print(f"wrote {out}")
    return 0


def _profile(path: str, x_column: str, z_column: str) -> tuple[np.ndarray, np.ndarray]:
    """The distance and elevation columns of a profile's CSV; a cell that is not a
    number is named by its column and its line in the file."""
    frame, lines = read_csv(Path(path))
    found = []
    for column in (x_column, z_column):
        if column not in frame.columns:
            raise ValueError(f"column {column!r} is not among {list(frame.columns)}")
        values = pd.to_numeric(frame[column], errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise ValueError(
                f"column {column!r} is not a number at row {row_of(lines, int(bad[0]))} of {path!r}"
            )
        found.append(values)
    return found[0], found[1]


def _cmd_iri(args, tools: CommandTools) -> int:
    try:
        if not math.isfinite(args.z_scale) or args.z_scale == 0:
            raise ValueError(
                f"--z-scale must be a finite factor to metres, not 0 (mm: 0.001), "
                f"got {args.z_scale!r}"
            )
        x, z = _profile(args.profile, args.x, args.z)
        result = iri(x, args.z_scale * z, segment=args.segment)
    except ValueError as exc:
        raise tools.usage_error(str(exc)) from None
    if not isinstance(result, IRISegments):
        print(f"IRI {result:.3f} m/km over {x[-1] - x[0]:.6g} m")
        return 0
    table = pd.DataFrame({"from [m]": result.start, "to [m]": result.end, "IRI [m/km]": result.iri})
    print(table.to_string(index=False, float_format="{:.3f}".format))
    print(f"IRI {result.overall:.3f} m/km over the whole profile")
    return 0
