"""Unit tests of the plot logic (no ROS graph needed)."""
import csv
import math

import genpy
import pytest
from geometry_msgs.msg import PoseArray, PoseStamped
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Bool, Float64, Header

from onedof_sim.tools.plot import (PlotError, SampleBuffer, expand_specs, field_accessor,
                                   header_stamp, held_window, make_figure,
                                   make_panels_figure, motion_span, parse_args,
                                   parse_field_path, plottable_paths, read_csv,
                                   settling_time, split_topic_field, step_path, unit_of,
                                   unit_panels, write_csv, write_figure)


def test_expand_specs_keeps_plain_specs():
    assert expand_specs(['/jnt_pos/data', '/jnt_trq/data']) == ['/jnt_pos/data', '/jnt_trq/data']


def test_expand_specs_colon_gives_several_fields_of_one_topic():
    assert expand_specs(['/pose/position/x:y:z']) == [
        '/pose/position/x', '/pose/position/y', '/pose/position/z']
    assert expand_specs(['/joint_states/position[0]:velocity[0]']) == [
        '/joint_states/position[0]', '/joint_states/velocity[0]']


def test_expand_specs_comma_separates_specs():
    assert expand_specs(['/a/data,/b/data', '/c/x']) == ['/a/data', '/b/data', '/c/x']


@pytest.mark.parametrize('bad', ['data:x', '/t/a:'])
def test_expand_specs_rejects_malformed_colon_shorthand(bad):
    with pytest.raises(PlotError, match='topic/field|empty field'):
        expand_specs([bad])


def test_split_takes_the_longest_published_topic_prefix():
    topics = ['/gazebo', '/gazebo/link_states', '/jnt_pos']
    assert split_topic_field('/gazebo/link_states/pose[1]/position/z', topics) == (
        '/gazebo/link_states', 'pose[1]/position/z')
    assert split_topic_field('/jnt_pos/data', topics) == ('/jnt_pos', 'data')
    assert split_topic_field('/jnt_pos', topics) == ('/jnt_pos', '')


def test_split_needs_a_whole_name_component():
    assert split_topic_field('/jnt_position/data', ['/jnt_pos']) is None
    assert split_topic_field('/other/data', ['/jnt_pos']) is None


def test_parse_field_path():
    assert parse_field_path('pose[12]/position/x') == [('pose', 12), ('position', None),
                                                       ('x', None)]
    assert parse_field_path('') == []


@pytest.mark.parametrize('bad', ['pose[]', 'pose[-1]', 'a//b', '1abc', 'pose[0]x'])
def test_parse_field_path_rejects_bad_syntax(bad):
    with pytest.raises(PlotError, match='bad field'):
        parse_field_path(bad)


def test_accessor_reads_scalars_array_elements_and_nested_fields():
    assert field_accessor(Float64, 'data')(Float64(2.5)) == 2.5
    state = JointState(name=['a', 'b'], position=[0.1, -0.7], velocity=[3.0, 4.0])
    assert field_accessor(JointState, 'position[1]')(state) == -0.7
    assert field_accessor(JointState, 'velocity[0]')(state) == 3.0
    pose = PoseStamped()
    pose.pose.position.z = 1.25
    assert field_accessor(PoseStamped, 'pose/position/z')(pose) == 1.25
    poses = PoseArray(poses=[PoseStamped().pose, pose.pose])
    assert field_accessor(PoseArray, 'poses[1]/position/z')(poses) == 1.25
    assert field_accessor(Bool, 'data')(Bool(True)) == 1.0


def test_accessor_reads_times_as_seconds_or_through_secs():
    clock = Clock(clock=genpy.Time(3, 500000000))
    assert field_accessor(Clock, 'clock')(clock) == 3.5
    assert field_accessor(Clock, 'clock/nsecs')(clock) == 500000000
    state = JointState(header=Header(stamp=genpy.Time(7, 0)))
    assert field_accessor(JointState, 'header/stamp')(state) == 7.0


def test_unknown_field_names_it_and_lists_the_valid_ones():
    with pytest.raises(PlotError) as error:
        field_accessor(Float64, 'value')
    assert "'value'" in str(error.value) and 'data' in str(error.value)
    with pytest.raises(PlotError) as error:
        field_accessor(JointState, 'positions[0]')
    message = str(error.value)
    assert "'positions'" in message
    for field in ('header', 'name', 'position', 'velocity', 'effort'):
        assert field in message
    with pytest.raises(PlotError, match="'w'.*x, y, z"):
        field_accessor(PoseStamped, 'pose/position/w')


