"""Item 11, the laser's cost, on the book's mobot-in-a-pen scene (learning_ros's
mobot_in_pen.launch: the starting pen 5 m to the side, the mobot at the origin) with a mobot of
our own making that carries the book's lidar with 720 rays at 40 Hz of sim time
(bench/mobot_w_lidar.urdf). The laser measures and publishes only while /scan has a subscriber,
as Gazebo's does, so the same node is measured with and without one:
- the step loop's time: the node as fast as possible, in alternating windows with /scan
  subscribed and not, the CPU time per step of its loop's thread (the node's main thread, from
  /proc/PID/task/PID/schedstat: the steps, the plugins' hooks with the scans, the messages'
  serialization); the laser's share of the loop's time with it is 1 - (time per step without) /
  (with); aim: below 25 %. Beside it, the same of every thread of the node (ROS's own threads
  writing the scans out too), and steps per wall second, which also pay for this process reading
  the scans on the same two cores and for whatever else the machine runs;
- real time: the node paced at real-time factor 1 with /scan subscribed, its real-time factor
  over the run's pacing time from /clock arrivals, and the scans heard against the 40 a second
  of sim time it owes; aim: within 1 %."""
import os
import time

import rospkg

from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark import report as bm
from onedof_sim.benchmark.graph import STEP, NotMeasured, cpu_seconds, node_label, read_file

SCAN_HZ = 40.0
PEN_Y = -5.0   # mobot_in_pen.launch: spawn_model ... -model starting_pen -y -5
SETTLE_S = 0.25  # wall seconds after a change before a window opens


def scene():
    """(name, path, format, y) of the models spawned, in order."""
    onedof = rospkg.RosPack().get_path('onedof_sim')
    return [('starting_pen', os.path.join(onedof, 'models', 'starting_pen', 'model.sdf'), 'sdf',
             PEN_Y),
            ('mobot', os.path.join(onedof, 'bench', 'mobot_w_lidar.urdf'), 'urdf', 0.0)]


def spawn_scene(bench):
    from geometry_msgs.msg import Pose
    for name, path, fmt, y in scene():
        pose = Pose()
        pose.position.y = y
        pose.orientation.w = 1.0
        bench.call('/gazebo/spawn_%s_model' % fmt, bench.srv.SpawnModel, name, read_file(path),
                   '', pose, '')


class ScanCounter:
    """Subscribes /scan while it lives and counts the scans (not deserialized: what is measured
    is the node's cost, not this process's)."""

    def __init__(self, rospy):
        self.count = 0
        self._subscriber = rospy.Subscriber('/scan', rospy.AnyMsg, self._on_scan,
                                            queue_size=1000, tcp_nodelay=True)

    def _on_scan(self, _msg):
        self.count += 1

    def close(self):
        self._subscriber.unregister()


def scan_connected(bench):
    """Whether the simulator's /scan has a connection to this process now."""
    return bench.ros.connected('/gazebo', '/scan', '/benchmark')


def measure(bench, engine):
    name = node_label(engine)
    try:
        loop_share(bench, engine)
    except (NotMeasured, TimeoutError, OSError) as error:
        bench.not_measured('11', 'the laser\'s share of the step loop, %s' % name,
                           str(error)[:200])
    try:
        real_time(bench, engine)
    except (NotMeasured, TimeoutError, OSError) as error:
        bench.not_measured('11', 'real-time factor with the laser, %s' % name, str(error)[:200])


