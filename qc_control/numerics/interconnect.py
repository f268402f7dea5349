"""A precomputed `control.InterconnectedSystem`: the fast path of `input_output_response`.

python-control evaluates an interconnection's right-hand side
(``InterconnectedSystem._rhs``) by solving its static input/output
relations afresh at every call: it evaluates every subsystem's output
function, maps outputs to inputs through ``connect_map``, and repeats until
nothing changes (up to ``len(syslist) + 1`` sweeps). At a fixed step that is
most of the run's time. Here the interconnection is solved once, when the
system is compiled:

* **Linear subsystems** (``control.StateSpace``) are eliminated
  algebraically. With ``K`` the connection map (subsystem inputs from
  subsystem outputs), ``E`` the input map, ``w`` the external inputs and
  ``y_N`` the outputs of the nonlinear subsystems, the linear outputs satisfy
  ``y_L = C_L x_L + D_L (K_LL y_L + K_LN y_N + E_L w)``, so

  .. math::

      y_L = M^{-1}\\big(C_L x_L + D_L K_{LN}\\, y_N + D_L E_L\\, w\\big),
      \\qquad M = I - D_L K_{LL},

  and every subsystem input is then an affine map of ``x_L``, ``y_N`` and
  ``w``; the linear states' derivative is ``A_L x_L + B_L u_L``, one matrix
  product per term.
* **Nonlinear subsystems** are evaluated once each, in an order in which
  every input they need through the (eliminated) linear part is already
  known: their update and output functions are called directly, with the
  parameters python-control gives them (``sys._update_params``).

The result equals python-control's ``_rhs``/``_out`` to rounding (the same
sums in another order).

When every state is a linear subsystem's and the nonlinear subsystems are
static (a car and a static controller), a whole Runge–Kutta step is linear
in the state and in the controller's stage values: `FusedSteps` composes the
tableau with the linear part once, and the stage loop for such plants
(`qc_control.numerics.stepper.affine_rk_steps`) takes each step as one
matrix product plus the controller's calls (its fused stage), with the input's
terms of all steps computed at once, and keeps the controller's value at
each sample for the outputs. When ``M`` is singular, or the nonlinear subsystems
feed each other (or themselves) through a direct path, there is an
algebraic loop that python-control resolves (or refuses) by iteration:
`compile_interconnect` returns None and the caller uses ``sys._rhs``.
"""

from __future__ import annotations

from collections.abc import Callable

import control
import numpy as np

from .. import compat
from .sampled import linear_input
from .stepper import affine_rk_steps, sample_steps

__all__ = ["CompiledInterconnect", "FusedSteps", "compile_interconnect"]


def _is_linear(sub) -> bool:
    return isinstance(sub, control.StateSpace)


