"""Gazebo's translate and rotate modes in the simulator's rviz view: an interactive marker server
(topics under /gazebo_model_handles, the node /gazebo_model_handles) with a handle on the selected
model, as Gazebo puts its arrows and rings on the model selected alone: the model named on
SELECTED_TOPIC (latched; the view's Select Model tool publishes a clicked model, an empty name for
none), at its pose in the simulator's world (/gazebo/view_model_states: its poses at its views'
rate, not every step as /gazebo/model_states): arrows along the world's x, y and z (translate) and
rings about them (rotate), dragged with that tool. Static models have handles too (Gazebo moves a
static model, the cafe table a student places, with the mouse); the ground plane has none, as
Gazebo selects no plane. Every other model has a marker whose one control neither moves nor shows
anything (UNSELECTED_CONTROL; interactive_markers takes a marker of no controls for a deleted one,
and rviz then draws no handle at all): selected, a model's marker gains its controls, and a press
on them is taken at once (take_feedback_at_once). A model deselected mid-drag keeps its controls
until its release is sent; a deleted model is deselected. world.rviz's "Move models" display shows
the handles (the Gazebo panel's "Move models" button ticks it); it starts unticked, as Gazebo
starts in its select mode, so that the picture of the world is the world's until the user asks for
them.

A handle follows its model while it is not dragged (at most FOLLOW_HZ times a wall second, and only
when the model moved): the poses of /gazebo/view_model_states, or, while none has come for
STALE_S (a world slowed far below real time publishes them seldom), those
/gazebo/get_world_properties and /gazebo/get_model_state answer, so that a model inserted or moved
in a world that hardly moves is handled.
While a handle is dragged, the model is held where the mouse puts it, as Gazebo holds a dragged
model: its links' gravity off (/gazebo/set_link_properties, those whose gravity_mode is on) and
the dragged pose, with zero velocity, through /gazebo/set_model_state at most DRAG_HZ times a wall
second, sent again at that rate while the mouse is down; the pose where the mouse is released is
sent last, then the links' gravity is back on, and the model is let go with zero velocity. A drag
is rviz's MOUSE_DOWN to MOUSE_UP; feedback outside one moves nothing. While a handle is dragged,
the server does not send rviz its pose (rviz has it). A node ended (SIGINT, SIGTERM) while a model
is held gives it its gravity back first.

A handle's right-click menu has Gazebo's Move To and Follow, for the Gazebo panel, which holds
rviz's view (the model's name on MOVE_TO_TOPIC, or FOLLOW_TOPIC; Stop Following sends an empty
name there), Gazebo's View > Transparent and Wireframe for that model alone (checked while on: the
models in each mode on its latched topic, TRANSPARENT_TOPIC and WIREFRAME_TOPIC, which the view's
model visuals display follows), View > Collisions, Joints, Center of Mass and Inertia for that
model alone (gazebo_ros.model_marker_views: the model's markers of the simulator's view, relayed
to the view's "Model views" display), Apply Force/Torque (a dialog, gazebo_ros.wrench_dialog, through
/gazebo/apply_body_wrench), Reset Model Pose (/gazebo/reset_model, the simulator's own: the model
back at its spawn pose, as Gazebo's Edit > Reset Model Poses puts every model; Gazebo's menu has
no entry for one model) and Delete (/gazebo/delete_model).

No simulator, or a refused move or delete, is logged once per reason; the node keeps serving.
"""
import math
import signal
import subprocess
import sys
import threading
import time

from gazebo_ros.model_marker_views import MODEL_VIEW_MARKERS, ModelMarkerViews

