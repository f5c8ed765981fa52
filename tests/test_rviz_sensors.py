"""The sensors in rviz, over real ROS on a private Xvfb, with screenshots whose pixels are counted.

The simulator's view (gzclient: rviz on gazebo_ros/rviz/world.rviz) adds a display for each
sensor stream the simulator publishes once a robot carrying the sensor is spawned: the laser of
tests/robots/laser_bot.urdf, 2 m before a box, draws its scan's points on the box's face and
nowhere else. A world without sensors shows world.rviz's displays and no other. The book's way
works too: the user's own rviz with the book's LaserScan display on /scan and fixed frame
base_link (as the book's mobot_w_lidar.rviz has them) shows the same points.
"""
import math
import os
import subprocess

import numpy as np
import yaml

from conftest import ENGINES, start_sim
from api_client import GazeboApi, pose
from onedof_sim.tutorial.rviz_view import start_xvfb
from test_laser import BOX_SDF, FACE_X, HALF_WIDTH, laser_bot_urdf
from test_tutorial import count_pixels

WORLD_RVIZ = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'src',
                          'gazebo_ros', 'rviz', 'world.rviz')
LASER = ('ray', 'libgazebo_ros_laser.so')
LIDAR_Z = 0.3  # the lidar's height (the base is welded at the origin)
# rviz's 3D panel in a 1000 x 720 window (the Xvfb screen) with the Displays panel docked left.
RENDER_PANEL = (364, 62, 984, 690)
# The scan's points are looked for this many pixels around where the box's face projects.
MARGIN = 12
scan_green = lambda r, g, b: (g > 180) & (r < 100) & (b < 100)
coloured = lambda r, g, b: (abs(r - g) + abs(g - b) + abs(r - b)) > 90

BOOK_RVIZ = """
Panels:
  - Class: rviz/Displays
    Name: Displays
Visualization Manager:
  Class: ""
  Displays:
    - Class: rviz/Grid
      Enabled: true
      Name: Grid
      Plane: XY
      Plane Cell Count: 10
      Cell Size: 1
      Reference Frame: <Fixed Frame>
      Value: true
    - Alpha: 1
      Autocompute Intensity Bounds: true
      Axis: Z
      Channel Name: intensity
      Class: rviz/LaserScan
      Color: 255; 255; 255
      Color Transformer: Intensity
      Decay Time: 0
      Enabled: true
      Invert Rainbow: false
      Max Color: 255; 255; 255
      Min Color: 0; 0; 0
      Name: LaserScan
      Position Transformer: XYZ
      Queue Size: 10
      Selectable: true
      Size (Pixels): 3
      Size (m): 0.04
      Style: Spheres
      Topic: /scan
      Use Fixed Frame: true
      Use rainbow: true
      Value: true
  Enabled: true
  Global Options:
    Background Color: 48; 48; 48
    Fixed Frame: base_link
    Frame Rate: 30
  Name: root
  Tools:
    - Class: rviz/Interact
  Value: true
  Views:
    Current:
      Class: rviz/Orbit
      Distance: 5
      Focal Point:
        X: 1.5
        Y: 0
        Z: 0
      Name: Current View
      Pitch: 1.2
      Yaw: 3.14
      Target Frame: <Fixed Frame>
      Value: Orbit (rviz)
    Saved: ~
Window Geometry:
  Height: 720
  Width: 1000
  Hide Left Dock: false
"""


def project(view, point):
    """The pixel (x, y) of the screenshot where rviz's orbit view (a config's Views: Current)
    draws a point of the fixed frame: the camera at Distance from the Focal Point, at Yaw about
    z and Pitch above the x-y plane, looking at it with z up; OGRE's vertical field of view,
    45 degrees, over the render panel."""
    focal = np.array([view['Focal Point'][axis] for axis in 'XYZ'], dtype=float)
    yaw, pitch = view['Yaw'], view['Pitch']
    eye = focal + view['Distance'] * np.array([math.cos(yaw) * math.cos(pitch),
                                               math.sin(yaw) * math.cos(pitch), math.sin(pitch)])
    forward = (focal - eye) / np.linalg.norm(focal - eye)
    right = np.cross(forward, [0, 0, 1])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    offset = np.array(point, dtype=float) - eye
    depth = offset @ forward
    x0, y0, x1, y1 = RENDER_PANEL
    half_height = math.tan(math.pi / 8) * depth
    half_width = half_height * (x1 - x0) / (y1 - y0)
    return (x0 + (x1 - x0) / 2 * (1 + (offset @ right) / half_width),
            y0 + (y1 - y0) / 2 * (1 - (offset @ up) / half_height))


def scan_region(config_text):
    """The screenshot region (x0, y0, x1, y1) around the scan's points on the box's face (from
    y = -0.25 to 0.25 m at x = 2.2 m, the lidar's height) in the view of an rviz config."""
    view = yaml.safe_load(config_text)['Visualization Manager']['Views']['Current']
    ends = [project(view, (FACE_X, y, LIDAR_Z)) for y in (-HALF_WIDTH, HALF_WIDTH)]
    xs, ys = [x for x, _ in ends], [y for _, y in ends]
    return (int(min(xs)) - MARGIN, int(min(ys)) - MARGIN, int(max(xs)) + MARGIN + 1,
            int(max(ys)) + MARGIN + 1)


