"""rosrun onedof_sim benchmark: measures the simulator node on every engine side by side with its
references on one private ROS graph, and writes the table (README-table.md), the plots and
results.json.

Items (issue 6), short ones first so that a failure shows early:
  6 start-up, 1 throughput + 7 memory, 2 scaling, 3 service latency, 4 control loop, 5 pacing;
and of issue 11 (lock-step): 8 the real-time factor of the lock-stepped tutorial with each
controller, 9 the tutorial's settled angle on a busy machine, lock-step against free-running.
What is compared runs alternately in short windows (never at the same time: two cores), and the
ratio of the two is the claim. Nothing here fails on speed; a node that cannot be measured (not
built, crashed) gets its rows marked as not measured and the run goes on, and a missing profiler
is said so in the notes.
"""
import argparse
import dataclasses
import datetime
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import traceback
import xmlrpc.client

import rospkg

from onedof_harness import book_client
from onedof_harness.busy import busy_processes
from onedof_harness.private_ros import PrivateRos, wait_until
from onedof_sim.benchmark import report as bm
from onedof_sim.engines import engine_names, node_command
from onedof_sim.tools import workspace_root
from onedof_sim.tutorial import player

# The engine whose physics library pybullet wraps: its node is also set against bare pybullet.
PYBULLET_COUNTERPART = 'bullet'
# The engine with a second solver, which ~quick_step picks (ODE's dWorldQuickStep): the scaling
# item measures both.
QUICK_STEP_ENGINE = 'ode'
STEP = 0.001  # the nodes' default step, s
TABLE_X = 0.85
BARE_SERVICE = 'bare'  # node name of the bare service: /bare/get_joint_properties, ...
SERVICES = ('get_joint_properties', 'apply_joint_effort')
WARM_UP_CALLS = 20
PROFILE_S = 3  # seconds of samples in each profile
CLOCK_FREQUENCY = '/gazebo/pub_clock_frequency'
MEMORY_CLOCK_FREQUENCY = 100.0
THROTTLED_CLOCK_HZ = 100.0
SETTLE_S = 0.25  # wall seconds after an unpause before a window opens
LOCKSTEP_COMMAND = 1.0  # the tutorial's first command step, rad
LOCKSTEP_TIMEOUT_TEXT = 'lock-step: the world waited'  # the simulator's line when it gives up
BUSY_PROCESSES = 8  # as the tutorial's test under load


@dataclasses.dataclass
class Sizes:
    startup_repeats: int = 3
    throughput_windows: int = 5
    throughput_window_s: float = 1.0
    memory_steps: int = 1000000
    chain_links: tuple = (1, 10, 50, 200)
    chain_windows: int = 2
    chain_window_s: float = 1.0
    chain_min_steps: int = 3
    latency_batches: int = 3
    persistent_calls: int = 300
    fresh_calls: int = 50
    control_s: float = 60.0
    sweep_rates: tuple = (200, 500, 1000)
    sweep_s: float = 10.0
    # The default engine's pacing is measured during its control_s control run; the other
    # engines' (no control run) over pacing_s.
    pacing_s: float = 10.0
    # Sim seconds the lock-stepped tutorial is stepped through with each controller (item 8),
    # and the tutorial phase played for the comparison on a busy machine (item 9).
    lockstep_s: float = 10.0
    comparison_phase_s: float = 5.0


# The rows of the table, one per kind of measurement.
ROWS = (1, 2, 3, 4, 5, 6, 7, 8, 9)
FULL = Sizes()
QUICK = Sizes(startup_repeats=1, throughput_windows=2, throughput_window_s=0.3, memory_steps=20000,
              chain_links=(1, 10), chain_windows=1, chain_window_s=0.2, chain_min_steps=2,
              latency_batches=1, persistent_calls=20, fresh_calls=5, control_s=2.0,
              sweep_rates=(200,), sweep_s=1.0, pacing_s=2.0, lockstep_s=0.5,
              comparison_phase_s=1.0)


def say(text):
    print('[bench] ' + text, flush=True)


def read_file(path):
    with open(path) as f:
        return f.read()


def memory_kb(pid):
    """{'VmRSS', 'RssAnon', 'RssFile'} of a process from /proc/PID/status, in kB: anonymous
    memory is what a leak grows; file-backed pages are code and data of the libraries, paged in
    on first use."""
    fields = {}
    for line in read_file('/proc/%d/status' % pid).splitlines():
        key, _, value = line.partition(':')
        if key in ('VmRSS', 'RssAnon', 'RssFile'):
            fields[key] = int(value.split()[0])
    return fields


def format_memory(fields):
    return '%.1f MiB (anonymous %.1f, file-backed %.1f)' % (
        fields['VmRSS'] / 1024, fields['RssAnon'] / 1024, fields['RssFile'] / 1024)


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


def node_label(engine):
    return 'node with _physics:=%s' % engine


def microseconds(values):
    return '%.0f / %.0f us' % (bm.percentile(values, 50), bm.percentile(values, 99))


class NotMeasured(Exception):
    """An item could not be measured (a node missing or failing); its rows say why."""


def engine_loop_command(engine, quick_step=False):
    return (['rosrun', 'onedof_sim', 'bench_engine_loop', '--physics', engine]
            + (['--quick-step'] if quick_step else []))


def workspace_venv_bin():
    """bin/ of the workspace venv (make venv), where pybullet's python and py-spy live: rosrun
    runs this under the system python, which has neither."""
    return os.path.join(workspace_root(), '.venv', 'bin')


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
        args = list(command)
        for name, path, fmt, x in models:
            args += ['--' + fmt, name, path, str(x)]
        self.chatter = tempfile.TemporaryFile(mode='w+')
        self.proc = subprocess.Popen(args, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self.chatter, text=True)
        said = []
        for line in self.proc.stdout:
            if line.strip() == 'ready':
                return
            said.append(line)
        self.close()
        raise NotMeasured('%s did not start: %s' % (' '.join(command), self.said(said)))

    def said(self, stdout_lines):
        self.chatter.seek(0)
        return (''.join(stdout_lines) + self.chatter.read())[-300:]

    def run(self, seconds, min_steps=1):
        """(steps, wall seconds) of one window."""
        self.proc.stdin.write('%g %d\n' % (seconds, min_steps))
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line.startswith('window '):
            raise NotMeasured('the bare loop exited (%s): %s' % (self.proc.wait(), self.said([line])))
        _, steps, wall, _ = line.split()
        return int(steps), float(wall)

    def close(self):
        self.proc.stdin.close()
        self.proc.wait(timeout=60)
        self.chatter.close()


