"""The half car (bounce-pitch, 4 DOF) and the full car (heave-pitch-roll, 7 DOF).

Both are rigid bodies on linear corner suspensions (spring ``ks`` and damper
``cs`` between the body and an unsprung mass ``mu``) and linear tires
(stiffness ``ku``), for small motions about the static equilibrium.

Conventions (written once, used by every output):

- ``z`` [m] is the heave of the body's centre of gravity (CG), positive up.
- ``theta`` [rad] is the pitch, positive **nose up**: a body point at ``x``
  [m] ahead of the CG (``x = a`` at the front axle, ``x = -b`` at the rear)
  moves ``z + x·theta``. (ISO 8855 counts pitch positive nose-down; here the
  sign is flipped so that a front bump gives a positive pitch.)
- ``phi`` [rad] (full car) is the roll, positive **left side up** (ISO 8855:
  right-hand rotation about the forward x axis): a point at ``y`` [m] to the
  left of the CG moves ``z + x·theta + y·phi``.
- Wheel displacements ``xu_*`` [m] are positive up; the suspension travel at
  a corner is ``body point - wheel`` (extension positive, as the quarter
  car's ``xs - xu``) and the tire deflection is ``wheel - road`` (compression
  negative).
- The state is the velocities, then the displacements, as the quarter car's
  ``[vs, vu, xs, xu]``: ``x = [q', q]`` with ``q = [z, theta, xu_front,
  xu_rear]`` (half car) or ``[z, theta, phi, xu_fl, xu_fr, xu_rl, xu_rr]``
  (full car). Then ``A = [[-M⁻¹C, -M⁻¹K], [I, 0]]``.

The equations of motion are Lagrange's for the kinetic energy
``T = ½ q'ᵀ M q'``, the potential ``V = ½ qᵀ K q`` and the dissipation
``D = ½ q'ᵀ C q'``, with

.. math::

    V = \\tfrac12 \\sum_i k_{s,i} s_i^2 + \\tfrac12 \\sum_i k_{u,i} (x_{u,i} - z_{r,i})^2
        + \\tfrac12 \\sum_{axles} K_{arb} \\Big(\\frac{s_{left} - s_{right}}{t}\\Big)^2

where ``s_i`` is the suspension travel at corner ``i`` and the anti-roll bar
of an axle of track ``t`` resists the roll of the axle relative to the body
with the roll stiffness ``K_arb`` [N·m/rad] (Gillespie, *Fundamentals of
Vehicle Dynamics*, SAE 1992, ch. 5 and 8; Jazar, *Vehicle Dynamics*, 2nd ed.
2014, ch. 15).

The default vehicle is the passenger car of Ikenaga, Lewis, Campos and Davis,
"Active suspension control of ground vehicle based on a full-vehicle model",
Proc. American Control Conference 2000, pp. 4019-4024 (Table 1); the half car
is its bicycle half (half the body mass and pitch inertia, one corner per axle).
Its spring, damper, unsprung-mass and tire values and Iy agree with the public
parameter file ``half_car_parameter.m`` of github.com/junhyukch7/Semi-Active-Suspension;
ms, Ix, a, b and the tracks are quoted from the paper's Table 1, not rechecked here.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import control
import numpy as np

from ..numerics.checks import Field, ParameterError, blamed_field, check_fields, instance_from
from .quarter import MAX_RATE_SPAN
from .vehicle import STANDARD_GRAVITY, BatchedModel, Corner, SignalRoles, VehicleModel, params_as

__all__ = [
    "HalfCarParams",
    "FullCarParams",
    "half_car",
    "half_car_model",
    "full_car",
    "full_car_model",
    "vehicle_abcd",
    "HALF_CAR_CORNERS",
    "FULL_CAR_CORNERS",
]

#: Corner suffixes and names of the half car, in corner order.
HALF_CAR_CORNERS = (("front", "front"), ("rear", "rear"))
#: Corner suffixes and names of the full car, in corner order.
FULL_CAR_CORNERS = (
    ("fl", "front left"),
    ("fr", "front right"),
    ("rl", "rear left"),
    ("rr", "rear right"),
)

#: Each parameter of both cars declared once: what it is, its SI unit, its
#: range. The constructors validate from it, `_VehicleParams.table` reports from it.
_SPEC: dict[str, Field] = {
    "ms": Field("sprung (body) mass", "kg"),
    "Ix": Field("roll moment of inertia of the body about its CG", "kg·m²"),
    "Iy": Field("pitch moment of inertia of the body about its CG", "kg·m²"),
    "a": Field("distance from the CG to the front axle", "m"),
    "b": Field("distance from the CG to the rear axle", "m"),
    "track_front": Field("front track width", "m"),
    "track_rear": Field("rear track width", "m"),
    "ks_front": Field("front suspension stiffness (per wheel)", "N/m"),
    "ks_rear": Field("rear suspension stiffness (per wheel)", "N/m"),
    "cs_front": Field("front suspension damping (per wheel)", "N·s/m", "nonneg"),
    "cs_rear": Field("rear suspension damping (per wheel)", "N·s/m", "nonneg"),
    "mu_front": Field("front unsprung mass (per wheel)", "kg"),
    "mu_rear": Field("rear unsprung mass (per wheel)", "kg"),
    "ku_front": Field("front tire stiffness (per wheel)", "N/m"),
    "ku_rear": Field("rear tire stiffness (per wheel)", "N/m"),
    "arb_front": Field("front anti-roll bar roll stiffness", "N·m/rad", "nonneg"),
    "arb_rear": Field("rear anti-roll bar roll stiffness", "N·m/rad", "nonneg"),
    "seat_x": Field("seat position ahead of the CG", "m", "finite"),
    "seat_y": Field("seat position left of the CG", "m", "finite"),
}


class _VehicleParams:
    """Validation, ``from_mapping``, ``to_dict`` and ``table`` shared by both cars."""

    kind: ClassVar[str]

    def __post_init__(self):
        check_fields(self, self.spec())
        self._check_scales()

    @classmethod
    def spec(cls) -> dict[str, Field]:
        """This car's fields, declared: ``{name: Field}`` in field order."""
        return {f.name: _SPEC[f.name] for f in fields(cls)}  # type: ignore[arg-type]

    def _rates(self) -> tuple[dict[str, float], dict[str, float]]:
        """The car's stiffness rates and damping rates [1/s], by plain arithmetic.

        Each mode's natural frequency lies among the stiffness rates:
        ``sqrt(k/m)`` of every wheel (against its tire and its spring), of
        the body's heave, and of its pitch (``Σ k l²/Iy``) and roll
        (``(Σ k t²/4 + arb)/Ix``) about the CG; the damping rates ``c/m``
        and ``c l²/I`` are the decay rates. Products, not ``**``: an
        overflow is then ``inf``, refused by name, never an OverflowError.
        """
        v = {f.name: getattr(self, f.name) for f in fields(self)}  # type: ignore[arg-type]
        wheels = 1 if self.kind == "half" else 2  # per axle
        arm = {"front": v["a"], "rear": v["b"]}
        stiff = {}
        damp = {}
        for ax, l in arm.items():
            mu = v[f"mu_{ax}"]
            stiff[f"sqrt(ks_{ax}/mu_{ax})"] = math.sqrt(v[f"ks_{ax}"] / mu)
            stiff[f"sqrt(ku_{ax}/mu_{ax})"] = math.sqrt(v[f"ku_{ax}"] / mu)
            damp[f"cs_{ax}/mu_{ax}"] = v[f"cs_{ax}"] / mu
            damp[f"cs_{ax}*{'a' if ax == 'front' else 'b'}²/Iy"] = (
                wheels * v[f"cs_{ax}"] * l * l / v["Iy"]
            )
        ks = {ax: wheels * v[f"ks_{ax}"] for ax in arm}
        stiff["sqrt(Σks/ms)"] = math.sqrt((ks["front"] + ks["rear"]) / v["ms"])
        stiff["sqrt(Σks·l²/Iy)"] = math.sqrt(
            (ks["front"] * arm["front"] * arm["front"] + ks["rear"] * arm["rear"] * arm["rear"])
            / v["Iy"]
        )
        damp["Σcs/ms"] = wheels * (v["cs_front"] + v["cs_rear"]) / v["ms"]
        if self.kind == "full":
            roll = sum(
                v[f"ks_{ax}"] * v[f"track_{ax}"] * v[f"track_{ax}"] / 2 + v[f"arb_{ax}"]
                for ax in arm
            )
            stiff["sqrt(roll stiffness/Ix)"] = math.sqrt(roll / v["Ix"])
        return stiff, damp

    def _check_scales(self) -> None:
        """Refuse a car whose matrix overflows or whose modes cannot be resolved.

        As for the quarter car (`QuarterCarParams`): every rate must be
        finite, and the fastest at most `MAX_RATE_SPAN` times the slowest
        stiffness rate (light damping is a slow decay, harmless). The seat,
        where ``seat_acc`` is read, must be in the car: within ten
        wheelbases of the CG (and ten tracks across), so that its lever arm
        times the body's rotation stays finite.
        """
        stiff, damp = self._rates()
        rates = {**stiff, **damp}
        bad = next((k for k, r in rates.items() if not math.isfinite(r)), None)
        if bad is not None:
            self._refuse(
                blamed_field(self, bad),
                f"a value for which the {self.kind} car's matrix is finite, but it would not "
                f"be finite: {bad} overflows to {rates[bad]!r} ({self._values()})",
            )
        slow = min(stiff, key=stiff.__getitem__)
        fast = max(rates, key=rates.__getitem__)
        if rates[fast] > MAX_RATE_SPAN * stiff[slow]:
            self._refuse(
                blamed_field(self, fast),
                f"a value whose modes can be resolved in double precision, but the "
                f"{self.kind} car's time scales span more than {MAX_RATE_SPAN:.0e}: {fast} = "
                f"{rates[fast]:.3g} 1/s against {slow} = {stiff[slow]:.3g} 1/s "
                f"({self._values()})",
            )
        self._check_lengths()
        self._check_seat()

    def _check_lengths(self) -> None:
        # the model divides by the squared track (an anti-roll bar's force per
        # wheel is its moment over the track): a length 1e7 times shorter than
        # the wheelbase is a car of no width, and its square underflows first
        names = ["a", "b", "track_front", "track_rear"][: 2 if self.kind == "half" else 4]
        for name in names:
            value = getattr(self, name)
            if value * MAX_RATE_SPAN < self.wheelbase:
                self._refuse(
                    name,
                    f"at most {MAX_RATE_SPAN:.0e} times shorter than the wheelbase a + b = "
                    f"{self.wheelbase:.6g} m",
                )

    def _check_seat(self) -> None:
        reach = {"seat_x": 10 * self.wheelbase}
        if self.kind == "full":
            reach["seat_y"] = 10 * max(self.track_front, self.track_rear)  # type: ignore[attr-defined]
        for name, limit in reach.items():
            value = getattr(self, name)
            if abs(value) > limit:
                self._refuse(
                    name,
                    f"within {limit:.6g} m of the CG (ten "
                    f"{'wheelbases' if name == 'seat_x' else 'track widths'})",
                )

    def _refuse(self, name: str, expected: str) -> None:
        """A cross-field refusal: a `ParameterError` naming the field ``name``."""
        raise ParameterError(
            name, getattr(self, name), expected, description=_SPEC[name].description
        )

    def _values(self) -> str:
        return ", ".join(f"{f.name}={getattr(self, f.name):.6g}" for f in fields(self))  # type: ignore[arg-type]

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any]):
        """Build from a dict; an unknown key is a `qc_control.ParameterError` naming it."""
        return instance_from(cls, values)

    def to_dict(self, *, changing: Iterable[str] | None = None) -> dict[str, float]:
        """Every field as a plain dict. ``changing`` is accepted for the sweep
        interface (`qc_control.design_grid`); no field depends on another."""
        return {f.name: getattr(self, f.name) for f in fields(self)}  # type: ignore[arg-type]

    def table(self) -> list[tuple[str, str, float, str]]:
        """Rows ``(symbol, description, value, unit)`` for reports."""
        return [(n, f.description, getattr(self, n), f.unit) for n, f in self.spec().items()]

    def model(self, *, road: bool = False, actuator: bool = False) -> VehicleModel:
        """This car as a `VehicleModel` (`half_car_model` or `full_car_model`)."""
        return _model(self, road, actuator)

    @property
    def wheelbase(self) -> float:
        """``a + b`` [m]."""
        return self.a + self.b  # type: ignore[attr-defined]