SERVER_TOPIC = '/gazebo_model_handles'
NODE_NAME = 'gazebo_model_handles'
MODEL_STATES = '/gazebo/view_model_states'
# The selected model's name (std_msgs/String, latched; gazebo_ros_panels' select_model_tool.h).
SELECTED_TOPIC = '/gazebo_window/selected_model'
SET_MODEL_STATE = '/gazebo/set_model_state'
GET_MODEL_PROPERTIES = '/gazebo/get_model_properties'
DELETE_MODEL = '/gazebo/delete_model'
RESET_MODEL = '/gazebo/reset_model'
GET_LINK_PROPERTIES = '/gazebo/get_link_properties'
SET_LINK_PROPERTIES = '/gazebo/set_link_properties'
GET_WORLD_PROPERTIES = '/gazebo/get_world_properties'
GET_MODEL_STATE = '/gazebo/get_model_state'
FRAME = 'world'
# The Gazebo panel's view requests (std_msgs/String, a model's name; gazebo_client.h).
MOVE_TO_TOPIC = '/gazebo_window/move_to'
FOLLOW_TOPIC = '/gazebo_window/follow'
# The models drawn transparent, and wireframe, by the view's model visuals display
# (std_msgs/String, the names one a line, latched; gazebo_ros_panels' model_visuals.h).
TRANSPARENT_TOPIC = '/gazebo_window/transparent_models'
WIREFRAME_TOPIC = '/gazebo_window/wireframe_models'
# A model's View menu, Gazebo's titles: each mode and its topic.
VIEW_MODES = (('Transparent', TRANSPARENT_TOPIC), ('Wireframe', WIREFRAME_TOPIC))
# The world's plane: Gazebo's ground_plane model, which Gazebo's mouse neither selects nor moves.
GROUND_PLANE = 'ground_plane'
# The name of an unselected model's handle's only control.
UNSELECTED_CONTROL = 'unselected'
FOLLOW_HZ = 10.0
DRAG_HZ = 20.0
# A handle is moved to its model once the model is this far (m, rad) from the handle.
FOLLOW_TOLERANCE = 1e-3
# Wall seconds without view_model_states after which the poses are asked for instead.
STALE_S = 0.5
# Bounds a dialog's orderly exit after the node's; only a hung dialog waits this long.
DIALOG_STOP_SECONDS = 10.0


def axis_controls():
    """Translate (MOVE_AXIS) and rotate (ROTATE_AXIS) controls along and about the world's x, y
    and z: a control's axis is the x axis of its orientation."""
    from visualization_msgs.msg import InteractiveMarkerControl
    half = math.sqrt(0.5)
    controls = []
    for axis, (qx, qy, qz) in (('x', (half, 0, 0)), ('y', (0, 0, half)), ('z', (0, half, 0))):
        for mode, verb in ((InteractiveMarkerControl.MOVE_AXIS, 'move'),
                           (InteractiveMarkerControl.ROTATE_AXIS, 'rotate')):
            control = InteractiveMarkerControl()
            control.name = '%s_%s' % (verb, axis)
            control.orientation.w, control.orientation.x = half, qx
            control.orientation.y, control.orientation.z = qy, qz
            control.orientation_mode = InteractiveMarkerControl.FIXED
            control.interaction_mode = mode
            controls.append(control)
    return controls


def unselected_control():
    """The one control of an unselected model's handle: no interaction, nothing drawn."""
    from visualization_msgs.msg import InteractiveMarkerControl
    return InteractiveMarkerControl(name=UNSELECTED_CONTROL,
                                    interaction_mode=InteractiveMarkerControl.NONE)


def handle_marker(name, pose, selected):
    """The interactive marker of model `name` at `pose` (geometry_msgs/Pose in FRAME): its
    arrows and rings if `selected`, unselected_control() else."""
    from visualization_msgs.msg import InteractiveMarker
    marker = InteractiveMarker()
    marker.header.frame_id = FRAME
    marker.name = name
    marker.description = name
    marker.pose = pose
    marker.scale = 1.0
    marker.controls = axis_controls() if selected else [unselected_control()]
    return marker


def pose_distance(a, b):
    """The larger of the positions' distance (m) and the orientations' angle (rad) between two
    geometry_msgs/Pose."""
    position = math.dist((a.position.x, a.position.y, a.position.z),
                         (b.position.x, b.position.y, b.position.z))
    dot = abs(a.orientation.x * b.orientation.x + a.orientation.y * b.orientation.y +
              a.orientation.z * b.orientation.z + a.orientation.w * b.orientation.w)
    return max(position, 2 * math.acos(min(1.0, dot)))


class ServiceUnavailable(Exception):
    """A simulator's service that is not served, or failed to answer."""