def loop_share(bench, engine):
    sizes = bench.sizes
    name = node_label(engine)
    proc = None
    try:
        proc, pid = bench.start_sim(engine, max_update_rate=0, paused=True)
        spawn_scene(bench)
        sim_time = bench.sim_clock()

        def window(subscribed):
            """(steps, wall seconds, the loop's and the node's CPU seconds, scans heard) of one
            window."""
            counter = ScanCounter(bench.rospy) if subscribed else None
            try:
                wait_until(lambda: scan_connected(bench) == subscribed, 30,
                           what='/scan %s' % ('connected' if subscribed else 'unconnected'))
                bench.pause(False)
                time.sleep(SETTLE_S)
                heard0 = counter.count if counter else 0
                loop0, cpu0 = cpu_seconds(pid, pid), cpu_seconds(pid)
                wall0, sim0 = sim_time()
                time.sleep(sizes.laser_window_s)  # the measurement window itself
                wall1, sim1 = sim_time()
                loop1, cpu1 = cpu_seconds(pid, pid), cpu_seconds(pid)
                heard = (counter.count if counter else 0) - heard0
                bench.pause(True)
            finally:
                if counter:
                    counter.close()
            return round((sim1 - sim0) / STEP), wall1 - wall0, loop1 - loop0, cpu1 - cpu0, heard

        windows = {'with': [], 'without': []}
        for _ in range(sizes.laser_windows):
            windows['without'].append(window(False))
            windows['with'].append(window(True))
        steps = {key: sum(w[0] for w in ws) for key, ws in windows.items()}
        rates = {key: bm.rate([w[0] for w in ws], [w[1] for w in ws])
                 for key, ws in windows.items()}

        def per_step_us(key, column):
            return 1e6 * sum(w[column] for w in windows[key]) / max(steps[key], 1)
        loop_us = {key: per_step_us(key, 2) for key in windows}
        node_us = {key: per_step_us(key, 3) for key in windows}
        heard = sum(w[4] for w in windows['with'])
        share = 1 - loop_us['without'] / loop_us['with']
        node_share = 1 - node_us['without'] / node_us['with']
        bench.add('11', 'CPU time per step of the loop of the %s as fast as possible, the book\'s '
                  'mobot in the starting pen, its 720-ray lidar at 40 Hz of sim time measuring '
                  '(/scan subscribed; %d scans heard in %.1f s of sim time); the laser\'s share '
                  'of the loop\'s time = 1 - 1 / ratio: %.0f %% (every thread of the node: %.1f '
                  'against %.1f us, %.0f %%; steps per wall s: %.0f against %.0f)'
                  % (name, heard, steps['with'] * STEP, 100 * share, node_us['with'],
                     node_us['without'], 100 * node_share, rates['with'], rates['without']),
                  '%.1f us' % loop_us['with'], 'the same node in the same windows alternating, '
                  '/scan unsubscribed (the laser measures nothing)', '%.1f us' % loop_us['without'],
                  loop_us['with'] / loop_us['without'], 'share < 25 %', share < 0.25)
        bench.results.setdefault('laser_cost', {})[engine] = dict(windows=windows, share=share)
    finally:
        if proc:
            bench.stop(proc)


def real_time(bench, engine):
    sizes = bench.sizes
    proc = None
    try:
        proc, _ = bench.start_sim(engine, max_update_rate=1000, paused=True)
        spawn_scene(bench)
        counter = ScanCounter(bench.rospy)
        probe = bench.clock_probe()
        try:
            wait_until(lambda: scan_connected(bench), 30, what='/scan connected')
            bench.pause(False)
            wait_until(lambda: probe.samples and counter.count, 30, what='/clock and /scan')
            start_sim, start_count = probe.latest, counter.count
            end = start_sim + sizes.laser_real_time_s
            wait_until(lambda: probe.latest >= end, sizes.laser_real_time_s * 5 + 30,
                       interval=0.1, what='%.0f s of sim time' % sizes.laser_real_time_s)
            heard = counter.count - start_count
            samples = [s for s in probe.samples if s[1] >= start_sim]
        finally:
            probe.close()
            counter.close()
        wall, sim = zip(*samples)
        mean = bm.mean_rtf(wall, sim)
        owed = (sim[-1] - sim[0]) * SCAN_HZ
        bench.add('11', 'real-time factor of the %s paced at 1.0, the book\'s mobot in the '
                  'starting pen with its 720-ray lidar at 40 Hz measuring (/scan subscribed), '
                  'over %.0f s of sim time; scans heard: %d of %.0f owed'
                  % (node_label(engine), sim[-1] - sim[0], heard, owed),
                  '%.4f' % mean, 'the wall clock (CLOCK_MONOTONIC at /clock arrival)', '1.0',
                  mean, 'within 1 %', abs(mean - 1) <= 0.01)
        bench.results.setdefault('laser_real_time', {})[engine] = dict(
            mean=mean, scans=heard, owed=owed)
    finally:
        if proc:
            bench.stop(proc)