class Bench:
    def __init__(self, ros, sizes, output, engines, profiles=True):
        self.ros = ros
        self.profiles = profiles  # profile where an aim is missed
        self.sizes = sizes
        self.output = output
        self.engines = engines
        self.work = tempfile.mkdtemp(prefix='onedof_bench_')
        self.rows = []
        self.failed_calls = 0  # roscpp calls that got no answer, in the latency item
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

    def close(self):
        self.rospy.signal_shutdown('benchmark finished')
        shutil.rmtree(self.work, ignore_errors=True)

    def add(self, item, measured, figure, against, against_figure, ratio=None, aim=None,
            met=None):
        row = bm.Row(item, measured, figure, against, against_figure, ratio, aim, met)
        self.rows.append(row)
        say('%s %s: %s (against %s: %s)' % (item, measured, figure, against, against_figure))

    def not_measured(self, item, measured, reason):
        self.add(item, measured, 'not measured', reason, '—')

    # --- the graph ------------------------------------------------------------------------------

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

    def start_sim(self, engine, max_update_rate=1000, paused=False, lockstep=False):
        # Always given: a private parameter set with _name:=value (or by a launch file) outlives
        # its node on the parameter server, and the next simulator would inherit it.
        proc = self.ros.start(node_command(engine) + [
            '_max_update_rate:=%g' % max_update_rate, '_paused:=%s' % str(paused).lower(),
            '_lockstep:=%s' % str(lockstep).lower(),
            '_lockstep_timeout:=%g' % player.LOCKSTEP_TIMEOUT],
            name='sim_' + engine)
        pid = self.wait_for_node(proc, '/gazebo')
        self.ros.wait_for_service('/gazebo/unpause_physics')
        return proc, pid

    def stop(self, proc):
        PrivateRos.terminate(proc)

    def subscribers(self, topic):
        """The nodes subscribed to `topic` now, as the master knows them."""
        _, _, (_, subscriptions, _) = self.ros.master().getSystemState('/benchmark')
        return sorted(next((nodes for name, nodes in subscriptions if name == topic), []))

    def proxy(self, name, srv_class, persistent=False):
        return self.rospy.ServiceProxy(name, srv_class, persistent=persistent)

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

    def answers(self, service, srv_class, *args):
        if not self.ros.has_service(service):
            return False
        try:
            return self.proxy(service, srv_class)(*args).success
        except (self.rospy.ServiceException, OSError):
            return False

    def clock_probe(self):
        return ClockProbe(self.rospy)

    # --- profiles, taken where an aim is missed -------------------------------------------------

    def profile(self, pid, seconds, label, python=False):
        """Samples a running process for `seconds` (perf for the C++ node, py-spy for the Python
        controller), keeps the report in the output folder and adds a note saying where the time
        goes."""
        if not self.profiles:
            self.notes.append('%s: not profiled (--no-profiles)' % label)
            return
        path = os.path.join(self.output, 'profile_%s.txt' % label)
        summary = take_profile(pid, seconds, path, python)
        self.notes.append('%s: %s (report: %s)' % (label, summary, os.path.basename(path)))
        say('profile %s: %s' % (label, summary))

    # --- 6: start-up ----------------------------------------------------------------------------

    def startup(self):
        floor_launch = os.path.join(self.work, 'bare_service.launch')
        with open(floor_launch, 'w') as f:
            f.write('<launch><node name="bare_startup" pkg="onedof_sim" '
                    'type="bench_bare_service"/></launch>\n')
        floor, results = [], {engine: {'clock': [], 'robot': []} for engine in self.engines}
        failed = {}
        for repeat in range(self.sizes.startup_repeats):
            floor.append(self.launch_until(
                [floor_launch], '/bare_startup/get_joint_properties')[1])
            for engine in self.engines:
                if engine in failed:
                    continue
                try:
                    clock, robot = self.launch_until(
                        ['minimal_robot_description', 'minimal_robot_description.launch',
                         'physics:=' + engine], '/gazebo/get_joint_properties', clock=True)
                except (NotMeasured, TimeoutError) as error:
                    failed[engine] = str(error)
                    continue
                results[engine]['clock'].append(clock)
                results[engine]['robot'].append(robot)
        floor_median = bm.percentile(floor, 50)
        against = 'roslaunch of a bare roscpp service node until it answers'
        for engine in self.engines:
            launch = 'start-up: roslaunch minimal_robot_description.launch physics:=%s ' % engine
            if engine in failed:
                self.not_measured('6', launch, failed[engine][:200])
                continue
            for key, what in (('clock', launch + 'to the first /clock, median of %d'),
                              ('robot', launch + 'to get_joint_properties(joint1) answering, '
                                                 'median of %d')):
                value = bm.percentile(results[engine][key], 50)
                self.add('6', what % len(results[engine][key]), '%.2f s' % value, against,
                         '%.2f s' % floor_median, bm.ratio(value, floor_median))
        self.results['startup'] = dict(floor=floor, **results)

    def launch_until(self, launch_args, service, clock=False):
        """Wall seconds from starting roslaunch to the first /clock (when clock) and to
        `service` answering for joint1."""
        probe = self.clock_probe() if clock else None
        start = time.monotonic()
        proc = self.ros.start(['roslaunch'] + launch_args, name='launch')
        try:
            def answered():
                if proc.poll() is not None:
                    raise NotMeasured('roslaunch %s exited: %s' % (
                        ' '.join(launch_args), self.ros.log_text(proc)[-400:]))
                return self.answers(service, self.srv.GetJointProperties, 'joint1')
            wait_until(answered, 60, interval=0.01, what=service)
            answered_at = time.monotonic()
            first_clock = None
            if probe:
                wait_until(lambda: probe.samples, 10, interval=0.01, what='a /clock')
                first_clock = probe.samples[0][0] - start
            return first_clock, answered_at - start
        finally:
            if probe:
                probe.close()
            self.stop(proc)

    # --- 1 and 7: throughput and memory ---------------------------------------------------------

    def throughput_and_memory(self, engine):
        sizes = self.sizes
        proc = None
        loops = {}
        try:
            proc, pid = self.start_sim(engine, max_update_rate=0, paused=True)
            self.spawn(self.tutorial_models)
            clock = self.proxy('/gazebo/get_world_properties', self.srv.GetWorldProperties,
                               persistent=True)

            def sim_time():
                before = time.monotonic()
                sim = clock().sim_time
                return (before + time.monotonic()) / 2, sim

            def node_window(clock_frequency):
                """(steps, wall seconds) of the node running for one window."""
                self.ros.set_param(CLOCK_FREQUENCY, clock_frequency)
                self.pause(False)
                time.sleep(SETTLE_S)  # the node re-reads pub_clock_frequency 10 times a second
                wall0, sim0 = sim_time()
                time.sleep(sizes.throughput_window_s)  # the measurement window itself
                wall1, sim1 = sim_time()
                self.pause(True)
                return round((sim1 - sim0) / STEP), wall1 - wall0

            self.pause(False)
            wait_until(lambda: sim_time()[1] > 0.1, 30, what='the first 100 steps')
            self.pause(True)
            self.memory(engine, pid, sim_time)
            clock_subscribers = self.subscribers('/clock')
            loops['bare'] = BareLoop(engine_loop_command(engine), self.tutorial_models)
            against_pybullet = ('steps/s of the %s, /clock every step, against bare pybullet'
                                % node_label(engine))
            if engine == PYBULLET_COUNTERPART:
                try:
                    loops['pybullet'] = BareLoop(pybullet_loop_command(), self.tutorial_models)
                except NotMeasured as error:
                    self.not_measured('1', against_pybullet, str(error)[:200])
            for loop in loops.values():
                loop.run(sizes.throughput_window_s / 4)  # warm-up, not counted
            windows = {'node': [], 'throttled': []}
            windows.update((key, []) for key in loops)
            for _ in range(sizes.throughput_windows):
                for key, loop in loops.items():
                    windows[key].append(loop.run(sizes.throughput_window_s))
                windows['node'].append(node_window(0.0))
                windows['throttled'].append(node_window(THROTTLED_CLOCK_HZ))
            self.ros.set_param(CLOCK_FREQUENCY, 0.0)
            rates = {key: bm.rate(*zip(*key_windows)) for key, key_windows in windows.items()}
            met = rates['node'] / rates['bare'] >= 0.5
            self.add('1', 'steps/s of the %s, tutorial robot + cafe table, as fast as possible, '
                     '/clock every step; /clock subscribers: %s' % (
                         node_label(engine), ', '.join(clock_subscribers) or 'none'),
                     '%.0f' % rates['node'], 'bare loop on the same models, %s (World::step: '
                     'effort jobs, collisions, contacts, the engine\'s step; no mutex, /clock or '
                     'pacing)' % ' '.join(engine_loop_command(engine)[2:]),
                     '%.0f' % rates['bare'], rates['node'] / rates['bare'], '>= 0.5', met)
            self.add('1', 'the same %s with /gazebo/pub_clock_frequency %g (what /clock every '
                     'step costs)' % (node_label(engine), THROTTLED_CLOCK_HZ),
                     '%.0f' % rates['throttled'], 'the same bare loop', '%.0f' % rates['bare'],
                     rates['throttled'] / rates['bare'])
            if 'pybullet' in rates:
                of_pybullet = rates['node'] / rates['pybullet']
                met = met and of_pybullet >= 0.3
                self.add('1', against_pybullet, '%.0f' % rates['node'],
                         'bare pybullet loop on the same models (pybullet\'s own loadURDF and '
                         'loadSDF; stepSimulation alone)', '%.0f' % rates['pybullet'],
                         of_pybullet, '>= 0.3', of_pybullet >= 0.3)
            if not met:
                self.pause(False)
                self.profile(pid, PROFILE_S, '1_%s_node_as_fast_as_possible' % engine)
                self.pause(True)
            self.results.setdefault('throughput', {})[engine] = dict(
                clock_subscribers=clock_subscribers, **windows)

        except (NotMeasured, TimeoutError, OSError) as error:
            self.not_measured('1, 7', 'throughput and memory, %s' % node_label(engine),
                              str(error)[:200])
        finally:
            for loop in loops.values():
                loop.close()
            if proc:
                self.stop(proc)

    # --- 2: scaling ----------------------------------------------------------------------------

    def memory(self, engine, pid, sim_time):
        """Memory of the node after start, then after memory_steps more steps as fast as
        possible, sampled along the way: growth in the second half would be a leak, growth in
        the first half alone is warm-up."""
        sizes = self.sizes
        start, sim_start = memory_kb(pid), sim_time()[1]
        target = sim_start + sizes.memory_steps * STEP
        samples = []

        def done():
            sim = sim_time()[1]
            samples.append((sim - sim_start, memory_kb(pid)['RssAnon']))
            return sim >= target

        # /clock at 100 Hz: publishing it every step costs a node more than its physics (item 1),
        # and the steps, not the clock, are what is measured here.
        self.ros.set_param(CLOCK_FREQUENCY, MEMORY_CLOCK_FREQUENCY)
        self.pause(False)
        started = time.monotonic()
        wait_until(done, sizes.memory_steps / 1000.0 + 60, interval=0.2,
                   what='%d steps' % sizes.memory_steps)
        self.pause(True)
        self.ros.set_param(CLOCK_FREQUENCY, 0.0)
        wall = time.monotonic() - started
        end = memory_kb(pid)
        half = sizes.memory_steps * STEP / 2
        at_half = next(anon for steps, anon in samples if steps >= half)
        growth = end['RssAnon'] / start['RssAnon'] - 1
        self.add('7', 'memory (/proc/PID/status) of the %s after %d more steps (%.0f s as '
                 'fast as possible, /clock at %d Hz); anonymous growth in the second half: '
                 '%+.1f MiB' % (node_label(engine), sizes.memory_steps, wall,
                                MEMORY_CLOCK_FREQUENCY, (end['RssAnon'] - at_half) / 1024),
                 format_memory(end), 'the same node after start (models spawned, 100 steps)',
                 format_memory(start), end['RssAnon'] / start['RssAnon'],
                 'flat: anonymous growth < 2 %', growth < 0.02)
        self.results.setdefault('memory', {})[engine] = dict(start=start, end=end,
                                                             anon_by_steps=samples)

    def scaling_variants(self):
        """(key, label, bare loop command) of each bare loop of the scaling item."""
        variants = []
        for engine in self.engines:
            commands = [(engine, engine_loop_command(engine))]
            if engine == QUICK_STEP_ENGINE:
                commands.append((engine + '_quick', engine_loop_command(engine, quick_step=True)))
            variants += [(key, 'bare loop, ' + ' '.join(command[2:]), command)
                         for key, command in commands]
        return variants

    def scaling(self):
        sizes = self.sizes
        variants = self.scaling_variants()
        labels = {key: label for key, label, _ in variants}
        rates = {key: {} for key in labels}
        for links in sizes.chain_links:
            path = os.path.join(self.work, 'chain_%d.urdf' % links)
            with open(path, 'w') as f:
                f.write(bm.chain_urdf(links))
            loops = {}
            try:
                for key, label, command in variants:
                    try:
                        loops[key] = BareLoop(command, [('chain', path, 'urdf', 0.0)])
                    except NotMeasured as error:
                        self.notes.append('2: %s, chain of %d links: %s' % (label, links, error))
                windows = {key: [] for key in loops}
                for _ in range(sizes.chain_windows):  # the variants alternate
                    for key, loop in loops.items():
                        windows[key].append(loop.run(sizes.chain_window_s, sizes.chain_min_steps))
                for key, key_windows in windows.items():
                    rates[key][links] = bm.rate(*zip(*key_windows))
                    say('2 chain of %d links, %s: %.0f steps/s'
                        % (links, labels[key], rates[key][links]))
            finally:
                for loop in loops.values():
                    loop.close()
        exponents = {}
        for key, by_links in rates.items():
            links = sorted(by_links)
            if len(links) < 2:
                continue
            # The fit leaves out the 1-link chain where there are enough others: its cost is
            # mostly the fixed cost of a step.
            fitted = [n for n in links if n >= 10]
            fitted = fitted if len(fitted) >= 2 else links
            exponents[key] = bm.power_law_exponent(fitted, [1 / by_links[n] for n in fitted])
            self.add('2', '%s steps/s, chains of %s moving links; cost per step grows as '
                     'links^k' % (labels[key], ', '.join(map(str, links))),
                     '%s; k = %.2f (fit over %s links)' % (
                         ', '.join('%.0f' % by_links[n] for n in links), exponents[key],
                         ', '.join(map(str, fitted))),
                     'the same loop with 1 link', '%.0f' % by_links[links[0]],
                     by_links[links[-1]] / by_links[links[0]])
        self.results['scaling'] = dict(rates={key: {str(n): r for n, r in v.items()}
                                              for key, v in rates.items()},
                                       exponents=exponents)
        if any(rates.values()):
            write_scaling_plot(rates, labels, exponents,
                               os.path.join(self.output, 'scaling.png'))

    # --- 3: service latency ---------------------------------------------------------------------

    def latency(self, engine):
        name = node_label(engine)
        sizes = self.sizes
        sim = bare = None
        samples = {}
        try:
            sim, sim_pid = self.start_sim(engine)
            self.spawn(self.tutorial_models[:1])
            bare = self.ros.start(['rosrun', 'onedof_sim', 'bench_bare_service',
                                   '__name:=' + BARE_SERVICE], name='bare_service')
            self.wait_for_node(bare, '/' + BARE_SERVICE)
            for service in SERVICES:
                self.ros.wait_for_service('/%s/%s' % (BARE_SERVICE, service))
            self.failed_calls = 0
            for client in ('rospy', 'roscpp'):
                for mode in ('persistent', 'fresh'):
                    count = sizes.persistent_calls if mode == 'persistent' else sizes.fresh_calls
                    for service in SERVICES:
                        key = (client, mode, service)
                        samples[key] = {'sim': [], 'bare': []}
                        for _ in range(sizes.latency_batches):
                            for target, ns in (('sim', 'gazebo'), ('bare', BARE_SERVICE)):
                                samples[key][target] += self.round_trips(
                                    client, '/%s/%s' % (ns, service), mode, count)
            if self.failed_calls:
                self.notes.append('3: %d roscpp calls got no answer during the %s latency item '
                                  '(left out of the percentiles)' % (self.failed_calls, name))
            ratios = {key: bm.percentile(by_target['sim'], 50) /
                      bm.percentile(by_target['bare'], 50) for key, by_target in samples.items()}
            worst = max(ratios, key=ratios.get)
            if ratios[worst] > 1.3:
                self.profile_under_load(sim_pid, engine, worst)
        except (NotMeasured, TimeoutError, subprocess.CalledProcessError) as error:
            self.not_measured('3', 'service latency, %s' % name, str(error)[:200])
            return
        finally:
            for proc in (bare, sim):
                if proc:
                    self.stop(proc)
        for (client, mode, service), by_target in samples.items():
            self.add('3', '%s round trip p50 / p99, %s client, %s connection (%s, %d calls)'
                     % (service, client, mode, name, len(by_target['sim'])),
                     microseconds(by_target['sim']),
                     'bare roscpp service, same srv type and reply size, alternating batches',
                     microseconds(by_target['bare']), ratios[(client, mode, service)],
                     'p50 <= 1.3x', ratios[(client, mode, service)] <= 1.3)
        self.results.setdefault('latency', {})[engine] = {
            ' '.join(key): {target: dict(p50=bm.percentile(v, 50), p99=bm.percentile(v, 99))
                            for target, v in by_target.items()}
            for key, by_target in samples.items()}
        write_latency_plot(samples, name, os.path.join(self.output, 'latency_%s.png' % engine))

    def profile_under_load(self, sim_pid, engine, key):
        """Profiles the simulator while a roscpp client calls the service of `key` (the pair
        furthest from the floor) back to back."""
        _, mode, service = key
        load = subprocess.Popen(['rosrun', 'onedof_sim', 'bench_service_client',
                                 '/gazebo/' + service, service.split('_')[0], mode, '1000000'],
                                env=self.ros.env, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL, start_new_session=True)
        try:
            self.profile(sim_pid, PROFILE_S, '3_%s_node_serving_%s_%s' % (engine, service, mode))
        finally:
            PrivateRos.terminate(load)

    def round_trips(self, client, service, mode, count):
        """Round trips in microseconds, warm-up calls excluded."""
        if client == 'roscpp':
            result = subprocess.run(['rosrun', 'onedof_sim', 'bench_service_client', service,
                                     'get' if 'get_' in service else 'apply', mode, str(count)],
                                    env=self.ros.env, capture_output=True, text=True, timeout=120)
            if result.returncode != 0:
                raise NotMeasured('bench_service_client %s: %s' % (service, result.stderr[-300:]))
            lines = result.stdout.split()
            self.failed_calls += lines.count('failed')
            return [float(line) for line in lines if line != 'failed']
        if 'get_' in service:
            srv_class, args = self.srv.GetJointProperties, ('joint1',)
        else:
            srv_class = self.srv.ApplyJointEffort
            args = ('joint1', 0.0, self.rospy.Time(0), self.rospy.Duration(0.01))
        proxy = self.proxy(service, srv_class, persistent=mode == 'persistent')
        try:
            times = []
            for i in range(-WARM_UP_CALLS, count):
                start = time.perf_counter()
                result = proxy(*args)
                elapsed = time.perf_counter() - start
                if not result.success:
                    raise NotMeasured('%s: %s' % (service, result.status_message))
                if i >= 0:
                    times.append(elapsed * 1e6)
            return times
        finally:
            proxy.close()

    # --- 4 and 5: the control loop and pacing ---------------------------------------------------

    def control_and_pacing(self, engine, pacing_s, control=True):
        name = node_label(engine)
        sim = None
        try:
            sim, sim_pid = self.start_sim(engine)
            self.spawn(self.tutorial_models[:1])
            if control:
                # The 60 s control run is paced at real-time factor 1 too: its /clock arrivals
                # are the pacing measurement, with the tutorial's controller running.
                clock = self.control_loop(name)
                self.pacing_of(engine, sim_pid, clock, 'during the 100 Hz control run')
            else:
                self.pacing(engine, sim_pid, pacing_s)
        except (NotMeasured, TimeoutError) as error:
            self.not_measured('4, 5' if control else '5', 'control loop and pacing, %s' % name,
                              str(error)[:200])
        finally:
            if sim:
                self.stop(sim)

    def control_loop(self, name):
        sizes = self.sizes
        runs = {}
        # Shortest first: a failure shows early.
        for duration, rate in sorted([(sizes.control_s, 100)] +
                                     [(sizes.sweep_s, r) for r in sizes.sweep_rates]):
            runs[rate] = self.control_run(rate, duration)
            say('4 controller at %d Hz for %.0f s of sim time: %d missed periods'
                % (rate, duration, runs[rate]['missed']))
        at_100 = runs[100]
        self.add('4', 'missed periods of the tutorial controller at 100 Hz, %.0f s of sim time at '
                 'real-time factor 1 (%s; from joint_states stamps)' % (sizes.control_s, name),
                 '%d of %d' % (at_100['missed'], at_100['expected']),
                 'its own period (10 ms of sim time)', '—', None, '0 missed', at_100['missed'] == 0)
        self.add('4', 'p99 period jitter of jnt_pos arrivals at 100 Hz, sim time / wall time',
                 '%.2f / %.2f ms' % (at_100['jitter_sim'] * 1e3, at_100['jitter_wall'] * 1e3),
                 'the period, 10 ms (sim time: /clock ticks of 1 ms in this process)', '10 ms',
                 at_100['jitter_wall'] / 0.01)
        # The highest rate up to which no tried rate missed a period.
        highest = None
        for rate in sorted(runs):
            if runs[rate]['missed']:
                break
            highest = rate
        self.add('4', 'highest controller rate with 0 missed periods, of %s Hz (%.0f s of sim '
                 'time each above 100 Hz)' % (', '.join(map(str, sorted(runs))), sizes.sweep_s),
                 '%s Hz' % highest if highest else 'none',
                 'missed periods at each rate', ', '.join('%d Hz: %d of %d' % (
                     r, runs[r]['missed'], runs[r]['expected']) for r in sorted(runs)))
        clock = runs[100].pop('clock')
        for run in runs.values():
            run.pop('clock', None)
        self.results['control_loop'] = {str(r): v for r, v in runs.items()}
        missing = [rate for rate in sorted(runs) if runs[rate]['missed']]
        if missing and self.profiles:
            self.control_run(missing[0], PROFILE_S + 2, profile=True)
        write_period_plot(runs, os.path.join(self.output, 'control_loop.png'))
        return clock

    def control_run(self, rate, duration, profile=False):
        """Runs the tutorial controller at `rate` Hz for `duration` s of sim time; with profile,
        samples the controller during the window."""
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64
        rospy = self.rospy
        probe = self.clock_probe()
        arrivals, stamps = [], []
        subscribers = [
            rospy.Subscriber('/jnt_pos', Float64, lambda _: arrivals.append(
                (time.monotonic(), probe.latest)), queue_size=1000),
            rospy.Subscriber('/joint_states', JointState, lambda msg: stamps.append(
                msg.header.stamp.to_sec()), queue_size=1000)]
        controller = self.ros.start(['rosrun', 'minimal_joint_controller',
                                     'minimal_joint_controller', '_rate:=%g' % rate],
                                    name='controller_%d' % rate)
        try:
            wait_until(lambda: controller.poll() is not None or arrivals, 60,
                       what='the controller on jnt_pos')
            if controller.poll() is not None:
                raise NotMeasured('the controller exited: ' + self.ros.log_text(controller)[-300:])
            start = probe.latest + 1.0  # one second of sim time to settle in
            end = start + duration
            if profile:
                self.profile(self.node_pid('/minimal_joint_controller'), PROFILE_S,
                             '4_controller_at_%d_Hz' % rate, python=True)
            wait_until(lambda: probe.latest >= end, duration * 5 + 30, interval=0.1,
                       what='%.0f s of sim time' % duration)
        finally:
            self.stop(controller)
            for subscriber in subscribers:
                subscriber.unregister()
            probe.close()
        period = 1.0 / rate
        window_stamps = [t for t in stamps if start <= t < end]
        window = [(wall, sim) for wall, sim in arrivals if start <= sim < end]
        if len(window_stamps) < 2 or len(window) < 2:
            raise NotMeasured('the controller at %g Hz published %d joint_states in the window'
                              % (rate, len(window_stamps)))
        expected = round((window_stamps[-1] - window_stamps[0]) / period) + 1
        return dict(
            missed=bm.missed_periods(window_stamps, period), expected=expected,
            jitter_sim=bm.percentile(bm.period_jitter([s for _, s in window], period), 99),
            jitter_wall=bm.percentile(bm.period_jitter([w for w, _ in window], period), 99),
            wall_intervals=[b - a for (a, _), (b, _) in zip(window, window[1:])],
            clock=[(wall, sim) for wall, sim in probe.samples if start <= sim < end])

    def pacing(self, engine, sim_pid, duration):
        probe = self.clock_probe()
        try:
            wait_until(lambda: probe.samples, 30, what='/clock')
            end = probe.latest + duration
            wait_until(lambda: probe.latest >= end, duration * 5 + 30, interval=0.1,
                       what='%.0f s of sim time' % duration)
        finally:
            probe.close()
        self.pacing_of(engine, sim_pid, probe.samples, 'no controller')

    def pacing_of(self, engine, sim_pid, clock, condition):
        """The real-time factor from (CLOCK_MONOTONIC, sim time) /clock arrivals."""
        name = node_label(engine)
        wall, sim = zip(*clock)
        duration = sim[-1] - sim[0]
        windows = bm.windowed_rtf(wall, sim, 1.0)
        mean = bm.mean_rtf(wall, sim)
        worst = max(windows, key=lambda f: abs(f - 1.0)) if windows else mean
        against = 'the wall clock (CLOCK_MONOTONIC at /clock arrival)'
        self.add('5', 'real-time factor at 1.0, mean over %.0f s of sim time (%s, %s)'
                 % (duration, name, condition), '%.4f' % mean, against, '1.0', mean,
                 'within 1 %', abs(mean - 1) <= 0.01)
        self.add('5', 'real-time factor, worst one-second window of %d (%s)'
                 % (len(windows), name), '%.4f' % worst, against, '1.0', worst, 'within 1 %',
                 abs(worst - 1) <= 0.01)
        self.results.setdefault('pacing', {})[engine] = dict(mean=mean, windows=windows)
        if abs(mean - 1) > 0.01 or abs(worst - 1) > 0.01:
            self.profile(sim_pid, PROFILE_S, '5_%s_node_paced' % engine)
        write_pacing_plot(windows, name, os.path.join(self.output, 'pacing_%s.png' % engine))


    # --- 8: the lock-stepped tutorial's real-time factor ---------------------------------------

    def lockstep_speed(self, engine):
        """The lock-stepped tutorial as fast as each controller allows: the rospy controller and
        the book-shaped C++ client, each at 100 Hz and at 1 kHz."""
        from std_msgs.msg import Float64
        # One publisher for every run: a latched rospy publisher unregistered and made again on
        # the same topic delivers nothing to the next subscriber.
        pos_cmd = self.rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)
        try:
            setup, build_error = book_client.build_overlay(self.work), None
        except (RuntimeError, subprocess.TimeoutExpired) as error:
            setup, build_error = None, str(error)
        for rate in (100, 1000):
            controllers = [('rospy minimal_joint_controller', player.CONTROLLER_NODE,
                            ['rosrun', 'minimal_joint_controller', 'minimal_joint_controller',
                             '_rate:=%g' % rate]),
                           ('book-shaped C++ client (%s)' % book_client.EXECUTABLES[rate],
                            book_client.NODE, book_client.command(setup, rate) if setup else None)]
            for label, node, command in controllers:
                what = ('real-time factor of the lock-stepped tutorial (_lockstep:=true, '
                        '_max_update_rate:=0: as fast as the controller allows), command step '
                        '0 -> %g at the start, %g s of sim time through /gazebo/step_simulation; '
                        '%s at %d Hz (%s)' % (LOCKSTEP_COMMAND, self.sizes.lockstep_s, label, rate,
                                              node_label(engine)))
                if command is None:
                    self.not_measured('8', what, 'the overlay build failed: ' + build_error[-200:])
                    continue
                try:
                    run = self.lockstep_run(engine, command, node, 'lockstep_%s_%d' % (
                        'cpp' if node == book_client.NODE else 'rospy', rate), pos_cmd)
                except (NotMeasured, TimeoutError) as error:
                    self.not_measured('8', what, str(error)[:300])
                    continue
                self.add('8', what, '%.2f (lock-step timeouts in the simulator\'s log: %d)'
                         % (run['rtf'], run['timeouts']),
                         'real time: the free-running tutorial\'s real-time factor', '1.0',
                         run['rtf'])
                if run['timeouts']:
                    self.notes.append('8: %s at %d Hz: the simulator gave up waiting %d times; '
                                      'the first: %s' % (label, rate, run['timeouts'],
                                                         run['timeout_lines'][0]))
                self.results.setdefault('lockstep_speed', {})['%s at %d Hz' % (label, rate)] = run

    def lockstep_run(self, engine, controller_command, node, name, pos_cmd):
        """Starts the lock-stepped simulator paused with the tutorial's robot, steps it through
        one period so that the controller starts on a valid ROS time, starts the controller with
        the command latched on /pos_cmd, waits for it to join the lock-step and to hear /clock,
        and times /gazebo/step_simulation through lockstep_s of sim time. Returns the real-time
        factor and the lock-step timeouts the simulator logged."""
        from onedof_sim.srv import StepSimulation
        sim = controller = None
        # The simulators of one engine share a log: this one's lines are those after this offset.
        log_start = len(self.ros.log_text('sim_' + engine))

        def sim_log():
            return self.ros.log_text(sim)[log_start:]
        try:
            sim, _ = self.start_sim(engine, max_update_rate=0, paused=True, lockstep=True)
            self.spawn(self.tutorial_models[:1])
            step = self.proxy('/gazebo/step_simulation', StepSimulation)
            period_steps = round(player.CONTROL_PERIOD / STEP)
            self.stepped(step, period_steps)
            pos_cmd.publish(pos_cmd.data_class(LOCKSTEP_COMMAND))
            controller = self.ros.start(controller_command, name=name)

            def joined():
                if controller.poll() is not None:
                    raise NotMeasured('%s exited: %s' % (name, self.ros.log_text(controller)[-300:]))
                return ('lock-step: joint1 is commanded by ' + node in sim_log()
                        and self.hears_clock(node))
            # A roscpp client can command before it has heard any /clock (its time still 0); its
            # ros::Rate then sleeps a whole period from the first time it hears, and a world
            # stepped on before that would wait for a command that comes a period too late. Its
            # /clock connection up, the latched time it hears first is the one the world stands at.
            wait_until(joined, 60, what='%s to join the lock-step and hear /clock' % name)
            steps = round(self.sizes.lockstep_s / STEP)
            start = time.monotonic()
            sim_start = self.stepped(step, 0)  # where the controller stands
            sim_end = self.stepped(step, steps)
            wall = time.monotonic() - start
            if controller.poll() is not None:
                raise NotMeasured('%s exited: %s' % (name, self.ros.log_text(controller)[-300:]))
            if 'received value of pos_cmd is: %f' % LOCKSTEP_COMMAND not in \
                    self.ros.log_text(controller):
                raise NotMeasured('%s never took the command %g' % (name, LOCKSTEP_COMMAND))
        finally:
            for proc in (controller, sim):
                if proc:
                    self.stop(proc)
        timeouts = [line for line in sim_log().splitlines() if LOCKSTEP_TIMEOUT_TEXT in line]
        return dict(rtf=(sim_end - sim_start) / wall, sim_s=sim_end - sim_start, wall_s=wall,
                    timeouts=len(timeouts), timeout_lines=timeouts)

    def hears_clock(self, node):
        """Whether the simulator's /clock has a connection to `node` (from its bus information)."""
        code, _, uri = self.ros.master().lookupNode('/benchmark', '/gazebo')
        if code != 1:
            return False
        code, _, bus_info = xmlrpc.client.ServerProxy(uri).getBusInfo('/benchmark')
        return code == 1 and bm.connected_to(bus_info, node, '/clock')

    def stepped(self, step, steps):
        """Sim seconds after /gazebo/step_simulation of `steps` (0: once the controllers have
        acted at the current time)."""
        reply = step(steps)
        if not reply.success:
            raise NotMeasured('step_simulation: ' + reply.status_message)
        return reply.sim_time.to_sec()

    # --- 9: the tutorial on a busy machine, lock-step and free-running --------------------------

    def busy_machine(self, engine):
        """The tutorial's first phase (command 1.0) with BUSY_PROCESSES CPU-bound processes beside
        it, lock-stepped and free-running at real-time factor 1, each against the lock-stepped
        run on the quiet machine: lock-step keeps the figure, free-running loses periods."""
        duration = self.sizes.comparison_phase_s
        runs = {}
        try:
            quiet = self.first_phase(engine, 'quiet_lockstep')
            for key, args in (('lockstep', ()), ('free_run', ('--free-run',))):
                with busy_processes(BUSY_PROCESSES):
                    runs[key] = self.first_phase(engine, 'busy_' + key, *args)
        except (NotMeasured, subprocess.TimeoutExpired) as error:
            self.not_measured('9', 'the tutorial\'s settled angle with %d busy processes beside '
                              'it, lock-stepped and free-running (node with _physics:=%s)'
                              % (BUSY_PROCESSES, engine), str(error)[:300])
            return
        periods = round(duration / player.CONTROL_PERIOD)
        against = ('the same, lock-stepped on the quiet machine (%d of %d samples)'
                   % (quiet['samples'], periods))
        for key, title in (('lockstep', 'lock-stepped'),
                           ('free_run', 'free-running at real-time factor 1')):
            run = runs[key]
            self.add('9', 'the tutorial\'s settled angle for command %g (its first phase, %g s of '
                     'sim time), %s, %d busy processes beside it (node with _physics:=%s; '
                     'controller samples: %d of %d)' % (
                         LOCKSTEP_COMMAND, duration, title, BUSY_PROCESSES, engine,
                         run['samples'], periods),
                     '%.6f rad (%+.1e from quiet)' % (run['settled'],
                                                       run['settled'] - quiet['settled']),
                     against, '%.6f rad' % quiet['settled'])
        self.results['busy_machine'] = dict(quiet_lockstep=quiet, **runs)

    def first_phase(self, engine, name, *args):
        """Summary row of the tutorial's first phase played by play_tutorial (the main job)."""
        output = os.path.join(self.work, name)
        env = dict(os.environ)
        env.pop('DISPLAY', None)
        result = subprocess.run(['rosrun', 'onedof_sim', 'play_tutorial', '--output', output,
                                 '--physics', engine, '--phases', '1', '--no-screenshot',
                                 '--phase-duration', '%g' % self.sizes.comparison_phase_s,
                                 '--in-sim-phase-duration', '0']
                                + list(args), capture_output=True, text=True, timeout=600, env=env)
        if result.returncode != 0:
            raise NotMeasured('play_tutorial %s: %s' % (' '.join(args), (result.stdout
                                                                         + result.stderr)[-300:]))
        with open(os.path.join(output, 'summary.json')) as f:
            return json.load(f)['phases'][0]


