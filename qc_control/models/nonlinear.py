"""The nonlinear quarter car: wheel lift-off, bump stops, a nonlinear damper and spring.

The seed's two masses (`qc_control.models.quarter`), with the force elements made
nonlinear one at a time. Displacements are measured from the static
equilibrium (as in `qc_control.quarter_car`), so with every nonlinearity
off the model *is* the seed's linear one. With ``d = xs - xu`` the
suspension extension, ``v = vs - vu`` its rate, ``δ = xu - zr`` the tire
deflection (compression negative) and ``δ0 = (ms + mu) g / ku`` the static
tire compression:

.. math::

    m_s \\ddot x_s = -F_s(d) - F_d(v) - F_b(d) + f_a

    m_u \\ddot x_u = F_s(d) + F_d(v) + F_b(d) - f_a + F_t - k_u \\delta_0

where ``F_t`` is the tire's contact force (the output ``tire_force``):

* ``tire='linear'``: ``F_t = k_u (δ0 - δ)`` (it may pull: negative);
* ``tire='unilateral'``: ``F_t = max(0, k_u (δ0 - δ))`` — the wheel leaves
  the road when ``δ > δ0`` and flies, under gravity and the suspension, until
  it lands (point-contact tire, e.g. Rill, *Road Vehicle Dynamics*, CRC
  Press 2012, the tire as a unilateral spring).

Gravity and the static preloads cancel in both equations except where the
tire lets go, which is why a unilateral tire needs ``gravity=True`` to know
``δ0``; with ``gravity=False`` the static deflection is 0 (a tire without
preload, lifting at ``δ > 0``).

The force elements (each 0 at the static point, ``d = v = 0``):

* **spring** ``F_s``: ``ks·d`` (None), progressive ``ks·d + k3·d³`` (a
  number ``k3`` [N/m³]), or a callable ``F_s(d)``;
* **damper** ``F_d``: ``cs·v`` (None), a `PiecewiseDamper` (asymmetric,
  bilinear per direction), or a callable ``F_d(v)``;
* **bump stops** ``F_b``: None, or a `BumpStop` — a clearance in bound and in
  rebound, beyond which an elastomer acts with the progressive polynomial
  ``F = k·p + k3·p³`` of its penetration ``p`` (Rill 2012, the bump stop as
  a progressive spring acting after a clearance; Gillespie, *Fundamentals of
  Vehicle Dynamics*, SAE 1992, ch. 7, the jounce bumper).

The system carries its **switching functions** (``switching(t, x, u,
params)``, labels ``switching_labels``): the scalar functions whose zeros
are the kinks of the right-hand side (contact lost or regained, a stop
engaged or released, a damper knee). `qc_control.input_output_response`
with ``events=True`` steps exactly to each of them.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import control
import numpy as np

from ..numerics.checks import Field, ParameterError, check_fields, choice
from .quarter import OUTPUTS, STATES, UNITS, QuarterCarParams, as_params
from .vehicle import STANDARD_GRAVITY, Corner, SignalRoles, VehicleModel

__all__ = [
    "PiecewiseDamper",
    "BumpStop",
    "nonlinear_quarter_car",
    "nonlinear_quarter_car_model",
    "NonlinearQuarterCarBatch",
    "NONLINEAR_OUTPUTS",
    "NONLINEAR_UNITS",
]

#: The outputs of the nonlinear car: quarter_car's, then the tire contact force.
NONLINEAR_OUTPUTS = (*OUTPUTS, "tire_force")
#: The SI unit of every signal of the nonlinear car.
NONLINEAR_UNITS = {**UNITS, "tire_force": "N"}

_TIRES = ("unilateral", "linear")
#: A progressive spring's cubic coefficient (``spring=k3``), declared once.
_SPRING_K3 = Field("the cubic coefficient k3 of a progressive spring", "N/m³", "nonneg")


def _unset(value) -> bool:
    """None or NaN: a high-speed coefficient left to default to the low-speed one."""
    return value is None or (isinstance(value, float) and math.isnan(value))


#: `PiecewiseDamper`'s fields, declared once: what each is, its SI unit, its range.
_DAMPER_SPEC = {
    "rebound": Field("low-speed rebound (extension) damping c_r", "N·s/m", "nonneg"),
    "bound": Field("low-speed bound (compression) damping c_b", "N·s/m", "nonneg"),
    "knee_rebound": Field("rebound knee velocity v_r (inf: one slope)", "m/s", allow_inf=True),
    "knee_bound": Field("bound knee velocity v_b (inf: one slope)", "m/s", allow_inf=True),
    "rebound_high": Field(
        "high-speed rebound damping (None or NaN: c_r)", "N·s/m", "nonneg", optional=True
    ),
    "bound_high": Field(
        "high-speed bound damping (None or NaN: c_b)", "N·s/m", "nonneg", optional=True
    ),
}
#: `BumpStop`'s fields, declared once.
_STOP_SPEC = {
    "clearance_bound": Field(
        "travel in compression before the bump stop touches (inf: none)",
        "m",
        "nonneg",
        allow_inf=True,
    ),
    "stiffness": Field("bump-stop stiffness k", "N/m", "nonneg"),
    "cubic": Field("bump-stop cubic coefficient k3", "N/m³", "nonneg"),
    "clearance_rebound": Field(
        "travel in extension before the rebound stop touches (inf: none)",
        "m",
        "nonneg",
        allow_inf=True,
    ),
}


@dataclass(frozen=True)
class PiecewiseDamper:
    """An asymmetric, bilinear damper: its force against the extension rate ``v = vs - vu``.

    .. math::

        F_d(v) = \\begin{cases}
            c_r v & 0 \\le v \\le v_r \\\\
            c_r v_r + c_{r2} (v - v_r) & v > v_r \\\\
            c_b v & -v_b \\le v < 0 \\\\
            -c_b v_b + c_{b2} (v + v_b) & v < -v_b
        \\end{cases}

    the usual two-slope characteristic of a passive damper, stiffer in
    rebound (extension) than in bound (compression), softer past a knee
    where the blow-off valve opens (Dixon, *The Shock Absorber Handbook*,
    2nd ed., Wiley 2007, ch. 5).

    Parameters
    ----------
    rebound, bound : float
        Low-speed coefficients ``c_r``, ``c_b`` [N·s/m], >= 0.
    knee_rebound, knee_bound : float, default inf
        Knee velocities ``v_r``, ``v_b`` [m/s], > 0 (inf: one slope).
    rebound_high, bound_high : float, optional
        High-speed coefficients [N·s/m], >= 0; default (None or NaN) the
        low-speed one.

    Raises
    ------
    qc_control.ParameterError
        A value out of its declared range (``PiecewiseDamper.spec()``),
        naming the field and the value.
    """

    rebound: float
    bound: float
    knee_rebound: float = math.inf
    knee_bound: float = math.inf
    rebound_high: float = math.nan
    bound_high: float = math.nan

    def __post_init__(self):
        # None or NaN high-speed coefficient: the low-speed one, once that is checked
        for name in ("rebound_high", "bound_high"):
            if _unset(getattr(self, name)):
                object.__setattr__(self, name, None)
        check_fields(self, _DAMPER_SPEC)
        for name, low in (("rebound_high", "rebound"), ("bound_high", "bound")):
            if getattr(self, name) is None:
                object.__setattr__(self, name, getattr(self, low))

    @classmethod
    def spec(cls) -> dict[str, Field]:
        """The fields, declared: ``{name: Field}`` (description, SI unit, range)."""
        return dict(_DAMPER_SPEC)

    def __call__(self, v: float) -> float:
        if v >= 0:
            if v <= self.knee_rebound:
                return self.rebound * v
            return self.rebound * self.knee_rebound + self.rebound_high * (v - self.knee_rebound)
        if v >= -self.knee_bound:
            return self.bound * v
        return -self.bound * self.knee_bound + self.bound_high * (v + self.knee_bound)

    def forces(self, v: np.ndarray) -> np.ndarray:
        """`__call__` over an array of extension rates (elementwise, same formula)."""
        low = np.where(v >= 0, self.rebound * v, self.bound * v)
        if math.isfinite(self.knee_rebound):
            k = self.knee_rebound
            low = np.where(v > k, self.rebound * k + self.rebound_high * (v - k), low)
        if math.isfinite(self.knee_bound):
            k = self.knee_bound
            low = np.where(v < -k, -self.bound * k + self.bound_high * (v + k), low)
        return low

    def knees(self) -> tuple[float, ...]:
        """The finite knee velocities, signed (rebound positive)."""
        return tuple(
            k for k in (self.knee_rebound, -self.knee_bound) if math.isfinite(k) and k != 0
        )


@dataclass(frozen=True)
class BumpStop:
    """Bump (bound) and rebound stops: a clearance, then a progressive elastomer.

    With ``d = xs - xu`` the suspension extension from static, the bound
    stop's penetration is ``p = -d - clearance_bound`` and the rebound
    stop's ``p = d - clearance_rebound``; where ``p > 0`` the stop pushes
    back with

    .. math:: F(p) = k\\,p + k_3\\,p^3

    (a progressive polynomial spring after a clearance; Rill, *Road Vehicle
    Dynamics*, CRC Press 2012, force elements; Gillespie 1992, ch. 7).

    Parameters
    ----------
    clearance_bound : float
        Travel in compression before the bump stop touches [m], >= 0.
    stiffness : float
        ``k`` [N/m], >= 0.
    cubic : float, default 0
        ``k3`` [N/m³], >= 0.
    clearance_rebound : float, default inf
        Travel in extension before the rebound stop touches [m], >= 0
        (inf: no rebound stop).

    Raises
    ------
    qc_control.ParameterError
        A value out of its declared range (``BumpStop.spec()``), naming the
        field and the value.
    """

    clearance_bound: float
    stiffness: float
    cubic: float = 0.0
    clearance_rebound: float = math.inf

    def __post_init__(self):
        check_fields(self, _STOP_SPEC)

    @classmethod
    def spec(cls) -> dict[str, Field]:
        """The fields, declared: ``{name: Field}`` (description, SI unit, range)."""
        return dict(_STOP_SPEC)

    def force(self, d: float) -> float:
        """The stops' force on the body against the extension ``d`` [N] (0 inside the clearance)."""
        # p * p * p, not p**3: a diverging state gives inf, not a Python OverflowError
        p = -d - self.clearance_bound
        if p > 0:
            return -(self.stiffness * p + self.cubic * (p * p * p))
        p = d - self.clearance_rebound
        if p > 0:
            return self.stiffness * p + self.cubic * (p * p * p)
        return 0.0

    def forces(self, d: np.ndarray):
        """`force` over an array of extensions (elementwise), as
        ``F = q (k + k3 q²)`` with ``q = d - clip(d, -c_b, c_r)`` the signed
        penetration (``d + c_b`` in bound, ``d - c_r`` in rebound, 0 between):
        the same values to a few ulps, in fewer operations.

        Returns the float 0.0 when no element of ``d`` is past a clearance
        (the common case, skipped at the cost of one comparison per stop; a
        NaN element, a diverged design, is left out of that comparison).
        """
        k, k3 = self.stiffness, self.cubic
        cb, cr = self.clearance_bound, self.clearance_rebound
        bound = math.isfinite(cb) and np.fmin.reduce(d, axis=None) < -cb
        rebound = math.isfinite(cr) and np.fmax.reduce(d, axis=None) > cr
        # the signed penetration as d less d clipped to the clearances: d + c_b in
        # bound, d - c_r in rebound (the same roundings), exactly 0 in between
        if bound and rebound:
            q = d - np.minimum(np.maximum(d, -cb), cr)
        elif bound:
            q = d - np.maximum(d, -cb)
        elif rebound:
            q = d - np.minimum(d, cr)
        else:
            return 0.0
        return q * (k + k3 * (q * q)) if k3 else k * q

    def energy(self, d: float) -> float:
        """The stops' potential energy at extension ``d`` [J]: ``k p²/2 + k3 p⁴/4``."""
        p = max(-d - self.clearance_bound, d - self.clearance_rebound, 0.0)
        p2 = p * p
        return 0.5 * self.stiffness * p2 + 0.25 * self.cubic * (p2 * p2)


