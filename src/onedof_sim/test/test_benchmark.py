"""Unit tests of the benchmarks' arithmetic, report and bare-loop start (no ROS graph needed)."""
import math
import xml.etree.ElementTree as ElementTree

import pytest

from onedof_sim.benchmark.graph import BareLoop, NotMeasured, engine_loop_command
from onedof_sim.benchmark.report import (Row, chain_urdf, collapsed_stack_shares,
                                         cpu_model, markdown_cell, mean_rtf, missed_periods, one_line,
                                         percentile, perf_report_shares, period_jitter,
                                         power_law_exponent, rate, render_table, windowed_rtf)


def test_percentile_interpolates_between_ranks_as_numpy():
    values = [5.0, 1.0, 4.0, 2.0, 3.0]
    assert percentile(values, 0) == 1.0
    assert percentile(values, 50) == 3.0
    assert percentile(values, 100) == 5.0
    assert percentile(values, 25) == 2.0
    assert percentile([1.0, 2.0], 99) == pytest.approx(1.99)
    assert percentile([7.0], 99) == 7.0


def test_percentile_of_nothing_is_an_error():
    with pytest.raises(ValueError):
        percentile([], 50)


def test_rate_weighs_windows_by_their_length():
    assert rate([100, 300], [1.0, 1.0]) == 200
    assert rate([100, 900], [1.0, 3.0]) == 250


def test_windowed_rtf_of_a_steady_clock_is_its_rate():
    wall = [i * 0.01 for i in range(501)]  # 5 s sampled every 10 ms
    sim = [0.5 * t for t in wall]
    factors = windowed_rtf(wall, sim, window=1.0)
    assert len(factors) == 5
    assert all(f == pytest.approx(0.5) for f in factors)
    assert mean_rtf(wall, sim) == pytest.approx(0.5)


def test_windowed_rtf_finds_the_slow_second():
    wall = [i * 0.001 for i in range(3001)]
    # 1.0 in the first and last second, 0.9 in the middle one.
    sim = [t if t <= 1 else (1 + 0.9 * (t - 1) if t <= 2 else 1.9 + (t - 2)) for t in wall]
    factors = windowed_rtf(wall, sim, window=1.0)
    assert [round(f, 3) for f in factors] == [1.0, 0.9, 1.0]
    assert mean_rtf(wall, sim) == pytest.approx(2.9 / 3)


def test_windowed_rtf_leaves_out_a_short_tail():
    assert windowed_rtf([0.0, 0.5, 1.0, 1.5], [0.0, 0.5, 1.0, 1.5]) == [1.0]


def test_missed_periods_counts_empty_slots():
    period = 0.01
    assert missed_periods([i * period for i in range(100)], period) == 0
    assert missed_periods([0.0, 0.01, 0.03, 0.04, 0.07], period) == 3
    assert missed_periods([], period) == 0


def test_missed_periods_forgives_a_late_iteration_that_catches_up():
    # 13 ms late, then the next one 7 ms later: rospy.Rate catches up, no period is lost.
    assert missed_periods([0.0, 0.01, 0.023, 0.030, 0.04], 0.01) == 0


def test_period_jitter_is_the_deviation_of_each_interval():
    jitter = period_jitter([0.0, 0.011, 0.020, 0.030], 0.01)
    assert jitter == pytest.approx([0.001, 0.001, 0.0])


def test_power_law_exponent_recovers_the_power():
    xs = [1, 10, 50, 200]
    assert power_law_exponent(xs, [3.0 * x ** 2 for x in xs]) == pytest.approx(2.0)
    assert power_law_exponent(xs, [5.0 * x for x in xs]) == pytest.approx(1.0)
    with pytest.raises(ValueError):
        power_law_exponent([1], [1])


def test_cpu_model_reads_proc_cpuinfo():
    text = 'processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC 7B13\n'
    assert cpu_model(text) == 'AMD EPYC 7B13'
    assert cpu_model('processor : 0\n') == 'unknown'


@pytest.mark.parametrize('links', [1, 10, 50])
def test_chain_urdf_has_the_links_and_revolute_joints_asked_for(links):
    robot = ElementTree.fromstring(chain_urdf(links))
    moving = [link for link in robot.findall('link') if link.get('name').startswith('link')]
    joints = robot.findall('joint')
    assert len(moving) == links
    assert [j.get('type') for j in joints] == ['fixed'] + ['revolute'] * links
    # Each joint hangs under the one before: the parent of joint i is the child of joint i-1.
    for before, after in zip(joints, joints[1:]):
        assert after.find('parent').get('link') == before.find('child').get('link')
    # High enough that the chain never touches the ground.
    height = float(joints[0].find('origin').get('xyz').split()[2])
    assert height > links * 0.1


