"""The tutorial's PD joint control law, free of ROS so it can be unit-tested on its own."""
import math


def wrap_angle(angle):
    """The angle brought into [-pi, pi]: a continuous joint keeps counting past +-pi, and the
    controller must turn the short way round instead of unwinding every revolution."""
    return math.remainder(angle, 2.0 * math.pi)


def pd_torque(pos_cmd, position, rate, kp, kv, torque_limit=None):
    """Torque = kp * wrap(pos_cmd - position) - kv * rate, clamped to +-torque_limit if given."""
    torque = kp * wrap_angle(pos_cmd - position) - kv * rate
    if torque_limit is not None:
        torque = min(max(torque, -torque_limit), torque_limit)
    return torque
