"""The model handles of the simulator's rviz view (gazebo_ros.model_handles: Gazebo's translate and
rotate modes as interactive markers), over real ROS against the real simulator: a free model gets
a handle at its pose, a static one none; feedback as rviz's Interact tool sends it (POSE_UPDATE
while the mouse drags, MOUSE_UP where it is released) moves the model there with zero velocity;
the handle follows a model moved by anyone else, and goes with a deleted model; a refused move
is logged once and the node keeps serving; started before the simulator, the node serves and
picks the simulator up when it comes."""
import math

import pytest

from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from onedof_sim.tutorial.rviz_view import start_xvfb

SERVER = '/gazebo_model_handles'
HANDLES = ['rosrun', 'gazebo_ros', 'model_handles']


class HandlesSeen:
    """The server's markers as an rviz client sees them: the latched full state it republishes
    after each change ({name: InteractiveMarker})."""

    def __init__(self, rospy):
        from visualization_msgs.msg import InteractiveMarkerInit
        self.markers = None
        self.subscriber = rospy.Subscriber(SERVER + '/update_full', InteractiveMarkerInit,
                                           self._received, queue_size=10)

    def _received(self, init):
        self.markers = {marker.name: marker for marker in init.markers}


class Mouse:
    """rviz's Interact tool on the handles: InteractiveMarkerFeedback to the server."""

    def __init__(self, ros, rospy):
        from visualization_msgs.msg import InteractiveMarkerFeedback
        self.feedback = InteractiveMarkerFeedback
        self.publisher = rospy.Publisher(SERVER + '/feedback', InteractiveMarkerFeedback,
                                         queue_size=10)
        ros.wait_until(lambda: self.publisher.get_num_connections() > 0, 120,
                       what='the handles to hear the mouse')

    def send(self, name, event, target):
        message = self.feedback(marker_name=name, control_name='move_x', event_type=event,
                                client_id='/rviz/Move models', pose=target)
        message.header.frame_id = 'world'
        self.publisher.publish(message)

    def drag_until(self, ros, name, target, condition, what):
        """Drags the handle to target until condition holds: rviz sends a POSE_UPDATE at each
        move of the mouse (the server takes a client's feedback only 1 s after the marker
        appeared or another client's feedback came)."""
        def dragged():
            self.send(name, self.feedback.POSE_UPDATE, target)
            return condition()
        ros.wait_until(dragged, 60, interval=0.1, what=what)

    def release(self, name, target):
        self.send(name, self.feedback.MOUSE_UP, target)


def yawed(x, y, z, yaw):
    result = pose(x, y, z)
    result.orientation.z, result.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return result


def close(a, b, tolerance=1e-3):
    """Whether two geometry_msgs/Pose agree within tolerance (m, and per quaternion component,
    either sign)."""
    position = math.dist((a.position.x, a.position.y, a.position.z),
                         (b.position.x, b.position.y, b.position.z))
    qa = (a.orientation.x, a.orientation.y, a.orientation.z, a.orientation.w)
    qb = (b.orientation.x, b.orientation.y, b.orientation.z, b.orientation.w)
    turn = min(max(abs(p - q) for p, q in zip(qa, qb)), max(abs(p + q) for p, q in zip(qa, qb)))
    return position < tolerance and turn < tolerance


def model_pose(api, name):
    return api.get_model_state(name, '').pose


def handle_at(seen, name, target):
    return seen.markers is not None and name in seen.markers and close(
        seen.markers[name].pose, target)


