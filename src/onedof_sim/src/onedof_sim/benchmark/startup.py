"""Item 6, start-up: roslaunch of minimal_robot_description.launch on each engine to the first
/clock and to get_joint_properties(joint1) answering, against roslaunch of a bare roscpp service
node until it answers; the median of a few launches, alternating."""
import os
import time

from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark import report as bm
from onedof_sim.benchmark.graph import NotMeasured


def measure(bench):
    floor_launch = os.path.join(bench.work, 'bare_service.launch')
    with open(floor_launch, 'w') as f:
        f.write('<launch><node name="bare_startup" pkg="onedof_sim" '
                'type="bench_bare_service"/></launch>\n')
    floor, results = [], {engine: {'clock': [], 'robot': []} for engine in bench.engines}
    failed = {}
    for repeat in range(bench.sizes.startup_repeats):
        floor.append(launch_until(bench, [floor_launch], '/bare_startup/get_joint_properties')[1])
        for engine in bench.engines:
            if engine in failed:
                continue
            try:
                clock, robot = launch_until(
                    bench, ['minimal_robot_description', 'minimal_robot_description.launch',
                            'physics:=' + engine], '/gazebo/get_joint_properties', clock=True)
            except (NotMeasured, TimeoutError) as error:
                failed[engine] = str(error)
                continue
            results[engine]['clock'].append(clock)
            results[engine]['robot'].append(robot)
    floor_median = bm.percentile(floor, 50)
    against = 'roslaunch of a bare roscpp service node until it answers'
    for engine in bench.engines:
        launch = 'start-up: roslaunch minimal_robot_description.launch physics:=%s ' % engine
        if engine in failed:
            bench.not_measured('6', launch, failed[engine][:200])
            continue
        for key, what in (('clock', launch + 'to the first /clock, median of %d'),
                          ('robot', launch + 'to get_joint_properties(joint1) answering, '
                                             'median of %d')):
            value = bm.percentile(results[engine][key], 50)
            bench.add('6', what % len(results[engine][key]), '%.2f s' % value, against,
                      '%.2f s' % floor_median, bm.ratio(value, floor_median))
    bench.results['startup'] = dict(floor=floor, **results)


def launch_until(bench, launch_args, service, clock=False):
    """Wall seconds from starting roslaunch to the first /clock (when clock) and to `service`
    answering for joint1."""
    probe = bench.clock_probe() if clock else None
    start = time.monotonic()
    proc = bench.ros.start(['roslaunch'] + launch_args, name='launch')
    try:
        def answered():
            if proc.poll() is not None:
                raise NotMeasured('roslaunch %s exited: %s' % (
                    ' '.join(launch_args), bench.ros.log_text(proc)[-400:]))
            return bench.answers(service, bench.srv.GetJointProperties, 'joint1')
        wait_until(answered, 60, interval=0.01, what=service)
        answered_at = time.monotonic()
        first_clock = None
        if probe:
            wait_until(lambda: probe.samples, 10, interval=0.01, what='a /clock')
            first_clock = probe.samples[0][0] - start
        return first_clock, answered_at - start
    finally:
        if probe:
            probe.close()
        bench.stop(proc)