def _check_spring(spring, ks: float) -> float | None:
    """The cubic coefficient ``k3`` for a number, None for a callable (checked at d = 0)."""
    if callable(spring):
        try:
            f0 = float(spring(0.0))
        except Exception as exc:
            raise ValueError(f"spring(0.0) failed: {type(exc).__name__}: {exc}") from None
        if not abs(f0) <= 1e-9 * ks:
            raise ParameterError(
                "spring",
                spring,
                f"a force law giving 0 N at the static point (d = 0), but spring(0.0) = "
                f"{f0!r}; measure its force from the static preload",
            )
        return None
    return _SPRING_K3.check("spring", spring)


def _check_damper(damper) -> None:
    """A callable damper must give a finite force at rest."""
    if isinstance(damper, PiecewiseDamper):
        return
    if not callable(damper):
        raise TypeError(
            "damper must be None (linear cs), a PiecewiseDamper or a callable F(v) [N], "
            f"got {type(damper).__name__}"
        )
    try:
        f0 = float(damper(0.0))
    except Exception as exc:
        raise ValueError(f"damper(0.0) failed: {type(exc).__name__}: {exc}") from None
    if not math.isfinite(f0):
        raise ParameterError(
            "damper", damper, f"a force law finite at rest, but damper(0.0) = {f0!r}"
        )


