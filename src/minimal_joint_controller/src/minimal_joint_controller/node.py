"""The ROS side of minimal_joint_controller: reads the joint through the simulator's
get_joint_properties, applies the PD torque through apply_joint_effort, at a fixed rate of ROS time.

Beyond the tutorial's node it survives the simulator going away (it waits and reconnects), a joint
that does not exist yet (it warns and retries), a non-finite command (ignored) and ROS time jumping
back (reset_simulation, a restarted simulator).
"""
import math
import time

import rospy
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from gazebo_msgs.srv import ApplyJointEffort, GetJointProperties

from minimal_joint_controller.control_law import pd_torque

GET_JOINT_PROPERTIES = '/gazebo/get_joint_properties'
APPLY_JOINT_EFFORT = '/gazebo/apply_joint_effort'
# Seconds (ROS time) between two repeats of the same warning while a condition lasts.
WARN_PERIOD = 5.0
# Wall seconds between checks for shutdown while waiting for the simulator's services.
SERVICE_WAIT_SLICE = 1.0
# Wall seconds between checks for the first /clock.
CLOCK_WAIT_SLICE = 0.005
# Errors of a service call whose cause is the connection (simulator gone or restarted).
CONNECTION_ERRORS = (rospy.ServiceException, rospy.exceptions.TransportException, OSError)


def wait_until_time(target, jumped_back_before):
    """Waits until ROS time reaches `target`; returns the time then, or at once the time earlier
    than `jumped_back_before` when time jumped back (reset_simulation, a restarted simulator), even
    if it jumped before this call: a reset while the last period's calls were under way.

    rospy.Rate cannot be used here: it reads the time, then rospy.sleep reads it again and
    sleeps a whole remainder from the second reading, so a clock that moves in between puts
    the wake-up past the period (and past the end of the effort job a lock-stepped simulator
    waits at); and it checks the time outside the clock's condition, so a clock message can slip
    by unnoticed for half a second. Here the time is read under the condition the clock
    callback notifies."""
    if rospy.rostime.is_wallclock():
        rospy.sleep(target - rospy.Time.now())
        return rospy.Time.now()
    condition = rospy.rostime.get_rostime_cond()
    with condition:
        while not rospy.is_shutdown():
            now = rospy.Time.now()
            if now >= target or now < jumped_back_before:
                return now
            condition.wait(1.0)
    raise rospy.ROSInterruptException('shutdown while waiting for the next period')


def next_tick(tick, period, now):
    """The next period's start, given the time `now` the loop woke for the one after `tick`: a
    period after `tick`, or `now` when time jumped back or the loop fell a whole period behind (a
    free-running simulator outpacing it). Never a whole period before `now`: the period after it
    would start at `now` again, and a lock-stepped world stands still there, so the loop would
    act twice at one time."""
    upcoming = tick + period
    if now < tick or now - upcoming >= period:
        return now
    return upcoming


class ParameterError(ValueError):
    pass


def read_parameters():
    """The private parameters, the tutorial's values by default; ParameterError if one is unusable."""
    params = {
        'joint_name': rospy.get_param('~joint_name', 'joint1'),
        'kp': rospy.get_param('~kp', 10.0),
        'kv': rospy.get_param('~kv', 3.0),
        'rate': rospy.get_param('~rate', 100.0),
        'torque_limit': rospy.get_param('~torque_limit', None),
    }
    if not isinstance(params['joint_name'], str) or not params['joint_name']:
        raise ParameterError('~joint_name must be a non-empty string, got %r' % params['joint_name'])
    for name in ('kp', 'kv', 'rate', 'torque_limit'):
        value = params[name]
        if value is None and name == 'torque_limit':
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ParameterError('~%s must be a finite number, got %r' % (name, value))
        params[name] = float(value)
    if params['rate'] <= 0:
        raise ParameterError('~rate must be > 0 Hz, got %r' % params['rate'])
    if params['torque_limit'] is not None and params['torque_limit'] <= 0:
        raise ParameterError('~torque_limit must be > 0, got %r' % params['torque_limit'])
    return params


