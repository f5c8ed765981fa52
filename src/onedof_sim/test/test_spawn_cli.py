"""Unit tests of onedof_sim.tools.spawn_cli: spawn_model's arguments, the search of the model path
and the model XML sources."""
import io
import math
import os

import numpy as np
import pytest

from onedof_sim.tools import spawn_cli
from onedof_sim.tools.spawn_cli import SpawnError
from onedof_sim.transforms import quaternion_from_rpy

PACKAGE_MODELS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'models')
URDF = '<robot name="r"><link name="a"/></robot>'


def parse(line):
    return spawn_cli.parse_args(line.split())


def test_tutorial_robot_command():
    args = parse('-file minimal_robot_description.urdf -urdf -model one_DOF_robot')
    assert (args.file, args.urdf, args.sdf, args.model) == (
        'minimal_robot_description.urdf', True, False, 'one_DOF_robot')
    assert (args.x, args.y, args.z, args.R, args.P, args.Y) == (0, 0, 0, 0, 0, 0)
    assert (args.gazebo_namespace, args.reference_frame, args.robot_namespace) == ('/gazebo', '', None)
    assert (args.joints, args.unpause, args.bond, args.wait) == ([], False, False, None)
    assert spawn_cli.spawn_service_name(args) == '/gazebo/spawn_urdf_model'


def test_tutorial_table_command():
    args = parse('-database cafe_table -sdf -model cafe_table -x 0.85')
    assert (args.database, args.sdf, args.model, args.x) == ('cafe_table', True, 'cafe_table', 0.85)
    assert spawn_cli.spawn_service_name(args) == '/gazebo/spawn_sdf_model'


def test_every_option():
    args = parse('-param robot_description -urdf -model m -x 1 -y -2 -z 3.5 -R 0.1 -P -0.2 -Y 3 '
                 '-reference_frame other::link -gazebo_namespace /sim/ -robot_namespace /r1 '
                 '-J joint1 -1.5 -J joint2 2 -unpause -wait ground -b')
    assert args.param == 'robot_description'
    assert (args.x, args.y, args.z, args.R, args.P, args.Y) == (1, -2, 3.5, 0.1, -0.2, 3)
    assert args.reference_frame == 'other::link' and args.robot_namespace == '/r1'
    assert args.joints == [('joint1', -1.5), ('joint2', 2.0)]
    assert args.unpause and args.bond and args.wait == 'ground'
    assert spawn_cli.spawn_service_name(args) == '/sim/spawn_urdf_model'
    assert spawn_cli.service_name(args.gazebo_namespace, 'delete_model') == '/sim/delete_model'


def test_stdin_source():
    assert parse('-stdin -sdf -model m').stdin


@pytest.mark.parametrize('line,expected', [
    ('-file f.urdf -urdf', 'required: -model'),
    ('-file f.urdf -model m', 'one of the arguments -urdf -sdf is required'),
    ('-file f.urdf -urdf -sdf -model m', 'not allowed with argument -urdf'),
    ('-urdf -model m', 'one of the arguments -file -param -database -stdin is required'),
    ('-file f -param p -urdf -model m', 'not allowed with argument -file'),
    ('-file f -urdf -model m -frobnicate', 'unrecognized arguments: -frobnicate'),
    ('-file f -urdf -model m -r x', 'ambiguous option: -r could match -reference_frame, -robot_namespace'),
    ('-file f -urdf -model m -x ahead', "argument -x: invalid float value: 'ahead'"),
    ('-file f -urdf -model m -x nan', '-x must be a finite number'),
    ('-file f -urdf -model m -J joint1', 'argument -J: expected 2 arguments'),
    ('-file f -urdf -model m -J joint1 up', "joint position 'up' is not a number"),
    ('-file f -urdf -model m -J joint1 inf', "joint position 'inf' is not finite"),
])
def test_bad_command_lines_say_what_is_wrong(line, expected):
    with pytest.raises(SpawnError, match=expected.replace('(', r'\(')):
        parse(line)


def test_empty_model_name_is_refused():
    with pytest.raises(SpawnError, match='non-empty'):
        spawn_cli.parse_args(['-file', 'f', '-urdf', '-model', ''])


def test_quaternion_matches_tf_convention():
    # Zero angles: identity. A pure yaw, pitch, roll: half-angle about z, y, x.
    assert quaternion_from_rpy(0, 0, 0) == (0, 0, 0, 1)
    for axis, rpy in ((0, (0.7, 0, 0)), (1, (0, 0.7, 0)), (2, (0, 0, 0.7))):
        q = quaternion_from_rpy(*rpy)
        expected = [0, 0, 0, math.cos(0.35)]
        expected[axis] = math.sin(0.35)
        assert q == pytest.approx(expected)
    # All three: the rotation matrix of the quaternion is Rz(yaw) Ry(pitch) Rx(roll).
    x, y, z, w = quaternion_from_rpy(0.1, 0.2, 0.3)
    from_quaternion = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    assert from_quaternion == pytest.approx(rotation('z', 0.3) @ rotation('y', 0.2) @ rotation('x', 0.1))


