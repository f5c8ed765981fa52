"""The sensors in rviz, over real ROS on a private Xvfb, with screenshots whose pixels are counted.

The simulator's view (gzclient: rviz on gazebo_ros/rviz/world.rviz) adds a display for each sensor
stream the simulator publishes once a robot carrying the sensor is spawned: the laser of
tests/robots/laser_bot.urdf, 2 m before a box, draws its scan's points on the box's face and
nowhere else; the Kinect of tests/robots/kinect_bot.urdf, 2 m before a red box, draws its point
cloud's points of the box on the box's face and nowhere else, and the box shows in the camera's and
the Kinect's images, in panels of their own. A mobile base with the lidar (the book's mobot's TF:
the diff drive's odom -> base_link, robot_state_publisher's base_link -> lidar_link) shows its scan
once a static world -> odom joins odom to the view's world. A world without sensors shows
world.rviz's displays and no other. The book's way works too: the user's own rviz with the book's
LaserScan display on /scan and fixed frame base_link (as the book's mobot_w_lidar.rviz has them)
shows the same points.
"""
import os
import subprocess

import numpy as np
import yaml

from api_client import ROBOT, GazeboApi, pose
from book_rviz import BookRviz
from conftest import ENGINES, TUTORIAL_URDF, start_sim
from gazebo_commands import start_serving
from onedof_sim.tutorial.gazebo_window import orbit_pixel
from onedof_sim.tutorial.rviz_view import start_xvfb
from test_camera import BOX, DISTANCE, KINECT, box_sdf, kinect_bot_urdf
from test_diff_drive import drive_base_urdf
from test_laser import BOX_SDF, FACE_X, HALF_WIDTH, laser_bot_urdf
from test_tutorial import count_pixels

WORLD_RVIZ = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'src',
                          'gazebo_ros', 'rviz', 'world.rviz')
LASER = ('ray', 'libgazebo_ros_laser.so')
LIDAR_Z = 0.3  # the lidar's height (the base is welded at the origin)
# rviz's 3D panel in a 1000 x 720 window (the Xvfb screen): right of the docked panels (the
# Displays, and the images' panels below it, whose width depends on what they hold: the panel's
# left edge is found in each screenshot), below the tool bar, above the status bar.
PANEL_TOP, PANEL_RIGHT, PANEL_BOTTOM = 62, 984, 690
BACKGROUND = (48, 48, 48)  # the view's background colour
# The scan's points are looked for this many pixels around where the box's face projects.
MARGIN = 12
scan_green = lambda r, g, b: (g > 180) & (r < 100) & (b < 100)
coloured = lambda r, g, b: (abs(r - g) + abs(g - b) + abs(r - b)) > 90
# The red box's points as rviz colours them from the cloud's rgb field: blue, as with Gazebo's
# Kinect (its colour bytes in the image's order, which rviz reads as blue-green-red).
cloud_blue = lambda r, g, b: (b > 60) & (r < 30) & (g < 30)
# The red box in the camera's and the Kinect's colour images (Gazebo/Red turned from the sun).
image_red = lambda r, g, b: (r > 80) & (g < 30) & (b < 30)
# The Kinect's period (its updateRate, 10 Hz) in the default 1 ms steps.
KINECT_PERIOD_STEPS = 100

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


def rgb_of(png):
    import matplotlib.image
    return (matplotlib.image.imread(str(png))[..., :3] * 255).round()


def render_panel(png):
    """The 3D panel's region (x0, y0, x1, y1) in a screenshot: its left edge is the first pixel
    of the background colour in its top row (the world's far side is drawn lower down)."""
    row = rgb_of(png)[PANEL_TOP + 4]
    background = np.all(row == BACKGROUND, axis=1)
    return (int(np.argmax(background)), PANEL_TOP, PANEL_RIGHT, PANEL_BOTTOM)


def region_around(config_text, panel, points):
    """The screenshot region (x0, y0, x1, y1) around where points project in the view of an rviz
    config drawn in panel, MARGIN pixels wider on every side."""
    view = yaml.safe_load(config_text)['Visualization Manager']['Views']['Current']
    pixels = [orbit_pixel(view, panel, point) for point in points]
    xs, ys = [x for x, _ in pixels], [y for _, y in pixels]
    return (int(min(xs)) - MARGIN, int(min(ys)) - MARGIN, int(max(xs)) + MARGIN + 1,
            int(max(ys)) + MARGIN + 1)


