r"""ISO 2631-1 weighted RMS on an ISO 8608 road, exactly: every axis, every linear car.

On white road velocity of intensity ``q`` (an ISO 8608 road of waviness 2
at constant speed, `qc_control.ride.road.iso8608_intensity`), the car of
`qc_control.ride.spectral.white_velocity_system`, ``x̃' = A x̃ + A⁻¹B_r w``,
has a stationary acceleration ``a = c x̃`` on each ISO axis (``c`` a row of
its ``C``, or a combination: the seat's fore-aft ``x = -h θ''``). Put in
series with the axis's Annex A weighting ``(A_w, b_w, c_w, d_w)``
(`qc_control.weighting`), the augmented system

.. math:: A_c = \begin{bmatrix} A & 0 \\ b_w c & A_w \end{bmatrix}, \quad
          B_c = \begin{bmatrix} A^{-1} B_r \\ 0 \end{bmatrix}, \quad
          c_c = [\,d_w c \;\; c_w\,]

gives the weighted RMS ``a_w = (q · c_c P c_cᵀ)^½`` with
``A_c P + P A_cᵀ + B_c B_cᵀ = 0`` (Lyapunov): exact over the unbounded
band, no simulation. Given the car's speed, its rear wheels meet the front
wheels' road ``τ = (a + b)/v`` later, which adds the cross terms
``2 c_c e^{A_c τ} X c_cᵀ`` (`qc_control.ride.spectral.road_variances`: a
cross-Gramian, exact for the delay); a full car's left and right tracks are
independent.
"""

from __future__ import annotations

# The machinery lives beside the other Lyapunov values in `qc_control.ride.spectral`,
# whose `spectral_metrics` (the spectral sweep) computes these metrics by name with it;
# this module remains their documented home.
from .spectral import spectral_a_v, spectral_axis_rms

__all__ = ["spectral_axis_rms", "spectral_a_v"]
