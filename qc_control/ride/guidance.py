r"""What ISO 2631-1:1997 says of a number: axis rules, the comfort scale, health, sickness.

The standard's judgement, apart from the signal processing
(`qc_control.ride.assessment`), each rule beside its clause:

- per axis and posture, the weighting and the multiplying factors ``k``
  (§7.2 for health, §8.2 for comfort; `AXIS_RULES`);
- the crest-factor rule (§6.2) and the ratios that call for the additional
  methods (§6.3.3, eqs. 6 and 7);
- Annex C's comfort scale (`comfort_labels`), its bands overlapping as
  printed;
- Annex B's health guidance caution zone for a daily exposure
  (`health_guidance`), eq. (B.1) and the VDV zone of eq. (B.2);
- Annex D's illness rating from the motion sickness dose value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from ..numerics import checks

__all__ = [
    "AxisRule",
    "AXIS_RULES",
    "POSTURES",
    "COMFORT_SCALE",
    "comfort_labels",
    "HealthGuidance",
    "health_guidance",
    "CREST_FACTOR_LIMIT",
    "MTVV_RATIO_LIMIT",
    "VDV_RATIO_LIMIT",
    "ILLNESS_CONSTANT",
    "RUNNING_RMS_WINDOW",
]

#: §6.2: the basic (RMS) method is normally sufficient up to this crest factor.
CREST_FACTOR_LIMIT = 9.0
#: §6.3.3 eq. (6): MTVV / a_w above this calls for the additional methods.
MTVV_RATIO_LIMIT = 1.5
#: §6.3.3 eq. (7): VDV / (a_w T^¼) above this calls for the additional methods.
VDV_RATIO_LIMIT = 1.75
#: Annex D (D.2): percentage of a mixed population of unadapted adults who may
#: vomit per unit MSDV_z: ``K_m = 1/3`` [% per m/s^1.5].
ILLNESS_CONSTANT = 1.0 / 3.0
#: §6.3.1: the running RMS's integration time τ [s], "1 s recommended".
RUNNING_RMS_WINDOW = 1.0


class AxisRule(NamedTuple):
    """How one axis is weighted and combined (ISO 2631-1:1997).

    Attributes
    ----------
    weighting : str
        The Annex A weighting (`qc_control.weighting`).
    k_comfort : float
        Multiplying factor in the vibration total value for comfort
        [-] (translation) or [m/rad] (rotation).
    k_health : float or None
        Factor for health (§7.2.3), None where the standard gives no health
        assessment of the axis.
    clause : str
        Where the weighting and factors are stated.
    unit : str
        The acceleration's unit.
    """

    weighting: str
    k_comfort: float
    k_health: float | None
    clause: str
    unit: str


_FLOOR = "ISO 2631-1:1997 §8.2 (comfort, standing: the floor, k = 1)"
_SEAT = "ISO 2631-1:1997 §8.2 (comfort, seated: the seat surface, k = 1)"
_SEAT_ROT = "ISO 2631-1:1997 §8.2 (comfort, seat-surface rotations, We)"
#: Per posture, the axes the standard assesses there and their rules. Seated:
#: the seat surface, translations weighted Wd (x, y) and Wk (z) with k = 1 for
#: comfort (§8.2) and k = 1.4, 1.4, 1 for health (§7.2.3); rotations
#: weighted We with k = 0.63, 0.4, 0.2 m/rad (§8.2; no health rule).
#: Standing: the floor, Wd, Wd, Wk, k = 1 (§8.2); Annex B is for seated
#: persons, so no health rule.
AXIS_RULES: dict[str, dict[str, AxisRule]] = {
    "seated": {
        "x": AxisRule("Wd", 1.0, 1.4, _SEAT + "; health §7.2.3, k = 1.4", "m/s²"),
        "y": AxisRule("Wd", 1.0, 1.4, _SEAT + "; health §7.2.3, k = 1.4", "m/s²"),
        "z": AxisRule("Wk", 1.0, 1.0, _SEAT + "; health §7.2.3, k = 1", "m/s²"),
        "rx": AxisRule("We", 0.63, None, _SEAT_ROT + ", k = 0.63 m/rad", "rad/s²"),
        "ry": AxisRule("We", 0.40, None, _SEAT_ROT + ", k = 0.4 m/rad", "rad/s²"),
        "rz": AxisRule("We", 0.20, None, _SEAT_ROT + ", k = 0.2 m/rad", "rad/s²"),
    },
    "standing": {
        "x": AxisRule("Wd", 1.0, None, _FLOOR, "m/s²"),
        "y": AxisRule("Wd", 1.0, None, _FLOOR, "m/s²"),
        "z": AxisRule("Wk", 1.0, None, _FLOOR, "m/s²"),
    },
}  # fmt: skip
#: The postures the assessment knows.
POSTURES = tuple(AXIS_RULES)

#: ISO 2631-1:1997 Annex C.2.3: the likely reactions to a vibration total value
#: [m/s²] in public transport, as ``(label, low, high)``; the bands overlap as
#: printed, ``low`` None for "less than", ``high`` None for "greater than".
COMFORT_SCALE: tuple[tuple[str, float | None, float | None], ...] = (
    ("not uncomfortable", None, 0.315),
    ("a little uncomfortable", 0.315, 0.63),
    ("fairly uncomfortable", 0.5, 1.0),
    ("uncomfortable", 0.8, 1.6),
    ("very uncomfortable", 1.25, 2.5),
    ("extremely uncomfortable", 2.0, None),
)


def comfort_labels(a_v: float) -> tuple[str, ...]:
    """Every Annex C.2.3 label whose band holds ``a_v`` [m/s²].

    The bands overlap as the standard prints them ("0,5 m/s² to 1 m/s²:
    fairly uncomfortable", "0,8 m/s² to 1,6 m/s²: uncomfortable" ...), so a
    value may carry two labels. A printed range holds its ends; "less than
    0,315" and "greater than 2" do not.

    Examples
    --------
    >>> comfort_labels(0.9)
    ('fairly uncomfortable', 'uncomfortable')
    """
    v = checks.nonnegative("a_v", a_v, "m/s²")
    out = []
    for label, low, high in COMFORT_SCALE:
        if low is None:
            holds = high is not None and v < high
        elif high is None:
            holds = v > low
        else:
            holds = low <= v <= high
        if holds:
            out.append(label)
    return tuple(out)


#: Annex B, Figure B.1, eq. (B.1) ``a_w1 T1^½ = a_w2 T2^½``: the caution zone's
#: lower and upper bounds [m/s²] at 8 h, from which the zone scales with T^-½.
HEALTH_ZONE_8H = (0.43, 0.86)
#: Annex B.3.1 / Figure B.1, eq. (B.2): the zone in vibration dose value
#: [m/s^1.75], for a daily dose.
HEALTH_ZONE_VDV = (8.5, 17.0)
#: Figure B.1's exposure axis: 10 min to 24 h [s]; no guidance outside it.
HEALTH_DURATIONS = (600.0, 86400.0)
_EIGHT_HOURS = 8 * 3600.0


@dataclass(frozen=True)
class HealthGuidance:
    """Annex B's health guidance caution zone for a seated person's daily exposure.

    Attributes
    ----------
    duration : float or None
        The daily exposure [s] (None: not given, and no zone).
    a_w : float or None
        The highest ``k a_w`` of the seat's translational axes [m/s²], the
        value §7.2.3 assesses.
    axis : str or None
        The axis it comes from.
    zone : (float, float) or None
        Eq. (B.1)'s bounds at ``duration`` [m/s²]:
        ``(0.43, 0.86)·(8 h / duration)^½``.
    rms_verdict : str or None
        ``'below'``, ``'in'`` or ``'above'`` the caution zone.
    vdv : float or None
        The daily dose ``VDV (duration / T)^¼`` [m/s^1.75] of the measured
        ``VDV`` over ``T`` (§6.3.2: doses of repeated periods add in the
        fourth power), highest over the axes with ``k``.
    vdv_verdict : str or None
        Against eq. (B.2)'s zone, 8.5-17 m/s^1.75.
    note : str
        What the guidance rests on, or what is missing.
    clause : str
    """

    duration: float | None
    a_w: float | None
    axis: str | None
    zone: tuple[float, float] | None
    rms_verdict: str | None
    vdv: float | None
    vdv_verdict: str | None
    note: str
    clause: str = "ISO 2631-1:1997 §7.2.3, Annex B (B.3.1, Figure B.1, eqs. B.1 and B.2)"


def _where(value: float, zone: tuple[float, float]) -> str:
    return "below" if value < zone[0] else ("above" if value > zone[1] else "in")


def health_guidance(per_axis, posture: str, span: float, duration) -> HealthGuidance:
    """Annex B's caution zone for the assessed axes.

    Parameters
    ----------
    per_axis : Mapping[str, (a_w, vdv)]
        Each axis's weighted RMS [m/s²] and VDV [m/s^1.75].
    posture : str
        Annex B applies to seated persons (§7.1).
    span : float
        The measured duration T [s].
    duration : float or None
        The daily exposure [s].
    """
    if duration is not None:
        duration = checks.positive("duration", duration, "s")
    rules = AXIS_RULES[posture]
    scored = {a: v for a, v in per_axis.items() if rules[a].k_health is not None}
    if not scored:
        note = (
            "Annex B gives health guidance for seated persons' seat-surface translations "
            f"only; the {posture} assessment has none"
        )
        return HealthGuidance(duration, None, None, None, None, None, None, note)
    k = {a: float(rules[a].k_health or 0.0) for a in scored}
    axis = max(scored, key=lambda a: k[a] * scored[a][0])
    a_w = k[axis] * scored[axis][0]
    if duration is None:
        note = (
            "give the daily exposure, 10 min to 24 h (ride_assessment's duration= in s, "
            "qc-control report's --exposure in h), to place "
            f"k·a_w = {a_w:.3g} m/s² ({axis}) against Annex B's caution zone"
        )
        return HealthGuidance(None, a_w, axis, None, None, None, None, note)
    if not HEALTH_DURATIONS[0] <= duration <= HEALTH_DURATIONS[1]:
        note = f"Figure B.1 covers 10 min to 24 h; the exposure {duration:g} s is outside it"
        return HealthGuidance(duration, a_w, axis, None, None, None, None, note)
    scale = math.sqrt(_EIGHT_HOURS / duration)
    zone = (HEALTH_ZONE_8H[0] * scale, HEALTH_ZONE_8H[1] * scale)
    dose = max(k[a] * v[1] for a, v in scored.items()) * (duration / span) ** 0.25
    note = (
        "the zone of eq. (B.1) is mainly based on exposures of 4 h to 8 h (B.3.1); the "
        "daily VDV repeats the measured period (§6.3.2)"
    )
    return HealthGuidance(
        duration,
        a_w,
        axis,
        zone,
        _where(a_w, zone),
        dose,
        _where(dose, HEALTH_ZONE_VDV),
        note,
    )
