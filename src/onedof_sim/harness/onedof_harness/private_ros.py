"""A private ROS graph: its own roscore on a free port and the processes started against it.

The roscore is what `roscore` starts, without roslaunch's own process in between: rosmaster
--core, the parameters of roscore.xml (/run_id, /rosversion, /rosdistro) and rosout. Tests start
a graph each (hundreds per suite run), and roslaunch's start-up (its imports and the two
`rosversion` commands roscore.xml runs) costs a graph more CPU than the master and rosout together.

Tests, the tutorial player and the benchmarks all run their nodes here, so they can run side by
side and never touch a user's roscore on 11311. Every process gets its own process group, and
stop() ends them all (SIGINT first, as roslaunch does, then SIGKILL), also after a failure.

Every process listens on one address only, loopback unless told otherwise: ROS_IP is that address
(ROS_HOSTNAME, which would override it, is dropped), and bind_to_ros_ip.c is preloaded, because
ROS 1 binds its XML-RPC servers to every interface whatever ROS_IP says.
"""
import functools
import os
import signal
import socket
import subprocess
import tempfile
import time
import uuid
import xmlrpc.client
from xml.parsers.expat import ExpatError

import psutil


def free_port():
    with socket.socket() as sock:
        sock.bind(('127.0.0.1', 0))
        return sock.getsockname()[1]


class TimeoutTransport(xmlrpc.client.Transport):
    """XML-RPC over HTTP that gives up on a server silent for `timeout` s."""

    def __init__(self, timeout):
        super().__init__()
        self.timeout = timeout

    def make_connection(self, host):
        connection = super().make_connection(host)
        connection.timeout = self.timeout
        return connection


class PortTaken(Exception):
    """The port chosen for the roscore answers for another program, or the roscore could not bind it."""


def listeners(port):
    """The pids of the processes listening on TCP `port` (None for one this user may not see)."""
    return [connection.pid for connection in psutil.net_connections(kind='tcp')
            if connection.status == psutil.CONN_LISTEN and connection.laddr.port == port]