def take_profile(pid, seconds, path, python=False):
    """Profiles pid (perf, or py-spy for a Python process) into path; returns a one-line summary
    of where the time goes or, when the profiler is missing or fails, says so plainly."""
    try:
        return (pyspy_profile if python else perf_profile)(pid, seconds, path)
    except NotMeasured as error:
        return 'no profile: %s' % error
    except (OSError, subprocess.SubprocessError) as error:
        return 'the profile failed: %s' % error


def perf_profile(pid, seconds, path):
    """On-CPU samples of a process and its threads with perf; the shares by shared object and
    the top symbols."""
    if not shutil.which('perf'):
        raise NotMeasured('perf is not installed (Debian package linux-perf)')
    data = path[:-len('.txt')] + '.perf.data'
    recorded = subprocess.run(['perf', 'record', '-F', '1999', '-g', '-p', str(pid), '-o', data,
                               '--', 'sleep', str(seconds)],
                              capture_output=True, text=True, timeout=seconds + 60)
    if recorded.returncode != 0:
        raise NotMeasured('perf record: ' + recorded.stderr[-300:])
    reports = []
    for sort in ('dso', 'dso,sym'):
        reports.append(subprocess.run(['perf', 'report', '-i', data, '--stdio', '--no-children',
                                       '-g', 'none', '--sort', sort, '--percent-limit', '0.5'],
                                      capture_output=True, text=True, timeout=120).stdout)
    os.remove(data)
    with open(path, 'w') as f:
        f.write('\n'.join(reports))
    objects = bm.perf_report_shares(reports[0])
    symbols = bm.perf_report_shares(reports[1])
    return 'perf, %g s of on-CPU samples: by object %s; top symbols %s' % (
        seconds, ', '.join('%s %.0f %%' % (os.path.basename(dso), pct)
                           for pct, dso, _ in objects[:5]),
        ', '.join('%s %.0f %%' % (sym[:60], pct) for pct, _, sym in symbols[:6]))


