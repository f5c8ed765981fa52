"""A C++ client in the shape of the book's minimal joint controller (tests/book_cpp_client:
gazebo_msgs/ApplyJointEffort.h and GetJointProperties.h, non-persistent ros::ServiceClient, a
ros::Rate of 100 Hz in sim time, 10 ms effort jobs starting now), built with catkin_make in a
scratch overlay on this workspace's devel as a student builds it, and run against the simulator.

The overlay is built once for the session's tests (both engines, both test workers): a folder
beside the workers' own, under a lock.

The simulator runs in lock-step at the tutorial's real-time factor 1: it waits for the client's
command at the end of every period, so the client misses none however busy the machine, and its
rest angle is the physics' to the last micro-radian: that of the rospy controller on the same
simulator, and that of the in-process run of the tutorial's controller law.
"""
import pytest

from api_client import GazeboApi
from conftest import OVERLAY_TESTS_TIMEOUT, session_folder, start_sim
from onedof_harness import book_client
from onedof_harness.private_ros import wait_until
from onedof_sim.tutorial import physics

pytestmark = OVERLAY_TESTS_TIMEOUT

LOCKSTEP = ['_lockstep:=true']
COMMAND = 1.0
# Sim seconds from the command to the reading: the step response decays as exp(-Kv t / 2 I), to
# well under 1e-7 rad in 5 s.
SETTLE_S = 5.0
SAME = 1e-6  # rad


@pytest.fixture
def book_client_setup(tmp_path_factory):
    """The overlay's setup.bash, built by the first test that asks (pytest-forked: no fixture
    outlives its test, so the folder is what is shared)."""
    return book_client.shared_overlay(session_folder(tmp_path_factory, 'book_cpp_client'))


@pytest.fixture
def sim_time_client(ros, request):
    ros.set_param('/use_sim_time', True)
    return request.getfixturevalue('rospy_client')


def rest_angle(ros, api, sim, pos_cmd, command, controller, name):
    """Starts the controller on the running lock-stepped simulator, spawns the robot once the
    controller looks for joint1, commands `command` and returns joint1's angle SETTLE_S of sim time
    later, as the simulator reads it. Then removes the robot, resets the simulation and stops the
    controller."""
    proc = ros.start(controller, name=name)
    wait_until(lambda: proc.poll() is not None or pos_cmd.get_num_connections() > 0, 60,
               what='%s to subscribe to pos_cmd' % name)
    wait_until(lambda: proc.poll() is not None or 'cannot read joint' in ros.log_text(proc),
               60, what='%s to look for joint1' % name)
    assert proc.poll() is None, ros.log_text(proc)
    api.spawn_robot()
    pos_cmd.publish(pos_cmd.data_class(command))
    wait_until(lambda: 'received value of pos_cmd is: %f' % command in ros.log_text(proc), 60,
               what='%s to take the command' % name)
    end = api.sim_time_ns() + SETTLE_S * 1e9
    wait_until(lambda: proc.poll() is not None or api.sim_time_ns() >= end, 300,
               what='%g s of sim time' % SETTLE_S)
    assert proc.poll() is None, name + ' exited:\n' + ros.log_text(proc)
    q = api.get_joint_properties('joint1').position[0]
    # Lock-stepped all along: the simulator took it in and never had to go on without it.
    log = ros.log_text(sim)
    assert 'lock-step: joint1 is commanded by /%s' % name in log, log
    assert 'the world waited' not in log, log
    # Without the robot the controller has nothing to command: the world does not wait for it.
    api.delete_model('one_DOF_robot')
    api.reset_simulation()
    ros.terminate(proc)
    return q


def in_process_rest_angle(engine):
    """The tutorial's first phase on the core with no ROS in between (the cross-validation's run)."""
    from onedof_sim.reference.cross_validation import ToolEngine, settled
    return settled(ToolEngine(engine).scenario(), 0)


def test_book_shaped_cpp_controller_rests_where_the_rospy_controller_does(
        ros, engine, sim_time_client, book_client_setup):
    rospy = sim_time_client
    setup = book_client_setup
    sim = start_sim(ros, engine, LOCKSTEP)
    api = GazeboApi(rospy)
    from std_msgs.msg import Float64
    pos_cmd = rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)
    q_cpp = rest_angle(ros, api, sim, pos_cmd, COMMAND,
                       book_client.command(setup), 'book_controller')
    pos_cmd.publish(Float64(0.0))
    q_rospy = rest_angle(ros, api, sim, pos_cmd, COMMAND,
                         ['rosrun', 'minimal_joint_controller', 'minimal_joint_controller'],
                         'minimal_joint_controller')
    reference = in_process_rest_angle(engine)
    assert abs(q_cpp - q_rospy) < SAME, (q_cpp, q_rospy)
    assert abs(q_cpp - reference) < SAME, (q_cpp, reference)
    assert q_cpp == pytest.approx(physics.settled_angle(COMMAND), abs=1e-4)
