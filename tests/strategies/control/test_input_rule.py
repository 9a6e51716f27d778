"""The control theory checks its inputs with envs.validation: bools and strings are not numbers."""

from __future__ import annotations

import numpy as np
import pytest

from envs.errors import InfeasibleError, InvalidConfigError
from strategies.control import corner_min_distance, straight_leader_time, theta_dot, tractrix
from strategies.control.kinematics import pursuer_velocity, theta_dot_feasible


@pytest.mark.parametrize("bad", [True, "2", None, np.nan, [2.0]])
def test_scalars_refuse_non_numbers(bad) -> None:
    with pytest.raises(InvalidConfigError, match=r"^L = "):
        theta_dot(0.1, 0.2, L=bad, v_p=1.0, rho=0.5)
    with pytest.raises(InvalidConfigError, match=r"^rho = "):
        corner_min_distance(L=2.0, rho=bad)


def test_arrays_refuse_strings_and_bools_but_take_numpy_scalars() -> None:
    with pytest.raises(InvalidConfigError, match=r"^alpha = "):
        theta_dot(["a", "b"], 0.2, L=2.0, v_p=1.0, rho=0.5)
    with pytest.raises(InvalidConfigError, match=r"^alpha = "):
        theta_dot_feasible(np.array([True, False]), 0.0, rho=0.5)
    a = theta_dot(np.float32(0.1), np.array(0.2), L=np.int64(2), v_p=1.0, rho=0.5)
    assert a == pytest.approx(theta_dot(0.1, 0.2, L=2.0, v_p=1.0, rho=0.5))


def test_points_need_a_last_axis_of_two() -> None:
    with pytest.raises(InvalidConfigError, match=r"evader_velocity: expected shape \(2,\)"):
        pursuer_velocity([1.0, 2.0, 3.0], 0.0, 0.1, L=2.0)
    with pytest.raises(InvalidConfigError, match=r"leader_start = "):
        tractrix(1.0, L=2.0, v_e=0.5, leader_start=[0.0, np.inf])


def test_domain_rules_stay_domain_errors() -> None:
    with pytest.raises(InfeasibleError):
        straight_leader_time(0.1, 2.0, L=2.0, v_p=1.0, rho=1.5, alpha=0.0)