@dataclass(frozen=True)
class HalfCarParams(_VehicleParams):
    """Parameters of the 4-DOF bounce-pitch half car, SI units.

    Defaults: the bicycle half of Ikenaga et al. (2000), Table 1 (see the
    module docstring): half the body's mass and pitch inertia, one wheel per
    axle.

    Parameters
    ----------
    ms : float
        Body mass [kg], > 0. Default 730.
    Iy : float
        Pitch moment of inertia about the CG [kg·m²], > 0. Default 1230.
    a, b : float
        CG to front axle and CG to rear axle [m], > 0. Default 1.011, 1.803.
    ks_front, ks_rear : float
        Suspension stiffness [N/m], > 0. Default 19960, 17500.
    cs_front, cs_rear : float
        Suspension damping [N·s/m], >= 0. Default 1290, 1620.
    mu_front, mu_rear : float
        Unsprung mass [kg], > 0. Default 40, 35.5.
    ku_front, ku_rear : float
        Tire stiffness [N/m], > 0. Default 175500 both.
    seat_x : float
        Where ``seat_acc`` is measured: the distance ahead of the CG [m]
        (negative behind it). Default 0 (at the CG).

    Raises
    ------
    qc_control.ParameterError
        (a ``ValueError``) A value that is not a finite number (a bool is
        not), a mass, inertia, length or stiffness that is not > 0, a
        damping < 0, a length or seat out of the car's proportions, or time
        scales that cannot be resolved; ``.name`` is the field, ``.value``
        the value, and the message gives the field's meaning (each declared
        once, in ``_SPEC``).

    Examples
    --------
    >>> p = HalfCarParams()
    >>> round(p.wheelbase, 3), p.ms
    (2.814, 730.0)
    """

    ms: float = 730.0
    Iy: float = 1230.0
    a: float = 1.011
    b: float = 1.803
    kind: ClassVar[str] = "half"  # the body above; one wheel per axle below
    ks_front: float = 19960.0
    ks_rear: float = 17500.0
    cs_front: float = 1290.0
    cs_rear: float = 1620.0
    mu_front: float = 40.0
    mu_rear: float = 35.5
    ku_front: float = 175500.0
    ku_rear: float = 175500.0
    seat_x: float = 0.0


