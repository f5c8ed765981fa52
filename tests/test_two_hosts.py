"""ROS across two hosts: the simulator and the tutorial's controller on two
network namespaces joined by a virtual link, as on two machines, set up as docker/compose.yaml
sets up its two services.

The "sim" host (10.77.0.1) runs roscore and the tutorial's launch file; the "controller" host
(10.77.0.2) runs the controller and `rostopic pub pos_cmd`, with ROS_MASTER_URI at the sim host.
Each side has ROS_IP set to its own address. The arm must settle where it settles on one machine,
and every node must listen on its own host's address only. This test process joins the sim host
(its rospy is a client there), so it needs pytest-forked and root (`ip netns`).
"""
import ctypes
import os
import subprocess
import uuid

import pytest

from api_client import GazeboApi
from conftest import running_graph
from listening import listening_sockets, process_tree
from onedof_harness.private_ros import PrivateRos, listening_environment, wait_until
from onedof_sim.tutorial import physics
from test_controller import Topic

SIM_ADDRESS = '10.77.0.1'
CONTROLLER_ADDRESS = '10.77.0.2'
PREFIX_LENGTH = 24
CLONE_NEWNET = 0x40000000
COMMAND = 1.0
LOCKSTEP = 'lockstep:=true'  # the controller's every period, however slow the link
SETTLE_WINDOW = 1.0  # s of sim time the link must stay within SETTLE_BAND to count as settled
SETTLE_BAND = 0.01
# The closed form neglects nothing but missed periods; a missed period or two moves the rest
# position by millirad.
TOLERANCE = 0.02


def ip(*args):
    return subprocess.run(['ip'] + list(args), capture_output=True, text=True, timeout=60)


class HostsUnavailable(Exception):
    """The two hosts cannot be made on this machine: the step that failed, and why."""


def run_ip(*args):
    result = ip(*args)
    if result.returncode != 0:
        raise HostsUnavailable('ip %s: %s' % (' '.join(args), result.stderr.strip()))


class TwoHosts:
    """Two network namespaces, each with loopback up and one end of a veth pair holding its
    address. Names carry a random tag, so that runs side by side never share one."""

    def __init__(self):
        tag = uuid.uuid4().hex[:8]
        self.sim, self.controller = 'onedof-sim-' + tag, 'onedof-ctl-' + tag
        self.links = {self.sim: ('ods' + tag, SIM_ADDRESS),
                      self.controller: ('odc' + tag, CONTROLLER_ADDRESS)}

    def create(self):
        """Makes both hosts, or raises HostsUnavailable at the first step that fails: namespaces
        may be added where they cannot be entered (a chroot or a container, whose / is no mount
        point that `ip -n` and `ip netns exec` can make a slave)."""
        for netns in self.links:
            run_ip('netns', 'add', netns)
        (sim_link, _), (controller_link, _) = self.links.values()
        run_ip('link', 'add', sim_link, 'type', 'veth', 'peer', 'name', controller_link)
        for netns, (link, address) in self.links.items():
            run_ip('link', 'set', link, 'netns', netns)
            run_ip('-n', netns, 'addr', 'add', '%s/%d' % (address, PREFIX_LENGTH), 'dev', link)
            run_ip('-n', netns, 'link', 'set', link, 'up')
            run_ip('-n', netns, 'link', 'set', 'lo', 'up')
            # How the test starts the controller host's programs.
            run_ip('netns', 'exec', netns, 'true')

    def remove(self):
        """Removes whatever create() made, also when it stopped half-way."""
        # Deleting a namespace deletes its end of the veth pair, and with it the other end; a
        # pair not yet moved into them is deleted where it is.
        ip('link', 'delete', self.links[self.sim][0])
        for netns in self.links:
            ip('netns', 'delete', netns)

    def enter(self, netns):
        """Moves this (single-threaded, forked) process into netns."""
        libc = ctypes.CDLL(None, use_errno=True)
        try:
            handle = open('/run/netns/' + netns)
        except OSError as error:
            raise HostsUnavailable('open /run/netns/%s: %s' % (netns, error.strerror))
        with handle:
            if libc.setns(handle.fileno(), CLONE_NEWNET) != 0:
                error = ctypes.get_errno()
                raise HostsUnavailable('setns %s: %s' % (netns, os.strerror(error)))


