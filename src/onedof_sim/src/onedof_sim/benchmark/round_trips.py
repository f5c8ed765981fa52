"""Item 3, service round trips: get_joint_properties and apply_joint_effort on the simulator node,
from a rospy and a roscpp client, over persistent and fresh connections, against a bare roscpp
service of the same srv types and reply sizes, in alternating batches; p50 and p99."""
import os
import subprocess
import time

from onedof_harness.private_ros import PrivateRos
from onedof_sim.benchmark import report as bm
from onedof_sim.benchmark.graph import PROFILE_S, NotMeasured, by_path, node_label
from onedof_sim.benchmark.plots import write_latency_plot

BARE_SERVICE = 'bare'  # node name of the bare service: /bare/get_joint_properties, ...
SERVICES = ('get_joint_properties', 'apply_joint_effort')
WARM_UP_CALLS = 20


def microseconds(values):
    return '%.0f / %.0f us' % (bm.percentile(values, 50), bm.percentile(values, 99))


def measure(bench, engine):
    name = node_label(engine)
    sizes = bench.sizes
    sim = bare = None
    samples = {}
    try:
        sim, sim_pid = bench.start_sim(engine)
        bench.spawn(bench.tutorial_models[:1])
        bare = bench.ros.start(by_path(['rosrun', 'onedof_sim', 'bench_bare_service',
                                        '__name:=' + BARE_SERVICE]), name='bare_service')
        bench.wait_for_node(bare, '/' + BARE_SERVICE)
        for service in SERVICES:
            bench.ros.wait_for_service('/%s/%s' % (BARE_SERVICE, service))
        failed_calls = 0  # roscpp calls that got no answer
        for client in ('rospy', 'roscpp'):
            for mode in ('persistent', 'fresh'):
                count = sizes.persistent_calls if mode == 'persistent' else sizes.fresh_calls
                for service in SERVICES:
                    key = (client, mode, service)
                    samples[key] = {'sim': [], 'bare': []}
                    for _ in range(sizes.latency_batches):
                        for target, ns in (('sim', 'gazebo'), ('bare', BARE_SERVICE)):
                            times, failed = round_trips(
                                bench, client, '/%s/%s' % (ns, service), mode, count)
                            samples[key][target] += times
                            failed_calls += failed
        if failed_calls:
            bench.notes.append('3: %d roscpp calls got no answer during the %s latency item '
                               '(left out of the percentiles)' % (failed_calls, name))
        ratios = {key: bm.percentile(by_target['sim'], 50) /
                  bm.percentile(by_target['bare'], 50) for key, by_target in samples.items()}
        worst = max(ratios, key=ratios.get)
        if ratios[worst] > 1.3:
            profile_under_load(bench, sim_pid, engine, worst)
    except (NotMeasured, TimeoutError, subprocess.CalledProcessError) as error:
        bench.not_measured('3', 'service latency, %s' % name, str(error)[:200])
        return
    finally:
        for proc in (bare, sim):
            if proc:
                bench.stop(proc)
    for (client, mode, service), by_target in samples.items():
        bench.add('3', '%s round trip p50 / p99, %s client, %s connection (%s, %d calls)'
                  % (service, client, mode, name, len(by_target['sim'])),
                  microseconds(by_target['sim']),
                  'bare roscpp service, same srv type and reply size, alternating batches',
                  microseconds(by_target['bare']), ratios[(client, mode, service)],
                  'p50 <= 1.3x', ratios[(client, mode, service)] <= 1.3)
    bench.results.setdefault('latency', {})[engine] = {
        ' '.join(key): {target: dict(p50=bm.percentile(v, 50), p99=bm.percentile(v, 99))
                        for target, v in by_target.items()}
        for key, by_target in samples.items()}
    write_latency_plot(samples, name, os.path.join(bench.output, 'latency_%s.png' % engine))


def profile_under_load(bench, sim_pid, engine, key):
    """Profiles the simulator while a roscpp client calls the service of `key` (the pair furthest
    from the floor) back to back."""
    _, mode, service = key
    load = subprocess.Popen(by_path(['rosrun', 'onedof_sim', 'bench_service_client',
                                     '/gazebo/' + service, service.split('_')[0], mode,
                                     '1000000']),
                            env=bench.ros.env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        bench.profile(sim_pid, PROFILE_S, '3_%s_node_serving_%s_%s' % (engine, service, mode))
    finally:
        PrivateRos.terminate(load)


def round_trips(bench, client, service, mode, count):
    """(round trips in microseconds, warm-up calls excluded; calls that got no answer)."""
    if client == 'roscpp':
        result = subprocess.run(by_path(['rosrun', 'onedof_sim', 'bench_service_client',
                                         service, 'get' if 'get_' in service else 'apply', mode,
                                         str(count)]),
                                env=bench.ros.env, capture_output=True, text=True, timeout=120)
        if result.returncode != 0:
            raise NotMeasured('bench_service_client %s: %s' % (service, result.stderr[-300:]))
        lines = result.stdout.split()
        return [float(line) for line in lines if line != 'failed'], lines.count('failed')
    if 'get_' in service:
        srv_class, args = bench.srv.GetJointProperties, ('joint1',)
    else:
        srv_class = bench.srv.ApplyJointEffort
        args = ('joint1', 0.0, bench.rospy.Time(0), bench.rospy.Duration(0.01))
    proxy = bench.proxy(service, srv_class, persistent=mode == 'persistent')
    try:
        times = []
        for i in range(-WARM_UP_CALLS, count):
            start = time.perf_counter()
            result = proxy(*args)
            elapsed = time.perf_counter() - start
            if not result.success:
                raise NotMeasured('%s: %s' % (service, result.status_message))
            if i >= 0:
                times.append(elapsed * 1e6)
        return times, 0
    finally:
        proxy.close()
