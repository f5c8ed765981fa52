"""robot_state_publisher, fed a JointState of joint1 = q, publishes link1 -> link2 at (0, 0, 1)
rotated by q about y: the URDF's kinematics as rviz will see them."""
import math

import pytest

from conftest import TUTORIAL_URDF
from onedof_harness.private_ros import wait_until


@pytest.fixture
def state_publisher(ros):
    with open(TUTORIAL_URDF) as f:
        ros.set_param('/robot_description', f.read())
    return ros.start(['rosrun', 'robot_state_publisher', 'robot_state_publisher'],
                     name='robot_state_publisher')


def test_link2_transform_follows_joint1(ros, rospy_client, state_publisher):
    rospy = rospy_client
    from sensor_msgs.msg import JointState
    from tf2_msgs.msg import TFMessage

    latest = {}

    def on_tf(msg):
        for t in msg.transforms:
            if (t.header.frame_id, t.child_frame_id) == ('link1', 'link2'):
                latest['tf'] = t.transform

    rospy.Subscriber('/tf', TFMessage, on_tf)
    joint_states = rospy.Publisher('/joint_states', JointState, queue_size=1)
    wait_until(lambda: joint_states.get_num_connections() > 0, 30,
               what='robot_state_publisher to subscribe to /joint_states')

    for q in (0.0, 0.7, -1.3, 2.5, math.pi):
        msg = JointState(name=['joint1'], position=[q])

        def matches():
            msg.header.stamp = rospy.Time.now()
            joint_states.publish(msg)
            t = latest.get('tf')
            if t is None:
                return False
            # Rotation about y by q: quaternion (x, y, z, w) = (0, sin q/2, 0, cos q/2), up to sign.
            rot = t.rotation
            dot = rot.y * math.sin(q / 2) + rot.w * math.cos(q / 2)
            return abs(abs(dot) - 1) < 1e-6 and abs(rot.x) < 1e-9 and abs(rot.z) < 1e-9

        wait_until(matches, 20, interval=0.1, what='the link1->link2 transform for q = %g' % q)
        translation = latest['tf'].translation
        assert (translation.x, translation.y, translation.z) == pytest.approx((0, 0, 1), abs=1e-9)
