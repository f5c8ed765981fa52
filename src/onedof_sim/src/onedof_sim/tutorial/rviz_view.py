"""rviz with the committed view (the robot, and the simulated world's other models as collision
markers), on the user's display or on a private Xvfb, and a screenshot of it once the picture stops
changing.

rviz is the one process of the main job that may die without failing it. rviz 1.14 (Qt 5, OGRE
1.12, Mesa's software renderer) aborts when its X server goes first: libX11's I/O error handler
calls exit() in rviz's render thread while roscpp's threads still run and use what exit()'s
destructors free, and glibc aborts on the corrupted heap (`free(): invalid next size`, a failed
mutex assertion); stop() therefore ends rviz before its Xvfb. For an abort of rviz at any other
time, the view restarts a dead rviz, a bounded number of times in all, says each time which rviz
died and how, and, when every try has failed, tells its caller why the screenshot is missing
instead of raising, so that the job can write its other outputs first.
"""
import math
import os
import shutil
import subprocess
import xmlrpc.client

import yaml

from onedof_harness.private_ros import exit_status_text, log_tail
from onedof_sim.simulator_extras import MARKERS_TOPIC as MARKERS, request_collision_markers
from onedof_sim.tools import package_path

# rviz processes one view starts at most: the first and two restarts.
RVIZ_STARTS = 3
# Pixels two frames of a still scene may differ by: rviz's frame-rate counter.
STEADY_PIXELS = 400
# What a restarted rviz must be connected to before the world shows it the final pose again: the
# simulator's markers and robot_state_publisher's transforms.
SHOWN_TOPICS = (MARKERS, '/tf')


class RvizDied(RuntimeError):
    """The rviz process ended while the view was waiting for it."""


def xvfb_display(log_text):
    """The display (':N') whose number Xvfb -displayfd 1 wrote on its output, a line of digits,
    once it accepts clients; else None."""
    for line in log_text.splitlines():
        if line.strip().isdigit():
            return ':' + line.strip()
    return None


def start_xvfb(ros, screen='1000x720x24'):
    """An Xvfb of `ros`'s graph on a display it picks itself (-displayfd), so that servers started
    side by side never share one; returns (its process, its display ':N')."""
    xvfb = ros.start(['Xvfb', '-displayfd', '1', '-screen', '0', screen, '-nolisten', 'tcp'],
                     name='xvfb')
    display = ros.wait_until(lambda: xvfb_display(ros.log_text(xvfb)), 20,
                             what='Xvfb to choose a display')
    return xvfb, display


