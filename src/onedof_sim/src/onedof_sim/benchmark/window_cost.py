"""Item 12, the Gazebo window's cost: the simulator node's CPU time per step, paced at real time,
with the book's mobot in its pen (its 720-ray lidar) and an arm of the book's arm7dof's shape
(bench/arm7dof_shape.urdf), with no window, then with the window open (gzclient: rviz on the world
view with the Gazebo panel and the model handles, on an Xvfb, drawing in software), then with no
window again, in one run. The lidar measures throughout: the benchmark listens to /scan as the
book's lidar nodes do (the laser's own cost is item 11's), so that what changes is the window
alone. The node's CPU time (every thread's, from /proc) is what the window costs the simulator's
loop: the streams it listens to (the visual markers and the window's model states at the views'
rate, /clock, /scan drawn), whatever rviz's drawing takes of the machine beside it. And no window
costs nothing: the two no-window stretches, before it opened and after it closed, agree. While the
window is open, the frames per second its view draws are taken as the Gazebo panel reports them
(its Time tab's FPS, published once a wall second), against the frame rate the view's
configuration asks rviz for."""

import os

import rospkg

from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark import laser_cost
from onedof_sim.benchmark import report as bm
from onedof_sim.benchmark.graph import STEP, NotMeasured, node_label, say

SETTLE_S = 0.25  # wall seconds after an unpause before a window opens
# The window's cost the issue allows: the node's CPU time per step with it open over that without,
# less one, below this.
WINDOW_COST_AIM = 0.10
WINDOW_UP_S = 600  # bounds rviz's start on a busy machine; only a failed start waits this long
ARM_X = -2.5  # the arm beside the mobot, within the lidar's reach
VISUAL_MARKERS = '/gazebo/visual_markers'
VIEW_MODEL_STATES = '/gazebo/view_model_states'
MODEL_STATES = '/gazebo/model_states'  # per step: the window does not listen to it
FRAME_RATE = '/gazebo_window/frame_rate'  # the Gazebo panel's FPS (std_msgs/Float64)
FRAME_RATE_AIM = 20.0  # frames per second the view keeps, at least
FRAME_RATE_WAIT_S = 60  # bounds the wait for a reading; the panel sends one a wall second


class FrameRates:
    """The Gazebo panel's frames per second, those that come while `taking` is set."""

    def __init__(self, rospy):
        from std_msgs.msg import Float64
        self.taking = False
        self.heard = 0
        self.rates = []
        self._subscriber = rospy.Subscriber(FRAME_RATE, Float64, self._on_rate, queue_size=100)

    def _on_rate(self, message):
        self.heard += 1
        if self.taking:
            self.rates.append(message.data)

    def connections(self):
        return self._subscriber.get_num_connections()

    def close(self):
        self._subscriber.unregister()


def configured_frame_rate():
    """The frame rate the simulator's view (gazebo_ros' world.rviz) asks rviz for."""
    import yaml
    path = os.path.join(rospkg.RosPack().get_path('gazebo_ros'), 'rviz', 'world.rviz')
    with open(path) as f:
        return float(yaml.safe_load(f)['Visualization Manager']['Global Options']['Frame Rate'])


def arm():
    """(name, path, format, x) of the arm."""
    onedof = rospkg.RosPack().get_path('onedof_sim')
    return ('arm7dof', os.path.join(onedof, 'bench', 'arm7dof_shape.urdf'), 'urdf', ARM_X)


