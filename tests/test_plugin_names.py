"""A spawn is whole or nothing, over real ROS on every engine: a plugin parameter that names a ROS
namespace, topic or service with a name roscpp refuses (a space, a non-ASCII letter, "::") is
refused with the parameter and the value named, before the model enters the world; nothing of it
is left, and the same model with a good name spawns. Every plugin of the registry
(src/onedof_sim/src/ros/plugins/registry.cpp), model and sensor plugins, with each of its name
parameters. A plugin that fails to start for a name the check does not read (a namespace made
from the model's name) takes its model back out of the world. A plugin whose other parameters it
refuses is left out and the model spawns, as in Gazebo, and the answer says why.
"""
import os
import re

from api_client import pose, tutorial_urdf
from conftest import GROUND

REGISTRY = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'src', 'onedof_sim',
                        'src', 'ros', 'plugins', 'registry.cpp')

CAMERA = ['robotNamespace', 'cameraName', 'imageTopicName', 'cameraInfoTopicName']
DEPTH = CAMERA + ['depthImageTopicName', 'depthImageCameraInfoTopicName', 'pointCloudTopicName']
# Each plugin's sensor type (None: a model plugin) and the parameters it takes ROS names from.
PLUGINS = {
    'libgazebo_ros_control.so': (None, ['robotNamespace']),
    'libgazebo_ros_diff_drive.so': (None, ['robotNamespace', 'commandTopic', 'odometryTopic']),
    'libgazebo_ros_ft_sensor.so': (None, ['robotNamespace', 'topicName']),
    'libgazebo_ros_imu.so': (None, ['robotNamespace', 'topicName', 'serviceName']),
    'libgazebo_ros_joint_state_publisher.so': (None, ['robotNamespace']),
    'libgazebo_ros_p3d.so': (None, ['robotNamespace', 'topicName']),
    'libgazebo_ros_block_laser.so': ('ray', ['robotNamespace', 'topicName']),
    'libgazebo_ros_bumper.so': ('contact', ['robotNamespace', 'bumperTopicName']),
    'libgazebo_ros_camera.so': ('camera', CAMERA),
    'libgazebo_ros_depth_camera.so': ('depth', DEPTH),
    'libgazebo_ros_gpu_laser.so': ('gpu_ray', ['robotNamespace', 'topicName']),
    'libgazebo_ros_imu_sensor.so': ('imu', ['robotNamespace', 'topicName']),
    'libgazebo_ros_laser.so': ('ray', ['robotNamespace', 'topicName']),
    'libgazebo_ros_multicamera.so': ('multicamera', CAMERA),
    'libgazebo_ros_openni_kinect.so': ('depth', DEPTH),
    'libgazebo_ros_range.so': ('ray', ['robotNamespace', 'topicName']),
    'libgazebo_ros_triggered_camera.so': ('camera', CAMERA + ['triggerTopicName']),
}
BAD_NAMES = ['cmd vel', 'cam\u00e9ra', 'a::b']


def registered_filenames():
    with open(REGISTRY) as f:
        return set(re.findall(r'\{"(lib[a-z0-9_]+\.so)"', f.read()))


def with_plugin(filename, params):
    """The tutorial robot with one plugin, its parameters as given (tag: text)."""
    sensor_type, _ = PLUGINS[filename]
    body = ''.join('<%s>%s</%s>' % (tag, text, tag) for tag, text in params.items())
    plugin = '<plugin name="p" filename="%s">%s</plugin>' % (filename, body)
    if sensor_type is None:
        block = '<gazebo>%s</gazebo>' % plugin
    else:
        block = ('<gazebo reference="link2"><sensor type="%s" name="s">%s</sensor></gazebo>'
                 % (sensor_type, plugin))
    return tutorial_urdf().replace('</robot>', block + '</robot>')


def assert_nothing_left(api):
    world = api.get_world_properties()
    assert world.model_names == [GROUND], world.model_names


def test_every_plugins_name_parameters_are_checked_before_the_model_enters_the_world(shared_sim):
    api = shared_sim
    assert registered_filenames() == set(PLUGINS)
    for filename, (_, tags) in sorted(PLUGINS.items()):
        for tag in tags:
            for bad in BAD_NAMES:
                res = api.spawn_urdf_model('robot', with_plugin(filename, {tag: bad}), '',
                                           pose(), '')
                case = '%s <%s>%s' % (filename, tag, bad)
                assert not res.success, case
                assert res.status_message.startswith('SpawnModel: '), (case, res.status_message)
                assert ("plugin 'p' (%s" % filename) in res.status_message, \
                    (case, res.status_message)
                assert ("<%s> '%s' is not a valid ROS name" % (tag, bad)) in res.status_message, \
                    (case, res.status_message)
                assert_nothing_left(api)
        res = api.spawn_urdf_model('robot', with_plugin(filename, {tags[-1]: 'good_name'}), '',
                                   pose(), '')
        assert res.success, (filename, res.status_message)
        res = api.delete_model('robot')
        assert res.success, (filename, res.status_message)


def test_the_spawn_requests_robot_namespace_is_checked_as_the_plugins_own(shared_sim):
    api = shared_sim
    urdf = with_plugin('libgazebo_ros_p3d.so', {'bodyName': 'link2', 'topicName': 'odom'})
    res = api.spawn_urdf_model('robot', urdf, 'bad ns', pose(), '')
    assert not res.success
    assert "<robotNamespace> 'bad ns' is not a valid ROS name" in res.status_message, \
        res.status_message
    assert_nothing_left(api)
    res = api.spawn_urdf_model('robot', urdf, 'good_ns', pose(), '')
    assert res.success, res.status_message


def test_a_plugin_that_fails_to_start_takes_its_model_back_out(shared_sim):
    """gazebo_ros_imu_sensor without <robotNamespace> is in /<model name>: a model named with a
    space leaves roscpp a namespace it refuses as the plugin starts."""
    api = shared_sim
    urdf = with_plugin('libgazebo_ros_imu_sensor.so', {'frameName': 'link2', 'topicName': 'imu'})
    res = api.spawn_urdf_model('my robot', urdf, '', pose(), '')
    assert not res.success
    assert res.status_message.startswith('SpawnModel: a plugin of the model failed to start, so '
                                         'the model was not spawned: '), res.status_message
    assert_nothing_left(api)
    res = api.spawn_urdf_model('my_robot', urdf, '', pose(), '')
    assert res.success, res.status_message
    assert api.get_world_properties().model_names == [GROUND, 'my_robot']


def test_a_plugin_left_out_for_its_parameters_is_named_in_the_answer(shared_sim):
    """As in Gazebo the model spawns without the plugin; the answer says which and why."""
    api = shared_sim
    urdf = with_plugin('libgazebo_ros_p3d.so', {'topicName': 'odom'})  # no <bodyName>
    res = api.spawn_urdf_model('robot', urdf, '', pose(), '')
    assert res.success, res.status_message
    assert res.status_message.startswith('SpawnModel: Successfully spawned entity; warning: '
                                         'libgazebo_ros_p3d.so for model \'robot\' not started: '), \
        res.status_message
    assert api.get_world_properties().model_names == [GROUND, 'robot']