def said_once(log):
    """log(text), each text once."""
    said = set()

    def say_once(text):
        if text not in said:
            said.add(text)
            log(text)
    return say_once


class GravityHold:
    """Turns the gravity of a model's links off while the mouse holds it, and back on. The
    simulator's calls are get_model_properties(name), get_link_properties(link) and
    set_link_properties(request) (gazebo_msgs' services), each raising ServiceUnavailable when it
    cannot be made; say_once(text) says a problem."""

    def __init__(self, get_model_properties, get_link_properties, set_link_properties, say_once):
        self.get_model_properties = get_model_properties
        self.get_link_properties = get_link_properties
        self.set_link_properties = set_link_properties
        self.say_once = say_once

    def hold(self, name):
        """Gravity off on model `name`'s links that have it; returns what let_go needs."""
        held = []
        try:
            model = self.get_model_properties(name)
            for body in model.body_names if model.success else ():
                link = '%s::%s' % (name, body)
                properties = self.get_link_properties(link)
                if properties.success and properties.gravity_mode:
                    if self._set_gravity(link, properties, False):
                        held.append((link, properties))
        except ServiceUnavailable as error:
            self.say_once('cannot hold %s without gravity: %s' % (name, error))
        return held

    def let_go(self, held):
        """Gravity back on where hold() turned it off."""
        for link, properties in held:
            try:
                self._set_gravity(link, properties, True)
            except ServiceUnavailable as error:
                self.say_once('cannot give %s its gravity back: %s' % (link, error))

    def _set_gravity(self, link, properties, on):
        from gazebo_msgs.srv import SetLinkPropertiesRequest
        result = self.set_link_properties(SetLinkPropertiesRequest(
            link_name=link, com=properties.com, gravity_mode=on, mass=properties.mass,
            ixx=properties.ixx, ixy=properties.ixy, ixz=properties.ixz, iyy=properties.iyy,
            iyz=properties.iyz, izz=properties.izz))
        if not result.success:
            self.say_once('%s refused gravity %s on %s: %s' % (
                SET_LINK_PROPERTIES, 'on' if on else 'off', link, result.status_message))
        return result.success


