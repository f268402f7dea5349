"""Suspension controllers as python-control systems, and the closed loop.

Every controller here is a ``control`` system whose inputs are named after
the signals it measures and whose one output is the actuator force ``fa``
[N] of `qc_control.quarter_car` (``actuator=True``): a force between body
and wheel that pushes them apart, ``+fa`` on the body, ``-fa`` on the
wheel. `closed_loop` connects it to a car with ``control.interconnect``.

The measured signals are the car's outputs (``body_acc``, ``susp_travel``,
``tire_defl``, ``xs``, ``xu``) and its states (``vs``, ``vu``: body and
wheel velocity, what the velocity-feedback laws need). With ``vrel = vs -
vu`` the suspension's stroke velocity:

============================  ===========================================
law                           ideal force (active), source
============================  ===========================================
`skyhook`                     ``fa = -c·vs`` (Karnopp, Crosby & Harwood 1974)
`groundhook`                  ``fa = +c·vu`` (Valášek et al. 1997)
`hybrid`                      ``fa = α(-c·vs) + (1-α)(c·vu)``
                              (Goncalves & Ahmadian 2003)
`add_damper`                  semi-active only (Savaresi et al. 2005;
                              Savaresi & Spelta 2007)
`lqr_controller`              ``fa = -K_z [vs, vu, travel, tire_defl]``,
                              ``control.lqr`` (+ ``control.lqe``)
`hinf_controller`             ``control``'s H∞ plant, slycot ``sb10ad``
============================  ===========================================

A **semi-active** device is a damper whose coefficient ``c(t)`` is set
between ``cmin`` and ``cmax``: its force ``fa = -c(t)·vrel`` always
opposes the stroke velocity (``fa·vrel <= 0``), so it can only dissipate.
Given a law's ideal force ``f*``:

- ``'on-off'``: ``c = cmax`` when ``f*·vrel < 0`` (the damper can push the
  way the law asks), else ``cmin``;
- ``'continuous'`` (clipped): ``c = clip(-f*/vrel, cmin, cmax)`` when
  ``f*·vrel < 0``, else ``cmin``: the damper follows ``f*`` as far as it
  can.

These are `control.NonlinearIOSystem`; their closed loops run through
`qc_control.input_output_response`. The ideal (active) laws are static
gains, and their closed loops are ``control.StateSpace``.

The car keeps its own passive damper ``cs`` in parallel with the device;
to make the whole damper controllable, build the car with ``cs=0``.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import control
import numpy as np

from ..numerics.checks import (
    Field,
    ParameterError,
    check_fields,
    choice,
    nonnegative,
    number,
    positive,
)
from ..numerics.messages import install_hint
from .sampled_loop import sampled_loop
from .vehicle import VehicleModel

try:  # optional: qc-control[robust], for hinf_controller
    import slycot
except ImportError:  # pragma: no cover - depends on the installation
    slycot = None

#: Whether `hinf_controller` can run (slycot is installed).
HINF_AVAILABLE = slycot is not None

__all__ = [
    "skyhook",
    "groundhook",
    "hybrid",
    "add_damper",
    "lqr_controller",
    "hinf_controller",
    "HinfDesign",
    "closed_loop",
    "relative_coordinates",
    "lqr_weights",
    "SEMI_ACTIVE_MODES",
    "semi_active_coefficient",
    "HINF_AVAILABLE",
    "MATLAB_ACTIVE_SUSPENSION",
]

#: The semi-active modes: ``None`` is the ideal (active) law.
SEMI_ACTIVE_MODES = (None, "on-off", "continuous")

#: The measured velocity signals: the car's body and wheel velocity states.
_VELOCITIES = ("vs", "vu")


def _limits(cmin, cmax) -> tuple[float, float]:
    """The semi-active damper's range [N·s/m]: ``0 <= cmin < cmax``."""
    lo = nonnegative("cmin", cmin, "N·s/m", description="smallest damping of the damper")
    hi = positive("cmax", cmax, "N·s/m", description="largest damping of the damper")
    if hi <= lo:
        raise ParameterError(
            "cmax", cmax, f"> cmin = {lo!r} N·s/m", description="largest damping of the damper"
        )
    return lo, hi


def semi_active_coefficient(f_ideal, vrel, cmin: float, cmax: float, mode: str):
    """The damping ``c`` a semi-active damper takes to follow an ideal force.

    ``'on-off'``: ``cmax`` when ``f_ideal·vrel < 0``, else ``cmin``;
    ``'continuous'``: ``clip(-f_ideal/vrel, cmin, cmax)`` when
    ``f_ideal·vrel < 0``, else ``cmin``. The force is then ``-c·vrel``.
    """
    if isinstance(f_ideal, float) and isinstance(vrel, float):
        # one sample (a controller's output at a stage): plain float arithmetic, the
        # same decisions as the array path below, without its ~5 µs of NumPy calls
        if not f_ideal * vrel < 0:
            return cmin
        return cmax if mode == "on-off" else min(max(-f_ideal / vrel, cmin), cmax)
    f_ideal, vrel = np.asarray(f_ideal, dtype=float), np.asarray(vrel, dtype=float)
    wants = f_ideal * vrel < 0
    if mode == "on-off":
        return np.where(wants, cmax, cmin)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(wants, -f_ideal / np.where(wants, vrel, 1.0), cmin)
    return np.clip(c, cmin, cmax)


