"""`rosrun controller_manager unspawner NAMES...`: keeps the named controllers stopped while it
runs and starts again those it stopped when it ends (ros_control's unspawner)."""

import signal
import sys
import threading

from controller_manager.naming import service_name

BEST_EFFORT = 1
POLL_SECONDS = 3.0

HELP = '''./unspawner name1 name2 name3

\tStops a set of controllers until killed.
\tUseful in roslaunch files to temporarily stop controllers'''


def running_to_stop(controllers, to_inhibit):
    """Names among `to_inhibit` that ListControllers reports running."""
    return [c.name for c in controllers if c.name in to_inhibit and c.state == 'running']


def main(argv=None):
    import rospy
    from controller_manager_msgs.srv import ListControllers, SwitchController
    argv = rospy.myargv(argv if argv is not None else sys.argv)
    if len(argv) == 1 or argv[1] in ('-h', '--help'):
        print(HELP)
        return 1
    to_inhibit = argv[1:]
    rospy.init_node('inhibit', anonymous=True, disable_signals=True)
    stopping = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stopping.set())
    list_name = service_name('', 'list_controllers')
    switch_name = service_name('', 'switch_controller')
    inhibited = set()
    try:
        rospy.wait_for_service(list_name)
        rospy.wait_for_service(switch_name)
        list_controllers = rospy.ServiceProxy(list_name, ListControllers)
        switch = rospy.ServiceProxy(switch_name, SwitchController)
        while not stopping.is_set():
            to_stop = running_to_stop(list_controllers().controller, to_inhibit)
            if to_stop:
                rospy.loginfo('Inhibiting controllers: %s', ', '.join(to_stop))
                switch(start_controllers=[], stop_controllers=to_stop, strictness=BEST_EFFORT,
                       start_asap=False, timeout=0.0)
                inhibited.update(to_stop)
            stopping.wait(POLL_SECONDS)
        if inhibited:
            switch(start_controllers=sorted(inhibited), stop_controllers=[],
                   strictness=BEST_EFFORT, start_asap=False, timeout=0.0)
        return 0
    finally:
        rospy.signal_shutdown('unspawner finished')
