"""`rosrun controller_manager controller_manager COMMAND [NAMES...]`, ros_control's command line."""

import sys

from controller_manager import controller_manager_interface as cmi

USAGE = '''Commands:
    load <name>          - Load the controller named <name>
    unload <name>        - Unload the controller named <name>
    start <name>         - Start the controller named <name>
    stop <name>          - Stop the controller named <name>
    spawn <name>         - Load and start the controller named <name>
    kill <name>          - Stop and unload the controller named <name>
    list                 - List active controllers
    list-types           - List controller Types
    reload-libraries     - Reloads all plugin controller libraries'''

ALIASES = {'lt': 'list-types', 'lc': 'list', 'sp': 'spawn', 'kl': 'kill'}


def plan(args):
    """The interface calls a command line asks for, in order, as (function name, argument)
    pairs; None for a command this tool does not know (usage, exit 1), [] for none at all
    (usage, exit 0)."""
    if not args:
        return []
    command, names = ALIASES.get(args[0], args[0]), args[1:]
    if command == 'list-types':
        return [('list_controller_types', None)]
    if command == 'list':
        return [('list_controllers', None)]
    if command == 'reload-libraries':
        return [('reload_libraries', '--restore' in names)]
    per_name = {'load': ['load_controller'], 'unload': ['unload_controller'],
                'start': ['start_controller'], 'stop': ['stop_controller'],
                'spawn': ['load_controller', 'start_controller'],
                'kill': ['stop_controller', 'unload_controller']}
    if command not in per_name:
        return None
    # spawn loads every name before starting any, kill stops all before unloading any.
    return [(call, name) for call in per_name[command] for name in names]


def main(argv=None):
    import rospy
    args = rospy.myargv(argv if argv is not None else sys.argv)[1:]
    calls = plan(args)
    if not calls:
        print(USAGE)
        return 0 if calls == [] else 1
    # No node: each command is a few service calls, which rospy makes without one (a name resolves
    # in the namespace of __ns:= or ROS_NAMESPACE). A node would register with the master, serve
    # XML-RPC, advertise /rosout and, on sim time, subscribe to /clock, for nothing.
    ok = True
    for call, arg in calls:
        if call == 'reload_libraries':
            ok &= cmi.reload_libraries(True, restore=arg)
        elif arg is None:
            ok &= getattr(cmi, call)()
        else:
            ok &= getattr(cmi, call)(arg)
    return 0 if ok else 1