@dataclass(frozen=True)
class FullCarParams(_VehicleParams):
    """Parameters of the 7-DOF heave-pitch-roll full car, SI units.

    The body's CG is on the centre line; left and right wheels of an axle
    are equal. Defaults: Ikenaga et al. (2000), Table 1 (module docstring),
    without anti-roll bars.

    Parameters
    ----------
    ms : float
        Body mass [kg]. Default 1460.
    Ix, Iy : float
        Roll and pitch moments of inertia about the CG [kg·m²]. Default 460,
        2460.
    a, b : float
        CG to front and rear axle [m]. Default 1.011, 1.803.
    track_front, track_rear : float
        Track widths [m] (wheel centre to wheel centre). Default 1.522 both.
    ks_front, ks_rear, cs_front, cs_rear, mu_front, mu_rear, ku_front, ku_rear : float
        Per wheel, as in `HalfCarParams`.
    arb_front, arb_rear : float
        Anti-roll bar roll stiffness of each axle [N·m/rad], >= 0: the moment
        per radian of the axle's roll relative to the body,
        ``(s_left - s_right)/track``. Default 0 (no bar).
    seat_x, seat_y : float
        Where ``seat_acc`` is measured: ahead of and left of the CG [m].
        Default 0, 0.
    """

    kind: ClassVar[str] = "full"

    ms: float = 1460.0
    Ix: float = 460.0
    Iy: float = 2460.0
    # the axles' positions and each wheel are the half car's: one source for
    # Ikenaga et al.'s geometry and axle data
    a: float = HalfCarParams.a
    b: float = HalfCarParams.b
    track_front: float = 1.522
    track_rear: float = 1.522
    ks_front: float = HalfCarParams.ks_front
    ks_rear: float = HalfCarParams.ks_rear
    cs_front: float = HalfCarParams.cs_front
    cs_rear: float = HalfCarParams.cs_rear
    mu_front: float = HalfCarParams.mu_front
    mu_rear: float = HalfCarParams.mu_rear
    ku_front: float = HalfCarParams.ku_front
    ku_rear: float = HalfCarParams.ku_rear
    arb_front: float = 0.0
    arb_rear: float = 0.0
    seat_x: float = 0.0
    seat_y: float = 0.0


