"""The stereo camera over real ROS, on every engine: libgazebo_ros_multicamera.so on a
`multicamera` sensor, on a camera of our own making shaped as the book's multi_camera_model.xacro
(tests/robots/stereo_bot.urdf: cameraName stereo_camera, the sensor on a massless link, a 0.1 m
baseline). Facing a red box whose near face is 1 m ahead: Gazebo's topic and frame names, one stamp
for the pair at each update, the right camera's CameraInfo carrying -f B in P[3], and the box's
edges in the two images a disparity of f B / Z apart, within one pixel. A multicamera whose
cameras Gazebo's plugin cannot name is refused, by name, once, and the world runs on."""
import math
import os

import numpy
import pytest

from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from test_camera import box_sdf, hear_periods, red_columns, rgb
from test_camera_formats import cameras_urdf

URDF = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'robots', 'stereo_bot.urdf')
WIDTH, HEIGHT, FOV = 640, 480, 1.0
FOCAL = WIDTH / (2 * math.tan(FOV / 2))
LEFT_Y, BASELINE, LENS_Z = 0.05, 0.1, 0.5  # the left lens at (0, 0.05, 0.5), the right 0.1 to -y
DISTANCE = 1.0                             # from the lenses to the box's near face
BOX = {'y': 0.08, 'half': 0.15}            # a 0.3 m red cube, its face's middle at y = 0.08
PERIOD_STEPS = 100                         # the sensor's update_rate, 10 Hz, in 1 ms steps
SIDES = ('left', 'right')


def topics(camera='stereo_camera'):
    from sensor_msgs.msg import CameraInfo, Image
    found = {}
    for side in SIDES:
        found['/%s/%s/image_raw' % (camera, side)] = Image
        found['/%s/%s/camera_info' % (camera, side)] = CameraInfo
    return found


def predicted_columns(lens_y):
    """The first and last columns whose centres look at the box's face, for a lens at lens_y:
    pixel u's centre looks along (1, -(u + 0.5 - W / 2) / f, ...) in the camera frame."""
    left_edge = WIDTH / 2 - FOCAL * (BOX['y'] + BOX['half'] - lens_y) / DISTANCE
    right_edge = WIDTH / 2 - FOCAL * (BOX['y'] - BOX['half'] - lens_y) / DISTANCE
    return math.ceil(left_edge - 0.5), math.floor(right_edge - 0.5)


def record(ros, rospy, engine, periods, urdf=None, extra=None):
    """A paused lock-step simulator with the stereo camera and the box (and `extra`'s URDF
    models), every stereo topic subscribed, stepped one update period at a time: the simulator
    and what each topic heard."""
    sim = start_sim(ros, engine, args=['_paused:=true', '_lockstep:=true'])
    api = GazeboApi(rospy)
    if urdf is None:
        with open(URDF) as f:
            urdf = f.read()
    spawned = api.spawn_urdf_model('stereo_bot', urdf, '', pose(), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_sdf_model('red_box', box_sdf(size=2 * BOX['half']), '',
                                  pose(DISTANCE + BOX['half'], BOX['y'], LENS_Z), '')
    assert spawned.success, spawned.status_message
    for name, model in (extra or {}).items():
        spawned = api.spawn_urdf_model(name, model, '', pose(), '')
        assert spawned.success, spawned.status_message
    return sim, hear_periods(ros, rospy, api, topics(), periods, PERIOD_STEPS)


# A multicamera with a camera of neither name and two that would both publish as left.
MISNAMED_URDF = cameras_urdf(["""  <gazebo reference="camera_link">
    <sensor type="multicamera" name="twin_lefts">
      <camera name="middle"><image><width>64</width><height>48</height></image></camera>
      <camera name="left_a"><image><width>64</width><height>48</height></image></camera>
      <camera name="left_b"><image><width>64</width><height>48</height></image></camera>
      <plugin name="twin_controller" filename="libgazebo_ros_multicamera.so">
        <cameraName>twins</cameraName>
      </plugin>
    </sensor>
  </gazebo>
"""])


@pytest.mark.parametrize('engine', ENGINES)
def test_the_stereo_pair_sees_the_box_with_the_disparity_f_b_over_z(ros, rospy_client, engine):
    sim, heard = record(ros, rospy_client, engine, 2, extra={'misnamed_stereo': MISNAMED_URDF})
    # Every topic at every update, the pair at one stamp.
    for topic, messages in heard.items():
        assert [m.header.stamp.to_nsec() for m in messages] == \
            [n * PERIOD_STEPS * 1000000 for n in (1, 2)], topic
        assert all(m.header.frame_id == 'left_camera_optical_frame' for m in messages), topic

    images = {side: heard['/stereo_camera/%s/image_raw' % side][-1] for side in SIDES}
    for image in images.values():
        assert (image.width, image.height, image.encoding, image.step) == \
            (WIDTH, HEIGHT, 'rgb8', WIDTH * 3)
    # CameraInfo as gazebo_ros_camera_utils fills it: the right camera's P[3] is -f B.
    for side, baseline in (('left', 0.0), ('right', BASELINE)):
        info = heard['/stereo_camera/%s/camera_info' % side][-1]
        assert list(info.P) == pytest.approx(
            [FOCAL, 0, (WIDTH + 1) / 2, -FOCAL * baseline, 0, FOCAL, (HEIGHT + 1) / 2, 0,
             0, 0, 1, 0], rel=1e-12), side

    # The box's edges in each image where each lens's geometry puts them, and a disparity of
    # f B / Z between the images.
    row = HEIGHT // 2
    edges = {side: red_columns(images[side], row) for side in SIDES}
    for side, lens_y in (('left', LEFT_Y), ('right', LEFT_Y - BASELINE)):
        expected = predicted_columns(lens_y)
        assert all(abs(a - b) <= 1 for a, b in zip(edges[side], expected)), \
            (side, edges[side], expected)
    disparity = FOCAL * BASELINE / DISTANCE
    for edge in (0, 1):
        measured = edges['left'][edge] - edges['right'][edge]
        assert abs(measured - disparity) <= 1, (edge, measured, disparity)
    # The rows agree: a horizontal baseline moves nothing up or down.
    left_red = numpy.all(rgb(images['left']) == (102, 0, 0), axis=2)
    right_red = numpy.all(rgb(images['right']) == (102, 0, 0), axis=2)
    assert numpy.array_equal(numpy.flatnonzero(left_red.any(axis=1)),
                             numpy.flatnonzero(right_red.any(axis=1)))

    # The misnamed multicamera: refused at spawn, by name, once; the world ran on (above).
    log = ros.log_text(sim)
    assert log.count("libgazebo_ros_multicamera.so for model 'misnamed_stereo': sensor "
                     "'twin_lefts' not started: cameras 'left_a' and 'left_b' would both publish "
                     "as left") == 1, log
    assert log.count("camera 'middle' has neither 'left' nor 'right' in its name") == 1, log