def _damping(params, f_ideal, vrel, mode, cmin, cmax):
    """`semi_active_coefficient` with the range and mode of ``params`` (a
    response's ``params`` override the law's own, as python-control passes
    them), the law's own where ``params`` does not name them."""
    return semi_active_coefficient(
        f_ideal,
        vrel,
        params.get("cmin", cmin),
        params.get("cmax", cmax),
        params.get("mode", mode),
    )


def _velocity_law(name: str, gain_vs: float, gain_vu: float, semi_active, cmin, cmax):
    """``fa = gain_vs·vs + gain_vu·vu``, ideal or clipped to a semi-active damper."""
    choice("semi_active", semi_active, SEMI_ACTIVE_MODES)
    if semi_active is None:
        return control.ss(
            np.zeros((0, 0)),
            np.zeros((0, 2)),
            np.zeros((1, 0)),
            [[gain_vs, gain_vu]],
            inputs=list(_VELOCITIES),
            outputs=["fa"],
            name=name,
        )
    lo, hi = _limits(cmin, cmax)

    def output(t, x, u, params):
        # the damper's range and mode from the system's parameters, so that
        # params={'cmax': ...} in a response changes the damper it simulates
        vs, vu = u[0], u[1]
        vrel = vs - vu
        f_ideal = gain_vs * vs + gain_vu * vu
        return np.array([-_damping(params, f_ideal, vrel, semi_active, lo, hi) * vrel])

    return _damper_law(None, output, name, {"cmin": lo, "cmax": hi, "mode": semi_active})


def _damper_law(update, output, name: str, params: dict, states=None):
    """A semi-active law as a system: the body and wheel velocities in, the
    force ``fa`` out (what `closed_loop` connects)."""
    return control.nlsys(
        update,
        output,
        inputs=list(_VELOCITIES),
        states=states,
        outputs=["fa"],
        name=name,
        params=params,
    )


def skyhook(c_sky: float, *, semi_active=None, cmin=0.0, cmax=None, name: str = "skyhook"):
    """Skyhook damping: a damper from the body to the sky.

    .. math:: f_a^* = -c_{sky}\\,\\dot x_s

    (Karnopp, Crosby & Harwood, "Vibration control using semi-active force
    generators", ASME J. Eng. Ind. 96(2), 1974.) The semi-active version
    (``semi_active='on-off'`` or ``'continuous'``) sets a damper between
    ``cmin`` and ``cmax`` (see the module notes): on-off is ``cmax`` when
    ``vs·(vs - vu) > 0``, ``cmin`` otherwise.

    Parameters
    ----------
    c_sky : float
        Skyhook damping [N·s/m], > 0.
    semi_active : None, 'on-off' or 'continuous'
        ``None``: the ideal active law, a static gain ``control.StateSpace``.
    cmin, cmax : float
        The semi-active damper's range [N·s/m], ``0 <= cmin < cmax``.
    name : str

    Returns
    -------
    control.StateSpace or control.NonlinearIOSystem
        Inputs ``['vs', 'vu']``, output ``['fa']``.

    Examples
    --------
    >>> sky = skyhook(2000.0)
    >>> sky.input_labels, sky.output_labels, sky.D.tolist()
    (['vs', 'vu'], ['fa'], [[-2000.0, 0.0]])
    """
    c = positive("c_sky", c_sky, "N·s/m")
    return _velocity_law(name, -c, 0.0, semi_active, cmin, cmax)


def groundhook(c_ground: float, *, semi_active=None, cmin=0.0, cmax=None, name="groundhook"):
    """Groundhook damping: a damper from the wheel to the ground.

    .. math:: f_a^* = +c_{gnd}\\,\\dot x_u

    (the force on the wheel is ``-fa = -c_gnd·vu``; Valášek, Novák, Šika &
    Vaculín, "Extended ground-hook: new concept of semi-active control of
    truck's suspension", Vehicle System Dynamics 27(5-6), 1997). It damps
    the wheel hop and so the dynamic tire load, at the body's expense.
    Parameters and return value as in `skyhook`.
    """
    c = positive("c_ground", c_ground, "N·s/m")
    return _velocity_law(name, 0.0, c, semi_active, cmin, cmax)


def hybrid(c: float, alpha: float = 0.5, *, semi_active=None, cmin=0.0, cmax=None, name="hybrid"):
    """The skyhook-groundhook blend.

    .. math:: f_a^* = \\alpha\\,(-c\\,\\dot x_s) + (1-\\alpha)\\,c\\,\\dot x_u

    ``alpha = 1`` is skyhook, ``alpha = 0`` groundhook (Goncalves &
    Ahmadian, "A hybrid control policy for semi-active vehicle
    suspensions", Shock and Vibration 10(1), 2003). The semi-active version
    clips the blended force (the paper clips each part and then blends; the
    two agree whenever both parts ask for dissipation).

    Parameters
    ----------
    c : float
        Damping of both hooks [N·s/m], > 0.
    alpha : float
        Weight of skyhook, in [0, 1].
    semi_active, cmin, cmax, name
        As in `skyhook`.
    """
    c = positive("c", c, "N·s/m")
    a = number("alpha", alpha, low=0.0, high=1.0, description="weight of skyhook")
    return _velocity_law(name, -a * c, (1 - a) * c, semi_active, cmin, cmax)


