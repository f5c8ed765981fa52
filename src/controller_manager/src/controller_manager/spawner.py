"""`rosrun controller_manager spawner NAMES...`: loads controllers and starts them in one switch,
and stops and unloads them when it ends (SIGINT, SIGTERM, roslaunch shutting down). The logic is
plain functions; main() is the rospy part."""

import argparse
import os
import signal
import sys
import threading
import time

from controller_manager.naming import service_name

STRICT = 2  # controller_manager_msgs/SwitchController STRICT


def parse_args(argv):
    """ros_control Noetic's spawner command line."""
    parser = argparse.ArgumentParser(prog='spawner', description='Controller spawner')
    parser.add_argument('--stopped', action='store_true',
                        help='loads controllers, but does not start them')
    parser.add_argument('--wait-for', metavar='topic', help='does not load or start controllers '
                        'until it hears "True" on a topic (Bool)')
    parser.add_argument('--namespace', metavar='ns',
                        help='namespace of the controller_manager services')
    parser.add_argument('--timeout', metavar='T', type=float, default=30,
                        help='how long to wait for controller_manager services when starting up '
                        '[s] (default: 30)')
    parser.add_argument('--shutdown-timeout', metavar='T', type=float, default=30,
                        help='how long to wait for controller_manager services when shutting '
                        'down [s] (default: 30)')
    parser.add_argument('controllers', metavar='controller', nargs='+',
                        help='controllers to load')
    return parser.parse_args(argv)


def expand_controller_args(args, is_file=os.path.exists, read_yaml=None):
    """The controllers to load, in order, and the YAML documents to put on the parameter server
    first: an argument naming an existing file is a YAML file whose top-level keys are
    controllers (ros_control's spawner accepts those), any other is a controller name."""
    import yaml
    read_yaml = read_yaml or (lambda path: yaml.safe_load(open(path)))
    names, documents = [], []
    for arg in args:
        if is_file(arg):
            document = read_yaml(arg)
            if not isinstance(document, dict):
                raise ValueError('%s: expected a mapping of controller names to their '
                                 'parameters' % arg)
            documents.append(document)
            names.extend(document)
        else:
            names.append(arg)
    return names, documents


def load_all(names, load):
    """Loads each name with load(name) -> bool until one fails; returns (loaded, failed name or
    None). Stopping at the first failure leaves nothing started that the user did not get."""
    loaded = []
    for name in names:
        if not load(name):
            return loaded, name
        loaded.append(name)
    return loaded, None


def load_failure_message(name, manager):
    return ("Failed to load controller '%s': %s refused it (is %s/type set to a known controller "
            "type, and are its joint and parameters right? The controller manager's log says "
            "why)" % (name, manager, name))


def take_down(loaded, switch, unload):
    """Stops `loaded` in one strict switch, then unloads them in reverse order; returns the
    names that would not unload."""
    if loaded:
        switch(start=[], stop=list(loaded))
    return [name for name in reversed(loaded) if not unload(name)]


class ControllerManagerClient:
    """The controller manager's services, as rospy proxies."""

    def __init__(self, namespace, timeout):
        import rospy
        from controller_manager_msgs.srv import LoadController, SwitchController, UnloadController
        self.manager = rospy.resolve_name(service_name(namespace, '')).rstrip('/')
        proxies = {}
        for service, srv_type in (('load_controller', LoadController),
                                  ('switch_controller', SwitchController),
                                  ('unload_controller', UnloadController)):
            name = service_name(namespace, service)
            rospy.loginfo('Controller Spawner: Waiting for service %s', rospy.resolve_name(name))
            rospy.wait_for_service(name, timeout=timeout)
            proxies[service] = rospy.ServiceProxy(name, srv_type)
        self._proxies = proxies

    def load(self, name):
        return bool(self._proxies['load_controller'](name=name).ok)

    def unload(self, name):
        return bool(self._proxies['unload_controller'](name=name).ok)

    def switch(self, start, stop):
        return bool(self._proxies['switch_controller'](
            start_controllers=start, stop_controllers=stop, strictness=STRICT,
            start_asap=False, timeout=0.0).ok)


