"""ros_control's controller_manager_interface: one call per controller_manager service, printing
what `rosrun controller_manager controller_manager ...` prints. Names are relative (the caller's
namespace: `ROS_NAMESPACE=/one_DOF_robot` or `__ns:=`), as upstream's are. Each returns whether it
succeeded."""

from controller_manager.naming import service_name

STRICT = 2  # controller_manager_msgs/SwitchController STRICT
BEST_EFFORT = 1


def format_controller(name, state, hardware_interfaces):
    """One line of `controller_manager list`: `name - interfaces ( state )`."""
    return '%s - %s ( %s )' % (name, '+'.join(hardware_interfaces), state)


def controller_lines(controllers):
    """The lines `controller_manager list` prints for ListControllers' controller field."""
    if not controllers:
        return ['No controllers are loaded in mechanism control']
    return [format_controller(c.name, c.state,
                              sorted({r.hardware_interface for r in c.claimed_resources}))
            for c in controllers]


def switch_report(names, start, ok):
    verb = ('Started' if start else 'Stopped') if ok else (
        'Error when starting' if start else 'Error when stopping')
    return ('%s %s successfully' if ok else '%s %s') % (verb, names)


def _proxy(service, srv_type):
    import rospy
    name = service_name('', service)
    rospy.wait_for_service(name)
    return rospy.ServiceProxy(name, srv_type)


def list_controller_types():
    from controller_manager_msgs.srv import ListControllerTypes
    resp = _proxy('list_controller_types', ListControllerTypes)()
    for controller_type in resp.types:
        print(controller_type)
    return True


def list_controllers():
    from controller_manager_msgs.srv import ListControllers
    resp = _proxy('list_controllers', ListControllers)()
    for line in controller_lines(resp.controller):
        print(line)
    return True


def reload_libraries(force_kill, restore=False):
    from controller_manager_msgs.srv import (ListControllers, LoadController,
                                             ReloadControllerLibraries, SwitchController)
    print('Restore:', restore)
    if restore:
        originally = _proxy('list_controllers', ListControllers)().controller
    ok = _proxy('reload_controller_libraries', ReloadControllerLibraries)(force_kill=force_kill).ok
    print('Successfully reloaded libraries' if ok else
          'Failed to reload libraries. Do you still have controllers loaded?')
    if restore:
        load = _proxy('load_controller', LoadController)
        for c in originally:
            load(name=c.name)
        _proxy('switch_controller', SwitchController)(
            start_controllers=[c.name for c in originally if c.state == 'running'],
            stop_controllers=[], strictness=BEST_EFFORT, start_asap=False, timeout=0.0)
        print('Controllers restored to original state')
    return bool(ok)


def load_controller(name):
    from controller_manager_msgs.srv import LoadController
    ok = _proxy('load_controller', LoadController)(name=name).ok
    print(('Loaded %s' if ok else 'Error when loading %s') % name)
    return bool(ok)


def unload_controller(name):
    from controller_manager_msgs.srv import UnloadController
    ok = _proxy('unload_controller', UnloadController)(name=name).ok
    print(('Unloaded %s successfully' if ok else 'Error when unloading %s') % name)
    return bool(ok)


def start_stop_controllers(names, start):
    from controller_manager_msgs.srv import SwitchController
    ok = _proxy('switch_controller', SwitchController)(
        start_controllers=names if start else [], stop_controllers=[] if start else names,
        strictness=STRICT, start_asap=False, timeout=0.0).ok
    print(switch_report(names, start, ok))
    return bool(ok)


def start_controller(name):
    return start_stop_controllers([name], True)


def start_controllers(names):
    return start_stop_controllers(names, True)


def stop_controller(name):
    return start_stop_controllers([name], False)


def stop_controllers(names):
    return start_stop_controllers(names, False)
