"""The model-plugin seam over real ROS: a plugin named by a spawned URDF's <gazebo><plugin> is
created with its model, called before and after every step under the world lock, in sim time, and
is gone after delete_model; an unknown plugin filename is logged once by name and the model spawns.

The simulator here is the test build's node with one plugin more than the registry's,
libonedof_sim_hook_probe.so (src/onedof_sim/test/plugins/hook_probe_node.cpp), which tells each
hook call on <robotNamespace>/hook_probe."""
import pytest

from api_client import GazeboApi, STEP_NS, pose, tutorial_urdf
from conftest import ENGINES
from onedof_harness.private_ros import wait_until

PROBE_TOPIC = '/probe/hook_probe'
UNKNOWN = 'libgazebo_ros_not_simulated_here.so'


def probed_urdf():
    """The tutorial robot with the probe and two uses of a plugin the simulator does not have."""
    plugins = """
  <gazebo><plugin name="probe" filename="libonedof_sim_hook_probe.so">
    <robotNamespace>/probe</robotNamespace></plugin></gazebo>
  <gazebo reference="link2"><plugin name="first" filename="%s"/></gazebo>
  <gazebo><plugin name="second" filename="%s"/></gazebo>
</robot>""" % (UNKNOWN, UNKNOWN)
    return tutorial_urdf().replace('</robot>', plugins)


@pytest.fixture(params=ENGINES)
def probe_sim(request, ros, rospy_client):
    proc = ros.start(['rosrun', 'onedof_sim', 'onedof_sim_hook_probe_node',
                      '_physics:=' + request.param, '_enable_step_simulation:=true', '-u'],
                     name='probe_sim')
    wait_until(lambda: proc.poll() is not None or ros.has_service('/gazebo/unpause_physics'), 60,
               what='the probe simulator')
    assert proc.poll() is None, ros.log_text(proc)
    return proc


def test_a_plugin_sees_its_hooks_in_order_in_sim_time_and_is_gone_after_delete(
        ros, rospy_client, probe_sim):
    rospy = rospy_client
    from std_msgs.msg import String
    api = GazeboApi(rospy)
    told = []
    rospy.Subscriber(PROBE_TOPIC, String, lambda msg: told.append(msg.data), queue_size=100000)
    spawned = api.spawn_urdf_model('probed', probed_urdf(), '', pose(), '')
    assert spawned.success, spawned.status_message
    # Its messages reach this subscriber once the connection is up: step one at a time until
    # they do, then until the last step's two calls are in.
    stepped_to = []

    def step_and_heard():
        stepped_to.append(api.step_simulation(1).iterations)
        return told
    wait_until(step_and_heard, 30, what='the probe to tell its hook calls')
    first = stepped_to[-1]  # steps done so far
    wait_until(lambda: told[-1] == 'after %d %d' % (first * STEP_NS, first), 30,
               what="the last warm-up step's after-hook")
    start = len(told)

    steps = 50
    assert api.step_simulation(steps).success
    wait_until(lambda: len(told) >= start + 2 * steps, 30,
               what='the probe to tell %d hook calls' % (2 * steps))
    expected = []
    for step in range(first, first + steps):
        expected.append('before %d %d' % (step * STEP_NS, step))
        expected.append('after %d %d' % ((step + 1) * STEP_NS, step + 1))
    assert told[start:] == expected

    api.reset_world()
    assert api.step_simulation(1).success
    wait_until(lambda: len(told) >= start + 2 * steps + 3, 30, what='reset and one more step')
    assert told[start + 2 * steps] == 'reset'

    deleted = api.delete_model('probed')
    assert deleted.success, deleted.status_message
    wait_until(lambda: not any(name == PROBE_TOPIC for name, _ in rospy.get_published_topics()),
               30, what='the probe to be gone with its model')
    count = len(told)
    assert api.step_simulation(10).success
    assert len(told) == count  # no hook of a deleted model's plugin runs

    log = ros.log_text(probe_sim)
    assert log.count(UNKNOWN) == 1, log  # logged once, by name, for its two uses
    assert "model 'probed': Failed to load plugin" in log, log


def test_a_plugin_without_a_robot_namespace_takes_the_spawn_requests(
        ros, rospy_client, probe_sim):
    """As Gazebo's spawn services do: the request's robot_namespace becomes the <robotNamespace>
    of each plugin that has none; a plugin's own stays; an empty request's leaves it at '/'."""
    rospy = rospy_client
    api = GazeboApi(rospy)
    urdf = tutorial_urdf().replace('</robot>', """
  <gazebo><plugin name="defaulted" filename="libonedof_sim_hook_probe.so"/></gazebo>
  <gazebo><plugin name="own" filename="libonedof_sim_hook_probe.so">
    <robotNamespace>/probe</robotNamespace></plugin></gazebo>
</robot>""")
    spawned = api.spawn_urdf_model('namespaced', urdf, '/r1', pose(), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_urdf_model('plain', urdf.replace('/probe<', '/probe2<'), '', pose(x=2.0),
                                   '')
    assert spawned.success, spawned.status_message

    def topics():
        return {name for name, _ in rospy.get_published_topics()}
    expected = {'/r1/hook_probe', '/probe/hook_probe', '/hook_probe', '/probe2/hook_probe'}
    wait_until(lambda: expected <= topics(), 30, what="the probes' topics")
    assert not any(name.startswith('/r1/') and name != '/r1/hook_probe' for name in topics())
