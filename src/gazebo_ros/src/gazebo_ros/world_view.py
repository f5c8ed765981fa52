"""rviz showing the simulated world, as gzclient and gazebo start it: the view of rviz/world.rviz
(the world's visuals on the ground grid, Gazebo's View menu as displays, fixed frame `world`) and
one display for each sensor stream the simulator publishes: a LaserScan, a PointCloud2 or an Image
on the topic a spawned robot's sensor plugin advertises. The simulator publishes its markers only
when asked (gazebo_ros' API has no such topic): the view asks for them as it starts rviz, by
setting the simulator's ~enable_collision_markers, which the node follows while running and which
stays set after the view exits. rviz's /clock is the simulator's view clock (/gazebo/view_clock,
a remapping): the sim time as often as the view's markers move, so that an open window costs the
simulator's loop no message per step (nor does its Gazebo panel, in rviz's process). The view
asks the master which topics of those types the simulator (the node publishing
/gazebo/model_states, which gazebo_ros' API advertises from its start) advertises, as rviz starts
and each second while it runs; when the set changes (a robot with sensors spawned or deleted) it
saves rviz's current configuration (the user's camera and settings), replaces the sensor displays
in it and has rviz load it again. A loaded configuration builds rviz's panels anew, so a world
that has its sensors when the view opens starts with their displays and is not loaded twice. A
world without sensors shows exactly world.rviz.

Beside rviz the view runs the model handles (gazebo_ros.model_handles, the node
/gazebo_model_handles): Gazebo's translate and rotate modes as interactive markers on every
model but the ground plane, world.rviz's "Move models" display; it stops with rviz.

rviz renders in software where there is no GPU (Mesa's llvmpipe: Mesa 22.3 on LLVM 15 here),
which now and then crashes it as it starts, most often inside LLVM compiling a shader (LLVM's
issue 57850, Mesa's 7224). The view then starts rviz again on the same configuration, says so on
its output, and does this a bounded number of times; rviz ended any other way (closed, Ctrl-C)
ends the view with rviz's exit status.

Scans and point clouds are drawn where TF puts their frames relative to `world`, as in any rviz:
robot_state_publisher places a robot's links (a URDF rooted at a link named `world` is placed
in the world; a mobile base's tree starts at the diff drive's `odom`, which with
<odometrySource> world, Gazebo's default, coincides with the world frame).
"""
import os
import shutil
import signal
import struct
import subprocess
import sys
import tempfile

import genpy
import rosgraph
import rosgraph.names
import rospkg
import yaml

from onedof_harness.private_ros import exit_status_text
from onedof_sim.simulator_extras import NODE as SIMULATOR_NAMESPACE, VIEW_CLOCK_TOPIC, \
    request_collision_markers

SENSOR_DISPLAY_PREFIX = 'Sensor: '
# A topic the simulator node advertises from its start (gazebo_ros' API) and no other node does:
# the sensor streams shown are those of the node that publishes it. (The collision markers are
# advertised only once the view asks for them, later than the view first looks.)
SIMULATOR_TOPIC = SIMULATOR_NAMESPACE + '/model_states'
# The depth an image's white stands for: the Kinect's far cutoff (pointCloudCutoffMax's default);
# rviz's normalised range goes black on the NaNs a Kinect's depth image has where nothing is.
DEPTH_SHOWN_M = 5.0
# Seconds between two looks at the master: a sensor appears in the view this long after spawn.
POLL_SECONDS = 1.0
# Bounds the model handles' orderly exit after rviz's; only a hung node waits this long.
HANDLES_STOP_SECONDS = 10.0
# How a crash ends rviz, as opposed to a close or a stop.
CRASH_SIGNALS = (signal.SIGSEGV, signal.SIGBUS, signal.SIGILL, signal.SIGFPE, signal.SIGABRT)
# rviz starts after crashes the view makes, in all.
CRASH_RESTARTS = 3


def ended_by_crash(status):
    """Whether a process's exit status (Popen's returncode) is a crash's, not a close or a stop."""
    return status is not None and status < 0 and -status in CRASH_SIGNALS


