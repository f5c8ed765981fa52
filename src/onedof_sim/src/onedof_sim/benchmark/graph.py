"""What every measured item of the benchmark shares: the private ROS graph and the nodes started on
it (Bench), the bare physics loops (BareLoop), the /clock probe (ClockProbe), and the rows, notes
and raw results a run records."""
import os
import shutil
import subprocess
import sys
import tempfile
import time
import xmlrpc.client

import rospkg

from onedof_harness.private_ros import PrivateRos, wait_until
from onedof_harness.rospy_shutdown import shut_down_rospy
from onedof_sim.benchmark import profiling
from onedof_sim.benchmark import report as bm
from onedof_sim.engines import node_command
from onedof_sim.simulator_extras import step_service
from onedof_sim.tools import rosrun_by_path, workspace_venv_bin
from onedof_sim.tutorial import player

STEP = 0.001  # the nodes' default step, s
TABLE_X = 0.85
PROFILE_S = 3  # seconds of samples in each profile
CLOCK_FREQUENCY = '/gazebo/pub_clock_frequency'


class NotMeasured(Exception):
    """An item could not be measured (a node missing or failing); its rows say why."""


def say(text):
    print('[bench] ' + text, flush=True)


def read_file(path):
    with open(path) as f:
        return f.read()


def cpu_seconds(pid, thread=None):
    """CPU time so far of a thread of a process, or of all of them, s (schedstat: nanoseconds on
    a CPU)."""
    total = 0
    for task in [str(thread)] if thread else os.listdir('/proc/%d/task' % pid):
        try:
            total += int(read_file('/proc/%d/task/%s/schedstat' % (pid, task)).split()[0])
        except (OSError, ValueError, IndexError):
            continue  # a thread that has just ended
    return total * 1e-9


def descendants(pid):
    """pid and every process below it (a launch's nodes, rosrun's exec'd node)."""
    children = {}
    for entry in os.listdir('/proc'):
        if entry.isdigit():
            try:
                stat = read_file('/proc/%s/stat' % entry)
            except OSError:
                continue
            ppid = int(stat[stat.rindex(')') + 2:].split()[1])
            children.setdefault(ppid, []).append(int(entry))
    found, todo = set(), [pid]
    while todo:
        current = todo.pop()
        found.add(current)
        todo.extend(children.get(current, ()))
    return found


def by_path(command):
    """A command as the benchmark starts it: `rosrun PACKAGE EXECUTABLE ARGS...` as the
    executable's path and ARGS, the same process without rosrun's lookup, which would cost each
    of the benchmark's many starts about 0.2 CPU-s (tools.package_executable); any other command
    as it is. The rows show the rosrun form, for a reader to repeat."""
    try:
        return rosrun_by_path(command)
    except RuntimeError as error:
        raise NotMeasured(str(error)) from None


def node_label(engine):
    return 'node with _physics:=%s' % engine


def engine_loop_command(engine, quick_step=False):
    return (['rosrun', 'onedof_sim', 'bench_engine_loop', '--physics', engine]
            + (['--quick-step'] if quick_step else []))


def pybullet_loop_command():
    for python in (sys.executable, os.path.join(workspace_venv_bin(), 'python')):
        if os.access(python, os.X_OK) and subprocess.run(
                [python, '-c', 'import pybullet'], capture_output=True).returncode == 0:
            return [python, '-m', 'onedof_sim.benchmark.pybullet_loop']
    raise NotMeasured('no python here imports pybullet (make venv installs it in %s)'
                      % os.path.dirname(workspace_venv_bin()))


class BareLoop:
    """A physics loop stepping without ROS in its own process (bench_engine_loop, or
    onedof_sim.benchmark.pybullet_loop), kept alive between windows so that it moves on from
    where it stopped, as the node does. Its stdout carries only the protocol; what the engine
    says on its own (pybullet's loaders print warnings without line ends) goes to a file."""

    def __init__(self, command, models):
        args = by_path(command)
        for name, path, fmt, x in models:
            args += ['--' + fmt, name, path, str(x)]
        self.chatter = tempfile.TemporaryFile(mode='w+')
        # A session of its own, as each node PrivateRos starts: where the kernel groups processes
        # by session for scheduling (sched_autogroup), a loop sharing the benchmark's session
        # would share its CPU with everything else started there while the node it is compared
        # with has a group to itself.
        self.proc = subprocess.Popen(args, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self.chatter, text=True, start_new_session=True)
        said = []
        for line in self.proc.stdout:
            if line.strip() == 'ready':
                return
            said.append(line)
        message = self.said(said)  # before close, which closes the chatter's file
        self.close()
        raise NotMeasured('%s did not start: %s' % (' '.join(command), message))

    def said(self, stdout_lines):
        self.chatter.seek(0)
        return (''.join(stdout_lines) + self.chatter.read())[-300:]

    def run(self, seconds, min_steps=1):
        """(steps, wall seconds) of one window."""
        self.proc.stdin.write('%g %d\n' % (seconds, min_steps))
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line.startswith('window '):
            raise NotMeasured('the bare loop exited (%s): %s'
                              % (self.proc.wait(), self.said([line])))
        _, steps, wall, _ = line.split()
        return int(steps), float(wall)

    def close(self):
        self.proc.stdin.close()
        self.proc.wait(timeout=60)
        self.chatter.close()