def add_damper(cmin: float, cmax: float, *, sensor_hz: float = 50.0, name: str = "add"):
    """The acceleration-driven damper (ADD), a semi-active comfort law.

    .. math:: c(t) = \\begin{cases} c_{max} & \\ddot x_s\\,(\\dot x_s - \\dot x_u) > 0
              \\\\ c_{min} & \\text{otherwise}\\end{cases}, \\qquad
              f_a = -c(t)\\,(\\dot x_s - \\dot x_u)

    (Savaresi, Silani & Bittanti, "Acceleration-Driven-Damper (ADD): an
    optimal control algorithm for comfort-oriented semiactive suspensions",
    ASME J. Dyn. Syst. Meas. Control 127(2), 2005; Savaresi & Spelta,
    "Mixed sky-hook and ADD: approaching the filtering limits of a
    semi-active suspension", ASME JDSMC 129(4), 2007.)

    The body acceleration is measured through a first-order accelerometer
    with bandwidth ``sensor_hz``, ``a_m = ω_c/(s + ω_c) · ẍs``. It is
    realised from the body velocity as ``a_m = ω_c (vs - z)``, ``z' = ω_c
    (vs - z)`` (the same transfer function, ``ω_c s/(s + ω_c)`` on ``vs``):
    the car's ``body_acc`` depends on ``fa`` at once, and fed back directly
    it would close an algebraic loop (the papers run the law at a sampling
    period instead).

    Parameters
    ----------
    cmin, cmax : float
        The damper's range [N·s/m], ``0 <= cmin < cmax``.
    sensor_hz : float
        Accelerometer bandwidth [Hz], > 0; its pole ``-2π·sensor_hz`` bounds
        a fixed step's stability (RK4: h < 2.79/(2π·sensor_hz)).
    name : str

    Returns
    -------
    control.NonlinearIOSystem
        Inputs ``['vs', 'vu']``, state ``['acc_filter']`` [m/s] (``z``
        above), output ``['fa']``.
    """
    lo, hi = _limits(cmin, cmax)
    wc = 2 * math.pi * positive("sensor_hz", sensor_hz, "Hz")

    def update(t, x, u, params):
        return np.array([wc * (u[0] - x[0])])

    def output(t, x, u, params):
        acc, vrel = wc * (u[0] - x[0]), u[0] - u[1]
        # on-off toward the force -acc·(anything > 0): cmax when acc·vrel > 0
        return np.array([-_damping(params, -acc, vrel, "on-off", lo, hi) * vrel])

    params = {"cmin": lo, "cmax": hi, "sensor_hz": float(sensor_hz)}
    return _damper_law(update, output, name, params, states=["acc_filter"])


# ---------------------------------------------------------------- LQR

#: Default LQR weights: each signal over the square of a typical size
#: (1 m/s² body acceleration, 5 cm travel, 5 mm tire deflection, 1 kN).
DEFAULT_LQR_WEIGHTS = {"body_acc": 1.0, "susp_travel": 400.0, "tire_defl": 4e4, "fa": 1e-6}


def _actuated(car: VehicleModel) -> tuple[np.ndarray, np.ndarray, int]:
    sys = car.system
    if not isinstance(car, VehicleModel):
        raise TypeError(f"car must be a VehicleModel, got {type(car).__name__}")
    if "fa" not in sys.input_labels:
        raise ValueError(
            f"car {car.name!r} has no actuator input 'fa'; build it with "
            "quarter_car_model(params, road=True, actuator=True)"
        )
    if not isinstance(sys, control.StateSpace):
        raise TypeError(f"car {car.name!r} must be linear (a control.StateSpace)")
    j = sys.input_labels.index("fa")
    return np.asarray(sys.A, dtype=float), np.asarray(sys.B, dtype=float), j


def lqr_weights(car: VehicleModel, weights: Mapping[str, float] | None = None):
    """``Q, R, N`` of the LQR cost on the car's outputs and the force.

    .. math:: J = \\int_0^\\infty \\Big(\\sum_i w_i\\, z_i^2 + w_f\\, f_a^2\\Big) dt,
              \\quad z = C_z x + D_z f_a

    with ``z`` the weighted outputs at zero road input, so that
    ``Q = C_zᵀ W C_z``, ``R = D_zᵀ W D_z + w_f``, ``N = C_zᵀ W D_z``
    (``body_acc`` depends on ``fa`` directly: the cross term ``N``).
    """
    w = dict(DEFAULT_LQR_WEIGHTS if weights is None else weights)
    A, B, j = _actuated(car)
    sys = car.system
    wf = nonnegative("weights['fa']", w.pop("fa", 0.0), "1/N²")
    rows, ws = [], []
    for label, value in w.items():
        k = car.output(label)
        rows.append(k)
        ws.append(nonnegative(f"weights[{label!r}]", value))
    C = np.asarray(sys.C, dtype=float)[rows]
    D = np.asarray(sys.D, dtype=float)[rows][:, [j]]
    W = np.diag(ws)
    R = D.T @ W @ D + wf
    if R[0, 0] <= 0:
        raise ValueError(
            "the LQR cost must weigh the force: give weights['fa'] > 0 or weigh body_acc"
        )
    return C.T @ W @ C, R, C.T @ W @ D


