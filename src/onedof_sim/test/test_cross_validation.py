"""Cross-validation of the physics engines: each against the closed form, each of ours
against pybullet with its own loaders, over the tutorial scenario. All run in-process without ROS
(ours through `rosrun onedof_sim tutorial_scenario --physics NAME`, so the devel space must be
sourced; pybullet in this process, so it must import: the venv).
"""
import functools
import math

import pytest

from onedof_sim.engines import engine_names
from onedof_sim.reference import cross_validation as cv
from onedof_sim.reference import engine_checks as ec
from onedof_sim.tutorial import physics

ENGINES = cv.engines()
engines = pytest.mark.parametrize('engine', ENGINES, ids=lambda engine: engine.name)
# Where the settled angles must agree, with each other and with the closed form, rad.
SETTLED_TOLERANCE = 1e-3


@functools.lru_cache(maxsize=None)
def scenario(name):
    """The run of the tutorial scenario of an engine (ours or the reference) by name, once per
    process."""
    return next(engine for engine in ENGINES if engine.name == name).scenario()


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
    run = scenario(engine.name)
    assert len(run.t) == round(len(cv.PHASES) * cv.PHASE_SECONDS / 0.01)
    for index, phase in enumerate(cv.PHASES):
        if index == cv.TABLE_PHASE:
            expected, tolerance = physics.table_contact_angle(cv.TABLE_X), 0.01
            # The table holds the link well short of where the controller would bring it.
            assert cv.settled(run, index) < physics.settled_angle(phase.command) - 0.5
        else:
            expected, tolerance = physics.settled_angle(phase.command), SETTLED_TOLERANCE
        assert cv.settled(run, index) == pytest.approx(expected, abs=tolerance), phase.name


# --- engine against engine ----------------------------------------------------------------------

@pytest.mark.parametrize('name', engine_names())
def test_each_engine_follows_pybullet_over_the_tutorial_scenario(name):
    differences = cv.engine_differences(scenario(name), scenario(cv.PybulletReference.name))
    for part, aim in cv.RMS_AIMS.items():
        assert differences[part][0] < aim, part


def test_the_engines_settle_within_a_milliradian_of_each_other():
    for index, phase in enumerate(cv.PHASES):
        if index != cv.TABLE_PHASE:
            angles = {engine.name: cv.settled(scenario(engine.name), index) for engine in ENGINES}
            assert max(angles.values()) - min(angles.values()) < SETTLED_TOLERANCE, \
                (phase.name, angles)


# --- beyond the tutorial's arm -----------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def checks_of(name):
    return ec.checks(name, cv.ground_sdf_path())


@pytest.mark.parametrize('name', engine_names())
def test_each_engine_drives_the_base_holds_the_load_ranges_the_walls_and_holds_the_arm(name):
    checks = checks_of(name)
    assert len(checks) == 7
    for check in checks:
        assert ec.met(check), check


def test_a_joint_is_past_its_droop_only_outside_the_span_from_its_command_to_the_droop():
    assert ec.beyond_droop(0.05, 0.1) == 0.0
    assert ec.beyond_droop(0.0, 0.1) == 0.0
    assert ec.beyond_droop(0.12, 0.1) == pytest.approx(0.02)
    assert ec.beyond_droop(-0.01, 0.1) == pytest.approx(0.01)
    assert ec.beyond_droop(-0.05, -0.1) == 0.0
    assert ec.beyond_droop(0.003, 0.0) == pytest.approx(0.003)


def test_a_ray_in_the_pen_meets_the_wall_it_points_at():
    assert ec.wall_distance(0.1, 0.0, 0.0, 2.0) == pytest.approx(1.9)
    assert ec.wall_distance(0.1, 0.0, math.pi / 2, 2.0) == pytest.approx(2.0)
    assert ec.wall_distance(0.0, 0.0, math.pi / 4, 2.0) == pytest.approx(2 * math.sqrt(2))
    assert ec.wall_distance(0.5, -0.5, -math.pi / 2, 2.0) == pytest.approx(1.5)


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
    figures = [cv.Figure('ode', 'small-swing period', 's', 1.01, 1.0),
               cv.Figure('pybullet', 'drift', '', 0.002, 0.0)]
    differences = {'ode': {'before the table': (0.004, 0.01), 'with the table': (0.03, 0.09)}}
    text = cv.markdown(figures, differences, {'ode': {'with the table': (0.0002, 0.003)}})
    assert '| ode | small-swing period | 1.01 s | 1 s | +0.01 s (+1 %) |' in text
    assert '| pybullet | drift | 0.002 | 0 | +0.002 |' in text
    assert '| ode | before the table | 0.004 rad | 0.01 rad | < 0.01 rad | yes |' in text
    assert '| ode | with the table | 0.03 rad | 0.09 rad | < 0.02 rad | no |' in text
    assert '0.0002 rad for ode (max 0.003 rad)' in text
    checks = [ec.Check('dart', 'turn rate', 'rad/s', 0.31, 0.3, 0.006),
              ec.Check('ode', 'force', 'N', 29.5, 29.4, 0.294)]
    text = cv.markdown(figures, differences, {}, checks)
    assert '| dart | turn rate | 0.31 rad/s | 0.3 rad/s | +0.01 rad/s (+3.33 %) | within ' \
        '0.006 rad/s | no |' in text
    assert '| ode | force | 29.5 N | 29.4 N | +0.1 N (+0.34 %) | within 0.294 N | yes |' in text
    assert "Not met: dart's turn rate (0.31 rad/s against 0.3 rad/s)." in text


@pytest.mark.parametrize('name', engine_names())
def test_the_tool_says_what_is_wrong_with_its_arguments(name):
    with pytest.raises(RuntimeError, match="--q wants finite numbers, got 'nan'"):
        cv.ToolEngine(name).release(math.nan, 0.0, 1.0)


def test_the_arm_check_says_when_its_p_terms_hold_the_arm_nowhere():
    weak = dict(ec.ARM_GAINS, p=[1.0] * len(ec.ARM_JOINTS))
    with pytest.raises(RuntimeError, match='the P terms hold the arm at no pose near the command'):
        ec.held_arm(ENGINES[0].name, cv.ground_sdf_path(), weak, 1.0)