class CompiledInterconnect:
    """An interconnection solved once: see the module docstring.

    Built by `compile_interconnect`. ``rhs(t, x, w)`` and ``out(t, x, w)``
    equal the system's ``_rhs`` and ``_out`` to rounding; ``rhs_terms(W)``
    precomputes the input terms for many input values at once.
    """

    def __init__(self, sys, lin, nonlin, order, mats):
        self.sys = sys
        self.nstates = sys.nstates
        self._lin_x = lin  # indices of the linear subsystems' states in x
        self._nonlin = nonlin  # per nonlinear subsystem: (sub, x slice, u rows)
        self._order = order
        (
            self._Px,
            self._Pn,
            self._Pw,
            self._Fx,
            self._Fn,
            self._Fw,
            self._Ox,
            self._On,
            self._Ow,
        ) = mats
        self._lin_contiguous = lin.size == 0 or np.array_equal(lin, np.arange(lin.size))
        self._all_linear_states = lin.size == self.nstates

    # The stage-by-stage functions are written for few Python-level calls:
    # one matrix product per term, the subsystems' own functions called directly.

    def _nonlinear_outputs(self, t, x, xl, uw_terms):
        """``(y_N pieces, u_N pieces)`` of the nonlinear subsystems, in evaluation order."""
        ys: list = [None] * len(self._nonlin)
        us: list = [None] * len(self._nonlin)
        for j in self._order:
            sub, xs, _ = self._nonlin[j]
            u = self._Px[j] @ xl + uw_terms[j]
            for i, Pn in self._Pn[j]:
                u = u + Pn @ ys[i]
            us[j] = u
            y = compat.output_function(sub)(t, x[xs], u)
            ys[j] = y
        return ys, us

    def rhs_terms(self, W: np.ndarray):
        """The external input's terms for input values ``W`` (``(nw, K)``), stacked over K."""
        uw = [Pw @ W for Pw in self._Pw]
        fw = self._Fw @ W
        return uw, fw

    def rhs(self, t: float, x: np.ndarray, w: np.ndarray) -> np.ndarray:
        """``dx/dt`` at ``(t, x)`` with external input ``w``."""
        return self._rhs(t, x, [Pw @ w for Pw in self._Pw], self._Fw @ w)

    def _rhs(self, t, x, uw_terms, fw_term):
        xl = x if self._all_linear_states else x[self._lin_x]
        ys, us = self._nonlinear_outputs(t, x, xl, uw_terms)
        dl = self._Fx @ xl + fw_term
        for Fn, y in zip(self._Fn, ys):
            dl = dl + Fn @ y
        if self._all_linear_states:
            return dl
        xdot = np.empty(self.nstates)
        xdot[self._lin_x] = dl
        for (sub, xs, _), u in zip(self._nonlin, us):
            if sub.nstates:
                xdot[xs] = compat.state_derivative(sub)(t, x[xs], u)
        return xdot

    def out(self, t: float, x: np.ndarray, w: np.ndarray) -> np.ndarray:
        """The interconnection's outputs at ``(t, x)`` with external input ``w``."""
        xl = x if self._all_linear_states else x[self._lin_x]
        ys, _ = self._nonlinear_outputs(t, x, xl, [Pw @ w for Pw in self._Pw])
        y = self._Ox @ xl + self._Ow @ w
        for On, yn in zip(self._On, ys):
            y = y + On @ yn
        return y

    def outputs(self, times: np.ndarray, X: np.ndarray, W: np.ndarray) -> np.ndarray:
        """The outputs at many samples at once: ``(ny, K)`` from ``X (n, K)``, ``W (nw, K)``.

        The linear terms are matrix products over all samples; only the
        nonlinear subsystems' output functions are called sample by sample.
        """
        XL = X[self._lin_x]
        ts = np.asarray(times, dtype=float).tolist()
        Ys: list = [None] * len(self._nonlin)
        for j in self._order:
            sub, xs, _ = self._nonlin[j]
            U = self._Px[j] @ XL + self._Pw[j] @ W
            for i, Pn in self._Pn[j]:
                U = U + Pn @ Ys[i]
            Xj = X[xs]
            out = compat.output_function(sub)
            Ys[j] = (
                np.array([out(t, Xj[:, k], U[:, k]) for k, t in enumerate(ts)], dtype=float)
                .reshape(len(ts), -1)
                .T
            )
        Y = self._Ox @ XL + self._Ow @ W
        for On, Yn in zip(self._On, Ys):
            Y = Y + On @ Yn
        return Y

    def make_rhs(self, u_of_t: Callable, inputs=None, times: np.ndarray | None = None):
        """``f(t, x)`` for the stepper, the input ``u_of_t(t)`` read at each stage.

        With ``inputs = (T, U)`` (the samples ``u_of_t`` interpolates
        linearly) and ``times`` (every stage time the stepper will ask for,
        `qc_control.numerics.integrate.stage_times`), the input's terms are
        computed for all stages at once (`qc_control.numerics.sampled.linear_input`),
        and a stage at one of those times looks them up; any other time (an event's root finding)
        computes them from ``u_of_t``.
        """
        rhs_ = self._rhs
        Pw_list, Fw = self._Pw, self._Fw
        nn = len(Pw_list)

        def direct(t, x):
            w = u_of_t(t)
            return rhs_(t, x, [Pw @ w for Pw in Pw_list], Fw @ w)

        if times is None or inputs is None or np.size(times) == 0:
            return direct
        T, U = inputs
        flat = np.asarray(times, dtype=float).reshape(-1)
        W = linear_input(T, U).at(flat).T  # (k, K): every stage's input
        uw, fw = self.rhs_terms(W)
        index = dict(zip(flat.tolist(), range(flat.size)))
        fw_rows = list(fw.T)
        if (
            self._all_linear_states
            and nn == 1
            and not self._Pn[0]
            and not self._nonlin[0][0].nstates
        ):
            # the common case (a plant and one static controller): no lists, no loops
            (sub, _, _), Px, Fn = self._nonlin[0], self._Px[0], self._Fn[0]
            uw_rows = list(uw[0].T)
            Fx, empty = self._Fx, np.empty(0)
            get, asarray = index.get, np.asarray
            if sub.outfcn is None:  # the output is the (empty) state: nothing to feed back
                return f_plain(Fx, fw_rows, get, direct)
            outfcn, params = sub.outfcn, compat.current_params(sub)
            n = Fx.shape[0]
            G = np.vstack([Fx, Px])  # one product gives both x's derivative part and u
            # ... and one sum adds the input's terms to both: [Fw w; Pw w] per stage
            pre = list(np.vstack([fw, uw[0]]).T)
            if sub.noutputs == 1:
                column = Fn[:, 0].copy()
                sequence = (list, tuple, np.ndarray)

                def one(t, x):
                    try:
                        z = G @ x + pre[index[t]]
                    except KeyError:
                        return direct(t, x)
                    r = outfcn(t, empty, z[n:], params)
                    return z[:n] + column * (r[0] if isinstance(r, sequence) else r)

            else:

                def one(t, x):
                    k = get(t)
                    if k is None:
                        return direct(t, x)
                    z = G @ x
                    y = asarray(outfcn(t, empty, z[n:] + uw_rows[k], params), dtype=float)
                    return z[:n] + Fn @ y.reshape(-1) + fw_rows[k]

            return one
        rows = [list(u.T) for u in uw]

        def f(t, x):
            k = index.get(t)
            if k is None:
                return direct(t, x)
            return rhs_(t, x, [rows[j][k] for j in range(nn)], fw_rows[k])

        return f

    def fused(self, tab, h: float, stages: np.ndarray, inputs, substeps: int = 1):
        """Whole steps of ``tab`` at the step ``h`` (`FusedSteps`), or None where not applicable.

        Applies when every state belongs to a linear subsystem and every
        nonlinear subsystem is static with an output function (a plant and
        a static controller); ``stages`` are the stage times of every step
        (`qc_control.numerics.integrate.stage_times` on a uniform grid, ``substeps``
        steps ``h`` per interval), ``inputs = (T, U)`` the samples the
        input interpolates.
        """
        if not self._all_linear_states or any(sub.outfcn is None for sub, _, _ in self._nonlin):
            return None
        return FusedSteps(self, tab, h, stages, inputs, substeps)

    def outputs_known(self, X: np.ndarray, W: np.ndarray, YN: np.ndarray) -> np.ndarray:
        """`outputs` with the nonlinear subsystems' outputs ``YN`` (stacked, ``(p, K)``) known."""
        XL = X[self._lin_x]
        Y = self._Ox @ XL + self._Ow @ W
        start = 0
        for On in self._On:
            # only the nonlinear outputs that reach an output: an overflowed one that
            # does not (an inf times a zero column) must not turn the outputs into NaN
            used = np.flatnonzero(np.any(On != 0, axis=0))
            if used.size:
                Y = Y + On[:, used] @ YN[start + used]
            start += On.shape[1]
        return Y