class ModelHandles:
    """The handles of the simulator's models on `server` (an InteractiveMarkerServer). The
    simulator's calls are `set_state(ModelState)` (a SetModelState response) and `ask_poses()`
    ({name: Pose}); each raises ServiceUnavailable when it cannot be made. `gravity` (a
    GravityHold) holds a dragged model up. `menus` (a ModelMenus, or None) gives each handle its
    right-click menu. `say_once(text)` says a problem (said_once)."""

    def __init__(self, server, set_state, ask_poses, gravity, say_once, menus=None):
        self.server = server
        self.set_state = set_state
        self.ask_poses = ask_poses
        self.gravity = gravity
        self.say_once = say_once
        self.menus = menus
        self.lock = threading.Lock()
        self.selected = ''        # the selected model's name ('': none)
        self.latest = None        # the latest view_model_states, serialised
        self.latest_at = -math.inf  # and the wall time it came
        self.shown = {}           # name -> the Pose its handle was last put at (None: released)
        self.controlled = {}      # name -> whether its handle has its controls
        self.dragged = {}         # name -> the Pose the mouse holds it at
        self.to_send = {}         # name -> a dragged or released Pose not yet sent
        self.last_sent = {}       # name -> wall time of the last move sent
        self.moved_at = {}        # name -> wall time the simulator last answered a move
        self.held = {}            # name -> its links held without gravity (send_moves' own)

    def on_model_states(self, raw):
        """Keeps the latest model states undecoded (a rospy.AnyMsg): they come up to 20 times a
        second, and the handles read them FOLLOW_HZ times a second."""
        with self.lock:
            self.latest = raw._buff
            self.latest_at = time.monotonic()

    def on_selected(self, name):
        """The selected model (a std_msgs/String: its name, empty for none)."""
        with self.lock:
            self.selected = name.data

    def current_poses(self, now):
        """({name: Pose} of the simulator's models, the wall time they are from), or (None,
        None) when it cannot say."""
        from gazebo_msgs.msg import ModelStates
        with self.lock:
            latest, latest_at = self.latest, self.latest_at
        if now - latest_at < STALE_S:
            states = ModelStates().deserialize(latest)
            return dict(zip(states.name, states.pose)), latest_at
        try:
            return self.ask_poses(), now
        except ServiceUnavailable as error:
            self.say_once('no model poses: %s' % error)
            return None, None

    def on_feedback(self, feedback):
        """A drag is rviz's MOUSE_DOWN, POSE_UPDATEs and MOUSE_UP on a handle. A POSE_UPDATE or
        MOUSE_UP outside a drag moves nothing: rviz sends that pair, with the pose it shows,
        when the control under a still mouse changes after a release (a focus change)."""
        with self.lock:
            name = feedback.marker_name
            # No press on a handle with no controls: what rviz cannot show it cannot press.
            if name not in self.shown or (feedback.event_type == feedback.MOUSE_DOWN and
                                          not self.controlled.get(name)):
                return
            if feedback.event_type == feedback.MOUSE_DOWN or (
                    feedback.event_type == feedback.POSE_UPDATE and name in self.dragged):
                self.dragged[name] = feedback.pose
                self.to_send[name] = feedback.pose
            elif feedback.event_type == feedback.MOUSE_UP and name in self.dragged:
                del self.dragged[name]
                self.to_send[name] = feedback.pose
                self.shown[name] = None  # put at its model's pose once the release is sent
                self.last_sent.pop(name, None)  # the release is sent at once
            elif feedback.event_type == feedback.POSE_UPDATE:
                self.shown[name] = None  # the server took its pose: back to its model's

    def follow(self, now):
        """Adds, moves and erases handles after the selection and the simulator's current
        poses."""
        poses, as_of = self.current_poses(now)
        if poses is None:
            return
        for name in [name for name in self.shown if name not in poses]:
            self.server.erase(name)
            if self.menus:
                self.menus.forget(name)
            with self.lock:
                for table in (self.shown, self.controlled, self.dragged, self.to_send,
                              self.last_sent, self.moved_at):
                    table.pop(name, None)
                if self.selected == name:
                    self.selected = ''
        with self.lock:
            selected = self.selected
        added = []
        for name, pose in poses.items():
            if name == GROUND_PLANE:
                continue
            with self.lock:
                # A model moved by the mouse after these poses were taken is not where they say.
                if (name in self.dragged or name in self.to_send or
                        as_of < self.moved_at.get(name, -math.inf)):
                    continue
                if name not in self.shown:
                    added.append(name)
                if name not in self.shown or self.controlled[name] != (name == selected):
                    self.server.insert(handle_marker(name, pose, name == selected),
                                       self.on_feedback)
                    self.controlled[name] = name == selected
                    if self.menus:
                        self.menus.apply(name)
                elif (self.shown[name] is None or
                      pose_distance(pose, self.shown[name]) > FOLLOW_TOLERANCE):
                    self.server.setPose(name, pose)
                else:
                    continue
                self.shown[name] = pose
        self.withhold_dragged_poses()
        self.server.applyChanges()
        self.take_feedback_at_once(added)

    def take_feedback_at_once(self, names):
        """Lets the server take rviz's feedback on the new handles of `names` at once: ROS's
        marker server refuses a client's feedback within a second of the last feedback of
        another client, and counts a new marker's creation as one; a model inserted and dragged
        in its first second would stay where it was while rviz shows its handle dragged. One
        view drags the handles."""
        import rospy
        with self.server.mutex:
            for name in names:
                context = self.server.marker_contexts.get(name)
                if context is not None:
                    context.last_feedback = rospy.Time(0)

    def withhold_dragged_poses(self):
        """Drops the server's pending pose of each dragged handle: the server takes a drag's
        feedback as its handle's pose, and rviz keeps a pose the server sends during a drag until
        the release, then shows the handle there, behind the mouse when the pose was late (the
        next press then takes the model back there). Released, a handle is put at its model's
        pose."""
        with self.lock:
            dragged = list(self.dragged)
        with self.server.mutex:
            for name in dragged:
                update = self.server.pending_updates.get(name)
                if update is not None and update.update_type == update.POSE_UPDATE:
                    del self.server.pending_updates[name]

    def send_moves(self, now):
        """Sends each dragged or released pose whose model was last moved at least 1 / DRAG_HZ
        ago; a model still held is sent its pose again at that rate."""
        from gazebo_msgs.msg import ModelState
        with self.lock:
            to_hold = [name for name in self.dragged if name not in self.held]
        for name in to_hold:
            self.held[name] = self.gravity.hold(name)
        with self.lock:
            for name, pose in self.dragged.items():
                self.to_send.setdefault(name, pose)
            due = [(name, pose) for name, pose in self.to_send.items()
                   if now - self.last_sent.get(name, -math.inf) >= 1.0 / DRAG_HZ]
            for name, _ in due:
                del self.to_send[name]
                self.last_sent[name] = now
        for name, pose in due:
            state = ModelState(model_name=name, pose=pose, reference_frame='')
            try:
                result = self.set_state(state)
            except ServiceUnavailable as error:
                self.say_once('cannot move %s through %s: %s' % (name, SET_MODEL_STATE, error))
                continue
            with self.lock:
                self.moved_at[name] = time.monotonic()
            if not result.success:
                self.say_once('%s refused to move %s: %s'
                              % (SET_MODEL_STATE, name, result.status_message))
        with self.lock:
            released = [name for name in self.held
                        if name not in self.dragged and name not in self.to_send]
        for name in released:
            self.gravity.let_go(self.held.pop(name))

    def let_all_go(self):
        """Gives every model still held its gravity back (the node ends mid-drag)."""
        while self.held:
            self.gravity.let_go(self.held.popitem()[1])


