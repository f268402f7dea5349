"""Exact stationary variances of linear vehicles on random roads (Lyapunov equations).

A stable linear system ``x' = A x + B w`` driven by white noise of unit
intensity, ``E[w(t) w(s)ᵀ] = I δ(t - s)``, settles to a stationary state
covariance ``P``, the solution of the Lyapunov equation

.. math:: A P + P A^T + B B^T = 0,

and an output ``y = C x`` has the variances ``diag(C P Cᵀ)`` (the squared
H2 norm of each output channel). No simulation and no frequency
quadrature: the variance is exact over the unbounded band.

An ISO 8608 road of waviness 2 is exactly white road *velocity* at a
constant speed: its displacement PSD ``Gd(n) = Gd(n0)(n/n0)^-2`` makes the
velocity PSD flat, of two-sided intensity
``q = 2 π² n0² Gd(n0) v`` (`iso8608_intensity`). `white_velocity_variances`
drives a vehicle's road inputs with it.

Sources: Gobbi & Mastinu, J. Sound Vib. 245(3), 2001 (closed forms for the
quarter car); Dahlberg, J. Sound Vib. 58(2), 1978; Kwakernaak & Sivan,
*Linear Optimal Control Systems*, 1972, §1.11 (the Lyapunov equation).
"""

from __future__ import annotations

import functools
import warnings
from typing import Any

import control
import numpy as np
import scipy.linalg

from ..models.registry import model_for_params
from ..models.vehicle import VehicleModel
from ..numerics import checks
from ..numerics.checks import ParameterError, positive
from ..numerics.threads import one_blas_thread
from .assessment import AXES
from .guidance import AXIS_RULES, POSTURES
from .iso2631 import weighting, wk_filter
from .metrics import metric_columns
from .road import ISO8608_BAND, ISO8608Road, iso8608_intensity

__all__ = [
    "lyapunov_variances",
    "stationary_covariance",
    "white_velocity_system",
    "white_velocity_variances",
    "white_velocity_wk_variance",
    "iso8608_intensity",
    "ISO8608Road",
    "road_variances",
    "rear_delay",
    "IndependentTracksWarning",
    "road_intensity",
    "spectral_road",
    "iso8608_spelling",
    "DEFAULT_ROAD",
    "spectral_metrics",
    "spectral_axis_rms",
    "spectral_a_v",
    "SPECTRAL_METRICS",
    "SPECTRAL_CAPABLE",
]

#: Up to this many states the batched solve uses the Kronecker form (n² unknowns,
#: one LU per design, backward stable); above it, the eigendecomposition.
_KRONECKER_MAX_STATES = 6


def _as_batch(A, B, C=None):
    A = np.asarray(A, dtype=float)
    B = np.asarray(B, dtype=float)
    if A.ndim < 2 or A.shape[-1] != A.shape[-2]:
        raise ValueError(f"A must be square, of shape (n, n) or (m, n, n), got shape {A.shape}")
    n = A.shape[-1]
    if B.ndim < 2 or B.shape[-2] != n:
        raise ValueError(f"B must be of shape (..., {n}, k) to match A, got shape {B.shape}")
    if C is not None:
        C = np.asarray(C, dtype=float)
        if C.ndim < 2 or C.shape[-1] != n:
            raise ValueError(f"C must be of shape (..., p, {n}) to match A, got shape {C.shape}")
    return A, B, C


def _check_hurwitz(A: np.ndarray) -> None:
    """ValueError naming the first design whose A has an eigenvalue with Re >= 0."""
    flat = A.reshape((-1,) + A.shape[-2:])
    finite = np.isfinite(flat).all(axis=(-1, -2))
    if not finite.all():
        i = int(np.argmin(finite))
        raise ValueError(f"A of design {i} is not finite")
    top = np.linalg.eigvals(flat).real.max(axis=-1)
    bad = np.flatnonzero(top >= 0)
    if bad.size:
        i = int(bad[0])
        where = f"design {i}" if A.ndim == 3 else "the system"
        raise ValueError(
            f"A of {where} is not Hurwitz (largest real part of an eigenvalue {top[i]:.6g} "
            ">= 0): it has no stationary variance"
        )


