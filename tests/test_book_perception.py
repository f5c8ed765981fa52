"""The book's perception packages' tool chain, over real ROS: a package of our own making in their
shape (tests/book_perception: PCL through pcl_ros, cv_bridge and image_transport with OpenCV,
laser_geometry, tf_conversions, interactive_markers, an action of its own on actionlib_msgs) builds
in an overlay over this workspace, and its node reads the simulated Kinect's cloud
(tests/robots/kinect_bot.urdf, libgazebo_ros_openni_kinect.so) through pcl_ros and finds, with
PCL's RANSAC, the ground (the default world's ground_plane) at z = 0 and then, among the points it
left, the red box's near face, each within 1 cm: asked through its action, shown as interactive
markers. In the same overlay, a package shaped as the book's mobot_gazebo_state
(tests/model_states_reader) includes gazebo_msgs/ModelStates.h without naming gazebo_msgs among its
dependencies, builds, and reads the box's pose from /gazebo/model_states."""
import math
import os
import subprocess

import pytest

from api_client import GazeboApi, pose
from conftest import ENGINES, OVERLAY_TESTS_TIMEOUT, session_folder, start_sim
from onedof_harness import book_client
from test_camera import BOX, DISTANCE, FACE_X, KINECT, box_sdf, kinect_bot_urdf

PACKAGES = ('book_perception', 'model_states_reader')
pytestmark = OVERLAY_TESTS_TIMEOUT


@pytest.fixture
def overlay_setup(tmp_path_factory):
    """The overlay's setup.bash, built once for the session's workers (pytest-forked: no fixture
    outlives a test)."""
    folder = session_folder(tmp_path_factory, 'book_perception')
    return book_client.shared_overlay(folder, PACKAGES)


def in_overlay(setup, command):
    return ['bash', '-c', 'source %s && exec %s' % (setup, command)]