class ModelViews:
    """Gazebo's View > Transparent and Wireframe of single models: the models in each mode
    (VIEW_MODES), published on the mode's topic at each change and at start (none).
    `publisher(topic)` makes a latched std_msgs/String publisher."""

    def __init__(self, publisher):
        self.modes = [mode for mode, _ in VIEW_MODES]
        self.models = {mode: set() for mode, _ in VIEW_MODES}
        self.publishers = {mode: publisher(topic) for mode, topic in VIEW_MODES}
        for mode in self.models:
            self._publish(mode)

    def is_on(self, mode, name):
        return name in self.models[mode]

    def toggle(self, mode, name):
        """Model `name` into mode, or out of it; whether it is in it now."""
        self.models[mode].symmetric_difference_update({name})
        self._publish(mode)
        return self.is_on(mode, name)

    def forget(self, name):
        """A model gone: in no mode."""
        for mode, models in self.models.items():
            if name in models:
                models.discard(name)
                self._publish(mode)

    def _publish(self, mode):
        from std_msgs.msg import String
        self.publishers[mode].publish(String(data='\n'.join(sorted(self.models[mode]))))


class ModelMenus:
    """Each handle's right-click menu (an interactive_markers MenuHandler of its own, so that
    its View entries' check marks are its model's), in Gazebo's order: Move To, Follow and Stop
    Following, through view (a ViewRequests), View > Transparent, Wireframe, Collisions, Joints,
    Center of Mass and Inertia, through views (view groups: a ModelViews and a ModelMarkerViews,
    each with its `modes`), Apply Force/Torque, through open_wrench_dialog(name), Reset Model Pose, through
    reset(name) (a ResetModel call), and Delete, through delete(name) (a DeleteModel call), on
    `server` (the handles' InteractiveMarkerServer); the calls raise ServiceUnavailable when they
    cannot be made."""

    def __init__(self, server, reset, delete, open_wrench_dialog, view, views, say_once):
        self.server = server
        self.reset = reset
        self.delete = delete
        self.open_wrench_dialog = open_wrench_dialog
        self.view = view
        self.views = {mode: group for group in views for mode in group.modes}
        self.say_once = say_once
        self.menus = {}  # model name -> its MenuHandler

    def apply(self, name):
        """Model name's menu on its handle (the server's changes applied by the caller)."""
        if name not in self.menus:
            self.menus[name] = self._menu(name)
        self.menus[name].apply(self.server, name)

    def forget(self, name):
        self.menus.pop(name, None)
        for group in set(self.views.values()):
            group.forget(name)

    def _menu(self, name):
        from interactive_markers.menu_handler import MenuHandler
        menu = MenuHandler()
        menu.insert('Move To', callback=lambda feedback: self.view.move_to(name))
        menu.insert('Follow', callback=lambda feedback: self.view.follow(name))
        menu.insert('Stop Following', callback=lambda feedback: self.view.stop_following())
        view = menu.insert('View')
        for mode in self.views:
            entry = menu.insert(mode, parent=view,
                                callback=lambda feedback, mode=mode: self._toggle(menu, mode,
                                                                                  feedback))
            menu.setCheckState(entry, MenuHandler.UNCHECKED)
        menu.insert('Apply Force/Torque', callback=lambda feedback: self.open_wrench_dialog(name))
        menu.insert('Reset Model Pose', callback=lambda feedback: self._call(
            self.reset, RESET_MODEL, 'reset', name))
        menu.insert('Delete', callback=lambda feedback: self._call(
            self.delete, DELETE_MODEL, 'delete', name))
        return menu

    def _toggle(self, menu, mode, feedback):
        from interactive_markers.menu_handler import MenuHandler
        on = self.views[mode].toggle(mode, feedback.marker_name)
        menu.setCheckState(feedback.menu_entry_id,
                           MenuHandler.CHECKED if on else MenuHandler.UNCHECKED)
        menu.reApply(self.server)
        self.server.applyChanges()

    def _call(self, call, service, verb, name):
        try:
            result = call(name)
        except ServiceUnavailable as error:
            self.say_once('cannot %s %s through %s: %s' % (verb, name, service, error))
            return
        if not result.success:
            self.say_once('%s refused to %s %s: %s' % (service, verb, name,
                                                       result.status_message))


