"""A world and a model at the documented limits (README's limits table), over real ROS on every
engine. A world of 1000 models loads, and SIGINT (Ctrl-C) ends the node while it loads, whether
libsdformat is still reading the file or the models are being spawned. The time a load takes is a
figure for the README, measured on its own, never asserted here; the bounds below only catch a
hang. A model of 1000 links spawned and deleted, or refused once parsed, leaves the node's memory
(its resident set) where it was, within MEMORY_KEPT_MB."""
import os
import signal
import time

import pytest

from api_client import GazeboApi, fixed_chain_sdf, pose
from conftest import ENGINES, GROUND, simulator_executable, start_sim
from onedof_harness.private_ros import wait_until

MODELS = 1000  # the limit the README gives for a world file
# Bounds a load that hangs: a load takes a few minutes at most on 2 busy cores.
LOAD_TIMEOUT_S = 900
# Bounds a node that does not end on SIGINT: roscpp's own shutdown takes seconds on a busy
# machine; a load that went on to its end would take minutes.
SIGINT_TIMEOUT_S = 30
# What a 1000-link spawn and delete (or refusal) may leave in the node's resident set: the heap's
# bookkeeping and what roscpp keeps of the calls, not the model's hundreds of MB.
MEMORY_KEPT_MB = 50


def boxes_world(folder, odometry=False):
    """MODELS static unit boxes on a grid, each with a collision and a visual, and with odometry
    each with a gazebo_ros_p3d plugin publishing its pose: a publisher advertised for each model
    makes the models' spawns last seconds on a busy machine, where the boxes alone are spawned
    within a fraction of one, once the file is read."""
    models = []
    for i in range(MODELS):
        plugin = ('<plugin name="p3d" filename="libgazebo_ros_p3d.so"><bodyName>link</bodyName>'
                  '<topicName>box_%d/odom</topicName><updateRate>1</updateRate></plugin>' % i
                  if odometry else '')
        models.append('<model name="box_%d"><static>true</static><pose>%g %g 0.5 0 0 0</pose>'
                      '<link name="link"><collision name="c"><geometry><box><size>1 1 1</size>'
                      '</box></geometry></collision><visual name="v"><geometry><box>'
                      '<size>1 1 1</size></box></geometry></visual></link>%s</model>'
                      % (i, 2.0 * (i % 32), 2.0 * (i // 32), plugin))
    path = os.path.join(str(folder), 'boxes%s.world' % ('_odometry' if odometry else ''))
    with open(path, 'w') as f:
        f.write('<?xml version="1.0"?><sdf version="1.6"><world name="boxes">%s</world></sdf>'
                % ''.join(models))
    return path


def start_loading(ros, engine, folder, name, odometry=False):
    return ros.start([simulator_executable(), '_physics:=' + engine, '-u',
                      boxes_world(folder, odometry)], name=name)


@pytest.mark.parametrize('engine', ENGINES)
def test_a_world_of_as_many_models_as_the_limit_loads(ros, rospy_client, engine, tmp_path):
    sim = start_loading(ros, engine, tmp_path, 'sim')
    ros.wait_until(lambda: ros.has_service('/gazebo/unpause_physics'), LOAD_TIMEOUT_S,
                   what='the world of %d models to load' % MODELS)
    names = GazeboApi(rospy_client).get_world_properties().model_names
    assert sorted(names) == sorted('box_%d' % i for i in range(MODELS))
    assert sim.poll() is None


def interrupted_within_bound(ros, sim):
    """SIGINT to the node alone, as Ctrl-C; True if it ended within SIGINT_TIMEOUT_S."""
    os.kill(sim.pid, signal.SIGINT)
    sim.stopped = True
    try:
        sim.wait(timeout=SIGINT_TIMEOUT_S)
    except Exception:  # subprocess.TimeoutExpired
        return False
    return True


@pytest.mark.parametrize('engine', ENGINES)
def test_sigint_ends_the_node_while_a_large_world_loads(ros, engine, tmp_path):
    # While libsdformat reads the file: the node registers with the master before it reads.
    reading = start_loading(ros, engine, tmp_path, 'reading')
    wait_until(lambda: reading.poll() is not None or
               ros.master().lookupNode('/test_large_world', '/gazebo')[0] == 1,
               60, what='the node to register with the master')
    started = time.monotonic()
    assert interrupted_within_bound(ros, reading), \
        'still running %.0f s after SIGINT:\n%s' % (time.monotonic() - started,
                                                     ros.log_text(reading)[-2000:])
    # While the models are spawned: models whose spawns last long enough to be interrupted.
    spawning = start_loading(ros, engine, tmp_path, 'spawning', odometry=True)
    wait_until(lambda: spawning.poll() is not None or
               "spawned model 'box_" in ros.log_text(spawning), LOAD_TIMEOUT_S,
               what='the first model of the world to be spawned')
    assert interrupted_within_bound(ros, spawning), ros.log_text(spawning)[-2000:]
    # Interrupted right after the first model, it spawned no more than a few.
    log = ros.log_text(spawning)
    assert ("spawned model 'box_%d'" % (MODELS - 1)) not in log, log[-2000:]


def resident_mb(pid):
    with open('/proc/%d/status' % pid) as f:
        for line in f:
            if line.startswith('VmRSS:'):
                return int(line.split()[1]) / 1024.0
    raise AssertionError('no VmRSS for pid %d' % pid)


@pytest.mark.parametrize('engine', ENGINES)
def test_memory_is_given_back_after_a_large_model_is_deleted_or_refused(ros, rospy_client,
                                                                        engine):
    sim = start_sim(ros, engine, ['-u'])
    api = GazeboApi(rospy_client)
    # What the first spawns set up once (libsdformat's schema, roscpp's connections) stays.
    for _ in range(2):
        assert api.spawn_sdf_model('small', fixed_chain_sdf(10, 'small'), '', pose(), '').success
        assert api.delete_model('small').success
    before = resident_mb(sim.pid)
    figures = ['before: %.0f MB' % before]
    refused = fixed_chain_sdf(1000).replace(
        '</model>', '<plugin name="p" filename="libgazebo_ros_p3d.so"><bodyName>l0</bodyName>'
        '<topicName>bad name</topicName></plugin></model>')
    for _ in range(2):
        res = api.spawn_sdf_model('chain', fixed_chain_sdf(1000), '', pose(), '')
        assert res.success, res.status_message
        figures.append('spawned: %.0f MB' % resident_mb(sim.pid))
        assert api.delete_model('chain').success
        figures.append('deleted: %.0f MB' % resident_mb(sim.pid))
        res = api.spawn_sdf_model('chain', refused, '', pose(), '')
        assert not res.success and 'is not a valid ROS name' in res.status_message, res
        figures.append('refused: %.0f MB' % resident_mb(sim.pid))
    print('%s: %s' % (engine, ', '.join(figures)))
    assert api.get_world_properties().model_names == [GROUND]
    assert resident_mb(sim.pid) - before <= MEMORY_KEPT_MB, figures