def _spring_law(spring, k3: float | None) -> Callable:
    """``F_s(d, q)`` [N]: linear ``ks·d``, progressive ``ks·d + k3·d³``, or the user's."""
    if spring is None:
        return lambda d, q: q["ks"] * d
    if k3 is not None:
        return lambda d, q: q["ks"] * d + k3 * d**3
    return lambda d, q: float(spring(d))


def _damper_law(damper) -> Callable:
    """``F_d(v, q)`` [N]: linear ``cs·v``, or the `PiecewiseDamper` or callable given."""
    if damper is None:
        return lambda v, q: q["cs"] * v
    return lambda v, q: float(damper(v))


def _profile_of(road) -> Callable[[float], float] | None:
    """The road height ``zr(t)`` [m] of a road given as a function of time: a
    `qc_control.road.Road`'s ``height_at`` (read without its ``__call__``'s
    dispatch), or a plain function itself; None for the input ``zr`` or none."""
    if isinstance(road, bool) or not callable(road):
        return None
    return getattr(road, "height_at", road)


def _warn_plain_road(road, stacklevel: int) -> None:
    """A plain function ``zr(t)`` (with a patched ``.jumps``) was 0.1's road form:
    it still runs, warning; a `qc_control.road.Road` carries its jumps itself."""
    if callable(road) and not isinstance(road, bool) and not hasattr(road, "height_at"):
        warnings.warn(
            f"road={road!r}: a plain function zr(t) is deprecated and will be removed in "
            "the next release: give a qc.road.Road (Step, Bump, Sine, a Profile of "
            "measured points, or a Road subclass with height_at and jumps)",
            DeprecationWarning,
            stacklevel=stacklevel + 1,
        )


def _road_height(road, actuator: bool):
    """``(zr_at(t, u), inputs, ia)``: the road height [m] from the input ``zr`` or a
    road function ``zr(t)`` (0 without either), the input labels, and the index of
    the actuator force ``fa`` (None without one)."""
    profile = _profile_of(road)
    if profile is None and not isinstance(road, bool):
        raise TypeError(
            f"road must be True, False or a qc.road.Road (a function zr(t) [m]), got {road!r}"
        )
    road_input = road is True
    iz = 0 if road_input else None
    ia = (1 if road_input else 0) if actuator else None

    def zr_at(t, u):
        if iz is not None:
            return u[iz]
        return 0.0 if profile is None else float(profile(t))

    inputs = [s for s, on in (("zr", road_input), ("fa", actuator)) if on]
    return zr_at, inputs, ia


def _road_jumps(road) -> tuple[float, ...]:
    """The times [s] where a road function jumps (its ``jumps``, sorted); () for an
    input ``zr``, which python-control interpolates linearly, or for no road."""
    given = getattr(road, "jumps", ()) if callable(road) else ()
    try:
        jumps = tuple(sorted(float(t) for t in given))
    except (TypeError, ValueError):
        jumps = (math.nan,)
    if not all(math.isfinite(t) for t in jumps):
        raise ParameterError("road.jumps", given, "finite times [s]")
    return jumps


