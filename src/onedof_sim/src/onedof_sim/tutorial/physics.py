"""Closed-form answers for the tutorial's robot, controller and table, the predictions each phase's
figures are set against (the rospy PD controller's and the in-simulator PID's settled angle and
holding torque), and the step-response metrics the main job reports. Plain functions: the tests
and the tutorial player share them.

Conventions: joint1 turns about +y, q = 0 points link2 straight up, q > 0 tilts it toward +x.
Gravity's torque about the joint is +m g d sin q (it pulls the link away from upright).

The robot's constants are read from its URDF (minimal_robot_description.urdf), the one place
they are written, so the closed forms always describe the robot the simulator loads.
"""
import math
import os
import xml.etree.ElementTree as ElementTree

import rospkg


ROBOT_URDF = os.path.join(rospkg.RosPack().get_path('minimal_robot_description'),
                          'minimal_robot_description.urdf')


def _numbers(text):
    return [float(value) for value in text.split()]


def _origin_xyz(element):
    """xyz of an element's <origin> ([0, 0, 0] without one); the closed forms know no rotation."""
    origin = element.find('origin')
    if origin is None:
        return [0.0, 0.0, 0.0]
    if any(_numbers(origin.get('rpy', '0 0 0'))):
        raise ValueError('%s: the closed forms take no rotated origin (%s %s)'
                         % (ROBOT_URDF, element.tag, element.get('name', '')))
    return _numbers(origin.get('xyz', '0 0 0'))


def read_robot(path):
    """link2's mass (kg), the distance from joint1 to its centre of mass (m), its iyy about that
    centre (kg m^2), its collision cylinder's length and radius (m), and joint1's height above
    the world's origin (m), from the tutorial robot's URDF. Raises ValueError where the robot is
    not the one the closed forms describe: joint1 about y, link2's centre of mass on its axis."""
    robot = ElementTree.parse(path).getroot()
    joints = {joint.find('child').get('link'): joint for joint in robot.findall('joint')}
    joint1 = robot.find("joint[@name='joint1']")
    if _numbers(joint1.find('axis').get('xyz')) != [0.0, 1.0, 0.0]:
        raise ValueError('%s: joint1 must turn about y' % path)
    link2 = robot.find("link[@name='%s']" % joint1.find('child').get('link'))
    inertial = link2.find('inertial')
    com = _origin_xyz(inertial)
    if com[:2] != [0.0, 0.0]:
        raise ValueError('%s: link2\'s centre of mass must be on its axis (z)' % path)
    cylinder = link2.find('collision/geometry/cylinder')
    height, parent = _origin_xyz(joint1)[2], joint1.find('parent').get('link')
    while parent in joints:  # down to the world: the heights of the joints below joint1
        height += _origin_xyz(joints[parent])[2]
        parent = joints[parent].find('parent').get('link')
    return dict(mass=float(inertial.find('mass').get('value')), com_distance=com[2],
                iyy=float(inertial.find('inertia').get('iyy')),
                length=float(cylinder.get('length')), radius=float(cylinder.get('radius')),
                joint_height=height)


_ROBOT = read_robot(ROBOT_URDF)
MASS = _ROBOT['mass']                  # link2, kg
COM_DISTANCE = _ROBOT['com_distance']  # joint1 to link2's centre of mass, m
LINK_LENGTH = _ROBOT['length']
LINK_RADIUS = _ROBOT['radius']
JOINT_HEIGHT = _ROBOT['joint_height']  # joint1 above the ground, m
INERTIA_ABOUT_JOINT = _ROBOT['iyy'] + MASS * COM_DISTANCE ** 2  # iyy at the COM + m d^2
GRAVITY = 9.8  # the simulator's default gravity, m/s^2 (-z)

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


def link_outline(q):
    """Corners of link2's cross-section in the x-z plane (y = 0) at angle q: the cylinder seen from
    the side, a rectangle one link long and two radii wide."""
    axis = (math.sin(q), math.cos(q))
    ahead = (math.cos(q), -math.sin(q))  # the side that leads when q grows
    corners = []
    for along in (0.0, LINK_LENGTH):
        for side in (LINK_RADIUS, -LINK_RADIUS):
            corners.append((axis[0] * along + ahead[0] * side,
                            JOINT_HEIGHT + axis[1] * along + ahead[1] * side))
    return corners


