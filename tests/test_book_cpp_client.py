"""A C++ client in the shape of the book's minimal joint controller (tests/book_cpp_client:
gazebo_msgs/ApplyJointEffort.h and GetJointProperties.h, non-persistent ros::ServiceClient, a
ros::Rate of 100 Hz in sim time, 10 ms effort jobs starting now), built with catkin_make in a
scratch overlay on this workspace's devel as a student builds it, and run against the simulator.

The build takes seconds (one source file), so each engine's test builds its own overlay: under
pytest-forked no fixture outlives its test.

The simulator runs at a quarter of real time: the client runs free against the simulator's clock,
and on a busy machine a period it misses leaves the link without torque for 10 ms, so it droops a
little further than the closed form. A quarter speed gives it four times the wall time per period.
"""
import os
import shutil
import subprocess

import pytest

from api_client import GazeboApi
from conftest import WORKSPACE, start_sim
from onedof_sim.private_ros import wait_until
from onedof_sim.tutorial import physics
from test_controller import Topic

PACKAGE = 'book_cpp_client'
QUARTER_SPEED = ['_max_update_rate:=250']
COMMAND = 1.0
SETTLE_WINDOW = 1.0  # s of sim time the link must stay within SETTLE_BAND to count as settled
SETTLE_BAND = 0.01
# The closed form neglects nothing but missed periods; a missed period or two moves the rest
# position by millirad.
TOLERANCE = 0.02


def build_overlay(tmp_path):
    """catkin_make of the client in tmp_path/overlay, under this workspace's devel (the test's
    environment); returns the overlay's devel/setup.bash."""
    overlay = tmp_path / 'overlay'
    shutil.copytree(os.path.join(WORKSPACE, 'tests', PACKAGE), overlay / 'src' / PACKAGE)
    env = dict(os.environ)
    env.pop('PYTHONPATH', None)  # as the Makefile builds: catkin_make sets its own
    # -C: catkin_make takes the workspace from $PWD (inherited: this workspace's), not the cwd.
    result = subprocess.run(['catkin_make', '-C', str(overlay), '-j2',
                             '-DPYTHON_EXECUTABLE=/usr/bin/python3'],
                            cwd=overlay, env=dict(env, PWD=str(overlay)), capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return overlay / 'devel' / 'setup.bash'


@pytest.fixture
def sim_time_client(ros, request):
    ros.set_param('/use_sim_time', True)
    return request.getfixturevalue('rospy_client')


def test_book_shaped_cpp_controller_holds_the_link_where_gravity_balances_the_gain(
        ros, engine, sim_time_client, tmp_path):
    from std_msgs.msg import Float64
    rospy = sim_time_client
    setup = build_overlay(tmp_path)
    start_sim(ros, engine, QUARTER_SPEED)
    jnt_pos = Topic(rospy, '/jnt_pos', Float64)
    pos_cmd = rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)
    client = ros.start(['bash', '-c', 'source %s && rosrun %s book_controller' % (setup, PACKAGE)],
                       name='book_controller')
    # Controlling before the robot exists, so the upright link is held from the first period.
    wait_until(lambda: client.poll() is not None or pos_cmd.get_num_connections() > 0, 60,
               what='the C++ client to subscribe to pos_cmd')
    wait_until(lambda: client.poll() is not None or 'cannot read joint1' in ros.log_text(client),
               60, what='the C++ client to look for joint1')
    assert client.poll() is None, ros.log_text(client)
    api = GazeboApi(rospy)
    api.spawn_robot()
    start = rospy.get_time()
    pos_cmd.publish(Float64(COMMAND))

    def settled():
        assert client.poll() is None, 'client exited:\n' + ros.log_text(client)
        tail = jnt_pos.steady_tail(start, SETTLE_WINDOW, SETTLE_BAND)
        if not tail or max(q for _, q in tail) < COMMAND:
            return None
        return sum(q for _, q in tail) / len(tail)

    q = wait_until(settled, 300, interval=0.2,
                   what='jnt_pos to settle within %g rad for %g s of sim time'
                   % (SETTLE_BAND, SETTLE_WINDOW))
    expected = physics.settled_angle(COMMAND)
    assert q == pytest.approx(expected, abs=TOLERANCE), \
        'settled at %.4f rad, Kp (c - q) + m g d sin q = 0 gives %.4f' % (q, expected)
    # The simulator's own reading, not only what the client says it read.
    assert api.get_joint_properties('joint1').position[0] == pytest.approx(expected,
                                                                           abs=TOLERANCE)
