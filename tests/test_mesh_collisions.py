"""Mesh collisions over real ROS on every engine: a model of our own (tests/mesh_models/
onedof_mesh_block) standing on two feet, an STL block and a COLLADA wedge with a gap between them
under its centre of mass, spawned as URDF with package:// URIs and as SDF with model:// URIs,
rests level on the ground where its geometry says; meshes past the triangle limit, missing,
unreadable or in an unknown package are refused naming the limit, the file or the package."""
import math
import os
import struct

import pytest

from api_client import pose
from conftest import GROUND, WORKSPACE

MODELS = os.path.join(WORKSPACE, 'tests', 'mesh_models')
MODEL = os.path.join(MODELS, 'onedof_mesh_block')
URDF = os.path.join(MODEL, 'urdf', 'onedof_mesh_block.urdf')
SDF = os.path.join(MODEL, 'model.sdf')

# How far the resting body may sink into the ground or float above it, and tilt: the allowance of
# the core's box-on-the-ground test (ODE's 1 mm contact layer and soft contacts, Bullet's slop and
# margin: a body at rest sinks about a millimetre), and 1 degree. Without either foot the centre
# of mass is over the gap and the body tips over, ending tens of degrees off level.
SINK, FLOAT, MAX_TILT = 0.005, 0.001, math.radians(1)


def shared_sim_env(env):
    """The module's simulators' model path and package path hold our test model (conftest)."""
    return {'GAZEBO_MODEL_PATH': MODELS,
            'ROS_PACKAGE_PATH': MODELS + os.pathsep + env.get('ROS_PACKAGE_PATH', '')}


@pytest.fixture
def api(shared_sim):
    """The module's paused simulator of each engine, with no model (conftest's shared_sim)."""
    return shared_sim


def read(path):
    with open(path) as f:
        return f.read()


def tilt(orientation):
    """The angle between the body's z axis and the world's."""
    q = orientation
    return math.acos(max(-1.0, min(1.0, 1 - 2 * (q.x * q.x + q.y * q.y))))


def assert_rests_level_on_the_ground(api, name):
    res = api.step_simulation(2000)
    assert res.success, res.status_message
    state = api.get_model_state(name, '')
    assert state.success, state.status_message
    sink = -state.pose.position.z
    speed = math.sqrt(state.twist.linear.x ** 2 + state.twist.linear.y ** 2 +
                      state.twist.linear.z ** 2)
    figures = 'sinks %.2f mm, tilt %.2f mrad, speed %.1e m/s' % (1000 * sink,
                                                              1000 * tilt(state.pose.orientation),
                                                              speed)
    assert -FLOAT < sink < SINK, figures
    assert tilt(state.pose.orientation) < MAX_TILT, figures
    assert speed < 1e-3, figures


def test_urdf_with_package_uris_rests_on_its_stl_and_collada_feet(api):
    res = api.spawn_urdf_model('mesh_block', read(URDF), '', pose(z=0.2), '')
    assert res.success, res.status_message
    props = api.get_model_properties('mesh_block')
    assert sorted(props.geom_names) == ['block', 'wedge']
    assert_rests_level_on_the_ground(api, 'mesh_block')


def test_sdf_with_model_uris_rests_on_its_stl_and_collada_feet(api):
    res = api.spawn_sdf_model('mesh_block', read(SDF), '', pose(z=0.2), '')
    assert res.success, res.status_message
    assert_rests_level_on_the_ground(api, 'mesh_block')


def binary_stl(triangles):
    """A binary STL of that many small triangles."""
    data = [b'\0' * 80, struct.pack('<I', triangles)]
    for t in range(triangles):
        x, y = 0.001 * (t % 1000), 0.001 * (t // 1000)
        data.append(struct.pack('<12fH', 0, 0, 1, x, y, 0, x + 0.001, y, 0, x, y + 0.001, 0, 0))
    return b''.join(data)


def static_mesh_urdf(filename):
    return ('<robot name="floor"><link name="world"/><joint name="glue" type="fixed">'
            '<parent link="world"/><child link="floor"/></joint><link name="floor"><collision>'
            '<geometry><mesh filename="%s"/></geometry></collision></link></robot>' % filename)


def test_meshes_past_the_limit_unreadable_or_unknown_are_refused_missing_left_out(api, tmp_path):
    def refused(filename):
        res = api.spawn_urdf_model('floor', static_mesh_urdf(filename), '', pose(), '')
        assert not res.success, res.status_message
        return res.status_message

    past = tmp_path / 'past.stl'
    past.write_bytes(binary_stl(20001))
    assert ('the mesh file %s has 20001 triangles; at most 20000 are accepted per mesh' % past
            in refused('file://%s' % past))

    # A mesh found nowhere: the model is spawned without that collision, as Gazebo spawns it.
    for name, filename, text in (
            ('gone_stl', 'package://onedof_mesh_block/meshes/gone.stl',
             "the mesh '%s/meshes/gone.stl', which is not found" % MODEL),
            ('gone_dae', 'model://onedof_mesh_block/meshes/gone.dae',
             "the mesh 'model://onedof_mesh_block/meshes/gone.dae', which is not found or not "
             "readable (model:// and package:// URIs are looked up within ")):
        res = api.spawn_urdf_model(name, static_mesh_urdf(filename), '', pose(), '')
        assert res.success, res.status_message
        assert 'SpawnModel: Successfully spawned entity; warning: link ' in res.status_message
        assert text in res.status_message and 'the collision is left out' in res.status_message
        assert api.get_model_properties(name).geom_names == []
        assert api.delete_model(name).success

    broken = tmp_path / 'broken.dae'
    broken.write_text('<COLLADA/>')
    assert 'cannot read the mesh file %s: ' % broken in refused(str(broken))

    # gazebo_ros' own answer for a package it cannot find.
    assert (refused('package://no_such_package/meshes/x.stl')
            == 'urdf reference package name does not exist: no_such_package')
    assert api.get_world_properties().model_names == [GROUND]

    # Prose that names the scheme is no package (gazebo_ros would look " URIs (see ..." up).
    commented = static_mesh_urdf('package://onedof_mesh_block/meshes/unit_block.stl').replace(
        '<link name="world"/>', '<!-- meshes by package:// URIs (see the README/) --><link name="world"/>')
    res = api.spawn_urdf_model('floor', commented, '', pose(z=-1), '')
    assert res.success, res.status_message
