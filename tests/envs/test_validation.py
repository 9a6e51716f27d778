"""The one input-validation module: one rule for what is a number, messages that name it."""

import math

import numpy as np
import pytest

from envs import surveillance_v1
from envs import validation as v
from envs.errors import InvalidConfigError


@pytest.mark.parametrize("bad", [True, False, "1", None, 1j, [1.0], np.bool_(True)])
def test_non_numbers_are_refused_everywhere(bad):
    for check in (v.real, v.positive, v.nonnegative, v.unit_interval):
        with pytest.raises(InvalidConfigError, match="x = "):
            check("x", bad)
    with pytest.raises(InvalidConfigError, match="expected an integer"):
        v.integer("x", bad)


@pytest.mark.parametrize("good", [2, 2.0, np.float32(2.0), np.int64(2), np.float64(2.0)])
def test_python_and_numpy_reals_are_numbers(good):
    assert v.positive("x", good) == 2.0
    assert type(v.positive("x", good)) is float


def test_ranges_and_finiteness():
    with pytest.raises(InvalidConfigError, match=r"l_min = -1: expected a finite number > 0"):
        v.positive("l_min", -1)
    with pytest.raises(InvalidConfigError, match="nan"):
        v.real("x", math.nan)
    with pytest.raises(InvalidConfigError, match="inf"):
        v.nonnegative("x", math.inf)
    assert v.real("x", math.inf, allow_inf=True) == math.inf
    with pytest.raises(InvalidConfigError, match=r">= 1, <= 3"):
        v.real("x", 4, minimum=1, maximum=3)
    assert v.nonnegative("x", 0) == 0.0
    with pytest.raises(InvalidConfigError, match=r"\(0, 1\)"):
        v.unit_interval("confidence", 1.0)
    assert v.unit_interval("p", 1.0, open=False) == 1.0


def test_integers_refuse_floats_and_bools_and_name_the_range():
    assert v.integer("seeds", np.int32(4), minimum=1) == 4
    with pytest.raises(InvalidConfigError, match=r"seeds = 2.0: expected an integer >= 1"):
        v.integer("seeds", 2.0, minimum=1)
    with pytest.raises(InvalidConfigError, match=r"n = 0: expected an integer in \[1, 5\]"):
        v.integer("n", 0, minimum=1, maximum=5)


def test_where_prefixes_the_message():
    with pytest.raises(InvalidConfigError, match=r"^spec.toml \[env\]: dt = 0: expected"):
        v.positive("dt", 0, where="spec.toml [env]")


def test_boolean_choice_string_mapping():
    assert v.boolean("shoot", np.bool_(False)) is False
    for bad in ("no", 1, 0, None):
        with pytest.raises(InvalidConfigError, match="expected true or false"):
            v.boolean("shoot", bad)
    assert v.choice("start", "safe", ("safe", "valid")) == "safe"
    with pytest.raises(InvalidConfigError, match="expected one of 'safe', 'valid'"):
        v.choice("start", "sa", ("safe", "valid"))
    with pytest.raises(InvalidConfigError):
        v.choice("flag", 1, (True, False))  # 1 == True, but 1 is not a bool
    with pytest.raises(InvalidConfigError, match="non-empty string"):
        v.string("name", "")
    assert v.mapping("params", {"a": 1}) == {"a": 1}
    with pytest.raises(InvalidConfigError, match="table"):
        v.mapping("params", [1, 2])


