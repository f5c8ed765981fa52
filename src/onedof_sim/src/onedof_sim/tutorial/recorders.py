"""What the player records while the tutorial plays: the samples the plots, the CSV and the
per-phase figures are made of (Recorder, filled from the rospy controller's /joint_states or from
the in-simulator controller's state), and the log lines (/rosout) that tell the player when to
go on."""
import math

from onedof_sim.tools.plot import held_window
from onedof_sim.tutorial.phases import CONTROLLER_NODE, JOINT

RECORDED_TOPICS = ('pos_cmd', 'jnt_pos', 'jnt_vel', 'jnt_trq')


def joint_state_samples(msg, joint=JOINT):
    """[(topic, sim time, value)] of a sensor_msgs/JointState: the joint's position, velocity and
    effort as jnt_pos, jnt_vel and jnt_trq, at the header stamp."""
    if joint not in msg.name:
        return []
    index = msg.name.index(joint)
    t = msg.header.stamp.to_sec()
    return [(topic, t, values[index]) for topic, values in
            (('jnt_pos', msg.position), ('jnt_vel', msg.velocity), ('jnt_trq', msg.effort))
            if index < len(values)]


def controller_state_samples(msg):
    """[(topic, sim time, value)] of a control_msgs/JointControllerState: the process value and
    its rate as jnt_pos and jnt_vel, the controller's effort command as jnt_trq, at the stamp."""
    t = msg.header.stamp.to_sec()
    return [('jnt_pos', t, msg.process_value), ('jnt_vel', t, msg.process_value_dot),
            ('jnt_trq', t, msg.command)]


class Recorder:
    """Keeps (sim time, value) of what the tutorial plots: pos_cmd as the player commands it, and
    jnt_pos, jnt_vel and jnt_trq as a controller reports them, each at the sim time its sample was
    taken (the header stamp: the Float64 topics carry no time, and the time of reception says
    nothing when the simulator runs faster than real time)."""

    def __init__(self):
        self.samples = {topic: [] for topic in RECORDED_TOPICS}

    def add(self, samples):
        for topic, t, value in samples:
            self.samples[topic].append((t, value))

    def command(self, t, value):
        self.samples['pos_cmd'].append((t, value))

    def latest(self):
        """Sim time of the newest joint sample (-inf before the first)."""
        return self.samples['jnt_pos'][-1][0] if self.samples['jnt_pos'] else -math.inf

    def between(self, topic, start, end):
        return [(t, v) for t, v in self.samples[topic] if start <= t < end]

    def series(self, start=-math.inf, end=math.inf, origin=0.0):
        """{topic: (times since origin, values)} of the samples in [start, end), each topic led
        by its value held at `start` (pos_cmd is published once per phase, before some)."""
        series = {}
        for topic in RECORDED_TOPICS:
            samples = list(self.samples[topic])  # one snapshot: the callbacks keep appending
            times, values = held_window([t for t, _ in samples], [v for _, v in samples],
                                        start, end)
            series[topic] = ([t - origin for t in times], values)
        return series


class JointStatesRecorder(Recorder):
    """The rospy controller's /joint_states, every message (one per control period)."""

    def __init__(self, rospy):
        super().__init__()
        from sensor_msgs.msg import JointState
        self.subscriber = rospy.Subscriber(
            '/joint_states', JointState, lambda msg: self.add(joint_state_samples(msg)),
            queue_size=100000)

    def connected(self):
        return self.subscriber.get_num_connections() > 0


class Rosout:
    """The log lines of some nodes (/rosout): the controller's for each command it takes, the
    simulator's when a controller joins the lock-step. They tell the player when to go on."""

    COMMAND_TAKEN = 'received value of pos_cmd is: '
    JOINED = 'lock-step: %s is commanded by %s' % (JOINT, CONTROLLER_NODE)

    def __init__(self, ros, rospy):
        from rosgraph_msgs.msg import Log
        self.wait_until = ros.wait_until
        self.lines = []
        self.subscriber = rospy.Subscriber('/rosout', Log, self._on_log, queue_size=1000)

    def connected(self, node):
        """Whether the node's /rosout reaches this subscriber."""
        return any(getattr(connection, 'callerid_pub', None) == node
                   for connection in list(self.subscriber.impl.connections))

    def _on_log(self, msg):
        self.lines.append((msg.name, msg.msg))

    def commands_taken(self):
        return [float(line[len(self.COMMAND_TAKEN):]) for node, line in list(self.lines)
                if node == CONTROLLER_NODE and line.startswith(self.COMMAND_TAKEN)]

    def wait_for_command_taken(self, value, taken_before, timeout=60):
        def taken():
            commands = self.commands_taken()
            return len(commands) > taken_before and abs(commands[-1] - value) < 1e-9
        self.wait_until(taken, timeout,
                        what='the controller to log that it took pos_cmd %g' % value)

    def wait_for_join(self, timeout=60):
        self.wait_until(lambda: any(node == '/gazebo' and line.startswith(self.JOINED)
                               for node, line in list(self.lines)), timeout,
                   what='the controller to join the lock-step')