def sensor_display(topic, msg_type):
    """The rviz display of one sensor stream, or None for a type the view does not show."""
    name = '%s%s (%s)' % (SENSOR_DISPLAY_PREFIX, topic, msg_type.split('/')[-1])
    common = {'Name': name, 'Enabled': True, 'Value': True}
    if msg_type == 'sensor_msgs/LaserScan':
        # One flat colour: the simulated scans carry no intensities to colour by.
        return dict(common, **{
            'Class': 'rviz/LaserScan', 'Topic': topic, 'Style': 'Flat Squares',
            'Size (m)': 0.03, 'Color Transformer': 'FlatColor', 'Color': '0; 255; 0',
            'Alpha': 1, 'Decay Time': 0, 'Queue Size': 10})
    if msg_type == 'sensor_msgs/PointCloud2':
        # rviz colours the points by the cloud's own fields (rgb when it has them).
        return dict(common, **{
            'Class': 'rviz/PointCloud2', 'Topic': topic, 'Style': 'Points',
            'Size (Pixels)': 2, 'Alpha': 1, 'Decay Time': 0, 'Queue Size': 10})
    if msg_type == 'sensor_msgs/Image':
        # A depth image (32FC1, metres) in grey from 0 to DEPTH_SHOWN_M; colour images as sent.
        return dict(common, **{
            'Class': 'rviz/Image', 'Image Topic': topic, 'Transport Hint': 'raw',
            'Normalize Range': False, 'Min Value': 0, 'Max Value': DEPTH_SHOWN_M,
            'Queue Size': 2})
    return None


def simulator_sensor_topics(system_state, topic_types):
    """Sorted (topic, type) of the streams the view shows that the simulator node advertises.
    system_state and topic_types are the master's getSystemState and getTopicTypes answers."""
    publishers = dict(system_state[0])
    simulators = set(publishers.get(SIMULATOR_TOPIC, ()))
    return sorted((topic, msg_type) for topic, msg_type in topic_types
                  if sensor_display(topic, msg_type) is not None
                  and simulators & set(publishers.get(topic, ())))


def with_sensor_displays(config, topics):
    """config (an rviz configuration) with its sensor displays replaced by those of topics."""
    manager = config['Visualization Manager']
    kept = [display for display in manager.get('Displays') or []
            if not str(display.get('Name', '')).startswith(SENSOR_DISPLAY_PREFIX)]
    manager['Displays'] = kept + [sensor_display(topic, msg_type) for topic, msg_type in topics]
    return config


def world_config_path():
    return os.path.join(rospkg.RosPack().get_path('gazebo_ros'), 'rviz', 'world.rviz')


class _FilePathRequest(genpy.Message):
    """rviz/SendFilePath's request (std_msgs/String path): Debian's rviz has no Python module
    for its services."""
    _md5sum = '8a631822f6e3078667af5e13f8ab06b7'
    _type = 'rviz/SendFilePathRequest'
    _has_header = False
    _full_text = 'std_msgs/String path\n'
    __slots__ = ['path']
    _slot_types = ['string']

    def __init__(self, path=''):
        super().__init__()
        self.path = path

    def serialize(self, buff):
        data = self.path.encode()
        buff.write(struct.pack('<I', len(data)) + data)


class _FilePathResponse(genpy.Message):
    _md5sum = '358e233cde0c8a8bcfea4ce193f8fc15'
    _type = 'rviz/SendFilePathResponse'
    _has_header = False
    _full_text = 'bool success\n'
    __slots__ = ['success']
    _slot_types = ['bool']

    def __init__(self, success=False):
        super().__init__()
        self.success = success

    def deserialize(self, data):
        self.success = bool(data[0])
        return self


class SendFilePath:
    _type = 'rviz/SendFilePath'
    _md5sum = '92f17244ff295b327b62c307fafe751b'
    _request_class = _FilePathRequest
    _response_class = _FilePathResponse


