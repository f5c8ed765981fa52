"""The simulator's view (gzclient: rviz on gazebo_ros/rviz/world.rviz) draws the world's visuals
in their materials' colours where the models stand, over real ROS on a private Xvfb: a Gazebo/Green
box shows green pixels where the view's camera projects it and nowhere else in the 3D panel. An
rviz that crashes (as Mesa's software renderer now and then makes it) is started again by the view
and draws the same; an rviz that is closed ends the view."""
import signal

from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from onedof_sim.tutorial.rviz_view import start_xvfb
from test_camera import box_sdf
from test_rviz_sensors import WORLD_RVIZ, region_around, screenshot_with, subscribers
from test_tutorial import count_pixels
from test_tutorial_rviz_failure import rviz_processes

HALF = 0.25  # the box's half side (box_sdf's 0.5 m)
# Gazebo/Green lit by rviz's light: green, the other channels dark (the grey ground and the
# dark background are neither).
green = lambda r, g, b: (g > 90) & (r < 50) & (b < 50)


def start_view(ros, display, may_exit=False):
    view = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                     env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'}, may_exit=may_exit)
    ros.wait_until(lambda: subscribers(ros, '/gazebo/visual_markers', '/gzclient_'), 120,
                   what='the view to subscribe to the visual markers')
    return view


def spawn_green_box(rospy_client):
    api = GazeboApi(rospy_client)
    spawned = api.spawn_sdf_model('green_box', box_sdf('green_box', 2 * HALF, 'Gazebo/Green'), '',
                                  pose(1, 0.5, HALF), '')
    assert spawned.success, spawned.status_message


def assert_green_box_shown(ros, display, png):
    with open(WORLD_RVIZ) as f:
        config = f.read()
    corners = [(1 + dx, 0.5 + dy, HALF + dz) for dx in (-HALF, HALF) for dy in (-HALF, HALF)
               for dz in (-HALF, HALF)]
    panel = screenshot_with(
        ros, display, png,
        lambda png, panel: count_pixels(png, region_around(config, panel, corners), green) > 500,
        'the green box in the view')
    assert count_pixels(png, panel, green) == count_pixels(
        png, region_around(config, panel, corners), green), 'green off the box'


def test_the_view_draws_a_green_box_in_green_where_it_stands(ros, rospy_client, tmp_path):
    start_sim(ros, ENGINES[0])
    xvfb, display = start_xvfb(ros)
    view = start_view(ros, display)
    spawn_green_box(rospy_client)
    assert_green_box_shown(ros, display, tmp_path / 'view.png')
    ros.terminate(view)  # rviz before its X server
    ros.terminate(xvfb)


def test_a_crashed_rviz_is_started_again_and_a_closed_one_ends_the_view(ros, rospy_client,
                                                                        tmp_path):
    start_sim(ros, ENGINES[0])
    xvfb, display = start_xvfb(ros)
    view = start_view(ros, display, may_exit=True)
    spawn_green_box(rospy_client)
    crashed = ros.wait_until(lambda: rviz_processes(view), 60, what="the view's rviz")[0]
    crashed.send_signal(signal.SIGSEGV)
    said = 'gzclient: rviz crashed (status -11, SIGSEGV); starting it again on the same ' \
           'configuration (restart 1 of at most 3)'
    ros.wait_until(lambda: said in ros.log_text(view), 120, what='the view to say: ' + said)
    restarted = ros.wait_until(
        lambda: [proc for proc in rviz_processes(view) if proc.pid != crashed.pid], 120,
        what='a new rviz')[0]
    assert_green_box_shown(ros, display, tmp_path / 'view.png')
    assert view.poll() is None
    # Closed, not crashed: the view ends with it.
    restarted.send_signal(signal.SIGTERM)
    ros.wait_until(lambda: view.poll() is not None, 120, what='the view to end with its rviz')
    assert 'restart 2' not in ros.log_text(view)
    ros.terminate(xvfb)
