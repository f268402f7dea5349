"""The quarter-car model of the seed paper as a ``control.StateSpace``.

Two masses, the sprung body ``ms`` and the unsprung wheel ``mu``, joined by
the suspension spring ``ks`` and damper ``cs``; the wheel stands on the road
through the tire spring ``ku``. With the seed's state vector
``x = [xs', xu', xs, xu]`` the equations of motion (seed, section 4.1)

.. math::

    m_s \\ddot x_s + c_s(\\dot x_s - \\dot x_u) + k_s(x_s - x_u) = f_a

    m_u \\ddot x_u + c_s(\\dot x_u - \\dot x_s) + k_s(x_u - x_s)
        + k_u (x_u - z_r) = -f_a

become ``dx/dt = A x + B u`` with the seed's matrix ``A`` (section 4.2).
All quantities are SI: kg, N/m, N·s/m, m, s.

A tire damping ``cu`` (default 0, the seed's car) adds ``cu (x_u' - z_r')``
to the tire force. The road's rate is never formed: the second state becomes
``q = x_u' - (cu/mu) z_r``, whose equation holds no ``z_r'`` (the tire
damper's ``cu z_r'/mu`` is exactly ``(cu/mu) z_r``'s rate), and ``xu' = q +
(cu/mu) z_r``. With ``cu = 0``, ``q`` is the seed's ``xu'`` and every matrix
is the seed's.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any

import control
import numpy as np

from ..numerics.checks import Field, ParameterError, blamed_field, check_fields, instance_from
from .vehicle import STANDARD_GRAVITY, BatchedModel, Corner, SignalRoles, VehicleModel, params_as

__all__ = [
    "QuarterCarParams",
    "quarter_car",
    "quarter_car_model",
    "quarter_car_abcd",
    "as_params",
    "seed_matrices",
    "SEED_X0",
    "STATES",
    "OUTPUTS",
    "UNITS",
    "MOUNT_STATE",
    "check_mount_stiffness",
    "mounted_abcd",
]

#: State names: the seed's ``[xs', xu', xs, xu]``.
STATES = ("vs", "vu", "xs", "xu")
#: Output names, in order.
OUTPUTS = ("xs", "xu", "susp_travel", "tire_defl", "body_acc")
#: The largest ratio of the fastest to the slowest of a vehicle's rates
#: (sqrt(k/m), c/m) that the parameter classes (this car's, the half and full
#: car's) accept; see `QuarterCarParams`'s validation.
MAX_RATE_SPAN = 1e7
#: The seed's initial state: the body released from 5 cm, at rest [m/s, m/s, m, m].
SEED_X0 = (0.0, 0.0, 0.05, 0.0)
#: The SI unit of every signal of the quarter car.
UNITS = {
    "vs": "m/s",
    "vu": "m/s",
    "xs": "m",
    "xu": "m",
    "zr": "m",
    "fa": "N",
    "susp_travel": "m",
    "tire_defl": "m",
    "body_acc": "m/s²",
    "xd": "m",
}
#: The extra state of a car with a damper top mount: the displacement of the
#: damper's upper end, between the damper and the mount's spring [m].
MOUNT_STATE = "xd"

#: Each parameter declared once: what it is, its SI unit, its range. The
#: constructor validates from it, `QuarterCarParams.table` reports from it.
_SPEC = {
    "ms": Field("sprung mass", "kg"),
    "mu": Field("unsprung mass", "kg"),
    "ks": Field("suspension stiffness", "N/m"),
    "ku": Field("tire stiffness", "N/m"),
    "zeta": Field("nominal damping ratio cs/(2√(ks·ms))", "-", "nonneg", optional=True),
    "cs": Field("suspension damping", "N·s/m", "nonneg", optional=True),
    "cu": Field("tire damping", "N·s/m", "nonneg"),
}
#: The damper's top mount (`quarter_car`'s ``mount_stiffness``); None: no mount.
_MOUNT_STIFFNESS = Field("the damper's top mount", "N/m", optional=True)


@dataclass(frozen=True)
class QuarterCarParams:
    """Physical parameters of the quarter car, in SI units.

    Defaults are the seed paper's Table 1.

    Parameters
    ----------
    ms : float
        Sprung (body) mass [kg], > 0. Default 301.2.
    mu : float
        Unsprung (wheel) mass [kg], > 0. Default 100.
    ks : float
        Suspension stiffness [N/m], > 0. Default 30000.
    ku : float
        Tire stiffness [N/m], > 0. Default 29530.
    zeta : float, optional
        Nominal damping ratio [-], >= 0. Default 0.25 when ``cs`` is not
        given; derived from ``cs`` when only ``cs`` is given.
    cs : float, optional
        Suspension damping [N·s/m], >= 0. Derived from ``zeta`` when not
        given (seed, Table 1):

        .. math:: c_s = 2 \\zeta \\sqrt{k_s m_s}

    cu : float, optional
        Tire damping [N·s/m], >= 0. Default 0 (the seed's tire, a spring).

    Raises
    ------
    qc_control.ParameterError
        (a ``ValueError``) If a value is not a finite number (a bool is
        not), a mass or stiffness is not > 0, a damping value is < 0,
        ``zeta`` and ``cs`` are both given and disagree, or the car's time
        scales cannot be resolved (`_check_scales`). ``.name`` is the field,
        ``.value`` the value given; each field's description, unit and
        range are declared once, in ``_SPEC``.

    Notes
    -----
    The nominal ``zeta`` is the damping ratio the body would have on a
    rigid tire. On a soft tire the body mode's modal damping is lower; see
    `qc_control.modal_analysis`.

    Examples
    --------
    >>> p = QuarterCarParams()
    >>> round(p.cs, 3)
    1502.997
    >>> QuarterCarParams(cs=1000.0).cs
    1000.0
    """

    ms: float = 301.2
    mu: float = 100.0
    ks: float = 30000.0
    ku: float = 29530.0
    zeta: float | None = None
    cs: float | None = None
    cu: float = 0.0

    def __post_init__(self):
        check_fields(self, _SPEC)
        # 2·√ks·√ms rather than 2·√(ks·ms): the product overflows first
        critical = 2.0 * math.sqrt(self.ks) * math.sqrt(self.ms)
        if self.cs is None:
            zeta = 0.25 if self.zeta is None else self.zeta
            object.__setattr__(self, "zeta", zeta)
            object.__setattr__(self, "cs", zeta * critical)
        elif self.zeta is None:
            object.__setattr__(self, "zeta", self.cs / critical)
        elif not math.isclose(self.cs, self.zeta * critical, rel_tol=1e-9, abs_tol=1e-12):
            raise ParameterError(
                "cs",
                self.cs,
                f"2*zeta*sqrt(ks*ms) = {self.zeta * critical:.6g} N·s/m, as zeta={self.zeta!r} "
                f"gives (cs={self.cs!r} and zeta={self.zeta!r} disagree; give only one)",
                description=_SPEC["cs"].description,
            )
        self._check_scales()

    @classmethod
    def spec(cls) -> dict[str, Field]:
        """The fields, declared: ``{name: Field}`` (description, SI unit, range)."""
        return dict(_SPEC)

    def _check_scales(self) -> None:
        """Refuse a vehicle whose matrix overflows or whose modes cannot be resolved.

        Every entry of A must be finite, or no method can step the model. And
        the model's rates [1/s] (its eigenvalues lie among them): A's entries
        are rates and squared rates, so eigenvalues come out of double
        precision with a relative error of about eps·(fastest/slowest)²; beyond
        `MAX_RATE_SPAN` the slow mode loses its digits, and a fixed step that
        resolves the fast one would need more steps than any run can take.
        Light damping is harmless (a slow decay), so the slowest rate is a
        stiffness rate. (Plain arithmetic first: sweeps build thousands.)
        """
        ms, mu, ks, ku = self.ms, self.mu, self.ks, self.ku
        cs = float(self.cs)  # type: ignore[arg-type]  # resolved by __post_init__
        ratios = {
            "cs": cs,
            "ks/ms": ks / ms,
            "ks/mu": ks / mu,
            "ku/mu": ku / mu,
            "cs/ms": cs / ms,
            "cs/mu": cs / mu,
        }
        if not math.isfinite(sum(ratios.values())):
            what = next(k for k, v in ratios.items() if not math.isfinite(v))
            self._refuse(
                what,
                f"a value for which the model's matrix is finite, but {what} overflows to "
                f"{ratios[what]!r} for ms={ms!r}, mu={mu!r}, ks={ks!r}, ku={ku!r}",
            )
        rates = {
            "sqrt(ks/ms)": math.sqrt(ratios["ks/ms"]),
            "sqrt(ks/mu)": math.sqrt(ratios["ks/mu"]),
            "sqrt(ku/mu)": math.sqrt(ratios["ku/mu"]),
            "cs/ms": ratios["cs/ms"],
            "cs/mu": ratios["cs/mu"],
        }
        values = list(rates.values())
        if max(values) > MAX_RATE_SPAN * min(values[:3]):
            fast = max(rates, key=rates.__getitem__)
            slow = min(list(rates)[:3], key=rates.__getitem__)
            self._refuse(
                fast,
                f"a value whose modes can be resolved in double precision, but the vehicle's "
                f"time scales span more than {MAX_RATE_SPAN:.0e}: {fast} = {rates[fast]:.3g} "
                f"1/s against {slow} = {rates[slow]:.3g} 1/s (ms={ms!r}, mu={mu!r}, ks={ks!r}, "
                f"ku={ku!r}, cs={cs:.6g})",
            )

    def _refuse(self, rate: str, expected: str) -> None:
        """A `ParameterError` naming the field the refused ``rate`` most likely blames."""
        name = blamed_field(self, rate)
        raise ParameterError(
            name, getattr(self, name), expected, description=_SPEC[name].description
        )

    @property
    def system(self) -> control.StateSpace:
        """The plain quarter car (no inputs): ``quarter_car(self)``."""
        return quarter_car(self)

    def model(self, *, road: bool = False, actuator: bool = False) -> VehicleModel:
        """The quarter car as a `VehicleModel`: ``quarter_car_model(self, ...)``."""
        return quarter_car_model(self, road=road, actuator=actuator)

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any]) -> QuarterCarParams:
        """Build from a dict; an unknown key is a `qc_control.ParameterError` naming it."""
        return instance_from(cls, values)

    @classmethod
    def from_mappings(cls, designs: Sequence[Any]) -> list[QuarterCarParams | None]:
        """Many designs checked at once: each one's parameters, or None where
        only the one-by-one constructor can say (it raises, naming the value).

        The checks of ``__post_init__`` (finite; masses and stiffnesses > 0,
        damping >= 0; ``cs`` and ``zeta`` agree; `_check_scales`) run as one
        array expression per condition over the designs that are dicts of
        numbers, with the same formulas (``2·√ks·√ms``, ``math.isclose``'s
        test), so a design passes here only if the constructor accepts it, and
        gets the same values to the bit (IEEE square root and products). Any
        other design (a bad value, another type, an unknown key, a
        `QuarterCarParams` already) is left as None for the caller to build
        one by one. Used by `qc_control.studies.sweeps.sweep` on thousands of designs.
        """
        out: list[QuarterCarParams | None] = [None] * len(designs)
        names = ("ms", "mu", "ks", "ku", "zeta", "cs")
        # the common case, a grid: dicts with the same keys, one column per key
        keys = designs[0].keys() if designs and isinstance(designs[0], Mapping) else None
        # a tire damping is rare in a grid: such designs are built one by one
        if keys is None or not _FIELDS.issuperset(keys) or "cu" in keys:
            return out
        if not all(isinstance(d, Mapping) and d.keys() == keys for d in designs):
            return out
        columns = {}
        for key in keys:
            column = [d[key] for d in designs]
            # plain numbers only (bool, None, other types: one by one)
            if not _NUMBER_TYPES.issuperset(map(type, column)):
                return out
            try:
                columns[key] = np.array(column, dtype=float)
            except OverflowError:  # an int beyond float's range
                return out
        m = len(designs)
        seed = cls()  # the defaults of the fields not in the grid
        ms, mu, ks, ku = (
            columns[k] if k in columns else np.full(m, getattr(seed, k)) for k in names[:4]
        )
        zeta, cs = columns.get("zeta", np.nan), columns.get("cs", np.nan)
        has_zeta, has_cs = "zeta" in keys, "cs" in keys
        with np.errstate(all="ignore"):
            # each given value in its declared range, as check_fields finds it
            # (the defaults of the others are in theirs)
            ok = np.ones(m, dtype=bool)
            for name, given in columns.items():
                ok &= _SPEC[name].holds(given)
            critical = 2.0 * np.sqrt(ks) * np.sqrt(ms)
            if not has_cs:
                zeta = zeta if has_zeta else np.full(m, 0.25)
                cs = zeta * critical
            elif not has_zeta:
                zeta = cs / critical
            else:  # both: math.isclose(cs, zeta·critical, rel_tol=1e-9, abs_tol=1e-12)
                target = zeta * critical
                ok &= np.abs(cs - target) <= np.maximum(
                    1e-9 * np.maximum(np.abs(cs), np.abs(target)), 1e-12
                )
            # _check_scales, the same arithmetic in the same order
            ratios = [cs, ks / ms, ks / mu, ku / mu, cs / ms, cs / mu]
            ok &= np.isfinite(sum(ratios))
            rates = [np.sqrt(ratios[1]), np.sqrt(ratios[2]), np.sqrt(ratios[3]), *ratios[4:]]
            fastest, slowest = np.maximum.reduce(rates), np.minimum.reduce(rates[:3])
            ok &= ~(fastest > MAX_RATE_SPAN * slowest)
        values = np.stack([ms, mu, ks, ku, zeta, cs], axis=1)
        for i, (row, good) in enumerate(zip(values.tolist(), ok.tolist())):
            if good:  # what __post_init__ stores: seven Python floats
                p = object.__new__(cls)
                vars(p).update(zip(names, row), cu=0.0)
                out[i] = p
        return out

    def to_dict(self, *, changing: Iterable[str] | None = None) -> dict[str, float]:
        """The seven values as a plain dict (``cs`` and ``zeta`` both resolved).

        With ``changing``, the values to build a variant from when the fields
        in ``changing`` take new values: ``cs`` and ``zeta`` are one quantity,
        so ``cs`` is left out (it follows ``zeta``, ``ks`` and ``ms``) unless
        ``cs`` itself changes, and then ``zeta`` is left out.
        """
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        if changing is not None:
            values.pop("zeta" if "cs" in set(changing) else "cs")
        return values

    def table(self) -> list[tuple[str, str, float, str]]:
        """Rows ``(symbol, description, value, unit)`` for reports."""
        return [(n, f.description, getattr(self, n), f.unit) for n, f in _SPEC.items()]


_FIELDS = frozenset(f.name for f in fields(QuarterCarParams))


#: The value types `QuarterCarParams.from_mappings` checks in arrays (not bool).
_NUMBER_TYPES = frozenset({float, int, np.float64, np.float32, np.int64, np.int32})


def as_params(params) -> QuarterCarParams:
    """``params`` as `QuarterCarParams`: the seed's car for None, a dict by field name."""
    return params_as(QuarterCarParams, params)


def seed_matrices(ms, mu, ks, ku, cs, cu=0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The seed's ``A`` (section 4.2) and the road and actuator columns of ``B``.

    Takes numbers or equal-shaped arrays (a batch of designs) and returns
    ``A (..., 4, 4)``, ``b_road = [0, ku/mu, 0, 0]`` and
    ``b_act = [1/ms, -1/mu, 0, 0]``, each ``(..., 4)``. A tire damping
    ``cu`` (see the module's note: the second state is then
    ``q = xu' - (cu/mu) zr``) adds ``-cu/mu`` to ``A[1, 1]`` and
    ``r = cu/mu`` times ``[cs/ms, -(cs + cu)/mu, 0, 1]`` to ``b_road``.
    """
    ms, mu, ks, ku, cs, cu = np.broadcast_arrays(
        *(np.asarray(v, dtype=float) for v in (ms, mu, ks, ku, cs, cu))
    )
    zero, one = np.zeros_like(ms), np.ones_like(ms)
    A = np.stack(
        [
            np.stack([-cs / ms, cs / ms, -ks / ms, ks / ms], axis=-1),
            np.stack([cs / mu, -(cs + cu) / mu, ks / mu, -(ks + ku) / mu], axis=-1),
            np.stack([one, zero, zero, zero], axis=-1),
            np.stack([zero, one, zero, zero], axis=-1),
        ],
        axis=-2,
    )
    r = cu / mu  # xu' = q + r zr
    b_road = np.stack([cs * r / ms, ku / mu - (cs + cu) * r / mu, zero, r], axis=-1)
    b_act = np.stack([1.0 / ms, -1.0 / mu, zero, zero], axis=-1)
    return A, b_road, b_act


def quarter_car_abcd(ms, mu, ks, ku, cs, *, road: bool = False, actuator: bool = False, cu=0.0):
    """``A, B, C, D`` of the quarter car, for one design or a batch.

    Numbers give ``A (4, 4)``, ``B (4, k)``, ``C (5, 4)``, ``D (5, k)``;
    equal-shaped arrays of ``m`` designs give the same with a leading
    ``(m,)``. The inputs are ``zr`` (if ``road``) then ``fa`` (if
    ``actuator``); the outputs are `OUTPUTS`:
    ``xs``, ``xu``, ``susp_travel = xs - xu``, ``tire_defl = xu - zr`` and
    ``body_acc``, the first row of ``A x + B u`` (exact, no differencing).
    This is the one place the model's matrices are assembled: `quarter_car`
    and the sweep engine both read it. ``cu`` is the tire damping (default 0).
    """
    A, b_road, b_act = seed_matrices(ms, mu, ks, ku, cs, cu)
    batch = A.shape[:-2]
    columns = [b for b, on in ((b_road, road), (b_act, actuator)) if on]
    B = np.stack(columns, axis=-1) if columns else np.zeros(batch + (4, 0))
    C = np.zeros(batch + (5, 4))
    C[..., 0, 2] = C[..., 1, 3] = C[..., 2, 2] = C[..., 3, 3] = 1.0
    C[..., 2, 3] = -1.0
    C[..., 4, :] = A[..., 0, :]
    D = np.zeros(batch + (5, int(np.shape(B)[-1])))
    if road:
        D[..., 3, 0] = -1.0
    D[..., 4, :] = B[..., 0, :]
    return A, B, C, D


def check_mount_stiffness(value) -> float | None:
    """``value`` as a mount stiffness [N/m]: None (no mount) or a finite number
    > 0 (as declared in ``_MOUNT_STIFFNESS``), else a `qc_control.ParameterError`
    naming ``mount_stiffness``."""
    return _MOUNT_STIFFNESS.check("mount_stiffness", value)


def mounted_abcd(A, B, C, D, ms: float, mu: float, cs: float, km: float):
    """The quarter car's ``A, B, C, D`` with the damper on a top mount of stiffness ``km``.

    The mount is a spring in series with the damper (a Maxwell element). The
    damper's upper end ``xd`` is one more state: the series pair carries the
    force ``F = km (xs - xd) = cs (xd' - xu')`` (equal in the spring and the
    damper, as the point between them has no mass), which replaces the
    damper's ``cs (xs' - xu')`` on both masses, so

    .. math::

        \\dot x_d = \\dot x_u + \\frac{k_m}{c_s}(x_s - x_d)

    As ``km -> inf``, ``xd -> xs`` and the seed's car returns. The mount adds
    a real mode near ``-km/cs`` (the spring relaxing through the damper):
    with the seed's damper, -645 1/s at 1e6 N/m and -6,633 1/s at 1e7 N/m.
    The state is ``[vs, vu, xs, xu, xd]``; the outputs are unchanged, with
    ``body_acc`` still the first row of ``A x + B u``.
    """
    if not cs > 0:
        raise ParameterError(
            "cs",
            cs,
            "> 0 N·s/m with mount_stiffness: a damper top mount needs a damper",
            description=_SPEC["cs"].description,
        )
    A5 = np.zeros((5, 5))
    A5[:4, :4] = A
    # the damper's force on the masses becomes the mount's spring force km (xs - xd)
    A5[0, :2] = A5[1, :2] = 0.0
    A5[0, 2] += -km / ms
    A5[0, 4] = km / ms
    A5[1, 2] += km / mu
    A5[1, 4] = -km / mu
    A5[4, 1], A5[4, 2], A5[4, 4] = 1.0, km / cs, -km / cs
    B5 = np.vstack([B, np.zeros((1, B.shape[1]))])
    C5 = np.hstack([C, np.zeros((C.shape[0], 1))])
    C5[4, :] = A5[0, :]  # body_acc: the first row of A x + B u, as without the mount
    return A5, B5, C5, D


def _inputs(road: bool, actuator: bool) -> list[str]:
    return [label for label, on in (("zr", road), ("fa", actuator)) if on]


def quarter_car(
    params=None,
    *,
    road: bool = False,
    actuator: bool = False,
    name: str = "quarter_car",
    mount_stiffness: float | None = None,
) -> control.StateSpace:
    """The quarter car as a continuous-time ``control.StateSpace``.

    Parameters
    ----------
    params : QuarterCarParams or dict, optional
        Vehicle parameters; the seed's Table 1 when omitted.
    road : bool, default False
        Add the input ``'zr'`` [m], the road height under the tire,
        with ``B`` column ``[0, ku/mu, 0, 0]``.
    actuator : bool, default False
        Add the input ``'fa'`` [N], a force between the masses that pushes
        them apart, with ``B`` column ``[1/ms, -1/mu, 0, 0]``.
    name : str, default ``'quarter_car'``
        The system's name.
    mount_stiffness : float, optional
        The stiffness [N/m] of a rubber top mount in series with the damper
        (see `mounted_abcd`): one more state, ``xd``, the damper's upper
        end. None (default): the damper is fixed to the body, as the seed's.

    Returns
    -------
    control.StateSpace
        States ``['vs', 'vu', 'xs', 'xu']`` (seed: ``[xs', xu', xs, xu]``);
        inputs ``[]``, ``['zr']``, ``['fa']`` or ``['zr', 'fa']``; outputs

        - ``xs``, ``xu`` [m]: body and wheel displacement;
        - ``susp_travel = xs - xu`` [m];
        - ``tire_defl = xu - zr`` [m] (compression is negative);
        - ``body_acc = xs''`` [m/s²], the first row of ``A x + B u``,
          exact (no finite differences).

    Examples
    --------
    >>> import control
    >>> sys = quarter_car(road=True)
    >>> sys.input_labels, sys.nstates
    (['zr'], 4)
    >>> round(float(control.dcgain(sys)[0, 0]), 12)   # zr -> xs: the body follows the road
    1.0
    """
    p = as_params(params)
    km = check_mount_stiffness(mount_stiffness)
    if km is not None and p.cu:
        raise ParameterError(
            "mount_stiffness",
            km,
            f"None with tire damping (cu={p.cu!r} N·s/m): a damper top mount with tire "
            "damping is not modelled; give one of them",
            description=_MOUNT_STIFFNESS.description,
        )
    A, B, C, D = quarter_car_abcd(
        p.ms, p.mu, p.ks, p.ku, p.cs, road=road, actuator=actuator, cu=p.cu
    )
    states = list(STATES)
    if km is not None:
        A, B, C, D = mounted_abcd(A, B, C, D, p.ms, p.mu, float(p.cs), km)  # type: ignore[arg-type]
        states.append(MOUNT_STATE)
    return control.ss(
        A,
        B,
        C,
        D,
        states=states,
        inputs=_inputs(road, actuator),
        outputs=list(OUTPUTS),
        name=name,
    )


def quarter_car_model(
    params=None,
    *,
    road: bool = False,
    actuator: bool = False,
    mount_stiffness: float | None = None,
) -> VehicleModel:
    """The quarter car as a `VehicleModel`: `quarter_car` plus the roles of its signals.

    ``mount_stiffness`` [N/m] puts the damper on a top mount (`mounted_abcd`):
    five states, the fifth the damper's upper end ``xd``.

    The body acceleration is ``body_acc``, the body displacement ``xs``;
    its one corner has the travel ``susp_travel``, the tire deflection
    ``tire_defl``, the road ``zr`` (when ``road``), the tire stiffness
    ``ku`` and the static wheel load ``(ms + mu)·g``.

    Examples
    --------
    >>> m = quarter_car_model(road=True)
    >>> m.body_acc, m.corners[0].tire_defl, round(m.corners[0].static_load, 1)
    ('body_acc', 'tire_defl', 3934.4)
    """
    p = as_params(params)
    corner = Corner(
        "",
        "susp_travel",
        "tire_defl",
        "zr" if road else None,
        p.ku,
        (p.ms + p.mu) * STANDARD_GRAVITY,
    )
    km = check_mount_stiffness(mount_stiffness)
    batch = functools.partial(_quarter_car_batch, road=road, actuator=actuator)
    # partials of module-level functions, so that a model pickles to worker processes;
    # a mounted car's batch stacks one rebuild per design (the batch form is the seed's)
    return VehicleModel(
        quarter_car(p, road=road, actuator=actuator, mount_stiffness=km),
        p,
        UNITS,
        SignalRoles("body_acc", "xs", (corner,)),
        functools.partial(quarter_car_model, road=road, actuator=actuator, mount_stiffness=km),
        None if km is not None else batch,
    )


def _quarter_car_batch(designs, *, road: bool, actuator: bool) -> BatchedModel:
    """`quarter_car_model`'s matrices for many designs at once (no loop per design)."""
    ms, mu, ks, ku, cs, cu = (
        np.array([[d.ms, d.mu, d.ks, d.ku, d.cs, d.cu] for d in map(as_params, designs)])
        .reshape(-1, 6)
        .T
    )
    A, B, C, D = quarter_car_abcd(ms, mu, ks, ku, cs, road=road, actuator=actuator, cu=cu)
    return BatchedModel(A, B, C, D, (ku,), ((ms + mu) * STANDARD_GRAVITY,))
