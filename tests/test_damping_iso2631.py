"""ISO 2631-1's exact stationary metrics as objectives of optimal_damping and pareto_front.

References, each computed here apart from the study:

* ``a_w_z`` of one design from `spectral_axis_rms` (the car in series with
  Annex A's Wk, one Lyapunov solve, itself held to a long simulation in
  tests/test_assessment_spectral.py), minimised over ζ by a dense scan and
  scipy's Brent search started from the scan's best bracket: an independent
  search on the single-design value, not the study's bounded search on its
  batched objective.
* the same optimum through the older Wk filter (`rms_body_acc_wk`, the
  `qc_control.ride.iso2631.wk_filter` realisation): two state-space
  realisations of one weighting, so one optimum.
* the road-holding variance of Gobbi & Mastinu (2001), written out here.
* a half and a full car's a_w_z, a_w_ry, a_w_rx per design from
  `spectral_axis_rms` of the car built here, and a_v from ISO 2631-1:1997
  §6.5 with the seated factors of §8.2 written out (k_z = 1, k_ry = 0.4
  m/rad, k_rx = 0.63 m/rad).
"""

import math

import numpy as np
import pytest
import scipy.optimize

import qc_control as qc
from qc_control.models.vehicle import STANDARD_GRAVITY
from qc_control.ride.iso2631_spectral import spectral_axis_rms
from qc_control.studies.damping import OBJECTIVES

SEED = qc.QuarterCarParams()
C20 = qc.road.ISO8608Road("C", speed=20.0)
Q = C20.intensity
CRITICAL = 2 * math.sqrt(SEED.ks * SEED.ms)  # cs of ζ = 1 [N·s/m]
AWZ = "a_w_z [m/s²]"


def with_cs(cs, ks=SEED.ks):
    return qc.QuarterCarParams(ms=SEED.ms, mu=SEED.mu, ks=ks, ku=SEED.ku, cs=cs)


def a_w_z(cs, ks=SEED.ks):
    """The single design's exact Wk-weighted RMS vertical acceleration [m/s²]."""
    return spectral_axis_rms(qc.quarter_car_model(with_cs(cs, ks), road=True), Q)["z"]


def road_holding_variance(cs):
    """σ² of the dynamic tire load over the static load (Gobbi & Mastinu 2001), at Q."""
    ms, mu, ks, kt = SEED.ms, SEED.mu, SEED.ks, SEED.ku
    M = ms + mu
    tire = (cs**2 * kt * M**2 + ks**2 * M**3 - 2 * ks * kt * ms * mu * M + kt**2 * ms**2 * mu) / (
        2 * cs * kt**2 * ms**2
    )
    return Q * tire * (kt / (M * STANDARD_GRAVITY)) ** 2


@pytest.fixture(scope="module")
def reference_optimum():
    """ζ scanned at 400 points from 0.05 to 4, then Brent's method on the best bracket."""
    zeta = np.geomspace(0.05, 4.0, 400)
    values = np.array([a_w_z(z * CRITICAL) for z in zeta])
    i = int(np.argmin(values))
    assert 0 < i < len(zeta) - 1  # an interior minimum: the bracket below holds
    res = scipy.optimize.minimize_scalar(
        lambda log_z: a_w_z(math.exp(log_z) * CRITICAL) ** 2,
        bracket=(math.log(zeta[i - 1]), math.log(zeta[i]), math.log(zeta[i + 1])),
        method="brent",
        tol=1e-10,
    )
    return math.exp(res.x) * CRITICAL, values.min()


def test_the_a_w_z_optimum_agrees_with_an_independent_search(reference_optimum):
    cs_ref, scan_min = reference_optimum
    opt = qc.optimal_damping(SEED, "a_w_z", road=C20)
    assert opt.method == "scipy.optimize"  # a weighting filter: no closed form
    # a_w_z² is flat at its minimum (quadratic in log cs): both searches locate it to
    # about √eps ≈ 1.5e-8 in log cs, stretched by the curvature; 1e-5 relative is
    # three orders above that and far below the 0.25 % spacing of the scan
    assert opt.cs == pytest.approx(cs_ref, rel=1e-5)
    # the objective is a_w_z squared, and its minimum is the scan's best or below it
    # (the scan's points are designs too; 1e-12 relative: rounding of one solve)
    assert opt.value == pytest.approx(a_w_z(opt.cs) ** 2, rel=1e-12)
    assert opt.value <= scan_min**2 * (1 + 1e-12)
    assert opt.metrics[AWZ] == pytest.approx(a_w_z(opt.cs), rel=1e-12)


def test_the_a_w_z_optimum_is_the_wk_comfort_optimum():
    """Annex A's Wk through `qc.weighting` and through the older `wk_filter`: one
    weighting, so one optimum; 1e-6 relative covers the two searches' resolution
    (√eps in log cs) and the two realisations' rounding."""
    iso = qc.optimal_damping(SEED, "a_w_z", road=C20)
    older = qc.optimal_damping(SEED, "comfort_wk", road=C20)
    assert iso.cs == pytest.approx(older.cs, rel=1e-6)
    assert iso.metrics[AWZ] == pytest.approx(older.metrics["rms_body_acc_wk [m/s²]"], rel=1e-6)


def non_dominated(pts):
    """Indices of the rows of ``pts`` no other row beats in every column (brute force)."""

    def dominated(v):
        return np.any(np.all(pts <= v, axis=1) & np.any(pts < v, axis=1))

    return {i for i, v in enumerate(pts) if not dominated(v)}


