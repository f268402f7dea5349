"""The nonlinear quarter car: wheel lift-off, bump stops, a nonlinear damper and spring.

The seed's two masses (`qc_control.model`), with the force elements made
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
from collections.abc import Callable
from dataclasses import dataclass

import control
import numpy as np

from .model import OUTPUTS, STATES, UNITS, as_params
from .vehicle import STANDARD_GRAVITY, Corner, SignalRoles, VehicleModel

__all__ = [
    "PiecewiseDamper",
    "BumpStop",
    "nonlinear_quarter_car",
    "nonlinear_quarter_car_model",
    "NONLINEAR_OUTPUTS",
    "NONLINEAR_UNITS",
]

#: The outputs of the nonlinear car: quarter_car's, then the tire contact force.
NONLINEAR_OUTPUTS = (*OUTPUTS, "tire_force")
#: The SI unit of every signal of the nonlinear car.
NONLINEAR_UNITS = {**UNITS, "tire_force": "N"}

_TIRES = ("unilateral", "linear")


def _number(name: str, value, *, minimum: float = 0.0, strict: bool = False, inf: bool = False):
    """``value`` as a float >= minimum (or > when strict), or a ValueError naming it."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
        raise ValueError(f"{name} must be a number, got {value!r}")
    value = float(value)
    if math.isnan(value) or (math.isinf(value) and not inf):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if value < minimum or (strict and value == minimum):
        sign = ">" if strict else ">="
        raise ValueError(f"{name} must be {sign} {minimum:g}, got {value!r}")
    return value


def _unset(value) -> bool:
    """None or NaN: a high-speed coefficient left to default to the low-speed one."""
    return value is None or (isinstance(value, float) and math.isnan(value))


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
    """

    rebound: float
    bound: float
    knee_rebound: float = math.inf
    knee_bound: float = math.inf
    rebound_high: float = math.nan
    bound_high: float = math.nan

    def __post_init__(self):
        for name in ("rebound", "bound"):
            object.__setattr__(self, name, _number(name, getattr(self, name)))
        for name in ("knee_rebound", "knee_bound"):
            value = _number(name, getattr(self, name), strict=True, inf=True)
            object.__setattr__(self, name, value)
        for name, low in (("rebound_high", "rebound"), ("bound_high", "bound")):
            value = getattr(self, name)
            value = getattr(self, low) if _unset(value) else _number(name, value)
            object.__setattr__(self, name, value)

    def __call__(self, v: float) -> float:
        if v >= 0:
            if v <= self.knee_rebound:
                return self.rebound * v
            return self.rebound * self.knee_rebound + self.rebound_high * (v - self.knee_rebound)
        if v >= -self.knee_bound:
            return self.bound * v
        return -self.bound * self.knee_bound + self.bound_high * (v + self.knee_bound)

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
        Travel in extension before the rebound stop touches [m], > 0
        (inf: no rebound stop).
    """

    clearance_bound: float
    stiffness: float
    cubic: float = 0.0
    clearance_rebound: float = math.inf

    def __post_init__(self):
        object.__setattr__(
            self, "clearance_bound", _number("clearance_bound", self.clearance_bound, inf=True)
        )
        object.__setattr__(
            self,
            "clearance_rebound",
            _number("clearance_rebound", self.clearance_rebound, inf=True),
        )
        object.__setattr__(self, "stiffness", _number("stiffness", self.stiffness))
        object.__setattr__(self, "cubic", _number("cubic", self.cubic))

    def force(self, d: float) -> float:
        """The stops' force on the body against the extension ``d`` [N] (0 inside the clearance)."""
        p = -d - self.clearance_bound
        if p > 0:
            return -(self.stiffness * p + self.cubic * p**3)
        p = d - self.clearance_rebound
        if p > 0:
            return self.stiffness * p + self.cubic * p**3
        return 0.0

    def energy(self, d: float) -> float:
        """The stops' potential energy at extension ``d`` [J]: ``k p²/2 + k3 p⁴/4``."""
        p = max(-d - self.clearance_bound, d - self.clearance_rebound, 0.0)
        return 0.5 * self.stiffness * p**2 + 0.25 * self.cubic * p**4