@pytest.fixture
def two_hosts(request):
    if os.geteuid() != 0:
        pytest.skip('ip netns needs root')
    if not request.config.getoption('forked', False):
        pytest.skip('needs --forked: the test moves its own process into the sim host')
    hosts = TwoHosts()
    try:
        try:
            hosts.create()
            hosts.enter(hosts.sim)
        except HostsUnavailable as reason:
            pytest.skip('the two hosts (network namespaces) cannot be made here: %s' % reason)
        yield hosts
    finally:
        hosts.remove()


@pytest.fixture
def ros(request, tmp_path, two_hosts):
    """The sim host's roscore, with this process on the sim host (rospy_client joins it)."""
    graph = PrivateRos(log_dir=str(tmp_path / 'ros'), use_sim_time=True, address=SIM_ADDRESS)
    yield from running_graph(request, graph)


def on_controller_host(ros, two_hosts, args, name):
    """Starts args on the controller host, pointed at the sim host's roscore."""
    return ros.start(['ip', 'netns', 'exec', two_hosts.controller] + args, name=name,
                     env=listening_environment(CONTROLLER_ADDRESS))


def test_the_controller_on_another_host_holds_the_arm_where_it_does_on_one(two_hosts, ros,
                                                                          rospy_client):
    rospy = rospy_client
    from std_msgs.msg import Float64
    launch = ros.start(['roslaunch', 'minimal_robot_description',
                        'minimal_robot_description.launch', 'paused:=true', LOCKSTEP],
                       name='launch_simulator')
    api = GazeboApi(rospy)
    wait_until(lambda: launch.poll() is not None or api.get_model_state('one_DOF_robot', '').success,
               90, what='one_DOF_robot to be spawned')
    assert launch.poll() is None, 'roslaunch exited:\n' + ros.log_text(launch)

    # Past sim time 0, which is no valid time to a ROS node: the controller starts on the time
    # the paused world holds.
    api.step_simulation(10)
    controller = on_controller_host(
        ros, two_hosts, ['rosrun', 'minimal_joint_controller', 'minimal_joint_controller'],
        'controller')
    # Its first reading and effort job crossed the link: it is controlling.
    wait_until(lambda: controller.poll() is not None
               or 'controlling joint1' in ros.log_text(controller), 60,
               what='the controller on %s to reach the simulator' % CONTROLLER_ADDRESS)
    assert controller.poll() is None, 'controller exited:\n' + ros.log_text(controller)
    jnt_pos = Topic(rospy, '/jnt_pos', Float64)
    api.unpause_physics()
    start = rospy.get_time()
    publisher = on_controller_host(
        ros, two_hosts, ['rostopic', 'pub', 'pos_cmd', 'std_msgs/Float64', str(COMMAND)], 'pos_cmd')

    def settled():
        assert controller.poll() is None, 'controller exited:\n' + ros.log_text(controller)
        assert publisher.poll() is None, 'rostopic pub exited:\n' + ros.log_text(publisher)
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
    assert api.joint('joint1')[0] == pytest.approx(expected, abs=TOLERANCE)

    hosts = {two_hosts.sim: (SIM_ADDRESS, [proc for proc in ros.processes
                                           if proc not in (controller, publisher)]),
             two_hosts.controller: (CONTROLLER_ADDRESS, [controller, publisher])}
    expected_programs = {two_hosts.sim: {'rosmaster', 'rosout', 'roslaunch', 'onedof_sim'},
                         two_hosts.controller: {'minimal_joint_controller', 'rostopic'}}
    for netns, (address, processes) in hosts.items():
        ours = set.union(*(process_tree(proc.pid) for proc in processes))
        # This process's rospy is the test's probe, not one of the tutorial's nodes: started
        # before the bind library could be preloaded, it listens on the whole sim host.
        sockets = [s for s in listening_sockets(netns) if s.pid != os.getpid()]
        assert {s.pid for s in sockets} <= ours, 'strangers listening on %s: %s' % (netns, sockets)
        programs = {s.program for s in sockets}
        assert expected_programs[netns] <= programs, \
            'on %s, no socket of %s' % (netns, expected_programs[netns] - programs)
        elsewhere = {(s.program, s.protocol, s.address) for s in sockets if s.address != address}
        assert not elsewhere, 'on %s, listening beyond %s: %s' % (netns, address, elsewhere)