def scan_region(config_text, panel, height=LIDAR_Z):
    """Around the scan's points on the laser's box: its near face, x = 2.2 m, from y = -0.25 to
    0.25 m at the lidar's height."""
    return region_around(config_text, panel,
                         [(FACE_X, y, height) for y in (-HALF_WIDTH, HALF_WIDTH)])


def red_box_face_region(config_text, panel):
    """Around the Kinect's red box's near face: a 0.5 m square 2 m ahead of the Kinect's lens."""
    face_x = KINECT['x'] + DISTANCE
    return region_around(config_text, panel, [(face_x, BOX['y'] + dy, BOX['z'] + dz)
                                       for dy in (-BOX['half'], BOX['half'])
                                       for dz in (-BOX['half'], BOX['half'])])


# The book's lidar on the drive base, ahead of its body and above it (the base's body reaches
# 0.55 m up; its wheels and casters stay clear of the scan's plane).
MOBOT_LIDAR = {'x': 0.2, 'z': 0.6}
MOBOT_LIDAR_URDF = """
  <joint name="lidar_joint" type="fixed">
    <parent link="base_link"/>
    <child link="lidar_link"/>
    <origin xyz="%(x)g 0 %(z)g"/>
  </joint>
  <link name="lidar_link">
    <inertial><mass value="0.1"/>
      <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
  </link>
  <gazebo reference="lidar_link">
    <sensor type="gpu_ray" name="lidar">
      <update_rate>40</update_rate>
      <ray>
        <scan><horizontal><samples>721</samples><resolution>1</resolution>
          <min_angle>-1.570796</min_angle><max_angle>1.570796</max_angle></horizontal></scan>
        <range><min>0.10</min><max>30.0</max><resolution>0.01</resolution></range>
      </ray>
      <plugin name="lidar_controller" filename="libgazebo_ros_gpu_laser.so">
        <topicName>scan</topicName>
        <frameName>lidar_link</frameName>
      </plugin>
    </sensor>
  </gazebo>
</robot>""" % MOBOT_LIDAR


def grab(display, path):
    """A screenshot of the display's root window at path (in RGB, also while the screen is all
    grey), or None when it could not be taken."""
    result = subprocess.run(['import', '-display', display, '-window', 'root', 'PNG24:%s' % path],
                            capture_output=True, text=True)
    return path if result.returncode == 0 else None


def red_row_runs(png, region):
    """The runs of rows of region (x0, y0, x1, y1) with image_red pixels: 'rows A-B: N pixels'
    for each, or 'none'."""
    rgb = rgb_of(png)
    x0, y0, x1, y1 = region
    per_row = image_red(*(rgb[y0:y1, x0:x1, i] for i in range(3))).sum(axis=1)
    runs, start = [], None
    for offset, count in enumerate(list(per_row) + [0]):
        if count and start is None:
            start = offset
        elif not count and start is not None:
            runs.append('rows %d-%d: %d pixels' % (y0 + start, y0 + offset - 1,
                                                   int(per_row[start:offset].sum())))
            start = None
    return ', '.join(runs) or 'none'


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


def screenshot_with(ros, display, path, shown, what, before=None, describe=None):
    """Screenshots at path until shown(png, panel) holds for one, panel being its 3D panel's
    region (rviz draws what it receives a few frames after it arrives; on a busy machine many
    seconds later); runs before() ahead of each. Returns the panel. On a timeout the error says
    the last screenshot's panel and describe(png, panel), what it had instead (the screenshot
    is still at path then)."""
    last = {}

    def screenshot_shown():
        if before:
            before()
        if not grab(display, path):
            return None
        last['panel'] = render_panel(path)
        return last['panel'] if shown(path, last['panel']) else None
    try:
        return ros.wait_until(screenshot_shown, 300, interval=0.5, what=what)
    except TimeoutError as error:
        raise TimeoutError('%s; the last screenshot: %s' % (
            error, 'none taken' if not last else '3D panel %s %s' % (
                last['panel'], describe(path, last['panel']) if describe else '')))


def assert_scan_on_the_face_only(ros, display, png, config, colour, height=LIDAR_Z,
                                 before=None):
    """Screenshots until more than 40 pixels of `colour` are on the box's face where the view of
    `config` projects it (running before() ahead of each); then none of that colour may be
    elsewhere in the 3D panel (the rays meet nothing else)."""
    panel = screenshot_with(
        ros, display, png, lambda png, panel: count_pixels(
            png, scan_region(config, panel, height), colour) > 40,
        "the scan's points on the box", before=before)
    assert count_pixels(png, panel, colour) == count_pixels(
        png, scan_region(config, panel, height), colour), \
        "scan pixels off the box's face, where the rays meet nothing"