def _force_elements(p, *, tire: str, bump_stop, damper, spring, gravity: bool, zr_at):
    """``elements(t, x, u, q) -> (F_s + F_d + F_b, F_t - ku δ0, F_t, δ)``, the force
    elements at the state ``x`` (module docstring), checked and built once."""
    choice("tire", tire, _TIRES)
    if bump_stop is not None and not isinstance(bump_stop, BumpStop):
        raise TypeError(f"bump_stop must be a BumpStop or None, got {type(bump_stop).__name__}")
    if not isinstance(gravity, bool):
        raise TypeError(f"gravity must be True or False, got {gravity!r}")
    unilateral = tire == "unilateral"
    g = STANDARD_GRAVITY if gravity else 0.0
    spring_force = _spring_law(spring, None if spring is None else _check_spring(spring, p.ks))
    if damper is not None:
        _check_damper(damper)
    damper_force = _damper_law(damper)
    stop = bump_stop

    def elements(t, x, u, q):
        vs, vu, xs, xu = x[0], x[1], x[2], x[3]
        d, v = xs - xu, vs - vu
        fb = stop.force(d) if stop is not None else 0.0
        delta = xu - zr_at(t, u)
        static = (q["ms"] + q["mu"]) * g
        ft = static - q["ku"] * delta
        if unilateral and ft < 0.0:
            ft = 0.0
        return spring_force(d, q) + damper_force(v, q) + fb, ft - static, ft, delta

    return elements


def _kinks(*, tire: str, bump_stop, damper, gravity: bool, zr_at):
    """``(switching(t, x, u, q), labels)``: the functions whose zeros are the kinks
    of the right-hand side (contact, stops, damper knees), and their names."""
    g = STANDARD_GRAVITY if gravity else 0.0
    labels: list[str] = []
    kinks: list[Callable] = []
    if tire == "unilateral":
        labels.append("contact")
        kinks.append(lambda t, x, u, q: (q["ms"] + q["mu"]) * g / q["ku"] - (x[3] - zr_at(t, u)))
    stop = bump_stop
    if stop is not None and math.isfinite(stop.clearance_bound):
        labels.append("bump stop")
        kinks.append(lambda t, x, u, q: x[2] - x[3] + stop.clearance_bound)
    if stop is not None and math.isfinite(stop.clearance_rebound):
        labels.append("rebound stop")
        kinks.append(lambda t, x, u, q: stop.clearance_rebound - (x[2] - x[3]))
    if isinstance(damper, PiecewiseDamper):
        for knee in damper.knees():
            labels.append(f"damper knee {knee:+g} m/s")
            kinks.append(lambda t, x, u, q, k=knee: x[0] - x[1] - k)

    def switching(t, x, u, q):
        return np.array([k(t, x, u, q) for k in kinks])

    return switching, tuple(labels)


def nonlinear_quarter_car(
    params=None,
    *,
    tire: str = "unilateral",
    bump_stop: BumpStop | None = None,
    damper=None,
    spring=None,
    gravity: bool = True,
    road: bool | Callable[[float], float] = True,
    actuator: bool = False,
    name: str = "nonlinear_quarter_car",
) -> control.NonlinearIOSystem:
    """The quarter car with a unilateral tire, bump stops and nonlinear force elements.

    See the module docstring for the equations. States, inputs and outputs
    have `qc_control.quarter_car`'s names, plus the output ``tire_force``
    (the tire's contact force [N], ``(ms + mu)·g`` at rest with gravity).

    Parameters
    ----------
    params : QuarterCarParams or dict, optional
        The seed's Table 1 when omitted. ``ms, mu, ks, ku, cs`` are also the
        system's ``params`` (python-control's), so
        ``qc.input_output_response(sys, ..., params={'cs': 2000.0})`` runs
        another design.
    tire : {'unilateral', 'linear'}, default 'unilateral'
    bump_stop : BumpStop, optional
    damper : None, PiecewiseDamper or callable ``F(v)`` [N]
    spring : None, float ``k3`` [N/m³] or callable ``F(d)`` [N] (0 at ``d = 0``)
    gravity : bool, default True
        Whether the tire carries the static load ``(ms + mu)·g``.
    road : bool or qc_control.road.Road, default True
        True: the input ``zr`` [m], as in `quarter_car` (but on by default:
        the nonlinear car is mostly driven by one). A `qc_control.road.Road`
        (``qc.road.Step(0.05, 0.5)``, a measured ``qc.road.Profile``): the
        road height as a function of time, its ``height_at(t)`` evaluated
        at every stage (no ``zr`` input), so that no interpolation of
        samples limits the order of a convergence study; its ``jumps`` (a
        step's ``t0``) the system carries. A plain function ``zr(t)``, with
        an optional attribute ``jumps``, still runs, with a
        DeprecationWarning.
    actuator : bool
        The input ``fa`` [N], as in `quarter_car`.
    name : str

    Returns
    -------
    control.NonlinearIOSystem
        Also with ``switching(t, x, u, params) -> ndarray`` and
        ``switching_labels``: the functions whose sign changes are the
        kinks of the right-hand side (for ``events=True``); and ``jumps``:
        the road function's jumps [s], sorted (empty without), where
        `qc_control.studies.compare.nonlinear_reference` restarts.

    Raises
    ------
    ValueError, TypeError
        Naming the argument and the value.

    Examples
    --------
    >>> import numpy as np, qc_control as qc
    >>> car = qc.nonlinear_quarter_car()
    >>> car.output_labels[-1], car.switching_labels
    ('tire_force', ('contact',))
    >>> round(float(car.output(0, np.zeros(4), [0.0])[-1]), 1)  # the static wheel load [N]
    3934.4
    """
    _warn_plain_road(road, stacklevel=2)
    p = as_params(params)
    if p.cu:  # its tire is a spring that may lift off; a tire damper is the linear car's
        raise ParameterError(
            "cu", p.cu, "0 N·s/m: the nonlinear car has no tire damping", description="tire damping"
        )
    zr_at, inputs, ia = _road_height(road, actuator)
    forces = dict(tire=tire, bump_stop=bump_stop, damper=damper, gravity=gravity, zr_at=zr_at)
    elements = _force_elements(p, spring=spring, **forces)
    switching, switching_labels = _kinks(**forces)

    def update(t, x, u, q):
        f, tire_dyn, _, _ = elements(t, x, u, q)
        fa = u[ia] if ia is not None else 0.0
        return np.array([(fa - f) / q["ms"], (f - fa + tire_dyn) / q["mu"], x[0], x[1]])

    def output(t, x, u, q):
        f, _, ft, delta = elements(t, x, u, q)
        fa = u[ia] if ia is not None else 0.0
        return np.array([x[2], x[3], x[2] - x[3], delta, (fa - f) / q["ms"], ft])

    sys = control.nlsys(
        update,
        output,
        inputs=inputs,
        outputs=list(NONLINEAR_OUTPUTS),
        states=list(STATES),
        name=name,
        params={"ms": p.ms, "mu": p.mu, "ks": p.ks, "ku": p.ku, "cs": float(p.cs)},  # type: ignore[arg-type]
    )
    sys.switching = switching
    sys.switching_labels = switching_labels
    sys.jumps = _road_jumps(road)
    return sys


