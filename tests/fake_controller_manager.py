#!/usr/bin/env python3
"""A stand-in controller manager for testing the controller_manager tools before the simulator
serves the real one: the six controller_manager services in this node's namespace, keeping
controller names and states only (no controllers run). A controller loads when
<namespace>/<name>/type is one of KNOWN_TYPES; the switch is all-or-nothing (STRICT); a running
controller does not unload. Test code only."""

import rospy
from controller_manager_msgs.msg import ControllerState, HardwareInterfaceResources
from controller_manager_msgs.srv import (ListControllers, ListControllersResponse,
                                         ListControllerTypes, ListControllerTypesResponse,
                                         LoadController, ReloadControllerLibraries,
                                         SwitchController, UnloadController)

KNOWN_TYPES = {
    'joint_state_controller/JointStateController': '',
    'effort_controllers/JointPositionController': 'hardware_interface::EffortJointInterface',
}


def main():
    rospy.init_node('controller_manager')
    states = {}  # name -> (type, 'running' | 'stopped'), in load order

    def load(req):
        controller_type = rospy.get_param(req.name + '/type', None)
        if req.name in states or controller_type not in KNOWN_TYPES:
            rospy.logerr('cannot load %s (type %r)', req.name, controller_type)
            return False
        states[req.name] = (controller_type, 'stopped')
        return True

    def unload(req):
        if states.get(req.name, (None, 'running'))[1] == 'running':
            return False
        del states[req.name]
        return True

    def switch(req):
        names = list(req.start_controllers) + list(req.stop_controllers)
        if any(name not in states for name in names):
            return False
        for name, state in [(n, 'running') for n in req.start_controllers] + [
                (n, 'stopped') for n in req.stop_controllers]:
            states[name] = (states[name][0], state)
        return True

    def listed(_):
        return ListControllersResponse([ControllerState(
            name=name, state=state, type=controller_type, claimed_resources=[
                HardwareInterfaceResources(KNOWN_TYPES[controller_type], ['joint1'])]
            if KNOWN_TYPES[controller_type] else [])
            for name, (controller_type, state) in states.items()])

    services = [
        rospy.Service('controller_manager/load_controller', LoadController, load),
        rospy.Service('controller_manager/unload_controller', UnloadController, unload),
        rospy.Service('controller_manager/switch_controller', SwitchController, switch),
        rospy.Service('controller_manager/list_controllers', ListControllers, listed),
        rospy.Service('controller_manager/list_controller_types', ListControllerTypes,
                      lambda _: ListControllerTypesResponse(
                          sorted(KNOWN_TYPES), ['controller_interface::ControllerBase'] * 2)),
        rospy.Service('controller_manager/reload_controller_libraries',
                      ReloadControllerLibraries, lambda req: not states or req.force_kill),
    ]
    rospy.spin()
    del services


if __name__ == '__main__':
    main()