def stationary_covariance(A, B) -> np.ndarray:
    """``P`` solving ``A P + P Aᵀ + B Bᵀ = 0``, for one system or a batch.

    Parameters
    ----------
    A : array_like, shape (n, n) or (m, n, n)
        Hurwitz.
    B : array_like, shape (n, k) or (m, n, k)

    Returns
    -------
    ndarray, shape (n, n) or (m, n, n)
        The stationary state covariance under unit-intensity white noise
        (the controllability Gramian of ``(A, B)``).

    Notes
    -----
    Up to six states, each design's equation is solved in its Kronecker
    form ``(I ⊗ A + A ⊗ I) vec P = -vec(B Bᵀ)`` (one batched LU of n²
    unknowns, backward stable). Larger systems use the eigendecomposition
    ``A = V Λ V⁻¹``: ``P̂ = -Q̂ / (λ_i + λ̄_j)`` with ``Q̂ = V⁻¹ Q V⁻ᴴ``; a
    design whose eigenvectors are ill-conditioned (``cond(V) > 1e6``, near a
    defective A) is solved instead by Bartels–Stewart
    (`scipy.linalg.solve_continuous_lyapunov`).
    """
    A, B, _ = _as_batch(A, B)
    _check_hurwitz(A)
    single = A.ndim == 2
    A3 = A.reshape((-1,) + A.shape[-2:])
    B3 = np.broadcast_to(B, A.shape[:-2] + B.shape[-2:]).reshape((A3.shape[0],) + B.shape[-2:])
    P = _gramian(A3, B3 @ np.swapaxes(B3, -1, -2))
    P = 0.5 * (P + np.swapaxes(P, -1, -2))
    return P[0] if single else P.reshape(A.shape)


