"""The cross-validation's experiments beyond the tutorial's arm, each of our engines against what
it should give: the book's diff-drive base (bench/mobot_w_lidar.urdf) driven straight and
turning, a force-torque joint holding a block, the base's lidar in a pen of four walls, and an
arm of the book's arm7dof's shape (bench/arm7dof_shape.urdf) held by its controllers. They
run through `rosrun onedof_sim engine_checks MODE --physics NAME` (bench/engine_checks.cpp): the
core with one engine, in-process, no ROS, each plugin's world calls made directly.

Each Check has the aim the engines are held to (docs/cross_validation.md shows whether it is met):
the base within 2 % of its commanded twist, the joint's force within 1 % of m g, every ray within
1 cm of the wall it meets, every joint of the arm within 1 mrad of where its controller's P term
holds gravity (the droop), and never past it under the book's gains.
"""
import collections
import math
import os
import subprocess

import rospkg

from onedof_sim.tutorial import physics

TOOL = ('rosrun', 'onedof_sim', 'engine_checks')

# The book's mobot as gazebo_ros_diff_drive drives it (its <wheelDiameter>, <wheelSeparation> and
# <torque>): left_wheel_joint is the wheel at +y, both turn the base forward at positive rates.
MOBOT = {'left': 'left_wheel_joint', 'right': 'right_wheel_joint', 'radius': 0.1651,
         'separation': 0.56515, 'torque': 200.0}
# Its lidar: 0.1 m ahead of base_link, 0.56 m up (lidar_joint).
LIDAR_X, LIDAR_Z = 0.1, 0.56
LIDAR_SAMPLES = 720
PEN_HALF = 2.0          # m from the origin to each wall's inner face
STRAIGHT = (0.5, 0.0, 2.0)   # m/s, rad/s, s
TURNING = (0.5, 0.3, 4.0)
HELD_MASS = 3.0         # kg
# The book's arm7dof_pos_ctl.yaml: one effort_controllers/JointPositionController per joint (and a
# joint_state_controller, which moves nothing), these pid gains.
ARM_JOINTS = ['joint%d' % k for k in range(7)]
ARM_GAINS = {'p': [500.0, 500.0, 500.0, 500.0, 30.0, 30.0, 20.0],
             'i': [0.5, 0.1, 0.5, 0.1, 0.5, 0.1, 0.1],
             'd': [50.0, 50.0, 50.0, 50.0, 2.0, 2.0, 1.0]}
# A bent pose, where gravity pulls on every joint whose axis is not vertical (rad).
ARM_POSE = [0.0, 0.3, 0.0, -0.6, 0.0, 0.5, 0.0]
# Long enough for the slowest joint to settle (joint3: its damping over its p, 2 s, five times).
ARM_PD_SECONDS = 20.0
ARM_BOOK_SECONDS = 10.0
ARM_AIM = 0.001         # rad
TWIST_AIM = 0.02        # of the commanded speed and turn rate
FORCE_AIM = 0.01        # of m g
RANGE_AIM = 0.01        # m

# measured and expected are in unit; aim is the largest |measured - expected| that meets it.
Check = collections.namedtuple('Check', 'engine quantity unit measured expected aim')


def met(check):
    return abs(check.measured - check.expected) <= check.aim


def mobot_urdf_path():
    return os.path.join(rospkg.RosPack().get_path('onedof_sim'), 'bench', 'mobot_w_lidar.urdf')


def parse_columns(text):
    """{column: [values]} from the CSV the tool prints (a header line, then rows)."""
    lines = text.strip().splitlines()
    header = lines[0].split(',')
    columns = {name: [] for name in header}
    for line in lines[1:]:
        for name, value in zip(header, line.split(',')):
            columns[name].append(float(value))
    return columns


