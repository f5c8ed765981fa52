import math

import pytest

from onedof_sim.tutorial import physics as tp
from onedof_sim.tutorial.phases import PHASES, TABLE_X

BOOK_GAINS = {'p': 10.0, 'i': 10.0, 'd': 10.0, 'i_clamp_min': -10.0, 'i_clamp_max': 10.0}
COMMAND_1 = PHASES[0]
TABLE = PHASES[3]


@pytest.mark.parametrize('command', [0.3, 1.0, 2.0, 2.5, -1.0])
def test_settled_angle_balances_gravity(command):
    q = tp.settled_angle(command)
    assert tp.KP * (command - q) + tp.gravity_torque(q) == pytest.approx(0, abs=1e-9)


def test_low_gain_droops_past_the_command():
    assert tp.settled_angle(1.0) > 1.0
    assert tp.settled_angle(2.0) > 2.0
    assert tp.settled_angle(2.0) == pytest.approx(2.35, abs=0.01)  # "hangs near 2.35"


def test_pendulum_period():
    assert tp.pendulum_period() == pytest.approx(2 * math.pi * math.sqrt(0.35 / 4.9))


def test_table_contact_angle_puts_the_link_tip_on_the_table_top():
    q = tp.table_contact_angle(0.85)
    # The leading rim of the link's far end reaches down to the top face (z 0.775), over the top.
    x, z = tp.tip_rim(q)
    assert z == pytest.approx(tp.TABLE_TOP_Z, abs=1e-9)
    assert 0.85 - tp.TABLE_TOP_HALF_WIDTH < x < 0.85 + tp.TABLE_TOP_HALF_WIDTH
    assert x == pytest.approx(math.sin(q) + tp.LINK_RADIUS * math.cos(q))
    assert 1 + math.cos(q) - tp.LINK_RADIUS * math.sin(q) == pytest.approx(tp.TABLE_TOP_Z)
    # Short of the command 2.5, and of where it would hang without the table (2.35 for 2.0).
    assert 1.6 < q < 1.8


def test_table_out_of_reach_is_an_error():
    with pytest.raises(ValueError, match='out of the link'):
        tp.table_contact_angle(3.0)


def test_step_metrics_of_a_damped_response():
    times = [i * 0.01 for i in range(1001)]
    # Second-order step from 0 to 1 with overshoot exp(-zeta pi / sqrt(1 - zeta^2)).
    zeta, wn = 0.3, 5.0
    wd = wn * math.sqrt(1 - zeta ** 2)
    q = [1 - math.exp(-zeta * wn * t) * (math.cos(wd * t) + zeta * wn / wd * math.sin(wd * t))
         for t in times]
    m = tp.step_metrics(times, q, start_value=0.0)
    assert m['settled'] == pytest.approx(1.0, abs=1e-4)
    assert m['overshoot'] == pytest.approx(math.exp(-zeta * math.pi / math.sqrt(1 - zeta ** 2)),
                                           rel=1e-3)
    # Envelope exp(-zeta wn t) / sqrt(1 - zeta^2) falls under 0.02 near t = 2.7 s.
    assert 2.0 < m['settling_time'] < 2.8


def test_step_metrics_downward_step():
    times = [0, 1, 2, 3]
    m = tp.step_metrics(times, [2.0, -0.2, 0.0, 0.0], start_value=2.0, window=1)
    assert m['settled'] == 0.0
    assert m['overshoot'] == pytest.approx(0.2)


def test_tail_mean_takes_the_last_window():
    assert tp.tail_mean([0, 1, 2, 3], [5, 5, 1, 3], window=1) == 2


def test_pd_predicts_the_droop_and_on_the_table_kp_times_the_error():
    predicted, torque = tp.pd_prediction(COMMAND_1, 1.49)
    assert predicted == tp.settled_angle(1.0)
    assert torque == pytest.approx(-tp.gravity_torque(predicted))
    predicted, torque = tp.pd_prediction(TABLE, 1.7)
    assert predicted == tp.table_contact_angle(TABLE_X)
    assert torque == pytest.approx(tp.KP * 0.8)


def test_pid_predicts_the_command_and_on_the_table_the_clamped_integral_on_top():
    predict = tp.pid_prediction(BOOK_GAINS)
    assert predict(COMMAND_1, 1.0) == (1.0, pytest.approx(-tp.gravity_torque(1.0)))
    predicted, torque = predict(TABLE, 1.7)
    assert predicted == tp.table_contact_angle(TABLE_X)
    assert torque == pytest.approx(10.0 * 0.8 + 10.0)


def edited_urdf(tmp_path, old, new):
    with open(tp.ROBOT_URDF) as f:
        text = f.read()
    assert old in text
    path = tmp_path / 'robot.urdf'
    path.write_text(text.replace(old, new))
    return str(path)


def test_read_robot_follows_an_edited_urdf(tmp_path):
    # The closed forms describe the robot the simulator loads: a changed URDF changes them.
    heavier = edited_urdf(tmp_path, '<mass value="1"/>\n      <inertia ixx="0.1"',
                          '<mass value="2"/>\n      <inertia ixx="0.1"')
    assert tp.read_robot(heavier)['mass'] == 2.0
    higher = edited_urdf(tmp_path, '<origin xyz="0 0 1.0" rpy="0 0 0"/>\n    <axis',
                         '<origin xyz="0 0 1.5" rpy="0 0 0"/>\n    <axis')
    assert tp.read_robot(higher)['joint_height'] == 1.5


@pytest.mark.parametrize('old,new,why', [
    ('<axis xyz="0 1 0"/>', '<axis xyz="1 0 0"/>', 'joint1 must turn about y'),
    ('<origin xyz="0 0 0.5" rpy="0 0 0"/>\n      <mass value="1"/>\n      <inertia ixx="0.1"',
     '<origin xyz="0.1 0 0.5" rpy="0 0 0"/>\n      <mass value="1"/>\n      <inertia ixx="0.1"',
     'centre of mass must be on its axis')])
def test_a_robot_the_closed_forms_do_not_describe_is_refused(tmp_path, old, new, why):
    with pytest.raises(ValueError, match=why):
        tp.read_robot(edited_urdf(tmp_path, old, new))