class WorldView:
    """One rviz on the world view, kept showing the simulator's sensor streams."""

    def __init__(self, ros_args=()):
        self.master = rosgraph.Master('/gzclient')
        self.folder = tempfile.mkdtemp(prefix='gzclient_')
        self.config = os.path.join(self.folder, 'world.rviz')
        # rviz's node name: the one roslaunch gives gzclient, else one of this process's own.
        names = [arg.split(':=', 1)[1] for arg in ros_args if arg.startswith('__name:=')]
        self.name = names[-1] if names else 'gzclient_%d' % os.getpid()
        self.node = rosgraph.names.ns_join(rosgraph.names.get_ros_namespace(), self.name)
        self.ros_args = [arg for arg in ros_args if not arg.startswith('__name:=')]
        self.topics = self._sensor_topics() or []
        with open(world_config_path()) as f:
            base = yaml.safe_load(f)
        self._write(with_sensor_displays(base, self.topics))
        self.rviz = None
        self.handles = None
        self.stopping = False  # asked to stop: rviz ending is then no crash to recover from
        self.restarts = 0

    def command(self):
        """rviz on the view, its /clock the simulator's view clock: the sim time as often as the
        view draws (the simulator's views' rate), not a message per step."""
        return (['rosrun', 'rviz', 'rviz', '-d', self.config, '__name:=' + self.name,
                 '/clock:=' + VIEW_CLOCK_TOPIC] + self.ros_args)

    def handles_command(self):
        """The model handles' node (gazebo_ros.model_handles): its own name, this view's
        remappings and namespace, not its log file."""
        return ([sys.executable, '-m', 'gazebo_ros.model_handles'] +
                [arg for arg in self.ros_args if not arg.startswith('__log:=')])

    def start(self):
        request_collision_markers(self.node)
        print('gzclient: the view opens on the simulator\'s sensor streams: %s' % (
            ', '.join(topic for topic, _ in self.topics) or 'none'), flush=True)
        self.handles = subprocess.Popen(self.handles_command())
        self.rviz = subprocess.Popen(self.command())
        return self.rviz

    def stop_handles(self):
        if self.handles and self.handles.poll() is None:
            self.handles.send_signal(signal.SIGINT)
            try:
                self.handles.wait(timeout=HANDLES_STOP_SECONDS)
            except subprocess.TimeoutExpired:
                self.handles.kill()
                self.handles.wait()

    def _sensor_topics(self):
        """The simulator's sensor streams, or None when the master does not answer."""
        try:
            return simulator_sensor_topics(self.master.getSystemState(),
                                           self.master.getTopicTypes())
        except (OSError, rosgraph.MasterException):
            return None

    def _write(self, config):
        with open(self.config, 'w') as f:
            yaml.safe_dump(config, f, default_flow_style=False)

    def _call(self, service, path):
        import rospy
        proxy = rospy.ServiceProxy(rosgraph.names.ns_join(self.node, service), SendFilePath)
        try:
            return proxy(_FilePathRequest(path)).success
        except (rospy.ServiceException, rospy.ROSException, OSError):
            return False
        finally:
            proxy.close()

    def update(self):
        """Shows the simulator's current sensor streams; False while rviz cannot take them yet
        (starting: the next update tries again)."""
        topics = self._sensor_topics()
        if topics is None or topics == self.topics:
            return True
        if not self._call('save_config', self.config):
            return False  # rviz starting: it serves save_config once it is up
        with open(self.config) as f:
            current = yaml.safe_load(f)
        self._write(with_sensor_displays(current, topics))
        if not self._call('load_config_discarding_changes', self.config):
            print('gzclient: rviz did not load the configuration with the sensor streams; '
                  'trying again at the next look', flush=True)
            return False
        self.topics = topics
        print('gzclient: the view shows the simulator\'s sensor streams: %s' % (
            ', '.join(topic for topic, _ in topics) or 'none'), flush=True)
        return True

    def crashed(self, status):
        """Whether rviz ended with `status` by a crash the view recovers from."""
        return not self.stopping and ended_by_crash(status) and self.restarts < CRASH_RESTARTS

    def stop(self, signum):
        """Passes a stop (SIGINT, SIGTERM) on to rviz and the model handles."""
        self.stopping = True
        for process in (self.rviz, self.handles):
            if process and process.poll() is None:
                process.send_signal(signum)

    def run(self):
        """Runs rviz until it exits, updating its sensor displays and starting it again after a
        crash; its exit status."""
        self.start()
        try:
            while True:
                try:
                    status = self.rviz.wait(timeout=POLL_SECONDS)
                except subprocess.TimeoutExpired:
                    self.update()
                    continue
                if not self.crashed(status):
                    return status
                self.restarts += 1
                print('gzclient: rviz crashed (%s); starting it again on the same configuration '
                      '(restart %d of at most %d)' % (exit_status_text(status), self.restarts,
                                                      CRASH_RESTARTS), flush=True)
                self.rviz = subprocess.Popen(self.command())
        finally:
            self.stop_handles()
            shutil.rmtree(self.folder, ignore_errors=True)


def main(argv):
    view = WorldView([arg for arg in argv if ':=' in arg])
    signal.signal(signal.SIGINT, lambda signum, frame: view.stop(signum))
    signal.signal(signal.SIGTERM, lambda signum, frame: view.stop(signum))
    return view.run()


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
