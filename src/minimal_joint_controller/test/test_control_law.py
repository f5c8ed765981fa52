import math

import pytest

from minimal_joint_controller.control_law import pd_torque, wrap_angle


@pytest.mark.parametrize('angle, wrapped', [
    (0.0, 0.0),
    (1.0, 1.0),
    (-3.0, -3.0),
    (math.pi + 0.25, -math.pi + 0.25),
    (-math.pi - 0.25, math.pi - 0.25),
    (2 * math.pi + 0.5, 0.5),
    (-7 * math.pi + 0.5, -math.pi + 0.5),
    (100.0, 100.0 - 32 * math.pi),
])
def test_wrap_angle_brings_angles_into_minus_pi_pi(angle, wrapped):
    assert wrap_angle(angle) == pytest.approx(wrapped, abs=1e-12)
    assert -math.pi <= wrap_angle(angle) <= math.pi


def test_tutorial_gains_give_proportional_and_damping_terms():
    assert pd_torque(1.0, 0.0, 0.0, kp=10, kv=3) == pytest.approx(10.0)
    assert pd_torque(0.0, 0.0, 2.0, kp=10, kv=3) == pytest.approx(-6.0)
    assert pd_torque(2.0, 2.5, -1.0, kp=10, kv=3) == pytest.approx(-5.0 + 3.0)


def test_error_is_wrapped_so_the_joint_turns_the_short_way():
    # Command 3.0 from -3.0: the raw error is 6.0, the short way is 6.0 - 2 pi (about -0.28).
    assert pd_torque(3.0, -3.0, 0.0, kp=10, kv=0) == pytest.approx(10 * (6.0 - 2 * math.pi))
    # A joint that has turned one full revolution is already at the command.
    assert pd_torque(1.0, 1.0 + 2 * math.pi, 0.0, kp=10, kv=3) == pytest.approx(0.0, abs=1e-12)


def test_torque_limit_clamps_both_signs_and_leaves_small_torques_alone():
    assert pd_torque(3.0, 0.0, 0.0, kp=10, kv=3, torque_limit=5.0) == 5.0
    assert pd_torque(-3.0, 0.0, 0.0, kp=10, kv=3, torque_limit=5.0) == -5.0
    assert pd_torque(0.1, 0.0, 0.0, kp=10, kv=3, torque_limit=5.0) == pytest.approx(1.0)


def test_no_limit_by_default():
    assert pd_torque(3.0, 0.0, 0.0, kp=10, kv=3) == pytest.approx(30.0)