def pyspy_executable():
    """py-spy from the workspace venv (requirements.txt) or the PATH."""
    found = shutil.which('py-spy', path=os.pathsep.join(
        [workspace_venv_bin(), os.environ.get('PATH', '')]))
    if not found:
        raise NotMeasured('py-spy is not installed (make venv installs it)')
    return found


def pyspy_profile(pid, seconds, path):
    """Python stacks of a process sampled by py-spy (the thread holding the GIL); the functions
    with the largest self and inclusive shares."""
    raw = path[:-len('.txt')] + '.stacks'
    # --gil: only the thread running Python code; threads blocked in a socket read would
    # otherwise look busy.
    recorded = subprocess.run([pyspy_executable(), 'record', '--format', 'raw', '--nonblocking',
                               '--gil',
                               '-d', str(seconds), '-p', str(pid), '-o', raw],
                              capture_output=True, text=True, timeout=seconds + 60)
    if recorded.returncode != 0:
        raise NotMeasured('py-spy record: ' + (recorded.stderr or recorded.stdout)[-300:])
    text = read_file(raw)
    os.remove(raw)
    shares = bm.collapsed_stack_shares(text)
    by_self = sorted(shares.items(), key=lambda item: -item[1][0])
    by_inclusive = sorted(shares.items(), key=lambda item: -item[1][1])
    with open(path, 'w') as f:
        f.write('self %   inclusive %   function\n')
        for frame, (own, inclusive) in by_inclusive:
            f.write('%6.1f   %11.1f   %s\n' % (own * 100, inclusive * 100, frame))
    return 'py-spy, %g s of samples of the thread running Python: self %s; inclusive %s' % (
        seconds, ', '.join('%s %.0f %%' % (frame, own * 100) for frame, (own, _) in by_self[:6]),
        ', '.join('%s %.0f %%' % (frame, inclusive * 100)
                  for frame, (_, inclusive) in by_inclusive[:8]))


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