class ClockProbe:
    """Subscribes /clock while it lives: (CLOCK_MONOTONIC, sim time) of every arrival."""

    def __init__(self, rospy):
        from rosgraph_msgs.msg import Clock
        self.samples = []
        self.latest = -1.0
        self._subscriber = rospy.Subscriber('/clock', Clock, self._on_clock, queue_size=1000,
                                            tcp_nodelay=True)

    def _on_clock(self, msg):
        self.latest = msg.clock.to_sec()
        self.samples.append((time.monotonic(), self.latest))

    def close(self):
        self._subscriber.unregister()


class Bench:
    """One benchmark run: its private ROS graph (this process is the node /benchmark on it), the
    simulators and helpers it starts there, and what it records (rows of the table, notes, raw
    results)."""

    def __init__(self, ros, sizes, output, engines, profiles=True, book_client_overlay=None):
        self.ros = ros
        # Where the book-shaped C++ client is built once for every run that names the folder
        # (None: a build of this run's own).
        self.book_client_overlay = book_client_overlay
        self.profiles = profiles  # profile where an aim is missed
        self.sizes = sizes
        self.output = output
        self.engines = engines
        self.work = tempfile.mkdtemp(prefix='onedof_bench_')
        self.rows = []
        self.notes = []
        self.results = {}
        ros.adopt_environment()
        import rospy
        self.rospy = rospy
        # Before any simulator sets /use_sim_time: this process keeps wall time and reads sim
        # time only where it subscribes /clock itself, so the nodes have no /clock subscriber
        # when they run as fast as possible.
        rospy.init_node('benchmark', disable_signals=True)
        from gazebo_msgs import srv
        self.srv = srv
        packages = rospkg.RosPack()
        self.robot_urdf = os.path.join(packages.get_path('minimal_robot_description'),
                                       'minimal_robot_description.urdf')
        self.table_sdf = os.path.join(packages.get_path('onedof_sim'), 'models', 'cafe_table',
                                      'model.sdf')
        self.tutorial_models = [('one_DOF_robot', self.robot_urdf, 'urdf', 0.0),
                                ('cafe_table', self.table_sdf, 'sdf', TABLE_X)]
        # The ground the node's default world places (worlds/empty.world), for a loop on the
        # core to step the node's world; pybullet's loop loads a plane of its own.
        self.ground_model = ('ground_plane', os.path.join(
            packages.get_path('onedof_sim'), 'models', 'ground_plane', 'model.sdf'), 'sdf', 0.0)

    def close(self):
        shut_down_rospy(self.rospy, 'benchmark finished')
        shutil.rmtree(self.work, ignore_errors=True)

    # --- what a run records -------------------------------------------------------------------

    def add(self, item, measured, figure, against, against_figure, ratio=None, aim=None,
            met=None):
        row = bm.Row(item, measured, figure, against, against_figure, ratio, aim, met)
        self.rows.append(row)
        say('%s %s: %s (against %s: %s)' % (item, measured, figure, against, against_figure))

    def not_measured(self, item, measured, reason):
        self.add(item, measured, 'not measured', reason, '—')

    def profile(self, pid, seconds, label, python=False):
        """Samples a running process for `seconds` (perf for the C++ node, py-spy for the Python
        controller), keeps the report in the output folder and adds a note saying where the time
        goes."""
        if not self.profiles:
            self.notes.append('%s: not profiled (--no-profiles)' % label)
            return
        path = os.path.join(self.output, 'profile_%s.txt' % label)
        summary = profiling.take_profile(pid, seconds, path, python)
        self.notes.append('%s: %s (report: %s)' % (label, summary, os.path.basename(path)))
        say('profile %s: %s' % (label, summary))

    # --- the graph ----------------------------------------------------------------------------

    def node_pid(self, name):
        """The pid a node reports itself (not rosrun's or roslaunch's), or None."""
        code, _, uri = self.ros.master().lookupNode('/benchmark', name)
        if code != 1:
            return None
        try:
            code, _, pid = xmlrpc.client.ServerProxy(uri).getPid('/benchmark')
        except OSError:
            return None  # a node that has gone
        return pid if code == 1 else None

    def wait_for_node(self, proc, name, timeout=60):
        """Waits until `name` is a node of proc's process tree; returns its pid."""
        def started():
            if proc.poll() is not None:
                raise NotMeasured('%s exited with %s: %s' % (proc.log_name, proc.returncode,
                                                             self.ros.log_text(proc)[-600:]))
            pid = self.node_pid(name)
            return pid if pid in descendants(proc.pid) else None
        return wait_until(started, timeout, what='node %s' % name)

    def start_sim(self, engine, max_update_rate=1000, paused=False, lockstep=False,
                  step_simulation=False):
        """The simulator node of `engine`; it serves /gazebo/step_simulation with step_simulation
        or lockstep (which implies it)."""
        def flag(value):
            return str(bool(value)).lower()
        # Always given: a private parameter set with _name:=value (or by a launch file) outlives
        # its node on the parameter server, and the next simulator would inherit it.
        proc = self.ros.start(by_path(node_command(engine)) + [
            '_max_update_rate:=%g' % max_update_rate, '_paused:=%s' % flag(paused),
            '_lockstep:=%s' % flag(lockstep),
            '_lockstep_timeout:=%g' % player.LOCKSTEP_TIMEOUT,
            '_enable_step_simulation:=%s' % flag(step_simulation or lockstep)],
            name='sim_' + engine)
        pid = self.wait_for_node(proc, '/gazebo')
        self.ros.wait_for_service('/gazebo/unpause_physics')
        return proc, pid

    def stop(self, proc):
        PrivateRos.terminate(proc)

    def subscribers(self, topic):
        """The nodes subscribed to `topic` now, as the master knows them."""
        return self._nodes_of(topic, 1)

    def publishers(self, topic):
        """The nodes publishing `topic` now, as the master knows them."""
        return self._nodes_of(topic, 0)

    def _nodes_of(self, topic, kind):
        """The nodes of `topic` in the master's system state's list `kind` (0 publications, 1
        subscriptions)."""
        _, _, state = self.ros.master().getSystemState('/benchmark')
        return sorted(next((nodes for name, nodes in state[kind] if name == topic), []))

    def hears_clock(self, node):
        """Whether the simulator's /clock has a connection to `node` (from its bus information)."""
        return self.ros.connected('/gazebo', '/clock', node)

    def proxy(self, name, srv_class, persistent=False):
        return self.rospy.ServiceProxy(name, srv_class, persistent=persistent)

    def step_service(self, persistent=False):
        """The simulator's /gazebo/step_simulation; NotMeasured, naming the parameter that serves
        it, when the simulator does not."""
        try:
            return step_service(self.rospy, persistent=persistent)
        except RuntimeError as error:
            raise NotMeasured(str(error)) from None

    def sim_clock(self):
        """A reader of the simulator's sim time over a persistent get_world_properties: each call
        returns (the wall time halfway through the call, the sim time it answered)."""
        clock = self.proxy('/gazebo/get_world_properties', self.srv.GetWorldProperties,
                           persistent=True)

        def sim_time():
            before = time.monotonic()
            sim = clock().sim_time
            return (before + time.monotonic()) / 2, sim
        return sim_time

    def call(self, name, srv_class, *args):
        result = self.proxy(name, srv_class)(*args)
        if hasattr(result, 'success') and not result.success:
            raise NotMeasured('%s: %s' % (name, result.status_message))
        return result

    def spawn(self, models):
        from geometry_msgs.msg import Pose
        for name, path, fmt, x in models:
            pose = Pose()
            pose.position.x = x
            pose.orientation.w = 1.0
            self.call('/gazebo/spawn_%s_model' % fmt, self.srv.SpawnModel, name, read_file(path),
                      '', pose, '')

    def pause(self, paused):
        from std_srvs.srv import Empty
        self.call('/gazebo/pause_physics' if paused else '/gazebo/unpause_physics', Empty)

    def running_window(self, sim_time, settle_s, window_s, pid=None):
        """(steps, wall seconds) of the paused node run for one window: unpaused, settle_s of
        wall time let pass, then window_s measured through sim_time (a sim_clock()), paused
        again; given the node's pid, (steps, wall seconds, the CPU seconds of its threads)."""
        self.pause(False)
        time.sleep(settle_s)
        cpu0 = cpu_seconds(pid) if pid else 0.0
        wall0, sim0 = sim_time()
        time.sleep(window_s)  # the measurement window itself
        wall1, sim1 = sim_time()
        cpu1 = cpu_seconds(pid) if pid else 0.0
        self.pause(True)
        steps = round((sim1 - sim0) / STEP)
        return (steps, wall1 - wall0, cpu1 - cpu0) if pid else (steps, wall1 - wall0)

    def answers(self, service, srv_class, *args):
        if not self.ros.has_service(service):
            return False
        try:
            return self.proxy(service, srv_class)(*args).success
        except (self.rospy.ServiceException, OSError):
            return False

    def clock_probe(self):
        return ClockProbe(self.rospy)