class FusedSteps:
    r"""Whole Runge–Kutta steps of a linear plant closed by static nonlinear subsystems.

    With every state linear and the nonlinear subsystems static, the
    interconnection is ``x' = F x + g(t) + N y``, where ``y = φ(t, P x + q(t))``
    stacks the nonlinear subsystems' outputs (``F``, ``N``, ``P`` from
    `compile_interconnect`; ``g``, ``q`` the external input's terms). An
    explicit Runge–Kutta step is then linear in ``x`` and in the stage
    values ``y_l = φ(t + c_l h, z_l)``: by induction over the stages
    (``X_l = x + h \sum_{j<l} a_{lj} k_j``, ``k_l = F X_l + g_l + N y_l``),

    .. math::

        X_l = A_l x + \gamma_l + \sum_{r<l} B_{lr}\, y_r, \qquad
        A_l = I + h \sum_{j<l} a_{lj} F A_j, \quad
        B_{lr} = h\, a_{lr} N + h \sum_{r<j<l} a_{lj} F B_{jr},

    with ``γ_l`` the same recursion on the input terms, and the step's end
    ``x + h \sum_l b_l k_l = Φ x + γ + \sum_r W_r y_r`` the same with ``b``
    for ``a``. So each step is one matrix product giving ``P A_l x`` (every
    stage) and ``Φ x`` together; then, stage by stage, ``φ`` is called and
    its value ``y_r`` added through one column block (``P B_{lr}`` for the
    later stages' inputs, ``W_r`` for the end). The input's terms of every
    step (``P γ_l + q_l`` and ``γ``) are computed for the whole run at
    once, with the same interpolation as `CompiledInterconnect.make_rhs`.
    The stepped values equal the stage-by-stage step's to rounding (the
    same sums in another order: 2.4e-14 of the largest state over 10 s of
    car and clipped skyhook).

    Built by `CompiledInterconnect.fused`; ``stepper()`` is what
    `qc_control.numerics.integrate.integrate_stepper` runs.

    The first stage is at ``(t_k, x_k)`` itself, so its ``y`` is the
    nonlinear subsystems' output at the sample: it is kept (``yn``) and the
    run's outputs need no second evaluation of ``φ``.
    """

    def __init__(self, compiled: CompiledInterconnect, tab, h, stages, inputs, substeps=1):
        nonlin = compiled._nonlin
        Px, Pw, Pn = compiled._Px, compiled._Pw, compiled._Pn
        F, Fw = compiled._Fx, compiled._Fw
        N = np.hstack(compiled._Fn)
        P = np.vstack(Px)
        n, p, m = F.shape[0], N.shape[1], P.shape[0]
        a, b = np.asarray(tab.a, dtype=float), np.asarray(tab.b, dtype=float)
        s = b.size
        eye = np.eye(n)
        A = [eye]
        B: list[list[np.ndarray]] = [[]]
        rows = [*a[1:], b]
        for i, coef in enumerate(rows, start=1):
            Ai = eye.copy()
            Bi = [np.zeros((n, p)) for _ in range(i)]
            for j in range(i):
                if coef[j] == 0:
                    continue
                Ai = Ai + h * coef[j] * (F @ A[j])
                Bi[j] = Bi[j] + h * coef[j] * N
                for r in range(j):
                    Bi[r] = Bi[r] + h * coef[j] * (F @ B[j][r])
            A.append(Ai)
            B.append(Bi)
        # the input's terms at every stage of every step: gamma_l (n, K) and q_l (m, K)
        T, U = inputs
        K = stages.shape[0]
        u_of_t = linear_input(T, U)
        Wst = [u_of_t.at(stages[:, l]).T for l in range(s)]  # (k, K) per stage
        gam = [np.zeros((n, K))]
        for i, coef in enumerate(rows, start=1):
            gi = np.zeros((n, K))
            for j in range(i):
                if coef[j] != 0:
                    gi = gi + h * coef[j] * (F @ gam[j] + Fw @ Wst[j])
            gam.append(gi)
        Pw_all = np.vstack(Pw)
        pre = np.vstack([P @ gam[l] + Pw_all @ Wst[l] for l in range(s)] + [gam[s]])
        self._G = np.vstack([P @ A[l] for l in range(s)] + [A[s]])
        self._Pw_all = Pw_all
        self._pre = list(np.ascontiguousarray(pre.T))
        # y_r's contribution to every later stage's input and to the step's end, as one
        # full-length column block (zeros for the stages up to r): z += C_r y_r, no slicing
        self._C = [
            np.vstack(
                [np.zeros(((r + 1) * m, p))] + [P @ B[l][r] for l in range(r + 1, s)] + [B[s][r]]
            )
            for r in range(s)
        ]
        self._times = stages.tolist()
        self._n, self._m, self._p, self._s = n, m, p, s
        self._substeps = substeps
        self.yn = np.empty((K, p))  # phi at each step's first stage: the outputs at the samples
        # phi: the nonlinear subsystems in their order, the later ones fed by the earlier
        widths_u = [P_.shape[0] for P_ in Px]
        u_start = np.cumsum([0] + widths_u)
        widths_y = [Fn.shape[1] for Fn in compiled._Fn]
        y_start = np.cumsum([0] + widths_y)
        order = compiled._order
        empty = np.empty(0)

        def phi(t, z, y):
            for j in order:
                u = z[u_start[j] : u_start[j + 1]]
                for i, Pn_ji in Pn[j]:
                    u = u + Pn_ji @ y[y_start[i] : y_start[i + 1]]
                sub = nonlin[j][0]
                y[y_start[j] : y_start[j + 1]] = np.asarray(
                    sub.outfcn(t, empty, u, compat.current_params(sub))
                ).reshape(-1)

        self._phi = phi
        self._single = len(nonlin) == 1
        self._sub = nonlin[0][0]
        self.compiled = compiled

    def stepper(self):
        """``run(x, out, start, stop)`` for `qc_control.numerics.integrate.integrate_stepper`.

        The steps are `qc_control.numerics.stepper.affine_rk_steps` with this
        interconnection's fused stage (`_stage`), the value at each step's
        first stage kept in ``yn``; ``substeps`` steps per interval of the
        grid, every ``substeps``-th kept
        (`qc_control.numerics.stepper.sample_steps`), as `integrate` takes them.
        """
        stage, yn = self._stage(), self._yn_rows()
        G, pre, C, times, m, ns = self._G, self._pre, self._C, self._times, self._m, self._substeps
        if self._single and self._p == 1:
            C = [c[:, 0].copy() for c in C]  # one output: columns scaled by a number

        def run(x, out, start, stop):
            q0, q1 = start * ns, stop * ns

            def advance(x, buf):
                return affine_rk_steps(stage, G, pre, C, times, x, buf, yn, q0, q0, q1, m)

            return sample_steps(advance, x, out[start:], stop - start, ns)

        return run

    def _stage(self):
        """``stage(t, z)``: the nonlinear subsystems' outputs at a stage with input ``z``."""
        if self._single and self._p == 1:
            # the common case (one static controller, one output): a number, no y vector
            sub = self._sub
            outfcn, params, empty = sub.outfcn, compat.current_params(sub), np.empty(0)

            def one(t, z):
                r = outfcn(t, empty, z, params)
                return r[0] if type(r) is list and len(r) == 1 else _scalar(r)

            return one
        phi, y = self._phi, np.empty(self._p)

        def stage(t, z):
            phi(t, z, y)
            return y

        return stage

    def nonlinear_outputs(self, index: np.ndarray, t_out, X: np.ndarray, W: np.ndarray):
        """The nonlinear subsystems' outputs ``(p, K)`` at grid samples ``index``.

        Those kept from a step's first stage (every sample a step started
        from); the others (the grid's last point) are evaluated here from
        the state ``X`` and input ``W`` at ``t_out``.
        """
        index = np.asarray(index, dtype=int) * self._substeps  # the step starting there
        steps = self.yn.shape[0]
        YN = np.empty((self._p, index.size))
        kept = index < steps
        YN[:, kept] = self.yn[index[kept]].T
        P = self._G[: self._m]  # P A_1 = P
        Pw = self._Pw_all
        y = np.empty(self._p)
        for c in np.flatnonzero(~kept).tolist():
            self._phi(float(t_out[c]), P @ X[:, c] + Pw @ W[:, c], y)
            YN[:, c] = y
        return YN

    def _yn_rows(self):
        return self.yn[:, 0] if self._single and self._p == 1 else self.yn


