"""The main job and the tests listen on loopback only (issue 12, finding 11): the tutorial's nodes,
started through PrivateRos as the player starts them, bind no TCP or UDP socket to the wildcard or
to an external address, even when the user's shell names the machine in ROS_HOSTNAME.

ROS 1 exposes a node with no authentication: anyone who reaches its XML-RPC port can shut it down,
and anyone who reaches the simulator's services can move or spawn models.
"""
import ipaddress
import os
import socket

import psutil
import pytest

from onedof_sim.private_ros import wait_until
from onedof_sim.tutorial.player import RvizView


@pytest.fixture
def networked_shell(monkeypatch):
    """The shell of a user whose ROS talks to other machines: ROS_HOSTNAME names this one."""
    monkeypatch.setenv('ROS_HOSTNAME', socket.gethostname())
    monkeypatch.delenv('ROS_IP', raising=False)


def program(cmdline):
    """The program a command line runs: the script for a Python interpreter."""
    words = [os.path.basename(word) for word in cmdline]
    if words[0].startswith('python'):
        words = [word for word in words[1:] if not word.startswith('-')]
    return words[0]


def bound_sockets(pid):
    """(program, protocol, address) of every listening TCP socket and bound UDP socket of pid and
    its descendants."""
    sockets = []
    try:
        root = psutil.Process(pid)
        processes = [root] + root.children(recursive=True)
    except psutil.NoSuchProcess:
        return sockets
    for process in processes:
        try:
            name = program(process.cmdline())
            for connection in process.connections(kind='inet'):
                if connection.type == socket.SOCK_STREAM and connection.status == psutil.CONN_LISTEN:
                    sockets.append((name, 'tcp', connection.laddr.ip))
                elif connection.type == socket.SOCK_DGRAM and connection.laddr:
                    sockets.append((name, 'udp', connection.laddr.ip))
        except psutil.NoSuchProcess:
            continue
    return sockets


def test_the_tutorial_nodes_listen_on_loopback_only(networked_shell, ros, rospy_client, tmp_path):
    rospy = rospy_client
    from std_msgs.msg import Float64
    ros.start(['roslaunch', 'minimal_robot_description', 'minimal_robot_description.launch'],
              name='launch_simulator')
    ros.wait_for_service('/gazebo/get_model_state', 60)
    rviz = RvizView(ros, str(tmp_path))
    rviz.wait_until_up()
    ros.start(['rosrun', 'minimal_joint_controller', 'minimal_joint_controller'],
              name='controller')
    positions = []
    rospy.Subscriber('/jnt_pos', Float64, lambda msg: positions.append(msg.data))
    ros.start(['rostopic', 'pub', 'pos_cmd', 'std_msgs/Float64', '1.0'], name='pos_cmd')
    wait_until(lambda: positions, 60, what='jnt_pos from the controller')

    sockets = [s for proc in ros.processes for s in bound_sockets(proc.pid)]
    sockets += bound_sockets(os.getpid())  # this process's rospy, as the player's own node
    programs = {name for name, _, _ in sockets}
    for expected in ('rosmaster', 'rosout', 'roslaunch', 'onedof_sim', 'robot_state_publisher',
                     'rviz', 'minimal_joint_controller', 'rostopic', 'pytest'):
        assert expected in programs, 'no socket of %s found among %s' % (expected, sorted(programs))
    exposed = [s for s in sockets if not ipaddress.ip_address(s[2]).is_loopback]
    assert not exposed, 'listening beyond loopback: %s' % sorted(set(exposed))