@pytest.mark.parametrize('msg_class, path, pattern', [
    (JointState, 'position', r'array of float64: pick an element, e\.g\. position\[0\]'),
    (Float64, 'data[0]', 'not an array'),
    (JointState, 'name[0]', 'string, not a number'),
    (PoseStamped, 'pose/position', 'pick one of its fields: x, y, z'),
    (Float64, '', 'is a message: pick one of its fields: data'),
    (Float64, 'data/x', "has no field 'x'"),
])
def test_unplottable_paths_are_refused_with_a_reason(msg_class, path, pattern):
    with pytest.raises(PlotError, match=pattern):
        field_accessor(msg_class, path)


def test_a_message_stands_for_its_numeric_fields_as_in_rqt_plot():
    assert plottable_paths(Float64, '') == ['data']
    assert plottable_paths(PoseStamped, 'pose/position') == [
        'pose/position/x', 'pose/position/y', 'pose/position/z']
    # Arrays and strings are left out; a time is a number of seconds.
    assert plottable_paths(JointState, 'header') == ['header/seq', 'header/stamp']
    assert plottable_paths(Clock, '') == ['clock']
    assert plottable_paths(JointState, 'position[0]') == ['position[0]']


def test_a_message_without_numeric_fields_is_refused():
    with pytest.raises(PlotError, match='no numeric field to plot; its fields: header, name'):
        plottable_paths(JointState, '')
    with pytest.raises(PlotError, match="has no field 'positions'"):
        plottable_paths(JointState, 'positions[0]')


def test_accessor_raises_index_error_on_a_message_without_that_element():
    with pytest.raises(IndexError):
        field_accessor(JointState, 'position[2]')(JointState(position=[1.0]))


def test_header_stamp():
    assert header_stamp(Float64(1.0)) is None
    assert header_stamp(JointState()) is None  # zero stamp: use reception time
    assert header_stamp(JointState(header=Header(stamp=genpy.Time(2, 250000000)))) == 2.25


def test_buffer_times_are_relative_to_the_earliest_sample_of_any_label():
    buffer = SampleBuffer(['a', 'b'])
    buffer.append('b', 10.0, 1.0)
    buffer.append('a', 10.5, 2.0)
    buffer.append('b', 11.0, 3.0)
    assert buffer.series() == {'a': ([0.5], [2.0]), 'b': ([0.0, 1.0], [1.0, 3.0])}
    assert buffer.count('b') == 2
    # A header stamp older than what arrived before it moves the origin back.
    buffer.append('a', 9.75, 4.0)
    assert buffer.series() == {'a': ([0.75, 0.0], [2.0, 4.0]), 'b': ([0.25, 1.25], [1.0, 3.0])}


def test_buffer_series_until_a_time_leaves_out_what_came_after_it():
    buffer = SampleBuffer(['a'])
    for t in (10.0, 10.5, 11.0, 11.5):
        buffer.append('a', t, t * 2)
    assert buffer.series(until=11.0) == {'a': ([0.0, 0.5, 1.0], [20.0, 21.0, 22.0])}


def test_buffer_series_since_a_time_starts_there_at_zero():
    buffer = SampleBuffer(['a', 'b'])
    for t in (10.0, 10.5, 11.0, 11.5):
        buffer.append('a', t, t * 2)
    buffer.append('b', 10.75, 1.0)  # b's first sample: the recording covers both from here
    assert buffer.series(since=10.75, until=11.5) == {'a': ([0.25, 0.75], [22.0, 23.0]),
                                                      'b': ([0.0], [1.0])}


def test_buffer_is_bounded_and_keeps_the_newest_samples():
    buffer = SampleBuffer(['a'], maxlen=100)
    for i in range(10000):
        buffer.append('a', float(i), float(i) * 2)
    times, values = buffer.series()['a']
    assert len(times) == 100
    assert times[0] == 9900.0 and values[-1] == 19998.0