def is_descendant(pid, ancestor):
    """Whether process pid is ancestor or below it (Linux /proc)."""
    while pid > 1:
        if pid == ancestor:
            return True
        try:
            with open('/proc/%d/stat' % pid) as f:
                # The parent pid is the second field after the command name, which is in
                # parentheses and may itself hold spaces.
                pid = int(f.read().rsplit(')', 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            return False
    return False


def wait_until(condition, timeout, interval=0.05, what='condition'):
    """Polls condition() until it returns a truthy value, which is returned; raises on timeout."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            raise TimeoutError('timed out after %.1f s waiting for %s' % (timeout, what))
        time.sleep(interval)


BIND_LIBRARY = 'libonedof_bind_to_ros_ip.so'
# How long a command (rosrun, rosservice, spawn_model, a roslaunch that starts and stops its nodes)
# may take before it counts as hung (s): seconds on a quiet machine, minutes on a 2-core machine at
# load 30.
COMMAND_TIMEOUT = 300
# How long a catkin_make of a test's overlay may take before it counts as hung (s): at load 20 and
# more a compile takes ten times its quiet time and more.
BUILD_TIMEOUT = 3600
# How long a call to the roscore may take (s): rosmaster answers in milliseconds, seconds on a
# loaded machine; a port held by a program that never answers must not hang us.
MASTER_TIMEOUT = 60
ANSWER_TIMEOUT = 2  # per try while waiting for our roscore to answer: the wait retries
# How long our rosmaster may take to answer at all before its port counts as lost to another
# program (s): a second on a quiet machine, many on a busy one; only a bound on a hang.
MASTER_START_TIMEOUT = 60


class ProcessExited(RuntimeError):
    """A process started through PrivateRos.start() ended while something waited for a condition."""


LOG_TAIL_LINES = 25


def log_tail(text, lines=LOG_TAIL_LINES):
    return '\n'.join(text.rstrip('\n').split('\n')[-lines:])


def exit_status_text(status):
    """'status -6, SIGABRT' for a process a signal ended, 'status 1' otherwise."""
    if status is not None and status < 0:
        try:
            return 'status %d, %s' % (status, signal.Signals(-status).name)
        except ValueError:
            pass
    return 'status %s' % status


def bind_library():
    """The path of the preloaded bind library, from the workspace's library path (devel/lib)."""
    for directory in os.environ.get('LD_LIBRARY_PATH', '').split(os.pathsep):
        path = os.path.join(directory, BIND_LIBRARY)
        if directory and os.path.exists(path):
            return path
    raise RuntimeError('%s is not on LD_LIBRARY_PATH: build the workspace and source its '
                       'devel/setup.bash' % BIND_LIBRARY)


def bus_has_connection(bus_info, other, topic):
    """Whether a node's bus information (its getBusInfo reply: per connection [id, the other
    node, direction, transport, topic, ...]) has a connection with `other` on `topic`."""
    return any(connection[1] == other and connection[4] == topic for connection in bus_info)


def listening_environment(address):
    """The variables that make a ROS process advertise `address` and listen on it only."""
    preload = os.environ.get('LD_PRELOAD', '').split()
    library = bind_library()
    if library not in preload:
        preload.append(library)
    return {'ROS_IP': address, 'LD_PRELOAD': ' '.join(preload)}


@functools.lru_cache(maxsize=None)
def core_parameters():
    """The parameters roscore.xml gives a roscore: the output of `rosversion roslaunch` and of
    `rosversion -d` (computed as rosversion does)."""
    from rospkg import rosversion
    distro = (os.environ.get('ROS_DISTRO') or rosversion.get_distro_name_from_roscore()
              or 'Debian')
    return {'/rosversion': rosversion.get_version_from_package_name('roslaunch') + '\n',
            '/rosdistro': distro + '\n'}


@functools.lru_cache(maxsize=None)
def rosout_command():
    """rosout as roslaunch starts it for roscore.xml's node."""
    import roslib.packages
    found = roslib.packages.find_node('rosout', 'rosout')
    if not found:
        raise RuntimeError('rosout is not installed (Debian package ros-core-dev)')
    return [found[0], '__name:=rosout']


class PrivateRos:
    """Context manager: a roscore on a free port plus every process started through start().
    address is the one every process listens on and advertises."""

    def __init__(self, log_dir=None, use_sim_time=None, address='127.0.0.1'):
        self.address = address
        self.log_dir = log_dir or tempfile.mkdtemp(prefix='onedof_ros_')
        os.makedirs(self.log_dir, exist_ok=True)
        self.port = None
        self.env = None
        self.processes = []
        self.roscore = None  # rosmaster
        self.rosout = None
        self._use_sim_time = use_sim_time

    @property
    def master_uri(self):
        return 'http://%s:%d' % (self.address, self.port)

    def __enter__(self):
        self.start_master()
        return self

    def __exit__(self, *exc):
        self.stop()

    def start_master(self, attempts=5):
        """Starts the roscore. A free port chosen now may be taken by another process before
        roscore binds it, so only an answer from our own rosmaster counts; any other answer, or
        roscore exiting, means another port."""
        failures = []
        for _ in range(attempts):
            self.port = free_port()
            self.env = dict(os.environ, ROS_MASTER_URI=self.master_uri, ROS_LOG_DIR=self.log_dir,
                            ROS_HOME=self.log_dir, **listening_environment(self.address))
            self.env.pop('ROS_HOSTNAME', None)
            # Each log line reaches the log file when it is written (C++ and Python nodes buffer
            # stdout into a file otherwise): waits on a node's log see what it has said.
            self.env.update(ROSCONSOLE_STDOUT_LINE_BUFFERED='1', PYTHONUNBUFFERED='1')
            try:
                self._launch_master()
                break
            except (PortTaken, TimeoutError) as failure:
                failures.append(str(failure))
        else:
            raise RuntimeError('roscore did not start on %d ports (%s); logs in %s'
                               % (attempts, '; '.join(failures), self.log_dir))
        if self._use_sim_time is not None:
            self.set_param('/use_sim_time', self._use_sim_time)

    def _launch_master(self):
        """Starts the roscore on self.port and waits until its rosout is up; PortTaken or
        TimeoutError (the roscore killed) when the master does not answer."""
        self.roscore = self.start(['rosmaster', '--core', '-p', str(self.port), '-w', '3'],
                                  name='roscore')
        try:
            wait_until(self._our_master_answers, MASTER_START_TIMEOUT,
                       what='roscore on port %d' % self.port)
        except (PortTaken, TimeoutError):
            # Killed: a master that found the port taken has nothing to save.
            self.kill(self.roscore)
            self.processes.remove(self.roscore)
            raise
        master = self.master()
        for name, value in dict(core_parameters(), **{'/run_id': str(uuid.uuid1())}).items():
            master.setParam('/private_ros', name, value)
        self.rosout = self.start(rosout_command(), name='rosout')

        def rosout_up():
            if self.rosout.poll() is not None:
                raise RuntimeError('rosout exited with %s: %s' % (
                    self.rosout.returncode, log_tail(self.log_text(self.rosout))))
            return master.lookupNode('/private_ros', '/rosout')[0] == 1
        wait_until(rosout_up, 60, what='rosout on port %d' % self.port)

    def restart_master(self):
        """Kills the roscore (master and rosout) and starts a new one on the same port, as a
        user restarting roscore does: the nodes started here go on running, and the new master
        knows nothing of them (no registrations, no parameters, not even use_sim_time given to
        the constructor)."""
        for proc in (self.rosout, self.roscore):
            self.kill(proc)
            self.processes.remove(proc)
        self._launch_master()

    def _our_master_answers(self):
        if self.roscore.poll() is not None:
            raise PortTaken('roscore on port %d exited with %s' % (self.port,
                                                                   self.roscore.returncode))
        try:
            code, _, pid = self.master(timeout=ANSWER_TIMEOUT).getPid('/private_ros')
        except TimeoutError:
            # Something listens and does not answer: our rosmaster starting up, or another
            # program, which would keep the port from our master.
            strangers = [pid for pid in listeners(self.port)
                         if pid is None or not is_descendant(pid, self.roscore.pid)]
            if strangers:
                raise PortTaken('port %d is held by a program that does not answer (pid %s)'
                                % (self.port, strangers[0]))
            return False
        except OSError:
            # Nothing listens on the port yet: our rosmaster starting up (one that could not
            # bind the port stays up without it, and the wait's timeout ends it).
            return False
        except (xmlrpc.client.Error, ExpatError) as answer:
            raise PortTaken('port %d answers for another program: %s' % (self.port, answer))
        if code != 1 or not is_descendant(pid, self.roscore.pid):
            raise PortTaken('port %d answers for another ROS master (pid %s)' % (self.port, pid))
        return True

    def adopt_environment(self):
        """Points this process at the graph (before rospy.init_node here): the graph's variables,
        and no ROS_HOSTNAME of the user's, which would override ROS_IP."""
        os.environ.pop('ROS_HOSTNAME', None)
        os.environ.update(self.env)

    def master(self, timeout=MASTER_TIMEOUT):
        return xmlrpc.client.ServerProxy(self.master_uri, transport=TimeoutTransport(timeout))

    def set_param(self, name, value):
        self.master().setParam('/private_ros', name, value)

    def connected(self, node, topic, other):
        """Whether `node` has a connection with `other` on `topic` now, as `node` itself says
        (its getBusInfo: per connection [id, the other node, direction, transport, topic, ...]).
        A subscriber's own count can still hold a connection to a publisher that has gone; the
        publisher's running process knows only its own."""
        code, _, uri = self.master().lookupNode('/private_ros', node)
        if code != 1:
            return False
        try:
            code, _, bus_info = xmlrpc.client.ServerProxy(
                uri, transport=TimeoutTransport(MASTER_TIMEOUT)).getBusInfo('/private_ros')
        except OSError:
            return False  # a node that has gone
        return code == 1 and bus_has_connection(bus_info, other, topic)

    def has_service(self, name):
        code, _, _ = self.master().lookupService('/private_ros', name)
        return code == 1

    def wait_for_service(self, name, timeout=30):
        self.wait_until(lambda: self.has_service(name), timeout, what='service %s' % name)

    def check_running(self, what='condition'):
        """Raises ProcessExited for the first process started here that has ended although
        nothing stopped it (and it was not started with may_exit)."""
        for proc in self.processes:
            if proc.may_exit or proc.stopped or proc.poll() is None:
                continue
            raise ProcessExited(
                '%s exited (%s) while waiting for %s; the end of its log %s:\n%s'
                % (proc.log_name, exit_status_text(proc.returncode), what,
                   self.log_path(proc.log_name), log_tail(self.log_text(proc))))

    def wait_until(self, condition, timeout, interval=0.05, what='condition'):
        """wait_until() that also fails as soon as a process started here dies (check_running)."""
        def watched():
            self.check_running(what)
            return condition()
        return wait_until(watched, timeout, interval=interval, what=what)

    def log_path(self, name):
        return os.path.join(self.log_dir, name + '.log')

    def start(self, args, name=None, env=None, may_exit=False):
        """Starts args in its own process group, output to <log_dir>/<name>.log. Unless may_exit,
        the process is meant to run until stopped, and wait_until() fails if it ends."""
        name = name or os.path.basename(args[0])
        log = open(self.log_path(name), 'ab')
        proc = subprocess.Popen(args, env=dict(self.env, **(env or {})), stdout=log,
                                stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                start_new_session=True)
        proc.log_name = name
        proc.may_exit = may_exit
        proc.stopped = False
        log.close()
        self.processes.append(proc)
        return proc

    def run(self, args, timeout=COMMAND_TIMEOUT, input=None):
        """Runs a command (rosservice, rostopic, ...) against this graph; returns CompletedProcess.
        The timeout only catches a command that hangs."""
        return subprocess.run(args, env=self.env, capture_output=True, text=True, timeout=timeout,
                              input=input)

    def log_text(self, proc_or_name):
        name = getattr(proc_or_name, 'log_name', proc_or_name)
        try:
            with open(self.log_path(name), errors='replace') as f:
                return f.read()
        except FileNotFoundError:
            return ''

    @staticmethod
    def terminate(*procs, timeout=10):
        """Ends the processes' groups: SIGINT to all at once (each shuts down on its own, side by
        side), then SIGTERM and SIGKILL to those still running `timeout` s later."""
        running = list(procs)
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
            for proc in running:
                proc.stopped = True
                try:
                    os.killpg(proc.pid, sig)
                except ProcessLookupError:
                    pass
            deadline = time.monotonic() + timeout
            for proc in running:
                try:
                    proc.wait(timeout=max(0.0, deadline - time.monotonic()))
                except subprocess.TimeoutExpired:
                    pass
            running = [proc for proc in running if proc.poll() is None]
            if not running:
                return

    @staticmethod
    def kill(proc):
        """SIGKILL to the process's group and every process under it: roslaunch starts each
        node in a session of its own, out of its group's reach."""
        proc.stopped = True
        try:
            descendants = psutil.Process(proc.pid).children(recursive=True)
        except psutil.NoSuchProcess:
            descendants = []
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        for descendant in descendants:
            try:
                descendant.kill()
            except psutil.NoSuchProcess:
                pass
        proc.wait()

    def stop(self):
        # Nodes (rosout among them) first, so they can unregister cleanly; then the master,
        # killed: it keeps nothing.
        self.terminate(*[proc for proc in self.processes if proc is not self.roscore])
        if self.roscore in self.processes:
            self.kill(self.roscore)
        self.processes.clear()
