"""Item 4, controller periods: the tutorial's rospy controller sampling a free-running simulator at
real-time factor 1, at 100 Hz and at higher rates: the periods it missed (from joint_states
stamps), the jitter of its jnt_pos arrivals, and the highest rate with none missed. Its /clock
arrivals at 100 Hz are also item 5's pacing figure (real_time_factor)."""
import os
import time

from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark import report as bm
from onedof_sim.benchmark.graph import PROFILE_S, NotMeasured, by_path, say
from onedof_sim.benchmark.plots import write_period_plot


def measure(bench, name):
    """Runs the controller at each rate on the running simulator (`name` labels it); returns the
    (CLOCK_MONOTONIC, sim time) /clock arrivals of the 100 Hz run."""
    sizes = bench.sizes
    runs = {}
    # Shortest first: a failure shows early.
    for duration, rate in sorted([(sizes.control_s, 100)] +
                                 [(sizes.sweep_s, r) for r in sizes.sweep_rates]):
        runs[rate] = control_run(bench, rate, duration)
        say('4 controller at %d Hz for %.0f s of sim time: %d missed periods'
            % (rate, duration, runs[rate]['missed']))
    at_100 = runs[100]
    bench.add('4', 'missed periods of the tutorial controller at 100 Hz, %.0f s of sim time at '
              'real-time factor 1 (%s; from joint_states stamps)' % (sizes.control_s, name),
              '%d of %d' % (at_100['missed'], at_100['expected']),
              'its own period (10 ms of sim time)', '—', None, '0 missed', at_100['missed'] == 0)
    bench.add('4', 'p99 period jitter of jnt_pos arrivals at 100 Hz, sim time / wall time',
              '%.2f / %.2f ms' % (at_100['jitter_sim'] * 1e3, at_100['jitter_wall'] * 1e3),
              'the period, 10 ms (sim time: /clock ticks of 1 ms in this process)', '10 ms',
              at_100['jitter_wall'] / 0.01)
    # The highest rate up to which no tried rate missed a period.
    highest = None
    for rate in sorted(runs):
        if runs[rate]['missed']:
            break
        highest = rate
    bench.add('4', 'highest controller rate with 0 missed periods, of %s Hz (%.0f s of sim '
              'time each above 100 Hz)' % (', '.join(map(str, sorted(runs))), sizes.sweep_s),
              '%s Hz' % highest if highest else 'none',
              'missed periods at each rate', ', '.join('%d Hz: %d of %d' % (
                  r, runs[r]['missed'], runs[r]['expected']) for r in sorted(runs)))
    clock = runs[100].pop('clock')
    for run in runs.values():
        run.pop('clock', None)
    bench.results['control_loop'] = {str(r): v for r, v in runs.items()}
    missing = [rate for rate in sorted(runs) if runs[rate]['missed']]
    if missing and bench.profiles:
        control_run(bench, missing[0], PROFILE_S + 2, profile=True)
    write_period_plot(runs, os.path.join(bench.output, 'control_loop.png'))
    return clock


def control_run(bench, rate, duration, profile=False):
    """Runs the tutorial controller at `rate` Hz for `duration` s of sim time; with profile,
    samples the controller during the window."""
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64
    rospy = bench.rospy
    probe = bench.clock_probe()
    arrivals, stamps = [], []
    subscribers = [
        rospy.Subscriber('/jnt_pos', Float64, lambda _: arrivals.append(
            (time.monotonic(), probe.latest)), queue_size=1000),
        rospy.Subscriber('/joint_states', JointState, lambda msg: stamps.append(
            msg.header.stamp.to_sec()), queue_size=1000)]
    controller = bench.ros.start(by_path(['rosrun', 'minimal_joint_controller',
                                          'minimal_joint_controller', '_rate:=%g' % rate]),
                                 name='controller_%d' % rate)
    try:
        wait_until(lambda: controller.poll() is not None or arrivals, 60,
                   what='the controller on jnt_pos')
        if controller.poll() is not None:
            raise NotMeasured('the controller exited: ' + bench.ros.log_text(controller)[-300:])
        start = probe.latest + 1.0  # one second of sim time to settle in
        end = start + duration
        if profile:
            bench.profile(bench.node_pid('/minimal_joint_controller'), PROFILE_S,
                          '4_controller_at_%d_Hz' % rate, python=True)
        wait_until(lambda: probe.latest >= end, duration * 5 + 30, interval=0.1,
                   what='%.0f s of sim time' % duration)
    finally:
        bench.stop(controller)
        for subscriber in subscribers:
            subscriber.unregister()
        probe.close()
    period = 1.0 / rate
    window_stamps = [t for t in stamps if start <= t < end]
    window = [(wall, sim) for wall, sim in arrivals if start <= sim < end]
    if len(window_stamps) < 2 or len(window) < 2:
        raise NotMeasured('the controller at %g Hz published %d joint_states in the window'
                          % (rate, len(window_stamps)))
    expected = round((window_stamps[-1] - window_stamps[0]) / period) + 1
    return dict(
        missed=bm.missed_periods(window_stamps, period), expected=expected,
        jitter_sim=bm.percentile(bm.period_jitter([s for _, s in window], period), 99),
        jitter_wall=bm.percentile(bm.period_jitter([w for w, _ in window], period), 99),
        wall_intervals=[b - a for (a, _), (b, _) in zip(window, window[1:])],
        clock=[(wall, sim) for wall, sim in probe.samples if start <= sim < end])