def _labels(kind: str) -> dict[str, list[str]]:
    """State, input and output labels of a car (all inputs: roads then actuators)."""
    corners = HALF_CAR_CORNERS if kind == "half" else FULL_CAR_CORNERS
    body = ["z", "theta"] + (["phi"] if kind == "full" else [])
    wheels = [f"xu_{s}" for s, _ in corners]
    q = body + wheels
    return {
        "states": [f"v{label}" for label in q] + q,
        "road": [f"zr_{s}" for s, _ in corners],
        "actuator": [f"fa_{s}" for s, _ in corners],
        "outputs": q
        + [f"susp_travel_{s}" for s, _ in corners]
        + [f"tire_defl_{s}" for s, _ in corners]
        + ["heave_acc", "pitch_acc"]
        + (["roll_acc"] if kind == "full" else [])
        + ["seat_acc"],
    }


def _units(kind: str) -> dict[str, str]:
    units = {}
    labels = _labels(kind)
    for label in labels["states"]:
        angle = label.endswith(("theta", "phi"))
        speed = label.startswith("v")
        units[label] = ("rad" if angle else "m") + ("/s" if speed else "")
    units |= {label: "m" for label in labels["road"]}
    units |= {label: "N" for label in labels["actuator"]}
    for label in labels["outputs"]:
        units.setdefault(label, "m")
    units |= {"heave_acc": "m/s²", "pitch_acc": "rad/s²", "roll_acc": "rad/s²", "seat_acc": "m/s²"}
    return units


