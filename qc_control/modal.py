"""Modal analysis of the quarter car: frequencies, damping and mode shapes."""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np
import pandas as pd

from . import stability
from .model import QuarterCarParams, quarter_car

__all__ = ["Mode", "ModalAnalysis", "modal_analysis", "quarter_car_matrices", "numerical_modes"]

BODY, WHEEL = "body bounce", "wheel hop"


@dataclass(frozen=True)
class Mode:
    """One vibration mode (a conjugate pair, or two real eigenvalues).

    Attributes
    ----------
    name : str
        ``'body bounce'`` or ``'wheel hop'``, from the mode shape.
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
        |xu/xs| and its phase [deg] in the eigenvector.
    zeta_nominal : float
        The nominal cs/(2√(ks·ms)), the same for both modes.
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


@dataclass(frozen=True)
class ModalAnalysis:
    """The two modes of a quarter car, body bounce first.

    ``str()`` gives the table and the note; `to_frame` gives a DataFrame.
    """

    modes: tuple[Mode, Mode]
    note: str

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
            m.name: {label: getattr(m, attr) for attr, label in _COLUMNS.items()}
            for m in self.modes
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
    sys_or_params : QuarterCarParams, dict, control.StateSpace or None
        The vehicle; a system must have the states ``[vs, vu, xs, xu]``
        (as `quarter_car` builds it). ``None`` is the seed's vehicle.

    Returns
    -------
    ModalAnalysis
        Two `Mode` rows, body bounce first, and a one-line note when the
        body mode's damping departs from the nominal ratio.

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

    w2, phi = np.linalg.eig(MinvK)
    order = np.argsort(np.abs(w2))
    w2, phi = w2[order].real, phi[:, order].real
    undamped_names = _classify(
        [phi[1, i] / phi[0, i] if phi[0, i] else complex(math.inf) for i in range(2)]
    )
    fn_undamped = {n: math.sqrt(max(w, 0.0)) / (2 * math.pi) for n, w in zip(undamped_names, w2)}

    modes = []
    for name, (lams, v) in zip(names, groups):
        if len(lams) == 1:  # a conjugate pair, represented by Im >= 0
            lam = lams[0]
            wn, zeta, fd = abs(lam), -lam.real / abs(lam), abs(lam.imag) / (2 * math.pi)
        else:  # two real eigenvalues of one overdamped mode
            l1, l2 = (float(x.real) for x in lams)
            wn = math.sqrt(l1 * l2)
            zeta, fd, lam = -(l1 + l2) / (2 * wn), 0.0, complex(max(l1, l2))
        ratio = _shape(v)
        modes.append(
            Mode(
                name,
                complex(lam),
                float(wn),
                float(zeta),
                float(fd),
                fn_undamped[name],
                float(abs(ratio)),
                float(np.degrees(np.angle(ratio))),
                float(zeta_nominal),
            )
        )
    modes.sort(key=lambda m: m.name != BODY)
    return ModalAnalysis((modes[0], modes[1]), _damping_note(modes[0], MinvK))


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
    """`qc_control.stability.numerical_modes` with the vehicle's modes named.

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
