import rospy

from minimal_joint_controller.node import next_tick

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
