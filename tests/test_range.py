"""libgazebo_ros_range.so on `ray` sensors over real ROS, on every engine, on a post of our own
making with three range finders half a metre up: a sonar facing a wall 1.2 m ahead reads 1.2 m
(the nearest of its rays, the one straight ahead), an infrared sensor facing the other way, where
the nearest thing is 3.5 m off and its range ends at 3 m, reads exactly max_range, and a noisy
sonar measuring at 50 Hz publishes at its plugin's 10 Hz ranges scattered about 1.2 m; each with
Gazebo's Range fields, frame, defaults and warnings."""
import math
import statistics

import pytest

from api_client import pose
from onedof_harness.private_ros import wait_until
from test_imu_ft import listen

SENSOR_Z = 0.5
WALL_DISTANCE = 1.2      # from the front sensors to the wall's face
BACK_DISTANCE = 3.5      # from the back sensor to the box behind, past its 3 m
MAX_RANGE = 3.0
NOISE = 0.01


def sonar(name, x, yaw, rate, plugin):
    """A 5 x 5 ray sensor spanning 0.3 rad each way, 2 cm to 3 m, with the range plugin."""
    return """
  <sensor type="ray" name="{name}">
    <pose>{x} 0 {z} 0 0 {yaw}</pose>
    <update_rate>{rate}</update_rate>
    <ray>
      <scan>
        <horizontal><samples>5</samples><resolution>1</resolution>
          <min_angle>-0.15</min_angle><max_angle>0.15</max_angle></horizontal>
        <vertical><samples>5</samples><resolution>1</resolution>
          <min_angle>-0.15</min_angle><max_angle>0.15</max_angle></vertical>
      </scan>
      <range><min>0.02</min><max>{max}</max><resolution>0.01</resolution></range>
    </ray>
    <plugin name="{name}_plugin" filename="libgazebo_ros_range.so">{plugin}</plugin>
  </sensor>""".format(name=name, x=x, z=SENSOR_Z, yaw=yaw, rate=rate, max=MAX_RANGE,
                      plugin=plugin)


POST_SDF = """<sdf version="1.6"><model name="post"><static>true</static><link name="post">
  <collision name="collision"><pose>0 0 0.5 0 0 0</pose>
    <geometry><box><size>0.1 0.1 1</size></box></geometry></collision>""" + sonar(
    'front', 0.05, 0, 10,
    '<topicName>front_sonar</topicName><frameName>front_sonar_link</frameName>'
    '<fov>0.3</fov><radiation>ultrasound</radiation>') + sonar(
    'back', -0.05, math.pi, 10,
    '<topicName>back_ir</topicName><frameName>back_ir_link</frameName>'
    '<radiation>infrared</radiation>') + sonar(
    'noisy', 0.05, 0, 50,
    '<topicName>noisy_sonar</topicName><frameName>noisy_sonar_link</frameName><fov>0.3</fov>'
    '<radiation>ultrasound</radiation><gaussianNoise>%r</gaussianNoise>'
    '<updateRate>10</updateRate>' % NOISE) + """
</link></model></sdf>"""


def box_sdf(name):
    return ("""<sdf version="1.6"><model name="%s"><static>true</static><link name="link">
<collision name="collision"><geometry><box><size>0.2 2 2</size></box></geometry></collision>
</link></model></sdf>""" % name)


def test_range_finders_read_the_nearest_ray_and_max_range_where_nothing_is_within_it(
        shared_sim, ros, rospy_client, engine):
    from sensor_msgs.msg import Range
    api = shared_sim
    for name, xml, at in [('post', POST_SDF, pose()),
                          ('wall', box_sdf('wall'), pose(0.05 + WALL_DISTANCE + 0.1, 0, 1)),
                          ('behind', box_sdf('behind'), pose(-0.05 - BACK_DISTANCE - 0.1, 0, 1))]:
        spawned = api.spawn_sdf_model(name, xml, '', at, '')
        assert spawned.success, spawned.status_message
    front = listen(ros, rospy_client, '/front_sonar', Range)
    back = listen(ros, rospy_client, '/back_ir', Range)
    noisy = listen(ros, rospy_client, '/noisy_sonar', Range)
    # A period at a time: each topic keeps one message in its queue, as upstream's.
    for period in range(1, 21):
        assert api.step_simulation(100).success
        for heard in (front, back, noisy):
            wait_until(lambda: heard and heard[-1].header.stamp.to_nsec() >= period * 100000000,
                       30, what='the ranges at %d ms' % (period * 100))

    # Each at 10 Hz of sim time: the sensors' rate, and the noisy one's plugin's.
    for heard in (front, back, noisy):
        assert [m.header.stamp.to_nsec() for m in heard] == [
            n * 100000000 for n in range(1, 21)], [m.header.stamp.to_nsec() for m in heard]
    msg = front[-1]
    assert msg.header.frame_id == 'front_sonar_link'
    assert msg.radiation_type == Range.ULTRASOUND
    assert msg.field_of_view == pytest.approx(0.3)
    assert (msg.min_range, msg.max_range) == (pytest.approx(0.02), pytest.approx(MAX_RANGE))
    assert all(abs(m.range - WALL_DISTANCE) <= 1e-4 for m in front), [m.range for m in front]

    msg = back[-1]
    assert msg.header.frame_id == 'back_ir_link'
    assert msg.radiation_type == Range.INFRARED
    assert msg.field_of_view == pytest.approx(0.05)  # upstream's default
    assert all(m.range == m.max_range for m in back), [m.range for m in back]

    ranges = [m.range for m in noisy]
    assert len(set(ranges)) == len(ranges), ranges
    assert abs(statistics.mean(ranges) - WALL_DISTANCE) <= 3 * NOISE, ranges
    assert 0.3 * NOISE <= statistics.stdev(ranges) <= 3 * NOISE, ranges

    log = ros.log_text('sim_' + engine)
    assert log.count('Range plugin missing <fov>, defaults to 0.05') == 1, log
    assert 'Range plugin missing <radiation>' not in log, log
