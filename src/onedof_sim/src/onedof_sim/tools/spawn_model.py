"""The ROS side of spawn_model (gazebo_ros' command line; the arguments and model sources are in
onedof_sim.tools.spawn_cli): `rosrun onedof_sim spawn_model` and `rosrun gazebo_ros spawn_model`
both run main().

Exits non-zero with the reason on any failure; with -b it stays alive and deletes the model when
stopped.
"""
import signal
import sys
import time

import rospy
from gazebo_msgs.srv import (DeleteModel, GetWorldProperties, SetModelConfiguration, SpawnModel,
                             SpawnModelRequest)
from geometry_msgs.msg import Point, Pose, Quaternion
from std_srvs.srv import Empty

from onedof_sim.tools import spawn_cli
from onedof_sim.tools.spawn_cli import SpawnError
from onedof_sim.transforms import quaternion_from_rpy

# Poll interval of -wait; wall time, because sim time may be paused.
WAIT_POLL_S = 0.2


def say(text):
    print('spawn_model: ' + text, flush=True)


def call(gazebo_namespace, service, srv_type, *request):
    """The response of a simulator service, once it is up; SpawnError if the call fails."""
    name = spawn_cli.service_name(gazebo_namespace, service)
    rospy.wait_for_service(name)
    try:
        return rospy.ServiceProxy(name, srv_type)(*request)
    except (rospy.ServiceException, rospy.ROSException) as e:
        raise SpawnError('call to %s failed: %s' % (name, e))


def param_model_xml(param):
    name = rospy.resolve_name(param)
    try:
        xml = rospy.get_param(name)
    except KeyError:
        raise SpawnError('parameter %s does not exist' % name)
    if not isinstance(xml, str):
        raise SpawnError('parameter %s is not a string of model XML' % name)
    return spawn_cli.check_model_xml(xml, 'parameter %s' % name)


def database_model_xml(args):
    """The model XML of -database, from the model path of the simulator it spawns into: the
    folders it resolves model://NAME in, which it sets as a parameter before serving."""
    param = spawn_cli.model_path_param(args.gazebo_namespace)
    try:
        folders = rospy.get_param(param)
    except KeyError:
        raise SpawnError('parameter %s does not exist: the simulator in %s does not say where its '
                         'models are, so -database %s has no model path to search'
                         % (param, args.gazebo_namespace, args.database))
    return spawn_cli.database_model_xml(args.database,
                                        spawn_cli.check_model_path(folders, param))


def wait_for_simulator(args):
    service = spawn_cli.spawn_service_name(args)
    say('waiting for service %s' % service)
    rospy.wait_for_service(service)


def wait_for_model(args):
    say('waiting for model %s' % args.wait)
    while args.wait not in call(args.gazebo_namespace, 'get_world_properties',
                                GetWorldProperties).model_names:
        time.sleep(WAIT_POLL_S)


def spawn(args, xml):
    request = SpawnModelRequest(
        model_name=args.model, model_xml=xml, reference_frame=args.reference_frame,
        robot_namespace=rospy.get_namespace() if args.robot_namespace is None
        else args.robot_namespace,
        initial_pose=Pose(Point(args.x, args.y, args.z),
                          Quaternion(*quaternion_from_rpy(args.R, args.P, args.Y))))
    service = spawn_cli.spawn_service_name(args)
    if args.wait:
        wait_for_model(args)
    try:
        response = rospy.ServiceProxy(service, SpawnModel)(request)
    except (rospy.ServiceException, rospy.ROSException) as e:
        raise SpawnError('call to %s failed: %s' % (service, e))
    if not response.success:
        raise SpawnError('spawning %s failed: %s' % (args.model, response.status_message))
    say(response.status_message)


def set_joints(args):
    names = [name for name, _ in args.joints]
    positions = [position for _, position in args.joints]
    response = call(args.gazebo_namespace, 'set_model_configuration', SetModelConfiguration,
                    args.model, '', names, positions)
    if not response.success:
        raise SpawnError('setting joints %s of %s failed: %s'
                         % (', '.join(names), args.model, response.status_message))
    say(response.status_message)


def delete_on_interrupt(args):
    say('holding %s; stop this program (Ctrl-C) to delete it' % args.model)
    try:
        while not rospy.is_shutdown():
            time.sleep(0.5)
    except KeyboardInterrupt:
        pass
    # No wait_for_service: if the simulator is gone there is nothing left to delete.
    name = spawn_cli.service_name(args.gazebo_namespace, 'delete_model')
    try:
        response = rospy.ServiceProxy(name, DeleteModel)(args.model)
    except (rospy.ServiceException, rospy.ROSException) as e:
        raise SpawnError('deleting %s: call to %s failed: %s' % (args.model, name, e))
    if not response.success:
        raise SpawnError('deleting %s failed: %s' % (args.model, response.status_message))
    say(response.status_message)


def raise_interrupt(signum, frame):
    raise KeyboardInterrupt


def main():
    # roslaunch stops nodes with SIGINT, then SIGTERM: both end the program the same way.
    signal.signal(signal.SIGTERM, raise_interrupt)
    try:
        args = spawn_cli.parse_args(rospy.myargv(sys.argv)[1:])
        say('spawning %s into onedof_sim, this workspace\'s simulator standing in for Gazebo'
            % args.model)
        # Local sources are checked before contacting the master, so a typo fails at once.
        xml = spawn_cli.load_local_model_xml(args, sys.stdin)
        rospy.init_node('spawn_model', anonymous=True, disable_signals=True)
        if args.param is not None:
            xml = param_model_xml(args.param)
        wait_for_simulator(args)
        if args.database is not None:
            xml = database_model_xml(args)
        spawn(args, xml)
        if args.joints:
            set_joints(args)
        if args.unpause:
            call(args.gazebo_namespace, 'unpause_physics', Empty)
            say('physics unpaused')
        if args.bond:
            delete_on_interrupt(args)
    except SpawnError as e:
        print('spawn_model: error: %s' % e, file=sys.stderr, flush=True)
        return 1
    except KeyboardInterrupt:
        print('spawn_model: interrupted', file=sys.stderr, flush=True)
        return 1
    return 0

