"""The simulator node's two names beyond gazebo_ros' API, each served only when asked for, so that
by default the node advertises exactly Gazebo's names: the step service /gazebo/step_simulation
(the node's ~enable_step_simulation, read at start-up; ~lockstep implies it) and the collision
markers /gazebo/collision_markers (~enable_collision_markers, which the node also follows while
running). The tools that need them ask for them through this module."""

NODE = '/gazebo'
STEP_SERVICE = NODE + '/step_simulation'
MARKERS_TOPIC = NODE + '/collision_markers'
MARKERS_PARAMETER = NODE + '/enable_collision_markers'
# The sim time at the views' rate (with the markers): the window's rviz takes it for its /clock.
VIEW_CLOCK_TOPIC = NODE + '/view_clock'
# The service the node advertises last: once it is there, so is the step service if it is served.
LAST_SERVICE = NODE + '/unpause_physics'

STEP_SERVICE_MISSING = (
    '%s is not served: the simulator serves it only when asked for, with its parameter '
    '~enable_step_simulation (rosrun onedof_sim onedof_sim _enable_step_simulation:=true, or '
    'enable_step_simulation:=true on the launch files; lock-step, ~lockstep, implies it)'
    % STEP_SERVICE)


def step_service(rospy, persistent=False, timeout=60):
    """A rospy ServiceProxy of the step service, once the simulator serves its API (waits up to
    `timeout` s for it). Raises RuntimeError(STEP_SERVICE_MISSING) when the simulator serves its
    API without the step service."""
    import rosgraph
    from onedof_sim.srv import StepSimulation
    rospy.wait_for_service(LAST_SERVICE, timeout)
    try:
        rosgraph.Master(rospy.get_name()).lookupService(STEP_SERVICE)
    except rosgraph.MasterError:
        raise RuntimeError(STEP_SERVICE_MISSING) from None
    return rospy.ServiceProxy(STEP_SERVICE, StepSimulation, persistent=persistent)


def request_collision_markers(caller_id, master_uri=None):
    """Asks the simulator for its collision markers (sets its ~enable_collision_markers, which it
    follows while running), as the views that draw them do. Returns False when the master does
    not answer."""
    import rosgraph
    try:
        rosgraph.Master(caller_id, master_uri=master_uri).setParam(MARKERS_PARAMETER, True)
    except (OSError, rosgraph.MasterException):
        return False
    return True
