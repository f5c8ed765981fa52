"""libgazebo_ros_block_laser.so on `ray` sensors over real ROS, on every engine, on a post of our
own making with a block laser (21 x 11 rays, 0.3 to 3 m) 1.5 m before a wall narrower and lower
than its fan, a small cube standing between them nearer than its minimum range: each point lies
along its ray, on the wall's face within 1 mm where the ray meets it (the cube is not seen) and at
exactly 3 m where it meets nothing, so every point is between the minimum and the maximum range
(upstream's block_laser_clipping test); one intensity channel, unnamed, all 0. A second block
laser with gaussianNoise scatters the points on the wall and the intensities, not those at the
maximum range. A block laser looking down from 0.8 m, its range 1 m, over a world with Gazebo's
ground plane and over one without it (upstream's block_laser_clipping world has none): with the
ground every ray ends on the plane z = 0; without it, as in Gazebo, every ray meets nothing."""
import math

import pytest

from api_client import pose
from conftest import GROUND
from onedof_harness.private_ros import wait_until
from test_imu_ft import listen

SENSOR = (0.05, 0.0, 0.8)         # on the post's face, in the world
COLUMNS, ROWS = 21, 11
MIN_YAW, MAX_YAW = -0.3, 0.3
MIN_PITCH, MAX_PITCH = -0.2, 0.2
MIN_RANGE, MAX_RANGE = 0.3, 3.0
WALL = 1.5                        # its face, ahead of the sensor
WALL_HALF_WIDTH, WALL_HALF_HEIGHT = 0.3, 0.2
NOISE = 0.005


def block_laser(name, plugin):
    return """
  <sensor type="ray" name="{name}">
    <pose>{x} {y} {z} 0 0 0</pose>
    <update_rate>10</update_rate>
    <ray>
      <scan>
        <horizontal><samples>{columns}</samples><resolution>1</resolution>
          <min_angle>{min_yaw}</min_angle><max_angle>{max_yaw}</max_angle></horizontal>
        <vertical><samples>{rows}</samples><resolution>1</resolution>
          <min_angle>{min_pitch}</min_angle><max_angle>{max_pitch}</max_angle></vertical>
      </scan>
      <range><min>{min_range}</min><max>{max_range}</max><resolution>0.001</resolution></range>
    </ray>
    <plugin name="{name}_plugin" filename="libgazebo_ros_block_laser.so">{plugin}</plugin>
  </sensor>""".format(name=name, x=SENSOR[0], y=SENSOR[1], z=SENSOR[2], columns=COLUMNS,
                      rows=ROWS, min_yaw=MIN_YAW, max_yaw=MAX_YAW, min_pitch=MIN_PITCH,
                      max_pitch=MAX_PITCH, min_range=MIN_RANGE, max_range=MAX_RANGE,
                      plugin=plugin)


POST_SDF = """<sdf version="1.6"><model name="post"><static>true</static><link name="post">
  <collision name="collision"><pose>0 0 0.5 0 0 0</pose>
    <geometry><box><size>0.1 0.1 1</size></box></geometry></collision>""" + block_laser(
    'block', '<topicName>block_cloud</topicName><frameName>block_link</frameName>') + block_laser(
    'noisy_block', '<topicName>noisy_cloud</topicName><frameName>block_link</frameName>'
    '<gaussianNoise>%r</gaussianNoise>' % NOISE) + """
</link></model></sdf>"""


def box_sdf(name, size):
    return ("""<sdf version="1.6"><model name="%s"><static>true</static><link name="link">
<collision name="collision"><geometry><box><size>%g %g %g</size></box></geometry></collision>
</link></model></sdf>""" % ((name,) + size))


def ray(index):
    """The yaw and pitch of point `index` (row after row, each from the first yaw to the last)."""
    row, column = divmod(index, COLUMNS)
    return (MIN_YAW + column * (MAX_YAW - MIN_YAW) / (COLUMNS - 1),
            MIN_PITCH + row * (MAX_PITCH - MIN_PITCH) / (ROWS - 1))


def on_wall(yaw, pitch, margin):
    """Whether the ray meets the wall's face this far (m) inside its edges; None near an edge."""
    distance = WALL / (math.cos(pitch) * math.cos(yaw))
    y, z = WALL * math.tan(yaw), distance * math.sin(pitch)
    if abs(y) < WALL_HALF_WIDTH - margin and abs(z) < WALL_HALF_HEIGHT - margin:
        return True
    if abs(y) > WALL_HALF_WIDTH + margin or abs(z) > WALL_HALF_HEIGHT + margin:
        return False
    return None


def norm(p):
    return math.sqrt(p.x ** 2 + p.y ** 2 + p.z ** 2)


