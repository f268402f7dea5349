"""python-control's private names that qc_control relies on (`qc_control.compat`).

One test per name: it exists in the installed python-control and behaves as
qc relies on, checked against python-control's public behaviour (its own
responses, a system's ``updfcn``/``outfcn``, the documented aliases), never
against compat itself. When python-control moves, these fail first and say
which name to adapt in compat.py.
"""

from __future__ import annotations

import warnings

import control
import numpy as np
import pytest

from qc_control import compat


def _pendulum():
    """A nonlinear system with states, inputs, outputs and a parameter."""

    def updfcn(t, x, u, params):
        return np.array([x[1], -params["g"] / params["l"] * np.sin(x[0]) + u[0] - 0.1 * t])

    def outfcn(t, x, u, params):
        return np.array([params["l"] * np.sin(x[0]), x[1] + u[0]])

    return control.nlsys(
        updfcn,
        outfcn,
        inputs=["tau"],
        outputs=["horiz", "rate"],
        states=["theta", "omega"],
        params={"g": 9.81, "l": 1.0},
        name="pendulum",
    )


def test_the_alias_table_has_the_keys_and_aliases_qc_uses():
    """The aliases python-control documents for its time responses."""
    table = compat.TIMERESP_ALIASES
    for name, alias in [
        ("timepts", "T"),
        ("inputs", "U"),
        ("initial_state", "X0"),
        ("return_states", "return_x"),
        ("evaluation_times", "t_eval"),
        ("timepts_num", "T_num"),
    ]:
        aliases, legacy = table[name]
        assert alias in aliases and isinstance(legacy, list)


def test_process_kwargs_renames_aliases_and_refuses_two_names_as_control_does():
    kwargs = {"T": [0.0, 1.0], "X0": 1.0}
    compat.process_time_response_kwargs(kwargs)
    assert kwargs == {"timepts": [0.0, 1.0], "initial_state": 1.0}
    # two names for one parameter: refused, as control's own response refuses them
    with pytest.raises(TypeError, match="multiple values for parameter `timepts`"):
        compat.process_time_response_kwargs({"T": 1.0, "timepts": 2.0})
    with pytest.raises(TypeError, match="multiple values for parameter"):
        control.step_response(control.tf([1], [1, 1]), T=1.0, timepts=2.0)
    # a legacy name warns as in control
    with pytest.warns(PendingDeprecationWarning, match="legacy"):
        compat.process_time_response_kwargs({"x0": 1.0})


def test_process_param_takes_the_keyword_and_refuses_a_clash_as_control_does():
    """A value given by keyword (an alias, renamed by process_kwargs) wins over
    the signature's default; given as well positionally, control's response
    raises, and so does the same sequence here, with control's message."""
    kwargs = {"U": 2.0}
    compat.process_time_response_kwargs(kwargs)
    assert compat.process_time_response_param("inputs", 0.0, kwargs, sigval=0.0) == 2.0
    assert kwargs == {}
    assert compat.process_time_response_param("inputs", 3.0, {}, sigval=0.0) == 3.0
    kwargs = {"U": 2.0}
    compat.process_time_response_kwargs(kwargs)
    with pytest.raises(TypeError) as ours:
        compat.process_time_response_param("inputs", 1.0, kwargs, sigval=0.0)
    sys = control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])
    with pytest.raises(TypeError) as theirs:
        control.forced_response(sys, [0.0, 1.0], [1.0, 1.0], U=[2.0, 2.0])
    assert str(ours.value) == str(theirs.value)
    # and the alias alone gives control's own response to that input
    ref = control.forced_response(sys, [0.0, 1.0], U=[2.0, 2.0])
    np.testing.assert_array_equal(ref.inputs, [2.0, 2.0])


def test_check_convert_array_spreads_numbers_and_gives_controls_message():
    out = compat.check_convert_array(2.0, [(1, 4)], "Parameter `U`: ", squeeze=False)
    np.testing.assert_array_equal(out, np.full((1, 4), 2.0))
    with pytest.raises(ValueError) as ours:
        compat.check_convert_array(np.ones((2, 3)), [(1, 4)], "Parameter `U`: ", squeeze=False)
    sys = control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])
    with pytest.raises(ValueError) as theirs:
        control.forced_response(sys, np.linspace(0, 1, 4), np.ones((2, 3)))
    assert str(ours.value).startswith("Parameter `U`: ")
    assert str(theirs.value).startswith("Parameter `U`: ")


