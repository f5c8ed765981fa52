"""Cameras over real ROS, on every engine: libgazebo_ros_camera.so on a camera sensor and
libgazebo_ros_openni_kinect.so (and libgazebo_ros_depth_camera.so) on a depth sensor, on a base of
our own making that carries them as the book's mobot does (tests/robots/kinect_bot.urdf). Facing
a red box 2 m ahead over the default world's ground: the box fills the image columns its angular
extent predicts for the field of view, the depth image gives its distance within 1 cm, the point
cloud's points on it lie on its face in the optical frame and those on the ground at z = 0,
CameraInfo's K is the field of view's; in lock-step two runs publish
the same bytes; a malformed camera sensor is refused, by name, once, and the world runs on."""
import math
import os
import struct

import numpy
import pytest

from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from onedof_harness.private_ros import wait_until

URDF = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'robots', 'kinect_bot.urdf')
WIDTH, HEIGHT = 640, 480
CAMERA = {'x': 0.1, 'z': 0.5, 'fov': 1.0}    # camera_link in the world, its horizontal_fov
KINECT = {'x': 0.1, 'z': 0.56, 'fov': 1.047}  # kinect_link
DISTANCE = 2.0                        # from both lenses to the box's near face
BOX = {'y': 0.2, 'z': 0.5, 'half': 0.25}      # a 0.5 m red cube, off to the cameras' left
FACE_X = CAMERA['x'] + DISTANCE
PERIOD_STEPS = 100                    # the plugins' updateRate, 10 Hz, in 1 ms steps
RED = (102, 0, 0)                     # Gazebo/Red's face turned from the sun: ambient 0.4
BACKGROUND = (178,) * 3               # Gazebo's sky: the scene's background, 0.7 grey
# The ground (the default world's ground_plane, Gazebo/Grey: ambient 0.3, diffuse 0.7) under the
# scene's ambient 0.4 and the sun's diffuse 0.8, which falls on it from 0.9 / |(-0.5, 0.1, -0.9)|
# of overhead.
GROUND_GREY = (round(255 * (0.3 * 0.4 + 0.7 * 0.8 * 0.9 / math.sqrt(0.25 + 0.01 + 0.81))),) * 3


def box_sdf(name='red_box', size=0.5, material='Gazebo/Red'):
    return """<sdf version="1.6"><model name="%s"><static>true</static><link name="link">
<visual name="visual"><geometry><box><size>%g %g %g</size></box></geometry>
<material><script><uri>file://media/materials/scripts/gazebo.material</uri><name>%s</name>
</script></material></visual>
<collision name="collision"><geometry><box><size>%g %g %g</size></box></geometry></collision>
</link></model></sdf>""" % ((name,) + (size,) * 3 + (material,) + (size,) * 3)


BALL_SDF = """<sdf version="1.6"><model name="ball"><link name="link"><inertial><mass>0.5</mass>
<inertia><ixx>0.002</ixx><iyy>0.002</iyy><izz>0.002</izz></inertia></inertial>
<visual name="visual"><geometry><sphere><radius>0.1</radius></sphere></geometry>
<material><script><uri>file://media/materials/scripts/gazebo.material</uri>
<name>Gazebo/Green</name></script></material></visual>
<collision name="collision"><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>
</link></model></sdf>"""

# Two camera sensors the simulator refuses, and one it has no plugin for.
MALFORMED_URDF = """<robot name="bad_cameras">
  <link name="world"/>
  <joint name="weld" type="fixed"><parent link="world"/><child link="body"/></joint>
  <link name="body">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <gazebo reference="body">
    <sensor type="camera" name="fisheye">
      <camera><horizontal_fov>4.0</horizontal_fov></camera>
      <plugin name="fisheye_controller" filename="libgazebo_ros_camera.so">
        <cameraName>fisheye</cameraName>
      </plugin>
    </sensor>
  </gazebo>
  <gazebo reference="body">
    <sensor type="camera" name="grey">
      <camera><image><width>64</width><height>48</height><format>FLOAT32</format></image></camera>
      <plugin name="grey_controller" filename="libgazebo_ros_camera.so">
        <cameraName>grey</cameraName>
      </plugin>
    </sensor>
  </gazebo>
</robot>"""


