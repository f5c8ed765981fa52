"""Every command of docs/tutorial.md's "What the student types", as the page prints
it, in the page's order, one session against a private roscore: the commands are parsed from the
page, so this test follows it, and a command it does not know fails the test.

Each command runs as typed in bash (quotes and all) in the directory the page's `cd` left, without
a display. Long-running ones (simulator, controller, `rostopic pub`, launches) stay up as in their
own terminals; a `rostopic pub` is stopped (Ctrl-C) before the next one, and the Part 2 commands
start after the first block's terminals are closed, the roscore kept. Each is checked for what the
page says it does or prints. The single behaviours are tested in depth elsewhere (test_api,
test_gazebo_ros, test_controller, test_plot_cli, test_rviz_view); this is the page as a user
follows it.

The simulator runs at real time as typed, with the Python controller free-running on a shared
machine; a missed period droops the link a little further, hence the tolerance on rest angles.
"""
import os
import re
import shlex
import signal
import subprocess

import pytest
import yaml

from api_client import BOX_SDF, GazeboApi, ROBOT
from conftest import GROUND, WORKSPACE
from onedof_harness.private_ros import wait_until
from onedof_sim.tutorial import physics
from test_controller import Topic

PAGE = os.path.join(WORKSPACE, 'docs', 'tutorial.md')
REST_TOLERANCE = 0.05  # rad
SETTLE_WINDOW = 1.0    # s of sim time within SETTLE_BAND
SETTLE_BAND = 0.01
# Only a bound on a hang, for a command or a wait: spawning takes over a minute on a busy machine.
HANG_SECONDS = 300
TABLE_X = 0.85         # the page's table command


def page_text():
    with open(PAGE) as f:
        return f.read()


def typed_block(text):
    """The commands of the fenced block under "What the student types", comments dropped, `a ; b`
    split as the shell runs them."""
    section = text.split('## What the student types', 1)[1]
    block = re.search(r'^```\n(.*?)^```', section, re.S | re.M).group(1)
    commands = []
    for line in block.splitlines():
        line = line.split('  #', 1)[0].strip()
        commands += [part.strip() for part in line.split(' ; ') if part.strip()]
    return commands


def part2_commands(text):
    """The backticked commands of the page's Part 2 command summary."""
    summary = re.search(r"Part 2 command summary:(.*?)The project's own names", text, re.S)
    return [' '.join(c.split()) for c in re.findall(r'`([^`]+)`', summary.group(1))]


def spawned_joint1_lines(text):
    """What the page says get_joint_properties prints right after spawning."""
    paragraph = re.search(r'Right after spawning.*?prints(.*?)\n\n', text, re.S).group(1)
    return re.findall(r'`([^`]+)`', paragraph)


class Session:
    """A user's terminals against one roscore: foreground commands run to completion, background
    ones stay up until closed."""

    def __init__(self, ros, rospy):
        self.ros, self.rospy = ros, rospy
        self.cwd = WORKSPACE
        self.env = dict(ros.env, DISPLAY='')
        self.env.pop('WAYLAND_DISPLAY', None)
        self.terminals = []
        self.count = 0

    def run(self, command, timeout=HANG_SECONDS):
        result = subprocess.run(['bash', '-c', command], cwd=self.cwd, env=self.env,
                                stdin=subprocess.DEVNULL, capture_output=True, text=True,
                                timeout=timeout)
        result.shown = '$ %s\n(exit %d)\nstdout:\n%s\nstderr:\n%s' % (
            command, result.returncode, result.stdout, result.stderr)
        return result

    def start(self, command):
        self.count += 1
        proc = self.ros.start(['bash', '-c', 'cd %s && exec %s' % (shlex.quote(self.cwd), command)],
                              name='terminal%d' % self.count, env=self.env)
        proc.command = command
        self.terminals.append(proc)
        return proc

    def alive(self, proc):
        assert proc.poll() is None, '`%s` exited:\n%s' % (proc.command, self.ros.log_text(proc))

    def close(self, proc):
        """Ctrl-C in the terminal, as a user stops a command (if it is still running)."""
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
        self.ros.terminate(proc)
        self.terminals.remove(proc)

    def close_all(self):
        for proc in list(self.terminals):
            self.close(proc)

    def api(self):
        return GazeboApi(self.rospy)