# --- plots ---------------------------------------------------------------------------------------

def _pyplot():
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot
    return pyplot


def _save(pyplot, figure, path):
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    pyplot.close(figure)


def write_scaling_plot(rates, labels, exponents, path):
    pyplot = _pyplot()
    figure, axes = pyplot.subplots(figsize=(7, 4.5))
    for key, by_links in rates.items():
        links = sorted(by_links)
        label = labels[key]
        if key in exponents:
            label += ' (cost per step ~ links^%.2f)' % exponents[key]
        axes.loglog(links, [by_links[n] for n in links], 'o-', label=label)
    axes.set_xlabel('moving links in the chain (revolute joints)')
    axes.set_ylabel('steps per second')
    axes.set_title('Scaling: URDF chains, as fast as possible, no ROS')
    axes.grid(True, which='both', alpha=0.3)
    axes.legend()
    _save(pyplot, figure, path)


def write_latency_plot(samples, name, path):
    pyplot = _pyplot()
    keys = list(samples)
    figure, axes = pyplot.subplots(figsize=(9, 4.5))
    for offset, target, color in ((-0.2, 'sim', 'tab:blue'), (0.2, 'bare', 'tab:gray')):
        p50 = [bm.percentile(samples[k][target], 50) for k in keys]
        p99 = [bm.percentile(samples[k][target], 99) for k in keys]
        positions = [i + offset for i in range(len(keys))]
        axes.bar(positions, p50, width=0.4, color=color,
                 label='%s p50 (line: p99)' % (name if target == 'sim'
                                               else 'bare roscpp service'))
        axes.vlines(positions, p50, p99, color='black')
    axes.set_xticks(range(len(keys)))
    axes.set_xticklabels(['%s\n%s\n%s' % (s.replace('_joint_', ' '), c, m) for c, m, s in keys],
                         fontsize=7)
    axes.set_yscale('log')
    axes.set_ylabel('round trip (us)')
    axes.set_title('Service round trips, %s against the bare service' % name)
    axes.legend()
    _save(pyplot, figure, path)