class RvizView:
    """rviz on the user's display, or on an Xvfb of its own (Xvfb picks a free display itself, so
    that views started side by side never share one), with robot_state_publisher beside it.
    `say` prints the view's progress and each rviz that failed."""

    def __init__(self, ros, work_dir, say=print, starts=RVIZ_STARTS):
        self.ros = ros
        self.work_dir = work_dir
        self.say = say
        self.starts_left = starts
        self.started = 0
        self.failures = []  # why each rviz failed, in the order they failed
        self._failed_rviz = None  # the last rviz whose failure is recorded
        self.env = {}
        self.xvfb = None
        if not os.environ.get('DISPLAY'):
            self.xvfb, self.env['DISPLAY'] = start_xvfb(ros)
        self.display = self.env.get('DISPLAY', os.environ.get('DISPLAY'))
        self.config = os.path.join(work_dir, 'tutorial.rviz')
        self._write_config()
        # As display.launch, whose view this is: the simulator's markers draw the world.
        request_collision_markers('/tutorial', ros.master_uri)
        self.robot_state_publisher = ros.start(
            ['rosrun', 'robot_state_publisher', 'robot_state_publisher'],
            name='robot_state_publisher')
        self.rviz = None
        self._stale_nodes = set()
        self._start()

    def _write_config(self):
        with open(os.path.join(package_path('minimal_robot_description'), 'rviz',
                               'minimal_robot.rviz')) as f:
            config = yaml.safe_load(f)
        # rviz renders in software here: a few frames a second leave the CPU to the controller.
        config['Visualization Manager']['Global Options']['Frame Rate'] = 5
        with open(self.config, 'w') as f:
            yaml.safe_dump(config, f)

    def _start(self):
        # A crashed rviz stays registered with the master: its node names are not the new one's.
        self._stale_nodes |= set(self._rviz_nodes())
        self.starts_left -= 1
        self.started += 1
        name = 'rviz' if self.started == 1 else 'rviz_%d' % self.started
        # may_exit: rviz dying is the view's to notice and handle, not a failure of the graph.
        self.rviz = self.ros.start(['rosrun', 'rviz', 'rviz', '-d', self.config], name=name,
                                   env=dict(self.env, LIBGL_ALWAYS_SOFTWARE='1'), may_exit=True)

    def _ended(self):
        tail = log_tail(self.ros.log_text(self.rviz), 3).replace('\n', ' | ')
        return 'rviz exited (%s); the end of its log %s: %s' % (
            exit_status_text(self.rviz.returncode), self.ros.log_path(self.rviz.log_name), tail)

    def _failed(self, reason):
        """Records why the current rviz failed and ends it if it still runs."""
        if self.rviz.poll() is None:
            self.ros.terminate(self.rviz)
        self._failed_rviz = self.rviz
        self.failures.append('try %d: %s' % (self.started, reason))
        self.say('rviz try %d of %d failed: %s%s' % (
            self.started, self.started + self.starts_left, reason,
            '; starting rviz again' if self.starts_left else ''))

    def _wait(self, condition, timeout, what, interval=0.05):
        """ros.wait_until for the current rviz: raises RvizDied as soon as it has exited."""
        def alive_and(condition=condition):
            if self.rviz.poll() is not None:
                raise RvizDied(self._ended())
            return condition()
        return self.ros.wait_until(alive_and, timeout, interval=interval, what=what)

    def _tries(self, attempt):
        """Runs attempt(restarted) with the current rviz, and again with a new rviz after each
        failure while starts are left; returns True once an attempt succeeds, False when all
        failed. `restarted` says whether this rviz was started by this call."""
        restarted = False
        while True:
            if self._failed_rviz is not self.rviz:
                try:
                    if self.rviz.poll() is not None:
                        raise RvizDied(self._ended())
                    attempt(restarted)
                    return True
                except (RvizDied, TimeoutError) as failure:
                    self._failed(str(failure))
            if not self.starts_left:
                return False
            self._start()
            restarted = True

    def wait_until_up(self, timeout=90):
        """Until rviz subscribes to the markers; restarts it if it dies first. Returns whether an
        rviz is up (False once every try has failed: the screenshot will say so)."""
        return self._tries(lambda restarted: self._wait_subscribed(timeout))

    def _wait_subscribed(self, timeout):
        self._wait(lambda: self._subscriber_node(MARKERS), timeout,
                   what='rviz to subscribe to %s' % MARKERS)

    def screenshot(self, path, refresh=None, timeout=90):
        """Grabs frames until two in a row are the same but for a few pixels (rviz's frame-rate
        counter) and not blank, and writes that one at path. An rviz started here (the one before
        it died) has not seen the world yet: once it is connected to the markers and transforms,
        refresh() has the world show its pose again before each frame. Returns None once path is
        written, else why the screenshot is missing (path is then not written)."""
        frame = os.path.join(self.work_dir, 'frame.png')
        previous = os.path.join(self.work_dir, 'previous.png')

        def steady_frame(refresh=None):
            if refresh:
                refresh()
            if os.path.exists(frame):
                os.replace(frame, previous)
            if not self._grab(frame) or is_blank(frame) or not os.path.exists(previous):
                return False
            return differing_pixels(frame, previous) < STEADY_PIXELS

        def attempt(restarted):
            self._wait_subscribed(timeout)
            shown_again = restarted and refresh
            if shown_again:
                self._wait(lambda: all(self._connected(topic) for topic in SHOWN_TOPICS),
                           timeout, what='rviz to connect to %s' % ' and '.join(SHOWN_TOPICS))
                # A connection is no message: the world shows its pose until rviz has received
                # the markers and a transform (the markers come at 10 Hz of sim time, a control
                # period is 10 ms). Two frames of an rviz that has drawn nothing since it started
                # would agree too.
                self._wait(lambda: refresh() or all(self._received(topic)
                                                    for topic in SHOWN_TOPICS),
                           timeout, interval=0.2,
                           what='rviz to receive %s' % ' and '.join(SHOWN_TOPICS))
            for stale in (frame, previous):
                if os.path.exists(stale):
                    os.remove(stale)
            # A connection is up before its first message arrives, and one message may land
            # before rviz's displays are ready for it: the world shows its pose before each
            # frame until two frames agree.
            self._wait(lambda: steady_frame(refresh if shown_again else None), timeout,
                       interval=0.5, what='a steady rviz picture')
            shutil.copyfile(frame, path)

        if self._tries(attempt):
            return None
        return 'rviz failed on all %d tries (%s)' % (self.started, '; '.join(self.failures))

    def stop(self):
        """Ends rviz before its display: rviz whose X server goes first exits from Qt's X error
        handler with its ROS threads still running, and aborts in static destructors."""
        self.ros.terminate(self.rviz)
        self.ros.terminate(*[proc for proc in (self.robot_state_publisher, self.xvfb) if proc])

    def _grab(self, path):
        result = subprocess.run(['import', '-display', self.display, '-window', 'root', path],
                                capture_output=True, text=True)
        return result.returncode == 0

    def _rviz_nodes(self):
        _, _, (_, subscribers, _) = self.ros.master().getSystemState('/tutorial')
        return [node for name, nodes in subscribers if name == MARKERS
                for node in nodes if 'rviz' in node]

    def _subscriber_node(self, topic):
        """The current rviz's node name once it subscribes to topic, else None."""
        _, _, (_, subscribers, _) = self.ros.master().getSystemState('/tutorial')
        return next((node for name, nodes in subscribers if name == topic for node in nodes
                     if 'rviz' in node and node not in self._stale_nodes), None)

    def _rviz_api(self):
        """The current rviz's XML-RPC server, or None before it has registered."""
        node = self._subscriber_node(MARKERS)
        if not node:
            return None
        code, _, uri = self.ros.master().lookupNode('/tutorial', node)
        return xmlrpc.client.ServerProxy(uri) if code == 1 else None

    def _connected(self, topic):
        """Whether the current rviz has a publisher's connection on topic (its bus info)."""
        try:
            _, _, connections = self._rviz_api().getBusInfo('/tutorial')
        except (AttributeError, OSError, xmlrpc.client.Error):
            return False
        # roscpp: [id, publisher, direction, transport, topic, connected, ...] per connection.
        return any(len(c) > 5 and c[2] == 'i' and c[4] == topic and c[5] for c in connections)

    def _received(self, topic):
        """Messages the current rviz has received on topic (its bus statistics)."""
        try:
            # roscpp answers [publications, subscriptions] (no status code, unlike getBusInfo);
            # a subscription is [topic, [[connection id, bytes, messages, drops, ...], ...]].
            _, subscriptions = self._rviz_api().getBusStats('/tutorial')[:2]
            return sum(link[2] for name, links in subscriptions if name == topic
                       for link in links)
        except (AttributeError, OSError, xmlrpc.client.Error, ValueError, TypeError,
                IndexError):
            return 0


def differing_pixels(png_a, png_b):
    result = subprocess.run(['compare', '-metric', 'AE', png_a, png_b, 'null:'],
                            capture_output=True, text=True)
    try:
        return float(result.stderr.split()[0])
    except (IndexError, ValueError):
        return math.inf


def is_blank(png_path):
    result = subprocess.run(['identify', '-format', '%k', png_path], capture_output=True,
                            text=True)
    return result.returncode != 0 or result.stdout.strip() in ('', '1')