def vehicle_abcd(kind: str, p: Mapping[str, np.ndarray], *, road=True, actuator=True):
    """``A, B, C, D`` of the half (``kind='half'``) or full car, one design or many.

    ``p`` maps every field of `HalfCarParams` / `FullCarParams` to a number
    or to equal-shaped arrays (a batch of ``m`` designs, a leading ``(m,)``
    on every matrix). Inputs: the road heights (if ``road``), then the
    actuator forces (if ``actuator``), corner by corner; outputs as
    `half_car` and `full_car` list them. This is the one place the matrices
    are assembled.

    Notes
    -----
    With the corner incidence ``E`` (``s = E q``: the suspension travel of
    every corner), the tire incidence ``W`` (``W q``: the wheels'
    displacements) and, for the full car, the axle roll rows ``R``
    (``(s_left - s_right)/t``),

    .. math:: K = E^T K_s E + W^T K_u W + R^T K_{arb} R, \\quad C = E^T C_s E,
              \\quad M = \\mathrm{diag}(m_s, I_y[, I_x], m_u...)

    the road enters as the generalised force ``Wᵀ K_u z_r`` and an actuator
    force ``f`` pushing body and wheel apart as ``Eᵀ f``.
    """
    full = kind == "full"
    ms = np.asarray(p["ms"], dtype=float)
    batch = ms.shape
    one = np.ones(batch)
    nc = 4 if full else 2
    nb = 3 if full else 2
    n = nb + nc
    # corner geometry: x ahead of the CG, y left of it; per-corner parameters
    a, b = np.asarray(p["a"], dtype=float), np.asarray(p["b"], dtype=float)
    if full:
        tf, tr = (np.asarray(p[k], dtype=float) for k in ("track_front", "track_rear"))
        xs = [a, a, -b, -b]
        ys = [tf / 2, -tf / 2, tr / 2, -tr / 2]
        axle = ["front", "front", "rear", "rear"]
    else:
        xs, ys, axle = [a, -b], [0 * one, 0 * one], ["front", "rear"]

    def per_corner(name):
        return np.stack([np.asarray(p[f"{name}_{ax}"], dtype=float) * one for ax in axle], -1)

    ks, cs, mu, ku = (per_corner(k) for k in ("ks", "cs", "mu", "ku"))
    E = np.zeros(batch + (nc, n))
    W = np.zeros(batch + (nc, n))
    for i in range(nc):
        E[..., i, 0] = 1.0
        E[..., i, 1] = xs[i]
        if full:
            E[..., i, 2] = ys[i]
        E[..., i, nb + i] = -1.0
        W[..., i, nb + i] = 1.0
    Et = np.swapaxes(E, -1, -2)
    Wt = np.swapaxes(W, -1, -2)
    K = Et @ (ks[..., :, None] * E) + Wt @ (ku[..., :, None] * W)
    Cm = Et @ (cs[..., :, None] * E)
    if full:
        for left, right, track, bar in ((0, 1, tf, "arb_front"), (2, 3, tr, "arb_rear")):
            R = (E[..., left, :] - E[..., right, :]) / track[..., None]
            K = K + np.asarray(p[bar], dtype=float)[..., None, None] * (
                R[..., :, None] * R[..., None, :]
            )
    inertia = [ms * one, np.asarray(p["Iy"], dtype=float) * one]
    if full:
        inertia.append(np.asarray(p["Ix"], dtype=float) * one)
    minv = 1.0 / np.concatenate([np.stack(inertia, -1), mu], axis=-1)  # (..., n)
    A = np.zeros(batch + (2 * n, 2 * n))
    A[..., :n, :n] = -minv[..., :, None] * Cm + 0.0  # + 0.0: no -0.0 entries
    A[..., :n, n:] = -minv[..., :, None] * K + 0.0
    A[..., n:, :n] = np.eye(n)
    columns = []
    if road:
        columns.append(Wt * ku[..., None, :])  # (..., n, nc)
    if actuator:
        columns.append(Et)
    Bq = np.concatenate(columns, axis=-1) if columns else np.zeros(batch + (n, 0))
    k = int(np.shape(Bq)[-1])
    B = np.zeros(batch + (2 * n, k))
    B[..., :n, :] = minv[..., :, None] * Bq
    # outputs: q, travel E q, tire W q - zr, accelerations (rows of A x + B u), seat
    no = n + 2 * nc + nb + 1
    C = np.zeros(batch + (no, 2 * n))
    D = np.zeros(batch + (no, k))
    C[..., :n, n:] = np.eye(n)
    C[..., n : n + nc, n:] = E
    C[..., n + nc : n + 2 * nc, n:] = W
    if road:
        D[..., n + nc : n + 2 * nc, :nc] = 0.0 - np.eye(nc)
    acc = n + 2 * nc
    C[..., acc : acc + nb, :] = A[..., :nb, :]
    D[..., acc : acc + nb, :] = B[..., :nb, :]
    seat = np.stack(
        [one, np.asarray(p["seat_x"], dtype=float) * one]
        + ([np.asarray(p["seat_y"], dtype=float) * one] if full else []),
        -1,
    )  # (..., nb): the heave, pitch (and roll) weights of a body point
    C[..., -1, :] = np.einsum("...i,...ij->...j", seat, A[..., :nb, :])
    D[..., -1, :] = np.einsum("...i,...ij->...j", seat, B[..., :nb, :])
    return A, B, C, D