def _scalar(r):
    """A one-output function's value as a number (control's ``asarray(r).reshape(-1)``)."""
    if type(r) is np.ndarray and r.shape == (1,):  # np.array([f]): the usual return
        return r[0]
    if type(r) is float:
        return r
    flat = np.asarray(r, dtype=float).reshape(-1)
    if flat.size != 1:
        raise ValueError(f"the output function returned {flat.size} values; expected 1")
    return flat[0]


def f_plain(Fx, fw_rows, get, direct):
    """``Fx x + fw``: a static subsystem with no output function feeds nothing back."""

    def f(t, x):
        k = get(t)
        return direct(t, x) if k is None else Fx @ x + fw_rows[k]

    return f


def _indices(offsets, group) -> np.ndarray:
    """The positions of the subsystems ``group`` in a vector laid out by ``offsets``."""
    return np.concatenate(
        [np.arange(offsets[i], offsets[i + 1]) for i in group] or [np.empty(0, int)]
    ).astype(int)


def _block_diagonal(subs, lin, get, rows: int, cols: int) -> np.ndarray:
    """One of the linear subsystems' matrices (``get``: A, B, C or D), block-diagonal."""
    out = np.zeros((rows, cols))
    r = c = 0
    for i in lin:
        m = np.atleast_2d(np.asarray(get(subs[i]), dtype=float))
        out[r : r + m.shape[0], c : c + m.shape[1]] = m
        r, c = r + m.shape[0], c + m.shape[1]
    return out