class ViewRequests:
    """Move To and Follow for the Gazebo panel (gazebo_ros_panels), which moves rviz's view: a
    model's name on MOVE_TO_TOPIC or FOLLOW_TOPIC, an empty one on FOLLOW_TOPIC to stop
    following. `publisher(topic)` makes a std_msgs/String publisher; with no panel listening, the
    view stays and say_once says so."""

    def __init__(self, publisher, say_once):
        self.publishers = {topic: publisher(topic) for topic in (MOVE_TO_TOPIC, FOLLOW_TOPIC)}
        self.say_once = say_once

    def move_to(self, name):
        self._send(MOVE_TO_TOPIC, name)

    def follow(self, name):
        self._send(FOLLOW_TOPIC, name)

    def stop_following(self):
        self._send(FOLLOW_TOPIC, '')

    def _send(self, topic, name):
        from std_msgs.msg import String
        publisher = self.publishers[topic]
        if publisher.get_num_connections() == 0:
            self.say_once('no Gazebo panel listens on %s: the view stays' % topic)
        publisher.publish(String(data=name))


class WrenchDialogs:
    """Gazebo's Apply Force/Torque dialogs (gazebo_ros.wrench_dialog), one process per model
    at most, on this node's display and graph; closed with the node."""

    def __init__(self):
        self.dialogs = {}  # model name -> its dialog's Popen

    def open(self, name):
        if name in self.dialogs and self.dialogs[name].poll() is None:
            return
        self.dialogs[name] = subprocess.Popen([sys.executable, '-m', 'gazebo_ros.wrench_dialog',
                                               name])

    def close_all(self):
        for dialog in self.dialogs.values():
            if dialog.poll() is None:
                dialog.send_signal(signal.SIGINT)
        for dialog in self.dialogs.values():
            try:
                dialog.wait(timeout=DIALOG_STOP_SECONDS)
            except subprocess.TimeoutExpired:  # a hung dialog
                dialog.kill()
                dialog.wait()


def proxy_call(rospy, service, service_class):
    """A call of `service` over one connection kept open (the poses are asked for FOLLOW_HZ
    times a second while the world is paused), opened again after a failure; raises
    ServiceUnavailable when the service is not served or the call fails."""
    proxies = []

    def call(*args):
        if not proxies:
            proxies.append(rospy.ServiceProxy(service, service_class, persistent=True))
        try:
            return proxies[0](*args)
        except (rospy.ServiceException, rospy.ROSException, OSError) as error:
            proxies.pop().close()
            raise ServiceUnavailable(str(error)) from None
    return call


