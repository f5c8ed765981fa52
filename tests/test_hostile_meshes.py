"""Hostile mesh files over real ROS on every engine, each given as a URDF's <mesh filename> to
spawn_urdf_model: COLLADA nested 10,000 nodes deep, a node that instances itself, one triangle
instanced 4^10 times, a format Gazebo does not read. The node answers each with the reason,
stays up with its world as it was, and another client's get_world_properties answers meanwhile.
Paths: model:// and package:// URIs that climb out of their folders name no file; such a URI, an
unreadable file and a missing one are all left out in the same words, which tell a caller
nothing of which files exist. The files are made in the test's temporary folder."""
import os
import threading

import pytest

from api_client import BOX_SDF, GazeboApi, pose
from conftest import GROUND, WORKSPACE
from onedof_harness.private_ros import wait_until

MODELS = os.path.join(WORKSPACE, 'tests', 'mesh_models')


def shared_sim_env(env):
    """The module's simulators' model path and package path hold our test model (conftest)."""
    return {'GAZEBO_MODEL_PATH': MODELS,
            'ROS_PACKAGE_PATH': MODELS + os.pathsep + env.get('ROS_PACKAGE_PATH', '')}


TRIANGLE = ('<library_geometries><geometry id="g"><mesh>'
            '<source id="p"><float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array>'
            '<technique_common><accessor source="#pa" count="3" stride="3">'
            '<param name="X" type="float"/><param name="Y" type="float"/>'
            '<param name="Z" type="float"/></accessor></technique_common></source>'
            '<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>'
            '<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/>'
            '<p>0 1 2</p></triangles></mesh></geometry></library_geometries>')


def collada(library, scene):
    return ('<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" '
            'version="1.4.1"><asset><unit meter="1"/><up_axis>Z_UP</up_axis></asset>' + TRIANGLE +
            '<library_nodes>' + library + '</library_nodes><library_visual_scenes>'
            '<visual_scene id="s">' + scene + '</visual_scene></library_visual_scenes>'
            '<scene><instance_visual_scene url="#s"/></scene></COLLADA>')


def nested(levels):
    return collada('', '<node>' * levels + '<instance_geometry url="#g"/>' + '</node>' * levels)


def fan_out(levels, fan):
    """level0 places `fan` instances of level1, ...; the last places `fan` triangles."""
    library = ''
    for level in range(levels):
        inner = ('<instance_node url="#level%d"/>' % (level + 1) if level + 1 < levels
                 else '<instance_geometry url="#g"/>')
        library += '<node id="level%d">%s</node>' % (level, inner * fan)
    return collada(library, '<node><instance_node url="#level0"/></node>')


SELF_INSTANCING = collada('<node id="loop"><instance_geometry url="#g"/>'
                          '<instance_node url="#loop"/></node>',
                          '<node><instance_node url="#loop"/></node>')

HOSTILE = {
    'nested.dae': (nested(10000), 'nests its XML elements more than 100 deep; at most 100 levels '
                                  'are accepted'),
    'loop.dae': (SELF_INSTANCING, 'has a node that instances itself: loop -> loop'),
    'fan.dae': (fan_out(10, 4), 'places 1398102 nodes and geometry instances; at most 20000 are '
                                'accepted'),
    'cube.ply': ('ply\nformat ascii 1.0\nend_header\n',
                 'is not STL (.stl), COLLADA (.dae) or OBJ (.obj), the formats Gazebo reads'),
}


def mesh_urdf(filename):
    return ('<robot name="floor"><link name="world"/><joint name="glue" type="fixed">'
            '<parent link="world"/><child link="floor"/></joint><link name="floor"><collision>'
            '<geometry><mesh filename="%s"/></geometry></collision></link></robot>' % filename)


def world_state(api):
    world = api.get_world_properties()
    poses = [api.get_model_state(name, '').pose for name in world.model_names]
    return world.model_names, poses


