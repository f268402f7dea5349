"""Roads and ride comfort.

Road inputs (`road`: bumps, steps, ISO 8608 profiles, several wheels),
the ISO 2631-1 Wk weighting (`iso2631`), the metric registry (`metrics`),
exact stationary variances on a random road (`spectral`), and ride metrics
and transmissibility of a response (`comfort`).
"""