def _gramian(A3: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """``X`` solving ``A X + X Aᵀ + Q = 0`` for each of ``m`` Hurwitz designs
    ``(m, n, n)``; ``Q`` need not be symmetric (a cross-Gramian ``b_i b_jᵀ``).
    The solvers of `stationary_covariance`'s notes, each valid for any ``Q``."""
    m, n = A3.shape[0], A3.shape[-1]
    if n <= _KRONECKER_MAX_STATES:
        eye = np.eye(n)
        # row-major vec: vec(A P) = (A ⊗ I) vec P, vec(P Aᵀ) = (I ⊗ A) vec P
        K = np.einsum("mij,kl->mikjl", A3, eye).reshape(m, n * n, n * n)
        K += np.einsum("ij,mkl->mikjl", eye, A3).reshape(m, n * n, n * n)
        P = np.linalg.solve(K, -Q.reshape(m, n * n, 1)).reshape(m, n, n)
    else:
        lam, V = np.linalg.eig(A3)
        Vinv = np.linalg.inv(V)
        Qh = Vinv @ Q @ np.swapaxes(Vinv.conj(), -1, -2)
        Ph = -Qh / (lam[:, :, None] + lam[:, None, :].conj())
        P = (V @ Ph @ np.swapaxes(V.conj(), -1, -2)).real
        bad = np.flatnonzero(np.linalg.cond(V) > 1e6)
        if bad.size:
            for i in bad:
                P[i] = scipy.linalg.solve_continuous_lyapunov(A3[i], -Q[i])
    return P


def lyapunov_variances(A, B, C) -> np.ndarray:
    """Stationary output variances ``diag(C P Cᵀ)`` under unit-intensity white noise.

    .. math:: A P + P A^T + B B^T = 0, \\qquad σ_i^2 = (C P C^T)_{ii}

    for ``x' = A x + B w``, ``y = C x``, ``E[w(t) w(s)ᵀ] = I δ(t - s)``.
    ``σ_i²`` is the squared H2 norm of output ``i``, the variance over the
    unbounded frequency band.

    Parameters
    ----------
    A : array_like, shape (n, n) or (m, n, n)
        ``m`` designs; each must be Hurwitz.
    B : array_like, shape (..., n, k)
    C : array_like, shape (..., p, n)

    Returns
    -------
    ndarray, shape (p,) or (m, p)

    Raises
    ------
    ValueError
        If the shapes disagree, or a design's ``A`` is not Hurwitz (the
        message names the design).

    Examples
    --------
    >>> import numpy as np
    >>> # x' = -a x + w: σ² = 1/(2a)
    >>> float(lyapunov_variances([[-2.0]], [[1.0]], [[1.0]])[0])
    0.25
    """
    A, B, C = _as_batch(A, B, C)
    P = stationary_covariance(A, B)
    return np.einsum("...ij,...jk,...ik->...i", C, P, C)


def road_variances(A, B, C, followers=(), delay=None) -> np.ndarray:
    """`lyapunov_variances`, with some inputs the delayed copies of others.

    Input ``j`` of a pair ``(i, j)`` in ``followers`` is input ``i``'s white
    noise ``τ`` later (a rear wheel meeting the front wheel's road a
    wheelbase later); the other inputs are independent. With ``y_i`` the
    response to input ``i`` alone, ``E[y_i(t) y_j(t)ᵀ] = C e^{Aτ} X_ij Cᵀ``,
    ``A X_ij + X_ij Aᵀ + b_i b_jᵀ = 0`` (the white noise reaches ``y_j`` ``τ``
    after ``y_i``: substitute ``w_j(t) = w_i(t - τ)`` in the two convolution
    integrals), so

    .. math:: σ^2 = \\mathrm{diag}\\Big(C P C^T + \\sum_{(i,j)} \\big(C e^{Aτ} X_{ij} C^T
              + (C e^{Aτ} X_{ij} C^T)^T\\big)\\Big),

    exact for the pure delay ``e^{-sτ}`` (no Padé approximation): it equals
    Parseval's ``(1/2π) ∫ |Σ_i H_i(jω) e^{-jωτ_i}|² dω``.

    Parameters
    ----------
    A, B, C : array_like
        As `lyapunov_variances`.
    followers : sequence of (int, int)
        ``(leading input, following input)`` column pairs of ``B``.
    delay : float or array_like (m,)
        ``τ`` [s] of every pair, one per design for a batch.

    Returns
    -------
    ndarray, shape (p,) or (m, p)
    """
    A, B, C = _as_batch(A, B, C)
    var = lyapunov_variances(A, B, C)
    if not followers:
        return var
    A3 = A.reshape((-1,) + A.shape[-2:])
    m = A3.shape[0]
    B3 = np.broadcast_to(B, A.shape[:-2] + B.shape[-2:]).reshape((m,) + B.shape[-2:])
    C3 = np.broadcast_to(C, A.shape[:-2] + C.shape[-2:]).reshape((m,) + C.shape[-2:])
    tau = np.broadcast_to(np.asarray(delay, dtype=float), (m,))
    E = scipy.linalg.expm(A3 * tau[:, None, None])  # e^{Aτ}, per design
    cross = np.zeros((m, C3.shape[1]))
    for i, j in followers:
        X = _gramian(A3, B3[:, :, i, None] @ B3[:, :, j, None].swapaxes(-1, -2))
        cross += 2.0 * np.einsum("mpi,mij,mjk,mpk->mp", C3, E, X, C3)
    return var + cross.reshape(var.shape)


def rear_delay(model: VehicleModel, speed, batch=None) -> tuple[tuple[tuple[int, int], ...], Any]:
    """``(followers, τ)`` of `road_variances` for a car at ``speed`` [m/s]: its
    rear wheels meet its front wheels' road ``τ = (a + b)/speed`` later.

    The pairs follow the car's road layout (`ModelEntry.road_layout`, as the
    time-domain roads of `qc_control.studies.on_road` do): ``'axles'``, the
    rear input follows the front one; ``'corners'``, each rear corner its own
    side's front corner (the left and right tracks independent of each other).
    A one-wheel car, or ``speed`` None, has none: ``((), None)``; then every
    road input is an independent track.
    """
    if speed is None:
        return (), None
    speed = positive("speed", speed, "m/s")
    pairs = _FOLLOWERS.get(_road_layout(model), ())
    if not pairs:
        return (), None
    wheelbase = model.params.a + model.params.b if batch is None else batch.wheelbase
    if wheelbase is None:
        raise ValueError("the batch has no wheelbases: build it with model.batch(designs)")
    return pairs, np.asarray(wheelbase, dtype=float) / speed


def _road_layout(model: VehicleModel) -> str:
    """The registered model's `ModelEntry.road_layout` (``'single'`` for a model
    the registry does not know)."""
    entry = model_for_params(model.params)
    return entry.road_layout if entry is not None else "single"


#: Per road layout, the (front, rear) pairs of its road inputs (in
#: `VehicleModel.road_inputs` order) where the rear follows the front.
_FOLLOWERS = {"axles": ((0, 1),), "corners": ((0, 2), (1, 3))}


def require_linear(model: VehicleModel, what: str = "") -> None:
    """Refuse a nonlinear model for stationary (spectral) metrics, naming it.

    The stationary variances solve a Lyapunov equation of ``(A, B, C)``; a
    law that switches (semi-active damping, contact, bump stops) has no
    such matrices, and its ride is found by simulating it on a road.
    """
    if model.is_nonlinear:
        raise ValueError(
            f"{what or 'model'} {model.name!r} is nonlinear: stationary (spectral) ride "
            "metrics need a linear vehicle; simulate it on a road instead (qc.ride_metrics, "
            "or qc.sweep with T and U)"
        )


def white_velocity_system(model: VehicleModel, batch=None):
    """``(Ã, B̃, C)`` of a vehicle whose road inputs are driven by white road velocity.

    With the road displacement ``zr`` integrated from a white velocity
    ``w = zr'``, the state measured from the static equilibrium over the
    current road height, ``x̃ = x + A⁻¹ B_r zr``, obeys

    .. math:: \\tilde x' = A \\tilde x + A^{-1} B_r\\, w, \\qquad
              y = C \\tilde x + G_r(0)\\, z_r,

    with ``G_r(0) = D_r - C A⁻¹ B_r`` the static gain from the road. The
    outputs that do not follow a constant road height (``G_r(0) = 0``:
    body acceleration, suspension travel, tire deflection) are therefore
    ``C x̃``, stationary, with the Lyapunov variances of ``(A, A⁻¹B_r, C)``;
    the others (the body and wheel heights) follow the road's random walk
    and have no stationary variance.

    Parameters
    ----------
    model : VehicleModel
        With at least one road input (`VehicleModel.road_inputs`).
    batch : BatchedModel, optional
        Many designs of ``model`` (``model.batch(designs)``); default the
        model itself.

    Returns
    -------
    A, Bw, C, static_gain : ndarray
        ``(..., n, n)``, ``(..., n, r)`` for the ``r`` road inputs,
        ``(..., p, n)`` and ``(..., p)``: the largest ``|G_r(0)|`` of each
        output over the road inputs.
    """
    if not isinstance(model, VehicleModel):
        raise TypeError(f"model must be a VehicleModel, got {type(model).__name__}")
    require_linear(model)
    roads = model.road_inputs()
    if not roads:
        raise ValueError(
            f"model {model.name!r} has no road input: build it with road=True "
            f"(inputs are {list(model.system.input_labels)})"
        )
    _warn_of_independent_sides(model)
    cols = [list(model.system.input_labels).index(r) for r in roads]
    if batch is None:
        A, B, C, D = (np.asarray(getattr(model.system, k), dtype=float) for k in "ABCD")
    else:
        A, B, C, D = batch.A, batch.B, batch.C, batch.D
    _check_hurwitz(A)
    Br, Dr = B[..., cols], D[..., cols]
    Bw = np.linalg.solve(A, Br)  # A⁻¹ B_r
    gain = np.abs(Dr - C @ Bw).max(axis=-1)
    return A, Bw, C, gain


class IndependentTracksWarning(UserWarning):
    """Spectral values of a car on two tracks, taken as independent roads."""


def _warn_of_independent_sides(model: VehicleModel) -> None:
    """Say so when a car's left and right wheels are on tracks the spectral values
    take as independent: on a real road (and `ISO8608Road`'s two simulated tracks,
    an isotropic surface) they are coherent at long wavelengths, with the coherence
    ``kB K₁(kB)`` of no finite state space, so the values are not the road's."""
    if _road_layout(model) == "corners":
        warnings.warn(
            f"spectral values of {model.name!r} take its left and right tracks as "
            "independent roads; an ISO 8608 road's two tracks are coherent at long "
            "wavelengths, so its roll comes out too large (1.8 times a simulated ride "
            "on class C at 20 m/s) and its heave too small (0.92 times): for a car on "
            "four corners, simulate the road (qc.sweep with T, qc.ride_assessment)",
            IndependentTracksWarning,
            stacklevel=3,
        )


def white_velocity_variances(
    model: VehicleModel, *, intensity: float = 1.0, outputs=None, batch=None, speed=None
) -> dict:
    """Stationary output variances of a vehicle on white road velocity.

    Every track of ``model`` is driven by white road velocity of two-sided
    intensity ``intensity`` [m²/s], ``E[zr'(t) zr'(s)] = intensity · δ(t -
    s)``, the road displacement being its integral. Given the ``speed``, a
    car's rear wheels meet its front wheels' road ``(a + b)/speed`` later
    (`rear_delay`, `road_variances`: exact for the delay); without it, every
    road input is an independent track.

    .. math:: σ_y^2 = q\\, \\mathrm{diag}(C P C^T), \\qquad
              A P + P A^T + A^{-1} B_r B_r^T A^{-T} = 0

    (see `white_velocity_system`). For the quarter car and unit intensity
    the results equal the closed forms of Gobbi & Mastinu (2001):
    ``σ²(body_acc) = (cs² kt + ks² (ms + mu)) / (2 cs ms²)`` and
    ``σ²(susp_travel) = (ms + mu) / (2 cs)``.

    Parameters
    ----------
    model : VehicleModel
        A linear vehicle with road inputs (e.g. ``quarter_car_model(road=True)``).
    intensity : float, default 1
        ``q`` [m²/s]; `iso8608_intensity` gives an ISO 8608 road's.
    outputs : sequence of str, optional
        Output labels; default all.
    batch : BatchedModel, optional
        Many designs at once: each value is then an array ``(m,)``.
    speed : float, optional
        The car's speed [m/s], for the rear wheels' delay (`rear_delay`).

    Returns
    -------
    dict[str, float or ndarray]
        Variance of each output [unit²]; ``inf`` for an output that follows
        the road height (``xs``, ``xu``), which has no stationary variance
        under a random-walk road (see `iso8608` for a band-limited road).

    Examples
    --------
    >>> from qc_control.models.quarter import quarter_car_model
    >>> v = white_velocity_variances(quarter_car_model(road=True))
    >>> round(v["susp_travel"], 9)           # (ms + mu) / (2 cs)
    0.133466666
    """
    q = positive("intensity", intensity, "m²/s")
    labels = list(model.system.output_labels)
    wanted = labels if outputs is None else list(outputs)
    unknown = [o for o in wanted if o not in labels]
    if unknown:
        raise ValueError(f"no output {unknown[0]!r}; outputs are {labels}")
    A, Bw, C, gain = white_velocity_system(model, batch)
    rows = [labels.index(o) for o in wanted]
    var = q * road_variances(A, Bw, C[..., rows, :], *rear_delay(model, speed, batch))
    scale = np.abs(C[..., rows, :]).max(axis=-1) + 1.0
    follows = gain[..., rows] > 1e-9 * scale
    var = np.where(follows, np.inf, var)
    return {o: (float(var[..., i]) if var.ndim == 1 else var[..., i]) for i, o in enumerate(wanted)}


def white_velocity_wk_variance(
    model: VehicleModel, *, intensity: float = 1.0, batch=None, speed=None
):
    """Stationary variance of the ISO 2631-1 Wk-weighted body acceleration on white road velocity.

    The car of `white_velocity_system` in series with `qc_control.ride.iso2631.wk_filter`
    (``x_w' = A_w x_w + B_w a``, ``a_w = C_w x_w + D_w a`` with ``a`` the body
    acceleration ``C_a x̃``):

    .. math:: A_c = \\begin{bmatrix} A & 0 \\\\ B_w C_a & A_w \\end{bmatrix}, \\quad
              B_c = \\begin{bmatrix} A^{-1} B_r \\\\ 0 \\end{bmatrix}, \\quad
              C_c = [D_w C_a \\;\\; C_w],

    and ``σ² = q · C_c P C_cᵀ`` with ``A_c P + P A_cᵀ + B_c B_cᵀ = 0`` (with the
    rear wheels' delay at ``speed`` [m/s], `road_variances`).

    Returns
    -------
    float, or ndarray (m,) for a ``batch``
    """
    q = positive("intensity", intensity, "m²/s")
    A, Bw, C, gain = white_velocity_system(model, batch)
    row = list(model.system.output_labels).index(model.body_acc)
    if np.any(gain[..., row] > 1e-9 * (np.abs(C[..., row, :]).max(axis=-1) + 1.0)):
        raise ValueError(
            f"the body acceleration {model.body_acc!r} follows the road height: "
            "it has no stationary variance under white road velocity"
        )
    Aw, Bk, Cw, Dw = _wk_matrices()
    n, nw = A.shape[-1], Aw.shape[0]
    Ca = C[..., row, :]  # (..., n)
    batch_shape = A.shape[:-2]
    Ac = np.zeros(batch_shape + (n + nw, n + nw))
    Ac[..., :n, :n] = A
    Ac[..., n:, :n] = Bk[:, :1] * Ca[..., None, :]
    Ac[..., n:, n:] = Aw
    Bc = np.zeros(batch_shape + (n + nw, Bw.shape[-1]))
    Bc[..., :n, :] = Bw
    Cc = np.zeros(batch_shape + (1, n + nw))
    Cc[..., 0, :n] = Dw[0, 0] * Ca
    Cc[..., 0, n:] = Cw[0]
    var = q * road_variances(Ac, Bc, Cc, *rear_delay(model, speed, batch))[..., 0]
    return float(var) if var.ndim == 0 else var


@functools.lru_cache(maxsize=1)
def _wk_matrices() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    sys = control.ss(wk_filter())
    return tuple(np.asarray(getattr(sys, k), dtype=float) for k in "ABCD")  # type: ignore[return-value]


#: What a stationary (spectral) metric takes as its road.
_SPECTRAL_ROAD = (
    "an ISO8608Road (white road velocity), a white road-velocity intensity q > 0 m²/s, "
    "or None (q = 1)"
)


#: The random road of the spectral studies unless told otherwise: ISO 8608
#: class C (average) at 20 m/s (72 km/h), seed 0, the standard's band.
DEFAULT_ROAD = ISO8608Road("C", speed=20.0)


def iso8608_spelling(road_class, speed, seed=0, band=ISO8608_BAND) -> str:
    """``"qc.road.ISO8608Road('C', speed=20.0)"``: an ISO 8608 road as a user writes it,
    for a DeprecationWarning that names the new form of an older one (the seed
    and the band only when they are not the defaults)."""
    more = f", seed={seed!r}" if seed != 0 else ""
    more += f", band={tuple(band)!r}" if tuple(band) != tuple(ISO8608_BAND) else ""
    return f"qc.road.ISO8608Road({road_class!r}, speed={speed!r}{more})"


def road_intensity(road=None, *, stacklevel: int = 2) -> float:
    """The white road-velocity intensity ``q`` [m²/s] a stationary metric reads from ``road``.

    The variances of a linear car on white road velocity are proportional to
    ``q``; an ISO 8608 road of waviness 2 at a constant speed is white road
    velocity of intensity

    .. math:: q = 2 π^2 n_0^2 G_d(n_0)\\, v

    (`iso8608_intensity`; ISO 8608:2016, Gobbi & Mastinu, 2001).

    Parameters
    ----------
    road : None, ISO8608Road or float
        ``None``: unit intensity, ``q = 1`` (every variance per unit of
        ``q``); an `ISO8608Road`: its ``intensity``; a number: ``q`` itself
        [m²/s], > 0, the level of a road's white velocity spectrum (a
        measured road's, which has no class or speed). A ``(class, speed)``
        pair, the older form, is read as ``ISO8608Road(class, speed=speed)``
        with a DeprecationWarning naming it.
    stacklevel : int, default 2
        The frame the DeprecationWarning points at, counted from this
        function's caller (2: the caller's caller, a user calling a study).

    Returns
    -------
    float

    Raises
    ------
    qc_control.ParameterError
        For another kind of road (a step or a bump has no stationary
        spectrum: simulate it) or an intensity that is not a number > 0.

    Examples
    --------
    >>> road_intensity(ISO8608Road("C", speed=20.0)) == iso8608_intensity("C", 20.0)
    True
    """
    road = spectral_road(road, stacklevel=stacklevel + 1)
    return road.intensity if isinstance(road, ISO8608Road) else road


def spectral_road(road=None, *, stacklevel: int = 2):
    """``road`` as a stationary study keeps it: an `ISO8608Road` (whose speed
    delays a car's rear wheels, `rear_delay`), or the intensity ``q`` [m²/s]
    (None: 1). The older ``(class, speed)`` pair is read as its `ISO8608Road`,
    with the DeprecationWarning of `road_intensity`, which gives its ``q``."""
    if road is None:
        return 1.0
    if isinstance(road, ISO8608Road):
        return road
    if isinstance(road, tuple) and len(road) == 2:
        new = ISO8608Road(road[0], speed=road[1])  # a bad class or speed is refused by name
        warnings.warn(
            f"road={road!r}: a (class, speed) pair is deprecated and will be removed in the "
            f"next minor release: use road={iso8608_spelling(*road)}",
            DeprecationWarning,
            stacklevel=stacklevel + 1,
        )
        return new
    if isinstance(road, (bool, np.bool_)) or not isinstance(
        road, (int, float, np.integer, np.floating)
    ):
        raise ParameterError("road", road, _SPECTRAL_ROAD)
    return positive("road", road, "m²/s", description="white road-velocity intensity q")


@functools.lru_cache(maxsize=8)
def _weighting_matrices(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    sys = control.ss(weighting(name))
    A, B, C, D = (np.asarray(getattr(sys, k), dtype=float) for k in "ABCD")
    return A, B[:, 0], C[0], float(D[0, 0])


def _axis_rows(model: VehicleModel, C: np.ndarray, seat) -> dict[str, np.ndarray]:
    """Each ISO axis's acceleration as rows ``(..., n)`` of the car's ``C``."""
    labels = list(model.system.output_labels)
    rows = {"z": C[..., labels.index(model.body_acc), :]}
    if "pitch_acc" in labels:  # ISO ry is nose down; the cars count pitch nose up
        rows["ry"] = -C[..., labels.index("pitch_acc"), :]
    if "roll_acc" in labels:
        rows["rx"] = C[..., labels.index("roll_acc"), :]
    if seat is not None:
        h = checks.finite("seat", seat, "m", description="seat height above the pitch/roll axes")
        if "ry" in rows:
            rows["x"] = h * rows["ry"]
        if "rx" in rows:
            rows["y"] = -h * rows["rx"]
    return rows


def _weighted_variance(A, Bw, c, name: str, q: float, delayed=((), None)):
    """``q c_c P c_cᵀ`` of the car's row ``c`` in series with weighting ``name``
    (``delayed``: `rear_delay`'s followers and delay)."""
    Aw, bw, cw, dw = _weighting_matrices(name)
    n, nw = A.shape[-1], Aw.shape[0]
    batch = A.shape[:-2]
    Ac = np.zeros(batch + (n + nw, n + nw))
    Ac[..., :n, :n] = A
    Ac[..., n:, :n] = bw[:, None] * c[..., None, :]
    Ac[..., n:, n:] = Aw
    Bc = np.zeros(batch + (n + nw, Bw.shape[-1]))
    Bc[..., :n, :] = Bw
    Cc = np.zeros(batch + (1, n + nw))
    Cc[..., 0, :n] = dw * c
    Cc[..., 0, n:] = cw
    return q * road_variances(Ac, Bc, Cc, *delayed)[..., 0]


def spectral_axis_rms(
    model: VehicleModel,
    intensity: float,
    *,
    seat: float | None = None,
    posture: str = "seated",
    batch=None,
    speed: float | None = None,
) -> dict:
    """Exact stationary ISO 2631-1 weighted RMS ``a_w`` of each axis on white road velocity.

    Parameters
    ----------
    model : VehicleModel
        A linear car with road inputs (``road=True``).
    intensity : float
        ``q`` [m²/s], e.g. ``ISO8608Road('C', speed=20).intensity``.
    seat : float, optional
        Seat height above the pitch and roll axes [m]: adds ``x`` and ``y``
        (as `qc_control.ride.assessment.axis_signals` derives them).
    posture : {'seated', 'standing'}
        The weighting of each axis (`qc_control.ride.guidance.AXIS_RULES`).
    batch : BatchedModel, optional
        Many designs: each value is then an array ``(m,)``.
    speed : float, optional
        The car's speed [m/s] (an ISO 8608 road's ``speed``): its rear wheels
        meet the front wheels' road ``(a + b)/speed`` later (`rear_delay`).
        Without it the tracks are independent, which is not a car on one
        road: a half car's pitch at 20 m/s comes out 1.7 times too large.

    Returns
    -------
    dict[str, float or ndarray]
        ``a_w`` by axis, in ISO order: m/s² for x, y, z; rad/s² for rx, ry.

    Examples
    --------
    >>> from qc_control.models.quarter import quarter_car_model
    >>> from qc_control.ride.road import ISO8608Road
    >>> q = ISO8608Road("C", speed=20.0).intensity
    >>> round(spectral_axis_rms(quarter_car_model(road=True), q)["z"], 3)
    0.665
    """
    q = checks.positive("intensity", intensity, "m²/s")
    posture = checks.choice("posture", posture, POSTURES)
    A, Bw, C, gain = white_velocity_system(model, batch)
    rules = AXIS_RULES[posture]
    rows = _axis_rows(model, C, seat)
    delayed = rear_delay(model, speed, batch)
    out: dict = {}
    for axis in (a for a in AXES if a in rows and a in rules):
        var = _weighted_variance(A, Bw, rows[axis], rules[axis].weighting, q, delayed)
        out[axis] = float(np.sqrt(var)) if np.ndim(var) == 0 else np.sqrt(var)
    if not out:
        raise ParameterError("posture", posture, f"a posture with the axes of {model.name!r}")
    return out


def spectral_a_v(per_axis, posture: str = "seated"):
    """The vibration total value ``(Σ k² a_w²)^½`` (ISO 2631-1:1997 §6.5, k of
    §8.2) of `spectral_axis_rms`' values [m/s²]."""
    rules = AXIS_RULES[checks.choice("posture", posture, POSTURES)]
    return np.sqrt(sum((rules[a].k_comfort * v) ** 2 for a, v in per_axis.items()))


#: The ISO 2631-1 metrics of `qc_control.ride.metrics` with an exact stationary value:
#: the body's axes as `spectral_axis_rms` weights them, no seat height (as the metrics).
ISO2631_SPECTRAL = ("a_w_z", "a_w_rx", "a_w_ry", "a_v")
#: The metrics a spectral sweep computes unless told otherwise (the
#: Wk-weighted one costs a 12-state Lyapunov equation per design; ask for it).
SPECTRAL_METRICS = ("rms_body_acc", "rms_susp_travel", "rms_tire_load / static")
#: Every metric with an exact stationary value under white road velocity.
SPECTRAL_CAPABLE = (
    "rms_body_acc", "rms_body_acc_wk", "rms_susp_travel", "rms_tire_load / static",
    *ISO2631_SPECTRAL,
)  # fmt: skip


@one_blas_thread
def spectral_metrics(
    model: VehicleModel, intensity: float, names=SPECTRAL_METRICS, batch=None, speed=None
) -> dict:
    """Exact stationary RMS metrics of a vehicle (or a batch of designs) on white road velocity.

    ``rms_body_acc``, ``rms_body_acc_wk``, ``rms_susp_travel`` and
    ``rms_tire_load / static`` (``kt σ(tire_defl) / static load``), under the
    column names of `qc_control.ride.metrics` (per corner for a wheel's metric),
    from `white_velocity_variances` and `white_velocity_wk_variance`: the
    Lyapunov values over the unbounded band. ISO 2631-1's ``a_w_z``,
    ``a_w_rx``, ``a_w_ry`` (the body's vertical, roll and pitch, each with
    its Annex A weighting) and ``a_v = (Σ k² a_w²)^½`` over them (§6.5, k of
    §8.2) come from `spectral_axis_rms` without a seat height, as the
    time-domain metrics define them; a rotation the car does not have is 0.

    Parameters
    ----------
    model : VehicleModel
        With road inputs.
    intensity : float
        ``q`` [m²/s] (`iso8608_intensity`, or ``ISO8608Road.intensity``).
    names : sequence of str, default `SPECTRAL_METRICS`
        Metric names (or columns) among `SPECTRAL_CAPABLE`.
    batch : BatchedModel, optional
        Many designs at once: values are then arrays ``(m,)``.
    speed : float, optional
        The car's speed [m/s]: its rear wheels meet the front wheels' road
        ``(a + b)/speed`` later (`rear_delay`); without it, independent tracks.

    Returns
    -------
    dict[str, float or ndarray]
    """
    items = metric_columns(list(names), model.roles)
    other = sorted({metric.name for _, metric, _ in items} - set(SPECTRAL_CAPABLE))
    if other:
        raise ValueError(
            f"metric {other[0]!r} has no stationary spectral value; a spectral sweep "
            f"computes {', '.join(SPECTRAL_CAPABLE)}"
        )
    roles = model.roles
    labels = [roles.body_acc] + [c.susp_travel for c in roles.corners]
    labels += [c.tire_defl for c in roles.corners]
    var = white_velocity_variances(
        model, intensity=intensity, outputs=list(dict.fromkeys(labels)), batch=batch, speed=speed
    )
    stiffness = (
        batch.tire_stiffness if batch is not None else [c.tire_stiffness for c in roles.corners]
    )
    load = batch.static_load if batch is not None else [c.static_load for c in roles.corners]
    out: dict = {}
    axes = (
        spectral_axis_rms(model, intensity, batch=batch, speed=speed)
        if any(metric.name in ISO2631_SPECTRAL for _, metric, _ in items)
        else {}
    )
    for column, metric, i in items:
        corner = roles.corners[i]
        if metric.name in ISO2631_SPECTRAL:
            out[column] = _iso2631_value(metric.name, axes)
        elif metric.name == "rms_body_acc":
            out[column] = np.sqrt(var[roles.body_acc])
        elif metric.name == "rms_body_acc_wk":
            out[column] = np.sqrt(
                white_velocity_wk_variance(model, intensity=intensity, batch=batch, speed=speed)
            )
        elif metric.name == "rms_susp_travel":
            out[column] = np.sqrt(var[corner.susp_travel])
        else:
            out[column] = stiffness[i] * np.sqrt(var[corner.tire_defl]) / load[i]
    return {k: (float(v) if np.ndim(v) == 0 else v) for k, v in out.items()}


def _iso2631_value(name: str, axes: dict):
    """A metric of `ISO2631_SPECTRAL` from `spectral_axis_rms`' ``axes``; a rotation
    the car's body does not have (a quarter car's pitch) is 0, as in the time domain."""
    if name == "a_v":
        return spectral_a_v(axes)
    axis = name.removeprefix("a_w_")
    return axes[axis] if axis in axes else 0.0 * axes["z"]
