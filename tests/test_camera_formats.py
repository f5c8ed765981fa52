"""Camera image formats and the triggered camera over real ROS, on every engine: cameras of every
<image><format> gazebo_ros publishes (R8G8B8, B8G8R8, L8, L16, R16G16B16 and the four Bayer
patterns) side by side on one link, facing a red box, and libgazebo_ros_triggered_camera.so.
Each image carries the ROS encoding Gazebo's plugins give it and the R8G8B8 camera's pixels in
that encoding: 16-bit images the same colours rounded to 16 bits (the red face 0.4: 26214),
mono the luma, Bayer each pixel's channel of its pattern. The triggered camera publishes one
frame for each message on its image_trigger topic, after the next step, and none without."""
import numpy
import pytest

from api_client import GazeboApi, pose
from conftest import ENGINES, start_sim
from onedof_harness.private_ros import wait_until
from test_camera import Listener, box_sdf, hear_periods

WIDTH, HEIGHT = 160, 120
PERIOD_STEPS = 100  # the sensors' update_rate, 10 Hz, in 1 ms steps
# Camera name: its <image><format>, and the encoding and bytes a pixel its image has.
FORMATS = {
    'rgb': ('R8G8B8', 'rgb8', 3), 'bgr': ('B8G8R8', 'bgr8', 3), 'grey': ('L8', 'mono8', 1),
    'grey16': ('L16', 'mono16', 2), 'rgb16': ('R16G16B16', 'rgb16', 6),
    'rggb': ('BAYER_RGGB8', 'bayer_rggb8', 1), 'bggr': ('BAYER_BGGR8', 'bayer_bggr8', 1),
    'gbrg': ('BAYER_GBRG8', 'bayer_gbrg8', 1), 'grbg': ('BAYER_GRBG8', 'bayer_grbg8', 1),
}
# Which channel of r, g, b each Bayer pattern keeps at [row % 2][column % 2].
BAYER = {'rggb': ((0, 1), (1, 2)), 'bggr': ((2, 1), (1, 0)), 'gbrg': ((1, 2), (0, 1)),
         'grbg': ((1, 0), (2, 1))}


def camera_sensor(name, image_format='R8G8B8', plugin='libgazebo_ros_camera.so', rate=10.0,
                  extra='', width=WIDTH, height=HEIGHT, fov=1.0, lens=''):
    """A camera sensor on camera_link with its plugin; `extra`: more of the plugin's parameters,
    `lens`: more of the <camera>'s elements."""
    return """  <gazebo reference="camera_link">
    <sensor type="camera" name="%(name)s_sensor">
      <update_rate>%(rate)r</update_rate>
      <camera name="%(name)s">
        <horizontal_fov>%(fov)r</horizontal_fov>
        <image><width>%(width)d</width><height>%(height)d</height>
          <format>%(format)s</format></image>
        <clip><near>0.05</near><far>20</far></clip>%(lens)s
      </camera>
      <plugin name="%(name)s_controller" filename="%(plugin)s">
        <cameraName>%(name)s</cameraName>
        <frameName>camera_link</frameName>%(extra)s
      </plugin>
    </sensor>
  </gazebo>
""" % {'name': name, 'format': image_format, 'plugin': plugin, 'rate': rate, 'width': width,
       'height': height, 'fov': fov, 'extra': extra, 'lens': lens}


def cameras_urdf(sensors):
    """A link at (0, 0, 0.5) welded to the world, looking along +x, carrying `sensors`."""
    return """<robot name="cameras">
  <link name="world"/>
  <joint name="weld" type="fixed"><parent link="world"/><child link="camera_link"/>
    <origin xyz="0 0 0.5"/></joint>
  <link name="camera_link">
    <inertial><mass value="0.1"/>
      <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
  </link>
%s</robot>""" % ''.join(sensors)


def start(ros, rospy, engine, sensors, scene=None, world=()):
    """A paused lock-step simulator on the world file `world` (by default none given: Gazebo's
    empty world, its ground and sun) with `sensors` and an SDF model `scene` (by default a red box
    1 m before them, off to the left)."""
    sim = start_sim(ros, engine, args=['_paused:=true', '_lockstep:=true'] + list(world))
    api = GazeboApi(rospy)
    spawned = api.spawn_urdf_model('cameras', cameras_urdf(sensors), '', pose(), '')
    assert spawned.success, spawned.status_message
    if scene is None:
        spawned = api.spawn_sdf_model('red_box', box_sdf(size=0.4), '', pose(1.2, 0.15, 0.5), '')
    else:
        spawned = api.spawn_sdf_model('scene', scene, '', pose(), '')
    assert spawned.success, spawned.status_message
    return sim, api


def pixels(image, channels, dtype):
    assert image.is_bigendian == 0
    return numpy.frombuffer(image.data, dtype=dtype).reshape(image.height, image.width, channels)


def luma(rgb):
    """ITU-R BT.601's, rounded, as integers."""
    rgb = rgb.astype(numpy.int64)
    return (299 * rgb[..., 0] + 587 * rgb[..., 1] + 114 * rgb[..., 2] + 500) // 1000