def kinect_bot_urdf(depth_plugin='libgazebo_ros_openni_kinect.so', camera_noise=0.0):
    """The robot, its depth sensor's plugin and its camera's image noise (stddev) as given."""
    with open(URDF) as f:
        urdf = f.read().replace('libgazebo_ros_openni_kinect.so', depth_plugin)
    assert urdf.count('<stddev>0.0</stddev>') == 1
    return urdf.replace('<stddev>0.0</stddev>', '<stddev>%r</stddev>' % camera_noise)


def focal(fov):
    return WIDTH / (2 * math.tan(fov / 2))


class Listener:
    """Every message of each topic, in order."""

    def __init__(self, ros, rospy, topics):
        self.heard = {topic: [] for topic in topics}
        self.subscribers = [rospy.Subscriber(topic, kind, self.heard[topic].append,
                                             queue_size=1000)
                            for topic, kind in topics.items()]
        # Connected as the running simulator says: a subscriber's own count can still hold its
        # connection to a simulator stopped before.
        for topic in topics:
            wait_until(lambda: ros.connected('/gazebo', topic, rospy.get_name()), 30,
                       what='%s to connect' % topic)

    def stop(self):
        for subscriber in self.subscribers:
            subscriber.unregister()


def topics():
    from sensor_msgs.msg import CameraInfo, Image, PointCloud2
    return {'/example_camera/image_raw': Image, '/example_camera/camera_info': CameraInfo,
            '/kinect/rgb/image_raw': Image, '/kinect/rgb/camera_info': CameraInfo,
            '/kinect/depth/image_raw': Image, '/kinect/depth/camera_info': CameraInfo,
            '/kinect/depth/points': PointCloud2}


