"""End-to-end tests of `rosrun onedof_sim plot` (the rqt_plot stand-in), headless.

The test process publishes known values; the plotter records them into a PNG and a CSV, which must
hold exactly what was published. Errors (a silent topic, an unknown topic or field) must end the
plotter with a non-zero status and a message naming the culprit.
"""
import threading

import pytest

from onedof_sim.tools.plot import read_csv
from onedof_sim.private_ros import wait_until

PLOT = ['rosrun', 'onedof_sim', 'plot']
PNG_MAGIC = b'\x89PNG\r\n\x1a\n'


def published_value(k):
    """The k-th value published on /test_value: not a round number, so a match is no accident."""
    return k * 0.37 + 1.0 / 3.0


class KnownPublisher:
    """Publishes /test_value (Float64) and /test_joint_states (JointState, stamped) at 50 Hz of
    ROS time, message k carrying values computed from k, until stopped."""

    def __init__(self, rospy):
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64
        self.rospy = rospy
        self.JointState, self.Float64 = JointState, Float64
        self.value = rospy.Publisher('/test_value', Float64, queue_size=100)
        self.states = rospy.Publisher('/test_joint_states', JointState, queue_size=100)
        self.stamps = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self):
        rate = self.rospy.Rate(50)
        k = 0
        while not self._stop.is_set():
            stamp = self.rospy.Time.now()
            self.value.publish(self.Float64(published_value(k)))
            self.states.publish(self.JointState(
                header=self._header(stamp), name=['a', 'b'],
                position=[-published_value(k), 2 * published_value(k)],
                velocity=[published_value(k) / 7.0, 0.0]))
            self.stamps.append(stamp.to_sec())
            k += 1
            rate.sleep()

    def _header(self, stamp):
        from std_msgs.msg import Header
        return Header(stamp=stamp)

    def stop(self):
        self._stop.set()
        self._thread.join(timeout=5)


@pytest.fixture
def publisher(rospy_client):
    pub = KnownPublisher(rospy_client)
    yield pub
    pub.stop()


def index_of_value(value):
    k = round((value - 1.0 / 3.0) / 0.37)
    assert published_value(k) == value, '%r was never published' % value
    return k


def test_records_what_was_published_into_png_and_csv(ros, publisher, tmp_path):
    png, csv_path = str(tmp_path / 'plot.png'), str(tmp_path / 'plot.csv')
    result = ros.run(PLOT + ['/test_value/data', '/test_joint_states/position[1]:velocity[0]',
                             '--duration', '2', '--png', png, '--csv', csv_path], timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr

    with open(png, 'rb') as f:
        assert f.read(8) == PNG_MAGIC
    series = read_csv(csv_path)
    assert list(series) == ['/test_value/data', '/test_joint_states/position[1]',
                            '/test_joint_states/velocity[0]']

    # /test_value: consecutive published values, in order, about 2 s at 50 Hz.
    times, values = series['/test_value/data']
    indices = [index_of_value(v) for v in values]
    assert indices == list(range(indices[0], indices[0] + len(indices)))
    assert 80 <= len(indices) <= 110

    # /test_joint_states: both fields of each message share a row and come from the same message;
    # its times are the header stamps, relative to the first sample.
    pos_times, positions = series['/test_joint_states/position[1]']
    vel_times, velocities = series['/test_joint_states/velocity[0]']
    assert pos_times == vel_times and len(positions) >= 80
    origin = min(times[0], pos_times[0])
    assert origin == 0.0
    ks = [index_of_value(p / 2) for p in positions]
    assert ks == list(range(ks[0], ks[0] + len(ks)))
    assert velocities == [published_value(k) / 7.0 for k in ks]
    stamps = [publisher.stamps[k] for k in ks]
    for t, stamp in zip(pos_times, stamps):
        assert t - pos_times[0] == pytest.approx(stamp - stamps[0], abs=1e-6)


def test_fails_clearly_on_a_topic_that_sends_nothing(ros, rospy_client, publisher, tmp_path):
    from std_msgs.msg import Float64
    rospy_client.Publisher('/silent', Float64, queue_size=1)
    wait_until(lambda: '/silent' in dict(ros.master().getPublishedTopics('/', '')[2]), 10,
               what='/silent to be registered')
    result = ros.run(PLOT + ['/test_value/data', '/silent/data', '--duration', '1',
                             '--png', str(tmp_path / 'p.png')], timeout=60)
    assert result.returncode != 0
    assert 'no message on /silent' in result.stderr
    assert '/test_value' not in result.stderr


def test_fails_clearly_on_an_unknown_topic(ros, publisher, tmp_path):
    result = ros.run(PLOT + ['/test_value/data', '/no_such_topic/data', '--timeout', '2',
                             '--duration', '1', '--csv', str(tmp_path / 'p.csv')], timeout=60)
    assert result.returncode != 0
    assert "no published topic matches /no_such_topic/data" in result.stderr


@pytest.mark.parametrize('spec, expected', [
    ('/test_value/dta', "std_msgs/Float64 has no field 'dta'; its fields: data"),
    ('/test_joint_states/positions[0]', "has no field 'positions'"),
    ('/test_joint_states/position', 'pick an element, e.g. position[0]'),
])
def test_fails_clearly_on_an_unknown_or_unplottable_field(ros, publisher, tmp_path, spec,
                                                           expected):
    result = ros.run(PLOT + [spec, '--duration', '1', '--png', str(tmp_path / 'p.png')],
                     timeout=60)
    assert result.returncode != 0
    assert spec in result.stderr and expected in result.stderr
    assert not (tmp_path / 'p.png').exists()