def kinect_before_the_box(ros, rospy):
    """The simulator running with the Kinect robot and the red box whose near face is 2 m ahead
    of the Kinect."""
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy)
    spawned = api.spawn_urdf_model('kinect_bot', kinect_bot_urdf(), '', pose(), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_sdf_model('red_box', box_sdf(), '',
                                  pose(FACE_X + BOX['half'], BOX['y'], BOX['z']), '')
    assert spawned.success, spawned.status_message


def answer(ros, setup, command):
    """The lines `key v1 v2 ...` the overlay's command printed, as {key: [values]}."""
    result = ros.run(in_overlay(setup, command), timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    return {line.split()[0]: line.split()[1:] for line in result.stdout.splitlines() if line}


def test_the_book_shaped_perception_node_finds_the_floor_and_the_box_face_in_the_kinect_cloud(
        ros, rospy_client, overlay_setup):
    from visualization_msgs.msg import InteractiveMarkerInit
    kinect_before_the_box(ros, rospy_client)
    finder = ros.start(in_overlay(overlay_setup, 'rosrun book_perception find_box_plane '
                                  'cloud:=/kinect/depth/points'), name='find_box_plane')
    printed = answer(ros, overlay_setup, 'rosrun book_perception find_plane_client 2')
    assert finder.poll() is None, ros.log_text(finder)
    assert printed['frame'] == ['kinect_depth_frame']

    # In the Kinect's optical frame (x right, y down, z ahead; world y = -optical x, z = kinect
    # z - optical y). The largest plane is the world's ground (the default world's ground_plane,
    # which the Kinect sees below the horizon): its normal facing the sensor is world up,
    # (0, -1, 0), and d the Kinect's height: the floor's points lie at world z = 0, within 1 cm.
    a, b, c, d = (float(v) for v in printed['plane0'])
    assert [a, b, c] == pytest.approx([0, -1, 0], abs=0.005), printed
    assert abs(d - KINECT['z']) <= 0.01, printed
    floor = [float(v) for v in printed['face0']]
    assert abs(KINECT['z'] - floor[1]) <= 0.01, printed
    assert int(printed['inliers0'][0]) > int(printed['inliers1'][0]), printed

    # Among the points the floor left, the box's near face: the plane z = 2 m, its normal facing
    # the sensor, (0, 0, -1) with d = 2.
    a, b, c, d = (float(v) for v in printed['plane1'])
    assert [a, b, c] == pytest.approx([0, 0, -1], abs=0.005), printed
    assert abs(d - DISTANCE) <= 0.01, printed
    # Its inliers: the face's pixels (more than 10000, as tests/test_camera.py counts them), and
    # their centroid the face's middle.
    assert int(printed['inliers1'][0]) > 10000, printed
    face = [float(v) for v in printed['face1']]
    assert face == pytest.approx([-BOX['y'], KINECT['z'] - BOX['z'], DISTANCE], abs=0.01), printed

    # Both as interactive markers: the server's full update.
    init = rospy_client.wait_for_message('/box_plane/update_full', InteractiveMarkerInit,
                                         timeout=60)
    markers = {marker.name: marker for marker in init.markers}
    assert sorted(markers) == ['plane_0', 'plane_1']
    assert {m.header.frame_id for m in markers.values()} == {'kinect_depth_frame'}
    for name, centroid in (('plane_0', floor), ('plane_1', face)):
        p = markers[name].pose.position
        assert [p.x, p.y, p.z] == pytest.approx(centroid, abs=1e-6), name
    # Each x axis along its normal: the floor's (0, -1, 0), a turn of -pi/2 about z; the face's
    # (0, 0, -1), a turn of pi/2 about y.
    for name, expected in (('plane_0', [0, 0, -math.sin(math.pi / 4), math.cos(math.pi / 4)]),
                           ('plane_1', [0, math.sin(math.pi / 4), 0, math.cos(math.pi / 4)])):
        q = markers[name].pose.orientation
        assert [q.x, q.y, q.z, q.w] == pytest.approx(expected, abs=0.005), name


def test_the_image_node_sees_the_red_box_through_image_transport_and_cv_bridge(
        ros, rospy_client, overlay_setup):
    """The overlay's image_and_scan node on the Kinect's colour image: the red columns of the
    middle row, those tests/test_camera.py finds in the image itself."""
    from sensor_msgs.msg import Image
    from test_camera import red_columns
    kinect_before_the_box(ros, rospy_client)
    image = rospy_client.wait_for_message('/kinect/rgb/image_raw', Image, timeout=120)
    expected = red_columns(image, image.height // 2)
    node = ros.start(in_overlay(overlay_setup, 'rosrun book_perception image_and_scan '
                                'image:=/kinect/rgb/image_raw'), name='image_and_scan')
    line = 'red columns %d %d' % expected
    ros.wait_until(lambda: line in ros.log_text(node), 120, what="image_and_scan's " + line)


def test_an_overlay_package_finds_gazebo_msgs_headers_without_naming_the_package(
        ros, rospy_client, overlay_setup):
    kinect_before_the_box(ros, rospy_client)
    printed = answer(ros, overlay_setup, 'rosrun model_states_reader model_pose red_box')
    position = [float(v) for v in printed['position']]
    assert position == pytest.approx([FACE_X + BOX['half'], BOX['y'], BOX['z']], abs=1e-6)


def test_the_workspace_puts_its_message_headers_on_every_builds_include_path():
    """Sourcing the workspace puts its one include folder, where gazebo_msgs' headers are, on
    CPATH once, however often it is sourced (src/gazebo_msgs/env-hooks)."""
    def holding_gazebo_msgs(cpath):
        return [folder for folder in cpath.split(':')
                if os.path.isfile(os.path.join(folder, 'gazebo_msgs', 'ModelStates.h'))]
    [include] = holding_gazebo_msgs(os.environ.get('CPATH', ''))
    setup = os.path.join(os.path.dirname(include), 'setup.bash')
    result = subprocess.run(['bash', '-c', 'source "$1" && source "$1" && echo "$CPATH"', '-',
                             setup], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert holding_gazebo_msgs(result.stdout.strip()) == [include], result.stdout