def record(ros, rospy, engine, periods, depth_plugin='libgazebo_ros_openni_kinect.so',
           ball=False, extra=None, camera_noise=0.0):
    """Starts a paused lock-step simulator, spawns the robot, the box (and the ball, dropped in
    front of the cameras; and `extra`'s URDF models), subscribes to every camera topic and steps
    one publication period at a time: what each topic heard."""
    sim = start_sim(ros, engine, args=['_paused:=true', '_lockstep:=true'])
    api = GazeboApi(rospy)
    spawned = api.spawn_urdf_model('kinect_bot', kinect_bot_urdf(depth_plugin, camera_noise), '',
                                   pose(), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_sdf_model('red_box', box_sdf(), '',
                                  pose(FACE_X + BOX['half'], BOX['y'], BOX['z']), '')
    assert spawned.success, spawned.status_message
    if ball:
        spawned = api.spawn_sdf_model('ball', BALL_SDF, '', pose(1.2, -0.1, 0.9), '')
        assert spawned.success, spawned.status_message
    for name, urdf in (extra or {}).items():
        spawned = api.spawn_urdf_model(name, urdf, '', pose(), '')
        assert spawned.success, spawned.status_message
    return sim, hear_periods(ros, rospy, api, topics(), periods)


def hear_periods(ros, rospy, api, topics, periods, steps=PERIOD_STEPS):
    """Subscribes to `topics` and steps the paused simulator `steps` at a time until every topic
    heard once a time, `periods` times: what each heard."""
    listener = Listener(ros, rospy, topics)
    for count in range(1, periods + 1):
        assert api.step_simulation(steps).success
        wait_until(lambda: all(len(heard) >= count for heard in listener.heard.values()), 60,
                   what='period %d on every topic' % count)
    listener.stop()
    return listener.heard


def rgb(image):
    return numpy.frombuffer(image.data, dtype=numpy.uint8).reshape(image.height, image.width, 3)


def red_columns(image, row):
    pixels = rgb(image)[row]
    red = [u for u in range(image.width) if tuple(pixels[u]) == RED]
    assert red, 'no red pixel in row %d' % row
    assert red == list(range(red[0], red[-1] + 1)), 'the red span has holes'
    return red[0], red[-1]


def predicted_columns(fov):
    """The first and last columns whose centres look at the box's near face: pixel u's centre
    looks along (1, -(u + 0.5 - W / 2) / f, ...) in the camera frame (+y to the image's left)."""
    f = focal(fov)
    left_y, right_y = BOX['y'] + BOX['half'], BOX['y'] - BOX['half']
    left_edge = WIDTH / 2 - f * left_y / DISTANCE   # u + 0.5 at the box's left edge
    right_edge = WIDTH / 2 - f * right_y / DISTANCE
    return math.ceil(left_edge - 0.5), math.floor(right_edge - 0.5)


def assert_camera_info(info, fov, frame_id, baseline=0.0, distortion=(0.0,) * 5):
    f = focal(fov)
    assert info.header.frame_id == frame_id
    assert (info.width, info.height) == (WIDTH, HEIGHT)
    assert info.distortion_model == 'plumb_bob'
    assert list(info.D) == pytest.approx(list(distortion), abs=1e-12)
    # Gazebo's principal point: ((width + 1) / 2, (height + 1) / 2).
    assert list(info.K) == pytest.approx([f, 0, (WIDTH + 1) / 2, 0, f, (HEIGHT + 1) / 2, 0, 0, 1],
                                         rel=1e-12)
    assert list(info.R) == [1, 0, 0, 0, 1, 0, 0, 0, 1]
    assert list(info.P) == pytest.approx([f, 0, (WIDTH + 1) / 2, -f * baseline,
                                          0, f, (HEIGHT + 1) / 2, 0, 0, 0, 1, 0], rel=1e-12)


def depths(image):
    assert image.encoding == '32FC1' and image.step == image.width * 4
    return numpy.frombuffer(image.data, dtype='<f4').reshape(image.height, image.width)


def cloud_points(cloud):
    """x, y, z (float32) and the three rgb bytes of each point, row after row."""
    raw = numpy.frombuffer(cloud.data, dtype=numpy.uint8).reshape(-1, cloud.point_step)
    xyz = raw[:, 0:12].copy().view('<f4').reshape(-1, 3)
    return xyz, raw[:, 16:19]


@pytest.mark.parametrize('engine', ENGINES)
def test_the_camera_and_the_kinect_see_the_red_box_where_the_geometry_puts_it(
        ros, rospy_client, engine):
    sim, heard = record(ros, rospy_client, engine, 2, extra={'bad_cameras': MALFORMED_URDF})
    for topic, messages in heard.items():
        assert [m.header.stamp.to_nsec() for m in messages] == \
            [n * PERIOD_STEPS * 1000000 for n in (1, 2)], topic

    # The camera: rgb8 in camera_link, the box in the columns its field of view predicts.
    image = heard['/example_camera/image_raw'][-1]
    assert (image.width, image.height, image.encoding, image.step, image.is_bigendian) == \
        (WIDTH, HEIGHT, 'rgb8', WIDTH * 3, 0)
    assert image.header.frame_id == 'camera_link'
    first, last = red_columns(image, HEIGHT // 2)
    expected = predicted_columns(CAMERA['fov'])
    assert abs(first - expected[0]) <= 1 and abs(last - expected[1]) <= 1, \
        ((first, last), expected)
    assert tuple(rgb(image)[0][0]) == (178, 178, 178)  # Gazebo's grey background above it
    assert_camera_info(heard['/example_camera/camera_info'][-1], CAMERA['fov'], 'camera_link',
                       distortion=(0.01, 0.02, 0.004, 0.005, 0.03))

    # The Kinect's colour image: its wider field of view puts the box in other columns.
    kinect_image = heard['/kinect/rgb/image_raw'][-1]
    assert kinect_image.header.frame_id == 'kinect_depth_frame'
    first, last = red_columns(kinect_image, HEIGHT // 2)
    expected = predicted_columns(KINECT['fov'])
    assert abs(first - expected[0]) <= 1 and abs(last - expected[1]) <= 1, \
        ((first, last), expected)
    for topic in ('/kinect/rgb/camera_info', '/kinect/depth/camera_info'):
        assert_camera_info(heard[topic][-1], KINECT['fov'], 'kinect_depth_frame', baseline=0.07)

    # Its depth image: the face's distance within 1 cm on the box, NaN past the 5 m cutoff (the
    # sky); the bottom row on the ground (the default world's ground_plane) at the depth its
    # geometry gives: the Kinect's height h over the ray's drop, h f / (v + 0.5 - H / 2).
    depth = depths(heard['/kinect/depth/image_raw'][-1])
    red = numpy.all(rgb(kinect_image) == RED, axis=2)
    assert red.sum() > 10000
    assert numpy.all(numpy.abs(depth[red] - DISTANCE) <= 0.01), depth[red]
    assert numpy.isnan(depth[0][0])
    floor_depth = KINECT['z'] * focal(KINECT['fov']) / (HEIGHT / 2 - 0.5)
    assert numpy.all(numpy.abs(depth[HEIGHT - 1] - floor_depth) <= 0.01), depth[HEIGHT - 1]

    # Its point cloud: Gazebo's fields, NaN where the depth image is, the box's points on its
    # face in the optical frame (x right, y down, z ahead) with the image's bytes for colour.
    cloud = heard['/kinect/depth/points'][-1]
    assert cloud.header.frame_id == 'kinect_depth_frame'
    assert [(f.name, f.offset, f.datatype, f.count) for f in cloud.fields] == \
        [('x', 0, 7, 1), ('y', 4, 7, 1), ('z', 8, 7, 1), ('rgb', 16, 7, 1)]
    assert (cloud.width, cloud.height, cloud.point_step, cloud.row_step, cloud.is_dense) == \
        (WIDTH, HEIGHT, 32, 32 * WIDTH, False)
    xyz, colours = cloud_points(cloud)
    on_box = red.reshape(-1)
    assert numpy.array_equal(numpy.isnan(xyz[:, 2]), numpy.isnan(depth.reshape(-1)))
    assert numpy.all(colours[on_box] == RED)
    box_xyz = xyz[on_box]
    assert numpy.all(numpy.abs(box_xyz[:, 2] - DISTANCE) <= 0.01)
    margin = 0.01
    # The face spans world y in [-0.05, 0.45] (optical x = -y) and z in [0.25, 0.75] (optical
    # y = kinect z - z).
    assert numpy.all(box_xyz[:, 0] >= -(BOX['y'] + BOX['half']) - margin)
    assert numpy.all(box_xyz[:, 0] <= -(BOX['y'] - BOX['half']) + margin)
    assert numpy.all(box_xyz[:, 1] >= KINECT['z'] - (BOX['z'] + BOX['half']) - margin)
    assert numpy.all(box_xyz[:, 1] <= KINECT['z'] - (BOX['z'] - BOX['half']) + margin)
    assert box_xyz[:, 0].min() < -0.4 and box_xyz[:, 0].max() > 0.0  # it spans the face
    # The ground's points (its grey, within the cutoff) lie on the floor, world z = 0: optical
    # y = the Kinect's height.
    on_ground = numpy.all(rgb(kinect_image) == GROUND_GREY, axis=2).reshape(-1) & \
        ~numpy.isnan(xyz[:, 2])
    assert on_ground.sum() > 10000
    assert numpy.all(numpy.abs(xyz[on_ground, 1] - KINECT['z']) <= 0.01)

    # The malformed cameras: refused at spawn, by name, once; the world ran on (above).
    log = ros.log_text(sim)
    assert log.count("libgazebo_ros_camera.so for model 'bad_cameras': sensor 'fisheye' not "
                     "started: <camera><horizontal_fov> is 4.0 rad") == 1, log
    assert log.count("sensor 'grey' not started: <image><format> is 'FLOAT32'") == 1, log


@pytest.mark.parametrize('engine', ENGINES[:1])
def test_the_depth_camera_keeps_depths_past_the_kinects_far_cutoff(ros, rospy_client, engine):
    _, heard = record(ros, rospy_client, engine, 1, depth_plugin='libgazebo_ros_depth_camera.so')
    depth = depths(heard['/kinect/depth/image_raw'][-1])
    red = numpy.all(rgb(heard['/kinect/rgb/image_raw'][-1]) == RED, axis=2)
    assert numpy.all(numpy.abs(depth[red] - DISTANCE) <= 0.01)
    # Nothing there: the far clip, 100 m, which GazeboRosDepthCamera (no pointCloudCutoffMax)
    # keeps and the Kinect's 5 m cutoff makes NaN.
    assert depth[0][0] == 100.0
    xyz, _ = cloud_points(heard['/kinect/depth/points'][-1])
    assert xyz[0][2] == 100.0
    assert_camera_info(heard['/kinect/depth/camera_info'][-1], KINECT['fov'],
                       'kinect_depth_frame', baseline=0.07)


@pytest.mark.parametrize('engine', ENGINES)
def test_two_lockstep_runs_publish_identical_images(ros, rospy_client, engine):
    """With the book's image noise on the camera (stddev 0.007) and a ball falling in view."""
    runs = []
    for _ in range(2):
        sim, heard = record(ros, rospy_client, engine, 6, ball=True, camera_noise=0.007)
        ros.terminate(sim)
        runs.append({topic: [(m.header.stamp.to_nsec(), bytes(m.data)) for m in messages]
                     for topic, messages in heard.items() if hasattr(messages[0], 'data')})
    assert runs[0] == runs[1]
    frames = runs[0]['/example_camera/image_raw']
    assert len({data for _, data in frames}) == len(frames)  # the noise is drawn anew each frame
    # The noise: the grey background (178) spread by about 0.007 x 255 = 1.8 levels.
    background = numpy.frombuffer(frames[0][1], dtype=numpy.uint8).reshape(HEIGHT, WIDTH, 3)
    top_rows = background[:20, :100].astype(float)  # the top left corner: the ball is right
    assert 1.2 < top_rows.std() < 2.4 and abs(top_rows.mean() - 178) < 0.2, top_rows.std()
    assert numpy.all(top_rows[:, :, 0] == top_rows[:, :, 2])  # one value a pixel, every channel
    # The Kinect's images, free of noise, change with the falling ball alone: the corner the ball
    # never crosses is the same in every frame, and the frames differ while it falls (how soon it
    # rests differs by engine: on mujoco it still moves in the last frame).
    kinect = runs[0]['/kinect/rgb/image_raw']
    corners = {numpy.frombuffer(data, dtype=numpy.uint8).reshape(HEIGHT, WIDTH, 3)[:20, :100]
               .tobytes() for _, data in kinect}
    assert len(corners) == 1
    assert len({data for _, data in kinect}) >= 3


def test_without_a_renderer_the_cameras_say_so_once_and_everything_else_runs(ros, rospy_client):
    """libglvnd pointed at no EGL vendor: no renderer can be made. The simulator says so once,
    the cameras publish their CameraInfo and no image, and the world steps on."""
    from sensor_msgs.msg import CameraInfo, Image
    sim = start_sim(ros, ENGINES[0], args=['_paused:=true'],
                    env={'__EGL_VENDOR_LIBRARY_FILENAMES': '/nonexistent/egl_vendor.json'})
    api = GazeboApi(rospy_client)
    spawned = api.spawn_urdf_model('kinect_bot', kinect_bot_urdf(), '', pose(), '')
    assert spawned.success, spawned.status_message
    listener = Listener(ros, rospy_client, {'/example_camera/image_raw': Image,
                                            '/example_camera/camera_info': CameraInfo,
                                            '/kinect/depth/image_raw': Image,
                                            '/kinect/depth/camera_info': CameraInfo})
    for count in (1, 2):
        done = api.step_simulation(PERIOD_STEPS)
        assert done.success and done.iterations == count * PERIOD_STEPS
        wait_until(lambda: len(listener.heard['/example_camera/camera_info']) >= count and
                   len(listener.heard['/kinect/depth/camera_info']) >= count, 30,
                   what='the CameraInfos of period %d' % count)
    listener.stop()
    assert listener.heard['/example_camera/image_raw'] == []
    assert listener.heard['/kinect/depth/image_raw'] == []
    log = ros.log_text(sim)
    assert log.count('cameras: no renderer can be made here (EGL has no surfaceless platform') \
        == 1, log
    assert 'publish no images, and everything else runs as before' in log