def write_pacing_plot(windows, name, path):
    pyplot = _pyplot()
    figure, axes = pyplot.subplots(figsize=(7, 3.5))
    axes.plot(range(1, len(windows) + 1), windows, 'o-', markersize=3)
    axes.axhline(1.0, color='gray', linewidth=0.8)
    for bound in (0.99, 1.01):
        axes.axhline(bound, color='gray', linestyle='--', linewidth=0.8)
    axes.set_xlabel('one-second window (wall time)')
    axes.set_ylabel('real-time factor')
    axes.set_title('Pacing at real-time factor 1, %s (dashed: +-1 %%)' % name)
    _save(pyplot, figure, path)


def write_period_plot(runs, path):
    pyplot = _pyplot()
    figure, axes = pyplot.subplots(figsize=(7, 4))
    for rate in sorted(runs):
        intervals = [interval * rate for interval in runs[rate]['wall_intervals']]
        axes.hist(intervals, bins=60, histtype='step', label='%d Hz' % rate, log=True)
    axes.set_xlabel('wall interval between jnt_pos arrivals / period')
    axes.set_ylabel('count')
    axes.set_title('Controller periods in wall time (1 = on time, 2 = one period missed)')
    axes.legend()
    _save(pyplot, figure, path)


# --- the command -------------------------------------------------------------------------------

