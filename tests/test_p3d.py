"""gazebo_ros_p3d's noise over real ROS, on every engine, on a cube of our own making that carries
two p3d plugins alike but for their names (tests/robots/p3d_box.urdf): two lock-stepped runs
publish the same numbers, noise included; the noise is on the twist alone, of the standard
deviation asked for, and the two plugins draw different noise from their own generators."""
import math
import os
import statistics

from api_client import GazeboApi, pose
from conftest import start_sim
from onedof_harness.private_ros import wait_until
from test_imu_ft import listen, step_and_hear

ROBOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'robots', 'p3d_box.urdf')
NOISE = 0.01  # gaussianNoise: m/s and rad/s


def robot(noise):
    with open(ROBOT) as f:
        return f.read().replace('NOISE', repr(noise))


def twist(msg):
    t = msg.twist.twist
    return (t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z)


def record(ros, rospy, engine):
    """A paused lock-step simulator of its own, the cube dropped from 30 cm, stepped 400 steps:
    both plugins' messages, as (stamp, pose, twist, covariance's first entry)."""
    from nav_msgs.msg import Odometry
    sim = start_sim(ros, engine, args=['_paused:=true', '_lockstep:=true'])
    api = GazeboApi(rospy)
    api.set_gravity(0, 0, -9.81)
    assert api.spawn_urdf_model('p3d_box', robot(NOISE), '', pose(z=0.3), '').success
    heard_a = listen(ros, rospy, '/ground_truth_a', Odometry)
    heard_b = listen(ros, rospy, '/ground_truth_b', Odometry)
    # A model plugin measures before a step, at the time the step starts from: at 100 Hz, once
    # more than 10 ms have passed, at 11, 21, ..., 391 ms. Each heard before the next steps.
    for stamp_ms in range(11, 392, 10):
        step_and_hear(api, heard_a, 20 if stamp_ms == 11 else 10, stamp_ms * 1000000)
    wait_until(lambda: heard_b and heard_b[-1].header.stamp.to_nsec() >= 391000000, 30,
               what='the last message of p3d_b')
    ros.terminate(sim)
    wait_until(lambda: not ros.has_service('/gazebo/unpause_physics'), 60,
               what='the stopped simulator to leave the graph')
    return [[(m.header.stamp.to_nsec(), m.pose.pose, twist(m), m.twist.covariance[0])
             for m in heard] for heard in (heard_a, heard_b)]


def test_two_lock_step_runs_of_a_noisy_p3d_publish_the_same_numbers(ros, rospy_client, engine):
    first = record(ros, rospy_client, engine)
    second = record(ros, rospy_client, engine)
    a, b = first
    assert len(a) == len(b) == 39
    assert first == second
    # The cube fell and landed: the runs are not equal by standing still.
    assert max(abs(t[2]) for _, _, t, _ in a) > 1
    assert {c for _, _, _, c in a} == {NOISE * NOISE}
    # Same truth, own noise: the poses (no noise) are the same, every twist differs, by a spread
    # of sqrt(2) NOISE (234 differences: within 30 %).
    assert [(s, p) for s, p, _, _ in a] == [(s, p) for s, p, _, _ in b]
    differences = [x - y for (_, _, ta, _), (_, _, tb, _) in zip(a, b) for x, y in zip(ta, tb)]
    assert all(d != 0 for d in differences)
    spread = statistics.pstdev(differences)
    assert 0.7 * math.sqrt(2) * NOISE < spread < 1.3 * math.sqrt(2) * NOISE, spread