def _inputs(kind: str, road: bool, actuator: bool) -> list[str]:
    labels = _labels(kind)
    return (labels["road"] if road else []) + (labels["actuator"] if actuator else [])


def _system(p, road: bool, actuator: bool, name: str) -> control.StateSpace:
    A, B, C, D = vehicle_abcd(p.kind, p.to_dict(), road=road, actuator=actuator)
    labels = _labels(p.kind)
    return control.ss(
        A,
        B,
        C,
        D,
        states=labels["states"],
        inputs=_inputs(p.kind, road, actuator),
        outputs=labels["outputs"],
        name=name,
    )


def half_car(
    params=None, *, road: bool = False, actuator: bool = False, name: str = "half_car"
) -> control.StateSpace:
    """The 4-DOF bounce-pitch half car as a continuous-time ``control.StateSpace``.

    The body heaves and pitches on one wheel per axle: the side view of a
    car whose left and right sides move alike.

    Parameters
    ----------
    params : HalfCarParams or dict, optional
        Default: `HalfCarParams` () (Ikenaga et al., 2000, bicycle half).
    road : bool, default False
        Add the inputs ``zr_front`` and ``zr_rear`` [m], the road under each
        wheel (for the delayed rear input of one road, see
        `qc_control.ride.road.wheelbase_inputs`).
    actuator : bool, default False
        Add ``fa_front`` and ``fa_rear`` [N], forces pushing body and wheel
        apart at each axle.
    name : str

    Returns
    -------
    control.StateSpace
        States ``[vz, vtheta, vxu_front, vxu_rear, z, theta, xu_front,
        xu_rear]`` (velocities then displacements; module docstring for the
        signs: pitch positive nose up). Outputs:

        - ``z`` [m], ``theta`` [rad], ``xu_front``, ``xu_rear`` [m];
        - ``susp_travel_front = z + a·theta - xu_front`` and
          ``susp_travel_rear = z - b·theta - xu_rear`` [m];
        - ``tire_defl_front = xu_front - zr_front``, ``tire_defl_rear`` [m];
        - ``heave_acc`` [m/s²] and ``pitch_acc`` [rad/s²], rows of
          ``A x + B u`` (exact);
        - ``seat_acc = heave_acc + seat_x·pitch_acc`` [m/s²], the vertical
          acceleration of the body at ``seat_x`` ahead of the CG.

    Examples
    --------
    >>> sys = half_car(road=True)
    >>> sys.input_labels, sys.nstates
    (['zr_front', 'zr_rear'], 8)
    """
    return _system(params_as(HalfCarParams, params), road, actuator, name)