#: Default sensor noise intensities of the LQR's Kalman filter: displacements
#: [m²·s] and the accelerometer [(m/s²)²·s].
ESTIMATOR_NOISE = {"body_acc": 1e-3}
_DISPLACEMENT_NOISE = 1e-7
#: Default road-velocity intensity of the Kalman filter [m²/s]: about an ISO
#: 8608 class C road at 20 m/s (2π²·n0²·Gd(n0)·v = 1.0e-3).
ROAD_VELOCITY_INTENSITY = 1e-3


def _default_rn(measured: Sequence[str]) -> list[float]:
    return [ESTIMATOR_NOISE.get(label, _DISPLACEMENT_NOISE) for label in measured]


def relative_coordinates(car: VehicleModel):
    """The car in the coordinates ``z = [vs, vu, susp_travel, tire_defl]``.

    ``z = T x + t_r zr`` (``tire_defl = xu - zr``). In these coordinates the
    road enters only through its velocity: ``z' = A_z z + b_z fa + t_r zr'``
    with ``A_z = T A T⁻¹``, ``b_z = T b`` (the road height's own term
    vanishes, checked here). Returns ``(labels, T, t_r, A_z, b_z)``.
    """
    A, B, j = _actuated(car)
    sys = car.system
    corner = car.corners[0]
    if corner.road is None:
        raise ValueError(f"car {car.name!r} has no road input; build it with road=True")
    r = sys.input_labels.index(corner.road)
    states = list(sys.state_labels)
    labels = [s for s in _VELOCITIES if s in states] + [corner.susp_travel, corner.tire_defl]
    rows, t_r = [], []
    for label in labels:
        if label in states:
            rows.append(np.eye(len(states))[states.index(label)])
            t_r.append(0.0)
        else:
            k = car.output(label)
            rows.append(np.asarray(sys.C, float)[k])
            t_r.append(float(np.asarray(sys.D, float)[k, r]))
    T = np.array(rows)
    if T.shape != A.shape or np.linalg.cond(T) > 1e12:
        raise ValueError(f"car {car.name!r}: {labels} are not coordinates of its states {states}")
    Ti = np.linalg.inv(T)
    Az = T @ A @ Ti
    tr = np.array(t_r)[:, None]
    residual = T @ B[:, [r]] - Az @ tr
    if np.abs(residual).max() > 1e-9 * (np.abs(T @ B[:, [r]]).max() + 1.0):
        raise ValueError(f"car {car.name!r}: the road height does not drop out of {labels}")
    return labels, T, tr, Az, T @ B[:, [j]]


def _check_covariances(QN: np.ndarray, RN: np.ndarray) -> None:
    """Noise intensities: QN positive semi-definite, RN positive definite
    (a Kalman filter's assumptions; ``control.lqe`` accepts others and
    returns a filter with unstable poles)."""
    if not np.all(np.isfinite(QN)) or np.min(np.linalg.eigvalsh((QN + QN.T) / 2)) < 0:
        raise ParameterError(
            "estimator['QN']",
            QN.tolist(),
            "positive semi-definite",
            description="process noise intensity",
        )
    if not np.all(np.isfinite(RN)) or np.min(np.diag(RN)) <= 0:
        raise ParameterError(
            "estimator['RN']",
            np.diag(RN).tolist(),
            "finite and > 0",
            description="sensor noise intensities",
        )