@pytest.mark.parametrize("is_step", [True, False])
def test_default_time_vector_is_the_grid_control_chooses(is_step):
    """The grid of control's own step/impulse response without T."""
    sys = control.ss([[0.0, 1.0], [-100.0, -2.0]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    respond = control.step_response if is_step else control.impulse_response
    T = compat.default_time_vector(sys, is_step=is_step)
    np.testing.assert_array_equal(T, respond(sys).time)
    # with a final time: a grid ending there, as control's own
    T = compat.default_time_vector(sys, tfinal=3.0, is_step=is_step)
    assert T[0] == 0.0 and T[-1] == 3.0
    np.testing.assert_array_equal(T, respond(sys, 3.0).time)
    # for a list of systems: the longest grid, as control.step_response uses for the list
    slow = control.ss([[-0.5]], [[1.0]], [[1.0]], [[0.0]])
    T = compat.default_time_vector([sys, slow], is_step=is_step)
    np.testing.assert_array_equal(T, respond([sys, slow])[0].time)


def test_process_vector_argument_reads_x0_as_input_output_response_does():
    """Lists stacked, numbers spread, short vectors padded: the initial state
    control's own response starts from (its first state sample)."""
    sys = _pendulum()
    T = np.linspace(0.0, 0.1, 3)
    for X0 in ([0.1, 0.2], [[0.1], 0.2], 0.3, [0.1]):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "X0 too short; padding with zeros", from both
            x0, n = compat.process_vector_argument(X0, "X0", sys.nstates)
            ref = control.input_output_response(sys, T, 0.0, X0=X0)
        assert n == sys.nstates
        np.testing.assert_array_equal(x0, ref.states[:, 0])


def test_state_derivative_and_output_function_are_updfcn_and_outfcn_with_the_parameters():
    """``_rhs``/``_out`` equal the system's own functions called with its
    parameters updated as requested (exactly: the same call)."""
    sys = _pendulum()
    params = {"l": 2.0}
    compat.update_params(sys, params)
    current = compat.current_params(sys)
    assert current == {"g": 9.81, "l": 2.0}
    t, x, u = 0.3, np.array([0.4, -0.2]), np.array([0.5])
    np.testing.assert_array_equal(
        compat.state_derivative(sys)(t, x, u), sys.updfcn(t, x, u, {"g": 9.81, "l": 2.0})
    )
    np.testing.assert_array_equal(
        compat.output_function(sys)(t, x, u), sys.outfcn(t, x, u, {"g": 9.81, "l": 2.0})
    )
    # updating again starts from the system's own parameters, not the last update
    compat.update_params(sys, {"g": 1.0})
    assert compat.current_params(sys) == {"g": 1.0, "l": 1.0}
    # without an output function, the output is the state
    bare = control.nlsys(sys.updfcn, None, inputs=1, states=2, params={"g": 9.81, "l": 1.0})
    compat.update_params(bare, None)
    np.testing.assert_array_equal(compat.output_function(bare)(t, x, u), x)


def test_update_params_reaches_the_subsystems_of_an_interconnection():
    """The interconnection's derivative with a subsystem's parameter changed
    equals the plant's own update function fed what the changed gain makes
    of the plant's output (worked out by hand, to rounding)."""
    plant = _pendulum()
    gain = control.nlsys(
        None,
        lambda t, x, u, p: -p["k"] * u,
        inputs=["e"],
        outputs=["tau"],
        params={"k": 1.0},
        name="gain",
    )
    closed = control.interconnect(
        [plant, gain],
        connections=[["gain.e", "pendulum.horiz"], ["pendulum.tau", "gain.tau"]],
        inplist=[],
        outlist=["pendulum.horiz"],
    )
    compat.update_params(closed, {"k": 3.0})
    assert compat.current_params(gain)["k"] == 3.0
    x = np.array([0.4, -0.2])
    f = compat.state_derivative(closed)(0.0, x, np.empty(0))
    tau = -3.0 * 1.0 * np.sin(x[0])  # tau = -k horiz, horiz = l sin(theta)
    # rtol 1e-14: the same arithmetic, perhaps in another order
    np.testing.assert_allclose(
        f, plant.updfcn(0.0, x, np.array([tau]), {"g": 9.81, "l": 1.0}), rtol=1e-14
    )


def test_current_params_gives_the_default_for_a_system_without_them():
    assert compat.current_params(object(), {"a": 1}) == {"a": 1}


def test_interconnection_maps_have_the_shapes_relied_on():
    """u = connect y + inputs w and z = outputs [y; u]: checked against
    python-control's own outputs of the interconnection, which it computes
    from these maps, for a linear plant and a static gain."""
    plant = control.ss(
        [[0.0, 1.0], [-4.0, -0.4]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]],
        inputs="u", outputs="y", name="P",
    )  # fmt: skip
    gain = control.nlsys(None, lambda t, x, u, p: -2.0 * u, inputs="e", outputs="f", name="C")
    closed = control.interconnect(
        [plant, gain],
        connections=[["C.e", "P.y"], ["P.u", "C.f"]],
        inplist=["C.e"],
        outlist=["P.y", "C.f", "P.u"],
    )
    maps = compat.interconnection_maps(closed)
    assert maps.syslist == list(closed.syslist)
    n_in = sum(s.ninputs for s in maps.syslist)
    n_out = sum(s.noutputs for s in maps.syslist)
    assert maps.connect.shape == (n_in, n_out)
    assert maps.inputs.shape == (n_in, closed.ninputs)
    assert maps.outputs.shape == (closed.noutputs, n_out + n_in)
    # the relation, against control's own output at one point
    x, w = np.array([0.3, -0.1]), np.array([0.2])
    compat.update_params(closed, None)
    y_plant = plant.C @ x  # no feedthrough: the plant's output needs no input
    u_gain = maps.connect[1:, :1] @ y_plant + maps.inputs[1:] @ w
    y = np.concatenate([y_plant, -2.0 * u_gain])
    u = maps.connect @ y + maps.inputs @ w
    z = maps.outputs @ np.concatenate([y, u])
    np.testing.assert_allclose(z, compat.output_function(closed)(0.0, x, w), rtol=1e-14)
    ref = control.input_output_response(closed, [0.0, 1e-3], w[:, None] * [1, 1], X0=x)
    np.testing.assert_allclose(z, ref.outputs[:, 0], rtol=1e-14)
