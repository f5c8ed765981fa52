"""End-to-end tests of `rosrun onedof_sim plot` and of `rqt_plot` (the same plotter under rqt_plot's
name, on PATH after sourcing devel/setup.bash), headless and in a live window on a private Xvfb.

The test process publishes known values; the plotter records them into a PNG and a CSV, which must
hold exactly what was published. A command published once must be drawn held (a horizontal line up
to now, then a step to the next command), checked in the pixels. Errors (a silent topic, an unknown
topic or field) must end the plotter with a non-zero status and a message naming the culprit.
"""
import os
import signal
import subprocess
import threading

import pytest

from onedof_harness.private_ros import wait_until
from onedof_sim.tools.plot import read_csv
from onedof_sim.tutorial.rviz_view import start_xvfb

PLOT = ['rosrun', 'onedof_sim', 'plot']
RQT_PLOT_COMMANDS = [PLOT, ['rqt_plot'], ['rosrun', 'rqt_plot', 'rqt_plot']]
PNG_MAGIC = b'\x89PNG\r\n\x1a\n'
# Only a guard against a hang: the plotter's start-up (Python, rospy, matplotlib) takes over a
# minute on a machine as busy as make test-under-load makes it.
CLI_TIMEOUT = 300


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


@pytest.mark.parametrize('command', RQT_PLOT_COMMANDS, ids=' '.join)
def test_records_what_was_published_into_png_and_csv(ros, publisher, tmp_path, command):
    png, csv_path = str(tmp_path / 'plot.png'), str(tmp_path / 'plot.csv')
    result = ros.run(command + ['/test_value/data', '/test_joint_states/position[1]:velocity[0]',
                             '--duration', '2', '--png', png, '--csv', csv_path],
                     timeout=CLI_TIMEOUT)
    assert result.returncode == 0, result.stdout + result.stderr

    with open(png, 'rb') as f:
        assert f.read(8) == PNG_MAGIC
    series = read_csv(csv_path)
    assert list(series) == ['/test_value/data', '/test_joint_states/position[1]',
                            '/test_joint_states/velocity[0]']

    # /test_value: consecutive published values, in order, none dropped; at most 2 s at 50 Hz
    # (fewer when a busy machine makes the publisher late: it publishes at 50 Hz at best).
    times, values = series['/test_value/data']
    indices = [index_of_value(v) for v in values]
    assert indices == list(range(indices[0], indices[0] + len(indices)))
    assert 10 <= len(indices) <= 110

    # /test_joint_states: both fields of each message share a row and come from the same message;
    # its times are the header stamps, relative to the first sample.
    pos_times, positions = series['/test_joint_states/position[1]']
    vel_times, velocities = series['/test_joint_states/velocity[0]']
    assert pos_times == vel_times and len(positions) >= 10
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
                             '--png', str(tmp_path / 'p.png')], timeout=CLI_TIMEOUT)
    assert result.returncode != 0
    assert 'no message on /silent' in result.stderr
    assert '/test_value' not in result.stderr


def test_under_sim_time_waits_for_the_clock_and_says_when_none_comes(ros, publisher, tmp_path):
    # /test_value is published, but with /use_sim_time set and no /clock no sample has a time.
    ros.set_param('/use_sim_time', True)
    result = ros.run(PLOT + ['/test_value/data', '--timeout', '2', '--duration', '1',
                             '--csv', str(tmp_path / 'p.csv')], timeout=CLI_TIMEOUT)
    assert result.returncode != 0
    assert 'no /clock message came in 2 s' in result.stderr
    assert not os.path.exists(str(tmp_path / 'p.csv'))


def test_fails_clearly_on_an_unknown_topic(ros, publisher, tmp_path):
    result = ros.run(PLOT + ['/test_value/data', '/no_such_topic/data', '--timeout', '2',
                             '--duration', '1', '--csv', str(tmp_path / 'p.csv')],
                     timeout=CLI_TIMEOUT)
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
                     timeout=CLI_TIMEOUT)
    assert result.returncode != 0
    assert spec in result.stderr and expected in result.stderr
    assert not (tmp_path / 'p.png').exists()


def test_rqt_plot_is_on_path_and_says_what_it_is(ros):
    result = ros.run(['rqt_plot', '-h'])
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith('usage: rqt_plot')
    assert "plotter (rosrun onedof_sim plot) standing in for rqt_plot" in \
        ' '.join(result.stdout.split())


# ---- a command published once is drawn held: the pixels of the figure ----

# matplotlib's first line colour (C0, #1f77b4) and how far an antialiased pixel of it may stray.
LINE_RGB = (31, 119, 180)
# A horizontal run of the line at least this long (px) is a held value; the legend's sample of the
# line is about 40 px.
HELD_RUN = 150


