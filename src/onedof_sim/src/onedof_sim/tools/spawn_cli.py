"""The command line of `rosrun onedof_sim spawn_model` (and `rosrun gazebo_ros spawn_model`):
gazebo_ros' spawn_model arguments, how `-database` finds a model in the simulator's model path,
and the model XML each source yields.

Free of rospy so it can be unit-tested; onedof_sim.tools.spawn_model makes the ROS calls. Every problem a
user can cause is raised as SpawnError with a message meant for them.
"""
import argparse
import math
import os
import xml.etree.ElementTree as ET


class SpawnError(Exception):
    """A problem with the user's request; str() is the message to print."""


class _Parser(argparse.ArgumentParser):
    # argparse would print and exit(2) itself; raising keeps the decision with the caller and lets
    # the unit tests see the message.
    def error(self, message):
        raise SpawnError(message)


def build_parser():
    parser = _Parser(
        prog='spawn_model',
        description="Spawn a model into onedof_sim, this workspace's simulator standing in for "
                    'Gazebo, through its Gazebo ROS API (the arguments of gazebo_ros spawn_model).')
    fmt = parser.add_mutually_exclusive_group(required=True)
    fmt.add_argument('-urdf', action='store_true', help='the model XML is URDF')
    fmt.add_argument('-sdf', action='store_true', help='the model XML is SDF')
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument('-file', metavar='FILE_NAME',
                        help='read the model XML from a file (relative to the current directory)')
    source.add_argument('-param', metavar='PARAM_NAME',
                        help='read the model XML from a ROS parameter')
    source.add_argument('-database', metavar='MODEL_NAME',
                        help='read MODEL_NAME/model.sdf from the model path of the simulator '
                             '(its parameter GAZEBO_NAMESPACE/model_path: the models/ folder of '
                             'onedof_sim, then every folder of its GAZEBO_MODEL_PATH)')
    source.add_argument('-stdin', action='store_true', help='read the model XML from stdin')
    parser.add_argument('-model', metavar='MODEL_NAME', required=True,
                        help='name of the model to spawn')
    parser.add_argument('-reference_frame', default='',
                        help='model or link the initial pose is relative to; empty or "world" '
                             'for the world frame')
    parser.add_argument('-gazebo_namespace', default='/gazebo',
                        help='ROS namespace of the simulator services (default /gazebo)')
    parser.add_argument('-robot_namespace', default=None,
                        help='ROS namespace of the model (default: this node\'s namespace)')
    parser.add_argument('-unpause', action='store_true', help='unpause physics after spawning')
    parser.add_argument('-wait', metavar='MODEL_NAME',
                        help='wait until this model exists before spawning')
    for name, what in (('x', 'x position'), ('y', 'y position'), ('z', 'z position'),
                       ('R', 'roll angle'), ('P', 'pitch angle'), ('Y', 'yaw angle')):
        parser.add_argument('-' + name, type=float, default=0.0, help='initial %s' % what)
    parser.add_argument('-J', dest='joints', nargs=2, action='append', default=[],
                        metavar=('JOINT_NAME', 'JOINT_POSITION'),
                        help='set a joint position after spawning (repeatable)')
    parser.add_argument('-b', dest='bond', action='store_true',
                        help='stay alive and delete the model when this program is stopped')
    return parser


def parse_args(argv):
    """Parses the arguments (without the program name); -J positions become floats."""
    args = build_parser().parse_args(argv)
    if not args.model:
        raise SpawnError('-model needs a non-empty name')
    joints = []
    for name, position in args.joints:
        try:
            value = float(position)
        except ValueError:
            raise SpawnError('-J %s: joint position %r is not a number' % (name, position))
        if not math.isfinite(value):
            raise SpawnError('-J %s: joint position %r is not finite' % (name, position))
        joints.append((name, value))
    args.joints = joints
    for name in ('x', 'y', 'z', 'R', 'P', 'Y'):
        if not math.isfinite(getattr(args, name)):
            raise SpawnError('-%s must be a finite number' % name)
    return args