class Poller:
    """Another client calling get_world_properties over and over until stopped: every answer
    must be a success."""

    def __init__(self, rospy_client):
        self.api = GazeboApi(rospy_client)
        self.answers, self.failures = 0, []
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self.poll, daemon=True)

    def poll(self):
        while not self.stopping.is_set():
            try:
                res = self.api.get_world_properties()
                if res.success:
                    self.answers += 1
                else:
                    self.failures.append(res.status_message)
            except Exception as error:  # the node gone: recorded, the test says so
                self.failures.append(repr(error))
                return

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.stopping.set()
        self.thread.join(60)


@pytest.fixture
def api(shared_sim):
    """The module's paused simulator of each engine with a box in its world."""
    res = shared_sim.spawn_sdf_model('box', BOX_SDF, '', pose(z=0.5), '')
    assert res.success, res.status_message
    return shared_sim


@pytest.mark.parametrize('case', sorted(HOSTILE))
def test_a_hostile_mesh_is_refused_the_node_up_its_world_intact(api, rospy_client, tmp_path,
                                                                case):
    data, reason = HOSTILE[case]
    path = tmp_path / case
    path.write_text(data)
    before = world_state(api)
    with Poller(rospy_client) as other:
        wait_until(lambda: other.answers > 0 or other.failures, 60,
                   what='the other client to be answered')
        res = api.spawn_urdf_model('hostile', mesh_urdf(str(path)), '', pose(), '')
        assert not res.success, res.status_message
        assert "the mesh file %s %s" % (path, reason) in res.status_message, res.status_message
        answered = other.answers
        wait_until(lambda: other.answers > answered or other.failures, 60,
                   what='the other client to be answered after the refusal')
    assert other.failures == [], other.failures
    assert world_state(api) == before
    res = api.step_simulation(10)
    assert res.success, res.status_message
    assert api.get_world_properties().model_names == [GROUND, 'box']


def test_paths_out_of_their_folders_unreadable_and_missing_are_alike(api, tmp_path):
    """model:// and package:// confined to their folders; each file that cannot be read is left
    out in the words of a missing one. `file://` meshes are the user's own: one outside the
    model path loads."""
    outside = tmp_path / 'elsewhere'
    outside.mkdir()
    block = os.path.join(MODELS, 'onedof_mesh_block', 'meshes', 'unit_block.stl')
    with open(block, 'rb') as source:
        (outside / 'x.stl').write_bytes(source.read())
    unreadable = tmp_path / 'models' / 'locked.stl'
    unreadable.parent.mkdir()
    unreadable.write_bytes((outside / 'x.stl').read_bytes())
    unreadable.chmod(0)
    climb = '../' * (len(MODELS.split('/')) + 2) + str(outside / 'x.stl').lstrip('/')
    uris = ['model://' + climb,
            'model://onedof_mesh_block/../../../../../../../../../..' + str(outside / 'x.stl'),
            'package://onedof_mesh_block/' + climb,
            'model:///' + str(outside / 'x.stl').lstrip('/'),
            'model://onedof_mesh_block/meshes/gone.stl']
    # Files that exist but are no readable regular file: a folder and a FIFO (never opened: it
    # would wait for a writer) named as meshes, and a file of mode 0 (which root reads).
    folder = tmp_path / 'folder.stl'
    folder.mkdir()
    fifo = tmp_path / 'pipe.stl'
    os.mkfifo(str(fifo))
    uris += ['file://' + str(folder), 'file://' + str(fifo)]
    if os.geteuid() != 0:
        uris.append('file://' + str(unreadable))
    for index, uri in enumerate(uris):
        name = 'climb%d' % index
        res = api.spawn_urdf_model(name, mesh_urdf(uri), '', pose(), '')
        assert res.success, res.status_message
        assert ("the mesh '%s', which is not found or not readable (model:// and package:// URIs "
                "are looked up within " % uri) in res.status_message, (uri, res.status_message)
        assert api.get_model_properties(name).geom_names == [], uri
        assert api.delete_model(name).success
    # file:// is not confined.
    res = api.spawn_urdf_model('own', mesh_urdf('file://' + str(outside / 'x.stl')), '', pose(), '')
    assert res.success and 'warning' not in res.status_message, res.status_message
    assert api.get_model_properties('own').geom_names == ['floor_collision']
