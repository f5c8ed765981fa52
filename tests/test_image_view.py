"""The book's `rosrun image_view image_view image:=/camera/image_raw`, and image_view's nodelet form
(`rosrun nodelet nodelet standalone image_view/image`), over real ROS on a private Xvfb: the
simulated camera (tests/robots/kinect_bot.urdf's camera, its cameraName `camera`) looks at a red
box 2 m ahead over the default world's ground, and the window shows its image pixel for pixel, the
box where the camera's geometry puts it; found in a screenshot of the whole screen."""
import numpy
import pytest

from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from onedof_sim.tutorial.rviz_view import start_xvfb
from test_camera import (BACKGROUND, BOX, CAMERA, FACE_X, GROUND_GREY, HEIGHT, WIDTH, box_sdf,
                         kinect_bot_urdf, predicted_columns, rgb)
from test_rviz_sensors import grab

TOPIC = '/camera/image_raw'
# The box's red in the image (Gazebo/Red turned from the sun), and in the screenshot.
is_red = lambda pixels: (pixels[..., 0] > 80) & (pixels[..., 1] < 30) & (pixels[..., 2] < 30)


def camera_before_the_box(ros, rospy):
    """The simulator running with the robot (its camera named `camera`, as the book's command
    has it) and the box 2 m ahead of the camera; returns an image the camera published."""
    from sensor_msgs.msg import Image
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy)
    urdf = kinect_bot_urdf().replace('<cameraName>example_camera</cameraName>',
                                     '<cameraName>camera</cameraName>')
    spawned = api.spawn_urdf_model('kinect_bot', urdf, '', pose(), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_sdf_model('red_box', box_sdf(), '',
                                  pose(FACE_X + BOX['half'], BOX['y'], BOX['z']), '')
    assert spawned.success, spawned.status_message
    return rospy.wait_for_message(TOPIC, Image, timeout=120)


def red_box(pixels):
    """The first and last rows and columns of the red pixels, or None."""
    rows = numpy.flatnonzero(is_red(pixels).any(axis=1))
    columns = numpy.flatnonzero(is_red(pixels).any(axis=0))
    return (rows[0], rows[-1], columns[0], columns[-1]) if len(rows) else None


def shown_in(screenshot):
    """Where the window shows the camera's image in the screenshot, scaled to the window as
    image_view's window (OpenCV's, not sized to the image) scales it: the screen's rows and columns
    the image's sky, ground and box fill most of ((top, bottom, left, right)), and the red box's,
    as ((top, bottom, left, right), (box's top, bottom, left, right)); None while neither shows."""
    import matplotlib.image
    screen = (matplotlib.image.imread(str(screenshot))[..., :3] * 255).round().astype(int)
    image = (numpy.all(screen == BACKGROUND, axis=2) | numpy.all(screen == GROUND_GREY, axis=2) |
             is_red(screen))
    rows = numpy.flatnonzero(image.sum(axis=1) > 100)
    columns = numpy.flatnonzero(image.sum(axis=0) > 100)
    box = red_box(screen)
    if box is None or not len(rows) or not len(columns):
        return None
    return (rows[0], rows[-1], columns[0], columns[-1]), box


@pytest.mark.parametrize('command', [
    ['rosrun', 'image_view', 'image_view', 'image:=' + TOPIC],
    ['rosrun', 'nodelet', 'nodelet', 'standalone', 'image_view/image', 'image:=' + TOPIC],
], ids=['image_view', 'nodelet'])
def test_image_view_shows_the_simulated_camera(ros, rospy_client, tmp_path, command):
    image = rgb(camera_before_the_box(ros, rospy_client))
    # The camera sees the box's near face in the columns its geometry predicts (the image the
    # window must show, below).
    row = red_box(image)
    assert abs(row[2] - predicted_columns(CAMERA['fov'])[0]) <= 1, row
    assert abs(row[3] - predicted_columns(CAMERA['fov'])[1]) <= 1, row
    # Above the horizon the sky, below it the ground: the image's top and bottom rows.
    assert numpy.all(image[0] == BACKGROUND) and numpy.all(image[-1] == GROUND_GREY)

    _, display = start_xvfb(ros)
    viewer = ros.start(command, name='image_view', env={'DISPLAY': display})
    png = str(tmp_path / 'screen.png')

    def on_screen():
        assert viewer.poll() is None, 'image_view exited:\n' + ros.log_text(viewer)
        return grab(display, png) and shown_in(png)
    area, box = ros.wait_until(on_screen, 300, interval=0.5,
                               what='the camera image in the image_view window')
    # The whole image, its aspect kept, and the box in it where the image has it: each edge
    # within two of the screen's pixels.
    scale = (area[3] - area[2] + 1) / WIDTH
    assert abs((area[1] - area[0] + 1) - scale * HEIGHT) <= 2, (area, scale)
    expected = red_box(image)
    for edge, (screen_at, image_at) in enumerate(zip(box, expected)):
        origin = area[0] if edge < 2 else area[2]
        last = edge % 2  # a last row or column: its far side is where the next one starts
        assert abs(screen_at - (origin + scale * (image_at + last) - last)) <= 2, \
            (edge, box, expected, area, scale)
    log = ros.log_text(viewer)
    assert 'not found' not in log and 'Exception' not in log, log
