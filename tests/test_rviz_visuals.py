"""The simulator's view (gzclient: rviz on gazebo_ros/rviz/world.rviz) draws the world's visuals
in their materials' colours where the models stand, over real ROS on a private Xvfb: a Gazebo/Green
box shows green pixels where the view's camera projects it and nowhere else in the 3D panel."""
from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from onedof_sim.tutorial.rviz_view import start_xvfb
from test_camera import box_sdf
from test_rviz_sensors import WORLD_RVIZ, region_around, screenshot_with, subscribers
from test_tutorial import count_pixels

HALF = 0.25  # the box's half side (box_sdf's 0.5 m)
# Gazebo/Green lit by rviz's light: green, the other channels dark (the grey ground and the
# dark background are neither).
green = lambda r, g, b: (g > 90) & (r < 50) & (b < 50)


def test_the_view_draws_a_green_box_in_green_where_it_stands(ros, rospy_client, tmp_path):
    start_sim(ros, ENGINES[0])
    xvfb, display = start_xvfb(ros)
    view = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                     env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
    ros.wait_until(lambda: subscribers(ros, '/gazebo/visual_markers', '/gzclient_'), 120,
                   what='the view to subscribe to the visual markers')
    api = GazeboApi(rospy_client)
    spawned = api.spawn_sdf_model('green_box', box_sdf('green_box', 2 * HALF, 'Gazebo/Green'), '',
                                  pose(1, 0.5, HALF), '')
    assert spawned.success, spawned.status_message
    with open(WORLD_RVIZ) as f:
        config = f.read()
    corners = [(1 + dx, 0.5 + dy, HALF + dz) for dx in (-HALF, HALF) for dy in (-HALF, HALF)
               for dz in (-HALF, HALF)]
    png = tmp_path / 'view.png'
    panel = screenshot_with(
        ros, display, png,
        lambda png, panel: count_pixels(png, region_around(config, panel, corners), green) > 500,
        'the green box in the view')
    assert count_pixels(png, panel, green) == count_pixels(
        png, region_around(config, panel, corners), green), 'green off the box'
    ros.terminate(view)  # rviz before its X server
    ros.terminate(xvfb)
