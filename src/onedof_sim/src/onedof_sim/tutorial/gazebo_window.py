"""The simulator's window driven as a student drives Gazebo's: gzclient (rviz on gazebo_ros'
world.rviz with the Gazebo panel and the model handles) on an Xvfb of its own, its keys and mouse
through xdotool, the pixels to click computed from the view's camera (world.rviz's orbit view over
rviz's 3D view, as xwininfo places it on the screen), and screenshots of the screen once its
picture holds still.

A model is inserted as in Gazebo's Insert tab: the model chosen in the panel's list by typing its
name, "Insert by clicking", and a click on the ground where it goes. It is moved as in Gazebo's
translate mode: the panel's "Move models" (the handles shown, the Select Model tool current), a
click on the model (its handle's arrows and rings on it once the view says it selected), then
the mouse pressed on the middle of the arrow's head of its handle, moved by the pixels the
distance projects to, and released; a handle's ring turns it the same way. The press, each step
of the move and the release go on once rviz has reported the one before (its feedback to the
model handles), and the drag is done when the model is where rviz last reported it: the
driver waits for rviz, never for a time.
"""
import math
import os
import re
import shutil
import subprocess

import yaml

from onedof_sim.tools import package_path
from onedof_sim.tutorial.rviz_view import differing_pixels, is_blank, start_xvfb

PANEL_UP = 'gazebo_ros_panels: the Gazebo panel is up'
CATALOG_LISTED = 'gazebo_ros_panels: Insert: '
HANDLES_UPDATE = '/gazebo_model_handles/update'
HANDLES_FEEDBACK = '/gazebo_model_handles/feedback'
# The model the view's Select Model tool selected (std_msgs/String, latched).
SELECTED_TOPIC = '/gazebo_window/selected_model'
# interactive_markers' default controls of a handle of scale 1 (the model handles'): a MOVE_AXIS
# arrow runs from 0.5 to 0.9 m along its axis, its head the outer part, clear of the rotate rings
# (radius 0.5 to 0.65 m); ARROW_GRAB is where the mouse takes it. RING_GRAB: the middle of a ring.
ARROW_GRAB = 0.8
RING_GRAB = 0.575
# Mouse positions a drag passes through on its way, as a hand's drag does (rviz moves the model
# at each).
DRAG_MOVES = 10
# A handle's pose changed by at least this (m, quaternion component) is one rviz moved.
MOVED = 1e-9
# Pixels two frames of a still picture may differ by (the text cursor, the panel's clocks).
STEADY_PIXELS = 400


def xdotool(display, *args):
    """Runs xdotool on display; its CompletedProcess."""
    return subprocess.run(['xdotool'] + [str(arg) for arg in args], env={'DISPLAY': display},
                          capture_output=True, text=True, timeout=60)


def world_view():
    """world.rviz's orbit view (its Views: Current): what gzclient shows at start."""
    with open(os.path.join(package_path('gazebo_ros'), 'rviz', 'world.rviz')) as f:
        return yaml.safe_load(f)['Visualization Manager']['Views']['Current']


def orbit_pixel(view, panel, point):
    """The pixel (x, y) of the screen where rviz's orbit view (a config's Views: Current) draws a
    point of the fixed frame in panel (x0, y0, x1, y1): the camera at Distance from the Focal
    Point, at Yaw about z and Pitch above the x-y plane, looking at it with z up; OGRE's vertical
    field of view, 45 degrees, over the render panel."""
    focal = [view['Focal Point'][axis] for axis in 'XYZ']
    yaw, pitch, distance = view['Yaw'], view['Pitch'], view['Distance']
    eye = [f + distance * d for f, d in zip(focal, (math.cos(yaw) * math.cos(pitch),
                                                  math.sin(yaw) * math.cos(pitch),
                                                  math.sin(pitch)))]
    forward = unit([f - e for f, e in zip(focal, eye)])
    right = unit(cross(forward, (0, 0, 1)))
    up = cross(right, forward)
    offset = [p - e for p, e in zip(point, eye)]
    depth = dot(offset, forward)
    x0, y0, x1, y1 = panel
    half_height = math.tan(math.pi / 8) * depth
    half_width = half_height * (x1 - x0) / (y1 - y0)
    return (x0 + (x1 - x0) / 2 * (1 + dot(offset, right) / half_width),
            y0 + (y1 - y0) / 2 * (1 - dot(offset, up) / half_height))