def nonlinear_quarter_car_model(params=None, **options) -> VehicleModel:
    """The nonlinear quarter car as a `VehicleModel`: `nonlinear_quarter_car` plus roles.

    The roles are `qc_control.quarter_car_model`'s (body acceleration
    ``body_acc``, body displacement ``xs``, one corner with ``susp_travel``,
    ``tire_defl``, the road ``zr`` when the car has that input, the tire
    stiffness ``ku`` and the static load ``(ms + mu)·g``), so that compare,
    ride metrics, sweeps and the report read it as they read the linear car.
    Its ``system`` is the `control.NonlinearIOSystem`; ``rebuild(params)``
    builds the same car (same options) from other parameters;
    ``batch_dynamics(designs)`` gives the `NonlinearQuarterCarBatch` of many
    designs, which `qc_control.sweep` steps all at once (None when a callable
    ``spring`` or ``damper`` does not vectorise over arrays: a sweep then runs
    one response per design).

    Parameters
    ----------
    params : QuarterCarParams or dict, optional
    **options
        `nonlinear_quarter_car`'s keyword arguments (``tire``, ``bump_stop``,
        ``damper``, ``spring``, ``gravity``, ``road``, ``actuator``, ``name``).

    Examples
    --------
    >>> import qc_control as qc
    >>> m = qc.nonlinear_quarter_car_model()
    >>> m.body_acc, m.corners[0].road, m.system.output_labels[-1]
    ('body_acc', 'zr', 'tire_force')
    """
    p = as_params(params)
    _warn_plain_road(options.get("road"), stacklevel=2)
    with warnings.catch_warnings():  # warned above, at the caller's line
        warnings.simplefilter("ignore", DeprecationWarning)
        sys = nonlinear_quarter_car(p, **options)
    corner = Corner(
        "",
        "susp_travel",
        "tire_defl",
        "zr" if "zr" in sys.input_labels else None,
        p.ku,
        (p.ms + p.mu) * STANDARD_GRAVITY,
    )
    laws = [options.get(k) for k in ("spring", "damper")]
    vectorised = all(
        not callable(f) or isinstance(f, PiecewiseDamper) or _vectorises(f) for f in laws
    )
    return VehicleModel(
        sys,
        p,
        NONLINEAR_UNITS,
        SignalRoles("body_acc", "xs", (corner,)),
        functools.partial(nonlinear_quarter_car_model, **options),
        batch_dynamics=(
            functools.partial(NonlinearQuarterCarBatch.from_params, **options)
            if vectorised
            else None
        ),
    )


#: The design fields of a batch: each an array of shape (m,).
_BATCH_FIELDS = ("ms", "mu", "ks", "ku", "cs")