def test_block_laser_points_lie_on_the_wall_and_at_max_range_where_nothing_is(
        shared_sim, ros, rospy_client):
    from sensor_msgs.msg import PointCloud
    api = shared_sim
    wall_x = SENSOR[0] + WALL + 0.1
    cube_x = SENSOR[0] + MIN_RANGE - 0.1  # its far face 5 cm short of the rays' start
    for name, xml, at in [
            ('post', POST_SDF, pose()),
            ('wall', box_sdf('wall', (0.2, 2 * WALL_HALF_WIDTH, 2 * WALL_HALF_HEIGHT)),
             pose(wall_x, 0, SENSOR[2])),
            ('cube', box_sdf('cube', (0.1, 0.1, 0.1)), pose(cube_x, 0, SENSOR[2]))]:
        spawned = api.spawn_sdf_model(name, xml, '', at, '')
        assert spawned.success, spawned.status_message
    clean = listen(ros, rospy_client, '/block_cloud', PointCloud)
    noisy = listen(ros, rospy_client, '/noisy_cloud', PointCloud)
    # A period at a time: each topic keeps one message in its queue, as upstream's.
    for period in range(1, 4):
        assert api.step_simulation(100).success
        for heard in (clean, noisy):
            wait_until(lambda: heard and heard[-1].header.stamp.to_nsec() >= period * 100000000,
                       30, what='the clouds at %d ms' % (period * 100))

    assert [m.header.stamp.to_nsec() for m in clean] == [100000000, 200000000, 300000000]
    cloud = clean[-1]
    assert cloud.header.frame_id == 'block_link'
    assert len(cloud.points) == COLUMNS * ROWS
    assert [c.name for c in cloud.channels] == ['']
    assert list(cloud.channels[0].values) == [0.0] * (COLUMNS * ROWS)
    met = missed = 0
    for index, point in enumerate(cloud.points):
        yaw, pitch = ray(index)
        r = norm(point)
        assert MIN_RANGE <= r <= MAX_RANGE + 1e-5, (index, r)  # upstream's clipping test
        direction = (math.cos(pitch) * math.cos(yaw), math.cos(pitch) * math.sin(yaw),
                     math.sin(pitch))
        assert all(abs(a / r - b) <= 1e-5 for a, b in zip((point.x, point.y, point.z), direction)), \
            (index, point)
        wall = on_wall(yaw, pitch, 0.005)
        if wall:
            assert abs(point.x - WALL) <= 1e-3, (index, point)
            met += 1
        elif wall is False:
            assert r == pytest.approx(MAX_RANGE, abs=1e-5), (index, r)
            missed += 1
    assert met > 40 and missed > 40, (met, missed)

    cloud = noisy[-1]
    scattered = []
    for index, point in enumerate(cloud.points):
        wall = on_wall(*ray(index), 0.05)
        if wall:
            scattered.append(point.x - WALL)
            assert abs(point.x - WALL) <= 6 * NOISE, (index, point)
        elif wall is False:
            assert norm(point) == pytest.approx(MAX_RANGE, abs=1e-5), (index, point)
    assert len(set(scattered)) == len(scattered) > 20
    intensities = cloud.channels[0].values
    assert len(set(intensities)) == len(intensities)
    assert all(abs(value) <= 6 * NOISE for value in intensities)


# A block laser looking straight down (its x axis along the world's -z) from DOWN_HEIGHT, the
# shape of upstream's block_laser_clipping world: 0.4 to 1 m, 0.6 rad by 0.8 rad.
DOWN_HEIGHT, DOWN_MIN, DOWN_MAX = 0.8, 0.4, 1.0
DOWN_COLUMNS, DOWN_ROWS = 7, 9
DOWN_YAW, DOWN_PITCH = 0.3, 0.4
LOOKING_DOWN_SDF = """<sdf version="1.6"><model name="looking_down"><static>true</static>
<link name="link"><sensor type="ray" name="down">
  <pose>0 0 0 0 1.5707963267948966 0</pose>
  <update_rate>10</update_rate>
  <ray>
    <scan>
      <horizontal><samples>{columns}</samples><resolution>1</resolution>
        <min_angle>-{yaw}</min_angle><max_angle>{yaw}</max_angle></horizontal>
      <vertical><samples>{rows}</samples><resolution>1</resolution>
        <min_angle>-{pitch}</min_angle><max_angle>{pitch}</max_angle></vertical>
    </scan>
    <range><min>{min_range}</min><max>{max_range}</max><resolution>0.001</resolution></range>
  </ray>
  <plugin name="down_plugin" filename="libgazebo_ros_block_laser.so">
    <topicName>down_cloud</topicName><frameName>down_link</frameName></plugin>
</sensor></link></model></sdf>""".format(columns=DOWN_COLUMNS, rows=DOWN_ROWS, yaw=DOWN_YAW,
                                        pitch=DOWN_PITCH, min_range=DOWN_MIN,
                                        max_range=DOWN_MAX)


@pytest.mark.parametrize('ground', [True, False], ids=['with_ground_plane', 'without_ground'])
def test_a_block_laser_looking_down_sees_the_ground_plane_only_where_the_world_has_it(
        shared_sim, ros, rospy_client, ground):
    from sensor_msgs.msg import PointCloud
    api = shared_sim
    if not ground:
        deleted = api.delete_model(GROUND)
        assert deleted.success, deleted.status_message
    spawned = api.spawn_sdf_model('looking_down', LOOKING_DOWN_SDF, '', pose(z=DOWN_HEIGHT), '')
    assert spawned.success, spawned.status_message
    heard = listen(ros, rospy_client, '/down_cloud', PointCloud)
    assert api.step_simulation(100).success
    wait_until(lambda: heard and heard[-1].header.stamp.to_nsec() >= 100000000, 30,
               what='the cloud at 100 ms')
    cloud = heard[-1]
    assert len(cloud.points) == DOWN_COLUMNS * DOWN_ROWS
    for index, point in enumerate(cloud.points):
        row, column = divmod(index, DOWN_COLUMNS)
        yaw = -DOWN_YAW + column * 2 * DOWN_YAW / (DOWN_COLUMNS - 1)
        pitch = -DOWN_PITCH + row * 2 * DOWN_PITCH / (DOWN_ROWS - 1)
        # The ray's component along the sensor's x axis, the world's -z, is cos(pitch) cos(yaw):
        # the ground is DOWN_HEIGHT / that along it, within the 1 m range for every ray.
        expected = DOWN_HEIGHT / (math.cos(pitch) * math.cos(yaw)) if ground else DOWN_MAX
        assert norm(point) == pytest.approx(expected, abs=1e-3), (index, point)
        assert point.x == pytest.approx(expected * math.cos(pitch) * math.cos(yaw), abs=1e-3), \
            (index, point)
