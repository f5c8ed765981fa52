"""Cross-validation of the two physics engines (issue 5): each against the closed form, and the two
against each other over the tutorial scenario. Both run in-process without ROS (the ODE core
through `rosrun onedof_sim tutorial_scenario`, so the devel space must be sourced; the pybullet
core through BulletWorld, so pybullet must import: the venv).
"""
import math

import pytest

from onedof_sim import cross_validation as cv
from onedof_sim import tutorial_physics as physics

engines = pytest.mark.parametrize('engine', [cv.OdeEngine(), cv.BulletEngine()],
                                  ids=lambda engine: engine.name)


# --- each engine against the closed form --------------------------------------------------------

@engines
def test_small_swing_period_is_the_compound_pendulum_s(engine):
    swing = engine.release(math.pi + cv.SWING_AMPLITUDE, 0.0, cv.SWING_SECONDS)
    period = cv.mean_period(swing.t, swing.q, math.pi)
    assert period == pytest.approx(physics.pendulum_period(), rel=0.001)


@engines
def test_energy_is_kept_over_ten_seconds_undamped(engine):
    swing = engine.release(cv.ENERGY_START, 0.0, cv.ENERGY_SECONDS)
    assert swing.t[-1] == pytest.approx(cv.ENERGY_SECONDS)
    energies = [cv.energy(q, qdot) for q, qdot in zip(swing.q, swing.qdot)]
    assert energies[0] == pytest.approx(physics.MASS * physics.GRAVITY * physics.COM_DISTANCE
                                        * (1 + math.cos(cv.ENERGY_START)))
    assert max(abs(e / energies[0] - 1) for e in energies) < 0.01
    # It swings through the bottom and back: the check covers the whole range of speeds.
    assert min(swing.q) < 1.5 and max(swing.q) > math.pi + 0.5


@engines
@pytest.mark.parametrize('angle', cv.HOLDING_ANGLES)
def test_static_holding_effort_balances_m_g_d_sin_q(engine, angle):
    assert cv.holding_effort(engine, angle) == pytest.approx(-physics.gravity_torque(angle),
                                                             rel=1e-3)


@engines
def test_the_controller_settles_where_the_closed_form_says(engine):
    run = engine.scenario()
    for index, phase in enumerate(cv.PHASES):
        if index == cv.TABLE_PHASE:
            expected, tolerance = physics.table_contact_angle(cv.TABLE_X), 0.01
            # The table holds the link well short of where the controller would bring it.
            assert cv.settled(run, index) < physics.settled_angle(phase.command) - 0.5
        else:
            expected, tolerance = physics.settled_angle(phase.command), 0.002
        assert cv.settled(run, index) == pytest.approx(expected, abs=tolerance), phase.name


# --- engine against engine ----------------------------------------------------------------------

def test_the_engines_agree_over_the_tutorial_scenario():
    ode, bullet = cv.OdeEngine().scenario(), cv.BulletEngine().scenario()
    assert len(ode.t) == round(len(cv.PHASES) * cv.PHASE_SECONDS / 0.01)
    differences = cv.engine_differences(ode, bullet)
    for part, aim in cv.RMS_AIMS.items():
        assert differences[part][0] < aim, part


# --- the comparison logic on its own ------------------------------------------------------------

def test_mean_period_of_a_sampled_sine():
    times = [i * 0.001 for i in range(5001)]
    positions = [2.0 + 0.1 * math.sin(2 * math.pi * t / 0.7 + 0.3) for t in times]
    assert cv.mean_period(times, positions, 2.0) == pytest.approx(0.7, rel=1e-5)
    with pytest.raises(ValueError):
        cv.mean_period(times, [2.5] * len(times), 2.0)


def test_parse_csv_reads_the_tools_columns():
    run = cv.parse_csv('t,q,qdot,torque\n0.000,0,0,10\n0.010,0.001,0.1,9.5\n')
    assert run == cv.Run([0.0, 0.01], [0.0, 0.001], [0.0, 0.1], [10.0, 9.5])
    assert cv.parse_csv('t,q,qdot\n0.000,3,0\n').torque is None


def test_engine_differences_split_at_the_table():
    table_time = cv.TABLE_PHASE * cv.PHASE_SECONDS
    times = [0.0, 1.0, table_time, table_time + 1]
    first = cv.Run(times, [0.0, 1.0, 2.0, 2.0], None, None)
    second = cv.Run(times, [0.0, 1.0 + 0.003, 2.0 - 0.05, 2.0 + 0.05], None, None)
    differences = cv.engine_differences(first, second)
    assert differences['before the table'] == pytest.approx((math.sqrt(0.003 ** 2 / 2), 0.003))
    assert differences['with the table'] == pytest.approx((0.05, 0.05))
    with pytest.raises(ValueError):
        cv.engine_differences(first, cv.Run(times[:-1], second.q[:-1], None, None))


def test_markdown_shows_each_figure_its_error_and_whether_an_aim_is_met():
    figures = [cv.Figure('ODE', 'small-swing period', 's', 1.01, 1.0),
               cv.Figure('bullet', 'drift', '', 0.002, 0.0)]
    differences = {'before the table': (0.004, 0.01), 'with the table': (0.03, 0.09)}
    text = cv.markdown(figures, differences, {'with the table': (0.0002, 0.003)})
    assert '| ODE | small-swing period | 1.01 s | 1 s | +0.01 s (+1 %) |' in text
    assert '| bullet | drift | 0.002 | 0 | +0.002 |' in text
    assert '| before the table | 0.004 rad | 0.01 rad | < 0.01 rad | yes |' in text
    assert '| with the table | 0.03 rad | 0.09 rad | < 0.02 rad | no |' in text
    assert 'becomes 0.0002 rad (max 0.003 rad)' in text


def test_the_ode_tool_says_what_is_wrong_with_its_arguments():
    with pytest.raises(RuntimeError, match="--q wants finite numbers, got 'nan'"):
        cv.OdeEngine().release(math.nan, 0.0, 1.0)