def test_a_world_without_sensors_is_shown_with_world_rviz_displays_only(ros, rospy_client):
    """The tutorial's world: its robot and a box."""
    from gazebo_ros.world_view import simulator_sensor_topics, with_sensor_displays
    start_sim(ros, ENGINES[0])
    api = GazeboApi(rospy_client)
    with open(TUTORIAL_URDF) as f:
        spawned = api.spawn_urdf_model(ROBOT, f.read(), '', pose(), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_sdf_model('wall', BOX_SDF, '', pose(2, 0, 0.25), '')
    assert spawned.success, spawned.status_message
    master = ros.master()
    topics = simulator_sensor_topics(master.getSystemState('/test')[2],
                                     master.getTopicTypes('/test')[2])
    assert topics == []
    with open(WORLD_RVIZ) as f:
        assert with_sensor_displays(yaml.safe_load(f), topics) == yaml.safe_load(open(WORLD_RVIZ))


def test_the_view_shows_the_simulators_sensor_topics_only_and_keeps_the_users_displays():
    from gazebo_ros.world_view import simulator_sensor_topics, with_sensor_displays
    publishers = [['/gazebo/model_states', ['/gazebo']], ['/scan', ['/gazebo']],
                  ['/kinect/depth/points', ['/gazebo']], ['/kinect/rgb/image_raw', ['/gazebo']],
                  ['/kinect/rgb/camera_info', ['/gazebo']], ['/filtered_scan', ['/my_filter']],
                  ['/imu_data', ['/gazebo']]]
    types = [['/gazebo/model_states', 'gazebo_msgs/ModelStates'],
             ['/scan', 'sensor_msgs/LaserScan'],
             ['/kinect/depth/points', 'sensor_msgs/PointCloud2'],
             ['/kinect/rgb/image_raw', 'sensor_msgs/Image'],
             ['/kinect/rgb/camera_info', 'sensor_msgs/CameraInfo'],
             ['/filtered_scan', 'sensor_msgs/LaserScan'], ['/imu_data', 'sensor_msgs/Imu']]
    topics = simulator_sensor_topics([publishers, [], []], types)
    assert topics == [('/kinect/depth/points', 'sensor_msgs/PointCloud2'),
                      ('/kinect/rgb/image_raw', 'sensor_msgs/Image'),
                      ('/scan', 'sensor_msgs/LaserScan')]

    with open(WORLD_RVIZ) as f:
        config = yaml.safe_load(f)
    config['Visualization Manager']['Displays'].append({'Class': 'rviz/TF', 'Name': 'My TF'})
    shown = with_sensor_displays(config, topics)
    displays = shown['Visualization Manager']['Displays']
    assert [(d['Class'], d.get('Topic', d.get('Image Topic'))) for d in displays[-3:]] == [
        ('rviz/PointCloud2', '/kinect/depth/points'), ('rviz/Image', '/kinect/rgb/image_raw'),
        ('rviz/LaserScan', '/scan')]
    # The robot deleted: its displays go, the user's stay.
    displays = with_sensor_displays(shown, [])['Visualization Manager']['Displays']
    names = [d['Name'] for d in displays]
    assert names == ['Ground plane', 'Visuals', 'Collisions', 'Joints', 'Center of Mass',
                     'Inertias', 'Contacts', 'Model views', 'Move models', 'My TF']


def test_the_simulators_view_shows_a_spawned_robots_scan_on_the_box(ros, rospy_client,
                                                                    tmp_path):
    """Started as the book starts Gazebo: empty_world.launch, whose gui runs gzclient as the node
    gazebo_gui."""
    xvfb, display = start_xvfb(ros)
    launch = start_serving(ros, ['roslaunch', 'gazebo_ros', 'empty_world.launch'], 'launch',
                           env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
    ros.wait_until(lambda: subscribers(ros, '/gazebo/visual_markers', '/gazebo_gui'), 120,
                   what='the view to subscribe to the visual markers')
    spawn_laser_bot_before_the_box(ros, rospy_client)
    ros.wait_until(lambda: subscribers(ros, '/scan', '/gazebo_gui'), 120,
                   what='the view to show /scan')
    with open(WORLD_RVIZ) as f:
        view_config = f.read()
    png = tmp_path / 'view.png'
    assert_scan_on_the_face_only(ros, display, png, view_config, scan_green)
    ros.terminate(launch)  # rviz before its X server
    ros.terminate(xvfb)


def test_a_view_opened_on_a_robot_with_a_lidar_starts_with_its_scan_and_one_panel(ros,
                                                                                 rospy_client):
    """gzclient opened on a world whose robot has a lidar, the simulator started as a user starts
    it (its collision markers not yet asked for): the view's first configuration already shows
    the scan, so rviz loads one configuration and builds one Gazebo panel (a second load builds
    the panel anew, and a client that subscribed to its topics in between could be left
    unconnected)."""
    start_sim(ros, ENGINES[0], extras=False)
    spawn_laser_bot_before_the_box(ros, rospy_client)
    xvfb, display = start_xvfb(ros)
    view = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                     env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
    panel_up = 'the Gazebo panel is up'
    ros.wait_until(lambda: subscribers(ros, '/scan', '/gzclient_') and
                   panel_up in ros.log_text(view), 120,
                   what="the view to show /scan with the Gazebo panel up")
    log = ros.log_text(view)
    assert "the view opens on the simulator's sensor streams: /scan" in log, log
    assert log.count(panel_up) == 1, log
    ros.terminate(view)  # rviz before its X server
    ros.terminate(xvfb)


def test_the_view_shows_a_mobile_bases_scan_once_odom_is_joined_to_the_world(ros, rospy_client,
                                                                              tmp_path):
    """The book's mobot: its TF tree starts at the diff drive's odom, which with its default
    odometry source (world) is the world frame; a static world -> odom joins it to the view."""
    ros.set_param('/use_sim_time', True)
    # Without the collision markers: the view asks the simulator for them.
    start_sim(ros, ENGINES[0], extras=False)
    xvfb, display = start_xvfb(ros)
    view = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                     env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
    ros.wait_until(lambda: subscribers(ros, '/gazebo/visual_markers', '/gzclient_'), 120,
                   what='the view to subscribe to the visual markers')
    urdf = drive_base_urdf('world').replace('</robot>', MOBOT_LIDAR_URDF)
    ros.set_param('/robot_description', urdf)
    ros.start(['rosrun', 'robot_state_publisher', 'robot_state_publisher'],
              name='robot_state_publisher')
    ros.start(['rosrun', 'tf', 'static_transform_publisher', '0', '0', '0', '0', '0', '0',
               'world', 'odom', '100'], name='world_odom')
    api = GazeboApi(rospy_client)
    # Off the origin, so that odom -> base_link (the base's true pose) is not the identity.
    spawned = api.spawn_urdf_model('mobot', urdf, '', pose(-0.5, 0.1, 0), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_sdf_model('wall', BOX_SDF, '',
                                  pose(FACE_X + HALF_WIDTH, 0, MOBOT_LIDAR['z']), '')
    assert spawned.success, spawned.status_message
    ros.wait_until(lambda: subscribers(ros, '/scan', '/gzclient_'), 120,
                   what='the view to show /scan')
    with open(WORLD_RVIZ) as f:
        view_config = f.read()
    png = tmp_path / 'view.png'
    assert_scan_on_the_face_only(ros, display, png, view_config, scan_green, MOBOT_LIDAR['z'])
    ros.terminate(view)  # rviz before its X server
    ros.terminate(xvfb)


def test_the_simulators_view_shows_a_spawned_kinects_point_cloud_on_the_box(ros, rospy_client,
                                                                            tmp_path):
    """The Kinect's frame, kinect_depth_frame, is the book's: its launch file publishes it from
    kinect_link with a static_transform_publisher, the optical frame's rotation. The world is
    paused and stepped a Kinect period at a time: the view shows the last cloud it received."""
    ros.set_param('/use_sim_time', True)
    # Without the collision markers: the view asks the simulator for them.
    start_sim(ros, ENGINES[0], args=['_paused:=true', '_enable_step_simulation:=true'],
              extras=False)
    api = GazeboApi(rospy_client)
    xvfb, display = start_xvfb(ros)
    view = ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                     env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
    ros.wait_until(lambda: subscribers(ros, '/gazebo/visual_markers', '/gzclient_'), 120,
                   what='the view to subscribe to the visual markers')
    urdf = kinect_bot_urdf()
    ros.set_param('/robot_description', urdf)
    ros.start(['rosrun', 'robot_state_publisher', 'robot_state_publisher'],
              name='robot_state_publisher')
    ros.start(['rosrun', 'tf', 'static_transform_publisher', '0', '0', '0', '-0.5', '0.5', '-0.5',
               '0.5', 'kinect_link', 'kinect_depth_frame', '100'], name='kinect_broadcaster')
    spawned = api.spawn_urdf_model('kinect_bot', urdf, '', pose(), '')
    assert spawned.success, spawned.status_message
    spawned = api.spawn_sdf_model('red_box', box_sdf(), '',
                                  pose(KINECT['x'] + DISTANCE + BOX['half'], BOX['y'], BOX['z']),
                                  '')
    assert spawned.success, spawned.status_message
    ros.wait_until(lambda: subscribers(ros, '/kinect/depth/points', '/gzclient_'), 120,
                   what='the view to show /kinect/depth/points')

    with open(WORLD_RVIZ) as f:
        view_config = f.read()
    png = tmp_path / 'view.png'

    def docked_images(panel):
        return (0, PANEL_TOP, panel[0], 720)

    def cloud_and_images(png, panel):
        return (count_pixels(png, red_box_face_region(view_config, panel), cloud_blue),
                count_pixels(png, docked_images(panel), image_red))

    def cloud_and_images_shown(png, panel):
        cloud, images = cloud_and_images(png, panel)
        return cloud > 300 and images > 1000

    def cloud_and_images_described(png, panel):
        # Which docked image lacks the box: the rows with red among the docked images, in runs
        # (each image that shows the box, one run), and whether the view still subscribes to the
        # two colour images.
        images = {topic: bool(subscribers(ros, topic, '/gzclient_'))
                  for topic in ('/example_camera/image_raw', '/kinect/rgb/image_raw')}
        return ('had %d cloud pixels on the box (more than 300 wanted) and %d red image pixels '
                'left of the 3D panel (more than 1000 wanted; by run of rows: %s; the view '
                'subscribed to %s), the simulator at %s' % (
                    cloud_and_images(png, panel) + (
                        red_row_runs(png, docked_images(panel)),
                        ', '.join('%s %s' % (topic, 'yes' if on else 'no')
                                  for topic, on in images.items()),
                        api.get_world_properties().sim_time)))
    panel = screenshot_with(
        ros, display, png, cloud_and_images_shown, "the cloud's points on the box and the box "
        "in the camera's and the Kinect's images",
        before=lambda: api.step_simulation(KINECT_PERIOD_STEPS),
        describe=cloud_and_images_described)
    # The Kinect's own case is blue too (its visual, kinect_case).
    kinect_case = region_around(view_config, panel, [(KINECT['x'], dy, KINECT['z'])
                                                     for dy in (-0.05, 0.05)])
    assert count_pixels(png, panel, cloud_blue) - count_pixels(png, kinect_case, cloud_blue) == \
        count_pixels(png, red_box_face_region(view_config, panel), cloud_blue), \
        "the red box's cloud colour off the box's face"
    # In the 3D panel the red is the box's own visual: the images are drawn in their own panels.
    box = region_around(view_config, panel, [
        (KINECT['x'] + DISTANCE + BOX['half'] + dx, BOX['y'] + dy, BOX['z'] + dz)
        for dx in (-BOX['half'], BOX['half']) for dy in (-BOX['half'], BOX['half'])
        for dz in (-BOX['half'], BOX['half'])])
    assert count_pixels(png, panel, image_red) == count_pixels(png, box, image_red), \
        'the images are drawn in their own panels'
    ros.terminate(view)  # rviz before its X server
    ros.terminate(xvfb)


def test_the_books_rviz_config_shows_the_scan_in_base_link(ros, rospy_client, tmp_path):
    ros.set_param('/use_sim_time', True)
    start_sim(ros, ENGINES[0])
    spawn_laser_bot_before_the_box(ros, rospy_client)
    config = tmp_path / 'mobot_w_lidar.rviz'
    config.write_text(BOOK_RVIZ)
    xvfb, display = start_xvfb(ros)
    rviz = BookRviz(ros, config, display)
    png = tmp_path / 'book.png'
    assert_scan_on_the_face_only(ros, display, png, BOOK_RVIZ, coloured, before=rviz.keep_up)
    ros.terminate(rviz.proc)
    ros.terminate(xvfb)
