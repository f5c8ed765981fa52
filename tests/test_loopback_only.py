"""The main job and the tests listen on loopback only: the tutorial's nodes,
started through PrivateRos as the player starts them, bind no TCP or UDP socket to the wildcard or
to an external address, even when the user's shell names the machine in ROS_HOSTNAME.

ROS 1 exposes a node with no authentication: anyone who reaches its XML-RPC port can shut it down,
and anyone who reaches the simulator's services can move or spawn models.
"""
import ipaddress
import os
import socket

import pytest

from listening import WILDCARD, listening_sockets, process_tree
from onedof_harness.private_ros import wait_until
from onedof_sim.tutorial.rviz_view import RvizView


@pytest.fixture
def networked_shell(monkeypatch):
    """The shell of a user whose ROS talks to other machines: ROS_HOSTNAME names this one."""
    monkeypatch.setenv('ROS_HOSTNAME', socket.gethostname())
    monkeypatch.delenv('ROS_IP', raising=False)


def sockets_with_rviz_up(ros, rviz):
    """The listening sockets of this process and of every process the test started, listed while
    rviz runs: rviz on software GL now and then crashes (its view then starts another), and a
    crashed rviz holds no socket to check."""
    while True:
        assert rviz.wait_until_up(), 'rviz did not come up: %s' % '; '.join(rviz.failures)
        running = rviz.rviz
        # This process's rospy stands for the player's own node.
        ours = set.union({os.getpid()}, *(process_tree(proc.pid) for proc in ros.processes))
        sockets = [s for s in listening_sockets() if s.pid in ours]
        if running.poll() is None:
            return sockets


def rviz_sockets_text(pid):
    """What rviz (pid) holds: whether it runs, its socket descriptors, and its listening sockets
    as ss lists them, for a failure's message."""
    def is_socket(fd):
        try:
            return os.readlink('/proc/%d/fd/%s' % (pid, fd)).startswith('socket:')
        except OSError:  # closed since it was listed
            return False
    try:
        sockets = sum(map(is_socket, os.listdir('/proc/%d/fd' % pid)))
    except OSError as error:
        return 'pid %d: %s' % (pid, error)
    return 'pid %d runs with %d socket descriptors; listening: %s' % (
        pid, sockets, [s for s in listening_sockets() if s.pid == pid])


def test_the_tutorial_nodes_listen_on_loopback_only(networked_shell, ros, rospy_client, tmp_path):
    rospy = rospy_client
    from std_msgs.msg import Float64
    ros.start(['roslaunch', 'minimal_robot_description', 'minimal_robot_description.launch'],
              name='launch_simulator')
    ros.wait_for_service('/gazebo/get_model_state', 60)
    rviz = RvizView(ros, str(tmp_path))
    assert rviz.wait_until_up(), 'rviz did not come up: %s' % '; '.join(rviz.failures)
    ros.start(['rosrun', 'minimal_joint_controller', 'minimal_joint_controller'],
              name='controller')
    positions = []
    rospy.Subscriber('/jnt_pos', Float64, lambda msg: positions.append(msg.data))
    ros.start(['rostopic', 'pub', 'pos_cmd', 'std_msgs/Float64', '1.0'], name='pos_cmd')
    wait_until(lambda: positions, 60, what='jnt_pos from the controller')

    sockets = sockets_with_rviz_up(ros, rviz)
    programs = {s.program for s in sockets}
    for expected in ('rosmaster', 'rosout', 'roslaunch', 'onedof_sim', 'robot_state_publisher',
                     'rviz', 'minimal_joint_controller', 'rostopic'):
        assert expected in programs, 'no socket of %s found among %s; rviz: %s' % (
            expected, sorted(programs), rviz_sockets_text(rviz.rviz.pid))
    assert os.getpid() in {s.pid for s in sockets}, 'no socket of this process\'s rospy found'
    exposed = {(s.program, s.protocol, s.address) for s in sockets
               if s.address == WILDCARD or not ipaddress.ip_address(s.address).is_loopback}
    assert not exposed, 'listening beyond loopback: %s' % sorted(exposed)