def _eliminate_linear_outputs(CL, DL, K, E, uL, yL, yN_all):
    """``(Gx, Gn, Gw)`` with ``y_L = Gx x_L + Gn y_N + Gw w`` (module docstring),
    or None when ``M = I - D_L K_LL`` is singular: an algebraic loop."""
    M = np.eye(yL.size) - DL @ K[np.ix_(uL, yL)]
    if yL.size and np.linalg.cond(M) > 1e12:
        return None
    Minv = np.linalg.inv(M) if yL.size else np.zeros((0, 0))
    return Minv @ CL, Minv @ DL @ K[np.ix_(uL, yN_all)], Minv @ DL @ E[uL]


def _nonlinear_inputs(Ux, Un, Uw, uN, starts):
    """Each nonlinear subsystem's input as ``Px x_L + Σ_i Pn_i y_N,i + Pw w``:
    ``(Px, Pn, Pw)``, with ``Pn[j]`` the ``(i, block)`` of the outputs it reads."""
    Px, Pn, Pw = [], [], []
    nn = len(uN)
    for j in range(nn):
        rows = uN[j]
        Px.append(Ux[rows])
        Pw.append(Uw[rows])
        deps = []
        for i in range(nn):
            block = Un[np.ix_(rows, np.arange(starts[i], starts[i + 1]))]
            if np.any(block != 0):
                deps.append((i, block))
        Pn.append(deps)
    return Px, Pn, Pw