class MinimalJointController:
    def __init__(self, joint_name='joint1', kp=10.0, kv=3.0, rate=100.0, torque_limit=None):
        self.joint_name = joint_name
        self.kp = kp
        self.kv = kv
        self.rate = rate
        self.torque_limit = torque_limit
        self.period = rospy.Duration.from_sec(1.0 / rate)
        self.pos_cmd = 0.0
        self._get_properties = None
        self._apply_effort = None
        # A lock-stepped simulator runs as fast as this loop: ten periods per wall millisecond
        # at times. A second of samples queued per subscriber keeps a busy subscriber (a
        # recorder, rqt_plot) from losing any.
        queue = int(max(rate, 1000))
        self._pos_pub = rospy.Publisher('jnt_pos', Float64, queue_size=queue)
        self._vel_pub = rospy.Publisher('jnt_vel', Float64, queue_size=queue)
        self._trq_pub = rospy.Publisher('jnt_trq', Float64, queue_size=queue)
        self._joint_state_pub = rospy.Publisher('joint_states', JointState, queue_size=queue)
        self._cmd_sub = rospy.Subscriber('pos_cmd', Float64, self._on_pos_cmd, queue_size=10)

    def _on_pos_cmd(self, msg):
        if not math.isfinite(msg.data):
            rospy.logwarn('ignoring pos_cmd %r: not a finite angle; keeping the command %g',
                          msg.data, self.pos_cmd)
            return
        self.pos_cmd = msg.data
        # The book's controller prints this line; it also tells a script driving the simulator
        # step by step (on /rosout) that the command is in before the next period.
        rospy.loginfo('received value of pos_cmd is: %f', msg.data)

    def run(self):
        """Controls until shutdown (rospy.ROSInterruptException then)."""
        # Sim time is 0 until the first /clock: a rate started then would keep a grid of periods
        # from 0 while its first sleep counts from the first time seen, and the periods would
        # not start where the commanded efforts end (what a lock-stepped simulator waits at).
        while rospy.Time.now().is_zero():
            if rospy.is_shutdown():
                raise rospy.ROSInterruptException('shutdown before the first /clock')
            time.sleep(CLOCK_WAIT_SLICE)
        tick = rospy.Time.now()
        while not rospy.is_shutdown():
            if self._get_properties is None:
                self._connect()
            self.control_once()
            tick = next_tick(tick, self.period, wait_until_time(tick + self.period, tick))

    def _connect(self):
        """Waits for both services and opens persistent connections to them."""
        for name in (GET_JOINT_PROPERTIES, APPLY_JOINT_EFFORT):
            waited = False
            while True:
                try:
                    rospy.wait_for_service(name, timeout=SERVICE_WAIT_SLICE)
                    break
                except rospy.ROSException:
                    if rospy.is_shutdown():
                        raise rospy.ROSInterruptException('shutdown while waiting for ' + name)
                    if not waited:
                        rospy.loginfo('waiting for %s (is the simulator running?)', name)
                        waited = True
        # Persistent: one TCP connection per service for the node's life instead of one per call,
        # which matters at 200 calls a second.
        self._get_properties = rospy.ServiceProxy(GET_JOINT_PROPERTIES, GetJointProperties,
                                                  persistent=True)
        self._apply_effort = rospy.ServiceProxy(APPLY_JOINT_EFFORT, ApplyJointEffort,
                                                persistent=True)
        rospy.loginfo('connected to %s and %s; controlling %s at %g Hz',
                      GET_JOINT_PROPERTIES, APPLY_JOINT_EFFORT, self.joint_name, self.rate)

    def _disconnect(self, error):
        rospy.logwarn('lost the simulator (%s); waiting for it to come back', error)
        for proxy in (self._get_properties, self._apply_effort):
            proxy.close()
        self._get_properties = self._apply_effort = None

    def control_once(self):
        """One period: read the joint, publish its state, compute and apply the torque. Publishes
        nothing when the joint cannot be read."""
        try:
            props = self._get_properties(self.joint_name)
        except CONNECTION_ERRORS as error:
            self._disconnect(error)
            return
        if not props.success or not props.position or not props.rate:
            rospy.logwarn_throttle(WARN_PERIOD, 'cannot read joint %s: %s; retrying',
                                   self.joint_name, props.status_message or 'no position')
            return
        now = rospy.Time.now()
        position, rate = props.position[0], props.rate[0]
        torque = pd_torque(self.pos_cmd, position, rate, self.kp, self.kv, self.torque_limit)

        self._pos_pub.publish(Float64(position))
        self._vel_pub.publish(Float64(rate))
        # Stamped with the sample's sim time, and with the torque commanded for the period: the
        # one topic that says when each sample was taken (the Float64 topics cannot).
        joint_state = JointState(name=[self.joint_name], position=[position], velocity=[rate],
                                 effort=[torque])
        joint_state.header.stamp = now
        self._joint_state_pub.publish(joint_state)
        self._trq_pub.publish(Float64(torque))

        try:
            result = self._apply_effort(self.joint_name, torque, now, self.period)
        except CONNECTION_ERRORS as error:
            self._disconnect(error)
            return
        if not result.success:
            rospy.logwarn_throttle(WARN_PERIOD, 'apply_joint_effort on %s refused: %s',
                                   self.joint_name, result.status_message)


USAGE = '''usage: rosrun minimal_joint_controller minimal_joint_controller [_kp:=10] [_kv:=3]
       [_rate:=100] [_joint_name:=joint1] [_torque_limit:=N] [name remappings]

The tutorial's PD joint controller: reads the joint through /gazebo/get_joint_properties, applies
Kp * wrap(pos_cmd - q) - Kv * rate through /gazebo/apply_joint_effort for one period, at _rate Hz of
ROS time; listens on pos_cmd, publishes jnt_pos, jnt_vel, jnt_trq and joint_states (stamped, with the torque
as effort).'''


def main():
    if {'-h', '--help'} & set(rospy.myargv()[1:]):
        print(USAGE)
        return 0
    rospy.init_node('minimal_joint_controller')
    try:
        params = read_parameters()
    except ParameterError as error:
        rospy.logfatal(str(error))
        return 2
    controller = MinimalJointController(**params)
    try:
        controller.run()
    except rospy.ROSInterruptException:
        pass
    return 0