def measure(bench, engine):
    from onedof_sim.tutorial.rviz_view import start_xvfb
    sizes = bench.sizes
    name = node_label(engine)
    proc = xvfb = window = scans = frame_rates = None
    try:
        proc, pid = bench.start_sim(engine, max_update_rate=1000, paused=True)
        laser_cost.spawn_scene(bench)
        bench.spawn([arm()])
        sim_time = bench.sim_clock()
        scans = laser_cost.ScanCounter(bench.rospy)
        wait_until(lambda: laser_cost.scan_connected(bench), 30, what='/scan connected')

        def windows(count):
            """(steps, wall seconds, the node's CPU seconds) of `count` windows of it running."""
            return [bench.running_window(sim_time, SETTLE_S, sizes.window_cost_window_s, pid)
                    for _ in range(count)]

        runs = {'before': windows(sizes.window_cost_windows)}
        xvfb, display = start_xvfb(bench.ros)
        window = bench.ros.start(['rosrun', 'gazebo_ros', 'gzclient'], name='gzclient',
                                 env={'DISPLAY': display, 'LIBGL_ALWAYS_SOFTWARE': '1'})
        wait_until(lambda: window.poll() is not None or (
            any(node.startswith('/gzclient') for node in bench.subscribers(VISUAL_MARKERS)) and
            '/gazebo_model_handles' in bench.subscribers(VIEW_MODEL_STATES) and
            any(node.startswith('/gzclient') for node in bench.subscribers('/scan'))),
            WINDOW_UP_S, what='the window to subscribe to the visual markers, the model states '
            'and the lidar')
        if window.poll() is not None:
            raise NotMeasured('gzclient ended: %s' % bench.ros.log_text(window)[-200:])
        frame_rates = FrameRates(bench.rospy)
        try:
            wait_until(lambda: window.poll() is not None or frame_rates.heard, WINDOW_UP_S,
                       what="the Gazebo panel's frames per second")
        except TimeoutError as error:
            raise NotMeasured('%s (%s published by: %s; this benchmark connected to %d of them; '
                              'gzclient\'s log ends: %s)' % (
                                  error, FRAME_RATE, ', '.join(bench.publishers(FRAME_RATE)) or
                                  'no node', frame_rates.connections(),
                                  bench.ros.log_text(window)[-1500:])) from None
        listeners = {topic: bench.subscribers(topic)
                     for topic in (VISUAL_MARKERS, VIEW_MODEL_STATES, '/scan', MODEL_STATES,
                                   '/clock')}
        frame_rates.taking = True
        runs['open'] = windows(sizes.window_cost_windows)
        # A reading a wall second: a quick run's windows can be shorter; the world runs on.
        if not frame_rates.rates:
            bench.pause(False)
            wait_until(lambda: frame_rates.rates or window.poll() is not None,
                       FRAME_RATE_WAIT_S, what="a reading of the view's frames per second")
            bench.pause(True)
        frame_rates.taking = False
        bench.ros.terminate(window)
        window = None
        wait_until(lambda: not bench.subscribers(VISUAL_MARKERS), 120,
                   what='the window gone from the graph')
        runs['after'] = windows(sizes.window_cost_windows)

        def cpu_per_step_us(taken):
            return 1e6 * sum(w[2] for w in taken) / max(sum(w[0] for w in taken), 1)
        per_step = {key: cpu_per_step_us(taken) for key, taken in runs.items()}
        without = cpu_per_step_us(runs['before'] + runs['after'])
        cost = per_step['open'] / without - 1
        rtf = {key: bm.rate([w[0] * STEP for w in taken], [w[1] for w in taken])
               for key, taken in runs.items()}
        bench.add('12', 'CPU time per step of the %s (every thread), paced at real time, the '
                  'book\'s mobot in its pen and an arm of arm7dof\'s shape, the Gazebo window '
                  'open (gzclient on Xvfb, software rendering; subscribers: %s); the window\'s '
                  'cost = ratio - 1: %.0f %% (real-time factor %.3f open, %.3f without; the lidar '
                  'measuring throughout, /scan heard by this benchmark)'
                  % (name, '; '.join('%s %s' % (topic, ', '.join(nodes) or 'none')
                                     for topic, nodes in listeners.items()),
                     100 * cost, rtf['open'], rtf['before']),
                  '%.1f us' % per_step['open'], 'the same node with no window, before it '
                  'opened and after it closed', '%.1f us' % without, per_step['open'] / without,
                  'cost < %.0f %%' % (100 * WINDOW_COST_AIM), cost < WINDOW_COST_AIM)
        bench.add('12', 'CPU time per step of the %s with no window, after the window closed'
                  % name, '%.1f us' % per_step['after'], 'the same, before the window opened',
                  '%.1f us' % per_step['before'], per_step['after'] / per_step['before'])
        rates = frame_rates.rates
        if rates:
            mean_rate, configured = sum(rates) / len(rates), configured_frame_rate()
            bench.add('12', 'frames per second the Gazebo window\'s view draws while the world '
                      'runs (gzclient on Xvfb, software rendering; the panel\'s FPS, %d reading(s) '
                      'a wall second apart, slowest %.1f)' % (len(rates), min(rates)),
                      '%.1f fps' % mean_rate, 'the frame rate the view\'s configuration asks '
                      'rviz for (world.rviz)', '%.0f fps' % configured, mean_rate / configured,
                      '>= %.0f fps' % FRAME_RATE_AIM, mean_rate >= FRAME_RATE_AIM)
        else:
            bench.not_measured('12', 'frames per second of the Gazebo window\'s view',
                               'no reading of %s came while the window was open' % FRAME_RATE)
        bench.results['window'] = dict(engine=engine, listeners=listeners, cost=cost,
                                       frame_rates=rates, **runs)
    except (NotMeasured, TimeoutError, OSError) as error:
        say('item 12 not measured: %s' % error)  # whole, where the row keeps its start
        bench.not_measured('12', 'the Gazebo window\'s cost, %s' % name, str(error)[:200])
    finally:
        if scans:
            scans.close()
        if frame_rates:
            frame_rates.close()
        if window:
            bench.ros.terminate(window)  # rviz before its X server
        if xvfb:
            bench.ros.terminate(xvfb)
        if proc:
            bench.stop(proc)