def asked_poses(get_world_properties, get_model_state):
    """The ask_poses of ModelHandles through the two calls (proxy_call's)."""
    def ask():
        world = get_world_properties()
        if not world.success:
            raise ServiceUnavailable(world.status_message)
        poses = {}
        for name in world.model_names:
            state = get_model_state(name, '')
            if state.success:  # else deleted meanwhile
                poses[name] = state.pose
        return poses
    return ask


def keep_wall_time(rospy):
    """Makes this node's ROS time the wall clock's whatever /use_sim_time says. The marker
    server refuses a client's feedback within 1 s of ROS time after the marker's creation or
    another client's feedback, and sends its keep-alives on a ROS timer: on the simulator's clock
    a paused world would refuse every drag and stop the keep-alives."""
    from rospy.impl import simtime
    if getattr(simtime, '_clock_sub', None) is not None:
        simtime._clock_sub.unregister()
        simtime._clock_sub = None
    rospy.rostime.switch_to_wallclock()


def main(argv):
    import rospy
    from gazebo_msgs.srv import (DeleteModel, GetLinkProperties, GetModelProperties,
                                 GetModelState, GetWorldProperties, SetLinkProperties,
                                 SetModelState)
    from interactive_markers.interactive_marker_server import InteractiveMarkerServer
    from onedof_sim.srv import ResetModel
    from std_msgs.msg import String
    from visualization_msgs.msg import MarkerArray
    # Its own signal handling: the node ends its loop on SIGINT or SIGTERM and gives a model
    # held mid-drag its gravity back before rospy shuts down (after which no service is called).
    rospy.init_node(NODE_NAME, argv=argv, disable_signals=True)
    stopping = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stopping.set())
    keep_wall_time(rospy)
    server = InteractiveMarkerServer(SERVER_TOPIC)
    say_once = said_once(lambda text: rospy.logwarn('model handles: %s', text))
    dialogs = WrenchDialogs()
    view = ViewRequests(lambda topic: rospy.Publisher(topic, String, queue_size=10), say_once)
    gravity = GravityHold(proxy_call(rospy, GET_MODEL_PROPERTIES, GetModelProperties),
                          proxy_call(rospy, GET_LINK_PROPERTIES, GetLinkProperties),
                          proxy_call(rospy, SET_LINK_PROPERTIES, SetLinkProperties), say_once)
    views = [ModelViews(lambda topic: rospy.Publisher(topic, String, queue_size=1, latch=True)),
             ModelMarkerViews(rospy.Publisher(MODEL_VIEW_MARKERS, MarkerArray, queue_size=100),
                              lambda topic, callback: rospy.Subscriber(topic, MarkerArray,
                                                                       callback, queue_size=1))]
    menus = ModelMenus(server, proxy_call(rospy, RESET_MODEL, ResetModel),
                       proxy_call(rospy, DELETE_MODEL, DeleteModel), dialogs.open, view, views,
                       say_once)
    handles = ModelHandles(server, proxy_call(rospy, SET_MODEL_STATE, SetModelState),
                           asked_poses(proxy_call(rospy, GET_WORLD_PROPERTIES, GetWorldProperties),
                                       proxy_call(rospy, GET_MODEL_STATE, GetModelState)),
                           gravity, say_once, menus)
    rospy.Subscriber(MODEL_STATES, rospy.AnyMsg, handles.on_model_states, queue_size=1)
    rospy.Subscriber(SELECTED_TOPIC, String, handles.on_selected, queue_size=1)
    rospy.loginfo('model handles: serving %s', SERVER_TOPIC)
    # Wall time: the rates bound the node's cost whatever the simulator's clock does (paused too).
    next_follow = time.monotonic()
    while not stopping.is_set() and not rospy.is_shutdown():
        now = time.monotonic()
        handles.send_moves(now)
        if now >= next_follow:
            handles.follow(now)
            next_follow = now + 1.0 / FOLLOW_HZ
        time.sleep(1.0 / DRAG_HZ)
    handles.let_all_go()
    dialogs.close_all()
    rospy.signal_shutdown('stopped')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