def grab(display, path):
    """A screenshot of the display's root window at path (in RGB, also while the screen is all
    grey), or None when it could not be taken."""
    result = subprocess.run(['import', '-display', display, '-window', 'root', 'PNG24:%s' % path],
                            capture_output=True, text=True)
    return path if result.returncode == 0 else None


def subscribers(ros, topic, prefix):
    _, _, (_, subscribed, _) = ros.master().getSystemState('/test')
    return [node for name, nodes in subscribed if name == topic for node in nodes
            if node.startswith(prefix)]


def spawn_laser_bot_before_the_box(ros, rospy):
    """The laser bot welded at the origin, its description on the parameter server with
    robot_state_publisher publishing its links' transforms (world -> base_link -> lidar_link),
    and the box 2 m ahead of its lidar."""
    urdf = laser_bot_urdf(*LASER, 0.0)
    ros.set_param('/robot_description', urdf)
    ros.start(['rosrun', 'robot_state_publisher', 'robot_state_publisher'],
              name='robot_state_publisher')
    api = GazeboApi(rospy)
    spawned = api.spawn_urdf_model('laser_bot', urdf, '', pose(), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_sdf_model('wall', BOX_SDF, '', pose(FACE_X + HALF_WIDTH, 0, 0.25), '')
    assert spawned.success, spawned.status_message


def screenshot_with(ros, display, path, region, colour, pixels, what):
    """Screenshots until one has more than `pixels` of colour in region (rviz draws what it
    receives a few frames after it arrives; on a busy machine many seconds later)."""
    def shown():
        return (grab(display, path) and count_pixels(path, region, colour) > pixels) or None
    ros.wait_until(shown, 180, interval=0.5, what=what)
    return path


def test_a_world_without_sensors_is_shown_with_world_rviz_displays_only(ros, rospy_client):
    from gazebo_ros.world_view import simulator_sensor_topics, with_sensor_displays
    start_sim(ros, ENGINES[0])
    spawned = GazeboApi(rospy_client).spawn_sdf_model('wall', BOX_SDF, '', pose(2, 0, 0.25), '')
    assert spawned.success, spawned.status_message
    master = ros.master()
    topics = simulator_sensor_topics(master.getSystemState('/test')[2],
                                     master.getTopicTypes('/test')[2])
    assert topics == []
    with open(WORLD_RVIZ) as f:
        assert with_sensor_displays(yaml.safe_load(f), topics) == yaml.safe_load(open(WORLD_RVIZ))


def test_the_simulators_view_shows_a_spawned_robots_scan_on_the_box(ros, rospy_client,
                                                                    tmp_path):
    ros.set_param('/use_sim_time', True)
    start_sim(ros, ENGINES[0])
    xvfb, display = start_xvfb(ros)
    view = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                     env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
    ros.wait_until(lambda: subscribers(ros, '/gazebo/collision_markers', '/gzclient_'), 120,
                   what='the view to subscribe to the collision markers')
    spawn_laser_bot_before_the_box(ros, rospy_client)
    ros.wait_until(lambda: subscribers(ros, '/scan', '/gzclient_'), 120,
                   what='the view to show /scan')
    with open(WORLD_RVIZ) as f:
        on_the_box = scan_region(f.read())
    png = screenshot_with(ros, display, tmp_path / 'view.png', on_the_box, scan_green, 40,
                          "the scan's points on the box")
    assert count_pixels(png, RENDER_PANEL, scan_green) == count_pixels(png, on_the_box,
                                                                       scan_green), \
        "scan-green pixels off the box's face, where the rays meet nothing"
    ros.terminate(view)  # rviz before its X server
    ros.terminate(xvfb)


def test_the_books_rviz_config_shows_the_scan_in_base_link(ros, rospy_client, tmp_path):
    ros.set_param('/use_sim_time', True)
    start_sim(ros, ENGINES[0])
    spawn_laser_bot_before_the_box(ros, rospy_client)
    config = tmp_path / 'mobot_w_lidar.rviz'
    config.write_text(BOOK_RVIZ)
    xvfb, display = start_xvfb(ros)
    rviz = ros.start(['rosrun', 'rviz', 'rviz', '-d', str(config)], name='rviz',
                     env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
    on_the_box = scan_region(BOOK_RVIZ)
    png = screenshot_with(ros, display, tmp_path / 'book.png', on_the_box, coloured, 40,
                          "the scan's points on the box")
    assert count_pixels(png, RENDER_PANEL, coloured) == count_pixels(png, on_the_box, coloured), \
        "coloured pixels off the box's face, where the rays meet nothing"
    ros.terminate(rviz)
    ros.terminate(xvfb)