def held_lines(png):
    """{row: (first, last) column} of the rows of `png` where the line colour runs for HELD_RUN
    pixels or more (short interruptions by grid lines allowed)."""
    import matplotlib.image
    import numpy
    image = matplotlib.image.imread(str(png))
    if image.ndim < 3:  # saved grey (a screen without the window yet): no line of its colour
        return {}
    rgb = (image[..., :3] * 255).round()
    is_line = (numpy.abs(rgb - numpy.array(LINE_RGB)) < 40).all(axis=2)
    rows = {}
    for row in numpy.flatnonzero(is_line.sum(axis=1) >= HELD_RUN):
        columns = numpy.flatnonzero(is_line[row])
        rows[int(row)] = (int(columns[0]), int(columns[-1]))
    return rows


def a_step_up(png):
    """(lower, upper) held lines if `png` shows one held value, then a higher one from where the
    first ends on to the right (a step, not a ramp or lone points); None otherwise."""
    rows = held_lines(png)
    if not rows:
        return None
    lower, upper = rows[max(rows)], rows[min(rows)]  # image rows grow downwards
    if max(rows) - min(rows) < 50:  # one level only
        return None
    jump_close = abs(upper[0] - lower[1]) <= 3
    return (lower, upper) if jump_close and lower[0] < upper[0] - HELD_RUN else None


class CommandPublisher:
    """Publishes /pos_cmd (std_msgs/Float64) latched, once per call, as `rostopic pub` does."""

    def __init__(self, rospy):
        from std_msgs.msg import Float64
        self.rospy, self.Float64 = rospy, Float64
        self.publisher = rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)

    def publish(self, value):
        self.publisher.publish(self.Float64(value))

    def wait_for_subscriber(self, proc, ros):
        wait_until(lambda: proc.poll() is not None or self.publisher.get_num_connections(), 60,
                   what='the plotter to subscribe to /pos_cmd')
        assert proc.poll() is None, ros.log_text(proc)

    def wait_ros_time(self, seconds):
        end = self.rospy.get_time() + seconds
        wait_until(lambda: self.rospy.get_time() >= end, seconds * 10 + 10,
                   what='%g s of ROS time' % seconds)


def test_headless_draws_a_command_published_once_as_held_values(ros, rospy_client, tmp_path):
    png, csv_path = tmp_path / 'cmd.png', tmp_path / 'cmd.csv'
    command = CommandPublisher(rospy_client)
    command.publish(1.0)
    proc = ros.start(['rqt_plot', '/pos_cmd', '--duration', '4', '--png', str(png),
                      '--csv', str(csv_path)], name='rqt_plot')
    command.wait_for_subscriber(proc, ros)
    command.wait_ros_time(1.5)
    command.publish(2.0)
    assert proc.wait(timeout=CLI_TIMEOUT) == 0, ros.log_text(proc)

    # The CSV holds what was published: each value once.
    assert read_csv(str(csv_path))['/pos_cmd/data'][1] == [1.0, 2.0]
    step = a_step_up(png)
    assert step, 'no held 1.0 then 2.0 in the figure; held lines by row: %s' % held_lines(png)
    (_, lower_end), (_, upper_end) = step
    # 2.0 came about 1.5 s into 4 s: it is held for the longer part of the figure, to its end.
    assert upper_end - lower_end > lower_end - step[0][0]


def test_live_window_draws_a_command_published_once_as_a_step(ros, rospy_client, tmp_path):
    xvfb, display = start_xvfb(ros, '1000x700x24')
    command = CommandPublisher(rospy_client)
    command.publish(1.0)
    proc = ros.start(['rqt_plot', '/pos_cmd/data'], name='rqt_plot', env={'DISPLAY': display})
    command.wait_for_subscriber(proc, ros)
    shot = tmp_path / 'window.png'

    def grabbed():
        assert proc.poll() is None, ros.log_text(proc)
        return subprocess.run(['import', '-display', display, '-window', 'root', str(shot)],
                              capture_output=True).returncode == 0

    # The time axis grows with the run: 1.0 is drawn held before 2.0 comes, so that however
    # long the window took to come up, 1.0's line is as long as that and stays in sight.
    wait_until(lambda: grabbed() and held_lines(shot), 120, interval=0.5,
               what='the live window to show 1.0 held')
    command.wait_ros_time(1.5)
    command.publish(2.0)

    def window_shows_the_step():
        if not grabbed():
            return None
        step = a_step_up(shot)
        # Held "up to now": 2.0 has been held longer than 1.0 was, on the live time axis.
        return step and step[1][1] - step[1][0] > step[0][1] - step[0][0]

    wait_until(window_shows_the_step, 60, interval=0.5,
               what='the live window to show 1.0 held, then 2.0 held up to now')
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C in its terminal closes the window
    assert proc.wait(timeout=30) == 130, ros.log_text(proc)
