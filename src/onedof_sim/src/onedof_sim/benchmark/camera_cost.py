"""Item 10, the camera's cost: the real-time factor of the simulator node running as fast as
possible with the tutorial robot and the cafe table and a 640x480 camera at 30 Hz of sim time
(libgazebo_ros_camera.so) that sees bench_render_frame's scene, with the camera subscribed (each
frame rendered and published) and without (nothing rendered), in alternating windows; and the
camera's cost per frame in the node (the wall time a sim second costs more with it, over the
frames it rendered) against the renderer's bare frame time on the same scene and view
(bench_render_frame: draw and read back, no ROS), measured in the same run."""
import re
import subprocess
import time

from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark.graph import NotMeasured, by_path, node_label

WIDTH, HEIGHT, RATE = 640, 480, 30
IMAGE_TOPIC = '/bench_camera/image_raw'
SETTLE_S = 0.25  # wall seconds after an unpause (or a subscription change) before a window opens
RENDER_COMMAND = ['rosrun', 'onedof_sim', 'bench_render_frame', str(WIDTH), str(HEIGHT)]

# The frame bench_render_frame draws bare (bench/render_frame.cpp: its camera 0.5 m up looking
# along +x, horizontal_fov 1.047, clip 0.1 to 100; a 100 m grey ground plane, a red box, a blue
# cylinder and a green sphere ahead), moved 10 m to the left of the tutorial robot and the cafe
# table, which stay out of its view: the node draws the same scene from the same view, so that
# the two costs differ by what the node does around the renderer. The plugin publishes every
# frame of the sensor's 30 Hz.
SCENE_Y = 10.0
CAMERA_URDF = """<robot name="bench_camera">
  <link name="world"/>
  <joint name="weld" type="fixed"><parent link="world"/><child link="post"/>
    <origin xyz="0 %g 0"/></joint>
  <link name="post">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <gazebo reference="post">
    <sensor type="camera" name="bench_camera">
      <pose>0 0 0.5 0 0 0</pose>
      <update_rate>%d</update_rate>
      <camera>
        <horizontal_fov>1.047</horizontal_fov>
        <image><width>%d</width><height>%d</height><format>R8G8B8</format></image>
        <clip><near>0.1</near><far>100</far></clip>
      </camera>
      <plugin name="bench_camera_controller" filename="libgazebo_ros_camera.so">
        <cameraName>bench_camera</cameraName>
        <frameName>bench_camera_link</frameName>
      </plugin>
    </sensor>
  </gazebo>
</robot>""" % (SCENE_Y, RATE, WIDTH, HEIGHT)


def scene_sdf():
    """bench_render_frame's four shapes, one static model, SCENE_Y to the left."""
    def shape(name, geometry, x, y, z, material):
        return ('<link name="%s"><pose>%g %g %g 0 0 0</pose><visual name="visual"><geometry>%s'
                '</geometry><material><script><uri>file://media/materials/scripts/'
                'gazebo.material</uri><name>%s</name></script></material></visual></link>'
                % (name, x, y + SCENE_Y, z, geometry, material))
    return ('<sdf version="1.6"><model name="bench_scene"><static>true</static>%s</model></sdf>'
            % ''.join([
                shape('ground', '<plane><normal>0 0 1</normal><size>100 100</size></plane>',
                      0, 0, 0, 'Gazebo/Grey'),
                shape('box', '<box><size>0.5 0.5 0.5</size></box>', 3, 0.5, 0.25, 'Gazebo/Red'),
                shape('cylinder', '<cylinder><radius>0.2</radius><length>1</length></cylinder>',
                      4, -1, 0.5, 'Gazebo/Blue'),
                shape('sphere', '<sphere><radius>0.3</radius></sphere>', 2.5, -0.4, 0.3,
                      'Gazebo/Green')]))


def bare_frame_ms(frames):
    """The renderer's bare frame time on its scene of four shapes (ms), from
    bench_render_frame."""
    result = subprocess.run(by_path(RENDER_COMMAND + [str(frames)]), capture_output=True,
                            text=True, timeout=300)
    found = re.search(r'ground, box, cylinder, sphere: ([0-9.]+) ms a frame', result.stdout)
    if result.returncode != 0 or not found:
        raise NotMeasured('bench_render_frame: %s' % (result.stdout + result.stderr)[-200:])
    return float(found.group(1))