@pytest.mark.parametrize('engine', ENGINES)
def test_every_format_carries_the_rgb_cameras_pixels_in_its_encoding(ros, rospy_client, engine):
    from sensor_msgs.msg import Image
    _, api = start(ros, rospy_client, engine,
                   [camera_sensor(name, image_format)
                    for name, (image_format, _, _) in FORMATS.items()])
    heard = hear_periods(ros, rospy_client, api,
                         {'/%s/image_raw' % name: Image for name in FORMATS}, 1, PERIOD_STEPS)
    images = {name: heard['/%s/image_raw' % name][0] for name in FORMATS}
    for name, (_, encoding, size) in FORMATS.items():
        image = images[name]
        assert (image.encoding, image.width, image.height, image.step) == \
            (encoding, WIDTH, HEIGHT, WIDTH * size), name
        assert image.header.stamp.to_nsec() == PERIOD_STEPS * 1000000, name

    rgb = pixels(images['rgb'], 3, numpy.uint8)
    red = numpy.all(rgb == (102, 0, 0), axis=2)
    grey = numpy.all(rgb == (178, 178, 178), axis=2)
    assert red.sum() > 1000 and grey.sum() > 1000  # the box and the background both in view
    assert numpy.array_equal(pixels(images['bgr'], 3, numpy.uint8), rgb[:, :, ::-1])
    assert numpy.array_equal(pixels(images['grey'], 1, numpy.uint8)[:, :, 0], luma(rgb))

    # 16 bits a channel: the same colours, each rounded to 16 bits instead of 8 (the red face
    # 0.4 x 65535 = 26214, the background 0.7 x 65535 = 45874.5).
    rgb16 = pixels(images['rgb16'], 3, '<u2').astype(float)
    assert numpy.all(numpy.abs(rgb16 / 257 - rgb) <= 0.5 + 1 / 257)
    assert numpy.all(numpy.abs(rgb16[red] - (26214, 0, 0)) <= 1)
    assert numpy.all(numpy.abs(rgb16[grey] - 45874.5) <= 1)
    assert len(numpy.unique(rgb16[grey])) <= 2
    grey16 = pixels(images['grey16'], 1, '<u2')[:, :, 0]
    assert numpy.array_equal(grey16, luma(rgb16.astype(numpy.uint16)))

    # Bayer: each pixel keeps one channel, as its pattern's ROS encoding names it.
    rows, columns = numpy.indices((HEIGHT, WIDTH))
    for name, pattern in BAYER.items():
        channel = numpy.choose(2 * (rows % 2) + columns % 2,
                               [pattern[0][0], pattern[0][1], pattern[1][0], pattern[1][1]])
        expected = numpy.take_along_axis(rgb, channel[:, :, None], axis=2)[:, :, 0]
        assert numpy.array_equal(pixels(images[name], 1, numpy.uint8)[:, :, 0], expected), name


def trigger_subscribers(ros, topic):
    """The nodes the master lists as subscribing to `topic`."""
    _, _, (_, subscribers, _) = ros.master().getSystemState('/private_ros')
    return [nodes for name, nodes in subscribers if name == topic]


@pytest.mark.parametrize('engine', ENGINES)
def test_the_triggered_camera_publishes_one_frame_a_trigger(ros, rospy_client, engine):
    import rospy
    from sensor_msgs.msg import CameraInfo, Image
    from std_msgs.msg import Empty
    _, api = start(ros, rospy_client, engine, [
        camera_sensor('shutter', 'R8G8B8', plugin='libgazebo_ros_triggered_camera.so', rate=1.0),
        camera_sensor('plain', 'R8G8B8')])
    # Only the triggered camera listens for triggers, on <cameraName>/image_trigger.
    assert trigger_subscribers(ros, '/shutter/image_trigger') == [['/gazebo']]
    assert trigger_subscribers(ros, '/plain/image_trigger') == []
    listener = Listener(ros, rospy_client, {'/shutter/image_raw': Image,
                                            '/shutter/camera_info': CameraInfo})
    trigger = rospy.Publisher('/shutter/image_trigger', Empty, queue_size=10)
    wait_until(lambda: trigger.get_num_connections() > 0, 30, what='the trigger to connect')
    frames = listener.heard['/shutter/image_raw']
    step_ns = 1000000

    def now():
        return api.get_world_properties().sim_time

    def shoot(triggers):
        """Publishes `triggers` triggers, then steps one step at a time until as many new frames
        came: each frame's stamp is the sim time of a step after its trigger was sent."""
        before, sent_at = len(frames), now()
        for _ in range(triggers):
            trigger.publish(Empty())
        wait_until(lambda: api.step_simulation(1).success and len(frames) >= before + triggers,
                   60, what='%d triggered frames' % triggers)
        new = frames[before:]
        assert len(new) == triggers
        assert all(frame.header.stamp.to_sec() > sent_at for frame in new)
        return [frame.header.stamp.to_nsec() for frame in new]

    # Two seconds of sim time, past two of the sensor's 1 Hz updates: no frame. Any frame made
    # then would arrive before the triggered one, on the same connection.
    assert api.step_simulation(2000).success
    first = shoot(1)
    assert first[0] > 2000 * step_ns
    assert len(frames) == 1
    # Another second: nothing more, then one frame for the next trigger.
    assert api.step_simulation(1000).success
    second = shoot(1)
    assert second[0] > first[0] + 1000 * step_ns and len(frames) == 2
    # Two triggers at once: two frames, each after its own step.
    third = shoot(2)
    assert third[1] > third[0] > second[0] and len(frames) == 4
    assert api.step_simulation(1000).success
    fourth = shoot(1)
    assert len(frames) == 5 and fourth[0] > third[1] + 1000 * step_ns
    # Each frame's CameraInfo, at its stamp.
    wait_until(lambda: len(listener.heard['/shutter/camera_info']) >= 5, 30,
               what='five CameraInfos')
    listener.stop()
    assert [m.header.stamp.to_nsec() for m in listener.heard['/shutter/camera_info']] == \
        [m.header.stamp.to_nsec() for m in frames]
    assert frames[0].encoding == 'rgb8' and frames[0].header.frame_id == 'camera_link'
