"""The runs: how the player advances the simulator through the tutorial's phases, each command
given as the student types it, and each phase summed up as it ends (play_phases). LockstepRun
steps the lock-stepped simulator, each command taken before its phase starts; FreeRun lets the
simulator pace itself while the controller samples it; InSimRun steps a paused world whose
controllers run inside the simulator (the book's gazebo_ros_control robot and YAML)."""
import os
import time

import yaml

from onedof_sim.simulator_extras import STEP_SERVICE, step_service
from onedof_sim.tools import package_path
from onedof_sim.tutorial.phases import CONTROL_PERIOD, CONTROLLER_NODE, spawn_table
from onedof_sim.tutorial.physics import pd_prediction
from onedof_sim.tutorial.recorders import Rosout, controller_state_samples
from onedof_sim.tutorial.summary import phase_summary


def seconds(ns):
    """Seconds from integer nanoseconds, rounded as rospy's Time.to_sec() rounds them."""
    return float(ns // 1000000000) + float(ns % 1000000000) / 1e9


def say(text):
    print('[tutorial] ' + text, flush=True)


class LockstepRun:
    """Advances the lock-stepped simulator phase by phase: each command is published while the
    world stands, taken by the controller (its log line), then the world steps through the phase
    and answers once the controller has acted at the phase's end. A phase is the periods in which
    the controller holds its command: from the period after the world stood to the one at the
    phase's end, times in integer nanoseconds so that every run draws the same edges."""

    def __init__(self, ros, rospy, recorder, pos_cmd):
        self.wait_until = ros.wait_until
        from gazebo_msgs.srv import GetPhysicsProperties
        self.rospy = rospy
        self.recorder = recorder
        self.pos_cmd = pos_cmd
        self.rosout = Rosout(ros, rospy)
        self.step_service = step_service(rospy)
        self.time_step = rospy.ServiceProxy('/gazebo/get_physics_properties',
                                            GetPhysicsProperties)().time_step
        self.now_ns = 0
        self.period_ns = int(round(CONTROL_PERIOD * 1e9))

    def before_controller(self):
        self.wait_until(lambda: self.rosout.connected('/gazebo'), 60,
                        what='the simulator\'s /rosout')
        # One period without a controller (the arm upright and at rest, no torque): ROS clients
        # have no valid time at sim time 0, so the controller starts on a time the world holds.
        self.now_ns = self.step(int(round(CONTROL_PERIOD / self.time_step)))

    def start(self):
        # The controller's first period, on its initial command: with it the controller joins
        # the lock-step (the simulator says so), and the world waits for it from then on.
        self.rosout.wait_for_join()
        self.wait_until(lambda: self.rosout.connected(CONTROLLER_NODE), 60,
                   what='the controller\'s /rosout')

    def step(self, steps):
        say('rosservice call %s "steps: %d"' % (STEP_SERVICE, steps))
        reply = self.step_service(steps)
        if not reply.success:
            raise RuntimeError('step_simulation: ' + reply.status_message)
        return reply.sim_time.to_nsec()

    def refresh(self):
        """One more control period at the final pose, after the phases: the world stands between
        steps, so an rviz started after the phases gets the controller's joint state (its
        transforms) and the simulator's markers only from a step."""
        self.now_ns = self.step(int(round(CONTROL_PERIOD / self.time_step)))

    def phase(self, command, duration):
        """Runs one phase; returns its (start, end) in sim time."""
        taken_before = len(self.rosout.commands_taken())
        self.pos_cmd.publish(self.pos_cmd.data_class(command))
        self.rosout.wait_for_command_taken(command, taken_before)
        start = seconds(self.now_ns + self.period_ns)
        self.recorder.command(start, command)
        self.now_ns = self.step(int(round(duration / self.time_step)))
        end = seconds(self.now_ns + self.period_ns)
        # Every sample of the phase is in once the one taken at its end is.
        self.wait_until(lambda: self.recorder.latest() >= seconds(self.now_ns), 60,
                   what='the controller\'s samples up to %.2f s' % seconds(self.now_ns))
        return start, end


class FreeRun:
    """Lets the simulator run at its pace; a phase is the sim time between a command and the end
    of its duration, as a student lives it."""

    def __init__(self, ros, rospy, recorder, pos_cmd):
        self.wait_until = ros.wait_until
        self.rospy = rospy
        self.recorder = recorder
        self.pos_cmd = pos_cmd

    def before_controller(self):
        pass

    def refresh(self):
        """Nothing: the free-running world goes on publishing its pose and markers."""

    def start(self):
        from std_srvs.srv import Empty
        say('rosservice call /gazebo/unpause_physics')
        self.rospy.ServiceProxy('/gazebo/unpause_physics', Empty)()
        self.wait_until(lambda: self.recorder.samples['jnt_pos'], 60,
                        what='the controller on jnt_pos')

    def phase(self, command, duration):
        start = self.rospy.get_time()
        self.pos_cmd.publish(self.pos_cmd.data_class(command))
        self.recorder.command(start, command)
        end = start + duration
        self.wait_until(lambda: self.rospy.get_time() >= end, duration * 20 + 30,
                   what='%.0f s of sim time' % duration)
        return start, end


def run_before(ros, phase):
    """What the student does before the phase's command: the table's spawn, if the phase has
    one; returns the phase as played."""
    if phase.table:
        command = spawn_table(*phase.table)
        say(' '.join(command))
        result = ros.run(command)
        if result.returncode != 0:
            raise RuntimeError('%s failed:\n%s%s' % (' '.join(command), result.stdout,
                                                    result.stderr))
    return phase


def play_phases(ros, run, recorder, phases, phase_duration, command_topic, sample_period,
                predict=pd_prediction, before=run_before):
    """Plays the phases with `run` (LockstepRun, FreeRun or InSimRun), as the student types them;
    returns their summary rows, each phase's series since its command, and each one's (start,
    end) in sim time. before(ros, phase) is what the student does before each command
    (run_before: the table spawned from the command line); it returns the phase as played,
    which the phase's summary is of.
    With a sample_period, each phase must have recorded one sample per period."""
    rows, series, spans = [], [], []
    for phase in phases:
        phase = before(ros, phase)
        say('rostopic pub %s std_msgs/Float64 %.1f   (%.0f s of sim time)'
            % (command_topic, phase.command, phase_duration))
        phase_wall = time.monotonic()
        start, end = run.phase(phase.command, phase_duration)
        row = phase_summary(phase, recorder, start, end, predict=predict,
                            expected_samples=sample_period and round((end - start) / sample_period))
        say('  settled at %.4f rad (predicted %.4f), holding %.3f N m; %.1f s of sim time '
            'in %.1f s of wall time' % (row['settled'], row['predicted'], row['holding_torque'],
                                        end - start, time.monotonic() - phase_wall))
        rows.append(row)
        series.append(recorder.series(start, end, origin=start))
        spans.append((start, end))
    return rows, series, spans


# The in-simulator run: the book's gazebo_ros_control robot and controllers.
IN_SIM_NAMESPACE = '/one_DOF_robot'
IN_SIM_CONTROLLER = 'joint1_position_controller'
IN_SIM_CONTROLLERS = ('joint_state_controller', IN_SIM_CONTROLLER)
IN_SIM_COMMAND = '%s/%s/command' % (IN_SIM_NAMESPACE, IN_SIM_CONTROLLER)
IN_SIM_STATE = '%s/%s/state' % (IN_SIM_NAMESPACE, IN_SIM_CONTROLLER)
# The integral brings the link to its command slowly (upright after 2.0 is the slowest: the
# integral holding 2.0 against gravity unwinds over some 30 s): this long settles every phase
# within 1e-3 rad.
IN_SIM_PHASE_DURATION = 40.0
# Sim seconds between the in-sim samples: the world is stepped this much at a time and the
# controller's newest state of each step taken (its state publisher keeps only the newest).
IN_SIM_SAMPLE_PERIOD = 0.05
STATE_PERIOD = 0.01  # ros_controllers publish the state on every tenth 1 ms update


def book_pid_gains():
    """The position controller's pid gains from the book's YAML, as the simulator reads them."""
    with open(os.path.join(package_path('minimal_robot_description'), 'control_config',
                           'one_dof_ctl_params.yaml')) as f:
        config = yaml.safe_load(f)
    return config[IN_SIM_NAMESPACE.strip('/')][IN_SIM_CONTROLLER]['pid']


def newest_sample_of_step(states, after_ns, until_ns):
    """The newest of the (stamp ns, message) states in (after_ns, until_ns], None if none: the one
    sample a step from after_ns to until_ns keeps, whichever others got through."""
    inside = [(stamp, msg) for stamp, msg in states if after_ns < stamp <= until_ns]
    return max(inside, key=lambda pair: pair[0]) if inside else None


def bus_messages_received(bus_stats, topic):
    """Messages a roscpp node's subscription to `topic` has read, from its slave API's
    getBusStats answer. roscpp answers the stats themselves, without rospy's [code, message]
    before them: [publish stats, subscribe stats, ...], the subscribe stats as
    [topic, [[connection, bytes, messages, drops, connected], ...]]."""
    subscribe_stats = bus_stats[1]
    return sum(connection[2] for name, connections in subscribe_stats if name == topic
               for connection in connections)


class InSimRun:
    """Advances a paused world with in-simulator controllers phase by phase: each command is
    published on the controller's command topic while the world stands, read by the simulator
    before the world moves again, then the world steps through the phase IN_SIM_SAMPLE_PERIOD at
    a time and the controller's newest state of each step is recorded. Controllers inside the
    step need no lock-step: nothing outside the simulator takes part in a period."""

    def __init__(self, ros, rospy, recorder):
        import threading
        import xmlrpc.client
        from control_msgs.msg import JointControllerState
        from controller_manager_msgs.srv import ListControllers
        from gazebo_msgs.srv import GetPhysicsProperties
        from std_msgs.msg import Float64
        self.ros = ros
        self.recorder = recorder
        self.states = []  # (stamp ns, JointControllerState), as they arrive
        self.arrived = threading.Condition()
        self.state_subscriber = rospy.Subscriber(IN_SIM_STATE, JointControllerState,
                                                 self._on_state, queue_size=1000)
        self.command_pub = rospy.Publisher(IN_SIM_COMMAND, Float64, queue_size=1, latch=True)
        # Persistent: a phase is hundreds of short requests, each a master lookup and a new
        # connection otherwise.
        self.step_service = step_service(rospy, persistent=True)
        self.list_controllers = rospy.ServiceProxy(
            IN_SIM_NAMESPACE + '/controller_manager/list_controllers', ListControllers)
        self.time_step = rospy.ServiceProxy('/gazebo/get_physics_properties',
                                            GetPhysicsProperties)().time_step
        _, _, simulator_uri = ros.master().lookupNode('/tutorial_player', '/gazebo')
        self.simulator = xmlrpc.client.ServerProxy(simulator_uri)
        self.now_ns = 0

    def _on_state(self, msg):
        with self.arrived:
            self.states.append((msg.header.stamp.to_nsec(), msg))
            self.arrived.notify_all()

    def wait_for_controllers(self, timeout=60):
        """Until the spawner has both controllers running and our topics are connected."""
        def running():
            listed = {c.name: c.state for c in self.list_controllers().controller}
            return all(listed.get(name) == 'running' for name in IN_SIM_CONTROLLERS)
        self.ros.wait_for_service(IN_SIM_NAMESPACE + '/controller_manager/list_controllers', 60)
        self.ros.wait_until(running, timeout, what='the spawner to start %s'
                            % ' and '.join(IN_SIM_CONTROLLERS))
        self.ros.wait_until(lambda: self.state_subscriber.get_num_connections() > 0 and
                            self.command_pub.get_num_connections() > 0, timeout,
                            what='the connections to %s and %s' % (IN_SIM_STATE, IN_SIM_COMMAND))

    def commands_received(self):
        return bus_messages_received(self.simulator.getBusStats('/tutorial_player'),
                                     IN_SIM_COMMAND)

    def step(self, steps):
        reply = self.step_service(steps)
        if not reply.success:
            raise RuntimeError('step_simulation: ' + reply.status_message)
        return reply.sim_time.to_nsec()

    def wait_for_state(self, after_ns, until_ns, timeout=60):
        deadline = time.monotonic() + timeout
        with self.arrived:
            while True:
                newest = newest_sample_of_step(self.states, after_ns, until_ns)
                if newest and newest[0] > until_ns - STATE_PERIOD * 1e9:
                    return newest
                self.ros.check_running('the controller state at %.3f s' % seconds(until_ns))
                if time.monotonic() > deadline:
                    raise TimeoutError('timed out after %.0f s waiting for %s at %.3f s'
                                       % (timeout, IN_SIM_STATE, seconds(until_ns)))
                self.arrived.wait(0.5)

    def phase(self, command, duration):
        """Runs one phase; returns its (start, end) in sim time."""
        received_before = self.commands_received()
        self.command_pub.publish(self.command_pub.data_class(command))
        self.ros.wait_until(lambda: self.commands_received() > received_before, 60, interval=0.01,
                            what='the simulator to read command %g' % command)
        # Read is not yet taken: the command's callback is queued on the simulator's spinner. A
        # service call queued after it answers once the callback has been dequeued.
        self.list_controllers()
        start = seconds(self.now_ns)
        self.recorder.command(start, command)
        chunk = int(round(IN_SIM_SAMPLE_PERIOD / self.time_step))
        with self.arrived:
            self.states = []
        for _ in range(int(round(duration / IN_SIM_SAMPLE_PERIOD))):
            before_ns, self.now_ns = self.now_ns, self.step(chunk)
            stamp_ns, state = self.wait_for_state(before_ns, self.now_ns)
            if state.set_point != command:
                raise RuntimeError('%s reports set point %g at %.3f s, not the command %g'
                                   % (IN_SIM_STATE, state.set_point, seconds(stamp_ns), command))
            self.recorder.add(controller_state_samples(state))
            with self.arrived:
                self.states = []
        return start, seconds(self.now_ns)