def test_csv_is_wide_with_shared_rows_for_one_topic_and_round_trips_exactly(tmp_path):
    series = {
        '/jnt_pos/data': ([0.0, 0.01, 0.02], [0.1, 1.0 / 3.0, math.pi]),
        '/jnt_vel/data': ([0.0, 0.01, 0.02], [-1e-300, 2.0, 3.0]),
        '/joint_states/position[0]': ([0.005, 0.015], [0.7, 0.8]),
    }
    path = str(tmp_path / 'samples.csv')
    write_csv(series, path)
    with open(path, newline='') as f:
        rows = list(csv.reader(f))
    assert rows[0] == ['time', '/jnt_pos/data', '/jnt_vel/data', '/joint_states/position[0]']
    assert [row[0] for row in rows[1:]] == ['0.0', '0.005', '0.01', '0.015', '0.02']
    assert rows[2] == ['0.005', '', '', '0.7']
    assert rows[3] == ['0.01', repr(1.0 / 3.0), '2.0', '']
    assert read_csv(path) == series


def test_csv_keeps_samples_that_share_a_time(tmp_path):
    series = {'a': ([1.0, 1.0, 2.0], [5.0, 6.0, 7.0])}
    write_csv(series, str(tmp_path / 's.csv'))
    assert read_csv(str(tmp_path / 's.csv')) == series


def test_a_value_published_once_is_held_up_to_now():
    assert step_path([2.0], [1.0], until=7.5) == ([2.0, 7.5], [1.0, 1.0])


def test_two_commands_are_a_step_not_a_ramp():
    xs, ys = step_path([1.0, 4.0], [1.0, 2.0], until=6.0)
    assert list(zip(xs, ys)) == [(1.0, 1.0), (4.0, 1.0), (4.0, 2.0), (6.0, 2.0)]
    # Between two samples the drawn line is flat: no vertex lies between the old and new value
    # away from the jump's time.
    assert all(y in (1.0, 2.0) for y in ys)
    assert all(x == 4.0 for x, y, y_next in zip(xs, ys, ys[1:]) if y != y_next)


def test_step_path_without_until_or_samples():
    assert step_path([0.0, 1.0], [5.0, 6.0]) == ([0.0, 1.0, 1.0], [5.0, 5.0, 6.0])
    assert step_path([], [], until=3.0) == ([], [])
    # `until` before the last sample (a header stamp from the future) draws nothing extra.
    assert step_path([0.0, 2.0], [5.0, 6.0], until=1.0) == ([0.0, 2.0, 2.0], [5.0, 5.0, 6.0])


def test_held_window_leads_with_the_value_held_at_its_start():
    times, values = [0.0, 1.0, 5.0, 9.0], [10.0, 11.0, 12.0, 13.0]
    assert held_window(times, values, 3.0, 9.0) == ([3.0, 5.0], [11.0, 12.0])
    # A sample right at the start needs no held value before it.
    assert held_window(times, values, 5.0, 9.0) == ([5.0], [12.0])
    # Nothing inside: the held value alone, so the window still shows the command.
    assert held_window(times, values, 6.0, 8.0) == ([6.0], [12.0])
    assert held_window(times, values, -5.0, -1.0) == ([], [])
    assert held_window(times, values, -math.inf, math.inf) == (times, values)


def test_figure_has_one_line_per_label_with_the_data_held(tmp_path):
    series = {'/a/data': ([0.0, 1.0, 2.0], [1.0, 4.0, 9.0]), '/b/data': ([0.5], [-1.0])}
    figure = make_figure(series, title='phase 1', ylabel='rad', until=3.0)
    ax = figure.axes[0]
    assert [line.get_label() for line in ax.lines] == ['/a/data', '/b/data']
    assert list(ax.lines[0].get_xdata()) == [0.0, 1.0, 1.0, 2.0, 2.0, 3.0]
    assert list(ax.lines[0].get_ydata()) == [1.0, 1.0, 4.0, 4.0, 9.0, 9.0]
    assert list(ax.lines[1].get_xdata()) == [0.5, 3.0]
    assert list(ax.lines[1].get_ydata()) == [-1.0, -1.0]
    assert ax.get_title() == 'phase 1' and ax.get_xlabel() == 'ROS time since the first sample [s]'

    png = tmp_path / 'plot.png'
    write_figure(series, str(png), title='phase 1', xlabel='sim time (s)')
    data = png.read_bytes()
    assert data[:8] == b'\x89PNG\r\n\x1a\n' and len(data) > 5000