def test_choice_takes_numpy_strings_and_integers_as_the_option_they_equal():
    """Found by probing the env with numpy scalars: ``parallel_env(observation=np.str_(
    "lidar"))`` (an option drawn with ``rng.choice`` or read from an array) was refused with
    "observation = np.str_('lidar'): expected one of 'state', 'lidar', 'lidar_track'", as
    was ``np.int64(1)`` for the option 1, although the number rule takes numpy integers
    for integers (and ``map=np.str_("corridor")`` was accepted). Bools still match bools only."""
    got = v.choice("observation", np.str_("lidar"), ("state", "lidar"))
    assert got == "lidar" and type(got) is str  # the option itself: no numpy type leaks on
    got = v.choice("direction", np.int64(-1), (1, -1))
    assert got == -1 and type(got) is int
    assert v.choice("flag", np.bool_(True), (True, False)) is True
    for value, options in [(1, (True, False)), (True, (1, 0)), (np.int64(1), (True, False)),
                           (1.0, (1, -1)), (np.str_("1"), (1, -1)), (1, ("1", "2"))]:  # fmt: skip
        with pytest.raises(InvalidConfigError, match="expected one of"):
            v.choice("x", value, options)
    env = surveillance_v1.parallel_env(observation=np.str_("lidar"), reward=np.str_("sparse"))
    assert (env.config.observation, env.config.reward) == ("lidar", "sparse")
    assert type(env.config.observation) is str


def test_arrays_and_points():
    np.testing.assert_array_equal(v.point("p", [1, 2]), [1.0, 2.0])
    with pytest.raises(InvalidConfigError, match=r"expected shape \(2,\), got shape \(3,\)"):
        v.point("p", [1, 2, 3])
    with pytest.raises(InvalidConfigError, match="expected finite values, got nan"):
        v.point("p", [1, math.nan])
    with pytest.raises(InvalidConfigError, match="real numbers"):
        v.point("p", ["a", "b"])
    with pytest.raises(InvalidConfigError):
        v.point("p", [[1, 2], [3]])
    assert v.finite_array("xs", [[0, 1], [2, 3]], shape=(None, 2)).shape == (2, 2)


def test_long_values_are_shortened_in_messages():
    with pytest.raises(InvalidConfigError) as info:
        v.positive("x", "y" * 500)
    assert len(str(info.value)) < 200


def test_messages_show_arrays_on_one_line():
    # a numpy array's repr spans lines: the message did too
    ring = np.array([[0.0, 0.0], [12.0, 0.0], [12.0, np.nan], [0.0, 8.0]])
    for call in (lambda: v.finite_array("ring", ring), lambda: v.positive("x", ring)):
        with pytest.raises(InvalidConfigError) as info:
            call()
        assert "\n" not in str(info.value) and "[12., nan]" in str(info.value)
    assert v.shown("a  b") == "'a  b'"  # spaces inside a value are kept


def test_arrays_refuse_bools_hidden_in_lists_and_name_the_bad_entry():
    with pytest.raises(InvalidConfigError, match=r"^p = \[True, 2.0\]: expected an array of shape"):
        v.point("p", [True, 2.0])
    with pytest.raises(InvalidConfigError, match=r"expected real numbers"):
        v.finite_array("ring", [(0, 0), (1, (False))])
    with pytest.raises(InvalidConfigError, match=r"got inf at index \(1, 0\)"):
        v.points("ring", [(0.0, 0.0), (np.inf, 1.0)])
    assert v.is_real(np.array(2.5)) and not v.is_real(np.array([2.5]))
    arr = np.zeros((3, 2))
    assert v.points("pts", arr) is arr  # float64 input is not copied


def test_integers_beyond_a_float_are_refused_as_not_finite():
    """A JSON integer of 400 digits (``--config '{"l_min": 1000...0}'``) raised
    OverflowError from float(); it is refused as a number that is not finite."""
    huge = 10**400
    for check in (v.positive, v.nonnegative, v.real):
        with pytest.raises(InvalidConfigError, match=r"l_min = 1000.*\.\.\.: expected a finite"):
            check("l_min", huge)
    with pytest.raises(InvalidConfigError, match=r"expected a number in \(0, 1\)"):
        v.unit_interval("alpha", -huge)
    assert v.real("x", huge, allow_inf=True) == math.inf
    with pytest.raises(InvalidConfigError, match=r"l_max = -1000.*: expected a finite number > 0"):
        surveillance_v1.parallel_env(l_max=-huge)