def full_car(
    params=None, *, road: bool = False, actuator: bool = False, name: str = "full_car"
) -> control.StateSpace:
    """The 7-DOF heave-pitch-roll full car as a ``control.StateSpace``.

    Corners in the order front left, front right, rear left, rear right
    (suffixes ``_fl``, ``_fr``, ``_rl``, ``_rr``).

    Parameters
    ----------
    params : FullCarParams or dict, optional
    road : bool, default False
        Add ``zr_fl``, ``zr_fr``, ``zr_rl``, ``zr_rr`` [m].
    actuator : bool, default False
        Add ``fa_fl`` ... ``fa_rr`` [N].
    name : str

    Returns
    -------
    control.StateSpace
        States ``[vz, vtheta, vphi, vxu_fl, ..., z, theta, phi, xu_fl, ...]``
        (roll positive left side up, pitch nose up). Outputs: the seven
        displacements, ``susp_travel_*`` (``z + x·theta + y·phi - xu``) and
        ``tire_defl_*`` per corner, ``heave_acc`` [m/s²], ``pitch_acc`` and
        ``roll_acc`` [rad/s²], and ``seat_acc`` at ``(seat_x, seat_y)``.

    Examples
    --------
    >>> sys = full_car(road=True)
    >>> sys.nstates, sys.input_labels[0]
    (14, 'zr_fl')
    """
    return _system(params_as(FullCarParams, params), road, actuator, name)


