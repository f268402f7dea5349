"""The README's Python blocks run, in order, as a reader would paste them,
and what they leave behind is checked against independent values."""

import itertools
import re
from pathlib import Path

import control
import numpy as np
import pytest

README = Path(__file__).parent.parent / "README.md"

pytestmark = pytest.mark.slow  # a sweep of 1,000 designs and a 60 s road: about 9 s


@pytest.fixture(scope="module")
def namespace():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
    assert len(blocks) >= 5
    namespace: dict = {}
    for i, block in enumerate(blocks):
        try:
            exec(compile(block, f"README block {i}", "exec"), namespace)
        except Exception as exc:  # name the block that broke
            raise AssertionError(f"README python block {i} failed: {exc!r}\n{block}") from exc
    return namespace


def _readme_value(namespace, name):
    assert name in namespace, f"the README's Python blocks no longer define {name!r}"
    return namespace[name]


def test_readme_python_blocks_run(namespace):
    assert "qc" in namespace and "control" in namespace


def test_the_damped_frequencies_are_those_of_the_seed_matrix(namespace):
    """``wn, zeta, poles = control.damp(sys)`` of the car the README built,
    against the eigenvalues of the seed's A written out here from its
    parameters (states [xs', xu', xs, xu])."""
    p = _readme_value(namespace, "params")
    ms, mu, ks, ku, cs = p.ms, p.mu, p.ks, p.ku, p.cs
    A = np.array(
        [
            [-cs / ms, cs / ms, -ks / ms, ks / ms],
            [cs / mu, -cs / mu, ks / mu, -(ks + ku) / mu],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
        ]
    )
    expected = np.linalg.eigvals(A)
    wn = _readme_value(namespace, "wn")
    poles = _readme_value(namespace, "poles")
    # Both sides are eigenvalues of the same well-conditioned 4x4 matrix
    # (distinct pairs, |lambda| from 7 to 25 rad/s): they agree to rounding,
    # a few 1e-15 relative; 1e-9 leaves room for a different LAPACK.
    np.testing.assert_allclose(np.sort(wn), np.sort(np.abs(expected)), rtol=1e-9)
    np.testing.assert_allclose(np.sort_complex(poles), np.sort_complex(expected), rtol=1e-9, atol=0)
    assert p.zeta == 0.3  # the README's "firmer damper"


def test_the_road_response_is_rk4_on_the_exact_response(namespace):
    """The last ``resp`` is RK4 at h = 5 ms on the ISO 8608 class C road
    ``zr``; python-control's exact response to the same samples is the
    reference."""
    T = _readme_value(namespace, "T")
    zr = _readme_value(namespace, "zr")
    resp = _readme_value(namespace, "resp")
    p = _readme_value(namespace, "params")
    qc = namespace["qc"]
    assert resp.method.name == "rk4"
    exact = control.forced_response(qc.quarter_car(p, road=True), T, zr)
    for label in ("xs", "body_acc", "susp_travel"):
        got = resp.outputs[list(resp.output_labels).index(label)]
        ref = exact.outputs[list(exact.output_labels).index(label)]
        gap = np.max(np.abs(got - ref)) / np.max(np.abs(ref))
        # Measured: 1.1e-6 of the peak for body_acc (the worst), 1.2e-7 for xs.
        # 1e-5 holds that with margin, and is far below a second-order
        # method's gap on the same road (Heun: 2e-3), so it tells RK4 apart.
        assert gap < 1e-5, (label, gap)


def test_the_sweep_covers_its_grid_without_rejections(namespace):
    """``result`` is the README's sweep over 40 ks by 25 zeta."""
    result = _readme_value(namespace, "result")
    assert result.errors.empty
    assert len(result.metrics) == 40 * 25
    grid = set(itertools.product(np.linspace(15e3, 45e3, 40), np.linspace(0.1, 0.6, 25)))
    got = set(zip(result.metrics["ks"], result.metrics["zeta"]))
    assert got == grid
    assert result.metrics["stable"].all()  # RK4 at h = 1 ms is far inside every limit