def lqr_controller(
    car: VehicleModel,
    weights: Mapping[str, float] | None = None,
    *,
    estimator: Mapping[str, Any] | None = None,
    name: str = "lqr",
) -> control.StateSpace:
    r"""Linear-quadratic regulator on the actuator force, by ``control.lqr``.

    Minimises the cost of `lqr_weights` (a weight per car output, e.g.
    ``body_acc``, ``susp_travel``, ``tire_defl``, and ``'fa'`` on the force)
    with ``K, S, E = control.lqr(A, B_fa, Q, R, N)`` (Anderson & Moore,
    *Optimal Control: Linear Quadratic Methods*, 1990, §2.4 and §3.4 for the
    cross term). The law is full-state feedback written in the coordinates
    of `relative_coordinates`, ``fa = -K_z [vs, vu, susp_travel,
    tire_defl]`` with ``K_z = K T⁻¹``: the same law as ``-K x`` on a flat
    road, but measured against the road, so that the car follows a road
    that rises instead of holding its body at an absolute height (the
    classic full-state active suspension, Hrovat, "Survey of advanced
    suspension developments and related optimal control applications",
    Automatica 33(10), 1997).

    With ``estimator``, the state comes from a Kalman filter
    (``control.lqe``) on measured outputs, the road velocity being the
    process noise: ``{'outputs': ['susp_travel', 'body_acc'], 'QN':
    road-velocity intensity [m²/s] (default `ROAD_VELOCITY_INTENSITY`),
    'RN': sensor noise intensities}`` (default 1e-7 m²·s on a displacement,
    1e-3 (m/s²)²·s on ``body_acc``). The controller is the observer-based
    compensator in ``z``:

    .. math:: \dot{\hat z} = (A_z - b_z K_z - L(C_z - D K_z))\hat z + L y,
              \qquad f_a = -K_z\hat z

    Parameters
    ----------
    car : VehicleModel
        A linear car with the inputs ``'zr'`` and ``'fa'``.
    weights : mapping, optional
        Output label (or ``'fa'``) -> weight >= 0; default
        `DEFAULT_LQR_WEIGHTS`.
    estimator : mapping, optional
    name : str

    Returns
    -------
    control.StateSpace
        Full state: a static gain ``-K_z`` with inputs ``['vs', 'vu',
        'susp_travel', 'tire_defl']``. With an estimator: inputs the
        measured outputs, states ``zhat_<label>``. Output ``['fa']``.
    """
    A, B, j = _actuated(car)
    Q, R, N = lqr_weights(car, weights)
    b = B[:, [j]]
    K, _, _ = control.lqr(A, b, Q, R, N)
    labels, T, tr, Az, bz = relative_coordinates(car)
    Kz = np.asarray(K, dtype=float) @ np.linalg.inv(T)
    if estimator is None:
        return control.ss(
            np.zeros((0, 0)),
            np.zeros((0, len(labels))),
            np.zeros((1, 0)),
            -Kz,
            inputs=labels,
            outputs=["fa"],
            name=name,
        )
    est = dict(estimator)
    measured = list(est.pop("outputs", ["susp_travel", "body_acc"]))
    QN = np.atleast_2d(est.pop("QN", ROAD_VELOCITY_INTENSITY))
    if not measured:
        raise ValueError(
            "estimator outputs must name at least one measured output of the car, got []"
        )
    RN = np.diag(np.atleast_1d(np.asarray(est.pop("RN", _default_rn(measured)), float)))
    _check_covariances(QN, RN)
    if est:
        raise ValueError(f"unknown estimator option(s) {sorted(est)}; expected outputs, QN, RN")
    rows = [car.output(label) for label in measured]
    Ti = np.linalg.inv(T)
    Cz = np.asarray(car.system.C, dtype=float)[rows] @ Ti
    D = np.asarray(car.system.D, dtype=float)[rows][:, [j]]
    L, _, _ = control.lqe(Az, tr, Cz, QN, RN)
    L = np.asarray(L, dtype=float)
    Ak = Az - bz @ Kz - L @ (Cz - D @ Kz)
    return control.ss(
        Ak,
        L,
        -Kz,
        np.zeros((1, len(measured))),
        inputs=measured,
        states=[f"zhat_{s}" for s in labels],
        outputs=["fa"],
        name=name,
    )


# ---------------------------------------------------------------- H-infinity


#: `HinfWeights`' number fields, declared once (MATLAB's example's meaning and unit).
_HINF_SPEC = {
    "road": Field("road disturbance weight W_road: zr = W_road d1", "m"),
    "travel_noise": Field("travel sensor noise weight", "m"),
    "acc_noise": Field("accelerometer noise weight", "m/s²"),
    "actuator_bandwidth": Field("nominal actuator bandwidth: 1/(s/ω + 1)", "rad/s"),
    "force_unit": Field("newtons per unit of the command u", "N"),
}
#: `HinfWeights`' weighting filters, each a ``(num, den)`` pair, and what each weighs.
_HINF_FILTERS = {
    "actuator": "actuator effort weight W_act",
    "handling": "handling target: e3 = beta/Handling · susp_travel",
    "comfort": "comfort target: e2 = (1 - beta)/Comfort · body_acc",
}