def measure(bench, engine):
    from geometry_msgs.msg import Pose
    sizes = bench.sizes
    name = node_label(engine)
    proc = None
    frames = []
    subscriber = None
    try:
        proc, _ = bench.start_sim(engine, max_update_rate=0, paused=True)
        bench.spawn(bench.tutorial_models)
        pose = Pose()
        pose.orientation.w = 1.0
        bench.call('/gazebo/spawn_urdf_model', bench.srv.SpawnModel, 'bench_camera', CAMERA_URDF,
                   '', pose, '')
        bench.call('/gazebo/spawn_sdf_model', bench.srv.SpawnModel, 'bench_scene', scene_sdf(),
                   '', pose, '')
        clock = bench.proxy('/gazebo/get_world_properties', bench.srv.GetWorldProperties,
                            persistent=True)

        def subscribe(on):
            nonlocal subscriber
            if on and not subscriber:
                subscriber = bench.rospy.Subscriber(IMAGE_TOPIC, bench.rospy.AnyMsg,
                                                    lambda _: frames.append(1), queue_size=10)
                wait_until(lambda: subscriber.get_num_connections() > 0, 30,
                           what='%s to connect' % IMAGE_TOPIC)
            elif not on and subscriber:
                subscriber.unregister()
                subscriber = None

        def window(with_camera):
            """(sim seconds, wall seconds, frames heard) of one window."""
            subscribe(with_camera)
            bench.pause(False)
            time.sleep(SETTLE_S)
            heard0, wall0, sim0 = len(frames), time.monotonic(), clock().sim_time
            time.sleep(sizes.camera_window_s)
            sim1, wall1, heard1 = clock().sim_time, time.monotonic(), len(frames)
            bench.pause(True)
            return sim1 - sim0, wall1 - wall0, heard1 - heard0

        # The node's two windows and a run of bare frames in turn, so that all three see the
        # machine alike.
        windows = {'with': [], 'without': []}
        bare_runs = []
        for _ in range(sizes.camera_windows):
            windows['without'].append(window(False))
            windows['with'].append(window(True))
            bare_runs.append(bare_frame_ms(max(1, sizes.render_frames // sizes.camera_windows)))
        subscribe(False)
        bare_ms = sum(bare_runs) / len(bare_runs)
        totals = {key: [sum(column) for column in zip(*rows)] for key, rows in windows.items()}
        rtf = {key: sim / wall for key, (sim, wall, _) in totals.items()}
        sim_with, _, heard = totals['with']
        if heard == 0:
            raise NotMeasured('no camera frame arrived in %.1f s of sim time' % sim_with)
        # Wall seconds a sim second costs more with the camera, over the frames rendered in a sim
        # second (the sensor's rate: the node renders each; its publisher's queue of 2 drops
        # those one subscriber cannot read as fast, when the node runs many times real time).
        extra_per_sim_s = 1 / rtf['with'] - 1 / rtf['without']
        frame_ms = 1000 * extra_per_sim_s / RATE
        scene = 'tutorial robot + cafe table; in view, bench_render_frame\'s frame'
        bench.add('10', 'real-time factor as fast as possible with a %dx%d camera at %d Hz of sim '
                  'time subscribed (%s; %s; %.1f s of sim time; %d frames heard by a rospy '
                  'subscriber)' % (WIDTH, HEIGHT, RATE, name, scene, sim_with, heard),
                  '%.2f' % rtf['with'], 'the same node in alternating windows, camera not '
                  'subscribed (nothing rendered)', '%.2f' % rtf['without'],
                  rtf['with'] / rtf['without'])
        bench.add('10', 'the camera\'s cost per frame in the node (%s: rendering, the image '
                  'message, publishing to one subscriber)' % name, '%.2f ms' % frame_ms,
                  'the renderer\'s bare frame time, %s %d, run between the node\'s windows '
                  '(the same scene and view: draw and read back RGB and depth, no ROS)'
                  % (' '.join(RENDER_COMMAND), max(1, sizes.render_frames // sizes.camera_windows)),
                  '%.2f ms' % bare_ms, frame_ms / bare_ms)
        bench.results['camera'] = dict(engine=engine, windows=windows, bare_frame_ms=bare_runs,
                                       frame_ms=frame_ms)
    except (NotMeasured, TimeoutError, OSError) as error:
        bench.not_measured('10', 'camera cost, %s' % name, str(error)[:200])
    finally:
        if subscriber:
            subscriber.unregister()
        if proc:
            bench.stop(proc)