def test_render_table_names_the_machine_and_marks_the_aims():
    rows = [Row('1', 'ODE node steps/s', '90000', 'bare ODE loop', '100000', 0.9, '>= 0.5', True),
            Row('3', 'p50', '120 us', 'bare service', '80 us', 1.5, '<= 1.3x', False),
            Row('6', 'start-up', '1.2 s', 'bare node', '0.8 s', math.nan, None, None)]
    text = render_table(rows, {'cpu': 'AMD EPYC', 'cores': 2}, '2024-01-01',
                        notes=['profile: dWorldStep 80 %'])
    assert 'AMD EPYC, 2 cores; 2024-01-01' in text
    loaded = render_table(rows, {'cpu': 'AMD EPYC', 'cores': 2, 'load': '0.5 / 1.5'}, 'today')
    assert 'AMD EPYC, 2 cores; load average (1 min) at the start and the end of the run ' \
           '0.5 / 1.5; today' in loaded
    lines = [line for line in text.splitlines() if line.startswith('| ')]
    assert len(lines) == 1 + len(rows)  # header + rows
    assert '| 0.90 | >= 0.5 | met |' in lines[1]
    assert '**not met**' in lines[2]
    assert lines[3].endswith('| — | — | — |')
    assert '- profile: dWorldStep 80 %' in text


def test_cells_and_notes_quoting_logs_stay_on_one_line():
    log = 'roslaunch exited:\n\x1b]2;/work/launch\x07\x1b[31mERROR\x1b[0m a | b\n'
    assert one_line(log) == 'roslaunch exited: ERROR a | b'
    assert markdown_cell(log) == 'roslaunch exited: ERROR a \\| b'


PERF_REPORT = '''# Samples: 534  of event 'cpu-clock:ppp'
#
# Overhead  Shared Object         Symbol
# ........  ....................  ....................................
#
    15.54%  libode.so.8           [.] dxStepIsland
     6.37%  libroscpp.so          [.] ros::Publication::publish(ros::SerializedMessage const&)
     2.10%  [kernel.kallsyms]     [k] __schedule
'''


def test_perf_report_shares_reads_symbols_and_objects():
    assert perf_report_shares(PERF_REPORT) == [
        (15.54, 'libode.so.8', 'dxStepIsland'),
        (6.37, 'libroscpp.so', 'ros::Publication::publish(ros::SerializedMessage const&)'),
        (2.10, '[kernel.kallsyms]', '__schedule')]
    assert perf_report_shares('    81.46%  libpython3.11.so.1.0\n     1.12%  libc.so.6\n') == [
        (81.46, 'libpython3.11.so.1.0', None), (1.12, 'libc.so.6', None)]


def test_collapsed_stack_shares_counts_self_and_inclusive_once_per_stack():
    text = ('<module> (/a/node.py:3);run (/a/node.py:10);step (/b/world.py:5) 6\n'
            '<module> (/a/node.py:3);run (/a/node.py:12);step (/b/world.py:7) 2\n'
            '<module> (/a/node.py:3);run (/a/node.py:14);publish (/c/topics.py:9) 2\n')
    shares = collapsed_stack_shares(text)
    assert shares['step (world.py)'] == pytest.approx((0.8, 0.8))
    assert shares['publish (topics.py)'] == pytest.approx((0.2, 0.2))
    assert shares['run (node.py)'] == pytest.approx((0.0, 1.0))
    # A recursive function counts once in its stack's inclusive share.
    recursive = collapsed_stack_shares('f (x.py:1);f (x.py:2);g (x.py:9) 4\n')
    assert recursive['f (x.py)'] == pytest.approx((0.0, 1.0))
    assert collapsed_stack_shares('') == {}


def test_bus_has_connection_reads_bus_info_rows():
    from onedof_harness.private_ros import bus_has_connection as connected_to
    # As roscpp's getBusInfo answers: [id, other node, direction, transport, topic, connected, ...]
    bus_info = [[1, '/book_controller', 'o', 'TCPROS', '/clock', True, 'c1'],
                [2, '/benchmark', 'o', 'TCPROS', '/rosout', True, 'c2']]
    assert connected_to(bus_info, '/book_controller', '/clock')
    assert not connected_to(bus_info, '/benchmark', '/clock')
    assert not connected_to(bus_info, '/book_controller', '/rosout')
    assert not connected_to([], '/book_controller', '/clock')


def test_a_bare_loop_whose_engine_refuses_the_model_is_not_measured_in_the_engines_words(
        tmp_path):
    # MuJoCo refuses a chain deeper than 95 links (mujoco_engine.cpp), as row 2's 200 links.
    path = tmp_path / 'chain_96.urdf'
    path.write_text(chain_urdf(96))
    with pytest.raises(NotMeasured, match='mujoco: a chain of more than 95 links'):
        BareLoop(engine_loop_command('mujoco'), [('chain', str(path), 'urdf', 0.0)])