@dataclass(frozen=True)
class HinfWeights:
    """The weights of MATLAB's "Robust Control of an Active Suspension" example.

    All transfer functions in rad/s; the controller's output ``u`` is in
    ``force_unit`` newtons (kN in the example).

    Raises
    ------
    qc_control.ParameterError
        A number out of its declared range (``HinfWeights.spec()``: each
        > 0) or a filter that is not ``(num, den)`` of finite coefficients,
        naming the field and the value.
    """

    road: float = 0.07
    actuator: tuple = ((0.8, 40.0), (1.0, 500.0))  # 0.8 (s + 50)/(s + 500)
    travel_noise: float = 0.01
    acc_noise: float = 0.5
    handling: tuple = ((0.04 / 8, 0.04), (1 / 80, 1.0))  # 0.04 (s/8 + 1)/(s/80 + 1)
    comfort: tuple = ((0.4 / 0.45, 0.4), (1 / 150, 1.0))  # 0.4 (s/0.45 + 1)/(s/150 + 1)
    actuator_bandwidth: float = 60.0  # ActNom = 1/(s/60 + 1)
    force_unit: float = 1e3

    def __post_init__(self):
        check_fields(self, _HINF_SPEC)
        for name in _HINF_FILTERS:
            self._check_filter(name)

    @classmethod
    def spec(cls) -> dict[str, Field]:
        """The number fields, declared: ``{name: Field}`` (description, SI unit,
        range); the filters ``actuator``, ``handling`` and ``comfort`` are
        ``(numerator, denominator)`` coefficient pairs, checked as such."""
        return dict(_HINF_SPEC)

    def _check_filter(self, name: str) -> None:
        """A weighting filter: ``(num, den)`` of finite real coefficients, den not all 0."""
        spec = getattr(self, name)
        try:
            num, den = (np.asarray(part, dtype=float) for part in spec)
            ok = num.ndim == den.ndim == 1 and bool(np.all(np.isfinite(num)))
            ok = ok and bool(np.all(np.isfinite(den))) and bool(np.any(den != 0))
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise ParameterError(
                name,
                spec,
                "(numerator, denominator) coefficients of a transfer function in s [rad/s], "
                "finite, the denominator not all 0",
                description=_HINF_FILTERS[name],
            )


#: MATLAB's weights, as published in the example.
MATLAB_ACTIVE_SUSPENSION = HinfWeights()


@dataclass(frozen=True, eq=False)
class HinfDesign:
    """An H∞ active-suspension design whose γ has been verified.

    Attributes
    ----------
    controller : control.StateSpace
        Inputs ``['susp_travel', 'body_acc']``, output ``['fa']`` [N]: the
        synthesised ``K`` followed by the nominal actuator and the unit
        (what `closed_loop` connects to the car).
    K : control.StateSpace
        The synthesised controller, measurements to ``u`` [force_unit].
    plant : control.StateSpace
        The weighted generalised plant, inputs ``[d1, d2, d3, u]``, outputs
        ``[e1, e2, e3, y1, y2]``.
    gamma : float
        The smallest γ (to ``rtol``) at which ``sb10ad`` returned a
        controller whose closed loop is stable with ``‖T_zw‖∞ <= γ``.
    norm : float
        ``‖T_zw‖∞`` of that closed loop, by ``control.norm(cl, 'inf')``.
    beta : float
    """

    controller: control.StateSpace
    K: control.StateSpace
    plant: control.StateSpace
    gamma: float
    norm: float
    beta: float


#: What `hinf_plant`'s ``beta`` and `hinf_controller`'s ``rtol`` are, for their refusals.
_BETA = "weight on travel against comfort"
_RTOL = "relative width of the γ bracket"


def _tf(spec) -> control.TransferFunction:
    num, den = spec
    return control.tf(list(num), list(den))


def hinf_plant(car: VehicleModel, beta: float = 0.5, weights: HinfWeights | None = None):
    """The weighted generalised plant of MATLAB's active-suspension example.

    Inputs ``d1`` (road, ``zr = W_road d1``), ``d2``, ``d3`` (sensor noise
    on travel and acceleration) and ``u`` (actuator command, in
    ``force_unit``); outputs ``e1 = W_act u``, ``e2 = (1-β)/Comfort · ab``,
    ``e3 = β/Handling · sd`` and the measurements ``y1 = sd + 0.01 d2``,
    ``y2 = ab + 0.5 d3``; the actuator is ``fa = force_unit/(s/60 + 1)·u``.
    ``β`` trades road handling (travel, β → 1) against comfort (β → 0).
    """
    w = MATLAB_ACTIVE_SUSPENSION if weights is None else weights
    beta = number("beta", beta, low=0.0, high=1.0, low_open=True, high_open=True, description=_BETA)
    _actuated(car)
    sys = car.system
    road = car.corners[0].road
    if road is None:
        raise ValueError(f"car {car.name!r} has no road input; build it with road=True")
    plant = control.ss(sys, name="car")
    act = control.tf(
        [w.force_unit], [1 / w.actuator_bandwidth, 1.0], inputs="u", outputs="fa", name="act"
    )
    blocks = [
        plant,
        act,
        control.ss([], [], [], w.road, inputs="d1", outputs=road, name="Wroad"),
        control.tf(_tf(w.actuator), inputs="u", outputs="e1", name="Wact"),
        control.tf((1 - beta) / _tf(w.comfort), inputs="body_acc", outputs="e2", name="Wab"),
        control.tf(beta / _tf(w.handling), inputs="susp_travel", outputs="e3", name="Wsd"),
        control.ss([], [], [], w.travel_noise, inputs="d2", outputs="n2", name="Wd2"),
        control.ss([], [], [], w.acc_noise, inputs="d3", outputs="n3", name="Wd3"),
        control.summing_junction(["susp_travel", "n2"], "y1", name="sdmeas"),
        control.summing_junction(["body_acc", "n3"], "y2", name="abmeas"),
    ]
    io = dict(inplist=["d1", "d2", "d3", "u"], outlist=["e1", "e2", "e3", "y1", "y2"])
    P = control.interconnect(
        blocks, **io, inputs=io["inplist"], outputs=io["outlist"], check_unused=False
    )
    return control.ss(P, name="hinf_plant")


