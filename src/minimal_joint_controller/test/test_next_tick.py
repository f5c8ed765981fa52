import threading

import pytest
import rospy

from minimal_joint_controller.node import next_tick, wait_until_time

PERIOD = rospy.Duration(0, 10000000)


def t(ms):
    return rospy.Time(0, 0) + rospy.Duration(0, ms * 1000000)


def test_the_next_period_starts_a_period_after_the_last_on_time_or_a_little_late():
    assert next_tick(t(20), PERIOD, t(30)) == t(30)
    assert next_tick(t(20), PERIOD, t(34)) == t(30)  # woke late: the grid is kept


def test_time_jumping_back_restarts_from_the_new_time():
    assert next_tick(t(5000), PERIOD, t(0)) == t(0)


def test_falling_a_whole_period_behind_restarts_from_now():
    assert next_tick(t(20), PERIOD, t(41)) == t(41)
    assert next_tick(t(20), PERIOD, t(40)) == t(40)
    assert next_tick(t(20), PERIOD, t(39)) == t(30)


@pytest.fixture
def sim_time():
    rospy.rostime.set_rostime_initialized(True)
    yield rospy.rostime._set_rostime
    rospy.rostime.switch_to_wallclock()


def test_waiting_for_the_next_period_returns_at_once_when_time_already_jumped_back(sim_time):
    # reset_simulation while the period at 7.42 s was being acted on: the clock is back at 5 ms
    # before the wait begins, and waiting for 7.43 s would leave the joint without torque.
    sim_time(t(5))
    assert wait_until_time(t(7430), t(7420)) == t(5)


def test_waiting_for_the_next_period_returns_when_the_clock_reaches_it(sim_time):
    sim_time(t(7420))
    condition = rospy.rostime.get_rostime_cond()

    def tick():
        with condition:
            sim_time(t(7430))
            condition.notify_all()
    threading.Timer(0.05, tick).start()
    assert wait_until_time(t(7430), t(7420)) == t(7430)
