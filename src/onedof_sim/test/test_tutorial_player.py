"""The tutorial player's plain pieces: samples from the controllers' messages, the newest sample of
a step, the simulator's bus statistics, the summary, the compared figure's series and zoom, and
the outputs a run clears."""
import math
import types

import pytest

from onedof_sim.tools import plot
from onedof_sim.tutorial import phases, physics, player, recorders, runs, summary

BOOK_GAINS = {'p': 10.0, 'i': 10.0, 'd': 10.0, 'i_clamp_min': -10.0, 'i_clamp_max': 10.0}
COMMAND_1 = phases.PHASES[0]


def stamp(seconds):
    return types.SimpleNamespace(to_sec=lambda: seconds)


def test_joint_state_samples_take_the_joint_at_the_stamp():
    msg = types.SimpleNamespace(name=['other', 'joint1'], position=[9.0, 1.5],
                                velocity=[9.0, 0.25], effort=[9.0, -3.0],
                                header=types.SimpleNamespace(stamp=stamp(2.5)))
    assert recorders.joint_state_samples(msg) == [('jnt_pos', 2.5, 1.5), ('jnt_vel', 2.5, 0.25),
                                                  ('jnt_trq', 2.5, -3.0)]
    msg.name = ['other']
    assert recorders.joint_state_samples(msg) == []


def test_controller_state_samples_are_process_value_rate_and_command():
    msg = types.SimpleNamespace(process_value=0.9, process_value_dot=0.1, command=4.2,
                                set_point=1.0, header=types.SimpleNamespace(stamp=stamp(1.0)))
    assert recorders.controller_state_samples(msg) == [('jnt_pos', 1.0, 0.9),
                                                       ('jnt_vel', 1.0, 0.1),
                                                       ('jnt_trq', 1.0, 4.2)]


def test_recorder_keeps_what_it_is_given_by_topic():
    recorder = recorders.Recorder()
    recorder.command(0.0, 1.0)
    recorder.add([('jnt_pos', 0.01, 0.5), ('jnt_trq', 0.01, 2.0)])
    recorder.add([('jnt_pos', 0.02, 0.6)])
    assert recorder.latest() == 0.02
    assert recorder.between('jnt_pos', 0.0, 0.02) == [(0.01, 0.5)]
    assert recorder.series(0.0, 1.0)['pos_cmd'] == ([0.0], [1.0])


def test_newest_sample_of_step_ignores_older_and_later_states():
    states = [(10, 'a'), (30, 'c'), (20, 'b'), (40, 'd')]
    assert runs.newest_sample_of_step(states, 10, 30) == (30, 'c')
    assert runs.newest_sample_of_step(states, 40, 60) is None


def test_bus_messages_received_sums_the_topics_connections():
    stats = [[['/out', [[1, 100, 7, True]]]],
             [['/cmd', [[2, 80, 3, 0, 0], [3, 40, 2, 0, 0]]], ['/other', [[4, 10, 9, 0, 0]]]]]
    assert runs.bus_messages_received(stats, '/cmd') == 5
    assert runs.bus_messages_received(stats, '/none') == 0


def test_phase_summary_refuses_a_lost_sample():
    recorder = recorders.Recorder()
    recorder.add([('jnt_pos', t / 100, 1.0) for t in range(10)] +
                 [('jnt_trq', t / 100, 0.0) for t in range(10)])
    row = summary.phase_summary(COMMAND_1, recorder, 0.0, 0.1, expected_samples=10,
                                predict=physics.pid_prediction(BOOK_GAINS))
    assert (row['settled'], row['predicted'], row['samples']) == (1.0, 1.0, 10)
    with pytest.raises(RuntimeError, match='9 samples'):
        summary.phase_summary(COMMAND_1, recorder, 0.0, 0.09, expected_samples=10)


def test_summary_shows_the_in_sim_rows_under_the_pd_rows():
    row = dict(name='command_1.0', command=1.0, settled=1.49, predicted=1.49, overshoot=0.0,
               settling_time=1.0, holding_torque=-4.9, predicted_torque=-4.9, met_table='')
    text = summary.summary_markdown([row], 'ode', in_sim_rows=[dict(row, settled=1.0)])
    pd_part, pid_part = text.split('in-simulator PID')
    assert '| 1.4900 |' in pd_part and '| 1.0000 |' in pid_part
    assert 'in-simulator' not in summary.summary_markdown([row], 'ode')


def test_compared_panels_put_positions_above_torques_by_controller():
    pd = {topic: ([0.0], [1.0]) for topic in recorders.RECORDED_TOPICS}
    pid = {topic: ([0.0], [2.0]) for topic in recorders.RECORDED_TOPICS}
    (angle_label, angles), (torque_label, torques) = player.compared_panels(pd, pid)
    assert set(angles) == {'pos_cmd', 'rospy PD jnt_pos', 'in-sim PID jnt_pos'}
    assert angles['rospy PD jnt_pos'] == ([0.0], [1.0])
    assert torques == {'rospy PD jnt_trq': ([0.0], [1.0]), 'in-sim PID jnt_trq': ([0.0], [2.0])}
    assert (angle_label, torque_label) == ('angle (rad)', 'torque (N m)')


def settling_step(final, time_constant, duration, period, start=0.0):
    """{topic: (times, values)} of a phase whose link approaches `final` exponentially."""
    times = [i * period for i in range(int(round(duration / period)) + 1)]
    decay = [math.exp(-t / time_constant) for t in times]
    return {'pos_cmd': ([0.0], [1.0]),
            'jnt_pos': (times, [final + (start - final) * d for d in decay]),
            'jnt_vel': (times, [(final - start) * d / time_constant for d in decay]),
            'jnt_trq': (times, [-4.9 + 14.9 * d for d in decay])}


def test_the_compared_figure_zooms_until_the_slower_controller_settles():
    pd = settling_step(1.49, 0.2, phases.CONTROL_PERIOD * 500, phases.CONTROL_PERIOD)
    pid = settling_step(1.0, 2.0, runs.IN_SIM_PHASE_DURATION, runs.IN_SIM_SAMPLE_PERIOD)
    figure = plot.make_panels_figure(player.compared_panels(pd, pid), xlabel='t (s)',
                                     until=runs.IN_SIM_PHASE_DURATION, zoom=True)
    angle, torque, whole_run = figure.axes
    # The PID is within 5 % of its step after 2 ln 20 = 6 s, the PD long before.
    low, high = angle.get_xlim()
    assert low == 0.0 and 6.0 < high < 10.0
    assert torque.get_xlim() == (low, high)
    assert [ax.get_ylabel() for ax in figure.axes] == ['angle (rad)', 'torque (N m)',
                                                      'angle (rad)']
    assert whole_run.get_xlim()[1] >= runs.IN_SIM_PHASE_DURATION


def test_clear_outputs_removes_what_a_run_writes_and_nothing_else(tmp_path):
    earlier = ['rviz_final.png', 'phase4_table_2.5.png', 'phase2_command_2.0_pd_vs_pid.png',
               'summary.md', 'summary.json', 'samples.csv', 'in_sim_samples.csv', 'tutorial.png']
    for name in earlier + ['notes.txt', 'phase9_mine.png']:
        (tmp_path / name).write_text('x')
    (tmp_path / 'logs' / 'in_sim').mkdir(parents=True)
    (tmp_path / 'logs' / 'in_sim' / 'result.json').write_text('{}')
    player.clear_outputs(str(tmp_path))
    assert sorted(p.name for p in tmp_path.iterdir()) == ['notes.txt', 'phase9_mine.png']
    assert set(earlier) <= set(player.job_outputs())