def rotation(axis, angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array({'x': [[1, 0, 0], [0, c, -s], [0, s, c]],
                     'y': [[c, 0, s], [0, 1, 0], [-s, 0, c]],
                     'z': [[c, -s, 0], [s, c, 0], [0, 0, 1]]}[axis])


def test_model_path_is_the_simulators_parameter():
    assert spawn_cli.model_path_param('/gazebo') == '/gazebo/model_path'
    assert spawn_cli.model_path_param('/sim/') == '/sim/model_path'
    assert spawn_cli.check_model_path(['/pkg/models', '/a'], '/gazebo/model_path') == [
        '/pkg/models', '/a']
    for value in ('/pkg/models:/a', ['/a', 3], None):
        with pytest.raises(SpawnError, match='parameter /gazebo/model_path is not a list of '
                                             'folders'):
            spawn_cli.check_model_path(value, '/gazebo/model_path')


def write_model(folder, name, files):
    model_dir = folder / name
    model_dir.mkdir(parents=True)
    for file_name, text in files.items():
        (model_dir / file_name).write_text(text)
    return model_dir


def test_database_model_found_in_the_first_folder_that_has_it(tmp_path):
    write_model(tmp_path / 'a', 'box', {'model.sdf': '<sdf version="1.6"/>'})
    write_model(tmp_path / 'b', 'box', {'model.sdf': '<sdf version="1.7"/>'})
    folders = [str(tmp_path / 'missing'), str(tmp_path / 'a'), str(tmp_path / 'b')]
    assert spawn_cli.find_database_model('box', folders) == str(tmp_path / 'a' / 'box' / 'model.sdf')


def test_database_model_uses_the_newest_sdf_named_by_model_config(tmp_path):
    config = ('<model><name>box</name><sdf version="1.4">model-1_4.sdf</sdf>'
              '<sdf version="1.6">model.sdf</sdf><sdf version="1.10">box-1_10.sdf</sdf></model>')
    write_model(tmp_path, 'box', {'model.config': config, 'model.sdf': '', 'box-1_10.sdf': ''})
    assert spawn_cli.find_database_model('box', [str(tmp_path)]) == str(tmp_path / 'box' / 'box-1_10.sdf')


def test_unknown_database_model_lists_the_folders_searched(tmp_path):
    write_model(tmp_path, 'empty_folder', {})
    with pytest.raises(SpawnError) as error:
        spawn_cli.find_database_model('empty_folder', ['/pkg/models', str(tmp_path)])
    assert "model 'empty_folder' not found" in str(error.value)
    assert '/pkg/models, %s' % tmp_path in str(error.value)
    assert 'GAZEBO_MODEL_PATH' in str(error.value)


@pytest.mark.parametrize('name', ['', '../x', '..'])
def test_database_name_must_be_a_folder_name(name):
    with pytest.raises(SpawnError, match='model folder name'):
        spawn_cli.find_database_model(name, ['/pkg/models'])


def test_package_models_are_found():
    for name in ('cafe_table', 'ground_plane'):
        path = spawn_cli.find_database_model(name, [PACKAGE_MODELS])
        assert path == os.path.join(PACKAGE_MODELS, name, 'model.sdf')


def test_file_is_read_relative_to_the_current_directory(tmp_path, monkeypatch):
    (tmp_path / 'robot.urdf').write_text(URDF)
    monkeypatch.chdir(tmp_path)
    args = parse('-file robot.urdf -urdf -model r')
    assert spawn_cli.load_local_model_xml(args, io.StringIO()) == URDF


def test_missing_file_names_the_absolute_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SpawnError, match='file nope.urdf does not exist \\(looked for %s\\)'
                       % (tmp_path / 'nope.urdf')):
        spawn_cli.load_local_model_xml(parse('-file nope.urdf -urdf -model r'), io.StringIO())


def test_directory_is_not_a_file(tmp_path):
    with pytest.raises(SpawnError, match='is not a file'):
        spawn_cli.read_file(str(tmp_path))


@pytest.mark.parametrize('text,expected', [('', 'is empty'), ('  \n', 'is empty'),
                                           ('<robot>', 'is not well-formed XML')])
def test_empty_or_malformed_xml_is_refused_naming_the_source(tmp_path, text, expected):
    path = tmp_path / 'bad.urdf'
    path.write_text(text)
    with pytest.raises(SpawnError, match='file %s %s' % (path, expected)):
        spawn_cli.load_local_model_xml(parse('-file %s -urdf -model r' % path), io.StringIO())


def test_database_and_stdin_sources(tmp_path):
    write_model(tmp_path, 'box', {'model.sdf': '<sdf version="1.6"><model name="box"/></sdf>'})
    assert parse('-database box -sdf -model b').database == 'box'
    assert 'model name="box"' in spawn_cli.database_model_xml('box', [str(tmp_path)])
    args = parse('-stdin -urdf -model r')
    assert spawn_cli.load_local_model_xml(args, io.StringIO(URDF)) == URDF
    with pytest.raises(SpawnError, match='read from stdin is empty'):
        spawn_cli.load_local_model_xml(args, io.StringIO(''))


def test_param_and_database_sources_are_left_to_the_caller():
    # Both need the master: the parameter, and the simulator's model path.
    assert spawn_cli.load_local_model_xml(parse('-param p -urdf -model r'), io.StringIO()) is None
    assert spawn_cli.load_local_model_xml(parse('-database box -sdf -model b'),
                                          io.StringIO()) is None