def model_path_param(gazebo_namespace):
    """The parameter in which the simulator says where its models are (the folders model://NAME
    resolves in, in order), set before it serves its services."""
    return service_name(gazebo_namespace, 'model_path')


def check_model_path(value, param):
    """The folders of the simulator's model path parameter (its value, as read); SpawnError when
    it is not a list of folder names."""
    if not isinstance(value, list) or not all(isinstance(folder, str) for folder in value):
        raise SpawnError('parameter %s is not a list of folders: %r' % (param, value))
    return value


def _version_key(version):
    try:
        return tuple(int(part) for part in version.split('.'))
    except ValueError:
        return ()


def _sdf_file_of(model_dir):
    """The model's SDF file: the newest <sdf> named by model.config, else model.sdf."""
    config = os.path.join(model_dir, 'model.config')
    if os.path.isfile(config):
        try:
            entries = ET.parse(config).getroot().findall('sdf')
        except ET.ParseError:
            entries = []
        named = [(e.get('version', ''), e.text.strip()) for e in entries if e.text and e.text.strip()]
        if named:
            newest = max(named, key=lambda entry: _version_key(entry[0]))[1]
            return os.path.join(model_dir, newest)
    return os.path.join(model_dir, 'model.sdf')


def find_database_model(name, folders):
    """Path of NAME's SDF file in the first folder that holds NAME/; SpawnError naming the folders
    searched when none does."""
    if not name or '/' in name or name in ('.', '..'):
        raise SpawnError('-database needs a model folder name, got %r' % name)
    for folder in folders:
        model_dir = os.path.join(folder, name)
        if os.path.isdir(model_dir):
            sdf = _sdf_file_of(model_dir)
            if os.path.isfile(sdf):
                return sdf
    raise SpawnError('model %r not found in the model path: no %s/model.sdf in %s '
                     '(add its parent folder to the simulator\'s GAZEBO_MODEL_PATH, '
                     'colon-separated)' % (name, name, ', '.join(folders)))


def read_file(path):
    """The text of a model file; relative paths are relative to the current directory."""
    absolute = os.path.abspath(path)
    if not os.path.exists(absolute):
        raise SpawnError('file %s does not exist (looked for %s)' % (path, absolute))
    if not os.path.isfile(absolute):
        raise SpawnError('%s is not a file' % absolute)
    try:
        with open(absolute, encoding='utf-8') as f:
            return f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise SpawnError('cannot read %s: %s' % (absolute, e))


def check_model_xml(xml, source):
    """Refuses empty or malformed XML before it reaches the simulator, naming where it came from."""
    if not xml or not xml.strip():
        raise SpawnError('%s is empty' % source)
    try:
        ET.fromstring(xml)
    except ET.ParseError as e:
        raise SpawnError('%s is not well-formed XML: %s' % (source, e))
    return xml


def load_local_model_xml(args, stdin):
    """The checked model XML from -file or -stdin; None for -param and -database (they need the
    master and the simulator)."""
    if args.file is not None:
        return check_model_xml(read_file(args.file), 'file %s' % args.file)
    if args.stdin:
        return check_model_xml(stdin.read(), 'the model XML read from stdin')
    return None


def database_model_xml(name, folders):
    """The checked model XML of -database NAME, found in the model path `folders`."""
    path = find_database_model(name, folders)
    return check_model_xml(read_file(path), 'model file %s' % path)


def service_name(gazebo_namespace, service):
    """Name of a simulator service in gazebo_namespace (-gazebo_namespace)."""
    return '%s/%s' % (gazebo_namespace.rstrip('/'), service)


def spawn_service_name(args):
    return service_name(args.gazebo_namespace,
                        'spawn_urdf_model' if args.urdf else 'spawn_sdf_model')
