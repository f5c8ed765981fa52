"""`rosrun controller_manager controller_manager ...` in the book's namespace, for the tests."""

NS = '/one_DOF_robot'
# What `list` prints for the book's two controllers (one_dof_ctl_params.yaml), both running.
STATE_CONTROLLER_RUNNING = (
    'joint_state_controller - hardware_interface::JointStateInterface ( running )')
BOOK_CONTROLLERS_RUNNING = [
    STATE_CONTROLLER_RUNNING,
    'joint1_position_controller - hardware_interface::EffortJointInterface ( running )']


def cli(ros, *args):
    out = ros.run(['rosrun', 'controller_manager', 'controller_manager'] + list(args)
                  + ['__ns:=' + NS])
    return out


def listing(ros):
    out = cli(ros, 'list')
    assert out.returncode == 0, out.stderr
    return out.stdout.splitlines()


def wait_for_listing(ros, rospy, expected, what, timeout=60):
    """Waits until `controller_manager list` prints `expected`, then checks that it does. The wait
    asks the controller manager from this process (rospy, a node of ros), with the lines the tool
    makes of the answer: a tool process per look would cost a Python start-up each."""
    from controller_manager.controller_manager_interface import controller_lines
    from controller_manager_msgs.srv import ListControllers
    proxy = rospy.ServiceProxy(NS + '/controller_manager/list_controllers', ListControllers)

    def listed():
        try:
            return controller_lines(proxy().controller) == expected
        except (rospy.ServiceException, rospy.ROSException, OSError):
            return False  # not served yet
    ros.wait_until(listed, timeout, what=what)
    assert listing(ros) == expected