def _corners(p, road: bool) -> tuple[Corner, ...]:
    g, L = STANDARD_GRAVITY, p.a + p.b
    names = HALF_CAR_CORNERS if p.kind == "half" else FULL_CAR_CORNERS
    per_axle = 1 if p.kind == "half" else 2
    out = []
    for suffix, name in names:
        axle = "front" if name.startswith("front") else "rear"
        body = p.ms * (p.b if axle == "front" else p.a) / L / per_axle
        out.append(
            Corner(
                name,
                f"susp_travel_{suffix}",
                f"tire_defl_{suffix}",
                f"zr_{suffix}" if road else None,
                getattr(p, f"ku_{axle}"),
                (body + getattr(p, f"mu_{axle}")) * g,
            )
        )
    return tuple(out)


def _model(p, road: bool, actuator: bool) -> VehicleModel:
    build = half_car_model if p.kind == "half" else full_car_model
    return VehicleModel(
        _system(p, road, actuator, f"{p.kind}_car"),
        p,
        _units(p.kind),
        SignalRoles("seat_acc", "z", _corners(p, road)),
        functools.partial(build, road=road, actuator=actuator),
        functools.partial(_batch, kind=p.kind, road=road, actuator=actuator),
    )


def half_car_model(params=None, *, road: bool = False, actuator: bool = False) -> VehicleModel:
    """The half car as a `VehicleModel`.

    The body acceleration is ``seat_acc`` (at ``seat_x``), the body
    displacement ``z``; the corners ``front`` and ``rear`` carry their
    travel, tire deflection, road input (when ``road``), tire stiffness and
    static wheel load ``(ms·b/L + mu_front)·g`` and ``(ms·a/L + mu_rear)·g``
    (``L = a + b``).

    Examples
    --------
    >>> m = half_car_model(road=True)
    >>> [c.name for c in m.corners], m.road_inputs()
    (['front', 'rear'], ['zr_front', 'zr_rear'])
    """
    return _model(params_as(HalfCarParams, params), road, actuator)


def full_car_model(params=None, *, road: bool = False, actuator: bool = False) -> VehicleModel:
    """The full car as a `VehicleModel`: four corners, static loads
    ``(ms·b/(2L) + mu_front)·g`` in front and ``(ms·a/(2L) + mu_rear)·g`` at the rear."""
    return _model(params_as(FullCarParams, params), road, actuator)


def _batch(designs: Sequence[Any], *, kind: str, road: bool, actuator: bool) -> BatchedModel:
    """The matrices of many designs at once (no loop per design)."""
    cls = HalfCarParams if kind == "half" else FullCarParams
    ps = [params_as(cls, d) for d in designs]
    names = [f.name for f in fields(cls)]
    values = {n: np.array([getattr(p, n) for p in ps], dtype=float) for n in names}
    A, B, C, D = vehicle_abcd(kind, values, road=road, actuator=actuator)
    corners = [_corners(p, road) for p in ps]
    nc = len(corners[0]) if corners else (2 if kind == "half" else 4)
    stiffness = tuple(np.array([c[i].tire_stiffness for c in corners]) for i in range(nc))
    load = tuple(np.array([c[i].static_load for c in corners]) for i in range(nc))
    return BatchedModel(A, B, C, D, stiffness, load, values["a"] + values["b"])