def _hinf_attempt(P: control.StateSpace, gamma: float, ncon: int, nmeas: int):
    """``(K, CL, ‖CL‖∞)`` from ``sb10ad`` (job=4) at ``gamma``, or None if not met."""
    n, m, p = P.nstates, P.ninputs, P.noutputs
    try:
        out = slycot.sb10ad(n, m, p, ncon, nmeas, gamma, P.A, P.B, P.C, P.D, job=4)
    except (ValueError, ArithmeticError):  # slycot's errors for "no controller at gamma"
        return None
    K = control.ss(*out[1:5])
    CL = control.ss(*out[5:9])
    if CL.nstates and np.max(CL.poles().real) >= 0:
        return None
    norm = float(control.norm(CL, "inf"))
    return (K, CL, norm) if norm <= gamma * (1 + 1e-6) else None


def hinf_controller(
    car: VehicleModel,
    beta: float = 0.5,
    *,
    weights: HinfWeights | None = None,
    gamma_max: float = 100.0,
    rtol: float = 1e-3,
    name: str = "hinf",
) -> HinfDesign:
    """H∞ output-feedback controller on travel and body acceleration.

    The design of MATLAB's *Robust Control of an Active Suspension*
    (Robust Control Toolbox example; the plant is `hinf_plant` with
    `MATLAB_ACTIVE_SUSPENSION`'s weights): measurements ``susp_travel`` and
    ``body_acc``, one command ``u`` through the nominal actuator.

    python-control's ``control.hinfsyn`` starts ``sb10ad`` from γ = 1e100
    with its default search, and on this plant it can report a γ that the
    controller it returns does not meet. So γ is found here by bisection:
    at each trial γ, ``sb10ad`` (``job=4``: a suboptimal controller at that
    γ) is asked for a controller, which is accepted only if the closed loop
    is stable and its H∞ norm, computed independently with
    ``control.norm(cl, 'inf')``, is at most γ. The bisection stops when the
    bracket is narrower than ``rtol``; the design returned is the accepted
    one, and ``norm`` is its verified closed-loop norm (``norm <= gamma``).

    Parameters
    ----------
    car : VehicleModel
        A linear car with inputs ``'zr'`` and ``'fa'``.
    beta : float, default 0.5
        In (0, 1): the weight on travel (road handling) against comfort.
        MATLAB's example designs at 0.01, 0.5 and 0.99.
    weights : HinfWeights, optional
    gamma_max : float
        The upper end of the search; a ValueError if no controller meets it.
    rtol : float
        Relative width of the final γ bracket.
    name : str

    Returns
    -------
    HinfDesign

    Raises
    ------
    ImportError
        Without slycot (``pip install "qc-control[robust]"``).
    """
    w = MATLAB_ACTIVE_SUSPENSION if weights is None else weights
    P = hinf_plant(car, beta, w)
    gamma_max = positive("gamma_max", gamma_max)
    rtol = number("rtol", rtol, low=0.0, high=1.0, low_open=True, high_open=True, description=_RTOL)
    if slycot is None:
        raise ImportError(f"hinf_controller needs slycot: {install_hint('robust')}")
    best = _hinf_attempt(P, gamma_max, 1, 2)
    if best is None:
        raise ValueError(
            f"no stabilising H∞ controller meets gamma_max={gamma_max!r} for car {car.name!r}"
        )
    lo, hi = gamma_max * 1e-6, gamma_max
    while hi > lo * (1 + rtol):
        trial = math.sqrt(lo * hi)
        found = _hinf_attempt(P, trial, 1, 2)
        if found is None:
            lo = trial
        else:
            hi, best = trial, found
    K, _, norm = best
    K = control.ss(K.A, K.B, K.C, K.D, inputs=["susp_travel", "body_acc"], outputs=["u"])
    # the actuator as a StateSpace: series with a TransferFunction would go
    # through a transfer-function realisation, non-minimal and with hidden modes
    act = control.ss(control.tf([w.force_unit], [1 / w.actuator_bandwidth, 1.0]))
    controller = control.series(K, act)
    controller = control.ss(
        controller.A,
        controller.B,
        controller.C,
        controller.D,
        inputs=["susp_travel", "body_acc"],
        outputs=["fa"],
        states=[f"k{i}" for i in range(controller.nstates)],
        name=name,
    )
    return HinfDesign(controller, K, P, float(hi), norm, float(beta))


# ---------------------------------------------------------------- the closed loop


def _measured_plant(car: VehicleModel, measured: Sequence[str]) -> control.StateSpace:
    """The car with the states the controller measures added as outputs."""
    sys = car.system
    outputs, states = list(sys.output_labels), list(sys.state_labels)
    extra = []
    for label in measured:
        if label in outputs or label in extra:
            continue
        if label not in states:
            raise ValueError(
                f"the controller measures {label!r}, which car {car.name!r} has neither "
                f"as an output {outputs} nor as a state {states}"
            )
        extra.append(label)
    A, B = np.asarray(sys.A, float), np.asarray(sys.B, float)
    S = np.eye(len(states))[[states.index(label) for label in extra]]
    C = np.vstack([np.asarray(sys.C, float), S])
    D = np.vstack([np.asarray(sys.D, float), np.zeros((len(extra), B.shape[1]))])
    return control.ss(
        A,
        B,
        C,
        D,
        inputs=list(sys.input_labels),
        outputs=outputs + extra,
        states=states,
        name="car",
    )