def _design_arrays(values: dict) -> dict[str, np.ndarray]:
    """The five design arrays, 1-D of one length, finite, masses and stiffnesses > 0,
    ``cs`` >= 0; a ValueError naming the field, the design and the value."""
    out: dict[str, np.ndarray] = {}
    for name in _BATCH_FIELDS:
        try:
            a = np.asarray(values[name], dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(name, values[name], "an array of numbers") from None
        if a.ndim != 1 or a.size == 0:
            raise ParameterError(name, values[name], f"a 1-D array of designs, not shape {a.shape}")
        out[name] = a
    sizes = {name: a.size for name, a in out.items()}
    if len(set(sizes.values())) != 1:
        raise ValueError(
            f"the design arrays must have one length (one value per design), got sizes {sizes}"
        )
    spec = QuarterCarParams.spec()  # each design's range, as its constructor's
    for name, a in out.items():
        bad = np.flatnonzero(~spec[name].holds(a))
        if bad.size:
            i = int(bad[0])
            spec[name].check(f"{name}[{i}]", float(a[i]))  # refuses, naming the design
    return out


def _vectorises(fn) -> bool:
    """Whether a user force law ``fn`` maps an array to the array of its scalar values."""
    probe = np.array([-0.3, -0.01, 0.0, 0.02, 0.4])
    try:
        with np.errstate(all="ignore"):
            got = np.asarray(fn(probe), dtype=float)
            want = np.array([float(fn(float(v))) for v in probe])
    except Exception:
        return False
    return got.shape == probe.shape and bool(np.allclose(got, want, rtol=1e-12, atol=0.0))


class NonlinearQuarterCarBatch:
    """``m`` designs of `nonlinear_quarter_car` (one set of options), over arrays.

    The same equations as `nonlinear_quarter_car` (module docstring), written
    with NumPy over the designs: ``ms, mu, ks, ku, cs`` are arrays of shape
    ``(m,)`` and a state is ``x`` of shape ``(4, m)`` (or ``(4, m, L)`` for
    ``L`` samples at once), states in `quarter_car`'s order. The force
    elements are the single car's (`BumpStop.forces`, `PiecewiseDamper.forces`
    are `BumpStop.force` and `PiecewiseDamper.__call__` elementwise), with
    the same operations in the same order, so a design's right-hand side
    equals the single car's to rounding. `qc_control.studies.nlsweep` steps it.

    A user callable ``spring(d)`` or ``damper(v)`` must vectorise: called
    with an array, return the array of its values (NumPy ufuncs, ``np.where``;
    an ``if`` on the value does not); otherwise a TypeError says so.

    Parameters
    ----------
    ms, mu, ks, ku, cs : array_like, shape (m,)
        Masses [kg] and stiffnesses [N/m] > 0, damping [N·s/m] >= 0.
    **options
        `nonlinear_quarter_car`'s keyword arguments (``tire``, ``bump_stop``,
        ``damper``, ``spring``, ``gravity``, ``road``, ``actuator``,
        ``name``), checked by it.

    Raises
    ------
    ValueError
        Arrays of different lengths, or a value out of range (naming the
        field, the design and the value).
    TypeError
        A callable force law that does not vectorise; a bad option.
    """

    def __init__(self, ms, mu, ks, ku, cs, **options):
        a = _design_arrays({"ms": ms, "mu": mu, "ks": ks, "ku": ku, "cs": cs})
        first = {name: float(v[0]) for name, v in a.items()}
        with warnings.catch_warnings():  # a plain road function warned where the model was built
            warnings.simplefilter("ignore", DeprecationWarning)
            single = nonlinear_quarter_car(first, **options)  # checks the options once
        for which in ("spring", "damper"):
            fn = options.get(which)
            if callable(fn) and not isinstance(fn, PiecewiseDamper) and not _vectorises(fn):
                raise TypeError(
                    f"{which} {fn!r} does not vectorise over arrays (called with an array it "
                    "must return the array of its values); a batch needs that. Write it with "
                    "NumPy (np.where, ufuncs), or sweep the model without a batch form"
                )
        self.options = dict(options)
        self.state_labels = tuple(single.state_labels)
        self.input_labels = tuple(single.input_labels)
        self.output_labels = tuple(single.output_labels)
        self.switching_labels = tuple(single.switching_labels)
        self._g = STANDARD_GRAVITY if options.get("gravity", True) else 0.0
        self._unilateral = options.get("tire", "unilateral") == "unilateral"
        spring = options.get("spring")
        self._spring = spring if callable(spring) else None
        self._k3 = None if spring is None or callable(spring) else float(spring)
        self._damper = options.get("damper")
        self._stop = options.get("bump_stop")
        road = options.get("road", True)
        self._profile = _profile_of(road)
        self._iz = 0 if road is True else None
        self._ia = (1 if road is True else 0) if options.get("actuator", False) else None
        self._set(a)

    def _set(self, a: dict[str, np.ndarray]) -> None:
        a = dict(a)
        a["static"] = (a["ms"] + a["mu"]) * self._g
        self.params = a
        self._col = {k: v[:, None] for k, v in a.items()}  # for (4, m, L) blocks
        self.rhs = self._stepping_rhs()

    def _stepping_rhs(self):
        """``rhs(t, x, u, out=None)``, specialised to the options: the fewest NumPy
        calls on ``(4, m)`` states, with the parameters bound.

        The single car's formulas with the constants folded, ``-F/m_s`` as
        ``F·(-1/m_s)`` and the tire's dynamic force ``F_t - k_u δ0`` as
        ``max(k_u (z_r - x_u), -k_u δ0)``: the same values to rounding (a
        few ulps), in fewer operations.
        """
        ms, mu, ks, ku, cs, static = (self.params[k] for k in (*_BATCH_FIELDS, "static"))
        neg_inv_ms, inv_mu, neg_static = -1.0 / ms, 1.0 / mu, -static
        spring, k3, damper, stop = self._spring, self._k3, self._damper, self._stop
        piecewise = isinstance(damper, PiecewiseDamper)
        unilateral, iz, ia, profile = self._unilateral, self._iz, self._ia, self._profile
        maximum, multiply = np.maximum, np.multiply
        if spring is None and k3 is None and damper is None:
            return self._linear_elements_rhs()

        def rhs(t: float, x: np.ndarray, u, out: np.ndarray | None = None) -> np.ndarray:
            """``dx/dt`` ``(4, m)`` of every design at the states ``x`` ``(4, m)``,
            with ``u`` this time's inputs ``(k,)``."""
            if x.ndim != 2:
                return self._block_rhs(t, x, u, out)
            vs, vu, xs, xu = x
            d = xs - xu
            if spring is not None:
                fs = np.asarray(spring(d), dtype=float)
            elif k3 is not None:
                fs = ks * d + k3 * d**3
            else:
                fs = ks * d
            if damper is None:
                f = fs + cs * (vs - vu)
            elif piecewise:
                f = fs + damper.forces(vs - vu)
            else:
                f = fs + np.asarray(damper(vs - vu), dtype=float)
            if stop is not None:
                fb = stop.forces(d)
                if isinstance(fb, np.ndarray):
                    f = f + fb
            zr = u[iz] if iz is not None else (0.0 if profile is None else float(profile(t)))
            tire = ku * (zr - xu)  # F_t - k_u δ0
            if unilateral:
                tire = maximum(tire, neg_static, out=tire)
            out = np.empty_like(x) if out is None else out
            if ia is None:
                multiply(f, neg_inv_ms, out=out[0])
                multiply(f + tire, inv_mu, out=out[1])
            else:
                fa = u[ia]
                multiply(f - fa, neg_inv_ms, out=out[0])
                multiply(f - fa + tire, inv_mu, out=out[1])
            out[2:] = x[:2]
            return out

        return rhs

    def _linear_elements_rhs(self):
        """`rhs` when the spring and the damper are linear: the same sums, fused.

        ``[vs - vu, xs - xu]`` is one subtraction of the state's even and odd
        rows, ``[cs v, ks d]`` one product with a stacked coefficient array, and
        both accelerations one product with ``[-1/ms, 1/mu]``: 11 NumPy calls a
        stage (with a stop, 13 when it touches) instead of 17, on the same
        operands, so each design's value equals the single car's to rounding
        (the stops add their force to ``F`` as in `force`).
        """
        p = self.params
        m = p["ms"].size
        coef = np.stack([p["cs"], p["ks"]])  # (2, m): [cs, ks]
        scale = np.stack([-1.0 / p["ms"], 1.0 / p["mu"]])  # (2, m)
        ku, neg_static = p["ku"], -p["static"]
        stop, unilateral = self._stop, self._unilateral
        iz, ia, profile = self._iz, self._ia, self._profile
        dv = np.empty((2, m))
        force = np.empty((2, m))  # [F, F + F_t - ku δ0] (F less fa with an actuator)
        tire = np.empty(m)
        subtract, multiply, add, maximum = np.subtract, np.multiply, np.add, np.maximum

        def rhs(t: float, x: np.ndarray, u, out: np.ndarray | None = None) -> np.ndarray:
            """``dx/dt`` ``(4, m)`` of every design at the states ``x`` ``(4, m)``."""
            if x.ndim != 2:
                return self._block_rhs(t, x, u, out)
            subtract(x[0::2], x[1::2], out=dv)  # [v, d]
            fb = 0.0 if stop is None else stop.forces(dv[1])
            multiply(dv, coef, out=dv)  # [cs v, ks d]
            f = add(dv[0], dv[1], out=force[0])
            if isinstance(fb, np.ndarray):
                add(f, fb, out=f)
            if ia is not None:
                subtract(f, u[ia], out=f)
            zr = u[iz] if iz is not None else (0.0 if profile is None else float(profile(t)))
            subtract(zr, x[3], out=tire)
            multiply(tire, ku, out=tire)  # F_t - k_u δ0
            if unilateral:
                maximum(tire, neg_static, out=tire)
            add(f, tire, out=force[1])
            out = np.empty_like(x) if out is None else out
            multiply(force, scale, out=out[:2])
            out[2:] = x[:2]
            return out

        return rhs

    def compiled_stepper(self):
        """The compiled batched step of these designs, or None where an option has none.

        Returns ``step(x, out, first, count, start, substeps, a, b, stage_u)``:
        `qc_control.models.nlkernel.advance` with these designs' parameters and
        options bound (its docstring has the arguments). None for a callable
        spring, damper or road profile: user Python code, which only the
        NumPy path (`rhs`) can call.
        """
        damper = self._damper
        if damper is None:
            # a linear damper as a bilinear one without knees, with each design's cs
            knees, c_reb, c_bnd = PiecewiseDamper(0.0, 0.0), self.params["cs"], self.params["cs"]
        elif isinstance(damper, PiecewiseDamper):
            c_reb, c_bnd = np.full(self.size, damper.rebound), np.full(self.size, damper.bound)
            knees = damper
        else:
            return None
        if self._spring is not None or self._profile is not None:
            return None
        # numba: ~0.5 s to import, needed only to step a batch
        from .nlkernel import OPTION_SLOTS, PARAMETER_ROWS, advance

        q, inf, stop = self.params, math.inf, self._stop
        rows = {
            "neg_inv_ms": -1.0 / q["ms"],
            "inv_mu": 1.0 / q["mu"],
            "ks": q["ks"],
            "ku": q["ku"],
            # the least F_t - k_u δ0: the tire lets go of its static load, or never
            "tire_floor": -q["static"] if self._unilateral else np.full(self.size, -inf),
            "c_rebound": c_reb,
            "c_bound": c_bnd,
        }
        p = np.stack([rows[name] for name in PARAMETER_ROWS])  # (7, m), C-contiguous
        options = {
            "k3": self._k3 or 0.0,
            "stop_bound": inf if stop is None else stop.clearance_bound,
            "stop_rebound": inf if stop is None else stop.clearance_rebound,
            "stop_k": 0.0 if stop is None else stop.stiffness,
            "stop_k3": 0.0 if stop is None else stop.cubic,
            "knee_rebound": knees.knee_rebound,
            "knee_bound": knees.knee_bound,
            "rebound_high": knees.rebound_high,
            "bound_high": knees.bound_high,
            "road": -1.0 if self._iz is None else float(self._iz),
            "actuator": -1.0 if self._ia is None else float(self._ia),
        }
        o = np.array([options[name] for name in OPTION_SLOTS], dtype=float)

        def step(x, out, first, count, start, substeps, a, b, stage_u):
            advance(x, out, first, count, start, substeps, a, b, stage_u, p, o)

        return step

    def _block_rhs(self, t, x, u, out=None):
        """`rhs` on states with more axes (``(4, m, L)``): the general formula."""
        q = self._col
        f, ft, _ = self._elements(t, x, u)
        out = np.empty_like(x) if out is None else out
        fa = 0.0 if self._ia is None else u[self._ia]
        out[0] = (fa - f) / q["ms"]
        out[1] = (f - fa + (ft - q["static"])) / q["mu"]
        out[2:] = x[:2]
        return out

    @classmethod
    def from_params(cls, designs, **options) -> NonlinearQuarterCarBatch:
        """A batch from parameter objects (`QuarterCarParams` or dicts), in order."""
        ps = [as_params(p) for p in designs]
        if not ps:
            raise ValueError("designs is empty: give at least one design")
        return cls(*([float(getattr(p, f)) for p in ps] for f in _BATCH_FIELDS), **options)

    @property
    def size(self) -> int:
        """The number of designs ``m``."""
        return int(self.params["ms"].size)

    @property
    def tire_stiffness(self) -> tuple[np.ndarray, ...]:
        """Per corner (one), each design's tire stiffness [N/m] (as `Corner`)."""
        return (self.params["ku"],)

    @property
    def static_load(self) -> tuple[np.ndarray, ...]:
        """Per corner (one), each design's static wheel load ``(ms + mu)·g`` [N] (as `Corner`)."""
        return ((self.params["ms"] + self.params["mu"]) * STANDARD_GRAVITY,)

    def take(self, index) -> NonlinearQuarterCarBatch:
        """The designs at ``index`` (an integer array or slice), same options."""
        out = object.__new__(type(self))
        out.__dict__.update(self.__dict__)
        out._set({k: np.atleast_1d(self.params[k][index]) for k in _BATCH_FIELDS})
        return out

    def _road(self, t, u):
        if self._iz is not None:
            return u[self._iz]
        if self._profile is not None:
            if np.ndim(t):
                return np.array([float(self._profile(s)) for s in np.ravel(t)])
            return float(self._profile(t))
        return 0.0

    def _elements(self, t, x, u):
        """``(F_s + F_d + F_b, F_t, δ)`` at the states ``x`` (the single car's ``elements``)."""
        q = self.params if x.ndim == 2 else self._col
        vs, vu, xs, xu = x[0], x[1], x[2], x[3]
        d, v = xs - xu, vs - vu
        if self._spring is not None:
            fs = np.asarray(self._spring(d), dtype=float)
        elif self._k3 is not None:
            fs = q["ks"] * d + self._k3 * d**3
        else:
            fs = q["ks"] * d
        damper = self._damper
        if damper is None:
            fd = q["cs"] * v
        elif isinstance(damper, PiecewiseDamper):
            fd = damper.forces(v)
        else:
            fd = np.asarray(damper(v), dtype=float)
        f = fs + fd
        if self._stop is not None:
            f = f + self._stop.forces(d)  # 0.0 when no stop touches: exact
        delta = xu - self._road(t, u)
        ft = q["static"] - q["ku"] * delta
        if self._unilateral:
            ft = np.maximum(ft, 0.0)
        return f, ft, delta

    def outputs(self, t, x: np.ndarray, u) -> dict[str, np.ndarray]:
        """Every output by label, shape ``x.shape[1:]``: ``x`` ``(4, m, L)`` at the
        times ``t`` ``(L,)`` with the inputs ``u`` ``(k, L)`` (or one time: ``(4, m)``)."""
        q = self.params if x.ndim == 2 else self._col
        f, ft, delta = self._elements(t, x, u)
        acc = -f if self._ia is None else u[self._ia] - f
        values = {
            "xs": x[2],
            "xu": x[3],
            "susp_travel": x[2] - x[3],
            "tire_defl": np.broadcast_to(delta, x[3].shape),
            "body_acc": acc / q["ms"],
            "tire_force": np.broadcast_to(ft, x[3].shape),
        }
        return {label: values[label] for label in self.output_labels}

    def switching(self, t: float, x: np.ndarray, u) -> np.ndarray:
        """The switching functions ``(q, m)`` (``switching_labels``; the single car's)."""
        q = self.params
        d = x[2] - x[3]
        rows = []
        if self._unilateral:
            rows.append(q["static"] / q["ku"] - (x[3] - self._road(t, u)))
        stop = self._stop
        if stop is not None:
            if math.isfinite(stop.clearance_bound):
                rows.append(d + stop.clearance_bound)
            if math.isfinite(stop.clearance_rebound):
                rows.append(stop.clearance_rebound - d)
        if isinstance(self._damper, PiecewiseDamper):
            rows += [x[0] - x[1] - k for k in self._damper.knees()]
        return np.array(rows).reshape(len(rows), x.shape[1])