def test_panels_figure_stacks_its_panels_on_one_time_axis():
    angles = {'q': ([0.0, 1.0], [0.5, 1.0])}
    torques = {'u': ([0.0], [2.0]), 'v': ([0.0], [3.0])}
    figure = make_panels_figure([('rad', angles), ('N m', torques)], title='both',
                                xlabel='sim time (s)', until=2.0)
    top, bottom = figure.axes
    assert [line.get_label() for line in top.lines] == ['q']
    assert [line.get_label() for line in bottom.lines] == ['u', 'v']
    assert (top.get_title(), top.get_xlabel(), top.get_ylabel()) == ('both', '', 'rad')
    assert (bottom.get_title(), bottom.get_xlabel()) == ('', 'sim time (s)')
    assert list(bottom.lines[0].get_xdata()) == [0.0, 2.0]
    assert top.get_shared_x_axes().joined(top, bottom)


def approach(final, time_constant, duration=40.0, period=0.05, start=0.0):
    """Samples of an exponential step from `start` to `final`: settled within 5 % of the step
    after time_constant * ln 20."""
    times = [i * period for i in range(int(round(duration / period)) + 1)]
    return times, [final + (start - final) * math.exp(-t / time_constant) for t in times]


@pytest.mark.parametrize('label, ylabel', [
    ('/jnt_pos/data', 'angle (rad)'), ('/pos_cmd', 'angle (rad)'), ('pos_cmd', 'angle (rad)'),
    ('/jnt_vel/data', 'rate (rad/s)'), ('/ns/jnt_trq/data', 'torque (N m)'),
    ('rospy PD jnt_trq', 'torque (N m)'), ('/jnt_position/data', None),
    ('/joint_states/effort[0]', None),
])
def test_the_unit_comes_from_a_name_in_the_label(label, ylabel):
    assert unit_of(label) == ylabel


def test_series_of_one_unit_share_a_panel_and_an_unknown_one_gets_its_own():
    q, v, u, z = ([0.0], [1.0]), ([0.0], [2.0]), ([0.0], [3.0]), ([0.0], [4.0])
    series = {'/jnt_pos/data': q, '/jnt_trq/data': u, '/link/z': z, '/jnt_vel/data': v,
              '/pos_cmd/data': q}
    assert unit_panels(series) == [
        ('angle (rad)', {'/jnt_pos/data': q, '/pos_cmd/data': q}),
        ('torque (N m)', {'/jnt_trq/data': u}), ('/link/z', {'/link/z': z}),
        ('rate (rad/s)', {'/jnt_vel/data': v})]


def test_the_tutorial_figure_has_a_panel_per_unit_on_one_labelled_time_axis():
    series = {'pos_cmd': ([0.0], [1.0]), 'jnt_pos': approach(1.49, 0.3, 5.0),
              'jnt_vel': ([0.0, 1.0], [2.0, 0.0]), 'jnt_trq': approach(-4.9, 0.3, 5.0, start=10.0)}
    figure = make_figure(series, title='phase 1', xlabel='sim time since the command (s)',
                         until=5.0)
    angle, rate, torque = figure.axes
    assert [ax.get_ylabel() for ax in figure.axes] == [
        'angle (rad)', 'rate (rad/s)', 'torque (N m)']
    assert [line.get_label() for line in angle.lines] == ['pos_cmd', 'jnt_pos']
    assert [line.get_label() for line in rate.lines] == ['jnt_vel']
    assert [line.get_label() for line in torque.lines] == ['jnt_trq']
    assert [ax.get_xlabel() for ax in figure.axes] == ['', '', 'sim time since the command (s)']
    assert angle.get_title() == 'phase 1'
    assert angle.get_shared_x_axes().joined(angle, rate)
    assert angle.get_shared_x_axes().joined(angle, torque)


def test_a_field_of_unknown_unit_is_a_panel_labelled_with_its_name():
    figure = make_figure({'/jnt_pos/data': ([0.0], [1.0]),
                          '/joint_states/effort[0]': ([0.0], [2.0])})
    assert [ax.get_ylabel() for ax in figure.axes] == ['angle (rad)', '/joint_states/effort[0]']
    assert figure.axes[1].get_xlabel() == 'ROS time since the first sample [s]'


def test_settling_time_is_the_last_sample_outside_the_band():
    times, values = [0.0, 1.0, 2.0, 3.0, 4.0], [0.0, 1.5, 0.85, 1.05, 1.0]
    assert settling_time(times, values, 0.1) == 2.0
    assert settling_time(times, values, 0.01) == 3.0
    assert settling_time(times, values, 2.0) == 0.0
    assert settling_time([], [], 0.1) is None