def wait_for_true(topic, timeout, stopping):
    """Blocks until std_msgs/Bool True arrives on topic (warning once after timeout) or
    stopping is set; returns whether True arrived."""
    import rospy
    from std_msgs.msg import Bool
    heard = threading.Event()
    anything = threading.Event()

    def callback(msg):
        anything.set()
        if msg.data:
            heard.set()
    sub = rospy.Subscriber(topic, Bool, callback)
    deadline = time.monotonic() + timeout
    warned = False
    while not heard.wait(0.05):
        if stopping.is_set() or rospy.is_shutdown():
            break
        if not warned and not anything.is_set() and time.monotonic() > deadline:
            rospy.logwarn('Controller Spawner hasn\'t heard anything from its "wait for" topic '
                          '(%s)', topic)
            warned = True
    sub.unregister()
    return heard.is_set()


def main(argv=None):
    import rospy
    import rosparam
    args = parse_args(rospy.myargv(argv if argv is not None else sys.argv)[1:])
    # Our own signal handling: the controllers are stopped and unloaded while the node can still
    # call services (in rospy's shutdown hooks it often no longer can).
    rospy.init_node('spawner', anonymous=True, disable_signals=True)
    stopping = threading.Event()

    def on_signal(*_):
        stopping.set()
        if not stopping.loading_started:
            # Nothing to take down yet: end the wait for the services now rather than when
            # roslaunch escalates to SIGKILL. From a thread of its own: the handler runs in the
            # main thread between two of its bytecodes, maybe while it holds a lock that rospy's
            # shutdown takes (a SIGINT just after the "Waiting for service" line deadlocked).
            threading.Thread(target=rospy.signal_shutdown, args=('interrupted',),
                             daemon=True).start()
    stopping.loading_started = False
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, on_signal)
    try:
        return run(args, stopping, rospy, rosparam)
    finally:
        rospy.signal_shutdown('spawner finished')


def run(args, stopping, rospy, rosparam):
    try:
        names, documents = expand_controller_args(args.controllers)
    except (OSError, ValueError) as exc:
        rospy.logerr('Controller Spawner: %s', exc)
        return 2
    try:
        manager = ControllerManagerClient(args.namespace, args.timeout)
    except rospy.ROSException:
        if stopping.is_set():
            return 0  # interrupted while waiting (ROSInterruptException is a ROSException)
        rospy.logerr("Controller Spawner couldn't find the expected controller_manager ROS "
                     "interface (%s/load_controller, switch_controller, unload_controller) within "
                     "%g s.", rospy.resolve_name(service_name(args.namespace, '')).rstrip('/'),
                     args.timeout)
        return 1
    if args.wait_for and not wait_for_true(args.wait_for, args.timeout, stopping):
        return 0
    for document in documents:
        rosparam.upload_params(rospy.get_namespace(), document)

    loaded, failed = [], None
    stopping.loading_started = True
    try:
        for name in names:
            rospy.loginfo('Loading controller: %s', name)
        loaded, failed = load_all(names, manager.load)
        if failed is not None:
            rospy.logerr(load_failure_message(failed, manager.manager))
        else:
            rospy.loginfo('Controller Spawner: Loaded controllers: %s', ', '.join(loaded))
            if not args.stopped:
                if manager.switch(start=loaded, stop=[]):
                    rospy.loginfo('Started controllers: %s', ', '.join(loaded))
                else:
                    rospy.logerr('Failed to start controllers: %s (the controller manager\'s '
                                 'log says why)', ', '.join(loaded))
                    failed = loaded[0]
        while failed is None and not stopping.is_set() and not rospy.is_shutdown():
            stopping.wait(0.2)
    except rospy.ServiceException as exc:
        rospy.logerr('Controller Spawner: the controller manager stopped answering: %s', exc)
        return 1
    finally:
        take_down_quietly(loaded, manager, args.shutdown_timeout, rospy)
    return 1 if failed is not None else 0


def take_down_quietly(loaded, manager, timeout, rospy):
    if not loaded:
        return
    rospy.loginfo('Shutting down spawner. Stopping and unloading controllers...')
    try:
        rospy.wait_for_service(service_name_of(manager, 'unload_controller'), timeout=timeout)
        stuck = take_down(loaded, manager.switch, manager.unload)
        if stuck:
            rospy.logwarn('Controller Spawner could not unload: %s', ', '.join(stuck))
    except (rospy.ServiceException, rospy.ROSException):
        rospy.logwarn("Controller Spawner couldn't reach controller_manager to take down "
                      "controllers. Waited for %g second(s).", timeout)


def service_name_of(manager, service):
    return manager.manager + '/' + service
