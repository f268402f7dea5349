"""Roads and ride comfort.

Road inputs (`road`: bumps, steps, ISO 8608 profiles, measured profiles,
several wheels) and the roughness index of a measured profile (`roughness`,
ASTM E1926's IRI); ISO 2631-1:1997's frequency weightings of every axis
(`iso2631`: Wk, Wd, Wf, ... of Annex A), the assessment of a ride as the
standard makes it (`assessment`: weighted r.m.s., MTVV, VDV, crest factor
and the combined vibration total value per axis) and its judgement
(`guidance`: the axis rules, the comfort scale, health and sickness); the
metric registry (`metrics`); exact stationary variances on a random road
(`spectral`) and ISO 2631-1's weighted r.m.s. computed the same way
(`iso2631_spectral`); ride metrics and transmissibility of a response
(`comfort`).
"""