def test_a_dragged_handle_moves_its_model_and_follows_it(ros, rospy_client, engine):
    start_sim(ros, engine)
    api = GazeboApi(rospy_client)
    api.pause_physics()
    api.spawn_box('box', yawed(0.5, -0.5, 0.1, 0.3))
    handles = ros.start(HANDLES, name='model_handles')
    seen = HandlesSeen(rospy_client)
    ros.wait_until(lambda: handle_at(seen, 'box', model_pose(api, 'box')), 120,
                   what="the box's handle at the box")
    assert api.get_world_properties().model_names == ['ground_plane', 'box']
    assert 'ground_plane' not in seen.markers  # static: no handle, as Gazebo moves none
    controls = sorted(control.name for control in seen.markers['box'].controls)
    assert controls == ['move_x', 'move_y', 'move_z', 'rotate_x', 'rotate_y', 'rotate_z']
    assert seen.markers['box'].header.frame_id == 'world'

    # The mouse drags the box up and about z, the box follows; released, the box stays there.
    mouse = Mouse(ros, rospy_client)
    held = yawed(1.0, 0.5, 0.6, 0.3)
    mouse.drag_until(ros, 'box', held, lambda: close(model_pose(api, 'box'), held),
                     'the box held')
    released = yawed(1.2, 0.5, 0.6, math.pi / 2)
    mouse.release('box', released)
    ros.wait_until(lambda: close(model_pose(api, 'box'), released), 60, what='the box released')
    twist = api.get_model_state('box', '').twist
    assert (twist.linear.x, twist.linear.y, twist.linear.z,
            twist.angular.x, twist.angular.y, twist.angular.z) == (0, 0, 0, 0, 0, 0)
    ros.wait_until(lambda: handle_at(seen, 'box', released), 60, what='the handle released')

    # Moved by another client, the box takes its handle along.
    moved = api.set_model_state(model_state('box', yawed(-1.0, 2.0, 0.1, 0)))
    assert moved.success, moved.status_message
    ros.wait_until(lambda: handle_at(seen, 'box', yawed(-1.0, 2.0, 0.1, 0)), 60,
                   what='the handle following the box')

    # A model spawned gets a handle; a deleted one loses it.
    api.spawn_box('box2', pose(0, 1, 0.1))
    ros.wait_until(lambda: handle_at(seen, 'box2', pose(0, 1, 0.1)), 60, what="box2's handle")
    deleted = api.delete_model('box')
    assert deleted.success, deleted.status_message
    ros.wait_until(lambda: 'box' not in seen.markers, 60, what="the box's handle gone")
    assert 'box2' in seen.markers

    # In a running world the handle follows a falling box down to where it rests.
    dropped = api.set_model_state(model_state('box2', pose(0, 1, 0.6)))
    assert dropped.success, dropped.status_message
    api.unpause_physics()
    ros.wait_until(lambda: seen.markers['box2'].pose.position.z < 0.2 and close(
        seen.markers['box2'].pose, model_pose(api, 'box2'), 3e-3), 120,
        what='the handle following the falling box to rest')
    assert handles.poll() is None, ros.log_text(handles)


def model_state(name, target):
    from gazebo_msgs.msg import ModelState
    return ModelState(model_name=name, pose=target, reference_frame='')


def test_a_refused_move_is_logged_once_and_the_handles_keep_serving(ros, rospy_client):
    # No simulator yet: the node serves its (empty) handles and waits for one.
    handles = ros.start(HANDLES, name='model_handles')
    seen = HandlesSeen(rospy_client)
    ros.wait_until(lambda: seen.markers == {}, 120, what='the handles served')
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy_client)
    api.pause_physics()
    api.spawn_box('box', pose(0, 0, 0.1))
    ros.wait_until(lambda: handle_at(seen, 'box', pose(0, 0, 0.1)), 120, what="the box's handle")

    # A pose the simulator refuses (not finite), dragged and held: said once, the box where it was.
    mouse = Mouse(ros, rospy_client)
    nowhere = pose(math.nan, 0, 0.1)
    refusal = '/gazebo/set_model_state refused to move box: '
    mouse.drag_until(ros, 'box', nowhere, lambda: refusal in ros.log_text(handles),
                     'the refusal logged')
    assert close(model_pose(api, 'box'), pose(0, 0, 0.1))
    # Released at a pose it takes, the box moves there: the node kept serving.
    mouse.release('box', pose(0.3, 0, 0.1))
    ros.wait_until(lambda: close(model_pose(api, 'box'), pose(0.3, 0, 0.1)), 60,
                   what='the box moved')
    assert ros.log_text(handles).count(refusal) == 1, ros.log_text(handles)
    assert handles.poll() is None, ros.log_text(handles)


def test_the_simulators_view_runs_the_handles_and_stops_them_with_rviz(ros, rospy_client):
    import rosnode
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy_client)
    api.pause_physics()
    api.spawn_box('box', pose(0.5, 0, 0.1))
    xvfb, display = start_xvfb(ros)
    view = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                     env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
    seen = HandlesSeen(rospy_client)
    ros.wait_until(lambda: handle_at(seen, 'box', pose(0.5, 0, 0.1)), 300,
                   what="the view's handle on the box")
    assert rosnode.rosnode_ping(SERVER, max_count=1)
    ros.terminate(view)
    ros.wait_until(lambda: not rosnode.rosnode_ping(SERVER, max_count=1), 120,
                   what='the handles stopped with the view')
    ros.terminate(xvfb)