def mouse_position(view, panel, point):
    """Where on the screen (x, y, unrounded) the mouse is to be for rviz to take it at a point of
    the fixed frame, in rviz's orbit view (a config's Views: Current) drawn in panel (x0, y0, x1,
    y1). orbit_pixel gives where the point is drawn, along a panel W pixels wide where pixel i
    spans [i, i + 1); rviz's mouse tools (its interactive markers' drags, SelectionManager's
    get3DPoint, which the Interact and Insert Here tools take a click's point from) cast the ray
    of a mouse at pixel i through the viewport's fraction (i + 0.5) / (W - 1), between half a pixel
    and a pixel and a half further right (down) than the pixel's own place."""
    column, row = orbit_pixel(view, panel, point)
    x0, y0, x1, y1 = panel

    def mouse(at, start, size):
        return start + (at - start) * (size - 1) / size - 0.5
    return mouse(column, x0, x1 - x0), mouse(row, y0, y1 - y0)


def dot(a, b):
    return sum(p * q for p, q in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def unit(v):
    norm = math.sqrt(dot(v, v))
    return [c / norm for c in v]


def render_view(display):
    """(x, y, width, height) of rviz's 3D view on the screen: the one unnamed native window under
    rviz's main window (Ogre's), as xwininfo lists it; None until there is exactly one."""
    tree = subprocess.run(['xwininfo', '-root', '-tree'], env={'DISPLAY': display},
                          capture_output=True, text=True, timeout=60).stdout
    views = [tuple(int(v) for v in match.groups()) for match in re.finditer(
        r'\(has no name\): \(\)\s+(\d+)x(\d+)\+-?\d+\+-?\d+\s+\+(-?\d+)\+(-?\d+)', tree)]
    views = [(x, y, w, h) for w, h, x, y in views if w > 100 and h > 100]
    return views[0] if len(views) == 1 else None


class GazeboWindow:
    """gzclient on an Xvfb of `ros`'s graph (a PrivateRos), up once its Gazebo panel has listed
    the model path and its 3D view is on the screen. `say` prints what the student does."""

    def __init__(self, ros, say=print, timeout=300):
        self.ros = ros
        self.say = say
        self.xvfb, self.display = start_xvfb(ros)
        say('rosrun gazebo_ros gzclient   (the simulator\'s window, on Xvfb %s)' % self.display)
        self.gzclient = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                                  env={'DISPLAY': self.display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
        ros.wait_until(lambda: PANEL_UP in self.log(), timeout, what='the Gazebo panel')
        ros.wait_until(lambda: CATALOG_LISTED in self.log(), timeout,
                       what='the Gazebo panel to list the model path')
        self.window = ros.wait_until(
            lambda: self.xdotool('search', '--onlyvisible', '--name', 'RViz').stdout.split(),
            timeout, what="rviz's window")[0]
        x, y, width, height = ros.wait_until(lambda: render_view(self.display), timeout,
                                             what="rviz's 3D view")
        self.panel = (x, y, x + width, y + height)
        self.view = world_view()

    def log(self):
        return self.ros.log_text(self.gzclient)

    def xdotool(self, *args):
        return xdotool(self.display, *args)

    def _must(self, *args):
        done = self.xdotool(*args)
        if done.returncode != 0:
            raise RuntimeError('xdotool %s: %s' % (' '.join(map(str, args)), done.stderr.strip()))

    def press(self, *keys):
        """Focuses rviz's window and types keys (xdotool's names) into it."""
        self._must('windowfocus', '--sync', self.window)
        self._must('key', '--clearmodifiers', *keys)

    def pixel(self, point):
        """The screen pixel to put the mouse on for rviz to take it at a point of the world."""
        return tuple(round(c) for c in mouse_position(self.view, self.panel, point))

    def insert_by_click(self, typed, shown_name, point, timeout=120):
        """Chooses the model whose name starts with `typed` in the Insert tab's list (shown there
        as shown_name), presses "Insert by clicking" and clicks where the view shows `point` on
        the ground."""
        waiting = 'gazebo_ros_panels: click in the 3D view where %s goes' % shown_name
        before = self.log().count(waiting)
        self.say('Insert tab: %s, Insert by clicking, a click on the ground at (%g, %g)'
                 % (shown_name, point[0], point[1]))
        self.press('alt+i', 'alt+d', *typed, 'alt+c')
        self.ros.wait_until(lambda: self.log().count(waiting) > before, timeout,
                            what='the Gazebo panel to wait for a click')
        x, y = self.pixel(point)
        self._must('mousemove', '--sync', x, y, 'click', '1')

    def choose_in_world_tab(self, name):
        """The World tab raised, its model tree focused (Alt+D) and `name` typed: the tree's
        keyboard search makes that model the chosen one."""
        self.say('World tab: %s chosen in the tree' % name)
        self.press('alt+w', 'alt+d', *name)

    def move_chosen_in_world_tab(self, timeout=120):
        """The World tab's Move (Alt+O): the chosen model set to the pose its fields show. The
        model moved, as the panel's line names it."""
        moved = 'gazebo_ros_panels: moved '
        before = self.log().count(moved)
        self.press('alt+w', 'alt+o')
        self.ros.wait_until(lambda: self.log().count(moved) > before, timeout,
                            what='the World tab to move its chosen model')
        return re.match(r'[^\s\x1b]*', self.log().rsplit(moved, 1)[1]).group()

    def show_handles(self, timeout=120):
        """The panel's "Move models" (Alt+T): the handles shown (rviz subscribes to them), and
        Select Model the current tool."""
        self.say('Move models (Gazebo\'s translate mode)')
        self.press('alt+t')
        self.ros.wait_until(self._handles_shown, timeout, what='rviz to show the model handles')

    def hide_handles(self, timeout=120):
        """"Move models" again: the handles hidden (Gazebo's select mode)."""
        self.say('Move models off (Gazebo\'s select mode)')
        self.press('alt+t')
        self.ros.wait_until(lambda: not self._handles_shown(), timeout,
                            what='rviz to hide the model handles')

    def select(self, name, point, timeout=120):
        """Clicks where the view shows world point `point`, on model `name`'s visuals, until the
        view names `name` selected ('' for a click on no model): a model just added to the world
        is drawn once its visuals reach rviz, and a click before that selects none. Each click
        waits for the view's answer to it."""
        import rospy
        from std_msgs.msg import String
        said = []
        subscriber = rospy.Subscriber(SELECTED_TOPIC, String, lambda m: said.append(m.data))
        try:
            # The latched answer to an earlier click first: the next one is this click's.
            self.ros.wait_until(lambda: subscriber.get_num_connections() > 0, timeout,
                                what='the view\'s selection')
            self.say('a click on %s' % (name or 'no model'))
            self._must('mousemove', '--sync', *self.pixel(point))

            def clicked():
                answers = len(said)
                self._must('click', '1')
                self.ros.wait_until(lambda: len(said) > answers, timeout,
                                    what='the view to answer a click')
                return said[-1] == name
            self.ros.wait_until(clicked, timeout, what='the view to select %r' % name)
        finally:
            subscriber.unregister()

    def _handles_shown(self):
        _, _, (_, subscribers, _) = self.ros.master().getSystemState('/gazebo_window')
        return any(topic == HANDLES_UPDATE and nodes for topic, nodes in subscribers)

    def grab(self, drag, point, timeout=120):
        """The mouse pressed where the view shows world point `point`, on a control of drag's
        handle (a DragSeen), once rviz reports the press there."""
        presses = drag.presses
        self._must('mousemove', '--sync', *self.pixel(point))
        self._must('mousedown', '1')
        self.ros.wait_until(lambda: drag.presses > presses, timeout,
                            what="rviz to report the mouse pressed on %s's handle" % drag.name)

    def move(self, drag, start, end, timeout=120):
        """The pressed mouse moved in DRAG_MOVES steps from where rviz takes `start` to where it
        takes `end`, as a hand's drag passes through the pixels between; after each step, the
        next waits for rviz to report the handle's pose there (drag: a DragSeen on the handle's
        model), so that every step is one rviz has taken however slow it is."""
        first, last = self.pixel(start), self.pixel(end)
        at = first
        for i in range(1, DRAG_MOVES + 1):
            step = tuple(round(s + (e - s) * i / DRAG_MOVES) for s, e in zip(first, last))
            if step == at:
                continue
            # A pose rviz reports twice (it may) is no report of this step: the pose must change.
            reported = drag.pose
            self._must('mousemove', '--sync', *step)
            self.ros.wait_until(lambda: not same_pose(drag.pose, reported, MOVED), timeout,
                                what="rviz to report %s's handle dragged to pixel %s"
                                     % (drag.name, step))
            at = step

    def flick(self, point):
        """The pressed mouse moved straight to where the view shows `point`, in one motion and
        with no wait for rviz, as a quick hand lets go of a drag."""
        self._must('mousemove', '--sync', *self.pixel(point))

    def press_and_move(self, drag, grab, to):
        """The mouse pressed where the view shows `grab` and moved to where it shows `to`,
        held there (release() lets it go)."""
        self.grab(drag, grab)
        self.move(drag, grab, to)

    def release(self, drag, pose_of, timeout=120):
        """Releases the mouse, waits for rviz to report the release of drag's handle and for its
        model to be where the drag last reported (pose_of(name): the model's
        geometry_msgs/Pose), as the model handles release it; returns that pose."""
        released = drag.releases
        self._must('mouseup', '1')
        self.ros.wait_until(lambda: drag.releases > released, timeout,
                            what="rviz to report %s's handle released" % drag.name)
        last = drag.pose
        self.ros.wait_until(lambda: same_pose(pose_of(drag.name), last), timeout,
                            what='%s released where the drag left it' % drag.name)
        return last

    def choose_from_menu(self, point, entry, sub_entry=None, timeout=60):
        """Right-clicks where the view shows `point` (a handle's control) and chooses the
        entry-th (from 1) entry of the menu that opens there, with the keyboard; with sub_entry,
        the sub_entry-th entry of the entry's submenu."""
        shown = self._shown_windows()
        self._must('mousemove', '--sync', *self.pixel(point))
        self._must('click', '3')
        self.ros.wait_until(lambda: self._shown_windows() - shown, timeout,
                            what='the right-click menu')
        if sub_entry is None:
            self._must('key', *(['Down'] * entry), 'Return')
            return
        # Right opens the submenu on its first entry.
        self._must('key', *(['Down'] * entry), 'Right', *(['Down'] * (sub_entry - 1)), 'Return')

    def fill_in(self, title, values, timeout=120):
        """Types `values` (strings) into the fields of the window titled `title` (a dialog the
        view opened), from the field with the focus on, Tab between them, and presses Return
        (the dialog's default button)."""
        dialog = self.ros.wait_until(
            lambda: self.xdotool('search', '--onlyvisible', '--name',
                                 '^%s$' % re.escape(title)).stdout.split(),
            timeout, what='the window %r' % title)[0]
        self._must('windowfocus', '--sync', dialog)
        for i, value in enumerate(values):
            if i:
                self._must('key', 'Tab')
            self._must('key', 'ctrl+a')
            self._must('type', value)
        self._must('key', 'Return')

    def read_view(self, path, timeout=120):
        """rviz's current view (its saved config's Views: Current: Focal Point, Distance, Yaw,
        Pitch, ...), saved to `path` through rviz's save_config; the pixels computed from here
        on are that view's."""
        import rospy
        from gazebo_ros.world_view import SendFilePath

        def save_config():
            _, _, (_, _, services) = self.ros.master().getSystemState('/gazebo_window')
            return next((name for name, _ in services if name.endswith('/save_config')), None)
        proxy = rospy.ServiceProxy(self.ros.wait_until(save_config, timeout,
                                                       what="rviz's save_config"), SendFilePath)

        def saved():
            try:
                return proxy(SendFilePath._request_class(path)).success
            except (rospy.ServiceException, OSError):
                return False
        try:
            self.ros.wait_until(saved, timeout, what='rviz to save its config')
        finally:
            proxy.close()
        with open(path) as f:
            self.view = yaml.safe_load(f)['Visualization Manager']['Views']['Current']
        return self.view

    def _shown_windows(self):
        return set(self.xdotool('search', '--onlyvisible', '--classname', 'rviz').stdout.split())

    def screenshot(self, path, timeout=120):
        """Grabs the screen until two frames in a row agree but for STEADY_PIXELS and are not
        blank, and writes the last at path."""
        frames = [path + '.previous.png', path + '.frame.png']
        for stale in frames:
            if os.path.exists(stale):
                os.remove(stale)

        def steady():
            if os.path.exists(frames[1]):
                os.replace(frames[1], frames[0])
            grabbed = subprocess.run(['import', '-display', self.display, '-window', 'root',
                                      frames[1]], capture_output=True, timeout=60)
            return (grabbed.returncode == 0 and not is_blank(frames[1]) and
                    os.path.exists(frames[0]) and
                    differing_pixels(frames[0], frames[1]) < STEADY_PIXELS)
        self.ros.wait_until(steady, timeout, interval=0.5, what='a steady picture of the window')
        shutil.move(frames[1], path)
        os.remove(frames[0])

    def stop(self):
        """Ends rviz before its display (see rviz_view: rviz whose X server goes first aborts)."""
        self.ros.terminate(self.gzclient)
        self.ros.terminate(self.xvfb)


# The tutorial's table through the window: where the student's click puts it (on the ground,
# clear of the arm, in the view), then dragged along x to where the tutorial wants it.
TABLE_SHOWN_NAME = 'Cafe table'
TABLE_INSERTED_AT = (1.3, 0.0)
# The height of the cafe table's top (src/onedof_sim/models/cafe_table), where a click selects it.
TABLE_TOP = 0.775
# The window's screenshots, in the order the student sees them.
WINDOW_SHOTS = ('window_1_open.png', 'window_2_table_inserted.png', 'window_3_move_models.png',
                'window_4_table_dragged.png', 'window_5_table_2.5.png')


class HandlesSeen:
    """The model handles as rviz receives them: the server's latched full state, republished
    after each change ({name: InteractiveMarker}; None until the first)."""

    def __init__(self, rospy):
        from visualization_msgs.msg import InteractiveMarkerInit
        self.markers = None
        self.subscriber = rospy.Subscriber(HANDLES_UPDATE + '_full',
                                           InteractiveMarkerInit, self._received, queue_size=10)

    def _received(self, init):
        self.markers = {marker.name: marker for marker in init.markers}

    def has_controls(self, name):
        """Whether model name's handle has its arrows and rings (the model is selected)."""
        return bool(self.markers and name in self.markers and any(
            control.name == 'move_x' for control in self.markers[name].controls))


class DragSeen:
    """rviz's feedback on model `name`'s handle as the model handles hear it: the pose the drag
    last reported (MOUSE_DOWN or POSE_UPDATE; None before), and how many MOUSE_DOWNs and
    MOUSE_UPs came. Up once it hears rviz (the handles shown)."""

    def __init__(self, ros, rospy, name, timeout=120):
        from visualization_msgs.msg import InteractiveMarkerFeedback
        self.name = name
        self.pose = None
        self.presses = 0
        self.releases = 0
        self.subscriber = rospy.Subscriber(HANDLES_FEEDBACK, InteractiveMarkerFeedback,
                                           self._received, queue_size=100)
        ros.wait_until(lambda: self.subscriber.get_num_connections() > 0, timeout,
                       what="rviz's feedback on the handles")

    def _received(self, feedback):
        if feedback.marker_name != self.name:
            return
        if feedback.event_type in (feedback.MOUSE_DOWN, feedback.POSE_UPDATE):
            self.pose = feedback.pose
        if feedback.event_type == feedback.MOUSE_DOWN:
            self.presses += 1
        elif feedback.event_type == feedback.MOUSE_UP:
            self.releases += 1

    def stop(self):
        self.subscriber.unregister()


def same_pose(a, b, tolerance=1e-6):
    """Whether two geometry_msgs/Pose agree within tolerance (m, and per quaternion component,
    either sign)."""
    position = math.dist((a.position.x, a.position.y, a.position.z),
                         (b.position.x, b.position.y, b.position.z))
    qa = (a.orientation.x, a.orientation.y, a.orientation.z, a.orientation.w)
    qb = (b.orientation.x, b.orientation.y, b.orientation.z, b.orientation.w)
    turn = min(max(abs(p - q) for p, q in zip(qa, qb)), max(abs(p + q) for p, q in zip(qa, qb)))
    return position < tolerance and turn < tolerance


def place_table_by_mouse(window, rospy, x, output, timeout=120):
    """Inserts the cafe table through the window's Insert tab at TABLE_INSERTED_AT, selects it
    with a click and drags it by its handle's x arrow to `x`, the handles shown for the drag
    only, a screenshot in `output` after each step (WINDOW_SHOTS 2 to 4); returns the table's
    name and where the mouse left it (x, y, z)."""
    from gazebo_msgs.srv import GetModelState, GetWorldProperties
    world = rospy.ServiceProxy('/gazebo/get_world_properties', GetWorldProperties)
    model_state = rospy.ServiceProxy('/gazebo/get_model_state', GetModelState)
    before = set(world().model_names)
    window.insert_by_click('Cafe', TABLE_SHOWN_NAME, TABLE_INSERTED_AT + (0.0,))
    name = window.ros.wait_until(
        lambda: next((n for n in world().model_names if n not in before and
                      n.startswith('cafe_table')), None), timeout, what='the cafe table inserted')
    start = model_state(name, '').pose.position
    window.say('%s inserted at (%.3f, %.3f)' % (name, start.x, start.y))
    window.screenshot(os.path.join(output, WINDOW_SHOTS[1]))

    seen = HandlesSeen(rospy)
    window.show_handles()
    window.select(name, (start.x, start.y, TABLE_TOP))
    window.ros.wait_until(lambda: seen.has_controls(name), timeout, what="the table's handle")
    window.screenshot(os.path.join(output, WINDOW_SHOTS[2]))  # drawn before the mouse goes

    window.say('the x arrow of %s dragged by the pixels %.3f m project to'
               % (name, x - start.x))
    drag = DragSeen(window.ros, rospy, name)
    window.press_and_move(drag, (start.x + ARROW_GRAB, start.y, start.z),
                          (x + ARROW_GRAB, start.y, start.z))
    window.release(drag, lambda model: model_state(model, '').pose)
    drag.stop()
    seen.subscriber.unregister()
    end = model_state(name, '').pose.position
    window.say('%s dragged to (%.4f, %.4f, %.4f)' % (name, end.x, end.y, end.z))
    window.hide_handles()
    window.screenshot(os.path.join(output, WINDOW_SHOTS[3]))
    return name, (end.x, end.y, end.z)
