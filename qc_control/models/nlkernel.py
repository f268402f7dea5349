"""The nonlinear quarter car's right-hand side over batches of designs, compiled (numba).

`qc_control.studies.nlsweep` steps many designs of `qc_control.nonlinear_quarter_car`
together. Written with NumPy over the designs, each stage of each step is a
dozen NumPy calls on arrays of a thousand numbers, and the calls' fixed cost
(about a microsecond each), not the arithmetic, sets the time. This
module writes the right-hand side as a loop over the designs
(`_accelerations`) and hands it to the compiled stage loop of the numerics
(`qc_control.numerics.compiled_stepper.stage_loop`), compiled together with
numba (LLVM), so that a step costs its arithmetic: the loops over the
designs are simple enough for the compiler to vectorise. `advance` is
that binding; the stage loop itself is the numerics', as for every
compiled right-hand side.

The right-hand side is `NonlinearQuarterCarBatch`'s (the module docstring of
`qc_control.models.nonlinear` has the equations) with the same folded constants:
``-F/m_s`` as ``F·(-1/m_s)``, the tire's dynamic force ``F_t - k_u δ0`` as
``max(k_u (z_r - x_u), -k_u δ0)`` for a unilateral tire, the stops'
``F = q (k + k3 q²)`` with ``q = d - clip(d, -c_b, c_r)``, which is exactly
0 between the clearances. The sums are the NumPy path's, some in another
order: a design's trajectory equals it, and
`qc_control.input_output_response`'s, to rounding (the tests hold it to
1e-13 and 1e-12 of the largest state).

What has no compiled form: a callable spring, damper or road profile (user
Python code), and event location (a Python call per event); the NumPy path
takes those (`NonlinearQuarterCarBatch.compiled_stepper` returns None).

numba is imported with this module (through `qc_control.numerics.recurrence`), which
takes about half a second, so `qc_control.models.nonlinear` imports it only when a
batch is first stepped. The compiled code is cached on disk
(`qc_control.numerics.recurrence.compiled`: beside this file, or in a per-user cache
where the package is read-only), so the one-off compilation (about three
seconds) is paid once per installation.
"""

from __future__ import annotations

from ..numerics.compiled_stepper import stage_loop
from ..numerics.recurrence import compiled

__all__ = ["advance", "PARAMETER_ROWS", "OPTION_SLOTS"]

#: Rows of the per-design parameter array ``p`` ``(7, m)``, in this order. The
#: tire floor is the least dynamic tire force ``F_t - k_u δ0``: ``-k_u δ0`` for a
#: unilateral tire, -inf for a linear one; the damper's low-speed coefficients in
#: rebound and in bound are each design's ``cs`` for a linear damper, the
#: `PiecewiseDamper`'s otherwise.
PARAMETER_ROWS = ("neg_inv_ms", "inv_mu", "ks", "ku", "tire_floor", "c_rebound", "c_bound")
#: Slots of the options array ``o``: every option as a number, each chosen so
#: that an element that is off adds exactly 0 (no branch in the loops).
OPTION_SLOTS = (
    "k3",  # the cubic spring coefficient [N/m³] (0: linear)
    "stop_bound",  # c_b [m] (inf: none)
    "stop_rebound",  # c_r [m] (inf: none)
    "stop_k",  # k [N/m]
    "stop_k3",  # k3 [N/m³]
    "knee_rebound",  # the damper's knees [m/s] (inf: none) and high-speed coefficients
    "knee_bound",
    "rebound_high",
    "bound_high",
    "road",  # the road input's row in u (-1: none, zr = 0)
    "actuator",  # the actuator force's row in u (-1: none)
)


@compiled(inline="always")
def _accelerations(x, u, p, o, out):  # pragma: no cover - compiled (tested through advance)
    """``out[:2] = (v̇s, v̇u)`` and ``out[2:] = (vs, vu)`` of every design at ``x`` ``(4, m)``.

    Branch-free over the designs (selects, and terms that are exactly 0 when
    an element is off), so that the compiler vectorises the loop.
    """
    m = x.shape[1]
    k3, cb, cr, kb, kb3 = o[0], o[1], o[2], o[3], o[4]
    knee_r, knee_b, c_reb_hi, c_bnd_hi = o[5], o[6], o[7], o[8]
    iz, ia = int(o[9]), int(o[10])
    zr = u[iz] if iz >= 0 else 0.0
    fa = u[ia] if ia >= 0 else 0.0
    # one row at a time (1-D views: unit strides the compiler can vectorise)
    x0, x1, x2, x3 = x[0], x[1], x[2], x[3]
    neg_inv_ms, inv_mu, ks, ku, floor, c_rebound, c_bound = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    out0, out1, out2, out3 = out[0], out[1], out[2], out[3]
    for j in range(m):
        vs, vu, xs, xu = x0[j], x1[j], x2[j], x3[j]
        v = vs - vu
        d = xs - xu
        fs = ks[j] * d + k3 * (d * d * d)
        c_reb, c_bnd = c_rebound[j], c_bound[j]
        fd = c_reb * v if v >= 0.0 else c_bnd * v
        fd = c_reb * knee_r + c_reb_hi * (v - knee_r) if v > knee_r else fd
        fd = -c_bnd * knee_b + c_bnd_hi * (v + knee_b) if v < -knee_b else fd
        # the stops: q = d - clip(d, -c_b, c_r), exactly 0 between the clearances
        clip = d if d > -cb else -cb
        clip = clip if clip < cr else cr
        q = d - clip
        f = (fd + fs) + q * (kb + kb3 * (q * q)) - fa
        tire = (zr - xu) * ku[j]  # F_t - k_u δ0
        tire = floor[j] if tire < floor[j] else tire  # (a NaN stays NaN, as np.maximum)
        out0[j] = f * neg_inv_ms[j]
        out1[j] = (f + tire) * inv_mu[j]
        out2[j] = vs
        out3[j] = vu


@compiled()
def advance(x, out, first, count, step, substeps, a, b, stage_u, p, o):  # pragma: no cover
    """Step the designs ``x`` ``(4, m)`` (in place) over ``count`` samples: the
    compiled stage loop (`qc_control.numerics.compiled_stepper.stage_loop`, whose
    docstring has the arguments) on `_accelerations`, with ``p`` the designs'
    parameters (`PARAMETER_ROWS`) and ``o`` the options (`OPTION_SLOTS`)."""
    stage_loop(_accelerations, x, out, first, count, step, substeps, a, b, stage_u, p, o)