def run_tool(mode, engine, ground, args):
    done = subprocess.run(list(TOOL) + [mode, '--physics', engine, '--ground', ground] +
                          [str(arg) for arg in args], capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        raise RuntimeError('engine_checks %s --physics %s failed: %s'
                           % (mode, engine, done.stderr.strip()))
    return parse_columns(done.stdout)


def drive(engine, ground, linear, angular, seconds):
    """(mean speed along the heading, mean turn rate) of the base driven at the twist."""
    args = ['--urdf', mobot_urdf_path()]
    for key in ('left', 'right', 'radius', 'separation', 'torque'):
        args += ['--' + key, str(MOBOT[key])]
    columns = run_tool('drive', engine, ground, args + [
        '--linear', repr(linear), '--angular', repr(angular), '--seconds', repr(seconds)])
    return columns['linear'][0], columns['angular'][0]


def held_force(engine, ground, mass):
    return run_tool('hold', engine, ground, ['--mass', repr(mass)])['force_z'][0]


def arm_path():
    return os.path.join(rospkg.RosPack().get_path('onedof_sim'), 'bench', 'arm7dof_shape.urdf')


def held_arm(engine, ground, gains, seconds):
    """(position - command, droop) of each joint of the arm held at ARM_POSE with `gains`."""
    args = ['--urdf', arm_path(), '--joints', ','.join(ARM_JOINTS),
            '--pose', ','.join(repr(q) for q in ARM_POSE), '--seconds', repr(seconds)]
    for term in ('p', 'i', 'd'):
        args += ['--' + term, ','.join(repr(gain) for gain in gains[term])]
    columns = run_tool('arm', engine, ground, args)
    return [(position - command, droop) for command, position, droop in
            zip(columns['command'], columns['position'], columns['droop'])]


def beyond_droop(offset, droop):
    """How far a joint's offset from its command lies outside the span from 0 to its droop."""
    return max(0.0, min(0.0, droop) - offset, offset - max(0.0, droop))


def wall_distance(x, y, angle, half):
    """How far a horizontal ray from (x, y) inside the pen travels at `angle` to a wall's inner
    face."""
    dx, dy = math.cos(angle), math.sin(angle)
    reaches = [(math.copysign(half, d) - start) / d for start, d in ((x, dx), (y, dy))
               if abs(d) > 1e-12]
    return min(reaches)


def scan_errors(engine, ground):
    """|measured - exact| of every ray of the lidar in the pen, m."""
    columns = run_tool('scan', engine, ground, [
        '--urdf', mobot_urdf_path(), '--lidar-x', repr(LIDAR_X), '--lidar-z', repr(LIDAR_Z),
        '--pen-half', repr(PEN_HALF), '--samples', str(LIDAR_SAMPLES)])
    return [abs(distance - wall_distance(x, y, angle, PEN_HALF))
            for x, y, angle, distance in zip(columns['x'], columns['y'], columns['angle'],
                                             columns['distance'])]


def checks(engine, ground):
    """The Checks of one engine."""
    out = []
    linear, angular = drive(engine, ground, *STRAIGHT)
    out.append(Check(engine, 'diff-drive base driven at %g m/s: speed' % STRAIGHT[0], 'm/s',
                     linear, STRAIGHT[0], TWIST_AIM * STRAIGHT[0]))
    linear, angular = drive(engine, ground, *TURNING)
    out.append(Check(engine, 'diff-drive base driven at %g m/s, %g rad/s: speed'
                     % TURNING[:2], 'm/s', linear, TURNING[0], TWIST_AIM * TURNING[0]))
    out.append(Check(engine, 'diff-drive base driven at %g m/s, %g rad/s: turn rate'
                     % TURNING[:2], 'rad/s', angular, TURNING[1], TWIST_AIM * TURNING[1]))
    weight = HELD_MASS * physics.GRAVITY
    out.append(Check(engine, 'force-torque joint holding %g kg: force along z' % HELD_MASS, 'N',
                     held_force(engine, ground, HELD_MASS), weight, FORCE_AIM * weight))
    out.append(Check(engine, 'lidar in a pen, %d rays: worst range error' % LIDAR_SAMPLES, 'mm',
                     1000 * max(scan_errors(engine, ground)), 0.0, 1000 * RANGE_AIM))
    pd_gains = dict(ARM_GAINS, i=[0.0] * len(ARM_JOINTS))
    joints = held_arm(engine, ground, pd_gains, ARM_PD_SECONDS)
    out.append(Check(engine, 'arm7dof\'s shape held by P and D terms alone: worst joint off its '
                     'droop', 'mrad', 1000 * max(abs(offset - droop) for offset, droop in joints),
                     0.0, 1000 * ARM_AIM))
    joints = held_arm(engine, ground, ARM_GAINS, ARM_BOOK_SECONDS)
    out.append(Check(engine, 'arm7dof\'s shape held by the book\'s gains: worst joint past its '
                     'droop', 'mrad', 1000 * max(beyond_droop(*joint) for joint in joints), 0.0,
                     1000 * ARM_AIM))
    return out