def test_the_motion_span_runs_until_the_slowest_series_settles_with_a_margin():
    fast, slow = approach(1.49, 0.2), approach(1.0, 2.0)
    start, end = motion_span({'fast': fast, 'slow': slow, 'command': ([0.0], [1.0])})
    # The slow one is within 5 % of its step from 2 ln 20 = 6.0 s on (its last sample outside
    # the band is the one before); a quarter more is margin.
    slow_settled = 2.0 * math.log(20)
    assert start == 0.0
    assert (slow_settled - 0.05) * 1.25 <= end <= slow_settled * 1.25
    assert motion_span({'slow': slow, 'fast': fast}) == (start, end)
    assert motion_span({'fast': fast})[1] < 1.0
    assert motion_span({'command': ([0.0], [1.0])}) is None
    assert motion_span({}) is None


def test_a_zoomed_figure_shows_where_the_series_move_and_the_whole_run_below():
    angles = {'pd': approach(1.49, 0.2, 5.0), 'pid': approach(1.0, 2.0), 'cmd': ([0.0], [1.0])}
    torques = {'pd': approach(-4.9, 0.2, 5.0, start=10.0), 'pid': approach(-4.1, 2.0, start=10.0)}
    figure = make_panels_figure([('angle (rad)', angles), ('torque (N m)', torques)],
                                title='zoomed', xlabel='t (s)', until=40.0, zoom=True)
    angle, torque, whole_run = figure.axes
    span = motion_span(dict(angles, **{'trq ' + k: v for k, v in torques.items()}))
    assert 5.9 * 1.25 < span[1] < 10.0
    assert angle.get_xlim() == pytest.approx(span) and torque.get_xlim() == pytest.approx(span)
    assert (angle.get_ylabel(), torque.get_ylabel()) == ('angle (rad)', 'torque (N m)')
    assert (torque.get_xlabel(), whole_run.get_xlabel()) == ('t (s)', 't (s)')
    # Below, smaller: the first panel's series over the whole run, the zoomed span shaded.
    assert whole_run.get_ylabel() == 'angle (rad)'
    assert [line.get_label() for line in whole_run.lines] == ['pd', 'pid', 'cmd']
    low, high = whole_run.get_xlim()
    assert low <= 0.0 and high >= 40.0
    assert whole_run.get_position().height < angle.get_position().height
    shaded = whole_run.patches[0].get_xy()
    assert min(x for x, _ in shaded) == pytest.approx(span[0])
    assert max(x for x, _ in shaded) == pytest.approx(span[1])


def test_a_figure_that_moves_until_its_end_is_not_zoomed():
    angles = {'slow': approach(1.0, 20.0)}
    figure = make_panels_figure([('angle (rad)', angles)], until=40.0, zoom=True)
    assert len(figure.axes) == 1
    low, high = figure.axes[0].get_xlim()
    assert low <= 0.0 and high >= 40.0


@pytest.mark.parametrize('argv, message', [
    (['/a/data', '--png', 'x.png'], '--duration'),
    (['/a/data', '--csv', 'x.csv', '--duration', '0'], '--duration'),
    (['/a/data', '--duration', '3'], '--png'),
    (['/a/data', '--png', 'x.png', '--duration', '1', '--timeout', '0'], '--timeout'),
])
def test_argument_errors(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        parse_args(argv)
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err


def test_rqt_plot_help_says_what_stands_in(capsys):
    with pytest.raises(SystemExit) as exit_info:
        parse_args(['-h'], prog='rqt_plot')
    assert exit_info.value.code == 0
    text = ' '.join(capsys.readouterr().out.split())
    assert text.startswith('usage: rqt_plot')
    assert "This workspace's plotter (rosrun onedof_sim plot) standing in for rqt_plot" in text


def test_rqt_plot_options():
    args, headless = parse_args(['-P', '-e', '/pos_cmd'], prog='rqt_plot')
    assert args.start_paused and args.start_empty and args.fields == ['/pos_cmd']
    assert not headless


def test_headless_arguments():
    args, headless = parse_args(['/a/data:b', '--duration', '2', '--csv', 'x.csv'])
    assert headless and args.duration == 2.0 and args.fields == ['/a/data:b']
    assert parse_args(['/a/data'])[1] is False
