"""Shared fixtures and strategies."""

import os

import matplotlib
import pytest
from hypothesis import strategies as st

matplotlib.use("Agg")  # no screen on CI

from qc_control import QuarterCarParams  # noqa: E402

#: Physically plausible vehicles, from a kart to a truck axle (SI units).
#: Damping is kept > 0 so every mode decays; cs = 0 is tested separately.
valid_params = st.builds(
    QuarterCarParams,
    ms=st.floats(50.0, 5000.0),
    mu=st.floats(10.0, 1000.0),
    ks=st.floats(5e3, 5e5),
    ku=st.floats(5e4, 5e6),
    zeta=st.floats(0.01, 2.0),
)

#: Doctests that run a whole comparison, by node id (a docstring can't carry a marker).
SLOW_DOCTESTS = {"qc_control/__init__.py::qc_control"}  # the quickstart: about 3 s


@pytest.fixture
def seed_params():
    return QuarterCarParams()


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def pytest_configure(config):
    os.environ.setdefault("MPLBACKEND", "Agg")


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.nodeid in SLOW_DOCTESTS:
            item.add_marker(pytest.mark.slow)