def closed_loop(
    car: VehicleModel, controller, *, name: str | None = None, delay: int = 0
) -> VehicleModel:
    """The car with a controller driving its actuator force ``fa``.

    ``control.interconnect`` joins the car (its outputs and, where the
    controller measures them, its states ``vs``/``vu``) and the controller
    (inputs named after what it measures, output ``fa``) by signal name.

    Parameters
    ----------
    car : VehicleModel
        A linear car with the input ``'fa'`` (e.g.
        ``quarter_car_model(params, road=True, actuator=True)``).
    controller : control.StateSpace or control.NonlinearIOSystem
        From this module, or any system with output ``'fa'`` whose inputs
        are outputs or states of the car.
    name : str, optional
        Default ``'<car> + <controller>'``.
    delay : int, default 0
        For a discrete controller: whole samples of computation delay (the
        move computed at tick ``k`` is applied from tick ``k + delay``; the
        moves before the first are 0). A continuous controller has none.

    Returns
    -------
    VehicleModel
        Inputs: the car's other inputs (``zr``); states: the car's (same
        labels and order, so the car's initial states apply) then the
        controller's; outputs: the car's, then ``fa`` [N]. Its ``system``
        is a ``control.StateSpace`` for a linear controller (every tool
        takes it: responses, `compare_methods`, `transmissibility` of its
        ``zr`` input, sweeps) and a `control.NonlinearIOSystem` for a
        semi-active one (through `qc_control.input_output_response`). Roles,
        units and parameters are the car's; ``rebuild(params)`` closes the
        same controller around the rebuilt car.

        A **discrete** controller (``dt > 0``: a ``control.StateSpace`` or
        ``control.NonlinearIOSystem``, or `qc_control.mpc_controller`) runs
        on a clock beside the continuous car
        (`qc_control.models.sampled_loop`): its move is held between ticks
        (zero-order hold) and the loop's ``system`` is a
        `qc_control.numerics.clocked.ClockedLoop` whose states end with the
        held move ``fa_held`` (and the queued ones ``fa_queued<i>``); the
        responses step it with steps landing on every tick, and the
        controller's period must be a whole multiple of the car's step.
    """
    if not isinstance(car, VehicleModel):
        raise TypeError(f"car must be a VehicleModel, got {type(car).__name__}")
    if not isinstance(controller, control.NonlinearIOSystem):
        raise TypeError(
            f"controller must be a control system with output 'fa', got {type(controller).__name__}"
        )
    _actuated(car)
    if list(controller.output_labels) != ["fa"]:
        raise ValueError(
            f"controller {controller.name!r} must have the one output 'fa', "
            f"has {list(controller.output_labels)}"
        )
    if controller.name == "car":  # the interconnection's own name for the car's block
        raise ValueError(
            "controller name 'car' is the car's block in the closed loop; name the "
            "controller otherwise (e.g. controller.copy(name='my_law') or name= when built)"
        )
    measured = list(controller.input_labels)
    plant = _measured_plant(car, measured)
    rebuild = functools.partial(_rebuild, car.rebuild, controller, name, delay=delay)
    if control.isdtime(controller, strict=True):
        return sampled_loop(car, controller, plant, delay, name, rebuild)
    if delay != 0:
        raise ValueError(
            f"delay={delay!r} needs a discrete controller (dt > 0); controller "
            f"{controller.name!r} is continuous"
        )
    inputs = [label for label in car.system.input_labels if label != "fa"]
    outputs = [*car.system.output_labels, "fa"]
    ctrl_states = [f"{controller.name}_{s}" for s in controller.state_labels]
    states = [*car.system.state_labels, *ctrl_states]
    system = control.interconnect(
        [plant, controller],
        inplist=inputs,
        outlist=outputs,
        inputs=inputs,
        outputs=outputs,
        states=states,
        name=name or f"{car.name} + {controller.name}",
        check_unused=False,
    )
    if isinstance(system, control.StateSpace):
        system = control.ss(system)  # a plain StateSpace (not LinearICSystem) for every tool
    units = dict(car.units)
    units["fa"] = "N"
    if isinstance(controller, control.StateSpace):
        # an estimator's states are the car's own quantities; others have no unit
        for s, label in zip(controller.state_labels, ctrl_states):
            units[label] = car.unit(s[5:]) if s.startswith("zhat_") else "-"
    else:
        for s, label in zip(controller.state_labels, ctrl_states):
            units[label] = "m/s" if s == "acc_filter" else "-"
    return VehicleModel(
        system,  # a StateSpace, or a NonlinearIOSystem for semi-active laws
        car.params,
        units,
        car.roles,
        rebuild,
    )


def _rebuild(car_rebuild, controller, name, params, delay=0) -> VehicleModel:
    return closed_loop(car_rebuild(params), controller, name=name, delay=delay)