class Checks:
    """What the page says about each command, by the command's words."""

    def __init__(self, session, text):
        from std_msgs.msg import Float64
        self.s = session
        self.text = text
        self.jnt_pos = Topic(session.rospy, '/jnt_pos', Float64)
        self.pub = None
        self.controller = None
        self.table = False

    def __call__(self, command):
        words = shlex.split(command)
        if words == ['roscore']:
            return  # the private roscore is this session's
        if words[0] == 'cd':
            self.s.cwd = os.path.join(self.s.cwd, words[1])
            return
        if words[:3] == ['rosrun', 'gazebo_ros', 'gazebo']:
            return self.serving(self.s.start(command))
        if words[:2] == ['roslaunch', 'gazebo_ros']:
            return self.serving(self.s.start(command))
        if words[:3] == ['rosrun', 'gazebo_ros', 'spawn_model']:
            return self.spawn(command, words)
        if words[:2] in (['rostopic', 'list'], ['rosservice', 'list']):
            result = self.ok(command)
            expected = '/clock' if words[0] == 'rostopic' else '/gazebo/get_joint_properties'
            assert expected in result.stdout.split(), result.shown
            return
        if words[:3] == ['rosservice', 'call', '/gazebo/get_joint_properties']:
            result = self.ok(command)
            for line in spawned_joint1_lines(self.text):
                assert line in result.stdout.splitlines(), result.shown
            return
        if words[:2] == ['rosrun', 'minimal_joint_controller']:
            self.controller = self.s.start(command)
            wait_until(lambda: self.s.alive(self.controller) or self.jnt_pos.samples, HANG_SECONDS,
                       what='the controller to publish jnt_pos')
            return
        if words[:3] == ['rostopic', 'pub', 'pos_cmd']:
            return self.command(command, float(words[-1]))
        if words[0] == 'rqt_plot':
            # No display here: it says how to record headless instead of failing obscurely.
            result = self.s.run(command)
            assert result.returncode == 2, result.shown
            assert 'no display: record headless with --duration' in result.stderr, result.shown
            return
        if words[:2] == ['roslaunch', 'minimal_robot_description']:
            return self.robot_launch(command)
        if words[:2] == ['rosrun', 'robot_state_publisher']:
            self.s.start(command)
            result = self.ok('rostopic echo -n 1 /tf')
            assert 'child_frame_id: "link2"' in result.stdout, result.shown
            return
        if words == ['rviz']:
            return  # needs a display; test_rviz_view runs it on a private Xvfb
        if words[:2] == ['rosmsg', 'show']:
            result = self.ok(command)
            for field in ('string model_name', 'geometry_msgs/Pose pose',
                          'geometry_msgs/Twist twist', 'string reference_frame'):
                assert field in result.stdout.splitlines(), result.shown
            return
        if words[:2] == ['rosservice', 'info']:
            result = self.ok(command)
            assert 'Type: gazebo_msgs/SetModelState' in result.stdout, result.shown
            return
        if words[:3] == ['rosservice', 'call', '/gazebo/set_model_state']:
            return self.lift(command)
        if words[:2] == ['rostopic', 'echo']:
            return self.echo(command, words)
        pytest.fail('the page has a command this test does not know: %s' % command)

    def ok(self, command, timeout=HANG_SECONDS):
        result = self.s.run(command, timeout=timeout)
        assert result.returncode == 0, result.shown
        return result

    def serving(self, proc):
        wait_until(lambda: self.s.alive(proc) or self.s.ros.has_service('/gazebo/unpause_physics'),
                   HANG_SECONDS, what='`%s` to serve /gazebo' % proc.command)

    def spawn(self, command, words):
        model = words[words.index('-model') + 1]
        result = self.ok(command)
        assert model in self.s.api().get_world_properties().model_names, result.shown
        self.table = self.table or model == 'cafe_table'

    def command(self, command, value):
        """A latched pos_cmd left running, as typed; the previous one is stopped first. The link
        settles where the page says."""
        if self.pub is not None:
            self.s.close(self.pub)
        heard = 'received value of pos_cmd is: %f' % value  # the controller's line, as the book's
        said_before = self.s.ros.log_text(self.controller).count(heard)
        self.pub = self.s.start(command)
        # Settled only after the controller has the command: a slow `rostopic pub` would
        # otherwise find the link at rest where the last command left it.
        wait_until(lambda: self.s.alive(self.pub) or self.s.alive(self.controller)
                   or self.s.ros.log_text(self.controller).count(heard) > said_before, HANG_SECONDS,
                   what='the controller to log "%s"' % heard)
        q = self.settled_since(self.s.rospy.get_time())
        if self.table and value > physics.table_contact_angle(TABLE_X):
            # "the link comes to rest on the table top ... short of its goal"
            expected = physics.table_contact_angle(TABLE_X)
            assert q < value
        else:
            # "gravity makes the link droop past the command"
            expected = physics.settled_angle(value) if value else 0.0
            assert value == 0 or q > value
        assert q == pytest.approx(expected, abs=REST_TOLERANCE), \
            'pos_cmd %g: at rest at %.4f rad, the page expects %.4f' % (value, q, expected)

    def settled_since(self, start):
        def settled():
            self.s.alive(self.controller)
            tail = self.jnt_pos.steady_tail(start, SETTLE_WINDOW, SETTLE_BAND, after=1.0)
            return tail and [sum(q for _, q in tail) / len(tail)]
        return wait_until(settled, 180, interval=0.2, what='jnt_pos to settle')[0]

    def robot_launch(self, command):
        """Launched while the first simulator runs, its simulator takes the name /gazebo (ROS
        shuts the old node down) and the robot is spawned into the new world (its ground alone); the
        controller reconnects."""
        proc = self.s.start(command)
        wait_until(lambda: self.s.alive(proc) or self.world_models() == [GROUND, ROBOT], 90,
                   what='the launch to spawn the robot into a new world')
        assert self.s.rospy.has_param('/robot_description')
        self.table = False
        start = self.s.rospy.get_time()
        wait_until(lambda: self.jnt_pos.values_since(start), 90,
                   what='the controller to control the relaunched robot')

    def world_models(self):
        try:
            return list(self.s.api().get_world_properties().model_names)
        except Exception:  # the old simulator going or the new one coming
            return None

    def lift(self, command):
        """The model is lifted: the world's model states show it above 1 m after the command
        (it falls back at once in the running world, before a later get_model_state on a busy
        machine)."""
        from gazebo_msgs.msg import ModelStates
        name = re.search(r'model_name: (\w+)', command).group(1)
        heights = []

        def heard(states):
            if name in states.name:
                heights.append(states.pose[states.name.index(name)].position.z)
        # Every message kept (a busy machine may hold this process up for seconds of steps).
        listener = self.s.rospy.Subscriber('/gazebo/model_states', ModelStates, heard,
                                           queue_size=None)
        try:
            wait_until(lambda: heights, 60, what='the model states of %s' % name)
            result = self.ok(command)
            assert 'success: True' in result.stdout, result.shown
            wait_until(lambda: heights and max(heights) > 1.0, 60,
                       what='the model states to show %s lifted above 1 m' % name)
        finally:
            listener.unregister()

    def echo(self, command, words):
        result = self.ok(command + ' -n 1')
        names = yaml.safe_load(result.stdout.split('\n---')[0])['name']
        if words[2].endswith('model_states'):
            assert names == [GROUND, ROBOT, 'box'], result.shown
        else:
            assert names == [GROUND + '::link', ROBOT + '::link1', ROBOT + '::link2',
                             'box::body'], result.shown


@pytest.fixture
def session(ros, request):
    ros.set_param('/use_sim_time', True)
    rospy = request.getfixturevalue('rospy_client')
    s = Session(ros, rospy)
    yield s
    s.close_all()


def test_every_command_of_the_tutorial_page_works_as_typed(session, tmp_path):
    text = page_text()
    checks = Checks(session, text)
    for command in typed_block(text):
        checks(command)

    session.close_all()  # the first block's terminals; the roscore stays
    checks.pub = checks.controller = None
    box = tmp_path / 'box.sdf'
    box.write_text(BOX_SDF)
    for command in part2_commands(text):
        # NAME: "on a free model (the book spawns a box)"
        checks(command.replace('model_name: NAME', 'model_name: box'))
        if command.startswith('rosrun gazebo_ros spawn_model -param'):
            checks('rosrun gazebo_ros spawn_model -file %s -sdf -model box' % box)
