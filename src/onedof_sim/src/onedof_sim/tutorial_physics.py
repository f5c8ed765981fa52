"""Closed-form answers for the tutorial's robot, controller and table, and the step-response
metrics the main job reports. Plain functions: the tests and the tutorial player share them.

Conventions: joint1 turns about +y, q = 0 points link2 straight up, q > 0 tilts it toward +x.
Gravity's torque about the joint is +m g d sin q (it pulls the link away from upright).
"""
import math

MASS = 1.0            # link2, kg
COM_DISTANCE = 0.5    # joint1 to link2's centre of mass, m
GRAVITY = 9.8
LINK_LENGTH = 1.0
LINK_RADIUS = 0.1
JOINT_HEIGHT = 1.0    # joint1 above the ground, m
INERTIA_ABOUT_JOINT = 0.1 + MASS * COM_DISTANCE ** 2  # iyy at the COM + m d^2

KP = 10.0
KV = 3.0

# cafe_table collision geometry (onedof_sim/models/cafe_table): the top surface.
TABLE_TOP_Z = 0.775
TABLE_TOP_HALF_WIDTH = 0.913 / 2


def gravity_torque(q):
    return MASS * GRAVITY * COM_DISTANCE * math.sin(q)


def pendulum_period():
    """Small-swing period of link2 about its lowest point (compound pendulum)."""
    return 2 * math.pi * math.sqrt(INERTIA_ABOUT_JOINT / (MASS * GRAVITY * COM_DISTANCE))


def _bisect(f, lo, hi, tol=1e-12):
    flo = f(lo)
    if flo * f(hi) > 0:
        raise ValueError('no sign change in [%g, %g]' % (lo, hi))
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if (f(mid) > 0) == (flo > 0):
            lo, flo = mid, f(mid)
        else:
            hi = mid
    return 0.5 * (lo + hi)


def settled_angle(command, kp=KP):
    """Where the PD controller comes to rest: Kp (c - q) + m g d sin q = 0. With this low gain,
    gravity holds the link past the command (for 0 < c < pi, beyond it)."""
    balance = lambda q: kp * (command - q) + gravity_torque(q)
    # The balance is positive at q = c (for 0 < c < pi) and falls by at least kp - m g d per radian.
    reach = MASS * GRAVITY * COM_DISTANCE / (kp - MASS * GRAVITY * COM_DISTANCE) + 1e-9
    return _bisect(balance, command - reach, command + reach)


def table_contact_angle(table_x, table_top_z=TABLE_TOP_Z, half_width=TABLE_TOP_HALF_WIDTH):
    """The angle at which link2's cylinder, swinging toward +x, first touches the near edge of a
    table top centred at table_x. With the table within reach the side of the cylinder meets the
    edge (x_e, z_e): the edge's distance from the link's axis equals the radius."""
    edge_x, edge_z = table_x - half_width, table_top_z
    dx, dz = edge_x, edge_z - JOINT_HEIGHT
    distance = math.hypot(dx, dz)
    if distance > LINK_LENGTH or distance < LINK_RADIUS:
        raise ValueError('the table edge at x = %.3f is out of the link\'s reach' % edge_x)
    edge_angle = math.atan2(dx, dz)  # measured like q: from +z toward +x
    return edge_angle - math.asin(LINK_RADIUS / distance)


def table_edge(table_x, table_top_z=TABLE_TOP_Z, half_width=TABLE_TOP_HALF_WIDTH):
    """(x, z) of the table top's edge nearest the robot: where the link meets the table."""
    return table_x - half_width, table_top_z


def step_metrics(times, positions, torques, start_value, window=0.5, band=0.02):
    """Step-response figures of one phase (samples from the command change on).

    settled: mean position over the last `window` seconds; overshoot: the furthest excursion past
    the settled value in the direction of the step (rad, >= 0); settling_time: from the first
    sample until the position stays within `band` rad of the settled value; holding_torque: mean
    torque over the last window.
    """
    if len(times) < 2:
        raise ValueError('a phase needs at least two samples')
    t0, t_end = times[0], times[-1]
    tail = [i for i, t in enumerate(times) if t >= t_end - window]
    settled = sum(positions[i] for i in tail) / len(tail)
    holding = sum(torques[i] for i in tail) / len(tail)
    direction = 1.0 if settled >= start_value else -1.0
    overshoot = max(0.0, max(direction * (q - settled) for q in positions))
    settling_time = 0.0
    for t, q in zip(times, positions):
        if abs(q - settled) > band:
            settling_time = t - t0
    return {'settled': settled, 'overshoot': overshoot, 'settling_time': settling_time,
            'holding_torque': holding}