def load_average():
    """The 1-minute load average: the run's figures mean little on a machine busy elsewhere."""
    return float(read_file('/proc/loadavg').split()[0])


def machine(load_at_start):
    return {'cpu': bm.cpu_model(read_file('/proc/cpuinfo')), 'cores': os.cpu_count(),
            'load': '%.1f / %.1f' % (load_at_start, load_average())}


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog='rosrun onedof_sim benchmark',
        description='Measures the simulator node on each engine side by side with bare '
                    'references on a private ROS graph; writes README-table.md, plots and '
                    'results.json.')
    parser.add_argument('--output', default='output/bench', help='output folder')
    parser.add_argument('--quick', action='store_true',
                        help='tiny sizes (seconds instead of minutes): checks that it runs')
    parser.add_argument('--engines',
                        help='comma-separated engines (default: every one the node lists)')
    parser.add_argument('--no-profiles', action='store_true',
                        help='never profile, also where an aim is missed (for tests, whose path '
                             'must not depend on how busy the machine is)')
    parser.add_argument('--items', default=','.join(str(row) for row in ROWS),
                        help='comma-separated row numbers to measure (default: all, %s)'
                             % ','.join(str(row) for row in ROWS))
    args = parser.parse_args(argv)
    try:
        args.items = {int(row) for row in args.items.split(',') if row}
    except ValueError:
        parser.error('--items takes row numbers: %s' % args.items)
    if not args.items or not args.items <= set(ROWS):
        parser.error('--items: rows are %s' % ','.join(str(row) for row in ROWS))
    try:
        known = engine_names()
    except RuntimeError as error:
        parser.error(str(error))
    args.engines = [e for e in args.engines.split(',') if e] if args.engines else list(known)
    unknown = [e for e in args.engines if e not in known]
    if unknown:
        parser.error('unknown engine(s): %s' % ', '.join(unknown))
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    sizes = QUICK if args.quick else FULL
    output = os.path.abspath(args.output)
    os.makedirs(output, exist_ok=True)
    log_dir = os.path.join(output, 'logs')
    shutil.rmtree(log_dir, ignore_errors=True)
    engines = args.engines
    started = time.monotonic()
    load_at_start = load_average()
    date = datetime.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')
    with PrivateRos(log_dir=log_dir) as ros:
        say('roscore on %s (logs in %s)' % (ros.master_uri, log_dir))
        bench = Bench(ros, sizes, output, engines, profiles=not args.no_profiles)
        # (the table's row numbers an item measures, its title, the measurement)
        items = [({6}, '6 start-up', bench.startup)]
        items += [({1, 7}, '1, 7 throughput and memory, ' + e,
                   lambda e=e: bench.throughput_and_memory(e)) for e in engines]
        items += [({2}, '2 scaling', bench.scaling)]
        items += [({3}, '3 latency, ' + e, lambda e=e: bench.latency(e)) for e in engines]
        # The controller's loop is measured on the default engine, the others' pacing alone.
        items += [({4, 5}, '4, 5 control loop and pacing, ' + e,
                   lambda e=e: bench.control_and_pacing(e, sizes.pacing_s,
                                                        control=e == engine_names()[0]))
                  for e in engines]
        # Lock-step (issue 11) on the default engine: the controller sets the pace, not the engine.
        items += [({8}, '8 lock-step speed, ' + engines[0],
                   lambda: bench.lockstep_speed(engines[0])),
                  ({9}, '9 busy machine, ' + engines[0], lambda: bench.busy_machine(engines[0]))]
        items = [(title, run) for rows, title, run in items if rows & args.items]
        try:
            for title, run in items:
                say('--- %s (%.0f s so far)' % (title, time.monotonic() - started))
                try:
                    run()
                except Exception:  # one broken item must not lose the others' figures
                    bench.notes.append('%s failed: %s' % (title, traceback.format_exc(limit=3)
                                                          .strip().splitlines()[-1]))
                    say(traceback.format_exc())
        finally:
            bench.close()
    elapsed = time.monotonic() - started
    bench.notes.insert(0, 'Run: `rosrun onedof_sim benchmark%s` in %.0f s of wall time; plots '
                       'next to this table; raw figures in results.json.'
                       % (' --quick' if args.quick else '', elapsed))
    host = machine(load_at_start)
    table = bm.render_table(bench.rows, host, date, bench.notes)
    with open(os.path.join(output, 'README-table.md'), 'w') as f:
        f.write(table)
    with open(os.path.join(output, 'results.json'), 'w') as f:
        json.dump(dict(machine=host, date=date, quick=args.quick, elapsed_s=elapsed,
                       results=bench.results), f, indent=1, default=str)
    print(table)
    say('done in %.0f s; outputs in %s' % (elapsed, output))
    return 0