def _overlap(points_a, points_b, direction):
    project = lambda points: [p[0] * direction[0] + p[1] * direction[1] for p in points]
    a, b = project(points_a), project(points_b)
    return min(max(a), max(b)) - max(min(a), min(b)) > 0


def _rectangles_intersect(a, b):
    """Separating-axis test of two rectangles given by their corners (a[0]-a[1] and a[0]-a[2] are
    edges, as link_outline orders them)."""
    axes = []
    for rect in (a, b):
        for i, j in ((0, 1), (0, 2)):
            axes.append((rect[j][0] - rect[i][0], rect[j][1] - rect[i][1]))
    return all(_overlap(a, b, axis) for axis in axes)


def table_contact_angle(table_x, table_top_z=TABLE_TOP_Z, half_width=TABLE_TOP_HALF_WIDTH,
                        top_thickness=0.04, resolution=1e-3):
    """The first angle at which link2, swinging from upright toward +x, touches the top of a table
    centred at table_x: the least q in (0, pi) where the link's side view meets the top's."""
    x0, x1 = table_x - half_width, table_x + half_width
    z0, z1 = table_top_z - top_thickness, table_top_z
    top = [(x0, z0), (x0, z1), (x1, z0), (x1, z1)]
    touches = lambda q: _rectangles_intersect(link_outline(q), top)
    q = 0.0
    while not touches(q):
        q += resolution
        if q >= math.pi:
            raise ValueError('the table at x = %.3f is out of the link\'s reach' % table_x)
    lo, hi = q - resolution, q
    while hi - lo > 1e-10:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if touches(mid) else (mid, hi)
    return hi


def tip_rim(q):
    """(x, z) of the leading rim of link2's far end at angle q: where the link meets the table top
    in the tutorial's scene."""
    return link_outline(q)[2]


def pd_prediction(phase, settled):
    """(predicted angle, predicted holding torque) of the rospy PD controller: where
    Kp (c - q) + m g d sin q = 0; on the table, at rest (rate 0), Kp times the remaining error."""
    if phase.table:
        return table_contact_angle(phase.table[0]), KP * (phase.command - settled)
    predicted = settled_angle(phase.command)
    return predicted, -gravity_torque(predicted)


def pid_prediction(gains):
    """The prediction function of a PID with these gains (p, i_clamp_max as ros_control reads
    them): the integral removes the droop, the link settles at the command holding gravity's
    torque; on the table the integral winds up to its clamp, so the torque is p times the
    remaining error plus i_clamp_max."""
    def predict(phase, settled):
        if phase.table:
            return (table_contact_angle(phase.table[0]),
                    gains['p'] * (phase.command - settled) + gains['i_clamp_max'])
        return phase.command, -gravity_torque(phase.command)
    return predict


def tail_mean(times, values, window=0.5):
    """Mean of the values over the last `window` seconds of the samples."""
    if not times:
        raise ValueError('no samples')
    # A sample on the window's edge counts whatever the rounding of its time: two runs whose
    # times differ by an offset then average the same samples.
    tail = [v for t, v in zip(times, values) if t >= times[-1] - window - 1e-9]
    return sum(tail) / len(tail)


def step_metrics(times, positions, start_value, window=0.5, band=0.02):
    """Step-response figures of one phase (position samples from the command change on).

    settled: mean position over the last `window` seconds; overshoot: the furthest excursion past
    the settled value in the direction of the step (rad, >= 0); settling_time: from the first
    sample until the position stays within `band` rad of the settled value.
    """
    if len(times) < 2:
        raise ValueError('a phase needs at least two samples')
    settled = tail_mean(times, positions, window)
    direction = 1.0 if settled >= start_value else -1.0
    overshoot = max(0.0, max(direction * (q - settled) for q in positions))
    settling_time = 0.0
    for t, q in zip(times, positions):
        if abs(q - settled) > band:
            settling_time = t - times[0]
    return {'settled': settled, 'overshoot': overshoot, 'settling_time': settling_time}