def _evaluation_order(Pn) -> list[int] | None:
    """An order of the nonlinear subsystems in which each one's inputs are known
    before it is called; None for a loop through direct feedthrough (control
    iterates there, and so does its ``_rhs``)."""
    needs = [{i for i, _ in deps} for deps in Pn]
    order: list[int] = []
    done: set[int] = set()
    while len(order) < len(needs):
        ready = [j for j in range(len(needs)) if j not in done and needs[j] <= done]
        if not ready:
            return None
        order.extend(ready)
        done.update(ready)
    return order


def compile_interconnect(sys) -> CompiledInterconnect | None:
    """``sys`` solved once (`CompiledInterconnect`), or None where that does not apply.

    None for anything but a continuous-time `control.InterconnectedSystem`
    that is not itself linear (a linear one is a `control.StateSpace`,
    stepped as such), and for an algebraic loop (see the module docstring).
    Call ``sys._update_params(params)`` before using the result, as for
    ``sys._rhs``: the subsystems' functions read their current parameters.
    """
    if not isinstance(sys, control.InterconnectedSystem) or isinstance(sys, control.StateSpace):
        return None
    if control.isdtime(sys, strict=True):
        return None
    subs, K, E, O = compat.interconnection_maps(sys)
    x_off = np.cumsum([0] + [s.nstates for s in subs])
    u_off = np.cumsum([0] + [s.ninputs for s in subs])
    y_off = np.cumsum([0] + [s.noutputs for s in subs])
    lin = [i for i, s in enumerate(subs) if _is_linear(s)]
    non = [i for i, s in enumerate(subs) if not _is_linear(s)]
    xL, uL, yL = _indices(x_off, lin), _indices(u_off, lin), _indices(y_off, lin)
    AL, BL, CL, DL = (
        _block_diagonal(subs, lin, lambda s, k=k: getattr(s, k), rows, cols)
        for k, rows, cols in (
            ("A", xL.size, xL.size),
            ("B", xL.size, uL.size),
            ("C", yL.size, xL.size),
            ("D", yL.size, uL.size),
        )
    )
    yN = [np.arange(y_off[i], y_off[i + 1]) for i in non]
    uN = [np.arange(u_off[i], u_off[i + 1]) for i in non]
    yN_all = np.concatenate(yN) if yN else np.empty(0, int)
    G = _eliminate_linear_outputs(CL, DL, K, E, uL, yL, yN_all)
    if G is None:
        return None
    Gx, Gn, Gw = G
    # every subsystem input as  Ux x_L + Un y_N + Uw w
    Ux = K[:, yL] @ Gx
    Un = K[:, yL] @ Gn + K[:, yN_all]
    Uw = K[:, yL] @ Gw + E
    # the nonlinear subsystems' inputs, and the order that resolves them
    starts = np.cumsum([0] + [len(y) for y in yN])
    Px, Pn, Pw = _nonlinear_inputs(Ux, Un, Uw, uN, starts)
    order = _evaluation_order(Pn)
    if order is None:
        return None
    spans = [np.arange(starts[i], starts[i + 1]) for i in range(len(non))]
    Fx = AL + BL @ Ux[uL]
    Fn = [BL @ Un[np.ix_(uL, span)] for span in spans]
    Fw = BL @ Uw[uL]
    # the outputs read subsystem outputs (O's first columns) and may read subsystem inputs
    Ou = O[:, y_off[-1] :]
    Ox = O[:, yL] @ Gx + Ou @ Ux
    On = [O[:, yL] @ Gn[:, span] + O[:, yN[i]] + Ou @ Un[:, span] for i, span in enumerate(spans)]
    Ow = O[:, yL] @ Gw + Ou @ Uw
    nonlin = [(subs[i], slice(x_off[i], x_off[i + 1]), uN[j]) for j, i in enumerate(non)]
    return CompiledInterconnect(sys, xL, nonlin, order, (Px, Pn, Pw, Fx, Fn, Fw, Ox, On, Ow))