def test_a_v_of_a_quarter_car_is_its_vertical():
    """ISO 2631-1 §6.5 with k_z = 1 (§8.2) and no rotation: a_v = a_w_z exactly."""
    opt = qc.optimal_damping(SEED, "a_v", road=C20)
    assert opt.metrics["a_v [m/s²]"] == pytest.approx(a_w_z(opt.cs), rel=1e-12)


def test_an_iso_metric_weighs_in_as_its_square():
    weights = {"a_w_z": 1.0, "road_holding": 10.0}
    opt = qc.optimal_damping(SEED, weights, road=C20)

    def objective(cs):
        return a_w_z(cs) ** 2 + 10.0 * road_holding_variance(cs)

    # the reported value is the weighted sum of variances at the optimum (1e-10: the
    # closed form against the Lyapunov solve of one 4-state car)
    assert opt.value == pytest.approx(objective(opt.cs), rel=1e-10)
    # and it is a minimum: 1 % either side is worse
    assert objective(opt.cs) < min(objective(0.99 * opt.cs), objective(1.01 * opt.cs))


def test_the_a_w_z_front_is_non_dominated_and_exact_per_design():
    vary = {"cs": list(np.geomspace(0.1, 3.0, 12) * CRITICAL), "ks": [2e4, 3e4, 6e4]}
    pf = qc.pareto_front(SEED, vary, ("a_w_z", "road_holding"), road=C20)
    allp = pf.all_designs
    # every design's a_w_z is the single-design Lyapunov value (1e-9 relative: the same
    # equation solved for the batch and for one design differs by rounding only)
    for _, row in allp.iterrows():
        assert row[AWZ] == pytest.approx(a_w_z(row["cs"], row["ks"]), rel=1e-9)
    expected = non_dominated(allp[[AWZ, "rms_tire_load / static [-]"]].to_numpy())
    assert set(np.flatnonzero(allp["pareto"])) == expected and len(pf.designs) == len(expected)
    assert AWZ in pf.markers.columns
    assert "ISO 2631-1" in pf.figure.axes[0].get_xlabel()


@pytest.mark.parametrize(
    "call, name, words",
    [
        (lambda: qc.optimal_damping(SEED, "a_w_q"), "objective", ["'a_w_z'", "'a_v'"]),
        (
            lambda: qc.optimal_damping(SEED, {"a_w_z": 1.0, "a_w_q": 1.0}),
            "objective['a_w_q']",
            ["'a_w_z'"],
        ),
        (lambda: qc.optimal_damping(SEED, "a_w_ry"), "objective", ["pitches", "HalfCarParams"]),
        (lambda: qc.pareto_front(SEED, objectives=("a_w_z", "a_w_q")), "objectives", ["'a_v'"]),
        (lambda: qc.pareto_front(SEED, objectives=("a_w_z", "a_w_rx")), "objectives", ["rolls"]),
        (
            lambda: qc.pareto_front(qc.HalfCarParams(), {"cs_front": [1e3]}, ("a_w_z", "a_w_rx")),
            "objectives",
            ["rolls", "'a_w_rx'"],
        ),
        (lambda: qc.pareto_front(qc.HalfCarParams()), "vary", ["cs_front", "HalfCarParams"]),
    ],
)
def test_a_bad_objective_is_refused_naming_the_argument_and_the_choices(call, name, words):
    with pytest.raises(qc.ParameterError) as err:
        call()
    assert err.value.name == name
    for word in words:
        assert word in str(err.value)


def test_an_iso_objective_has_no_closed_form():
    with pytest.raises(ValueError, match="no closed form"):
        qc.optimal_damping(SEED, "a_w_z", solver="closed form")


ROTATIONS = {"a_w_ry [rad/s²]": ("ry", 0.4), "a_w_rx [rad/s²]": ("rx", 0.63)}


@pytest.mark.filterwarnings("ignore::qc_control.ride.spectral.IndependentTracksWarning")
@pytest.mark.parametrize(
    "params, objectives",
    [
        (qc.HalfCarParams(), ("a_w_z", "a_w_ry", "a_v")),
        (qc.FullCarParams(), ("a_w_rx", "a_w_ry", "a_v")),
    ],
)
def test_a_half_and_a_full_cars_front_in_pitch_and_roll(params, objectives):
    vary = {"cs_front": [500.0, 1290.0, 3000.0], "cs_rear": [600.0, 1620.0, 3500.0]}
    pf = qc.pareto_front(params, vary, objectives, road=C20)
    allp = pf.all_designs
    build = qc.half_car_model if isinstance(params, qc.HalfCarParams) else qc.full_car_model
    for _, row in allp.iterrows():
        design = type(params)(**{**params.to_dict(), "cs_front": row["cs_front"],
                                 "cs_rear": row["cs_rear"]})  # fmt: skip
        # on the road, the rear wheels a wheelbase behind the front ones
        axes = spectral_axis_rms(build(design, road=True), Q, speed=C20.speed)
        # 1e-9 relative: the batch's Lyapunov solve against one design's, rounding only
        total = axes["z"] ** 2
        for column, (axis, k) in ROTATIONS.items():
            if axis in axes:
                total += (k * axes[axis]) ** 2
                if column in allp:
                    assert row[column] == pytest.approx(axes[axis], rel=1e-9), column
        assert row["a_v [m/s²]"] == pytest.approx(math.sqrt(total), rel=1e-9)
        if "a_w_z [m/s²]" in allp:
            assert row["a_w_z [m/s²]"] == pytest.approx(axes["z"], rel=1e-9)
    cols = [OBJECTIVES[o][0] for o in objectives]
    assert set(np.flatnonzero(allp["pareto"])) == non_dominated(allp[cols].to_numpy())
    # the closed-form optima are the quarter car's: a half or full car marks only itself
    assert list(pf.markers.index) == ["passive (this car)"]
