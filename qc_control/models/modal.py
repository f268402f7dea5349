"""Modal analysis of any vehicle: frequencies, damping, and modes named by shape.

The quarter car's two modes are body bounce and wheel hop. A half or full car
(`qc_control.models.halfcar`) has body modes (bounce, pitch, roll) and wheel modes
(per axle: wheel hop, and on a full car axle tramp, the wheels against each
other), named from their eigenvectors by `vehicle_modes`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np
import pandas as pd
import scipy.optimize

from ..numerics import stability
from .halfcar import FULL_CAR_CORNERS, HALF_CAR_CORNERS, FullCarParams, HalfCarParams
from .quarter import MOUNT_STATE, QuarterCarParams, quarter_car
from .vehicle import VehicleModel

__all__ = [
    "Mode",
    "ModalAnalysis",
    "modal_analysis",
    "vehicle_modes",
    "quarter_car_matrices",
    "numerical_modes",
]

BODY, WHEEL = "body bounce", "wheel hop"
#: The real mode a damper top mount adds (`qc_control.models.quarter.mounted_abcd`).
MOUNT = "top mount"


@dataclass(frozen=True)
class Mode:
    """One vibration mode (a conjugate pair, or two real eigenvalues).

    Attributes
    ----------
    name : str
        From the mode shape: ``'body bounce'`` or ``'wheel hop'`` on a
        quarter car; ``'bounce'``, ``'pitch'``, ``'roll'``, ``'front wheel
        hop'``, ``'rear axle tramp'``... on other vehicles (`vehicle_modes`).
    eigenvalue : complex
        The eigenvalue with Im >= 0 (for an overdamped mode, the slower one).
    wn : float
        Natural frequency |λ| [rad/s]; for an overdamped pair √(λ₁λ₂).
    zeta : float
        Modal damping ratio -Re(λ)/|λ| [-]; for an overdamped pair
        -(λ₁+λ₂)/(2√(λ₁λ₂)) >= 1.
    fd : float
        Damped frequency Im(λ)/2π [Hz] (0 when overdamped).
    fn_undamped : float
        Undamped natural frequency [Hz] from K·φ = ω²·M·φ.
    shape_ratio, shape_phase : float
        |xu/xs| and its phase [deg] in the eigenvector; on other vehicles the
        same ratio over all corners, wheel motion against the body's motion
        above the wheels, ``Σ u_i conj(b_i) / Σ |b_i|²`` (its modulus and phase).
    zeta_nominal : float
        The nominal cs/(2√(ks·ms)), the same for both modes (quarter car;
        NaN otherwise).
    shape : tuple of (label, complex)
        The displacement part of the eigenvector by state label, scaled so
        that its largest entry is 1 (empty for the quarter car's table).
    node_x : float
        Where along the body (ahead of the CG [m]) its heave and pitch
        motions cancel, ``-Re(z/theta)``, for the bounce and pitch modes of a
        vehicle with a pitch state (``inf`` when it does not pitch); NaN
        otherwise.
    """

    name: str
    eigenvalue: complex
    wn: float
    zeta: float
    fd: float
    fn_undamped: float
    shape_ratio: float
    shape_phase: float
    zeta_nominal: float
    shape: tuple = ()
    node_x: float = math.nan

    @property
    def fn(self) -> float:
        """Natural frequency wn/2π [Hz]."""
        return self.wn / (2.0 * math.pi)


_COLUMNS = {
    "eigenvalue": "eigenvalue [1/s]",
    "wn": "wn [rad/s]",
    "fn": "fn [Hz]",
    "zeta": "zeta [-]",
    "zeta_nominal": "zeta nominal [-]",
    "fd": "fd [Hz]",
    "fn_undamped": "fn undamped [Hz]",
    "shape_ratio": "|xu/xs| [-]",
    "shape_phase": "phase(xu/xs) [deg]",
}


_VEHICLE_COLUMNS = {
    "eigenvalue": "eigenvalue [1/s]",
    "wn": "wn [rad/s]",
    "fn": "fn [Hz]",
    "zeta": "zeta [-]",
    "fd": "fd [Hz]",
    "fn_undamped": "fn undamped [Hz]",
    "shape_ratio": "|wheel/body| [-]",
    "shape_phase": "phase(wheel/body) [deg]",
    "node_x": "node x [m]",
}


@dataclass(frozen=True)
class ModalAnalysis:
    """The modes of a vehicle: body modes first (a quarter car: body bounce first).

    ``str()`` gives the table and the note; `to_frame` gives a DataFrame.
    """

    modes: tuple[Mode, ...]
    note: str
    columns: tuple[tuple[str, str], ...] = tuple(_COLUMNS.items())

    def __getitem__(self, name: str) -> Mode:
        for mode in self.modes:
            if mode.name == name:
                return mode
        raise KeyError(f"no mode {name!r}; modes are {[m.name for m in self.modes]}")

    @property
    def body(self) -> Mode:
        return self[BODY]

    @property
    def wheel(self) -> Mode:
        return self[WHEEL]

    def to_frame(self) -> pd.DataFrame:
        """One row per mode, indexed by name, columns with units."""
        rows = {
            m.name: {label: getattr(m, attr) for attr, label in self.columns} for m in self.modes
        }
        frame = pd.DataFrame.from_dict(rows, orient="index")
        frame.index.name = "mode"
        return frame

    def __str__(self) -> str:
        frame = self.to_frame()
        frame[_COLUMNS["eigenvalue"]] = [f"{m.eigenvalue:.4f}" for m in self.modes]
        text = frame.to_string(float_format=lambda v: f"{v:.4g}")
        return f"{text}\n{self.note}" if self.note else text


def quarter_car_matrices(sys: control.StateSpace) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``M⁻¹C``, ``M⁻¹K`` and ``A`` of a system in quarter-car state form.

    The state must be ``[vs, vu, xs, xu]`` so that
    ``A = [[-M⁻¹C, -M⁻¹K], [I, 0]]``.

    Raises
    ------
    ValueError
        If the system is not continuous-time with 4 states of that form.
    """
    if not isinstance(sys, control.StateSpace):
        raise TypeError(
            f"expected QuarterCarParams or control.StateSpace, got {type(sys).__name__}"
        )
    if not control.isctime(sys, strict=True):
        raise ValueError(f"system {sys.name!r} must be continuous-time, got dt={sys.dt!r}")
    A = np.asarray(sys.A, dtype=float)
    if A.shape != (4, 4) or not np.array_equal(A[2:], np.hstack([np.eye(2), np.zeros((2, 2))])):
        raise ValueError(
            f"system {sys.name!r} is not in quarter-car form: states must be "
            "[vs, vu, xs, xu] with A[2:] = [[1,0,0,0],[0,1,0,0]]"
        )
    return -A[:2, :2], -A[:2, 2:], A


def _in_phase(ratio: complex) -> float:
    """Re(xu/xs): how far the wheel moves with the body (-inf when xs = 0)."""
    return float(np.real(ratio)) if np.isfinite(ratio) else -math.inf


def _classify(ratios: list[complex]) -> list[str]:
    """Body bounce is the mode in which the wheel moves most in phase with the body.

    In the two-mass chain the undamped shapes have ``xu/xs`` of opposite
    signs: bounce in phase, hop against the body. That holds for damped and
    overdamped modes too, where |xu/xs| alone does not: with a stiff damper
    the body and the wheel bounce together on the tire (|xu/xs| ≈ 1) while
    the overdamped relative motion has a slow part with |xu/xs| ≈ 0.
    """
    body = int(np.argmax([_in_phase(r) for r in ratios]))
    return [BODY if i == body else WHEEL for i in range(len(ratios))]


def modal_analysis(sys_or_params=None) -> ModalAnalysis:
    """Natural frequencies, damping ratios and mode shapes of a quarter car.

    Parameters
    ----------
    sys_or_params : vehicle parameters, dict, VehicleModel, control.StateSpace or None
        `QuarterCarParams` (or a dict of its fields), `HalfCarParams`,
        `FullCarParams`, a model or a system.
        The vehicle; a 4-state system must have the states ``[vs, vu, xs,
        xu]`` (as `quarter_car` builds it), a larger one the labels of a
        half or full car (see `vehicle_modes`). ``None`` is the seed's
        quarter car.

    Returns
    -------
    ModalAnalysis
        A quarter car: two `Mode` rows, body bounce first, and a one-line
        note when the body mode's damping departs from the nominal ratio.
        Another vehicle: one row per mode, named by `vehicle_modes`.

    Notes
    -----
    For each eigenvalue λ of ``A`` (python-control's `damp` convention):

    .. math:: \\omega_n = |\\lambda|, \\quad \\zeta = -\\mathrm{Re}\\,\\lambda/|\\lambda|,
              \\quad f_d = \\mathrm{Im}\\,\\lambda / 2\\pi

    The undamped frequencies solve :math:`K\\varphi = \\omega^2 M\\varphi`,
    i.e. they are the square roots of the eigenvalues of :math:`M^{-1}K`.
    A mode is named from its eigenvector's displacements ``(xs, xu)``: of
    the two, the mode in which the wheel moves most in phase with the body
    (the larger :math:`\\mathrm{Re}(x_u/x_s)`) is body bounce, and the
    other, the wheel moving against the body, is wheel hop. This holds for
    overdamped modes too.
    The nominal ratio :math:`c_s/(2\\sqrt{k_s m_s})` is the body's damping
    on a rigid tire (:math:`k_u \\to \\infty`); a soft tire lowers it.

    Examples
    --------
    >>> ma = modal_analysis()
    >>> round(ma.body.fn, 3), round(ma.body.zeta, 4)
    (1.087, 0.0677)
    """
    if isinstance(sys_or_params, (HalfCarParams, FullCarParams)):
        return vehicle_modes(sys_or_params.model())
    if isinstance(sys_or_params, VehicleModel):
        if not isinstance(sys_or_params.params, QuarterCarParams):
            return vehicle_modes(sys_or_params)
        sys_or_params = sys_or_params.system
    if _is_mounted(sys_or_params):
        return _mounted_modes(sys_or_params)
    if isinstance(sys_or_params, control.StateSpace) and sys_or_params.nstates != 4:
        return vehicle_modes(sys_or_params)
    if sys_or_params is None or isinstance(sys_or_params, (QuarterCarParams, dict)):
        sys_or_params = quarter_car(sys_or_params)
    MinvC, MinvK, A = quarter_car_matrices(sys_or_params)
    # -A[0,0] = cs/ms and -A[0,2] = ks/ms, so cs/(2 sqrt(ks ms)) needs no params.
    zeta_nominal = MinvC[0, 0] / (2.0 * math.sqrt(MinvK[0, 0])) if MinvK[0, 0] > 0 else math.nan

    eigvals, eigvecs = np.linalg.eig(A)
    # a damping ratio below MARGINAL_RTOL is rounding: reported as 0, never < 0
    eigvals = stability.settle_marginal(eigvals)
    groups = _pair_eigenvalues(eigvals, eigvecs)
    names = _classify([_shape(v) for _, v in groups])

    fn_undamped = _undamped_frequencies(MinvK)

    modes = [
        _mode(name, lams, _shape(v), fn_undamped[name], zeta_nominal=float(zeta_nominal))
        for name, (lams, v) in zip(names, groups)
    ]
    modes.sort(key=lambda m: m.name != BODY)
    return ModalAnalysis((modes[0], modes[1]), _damping_note(modes[0], MinvK))


def _undamped_frequencies(MinvK: np.ndarray) -> dict[str, float]:
    """The quarter car's undamped frequencies [Hz] by mode name, from ``K φ = ω² M φ``."""
    w2, phi = np.linalg.eig(MinvK)
    order = np.argsort(np.abs(w2))
    w2, phi = w2[order].real, phi[:, order].real
    undamped_names = _classify(
        [phi[1, i] / phi[0, i] if phi[0, i] else complex(math.inf) for i in range(2)]
    )
    fn_undamped = {n: math.sqrt(max(w, 0.0)) / (2 * math.pi) for n, w in zip(undamped_names, w2)}
    return fn_undamped


def _is_mounted(sys) -> bool:
    """Whether ``sys`` is a quarter car with a damper top mount (states ``[..., xd]``)."""
    return (
        isinstance(sys, control.StateSpace)
        and sys.nstates == 5
        and list(sys.state_labels) == ["vs", "vu", "xs", "xu", MOUNT_STATE]
    )


def _mounted_modes(sys: control.StateSpace) -> ModalAnalysis:
    """Body bounce, wheel hop and the mount's real mode of a car with a top mount.

    The mount adds one real eigenvalue, the spring relaxing through the
    damper (near ``-km/cs``): the fastest real one. The other four are
    paired and named as the seed's car's (`_pair_eigenvalues`, on their
    ``[vs, vu, xs, xu]`` parts). Undamped, the damper carries no force, so
    the mount carries none either: the undamped frequencies are the seed's,
    from ``M⁻¹K`` with the mount's terms taken out of ``A``.
    """
    if not control.isctime(sys, strict=True):
        raise ValueError(f"system {sys.name!r} must be continuous-time, got dt={sys.dt!r}")
    A = np.asarray(sys.A, dtype=float)
    eigvals, eigvecs = np.linalg.eig(A)
    eigvals = stability.settle_marginal(eigvals)
    real = [i for i in range(5) if eigvals[i].imag == 0]
    mount = min(real, key=lambda i: eigvals[i].real)
    rest = [i for i in range(5) if i != mount]
    groups = _pair_eigenvalues(eigvals[rest], eigvecs[:4][:, rest])
    names = _classify([_shape(v) for _, v in groups])
    # A[:2, 2:4] holds -M⁻¹(K + km e₁e₁ᵀ) and A[:2, 4] = M⁻¹ km e₁: add it back on xs
    MinvK = -(A[:2, 2:4] + np.outer(A[:2, 4], [1.0, 0.0]))
    fn_undamped = _undamped_frequencies(MinvK)
    # cs/ms = A[0, 4] / A[4, 2] (km/ms over km/cs), so the nominal ratio needs no params
    zeta_nominal = A[0, 4] / A[4, 2] / (2.0 * math.sqrt(MinvK[0, 0]))
    modes = [
        _mode(name, lams, _shape(v), fn_undamped[name], zeta_nominal=float(zeta_nominal))
        for name, (lams, v) in zip(names, groups)
    ]
    modes.sort(key=lambda m: m.name != BODY)
    lam = eigvals[mount]
    modes.append(_mode(MOUNT, (lam,), _shape(eigvecs[:, mount]), math.nan))
    note = (
        f"The damper's top mount adds a real mode at {lam.real:.4g} 1/s (time constant "
        f"{-1e3 / lam.real:.3g} ms): it sets the step limit of explicit methods."
    )
    return ModalAnalysis(tuple(modes), note)


def _mode(name: str, lams, ratio: complex, fn_undamped: float, **extra) -> Mode:
    """The `Mode` of eigenvalues ``lams`` whose shape has the ratio ``ratio``
    (wheel to body for the quarter car, `_Shapes.ratio` for a vehicle)."""
    lam, wn, zeta, fd = _mode_numbers(lams)
    phase = float(np.degrees(np.angle(ratio)))
    extra.setdefault("zeta_nominal", math.nan)
    return Mode(name, lam, wn, zeta, fd, fn_undamped, float(abs(ratio)), phase, **extra)


def _mode_numbers(lams) -> tuple[complex, float, float, float]:
    """``(eigenvalue, wn, zeta, fd)`` of a mode: a conjugate pair (given by its
    Im > 0 member), two real eigenvalues of an overdamped mode (the slower one
    stands for it, ``wn = √(λ₁λ₂)``, ``ζ = -(λ₁+λ₂)/(2 wn) >= 1``), or one real."""
    if len(lams) == 2:
        l1, l2 = (float(x.real) for x in lams)
        wn = math.sqrt(l1 * l2)
        if wn == 0.0:
            # the slower root settled to 0 (below rounding against the faster one):
            # ζ = -(λ₁+λ₂)/(2√(λ₁λ₂)) -> +inf as λ₁ -> 0⁻, and 0 when both are 0
            return complex(max(l1, l2)), 0.0, math.inf if l1 + l2 < 0 else 0.0, 0.0
        return complex(max(l1, l2)), wn, -(l1 + l2) / (2 * wn), 0.0
    lam = complex(lams[0])
    if lam.imag > 0:
        return lam, abs(lam), -lam.real / abs(lam), lam.imag / (2 * math.pi)
    return lam, abs(lam), 1.0, 0.0


def _shape(v: np.ndarray) -> complex:
    """``xu/xs`` of an eigenvector (states ``[vs, vu, xs, xu]``); inf when xs = 0."""
    return complex(v[3] / v[2]) if v[2] != 0 else complex(math.inf)


def _pair_eigenvalues(eigvals, eigvecs):
    """Group the 4 eigenvalues into 2 modes: ``[(eigenvalues, eigenvector)]``.

    A conjugate pair is one mode. Real eigenvalues come from overdamped
    modes; they are paired by mode shape (the two most in phase, largest
    Re(xu/xs), form the body mode), and the slower one's vector stands for it.
    """
    complex_idx = [i for i in range(4) if eigvals[i].imag > 0]
    real_idx = [i for i in range(4) if eigvals[i].imag == 0]
    groups = [((eigvals[i],), eigvecs[:, i]) for i in complex_idx]
    if real_idx:
        real_idx.sort(key=lambda i: -_in_phase(_shape(eigvecs[:, i])))
        for pair in (real_idx[:2], real_idx[2:]):
            if pair:
                slow = max(pair, key=lambda i: eigvals[i].real)
                groups.append((tuple(eigvals[i] for i in pair), eigvecs[:, slow]))
    return groups


def _damping_note(body: Mode, MinvK: np.ndarray) -> str:
    """One line on how the body's modal damping compares with the nominal."""
    nominal, modal = body.zeta_nominal, body.zeta
    if not math.isfinite(nominal) or nominal == 0:
        return ""
    if abs(modal - nominal) <= 0.1 * nominal:
        return (
            f"The body mode's modal damping ratio {modal:.3f} is within 10% of the "
            f"nominal {nominal:.3f} = cs/(2*sqrt(ks*ms))."
        )
    # M^-1 K = [[ks/ms, -ks/ms], [-ks/mu, (ks+ku)/mu]], so ku/ks is read off the matrix.
    ku_over_ks = (MinvK[1, 1] + MinvK[1, 0]) / -MinvK[1, 0]
    ratio = body.shape_ratio * np.exp(1j * np.radians(body.shape_phase))
    stroke = abs(1.0 - ratio) if math.isfinite(body.shape_ratio) else math.inf
    return (
        f"Note: the body mode's modal damping ratio {modal:.3f} is not the nominal "
        f"{nominal:.3f} = cs/(2*sqrt(ks*ms)), which assumes a rigid tire; here the tire "
        f"is {ku_over_ks:.2f} times as stiff as the spring, so in body bounce the wheel "
        f"moves {body.shape_ratio:.2f} times as far as the body and the damper strokes "
        f"{stroke:.2f} of the body's motion."
    )


def numerical_modes(method, h: float, vehicle=None) -> pd.DataFrame:
    """`qc_control.numerics.stability.numerical_modes` with the vehicle's modes named.

    A quarter car (parameters, a dict, ``None`` for the seed's, or a system
    in quarter-car form) gets rows ``body bounce`` and ``wheel hop`` from
    `modal_analysis`; any other system or list of eigenvalues gets the
    general rows (``mode 1``, ``mode 2``, ... by increasing ``|λ|``).

    Examples
    --------
    >>> nm = numerical_modes("euler", 0.01)
    >>> list(nm.index), bool(nm.loc["body bounce", "zeta error"] < 0)
    (['body bounce', 'wheel hop'], True)
    """
    if vehicle is None or isinstance(vehicle, (QuarterCarParams, dict)):
        return stability.numerical_modes(method, h, modal_analysis(vehicle))
    try:
        named = modal_analysis(vehicle)
    except (TypeError, ValueError):  # not a quarter car: general rows
        return stability.numerical_modes(method, h, vehicle)
    return stability.numerical_modes(method, h, named)


#: Body degrees of freedom by displacement-state label, and the mode each names.
BODY_MODES = {"xs": "bounce", "z": "bounce", "theta": "pitch", "phi": "roll"}


def _corner_labels(
    sys: control.StateSpace, model: VehicleModel | None
) -> list[tuple[str, str, str]]:
    """``(name, travel label, tire label)`` per corner: the model's roles, or
    for a bare system the outputs ``susp_travel_<s>`` / ``tire_defl_<s>``."""
    if model is not None:
        return [(c.name, c.susp_travel, c.tire_defl) for c in model.corners]
    names = dict(HALF_CAR_CORNERS + FULL_CAR_CORNERS)
    out = list(sys.output_labels)
    return [
        (names.get(label[12:], label[12:]), label, "tire_defl_" + label[12:])
        for label in out
        if label.startswith("susp_travel_") and "tire_defl_" + label[12:] in out
    ]


def _assign(scores: np.ndarray) -> list[int | None]:
    """For each row (a mode), the column (a name) of the best one-to-one match
    (largest product of scores); None for rows left over."""
    rows, cols = scipy.optimize.linear_sum_assignment(-np.log(np.maximum(scores, 1e-300)))
    out: list[int | None] = [None] * scores.shape[0]
    for r, c in zip(rows, cols):
        out[r] = int(c)
    return out


class _Shapes:
    """What naming needs of a vehicle: its wheels, its body points over them and its templates."""

    def __init__(self, sys: control.StateSpace, model: VehicleModel | None):
        A = np.asarray(sys.A, dtype=float)
        N = A.shape[0]
        n = N // 2
        if N % 2 or not np.array_equal(A[n:], np.hstack([np.eye(n), np.zeros((n, n))])):
            raise ValueError(
                f"system {sys.name!r} is not in vehicle form: the states must be the "
                "velocities then the displacements, A = [[-M⁻¹C, -M⁻¹K], [I, 0]]"
            )
        corners = _corner_labels(sys, model)
        if not corners:
            raise ValueError(
                f"system {sys.name!r} names no corners: pass a VehicleModel, or a system with "
                "outputs 'susp_travel_<corner>' and 'tire_defl_<corner>'"
            )
        out, C = list(sys.output_labels), np.asarray(sys.C, dtype=float)
        self.n, self.A = n, A
        self.labels = list(sys.state_labels)[n:]
        self.wheels = [int(np.argmax(np.abs(C[out.index(t), n:]))) for _, _, t in corners]
        eye = np.eye(n)
        # the body point above each wheel: travel + wheel
        self.body = np.array(
            [C[out.index(s), n:] + eye[w] for (_, s, _), w in zip(corners, self.wheels)]
        )
        self.dofs = [j for j in range(n) if j not in self.wheels]
        self.body_names = [
            BODY_MODES.get(self.labels[j], f"{self.labels[j]} mode") for j in self.dofs
        ]
        # how far each body coordinate moves the body points over the wheels (rms)
        self.lever = np.sqrt(np.mean(self.body[:, self.dofs] ** 2, axis=0))
        axles: dict[str, list[tuple[int, str]]] = {}
        for i, (name, _, _) in enumerate(corners):
            words = name.split()
            axles.setdefault(words[0] if words else "", []).append(
                (i, words[1] if len(words) > 1 else "")
            )
        self.templates, self.wheel_names = [], []
        for axle, members in axles.items():
            hop = np.zeros(len(corners))
            hop[[i for i, _ in members]] = 1.0
            self.templates.append(hop)
            self.wheel_names.append(f"{axle} wheel hop".strip())
            sides = dict((side, i) for i, side in members)
            if "left" in sides and "right" in sides:
                tramp = np.zeros(len(corners))
                tramp[sides["left"]], tramp[sides["right"]] = 1.0, -1.0
                self.templates.append(tramp)
                self.wheel_names.append(f"{axle} axle tramp".strip())

    def motions(self, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(wheel motions u, body motions b above the wheels) of a displacement shape."""
        return phi[self.wheels], self.body @ phi

    def names(self, shapes: list[np.ndarray]) -> list[str]:
        """Names of displacement shapes: the body modes are those whose wheels follow
        the body most closely; each gets the body coordinate that moves the body
        most, and each wheel mode the axle pattern it resembles most, one-to-one."""
        stroke = []
        for phi in shapes:
            u, b = self.motions(phi)
            stroke.append(np.sum(np.abs(u - b) ** 2) / np.sum(np.abs(u) ** 2 + np.abs(b) ** 2))
        order = list(np.argsort(stroke, kind="stable"))
        body, wheel = order[: len(self.dofs)], order[len(self.dofs) :]
        names = [f"mode {i + 1}" for i in range(len(shapes))]
        if body:
            share = np.array([np.abs(shapes[i][self.dofs]) * self.lever for i in body])
            share /= np.maximum(share.sum(axis=1, keepdims=True), 1e-300)
            for i, k in zip(body, _assign(share)):
                if k is not None:
                    names[i] = self.body_names[k]
        if wheel:
            score = []
            for i in wheel:
                u = self.motions(shapes[i])[0]
                score.append(
                    [
                        abs(np.vdot(t, u)) ** 2 / (t @ t * max(np.vdot(u, u).real, 1e-300))
                        for t in self.templates
                    ]
                )
            for i, k in zip(wheel, _assign(np.array(score))):
                if k is not None:
                    names[i] = self.wheel_names[k]
        return names

    def node_x(self, phi: np.ndarray) -> float:
        """``-Re(z/theta)``: where along the body heave and pitch cancel."""
        if "theta" not in self.labels:
            return math.nan
        z = next((phi[self.labels.index(k)] for k in ("z", "xs") if k in self.labels), 0.0)
        theta = phi[self.labels.index("theta")]
        return -float(np.real(z / theta)) if abs(theta) > 0 else math.inf

    def ratio(self, phi: np.ndarray) -> complex:
        u, b = self.motions(phi)
        body = float(np.sum(np.abs(b) ** 2))
        return complex(np.vdot(b, u) / body) if body > 0 else complex(math.inf)


def vehicle_modes(vehicle) -> ModalAnalysis:
    """The modes of a half car, a full car or any vehicle, named by their shapes.

    Parameters
    ----------
    vehicle : VehicleModel or control.StateSpace
        A continuous-time model whose state is the velocities then the
        displacements (``A = [[-M⁻¹C, -M⁻¹K], [I, 0]]``) with the corners
        in its roles (or, for a bare system, outputs ``susp_travel_<s>`` and
        ``tire_defl_<s>``), as `qc_control.half_car` and
        `qc_control.full_car` build them.

    Returns
    -------
    ModalAnalysis
        One `Mode` per degree of freedom: the body modes first, then the
        wheel modes.

    Notes
    -----
    Each eigenvalue pair ``λ`` (Im > 0) gives ``ωn = |λ|``, ``ζ = -Re λ/|λ|``
    and ``fd = Im λ/2π`` (python-control's `damp` convention); the undamped
    frequencies are the square roots of the eigenvalues of ``M⁻¹K``. A mode
    is named from the displacement part ``φ`` of its eigenvector:

    - the wheels' motion ``u`` and the body's motion ``b`` above them (read
      from the travel outputs: travel = body point - wheel) give the
      relative stroke ``Σ|u - b|² / Σ(|u|² + |b|²)``, near 0 when the
      wheels ride with the body and near or above 1 when they move against
      it. The modes with the smallest strokes, as many as the body has
      coordinates, are body modes;
    - each body mode is named after the body coordinate (``z`` bounce,
      ``theta`` pitch, ``phi`` roll) whose motion moves the body points
      over the wheels most, one name per mode (an assignment maximising
      the product of the shares);
    - each wheel mode is named after the axle pattern its wheel motions
      match best (normalised ``|tᵀu|²``): both wheels of an axle together
      (``front wheel hop``) or against each other (``front axle tramp``).

    A bounce mode is the one whose node (``node x``: where heave and pitch
    cancel) lies far from the CG, the pitch mode's lies near it (Gillespie,
    *Fundamentals of Vehicle Dynamics*, SAE 1992, ch. 5). Under Olley's
    condition ``Iy = ms·a·b`` the nodes are at the axles: each mode moves
    one axle only.

    Examples
    --------
    >>> from qc_control.models.halfcar import half_car_model
    >>> [m.name for m in vehicle_modes(half_car_model()).modes]
    ['bounce', 'pitch', 'front wheel hop', 'rear wheel hop']
    """
    model = vehicle if isinstance(vehicle, VehicleModel) else None
    sys = vehicle.system if model is not None else vehicle
    if not isinstance(sys, control.StateSpace):
        raise TypeError(f"expected a VehicleModel or control.StateSpace, got {type(sys).__name__}")
    if not control.isctime(sys, strict=True):
        raise ValueError(f"system {sys.name!r} must be continuous-time, got dt={sys.dt!r}")
    geo = _Shapes(sys, model)
    n = geo.n
    eigvals, eigvecs = np.linalg.eig(geo.A)
    groups = _group(eigvals, eigvecs[n:])
    names = geo.names([v for _, v in groups])

    w2, phi = np.linalg.eig(-geo.A[:n, n:])  # M⁻¹K
    w2, phi = w2.real, phi.real
    undamped = dict(zip(geo.names(list(phi.T)), np.sqrt(np.maximum(w2, 0.0)) / (2 * math.pi)))

    modes = []
    for name, (lams, v) in zip(names, groups):
        v = v / v[np.argmax(np.abs(v))]
        modes.append(
            _mode(
                name,
                lams,
                geo.ratio(v),
                float(undamped.get(name, math.nan)),
                shape=tuple(zip(geo.labels, (complex(x) for x in v))),
                node_x=geo.node_x(v) if name in ("bounce", "pitch") else math.nan,
            )
        )
    rank = {name: i for i, name in enumerate(geo.body_names + geo.wheel_names)}
    modes.sort(key=lambda m: (rank.get(m.name, len(rank)), m.wn))
    return ModalAnalysis(tuple(modes), "", tuple(_VEHICLE_COLUMNS.items()))


def _group(eigvals: np.ndarray, shapes: np.ndarray) -> list[tuple[tuple[complex, ...], np.ndarray]]:
    """Eigenvalues grouped into modes with their displacement shapes: a conjugate
    pair is one mode; real eigenvalues (overdamped) pair up by the most similar
    shapes, the slower one's shape standing for the pair."""
    groups: list[tuple[tuple[complex, ...], np.ndarray]] = [
        ((complex(eigvals[i]),), shapes[:, i]) for i in range(eigvals.size) if eigvals[i].imag > 0
    ]
    real = [i for i in range(eigvals.size) if eigvals[i].imag == 0]
    unit = {i: shapes[:, i] / max(np.linalg.norm(shapes[:, i]), 1e-300) for i in real}
    while real:
        i = real.pop(0)
        if not real:
            groups.append(((complex(eigvals[i]),), shapes[:, i]))
            break
        j = max(real, key=lambda k: abs(np.vdot(unit[i], unit[k])))
        real.remove(j)
        slow = i if eigvals[i].real > eigvals[j].real else j
        groups.append(((complex(eigvals[i]), complex(eigvals[j])), shapes[:, slow]))
    return groups