def _check_spring(spring, ks: float) -> float | None:
    """The cubic coefficient ``k3`` for a number, None for a callable (checked at d = 0)."""
    if callable(spring):
        try:
            f0 = float(spring(0.0))
        except Exception as exc:
            raise ValueError(f"spring(0.0) failed: {type(exc).__name__}: {exc}") from None
        if not abs(f0) <= 1e-9 * ks:
            raise ValueError(
                f"spring must give 0 N at the static point (d = 0): spring(0.0) = {f0!r}; "
                "measure its force from the static preload"
            )
        return None
    return _number("spring (the cubic coefficient k3 [N/m³])", spring)


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
        raise ValueError(f"damper(0.0) must be finite, got {f0!r}")


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
    road : bool or callable ``zr(t)`` [m], default True
        True: the input ``zr`` [m], as in `quarter_car` (but on by default:
        the nonlinear car is mostly driven by one). A callable: the road
        height as a function of time, evaluated at every stage (no ``zr``
        input), so that no interpolation of samples limits the order of a
        convergence study.
    actuator : bool
        The input ``fa`` [N], as in `quarter_car`.
    name : str

    Returns
    -------
    control.NonlinearIOSystem
        Also with ``switching(t, x, u, params) -> ndarray`` and
        ``switching_labels``: the functions whose sign changes are the
        kinks of the right-hand side (for ``events=True``).

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
    p = as_params(params)
    if tire not in _TIRES:
        raise ValueError(f"tire must be 'unilateral' or 'linear', got {tire!r}")
    if bump_stop is not None and not isinstance(bump_stop, BumpStop):
        raise TypeError(f"bump_stop must be a BumpStop or None, got {type(bump_stop).__name__}")
    if not isinstance(gravity, bool):
        raise TypeError(f"gravity must be True or False, got {gravity!r}")
    unilateral = tire == "unilateral"
    g = STANDARD_GRAVITY if gravity else 0.0
    k3 = None if spring is None else _check_spring(spring, p.ks)
    if damper is not None:
        _check_damper(damper)
    stop = bump_stop
    profile = road if callable(road) else None
    if profile is None and not isinstance(road, bool):
        raise TypeError(f"road must be True, False or a callable zr(t) [m], got {road!r}")
    road_input = road is True
    iz = 0 if road_input else None
    ia = (1 if road_input else 0) if actuator else None

    def zr_at(t, u):
        if iz is not None:
            return u[iz]
        return 0.0 if profile is None else float(profile(t))

    def elements(t, x, u, q):
        """The force elements at the state ``x``: ``(F_s + F_d + F_b, F_t - ku δ0, F_t, δ)``."""
        vs, vu, xs, xu = x[0], x[1], x[2], x[3]
        d, v = xs - xu, vs - vu
        if spring is None:
            fs = q["ks"] * d
        elif k3 is not None:
            fs = q["ks"] * d + k3 * d**3
        else:
            fs = float(spring(d))
        fd = q["cs"] * v if damper is None else float(damper(v))
        fb = stop.force(d) if stop is not None else 0.0
        delta = xu - zr_at(t, u)
        ku = q["ku"]
        static = (q["ms"] + q["mu"]) * g
        ft = static - ku * delta
        if unilateral and ft < 0.0:
            ft = 0.0
        return fs + fd + fb, ft - static, ft, delta

    def update(t, x, u, q):
        f, tire_dyn, _, _ = elements(t, x, u, q)
        fa = u[ia] if ia is not None else 0.0
        return np.array([(fa - f) / q["ms"], (f - fa + tire_dyn) / q["mu"], x[0], x[1]])

    def output(t, x, u, q):
        f, _, ft, delta = elements(t, x, u, q)
        fa = u[ia] if ia is not None else 0.0
        return np.array([x[2], x[3], x[2] - x[3], delta, (fa - f) / q["ms"], ft])

    labels: list[str] = []
    kinks: list[Callable] = []
    if unilateral:
        labels.append("contact")
        kinks.append(lambda t, x, u, q: (q["ms"] + q["mu"]) * g / q["ku"] - (x[3] - zr_at(t, u)))
    if stop is not None:
        if math.isfinite(stop.clearance_bound):
            labels.append("bump stop")
            kinks.append(lambda t, x, u, q: x[2] - x[3] + stop.clearance_bound)
        if math.isfinite(stop.clearance_rebound):
            labels.append("rebound stop")
            kinks.append(lambda t, x, u, q: stop.clearance_rebound - (x[2] - x[3]))
    if isinstance(damper, PiecewiseDamper):
        for knee in damper.knees():
            labels.append(f"damper knee {knee:+g} m/s")
            kinks.append(lambda t, x, u, q, k=knee: x[0] - x[1] - k)

    def switching(t, x, u, q):
        return np.array([k(t, x, u, q) for k in kinks])

    inputs = [s for s, on in (("zr", road_input), ("fa", actuator)) if on]
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
    sys.switching_labels = tuple(labels)
    return sys


def nonlinear_quarter_car_model(params=None, **options) -> VehicleModel:
    """The nonlinear quarter car as a `VehicleModel`: `nonlinear_quarter_car` plus roles.

    The roles are `qc_control.quarter_car_model`'s (body acceleration
    ``body_acc``, body displacement ``xs``, one corner with ``susp_travel``,
    ``tire_defl``, the road ``zr`` when the car has that input, the tire
    stiffness ``ku`` and the static load ``(ms + mu)·g``), so that compare,
    ride metrics, sweeps and the report read it as they read the linear car.
    Its ``system`` is the `control.NonlinearIOSystem`; ``rebuild(params)``
    builds the same car (same options) from other parameters.

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
    sys = nonlinear_quarter_car(p, **options)
    corner = Corner(
        "",
        "susp_travel",
        "tire_defl",
        "zr" if "zr" in sys.input_labels else None,
        p.ku,
        (p.ms + p.mu) * STANDARD_GRAVITY,
    )
    return VehicleModel(
        sys,
        p,
        NONLINEAR_UNITS,
        SignalRoles("body_acc", "xs", (corner,)),
        functools.partial(nonlinear_quarter_car_model, **options),
    )
