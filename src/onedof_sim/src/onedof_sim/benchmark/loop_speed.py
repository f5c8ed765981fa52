"""Item 1, loop speed: steps per second of the simulator node with the tutorial robot and the cafe
table, as fast as possible, /clock every step and throttled, against the bare loop of its engine
on the same models (and, for the engine pybullet wraps, against bare pybullet), in alternating
windows. The same node also gives item 7 (memory) before its windows."""

from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark import memory
from onedof_sim.benchmark import report as bm
from onedof_sim.benchmark.graph import (CLOCK_FREQUENCY, PROFILE_S, BareLoop, NotMeasured,
                                        engine_loop_command, node_label, pybullet_loop_command)

# The engine whose physics library pybullet wraps: its node is also set against bare pybullet.
PYBULLET_COUNTERPART = 'bullet'
THROTTLED_CLOCK_HZ = 100.0
# The node's steps per second as a share of its engine's bare loop's, on every engine: what the
# node adds to a step (its mutex, /clock, the plugins' hooks) stays a fifth of it at most.
NODE_SHARE_AIM = 0.8
SETTLE_S = 0.25  # wall seconds after an unpause before a window opens


def measure_with_memory(bench, engine):
    """Items 1 and 7 on one node of `engine`."""
    sizes = bench.sizes
    proc = None
    loops = {}
    try:
        proc, pid = bench.start_sim(engine, max_update_rate=0, paused=True)
        bench.spawn(bench.tutorial_models)
        sim_time = bench.sim_clock()

        def node_window(clock_frequency):
            """(steps, wall seconds) of the node running for one window."""
            bench.ros.set_param(CLOCK_FREQUENCY, clock_frequency)
            # The settling: the node re-reads pub_clock_frequency 10 times a second.
            return bench.running_window(sim_time, SETTLE_S, sizes.throughput_window_s)

        bench.pause(False)
        wait_until(lambda: sim_time()[1] > 0.1, 30, what='the first 100 steps')
        bench.pause(True)
        memory.measure(bench, engine, pid, sim_time)
        clock_subscribers = bench.subscribers('/clock')
        loops['bare'] = BareLoop(engine_loop_command(engine),
                                 [bench.ground_model] + bench.tutorial_models)
        against_pybullet = ('steps/s of the %s, /clock every step, against bare pybullet'
                            % node_label(engine))
        if engine == PYBULLET_COUNTERPART:
            try:
                loops['pybullet'] = BareLoop(pybullet_loop_command(), bench.tutorial_models)
            except NotMeasured as error:
                bench.not_measured('1', against_pybullet, str(error)[:200])
        for loop in loops.values():
            loop.run(sizes.throughput_window_s / 4)  # warm-up, not counted
        windows = {'node': [], 'throttled': []}
        windows.update((key, []) for key in loops)
        for _ in range(sizes.throughput_windows):
            for key, loop in loops.items():
                windows[key].append(loop.run(sizes.throughput_window_s))
            windows['node'].append(node_window(0.0))
            windows['throttled'].append(node_window(THROTTLED_CLOCK_HZ))
        bench.ros.set_param(CLOCK_FREQUENCY, 0.0)
        rates = {key: bm.rate(*zip(*key_windows)) for key, key_windows in windows.items()}
        met = rates['node'] / rates['bare'] >= NODE_SHARE_AIM
        bench.add('1', 'steps/s of the %s, tutorial robot + cafe table, as fast as possible, '
                  '/clock every step; /clock subscribers: %s' % (
                      node_label(engine), ', '.join(clock_subscribers) or 'none'),
                  '%.0f' % rates['node'], 'bare loop on the same models, %s (World::step: '
                  'effort jobs, collisions, contacts, the engine\'s step; no mutex, /clock or '
                  'pacing)' % ' '.join(engine_loop_command(engine)[2:]),
                  '%.0f' % rates['bare'], rates['node'] / rates['bare'],
                  '>= %g' % NODE_SHARE_AIM, met)
        bench.add('1', 'the same %s with /gazebo/pub_clock_frequency %g (what /clock every '
                  'step costs)' % (node_label(engine), THROTTLED_CLOCK_HZ),
                  '%.0f' % rates['throttled'], 'the same bare loop', '%.0f' % rates['bare'],
                  rates['throttled'] / rates['bare'])
        if 'pybullet' in rates:
            of_pybullet = rates['node'] / rates['pybullet']
            met = met and of_pybullet >= 0.3
            bench.add('1', against_pybullet, '%.0f' % rates['node'],
                      'bare pybullet loop on the same models (pybullet\'s own loadURDF and '
                      'loadSDF; stepSimulation alone)', '%.0f' % rates['pybullet'],
                      of_pybullet, '>= 0.3', of_pybullet >= 0.3)
        if not met:
            bench.pause(False)
            bench.profile(pid, PROFILE_S, '1_%s_node_as_fast_as_possible' % engine)
            bench.pause(True)
        bench.results.setdefault('throughput', {})[engine] = dict(
            clock_subscribers=clock_subscribers, **windows)

    except (NotMeasured, TimeoutError, OSError) as error:
        bench.not_measured('1, 7', 'throughput and memory, %s' % node_label(engine),
                           str(error)[:200])
    finally:
        for loop in loops.values():
            loop.close()
        if proc:
            bench.stop(proc)
